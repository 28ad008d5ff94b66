"""Which CSV column is the time base when its header is not one pidcore reads as a time
(``Abscissa``, ``Zeit_ms``, ``Time [msek]``): with ``--time-unit`` given, the first column
named as a time whose unit is not read, else the first column whose header states no other
quantity, read in the unit given (noted); without it, a one-line refusal naming the file and
the column. Before, such a file was refused as having "no time column" even with
``--time-unit ms`` given (the option could not rescue it), without naming the column.
Headers of a unit written ``Time - sec`` are read from the header itself."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _cli_runs import analyze_json, refusal

from pidcore.errors import InputFileError
from pidcore.io import read_measurement

RATE_HZ = 5000.0
DRIVE_HZ = 125.0


def export(path: Path, time_header: str, seconds_per_unit: float,
           others: tuple[str, str] = ("Force [N]", "Velocity [m/s]")) -> Path:
    """0.4 s of a 125 Hz force and velocity at 5 kHz under ``time_header``, the time column
    written in its unit (``seconds_per_unit``)."""
    t = np.arange(2000) / RATE_HZ
    w = 2 * math.pi * DRIVE_HZ
    rows = zip(t / seconds_per_unit, 3.0 * np.sin(w * t), 0.01 * np.sin(w * t - 1.0),
               strict=True)
    path.write_text("\n".join([",".join((time_header, *others))]
                              + [f"{a:.12g},{b:.12g},{c:.12g}" for a, b, c in rows]) + "\n",
                    encoding="utf-8")
    return path


@pytest.mark.parametrize(("header", "unit", "seconds"), [
    ("Abscissa", "ms", 1e-3), ("Zeit_ms", "ms", 1e-3), ("Time [msek]", "ms", 1e-3),
    ("Abscissa", "s", 1.0), ("Time - xyz", "us", 1e-6),
])
def test_time_unit_reads_a_first_column_of_an_unread_header(tmp_path, capsys, header, unit,
                                                            seconds):
    path = export(tmp_path / "run_fill50.csv", header, seconds)
    record = analyze_json(path, capsys, "--time-unit", unit)
    # the rate and drive line of the samples written, not 1000 x off (analytic truth: the
    # noiseless 125 Hz line over 50 periods is found to far better than 1e-6)
    assert record["frequency_hz"] == pytest.approx(DRIVE_HZ, rel=1e-6)
    said = [n for n in record["notes"] if "time column" in n]
    assert any(f"taken as {unit!r} (--time-unit)" in n for n in said), said
    # the header's words stay out of the channels: force and velocity only
    assert sorted(c["role"] for c in record["channels"]) == ["force", "velocity"]


@pytest.mark.parametrize("header", ["Abscissa", "Zeit_ms"])
def test_a_first_column_of_an_unread_header_is_refused_by_name(tmp_path, capsys, header):
    path = export(tmp_path / "run_fill50.csv", header, 1e-3)
    with pytest.raises(InputFileError) as info:
        read_measurement(path)
    said = str(info.value)
    assert said.startswith(f"{path}: no time column (the first column {header!r} is not read "
                           "as one")
    assert "give its unit with time_unit=UNIT" in said
    err = refusal(["analyze", str(path), "--no-store"], capsys)
    assert "\n" not in err.strip() and f"the first column {header!r}" in err
    assert "give its unit with --time-unit UNIT" in err


def test_a_first_column_that_is_no_time_says_why_it_was_taken(tmp_path, capsys):
    path = tmp_path / "points_fill50.csv"
    path.write_text("Point1:+Z,Force [N]\n" + "".join(
        f"{np.sin(i / 7):.6g},{np.cos(i / 7):.6g}\n" for i in range(300)))
    err = refusal(["analyze", str(path), "--no-store", "--time-unit", "ms"], capsys)
    assert (f"{path}: column 'Point1:+Z' (taken as the time with --time-unit: the first "
            "column, its header not read as a time): time does not increase") in err


def test_time_unit_does_not_take_a_force_column_for_the_time(tmp_path, capsys):
    path = tmp_path / "bare_fill50.csv"
    path.write_text("Force [N],Velocity [m/s]\n" + "".join(
        f"{np.sin(i / 10):.6g},{np.cos(i / 10):.6g}\n" for i in range(400)))
    err = refusal(["analyze", str(path), "--no-store", "--time-unit", "ms"], capsys)
    assert "'Force [N]' is a force channel" in err
    assert err.rstrip().endswith("give the sample rate (--sample-rate)")


@pytest.mark.parametrize(("header", "seconds"), [("Time - sec", 1.0), ("Time - ms", 1e-3)])
def test_a_unit_after_a_dash_is_read_from_the_header(tmp_path, header, seconds):
    path = export(tmp_path / "dash.csv", header, seconds)
    measurement = read_measurement(path)
    assert [c.sample_rate_hz for c in measurement.channels] == [RATE_HZ, RATE_HZ]
    assert not measurement.metadata.get("reader_notes")  # nothing assumed
