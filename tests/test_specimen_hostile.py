"""Hostile specimen files (found by an own-specimen trial of the Predict workflow): each is
one line naming the file and key, exit 2, before anything is simulated or stored."""

from __future__ import annotations

from pathlib import Path

import pytest

from pidcore.cli import main
from pidcore.errors import ParameterError
from pidcore.specimen import Specimen

REPO = Path(__file__).resolve().parents[1]
STEEL = REPO / "data_samples" / "specimens" / "steel_6mm.toml"
TEXT = STEEL.read_text(encoding="utf-8")


def _edit(old: str, new: str, text: str = TEXT) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def _one_line_exit_2(argv: list[str], capsys) -> str:
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    return err


def test_an_integer_past_pythons_digit_limit_is_one_line_naming_the_file(tmp_path, capsys):
    """tomllib reads a 5000-digit integer into int(), which raised a bare ValueError
    (traceback, exit 1) through `specimen check` and `dem run --specimen`."""
    path = tmp_path / "long.toml"
    path.write_text(_edit("count = 286", "count = " + "9" * 5000))
    with pytest.raises(ParameterError, match=r"long.toml: not a specimen file \(an integer "
                                             r"of more than 4300 digits"):
        Specimen.from_text(path.read_text(), source=str(path))
    err = _one_line_exit_2(["specimen", "check", str(path)], capsys)
    assert str(path) in err and "integer of more than" in err
