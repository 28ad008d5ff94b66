"""``pidcore samples make``: regenerate the bundled ``data_samples/``."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._options import check_out_folder, path_argument, positive_int, progress_wanted


def register(subparsers: argparse._SubParsersAction) -> None:
    # the trial script is named here as the README names it: a user with a specimen of their
    # own looked in `samples --help` for how to make exports of it and found nothing
    own = ("They are the paper's coupon's; for virtual shaker exports of a specimen file of "
           "your own, see docs/trial_own_specimen/make_measurements.py in the source tree "
           "(README, 'Specimen files').")
    p = subparsers.add_parser("samples", help="regenerate the bundled sample data",
                              description="Regenerate the bundled sample data. " + own)
    sub = p.add_subparsers(dest="samples_command", metavar="ACTION", required=True)
    m = sub.add_parser("make", help="Table 3 CSV, DEM grid store and virtual shaker exports",
                       description="Regenerate data_samples/: the paper's Table 3 as CSV, a DEM "
                                   "store of the whole Table 3 grid (sweep, resumable) and "
                                   "synthetic virtual shaker-test exports in every format. "
                                   + own)
    m.add_argument("--out", type=path_argument, default=Path("data_samples"),
                   help="output folder (default: ./data_samples)")
    m.add_argument("--skip-sweep", action="store_true",
                   help="reuse the DEM runs already in OUT/dem_table3.h5")
    m.add_argument("--workers", metavar="N", type=positive_int, default=None,
                   help="processes for the DEM sweep (default: all cores)")
    m.set_defaults(func=_make)


def _make(args: argparse.Namespace) -> int:
    from ..samples import make_samples

    check_out_folder(args.out)  # before the sweep, not after it
    for name, path in make_samples(args.out, run_sweep=not args.skip_sweep,
                                   workers=args.workers,
                                   progress=progress_wanted(args)).items():
        print(f"{name:<50} {path}")
    return 0
