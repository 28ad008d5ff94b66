"""A sidecar's ``time_unit`` column: the unit of each file's time base, so that a batch of
exports in s and in ms is read each in its own unit (one ``--time-unit`` for all made every
frequency of half of them 1000 x off, and the table had no column to say it: it was refused
as unknown). Same vocabulary and checks as ``--time-unit``; a ``--time-unit`` (or the app's
time base unit for every file) that reads a file's time otherwise than its row is refused
naming both, nothing written."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from _cli_runs import refusal

from pidcore.cli import main

RATE_HZ = 5000.0
DRIVE_HZ = 125.0


def export(path: Path, seconds_per_unit: float) -> Path:
    """0.4 s of a 125 Hz force and velocity at 5 kHz, the time column ``Time`` (no unit)
    written in a unit of ``seconds_per_unit``."""
    t = np.arange(2000) / RATE_HZ
    w = 2 * math.pi * DRIVE_HZ
    rows = zip(t / seconds_per_unit, 3.0 * np.sin(w * t), 0.01 * np.sin(w * t - 1.0),
               strict=True)
    path.write_text("Time,Force [N],Velocity [m/s]\n"
                    + "".join(f"{a:.12g},{b:.12g},{c:.12g}\n" for a, b, c in rows),
                    encoding="utf-8")
    return path


def batch(folder: Path, cells: tuple[str, str]) -> list[Path]:
    """Two exports, in s and in ms, and a loadcases.csv stating ``cells`` as their units."""
    paths = [export(folder / "a_fill50.csv", 1.0), export(folder / "b_fill50.csv", 1e-3)]
    (folder / "loadcases.csv").write_text(
        f"file,time_unit\na_fill50.csv,{cells[0]}\nb_fill50.csv,{cells[1]}\n", encoding="utf-8")
    return paths


def analysed(paths: list[Path], capsys, *extra: str) -> list[dict]:
    assert main(["analyze", *map(str, paths), "--json", "--no-store", "--no-progress",
                 *extra]) == 0
    return json.loads(capsys.readouterr().out)["records"]


def test_each_file_is_read_in_the_unit_of_its_row(tmp_path, capsys):
    records = analysed(batch(tmp_path, ("s", "ms")), capsys)
    # the rate and drive line of the samples written, for both (analytic truth: a noiseless
    # 125 Hz line over 50 periods is found to far better than 1e-6); the export in ms read
    # as seconds gave 0.125 Hz
    assert [r["frequency_hz"] for r in records] == [pytest.approx(DRIVE_HZ, rel=1e-6)] * 2
    said = " ".join(records[1]["notes"])
    # said of the row that stated it, not of --time-unit, which was not given
    assert ("time column 'Time' (no unit) taken as 'ms' (column time_unit of "
            f"{tmp_path / 'loadcases.csv'}, line 3 (b_fill50.csv))") in said


def test_a_time_unit_given_for_every_file_that_agrees_is_taken(tmp_path, capsys):
    paths = batch(tmp_path, ("", "ms"))
    # 'msec' reads as the row's 'ms': no refusal of the unit, no override said; the file in s
    # is read in ms as given (its frequency 1000 x up), which is what the user said of it,
    # and its vibrated mass is then 1000 x the coupon's: implausible, kept only when asked
    err = refusal(["analyze", *map(str, paths), "--no-store", "--time-unit", "msec"], capsys)
    assert "a_fill50.csv: implausible: the vibrated mass the record shows" in err
    records = analysed(paths, capsys, "--time-unit", "msec", "--accept-implausible")
    assert records[1]["frequency_hz"] == pytest.approx(DRIVE_HZ, rel=1e-6)
    assert records[0]["frequency_hz"] == pytest.approx(1000 * DRIVE_HZ, rel=1e-6)
    assert not any("overrides" in n for r in records for n in r["notes"])


def test_a_time_unit_given_for_every_file_that_disagrees_is_refused(tmp_path, capsys):
    paths = batch(tmp_path, ("s", "ms"))
    store = tmp_path / "store.h5"
    err = refusal(["analyze", *map(str, paths), "--store", str(store), "--time-unit", "s"],
                  capsys)
    assert ("error: b_fill50.csv: --time-unit 's' disagrees with column time_unit 'ms' of "
            f"{tmp_path / 'loadcases.csv'}, line 3 (b_fill50.csv)") in err
    assert not store.exists()  # refused before any file was read


@pytest.mark.parametrize(("cell", "why"), [("Hz", "'Hz' is not a unit of time"),
                                           ("MS", "'MS' is not a unit of time")])
def test_a_cell_that_is_no_unit_of_time_is_refused_naming_the_cell(tmp_path, capsys, cell,
                                                                     why):
    paths = batch(tmp_path, ("s", cell))
    err = refusal(["analyze", *map(str, paths), "--no-store"], capsys)
    assert (f"error: {tmp_path / 'loadcases.csv'}, line 3 (b_fill50.csv), column time_unit: "
            f"{why}") in err
    assert err.rstrip().endswith("expected a unit of time: s, ms or us")


def test_the_app_reads_each_upload_in_its_rows_unit():
    from pidcore.app import uploads
    from pidcore.errors import SettingsTableError

    row = {"file": "b_fill50.csv", "time base unit": "ms"}
    assert uploads.file_time_unit(row, None) == "ms"
    assert uploads.options_of(row).time_unit == "ms"
    assert uploads.options_of({**row, "time base unit": ""}, time_unit="us").time_unit == "us"
    with pytest.raises(SettingsTableError, match=r"time base unit 's' \(for every file\) "
                                                 r"disagrees with column time base unit 'ms'"):
        uploads.options_of(row, time_unit="s")


def test_the_app_reads_an_upload_in_its_rows_unit_and_says_so(tmp_path):
    from pidcore.app import uploads

    path = export(tmp_path / "b_fill50.csv", 1e-3)
    row = {"file": path.name, "time base unit": "ms"}
    unit = uploads.file_time_unit(row, None)
    outcome = uploads.analyze_parsed(
        uploads.parse_upload(path.name, path.read_bytes(), time_unit=unit),
        uploads.options_of(row))
    assert outcome.ok, outcome.error
    record = uploads.row_time_unit_notes(outcome.record, row, None)
    assert record.analysis.frequency_hz == pytest.approx(DRIVE_HZ, rel=1e-6)  # not 0.125 Hz
    # the row's cell stated it, not the page's field for every file, which was empty
    assert any("taken as 'ms' (the settings table's column 'time base unit')" in n
               for n in record.notes), record.notes
