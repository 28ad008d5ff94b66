"""Calibration page: fit DEM parameters to the store's measurements (:mod:`pidcore.calibrate`),
show the posterior and the measured-vs-predicted plot with bands, download the specimen."""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

import streamlit as st

from pidcore import defaults
from pidcore.app import state
from pidcore.app.calibration import (
    SAVED_FIGURE_CAPTION,
    calibration_api,
    calibration_digest,
    fittable_names,
    page_words,
    points_by_material,
    points_display,
    points_for_paper,
    points_for_specimen,
    points_needed,
    points_needed_text,
    runner_for,
    specimen_label,
)
from pidcore.app.tabs import (
    ADDRESS_BINDING,
    draw_polling,
    refuse_address_choices,
    specimen_choice,
)
from pidcore.loadcase import parse_count
from pidcore.specimen import calibrated_name, measured_specimen_name

#: Seconds between refreshes of the calibration's state while it runs.
REFRESH_S = 2.0


def _running(stores) -> bool:
    task = runner_for(stores.path).task
    return task is not None and task.state == "running"


def _task(stores, chosen: str, polling: bool) -> None:
    # a fragment (see draw_polling): rerun every REFRESH_S while the calibration runs
    task = runner_for(stores.path).task
    if task is None:
        return
    if polling and task.state != "running":  # it ended: draw the page again, without the timer
        st.rerun(scope="app")
    if task.specimen and task.specimen != chosen:  # the result stays; say whose it is
        st.caption(f"The calibration below is of {task.specimen}; {chosen} is chosen now.")
    if task.state == "running":
        st.info(f"calibrating {task.specimen} ({', '.join(task.fit)}, {task.n_points} load "
                f"case(s)): {task.progress_text()}; DEM runs are saved in the store as they "
                "finish")
        if task.runs_total:
            st.progress((task.runs_stored_before + task.runs_done) / task.runs_total)
        if task.cancel_requested:
            st.caption("cancelling: the running DEM run(s) are being stopped" if task.runs_total
                       else "cancelling: the design is being set up, no DEM run started yet")
        else:
            st.button("Cancel calibration", key="calibration_cancel",
                      on_click=runner_for(stores.path).cancel,
                      help="stops the running DEM runs at once (their partial results are "
                           "discarded); saved runs are kept and reused")
        return
    if task.state == "failed":
        st.error(f"calibration of {task.specimen} failed: {task.message}")
        return
    if task.state == "cancelled":
        st.warning(f"calibration of {task.specimen} cancelled: {task.message}")
        return
    st.success(f"calibrated {task.specimen} in {task.elapsed_s():.0f} s: {task.message}")
    out = task.outputs
    if "summary.md" in out:
        # its headings below the page's own (# and ## would dwarf the page title)
        # its notes in the page's terms (they advise command-line options)
        st.markdown(re.sub(r"^(#{1,3}) ", lambda m: "#" * (len(m[1]) + 3) + " ",
                           page_words(out["summary.md"].decode()), flags=re.MULTILINE))
    c1, c2 = st.columns(2)
    if "predictions.png" in out:
        c1.image(out["predictions.png"], caption="measured vs predicted SDC, 95 % bands")
    if "posterior_pairs.png" in out:
        c2.image(out["posterior_pairs.png"], caption="posterior")
    mimes = {".toml": "application/toml", ".json": "application/json", ".html": "text/html"}
    files = [n for n in sorted(out) if Path(n).suffix in mimes]
    for col, name in zip(st.columns(max(len(files), 1)), files, strict=False):
        # the calibrated specimen file saves under its specimen's name
        file_name = f"{calibrated_name(task.specimen)}.toml" \
            if name.endswith(".toml") and task.specimen else name
        label = "calibrated specimen (TOML)" if name.endswith(".toml") else name
        col.download_button(label, out[name], file_name=file_name,
                            mime=mimes[Path(name).suffix], key=f"calibration_{name}",
                            help=file_name)


def render(stores, stored) -> None:
    """The page (a clear "not available" state while the calibration library is missing).
    ``stored``: the store's calibrations as this draw read them
    (:func:`pidcore.app.calibration.read_store_calibrations`)."""

    st.subheader("Calibrate the DEM against measurements")
    api, reason = calibration_api()
    if api is None:
        st.info(f"Calibration is not available: {reason}.")
        return
    _interrupted(stores)
    _calibrate(stores, api)
    _saved(stored)  # also where nothing can be calibrated now (no measurement saved yet)


def _interrupted(stores) -> None:
    """The calibrations a stop of the app ended (as the DEM tab lists its interrupted
    jobs): what each was, and that the DEM runs it saved are kept for a re-run."""
    from pidcore.app.calibration import (
        dismiss_interrupted_calibrations,
        interrupted_calibrations,
    )

    found = interrupted_calibrations(stores.path)
    for calibration in found:
        st.warning(calibration.text(stores.path.name))
    if found and st.button(f"Dismiss interrupted ({len(found)})",
                           key="calibration_dismiss_interrupted",
                           help="its saved DEM runs stay in the store"):
        dismiss_interrupted_calibrations(stores.path)
        st.rerun()


def _calibrate(stores, api) -> None:
    """The form and the running or finished calibration (a word where nothing can be
    calibrated)."""
    from pidcore.errors import PidcoreError

    left_out: list[str] = []  # records saved as implausible: named, as the CLI names them
    try:
        points = api.measured_from_store(stores.path, left_out=left_out) \
            if stores.path.is_file() else []
    except PidcoreError as exc:
        st.info(f"Nothing to calibrate against: {exc}")
        return
    for note in left_out:
        st.caption(f"Note: {note}")
    if not points:
        st.info(f"{stores.path} holds no saved measurements with a load case yet: analyse "
                "files on the Analyse tab and Save them.")
        return
    chosen_label = _form(stores, api, points, left_out)
    # the running or finished calibration, whichever specimen is chosen now
    draw_polling(_task, stores, chosen_label, polling=_running(stores), every_s=REFRESH_S)


def _saved(stored) -> None:
    """The calibrations saved in the store (they outlive a restart of the app; the Compare
    and Report tabs use them, newest first), each file offered for download. ``stored``: as
    :func:`pidcore.app.calibration.read_store_calibrations` read them for this draw."""
    from pidcore.app.calibration import saved_calibrations_table

    # a damaged calibration is said, and does not hide the others
    if stored.listing is None and stored.damaged:
        st.caption(f"Calibrations of the store not shown: {stored.damaged[0]}")
        return
    for problem in stored.damaged:
        st.caption(f"Calibration of the store not shown: {problem}")
    saved = stored.readable
    if not saved:
        return
    st.markdown("**Calibrations saved in this store** (newest first; Compare and Report use "
                "them)")
    st.dataframe(saved_calibrations_table(listing=stored.listing), hide_index=True)
    keys = [c.store_key for c in saved]
    # a choice per set of saved calibrations: one saved since (the run just made) is offered
    # first, not the older one the box showed before
    listed = hashlib.sha256("\n".join(keys).encode()).hexdigest()[:12]
    key = st.selectbox("download the files of", keys, key=f"calibration_saved_key_{listed}")
    chosen = saved[keys.index(key)]
    # its bands as predictions.png draws them: only the run just made showed a figure
    st.image(state.calibration_png(calibration_digest(chosen), chosen),
             caption=f"{key}: {SAVED_FIGURE_CAPTION}")
    c1, c2 = st.columns(2)
    c1.download_button("calibration.json", chosen.document_text, file_name="calibration.json",
                       mime="application/json", key="calibration_saved_json")
    name = f"{calibrated_name(chosen.specimen_name)}.toml"
    c2.download_button("calibrated specimen (TOML)", chosen.specimen_text, file_name=name,
                       mime="application/toml", key="calibration_saved_toml", help=name)


def _form(stores, api, points: list, left_out: list[str]) -> str:
    """The specimen, cases and parameters to calibrate, and Run; returns the chosen
    specimen's name as the result below is compared with it. ``left_out``: the store's
    records left out as implausible; kept with the outputs' notes, with what the specimen
    leaves out."""
    from pidcore.errors import PidcoreError

    specimen, refused = specimen_choice("calibration", stores.path)
    if refused is not None:  # nothing runs, and no fallback to the paper's coupon
        st.info("Run is off until the specimen file is fixed or another is chosen.")
        return "a refused specimen file"
    chosen_label = specimen_label(specimen)
    cases_key = "calibration_cases"
    if specimen is not None:
        # read again for this file: a record saved without its file's hash joins its name's
        # tests only where they and this file are one file (as calibrate --specimen reads)
        again: list[str] = []
        try:
            points = api.measured_from_store(stores.path, left_out=again, specimen=specimen)
        except PidcoreError as exc:
            st.info(f"Nothing to calibrate against: {exc}")
            return chosen_label
        for said in again:
            if said not in left_out:
                st.caption(f"Note: {said}")
        left_out = again
        points, note = points_for_specimen(points, specimen)
        if note:
            st.caption(note)
            left_out = [*left_out, note]
        if not points:
            # named as its tests are saved and its DEM runs labelled: a file taking the paper
            # coupon's name with other content is "paper_coupon [f849cf]", not the paper's
            st.info(f"No saved measurement is of specimen {measured_specimen_name(specimen)} "
                    f"({specimen.particles.material} particles) or of an unnamed specimen of "
                    "them.")
            return chosen_label
        cases_key = f"calibration_cases_{specimen.hash[:12]}"  # its own choice of cases
    if specimen is None:  # measurements named after another specimen are not the paper's
        points, note = points_for_paper(points)
        if note:
            st.caption(note)
            left_out = [*left_out, note]
        if not points:
            return chosen_label
    by_material = points_by_material(points)
    if specimen is None:  # the paper's coupon holds table particles only
        from pidcore.constants import PARTICLE_MATERIALS

        own = [m for m in by_material if m not in PARTICLE_MATERIALS]
        if own:
            st.caption(f"Measurements of {', '.join(own)} particles are calibrated with their "
                       "specimen file: choose it above.")
        by_material = {m: p for m, p in by_material.items() if m in PARTICLE_MATERIALS}
        if not by_material:
            return chosen_label
        points = [p for group in by_material.values() for p in group]
    if len(by_material) > 1:  # one specimen at a time: its particle material first
        refuse_address_choices("calibration_material", "particle material", list(by_material),
                               next(iter(by_material)))
        material = st.selectbox("particle material (one calibration per material)",
                                list(by_material), key="calibration_material",
                                bind=ADDRESS_BINDING)
        points = by_material[material]
        cases_key = f"calibration_cases_{material}"  # each material keeps its own choice
    labels = [p.label() for p in points]
    # a choice per set of saved cases: cases saved since are chosen, not left out unseen
    cases_key += "_" + hashlib.sha256("\n".join(labels).encode()).hexdigest()[:12]
    refuse_address_choices(cases_key, "measured load cases", labels, labels)
    chosen_cases = st.multiselect("measured load cases to calibrate against (from the store)",
                                  labels, default=labels, key=cases_key, bind=ADDRESS_BINDING)
    points = [p for p, label in zip(points, labels, strict=True) if label in chosen_cases]
    st.dataframe(points_display(points), hide_index=True, width="stretch",
                 key="calibration_points", placeholder="")
    c1, c2, c3 = st.columns(3)
    fittable = fittable_names(api)
    default_fit = [n for n in api.parse_fit(None) if n in fittable]
    with c1:
        refuse_address_choices("calibration_fit", "parameters to fit", fittable, default_fit)
    # the form's fields are bound to the page address: a reload keeps them (ADDRESS_BINDING)
    chosen = c1.multiselect("parameters to fit", fittable, default=default_fit,
                            key="calibration_fit", bind=ADDRESS_BINDING)
    extra = c1.text_input("more parameters (specimen fields, comma-separated)", "",
                          key="calibration_fit_extra", bind=ADDRESS_BINDING,
                          help="e.g. friction, restitution (as `pidcore calibrate --fit`)")
    # text read by pidcore (parse_count): the browser's number box made "2,5" 25 cells
    cells = c2.text_input("cells per DEM run", "4", key="calibration_cells",
                          help=f"2 to {defaults.APP_MAX_DEM_CELLS}", bind=ADDRESS_BINDING)
    design = c3.text_input("design points (0 = default)", "0", key="calibration_design",
                           help=f"at most {defaults.CALIBRATION_MAX_DESIGN_SIZE}: each is one "
                                "DEM run per load case", bind=ADDRESS_BINDING)
    wanted = [*chosen, *(n.strip() for n in extra.split(",") if n.strip())]
    too_few = bool(wanted) and len(points) < points_needed(wanted)
    if too_few:
        st.caption(points_needed_text(len(points), wanted))
    if st.button("Run calibration", type="primary", key="calibration_run",
                 disabled=not points or not wanted or too_few):
        try:
            fit = api.parse_fit(wanted, specimen)
            n_cells = parse_count(cells, name="cells per DEM run", minimum=2,
                                  maximum=defaults.APP_MAX_DEM_CELLS)
            n_design = parse_count(design, name="design points (0 = default)",
                                   maximum=defaults.CALIBRATION_MAX_DESIGN_SIZE)
            started = runner_for(stores.path).start(api, points, fit=fit, cells=n_cells,
                                                    design_size=n_design or None,
                                                    specimen=specimen, notes=left_out)
        except PidcoreError as exc:
            st.error(page_words(str(exc)))
        else:
            if started is None:
                st.warning("a calibration is running already; wait for it to finish")
    return chosen_label
