"""The ``pidcore`` entry point: exit statuses, Ctrl-C after a command, every help page."""

from __future__ import annotations

import argparse
import re
import signal
from pathlib import Path

import pytest

from pidcore.cli import build_parser, console_main

ROOT = Path(__file__).resolve().parents[1]
PAPER_SPECIMEN = ROOT / "pidcore" / "data" / "specimens" / "paper_coupon.toml"


def test_after_the_command_ctrl_c_is_ignored_so_shutdown_keeps_the_exit_status(capsys):
    previous = signal.getsignal(signal.SIGINT)
    try:
        assert console_main(["specimen", "check", str(PAPER_SPECIMEN)]) == 0
        # a SIGINT now (interpreter shutdown in a real process) must not raise
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        signal.raise_signal(signal.SIGINT)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert "capacity" in capsys.readouterr().out.lower()



def _all_parsers(parser: argparse.ArgumentParser):
    yield parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in action.choices.values():
                yield from _all_parsers(child)


def test_every_help_page_renders():
    # argparse expands %-formats in help texts only when --help is asked for: a bare '%'
    # (e.g. "fills, %") crashed `pidcore dem sweep --help` with a traceback
    parsers = list(_all_parsers(build_parser()))
    assert len(parsers) > 15  # every sub-command's parser, nested ones included
    for parser in parsers:
        text = parser.format_help()
        assert parser.prog in text


def test_the_sidecar_help_lists_every_column_the_table_reader_takes():
    # analyze and report each wrote the sidecar's columns and the --material default by hand
    # (one table, one rule: resolve_files); a column added to the reader went unlisted
    from pidcore.compare.loadcase import SETTINGS_COLUMNS

    helps = {}
    for parser in _all_parsers(build_parser()):
        if parser.prog.split()[-1] in ("analyze", "report"):
            helps[parser.prog] = {a.dest: " ".join(a.help.split()) for a in parser._actions
                                  if a.dest in ("sidecar", "material")}
    assert len(helps) == 2, helps
    for said in helps.values():
        # every column named as a word of the help
        named = {c for c in said["sidecar"].replace("(", " ").replace(")", " ")
                 .replace(",", " ").replace(";", " ").split() if c in SETTINGS_COLUMNS}
        assert named == set(SETTINGS_COLUMNS), said["sidecar"]
    assert len({said["material"].replace("PATH", "FILE") for said in helps.values()}) == 1


def test_errors_name_the_sub_command_and_its_action(capsys):
    # the message points at the --help that explains the option: `pidcore dem sweep --help`,
    # not `pidcore dem --help`, which lists no sweep option
    with pytest.raises(SystemExit) as exited:  # argparse's exit, as from the shell
        console_main(["dem", "sweep", "--bogus"])
    assert exited.value.code == 2
    err = capsys.readouterr().err
    assert err == ("pidcore dem sweep: error: unrecognized arguments: --bogus "
                   "(see pidcore dem sweep --help)\n")
    assert console_main(["dem", "sweep", "--fills", "0", "--no-progress"]) == 2
    assert capsys.readouterr().err.startswith("pidcore dem sweep: error: --fills: '0'")
    with pytest.raises(SystemExit):
        console_main(["analyze", "--bogus", "x.csv"])
    assert capsys.readouterr().err.startswith("pidcore analyze: error: unrecognized")


def test_bench_signal_with_too_few_samples_is_one_line_exit_2(capsys):
    """`pidcore bench signal --samples 5` ended in a ValueError traceback (exit 1)."""
    assert console_main(["bench", "signal", "--samples", "5"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--samples 5" in err[0] and "10000" in err[0], err


def test_report_calibration_help_says_a_folder_is_taken_too(capsys):
    """README: `--calibration DIR/calibration.json (of pidcore calibrate; or DIR)`; the help
    named only the file, though `--calibration data_samples/paper_calibration` works."""
    with pytest.raises(SystemExit):
        console_main(["report", "--help"])
    assert "(or the --out folder holding it)" in " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize("argv", [
    ["report", "--out", "r", "--dem-store", ""],
    ["analyze", ""],
    ["calibrate", "--data", " ", "--fit", "fixture_mass_kg"],
    ["specimen", "check", ""],
])
def test_an_empty_path_is_refused_naming_its_option_not_taken_as_the_current_folder(
        argv, capsys, tmp_path, monkeypatch):
    # `--dem-store "$UNSET"` was read as "." and refused as ".: is a folder"
    from pidcore.cli import main

    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as done:  # argparse's usage error
        main(argv)
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert "expected a path, got" in err
    assert list(tmp_path.iterdir()) == []  # nothing written


@pytest.mark.parametrize(("argv", "dests"), [
    (["report", "a.uff", "--out=~/rep", "--store=~/s.h5", "--dem-store=~/d.h5"],
     ["out", "store", "dem_store"]),
    (["model", "damper", "--out=~/d"], ["out"]),
    (["calibrate", "--data=~/m.csv", "--out=~/c", "--dem-store=~/c.h5"],
     ["data", "out", "dem_store"]),
    (["analyze", "~/a.uff", "--store=~/x.h5", "--sidecar=~/l.csv"], ["store", "sidecar"]),
    (["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", "50",
      "--store=~/x.h5", "--specimen=~/s.toml"], ["store", "specimen"]),
    (["app", "--store=~/x.h5"], ["store"]),
])
def test_a_leading_tilde_in_any_path_option_is_the_home_folder(argv, dests, monkeypatch,
                                                                 tmp_path):
    # --out=~/d (no shell expansion after '=') wrote into ./~/d (model damper, calibrate),
    # dem run --store=~/x.h5 was refused as "directory ~ does not exist", report --out made
    # ./~ and then failed in pandas (which expands ~ itself); only the app expanded it
    monkeypatch.setenv("HOME", str(tmp_path))
    args = build_parser().parse_args(argv)
    for dest in dests:
        value = getattr(args, dest)
        value = value[0] if isinstance(value, list) else value  # report's --dem-store: several
        assert value.parent == tmp_path and not str(value).startswith("~"), (dest, value)
    if argv[0] == "analyze":
        assert args.paths == [tmp_path / "a.uff"]


def test_every_path_option_takes_the_one_path_rule():
    # one rule for every path option: an option typed by hand would expand ~ (or not) its way
    from pidcore.cli._options import path_argument

    paths = [(parser.prog, action.option_strings or action.dest)
             for parser in _all_parsers(build_parser()) for action in parser._actions
             if re.fullmatch(r"FILE|DIR|PATH|CSV|TABLE\.csv|.*\.(h5|csv|json|toml)",
                             str(action.metavar or "")) and action.type is not path_argument]
    # kept specimen files are named by a sha256 or their path in the kept folder
    assert paths == [("pidcore specimen kept", "files")]


def test_a_tilde_of_no_such_user_is_refused_not_made_a_folder(capsys, tmp_path, monkeypatch):
    from pidcore.cli import main

    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as done:
        main(["model", "damper", "--out=~no_such_user_pidcore/d"])
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert "argument --out: ~no_such_user_pidcore/d: cannot expand ~no_such_user_pidcore" in err
    assert list(tmp_path.iterdir()) == []


def test_model_damper_out_with_a_tilde_writes_into_the_home_folder(capsys, tmp_path,
                                                                   monkeypatch):
    from pidcore.cli import main

    home, work = tmp_path / "home", tmp_path / "work"
    home.mkdir()
    work.mkdir()
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir(work)
    assert main(["model", "damper", "--out=~/damper"]) == 0
    assert (home / "damper").is_dir() and list(work.iterdir()) == []


class _Refused(Exception):
    pass


def _lenient_parsers():
    """Every parser, with nothing required (an option is parsed alone, no FILE missing), its
    usage errors raised as :class:`_Refused`."""
    for parser in _all_parsers(build_parser()):
        for action in parser._actions:
            action.required = False
        for group in parser._mutually_exclusive_groups:
            group.required = False

        def refuse(message: str, prog: str = parser.prog) -> None:
            raise _Refused(f"{prog}: {message}")
        parser.error = refuse
        yield parser


def _shortest_unique_prefix(option: str, others: list[str]) -> str | None:
    """The shortest prefix of a long ``option`` no other option of its parser starts with;
    None where there is none (it is itself a prefix of another: --fill of --fills)."""
    for end in range(3, len(option)):
        if not any(other.startswith(option[:end]) for other in others if other != option):
            return option[:end]
    return None


def test_no_option_of_any_command_is_taken_from_a_prefix_of_its_name():
    # argparse took a unique prefix as the whole option: `analyze --mass 0.003` ran as
    # --mass-below-gauge (SDC 1.139 -> 1.238, saved) and `store remove KEY --with` as
    # --with-dependents (a calibration removed too)
    tried = 0
    for parser in _lenient_parsers():
        options = [o for a in parser._actions for o in a.option_strings if o.startswith("--")]
        for option in options:
            prefix = _shortest_unique_prefix(option, options)
            if prefix is None:
                continue
            try:
                _, left = parser.parse_known_args([prefix])
            except SystemExit:  # --vers, --he: the version or the help, as if typed whole
                left = None
            assert left == [prefix], (parser.prog, prefix, option)
            tried += 1
    assert tried > 100  # every command's options, nested commands included


@pytest.mark.parametrize("number", ["-5e-5", "-1E+3", "-inf"])
def test_a_negative_number_in_any_float_notation_is_a_value_of_every_option(number):
    # argparse's pattern of a negative number knows no exponent: `--velocity-delay -5e-5`
    # said "expected one argument" instead of the option's own range check
    tried = 0
    for parser in _lenient_parsers():
        for action in parser._actions:
            if not action.option_strings or action.nargs is not None:  # no value of one
                continue
            try:
                parser.parse_known_args([action.option_strings[0], number])
            except _Refused as refused:  # the option's own check (a type, choices) is fine
                assert "expected one argument" not in str(refused), refused
            tried += 1
    assert tried > 100


def test_a_negative_delay_in_scientific_notation_meets_the_delays_own_check(capsys):
    assert console_main(["analyze", "x.csv", "--no-store", "--velocity-delay", "-5e-5"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pidcore analyze: error: --velocity-delay: -5e-05 s, expected a "
                          "delay >= 0 s"), err


def test_an_empty_item_of_any_comma_list_option_is_refused_naming_the_option():
    # `dem sweep --frequencies 50,,200` ran 2 load cases without a word (report --format
    # refused its empty item, model damper and calibrate --fit dropped theirs too)
    lists = []
    for parser in _lenient_parsers():
        for action in parser._actions:
            if not action.option_strings or action.nargs is not None or not (
                    "," in str(action.metavar) or action.metavar == "LIST"
                    or "comma" in (action.help or "")):
                continue
            option = action.option_strings[0]
            for given in ("50,,200", "csv,", ""):
                with pytest.raises(_Refused, match=f"argument {option}: expected comma-"
                                                   "separated values, none of them empty"):
                    parser.parse_known_args([option, given])
            lists.append(f"{parser.prog.removeprefix('pidcore ')} {option}")
    assert sorted(lists) == [
        "calibrate --fit", "dem sweep --accelerations", "dem sweep --fills",
        "dem sweep --frequencies", "model damper --accelerations", "model damper --fills",
        "model damper --format", "model damper --frequencies", "report --format"]


def _a_value(action: argparse.Action) -> str:
    """A word the option takes alone (its first choice, else one its type reads)."""
    if action.choices:
        return str(next(iter(action.choices)))
    for word in ("1", "a", "csv"):
        try:
            (action.type or str)(word)
        except (argparse.ArgumentTypeError, TypeError, ValueError):
            continue
        return word
    raise AssertionError(f"no value found for {action.option_strings}")


def test_every_single_valued_option_given_twice_is_refused_naming_both_values():
    # `analyze F --fill 70 --fill 30` saved 30 % and `--store a.h5 --store b.h5` wrote to
    # b.h5 without a word: the last one won. Options meant to be repeated (append: --invert,
    # --prior, report --dem-store) and flags (store_true) are left as they were
    repeatable = (argparse._AppendAction, argparse._CountAction, argparse._HelpAction,
                  argparse._VersionAction, argparse._SubParsersAction)
    tried = []
    for parser in _lenient_parsers():
        for action in parser._actions:
            if not action.option_strings or action.nargs == 0 or isinstance(action,
                                                                            repeatable):
                continue
            option, word = action.option_strings[0], _a_value(action)
            words = [word] * (action.nargs if isinstance(action.nargs, int) else 1)
            with pytest.raises(_Refused, match=re.escape(
                    f"argument {'/'.join(action.option_strings)}: given twice "
                    f"({' '.join(words)}, {' '.join(words)}); give it once")):
                parser.parse_known_args([option, *words, option, *words])
            tried.append(f"{parser.prog.removeprefix('pidcore ')} {option}")
    assert {"analyze --fill", "analyze --store", "dem sweep --fills"} <= set(tried)
    assert len(tried) > 100


def test_options_meant_to_be_repeated_still_take_every_value(tmp_path):
    parser = build_parser()
    args = parser.parse_args(["analyze", "f.csv", "--invert", "a", "--invert", "b",
                              "--allow-clipped", "--allow-clipped"])
    assert args.invert == ["a", "b"] and args.allow_clipped
    args = parser.parse_args(["report", "--out", "r", "--dem-store", "a.h5", "--dem-store",
                              "b.h5"])
    assert args.dem_store == [Path("a.h5"), Path("b.h5")]
