"""``pidcore bench``: speed and memory benchmarks (targets live here, not in timed tests)."""

from __future__ import annotations

import argparse

from ._options import positive_int, print_json, progress_wanted


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("bench", help="speed and memory benchmarks")
    sub = p.add_subparsers(dest="bench_command", metavar="WHAT", required=True)
    s = sub.add_parser("signal", help="Eq. 11 analysis throughput on a two-channel record")
    s.add_argument("--samples", type=positive_int, default=10_000_000,
                   help="samples per channel (default 10 000 000)")
    s.add_argument("--repeat", type=positive_int, default=3,
                   help="timed repetitions (best is kept; default 3)")
    s.add_argument("--json", action="store_true", help="one JSON document on stdout")
    s.set_defaults(func=_bench_signal)
    r = sub.add_parser("read", help="peak memory of reading a long export in each format "
                                    "and of analysing it with and without a store",
                       description="Writes a force/velocity export (and --unused acceleration "
                                   "channels) as CSV, ASCII and binary UFF, MAT and HDF5, and "
                                   "measures in a fresh process per case the peak memory of "
                                   "reading each, and of `pidcore analyze` of the CSV and 58b "
                                   "files with --no-store and with a store: resident set "
                                   "growth and tracemalloc peak, as multiples of the bytes of "
                                   "the two channels the analysis uses, against targets.")
    r.add_argument("--samples", type=positive_int, default=1_000_000,
                   help="samples per channel (default 1 000 000)")
    r.add_argument("--unused", type=int, default=0, metavar="N",
                   help="acceleration channels in the file besides force and velocity "
                        "(default 0)")
    r.add_argument("--json", action="store_true", help="one JSON document on stdout")
    r.set_defaults(func=_bench_read)
    t = sub.add_parser("store", help="store listing, reads by key, batch reads and verify "
                                     "on a store of years of tests",
                       description="Builds a temporary store of many small entries (default "
                                   "400 measurements, 2000 analyses, 300 DEM runs) and times "
                                   "a listing, one read by key (whose cost must not grow with "
                                   "the store), every analysis read through one opening, and "
                                   "verify; per entry, against targets.")
    t.add_argument("--analyses", type=positive_int, default=2000,
                   help="analyses stored (default 2000)")
    t.add_argument("--measurements", type=positive_int, default=400,
                   help="measurements stored (default 400)")
    t.add_argument("--dem-runs", type=positive_int, default=300,
                   help="DEM runs stored (default 300)")
    t.add_argument("--json", action="store_true", help="one JSON document on stdout")
    t.set_defaults(func=_bench_store)
    d = sub.add_parser("dem", help="DEM particle-steps/s on one core and the Table 3 grid time",
                       description="Particle-steps per second on one core for standard beds: "
                                   "acrylic at capacity (22/cell) and 24 aluminium per cell, "
                                   "flying (100 Hz, 5 g), and an acrylic bed resting at 1 g; "
                                   "the acrylic beds also with static friction 0.3 and "
                                   "rolling friction 0.05. Per bed: particle-steps/s by wall "
                                   "time and by process CPU time (_cpu: the kernel's own "
                                   "speed when other processes share the core), the target, "
                                   "and the speed of a plain all-pairs kernel without contact "
                                   "history, static friction or rolling resistance "
                                   "(_reference: the yardstick the targets were set against) "
                                   "on the same bed, with our CPU-time speed as a ratio to "
                                   "it, which carries across machines. Numbers are rounded "
                                   "to 4 digits (--json: in full).")
    d.add_argument("--repeat", type=positive_int, default=3,
                   help="timed repetitions per bed (fastest kept; default 3)")
    d.add_argument("--grid", action="store_true",
                   help="also run the full Table 3 grid (48 cases) and report its wall time")
    d.add_argument("--workers", type=positive_int, default=None,
                   help="processes for the grid (default: all cores)")
    d.add_argument("--json", action="store_true", help="one JSON document on stdout")
    d.add_argument("--no-progress", action="store_true",
                   help="no progress bars (drawn only on a terminal)")
    d.set_defaults(func=_bench_dem)


def _emit(result: dict, as_json: bool) -> None:
    if as_json:
        print_json(result)
        return
    width = max(len(k) for k in result)
    for key, value in result.items():
        shown = f"{value:.4g}" if isinstance(value, float) else value
        print(f"{key:<{width}}  {shown}")


def _bench_signal(args: argparse.Namespace) -> int:
    from ..signal.bench import run_signal_bench

    _emit(run_signal_bench(args.samples, repeat=args.repeat), args.json)
    return 0


def _bench_read(args: argparse.Namespace) -> int:
    from ..errors import ParameterError
    from ..signal.bench import run_read_bench

    if args.unused < 0:
        raise ParameterError(f"--unused {args.unused}: expected 0 or more channels")
    _emit(run_read_bench(args.samples, n_unused=args.unused), args.json)
    return 0


def _bench_store(args: argparse.Namespace) -> int:
    from ..store.bench import run_store_bench

    _emit(run_store_bench(args.analyses, n_measurements=args.measurements,
                          n_dem_runs=args.dem_runs), args.json)
    return 0


#: Beds timed by ``pidcore bench dem``: (label, material, particles per cell, acceleration g,
#: static friction (None: the table's), rolling friction, target particle-steps/s).
DEM_BENCH_BEDS = (
    ("acrylic_22_flying", "acrylic", 22, 5.0, None, 0.0, 3.5e7),
    ("aluminium_24_flying", "aluminium", 24, 5.0, None, 0.0, 3.5e7),
    ("acrylic_22_resting_1g", "acrylic", 22, 1.0, None, 0.0, 2.5e7),
    ("acrylic_22_flying_static_rolling", "acrylic", 22, 5.0, 0.3, 0.05, 3.5e7),
    ("acrylic_22_resting_1g_static_rolling", "acrylic", 22, 1.0, 0.3, 0.05, 2.5e7),
)


def _bench_dem(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from ..dem.bench import run_dem_bench, run_grid_bench

    result: dict = {}
    # the beds of --repeat 1 took ~40 s with no sign of life; the bar is closed (its line
    # cleared) as the block ends, Ctrl-C included, before the CLI's one line
    with tqdm(total=len(DEM_BENCH_BEDS), desc="DEM beds", unit="bed", leave=False,
              dynamic_ncols=True, disable=not progress_wanted(args)) as bar:
        for label, material, n, accel, mu_s, mu_r, target in DEM_BENCH_BEDS:
            r = run_dem_bench(particles_per_cell=n, material=material, acceleration_g=accel,
                              static_friction=mu_s, rolling_friction=mu_r,
                              repeat=args.repeat, reference=True)
            result[f"{label}_particle_steps_per_s"] = r["particle_steps_per_s"]
            result[f"{label}_particle_steps_per_s_cpu"] = r["particle_steps_per_s_cpu"]
            result[f"{label}_target_particle_steps_per_s"] = target
            result[f"{label}_reference_particle_steps_per_s_cpu"] = \
                r["reference_particle_steps_per_s"]
            # both CPU times: the kernel's own speed on a shared machine
            result[f"{label}_ratio_to_reference"] = \
                r["particle_steps_per_s_cpu"] / r["reference_particle_steps_per_s"]
            bar.update(1)
    result["threads"] = 1
    result["repeat"] = args.repeat
    if args.grid:
        result.update(run_grid_bench(workers=args.workers,
                                     progress=progress_wanted(args)), target_grid_wall_s=60.0)
    _emit(result, args.json)
    return 0
