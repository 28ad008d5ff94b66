"""Complex input power, loss factor and specific damping capacity of a shaker record (Eq. 8-11).

Conventions
-----------
A periodic signal is written with one-sided phasors, ``x(t) = x_0 + sum_n Re(X_n exp(j n w t))``.
The complex power is

    P_c = 1/2 sum_n F_n conj(V_n)

summed over the harmonics fitted in both channels. The printed Eq. 11 of the paper omits the
conjugate; without it the time average of the product would not be the power. With it,
``Re(P_c)`` is the time average of ``f(t) v(t)``, the mean power flowing *into* the structure
(> 0 for a damper), and ``Im(P_c)`` the reactive power: a rigid mass, ``F_n = j n w m V_n``,
gives ``Im(P_c) = 1/2 w m |V_1|^2 > 0`` (inertance); a spring gives ``Im(P_c) < 0``.

From ``P_c`` (``T = 1/f``, ``w = 2 pi f``):

* energy dissipated per cycle ``dE = Re(P_c) T``;
* maximum kinetic energy ``E = Im(P_c) / w`` -- for a rigid mass driven by a sine,
  ``Im(P_c)/w = 1/2 m |V_1|^2 = m a^2/(2 w^2)``, which is Eq. 10; for a measurement it is the
  kinetic energy of the mass that the gauge actually drives, without having to know it;
* loss factor ``eta_l = Re(P_c)/Im(P_c) = dE / (2 pi E)``;
* SDC (Eq. 8) ``psi = dE/E = 2 pi eta_l``;
* equivalent viscous damping ratio ``zeta = -ln(1 - psi) / (4 pi)`` (paper Sect. 3), defined
  only for ``0 <= psi < 1``.

Drift: the phasors are least-squares fits of the harmonics beside a drift model
(:mod:`pidcore.signal.harmonics`): a cubic spline with knots every
:data:`~pidcore.defaults.DRIFT_KNOT_PERIODS` whole periods. A slow wander (a shaker table at
0.3-1 Hz under its control loop, a vibrometer's drift) is no line over a record of seconds,
and the one DC and trend over the record that pidcore fitted before leaked the rest into the
harmonics (5 % of the amplitudes at 0.3-1 Hz moved the loss factor of a 2 s, 100 Hz record by up
to 1e-4, more than ten standard errors at 60 dB); the spline follows it, and being smooth takes up
nothing near the harmonics (docs/measurement.md). The blocks of the standard error keep their
own DC and trend, as before. A record of fewer than two knot spaces, or analysed without
blocks (``n_blocks`` < 2: the DEM's observations of a calibration), keeps one DC and linear
trend over the record (noted where there are blocks); ``corrections["drift_model"]`` says
which.

Corrections (applied to the phasors in this order):

1. ``velocity_delay_s``: a laser vibrometer outputs ``v(t - tau)``; its phasors are multiplied by
   ``exp(+j n w tau)``. ``start_offset_delay_s`` (a motion channel sampled a fraction of a
   sample off the force's instants) adds to that ``tau`` and is corrected by the same factor,
   on the velocity channel or, without one, on the acceleration the velocity comes from.
   ``acceleration_start_offset_delay_s`` is the same for an acceleration channel beside a
   velocity channel (the one mass cancellation takes), by the same factor on its phasors; the
   vibrometer's delay is not its.
2. Velocity from acceleration when there is no velocity channel: ``V_n = A_n / (j n w)``.
3. Mass cancellation: the gauge also feels the inertia of the mass between it and the coupon
   (impedance-head seismic mass, fixture): ``F_n -= m_below A_n`` with ``A_n`` from the
   acceleration channel when there is one (corrected by correction 1), else ``j n w V_n``.
4. Baseline subtraction: the empty structure (coupon and fixture, measured the same way)
   dissipates ``eta_baseline`` of its *own* reactive power, ``Q_s = sum_n 1/2 n w m_s |V_n|^2``
   for its mass ``m_s`` (``structure_mass_kg``), so ``eta_baseline Q_s`` is taken off
   ``Re(P_c)``: ``eta_l = (Re P_c - eta_baseline Q_s) / Im P_c``, and so are the SDC and the
   energy per cycle. Without ``m_s`` the whole reactive power stands for ``Q_s``
   (``eta_l - eta_baseline``), which takes off too much by ``eta_baseline`` times the particles'
   share of the vibrated mass; the result says so in a note. ``complex_power_w`` stays the
   measured (corrections 1-3) value.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pandas as pd

from .. import defaults
from ..constants import STANDARD_GRAVITY
from ..errors import ChannelError, ParameterError, SignalError, as_given, real_number
from ..loop import ForceDisplacementLoop
from ..records import Channel
from . import validate
from .frequency import estimate_drive_frequency
from .harmonics import HarmonicFit, fit_harmonics, fit_parameter_count


@dataclass(frozen=True)
class PowerAnalysis:
    """Result of :func:`analyze_power`: phasors, complex power and damping measures (SI units).

    Attributes
    ----------
    source : str
        Record the result belongs to.
    frequency_hz : float
        Estimated drive frequency, Hz.
    omega_rad_s : float
        Drive angular frequency, rad/s.
    n_periods : float
        Drive periods in the record.
    sample_rate_hz : float
        Sample rate, Hz.
    harmonics : numpy.ndarray of int
        Harmonic orders fitted (1..H, those below 0.9 x Nyquist).
    force_phasors_n : numpy.ndarray of complex
        F_n after mass cancellation, N.
    velocity_phasors_m_s : numpy.ndarray of complex
        V_n after delay correction (or from acceleration), m/s.
    complex_power_w : complex
        ``1/2 sum F_n conj(V_n)``, W (before baseline subtraction).
    loss_factor, loss_factor_stderr : float
        Loss factor (baseline subtracted) and its standard error (NaN when not available).
    loss_factor_raw : float
        Loss factor before baseline subtraction.
    sdc, sdc_stderr : float
        Specific damping capacity ``2 pi loss_factor`` and its standard error.
    damping_ratio : float or None
        ``-ln(1 - sdc)/(4 pi)``; None when undefined, see ``damping_ratio_note``.
    damping_ratio_note : str
        Why ``damping_ratio`` is None (empty otherwise).
    energy_per_cycle_j : float
        Dissipated energy per cycle, J (baseline subtracted).
    max_kinetic_energy_j : float
        ``Im(P_c)/omega``, J.
    force_amplitude_n, velocity_amplitude_m_s : float
        Fundamental amplitudes |F_1|, |V_1|.
    acceleration_amplitude_m_s2 : float
        ``omega |V_1|``, m/s^2.
    displacement_amplitude_m : float
        ``|V_1| / omega``, m.
    n_blocks : int
        Blocks used for the standard errors (0 when none).
    uncertainty_note : str
        Why the standard errors are NaN (empty otherwise).
    corrections : dict
        Corrections applied and their values.
    notes : tuple of str
        Lines to read beside the numbers: the damping-ratio and uncertainty notes, and channels
        analysed although clipped (``allow_clipped``).
    """

    source: str
    frequency_hz: float
    omega_rad_s: float
    n_periods: float
    sample_rate_hz: float
    harmonics: np.ndarray
    force_phasors_n: np.ndarray
    velocity_phasors_m_s: np.ndarray
    complex_power_w: complex
    loss_factor: float
    loss_factor_stderr: float
    loss_factor_raw: float
    sdc: float
    sdc_stderr: float
    damping_ratio: float | None
    damping_ratio_note: str
    energy_per_cycle_j: float
    max_kinetic_energy_j: float
    force_amplitude_n: float
    velocity_amplitude_m_s: float
    acceleration_amplitude_m_s2: float
    displacement_amplitude_m: float
    n_blocks: int
    uncertainty_note: str
    corrections: dict[str, Any] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    @property
    def sdc_stderr_dof(self) -> float:
        """Degrees of freedom of :attr:`sdc_stderr` (and :attr:`loss_factor_stderr`):
        ``n_blocks - 1``, the scatter of n_blocks block estimates about their mean, so
        (estimate - truth) / stderr is Student's t with them (a 95 % band takes t's quantile,
        2.365 for 8 blocks, not 1.96); NaN where there is no standard error."""
        if self.n_blocks >= 2 and math.isfinite(self.sdc_stderr):
            return float(self.n_blocks - 1)
        return math.nan

    @property
    def acceleration_g(self) -> float:
        """Fundamental acceleration amplitude in g (standard gravity)."""
        return self.acceleration_amplitude_m_s2 / STANDARD_GRAVITY

    @property
    def period_s(self) -> float:
        """Drive period, s."""
        return 1.0 / self.frequency_hz

    def loop(self, n_points: int = defaults.LOOP_POINTS, *,
             label: str | None = None) -> ForceDisplacementLoop:
        """One period of the reconstructed force-displacement loop (harmonic synthesis).

        ``n_points`` equally spaced phases; DC is left out. The loop's area
        (``energy_per_cycle_j``) equals ``complex_power_w.real * period_s`` (the energy per
        cycle before baseline subtraction). ``label`` defaults to :attr:`source`.
        """
        return ForceDisplacementLoop.from_phasors(
            self.harmonics, self.force_phasors_n, self.velocity_phasors_m_s, self.frequency_hz,
            n_points=n_points, label=self.source if label is None else label)

    def force_displacement_loop(self, n_points: int = defaults.LOOP_POINTS,
                                ) -> tuple[np.ndarray, np.ndarray]:
        """``(displacement_m, force_n)`` of :meth:`loop` (kept for callers of pidcore 0.1)."""
        loop = self.loop(n_points)
        return loop.displacement_m, loop.force_n

    def to_pandas(self) -> pd.DataFrame:
        """Fitted harmonics, one row each: order, frequency, amplitudes and phases (SI units).

        Columns ``harmonic [-]``, ``frequency [Hz]``, ``force amplitude [N]``,
        ``velocity amplitude [m/s]``, ``force phase [rad]``, ``velocity phase [rad]``
        (``|F_n|`` and ``arg F_n`` of the one-sided phasors, after corrections). The frame's
        ``attrs`` hold ``source``, ``frequency_hz`` and ``sdc``; the scalar results are
        :meth:`to_dict`'s.
        """
        n = np.asarray(self.harmonics, dtype=int)
        f = np.asarray(self.force_phasors_n, dtype=complex)
        v = np.asarray(self.velocity_phasors_m_s, dtype=complex)
        frame = pd.DataFrame({
            "harmonic [-]": n,
            "frequency [Hz]": n.astype(float) * self.frequency_hz,
            "force amplitude [N]": np.abs(f),
            "velocity amplitude [m/s]": np.abs(v),
            "force phase [rad]": np.angle(f),
            "velocity phase [rad]": np.angle(v),
        })
        frame.attrs.update(source=self.source, frequency_hz=self.frequency_hz, sdc=self.sdc)
        return frame

    def spectrum_frame(self) -> pd.DataFrame:
        """:meth:`to_pandas` (the name of pidcore 0.2; the same frame)."""
        return self.to_pandas()

    def to_dict(self) -> dict[str, Any]:
        """JSON-safe scalars (NaN -> None); includes the CLI keys, each naming its unit
        (``complex_power_real_w``, ``complex_power_imag_w``: Re and Im of P_c, Eq. 11)."""

        def num(v: float | None) -> float | None:
            return None if v is None or not math.isfinite(v) else float(v)

        p = self.complex_power_w
        return {
            "source": self.source,
            "frequency_hz": num(self.frequency_hz),
            "acceleration_g": num(self.acceleration_g),
            # P_c once, each part's unit in its key (a {"real", "imag"} pair named none)
            "complex_power_real_w": num(p.real),
            "complex_power_imag_w": num(p.imag),
            "loss_factor": num(self.loss_factor),
            "sdc": num(self.sdc),
            "sdc_stderr": num(self.sdc_stderr),
            "damping_ratio": num(self.damping_ratio),
            "energy_per_cycle_j": num(self.energy_per_cycle_j),
            "omega_rad_s": num(self.omega_rad_s),
            "n_periods": num(self.n_periods),
            "sample_rate_hz": num(self.sample_rate_hz),
            "loss_factor_stderr": num(self.loss_factor_stderr),
            "loss_factor_raw": num(self.loss_factor_raw),
            "damping_ratio_note": self.damping_ratio_note,
            "max_kinetic_energy_j": num(self.max_kinetic_energy_j),
            "force_amplitude_n": num(self.force_amplitude_n),
            "velocity_amplitude_m_s": num(self.velocity_amplitude_m_s),
            "acceleration_amplitude_m_s2": num(self.acceleration_amplitude_m_s2),
            "displacement_amplitude_m": num(self.displacement_amplitude_m),
            "harmonics": [int(n) for n in self.harmonics],
            "n_blocks": int(self.n_blocks),
            "uncertainty_note": self.uncertainty_note,
            "corrections": {k: (num(v) if isinstance(v, float) else v)
                            for k, v in self.corrections.items()},
        }

    def plot(self, ax: Any = None) -> Any:
        """Harmonic spectrum (:func:`pidcore.report.figures_results.plot_spectrum`); returns ``ax``.
        """
        from ..report.figures_results import plot_spectrum  # lazy: drawing is optional

        return plot_spectrum(self.to_pandas(), ax=ax)


def _damping_ratio(sdc: float, loss_factor: float) -> tuple[float | None, str]:
    if not math.isfinite(loss_factor):
        return None, "loss factor undefined (reactive power Im(P_c) <= 0: not mass-like)"
    if loss_factor < 0:
        return None, f"loss factor {loss_factor:.4g} < 0: no equivalent positive damping"
    if sdc >= 1:
        return None, (f"no equivalent damping ratio: SDC {sdc:.4g} >= 1, more than the "
                      "stored energy lost per cycle (zeta = -ln(1 - SDC)/(4 pi) needs SDC < 1)")
    return -math.log1p(-sdc) / (4 * math.pi), ""


def _check_reactive_power_resolved(p_c: complex, p_blocks: np.ndarray | None, *,
                                   source: str) -> None:
    """Refuse a reactive power that is zero within its uncertainty, of either sign.

    E = Im(P_c)/w is the denominator of the loss factor and the SDC: a purely resistive load
    (force in phase with velocity) has no stored kinetic energy, and its Im(P_c) is round-off
    or noise of either sign. A positive one gave a loss factor of 1e15 and an SDC reported as
    a result; a negative one (-6e-35 W noise-free on one machine) was refused as an inverted
    channel, which it is not. A negative one beyond its uncertainty is left to the caller's
    inverted-channel refusal.
    """
    if not math.isfinite(p_c.imag):
        return
    floor = defaults.REACTIVE_POWER_MIN_FRACTION * abs(p_c)
    why = f"below {defaults.REACTIVE_POWER_MIN_FRACTION:g} x |P_c| (round-off)"
    if p_blocks is not None and p_blocks.size >= 2:
        stderr = float(np.std(p_blocks.imag, ddof=1) / math.sqrt(p_blocks.size))
        if defaults.REACTIVE_POWER_MIN_STDERRS * stderr > floor:
            floor = defaults.REACTIVE_POWER_MIN_STDERRS * stderr
            why = (f"within {defaults.REACTIVE_POWER_MIN_STDERRS:g} standard errors "
                   f"({stderr:.3g} W, from {p_blocks.size} blocks) of zero")
    if abs(p_c.imag) <= floor:
        raise SignalError(
            f"{source or 'record'}: reactive power Im(P_c) = {p_c.imag:.4g} W is {why}, with "
            f"Re(P_c) = {p_c.real:.4g} W: no stored kinetic energy E = Im(P_c)/w is resolved, "
            "so the loss factor Re/Im and the SDC are undefined (force in phase with velocity: "
            "a purely resistive load, or a velocity channel that is not the structure's)")


def _undelayed(phasors: np.ndarray | complex, n: np.ndarray | int, omega: float,
               delay_s: float) -> np.ndarray | complex:
    """Phasors of ``x(t)`` from those of a channel that recorded ``x(t - delay_s)``: the one
    phase correction of every channel's delay (a vibrometer's, a start offset's)."""
    return phasors * np.exp(1j * n * omega * delay_s)


def _complex_power(f_ph: np.ndarray, m_ph: np.ndarray, a_ph: np.ndarray | None,
                   n: np.ndarray, omega: float, *, motion_is_velocity: bool, delay_s: float,
                   acceleration_delay_s: float, mass_kg: float
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Corrected (F, V) phasors and P_c; arrays over (..., harmonic)."""
    jnw = 1j * n * omega
    # x(t - tau) recorded for either motion channel: a velocity integrated from a delayed
    # acceleration is the delayed velocity, so the one phase factor serves both
    v = _undelayed(m_ph, n, omega, delay_s)
    if not motion_is_velocity:
        v = v / jnw
    if mass_kg:
        # the inertia force m a at the force's instants: an acceleration sampled off them
        # turns m a by n w tau against the force, which moves Re(P_c) by that phase times
        # the inertia force's share of the force
        acc = (_undelayed(a_ph, n, omega, acceleration_delay_s) if a_ph is not None
               else jnw * v)
        f = f_ph - mass_kg * acc
    else:
        f = f_ph
    return f, v, 0.5 * np.sum(f * np.conj(v), axis=-1)


#: Largest share of the measured reactive power the empty structure's mass may claim before
#: it is taken for a unit slip: particles moving against the coupon (a bed above its own
#: resonance) lower the reactive power below the structure's, by tens of per cent, not by the
#: factor 1000 of grams typed as kilograms.
UNIT_SLIP_SHARE = 2.0
#: Smallest share the empty structure may hold: particles a hundred times heavier than the
#: coupon and fixture they fill are no sandwich panel (tungsten-carbide beads filling a light
#: coupon reach about 9 times, a share of 0.1); below it the mass was typed in another unit.
MIN_STRUCTURE_SHARE = 0.01


def check_analysis_settings(*, n_harmonics: int = defaults.N_HARMONICS,
                            mass_below_gauge_kg: float = 0.0, frequency_hz: float | None = None,
                            velocity_delay_s: float = 0.0, baseline_loss_factor: float = 0.0,
                            sample_rate_hz: float | None = None,
                            structure_mass_kg: float | None = None) -> None:
    """Refuse the settings of an analysis that no record can make right (a string, a bool, a
    fraction of a harmonic, a negative mass or baseline, a non-positive frequency hint, rate
    or structure mass), each naming its keyword: :func:`analyze_power` checks them, and
    :class:`pidcore.measure.AnalysisOptions` when it is made, before any file is read."""
    for name, value in (("mass_below_gauge_kg", mass_below_gauge_kg),
                        ("velocity_delay_s", velocity_delay_s),
                        ("baseline_loss_factor", baseline_loss_factor),
                        *((("frequency_hz", frequency_hz),) if frequency_hz is not None else ()),
                        *((("sample_rate_hz", sample_rate_hz),) if sample_rate_hz is not None
                          else ())):
        real_number(name, value)
    if sample_rate_hz is not None and not (math.isfinite(sample_rate_hz) and sample_rate_hz > 0):
        raise ParameterError(f"sample_rate_hz: {sample_rate_hz!r}, expected a positive number")
    if (isinstance(n_harmonics, bool) or not isinstance(n_harmonics, numbers.Real)
            or not math.isfinite(n_harmonics) or int(n_harmonics) != n_harmonics
            or n_harmonics < 1):
        raise ParameterError(f"n_harmonics: {n_harmonics!r}, expected an integer >= 1")
    if not (math.isfinite(mass_below_gauge_kg) and mass_below_gauge_kg >= 0):
        raise ParameterError(f"mass_below_gauge_kg: {mass_below_gauge_kg!r}, expected >= 0 kg")
    if frequency_hz is not None and not (math.isfinite(frequency_hz) and frequency_hz > 0):
        raise ParameterError(f"frequency_hz: {frequency_hz!r}, expected a positive hint in Hz")
    if not math.isfinite(velocity_delay_s):
        raise ParameterError(f"velocity_delay_s: {velocity_delay_s!r}, expected a finite time")
    if not (math.isfinite(baseline_loss_factor) and baseline_loss_factor >= 0):
        # the empty coupon dissipates energy: a negative baseline would add damping
        raise ParameterError(f"baseline_loss_factor: {baseline_loss_factor!r}, expected a "
                             "loss factor >= 0 (that of the empty coupon)")
    if structure_mass_kg is not None and not (
            isinstance(structure_mass_kg, (int, float)) and not isinstance(structure_mass_kg, bool)
            and math.isfinite(structure_mass_kg) and structure_mass_kg > 0):
        raise ParameterError(f"structure_mass_kg: {structure_mass_kg!r}, expected the empty "
                             "structure's mass in kg > 0 (coupon and fixture above the gauge)")


def _check_parameters(sample_rate_hz: float, n_harmonics: int, n_blocks: int, min_periods: int,
                      mass_below_gauge_kg: float, frequency_hz: float | None,
                      velocity_delay_s: float, baseline_loss_factor: float,
                      structure_mass_kg: float | None = None, source: str = "") -> None:
    check_analysis_settings(n_harmonics=n_harmonics, mass_below_gauge_kg=mass_below_gauge_kg,
                            frequency_hz=frequency_hz, velocity_delay_s=velocity_delay_s,
                            baseline_loss_factor=baseline_loss_factor,
                            sample_rate_hz=sample_rate_hz, structure_mass_kg=structure_mass_kg)
    if int(n_blocks) != n_blocks or n_blocks < 0:
        raise ParameterError(f"n_blocks: {n_blocks!r}, expected an integer >= 0 (0: no stderr)")
    if int(min_periods) != min_periods or min_periods < 1:
        raise ParameterError(f"min_periods: {min_periods!r}, expected an integer >= 1")
    if frequency_hz is not None and frequency_hz >= sample_rate_hz / 2:
        # a hint the rate cannot hold is a wrong hint or a wrong rate: a time base in ms read
        # as s (a UFF abscissa labelled s, a CSV time column without a unit) is 1000 x too low
        # the rate is this record's: the refusal names it (in a batch, which file)
        raise ParameterError(f"{_of(source)}frequency_hz: {as_given(frequency_hz)} Hz is not "
                             f"below the Nyquist frequency {sample_rate_hz / 2:g} Hz of the "
                             f"sample rate {sample_rate_hz:g} Hz; correct the hint, or the "
                             "file's time unit (time_unit=UNIT) where its time base is in ms or "
                             "us read as s")


#: The refusal of a negative reactive power says a channel "is probably inverted".
PROBABLY_INVERTED = "is probably inverted"


def _of(source: str) -> str:
    """``"SOURCE: "`` that starts a refusal of one record's parameter, ``""`` without one:
    an option given for every file of a batch is refused for one of them, which it names."""
    return f"{source}: " if source else ""


def _check_delay(velocity_delay_s: float, frequency_hz: float, duration_s: float,
                 source: str = "") -> None:
    # A vibrometer's output delay is tens of µs to a few ms; a value of several drive periods
    # (or longer than the record) is a unit slip (ms typed as s): the phase correction wraps
    # every period, so such a value cannot be told from a small one and must not pass.
    limit = min(defaults.MAX_VELOCITY_DELAY_PERIODS / frequency_hz, duration_s)
    if abs(velocity_delay_s) > limit:
        # a negative value (a lead, as a test of the correction's sign may pass) is no
        # "longer" delay: it is said as the shift it is
        said = "is longer than" if velocity_delay_s > 0 else "shifts the velocity by more than"
        raise ParameterError(
            f"{_of(source)}velocity_delay_s: {velocity_delay_s:g} s {said} "
            f"{defaults.MAX_VELOCITY_DELAY_PERIODS} drive periods of {frequency_hz:.6g} Hz "
            f"({limit:.6g} s, record {duration_s:.6g} s); expected a vibrometer delay in s "
            "(e.g. 2e-4)")


def _short_delay_note(velocity_delay_s: float, frequency_hz: float) -> str:
    """A note for a vibrometer delay too short to be one (a value in ms given as µs), with
    what it turns the velocity's phase by and what 1000 x it would: taken as given, since no
    rule tells a slip from a deliberate tiny correction, but never without a word."""
    tau = abs(float(velocity_delay_s))
    if not 0.0 < tau < defaults.MIN_NOTED_VELOCITY_DELAY_S:
        return ""
    turn = 2 * math.pi * frequency_hz * tau
    return (f"vibrometer delay {velocity_delay_s * 1e6:.3g} µs is shorter than any vibrometer's "
            f"output delay (µs to ms): it turns the velocity's phase at {frequency_hz:.6g} Hz "
            f"by {turn:.2g} rad, 1000 x it (the value read in ms) by {1000 * turn:.3g} rad; "
            "check the delay's unit")


def _check_start_offset(start_offset_delay_s: float, sample_rate_hz: float,
                        source: str = "", name: str = "start_offset_delay_s") -> None:
    # what is left of a start offset once whole samples are cut: half a sample at most (a
    # larger value is whole samples that belong cut, or a time in the wrong unit)
    real_number(name, start_offset_delay_s)
    half = 0.5 / sample_rate_hz
    if not (math.isfinite(start_offset_delay_s)
            and abs(start_offset_delay_s) <= half * (1 + 1e-9)):
        raise ParameterError(f"{_of(source)}{name}: {start_offset_delay_s!r} s, "
                             f"expected a fraction of a sample, at most {half:.6g} s (half a "
                             f"sample at {sample_rate_hz:g} Hz)")


def _check_acceleration_sign(acceleration_phasor: complex, velocity_phasor: complex,
                             omega: float, velocity_delay_s: float,
                             acceleration_delay_s: float, *, source: str,
                             acceleration_name: str, velocity_name: str) -> None:
    """Refuse an acceleration channel that moves against the velocity at the drive line.

    Mass cancellation takes ``m a`` off the force; an accelerometer mounted the other way
    (or a -Z record not applied) made it add ``m a`` instead, and the loss factor came out
    too small by the share of that mass in the reactive power (0.015 for 0.02 with 50 g on
    a 0.3 kg coupon) without a word: the reactive power stays positive, so nothing else
    catches it. The same point moves alike in both channels (a fixture resonance turns the
    phase by tens of degrees, not past 90).

    Each channel is judged as corrected, by its own delay: an acceleration half a sample off
    the force's instants near the Nyquist limit is turned by up to 80 degrees, which with a
    fixture's tens of degrees took a sound channel past 90."""
    expected = 1j * omega * _undelayed(velocity_phasor, 1, omega, velocity_delay_s)
    acceleration = _undelayed(acceleration_phasor, 1, omega, acceleration_delay_s)
    if not (acceleration * np.conj(expected)).real < 0:
        return
    phase = math.degrees(abs(np.angle(acceleration * np.conj(expected))))
    raise SignalError(
        f"{source or 'record'}: channel {acceleration_name!r} moves against the velocity "
        f"{velocity_name!r} at the drive line ({phase:.0f}° from j omega V, expected about 0°): "
        f"mass cancellation would add its inertia force to the force instead of taking "
        f"it off; one of the channels {acceleration_name!r} / {velocity_name!r} "
        f"{PROBABLY_INVERTED}: check the sensor directions, or pass invert=NAME for the "
        "inverted channel (or the vibrometer delay is far from corrected)")


def _quantity_slip_cause(p_c: complex, motion_name: str, *, motion_is_velocity: bool) -> str:
    """The likely cause of a negative reactive power whose P_c lies near the force's line: the
    motion channel holds its quantity's derivative (an acceleration in the velocity column),
    which turns P_c by 90 degrees, where an inversion turns it by 180
    (:data:`~pidcore.defaults.QUANTITY_SLIP_MAX_PHASE_DEG`); "" elsewhere."""
    phase = math.degrees(math.atan2(p_c.imag, p_c.real))
    if not (p_c.real > 0 and -defaults.QUANTITY_SLIP_MAX_PHASE_DEG <= phase <= 0):
        return ""
    # the slips that land there: the derivative, or the integral with the other sign
    expected, slips = (("a velocity in m/s",
                        "an acceleration (m/s²), or a displacement (m) of the other sign")
                       if motion_is_velocity else
                       ("an acceleration in m/s²", "a velocity (m/s) of the other sign"))
    return (f"force and motion are {abs(phase):.0f}° apart, near in phase, where a mass gives "
            f"about 90° and an inverted channel about -90°: channel {motion_name!r}, read as "
            f"{expected}, probably holds {slips} (check the column's quantity and unit)")


def _shortest_block(edges: np.ndarray, n_blocks: int) -> int:
    """Samples in the shortest of the ``n_blocks`` blocks of the standard error."""
    return int(np.min(np.diff(edges[:n_blocks + 1])))


def _noise_judges(fit: HarmonicFit, n_blocks: int, edges: np.ndarray) -> bool:
    """Whether the blocks' residuals hold the :data:`~pidcore.defaults.DRIVE_PHASE_MIN_DOF`
    spare samples their noise estimate needs to judge a block's phasor by. A block a few
    samples longer than the fit's parameters has none (one period of 12.8 samples at 12
    parameters leaves under 1 degree of freedom, and the near-saturated fit multiplies its
    noise): a steady drive at 20 dB was refused as a sweep there half the time; the checks
    that judge blocks by their noise say nothing there."""
    spare = _shortest_block(edges, n_blocks) - fit_parameter_count(fit.phasors.shape[2])
    return spare >= defaults.DRIVE_PHASE_MIN_DOF


def _check_stationary_drive(fit: HarmonicFit, n_blocks: int, edges: np.ndarray,
                            motion: np.ndarray, sample_rate_hz: float, frequency_hz: float, *,
                            what: str, noise_of_quietest_block: bool = False) -> str:
    """Refuse a drive whose frequency moves over the record (a slow sweep, a controller hunting),
    or return a note where it moves less but beyond noise ("" where it does not).

    The phasors of the record are one fit at one frequency; a drive line whose phase moves
    between the blocks adds up incoherently in it, so the acceleration and the energy per
    cycle came out low without a word (a 0.3 % sweep over 2 s at 500 Hz: 23 % and 40 % low),
    and a faster sweep was refused as a purely resistive load. The motion channel's
    fundamentals in the ``n_blocks`` blocks of the standard error (channel 1 of ``fit``) give
    the loss ``1 - |mean of the fundamentals| / mean of their amplitudes``, which an amplitude
    change alone (a beat) leaves at 0. Noise makes some: about a quarter of the blocks'
    relative phasor variance ``E|dV_1|^2 / |V_1|^2``, which the fit gives from each block's
    residual over its degrees of freedom (:class:`~pidcore.signal.harmonics.HarmonicFit`).
    ``noise_of_quietest_block`` judges noise by the quietest block, not the median one: where the
    drive has left most blocks (a sweep over +-10 % and more) their residuals hold it, and the
    median block's took the loss for noise."""
    fundamentals = fit.phasors[1, :n_blocks, 0]
    amplitudes = np.abs(fundamentals)
    if fundamentals.size < 2 or not np.all(amplitudes > 0):
        return ""
    mean_amplitude = float(np.mean(amplitudes))
    loss = 1.0 - float(abs(np.mean(fundamentals))) / mean_amplitude
    if loss <= defaults.DRIVE_COHERENCE_NOTED_LOSS:
        return ""
    if not _noise_judges(fit, n_blocks, edges):
        return ""
    scatter = fit.fundamental_variance[1, :n_blocks] / amplitudes ** 2
    # the median: a block the drive has left (a fast sweep) holds its power in its residual
    noise = float(np.min(scatter) if noise_of_quietest_block else np.median(scatter))
    if loss <= defaults.DRIVE_PHASE_NOISE_FACTOR * noise:
        return ""
    phases = np.degrees(np.angle(fundamentals * np.conj(np.mean(fundamentals))))
    moved = (f"the drive line's phase spans {np.ptp(phases):.3g} degrees over the "
             f"{fundamentals.size} blocks of the record")
    # a block's own frequency is known where it holds as many periods as a record must
    block_periods = _shortest_block(edges, n_blocks) * frequency_hz / sample_rate_hz
    if block_periods >= defaults.MIN_PERIODS:
        # each block's line found in its own spectrum: refined from the record's frequency, a
        # block a wide sweep had carried far from it settled on a wrong line (597.9 Hz for
        # the 300 Hz start of a 300-700 Hz sweep)
        try:
            first, last = (estimate_drive_frequency(motion[edges[i]:edges[i + 1]],
                                                    sample_rate_hz)
                           for i in (0, fundamentals.size - 1))
        except SignalError:  # a block without a dominant line: its phase span is said
            pass
        else:
            moved += f" (from {first:.6g} Hz in the first to {last:.6g} Hz in the last)"
    # what was measured, not a loss against the truth: a sweep's result is that much low (or
    # more), but a two-tone beat's (500 and 500.7 Hz) came out 2 % above its stronger tone
    said = (f"{moved}: the drive is not one steady sine, and the record's fit at "
            f"{frequency_hz:.6g} Hz, which adds the blocks' phasors, has {100 * loss:.3g} % "
            "less amplitude than they have on average; its acceleration and energy per cycle "
            "are those of that sum (the loss factor, a ratio, keeps)")
    if loss <= defaults.DRIVE_COHERENCE_MAX_LOSS:
        return f"drive frequency not quite stationary: {said}"
    raise SignalError(
        f"{what}: drive frequency not stationary: {said}; "
        f"{100 * defaults.DRIVE_COHERENCE_MAX_LOSS:g} % allowed: analyse a stretch at "
        "constant frequency")


def _check_block_amplitudes(fit: HarmonicFit, n_blocks: int, edges: np.ndarray,
                            sample_rate_hz: float, *, names: tuple[str, str],
                            source: str) -> str:
    """Refuse a record where one channel's drive line drops out in some blocks of the standard
    error (or rises) while the rest of the record is steady, or return a note where the
    result moves less ("" where no block stands out).

    A vibrometer losing its return (or a cable, a trigger) records noise instead of the
    motion for a while; the one fit of the record then has that much less of the channel's
    line and the energy per cycle came out low without a word (5 % of a record: -5 %), while
    the stretch's samples are no run of identical values (:func:`validate.dropout_runs`). A
    block is out where its fundamental's amplitude departs from the median block's by more
    than :data:`~pidcore.defaults.BLOCK_AMPLITUDE_MIN_DEPARTURE`, than
    :data:`~pidcore.defaults.BLOCK_AMPLITUDE_SPREAD_FACTOR` x the blocks' own spread (their
    median absolute departure, a bed's cycle-to-cycle force) and than as many times the
    median block's noise: a beat or a slow ramp moves every block and none stands out. The
    record's fit, about the blocks' mean, then departs from the steady blocks by the out
    blocks' departures over the block count, which is what the message says."""
    if n_blocks < defaults.BLOCK_AMPLITUDE_MIN_BLOCKS or not _noise_judges(fit, n_blocks, edges):
        return ""
    said = []
    worst = 0.0
    for channel, name in enumerate(names):
        amplitudes = np.abs(fit.phasors[channel, :n_blocks, 0])
        median = float(np.median(amplitudes))
        if not median > 0:
            continue
        departure = amplitudes / median - 1.0
        spread = 1.4826 * float(np.median(np.abs(departure)))  # a normal's sigma from its MAD
        noise = math.sqrt(float(np.median(fit.fundamental_variance[channel, :n_blocks]))) / median
        limit = max(defaults.BLOCK_AMPLITUDE_MIN_DEPARTURE,
                    defaults.BLOCK_AMPLITUDE_SPREAD_FACTOR * max(spread, noise))
        out = np.flatnonzero(np.abs(departure) > limit)
        if not out.size:
            continue
        effect = float(np.sum(departure[out])) / n_blocks
        worst = max(worst, abs(effect))
        blocks = ", ".join(
            f"{i + 1} ({edges[i] / sample_rate_hz:.4g}-{edges[i + 1] / sample_rate_hz:.4g} s: "
            f"{100 * abs(departure[i]):.3g} % {'less' if departure[i] < 0 else 'more'})"
            for i in out)
        said.append(f"channel {name!r} holds its drive line steady in the other blocks of "
                    f"{n_blocks} but not in block(s) {blocks} (a sensor dropout, a vibrometer "
                    "losing its return, a cable or a structure changing mid-record); the "
                    f"record's fit of it is about {100 * abs(effect):.2g} % "
                    f"{'low' if effect < 0 else 'high'} against the steady blocks")
    if not said:
        return ""
    if worst <= defaults.DRIVE_COHERENCE_MAX_LOSS:
        return "drive line not steady in every block: " + "; ".join(said)
    raise SignalError(f"{source or 'record'}: {'; '.join(said)}; "
                      f"{100 * defaults.DRIVE_COHERENCE_MAX_LOSS:g} % allowed: analyse a "
                      "stretch without those blocks")


def _block_edges(whole: int, k_blocks: int, n_samples: int, sample_rate_hz: float,
                 frequency_hz: float) -> np.ndarray:
    """Sample edges of the ``k_blocks`` blocks of the standard error: whole periods, the
    ``whole`` of the record shared out as evenly as they go (``whole // k_blocks`` or one
    more each), the last block running to the record's end.

    Every sample the record's fit uses is in a block, so whatever moves the result moves the
    blocks' scatter too. Blocks of ``whole // k_blocks`` periods from the start left up to
    ``k_blocks`` periods at the end in the record's fit only: a glitch there (one sample
    100 x, a cut last row) moved the SDC 13 % while its standard error stayed 5000 x smaller
    (docs/measurement.md)."""
    marks = np.round(np.arange(k_blocks) * whole / k_blocks)
    edges = np.round(marks * sample_rate_hz / frequency_hz).astype(np.int64)
    return np.append(edges, n_samples)


def _drift_knots(whole: int, n_samples: int, sample_rate_hz: float,
                 frequency_hz: float) -> np.ndarray | None:
    """Knots of the drift's cubic spline: every ``DRIFT_KNOT_PERIODS`` whole periods, the
    last space running to the record's end (what is left: less than one more space); None
    where the record holds fewer than two spaces."""
    spaces = whole // defaults.DRIFT_KNOT_PERIODS
    if spaces < 2:
        return None
    marks = np.arange(spaces) * defaults.DRIFT_KNOT_PERIODS
    knots = np.round(marks * sample_rate_hz / frequency_hz).astype(np.int64)
    return np.append(knots, n_samples)


def analyze_power(force: np.ndarray, velocity: np.ndarray | None, sample_rate_hz: float, *,
                  acceleration: np.ndarray | None = None,
                  frequency_hz: float | None = None,
                  n_harmonics: int = defaults.N_HARMONICS,
                  velocity_delay_s: float = 0.0,
                  start_offset_delay_s: float = 0.0,
                  acceleration_start_offset_delay_s: float = 0.0,
                  mass_below_gauge_kg: float = 0.0,
                  baseline_loss_factor: float = 0.0,
                  structure_mass_kg: float | None = None,
                  n_blocks: int = defaults.N_UNCERTAINTY_BLOCKS,
                  min_periods: int = defaults.MIN_PERIODS,
                  source: str = "",
                  force_name: str = "force",
                  velocity_name: str = "velocity",
                  acceleration_name: str = "acceleration",
                  require_mass_like: bool = True) -> PowerAnalysis:
    """Complex power, loss factor and SDC of a sine-driven force/velocity record (Eq. 8-11).

    Parameters
    ----------
    force : numpy.ndarray
        Force at the gauge, N.
    velocity : numpy.ndarray or None
        Velocity of the driving point, m/s. None: derived from ``acceleration``.
    sample_rate_hz : float
        Sample rate of all channels, Hz.
    acceleration : numpy.ndarray, optional
        Acceleration of the driving point, m/s^2 (velocity source when ``velocity`` is None,
        and the acceleration used by mass cancellation when given).
    frequency_hz : float, optional
        Nominal drive frequency, Hz: only a hint; the frequency is estimated from the motion
        channel within +-5 % of it (see :mod:`pidcore.signal.frequency`).
    n_harmonics : int
        Harmonics fitted; those above 0.9 x Nyquist are dropped.
    velocity_delay_s : float
        Output delay of the velocity signal (vibrometer), s; requires a velocity channel.
    start_offset_delay_s : float
        Delay, s, in the convention of ``velocity_delay_s`` (the channel holds ``x(t - tau)``),
        of a motion channel whose samples lie a fraction of a sample off the force's: the
        velocity, or without one the acceleration the velocity comes from. Corrected with
        ``velocity_delay_s`` (the two add); at most half a sample.
        :func:`pidcore.measure.analyze_measurement` passes it from the channels' start times.
    acceleration_start_offset_delay_s : float
        The same for an ``acceleration`` channel beside a ``velocity`` channel (the one mass
        cancellation takes), corrected on its phasors by the same factor (without
        ``velocity_delay_s``, the vibrometer's); at most half a sample. Refused without a
        velocity channel: the acceleration is then the motion channel, whose offset is
        ``start_offset_delay_s``.
    mass_below_gauge_kg : float
        Mass between force gauge and structure whose inertia force is cancelled, kg.
    baseline_loss_factor : float
        Loss factor of the empty structure, subtracted from the result (correction 4 of the
        module docstring).
    structure_mass_kg : float, optional
        Mass of that empty structure as the gauge sees it (coupon and fixture above the gauge,
        less what ``mass_below_gauge_kg`` cancels), kg: its dissipation ``baseline_loss_factor
        x Q_s`` is subtracted. None: the whole reactive power stands for ``Q_s`` (noted).
    n_blocks : int
        Blocks of whole periods for the standard errors (0 or 1: none, and one DC and trend
        over the record as the drift model; see the module docstring).
    min_periods : int
        Fewest drive periods accepted.
    source, force_name, velocity_name, acceleration_name : str
        Names used in messages and in the result.
    require_mass_like : bool
        Refuse a reactive power Im(P_c) <= 0 (default; a measured structure is mass-like, so
        it means an inverted channel). False for a DEM particle bed's own wall force, whose
        reactive part may be either sign (the structure's mass is added by the caller); the
        loss factor, SDC and damping ratio are then NaN or negative and say so.
    Returns
    -------
    PowerAnalysis

    Raises
    ------
    SignalError
        No dominant drive frequency, or fewer than ``min_periods`` periods.
    ChannelError
        Non-finite samples, mismatched lengths.
    ParameterError
        Out-of-range options.

    Examples
    --------
    >>> fs, f, m, c = 10000.0, 100.0, 0.5, 2.0
    >>> t = np.arange(20000) / fs
    >>> v = 0.01 * np.sin(2 * np.pi * f * t)
    >>> force = m * 0.01 * 2 * np.pi * f * np.cos(2 * np.pi * f * t) + c * v  # m dv/dt + c v
    >>> res = analyze_power(force, v, fs)
    >>> round(res.loss_factor, 4), round(c / (m * 2 * np.pi * f), 4)
    (0.0064, 0.0064)
    """
    _check_parameters(sample_rate_hz, n_harmonics, n_blocks, min_periods, mass_below_gauge_kg,
                      frequency_hz, velocity_delay_s, baseline_loss_factor, structure_mass_kg,
                      source)
    if velocity is None and acceleration is None:
        raise ParameterError(f"{source or 'record'}: neither a velocity nor an acceleration "
                             "channel given; expected at least one")
    if velocity is None and velocity_delay_s:
        raise ParameterError(f"{_of(source)}velocity_delay_s: a vibrometer delay needs a "
                             "velocity channel; the velocity here comes from the acceleration")
    _check_start_offset(start_offset_delay_s, sample_rate_hz, source)
    _check_start_offset(acceleration_start_offset_delay_s, sample_rate_hz, source,
                        "acceleration_start_offset_delay_s")
    if velocity is None and acceleration_start_offset_delay_s:
        raise ParameterError(f"{_of(source)}acceleration_start_offset_delay_s: the acceleration "
                             "is the motion channel here (no velocity channel); its start "
                             "offset is start_offset_delay_s")
    # the one phase correction of the motion channel (correction 1 of the module docstring)
    motion_delay_s = float(velocity_delay_s) + float(start_offset_delay_s)
    acceleration_delay_s = float(acceleration_start_offset_delay_s)
    acc_name = acceleration_name if velocity is not None else velocity_name
    channels: list[tuple[str, np.ndarray]] = [(force_name, np.asarray(force, dtype=np.float64))]
    if velocity is not None:
        channels.append((velocity_name, np.asarray(velocity, dtype=np.float64)))
    if acceleration is not None:
        channels.append((acc_name, np.asarray(acceleration, dtype=np.float64)))
    for name, data in channels:
        validate.check_length(data, source=source, channel=name, min_samples=8)
        validate.check_finite(data, source=source, channel=name)
        validate.check_outliers(data, source=source, channel=name)
    validate.check_same_sampling([c[0] for c in channels], [sample_rate_hz] * len(channels),
                                 [c[1].shape[0] for c in channels], source=source)
    f_data = channels[0][1]
    motion_name, motion = channels[1]
    acc_data = channels[-1][1] if acceleration is not None else None
    n_samples = f_data.shape[0]
    what = f"{source}: channel {motion_name!r}" if source else f"channel {motion_name!r}"

    freq = estimate_drive_frequency(motion, sample_rate_hz, frequency_hint_hz=frequency_hz,
                                    what=what)
    n_periods = n_samples * freq / sample_rate_hz
    # a record of exactly min_periods periods must pass although the estimated frequency may
    # be a few ppm low: allow half a percent of a period
    if n_periods < min_periods - 0.005:
        raise SignalError(f"{what}: {n_periods:.2f} drive periods of {freq:.6g} Hz in "
                          f"{n_samples} samples, expected at least {min_periods}")
    _check_delay(velocity_delay_s, freq, n_samples / sample_rate_hz, source)
    delay_note = _short_delay_note(velocity_delay_s, freq)
    max_harm = int(defaults.HARMONIC_MAX_FRACTION_OF_NYQUIST * 0.5 * sample_rate_hz / freq)
    n_harm = min(int(n_harmonics), max_harm)
    if n_harm < 1:
        raise SignalError(f"{what}: drive frequency {freq:.6g} Hz is too close to the Nyquist "
                          f"frequency {sample_rate_hz / 2:g} Hz")
    harmonics_note = ""
    if n_harm < int(n_harmonics):
        # the fit cannot resolve them; the record's parameters keep the number asked, so say
        # how many the result holds (--harmonics 20 at 1000 Hz fitted 11 without a word)
        limit_hz = defaults.HARMONIC_MAX_FRACTION_OF_NYQUIST * 0.5 * sample_rate_hz
        harmonics_note = (f"{n_harm} of the {int(n_harmonics)} drive harmonics asked fitted: "
                          f"harmonics {n_harm + 1} and above of {freq:.6g} Hz lie above "
                          f"{limit_hz:.6g} Hz, {defaults.HARMONIC_MAX_FRACTION_OF_NYQUIST:g} x "
                          f"the Nyquist frequency of {sample_rate_hz:g} Hz sampling")
    harmonics = np.arange(1, n_harm + 1)
    omega = 2 * np.pi * freq
    theta = omega / sample_rate_hz

    whole = int(math.floor(n_periods))
    k_blocks = int(n_blocks)
    if k_blocks >= 2 and whole >= k_blocks:
        edges = _block_edges(whole, k_blocks, n_samples, sample_rate_hz, freq)
        uncertainty_note = ""
        # a block of fewer samples than the fit's parameters (harmonics, DC and trend) has no
        # phasors (NaN): one period of 11.6 samples at 5 harmonics holds 11 for 12
        shortest = _shortest_block(edges, k_blocks)
        n_params = fit_parameter_count(n_harm)
        if shortest < n_params:
            edges = np.array([0, n_samples], dtype=np.int64)
            uncertainty_note = (f"no standard error: blocks of {shortest} samples "
                                f"({whole // k_blocks} period(s) in the shortest of "
                                f"{k_blocks}) hold fewer than the fit's {n_params} parameters "
                                f"({n_harm} harmonics, DC and trend)")
            k_blocks = 0
    else:
        edges = np.array([0, n_samples], dtype=np.int64)
        uncertainty_note = (f"no standard error: {whole} whole periods cannot make "
                            f"{k_blocks} blocks (need n_blocks >= 2 and >= 1 period each)")
        k_blocks = 0

    # the drift of the result: a cubic spline with knots every few periods where the record
    # holds two spaces (the blocks keep their DC and trend: the standard error is theirs)
    drift_knots = (_drift_knots(whole, n_samples, sample_rate_hz, freq) if k_blocks else None)
    drift_note = ""
    if k_blocks and drift_knots is None:
        drift_note = (f"drift taken as one linear trend over the record: its {whole} whole "
                      f"periods are too few for a spline with knots every "
                      f"{defaults.DRIFT_KNOT_PERIODS}, so a slow wander that is not linear over "
                      "the record is not removed")
    fit = fit_harmonics(f_data, motion, theta, n_harm, edges, drift_knots=drift_knots)
    stationary_note = (_check_stationary_drive(fit, k_blocks, edges, motion, sample_rate_hz,
                                               freq, what=what)
                       if k_blocks else "")
    a_fit = None
    if acc_data is not None and velocity is not None:
        a_fit = fit_harmonics(acc_data, None, theta, n_harm, edges, drift_knots=drift_knots)
    if a_fit is not None and mass_below_gauge_kg > 0:
        _check_acceleration_sign(a_fit.total[0, 0], fit.total[1, 0], omega, motion_delay_s,
                                 acceleration_delay_s, source=source,
                                 acceleration_name=acc_name, velocity_name=velocity_name)
    kw = dict(motion_is_velocity=velocity is not None, delay_s=motion_delay_s,
              acceleration_delay_s=acceleration_delay_s, mass_kg=float(mass_below_gauge_kg))
    f_ph, v_ph, p_c = _complex_power(fit.total[0], fit.total[1],
                                     None if a_fit is None else a_fit.total[0],
                                     harmonics, omega, **kw)
    p_c = complex(p_c)
    p_blocks = None
    if k_blocks:
        _, _, p_blocks = _complex_power(fit.phasors[0, :k_blocks], fit.phasors[1, :k_blocks],
                                        None if a_fit is None else a_fit.phasors[0, :k_blocks],
                                        harmonics, omega, **kw)
    if require_mass_like:
        try:
            _check_reactive_power_resolved(p_c, p_blocks, source=source)
        except SignalError:
            # a wide sweep (400-600 Hz in 0.5 s) adds its blocks' phasors to about nothing, and
            # was refused as a purely resistive load; its blocks' phases disagree, a resistive
            # load's do not, so the drive is asked about before the load is blamed
            if k_blocks:
                _check_stationary_drive(fit, k_blocks, edges, motion, sample_rate_hz, freq,
                                        what=what, noise_of_quietest_block=True)
            raise
    if require_mass_like and not p_c.imag > 0:
        # There is no negative mass: a driven structure above its suspension resonance is
        # mass-like, Im(P_c) > 0. A negative reactive power is almost always one channel with
        # the wrong sign (sensor mounted the other way, a -Z direction not applied), or, with
        # mass cancellation, a mass below the gauge larger than the mass actually there: its
        # subtracted inertia force then exceeds the structure's.
        cause = (f"one of the channels {force_name!r} / {motion_name!r} {PROBABLY_INVERTED}: "
                 "check the sensor directions, or pass invert=NAME for the inverted channel")
        slip = _quantity_slip_cause(p_c, motion_name, motion_is_velocity=velocity is not None)
        if slip:
            cause = f"{slip}; else {cause}"
        if mass_below_gauge_kg > 0:
            cause = (f"mass_below_gauge_kg {mass_below_gauge_kg:g} kg is probably larger than "
                     "the mass between gauge and structure (its cancelled inertia exceeds the "
                     "structure's), or " + cause)
        raise SignalError(
            f"{source or 'record'}: reactive power Im(P_c) = {p_c.imag:.4g} W <= 0 (no "
            f"positive kinetic energy: a mass-like structure gives Im(P_c) > 0); {cause}")
    # a drive whose phase moves (said above) moves the blocks' amplitudes at the record's
    # frequency too: that is not a channel dropping out
    steady_note = (_check_block_amplitudes(fit, k_blocks, edges, sample_rate_hz,
                                           names=(force_name, motion_name), source=source)
                   if k_blocks and not stationary_note else "")

    loss_raw = p_c.real / p_c.imag if p_c.imag != 0 else math.nan
    # the empty structure's share of the reactive power, whose baseline_loss_factor it
    # dissipates (1: the whole of it stands for the structure's, noted below)
    structure_share, baseline_note = _structure_share(
        structure_mass_kg, baseline_loss_factor, v_ph, harmonics, omega, p_c, source)
    baseline = baseline_loss_factor * structure_share
    if baseline_loss_factor > 0 and not loss_raw > baseline:
        # subtracting it would give zero or negative damping: energy created per cycle
        raise ParameterError(
            f"{source or 'record'}: baseline_loss_factor {baseline_loss_factor:g} "
            + ("is not below " if structure_share == 1.0 else
               f"x the structure's share {structure_share:.4g} of the reactive power is not "
               "below ")
            + f"the measured loss factor {loss_raw:.6g}; expected the empty coupon's loss factor, "
            "smaller than that of the filled one"
            # heavy beads may damp less than the empty coupon: only the exact subtraction
            # (the structure's own share) tells that from a wrong baseline
            + ("" if structure_share != 1.0 else
               " (heavy particles can take it below: give structure_mass_kg, the coupon and "
               "fixture above the gauge, for the exact subtraction)"))
    loss = loss_raw - baseline
    sdc = 2 * np.pi * loss
    lf_stderr = float("nan")
    if p_blocks is not None:
        if np.all(p_blocks.imag > 0):
            lf_blocks = p_blocks.real / p_blocks.imag
            lf_stderr = float(np.std(lf_blocks, ddof=1) / np.sqrt(k_blocks))
        else:
            # such a block is not mass-like (a transient, a resonance passed): its loss
            # factor means nothing, and a scatter taken over it would be a wrong error bar
            bad = int(np.flatnonzero(~(p_blocks.imag > 0))[0])
            uncertainty_note = (f"no standard error: block {bad + 1} of {k_blocks} has "
                                "reactive power Im(P) <= 0")
    zeta, zeta_note = _damping_ratio(sdc, loss)
    period = 1.0 / freq
    v1 = abs(v_ph[0])
    corrections: dict[str, Any] = {
        "velocity_delay_s": float(velocity_delay_s),
        "mass_below_gauge_kg": float(mass_below_gauge_kg),
        "baseline_loss_factor": float(baseline_loss_factor),
        "velocity_from_acceleration": velocity is None,
        "drift_model": ("DC and linear trend over the record" if drift_knots is None else
                        f"cubic spline, knots every {defaults.DRIFT_KNOT_PERIODS} periods"),
        "mass_acceleration_from": ("none" if not mass_below_gauge_kg else
                                   "acceleration channel" if acc_data is not None
                                   else "velocity (j n w V_n)"),
    }
    if start_offset_delay_s:
        corrections["start_offset_delay_s"] = float(start_offset_delay_s)
    if acceleration_start_offset_delay_s:
        corrections["acceleration_start_offset_delay_s"] = acceleration_delay_s
    if baseline_loss_factor > 0:
        corrections["baseline_structure_share"] = float(structure_share)
        if structure_mass_kg is not None:
            corrections["structure_mass_kg"] = float(structure_mass_kg)
    return PowerAnalysis(
        source=source,
        frequency_hz=float(freq),
        omega_rad_s=float(omega),
        n_periods=float(n_periods),
        sample_rate_hz=float(sample_rate_hz),
        harmonics=harmonics,
        force_phasors_n=f_ph,
        velocity_phasors_m_s=v_ph,
        complex_power_w=p_c,
        loss_factor=float(loss),
        loss_factor_stderr=lf_stderr,
        loss_factor_raw=float(loss_raw),
        sdc=float(sdc),
        sdc_stderr=float(2 * np.pi * lf_stderr),
        damping_ratio=zeta,
        damping_ratio_note=zeta_note,
        energy_per_cycle_j=float((p_c.real - baseline * p_c.imag) * period),
        max_kinetic_energy_j=float(p_c.imag / omega),
        force_amplitude_n=float(abs(f_ph[0])),
        velocity_amplitude_m_s=float(v1),
        acceleration_amplitude_m_s2=float(omega * v1),
        displacement_amplitude_m=float(v1 / omega),
        n_blocks=k_blocks,
        uncertainty_note=uncertainty_note,
        corrections=corrections,
        notes=tuple(n for n in (zeta_note, uncertainty_note, baseline_note, drift_note,
                                harmonics_note, delay_note, stationary_note, steady_note) if n),
    )


def _structure_share(structure_mass_kg: float | None, baseline_loss_factor: float,
                     v_ph: np.ndarray, harmonics: np.ndarray, omega: float, p_c: complex,
                     source: str) -> tuple[float, str]:
    """The empty structure's share ``Q_s / Im(P_c)`` of the reactive power (correction 4),
    and a note; ``(1.0, note)`` without its mass. A mass whose reactive power would be many
    times the measured one, or a vanishing part of it, is a unit slip and is refused, with a
    baseline or without one (the mass is saved with the record either way)."""
    if baseline_loss_factor <= 0:
        if structure_mass_kg is not None:
            _structure_share_checked(structure_mass_kg, v_ph, harmonics, omega, p_c, source)
        return 1.0, ""
    if structure_mass_kg is None:
        return 1.0, (f"baseline loss factor {baseline_loss_factor:g} subtracted as if the whole "
                     "vibrated mass were the empty structure's (too much by the particles' "
                     "share of it); give the structure's mass (coupon and fixture above the "
                     "gauge: structure_mass_kg, or a structure_mass_g column of the settings "
                     "table) for the exact subtraction")
    share, vibrated_kg = _structure_share_checked(structure_mass_kg, v_ph, harmonics, omega,
                                                  p_c, source)
    note = (f"baseline: the empty structure ({structure_mass_kg:.4g} kg) holds {share:.3g} of "
            f"the reactive power (vibrated mass {vibrated_kg:.4g} kg); baseline loss factor "
            f"{baseline_loss_factor:g} x {share:.3g} subtracted")
    return share, note


def _structure_share_checked(structure_mass_kg: float, v_ph: np.ndarray, harmonics: np.ndarray,
                             omega: float, p_c: complex, source: str) -> tuple[float, float]:
    """``(share of the reactive power, vibrated mass kg)`` of the empty structure's mass, or a
    one-line refusal where it cannot be that structure's (a unit slip)."""
    q_s = float(np.sum(0.5 * harmonics * omega * structure_mass_kg * np.abs(v_ph) ** 2))
    share = q_s / p_c.imag
    vibrated_kg = structure_mass_kg / share  # the mass-like reactive power's mass
    expected = ("expected the empty coupon and fixture above the gauge (structure_mass_kg in "
                "kg; a structure_mass_g column of the settings table in g)")
    if share > UNIT_SLIP_SHARE:
        raise ParameterError(
            f"{source or 'record'}: structure_mass_kg {structure_mass_kg:g} kg is {share:.3g} "
            f"times the vibrated mass the measurement shows ({vibrated_kg:.4g} kg from Im(P_c)); "
            f"{expected} (was it in g, or in mg in a g column?)")
    if share < MIN_STRUCTURE_SHARE:
        raise ParameterError(
            f"{source or 'record'}: structure_mass_kg {structure_mass_kg:g} kg is only "
            f"{share:.3g} of the vibrated mass the measurement shows ({vibrated_kg:.4g} kg from "
            f"Im(P_c)); {expected} (was it in t, or in kg in a g column?)")
    return share, vibrated_kg


def analyze_channels(force: Channel, velocity: Channel | None, *,
                     acceleration: Channel | None = None,
                     source: str,
                     frequency_hz: float | None = None,
                     n_harmonics: int = defaults.N_HARMONICS,
                     velocity_delay_s: float = 0.0,
                     start_offset_delay_s: float = 0.0,
                     acceleration_start_offset_delay_s: float = 0.0,
                     mass_below_gauge_kg: float = 0.0,
                     baseline_loss_factor: float = 0.0,
                     structure_mass_kg: float | None = None,
                     n_blocks: int = defaults.N_UNCERTAINTY_BLOCKS,
                     min_periods: int = defaults.MIN_PERIODS,
                     allow_clipped: bool = False) -> PowerAnalysis:
    """:func:`analyze_power` on :class:`~pidcore.records.Channel` records, after validation.

    Checks, each a one-line :class:`~pidcore.errors.ChannelError` naming ``source`` and the
    channel: quantity of each channel, NaN/inf samples, all-equal (zero) channels, equal sample
    rates and lengths, clipping (unless ``allow_clipped``); then fewer than ``min_periods``
    periods or no dominant frequency raise :class:`~pidcore.errors.SignalError`.

    Dropouts (runs of identical samples away from the extremes, :func:`validate.dropout_runs`)
    are cut out: only the longest stretch free of them in every channel is analysed, and a note
    says which samples were kept (``corrections["analysed_samples"]``).
    """
    if velocity is None and acceleration is None:
        raise ParameterError(f"{source}: neither a velocity nor an acceleration channel given; "
                             "expected at least one")
    roles = [("force", force), ("velocity", velocity), ("acceleration", acceleration)]
    present = [(role, ch) for role, ch in roles if ch is not None]
    datas = []
    for role, ch in present:
        validate.check_quantity(ch.quantity, role, source=source, channel=ch.name)
        data = np.asarray(ch.data, dtype=np.float64)
        validate.check_length(data, source=source, channel=ch.name, min_samples=8)
        validate.check_finite(data, source=source, channel=ch.name)
        validate.check_not_constant(data, source=source, channel=ch.name, unit=ch.unit)
        validate.check_outliers(data, source=source, channel=ch.name, unit=ch.unit)
        datas.append(data)
    validate.check_same_sampling([ch.name for _, ch in present],
                                 [ch.sample_rate_hz for _, ch in present],
                                 [ch.n_samples for _, ch in present], source=source)
    datas, dropout_notes, kept = _cut_dropouts([ch for _, ch in present], datas, source=source)
    clipping_notes: list[str] = []
    for (_, ch), data in zip(present, datas, strict=True):
        if not allow_clipped:
            validate.check_clipping(data, source=source, channel=ch.name, unit=ch.unit)
        else:  # analysed on request, but reported, never silently used
            clipping_notes.append(validate.clipping_description(
                data, source=source, channel=ch.name, unit=ch.unit))
    by_role = {role: data for (role, _), data in zip(present, datas, strict=True)}
    motion = velocity if velocity is not None else acceleration
    assert motion is not None
    try:
        result = analyze_power(
            by_role["force"], by_role.get("velocity"), force.sample_rate_hz,
            acceleration=by_role.get("acceleration"),
            frequency_hz=frequency_hz, n_harmonics=n_harmonics,
            velocity_delay_s=velocity_delay_s, start_offset_delay_s=start_offset_delay_s,
            acceleration_start_offset_delay_s=acceleration_start_offset_delay_s,
            mass_below_gauge_kg=mass_below_gauge_kg, baseline_loss_factor=baseline_loss_factor,
            structure_mass_kg=structure_mass_kg, n_blocks=n_blocks, min_periods=min_periods,
            source=source, force_name=force.name, velocity_name=motion.name,
            acceleration_name=acceleration.name if acceleration is not None else "acceleration")
    except SignalError as exc:
        if dropout_notes:
            raise SignalError(f"{exc} (after cutting out dropouts: {dropout_notes[0]})") from None
        raise
    extra = tuple(n for n in clipping_notes if n) + tuple(dropout_notes)
    if kept is not None:
        result = replace(result, corrections={**result.corrections,
                                              "analysed_samples": [int(kept[0]), int(kept[1])]})
    return replace(result, notes=result.notes + extra) if extra else result


def _cut_dropouts(channels: list[Channel], datas: list[np.ndarray], *, source: str
                  ) -> tuple[list[np.ndarray], list[str], tuple[int, int] | None]:
    """Keep the longest stretch free of dropouts in every channel (see
    :func:`validate.dropout_runs`); returns the data, the notes and the kept ``[start, stop)``."""
    bad: list[tuple[int, int]] = []
    described: list[str] = []
    for ch, data in zip(channels, datas, strict=True):
        runs = validate.dropout_runs(data)
        bad.extend((start, start + length) for start, length, _ in runs)
        if runs:
            start, length, value = max(runs, key=lambda r: r[1])
            at = ch.start_time_s + start / ch.sample_rate_hz
            described.append(
                f"channel {ch.name!r}: {len(runs)} dropout(s), longest {length} samples stuck at "
                f"{value:+.6g} {ch.unit} from t = {at:.6g} s")
    if not bad:
        return datas, [], None
    n = datas[0].shape[0]
    bounds = sorted(bad)
    clean: list[tuple[int, int]] = []
    pos = 0
    for a, b in bounds:
        if a > pos:
            clean.append((pos, a))
        pos = max(pos, b)
    if pos < n:
        clean.append((pos, n))
    if not clean:
        raise ChannelError(f"{source}: {'; '.join(described)}; no sample is free of dropouts")
    lo, hi = max(clean, key=lambda c: c[1] - c[0])
    rate = channels[0].sample_rate_hz
    note = (f"{source}: {'; '.join(described)}; analysed only the longest clean stretch, "
            f"samples {lo}..{hi} ({(hi - lo) / rate:.6g} s of {n / rate:.6g} s)")
    return [d[lo:hi] for d in datas], [note], (lo, hi)


def baseline_sdc_taken_off(record: PowerAnalysis | Mapping[str, Any]) -> float:
    """The part of an analysis's Eq. 11 SDC that its baseline subtraction took off
    (``analyze --baseline-loss-factor``: 2 pi eta_0 x the structure's share of the reactive
    power), [-]: the SDC before the subtraction less ``sdc``.

    ``record`` is a :class:`~pidcore.signal.PowerAnalysis`, or a stored analysis (a row of
    :meth:`pidcore.store.Store.list_analyses`), whose SDC before the subtraction is 2 pi
    Re/Im of its stored complex power (which is that before it). 0 where it subtracted none,
    or states no parameters (a record of an older pidcore); NaN where it did but its complex
    power is not stored. The calibrated DEM predicts the SDC before the subtraction (it adds
    the baseline itself), so that is the SDC to judge against its band.
    """
    import json

    if isinstance(record, PowerAnalysis):
        return float(2 * np.pi * (record.loss_factor_raw - record.loss_factor))
    text = record.get("parameters_json")
    try:
        stated = json.loads(text) if isinstance(text, str) and text else {}
    except ValueError:
        stated = {}
    eta = stated.get("baseline_loss_factor", 0.0) if isinstance(stated, dict) else 0.0
    if isinstance(eta, bool) or not isinstance(eta, int | float) or not eta > 0:
        return 0.0
    try:
        real = float(record.get("complex_power_real_w"))
        imag = float(record.get("complex_power_imag_w"))
        sdc = float(record.get("sdc"))
    except (TypeError, ValueError):
        return math.nan
    if not (math.isfinite(real) and math.isfinite(sdc) and math.isfinite(imag) and imag > 0):
        return math.nan
    return float(2 * np.pi * real / imag - sdc)
