"""``pidcore calibrate``: fit specimen parameters to measured SDCs, with uncertainty."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .. import defaults, interrupt
from ._options import (
    check_out_folder,
    comma_list,
    command_line,
    displayed_names,
    non_negative_int,
    path_argument,
    positive_int,
    progress_wanted,
)
from ._vocabulary import cli_words

DEFAULT_STORE = Path("calibration_store.h5")


def register(subparsers: argparse._SubParsersAction) -> None:
    from ..calibrate.parameters import DEFAULT_FIT, dem_parameter_names
    from ..calibrate.posterior import DISCREPANCY_FLOOR
    from ..calibrate.surrogate import default_design_size

    names = ", ".join(["fixture_mass_kg", "baseline_loss_factor", *dem_parameter_names(),
                       "any numeric specimen field by dotted path"])
    p = subparsers.add_parser(
        "calibrate", help="fit DEM/specimen parameters to measured SDCs",
        description="Fit chosen parameters to measured SDCs (Eq. 11 of the DEM's virtual "
                    "shaker, with fixture mass and baseline loss factor), with a posterior, "
                    "95 % intervals and optional leave-one-out cross-validation. DEM runs "
                    "over a space-filling design are cached in --dem-store, and the result is "
                    "saved there.")
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--data", metavar="TABLE.csv", type=path_argument,
                        help="measured SDCs: frequency_hz, acceleration_g, fill_percent, sdc "
                             "[, sdc_stderr, sdc_stderr_dof, energy_per_cycle_j, material, "
                             "specimen]; a row "
                             "without a material is of --specimen's particles (else acrylic); "
                             "one of another material than the specimen's is refused")
    source.add_argument("--store", metavar="FILE", type=path_argument,
                        help="use the analysed measurements of this store, per load case: "
                             "those of --specimen's particles measured on it or on no named "
                             "specimen (the paper's coupon: those naming no other specimen); "
                             "a note names the ones left out")
    p.add_argument("--specimen", metavar="FILE", type=path_argument, default=None,
                   help="specimen file to start from (default: the paper's coupon)")
    p.add_argument("--fit", metavar="NAME,...", type=comma_list, default=",".join(DEFAULT_FIT),
                   help=f"parameters to fit (default %(default)s); from: {names}")
    p.add_argument("--prior", metavar="NAME=LOW:HIGH", action="append", default=[],
                   help="change a prior: NAME=LOW:HIGH (uniform) or "
                        "NAME=normal:MU:SD[:LOW:HIGH]; repeatable")
    p.add_argument("--discrepancy", metavar="TAU", type=float, default=None,
                   help="fix the relative model discrepancy instead of fitting it")
    p.add_argument("--discrepancy-floor", metavar="SDC", type=float, default=DISCREPANCY_FLOOR,
                   help="absolute model-error floor on the SDC (default %(default)s)")
    p.add_argument("--cells", metavar="K", type=positive_int, default=None,
                   help="cells per DEM run, at least 2: the run's error is their scatter "
                        "(default 4)")
    p.add_argument("--steady-cycles", metavar="N", type=positive_int, default=None,
                   help="steady cycles measured per DEM run (default: the DEM's)")
    p.add_argument("--design-size", metavar="N", type=positive_int, default=None,
                   help=f"DEM design points (default {default_design_size(1)} for one DEM "
                        f"parameter, {default_design_size(2) - default_design_size(1)} more per "
                        "further one; none fitted: one run per load case; at most "
                        f"{defaults.CALIBRATION_MAX_DESIGN_SIZE}, each is one DEM run per load "
                        "case)")
    p.add_argument("--seed", type=non_negative_int, default=defaults.DEM_SEED,
                   help=f"DEM seed (default {defaults.DEM_SEED})")
    p.add_argument("--workers", metavar="N", type=positive_int, default=2,
                   help="DEM processes (default 2)")
    p.add_argument("--method", choices=("auto", "grid", "emcee"), default="auto",
                   help="posterior: exact grid (<= 4 fitted quantities: 3 parameters plus "
                        "the discrepancy) or emcee; auto picks (default auto)")
    p.add_argument("--dem-store", metavar="FILE", type=path_argument, default=DEFAULT_STORE,
                   help="HDF5 store caching the DEM runs; the calibration is saved in it "
                        "too (report --calibration FILE reads it) (default %(default)s)")
    p.add_argument("--cross-validate", choices=("loo",), default=None,
                   help="leave-one-out: predict each load case from a fit without it")
    p.add_argument("--out", metavar="DIR", type=path_argument, default=None,
                   help="write calibration.json, the calibrated specimen, figures, summary")
    p.add_argument("--json", action="store_true", help="print the result document on stdout")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..calibrate.calibrate import CALIBRATION_CELLS, calibrate
    from ..calibrate.data import DEFAULT_MATERIAL, measured_from_store, read_measured_table
    from ..calibrate.outputs import finish_interrupted_outputs, write_outputs
    from ..calibrate.parameters import parse_fit
    from ..calibrate.persist import save_calibration
    from ..calibrate.runner import RunTally
    from ..errors import InputFileError, ParameterError
    from ..specimen import load_specimen

    if args.out is not None:  # said before the DEM runs and the fit, not after them
        check_out_folder(args.out, built_beside=True)
        # a killed run's half-moved outputs completed first: said now, and the earlier set
        # this run replaces is then whole
        finished = finish_interrupted_outputs(args.out)
        if finished:
            print(f"pidcore calibrate: note: {finished}", file=sys.stderr)
    specimen = load_specimen(args.specimen) if args.specimen is not None else None
    fit = parse_fit(args.fit, specimen)
    cells = CALIBRATION_CELLS if args.cells is None else args.cells
    if cells < 2:
        raise ParameterError(f"--cells: expected >= 2 (the ensemble scatter needs two), "
                             f"got {cells}")
    # a table row without a material is of the specimen given (as in `pidcore compare
    # --specimen`); a stated material other than the specimen's is refused by calibrate()
    default_material = specimen.particles.material if specimen is not None \
        else DEFAULT_MATERIAL
    # what the store held but the fit leaves out, said now (before the DEM runs) and kept with
    # the outputs: summary.md and calibration.json said '5 measured load cases' with no word
    # of the record left out as implausible
    left_out: list[str] = []
    if args.data is not None:
        points = read_measured_table(args.data, default_material=default_material,
                                     specimen=specimen)
    else:
        if not Path(args.store).is_file():
            # read as an empty store, a mistyped path said it held no analysed measurements
            raise InputFileError(f"{args.store}: store not found; expected the store that "
                                 "pidcore analyze saved the measurements in")
        measured = measured_from_store(args.store, left_out=left_out, specimen=specimen)
        points = _store_points(measured, specimen, args.store, left_out)
        for note in left_out:
            print(f"pidcore calibrate: note: {cli_words(note, 'calibrate')}", file=sys.stderr)
    tally = RunTally(args.dem_store)
    written, fitted, saved, unreported = False, False, None, ""
    try:
        result = calibrate(points, fit=fit, priors=args.prior, discrepancy=args.discrepancy,
                           discrepancy_floor=args.discrepancy_floor, store_path=args.dem_store,
                           cells=cells, seed=args.seed, steady_cycles=args.steady_cycles,
                           design_size=args.design_size, workers=args.workers,
                           cross_validate=args.cross_validate, method=args.method,
                           progress=progress_wanted(args), specimen=specimen,
                           on_design=tally.design)
        own_notes = list(result.notes)
        result.notes = [*left_out, *own_notes]
        unreported = _unreported(args, tally, specimen)
        fitted = True
        if args.out is not None:
            # all or nothing; its notes in the words printed below (--prior, not priors=)
            write_outputs(result, args.out,
                          wording=lambda text: cli_words(text, "calibrate"))
            written = True
        # beside the DEM runs it was made from (one transaction, after --out so that a Ctrl-C
        # while the figures are drawn commits nothing): reports and the app read it from there
        # (report --calibration STORE), and it outlives the --out folder
        saved = save_calibration(result, args.dem_store)
        # inside: a Ctrl-C as the result printed was answered by the generic line, which
        # said the complete --out "may hold part of this run's files"
        _print_result(args, result, own_notes, _saved_words(saved, args, unreported),
                      tally.specimens())
        interrupt.raise_if_interrupted()  # one swallowed on the way, or held by the move
    except BaseException as exc:  # noqa: BLE001 - an interrupt, or what one became in C code
        if not interrupt.is_interruption(exc):
            raise
        # finished runs are each saved in their own transaction: counted from the store
        print(f"pidcore calibrate: interrupted; {tally.interrupted()}"
              f"{_saved_words(saved, args, unreported) if fitted else ''}"
              f"{_out_words(args.out, written)}",
              file=sys.stderr)
        interrupt.mark_handled()
        return interrupt.exit_status()
    return 0


def _print_result(args: argparse.Namespace, result, own_notes: list[str], saved: str,
                  specimens: str = "") -> None:
    """The calibration's notes (stderr), its parameters and scores or its JSON document, how
    many DEM runs it computed and reused and of which specimens (``specimens``:
    :meth:`~pidcore.calibrate.runner.RunTally.specimens`, as the report and the app list
    them), and ``saved`` (:func:`_saved_words`: where the store keeps it)."""
    from ..calibrate.outputs import coverage_text, document_json, rms_text

    for note in own_notes:  # the library's words, kept so with the outputs and the store
        print(f"pidcore calibrate: note: {cli_words(note, 'calibrate')}", file=sys.stderr)
    said = saved.removeprefix("; ")
    # a re-run (after Ctrl-C, or with other priors) says that it reused its stored runs; on
    # stderr beside --json's one document
    runs = (f"DEM runs: {result.runs['computed']} computed, {result.runs['cached']} reused "
            f"from {args.dem_store}" + (f" ({specimens})" if specimens else ""))
    if args.json:
        print(f"pidcore calibrate: note: {runs}", file=sys.stderr)
        print(document_json(displayed_names(result.document())))
        print(f"pidcore calibrate: {said}", file=sys.stderr)
    else:
        from ..calibrate.outputs import file_prediction_rows, parameter_units, specimen_words
        from ..calibrate.posterior import summary_texts

        print(specimen_words(result, full_hash=False))
        units = parameter_units(result)
        for name, p in result.parameters.items():
            median, low, high = summary_texts(p)
            print(f"{name} [{units[name]}]: {median} (95 % {low} .. {high})")
        # with its count, as summary.md heads its in-sample table
        print(f"in-sample RMS {rms_text(result.rms)}, "
              f"{coverage_text(result.band_verdicts(result.predictions))}")
        if result.file_predicted:
            rows = file_prediction_rows(result)
            print("calibrated file's own values (each median) predict "
                  + ", ".join(c[1] for c in rows) + " where the posterior median SDC is "
                  + ", ".join(c[2] for c in rows) + " (a DEM re-run of the file should give "
                  "the former; its header and the summary give each load case)")
        print(runs)
        if result.loo is not None:
            print(f"leave-one-out RMS {rms_text(result.loo_rms)}, "
                  f"{coverage_text(result.band_verdicts(result.loo))}")
        print(said)
        if args.out is not None:
            print(f"wrote {args.out}")


def _saved_words(saved, args: argparse.Namespace, unreported: str = "") -> str:
    """What became of the calibration in the store (:func:`pidcore.calibrate.persist.
    save_calibration`'s :class:`~pidcore.calibrate.persist.SavedCalibration`; None: not
    saved), with the report of it to paste, or (``unreported``: :func:`_unreported`) why
    none is printed."""
    store = args.dem_store
    if saved is None:
        return f"; the calibration was not saved in {store}"
    key, added = saved[0], saved[1]
    superseded = tuple(saved[2]) if len(saved) > 2 else ()
    if added:  # the key in the command: it still reads this one once the store holds more
        then = _report_command(args, key) if not unreported else (
            f"no report line to paste: {unreported}; a report of the measurements (their "
            f"FILES, or a --store of their analyses) with "
            f"{command_line('--calibration', store, '--calibration-key', key)} shows them "
            "with its bands")
        words = f"; saved calibration {key} in {store} ({then})"
        if superseded:
            # "stored already" gave the earlier file: say that one is there, and why not it
            words += (f"; the same fit was stored before as {'; '.join(superseded)}: kept as "
                      "it was, this one saved beside it")
        return words
    return f"; calibration {key} is stored in {store} already (the same result)"


def _report_command(args: argparse.Namespace, key: str) -> str:
    """The ``pidcore report`` of this calibration, to paste: ``--out`` is required there (the
    line without it failed "the following arguments are required: --out"), and the report
    finds the measurements of --store and the DEM runs of --dem-store it was made from (--data's
    table is no report input: the report is then of the DEM runs)."""
    measured = ("--store", args.store) if args.store is not None else ()
    specimen = ("--specimen", args.specimen) if args.specimen is not None else ()
    return command_line("pidcore", "report", *measured, "--dem-store", args.dem_store,
                        *specimen, "--calibration", args.dem_store, "--calibration-key", key,
                        "--out", "report_out")


def _unreported(args: argparse.Namespace, tally, specimen) -> str:
    """Why :func:`_report_command`'s report would show none of the calibrated load cases ("":
    it shows them). Its rows are the measurements of --store, else the DEM runs of the
    specimen (:func:`pidcore.dem.persist.runs_of_specimen`, as the report chooses them): a fit
    of a DEM parameter runs only variants of the specimen, so the line printed for a --data
    fit of one gave "(no load cases)"."""
    from ..dem.persist import runs_of_specimen

    if args.store is not None:
        return ""
    runs = tally.stored_runs()
    if runs is not None and not runs_of_specimen(runs, specimen).empty:
        return ""
    return ("its DEM runs are variants of the specimen (the design's points), which a report "
            "leaves out, and the --data table is no report input, so that report would have "
            "no rows")


def _store_points(points: list, specimen, store: Path, left_out: list[str]) -> list:
    """The store's measured points the specimen is calibrated against, as the app's Calibrate
    page chooses them (its particles, measured on it or on no named specimen; the paper's
    coupon: those naming no other specimen); what is left out is added to ``left_out`` (said
    on stderr and kept with the outputs). A store of acrylic and steel measurements was
    refused as a whole ("choose the points of one material"), with no option to choose them."""
    from ..calibrate.data import points_for_paper, points_for_specimen
    from ..errors import ParameterError

    if specimen is None:
        kept, note = points_for_paper(points, hint="--specimen FILE of theirs")
        if not kept:  # the library's 'no measured points' would not say why
            raise ParameterError(
                f"--store {store}: no measurement of the paper's coupon or of an unnamed "
                f"specimen{_continued(note)}")
        materials = sorted({str(p.material) for p in kept})
        if len(materials) > 1:
            raise ParameterError(
                f"--store {store}: measurements of {', '.join(materials)} particles; give "
                "--specimen FILE to calibrate those of its particles")
    else:
        from ..specimen import measured_specimen_name

        kept, note = points_for_specimen(points, specimen)
        if not kept:
            raise ParameterError(
                f"--store {store}: no measurement of specimen {measured_specimen_name(specimen)} "
                f"({specimen.particles.material} particles) or of an unnamed specimen of them"
                f"{_continued(note)}")
    if note and kept:
        left_out.append(note)  # said with the others by the caller
    return kept


def _continued(note: str) -> str:
    """``note`` (a sentence of its own, "Not used for ...: ... .") continuing an error after
    "; ": it read "...specimen; Not used for the paper's coupon: ... ." mid-sentence."""
    if not note:
        return ""
    return "; " + note[:1].lower() + note[1:].removesuffix(".")


def _out_words(out: Path | None, written: bool) -> str:
    """What an interrupt left of ``--out`` (written all at once or not at all: write_outputs)."""
    if out is None:
        return ""
    if written:
        return f"; {out} was written in full"
    if not out.exists():  # it was said to be "left as it was"
        return f"; {out} not created"
    return f"; nothing written to {out} (left as it was)"
