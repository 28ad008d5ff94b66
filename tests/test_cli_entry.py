"""The ``pidcore`` entry point: exit statuses, Ctrl-C after a command, every help page."""

from __future__ import annotations

import argparse
import signal
from pathlib import Path

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
