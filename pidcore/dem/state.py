"""Particle state arrays of K cells, energy bookkeeping, and the chunked kernel call."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import defaults
from ..constants import DRIVE_DIRECTIONS, STANDARD_GRAVITY
from ..errors import SimulationError
from .contact import ContactLaw, check_tangential_model
from .geometry import WALL_NAMES, CellGeometry
from .kernel import (
    N_TALLIES,
    STATUS_ESCAPED,
    STATUS_NONFINITE,
    STATUS_OK,
    STATUS_OVERLAP,
    advance_cells,
)

#: Array index of each drive direction (``DRIVE_DIRECTIONS`` is ordered z, x, y).
AXIS_INDEX: dict[str, int] = {"x": 0, "y": 1, "z": 2}


@dataclass
class CellsState:
    """Mutable structure-of-arrays state of K cells of N particles (SI units).

    ``pos``, ``vel``, ``omg``, ``frc``, ``trq`` have shape (3, K, N); ``step`` counts steps
    since the drive clock's origin (t = step * dt). ``spring_pp`` (3, K, N, N; entry [i, j]
    with i < j) and ``spring_pw`` (3, K, N, walls) hold the stretch of the tangential contact
    springs of the stick-slip model, m (zero where there is no contact).
    """

    pos: np.ndarray
    vel: np.ndarray
    omg: np.ndarray
    frc: np.ndarray
    trq: np.ndarray
    spring_pp: np.ndarray
    spring_pw: np.ndarray
    step: int = 0

    @classmethod
    def from_positions(cls, positions: np.ndarray, *, mass_kg: float,
                       gravity_m_s2: float = STANDARD_GRAVITY) -> CellsState:
        """State at rest from (K, N, 3) centres; the start force is gravity alone.

        Raises SimulationError if any two particles overlap (the start must be contact-free;
        checked by the caller against the walls, see :func:`assert_no_overlap`).
        """
        pos = np.ascontiguousarray(np.moveaxis(np.asarray(positions, dtype=float), -1, 0))
        zeros = np.zeros_like(pos)
        frc = zeros.copy()
        frc[2] = -mass_kg * gravity_m_s2
        k, n = pos.shape[1], pos.shape[2]
        return cls(pos=pos, vel=zeros.copy(), omg=zeros.copy(), frc=frc, trq=zeros.copy(),
                   spring_pp=np.zeros((3, k, n, n)),
                   spring_pw=np.zeros((3, k, n, len(WALL_NAMES))))

    @property
    def n_cells(self) -> int:
        return self.pos.shape[1]

    @property
    def n_particles(self) -> int:
        return self.pos.shape[2]

    def copy(self) -> CellsState:
        return CellsState(self.pos.copy(), self.vel.copy(), self.omg.copy(), self.frc.copy(),
                          self.trq.copy(), self.spring_pp.copy(), self.spring_pw.copy(),
                          self.step)


def wall_displacement(t_s, *, accel_m_s2: float, omega_rad_s: float):
    """Cell displacement u(t) = -(a/w^2) sin(w t) (so that u'' = a sin(w t)), m."""
    if omega_rad_s <= 0:
        return np.zeros_like(np.asarray(t_s, dtype=float))
    return -accel_m_s2 / omega_rad_s**2 * np.sin(omega_rad_s * np.asarray(t_s))


def wall_velocity(t_s, *, accel_m_s2: float, omega_rad_s: float):
    """Cell velocity u'(t) = -(a/w) cos(w t), m/s."""
    if omega_rad_s <= 0:
        return np.zeros_like(np.asarray(t_s, dtype=float))
    return -accel_m_s2 / omega_rad_s * np.cos(omega_rad_s * np.asarray(t_s))


def energies(state: CellsState, law: ContactLaw, geometry: CellGeometry, *,
             wall_offset_m: np.ndarray, gravity_m_s2: float) -> np.ndarray:
    """Per-cell mechanical energy, (K, 4): kinetic (incl. rotation), potential, elastic, sum; J.

    ``wall_offset_m`` is the (3,) displacement of the cell at the state's time. The potential
    energy is m g z of the particle centres (absolute z); the elastic energy is the Hertz
    energy of the overlaps plus 1/2 k_t |xi|^2 of the tangential springs.
    """
    m = law.mass_kg
    ke = 0.5 * m * np.sum(state.vel**2, axis=(0, 2)) \
        + 0.5 * law.inertia_kg_m2 * np.sum(state.omg**2, axis=(0, 2))
    pe = m * gravity_m_s2 * np.sum(state.pos[2], axis=1)
    p = np.moveaxis(state.pos, 0, -1)  # (K, N, 3)
    dist = geometry.signed_distances(p - wall_offset_m)
    u_wall = 0.4 * law.pair_wall.stiffness * np.maximum(law.radius_m - dist, 0.0) ** 2.5
    diff = p[:, :, None, :] - p[:, None, :, :]
    d = np.sqrt(np.sum(diff**2, axis=-1))
    overlap = np.maximum(2 * law.radius_m - d, 0.0)
    overlap[:, np.arange(p.shape[1]), np.arange(p.shape[1])] = 0.0
    u_pair = 0.5 * np.sum(0.4 * law.pair_particle.stiffness * overlap**2.5, axis=(1, 2))
    u_spring = (0.5 * law.pair_particle.tangential_stiffness
                * np.sum(state.spring_pp**2, axis=(0, 2, 3))
                + 0.5 * law.pair_wall.tangential_stiffness
                * np.sum(state.spring_pw**2, axis=(0, 2, 3)))
    elastic = np.sum(u_wall, axis=(1, 2)) + u_pair + u_spring
    return np.column_stack([ke, pe, elastic, ke + pe + elastic])


def assert_no_overlap(positions: np.ndarray, radius_m: float, geometry: CellGeometry) -> None:
    """Raise SimulationError if any particle of (K, N, 3) centres touches another or a wall."""
    p = np.asarray(positions)
    if np.any(geometry.signed_distances(p) < radius_m):
        raise SimulationError("start state: a particle overlaps a cell wall")
    d = np.sqrt(np.sum((p[:, :, None, :] - p[:, None, :, :]) ** 2, axis=-1))
    n = p.shape[1]
    d[:, np.arange(n), np.arange(n)] = np.inf
    if np.any(d < 2 * radius_m):
        raise SimulationError("start state: two particles overlap")


@dataclass(frozen=True)
class KernelSettings:
    """Everything the kernel needs besides the state (SI units)."""

    law: ContactLaw
    geometry: CellGeometry
    dt_s: float
    omega_rad_s: float = 0.0
    accel_m_s2: float = 0.0
    direction: str = "z"
    gravity_m_s2: float = STANDARD_GRAVITY
    clip_attraction: bool = True
    tangential_model: str = defaults.DEM_TANGENTIAL_MODEL
    friction_regularisation_m_s: float = defaults.DEM_FRICTION_REGULARISATION_SPEED_M_S
    max_overlap_fraction: float = defaults.DEM_MAX_OVERLAP_FRACTION

    def __post_init__(self):
        if self.direction not in DRIVE_DIRECTIONS:
            raise SimulationError(f"direction: expected one of {DRIVE_DIRECTIONS}")
        check_tangential_model(self.tangential_model)


def advance(state: CellsState, settings: KernelSettings, n_steps: int, *,
            steps_per_cycle: int | None = None, sample_every: int | None = None
            ) -> tuple[np.ndarray, np.ndarray]:
    """Advance all cells ``n_steps``; returns (tally (K, cycles, 3) in J, samples (K, S) in N).

    ``samples`` are interval means of the drive-axis force of the walls on the particles.
    Raises SimulationError when a cell becomes unphysical.
    """
    spc = n_steps if steps_per_cycle is None else int(steps_per_cycle)
    se = n_steps if sample_every is None else int(sample_every)
    spc = max(spc, 1)
    se = max(se, 1)
    law = settings.law
    pp, pw = law.pair_particle, law.pair_wall
    g = settings.geometry
    k = state.n_cells
    tally = np.zeros((k, max(-(-n_steps // spc), 1), N_TALLIES))
    samples = np.zeros((k, max(-(-n_steps // se), 1)))
    status = np.zeros(k, dtype=np.int64)
    fail_step = np.zeros(k, dtype=np.int64)
    advance_cells(state.pos, state.vel, state.omg, state.frc, state.trq,
                  g.wall_normals, g.wall_offsets,
                  law.radius_m, law.mass_kg, law.inertia_kg_m2,
                  pp.stiffness, pp.damping, pp.sliding_friction, pp.tangential_mass_kg,
                  pw.stiffness, pw.damping, pw.sliding_friction, pw.tangential_mass_kg,
                  settings.friction_regularisation_m_s, settings.clip_attraction,
                  settings.gravity_m_s2,
                  settings.tangential_model == "stick_slip", pp.tangential_stiffness,
                  pw.tangential_stiffness, state.spring_pp, state.spring_pw,
                  settings.dt_s, np.int64(state.step), np.int64(n_steps),
                  settings.omega_rad_s, settings.accel_m_s2,
                  AXIS_INDEX[settings.direction],
                  np.int64(spc), np.int64(se), settings.max_overlap_fraction,
                  tally, samples, status, fail_step)
    state.step += n_steps
    if np.any(status != STATUS_OK):
        c = int(np.flatnonzero(status != STATUS_OK)[0])
        t = fail_step[c] * settings.dt_s
        why = {STATUS_OVERLAP: f"overlap above {settings.max_overlap_fraction:.0%} of the "
                               "radius (time step too large or impact too fast)",
               STATUS_ESCAPED: "a particle left its cell (time step too large)",
               STATUS_NONFINITE: "non-finite positions"}[int(status[c])]
        raise SimulationError(f"DEM cell {c} at t = {t:.6g} s: {why}; try a smaller "
                              f"time step than {settings.dt_s:.3g} s")
    samples /= se
    return tally, samples
