"""Eq. 2's head-on impact integrated by scipy, independent of the DEM kernel, for the
restitution tests of the impact calibration."""

from __future__ import annotations

import math

from scipy.integrate import solve_ivp


def hertz_tsuji_restitution(stiffness: float, mass_kg: float, alpha: float,
                            speed_m_s: float) -> float:
    """Restitution of Eq. 2's head-on impact with clipped (no_attraction) damping, integrated
    by scipy to separation: m x'' = -max(k x^1.5 + alpha sqrt(m k) x^0.25 x', 0), independent
    of the kernel."""
    c = alpha * math.sqrt(mass_kg * stiffness)

    def rhs(_t, y):
        x, v = y
        force = max(stiffness * x**1.5 + c * x**0.25 * v, 0.0) if x > 0 else 0.0
        return [v, -force / mass_kg]

    def left(_t, y):
        return y[0]

    left.terminal, left.direction = True, -1
    t_c = 3.22 * (mass_kg**2 / (stiffness**2 * speed_m_s)) ** 0.2  # Hertz contact time
    out = solve_ivp(rhs, [0, 100 * t_c], [0.0, speed_m_s], events=left, rtol=1e-10,
                    atol=1e-16 * speed_m_s * t_c, max_step=t_c / 200)
    return -out.y_events[0][0][1] / speed_m_s
