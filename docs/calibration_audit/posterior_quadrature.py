"""Check 1: pidcore's posterior (grid and emcee) and its predictive band against an
independent 4-D quadrature of the documented likelihood and priors.

Problem: _problem.Problem (12 load cases, closed-form nonlinear response), fitting
theta (DEM, uniform), fixture mass (uniform 0..1 kg), baseline loss factor (uniform 0..0.05)
and the model discrepancy tau (log-uniform 0.02..2), the paper calibration's four quantities.

Independent computation: midpoint quadrature on (theta, m_f, eta, log tau) (log tau uniform is
the log-uniform prior, so no Jacobian is needed), coarse pass over the prior box then a fine
pass over the box holding all nodes within e^-25 of the peak; marginal quantiles from the
cumulative sum (linear inside a cell); posterior-predictive quantiles of a held-out case by
solving sum_j w_j Phi((q - s_j) / sigma_j) = p (a measured SDC cut at -3 sdc_stderr, below
which a measurement is refused, as documented).

Run: PYTHONPATH=. python docs/calibration_audit/posterior_quadrature.py
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
from scipy import optimize, special

sys.path.insert(0, str(Path(__file__).parent))
from _problem import NAMES, PRIOR, Problem, pidcore_model  # noqa: E402

Q = (2.5, 50.0, 97.5)


def _axes(lo, hi, n):
    step = (hi - lo) / n
    return lo + step * (np.arange(n) + 0.5), step


def quadrature(problem, y, cases, n_coarse=24, n_fine=48):
    """(nodes (N, 4) in natural units, weights, cell steps, box lo, hi) in (theta, m_f, eta,
    log tau) coordinates."""
    lo = np.array([PRIOR[n][0] for n in NAMES[:3]] + [math.log(PRIOR[NAMES[3]][0])])
    hi = np.array([PRIOR[n][1] for n in NAMES[:3]] + [math.log(PRIOR[NAMES[3]][1])])
    for n, zoom in ((n_coarse, True), (n_fine, True), (n_fine, False)):
        axes = [_axes(lo[j], hi[j], n) for j in range(4)]
        mesh = np.stack(np.meshgrid(*[a[0] for a in axes], indexing="ij"), -1).reshape(-1, 4)
        x = mesh.copy()
        x[:, 3] = np.exp(mesh[:, 3])
        logp = np.concatenate([problem.log_likelihood(x[k:k + 200_000], y, cases)
                               for k in range(0, len(x), 200_000)])
        step = np.array([a[1] for a in axes])
        if not zoom:
            break
        keep = mesh[logp > logp.max() - 25.0]
        prior_lo = np.array([PRIOR[n][0] for n in NAMES[:3]] + [math.log(PRIOR[NAMES[3]][0])])
        prior_hi = np.array([PRIOR[n][1] for n in NAMES[:3]] + [math.log(PRIOR[NAMES[3]][1])])
        lo = np.maximum(keep.min(0) - step, prior_lo)
        hi = np.minimum(keep.max(0) + step, prior_hi)
    w = np.exp(logp - logp.max())
    return x, mesh, w / w.sum(), step, lo, hi


def marginal_quantiles(mesh, w, step, lo, j, q, log=False):
    n = int(round((mesh[:, j].max() - mesh[:, j].min()) / step[j])) + 1
    idx = np.rint((mesh[:, j] - lo[j]) / step[j] - 0.5).astype(int)
    mass = np.bincount(idx, w, minlength=n)
    edges = lo[j] + step[j] * np.arange(n + 1)
    cdf = np.concatenate([[0.0], np.cumsum(mass)])
    out = np.interp(np.asarray(q) / 100.0, cdf, edges)
    return np.exp(out) if log else out


def predictive_quantiles(problem, x, w, case, q=(2.5, 97.5)):
    keep = w > 1e-12 * w.max()
    x, w = x[keep], w[keep] / w[keep].sum()
    s, var_dem = problem.sdc(x[:, 0], x[:, 1], x[:, 2])
    s, var_dem = s[case], var_dem[case]
    sd = np.sqrt(problem.variance(s[None], var_dem[None], x[:, 3], np.array([case]))[0])

    def cdf(v):
        return float(np.sum(w * special.ndtr((v - s) / sd)))

    lowest = -3.0 * float(problem.stderr[case])  # a measurement below it is refused
    out = []
    for p in np.asarray(q) / 100.0:
        out.append(lowest if cdf(lowest) >= p else optimize.brentq(
            lambda v, p=p: cdf(v) - p, lowest, 10.0))
    return out, float(np.sum(w * s))


def main() -> int:
    from pidcore.calibrate.posterior import predictive, sample_posterior, summarise

    problem = Problem(n_cases=12, seed=3)
    truth = np.array([0.35, 0.25, 0.015, 0.15])
    y = problem.draw_data(truth, np.random.default_rng(11))
    held_out = 4
    cases = [i for i in range(problem.n) if i != held_out]
    x, mesh, w, step, lo, hi = quadrature(problem, y, cases)
    exact = np.array([marginal_quantiles(mesh, w, step, lo, j, Q, log=(j == 3))
                      for j in range(4)])
    band, _ = predictive_quantiles(problem, x, w, held_out)
    model = pidcore_model(problem, y)
    # the documented likelihood: pidcore's equals ours (an additive constant allowed)
    probe = np.column_stack([np.random.default_rng(1).uniform(PRIOR[n][0], PRIOR[n][1], 500)
                             for n in NAMES])
    diff = model.log_likelihood(probe, cases) - problem.log_likelihood(probe, y, cases)
    print(f"likelihood: pidcore - independent spread {np.ptp(diff):.2e} (0 = same model)")
    prior_diff = model.log_prior(probe) - (-np.log(probe[:, 3]))
    print(f"prior: pidcore - independent spread {np.ptp(prior_diff):.2e}")
    failures = int(np.ptp(diff) > 1e-8) + int(np.ptp(prior_diff) > 1e-10)
    for method in ("grid", "emcee"):
        drawn = sample_posterior(model, cases, seed=5, method=method)
        summary, _ = summarise(model.specs, drawn.samples)
        pred = predictive(model, drawn.samples, held_out, rng=np.random.default_rng(2))
        print(f"\n{method} (method used: {drawn.method}; "
              f"{drawn.diagnostics.to_dict() if drawn.diagnostics else 'exact grid'})")
        for j, name in enumerate(NAMES):
            s = summary[name]
            got = np.array([s["low95"], s["median"], s["high95"]])
            se = np.array([s["low95_mc_se"], s["median_mc_se"], s["high95_mc_se"]])
            # 4 Monte-Carlo standard errors (pidcore's own, which for emcee count the chain's
            # effective draws) plus 1 % of the interval for the quadrature's resolution
            tol = 4 * se + 0.01 * (exact[j, 2] - exact[j, 0])
            ok = np.all(np.abs(got - exact[j]) <= tol)
            failures += not ok
            print(f"  {name:22s} pidcore {got.round(5)} exact {exact[j].round(5)} "
                  f"off {np.max(np.abs(got - exact[j]) / tol):.2f} x tolerance "
                  f"{'ok' if ok else 'MISMATCH'}")
        width = band[1] - band[0]
        got = np.array([pred["low95"], pred["high95"]])
        ok = np.all(np.abs(got - band) < 0.04 * width)  # 2.5 % tails of 4000 draws: ~2 %
        failures += not ok
        print(f"  held-out band           pidcore {got.round(4)} exact {np.round(band, 4)} "
              f"{'ok' if ok else 'MISMATCH'}")
    print(f"\n{failures} failure(s)")
    return int(failures > 0)


if __name__ == "__main__":
    raise SystemExit(main())
