"""Synthetic shaker-test exports for the app tests (a mass-damper driven at constant amplitude).

A rigid mass ``m`` with a viscous damper ``c`` moving with velocity ``V sin(wt)`` needs the force
``F = m V w cos(wt) + c V sin(wt)``. Its complex power gives the analytic truth: loss factor
``eta = c / (m w)`` and specific damping capacity ``SDC = 2 pi eta`` (energy dissipated per cycle
``pi c w X^2`` over the peak kinetic energy ``m V^2 / 2``).
"""

from __future__ import annotations

import math

import numpy as np

from pidcore.constants import STANDARD_GRAVITY

MASS_KG = 0.3


def damper_for(loss_factor: float, frequency_hz: float, mass_kg: float = MASS_KG) -> float:
    """Viscous coefficient, N s/m, that gives ``loss_factor`` at ``frequency_hz``."""
    return loss_factor * mass_kg * 2 * math.pi * frequency_hz


def mass_damper_csv(*, frequency_hz: float = 100.0, acceleration_g: float = 5.0,
                    loss_factor: float = 0.05, sample_rate_hz: float = 10_000.0,
                    duration_s: float = 1.0, noise: float = 1e-3, seed: int = 1,
                    extra_velocity_phase_rad: float | None = None,
                    velocity_late_s: float = 0.0) -> bytes:
    """CSV bytes ``Time [s],Force [N],Velocity [m/s]`` of a driven mass-damper.

    ``velocity_late_s``: the velocity column recorded that much after the motion (a
    vibrometer's output delay nobody corrected).

    ``extra_velocity_phase_rad`` adds a second velocity column ``Velocity 2 [m/s]`` shifted by
    that phase (a mis-mapped channel for the mapping tests).
    """
    w = 2 * math.pi * frequency_hz
    v_amp = acceleration_g * STANDARD_GRAVITY / w
    c = damper_for(loss_factor, frequency_hz)
    t = np.arange(int(round(duration_s * sample_rate_hz))) / sample_rate_hz
    v = v_amp * np.sin(w * t)
    f = MASS_KG * v_amp * w * np.cos(w * t) + c * v
    v = v_amp * np.sin(w * (t - velocity_late_s))
    rng = np.random.default_rng(seed)
    f = f + noise * np.max(np.abs(f)) * rng.standard_normal(t.size)
    v = v + noise * v_amp * rng.standard_normal(t.size)
    columns = [t, f, v]
    header = "Time [s],Force [N],Velocity [m/s]"
    if extra_velocity_phase_rad is not None:
        columns.append(v_amp * np.sin(w * t + extra_velocity_phase_rad))
        header += ",Velocity 2 [m/s]"
    body = "\n".join(",".join(f"{x:.9e}" for x in row) for row in zip(*columns, strict=True))
    return (header + "\n" + body + "\n").encode()


def analytic_sdc(loss_factor: float) -> float:
    return 2 * math.pi * loss_factor
