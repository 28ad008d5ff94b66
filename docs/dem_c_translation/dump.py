"""Build the four benchmark beds exactly as run_dem_bench does (settle + steady pre-advance)
and dump every argument advance_cells receives for the timed 20000-step call, plus the
Numba kernel's outputs after that call (reference for the C comparison).

Usage (repository root): PYTHONPATH=$PWD python docs/dem_c_translation/dump.py [steps]
    -> docs/dem_c_translation/beds/<bed>_{in,numba}.npz (not kept in git)
"""
import sys
from pathlib import Path

import numpy as np

import pidcore.dem.bench as bench
import pidcore.dem.state as st

NAMES = ("pos vel omg frc trq wall_n wall_d radius mass inertia law_pp law_pw v_reg "
         "clip_attraction gravity stick_slip rolling hist_pp hist_pw dt step0 n_steps omega "
         "accel_amp drive_axis steps_per_cycle sample_every max_overlap_fraction tally "
         "samples status fail_step").split()
BEDS = {
    "resting_default": dict(acceleration_g=1.0, static_friction=None, rolling_friction=0.0),
    "resting_static_rolling": dict(acceleration_g=1.0, static_friction=0.3,
                                   rolling_friction=0.05),
    "flying_default": dict(acceleration_g=5.0, static_friction=None, rolling_friction=0.0),
    "flying_static_rolling": dict(acceleration_g=5.0, static_friction=0.3,
                                  rolling_friction=0.05),
}


def snap(args):
    return {n: (np.array(a, copy=True) if isinstance(a, np.ndarray) else np.array(a))
            for n, a in zip(NAMES, args, strict=True)}


def dump_bed(bed: str, kw: dict, steps: int, out: Path) -> None:
    """Run one bench bed, capturing the arguments and results of its timed ``advance``."""
    orig_advance = bench.advance
    orig_threads = st._advance_on_threads
    calls = []
    captured = {}

    def capturing_threads(args, k):
        captured["in"] = snap(args)
        orig_threads(args, k)
        captured["out"] = snap(args)

    def wrapped(state, settings, n, **kwargs):
        calls.append(n)
        if len(calls) == 2:  # the timed call (1st: steady pre-advance)
            st._advance_on_threads = capturing_threads
            try:
                return orig_advance(state, settings, n, **kwargs)
            finally:
                st._advance_on_threads = orig_threads
        return orig_advance(state, settings, n, **kwargs)

    bench.advance = wrapped
    try:
        r = bench.run_dem_bench(particles_per_cell=22, material="acrylic", steps=steps,
                                repeat=1, **kw)
    finally:
        bench.advance = orig_advance
    assert calls[1] == steps, calls
    np.savez(out / f"{bed}_in.npz", **captured["in"])
    np.savez(out / f"{bed}_numba.npz", **captured["out"])
    i = captured["in"]
    print(bed, "pre-advance steps", calls[0], "dt", float(i["dt"]), "step0",
          int(i["step0"]), "rolling", bool(i["rolling"]), "law_pp", i["law_pp"].tolist(),
          f"bench cpu rate {r['particle_steps_per_s_cpu']:.4g}")


def main():
    steps = int(sys.argv[1]) if len(sys.argv) > 1 else 20000
    out = Path(__file__).parent / "beds"
    out.mkdir(exist_ok=True)
    for bed, kw in BEDS.items():
        dump_bed(bed, kw, steps, out)


if __name__ == "__main__":
    main()
