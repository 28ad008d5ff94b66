"""Run the C kernel (ctypes) on the dumped bench states; compare with Numba; time both.

Usage (repository root): PYTHONPATH=$PWD:docs/dem_c_translation \
    python docs/dem_c_translation/run_c.py LIB.so [--repeat 3] [--no-numba]
Prints per bed: max relative difference of the outputs vs the Numba run, and
particle-steps/s (22 x 8 x steps / best process CPU time) for C and for Numba's
advance_cells called directly with the same arguments.
"""
import argparse
import ctypes as ct
import time
from pathlib import Path

import numpy as np
from dump import BEDS, NAMES

HERE = Path(__file__).parent
ARRAYS = {"pos", "vel", "omg", "frc", "trq", "wall_n", "wall_d", "law_pp", "law_pw",
          "hist_pp", "hist_pw", "tally", "samples", "status", "fail_step"}
INTS = {"clip_attraction", "stick_slip", "rolling", "step0", "n_steps", "drive_axis",
        "steps_per_cycle", "sample_every"}
OUTPUTS = ("pos", "vel", "omg", "frc", "trq", "hist_pp", "hist_pw", "tally", "samples",
           "status", "fail_step")


def load_lib(path):
    lib = ct.CDLL(str(Path(path).resolve()))
    f = lib.advance_cells
    argtypes = []
    for n in NAMES:
        if n in ARRAYS:
            argtypes.append(ct.c_void_p)
        elif n in INTS:
            argtypes.append(ct.c_int64)
        else:
            argtypes.append(ct.c_double)
    argtypes += [ct.c_int64] * 7  # first_cell end_cell K N W n_cyc n_smp
    f.argtypes = argtypes
    f.restype = ct.c_int64
    return f


def fresh(inp):
    return {n: inp[n].copy() for n in NAMES}


def call_c(f, a):
    vals = []
    for n in NAMES:
        v = a[n]
        if n in ARRAYS:
            assert v.flags.c_contiguous
            assert v.dtype == (np.int64 if n in ("status", "fail_step") else np.float64), n
            vals.append(v.ctypes.data)
        elif n in INTS:
            vals.append(int(v))
        else:
            vals.append(float(v))
    k, n_part = a["pos"].shape[1], a["pos"].shape[2]
    vals += [0, k, k, n_part, a["wall_n"].shape[0], a["tally"].shape[1],
             a["samples"].shape[1]]
    f(*vals)


def call_numba(a):
    from pidcore.dem.kernel import advance_cells
    args = []
    for n in NAMES:
        v = a[n]
        if n in ARRAYS:
            args.append(v)
        elif n in ("clip_attraction", "stick_slip", "rolling"):
            args.append(bool(v))
        elif n in INTS:
            args.append(np.int64(v) if n in ("step0", "n_steps", "steps_per_cycle",
                                               "sample_every") else int(v))
        else:
            args.append(float(v))
    k = a["pos"].shape[1]
    advance_cells(*args, np.int64(0), np.int64(k))


def max_rel(a, b):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    scale = np.max(np.abs(b)) if b.size else 0.0
    if scale == 0.0:
        return 0.0 if np.array_equal(a, b) else np.inf
    return float(np.max(np.abs(a - b)) / scale)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("lib")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-numba", action="store_true")
    ap.add_argument("--beds", default=",".join(BEDS))
    ns = ap.parse_args()
    f = load_lib(ns.lib)
    print(f"lib {ns.lib}")
    for bed in ns.beds.split(","):
        inp = dict(np.load(HERE / "beds" / f"{bed}_in.npz"))
        ref = dict(np.load(HERE / "beds" / f"{bed}_numba.npz"))
        work = 22 * inp["pos"].shape[1] * int(inp["n_steps"])
        a = fresh(inp)
        call_c(f, a)
        identical = all(np.array_equal(a[n], ref[n]) for n in OUTPUTS)
        diffs = {n: max_rel(a[n], ref[n]) for n in OUTPUTS if n not in ("status", "fail_step")}
        worst = max(diffs, key=diffs.get)
        st = (a["status"].tolist(), ref["status"].tolist())
        t_c = []
        for _ in range(ns.repeat):
            a = fresh(inp)
            t0 = time.process_time()
            call_c(f, a)
            t_c.append(time.process_time() - t0)
        line = (f"{bed:24s} bit-identical={identical} max_rel_diff={diffs[worst]:.3g} "
                f"({worst}) status c/numba={st[0] == st[1]} "
                f"C {work / min(t_c):.4g} p-steps/s")
        if not ns.no_numba:
            call_numba(fresh(inp))  # load/compile
            t_n = []
            for _ in range(ns.repeat):
                a = fresh(inp)
                t0 = time.process_time()
                call_numba(a)
                t_n.append(time.process_time() - t0)
            line += f"  Numba {work / min(t_n):.4g} p-steps/s  C/Numba {min(t_n) / min(t_c):.2f}"
        print(line, flush=True)
        if not identical:
            print("   per-array max rel diff:", {k: f"{v:.2g}" for k, v in diffs.items()})


if __name__ == "__main__":
    main()
