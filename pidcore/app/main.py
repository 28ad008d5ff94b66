"""Layout of the pidcore Streamlit app: sidebar and five tabs, one module each.

Tabs rather than separate pages: every tab is drawn on each run, so uploads and their
per-file settings live as long as the session without copying widget state around, and a tab
switch happens in the browser (no server round trip).
"""

from __future__ import annotations

import streamlit as st

from pidcore import __version__, defaults
from pidcore.app import state
from pidcore.app.calibration import (
    available_calibrations,
    calibration_read_notes,
    remember_read_notes,
    runner_for,
)
from pidcore.app.stores import AppStores
from pidcore.app.tabs import analyse, calibrate, compare, dem, report
from pidcore.specimen import hearing_read_notes


def main() -> None:
    """Draw the app (the entry script calls this on every run)."""
    st.set_page_config(page_title="pidcore", layout="wide")
    stores = AppStores.from_environment()
    st.title("pidcore: particle impact damping")
    with st.sidebar:
        st.markdown(f"**store**: `{stores.path}`")
        if stores.dem_reference is not None:
            st.markdown(f"**reference DEM runs** (read-only): `{stores.dem_reference}`")
        st.markdown(f"**upload limit**: {defaults.APP_MAX_UPLOAD_MB} MB per file")
        st.caption(f"pidcore {__version__}")
    # read once per store state: the Compare and Report tabs offer the same calibrations and
    # the Calibrate tab lists them
    stored = state.store_calibrations(stores.stamp(), stores)
    calibrations = available_calibrations(runner_for(stores.path).task, store_path=stores.path,
                                          stored=stored)
    # what reading a calibration folder or a calibrated specimen file did first (a killed
    # calibration's moves finished), kept for the session: only the read that finished them
    # has it to say; shown above the tabs once they are drawn (their reads are heard too)
    read_notes = remember_read_notes(st.session_state.setdefault("_read_notes", []),
                                     calibration_read_notes(calibrations))
    notes_box = st.container()
    t_analyse, t_compare, t_dem, t_cal, t_report = st.tabs(
        ["Analyse", "Compare", "DEM", "Calibrate", "Report"])
    with hearing_read_notes(lambda note: remember_read_notes(read_notes, [note])):
        with t_analyse:
            analysed = analyse.render(stores)
        with t_compare:
            compare.render(stores, analysed, calibrations)
        with t_dem:
            dem.render(stores)
        with t_cal:
            calibrate.render(stores, stored)
        with t_report:
            report.render(stores, calibrations)
    with notes_box:
        for note in read_notes:
            st.info(note)
