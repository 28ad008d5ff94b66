"""DEM page: submit load cases (any frequency, acceleration and fill) to the background job
runner (:mod:`pidcore.app.jobs`), watch progress with elapsed time and ETA, cancel at any time.

The page never computes: a click submits or cancels and returns at once, the job table
refreshes itself every second while jobs run (a fragment), and every finished case is saved
by the runner.
"""

from __future__ import annotations

import pandas as pd
import streamlit as st

from pidcore import defaults
from pidcore.app import jobs, state
from pidcore.app.tabs import (
    ADDRESS_BINDING,
    draw_polling,
    refuse_address_choices,
    specimen_choice,
)
from pidcore.app.workbench import report_number_formats
from pidcore.constants import DRIVE_DIRECTIONS, PARTICLE_MATERIALS
from pidcore.loadcase import parse_count, parse_values

#: Most cells a DEM job of the page simulates.
MAX_CELLS = defaults.APP_MAX_DEM_CELLS

#: Seconds between refreshes of the job table while jobs run.
REFRESH_S = 1.0
#: Longest wait of the Cancel button for the running case's process to end, s (a process
#: that does not stop at once is killed after the runner's grace time).
CANCEL_WAIT_S = 1.5


def _config(cells: str, seed: str, steady_cycles: str):
    from pidcore.dem import DemConfig

    steady = parse_count(steady_cycles, name="steady cycles (0 = automatic)",
                         maximum=defaults.DEM_MAX_STEADY_CYCLES)
    return DemConfig(cells=parse_count(cells, name="cells simulated", minimum=1,
                                       maximum=MAX_CELLS),
                     seed=parse_count(seed, name="seed"),
                     steady_cycles=steady if steady > 0 else None)


def _runner(stores) -> jobs.DemJobRunner:
    # the reference store's runs are not run again, as `pidcore dem sweep` reuses stored runs
    return jobs.runner_for(stores.path, stores.dem_reference)


def _cancel(stores) -> None:
    # Button callback: runs before the script, so the cancel reaches the runner at once; it
    # waits (briefly) for the running case's process to end, so that this very script run
    # shows the jobs cancelled instead of the next table refresh a second later
    runner = _runner(stores)
    n = runner.cancel()
    runner.wait_cancelled(CANCEL_WAIT_S)
    st.session_state["dem_message"] = jobs.cancelled_text(n, runner.jobs())


def _job_table(stores, polling: bool) -> None:
    # a fragment (see draw_polling): rerun every REFRESH_S while jobs are queued or running
    runner = _runner(stores)
    listed = runner.jobs()  # one locked copy for the table and the progress bar
    rows = [j.row() for j in listed]
    busy = runner.busy()
    # this server's: another server's progress is not in the journal (it writes states only)
    running = [j for j in listed if j.state == "running" and not j.server]
    if running:
        st.progress(running[0].fraction(), text=running[0].progress_text())
    if rows:
        st.dataframe(pd.DataFrame(rows), hide_index=True, width="stretch", key="dem_jobs")
        counts = pd.Series([r["state"] for r in rows]).value_counts()
        st.caption("jobs: " + ", ".join(f"{n} {s}" for s, n in counts.items())
                   + (" · refreshing every second" if busy else ""))
    # A job that finished since the last look changes the store: let the other tabs re-read.
    # A session's first look has none before it (its tabs read the store this run), and a
    # rerun then kept the fields Streamlit had just filled from the page address in the session
    # state into the next run, beside their defaults: a warning with a stack trace in the log
    done = sum(r["state"] == "saved" for r in rows)
    seen = st.session_state.get("_dem_saved_seen")
    st.session_state["_dem_saved_seen"] = done
    if seen is not None and seen != done and done:
        st.rerun(scope="app")
    if polling and not busy:  # the last job ended: draw the page again, without the timer
        st.rerun(scope="app")


def render(stores) -> None:
    """The page."""
    from pidcore.errors import PidcoreError

    st.subheader("DEM: run load cases")
    st.caption(f"Any frequencies, accelerations and fills, on any specimen (at most "
               f"{defaults.APP_MAX_DEM_CASES} cases at a time). Cases run in the background, "
               "one after the other, each saved to the store as it finishes; you can switch "
               "tabs or reload meanwhile. Larger grids: `pidcore dem`.")
    c1, c2, c3 = st.columns(3)
    # every field is bound to the page address: a reload keeps the form (ADDRESS_BINDING)
    freqs = c1.text_input("frequencies [Hz]", "100", key="dem_freqs",
                          help="one or more values, e.g. 50, 100, 333", bind=ADDRESS_BINDING)
    accs = c2.text_input("accelerations [g]", "5", key="dem_accs", help="e.g. 1, 5, 7.5",
                         bind=ADDRESS_BINDING)
    fills = c3.text_input("fills [%]", "50", key="dem_fills", bind=ADDRESS_BINDING,
                          help="e.g. 25, 50; empty: the specimen file's own count_per_cell or "
                               "fill_percent")
    specimen, refused = specimen_choice("dem", stores.path)
    c4, c5 = st.columns(2)
    if refused is not None:  # no fallback to the paper's coupon: nothing runs until fixed
        c4.text_input("particle material", "(the specimen file is refused)", disabled=True,
                      key="dem_material_refused")
    elif specimen is None:
        with c4:
            refuse_address_choices("dem_material", "particle material", PARTICLE_MATERIALS,
                                   PARTICLE_MATERIALS[0])
        material = c4.selectbox("particle material", PARTICLE_MATERIALS, key="dem_material",
                                bind=ADDRESS_BINDING)
    else:
        material = specimen.particles.material
        c4.text_input("particle material (the specimen's)", material, disabled=True,
                      key="dem_material_specimen")
    with c5:
        refuse_address_choices("dem_direction", "drive direction", DRIVE_DIRECTIONS,
                               DRIVE_DIRECTIONS[0])
    direction = c5.selectbox("drive direction", DRIVE_DIRECTIONS, key="dem_direction",
                             bind=ADDRESS_BINDING)
    numerical = {"dem_cells": str(defaults.DEM_CELLS), "dem_seed": str(defaults.DEM_SEED),
                 "dem_steady": "0"}
    # open where a setting is not its default: one a reload or a shared address brought back
    # (cells 1, say) was hidden under the closed expander and ran with the next Run
    changed = any(str(st.session_state.get(key, st.query_params.get(key, default))) != default
                  for key, default in numerical.items())
    with st.expander("numerical settings", expanded=changed):
        d1, d2, d3 = st.columns(3)
        # text read by pidcore (parse_count): the browser's number box made "1e3" steady
        # cycles 1 and "2,5" cells 25 without a word
        cells = d1.text_input("cells simulated", numerical["dem_cells"], key="dem_cells",
                              help=f"1 to {MAX_CELLS}", bind=ADDRESS_BINDING)
        seed = d2.text_input("seed", numerical["dem_seed"], key="dem_seed",
                             bind=ADDRESS_BINDING)
        steady = d3.text_input("steady cycles (0 = automatic)", numerical["dem_steady"],
                               key="dem_steady", bind=ADDRESS_BINDING)
    b1, b2 = st.columns(2)
    start = b1.button("Run", type="primary", key="dem_run", disabled=refused is not None,
                      help="off while the chosen specimen file is refused"
                      if refused is not None else None)
    b2.button("Cancel", key="dem_cancel", on_click=_cancel, args=(stores,),
              help="stops the running case within a second and drops the queued ones")
    if start and refused is not None:  # a click that raced the disabling
        st.session_state["dem_message"] = ("error", f"not run: {refused}")
    elif start:
        try:
            config = _config(cells, seed, steady)
            fill_values, fill_note = jobs.dem_fills(fills, specimen)
            cases = jobs.plan_dem_cases(
                parse_values(freqs, name="frequencies [Hz]"),
                parse_values(accs, name="accelerations [g]"),
                fill_values, material=material, direction=direction)
            jobs.check_dem_cases(cases, config, specimen)
        except PidcoreError as exc:
            st.session_state["dem_message"] = ("error", str(exc))
        else:
            created = _runner(stores).submit(cases, config, specimen)
            text = jobs.submitted_text(len(cases), created)
            st.session_state["dem_message"] = (
                "info", text if fill_note is None else f"{fill_note}; {text}")
    runner = _runner(stores)
    interrupted = sum(j.state == jobs.INTERRUPTED_STATE for j in runner.jobs())
    if interrupted:
        st.warning(f"{interrupted} job(s) were queued or running when the app stopped; nothing "
                   "of them was saved.")
        if st.button(f"Resubmit interrupted ({interrupted})", key="dem_resubmit"):
            created = runner.resubmit_interrupted()
            st.session_state["dem_message"] = ("info", jobs.submitted_text(interrupted,
                                                                            created))
            st.rerun()
    if runner.journal_problem:
        st.caption(f"Note: {runner.journal_problem}")
    message = st.session_state.get("dem_message")
    if message:
        getattr(st, message[0])(message[1])
    draw_polling(_job_table, stores, polling=_runner(stores).busy(),
                 every_s=REFRESH_S)
    try:
        stamp = stores.stamp()
        runs = state.store_listing("dem_runs", stamp, stores)
    except PidcoreError as exc:
        st.error(f"cannot read the DEM runs: {exc}")
        return
    if not runs.empty:
        st.markdown(f"**DEM runs in the stores** ({len(runs)})")
        table = jobs.dem_runs_table(runs)
        # the SDC as the report's cells write it (4 significant digits, not 4 decimals)
        st.dataframe(table, hide_index=True, width="stretch", key="dem_runs_table",
                     placeholder="", column_config={
                         column: st.column_config.NumberColumn(format=number_format)
                         for column, number_format in report_number_formats(table).items()})
        # listed as the store holds them, but said: Compare and Report leave them out
        design = state.design_runs(stamp, stores)
        if design:
            calibrations = sorted({c for keys in design.values() for c in keys})
            st.caption(f"{len(design)} of these run(s) are the design runs of calibration(s) "
                       f"{', '.join(calibrations)}: inputs of its fit, not "
                       "predictions of the specimen; the Compare and Report tabs leave them "
                       "out where another run of the specimen stands at their load case")
        unconverged = int(table["steady state"].str.startswith("NOT").sum())
        if unconverged:
            st.warning(f"{unconverged} run(s) did not converge (steady state NOT detected "
                       "before the transient cap): their SDC may include the transient; see "
                       "the column steady state.", icon="⚠️")
