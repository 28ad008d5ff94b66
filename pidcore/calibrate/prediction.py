"""Read a ``calibration.json`` written by ``pidcore calibrate`` and look up the calibrated DEM's
prediction (Eq. 11 SDC of the virtual shaker, 95 % band) for one load case.

Reports and the app use it to show the calibrated prediction beside the raw DEM and the
measurement; it reads only the file (no DEM, no store).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pandas as pd

from .. import defaults
from ..compare.align import (  # noqa: F401 (public here)
    CALIBRATED_BAND_COLUMN,
    CALIBRATED_COLUMN,
    CALIBRATED_HIGH_COLUMN,
    CALIBRATED_INSIDE_COLUMN,
    CALIBRATED_LOW_COLUMN,
    MEASURED_EQ11_COLUMN,
    MEASURED_EQ11_DOF_COLUMN,
    MEASURED_EQ11_STDERR_COLUMN,
    PACKING_RATIO_COLUMN,
    Z95,
    Tolerances,
    band_quantile,
    quantile_label,
)
from ..compare.plausibility import (
    SDC_BOUND_COLUMN,
    SDC_UPPER_BOUND,
    UNKNOWN_SPECIMEN_BOUND,
    SdcBound,
    lowest_kept_sdc,
)
from ..constants import BAND_VERDICTS
from ..errors import ParameterError, instance_of, real_number
from ..loadcase import LoadCase

if TYPE_CHECKING:  # pragma: no cover
    from ..specimen import Specimen

#: :meth:`Calibration.to_pandas`'s measured Eq. 11 columns, calibrated prediction and band as
#: pidcore before 2026-12 named them -> the names every other table gives those quantities
#: (:data:`pidcore.compare.align.MEASURED_COLUMNS_RENAMED`, :data:`pidcore.compare.align.
#: CALIBRATED_COLUMN`): it was a third spelling, "sdc measured [-]" beside the report's
#: "SDC measured (Eq. 11) [-]", and "sdc predicted [-]", "low95 [-]", "high95 [-]" beside the
#: report's "SDC calibrated DEM (Eq. 11) [-]" and its band. An older saved frame reads as
#: today's with
#: ``frame.rename(columns=CALIBRATION_COLUMNS_RENAMED)`` (as :func:`pidcore.report.
#: figures_results.plot_calibration` does). Its verdict column, "measured in 95 % band [...]"
#: beside the report's "measured in calibrated 95 % band [...]" for the same verdict, its
#: "sdc bound [-]" and its "low95 without stderr [-]" (named after calibration.json's key, not
#: beside the band it narrows) followed in 2026-12, and its "fill [%]" beside the report's
#: "packing ratio [%]" (:data:`pidcore.compare.align.PACKING_RATIO_COLUMN`).
CALIBRATION_COLUMNS_RENAMED: dict[str, str] = {
    "sdc measured [-]": MEASURED_EQ11_COLUMN,
    "sdc measured stderr [-]": MEASURED_EQ11_STDERR_COLUMN,
    "sdc measured stderr dof [-]": MEASURED_EQ11_DOF_COLUMN,
    "sdc predicted [-]": CALIBRATED_COLUMN,
    "low95 [-]": CALIBRATED_LOW_COLUMN,
    "high95 [-]": CALIBRATED_HIGH_COLUMN,
    f"measured in 95 % band [{'/'.join(BAND_VERDICTS)}]": CALIBRATED_INSIDE_COLUMN,
    "low95 without stderr [-]": "calibrated low 95 % without measurement stderr [-]",
    "high95 without stderr [-]": "calibrated high 95 % without measurement stderr [-]",
    "sdc bound [-]": SDC_BOUND_COLUMN,
    "fill [%]": PACKING_RATIO_COLUMN,
}
#: The calibrated band of the model's SDC alone (calibration.json's ``low95_without_stderr``,
#: ``high95_without_stderr``): :data:`CALIBRATED_LOW_COLUMN`'s band without the measurement's
#: standard error.
CALIBRATED_LOW_WITHOUT_STDERR_COLUMN = CALIBRATION_COLUMNS_RENAMED["low95 without stderr [-]"]
CALIBRATED_HIGH_WITHOUT_STDERR_COLUMN = CALIBRATION_COLUMNS_RENAMED["high95 without stderr [-]"]
#: The calibrated DEM's SDC minus the measured one, as calibration's summaries name it.
CALIBRATED_DIFFERENCE_COLUMN = "difference calibrated DEM - measured (Eq. 11) [-]"

_REQUIRED = ("frequency_hz", "acceleration_g", "fill_percent", "predicted", "low95", "high95")


def calibrated_sdc_bound(calibrated: Specimen | None, specimen_name: str = "", *,
                         fill_percent: float, material: str) -> SdcBound:
    """The SDC bound (:func:`pidcore.compare.plausibility.sdc_bound`) of a test of the specimen
    a calibration is of (``calibrated``: its calibrated specimen, None where not at hand;
    ``specimen_name``: the name it states): the paper's coupon's where it calibrates that (the
    bound its tests were judged by when analysed: the fitted fixture, 254 g in the bundled
    calibration, is no mass of the tested coupon), else the calibrated specimen's, else 2 pi."""
    from ..compare.plausibility import sdc_bound
    from ..specimen import is_paper_coupon, measured_specimen_name

    tested = measured_specimen_name(calibrated) if calibrated is not None else specimen_name
    if is_paper_coupon(tested):
        return sdc_bound(fill_percent=fill_percent, material=material)
    if calibrated is not None:
        return sdc_bound(fill_percent=fill_percent, material=material, specimen=calibrated)
    return UNKNOWN_SPECIMEN_BOUND


def band_cut_words(bound: SdcBound) -> str:
    """Where a calibrated band is cut and why, e.g. ``'2 pi = 6.283 (a loss factor of 1, above
    which a measured SDC is refused as implausible)'``."""
    if bound.sdc > SDC_UPPER_BOUND:
        return (f"{bound.sdc:.4g}, the SDC bound of the specimen's particles ({bound.basis()}; "
                "a measured SDC above it is refused as implausible)")
    return (f"2 pi = {SDC_UPPER_BOUND:.4g} (a loss factor of 1, above which a measured SDC is "
            "refused as implausible)")



def sdc_text(value: float, *, signed: bool = False) -> str:
    """An SDC as the report's cells write it (4 significant digits, ``"0.4921"``,
    ``"0.08264"``; with its sign where ``signed``: a difference), so that one SDC reads the same
    in every file: calibrate's summaries wrote the calibrated SDC the report shows as 0.4921
    as 0.492, and 0.08264 as 0.083 beside its band's 0.01469; ``"—"`` for a value that is not
    a number."""
    if not math.isfinite(value):
        return "—"
    return f"{value:+.4g}" if signed else f"{value:.4g}"


def band_text(low: float, high: float) -> str:
    """A 95 % band as the report's cells write its bounds (:func:`sdc_text`, e.g.
    ``"0 .. 16.91"``), so that the one band reads the same in every sentence of a page;
    ``"—"`` for a bound that is not a number."""
    return " .. ".join(sdc_text(v) for v in (low, high))


def plausible_sdc_top(bound: SdcBound) -> float:
    """The top of the SDCs a measurement of a particle damper plausibly has: 2 pi (a loss
    factor of 1), or the specimen's ``bound`` where that is lower. A calibrated band from 0 (or
    below) to it refutes none of them (:meth:`CalibratedPrediction.uninformative_reason`)."""
    return min(SDC_UPPER_BOUND, bound.sdc)


def uninformative_count_text(count: int) -> str:
    """How many more bands were ``uninformative`` (:meth:`CalibratedPrediction.judge`),
    counted neither inside nor among those judged, as every count of a calibration's verdicts
    says it after its "k of n inside": the report's note (:func:`pidcore.report.table.
    add_calibration_columns`) and the calibration's summaries and command
    (:func:`pidcore.calibrate.outputs.coverage_text`) wrote these words each in its own copy;
    ``" (1 more uninformative: a band of 0 .. 2 pi, spanning every plausible SDC,
    cannot test the model)"``, "" for none."""
    if count <= 0:
        return ""
    return (f" ({count} more {BAND_VERDICTS[3]}: a band of 0 .. 2 pi, spanning "
            "every plausible SDC, cannot test the model)")


#: Column of :meth:`Calibration.to_pandas` holding each fitted measurement's verdict (words of
#: :data:`pidcore.constants.BAND_VERDICTS`): the report's column
#: (:data:`pidcore.compare.align.CALIBRATED_INSIDE_COLUMN`).
VERDICT_COLUMN = CALIBRATED_INSIDE_COLUMN


@dataclass(frozen=True)
class CalibratedPrediction:
    """The calibrated DEM's prediction at one load case.

    Attributes
    ----------
    load_case : LoadCase
        Load case the calibration predicted (its measured point).
    sdc : float
        Posterior median of the calibrated model's Eq. 11 SDC [-] (the model's mean; the
        band is that of a measurement).
    low95, high95 : float
        Bounds of the 95 % posterior-predictive band [-] of a measurement with the fitted
        point's standard error (:attr:`measured_stderr`).
    measured : float
        SDC the calibration was fitted to at this load case [-] (NaN if not stated).
    measured_stderr : float
        Standard error of that SDC [-] (0: none stated; NaN: a calibration.json written
        before it was kept).
    measured_stderr_dof : float
        Degrees of freedom of that standard error (``n_blocks - 1`` of a pidcore analysis;
        NaN: unknown, its errors taken as normal).
    low95_without_stderr, high95_without_stderr : float
        The band without measurement error [-] (NaN in an older calibration.json).
    sdc_bound : SdcBound
        The SDC above which a measurement of this load case is refused as implausible
        (:func:`pidcore.compare.plausibility.sdc_bound` of the calibrated specimen and this
        fill; 2 pi where the specimen is not known): :meth:`band` is cut there.
    """

    load_case: LoadCase
    sdc: float
    low95: float
    high95: float
    measured: float = math.nan
    measured_stderr: float = math.nan
    low95_without_stderr: float = math.nan
    high95_without_stderr: float = math.nan
    measured_stderr_dof: float = math.nan
    # where the band is cut, from the specimen the calibration is of, not part of the
    # prediction's identity (:meth:`Calibration.lookup` sets it)
    sdc_bound: SdcBound = field(default=UNKNOWN_SPECIMEN_BOUND, compare=False)

    def band(self, stderr: float = math.nan, dof: float = math.nan) -> tuple[float, float]:
        """The 95 % band [-] a measurement with standard error ``stderr`` of ``dof`` degrees
        of freedom (NaN: unknown) is checked against.

        The fitted point's band (:attr:`low95`, :attr:`high95`) where ``stderr`` and ``dof``
        are that point's, ``stderr`` is unknown (NaN) or they cannot be told apart (an older
        calibration.json); else the band without measurement error widened by ``stderr``
        (each side's distance from :attr:`sdc` and q ``stderr`` added in quadrature, q the
        :func:`band_quantile` of ``dof``: Student's t where known, 1.96 where not): a
        precise new measurement is not judged by the wider band of a noisy fitted one, nor
        a noisy one by a narrow band. The quadrature is exact for normal errors; with the
        t's quantile it is at most ~1 % wider than the exact quantile of normal + t (e.g.
        3.07 for 3.05 where both parts are equal: on the safe side), and exact where either
        part dominates (tests/test_calibrate_band_quantile.py checks its coverage).

        The upper bound is cut at :attr:`sdc_bound` (``max(2 pi, 8 m_p / m_s)`` of the
        calibrated specimen at this fill; :data:`SDC_UPPER_BOUND`, 2 pi, a loss factor of 1,
        where the specimen is not known): the model's normal error (discrepancy tau SDC,
        surrogate scatter) is unbounded, and a poorly constrained calibration (tau near its
        prior's 2) reached 12.7, a value no measurement is kept at (``pidcore analyze``
        refuses an SDC above that bound as a set-up error, :mod:`pidcore.compare.
        plausibility`). Cut there the band still holds >= 95 %
        of the measurements that can be kept wherever at most half the model's draws lie
        above the bound ((0.975 - p) / (1 - p) >= 0.95 for p <= 0.5); :meth:`band_note`
        says it was cut, and that the model does not constrain the SDC there.

        The lower bound is not cut at 0: a measurement holds its own error, and one of a small
        SDC lies below 0 as often as its noise says (-0.057 +- 0.13 of 7 degrees of freedom,
        zero damping measured with noise, was judged outside a band cut to 0 .. 0.46). It is
        cut only at :func:`~pidcore.compare.plausibility.lowest_kept_sdc` of ``stderr``
        (-3 ``stderr``; 0 without one), below which a measurement is refused as energy
        created beyond its noise, as the top is cut where one is refused.
        """
        low, high = self.model_band(stderr, dof)
        # a model median above the bound leaves no band below it: [bound, bound], noted
        bound = self.sdc_bound.sdc
        return min(low, bound), min(high, bound)

    def model_band(self, stderr: float = math.nan, dof: float = math.nan) -> tuple[float, float]:
        """:meth:`band` before its upper bound is cut at :attr:`sdc_bound`: the
        posterior-predictive band as the normal error model gives it (:meth:`band_note` says
        where it reaches beyond), its bottom cut at the lowest SDC a measurement of ``stderr``
        is kept at (the fitted point's band was cut there when drawn:
        :func:`pidcore.calibrate.posterior.predictive`)."""
        stderr = real_number("stderr", stderr)
        q = band_quantile(dof)  # checks dof before any early return
        if self._fitted_band_applies(stderr, dof):
            return self.low95, self.high95
        if stderr < 0:
            raise ParameterError(f"stderr {stderr!r}: expected a standard error >= 0")
        width = q * stderr
        low = self.sdc - math.hypot(self.sdc - self.low95_without_stderr, width)
        high = self.sdc + math.hypot(self.high95_without_stderr - self.sdc, width)
        if not math.isfinite(high):  # a stderr near 1e308: its band has no finite bound
            raise ParameterError(f"stderr {stderr!r}: no finite 95 % band; expected a "
                                 "standard error of an SDC")
        return max(low, lowest_kept_sdc(stderr)), high

    def band_note(self, stderr: float = math.nan, dof: float = math.nan) -> str:
        """Where :meth:`model_band` reaches above :attr:`sdc_bound`: that it was cut
        there and why, with the model's own bound; "" otherwise."""
        high = self.model_band(stderr, dof)[1]
        if not high > self.sdc_bound.sdc:
            return ""
        cut = f"calibrated 95 % band cut at {band_cut_words(self.sdc_bound)}; "
        widening = self._measurement_widening(stderr, dof)
        # a pooled pair of records (stderr 1.8, t of 1 degree of freedom: 12.7) reached 23.3
        # by its own scatter, beside a model half-width of 0.41: blaming the calibration
        # told the user the model was at fault where the measurement was
        if widening > self.high95_without_stderr - self.sdc:
            return (cut + f"the band's own upper bound {high:.3g} comes from this "
                    f"measurement's standard error (stderr {stderr:.3g} x its 95 % quantile "
                    f"{band_quantile(dof):.4g} = {widening:.3g}, beside the calibrated "
                    f"model's {self.high95_without_stderr - self.sdc:.3g} above its "
                    "prediction): the measurement is too uncertain here for the band to "
                    "judge it")
        return (cut + f"the model's own upper bound {high:.3g} says the calibration does not "
                "constrain the SDC here (its model discrepancy and surrogate scatter dominate)")

    def _fitted_band_applies(self, stderr: float, dof: float) -> bool:
        """Whether :meth:`model_band` takes the fitted point's band (``stderr`` unknown, an
        older calibration.json, or the fitted point's own stderr and dof) rather than
        widening the band without measurement error by ``stderr``."""
        same_dof = (math.isnan(dof) and math.isnan(self.measured_stderr_dof)) or \
            dof == self.measured_stderr_dof
        return (not math.isfinite(stderr) or not math.isfinite(self.measured_stderr)
                or not math.isfinite(self.low95_without_stderr)
                or (same_dof and math.isclose(stderr, self.measured_stderr, rel_tol=1e-9,
                                              abs_tol=1e-12)))

    def _measurement_widening(self, stderr: float, dof: float) -> float:
        """The half-width ``q x stderr`` :meth:`model_band` adds in quadrature for a
        measurement's standard error; 0 where it takes the fitted point's band instead."""
        stderr = real_number("stderr", stderr)
        if self._fitted_band_applies(stderr, dof):
            return 0.0
        return band_quantile(dof) * stderr

    def uninformative_reason(self, stderr: float = math.nan, dof: float = math.nan) -> str:
        """Why the 95 % band (:meth:`band`) of a measurement with standard error ``stderr``
        of ``dof`` degrees of freedom cannot judge it: it spans every SDC a measurement of a
        particle damper plausibly has, from 0 (or below) to :func:`plausible_sdc_top` (2 pi, a
        loss factor of 1), so it refutes no plausible measurement and "inside" says nothing
        about the model; "" where the band can judge it.

        The top is 2 pi, not :attr:`sdc_bound`: the specimen's bound (16.9 for the paper's
        coupon at 50 %) is the most its particles could ever dissipate, where a result is
        refused as a set-up error, not an SDC measurements plausibly have, and the bound a
        path knows differs (16.9 where the report has the specimen, 2 pi where a prediction is
        loaded alone). Judged against the bound, a pooled pair of records (SDC 1.664 +- 0.529
        of 1 degree of freedom, t = 12.7) got the band -1.587 .. 6.925 around 0.197: "inside"
        in the report (short of 16.9), "uninformative" where loaded alone (cut at 2 pi), for
        the one band. Against 2 pi the verdict is the same whichever bound cuts the band (each
        is >= 2 pi). A criterion on the measurement's widening dominating the model's
        half-width was not taken: such a band (0.05 stderr beside a model's 0.03) still
        refutes an SDC far off, and the question is whether the band can refute one."""
        low, high = self.band(stderr, dof)
        top = plausible_sdc_top(self.sdc_bound)
        # a bottom below 0 (a noisy measurement's, cut at lowest_kept_sdc) refutes no more of
        # the plausible SDCs than one at 0
        if not (low <= 0.0 and high >= top):
            return ""
        widening = self._measurement_widening(stderr, dof)
        cause = ("this measurement's own scatter widens it" if widening
                 > self.high95_without_stderr - self.sdc else
                 "the calibration does not constrain the SDC here")
        return (f"uninformative: the calibrated 95 % band {band_text(low, high)} spans every "
                f"plausible SDC (0 to 2 pi, a loss factor of 1; {cause}), so it cannot test "
                "the model: not judged and not counted as inside")

    def contains(self, sdc: float, stderr: float = math.nan, dof: float = math.nan) -> bool:
        """True if ``sdc`` lies inside the 95 % band of a measurement with standard error
        ``stderr`` of ``dof`` degrees of freedom (:meth:`band`; bounds included); False for
        NaN."""
        low, high = self.band(stderr, dof)
        return bool(low <= sdc <= high)

    def judge(self, sdc: float, stderr: float = math.nan, dof: float = math.nan
              ) -> tuple[str, str]:
        """``(verdict, reason)`` of a measured ``sdc`` with standard error ``stderr`` of
        ``dof`` degrees of freedom: ``uninformative`` with :meth:`uninformative_reason`
        where the band cannot judge it, else ``yes`` or ``no`` (:meth:`contains`) and ""
        (words of :data:`pidcore.constants.BAND_VERDICTS`). The one rule of the report's
        rows, the app's Compare page and the calibration's own summaries."""
        from ..constants import BAND_VERDICTS

        inside, outside, _, uninformative = BAND_VERDICTS
        reason = self.uninformative_reason(stderr, dof)
        if reason:
            return uninformative, reason
        return (inside if self.contains(sdc, stderr, dof) else outside), ""


#: Why a measured SDC that pools a record the plausibility checks refuse (kept with
#: --accept-implausible) is not judged: its standard error is the scatter of an impossible SDC
#: about the others (22 for 46.1 pooled with 2.19), so the band it gives holds anything.
POOLS_IMPLAUSIBLE_REASON = ("it pools an implausible result, so the calibrated band does not "
                            "judge it")


#: Why a row without a measured SDC is not judged (:func:`judge_measurement`).
NO_MEASUREMENT_REASON = "no Eq. 11 measurement to compare with the calibrated band"


@dataclass(frozen=True)
class MeasurementJudgement:
    """The calibrated prediction beside one measured Eq. 11 SDC, and its verdict
    (:func:`judge_measurement`): what a report row, the app's Compare page and the load-case
    PDF sheet each show, from the one rule.

    Attributes
    ----------
    sdc : float
        The calibrated DEM's Eq. 11 SDC at the load case [-].
    low, high : float
        The 95 % band of a measurement with the measured SDC's own standard error [-] (NaN:
        none for that standard error, :attr:`reason` says why).
    verdict : str
        A word of :data:`pidcore.constants.BAND_VERDICTS`.
    reason : str
        Why the verdict is ``not compared`` or ``uninformative``; "" where judged.
    before_baseline : str
        Where the empty coupon's damping was taken off the measured SDC: that it was judged
        at the SDC before (the calibration predicts the whole coupon's); "" otherwise.
    widened : str
        Where the band is not the calibration's own point's: for which standard error and
        with which quantile it was widened; "" otherwise.
    cut : str
        Where the band is cut at the SDC bound, and why (:meth:`CalibratedPrediction.
        band_note`); "" otherwise.
    """

    sdc: float
    low: float
    high: float
    verdict: str
    reason: str = ""
    before_baseline: str = ""
    widened: str = ""
    cut: str = ""

    @property
    def note(self) -> str:
        """The words a report row's note gains (its verdict's reason first; the band's cut
        last), "; "-joined; "" where there are none."""
        return "; ".join(n for n in (self.reason, self.before_baseline, self.widened,
                                     self.cut) if n)


def judge_measurement(hit: CalibratedPrediction, measured: float, stderr: float,
                      dof: float = math.nan, baseline_sdc: float = 0.0, *,
                      pools_implausible: bool = False) -> MeasurementJudgement:
    """The calibrated prediction ``hit`` beside a measured Eq. 11 SDC ``measured`` (NaN: none)
    with standard error ``stderr`` of ``dof`` degrees of freedom, from which ``baseline_sdc``
    was taken off as the empty coupon's damping (:func:`pidcore.signal.power.
    baseline_sdc_taken_off`; 0: nothing, NaN: taken off, amount unknown).

    The one rule of the report's rows (:func:`pidcore.report.table.add_calibration_columns`),
    the app's Compare page and the load-case sheet: the band is that of a measurement with
    this one's standard error; the measurement is judged (:meth:`CalibratedPrediction.judge`)
    at its SDC before the baseline was taken off (the calibration predicts the whole coupon's
    SDC, adding a baseline of its own); ``not compared`` without a measurement, with an
    unknown baseline, where it ``pools_implausible`` records, or where its standard error
    gives no band (a negative or near-1e308 stderr of a hand-edited store)."""
    not_compared = BAND_VERDICTS[2]
    own_stderr = stderr if math.isfinite(measured) else math.nan
    try:
        low, high = hit.band(own_stderr, dof)
    except ParameterError as exc:
        return MeasurementJudgement(hit.sdc, math.nan, math.nan, not_compared,
                                    f"no calibrated band for this measurement's SDC stderr: "
                                    f"{exc}")
    cut = hit.band_note(own_stderr, dof)
    if not math.isfinite(measured):
        return MeasurementJudgement(hit.sdc, low, high, not_compared, NO_MEASUREMENT_REASON,
                                    cut=cut)
    if not math.isfinite(baseline_sdc):
        return MeasurementJudgement(
            hit.sdc, low, high, not_compared,
            "the measured SDC had the empty coupon's damping taken off, and its SDC before "
            "that (which the calibration predicts) is not stored: not compared with the "
            "calibrated band", cut=cut)
    if pools_implausible:
        return MeasurementJudgement(hit.sdc, low, high, not_compared, POOLS_IMPLAUSIBLE_REASON,
                                    cut=cut)
    widened = ""
    if (low, high) != hit.band():
        # "(the calibration's point at this load case: 0)" read as a point numbered 0, or an
        # SDC of 0: it is the stderr of the fitted point
        widened = (f"calibrated band for this measurement's SDC stderr {stderr:.3g} (the "
                   f"calibration's own measurement at this load case had SDC stderr "
                   f"{hit.measured_stderr:.3g}); its 95 % widening: {quantile_label(dof)}")
    judged_at = measured + baseline_sdc
    verdict, uninformative = hit.judge(judged_at, stderr, dof)
    before = (f"judged at the measured SDC before the empty coupon's damping "
              f"({sdc_text(baseline_sdc)}) was taken off, {sdc_text(judged_at)}, the SDC the "
              "calibration predicts") if baseline_sdc else ""
    return MeasurementJudgement(hit.sdc, low, high, verdict, uninformative, before, widened, cut)


def row_verdict(row: dict, bound: SdcBound) -> str:
    """The verdict of :data:`pidcore.constants.BAND_VERDICTS` on one prediction row of a
    calibration (``predictions`` or ``loo`` of its calibration.json, or of
    :class:`~pidcore.calibrate.calibrate.CalibrationResult`), its band cut at ``bound``
    (:func:`calibrated_sdc_bound` at the row's fill): :meth:`CalibratedPrediction.judge`, the
    rule the report and the app judge a measurement by (an ``uninformative`` row is counted
    neither inside nor among those judged)."""
    def number(key: str) -> float:  # absent or null (an older calibration.json): unknown
        value = row.get(key)
        return math.nan if value is None else float(value)

    prediction = CalibratedPrediction(
        LoadCase(row["frequency_hz"], row["acceleration_g"], row["fill_percent"],
                 str(row.get("material") or defaults.COMPARE_DEFAULT_MATERIAL)),
        number("predicted"), number("low95"), number("high95"), number("measured"),
        number("measured_stderr"), number("low95_without_stderr"),
        number("high95_without_stderr"), number("measured_stderr_dof"), sdc_bound=bound)
    # the row's own stderr and dof: the fitted point's band, as the row states it
    return prediction.judge(prediction.measured, prediction.measured_stderr,
                            prediction.measured_stderr_dof)[0]


@dataclass(frozen=True)
class Calibration:
    """A calibration read from ``calibration.json``.

    Attributes
    ----------
    path : Path
        The file read.
    parameters : dict
        ``{name: {"median", "low95", "high95"}}`` of the fitted parameters.
    predictions : tuple of CalibratedPrediction
        In-sample posterior-predictive predictions, one per measured load case.
    specimen_path : Path or None
        The calibrated specimen file beside it, if present.
    specimen_name : str
        The name of the specimen it calibrates where known without a file (a calibration
        held in memory by the app, or read from a store); "" otherwise.
    specimen_text : str
        The calibrated specimen file's text where it was read with the calibration (from a
        store: :mod:`pidcore.calibrate.persist`); "" otherwise.
    document_text : str
        The whole calibration.json where it was read from a store; "" otherwise.
    store_key : str
        Its key in the store it was read from; "" for a calibration.json.
    created_utc : str
        When the store saved it; "" for a calibration.json.
    """

    path: Path
    parameters: dict
    predictions: tuple[CalibratedPrediction, ...]
    specimen_path: Path | None = None
    specimen_name: str = ""
    specimen_text: str = ""
    document_text: str = ""
    store_key: str = ""
    created_utc: str = ""
    #: Said on reading it: the half-moved outputs of a killed calibration finished first.
    read_note: str = ""

    def to_pandas(self) -> pd.DataFrame:
        """The predictions, one row per calibrated load case, each column naming its unit.

        Columns ``frequency [Hz]``, ``acceleration [g]``, ``packing ratio [%]``, ``material``,
        ``direction``, ``SDC calibrated DEM (Eq. 11) [-]``, ``calibrated low 95 % [-]``,
        ``calibrated high 95 % [-]`` (the band of a measurement with the fitted point's
        standard error; the report's names, :data:`~pidcore.compare.align.CALIBRATED_COLUMN`),
        ``SDC measured (Eq. 11) [-]``,
        ``SDC measured (Eq. 11) stderr [-]``,
        ``calibrated low 95 % without measurement stderr [-]``,
        ``calibrated high 95 % without measurement stderr [-]`` (the model's SDC alone),
        ``SDC measured (Eq. 11) stderr dof [-]`` (the names of
        :mod:`pidcore.compare.align`; :data:`CALIBRATION_COLUMNS_RENAMED` renames an older
        frame's; NaN where the file
        does not state them), ``SDC bound [-]`` (where the band is cut: :meth:`sdc_bound`)
        and :data:`VERDICT_COLUMN` (the report's
        ``measured in calibrated 95 % band [yes/no/not compared/uninformative]``:
        :meth:`CalibratedPrediction.judge` of the fitted
        measurement at that bound; ``not compared`` where none is stated): what
        :meth:`plot` draws, so that an uninformative band is not drawn as a hit.
        """
        specimen = self.calibrated_specimen()  # read once, not once per row
        not_compared = BAND_VERDICTS[2]
        rows = []
        for p in self.predictions:
            judged = replace(p, sdc_bound=calibrated_sdc_bound(
                specimen, self.specimen_name, fill_percent=p.load_case.fill_percent,
                material=p.load_case.material))
            rows.append((judged, not_compared if math.isnan(p.measured) else judged.judge(
                p.measured, p.measured_stderr, p.measured_stderr_dof)[0]))
        return pd.DataFrame([{
            "frequency [Hz]": p.load_case.frequency_hz,
            "acceleration [g]": p.load_case.acceleration_g,
            PACKING_RATIO_COLUMN: p.load_case.fill_percent,
            "material": p.load_case.material,
            "direction": p.load_case.direction,
            CALIBRATED_COLUMN: p.sdc,
            CALIBRATED_LOW_COLUMN: p.low95,
            CALIBRATED_HIGH_COLUMN: p.high95,
            MEASURED_EQ11_COLUMN: p.measured,
            MEASURED_EQ11_STDERR_COLUMN: p.measured_stderr,
            CALIBRATED_LOW_WITHOUT_STDERR_COLUMN: p.low95_without_stderr,
            CALIBRATED_HIGH_WITHOUT_STDERR_COLUMN: p.high95_without_stderr,
            MEASURED_EQ11_DOF_COLUMN: p.measured_stderr_dof,
            SDC_BOUND_COLUMN: p.sdc_bound.sdc,
            VERDICT_COLUMN: verdict,
        } for p, verdict in rows])

    def plot(self, ax: Any = None) -> Any:
        """Predictions with their 95 % bands beside the measured SDCs
        (:func:`pidcore.report.figures_results.plot_calibration`); returns ``ax``."""
        from ..report.figures_results import plot_calibration  # lazy: drawing is optional

        return plot_calibration(self.to_pandas(), ax=ax)

    def lookup(self, case: LoadCase, *,
               tolerances: Tolerances | None = None) -> CalibratedPrediction | None:
        """The prediction at ``case`` (same material; frequency, acceleration and fill within
        ``tolerances``, default the report's ``COMPARE_*``), or None if it predicts none."""
        instance_of("case", case, LoadCase, hint="e.g. LoadCase(500.0, 5.0, 50.0)")
        tolerances = tolerances or Tolerances()
        hits = [p for p in self.predictions
                if p.load_case.material == case.material and tolerances.matches(case,
                                                                                p.load_case)]
        if not hits:
            return None
        # the nearest in frequency, then acceleration, then fill, if tolerances admit several
        hit = min(hits, key=lambda p: (abs(p.load_case.frequency_hz - case.frequency_hz),
                                       abs(p.load_case.acceleration_g - case.acceleration_g),
                                       abs(p.load_case.fill_percent - case.fill_percent)))
        return replace(hit, sdc_bound=self.sdc_bound(hit.load_case))

    def sdc_bound(self, case: LoadCase) -> SdcBound:
        """The SDC bound of a measurement at ``case`` (:func:`pidcore.compare.plausibility.
        sdc_bound`) of the specimen this calibration is of: the paper's coupon's where it
        calibrates that (the bound its tests were judged by when analysed: the calibration's
        fitted fixture, 254 g in the bundled one, is no mass of the tested coupon), else its
        calibrated specimen's, else 2 pi (not known)."""
        return calibrated_sdc_bound(self.calibrated_specimen(), self.specimen_name,
                                    fill_percent=case.fill_percent, material=case.material)

    def calibrated_specimen(self) -> Specimen | None:
        """The calibrated specimen: read with it from a store (:attr:`specimen_text`), else
        the file beside the calibration (:attr:`specimen_path`); None where there is none or
        it cannot be read (then which specimen it calibrates is unknown)."""
        from ..errors import PidcoreError
        from ..specimen import Specimen, load_specimen

        try:
            if self.specimen_text:
                return Specimen.from_text(self.specimen_text, source=f"{self.path} (specimen)")
            if self.specimen_path is None:
                return None
            return load_specimen(self.specimen_path)
        except (PidcoreError, OSError):
            return None

    def tested_sha256(self) -> str:
        """The sha256 of the specimen file whose tests this calibration fitted (its calibrated
        file's ``[provenance]``: :func:`tested_sha256`); "" where that is unknown (no
        readable calibrated file, or one written before ``[provenance]`` existed)."""
        spec = self.calibrated_specimen()
        return (tested_sha256(spec) or "") if spec is not None else ""

    def other_file_reason(self, sha256: object, specimen_name: str = "") -> str:
        """Why this calibration does not speak for a measurement that recorded its specimen
        file's hash ``sha256`` (``specimen_sha256``): another file, of the same name where the
        names agree (an edited ``x.toml``); "" where it does, or where either hash is unknown
        (a record saved before the hash was, a calibrated file without ``[provenance]``:
        the names decide, :meth:`speaks_for`)."""
        from ..specimen import hashed_name, same_tested_file, uncalibrated_name

        theirs = self.tested_sha256()
        if same_tested_file(sha256, theirs) is not False:
            return ""
        spec = self.calibrated_specimen()
        source = spec.provenance if spec is not None else None
        calibrated = source.calibrated_from_name if source is not None else self.specimen_name
        tested = uncalibrated_name(specimen_name) if specimen_name else calibrated
        # "paper_coupon [45d792]" (a test of another file of the coupon's name) says its hash
        shown = tested if tested.endswith("]") else hashed_name(tested, str(sha256))
        return (f"it calibrates specimen {hashed_name(calibrated, theirs)}, not "
                f"{shown} (another file"
                + (" of the same name)" if tested == calibrated else ")"))

    def speaks_for(self, specimen_name: str, sha256: object = "") -> bool:
        """Whether this calibration may predict a measurement of the specimen named
        ``specimen_name`` ("" : not named): the same name as the specimen it calibrates (its
        calibrated file is "<name>_calibrated"), or either unknown. The paper's coupon is
        :func:`pidcore.specimen.is_paper_coupon`'s: its calibration speaks for a test naming
        ``paper_coupon`` or ``paper_coupon_aluminium`` (the material is :meth:`lookup`'s), and
        a calibrated file named ``paper_coupon_calibrated`` with another cell, or made from
        another file of the coupon's name (its ``[provenance]``), is named as its tests are
        (:func:`pidcore.specimen.measured_specimen_name`), not as the coupon's."""
        from ..specimen import is_paper_coupon, measured_specimen_name, uncalibrated_name

        # a measurement that recorded its specimen file's hash (``sha256``) is matched by it
        # where the calibrated file records its source: two files of one name are two
        # specimens. Otherwise (an older record or calibration) by name, as before
        if self.other_file_reason(sha256, specimen_name):
            return False
        calibrated = self.specimen_name
        if specimen_name and (not calibrated or is_paper_coupon(calibrated)):
            # another file named paper_coupon (another cell) calibrates to
            # paper_coupon_calibrated too: its band was shown beside the coupon's tests
            spec = self.calibrated_specimen()
            calibrated = measured_specimen_name(spec) if spec is not None else calibrated
        if not specimen_name or not calibrated:
            return True
        if is_paper_coupon(calibrated) and is_paper_coupon(specimen_name):
            return True
        return uncalibrated_name(calibrated) == uncalibrated_name(specimen_name)

    def other_specimen_reason(self, specimen: Specimen | None) -> str:
        """Why this calibration does not speak for ``specimen`` (another specimen, or one of
        the same name with another cell or particles); "" where it does, or where either is
        unknown (``specimen`` None, or no readable :meth:`calibrated_specimen`). A report
        checks this before :meth:`lookup`, which matches load cases only."""
        if specimen is None:  # nothing to check: do not read the specimen file
            return ""
        return _other_specimen(self.calibrated_specimen(), specimen)

    def why_not_predicted(self, case: LoadCase, *,
                          tolerances: Tolerances | None = None) -> str:
        """Why :meth:`lookup` finds no prediction at ``case``: another particle material,
        outside the calibrated range, or not one of the calibrated load cases (it predicts
        only where it was fitted). Another specimen is :meth:`other_specimen_reason`'s, asked
        first.

        Parameters
        ----------
        case : LoadCase
        tolerances : Tolerances, optional
            As for :meth:`lookup`.
        """
        tolerances = tolerances or Tolerances()
        materials = sorted({p.load_case.material for p in self.predictions})
        if case.material not in materials:
            return f"it calibrates {' and '.join(materials)} particles, not {case.material}"
        same = [p.load_case for p in self.predictions if p.load_case.material == case.material]
        outside = []
        for name, unit, attr, slack in (
                ("frequency", "Hz", "frequency_hz", lambda v: tolerances.frequency_rtol * v),
                ("acceleration", "g", "acceleration_g",
                 lambda v: tolerances.acceleration_rtol * v),
                ("fill", "%", "fill_percent", lambda v: tolerances.fill_atol_percent)):
            lo = min(getattr(c, attr) for c in same)
            hi = max(getattr(c, attr) for c in same)
            value = getattr(case, attr)
            if value < lo - slack(lo) or value > hi + slack(hi):
                span = f"{lo:g} {unit}" if lo == hi else f"{lo:g}-{hi:g} {unit}"
                outside.append(f"{name} {value:.4g} {unit} not in its {span}")
        if outside:
            return "outside its calibrated range (" + "; ".join(outside) + ")"
        return (f"not one of its {len(same)} calibrated {case.material} load cases (it predicts "
                "only where it was fitted)")


def _other_specimen(calibrated, specimen) -> str:
    """Why a calibration of ``calibrated`` (its calibrated specimen file) does not speak for
    ``specimen``; "" where it does, or where either is unknown."""
    if calibrated is None or specimen is None:
        return ""
    # the calibrated file is the starting specimen renamed "<name>_calibrated" with fitted
    # contact, coupon or mass values: the cell and the particles say which specimen it is
    from ..specimen import measured_specimen_name, provenance_test_name, uncalibrated_name

    source = calibrated.provenance
    tested = tested_sha256(specimen)
    if source is not None and tested is not None:
        # both files say which file was tested: the hashes decide, whatever the names (an
        # edited x.toml keeps its name, and a calibration of the earlier x was shown beside
        # the new one's rows; a user's paper_coupon.toml calibrates to the paper coupon's
        # name)
        if specimen.hash == calibrated.hash or tested == source.calibrated_from_sha256:
            return ""
        own = uncalibrated_name(measured_specimen_name(specimen))
        theirs = provenance_test_name(calibrated) or source.calibrated_from_name
        if theirs == own:  # one name, two files: their hashes tell them apart
            from ..specimen import hashed_name

            return (f"it calibrates specimen {hashed_name(theirs, source.calibrated_from_sha256)}"
                    f", not {hashed_name(own, tested)} (another file of the same name)")
        return f"it calibrates specimen {theirs}, not {own}"
    # by name: a calibrated file written before [provenance] existed (on either side) says
    # only its name, so a file of that name with the same cell and particles is taken for it
    routed = provenance_test_name(calibrated)
    if routed:
        # made from a user's paper_coupon.toml (its [provenance]): its name is the paper
        # coupon's calibrated one, and its band was shown beside the coupon's tests
        own = uncalibrated_name(measured_specimen_name(specimen))
        return "" if own == routed else f"it calibrates specimen {routed}, not {own}"
    base = uncalibrated_name(calibrated.name)
    names = {calibrated.name, base}
    shape = ("shape", "inscribed_diameter_m", "height_m")
    same_cell = all(getattr(calibrated.cell, a) == getattr(specimen.cell, a) for a in shape)
    same_particles = (calibrated.particles.material == specimen.particles.material
                      and calibrated.particles.radius_m == specimen.particles.radius_m)
    if specimen.name not in names:
        return f"it calibrates specimen {base}, not {specimen.name}"
    if not (same_cell and same_particles):
        what = "cell" if not same_cell else "particles"
        return f"it calibrates another specimen named {base} (its {what} differ)"
    return ""


def _stated_specimen_name(doc: dict) -> str:
    """The name of the specimen a calibration.json states it calibrated (its ``specimen``
    ``name``); "" where it states none (written before it did) or not as text."""
    from ..specimen import hashed_name, is_paper_coupon, uncalibrated_name

    stated = doc.get("specimen")
    if not isinstance(stated, dict) or not isinstance(stated.get("name"), str):
        return ""
    name, sha = stated["name"], stated.get("sha256")
    if isinstance(sha, str) and sha and uncalibrated_name(name) == name \
            and is_paper_coupon(name) and not is_paper_coupon(name, sha):
        # a user's own paper_coupon.toml: its tests are saved as "paper_coupon [45d792]"
        # (pidcore.specimen.measured_specimen_name), never as the paper coupon's
        return hashed_name(name, sha)
    return name


def tested_sha256(specimen) -> str | None:
    """The sha256 of the specimen file whose tests ``specimen`` models: the file it was
    calibrated from (its ``[provenance]``), else its own (a file that is not a calibrated
    one); None for a calibrated file without ``[provenance]`` (written before the table
    existed: which file it came from is unknown, only its name is). Otherwise the hash its
    tests are saved with (:func:`pidcore.specimen.measured_specimen_sha256`)."""
    from ..specimen import measured_specimen_sha256, uncalibrated_name

    if specimen.provenance is None and uncalibrated_name(specimen.name) != specimen.name:
        return None
    return measured_specimen_sha256(specimen)


def _number(value, what: str, path: Path) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not math.isfinite(value):
        raise ParameterError(f"{path}: {what} must be a finite number, got {value!r}")
    return float(value)


def _optional(value, what: str, path: Path) -> float:
    """An optional number of a prediction row: NaN where absent or null (an older file, or
    no value), else checked as :func:`_number` checks a required one."""
    return math.nan if value is None else _number(value, what, path)


def load_calibration(path: str | os.PathLike, *, key: str | None = None) -> Calibration:
    """Read and check a ``calibration.json`` of ``pidcore calibrate`` (or the ``--out`` folder
    holding it), or a calibration saved in an HDF5 store (``key``: which one; a store holding
    one needs none: :func:`pidcore.calibrate.persist.stored_calibration`).

    Raises
    ------
    ParameterError
        One line naming the file and what was expected: missing, not JSON, not a
        calibration (no ``parameters``/``predictions``), a store without it, or a prediction
        with a missing or non-finite field or ``low95 > high95``.
    """
    from .persist import is_store_file, stored_calibration

    path = Path(path)
    if is_store_file(path):
        return stored_calibration(path, key)
    if key is not None:
        raise ParameterError(f"{path}: a calibration key ({key}) chooses among the "
                             "calibrations of an HDF5 store; this is not one")
    from ..specimen import finish_calibration_moves

    # before any file is read: a killed --out may have left a mix of two calibrations
    read_note = finish_calibration_moves(path if path.is_dir() else path.parent)
    if path.is_dir() and (path / "calibration.json").is_file():
        path = path / "calibration.json"  # the folder `pidcore calibrate --out` wrote
    if path.is_dir():
        raise ParameterError(f"{path}: a folder without calibration.json (expected the "
                             "calibration.json written by write_outputs(result, out_dir), or its "
                             "folder)")
    if not path.is_file():
        raise ParameterError(f"{path}: no such calibration file (expected the calibration.json "
                             "written by write_outputs(result, out_dir))")
    calibration = calibration_from_json(path.read_bytes(), path)
    specimen = path.parent / "calibrated_specimen.toml"
    return Calibration(path=path, parameters=calibration.parameters,
                       predictions=calibration.predictions,
                       specimen_path=specimen if specimen.is_file() else None,
                       specimen_name=calibration.specimen_name, read_note=read_note)


def calibration_from_json(text: str | bytes, source: str | os.PathLike, *,
                          specimen_name: str = "") -> Calibration:
    """A calibration from the text of a ``calibration.json`` (``source`` names it in errors
    and in :attr:`Calibration.path`); checked as :func:`load_calibration` does.
    ``specimen_name``: the specimen it calibrates, where the caller knows it; else the
    ``specimen`` ``name`` the file states (written since it has one)."""
    path = Path(source)
    try:
        doc = json.loads(text)
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ParameterError(f"{path}: not a calibration.json of pidcore calibrate "
                             f"(not JSON: {exc})") from None
    except RecursionError:  # json.loads is recursive: "[[[[..." a traceback before
        raise ParameterError(f"{path}: not a calibration.json of pidcore calibrate (JSON "
                             "nested too deeply to be read)") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("predictions"), list) \
            or not isinstance(doc.get("parameters"), dict) or not doc["predictions"]:
        raise ParameterError(f"{path}: not a calibration.json of pidcore calibrate (expected "
                             "'parameters' and a non-empty 'predictions' list)")
    predictions = []
    for i, row in enumerate(doc["predictions"]):
        if not isinstance(row, dict) or any(k not in row for k in _REQUIRED):
            # keys quoted: the CLI names a keyword as its flag, and "predictions[5].--fill"
            # named a key no calibration.json has
            raise ParameterError(f"{path}: predictions[{i}] must have the keys "
                                 f"{', '.join(map(repr, _REQUIRED))}")
        f, a, fill, sdc, low, high = (_number(row[k], f"predictions[{i}][{k!r}]", path)
                                      for k in _REQUIRED)
        if not low <= sdc <= high:
            raise ParameterError(f"{path}: predictions[{i}]: expected low95 <= predicted <= "
                                 f"high95, got {low} / {sdc} / {high}")
        material = row.get("material") or defaults.COMPARE_DEFAULT_MATERIAL
        measured, measured_stderr, low0, high0 = (
            _optional(row.get(k), f"predictions[{i}][{k!r}]", path)
            for k in ("measured", "measured_stderr", "low95_without_stderr",
                      "high95_without_stderr"))
        if math.isfinite(low0) != math.isfinite(high0) or (
                math.isfinite(low0) and not low0 <= sdc <= high0):
            # a band without measurement error that misses its own median (low > predicted)
            # was folded about it by band()'s quadrature: a made-up band, not the file's
            raise ParameterError(f"{path}: predictions[{i}]: expected low95_without_stderr <= "
                                 f"predicted <= high95_without_stderr, got {low0} / {sdc} / "
                                 f"{high0}")
        if measured_stderr < 0:  # NaN (not stated) passes
            raise ParameterError(f"{path}: predictions[{i}].measured_stderr must be a standard "
                                 f"error >= 0, got {measured_stderr!r}")
        # absent in a calibration.json of a table without it (or written before it was kept)
        dof = _optional(row.get("measured_stderr_dof"), f"predictions[{i}].measured_stderr_dof",
                        path)
        if not dof > 0 and not math.isnan(dof):
            raise ParameterError(f"{path}: predictions[{i}].measured_stderr_dof must be degrees "
                                 f"of freedom > 0, got {dof!r}")
        try:
            case = LoadCase(f, a, fill, str(material))
        except ParameterError as exc:  # said without the file and row before
            raise ParameterError(f"{path}: predictions[{i}]: {exc}") from None
        predictions.append(CalibratedPrediction(case, sdc, low, high, measured,
                                                measured_stderr, low0, high0, dof))
    return Calibration(path=path, parameters=doc["parameters"], predictions=tuple(predictions),
                       specimen_name=specimen_name or _stated_specimen_name(doc))
