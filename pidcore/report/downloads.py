"""The report of what stores hold, as in-memory files (the app's downloads).

Written by :func:`pidcore.report.write_report` into a temporary folder and read back, so the
downloads are exactly the files ``pidcore report`` writes.
"""

from __future__ import annotations

import io
import os
import tempfile
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd

from ..constants import REPORT_FORMATS
from ..errors import ParameterError

if TYPE_CHECKING:  # pragma: no cover
    from ..calibrate.prediction import Calibration
    from ..specimen import Specimen
    from .pipeline import SpecimenTable

#: MIME type of each report format (:data:`pidcore.constants.REPORT_FORMATS`).
REPORT_MIME_TYPES: dict[str, str] = {
    "csv": "text/csv", "md": "text/markdown", "html": "text/html",
    "tex": "application/x-tex", "pdf": "application/pdf",
}
#: How the app's notes say another specimen's runs are chosen (:func:`store_report_table`).
CHOOSE_SPECIMEN_APP = "the Report tab's specimen choice for another"
#: Name of the report files offered for download: ``pidcore_report.<format>``.
DOWNLOAD_STEM = "pidcore_report"
#: Folder of the figures that the Markdown and LaTeX files link (``figures/<stem>.png``), as
#: :func:`pidcore.report.write_report` writes it beside them.
FIGURES_FOLDER = "figures"


def store_report_table(path: str | os.PathLike, dem_store: str | os.PathLike | None = None, *,
                       analysis_keys: list[str] | None = None, pool: bool = False,
                       calibration: Calibration | None = None,
                       specimen: Specimen | None = None) -> pd.DataFrame:
    """The Table 3-style report table of what the stores hold (empty if they hold nothing).

    Measurements: the newest analysis per measurement and parameters of the store that states
    a fill (:func:`pidcore.store.listing.saved_analyses`), or only ``analysis_keys``. DEM: the
    runs of both stores of ``specimen`` (default: the paper's coupon), chosen and noted as
    ``pidcore report --specimen`` chooses them
    (:func:`pidcore.report.pipeline.specimen_report_table`: other specimens' runs are left out
    and named in ``attrs["notes"]``). ``calibration``: add the calibrated DEM's columns, as
    ``pidcore report --calibration`` does (:func:`pidcore.report.table.add_calibration_columns`).
    """
    return _store_report(path, dem_store, analysis_keys=analysis_keys, pool=pool,
                         calibration=calibration, specimen=specimen)[0]


def _store_report(path: str | os.PathLike, dem_store: str | os.PathLike | None, *,
                  analysis_keys: list[str] | None, pool: bool, calibration: Calibration | None,
                  specimen: Specimen | None
                  ) -> tuple[pd.DataFrame, SpecimenTable | None, pd.DataFrame]:
    """(:func:`store_report_table`, what :func:`pidcore.report.pipeline.specimen_report_table`
    built it from: None for nothing to report, the saved analyses it reports)."""
    from ..store import Store
    from ..store.listing import checked_analyses, list_dem_runs
    from .pipeline import latest_per_measurement, specimen_report_table, stored_records_notes
    from .table import add_calibration_columns

    # the store's records, and those reported, chosen and ordered as `pidcore report --store`
    # chooses them: the notes name them and the loop figures are numbered in that order
    listed = checked_analyses(Store(path).list_analyses(), path) if Path(path).is_file() \
        else pd.DataFrame()
    analyses = latest_per_measurement(listed)
    if analysis_keys is not None and not analyses.empty:
        analyses = analyses[analyses["key"].isin(analysis_keys)].reset_index(drop=True)
    dem_runs = list_dem_runs(path, dem_store)
    if analyses.empty and dem_runs.empty:
        return pd.DataFrame(), None, analyses
    where = " and ".join(str(p) for p in (path, dem_store)
                         if p is not None and Path(p).is_file())
    from ..calibrate.persist import calibration_design_runs

    built = specimen_report_table(dem_runs if not dem_runs.empty else None,
                                  analyses if not analyses.empty else None, specimen=specimen,
                                  where=where or None, pool=pool,
                                  choose_another=CHOOSE_SPECIMEN_APP,
                                  design_runs=calibration_design_runs(dem_runs,
                                                                      [path, dem_store]),
                                  store_analyses=listed)
    table = built.table if calibration is None else add_calibration_columns(
        built.table, calibration, specimen=specimen, paper=specimen is None)
    # what `pidcore report --store` says of the records before the table's notes (the
    # specimen and particles assumed for them): the page and the files said none of it
    table.attrs["notes"] = [*stored_records_notes(listed, analyses, specimen),
                            *table.attrs.get("notes", [])]
    return table, built, analyses


def report_files(path: str | os.PathLike, dem_store: str | os.PathLike | None = None, *,
                 analysis_keys: list[str] | None = None, pool: bool = False,
                 calibration: Calibration | None = None, specimen: Specimen | None = None,
                 wording: Callable[[str], str] | None = None,
                 ) -> dict[str, tuple[str, bytes, str]]:
    """The report of :func:`store_report_table` as downloads: format -> (file name, bytes,
    MIME type), plus ``"csv_provenance"`` (the CSV's notes sidecar) and ``"zip"``: all of
    them with the ``figures/`` folder that the Markdown and LaTeX files link.

    Stores are verified first: a corrupt store raises :class:`pidcore.errors.StoreError` and
    nothing is written. ``wording``: the notes in the front-end's words, as
    :func:`pidcore.report.make_report`'s (the app's: ``pool=True`` is its checkbox).
    """
    from ..compare import Tolerances
    from .pipeline import (
        measured_loops,
        open_verified_store,
        report_figures,
        specimen_provenance,
        stored_parameters,
        worded,
    )
    from .provenance import calibration_provenance, collect_provenance
    from .render import write_report

    stores = [Path(p) for p in (path, dem_store) if p is not None and Path(p).is_file()]
    opened = [open_verified_store(p, must_exist=True) for p in stores]
    table, built, analyses = _store_report(path, dem_store, analysis_keys=analysis_keys,
                                           pool=pool, calibration=calibration,
                                           specimen=specimen)
    if table.empty or built is None:
        raise ParameterError("nothing to report: the stores hold no saved analyses with a "
                             "load case and no DEM runs")
    runs = built.dem_runs
    notes = list(table.attrs.get("notes", []))
    # the figures `pidcore report --store` draws, from the same stores: the force-displacement
    # loops of the stored records, each with its DEM run's where one is held
    main = opened[0] if stores and stores[0] == Path(path) else None
    figures = report_figures(table, runs, built.aligner,
                             measured_loops([], analyses, main, notes), opened, notes)
    if wording is not None:
        table, notes = worded(table, notes, wording)
    tol = Tolerances()
    # the seeds of the specimen's runs, those the table compared from
    seeds = sorted({int(s) for s in runs["seed"].dropna()}) \
        if runs is not None and "seed" in runs.columns else []
    provenance = collect_provenance(
        # the saved analyses' own settings first, as `pidcore report --store` lists them
        parameters={**stored_parameters(analyses), "frequency_rtol": tol.frequency_rtol,
                    "acceleration_rtol": tol.acceleration_rtol,
                    "fill_atol_percent": tol.fill_atol_percent, "pool": pool},
        seeds=seeds, stores=stores, notes=notes,
        specimens=specimen_provenance(specimen, table),
        calibrations=calibration_provenance(calibration))
    try:
        with tempfile.TemporaryDirectory(prefix="pidcore_report_") as folder:
            paths = write_report(table, figures, provenance, Path(folder) / "report",
                                 REPORT_FORMATS)
            out = {fmt: (f"{DOWNLOAD_STEM}.{fmt}", paths[fmt].read_bytes(),
                         REPORT_MIME_TYPES[fmt]) for fmt in REPORT_FORMATS}
            sidecar = paths["csv_provenance"]
            out["csv_provenance"] = (f"{DOWNLOAD_STEM}{sidecar.name[len('report'):]}",
                                     sidecar.read_bytes(), "text/plain")
            # the Markdown and LaTeX files link figures/<stem>.png: downloaded alone they
            # showed a broken image and did not compile, so one archive holds them together
            figure_files = {f"{FIGURES_FOLDER}/{p.name}": p.read_bytes()
                            for key, p in paths.items() if key.startswith("figure:")}
            out["zip"] = (f"{DOWNLOAD_STEM}.zip", _zip_bytes(
                {name: data for name, data, _ in out.values()} | figure_files),
                "application/zip")
            return out
    finally:
        for fig in figures.values():
            fig.clear()


def _zip_bytes(files: dict[str, bytes]) -> bytes:
    """A ZIP archive of ``{name inside the archive: content}``, names in the order given."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for name, data in files.items():
            archive.writestr(name, data)
    return buffer.getvalue()
