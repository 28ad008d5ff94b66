"""Study: SDC at 1 g and 5 g, 50 % fill, against static friction and rolling resistance.

Runs the paper's coupon (acrylic, z drive) through :func:`pidcore.dem.simulate_load_case` with
the static friction mu_s (both pairs) or the rolling friction mu_r (both pairs) changed in the
specimen, and writes ``docs/physics_study.csv`` (one row per run, resumable: rows already there
are kept) and the figures ``docs/physics_study_static.png``, ``docs/physics_study_rolling.png``.
``docs/physics_study.md`` discusses them.

Usage (from the repository root)::

    PYTHONPATH=. python docs/physics_study.py [--cells 4] [--plot-only]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

from pidcore.dem import DemConfig, LoadCase, simulate_load_case
from pidcore.model.table3 import load_paper_table3
from pidcore.specimen import paper_specimen

HERE = Path(__file__).resolve().parent
CSV = HERE / "physics_study.csv"
FREQUENCIES_HZ = (50.0, 100.0, 500.0, 1000.0)
ACCELERATIONS_G = (1.0, 5.0)
FILL_PERCENT = 50.0
#: mu_s for both pairs (None: the table's sliding friction, 0.096 pair / 0.14 wall)
STATIC = (None, 0.2, 0.3, 0.5, 0.8)
#: mu_r for both pairs, at the table's friction
ROLLING = (0.02, 0.05, 0.1)


def variants() -> list[tuple[str, float | None, float, dict]]:
    """(label, mu_s, mu_r, specimen changes) of every run family."""
    out = []
    for mu_s in STATIC:
        changes = {} if mu_s is None else {
            "pairs.particle_particle.static_friction": mu_s,
            "pairs.particle_wall.static_friction": mu_s}
        out.append((f"mu_s={mu_s if mu_s is not None else 'mu'}", mu_s, 0.0, changes))
    for mu_r in ROLLING:
        out.append((f"mu_r={mu_r}", None, mu_r, {
            "pairs.particle_particle.rolling_friction": mu_r,
            "pairs.particle_wall.rolling_friction": mu_r}))
    return out


def run(cells: int) -> pd.DataFrame:
    done = pd.read_csv(CSV) if CSV.exists() else pd.DataFrame()
    rows = done.to_dict("records")
    base = paper_specimen("acrylic")
    for label, mu_s, mu_r, changes in variants():
        specimen = base.with_values(changes) if changes else base
        for a in ACCELERATIONS_G:
            for f in FREQUENCIES_HZ:
                if not done.empty and ((done.variant == label) & (done.frequency_hz == f)
                                       & (done.acceleration_g == a)
                                       & (done.cells == cells)).any():
                    continue
                clock = time.perf_counter()
                r = simulate_load_case(LoadCase(f, a, FILL_PERCENT), DemConfig(cells=cells),
                                       specimen=specimen)
                rows.append({
                    "variant": label, "static_friction": mu_s if mu_s is not None else np.nan,
                    "rolling_friction": mu_r, "frequency_hz": f, "acceleration_g": a,
                    "fill_percent": FILL_PERCENT, "cells": cells, "sdc": r.sdc,
                    "sdc_stderr": r.sdc_stderr,
                    "dissipated_normal_j": r.energy_dissipated_normal_j,
                    "dissipated_friction_j": r.energy_dissipated_friction_j,
                    "dissipated_rolling_j": r.energy_dissipated_rolling_j,
                    "energy_balance_error": r.energy_balance_error,
                    "steady_detected": r.steady_detected, "wall_s": time.perf_counter() - clock})
                pd.DataFrame(rows).to_csv(CSV, index=False)
                print(f"{label:10s} {f:6g} Hz {a:g} g: SDC {r.sdc:.4g} +- {r.sdc_stderr:.2g}"
                      f"  balance {r.energy_balance_error:+.2e}"
                      f"  ({time.perf_counter() - clock:.0f} s)", flush=True)
    return pd.DataFrame(rows)


def measured() -> pd.DataFrame:
    t = load_paper_table3()
    return t[t.fill_percent == FILL_PERCENT].set_index(["acceleration_g", "frequency_hz"])


def plot(table: pd.DataFrame) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paper = measured()
    colours = dict(zip(FREQUENCIES_HZ, ("C0", "C1", "C2", "C3"), strict=True))
    for kind, column, xlabel, out in (
            ("static", "static_friction", "static friction mu_s (both pairs) [-]",
             "physics_study_static.png"),
            ("rolling", "rolling_friction", "rolling friction mu_r (both pairs) [-]",
             "physics_study_rolling.png")):
        fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
        for ax, a in zip(axes, ACCELERATIONS_G, strict=True):
            for f in FREQUENCIES_HZ:
                sel = table[(table.acceleration_g == a) & (table.frequency_hz == f)]
                base = sel[sel.variant == "mu_s=mu"]
                if kind == "static":
                    fam = sel[sel.variant.str.startswith("mu_s=") & (sel.variant != "mu_s=mu")]
                    x0 = 0.14  # the table's sliding friction (wall pair) marks mu_s = mu
                else:
                    fam = sel[sel.variant.str.startswith("mu_r=")]
                    x0 = 0.0
                fam = fam.sort_values(column)
                x = np.concatenate([[x0], fam[column].to_numpy()]) if len(base) else \
                    fam[column].to_numpy()
                y = np.concatenate([base.sdc.to_numpy(), fam.sdc.to_numpy()])
                e = np.concatenate([base.sdc_stderr.to_numpy(), fam.sdc_stderr.to_numpy()])
                if len(x) != len(y):
                    continue
                ax.errorbar(x, y, yerr=e, marker="o", color=colours[f], label=f"{f:g} Hz")
                if (a, f) in paper.index:
                    ax.axhline(paper.loc[(a, f), "sdc_experimental"], color=colours[f],
                               ls="--", lw=1)
            ax.set_yscale("log")
            ax.set_xlabel(xlabel)
            ax.set_ylabel("SDC [-]")
            ax.set_title(f"{a:g} g, 50 % fill (dashed: paper, measured)")
            ax.legend(fontsize=8)
        fig.savefig(HERE / out, dpi=120)
        plt.close(fig)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cells", type=int, default=4)
    p.add_argument("--plot-only", action="store_true")
    args = p.parse_args()
    table = pd.read_csv(CSV) if args.plot_only else run(args.cells)
    plot(table)


if __name__ == "__main__":
    main()
