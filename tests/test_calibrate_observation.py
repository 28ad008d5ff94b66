"""Observation model of the calibration: the DEM's virtual shaker analysed like a measurement."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pidcore.calibrate.observation import observation_from_run
from pidcore.calibrate.runner import RunRequest, simulate_request
from pidcore.dem.persist import dem_run_entry
from pidcore.dem.simulate import DemConfig, LoadCase
from pidcore.signal import analyze_power
from pidcore.specimen import paper_specimen

F_HZ = 200.0
FS_HZ = F_HZ * 128
CYCLES = 40


def _synthetic(mass_kg: float, damping_n_s_m: float):
    """Record, arrays of a 'bed' that is a mass plus a viscous damper on the cell."""
    t = np.arange(CYCLES * 128) / FS_HZ
    w = 2 * math.pi * F_HZ
    a_amp = 5 * 9.80665
    velocity = -a_amp / w * np.cos(w * t)
    accel = a_amp * np.sin(w * t)
    force = mass_kg * accel + damping_n_s_m * velocity
    energy = math.pi * damping_n_s_m * (a_amp / w) ** 2  # per cycle of a viscous damper
    record = {"frequency_hz": F_HZ, "acceleration_g": 5.0, "fill_percent": 50.0,
              "sample_rate_hz": FS_HZ, "steady_start_cycle": 0, "coupon_mass_kg": 0.0222,
              "max_kinetic_energy_j": 1.0, "energy_per_cycle_j": energy}
    arrays = {"wall_force_n": force, "velocity_m_s": velocity,
              "sdc_per_cell": np.full(4, energy)}  # x E_max = 1 J: per-cell energy
    return record, arrays, t, velocity, accel


def test_masses_of_a_mass_damper_bed_are_exact():
    # P = 1/2 (c + i w m) |V|^2, so d = c / w and m_p = m exactly (sampled sine, whole periods)
    m, c = 0.0153, 2.7
    record, arrays, *_ = _synthetic(m, c)
    obs = observation_from_run(record, arrays)
    w = 2 * math.pi * F_HZ
    assert obs.dissipative_mass_kg == pytest.approx(c / w, rel=1e-9)
    assert obs.reactive_mass_kg == pytest.approx(m, rel=1e-9)
    assert obs.dissipative_mass_stderr_kg == pytest.approx(0.0, abs=1e-12)


def test_a_bed_pulling_against_the_walls_is_observed_not_refused():
    # A bed moving against the cell (reactive part < 0, e.g. near its column resonance) is
    # no inverted sensor: the calibration adds the coupon's and fixture's inertia itself.
    # It was refused as "probably inverted" and stopped the README's calibration (500 Hz,
    # 10 g, 4 cells). Analytic truth: m_p = -m exactly, and the whole shaker force is
    # mass-like again, so Eq. 11 of it must equal the observation's SDC.
    m, c, fixture, eta0 = -0.0153, 2.7, 0.08, 0.012
    record, arrays, t, velocity, accel = _synthetic(m, c)
    obs = observation_from_run(record, arrays)
    assert obs.reactive_mass_kg == pytest.approx(m, rel=1e-9)
    m_s = record["coupon_mass_kg"] + fixture
    total = arrays["wall_force_n"] + m_s * accel + eta0 * 2 * math.pi * F_HZ * m_s * velocity
    measured = analyze_power(total, velocity, FS_HZ, frequency_hz=F_HZ).sdc
    assert obs.sdc(fixture, eta0) == pytest.approx(measured, rel=1e-7)
    # a measurement of such a force alone is still refused (an inverted channel)
    with pytest.raises(Exception, match="probably inverted"):
        analyze_power(arrays["wall_force_n"], velocity, FS_HZ, frequency_hz=F_HZ)


def test_a_run_giving_back_energy_over_its_window_is_named_in_the_calibrations_notes():
    # a run that never reached steady state can show Re P < 0 over its window (the bed gave
    # back stored energy); the surrogate takes its damping as 0 within its error, which was
    # silent. A damper of negative c is such a window: d = c / w exactly, < 0
    from pidcore.calibrate.calibrate import nonpositive_dissipation_notes

    w = 2 * math.pi * F_HZ
    giving = observation_from_run(*_synthetic(0.0153, -0.5)[:2])
    taking = observation_from_run(*_synthetic(0.0153, 2.7)[:2])
    assert giving.dissipative_mass_kg == pytest.approx(-0.5 / w, rel=1e-9)
    (note,) = nonpositive_dissipation_notes(["100 Hz, 5 g, 50 %", "200 Hz, 5 g, 50 %"],
                                            [[taking, giving], [taking]])
    assert note.startswith("100 Hz, 5 g, 50 %: 1 of 2 DEM run(s) dissipate nothing over their "
                           f"window (Re P <= 0, dissipative mass {-0.5 / w:.3g} +- ")
    assert nonpositive_dissipation_notes(["a"], [[taking]]) == []


def test_fixture_mass_and_baseline_equal_eq11_of_the_whole_shaker_force():
    # a structure of mass m_s with loss factor eta_0 is a mass plus a damper eta_0 w m_s; the
    # observation model must give what Eq. 11 (analyze_power) gives for the total gauge force
    m, c, fixture, eta0 = 0.0153, 2.7, 0.08, 0.012
    record, arrays, t, velocity, accel = _synthetic(m, c)
    obs = observation_from_run(record, arrays)
    w = 2 * math.pi * F_HZ
    m_s = record["coupon_mass_kg"] + fixture
    total = arrays["wall_force_n"] + m_s * accel + eta0 * w * m_s * velocity
    measured = analyze_power(total, velocity, FS_HZ, frequency_hz=F_HZ).sdc
    assert obs.sdc(fixture, eta0) == pytest.approx(measured, rel=1e-7)


def test_the_coupon_is_read_without_its_fixture_from_old_and_new_records():
    # coupon_mass_kg holds the coupon alone since moving_mass_kg exists; before, it held coupon
    # + fixture: the same run must give the same observation from either store
    record, arrays, *_ = _synthetic(0.0153, 2.7)
    new = {**record, "fixture_mass_kg": 0.05, "moving_mass_kg": 0.0722}
    old = {**record, "fixture_mass_kg": 0.05, "coupon_mass_kg": 0.0722}
    assert observation_from_run(new, arrays).coupon_mass_kg == pytest.approx(0.0222, rel=1e-12)
    assert observation_from_run(old, arrays).coupon_mass_kg == pytest.approx(0.0222, rel=1e-12)
    # an old record of the paper's coupon (no fixture key): its coupon_mass_kg as stored
    assert observation_from_run(record, arrays).coupon_mass_kg == 0.0222


@pytest.fixture(scope="module")
def flying_run():
    case = LoadCase(500.0, 5.0, 50.0)
    config = DemConfig(cells=2, steady_cycles=20, block_cycles=5, max_transient_cycles=10)
    return simulate_request(RunRequest(case, paper_specimen(), config))


def test_dem_observation_is_eq11_of_the_virtual_shaker(flying_run):
    # without fixture and baseline the prediction is Eq. 11 of the DEM's own shaker record,
    # analysed without blocks as the observation is: one DC and trend over the record (a
    # measurement's blocks bring the drift spline, 0.2 % off here on 20 cycles; a DEM record
    # has no wander, and the bundled calibration stays as it was)
    entry = dem_run_entry(flying_run)
    obs = observation_from_run(entry["record"], entry["arrays"])
    sl = flying_run.steady_slice()
    eq11 = analyze_power(flying_run.shaker_force_n[sl], flying_run.velocity_m_s[sl],
                         flying_run.sample_rate_hz, frequency_hz=500.0, n_harmonics=1,
                         n_blocks=0).sdc
    assert obs.sdc() == pytest.approx(eq11, rel=1e-6)
    # power closure: Re(P) x T is the dissipation tally per cycle (2 % as in test_dem_simulate)
    w = 2 * math.pi * 500.0
    v = 5 * 9.80665 / w
    assert obs.dissipative_mass_kg * 0.5 * w * v**2 / 500.0 == pytest.approx(
        flying_run.energy_per_cycle_j, rel=0.02)
    # a flying bed moves less mass than it weighs: m_p below the particles' mass
    particles = flying_run.vibrated_mass_kg - flying_run.moving_mass_kg
    assert obs.reactive_mass_kg < particles
    assert obs.dissipative_mass_stderr_kg > 0


def test_bound_notes_flag_a_posterior_piled_against_a_prior_bound():
    from pidcore.calibrate.parameters import parameter_spec
    from pidcore.calibrate.posterior import bound_notes

    spec = parameter_spec("fixture_mass_kg")  # prior 0 .. 1 kg
    rng = np.random.default_rng(0)
    flat = rng.uniform(spec.low, spec.high, (4000, 1))  # ~5 % per edge: the prior itself
    inside = rng.normal(0.5, 0.05, (4000, 1))
    assert bound_notes([spec], flat) == [] and bound_notes([spec], inside) == []
    high = spec.high - (spec.high - spec.low) * rng.beta(1, 8, (4000, 1))  # 34 % in the top 5 %
    (note,) = bound_notes([spec], high)
    assert "upper bound 1" in note and "priors=fixture_mass_kg=LOW:HIGH" in note
    (note,) = bound_notes([spec], spec.high - high)
    assert "lower bound 0" in note
    # a log-uniform prior's edges are measured in log: a model error of ~8 % lies in the
    # lowest 5 % of its 0.02-2 range taken linearly (39 % of the prior's mass), not in log
    from pidcore.calibrate.parameters import DISCREPANCY

    tau = parameter_spec(DISCREPANCY)
    assert (tau.prior, tau.low, tau.high) == ("log-uniform", 0.02, 2.0)
    good = np.exp(rng.normal(math.log(0.08), 0.2, (4000, 1)))
    assert bound_notes([tau], good) == []
    low = np.exp(rng.uniform(math.log(0.02), math.log(0.025), (4000, 1)))  # lowest 5 % in log
    assert "lower bound 0.02" in bound_notes([tau], low)[0]


def test_unconstrained_notes_flag_a_parameter_the_data_leave_at_its_prior():
    # a trial calibration (own alumina specimen, flying beds at 2-10 g) returned rolling
    # friction 0.0495 (95 % 0.0024 .. 0.0974) under its 0 .. 0.1 prior, which is the prior
    # itself, and wrote 0.0495 into the calibrated specimen without a word
    from pidcore.calibrate.parameters import DISCREPANCY, parameter_spec
    from pidcore.calibrate.posterior import bound_notes, unconstrained_notes

    rng = np.random.default_rng(3)
    mu_r = parameter_spec("rolling_friction")
    assert (mu_r.low, mu_r.high) == (0.0, 0.1)
    prior_like = rng.uniform(0.0, 0.1, (4000, 1))
    (note,) = unconstrained_notes([mu_r], prior_like)
    assert note.startswith("rolling_friction: the data hardly constrain it")
    assert "0 .. 0.1" in note and "calibrated specimen" in note
    assert bound_notes([mu_r], prior_like) == []  # the bound notes said nothing of it
    # constrained to half its prior's width: data, not prior (the trial's baseline: 0.59)
    assert unconstrained_notes([mu_r], rng.uniform(0.02, 0.07, (4000, 1))) == []
    # a log-uniform prior is judged in log: flat in log over 0.02 .. 2 is the prior, while
    # 0.02 .. 0.2 taken linearly is only 9 % of the range but half of it in log
    tau = parameter_spec(DISCREPANCY)
    flat_log = np.exp(rng.uniform(math.log(0.02), math.log(2.0), (4000, 1)))
    (note,) = unconstrained_notes([tau], flat_log)
    # the discrepancy is no specimen field: the note said it was written to the calibrated
    # specimen and to "not fit it", which --discrepancy TAU does
    assert note.endswith("its median is the prior's more than the data's, no specimen value "
                         "(the calibrated specimen holds none) but it widens every band; fix "
                         "it (discrepancy=TAU) where the model's relative error is known")
    half_log = np.exp(rng.uniform(math.log(0.02), math.log(0.2), (4000, 1)))
    assert unconstrained_notes([tau], half_log) == []
    # a truncated normal prior is compared with its own 95 % interval, not its bounds: the
    # prior N(0.1, 0.02) on 0 .. 1 kg drawn back is unconstrained though it spans 8 % of them
    from dataclasses import replace

    fixture = replace(parameter_spec("fixture_mass_kg"), prior="normal", prior_mean=0.1,
                      prior_sd=0.02)
    drawn = rng.normal(0.1, 0.02, (4000, 1))
    assert len(unconstrained_notes([fixture], drawn)) == 1
    assert unconstrained_notes([fixture], rng.normal(0.1, 0.005, (4000, 1))) == []


def test_bound_notes_spare_a_narrow_posterior_inside_the_prior_edge():
    # a 35 g fixture under the 0-1 kg prior: the data pin it to 20-54 g (95 %), all of it in
    # the prior's lowest 5 %, and the note said the median was "set by the prior, not the
    # data". Piling means the density is highest at the bound (half-normal against it: still
    # noted); a posterior 4 standard deviations clear of the bound is not piled.
    from pidcore.calibrate.parameters import parameter_spec
    from pidcore.calibrate.posterior import bound_notes

    spec = parameter_spec("fixture_mass_kg")
    assert (spec.low, spec.high) == (0.0, 1.0)
    rng = np.random.default_rng(1)
    narrow = rng.normal(0.037, 0.0087, (4000, 1))  # 95 % 0.020 .. 0.054 kg
    assert np.mean(narrow < 0.05) > 0.9  # the old rule's 20 % of the prior's edge, exceeded
    assert bound_notes([spec], narrow) == []
    half_normal = np.abs(rng.normal(0.0, 0.02, (4000, 1)))  # the data ask for <= 0 kg
    (note,) = bound_notes([spec], half_normal)
    assert "lower bound 0" in note


def test_a_bound_note_gives_the_median_as_the_summary_shows_it():
    # the note said 'its median 0.001285' under a summary row of 0.00128: the summary shows
    # each number to the digit its Monte-Carlo standard error leaves, the note to 4 digits
    from pidcore.calibrate.parameters import parameter_spec
    from pidcore.calibrate.posterior import bound_notes, summarise, summary_texts

    spec = parameter_spec("fixture_mass_kg")
    rng = np.random.default_rng(2)
    piled = np.abs(rng.normal(0.0, 0.002, (4000, 1)))  # against 0 kg, median ~1.35 g
    (note,) = bound_notes([spec], piled)
    median, low95, high95 = summary_texts(summarise([spec], piled)[0][spec.name])
    assert f"median {median} is set by where the prior ends" in note
    # the interval beside it, as the summary shows it: a truth inside a broad interval next to
    # the bound (trial H: baseline 0.006 inside 0.00027 .. 0.0283, piled against 0) read as
    # rejected by "the data ask for a value at or beyond it"
    assert f"95 % {low95} .. {high95})" in note
    assert "a value inside the 95 % interval still fits them" in note
    # the premise: the Monte-Carlo error leaves fewer digits than the 4 the note printed
    assert median != f"{float(np.median(piled)):.4g}"


def test_the_calibrated_file_states_what_its_own_values_predict_by_eq_11(tmp_path):
    # the file holds each parameter's marginal median, and the "calibrated DEM" column is the
    # posterior median of the SDC: with correlated parameters they differ (16 % in a tester's
    # fit) and the file's header said nothing of what a DEM re-run of it gives. Fitting only
    # observation parameters leaves one DEM run per case, so the truth is Eq. 11 of that run's
    # masses at the file's fixture mass and baseline loss factor
    from pidcore.calibrate import MeasuredPoint, calibrate
    from pidcore.calibrate.outputs import specimen_text
    from pidcore.calibrate.prediction import sdc_text

    points = [MeasuredPoint(frequency_hz=f, acceleration_g=a, fill_percent=50.0, sdc=sdc)
              for f, a, sdc in ((500.0, 5.0, 0.6), (1000.0, 5.0, 0.6), (500.0, 1.0, 0.2))]
    result = calibrate(points, fit="fixture_mass_kg,baseline_loss_factor",
                       store_path=tmp_path / "dem.h5", cells=2, steady_cycles=10, workers=1,
                       progress=False)
    written = result.calibrated_specimen().coupon
    truth = [float(obs[0].sdc(written.fixture_mass_kg, written.baseline_loss_factor))
             for obs in result.observations]
    # the surrogate of one design run is that run's masses up to its fitted GP mean's
    # rounding (a nugget over a single point): 1e-3 relative, below the 4 digits shown
    np.testing.assert_allclose(result.file_predicted, truth, rtol=1e-3)
    header = specimen_text(result).split("schema_version")[0]
    assert "this file's own values (each parameter's posterior median) predict" in header
    for row, own in zip(result.predictions, result.file_predicted, strict=True):
        assert f"{sdc_text(own)} (posterior median {sdc_text(row['predicted'])}" in header
    assert result.full_document()["calibrated_file_predicted"] == result.file_predicted
