"""``pidcore bench``: speed and memory benchmarks (targets live here, not in timed tests)."""

from __future__ import annotations

import argparse
import json


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("bench", help="speed and memory benchmarks")
    sub = p.add_subparsers(dest="bench", metavar="WHAT", required=True)
    s = sub.add_parser("signal", help="Eq. 11 analysis throughput on a two-channel record")
    s.add_argument("--samples", type=int, default=10_000_000,
                   help="samples per channel (default 10 000 000)")
    s.add_argument("--repeat", type=int, default=3, help="timed repetitions (best is kept)")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=_bench_signal)
    d = sub.add_parser("dem", help="DEM particle-steps/s on one core and the Table 3 grid time",
                       description="Particle-steps per second on one core for standard beds: "
                                   "acrylic at capacity (22/cell) and 24 aluminium per cell, "
                                   "flying (100 Hz, 5 g), and an acrylic bed resting at 1 g.")
    d.add_argument("--grid", action="store_true",
                   help="also run the full Table 3 grid (48 cases) and report its wall time")
    d.add_argument("--workers", type=int, default=None, help="processes for the grid")
    d.add_argument("--json", action="store_true")
    d.set_defaults(func=_bench_dem)


def _emit(result: dict, as_json: bool) -> None:
    if as_json:
        print(json.dumps(result))
        return
    width = max(len(k) for k in result)
    for key, value in result.items():
        print(f"{key:<{width}}  {value}")


def _bench_signal(args: argparse.Namespace) -> int:
    from ..signal.bench import run_signal_bench

    _emit(run_signal_bench(args.samples, repeat=args.repeat), args.json)
    return 0


#: Beds timed by ``pidcore bench dem``: (label, material, particles per cell, acceleration g).
DEM_BENCH_BEDS = (
    ("acrylic_22_flying", "acrylic", 22, 5.0),
    ("aluminium_24_flying", "aluminium", 24, 5.0),
    ("acrylic_22_resting_1g", "acrylic", 22, 1.0),
)


def _bench_dem(args: argparse.Namespace) -> int:
    from ..dem.bench import run_dem_bench, run_grid_bench

    result: dict = {}
    for label, material, n, accel in DEM_BENCH_BEDS:
        r = run_dem_bench(particles_per_cell=n, material=material, acceleration_g=accel)
        result[f"{label}_particle_steps_per_s"] = r["particle_steps_per_s"]
    result["threads"] = 1
    result["target_particle_steps_per_s"] = 2e7
    if args.grid:
        result.update(run_grid_bench(workers=args.workers), target_grid_wall_s=120.0)
    _emit(result, args.json)
    return 0
