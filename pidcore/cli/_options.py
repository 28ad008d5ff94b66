"""Option groups shared by several sub-commands (one definition, one set of defaults)."""

from __future__ import annotations

import argparse
import os
import shlex
import sys
from pathlib import Path

from .. import defaults
from ..errors import ParameterError
from ..measure import AnalysisOptions

#: Help of ``--store`` where it names the default store.
STORE_HELP = f"HDF5 store (default ./{defaults.STORE_PATH})"


def command_line(*words: str | os.PathLike[str]) -> str:
    """``words`` as one shell line that runs them as given, each quoted where a shell would
    read it otherwise (:func:`shlex.quote`): every command line pidcore prints for the user
    to run. A next step naming ``store % [1].h5`` bare was three words and a glob; a plain
    path (``runs.h5``) stays as it is."""
    return shlex.join(os.fspath(word) for word in words)


def _whole_number(text: str, minimum: int) -> int:
    try:
        value = int(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from exc
    if value < minimum:
        raise argparse.ArgumentTypeError(f"expected a whole number >= {minimum}, got {text!r}")
    return value


def path_argument(text: str) -> Path:
    """argparse type: a file or folder path, refused when empty (``--dem-store ""`` from an
    unset shell variable was taken as the current folder: ".: is a folder").

    A leading ``~`` or ``~user`` is expanded, as the shell does for ``--out ~/x`` but not for
    ``--out=~/x`` or a quoted ``"~/x"``: those made a folder ``./~`` (``model damper``,
    ``calibrate``), were refused as "directory ~ does not exist" (``dem run --store``) or
    expanded by pandas alone (``report --out``), and ``pidcore app --store`` expanded it. A
    ``~user`` of no such user is refused, not made a folder of that name."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"expected a path, got {text!r}")
    expanded = os.path.expanduser(text)
    if expanded == text and text.startswith("~"):
        head = text.split("/", 1)[0]
        raise argparse.ArgumentTypeError(
            f"{text}: cannot expand {head} (no such user, or no home folder); expected ~/PATH, "
            f"~USER/PATH of a user of this system, or ./{text} for a folder named {head}")
    return Path(expanded)


def comma_list(text: str) -> list[str]:
    """argparse type of every comma-separated list option (``--fills 40,60``, ``--format
    csv,md``): its items, stripped, an empty one refused: ``--frequencies 50,,200`` ran 2
    load cases without a word, where a value meant was lost between the commas."""
    items = [item.strip() for item in text.split(",")]
    if not all(items):
        raise argparse.ArgumentTypeError(
            f"expected comma-separated values, none of them empty, got {text!r}")
    return items


def positive_int(text: str) -> int:
    """argparse type: a whole number >= 1 (a count of repetitions, samples or processes)."""
    return _whole_number(text, 1)


def non_negative_int(text: str) -> int:
    """argparse type: a whole number >= 0 (a random seed)."""
    return _whole_number(text, 0)


def add_load_case_options(p: argparse._ActionsContainer, *, what: str) -> None:
    """``--fill``, ``--material``, ``--direction``, ``--sidecar``: the load case of every
    ``what`` (the positional's name), as :func:`pidcore.compare.loadcase.resolve_load_case`
    reads them (``pidcore analyze`` and ``pidcore report`` alike, ``--specimen`` included)."""
    from ..compare.loadcase import (
        ANALYSIS_SETTINGS_COLUMNS,
        SIDECAR_COLUMNS,
        SIDECAR_NAME,
        SPECIMEN_COLUMN,
    )
    from ..constants import DRIVE_DIRECTIONS, PARTICLE_MATERIALS

    p.add_argument("--fill", metavar="PERCENT", type=float, default=None,
                   help=f"packing ratio of every {what}, %% (overrides file name and sidecar)")
    p.add_argument("--material", metavar="NAME", default=None,
                   help=f"particle material of every {what}: {', '.join(PARTICLE_MATERIALS)}"
                        " or the --specimen's (default: stated, else the specimen's, else "
                        "acrylic)")
    p.add_argument("--direction", choices=DRIVE_DIRECTIONS, default=None,
                   help=f"drive direction of every {what} (default: stated or z)")
    # the table's columns as the reader knows them: a column added there is listed here
    p.add_argument("--sidecar", metavar="CSV", type=path_argument, default=None,
                   help=f"per-file table: load case ({', '.join(SIDECAR_COLUMNS)}) and "
                        f"analysis settings ({', '.join(ANALYSIS_SETTINGS_COLUMNS)}, "
                        f"{SPECIMEN_COLUMN}); options given override it; default: "
                        f"{SIDECAR_NAME} beside each file")


def check_out_folder(out: Path, *, built_beside: bool = False) -> None:
    """``--out`` must be a folder or not exist yet (a file there would be half-overwritten),
    and one pidcore may write: its files are written in it, where it exists, else it is made
    beside its siblings; ``built_beside``, its files are also built in a folder beside it
    (:func:`pidcore.atomic_files.new_temporary_folder_for`). Checked before any work, so a
    long run is not thrown away at the end."""
    from ..atomic_files import check_folder_can_be_made, file_in_the_way, real_folder

    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out {out}: exists and is not a folder")
    blocking = file_in_the_way(out)
    if blocking is not None:
        raise ParameterError(f"--out {out}: {blocking} is a file, not a folder")
    if out.is_dir():  # a build folder's name in it: its files' temporaries are made there
        check_folder_can_be_made(out / "out", label=f"--out {out}")
    if built_beside or not out.is_dir():
        # a link's folder is replaced where it lies, built beside it (pidcore.out_folder)
        for place in dict.fromkeys((out, real_folder(out))):
            check_folder_can_be_made(place, label=f"--out {out}")


def add_store_option(p: argparse.ArgumentParser, *, flag: str = "--store",
                     default: Path | None = defaults.STORE_PATH,
                     help: str = STORE_HELP) -> None:
    """An HDF5 store file option (``--store``, ``--dem-store``) read as a :class:`Path`."""
    p.add_argument(flag, metavar="FILE", type=path_argument, default=default, help=help)


def progress_wanted(args: argparse.Namespace) -> bool:
    """Whether a command draws progress bars: not with ``--no-progress``, and only on a
    terminal. tqdm redraws its bar with carriage returns, which a log file or a pipe keeps
    as one long line of every redraw (``pidcore dem sweep ... 2> log``)."""
    if getattr(args, "no_progress", False):
        return False
    isatty = getattr(sys.stderr, "isatty", None)
    return bool(isatty and isatty())


def scheduler_address(text: str) -> str:
    """argparse type: a dask.distributed scheduler address, refused when empty (``--scheduler
    "$SCHEDULER"`` with the variable unset ran the sweep on local processes without a word)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"expected a scheduler address such as "
                                         f"tcp://host:8786, got {text!r}")
    return text.strip()


def displayed_names(document):
    """A ``--json`` document with every file name in it as :func:`pidcore.io.display_path`
    shows it: the bytes of a name that are not UTF-8 (``os.fsdecode``'s surrogates, a store
    ``st_\\xff.h5``) as ``\\xNN``, as analyze stores a file's name. ``store list`` printed
    ``"st_\\udcff.h5"``, a lone surrogate strict JSON readers refuse, where analyze printed
    ``"ex2_\\\\xff..."``: one rule for every name, wherever in the document it lies (a path,
    a note naming one, a key)."""
    from ..io import display_path

    if isinstance(document, dict):
        return {displayed_names(k): displayed_names(v) for k, v in document.items()}
    if isinstance(document, (list, tuple)):
        return [displayed_names(v) for v in document]
    if isinstance(document, os.PathLike):
        return display_path(document)
    if isinstance(document, str) and any("\udc80" <= c <= "\udcff" for c in document):
        return display_path(document)
    return document


def print_json(document) -> None:
    """Print a command's ``--json`` document, one line on stdout (:func:`displayed_names`)."""
    import json

    print(json.dumps(displayed_names(document)))


def add_json_option(p: argparse.ArgumentParser, *, progress: bool = False) -> None:
    """``--json`` (one JSON document on stdout) and, with ``progress``, ``--no-progress``."""
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")
    if progress:
        p.add_argument("--no-progress", action="store_true", help="no progress bar")


def add_measurement_options(p: argparse.ArgumentParser) -> None:
    """Channel mapping and corrections of the Eq. 11 analysis (``analyze``, ``report``)."""
    g = p.add_argument_group("measurement analysis")
    # Defaults None: an option given overrides a sidecar's value for every file, one not
    # given leaves it (analysis_options fills in the defaults, given_options says which were
    # given)
    g.add_argument("--force", metavar="NAME",
                   help="force channel name (default: sidecar's, else detected)")
    g.add_argument("--velocity", metavar="NAME", help="velocity channel name")
    g.add_argument("--acceleration", metavar="NAME", help="acceleration channel name")
    g.add_argument("--velocity-delay", metavar="SECONDS", type=float, default=None,
                   help="vibrometer output delay to remove, s (default: the sidecar's "
                        "velocity_delay_us, else 0)")
    g.add_argument("--mass-below-gauge", metavar="KG", type=float, default=None,
                   help="mass between force gauge and structure to cancel, kg (default: the "
                        "sidecar's mass_below_gauge_g, else 0)")
    g.add_argument("--baseline-loss-factor", metavar="ETA", type=float, default=None,
                   help="loss factor of the empty coupon to subtract (default: the sidecar's, "
                        "else 0)")
    g.add_argument("--structure-mass", metavar="KG", type=float, default=None,
                   help="mass of that empty structure (coupon and fixture above the gauge), "
                        "kg: its own dissipation is subtracted (default: the sidecar's "
                        "structure_mass_g; none: the baseline is taken off the whole vibrated "
                        "mass, which takes too much, noted)")
    g.add_argument("--frequency", metavar="HZ", type=float, default=None,
                   help="drive frequency hint, Hz (estimated from the data anyway)")
    g.add_argument("--harmonics", metavar="N", type=int, default=defaults.N_HARMONICS,
                   help=f"drive harmonics fitted (default {defaults.N_HARMONICS})")
    g.add_argument("--sample-rate", metavar="HZ", type=float, default=None,
                   help="sample rate, Hz, for CSV/TXT files and MAT files of plain "
                        "vectors; overrides their time column (noted in the output); UFF, "
                        "HDF5 and Testlab/pidcore MAT files keep their own rate (noted)")
    g.add_argument("--allow-clipped", action="store_true",
                   help="analyse clipped channels anyway (reported in the output)")
    g.add_argument("--accept-implausible", action="store_true",
                   help="keep a result the plausibility checks refuse (a negative loss factor "
                        "beyond its noise, an SDC above the bound of the specimen's "
                        "particles, max(2 pi, 8 m_p/m_s), 2 pi where the specimen or fill is "
                        "unknown: usually a wrong delay, sign or correction), noted with the "
                        "record")
    g.add_argument("--force-unit", metavar="UNIT", default=None,
                   help="unit of the force channel's values (N, kN, mN, lbf, ...) when the "
                        "file gives none or a wrong one; case-sensitive as SI writes it (mN, "
                        "not MN)")
    g.add_argument("--velocity-unit", metavar="UNIT", default=None,
                   help="unit of the velocity channel's values (m/s, mm/s, um/s, in/s, ...); "
                        "case-sensitive (mm/s, not Mm/s)")
    g.add_argument("--acceleration-unit", metavar="UNIT", default=None,
                   help="unit of the acceleration channel's values (m/s^2, g, ...); "
                        "case-sensitive")
    g.add_argument("--time-unit", metavar="UNIT", default=None,
                   help="unit of the file's time base (s, ms, us): a UFF abscissa whose label "
                        "pidcore does not read (refused without it), a CSV time column or "
                        "MATLAB time vector without a unit (otherwise seconds, noted), a "
                        "Testlab MAT signal's x_values; overrides the file's (noted); a CSV "
                        "whose time header is not read (Abscissa) takes its first column "
                        "as the time in this unit")
    g.add_argument("--invert", metavar="NAME", action="append", default=None,
                   help="invert the sign of this channel (a sensor mounted the other way); "
                        "repeatable; replaces the sidecar's invert column")


#: Options fields of :func:`add_measurement_options` a sidecar may also state, and their flags.
SIDECAR_OPTION_FLAGS: dict[str, str] = {
    "force": "--force", "velocity": "--velocity", "acceleration": "--acceleration",
    "velocity_delay_s": "--velocity-delay", "mass_below_gauge_kg": "--mass-below-gauge",
    "baseline_loss_factor": "--baseline-loss-factor", "structure_mass_kg": "--structure-mass",
    "invert": "--invert", "time_unit": "--time-unit",
}


def given_options(args: argparse.Namespace) -> dict[str, str]:
    """The options fields given on the command line -> their flags: these override a
    sidecar's values (:func:`pidcore.file_settings.resolve_file_settings`)."""
    return {name: flag for name, flag in SIDECAR_OPTION_FLAGS.items()
            if getattr(args, flag[2:].replace("-", "_")) is not None}


def analysis_options(args: argparse.Namespace) -> AnalysisOptions:
    """The :class:`AnalysisOptions` the options of :func:`add_measurement_options` state
    (defaults filled in for those not given)."""
    def given(value: float | None) -> float:
        return 0.0 if value is None else value

    return AnalysisOptions(
        force=args.force, velocity=args.velocity, acceleration=args.acceleration,
        velocity_delay_s=given(args.velocity_delay),
        mass_below_gauge_kg=given(args.mass_below_gauge),
        baseline_loss_factor=given(args.baseline_loss_factor),
        structure_mass_kg=args.structure_mass, frequency_hz=args.frequency,
        n_harmonics=args.harmonics, sample_rate_hz=args.sample_rate,
        allow_clipped=args.allow_clipped, force_unit=args.force_unit,
        velocity_unit=args.velocity_unit, acceleration_unit=args.acceleration_unit,
        invert=tuple(args.invert or ()), time_unit=args.time_unit,
    )
