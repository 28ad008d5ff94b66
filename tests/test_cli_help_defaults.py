"""Every ``--help`` names the default of an option that has one."""

from __future__ import annotations

import argparse

from pidcore.cli import build_parser


def _options(parser: argparse.ArgumentParser, path: tuple[str, ...] = ()):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _options(sub, (*path, name))
        elif action.option_strings:
            yield path, action


def test_every_option_with_a_default_names_it_in_its_help():
    # dem run --help gave no default for --direction, --damping-coefficient,
    # --mass-convention, --start and --fill-reference (with_cell is not the choice a reader
    # would guess), nor calibrate for --method, bench signal for --repeat. An option whose
    # default is a value (not None, False or an empty list) says it: "default X", or where
    # the value depends on other options, "default:" and what it is
    missing = []
    for path, action in _options(build_parser()):
        if action.default in (None, False, argparse.SUPPRESS) or action.default == []:
            continue
        text = " ".join((action.help or "").split())
        if "default" not in text:
            missing.append(f"{' '.join(path)} {action.option_strings[0]}")
    assert not missing, missing
