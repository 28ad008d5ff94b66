"""``pidcore report``: measured SDC vs our DEM vs the paper, as CSV/Markdown/HTML/LaTeX/PDF.

All logic is in :func:`pidcore.report.pipeline.make_report`.
"""

from __future__ import annotations

import argparse
import sys

from .. import interrupt
from ..interrupt import untouched
from ..out_folder import folder_identity
from ..report.fonts import figure_fonts, missing_glyphs_note
from ..report.render import (
    display_rows,
    restore_previous_report,
    restored_report_note,
)
from ..report.table import (
    ALIGNMENT_COLUMN,
    CALIBRATED_BAND_COLUMN,
    CALIBRATED_COLUMN,
    CALIBRATED_INSIDE_COLUMN,
    MEASURED_EQ10_COLUMN,
    MEASURED_EQ11_COLUMN,
    with_band_text,
)
from ._options import (
    add_load_case_options,
    add_measurement_options,
    add_store_option,
    analysis_options,
    comma_list,
    given_options,
    path_argument,
    progress_wanted,
)
from ._vocabulary import cli_words

#: Columns of the short table printed on stdout.
#: The like-for-like measured SDC (Eq. 10's E, as our DEM's) stands beside our DEM's; the
#: Eq. 11 one beside the calibrated DEM's, which predicts it.
_STDOUT_COLUMNS = (
    "frequency [Hz]", "acceleration [g]", "packing ratio [%]", "SDC DEM (ours) [-]",
    MEASURED_EQ10_COLUMN, MEASURED_EQ11_COLUMN, CALIBRATED_COLUMN,
    CALIBRATED_BAND_COLUMN, CALIBRATED_INSIDE_COLUMN, "SDC DEM (paper) [-]",
    "SDC measured (paper) [-]", ALIGNMENT_COLUMN,
)


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "report", help="compare measured SDC, our DEM and the paper (Table 3 style report)",
        description="Analyse measurement FILES (optional), add them to --store, align every "
                    "measured load case with the DEM runs of --dem-store (default: --store) "
                    "and with the paper's Table 3, and write a report (CSV, Markdown, "
                    "self-contained HTML, LaTeX, PDF, figures as PNG and SVG) into --out. "
                    "Fill is stated in the file name (..._fill50_... or ..._50pct_...), in "
                    "a sidecar loadcases.csv, or with --fill; the sidecar may also state each "
                    "file's analysis settings (velocity_delay_us, ...), which options given "
                    "override.")
    p.add_argument("files", nargs="*", metavar="FILE", type=path_argument,
                   help="measurement exports to analyse (UFF58, CSV/TXT, MAT, HDF5)")
    p.add_argument("--out", metavar="DIR", type=path_argument, required=True,
                   help="report folder (new, empty or an earlier report holding only what a "
                        "report writes, replaced atomically)")
    add_store_option(p, default=None,
                     help="HDF5 store: analyses of FILES are added to it; without FILES its "
                          "analyses are reported (no default, unlike analyze and dem sweep: "
                          "without it FILES are analysed for the report only, not saved)")
    p.add_argument("--dem-store", metavar="FILE", type=path_argument, action="append", default=None,
                   help="HDF5 store holding the DEM runs (default: --store); only read; "
                        "repeat it to join the runs of several stores (the first holding a "
                        "run gives it), as the app joins its store's runs with the reference "
                        "runs: --dem-store APP.h5 --dem-store REFERENCE.h5")
    p.add_argument("--format", metavar="FMT", type=comma_list, default="all",
                   help="all or a comma-separated list of csv, md, html, tex, pdf (default "
                        "all); the figures (PNG and SVG, figures/) are written with any")
    add_load_case_options(p, what="FILE")
    p.add_argument("--specimen", metavar="FILE", type=path_argument, default=None,
                   help="compare only DEM runs of this specimen file (default: the paper's "
                        "coupon); the paper's Table 3 only for the paper's coupon; FILES of "
                        "its particles whose sidecar names no specimen are its tests (saved "
                        "as such to --store)")
    p.add_argument("--pool", action="store_true",
                   help="pool DEM runs of different numerical settings at one load case "
                        "into one row (default: a row each); tests of different specimens "
                        "are rows of their own either way")
    p.add_argument("--calibration", metavar="FILE", type=path_argument, default=None,
                   help="calibration.json of pidcore calibrate (or the --out folder holding "
                        "it), or an HDF5 store it saved calibrations in (its --dem-store): add "
                        "the calibrated DEM's Eq. 11 SDC with its 95 %% band beside the raw DEM "
                        "and the measurement")
    p.add_argument("--calibration-key", metavar="KEY", default=None,
                   help="which calibration of the --calibration store (cal_...; a store "
                        "holding one needs none)")
    p.add_argument("--case-sheets", action="store_true",
                   help="also write the PDF sheet of every measured load case into "
                        "DIR/cases/<load case>.pdf, as the app's Compare page prints it "
                        "(headline, measured Eq. 11 SDC, the --calibration's prediction, band "
                        "and verdict as the report's row, plots, each file's corrections); "
                        "not with --pool")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bars (drawn only on a terminal)")
    # a FILE may be a pidcore HDF5 store of several measurements, whose refusal says
    # "choose one with --key NAME", as for `pidcore analyze`
    p.add_argument("--key", metavar="NAME", default=None,
                   help="which measurement of a pidcore HDF5 store FILE to report, when it "
                        "holds several (the error lists them)")
    add_measurement_options(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..report.pipeline import make_report
    from ..specimen import load_specimen

    specimen = load_specimen(args.specimen) if args.specimen is not None else None
    # a hidden earlier report back first (a killed write's): else the identity below would
    # call the restored folder this run's report after a Ctrl-C
    if restore_previous_report(args.out) is not None:  # said at once: the run may fail
        print(f"note: {restored_report_note(args.out)}")
    before = folder_identity(args.out)
    # a commit puts a new store file in place (copy, then rename): its identity says after a
    # Ctrl-C whether the analyses of FILES were saved
    store_before = folder_identity(args.store) if args.store is not None else None
    try:
        with figure_fonts() as missing:
            result = make_report(
                args.files, out_dir=args.out, store=args.store, dem_store=args.dem_store,
                formats=args.format, fill_percent=args.fill, material=args.material,
                direction=args.direction, sidecar=args.sidecar, options=analysis_options(args),
                options_given=given_options(args),
                specimen=specimen, pool=args.pool, calibration=args.calibration,
                calibration_key=args.calibration_key,
                accept_implausible=args.accept_implausible, progress=progress_wanted(args),
                wording=lambda text: cli_words(text, "report"), key=args.key,
                case_sheets=args.case_sheets)
        print(short_table(result.table))
        glyphs = missing_glyphs_note(missing, "the figures and PDF pages")
        for note in [*result.notes, *([glyphs] if glyphs else [])]:  # in the command's words
            print(f"note: {note}")
        for name, path in result.paths.items():
            print(f"wrote {name}: {path}")
    except (KeyboardInterrupt, Exception) as exc:
        if not interrupt.is_interruption(exc):
            raise
        # the report folder is replaced whole or not at all: say which, not "may hold part"
        after = folder_identity(args.out)
        said = (f"the report was written to {args.out} before it" if after != before else
                f"{args.out} is as it was (a report is written whole or not at all)"
                if args.out.exists() else f"{untouched(args.out)} (a report is written whole "
                "or not at all)")
        if args.files and args.store is not None and \
                folder_identity(args.store) != store_before:
            # saved in one transaction before the report: said, not "nothing half-done" alone
            said += (f"; the analyses of the {len(args.files)} file(s) were saved to "
                     f"{args.store} before it (whole)")
        elif args.files and args.store is not None:  # saved in one transaction, or not
            said += ("; no store write was left half-done, the store is unchanged"
                     if args.store.exists() else f"; {untouched(args.store)}")
        print(f"pidcore report: interrupted; {said}", file=sys.stderr)
        interrupt.mark_handled()
        return interrupt.exit_status()
    return 0


def short_table(table) -> str:
    """A fixed-width text table of the main columns (the calibrated band in one cell, as
    :func:`~pidcore.report.table.with_band_text` writes it, and its verdict: an
    ``uninformative`` band showed as two numbers without a word)."""
    table = with_band_text(table)
    cols = [c for c in _STDOUT_COLUMNS if c in table.columns]
    # the measured SDCs keep report.csv's names: "SDC measured (Eq. 10)" here named as an
    # SDC of Eq. 10 the column report.csv calls "SDC measured, E of Eq. 10" (Eq. 10 gives
    # the energy E the measured dE is divided by, not an SDC)
    short = {ALIGNMENT_COLUMN: "alignment",
             CALIBRATED_INSIDE_COLUMN: "measured in calibrated 95 % band"}
    heads = [short.get(c, c) for c in cols]
    rows = display_rows(table, cols)
    widths = [max([len(h), *(len(r[i]) for r in rows)]) for i, h in enumerate(heads)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(heads, widths, strict=True))]
    lines.append("  ".join("-" * w for w in widths))
    lines += ["  ".join(v.rjust(w) for v, w in zip(r, widths, strict=True)) for r in rows]
    if not rows:
        lines.append("(no load cases)")
    return "\n".join(lines)
