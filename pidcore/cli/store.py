"""``pidcore store list``: what a store holds; ``pidcore store verify``: its integrity check;
``pidcore store remove KEY...``: records removed in one commit, with what depends on them."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import TYPE_CHECKING

from ._options import (
    STORE_HELP,
    add_json_option,
    add_store_option,
    command_line,
    print_json,
    progress_wanted,
)

if TYPE_CHECKING:
    import pandas as pd

    from ..store.manage import Removal

#: Exit status of ``pidcore store verify`` when the store is damaged (2: it cannot be read).
DAMAGED_EXIT = 1


def register(subparsers: argparse._SubParsersAction) -> None:
    from ..store.manage import SECTIONS

    p = subparsers.add_parser(
        "store", help="list, verify and remove the records of an HDF5 store",
        description="The HDF5 store's records: list them, verify the store, remove records "
                    "(see README 'The store'). Exit 2, one line, where the store does not "
                    "exist or is no readable pidcore store.")
    sub = p.add_subparsers(dest="store_command", metavar="STORE_COMMAND", required=True)
    listing = sub.add_parser(
        "list", help="one table per section: the keys and what tells the records apart",
        description="List the measurements, analyses, DEM runs and calibrations of the store, "
                    "one table per section, oldest first (DEM runs by key), each column with "
                    "its unit. The key names a record for `pidcore store remove`. Analyses: "
                    "newest or superseded (the newest analysis of a measurement is the one "
                    "report --store and calibrate --store take); DEM runs: the calibration "
                    "whose fit a run is a design run of.")
    add_store_option(listing, help=STORE_HELP)
    listing.add_argument("--section", choices=list(SECTIONS), action="append", default=None,
                         help="only this section (repeat for several; default: all)")
    add_json_option(listing)
    listing.set_defaults(func=run_list)
    verify = sub.add_parser(
        "verify", help="check every record and array of the store",
        description="Check the store's integrity (every array read, its checksum checked; "
                    "keys against contents; every analysis of a stored measurement; every "
                    "calibration readable) and print each problem. Exit 0: sound; exit "
                    f"{DAMAGED_EXIT}: damaged (the problems printed); exit 2: the store does "
                    "not exist or is no readable pidcore store.")
    add_store_option(verify, help=STORE_HELP)
    add_json_option(verify, progress=True)
    verify.set_defaults(func=run_verify)
    remove = sub.add_parser(
        "remove", help="remove records by key, in one commit",
        description="Remove the records KEY... (keys as `pidcore store list` prints them; "
                    "SECTION/KEY where a key is in two sections) in one commit: Ctrl-C or an "
                    "error commits nothing and the file is replaced whole. A measurement "
                    "takes its analyses with it. A DEM run that is a design run of a stored "
                    "calibration is refused (exit 2, nothing removed) unless the calibration "
                    "is named too or --with-dependents removes it with the run. An unknown "
                    "key is refused (exit 2, nothing removed). The file keeps its size "
                    "(HDF5 does not give back the space of removed records).")
    remove.add_argument("keys", metavar="KEY", nargs="+", help="record keys to remove")
    add_store_option(remove, help=STORE_HELP)
    remove.add_argument("--with-dependents", action="store_true",
                        help="also remove the calibrations fitted on a DEM run removed")
    remove.add_argument("--dry-run", action="store_true",
                        help="print what would be removed; the store is only read")
    add_json_option(remove)
    remove.set_defaults(func=run_remove)


def run_list(args: argparse.Namespace) -> int:
    from ..store.manage import SECTIONS, store_contents

    contents = store_contents(args.store, args.section or list(SECTIONS))
    if args.json:
        print_json({"store": args.store, **{
            section: json.loads(frame.to_json(orient="records"))
            for section, frame in contents.items()}})
        return 0
    blocks = [f"{section} ({len(frame)}):\n" + (_table(frame) if len(frame) else "  none")
              for section, frame in contents.items()]
    print(f"{args.store}\n\n" + "\n\n".join(blocks))
    return 0


def _table(frame: pd.DataFrame) -> str:
    """The table with its columns' headers (units named) and numbers as reports write
    them (6 significant digits; an empty value blank)."""
    import pandas as pd

    from ..store.manage import COLUMN_HEADERS

    def cell(value: object) -> str:
        if value is None or (isinstance(value, float) and math.isnan(value)):
            return ""
        if isinstance(value, float):
            return f"{value:.6g}"
        return str(value)

    columns = []
    for name in frame.columns:
        texts = [COLUMN_HEADERS.get(name, name), *map(cell, frame[name])]
        width = max(map(len, texts))
        numbers = pd.api.types.is_numeric_dtype(frame[name])
        columns.append([t.rjust(width) if numbers else t.ljust(width) for t in texts])
    return "\n".join("  ".join(row).rstrip() for row in zip(*columns, strict=True))


def run_verify(args: argparse.Namespace) -> int:
    from ..errors import StoreError
    from ..store.manage import existing_store, verify_with_progress

    store = existing_store(args.store)
    problems = verify_with_progress(store, progress=progress_wanted(args),
                                    label=f"verifying {args.store}")
    summary = store.summary()
    try:
        unchecked = store.unchecked()
    except StoreError:  # a store too damaged to say: its problems are printed
        unchecked = []
    if args.json:
        print_json({"store": args.store, "sound": not problems,
                          "problems": problems, "unchecked": unchecked, "summary": summary})
    elif problems:
        print("\n".join(problems))
        print(f"{args.store}: damaged: {len(problems)} problem(s)", file=sys.stderr)
    else:
        print(f"{args.store}: sound ({summary['n_measurements']} measurement(s), "
              f"{summary['n_analyses']} analysis(es), {summary['n_dem_runs']} DEM run(s), "
              f"{summary['n_calibrations']} calibration(s); every array read and its "
              "checksum checked)")
    if unchecked and not problems and not args.json:
        print("\n".join(unchecked))
    return DAMAGED_EXIT if problems else 0


def run_remove(args: argparse.Namespace) -> int:
    from ..store.manage import remove_records

    removal = remove_records(args.store, args.keys, with_dependents=args.with_dependents,
                             dry_run=args.dry_run)
    if args.json:
        print_json(removal.to_dict())
        return 0
    print(format_removal(removal))
    return 0


def format_removal(removal: Removal) -> str:
    """One line per record removed (or that would be), why where it was not named, the notes
    on what is left, and a closing line."""
    from ..app.kept_specimens import kept_specimen_file, kept_specimens_folder

    lines = [f"{'would remove' if removal.dry_run else 'removed'} {r.what} {r.key}"
             + (f" ({r.label})" if r.label else "") + (f": {r.because}" if r.because else "")
             for r in removal.records]
    lines += [f"note: {note}" for note in removal.notes]
    kept = [sha[:12] for sha in removal.unnamed_sha256
            if kept_specimen_file(removal.store, sha).is_file()]
    if kept:  # the app keeps an uploaded file while a record names it
        lines.append(f"note: no record names the specimen file(s) {', '.join(kept)} kept in "
                     f"{kept_specimens_folder(removal.store)} any more; `"
                     + command_line("pidcore", "specimen", "kept", "--remove", "--store",
                                    removal.store) + "` removes them")
    n = len(removal.records)
    lines.append(f"{removal.store}: {n} record(s) would be removed (--dry-run: nothing was "
                 "removed)" if removal.dry_run else
                 f"{removal.store}: {n} record(s) removed in one commit (the file keeps its "
                 "size: HDF5 does not give back the space)")
    return "\n".join(lines)
