"""Testlab-style text exports (header block, German locale, unit row under the names) against
the analytic truth of F = F0 sin(wt), V = V0 sin(wt - phi): P_c = 1/2 F0 V0 e^{j phi}."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from _cli_runs import analyze_json

from pidcore.cli import main
from pidcore.errors import InputFileError
from pidcore.io import read_measurement

F0, V0, FREQ, ETA, FS = 10.0, 0.05, 100.0, 0.05, 5120.0
PHI = math.pi / 2 - math.atan(ETA)  # velocity lags the force by 90 deg minus the loss angle
TRUE_REAL_POWER_W = 0.5 * F0 * V0 * math.cos(PHI)
TRUE_REACTIVE_POWER_W = 0.5 * F0 * V0 * math.sin(PHI)


def write_testlab_text(path: Path, columns: list[tuple[str, str, np.ndarray]]) -> Path:
    """A German Testlab ASCII export: key/value header block, names, unit row, tab separated,
    decimal comma, cp1252, CRLF; 2 s at 5120 Hz, 8 significant digits."""
    lines = ["Original file name\tC:\\Prüfstand\\PID_Wabe.lms", "Section\tSection1",
             "Run\tRun 7", "Temperatur\t23 °C", "",
             "\t".join(c[0] for c in columns), "\t".join(c[1] for c in columns)]
    for row in zip(*(c[2] for c in columns), strict=True):
        lines.append("\t".join(f"{x:.8g}".replace(".", ",") for x in row))
    path.write_bytes(("\r\n".join(lines) + "\r\n").encode("cp1252"))
    return path


def shaker_columns(force_name: str, force_unit: str, force_scale: float, velocity_name: str,
                   velocity_unit: str, velocity_scale: float) -> list:
    t = np.arange(int(2 * FS)) / FS
    w = 2 * math.pi * FREQ
    return [("Time", "s", t),
            (velocity_name, velocity_unit, V0 * np.sin(w * t - PHI) * velocity_scale),
            (force_name, force_unit, F0 * np.sin(w * t) * force_scale)]


def test_bracketed_words_in_a_name_above_a_unit_row_stay_in_the_name(tmp_path, capsys):
    # Testlab channel names such as 'Force (Drive point)' and 'Point1:+Z (Laser)' over a unit
    # row: the bracket was taken as the unit, the row's mm/s and N were lost and the names cut
    # to 'Force' and 'Point1:+Z' (then refused: 'no velocity or acceleration channel')
    path = write_testlab_text(tmp_path / "run07.txt", shaker_columns(
        "Force (Drive point)", "N", 1.0, "Point1:+Z (Laser)", "mm/s", 1e3))
    names = {c.name: c.source_unit for c in read_measurement(path).channels}
    assert names == {"Point1:+Z (Laser)": "mm/s", "Force (Drive point)": "N"}
    record = analyze_json(path, capsys)
    # noise-free samples printed with 8 significant digits: the fit is exact to ~1e-8; 1e-6
    # still catches any unit (x1000) or phase slip
    assert record["complex_power_real_w"] == pytest.approx(TRUE_REAL_POWER_W, rel=1e-6)
    assert record["complex_power_imag_w"] == pytest.approx(TRUE_REACTIVE_POWER_W, rel=1e-6)
    assert record["loss_factor"] == pytest.approx(ETA, rel=1e-6)


def test_a_unit_in_the_name_contradicted_by_the_unit_row_is_refused_not_guessed(tmp_path,
                                                                                capsys):
    # 'Force (N)' over a unit row 'kN': the name's N was taken, so every power was 1000 x too
    # small without a word (loss factor and SDC unchanged, so nothing looked wrong)
    path = write_testlab_text(tmp_path / "run08.txt", shaker_columns(
        "Force (N)", "kN", 1e-3, "Point1:+Z", "m/s", 1.0))
    assert main(["analyze", str(path), "--no-store", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "run08.txt" in err and "'Force'" in err
    assert "N in the name, kN in the unit row" in err and "--force-unit" in err
    # the option decides, and then the number is right
    record = analyze_json(path, capsys, "--force-unit", "kN")
    assert record["complex_power_imag_w"] == pytest.approx(TRUE_REACTIVE_POWER_W, rel=1e-6)


@pytest.mark.parametrize("row_units", [("N", "mm/s"), ("-", "-")])
def test_a_unit_in_the_name_agreeing_with_the_unit_row_is_read_as_before(tmp_path, capsys,
                                                                         row_units):
    # a row cell that states no unit ('-') says nothing against the name's unit
    path = write_testlab_text(tmp_path / "run09.txt", shaker_columns(
        "Force (N)", row_units[0], 1.0, "Point1:+Z [mm/s]", row_units[1], 1e3))
    names = {c.name: c.source_unit for c in read_measurement(path).channels}
    assert names == {"Point1:+Z": "mm/s", "Force": "N"}
    record = analyze_json(path, capsys)
    assert record["complex_power_real_w"] == pytest.approx(TRUE_REAL_POWER_W, rel=1e-6)


@pytest.mark.parametrize("options", [(), ("--allow-clipped",)])
def test_an_overflow_marker_is_named_not_called_clipping(tmp_path, capsys, options):
    # a float32-max overload marker in one sample: the clipping test's tolerance grew with the
    # range, so 'clipped: 10239 samples at -0.05 m/s' was said of a clean channel, and
    # --allow-clipped then fitted a 3.4e38 sample
    columns = shaker_columns("Force", "N", 1.0, "Point1:+Z", "m/s", 1.0)
    columns[1][2][100] = 3.402823e38
    path = write_testlab_text(tmp_path / "run10.txt", columns)
    assert main(["analyze", str(path), "--no-store", "--no-progress", *options]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "run10.txt" in err and "'Point1:+Z'" in err and "index 100" in err
    assert "3.40282e+38 m/s" in err and "overload" in err and "clipped" not in err


def test_the_array_api_refuses_an_overflow_marker_too():
    from pidcore.errors import ChannelError
    from pidcore.signal.power import analyze_power

    t = np.arange(int(2 * FS)) / FS
    force = F0 * np.sin(2 * math.pi * FREQ * t)
    velocity = V0 * np.sin(2 * math.pi * FREQ * t - PHI)
    force[777] = -9.9e37
    with pytest.raises(ChannelError, match=r"channel 'force'.*index 777 \(-9\.9e\+37"):
        analyze_power(force, velocity, FS, force_name="force", velocity_name="velocity")


@pytest.mark.parametrize("force_later_s", [1e-4, -1e-4])
def test_each_x_y_pair_keeps_its_own_time_column(tmp_path, capsys, force_later_s):
    # Testlab writes signals of their own time axis as x/y pairs ('Time, Point1:+Z, Time,
    # Force'). The second time column was an ignored channel and the force took the first
    # column's times: sampled 0.1 ms off (half a sample here), a 3.6 degree phase error: 0.1 ms
    # earlier gave a loss factor of 0.113 for 0.05, saved without a word (0.1 ms later: -0.013,
    # refused as an uncorrected vibrometer delay)
    t = np.arange(int(2 * FS)) / FS
    w = 2 * math.pi * FREQ
    shifted = t + force_later_s
    path = write_testlab_text(tmp_path / "run11.txt", [
        ("Time", "s", t), ("Point1:+Z", "m/s", V0 * np.sin(w * t - PHI)),
        ("Time", "s", shifted), ("Force", "N", F0 * np.sin(w * shifted))])
    channels = read_measurement(path).channels
    assert [c.name for c in channels] == ["Point1:+Z", "Force"]
    # 8 printed digits of 1e-4 s
    assert channels[1].start_time_s == pytest.approx(force_later_s, abs=1e-9)
    record = analyze_json(path, capsys)
    # the half-sample offset is removed as a velocity delay: exact up to the 8 printed digits
    assert record["loss_factor"] == pytest.approx(ETA, rel=1e-6)
    assert record["complex_power_imag_w"] == pytest.approx(TRUE_REACTIVE_POWER_W, rel=1e-6)


def test_an_x_y_pair_at_another_rate_is_refused_naming_both_rates(tmp_path, capsys):
    # the force pair holds every second sample; its shorter columns end in empty cells
    t = np.arange(int(2 * FS)) / FS
    w = 2 * math.pi * FREQ
    half = np.full(t.size // 2, np.nan)
    path = write_testlab_text(tmp_path / "run12.txt", [
        ("Time", "s", t), ("Point1:+Z", "m/s", V0 * np.sin(w * t - PHI)),
        ("Time", "s", np.r_[t[::2], half]), ("Force", "N", np.r_[F0 * np.sin(w * t[::2]), half])])
    path.write_bytes(path.read_bytes().replace(b"\tnan\tnan", b"\t\t"))
    assert main(["analyze", str(path), "--no-store", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "run12.txt" in err
    assert "5120 Hz" in err and "2560 Hz" in err


@pytest.mark.parametrize(("name", "unit", "value"), [("Delay", "ms", 0.5),
                                                      ("Time offset", "s", 1e-3)])
def test_a_constant_column_in_seconds_is_a_channel_not_a_time_base(tmp_path, capsys, name,
                                                                    unit, value):
    # a vibrometer delay or a trigger offset written as a column of its unit beside the
    # signals: read as the x of an x/y pair, it refused the whole file ('time does not
    # increase'); it is a quantity in seconds, as it was read before x/y pairs
    t = np.arange(int(2 * FS)) / FS
    w = 2 * math.pi * FREQ
    path = write_testlab_text(tmp_path / "run13.txt", [
        ("Time", "s", t), ("Point1:+Z", "m/s", V0 * np.sin(w * t - PHI)),
        (name, unit, np.full(t.size, value)), ("Force", "N", F0 * np.sin(w * t))])
    channels = read_measurement(path).channels
    assert [c.name for c in channels] == ["Point1:+Z", name, "Force"]
    # the force is timed by the first time column, as the velocity
    assert (channels[2].start_time_s, channels[2].sample_rate_hz) == \
        (channels[0].start_time_s, channels[0].sample_rate_hz)
    record = analyze_json(path, capsys)
    # same grid for both channels: exact up to the 8 printed digits
    assert record["loss_factor"] == pytest.approx(ETA, rel=1e-6)
    # a column named as the time column is the pair's time base, even broken: refused
    path = write_testlab_text(tmp_path / "run14.txt", [
        ("Time", "s", t), ("Point1:+Z", "m/s", V0 * np.sin(w * t - PHI)),
        ("Time", "s", np.zeros(t.size)), ("Force", "N", F0 * np.sin(w * t))])
    assert main(["analyze", str(path), "--no-store", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "run14.txt: column 'Time' (time of column 4)" in err


def test_a_time_column_that_does_not_advance_names_its_times_as_numbers(tmp_path):
    # numpy 2's repr leaked into the message: "(first np.float64(0.0005), last ...)"
    t = np.arange(64) / FS
    path = write_testlab_text(tmp_path / "run15.txt", [
        ("Time", "s", np.full(t.size, 0.0005)), ("Force", "N", np.sin(t))])
    with pytest.raises(InputFileError) as info:
        read_measurement(path)
    assert str(info.value).endswith("run15.txt: column 'Time': time does not increase "
                                    "(first 0.0005, last 0.0005)")


@pytest.mark.parametrize("options", [(), ("--allow-clipped",)])
def test_overflow_markers_on_over_half_a_percent_of_samples_are_named(tmp_path, capsys,
                                                                      options):
    # an overload of 2 % of the record: the markers were inside the central 99 % the outlier
    # test measures from, so 'clipped: 3911 samples' was said (and with --allow-clipped, an
    # 'unresolved' reactive power of -2.75e+33 W)
    columns = shaker_columns("Force", "N", 1.0, "Point1:+Z", "m/s", 1.0)
    marked = np.arange(50, columns[2][2].size, 50)  # every 50th sample: 2 %
    columns[2][2][marked] = 3.402823e38
    path = write_testlab_text(tmp_path / "run16.txt", columns)
    assert main(["analyze", str(path), "--no-store", "--no-progress", *options]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "run16.txt: channel 'Force': " in err
    assert f"{marked.size} samples far outside the signal, first at index 50 " in err
    # the rest of the channel is the drive line of amplitude F0: its central 99 % reach
    # within 0.1 % of +-F0 (a sine's 0.5 % quantile is F0 cos(0.005 pi), 0.012 % short of it,
    # sampled 51 times a period); the markers no longer stretch it to 3.4e38
    low, high = map(float, re.search(r"99 % of the other samples lie within (\S+) \.\. (\S+) N",
                                      err).groups())
    assert (low, high) == (pytest.approx(-F0, rel=1e-3), pytest.approx(F0, rel=1e-3))
    assert "clipped" not in err
