"""``streamlit run app/pidcore_app.py``: shim for the app shipped in the package (pidcore.app)."""

# A DEM job's worker process re-runs its parent's main script as "__mp_main__"
# (multiprocessing's start-up); during a Streamlit script run that is this script, which
# then imported the app and drew the whole page in every worker (hundreds of "no
# ScriptRunContext" warnings per job).
if __name__ != "__mp_main__":
    from pidcore.app.main import main

    main()
