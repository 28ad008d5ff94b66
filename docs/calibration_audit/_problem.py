"""A synthetic calibration problem whose answer can be computed without pidcore.

The DEM is replaced by a closed-form response per load case: dissipative mass
d_i(theta) = a_i (1 + b_i exp(-3 theta)) kg with a known surrogate variance var_d_i, reactive
mass m_p,i constant. The measured SDC follows docs/calibration.md ("Observation model",
"Likelihood"):

    s_i = 2 pi (d_i + eta m_s) / (m_p,i + m_s),   m_s = m_coupon + m_f
    y_i ~ N(s_i, se_i^2 + (2 pi / (m_p,i + m_s))^2 var_d_i + (tau s_i)^2 + floor^2)

Priors as documented: theta uniform 0..1 (a DEM parameter), m_f uniform 0..1 kg, eta uniform
0..0.05, tau log-uniform 0.02..2.

Everything here except ``pidcore_model`` is plain numpy/scipy written from the documentation,
not from pidcore's code. ``pidcore_model`` builds pidcore's Model from the same numbers (the
only coupling: a fake surrogate object with pidcore's ``predict`` signature).
"""

from __future__ import annotations

import math

import numpy as np

COUPON_KG = 0.02215
FLOOR = 0.01
PRIOR = {"theta": (0.0, 1.0), "fixture_mass_kg": (0.0, 1.0),
         "baseline_loss_factor": (0.0, 0.05), "model_discrepancy": (0.02, 2.0)}
NAMES = tuple(PRIOR)


class Problem:
    """n_cases load cases of the closed-form response (seeded)."""

    def __init__(self, n_cases: int = 12, seed: int = 0, stderr: float = 0.02):
        rng = np.random.default_rng(seed)
        self.a = rng.uniform(1e-3, 6e-3, n_cases)
        self.b = rng.uniform(-0.6, 1.5, n_cases)
        self.m_p = rng.uniform(0.002, 0.012, n_cases)
        self.var_d = (0.03 * self.a) ** 2  # a 3 % surrogate standard deviation
        self.stderr = np.full(n_cases, stderr)
        self.n = n_cases

    def sdc(self, theta, fixture, eta):
        """(n_cases, N) SDC and (n_cases, N) variance without tau, floor and stderr."""
        theta, fixture, eta = (np.asarray(v, float)[None, :] for v in (theta, fixture, eta))
        d = self.a[:, None] * (1 + self.b[:, None] * np.exp(-3 * theta))
        m_s = COUPON_KG + fixture
        den = self.m_p[:, None] + m_s
        s = 2 * math.pi * (d + eta * m_s) / den
        return s, (2 * math.pi / den) ** 2 * self.var_d[:, None]

    def variance(self, s, var_dem, tau, cases):
        return (self.stderr[cases, None] ** 2 + var_dem + (np.asarray(tau)[None, :] * s) ** 2
                + FLOOR ** 2)

    def log_likelihood(self, x, y, cases):
        """x: (N, 4) in NAMES order; y: measured SDC of all cases; cases: indices used."""
        cases = np.asarray(cases)
        s, var_dem = self.sdc(x[:, 0], x[:, 1], x[:, 2])
        s, var_dem = s[cases], var_dem[cases]
        v = self.variance(s, var_dem, x[:, 3], cases)
        r = y[cases, None] - s
        return np.sum(-0.5 * r**2 / v - 0.5 * np.log(2 * math.pi * v), axis=0)

    def draw_truth(self, rng):
        lo, hi = PRIOR["model_discrepancy"]
        return np.array([rng.uniform(*PRIOR["theta"]), rng.uniform(*PRIOR["fixture_mass_kg"]),
                         rng.uniform(*PRIOR["baseline_loss_factor"]),
                         math.exp(rng.uniform(math.log(lo), math.log(hi)))])

    def draw_data(self, truth, rng):
        s, var_dem = self.sdc(truth[None, 0], truth[None, 1], truth[None, 2])
        v = self.variance(s, var_dem, truth[None, 3], np.arange(self.n))
        return (s + np.sqrt(v) * rng.standard_normal(s.shape))[:, 0]


class FakeSurrogate:
    """pidcore's surrogate interface (``predict(theta) -> d, var d, m_p, var m_p``)."""

    frequency_hz, acceleration_g, fill_percent = 100.0, 5.0, 50.0
    coupon_mass_kg = COUPON_KG

    def __init__(self, a, b, m_p, var_d, theta_fixed=None):
        self.a, self.b, self.m_p, self.var_d = a, b, m_p, var_d
        self.theta_fixed = theta_fixed

    def predict(self, theta):
        theta = np.atleast_2d(theta)
        # no DEM parameter fitted: the response at the fixed theta
        theta = np.full(theta.shape[0], self.theta_fixed) if theta.shape[1] == 0 \
            else theta[:, 0]
        n = theta.shape[0]
        return (self.a * (1 + self.b * np.exp(-3 * theta)), np.full(n, self.var_d),
                np.full(n, self.m_p), np.zeros(n))


def pidcore_model(problem: Problem, y, *, fit=NAMES, fixed=None):
    """pidcore's Model of the same problem (``fit``: which of NAMES are fitted)."""
    from pidcore.calibrate.data import MeasuredPoint
    from pidcore.calibrate.parameters import ParameterSpec, parameter_spec
    from pidcore.calibrate.posterior import Model

    specs = []
    for name in fit:
        if name == "theta":
            specs.append(ParameterSpec("theta", "dem", 0.5, *PRIOR["theta"], "closed form"))
        elif name == "model_discrepancy":
            specs.append(parameter_spec("model_discrepancy"))
        else:
            specs.append(ParameterSpec(name, "observation", 0.0, *PRIOR[name], name))
    theta_fixed = None if "theta" in fit else float((fixed or {})["theta"])
    surrogates = tuple(FakeSurrogate(problem.a[i], problem.b[i], problem.m_p[i],
                                     problem.var_d[i], theta_fixed) for i in range(problem.n))
    points = tuple(MeasuredPoint(100.0, 5.0, 50.0, float(y[i]), float(problem.stderr[i]))
                   for i in range(problem.n))
    fixed = {k: v for k, v in (fixed or {}).items() if k != "theta"}
    return Model(tuple(specs), surrogates, points, fixed, FLOOR)
