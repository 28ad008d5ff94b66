"""Report page: the Table 3-style table of the store and its downloads."""

from __future__ import annotations

import streamlit as st

from pidcore.app import state
from pidcore.app.report_builds import start_report_build
from pidcore.app.tabs import (
    ADDRESS_BINDING,
    draw_polling,
    refuse_address_choices,
    refuse_address_flag,
)
from pidcore.app.vocabulary import page_terms

#: Seconds between refreshes of the report build's state while it runs.
REFRESH_S = 1.0

#: Said where the report files built in this session are of another state of the store or
#: other choices than the table shown.
STALE_BUILD_TEXT = ("The report files built before are not offered: the store or the choices "
                    "above changed since; build them again for this table.")

#: Download buttons' labels of the report files that are not their format's name in capitals.
DOWNLOAD_LABELS = {"csv_provenance": "CSV notes", "zip": "ZIP (all, with figures)"}

#: The Report tab's default specimen: the paper's coupon, as ``pidcore report`` without
#: ``--specimen``.
DEFAULT_SPECIMEN = "paper_coupon (the default)"


def render(stores, calibrations: list) -> None:
    """The page. ``calibrations``: [(calibration or None, label)], as the Compare tab's; the
    calibrated columns show the one chosen (the first by default)."""
    from pidcore.app.calibration import calibration_digest, default_calibration_index
    from pidcore.app.workbench import report_display, report_number_formats
    from pidcore.compare.specimens import run_specimens
    from pidcore.errors import PidcoreError
    from pidcore.report.downloads import report_files
    from pidcore.specimen import PAPER_SPECIMEN_NAME

    st.subheader("Report (Table 3 style)")
    stamp = stores.stamp()
    try:
        saved = state.store_listing("analyses", stamp, stores)
    except PidcoreError as exc:
        st.error(f"cannot read the store: {exc}")
        return
    c1, c2 = st.columns([2, 1])  # room for the checkbox's label at 1280-1500 px
    files = sorted(set(saved["file"])) if not saved.empty else []
    # the choices are bound to the page address, as the DEM and Calibrate forms: a reload
    # keeps them (ADDRESS_BINDING)
    with c1:
        refuse_address_choices("report_filter_files", "measurements in the report", files, [])
    chosen = c1.multiselect("measurements in the report (all when none chosen)", files,
                            key="report_filter_files", bind=ADDRESS_BINDING)
    with c2:
        refuse_address_flag("report_pool", "pool DEM settings")
    pool = c2.checkbox("pool DEM settings", value=False, key="report_pool",
                       bind=ADDRESS_BINDING,
                       help="one row per load case and specimen (default: a row per DEM "
                            "setting too); tests of different specimens are never pooled")
    keys = (tuple(saved[saved["file"].isin(chosen)]["key"]) if chosen and not saved.empty
            else None)
    # the DEM runs of one specimen, as `pidcore report [--specimen FILE]` compares them; the
    # others are left out and named in the notes
    try:
        others = run_specimens(state.store_listing("dem_runs", stamp, stores))
    except PidcoreError as exc:
        st.error(f"cannot read the store: {exc}")
        return
    specimen_label = DEFAULT_SPECIMEN
    if others:
        options = [DEFAULT_SPECIMEN, *others]
        refuse_address_choices("report_specimen", "specimen of the DEM runs compared",
                               options, DEFAULT_SPECIMEN)
        specimen_label = st.selectbox("specimen of the DEM runs compared", options,
                                      key="report_specimen", bind=ADDRESS_BINDING,
                                      help="as `pidcore report --specimen FILE`: the runs of "
                                           "other specimens are left out, the notes name them")
    specimen = others.get(specimen_label)
    # the calibration the Compare tab shows, in the same columns as `pidcore report
    # --calibration`: by default the newest that speaks for the specimen reported
    usable = [(c, text) for c, text in calibrations if c is not None]
    calibration, label = usable[0] if usable else calibrations[0]
    if len(usable) > 1:  # e.g. this store's steel calibration and the paper's bundled one
        labels = [text for _, text in usable]
        default = default_calibration_index(
            usable, PAPER_SPECIMEN_NAME if specimen is None else specimen.name, specimen)
        # a choice per specimen reported: another specimen starts at its own default
        chosen_label = st.selectbox("calibration for the calibrated DEM columns", labels,
                                    index=default,
                                    key=f"report_calibration_{specimen_label}")
        calibration, label = usable[labels.index(chosen_label)] \
            if chosen_label in labels else usable[default]
    digest = calibration_digest(calibration)
    try:
        table = state.report_table(stamp, pool, keys, digest, specimen_label, stores,
                                   calibration, specimen)
    except PidcoreError as exc:
        st.error(f"cannot read the store: {exc}")
        return
    if table.empty:
        st.info(f"{stores.path} holds no saved analyses with a load case and no DEM runs "
                f"of this specimen yet: save analysed files (tab Analyse) or run DEM cases "
                "(tab DEM).")
        for note in table.attrs.get("notes", []):  # e.g. other specimens' runs left out
            st.caption(f"note: {page_terms(note)}")
        return
    st.caption(f"calibrated DEM columns: {label}" if calibration is not None else label)
    # cells empty by design (measured columns of a DEM-only row, DEM columns of a measured-only
    # one) are empty, not the grid's greyed "None"; the two results that can lack a value say
    # why (report_display)
    shown = report_display(table)
    st.dataframe(shown, hide_index=True, key="report_table", width="stretch", placeholder="",
                 column_config={column: st.column_config.NumberColumn(format=number_format)
                                for column, number_format in report_number_formats(shown).items()})
    # the notes in the page's terms too (report_display's): "pool=True" is the checkbox here
    for note in shown.attrs.get("notes", []):
        st.caption(f"note: {note}")
    made = (stamp, pool, keys, digest, specimen_label)
    if st.button("Build report files (CSV, Markdown, HTML, LaTeX, PDF)", key="build_report"):
        # built in the background: the page stays usable, and a click elsewhere meanwhile
        # does not stop the build
        st.session_state["report_build"] = start_report_build(
            made, lambda: report_files(stores.path, stores.dem_reference, pool=pool,
                                       analysis_keys=None if keys is None else list(keys),
                                       calibration=calibration, specimen=specimen,
                                       wording=page_terms),
            st.session_state.get("report_build"))
    build = st.session_state.get("report_build")
    if build is not None and build.of == made:  # files of an older state are not offered
        draw_polling(_build_state, build, polling=build.state == "running", every_s=REFRESH_S)
    elif build is not None and build.state == "done":
        # the downloads vanished without a word when a DEM job or a save changed the store
        st.caption(STALE_BUILD_TEXT)


def _build_state(build, polling: bool) -> None:
    # a fragment (see draw_polling): rerun every REFRESH_S while the report is being built
    if build.state == "running":
        st.info(f"Writing the report ... {build.elapsed_s():.0f} s")
        return
    if polling:  # it ended: draw the page again, without the timer
        st.rerun(scope="app")
    if build.state == "failed":
        st.error(f"no report: {page_terms(build.message)}")
        return
    cols = st.columns(len(build.files))
    for col, (fmt, (name, data, mime)) in zip(cols, build.files.items(), strict=True):
        label = DOWNLOAD_LABELS.get(fmt, fmt.upper())
        col.download_button(label, data, file_name=name, mime=mime, key=f"download_{fmt}")
    st.caption("report.csv holds only the table (pandas.read_csv reads it as is); "
               "provenance and notes are in the CSV notes file and in the other formats. "
               "MD and TEX link their figure in figures/: the ZIP holds them together.")
