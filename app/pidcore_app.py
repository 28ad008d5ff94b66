"""``streamlit run app/pidcore_app.py``: shim for the app shipped in the package (pidcore._app)."""

from pidcore._app.ui import main

main()
