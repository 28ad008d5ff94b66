"""The report's main table: our DEM, our measurements and the paper, per load case (Table 3 style).

Rows are the union of our DEM grid cases and the measured cases. A measured case that matches a
DEM grid case (:mod:`pidcore.compare.align`) shares its row; those that do not are grouped as
the Compare page groups them (:func:`pidcore.compare.case.group_load_cases`, within the
tolerances of each other), each group a row of its own at its pooled load case with our DEM
value interpolated there by the pchip model (or none, out of range). Numbers are copied
from the inputs unchanged; only runs of one case and settings (seeds) and measurements of one
case and specimen are pooled (:func:`pidcore.compare.pooled_mean`); stored runs that are the
same simulation (:func:`pidcore.compare.align.simulation_identity`) count once, which the row's
note says. DEM runs of different
numerical settings get rows of their own unless ``pool=True`` (``pidcore report --pool``),
which the row's note then says; measurements of different specimens always do.

The difference column compares like with like: the measured energy per cycle over the DEM
case's E = m_c a^2 / (2 w^2) (Eq. 10), as our DEM SDC is defined, minus our DEM SDC.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd

from .. import defaults
from ..compare.align import (
    ALIGNMENT_STATUSES,
    CALIBRATED_BAND_COLUMN,
    CALIBRATED_COLUMN,
    CALIBRATED_HIGH_COLUMN,
    CALIBRATED_INSIDE_COLUMN,
    CALIBRATED_LOW_COLUMN,
    MEASURED_BASELINE_COLUMN,
    MEASURED_COLUMNS_RENAMED,
    MEASURED_EQ10_COLUMN,
    MEASURED_EQ11_COLUMN,
    MEASURED_EQ11_DOF_COLUMN,
    MEASURED_EQ11_STDERR_COLUMN,
    PACKING_RATIO_COLUMN,
    Aligner,
    DemCase,
    Tolerances,
    consistency_chi2,
    duplicates_note,
    interpolated_count_and_mass,
    match_paper,
    pooled_baseline_sdc,
    pooled_mean,
    pooled_sdc_eq10,
    pooled_stderr_dof,
    same_count_note,
    stored_stderr_dof,
)
from ..compare.case import group_load_cases, pooled_load_case
from ..compare.loadcase import LoadCase, LoadCaseError
from ..compare.plausibility import stored_findings
from ..compare.specimens import (
    NOT_PAPER_SPECIMEN_NOTE,
    runs_for_measurement,
)
from ..constants import BAND_VERDICTS
from ..errors import instance_of
from ..signal.power import baseline_sdc_taken_off
from ..specimen import (
    MEASURED_SHA256_FIELD,
    hashed_name,
    is_paper_coupon,
    match_hashless_records,
)
from ..units import g_to_si

#: Measured (Eq. 10 energy, as :data:`MEASURED_EQ10_COLUMN`) minus our DEM SDC: the same SDC on
#: both sides. NaN where the DEM case's m_c is unknown (no like-for-like value).
DIFFERENCE_COLUMN = "difference measured (E of Eq. 10) - ours [-]"
#: Chi-square per degree of freedom of the pooled measurements about their mean (~1: they agree
#: within their errors; NaN for a single measurement).
CONSISTENCY_COLUMN = "measured chi2/dof [-]"
#: The measured Eq. 11 SDC, its standard error and that error's degrees of freedom
#: (:data:`pidcore.compare.align.MEASURED_EQ11_COLUMN`, defined there for every table of
#: pidcore): named "SDC measured [-]" before, beside "SDC DEM (ours) [-]" in the HTML, Markdown
#: and LaTeX files, while the PDF and the terminal called the one column
#: "SDC measured (Eq. 11) [-]". Report columns renamed: old name -> new name, for scripts
#: reading a report.csv of an earlier pidcore
#: (``pd.read_csv(path).rename(columns=REPORT_COLUMNS_RENAMED)``).
REPORT_COLUMNS_RENAMED: dict[str, str] = dict(MEASURED_COLUMNS_RENAMED)
#: Column holding the alignment status; the header lists its values,
#: :data:`pidcore.compare.ALIGNMENT_STATUSES`.
ALIGNMENT_COLUMN = f"alignment [{'/'.join(ALIGNMENT_STATUSES)}]"
#: The sha256 of the specimen file a row's measurements recorded (``specimen_sha256``): empty
#: where they recorded only its name (saved without a specimen file, or by an older pidcore)
#: and for the paper's coupon (one coupon of either table material): matched by name. Two
#: files of one name get rows of their own.
SPECIMEN_SHA256_COLUMN = "specimen sha256"
#: Columns of :func:`build_report_table`, in order.
REPORT_COLUMNS: tuple[str, ...] = (
    "frequency [Hz]", "acceleration [g]", PACKING_RATIO_COLUMN, "material", "direction",
    "particles per cell [-]", "DEM runs [-]", "SDC DEM (ours) [-]", "SDC DEM stderr [-]",
    "measured frequency [Hz]", "measured acceleration [g]", MEASURED_EQ11_COLUMN,
    MEASURED_EQ11_STDERR_COLUMN, MEASURED_EQ11_DOF_COLUMN, MEASURED_BASELINE_COLUMN,
    MEASURED_EQ10_COLUMN, "SDC DEM (paper) [-]",
    "SDC measured (paper) [-]",
    "difference ours - paper DEM [-]", DIFFERENCE_COLUMN, CONSISTENCY_COLUMN, ALIGNMENT_COLUMN,
    "DEM settings", "specimen", SPECIMEN_SHA256_COLUMN, "source file(s)", "load case", "note",
)
#: Columns besides the load case's numbers that give a row of its own (:func:`build_report_table`
#: keeps another material, drive axis, DEM settings, specimen or specimen file apart, and sorts
#: by them): what tells two rows of one frequency, acceleration and fill apart.
ROW_IDENTITY_COLUMNS: tuple[str, ...] = ("material", "direction", "DEM settings", "specimen",
                                         SPECIMEN_SHA256_COLUMN)


def differing_columns(table: pd.DataFrame) -> list[str]:
    """Those :data:`ROW_IDENTITY_COLUMNS` of ``table`` in which its rows hold more than one
    value, an empty cell not counted (a measured row without DEM runs has no DEM settings: it
    differs from a DEM row in its alignment, not its settings)."""
    out = []
    for column in ROW_IDENTITY_COLUMNS:
        if column in table.columns:
            values = {str(v) for v in table[column] if isinstance(v, str) and v}
            if len(values) > 1:
                out.append(column)
    return out


def shared_identity(table: pd.DataFrame) -> dict[str, str]:
    """Those :data:`ROW_IDENTITY_COLUMNS` of ``table`` whose every row states one value, by
    that value. An empty cell is not that value: a test of ``steel_6mm`` named only (no
    sha256) beside tests of a file's specimen does not share that file's sha256, nor a row
    of no DEM runs the others' DEM settings."""
    out = {}
    for column in ROW_IDENTITY_COLUMNS:
        if column in table.columns and len(table):
            values = {v if isinstance(v, str) else "" for v in table[column]}
            if len(values) == 1 and "" not in values:
                out[column] = values.pop()
    return out


#: Columns an analyses table needs (as :meth:`pidcore.store.Store.list_analyses` gives, with the
#: load case fields the report pipeline stores in each record).
ANALYSIS_COLUMNS: tuple[str, ...] = ("frequency_hz", "acceleration_g", "fill_percent", "sdc",
                                     "sdc_stderr")
#: ``table.attrs`` key of :func:`build_report_table`'s table: per row, the positions in the
#: analyses table of the records its measured columns pool (empty for a DEM-only row), so
#: that a load case's sheet (``pidcore report --case-sheets``) pools exactly its row's records.
MEASURED_RECORDS_ATTR = "measured_records"


class _Measured(NamedTuple):
    """One measured record in a row, in the units of the analyses table."""

    sdc: float
    sdc_stderr: float
    frequency_hz: float
    acceleration_g: float
    source: str
    energy_per_cycle_j: float
    specimen: str
    #: the first plausibility warning beyond noise of the record (kept as accepted), or ""
    implausible: str = ""
    #: degrees of freedom of sdc_stderr (the analysis's n_blocks - 1; NaN: unknown)
    sdc_stderr_dof: float = math.nan
    #: the part of sdc taken off as the empty coupon's damping
    #: (:func:`pidcore.signal.power.baseline_sdc_taken_off`; NaN: taken off, amount unknown)
    baseline_sdc: float = 0.0
    #: its position in the analyses table (:data:`MEASURED_RECORDS_ATTR`)
    position: int = -1


@dataclass
class _Row:
    case: LoadCase
    status: str
    dem: DemCase | None = None
    sdc_dem: float = math.nan
    sdc_dem_stderr: float = math.nan
    paper_dem: float = math.nan
    paper_exp: float = math.nan
    measured: list[_Measured] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    specimen: str | None = None  # None: no measurement claimed the row yet
    specimen_sha256: str = ""  # of the file its measurements recorded ("" : by name)
    unconverged_nodes: tuple[str, ...] = ()  # interpolated from runs that did not converge
    # an interpolated row's own particle count and m_c (a grid row's are its DEM case's), or
    # why they are unknown
    particles_per_cell: int | None = None
    vibrated_mass_kg: float = math.nan
    no_mass_reason: str = ""


def _measured_rows(analyses: pd.DataFrame | None,
                   notes: list[str]) -> list[tuple[LoadCase, pd.Series, int]]:
    """(load case, record, its position in ``analyses``) of each analysis stating a fill."""
    if analyses is None or analyses.empty:
        return []
    missing = [c for c in ANALYSIS_COLUMNS if c not in analyses.columns]
    if "fill_percent" in missing:
        notes.append(f"{len(analyses)} analysed record(s) have no fill stated; not in the table")
        return []
    if missing:
        raise LoadCaseError(f"analyses table: missing columns {missing}; expected "
                            f"{list(ANALYSIS_COLUMNS)}")
    out = []
    for position, (_, row) in enumerate(analyses.iterrows()):
        source = str(row.get("source", "") or row.get("key", ""))
        fill = float(row["fill_percent"]) if row["fill_percent"] is not None else math.nan
        if not math.isfinite(fill):
            notes.append(f"{source}: no fill stated; not in the table")
            continue
        material = row.get("material") or "acrylic"
        direction = row.get("direction") or "z"
        try:
            case = LoadCase(float(row["frequency_hz"]), float(row["acceleration_g"]), fill,
                            str(material), str(direction))
        except LoadCaseError as exc:
            # a stored material 'x/../../pwned' said "load case: particle material ... is not a
            # name", naming neither the record nor its file
            key = row.get("key")
            raise LoadCaseError(f"{source}{f' (analysis {key})' if key else ''}: {exc}") from None
        out.append((case, row, position))
    return out


def no_runs_note(of: str, material: str, direction: str, store_runs: pd.DataFrame | None,
                 choose_another: str = "", *, named: bool = False, report_of: str = "") -> str:
    """Why a measured row has no DEM value: no run of its specimen ``of`` at its material and
    direction, and the runs of other specimens the store holds there (which are another
    specimen's, so not compared), e.g. "no DEM runs of steel_6mm for acrylic, direction z
    (the store has 48 of paper_coupon, another specimen's: report without --specimen to
    compare them)". ``choose_another``: how the reader compares them (default: the CLI's
    words); ``named``: the measurement names ``of`` itself (its record's specimen), so no
    choice of the report's specimen compares it with the others' runs; ``report_of``: the
    name of the specimen the report is of (its runs are chosen by hash: runs of ``of`` left
    out of a report of a file named ``of`` are another file's of that name)."""
    from ..compare.specimens import (
        are_calibration_variants,
        run_specimen_labels,
        runs_per_specimen_text,
    )
    from ..specimen import PAPER_SPECIMEN_NAME

    note = f"no DEM runs of {of or 'ours'} for {material}, direction {direction}"
    if store_runs is None or store_runs.empty or not {"material", "direction"} <= set(
            store_runs.columns):
        return note
    there = store_runs[(store_runs["material"] == material)
                       & (store_runs["direction"] == direction)]
    if there.empty:
        return note
    labels = run_specimen_labels(there)
    counts = labels.value_counts(sort=False)
    # runs of the specimen the measurement names are in the store, left out only because the
    # report is of another specimen: "another specimen's: not compared with a test of X" was
    # said of X's own runs
    own = named and bool(((labels == of) if of == PAPER_SPECIMEN_NAME
                          else (labels == of)
                          | (there.get("specimen_name", pd.Series(dtype=object)) == of)).any())
    if named and not own:
        choose_another = f"not compared with a test of {of}"
    elif not choose_another:
        choose_another = ("report without specimen= to compare them"
                          if set(counts.index) == {PAPER_SPECIMEN_NAME}
                          else "report with their specimen=FILE to compare them")
    # a calibration's variants named as such: "3 of x [7167f7]" read as an edited x.toml
    listed = runs_per_specimen_text(there)
    if own and of != PAPER_SPECIMEN_NAME and report_of == of:
        named_of = there[there["specimen_name"] == of] if "specimen_name" in there.columns \
            else there.iloc[:0]
        if not named_of.empty and are_calibration_variants(named_of).all():
            return (f"{note} among this report's runs (the store has {listed}: a "
                    f"calibration's variants, not a file named {of} as given; "
                    f"{choose_another})")
        # by name the runs are the test's specimen's, but the report's runs are chosen by the
        # file's hash: they are of another file of that name (an edited x.toml). "x's are
        # left out of a report of another specimen" was said of a report of x
        return (f"{note} among this report's runs (the store has {listed}: another file named "
                f"{of} than the one reported, whose hash differs; {choose_another})")
    if own:
        return (f"{note} among this report's runs (the store has {listed}; {of}'s are left "
                f"out of a report of another specimen: {choose_another})")
    return f"{note} (the store has {listed}, another specimen's: {choose_another})"


def _paper_dem_gap(case: LoadCase, paper: pd.DataFrame | None,
                   tolerances: Tolerances) -> str:
    """Why the paper's DEM column of a row at a Table 3 load case is empty: the printed table
    has no DEM value there (1000 Hz, 1 g, 90 %: the transcription keeps the row empty); "" where
    the row is no Table 3 point or the table has a value."""
    dem, _, point = match_paper(case, paper, tolerances=tolerances)
    if point is None or not math.isnan(dem):
        return ""
    return (f"the paper's Table 3 prints no DEM value at {point.label()}: no paper DEM SDC "
            "and no difference ours - paper DEM here")


def build_report_table(dem_runs: pd.DataFrame | None, analyses: pd.DataFrame | None,
                       paper: pd.DataFrame | None, *, model: object | None = None,
                       tolerances: Tolerances | None = None,
                       pool: bool = False, store_runs: pd.DataFrame | None = None,
                       of_specimen: str = "", choose_another: str = "",
                       tested_files: Mapping[str, str] | None = None,
                       store_analyses: pd.DataFrame | None = None) -> pd.DataFrame:
    """Table 3-style comparison of our DEM, our measurements and the paper.

    Parameters
    ----------
    dem_runs : pandas.DataFrame or None
        Our DEM runs, one row each (:meth:`pidcore.store.Store.list_dem_runs`): columns
        ``frequency_hz``, ``acceleration_g``, ``fill_percent``, ``material``, ``direction``,
        ``sdc``, ``sdc_stderr``, optionally ``particles_per_cell`` and ``key``.
    analyses : pandas.DataFrame or None
        Our measurements, one row each (:meth:`pidcore.store.Store.list_analyses`): columns
        ``frequency_hz``, ``acceleration_g``, ``fill_percent``, ``sdc``, ``sdc_stderr``,
        optionally ``material``, ``direction``, ``source``.
    paper : pandas.DataFrame or None
        The paper's Table 3 (:func:`pidcore.model.load_paper_table3`).
    model : SdcModel, optional
        pchip model for measured cases off our DEM grid; default: built from ``dem_runs`` per
        material and direction.
    tolerances : Tolerances, optional
        Grid-match tolerances (default from :mod:`pidcore.defaults`).
    pool : bool
        Pool DEM runs of different numerical settings at one load case (default: separate
        rows); measurements of different specimens stay rows of their own either way.
    store_runs : pandas.DataFrame, optional
        Every DEM run of the store, ``dem_runs`` being one specimen's of them: a measured row
        with no run of its specimen at its material and direction (alignment ``no_dem_runs``)
        names the other specimens' runs there (:func:`no_runs_note`). Default: ``dem_runs``.
    of_specimen : str
        The specimen ``dem_runs`` are of, named in those notes for a measurement that names
        none (default: "ours").
    choose_another : str
        How those notes say the other specimens' runs are compared (default: the CLI's words).
    tested_files : Mapping[str, str], optional
        Specimen name -> sha256 of the specimen file the report is of: a record of that name
        saved without its file's hash joins the tests of its name's one file only where that
        file is this one (:func:`pidcore.specimen.match_hashless_records`).
    store_analyses : pandas.DataFrame, optional
        Every analysis of the store ``analyses`` are some of (a report of chosen files):
        their specimens and hashes decide that rule too, so that the choice does not change
        which file a hashless record is of. Default: ``analyses``.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`REPORT_COLUMNS`, sorted by frequency, acceleration, fill (as Table 3).
        ``table.attrs["notes"]`` lists records left out and why.

    Examples
    --------
    >>> import pandas as pd
    >>> dem = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [5.0],
    ...                     "fill_percent": [50.0], "material": ["acrylic"], "direction": ["z"],
    ...                     "sdc": [0.52], "sdc_stderr": [0.01]})
    >>> from pidcore.model import load_paper_table3
    >>> t = build_report_table(dem, None, load_paper_table3())
    >>> round(float(t.loc[0, "difference ours - paper DEM [-]"]), 6)  # 0.52 - 0.5417
    -0.0217
    """
    # a Store given for its listing failed with AttributeError from inside
    for name, table, listing in (("dem_runs", dem_runs, "Store.list_dem_runs()"),
                                 ("analyses", analyses, "Store.list_analyses()"),
                                 ("paper", paper, "pidcore.model.load_paper_table3()")):
        instance_of(name, table, (pd.DataFrame, type(None)), hint=f"e.g. {listing}")
    return report_table_and_aligner(dem_runs, analyses, paper, model=model,
                                    tolerances=tolerances, pool=pool, store_runs=store_runs,
                                    of_specimen=of_specimen, choose_another=choose_another,
                                    tested_files=tested_files,
                                    store_analyses=store_analyses)[0]


def report_table_and_aligner(dem_runs: pd.DataFrame | None, analyses: pd.DataFrame | None,
                              paper: pd.DataFrame | None, *, model: object | None = None,
                              tolerances: Tolerances | None = None,
                              pool: bool = False, store_runs: pd.DataFrame | None = None,
                              of_specimen: str = "", choose_another: str = "",
                              given_specimen: object | None = None,
                              tested_files: Mapping[str, str] | None = None,
                              store_analyses: pd.DataFrame | None = None,
                              ) -> tuple[pd.DataFrame, Aligner]:
    """:func:`build_report_table` and the aligner of its DEM rows (the runs it counted, its
    pchip models), for figures that must show what the table compared. ``given_specimen``:
    the specimen file given (``--specimen``), whose tests are judged against its SDC bound
    (:func:`pidcore.compare.plausibility.stored_sdc_bound`)."""
    tolerances = tolerances or Tolerances()
    notes: list[str] = []
    measured_rows = _measured_rows(analyses, notes)
    # of stored runs that are one simulation, the one nearest the measured fill is counted
    # and names the row (a 50.2 % duplicate beside 50 % runs must not label a 50 % row)
    fills = [case.fill_percent for case, _, _ in measured_rows]
    aligner = Aligner.from_tables(dem_runs, paper, model=model, tolerances=tolerances,
                                  pool_settings=pool, reference_fills=fills)
    rows: dict[str, list[_Row]] = {}
    for dem in aligner.cases:
        paper_dem, paper_exp, _ = match_paper(dem.load_case, paper, tolerances=tolerances)
        rows.setdefault(dem.load_case.key, []).append(
            _Row(dem.load_case, "grid", dem, dem.sdc, dem.sdc_stderr, paper_dem, paper_exp))
    # a measurement meets only the DEM runs of its specimen (pidcore.compare.specimens); one
    # aligner per (specimen, material, direction) over those runs
    aligners: dict[tuple[str, str, str, str], tuple[Aligner, str, bool, str]] = {}
    # each one's DEM runs
    aligner_runs: dict[tuple[str, str, str, str], pd.DataFrame | None] = {}
    # its file's hash where it decides ("" for the paper's coupon, one coupon of either
    # material: by name); a record saved before the hash was joins its name's one file, or
    # stays apart (by name) where the name means two: calibrate and Compare decide alike
    # (a store's listing holds NaN where a record names no specimen and another does)
    matched = match_hashless_records(
        [rec.get("specimen", "") for _, rec, _ in measured_rows],
        [rec.get(MEASURED_SHA256_FIELD, "") for _, rec, _ in measured_rows],
        given=tested_files, others=[] if store_analyses is None
        or "specimen" not in store_analyses.columns else list(zip(
            store_analyses["specimen"], store_analyses.get(
                MEASURED_SHA256_FIELD, pd.Series([""] * len(store_analyses),
                                                 index=store_analyses.index)), strict=True)))
    def meet(case: LoadCase, specimen: str, sha256: str
             ) -> tuple[Aligner, pd.DataFrame | None, str, bool, str]:
        """The aligner of the DEM runs a test of ``specimen`` at ``case`` meets, its runs,
        the note on them, whether they were refused, and whose runs a calibrated file met."""
        if dem_runs is None or dem_runs.empty:
            return aligner, dem_runs, "", False, ""
        which = (specimen, case.material, case.direction, sha256)
        if which not in aligners:
            met = runs_for_measurement(dem_runs, *which)
            # the row's specimen column names the test's specimen: say whose runs it met
            calibrated = (f"a test of {met.calibrated_from} compared with the DEM runs of "
                          f"{met.specimen}, the file pidcore calibrate made from it"
                          if met.calibrated_from else "")
            aligners[which] = (Aligner.from_tables(met.runs, paper, model=model,
                                                   tolerances=tolerances, pool_settings=pool,
                                                   reference_fills=fills),
                               met.note if met.runs is None else "", met.refused,
                               calibrated)
            aligner_runs[which] = met.runs
        own, met_note, refused, met_calibrated = aligners[which]
        return own, aligner_runs[which], met_note, refused, met_calibrated

    # pool=True pools DEM settings, never tests of different specimens: a pooled test of
    # another specimen lost its name and met the report's specimen's runs
    specimens = ["" if not isinstance(rec.get("specimen", ""), str)
                 else rec.get("specimen", "") for _, rec, _ in measured_rows]
    met_runs = [meet(case, specimen, sha256) for (case, _, _), specimen, sha256
                in zip(measured_rows, specimens, matched.sha256, strict=True)]
    # repeated tests off the DEM grid differ by noise (2000 Hz at 4.99998 g and 5.00002 g):
    # keyed by their own load cases they were rows of their own, where a grid case pools such
    # tests and the Compare page pools them too. They are grouped by the page's rule, per
    # specimen and the runs they meet, and each group aligned at its pooled load case.
    row_cases = [case for case, _, _ in measured_rows]
    off_grid: dict[tuple[int, str, str], list[int]] = {}
    for i, (case, specimen, sha256, met) in enumerate(zip(
            row_cases, specimens, matched.sha256, met_runs, strict=True)):
        if met[0].grid_case(case) is None:
            off_grid.setdefault((id(met[0]), specimen, sha256), []).append(i)
    for members in off_grid.values():
        for group in group_load_cases([row_cases[i] for i in members], tolerances):
            pooled_case = pooled_load_case([row_cases[members[j]] for j in group])
            for j in group:
                row_cases[members[j]] = pooled_case
    for (case, rec, position), specimen, sha256, name_note, row_case, met in zip(
            measured_rows, specimens, matched.sha256, matched.notes, row_cases, met_runs,
            strict=True):
        own, own_runs, met_note, refused, met_calibrated = met
        aligned = own.align(row_case)
        if aligned.status == "no_dem_runs" and not refused:
            # name whose runs are missing and whose the store holds there instead: another
            # specimen's, never compared with this measurement ("of ours" alone misled when a
            # row of those runs stood just above)
            # the test's file by name and hash where it recorded one: "no DEM runs of
            # panel" beside a store of panel's runs named no difference
            shown = specimen
            if specimen and not specimen.endswith("]") and sha256:
                shown = hashed_name(specimen, sha256)
            aligned = replace(aligned, message=no_runs_note(
                shown or of_specimen, case.material, case.direction,
                dem_runs if store_runs is None else store_runs, choose_another,
                named=bool(specimen), report_of=of_specimen))
            met_note = ""
        found, _ = stored_findings(rec, given=given_specimen)
        entry = _Measured(float(rec["sdc"]), float(rec["sdc_stderr"]), case.frequency_hz,
                          case.acceleration_g, str(rec.get("source", "")),
                          float(rec.get("energy_per_cycle_j", math.nan)), specimen,
                          found[0].message if found else "",
                          stored_stderr_dof(rec.get("sdc_stderr_dof")),
                          baseline_sdc_taken_off(rec), position)
        base = None
        if aligned.status == "grid" and aligned.grid_case is not None:
            dem = aligned.grid_case
            group = rows[dem.load_case.key]
            # the same runs, grouped alike (settings name the specimen's hash)
            base = next((r for r in group if r.dem is not None and (
                r.dem.run_keys, r.dem.settings, r.dem.n_runs, r.dem.sdc) == (
                dem.run_keys, dem.settings, dem.n_runs, dem.sdc)), None)
            if base is None:
                base = _Row(dem.load_case, "grid", dem, dem.sdc, dem.sdc_stderr,
                            *match_paper(dem.load_case, paper, tolerances=tolerances)[:2])
        if base is None:
            group = rows.setdefault(row_case.key, [])
            # Table 3 describes the paper's coupon: a test of another specimen showed its
            # values (and the paper's measurement) as if they were that coupon's
            paper_values = (aligned.sdc_paper_dem, aligned.sdc_paper_experimental)
            not_paper = []
            # by name, even where the record saved its file's hash: a test of another file of
            # the coupon's name is saved as "paper_coupon [45d792]", and a calibrated file of
            # the coupon (another hash) is a model of the coupon tested
            if not is_paper_coupon(specimen) and np.isfinite(paper_values).any():
                paper_values = (math.nan, math.nan)
                not_paper = [NOT_PAPER_SPECIMEN_NOTE.format(name=specimen)]
            base = _Row(row_case, aligned.status, None, aligned.sdc_dem,
                        aligned.sdc_dem_stderr,
                        *paper_values,
                        notes=[aligned.message] + ([met_note] if met_note else []) + not_paper,
                        unconverged_nodes=aligned.unconverged_nodes)
            if aligned.status == "interpolated":
                # the specimen and fill fix its count and m_c, as a DEM run there would
                (base.particles_per_cell, base.vibrated_mass_kg,
                 base.no_mass_reason) = interpolated_count_and_mass(own_runs, row_case)
        # two files of one name are two specimens: their tests are not pooled
        row = next((r for r in group if r.dem is base.dem and r.specimen == specimen
                    and r.specimen_sha256 == sha256), None)
        if row is None:
            row = next((r for r in group if r.dem is base.dem and r.specimen is None), None)
        if row is None:  # another specimen at this case: a row of its own beside the DEM's
            row = _Row(base.case, base.status, base.dem, base.sdc_dem, base.sdc_dem_stderr,
                       base.paper_dem, base.paper_exp, notes=list(base.notes),
                       unconverged_nodes=base.unconverged_nodes,
                       particles_per_cell=base.particles_per_cell,
                       vibrated_mass_kg=base.vibrated_mass_kg,
                       no_mass_reason=base.no_mass_reason)
            group.append(row)
        row.specimen, row.specimen_sha256 = specimen, sha256
        row.measured.append(entry)
        if name_note and name_note not in row.notes:
            row.notes.append(name_note)
        if aligned.status == "grid" and aligned.grid_case is not None:
            counted = same_count_note(case, aligned.grid_case, tolerances)
            if counted and counted not in row.notes:
                row.notes.append(counted)
        if met_calibrated and aligned.status in ("grid", "interpolated") \
                and met_calibrated not in row.notes:
            row.notes.append(met_calibrated)

    records = []
    members: list[tuple[int, ...]] = []  # MEASURED_RECORDS_ATTR, in the order of records
    unconverged_rows: list[str] = []
    duplicate_rows: list[str] = []
    for row in (r for group in rows.values() for r in group):
        lc = row.case
        sdc_m = sdc_m_se = sdc_m_dof = f_m = a_m = chi2_dof = baseline_m = math.nan
        sources = ""
        values = errors = np.empty(0)
        if row.measured:
            values = np.array([m.sdc for m in row.measured])
            errors = np.array([m.sdc_stderr for m in row.measured])
            sdc_m, sdc_m_se = pooled_mean(values, errors)
            sdc_m_dof = pooled_stderr_dof(values, errors,
                                          np.array([m.sdc_stderr_dof for m in row.measured]))
            f_m = float(np.mean([m.frequency_hz for m in row.measured]))
            a_m = float(np.mean([m.acceleration_g for m in row.measured]))
            sources = "; ".join(m.source for m in row.measured if m.source)
            chi2, dof = consistency_chi2(values, errors)
            chi2_dof = chi2 / dof if dof else math.nan
            baseline_m = pooled_baseline_sdc(values, errors,
                                             [m.baseline_sdc for m in row.measured])
        m_c = row.dem.vibrated_mass_kg if row.dem is not None else row.vibrated_mass_kg
        _, sdc_m10, _ = pooled_sdc_eq10(
            np.array([m.energy_per_cycle_j for m in row.measured]),
            np.array([g_to_si(m.acceleration_g) for m in row.measured]),
            np.array([m.frequency_hz for m in row.measured]), values, errors,
            vibrated_mass_kg=m_c)
        note = list(row.notes)
        if len(row.measured) > 1:
            note.append(f"{len(row.measured)} measurements pooled"
                        + (f" (chi2/dof {chi2_dof:.2g}: they scatter more than their errors)"
                           if chi2_dof > 3 else ""))
        implausible = [m for m in row.measured if m.implausible]
        if implausible:
            # the report's notes named them apart from the rows: the CSV row of a case pooling
            # an SDC of 46.1 with one of 2.19 showed 24.1 with no word of it
            note.append(IMPLAUSIBLE_ROW_NOTE + "; ".join(
                f"{Path(m.source).name} ({m.implausible})" for m in implausible))
        if row.dem is not None and row.dem.n_runs > 1:
            note.append(f"{row.dem.n_runs} DEM runs pooled")
        if row.dem is not None and row.dem.duplicate_keys:
            note.append(duplicates_note(row.dem))
            duplicate_rows.append(f"{lc.label()} ({len(row.dem.duplicate_keys)} duplicate)")
        if row.dem is not None and row.dem.not_converged:
            note.append(not_converged_note(row.dem))
            unconverged_rows.append(lc.label())
        elif row.unconverged_nodes:  # the row's note, from its alignment, names them
            unconverged_rows.append(f"{lc.label()} (interpolated from "
                                    f"{'; '.join(row.unconverged_nodes)})")
        if pool:
            note.append("DEM runs of different settings pooled (pool=True)")
        if math.isnan(row.paper_dem) and is_paper_coupon(row.specimen or ""):
            gap = _paper_dem_gap(lc, paper, tolerances)
            if gap:
                note.append(gap)
        if row.measured and math.isfinite(row.sdc_dem) and not math.isfinite(sdc_m10):
            note.append("no DEM m_c: no like-for-like difference"
                        + (f" ({row.no_mass_reason})" if row.no_mass_reason else ""))
        members.append(tuple(m.position for m in row.measured))
        records.append({
            **lc.columns(),
            "particles per cell [-]": (row.dem.particles_per_cell if row.dem
                                       else row.particles_per_cell),
            "DEM runs [-]": row.dem.n_runs if row.dem else 0,
            "SDC DEM (ours) [-]": row.sdc_dem,
            "SDC DEM stderr [-]": row.sdc_dem_stderr,
            "measured frequency [Hz]": f_m,
            "measured acceleration [g]": a_m,
            MEASURED_EQ11_COLUMN: sdc_m,
            MEASURED_EQ11_STDERR_COLUMN: sdc_m_se,
            MEASURED_EQ11_DOF_COLUMN: sdc_m_dof,
            MEASURED_BASELINE_COLUMN: baseline_m,
            MEASURED_EQ10_COLUMN: sdc_m10,
            "SDC DEM (paper) [-]": row.paper_dem,
            "SDC measured (paper) [-]": row.paper_exp,
            "difference ours - paper DEM [-]": row.sdc_dem - row.paper_dem,
            DIFFERENCE_COLUMN: sdc_m10 - row.sdc_dem,
            CONSISTENCY_COLUMN: chi2_dof,
            ALIGNMENT_COLUMN: row.status,
            "DEM settings": row.dem.settings if row.dem else "",
            "specimen": row.specimen or "",
            SPECIMEN_SHA256_COLUMN: row.specimen_sha256,
            "source file(s)": sources,
            "load case": lc.key,
            "note": "; ".join(note),
        })
    table = pd.DataFrame.from_records(records, columns=list(REPORT_COLUMNS))
    table["DEM runs [-]"] = table["DEM runs [-]"].astype(int)
    # a count: whole numbers in every format (the CSV wrote 18.0), empty where no DEM ran
    table["particles per cell [-]"] = table["particles per cell [-]"].astype("Int64")
    # the positions travel with their rows through the sort, then into attrs
    table["__records"] = members
    table = _sort_like_table3(table, aligner, paper, tolerances)
    members = table.pop("__records").tolist()
    if unconverged_rows:
        # named here: the console's short table has no note column
        notes.append(f"{len(unconverged_rows)} row(s) rest on DEM runs that did not converge "
                     "(no steady state before the transient cap): their DEM SDC may include "
                     f"the transient: {'; '.join(unconverged_rows)}")
    if duplicate_rows:
        # named here too: the console's short table has no note column
        notes.append(f"{len(duplicate_rows)} row(s) have stored DEM runs counted once, "
                     "being the same simulation as a run counted (same particles per cell, "
                     "seed, settings and specimen under another key: another stated fill, or "
                     "the automatic count of steady cycles stated): "
                     f"{'; '.join(duplicate_rows)}")
    counted = paper_fill_count_note(table)
    if counted:
        notes.append(counted)
    table.attrs["notes"] = notes
    table.attrs[MEASURED_RECORDS_ATTR] = members
    return table, aligner


def paper_fill_count_note(table: pd.DataFrame) -> str:
    """Where rows set our DEM beside Table 3 at one packing ratio with another particle
    count: the paper counts :data:`pidcore.defaults.PAPER_PARTICLES_PER_FULL_CELL` (36)
    spheres per cell as 100 % (Sect. 5.1), our runs their cell's capacity (22 acrylic spheres
    fit the paper's cell), so at the paper's 50 % ours hold 11 where its count is 18. ""
    where every compared row's count is the paper's, or no row is compared."""
    from ..specimen import particles_for_fill

    paper_dem = table["SDC DEM (paper) [-]"].to_numpy(dtype=float)
    ours = table["SDC DEM (ours) [-]"].to_numpy(dtype=float)
    counts = table["particles per cell [-]"]
    compared = table[np.isfinite(paper_dem) & np.isfinite(ours) & counts.notna().to_numpy()]
    pairs = []
    for fill in sorted(compared[PACKING_RATIO_COLUMN].astype(float).unique()):
        held = sorted({int(n) for n in compared.loc[compared[PACKING_RATIO_COLUMN] == fill,
                                                   "particles per cell [-]"]})
        theirs = particles_for_fill(fill, defaults.PAPER_PARTICLES_PER_FULL_CELL)
        if held != [theirs]:
            pairs.append(f"{fill:g} %: ours {'/'.join(str(n) for n in held)}, the paper's "
                         f"{theirs}")
    if not pairs:
        return ""
    # the difference column read as the same bed at the same packing ratio
    return (f"Table 3's packing ratio counts {defaults.PAPER_PARTICLES_PER_FULL_CELL} spheres "
            "per cell as 100 % (paper Sect. 5.1), our DEM runs their cell's capacity: particles "
            f"per cell at {'; '.join(pairs)}; 'difference ours - paper DEM' sets beds of "
            "different particle counts side by side at one packing ratio")


def not_converged_note(dem: DemCase) -> str:
    """The row note for a DEM case with runs whose steady state was never detected, in the
    words ``pidcore dem run`` prints for such a run (the report table and the app's Compare tab
    say it alike)."""
    runs = "; ".join(f"steady state from cycle {start} (NOT converged, transient cap), "
                     f"{cycles} cycles measured" if start >= 0 and cycles >= 0
                     else "steady state NOT converged (transient cap)"
                     for start, cycles in dem.not_converged)
    which = "DEM run" if dem.n_runs == 1 else f"{len(dem.not_converged)} of {dem.n_runs} DEM runs"
    return f"{which} did not converge: {runs}; the DEM SDC may include the transient"


def _snap(values: pd.Series, grid: np.ndarray, *, rtol: float = 0.0,
          atol: float = 0.0) -> np.ndarray:
    """Each value replaced by the nearest grid value within the tolerance (else kept)."""
    out = values.to_numpy(dtype=float).copy()
    if grid.size == 0:
        return out
    for i, v in enumerate(out):
        nearest = grid[np.argmin(np.abs(grid - v))]
        if abs(v - nearest) <= rtol * abs(nearest) + atol:
            out[i] = nearest
    return out


def _snap_to_own(values: np.ndarray, grid: np.ndarray, *, rtol: float = 0.0,
                 atol: float = 0.0) -> np.ndarray:
    """Each value off ``grid`` replaced by the smallest of those within the tolerance of it,
    walking up (grid values are kept, however close): measured values near no grid value sort
    as one block (99.99997 and 99.99998 Hz, two tests at 100 Hz of a specimen with runs at
    200 Hz only, sorted by those digits first, putting the 70 % fill before the 30 % one)."""
    out = values.copy()
    order = np.argsort(values, kind="stable")
    start = np.nan
    for i in order:
        v = values[i]
        if not np.isfinite(v) or np.isin(v, grid):
            continue
        if not np.isfinite(start) or v - start > rtol * abs(start) + atol:
            start = v
        out[i] = start
    return out


def _sort_like_table3(table: pd.DataFrame, aligner: Aligner, paper: pd.DataFrame | None,
                      tolerances: Tolerances) -> pd.DataFrame:
    """Sort by frequency, acceleration, fill as Table 3 does; a measured case sorts by the grid
    value it is within tolerance of, so 499.97 Hz sorts with the 500 Hz block, not before it,
    and cases near no grid value by the lowest of their own within that tolerance."""
    axes = {"frequency_hz": [], "acceleration_g": [], "fill_percent": []}
    for case in aligner.cases:
        for name in axes:
            axes[name].append(getattr(case.load_case, name))
    if paper is not None and not paper.empty:
        for name in axes:
            axes[name].extend(paper[name].astype(float).tolist())
    grid = {name: np.unique(np.asarray(v, dtype=float)) for name, v in axes.items()}
    keys = pd.DataFrame({
        "f": _snap_to_own(_snap(table["frequency [Hz]"], grid["frequency_hz"],
                                rtol=tolerances.frequency_rtol), grid["frequency_hz"],
                          rtol=tolerances.frequency_rtol),
        "a": _snap_to_own(_snap(table["acceleration [g]"], grid["acceleration_g"],
                                rtol=tolerances.acceleration_rtol), grid["acceleration_g"],
                          rtol=tolerances.acceleration_rtol),
        "p": _snap(table[PACKING_RATIO_COLUMN], grid["fill_percent"],
                   atol=tolerances.fill_atol_percent),
        "fx": table["frequency [Hz]"], "ax": table["acceleration [g]"],
        "px": table[PACKING_RATIO_COLUMN], "m": table["material"], "d": table["direction"],
        "s": table["DEM settings"], "sp": table["specimen"],
        "sh": table[SPECIMEN_SHA256_COLUMN],
    })
    order = keys.sort_values(list(keys.columns), kind="stable").index
    return table.loc[order].reset_index(drop=True)


#: Opens the note of a row whose measured SDC includes a record the plausibility checks refuse
#: (saved or kept with --accept-implausible); :func:`add_calibration_columns` judges no band
#: for such a row.
IMPLAUSIBLE_ROW_NOTE = "includes a result no passive coupon gives, kept as accepted: "

#: Columns added by :func:`add_calibration_columns` (after :data:`MEASURED_EQ11_COLUMN`).
#: (:data:`pidcore.compare.align.CALIBRATED_COLUMN` and its band, defined there for every
#: table of pidcore, :meth:`pidcore.calibrate.Calibration.to_pandas` included.)
#: The verdicts of :data:`pidcore.constants.BandVerdict`: ``not compared`` rather than ``n/a``
#: (pandas.read_csv would read ``n/a`` back as NaN); ``uninformative`` where the band spans
#: every plausible SDC (:meth:`~pidcore.calibrate.prediction.CalibratedPrediction.
#: uninformative_reason`), neither inside nor outside.
INSIDE, OUTSIDE, NOT_COMPARED, UNINFORMATIVE = BAND_VERDICTS
CALIBRATION_COLUMNS: tuple[str, ...] = (CALIBRATED_COLUMN, CALIBRATED_LOW_COLUMN,
                                        CALIBRATED_HIGH_COLUMN, CALIBRATED_INSIDE_COLUMN)
#: :data:`CALIBRATED_BAND_COLUMN` is the one column a page shows the calibrated band in
#: (:func:`with_band_text`): the terminal's table, the PDF's and the app's Report tab; the CSV,
#: Markdown, HTML and LaTeX files keep its two numbers (:data:`CALIBRATED_LOW_COLUMN`,
#: :data:`CALIBRATED_HIGH_COLUMN`).


def with_band_text(table: pd.DataFrame) -> pd.DataFrame:
    """A copy of a report table for display, its calibrated low and high 95 % columns
    replaced by one :data:`CALIBRATED_BAND_COLUMN` as
    :func:`~pidcore.calibrate.prediction.band_text` writes a band (``"0 .. 16.91"``, as the
    row's note and the app's Compare page write it; empty where no band), in the place of
    the low column; the table unchanged where it has no such columns. The app's grid showed
    the two numbers with its own 4 decimals (``0.0000``, ``16.9115``) beside a note saying
    ``0 .. 16.91``."""
    from ..calibrate.prediction import band_text

    if not {CALIBRATED_LOW_COLUMN, CALIBRATED_HIGH_COLUMN} <= set(table.columns):
        return table
    texts = ["" if math.isnan(low) and math.isnan(high) else band_text(low, high)
             for low, high in zip(table[CALIBRATED_LOW_COLUMN].map(_finite_or_nan),
                                  table[CALIBRATED_HIGH_COLUMN].map(_finite_or_nan),
                                  strict=True)]
    out = table.drop(columns=[CALIBRATED_HIGH_COLUMN])
    at = list(out.columns).index(CALIBRATED_LOW_COLUMN)
    out = out.drop(columns=[CALIBRATED_LOW_COLUMN])
    out.insert(at, CALIBRATED_BAND_COLUMN, texts)
    out.attrs = dict(table.attrs)
    return out


def _finite_or_nan(value) -> float:
    """A table cell as a float; NaN for an empty, None or non-finite one."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        return math.nan
    return number if math.isfinite(number) else math.nan


def report_calibration_specimen(material: str, specimen=None, *, paper: bool = False):
    """The specimen a report's calibration must be of for a row of particle ``material``
    (:func:`add_calibration_columns`): the report's ``specimen``; without one and with
    ``paper`` (the default report), the paper's coupon with that table material; None (not
    checked) otherwise."""
    from ..constants import PARTICLE_MATERIALS
    from ..specimen import paper_specimen

    if specimen is None and paper and material in PARTICLE_MATERIALS:
        return paper_specimen(material)
    return specimen


def calibration_row_refusal(calibration, specimen: str, sha256: object = "") -> str:
    """Why ``calibration`` predicts nothing for a row of tests of ``specimen`` (its name as
    the row's ``specimen`` column gives it; "": not named) whose file's hash is ``sha256``
    (:data:`SPECIMEN_SHA256_COLUMN`; "": unknown); "" where it may
    (:meth:`~pidcore.calibrate.prediction.Calibration.speaks_for`, the Compare page's rule).

    A report of the paper's coupon (the default) judged a test naming another specimen, with
    no DEM run in its row, against the paper coupon's calibrated band; its sheet, as the
    Compare page, said that no calibration is of that specimen."""
    # the row's tests recorded their specimen file: a calibration of another file of that
    # name (an edited x.toml) does not predict them
    other = calibration.other_file_reason(sha256, specimen)
    if other or calibration.speaks_for(specimen, sha256):
        return other
    return f"it calibrates specimen {calibration.specimen_name}, not {specimen}"


def _place(row: pd.Series) -> tuple[str, str, str]:
    """A report row's load case and specimen: rows of several DEM settings share it."""
    return (str(row.get("load case", "") or ""), str(row.get("specimen", "") or ""),
            str(row.get(SPECIMEN_SHA256_COLUMN, "") or ""))


def _measured_row_settings(table: pd.DataFrame) -> dict[tuple[str, str, str], str]:
    """Per :func:`_place`, the DEM settings of the row carrying its measured Eq. 11 SDC
    ("DEM settings ..."; "the DEM row" where the runs record none)."""
    if MEASURED_EQ11_COLUMN not in table.columns:
        return {}
    return {_place(row): (f"DEM settings {row['DEM settings']}"
                          if str(row.get("DEM settings", "") or "") else "the DEM row")
            for _, row in table.iterrows()
            if math.isfinite(_finite_or_nan(row.get(MEASURED_EQ11_COLUMN)))}


def add_calibration_columns(table: pd.DataFrame, calibration, *,
                            tolerances=None, specimen=None, paper: bool = False) -> pd.DataFrame:
    """A copy of a report table with the calibrated DEM's prediction beside each row.

    Like for like: the calibration predicts the Eq. 11 SDC a shaker test of the DEM would
    measure, so the band is compared with ``SDC measured (Eq. 11) [-]``, not with Eq. 10.
    Rows whose load case the calibration does not predict (material, and frequency,
    acceleration, fill within ``tolerances``) get empty numbers, ``not compared`` and a note
    saying so and why (another specimen:
    :meth:`~pidcore.calibrate.prediction.Calibration.other_specimen_reason`; another material,
    outside its range, not a calibrated load case: ``why_not_predicted``). The
    table's notes (``attrs["notes"]``) gain one that counts the predicted rows and the
    measured rows inside the band.

    Parameters
    ----------
    table : DataFrame
        From :func:`build_report_table`.
    calibration : pidcore.calibrate.prediction.Calibration
        From :func:`pidcore.calibrate.prediction.load_calibration`.
    tolerances : Tolerances, optional
        Grid-match tolerances (default: the report's).
    specimen : pidcore.specimen.Specimen, optional
        The specimen the table is of, checked against the calibration's before any load case
        is looked up (a calibration of another specimen predicts no row of it).
    paper : bool
        Without ``specimen``: the rows are the paper's coupon with their own particle
        material (the default report), each checked against the calibration's specimen.
        Neither: unchecked.
    """
    from ..calibrate.data import CALIBRATION_DIRECTION, other_direction
    from ..calibrate.prediction import (
        NO_MEASUREMENT_REASON,
        judge_measurement,
        uninformative_count_text,
    )

    out = table.copy()
    sdc, low, high, inside, notes = [], [], [], [], []
    # the measurement of a load case is on one row of its DEM settings (the most cells): the
    # others' "no Eq. 11 measurement" was untrue beside it
    measured_on = _measured_row_settings(out)
    reasons: dict[str, str] = {}  # per material: why the calibration is of another specimen
    for _, row in out.iterrows():
        note = str(row.get("note", "") or "")
        case = LoadCase(float(row["frequency [Hz]"]), float(row["acceleration [g]"]),
                        float(row[PACKING_RATIO_COLUMN]),
                        str(row.get("material") or defaults.COMPARE_DEFAULT_MATERIAL))
        if case.material not in reasons:
            reasons[case.material] = calibration.other_specimen_reason(
                report_calibration_specimen(case.material, specimen, paper=paper))
        other = reasons[case.material]
        if not other:
            other = calibration_row_refusal(calibration, str(row.get("specimen", "") or ""),
                                            row.get(SPECIMEN_SHA256_COLUMN, ""))
        axis = other_direction(row.get("direction"))
        if not other and axis:
            # an x-drive row was given the z-drive prediction and an in-band verdict
            other = (f"driven along {axis}, where the calibration's DEM runs drive along "
                     f"{CALIBRATION_DIRECTION}")
        hit = None if other else calibration.lookup(case, tolerances=tolerances)
        if hit is None:
            sdc.append(math.nan)
            low.append(math.nan)
            high.append(math.nan)
            inside.append(NOT_COMPARED)
            why = other or calibration.why_not_predicted(case, tolerances=tolerances)
            extra = f"not predicted by the calibration {calibration.path.name}: {why}"
        else:
            # the calibration predicts the SDC before the empty coupon's damping was taken
            # off (it adds a baseline of its own): judged at that SDC. A table of an older
            # pidcore has no such column: nothing taken off; nor a dof column: unknown, the
            # normal's quantile
            judged = judge_measurement(
                hit, _finite_or_nan(row.get(MEASURED_EQ11_COLUMN)),
                _finite_or_nan(row.get(MEASURED_EQ11_STDERR_COLUMN)),
                _finite_or_nan(row.get(MEASURED_EQ11_DOF_COLUMN)),
                _finite_or_nan(row.get(MEASURED_BASELINE_COLUMN, 0.0)),
                pools_implausible=IMPLAUSIBLE_ROW_NOTE in note)
            settings = measured_on.get(_place(row))
            if judged.reason == NO_MEASUREMENT_REASON and settings is not None:
                judged = replace(judged, reason=(
                    "the measurement at this load case is compared with the calibrated band "
                    f"on the row of {settings}"))
            sdc.append(judged.sdc)
            low.append(judged.low)
            high.append(judged.high)
            inside.append(judged.verdict)
            extra = judged.note
        notes.append("; ".join(n for n in (note, extra) if n))
    at = list(out.columns).index(MEASURED_EQ11_COLUMN) + 1 \
        if MEASURED_EQ11_COLUMN in out.columns else len(out.columns)
    for offset, (name, values) in enumerate(zip(CALIBRATION_COLUMNS, (sdc, low, high, inside),
                                                strict=True)):
        out.insert(at + offset, name, values)
    out["note"] = notes
    # a band of 0 .. 2 pi refutes no plausible measurement: counted neither inside nor among
    # those judged
    compared = sum(v in (INSIDE, OUTSIDE) for v in inside)
    unjudged = inside.count(UNINFORMATIVE)
    summary = (f"calibration {calibration.path}: predicts {sum(math.isfinite(v) for v in sdc)} "
               f"of {len(out)} row(s); measured Eq. 11 SDC inside the 95 % band at "
               f"{inside.count(INSIDE)} of {compared} measured row(s)"
               + uninformative_count_text(unjudged))
    out.attrs = {**table.attrs, "notes": [*table.attrs.get("notes", []), summary]}
    return out
