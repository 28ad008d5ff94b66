"""The calibration's likelihood where a measured SDC's standard error states its degrees of
freedom: the measurement's error is sdc_stderr times Student's t, the model's terms normal.

Truths the code did not produce: scipy's t density (no model terms), a direct numerical
convolution of the t and the normal densities (scipy.integrate.quad), and the normal density
where the degrees of freedom are unknown.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy import integrate, stats

from pidcore.calibrate.data import MeasuredPoint
from pidcore.calibrate.likelihood import log_density
from pidcore.calibrate.parameters import ParameterSpec
from pidcore.calibrate.posterior import Model, sample_posterior
from tests.test_calibrate_posterior import COUPON_KG, REACTIVE_KG, LinearSurrogate

STDERR = 0.02
#: The table's interpolation error of the log density, at most 3.3e-3 for 7 degrees of freedom
#: and 8e-3 for 14-30 wherever the density is above e^-20 (checked against the quadrature
#: itself over 3000 random residuals and shares): 0.01 leaves room, and a normal likelihood
#: misses these densities by 0.5 and more.
TABLE_TOLERANCE = 0.01


def _model(values, *, dof, stderr=STDERR, floor=0.0):
    """One-parameter model (baseline loss factor, uniform 0..0.2): predicted SDC
    2 pi (c0 + eta m_s) / (m_p + m_s) at each point; no surrogate variance, no discrepancy."""
    surrogates = [LinearSurrogate(1e-3, np.zeros(0)) for _ in values]
    specs = (ParameterSpec("baseline_loss_factor", "observation", 0.0, 0.0, 0.2, "eta"),)
    points = tuple(MeasuredPoint(100.0, 1.0, 50.0, float(v), stderr, sdc_stderr_dof=dof)
                   for v in values)
    return Model(specs, tuple(surrogates), points,
                 {"fixture_mass_kg": 0.0, "model_discrepancy": 0.0}, floor)


def _predicted(eta):
    return 2 * math.pi * (1e-3 + eta * COUPON_KG) / (REACTIVE_KG + COUPON_KG)


@pytest.mark.parametrize("dof", [3.0, 7.0, 13.7])
def test_without_model_terms_the_likelihood_is_scipys_student_t(dof):
    # stderr * t_dof about the prediction: log t.pdf(r / s) - log s
    eta = 0.02
    residuals = np.array([0.0, 0.5, 1.0, 2.0, 3.0, 6.0, 15.0, 40.0]) * STDERR
    for r in residuals:
        model = _model([_predicted(eta) + r], dof=dof)
        got = model.log_likelihood(np.array([[eta]]), [0])[0]
        want = stats.t.logpdf(r / STDERR, dof) - math.log(STDERR)
        assert got == pytest.approx(want, abs=TABLE_TOLERANCE), r / STDERR


def _convolution(residual, stderr, dof, other_sd):
    """log of the density of stderr * t_dof + N(0, other_sd^2) at residual, by quadrature."""
    def integrand(e):
        return stats.t.pdf(e / stderr, dof) / stderr * stats.norm.pdf(residual - e,
                                                                    scale=other_sd)
    # the mass lies near 0 (the t's peak) and near the residual (the normal's): split there
    edges = sorted({-np.inf, min(0.0, residual) - 10 * other_sd, 0.0, residual,
                    max(0.0, residual) + 10 * other_sd, np.inf})
    total = sum(integrate.quad(integrand, a, b, epsabs=0, epsrel=1e-11, limit=400)[0]
                for a, b in itertools.pairwise(edges))
    return math.log(total)


@pytest.mark.parametrize("other_sd", [0.005, 0.02, 0.06])
def test_with_model_terms_the_likelihood_is_the_convolution_of_t_and_normal(other_sd):
    # the discrepancy floor is the model's normal term here
    eta = 0.02
    for z in (0.0, 1.0, 2.5, 5.0, 12.0):
        r = z * math.hypot(STDERR, other_sd)
        model = _model([_predicted(eta) + r], dof=7.0, floor=other_sd)
        got = model.log_likelihood(np.array([[eta]]), [0])[0]
        assert got == pytest.approx(_convolution(r, STDERR, 7.0, other_sd),
                                    abs=TABLE_TOLERANCE), z


def test_unknown_or_missing_degrees_of_freedom_keep_the_normal_likelihood_bit_for_bit():
    residual = np.array([-0.05, 0.0, 0.01, 0.3])
    variance = np.full(4, 0.03**2)
    normal = -0.5 * (residual**2 / variance + np.log(2 * math.pi * variance))
    # unknown, no stderr, infinite, above NORMAL_ABOVE_DOF, and a stderr below
    # MIN_MEASUREMENT_SHARE of the total standard deviation (1e-5 of 0.03)
    for stderr, dof in ((0.02, math.nan), (0.0, 7.0), (0.02, math.inf), (0.02, 1e6),
                        (1e-5, 7.0)):
        np.testing.assert_array_equal(log_density(residual, variance, stderr=stderr, dof=dof),
                                      normal)


def _posterior_median(values, dof):
    samples = sample_posterior(_model(values, dof=dof, floor=0.005), range(len(values)),
                               seed=1, method="grid").samples
    return float(np.median(samples[:, 0]))


def test_a_heavy_outlier_moves_the_posterior_less_than_under_a_normal_likelihood():
    # 8 measurements of one predicted SDC at eta = 0.02, scattered by +-1 stderr; then one of
    # them 15 stderr high. Under a normal error the estimate is the (weighted) mean, which the
    # outlier drags by 15/8 stderr; t with 7 degrees of freedom down-weights it
    rng = np.random.default_rng(4)
    clean = _predicted(0.02) + STDERR * rng.uniform(-1, 1, 8)
    dirty = clean.copy()
    dirty[3] += 15 * STDERR
    slope = _predicted(1.0) - _predicted(0.0)  # d SDC / d eta
    moved = {}
    for name, dof in (("normal", math.nan), ("t", 7.0)):
        moved[name] = (_posterior_median(dirty, dof) - _posterior_median(clean, dof)) * slope
    # the normal posterior's mean moves by exactly 15/8 stderr (equal variances); its median
    # within the grid's Monte-Carlo error (4000 samples: 0.05 of the posterior's sd)
    assert moved["normal"] == pytest.approx(15 / 8 * STDERR, rel=0.1)
    assert 0 < moved["t"] < 0.5 * moved["normal"]


def test_a_non_finite_prediction_gives_nan_as_the_normal_does_not_a_table_index():
    # NaN became a table index of -2^63 (IndexError) before the guard
    residual = np.array([np.nan, np.inf, 0.01])
    variance = np.array([0.03**2, 0.03**2, np.nan])
    got = log_density(residual, variance, stderr=0.02, dof=7.0)
    assert np.all(np.isnan(got))
    normal = log_density(residual, variance, stderr=0.02, dof=math.nan)
    assert np.all(~np.isfinite(normal))
