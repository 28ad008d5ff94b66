"""Harmonic response with the amplitude-dependent particle damper."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import brentq

from pidcore.constants import STANDARD_GRAVITY
from pidcore.errors import ParameterError
from pidcore.model import (
    SdcModel,
    TreatedMode,
    coupon_vibrated_mass_kg,
    equivalent_damping_coefficient,
    harmonic_response,
    load_paper_table3,
    paper_particles_mass_kg,
    paper_vibrated_mass,
    time_domain_response,
)

FORCE_N = 10.0


@pytest.fixture
def model(paper_model) -> SdcModel:
    return paper_model


@pytest.fixture(scope="module")
def mode() -> TreatedMode:
    # 2 kg mode at 300 Hz, 1 % structural damping, 0.2 m^2 treated at 50 % fill: with 10 N the
    # response spans about 1-7 g between 250 and 360 Hz, inside the model's 1-10 g.
    mc = coupon_vibrated_mass_kg(particles_mass_kg=paper_particles_mass_kg(50))
    return TreatedMode(natural_frequency_hz=300.0, modal_mass_kg=2.0,
                       structural_damping_ratio=0.01, treated_area_m2=0.2, fill_percent=50.0,
                       coupon_vibrated_mass_kg=mc)


def test_solution_balances_the_force(model, mode):
    f = np.array([250.0, 280.0, 300.0, 320.0, 360.0])
    r = harmonic_response(model, mode, frequencies_hz=f, force_amplitude_n=FORCE_N)
    w = 2 * np.pi * f
    k, m = mode.stiffness_n_m, mode.modal_mass_kg
    c = mode.structural_damping_n_s_m + r.particle_damping_n_s_m
    np.testing.assert_allclose(r.amplitude_m * np.abs(k - m * w**2 + 1j * w * c), FORCE_N,
                               rtol=1e-10)
    # the damper is the model's SDC at the response's own acceleration
    np.testing.assert_allclose(r.acceleration_g, w**2 * r.amplitude_m / STANDARD_GRAVITY)
    np.testing.assert_allclose(r.sdc, model(50.0, r.acceleration_g, f), rtol=1e-12)
    expected_c = equivalent_damping_coefficient(
        r.sdc, vibrated_mass_kg=mode.coupon_vibrated_mass_kg, frequency_hz=f) / 0.01 * 0.2
    np.testing.assert_allclose(r.particle_damping_n_s_m, expected_c, rtol=1e-12)
    assert np.all(r.amplitude_m < r.amplitude_untreated_m)
    # at the undamped natural frequency the displacement lags the force by 90 degrees
    assert r.phase_rad[2] == pytest.approx(-np.pi / 2, abs=1e-12)
    assert not r.clipped.any()


def test_constant_sdc_gives_the_linear_oscillator(mode):
    # With SDC independent of amplitude the damper is linear: closed-form FRF.
    grid = pd.DataFrame(list(itertools.product([25.0, 90.0], [1.0, 10.0], [50.0, 1000.0])),
                        columns=["fill_percent", "acceleration_g", "frequency_hz"])
    grid["sdc"] = 0.3
    flat = SdcModel.from_table(grid, value="sdc")
    f = np.linspace(260, 340, 9)
    r = harmonic_response(flat, mode, frequencies_hz=f, force_amplitude_n=FORCE_N)
    w = 2 * np.pi * f
    c_pd = 0.3 * mode.coupon_vibrated_mass_kg * w / (2 * np.pi) / 0.01 * 0.2
    h = FORCE_N / (mode.stiffness_n_m - mode.modal_mass_kg * w**2
                   + 1j * w * (mode.structural_damping_n_s_m + c_pd))
    np.testing.assert_allclose(r.amplitude_m, np.abs(h), rtol=1e-10)
    np.testing.assert_allclose(r.phase_rad, np.angle(h), atol=1e-10)


@pytest.mark.slow
@pytest.mark.parametrize("frequency_hz", [270.0, 300.0, 330.0])
def test_harmonic_balance_matches_time_integration(model, mode, frequency_hz):
    # The time-domain damper c_pd(sqrt(x^2 + (v/w)^2)) v is the same nonlinear system; started
    # from rest it must settle on the harmonic-balance amplitude and phase. 2 % is the brief's
    # acceptance; with exact harmonic steady states the agreement is ~1e-8 (integrator rtol).
    hb = harmonic_response(model, mode, frequencies_hz=[frequency_hz], force_amplitude_n=FORCE_N)
    td = time_domain_response(model, mode, frequency_hz=frequency_hz, force_amplitude_n=FORCE_N,
                              rtol=1e-8)
    assert td.amplitude_m == pytest.approx(hb.amplitude_m[0], rel=0.02)
    assert td.amplitude_m == pytest.approx(hb.amplitude_m[0], rel=1e-5)
    assert td.peak_amplitude_m == pytest.approx(hb.amplitude_m[0], rel=1e-4)
    assert td.phase_rad == pytest.approx(hb.phase_rad[0], abs=1e-5)


def test_out_of_range_refused_or_clipped(model, mode):
    # 0.1 N far below resonance: the response is well below 1 g
    with pytest.raises(ParameterError, match="outside the SDC model range"):
        harmonic_response(model, mode, frequencies_hz=[200.0], force_amplitude_n=0.1)
    r = harmonic_response(model, mode, frequencies_hz=[200.0], force_amplitude_n=0.1,
                          clip_to_range=True)
    assert r.clipped[0] and r.acceleration_g[0] < 1.0
    assert r.sdc[0] == pytest.approx(float(model(50.0, 1.0, 200.0)), rel=1e-12)
    with pytest.raises(ParameterError, match="frequency 2000 Hz"):
        harmonic_response(model, mode, frequencies_hz=[2000.0], force_amplitude_n=FORCE_N)


def test_bad_parameters(model, mode):
    with pytest.raises(ParameterError, match="modal_mass_kg"):
        TreatedMode(natural_frequency_hz=300.0, modal_mass_kg=-1.0, structural_damping_ratio=0.01,
                    treated_area_m2=0.2, fill_percent=50.0, coupon_vibrated_mass_kg=0.1)
    with pytest.raises(ParameterError, match="force_amplitude_n"):
        harmonic_response(model, mode, frequencies_hz=[300.0], force_amplitude_n=0.0)


def test_plot_draws_both_curves(model, mode):
    from matplotlib.figure import Figure

    f = np.linspace(260, 340, 5)
    r = harmonic_response(model, mode, frequencies_hz=f, force_amplitude_n=FORCE_N)
    ax = Figure().subplots()
    r.plot(ax=ax)
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), r.amplitude_untreated_m)
    np.testing.assert_array_equal(ax.lines[1].get_ydata(), r.amplitude_m)


def test_multiple_solutions_flagged_and_largest_returned():
    # SDC collapsing from 0.9 at 3 g to 0.05 at 10 g makes X (c_s + c_pd(X)) non-monotone at
    # resonance: several amplitudes balance the force (jump phenomenon). The largest lies beyond
    # 10 g, so it needs clip_to_range (SDC held at its 10 g value).
    grid = pd.DataFrame(list(itertools.product([25.0, 90.0], [1.0, 3.0, 10.0], [50.0, 1000.0])),
                        columns=["fill_percent", "acceleration_g", "frequency_hz"])
    grid["sdc"] = grid["acceleration_g"].map({1.0: 0.9, 3.0: 0.9, 10.0: 0.05})
    dip = SdcModel.from_table(grid, value="sdc")
    mode = TreatedMode(natural_frequency_hz=300.0, modal_mass_kg=2.0,
                       structural_damping_ratio=0.002, treated_area_m2=0.2, fill_percent=50.0,
                       coupon_vibrated_mass_kg=0.1)
    # by default the root inside the range is the answer, the one beyond it named as such
    inside = harmonic_response(dip, mode, frequencies_hz=[300.0], force_amplitude_n=5.0)
    assert inside.multiple_solutions[0] and not inside.clipped[0]
    assert 1 <= inside.acceleration_g[0] <= 10
    assert "not conservative: a larger stable one lies beyond the range" in inside.multiple_note
    r = harmonic_response(dip, mode, frequencies_hz=[300.0], force_amplitude_n=5.0,
                          clip_to_range=True)
    assert r.multiple_solutions[0] and r.clipped[0] and r.acceleration_g[0] > 10
    w = 2 * np.pi * 300.0

    def residual(x):
        sdc = dip(50.0, np.clip(w**2 * x / STANDARD_GRAVITY, 1, 10), 300.0)
        c = mode.structural_damping_n_s_m + sdc * 0.1 * w / (2 * np.pi) / 0.01 * 0.2
        return x * np.abs(mode.stiffness_n_m - mode.modal_mass_kg * w**2 + 1j * w * c) - 5.0

    x_hi = r.amplitude_untreated_m[0]
    below = residual(np.geomspace(x_hi * 1e-3, r.amplitude_m[0] * (1 - 1e-6), 20000))
    above = residual(np.geomspace(r.amplitude_m[0] * (1 + 1e-6), x_hi, 20000))
    assert np.any(np.diff(np.sign(below)) != 0)  # a smaller root exists
    assert np.all(above > 0)  # none larger than the one returned


def _trial_jump_mode() -> TreatedMode:
    # 50 Hz mode, 25 % fill, 2 m^2 treated, structural zeta 0.0005: driven at 22.908 N on
    # resonance the paper's SDC dips enough for 5.48 g and 9.88 g to balance the force, and
    # 10.5 g with the 10 g SDC held beyond the model's edge
    return TreatedMode(natural_frequency_hz=50.0, modal_mass_kg=1.0,
                       structural_damping_ratio=0.0005, treated_area_m2=2.0, fill_percent=25.0,
                       coupon_vibrated_mass_kg=paper_vibrated_mass()(25.0))


def test_a_jump_region_is_answered_inside_the_model_and_names_every_steady_amplitude(model):
    # the default refused "10.5 g outside the model range", a root that only the held 10 g
    # SDC makes, though 5.48 g and 9.88 g inside the range balance the force
    mode, force, f = _trial_jump_mode(), 22.908, 50.0
    w = 2 * np.pi * f

    def needed_force(x):  # X |D(X)|: the force amplitude X takes, SDC at its own acceleration
        a = np.clip(w**2 * x / STANDARD_GRAVITY, 1.0, 10.0)
        c = (mode.structural_damping_n_s_m + model(25.0, a, f) * mode.coupon_vibrated_mass_kg
             * f / mode.coupon_area_m2 * mode.treated_area_m2)
        return x * np.abs(mode.stiffness_n_m - mode.modal_mass_kg * w**2 + 1j * w * c)

    # an independent root search, on the model's own 1-10 g only (no SDC held)
    xs = np.geomspace(1.0, 10.0, 20001) * STANDARD_GRAVITY / w**2
    excess = needed_force(xs) - force
    roots = [brentq(lambda x: needed_force(x) - force, xs[j], xs[j + 1], xtol=1e-16,
                    rtol=1e-14)
             for j in np.flatnonzero(np.sign(excess[:-1]) != np.sign(excess[1:]))]
    accelerations = [w**2 * x / STANDARD_GRAVITY for x in roots]
    assert [round(a, 2) for a in accelerations] == [5.48, 9.88]
    # at resonance a root is stable where the force it needs rises with X (the averaged
    # equations' determinant; their trace then is negative too)
    rising = [needed_force(x * (1 + 1e-6)) > needed_force(x * (1 - 1e-6)) for x in roots]
    assert rising == [True, False]
    # beyond 10 g the held SDC is constant: the force needed is linear in X there
    x_20g = 20 * STANDARD_GRAVITY / w**2
    held = force / (needed_force(x_20g) / x_20g)
    held_g = w**2 * held / STANDARD_GRAVITY
    assert held_g > 10

    r = harmonic_response(model, mode, frequencies_hz=[f], force_amplitude_n=force)
    # the largest stable root inside the range, to brentq's tolerance (1e-9 covers both
    # searches' xtol/rtol on X of ~5e-4 m)
    assert r.acceleration_g[0] == pytest.approx(accelerations[0], rel=1e-9)
    assert r.multiple_solutions[0] and not r.clipped[0] and r.clipped_note == ""
    assert r.multiple_note == r.to_pandas().attrs["multiple_note"]
    assert r.multiple_note.startswith(
        f"50 Hz: 3 steady amplitudes balance the force, {accelerations[0]:.3g} g (stable), "
        f"{accelerations[1]:.3g} g (unstable: the force it needs falls as it grows), "
        f"{held_g:.3g} g (stable; beyond the model's [1, 10] g, found with the edge SDC held: "
        "the model does not tell whether it exists")
    assert r.multiple_note.endswith(
        f"{accelerations[0]:.3g} g returned (the largest stable one inside the model's range, "
        "not conservative: a larger stable one lies beyond the range)")
    # clip_to_range takes the held root, as documented (the largest), and names the others
    clipped = harmonic_response(model, mode, frequencies_hz=[f], force_amplitude_n=force,
                                clip_to_range=True)
    assert clipped.acceleration_g[0] == pytest.approx(held_g, rel=1e-9)
    assert clipped.clipped[0] and clipped.multiple_note.endswith(
        f"{held_g:.3g} g returned (the largest stable one)")


def test_time_domain_response_says_harmonic_balance_has_other_steady_amplitudes(model):
    # from rest it settled on 5.48 g without a word of 9.88 g and the one beyond 10 g
    mode = _trial_jump_mode()
    hb = harmonic_response(model, mode, frequencies_hz=[50.0], force_amplitude_n=22.908)
    td = time_domain_response(model, mode, frequency_hz=50.0, force_amplitude_n=22.908)
    acc = (2 * np.pi * 50.0) ** 2 * td.amplitude_m / STANDARD_GRAVITY
    assert td.multiple_solutions
    listed = hb.multiple_note.split("; 5.48 g returned")[0]
    assert td.multiple_note == (f"{listed}; this integration from rest settled on {acc:.3g} g, "
                                "another start can settle on another")
    assert f"{acc:.3g} g (stable)" in listed


def test_a_single_steady_amplitude_is_unchanged_bit_for_bit_and_says_nothing(model, mode):
    r = harmonic_response(model, mode, frequencies_hz=[250.0, 300.0, 360.0],
                          force_amplitude_n=FORCE_N)
    # the amplitudes and phases before several roots were told apart, to the last bit
    before_m = ["0x1.3446ad85b6123p-18", "0x1.31f2c940cd901p-16", "0x1.a906df152bd43p-19"]
    before_rad = ["-0x1.25ba41a7cad42p-4", "-0x1.921fb54442d18p+0", "-0x1.801f98fe79f6dp+1"]
    assert [float(v).hex() for v in r.amplitude_m] == before_m
    assert [float(v).hex() for v in r.phase_rad] == before_rad
    assert not r.multiple_solutions.any()
    assert r.multiple_note == "" and r.to_pandas().attrs["multiple_note"] == ""


@pytest.mark.parametrize(("keywords", "said"), [
    # measured the transient from rest as the steady state
    ({"settle_cycles": -1}, "settle_cycles: expected >= 0 (or None), got -1"),
    ({"measure_cycles": 0}, "measure_cycles: expected >= 1, got 0"),  # numpy's ValueError
    ({"rtol": float("nan")},  # integrated for ever
     "rtol: expected a finite relative tolerance > 0, got nan"),
    ({"force_amplitude_n": "2"}, "force_amplitude_n: expected a number, got '2'"),
])
def test_time_domain_response_refuses_settings_it_cannot_honour(keywords, said):
    model = SdcModel.from_table(load_paper_table3())
    mode = TreatedMode(natural_frequency_hz=300.0, modal_mass_kg=0.5,
                       structural_damping_ratio=0.005, treated_area_m2=0.01, fill_percent=50.0,
                       coupon_vibrated_mass_kg=0.07)
    call = {"frequency_hz": 300.0, "force_amplitude_n": 2.0, "measure_cycles": 3,
            "settle_cycles": 20, **keywords}
    with pytest.raises(ParameterError) as refused:
        time_domain_response(model, mode, **call)
    assert str(refused.value) == said
    if "force_amplitude_n" in keywords:  # harmonic balance takes it by the same rule
        with pytest.raises(ParameterError, match="^force_amplitude_n: expected a number"):
            harmonic_response(model, mode, frequencies_hz=[300.0], force_amplitude_n="2")


def test_time_domain_response_refuses_what_harmonic_balance_refuses(model, mode):
    # 2000 Hz ran on the 1000 Hz SDC and 1000 N settled at ~820 g on the 10 g SDC, both
    # returned as if the model held a damper there; 0 Hz was a ZeroDivisionError
    with pytest.raises(ParameterError, match=r"^time_domain_response: frequency 2000 Hz "
                                             r"outside the SDC model range \[50, 1000\] Hz"):
        time_domain_response(model, mode, frequency_hz=2000.0, force_amplitude_n=FORCE_N,
                             settle_cycles=20, measure_cycles=2)
    for bad in (0.0, -5.0, "300"):
        with pytest.raises(ParameterError, match=r"^frequency_hz: expected a"):
            time_domain_response(model, mode, frequency_hz=bad, force_amplitude_n=FORCE_N)
    with pytest.raises(ParameterError, match=r"^time_domain_response: at 300 Hz the steady "
                                             r"acceleration 8\d\d g is outside the SDC model "
                                             r"range \[1, 10\] g"):
        time_domain_response(model, mode, frequency_hz=300.0, force_amplitude_n=1000.0,
                             settle_cycles=300, measure_cycles=2)
    held = time_domain_response(model, mode, frequency_hz=300.0, force_amplitude_n=1000.0,
                                settle_cycles=300, measure_cycles=2, clip_to_range=True)
    assert held.clipped
    # at the edge the damper is linear: the steady amplitude is the closed-form one with the
    # 10 g SDC (300 settle cycles are 1 s, 19 decay time constants of the structural damping
    # alone: e^-19 of the start transient is left; 1e-6 allows for the integrator's rtol)
    w = 2 * np.pi * 300.0
    c = mode.structural_damping_n_s_m + equivalent_damping_coefficient(
        float(model(50.0, 10.0, 300.0)), vibrated_mass_kg=mode.coupon_vibrated_mass_kg,
        frequency_hz=300.0) / 0.01 * 0.2
    expected = 1000.0 / abs(mode.stiffness_n_m - mode.modal_mass_kg * w**2 + 1j * w * c)
    assert held.amplitude_m == pytest.approx(expected, rel=1e-6)
    inside = time_domain_response(model, mode, frequency_hz=300.0, force_amplitude_n=FORCE_N,
                                  settle_cycles=20, measure_cycles=2)
    assert not inside.clipped


def test_a_coupon_area_in_cm2_is_refused(mode):
    # coupon_area_m2=100 (the paper coupon's 0.01 m^2 typed in cm^2) gave a c_pd 1e4 x too
    # small without a word: only the CLI's --area was checked
    import dataclasses

    with pytest.raises(ParameterError) as caught:
        dataclasses.replace(mode, coupon_area_m2=100.0)
    message = str(caught.value)
    assert message.startswith("TreatedMode: coupon_area_m2 100 m^2 is ")
    assert "paper_coupon's 441 cells" in message and "was it cm^2 or mm^2?" in message
    with pytest.raises(ParameterError, match=r"coupon_area_m2 1e-05 m\^2 .* one cell's area"):
        dataclasses.replace(mode, coupon_area_m2=1e-5)
    # a specimen of 4 cells (its mass scaled with them) has a coupon of 7.8e-5 m^2: checked
    # against its own cells, that area passes
    import re

    from pidcore.specimen import Specimen, paper_specimen

    text = re.sub(r"(?m)^count = 441$", "count = 4", paper_specimen().text)
    text = re.sub(r"(?m)^mass_kg = .*$", "mass_kg = 0.0002", text)
    four_cells = Specimen.from_text(text, source="four cells")
    assert dataclasses.replace(mode, coupon_area_m2=5e-5,
                               coupon_specimen=four_cells).coupon_area_m2 == 5e-5
    with pytest.raises(ParameterError, match="specimen paper_coupon's 441 cells"):
        dataclasses.replace(mode, coupon_area_m2=5e-5)  # the same area, the paper's coupon


@pytest.mark.parametrize("slope_per_g,said", [
    (+0.01, "overstates the damping there (amplitude understated: not conservative)"),
    (-0.01, "understates the damping there (amplitude overstated: conservative)"),
    (0.0, "errs in a direction the model does not tell"),
])
def test_a_held_edge_sdc_says_which_way_it_errs_by_the_models_slope(mode, slope_per_g, said):
    # clip_to_range=True held the 1 g SDC for a 0.004 g response and flagged the row, but
    # not that where the SDC rises from 1 g the held value overstates the damping below it.
    # SDC linear in acceleration: pchip reproduces it, so its continuation below 1 g is the
    # truth the held value is measured against, and the slope at the edge is slope_per_g.
    grid = pd.MultiIndex.from_product([[25.0, 90.0], [1.0, 5.0, 10.0], [50.0, 1000.0]],
                                      names=["fill_percent", "acceleration_g", "frequency_hz"])
    table = grid.to_frame(index=False)
    table["sdc"] = 0.2 + slope_per_g * (table["acceleration_g"] - 1.0)
    linear = SdcModel.from_table(table, value="sdc", source="linear in acceleration")
    r = harmonic_response(linear, mode, frequencies_hz=[200.0, 220.0], force_amplitude_n=0.1,
                          clip_to_range=True)
    assert r.clipped.all() and (r.acceleration_g < 1.0).all()
    truth = 0.2 + slope_per_g * (r.acceleration_g - 1.0)
    held_minus_truth = np.sign(r.sdc - truth)
    assert set(held_minus_truth) == {np.sign(slope_per_g)}  # the direction the note must say
    note = r.to_pandas().attrs["clipped_note"]
    assert note == r.clipped_note and "\n" not in note
    assert note.startswith("200 .. 220 Hz (2 row(s)): response ")
    assert "below the model's 1 g edge" in note and said in note
    assert f"model slope there {slope_per_g:+.3g} per g" in note
    # the time integration says the same of its steady state
    td = time_domain_response(linear, mode, frequency_hz=200.0, force_amplitude_n=0.1,
                              clip_to_range=True)
    assert td.clipped and said in td.clipped_note
    # nothing held, nothing said
    inside = harmonic_response(linear, mode, frequencies_hz=[300.0], force_amplitude_n=3.0)
    assert not inside.clipped.any() and inside.clipped_note == ""


def test_the_paper_models_held_1g_sdc_overstates_the_damping_below_it(model, mode):
    # Table 3 at 50 % fill and 200 Hz: the SDC rises from 1 g to 5 g, so its slope at 1 g
    # (the model's own) is positive, and holding it below 1 g overstates the damping
    slope = float(model.acceleration_section(50.0, 200.0).derivative()(1.0))
    assert slope > 0
    r = harmonic_response(model, mode, frequencies_hz=[200.0], force_amplitude_n=0.1,
                          clip_to_range=True)
    assert "holding the 1 g SDC overstates the damping there" in r.clipped_note
    assert f"model slope there {slope:+.3g} per g" in r.clipped_note


@pytest.mark.parametrize("slope_per_hz,said", [
    (+4e-4, "rises with frequency: holding it understates the damping there (amplitude "
            "overstated: conservative)"),
    (-4e-4, "falls with frequency: holding it overstates the damping there (amplitude "
            "understated: not conservative)"),
    (0.0, "flat in frequency: holding it errs in a direction the model does not tell"),
])
def test_a_frequency_held_at_the_edge_says_which_way_it_errs(mode, slope_per_hz, said):
    # a 300 Hz row beyond a 250 Hz model said "which way that errs is not assessed". SDC
    # linear in frequency: pchip reproduces it, so its continuation beyond 250 Hz is the
    # truth the held value is measured against.
    grid = pd.MultiIndex.from_product([[25.0, 90.0], [1.0, 5.0, 10.0], [50.0, 150.0, 250.0]],
                                      names=["fill_percent", "acceleration_g", "frequency_hz"])
    table = grid.to_frame(index=False)
    table["sdc"] = 0.2 + slope_per_hz * (table["frequency_hz"] - 250.0)
    linear = SdcModel.from_table(table, value="sdc", source="linear in frequency")
    r = harmonic_response(linear, mode, frequencies_hz=[280.0, 300.0], force_amplitude_n=10.0,
                          clip_to_range=True)
    assert r.clipped.all() and ((r.acceleration_g >= 1) & (r.acceleration_g <= 10)).all()
    truth = 0.2 + slope_per_hz * (r.frequency_hz - 250.0)
    # the way the note says it errs: held minus truth, positive where it "overstates"
    assert set(np.sign(r.sdc - truth)) == {np.sign(slope_per_hz) * -1 or 0.0}
    assert "frequency outside the model's [50, 250] Hz, the 250 Hz SDC held (model slope " \
           f"there {slope_per_hz:+.3g} per Hz)" in r.clipped_note
    assert said in r.clipped_note and "not assessed" not in r.clipped_note
    td = time_domain_response(linear, mode, frequency_hz=300.0, force_amplitude_n=10.0,
                              clip_to_range=True)
    assert td.clipped and said in td.clipped_note


def _constant_sdc_model(sdc: float) -> SdcModel:
    grid = pd.MultiIndex.from_product([[25.0, 90.0], [1.0, 10.0], [50.0, 1000.0]],
                                      names=["fill_percent", "acceleration_g", "frequency_hz"])
    table = grid.to_frame(index=False)
    table["sdc"] = sdc
    return SdcModel.from_table(table, value="sdc", source="constant")


def test_treated_regions_weight_the_damper_by_the_mode_shape_squared_exactly_as_a_2dof():
    # harmonic_response put the whole treated area on the modal coordinate (no sum of
    # c_i phi_i^2). Truth: a physical 2-DOF (two treated patches, masses proportional to
    # their areas) solved directly, (K - w^2 M + j w C) x = F. With an SDC constant in
    # acceleration each patch's damper is c_per_area x its area, so C is proportional to M:
    # the modes stay uncoupled and a force shaped M phi excites mode 1 alone, making the
    # single-mode answer exact (textbook proportional damping).
    sdc, m_c, a_c = 0.3, 0.1, 0.01
    model = _constant_sdc_model(sdc)
    areas = np.array([0.05, 0.15])
    masses = 40.0 * areas  # kg: 40 kg/m^2 panel
    K = np.array([[6e5 + 3e5, -3e5], [-3e5, 3e5 + 9e5]])
    M = np.diag(masses)
    eigenvalues, vectors = np.linalg.eig(np.linalg.solve(M, K))
    first = int(np.argmin(eigenvalues))
    phi = vectors[:, first] / vectors[0, first] * 0.7  # any scaling: the mode's own is used
    modal_mass = float(phi @ M @ phi)
    f_n = float(np.sqrt(eigenvalues[first]) / (2 * np.pi))
    mode = TreatedMode(natural_frequency_hz=f_n, modal_mass_kg=modal_mass,
                       structural_damping_ratio=0.0, treated_area_m2=float(areas.sum()),
                       fill_percent=50.0, coupon_vibrated_mass_kg=m_c,
                       treated_regions=tuple(zip(areas, phi, strict=True)))
    scale = 3.0
    force = M @ phi * scale
    f = np.array([0.9, 0.99, 1.0, 1.1]) * f_n  # at f_n only the particles damp it
    r = harmonic_response(model, mode, frequencies_hz=f, force_amplitude_n=float(phi @ force),
                          clip_to_range=True)  # constant SDC: the held edge value is exact
    for fi, q in zip(f, r.amplitude_m, strict=True):
        w = 2 * np.pi * fi
        C = np.diag(sdc * m_c * fi / a_c * areas)  # c_eq per area x area, by hand
        x = np.linalg.solve(K - w**2 * M + 1j * w * C, force)
        # one linear solve against one scalar harmonic balance: round-off only
        np.testing.assert_allclose(np.abs(x), np.abs(phi) * q, rtol=1e-9)
    # the modal damper is sum c_i phi_i^2, so its ratio is that over 2 w m
    c_modal = sdc * m_c * f[1] / a_c * float(np.sum(areas * phi**2))
    assert r.particle_damping_n_s_m[1] == pytest.approx(c_modal, rel=1e-12)
    # the whole treated area at amplitude 1 (the old assumption) is another damper here
    uniform = harmonic_response(model, dataclasses.replace(mode, treated_regions=()),
                                frequencies_hz=f, force_amplitude_n=float(phi @ force),
                                clip_to_range=True)
    c_uniform = sdc * m_c * f[1] / a_c * float(areas.sum())
    assert uniform.particle_damping_n_s_m[1] == pytest.approx(c_uniform, rel=1e-12)
    assert abs(c_uniform / c_modal - 1) > 0.2  # 27 %: far beyond the 2-DOF check's 1e-9
    assert "2 treated region(s)" in r.mode_shape_note
    assert "whole treated area (0.2 m^2) moves with the modal coordinate" in \
        uniform.to_pandas().attrs["mode_shape_note"]


def test_treated_regions_do_not_depend_on_the_mode_shapes_scaling(model):
    # phi x s with the modal mass x s^2 and the modal force x s is the same physical mode:
    # each region's physical amplitude |phi_i| X (and so its SDC) must not change
    base = dict(natural_frequency_hz=300.0, structural_damping_ratio=0.01,
                treated_area_m2=0.2, fill_percent=50.0,
                coupon_vibrated_mass_kg=coupon_vibrated_mass_kg(
                    particles_mass_kg=paper_particles_mass_kg(50)))
    regions = ((0.05, 1.0), (0.1, 0.6), (0.05, -0.8))
    f = np.array([280.0, 300.0, 320.0])
    one = harmonic_response(model, TreatedMode(modal_mass_kg=2.0, treated_regions=regions,
                                               **base), frequencies_hz=f, force_amplitude_n=8.0)
    s = 2.5
    scaled = TreatedMode(modal_mass_kg=2.0 * s**2, **base,
                         treated_regions=tuple((a, p * s) for a, p in regions))
    two = harmonic_response(model, scaled, frequencies_hz=f, force_amplitude_n=8.0 * s)
    # the same residual solved to brentq's 1e-13: agreement to 1e-10
    np.testing.assert_allclose(two.amplitude_m * s, one.amplitude_m, rtol=1e-10)
    np.testing.assert_allclose(two.acceleration_g, one.acceleration_g, rtol=1e-10)
    np.testing.assert_allclose(two.particle_damping_n_s_m / s**2, one.particle_damping_n_s_m,
                               rtol=1e-10)
    # the time integration of the same regions settles on the harmonic balance's amplitude
    td = time_domain_response(model, TreatedMode(modal_mass_kg=2.0, treated_regions=regions,
                                                 **base),
                              frequency_hz=300.0, force_amplitude_n=8.0)
    assert td.amplitude_m == pytest.approx(one.amplitude_m[1], rel=1e-4)  # settle residue


@pytest.mark.parametrize("regions,message", [
    (((0.1, 1.0), (0.05, 0.5)), r"treated_regions' areas sum to 0.15 m\^2, but "
                                r"treated_area_m2 is 0.2 m\^2"),
    (((0.25, 1.0), (-0.05, 0.5)), r"treated_regions\[1\] area_m2 must be finite and > 0"),
    (((0.1, 0.0), (0.1, 0.0)), "every mode_shape_amplitude is 0"),
    (((0.1, float("nan")), (0.1, 1.0)), r"treated_regions\[0\] mode_shape_amplitude must be "
                                        "finite"),
    ((0.1, 0.1), "expected \\(area_m2, mode_shape_amplitude\\) pairs"),
])
def test_treated_regions_that_do_not_split_the_treated_area_are_refused(mode, regions,
                                                                        message):
    with pytest.raises(ParameterError, match=message):
        dataclasses.replace(mode, treated_regions=regions)


def test_a_mode_without_structural_damping_at_its_natural_frequency_is_bounded_by_the_particles(
        model):
    # structural_damping_ratio=0 driven at f_n: the untreated bound F0/0 made the scan run on
    # NaN and the solver refused with "response acceleration nan g"; the particles alone
    # bound it. At resonance k = m w^2, so the balance is X w c_pd(X) = F0 by hand.
    mc = coupon_vibrated_mass_kg(particles_mass_kg=paper_particles_mass_kg(50))
    mode = TreatedMode(natural_frequency_hz=300.0, modal_mass_kg=2.0,
                       structural_damping_ratio=0.0, treated_area_m2=0.2, fill_percent=50.0,
                       coupon_vibrated_mass_kg=mc)
    r = harmonic_response(model, mode, frequencies_hz=[300.0], force_amplitude_n=5.0)
    x, w = r.amplitude_m[0], 2 * np.pi * 300.0
    assert np.isfinite(x) and 1.0 <= r.acceleration_g[0] <= 10.0
    sdc = float(model(50.0, w**2 * x / STANDARD_GRAVITY, 300.0))
    c_by_hand = sdc * mc * 300.0 / 0.01 * 0.2  # SDC m_c f / A_c x A_t
    assert x * w * c_by_hand == pytest.approx(5.0, rel=1e-10)  # brentq's 1e-13 on log X
    assert r.amplitude_untreated_m[0] == np.inf  # undamped at resonance: unbounded
    assert r.phase_rad[0] == pytest.approx(-np.pi / 2, abs=1e-12)
    # where the model's SDC also reaches 0 nothing bounds it: refused, naming why
    zero = _constant_sdc_model(0.0)
    with pytest.raises(ParameterError, match=r"^harmonic_response: at 300 Hz \(the natural "
                                             r"frequency\) nothing bounds the response"):
        harmonic_response(zero, mode, frequencies_hz=[300.0], force_amplitude_n=5.0)


def test_a_fill_outside_the_model_or_beyond_100_percent_is_refused_by_name(model, mode):
    # fill_percent=150 was taken; a 95 % fill was then refused as "fill_percent=95 %,
    # frequency_hz=300 Hz outside the model range {...}", clip_to_range or not
    with pytest.raises(ParameterError, match=r"^TreatedMode: fill_percent must be in \(0, 100\] "
                                             r"%, got 150"):
        dataclasses.replace(mode, fill_percent=150.0)
    beyond = dataclasses.replace(mode, fill_percent=95.0)
    for clip in (False, True):
        with pytest.raises(ParameterError) as caught:
            harmonic_response(model, beyond, frequencies_hz=[300.0], force_amplitude_n=5.0,
                              clip_to_range=clip)
        assert str(caught.value).startswith(
            "harmonic_response: fill_percent 95 % outside the SDC model range [25, 90] %;")
    with pytest.raises(ParameterError, match=r"^time_domain_response: fill_percent 95 %"):
        time_domain_response(model, beyond, frequency_hz=300.0, force_amplitude_n=5.0)


@pytest.mark.parametrize(("typed", "said"), [
    (98.8, r"^TreatedMode: coupon_vibrated_mass_kg 98.8 kg is 1000 x the paper coupon's "
           r"vibrated masses \(0.0222 .. 0.0988 kg over every convention at 50 % fill, "
           r"acrylic particles\); expected m_c in kg; was it grams\?$"),
    (9.88e-5, r"^TreatedMode: coupon_vibrated_mass_kg 9.88e-05 kg is 0.00446 x .*was it in "
              r"another unit\?$"),
])
def test_a_coupon_vibrated_mass_in_grams_is_refused_by_the_damper_tables_rule(model, mode, typed,
                                                                              said):
    # coupon_vibrated_mass_kg=98.8 (the 50 % m_c, 0.0988 kg, typed in g) gave a c_pd 1000 x
    # too large (27108 N s/m, not 27) without a word, or a refusal blaming the force, while
    # equivalent_damper_table and `pidcore model damper --vibrated-mass` refused that m_c
    with pytest.raises(ParameterError, match=said):
        dataclasses.replace(mode, coupon_vibrated_mass_kg=typed)


def test_treated_mode_and_the_damper_table_take_the_same_vibrated_masses(model, mode):
    # one rule: just inside and just outside each bound of VIBRATED_MASS_LIMIT x the paper
    # coupon's m_c at the mode's fill, both take or both refuse (1e-6: far from round-off,
    # far inside the limit's 100 x)
    from pidcore.constants import VIBRATED_MASS_CONVENTIONS
    from pidcore.model import equivalent_damper_table, paper_vibrated_mass
    from pidcore.model.damper import VIBRATED_MASS_LIMIT

    masses = [paper_vibrated_mass(c)(50.0) for c in VIBRATED_MASS_CONVENTIONS]
    low, high = min(masses) / VIBRATED_MASS_LIMIT, max(masses) * VIBRATED_MASS_LIMIT
    for typed, taken in ((low * (1 + 1e-6), True), (low * (1 - 1e-6), False),
                         (high * (1 - 1e-6), True), (high * (1 + 1e-6), False)):
        def table(m=typed):
            return equivalent_damper_table(model, fills_percent=[50], accelerations_g=[5],
                                           frequencies_hz=[300], vibrated_mass_kg=m)

        def treated(m=typed):
            return dataclasses.replace(mode, coupon_vibrated_mass_kg=m)

        for make in (table, treated):
            if taken:
                make()
            else:
                with pytest.raises(ParameterError, match="x the paper coupon's vibrated"):
                    make()
    # the mass taken is the one used: c_pd = SDC m_c w / (2 pi) x A_t / A_c, one product
    r = harmonic_response(model, mode, frequencies_hz=[300.0], force_amplitude_n=FORCE_N)
    expected = float(r.sdc[0]) * mode.coupon_vibrated_mass_kg * 300.0 * 0.2 / 0.01
    assert r.particle_damping_n_s_m[0] == pytest.approx(expected, rel=1e-12)


def test_a_response_resting_on_the_held_hole_says_so(model):
    # a 1000 Hz mode at 90 % fill answered 1.24 g with SDC 0.8207, a value resting on the
    # 1000 Hz, 1 g, 90 % hole held at the 75 % value, and said nothing of it
    mode = TreatedMode(natural_frequency_hz=1000.0, modal_mass_kg=1.0,
                       structural_damping_ratio=0.01, treated_area_m2=0.05, fill_percent=90,
                       coupon_vibrated_mass_kg=coupon_vibrated_mass_kg(
                           particles_mass_kg=paper_particles_mass_kg(90)))
    r = harmonic_response(model, mode, frequencies_hz=np.array([990.0, 1000.0]),
                          force_amplitude_n=1.5)
    assert r.sdc_filled.tolist() == [True, True]
    frame = r.to_pandas()
    assert frame["sdc filled [True/False]"].tolist() == [True, True]
    assert frame.attrs["filled_note"] == r.filled_note
    assert r.filled_note.startswith("990 .. 1000 Hz (2 row(s)): 2 SDC(s) taken rest on the "
                                    "filled grid value at 1000 Hz, 1 g, 90 %")
    # the note's slope is the model's at the acceleration found
    dependence = model.filled_dependence(90.0, r.acceleration_g, r.frequency_hz)
    assert f"{dependence.slope_rising.min():+.3g}" in r.filled_note
    td = time_domain_response(model, mode, frequency_hz=1000.0, force_amplitude_n=1.5)
    assert td.sdc_filled and "1000 Hz, 1 g, 90 %" in td.filled_note


def test_a_response_far_from_the_hole_is_not_flagged(model, mode):
    r = harmonic_response(model, mode, frequencies_hz=np.array([280.0, 300.0, 320.0]),
                          force_amplitude_n=FORCE_N)
    assert not r.sdc_filled.any() and r.filled_note == ""


#: An own specimen unlike the paper's coupon: 7150 cells of 6.35 mm, a 12.7 mm core, 2 mm
#: tungsten carbide spheres (46 fit a cell, as `pidcore specimen check` prints), 0.9 kg coupon.
WC_PANEL = """schema_version = 1
name = "wc_panel"
[cell]
shape = "hexagonal"
inscribed_diameter_m = 6.35e-3
height_m = 12.7e-3
count = 7150
wall_material = "aluminium_wall"
[coupon]
mass_kg = 0.9
[particles]
material = "tungsten_carbide"
radius_m = 1.0e-3
density_kg_m3 = 15600.0
youngs_modulus_pa = 600e9
poisson_ratio = 0.22
[pairs.particle_particle]
restitution = 0.8
sliding_friction = 0.3
[pairs.particle_wall]
restitution = 0.8
sliding_friction = 0.3
"""


def test_an_own_specimens_vibrated_mass_is_checked_against_its_own_masses(model, mode):
    # 0.9 kg + 7150 x 23 x 65.35 mg = 11.646 kg, the right m_c of that panel at 50 % fill,
    # was refused as "118 x the paper coupon's vibrated masses ... was it grams?"
    from pidcore.model import equivalent_damper_table
    from pidcore.model.damper import VIBRATED_MASS_LIMIT
    from pidcore.specimen import Specimen

    panel = Specimen.from_text(WC_PANEL, source="wc_panel.toml")
    sphere = 15600.0 * 4.0 / 3.0 * np.pi * 1e-3**3
    m_c = 0.9 + 7150 * 23 * sphere
    assert m_c == pytest.approx(11.646, abs=5e-4)
    own = dataclasses.replace(mode, coupon_vibrated_mass_kg=m_c, coupon_specimen=panel,
                              coupon_area_m2=None)
    assert own.coupon_vibrated_mass_kg == m_c
    table = equivalent_damper_table(model, fills_percent=[50], accelerations_g=[5],
                                    frequencies_hz=[300], vibrated_mass_kg=m_c, specimen=panel)
    assert table["coupon_vibrated_mass [kg]"].iloc[0] == m_c
    # the range is the panel's: one sphere in each cell alone (0.467 kg, the particles
    # convention's least; lighter than its empty 0.9 kg coupon) to its cells full, 46 spheres
    # each; each bound with the paper's 100 x margin, 1e-6 either side (far from round-off)
    low, high = min(0.9, 7150 * sphere), 0.9 + 7150 * 46 * sphere
    for typed, taken in ((low / VIBRATED_MASS_LIMIT * (1 + 1e-6), True),
                         (low / VIBRATED_MASS_LIMIT * (1 - 1e-6), False),
                         (high * VIBRATED_MASS_LIMIT * (1 - 1e-6), True),
                         (high * VIBRATED_MASS_LIMIT * (1 + 1e-6), False)):
        for make in (lambda m=typed: dataclasses.replace(own, coupon_vibrated_mass_kg=m),
                     lambda m=typed: equivalent_damper_table(
                         model, fills_percent=[50], accelerations_g=[5], frequencies_hz=[300],
                         vibrated_mass_kg=m, specimen=panel)):
            if taken:
                make()
            else:
                with pytest.raises(ParameterError, match="x specimen wc_panel's vibrated"):
                    make()
    # the same mass typed in grams is still a unit slip, named against the panel's masses
    with pytest.raises(ParameterError) as caught:
        dataclasses.replace(own, coupon_vibrated_mass_kg=11646.0)
    assert str(caught.value).startswith(
        f"TreatedMode: coupon_vibrated_mass_kg 11646 kg is {11646.0 / high:.3g} x ")
    assert (f"x specimen wc_panel's vibrated masses ({low:.3g} .. {high:.3g} kg from one "
            "particle per cell to its 7150 cells full, 46 tungsten_carbide particles each"
            in str(caught.value))
    assert str(caught.value).endswith("was it grams?")


@pytest.mark.parametrize("typed", [2.0, 1.0])
def test_a_structural_damping_ratio_of_critical_or_more_is_refused_as_a_percentage(mode, typed):
    # structural_damping_ratio=2.0 ("2 %" typed for 0.02) was taken: an over-critical mode
    # that does not resonate, damped 100 x too much
    with pytest.raises(ParameterError) as caught:
        dataclasses.replace(mode, structural_damping_ratio=typed)
    assert str(caught.value) == (
        f"TreatedMode: structural_damping_ratio {typed:g} is critical damping or more (no "
        f"resonant mode); expected a fraction of critical, e.g. {typed / 100:g} for {typed:g} %")
    assert dataclasses.replace(mode, structural_damping_ratio=0.999).structural_damping_ratio \
        == 0.999


def test_a_treated_area_whose_particles_outweigh_the_mode_100_times_is_refused(mode):
    # treated_area_m2=500 (0.05 m^2 typed in cm^2) gave a c_pd 1e4 x too high: 3830 kg of the
    # paper coupon's particles (441 x 18 acrylic spheres per 0.01 m^2 at 50 % fill) on a
    # 2 kg mode
    from pidcore.model.response import PARTICLE_TO_MODAL_MASS_LIMIT

    sphere = 1180.0 * 4.0 / 3.0 * np.pi * 1.25e-3**3
    areal = 441 * 18 * sphere / 0.01
    with pytest.raises(ParameterError) as caught:
        dataclasses.replace(mode, treated_area_m2=500.0)
    message = str(caught.value)
    assert message.startswith(
        f"TreatedMode: treated_area_m2 500 m^2 carries {500 * areal:.3g} kg of particles at "
        f"50 % fill ({areal:.3g} kg/m^2: the coupon's 0.0766 kg over its 0.01 m^2), "
        f"{500 * areal / 2:.3g} x the modal mass 2 kg")
    assert message.endswith("(was it cm^2?) and the modal mass in kg")
    # the bound: the particles' modal mass, areal mass x sum A_i phi_i^2, at 100 x the modal
    # mass; 1e-6 either side (far from round-off), one region at amplitude 1 and two at 1
    # and 0.5 (sum A phi^2 = A (1 + 0.25) / 2)
    edge = PARTICLE_TO_MODAL_MASS_LIMIT * 2.0 / areal
    for area, regions in ((edge, ()), (edge / 0.625, "halves")):
        for factor, taken in ((1 - 1e-6, True), (1 + 1e-6, False)):
            a = area * factor
            kw = dict(treated_area_m2=a, treated_regions=((a / 2, 1.0), (a / 2, 0.5))
                      if regions else ())
            if taken:
                dataclasses.replace(mode, **kw)
            else:
                with pytest.raises(ParameterError, match="kg of particles"):
                    dataclasses.replace(mode, **kw)
