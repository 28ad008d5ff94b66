"""Check 2: simulation-based calibration of pidcore's posterior and predictive bands.

Truths drawn from the documented priors (theta, fixture mass, baseline loss factor, tau: the
paper calibration's four quantities), data from the documented noise model (_problem.py),
pidcore's posterior from 11 of 12 cases (the 12th held out as in a leave-one-out fold). A
Bayesian 95 % interval then holds the truth with probability 0.95 exactly, and the held-out
measurement falls in its 95 % predictive band with probability 0.95; the rank of the truth
among the posterior samples is uniform (Talts et al. 2018). Tolerances: 3 binomial standard
deviations; the rank histogram (10 bins) by a chi-square test at p = 0.001.

Run: PYTHONPATH=. python docs/calibration_audit/sbc_coverage.py [grid|emcee] [TRIALS] [all|no-theta]
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).parent))
from _problem import NAMES, Problem, pidcore_model  # noqa: E402


def main(method: str = "grid", trials: int = 300, fit: str = "all") -> int:
    """``fit``: "all" (theta, fixture, baseline, tau) or "no-theta" (theta fixed at its true
    value; 3 quantities: a cheaper emcee run)."""
    from pidcore.calibrate.posterior import predictive, sample_posterior

    rng = np.random.default_rng(20261130)
    covered, band_hits, ranks = [], [], []
    negative = 0
    for _ in range(trials):
        problem = Problem(n_cases=12, seed=int(rng.integers(2**31)))
        truth = problem.draw_truth(rng)
        y = problem.draw_data(truth, rng)
        if fit == "no-theta":
            model = pidcore_model(problem, y, fit=NAMES[1:], fixed={"theta": truth[0]})
        else:
            model = pidcore_model(problem, y)
        fitted = list(range(11))
        samples = sample_posterior(model, fitted, seed=int(rng.integers(2**31)),
                                   method=method, n_samples=2000).samples
        low, high = np.percentile(samples, [2.5, 97.5], axis=0)
        fitted_truth = truth[1:] if fit == "no-theta" else truth
        covered.append((low <= fitted_truth) & (fitted_truth <= high))
        ranks.append(np.mean(samples < fitted_truth, axis=0))
        band = predictive(model, samples, 11, rng=rng)
        # the band is cut at -3 stderr, below which a measurement is refused (documented);
        # tau up to 2 draws synthetic SDCs below it, which the cut band holds as that
        lowest = -3.0 * float(problem.stderr[11])
        band_hits.append(band["low95"] <= max(y[11], lowest) <= band["high95"])
        negative += y[11] < 0
    covered = np.array(covered)
    tol = 3 * math.sqrt(0.95 * 0.05 / trials)
    failures = 0
    names = NAMES[1:] if fit == "no-theta" else NAMES
    print(f"{method}, fit {', '.join(names)}, {trials} trials; "
          f"tolerance 0.95 +- {tol:.3f} (3 binomial sd)")
    for j, name in enumerate(names):
        rate = covered[:, j].mean()
        hist = np.histogram(np.array(ranks)[:, j], bins=10, range=(0, 1))[0]
        p = stats.chisquare(hist).pvalue
        ok = abs(rate - 0.95) <= tol and p > 1e-3
        failures += not ok
        print(f"  {name:22s} coverage {rate:.3f}  rank chi2 p = {p:.3f}  {'ok' if ok else 'FAIL'}"
              f"  ranks {hist.tolist()}")
    rate = float(np.mean(band_hits))
    ok = abs(rate - 0.95) <= tol
    failures += not ok
    print(f"  held-out 95 % band      coverage {rate:.3f}  {'ok' if ok else 'FAIL'}  "
          f"({negative} held-out SDCs drawn below 0, compared as 0)")
    return int(failures > 0)


if __name__ == "__main__":
    args = sys.argv[1:]
    raise SystemExit(main(args[0] if args else "grid", int(args[1]) if len(args) > 1 else 300,
                          args[2] if len(args) > 2 else "all"))
