"""Single impacts run through the production kernel: measured restitution and calibration.

Hertz + Tsuji damping (Eq. 2-3) is, in the continuum, independent of impact speed, but Eq. 3
is derived for a linear spring, so the restitution the code really gives differs from the
table's e_n; :func:`measure_restitution` reports it and :func:`calibrate_damping_coefficient`
finds the alpha that gives exactly the target at a chosen speed and time step.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np
from scipy.optimize import brentq

from .. import defaults
from ..constants import ImpactPair, NormalDampingMode, TangentialModel
from ..errors import ParameterError
from .contact import ContactLaw, check_damping_mode
from .geometry import CellGeometry, check_sphere_fits
from .state import CellsState, KernelSettings, advance, energies

#: How far the restitution of a calibrated alpha may be from the target before the calibration
#: is refused [-]: Brent stops at 1e-10 in alpha, and de/dalpha is O(1), so a root that is one
#: gives the target to ~1e-10; a root at the jump to "still in contact" misses it by e itself.
CALIBRATION_CHECK_TOLERANCE = 1e-6


class StillInContact(ParameterError):
    """The bodies of an impact still touch after 3 contact times of their own contact (a
    contact so damped that it hardly rebounds)."""


def pair_name(pair: ImpactPair) -> str:
    """The contact an impact ``pair`` is of, as messages name it."""
    return "particle-wall" if pair == "wall" else "particle-particle"


def impact_contact_time(law: ContactLaw, pair: ImpactPair, impact_speed_m_s: float) -> float:
    """Hertz contact time of the contact an impact of ``pair`` loads (the wall's or the
    pair's law, not the shorter of the two), s."""
    return (law.pair_wall if pair == "wall" else law.pair_particle).contact_time(
        impact_speed_m_s)


@dataclasses.dataclass(frozen=True)
class ImpactOutcome:
    """Velocities before/after one impact (SI units), kinetic energies (translation and
    rotation of both bodies) and the dissipated energy (normal, friction, rolling) [J]."""

    normal_speed_before_m_s: float
    normal_speed_after_m_s: float
    tangential_velocity_before_m_s: float
    tangential_velocity_after_m_s: float
    restitution: float
    dissipated_normal_j: float
    dissipated_friction_j: float
    steps: int
    kinetic_energy_before_j: float
    kinetic_energy_after_j: float
    dissipated_rolling_j: float = 0.0


def simulate_impact(*, pair: ImpactPair = "wall", impact_speed_m_s: float, dt_s: float,
                    mode: NormalDampingMode = "no_attraction", material: str = "acrylic",
                    tangential_speed_m_s: float = 0.0, spin_rad_s: float = 0.0,
                    wall: str = "floor", alpha: float | None = None,
                    law: ContactLaw | None = None,
                    tangential_model: TangentialModel = defaults.DEM_TANGENTIAL_MODEL,
                    geometry: CellGeometry | None = None,
                    ) -> ImpactOutcome:
    """One impact without gravity through :func:`pidcore.dem.kernel.advance_cells`.

    ``pair="wall"``: a particle hits wall ``wall`` (a name of
    :data:`pidcore.dem.geometry.WALL_NAMES`) head-on at ``impact_speed_m_s`` with a
    tangential velocity ``tangential_speed_m_s`` (along the wall) and spin ``spin_rad_s``
    about the axis normal to both. ``pair="particle"``: two particles approach along z at
    relative speed ``impact_speed_m_s`` (each at half of it). ``alpha`` overrides Eq. 3 for
    this contact; ``tangential_model`` picks the friction law (:mod:`pidcore.dem.contact`).
    ``law`` replaces the tables' law of ``material`` (e.g. a specimen's,
    :func:`pidcore.specimen.contact_law`); ``geometry`` is the cell the impact happens in (the
    paper's by default): the particle hits its wall centred on it, the pair meets along z.
    """
    from .geometry import WALL_NAMES

    check_damping_mode(mode)
    if pair not in ("wall", "particle"):
        raise ParameterError(f"pair: expected 'wall' or 'particle', got {pair!r}")
    if not impact_speed_m_s > 0:
        raise ParameterError(f"impact_speed: expected > 0 m/s, got {impact_speed_m_s}")
    geometry = geometry or CellGeometry()
    if law is None:
        law = ContactLaw.for_material(material, alpha_pw=alpha if pair == "wall" else None,
                                      alpha_pp=alpha if pair == "particle" else None)
    r = law.radius_m
    # a particle that does not fit the cell would touch other walls than the one it hits (a
    # large own particle in the paper's default cell): no head-on impact, a wrong number
    check_sphere_fits(geometry, r)
    # only the contact measured may touch: a cell too low to hold a particle pair one above
    # the other (a monolayer's) gets room for it, half a radius to spare at floor and
    # ceiling, and one whose opposite wall is closer than that to a particle rebounding from
    # its wall gets that room beyond it (0.5 µm above a bounce off the floor, the ceiling was
    # hit: a restitution of -0.16), the particle moving microns in the impact's time
    across = "inscribed_diameter_m" if pair == "wall" and not wall.startswith(
        ("floor", "ceiling")) else "height_m"
    if getattr(geometry, across) < 5 * r:
        geometry = dataclasses.replace(geometry, **{across: 5 * r})
    if pair == "wall":
        w = WALL_NAMES.index(wall)
        n = geometry.wall_normals[w]
        t_dir = np.cross(n, [0.0, 0.0, 1.0]) if abs(n[2]) < 0.5 else np.array([1.0, 0, 0])
        t_dir /= np.linalg.norm(t_dir)
        spin_axis = np.cross(n, t_dir)
        # touching the wall, centred on it
        pos = (-geometry.wall_offsets[w] + r) * n
        positions = pos[None, None, :]
        vel = -impact_speed_m_s * n + tangential_speed_m_s * t_dir
    else:
        n = np.array([0.0, 0.0, 1.0])
        t_dir = np.array([1.0, 0.0, 0.0])
        spin_axis = np.cross(n, t_dir)
        positions = np.array([[[0.0, 0.0, -r], [0.0, 0.0, r]]])
    state = CellsState.from_positions(positions, mass_kg=law.mass_kg, gravity_m_s2=0.0)
    if pair == "wall":
        state.vel[:, 0, 0] = vel
        state.omg[:, 0, 0] = spin_rad_s * spin_axis
    else:
        state.vel[2, 0, 0] = 0.5 * impact_speed_m_s
        state.vel[2, 0, 1] = -0.5 * impact_speed_m_s
        state.vel[0, 0, 0] = 0.5 * tangential_speed_m_s
        state.vel[0, 0, 1] = -0.5 * tangential_speed_m_s
    settings = KernelSettings(law=law, geometry=geometry, dt_s=dt_s, gravity_m_s2=0.0,
                              clip_attraction=mode == "no_attraction",
                              tangential_model=tangential_model)
    # the window is the contact simulated's own: the shorter of the two (ContactLaw's) ended
    # steel's impact on a Nomex wall (4.5 x longer than steel on steel) before its rebound
    m_t = impact_contact_time(law, pair, impact_speed_m_s)
    steps = int(math.ceil(3.0 * m_t / dt_s)) + 2
    zero = np.zeros(3)

    def kinetic() -> float:  # translation and rotation, all bodies
        return float(energies(state, law, geometry, wall_offset_m=zero,
                              gravity_m_s2=0.0)[:, 0].sum())

    ke_before = kinetic()
    tally, _ = advance(state, settings, steps)
    if pair == "wall":
        v_after = state.vel[:, 0, 0]
        if np.dot(geometry.wall_normals[w], state.pos[:, 0, 0]) + geometry.wall_offsets[w] <= r:
            raise StillInContact(f"impact: {pair_name(pair)} contact still closed after 3 of "
                                 f"its contact times ({m_t:.3g} s) at {impact_speed_m_s:g} m/s")
        vn_after = float(np.dot(v_after, n))
        vt_before = tangential_speed_m_s
        vt_after = float(np.dot(v_after, t_dir))
    else:
        rel = state.vel[:, 0, 1] - state.vel[:, 0, 0]
        if np.linalg.norm(state.pos[:, 0, 1] - state.pos[:, 0, 0]) <= 2 * r:
            raise StillInContact(f"impact: {pair_name(pair)} contact still closed after 3 of "
                                 f"its contact times ({m_t:.3g} s) at {impact_speed_m_s:g} m/s")
        vn_after = float(rel[2])
        vt_before = -tangential_speed_m_s
        vt_after = float(rel[0])
    return ImpactOutcome(impact_speed_m_s, vn_after, vt_before, vt_after,
                         vn_after / impact_speed_m_s, float(tally[..., 1].sum()),
                         float(tally[..., 2].sum()), steps, ke_before,
                         kinetic(), float(tally[..., 3].sum()))



def measure_restitution(*, pair: ImpactPair = "wall", impact_speed_m_s: float, dt_s: float,
                        mode: NormalDampingMode = "no_attraction", material: str = "acrylic",
                        alpha: float | None = None, law: ContactLaw | None = None,
                        geometry: CellGeometry | None = None) -> float:
    """Normal restitution the kernel really gives in a head-on impact [-] (``law`` and
    ``geometry`` as :func:`simulate_impact` takes them)."""
    return simulate_impact(pair=pair, impact_speed_m_s=impact_speed_m_s, dt_s=dt_s,
                           mode=mode, material=material, alpha=alpha, law=law,
                           geometry=geometry).restitution


def calibrate_damping_coefficient(target_e: float, pair: ImpactPair, impact_speed: float,
                                  dt: float, mode: NormalDampingMode = "no_attraction", *,
                                  material: str = "acrylic",
                                  law: Callable[[float], ContactLaw] | None = None,
                                  geometry: CellGeometry | None = None) -> float:
    """alpha of Eq. 2 that makes the simulated head-on impact give exactly ``target_e``.

    The contact is the tables' of ``material``, or ``law(alpha)``: any contact law with that
    alpha on ``pair`` (e.g. ``lambda a: contact_law(specimen, alpha_pw=a)``), in the cell
    ``geometry`` (the paper's by default; a specimen's own, :meth:`Specimen.geometry`).

    Root-finds (Brent, alpha in [0, 5]) on :func:`measure_restitution`; ``target_e`` 1 is
    alpha 0 (no damping). A target outside what alpha 0 and 5 give, or a root that does not
    give it (an impact that has not ended), is a ParameterError naming the pair. Hertz + Tsuji
    restitution is speed-independent in the continuum, so the alpha holds approximately at
    other speeds (the time discretisation adds a weak speed dependence).

    Examples
    --------
    >>> a = calibrate_damping_coefficient(0.7, "wall", 0.3, 1e-6)  # doctest: +SKIP
    """
    if not 0 < target_e <= 1:
        raise ParameterError(f"target_e: expected 0 < e <= 1, got {target_e}")
    if target_e == 1:  # a specimen may state elastic contacts: no damping is what gives them
        return 0.0

    def miss(alpha: float) -> float:
        try:
            e = measure_restitution(pair=pair, impact_speed_m_s=impact_speed, dt_s=dt,
                                    mode=mode, material=material, alpha=alpha,
                                    law=None if law is None else law(alpha),
                                    geometry=geometry)
        except StillInContact:
            # so damped that it has not left after 3 contact times (alpha near the bracket's
            # top, for 2 mm steel on aluminium): a rebound of no speed to speak of, below any
            # target, which is all the root-finder needs from it
            e = 0.0
        return e - target_e

    hi = 5.0
    least = miss(hi)
    if least > 0:
        # the cure the refusal names must work: literal damping reaches any e (Eq. 3 exact)
        raise ParameterError(
            f"{pair_name(pair)} restitution "
            f"{target_e:g}: below the {least + target_e:.3g} that the strongest damping tried "
            f"(alpha {hi:g}) gives in {mode} damping; expected a restitution it reaches"
            + (", or normal_damping_mode='literal' (Eq. 3's alpha gives any e exactly there)"
               if mode != "literal" else ""))
    most = miss(0.0)
    if most < 0:
        # brentq's "f(a) and f(b) must have different signs" was all a user saw of this
        raise ParameterError(
            f"{pair_name(pair)} restitution {target_e:g}: above the {most + target_e:.6g} "
            f"that no damping (alpha 0) gives at time step {dt:.3g} s; expected a "
            "restitution it reaches, or a shorter time step")
    alpha = float(brentq(miss, 0.0, hi, xtol=1e-10, rtol=1e-10))
    reached = miss(alpha) + target_e
    if not abs(reached - target_e) <= CALIBRATION_CHECK_TOLERANCE:
        # a root at the edge of "still in contact" (taken as e 0) is no calibration: the
        # alpha that gave e 0.156 for the targets 0.1, 0.05 and 0.02 alike
        raise ParameterError(
            f"{pair_name(pair)} restitution {target_e:g}: the damping found (alpha "
            f"{alpha:.4g}) gives {reached:.3g}, not the target: it is where the impact stops "
            "ending within 3 of its contact times; expected a restitution it reaches, or "
            "normal_damping_mode='literal'")
    return alpha
