"""DEM tab: run one load case or a small sweep, with progress and cancel; cases saved at once.

The sweep runs one case per step inside the script run. A click on Cancel (or any other
widget) asks Streamlit to rerun; the running case finishes and is saved before the script
reaches its next Streamlit call, where the rerun takes over. The rerun sees Cancel pressed and
drops the rest of the queue; any other rerun picks the queue up where it stopped. So finished
cases are never lost and nothing runs in a background thread.
"""

from __future__ import annotations

import streamlit as st

from pidcore import app_support, defaults
from pidcore.constants import DRIVE_DIRECTIONS, PARTICLE_MATERIALS

_GRID = {"frequency_hz": (50.0, 100.0, 500.0, 1000.0), "acceleration_g": (1.0, 5.0, 10.0),
         "fill_percent": (25.0, 50.0, 75.0, 90.0)}


def _grid() -> dict:
    try:
        from pidcore.dem.sweep import GRIDS

        return GRIDS["table3"]
    except (ImportError, KeyError):
        return _GRID


def _config(cells: int, seed: int, steady_cycles: int):
    from pidcore.dem import DemConfig

    return DemConfig(cells=int(cells), seed=int(seed),
                     steady_cycles=int(steady_cycles) if steady_cycles > 0 else None)


def _request_cancel() -> None:
    # Button callback: runs at the start of the rerun the click causes, before the script.
    st.session_state["dem_cancel_requested"] = True


def _cancel(state) -> None:
    left = len(state.get("dem_queue") or [])
    state["dem_queue"] = []
    state["dem_cancel_requested"] = False
    state["dem_message"] = ("warning", f"cancelled: {left} case(s) not run; "
                                       f"{len(state.get('dem_done', []))} finished case(s) are "
                                       "saved")


def render(stores) -> None:
    from pidcore.errors import PidcoreError

    st.subheader("DEM: run load cases")
    st.caption(f"One case or a small sweep (at most {defaults.APP_MAX_DEM_CASES} cases); each "
               f"finished case is saved to the store at once. Larger grids: `pidcore dem`.")
    grid = _grid()
    c1, c2, c3 = st.columns(3)
    freqs = c1.multiselect("frequency [Hz]", grid["frequency_hz"], default=[100.0],
                           key="dem_freqs")
    accs = c2.multiselect("acceleration [g]", grid["acceleration_g"], default=[5.0],
                          key="dem_accs")
    fills = c3.multiselect("fill [%]", grid["fill_percent"], default=[50.0], key="dem_fills")
    c4, c5 = st.columns(2)
    material = c4.selectbox("particle material", PARTICLE_MATERIALS, key="dem_material")
    direction = c5.selectbox("drive direction", DRIVE_DIRECTIONS, key="dem_direction")
    with st.expander("numerical settings", expanded=False):
        d1, d2, d3 = st.columns(3)
        cells = d1.number_input("cells simulated", min_value=1, max_value=64,
                                value=defaults.DEM_CELLS, step=1, key="dem_cells")
        seed = d2.number_input("seed", min_value=0, value=defaults.DEM_SEED, step=1,
                               key="dem_seed")
        steady = d3.number_input("steady cycles (0 = automatic)", min_value=0, value=0, step=1,
                                 key="dem_steady")

    state = st.session_state
    b1, b2 = st.columns(2)
    start = b1.button("Run", type="primary", key="dem_run", disabled=bool(state.get("dem_queue")))
    b2.button("Cancel", key="dem_cancel", disabled=not state.get("dem_queue"),
              on_click=_request_cancel)
    if start:
        try:
            config = _config(cells, seed, steady)
            cases = app_support.plan_dem_cases(freqs, accs, fills, material=material,
                                               direction=direction)
        except PidcoreError as exc:
            st.error(str(exc))
        else:
            state["dem_queue"] = [(case, config) for case in cases]
            state["dem_cancel_requested"] = False
            state["dem_total"] = len(cases)
            state["dem_done"] = []
            state["dem_skipped"] = []
            state["dem_message"] = None

    message = state.get("dem_message")
    if message:
        getattr(st, message[0])(message[1])
    queue = state.get("dem_queue") or []
    if queue:
        total = state["dem_total"]
        progress = st.progress(0.0, text="starting ...")
        while state.get("dem_queue"):
            if state.get("dem_cancel_requested"):
                _cancel(state)
                break
            case, config = state["dem_queue"][0]
            done = total - len(state["dem_queue"])
            progress.progress(done / total, text=f"case {done + 1} of {total}: "
                                                 f"{case.key} ...")
            try:
                if app_support.dem_run_stored(stores.path, case, config):
                    state["dem_skipped"].append(app_support.dem_run_key(case, config))
                else:
                    state["dem_done"].append(app_support.run_dem_case(stores.path, case, config))
            except PidcoreError as exc:
                state["dem_queue"] = []
                state["dem_message"] = ("error", f"{case.key}: {exc} (finished cases are "
                                                 "saved)")
                st.rerun()
            state["dem_queue"] = state["dem_queue"][1:]
        if not state.get("dem_message"):
            progress.progress(1.0, text="done")
            state["dem_message"] = ("success", f"{len(state['dem_done'])} case(s) run and "
                                               f"saved, {len(state['dem_skipped'])} already in "
                                               "the store")
        st.rerun()  # so the Compare and Report tabs read the new runs
    from pidcore._app.ui import store_listing

    try:
        runs = store_listing("dem_runs", stores.stamp(), stores)
    except PidcoreError as exc:
        st.error(f"cannot read the DEM runs: {exc}")
        return
    if not runs.empty:
        cols = [c for c in ("case_key", "frequency_hz", "acceleration_g", "fill_percent",
                            "material", "direction", "sdc", "sdc_stderr", "cells_simulated",
                            "seed", "wall_s", "store") if c in runs.columns]
        st.markdown(f"**DEM runs** ({len(runs)})")
        st.dataframe(runs[cols], hide_index=True)
