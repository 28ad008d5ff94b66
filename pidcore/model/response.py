"""Harmonic response of a structure treated with particle dampers (paper Sect. 1 and 8).

A mode of the treated structure is a single-degree-of-freedom oscillator (modal mass ``m``,
natural frequency ``f_n``, structural damping ratio ``zeta_s``) driven by a force
``F0 cos(w t)`` applied to the modal mass (force excitation: a shaker or an acoustic load
projected on the mode; base excitation would add the base motion to the damper's relative
velocity and is not modelled). The particles add the amplitude-dependent equivalent damper of
:mod:`pidcore.model.damper`:

    c_pd(X, w) = SDC(fill, a = w^2 X, f) * (m_c / A_c) * w / (2 pi) * A_t

with ``m_c`` and ``A_c`` the vibrated mass and area of the coupon tests behind the SDC model and
``A_t`` the treated area: the damper dissipates, per unit treated area, what the coupon
dissipated per unit area at the same acceleration amplitude and frequency.

By default the whole treated area moves with the modal coordinate X (mode-shape amplitude 1
over it; the result's ``mode_shape_note`` says so). Where the mode shape varies over the
treated area, :attr:`TreatedMode.treated_regions` gives each region's area ``A_i`` and
mode-shape amplitude ``phi_i`` (scaled as the modal mass is, ``m = sum m_j phi_j^2``): region
``i`` moves ``|phi_i| X``, its damper ``c_i`` is taken at its own acceleration
``w^2 |phi_i| X``, and projected on the mode (virtual work of the dashpot forces on the
displacements ``phi_i X``) the modal damper is

    c_pd(X, w) = sum_i c_i(|phi_i| X, w) phi_i^2,

so the particles add a modal damping ratio ``c_pd / (2 w m)``. The mode is assumed to stay
uncoupled from the others (the particle damping is light, or proportional to the mass).

First-order harmonic balance gives the amplitude as the root of

    X |k - m w^2 + j w (c_s + c_pd(X, w))| = F0,    k = m (2 pi f_n)^2,  c_s = 2 zeta_s m 2 pi f_n.

Since ``c_pd >= 0`` every root lies between the response with the largest particle damping and
the response without particles; the bracket is scanned on a log grid for sign changes and each
one is refined with :func:`scipy.optimize.brentq`. The SDC dips at high acceleration, so
several roots (jumps) can exist; the largest stable amplitude is returned (conservative),
flagged, and all of them are listed with their stability (``multiple_note``). A root is stable
where the averaged equations of amplitude and phase about it are: the force it needs rises
with the amplitude, and the damping ``c = c_s + c_pd`` falls no faster than ``1/X^2``.

Outside the model range (acceleration amplitude or frequency beyond the SDC grid) the solver
refuses with :class:`~pidcore.errors.ParameterError` unless ``clip_to_range=True``, which holds
the SDC at the nearest edge of the grid and flags the point. The scan holds the edge SDC
beyond the range all the same, so it can find roots there; by default they are not the
model's: the largest stable root inside the range is returned, the others named in the note,
and only a response with no root inside the range is refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from ..constants import STANDARD_GRAVITY
from ..errors import ParameterError, as_given, instance_of, real_number, whole_number
from .damper import (
    check_area,
    check_vibrated_mass,
    equivalent_damping_coefficient,
    specimen_area_m2,
    specimen_particles_mass,
)
from .sdc_model import SdcModel

if TYPE_CHECKING:  # a name for the hints only
    from ..specimen import Specimen

#: Points of the log-spaced scan for sign changes of the harmonic-balance residual.
_SCAN_POINTS = 400
#: Relative residual treated as zero (round-off of |D| X / F0).
_ZERO_RESIDUAL = 1e-12
#: Relative slack when deciding whether a solution's acceleration is inside the model range.
_RANGE_RTOL = 1e-9
#: Step in log(X) of the differences that judge a root's stability (pchip is smooth on it).
_STABILITY_STEP = 1e-6
#: Most the particles of the treated area may weigh in the mode (their mass per m^2 of coupon
#: x sum A_i phi_i^2) against its modal mass before the area is refused as a unit slip: a mode
#: carries its particles, and a modal mass given without them may be a few times lighter (2 mm
#: tungsten carbide fills a 0.9 kg panel with 12 x its own mass), while cm^2 typed for m^2 is
#: 1e4 x off (500 for 0.05 m^2: 3830 kg of the paper's particles on a 2 kg mode).
PARTICLE_TO_MODAL_MASS_LIMIT = 100.0


@dataclass(frozen=True, kw_only=True)
class TreatedMode:
    """One mode of a structure treated with particle dampers (SI units).

    Attributes
    ----------
    natural_frequency_hz : float
        Undamped natural frequency f_n [Hz].
    modal_mass_kg : float
        Modal mass m [kg].
    structural_damping_ratio : float
        Viscous damping ratio of the untreated mode zeta_s [-] (loss factor / 2 at resonance),
        in [0, 1): 1 or more (critical: no resonance; 2 for 2 % typed) is refused.
    treated_area_m2 : float
        Area A_t filled with particles [m^2]; without ``treated_regions`` all of it moves with
        the modal coordinate. One whose particles (the coupon's per m^2 of its face at
        ``fill_percent``, :func:`~pidcore.model.damper.specimen_particles_mass`, x sum
        A_i phi_i^2) weigh more than :data:`PARTICLE_TO_MODAL_MASS_LIMIT` x ``modal_mass_kg``
        is refused as a unit slip (cm^2 typed for m^2).
    fill_percent : float
        Fill of the treated cells [%].
    coupon_vibrated_mass_kg : float
        m_c [kg] of the coupon tests the SDC model comes from (Eq. 10), at ``fill_percent``
        and by the convention the SDC was divided by: ``paper_vibrated_mass()(fill_percent)``
        for the paper's Table 3, ``runs_vibrated_mass(runs)(fill_percent)`` for stored DEM
        runs. Not ``coupon_vibrated_mass_kg()`` alone, which leaves the particles out (c_pd
        4.5 x low at 50 % fill). More than
        :data:`~pidcore.model.damper.VIBRATED_MASS_LIMIT` times outside the m_c of
        ``coupon_specimen`` (:func:`~pidcore.model.damper.vibrated_mass_range`: the paper
        coupon's at ``fill_percent``, every convention; another specimen's from its empty
        coupon to its cells full) is refused as a unit slip (grams typed for kg), as
        :func:`~pidcore.model.equivalent_damper_table` refuses it.
    coupon_area_m2 : float, optional
        A_c [m^2] of those coupons; default (None) the area ``pidcore model damper`` takes
        for ``coupon_specimen`` (:func:`~pidcore.model.damper.specimen_area_m2`: the face
        area its file states, the paper's 0.1 m x 0.1 m, else its cells' cross-section), set
        when the mode is made. More than
        :data:`~pidcore.model.damper.AREA_TO_CELLS_LIMIT` times off the cells of
        ``coupon_specimen`` is refused as a unit slip (cm^2 or mm^2 typed for m^2).
    coupon_specimen : pidcore.specimen.Specimen, optional
        Those coupons (default: the paper's; for stored DEM runs
        :func:`~pidcore.model.damper.runs_specimen`), to check ``coupon_area_m2`` and
        ``coupon_vibrated_mass_kg`` against.
    treated_regions : sequence of (area_m2, mode_shape_amplitude), optional
        The treated area split into regions (cells, patches, FE element groups), each with its
        area [m^2] and the mode's amplitude phi_i [-] there, in the scaling the modal mass is
        of (``m = sum m_j phi_j^2`` over the structure: 1 for a mass-normalised shape with
        ``modal_mass_kg=1``). The areas sum to ``treated_area_m2``. Default: one region,
        ``treated_area_m2`` at amplitude 1.
    """

    natural_frequency_hz: float
    modal_mass_kg: float
    structural_damping_ratio: float
    treated_area_m2: float
    fill_percent: float
    coupon_vibrated_mass_kg: float
    coupon_area_m2: float | None = None
    coupon_specimen: Specimen | None = None
    treated_regions: tuple[tuple[float, float], ...] = ()

    def __post_init__(self) -> None:
        from ..specimen import paper_specimen

        if self.coupon_area_m2 is None:
            # the paper's 0.01 m^2 was the default whatever coupon_specimen, while the damper
            # table took another specimen's cells' area: one rule for both
            object.__setattr__(self, "coupon_area_m2", specimen_area_m2(
                self.coupon_specimen or paper_specimen())[0])
        for name in ("natural_frequency_hz", "modal_mass_kg", "structural_damping_ratio",
                     "treated_area_m2", "fill_percent", "coupon_vibrated_mass_kg",
                     "coupon_area_m2"):
            real_number(f"TreatedMode: {name}", getattr(self, name))  # "300" was a TypeError
        for name in ("natural_frequency_hz", "modal_mass_kg", "treated_area_m2",
                     "coupon_vibrated_mass_kg", "coupon_area_m2"):
            v = getattr(self, name)
            if not np.isfinite(v) or v <= 0:
                raise ParameterError(f"TreatedMode: {name} must be finite and > 0, got {v!r}")
        if not (math.isfinite(self.fill_percent) and 0 < self.fill_percent <= 100):
            # 150 was taken, and refused later as a frequency "outside the model range"
            raise ParameterError(f"TreatedMode: fill_percent must be in (0, 100] %, got "
                                 f"{self.fill_percent!r}; was it a fraction or a count?")
        if not np.isfinite(self.structural_damping_ratio) or self.structural_damping_ratio < 0:
            raise ParameterError(f"TreatedMode: structural_damping_ratio must be >= 0, got "
                                 f"{self.structural_damping_ratio!r}")
        if self.structural_damping_ratio >= 1:
            # 2.0 (2 % typed as a percentage) was taken: an over-critical "mode" that does not
            # resonate, its response 100 x damped
            raise ParameterError(
                f"TreatedMode: structural_damping_ratio {as_given(self.structural_damping_ratio)}"
                " is critical damping or more (no resonant mode); expected a fraction of "
                f"critical, e.g. {self.structural_damping_ratio / 100:g} for "
                f"{as_given(self.structural_damping_ratio)} %")
        # 98.8 (g) for m_c = 0.0988 kg gave a c_pd 1000 x too large without a word, or a
        # refusal blaming the force; the damper table refused it
        check_vibrated_mass(self.coupon_vibrated_mass_kg, (self.fill_percent,),
                            what="TreatedMode: coupon_vibrated_mass_kg",
                            specimen=self.coupon_specimen)
        object.__setattr__(self, "treated_regions", self._checked_regions())
        # 100 (cm^2) for A_c = 0.01 m^2 gave a c_pd 1e4 x too small without a word
        check_area(self.coupon_area_m2, self.coupon_specimen or paper_specimen(),
                   "TreatedMode: coupon_area_m2")
        self._check_particles_against_modal_mass()

    def _check_particles_against_modal_mass(self) -> None:
        """Refuse a treated area whose particles weigh more than
        :data:`PARTICLE_TO_MODAL_MASS_LIMIT` times the modal mass in the mode: 500 (cm^2)
        for A_t = 0.05 m^2 gave a c_pd 1e4 x too high without a word."""
        particles = specimen_particles_mass(self.coupon_specimen)(self.fill_percent)
        areal = particles / self.coupon_area_m2
        modal = areal * math.fsum(a * phi**2 for a, phi in self.regions)
        if modal <= PARTICLE_TO_MODAL_MASS_LIMIT * self.modal_mass_kg:
            return
        weighted = " (x phi_i^2 of treated_regions)" if self.treated_regions else ""
        raise ParameterError(
            f"TreatedMode: treated_area_m2 {as_given(self.treated_area_m2)} m^2 carries "
            f"{modal:.3g} kg of particles{weighted} at {as_given(self.fill_percent)} % fill "
            f"({areal:.3g} kg/m^2: the coupon's {particles:.3g} kg over its "
            f"{self.coupon_area_m2:.4g} m^2), {modal / self.modal_mass_kg:.3g} x the modal mass "
            f"{as_given(self.modal_mass_kg)} kg; a mode carries its particles (a modal mass "
            f"given without them may be lighter, not {PARTICLE_TO_MODAL_MASS_LIMIT:g} x "
            "lighter); expected the treated area in m^2 (was it cm^2?) and the modal mass "
            "in kg")

    def _checked_regions(self) -> tuple[tuple[float, float], ...]:
        try:
            regions = tuple((a, phi) for a, phi in self.treated_regions)
        except (TypeError, ValueError):
            raise ParameterError(f"TreatedMode: treated_regions: expected (area_m2, "
                                 f"mode_shape_amplitude) pairs, got "
                                 f"{self.treated_regions!r}") from None
        for k, (area, phi) in enumerate(regions):
            real_number(f"TreatedMode: treated_regions[{k}] area_m2", area)
            real_number(f"TreatedMode: treated_regions[{k}] mode_shape_amplitude", phi)
            if not (math.isfinite(area) and area > 0):
                raise ParameterError(f"TreatedMode: treated_regions[{k}] area_m2 must be "
                                     f"finite and > 0, got {area!r}")
            if not math.isfinite(phi):
                raise ParameterError(f"TreatedMode: treated_regions[{k}] mode_shape_amplitude "
                                     f"must be finite, got {phi!r}")
        if regions and all(phi == 0.0 for _, phi in regions):
            raise ParameterError("TreatedMode: treated_regions: every mode_shape_amplitude is "
                                 "0 (the treated area lies on a node line of the mode); "
                                 "expected the mode to move some treated region")
        if regions:
            total = math.fsum(a for a, _ in regions)
            # the regions split the treated area: a sum off it is a region left out or
            # counted twice (float sums of many cells: 1e-9)
            if not math.isclose(total, self.treated_area_m2, rel_tol=1e-9):
                raise ParameterError(
                    f"TreatedMode: treated_regions' areas sum to {total:g} m^2, but "
                    f"treated_area_m2 is {self.treated_area_m2:g} m^2; expected the regions "
                    "to split the treated area")
        return tuple((float(a), float(phi)) for a, phi in regions)

    @property
    def regions(self) -> tuple[tuple[float, float], ...]:
        """(area [m^2], mode-shape amplitude [-]) of each treated region: ``treated_regions``,
        or the whole treated area at amplitude 1."""
        return self.treated_regions or ((self.treated_area_m2, 1.0),)

    @property
    def mode_shape_note(self) -> str:
        """What the particle damper assumes of the mode shape over the treated area."""
        if not self.treated_regions:
            return (f"the whole treated area ({self.treated_area_m2:g} m^2) moves with the "
                    "modal coordinate (mode-shape amplitude 1 over it): the particle damper "
                    "is not weighted by phi^2; give treated_regions (area, amplitude) where "
                    "the mode shape varies over it")
        amplitudes = [abs(phi) for _, phi in self.treated_regions]
        return (f"{len(self.treated_regions)} treated region(s), mode-shape amplitude "
                f"{min(amplitudes):.3g} .. {max(amplitudes):.3g}: modal particle damper "
                "sum c_i(|phi_i| X) phi_i^2, each region's SDC at its own acceleration")

    @property
    def stiffness_n_m(self) -> float:
        """Modal stiffness k = m w_n^2 [N/m]."""
        return self.modal_mass_kg * (2.0 * np.pi * self.natural_frequency_hz) ** 2

    @property
    def structural_damping_n_s_m(self) -> float:
        """Structural damper c_s = 2 zeta_s m w_n [N s/m]."""
        return (2.0 * self.structural_damping_ratio * self.modal_mass_kg
                * 2.0 * np.pi * self.natural_frequency_hz)


@dataclass(frozen=True)
class HarmonicResponse:
    """Steady harmonic response over a frequency sweep (all arrays share the sweep's shape).

    Attributes
    ----------
    frequency_hz : ndarray
        Drive frequency [Hz].
    amplitude_m : ndarray
        Displacement amplitude X [m] of the modal coordinate (of the treated area where the
        mode gives no ``treated_regions``).
    phase_rad : ndarray
        Phase of the displacement relative to the force [rad] (negative: lagging).
    acceleration_g : ndarray
        Acceleration amplitude w^2 |phi| X [g] at which the SDC was taken, of the treated
        region moving most (largest |phi|; phi = 1 without ``treated_regions``); another
        region's is its |phi_i| / max |phi| times it.
    sdc : ndarray
        SDC [-] used at the solution, of that region.
    particle_damping_n_s_m : ndarray
        Modal c_pd [N s/m] at the solution: sum c_i phi_i^2 over the treated regions.
    amplitude_untreated_m : ndarray
        Amplitude without particles [m], for comparison (inf for a mode without structural
        damping driven at its natural frequency).
    clipped : ndarray of bool
        SDC taken at the edge of the model range (only with ``clip_to_range=True``).
    multiple_solutions : ndarray of bool
        More than one amplitude balances the force (a jump region: which one a structure
        shows depends on where it came from); the largest stable one is reported, inside
        the model's range unless ``clip_to_range=True``, and ``multiple_note`` lists them all.
    sdc_filled : ndarray of bool
        An SDC taken at that frequency (of any treated region) rests on a filled hole of the
        model grid (:meth:`SdcModel.filled_dependence`): the paper's 1000 Hz, 1 g, 90 %
        value, held at the 75 % one, reaches well beyond its own point.
    mode_shape_note : str
        What the particle damper assumed of the mode shape over the treated area
        (:attr:`TreatedMode.mode_shape_note`).
    clipped_note : str
        What the ``clipped`` rows hold and which way that errs ("" where none is clipped):
        below an edge where the model's SDC rises with acceleration (its own slope there)
        the held edge SDC overstates the damping (amplitude understated, not conservative);
        where it falls, understates it. A frequency beyond the model's range is judged
        alike by the model's slope along frequency at its edge; where a slope is flat the
        note says the direction is unknown.
    filled_note : str
        What the ``sdc_filled`` rows rest on and how far their SDC moves per unit of that
        filled value ("" where none does).
    multiple_note : str
        Per ``multiple_solutions`` row, every amplitude balancing the force (as the
        acceleration of ``acceleration_g``), each stable or why not (the averaged equations
        about it: unstable where the force it needs falls as it grows, or where its damping
        falls faster than 1/X^2), those beyond the model's range found with the edge SDC
        held, and which one was returned ("" where no row has several).
    """

    frequency_hz: np.ndarray
    amplitude_m: np.ndarray
    phase_rad: np.ndarray
    acceleration_g: np.ndarray
    sdc: np.ndarray
    particle_damping_n_s_m: np.ndarray
    amplitude_untreated_m: np.ndarray
    clipped: np.ndarray
    multiple_solutions: np.ndarray
    sdc_filled: np.ndarray
    force_amplitude_n: float
    clipped_note: str = ""
    mode_shape_note: str = ""
    filled_note: str = ""
    multiple_note: str = ""

    def to_pandas(self) -> pd.DataFrame:
        """One row per drive frequency, each column naming its unit.

        Columns ``frequency [Hz]``, ``amplitude [m]``, ``phase [rad]``, ``acceleration [g]``,
        ``sdc [-]``, ``particle damping [N s/m]``, ``amplitude untreated [m]``,
        ``clipped [True/False]``, ``multiple solutions [True/False]``, ``sdc filled
        [True/False]``; ``attrs`` hold ``force_amplitude_n``, ``clipped_note``,
        ``mode_shape_note``, ``filled_note`` and ``multiple_note``.
        """
        frame = pd.DataFrame({
            "frequency [Hz]": np.asarray(self.frequency_hz, dtype=float),
            "amplitude [m]": np.asarray(self.amplitude_m, dtype=float),
            "phase [rad]": np.asarray(self.phase_rad, dtype=float),
            "acceleration [g]": np.asarray(self.acceleration_g, dtype=float),
            "sdc [-]": np.asarray(self.sdc, dtype=float),
            "particle damping [N s/m]": np.asarray(self.particle_damping_n_s_m, dtype=float),
            "amplitude untreated [m]": np.asarray(self.amplitude_untreated_m, dtype=float),
            "clipped [True/False]": np.asarray(self.clipped, dtype=bool),
            "multiple solutions [True/False]": np.asarray(self.multiple_solutions, dtype=bool),
            "sdc filled [True/False]": np.asarray(self.sdc_filled, dtype=bool),
        })
        frame.attrs["force_amplitude_n"] = float(self.force_amplitude_n)
        frame.attrs["clipped_note"] = self.clipped_note
        frame.attrs["mode_shape_note"] = self.mode_shape_note
        frame.attrs["filled_note"] = self.filled_note
        frame.attrs["multiple_note"] = self.multiple_note
        return frame

    def plot(self, ax: Any = None) -> Any:
        """Amplitude (and the untreated amplitude) against frequency
        (:func:`pidcore.report.figures_results.plot_harmonic_response`); returns ``ax``."""
        from ..report.figures_results import plot_harmonic_response  # lazy: drawing is optional

        return plot_harmonic_response(self.to_pandas(), ax=ax)


def _check_force(force_amplitude_n: float) -> None:
    # "2" was a TypeError of numpy's isfinite, naming nothing
    if not (math.isfinite(real_number("force_amplitude_n", force_amplitude_n))
            and force_amplitude_n > 0):
        raise ParameterError(f"force_amplitude_n must be finite and > 0, got "
                             f"{force_amplitude_n!r}")


def _sdc_section(model: SdcModel, mode: TreatedMode, frequency_hz: float,
                 clip_to_range: bool, caller: str = "harmonic_response"):
    """SDC as a function of acceleration [g] (clamped to the grid) at this fill and frequency,
    whether the frequency was clamped, and the model's section there (for its slope)."""
    f_lo, f_hi = model.bounds["frequency_hz"]
    inside_f = f_lo * (1 - _RANGE_RTOL) <= frequency_hz <= f_hi * (1 + _RANGE_RTOL)
    if not inside_f and not clip_to_range:
        raise ParameterError(f"{caller}: frequency {as_given(frequency_hz)} Hz outside "
                             f"the SDC model range [{f_lo:g}, {f_hi:g}] Hz; pass "
                             f"clip_to_range=True to hold the edge SDC")
    p_lo, p_hi = model.bounds["fill_percent"]
    if not p_lo * (1 - _RANGE_RTOL) <= mode.fill_percent <= p_hi * (1 + _RANGE_RTOL):
        # a 95 % fill was refused naming the frequency and the whole range dict
        raise ParameterError(f"{caller}: fill_percent {as_given(mode.fill_percent)} % outside "
                             f"the SDC model range [{p_lo:g}, {p_hi:g}] %; the fill is the "
                             "treatment's own: clip_to_range holds acceleration and frequency "
                             "at the model's edge, not the fill")
    section = model.acceleration_section(mode.fill_percent,
                                         float(np.clip(frequency_hz, f_lo, f_hi)))
    a_lo, a_hi = model.bounds["acceleration_g"]

    def sdc(a_g: np.ndarray) -> np.ndarray:
        return section(np.clip(a_g, a_lo, a_hi))

    return sdc, (not inside_f), section


def _held_edge_error(section, acceleration_g: float, bounds: tuple[float, float]
                     ) -> tuple[str, str, float]:
    """(where, which way, slope per g) of holding the edge SDC at an acceleration beyond the
    model's range, from the model's own slope at that edge; ("", "", nan) inside it."""
    a_lo, a_hi = bounds
    if a_lo * (1 - _RANGE_RTOL) <= acceleration_g <= a_hi * (1 + _RANGE_RTOL):
        return "", "", math.nan
    below = acceleration_g < a_lo
    edge = a_lo if below else a_hi
    slope = float(section.derivative()(edge))
    where = f"{'below' if below else 'above'} the model's {edge:g} g edge"
    if not math.isfinite(slope) or slope == 0:
        return where, (f"where its SDC is flat: holding the {edge:g} g SDC errs in a "
                       "direction the model does not tell"), slope
    # the way a continuation of the edge's own trend goes: lower below a rising edge
    rises = slope > 0
    if rises == below:
        way = (f"where its SDC {'rises' if rises else 'falls'} with acceleration: holding the "
               f"{edge:g} g SDC overstates the damping there (amplitude understated: not "
               "conservative)")
    else:
        way = (f"where its SDC {'rises' if rises else 'falls'} with acceleration: holding the "
               f"{edge:g} g SDC understates the damping there (amplitude overstated: "
               "conservative)")
    return where, way, slope


#: What holding an SDC that errs this way (:data:`~pidcore.model.sdc_model.HELD_ERRORS`)
#: does to the response.
_HELD_CONSEQUENCE = {
    "overstated": "overstates the damping there (amplitude understated: not conservative)",
    "understated": "understates the damping there (amplitude overstated: conservative)",
}


def _held_frequency_error(model: SdcModel, fill_percent: float, acceleration_g: float,
                          frequency_hz: float) -> str:
    """The clause of a frequency beyond the model's range: the edge held and which way that
    errs by the model's slope along frequency there; "" inside the range."""
    edges = [e for e in model.held_edges(fill_percent, acceleration_g, frequency_hz)
             if e.axis == "frequency_hz"]
    if not edges:
        return ""
    (edge,) = edges
    f_lo, f_hi = model.bounds["frequency_hz"]
    held = (f"frequency outside the model's [{f_lo:g}, {f_hi:g}] Hz, the {edge.edge:g} Hz SDC "
            f"held (model slope there {edge.slope:+.3g} per Hz)")
    if edge.error == "unknown":
        return (f"{held}, where its SDC is flat in frequency: holding it errs in a direction "
                "the model does not tell")
    trend = "rises" if edge.slope > 0 else "falls"
    return (f"{held}, where its SDC {trend} with frequency: holding it "
            f"{_HELD_CONSEQUENCE[edge.error]}")


def _span(values: list[float], fmt: str) -> str:
    low, high = min(values), max(values)
    return format(low, fmt) if format(low, fmt) == format(high, fmt) \
        else f"{format(low, fmt)} .. {format(high, fmt)}"


def _clipped_note(rows: list[tuple[float, float, str, str, str, float]]) -> str:
    """One line for the clipped rows (frequency, acceleration, the clause of a frequency held
    (:func:`_held_frequency_error`), and :func:`_held_edge_error`'s where, which way, slope),
    grouped by edge and direction; "" where none is clipped."""
    groups: dict[tuple[str, str, str], list[tuple[float, float, float]]] = {}
    for f, acc, frequency_held, where, way, slope in rows:
        groups.setdefault((frequency_held, where, way), []).append((f, acc, slope))
    parts = []
    for (frequency_held, where, way), members in groups.items():
        clauses = []
        if frequency_held:
            # a 2000 Hz row said only that its 1000 Hz SDC was held, not which way that errs
            clauses.append(frequency_held)
        if where:
            clauses.append(f"response {_span([m[1] for m in members], '.3g')} g {where} "
                           f"(model slope there {_span([m[2] for m in members], '+.3g')} per "
                           f"g), {way}")
        parts.append(f"{_span([m[0] for m in members], 'g')} Hz ({len(members)} row(s)): "
                     + "; ".join(clauses))
    return "; ".join(parts)


def _filled(model: SdcModel, fill_percent: float, points: list[tuple[float, float, float]]
            ) -> tuple[np.ndarray, str]:
    """Per (frequency [Hz], acceleration [g], row) at which an SDC was taken: whether its row
    rests on a filled hole of the model's grid, and the note saying which and how far the SDC
    moves with it ("" where none does). Frequency and acceleration are held at the grid's
    edge as the SDC took them."""
    rows = max((int(r) for _, _, r in points), default=-1) + 1
    flagged = np.zeros(rows, dtype=bool)
    if not points:
        return flagged, ""
    f, acc, row = (np.array(c) for c in zip(*points, strict=True))
    dependence = model.filled_dependence(fill_percent, acc, f, clip_to_range=True)
    np.logical_or.at(flagged, row.astype(int), dependence.any)
    if not flagged.any():
        return flagged, ""
    frequencies = sorted({float(x) for x, on in zip(f, dependence.any, strict=True) if on})
    return flagged, (f"{_span(frequencies, 'g')} Hz ({int(flagged.sum())} row(s)): "
                     + dependence.summary().replace("point(s)", "SDC(s) taken"))


def particle_damping_n_s_m(sdc: np.ndarray | float, mode: TreatedMode,
                           frequency_hz: float, *, area_m2: float | None = None) -> np.ndarray:
    """c_pd [N s/m] of the treated area (or of ``area_m2`` of it) for a given SDC, on that
    area's own velocity (module docstring)."""
    per_area = equivalent_damping_coefficient(
        sdc, vibrated_mass_kg=mode.coupon_vibrated_mass_kg,
        frequency_hz=frequency_hz) / mode.coupon_area_m2
    return per_area * (mode.treated_area_m2 if area_m2 is None else area_m2)


def _modal_particle_damping(mode: TreatedMode, sdc_of, frequency_hz: float, x: np.ndarray
                            ) -> np.ndarray:
    """Modal c_pd [N s/m] at modal amplitude ``x``: sum over the treated regions of their
    damper at their own acceleration w^2 |phi_i| x, times phi_i^2 (module docstring)."""
    w = 2.0 * np.pi * frequency_hz
    total = 0.0
    for area, phi in mode.regions:
        if phi == 0.0:  # a region on a node line neither moves nor damps the mode
            continue
        sdc = sdc_of(w**2 * abs(phi) * x / STANDARD_GRAVITY)
        total = total + particle_damping_n_s_m(sdc, mode, frequency_hz, area_m2=area) * phi**2
    return np.asarray(total, dtype=float)


def _largest_amplitude(mode: TreatedMode) -> float:
    """max |phi_i| over the treated regions: the region whose acceleration leaves the model's
    range first above it (1 without regions)."""
    return max(abs(phi) for _, phi in mode.regions)


def _smallest_moving_amplitude(mode: TreatedMode) -> float:
    """min |phi_i| > 0: the region whose acceleration leaves the model's range first below it
    (a region at phi = 0 takes no SDC)."""
    moving = [abs(phi) for _, phi in mode.regions if phi != 0.0]
    return min(moving) if moving else math.nan


@dataclass(frozen=True)
class _SteadyRoot:
    """One amplitude that balances the force (:func:`_balance_roots`)."""

    log_x: float
    #: acceleration [g] of the treated region moving most
    acceleration_g: float
    #: the regions' accelerations [g] outside the model's range (the SDC held there)
    outside: list[float]
    #: "" where stable, else why not
    unstable: str

    @property
    def stable(self) -> bool:
        return not self.unstable


def _balance_roots(model: SdcModel, mode: TreatedMode, sdc_of, f: float,
                   force_amplitude_n: float, caller: str = "harmonic_response"
                   ) -> tuple[list[_SteadyRoot], float]:
    """Every amplitude that balances the force at ``f`` (module docstring), ascending, with
    its stability, and the amplitude without particles."""
    k, m, c_s = mode.stiffness_n_m, mode.modal_mass_kg, mode.structural_damping_n_s_m
    w = 2.0 * np.pi * f

    def damping(x: np.ndarray) -> np.ndarray:
        return c_s + _modal_particle_damping(mode, sdc_of, f, x)

    def residual(log_x: np.ndarray) -> np.ndarray:
        x = np.exp(log_x)
        return x * np.abs(k - m * w**2 + 1j * w * damping(x)) / force_amplitude_n - 1.0

    with np.errstate(divide="ignore"):  # undamped at its natural frequency: inf
        x_untreated = force_amplitude_n / abs(k - m * w**2 + 1j * w * c_s)
    sdc_max, sdc_min = float(np.max(model.values)), float(np.min(model.values))
    c_max, c_min = (float(_modal_particle_damping(mode, lambda _a, s=s: np.asarray(s), f,
                                                  np.asarray(1.0)))
                    for s in (max(sdc_max, 0.0), max(sdc_min, 0.0)))
    # the least damping the model can give bounds the amplitude from above: with no
    # structural damping at the natural frequency the untreated bound was 1/0, and the
    # scan from it ran on NaN ("response acceleration nan g")
    lightest = abs(k - m * w**2 + 1j * w * (c_s + c_min))
    if lightest == 0.0:
        raise ParameterError(
            f"{caller}: at {f:g} Hz (the natural frequency) nothing bounds the "
            "response: structural_damping_ratio is 0 and the SDC model reaches 0; give "
            "the mode's structural damping ratio (> 0)")
    x_hi = force_amplitude_n / lightest
    x_lo = force_amplitude_n / abs(k - m * w**2 + 1j * w * (c_s + c_max))
    if x_hi <= x_lo * (1 + 1e-14):
        roots = [np.log(x_hi)]
    else:
        grid = np.linspace(np.log(x_lo), np.log(x_hi), _SCAN_POINTS)
        r = residual(grid)
        # the residual is relative to F0: |r| below round-off is a root on the scan grid
        # (e.g. at x_hi when the SDC is 0 there)
        zero = np.abs(r) <= _ZERO_RESIDUAL
        roots = list(grid[zero])
        for j in np.flatnonzero((np.sign(r[:-1]) * np.sign(r[1:]) < 0)
                                & ~zero[:-1] & ~zero[1:]):
            roots.append(brentq(residual, grid[j], grid[j + 1], xtol=1e-14, rtol=1e-13))
        if not roots:  # residual >= 0 at x_lo within round-off: the bracket edge is the root
            roots = [grid[int(np.argmin(np.abs(r)))]]
    a_lo, a_hi = model.bounds["acceleration_g"]
    phi_top, phi_low = _largest_amplitude(mode), _smallest_moving_amplitude(mode)
    found: list[_SteadyRoot] = []
    # roots closer than 1e-9 in log(X) are one root found twice (the largest of them kept)
    for log_x in sorted(roots, reverse=True):
        if found and round(float(log_x), 9) == round(found[-1].log_x, 9):
            continue
        x = float(np.exp(log_x))
        acc = w**2 * phi_top * x / STANDARD_GRAVITY
        # the regions moving most and least take the highest and lowest accelerations
        extremes = sorted({acc, w**2 * phi_low * x / STANDARD_GRAVITY})
        outside = [a for a in extremes
                   if not a_lo * (1 - _RANGE_RTOL) <= a <= a_hi * (1 + _RANGE_RTOL)]
        # the averaged (slow-flow) equations of a', theta' about the root: their Jacobian's
        # determinant has the sign of d(force)/dX, its trace that of -(2 c + dc/dln X)
        steps = float(log_x) + np.array([-_STABILITY_STEP, _STABILITY_STEP])
        force_slope = float(np.diff(residual(steps))[0])
        c_here = float(damping(np.array(x)))
        c_slope = float(np.diff(damping(np.exp(steps)))[0]) / (2 * _STABILITY_STEP)
        unstable = ("" if force_slope > 0 and 2 * c_here + c_slope > 0
                    else "unstable: the force it needs falls as it grows" if force_slope <= 0
                    else "unstable: its damping falls faster than 1/X^2, the amplitude "
                         "oscillates away from it")
        found.append(_SteadyRoot(log_x=float(log_x), acceleration_g=acc, outside=outside,
                                 unstable=unstable))
    return found[::-1], x_untreated


def _chosen_root(roots: list[_SteadyRoot], clip_to_range: bool) -> _SteadyRoot:
    """The root returned: the largest stable one (conservative), inside the model's range
    unless ``clip_to_range``; where none is stable, the largest; where none is inside, the
    largest of all (refused by the caller)."""
    candidates = roots if clip_to_range else [r for r in roots if not r.outside]
    if not candidates:
        return roots[-1]
    return ([r for r in candidates if r.stable] or candidates)[-1]


def _multiple_note(roots: list[_SteadyRoot], model: SdcModel, f: float,
                   clip_to_range: bool) -> str:
    """The steady amplitudes at ``f``, each with its stability and whether the SDC was held
    beyond the model's edge to find it."""
    a_lo, a_hi = model.bounds["acceleration_g"]
    held = (f"beyond the model's [{a_lo:g}, {a_hi:g}] g, found with the edge SDC held"
            + ("" if clip_to_range else ": the model does not tell whether it exists "
               "(clip_to_range=True takes it)"))
    described = [f"{r.acceleration_g:.3g} g ({r.unstable or 'stable'}"
                 + (f"; {held})" if r.outside else ")") for r in roots]
    return f"{f:g} Hz: {len(roots)} steady amplitudes balance the force, {', '.join(described)}"


def harmonic_response(model: SdcModel, mode: TreatedMode, *, frequencies_hz: np.ndarray,
                      force_amplitude_n: float, clip_to_range: bool = False
                      ) -> HarmonicResponse:
    """Steady response amplitude and phase by first-order harmonic balance.

    Parameters
    ----------
    model : SdcModel
        SDC model (fill [%], acceleration [g], frequency [Hz]).
    mode : TreatedMode
        The treated mode.
    frequencies_hz : array_like
        Drive frequencies [Hz].
    force_amplitude_n : float
        F0 [N] of the force ``F0 cos(w t)`` on the modal mass.
    clip_to_range : bool
        Hold SDC at the model's edge where the solution leaves its range instead of raising.

    Returns
    -------
    HarmonicResponse
    """
    instance_of("model", model, SdcModel, hint="e.g. SdcModel.from_table(load_paper_table3())")
    instance_of("mode", mode, TreatedMode)
    _check_force(force_amplitude_n)
    freqs = np.atleast_1d(np.asarray(frequencies_hz, dtype=float))
    if not np.all(np.isfinite(freqs)) or np.any(freqs <= 0):
        raise ParameterError("frequencies_hz must be finite and > 0")
    k, m, c_s = mode.stiffness_n_m, mode.modal_mass_kg, mode.structural_damping_n_s_m
    a_lo, a_hi = model.bounds["acceleration_g"]
    out = {name: np.empty(freqs.shape) for name in
           ("x", "phase", "acc", "sdc", "c_pd", "x0")}
    clipped = np.zeros(freqs.shape, dtype=bool)
    multiple = np.zeros(freqs.shape, dtype=bool)
    # a 0.3 g response took the 1 g SDC, flagged but not which way that errs
    clip_rows: list[tuple[float, float, str, str, str, float]] = []
    # several steady amplitudes at one frequency: the one returned was picked without a word
    multiple_rows: list[str] = []
    phi_top = _largest_amplitude(mode)
    f_lo, f_hi = model.bounds["frequency_hz"]
    # (frequency, acceleration, row) of every SDC taken at a solution, for _filled
    taken: list[tuple[float, float, float]] = []
    for i, f in enumerate(freqs):
        w = 2.0 * np.pi * f
        sdc_of, freq_clipped, section = _sdc_section(model, mode, f, clip_to_range)
        roots, x_untreated = _balance_roots(model, mode, sdc_of, f, force_amplitude_n)
        root = _chosen_root(roots, clip_to_range)
        x = float(np.exp(root.log_x))
        multiple[i] = len(roots) > 1
        if multiple[i]:
            chosen = ("none is stable: the largest" if not root.stable
                      else "the largest stable one" + ("" if clip_to_range
                                                       else " inside the model's range"))
            if any(r.stable and r.outside and r.log_x > root.log_x for r in roots):
                chosen += ", not conservative: a larger stable one lies beyond the range"
            multiple_rows.append(f"{_multiple_note(roots, model, f, clip_to_range)}; "
                                 f"{root.acceleration_g:.3g} g returned ({chosen})")
        acc = w**2 * phi_top * x / STANDARD_GRAVITY
        outside = root.outside
        if outside and not clip_to_range:
            which = "" if len(mode.regions) == 1 else (
                " of the treated region moving " + ("most" if outside[-1] == acc else "least"))
            raise ParameterError(
                f"harmonic_response: at {f:g} Hz the response acceleration{which} "
                f"{outside[-1]:.3g} g is outside the SDC model range [{a_lo:g}, {a_hi:g}] g; "
                "change the force or pass clip_to_range=True to hold the edge SDC")
        clipped[i] = bool(outside) or freq_clipped
        for held_acc in outside or ([acc] if freq_clipped else []):
            clip_rows.append((float(f), float(held_acc),
                              _held_frequency_error(model, mode.fill_percent,
                                                    float(np.clip(held_acc, a_lo, a_hi)), f),
                              *_held_edge_error(section, held_acc, (a_lo, a_hi))))
        taken.extend((float(np.clip(f, f_lo, f_hi)),
                      float(np.clip(w**2 * abs(phi) * x / STANDARD_GRAVITY, a_lo, a_hi)), i)
                     for _, phi in mode.regions if phi != 0.0)
        cp = float(_modal_particle_damping(mode, sdc_of, f, np.array(x)))
        out["x"][i] = x
        out["phase"][i] = -np.angle(k - m * w**2 + 1j * w * (c_s + cp))
        out["acc"][i] = acc
        out["sdc"][i] = float(sdc_of(np.array(acc)))
        out["c_pd"][i] = cp
        out["x0"][i] = x_untreated
    sdc_filled, filled_note = _filled(model, mode.fill_percent, taken)
    return HarmonicResponse(frequency_hz=freqs, amplitude_m=out["x"], phase_rad=out["phase"],
                            acceleration_g=out["acc"], sdc=out["sdc"],
                            particle_damping_n_s_m=out["c_pd"],
                            amplitude_untreated_m=out["x0"], clipped=clipped,
                            multiple_solutions=multiple, sdc_filled=sdc_filled,
                            force_amplitude_n=float(force_amplitude_n),
                            clipped_note=_clipped_note(clip_rows),
                            mode_shape_note=mode.mode_shape_note, filled_note=filled_note,
                            multiple_note="; ".join(multiple_rows))


@dataclass(frozen=True)
class TimeDomainSteadyState:
    """Steady state of the time integration: fundamental amplitude [m] and phase [rad].

    ``clipped``: the frequency or the steady acceleration amplitude lies outside the SDC
    model's range and the edge SDC was held there (only with ``clip_to_range=True``);
    ``clipped_note`` says which way that errs, as :attr:`HarmonicResponse.clipped_note`.
    ``sdc_filled`` and ``filled_note``: the steady SDC rests on a filled hole of the model's
    grid, as :attr:`HarmonicResponse.sdc_filled` and ``filled_note``.
    ``multiple_solutions`` and ``multiple_note``: harmonic balance has several steady
    amplitudes at this frequency (as :attr:`HarmonicResponse.multiple_note`); the one
    integrated from rest is one of them, another start can settle on another.
    """

    frequency_hz: float
    amplitude_m: float
    phase_rad: float
    peak_amplitude_m: float
    settle_time_s: float
    clipped: bool = False
    clipped_note: str = ""
    sdc_filled: bool = False
    filled_note: str = ""
    multiple_solutions: bool = False
    multiple_note: str = ""


def time_domain_response(model: SdcModel, mode: TreatedMode, *, frequency_hz: float,
                         force_amplitude_n: float, settle_cycles: int | None = None,
                         measure_cycles: int = 10, rtol: float = 1e-9,
                         clip_to_range: bool = False) -> TimeDomainSteadyState:
    """Integrate the same nonlinear oscillator in time from rest; measure its steady state.

    The damper force is ``c_pd(A(t), w) * v`` with the instantaneous amplitude
    ``A = sqrt(x^2 + (v / w)^2)``, which equals X in steady harmonic motion. The harmonic-balance
    solution is therefore an exact periodic solution of this ODE; the comparison checks the
    root finding, the assembly of c_pd from the model and the units, and that the solution
    is the one the system settles on from rest (where harmonic balance has several, the
    result's ``multiple_note`` lists them). It does not check the equivalent-damper idea
    against DEM. SDC is held at the model edge while A(t) is outside the range (transients);
    a frequency, or a steady acceleration amplitude, outside the model range is refused as
    :func:`harmonic_response` refuses it, unless ``clip_to_range=True`` (then flagged
    ``clipped``).

    ``settle_cycles`` defaults to 8 decay time constants of the lightest possible damping
    (structural only), in drive cycles.
    """
    instance_of("model", model, SdcModel, hint="e.g. SdcModel.from_table(load_paper_table3())")
    instance_of("mode", mode, TreatedMode)
    _check_force(force_amplitude_n)
    # settle_cycles=-1 measured the transient from rest as the steady state; measure_cycles=0
    # was numpy's "need at least one array"; rtol=nan integrated for ever
    measure_cycles = whole_number("measure_cycles", measure_cycles)
    if measure_cycles < 1:
        raise ParameterError(f"measure_cycles: expected >= 1, got {measure_cycles}")
    if settle_cycles is not None:
        settle_cycles = whole_number("settle_cycles", settle_cycles)
        if settle_cycles < 0:
            raise ParameterError(f"settle_cycles: expected >= 0 (or None), got {settle_cycles}")
    if not (math.isfinite(real_number("rtol", rtol)) and rtol > 0):
        raise ParameterError(f"rtol: expected a finite relative tolerance > 0, got {rtol!r}")
    # 0 Hz was a ZeroDivisionError, "300" a TypeError of numpy, naming nothing
    if not (math.isfinite(real_number("frequency_hz", frequency_hz)) and frequency_hz > 0):
        raise ParameterError(f"frequency_hz: expected a finite frequency > 0 Hz, got "
                             f"{frequency_hz!r}")
    if not isinstance(clip_to_range, (bool, np.bool_)):
        raise ParameterError(f"clip_to_range: expected True or False, got {clip_to_range!r}")
    frequency_hz = float(frequency_hz)
    w = 2.0 * np.pi * frequency_hz
    k, m, c_s = mode.stiffness_n_m, mode.modal_mass_kg, mode.structural_damping_n_s_m
    # 2000 Hz ran on the 1000 Hz SDC without a word, though harmonic_response refused it
    sdc_of, frequency_clipped, section = _sdc_section(model, mode, frequency_hz,
                                                      clip_to_range, "time_domain_response")
    # 5.48 g from rest was returned alone where 9.88 g (unstable) and one beyond 10 g also
    # balance the force: which one settles depends on the start
    roots, _ = _balance_roots(model, mode, sdc_of, frequency_hz, force_amplitude_n,
                              "time_domain_response")
    wn = 2.0 * np.pi * mode.natural_frequency_hz
    if settle_cycles is None:
        zeta = max(mode.structural_damping_ratio, 1e-3)
        settle_cycles = int(np.ceil(8.0 / (zeta * wn) * frequency_hz))
    period = 1.0 / frequency_hz
    t_settle = settle_cycles * period
    t_end = t_settle + measure_cycles * period

    # c_pd is proportional to the SDC: its factor once, not its checks at every evaluation
    # (tens of thousands per integration)
    # per region: its modal damper per unit SDC (c_i phi_i^2) and |phi_i|
    regions = [(float(particle_damping_n_s_m(1.0, mode, frequency_hz, area_m2=area)) * phi**2,
                abs(phi)) for area, phi in mode.regions if phi != 0.0]

    def rhs(t: float, y: np.ndarray) -> list[float]:
        x, v = y
        amp = np.sqrt(x * x + (v / w) ** 2)
        c = c_s
        for c_per_sdc, phi in regions:
            c += c_per_sdc * float(sdc_of(np.array(w**2 * phi * amp / STANDARD_GRAVITY)))
        return [v, (force_amplitude_n * np.cos(w * t) - c * v - k * x) / m]

    x_scale = force_amplitude_n / k
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, 0.0], method="DOP853", rtol=rtol,
                    atol=[1e-12 * x_scale, 1e-12 * x_scale * w], dense_output=True,
                    max_step=period / 8)
    if not sol.success:
        raise ParameterError(f"time_domain_response: integration failed: {sol.message}")
    t = np.linspace(t_settle, t_end, measure_cycles * 256, endpoint=False)
    x = sol.sol(t)[0]
    # fundamental by projection over whole cycles: x ~ X cos(w t + phase)
    coef = 2.0 * np.mean(x * np.exp(-1j * w * t))
    # a steady state at 817 g was returned as if the model held a damper there
    acceleration_g = w**2 * _largest_amplitude(mode) * float(abs(coef)) / STANDARD_GRAVITY
    a_lo, a_hi = model.bounds["acceleration_g"]
    lowest = w**2 * _smallest_moving_amplitude(mode) * float(abs(coef)) / STANDARD_GRAVITY
    if lowest < a_lo * (1 - _RANGE_RTOL):  # the region moving least is the one below
        acceleration_g = lowest
    acceleration_outside = not (a_lo * (1 - _RANGE_RTOL) <= acceleration_g
                                <= a_hi * (1 + _RANGE_RTOL))
    if acceleration_outside and not clip_to_range:
        raise ParameterError(
            f"time_domain_response: at {as_given(frequency_hz)} Hz the steady acceleration "
            f"{acceleration_g:.3g} g is outside the SDC model range [{a_lo:g}, {a_hi:g}] g; "
            "change the force or pass clip_to_range=True to hold the edge SDC")
    f_lo, f_hi = model.bounds["frequency_hz"]
    sdc_filled, filled_note = _filled(
        model, mode.fill_percent,
        [(float(np.clip(frequency_hz, f_lo, f_hi)),
          float(np.clip(w**2 * phi * float(abs(coef)) / STANDARD_GRAVITY, a_lo, a_hi)), 0)
         for _, phi in regions])
    return TimeDomainSteadyState(frequency_hz=frequency_hz, amplitude_m=float(abs(coef)),
                                 phase_rad=float(np.angle(coef)),
                                 peak_amplitude_m=float(0.5 * (x.max() - x.min())),
                                 settle_time_s=float(t_settle),
                                 clipped=bool(acceleration_outside or frequency_clipped),
                                 clipped_note=_clipped_note(
                                     [(frequency_hz, acceleration_g,
                                       _held_frequency_error(
                                           model, mode.fill_percent,
                                           float(np.clip(acceleration_g, a_lo, a_hi)),
                                           frequency_hz),
                                       *_held_edge_error(section, acceleration_g,
                                                         (a_lo, a_hi)))]
                                     if acceleration_outside or frequency_clipped else []),
                                 sdc_filled=bool(sdc_filled.any()), filled_note=filled_note,
                                 multiple_solutions=len(roots) > 1,
                                 multiple_note=(
                                     f"{_multiple_note(roots, model, frequency_hz, clip_to_range)}"
                                     f"; this integration from rest settled on "
                                     f"{acceleration_g:.3g} g, another start can settle on "
                                     "another" if len(roots) > 1 else ""))
