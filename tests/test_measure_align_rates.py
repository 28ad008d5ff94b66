"""Channels of one clock whose rates differ by round-off are still aligned on their start
times (analytic truth: F = F0 sin(wt), V = V0 sin(wt - phi), loss factor = cot(phi))."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pidcore.io import read_measurement
from pidcore.measure import analyze_measurement
from pidcore.records import Channel, Measurement

F0, V0, FREQ, ETA, FS = 10.0, 0.05, 100.0, 0.05, 5120.0
PHI = math.pi / 2 - math.atan(ETA)


@pytest.mark.parametrize("velocity_start_samples", [0.488, -0.488, 3.25])
def test_start_offset_is_corrected_when_rates_differ_by_round_off(velocity_start_samples):
    # two time columns printed with 8 digits give 5119.99997 Hz twice, 1e-12 apart; the rates
    # were compared bit for bit, so the start offset was ignored: a half-sample offset read as
    # a 3.4 degree phase error (loss factor 0.11 or -0.01 for 0.05)
    n = int(2 * FS)
    w = 2 * math.pi * FREQ
    velocity_rate = FS * (1 + 1e-12)
    start = velocity_start_samples / FS
    t_velocity = start + np.arange(n) / velocity_rate
    t_force = np.arange(n) / FS
    measurement = Measurement("pairs.txt", (
        Channel("Force", "force", F0 * np.sin(w * t_force), FS, "N"),
        Channel("Velocity", "velocity", V0 * np.sin(w * t_velocity - PHI), velocity_rate, "m/s",
                start_time_s=start)))
    record = analyze_measurement(measurement)
    # noise-free, the offset removed as a delay: ~1e-8 is left; an ignored offset is 1e-1..10
    assert record.analysis.loss_factor == pytest.approx(ETA, rel=1e-6)
    assert record.analysis.complex_power_w.imag == pytest.approx(0.5 * F0 * V0 * math.sin(PHI),
                                                                 rel=1e-6)
    assert any("aligned on their common time span" in note for note in record.notes)


@pytest.mark.parametrize("velocity_start_samples", [3.0, 0.5])
def test_time_columns_printed_with_nine_digits_are_one_clock(tmp_path, velocity_start_samples):
    # x/y pairs of one 12 800 Hz clock, printed with 9 significant digits: the force's column
    # ends at 1.99992188 (rounded), the velocity's shifted one at 2.00015625 (exact). The
    # rates read 12 799.99997 and 12 800 Hz, 2.5e-9 apart, and the file was refused: "sample
    # rate 12800 Hz differs from 12800 Hz of channel 'Force'"
    fs, freq, n = 12_800.0, 160.0, 25_600
    w = 2 * math.pi * freq
    t = np.arange(n) / fs
    t_velocity = t + velocity_start_samples / fs
    rows = "".join(f"{a:.9g},{F0 * math.sin(w * a):.9g},{b:.9g},"
                   f"{V0 * math.sin(w * b - PHI):.9g}\n" for a, b in zip(t, t_velocity,
                                                                             strict=True))
    path = tmp_path / "pairs.csv"
    path.write_text("Time [s],Force [N],Time [s],Velocity [m/s]\n" + rows)
    record = analyze_measurement(read_measurement(path))
    assert [c.sample_rate_hz for c in record.measurement.channels] == [fs, fs]
    # noise-free but printed with 9 digits (relative rounding 5e-9 of each sample) and cut to
    # the common span: the loss factor to 1e-5 of itself; a lost offset is 0.1-1 off
    assert record.analysis.loss_factor == pytest.approx(ETA, rel=1e-5)
    assert any("aligned on their common time span" in note for note in record.notes)
