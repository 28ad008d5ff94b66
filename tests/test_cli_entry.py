"""The ``pidcore`` entry point: a finished command's exit status cannot be changed by Ctrl-C."""

from __future__ import annotations

import signal
from pathlib import Path

from pidcore.cli import console_main

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

