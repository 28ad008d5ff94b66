"""Cached reads of the app (Streamlit caches), keyed by content hashes and store stamps."""

from __future__ import annotations

import streamlit as st

from pidcore.app import charts, uploads
from pidcore.report import case_view as views

_CACHE_ENTRIES = 64
#: Parsed uploads kept in memory (each can be up to the upload limit).
_PARSED_ENTRIES = 16


# cache_resource, not cache_data: measurements can be large, and cache_data would unpickle a
# copy on every hit. The records are frozen and never mutated, so sharing them is safe.
@st.cache_resource(max_entries=_PARSED_ENTRIES, show_spinner="Reading file ...")
def parsed(sha256: str, name: str, sample_rate_hz: float | None, time_unit: str | None,
           _upload):
    """The upload read and its channels detected (once per content, sample rate and time
    unit: a changed unit reads the file again)."""
    return uploads.parse_upload(name, _upload.getvalue(), sample_rate_hz=sample_rate_hz,
                                time_unit=time_unit)


@st.cache_resource(max_entries=4 * _PARSED_ENTRIES, show_spinner="Analysing ...")
def analysed(sha256: str, name: str, sample_rate_hz: float | None, time_unit: str | None,
             options_json: str, _upload):
    """The upload analysed with one set of options (once per content and options)."""
    found = parsed(sha256, name, sample_rate_hz, time_unit, _upload)
    return uploads.analyze_parsed(found, uploads.options_from_json(options_json))


def upload_sha256(upload) -> str:
    """Content hash of an upload, computed once per uploaded file."""
    known = st.session_state.setdefault("_upload_sha256", {})
    file_id = getattr(upload, "file_id", None)
    if file_id is None or file_id not in known:
        digest = uploads.content_sha256(upload.getvalue())
        if file_id is None:
            return digest
        known[file_id] = digest
    return known[file_id]


@st.cache_data(max_entries=16, show_spinner=False)
def store_listing(what: str, stamp: tuple, _stores):
    """Store listings, re-read only when a store file changed (``AppStores.stamp``)."""
    from pidcore.store.listing import list_dem_runs, saved_analyses

    if what == "dem_runs":
        return list_dem_runs(_stores.path, _stores.dem_reference)
    if what == "analyses":
        return saved_analyses(_stores.path)
    raise ValueError(what)


@st.cache_data(max_entries=4, show_spinner=False)
def design_runs(stamp: tuple, _stores) -> dict[str, tuple[str, ...]]:
    """Which of the stores' DEM runs are a saved calibration's design runs (run key -> the
    keys of every calibration fitted on it,
    :func:`pidcore.calibrate.persist.calibration_design_runs`), re-read only when a store
    file changed: it opens the stores and reads every calibration."""
    from pidcore.calibrate.persist import calibration_design_runs

    return calibration_design_runs(store_listing("dem_runs", stamp, _stores),
                                   [_stores.path, _stores.dem_reference])


# cache_resource: the calibrations are frozen records, read once per store state (stamp) and
# shared by the Compare, Report and Calibrate tabs; a saved calibration rewrites the store, so
# the next draw has another stamp and reads it
@st.cache_resource(max_entries=4, show_spinner=False)
def store_calibrations(stamp: tuple, _stores):
    """The app store's calibrations (:func:`pidcore.app.calibration.read_store_calibrations`),
    re-read only when a store file changed (``AppStores.stamp``)."""
    from pidcore.app.calibration import read_store_calibrations

    return read_store_calibrations(_stores.path)


@st.cache_data(max_entries=16, show_spinner=False)
def report_table(stamp: tuple, pool: bool, keys: tuple[str, ...] | None,
                 calibration_digest: str, specimen_label: str, _stores, _calibration,
                 _specimen):
    """The report table of the stores (only the analyses ``keys``, all when None) of the
    DEM runs of ``_specimen`` (None: the paper's coupon; named by ``specimen_label``), with
    the calibrated DEM's columns of ``_calibration`` (identified by ``calibration_digest``)."""
    from pidcore.report.downloads import store_report_table

    return store_report_table(_stores.path, _stores.dem_reference, pool=pool,
                              analysis_keys=None if keys is None else list(keys),
                              calibration=_calibration, specimen=_specimen)


@st.cache_resource(max_entries=_CACHE_ENTRIES, show_spinner=False)
def saved_entries(keys: tuple[str, ...], stamp: tuple, _stores, _rows,
                  known_hashes: tuple[str, ...] = (), _known=()):
    """Measured entries of saved analyses (phasors read once per store state), judged against
    the SDC bound of the specimen files the page knows (``_known``, keyed by their hashes)."""
    return views.saved_entries(_stores.path, _rows, _known)


@st.cache_data(show_spinner=False)
def paper():
    """The paper's Table 3."""
    from pidcore.compare.case import paper_table

    return paper_table()


@st.cache_data(max_entries=_CACHE_ENTRIES, show_spinner=False)
def case_view(group_key: str, stamp: tuple, _entries, _stores) -> dict:
    """The Compare page's data and Vega-Lite specs of one load case.

    Keyed by the records' identity and the stores' state; specs are built once per case so a
    revisit only sends them (the tests validate them against the Vega-Lite schema).
    """
    # the library's view, which `pidcore report --case-sheets` prints too
    view = views.case_view(_entries, store_listing("dem_runs", stamp, _stores), paper(),
                           (_stores.path, _stores.dem_reference))
    view["sdc_spec"] = charts.sdc_chart(view["sdc_points"])
    view["loop_spec"] = charts.loop_chart(view["loops"])
    view["spectrum_spec"] = charts.spectrum_chart(view["spectrum"])
    return view


@st.cache_data(max_entries=8, show_spinner=False)
def calibration_png(calibration_digest: str, _calibration) -> bytes:
    """The figure of a calibration's bands (:func:`pidcore.report.figures_results.
    calibration_png` of its :meth:`~pidcore.calibrate.Calibration.to_pandas`), drawn once per
    calibration (``calibration_digest``: :func:`pidcore.app.calibration.calibration_digest`),
    not on every script run."""
    from pidcore.report.figures_results import calibration_png as draw

    return draw(_calibration.to_pandas())
