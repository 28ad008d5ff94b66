"""Study: error of the measured loss factor under a slow wander, before and after the drift
became a cubic spline with knots every 4 periods (``docs/measurement.md``).

A synthetic shaker record with an analytic loss factor (rigid mass + viscous damper,
:func:`pidcore.signal.synthesize_shaker_record`) gets a slow sine added to the force and the
velocity (``wander_fraction`` of each channel's amplitude). "Before" is the same code with
:data:`pidcore.defaults.DRIFT_KNOT_PERIODS` set to 1e9, which keeps the one DC and trend over
the whole record (the fit of pidcore before the change, to the last bit).

It prints tables and writes ``docs/measurement_wander.png``:

1. the candidates, each an explicit least-squares design matrix (numpy, small records at
   5.12 kHz): the error from a 5 % wander (RMS over 6 wander phases, no noise), from
   subharmonics of a bouncing bed in the force only (20 % at f/2, 10 % at 3f/2: they carry no
   power, so any change is an error), and the scatter over 12 seeds at 60 dB;
2. pidcore before and after, 2 s at 100 Hz, 25.6 kHz: the error against the wander frequency
   at 5 % and against the wander amplitude at 0.8 Hz (noise-free, RMS over 8 phases), the
   standard error at 60 and 40 dB (mean over 10 seeds), and the scatter over 40 seeds at 60 dB
   without wander;
3. the same error in standard errors (60 dB) for other records: 10 s at 100 Hz, 2 s at 50 Hz,
   0.5 s at 100 Hz.

Usage (from the repository root; a few minutes)::

    PYTHONPATH=. MPLBACKEND=Agg python docs/measurement_wander.py
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from scipy.interpolate import BSpline

from pidcore import defaults
from pidcore.signal import analyze_power, synthesize_shaker_record

HERE = Path(__file__).resolve().parent
FIGURE = HERE / "measurement_wander.png"
MASS_KG, ACCELERATION_M_S2, DAMPING_N_S_M = 0.5, 5 * 9.80665, 2.0
PHASES_RAD = np.linspace(0.0, 2 * math.pi, 8, endpoint=False) + 0.1
WANDER_FREQUENCIES_HZ = (0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0, 1.3, 1.7, 2.3, 3.3, 5.0)
WANDER_FRACTIONS = (0.005, 0.01, 0.02, 0.05, 0.1)
N_HARM = 5


def true_loss_factor(frequency_hz: float) -> float:
    return DAMPING_N_S_M / (MASS_KG * 2 * math.pi * frequency_hz)  # c / (m w)


def record(*, frequency_hz: float, duration_s: float, sample_rate_hz: float,
           fraction: float = 0.0, wander_hz: float = 0.5, phase: float = 0.0,
           subharmonic: float = 0.0, snr_db: float | None = None,
           seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(force, velocity) of the synthetic record, with wander and force subharmonics."""
    rec = synthesize_shaker_record(
        mass_kg=MASS_KG, acceleration_amplitude_m_s2=ACCELERATION_M_S2,
        frequency_hz=frequency_hz, sample_rate_hz=sample_rate_hz,
        n_periods=duration_s * frequency_hz + 0.37, viscous_damping_n_s_m=DAMPING_N_S_M,
        snr_db=snr_db, wander_fraction=fraction, wander_frequency_hz=wander_hz,
        wander_phase_rad=phase, seed=seed)
    t = np.arange(rec.force_n.size) / sample_rate_hz
    amplitude = MASS_KG * ACCELERATION_M_S2
    force = rec.force_n + subharmonic * amplitude * (
        np.sin(math.pi * frequency_hz * t + phase)
        + 0.5 * np.sin(3 * math.pi * frequency_hz * t + 2 * phase + 1))
    return force, rec.velocity_m_s


# --- 1. candidates as explicit design matrices ---------------------------------------------

def _harmonics(n: int, theta: float) -> np.ndarray:
    i = np.arange(n)
    return np.column_stack([g(k * theta * i) for g in (np.cos, np.sin)
                            for k in range(1, N_HARM + 1)])


def _piecewise_polynomial(n: int, bounds: np.ndarray, degree: int) -> np.ndarray:
    i = np.arange(n)
    cols = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        u = (i - 0.5 * (a + b - 1)) / (b - a)
        for p in range(degree + 1):
            cols.append(np.where((i >= a) & (i < b), u**p, 0.0))
    return np.column_stack(cols)


def _spline(n: int, knots: np.ndarray) -> np.ndarray:
    edges = knots - 0.5
    t = np.concatenate(([edges[0]] * 3, edges, [edges[-1]] * 3))
    return BSpline.design_matrix(np.arange(n, dtype=float), t, 3).toarray()


def candidates(n: int, samples_per_period: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """(drift columns, row weights) of every candidate."""
    whole = int(n / samples_per_period)

    def at_periods(marks: np.ndarray) -> np.ndarray:
        return np.append(np.round(marks * samples_per_period).astype(int), n)

    per_block = whole // 8
    ones = np.ones(n)
    hann = np.sin(math.pi * (np.arange(n) + 0.5) / n)  # residuals weighted by Hann
    return {
        "one DC + trend (before)": (_piecewise_polynomial(n, np.array([0, n]), 1), ones),
        "DC + trend per block": (
            _piecewise_polynomial(n, at_periods(np.arange(8) * per_block), 1), ones),
        "cubic per 8-9 periods": (_piecewise_polynomial(
            n, at_periods(np.arange(whole // 8) * 8), 3), ones),
        "Hann-weighted, one trend": (_piecewise_polynomial(n, np.array([0, n]), 1), hann),
        "spline, knots 16 periods": (_spline(n, at_periods(np.arange(whole // 16) * 16)),
                                     ones),
        "spline, knots 8 periods": (_spline(n, at_periods(np.arange(whole // 8) * 8)), ones),
        "spline, knots 4 periods (after)": (
            _spline(n, at_periods(np.arange(whole // 4) * 4)), ones),
    }


def _design_loss_factor(force: np.ndarray, velocity: np.ndarray, design: np.ndarray,
                        weights: np.ndarray) -> float:
    coef = np.linalg.lstsq(design * weights[:, None],
                           np.column_stack([force, velocity]) * weights[:, None], rcond=None)[0]
    f = coef[:N_HARM, 0] - 1j * coef[N_HARM:2 * N_HARM, 0]
    v = coef[:N_HARM, 1] - 1j * coef[N_HARM:2 * N_HARM, 1]
    power = 0.5 * np.sum(f * np.conj(v))
    return float(power.real / power.imag)


def compare_candidates(frequency_hz: float = 100.0, duration_s: float = 2.0) -> None:
    rate = 5120.0
    spec = dict(frequency_hz=frequency_hz, duration_s=duration_s, sample_rate_hz=rate)
    truth = true_loss_factor(frequency_hz)
    force, _ = record(**spec)
    harm = _harmonics(force.size, 2 * math.pi * frequency_hz / rate)
    cands = candidates(force.size, rate / frequency_hz)
    phases = np.linspace(0, 2 * math.pi, 6, endpoint=False) + 0.1

    def rms(records: list[tuple[np.ndarray, np.ndarray]], drift: np.ndarray,
            weights: np.ndarray) -> float:
        design = np.column_stack([harm, drift])
        return float(np.sqrt(np.mean([(_design_loss_factor(f, v, design, weights) - truth)**2
                                      for f, v in records])))

    rows: dict[str, list[float]] = {name: [] for name in cands}
    columns = ["wander 0.37 Hz", "0.73", "1.13", "1.77", "3.31", "subharm.", "sd 60 dB"]
    for wander_hz in (0.37, 0.73, 1.13, 1.77, 3.31):
        recs = [record(**spec, fraction=0.05, wander_hz=wander_hz, phase=p) for p in phases]
        for name, (drift, weights) in cands.items():
            rows[name].append(rms(recs, drift, weights))
    recs = [record(**spec, subharmonic=0.2, phase=p) for p in phases]
    for name, (drift, weights) in cands.items():
        rows[name].append(rms(recs, drift, weights))
    noisy = [record(**spec, snr_db=60.0, seed=s) for s in range(12)]
    for name, (drift, weights) in cands.items():
        design = np.column_stack([harm, drift])
        rows[name].append(float(np.std([_design_loss_factor(f, v, design, weights)
                                        for f, v in noisy], ddof=1)))
    print(f"candidates, {duration_s:g} s at {frequency_hz:g} Hz (loss factor {truth:.4g}): "
          "RMS error [1e-6] (5 % wander, noise-free; subharmonics), scatter at 60 dB [1e-6]")
    print(f"{'':32s}" + "".join(f"{c:>15s}" for c in columns))
    for name, values in rows.items():
        print(f"{name:32s}" + "".join(f"{v * 1e6:15.4g}" for v in values))


# --- 2., 3. pidcore before and after ----------------------------------------------------

@contextmanager
def before_change(before: bool) -> Iterator[None]:
    """The analysis as it was (one DC and trend over the record), or as it is."""
    kept = defaults.DRIFT_KNOT_PERIODS
    if before:
        defaults.DRIFT_KNOT_PERIODS = 10**9  # no record holds two spaces of 1e9 periods
    try:
        yield
    finally:
        defaults.DRIFT_KNOT_PERIODS = kept


def loss_factor(before: bool, *, frequency_hz: float = 100.0, duration_s: float = 2.0,
                **wander: float) -> tuple[float, float]:
    """(loss factor - truth, its standard error) from :func:`pidcore.signal.analyze_power`."""
    rate = 25600.0
    force, velocity = record(frequency_hz=frequency_hz, duration_s=duration_s,
                             sample_rate_hz=rate, **wander)
    with before_change(before):
        result = analyze_power(force, velocity, rate, frequency_hz=frequency_hz)
    return result.loss_factor - true_loss_factor(frequency_hz), result.loss_factor_stderr


def rms_error(before: bool, **spec: float) -> float:
    errors = [loss_factor(before, phase=p, **spec)[0] for p in PHASES_RAD]
    return float(np.sqrt(np.mean(np.square(errors))))


def table(title: str, xs: tuple[float, ...], error: Callable[[bool, float], float],
          scale: float, unit: str) -> dict[bool, list[float]]:
    out = {before: [error(before, x) for x in xs] for before in (True, False)}
    print(f"{title} [{unit}]")
    for i, x in enumerate(xs):
        print(f"  {x:7.3g}: before {out[True][i] / scale:10.4g}   "
              f"after {out[False][i] / scale:10.4g}")
    return out


def main() -> None:
    compare_candidates()
    stderr = {snr: float(np.mean([loss_factor(False, snr_db=snr, seed=s)[1]
                                  for s in range(10)])) for snr in (60.0, 40.0)}
    print(f"2 s at 100 Hz: loss factor {true_loss_factor(100.0):.6g}, standard error "
          + ", ".join(f"{v:.3g} at {k:g} dB" for k, v in stderr.items()))
    by_frequency = table("5 % wander, noise-free: RMS error over 8 phases vs wander Hz",
                         WANDER_FREQUENCIES_HZ,
                         lambda b, fw: rms_error(b, fraction=0.05, wander_hz=fw), 1e-6, "1e-6")
    by_fraction = table("0.8 Hz wander, noise-free: RMS error over 8 phases vs amplitude",
                        WANDER_FRACTIONS,
                        lambda b, a: rms_error(b, fraction=a, wander_hz=0.8), 1e-6, "1e-6")
    for before in (True, False):
        errors = np.array([loss_factor(before, snr_db=60.0, seed=s)[0] for s in range(40)])
        print(f"{'before' if before else 'after'}: no wander, 60 dB, 40 seeds: mean error "
              f"{errors.mean():+.3g}, scatter {errors.std(ddof=1):.4g}")
    for duration_s, frequency_hz in ((10.0, 100.0), (2.0, 50.0), (0.5, 100.0)):
        spec = dict(duration_s=duration_s, frequency_hz=frequency_hz)
        se = float(np.mean([loss_factor(False, snr_db=60.0, seed=s, **spec)[1]
                            for s in range(4)]))
        table(f"{duration_s:g} s at {frequency_hz:g} Hz: 5 % wander, RMS error / standard "
              f"error at 60 dB ({se:.3g}) vs wander Hz", (0.37, 0.73, 1.13, 1.77, 3.31),
              lambda b, fw, spec=spec: rms_error(b, fraction=0.05, wander_hz=fw, **spec),
              se, "standard errors")

    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for ax, x, key, xlabel in (
            (left, WANDER_FREQUENCIES_HZ, by_frequency, "wander frequency [Hz] (5 % amplitude)"),
            (right, np.array(WANDER_FRACTIONS) * 100, by_fraction,
             "wander amplitude [% of each channel] (0.8 Hz)")):
        ax.loglog(x, key[True], "o-", label="before: one DC + trend over the record")
        # a wander commensurate with the record leaves round-off only: floored onto the axes
        ax.loglog(x, np.maximum(key[False], 1e-12), "s-",
                  label=f"after: cubic spline, knots every {defaults.DRIFT_KNOT_PERIODS} periods")
        for snr, style in ((60.0, "--"), (40.0, ":")):
            ax.axhline(stderr[snr], color="grey", ls=style, label=f"standard error, {snr:g} dB")
        ax.set_xlabel(xlabel)
        ax.grid(True, which="both", alpha=0.3)
    left.set_ylabel("|loss factor error|, RMS over 8 wander phases [-]")
    left.legend(fontsize=7)
    fig.suptitle("Slow wander in a 2 s, 100 Hz record without noise "
                 f"(loss factor {true_loss_factor(100.0):.4g})", fontsize=10)
    fig.tight_layout()
    fig.savefig(FIGURE, dpi=110)
    print(f"wrote {FIGURE}")


if __name__ == "__main__":
    main()
