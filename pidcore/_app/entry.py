"""Streamlit entry script of the pidcore app: ``streamlit run <this file>``."""

from pidcore._app.ui import main

main()
