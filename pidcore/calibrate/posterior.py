"""Likelihood and posterior of the calibration parameters.

Each measured SDC y_i lies about the predicted SDC s_i(theta) (observation model through the
DEM surrogate) with variance::

    sigma_i^2 = sdc_stderr_i^2 + var_DEM_i(theta) + (tau s_i)^2 + floor^2

measurement standard error, the DEM surrogate's own variance (ensemble scatter), and the model
discrepancy: relative ``model_discrepancy`` tau (fitted, log-uniform prior, unless fixed) plus
an absolute floor (default DISCREPANCY_FLOOR). The model's terms are normal; the measurement's
error is normal where its standard error's degrees of freedom are unknown, else sdc_stderr_i
times Student's t with ``sdc_stderr_dof`` (:mod:`pidcore.calibrate.likelihood`: the standard
error of a mean of 8 blocks is itself estimated from 7 degrees of freedom). The posterior is
computed on an exact grid for at most GRID_MAX_DIMENSIONS fitted quantities (coarse pass, then
fine passes zooming into the region holding the mass until it is resolved), else (or where the
grid cannot box it) sampled with emcee. Either way the result is a set of equally weighted samples.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..compare.plausibility import lowest_kept_sdc
from ..errors import ParameterError
from .data import MeasuredPoint
from .likelihood import log_density
from .parameters import DISCREPANCY, ParameterSpec
from .surrogate import CaseSurrogate, predicted_sdc, unique_points

GRID_MAX_DIMENSIONS = 4
#: Grid points per dimension (coarse pass, fine pass) by number of dimensions. Four
#: quantities had 21 in the fine pass: each cell is sampled uniformly, and the steep lower
#: tails of a posterior spanning most of the box came out up to half a cell too low (the
#: calibration audit's quadrature; tests/test_calibrate_grid_tails.py). 31 costs ~2 x the
#: paper calibration's time (5 s to 10 s from cached runs) and ~0.7 GB.
GRID_SIZES = {1: (201, 401), 2: (61, 101), 3: (25, 41), 4: (13, 31)}
#: Absolute model-error floor on the SDC [-]: below it the measurement itself (a 1 g SDC of
#: 0.01 next to one of 0.10 at 50 Hz) is not reproducible by any smooth model.
DISCREPANCY_FLOOR = 0.01
#: Fine passes of the grid posterior at most (:func:`sample_grid`); a further pass zooms into
#: the box of the nodes within GRID_ZOOM_DROP of the highest log density (plus one cell;
#: e^-12.5: the mass left outside is < 1e-4 in 4 dimensions) while that box is under
#: GRID_ZOOM_SHARE of the last one in some dimension.
GRID_MAX_PASSES = 8
GRID_ZOOM_DROP = 12.5
GRID_ZOOM_SHARE = 0.7
#: A box whose face (not a prior bound) has a node within GRID_FACE_DROP of the highest log
#: density cuts the posterior off (e^-8: 4 sd of a normal): the next pass widens it there.
GRID_FACE_DROP = 8.0
N_SAMPLES = 4000


@dataclass(frozen=True)
class Model:
    """Everything the likelihood needs: specs, surrogates and measurements (same order)."""

    specs: tuple[ParameterSpec, ...]
    surrogates: tuple[CaseSurrogate, ...]
    points: tuple[MeasuredPoint, ...]
    fixed: dict
    discrepancy_floor: float = DISCREPANCY_FLOOR

    def _column(self, samples: np.ndarray, name: str) -> np.ndarray:
        names = [s.name for s in self.specs]
        if name in names:
            return samples[:, names.index(name)]
        return np.full(samples.shape[0], float(self.fixed[name]))

    def dem_theta(self, samples: np.ndarray) -> np.ndarray:
        cols = [i for i, s in enumerate(self.specs) if s.kind == "dem"]
        return samples[:, cols]

    def predict(self, samples: np.ndarray, index: int, *,
                unique=None) -> tuple[np.ndarray, np.ndarray]:
        """(predicted SDC, total predictive variance) of load case ``index`` per sample."""
        samples = np.atleast_2d(samples)
        sdc, var_dem = predicted_sdc(self.surrogates[index], self.dem_theta(samples),
                                     self._column(samples, "fixture_mass_kg"),
                                     self._column(samples, "baseline_loss_factor"),
                                     unique=unique)
        tau = self._column(samples, DISCREPANCY)
        variance = (self.points[index].sdc_stderr ** 2 + var_dem + (tau * sdc) ** 2
                    + self.discrepancy_floor ** 2)
        return sdc, variance

    def log_likelihood(self, samples: np.ndarray, indices: Sequence[int]) -> np.ndarray:
        total = np.zeros(np.atleast_2d(samples).shape[0])
        unique = unique_points(self.dem_theta(np.atleast_2d(samples)))
        for i in indices:
            sdc, variance = self.predict(samples, i, unique=unique)
            point = self.points[i]
            total += log_density(point.sdc - sdc, variance, stderr=point.sdc_stderr,
                                 dof=point.sdc_stderr_dof)
        return total

    def log_prior(self, samples: np.ndarray) -> np.ndarray:
        samples = np.atleast_2d(samples)
        total = np.zeros(samples.shape[0])
        for j, spec in enumerate(self.specs):
            total += spec.log_prior(samples[:, j])
        return total

    def log_posterior(self, samples: np.ndarray, indices: Sequence[int]) -> np.ndarray:
        prior = self.log_prior(samples)
        out = np.full(prior.shape, -np.inf)
        ok = np.isfinite(prior)
        if ok.any():
            out[ok] = prior[ok] + self.log_likelihood(np.atleast_2d(samples)[ok], indices)
        return np.where(np.isfinite(out), out, -np.inf)


class GridUnresolved(ParameterError):
    """The grid posterior could not find a box that resolves the posterior; ``reason`` says
    why (the message adds what to do)."""

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__(f"calibration: {reason}; use method=emcee")


def _to_unit(spec: ParameterSpec, x: np.ndarray) -> np.ndarray:
    if spec.prior == "log-uniform":
        return (np.log(x) - math.log(spec.low)) / (math.log(spec.high) - math.log(spec.low))
    return (x - spec.low) / (spec.high - spec.low)


def _from_unit(spec: ParameterSpec, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(value, dvalue/du) of grid coordinate u in [0, 1]: linear, or log for log-uniform."""
    if spec.prior == "log-uniform":
        span = math.log(spec.high) - math.log(spec.low)
        x = spec.low * np.exp(u * span)
        return x, x * span
    return spec.low + u * (spec.high - spec.low), np.full_like(u, spec.high - spec.low)


def _grid_pass(model: Model, indices, lo: np.ndarray, hi: np.ndarray, n: int):
    axes = [np.linspace(lo[j], hi[j], n) for j in range(len(lo))]
    mesh = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(lo))
    values = np.empty_like(mesh)
    log_jac = np.zeros(mesh.shape[0])
    for j, spec in enumerate(model.specs):
        values[:, j], jac = _from_unit(spec, mesh[:, j])
        log_jac += np.log(jac)
    logp = model.log_posterior(values, indices) + log_jac
    return mesh, values, logp, (hi - lo) / (n - 1)


def sample_grid(model: Model, indices: Sequence[int], *, rng: np.random.Generator,
                n_samples: int = N_SAMPLES) -> np.ndarray:
    """Equally weighted posterior samples from an exact grid (<= GRID_MAX_DIMENSIONS)."""
    k = len(model.specs)
    coarse, fine = GRID_SIZES[k]
    mesh, _, logp, _ = _grid_pass(model, indices, np.zeros(k), np.ones(k), coarse)
    if not np.isfinite(logp).any():
        raise ParameterError("calibration: the posterior is zero everywhere within the bounds")
    keep = logp > logp.max() - 20.0  # e^-20: negligible mass outside
    step = 1.0 / (coarse - 1)
    lo = np.clip(mesh[keep].min(axis=0) - step, 0.0, 1.0)
    hi = np.clip(mesh[keep].max(axis=0) + step, 0.0, 1.0)
    # fine passes: each on the box where the last one found the mass (the nodes within
    # GRID_ZOOM_DROP of the highest, plus a cell), widened where the mass reaches a face of
    # the box that is no prior bound (the box cut the posterior off), until the posterior
    # spans most of the box in every dimension. One pass on the coarse pass's box resolved
    # a posterior narrower than a coarse step by a handful of nodes: its sd off by 0.5x to
    # 5x, its mean by 0.5 sd (3-4 fitted quantities, precise data)
    for attempt in range(GRID_MAX_PASSES):
        mesh, _, logp, cell = _grid_pass(model, indices, lo, hi, fine)
        keep = logp > logp.max() - GRID_ZOOM_DROP
        k_lo, k_hi = mesh[keep].min(axis=0), mesh[keep].max(axis=0)
        high = mesh[logp > logp.max() - GRID_FACE_DROP]
        width = hi - lo
        grow_lo = (high.min(axis=0) < lo + 0.5 * cell) & (lo > 0.0)
        grow_hi = (high.max(axis=0) > hi - 0.5 * cell) & (hi < 1.0)
        new_lo = np.where(grow_lo, np.maximum(lo - 0.5 * width, 0.0),
                          np.maximum(k_lo - cell, lo))
        new_hi = np.where(grow_hi, np.minimum(hi + 0.5 * width, 1.0),
                          np.minimum(k_hi + cell, hi))
        if not (grow_lo.any() or grow_hi.any()) \
                and np.all(new_hi - new_lo >= GRID_ZOOM_SHARE * width):
            break
        if attempt == GRID_MAX_PASSES - 1:
            raise GridUnresolved(
                f"the grid posterior did not settle in {GRID_MAX_PASSES} passes (a posterior "
                "much narrower than the prior, or several modes)")
        lo, hi = new_lo, new_hi
    # each node stands for its cell [u - cell/2, u + cell/2] cut to [lo, hi]: a node on an
    # edge (a prior bound) holds half a cell per dimension, and its samples are drawn inside
    # that half only (a full weight clipped to the bound put a point mass there: in 4
    # dimensions 10-20 % of the samples of a posterior against a bound sat on the bound)
    cell_lo = np.maximum(mesh - 0.5 * cell, lo)
    cell_hi = np.minimum(mesh + 0.5 * cell, hi)
    volume = np.prod((cell_hi - cell_lo) / cell, axis=1)
    weights = np.exp(logp - logp.max()) * volume
    weights /= weights.sum()
    pick = rng.choice(len(weights), size=n_samples, p=weights)
    u = cell_lo[pick] + rng.random((n_samples, k)) * (cell_hi[pick] - cell_lo[pick])
    out = np.empty_like(u)
    for j, spec in enumerate(model.specs):
        out[:, j] = _from_unit(spec, u[:, j])[0]
    return out


#: emcee's own convergence rule (its documentation, "Autocorrelation analysis"): the chain
#: after burn-in at least EMCEE_TAU_LENGTHS integrated autocorrelation times long, else the
#: estimate of the autocorrelation time itself, and the effective sample size from it, cannot
#: be trusted. The burn-in is at least EMCEE_BURN_TAUS of them. The chain is extended in
#: blocks of the first run's length up to EMCEE_MAX_STEPS; a mean acceptance below
#: EMCEE_MIN_ACCEPTANCE means stuck walkers whatever the chain length.
EMCEE_TAU_LENGTHS = 50
EMCEE_BURN_TAUS = 5
EMCEE_MAX_STEPS = 20000
EMCEE_MIN_ACCEPTANCE = 0.1


@dataclass(frozen=True)
class SamplerDiagnostics:
    """How far to trust a set of emcee samples: mean ``acceptance`` fraction of the walkers,
    integrated autocorrelation time ``autocorrelation_steps`` per parameter (steps), the
    ``steps`` run and ``discarded`` as burn-in, ``walkers``, the ``effective_size`` of the
    kept chain (walkers x kept steps / the longest autocorrelation time), ``converged``
    (emcee's rule, see EMCEE_TAU_LENGTHS) and, where not, ``reason``."""

    acceptance: float
    autocorrelation_steps: tuple[float, ...]
    steps: int
    discarded: int
    walkers: int
    effective_size: float
    converged: bool
    reason: str | None = None

    def to_dict(self) -> dict:
        return dataclasses.asdict(self) | {
            "autocorrelation_steps": list(self.autocorrelation_steps)}


def _emcee_diagnostics(sampler, burn: int, names: Sequence[str]) -> SamplerDiagnostics:
    steps = sampler.iteration
    # tol=0: an estimate even where the chain is too short for it (then judged below)
    tau = np.asarray(sampler.get_autocorr_time(discard=burn, quiet=True, tol=0), dtype=float)
    tau_max = float(np.max(tau)) if np.all(np.isfinite(tau)) else math.inf
    discarded = max(burn, int(math.ceil(EMCEE_BURN_TAUS * tau_max))) \
        if math.isfinite(tau_max) else burn
    discarded = min(discarded, steps - 1)
    kept = steps - discarded
    walkers = sampler.nwalkers
    acceptance = float(np.mean(sampler.acceptance_fraction))
    effective = walkers * kept / tau_max if tau_max > 0 else 0.0
    reason = None
    if acceptance < EMCEE_MIN_ACCEPTANCE:
        reason = (f"mean acceptance {acceptance:.3f} of the walkers (below "
                  f"{EMCEE_MIN_ACCEPTANCE}: walkers stuck)")
    elif not kept >= EMCEE_TAU_LENGTHS * tau_max:
        slowest = names[int(np.nanargmax(tau))] if np.any(np.isfinite(tau)) else "?"
        reason = (f"chain of {kept} steps after burn-in is {kept / tau_max:.0f} "
                  f"autocorrelation times ({tau_max:.0f} steps, {slowest}), under the "
                  f"{EMCEE_TAU_LENGTHS} emcee requires")
    return SamplerDiagnostics(acceptance, tuple(float(t) for t in tau), steps, discarded,
                              walkers, float(effective), reason is None, reason)


def sample_emcee(model: Model, indices: Sequence[int], *, rng: np.random.Generator,
                 n_samples: int = N_SAMPLES, n_steps: int = 2000, burn: int = 500,
                 max_steps: int | None = None) -> tuple[np.ndarray, SamplerDiagnostics]:
    """Equally weighted posterior samples by emcee (affine-invariant ensemble, vectorised),
    and their :class:`SamplerDiagnostics`.

    The chain runs ``n_steps``, then further blocks of ``n_steps`` while it is shorter than
    emcee's convergence rule asks, up to ``max_steps`` (default EMCEE_MAX_STEPS); a chain that
    still fails it is returned with ``converged=False`` for the caller to flag: 2000 steps
    were taken as enough whatever the posterior (4 fitted quantities: 18 autocorrelation
    times, the effective sample 580 draws behind 4000 samples, and nothing said).
    """
    import emcee

    k = len(model.specs)
    walkers = max(32, 4 * k)
    max_steps = EMCEE_MAX_STEPS if max_steps is None else max_steps

    def log_prob(u: np.ndarray) -> np.ndarray:
        values = np.empty_like(u)
        log_jac = np.zeros(u.shape[0])
        inside = np.all((u >= 0) & (u <= 1), axis=1)
        for j, spec in enumerate(model.specs):
            values[:, j], jac = _from_unit(spec, np.clip(u[:, j], 0, 1))
            log_jac += np.log(jac)
        out = model.log_posterior(values, indices) + log_jac
        return np.where(inside, out, -np.inf)

    start = rng.random((walkers, k))
    sampler = emcee.EnsembleSampler(walkers, k, log_prob, vectorize=True)
    sampler.random_state = np.random.RandomState(int(rng.integers(2**31))).get_state()
    names = [s.name for s in model.specs]
    sampler.run_mcmc(start, n_steps, progress=False)
    diagnostics = _emcee_diagnostics(sampler, burn, names)
    while not diagnostics.converged and sampler.iteration + n_steps <= max_steps \
            and diagnostics.acceptance >= EMCEE_MIN_ACCEPTANCE:
        sampler.run_mcmc(None, n_steps, progress=False)
        diagnostics = _emcee_diagnostics(sampler, burn, names)
    chain = sampler.get_chain(discard=diagnostics.discarded, flat=True)
    pick = rng.choice(len(chain), size=n_samples, replace=len(chain) < n_samples)
    u = chain[pick]
    out = np.empty_like(u)
    for j, spec in enumerate(model.specs):
        out[:, j] = _from_unit(spec, u[:, j])[0]
    return out, diagnostics


class PosteriorSamples(NamedTuple):
    """Result of :func:`sample_posterior`: equally weighted ``samples`` (n_samples, n_specs),
    the ``method`` that drew them (``"grid"`` or ``"emcee"``), where ``auto`` fell back
    from the grid to emcee, ``fallback``: why (else None), and for emcee the sampler's
    ``diagnostics`` (None for the grid: an exact quadrature, whose settling is checked by
    :func:`sample_grid` itself)."""

    samples: np.ndarray
    method: str
    fallback: str | None = None
    diagnostics: SamplerDiagnostics | None = None

    @property
    def converged(self) -> bool:
        return self.diagnostics is None or self.diagnostics.converged

    @property
    def effective_size(self) -> float | None:
        """Effective number of independent draws behind the samples (None: they are)."""
        return None if self.diagnostics is None else self.diagnostics.effective_size


def sample_posterior(model: Model, indices: Sequence[int], *, seed: int = 0,
                     method: str = "auto", n_samples: int = N_SAMPLES) -> PosteriorSamples:
    """Posterior samples given the measured points ``indices``.

    ``method``: ``"grid"`` (at most GRID_MAX_DIMENSIONS fitted quantities), ``"emcee"``, or
    ``"auto"``: the grid where it applies, emcee where there are more quantities or where the
    grid cannot box the posterior (the result's ``fallback`` says why, so that it is shown).
    """
    rng = np.random.default_rng(seed)
    fallback = None
    if method == "auto":
        if len(model.specs) <= GRID_MAX_DIMENSIONS:
            try:
                return PosteriorSamples(sample_grid(model, indices, rng=rng,
                                                    n_samples=n_samples), "grid")
            except GridUnresolved as exc:  # a posterior the grid cannot box: the sampler can
                rng = np.random.default_rng(seed)
                fallback = exc.reason
        method = "emcee"
    if method == "grid":
        if len(model.specs) > GRID_MAX_DIMENSIONS:
            raise ParameterError(f"method=grid: at most {GRID_MAX_DIMENSIONS} fitted "
                                 f"quantities, got {len(model.specs)}")
        return PosteriorSamples(sample_grid(model, indices, rng=rng, n_samples=n_samples),
                                "grid")
    if method == "emcee":
        samples, diagnostics = sample_emcee(model, indices, rng=rng, n_samples=n_samples)
        return PosteriorSamples(samples, "emcee", fallback, diagnostics)
    raise ParameterError(f"method: expected auto, grid or emcee, got {method!r}")


def predictive(model: Model, samples: np.ndarray, index: int, *,
               rng: np.random.Generator) -> dict:
    """Prediction of load case ``index``: ``predicted``, the posterior median of the model's
    SDC (its mean: no measurement error or discrepancy; RMS errors are of it), and ``low95``
    / ``high95``, the posterior-predictive 95 % band of a measurement there (parameters,
    surrogate variance, discrepancy, floor and the point's own ``sdc_stderr``: what a
    measured value is checked against; not cut at 0, since a measurement of a small SDC lies
    below it by its noise, but at :func:`~pidcore.compare.plausibility.lowest_kept_sdc` of
    the point's stderr, below which a measurement is refused: 0 without a stderr);
    ``predicted_low95`` / ``predicted_high95``: the 95 % band of the model's SDC alone (>= 0);
    ``low95_without_stderr`` / ``high95_without_stderr``: the band of a measurement without
    measurement error (all of the above but ``sdc_stderr``; uncut, its bottom below 0 where
    the discrepancy's normal tail reaches there), which :meth:`pidcore.calibrate.prediction.
    CalibratedPrediction.band` widens by another measurement's own stderr.

    Where the point's stderr states its degrees of freedom (``sdc_stderr_dof``, e.g. 7 of an
    8-block analysis), its measurement error is drawn from Student's t with them, scaled by
    the stderr: the standardised error of a mean over few blocks is t, not normal, and a
    normal draw made the measurement's part of the band cover ~91 % at 7 degrees of freedom.
    Without them (NaN) the draws are normal, as they always were. Either way the draws are of
    the error model whose density the likelihood is (:func:`pidcore.calibrate.likelihood.
    log_density`; above its NORMAL_ABOVE_DOF degrees of freedom, normal there): the fit and
    the band it is scored by assume the same errors."""
    sdc, variance = model.predict(samples, index)
    normal = rng.standard_normal(sdc.shape)
    point = model.points[index]
    stderr = point.sdc_stderr
    # the same band without the point's own measurement error (the same normal draws): what
    # a report widens by another measurement's stderr at this load case
    error_free = sdc + normal * np.sqrt(np.maximum(variance - stderr**2, 0.0))
    if stderr > 0 and math.isfinite(point.sdc_stderr_dof):
        draws = error_free + stderr * rng.standard_t(point.sdc_stderr_dof, size=sdc.shape)
    else:  # unknown degrees of freedom: normal (the bundled calibration's draws, unchanged)
        draws = sdc + normal * np.sqrt(variance)
    # the model's SDC is >= 0 as it is (d > 0, eta_0 >= 0), and nothing else is cut at 0: a
    # measurement holds its own error, and one of a small SDC lies below 0 as often as its
    # noise says (-0.057 +- 0.13 of 7 dof was judged outside a band cut to 0 .. 0.46, its
    # draws' -0.25 .. 0.46). The measurement's band is cut only where a measurement is
    # refused, below 0 beyond its noise (lowest_kept_sdc: 0 without a stderr, as before), as
    # its top is at the SDC bound. The band without measurement error is not cut at all: it
    # is what CalibratedPrediction.band widens by another stderr, and its draws' tail below
    # 0 cut off narrowed that band's bottom (the likelihood's errors are not cut either)
    low, high = np.percentile(np.maximum(draws, lowest_kept_sdc(stderr)), [2.5, 97.5])
    low0, high0 = np.percentile(error_free, [2.5, 97.5])
    return {"predicted": float(np.median(sdc)), "low95": float(low), "high95": float(high),
            "predicted_low95": float(np.percentile(sdc, 2.5)),
            "predicted_high95": float(np.percentile(sdc, 97.5)),
            "low95_without_stderr": float(low0), "high95_without_stderr": float(high0)}


#: Batches of the posterior samples whose quantiles' scatter gives the Monte-Carlo standard
#: error of a reported quantile (:func:`summarise`).
MC_BATCHES = 10


def quantile_mc_stderr(x: np.ndarray, q: Sequence[float], batches: int = MC_BATCHES, *,
                       effective_size: float | None = None) -> np.ndarray:
    """Monte-Carlo standard error of the percentiles ``q`` of the samples ``x``: the scatter
    of each percentile over ``batches`` equal batches, / sqrt(batches) (the batch-means
    estimate; the samples are in random order). What a reported bound would move by with
    another set of samples: its digits beyond that are noise.

    ``effective_size``: the independent draws behind samples picked from a Markov chain
    (:attr:`PosteriorSamples.effective_size`). The batches see the picked samples as
    independent, but they repeat the chain's ``effective_size`` draws: the error is then
    sqrt(1 + n / effective_size) times larger (the chain's error plus the picking's)."""
    n = len(x) // batches
    if n < 2:
        return np.full(len(q), np.nan)
    per_batch = np.percentile(np.reshape(x[:n * batches], (batches, n)), q, axis=1)
    error = np.std(per_batch, axis=1, ddof=1) / math.sqrt(batches)
    if effective_size is not None:
        error = error * math.sqrt(1.0 + len(x) / max(effective_size, 1.0))
    return error


def summarise(specs: Sequence[ParameterSpec], samples: np.ndarray, *,
              effective_size: float | None = None) -> tuple[dict, list]:
    """({name: median, low95, high95, mean, sd, and the Monte-Carlo standard errors
    median_mc_se, low95_mc_se, high95_mc_se}, correlation matrix as nested lists).
    ``effective_size``: of a Markov chain's samples (:func:`quantile_mc_stderr`)."""
    out = {}
    for j, spec in enumerate(specs):
        x = samples[:, j]
        low, median, high = np.percentile(x, [2.5, 50, 97.5])
        se_low, se_median, se_high = quantile_mc_stderr(x, [2.5, 50, 97.5],
                                                        effective_size=effective_size)
        out[spec.name] = {"median": float(median), "low95": float(low), "high95": float(high),
                          "mean": float(np.mean(x)), "sd": float(np.std(x)),
                          "median_mc_se": float(se_median), "low95_mc_se": float(se_low),
                          "high95_mc_se": float(se_high),
                          "kind": spec.kind, "prior_low": spec.low, "prior_high": spec.high}
    if samples.shape[1] > 1:
        corr = np.corrcoef(samples.T)
    else:
        corr = np.ones((1, 1))
    return out, np.round(corr, 4).tolist()


def summary_texts(summary: dict) -> tuple[str, str, str]:
    """(median, low95, high95) of one parameter of :func:`summarise` as shown: each to the
    digit its Monte-Carlo standard error leaves (``*_mc_se``; 4 significant digits where the
    summary has none, e.g. a calibration.json written before them)."""
    from ..units import display_with_uncertainty

    return tuple(display_with_uncertainty(summary[k], summary.get(f"{k}_mc_se", math.nan))
                 for k in ("median", "low95", "high95"))


#: Share of the prior range, at each finite bound, that :func:`bound_notes` inspects, and the
#: share of the samples in it above which the posterior is said to pile against the bound: a
#: posterior that ignored the bound would put about EDGE_SHARE of its samples there if flat,
#: and less if peaked inside, so four times that is the data pressing on the bound.
EDGE_SHARE = 0.05
PILED_SHARE = 0.2
#: The same share, of the samples within a quarter of the posterior's own central 95 %
#: interval from the bound, must be exceeded too: a narrow posterior well inside the edge (a
#: 35 g fixture under the 0-1 kg prior, 95 % 20-54 g) has all its samples in the prior's
#: lowest 5 % and was said to pile against 0. A density highest at the bound puts >= ~24 % of
#: its samples there (flat: 95 % / 4; falling away from the bound: more), one peaked two or
#: more standard deviations inside it <= 16 %.
OWN_WIDTH_SHARE = 0.25


def bound_notes(specs: Sequence[ParameterSpec], samples: np.ndarray, *,
                effective_size: float | None = None) -> list[str]:
    """A note for each parameter whose posterior piles against a finite prior bound.

    Its median is then set by where the prior ends more than by the data (the data favour
    more, or less, than the prior allows; values inside the 95 % interval still fit them):
    a stated value that is off (a fixture mass, a baseline) or a prior that is too narrow.
    The median is still reported; the note says not to trust it.
    """
    notes = []
    for j, spec in enumerate(specs):
        low, high = float(spec.low), float(spec.high)
        if not (math.isfinite(low) and math.isfinite(high) and high > low):
            continue
        x = samples[:, j]
        # median and interval as the summary table shows them (the note said 0.001285 beside
        # the table's 0.00128, digits the Monte-Carlo error does not hold)
        median, low95, high95 = summary_texts(
            summarise([spec], x[:, None], effective_size=effective_size)[0][spec.name])
        u = _to_unit(spec, x)  # the prior's own scale: log for a log-uniform prior
        q_low, q_high = np.quantile(u, [0.025, 0.975])
        near = OWN_WIDTH_SHARE * float(q_high - q_low)
        for side, bound, share, own in (
                ("lower", low, float(np.mean(u < EDGE_SHARE)), float(np.mean(u <= near))),
                ("upper", high, float(np.mean(u > 1.0 - EDGE_SHARE)),
                 float(np.mean(u >= 1.0 - near)))):
            if share > PILED_SHARE and own > PILED_SHARE:
                notes.append(
                    f"{spec.name}: the posterior piles against its prior's {side} bound "
                    f"{bound:g} ({100 * share:.0f} % of the samples in the "
                    f"{100 * EDGE_SHARE:.0f} % of the prior's range next to it; 95 % "
                    f"{low95} .. {high95}): the data favour values at or beyond it, so its "
                    f"median {median} is set by where the prior ends more than by the data "
                    "(a value inside the 95 % interval still fits them); check the "
                    f"stated values, and widen the prior (priors={spec.name}=LOW:HIGH) unless "
                    "the bound is physical")
    return notes


#: A posterior whose central 95 % interval is at least this share of the prior's own (each
#: on the prior's scale: log for a log-uniform prior) was hardly narrowed by the data: a
#: rolling friction fitted to flying beds (5-10 g), where rolling dissipation only replaces
#: impact dissipation, kept 95 % 0.0024 .. 0.0974 under its 0 .. 0.1 prior (share 1.00) and
#: its median 0.05 was written into the calibrated specimen like a measured value. Fitted
#: parameters the data do constrain narrow to 0.1-0.6 of their prior (fixture mass 0.07,
#: baseline loss factor 0.59 in that calibration).
UNCONSTRAINED_SHARE = 0.8


def _prior_central_width(spec: ParameterSpec) -> float:
    """Width of the prior's central 95 % interval on its unit scale (:func:`_to_unit`)."""
    if spec.prior != "normal":
        return 0.95  # uniform, or uniform in log
    from scipy.stats import truncnorm

    a = (spec.low - spec.prior_mean) / spec.prior_sd
    b = (spec.high - spec.prior_mean) / spec.prior_sd
    lo, hi = truncnorm.ppf([0.025, 0.975], a, b, loc=spec.prior_mean, scale=spec.prior_sd)
    return float((hi - lo) / (spec.high - spec.low))


def unconstrained_notes(specs: Sequence[ParameterSpec], samples: np.ndarray) -> list[str]:
    """A note for each parameter the data hardly constrain: its posterior's central 95 %
    interval spans at least UNCONSTRAINED_SHARE of the prior's. Its median is then the prior's
    more than the data's, and the calibrated specimen holds it as if the measurements had
    determined it."""
    notes = []
    for j, spec in enumerate(specs):
        low, high = float(spec.low), float(spec.high)
        if not (math.isfinite(low) and math.isfinite(high) and high > low):
            continue
        q_low, q_high = np.quantile(_to_unit(spec, samples[:, j]), [0.025, 0.975])
        share = float(q_high - q_low) / _prior_central_width(spec)
        if share >= UNCONSTRAINED_SHARE:
            # the discrepancy is no specimen field: the note said its median was written to
            # the calibrated specimen, which holds no such key
            consequence = (
                "no specimen value (the calibrated specimen holds none) but it widens every "
                "band; fix it (discrepancy=TAU) where the model's relative error is known"
                if spec.name == DISCREPANCY else
                "no measured value, and so is the value written to the calibrated specimen; "
                "measure load cases where it changes the SDC, or do not fit it")
            notes.append(
                f"{spec.name}: the data hardly constrain it (its 95 % interval spans "
                f"{100 * min(share, 1.0):.0f} % of its prior's, {low:g} .. {high:g}): its "
                f"median is the prior's more than the data's, {consequence}")
    return notes
