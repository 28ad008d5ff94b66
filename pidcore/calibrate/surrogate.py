"""Space-filling design of the DEM parameters and a surrogate per load case.

Design: a Latin hypercube (:class:`scipy.stats.qmc.LatinHypercube`, centred, seeded) over the
DEM parameters' bounds; no DEM parameter -> one run per load case at the uncalibrated values.

Surrogate: per load case, least squares of ``log d`` (dissipative mass) and ``m_p`` (reactive
mass) on a polynomial in the design coordinates (quadratic where the design has room for it,
else linear, else a constant). Its variance at a point is s^2 x leverage, with s^2 the larger
of the residual variance and the DEM runs' own mean squared standard error (the ensemble
scatter across cells and blocks): with one run, exactly that run's standard error.
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
    """Design points for ``n_dem`` DEM parameters: room for a quadratic plus residual dof."""
    if n_dem == 0:
        return 1
    n_terms = (n_dem + 1) * (n_dem + 2) // 2
    return n_terms + 2


def _features(u: np.ndarray, degree: int) -> np.ndarray:
    """Polynomial features of unit coordinates u (N, d) up to ``degree`` (<= 2)."""
    n, d = u.shape
    columns = [np.ones(n)]
    if degree >= 1:
        columns += [u[:, j] for j in range(d)]
    if degree >= 2:
        columns += [u[:, i] * u[:, j] for i, j in itertools.combinations_with_replacement(
            range(d), 2)]
    return np.column_stack(columns)


def _n_terms(d: int, degree: int) -> int:
    return 1 + (d if degree >= 1 else 0) + (d * (d + 1) // 2 if degree >= 2 else 0)


@dataclass(frozen=True)
class _Fit:
    coef: np.ndarray
    cov_unscaled: np.ndarray  # (X^T X)^-1
    variance: float  # s^2

    def predict(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        mean = x @ self.coef
        leverage = np.einsum("ij,jk,ik->i", x, self.cov_unscaled, x)
        return mean, self.variance * leverage


def _fit(x: np.ndarray, y: np.ndarray, se: np.ndarray) -> _Fit:
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    n, p = x.shape
    scatter = float(np.mean(se**2))
    if n > p:
        residual = float(np.sum((y - x @ coef) ** 2) / (n - p))
        variance = max(residual, scatter)
    else:
        variance = scatter
    return _Fit(coef, np.linalg.pinv(x.T @ x), variance)


@dataclass(frozen=True)
class CaseSurrogate:
    """Surrogate of one load case's observation over the DEM parameters."""

    frequency_hz: float
    acceleration_g: float
    fill_percent: float
    coupon_mass_kg: float
    low: np.ndarray
    high: np.ndarray
    degree: int
    log_dissipative: _Fit
    reactive: _Fit

    def predict(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                  np.ndarray]:
        """(d, var d, m_p, var m_p) at DEM parameter values ``theta`` (N, n_dem), kg / kg^2."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        if theta.shape[1] == 0:
            u = np.zeros((theta.shape[0], 0))
        else:
            u = (theta - self.low) / (self.high - self.low)
        x = _features(u, self.degree)
        log_d, var_log_d = self.log_dissipative.predict(x)
        m_p, var_m = self.reactive.predict(x)
        d = np.exp(log_d)
        return d, d**2 * var_log_d, m_p, var_m


def build_surrogate(observations: Sequence[Observation], theta: np.ndarray,
                    specs: Sequence[ParameterSpec]) -> CaseSurrogate:
    """Surrogate of one load case from its runs at design points ``theta`` (n, n_dem)."""
    theta = np.atleast_2d(np.asarray(theta, dtype=float))
    n, d = theta.shape
    degree = 0
    for candidate in (2, 1):
        if d and n >= _n_terms(d, candidate) + 1:
            degree = candidate
            break
    low = np.array([s.low for s in specs]) if d else np.zeros(0)
    high = np.array([s.high for s in specs]) if d else np.ones(0)
    u = (theta - low) / (high - low) if d else np.zeros((n, 0))
    x = _features(u, degree)
    dm = np.array([max(o.dissipative_mass_kg, _MIN_DISSIPATIVE_MASS_KG) for o in observations])
    dm_se = np.array([o.dissipative_mass_stderr_kg for o in observations])
    mp = np.array([o.reactive_mass_kg for o in observations])
    mp_se = np.array([o.reactive_mass_stderr_kg for o in observations])
    first = observations[0]
    return CaseSurrogate(
        frequency_hz=first.frequency_hz, acceleration_g=first.acceleration_g,
        fill_percent=first.fill_percent, coupon_mass_kg=first.coupon_mass_kg,
        low=low, high=high, degree=degree,
        log_dissipative=_fit(x, np.log(dm), dm_se / dm), reactive=_fit(x, mp, mp_se))


def predicted_sdc(surrogate: CaseSurrogate, theta: np.ndarray, fixture_mass_kg: np.ndarray,
                  baseline_loss_factor: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(SDC, its variance from the DEM surrogate) for N parameter sets (observation model)."""
    d, var_d, m_p, var_m = surrogate.predict(theta)
    structure = surrogate.coupon_mass_kg + np.asarray(fixture_mass_kg, dtype=float)
    denominator = m_p + structure
    sdc = 2 * math.pi * (d + baseline_loss_factor * structure) / denominator
    var = (2 * math.pi / denominator) ** 2 * var_d + (sdc / denominator) ** 2 * var_m
    return sdc, var
