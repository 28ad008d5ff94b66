"""``streamlit run app/pidcore_app.py``: shim for the app shipped in the package (pidcore.app)."""

from pidcore.app.main import main

main()
