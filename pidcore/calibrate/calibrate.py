"""Calibration pipeline: measured points -> DEM design runs (cached) -> surrogates ->
posterior -> predictions, optionally leave-one-out cross-validation.

In a leave-one-out fold the held-out load case's DEM runs are shared (they do not depend on
the measurement), but its measured value never enters the fold's likelihood.
"""

from __future__ import annotations

import dataclasses
import math
import os
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import defaults
from ..compare.align import steady_stated
from ..compare.plausibility import SdcBound
from ..constants import BAND_VERDICTS, STANDARD_GRAVITY
from ..dem.simulate import DemConfig, LoadCase
from ..errors import ParameterError, real_number, whole_number
from ..interrupt import raise_if_stopped
from ..specimen import (
    Specimen,
    calibrated_name,
    calibrated_provenance,
    is_paper_coupon,
    measured_specimen_name,
    paper_specimen,
    uncalibrated_name,
)
from .data import MeasuredPoint, check_enough_points, measured_provenance
from .likelihood import NORMAL_ABOVE_DOF, uses_student_t
from .observation import Observation, observation_from_run
from .parameters import (
    CATALOGUE,
    DISCREPANCY,
    ParameterSpec,
    build_specs,
    parameter_spec,
    parse_fit,
)
from .posterior import (
    DISCREPANCY_FLOOR,
    Model,
    SamplerDiagnostics,
    bound_notes,
    predictive,
    sample_posterior,
    summarise,
    summary_texts,
    unconstrained_notes,
)
from .runner import RunRequest, run_requests, specimen_with, variant_provenance
from .surrogate import build_surrogate, default_design_size, design_points

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

    from .prediction import Calibration

#: Cells per DEM run of a calibration: the ensemble scatter enters the likelihood, and 4
#: cells keep a 12-case design within minutes on two cores.
CALIBRATION_CELLS = 4
CROSS_VALIDATIONS = ("loo",)
INSIDE, _, _, UNINFORMATIVE = BAND_VERDICTS


@dataclass
class CalibrationResult:
    """Outcome of :func:`calibrate`: posterior summary, predictions, LOO, run bookkeeping."""

    specimen: Specimen
    specs: list[ParameterSpec]
    samples: np.ndarray
    parameters: dict
    correlations: list
    predictions: list[dict]
    loo: list[dict] | None
    fixed: dict
    design: np.ndarray
    observations: list[list[Observation]]
    runs: dict
    settings: dict
    notes: list[str] = field(default_factory=list)
    energy_check: list[dict] = field(default_factory=list)
    wall_s: float = 0.0
    #: the model's SDC of each load case (order of :attr:`predictions`) at the values the
    #: calibrated file holds, each parameter's median (:func:`file_predictions`); empty for a
    #: result made without it
    file_predicted: list[float] = field(default_factory=list)

    @property
    def loo_rms(self) -> float | None:
        if not self.loo:
            return None
        return float(np.sqrt(np.mean([(r["predicted"] - r["measured"]) ** 2 for r in self.loo])))

    @property
    def loo_coverage(self) -> int | None:
        """How many leave-one-out folds' 95 % bands hold their held-out measurement, among
        the folds whose band can judge it (``len(loo) - loo_uninformative`` of them; None
        without leave-one-out): calibration.json's ``loo_coverage95``. A fold whose band
        spans every plausible SDC (:func:`~pidcore.calibrate.prediction.row_verdict`
        ``uninformative``) holds any measurement; it was counted inside."""
        if not self.loo:
            return None
        return self.band_verdicts(self.loo).count(INSIDE)

    @property
    def loo_uninformative(self) -> int | None:
        """How many leave-one-out folds' 95 % bands are uninformative (0 .. 2 pi):
        counted neither inside nor among the folds judged (calibration.json's
        ``loo_uninformative95``; a file without it had none counted apart)."""
        if not self.loo:
            return None
        return self.band_verdicts(self.loo).count(UNINFORMATIVE)

    def sdc_bounds(self, rows: Sequence[dict]) -> list[SdcBound]:
        """The SDC bound of each prediction row (:func:`pidcore.calibrate.prediction.
        calibrated_sdc_bound` of the calibrated specimen at the row's fill), where its band is
        cut, as the report cuts it."""
        from .prediction import calibrated_sdc_bound

        specimen = self.calibrated_specimen()
        return [calibrated_sdc_bound(specimen, fill_percent=r["fill_percent"],
                                     material=r.get("material") or specimen.particles.material)
                for r in rows]

    def band_verdicts(self, rows: Sequence[dict]) -> list[str]:
        """``yes``, ``no`` or ``uninformative`` (:data:`pidcore.constants.BAND_VERDICTS`) for
        each of ``rows`` (:attr:`predictions` or :attr:`loo`):
        :func:`~pidcore.calibrate.prediction.row_verdict` at its SDC bound."""
        from .prediction import row_verdict

        return [row_verdict(r, bound) for r, bound in zip(rows, self.sdc_bounds(rows),
                                                          strict=True)]

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean([(r["predicted"] - r["measured"]) ** 2
                                      for r in self.predictions])))

    def values(self) -> dict[str, float]:
        """Calibrated value (posterior median) of every fitted parameter."""
        return {name: p["median"] for name, p in self.parameters.items()}

    def calibrated_specimen(self) -> Specimen:
        """The starting specimen with every fitted specimen parameter at its median."""
        dem = {s.name: self.parameters[s.name]["median"] for s in self.specs if s.kind == "dem"}
        out = specimen_with(self.specimen, dem)
        coupon = {f"coupon.{name}": self.parameters[name]["median"]
                  for name in ("fixture_mass_kg", "baseline_loss_factor")
                  if name in self.parameters}
        out = out.with_values(coupon) if coupon else out
        # the values themselves: a description written for the start ("15 g fixture") would
        # otherwise contradict the fitted numbers below it
        fitted = "; ".join(
            "{} {} (95 % {} .. {})".format(s.name, *summary_texts(self.parameters[s.name]))
            for s in self.specs if s.kind != "hyper")
        return dataclasses.replace(
            out, name=calibrated_name(self.specimen.name),
            # the name alone does not say which file was tested: a user's paper_coupon.toml
            # calibrates to paper_coupon_calibrated as the paper's coupon does
            provenance=calibrated_provenance(self.specimen),
            description=f"{self.specimen.description} -- calibrated by pidcore calibrate: "
                        f"{fitted} (these replace any value stated above)".strip(" -"))

    def calibration(self) -> Calibration:
        """This result as :func:`~pidcore.calibrate.load_calibration` reads it back from its
        ``calibration.json``: ``lookup(case).band(stderr)``, ``to_pandas()``, ``plot()``."""
        from .outputs import document_json
        from .prediction import calibration_from_json

        calibrated = self.calibrated_specimen()
        # with its calibrated file's text, as a store reads it back: without it the bands of
        # heavy particles were cut at 2 pi here and at their own bound in predictions.png
        return dataclasses.replace(
            calibration_from_json(document_json(self.document()), "<calibration in memory>",
                                  specimen_name=calibrated.name),
            specimen_text=calibrated.to_toml())

    def to_pandas(self) -> pd.DataFrame:
        """The in-sample predictions with their 95 % bands, one row per measured load case,
        columns naming their units (:meth:`Calibration.to_pandas` of :meth:`calibration`)."""
        return self.calibration().to_pandas()

    def plot(self, ax: Any = None) -> Any:
        """Predictions and bands beside the measured SDCs (:meth:`Calibration.plot` of
        :meth:`calibration`); returns ``ax``."""
        return self.calibration().plot(ax=ax)

    def document(self) -> dict:
        """The ``--json`` document: parameters, predictions and loo (each row with its
        verdict ``inside95``, words of :data:`pidcore.constants.BAND_VERDICTS`:
        :meth:`band_verdicts`, as summary.md's table), rms_in_sample, coverage95 and
        uninformative95 (the in-sample counts summary.md heads its table with), loo_rms,
        loo_coverage95 and loo_uninformative95 (:attr:`loo_coverage`,
        :attr:`loo_uninformative`), the units of
        each of their numbers (``units``: the parameters' and the predictions' fields), and
        ``specimen``: which specimen file was calibrated and which it wrote (``name``,
        ``sha256``, ``calibrated_name``, ``calibrated_sha256``)."""
        keep = ("median", "low95", "high95")
        # each row's verdict as summary.md's table and its count state it: a script reading
        # the file judged low95 <= measured <= high95 itself, "yes" where the summary said
        # "uninformative" (a band cut at the SDC bound), and found no in-sample count at all
        predictions = _judged(self.predictions, self.band_verdicts(self.predictions))
        loo = _judged(self.loo, self.band_verdicts(self.loo)) if self.loo is not None else None
        named = {*self.parameters, "loo_rms", "rms_in_sample", "coverage95", "uninformative95",
                 "loo_coverage95", "loo_uninformative95", *(k for r in predictions for k in r)}
        calibrated = self.calibrated_specimen()
        return {
            # a calibration.json (or --json) named no specimen: apart from the file beside
            # it, it spoke for the tests of any
            "specimen": {"name": self.specimen.name, "sha256": self.specimen.hash,
                         "calibrated_name": calibrated.name,
                         "calibrated_sha256": calibrated.hash},
            "parameters": {n: {k: p[k] for k in keep} for n, p in self.parameters.items()},
            "predictions": predictions,
            "loo": loo,
            # the command prints it beside the leave-one-out RMS; --json left it out
            "rms_in_sample": self.rms,
            "coverage95": self.band_verdicts(self.predictions).count(INSIDE),
            "uninformative95": self.band_verdicts(self.predictions).count(UNINFORMATIVE),
            "loo_rms": self.loo_rms,
            # the command's "k/n inside (m more uninformative)" as numbers: without them a
            # script reading --json had to recompute the SDC bound of every fold; absent in a
            # calibration.json of an older pidcore, which counted an uninformative band inside
            "loo_coverage95": self.loo_coverage,
            "loo_uninformative95": self.loo_uninformative,
            "units": {k: u for k, u in self.units().items() if k in named},
        }

    def full_document(self) -> dict:
        """``calibration.json``: the document plus correlations, settings, runs, notes."""
        out = self.document()
        out.update({
            "parameter_details": self.parameters,
            "correlations": {"names": [s.name for s in self.specs],
                             "matrix": self.correlations},
            "fixed": self.fixed, "rms_in_sample": self.rms,
            "n_points": len(self.predictions),
            "design": {"names": [s.name for s in self.specs if s.kind == "dem"],
                       "points": self.design.tolist()},
            "runs": self.runs, "settings": self.settings, "notes": self.notes,
            "energy_check": self.energy_check,
            # what re-running the DEM with calibrated_specimen.toml should give, beside each
            # prediction's "predicted" (the posterior median of the SDC, another number)
            "calibrated_file_predicted": self.file_predicted,
            "wall_s": self.wall_s,
            "units": self.units(),
        })
        return out

    def units(self) -> dict[str, str]:
        """Units of what calibration.json reports: the load case, the SDCs, the energies, and
        exactly the fitted parameters and the fixed ones (from their definitions,
        :attr:`ParameterSpec.unit`)."""
        out = {"frequency_hz": "Hz", "acceleration_g": "g", "fill_percent": "%",
               "measured": "-", "measured_stderr": "-", "predicted": "-", "low95": "-",
               "high95": "-", "low95_without_stderr": "-", "high95_without_stderr": "-",
               "rms_in_sample": "-", "loo_rms": "-", "energy_per_cycle_per_cell_start_j": "J",
               "energy_per_cycle_per_cell_calibrated_j": "J", "low95_j": "J", "high95_j": "J",
               "wall_s": "s",
               # words, not numbers: their vocabulary, as the report's column header names it
               ROW_VERDICT_KEY: "/".join(BAND_VERDICTS[:2] + BAND_VERDICTS[3:]),
               "coverage95": "count", "uninformative95": "count",
               "loo_coverage95": "count", "loo_uninformative95": "count"}
        if any("measured_stderr_dof" in r for r in self.predictions):
            out["measured_stderr_dof"] = "-"  # degrees of freedom: a count
        for name in self.fixed:
            out[name] = parameter_spec(name, self.specimen).unit
        out.update((s.name, s.unit) for s in self.specs)
        return out


#: Key of each prediction row's verdict in calibration.json and ``--json``
#: (:meth:`CalibrationResult.document`).
ROW_VERDICT_KEY = "inside95"


def _judged(rows: Sequence[dict], verdicts: Sequence[str]) -> list[dict]:
    """The public fields of ``rows``, each with its verdict under :data:`ROW_VERDICT_KEY`."""
    return [{**_public(r), ROW_VERDICT_KEY: v} for r, v in zip(rows, verdicts, strict=True)]


def _public(row: dict) -> dict:
    keys = ("frequency_hz", "acceleration_g", "fill_percent", "material", "measured",
            "measured_stderr", "predicted", "low95", "high95", "low95_without_stderr",
            "high95_without_stderr")
    out = {k: row[k] for k in keys}
    if "measured_stderr_dof" in row:
        out["measured_stderr_dof"] = row["measured_stderr_dof"]
    return out


def _requests(points: Sequence[MeasuredPoint], dem_specs: Sequence[ParameterSpec],
              design: np.ndarray, config: DemConfig, specimen: Specimen, *,
              stop: threading.Event | None = None) -> list[list[RunRequest]]:
    specimens = []
    for row in design:
        raise_if_stopped(stop, _STOPPED)  # each variant is a specimen made and hashed
        values = {s.name: float(v) for s, v in zip(dem_specs, row, strict=True)}
        try:
            variant = specimen_with(specimen, values)
            specimens.append((variant, variant_provenance(specimen, variant, values)))
        except ParameterError as exc:
            # the design point's fault, not the specimen file's (check_domains catches the
            # prior's corners; a constraint that is not monotone could still fail inside)
            at = ", ".join(f"{n}={v:g}" for n, v in values.items())
            raise ParameterError(
                f"fit/priors: the design point {at} is outside the physical domain "
                f"({str(exc).removeprefix(f'{specimen.source}: ')}); narrow the ranges of "
                "priors=") from None
    out = []
    for point in points:
        raise_if_stopped(stop, _STOPPED)
        case = LoadCase(point.frequency_hz, point.acceleration_g, point.fill_percent,
                        point.material)
        out.append([RunRequest(case, s, config, variant) for s, variant in specimens])
    return out


def base_specimen(points: Sequence[MeasuredPoint], specimen: Specimen | None) -> Specimen:
    """The specimen to calibrate: the given one, or the paper's coupon with the points'
    particle material.

    Every point must be of the specimen's particle material. A point of another material would
    be run with the specimen's particles under its own material's name and fitted silently
    (steel measurements against acrylic DEM runs), so it is refused with the way out: choose
    the points of one material, or give the specimen file of theirs.
    """
    if not points:
        raise ParameterError("no measured points to calibrate against")
    materials = sorted({p.material for p in points})
    if len(materials) > 1:
        raise ParameterError(f"measured points name several particle materials {materials}; "
                             "calibrate one specimen at a time (choose the points of one "
                             "material)")
    material = materials[0]
    if specimen is None:
        try:
            chosen = paper_specimen(material)
        except ParameterError:
            raise ParameterError(f"the measured points are of {material} particles, which are "
                                 "not in the materials table: give the specimen file of these "
                                 "particles (specimen=FILE)") from None
    else:
        chosen = specimen
        own = specimen.particles.material
        if material != own:
            raise ParameterError(f"the measured points are of {material} particles, the "
                                 f"specimen {specimen.name!r} holds {own} particles; calibrate "
                                 f"{own} measurements with it (or give the specimen file of "
                                 f"the {material} particles)")
    check_point_specimens(points, chosen)
    return chosen


def check_point_fills(points: Sequence[MeasuredPoint], specimen: Specimen,
                      config: DemConfig) -> None:
    """Refuse a point whose fill the DEM cannot run (it rounds to no particle, or to more than
    the cell holds) before any DEM run, naming its table line: the DEM's own refusal named
    neither the table nor the row ("fill 0.4 % of 46 particles rounds to none")."""
    from ..dem.simulate import particles_per_cell

    for p in points:
        try:
            particles_per_cell(p.fill_percent, specimen=specimen,
                               fill_reference=config.fill_reference, what="fill", typed=True)
        except ParameterError as exc:
            raise ParameterError(f"{_where(p)} ({p.label()}): fill_percent: {exc}") from None


def _where(point: MeasuredPoint) -> str:
    """Where a measured point was read: its table and line, else its store (or none)."""
    if point.row is not None:
        return f"{point.source}, line {point.row}"
    return point.source or "measured point"


def check_repeated_simulations(points: Sequence[MeasuredPoint], specimen: Specimen,
                               config: DemConfig) -> None:
    """Refuse two points that are one DEM simulation: the same frequency and acceleration
    and fills of the same particles per cell of ``specimen``
    (:func:`pidcore.specimen.same_particles_per_cell`, as ``dem sweep`` and the app run such
    fills once). They are one load case measured twice, not two: fitted apart, the case
    weighed twice, and leave-one-out kept its twin in the fit of the fold that held it out
    (bit-identical DEM runs, and an outlier scored inside its band). Points of other
    specimen labels count too: every point left is of ``specimen``
    (:func:`check_point_specimens`)."""
    from ..dem.simulate import particles_per_cell
    from ..specimen import same_particles_per_cell

    for i, first in enumerate(points):
        for second in points[i + 1:]:
            if (first.frequency_hz, first.acceleration_g, first.material) != \
                    (second.frequency_hz, second.acceleration_g, second.material) \
                    or not same_particles_per_cell(first.fill_percent, second.fill_percent,
                                                   specimen, config.fill_reference):
                continue
            count, full = particles_per_cell(first.fill_percent, specimen=specimen,
                                             fill_reference=config.fill_reference)
            if first.source == second.source and first.row is not None \
                    and second.row is not None:
                where = f"{first.source}, lines {first.row} and {second.row}"
            else:
                where = f"{_where(first)} and {_where(second)}"
            raise ParameterError(
                f"{where} ({first.label()}; {second.label()}) state the same load case: "
                f"fills {first.fill_percent:g} % and {second.fill_percent:g} % are both "
                f"{count} of {full} particles per cell of specimen {specimen.name}, one DEM "
                "simulation; give one row per load case (the mean SDC of repeated tests and "
                "its standard error)")


def check_point_specimens(points: Sequence[MeasuredPoint], specimen: Specimen) -> None:
    """Refuse points measured on another specimen than ``specimen``, the one calibrated.

    A point naming no specimen is of the one calibrated; one naming it, or the specimen it was
    calibrated from (``x_calibrated`` is ``x``), is too, as a calibration speaks for a
    measurement in the report and the app (:meth:`pidcore.calibrate.prediction.Calibration.
    speaks_for`). Any other was fitted silently against this specimen's DEM runs.
    """
    from ..specimen import hashed_name, same_tested_file
    from .prediction import tested_sha256

    # a point that recorded its specimen file's hash is of this specimen only where it is the
    # file calibrated (or the one it was calibrated from): two files of one name are two
    # specimens. One without (a table's row, an older record) by its name, as before
    own = uncalibrated_name(measured_specimen_name(specimen))
    own_file = tested_sha256(specimen) or ""

    def of_another(name: str, sha256: str = "") -> bool:
        if name and same_tested_file(sha256, own_file) is False:
            return True
        if specimen.is_paper():
            # the paper's coupon with either table material is one coupon: a test naming
            # paper_coupon was refused for the aluminium coupon (and paper_coupon_aluminium
            # left out of it by points_for_paper)
            return not is_paper_coupon(name)
        return bool(name) and uncalibrated_name(name) != own

    others: dict[tuple[str, str], list[int | None]] = {}
    for p in points:
        if p.specimen_ambiguous:
            # its name is this file's and another's (match_hashless_records): by name it
            # was a second point of its load case beside this file's own tests
            named = (f"{p.specimen} (saved without its specimen's sha256; several files of "
                     "that name)")
            others.setdefault((p.source, named), []).append(p.row)
        elif of_another(p.specimen, p.specimen_sha256):
            named = p.specimen if not p.specimen_sha256 or p.specimen.endswith("]") \
                else hashed_name(p.specimen, p.specimen_sha256)
            others.setdefault((p.source, named), []).append(p.row)
    if not others:
        return
    said = []
    for (source, name), rows in others.items():
        numbered = [str(r) for r in rows if r is not None]
        if numbered:  # a table's rows
            # lines of the file, as every table's rows are named (pidcore.tables.line_where)
            where = f"{source} line{'s' if len(numbered) > 1 else ''} {', '.join(numbered)}"
        else:  # a store's load cases (or points made in code)
            where = f"{len(rows)} measured load case(s)" + (f" of {source}" if source else "")
        said.append(f"{where} name specimen {name!r}")
    calibrated = measured_specimen_name(specimen)
    if own_file and any(name.startswith(f"{calibrated} [") for _, name in others) \
            and not calibrated.endswith("]"):
        calibrated = hashed_name(calibrated, own_file)  # one name, two files: say which
    raise ParameterError(f"{'; '.join(said)}, not {calibrated!r}, the "
                         "specimen calibrated; "
                         "calibrate them with their own specimen file (specimen=FILE), or "
                         "leave those rows out")


def error_model_notes(points: Sequence[MeasuredPoint]) -> list[str]:
    """Which error model the fit and the 95 % bands use for the points' measurement error (it
    sets how much an outlying point pulls the fit and how wide the measurement's part of a
    band is), with the Student quantile of the fewest degrees of freedom stated (it said
    t_0.975,7 = 2.365 beside points of 1)."""
    import scipy.stats

    with_dof = sorted({p.sdc_stderr_dof for p in points
                       if p.sdc_stderr > 0 and math.isfinite(p.sdc_stderr_dof)})
    if not with_dof:
        return []
    t_dof = [d for d in with_dof if uses_student_t(1.0, d)]
    return ["likelihood and 95 % bands: the measurement error of a point whose sdc_stderr "
            "states its degrees of freedom (" + ", ".join(f"{d:g}" for d in with_dof)
            + f") is sdc_stderr times Student's t with them (t_0.975,{with_dof[0]:g} = "
            f"{float(scipy.stats.t.ppf(0.975, with_dof[0])):.4g}, not 1.96; an outlying "
            "point pulls the fit less than under a normal error)"
            + ("" if len(t_dof) == len(with_dof) else
               f"; above {NORMAL_ABOVE_DOF:g} degrees of freedom the likelihood takes it as "
               "normal")
            + "; of a point without them, normal"]


def calibrate(points: Sequence[MeasuredPoint], *, fit: str | Sequence[str],
              store_path: str | os.PathLike, priors: str | Sequence[str] = (),
              discrepancy: float | None = None,
              discrepancy_floor: float = DISCREPANCY_FLOOR,
              cells: int = CALIBRATION_CELLS, seed: int = defaults.DEM_SEED,
              steady_cycles: int | None = None, design_size: int | None = None,
              workers: int = 2, cross_validate: str | None = None, method: str = "auto",
              progress: bool = True, posterior_seed: int = 0,
              dem_config: DemConfig | None = None,
              specimen: Specimen | None = None,
              on_design: Callable[[list[str]], None] | None = None,
              on_run_done: Callable[[str], None] | None = None,
              stop: threading.Event | None = None) -> CalibrationResult:
    """Fit ``fit`` parameters to measured SDCs (see the package docstring for the model).

    ``fit``: parameter names, a sequence or ``"a,b"`` as ``--fit`` takes them; ``priors``:
    ``--prior`` texts (``"NAME=LOW:HIGH"``), one string or a sequence.

    DEM runs go to (and are reused from) the store at ``store_path``. ``discrepancy``: fix the
    relative model discrepancy instead of fitting it. ``cross_validate="loo"``: also predict
    every point from a fit without it. ``dem_config``: numerical DEM settings to start from
    (cells, seed and steady cycles are then set from the arguments). ``specimen``: the
    specimen to start from (default: the paper's coupon). ``on_design``: called with the DEM
    run keys of the design before any run starts (:class:`pidcore.calibrate.runner.RunTally`
    counts from them what a Ctrl-C kept). ``on_run_done``: called with each DEM run's key as
    it is saved (the app's progress: runs done of the design's). ``stop``: set by a caller in
    another thread (the app's Cancel, or its exit) to end the calibration within a fraction of
    a second while its DEM runs go (their running ones are discarded, the saved ones kept),
    or before its next stage after them: :class:`~pidcore.interrupt.StopRequested` is raised
    and nothing is returned.
    """
    start = time.perf_counter()
    points = list(points)
    specimen = base_specimen(points, specimen)
    # as the CLI reads them: "a,b" is two names (a string was taken letter by letter:
    # "unknown parameter 'r'"), one prior string is one prior
    fit = parse_fit(fit, specimen)
    priors = [priors] if isinstance(priors, str) else list(priors)
    specs = build_specs(fit, priors, discrepancy=discrepancy, specimen=specimen)
    check_enough_points(points, [spec.name for spec in specs])
    if cross_validate is not None and cross_validate not in CROSS_VALIDATIONS:
        raise ParameterError(f"cross_validate: expected one of {CROSS_VALIDATIONS}, "
                             f"got {cross_validate!r}")
    if cross_validate == "loo":
        check_enough_points(points, [spec.name for spec in specs], leave_one_out=True)
    if not (math.isfinite(real_number("discrepancy_floor", discrepancy_floor))
            and discrepancy_floor >= 0):
        raise ParameterError(f"discrepancy_floor: expected a finite SDC >= 0, got "
                             f"{discrepancy_floor}")
    # before any DEM run, as the CLI's --seed and --workers are: seed=-1 was numpy's
    # "expected non-negative integer" naming nothing, posterior_seed=-1 that after every DEM
    # run, and workers=0 or -1 ran without a word
    for name, value, least in (("seed", seed, 0), ("posterior_seed", posterior_seed, 0),
                               ("workers", workers, 1)):
        if whole_number(name, value) < least:
            raise ParameterError(f"{name}: expected a whole number >= {least}, got {value}")
    notes = []
    if all(p.sdc_stderr == 0 for p in points):
        notes.append("no sdc_stderr in the data: measurement error is carried by the "
                     "model-discrepancy term alone")
    notes.extend(error_model_notes(points))
    dem_specs = [s for s in specs if s.kind == "dem"]
    if not dem_specs and design_size not in (None, 1):
        # nothing varies between DEM runs: one run per load case, whatever the design asks
        notes.append(f"design_size {design_size} ignored: no DEM parameter is fitted, so "
                     "each load case needs one DEM run")
        design_size = None
    n_design = default_design_size(len(dem_specs)) if design_size is None else design_size
    if dem_specs and n_design < 2:
        raise ParameterError(f"design_size: expected >= 2 with DEM parameters, got {n_design}")
    if n_design > defaults.CALIBRATION_MAX_DESIGN_SIZE:
        raise ParameterError(f"design_size: expected at most "
                             f"{defaults.CALIBRATION_MAX_DESIGN_SIZE} design points (each is one "
                             f"DEM run per load case), got {n_design}")
    design = design_points(dem_specs, n_design, seed=seed)
    config = dataclasses.replace(dem_config or DemConfig(), cells=cells, seed=seed,
                                 steady_cycles=steady_cycles)
    check_point_fills(points, specimen, config)
    check_repeated_simulations(points, specimen, config)
    # a stop is heard while the design's requests and keys are made too: that takes a
    # fraction of a ms per request, seconds for a large design, before any DEM run starts
    requests = _requests(points, dem_specs, design, config, specimen, stop=stop)
    if on_design is not None:
        keys = []
        for row in requests:
            raise_if_stopped(stop, _STOPPED)
            keys += [r.key() for r in row]
        on_design(keys)
    # on_done only where asked for: the call is otherwise the CLI's as before
    told = {} if on_run_done is None else {"on_done": on_run_done}
    if stop is not None:
        told["stop"] = stop
    runs = run_requests([r for row in requests for r in row], store_path=store_path,
                        workers=workers, progress=progress, **told)
    raise_if_stopped(stop, _STOPPED)
    from ..store import Store

    store = Store(store_path)
    observations = []
    # point label -> the share of the dissipation each of its runs that never reached steady
    # state released from its stored energy over the cycles measured (None: not recorded)
    unsteady: dict[str, list[float | None]] = {}
    for point, row in zip(points, requests, strict=True):
        obs = []
        for request in row:
            entry = store.get_dem_run(request.key())
            obs.append(observation_from_run(entry.record, entry.arrays,
                                            coupon_mass_kg=specimen.coupon.mass_kg))
            if steady_stated(entry.record.get("steady_detected")) is False:
                unsteady.setdefault(point.label(), []).append(_released_share(entry.record))
        observations.append(obs)
    if unsteady:
        notes.append(f"{sum(map(len, unsteady.values()))} of {sum(len(r) for r in requests)} "
                     "DEM run(s) never reached steady state (their SDC is that of the cycles "
                     "after the transient cap, less certain than the error bar says; the share "
                     "of the dissipation per cycle the bed's stored energy fell by over them is "
                     "how much too high the SDC is if that is a drift, mostly noise where "
                     "particles fly): " + "; ".join(
                         f"{label} ({len(shares)}: "
                         + ", ".join("?" if share is None else f"{share:+.1%}" for share in shares)
                         + ")" for label, shares in unsteady.items()))
    notes.extend(nonpositive_dissipation_notes([p.label() for p in points], observations))
    surrogates = tuple(build_surrogate(obs, design, dem_specs) for obs in observations)
    fitted = [s.name for s in specs]
    fixed = {name: parameter_spec(name, specimen).default for name in CATALOGUE
             if name not in fitted}
    if discrepancy is not None:
        fixed[DISCREPANCY] = float(discrepancy)
    model = Model(tuple(specs), surrogates, tuple(points), fixed, discrepancy_floor)
    everything = list(range(len(points)))
    posterior = sample_posterior(model, everything, seed=posterior_seed, method=method)
    samples = posterior.samples
    if posterior.fallback:
        notes.append(f"method={method}: {posterior.fallback}; the posterior was sampled "
                     "with emcee instead of the grid")
    if not posterior.converged:
        notes.append(_not_converged_note(posterior.diagnostics))
    fold_fallbacks = []
    fold_unconverged: list[str] = []
    parameters, correlations = summarise(specs, samples,
                                         effective_size=posterior.effective_size)
    notes += bound_notes(specs, samples, effective_size=posterior.effective_size)
    notes += unconstrained_notes(specs, samples)
    rng = np.random.default_rng(posterior_seed + 1)
    predictions = [_row(points[i], predictive(model, samples, i, rng=rng)) for i in everything]
    check_not_percent(points, [r["predicted"] for r in predictions])
    file_predicted = file_predictions(model, parameters)
    energy = energy_check(model, samples, specimen)
    loo = None
    if cross_validate == "loo":
        loo = []
        folds = everything
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=len(folds), unit="fold", desc="leave-one-out", dynamic_ncols=True)
        try:
            for i in folds:
                raise_if_stopped(stop, _STOPPED)  # each fold is a posterior of its own: seconds
                others = [j for j in everything if j != i]
                fold = sample_posterior(model, others, seed=posterior_seed + 1 + i,
                                        method=method)
                if fold.fallback:
                    fold_fallbacks.append(points[i].label())
                if not fold.converged:
                    fold_unconverged.append(points[i].label())
                loo.append(_row(points[i], predictive(model, fold.samples, i, rng=rng),
                                fold="leave-one-out"))
                if bar is not None:
                    bar.update(1)
        finally:
            if bar is not None:
                bar.close()
    if fold_fallbacks:
        notes.append(f"method={method}: the grid could not box the posterior of "
                     f"{len(fold_fallbacks)} of {len(everything)} leave-one-out fold(s) "
                     f"(without {', '.join(fold_fallbacks)}); those were sampled with emcee")
    if fold_unconverged:
        notes.append(f"NOT CONVERGED: the emcee chains of {len(fold_unconverged)} of "
                     f"{len(everything)} leave-one-out fold(s) (without "
                     f"{', '.join(fold_unconverged)}) did not converge (emcee's rule: a chain "
                     "of 50 autocorrelation times): their predictions, and the leave-one-out "
                     "RMS and coverage, are not reliable")
    settings = {"fit": list(fit), "priors": list(priors), "cells": cells, "seed": seed,
                "steady_cycles": steady_cycles, "design_size": n_design, "method": method,
                "method_used": posterior.method,
                "discrepancy_fixed": discrepancy, "discrepancy_floor": discrepancy_floor,
                "cross_validate": cross_validate, "store": str(store_path),
                # the tests it was fitted to: a table's path and sha256, a store's path and
                # the analyses pooled (the DEM cache above is not where they came from)
                "measured": measured_provenance(points)}
    if posterior.diagnostics is not None:  # emcee's: acceptance, autocorrelation, sample size
        settings["sampler"] = posterior.diagnostics.to_dict()
    raise_if_stopped(stop, _STOPPED)
    return CalibrationResult(specimen=specimen, specs=specs, samples=samples, parameters=parameters,
                             correlations=correlations, predictions=predictions, loo=loo,
                             fixed=fixed, design=design, observations=observations, runs=runs,
                             settings=settings, notes=notes, energy_check=energy,
                             wall_s=time.perf_counter() - start, file_predicted=file_predicted)


#: What a stop says (:func:`pidcore.interrupt.raise_if_stopped`).
_STOPPED = "calibration stopped; the DEM runs saved before are kept"


def file_predictions(model: Model, parameters: dict) -> list[float]:
    """The model's SDC (Eq. 11, fixture and baseline included) of every load case at the
    values the calibrated file holds: each fitted parameter's posterior median.

    That point is not where the posterior median of the SDC lies: with correlated parameters
    (fixture mass and baseline, +0.63 in a tester's fit) the marginal medians together
    predicted up to 16 % less than the "calibrated DEM" column, and a user re-running the DEM
    with the file met numbers the calibration never stated."""
    point = np.array([[parameters[s.name]["median"] for s in model.specs]])
    return [float(model.predict(point, i)[0][0]) for i in range(len(model.points))]


#: Least ratio of every measured SDC to its calibrated prediction at which a table of SDCs all
#: above 1 is taken for percentages (:func:`check_not_percent`): a fit that reaches its data
#: leaves them on both sides of its prediction, the paper's worst point is 1.6 x its
#: prediction, and a percentage is 100 x the SDC.
PERCENT_SHORTFALL = 2.0


def check_not_percent(points: Sequence[MeasuredPoint], predicted: Sequence[float]) -> None:
    """Refuse measured SDCs that are all above 1 and all at least :data:`PERCENT_SHORTFALL`
    times the calibrated prediction (posterior median) of their load case: the fit cannot
    reach any of them, as with SDCs typed in percent (4.3 for 0.043).

    The plausibility check refuses a value above its specimen's SDC bound
    (:func:`pidcore.compare.plausibility.sdc_bound`, ``max(2 pi, 8 m_p/m_s)``) as it is read;
    percentages of a light bed (1.7 .. 4.3 for 1 mm steel spheres at 6-10 %) lie below 2 pi
    and were fitted, exit 0, with only "piles against its bound" notes: the discrepancy at
    the top of its prior and bands wide enough to hold 3 of 6. Real SDCs above 1 that the
    model reaches (the bundled exports' 1.1 .. 4.1) are left alone.
    """
    if not points or not all(p.sdc > 1 for p in points):
        return
    ratios = [p.sdc / s if s > 0 else math.inf for p, s in zip(points, predicted, strict=True)]
    if min(ratios) < PERCENT_SHORTFALL:
        return
    sources = ", ".join(dict.fromkeys(p.source for p in points if p.source)) or "the data"
    raise ParameterError(
        f"{sources}: every measured SDC ({min(p.sdc for p in points):.4g} .. "
        f"{max(p.sdc for p in points):.4g}) is above 1 and at least {min(ratios):.3g} x the "
        f"calibrated prediction of its load case ({min(predicted):.4g} .. "
        f"{max(predicted):.4g}): the fit cannot reach them; was the SDC given in percent? "
        "expected the SDC as a fraction (4.3 % is 0.043); the DEM runs are kept for a re-run")


def _released_share(record: dict) -> float | None:
    """:func:`pidcore.dem.result.released_share` of a stored DEM run's record (what
    :attr:`pidcore.dem.DemResult.notes` says of one run); None where the record lacks either
    number."""
    from ..dem.result import released_share

    try:
        share = released_share(record["work_per_cycle_j"], record["energy_per_cycle_j"])
    except (KeyError, TypeError, ValueError):
        return None
    return None if math.isnan(share) else share


def nonpositive_dissipation_notes(labels: Sequence[str],
                                  observations: Sequence[Sequence[Observation]]) -> list[str]:
    """A note per measured point whose DEM runs give no positive particle dissipation over
    their window (Re P <= 0: the bed gave back stored energy there, a window that is no
    steady state). The surrogate takes such a run's dissipative mass as it is, with its
    standard error (:func:`pidcore.calibrate.surrogate.build_surrogate`); that was silent,
    and a prediction of the baseline alone (0.024 where the run's dissipation tally said
    0.14) read as the model's."""
    notes = []
    for label, runs in zip(labels, observations, strict=True):
        found = [o for o in runs if not o.dissipative_mass_kg > 0]
        if found:
            notes.append(
                f"{label}: {len(found)} of {len(runs)} DEM run(s) dissipate nothing over their "
                "window (Re P <= 0, dissipative mass "
                + ", ".join(f"{o.dissipative_mass_kg:.3g} +- {o.dissipative_mass_stderr_kg:.2g}"
                            for o in found)
                + " kg: the bed gave back stored energy, no steady state); the surrogate "
                "of this load case is of d itself, not log d, and takes them as they are with "
                "that error (one of 0 +- 0 with the other runs' median error), so the "
                "prediction there may be low: give the runs more steady cycles or more cells")
    return notes


def _not_converged_note(diagnostics: SamplerDiagnostics) -> str:
    return (f"NOT CONVERGED: the emcee posterior did not converge within {diagnostics.steps} "
            f"steps ({diagnostics.reason}; effective sample {diagnostics.effective_size:.0f}): "
            "the medians, intervals and bands are not reliable; fit fewer parameters, narrow "
            "the priors, or use method=grid (at most 4 fitted quantities)")


#: Relative change of the energy per cycle below the DEM's resolution (:func:`energy_check`).
ENERGY_CHECK_RESOLUTION = 1e-3


def energy_check(model: Model, samples: np.ndarray, specimen: Specimen) -> list[dict]:
    """Work the walls do on the bed per cycle per cell (J), ``Re(P) T = d pi |V|^2`` of the
    surrogate's dissipative mass (Eq. 11, as a measurement sees it), of every load case: the
    DEM at the starting specimen's values against the calibrated DEM (posterior median and
    95 % band). It is the energy the bed dissipates per cycle only where the runs are steady;
    over a run still settling it is more (2.2 x the DEM's dissipation tally in a tester's
    400 Hz, 8 g run of 20 cycles), so it compares the two specimens, not the DEM's tally.

    Observation parameters do not change the DEM, so without DEM parameters both agree by
    construction. ``within`` says whether the starting value lies inside the calibrated band,
    i.e. whether the calibration's change of the physics is within its own uncertainty. A
    load case the fitted parameter does not move has a band of width ~0: the start is inside
    within 0.1 % of the calibrated value (below the DEM's resolution, its cell-to-cell scatter
    is percent level), not outside by a last digit. (The surrogate's variance at the start is
    no measure: a start outside the prior range, e.g. rolling friction 0, is extrapolated.)
    """
    dem = [s for s in model.specs if s.kind == "dem"]
    start = np.array([[s.default for s in dem]]) if dem else np.zeros((1, 0))
    theta = model.dem_theta(samples)
    out = []
    for surrogate in model.surrogates:
        omega = 2 * math.pi * surrogate.frequency_hz
        velocity = surrogate.acceleration_g * STANDARD_GRAVITY / omega
        per_cell = math.pi * velocity**2 / specimen.cell.count  # Re(P) T = d pi |V|^2
        e0 = float(surrogate.predict(start)[0][0] * per_cell)
        e = surrogate.predict(theta)[0] * per_cell
        low, median, high = (float(v) for v in np.percentile(e, [2.5, 50, 97.5]))
        slack = ENERGY_CHECK_RESOLUTION * abs(median)
        out.append({"frequency_hz": surrogate.frequency_hz,
                    "acceleration_g": surrogate.acceleration_g,
                    "fill_percent": surrogate.fill_percent,
                    "energy_per_cycle_per_cell_start_j": e0,
                    "energy_per_cycle_per_cell_calibrated_j": median,
                    "low95_j": low, "high95_j": high,
                    "within": bool(low - slack <= e0 <= high + slack) if dem else True})
    return out


def _row(point: MeasuredPoint, prediction: dict, fold: str = "in-sample") -> dict:
    row = {"frequency_hz": point.frequency_hz, "acceleration_g": point.acceleration_g,
           "fill_percent": point.fill_percent, "material": point.material,
           "measured": point.sdc,
           "measured_stderr": point.sdc_stderr}
    if math.isfinite(point.sdc_stderr_dof):
        # only where known: a calibration from a table without it writes what it always did
        row["measured_stderr_dof"] = point.sdc_stderr_dof
    row.update(prediction)
    row["error"] = row["predicted"] - point.sdc
    if not all(math.isfinite(row[k]) for k in ("predicted", "low95", "high95")):
        raise ParameterError(f"calibration: prediction at {point.label()} is not finite")
    if row["predicted"] > point.sdc_bound.sdc:
        from .prediction import band_cut_words

        # an SDC no measurement is kept at is no prediction: 99.4 (bound 2 pi) went into the
        # leave-one-out RMS (40.5) of the summary, the calibrated file and the store listing
        raise ParameterError(
            f"calibration: the {fold} prediction at {point.label()} is SDC "
            f"{row['predicted']:.4g}, above {band_cut_words(point.sdc_bound)}: the DEM "
            "surrogate there is not sound; give the DEM runs more cells or more steady "
            "cycles")
    return row
