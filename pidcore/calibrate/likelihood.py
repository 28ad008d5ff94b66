"""Density of a measured SDC about the model's: measurement error plus normal model terms.

A measured SDC's standard error ``s`` is estimated from few blocks (8 blocks: 7 degrees of
freedom, ``sdc_stderr_dof``). Its true standard deviation sigma_m is unknown: given s and nu
degrees of freedom, nu s^2 / sigma_m^2 is chi^2 with nu, and with the usual scale-invariant
prior on sigma_m the measurement error e is s t_nu (Student's t). The model's own terms
(surrogate variance, discrepancy, floor: variance ``o^2``) are normal, so the residual
r = y - SDC(theta) has the density::

    p(r) = integral N(r; 0, o^2 + nu s^2 / u) chi^2_nu(u) du

(s t_nu for o = 0, the normal N(0, s^2 + o^2) for nu -> infinity): the density of exactly what
:func:`pidcore.calibrate.posterior.predictive` draws. It has no closed form for o > 0; the
integral is a trapezoid rule in w = log u (the integrand is smooth and decays on both sides,
so the rule converges geometrically), tabulated once per nu over log(s^2 / o^2) and the
standardised residual and interpolated bilinearly, after the closed form of its two regimes
(normal bulk, t tail) is taken out. Where the
degrees of freedom are unknown (NaN), infinite or above NORMAL_ABOVE_DOF, or the point has no
standard error, the density is the normal one, computed as it always was.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.special import gammaln, logsumexp

#: Degrees of freedom above which the measurement error is taken as normal: t_100's 97.5 %
#: quantile is 1.984 against 1.960, and the tabulated quadrature needs ever finer steps (chi^2_nu
#: / nu narrows as 1/sqrt(nu): 270 nodes at 100, 4 s to tabulate at a load of 10).
NORMAL_ABOVE_DOF = 100.0
#: Share s / sqrt(s^2 + o^2) of the measurement in the total standard deviation below which the
#: error is taken as normal: the t tail then exceeds the normal's only beyond ~11 total standard
#: deviations (nu = 7), a residual no posterior with mass there has.
MIN_MEASUREMENT_SHARE = 1e-3
#: Largest standardised residual |r| / sqrt(s^2 + o^2) tabulated; beyond it the density is its
#: t tail (:func:`_two_regimes`) times the tabulated correction at the last node.
MAX_TABULATED_RESIDUAL = 100.0
#: Above this variance ratio s^2 / o^2 the model's normal part is left out (its standard
#: deviation is 1e-3 of the measurement's: the log density moves by < 1e-6).
MAX_VARIANCE_RATIO = 1e6
#: Table nodes: the log variance ratio log(s^2 / o^2) (fine where the t tail's weight, as
#: share^nu, changes and where the normal part vanishes), and asinh of the standardised
#: residual. Interpolation error of the log density < 0.01 wherever it is above -20 (3.3e-3 at
#: 7 degrees of freedom, 8e-3 at 14-30; against the quadrature over 3000 random points, and
#: tests/test_calibrate_likelihood.py against scipy).
_SHARE_NODES = 241
_RESIDUAL_NODES = 801


def _quadrature(dof: float) -> tuple[np.ndarray, np.ndarray]:
    """(u nodes, log weights) of the trapezoid rule in w = log u for u ~ chi^2_dof."""
    # chi^2_nu's density in w has width ~sqrt(2 / nu): steps of at most 0.7 of it (0.5 for
    # small nu) keep the rule's error < 1e-6; the upper end is beyond the chi^2's far tail,
    # the lower end the u at which the integrand of the largest tabulated residual at the
    # smallest tabulated share peaks (u = nu share^2 / z^2), less 2
    step = min(0.5, 0.7 * math.sqrt(2.0 / dof))
    w_high = math.log(dof + 12.0 * math.sqrt(2.0 * dof) + 40.0)
    # (less 30 / nu more for small nu, whose integrand falls slowly, as u^(nu/2), below it)
    w_low = (math.log(dof) + 2.0 * math.log(MIN_MEASUREMENT_SHARE / MAX_TABULATED_RESIDUAL)
             - 2.0 - 30.0 / dof)
    w = np.arange(w_high, w_low - step, -step)
    u = np.exp(w)
    log_weight = (0.5 * dof * w - 0.5 * u - 0.5 * dof * math.log(2.0) - gammaln(0.5 * dof)
                  + math.log(step))
    return u, log_weight


def standardised_log_density_exact(z: np.ndarray, share: float, dof: float) -> np.ndarray:
    """log density at ``z`` of Y = share T + sqrt(1 - share^2) Z, T Student's t with ``dof``
    and Z standard normal: a residual over sqrt(s^2 + o^2), share = s / sqrt(s^2 + o^2). The
    quadrature itself, without the table."""
    u, log_weight = _quadrature(dof)
    variance = (1.0 - share**2) + share**2 * dof / u
    z = np.asarray(z, dtype=float)
    terms = log_weight[:, None] - 0.5 * (z.ravel()[None, :] ** 2 / variance[:, None]
                                         + np.log(2 * math.pi * variance[:, None]))
    return logsumexp(terms, axis=0).reshape(z.shape)


@functools.lru_cache(maxsize=16)
def _table(dof: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(log variance ratio nodes, asinh residual nodes, table of the log density less
    :func:`_two_regimes`) for ``dof``."""
    smallest = MIN_MEASUREMENT_SHARE**2 / (1 - MIN_MEASUREMENT_SHARE**2)
    log_ratio = np.linspace(math.log(smallest), math.log(MAX_VARIANCE_RATIO), _SHARE_NODES)
    asinh_z = np.linspace(0.0, math.asinh(MAX_TABULATED_RESIDUAL), _RESIDUAL_NODES)
    z = np.sinh(asinh_z)
    table = np.empty((_SHARE_NODES, _RESIDUAL_NODES))
    for row, ratio in enumerate(np.exp(log_ratio)):
        share = math.sqrt(ratio / (1.0 + ratio))
        table[row] = (standardised_log_density_exact(z, share, dof)
                      - _two_regimes(z, np.full_like(z, share), dof))
    table.setflags(write=False)
    return log_ratio, asinh_z, table


def _t_const(dof: float) -> float:
    """log of Student's t density's constant, Gamma((nu+1)/2) / (Gamma(nu/2) sqrt(nu pi))."""
    return float(gammaln(0.5 * (dof + 1)) - gammaln(0.5 * dof) - 0.5 * math.log(dof * math.pi))


def _two_regimes(z: np.ndarray, share: np.ndarray, dof: float) -> np.ndarray:
    """log of N(z; 0, 1) + share^dof t_dof(z): the density's two regimes, the normal bulk and
    the measurement's t tail (share t_dof's density at |z| >> 1 is share^dof t_dof(z)), whose
    crossing is a kink that bilinear interpolation of the density itself missed by ~0.02; the
    table holds the smooth rest."""
    tail = dof * np.log(share) + _t_const(dof) - 0.5 * (dof + 1) * np.log1p(z**2 / dof)
    return np.logaddexp(-0.5 * z**2 - 0.5 * math.log(2 * math.pi), tail)


def _interpolated(residual: np.ndarray, variance: np.ndarray, stderr: float,
                  dof: float) -> np.ndarray:
    """The log density where the measurement's share is tabulated: bilinear interpolation of
    the table in (log variance ratio, asinh z) plus :func:`_two_regimes`. Written for numpy's
    vectorised logarithms, each computed once (a first version took 0.2 s for the 923 521
    nodes of a 4-quantity grid pass, 30 x the normal density; a scalar Numba loop as long)."""
    log_ratio, asinh_z, table = _table(dof)
    n_share, n_residual = table.shape
    log_stderr = math.log(stderr)
    log_variance = np.log(variance)
    log_share = np.minimum(log_stderr - 0.5 * log_variance, 0.0)
    z2 = residual * residual / variance
    # log(s^2 / o^2), o^2 = v - s^2; o = 0 (no model terms) clips to the last node
    with np.errstate(divide="ignore", invalid="ignore"):
        q = 2 * log_stderr - np.log(np.maximum(variance - stderr * stderr, 0.0))
    fq = np.clip((q - log_ratio[0]) / (log_ratio[1] - log_ratio[0]), 0.0, n_share - 1.0)
    fx = np.minimum(np.arcsinh(np.sqrt(z2)) / (asinh_z[1] - asinh_z[0]), n_residual - 1.0)
    i = np.minimum(fq.astype(np.intp), n_share - 2)
    j = np.minimum(fx.astype(np.intp), n_residual - 2)
    a = fq - i
    b = fx - j
    flat = table.ravel()
    corner = i * n_residual + j
    # beyond the table the rest is held at its last value: both regimes are exact there
    rest = ((1 - a) * ((1 - b) * flat[corner] + b * flat[corner + 1])
            + a * ((1 - b) * flat[corner + n_residual] + b * flat[corner + n_residual + 1]))
    bulk = -0.5 * z2 - 0.5 * math.log(2 * math.pi)
    tail = dof * log_share + _t_const(dof) - 0.5 * (dof + 1) * np.log1p(z2 / dof)
    regimes = np.maximum(bulk, tail) + np.log1p(np.exp(-np.abs(bulk - tail)))
    return rest + regimes - 0.5 * log_variance


def uses_student_t(stderr: float, dof: float) -> bool:
    """Whether a point's measurement error is taken as Student's t (else normal)."""
    return stderr > 0 and math.isfinite(dof) and 0 < dof <= NORMAL_ABOVE_DOF


def log_density(residual: np.ndarray, variance: np.ndarray, *, stderr: float,
                dof: float) -> np.ndarray:
    """log p(residual) of a measured SDC about a predicted one.

    ``variance``: the total variance, stderr^2 plus the model's normal terms (surrogate,
    discrepancy, floor), per sample; ``stderr``, ``dof``: the measurement's standard error and
    its degrees of freedom (NaN: unknown). Normal N(0, variance) where :func:`uses_student_t`
    says no; else the measurement's part is stderr * t_dof (module docstring).
    """
    residual = np.asarray(residual, dtype=float)
    variance = np.asarray(variance, dtype=float)
    if not uses_student_t(stderr, dof):
        return -0.5 * (residual ** 2 / variance + np.log(2 * math.pi * variance))
    # a non-finite prediction (outside a surrogate's reach) stays NaN, as the normal's does,
    # and the posterior drops it; it must not index the table
    finite = np.isfinite(residual) & np.isfinite(variance) & (variance > 0)
    safe_residual = np.where(finite, residual, 0.0)
    safe_variance = np.where(finite, variance, 1.0)
    value = _interpolated(safe_residual, safe_variance, float(stderr), float(dof))
    # a measurement whose share of the total standard deviation is below
    # MIN_MEASUREMENT_SHARE: normal
    small = stderr * stderr < MIN_MEASUREMENT_SHARE**2 * safe_variance
    if np.any(small):
        value = np.where(small, -0.5 * (residual ** 2 / safe_variance
                                        + np.log(2 * math.pi * safe_variance)), value)
    return np.where(finite, value, np.nan)
