"""Compare page: every saved record of the store (and this session's unsaved ones), filtered,
per load case: the headline (like-for-like measured SDC vs our DEM), SDC against fill, loops,
spectrum."""

from __future__ import annotations

import math

import streamlit as st

from pidcore.app import state, uploads, workbench
from pidcore.app.tabs import (
    ADDRESS_BINDING,
    address_choice,
    refuse_address_choices,
    refuse_address_flag,
)
from pidcore.app.vocabulary import page_terms
from pidcore.calibrate.prediction import band_text, sdc_text
from pidcore.compare.case import equivalent_dampers
from pidcore.constants import BAND_VERDICTS
from pidcore.report.case_sheet import (
    CalibratedCase,
    case_pdf,
    case_sheet_stem,
    members_calibrated_case,
)
from pidcore.report.case_view import case_title, group_entries, matched_specimens


def _entries(stores, session_files):
    """Saved entries (filtered by the user) + this session's unsaved ones."""
    from pidcore.compare.case import MeasuredEntry, unique_entries
    from pidcore.store.listing import filter_analyses

    stamp = stores.stamp()
    saved = state.store_listing("analyses", stamp, stores)
    listing = saved  # every saved record decides which file a hashless one is of
    if not saved.empty:
        # bound to the page address as the other tabs' fields (ADDRESS_BINDING): a reload
        # showed every record again; a value the store no longer holds is refused in one line
        f1, f2, f3 = st.columns(3)
        specimen_names = sorted(set(saved["specimen"]))
        with f1:
            refuse_address_choices("filter_specimen", "specimen",
                                   [_specimen_option(s) for s in specimen_names], [])
        specimens = f1.multiselect("specimen", specimen_names, key="filter_specimen",
                                   format_func=_specimen_option, bind=ADDRESS_BINDING)
        dates = sorted(set(saved["date"]), reverse=True)
        with f2:
            refuse_address_choices("filter_date", "date saved", dates, [])
        dates = f2.multiselect("date saved", dates, key="filter_date", bind=ADDRESS_BINDING)
        files = sorted(set(saved["file"]))
        with f3:
            refuse_address_choices("filter_file", "file", files, [])
        files = f3.multiselect("file", files, key="filter_file", bind=ADDRESS_BINDING)
        saved = filter_analyses(saved, specimens=specimens, dates=dates, files=files)
    # a record of a specimen file at hand is judged against that file's SDC bound, as
    # `pidcore analyze --specimen FILE` judged it
    from pidcore.app.tabs.analyse import _known_specimens

    known = _known_specimens(stores) if not saved.empty else []
    entries = list(state.saved_entries(tuple(saved["key"]) if not saved.empty else (), stamp,
                                       stores, saved, tuple(s.hash for s in known),
                                       known)) if not saved.empty else []
    refuse_address_flag("include_session", "include this session's unsaved analyses",
                        default=True)
    include = st.checkbox("include this session's unsaved analyses", value=True,
                          key="include_session", bind=ADDRESS_BINDING)
    if include:
        # a file stating no fill has no load case to be compared in, as its saved record
        unplaced = uploads.unplaced_note(session_files)
        if unplaced:
            st.caption(unplaced)
        entries += [MeasuredEntry.from_record(f.record, f.load_case, specimen=f.specimen,
                                              options=f.options,
                                              specimen_sha256=f.specimen_sha256,
                                              sdc_bound=f.sdc_bound)
                    for f in session_files if f.load_case is not None]
    # one data set counted once (a saved file uploaded again, or under another name)
    files = [e.file for e in entries]
    entries, notes = unique_entries(entries)
    for note in notes:  # a settings change named as the table's columns name it
        st.caption(uploads.app_words(note, names=files))
    # a record saved without its file's hash is grouped as calibrate and report group it
    return matched_specimens(entries, listing)


def _specimen_option(name: str) -> str:
    return name or "(none named)"


def _group_key(members) -> str:
    return "|".join(f"{e.key}:{e.load_case.key}:{e.specimen}:{e.specimen_sha256}:{e.sdc!r}"
                    for e in members)


def _calibrated(shown: CalibratedCase, comp, head) -> None:
    """The calibrated DEM's Eq. 11 SDC with its 95 % band beside the raw DEM and the measured
    Eq. 11 SDC (like for like: the calibration predicts what a shaker test of the DEM would
    measure with Eq. 11), and the verdict of the report's row (:func:`pidcore.report.
    case_sheet.calibrated_case`)."""
    for said in shown.said:
        st.caption(said)
    if shown.label:
        st.markdown("**calibrated DEM** (" + shown.label + ")")
    j = shown.judgement
    if j is None:
        return
    c1, c2, c3 = st.columns(3)
    c1.metric("SDC measured, Eq. 11 [-]",
              uploads.format_sdc(comp.measured_sdc, comp.measured_stderr))
    # an SDC as the report's cell and the band beside it write it (sdc_text, 4 significant
    # digits): 4 decimals showed the calibrated SDC the report writes 0.08264 as 0.0826
    c2.metric("SDC DEM, raw [-]", sdc_text(head.dem) if math.isfinite(head.dem) else "none")
    c3.metric("SDC calibrated DEM, Eq. 11 [-]", sdc_text(j.sdc),
              help=f"95 % band {band_text(j.low, j.high)}")
    yes, no, _, uninformative = BAND_VERDICTS
    # an uninformative band's reason says the verdict ("uninformative: ..."); a band not
    # compared says why in brackets
    verdict = (j.reason if j.verdict == uninformative else
               {yes: "inside", no: "outside"}.get(j.verdict, j.verdict)
               + (f" ({j.reason})" if j.reason else ""))
    if j.before_baseline:
        verdict += f" ({j.before_baseline})"
    # the report's format: its uninformative reason below writes this band "0 .. 16.91"
    st.caption(f"calibrated 95 % band {band_text(j.low, j.high)} [-]"
               + (f" ({j.widened})" if j.widened else "")
               + f"; the measured Eq. 11 SDC is {verdict}.")
    if j.cut:  # a bound no measurement can take is not shown without a word
        st.caption(j.cut + ".")


def render(stores, session_files: list, calibrations: list) -> None:
    """The page. ``calibrations``: :func:`pidcore.app.calibration.available_calibrations`'s
    [(calibration or None, label)], read once per script run for this tab and the Report
    tab."""
    from pidcore.errors import PidcoreError

    st.subheader("Compare per load case")
    try:
        entries = _entries(stores, session_files)
    except PidcoreError as exc:
        st.error(f"cannot read the store: {exc}")
        return
    if not entries:
        st.info(f"No analysed records: {stores.path} holds no saved analyses with a load case "
                "(or the filters exclude them), and nothing analysed in this session has one. "
                "Upload and save measurements on the Analyse tab.")
        return
    groups = group_entries(entries)
    # The choice is the group's load case, not its position: saving re-sorts the groups, and a
    # position would then show another load case's numbers under the chosen one's label. The
    # page address keeps it by the store's load-case key and the specimen
    # (workbench.case_address), not by the label, which counts the files: a file saved since
    # made a reload refuse a case that is still there.
    by_name = {workbench.case_address(entries, g): g for g in groups}
    if len(by_name) < len(groups):  # two groups whose keys agree: apart by position
        by_name = {f"{workbench.case_address(entries, g)} #{n}" if n else
                   workbench.case_address(entries, g): g for n, g in enumerate(groups)}
    labels = {name: case_title(entries, g) for name, g in by_name.items()}
    names = list(by_name)

    def resolve(address: str) -> str | None:
        found = workbench.case_at_address(address, entries, list(by_name.values()))
        return None if found is None else names[found]

    choice = address_choice("compare_case", "load case", labels, resolve,
                            offered=f"among the {len(groups)} load case(s) of the records "
                                    "shown")
    members = [entries[i] for i in by_name[choice]]
    stamp = stores.stamp()
    try:
        view = state.case_view(_group_key(members), stamp, members, stores)
    except PidcoreError as exc:
        st.error(f"cannot compare: {page_terms(str(exc))}")
        return
    comp, head = view["comparison"], view["headline"]
    aligned = comp.aligned
    # the DEM number names its specimen: runs of another specimen are never met
    st.markdown("### " + workbench.headline_heading(head, view["dem_specimen"]))
    if head.basis:  # what σ and the interval are: in the heading it wrapped the line
        st.caption(head.basis)
    if view["dem_refused"]:
        st.warning(f"No DEM value: {view['dem_refused']}.", icon="⚠️")
    if view["dem_warning"] and math.isfinite(head.dem):
        st.warning(view["dem_warning"], icon="⚠️")
    st.caption(f"Measured SDC: {head.measured_kind}"
               + (" (energy per cycle over the DEM case's m_c a²/(2ω²), as our DEM SDC is "
                  "defined)" if head.measured_kind.startswith("Eq. 10") else "")
               + f". DEM alignment: {aligned.status}. {aligned.message}")
    dampers = equivalent_dampers(comp)
    if dampers:  # the FEM number of `pidcore model damper` at this case
        st.caption("equivalent viscous damper of the whole coupon c_eq = SDC m_c ω/(2π) (as "
                   "`pidcore model damper`'s c_eq_per_coupon): "
                   + " · ".join(f"{name} **{c:.4g} N s/m**" for name, c in dampers.items())
                   + (f" (m_c = {comp.aligned.grid_case.vibrated_mass_kg:.4g} kg of the DEM "
                      "case)" if comp.aligned.grid_case is not None else
                      f" (m_c = {comp.vibrated_mass_kg:.4g} kg a DEM run at this fill would "
                      "have, as the report takes it; the DEM's SDC is the interpolated one)"))
    if len(members) > 1:
        if math.isfinite(comp.chi2_dof) and comp.chi2_dof > 3:
            st.warning(f"The {len(members)} pooled files scatter more than their errors allow "
                       f"(χ²/dof = {comp.chi2_dof:.2g}): different set-ups or corrections? "
                       "Check the per-file settings.", icon="⚠️")
        else:
            st.caption(f"{len(members)} files pooled; consistent within their errors "
                       f"(χ²/dof = {comp.chi2_dof:.2g})")
    with st.expander("details: Eq. 11 SDC and the paper", expanded=False):
        c1, c2, c3 = st.columns(3)
        c1.metric("SDC measured, Eq. 11 ± stderr [-]",
                  uploads.format_sdc(comp.measured_sdc, comp.measured_stderr),
                  help="energy per cycle over the reactive energy Im(P)/w")
        paper_metrics, paper_caption = workbench.paper_details(comp, members[0].specimen)
        for column, (label, value) in zip((c2, c3), paper_metrics.items(), strict=False):
            column.metric(label, value)
        if paper_caption:
            st.caption(paper_caption)
    # the rule `pidcore report --case-sheets` judges its sheets by
    calibrated = members_calibrated_case(calibrations, comp, members)
    _calibrated(calibrated, comp, head)
    for note in view["notes"]:
        st.caption(f"note: {note}")
    left, right = st.columns(2)
    left.vega_lite_chart(spec=view["sdc_spec"], key="sdc_chart", width="stretch")
    right.vega_lite_chart(spec=view["loop_spec"], key="loop_chart", width="stretch")
    if view["energies"]:
        analysed = view.get("energies_analysed", {})
        # a baseline loss factor taken off: the analysis's energy (`pidcore analyze` prints
        # it, Eq. 10 uses it) is the loop's area less the empty coupon's share
        st.markdown("energy per cycle (loop area): " + " · ".join(
            f"{label}: **{energy:.4e} J**" + (
                f" (**{analysed[label]:.4e} J** with the empty coupon's damping taken off, as "
                "`pidcore analyze` prints it)" if label in analysed else "")
            for label, energy in view["energies"].items()))
    # the two fixed-width spectra (~600 px) overflowed half a page into the table beside them
    st.vega_lite_chart(spec=view["spectrum_spec"], key="spectrum_chart")
    # in the chart's unit: harmonics of a few µm/s read as 0.0000 in m/s
    spectrum = view["spectrum"]
    st.dataframe(spectrum.drop(columns="velocity amplitude [m/s]").assign(
        **{"velocity amplitude [mm/s]": spectrum["velocity amplitude [m/s]"] * 1e3}),
        hide_index=True, width="stretch")
    st.dataframe(comp.measured, hide_index=True, width="stretch", key="compare_measured",
                 placeholder="")
    if st.button("PDF of this load case (plots and corrections)", key="case_pdf"):
        # keyed by the calibration's verdict too: another calibration chosen since made the
        # sheet of the same files another one
        st.session_state["case_pdf_bytes"] = ((_group_key(members), calibrated), case_pdf(
            view, title=labels[choice], calibrated=calibrated))
    made = st.session_state.get("case_pdf_bytes")
    if made and made[0] == (_group_key(members), calibrated):
        st.download_button("Download the load case PDF", made[1], mime="application/pdf",
                           file_name=f"pidcore_{case_sheet_stem(comp, members)}.pdf",
                           key="case_pdf_download")
    # Warm the cache for the other load cases after this one is on screen, so that switching
    # to any of them is a cache hit.
    warmed = st.session_state.setdefault("_compare_warmed", set())
    for other, indices in by_name.items():
        rest = [entries[i] for i in indices]
        key = (_group_key(rest), stamp)
        if other == choice or key in warmed:
            continue
        try:
            state.case_view(key[0], stamp, rest, stores)
        except PidcoreError:
            pass  # shown when that case is chosen
        warmed.add(key)
