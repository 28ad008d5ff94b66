"""Space-filling design of the DEM parameters and a surrogate per load case.

Design: a Latin hypercube (:class:`scipy.stats.qmc.LatinHypercube`, centred, seeded) over the
DEM parameters' bounds; no DEM parameter -> one run per load case at the starting values.

Surrogate: per load case, a Gaussian process of ``log d`` (dissipative mass) and of ``m_p``
(reactive mass) over the design coordinates scaled to [0, 1]: constant mean, squared-
exponential kernel, and the DEM runs' own standard errors (the ensemble scatter across cells
and blocks) as known noise on each run. Kernel amplitude and length scale maximise the
marginal likelihood over a small grid. Its predictive variance is the surrogate's uncertainty
of the DEM's mean at a parameter value: small at a design point with many cells, larger
between points where the response bends. With one run (no DEM parameter) it is that run's
value and standard error.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .observation import Observation
from .parameters import ParameterSpec

#: Smallest dissipative mass used in the log transform (kg): far below any measurable value.
_MIN_DISSIPATIVE_MASS_KG = 1e-12
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
    inverse: np.ndarray  # (K + N)^-1
    constant_variance: float

    def predict(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.u.shape[1] == 0:
            n = u.shape[0]
            return np.full(n, self.mean), np.full(n, self.constant_variance)
        k = self.amplitude * _kernel(u, self.u, self.length)
        mean = self.mean + k @ self.weights
        var = self.amplitude - np.einsum("ij,jk,ik->i", k, self.inverse, k)
        # the constant mean is estimated too (universal kriging): its variance where the
        # runs do not pin the prediction down
        ones = np.ones(self.u.shape[0])
        precision = ones @ self.inverse @ ones
        var = var + (1.0 - k @ (self.inverse @ ones)) ** 2 / precision
        return mean, np.maximum(var, 0.0)


def _fit(u: np.ndarray, y: np.ndarray, se: np.ndarray) -> _Process:
    n, d = u.shape
    noise = np.maximum(se**2, 1e-12 * max(float(np.var(y)), 1e-30))
    if d == 0 or n == 1:
        w = 1.0 / noise
        mean = float(np.sum(w * y) / np.sum(w))
        return _Process(u, mean, 0.0, 1.0, np.zeros(n), np.zeros((n, n)),
                        float(1.0 / np.sum(w)))
    scale = max(float(np.var(y)), float(np.mean(noise)), 1e-30)
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
            inv = np.linalg.inv(cov)
            ones = np.ones(n)
            mean = float(ones @ inv @ y / (ones @ inv @ ones))
            r = y - mean
            logml = -0.5 * r @ inv @ r - np.sum(np.log(np.diag(chol)))
            if best is None or logml > best[0]:
                best = (logml, amplitude, length, mean, inv, nugget)
    _, amplitude, length, mean, inv, nugget = best
    # the nugget is scatter of the runs, not of the DEM's mean: it widens the fit (through
    # the inverse) but is not added to the predictive variance of the mean
    return _Process(u, mean, amplitude, length, inv @ (y - mean), inv, 0.0)


@dataclass(frozen=True)
class CaseSurrogate:
    """Surrogate of one load case's observation over the DEM parameters."""

    frequency_hz: float
    acceleration_g: float
    fill_percent: float
    coupon_mass_kg: float
    low: np.ndarray
    high: np.ndarray
    log_dissipative: _Process
    reactive: _Process

    def predict(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                  np.ndarray]:
        """(d, var d, m_p, var m_p) at DEM parameter values ``theta`` (N, n_dem), kg / kg^2."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        if theta.shape[1] == 0:
            u = np.zeros((theta.shape[0], 0))
        else:
            u = (theta - self.low) / (self.high - self.low)
        log_d, var_log_d = self.log_dissipative.predict(u)
        m_p, var_m = self.reactive.predict(u)
        d = np.exp(log_d)
        return d, d**2 * var_log_d, m_p, var_m


def build_surrogate(observations: Sequence[Observation], theta: np.ndarray,
                    specs: Sequence[ParameterSpec]) -> CaseSurrogate:
    """Surrogate of one load case from its runs at design points ``theta`` (n, n_dem)."""
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    n, d = theta.shape
    low = np.array([s.low for s in specs]) if d else np.zeros(0)
    high = np.array([s.high for s in specs]) if d else np.ones(0)
    u = (theta - low) / (high - low) if d else np.zeros((n, 0))
    dm = np.array([max(o.dissipative_mass_kg, _MIN_DISSIPATIVE_MASS_KG) for o in observations])
    dm_se = np.array([o.dissipative_mass_stderr_kg for o in observations])
    mp = np.array([o.reactive_mass_kg for o in observations])
    mp_se = np.array([o.reactive_mass_stderr_kg for o in observations])
    first = observations[0]
    return CaseSurrogate(
        frequency_hz=first.frequency_hz, acceleration_g=first.acceleration_g,
        fill_percent=first.fill_percent, coupon_mass_kg=first.coupon_mass_kg,
        low=low, high=high, log_dissipative=_fit(u, np.log(dm), dm_se / dm),
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
