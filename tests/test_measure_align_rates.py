"""Channels of one clock whose rates differ by round-off are still aligned on their start
times (analytic truth: F = F0 sin(wt), V = V0 sin(wt - phi), loss factor = cot(phi))."""

from __future__ import annotations

import math

import numpy as np
import pytest

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
