"""One load case of measurements beside our DEM, the pchip model and the paper.

The Compare page of the app and its headline come from here; it reads analysed records (fresh
uploads or records of the store) and the store's DEM runs, never widgets.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd

from .. import defaults
from ..errors import ParameterError, PidcoreError
from ..units import display_sigmas
from .align import (
    MEASURED_EQ10_COLUMN,
    MEASURED_EQ11_COLUMN,
    MEASURED_EQ11_STDERR_COLUMN,
    PACKING_RATIO_COLUMN,
    Aligner,
    Tolerances,
    band_quantile,
    consistency_chi2,
    filled_corners,
    interpolated_count_and_mass,
    model_point,
    pooled_baseline_sdc,
    pooled_mean,
    pooled_sdc_eq10,
    pooled_stderr_dof,
    stored_stderr_dof,
    welch_satterthwaite_dof,
)
from .loadcase import LoadCase, StatedLoadCase
from .settings_columns import describe_corrections

#: Fill (packing ratio, %) the app names as the paper's (its help of the fill column) for a
#: file whose name states none; never taken as stated: such a file has no load case until the
#: user types its fill (it was put in the grid and saved as "stated in the app").
PROPOSED_FILL_PERCENT = defaults.APP_DEFAULT_FILL_PERCENT


def load_case_of(record, *, fill_percent: float, material: str,
                 direction: str = defaults.COMPARE_DEFAULT_DIRECTION) -> LoadCase:
    """Load case of an analysed record (:class:`pidcore.measure.AnalyzedRecord`, which sits
    above this layer): measured frequency and acceleration, stated fill, material, direction."""
    a = record.analysis
    return LoadCase(float(a.frequency_hz), float(a.acceleration_g), float(fill_percent),
                    material, direction)


def stated_case(name: str, sidecar: pd.DataFrame | None = None,
                materials: tuple[str, ...] = (),
                specimen_material: str | None = None) -> StatedLoadCase:
    """What the file name and a load-case table state about a file (the table wins).

    ``materials``: own materials recognised besides the table's (e.g. ``steel`` of the user's
    specimens: ``..._steel.csv``). ``specimen_material``: the particles of the specimen file
    given for the files (``pidcore analyze --specimen``, the Analyse tab's uploaded one): the
    material of a file that states none (origin ``material: specimen``), as the CLI takes it.
    Without a stated fill, the fill is NaN and the origin says ``fill: not stated``: nothing is
    proposed in its place, as ``pidcore analyze`` saves such a file without a load case (a
    proposed 50 % was saved as stated); the origin says which other values are defaults.
    """
    from ..constants import PARTICLE_MATERIALS
    from .loadcase import (
        SIDECAR_COLUMNS,
        UntabulatedMaterial,
        parse_file_name,
        resolve_load_case,
    )

    table = sidecar if sidecar is not None else pd.DataFrame(columns=list(SIDECAR_COLUMNS))
    untabulated = ""
    try:
        return resolve_load_case(Path(Path(name).name), sidecar=table, materials=materials,
                                 specimen_material=specimen_material)
    except UntabulatedMaterial as exc:  # "..._steel.csv" without a steel specimen
        untabulated = (f"the file name says {exc.material!r}, which neither the material "
                       "table nor a specimen gives; set the material, or the specimen of "
                       f"{exc.material} particles")
    except PidcoreError:  # no fill stated (or a bad table row): keep what the name states
        pass
    known = (*PARTICLE_MATERIALS, *(m for m in materials if m not in PARTICLE_MATERIALS),
             *([specimen_material] if specimen_material else []))
    try:
        found = parse_file_name(Path(name).name, known)
    except PidcoreError:
        found = {}
    fill = found.get("fill_percent")
    material = (f"{defaults.COMPARE_DEFAULT_MATERIAL} proposed: {untabulated}" if untabulated
                else "file name" if "material" in found
                else "specimen" if specimen_material else "default")
    return StatedLoadCase(
        float(fill) if untabulated and fill is not None else math.nan,
        str(found.get("material", specimen_material or defaults.COMPARE_DEFAULT_MATERIAL)),
        str(found.get("direction", defaults.COMPARE_DEFAULT_DIRECTION)),
        ("fill: file name" if untabulated and fill is not None else "fill: not stated")
        + f"; material: {material}; direction: "
        f"{'file name' if 'direction' in found else 'default'}")


def group_load_cases(cases: Sequence[LoadCase],
                     tolerances: Tolerances | None = None) -> list[list[int]]:
    """Indices of ``cases`` grouped into one load case each: taken in the order of their load
    cases (frequency, acceleration, fill, material, direction), a case joins the first group
    whose first case it matches within ``tolerances`` (default :class:`Tolerances`, the
    Compare page's). The groups are those of the cases, whatever order they are given in;
    listed by their first index, each group's indices ascending. The report groups its
    off-grid records by this rule too (:func:`pidcore.report.table.build_report_table`), each
    group at :func:`pooled_load_case`."""
    tol = tolerances or Tolerances()
    # matched against a group's first case, a chain of cases each within the tolerance of
    # the next (4.8, 5.0, 5.2 g at 5 %) split where the order of the records put its first
    # case: the Compare page's cases and the report's rows hung on the order files were given
    ordered = sorted(range(len(cases)), key=lambda i: _load_case_order(cases[i]))
    groups: list[list[int]] = []
    for i in ordered:
        for members in groups:
            if tol.matches(cases[i], cases[members[0]]):
                members.append(i)
                break
        else:
            groups.append([i])
    return sorted(sorted(members) for members in groups)


def _load_case_order(case: LoadCase) -> tuple:
    return (case.frequency_hz, case.acceleration_g, case.fill_percent, case.material,
            case.direction)


def pooled_load_case(cases: Sequence[LoadCase]) -> LoadCase:
    """The load case of repeated tests (a group of :func:`group_load_cases`): their mean
    measured frequency and acceleration, and the stated fill, material and direction of the
    first in load-case order (the fills of one group are within the fill tolerance; taken
    from the first given, 50 and 50.4 % pooled as either by the order of the files)."""
    if not cases:
        raise ParameterError("pooled_load_case: no load cases given")
    first = min(cases, key=_load_case_order)
    return LoadCase(float(np.mean([c.frequency_hz for c in cases])),
                    float(np.mean([c.acceleration_g for c in cases])),
                    first.fill_percent, first.material, first.direction)


def paper_table() -> pd.DataFrame:
    """The paper's Table 3 (:func:`pidcore.model.load_paper_table3`)."""
    from ..model import load_paper_table3

    return load_paper_table3()


@dataclass(frozen=True)
class CaseComparison:
    """Everything shown for one load case.

    Attributes
    ----------
    load_case : LoadCase
        Mean measured frequency [Hz] and acceleration [g] of the records, stated fill,
        material and direction.
    measured : pandas.DataFrame
        One row per record: ``file``, ``packing ratio [%]``, its Eq. 11 SDC and standard error
        (:data:`~pidcore.compare.align.MEASURED_EQ11_COLUMN`,
        :data:`~pidcore.compare.align.MEASURED_EQ11_STDERR_COLUMN`) and, with a DEM m_c, its
        Eq. 10 one (:data:`~pidcore.compare.align.MEASURED_EQ10_COLUMN`): the report's names.
    measured_sdc, measured_stderr : float
        Eq. 11 SDC of the records pooled (:func:`pidcore.compare.pooled_mean`), [-].
    measured_stderr_dof : float
        Degrees of freedom of ``measured_stderr`` (:func:`pidcore.compare.align.pooled_stderr_dof`;
        NaN: unknown), which set its 95 % quantile.
    aligned : AlignedCase
        Our DEM (grid value or pchip interpolation) and the paper's values at the case.
    dem_points : pandas.DataFrame
        Our DEM cases at this frequency, acceleration, material and direction, every fill:
        ``packing ratio [%]``, ``SDC [-]``, ``SDC stderr [-]``, ``runs [-]``.
    paper_points : pandas.DataFrame
        Table 3 rows at this frequency and acceleration.
    model_fill_percent, model_sdc : numpy.ndarray
        The pchip model over Table 3 (DEM) along fill at this case (empty outside its range).
    measured_sdc_eq10, measured_stderr_eq10 : float
        Energy per cycle over the DEM case's ``E = m_c a^2 / (2 w^2)`` (Eq. 10), pooled: the
        like-for-like counterpart of our DEM SDC. NaN without a DEM case that knows ``m_c``.
    chi2_dof : float
        Consistency of the pooled records (:func:`pidcore.compare.align.consistency_chi2`), per
        degree of freedom; NaN for one record.
    notes : tuple of str
        What was adjusted or left out (a model evaluated at the edge of its range, ...).
    measured_stderr_eq10_dof : float
        Degrees of freedom of ``measured_stderr_eq10``, as ``measured_stderr_dof`` of the
        Eq. 11 one (the records' Eq. 10 SDCs keep their relative errors, but their pooled
        error may be the scatter between them where the Eq. 11 one is not).
    vibrated_mass_kg : float
        The DEM's m_c of Eq. 10 at this case [kg]: its grid case's, or for an interpolated
        value the m_c a run at this fill would have
        (:func:`pidcore.compare.align.interpolated_count_and_mass`, as ``pidcore report``
        takes it); NaN where neither is known.
    measured_baseline_sdc : float
        The part of ``measured_sdc`` its analyses took off as the empty coupon's damping,
        pooled alike (:data:`pidcore.compare.align.MEASURED_BASELINE_COLUMN`; 0: none, NaN:
        not known): ``measured_sdc`` plus it is the SDC the calibrated DEM predicts.
    """

    load_case: LoadCase
    measured: pd.DataFrame
    measured_sdc: float
    measured_stderr: float
    aligned: object
    dem_points: pd.DataFrame
    paper_points: pd.DataFrame
    model_fill_percent: np.ndarray
    model_sdc: np.ndarray
    measured_sdc_eq10: float = math.nan
    measured_stderr_eq10: float = math.nan
    chi2_dof: float = math.nan
    notes: tuple[str, ...] = ()
    measured_stderr_dof: float = math.nan
    measured_stderr_eq10_dof: float = math.nan
    vibrated_mass_kg: float = math.nan
    measured_baseline_sdc: float = 0.0


@dataclass(frozen=True)
class MeasuredEntry:
    """One analysed measurement with its load case, from an upload or from the store.

    Attributes
    ----------
    key : str
        Store analysis key, or ``"upload:<sha256>"`` for an unsaved upload.
    file : str
        The measurement's file name.
    origin : str
        ``"store"`` or ``"this session (unsaved)"``.
    load_case : LoadCase
    frequency_hz, acceleration_m_s2 : float
        Measured drive, Hz and m/s^2.
    loss_factor, sdc, sdc_stderr : float
        Eq. 11 results, [-].
    energy_per_cycle_j : float
        Energy dissipated per cycle, J.
    harmonics, force_phasors_n, velocity_phasors_m_s : numpy.ndarray
        Fitted harmonics (for the loop and the spectrum).
    specimen, created_utc : str
        Specimen named with the record (may be empty) and when it was saved.
    implausible : str
        What the plausibility checks refuse in it (:mod:`pidcore.compare.plausibility`; saved
        with ``--accept-implausible`` or the app's confirmation), or empty.
    corrections : str
        The corrections the analysis ran with, e.g. ``"vibrometer delay 50 µs, mass below
        gauge 0 g, baseline loss factor 0"`` (empty where unknown).
    settings : dict
        The analysis's parameters (stored ``parameters_json``, or those an unsaved analysis
        would be stored with:
        :func:`pidcore.compare.settings_columns.analysis_parameters_to_store`): how its
        corrections went, e.g. the baseline off the whole vibrated mass
        (:func:`pidcore.report.pipeline.whole_mass_baseline_note`); empty where unknown.
    measurement_key : str
        The store's key of the measured data (:func:`pidcore.store.measurement_key`): equal
        for byte-identical files under any name, so :func:`unique_entries` counts them once
        (empty where unknown).
    specimen_sha256 : str
        The sha256 of the specimen file the record names (``specimen_sha256``), deciding
        which DEM runs and calibration it meets and keeping two files of one name apart; ""
        where only the name is known (:func:`pidcore.specimen.deciding_sha256`).
    specimen_note : str
        Where a record without its file's hash was matched by name only to its name's one
        file (``specimen_sha256`` is then that file's), or kept apart since the name means
        several files, the note saying so (:func:`pidcore.report.case_view.matched_specimens`);
        empty otherwise.
    bound_note : str
        Where the SDC bound stored with a saved record is not one and was ignored (judged at
        2 pi), the note saying so; empty otherwise.
    """

    key: str
    file: str
    origin: str
    load_case: LoadCase
    frequency_hz: float
    acceleration_m_s2: float
    loss_factor: float
    sdc: float
    sdc_stderr: float
    energy_per_cycle_j: float
    harmonics: np.ndarray
    force_phasors_n: np.ndarray
    velocity_phasors_m_s: np.ndarray
    specimen: str = ""
    created_utc: str = ""
    corrections: str = ""
    measurement_key: str = ""
    #: the first plausibility warning beyond noise (a result kept or saved as accepted), or ""
    implausible: str = ""
    settings: dict = field(default_factory=dict, repr=False, compare=False)
    #: degrees of freedom of sdc_stderr (the analysis's n_blocks - 1), NaN where unknown
    sdc_stderr_dof: float = math.nan
    specimen_sha256: str = ""
    #: how a record saved without its file's hash met its specimen's file (joined by name to
    #: the one file of that name, or kept apart: pidcore.specimen.match_hashless_records)
    specimen_note: str = ""
    #: the note of :func:`pidcore.compare.plausibility.stored_sdc_bound_and_note`, else ""
    bound_note: str = ""
    #: the part of ``sdc`` taken off as the empty coupon's damping
    #: (:func:`pidcore.signal.power.baseline_sdc_taken_off`; NaN: taken off, amount unknown)
    baseline_sdc: float = 0.0

    @classmethod
    def from_record(cls, record, load_case: LoadCase, *,
                    specimen: str = "", options=None,
                    specimen_sha256: str = "", sdc_bound=None) -> MeasuredEntry:
        """Entry of a fresh (unsaved) analysis (:class:`pidcore.measure.AnalyzedRecord`);
        ``options`` (:class:`pidcore.measure.AnalysisOptions`) names the corrections;
        ``specimen_sha256``: the specimen file's hash as it would be saved ("": none);
        ``sdc_bound``: the SDC bound of its specimen
        (:func:`pidcore.compare.plausibility.tested_sdc_bound`; None: 2 pi)."""
        from ..records import measurement_key
        from ..signal.power import baseline_sdc_taken_off
        from ..specimen import deciding_sha256
        from .plausibility import implausible_findings
        from .settings_columns import analysis_parameters_to_store

        a = record.analysis
        found, _ = implausible_findings(a, bound=sdc_bound)
        try:
            content = measurement_key(record.measurement)
        except PidcoreError:  # a malformed digest: the entry is never taken for a copy
            content = ""
        return cls(f"upload:{record.measurement.sha256}", Path(record.measurement.source).name,
                   "this session (unsaved)", load_case, float(a.frequency_hz),
                   float(a.acceleration_amplitude_m_s2), float(a.loss_factor), float(a.sdc),
                   float(a.sdc_stderr), float(a.energy_per_cycle_j),
                   np.asarray(a.harmonics), np.asarray(a.force_phasors_n),
                   np.asarray(a.velocity_phasors_m_s), specimen,
                   corrections=describe_corrections(vars(options)) if options else "",
                   measurement_key=content, implausible=found[0].message if found else "",
                   settings=(analysis_parameters_to_store(record, options.parameters())
                             if options else {}),
                   sdc_stderr_dof=a.sdc_stderr_dof,
                   specimen_sha256=deciding_sha256(specimen_sha256) if specimen else "",
                   baseline_sdc=baseline_sdc_taken_off(a))

    @classmethod
    def from_store(cls, row: pd.Series, arrays: dict, *, known=()) -> MeasuredEntry:
        """Entry of a saved analysis: a row of :func:`pidcore.store.listing.saved_analyses`
        and the entry's arrays (:meth:`pidcore.store.Store.get_analysis`). ``known``: the
        specimen files at hand (:class:`pidcore.specimen.Specimen`), among which the one the
        record names gives its SDC bound (:func:`pidcore.compare.plausibility.
        stored_sdc_bound`; 2 pi where its file is not among them)."""
        from ..signal.power import baseline_sdc_taken_off
        from ..specimen import MEASURED_SHA256_FIELD, measured_specimen_name
        from ..specimen import measured_specimen_sha256 as tested_sha256
        from .align import _row_case
        from .plausibility import stored_findings, stored_sdc_bound_and_note

        empty = np.empty(0)
        named = row.get("specimen", "")
        sha256 = row.get(MEASURED_SHA256_FIELD, "")
        sha256 = sha256 if isinstance(sha256, str) else ""
        given = next((s for s in known if isinstance(named, str) and named
                      and measured_specimen_name(s) == named
                      and (not sha256 or tested_sha256(s) == sha256)), None)
        bound, bound_note = stored_sdc_bound_and_note(row, given=given)
        found, _ = stored_findings(row, bound=bound)
        settings = saved_parameters(row.get("parameters_json"))
        return cls(str(row["key"]), Path(str(row.get("source", ""))).name, "store",
                   _row_case(row), float(row["frequency_hz"]),
                   float(row.get("acceleration_m_s2", math.nan)),
                   float(row.get("loss_factor", math.nan)), float(row["sdc"]),
                   float(row["sdc_stderr"]), float(row.get("energy_per_cycle_j", math.nan)),
                   np.asarray(arrays.get("harmonics", empty)),
                   np.asarray(arrays.get("force_phasors_n", empty)),
                   np.asarray(arrays.get("velocity_phasors_m_s", empty)),
                   _specimen_of(row), str(row.get("created_utc", "")),
                   describe_corrections(settings),
                   str(row.get("measurement_key", "") or ""),
                   found[0].message if found else "", settings,
                   stored_stderr_dof(row.get("sdc_stderr_dof")), _specimen_sha256_of(row),
                   bound_note=bound_note, baseline_sdc=baseline_sdc_taken_off(row))

    @property
    def loop_label(self) -> str:
        """The label of :meth:`loop`: ``"measured: <file>"``."""
        return f"measured: {self.file}"

    def loop(self):
        """The measured loop (:class:`pidcore.loop.ForceDisplacementLoop`, labelled
        ``"measured: <file>"``), or a note why there is none."""
        from ..loop import ForceDisplacementLoop

        if not (np.size(self.harmonics) and np.isfinite(self.frequency_hz)
                and self.frequency_hz > 0):
            return "no harmonic phasors stored with this analysis"
        return ForceDisplacementLoop.from_phasors(
            self.harmonics, self.force_phasors_n, self.velocity_phasors_m_s, self.frequency_hz,
            label=self.loop_label)

    def spectrum(self) -> pd.DataFrame:
        """Amplitudes of the fitted force and velocity harmonics (units in the columns)."""
        h = np.asarray(self.harmonics, dtype=float)
        return pd.DataFrame({
            "harmonic [-]": h.astype(int),
            "frequency [Hz]": h * self.frequency_hz,
            "force amplitude [N]": np.abs(np.asarray(self.force_phasors_n)),
            "velocity amplitude [m/s]": np.abs(np.asarray(self.velocity_phasors_m_s)),
        })


def unique_entries(entries: Sequence[MeasuredEntry]) -> tuple[list[MeasuredEntry], list[str]]:
    """``entries`` with each measured data set once, and a note per entry left out.

    Byte-identical files (one saved, one uploaded again under another name, or two uploads)
    are one measurement: pooling both would count the same data twice and shrink the standard
    error by about sqrt(2). The first entry of each :attr:`MeasuredEntry.measurement_key` is
    kept (list saved records first: the store's copy is the one Compare and Report share);
    entries without a key are all kept. An entry that is the saved copy of itself (same file
    and SDC: an upload still in the session after Save) is left out without a note. An
    unsaved analysis of a saved measurement with other settings (a corrected vibrometer
    delay) takes the saved record's place, as its Save would make it the one reports and
    calibrations use; the note names the settings that differ and both SDCs
    (:func:`pidcore.compare.settings_columns.other_settings_note`).
    """
    kept: list[MeasuredEntry] = []
    notes: list[str] = []
    first: dict[str, int] = {}  # measurement key -> its entry's index in kept
    for e in entries:
        at = first.get(e.measurement_key) if e.measurement_key else None
        if at is None:
            if e.measurement_key:
                first[e.measurement_key] = len(kept)
            kept.append(e)
            continue
        other = kept[at]
        reanalysed = _reanalysis_note(other, e)
        if reanalysed:
            kept[at] = e
            notes.append(reanalysed)
            continue
        if (e.file, e.sdc) == (other.file, other.sdc):
            continue  # the saved copy of this very analysis: nothing to say
        where = "saved" if other.origin == "store" else "this session"
        notes.append(f"{e.file} left out, {e.origin}: the same contents as {other.file} "
                     f"({where}); the same data are counted once")
    return kept, notes


def _reanalysis_note(saved: MeasuredEntry, session: MeasuredEntry) -> str:
    """Where ``session`` is an unsaved analysis of the measurement of the record ``saved``
    with other settings, the note that it is compared in the saved one's place; else "".
    The channel names asked for are not compared (the app saves none, ``pidcore analyze``
    those given): the channels used are, under ``channels``."""
    from .settings_columns import CHANNEL_FIELDS, other_settings_note

    if saved.origin != "store" or session.origin == "store":
        return ""
    if not (saved.settings and session.settings):  # not known: an earlier pidcore's record
        return ""
    old, new = ({k: v for k, v in e.settings.items() if k not in CHANNEL_FIELDS}
                for e in (saved, session))
    return other_settings_note(
        session.file, old, new, saved.sdc, session.sdc,
        saved_as=saved.file if saved.file != session.file else "",
        this="this session's unsaved analysis",
        now="the one compared, the saved one is left out (the same data are counted once); "
            "Save makes it the one reports and calibrations use")


def _specimen_of(row) -> str:
    """The specimen a stored analysis names ("" for none): a store's listing holds NaN where a
    record names none and another does (``str(NaN)`` would be a specimen "nan")."""
    named = row.get("specimen", "")
    return named if isinstance(named, str) else ""


def _specimen_shown(entry: MeasuredEntry) -> str:
    """The specimen of a record as the per-file table shows it: its name, and for a record
    saved without its file's hash beside hashed tests of that name
    (:attr:`MeasuredEntry.specimen_note`), whether it was matched to their one file or kept
    apart."""
    from ..specimen import hashed_name

    if not entry.specimen_note:
        return entry.specimen
    if entry.specimen_sha256:
        return (f"{entry.specimen} (no file hash saved; matched by name to "
                f"{hashed_name(entry.specimen, entry.specimen_sha256)})")
    return f"{entry.specimen} (no file hash saved; several files of that name)"


def _specimen_sha256_of(row) -> str:
    """The specimen file's hash a stored analysis recorded where it decides ("" for none, an
    older record, or the paper's coupon's: by name)."""
    from ..specimen import MEASURED_SHA256_FIELD, deciding_sha256

    return deciding_sha256(row.get(MEASURED_SHA256_FIELD, "")) if _specimen_of(row) else ""


def saved_parameters(text: object) -> dict:
    """A saved analysis's parameters (a listing's ``parameters_json``) as a dict; ``{}``
    where none are saved or they are not a readable JSON object (a record of an earlier
    pidcore, a hand-edited store): its corrections then read as unknown, not as an error."""
    import json

    try:
        found = json.loads(text) if isinstance(text, str) and text else {}
    except ValueError:
        return {}
    return found if isinstance(found, dict) else {}


def compare_case(records: Sequence[MeasuredEntry],
                 dem_runs: pd.DataFrame | None, paper: pd.DataFrame, *,
                 model_points: int = 121) -> CaseComparison:
    """Measured SDC of one load case next to our DEM, the pchip model and the paper.

    Parameters
    ----------
    records : sequence of MeasuredEntry
        The records of one load case (see :func:`group_load_cases`); at least one.
    dem_runs : pandas.DataFrame or None
        :meth:`pidcore.store.Store.list_dem_runs` (may be empty).
    paper : pandas.DataFrame
        Table 3 (:func:`pidcore.model.load_paper_table3`).
    model_points : int
        Points on the model curve.
    """
    from ..model import SdcModel
    from ..specimen import is_paper_coupon
    from .align import PAPER_DIRECTION, PAPER_MATERIAL
    from .specimens import NOT_PAPER_SPECIMEN_NOTE

    if not records:
        raise ParameterError("compare_case: no records given")
    case = pooled_load_case([r.load_case for r in records])
    measured = pd.DataFrame({
        "file": [r.file for r in records],
        "origin": [r.origin for r in records],
        # which of the pooled tests recorded only its specimen's name is seen per file
        "specimen": [_specimen_shown(r) for r in records],
        "corrections": [r.corrections for r in records],
        PACKING_RATIO_COLUMN: [r.load_case.fill_percent for r in records],
        # the report's names: "SDC [-]" here was the report's "SDC measured (Eq. 11) [-]"
        MEASURED_EQ11_COLUMN: [r.sdc for r in records],
        MEASURED_EQ11_STDERR_COLUMN: [r.sdc_stderr for r in records],
    })
    values = measured[MEASURED_EQ11_COLUMN].to_numpy(float)
    errors = measured[MEASURED_EQ11_STDERR_COLUMN].to_numpy(float)
    sdc, stderr = pooled_mean(values, errors)
    stderr_dof = pooled_stderr_dof(values, errors, np.array([r.sdc_stderr_dof for r in records]))
    baseline_sdc = pooled_baseline_sdc(values, errors, [r.baseline_sdc for r in records])
    chi2, dof = consistency_chi2(values, errors)
    tol = Tolerances()
    runs = dem_runs if dem_runs is not None and not dem_runs.empty else None
    notes: list[str] = []
    # Table 3 describes the paper's coupon: beside a test of another specimen its points, its
    # pchip curve and its values were read as that coupon's (the report's rule too)
    specimen = records[0].specimen
    # by name: a test of another file of the paper coupon's name is saved under its hashed
    # label (measured_specimen_name), and the paper's own hashes decide by name too
    if not is_paper_coupon(specimen):
        if case.material == PAPER_MATERIAL and case.direction == PAPER_DIRECTION:
            notes.append(NOT_PAPER_SPECIMEN_NOTE.format(name=specimen.strip()))
        paper = paper.iloc[0:0]
    # the measured fill chooses among stored runs that are one simulation (and names the case)
    aligner = Aligner.from_tables(runs, paper, tolerances=tol,
                                  reference_fills=[case.fill_percent])
    aligned = aligner.align(case)
    if aligned.status == "no_dem_runs" and not is_paper_coupon(specimen):
        # the runs were those of this specimen: "no DEM runs of ours for acrylic" read false
        # beside a store of the paper's coupon's acrylic runs
        aligned = replace(aligned, message=f"no DEM runs of specimen {specimen.strip()} for "
                                           f"{case.material}, direction {case.direction}")

    dem_rows = []
    for c in aligner.cases:
        probe = replace(case, fill_percent=c.load_case.fill_percent)
        if tol.matches(probe, c.load_case):
            dem_rows.append({PACKING_RATIO_COLUMN: c.load_case.fill_percent, "SDC [-]": c.sdc,
                             "SDC stderr [-]": c.sdc_stderr, "runs [-]": c.n_runs,
                             "settings": c.settings})
    dem_points = pd.DataFrame(dem_rows, columns=[PACKING_RATIO_COLUMN, "SDC [-]", "SDC stderr [-]",
                                                 "runs [-]", "settings"])

    paper_cols = [PACKING_RATIO_COLUMN, "SDC DEM (paper) [-]", "SDC measured (paper) [-]"]
    paper_points = pd.DataFrame(columns=paper_cols)
    model_x = model_y = np.empty(0)
    if case.material == PAPER_MATERIAL and case.direction == PAPER_DIRECTION and not paper.empty:
        f = paper["frequency_hz"].to_numpy(float)
        a = paper["acceleration_g"].to_numpy(float)
        at_case = ((np.abs(f - case.frequency_hz) <= tol.frequency_rtol * f)
                   & (np.abs(a - case.acceleration_g) <= tol.acceleration_rtol * a))
        rows = paper[at_case].sort_values("fill_percent")
        paper_points = pd.DataFrame({
            PACKING_RATIO_COLUMN: rows["fill_percent"].to_numpy(float),
            "SDC DEM (paper) [-]": rows["sdc_dem"].to_numpy(float),
            "SDC measured (paper) [-]": rows["sdc_experimental"].to_numpy(float)})
        model = SdcModel.from_table(paper, value="sdc_dem", source="paper Table 3 (DEM)")
        point = model_point(model, tol, case.acceleration_g, case.frequency_hz)
        if point is None:
            notes.append(f"{case.label()} lies outside the range of the paper's pchip model; "
                         "no model curve (never extrapolated)")
        else:
            lo, hi = model.bounds["fill_percent"]
            model_x = np.linspace(lo, hi, model_points)
            model_y = np.asarray(model(model_x, point[0], point[1]), dtype=float)
            if point[2]:
                notes.append(point[2])
            # at 1000 Hz, 1 g the curve's 75-90 % stretch is Table 3's gap held flat: it was
            # drawn as the paper's model with no word
            held = sorted(filled_corners(model, (model_x, point[0], point[1])))
            if held:
                notes.append(f"the paper's pchip curve has no Table 3 DEM value at "
                             f"{'; '.join(held)}: the model holds the nearest printed fill's "
                             "SDC there, not a value of the paper's")
    # (runs counted once as the same simulation are said by the alignment's message, shown
    # beside these notes)
    grid = getattr(aligned, "grid_case", None)
    m_c = float(grid.vibrated_mass_kg) if grid is not None else math.nan
    if grid is None and aligned.status == "interpolated":
        # the m_c a run at this fill would divide by, as `pidcore report` takes it: the
        # headline said "not comparable: the DEM case has no m_c" where the report's row
        # compared the like-for-like SDC
        _, m_c, no_mass = interpolated_count_and_mass(runs, case)
        if no_mass:
            notes.append(f"no DEM m_c at {case.label()}: no like-for-like SDC ({no_mass})")
    eq10, sdc10, stderr10 = pooled_sdc_eq10(
        np.array([r.energy_per_cycle_j for r in records]),
        np.array([r.acceleration_m_s2 for r in records]),
        np.array([r.frequency_hz for r in records]), values, errors,
        vibrated_mass_kg=m_c)
    stderr10_dof = math.nan
    if math.isfinite(m_c):
        measured[MEASURED_EQ10_COLUMN] = eq10
        stderr10_dof = pooled_stderr_dof(eq10, errors * eq10 / values,
                                         np.array([r.sdc_stderr_dof for r in records]))
    return CaseComparison(case, measured, sdc, stderr, aligned, dem_points, paper_points,
                          model_x, model_y, sdc10, stderr10, chi2 / dof if dof else math.nan,
                          tuple(notes), stderr_dof, stderr10_dof, m_c, baseline_sdc)


#: Name of the DEM's damper of :func:`equivalent_dampers` for an interpolated case: its SDC is
#: the pchip model's, not a run's.
INTERPOLATED_DAMPER_NAME = "our DEM (from the interpolated SDC)"


def equivalent_dampers(comparison: CaseComparison) -> dict[str, float]:
    """The equivalent viscous damper ``c_eq = SDC m_c w / (2 pi)`` [N s/m] of a compared case,
    the ``c_eq_per_coupon [N s/m]`` of ``pidcore model damper``: ``"our DEM"`` (its grid
    case's SDC and m_c; :data:`INTERPOLATED_DAMPER_NAME` for an interpolated case: the pchip
    model's SDC at the measured frequency with the m_c a run at this fill would have,
    :attr:`CaseComparison.vibrated_mass_kg`) and ``"measured"`` (the pooled Eq. 10 SDC with
    the same m_c, at the measured frequency: ``dE / (pi w X^2)`` of the measured energy per
    cycle). Empty where the DEM states no m_c (no DEM value, or runs that do not say one
    specimen); a value is left out where its SDC is not finite."""
    from ..model.damper import equivalent_damping_coefficient

    grid = getattr(comparison.aligned, "grid_case", None)
    m_c = float(getattr(grid, "vibrated_mass_kg", comparison.vibrated_mass_kg))
    if not (math.isfinite(m_c) and m_c > 0):
        return {}
    if grid is not None:
        dem = ("our DEM", grid.sdc, grid.load_case.frequency_hz)
    elif getattr(comparison.aligned, "status", "") == "interpolated":
        # the report's row has this m_c too; the page left the damper empty
        dem = (INTERPOLATED_DAMPER_NAME, float(comparison.aligned.sdc_dem),
               comparison.load_case.frequency_hz)
    else:
        return {}
    found = {dem[0]: dem[1:],
             "measured": (comparison.measured_sdc_eq10, comparison.load_case.frequency_hz)}
    return {name: float(equivalent_damping_coefficient(sdc, vibrated_mass_kg=m_c,
                                                       frequency_hz=freq))
            for name, (sdc, freq) in found.items() if math.isfinite(sdc)}


@dataclass(frozen=True)
class Headline:
    """The one line per load case: like-for-like measured SDC beside our DEM.

    Attributes
    ----------
    measured, measured_stderr : float
        Measured SDC with the Eq. 10 energy of the DEM case when known (like for like), else
        the Eq. 11 SDC, [-].
    measured_kind : str
        ``"Eq. 10 (DEM m_c)"`` or ``"Eq. 11"``.
    dem, dem_stderr : float
        Our DEM SDC (grid or pchip) [-]; NaN when there is none.
    sigmas : float
        |measured - DEM| / sigma, sigma = sqrt(measured stderr^2 + DEM stderr^2) (the known
        one alone where the other has none: then an upper bound); NaN when not comparable.
    verdict : str
        What was found, short enough for a heading, e.g. ``"agrees: |measured − DEM| = 0.83 σ,
        inside the 95 % interval ±2.45 σ"``, ``"no DEM value at this case: no DEM runs of ours
        for acrylic, direction z"``.
    basis : str
        What σ and the interval are, with the verdict's numbers, e.g. ``"σ = √(measured
        stderr² + DEM stderr²); ±2.45 σ: Student t of 6.03 degrees of freedom,
        Welch-Satterthwaite"`` (shown below the verdict: in the heading it wrapped); ``""``
        where nothing was judged.
    interval_sigmas : float
        Half-width of the 95 % interval of measured - DEM, in sigma: Student's t_0.975 of
        ``stderr_dof`` (:func:`pidcore.compare.align.band_quantile`); NaN when not
        comparable.
    stderr_dof : float
        Degrees of freedom of sigma: Welch-Satterthwaite's of the two standard errors' own
        (:func:`pidcore.compare.align.welch_satterthwaite_dof`); NaN where neither
        states them (normal: 1.96).
    agrees : bool or None
        Whether |measured - DEM| <= interval_sigmas x sigma: the verdict's "agrees" and what a
        count of agreeing cases counts; None when not comparable, or when one side has no
        standard error and the difference lies outside the other side's interval (then it
        is unknown whether it lies outside the whole one).
    """

    measured: float
    measured_stderr: float
    measured_kind: str
    dem: float
    dem_stderr: float
    sigmas: float
    verdict: str
    interval_sigmas: float = math.nan
    stderr_dof: float = math.nan
    agrees: bool | None = None
    basis: str = ""


def headline(comparison: CaseComparison, *, why_no_dem: str = "") -> Headline:
    """Measured (like for like) vs our DEM for one load case: whether their difference lies
    inside its 95 % interval, ±t_0.975 sigma with sigma = sqrt(measured stderr^2 + DEM
    stderr^2) and t of their Welch-Satterthwaite degrees of freedom (1.96 where neither states
    them). The verdict names the interval; its basis says what sigma is and which quantile.
    Without a DEM value the verdict says why: ``why_no_dem`` (what the caller knows of the
    runs, e.g. those of another specimen left out), else the alignment's message."""
    c = comparison
    if math.isfinite(c.measured_sdc_eq10):
        m, m_se, kind = c.measured_sdc_eq10, c.measured_stderr_eq10, "Eq. 10 (DEM m_c)"
        m_dof = c.measured_stderr_eq10_dof
    else:
        m, m_se, kind = c.measured_sdc, c.measured_stderr, "Eq. 11"
        m_dof = c.measured_stderr_dof
    dem = float(getattr(c.aligned, "sdc_dem", math.nan))
    dem_se = float(getattr(c.aligned, "sdc_dem_stderr", math.nan))
    grid = getattr(c.aligned, "grid_case", None)
    dem_dof = float(getattr(grid, "sdc_stderr_dof", math.nan)) if grid is not None else math.nan
    if not math.isfinite(dem):
        # "vs our DEM none" read as a number; the reason was only in a caption further down
        why = why_no_dem or getattr(c.aligned, "message", "")
        return Headline(m, m_se, kind, dem, dem_se, math.nan,
                        "no DEM value at this case" + (f": {why}" if why else ""))
    if kind == "Eq. 11":
        return Headline(m, m_se, kind, dem, dem_se, math.nan,
                        "not comparable: the DEM case has no m_c for the Eq. 10 energy")
    parts = [(se, dof) for se, dof in ((m_se, m_dof), (dem_se, dem_dof)) if math.isfinite(se)]
    se = math.sqrt(sum(p[0] ** 2 for p in parts))
    if not se > 0:
        return Headline(m, m_se, kind, dem, dem_se, math.nan, "no standard error to judge by")
    dof = welch_satterthwaite_dof([p[0] for p in parts], [p[1] for p in parts])
    q = band_quantile(dof)
    quantile = ("normal, neither standard error states its degrees of freedom"
                if math.isnan(dof) else f"Student t of {dof:.3g} degrees of freedom"
                + (", Welch-Satterthwaite" if len(parts) == 2 else ""))
    z = abs(m - dem) / se
    inside = z <= q
    z_text = display_sigmas(z)
    interval = f"the 95 % interval ±{q:.3g} σ"
    # the verdict is a heading's end; what σ and the interval are goes in its basis, below it
    quantile_basis = f"±{q:.3g} σ: {quantile}"
    if len(parts) == 2:
        basis = f"σ = √(measured stderr² + DEM stderr²); {quantile_basis}"
        verdict = (f"agrees: |measured − DEM| = {z_text} σ, inside {interval}" if inside else
                   f"differs: |measured − DEM| = {z_text} σ, outside {interval}")
    else:
        # one side's error is unknown (a 1-cell DEM run, a single record without one): the
        # combined σ is at least the known side's, so z is an upper bound; "differs by" would
        # overstate it ("differs by 314 σ" of a 1-cell run against the measurement's σ alone)
        unknown, known = (("DEM value", "measured") if not math.isfinite(dem_se)
                          else ("measured value", "DEM"))
        basis = (f"σ: the {known} stderr alone, the {unknown} has no standard error; "
                 f"{quantile_basis}")
        if inside:  # inside with the known σ alone: inside the whole, wider interval too
            verdict = f"agrees: |measured − DEM| ≤ {z_text} σ, inside {interval}"
        else:  # outside the known side's interval only: the whole one is unknown
            verdict = (f"differs by up to {z_text} σ: outside {interval} of the {known} stderr "
                       "alone")
            basis = (f"σ: the {known} stderr alone; the {unknown} has no standard error (e.g. "
                     "a 1-cell run), so whether it lies outside the whole interval is unknown; "
                     f"{quantile_basis}")
            return Headline(m, m_se, kind, dem, dem_se, z, verdict, q, dof, None, basis)
    return Headline(m, m_se, kind, dem, dem_se, z, verdict, q, dof, bool(inside), basis)


#: Series of :func:`sdc_points`, in legend order.
SDC_SERIES = ("pchip model (paper Table 3 DEM)", "paper DEM", "paper measured",
              "our DEM (mean ± stderr)", "our DEM (pchip over our runs)", "measured (± stderr)",
              "measured, E of Eq. 10 (± stderr)")


def sdc_points(comparison: CaseComparison) -> pd.DataFrame:
    """SDC against fill for one load case, one row per point (the chart's data).

    Columns ``series`` (one of :data:`SDC_SERIES`), ``packing ratio [%]``, ``SDC [-]``,
    ``low [-]`` and ``high [-]`` (value ± standard error; equal to the value where there is no
    error).
    """
    c = comparison
    parts = []

    def add(series: str, fill, sdc, err=None) -> None:
        fill = np.asarray(fill, dtype=float)
        sdc = np.asarray(sdc, dtype=float)
        err = np.zeros_like(sdc) if err is None else np.nan_to_num(np.asarray(err, float))
        keep = np.isfinite(sdc)
        parts.append(pd.DataFrame({"series": series, PACKING_RATIO_COLUMN: fill[keep],
                                   "SDC [-]": sdc[keep], "low [-]": (sdc - err)[keep],
                                   "high [-]": (sdc + err)[keep]}))

    add(SDC_SERIES[0], c.model_fill_percent, c.model_sdc)
    paper_fill = c.paper_points[PACKING_RATIO_COLUMN]
    add(SDC_SERIES[1], paper_fill, c.paper_points["SDC DEM (paper) [-]"])
    add(SDC_SERIES[2], paper_fill, c.paper_points["SDC measured (paper) [-]"])
    add(SDC_SERIES[3], c.dem_points[PACKING_RATIO_COLUMN], c.dem_points["SDC [-]"],
        c.dem_points["SDC stderr [-]"])
    if getattr(c.aligned, "status", "") == "interpolated":
        add(SDC_SERIES[4], [c.load_case.fill_percent], [c.aligned.sdc_dem])
    add(SDC_SERIES[5], [c.load_case.fill_percent], [c.measured_sdc], [c.measured_stderr])
    add(SDC_SERIES[6], [c.load_case.fill_percent], [c.measured_sdc_eq10],
        [c.measured_stderr_eq10])
    return pd.concat(parts, ignore_index=True)
