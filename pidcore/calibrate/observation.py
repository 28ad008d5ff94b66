"""Observation model: the SDC a shaker test of the DEM's coupon would measure (Eq. 11).

A measured SDC is 2 pi Re(P_c) / Im(P_c), with P_c = 1/2 F V* at the drive frequency from the
force gauge and the driving-point velocity. The DEM's virtual shaker gives the same for the
particles: the force the walls exert on the particle bed (``wall_force_n``) against the coupon
velocity (``velocity_m_s``), analysed by :func:`pidcore.signal.analyze_power`. Divided by
1/2 omega |V|^2 both parts are masses:

* ``dissipative_mass_kg`` d = Re(P_particles) / (1/2 omega |V|^2), and
* ``reactive_mass_kg``   m_p = Im(P_particles) / (1/2 omega |V|^2) (the particles' share of
  the moving mass: all of it for a bed locked to the cell, less when it flies).

The structure above the gauge (coupon face sheets + core ``coupon_mass_kg`` and the fixture,
``fixture_mass_kg``) adds its inertia omega m_s |V|^2 / 2 to Im(P_c) and, with a structural
loss factor eta_0 of the empty structure, eta_0 times that to Re(P_c). Hence::

    SDC = 2 pi (d + eta_0 m_s) / (m_p + m_s),   m_s = coupon_mass_kg + fixture_mass_kg

Fixture mass and eta_0 therefore need no new DEM run. This is not the DEM's Eq. 10 SDC with an
assumed m_c: where the bed flies, m_p is well below the particle mass and the two differ by 2x
and more.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..dem.persist import record_coupon_mass_kg
from ..errors import SimulationError


@dataclass(frozen=True)
class Observation:
    """Virtual shaker test of one DEM run, as masses (kg) that combine with the structure.

    ``*_stderr_kg``: standard errors of the DEM ensemble (dissipation: across the simulated
    cells; reactive mass: across blocks of whole periods of the cell-mean record).
    """

    frequency_hz: float
    acceleration_g: float
    fill_percent: float
    dissipative_mass_kg: float
    dissipative_mass_stderr_kg: float
    reactive_mass_kg: float
    reactive_mass_stderr_kg: float
    coupon_mass_kg: float
    energy_per_cycle_j: float

    def sdc(self, fixture_mass_kg: float | np.ndarray = 0.0,
            baseline_loss_factor: float | np.ndarray = 0.0) -> np.ndarray:
        """Predicted measured SDC (Eq. 11) for a fixture mass (kg) and a baseline loss factor."""
        structure = self.coupon_mass_kg + np.asarray(fixture_mass_kg, dtype=float)
        return 2 * math.pi * (self.dissipative_mass_kg + np.asarray(baseline_loss_factor)
                              * structure) / (self.reactive_mass_kg + structure)


def _fundamental_power(force: np.ndarray, velocity: np.ndarray, omega: float,
                       sample_rate_hz: float) -> complex:
    """1/2 F_1 conj(V_1) of records holding whole periods (least squares on sin/cos + DC)."""
    t = np.arange(len(force)) / sample_rate_hz
    basis = np.column_stack([np.ones_like(t), np.cos(omega * t), np.sin(omega * t)])
    cf = np.linalg.lstsq(basis, force, rcond=None)[0]
    cv = np.linalg.lstsq(basis, velocity, rcond=None)[0]
    f1 = cf[1] - 1j * cf[2]
    v1 = cv[1] - 1j * cv[2]
    return 0.5 * f1 * np.conj(v1)


def observation_from_run(record: dict, arrays: dict, *, n_blocks: int = 8,
                         coupon_mass_kg: float | None = None) -> Observation:
    """Observation of a stored DEM run (record and arrays as :func:`dem_run_entry` writes them).

    ``coupon_mass_kg``: the structure's mass without the fixture (the calibration adds its own
    fixture mass); default: the run's coupon (:func:`pidcore.dem.persist.record_coupon_mass_kg`,
    which also reads runs stored when ``coupon_mass_kg`` held coupon + fixture).

    The central complex power goes through :func:`pidcore.signal.analyze_power` (the same
    Eq. 11 code as a measurement); the reactive mass's standard error comes from ``n_blocks``
    blocks of whole periods, the dissipation's from the per-cell SDCs.
    """
    from ..signal import analyze_power

    f = float(record["frequency_hz"])
    omega = 2 * math.pi * f
    spc = int(round(float(record["sample_rate_hz"]) / f))
    start = int(record["steady_start_cycle"]) * spc
    force = np.asarray(arrays["wall_force_n"], dtype=float)[start:]
    velocity = np.asarray(arrays["velocity_m_s"], dtype=float)[start:]
    fs = float(record["sample_rate_hz"])
    # the particles' wall force alone: its reactive part may be either sign (a bed moving
    # against the walls); the coupon's and the fixture's inertia are added by the caller
    power = analyze_power(force, velocity, fs, frequency_hz=f, n_harmonics=1, n_blocks=0,
                          source=f"DEM run at {f:g} Hz, {float(record['acceleration_g']):g} g",
                          require_mass_like=False)
    p = complex(power.complex_power_w)
    v_amp = float(power.velocity_amplitude_m_s)
    if not (v_amp > 0 and np.isfinite(p.real) and np.isfinite(p.imag)):
        raise SimulationError(f"DEM run at {f:g} Hz: no virtual shaker record to analyse")
    scale = 0.5 * omega * v_amp**2
    cycles = len(force) // spc
    per = max(cycles // n_blocks, 1)
    blocks = [_fundamental_power(force[i * per * spc:(i + 1) * per * spc],
                                 velocity[i * per * spc:(i + 1) * per * spc], omega, fs)
              for i in range(cycles // per)]
    nb = len(blocks)
    im_se = float(np.std([b.imag for b in blocks], ddof=1) / math.sqrt(nb)) if nb > 1 else 0.0
    re_se_blocks = float(np.std([b.real for b in blocks], ddof=1) / math.sqrt(nb)) \
        if nb > 1 else 0.0
    # per-cell dissipation: SDC_cell x E_max is the cell's coupon-equivalent energy per cycle
    cells = np.asarray(arrays["sdc_per_cell"], dtype=float) * float(record["max_kinetic_energy_j"])
    re_se_cells = float(np.std(cells, ddof=1) / math.sqrt(len(cells)) * f) \
        if len(cells) > 1 else 0.0
    return Observation(
        frequency_hz=f, acceleration_g=float(record["acceleration_g"]),
        fill_percent=float(record["fill_percent"]),
        dissipative_mass_kg=p.real / scale,
        dissipative_mass_stderr_kg=max(re_se_cells, re_se_blocks) / scale,
        reactive_mass_kg=p.imag / scale, reactive_mass_stderr_kg=im_se / scale,
        coupon_mass_kg=float(record_coupon_mass_kg(record) if coupon_mass_kg is None
                             else coupon_mass_kg),
        energy_per_cycle_j=float(record["energy_per_cycle_j"]))
