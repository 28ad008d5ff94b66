"""``pidcore report`` as a library function: analyse, store, align, tabulate, plot, render.

Order matters for the guarantees of the command:

1. formats and the output folder are checked, the stores are opened and verified — a corrupt or
   partial store stops everything with one :class:`~pidcore.errors.StoreError` before anything
   is analysed, stored or written;
2. every file is analysed before anything is stored (one bad file leaves the store untouched);
3. the analyses go into the store in one transaction;
4. the table is built from the store's numbers (read back), so the report shows exactly what is
   stored; figures and provenance follow, and :func:`~pidcore.report.render.write_report` writes
   everything atomically.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from ..atomic_files import check_folder_can_be_made, real_folder, refused_unless_written
from ..compare.align import Aligner, Tolerances
from ..compare.case import saved_parameters
from ..compare.loadcase import LoadCase, StatedLoadCase
from ..compare.specimens import NOT_PAPER_SPECIMEN_NOTE
from ..constants import REPORT_FORMATS
from ..errors import ParameterError, StoreError
from ..io import display_path
from ..loadcase import refuse_identical_contents_stating_apart
from .provenance import calibration_provenance, collect_provenance
from .render import (
    CASE_SHEETS_FOLDER,
    check_out_dir,
    parse_formats,
    restore_previous_report,
    restored_report_note,
    write_report,
)
from .table import SPECIMEN_SHA256_COLUMN, add_calibration_columns, report_table_and_aligner

if TYPE_CHECKING:  # pragma: no cover
    from ..compare.case import MeasuredEntry
    from ..file_settings import FileSettings
    from ..loop import ForceDisplacementLoop
    from ..measure import AnalysisOptions, AnalyzedRecord
    from ..specimen import Specimen
    from ..store import Store
    from .case_sheet import CaseSheet

# pidcore.measure (readers, signal analysis) is imported where used: `import pidcore.report`
# stays light for the app, which only renders stored results.

#: Most force-displacement loop figures in one report (one per measurement).
MAX_LOOP_FIGURES = 12


@dataclass(frozen=True)
class MeasuredResult:
    """One analysed measurement file with its load case.

    Attributes
    ----------
    path : Path
    analyzed : pidcore.measure.AnalyzedRecord
        Measurement, analysis and the channels used (the same glue as ``pidcore analyze``).
    stated : StatedLoadCase
        Fill, material, direction as stated, and where from.
    load_case : LoadCase
        Measured frequency and acceleration with the stated fill/material/direction.
    settings : FileSettings, optional
        The options it was analysed with and who stated them (sidecar row, options), and the
        specimen its sidecar row names.
    """

    path: Path
    analyzed: AnalyzedRecord
    stated: StatedLoadCase
    load_case: LoadCase
    settings: FileSettings | None = None

    @property
    def measurement(self):
        return self.analyzed.measurement

    @property
    def analysis(self):
        return self.analyzed.analysis

    def record(self) -> dict[str, object]:
        """The record ``pidcore analyze`` stores, plus the load case (and the specimen the
        sidecar names)."""
        from ..measure import analysis_record

        return {**analysis_record(self.analyzed), **self.load_case.as_record(self.stated.origin),
                **self.fields()}

    def fields(self) -> dict[str, object]:
        """Record fields beyond the analysis and load case: the ``specimen`` tested (the
        sidecar's or ``specimen=``'s) and, where its file was given, its ``specimen_sha256``."""
        return self.settings.record_fields() if self.settings is not None else {}


@dataclass(frozen=True)
class ReportResult:
    """What :func:`make_report` produced.

    Attributes
    ----------
    paths : dict of str to Path
        Files written (format -> path, ``figure:<name>`` -> path, ``case:<name>.pdf`` -> a
        load case's sheet, with ``case_sheets``).
    table : pandas.DataFrame
        The report table.
    measured : list of MeasuredResult
        The files analysed in this call.
    notes : list of str
        Records left out, figures skipped, and why; an earlier report that a killed one
        had left hidden, put back before this one replaced it.
    """

    paths: dict[str, Path]
    table: pd.DataFrame
    measured: list[MeasuredResult] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def to_pandas(self) -> pd.DataFrame:
        """The report table (:attr:`table`; columns :data:`REPORT_COLUMNS`, each naming its
        unit, and the calibration's where one was given)."""
        return self.table

    def plot(self, ax: Any = None) -> Any:
        """SDC per load case, measured beside our DEM and the paper's
        (:func:`pidcore.report.comparison_figures.plot_sdc_comparison`); returns the figure."""
        from .comparison_figures import plot_sdc_comparison

        return plot_sdc_comparison(self.table, ax=ax)


def open_verified_store(path: str | Path, *, must_exist: bool,
                        progress: bool = False) -> Store:
    """Open a store and verify it; a corrupt or partial store raises one-line StoreError.

    Parameters
    ----------
    path : path
        Store file.
    must_exist : bool
        True for stores that are only read (a missing file is an error); False for a store that
        analyses will be added to (created on first write).
    progress : bool
        A bar over the store's entries on stderr while they are verified.
    """
    from ..store import Store, existing_store
    from ..store.manage import verify_with_progress

    path = Path(path)
    if not path.exists() and not must_exist:
        return Store(path)
    store = existing_store(path)
    problems = verify_with_progress(store, progress=progress, label=f"verifying {path.name}")
    if problems:
        more = f" (and {len(problems) - 1} more problem(s))" if len(problems) > 1 else ""
        raise StoreError(f"{path}: corrupt or partial store, no report written: "
                         f"{problems[0]}{more}")
    return store


def analyze_files(paths: Sequence[str | Path], *, fill_percent: float | None = None,
                  material: str | None = None, direction: str | None = None,
                  sidecar: str | Path | None = None,
                  options: AnalysisOptions | None = None,
                  options_given: Mapping[str, str] | None = None,
                  specimen_material: str | None = None,
                  specimen_name: str | None = None,
                  specimen: Specimen | None = None,
                  accept_implausible: bool = False,
                  progress: bool = False, key: str | None = None,
                  keep_unused_channels: bool = True) -> list[MeasuredResult]:
    """Read, assign roles, analyze (Eq. 11) and attach the load case of every file.

    The load case and the analysis settings are resolved first for every file, so a missing
    fill or a bad sidecar value is reported before any (slow) analysis runs. Each file is
    analysed with its own settings: ``options`` < its sidecar row < the fields of ``options``
    named in ``options_given`` (:func:`pidcore.file_settings.resolve_file_settings`; default:
    those that differ from the defaults). Files with identical contents are one measurement:
    kept once, and refused if they state different load cases, specimens or settings.
    ``specimen_material``: the particle material of the specimen compared with (accepted
    besides the table's, and the default); ``specimen_name``: its name, saved with the files
    of its particles whose sidecar names no specimen; ``specimen``: its cell, against which a
    stated fill of its particles must round to a particle at least
    (:func:`pidcore.file_settings.resolve_files`). A result the plausibility checks refuse (a
    negative loss factor beyond its noise, an SDC above its specimen's bound,
    :func:`pidcore.compare.plausibility.sdc_bound`) is refused unless
    ``accept_implausible`` (:func:`pidcore.compare.plausibility.refuse_implausible`).
    ``progress``: a bar over the files on stderr (:func:`pidcore.file_settings.analyze_each`).
    ``key``: which measurement of a pidcore HDF5 store among ``paths`` to read, where it holds
    several (as :func:`pidcore.measure.analyze_file` takes it).
    ``keep_unused_channels=False``: each result's measurement keeps only the channels its
    analysis used, for a caller that saves none (:func:`pidcore.file_settings.analyze_each`).
    """
    from ..compare.plausibility import refuse_implausible, stated_sdc_bounds
    from ..file_settings import analyze_each, resolve_files
    from ..io import detect_file_format
    from ..measure import AnalysisOptions

    options = options or AnalysisOptions()
    for path in paths:  # a missing or empty file is named as such, not as "no fill stated"
        detect_file_format(path)
    stated, settings = resolve_files(paths, options=options, given=options_given,
                                     fill_percent=fill_percent, material=material,
                                     direction=direction, sidecar=sidecar,
                                     specimen_material=specimen_material,
                                     specimen_name=specimen_name, specimen=specimen)
    analyzed_files = refuse_implausible(
        analyze_each(paths, settings, key=key, progress=progress,
                     keep_unused_channels=keep_unused_channels),
        [display_path(Path(path).name) for path in paths], accept=accept_implausible,
        bounds=stated_sdc_bounds(stated, settings, specimen))
    results = []
    for path, st, fs, analyzed in zip(paths, stated, settings, analyzed_files, strict=True):
        a = analyzed.analysis
        results.append(MeasuredResult(Path(path), analyzed, st,
                                      st.load_case(a.frequency_hz, a.acceleration_g), fs))
    # Identical bytes are one measurement (the store keeps it once); it cannot belong to two
    # load cases (or specimens, or be analysed two ways), and counting it twice would shrink
    # the pooled standard error.
    refuse_identical_contents_stating_apart(
        (r.path.name, r.measurement.sha256, (r.load_case.key, fs.statement()),
         ", ".join(w for w in (r.load_case.key, fs.label()) if w))
        for r, fs in zip(results, settings, strict=True))
    out: list[MeasuredResult] = []
    seen: set[str] = set()
    for r in results:
        sha = r.measurement.sha256
        if sha and sha in seen:
            continue
        seen.add(sha)
        out.append(r)
    return out


def _parameters(results: Sequence[MeasuredResult], options: AnalysisOptions) -> dict:
    """The analysis parameters for the provenance: each one the files share as it is, one
    that differs between them as ``"a.uff: 5e-05; b.uff: 0"`` (per-file sidecar settings)."""
    if not results:
        return options.parameters()
    return _shared_parameters([(r.path.name, (r.settings.options if r.settings is not None
                                              else options).parameters()) for r in results])


def stored_parameters(analyses: pd.DataFrame | None) -> dict:
    """The analysis parameters the reported stored analyses were saved with (their
    ``parameters_json``), for the provenance, as :func:`_parameters` gives those of files
    analysed now. A report of a store without files listed the options' defaults
    (``velocity_delay_s=0.0``) for records analysed with 50 µs."""
    if analyses is None or analyses.empty or "parameters_json" not in analyses.columns:
        return {}
    names = analyses["file"] if "file" in analyses.columns else analyses["source"].map(
        lambda s: Path(str(s)).name)
    per_file = [(str(name), saved_parameters(text))
                for name, text in zip(names, analyses["parameters_json"], strict=True)]
    # by file name: the CLI and the app list a store's analyses in different orders
    return _shared_parameters(sorted(per_file, key=lambda item: item[0]))


def _shared_parameters(per_file: list[tuple[str, dict]]) -> dict:
    """Each parameter as the files share it, one that differs between them as
    ``{"a.uff": 5e-05, "b.uff": 0.0}`` (None where a file has none)."""
    names = list(dict.fromkeys(k for _, p in per_file for k in p))
    out: dict[str, object] = {}
    for name in names:
        values = [p.get(name) for _, p in per_file]
        out[name] = values[0] if all(v == values[0] for v in values) else {
            file: v for (file, _), v in zip(per_file, values, strict=True)}
    return out


def measured_frame(results: Iterable[MeasuredResult]) -> pd.DataFrame:
    """The analyses table (as the store lists it) for results that were not stored."""
    # the path as stored (\xNN escapes): a file name that is not UTF-8 held surrogates that
    # pandas' string columns cannot encode (a traceback without --store)
    rows = [{"source": display_path(r.path), **r.record()} for r in results]
    return pd.DataFrame(rows)


def _tables_read(results: Sequence[MeasuredResult], sidecar: str | Path | None) -> list[Path]:
    """The load-case tables the files were read with: ``sidecar``, else each file's
    ``loadcases.csv`` beside it where one exists (the tables :func:`resolve_files` reads)."""
    from ..compare.loadcase import SIDECAR_NAME

    if not results:
        return []
    if sidecar is not None:
        return [Path(sidecar)]
    return [table for table in dict.fromkeys(r.path.parent / SIDECAR_NAME for r in results)
            if table.is_file()]


def latest_per_measurement(analyses: pd.DataFrame) -> pd.DataFrame:
    """The newest analysis of each measurement that states a fill (store-only reports)."""
    if analyses.empty or "fill_percent" not in analyses.columns:
        return analyses.iloc[0:0]
    from ..store.listing import latest_per_measurement as newest

    with_fill = analyses[np.isfinite(pd.to_numeric(analyses["fill_percent"], errors="coerce"))]
    return newest(with_fill).reset_index(drop=True)


def stored_records_notes(listed: pd.DataFrame, analyses: pd.DataFrame,
                         specimen: Specimen | None = None) -> list[str]:
    """What a report of a store's records says of them, before its table's notes: what
    ``pidcore analyze`` assumed for the records reported, ``analyses`` (the paper's acrylic,
    its coupon), a result of theirs saved as implausible, and how many measurements of the
    store's records ``listed`` have no analysis stating a fill (in no table). ``pidcore report
    --store`` and the app's Report tab both say them: the tab said none."""
    from ..compare.plausibility import stored_plausibility_notes, stored_record_name
    from ..file_settings import stored_assumption_notes

    # what analyze assumed for them is said again here
    notes = stored_assumption_notes(analyses)
    # a stored result kept as implausible is said again here, as when it was saved
    for _, record in analyses.iterrows():
        notes.extend(f"{stored_record_name(record)}: "
                     f"{n}" for n in stored_plausibility_notes(record, given=specimen))
    if not listed.empty:
        # of the store, not of the records chosen (the app reports some of them)
        left_out = (listed["measurement_key"].nunique()
                    - latest_per_measurement(listed)["measurement_key"].nunique())
        if left_out:
            notes.append(f"{left_out} stored measurement(s) have no analysis stating a fill; "
                         "not in the table (re-run with the files and fill_percent)")
    return notes


def measured_loops(results: Sequence[MeasuredResult], analyses: pd.DataFrame,
                   store: Store | None, notes: list[str]
                   ) -> list[tuple[str, LoadCase, ForceDisplacementLoop]]:
    """(name, load case, loop) per measurement: from the fresh analyses ``results``, else from
    the harmonic phasors of ``store``'s records ``analyses`` (store-only reports; a record
    without them is named in ``notes``)."""
    from .comparison_figures import loop_from_phasors

    if results:
        return [(display_path(r.path.name), r.load_case, r.analysis.loop())
                for r in results]
    loops = []
    if store is None or analyses.empty or "key" not in analyses.columns:
        return loops
    # one opening of the store for all of them, not one per analysis
    entries = store.get_analyses(str(key) for key in analyses["key"])
    for (_, row), entry in zip(analyses.iterrows(), entries, strict=True):
        name = Path(str(row.get("source", "") or row["key"])).name
        found = loop_from_phasors(entry.arrays, row.get("frequency_hz"))
        if isinstance(found, str):
            notes.append(f"{name}: {found}; loop not drawn")
            continue
        case = LoadCase(float(row["frequency_hz"]), float(row["acceleration_g"]),
                        float(row["fill_percent"]), str(row.get("material") or "acrylic"),
                        str(row.get("direction") or "z"))
        loops.append((name, case, found))
    return loops


def specimen_provenance(specimen, table: pd.DataFrame | None = None) -> list[tuple[str, str]]:
    """(label, SHA-256) of the specimen(s) whose DEM runs a report compares: the paper's
    coupon with the particle materials of ``table``'s rows (each, without a table)."""
    from ..constants import PARTICLE_MATERIALS
    from ..specimen import paper_specimen

    if specimen is not None:
        return [(f"{specimen.name} ({specimen.source})", specimen.hash)]
    # the default compares the paper's coupon with either of its particle materials: named
    # are those the rows hold (an acrylic report named the aluminium coupon it never used)
    used = set(table["material"].dropna().astype(str)) \
        if table is not None and "material" in table.columns else set(PARTICLE_MATERIALS)
    return [(f"{paper_specimen(m).name} (the default, {m} particles)", paper_specimen(m).hash)
            for m in PARTICLE_MATERIALS if m in used]


def _other_specimens(stored: pd.DataFrame, kept: pd.DataFrame) -> str:
    """"4 run(s) of other specimens: 3 of a [1b8b5d], 1 of paper_coupon" for the runs of
    ``stored`` not in ``kept``; "" if none. Labelled as Compare labels them
    (:func:`~pidcore.compare.specimens.run_specimen_labels`): the hash is named too, as an
    edited specimen file keeps its name but is another specimen."""
    from ..compare.specimens import runs_per_specimen_text

    left_out = stored[~stored["case_key"].isin(set(kept["case_key"]))]
    if left_out.empty:
        return ""
    return f"{len(left_out)} run(s) of other specimens: {runs_per_specimen_text(left_out)}"


#: How ``pidcore report`` says another specimen is chosen (the app says its own way).
CHOOSE_SPECIMEN_CLI = "specimen=FILE for another"


def specimen_dem_runs(stored: pd.DataFrame | None, specimen=None, *,
                      where: str | Path | None = None,
                      choose_another: str = CHOOSE_SPECIMEN_CLI,
                      ) -> tuple[pd.DataFrame | None, list[str]]:
    """The DEM runs a report of ``specimen`` compares, and notes naming those left out.

    ``specimen=None`` is the default: the paper's coupon with either table material
    (:func:`pidcore.dem.persist.runs_of_specimen`). Runs of other specimens are left out and
    named by label and count (``"1 run(s) of other specimens: 1 of my_steel [3e945a]; not
    compared ..."``). ``where``: the store named in the notes; ``choose_another``: how the
    default's note says another specimen is chosen. ``pidcore report`` and the app's Report
    tab both choose their runs here.
    """
    notes: list[str] = []
    where = where if where is not None else "the DEM store"
    if stored is None:
        return None, notes
    if stored.empty:
        notes.append(f"{where}: holds no DEM runs")
        return None, notes
    from ..compare.specimens import specimen_label
    from ..dem.persist import runs_of_specimen
    from ..specimen import paper_specimen

    kept = runs_of_specimen(stored, specimen)
    others = _other_specimens(stored, kept)
    # the default takes the paper's coupon with either table material: no one hash
    name = (specimen_label(specimen.name, specimen.hash) if specimen is not None else
            f"{paper_specimen().name} (the default; {choose_another})")
    if kept.empty:
        notes.append(f"{where}: holds no DEM runs of specimen {name} ({others})")
        return None, notes
    if others:
        notes.append(f"{where}: {others}; not compared (the report is of specimen {name})")
    return kept, notes


def without_design_runs(runs: pd.DataFrame, design_runs: Mapping[str, Sequence[str]], *,
                        poolable: bool = True) -> tuple[pd.DataFrame | None, str]:
    """``runs`` without the calibrations' design runs that another run of their specimen and
    load case stands beside, and the note naming the design runs ("" where there were none);
    ``poolable``: the note says that ``pool=True`` pools them (a page that does not pool does
    not).

    A calibration's runs (2 to 4 cells each, by default) showed as rows of their own beside the
    specimen's predictions, "DEM settings: cells 2", with an SDC of their own and nothing
    saying they were a fit's inputs: an engineer read them as another prediction of the
    coupon. Where one is the only run of its specimen at its load case it is kept, and the
    note says what it is: it is a DEM run of that very specimen (a store holding only a
    calibration's runs had no DEM value to compare with at all)."""
    design = runs["case_key"].isin(list(design_runs)).to_numpy(bool)
    if not design.any():
        return runs, ""
    # a run's load case is the start of its key (frequency, acceleration, fill, material,
    # direction as every writer formats them), of its specimen
    from ..dem.persist import run_key_case

    sha = (runs["specimen_sha256"].astype(str) if "specimen_sha256" in runs.columns
           else pd.Series([""] * len(runs), index=runs.index))
    where = list(zip(sha, runs["case_key"].astype(str).map(run_key_case), strict=True))
    covered = {w for w, d in zip(where, design, strict=True) if not d}
    replaced = np.array([d and w in covered for w, d in zip(where, design, strict=True)],
                        bool)
    design_keys = runs.loc[design, "case_key"]
    calibrations = sorted({c for k in design_keys for c in design_runs[k]})
    cells = sorted({int(c) for c in runs.loc[design, "cells_simulated"].dropna()}) \
        if "cells_simulated" in runs.columns else []
    of_cells = f" ({' or '.join(map(str, cells))} cells per run)" if cells else ""
    n_out, n_kept = int(replaced.sum()), int(design.sum() - replaced.sum())
    what = (f"DEM run(s) of the design of calibration(s) {', '.join(calibrations)}{of_cells}")
    said = []
    if n_out:
        said.append(f"{n_out} {what} are left out of the comparison: they are the inputs of "
                    "its fit, not predictions of the specimen (the calibrated DEM is its "
                    "prediction), and other runs of the specimen stand at their load cases"
                    + ("; pool=True pools them with the other runs" if poolable else ""))
    if n_kept:
        said.append(f"{n_kept} {what} are compared: the only DEM runs of the specimen at "
                    "their load cases (a fit's inputs, with the few cells of a fit)")
    kept = runs[~replaced].reset_index(drop=True)
    return (kept if not kept.empty else None), "; ".join(said)


def unsubtracted_baseline_note(specimen, analyses: pd.DataFrame | None) -> str:
    """The note for measurements of ``specimen``'s particles analysed without the empty
    coupon's loss factor its file states (``[coupon] baseline_loss_factor``); "" where it
    states none or every such record subtracted one.

    The DEM's SDC is the particles' alone and the measured one includes the structure's
    damping unless the analysis subtracted it; the specimen's value was used only by
    ``pidcore calibrate``, and a report of the specimen compared the two without a word.
    """
    from ..compare.align import stored_parameters

    eta = float(specimen.coupon.baseline_loss_factor) if specimen is not None else 0.0
    if eta <= 0 or analyses is None or analyses.empty or "material" not in analyses.columns:
        return ""
    material = specimen.particles.material
    named = analyses.get("specimen", pd.Series([""] * len(analyses), index=analyses.index))
    from ..specimen import (
        MEASURED_SHA256_FIELD,
        measured_specimen_name,
        measured_specimen_sha256,
        same_tested_file,
        uncalibrated_name,
    )

    # a record of its name whose file's hash is another's is another file's test (one saved
    # before the hash was, or without a file, is taken by its name)
    recorded = analyses.get(MEASURED_SHA256_FIELD,
                            pd.Series([""] * len(analyses), index=analyses.index))
    own = measured_specimen_sha256(specimen)
    other_file = recorded.map(lambda sha: same_tested_file(sha, own) is False)
    # the tests a calibrated file models are saved under the name of the file it was made
    # from ("x" for x_calibrated, as report and calibrate match them): its fitted baseline,
    # the one case where a file states one, went unsaid beside them
    tested = measured_specimen_name(specimen)
    mine = analyses[(analyses["material"] == material)
                    & named.fillna("").isin(["", tested, uncalibrated_name(tested)])
                    & ~other_file.astype(bool)]
    subtracted = [float((stored_parameters(p) or {}).get("baseline_loss_factor") or 0.0)
                  for p in mine.get("parameters_json", pd.Series([None] * len(mine)))]
    without = sum(1 for value in subtracted if value == 0.0)
    if not without:
        return ""
    structure_kg = float(specimen.coupon.mass_kg) + float(specimen.coupon.fixture_mass_kg)
    return (f"specimen {specimen.name} states [coupon] baseline_loss_factor {eta:g} (the empty "
            f"coupon's damping), which {without} measured record(s) of its {material} particles "
            f"were analysed without: their SDC includes the structure's share of it (2 pi x "
            f"{eta:g} x its share of the vibrated mass, at most {2 * math.pi * eta:.3g}) and the "
            f"DEM's, of the particles alone, does not; analyse them with baseline_loss_factor="
            f"{eta:g} structure_mass_kg={structure_kg:.4g} (coupon and fixture; or a sidecar's "
            # "column" keeps the sidecar's column names as written: the CLI's words turned
            # the first into the flag --baseline-loss-factor, which no sidecar column is
            "baseline_loss_factor column and structure_mass_g column) to subtract it")


def whole_mass_baseline_note(settings: Iterable[Mapping | None]) -> str:
    """The note for measured records whose baseline loss factor was subtracted off the whole
    vibrated mass (no structure mass given): ``settings`` are each record's analysis
    parameters (stored ``parameters_json``, or an analysis's ``corrections``); "" where none
    was. ``pidcore analyze`` says it per file; the report compared such an SDC, too low by
    the baseline x the particles' share of the vibrated mass, with the DEM without a word."""
    count = sum(1 for s in settings
                if s and float(s.get("baseline_loss_factor") or 0.0) > 0
                and not s.get("structure_mass_kg"))
    if not count:
        return ""
    return (f"{count} measured record(s) had the baseline loss factor subtracted as if the "
            "whole vibrated mass were the empty structure's (no structure mass given): too "
            "much by the baseline x the particles' share of that mass, so their SDC is low by "
            "2 pi x that; give the structure's mass (coupon and fixture above the gauge: "
            "structure_mass_kg, or a structure_mass_g column of the settings table) for the "
            "exact subtraction")


@dataclass(frozen=True)
class SpecimenTable:
    """What :func:`specimen_report_table` built: the table (notes in ``attrs["notes"]``), the
    DEM runs compared (None: none), the paper's Table 3 used (None where not compared) and the
    aligner of the table's DEM rows (the runs counted and their models, for its figures)."""

    table: pd.DataFrame
    dem_runs: pd.DataFrame | None
    paper: pd.DataFrame | None
    aligner: Aligner


def worded(table: pd.DataFrame, notes: Sequence[str], wording: Callable[[str], str]
           ) -> tuple[pd.DataFrame, list[str]]:
    """``table`` (its rows' ``note`` column and ``attrs["notes"]``) and ``notes`` in a
    front-end's words (``wording``: :func:`pidcore.cli._vocabulary.cli_words` for the CLI,
    :func:`pidcore.app.vocabulary.page_terms` for the app), as the report files say them."""
    attrs = {**table.attrs, "notes": [wording(n) for n in table.attrs.get("notes", [])]}
    if "note" in table.columns:
        table = table.assign(note=[wording(n) if isinstance(n, str) else n
                                   for n in table["note"]])
    table.attrs = attrs
    return table, [wording(n) for n in notes]


def specimen_report_table(stored_runs: pd.DataFrame | None, analyses: pd.DataFrame | None, *,
                          specimen: Specimen | None = None, where: str | Path | None = None,
                          tolerances: Tolerances | None = None, pool: bool = False,
                          choose_another: str = CHOOSE_SPECIMEN_CLI,
                          design_runs: Mapping[str, Sequence[str]] | None = None,
                          store_analyses: pd.DataFrame | None = None) -> SpecimenTable:
    """The report table of one specimen's DEM runs (:func:`specimen_dem_runs`) beside the
    analyses, as ``pidcore report`` and the app's Report tab show it.

    The paper's Table 3 is compared only for the paper's coupon. With a ``specimen`` the
    ``specimen`` column names it on every row of its particle material that
    does not name its own (its DEM runs', and the files given as its tests), and the
    ``specimen sha256`` column its file's hash where the row has none (the paper's coupon's
    stays empty: matched by name, :func:`pidcore.specimen.deciding_sha256`); a measurement of
    another material names none (it is not this specimen's test). A measured row with no DEM
    run of its specimen at its material and direction says so (alignment ``no_dem_runs``) and
    names the runs of other specimens the store holds there. The default (the paper's coupon)
    leaves the column empty, as the bundled report always had it.

    ``design_runs``: run key -> calibration keys of the runs that are calibrations' design runs
    (:func:`pidcore.calibrate.persist.calibration_design_runs`); unless ``pool``, they are left
    out of the rows, and a note says so. ``store_analyses``: every analysis of the store
    ``analyses`` are chosen from, deciding with them which file a record saved without its
    file's hash is of (:func:`pidcore.report.table.build_report_table`).
    """
    from ..model import load_paper_table3

    dem_runs, notes = specimen_dem_runs(stored_runs, specimen, where=where,
                                        choose_another=choose_another)
    if design_runs and not pool and dem_runs is not None:
        dem_runs, note = without_design_runs(dem_runs, design_runs)
        if note:
            notes.append(note)
            # nor are they "another specimen's runs" in a measured row's note
            stored_runs, _ = without_design_runs(stored_runs, design_runs)
    paper = load_paper_table3()
    from ..specimen import (
        PAPER_SPECIMEN_NAME,
        deciding_sha256,
        measured_specimen_name,
        measured_specimen_sha256,
        tabulated_by_paper,
    )

    # a file named paper_coupon with another cell is "paper_coupon [45d792]" here, as its
    # tests and DEM runs are: "specimen paper_coupon is not the paper's coupon" contradicted
    # itself, and its rows were named as the paper's coupon's
    name = measured_specimen_name(specimen) if specimen is not None else PAPER_SPECIMEN_NAME
    # as a row of its tests is judged (by the name they are saved under): a calibrated file
    # of the paper's coupon (another hash, the coupon's physics) lost Table 3 here only
    if specimen is not None and not tabulated_by_paper(specimen):
        paper = None
        notes.append(NOT_PAPER_SPECIMEN_NOTE.format(name=name))

    table, aligner = report_table_and_aligner(
        dem_runs, analyses, paper, tolerances=tolerances, pool=pool, store_runs=stored_runs,
        of_specimen=name, given_specimen=specimen,
        choose_another="" if choose_another == CHOOSE_SPECIMEN_CLI
        else f"choose theirs with {choose_another.removesuffix(' for another')} to compare "
             "them",
        tested_files={name: measured_specimen_sha256(specimen)} if specimen is not None
        else None, store_analyses=store_analyses)
    baseline = unsubtracted_baseline_note(specimen, analyses)
    if baseline:
        notes.append(baseline)
    if analyses is not None and "parameters_json" in analyses.columns:
        from ..compare.align import stored_parameters as parsed

        whole = whole_mass_baseline_note(parsed(p) for p in analyses["parameters_json"])
        if whole:
            notes.append(whole)
    if specimen is not None:
        # every DEM row is this specimen's (runs_of_specimen) and the files of its particle
        # material are its tests; a measurement of another material cannot be (its specimen
        # is unknown: left empty), and one stored with a specimen of its own (the app's
        # uploads, a sidecar's) keeps that one
        mine = (table["specimen"] == "") & (table["material"] == specimen.particles.material)
        table.loc[mine, "specimen"] = name
        # and its file's hash, as a row of its tests that recorded it shows it (the footer
        # named the hash, the DEM-only rows' cell was empty): "" for the paper's coupon,
        # matched by name (deciding_sha256)
        unhashed = mine & (table[SPECIMEN_SHA256_COLUMN] == "")
        table.loc[unhashed, SPECIMEN_SHA256_COLUMN] = deciding_sha256(
            measured_specimen_sha256(specimen))
    table.attrs["notes"] = notes + list(table.attrs.get("notes", []))
    return SpecimenTable(table, dem_runs, paper, aligner)


def report_figures(table: pd.DataFrame, dem_runs: pd.DataFrame | None, aligner: Aligner,
                   loops: list[tuple[str, LoadCase, ForceDisplacementLoop]],
                   dem_stores: Sequence[Store], notes: list[str]) -> dict[str, object]:
    """The report's figures by name: SDC per load case, the DEM models' SDC against
    acceleration and frequency, and the first :data:`MAX_LOOP_FIGURES` of ``loops``
    (:func:`measured_loops`) with the DEM run's loop of ``dem_stores`` at their grid case
    overlaid; what was drawn without it is said in ``notes``. ``pidcore report`` and the app's
    report files draw these."""
    from .comparison_figures import dem_loop_from_arrays, plot_loop_overlay, plot_sdc_comparison

    figures: dict[str, object] = {}
    if not table.empty:
        figures["sdc_per_load_case"] = plot_sdc_comparison(table)
    models = {k: m for k, m in aligner.models.items() if not isinstance(m, str)}
    if models:
        from .figures import plot_sdc_vs_acceleration, plot_sdc_vs_frequency

        for (material, direction), model in models.items():
            # its own runs only: those of other settings at a load case are left out of it,
            # as its caption says, and drawn as its data they contradicted it
            sub = dem_runs[dem_runs["case_key"].isin(aligner.model_run_keys(material,
                                                                            direction))]
            suffix = f"{material}_{direction}"
            figures[f"sdc_vs_acceleration_{suffix}"] = plot_sdc_vs_acceleration(
                model, table=sub, value="sdc")
            figures[f"sdc_vs_frequency_{suffix}"] = plot_sdc_vs_frequency(
                model, table=sub, value="sdc")
    for i, (name, case, loop) in enumerate(loops[:MAX_LOOP_FIGURES]):
        dem_loop = None
        grid = aligner.grid_case(case)
        holder = next((s for s in dem_stores if s.has_dem_run(grid.run_keys[0])), None) \
            if grid is not None and grid.run_keys else None
        if holder is None:
            notes.append(f"{name}: no DEM run at {case.label()}; loop drawn without DEM overlay")
        else:
            entry = holder.get_dem_run(grid.run_keys[0])
            found = dem_loop_from_arrays(entry.arrays, entry.record)
            if isinstance(found, str):
                notes.append(f"{name}: {found}; loop drawn without DEM overlay")
            else:
                dem_loop = found
        figures[f"loop_{i:02d}_{case.key}"] = plot_loop_overlay(
            loop, dem_loop, title=f"{name}: {case.label()}")
    if len(loops) > MAX_LOOP_FIGURES:
        notes.append(f"loops drawn for the first {MAX_LOOP_FIGURES} of {len(loops)} measurements")
    return figures


def _dem_paths(store: str | Path | None,
               dem_store: str | Path | Sequence[str | Path] | None) -> list[Path]:
    """The stores whose DEM runs a report compares: ``dem_store`` (one path or several, in
    order), else ``store``; each once."""
    if dem_store is None:
        return [Path(store)] if store else []
    given = [dem_store] if isinstance(dem_store, str | Path) else list(dem_store)
    # one file once, however spelt (d.h5, /abs/d.h5, a link to it): it was listed in the
    # provenance once per spelling
    first: dict[str, Path] = {}
    for p in map(Path, given):
        first.setdefault(os.path.realpath(p), p)
    return list(first.values())


def _joined_dem_runs(stores: list) -> pd.DataFrame | None:
    """The DEM runs of ``stores`` joined as the app joins its stores
    (:func:`pidcore.store.listing.list_dem_runs`: a run key held by several comes from the
    first); None without a store."""
    if not stores:
        return None
    from ..store.listing import checked_dem_runs, list_dem_runs

    if len(stores) == 1:
        return checked_dem_runs(stores[0].list_dem_runs(), stores[0].path)

    return list_dem_runs(*(s.path for s in stores))


def report_entries(results: Sequence[MeasuredResult], analyses: pd.DataFrame,
                   store: Store | None, specimen: Specimen | None = None,
                   ) -> list[MeasuredEntry]:
    """The report's measured records as the app's Compare page takes them
    (:class:`pidcore.compare.case.MeasuredEntry`), one per row of ``analyses`` and in its
    order (the positions of :data:`pidcore.report.table.MEASURED_RECORDS_ATTR`): with a
    ``store``, the stored analyses ``analyses`` reports (their keys) read back as the page
    reads its store's, judged against the SDC bound of ``specimen`` where they are its tests;
    without, the files analysed now (``results``, whose records ``analyses`` are) as the page
    takes an unsaved upload. A record saved without its file's hash is matched to its
    specimen's file over the store's records and ``specimen``'s file, as the report's rows
    match it (:func:`pidcore.report.case_view.matched_specimens`)."""
    from ..compare.case import MeasuredEntry
    from ..compare.plausibility import stated_sdc_bounds
    from ..specimen import MEASURED_SHA256_FIELD, measured_specimen_name, measured_specimen_sha256
    from ..store.listing import saved_analyses
    from .case_view import matched_specimens, saved_entries

    given = ({measured_specimen_name(specimen): measured_specimen_sha256(specimen)}
             if specimen is not None else None)
    if store is not None:
        if analyses.empty or "key" not in analyses.columns:
            return []
        # every analysis stating a fill, not only each measurement's newest: the report's
        # records by their keys, whichever it chose
        listing = saved_analyses(store.path, latest_only=False)
        rows = listing.set_index("key", drop=False).loc[
            analyses["key"].astype(str)].reset_index(drop=True)
        known = (specimen,) if specimen is not None else ()
        return matched_specimens(saved_entries(store.path, rows, known), listing, given=given)
    entries = []
    for r in results:
        fields = r.fields()
        entries.append(MeasuredEntry.from_record(
            r.analyzed, r.load_case, specimen=str(fields.get("specimen", "")),
            options=r.settings.options if r.settings is not None else None,
            specimen_sha256=str(fields.get(MEASURED_SHA256_FIELD, "")),
            sdc_bound=stated_sdc_bounds([r.stated], [r.settings], specimen)[0]))
    return matched_specimens(entries, given=given)


def report_case_sheets(results: Sequence[MeasuredResult], analyses: pd.DataFrame,
                       store: Store | None, dem_runs: pd.DataFrame | None,
                       dem_paths: Sequence[Path], specimen: Specimen | None,
                       calibration, table: pd.DataFrame,
                       paper: pd.DataFrame | None, *,
                       progress: bool = False) -> list[CaseSheet]:
    """The PDF sheet of every measured row of the report ``table``
    (:func:`pidcore.report.case_sheet.case_sheets`), as the app's Compare page prints a load
    case from the same records (:func:`report_entries`), DEM runs and ``calibration`` (the
    report's :func:`pidcore.calibrate.prediction.load_calibration`; None: none given, said on
    each sheet), the calibration named as the report's provenance names it.

    Each sheet pools the records its row pools (:data:`pidcore.report.table.
    MEASURED_RECORDS_ATTR`), in the table's order, which is not always the page's grouping:
    on the grid the report groups records by the DEM case they meet (tests at 4.8 g and 5.2 g
    both meet the 5 g run: one row, where the page shows two cases); off the grid it groups
    them as the page does, within the tolerances of each other
    (:func:`pidcore.compare.case.group_load_cases`). Each sheet is named by its row
    (:func:`pidcore.report.case_sheet.sheet_stem` of its ``load case``, the grid case a row on
    the grid shows, and its specimen), so that ``report.csv`` finds it by name.

    ``dem_runs``: every run of the stores ``dem_paths``, joined as the page joins its stores';
    the sheets meet only those the report's rows meet, of ``specimen``
    (:func:`specimen_dem_runs`; default the paper's coupon). The page meets each test's own
    specimen's runs: a test naming another specimen got its runs' SDC on its sheet beside a
    row saying the report has no DEM run of it. Likewise a calibration of another specimen
    than the report's (:func:`pidcore.report.table.report_calibration_specimen`) predicts no
    row and judges no sheet. ``paper``: the Table 3 the report compares (None: none, a
    report of a specimen that is not the paper's coupon), said on each sheet as in the
    report's notes: a test naming the paper's coupon had Table 3 in its sheet's chart beside
    a row without it."""
    from ..model import load_paper_table3
    from .case_sheet import case_sheets
    from .provenance import calibration_source
    from .table import MEASURED_RECORDS_ATTR, report_calibration_specimen

    label = calibration_source(calibration) if calibration is not None else ""
    groups: list[list[int]] = []
    keys: list[str] = []  # each sheet is named by its row's load case, which finds it
    calibrations: list[list[tuple[object | None, str]]] = []
    for pooled, (_, row) in zip(table.attrs.get(MEASURED_RECORDS_ATTR, []), table.iterrows(),
                                strict=True):
        if not pooled:  # a DEM-only row: no measured load case
            continue
        groups.append(list(pooled))
        keys.append(str(row["load case"]))
        if calibration is None:
            calibrations.append([])
            continue
        # the report's rule first (the calibration must be of the report's specimen), then
        # the page's (of the tests' specimen, members_calibrated_case)
        refused = calibration.other_specimen_reason(report_calibration_specimen(
            str(row["material"]), specimen, paper=specimen is None))
        calibrations.append([(None, f"not predicted by the calibration {label}: {refused}")]
                            if refused else [(calibration, label)])
    said = []
    if paper is None:
        from ..specimen import PAPER_SPECIMEN_NAME, measured_specimen_name

        paper = load_paper_table3().iloc[0:0]
        said.append(NOT_PAPER_SPECIMEN_NOTE.format(
            name=measured_specimen_name(specimen) if specimen is not None
            else PAPER_SPECIMEN_NAME))
    compared, _ = specimen_dem_runs(dem_runs, specimen)
    return case_sheets(report_entries(results, analyses, store, specimen), compared, paper,
                       list(dem_paths), groups=groups, group_calibrations=calibrations,
                       group_keys=keys, notes=said, progress=progress)


def make_report(files: Sequence[str | Path], *, out_dir: str | Path,
                store: str | Path | None = None,
                dem_store: str | Path | Sequence[str | Path] | None = None,
                formats: str | Iterable[str] = REPORT_FORMATS,
                fill_percent: float | None = None, material: str | None = None,
                direction: str | None = None, sidecar: str | Path | None = None,
                options: AnalysisOptions | None = None,
                options_given: Mapping[str, str] | None = None,
                tolerances: Tolerances | None = None, specimen: Specimen | None = None,
                pool: bool = False,
                calibration: str | Path | None = None,
                calibration_key: str | None = None,
                accept_implausible: bool = False, progress: bool = False,
                wording: Callable[[str], str] | None = None,
                key: str | None = None, case_sheets: bool = False) -> ReportResult:
    """Analyse files, store them, align with DEM and the paper, and write the report.

    Parameters
    ----------
    files : sequence of path
        Measurement files to analyse (may be empty: report what the store holds).
    out_dir : path
        Report folder (new, empty or an earlier report, which is replaced atomically).
    store : path, optional
        Store the analyses are added to; without files its analyses are reported (the newest
        per measurement that states a fill).
    dem_store : path or sequence of path, optional
        Store(s) whose DEM runs are compared (default: ``store``); several are joined as the
        app joins its store with the reference runs (a run key in several: the first's).
        Only read.
    formats : str or iterable of str
        ``csv, md, html, tex, pdf`` or ``"all"``.
    fill_percent, material, direction, sidecar
        Load case statements (:func:`pidcore.compare.resolve_load_case`); the material
        defaults to the ``specimen``'s particles (else acrylic), and may be the specimen's own.
    options : AnalysisOptions, optional
        Channel mapping and corrections of the Eq. 11 analysis (vibrometer delay, mass
        cancellation, baseline, sample rate for CSV without time column). A file's sidecar
        row may state its own (:mod:`pidcore.file_settings`); they replace these except the
        fields named in ``options_given``.
    options_given : mapping, optional
        Fields of ``options`` given explicitly -> their names in notes (``--velocity-delay``):
        they override the sidecar's values, and a note says where one differs. Default: the
        fields of ``options`` that differ from the defaults.
    tolerances : Tolerances, optional
        Grid-match tolerances.
    specimen : pidcore.specimen.Specimen, optional
        Only DEM runs of this specimen are compared (default: the paper's coupon); the
        paper's Table 3 only when it is the paper's coupon.
    pool : bool
        Pool DEM runs of different settings at one load case (default: separate rows; see
        :func:`pidcore.report.build_report_table`); tests of different specimens are never
        pooled.
    calibration : path, optional
        A ``calibration.json`` of ``pidcore calibrate``, or a store holding calibrations
        (:mod:`pidcore.calibrate.persist`): each row it predicts gets the calibrated DEM's
        Eq. 11 SDC with its 95 % band and whether the measured Eq. 11 SDC lies inside
        (:func:`pidcore.report.table.add_calibration_columns`).
    calibration_key : str, optional
        Which of the store's calibrations (a store holding one needs none).
    accept_implausible : bool
        Keep (noted) a file's result the plausibility checks refuse (:func:`analyze_files`).
    progress : bool
        Bars on stderr over the files analysed and the figures and formats written (forty
        files: 40-50 s, most of it figures and PDF, with no sign of life).
    key : str, optional
        Which measurement of a pidcore HDF5 store among ``files`` to read, where it holds
        several (its refusal lists them; :func:`analyze_files`).
    case_sheets : bool
        Also write the PDF sheet of every measured load case into ``out_dir/cases``, as the
        app's Compare page prints it (:func:`report_case_sheets`), judged by ``calibration``
        as the rows are; listed in the provenance. Not with ``pool`` (the page never pools
        specimens, so its sheets would not be the rows), nor with ``tolerances`` other than
        the defaults (the page's).
    wording : callable, optional
        The notes (the table's, its rows' and the report's) in a front-end's words: it names
        the parameters the library names by keyword (``structure_mass_kg``) as its own
        (``--structure-mass``: :func:`pidcore.cli._vocabulary.cli_words`). Default: the
        keywords of this function and :class:`AnalysisOptions`.

    Returns
    -------
    ReportResult
    """
    from ..measure import AnalysisOptions, refuse_store_among_inputs, save_analyses

    formats = parse_formats(formats)
    if case_sheets and pool:
        raise ParameterError("case_sheets=True: not with pool=True (a sheet is one load case of "
                             "one specimen, as the app's Compare page prints it; a pooled row "
                             "has no such sheet)")
    if case_sheets and tolerances is not None and tolerances != Tolerances():
        # the page meets a case's DEM run within the default tolerances: a row met within
        # wider ones (103 Hz at the 100 Hz run) had an interpolated DEM SDC on its sheet
        raise ParameterError(f"case_sheets=True: not with tolerances={tolerances} (a sheet is "
                             "the app's Compare page's, which meets DEM runs within the "
                             f"default {Tolerances()}; its DEM value would not be the row's)")
    calibrated = None
    if calibration is not None:  # checked before anything is analysed or written
        from ..calibrate.prediction import load_calibration

        try:
            calibrated = load_calibration(calibration, key=calibration_key)
        except ParameterError as exc:  # load_calibration's key is this one's calibration_key
            raise type(exc)(str(exc).replace("with key=KEY", "with calibration_key=KEY")) \
                from None
    elif calibration_key is not None:
        raise ParameterError(f"calibration_key={calibration_key}: give the store holding it "
                             "as calibration=PATH")
    out_dir = Path(out_dir)
    # a hidden earlier report back before the check (write_report would do it silently)
    restored = restore_previous_report(out_dir) is not None
    check_out_dir(out_dir)
    # the report is built beside out_dir (a link's folder) and renamed into place
    check_folder_can_be_made(real_folder(out_dir))
    tolerances = tolerances or Tolerances()
    files = [Path(f) for f in files]
    if not files and store is None and dem_store is None:
        raise StoreError("nothing to report: give measurement files, store=PATH or dem_store=PATH")
    if not files:
        # they would be ignored: stored analyses keep the load case and corrections they had
        stated = [keyword for keyword, value in (("fill_percent", fill_percent),
                                                 ("material=", material),
                                                 ("direction=", direction),
                                                 ("sidecar=", sidecar))
                  if value is not None]
        if options is not None and options != AnalysisOptions():
            stated.append("analysis options (velocity_delay_s, force=NAME, ...)")
        if stated:
            raise ParameterError(f"{', '.join(stated)}: only with measurement FILES (stored "
                                 "analyses keep the load case and corrections they were "
                                 "saved with)")
    main = (open_verified_store(store, must_exist=not files, progress=progress)
            if store is not None else None)
    dem_paths = _dem_paths(store, dem_store)
    dems = [main if (main is not None and p == Path(store)) else
            open_verified_store(p, must_exist=True, progress=progress) for p in dem_paths]
    dem_path = " and ".join(map(str, dem_paths)) or None  # as the notes name the runs' stores

    from ..store.listing import checked_analyses

    held = None  # the store's records before this report saves any
    if main is not None:
        refuse_store_among_inputs(main, files)  # before reading (it may hold many measurements)
        # a damaged record is refused before the files are analysed into the store
        held = checked_analyses(main.list_analyses(), main.path)
        if files:  # their analyses are added to it
            main.check_writable()
    from ..compare.plausibility import plausibility_notes, stated_sdc_bounds
    from ..file_settings import assumed, files_assumption_notes

    options = options or AnalysisOptions()
    results = analyze_files(
        files, fill_percent=fill_percent, material=material, direction=direction,
        sidecar=sidecar, options=options, options_given=options_given,
        specimen_material=specimen.particles.material if specimen is not None else None,
        specimen_name=specimen.name if specimen is not None else None, specimen=specimen,
        accept_implausible=accept_implausible, progress=progress, key=key,
        keep_unused_channels=main is not None,  # a store saves every channel of each file
    ) if files else []
    parameters = _parameters(results, options)
    notes: list[str] = [calibrated.read_note] if calibrated and calibrated.read_note else []
    for r in results:
        said = r.settings.summary() if r.settings is not None else ""
        notes.append(f"{display_path(r.path.name)}: load case {r.load_case.key} ({r.stated.origin})"
                     + (f"; {said}" if said else ""))
        # what the reader corrected or assumed (a time column without a unit taken as s, a
        # spreadsheet's empty rows left out), as `analyze` prints it: the report said nothing
        notes.extend(str(n).replace(str(r.path), display_path(r.path.name))
                     for n in r.measurement.metadata.get("reader_notes", ()) or ())
        # what the plausibility checks found (a result kept as asked, or zero within noise)
        notes.extend(f"{display_path(r.path.name)}: {n}"
                     for n in plausibility_notes(r.analyzed.analysis, bound=stated_sdc_bounds(
                         [r.stated], [r.settings], specimen)[0]))
        notes.extend(r.stated.notes)
        if r.settings is not None:
            notes.extend(r.settings.notes)
            if r.settings.unmatched:
                notes.append(r.settings.unmatched)
            named = r.settings.specimen
            if specimen is not None and named and named != specimen.name:
                # the sidecar's specimen is the file's (as an app upload's is kept): it meets
                # only DEM runs of that name, not the --specimen's
                notes.append(f"{display_path(r.path.name)}: its sidecar row names specimen "
                             f"{named!r}, not {specimen.name!r} (specimen=); compared as "
                             f"{named!r}")
    # said once for the files it holds for, counted (as a store's records are below): five
    # exports naming no specimen gave the same sentence five times
    notes.extend(files_assumption_notes([(display_path(r.path.name), assumed(
        r.stated, r.settings.specimen if r.settings is not None else "", specimen))
        for r in results]))
    if len(results) < len(files):
        kept = {r.path for r in results}
        notes += [f"{display_path(f.name)}: identical contents to another file given; counted once"
                  for f in files if f not in kept]
    listed = None  # the store's every record: which file a hashless one is of
    if main is not None and results:
        # Same entry as `pidcore analyze` for the same file and options (replaced, not
        # duplicated), with the load case fields
        saved = save_analyses(main, [r.analyzed for r in results],
                              [r.settings.options if r.settings is not None else options
                               for r in results],
                              [(r.path.name, r.load_case, r.stated.origin) for r in results],
                              # with the bound each was judged with, as analyze saves it
                              fields=[{**r.fields(), **stated_sdc_bounds(
                                  [r.stated], [r.settings], specimen)[0].as_record()} or None
                                  for r in results])
        keys = saved.keys
        notes += saved.notes
        listed = main.list_analyses()
        analyses = listed[listed["key"].isin(keys)]
        analyses = analyses.set_index("key").loc[keys].reset_index()  # order of the files
    elif main is not None:
        listed = held  # nothing saved since it was read
        analyses = latest_per_measurement(listed)
        notes.extend(stored_records_notes(listed, analyses, specimen))
    else:
        analyses = measured_frame(results)
        # not stored: the analyses' own corrections say how the baseline went off
        whole = whole_mass_baseline_note(r.analyzed.analysis.corrections for r in results)
        if whole:
            notes.append(whole)

    dem_runs = joined_runs = _joined_dem_runs(dems)
    if not results:  # the stored records' own settings, not the unused options' defaults
        parameters = stored_parameters(analyses)
    from ..calibrate.persist import calibration_design_runs

    # a calibration's runs are saved in its --dem-store, beside the calibration itself
    built = specimen_report_table(dem_runs, analyses, specimen=specimen, where=dem_path,
                                  tolerances=tolerances, pool=pool, store_analyses=listed,
                                  design_runs=calibration_design_runs(dem_runs, dem_paths))
    table, dem_runs, aligner = built.table, built.dem_runs, built.aligner
    if calibrated is not None:
        table = add_calibration_columns(table, calibrated, tolerances=tolerances,
                                        specimen=specimen, paper=specimen is None)
    notes.extend(table.attrs.get("notes", []))
    loops = measured_loops(results, analyses, main, notes)
    figures = report_figures(table, dem_runs, aligner, loops, dems, notes)
    if wording is not None:
        table, notes = worded(table, notes, wording)
    try:
        seeds = []
        if dem_runs is not None and "seed" in dem_runs.columns:
            seeds = [int(s) for s in dem_runs["seed"] if s is not None and not (
                isinstance(s, float) and math.isnan(s))]
        stores = [p for p in dict.fromkeys((*([Path(store)] if store else []), *dem_paths))
                  if p.exists()]
        sheets = report_case_sheets(results, analyses, main, joined_runs, dem_paths, specimen,
                                    calibrated, table, built.paper,
                                    progress=progress) if case_sheets else []
        provenance = collect_provenance(
            parameters={**parameters,
                        "frequency_rtol": tolerances.frequency_rtol,
                        "acceleration_rtol": tolerances.acceleration_rtol,
                        "fill_atol_percent": tolerances.fill_atol_percent, "pool": pool},
            # the load-case table too: its rows set the load case and the settings (the
            # bundled 500 Hz sample's SDC is 4.09 with its 50 µs delay, 2.81 without)
            seeds=seeds, inputs=[*(r.path for r in results), *_tables_read(results, sidecar)],
            input_hashes={str(r.path): getattr(r.measurement, "sha256", "") for r in results},
            stores=stores, notes=notes, specimens=specimen_provenance(specimen, table),
            calibrations=calibration_provenance(calibrated),
            case_sheets=[(f"{CASE_SHEETS_FOLDER}/{s.name}", s.title, s.pdf) for s in sheets])
        saved = (f"; the analyses of the {len(results)} file(s) were saved to {store} "
                 "before it (whole)" if main is not None and results else "")
        with refused_unless_written(out_dir, "the report", then=saved):
            paths = write_report(table, figures, provenance, out_dir, formats,
                                 progress=progress, case_sheets={s.name: s.pdf for s in sheets})
    finally:
        for fig in figures.values():  # bare Figures: drop references to free Agg buffers
            fig.clear()
    if restored:  # of this run, not of the report: after its provenance took the notes
        note = restored_report_note(out_dir)
        notes = [*notes, wording(note) if wording is not None else note]
    return ReportResult(paths, table, results, notes)
