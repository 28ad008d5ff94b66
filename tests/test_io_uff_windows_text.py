"""UFF header text written by Windows exporters in Windows-1252 (a German Testlab project: the
channel 'Kraft Prüfling', a vibrometer in 'µm/s'), read against the analytic truth of
F = F0 sin(wt), V = V0 sin(wt - phi): loss factor cot(phi), P_c = 1/2 F0 V0 e^{j phi}
(paper Eq. 11)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import pyuff

from pidcore.io import read_measurement
from pidcore.measure import AnalysisOptions, analyze_measurement

F0, V0, FREQ, FS, N = 12.0, 0.035, 123.4, 10240.0, 17787  # 1.737 s: not whole periods
PHI = math.radians(80.0)
#: Placeholders of one byte per character, replaced by the Windows-1252 bytes after writing:
#: the fixed columns of the header stay where pyuff wrote them.
PLACEHOLDERS = {b"KRAFT PRXFLING": "Kraft Prüfling".encode("cp1252"),
                b"SCHNELLE PRXFLING": "Schnelle Prüfling".encode("cp1252"),
                b"Xm/s": "µm/s".encode("cp1252")}


def windows_uff(path: Path, binary: bool) -> Path:
    t = np.arange(N) / FS
    w = 2 * math.pi * FREQ
    records = []
    for name, data, label, code in (("KRAFT PRXFLING", F0 * np.sin(w * t), "N", 13),
                                    ("SCHNELLE PRXFLING", 1e6 * V0 * np.sin(w * t - PHI),
                                     "Xm/s", 11)):
        records.append(pyuff.prepare_58(
            binary=int(binary), func_type=1, id1=name, id2="Testlab", id3="", id4="",
            id5="", rsp_node=1, rsp_dir=3, ref_node=0, ref_dir=0, rsp_ent_name="NONE",
            ref_ent_name="NONE", data=data, x=t, abscissa_spacing=1, abscissa_min=0.0,
            abscissa_inc=1 / FS, abscissa_spec_data_type=17, abscissa_axis_units_lab="s",
            ordinate_spec_data_type=code, ordinate_axis_units_lab=label,
            orddenom_spec_data_type=0, orddenom_axis_units_lab="NONE",
            z_axis_spec_data_type=0, z_axis_axis_units_lab="NONE"))
    pyuff.UFF(str(path)).write_sets(records, mode="add")
    raw = path.read_bytes()
    for placeholder, text in PLACEHOLDERS.items():
        assert raw.count(placeholder) == 1  # ID line 1, the unit label: header text only
        raw = raw.replace(placeholder, text)
    path.write_bytes(raw)
    return path


@pytest.mark.parametrize("binary", [False, True], ids=["58", "58b"])
def test_windows_1252_names_and_units_are_read(tmp_path, binary):
    # decoded as UTF-8 with replacement (pyuff's way), 'µm/s' became '\ufffdm/s' (refused as
    # no unit) and the channel 'Kraft Pr\ufffdfling', which no --force NAME could name
    path = windows_uff(tmp_path / "run_12.uff", binary)
    measurement = read_measurement(path)
    assert [(c.name, c.source_unit) for c in measurement.channels] == [
        ("Kraft Prüfling", "N"), ("Schnelle Prüfling", "µm/s")]
    velocity = measurement.channel("Schnelle Prüfling").data
    t = np.arange(N) / FS
    # E13.5 (ASCII, 6 digits) or float32 (58b) samples read back in m/s: 1e-5 of the amplitude
    # holds both and catches any prefix slip (x1e3)
    np.testing.assert_allclose(velocity, V0 * np.sin(2 * math.pi * FREQ * t - PHI),
                               atol=1e-5 * V0)
    record = analyze_measurement(measurement, AnalysisOptions(force="Kraft Prüfling",
                                                              velocity="Schnelle Prüfling"))
    # 6 significant digits per sample, noise-free: the fit is good to ~1e-6 of the loss
    # factor; 1e-5 still catches a sign, unit or phase slip
    assert record.analysis.loss_factor == pytest.approx(1 / math.tan(PHI), rel=1e-5)
    assert record.analysis.complex_power_w.imag == pytest.approx(
        0.5 * F0 * V0 * math.sin(PHI), rel=1e-5)
