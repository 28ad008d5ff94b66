"""Static friction, rolling resistance and the Mindlin tangential stiffness, against analytic
answers, through the production kernel (:func:`pidcore.dem.state.advance`)."""

import dataclasses
import math

import numpy as np
import pytest
from _incline import Incline

from pidcore.constants import STANDARD_GRAVITY as G
from pidcore.dem.contact import ContactLaw, capped_spring
from pidcore.dem.geometry import CellGeometry, random_packing
from pidcore.dem.impact import simulate_impact
from pidcore.dem.materials import PairParameters
from pidcore.dem.simulate import settle_bed
from pidcore.dem.state import CellsState, KernelSettings, advance, energies

DT = 1.0e-6  # > 15 steps per contact for acrylic at <= 1 m/s


def _law(sliding, static, rolling=0.0, *, frozen=False, model="constant", damping_ratio=0.0):
    pair = PairParameters(restitution=0.7, sliding_friction=sliding, static_friction=static,
                          rolling_friction=rolling, rolling_damping_ratio=damping_ratio)
    law = ContactLaw.for_material("acrylic", pair_particle=pair, pair_wall=pair,
                                  tangential_stiffness_model=model)
    if frozen:  # a sphere that cannot turn: a sliding block (no rolling down the slope)
        law = dataclasses.replace(law, inertia_kg_m2=law.inertia_kg_m2 * 1e12)
    return law


def _on_incline(law, theta, v0=0.0, spin=0.0, preload=False):
    """State of one sphere resting on the incline at its static overlap, moving down-slope.

    ``preload``: the tangential spring already holds the weight's down-slope part (a sphere
    put down gently; without it gravity is a step load and the undamped spring overshoots to
    twice the static force).
    """
    plane = Incline(theta)
    delta = (law.mass_kg * G * math.cos(theta) / law.pair_wall.stiffness) ** (2 / 3)
    state = CellsState.from_positions(((law.radius_m - delta) * plane.normal)[None, None, :],
                                      mass_kg=law.mass_kg)
    state.frc[:, 0, 0] += law.mass_kg * G * math.cos(theta) * plane.normal  # static contact
    state.vel[:, 0, 0] = v0 * plane.down
    state.omg[:, 0, 0] = spin * np.cross(plane.normal, plane.down)
    if preload:
        k_t = law.pair_wall.tangential_stiffness
        state.spring_pw[0, 0, 6, :3] = law.mass_kg * G * math.sin(theta) / k_t * plane.down
        state.spring_pw[0, 0, 6, 4] = k_t
    return state, KernelSettings(law=law, geometry=plane, dt_s=DT)


def _track(state, settings, chunks, every):
    """Down-slope position and velocity after each chunk of ``every`` steps."""
    down = settings.geometry.down
    s, v = [], []
    for _ in range(chunks):
        advance(state, settings, every)
        s.append(float(state.pos[:, 0, 0] @ down))
        v.append(float(state.vel[:, 0, 0] @ down))
    return np.arange(1, chunks + 1) * every * DT, np.array(s), np.array(v)


def _acceleration(t, s, start):
    """Second derivative of a least-squares parabola through s(t) for t >= start."""
    keep = t >= start
    return 2.0 * np.polyfit(t[keep], s[keep], 2)[0]


@pytest.mark.parametrize("tan_theta, sticks", [(0.35, True), (0.45, False)])
def test_block_on_incline_sticks_below_static_angle_and_slides_above(tan_theta, sticks):
    # mu = 0.2, mu_s = 0.4: from rest a non-rotating sphere holds below atan(mu_s) and, once
    # it breaks loose above it, slides against the *sliding* friction: a = g (sin - mu cos)
    law = _law(0.2, 0.4, frozen=True)
    theta = math.atan(tan_theta)
    state, settings = _on_incline(law, theta, preload=True)
    t, s, v = _track(state, settings, 50, 1000)  # 50 ms
    if sticks:
        # it stays within the spring's static stretch F / k_t (twice for any ringing)
        reach = 2 * law.mass_kg * G * math.sin(theta) / law.pair_wall.tangential_stiffness
        assert np.abs(s).max() <= 1.01 * reach
        assert reach < 1e-7  # i.e. it really holds: a slide would cover ~1 mm here
    else:
        expected = G * (math.sin(theta) - 0.2 * math.cos(theta))
        # constant friction mu |f_n| once sliding; the fit over 5-50 ms sees only the small
        # normal-contact ringing left from the start: 0.5 %
        assert _acceleration(t, s, 5e-3) == pytest.approx(expected, rel=5e-3)


def test_sliding_block_between_the_angles_keeps_sliding_at_the_sliding_friction():
    # tan(theta) = 0.3: above mu (0.2), below mu_s (0.4). Launched down-slope it never
    # re-sticks (the slip never stops) and accelerates at g (sin - mu cos), not at mu_s
    law = _law(0.2, 0.4, frozen=True)
    theta = math.atan(0.3)
    state, settings = _on_incline(law, theta, v0=0.05)
    t, s, v = _track(state, settings, 50, 1000)
    expected = G * (math.sin(theta) - 0.2 * math.cos(theta))
    assert _acceleration(t, s, 5e-3) == pytest.approx(expected, rel=5e-3)
    assert np.all(np.diff(v) > 0)


def test_sliding_block_below_the_sliding_angle_decelerates_stops_and_resticks():
    # tan(theta) = 0.1 < mu: decelerates at g (mu cos - sin), stops after v0^2 / (2 a), sticks
    law = _law(0.2, 0.4, frozen=True)
    theta = math.atan(0.1)
    v0 = 0.05
    decel = G * (0.2 * math.cos(theta) - math.sin(theta))
    state, settings = _on_incline(law, theta, v0=v0)
    t, s, v = _track(state, settings, 800, 100)  # 80 ms, stop at ~51 ms
    sliding = v > 1e-3
    assert _acceleration(t[sliding], s[sliding], 2e-3) == pytest.approx(-decel, rel=5e-3)
    # stop distance: 0.5 % (the spring's elastic stretch, ~1e-9 m, and ~0.1 ms sampling)
    assert s[-1] == pytest.approx(v0**2 / (2 * decel), rel=5e-3)
    # re-stuck: the last 20 ms stay within the stuck spring's elastic reach
    reach = 2 * 0.2 * law.mass_kg * G / law.pair_wall.tangential_stiffness
    assert np.ptp(s[t > 0.06]) <= reach


def test_equal_static_and_sliding_friction_slides_at_the_same_angle():
    # mu_s = mu = 0.2 (the model before static friction): tan(theta) = 0.3 breaks loose
    law = _law(0.2, 0.2, frozen=True)
    theta = math.atan(0.3)
    state, settings = _on_incline(law, theta, preload=True)
    t, s, _ = _track(state, settings, 50, 1000)
    assert _acceleration(t, s, 5e-3) == pytest.approx(
        G * (math.sin(theta) - 0.2 * math.cos(theta)), rel=5e-3)


@pytest.mark.parametrize("mu_r", [0.05, 0.1])
def test_rolling_sphere_stops_after_the_predicted_distance(mu_r):
    # a sphere rolling without slip on a flat floor, rolling torque mu_r R* m g (R* = r at a
    # wall): m a = F, I a / r = -F r - mu_r r m g  ->  a = -(5/7) mu_r g; s = 7 v0^2 / (10 mu_r g)
    law = _law(0.14, 0.14, mu_r)
    v0 = 0.05
    state, settings = _on_incline(law, 0.0, v0=v0, spin=v0 / law.radius_m)
    t, s, v = _track(state, settings, 1700, 100)  # 170 ms; it stops at v0 / (5/7 mu_r g)
    stop = int(np.argmax(v <= 0.0))
    assert stop > 0
    rolling = t < t[stop] - 2e-3
    assert _acceleration(t[rolling], s[rolling], 2e-3) == pytest.approx(
        -5 / 7 * mu_r * G, rel=5e-3)
    # 0.5 %: sampled every 0.1 ms near the stop, plus the spring's elastic angle (< 1 nm)
    assert s[stop] == pytest.approx(7 * v0**2 / (10 * mu_r * G), rel=5e-3)
    # it stays where it stopped: the spring only rocks elastically, no further rolling
    assert np.ptp(s[stop:]) < 1e-3 * s[stop]


def test_no_rolling_resistance_rolls_on():
    law = _law(0.14, 0.14, 0.0)
    v0 = 0.05
    state, settings = _on_incline(law, 0.0, v0=v0, spin=v0 / law.radius_m)
    _, _, v = _track(state, settings, 50, 1000)
    assert v[-1] == pytest.approx(v0, rel=1e-6)  # nothing resists rolling on a flat floor


def test_capped_spring_static_then_sliding_limit():
    # the law itself: a trial force between mu and mu_s holds when stuck, slides when sliding
    n = (0.0, 0.0, 1.0)
    k = 1e4
    sticky = capped_spring(0.0, 0.0, 0.0, 3e-5, 0.0, 0.0, *n, k, k, 0.4, 0.2, False)
    assert sticky[0] == 3e-5 and sticky[3] == 0.0 and not sticky[4]
    slid = capped_spring(0.0, 0.0, 0.0, 3e-5, 0.0, 0.0, *n, k, k, 0.4, 0.2, True)
    assert slid[0] == pytest.approx(0.2 / k) and slid[4]
    # lost = trapezoidal work on the spring minus its energy gain, >= 0
    assert slid[3] == pytest.approx(0.5 * k * (0 + 0.2 / k) * 3e-5 - 0.5 * k * (0.2 / k) ** 2)
    broke = capped_spring(0.0, 0.0, 0.0, 5e-5, 0.0, 0.0, *n, k, k, 0.4, 0.2, False)
    assert broke[0] == pytest.approx(0.2 / k) and broke[4]
    # Mindlin rescale: a stiffer contact keeps the force, a softer one the stretch; the
    # stored energy can only fall and the fall is counted as lost
    up = capped_spring(1e-5, 0.0, 0.0, 0.0, 0.0, 0.0, *n, 2 * k, k, 1.0, 1.0, False)
    assert up[0] * 2 * k == pytest.approx(1e-5 * k)
    assert up[3] == pytest.approx(0.5 * k * 1e-10 - 0.5 * 2 * k * (0.5e-5) ** 2)
    down = capped_spring(1e-5, 0.0, 0.0, 0.0, 0.0, 0.0, *n, 0.5 * k, k, 1.0, 1.0, False)
    assert down[0] == 1e-5 and down[3] == pytest.approx(0.5 * (k - 0.5 * k) * 1e-10)


ALL_ON = dict(sliding=0.14, static=0.3, rolling=0.05, damping_ratio=0.3)


@pytest.mark.parametrize("model", ["constant", "mindlin"])
@pytest.mark.parametrize("pair", ["wall", "particle"])
@pytest.mark.parametrize("vt", [0.01, 0.2, 1.0])
def test_impact_energy_conserved_with_every_law(model, pair, vt):
    # kinetic energy lost = normal + friction + rolling tallies; 1 %: the velocity Verlet
    # energy error at >= 15 steps per contact
    law = _law(ALL_ON["sliding"], ALL_ON["static"], ALL_ON["rolling"], model=model,
               damping_ratio=ALL_ON["damping_ratio"])
    out = simulate_impact(pair=pair, impact_speed_m_s=0.3, dt_s=DT, tangential_speed_m_s=vt,
                          spin_rad_s=300.0 if pair == "wall" else 0.0, law=law)
    lost = out.kinetic_energy_before_j - out.kinetic_energy_after_j
    tallied = out.dissipated_normal_j + out.dissipated_friction_j + out.dissipated_rolling_j
    assert out.dissipated_friction_j >= 0 and out.dissipated_rolling_j >= 0
    assert tallied == pytest.approx(lost, rel=0.01)


@pytest.mark.parametrize("model", ["constant", "mindlin"])
@pytest.mark.parametrize("freq, accel_g", [(100.0, 1.0), (500.0, 5.0)])
def test_driven_bed_energy_balance_with_every_law(model, freq, accel_g):
    # walls' work = change of mechanical energy (kinetic, gravity, Hertz and spring energy)
    # + normal, friction and rolling dissipation, within 1 % (the bound; the bundled
    # grid closes to < 0.6 % without these laws)
    geometry = CellGeometry()
    law = _law(ALL_ON["sliding"], ALL_ON["static"], ALL_ON["rolling"], model=model,
               damping_ratio=ALL_ON["damping_ratio"])
    rng = np.random.default_rng(7)
    pos = np.stack([random_packing(geometry, law.radius_m, 11, rng) for _ in range(3)])
    state = CellsState.from_positions(pos, mass_kg=law.mass_kg)
    dt = 1.0e-6
    rest = KernelSettings(law=law, geometry=geometry, dt_s=dt)
    settle_bed(state, rest)
    omega = 2 * np.pi * freq
    accel = accel_g * G
    state.vel[2] += -accel / omega  # moving with the cell when the drive starts
    drive = dataclasses.replace(rest, omega_rad_s=omega, accel_m_s2=accel)

    def mechanical(step):
        u = -accel / omega**2 * np.sin(omega * step * dt)
        return energies(state, law, geometry, wall_offset_m=np.array([0.0, 0.0, u]),
                        gravity_m_s2=G)[:, 3].sum()

    e0 = mechanical(state.step)
    tally, _ = advance(state, drive, int(20 / freq / dt))  # 20 cycles
    e1 = mechanical(state.step)
    work = tally[..., 0].sum()
    dissipated = tally[..., 1:].sum()
    assert tally[..., 2].sum() > 0 and tally[..., 3].sum() > 0  # the laws did act
    assert abs(work - (e1 - e0) - dissipated) <= 0.01 * max(abs(work), dissipated)
