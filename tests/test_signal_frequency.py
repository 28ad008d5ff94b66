"""Drive-frequency estimation and the harmonic least-squares core."""

from __future__ import annotations

import numpy as np
import pytest

from pidcore import defaults
from pidcore.errors import SignalError
from pidcore.signal import estimate_drive_frequency
from pidcore.signal.harmonics import fit_harmonics


@pytest.mark.parametrize("rel_off", [-0.005, 0.0, 0.0031, 0.005])
def test_hint_half_percent_off_is_found(rel_off):
    fs, nominal = 10240.0, 200.0
    f_true = nominal * (1 + rel_off)
    t = np.arange(30000) / fs
    rng = np.random.default_rng(1)
    x = np.sin(2 * np.pi * f_true * t + 1.0) + 0.3 * np.sin(6 * np.pi * f_true * t)
    x += 0.01 * rng.standard_normal(t.shape[0]) + 0.2
    f = estimate_drive_frequency(x, fs, frequency_hint_hz=nominal)
    # Cramer-Rao bound here is ~1e-7 relative; 1e-6 leaves room without hiding a bin error
    # (one FFT bin is 1.7e-3 relative)
    assert f == pytest.approx(f_true, rel=1e-6)


def test_hint_selects_the_peak_near_it():
    fs = 10240.0
    t = np.arange(20000) / fs
    x = np.sin(2 * np.pi * 100.0 * t) + 0.5 * np.sin(2 * np.pi * 333.0 * t)
    # the other tone leaks ~1e-6 into the single-tone phase fit of a 200-period record; 1e-5 is
    # still 500 times finer than one FFT bin (5e-3 relative), so a wrong peak cannot pass
    assert estimate_drive_frequency(x, fs) == pytest.approx(100.0, rel=1e-5)
    assert estimate_drive_frequency(x, fs, frequency_hint_hz=330.0) == pytest.approx(333.0,
                                                                                     rel=1e-5)


def test_long_record_with_few_periods_uses_decimated_spectrum(monkeypatch):
    """A record longer than the FFT segment, whose segment holds < 8 periods."""
    monkeypatch.setattr(defaults, "FREQUENCY_FFT_MAX_SAMPLES", 4096)
    fs, f_true = 10000.0, 3.217
    t = np.arange(100_000) / fs  # 32 periods, the first 4096 samples hold 1.3
    x = np.cos(2 * np.pi * f_true * t)
    assert estimate_drive_frequency(x, fs) == pytest.approx(f_true, rel=1e-8)


def test_noise_only_has_no_dominant_frequency():
    x = np.random.default_rng(3).standard_normal(50000)
    with pytest.raises(SignalError, match=r"rec: no dominant drive frequency near the hint 100 Hz"):
        estimate_drive_frequency(x, 1000.0, frequency_hint_hz=100.0, what="rec")


def test_harmonic_fit_exact_on_non_whole_periods_and_blocks():
    theta = 2 * np.pi * 0.01234
    i = np.arange(12345)
    x = 0.7 + 2.0 * np.cos(theta * i + 0.5) + 0.3 * np.cos(3 * theta * i - 1.0)
    y = -1.5 * np.sin(2 * theta * i)
    edges = np.array([0, 4000, 8000, 12345])
    fit = fit_harmonics(x, y, theta, 4, edges)
    expected_x = np.array([2 * np.exp(0.5j), 0, 0.3 * np.exp(-1j), 0])
    expected_y = np.array([0, 1.5j, 0, 0])  # -1.5 sin = Re(1.5j e^{j.})
    # an exact model: only rounding error remains (condition number of G is ~1)
    np.testing.assert_allclose(fit.total[0], expected_x, atol=1e-10)
    np.testing.assert_allclose(fit.total[1], expected_y, atol=1e-10)
    np.testing.assert_allclose(fit.dc_total, [0.7, 0.0], atol=1e-10)
    for s in range(3):
        np.testing.assert_allclose(fit.phasors[0, s], expected_x, atol=1e-10)


def test_harmonic_fit_matches_dense_least_squares_on_noise():
    """Against numpy's lstsq with the explicit design matrix (small N), linear trend included,
    for the union and for every segment (segments share one global index)."""
    rng = np.random.default_rng(0)
    x = rng.standard_normal(3001) + 1e-3 * np.arange(3001)
    theta = 0.0731
    edges = np.array([0, 1000, 2200, x.shape[0]])
    fit = fit_harmonics(x, None, theta, 3, edges)
    cases = [(0, x.shape[0], fit.total[0], fit.dc_total[0])]
    cases += [(edges[s], edges[s + 1], fit.phasors[0, s], None) for s in range(3)]
    for lo, hi, got, dc in cases:
        i = np.arange(lo, hi)
        cols = [np.ones(i.size), i - i.mean()] + [np.cos(n * theta * i) for n in range(1, 4)] + \
            [np.sin(n * theta * i) for n in range(1, 4)]
        coef = np.linalg.lstsq(np.column_stack(cols), x[lo:hi], rcond=None)[0]
        # 1e-10: round-off of the closed-form Gram against a dense QR solve
        np.testing.assert_allclose(got, coef[2:5] - 1j * coef[5:8], atol=1e-10)
        if dc is not None:
            assert dc == pytest.approx(coef[0], abs=1e-10)
