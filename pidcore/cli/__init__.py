"""Command-line interface ``pidcore``: a thin layer over the library.

Each sub-command lives in its own module with ``register(subparsers)``; all logic is in the
library. Errors derived from :class:`pidcore.errors.PidcoreError` become one line on stderr and
exit code 2; Ctrl-C exits 130 (SIGTERM 143, SIGHUP 129) after finished work has been saved.
"""

from __future__ import annotations

import argparse
import codecs
import importlib
import sys
from collections.abc import Callable

from .. import interrupt
from ..console import COMMANDS, command_name
from ..errors import PidcoreError

#: Sub-command modules, each exposing ``register(subparsers) -> None``.
_COMMAND_MODULES = tuple(COMMANDS)


class _NegativeNumber:
    """argparse's ``_negative_number_matcher``: whether a word is a negative number, as
    :func:`float` reads it (``-5e-5``, ``-.5``, ``-inf``)."""

    def match(self, word: str) -> bool:
        if not word.startswith("-"):
            return False
        try:
            float(word)
        except ValueError:
            return False
        return True


class _GivenOnce(argparse._StoreAction):
    """The default action of every option: a single value, refused when given a second time.
    ``analyze --fill 70 --fill 30`` saved 30 % and ``--store a.h5 --store b.h5`` wrote to
    b.h5 without a word, where one of the two was a slip; options meant to be repeated say so
    with ``action="append"`` (``--invert``, ``--prior``) and flags may repeat harmlessly."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        given = parser._given_once  # this parse's words per option (_OneLineParser)
        words = " ".join(parser._last_words)
        if self.dest in given:
            raise argparse.ArgumentError(
                self, f"given twice ({given[self.dest]}, {words}); give it once")
        given[self.dest] = words
        super().__call__(parser, namespace, values, option_string)


class _OneLineParser(argparse.ArgumentParser):
    """Usage errors as one line naming the sub-command (``pidcore analyze: error: ...``), exit 2;
    the usage stays one ``--help`` away. Sub-parsers inherit the class."""

    def __init__(self, *args, **kwargs) -> None:
        # no prefixes of long options: `--mass 0.003` ran as --mass-below-gauge and
        # `store remove --with` as --with-dependents, and an option added later would
        # silently change what an old abbreviation means
        kwargs["allow_abbrev"] = False
        super().__init__(*args, **kwargs)
        # argparse takes "-5e-5" for an option (its pattern knows no exponent) and says
        # "expected one argument"; a value in any float notation is a value, so that the
        # option's own check speaks ("expected a delay >= 0 s")
        self._negative_number_matcher = _NegativeNumber()
        self.register("action", None, _GivenOnce)  # add_argument without an action
        self._given_once: dict[str, str] = {}
        self._last_words: list[str] = []

    def parse_known_args(self, args=None, namespace=None):
        self._given_once = {}  # each parse counts its own (a sub-command's parser: its own)
        return super().parse_known_args(args, namespace)

    def _get_values(self, action, arg_strings):
        # the words as typed, for _GivenOnce's message: its values are converted (70.0 for
        # "70", a Path)
        self._last_words = list(arg_strings)
        return super()._get_values(action, arg_strings)

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``pidcore`` parser; with a known sub-command ``command``, only that one's module is
    imported and registered (a command's start-up should not pay for the imports of all the
    others: numba, scipy.optimize, the DEM and calibration code take ~0.5 s); otherwise all,
    so that ``pidcore --help`` and an unknown command's error list every command."""
    from .. import __version__  # not at import: see pidcore.__getattr__

    parser = _OneLineParser(
        prog="pidcore",
        description="Particle impact damping: measure, predict (DEM) and compare SDC.",
    )
    parser.add_argument("--version", action="version", version=f"pidcore {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in (command,) if command in _COMMAND_MODULES else _COMMAND_MODULES:
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


def _escape_unencodable(exc: UnicodeError) -> tuple[str, int]:
    """Codec error handler ``pidcore.display``: a file name byte that is not UTF-8 (a
    surrogate of ``os.fsdecode``) as ``\\xNN``, as :func:`pidcore.io.display_path` shows it;
    any other character the stream cannot encode as a backslash escape."""
    if not isinstance(exc, UnicodeEncodeError):
        raise exc
    bad = exc.object[exc.start:exc.end]
    return "".join(f"\\x{ord(c) - 0xDC00:02x}" if 0xDC80 <= ord(c) <= 0xDCFF else
                   c.encode("ascii", "backslashreplace").decode("ascii")
                   for c in bad), exc.end


codecs.register_error("pidcore.display", _escape_unencodable)


def _displayable_streams() -> Callable[[], None]:
    """stdout and stderr made to show what they cannot encode (a store or folder named in
    Latin-1 bytes, printed in a UTF-8 terminal: a UnicodeEncodeError traceback after the
    analyses were saved); returns what puts them back."""
    undo = []
    for stream in (sys.stdout, sys.stderr):
        errors = getattr(stream, "errors", None)
        if errors in (None, "pidcore.display") or not hasattr(stream, "reconfigure"):
            continue
        try:
            stream.reconfigure(errors="pidcore.display")
        except (ValueError, OSError):  # a stream that cannot change its handler: as it is
            continue
        undo.append((stream, errors))

    def restore() -> None:
        for stream, errors in undo:
            try:
                stream.reconfigure(errors=errors)
            except (ValueError, OSError):
                pass
    return restore


def main(argv: list[str] | None = None) -> int:
    return _main(argv)[0]


def _main(argv: list[str] | None, *, then_ignore: bool = False) -> tuple[int, bool]:
    """:func:`main`'s exit status, and whether the command was interrupted (which the flag,
    cleared on the way out, no longer says). ``then_ignore``: leave SIGINT, SIGTERM and SIGHUP
    ignored afterwards (:func:`console_main`) instead of putting the previous handlers back."""
    # First thing: Ctrl-C during the imports below (every sub-command) or inside Numba must
    # end as one line and exit 130, and an interrupt swallowed somewhere must still stop the
    # store from committing (pidcore.interrupt). Install and restore lie inside the try: a
    # Ctrl-C just after install, before _run's own try, escaped as a traceback.
    restore = None
    streams = None
    interrupt.reset()
    try:
        restore = interrupt.install()
        streams = _displayable_streams()
        rc = _run(argv)
        return rc, interrupt.interrupted()
    except KeyboardInterrupt:  # before _run's try, or after it returned
        return _interrupted(command_name(sys.argv[1:] if argv is None else argv), None), True
    finally:
        with interrupt.deferred():  # a Ctrl-C here is recorded, not raised: the run is over
            if streams is not None:
                streams()
            if restore is not None:
                restore(ignore_signals=then_ignore)
            elif then_ignore:
                interrupt.ignore()
        interrupt.reset()  # an in-process caller (app, tests) may commit again afterwards


def _run(argv: list[str] | None) -> int:
    words = sys.argv[1:] if argv is None else argv
    command = command_name(words)  # until the parser names it
    started = False
    args: argparse.Namespace | None = None
    out_before: tuple[int, int] | None = None
    try:
        parser = build_parser(command.split(" ", 1)[0])
        args, unknown = parser.parse_known_args(argv)
        command = _command_name(args)
        if unknown:  # reported by the top parser, which would not name the sub-command
            parser.exit(2, f"pidcore {command}: error: unrecognized arguments: "
                           f"{' '.join(unknown)} (see pidcore {command} --help)\n")
        from ..specimen import hearing_read_notes  # before the start: nothing done yet

        out_before = _out_before(args)
        started = True
        # what reading a --specimen file did first (a killed calibration's moves into its
        # folder finished) said here, for every command that takes one, as their notes are
        with hearing_read_notes(lambda note: _say_note(note, command, words)):
            rc = int(args.func(args) or 0)
        if rc != interrupt.exit_status() and interrupt.interrupted():
            raise KeyboardInterrupt  # swallowed on the way: still the interruption
        return rc
    except PidcoreError as exc:
        if interrupt.interrupted():  # an interrupt swallowed by a library (pyuff's bare
            # ``except:``) left data out and surfaced as a refusal: it is the interruption
            return _interrupted(command, args if started else None, out_before)
        print(f"pidcore {command}: error: {_in_flags(exc, command, words)}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # the reader of stdout (| head) stopped: end quietly
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except (KeyboardInterrupt, Exception) as exc:
        # an interrupt, or what one turned into inside C code (pidcore.interrupt)
        if not interrupt.is_interruption(exc):
            raise
        # commands that count what they saved say so themselves (analyze, dem, calibrate);
        # here only what holds for every command: a store write is whole or absent, never
        # half-done, and an output folder holds part of the files or, replaced whole, one set
        return _interrupted(command, args if started else None, out_before)


def _out_before(args: argparse.Namespace) -> tuple[int, int] | None:
    """The identity of a command's ``--out`` before it runs, where the command replaces it
    whole (``out_written_whole_by``: its name in :mod:`pidcore.out_folder`'s records)."""
    command = getattr(args, "out_written_whole_by", None)
    if command is None:
        return None
    from ..out_folder import identity_before

    return identity_before(args.out, command)


def _interrupted(command: str, args: argparse.Namespace | None,
                 out_before: tuple[int, int] | None = None) -> int:
    """Say on stderr that ``pidcore COMMAND`` was interrupted and what it may have left
    (``args``: the command's, None before it started: nothing was done; ``out_before``: its
    :func:`_out_before`); returns the exit status of an interruption, marked handled."""
    said = _what_an_interrupt_left(args, out_before) if args is not None else \
        "nothing was done"
    print(f"pidcore {command}: interrupted; {said}", file=sys.stderr)
    interrupt.mark_handled()
    return interrupt.exit_status()


def _say_note(note: str, command: str, words: list[str]) -> None:
    """Say a library's note on stderr as ``pidcore COMMAND: note: ...``, in the command's
    words (stderr: a command's --json prints one document on stdout)."""
    print(f"pidcore {command}: note: {_in_command_words(note, command, words)}",
          file=sys.stderr)


def _in_command_words(text: str, command: str, words: list[str]) -> str:
    """A library text in the words of ``pidcore COMMAND`` (:func:`cli_words`), the names the
    command line gave (a file, a folder, a key) left as the user wrote them."""
    from ._vocabulary import cli_words

    # what the command line gave is the user's, whatever it holds
    given = [w.split("=", 1)[1] if w.startswith("--") and "=" in w else w for w in words]
    return cli_words(text, command, names=[w for w in given if not w.startswith("-")])


def _in_flags(exc: PidcoreError, command: str, words: list[str]) -> str:
    """A library refusal in the words of ``pidcore COMMAND``: the parameters it names by their
    keyword (``structure_mass_kg``) as the flags the user types (``--structure-mass``). A
    settings table's refusal names the table's columns, which are no flags, and stays as it
    is."""
    from ..errors import SettingsTableError

    return str(exc) if isinstance(exc, SettingsTableError) else \
        _in_command_words(str(exc), command, words)


def _what_an_interrupt_left(args: argparse.Namespace,
                            out_before: tuple[int, int] | None) -> str:
    """What an interrupted command may have left, from the options it was given: a store
    (``--store``/``--dem-store``; none with ``--no-store``) whose writes are whole or absent,
    an ``--out`` folder that may hold part of the files, or where the command replaces it
    whole (``model figures``: "mf may hold part" was untrue) the folder as it was or the
    run's whole set. Only what the command has: an "output folder" said of ``analyze
    --no-store`` named something it does not have."""
    stores = [] if getattr(args, "no_store", False) else \
        [s for s in (getattr(args, "store", None), getattr(args, "dem_store", None)) if s]
    out = getattr(args, "out", None)
    if out is None:
        outputs = None
    elif getattr(args, "out_written_whole_by", None) is not None:
        from ..out_folder import interrupted_outputs

        outputs = interrupted_outputs(out, out_before)
    else:
        outputs = f"{out} may hold part of this run's files"
    if stores and outputs is not None:
        return f"no store write was left half-done; {outputs}"
    if stores:
        return "no store write was left half-done"
    return outputs if outputs is not None else "nothing was saved"


def _command_name(args: argparse.Namespace) -> str:
    """``dem sweep`` for ``pidcore dem sweep ...``: the command with its action, if it has one
    (errors name the parser whose --help explains them)."""
    action = getattr(args, f"{args.command}_command", None)
    return f"{args.command} {action}" if isinstance(action, str) else args.command


def console_main(argv: list[str] | None = None) -> int:
    """Entry point of the ``pidcore`` command and of ``python -m pidcore``: :func:`main`, then
    Ctrl-C, SIGTERM and SIGHUP ignored for the rest of the process.

    The command is over by then (whatever it saved is committed and reported); a Ctrl-C that
    lands while the interpreter shuts down would otherwise end the process by the signal
    (exit status -2) instead of the command's own status.
    """
    # _main ignores the signals itself, straight from its own handler: a separate ignore()
    # here left a moment with Python's default handler (a Ctrl-C there was a traceback)
    rc, interrupted = _main(argv, then_ignore=True)
    if interrupted:  # what the interrupted run left half-built is torn down at exit
        interrupt.silence_teardown()
    return rc


if __name__ == "__main__":  # pragma: no cover
    sys.exit(console_main())
