"""Space-filling design of the DEM parameters and a surrogate per load case.

Design: a Latin hypercube (:class:`scipy.stats.qmc.LatinHypercube`, centred, seeded) over the
DEM parameters' bounds; no DEM parameter -> one run per load case at the starting values.

Surrogate: per load case, a Gaussian process of ``log d`` (dissipative mass) and of ``m_p``
(reactive mass) over the design coordinates scaled to [0, 1]: constant mean, squared-
exponential kernel, and the DEM runs' own standard errors (the ensemble scatter across cells
and blocks) as known noise on each run. ``log d`` only where every run resolves its d (d at
least LOG_RESOLVED_STDERRS standard errors); else ``d`` itself, where a run that dissipates
nothing (d <= 0 within its noise) is an observation like any other. A run stated without
scatter (its cells agreed exactly, or its bed never touched a wall) takes the median standard
error of the case's other runs: it is one more noisy estimate, not an exact value. Kernel
amplitude and length scale maximise the marginal likelihood over a small grid. Its predictive
variance is the surrogate's uncertainty of the DEM's mean at a parameter value: small at a
design point with many cells, larger between points where the response bends (computed
through the Cholesky factor, positive between noisy runs). With one run (no DEM parameter) it
is that run's value and standard error.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .observation import Observation
from .parameters import ParameterSpec

#: A case's surrogate is of log d where every run's d is at least this many of its standard
#: errors: the log's standard error se / d is then <= 1/3, where its first-order propagation
#: holds (bias (se/d)^2 / 2 under 6 %). A run nearer 0 entered log space clamped to 1e-12 kg
#: with a relative error of ~1e9 (or, one with no wall force at all, as an exact log d of
#: -27.6): the kernel's amplitude went to ~1e15, d to 121 kg between the runs and its variance
#: to exactly 0 at others.
LOG_RESOLVED_STDERRS = 3.0
#: Length scales (in units of the design range) and amplitude factors searched.
_LENGTH_SCALES = (0.1, 0.2, 0.35, 0.6, 1.0, 2.0)
_AMPLITUDES = tuple(10.0 ** np.linspace(-3, 1.5, 10))
#: Extra noise (fraction of the amplitude) searched: DEM scatter beyond the runs' own standard
#: errors (a few cells give a poor estimate; a packing's stick-slip thresholds make the
#: response rough from one parameter value to the next).
_NUGGETS = (0.0, 1e-2, 0.03, 0.1, 0.3)


def design_points(specs: Sequence[ParameterSpec], n_points: int, *,
                  seed: int = 0) -> np.ndarray:
    """(n_points, n_dem) design over the DEM parameters' bounds; (1, 0) when there are none."""
    from scipy.stats import qmc

    if not specs:
        return np.zeros((1, 0))
    sampler = qmc.LatinHypercube(d=len(specs), scramble=False, seed=seed)
    unit = sampler.random(n_points)
    low = np.array([s.low for s in specs])
    high = np.array([s.high for s in specs])
    return low + unit * (high - low)


def default_design_size(n_dem: int) -> int:
    """Design points for ``n_dem`` DEM parameters: 5 for one, 4 more per further one."""
    if n_dem == 0:
        return 1
    return 5 + 4 * (n_dem - 1)


def _kernel(a: np.ndarray, b: np.ndarray, length: float) -> np.ndarray:
    d2 = np.sum((a[:, None, :] - b[None, :, :]) ** 2, axis=-1)
    return np.exp(-0.5 * d2 / length**2)


@dataclass(frozen=True)
class _Process:
    """A fitted 1-output Gaussian process (or a constant with its variance when n_dem = 0)."""

    u: np.ndarray
    mean: float
    amplitude: float
    length: float
    weights: np.ndarray  # (K + N)^-1 (y - mean)
    whitening: np.ndarray  # L^-1, L the lower Cholesky factor of K + N
    constant_variance: float

    def predict(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.u.shape[1] == 0 or self.amplitude == 0.0:
            n = u.shape[0]
            return np.full(n, self.mean), np.full(n, self.constant_variance)
        k = self.amplitude * _kernel(u, self.u, self.length)
        mean = self.mean + k @ self.weights
        # k (K + N)^-1 k as |L^-1 k|^2, a sum of squares: through the explicit inverse it
        # cancelled to below 0 (clipped to an exact 0) between noisy runs. L^-1 once per fit,
        # not a triangular solve per call: the grid posterior calls this thousands of times
        v = self.whitening @ k.T
        var = self.amplitude - np.sum(v * v, axis=0)
        # the constant mean is estimated too (universal kriging): its variance where the
        # runs do not pin the prediction down
        w = self.whitening.sum(axis=1)
        var = var + (1.0 - v.T @ w) ** 2 / (w @ w)
        return mean, np.maximum(var, 0.0)  # >= 0 exactly; rounding may take it a hair below


def _fit(u: np.ndarray, y: np.ndarray, se: np.ndarray) -> _Process:
    from scipy.linalg import cho_solve, solve_triangular

    n, d = u.shape
    noise = np.maximum(se**2, 1e-12 * max(float(np.var(y)), 1e-30))
    if d == 0 or n == 1:
        w = 1.0 / noise
        mean = float(np.sum(w * y) / np.sum(w))
        return _Process(u, mean, 0.0, 1.0, np.zeros(n), np.eye(n), float(1.0 / np.sum(w)))
    scale = max(float(np.var(y)), float(np.mean(noise)), 1e-30)
    ones = np.ones(n)
    best = None
    for length in _LENGTH_SCALES:
        base = _kernel(u, u, length)
        for factor, nugget in itertools.product(_AMPLITUDES, _NUGGETS):
            amplitude = factor * scale
            cov = amplitude * (base + nugget * np.eye(n)) + np.diag(noise)
            try:
                chol = np.linalg.cholesky(cov)
            except np.linalg.LinAlgError:
                continue
            solved_ones = cho_solve((chol, True), ones)
            mean = float(solved_ones @ y / (ones @ solved_ones))
            r = y - mean
            weights = cho_solve((chol, True), r)
            logml = -0.5 * r @ weights - np.sum(np.log(np.diag(chol)))
            if best is None or logml > best[0]:
                best = (logml, amplitude, length, mean, chol, weights)
    _, amplitude, length, mean, chol, weights = best
    # the nugget is scatter of the runs, not of the DEM's mean: it widens the fit (through
    # the factor) but is not added to the predictive variance of the mean
    return _Process(u, mean, amplitude, length, weights,
                    solve_triangular(chol, np.eye(n), lower=True), 0.0)


def _stated_stderr(se: np.ndarray) -> np.ndarray:
    """The runs' standard errors, where a run without scatter (0: its cells agreed exactly,
    or its bed never touched a wall) takes the median of the others': as an exact value it
    pinned the surrogate through it. Unchanged where no run states any scatter."""
    se = np.asarray(se, dtype=float)
    stated = se[np.isfinite(se) & (se > 0)]
    if stated.size == 0:
        return se
    return np.where(np.isfinite(se) & (se > 0), se, float(np.median(stated)))


@dataclass(frozen=True)
class CaseSurrogate:
    """Surrogate of one load case's observation over the DEM parameters."""

    frequency_hz: float
    acceleration_g: float
    fill_percent: float
    coupon_mass_kg: float
    low: np.ndarray
    high: np.ndarray
    dissipative: _Process
    #: whether :attr:`dissipative` is of log d (every run resolved its d) or of d itself
    logarithmic: bool
    reactive: _Process

    def predict(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                  np.ndarray]:
        """(d, var d, m_p, var m_p) at DEM parameter values ``theta`` (N, n_dem), kg / kg^2."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        if theta.shape[1] == 0:
            u = np.zeros((theta.shape[0], 0))
        else:
            u = (theta - self.low) / (self.high - self.low)
        d, var_d = self.dissipative.predict(u)
        m_p, var_m = self.reactive.predict(u)
        if self.logarithmic:
            d = np.exp(d)
            var_d = d**2 * var_d
        return d, var_d, m_p, var_m


def build_surrogate(observations: Sequence[Observation], theta: np.ndarray,
                    specs: Sequence[ParameterSpec]) -> CaseSurrogate:
    """Surrogate of one load case from its runs at design points ``theta`` (n, n_dem)."""
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    n, d = theta.shape
    low = np.array([s.low for s in specs]) if d else np.zeros(0)
    high = np.array([s.high for s in specs]) if d else np.ones(0)
    u = (theta - low) / (high - low) if d else np.zeros((n, 0))
    dm = np.array([o.dissipative_mass_kg for o in observations])
    dm_se = _stated_stderr([o.dissipative_mass_stderr_kg for o in observations])
    mp = np.array([o.reactive_mass_kg for o in observations])
    mp_se = _stated_stderr([o.reactive_mass_stderr_kg for o in observations])
    # the log only where no run's d is near 0 within its noise (a run of d <= 0 has no log)
    logarithmic = bool(np.all(dm > 0) and np.all(dm >= LOG_RESOLVED_STDERRS * dm_se))
    dissipative = (_fit(u, np.log(dm), dm_se / dm) if logarithmic else _fit(u, dm, dm_se))
    first = observations[0]
    return CaseSurrogate(
        frequency_hz=first.frequency_hz, acceleration_g=first.acceleration_g,
        fill_percent=first.fill_percent, coupon_mass_kg=first.coupon_mass_kg,
        low=low, high=high, dissipative=dissipative, logarithmic=logarithmic,
        reactive=_fit(u, mp, mp_se))


def unique_points(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(distinct rows, inverse index) of DEM parameter sets, or None when not worth it (few
    rows or no DEM parameter). A posterior grid repeats each DEM point many times."""
    theta = np.atleast_2d(theta)
    if theta.shape[1] == 0 or len(theta) < 64:
        return None
    if theta.shape[1] == 1:
        unique, inverse = np.unique(theta[:, 0], return_inverse=True)
        return unique[:, None], inverse.ravel()
    unique, inverse = np.unique(theta, axis=0, return_inverse=True)
    return unique, inverse.ravel()


def predicted_sdc(surrogate: CaseSurrogate, theta: np.ndarray, fixture_mass_kg: np.ndarray,
                  baseline_loss_factor: np.ndarray, *,
                  unique: tuple[np.ndarray, np.ndarray] | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """(SDC, its variance from the DEM surrogate) for N parameter sets (observation model).

    ``unique``: :func:`unique_points` of ``theta``, to evaluate the surrogate once per point.
    """
    if unique is None:
        d, var_d, m_p, var_m = surrogate.predict(theta)
    else:
        points, inverse = unique
        d, var_d, m_p, var_m = (v[inverse] for v in surrogate.predict(points))
    structure = surrogate.coupon_mass_kg + np.asarray(fixture_mass_kg, dtype=float)
    denominator = m_p + structure
    sdc = 2 * math.pi * (d + baseline_loss_factor * structure) / denominator
    var = (2 * math.pi / denominator) ** 2 * var_d + (sdc / denominator) ** 2 * var_m
    return sdc, var
