"""Synthetic shaker records with a known answer (tests, sample data, benchmarks).

A rigid mass ``m`` is driven at constant acceleration amplitude ``a`` and frequency ``f``; the
structure also dissipates through a viscous damper ``c`` and Coulomb friction ``F_c``:

    v(t) = V sin(w t + phi),  V = a / w
    f(t) = m dv/dt + c v + F_c sign(v) + sum_k d_k sin(k w t + psi_k)

The added force harmonics (and the odd harmonics of ``F_c sign(v)``) carry no power: the
velocity is a pure sine, so only the fundamental of the force is in phase with any velocity
component. Neither does a slow wander added to the recorded channels (a shaker table moving
under its control loop, a vibrometer's drift): it is far from every harmonic, so the answer
stays the analytic one and any change of the result is the analysis' error. The analytic
answer is (``X = V / w``):

    dE = pi c w X^2 + 4 F_c X,   E = 1/2 m V^2,   loss factor = dE / (2 pi E).

This module only *generates* signals; tests compute the truth from the formulas themselves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError


@dataclass(frozen=True)
class SyntheticRecord:
    """Simultaneous channels of a synthetic shaker test, SI units.

    ``velocity`` is what a vibrometer with ``velocity_delay_s`` output delay records;
    ``acceleration`` (None unless asked for) is the undelayed acceleration at the gauge.
    """

    force_n: np.ndarray
    velocity_m_s: np.ndarray
    acceleration_m_s2: np.ndarray | None
    sample_rate_hz: float
    frequency_hz: float


def _noise(rng: np.random.Generator, signal: np.ndarray, snr_db: float | None) -> np.ndarray:
    if snr_db is None:
        return np.zeros_like(signal)
    rms = float(np.sqrt(np.mean(signal**2)))
    return rng.standard_normal(signal.shape[0]) * rms * 10.0 ** (-snr_db / 20.0)


def synthesize_shaker_record(*, mass_kg: float, acceleration_amplitude_m_s2: float,
                             frequency_hz: float, sample_rate_hz: float, n_periods: float,
                             viscous_damping_n_s_m: float = 0.0,
                             coulomb_friction_n: float = 0.0,
                             force_harmonics_n: tuple[float, ...] = (),
                             phase_rad: float = 0.0,
                             force_offset_n: float = 0.0,
                             velocity_offset_m_s: float = 0.0,
                             snr_db: float | None = None,
                             velocity_delay_s: float = 0.0,
                             wander_fraction: float = 0.0,
                             wander_frequency_hz: float = 0.5,
                             wander_phase_rad: float = 0.0,
                             with_acceleration: bool = False,
                             seed: int = 0) -> SyntheticRecord:
    """Generate force, velocity (and acceleration) of the driven rigid mass.

    Parameters
    ----------
    mass_kg : float
        Driven rigid mass, kg.
    acceleration_amplitude_m_s2 : float
        Acceleration amplitude a, m/s^2.
    frequency_hz : float
        True drive frequency, Hz (may differ from any nominal value given to the analysis).
    sample_rate_hz : float
        Sample rate, Hz.
    n_periods : float
        Record length in periods (need not be whole).
    viscous_damping_n_s_m : float
        Viscous damping coefficient c, N s/m.
    coulomb_friction_n : float
        Coulomb friction force F_c, N.
    force_harmonics_n : tuple of float
        Amplitudes d_2, d_3, ... of force harmonics k = 2, 3, ... (no power), N; their phases
        are fixed (psi_k = 0.7 k rad).
    phase_rad : float
        Phase of the velocity, rad.
    force_offset_n, velocity_offset_m_s : float
        DC offsets of the recorded channels.
    snr_db : float, optional
        Signal-to-noise ratio of every channel (rms of the signal / rms of white noise), dB.
    velocity_delay_s : float
        The velocity channel records v(t - delay).
    wander_fraction, wander_frequency_hz, wander_phase_rad : float
        A slow sine added to every recorded channel, of ``wander_fraction`` times that
        channel's amplitude (sqrt(2) x rms of its noise-free signal), at ``wander_frequency_hz``
        (well below the drive) and phase ``wander_phase_rad`` in the force channel
        (+1.3 rad in the velocity, +2.6 rad in the acceleration: the channels wander apart).
    with_acceleration : bool
        Also return an acceleration channel dv/dt (with its own noise).
    seed : int
        Seed of the noise.

    Examples
    --------
    >>> rec = synthesize_shaker_record(mass_kg=1.0, acceleration_amplitude_m_s2=9.81,
    ...                                frequency_hz=100.0, sample_rate_hz=10000.0, n_periods=10)
    >>> rec.force_n.shape
    (1000,)
    """
    if not (frequency_hz > 0 and sample_rate_hz > 2 * frequency_hz):
        raise ParameterError(f"frequency_hz {frequency_hz!r} must be in (0, sample_rate/2)")
    if n_periods <= 0:
        raise ParameterError(f"n_periods: {n_periods!r}, expected > 0")
    if not (wander_fraction >= 0 and 0 < wander_frequency_hz < frequency_hz / 2):
        raise ParameterError(f"wander_fraction {wander_fraction!r} must be >= 0 and "
                             f"wander_frequency_hz {wander_frequency_hz!r} in (0, drive/2)")
    rng = np.random.default_rng(seed)
    n = int(round(n_periods * sample_rate_hz / frequency_hz))
    t = np.arange(n) / sample_rate_hz
    w = 2 * np.pi * frequency_hz
    amp_v = acceleration_amplitude_m_s2 / w
    arg = w * t + phase_rad
    v = amp_v * np.sin(arg)
    acc = acceleration_amplitude_m_s2 * np.cos(arg)
    force = mass_kg * acc + viscous_damping_n_s_m * v + coulomb_friction_n * np.sign(v)
    for k, d in enumerate(force_harmonics_n, start=2):
        force += d * np.sin(k * arg + 0.7 * k)
    v_meas = amp_v * np.sin(w * (t - velocity_delay_s) + phase_rad)

    def wander(signal: np.ndarray, phase: float) -> np.ndarray:
        if not wander_fraction:
            return np.zeros_like(signal)
        amplitude = wander_fraction * math.sqrt(2.0 * float(np.mean(signal**2)))
        return amplitude * np.sin(2 * np.pi * wander_frequency_hz * t + phase)

    force_out = force + force_offset_n + _noise(rng, force, snr_db) \
        + wander(force, wander_phase_rad)
    vel_out = v_meas + velocity_offset_m_s + _noise(rng, v_meas, snr_db) \
        + wander(v_meas, wander_phase_rad + 1.3)
    acc_out = acc + _noise(rng, acc, snr_db) + wander(acc, wander_phase_rad + 2.6) \
        if with_acceleration else None
    return SyntheticRecord(force_n=force_out, velocity_m_s=vel_out, acceleration_m_s2=acc_out,
                           sample_rate_hz=float(sample_rate_hz), frequency_hz=float(frequency_hz))
