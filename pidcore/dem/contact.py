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

import dataclasses
from dataclasses import dataclass

import numpy as np
from numba import njit

from .. import defaults
from ..constants import (
    NORMAL_DAMPING_MODES,
    TANGENTIAL_MODELS,
    TANGENTIAL_STIFFNESS_MODELS,
    NormalDampingMode,
    TangentialStiffnessModel,
)
from ..errors import ParameterError
from .materials import (
    WALL_MATERIAL,
    MaterialProperties,
    PairParameters,
    material,
    pair_properties,
)


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
    >>> damping_constant_from_restitution(1.0) == 0.0
    True
    """
    if not 0.0 < restitution <= 1.0:
        raise ParameterError(f"normal_restitution: expected 0 < e <= 1, got {restitution}")
    if restitution == 1.0:  # -ln(1) is -0.0: a run of elastic contacts printed "alpha -0"
        return 0.0
    ln_e = np.log(restitution)
    return float(-ln_e * np.sqrt(5.0 / (ln_e**2 + np.pi**2)))


@njit(cache=True, inline="always")
def hertz_normal_force(delta, delta_dot, k_n, c_n, clip_attraction):
    """Eq. 2: elastic part k_n delta^1.5 and total with Tsuji damping c_n delta^0.25 ddelta/dt.

    ``c_n`` is alpha sqrt(m* k_n) (Eq. 3-4); with ``clip_attraction`` the total may not pull
    (no adhesion at the end of a contact). Returns (elastic, total), N, repulsive > 0.
    """
    sq = np.sqrt(delta)
    f_el = k_n * delta * sq
    f_n = f_el + c_n * np.sqrt(sq) * delta_dot
    if clip_attraction and f_n < 0.0:
        f_n = 0.0
    return f_el, f_n


@njit(cache=True, inline="always")
def hertz_elastic_energy(delta, k_n):
    """Energy stored in a Hertz contact, (2/5) k_n delta^(5/2) (0 when open), J."""
    if delta <= 0.0:
        return 0.0
    return 0.4 * k_n * delta * delta * np.sqrt(delta)


@njit(cache=True, inline="always")
def mindlin_tangential_stiffness(delta, k_t, mindlin_factor):
    """k_t of a contact: constant ``k_t``, or Mindlin's mindlin_factor sqrt(delta) when > 0."""
    if mindlin_factor > 0.0:
        return mindlin_factor * np.sqrt(delta)
    return k_t


@njit(cache=True, inline="always")
def capped_spring(sx, sy, sz, dsx, dsy, dsz, nx, ny, nz, k, k_old, stick_limit, slide_limit,
                  sliding):
    """Elastic-plastic contact spring in the tangent plane (tangential and rolling laws).

    ``s`` is the stretch held so far (stored at stiffness ``k_old``), ``ds`` the step's
    relative displacement (tangential: of the contact points, m; rolling: rotation, rad),
    ``n`` the contact normal. The stretch is turned into the current tangent plane (its
    normal part is dropped and its energy counted as lost), rescaled if the stiffness changed
    (Mindlin: ``k`` > ``k_old`` keeps the force, a smaller ``k`` keeps the stretch, LAMMPS
    ``mindlin_rescale/force``; either way the stored energy can only fall, and the fall is
    counted as lost), then ``ds`` is added. If the trial force k|s| exceeds the limit (the
    static ``stick_limit``, or ``slide_limit`` when the contact was ``sliding`` already), the
    contact slides: the stretch is cut to the sliding limit. Re-sticks once a trial stays
    within the sliding limit (the slip stopped or turned).

    Returns (sx, sy, sz, lost, slides): the new stretch, the energy dissipated this step
    (work of the contact on the spring, trapezoidal force times ``ds`` as velocity Verlet
    changes the kinetic energy, minus the energy the spring gained), J, and whether it slid.
    """
    sn = sx * nx + sy * ny + sz * nz
    sx -= sn * nx
    sy -= sn * ny
    sz -= sn * nz
    lost = 0.5 * k_old * sn * sn
    old2 = sx * sx + sy * sy + sz * sz
    if k != k_old:
        held = 0.5 * k_old * old2
        if k > k_old:
            scale = k_old / k
            sx *= scale
            sy *= scale
            sz *= scale
            old2 = sx * sx + sy * sy + sz * sz
        lost += held - 0.5 * k * old2
    dn = dsx * nx + dsy * ny + dsz * nz
    dsx -= dn * nx
    dsy -= dn * ny
    dsz -= dn * nz
    ax = sx + dsx
    ay = sy + dsy
    az = sz + dsz
    trial2 = ax * ax + ay * ay + az * az
    limit = slide_limit if sliding else stick_limit
    slides = False
    if k * k * trial2 > limit * limit:
        keep = slide_limit / (k * np.sqrt(trial2))
        ax *= keep
        ay *= keep
        az *= keep
        work = 0.5 * k * ((sx + ax) * dsx + (sy + ay) * dsy + (sz + az) * dsz)
        gained = 0.5 * k * (ax * ax + ay * ay + az * az - old2)
        lost = lost + work - gained
        slides = True
    return ax, ay, az, lost, slides


@njit(cache=True, inline="always")
def coulomb_friction_scale(f_n, vt, mu, v_reg, m_t, dt):
    """Eq. 5 as a factor on the tangential slip velocity: f_t = scale * v_t (``vt`` > 0).

    Coulomb mu |f_n| against the slip, scaled down linearly below ``v_reg`` (no chatter at
    v_t -> 0) and capped at m_t v_t / (2 dt) so that one step can never reverse the slip
    (friction never injects energy).
    """
    ft = mu * abs(f_n)
    if vt < v_reg:
        ft *= vt / v_reg
    cap = 0.5 * m_t * vt / dt
    if ft > cap:
        ft = cap
    return -ft / vt


def normal_force(delta_m, delta_dot_m_s, *, stiffness: float, damping: float,
                 mode: NormalDampingMode):
    """Eq. 2 normal force magnitude (repulsive positive), N, elementwise.

    ``damping`` is ``alpha sqrt(m* k_n)``. ``mode="no_attraction"`` clips the total at zero
    (no adhesion at the end of a contact); ``"literal"`` keeps Eq. 2 as written. The same
    law as the kernel's (:func:`hertz_normal_force`).
    """
    check_damping_mode(mode)
    d, v = np.broadcast_arrays(np.asarray(delta_m, dtype=float),
                               np.asarray(delta_dot_m_s, dtype=float))
    out = np.array([hertz_normal_force(a, b, stiffness, damping, mode == "no_attraction")[1]
                    for a, b in zip(d.ravel(), v.ravel(), strict=True)]).reshape(d.shape)
    return out if out.ndim else float(out)


def elastic_energy(delta_m, *, stiffness: float):
    """Energy stored in a Hertz contact, (2/5) k_n delta^(5/2), J, elementwise."""
    d = np.asarray(delta_m, dtype=float)
    out = np.array([hertz_elastic_energy(a, stiffness) for a in d.ravel()]).reshape(d.shape)
    return out if out.ndim else float(out)


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


#: Slots of the per-pair parameter vector the kernel reads (:meth:`PairLaw.kernel_vector`).
LAW_STIFFNESS = 0  # Hertz k_n, N/m^1.5
LAW_DAMPING = 1  # alpha sqrt(m* k_n), N s/m^1.25
LAW_SLIDING = 2  # mu
LAW_STATIC = 3  # mu_s
LAW_TANGENTIAL_MASS = 4  # m_t, kg (Coulomb model's cap)
LAW_TANGENTIAL_STIFFNESS = 5  # constant k_t, N/m
LAW_MINDLIN_FACTOR = 6  # 8 G* sqrt(R*) when k_t follows the overlap, else 0
LAW_ROLLING_STIFFNESS = 7  # k_r, N m/rad (0: no rolling resistance)
LAW_ROLLING_ARM = 8  # mu_r R*, m: largest rolling torque per unit normal force
LAW_ROLLING_DAMPING = 9  # C_r, N m s/rad
N_LAW = 10


@dataclass(frozen=True)
class PairLaw:
    """Contact law of one pair of bodies (particle-particle or particle-wall), SI units.

    The dimensionless coefficients of :class:`~pidcore.dem.materials.PairParameters` plus
    what follows from the materials and the particle:

    ``stiffness``: Hertz k_n = 4/3 E* sqrt(R*), N/m^(3/2). ``alpha``: Eq. 3 damping constant
    (or an override) [-]; ``damping``: alpha sqrt(m* k_n), N s / m^(5/4).
    ``shear_modulus_pa``: Mindlin's G*, Pa. ``tangential_stiffness``: the constant k_t of the
    stick-slip spring, Mindlin's 8 G* sqrt(R* delta_ref) at the largest overlap delta_ref of a
    DEM_TANGENTIAL_REFERENCE_SPEED_M_S impact, N/m (the ``"mindlin"`` option uses
    8 G* sqrt(R* delta) of the current overlap instead). ``tangential_mass_kg``: effective mass
    of sliding at the contact point, 1/m_t = sum(1/m + arm^2/I), which caps Eq. 5's Coulomb
    force (``coulomb`` model). ``rolling_stiffness``: k_r = 2.25 mu_r^2 R*^2 k_n' (Ai et al.
    2011, with k_n' = 3/2 k_n sqrt(delta_ref) the Hertz tangent stiffness at delta_ref),
    N m/rad; ``rolling_inertia_kg_m2``: I_r = 1/sum(1/(I + m r^2)); ``rolling_damping``:
    eta_r 2 sqrt(I_r k_r), N m s/rad.
    """

    restitution: float
    sliding_friction: float
    static_friction: float
    rolling_friction: float
    rolling_damping_ratio: float
    alpha: float
    effective_radius_m: float
    effective_mass_kg: float
    stiffness: float
    damping: float
    shear_modulus_pa: float
    tangential_stiffness: float
    tangential_mass_kg: float
    rolling_stiffness: float
    rolling_inertia_kg_m2: float
    rolling_damping: float

    @property
    def parameters(self) -> PairParameters:
        """The dimensionless coefficients this law was built from."""
        return PairParameters(restitution=self.restitution,
                              sliding_friction=self.sliding_friction,
                              static_friction=self.static_friction,
                              rolling_friction=self.rolling_friction,
                              rolling_damping_ratio=self.rolling_damping_ratio)

    @property
    def mindlin_factor(self) -> float:
        """8 G* sqrt(R*): Mindlin's k_t = mindlin_factor sqrt(delta), N/m^(3/2)."""
        return 8.0 * self.shear_modulus_pa * np.sqrt(self.effective_radius_m)

    def kernel_vector(self, *, mindlin: bool = False) -> np.ndarray:
        """The parameters as the kernel reads them (slots ``LAW_*``), SI units."""
        v = np.zeros(N_LAW)
        v[LAW_STIFFNESS] = self.stiffness
        v[LAW_DAMPING] = self.damping
        v[LAW_SLIDING] = self.sliding_friction
        v[LAW_STATIC] = self.static_friction
        v[LAW_TANGENTIAL_MASS] = self.tangential_mass_kg
        v[LAW_TANGENTIAL_STIFFNESS] = self.tangential_stiffness
        v[LAW_MINDLIN_FACTOR] = self.mindlin_factor if mindlin else 0.0
        v[LAW_ROLLING_STIFFNESS] = self.rolling_stiffness
        v[LAW_ROLLING_ARM] = self.rolling_friction * self.effective_radius_m
        v[LAW_ROLLING_DAMPING] = self.rolling_damping
        return v

    def contact_time(self, impact_speed_m_s: float) -> float:
        """Hertz contact time of this pair at the given impact speed, s."""
        return hertz_contact_time(stiffness=self.stiffness, mass_kg=self.effective_mass_kg,
                                  impact_speed_m_s=impact_speed_m_s)

    def spring_period(self) -> float:
        """Shortest period of the stuck tangential and rolling springs, s (inf without)."""
        period = 2.0 * np.pi * np.sqrt(self.tangential_mass_kg / self.tangential_stiffness)
        if self.rolling_stiffness > 0.0:
            period = min(period, 2.0 * np.pi * np.sqrt(self.rolling_inertia_kg_m2
                                                       / self.rolling_stiffness))
        return float(period)


def pair_law(parameters: PairParameters, *, e_star_pa: float, g_star_pa: float,
             r_star_m: float, m_star_kg: float, tangential_mass_kg: float,
             rolling_inertia_kg_m2: float, alpha: float | None = None) -> PairLaw:
    """Derive a :class:`PairLaw` from a pair's coefficients and effective properties.

    ``alpha`` overrides Eq. 3 of ``parameters.restitution``.
    """
    k_n = hertz_stiffness(e_star_pa, r_star_m)
    delta_ref = maximum_overlap(stiffness=k_n, mass_kg=m_star_kg,
                                impact_speed_m_s=defaults.DEM_TANGENTIAL_REFERENCE_SPEED_M_S)
    a = damping_constant_from_restitution(parameters.restitution) if alpha is None \
        else float(alpha)
    mu_r = parameters.rolling_friction
    k_r = 2.25 * mu_r**2 * r_star_m**2 * 1.5 * k_n * np.sqrt(delta_ref)
    return PairLaw(
        restitution=parameters.restitution, sliding_friction=parameters.sliding_friction,
        static_friction=parameters.static_friction, rolling_friction=mu_r,
        rolling_damping_ratio=parameters.rolling_damping_ratio, alpha=a,
        effective_radius_m=r_star_m, effective_mass_kg=m_star_kg, stiffness=k_n,
        damping=a * np.sqrt(m_star_kg * k_n), shear_modulus_pa=g_star_pa,
        tangential_stiffness=tangential_stiffness(g_star_pa, r_star_m, delta_ref),
        tangential_mass_kg=tangential_mass_kg, rolling_stiffness=k_r,
        rolling_inertia_kg_m2=rolling_inertia_kg_m2,
        rolling_damping=parameters.rolling_damping_ratio * 2.0
        * np.sqrt(rolling_inertia_kg_m2 * k_r))


@dataclass(frozen=True)
class ContactLaw:
    """All contact parameters of one particle material in a cell (SI units).

    ``pair_particle``: the particle-particle :class:`PairLaw`; ``pair_wall``: particle-wall.
    ``particle`` and ``wall``: the materials they derive from. ``tangential_stiffness_model``:
    ``"constant"`` (k_t of the reference overlap; default) or ``"mindlin"`` (k_t from the
    current overlap, see :mod:`pidcore.dem.kernel`).

    Build with :meth:`for_material` (the CSV tables, optionally overriding pair rows) or
    :meth:`from_properties` (anything, e.g. a user's specimen).
    """

    particle_material: str
    radius_m: float
    mass_kg: float
    inertia_kg_m2: float
    particle: MaterialProperties
    wall: MaterialProperties
    pair_particle: PairLaw
    pair_wall: PairLaw
    tangential_stiffness_model: TangentialStiffnessModel = "constant"

    @classmethod
    def from_properties(cls, *, particle: MaterialProperties, radius_m: float,
                        wall: MaterialProperties, pair_particle: PairParameters,
                        pair_wall: PairParameters, particle_material: str = "custom",
                        alpha_pp: float | None = None, alpha_pw: float | None = None,
                        tangential_stiffness_model: TangentialStiffnessModel = "constant",
                        ) -> ContactLaw:
        """Build from explicit material properties and pair coefficients.

        Parameters
        ----------
        particle, wall : MaterialProperties
            Density and elastic constants of the spheres and of the (flat, rigid-body) walls.
        radius_m : float
            Sphere radius, m.
        pair_particle, pair_wall : PairParameters
            Restitution and friction coefficients, particle-particle and particle-wall.
        particle_material : str
            Name shown in messages and records.
        alpha_pp, alpha_pw : float, optional
            Override Eq. 3's damping constant (particle-particle, particle-wall).
        tangential_stiffness_model : {"constant", "mindlin"}

        Examples
        --------
        >>> steel = MaterialProperties(density_kg_m3=7800, youngs_modulus_pa=200e9,
        ...                            poisson_ratio=0.3)
        >>> law = ContactLaw.from_properties(
        ...     particle=steel, radius_m=1e-3, wall=steel, particle_material="steel",
        ...     pair_particle=PairParameters(restitution=0.9, sliding_friction=0.2),
        ...     pair_wall=PairParameters(restitution=0.9, sliding_friction=0.2,
        ...                              static_friction=0.3))
        >>> law.pair_wall.static_friction
        0.3
        """
        if not (np.isfinite(radius_m) and radius_m > 0):
            raise ParameterError(f"radius: expected > 0 m, got {radius_m}")
        if tangential_stiffness_model not in TANGENTIAL_STIFFNESS_MODELS:
            raise ParameterError(f"tangential_stiffness_model: expected one of "
                                 f"{TANGENTIAL_STIFFNESS_MODELS}, "
                                 f"got {tangential_stiffness_model!r}")
        r = float(radius_m)
        m = particle.sphere_mass(r)
        inertia = 0.4 * m * r * r
        e_p, nu_p = particle.youngs_modulus_pa, particle.poisson_ratio
        e_w, nu_w = wall.youngs_modulus_pa, wall.poisson_ratio
        rolling_one = inertia + m * r * r  # Ai et al.: I + m r^2 of one sphere
        pp = pair_law(pair_particle, e_star_pa=effective_modulus(e_p, nu_p, e_p, nu_p),
                      g_star_pa=effective_shear_modulus(e_p, nu_p, e_p, nu_p),
                      r_star_m=effective_radius(r, r), m_star_kg=effective_mass(m, m),
                      tangential_mass_kg=1.0 / (2.0 / m + 2.0 * r * r / inertia),
                      rolling_inertia_kg_m2=0.5 * rolling_one, alpha=alpha_pp)
        pw = pair_law(pair_wall, e_star_pa=effective_modulus(e_p, nu_p, e_w, nu_w),
                      g_star_pa=effective_shear_modulus(e_p, nu_p, e_w, nu_w),
                      r_star_m=effective_radius(r, None), m_star_kg=effective_mass(m, None),
                      tangential_mass_kg=1.0 / (1.0 / m + r * r / inertia),
                      rolling_inertia_kg_m2=rolling_one, alpha=alpha_pw)
        return cls(particle_material=particle_material, radius_m=r, mass_kg=m,
                   inertia_kg_m2=inertia, particle=particle, wall=wall,
                   pair_particle=pp, pair_wall=pw,
                   tangential_stiffness_model=tangential_stiffness_model)

    @classmethod
    def for_material(cls, name: str, *, radius_m: float | None = None,
                     alpha_pp: float | None = None, alpha_pw: float | None = None,
                     pair_particle: PairParameters | None = None,
                     pair_wall: PairParameters | None = None,
                     tangential_stiffness_model: TangentialStiffnessModel = "constant",
                     ) -> ContactLaw:
        """Build from the CSV tables (``pidcore/data``) for a particle material.

        ``radius_m`` defaults to the table's radius, ``pair_particle``/``pair_wall`` to the
        table's pair rows (with the aluminium wall), ``alpha_*`` to Eq. 3 of their e_n.

        Examples
        --------
        >>> ContactLaw.for_material("acrylic").pair_particle.sliding_friction
        0.096
        """
        mat = material(name)
        if mat.role != "particle":
            raise ParameterError(f"material: {name!r} is not a particle material")
        r = mat.default_radius_m if radius_m is None else float(radius_m)
        return cls.from_properties(
            particle=mat.properties, radius_m=r, wall=material(WALL_MATERIAL).properties,
            pair_particle=pair_properties(name, name) if pair_particle is None
            else pair_particle,
            pair_wall=pair_properties(name, WALL_MATERIAL) if pair_wall is None else pair_wall,
            particle_material=name, alpha_pp=alpha_pp, alpha_pw=alpha_pw,
            tangential_stiffness_model=tangential_stiffness_model)

    def with_parameters(self, *, pair_particle: PairParameters | None = None,
                        pair_wall: PairParameters | None = None,
                        alpha_pp: float | None = None, alpha_pw: float | None = None,
                        tangential_stiffness_model: TangentialStiffnessModel | None = None,
                        ) -> ContactLaw:
        """The same particle and walls with other pair coefficients (or alpha, k_t model).

        A pair left unchanged keeps its alpha; a new pair gets Eq. 3 unless ``alpha_*``.
        """
        if alpha_pp is None and pair_particle is None:
            alpha_pp = self.pair_particle.alpha
        if alpha_pw is None and pair_wall is None:
            alpha_pw = self.pair_wall.alpha
        return ContactLaw.from_properties(
            particle=self.particle, radius_m=self.radius_m, wall=self.wall,
            pair_particle=pair_particle or self.pair_particle.parameters,
            pair_wall=pair_wall or self.pair_wall.parameters,
            particle_material=self.particle_material, alpha_pp=alpha_pp, alpha_pw=alpha_pw,
            tangential_stiffness_model=tangential_stiffness_model
            or self.tangential_stiffness_model)

    def frictionless(self) -> ContactLaw:
        """This law with every friction coefficient (sliding, static, rolling) at zero."""
        def off(p: PairLaw) -> PairLaw:
            return dataclasses.replace(p, sliding_friction=0.0, static_friction=0.0,
                                       rolling_friction=0.0, rolling_stiffness=0.0,
                                       rolling_damping=0.0)
        return dataclasses.replace(self, pair_particle=off(self.pair_particle),
                                   pair_wall=off(self.pair_wall))

    def contact_time(self, impact_speed_m_s: float) -> float:
        """Shortest Hertz contact time (wall or pair) at the given impact speed, s."""
        return min(self.pair_wall.contact_time(impact_speed_m_s),
                   self.pair_particle.contact_time(impact_speed_m_s))

    def tangential_period(self) -> float:
        """Shortest period of a stuck tangential or rolling spring (pair or wall), s.

        With Mindlin's k_t, at the largest overlap the kernel accepts
        (DEM_MAX_OVERLAP_FRACTION of the radius).
        """
        pairs = (self.pair_particle, self.pair_wall)
        if self.tangential_stiffness_model == "mindlin":
            delta = defaults.DEM_MAX_OVERLAP_FRACTION * self.radius_m
            pairs = tuple(dataclasses.replace(
                p, tangential_stiffness=p.mindlin_factor * np.sqrt(delta)) for p in pairs)
        return min(p.spring_period() for p in pairs)


def check_damping_mode(mode: str) -> None:
    if mode not in NORMAL_DAMPING_MODES:
        raise ParameterError(
            f"normal_damping_mode: expected one of {NORMAL_DAMPING_MODES}, got {mode!r}")


def check_tangential_model(model: str) -> None:
    if model not in TANGENTIAL_MODELS:
        raise ParameterError(
            f"tangential_model: expected one of {TANGENTIAL_MODELS}, got {model!r}")
