"""``pidcore analyze``: complex power, loss factor and SDC of shaker-test exports."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from .. import interrupt
from ..file_settings import analyze_each
from ..interrupt import untouched
from ..io import display_path
from ..measure import NO_LOAD_CASE
from ..units import value_and_error_texts
from ._options import (
    add_json_option,
    add_load_case_options,
    add_measurement_options,
    add_store_option,
    analysis_options,
    given_options,
    path_argument,
    print_json,
    progress_wanted,
)
from ._vocabulary import cli_words


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "analyze",
        help="loss factor and SDC from force/velocity exports (Eq. 11)",
        description="Analyse shaker-test exports (UFF58/58b, CSV/TXT, MAT, HDF5): complex power "
                    "(Eq. 11), loss factor, specific damping capacity, one record per file, "
                    "saved with its load case. "
                    "Each file is analysed with its sidecar row's settings (vibrometer delay, "
                    "channels, ...) unless an option overrides them. Results are saved to the "
                    "store unless --no-store.",
    )
    p.add_argument("paths", nargs="+", metavar="PATH", type=path_argument, help="export files")
    add_measurement_options(p)
    add_store_option(p)
    p.add_argument("--no-store", action="store_true", help="do not save to the store")
    g = p.add_argument_group(
        "load case (saved with each analysis, so that `pidcore report --store` places it; "
        "a file with no fill stated is saved without one)")
    add_load_case_options(g, what="PATH")
    g.add_argument("--specimen", metavar="FILE", type=path_argument, default=None,
                   help="specimen file whose particle material the files may state (e.g. "
                        "steel, which the material table lacks) and which is the default "
                        "material; its name and sha256 are saved with the files of its "
                        "particles whose sidecar names no specimen")
    p.add_argument("--key", metavar="NAME", default=None,
                   help="which measurement of a pidcore HDF5 store to analyse, when it holds "
                        "several (the error lists them)")
    add_json_option(p, progress=True)
    p.set_defaults(func=run)


def _stated(args: argparse.Namespace) -> tuple[list, list, object]:
    """What each path states about its load case (None: no fill stated) and how it is analysed
    (:class:`~pidcore.file_settings.FileSettings`), resolved before any analysis so that a bad
    sidecar or option is refused at once; and the ``--specimen`` (None: none given)."""
    from ..file_settings import resolve_files

    specimen = None
    if args.specimen is not None:
        from ..specimen import load_specimen

        specimen = load_specimen(args.specimen)
    # (a missing file is named by its analysis)
    stated, settings = resolve_files(
        args.paths, options=analysis_options(args), given=given_options(args),
        fill_percent=args.fill, material=args.material, direction=args.direction,
        sidecar=args.sidecar,
        specimen_material=specimen.particles.material if specimen else None,
        fill_required=False, specimen_name=specimen.name if specimen else None,
        specimen=specimen)
    return stated, settings, specimen


def run(args: argparse.Namespace) -> int:
    from ..compare.plausibility import refuse_implausible, stated_sdc_bounds
    from ..loadcase import refuse_identical_contents_stating_apart
    from ..store import Store

    stated, settings, specimen = _stated(args)
    # refused before any analysis (a folder, a foreign file); its commit count says after a
    # Ctrl-C whether the records were saved, even if it came as the commit returned
    store = None if args.no_store else Store(args.store)
    if store is not None:
        from ..measure import refuse_store_among_inputs

        refuse_store_among_inputs(store, args.paths)
        store.check_writable()  # before the analyses, in one line naming the store
    results: list = []
    bounds = stated_sdc_bounds(stated, settings, specimen)
    try:
        # Analyse everything before writing anything: one bad file leaves the store untouched.
        results = refuse_implausible(
            analyze_each(args.paths, settings, key=args.key, progress=progress_wanted(args),
                         keep_unused_channels=store is not None),
            [display_path(Path(path).name) for path in args.paths],
            accept=args.accept_implausible, bounds=bounds)
        cases = [st.load_case(r.analysis.frequency_hz, r.analysis.acceleration_g)
                 if st is not None else None for r, st in zip(results, stated, strict=True)]
        # one content is one measurement: two statements (load case, specimen, settings) about
        # it cannot both be saved
        refuse_identical_contents_stating_apart(
            (Path(path).name, r.measurement.sha256, (c.key if c else None, fs.statement()),
             ", ".join(w for w in (c.full_label() if c else NO_LOAD_CASE, fs.label()) if w))
            for path, r, c, fs in zip(args.paths, results, cases, settings, strict=True))
        replaced: list[str] = []
        breakdown = ""
        if store is not None:
            from ..measure import save_analyses

            saved = save_analyses(  # one transaction
                store, results, [fs.options for fs in settings],
                [(Path(path).name, c, st.origin if st is not None else "")
                 for path, c, st in zip(args.paths, cases, stated, strict=True)],
                # the bound each was judged with: a later reading without the specimen
                # file judges it alike (the store keeps the file's name and hash only)
                fields=[{**fs.record_fields(), **bound.as_record()} or None
                        for fs, bound in zip(settings, bounds, strict=True)])
            replaced, breakdown = saved.notes, saved.breakdown()
        interrupt.raise_if_interrupted()  # an interrupt swallowed on the way still counts
        # inside: a Ctrl-C while the results are written out still says what was saved
        _print_results(args, results, cases, stated, settings, replaced, breakdown,
                       specimen=specimen)
    except (KeyboardInterrupt, Exception) as exc:
        # after SIGINT any error is the interruption: pyuff's bare ``except:`` swallows the
        # KeyboardInterrupt and its half-read file then comes back as "no force channel"
        if not interrupt.is_interruption(exc):
            raise
        said = (f"interrupted after saving {_saved(results)} to {args.store}"
                if store is not None and store.commits else
                ("interrupted; nothing saved, the store is unchanged" if store.path.exists()
                 else f"interrupted; nothing saved, {untouched(store.path)}")
                if store is not None else
                "interrupted; nothing saved (--no-store)")
        print(f"pidcore analyze: {said}", file=sys.stderr)
        interrupt.mark_handled()
        return interrupt.exit_status()
    return 0


def _print_results(args: argparse.Namespace, results: list, cases: list, stated: list,
                   settings: list, replaced: list[str], breakdown: str = "", *,
                   specimen: object = None) -> None:
    """The results table (or JSON document), each file's load case and settings, what was
    assumed for it (``specimen``: the ``--specimen``), notes, and how many of the saved
    records were new (``breakdown``: :meth:`SavedAnalyses.breakdown`)."""
    from ..file_settings import assumed, assumption_notes, files_assumption_notes

    # each file's load case overridden, then its settings (the JSON lists both per record)
    overridden = [[*(cli_words(n) for n in (st.notes if st is not None else ())), *fs.notes]
                  for st, fs in zip(stated, settings, strict=True)]
    overrides = [note for said, fs in zip(overridden, settings, strict=True)
                 for note in (*said, fs.unmatched) if note]
    # what no statement gave (the paper's coupon and its acrylic): with each record in JSON
    assumptions = [assumed(st, fs.specimen, specimen)
                   for st, fs in zip(stated, settings, strict=True)]
    said_assumed = [[cli_words(n) for n in assumption_notes(display_path(Path(path).name), a)]
                    for path, a in zip(args.paths, assumptions, strict=True)]
    if args.json:
        print_json({"records": [{**r.to_dict(),
                                 "notes": [*(cli_words(n) for n in r.notes), *words],
                                 "load_case": c.key if c else None,
                                 "specimen": fs.specimen or None,
                                 "specimen_sha256": fs.specimen_sha256 or None,
                                 "assumed": a,
                                 "parameters": fs.options.parameters(),
                                 "settings_from": dict(fs.sources),
                                 "overridden": said,
                                 "sidecar_row_missing": fs.unmatched or None}
                                for r, c, said, fs, a, words in zip(
                                    results, cases, overridden, settings, assumptions,
                                    said_assumed, strict=True)],
                    "notes": [*overrides, *replaced,
                              *([f"saved {breakdown}"] if breakdown else [])]})
        return
    print(format_table(results))
    for path, c, st, fs in zip(args.paths, cases, stated, settings, strict=True):
        said = fs.summary()
        print(f"{display_path(Path(path).name)}: " + (f"load case {c.key} ({st.origin})" if c else
              "no fill stated: saved without a load case (state it in the file name, "
              "a sidecar or --fill for `pidcore report --store` to place it)"
              if not args.no_store else "no fill stated") + (f"; {said}" if said else ""))
    # once for the files it holds for, counted: one sentence per file repeated it
    for note in files_assumption_notes([(display_path(Path(path).name), a)
                                        for path, a in zip(args.paths, assumptions, strict=True)]):
        print(f"note: {cli_words(note)}")
    for note in [*overrides, *replaced]:
        print(f"note: {note}")
    if not args.no_store:
        print(f"saved {_saved(results)} to {args.store}"
              + (f" ({breakdown})" if breakdown else ""))


def _saved(results: list) -> str:
    """"3 record(s)", saying so when byte-identical files made fewer records than files."""
    from ..records import measurement_key

    n = len({measurement_key(r.measurement) for r in results})
    same = len(results) - n
    return f"{n} record(s)" + (f" ({same} file(s) with the same contents as another file "
                               "given: one record)" if same > 0 else "")


def _significant(value: float | None, digits: int, *, keep_zeros: bool = True) -> str:
    """``digits`` significant digits (trailing zeros kept: "5.0000" is five), "n/a" for none
    or NaN: fixed decimals showed a damping ratio of 4e-6 as 0.00000, a loss factor of 8.1e-6
    as 0.000008 (one digit) and a missing standard error as nan."""
    if value is None or not math.isfinite(value):
        return "n/a"
    return f"{value:#.{digits}g}" if keep_zeros else f"{value:.{digits}g}"


def format_table(results: list) -> str:
    # the whole file name: a cut one may no longer say which load case a row is
    names = [Path(r.analysis.source).name for r in results]
    width = max([40, *map(len, names)])
    header = (f"{'source':<{width}} {'frequency [Hz]':>14} {'accel. [g]':>10} "
              f"{'loss factor [-]':>15} {'SDC [-]':>12} {'± SE [-]':>12} {'zeta [-]':>10} "
              f"{'dE/cycle [J]':>12}")
    lines = [header, "-" * len(header)]
    for r, name in zip(results, names, strict=True):
        a = r.analysis
        # as the app shows it (pidcore.app.uploads.format_sdc): one SDC, one text
        sdc_shown, stderr_shown = value_and_error_texts(a.sdc, a.sdc_stderr, missing="n/a")
        lines.append(f"{name:<{width}} {a.frequency_hz:14.4f} "
                     f"{_significant(a.acceleration_g, 5):>10} "
                     f"{_significant(a.loss_factor, 6):>15} {sdc_shown:>12} "
                     f"{stderr_shown or 'n/a':>12} "
                     f"{_significant(a.damping_ratio, 4):>10} {a.energy_per_cycle_j:12.4e}")
        lines += [f"    note: {cli_words(note)}" for note in r.notes]
    return "\n".join(lines)
