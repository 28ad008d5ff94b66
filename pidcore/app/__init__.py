"""The Streamlit app of pidcore (``pidcore app``), shipped inside the package.

Layout: :mod:`.main` lays out the tabs, :mod:`.tabs` holds one module per tab (analyse,
compare, dem, calibrate, report; not ``pages/``, which Streamlit would list as extra pages
beside :data:`ENTRY_SCRIPT`), :mod:`.charts` the Vega-Lite charts and :mod:`.state` the
cached reads. The logic the tabs call is free of Streamlit and tested directly:
:mod:`.uploads` (uploads, per-file settings, saving), :mod:`.stores` (which stores the app
uses), :mod:`.jobs` (the DEM job runner); comparison, loops, store listings and report files
live in :mod:`pidcore.compare.case`, :mod:`pidcore.loop`, :mod:`pidcore.store.listing`
and :mod:`pidcore.report.downloads`.

The entry script :data:`ENTRY_SCRIPT` lives in the package so that ``pidcore app`` finds it in
every installation; ``app/pidcore_app.py`` in the repository runs it for
``streamlit run app/pidcore_app.py``.
"""

from pathlib import Path

#: The script ``streamlit run`` executes.
ENTRY_SCRIPT = Path(__file__).with_name("entry.py")
