"""The Streamlit app of pidcore (``pidcore app``), shipped inside the package.

The entry script :data:`ENTRY_SCRIPT` lives in the package so that ``pidcore app`` finds it in
every installation (editable or not); ``app/pidcore_app.py`` in the repository is a shim that
runs it, for ``streamlit run app/pidcore_app.py``. The pages only lay out widgets; their logic
is in :mod:`pidcore.app_support`.
"""

from pathlib import Path

#: The script ``streamlit run`` executes.
ENTRY_SCRIPT = Path(__file__).with_name("entry.py")
