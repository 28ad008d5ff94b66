"""An accelerometer channel exported in milli-g (``mg``): SI and pint read ``mg`` as the
milligram, a mass, so the channel had no unit pidcore read, and ``--acceleration-unit mg`` was
refused as no acceleration unit. A channel that is an acceleration by its name or its option
can only mean 1e-3 g: it is read so, and a note says so; nowhere else is ``mg`` taken. Each
export is derived from the bundled CSV (its acceleration in mg), its numbers checked against
the original's in m/s^2."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from _cli_runs import analyze_json

from pidcore.cli import main
from pidcore.constants import STANDARD_GRAVITY
from pidcore.io import read_measurement
from pidcore.units import lookup_unit, milli_g

ROOT = Path(__file__).resolve().parents[1]
SAMPLE_CSV = ROOT / "data_samples" / "exports" / "synthetic_f500Hz_a1g_fill50_acrylic.csv"
#: One milli-g in m/s^2, from the definition of standard gravity (9.80665 m/s^2 exactly).
MILLI_G = 1e-3 * 9.80665
#: Scaling a column and back round-trips to ~1e-16; 1e-9 tells any unit slip (x10 at least).
SAME = 1e-9


def derived_csv(path: Path, acceleration_header: str, *, drop_velocity: bool = True) -> Path:
    """The sample export with its acceleration written in mg under ``acceleration_header``
    (and its velocity dropped, so the acceleration is the motion the analysis uses)."""
    values = np.loadtxt(SAMPLE_CSV, delimiter=",", skiprows=1)
    values[:, 3] /= MILLI_G
    header = ["Time [s]", "Force [N]", "Velocity [m/s]", acceleration_header]
    keep = [0, 1, 3] if drop_velocity else [0, 1, 2, 3]
    lines = [",".join(header[i] for i in keep)]
    lines += [",".join(f"{x:.17g}" for x in row) for row in values[:, keep]]
    path.write_text("\n".join(lines) + "\n")
    return path


def original_without_velocity(path: Path) -> Path:
    values = np.loadtxt(SAMPLE_CSV, delimiter=",", skiprows=1)[:, [0, 1, 3]]
    lines = ["Time [s],Force [N],Acceleration [m/s^2]"]
    lines += [",".join(f"{x:.17g}" for x in row) for row in values]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_milli_g_is_not_a_unit_by_itself():
    # a mass unit to SI: only the channel's role makes it milli-g
    assert lookup_unit("mg") is None
    assert milli_g("mg").factor == pytest.approx(1e-3 * STANDARD_GRAVITY, rel=1e-15)
    assert milli_g("MG") is None and milli_g("mm/s") is None


@pytest.mark.parametrize("spelling", ["mg", "milli-g", "mgn"])
def test_an_acceleration_channel_in_mg_is_read_as_milli_g(tmp_path, capsys, spelling):
    truth = analyze_json(original_without_velocity(tmp_path / "si_fill50.csv"), capsys)
    path = derived_csv(tmp_path / "mg_fill50.csv", f"Acceleration [{spelling}]")
    assert read_measurement(path).channel("Acceleration").quantity == "unknown"  # the reader
    record = analyze_json(path, capsys)
    for key in ("acceleration_amplitude_m_s2", "loss_factor", "complex_power_real_w",
                "complex_power_imag_w", "frequency_hz"):
        assert record[key] == pytest.approx(truth[key], rel=SAME), key
    # the bundled load case is 1 g at 500 Hz: 1000 mg read as m/s^2 would be ~100 g
    assert record["acceleration_g"] == pytest.approx(1.0, rel=1e-3)
    assert (f"channel 'Acceleration' (acceleration): unit {spelling!r} read as milli-g "
            "(0.00980665 m/s^2), not the milligram") in record["notes"]


def test_acceleration_unit_mg_reads_a_channel_without_unit(tmp_path, capsys):
    truth = analyze_json(original_without_velocity(tmp_path / "si_fill50.csv"), capsys)
    path = derived_csv(tmp_path / "plain_fill50.csv", "Acceleration")
    record = analyze_json(path, capsys, "--acceleration-unit", "mg")
    assert record["acceleration_amplitude_m_s2"] == pytest.approx(
        truth["acceleration_amplitude_m_s2"], rel=SAME)
    assert "--acceleration-unit: 'mg' read as milli-g (0.00980665 m/s^2), not the milligram" \
        in record["notes"]


def test_mg_for_another_role_stays_refused(tmp_path, capsys):
    path = derived_csv(tmp_path / "force_fill50.csv", "Acceleration [mg]",
                       drop_velocity=False)
    assert main(["analyze", str(path), "--no-store", "--no-progress", "--force-unit",
                 "mg"]) == 2
    assert capsys.readouterr().err == ("pidcore analyze: error: --force-unit 'mg': not a force "
                                       "unit\n")
