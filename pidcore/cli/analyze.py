"""``pidcore analyze``: complex power, loss factor and SDC of shaker-test exports."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .. import interrupt
from ..errors import PidcoreError
from ..measure import NO_LOAD_CASE, analyze_file
from ._options import (
    add_json_option,
    add_load_case_options,
    add_measurement_options,
    add_store_option,
    analysis_options,
    with_cli_flags,
)


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "analyze",
        help="loss factor and SDC from force/velocity exports (Eq. 11)",
        description="Analyse shaker-test exports (UFF58/58b, CSV/TXT, MAT, HDF5): complex power "
                    "(Eq. 11), loss factor, specific damping capacity, one record per load case. "
                    "Results are saved to the store unless --no-store.",
    )
    p.add_argument("paths", nargs="+", metavar="PATH", type=Path, help="export files")
    add_measurement_options(p)
    add_store_option(p)
    p.add_argument("--no-store", action="store_true", help="do not save to the store")
    g = p.add_argument_group(
        "load case (saved with each analysis, so that `pidcore report --store` places it; "
        "a file with no fill stated is saved without one)")
    add_load_case_options(g, what="PATH", material_help=" (default: stated, else acrylic)")
    p.add_argument("--key", metavar="NAME", default=None,
                   help="which measurement of a pidcore HDF5 store to analyse, when it holds "
                        "several (the error lists them)")
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    try:
        return _run(args)
    except PidcoreError as exc:  # library keywords -> the flags the user types
        raise type(exc)(with_cli_flags(str(exc))) from None


def _stated_load_cases(args: argparse.Namespace) -> list:
    """What each path states about its load case (None: no fill stated), resolved before any
    analysis so that a bad sidecar or option is refused at once."""
    from ..compare.loadcase import FillNotStated, resolve_load_case

    stated = []
    for path in args.paths:  # (a missing file is named by its analysis)
        try:
            stated.append(resolve_load_case(path, fill_percent=args.fill,
                                            material=args.material, direction=args.direction,
                                            sidecar=args.sidecar))
        except FillNotStated:
            stated.append(None)
    return stated


def _run(args: argparse.Namespace) -> int:
    from ..loadcase import refuse_identical_contents_stating_apart

    options = analysis_options(args)
    stated = _stated_load_cases(args)
    saved = False
    keys: list[str] = []
    try:
        # Analyse everything before writing anything: one bad file leaves the store untouched.
        results = [analyze_file(path, options, key=args.key) for path in args.paths]
        cases = [st.load_case(r.analysis.frequency_hz, r.analysis.acceleration_g)
                 if st is not None else None for r, st in zip(results, stated, strict=True)]
        refuse_identical_contents_stating_apart(
            (Path(path).name, r.measurement.sha256, c.key if c else None,
             c.full_label() if c else NO_LOAD_CASE)
            for path, r, c in zip(args.paths, results, cases, strict=True))
        replaced: list[str] = []
        if not args.no_store:
            from ..measure import save_analyses

            saved_now = save_analyses(  # one transaction
                args.store, results, options,
                [(Path(path).name, c, st.origin if st is not None else "")
                 for path, c, st in zip(args.paths, cases, stated, strict=True)])
            keys, replaced = saved_now.keys, saved_now.notes
            saved = True
        interrupt.raise_if_interrupted()  # an interrupt swallowed on the way still counts
    except (KeyboardInterrupt, SystemError) as exc:
        if not interrupt.is_interruption(exc):
            raise
        said = (f"interrupted after saving {_saved(results, keys)} to {args.store}" if saved
                else "interrupted; nothing saved, the store is unchanged")
        print(f"pidcore analyze: {said}", file=sys.stderr)
        interrupt.mark_handled()
        return 130
    if args.json:
        json.dump({"records": [{**r.to_dict(), "load_case": c.key if c else None}
                               for r, c in zip(results, cases, strict=True)]}, sys.stdout)
        sys.stdout.write("\n")
    else:
        print(format_table(results))
        for path, c, st in zip(args.paths, cases, stated, strict=True):
            print(f"{Path(path).name}: " + (f"load case {c.key} ({st.origin})" if c else
                  "no fill stated: saved without a load case (state it in the file name, "
                  "a sidecar or --fill for `pidcore report --store` to place it)"
                  if not args.no_store else "no fill stated"))
        for note in replaced:
            print(f"note: {note}")
        if not args.no_store:
            print(f"saved {_saved(results, keys)} to {args.store}")
    return 0


def _saved(results: list, keys: list[str]) -> str:
    """"3 record(s)", saying so when byte-identical files made fewer records than files."""
    n = len(set(keys))
    same = len(results) - n
    return f"{n} record(s)" + (f" ({same} file(s) with the same contents as another file "
                               "given: one record)" if same > 0 else "")


def format_table(results: list) -> str:
    # the whole file name: a cut one may no longer say which load case a row is
    names = [Path(r.analysis.source).name for r in results]
    width = max([40, *map(len, names)])
    header = (f"{'source':<{width}} {'frequency [Hz]':>14} {'accel. [g]':>10} "
              f"{'loss factor [-]':>15} {'SDC [-]':>9} {'± SE [-]':>9} {'zeta [-]':>9} "
              f"{'dE/cycle [J]':>12}")
    lines = [header, "-" * len(header)]
    for r, name in zip(results, names, strict=True):
        a = r.analysis
        zeta = "n/a" if a.damping_ratio is None else f"{a.damping_ratio:9.5f}"
        lines.append(f"{name:<{width}} {a.frequency_hz:14.4f} {a.acceleration_g:10.4f} "
                     f"{a.loss_factor:15.6f} {a.sdc:9.5f} {a.sdc_stderr:9.5f} {zeta:>9} "
                     f"{a.energy_per_cycle_j:12.4e}")
        for note in r.notes:
            lines.append(f"    note: {note}")
    return "\n".join(lines)
