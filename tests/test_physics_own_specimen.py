"""An independent physics audit on a specimen unlike the paper's: 6.35 mm hexagonal cells, a
12.7 mm core, 2 mm tungsten-carbide spheres (15.6x acrylic's density, 200x its modulus),
aluminium walls, a fixture and a baseline loss factor.

Every expected number is computed here from first principles (sphere mass, Hertz's
k_n = 4/3 E* sqrt(R*), Mindlin's k_t = 8 G* sqrt(R* delta), Johnson's impact time
2.9432 delta_max / v, the Tsuji-damped Hertz impact of Eq. 2-3 integrated by scipy, Newton on an
incline, a rolling sphere under a rolling torque), never by pidcore's own helpers; pidcore is run
only through its public entry points (``describe``, the kernel's ``advance``,
``simulate_impact``, ``simulate_load_case``).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from _incline import Incline
from scipy.integrate import solve_ivp

from pidcore.cli import main
from pidcore.dem.geometry import CellGeometry
from pidcore.dem.impact import simulate_impact
from pidcore.dem.simulate import DemConfig, simulate_load_case
from pidcore.dem.state import CellsState, KernelSettings, advance
from pidcore.errors import ParameterError
from pidcore.loadcase import LoadCase
from pidcore.specimen import Specimen, contact_law, describe

G0 = 9.80665
WC_TEXT = """\
schema_version = 1
name = "wc_6mm"
description = "6.35 mm x 12.7 mm aluminium honeycomb, 2 mm tungsten carbide spheres"
[cell]
shape = "hexagonal"
inscribed_diameter_m = 6.35e-3
height_m = 12.7e-3
count = 286
wall_material = "aluminium_wall"
[coupon]
mass_kg = 0.0333
fixture_mass_kg = 0.02
baseline_loss_factor = 0.004
[particles]
material = "tungsten_carbide"
radius_m = 1.0e-3
density_kg_m3 = 15630.0
youngs_modulus_pa = 600e9
poisson_ratio = 0.22
fill_percent = 50.0
[pairs.particle_particle]
restitution = 0.9
sliding_friction = 0.2
static_friction = 0.25
rolling_friction = 0.002
rolling_damping_ratio = 0.0
[pairs.particle_wall]
restitution = 0.75
sliding_friction = 0.3
static_friction = 0.35
rolling_friction = 0.005
rolling_damping_ratio = 0.0
"""
WC = Specimen.from_text(WC_TEXT)
R, RHO, E, NU = 1.0e-3, 15630.0, 600e9, 0.22
E_WALL, NU_WALL = 72e9, 0.33  # aluminium_wall of materials.csv (Table 2's face sheet)
D_FLAT, H = 6.35e-3, 12.7e-3
MASS = 4.0 / 3.0 * math.pi * R**3 * RHO


def _edit(old: str, new: str) -> str:
    assert old in WC_TEXT, old
    return WC_TEXT.replace(old, new, 1)


def _hertz(e_star: float, r_star: float) -> float:
    return 4.0 / 3.0 * e_star * math.sqrt(r_star)


def _max_overlap(k_n: float, m_star: float, v: float) -> float:
    # energy: 1/2 m v^2 = 2/5 k_n delta^(5/2)
    return (5.0 * m_star * v**2 / (4.0 * k_n)) ** 0.4


E_PP = 1.0 / (2.0 * (1 - NU**2) / E)
E_PW = 1.0 / ((1 - NU**2) / E + (1 - NU_WALL**2) / E_WALL)
K_PP, K_PW = _hertz(E_PP, R / 2), _hertz(E_PW, R)


def test_specimen_check_numbers_match_first_principles():
    facts = describe(WC)
    # shear: 1/G* = (2 - nu1)/G1 + (2 - nu2)/G2 (Mindlin); k_t at a 0.3 m/s impact's overlap
    g, g_wall = E / (2 * (1 + NU)), E_WALL / (2 * (1 + NU_WALL))
    g_pp, g_pw = 1 / (2 * (2 - NU) / g), 1 / ((2 - NU) / g + (2 - NU_WALL) / g_wall)
    kt_pp = 8 * g_pp * math.sqrt(R / 2 * _max_overlap(K_PP, MASS / 2, 0.3))
    kt_pw = 8 * g_pw * math.sqrt(R * _max_overlap(K_PW, MASS, 0.3))
    # hardest impact of the Table 3 grid (50 Hz, 10 g): wall and particle each at the drive's
    # velocity amplitude, opposite, plus a fall over the core height
    v = 2 * 10 * G0 / (2 * math.pi * 50) + math.sqrt(2 * G0 * H)
    t_contact = min(2.9432 * _max_overlap(K_PP, MASS / 2, v) / v,
                    2.9432 * _max_overlap(K_PW, MASS, v) / v)
    # a stuck tangential spring: the contact point's mass with rolling is 2/7 of m*
    t_spring = min(2 * math.pi * math.sqrt(2 / 7 * MASS / 2 / kt_pp),
                   2 * math.pi * math.sqrt(2 / 7 * MASS / kt_pw))
    n = facts["capacity_per_cell"] // 2  # fill 50 %
    expected = {
        "particle_mass_kg": MASS,
        "normal_stiffness_pp_n_m1_5": K_PP, "normal_stiffness_pw_n_m1_5": K_PW,
        "tangential_stiffness_pp_n_m": kt_pp, "tangential_stiffness_pw_n_m": kt_pw,
        "reference_impact_speed_m_s": v, "contact_time_s": t_contact,
        "tangential_period_s": t_spring,
        "time_step_s": min(2e-6, t_contact / 10, t_spring / 10),
        "wall_to_wall_gap_m": D_FLAT - 2 * R, "floor_to_ceiling_gap_m": H - 2 * R,
        "particles_mass_kg": 286 * n * MASS,
        "vibrated_mass_kg": 0.0333 + 0.02 + 286 * n * MASS,
    }
    for key, value in expected.items():
        # 1e-12: the same closed forms in another order of operations
        assert facts[key] == pytest.approx(value, rel=1e-12), key
    assert facts["particles_per_cell"] == n


def test_capacity_lies_between_a_layered_packing_and_keplers_bound():
    # A packing that surely fits: layers of 7 touching spheres (one on the axis, six around it
    # at 2r, inside the centres' hexagon of apothem a - r = 2.175 mm) stacked every 2r in the
    # 10.7 mm of room: 6 layers, 42. No packing beats Kepler's pi/sqrt(18) of the cell volume.
    apothem_room = D_FLAT / 2 - R
    assert 2 * R <= apothem_room  # the ring at 2r clears every side wall
    layers = math.floor((H - 2 * R) / (2 * R)) + 1
    cell_volume = math.sqrt(3) / 2 * D_FLAT**2 * H  # flat-to-flat d: area (sqrt 3 / 2) d^2
    kepler = math.pi / math.sqrt(18) * cell_volume / (4 / 3 * math.pi * R**3)
    assert 7 * layers <= describe(WC)["capacity_per_cell"] <= kepler


def test_hexagon_is_given_across_the_flats():
    # Table 2 gives the inscribed circle's diameter: the side walls lie d/2 from the axis, the
    # corners d/sqrt(3), the area is (sqrt 3 / 2) d^2 (286 cells tile a 100 x 100 mm coupon)
    cell = CellGeometry(D_FLAT, H)
    corner = np.array([D_FLAT / math.sqrt(3), 0.0, 0.0])
    flat = np.array([0.0, D_FLAT / 2, 0.0])
    assert cell.signed_distances(corner)[:6].min() == pytest.approx(0.0, abs=1e-15)
    assert cell.signed_distances(flat)[:6].min() == pytest.approx(0.0, abs=1e-15)
    assert cell.volume_m3() == pytest.approx(math.sqrt(3) / 2 * D_FLAT**2 * H, rel=1e-14)
    assert round(0.1**2 / (math.sqrt(3) / 2 * D_FLAT**2)) == 286


def _tsuji_restitution(restitution: float, k_n: float, m_star: float, v: float) -> float:
    """e of Eq. 2 as printed (literal) with alpha of Eq. 3, by an accurate ODE integration."""
    log_e = math.log(restitution)
    alpha = -log_e * math.sqrt(5.0 / (log_e**2 + math.pi**2))
    c = alpha * math.sqrt(m_star * k_n)

    def rhs(t, y):
        d, dd = y
        if d <= 0:
            return [dd, 0.0]
        return [dd, -(k_n * d**1.5 + c * d**0.25 * dd) / m_star]

    def separated(t, y):
        return y[0] if t > 0 else 1.0

    separated.terminal, separated.direction = True, -1
    t_c = 2.9432 * _max_overlap(k_n, m_star, v) / v
    out = solve_ivp(rhs, [0, 10 * t_c], [0.0, v], events=separated, rtol=1e-11, atol=1e-16,
                    max_step=t_c / 2000)
    return -out.y_events[0][0][1] / v


@pytest.mark.parametrize("pair, e_table, k_n, m_star", [
    ("wall", 0.75, K_PW, MASS), ("particle", 0.9, K_PP, MASS / 2)], ids=["wall", "particle"])
def test_single_bounce_restitution_is_the_tables_per_pair(pair, e_table, k_n, m_star):
    # Eq. 3 is the exact alpha(e) of the Hertz-Tsuji law as printed: the ODE gives e back to
    # 1e-6, at any speed (the law is scale-free)
    law = contact_law(WC)
    for v in (0.1, 1.0):
        e_ode = _tsuji_restitution(e_table, k_n, m_star, v)
        assert e_ode == pytest.approx(e_table, abs=1e-6)
        dt = 2.9432 * _max_overlap(k_n, m_star, v) / v / 50
        out = simulate_impact(pair=pair, impact_speed_m_s=v, dt_s=dt, law=law, mode="literal")
        # 0.2 %: 50 velocity-Verlet steps per contact (measured 3.6e-4 and 5.5e-4)
        assert out.restitution == pytest.approx(e_ode, rel=2e-3)
        # what it loses is what it tallies (0.1 %, the same steps)
        lost = out.kinetic_energy_before_j - out.kinetic_energy_after_j
        assert out.dissipated_normal_j == pytest.approx(lost, rel=1e-3)


def test_free_flight_is_a_parabola():
    # no contact for 3 ms in mid-cell: velocity Verlet is exact for constant gravity, spin kept
    law = contact_law(WC)
    state = CellsState.from_positions(np.zeros((1, 1, 3)), mass_kg=law.mass_kg)
    v0 = np.array([0.2, -0.1, 0.5])
    state.vel[:, 0, 0] = v0
    state.omg[:, 0, 0] = [100.0, 0.0, 0.0]
    dt, n = 1e-6, 3000
    advance(state, KernelSettings(law=law, geometry=WC.geometry(), dt_s=dt), n)
    t = n * dt
    # 1e-12: round-off of 3000 additions of g dt (measured 1.6e-13 m/s, 2.5e-16 m)
    np.testing.assert_allclose(state.pos[:, 0, 0], v0 * t + [0, 0, -0.5 * G0 * t**2],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(state.vel[:, 0, 0], v0 + [0, 0, -G0 * t], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(state.omg[:, 0, 0], [100.0, 0.0, 0.0])


def _resting(law, theta: float, *, v0: float = 0.0, rolling: bool = False):
    """One sphere at its static Hertz overlap on the incline, its tangential spring holding the
    weight's down-slope part (a sphere put down gently), moving down-slope at ``v0``."""
    plane = Incline(theta)
    k_n = law.pair_wall.stiffness
    overlap = (law.mass_kg * G0 * math.cos(theta) / k_n) ** (2 / 3)
    state = CellsState.from_positions(((law.radius_m - overlap) * plane.normal)[None, None, :],
                                      mass_kg=law.mass_kg)
    state.frc[:, 0, 0] += law.mass_kg * G0 * math.cos(theta) * plane.normal
    state.vel[:, 0, 0] = v0 * plane.down
    if rolling:
        state.omg[:, 0, 0] = v0 / law.radius_m * np.cross(plane.normal, plane.down)
    else:
        k_t = law.pair_wall.tangential_stiffness
        state.spring_pw[0, 0, 6, :3] = law.mass_kg * G0 * math.sin(theta) / k_t * plane.down
        state.spring_pw[0, 0, 6, 4] = k_t
    return state, KernelSettings(law=law, geometry=plane, dt_s=2e-7), plane


def _slide(state, settings, plane, chunks: int, every: int):
    t, s, v = [], [], []
    for i in range(chunks):
        advance(state, settings, every)
        t.append((i + 1) * every * settings.dt_s)
        s.append(float(state.pos[:, 0, 0] @ plane.down))
        v.append(float(state.vel[:, 0, 0] @ plane.down))
    return np.array(t), np.array(s), np.array(v)


@pytest.mark.parametrize("tan_theta", [0.34, 0.36, 0.40])
def test_block_on_incline_holds_below_atan_mu_s_and_slides_at_the_sliding_friction(tan_theta):
    # WC on aluminium: mu_s 0.35, mu 0.3. A sphere that cannot turn holds at tan 0.34 and, past
    # atan(mu_s), slides with g (sin - mu cos)
    law = contact_law(WC)
    block = dataclasses.replace(law, inertia_kg_m2=law.inertia_kg_m2 * 1e12)
    theta = math.atan(tan_theta)
    state, settings, plane = _resting(block, theta)
    t, s, _ = _slide(state, settings, plane, 40, 1000)  # 8 ms
    if tan_theta < 0.35:
        assert np.abs(s).max() < 1e-9  # a 1 nm creep would be a slide of ~3e-5 m here
    else:
        keep = t >= 2e-3
        accel = 2 * np.polyfit(t[keep], s[keep], 2)[0]
        # 1e-6: constant friction once sliding, and Verlet is exact for constant force
        assert accel == pytest.approx(G0 * (math.sin(theta) - 0.3 * math.cos(theta)), rel=1e-6)


def test_rolling_sphere_stops_after_the_predicted_distance():
    # mu_r = 0.005 at the wall: m a = F, (I/r) a = -F r - mu_r r m g with I = 2/5 m r^2
    # -> a = -(5/7) mu_r g, s = 7 v0^2 / (10 mu_r g) = 5.71 mm after 0.57 s
    law = contact_law(WC)
    v0 = 0.02
    state, settings, plane = _resting(law, 0.0, v0=v0, rolling=True)
    t, s, v = _slide(state, settings, plane, 300, 25000)  # 1.5 s in 5 ms chunks
    stop = int(np.argmax(v <= 0.0))
    assert stop > 0
    # 1e-3: the stop sampled every 5 ms at 1.4e-4 m/s^2 deceleration moves s by < 2e-9 m
    assert s[stop] == pytest.approx(7 * v0**2 / (10 * 0.005 * G0), rel=1e-3)
    assert t[stop] == pytest.approx(v0 / (5 / 7 * 0.005 * G0), abs=5e-3)
    assert np.ptp(s[stop:]) < 1e-3 * s[stop]  # and stays there


def _mass_of_eq10(result) -> float:
    return 0.0333 + 0.02 + 286 * result.particles_per_cell * MASS


def test_driven_bed_with_every_law_and_mindlin_stiffness_balances_its_energy():
    # static friction, rolling resistance and the Mindlin k_t of the current overlap, at 200 Hz
    # and 10 g: the walls' work = change of mechanical energy + dissipation within 1 % (the
    # issue's bound), and the SDC is the dissipation per cycle over m_c a^2 / (2 w^2)
    spec = WC.with_values({"pairs.tangential_stiffness_model": "mindlin"})
    result = simulate_load_case(LoadCase(200.0, 10.0, 50.0, "tungsten_carbide"),
                                DemConfig(cells=1, steady_cycles=4, block_cycles=2,
                                          max_transient_cycles=2), specimen=spec)
    work = result.work_walls_j
    closure = work - result.mechanical_energy_change_j - result.dissipated_total_j
    assert abs(closure) <= 0.01 * work
    assert result.energy_dissipated_rolling_j > 0 and result.energy_dissipated_friction_j > 0
    omega, accel = 2 * math.pi * 200.0, 10 * G0
    energy = _mass_of_eq10(result) * accel**2 / (2 * omega**2)
    assert result.sdc == pytest.approx(result.energy_per_cycle_j / energy, rel=1e-12)
    assert result.loss_factor == pytest.approx(result.sdc / (2 * math.pi), rel=1e-12)


@pytest.mark.parametrize("direction", ["z", "x"])
def test_a_drive_far_below_lift_off_and_slip_damps_nothing(direction):
    # 0.01 g: the bed never leaves the floor (z) and no contact reaches mu_s (x): the particles
    # ride with the cell. What is left is micro-slip of contacts near their limit:
    # SDC < 1e-4, i.e. < 0.01 % of the 1-90 % a flying bed of these spheres gives
    result = simulate_load_case(
        LoadCase(100.0, 0.01, 50.0, "tungsten_carbide", direction),
        DemConfig(cells=1, steady_cycles=4, block_cycles=2, max_transient_cycles=2),
        specimen=WC)
    assert 0 <= result.sdc < 1e-4


@pytest.mark.parametrize("old, new, message", [
    # tungsten carbide's 15.63 g/cm^3 typed as kg/m^3: inside 10-25000 kg/m^3 by itself
    ("density_kg_m3 = 15630.0", "density_kg_m3 = 15.63",
     r"\[particles\] density_kg_m3: 15.63 kg/m\^3 with youngs_modulus_pa 6e\+11 Pa gives a "
     r"bar wave speed sqrt\(E/rho\) of 196 km/s; .*was the density in g/cm\^3"),
    # the same slip for lead (11.34 g/cm^3, 16 GPa)
    ("density_kg_m3 = 15630.0\nyoungs_modulus_pa = 600e9",
     "density_kg_m3 = 11.34\nyoungs_modulus_pa = 16e9", r"37.6 km/s"),
    # a rolling damping ratio of 30 %: an overdamped dashpot the explicit steps cannot settle
    ("rolling_damping_ratio = 0.0", "rolling_damping_ratio = 30.0",
     r"\[pairs.particle_particle\] rolling_damping_ratio: 30: expected a fraction of critical"
     r" .*was it %\?"),
])
def test_values_in_the_wrong_unit_are_refused_in_one_line(tmp_path, capsys, old, new, message):
    with pytest.raises(ParameterError, match=message):
        Specimen.from_text(_edit(old, new))
    path = tmp_path / "slip.toml"
    path.write_text(_edit(old, new), encoding="utf-8")
    assert main(["specimen", "check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "slip.toml" in err


@pytest.mark.parametrize("density, modulus", [
    (3515.0, 1.2e12),   # diamond, the fastest solid (18.5 km/s)
    (1850.0, 287e9),    # beryllium
    (19300.0, 411e9),   # tungsten
    (15.0, 5e6),        # expanded polystyrene beads
    (1180.0, 2.84e9),   # the paper's acrylic
])
def test_real_solids_pass_the_wave_speed_check(density, modulus):
    spec = Specimen.from_text(_edit("density_kg_m3 = 15630.0\nyoungs_modulus_pa = 600e9",
                                    f"density_kg_m3 = {density!r}\n"
                                    f"youngs_modulus_pa = {modulus!r}"))
    assert spec.particles.density_kg_m3 == density


def test_a_critically_damped_rolling_dashpot_is_accepted():
    spec = Specimen.from_text(_edit("rolling_damping_ratio = 0.0", "rolling_damping_ratio = 1.0"))
    assert spec.pairs.particle_particle.rolling_damping_ratio == 1.0


def test_cells_that_ran_one_motion_give_no_standard_error():
    # one sphere per cell driven along z never touches a side wall, so the cells' random start
    # xy changes nothing: both cells are one simulation. Their scatter is exactly 0, which
    # `dem run` printed as "SDC 0.2635 +- 0" for a bouncer that had not even settled
    lone = Specimen.from_text(_edit("fill_percent = 50.0", "count_per_cell = 1"))
    result = simulate_load_case(
        LoadCase(200.0, 5.0, 100.0 / describe(lone)["capacity_per_cell"], "tungsten_carbide"),
        DemConfig(cells=2, steady_cycles=4, block_cycles=2, max_transient_cycles=2),
        specimen=lone)
    assert result.particles_per_cell == 1
    assert result.sdc_per_cell[0] == result.sdc_per_cell[1] > 0  # the same motion
    assert math.isnan(result.sdc_stderr)
    assert any("no standard error: the 2 cells ran the same motion" in n for n in result.notes)
