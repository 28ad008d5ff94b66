"""Contact laws (paper Eq. 2-5), as small pure functions.

Normal force (Eq. 2, Hertz + Tsuji damping), with the overlap ``delta`` > 0 and the approach
rate ``delta_dot`` (> 0 while the bodies approach)::

    f_n = k_n delta^(3/2) + alpha sqrt(m* k_n) delta^(1/4) delta_dot      (repulsive > 0)

``alpha`` from the restitution coefficient by Eq. 3, ``m*`` by Eq. 4 (a wall has infinite
mass: ``m* = m_i``), ``k_n = 4/3 E* sqrt(R*)`` (a wall has infinite radius: ``R* = r_i``).

Tangential force, two named models (``constants.TangentialModel``):

* ``"stick_slip"`` (default): an elastic tangential spring, f_t = -k_t xi with xi the
  accumulated tangential displacement of the contact points, capped at mu |f_n| (when the cap
  acts the contact slides and xi is shortened to the cap: the energy removed is the friction
  dissipation). k_t is constant per pair of materials: Mindlin's initial stiffness
  8 G* sqrt(R* delta) at the Hertz maximum overlap of a DEM_TANGENTIAL_REFERENCE_SPEED_M_S
  impact (constant so that 1/2 k_t xi^2 is a true potential and the energy balance closes).
* ``"coulomb"``: Eq. 5 as written, mu |f_n| against the slip velocity, scaled down linearly
  below a regularisation speed. Below that speed it is a viscous damper, so a bed under
  tangential load creeps and dissipates forever (it cannot stick).
The kernel (:mod:`pidcore.dem.kernel`) evaluates the same expressions inline; the tests check
the kernel against these functions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import defaults
from ..constants import NORMAL_DAMPING_MODES, TANGENTIAL_MODELS, NormalDampingMode
from ..errors import ParameterError
from .materials import WALL_MATERIAL, material, pair_properties


def effective_modulus(e1_pa: float, nu1: float, e2_pa: float, nu2: float) -> float:
    """Hertz effective modulus E* = 1 / ((1-nu1^2)/E1 + (1-nu2^2)/E2), Pa."""
    return 1.0 / ((1.0 - nu1**2) / e1_pa + (1.0 - nu2**2) / e2_pa)


def effective_radius(r1_m: float, r2_m: float | None) -> float:
    """R* = r1 r2 / (r1 + r2); ``r2_m=None`` is a flat wall (R* = r1), m."""
    if r2_m is None:
        return r1_m
    return r1_m * r2_m / (r1_m + r2_m)


def effective_mass(m1_kg: float, m2_kg: float | None) -> float:
    """Eq. 4: m* = m1 m2 / (m1 + m2); ``m2_kg=None`` is a wall (infinite mass, m* = m1), kg."""
    if m2_kg is None:
        return m1_kg
    return m1_kg * m2_kg / (m1_kg + m2_kg)


def effective_shear_modulus(e1_pa: float, nu1: float, e2_pa: float, nu2: float) -> float:
    """Mindlin's effective shear modulus G* = 1 / ((2-nu1)/G1 + (2-nu2)/G2), G = E/(2(1+nu)), Pa."""
    g1 = e1_pa / (2.0 * (1.0 + nu1))
    g2 = e2_pa / (2.0 * (1.0 + nu2))
    return 1.0 / ((2.0 - nu1) / g1 + (2.0 - nu2) / g2)


def tangential_stiffness(g_star_pa: float, r_star_m: float, overlap_m: float) -> float:
    """Mindlin's initial tangential stiffness k_t = 8 G* sqrt(R* delta), N/m."""
    return 8.0 * g_star_pa * np.sqrt(r_star_m * overlap_m)


def hertz_stiffness(e_star_pa: float, r_star_m: float) -> float:
    """Hertz constant k_n = 4/3 E* sqrt(R*), N/m^(3/2)."""
    return 4.0 / 3.0 * e_star_pa * np.sqrt(r_star_m)


def damping_constant_from_restitution(restitution: float) -> float:
    """Eq. 3: alpha = -ln(e) sqrt(5 / (ln(e)^2 + pi^2)) [-].

    Examples
    --------
    >>> round(damping_constant_from_restitution(1.0), 12)
    0.0
    """
    if not 0.0 < restitution <= 1.0:
        raise ParameterError(f"normal_restitution: expected 0 < e <= 1, got {restitution}")
    ln_e = np.log(restitution)
    return float(-ln_e * np.sqrt(5.0 / (ln_e**2 + np.pi**2)))


def normal_force(delta_m, delta_dot_m_s, *, stiffness: float, damping: float,
                 mode: NormalDampingMode):
    """Eq. 2 normal force magnitude (repulsive positive), N.

    ``damping`` is ``alpha sqrt(m* k_n)``. ``mode="no_attraction"`` clips the total at zero
    (no adhesion at the end of a contact); ``"literal"`` keeps Eq. 2 as written.
    """
    delta = np.asarray(delta_m, dtype=float)
    force = stiffness * delta**1.5 + damping * delta**0.25 * np.asarray(delta_dot_m_s)
    if mode == "no_attraction":
        force = np.maximum(force, 0.0)
    return force


def elastic_energy(delta_m, *, stiffness: float):
    """Energy stored in a Hertz contact, (2/5) k_n delta^(5/2), J."""
    delta = np.maximum(np.asarray(delta_m, dtype=float), 0.0)
    return 0.4 * stiffness * delta**2.5


def hertz_contact_time(*, stiffness: float, mass_kg: float, impact_speed_m_s: float) -> float:
    """Duration of an elastic Hertz impact, s.

    t_c = 2.9432 delta_max / v with delta_max = (5 m* v^2 / (4 k_n))^(2/5) (Johnson,
    Contact Mechanics, Sect. 11.4).
    """
    if impact_speed_m_s <= 0:
        raise ParameterError(f"impact_speed: expected > 0 m/s, got {impact_speed_m_s}")
    delta_max = (1.25 * mass_kg * impact_speed_m_s**2 / stiffness) ** 0.4
    return 2.9432 * delta_max / impact_speed_m_s


def maximum_overlap(*, stiffness: float, mass_kg: float, impact_speed_m_s: float) -> float:
    """Largest overlap of an elastic Hertz impact, (5 m* v^2 / (4 k_n))^(2/5), m."""
    return (1.25 * mass_kg * impact_speed_m_s**2 / stiffness) ** 0.4


@dataclass(frozen=True)
class ContactLaw:
    """All contact parameters of one particle material in an aluminium cell (SI units).

    ``*_pp``: particle-particle; ``*_pw``: particle-wall. ``damping_*`` is
    ``alpha sqrt(m* k_n)`` (N s / m^(5/4)); ``tangential_mass_*`` is the effective mass of
    sliding at the contact point, 1/m_t = sum(1/m + arm^2/I) (arm = r), used to cap the
    friction (at m_t |v_t| / (2 dt)) so it never reverses the slip within one step.
    ``tangential_stiffness_*`` (N/m) is k_t of the stick-slip model (module docstring).
    """

    particle_material: str
    radius_m: float
    mass_kg: float
    inertia_kg_m2: float
    stiffness_pp: float
    stiffness_pw: float
    alpha_pp: float
    alpha_pw: float
    damping_pp: float
    damping_pw: float
    friction_pp: float
    friction_pw: float
    restitution_pp: float
    restitution_pw: float
    tangential_mass_pp: float
    tangential_mass_pw: float
    tangential_stiffness_pp: float
    tangential_stiffness_pw: float

    @classmethod
    def for_material(cls, name: str, *, radius_m: float | None = None,
                     alpha_pp: float | None = None,
                     alpha_pw: float | None = None) -> ContactLaw:
        """Build from the CSV tables; ``alpha_*`` default to Eq. 3 of the table's e_n."""
        mat = material(name)
        if mat.role != "particle":
            raise ParameterError(f"material: {name!r} is not a particle material")
        wall = material(WALL_MATERIAL)
        r = mat.default_radius_m if radius_m is None else float(radius_m)
        if not r > 0:
            raise ParameterError(f"radius: expected > 0 m, got {r}")
        m = mat.sphere_mass(r)
        inertia = 0.4 * m * r * r
        pp = pair_properties(name, name)
        pw = pair_properties(name, WALL_MATERIAL)
        k_pp = hertz_stiffness(effective_modulus(mat.youngs_modulus_pa, mat.poisson_ratio,
                                                 mat.youngs_modulus_pa, mat.poisson_ratio),
                               effective_radius(r, r))
        k_pw = hertz_stiffness(effective_modulus(mat.youngs_modulus_pa, mat.poisson_ratio,
                                                 wall.youngs_modulus_pa, wall.poisson_ratio),
                               effective_radius(r, None))
        g_pp = effective_shear_modulus(mat.youngs_modulus_pa, mat.poisson_ratio,
                                       mat.youngs_modulus_pa, mat.poisson_ratio)
        g_pw = effective_shear_modulus(mat.youngs_modulus_pa, mat.poisson_ratio,
                                       wall.youngs_modulus_pa, wall.poisson_ratio)
        v_ref = defaults.DEM_TANGENTIAL_REFERENCE_SPEED_M_S
        kt_pp = tangential_stiffness(g_pp, effective_radius(r, r), maximum_overlap(
            stiffness=k_pp, mass_kg=effective_mass(m, m), impact_speed_m_s=v_ref))
        kt_pw = tangential_stiffness(g_pw, effective_radius(r, None), maximum_overlap(
            stiffness=k_pw, mass_kg=effective_mass(m, None), impact_speed_m_s=v_ref))
        a_pp = damping_constant_from_restitution(pp.normal_restitution) \
            if alpha_pp is None else float(alpha_pp)
        a_pw = damping_constant_from_restitution(pw.normal_restitution) \
            if alpha_pw is None else float(alpha_pw)
        return cls(
            particle_material=name, radius_m=r, mass_kg=m, inertia_kg_m2=inertia,
            stiffness_pp=k_pp, stiffness_pw=k_pw, alpha_pp=a_pp, alpha_pw=a_pw,
            damping_pp=a_pp * np.sqrt(effective_mass(m, m) * k_pp),
            damping_pw=a_pw * np.sqrt(effective_mass(m, None) * k_pw),
            friction_pp=pp.sliding_friction, friction_pw=pw.sliding_friction,
            restitution_pp=pp.normal_restitution, restitution_pw=pw.normal_restitution,
            tangential_mass_pp=1.0 / (2.0 / m + 2.0 * r * r / inertia),
            tangential_mass_pw=1.0 / (1.0 / m + r * r / inertia),
            tangential_stiffness_pp=kt_pp, tangential_stiffness_pw=kt_pw,
        )

    def contact_time(self, impact_speed_m_s: float) -> float:
        """Shortest Hertz contact time (wall or pair) at the given impact speed, s."""
        return min(hertz_contact_time(stiffness=self.stiffness_pw, mass_kg=self.mass_kg,
                                      impact_speed_m_s=impact_speed_m_s),
                   hertz_contact_time(stiffness=self.stiffness_pp, mass_kg=self.mass_kg / 2,
                                      impact_speed_m_s=impact_speed_m_s))


    def tangential_period(self) -> float:
        """Shortest period of a stuck tangential spring, 2 pi sqrt(m_t / k_t) (pair or wall), s."""
        return 2.0 * np.pi * min(np.sqrt(self.tangential_mass_pp / self.tangential_stiffness_pp),
                                 np.sqrt(self.tangential_mass_pw / self.tangential_stiffness_pw))


def check_damping_mode(mode: str) -> None:
    if mode not in NORMAL_DAMPING_MODES:
        raise ParameterError(
            f"normal_damping_mode: expected one of {NORMAL_DAMPING_MODES}, got {mode!r}")


def check_tangential_model(model: str) -> None:
    if model not in TANGENTIAL_MODELS:
        raise ParameterError(
            f"tangential_model: expected one of {TANGENTIAL_MODELS}, got {model!r}")
