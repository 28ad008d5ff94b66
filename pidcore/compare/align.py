"""Align measured load cases with our DEM results and with the paper's Table 3.

A measured case (frequency and acceleration measured, fill/material/direction stated) is
compared with our DEM in one of these ways, named by :data:`AlignmentStatus`:

``"grid"``
    A DEM case of ours lies within the tolerances of :mod:`pidcore.defaults`
    (``COMPARE_FREQUENCY_RTOL`` 1 % in frequency, ``COMPARE_ACCELERATION_RTOL`` 5 % in
    acceleration, ``COMPARE_FILL_ATOL_PERCENT`` 0.5 points in fill) with the same material and
    direction; its runs' mean SDC is used.
``"interpolated"``
    No such DEM case; the pchip model (:class:`pidcore.model.SdcModel`) over our DEM cases is
    evaluated at the measured point, which lies inside the model's grid box, or at the box's
    edge where the frequency or acceleration lies outside it within the tolerances above (a
    measured 49.9995 Hz is the 50 Hz edge: :func:`model_point`; the message says so).
``"out_of_range"``
    Outside the model's box: no value, a message says why. The model is never extrapolated.
``"no_model"``
    Off the DEM grid, and the runs at the case's material and direction give no pchip model
    (fewer than two distinct values along an axis: one fill run, say): no value, the message
    says why. It was labelled ``out_of_range``, which the message contradicted.
``"no_dem_runs"``
    No DEM run of ours at the case's material and direction at all (of the specimen compared):
    nothing to interpolate, so "out of range" would mislead; a message says which runs the store
    holds instead.

The paper's DEM and experimental values are attached where the case is a Table 3 grid point
within the same tolerances (the paper used acrylic particles driven along z); otherwise NaN.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from .. import defaults
from ..constants import (  # noqa: F401 (AlignmentStatus kept: defined here before; PACKING_RATIO_COLUMN public here)
    ALIGNMENT_STATUSES,
    BAND_VERDICTS,
    PACKING_RATIO_COLUMN,
    AlignmentStatus,
)
from ..errors import ParameterError, real_number
from .loadcase import LoadCase

#: Columns a table of measured cases must have (one row per analysed measurement).
MEASURED_COLUMNS: tuple[str, ...] = ("frequency_hz", "acceleration_g", "fill_percent", "material",
                                     "direction", "sdc", "sdc_stderr", "source")
#: Columns a table of DEM runs must have (as :meth:`pidcore.store.Store.list_dem_runs` gives).
DEM_COLUMNS: tuple[str, ...] = ("frequency_hz", "acceleration_g", "fill_percent", "material",
                                "direction", "sdc", "sdc_stderr")
#: The measured Eq. 11 SDC (Im(P_c)/w as the energy), its standard error and that error's
#: degrees of freedom, as every table of pidcore names them (:func:`align_measured`'s frame,
#: the report's files, :mod:`pidcore.report.table`): the SDC the calibrated DEM predicts, not
#: the like-for-like counterpart of our DEM's (Eq. 10's energy). Named "SDC measured [-]"
#: before: beside "SDC DEM (ours) [-]" a reader compared 1.139 with 0.6054 (a factor 2) where
#: the like-for-like 0.624 agrees.
MEASURED_EQ11_COLUMN = "SDC measured (Eq. 11) [-]"
MEASURED_EQ11_STDERR_COLUMN = "SDC measured (Eq. 11) stderr [-]"
MEASURED_EQ11_DOF_COLUMN = "SDC measured (Eq. 11) stderr dof [-]"
#: Measured energy per cycle over the DEM case's E = m_c a^2 / (2 w^2) (Eq. 10): the like-for-like
#: counterpart of our DEM SDC. The Eq. 11 SDC divides by Im(P_c)/w instead, the reactive energy,
#: which is smaller than Eq. 10's E whenever particles fly free of the cell walls.
MEASURED_EQ10_COLUMN = "SDC measured, E of Eq. 10 [-]"
#: The part of the measured Eq. 11 SDC that its analysis took off as the empty coupon's damping
#: (``analyze --baseline-loss-factor``; pooled as the SDC is; 0 where none was taken off, NaN
#: where a record did but its SDC before that is not known): the calibrated DEM predicts the SDC
#: before the subtraction (it adds a baseline of its own), so its band judges the sum.
MEASURED_BASELINE_COLUMN = "baseline SDC taken off the measured (Eq. 11) [-]"
#: The Eq. 11 columns renamed in 2026-12: old name -> new name, for scripts reading a table an
#: earlier pidcore wrote (``frame.rename(columns=MEASURED_COLUMNS_RENAMED)``): a report.csv
#: (:data:`pidcore.report.REPORT_COLUMNS_RENAMED`) or a saved :func:`align_measured` frame.
MEASURED_COLUMNS_RENAMED: dict[str, str] = {
    "SDC measured [-]": MEASURED_EQ11_COLUMN,
    "SDC measured stderr [-]": MEASURED_EQ11_STDERR_COLUMN,
    "SDC measured stderr dof [-]": MEASURED_EQ11_DOF_COLUMN,
}
#: The calibrated DEM's Eq. 11 SDC and its 95 % band (a measurement's, with its standard error),
#: as every table of pidcore names them: the report's columns
#: (:func:`pidcore.report.table.add_calibration_columns`) and
#: :meth:`pidcore.calibrate.Calibration.to_pandas`, which said "sdc predicted [-]",
#: "low95 [-]" and "high95 [-]" before 2026-12
#: (:data:`pidcore.calibrate.CALIBRATION_COLUMNS_RENAMED`).
CALIBRATED_COLUMN = "SDC calibrated DEM (Eq. 11) [-]"
CALIBRATED_LOW_COLUMN = "calibrated low 95 % [-]"
CALIBRATED_HIGH_COLUMN = "calibrated high 95 % [-]"
#: Whether the measured Eq. 11 SDC lies in that band (words of
#: :data:`pidcore.constants.BAND_VERDICTS`): the report's column and
#: :meth:`pidcore.calibrate.Calibration.to_pandas`'s, which said "measured in 95 % band [...]"
#: before 2026-12.
CALIBRATED_INSIDE_COLUMN = f"measured in calibrated 95 % band [{'/'.join(BAND_VERDICTS)}]"
#: The one column a page shows the calibrated band in, as :func:`pidcore.calibrate.prediction.
#: band_text` writes it (the terminal's and PDF's report tables, the app's Report tab, the
#: calibration's summary.md and summary.html).
CALIBRATED_BAND_COLUMN = "calibrated 95 % band [-]"
#: The paper's particles and drive direction (Sect. 4): Table 3 applies to these only.
PAPER_MATERIAL = "acrylic"
PAPER_DIRECTION = "z"


@dataclass(frozen=True)
class Tolerances:
    """When two load cases are the same grid point.

    Attributes
    ----------
    frequency_rtol : float
        Relative frequency tolerance, ``|f - f_grid| <= rtol * f_grid``.
    acceleration_rtol : float
        Relative acceleration tolerance.
    fill_atol_percent : float
        Absolute fill tolerance, percentage points.
    """

    frequency_rtol: float = defaults.COMPARE_FREQUENCY_RTOL
    acceleration_rtol: float = defaults.COMPARE_ACCELERATION_RTOL
    fill_atol_percent: float = defaults.COMPARE_FILL_ATOL_PERCENT

    def __post_init__(self) -> None:
        for name in ("frequency_rtol", "acceleration_rtol", "fill_atol_percent"):
            value = getattr(self, name)
            real_number(f"Tolerances: {name}", value)  # "0.1" was a TypeError of math
            if not (math.isfinite(value) and value >= 0):
                raise ParameterError(f"Tolerances: {name} must be a finite number >= 0, "
                                     f"got {value!r}")

    def matches(self, case: LoadCase, grid: LoadCase) -> bool:
        """True if ``case`` is the grid point ``grid``."""
        return (abs(case.frequency_hz - grid.frequency_hz)
                <= self.frequency_rtol * grid.frequency_hz
                and abs(case.acceleration_g - grid.acceleration_g)
                <= self.acceleration_rtol * grid.acceleration_g
                and abs(case.fill_percent - grid.fill_percent) <= self.fill_atol_percent
                and case.material == grid.material and case.direction == grid.direction)

    def distance(self, case: LoadCase, grid: LoadCase) -> float:
        """Distance in units of the tolerances (picks the nearest of several matches)."""
        parts = (
            (case.frequency_hz - grid.frequency_hz) / max(self.frequency_rtol * grid.frequency_hz,
                                                           1e-300),
            (case.acceleration_g - grid.acceleration_g)
            / max(self.acceleration_rtol * grid.acceleration_g, 1e-300),
            (case.fill_percent - grid.fill_percent) / max(self.fill_atol_percent, 1e-300),
        )
        return float(np.hypot.reduce(parts))


@dataclass(frozen=True)
class DemCase:
    """Our DEM result at one load case, pooled over its runs (seeds).

    Attributes
    ----------
    load_case : LoadCase
    sdc : float
        Mean SDC of the runs, [-].
    sdc_stderr : float
        Standard error of that mean, [-]: the run's own standard error for one run; for several
        runs the larger of the propagated within-run error ``sqrt(sum se_i^2) / n`` and the
        between-run scatter ``std(sdc, ddof=1) / sqrt(n)``, because independent seeds show the
        chaos of granular flow that a single run's block error cannot.
    n_runs : int
    particles_per_cell : float
        Particles per cell of the runs (NaN if unknown or differing).
    run_keys : tuple of str
        Store keys of the runs.
    vibrated_mass_kg : float
        Mean m_c of the runs (the mass in E = m_c a^2 / (2 w^2), Eq. 10), kg; NaN if unknown.
    settings : str
        The numerical settings the runs share, e.g.
        ``"cells 8, steady cycles auto, settings hash 3fa2c1"`` (every input but the load
        case and the seed); runs of different settings are separate cases unless pooled
        explicitly. Empty where the runs do not record their settings.
    cells_simulated : float
        Cells simulated per run (NaN if unknown); the preferred case of several settings at one
        load case is the one with the most cells.
    not_converged : tuple of (int, int)
        ``(steady_start_cycle, steady_cycles)`` of each run whose steady state was never
        detected (``steady_detected`` false: measured from the transient cap, as ``pidcore dem
        run`` prints "NOT converged, transient cap"); empty where every run converged or the
        runs do not record it.
    duplicate_keys : tuple of str
        Store keys of runs left out because they are the same simulation as a run counted
        (:func:`simulation_identity`: e.g. fills 50 % and 50.2 % both give 11 particles per
        cell, and the same seed gives the same numbers bit for bit). Counting such a run again
        would shrink the standard error by sqrt(2) with no new information. Not in ``n_runs``
        or ``run_keys``.
    duplicate_fills : tuple of float
        Fill percentages, %, the duplicates were stored with (for the note).
    sdc_stderr_dof : float
        Degrees of freedom of ``sdc_stderr`` (:func:`pooled_stderr_dof`): a run's own, as
        stored (``sdc_stderr_dof``: batches - 1 for a run whose cells ran one motion), else
        the scatter of its cells' SDCs, cells - 1; NaN where neither is known.
    particles_full_cell : float
        The particle count the runs took as 100 % fill (their cell's capacity, or the paper's
        36), NaN if unknown or differing: a measured fill that rounds to the case's
        ``particles_per_cell`` of it is the same simulation (:meth:`Aligner.grid_case`).
    """

    load_case: LoadCase
    sdc: float
    sdc_stderr: float
    n_runs: int
    particles_per_cell: float = math.nan
    run_keys: tuple[str, ...] = ()
    vibrated_mass_kg: float = math.nan
    settings: str = ""
    cells_simulated: float = math.nan
    not_converged: tuple[tuple[int, int], ...] = ()
    duplicate_keys: tuple[str, ...] = ()
    duplicate_fills: tuple[float, ...] = ()
    sdc_stderr_dof: float = math.nan
    particles_full_cell: float = math.nan


def duplicates_note(dem: DemCase) -> str:
    """The note for a DEM case with stored runs counted once (:attr:`DemCase.duplicate_keys`);
    "" where there are none. The report table and the app's Compare tab say it alike."""
    if not dem.duplicate_keys:
        return ""
    n = len(dem.duplicate_keys)
    fills = ", ".join(f"{f:g} %" for f in dict.fromkeys(dem.duplicate_fills))
    ppc = (f"{dem.particles_per_cell:g} particles per cell, "
           if math.isfinite(dem.particles_per_cell) else "")
    return (f"{n} stored DEM run(s) counted once: the same simulation ({ppc}seed, settings "
            f"and specimen) as a run counted, stored under another key (fill {fills}); "
            f"{dem.n_runs} distinct run(s) used")


@dataclass(frozen=True)
class AlignedCase:
    """One measured case next to our DEM and the paper.

    Attributes
    ----------
    load_case : LoadCase
        The measured case (measured frequency and acceleration, stated fill/material/direction).
    status : str
        One of :data:`AlignmentStatus`.
    sdc_dem : float
        Our DEM SDC at the case [-] (mean of the grid case's runs, or the model's value); NaN
        when out of range.
    sdc_dem_stderr : float
        Standard error of ``sdc_dem`` [-]; NaN for interpolated values (the model carries none).
    grid_case : DemCase or None
        The matched DEM case for status ``"grid"``.
    sdc_paper_dem, sdc_paper_experimental : float
        The paper's Table 3 values at the case [-], NaN where Table 3 has none.
    paper_case : LoadCase or None
        The Table 3 grid point matched.
    message : str
        Why the status is what it is (model used, range it covers...).
    unconverged_nodes : tuple of str
        For an interpolated value: the labels of the DEM cases at the corners of the grid
        cell it lies in whose runs never reached a steady state (``message`` names them).
    """

    load_case: LoadCase
    status: str
    sdc_dem: float = math.nan
    sdc_dem_stderr: float = math.nan
    grid_case: DemCase | None = None
    sdc_paper_dem: float = math.nan
    sdc_paper_experimental: float = math.nan
    paper_case: LoadCase | None = None
    message: str = ""
    unconverged_nodes: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, float | str]:
        """One row with unit-suffixed column names."""
        lc = self.load_case
        return {
            **lc.columns(),
            "load case": lc.key,
            "alignment": self.status,
            "SDC DEM (ours) [-]": self.sdc_dem,
            "SDC DEM stderr [-]": self.sdc_dem_stderr,
            "DEM grid case": self.grid_case.load_case.key if self.grid_case else "",
            "SDC DEM (paper) [-]": self.sdc_paper_dem,
            "SDC measured (paper) [-]": self.sdc_paper_experimental,
            "message": self.message,
        }


def _check_columns(table: pd.DataFrame, columns: Iterable[str], what: str) -> None:
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise ParameterError(f"{what}: missing columns {missing}; expected {list(columns)}")


def _row_case(row: pd.Series) -> LoadCase:
    for name in ("frequency_hz", "acceleration_g", "fill_percent"):
        try:  # a number per field, not a pandas Series per field: called once per run
            value = float(row.get(name))
        except (TypeError, ValueError):
            value = math.nan
        if not (math.isfinite(value) and value > 0):
            # a run stored without its load case (by hand, through the library): the report
            # said "load case: --frequency must be ..." and named no run
            key = row.get("case_key", row.name)
            raise ParameterError(
                f"DEM run {key!r}: record field {name} is {row.get(name)!r}; expected a "
                "positive number (a run stored without its load case cannot be compared)")
    material = row.get("material", defaults.COMPARE_DEFAULT_MATERIAL)
    direction = row.get("direction", defaults.COMPARE_DEFAULT_DIRECTION)
    return LoadCase(float(row["frequency_hz"]), float(row["acceleration_g"]),
                    float(row["fill_percent"]),
                    material if isinstance(material, str) and material
                    else defaults.COMPARE_DEFAULT_MATERIAL,
                    direction if isinstance(direction, str) and direction
                    else defaults.COMPARE_DEFAULT_DIRECTION)


def pooled_mean(values: np.ndarray, stderrs: np.ndarray) -> tuple[float, float]:
    """Mean and its standard error, pooled as described in :class:`DemCase`.

    For one value both numbers are returned unchanged (bit for bit).
    """
    values = np.asarray(values, dtype=float)
    stderrs = np.asarray(stderrs, dtype=float)
    if values.size == 1:
        return float(values[0]), float(stderrs[0])
    n = values.size
    mean = float(np.mean(values))
    within = float(np.sqrt(np.sum(stderrs ** 2)) / n) if np.all(np.isfinite(stderrs)) else math.nan
    between = float(np.std(values, ddof=1) / math.sqrt(n))
    return mean, float(np.nanmax([within, between]))


def pooled_baseline_sdc(values: np.ndarray, stderrs: np.ndarray, taken: np.ndarray) -> float:
    """The part of the pooled SDC (:func:`pooled_mean` of ``values``) that the records'
    analyses took off as the empty coupon's damping, ``taken`` each
    (:func:`pidcore.signal.power.baseline_sdc_taken_off`): the pooled SDC before the subtraction
    less the pooled SDC, whatever weights the pooling gives. 0 where no record took any off;
    NaN where one did by an unknown amount."""
    taken = np.asarray(taken, dtype=float)
    if not np.any(taken):
        return 0.0
    values = np.asarray(values, dtype=float)
    return pooled_mean(values + taken, stderrs)[0] - pooled_mean(values, stderrs)[0]


def stored_stderr_dof(value: object) -> float:
    """The ``sdc_stderr_dof`` of a stored analysis record (:attr:`pidcore.signal.power.
    PowerAnalysis.sdc_stderr_dof`, n_blocks - 1) as a number; NaN where the record has none
    (an older or foreign store, or no standard error): unknown, taken as normal."""
    try:
        dof = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return math.nan
    return dof if math.isfinite(dof) and dof > 0 else math.nan


def pooled_stderr_dof(values: np.ndarray, stderrs: np.ndarray, dofs: np.ndarray) -> float:
    """Degrees of freedom of :func:`pooled_mean`'s standard error, for its 95 % quantile
    (:func:`band_quantile`): one value's own ``dofs``; of the scatter between several, n - 1;
    of their propagated errors, Welch-Satterthwaite's (sum se^2)^2 / sum(se^4 / dof). NaN
    where unknown (a stderr without its degrees of freedom: the normal's quantile, as before
    they were kept)."""
    values = np.asarray(values, dtype=float)
    stderrs = np.asarray(stderrs, dtype=float)
    dofs = np.asarray(dofs, dtype=float)
    if values.size == 1:
        return float(dofs[0])
    n = values.size
    within = float(np.sqrt(np.sum(stderrs ** 2)) / n) if np.all(np.isfinite(stderrs)) else math.nan
    between = float(np.std(values, ddof=1) / math.sqrt(n))
    if not within > between:  # pooled_mean took the scatter between them (or within is NaN)
        return float(n - 1)
    if not (np.all(np.isfinite(dofs)) and np.all(dofs > 0)):
        return math.nan
    return welch_satterthwaite_dof(stderrs, dofs)


def welch_satterthwaite_dof(stderrs: Sequence[float] | np.ndarray,
                            dofs: Sequence[float] | np.ndarray) -> float:
    """Welch-Satterthwaite degrees of freedom of sqrt(sum se^2): (sum se^2)^2 /
    sum(se^4 / dof), a standard error whose degrees of freedom are unknown (NaN) counted as
    known exactly (infinite: normal, as :func:`band_quantile` takes it alone); NaN where
    none states them (or every error is 0)."""
    variances = np.asarray(stderrs, dtype=float) ** 2
    dofs = np.asarray(dofs, dtype=float)
    known = np.isfinite(dofs) & (dofs > 0) & (variances > 0)
    if not known.any():
        return math.nan
    return float(np.sum(variances) ** 2 / np.sum(variances[known] ** 2 / dofs[known]))


#: Two-sided 95 % quantile of the normal distribution (a measurement's stderr -> half-width)
#: where the stderr's degrees of freedom are unknown.
Z95 = 1.959963984540054


def band_quantile(dof: float = math.nan) -> float:
    """Two-sided 95 % quantile that turns a standard error into a half-width: Student's
    t_{0.975, dof} where the stderr's degrees of freedom are known (``n_blocks - 1`` of an
    analysis by pidcore: the errors of a mean over 8 block estimates follow a t with 7,
    whose quantile is 2.365; 1.96 covered ~91 %), else (NaN) the normal's :data:`Z95`.

    Raises
    ------
    ParameterError
        ``dof`` not NaN and not > 0.
    """
    from scipy.stats import t as student_t

    dof = real_number("dof", dof)
    if math.isnan(dof):
        return Z95
    if not dof > 0:
        raise ParameterError(f"dof {dof!r}: expected the degrees of freedom of a standard "
                             "error (> 0, e.g. n_blocks - 1), or NaN where unknown")
    return float(student_t.ppf(0.975, dof))


def quantile_label(dof: float = math.nan) -> str:
    """Which quantile :func:`band_quantile` uses, for a line beside a band: e.g.
    ``'Student t quantile 2.365 of 7 degrees of freedom'`` or ``'normal quantile 1.96, the
    degrees of freedom of the stderr unknown'``."""
    q = band_quantile(dof)
    if math.isnan(dof):
        return f"normal quantile {q:.3g}, the degrees of freedom of the stderr unknown"
    return f"Student t quantile {q:.4g} of {dof:.4g} degrees of freedom"


def pooled_sdc_eq10(energy_per_cycle_j: np.ndarray, acceleration_m_s2: np.ndarray,
                    frequency_hz: np.ndarray, sdc_eq11: np.ndarray, sdc_eq11_stderr: np.ndarray,
                    *, vibrated_mass_kg: float) -> tuple[np.ndarray, float, float]:
    """Measured SDC over the DEM case's ``E = m_c a^2 / (2 w^2)`` (Eq. 10), per record and pooled.

    The like-for-like counterpart of our DEM SDC (the Eq. 11 SDC divides by the reactive
    energy instead). Each record keeps the relative standard error of its Eq. 11 SDC: only the
    reference energy differs. Returns ``(values, pooled mean, pooled stderr)``
    (:func:`pooled_mean`); all NaN where ``vibrated_mass_kg`` is unknown.
    """
    from ..model.damper import sdc_from_energy_per_cycle

    energy = np.asarray(energy_per_cycle_j, dtype=float)
    if not math.isfinite(vibrated_mass_kg) or energy.size == 0:
        return np.full(energy.shape, math.nan), math.nan, math.nan
    values = np.array([sdc_from_energy_per_cycle(float(e), vibrated_mass_kg=vibrated_mass_kg,
                                                 acceleration_m_s2=float(a),
                                                 frequency_hz=float(f))
                       for e, a, f in zip(energy, acceleration_m_s2, frequency_hz, strict=True)])
    scale = values / np.asarray(sdc_eq11, dtype=float)
    mean, stderr = pooled_mean(values, np.asarray(sdc_eq11_stderr, dtype=float) * scale)
    return values, mean, stderr


def consistency_chi2(values: np.ndarray, stderrs: np.ndarray) -> tuple[float, int]:
    """Chi-square of ``values`` about their inverse-variance mean and its degrees of freedom.

    A pooled set of measurements is consistent when chi2 / dof is about 1; much larger means
    the records scatter more than their own errors allow (different set-ups, a wrong
    correction). Returns ``(nan, 0)`` for fewer than two finite values with finite errors.
    """
    v = np.asarray(values, dtype=float)
    e = np.asarray(stderrs, dtype=float)
    ok = np.isfinite(v) & np.isfinite(e) & (e > 0)
    if ok.sum() < 2:
        return math.nan, 0
    w = 1.0 / e[ok] ** 2
    mean = float(np.sum(w * v[ok]) / np.sum(w))
    return float(np.sum(w * (v[ok] - mean) ** 2)), int(ok.sum() - 1)


def stored_parameters(parameters_json: object) -> dict | None:
    """A DEM run's stored inputs as a dict (from a store listing's JSON string, or a dict
    :func:`pidcore.dem.persist.run_parameters` gives); None where none are readable."""
    import json

    if isinstance(parameters_json, dict):
        return _automatic_cycles_unstated(dict(parameters_json))
    if not isinstance(parameters_json, str) or not parameters_json:
        return None
    try:
        params = json.loads(parameters_json)
    except ValueError:
        return None
    return _automatic_cycles_unstated(params) if isinstance(params, dict) else None


#: The entry of a stored DEM run's inputs (``parameters_json``) that says where its specimen
#: came from, not an input of its numbers (no key, identity or settings hash holds it):
#: ``null`` for the run of a specimen file as given (``pidcore dem run``, sweeps, the app),
#: ``{"of_name", "of_sha256", "values"}`` for a run of a calibration's variant of the file
#: ``of_name`` [``of_sha256``] at a design point (``values``: ``[name, value]`` pairs of the
#: fitted DEM parameters by the names ``--fit`` took, as the design set them), absent in a
#: run stored before pidcore recorded it (either). Written by
#: :func:`pidcore.dem.persist.dem_run_entry`, read by :func:`pidcore.compare.specimens.
#: run_origin`.
CALIBRATION_VARIANT_FIELD = "calibration_variant"


def parameters_digest(params: Mapping[str, object]) -> str:
    """The sha256 (hex) of a DEM run's inputs: their JSON with sorted keys, any value JSON
    lacks as its text. The one spelling of a run's key (:func:`pidcore.dem.persist.run_key`),
    its simulation identity and its settings hash, which must hash alike to meet."""
    import hashlib
    import json

    return hashlib.sha256(json.dumps(params, sort_keys=True, default=str).encode()).hexdigest()


def _automatic_cycles_unstated(params: dict) -> dict:
    """``params`` with a stated ``config_steady_cycles`` that equals the automatic count
    written as unstated (""), as :func:`pidcore.dem.simulate.config_parameters` now writes it:
    runs stored before with `--cycles 80` are the same simulation and settings as the
    default's."""
    block = params.get("config_block_cycles", defaults.DEM_STEADY_BLOCK_CYCLES)
    steady = params.get("config_steady_cycles")
    if (isinstance(steady, int) and not isinstance(steady, bool) and isinstance(block, int)
            and steady == defaults.dem_automatic_steady_cycles(block)):
        params["config_steady_cycles"] = ""
    return params


def run_settings(parameters_json: object) -> dict | None:
    """A DEM run's numerical settings: every stored input (its ``parameters_json``) except the
    load case and the seed; None where they are not stored or not readable."""
    params = stored_parameters(parameters_json)
    if params is None:
        return None
    return {k: v for k, v in params.items() if not k.startswith("case_")
            and k not in ("config_seed", CALIBRATION_VARIANT_FIELD)}


def simulation_identity(parameters_json: object, particles_per_cell: object) -> str | None:
    """What makes two stored DEM runs the same simulation (hex digest), or None where a run
    does not record its inputs.

    A run's key (:func:`pidcore.dem.persist.run_key`) hashes the fill percentage as stated,
    but the simulation reads it only through the particle count it rounds to
    (:func:`pidcore.dem.simulate.particles_per_cell`): fills 50 % and 50.2 % of a 22-particle
    cell both run 11 particles, and with the same seed give the same numbers bit for bit. The
    identity is therefore every stored input except ``case_fill_percent`` and
    ``specimen_text`` (its hash ``specimen_sha256`` stands for it), plus the particles per
    cell. ``parameters_json``: a JSON string (a store listing's column) or a dict
    (:func:`pidcore.dem.persist.run_parameters`).
    """
    params = stored_parameters(parameters_json)
    if params is None:
        return None
    try:
        count = float(particles_per_cell)
    except (TypeError, ValueError):
        return None
    if not math.isfinite(count) or "config_seed" not in params:
        return None
    params.pop("case_fill_percent", None)
    params.pop("specimen_text", None)
    # where the specimen came from: the same simulation, whether a calibration or a user
    # stored it
    params.pop(CALIBRATION_VARIANT_FIELD, None)
    # runs stored before the version was recorded are version 1 (pidcore.dem.persist)
    params.setdefault("dem_code_version", 1)
    params["particles_per_cell"] = int(count)
    return parameters_digest(params)


def _settings_digest(settings: dict) -> str:
    return parameters_digest(settings)[:6]


def settings_hash(parameters_json: object) -> str:
    """Hash (6 hex digits) of a DEM run's :func:`run_settings`; "" where they are not
    stored."""
    settings = run_settings(parameters_json)
    return "" if settings is None else _settings_digest(settings)


def _settings_of(row: pd.Series, params: dict | None) -> tuple[str, float]:
    """(label, cells) of the numerical settings of one DEM run: every stored input except the
    load case and the seed (:func:`settings_hash`), with the cells and steady cycles spelled
    out. ``params``: the run's stored inputs (:func:`stored_parameters`)."""
    cells = float(row.get("cells_simulated", math.nan) or math.nan) \
        if "cells_simulated" in row else math.nan
    settings = run_settings(params)
    if settings is None:
        return (f"cells {cells:g}" if math.isfinite(cells) else ""), cells
    digest = _settings_digest(settings)
    if not math.isfinite(cells) and isinstance(settings.get("config_cells"), int | float):
        cells = float(settings["config_cells"])
    steady = settings.get("config_steady_cycles", "")
    # "settings hash": the specimen is named "name [hash]" beside it, another hash
    return (f"cells {cells:g}, steady cycles {steady if steady not in ('', None) else 'auto'}, "
            f"settings hash {digest}"), cells


def dem_cases(dem_runs: pd.DataFrame, *, tolerances: Tolerances | None = None,
              pool_settings: bool = False,
              reference_fills: Iterable[float] = ()) -> list[DemCase]:
    """Group DEM runs into load cases (runs within the tolerances pool into one case).

    Runs of different numerical settings (a 2-cell smoke run beside a 32-cell run), or of
    different particle counts within the fill tolerance (40 and 40.5 % of a 46-sphere cell: 18
    and 19 particles), are separate cases unless ``pool_settings`` is true; only seeds are
    pooled.

    Parameters
    ----------
    dem_runs : pandas.DataFrame
        Columns :data:`DEM_COLUMNS` (plus optional ``case_key`` or ``key``,
        ``particles_per_cell``); one row per
        run, as :meth:`pidcore.store.Store.list_dem_runs` returns. Runs with a non-finite SDC are
        skipped (an interrupted run has no result).
    reference_fills : iterable of float
        Fills, %, the cases are wanted at (the measured or asked ones). Of stored runs that are
        the same simulation (:func:`simulation_identity`) the one whose stored fill is nearest
        the case's reference is counted: the fill a reference within the fill tolerance states,
        else the fill most runs of the case state. The case is labelled by the fill most of
        its counted runs state (ties: the one nearest the reference), so a duplicate stored
        under a near fill (50.2 % beside 50 %) never names the case.

    Returns
    -------
    list of DemCase
        Sorted by frequency, acceleration, fill, material, direction.
    """
    tolerances = tolerances or Tolerances()
    if dem_runs is None or dem_runs.empty:
        return []
    _check_columns(dem_runs, DEM_COLUMNS, "DEM runs")
    runs = dem_runs[np.isfinite(dem_runs["sdc"].astype(float))]
    # each run's stored inputs parsed once, for its settings and its simulation identity
    params = [stored_parameters(v) for v in runs["parameters_json"]] \
        if "parameters_json" in runs.columns else [None] * len(runs)
    # runs of another particle count are another bed, not a replicate, even within the fill
    # tolerance (40 and 40.5 % of a 46-sphere cell: 18 and 19): not pooled unless pooling is
    # asked for (NaN: unknown, joins any)
    counts = pd.to_numeric(runs["particles_per_cell"], errors="coerce").to_numpy(float) \
        if "particles_per_cell" in runs.columns and not pool_settings \
        else np.full(len(runs), np.nan)
    groups: list[tuple[LoadCase, str, list[int]]] = []
    cells_of: dict[str, float] = {}
    for pos, (_, row) in enumerate(runs.iterrows()):
        case = _row_case(row)
        settings, cells = ("", math.nan) if pool_settings else _settings_of(row, params[pos])
        cells_of[settings] = cells
        for grid, grid_settings, members in groups:
            if grid_settings == settings and tolerances.matches(case, grid) and (
                    _same_count(counts[pos], counts[members])):
                members.append(pos)
                break
        else:
            groups.append((case, settings, [pos]))
    wanted = [float(f) for f in reference_fills if math.isfinite(float(f))]
    out = []
    for case, settings, members in groups:
        fills = runs["fill_percent"].astype(float).to_numpy()
        reference = _reference_fill(fills[members], wanted, tolerances)
        members, duplicates = _distinct(runs, members, params, reference)
        label = _label_fill(fills[members], reference)
        if label != case.fill_percent:
            case = replace(case, fill_percent=label)
        sub = runs.iloc[members]
        dup = runs.iloc[duplicates]
        sdc, stderr = pooled_mean(sub["sdc"].to_numpy(float), sub["sdc_stderr"].to_numpy(float))
        cells = cells_of.get(settings, math.nan)
        stderr_dof = pooled_stderr_dof(sub["sdc"].to_numpy(float),
                                       sub["sdc_stderr"].to_numpy(float),
                                       _run_stderr_dofs(sub, cells))
        ppc = full = math.nan
        if "particles_per_cell" in sub:
            unique = pd.unique(sub["particles_per_cell"].astype(float))
            if unique.size == 1:
                ppc = float(unique[0])
        if "particles_full_cell" in sub:
            unique = pd.unique(pd.to_numeric(sub["particles_full_cell"], errors="coerce"))
            if unique.size == 1:
                full = float(unique[0])
        key_column = "case_key" if "case_key" in sub else "key"
        keys = tuple(str(k) for k in sub[key_column]) if key_column in sub else ()
        # "m_c_kg": the column's name in stores written by pidcore 0.1
        mass_column = next((c for c in ("vibrated_mass_kg", "m_c_kg") if c in sub), None)
        m_c = float(sub[mass_column].astype(float).mean()) if mass_column else math.nan
        dup_keys = tuple(str(k) for k in dup[key_column]) if key_column in dup else ()
        dup_fills = tuple(float(f) for f in dup["fill_percent"])
        out.append(DemCase(case, sdc, stderr, len(members), ppc, keys, m_c, settings,
                           cells, _not_converged(sub), dup_keys, dup_fills, stderr_dof, full))
    return sorted(out, key=lambda c: (*_sort_key(c.load_case), c.settings))


def _same_particle_count(case: LoadCase, dem: DemCase, tolerances: Tolerances) -> bool:
    """Whether ``case`` is ``dem``'s simulation though its fill lies outside the fill
    tolerance: same frequency, acceleration, material and direction, and a fill that rounds
    to the case's particles per cell (:func:`pidcore.specimen.particles_for_fill`, the rule
    the DEM runs by). A specimen stating ``count_per_cell = 28`` of 46 runs at 60.87 %: a test
    at 60 % (28 spheres too) was "out_of_range" beside that very run."""
    from ..specimen import particles_for_fill

    if not (math.isfinite(dem.particles_per_cell) and math.isfinite(dem.particles_full_cell)
            and dem.particles_full_cell >= 1):
        return False
    at_fill = replace(dem.load_case, fill_percent=case.fill_percent)
    if not tolerances.matches(case, at_fill):
        return False
    try:
        count = particles_for_fill(case.fill_percent, int(dem.particles_full_cell))
    except ParameterError:  # a fill of no particle is no run's
        return False
    return count == dem.particles_per_cell


def same_count_note(case: LoadCase, dem: DemCase, tolerances: Tolerances | None = None) -> str:
    """The note for a measured ``case`` met by the DEM case ``dem`` through its particle count
    (:func:`_same_particle_count`), its fill outside the fill tolerance; "" otherwise: the
    row shows the DEM case's fill, and the measured one would go unsaid."""
    tolerances = tolerances or Tolerances()
    if abs(case.fill_percent - dem.load_case.fill_percent) <= tolerances.fill_atol_percent \
            or not _same_particle_count(case, dem, tolerances):
        return ""
    return (f"measured at {case.fill_percent:g} % fill: {dem.particles_per_cell:g} of "
            f"{dem.particles_full_cell:g} particles per cell, as the DEM runs at "
            f"{dem.load_case.fill_percent:g} %: the same simulation")


def _run_stderr_dofs(runs: pd.DataFrame, cells: float) -> np.ndarray:
    """Degrees of freedom of each run's ``sdc_stderr``: the stored ``sdc_stderr_dof`` where
    the run has one (a run whose cells ran one motion takes its error from batches of its
    steady window, batches - 1), else the scatter of its cells', cells - 1 (runs stored
    before the degrees of freedom were kept); NaN where neither is known."""
    assumed = cells - 1.0 if cells > 1 else math.nan
    if "sdc_stderr_dof" not in runs.columns:
        return np.full(len(runs), assumed)
    stored = np.array([stored_stderr_dof(v) for v in runs["sdc_stderr_dof"]], dtype=float)
    return np.where(np.isfinite(stored), stored, assumed)


def _same_count(count: float, group: np.ndarray) -> bool:
    """Whether a run of ``count`` particles per cell may join a group of runs of ``group``
    counts: the same count as every member that states one (an unknown count joins any)."""
    if not math.isfinite(count):
        return True
    known = group[np.isfinite(group)]
    return bool(np.all(known == count))


def _most_common(fills: np.ndarray) -> list[float]:
    """The fills stated by the most runs, in order of first appearance."""
    from collections import Counter

    counts = Counter(float(f) for f in fills)  # keeps the order of first appearance
    most = max(counts.values())
    return [v for v, n in counts.items() if n == most]


def _reference_fill(fills: np.ndarray, wanted: list[float], tolerances: Tolerances) -> float:
    """The fill a case's runs are wanted at: the wanted fill within the fill tolerance of its
    runs' (nearest their median), else the fill most of its runs state (the first of a tie)."""
    median = float(np.median(fills))
    near = [f for f in wanted if np.any(np.abs(fills - f) <= tolerances.fill_atol_percent)]
    if near:
        return min(near, key=lambda f: abs(f - median))
    return _most_common(fills)[0]


def _label_fill(fills: np.ndarray, reference: float) -> float:
    """The fill a case is labelled by: the one most of its counted runs state, of a tie the
    one nearest ``reference`` (then the first)."""
    common = _most_common(fills)
    return min(common, key=lambda f: abs(f - reference))


def _distinct(runs: pd.DataFrame, members: list[int], params: list[dict | None],
              reference: float = math.nan) -> tuple[list[int], list[int]]:
    """(members counted, members left out) of one case: of runs that are the same simulation
    (:func:`simulation_identity`) the one whose stored fill is nearest ``reference`` is
    counted (of a tie, or without a reference, the first stored); a run without recorded
    inputs is always counted (nothing shows it repeats another). Both lists keep the order of
    ``members``. ``params``: every run's stored inputs (:func:`stored_parameters`)."""
    if "parameters_json" not in runs.columns or "particles_per_cell" not in runs.columns:
        return members, []
    chosen: dict[str, int] = {}  # identity -> the member counted
    identities: list[str | None] = []
    for pos in members:
        row = runs.iloc[pos]
        identity = simulation_identity(params[pos], row["particles_per_cell"])
        identities.append(identity)
        if identity is None:
            continue
        if identity not in chosen:
            chosen[identity] = pos
        elif math.isfinite(reference):
            # the stored fill nearest the one asked or measured: its label is the row's
            distance = abs(float(row["fill_percent"]) - reference)
            best = abs(float(runs.iloc[chosen[identity]]["fill_percent"]) - reference)
            if distance < best:
                chosen[identity] = pos
    kept, left_out = [], []
    for pos, identity in zip(members, identities, strict=True):
        (kept if identity is None or chosen[identity] == pos else left_out).append(pos)
    return kept, left_out


def steady_stated(detected) -> bool | None:
    """A DEM run's ``steady_detected`` as stored (bool, or 0/1 as the store reads it back):
    True/False, or None where the run does not say (None/NaN: older stores)."""
    if detected is None or (isinstance(detected, float) and math.isnan(detected)):
        return None
    return bool(detected)


def _not_converged(runs: pd.DataFrame) -> tuple[tuple[int, int], ...]:
    """(steady_start_cycle, steady_cycles) of the runs that state steady_detected false."""
    if "steady_detected" not in runs:
        return ()
    out = []
    for _, run in runs.iterrows():
        if steady_stated(run["steady_detected"]) is not False:  # only a stated False
            continue
        start, cycles = (run.get(name) for name in ("steady_start_cycle", "steady_cycles"))
        out.append((int(start) if _finite(start) else -1, int(cycles) if _finite(cycles) else -1))
    return tuple(out)


def _finite(value) -> bool:
    return isinstance(value, int | float | np.integer | np.floating) and math.isfinite(value)


def _sort_key(case: LoadCase) -> tuple:
    return (case.frequency_hz, case.acceleration_g, case.fill_percent, case.material,
            case.direction)


def match_paper(case: LoadCase, paper: pd.DataFrame | None, *,
                tolerances: Tolerances | None = None) -> tuple[float, float, LoadCase | None]:
    """The paper's (DEM, experimental) SDC at ``case`` if it is a Table 3 grid point.

    Table 3 holds acrylic particles driven along z only; other materials or directions get NaN.
    """
    tolerances = tolerances or Tolerances()
    if paper is None or paper.empty or case.material != PAPER_MATERIAL \
            or case.direction != PAPER_DIRECTION:
        return math.nan, math.nan, None
    best: tuple[float, pd.Series, LoadCase] | None = None
    for _, row in paper.iterrows():
        grid = LoadCase(float(row["frequency_hz"]), float(row["acceleration_g"]),
                        float(row["fill_percent"]), PAPER_MATERIAL, PAPER_DIRECTION)
        if tolerances.matches(case, grid):
            d = tolerances.distance(case, grid)
            if best is None or d < best[0]:
                best = (d, row, grid)
    if best is None:
        return math.nan, math.nan, None
    row = best[1]
    return float(row["sdc_dem"]), float(row["sdc_experimental"]), best[2]


def _preference(case: DemCase) -> tuple[float, int]:
    """Sort key of the DEM cases of several settings at one load case, best first: the most
    cells simulated, then the most runs (the least noisy estimate)."""
    return (-float(np.nan_to_num(case.cells_simulated, nan=0.0)), -case.n_runs)


def _one_case_per_point(cases: list[DemCase]) -> tuple[list[DemCase], int]:
    """The preferred case (:func:`_preference`) at each load case, and how many load cases
    had cases of other settings: a model averaging them mixed, e.g., a calibration's 4-cell
    runs into the 8-cell grid, which :meth:`Aligner.grid_case` never does."""
    best: dict[tuple[float, float, float], DemCase] = {}
    crowded = set()
    for c in cases:
        point = (c.load_case.fill_percent, c.load_case.acceleration_g, c.load_case.frequency_hz)
        if point in best:
            crowded.add(point)
            if _preference(c) < _preference(best[point]):
                best[point] = c
        else:
            best[point] = c
    return list(best.values()), len(crowded)


def interpolated_count_and_mass(runs: pd.DataFrame | None,
                                case: LoadCase) -> tuple[int | None, float, str]:
    """(particles per cell, m_c of Eq. 10 in kg, "") of a load case off the DEM grid, as a DEM
    run of ``case`` would count them: from the specimen file and the fill reference and
    vibrated-mass convention that the ``runs`` the pchip model interpolates (those of its
    material and direction) all share, through the functions the DEM itself uses
    (:func:`pidcore.dem.simulate.particles_per_cell`, :meth:`pidcore.specimen.Specimen.
    vibrated_mass_kg`). ``(None, NaN, reason)`` where the runs do not say one specimen or one
    convention (runs of an older store, pooled runs of several specimens): a guessed m_c
    would give an Eq. 10 SDC that no run defines."""
    from ..dem.simulate import particles_per_cell
    from ..errors import PidcoreError
    from ..model.damper import runs_specimen

    if runs is None or runs.empty or not {"material", "direction"} <= set(runs.columns):
        return None, math.nan, "no DEM runs to take the specimen from"
    same = runs[(runs["material"] == case.material) & (runs["direction"] == case.direction)]
    try:
        specimen = runs_specimen(same)
    except PidcoreError:  # a stored text that no longer reads
        specimen = None
    if specimen is None:
        return (None, math.nan, "its DEM runs do not record one specimen file (an older store, "
                "or runs of several specimens)")
    settings = {}
    for column in ("fill_reference", "vibrated_mass_convention"):
        values = set(same[column].dropna()) if column in same.columns else set()
        if len(values) != 1 or same[column].isna().any():
            return (None, math.nan, f"its DEM runs do not share one {column.replace('_', ' ')}")
        settings[column] = values.pop()
    try:
        count, _ = particles_per_cell(case.fill_percent, specimen=specimen,
                                      fill_reference=settings["fill_reference"])
        mass = specimen.vibrated_mass_kg(count, settings["vibrated_mass_convention"])
    except PidcoreError as exc:  # e.g. a fill that rounds to no particle of that cell
        return None, math.nan, str(exc)
    return count, mass, ""


def build_dem_models(cases: list[DemCase]) -> dict[tuple[str, str], object]:
    """pchip models over our DEM cases, one per (material, direction); failures map to a message.

    Returns
    -------
    dict
        ``{(material, direction): SdcModel or str}``; the string says why no model could be built
        (for example fewer than two distinct values on an axis).
    """
    from ..model.sdc_model import complete_grid_model

    models: dict[tuple[str, str], object] = {}
    by_kind: dict[tuple[str, str], list[DemCase]] = {}
    for c in cases:
        by_kind.setdefault((c.load_case.material, c.load_case.direction), []).append(c)
    for kind, members in by_kind.items():
        members, other_settings = _one_case_per_point(members)
        table = pd.DataFrame({
            "fill_percent": [c.load_case.fill_percent for c in members],
            "acceleration_g": [c.load_case.acceleration_g for c in members],
            "frequency_hz": [c.load_case.frequency_hz for c in members],
            "sdc": [c.sdc for c in members],
        })
        source = f"our DEM runs ({kind[0]}, {kind[1]})"
        if other_settings:
            source += (f"; at {other_settings} load case(s) the runs of other settings left "
                       "out (those with the most cells kept, as for a grid case)")
        try:
            # one extra run (the app's DEM tab runs any frequency) leaves its frequency
            # without a value at the grid's other accelerations, which refused the model for
            # every off-grid measurement: the complete grid is modelled, its source saying
            # what is left out
            models[kind] = complete_grid_model(table, value="sdc", source=source)[0]
        except ParameterError as exc:
            # the refusal names its source first: "no pchip model over our DEM runs (steel,
            # z): our DEM runs (steel, z): ..." said it twice
            why = str(exc)
            models[kind] = f"no pchip model over {why}" if why.startswith(f"{source}: ") \
                else f"no pchip model over {source}: {why}"
    return models


def filled_corners(model: object, point: tuple[float, float, float] | tuple[np.ndarray, ...]
                   ) -> tuple[str, ...]:
    """Labels (``"500 Hz, 5 g, 90 %"``) of the model's grid points whose value no data gave
    (:attr:`pidcore.model.SdcModel.filled`) that the SDC at ``point`` (fill %, acceleration
    g, frequency Hz; arrays for several points) rests on, as
    :meth:`pidcore.model.SdcModel.filled_dependence` decides it: not only its grid cell's
    corners, a pchip slope takes the next grid point too. Empty for a model that flags none."""
    filled = getattr(model, "filled", None)
    if filled is None or not np.any(filled) or not hasattr(model, "filled_dependence"):
        return ()
    dependence = model.filled_dependence(*point, clip_to_range=True)
    rests = dependence.depends.reshape(-1, len(dependence.points)).any(axis=0)
    return tuple(f"{row.frequency_hz:g} Hz, {row.acceleration_g:g} g, {row.fill_percent:g} %"
                 for row, on in zip(dependence.points.itertuples(index=False), rests,
                                    strict=True) if on)


#: Words and units of the pchip model's axes as a report's note names them.
_AXIS_WORDS: dict[str, tuple[str, str]] = {"fill_percent": ("fill", "%"),
                                           "acceleration_g": ("acceleration", "g"),
                                           "frequency_hz": ("frequency", "Hz")}


def _edge_value(value: float, lo: float, hi: float, rtol: float) -> float | None:
    """``value`` taken into ``[lo, hi]``: itself inside, the nearest edge where it lies outside
    by no more than ``rtol`` of that edge (a measurement's noise, as a grid point's
    tolerance), None where it lies further out."""
    edge = min(max(value, lo), hi)
    return edge if abs(edge - value) <= rtol * edge else None


def model_point(model: object, tolerances: Tolerances, acceleration_g: float,
                frequency_hz: float, *, done: str = "drawn"
                ) -> tuple[float, float, str] | None:
    """(acceleration, frequency, note) to evaluate ``model`` at: the case itself, the model's
    grid point the case lies within the grid-match tolerance of (500.0005 Hz, 4.99967 g is the
    500 Hz, 5 g case, as the report aligns it), or the nearest edge of the model's range where
    the case lies outside it by no more than that tolerance (49.999998 Hz is the 50 Hz case).
    None where it lies further out. The note (``""`` for the case itself) says where the
    model was taken, ``done`` naming how: "model drawn at 50 Hz, 1 g: ...".

    The one rule of the Compare page's paper curve and of :meth:`Aligner.align` (the report's
    and the Compare page's DEM value): a measured 49.9995 Hz was the 50 Hz case on the one
    and out of range on the other."""
    a_lo, a_hi = model.bounds["acceleration_g"]
    f_lo, f_hi = model.bounds["frequency_hz"]
    a = _edge_value(acceleration_g, a_lo, a_hi, tolerances.acceleration_rtol)
    f = _edge_value(frequency_hz, f_lo, f_hi, tolerances.frequency_rtol)
    if a is None or f is None:
        return None
    edge = (a, f) != (acceleration_g, frequency_hz)
    # drawn between grid points, the curve of a case at 500.0005 Hz leant on the 1000 Hz
    # points (by a part in a million), and its note named a 1000 Hz, 1 g gap on a 500 Hz, 5 g
    # sheet
    a = _grid_value(model.axes[1], a, tolerances.acceleration_rtol)
    f = _grid_value(model.axes[2], f, tolerances.frequency_rtol)
    note = ""
    if (a, f) != (acceleration_g, frequency_hz):
        where = ("lies at the edge of its range" if edge else
                 "lies at that grid point of the model")
        note = (f"model {done} at {f:.6g} Hz, {a:.4g} g: the case ({frequency_hz:.8g} Hz, "
                f"{acceleration_g:.8g} g) {where}, within the grid tolerance")
    return a, f, note


def _grid_value(axis: np.ndarray, value: float, rtol: float) -> float:
    """The grid value of ``axis`` nearest ``value`` where within ``rtol`` of it, else
    ``value``."""
    nearest = float(axis[np.argmin(np.abs(np.asarray(axis, dtype=float) - value))])
    return nearest if abs(nearest - value) <= rtol * abs(nearest) else value


def _outside_text(value: float, lo: float, hi: float) -> str:
    """``value`` to as many significant digits as show it outside ``[lo, hi]`` (6 at least):
    "1 g outside 1-10 g" was printed for 0.9999999999999644 g."""
    for digits in range(6, 18):
        text = f"{value:.{digits}g}"
        if not lo <= float(text) <= hi:
            return text
    return repr(value)


def model_range_text(model: object, point: tuple[float, float, float],
                     tolerances: Tolerances | None = None) -> str:
    """The model's range per axis in words with units, the axes ``point`` (fill %,
    acceleration g, frequency Hz) lies outside first, e.g. ``"fill 95 % outside 25-90 %;
    acceleration 1-10 g, frequency 50-1000 Hz"``. With ``tolerances``, an acceleration or
    frequency within them of the range's edge lies inside (:func:`model_point` takes it at
    the edge).

    The keywords (``fill_percent in [25, 90]``) named no unit, and the command line's wording
    turned two of them into its flags (``--fill in [25, 90], acceleration_g in [1, 10],
    --frequency in [50, 1000]``) in report.csv's note."""
    bounds = getattr(model, "bounds", {}) or {}
    rtol = {"acceleration_g": tolerances.acceleration_rtol,
            "frequency_hz": tolerances.frequency_rtol} if tolerances is not None else {}
    outside, inside = [], []
    for (name, (lo, hi)), value in zip(bounds.items(), point, strict=False):
        word, unit = _AXIS_WORDS.get(name, (name, ""))
        span = f"{lo:g}-{hi:g} {unit}".rstrip()
        taken = _edge_value(value, lo, hi, rtol[name]) if name in rtol else None
        value = value if taken is None else taken
        if value < lo or value > hi:
            outside.append(f"{word} {_outside_text(value, lo, hi)} {unit} outside {span}"
                           .replace("  ", " "))
        else:
            inside.append(f"{word} {span}")
    return "; ".join(part for part in (", ".join(outside), ", ".join(inside)) if part)


@dataclass(frozen=True)
class Aligner:
    """Aligns measured cases with our DEM cases and the paper (see the module docstring).

    Build with :meth:`from_tables`; call :meth:`align` per case.

    Attributes
    ----------
    cases : list of DemCase
        Our DEM cases.
    paper : DataFrame or None
        Table 3 (:func:`pidcore.model.load_paper_table3`).
    model : SdcModel or None
        Model used for every off-grid case; None builds one per material/direction from ``cases``.
    tolerances : Tolerances
    """

    cases: list[DemCase]
    paper: pd.DataFrame | None = None
    model: object | None = None
    tolerances: Tolerances = field(default_factory=Tolerances)
    _models: dict = field(default_factory=dict, init=False, repr=False)

    def __post_init__(self) -> None:
        if self.model is None:
            self._models.update(build_dem_models(self.cases))

    @property
    def models(self) -> dict[tuple[str, str], object]:
        """Models built over our DEM cases: ``{(material, direction): SdcModel or reason}``."""
        return dict(self._models)

    @classmethod
    def from_tables(cls, dem_runs: pd.DataFrame | None, paper: pd.DataFrame | None = None, *,
                    model: object | None = None,
                    tolerances: Tolerances | None = None,
                    pool_settings: bool = False,
                    reference_fills: Iterable[float] = ()) -> Aligner:
        """Aligner over a table of DEM runs (see :func:`dem_cases`; ``reference_fills``: the
        measured fills, which choose among runs that are the same simulation)."""
        tolerances = tolerances or Tolerances()
        cases = dem_cases(dem_runs if dem_runs is not None else pd.DataFrame(),
                          tolerances=tolerances, pool_settings=pool_settings,
                          reference_fills=reference_fills)
        return cls(cases, paper, model, tolerances)

    def model_run_keys(self, material: str, direction: str) -> frozenset[str]:
        """Store keys of the runs the model of ``material`` and ``direction`` was built on:
        at each load case those of the preferred settings (:func:`_one_case_per_point`), at
        the points its grid holds data for (:func:`complete_grid` may leave some out); empty
        where it has no model. A figure of the model marked every run as its data, the
        2-cell run its caption said was left out among them."""
        model = self._models.get((material, direction))
        if model is None or isinstance(model, str):
            return frozenset()
        members, _ = _one_case_per_point([c for c in self.cases
                                          if (c.load_case.material, c.load_case.direction)
                                          == (material, direction)])
        data = model.data_points()
        keys: set[str] = set()
        for c in members:
            on = (np.isclose(data["fill_percent"], c.load_case.fill_percent)
                  & np.isclose(data["acceleration_g"], c.load_case.acceleration_g)
                  & np.isclose(data["frequency_hz"], c.load_case.frequency_hz))
            if on.any():
                keys.update(c.run_keys)
        return frozenset(keys)

    def grid_case(self, case: LoadCase) -> DemCase | None:
        """Our DEM case nearest to ``case`` within the tolerances, or None.

        Of several numerical settings at one load case the one with the most cells simulated
        is preferred (then the most runs): the least noisy estimate. A case whose particles
        per cell are those ``case``'s fill rounds to comes first: within the fill tolerance
        a nearer fill of another count (59.7 % of 46 is 27 spheres, 60 % is 28) is another
        bed.
        """
        counted = {id(c) for c in self.cases if _same_particle_count(case, c, self.tolerances)}
        hits = [c for c in self.cases
                if id(c) in counted or self.tolerances.matches(case, c.load_case)]
        if not hits:
            return None
        return min(hits, key=lambda c: (id(c) not in counted,
                                        self.tolerances.distance(case, c.load_case),
                                        *_preference(c)))

    def align(self, case: LoadCase) -> AlignedCase:
        """Align one measured case; never extrapolates the model."""
        paper_dem, paper_exp, paper_case = match_paper(case, self.paper,
                                                       tolerances=self.tolerances)
        common = {"sdc_paper_dem": paper_dem, "sdc_paper_experimental": paper_exp,
                  "paper_case": paper_case}
        grid = self.grid_case(case)
        if grid is not None:
            return AlignedCase(case, "grid", grid.sdc, grid.sdc_stderr, grid, **common,
                               message=f"DEM grid case {grid.load_case.key} "
                                       f"({grid.n_runs} run(s)"
                                       + (f", {grid.settings})" if grid.settings else ")")
                                       + (f"; {duplicates_note(grid)}"
                                          if grid.duplicate_keys else ""))
        model = self.model if self.model is not None \
            else self._models.get((case.material, case.direction))
        if model is None:  # nothing at this material and direction: not a range question
            return AlignedCase(case, "no_dem_runs", **common,
                               message=f"no DEM runs of ours for {case.material}, direction "
                                       f"{case.direction}")
        if isinstance(model, str):  # runs there, but too few to build a model over
            return AlignedCase(case, "no_model", **common, message=model)
        point = (case.fill_percent, case.acceleration_g, case.frequency_hz)
        source = getattr(model, "source", "") or "pchip model"
        taken_note = ""
        if not model.contains(point):
            # a measured 49.9995 Hz or 0.99999 g is the grid's 50 Hz or 1 g edge within the
            # tolerances, as the grid match and the Compare page take it; an interior point
            # is evaluated where it was measured
            taken = model_point(model, self.tolerances, case.acceleration_g,
                                case.frequency_hz, done="evaluated")
            if taken is not None:
                point = (case.fill_percent, taken[0], taken[1])
                taken_note = taken[2]
            if taken is None or not model.contains(point):
                return AlignedCase(
                    case, "out_of_range", **common,
                    message=f"{case.label()} lies outside the range of {source} "
                            f"({model_range_text(model, point, self.tolerances)}); not "
                            "extrapolated")
        value = float(np.asarray(model(*point)))
        at = replace(case, acceleration_g=point[1], frequency_hz=point[2])
        unconverged = self._unconverged_nodes(at) if self.model is None else ()
        # the row's empty "SDC DEM stderr" cell was left unexplained
        message = (f"pchip interpolation over {source} (no DEM stderr: the model interpolates "
                   "the runs' SDCs, not their errors)")
        if taken_note:
            message += f"; {taken_note}"
        if unconverged:
            # a grid row on such a run says so; the value interpolated from it said nothing
            message += ("; it rests on DEM runs that did not converge (no steady state before "
                        f"the transient cap) at {'; '.join(unconverged)}: the interpolated "
                        "SDC may include the transient")
        filled = filled_corners(model, point)
        if filled:
            # an interrupted sweep left 500 Hz, 5 g, 90 % unrun: the model held the 75 % SDC
            # there, and a measurement at 85 % got that held value as "interpolated"
            message += (f"; no DEM run at {'; '.join(filled)}, a grid point its pchip value "
                        "rests on: the "
                        "model fills it along fill from the runs at that frequency and "
                        "acceleration (pchip between runs, the nearest run's SDC held beyond "
                        "the last), so the SDC here rests partly on no run")
        return AlignedCase(case, "interpolated", value, math.nan, None, **common,
                           message=message, unconverged_nodes=unconverged)

    def _unconverged_nodes(self, case: LoadCase) -> tuple[str, ...]:
        """Labels of the DEM cases (one per grid point, as the model takes them) at the
        corners of the grid cell holding ``case`` whose runs did not converge."""
        members, _ = _one_case_per_point(
            [c for c in self.cases
             if (c.load_case.material, c.load_case.direction) == (case.material,
                                                                   case.direction)])
        corners = []
        for attr in ("fill_percent", "acceleration_g", "frequency_hz"):
            values = sorted({getattr(c.load_case, attr) for c in members})
            x = getattr(case, attr)
            below = [v for v in values if v <= x]
            above = [v for v in values if v >= x]
            corners.append({below[-1] if below else values[0],
                            above[0] if above else values[-1]})
        return tuple(c.load_case.label() for c in members
                     if c.not_converged and all(
                         getattr(c.load_case, attr) in allowed for attr, allowed in zip(
                             ("fill_percent", "acceleration_g", "frequency_hz"), corners,
                             strict=True)))


def align_measured(measured: pd.DataFrame, dem_runs: pd.DataFrame | None,
                   paper: pd.DataFrame | None = None, *, model: object | None = None,
                   tolerances: Tolerances | None = None) -> pd.DataFrame:
    """Align each measured case; one row per measured case with unit-suffixed columns.

    Parameters
    ----------
    measured : pandas.DataFrame
        Columns :data:`MEASURED_COLUMNS`.
    dem_runs : pandas.DataFrame or None
        Our DEM runs (:data:`DEM_COLUMNS`).
    paper : pandas.DataFrame, optional
        Table 3 (:func:`pidcore.model.load_paper_table3`).
    model : SdcModel, optional
        Model for off-grid cases (default: pchip over our DEM cases).

    Returns
    -------
    pandas.DataFrame
        :meth:`AlignedCase.to_dict` columns plus :data:`MEASURED_EQ11_COLUMN`
        (``SDC measured (Eq. 11) [-]``), :data:`MEASURED_EQ11_STDERR_COLUMN` and
        ``source file(s)``: the report's names of the measured SDC (``SDC measured [-]`` and
        ``SDC measured stderr [-]`` before 2026-12: :data:`MEASURED_COLUMNS_RENAMED` reads a
        frame saved with them).
    """
    _check_columns(measured, MEASURED_COLUMNS, "measured cases")
    aligner = Aligner.from_tables(dem_runs, paper, model=model, tolerances=tolerances)
    rows = []
    for _, row in measured.iterrows():
        aligned = aligner.align(_row_case(row))
        rows.append({**aligned.to_dict(), MEASURED_EQ11_COLUMN: float(row["sdc"]),
                     MEASURED_EQ11_STDERR_COLUMN: float(row["sdc_stderr"]),
                     "source file(s)": str(row["source"])})
    return pd.DataFrame(rows)
