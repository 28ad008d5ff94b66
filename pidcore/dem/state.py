"""Particle state arrays of K cells, energy bookkeeping, and the chunked kernel call."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import defaults
from ..constants import DRIVE_DIRECTIONS, STANDARD_GRAVITY
from ..errors import SimulationError
from .contact import LAW_ROLLING_STIFFNESS, ContactLaw, check_tangential_model
from .geometry import WALL_NAMES, CellGeometry
from .kernel import (
    N_HISTORY,
    N_TALLIES,
    STATUS_ESCAPED,
    STATUS_NONFINITE,
    STATUS_OK,
    STATUS_OVERLAP,
    advance_cells,
    contact_energy,
)

#: Array index of each drive direction (``DRIVE_DIRECTIONS`` is ordered z, x, y).
AXIS_INDEX: dict[str, int] = {"x": 0, "y": 1, "z": 2}


@dataclass
class CellsState:
    """Mutable structure-of-arrays state of K cells of N particles (SI units).

    ``pos``, ``vel``, ``omg``, ``frc``, ``trq`` have shape (3, K, N); ``step`` counts steps
    since the drive clock's origin (t = step * dt). ``spring_pp`` (K, N, N, N_HISTORY; entry
    [i, j] with i < j) and ``spring_pw`` (K, N, walls, N_HISTORY) hold each contact's history
    (slots ``HIST_*`` of :mod:`pidcore.dem.kernel`: tangential spring stretch, m, sliding
    flag, its k_t, N/m, rolling spring angle, rad; all zero where there is no contact).
    """

    pos: np.ndarray
    vel: np.ndarray
    omg: np.ndarray
    frc: np.ndarray
    trq: np.ndarray
    spring_pp: np.ndarray
    spring_pw: np.ndarray
    step: int = 0

    @staticmethod
    def bytes_per_cell(particles: int) -> int:
        """Bytes one cell of :meth:`from_positions`'s arrays takes: five 3-vectors per
        particle and the history of every pair and particle-wall slot."""
        return 8 * (15 * particles + N_HISTORY * particles * (particles + len(WALL_NAMES)))

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
                   spring_pp=np.zeros((k, n, n, N_HISTORY)),
                   spring_pw=np.zeros((k, n, len(WALL_NAMES), N_HISTORY)))

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


def law_vectors(law: ContactLaw) -> tuple[np.ndarray, np.ndarray]:
    """Kernel parameter vectors (particle pairs, walls) of a contact law."""
    mindlin = law.tangential_stiffness_model == "mindlin"
    return (law.pair_particle.kernel_vector(mindlin=mindlin),
            law.pair_wall.kernel_vector(mindlin=mindlin))


def energies(state: CellsState, law: ContactLaw, geometry: CellGeometry, *,
             wall_offset_m: np.ndarray, gravity_m_s2: float) -> np.ndarray:
    """Per-cell mechanical energy, (K, 4): kinetic (incl. rotation), potential, elastic, sum; J.

    ``wall_offset_m`` is the (3,) displacement of the cell at the state's time. The potential
    energy is m g z of the particle centres (absolute z); the elastic energy is the Hertz
    energy of the overlaps plus that of the tangential and rolling springs
    (:func:`pidcore.dem.kernel.contact_energy`, the same laws as the kernel's).
    """
    m = law.mass_kg
    ke = 0.5 * m * np.sum(state.vel**2, axis=(0, 2)) \
        + 0.5 * law.inertia_kg_m2 * np.sum(state.omg**2, axis=(0, 2))
    pe = m * gravity_m_s2 * np.sum(state.pos[2], axis=1)
    elastic = contact_energy(state.pos, state.spring_pp, state.spring_pw,
                             geometry.wall_normals, geometry.wall_offsets,
                             np.asarray(wall_offset_m, dtype=float), law.radius_m,
                             *law_vectors(law))
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


def _advance_on_threads(args: tuple, n_cells: int) -> None:
    """Run the kernel over all cells, in contiguous slices on ``numba.get_num_threads()``
    threads (the kernel releases the GIL; each thread writes only its own cells)."""
    import numba

    n_threads = max(min(numba.get_num_threads(), n_cells), 1)
    if n_threads == 1:
        advance_cells(*args, np.int64(0), np.int64(n_cells))
        return
    from concurrent.futures import ThreadPoolExecutor

    bounds = [round(n_cells * t / n_threads) for t in range(n_threads + 1)]

    with ThreadPoolExecutor(max_workers=n_threads, thread_name_prefix="pidcore-dem") as pool:
        futures = [pool.submit(advance_cells, *args, np.int64(lo), np.int64(hi))
                   for lo, hi in zip(bounds[:-1], bounds[1:], strict=True)]
        for future in futures:
            future.result()


def advance(state: CellsState, settings: KernelSettings, n_steps: int, *,
            steps_per_cycle: int | None = None, sample_every: int | None = None
            ) -> tuple[np.ndarray, np.ndarray]:
    """Advance all cells ``n_steps``; returns (tally (K, cycles, N_TALLIES) in J, samples (K, S)
    in N). Tally columns: walls' work, normal damping, friction, rolling resistance.

    ``samples`` are interval means of the drive-axis force of the walls on the particles.
    Raises SimulationError when a cell becomes unphysical.
    """
    spc = n_steps if steps_per_cycle is None else int(steps_per_cycle)
    se = n_steps if sample_every is None else int(sample_every)
    spc = max(spc, 1)
    se = max(se, 1)
    law = settings.law
    law_pp, law_pw = law_vectors(law)
    g = settings.geometry
    k = state.n_cells
    tally = np.zeros((k, max(-(-n_steps // spc), 1), N_TALLIES))
    samples = np.zeros((k, max(-(-n_steps // se), 1)))
    status = np.zeros(k, dtype=np.int64)
    fail_step = np.zeros(k, dtype=np.int64)
    args = (state.pos, state.vel, state.omg, state.frc, state.trq,
            g.wall_normals, g.wall_offsets,
            law.radius_m, law.mass_kg, law.inertia_kg_m2, law_pp, law_pw,
            settings.friction_regularisation_m_s, settings.clip_attraction,
            settings.gravity_m_s2, settings.tangential_model == "stick_slip",
            bool(law_pp[LAW_ROLLING_STIFFNESS] > 0 or law_pw[LAW_ROLLING_STIFFNESS] > 0),
            state.spring_pp, state.spring_pw,
            settings.dt_s, np.int64(state.step), np.int64(n_steps),
            settings.omega_rad_s, settings.accel_m_s2,
            AXIS_INDEX[settings.direction],
            np.int64(spc), np.int64(se), settings.max_overlap_fraction,
            tally, samples, status, fail_step)
    _advance_on_threads(args, k)
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
