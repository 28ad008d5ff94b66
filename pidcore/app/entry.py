"""Streamlit entry script of the pidcore app: ``streamlit run <this file>``."""

from pidcore.app.main import main

main()
