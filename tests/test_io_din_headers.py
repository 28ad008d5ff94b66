"""DIN-style CSV headers (``Time/s``, ``Force in N``) against the analytic truth of
F = F0 sin(wt), V = V0 sin(wt - phi): P_c = 1/2 F0 V0 e^{j phi}, loss factor tan(90 deg - phi)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pidcore.errors import InputFileError
from pidcore.io import read_measurement
from pidcore.measure import analyze_file

F0, V0, FREQ, ETA, FS = 10.0, 0.05, 100.0, 0.05, 5120.0
PHI = math.pi / 2 - math.atan(ETA)  # velocity lags the force by 90 deg minus the loss angle
TRUE_REAL_POWER_W = 0.5 * F0 * V0 * math.cos(PHI)


def write_export(path: Path, headers: tuple[str, str, str], scales: tuple[float, float, float],
                 *, delimiter: str = ",") -> Path:
    """1 s of force and velocity under ``headers`` (time, force, velocity), each column
    multiplied by its ``scales`` entry (the file's unit per SI unit)."""
    t = np.arange(int(FS)) / FS
    w = 2 * math.pi * FREQ
    columns = (t * scales[0], F0 * np.sin(w * t) * scales[1],
               V0 * np.sin(w * t - PHI) * scales[2])
    lines = [delimiter.join(headers)]
    lines += [delimiter.join(f"{x:.12g}" for x in row) for row in zip(*columns, strict=True)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize(("headers", "scales"), [
    (("Time/s", "Force/N", "Velocity/m/s"), (1.0, 1.0, 1.0)),
    (("Time in s", "Force in N", "Velocity in m/s"), (1.0, 1.0, 1.0)),
    (("t/s", "F/N", "v/m/s"), (1.0, 1.0, 1.0)),
    (("t / ms", "F / kN", "v / mm/s"), (1e3, 1e-3, 1e3)),
    (("Zeit in s", "Kraft in N", "Geschwindigkeit in mm/s"), (1.0, 1.0, 1e3)),
    (("Zeit [s]", "Kraft [N]", "Schnelle [mm/s]"), (1.0, 1.0, 1e3)),
])
def test_din_style_headers_round_trip_the_loss_factor(tmp_path, headers, scales):
    # 'Time/s' and 'Time in s' were refused as "no time column"; 'Force/N' was a channel of
    # unknown unit. Scaled units (ms, kN, mm/s) prove the unit is read, not taken as SI.
    path = write_export(tmp_path / "din.csv", headers, scales)
    measurement = read_measurement(path)
    assert [c.quantity for c in measurement.channels] == ["force", "velocity"]
    assert measurement.channels[0].sample_rate_hz == pytest.approx(FS, rel=1e-9)
    analysis = analyze_file(path).analysis
    # noise-free samples printed with 12 digits over whole periods: the fit is exact to
    # ~1e-10; 1e-6 still catches any unit (x1000) or phase slip
    assert analysis.loss_factor == pytest.approx(ETA, rel=1e-6)
    assert analysis.complex_power_w.real == pytest.approx(TRUE_REAL_POWER_W, rel=1e-6)


@pytest.mark.parametrize(("cell", "name"), [
    ("Velocity/Force", "Velocity/Force"),   # a mobility, not a velocity in 'Force'
    ("Force/V", "Force/V"),                 # a sensitivity: V is a volt, not a force unit
    ("Point1/m/s", "Point1/m/s"),           # the name says no quantity the unit could confirm
    ("Velocity/N", "Velocity/N"),           # N is no unit of a velocity
])
def test_a_slash_that_is_no_din_unit_stays_in_the_name(tmp_path, cell, name):
    path = write_export(tmp_path / "ratio.csv", ("Time/s", "Force/N", cell), (1.0, 1.0, 1.0))
    channel = read_measurement(path).channels[1]
    assert (channel.name, channel.quantity, channel.source_unit) == (name, "unknown", "")


@pytest.mark.parametrize(("cell", "unit"), [("Time/xyz", "xyz"), ("Zeit in Sekunden", "Sekunden"),
                                            ("Time [sek]", "sek")])
def test_a_time_header_of_an_unknown_unit_is_refused_naming_the_cell_and_spellings(
        tmp_path, cell, unit):
    # an unknown unit is never guessed; "no time column (e.g. 'Time [s]')" did not say which
    # cell was meant nor what would have been read
    path = write_export(tmp_path / "odd.csv", (cell, "Force/N", "Velocity/m/s"),
                        (1.0, 1.0, 1.0))
    with pytest.raises(InputFileError) as info:
        read_measurement(path)
    message = str(info.value)
    assert "\n" not in message
    assert f"header cell {cell!r} not read: {unit!r} is no unit of time" in message
    assert "'Time [s]', 'Time (s)', 'Time/s', 'Time in s'" in message
    assert "sample_rate_hz" in message
