"""Running the CLI in-process from tests: one analysed record as JSON, one one-line refusal."""

from __future__ import annotations

import json
from pathlib import Path

from pidcore.cli import main


def analyze_json(path: Path, capsys, *extra: str) -> dict:
    """The one record ``pidcore analyze PATH --json --no-store`` prints (exit 0 asserted)."""
    assert main(["analyze", str(path), "--json", "--no-store", "--no-progress", *extra]) == 0
    (record,) = json.loads(capsys.readouterr().out)["records"]
    return record


def refusal(args: list[str], capsys) -> str:
    """The error ``pidcore ARGS`` refuses with: exit 2 and one line on stderr (asserted)."""
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    return err.strip()
