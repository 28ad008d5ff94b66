"""One DEM load case: settle, drive, detect steady state, tally energy, compute the SDC.

:func:`simulate_load_case` is a pure function of a :class:`LoadCase` and a :class:`DemConfig`
(same inputs and seed -> same result, whatever the thread count), so a sweep can map it over a
grid.

Method (choices and why):

* **Specimen.** Cell, coupon and fixture masses, particles and contact pairs come from a
  :class:`~pidcore.specimen.Specimen` (default: the paper's coupon,
  ``pidcore/data/specimens/paper_coupon.toml``, with ``case.material`` particles).
* **Cells.** K independent cells (default 8, different random packings from one seed) stand
  for the coupon's identical cells (the specimen's ``[cell] count``, 441 for the paper's);
  coupon energies are that count x the K-cell mean, and the SDC's standard error is taken
  across the K cells.
* **Fill.** 100 % is the cell's capacity: spheres dropped one by one, each to the lowest rest
  position on a fine grid of centres (:func:`~pidcore.dem.geometry.cell_capacity`; 22 acrylic
  r = 1.25 mm, 55 aluminium r = 1 mm in the 4.76 x 25.4 mm cell). The paper's 36 particles
  = 100 % (``fill_reference="paper"``) is refused where 36 do not fit (acrylic: the particle
  centres are confined to a hexagon of apothem 1.13 mm, two spheres per layer at most).
* **Start.** Random non-overlapping drop packings (asserted), settled under gravity in the
  resting cell until every cell's kinetic energy < DEM_SETTLE_KINETIC_FRACTION x N m g r;
  with ``start_packing="dense"`` (default) first without friction (the bed slides into the
  densest state gravity gives), then again with friction; ``"loose"`` settles once, with
  friction, and such a bed keeps compacting under a 1 g drive. Then the drive starts with
  the particles moving with the cell (``start_protocol="with_cell"``, no start jolt) or at
  rest.
* **Time step.** ``"auto"`` = min(2e-6 s, t_contact / 10) with t_contact the Hertz contact time
  at the largest expected impact speed 2 a/w + sqrt(2 g h) (particle and wall moving
  oppositely at the drive's velocity amplitude, plus a free fall over the cell height); an
  explicit step above that is refused. The step is then shortened slightly so that a drive
  period holds a whole number of sample intervals (DEM_SAMPLES_PER_CYCLE per cycle).
* **Steady state.** Blocks of DEM_STEADY_BLOCK_CYCLES cycles: steady once successive block
  means of the dissipation agree and the walls' work balances the dissipation in both blocks
  (:func:`_steady_start`), at most DEM_MAX_TRANSIENT_CYCLES and DEM_MAX_TRANSIENT_TIME_S
  skipped; at that cap the cycles skipped are judged against their scatter
  (:func:`_steady_by_scatter`: no trend of the stored energy, no change of the dissipation)
  and the run is flagged not converged where they fail that too. Measured window:
  DEM_MIN_STEADY_CYCLES cycles (80: 1.6 s at 50 Hz).
* **SDC.** Eq. 8-10: steady dissipation per cycle over E = m_c a^2 / (2 w^2), m_c per
  ``vibrated_mass`` (default: coupon face sheets + core + all particles of the 441 cells).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from .. import defaults, interrupt
from ..constants import (
    DAMPING_COEFFICIENTS,
    FILL_REFERENCES,
    PARTICLE_MATERIALS,
    STANDARD_GRAVITY,
    START_PACKINGS,
    START_PROTOCOLS,
    VIBRATED_MASS_CONVENTIONS,
    NormalDampingMode,
    StartPacking,
    StartProtocol,
    TangentialModel,
    VibratedMassConvention,
)
from ..errors import (
    ParameterError,
    SimulationError,
    instance_of,
    real_number,
    whole_number,
)
from ..loadcase import LoadCase
from ..specimen import (
    Specimen,
    contact_law,
    paper_specimen,
    particles_for_fill,
    vibrated_mass_by_convention,
)
from .contact import ContactLaw, check_damping_mode, check_tangential_model
from .geometry import CellGeometry, cell_capacity, random_packing
from .result import DemResult
from .state import (
    AXIS_INDEX,
    CellsState,
    KernelSettings,
    advance,
    assert_no_overlap,
    energies,
    law_vectors,
    wall_displacement,
)


@dataclass(frozen=True, kw_only=True)
class DemConfig:
    """Numerical settings of a DEM run (defaults in :mod:`pidcore.defaults`).

    ``steady_cycles=None``: measure DEM_MIN_STEADY_CYCLES cycles (at least one block).
    ``time_step``: seconds, or ``"auto"`` = min(2e-6 s, t_contact / DEM_MIN_STEPS_PER_CONTACT).
    The step actually used is shortened slightly so that a drive period is a whole number of
    sample intervals. ``tangential_model`` and ``start_packing``: see the module docstring
    and :mod:`pidcore.dem.contact`.
    """

    cells: int = defaults.DEM_CELLS
    seed: int = defaults.DEM_SEED
    time_step: float | str = defaults.DEM_TIME_STEP_MODE
    normal_damping_mode: NormalDampingMode = defaults.DEM_NORMAL_DAMPING_MODE
    vibrated_mass: VibratedMassConvention = defaults.DEM_VIBRATED_MASS_CONVENTION
    start_protocol: StartProtocol = defaults.DEM_START_PROTOCOL
    start_packing: StartPacking = defaults.DEM_START_PACKING
    fill_reference: str = defaults.DEM_FILL_REFERENCE
    steady_cycles: int | None = None
    block_cycles: int = defaults.DEM_STEADY_BLOCK_CYCLES
    steady_relative_tolerance: float = defaults.DEM_STEADY_RELATIVE_TOLERANCE
    max_transient_cycles: int = defaults.DEM_MAX_TRANSIENT_CYCLES
    max_transient_s: float = defaults.DEM_MAX_TRANSIENT_TIME_S
    samples_per_cycle: int = defaults.DEM_SAMPLES_PER_CYCLE
    friction_regularisation_m_s: float = defaults.DEM_FRICTION_REGULARISATION_SPEED_M_S
    tangential_model: TangentialModel = defaults.DEM_TANGENTIAL_MODEL
    alpha_pp: float | None = None
    alpha_pw: float | None = None
    damping_coefficient: str = defaults.DEM_DAMPING_COEFFICIENT

    def __post_init__(self) -> None:
        # types first, each named: cells=2.5 ran and cells="4" failed in a comparison
        for name in ("cells", "seed", "block_cycles", "max_transient_cycles",
                     "samples_per_cycle", *(("steady_cycles",) if self.steady_cycles is not None
                                             else ())):
            object.__setattr__(self, name, whole_number(name, getattr(self, name)))
        for name in ("steady_relative_tolerance", "max_transient_s",
                     "friction_regularisation_m_s",
                     *(n for n in ("alpha_pp", "alpha_pw") if getattr(self, n) is not None),
                     *(("time_step",) if not isinstance(self.time_step, str) else ())):
            object.__setattr__(self, name, real_number(name, getattr(self, name)))
        if self.cells < 1:
            raise ParameterError(f"cells: expected >= 1, got {self.cells}")
        if self.seed < 0:  # numpy's generators take no negative seed
            raise ParameterError(f"seed: expected a whole number >= 0, got {self.seed}")
        if self.seed >= 2**63:
            # the same bound, said: "expected a whole number >= 0" of 10^19 (typed in the
            # app's seed field as 1e19) named a rule the value keeps
            raise ParameterError(f"seed: expected a whole number below 2^63 "
                                 f"({2**63}), got {self.seed}")
        check_damping_mode(self.normal_damping_mode)
        check_tangential_model(self.tangential_model)
        for name, value, allowed in (
                ("vibrated_mass", self.vibrated_mass, VIBRATED_MASS_CONVENTIONS),
                ("start_protocol", self.start_protocol, START_PROTOCOLS),
                ("start_packing", self.start_packing, START_PACKINGS),
                ("fill_reference", self.fill_reference, FILL_REFERENCES)):
            if value not in allowed:
                raise ParameterError(f"{name}: expected one of {allowed}, got {value!r}")
        if self.damping_coefficient not in DAMPING_COEFFICIENTS:
            raise ParameterError(f"damping_coefficient: expected one of "
                                 f"{DAMPING_COEFFICIENTS}, got {self.damping_coefficient!r}")
        if isinstance(self.time_step, str):
            if self.time_step != "auto":
                raise ParameterError(f"time_step: expected seconds or 'auto', "
                                     f"got {self.time_step!r}")
        elif not self.time_step > 0:
            raise ParameterError(f"time_step: expected > 0 s, got {self.time_step}")
        if self.steady_cycles is not None and not (
                1 <= self.steady_cycles <= defaults.DEM_MAX_STEADY_CYCLES):
            raise ParameterError(f"steady_cycles: expected 1 .. {defaults.DEM_MAX_STEADY_CYCLES}"
                                 f" cycles, got {self.steady_cycles}")
        if self.block_cycles < 1 or self.max_transient_cycles < 0:
            raise ParameterError("block_cycles >= 1 and max_transient_cycles >= 0 expected")
        if not (math.isfinite(self.max_transient_s) and self.max_transient_s >= 0):
            # inf was an OverflowError of the transient cap's ceil()
            raise ParameterError(f"max_transient_s: expected a finite time >= 0 s, got "
                                 f"{self.max_transient_s}")
        # NaN or a negative tolerance never found a steady state, inf found one at once (an SDC
        # of the transient stored as steady); a NaN, zero or negative regularisation speed and
        # a negative or NaN Eq. 3 constant were simulated, stored in the run's record, or
        # refused as "try a smaller time step"
        if not (math.isfinite(self.steady_relative_tolerance)
                and self.steady_relative_tolerance >= 0):
            raise ParameterError(f"steady_relative_tolerance: expected a finite fraction >= 0, "
                                 f"got {self.steady_relative_tolerance}")
        if not (math.isfinite(self.friction_regularisation_m_s)
                and self.friction_regularisation_m_s > 0):
            raise ParameterError(f"friction_regularisation_m_s: expected a speed > 0 m/s, got "
                                 f"{self.friction_regularisation_m_s}")
        for name in ("alpha_pp", "alpha_pw"):
            alpha = getattr(self, name)
            if alpha is not None and not (math.isfinite(alpha) and alpha >= 0):
                raise ParameterError(f"{name}: expected an Eq. 3 damping constant >= 0 (0: "
                                     f"elastic), got {alpha}")
        if self.samples_per_cycle < 8:
            raise ParameterError(f"samples_per_cycle: expected >= 8, "
                                 f"got {self.samples_per_cycle}")

    def transient_cap_cycles(self, frequency_hz: float) -> int:
        """Most transient cycles skipped at ``frequency_hz``: the cycle and the time caps."""
        return min(self.max_transient_cycles, math.ceil(self.max_transient_s * frequency_hz))


def coupon_mass_kg() -> float:
    """Mass of the paper's empty coupon: two face sheets plus the honeycomb core (Table 2), kg.

    Other specimens state theirs (``[coupon] mass_kg``, :mod:`pidcore.specimen`).
    """
    area = defaults.COUPON_SIDE_M**2
    return (2 * area * defaults.FACE_SHEET_THICKNESS_M * defaults.FACE_SHEET_DENSITY_KG_M3
            + area * defaults.CELL_HEIGHT_M * defaults.CORE_DENSITY_KG_M3)


def vibrated_mass_kg(convention: VibratedMassConvention, *, particles_per_cell: int,
                     particle_mass_kg: float, cells: int = defaults.COUPON_CELLS) -> float:
    """m_c of Eq. 10 of the paper's coupon under a named convention, kg
    (:func:`pidcore.specimen.vibrated_mass_by_convention`)."""
    return vibrated_mass_by_convention(convention, rigid_kg=coupon_mass_kg(),
                                       particles_kg=cells * particles_per_cell
                                       * particle_mass_kg)


def max_impact_speed(case: LoadCase, geometry: CellGeometry) -> float:
    """Largest expected impact speed, m/s: 2 a/w (particle and wall moving oppositely at the
    drive's velocity amplitude) plus free fall over the cell height, sqrt(2 g h)."""
    return (2 * case.acceleration_m_s2 / case.omega_rad_s
            + math.sqrt(2 * STANDARD_GRAVITY * geometry.height_m))


def choose_time_step(case: LoadCase, law: ContactLaw, geometry: CellGeometry,
                     requested: float | str,
                     tangential_model: TangentialModel = defaults.DEM_TANGENTIAL_MODEL) -> float:
    """Check or pick the time step, s (>= DEM_MIN_STEPS_PER_CONTACT steps per contact).

    With the stick-slip model the period of a stuck tangential spring (about the contact
    time) must be resolved as well.
    """
    v = max_impact_speed(case, geometry)
    t_contact = law.contact_time(v)
    what = f"{case.material} contact at the largest expected impact speed {v:.2f} m/s " \
        f"(t_contact {t_contact:.3g} s)"
    if tangential_model == "stick_slip" and law.tangential_period() < t_contact:
        t_contact = law.tangential_period()
        what = f"period of a stuck {case.material} tangential spring ({t_contact:.3g} s)"
    safe = t_contact / defaults.DEM_MIN_STEPS_PER_CONTACT
    automatic = min(defaults.DEM_TIME_STEP_S, safe)
    if requested == "auto":
        return automatic
    if requested > safe:
        raise ParameterError(
            f"time_step {requested:.3g} s gives {t_contact / requested:.2g} steps per "
            f"{what}; need >= {defaults.DEM_MIN_STEPS_PER_CONTACT}: "
            f"use time_step <= {safe:.3g} s or 'auto'")
    shortest = automatic / defaults.DEM_MAX_STEP_SHORTENING
    if requested < shortest:
        # no step-count limit: 1e-15 s (a unit typed twice) ran for ever without a word
        raise ParameterError(
            f"time_step {requested:.3g} s is {automatic / requested:.3g} x shorter than the "
            f"automatic {automatic:.3g} s, and the run as much longer; expected >= "
            f"{shortest:.3g} s (at most {defaults.DEM_MAX_STEP_SHORTENING:g} x shorter), "
            "or 'auto'")
    return float(requested)


def calibrated_contact_law(specimen: Specimen, config: DemConfig, dt_s: float) -> ContactLaw:
    """The specimen's contact law with each pair's alpha calibrated to its stated restitution
    (:func:`pidcore.dem.impact.calibrate_damping_coefficient`): a head-on impact at
    DEM_CALIBRATION_SPEED_M_S in the specimen's cell, at the run's step ``dt_s`` and damping
    mode, gives the stated e_n. An alpha the config states (``alpha_pp``, ``alpha_pw``) is kept.

    Any specimen's: the paper's coupon's law and cell are the tables' and the default cell bit
    for bit, so its alphas are those of the tables' material.
    """
    from .impact import calibrate_damping_coefficient

    geometry = specimen.geometry()
    stated = contact_law(specimen)
    v_cal = defaults.DEM_CALIBRATION_SPEED_M_S
    mode = config.normal_damping_mode
    try:
        return contact_law(
            specimen,
            alpha_pw=config.alpha_pw if config.alpha_pw is not None else
            calibrate_damping_coefficient(
                stated.pair_wall.restitution, "wall", v_cal, dt_s, mode, geometry=geometry,
                law=lambda a: contact_law(specimen, alpha_pp=config.alpha_pp, alpha_pw=a)),
            alpha_pp=config.alpha_pp if config.alpha_pp is not None else
            calibrate_damping_coefficient(
                stated.pair_particle.restitution, "particle", v_cal, dt_s, mode,
                geometry=geometry,
                law=lambda a: contact_law(specimen, alpha_pp=a, alpha_pw=config.alpha_pw)))
    except ParameterError as exc:  # which file's restitution, and which setting asked
        raise ParameterError(f"damping_coefficient='calibrated', specimen {specimen.name!r} "
                             f"({specimen.source}): {exc}") from None


def particles_per_cell(fill_percent: float, material_name: str | None = None, *,
                       specimen: Specimen | None = None,
                       geometry: CellGeometry | None = None,
                       fill_reference: str = defaults.DEM_FILL_REFERENCE,
                       what: str = "fill_percent", typed: bool = False) -> tuple[int, int]:
    """(particles per cell, count taken as 100 %) for a fill percentage.

    The particles and cell are the ``specimen``'s (default: the paper's coupon with
    ``material_name`` particles); ``geometry`` overrides its cell.
    ``fill_reference="capacity"``: 100 % is :func:`~pidcore.dem.geometry.cell_capacity`;
    ``"paper"``: 36 particles, refused when 36 do not fit the cell. ``what``: how a refused
    fill is named, and ``typed`` whether a person wrote it
    (:func:`pidcore.specimen.particles_for_fill`).
    """
    specimen = specimen or paper_specimen(material_name or "acrylic")
    material_name = specimen.particles.material
    if geometry is None:
        geometry = specimen.geometry()
        capacity = specimen.capacity_per_cell()
    else:
        capacity = cell_capacity(geometry, specimen.particles.radius_m)
    if fill_reference == "paper":
        full = defaults.PAPER_PARTICLES_PER_FULL_CELL
        if full > capacity:
            raise ParameterError(
                f"fill_reference='paper': {full} {material_name} particles (r = "
                f"{specimen.particles.radius_m * 1e3:g} mm) do not fit a "
                f"{geometry.inscribed_diameter_m * 1e3:g}"
                f" x {geometry.height_m * 1e3:g} mm cell (capacity {capacity}); use "
                "fill_reference='capacity'")
    elif fill_reference == "capacity":
        full = capacity
    else:
        raise ParameterError(f"fill_reference: expected one of {FILL_REFERENCES}, "
                             f"got {fill_reference!r}")
    # a specimen stating count_per_cell confirms a small typed fill of that count (1 of 441
    # particles is 0.23 %, which reads as a fraction otherwise)
    confirmed = False
    if (typed and fill_reference == "capacity"
            and specimen.particles.count_per_cell is not None):
        try:
            confirmed = (particles_for_fill(fill_percent, full, what=what)
                         == specimen.particles.count_per_cell)
        except ParameterError:
            # refused below as a typed fill, naming the fill a typed one must pass: refused
            # here, untyped, it named one (0.15 %) that was then refused as a fraction
            confirmed = False
    return particles_for_fill(fill_percent, full, what=what,
                              typed=typed and not confirmed), full


def particles_of_stated_fill(fill_percent: float, material: str, *,
                             specimen: Specimen | None = None,
                             what: str = "fill_percent", typed: bool = False) -> int | None:
    """Particles per cell of a measurement's stated fill, in the cell it was tested in: the
    ``specimen``'s where its particles are ``material``, else the paper's coupon's for a table
    material (:data:`~pidcore.constants.PARTICLE_MATERIALS`); None where neither says which
    cell (an own material without its specimen file). A fill that rounds to no particle is
    refused (:func:`~pidcore.specimen.particles_for_fill`, naming it ``what``): the one rule of
    ``pidcore analyze`` and :func:`pidcore.measure.save_analyses`, so that no stored load case
    is one that no DEM run can match."""
    if specimen is not None and material == specimen.particles.material:
        cell = specimen
    elif material in PARTICLE_MATERIALS:
        cell = None  # the paper's coupon with these particles
    else:
        return None
    return particles_per_cell(fill_percent, material, specimen=cell, what=what,
                              typed=typed)[0]


def _kernel_specializations() -> int:
    """Specialisations of the DEM kernel compiled (or loaded from Numba's cache) so far."""
    from .kernel import advance_cells

    return len(advance_cells.overloads)


@dataclass
class _KernelClock:
    """Kernel seconds and particle-steps of the calls that compiled nothing.

    A call in which the kernel gained a specialisation spent most of its time in Numba
    (tens of seconds cold against milliseconds of stepping); counting it would report the
    compiler's speed as the kernel's. Such calls are left out of the throughput and counted.
    """

    seconds: float = 0.0
    particle_steps: int = 0
    compiling_calls: int = 0
    #: told the simulated seconds of each call (the settle's progress line), when set
    on_simulated: Callable[[float], None] | None = None

    def advance(self, state: CellsState, settings: KernelSettings, n_steps: int,
                **kwargs) -> tuple[np.ndarray, np.ndarray]:
        before = _kernel_specializations()
        start = time.perf_counter()
        out = advance(state, settings, n_steps, **kwargs)
        elapsed = time.perf_counter() - start
        if _kernel_specializations() != before:
            self.compiling_calls += 1
        else:
            self.seconds += elapsed
            self.particle_steps += n_steps * state.n_particles * state.n_cells
        if self.on_simulated is not None:
            self.on_simulated(n_steps * settings.dt_s)
        # A Ctrl-C that arrived during the call may have been swallowed on its way out of
        # Numba; where pidcore.interrupt routes SIGINT (the CLI, DEM worker processes), stop
        # here instead of running the case to its end (a sweep's worker kept going ~80 s)
        interrupt.raise_if_interrupted()
        return out


def cycles_per_call(*, steps_per_cycle: int, particles: int, cycles: int,
                    budget: int | None = None) -> int:
    """Whole drive cycles per kernel call of a block of ``cycles``: as many as fit in
    ``budget`` particle-steps (``particles``: of all cells; default
    :data:`pidcore.defaults.DEM_PARTICLE_STEPS_PER_CALL`), at least one, at most the block."""
    if budget is None:
        budget = defaults.DEM_PARTICLE_STEPS_PER_CALL
    per_cycle = max(steps_per_cycle * particles, 1)
    return max(1, min(cycles, budget // per_cycle))


def _drive_block(clock: _KernelClock, state: CellsState, drive: KernelSettings, cycles: int,
                 *, steps_per_cycle: int, sample_every: int,
                 on_cycles: Callable[[int], None] | None = None
                 ) -> tuple[np.ndarray, np.ndarray]:
    """``cycles`` drive cycles in kernel calls of whole cycles (:func:`cycles_per_call`):
    the tally and samples of one call over the whole block, bit for bit.

    The kernel keeps nothing between calls that a call boundary on a cycle boundary changes:
    each cycle's tally and each sample interval start from zero within one call (a sample
    interval divides the cycle), the wall's position is recomputed from the step count, and
    the Verlet lists, rebuilt at each call, keep the brute-force order of contacts. Shorter
    calls only let Ctrl-C in sooner (:meth:`_KernelClock.advance` checks it after each);
    ``on_cycles(n)`` is told of each call's cycles (a progress bar)."""
    per_call = cycles_per_call(steps_per_cycle=steps_per_cycle,
                               particles=state.n_particles * state.n_cells, cycles=cycles)
    tallies, samples = [], []
    done = 0
    while done < cycles:
        n = min(per_call, cycles - done)
        t, s = clock.advance(state, drive, n * steps_per_cycle,
                             steps_per_cycle=steps_per_cycle, sample_every=sample_every)
        tallies.append(t)
        samples.append(s)
        done += n
        if on_cycles is not None:
            on_cycles(n)
    if len(tallies) == 1:
        return tallies[0], samples[0]
    return np.concatenate(tallies, axis=1), np.concatenate(samples, axis=1)


def settle(state: CellsState, settings: KernelSettings, *,
           max_time_s: float = defaults.DEM_MAX_SETTLE_TIME_S,
           kinetic_fraction: float = defaults.DEM_SETTLE_KINETIC_FRACTION,
           clock: _KernelClock | None = None) -> float:
    """Let the particles come to rest under gravity in the resting cell; returns the time, s.

    Ends when every cell's kinetic energy is below ``kinetic_fraction * N m g r``. Spheres
    without rolling resistance can roll about for a long time in a wide cell; after half of
    ``max_time_s`` the velocities are therefore zeroed after every 2 ms chunk (quench) so the
    bed comes to rest in its contacts. Raises SimulationError if not at rest by ``max_time_s``.
    """
    law = settings.law
    threshold = kinetic_fraction * state.n_particles * law.mass_kg * settings.gravity_m_s2 \
        * law.radius_m
    chunk = max(int(round(2e-3 / settings.dt_s)), 1)
    elapsed = 0.0
    zero = np.zeros(3)
    step = advance if clock is None else clock.advance
    while True:
        step(state, settings, chunk)
        elapsed += chunk * settings.dt_s
        e = energies(state, law, settings.geometry, wall_offset_m=zero,
                     gravity_m_s2=settings.gravity_m_s2)
        if np.all(e[:, 0] < threshold):
            state.step = 0
            return elapsed
        if elapsed > 0.5 * max_time_s:
            state.vel[:] = 0.0
            state.omg[:] = 0.0
        if elapsed > max_time_s:
            # elastic contacts (restitution 1 for both pairs) settled without friction, as the
            # dense start's first stage does, never come to rest: the refusal named no cause
            undamped = law.pair_particle.alpha == 0 and law.pair_wall.alpha == 0
            raise SimulationError(
                f"settling: kinetic energy still {e[:, 0].max():.3g} J > {threshold:.3g} J "
                f"after {elapsed:.3g} s"
                + ("; no contact is damped (restitution 1 for both pairs), so a bed settled "
                   "without friction keeps moving: state a restitution below 1, or start "
                   "with start_packing='loose'" if undamped else ""))


#: Beds settled without friction, keyed by everything that settling reads (see
#: :func:`settle_bed`), most recent last. The dense start's frictionless stage is ~80 % of a
#: short run and does not depend on friction or rolling resistance, so a calibration that
#: varies those settles each load case once instead of once per design point.
_FRICTIONLESS_BEDS: OrderedDict[str, tuple] = OrderedDict()
_FRICTIONLESS_BEDS_LOCK = threading.Lock()
#: Beds kept (each a few (3, K, N) arrays; 16 x 8 cells x 55 particles is ~1 MB).
FRICTIONLESS_BEDS_KEPT = 16


def _bed_key(state: CellsState, settings: KernelSettings) -> str:
    """Digest of every input of :func:`settle` for this state and settings (exact bytes)."""
    digest = hashlib.sha256(repr((settings, state.step)).encode())
    for array in (state.pos, state.vel, state.omg, state.frc, state.trq, state.spring_pp,
                  state.spring_pw, *law_vectors(settings.law), settings.geometry.wall_normals,
                  settings.geometry.wall_offsets):
        digest.update(repr((array.dtype.str, array.shape)).encode())
        digest.update(np.ascontiguousarray(array).tobytes())
    return digest.hexdigest()


def clear_settled_beds() -> None:
    """Forget the beds :func:`settle_bed` keeps (the next settle runs the kernel again)."""
    with _FRICTIONLESS_BEDS_LOCK:
        _FRICTIONLESS_BEDS.clear()


def _settle_frictionless(state: CellsState, settings: KernelSettings,
                         clock: _KernelClock | None) -> float:
    """The dense start's first stage: settle without friction (springs cleared), s.

    A bed settled before from the very same inputs is copied instead of settled again: the
    kernel is deterministic, so the copy is bit for bit what settling would give
    (tests/test_dem_simulate.py compares the two).
    """
    frictionless = dataclasses.replace(settings, law=settings.law.frictionless())
    key = _bed_key(state, frictionless)
    with _FRICTIONLESS_BEDS_LOCK:
        kept = _FRICTIONLESS_BEDS.get(key)
        if kept is not None:
            _FRICTIONLESS_BEDS.move_to_end(key)
    if kept is None:
        elapsed = settle(state, frictionless, clock=clock)
        state.spring_pp[:] = 0.0  # none stretched without friction; start the springs clean
        state.spring_pw[:] = 0.0
        kept = (elapsed, state.pos.copy(), state.vel.copy(), state.omg.copy(),
                state.frc.copy(), state.trq.copy())
        with _FRICTIONLESS_BEDS_LOCK:
            _FRICTIONLESS_BEDS[key] = kept
            while len(_FRICTIONLESS_BEDS) > FRICTIONLESS_BEDS_KEPT:
                _FRICTIONLESS_BEDS.popitem(last=False)
        return elapsed
    elapsed, pos, vel, omg, frc, trq = kept
    state.pos[:], state.vel[:], state.omg[:] = pos, vel, omg
    state.frc[:], state.trq[:] = frc, trq
    state.spring_pp[:] = 0.0
    state.spring_pw[:] = 0.0
    state.step = 0
    return elapsed


def settle_bed(state: CellsState, settings: KernelSettings,
               packing: StartPacking = defaults.DEM_START_PACKING, *,
               clock: _KernelClock | None = None) -> float:
    """Settle the start packing (``"dense"`` or ``"loose"``, see the module docstring), s.

    The dense start's frictionless stage is kept in memory per process (the last
    :data:`FRICTIONLESS_BEDS_KEPT` beds) and reused for the same inputs; see
    :func:`clear_settled_beds`.
    """
    if packing not in START_PACKINGS:
        raise ParameterError(f"start_packing: expected one of {START_PACKINGS}, got {packing!r}")
    elapsed = 0.0
    if packing == "dense":
        elapsed += _settle_frictionless(state, settings, clock)
    return elapsed + settle(state, settings, clock=clock)


def _steady_start(dissipated: np.ndarray, work: np.ndarray, config: DemConfig) -> int | None:
    """First cycle of the steady state from coupon-level per-cycle dissipation and wall work.

    Successive blocks of ``block_cycles`` cycles are compared: steady from block b-1 on when
    (1) the dissipation means of blocks b-1 and b differ by less than
    ``steady_relative_tolerance`` of the larger mean plus two combined standard errors (the
    cycle-to-cycle scatter of a granular bed is large; the error term keeps noise from
    delaying detection forever), and (2) in both blocks the walls' work matches the
    dissipation within DEM_STEADY_BALANCE_TOLERANCE (no stored energy drifting, e.g. a bed
    still compacting, which releases potential energy for tens of cycles).
    """
    b = config.block_cycles
    n_blocks = len(dissipated) // b
    tol_balance = defaults.DEM_STEADY_BALANCE_TOLERANCE

    def balanced(k: int) -> bool:
        d = dissipated[k * b:(k + 1) * b].sum()
        w = work[k * b:(k + 1) * b].sum()
        return abs(w - d) <= tol_balance * max(abs(d), 1e-300) or d == w

    for k in range(1, n_blocks):
        x0 = dissipated[(k - 1) * b:k * b]
        x1 = dissipated[k * b:(k + 1) * b]
        m0, m1 = x0.mean(), x1.mean()
        se = math.sqrt((x0.var(ddof=1) + x1.var(ddof=1)) / b) if b > 1 else 0.0
        converged = abs(m1 - m0) <= (config.steady_relative_tolerance * max(abs(m0), abs(m1))
                                     + 2 * se)
        if converged and balanced(k - 1) and balanced(k):
            return (k - 1) * b
    return None


def _halves_agree(first: np.ndarray, second: np.ndarray, relative_tolerance: float) -> bool:
    """Whether two runs of cycles dissipate alike: means within ``relative_tolerance`` of the
    larger plus two combined standard errors (the block rule's test, for any lengths)."""
    m0, m1 = first.mean(), second.mean()
    se = math.sqrt(first.var(ddof=1) / len(first) + second.var(ddof=1) / len(second))
    return abs(m1 - m0) <= relative_tolerance * max(abs(m0), abs(m1)) + 2 * se


def _steady_by_scatter(dissipated: np.ndarray, work: np.ndarray, config: DemConfig,
                       done: int) -> bool:
    """Whether the bed was steady over the second half of the transient skipped (cycles
    ``done // 2`` .. ``done`` on block boundaries), judged against the scatter of the cycles:
    the rule :func:`simulate_load_case` applies where the block rule (:func:`_steady_start`)
    found nothing by the transient cap.

    The block rule asks each of two blocks to balance the walls' work and the dissipation
    within DEM_STEADY_BALANCE_TOLERANCE; their difference is the change of the stored energy
    over the block, and where particles fly (a few steel spheres at 5 g, an alumina bed at
    5-10 g) its kinetic part at the block's two ends outweighs 2 % of ten cycles' dissipation
    by chance, so that test fails at random (docs/calibration.md, "DEM runs that never reach a
    steady state"). Here the stored energy at each cycle's end, the running sum of work minus
    dissipation, is fitted with a line: its slope is the energy the bed stores (or releases,
    compacting) per cycle, the error a drift makes in the dissipation per cycle. Steady when
    (1) that slope is within DEM_STEADY_BALANCE_TOLERANCE of the mean dissipation plus two
    standard errors of the slope (the scatter about the line taken as independent from cycle
    to cycle), and (2) the dissipation means of the window's two halves agree as the block
    rule's blocks must. Fewer than two blocks (and 8 cycles) in the window: not steady.
    """
    b = config.block_cycles
    lo = b * (done // (2 * b))
    d = np.asarray(dissipated[lo:done], dtype=float)
    w = np.asarray(work[lo:done], dtype=float)
    n = len(d)
    if n < max(2 * b, 8):
        return False
    stored = np.cumsum(w - d)
    cycle = np.arange(n, dtype=float)
    centred = cycle - cycle.mean()
    slope = float(centred @ stored / (centred @ centred))
    residual = stored - stored.mean() - slope * centred
    slope_se = math.sqrt(float(residual @ residual) / (n - 2) / float(centred @ centred))
    mean = float(d.mean())
    drift_ok = abs(slope) <= defaults.DEM_STEADY_BALANCE_TOLERANCE * abs(mean) + 2 * slope_se
    half = n // 2
    return bool(drift_ok and _halves_agree(d[:half], d[half:],
                                           config.steady_relative_tolerance))


def required_steady_cycles(case: LoadCase, config: DemConfig) -> int:
    if config.steady_cycles is not None:
        return config.steady_cycles
    return defaults.dem_automatic_steady_cycles(config.block_cycles)


def resolve_specimen(case: LoadCase, specimen: Specimen | None) -> Specimen:
    """The specimen a load case runs on: the paper's coupon with ``case.material`` particles
    by default; a given specimen's particles must be the ``case.material`` the load case names
    (a table material or the specimen's own, e.g. inline ``steel``).
    """
    if specimen is None:
        return paper_specimen(case.material)
    name = specimen.particles.material
    if name != case.material:
        raise ParameterError(f"material: the load case says {case.material!r} but specimen "
                             f"{specimen.name!r} ({specimen.source}) holds {name!r} particles")
    return specimen


def _amount(value: float) -> str:
    """A number as a message shows it: 3 significant digits, never 'inf'."""
    return f"{value:.3g}" if math.isfinite(value) else "more than 1e308"


def check_drive_stroke(case: LoadCase, *, what: str = "load case") -> None:
    """Refuse a drive whose displacement amplitude a/w^2 no shaker makes
    (:data:`pidcore.defaults.DEM_MAX_DISPLACEMENT_AMPLITUDE_M`): a frequency typed in kHz or an
    acceleration in m/s^2 where g is expected; one line naming ``what`` and the likely slip."""
    # a / w / w, not a / w**2: w**2 overflows (1e300 Hz) or underflows to 0 (1e-300 Hz), which
    # raised OverflowError / ZeroDivisionError; divided twice it is 0 or inf, judged as any
    stroke = case.acceleration_m_s2 / case.omega_rad_s / case.omega_rad_s
    if not stroke <= defaults.DEM_MAX_DISPLACEMENT_AMPLITUDE_M:
        raise ParameterError(
            f"{what} {case.frequency_hz:g} Hz, {case.acceleration_g:g} g: a displacement "
            f"amplitude of {_amount(stroke)} m (a / (2 pi f)^2); expected at most "
            f"{defaults.DEM_MAX_DISPLACEMENT_AMPLITUDE_M * 1e3:g} mm, a shaker's stroke; was "
            "the frequency typed in kHz, or the acceleration in m/s^2?")


def _physical_memory_bytes() -> int | None:
    """This machine's physical memory, bytes (None where the OS does not say)."""
    import os

    try:
        return int(os.sysconf("SC_PHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, OSError, ValueError):
        return None


def check_cells_fit_memory(cells: int, particles: int, *, what: str = "cells") -> None:
    """Refuse, before any work, more cells than this machine's memory holds the state of:
    ``--cells 1000000000`` packed cells for hours before running out of memory."""
    per_cell = CellsState.bytes_per_cell(particles)
    total = _physical_memory_bytes()
    if total is None or cells * per_cell <= total:
        return
    raise ParameterError(
        f"{what} {cells}: the state of {cells} cells of {particles} particles needs "
        f"{cells * per_cell / 1e9:.3g} GB, more than this machine's {total / 1e9:.3g} GB of "
        f"memory; expected at most {total // per_cell} cells")


def check_drive(case: LoadCase, config: DemConfig | None = None,
                specimen: Specimen | None = None, *, what: str = "load case") -> None:
    """Refuse, before any simulation, a drive :func:`simulate_load_case` refuses: a stroke no
    shaker makes (:func:`check_drive_stroke`) or a frequency its sampling cannot afford
    (:func:`check_drive_sampling`); a sweep refused the second only in the case's worker,
    after the cases before it had run. ``what`` names the options in the message."""
    config = config or DemConfig()
    check_drive_stroke(case, what=what)
    specimen = resolve_specimen(case, specimen)
    law = contact_law(specimen, alpha_pp=config.alpha_pp, alpha_pw=config.alpha_pw)
    dt_req = choose_time_step(case, law, specimen.geometry(), config.time_step,
                              config.tangential_model)
    _, dt = drive_sampling(case, dt_req, config.samples_per_cycle)
    check_drive_sampling(case, dt_s=dt, contact_step_s=dt_req,
                         samples_per_cycle=config.samples_per_cycle,
                         what=what.split("/")[0])  # the frequency's option
    n, _ = particles_per_cell(case.fill_percent, specimen=specimen,
                              fill_reference=config.fill_reference)
    check_cells_fit_memory(config.cells, n)


def drive_sampling(case: LoadCase, contact_step_s: float,
                   samples_per_cycle: int) -> tuple[int, float]:
    """(steps per output sample, time step in s) of a run: the contacts' step
    (:func:`choose_time_step`) shortened so that a drive period is a whole number of steps
    per each of its ``samples_per_cycle`` samples. This is the ``dt`` a run reports, up to a
    few % below the automatic step (steel_6mm at 500 Hz, 5 g: 6.98e-7 s -> 6.79e-7 s)."""
    period = 1.0 / case.frequency_hz
    sample_every = math.ceil(period / (samples_per_cycle * contact_step_s))
    return sample_every, period / (sample_every * samples_per_cycle)


def check_drive_sampling(case: LoadCase, *, dt_s: float, contact_step_s: float,
                         samples_per_cycle: int, what: str = "frequency") -> None:
    """Refuse a drive frequency whose samples per period shorten the contacts' time step
    ``contact_step_s`` to ``dt_s`` by more than :data:`pidcore.defaults.DEM_MAX_STEP_SHORTENING`
    (a frequency typed in mHz, or a megahertz drive no shaker makes): one line naming it."""
    if dt_s * defaults.DEM_MAX_STEP_SHORTENING >= contact_step_s:
        return
    highest = defaults.DEM_MAX_STEP_SHORTENING / (samples_per_cycle * contact_step_s)
    raise ParameterError(
        f"{what} {case.frequency_hz:g} Hz: {samples_per_cycle} samples per drive period need "
        f"a time step {contact_step_s / dt_s:.3g} x shorter than the contacts' "
        f"({contact_step_s:.3g} s), and the run as much longer; expected at most "
        f"{highest:.3g} Hz (was it typed in mHz?)")


def simulate_load_case(case: LoadCase, config: DemConfig | None = None, *,
                       progress: bool = False,
                       specimen: Specimen | None = None,
                       on_block: Callable[[int, int], None] | None = None,
                       on_settle: Callable[[float], None] | None = None) -> DemResult:
    """Simulate K independent cells under one load case and return the SDC (Eq. 8-10).

    Parameters
    ----------
    case : LoadCase
        Frequency, acceleration amplitude, fill, particle material, drive direction.
    config : DemConfig, optional
        Numerical settings; ``DemConfig()`` by default.
    progress : bool
        Show a tqdm progress bar on stderr.
    specimen : Specimen, optional
        Cell, coupon and fixture masses, particles and contact pairs
        (:mod:`pidcore.specimen`); the paper's coupon with ``case.material`` by default.
    on_block : callable, optional
        Called after every block as ``on_block(cycles_done, cycles_expected)`` (the
        expectation grows until the steady state is found); a job runner's progress hook.
    on_settle : callable, optional
        Called while the bed settles, before the first block (seconds to tens of seconds), as
        ``on_settle(simulated_s)`` with the settle's simulated seconds so far; a job runner's
        progress hook for that phase.

    Returns
    -------
    DemResult

    Raises
    ------
    ParameterError
        Unsafe time step, impossible fill.
    SimulationError
        Excess overlap, particle escape, no settling.

    Examples
    --------
    >>> r = simulate_load_case(LoadCase(500, 5, 50), DemConfig(cells=2, steady_cycles=10))
    ... # doctest: +SKIP
    """
    instance_of("case", case, LoadCase, hint="e.g. LoadCase(500.0, 5.0, 50.0)")
    instance_of("config", config, (DemConfig, type(None)), hint="e.g. DemConfig(cells=2)")
    instance_of("specimen", specimen, (Specimen, type(None)),
                hint="read a file with pidcore.specimen.load_specimen(path)")
    config = config or DemConfig()
    check_drive_stroke(case)
    specimen = resolve_specimen(case, specimen)
    geometry = specimen.geometry()
    wall_clock = time.perf_counter()
    law = contact_law(specimen, alpha_pp=config.alpha_pp, alpha_pw=config.alpha_pw)
    n, full = particles_per_cell(case.fill_percent, specimen=specimen,
                                 fill_reference=config.fill_reference)
    check_cells_fit_memory(config.cells, n)
    dt_req = choose_time_step(case, law, geometry, config.time_step, config.tangential_model)
    spc_samples = config.samples_per_cycle
    sample_every, dt = drive_sampling(case, dt_req, spc_samples)
    steps_per_cycle = sample_every * spc_samples
    check_drive_sampling(case, dt_s=dt, contact_step_s=dt_req, samples_per_cycle=spc_samples)
    if config.damping_coefficient == "calibrated":
        law = calibrated_contact_law(specimen, config, dt)

    rng = np.random.default_rng(config.seed)
    positions = np.stack([random_packing(geometry, law.radius_m, n, rng)
                          for _ in range(config.cells)])
    assert_no_overlap(positions, law.radius_m, geometry)
    state = CellsState.from_positions(positions, mass_kg=law.mass_kg)
    common = dict(law=law, geometry=geometry, dt_s=dt, direction=case.direction,
                  clip_attraction=config.normal_damping_mode == "no_attraction",
                  friction_regularisation_m_s=config.friction_regularisation_m_s,
                  tangential_model=config.tangential_model,
                  max_overlap_fraction=defaults.DEM_MAX_OVERLAP_FRACTION)
    clock = _KernelClock()
    settling = None
    if progress:  # the settle takes seconds before the cycle bar starts: say it is running
        from tqdm import tqdm
        settling = tqdm(desc=f"DEM {case.key}: settling the bed", unit="ms", leave=False,
                        bar_format="{desc}: {n:.0f} ms simulated [{elapsed}]")
    if settling is not None or on_settle is not None:
        settled = [0.0]

        def simulated(seconds: float) -> None:
            settled[0] += seconds
            if settling is not None:
                settling.update(seconds * 1e3)
            if on_settle is not None:
                on_settle(settled[0])

        clock.on_simulated = simulated
    try:
        settle_time = settle_bed(state, KernelSettings(**common), config.start_packing,
                                 clock=clock)
    finally:
        if settling is not None:
            settling.close()
        clock.on_simulated = None

    axis = AXIS_INDEX[case.direction]
    unit = np.zeros(3)
    unit[axis] = 1.0
    drive = KernelSettings(omega_rad_s=case.omega_rad_s, accel_m_s2=case.acceleration_m_s2,
                           **common)
    if config.start_protocol == "with_cell":
        state.vel[axis] += -case.acceleration_m_s2 / case.omega_rad_s
    e_start = energies(state, law, geometry, wall_offset_m=np.zeros(3),
                       gravity_m_s2=STANDARD_GRAVITY)

    need = required_steady_cycles(case, config)
    b = config.block_cycles
    tallies: list[np.ndarray] = []
    samples: list[np.ndarray] = []
    block_energy = [e_start[:, 3]]  # mechanical energy per cell at each block boundary
    steady_start: int | None = None
    detected = False
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=need + 2 * b, unit="cycle", desc=f"DEM {case.key}", leave=False)
    try:
        while True:
            t, s = _drive_block(clock, state, drive, b, steps_per_cycle=steps_per_cycle,
                                sample_every=sample_every,
                                on_cycles=bar.update if bar is not None else None)
            tallies.append(t)
            samples.append(s)
            u_now = wall_displacement(state.step * dt, accel_m_s2=case.acceleration_m_s2,
                                      omega_rad_s=case.omega_rad_s)
            block_energy.append(energies(state, law, geometry, wall_offset_m=unit * u_now,
                                         gravity_m_s2=STANDARD_GRAVITY)[:, 3])
            done = len(tallies) * b
            if steady_start is None:
                all_t = np.concatenate(tallies, axis=1).mean(axis=0)  # (cycles, 3)
                steady_start = _steady_start(all_t[:, 1] + all_t[:, 2] + all_t[:, 3],
                                             all_t[:, 0], config)
                detected = steady_start is not None
                cap = config.transient_cap_cycles(case.frequency_hz)
                if steady_start is None and done >= cap:
                    steady_start = -(-cap // b) * b  # block boundary
                    # the block rule's 2 % balance is one of a block's dissipation, which a
                    # flying bed's stored energy (kinetic at the block's ends) outweighs by
                    # chance: judged against that scatter the bed may well be steady. The
                    # window stays at the cap, so the SDC is the same either way
                    detected = _steady_by_scatter(all_t[:, 1] + all_t[:, 2] + all_t[:, 3],
                                                  all_t[:, 0], config, done)
                if bar is not None and steady_start is not None:
                    bar.total = steady_start + need
                    bar.refresh()
            if on_block is not None:
                on_block(done, steady_start + need if steady_start is not None
                         else done + need + b)
            if steady_start is not None and done - steady_start >= need:
                break
    finally:
        if bar is not None:
            bar.close()

    tally = np.concatenate(tallies, axis=1)  # (K, cycles, 3)
    force = np.concatenate(samples, axis=1)  # (K, cycles * samples_per_cycle)
    t_end = state.step * dt
    u_end = wall_displacement(t_end, accel_m_s2=case.acceleration_m_s2,
                              omega_rad_s=case.omega_rad_s)
    e_end = energies(state, law, geometry, wall_offset_m=unit * u_end,
                     gravity_m_s2=STANDARD_GRAVITY)
    stored_change = block_energy[-1] - block_energy[steady_start // b]  # (K,) J
    n_cycles = tally.shape[1]
    m_c = specimen.vibrated_mass_kg(n, config.vibrated_mass)
    wall = time.perf_counter() - wall_clock
    total_steps = n_cycles * steps_per_cycle
    return DemResult.from_run(
        case=case, config=config, law=law, tally=tally, wall_force=force,
        steady_start_cycle=int(steady_start), steady_detected=detected,
        particles_per_cell=n, full_count=full, vibrated_mass_kg=m_c,
        moving_mass_kg=specimen.coupon.moving_mass_kg, specimen=specimen,
        dt_s=dt, steps_per_cycle=steps_per_cycle, sample_every=sample_every,
        energy_start=e_start, energy_end=e_end, settle_time_s=settle_time,
        stored_energy_change_steady=stored_change,
        steps=total_steps, wall_s=wall, kernel_s=clock.seconds,
        particle_steps=clock.particle_steps)


def config_parameters(case: LoadCase, config: DemConfig) -> dict:
    """Flat dict of every input (JSON-safe) for records and stores."""
    out = {f"case_{k}": v for k, v in asdict(case).items()}
    out.update({f"config_{k}": v for k, v in asdict(config).items()})
    if config.steady_cycles == defaults.dem_automatic_steady_cycles(config.block_cycles):
        # the same run as steady_cycles=None, so the same key: `--cycles 80`, the documented
        # default, simulated again beside the default's stored run and made a report row of
        # its own ("steady cycles 80" beside "auto")
        out["config_steady_cycles"] = None
    return {k: ("" if v is None else v) for k, v in out.items()}


__all__ = ["LoadCase", "DemConfig", "simulate_load_case", "resolve_specimen", "choose_time_step",
           "calibrated_contact_law",
           "drive_sampling",
           "particles_of_stated_fill", "particles_per_cell", "vibrated_mass_kg",
           "coupon_mass_kg", "max_impact_speed",
           "settle", "settle_bed", "clear_settled_beds", "config_parameters"]
