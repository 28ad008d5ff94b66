"""Layout of the pidcore Streamlit app; all logic is in :mod:`pidcore.app_support`.

Four tabs: Analyse (upload, channel mapping, corrections, load case, results, Save), Compare
(per load case: SDC against DEM, model and paper; force-displacement loops; harmonic spectrum),
DEM (run a load case or a small sweep, progress and cancel, saved per case) and Report
(Table 3-style table and downloads). Tabs instead of separate pages: every tab is rendered on
each run, so uploads and the per-file choices live as long as the session without copying
widget state around.
"""

from __future__ import annotations

import numpy as np
import streamlit as st

from pidcore import __version__, app_support, defaults
from pidcore._app import charts
from pidcore.constants import DRIVE_DIRECTIONS, PARTICLE_MATERIALS

_CACHE_ENTRIES = 64
#: Parsed uploads kept in memory (each can be up to the upload limit).
_PARSED_ENTRIES = 16


# --- cached computations (keyed by content hash + options; the bytes are not hashed) ---------
# cache_resource, not cache_data: measurements can be large, and cache_data would unpickle a
# copy on every hit. The records are frozen and never mutated, so sharing them is safe.

@st.cache_resource(max_entries=_PARSED_ENTRIES, show_spinner="Reading file ...")
def _parsed(sha256: str, name: str, sample_rate_hz: float | None, _upload):
    return app_support.parse_upload(name, _upload.getvalue(), sample_rate_hz=sample_rate_hz)


@st.cache_resource(max_entries=4 * _PARSED_ENTRIES, show_spinner="Analysing ...")
def _analysed(sha256: str, name: str, sample_rate_hz: float | None, options_json: str,
              _upload):
    parsed = _parsed(sha256, name, sample_rate_hz, _upload)
    return app_support.analyze_parsed(parsed, app_support.options_from_json(options_json))


def _upload_sha256(upload) -> str:
    """Content hash of an upload, computed once per uploaded file (hashing 200 MB takes
    a noticeable fraction of a second; reruns must not repeat it)."""
    known = st.session_state.setdefault("_upload_sha256", {})
    file_id = getattr(upload, "file_id", None)
    if file_id is None or file_id not in known:
        digest = app_support.content_sha256(upload.getvalue())
        if file_id is None:
            return digest
        known[file_id] = digest
    return known[file_id]


@st.cache_data(max_entries=_CACHE_ENTRIES, show_spinner=False)
def _comparison(group_key: str, stamp: tuple, _records, _paper, _stores):
    # Keyed by the records' content and the stores' state; the arguments themselves unhashed.
    dem_runs = store_listing("dem_runs", stamp, _stores)
    comparison = app_support.compare_case(_records, dem_runs, _paper)
    loops = [app_support.measured_loop(r) for r, _ in _records]
    loops += app_support.dem_loops(_stores.path, comparison, _stores.dem_reference)
    spectrum = app_support.spectrum_table(_records[0][0])
    # Vega-Lite specs built once per case here: a revisit only sends them. Schema validation
    # (slow: ~50 ms a chart) is left to the tests, which validate every chart.
    return {
        "comparison": comparison,
        "loops": [(loop.label, loop.energy_per_cycle_j) for loop in loops],
        "spectrum": spectrum,
        "sdc_spec": charts.sdc_chart(app_support.sdc_chart_data(comparison)).to_dict(
            validate=False),
        "loop_spec": charts.loop_chart(app_support.loop_chart_data(loops)).to_dict(
            validate=False),
        "spectrum_spec": charts.spectrum_chart(spectrum).to_dict(validate=False),
    }


@st.cache_data(max_entries=8, show_spinner=False)
def store_listing(what: str, stamp: tuple, _stores):
    """Store listings, re-read only when a store file changed (``AppStores.stamp``)."""
    if what == "dem_runs":
        return app_support.list_dem_runs(_stores.path, _stores.dem_reference)
    if what == "report_table":
        return app_support.report_table(_stores.path, _stores.dem_reference)
    raise ValueError(what)


@st.cache_data(show_spinner=False)
def _paper_table():
    return app_support.paper_table()


# --- pages -------------------------------------------------------------------------------------

def _corrections():
    from pidcore.measure import AnalysisOptions

    with st.expander("Corrections and options", expanded=False):
        c1, c2, c3, c4 = st.columns(4)
        delay_us = c1.number_input("vibrometer delay [µs]", value=0.0, step=1.0,
                                   key="delay_us",
                                   help="output delay of the laser vibrometer, removed from "
                                        "the velocity channel")
        mass_g = c2.number_input("mass below force gauge [g]", value=0.0, min_value=0.0,
                                 step=0.1, key="mass_g",
                                 help="mass between force gauge and coupon (mass cancellation)")
        baseline = c3.number_input("empty-coupon loss factor [-]", value=0.0, min_value=0.0,
                                   step=0.0001, format="%.5f", key="baseline_eta",
                                   help="loss factor of the empty coupon, subtracted")
        rate = c4.number_input("sample rate if no time column [Hz]", value=0.0, min_value=0.0,
                               step=1000.0, key="sample_rate",
                               help="only for CSV/TXT files without a time column; 0 = none")
    return AnalysisOptions(velocity_delay_s=delay_us * 1e-6,
                           mass_below_gauge_kg=mass_g * 1e-3,
                           baseline_loss_factor=baseline,
                           sample_rate_hz=rate if rate > 0 else None)


def _file_panel(index: int, upload, base_options, sidecar):
    """Mapping, load case and results of one file; returns (record, load case) or None."""
    from pidcore.errors import PidcoreError

    name = upload.name
    with st.container(border=True):
        size = (f"{upload.size / 2**20:.1f} MB" if upload.size >= 2**20
                else f"{upload.size / 1024:.0f} kB" if upload.size >= 1024
                else f"{upload.size} bytes")
        st.markdown(f"**{name}** · {size}")
        try:
            app_support.check_upload_size(name, upload.size)
        except PidcoreError as exc:
            st.error(str(exc))
            return None
        sha = _upload_sha256(upload)
        wkey = f"{sha[:12]}_{index}"
        parsed = _parsed(sha, name, base_options.sample_rate_hz, upload)
        if parsed.error is not None:
            st.error(parsed.error)
            return None
        ch = parsed.channels
        c1, c2, c3 = st.columns(3)
        roles = {}
        for col, role in zip((c1, c2, c3), ("force", "velocity", "acceleration"), strict=True):
            opts = ch.options(role)
            roles[role] = col.selectbox(f"{role} channel", opts, index=ch.default_index(role),
                                        key=f"{role}_{wkey}")
        stated = app_support.stated_case(name, sidecar)
        c4, c5, c6 = st.columns(3)
        fill = c4.number_input("fill (packing ratio) [%]", min_value=0.1, max_value=100.0,
                               value=float(stated.fill_percent), step=5.0,
                               key=f"fill_{wkey}")
        materials = list(PARTICLE_MATERIALS)
        material = c5.selectbox("particle material", materials,
                                index=materials.index(stated.material),
                                key=f"material_{wkey}")
        directions = list(DRIVE_DIRECTIONS)
        direction = c6.selectbox("drive direction", directions,
                                 index=directions.index(stated.direction),
                                 key=f"direction_{wkey}")
        st.caption(f"load case stated by {stated.origin}")
        options = app_support.role_options(base_options, **roles)
        outcome = _analysed(sha, name, options.sample_rate_hz,
                            app_support.options_to_json(options), upload)
        if outcome.error is not None:
            st.error(outcome.error)
            return None
        record = outcome.record
        try:
            case = app_support.load_case_of(record, fill_percent=fill, material=material,
                                            direction=direction)
        except PidcoreError as exc:
            st.error(f"{name}: {exc}")
            return None
        a = record.analysis
        m1, m2, m3, m4 = st.columns(4)
        m1.metric("frequency [Hz]", f"{a.frequency_hz:.3f}")
        m2.metric("acceleration [g]", f"{a.acceleration_g:.3f}")
        m3.metric("loss factor [-]", f"{a.loss_factor:.5f}")
        m4.metric("SDC ± stderr [-]", app_support.format_sdc(a.sdc, a.sdc_stderr))
        for note in record.notes:
            st.caption(f"note: {note}")
        return record, case


def analyse_page(stores) -> list:
    st.subheader("Upload & analyse")
    st.caption(f"UFF58 (ASCII or binary), CSV/TXT, MAT and HDF5 exports; several at once. "
               f"Upload limit: {defaults.APP_MAX_UPLOAD_MB} MB per file. Files are parsed, "
               "never executed; nothing is stored until you press Save.")
    uploads = st.file_uploader("shaker-test exports", accept_multiple_files=True,
                               key="uploads", max_upload_size=defaults.APP_MAX_UPLOAD_MB)
    base = _corrections()
    sidecar = None
    measurements = []
    for upload in uploads or []:
        if not app_support.is_sidecar_upload(upload.name):
            measurements.append(upload)
            continue
        from pidcore.errors import PidcoreError

        try:
            sidecar = app_support.read_sidecar_upload(upload.getvalue())
            st.info(f"{upload.name}: load cases of {len(sidecar)} file(s) stated")
        except PidcoreError as exc:
            st.error(str(exc))
    analysed = []
    for i, upload in enumerate(measurements):
        result = _file_panel(i, upload, base, sidecar)
        if result is not None:
            analysed.append(result)
    if analysed:
        st.markdown("**Results**")
        st.dataframe(app_support.results_table(analysed), hide_index=True, key="results_table")
    if st.button(f"Save {len(analysed)} record(s) to the store", disabled=not analysed,
                 type="primary", key="save"):
        from pidcore.errors import PidcoreError

        try:
            keys = app_support.save_records(stores.path, analysed, base)
        except PidcoreError as exc:
            st.error(f"not saved: {exc}")
        else:
            st.success(f"saved {len(keys)} analysis record(s) to {stores.path}")
    return analysed


def _group_key(members) -> str:
    """Cache key of a load case's records: content, load case, mapping and result."""
    return "|".join(f"{r.measurement.sha256}:{c.key}:{r.channels_used}:{r.analysis.sdc!r}"
                    for r, c in members)


def compare_page(stores, analysed: list) -> None:
    st.subheader("Compare per load case")
    if not analysed:
        st.info("Upload and analyse measurements first (tab Analyse); this tab compares them "
                "with our DEM runs in the store, the pchip model and the paper's Table 3.")
        return
    cases = [case for _, case in analysed]
    groups = app_support.group_load_cases(cases)
    labels = [f"{cases[g[0]].label()}, {cases[g[0]].material}, {cases[g[0]].direction} "
              f"({len(g)} file(s))" for g in groups]
    choice = st.selectbox("load case", range(len(groups)), format_func=labels.__getitem__,
                          key="compare_case")
    members = [analysed[i] for i in groups[choice]]
    group_key = _group_key(members)
    from pidcore.errors import PidcoreError

    try:
        out = _comparison(group_key, stores.stamp(), members, _paper_table(), stores)
    except PidcoreError as exc:
        st.error(f"cannot compare: {exc}")
        return
    comp = out["comparison"]
    aligned = comp.aligned
    c1, c4, c2, c3 = st.columns(4)
    c1.metric("SDC measured ± stderr [-]",
              app_support.format_sdc(comp.measured_sdc, comp.measured_stderr),
              help="Eq. 11: energy per cycle over the reactive energy Im(P)/w")
    c4.metric("SDC measured, E of Eq. 10 [-]",
              app_support.format_sdc(comp.measured_sdc_eq10, comp.measured_stderr_eq10)
              if np.isfinite(comp.measured_sdc_eq10) else "no DEM m_c",
              help="energy per cycle over the DEM case's m_c a^2 / (2 w^2): like for like "
                   "with our DEM SDC")
    c2.metric("SDC our DEM ± stderr [-]",
              app_support.format_sdc(aligned.sdc_dem, aligned.sdc_dem_stderr)
              if aligned.status == "grid" else
              (f"{aligned.sdc_dem:.4f} (pchip)" if aligned.status == "interpolated" else "none"))
    c3.metric("SDC paper DEM / measured [-]",
              f"{aligned.sdc_paper_dem:.4f} / {aligned.sdc_paper_experimental:.4f}")
    st.caption(f"DEM alignment: {aligned.status}. {aligned.message}")
    left, right = st.columns(2)
    left.vega_lite_chart(spec=out["sdc_spec"], key="sdc_chart")
    right.vega_lite_chart(spec=out["loop_spec"], key="loop_chart")
    st.markdown("energy per cycle (loop area): " + " · ".join(
        f"{label}: **{energy:.4e} J**" for label, energy in out["loops"]))
    left2, right2 = st.columns([3, 2])
    left2.vega_lite_chart(spec=out["spectrum_spec"], key="spectrum_chart")
    right2.dataframe(out["spectrum"], hide_index=True)
    st.dataframe(comp.measured, hide_index=True)
    # Warm the cache for the other load cases after this one is on screen, so that switching
    # to any of them is a cache hit.
    warmed = st.session_state.setdefault("_compare_warmed", set())
    stamp = stores.stamp()
    for other, indices in enumerate(groups):
        rest = [analysed[i] for i in indices]
        key = (_group_key(rest), stamp)
        if other == choice or key in warmed:
            continue
        try:
            _comparison(key[0], stamp, rest, _paper_table(), stores)
        except PidcoreError:
            pass  # shown when that case is chosen
        warmed.add(key)


def dem_page(stores) -> None:
    from pidcore._app import dem_tab

    dem_tab.render(stores)


def report_page(stores) -> None:
    from pidcore._app import report_tab

    report_tab.render(stores)


def main() -> None:
    st.set_page_config(page_title="pidcore", layout="wide")
    stores = app_support.AppStores.from_environment()
    st.title("pidcore: particle impact damping")
    with st.sidebar:
        st.markdown(f"**store**: `{stores.path}`")
        if stores.dem_reference is not None:
            st.markdown(f"**reference DEM runs** (read-only): `{stores.dem_reference}`")
        st.markdown(f"**upload limit**: {defaults.APP_MAX_UPLOAD_MB} MB per file")
        st.caption(f"pidcore {__version__}")
    t_analyse, t_compare, t_dem, t_report = st.tabs(["Analyse", "Compare", "DEM", "Report"])
    with t_analyse:
        analysed = analyse_page(stores)
    with t_compare:
        compare_page(stores, analysed)
    with t_dem:
        dem_page(stores)
    with t_report:
        report_page(stores)
