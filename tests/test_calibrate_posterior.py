"""The posterior code against problems whose answer is known, without any DEM run.

A surrogate whose dissipative mass is linear in the DEM parameters, with a fixed reactive mass
and fixture, makes the predicted SDC linear in the DEM parameters and the baseline loss
factor. With Gaussian measurement errors, no model discrepancy and uniform priors the posterior
is a (truncated) multivariate normal: its moments and quantiles are known.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pidcore.calibrate.data import MeasuredPoint
from pidcore.calibrate.parameters import ParameterSpec
from pidcore.calibrate.posterior import Model, sample_posterior

COUPON_KG = 0.02215
REACTIVE_KG = 0.005


class LinearSurrogate:
    """d = c0 + c . theta (kg), m_p constant, no surrogate variance."""

    frequency_hz, acceleration_g, fill_percent = 100.0, 1.0, 50.0
    coupon_mass_kg = COUPON_KG

    def __init__(self, c0: float, c: np.ndarray):
        self.c0, self.c = c0, np.asarray(c, dtype=float)

    def predict(self, theta):
        theta = np.atleast_2d(theta)
        n = theta.shape[0]
        return (self.c0 + theta @ self.c, np.zeros(n), np.full(n, REACTIVE_KG), np.zeros(n))


def linear_problem(truth, sigma, *, seed, n_points=8, bounds=None):
    """(model, analytic mean, analytic covariance, bounds) of the untruncated posterior; the
    last entry of ``truth`` is the baseline loss factor, the others DEM parameters."""
    rng = np.random.default_rng(seed)
    k = len(truth) - 1
    bounds = bounds or [(0.0, 1.0)] * k + [(0.0, 0.2)]
    surrogates = [LinearSurrogate(1e-3 * (1 + i), 2e-3 * rng.uniform(0.3, 1.5, k))
                  for i in range(n_points)]
    specs = [ParameterSpec(f"p{j}", "dem", 0.5, *bounds[j], "x") for j in range(k)]
    specs.append(ParameterSpec("baseline_loss_factor", "observation", 0.0, *bounds[k], "eta"))
    scale = 2 * math.pi / (REACTIVE_KG + COUPON_KG)
    a = np.array([scale * s.c0 for s in surrogates])
    x = np.array([list(scale * s.c) + [scale * COUPON_KG] for s in surrogates])
    y = a + x @ np.asarray(truth) + sigma * rng.standard_normal(n_points)
    points = tuple(MeasuredPoint(100.0, 1.0, 50.0, float(v), sigma) for v in y)
    model = Model(tuple(specs), tuple(surrogates), points,
                  {"fixture_mass_kg": 0.0, "model_discrepancy": 0.0}, 0.0)
    cov = np.linalg.inv(x.T @ x) * sigma**2
    mean = cov @ x.T @ (y - a) / sigma**2
    return model, mean, cov, bounds


def truncated_quantiles(mean, cov, bounds, q, n=400_000):
    """Marginal quantiles of the normal (mean, cov) truncated to the box ``bounds``."""
    draws = np.random.default_rng(0).multivariate_normal(mean, cov, size=n)
    inside = np.all([(draws[:, j] >= lo) & (draws[:, j] <= hi)
                     for j, (lo, hi) in enumerate(bounds)], axis=0)
    return np.percentile(draws[inside], q, axis=0)


@pytest.mark.parametrize("method", ["grid", "emcee"])
def test_a_linear_gaussian_posterior_is_the_analytic_one(method):
    # well inside the bounds: the posterior is the untruncated normal
    model, mean, cov, _ = linear_problem([0.4, 0.02], 0.01, seed=1)
    sd = np.sqrt(np.diag(cov))
    samples = sample_posterior(model, range(8), seed=3, method=method).samples
    n = len(samples)
    # the mean within 4 Monte-Carlo standard errors (emcee's draws are correlated: x3)
    assert np.all(np.abs(samples.mean(axis=0) - mean) < 4 * 3 * sd / math.sqrt(n))
    assert samples.std(axis=0) == pytest.approx(sd, rel=0.06)
    low, high = np.percentile(samples, [2.5, 97.5], axis=0)
    assert np.all(np.abs(low - (mean - 1.959964 * sd)) < 0.15 * sd)
    assert np.all(np.abs(high - (mean + 1.959964 * sd)) < 0.15 * sd)


@pytest.mark.parametrize("method", ["grid", "emcee"])
def test_a_posterior_against_a_prior_bound_puts_no_point_mass_on_it(method):
    # 4 fitted quantities (the grid's coarsest case); two of them near their lower bound 0.
    # The grid's edge nodes used to carry a whole cell's weight, their samples clipped to the
    # bound: 13 % and 17 % of the samples sat exactly on it, and the medians were 9 % and 17 %
    # low (of a truncated normal known exactly)
    model, mean, cov, bounds = linear_problem([0.5, 0.5, 0.02, 0.002], 0.01, seed=5)
    samples = sample_posterior(model, range(8), seed=3, method=method).samples
    exact = truncated_quantiles(mean, cov, bounds, [2.5, 50, 97.5])
    for j in (2, 3):
        assert np.mean(samples[:, j] == bounds[j][0]) < 0.001
        low, median, high = np.percentile(samples[:, j], [2.5, 50, 97.5])
        assert median == pytest.approx(exact[1, j], rel=0.07)
        assert high == pytest.approx(exact[2, j], rel=0.07)
        assert low < 2 * exact[0, j]  # 0.1 and 0.05 of the median: near the bound


def _coverage_trial(rng: np.random.Generator, n_dem: int, n_points: int = 8):
    """One synthetic calibration with the truth drawn from the prior and data from the
    observation model itself (measurement error, relative discrepancy tau): (which 95 %
    parameter intervals hold the truth, whether the 95 % band of a held-out point holds its
    measurement)."""
    from dataclasses import replace

    from pidcore.calibrate.parameters import parameter_spec
    from pidcore.calibrate.posterior import predictive

    sigma = 0.01
    surrogates = [LinearSurrogate(1e-3 * (1 + i), 4e-3 * rng.uniform(0.3, 1.5, n_dem))
                  for i in range(n_points + 1)]
    specs = [ParameterSpec(f"p{j}", "dem", 0.5, 0.0, 1.0, "x") for j in range(n_dem)]
    specs.append(ParameterSpec("baseline_loss_factor", "observation", 0.0, 0.0, 0.05, "eta"))
    # log-uniform as the default, narrower: no synthetic SDC below 0 (the band is cut there)
    specs.append(replace(parameter_spec("model_discrepancy"), high=0.3))
    truth = np.array([math.exp(rng.uniform(math.log(s.low), math.log(s.high)))
                      if s.prior == "log-uniform" else rng.uniform(s.low, s.high)
                      for s in specs])
    fixed = {"fixture_mass_kg": 0.0}
    blank = tuple(MeasuredPoint(100.0, 1.0, 50.0, 0.0, sigma) for _ in surrogates)
    model = Model(tuple(specs), tuple(surrogates), blank, fixed, 0.01)
    points = []
    for i in range(n_points + 1):
        sdc, variance = model.predict(truth[None, :], i)
        points.append(MeasuredPoint(100.0, 1.0, 50.0,
                                    float(sdc[0] + math.sqrt(variance[0]) * rng.standard_normal()),
                                    sigma))
    model = Model(tuple(specs), tuple(surrogates), tuple(points), fixed, 0.01)
    fitted = range(n_points)  # the last point is held out, as in a leave-one-out fold
    samples = sample_posterior(model, fitted, seed=int(rng.integers(2**31)), method="grid",
                               n_samples=2000).samples
    low, high = np.percentile(samples, [2.5, 97.5], axis=0)
    band = predictive(model, samples, n_points, rng=rng)
    return (low <= truth) & (truth <= high), band["low95"] <= points[-1].sdc <= band["high95"]


@pytest.mark.parametrize("n_dem, trials", [(0, 300),
                                            pytest.param(1, 150, marks=pytest.mark.slow)])
def test_95_percent_intervals_cover_the_truth_95_percent_of_the_time(n_dem, trials):
    # truth drawn from the prior: a Bayesian 95 % interval then holds it with probability
    # 0.95 exactly, near a bound too; the band of a held-out measurement likewise
    rng = np.random.default_rng(2026 + n_dem)
    results = [_coverage_trial(rng, n_dem) for _ in range(trials)]
    covered = np.array([r[0] for r in results]).mean(axis=0)
    band = np.mean([r[1] for r in results])
    tolerance = 3.3 * math.sqrt(0.95 * 0.05 / trials)  # binomial, 3.3 sd
    assert np.all(np.abs(covered - 0.95) < tolerance), covered
    assert abs(band - 0.95) < tolerance, band


@pytest.mark.parametrize("truth, sigma", [([0.5, 0.5, 0.02], 0.001),
                                          ([0.5, 0.5, 0.5, 0.02], 0.0003)])
def test_a_posterior_narrower_than_the_grid_steps_is_resolved(truth, sigma):
    # precise data: a correlated posterior far narrower than the coarse grid's step (the
    # marginal sd 0.2-0.5 % of the prior range). One fine pass on the box the coarse pass
    # found put it on a handful of nodes, or cut it off: sd 0.7x-5.7x, the mean 0.3-0.6 sd off
    model, mean, cov, _ = linear_problem(truth, sigma, seed=5)
    sd = np.sqrt(np.diag(cov))
    samples = sample_posterior(model, range(8), seed=3, method="grid").samples
    assert samples.std(axis=0) == pytest.approx(sd, rel=0.08)
    assert np.all(np.abs(samples.mean(axis=0) - mean) < 0.15 * sd)


def test_a_grid_that_cannot_box_the_posterior_is_refused_or_left_to_emcee(monkeypatch):
    from pidcore.calibrate import posterior

    model, mean, cov, _ = linear_problem([0.5, 0.5, 0.02], 0.001, seed=5)
    passes = posterior.GRID_MAX_PASSES
    monkeypatch.setattr(posterior, "GRID_MAX_PASSES", 1)  # no room to zoom in
    with pytest.raises(posterior.GridUnresolved, match="use method=emcee"):
        sample_posterior(model, range(8), seed=3, method="grid")
    drawn = sample_posterior(model, range(8), seed=3, method="auto")
    assert drawn.samples.std(axis=0) == pytest.approx(np.sqrt(np.diag(cov)), rel=0.1)
    # the fallback is said (the calibration shows it as a note), not silent
    assert drawn.method == "emcee" and "did not settle" in drawn.fallback
    # where the grid resolves it, auto uses the grid and says nothing
    monkeypatch.setattr(posterior, "GRID_MAX_PASSES", passes)
    resolved = sample_posterior(model, range(8), seed=3, method="auto")
    assert resolved.method == "grid" and resolved.fallback is None


def test_a_band_for_another_measurements_stderr_is_that_measurements_band():
    # a report compared a new measurement with the band of the fitted point's measurement
    # error: a precise measurement was judged by a noisy point's wide band. The band without
    # measurement error widened by another stderr must be the band the posterior gives a
    # point of that stderr (independent normal errors add in quadrature)
    from dataclasses import replace

    from pidcore.calibrate.posterior import predictive
    from pidcore.calibrate.prediction import CalibratedPrediction
    from pidcore.loadcase import LoadCase

    sigma, other = 0.01, 0.05
    model, _, _, _ = linear_problem([0.4, 0.02], sigma, seed=1)
    samples = sample_posterior(model, range(8), seed=3, method="grid").samples
    fitted = predictive(model, samples, 0, rng=np.random.default_rng(7))
    hit = CalibratedPrediction(LoadCase(100.0, 1.0, 50.0), fitted["predicted"],
                               fitted["low95"], fitted["high95"], 0.0, sigma,
                               fitted["low95_without_stderr"], fitted["high95_without_stderr"])
    # its own point's stderr (or none known): the band calibration.json states, exactly
    assert hit.band(sigma) == hit.band() == (fitted["low95"], fitted["high95"])
    # without the measurement error the band is narrower, and no stderr gives exactly it
    assert fitted["low95"] < fitted["low95_without_stderr"] < fitted["predicted"]
    assert fitted["predicted"] < fitted["high95_without_stderr"] < fitted["high95"]
    assert hit.band(0.0) == pytest.approx((fitted["low95_without_stderr"],
                                           fitted["high95_without_stderr"]), rel=1e-12)
    # the same posterior asked for a point of stderr 0.05 at that load case
    points = (replace(model.points[0], sdc_stderr=other), *model.points[1:])
    noisy = predictive(replace(model, points=points), samples, 0, rng=np.random.default_rng(7))
    low, high = hit.band(other)
    width = noisy["high95"] - noisy["low95"]
    # Monte-Carlo percentiles of the 2.5 % tails of N_SAMPLES draws: ~2 % of the width
    assert low == pytest.approx(noisy["low95"], abs=0.03 * width)
    assert high == pytest.approx(noisy["high95"], abs=0.03 * width)
    assert high - low > 2 * (fitted["high95"] - fitted["low95"])  # 5 x the stderr: far wider


def test_a_reported_bound_is_shown_to_the_digits_its_sampling_leaves():
    # the fixture mass's upper bound read 0.4734 while it moved 0.467-0.484 from one set of
    # posterior samples to the next: digits beyond its Monte-Carlo error were noise. The
    # batch-means error must predict the seed-to-seed scatter, and the shown digits end there
    from pidcore.calibrate.posterior import summarise, summary_texts

    model, _, _, _ = linear_problem([0.4, 0.02], 0.01, seed=1)
    summaries = [summarise(model.specs, sample_posterior(model, range(8), seed=seed,
                                                          method="grid").samples)[0]["p0"]
                 for seed in range(30)]
    for key in ("median", "low95", "high95"):
        scatter = np.std([s[key] for s in summaries], ddof=1)
        predicted = np.mean([s[f"{key}_mc_se"] for s in summaries])
        # 30 seeds: the scatter's own estimate is good to ~13 %, each batch-means error to
        # ~24 % (10 batches); their ratio well inside a factor 1.6 either way
        assert predicted == pytest.approx(scatter, rel=0.6), key
    s = summaries[0]
    median, low, high = summary_texts(s)
    for text, key in ((median, "median"), (low, "low95"), (high, "high95")):
        decimals = len(text.split(".")[1]) if "." in text else 0
        # the last digit shown is the one the standard error reaches, not further
        assert 10.0 ** -decimals >= s[f"{key}_mc_se"] / 10
        assert float(text) == pytest.approx(s[key], abs=10.0 ** -decimals)


def test_an_emcee_chain_shorter_than_emcee_asks_is_flagged_not_passed():
    # emcee ran a fixed 2000 steps whatever the posterior and said nothing: with 4 fitted
    # quantities that was 18 autocorrelation times, an effective sample of 580 draws behind
    # the 4000 samples. A chain under emcee's rule must say so; the default run extends its
    # chain until the rule holds
    from pidcore.calibrate.posterior import EMCEE_TAU_LENGTHS, sample_emcee

    model, mean, cov, _ = linear_problem([0.4, 0.02], 0.01, seed=1)
    _, short = sample_emcee(model, range(8), rng=np.random.default_rng(3), n_steps=150,
                            burn=50, max_steps=150)
    assert not short.converged and "autocorrelation times" in short.reason
    assert short.steps - short.discarded < EMCEE_TAU_LENGTHS * max(short.autocorrelation_steps)
    drawn = sample_posterior(model, range(8), seed=3, method="emcee")
    d = drawn.diagnostics
    assert drawn.converged and d.reason is None
    kept = d.steps - d.discarded
    assert kept >= EMCEE_TAU_LENGTHS * max(d.autocorrelation_steps)
    assert d.effective_size == pytest.approx(d.walkers * kept / max(d.autocorrelation_steps))
    # the stretch move on a 2-d Gaussian accepts about half its proposals: far from stuck
    assert 0.2 < d.acceptance < 0.8
    # the grid is an exact quadrature: no chain to judge
    assert sample_posterior(model, range(8), seed=3, method="grid").diagnostics is None


def test_the_monte_carlo_error_of_chain_samples_counts_the_chains_effective_draws():
    # emcee's samples are 4000 picked from a correlated chain; the batch-means error saw them
    # as 4000 independent draws and shrank the error (and the digits shown) by
    # sqrt(1 + n / effective size). An AR(1) chain has a known autocorrelation time
    # (1 + rho) / (1 - rho): the error given its effective size must match the scatter of the
    # median over many chains
    from scipy.signal import lfilter

    from pidcore.calibrate.posterior import quantile_mc_stderr

    rng = np.random.default_rng(11)
    rho, length, n = 0.9, 40_000, 4000
    tau = (1 + rho) / (1 - rho)
    medians, errors, iid = [], [], []
    for _ in range(200):
        # started from the stationary law (unit variance): no burn-in
        chain = lfilter([math.sqrt(1 - rho**2)], [1, -rho], rng.standard_normal(length),
                        zi=[rho * rng.standard_normal()])[0]
        picked = rng.choice(chain, size=n, replace=False)
        medians.append(np.median(picked))
        errors.append(quantile_mc_stderr(picked, [50], effective_size=length / tau)[0])
        iid.append(quantile_mc_stderr(picked, [50])[0])
    scatter = np.std(medians, ddof=1)
    # 200 chains: the scatter is known to 5 %, the mean batch-means error to ~2 %; the
    # formula leaves out the picking's finite-population term (-n/length: 3 % of the variance)
    assert np.mean(errors) == pytest.approx(scatter, rel=0.15)
    assert np.mean(iid) < 0.7 * scatter  # the old error: 1.7x too small here


def test_a_measured_sdc_below_zero_within_its_noise_is_inside_its_band():
    # zero damping measured with noise: -0.057 +- 0.13 (7 degrees of freedom) beside a model
    # SDC of 0.002. The band's draws were cut at 0 after the measurement's own error was
    # added: band 0 .. 0.31, verdict "no" in-sample and leave-one-out, and every measurement
    # below 0 (half of them here) outside. The model's SDC is fixed (baseline prior 0..1e-6,
    # no discrepancy or floor): the band is that SDC + 0.13 t_7 exactly
    from scipy import stats

    from pidcore.calibrate.calibrate import _row
    from pidcore.calibrate.posterior import predictive
    from pidcore.calibrate.prediction import row_verdict
    from pidcore.compare.plausibility import UNKNOWN_SPECIMEN_BOUND

    stderr, dof = 0.13, 7.0
    surrogate = LinearSurrogate(1e-5, np.zeros(0))
    specs = (ParameterSpec("baseline_loss_factor", "observation", 0.0, 0.0, 1e-6, "eta"),)
    points = (MeasuredPoint(100.0, 1.0, 50.0, -0.057, stderr, sdc_stderr_dof=dof),
              MeasuredPoint(100.0, 1.0, 50.0, 0.05, stderr, sdc_stderr_dof=1.0))
    model = Model(specs, (surrogate,) * 2, points,
                  {"fixture_mass_kg": 0.0, "model_discrepancy": 0.0}, 0.0)
    samples = sample_posterior(model, [0, 1], seed=1, method="grid").samples
    band = predictive(model, samples, 0, rng=np.random.default_rng(0))
    sdc = 2 * math.pi * 1e-5 / (REACTIVE_KG + COUPON_KG)
    # the baseline's prior, up to 1e-6, adds at most 2 pi 1e-6 m_s / (m_p + m_s) = 5e-6
    assert band["predicted"] == pytest.approx(sdc, abs=5.2e-6)
    half = stats.t.ppf(0.975, dof) * stderr  # 0.307
    # the 2.5 % and 97.5 % points of 4000 t_7 draws scatter by ~0.07 t = 0.009: 4 sd
    assert band["low95"] == pytest.approx(sdc - half, abs=0.04)
    assert band["high95"] == pytest.approx(sdc + half, abs=0.04)
    # the verdict of the calibration's rows (in-sample and leave-one-out alike)
    assert row_verdict(_row(points[0], band), UNKNOWN_SPECIMEN_BOUND) == "yes"
    # held-out measurements drawn from the error model: 95 % inside (binomial, 3.3 sd)
    y = sdc + stderr * np.random.default_rng(5).standard_t(dof, 4000)
    inside = np.mean((band["low95"] <= y) & (y <= band["high95"]))
    assert abs(inside - 0.95) < 3.3 * math.sqrt(0.95 * 0.05 / 4000)
    # a measurement of 1 degree of freedom (t = 12.7): below -3 stderr it is refused as energy
    # created beyond its noise, so its band stops there (P(t_1 < -3) = 10 % of the draws)
    noisy = predictive(model, samples, 1, rng=np.random.default_rng(0))
    assert noisy["low95"] == -3 * stderr
