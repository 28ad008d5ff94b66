"""Drive-frequency estimation: coarse FFT peak, then Gauss-Newton on the phase of the fit.

The frequency is estimated from the *motion* channel (velocity, or acceleration when there is
no velocity), not from the force: under sine control the motion is the controlled, nearly pure
tone, while the force carries the particles' impact harmonics and the coupon's reactive force.

1. Coarse: Hann-windowed FFT of the mean-removed channel (of its first
   :data:`~pidcore.defaults.FREQUENCY_FFT_MAX_SAMPLES` samples; when that segment holds fewer
   than 8 periods of the peak, of a block-mean decimated copy of the whole record instead),
   peak searched near the hint if one is given, then Gaussian (log-parabolic) interpolation of
   the peak, which for a Hann window is good to a few hundredths of a bin.
2. Dominance: the peak's power must exceed the median power of the spectrum by
   :data:`~pidcore.defaults.DOMINANT_PEAK_MIN_POWER_RATIO`, else :class:`SignalError`.
3. Refinement over the whole record: the fundamental is fitted (3-parameter LS fit) in up to 32
   consecutive blocks at the current estimate; a frequency error ``df`` makes the fitted phase
   drift as ``2 pi df t``, so the slope of the unwrapped block phases against block centre time
   is the correction (one Gauss-Newton step of the phase model). Two to four passes reach the
   noise floor; each pass costs one streaming pass over one channel.
"""

from __future__ import annotations

import numpy as np

from .. import defaults
from ..errors import SignalError
from .harmonics import fit_harmonics

#: With a hint, a line outside the search window whose power exceeds the best peak inside the
#: window by more than 1/this factor (10 dB) means the hint is wrong.
HINT_MIN_FRACTION_OF_LINE = 0.1


def _coarse_spectrum(x: np.ndarray, sample_rate_hz: float,
                     max_samples: int) -> tuple[np.ndarray, float]:
    """Power spectrum of the first ``max_samples`` samples and its bin width (Hz)."""
    seg = np.asarray(x[:max_samples], dtype=float)
    seg = (seg - seg.mean()) * np.hanning(seg.shape[0])
    power = np.abs(np.fft.rfft(seg)) ** 2
    return power, sample_rate_hz / seg.shape[0]


def _decimated_spectrum(x: np.ndarray, sample_rate_hz: float,
                        max_samples: int) -> tuple[np.ndarray, float]:
    """Power spectrum of block means (boxcar decimation) of the whole record."""
    factor = int(np.ceil(x.shape[0] / max_samples))
    n = (x.shape[0] // factor) * factor
    dec = x[:n].reshape(-1, factor).mean(axis=1)
    return _coarse_spectrum(dec, sample_rate_hz / factor, dec.shape[0])


def _peak(power: np.ndarray, bin_hz: float, hint_hz: float | None,
          rel_width: float) -> tuple[float, float, int]:
    """Interpolated peak frequency (Hz), peak/median power ratio, peak bin."""
    lo, hi = 2, power.shape[0] - 2
    if hint_hz is not None:
        # the lines the hint admits (:func:`_off_hint`): hint / (1 +- rel_width)
        lo = max(lo, int(np.floor(hint_hz / (1 + rel_width) / bin_hz)) - 3)
        hi = min(hi, int(np.ceil(hint_hz / (1 - rel_width) / bin_hz)) + 4)
    if hi <= lo:
        return float("nan"), 0.0, 0
    k = lo + int(np.argmax(power[lo:hi]))
    median = float(np.median(power[2:-1])) if power.shape[0] > 4 else 0.0
    if median > 0:
        ratio = float(power[k] / median)
    else:  # a noise-free tone leaves a zero median; an all-zero channel has no peak at all
        ratio = float("inf") if power[k] > 0 else 0.0
    a, b, c = np.log(power[k - 1:k + 2] + 1e-300)
    den = a - 2 * b + c
    delta = 0.5 * (a - c) / den if den < 0 else 0.0
    return (k + float(np.clip(delta, -0.5, 0.5))) * bin_hz, ratio, k


def estimate_drive_frequency(x: np.ndarray, sample_rate_hz: float, *,
                             frequency_hint_hz: float | None = None,
                             what: str = "record") -> float:
    """Drive frequency of a nearly sinusoidal channel, Hz.

    Parameters
    ----------
    x : numpy.ndarray
        Finite samples of the motion channel.
    sample_rate_hz : float
        Sample rate, Hz.
    frequency_hint_hz : float, optional
        Nominal frequency; the line is searched where the hint lies within +-
        :data:`~pidcore.defaults.FREQUENCY_SEARCH_RELATIVE_WIDTH` of it (and 3 FFT bins
        more, where the bins of a short record are coarser). A dominant line outside that
        window, or a refined estimate the hint is more than that fraction of it off (the bins
        not added: the estimate is far finer than they are), raises :class:`SignalError`
        saying where the line is: a wrong hint never moves the estimate silently.
    what : str
        Names the record and channel in error messages.

    Raises
    ------
    SignalError
        If no spectral peak stands out of the median by
        :data:`~pidcore.defaults.DOMINANT_PEAK_MIN_POWER_RATIO`.

    Examples
    --------
    >>> t = np.arange(20000) / 10000.0
    >>> round(estimate_drive_frequency(np.sin(2 * np.pi * 101.3 * t), 10000.0), 6)
    101.3
    """
    max_samples = defaults.FREQUENCY_FFT_MAX_SAMPLES
    rel = defaults.FREQUENCY_SEARCH_RELATIVE_WIDTH
    power, bin_hz = _coarse_spectrum(x, sample_rate_hz, max_samples)
    f0, ratio, k = _peak(power, bin_hz, frequency_hint_hz, rel)
    if x.shape[0] > max_samples and k < 8:
        power, bin_hz = _decimated_spectrum(x, sample_rate_hz, max_samples)
        f0, ratio, k = _peak(power, bin_hz, frequency_hint_hz, rel)
    if frequency_hint_hz is not None and power.shape[0] > 4:
        # A wrong hint must not pull the estimate onto the skirt of the real line: look at the
        # whole spectrum, and refuse when the dominant line lies outside the search window.
        k_all = 2 + int(np.argmax(power[2:-2]))
        if power[k] < HINT_MIN_FRACTION_OF_LINE * power[k_all]:
            f_all, ratio_all, _ = _peak(power, bin_hz, None, rel)
            outside = abs(f_all - frequency_hint_hz) > rel * f_all + 3 * bin_hz
            if outside and ratio_all >= defaults.DOMINANT_PEAK_MIN_POWER_RATIO:
                raise SignalError(
                    f"{what}: the drive line is at {f_all:.6g} Hz, the frequency hint "
                    f"{frequency_hint_hz:g} Hz more than {100 * rel:g} % off it; "
                    f"{_time_base_slip(f_all, frequency_hint_hz, rel)}correct the hint "
                    "(frequency_hz) or leave it out")
    if not np.isfinite(f0) or ratio < defaults.DOMINANT_PEAK_MIN_POWER_RATIO:
        near = f" near the hint {frequency_hint_hz:g} Hz" if frequency_hint_hz else ""
        raise SignalError(
            f"{what}: no dominant drive frequency{near}: the largest spectral peak is "
            f"{10 * np.log10(max(ratio, 1e-30)):.1f} dB above the median, expected >= "
            f"{10 * np.log10(defaults.DOMINANT_PEAK_MIN_POWER_RATIO):.0f} dB")
    f = refine_frequency(x, sample_rate_hz, f0)
    # the refined line is known far better than an FFT bin (the fit's phase over the whole
    # record), so the bins that widen the coarse search play no part here: with them a short
    # record (bins of 34 Hz) accepted a hint of 500 Hz for a line at 420 Hz, 16 % off
    if frequency_hint_hz is not None and _off_hint(f, frequency_hint_hz, rel):
        raise SignalError(f"{what}: the drive frequency is {f:.6g} Hz, the frequency hint "
                          f"{frequency_hint_hz:g} Hz more than {100 * rel:g} % off it; "
                          f"{_time_base_slip(f, frequency_hint_hz, rel)}correct the hint "
                          "(frequency_hz) or leave it out")
    return f


def _off_hint(line_hz: float, hint_hz: float, relative_width: float) -> bool:
    """Whether the hint is more than ``relative_width`` of the drive line off it, the README's
    rule (5 % of the line, not of the hint: a hint of 475 Hz for a line at 500 Hz is 5 % off
    and passes, 526.3 Hz is 5.26 % off); a relative 1e-9 more lets a hint exactly that
    fraction off pass despite the rounding of its product."""
    return abs(line_hz - hint_hz) > relative_width * line_hz * (1 + 1e-9)


#: Factors between time units an export is written in (s, ms, us): a drive frequency found
#: this far off the one the user expects is the time base read in the wrong unit.
_TIME_UNIT_RATIOS = {1e-6: "us read as s", 1e-3: "ms read as s", 1e3: "s read as ms",
                     1e6: "s read as us"}


def _time_base_slip(found_hz: float, hint_hz: float, relative_width: float) -> str:
    """The phrase that names a time base read in the wrong unit where ``found_hz`` is a
    factor of 1000 or 1e6 off the hint (a UFF abscissa in ms labelled s, a CSV time column
    in ms without a unit), else ``""``: correcting the hint alone would keep every frequency
    of that file wrong."""
    for ratio, slip in _TIME_UNIT_RATIOS.items():
        if abs(found_hz - ratio * hint_hz) <= relative_width * ratio * hint_hz:
            return (f"it is {ratio:g} x the hint, as from a time base read in the wrong unit "
                    f"({slip}): give the file's time unit (time_unit=UNIT) or ")
    return ""


def refine_frequency(x: np.ndarray, sample_rate_hz: float, frequency_hz: float, *,
                     max_iterations: int = 4) -> float:
    """Gauss-Newton refinement of ``frequency_hz`` from the drift of block phases, Hz."""
    n = x.shape[0]
    f = float(frequency_hz)
    for _ in range(max_iterations):
        n_periods = n * f / sample_rate_hz
        n_blocks = int(min(32, max(2, n_periods // 2)))
        edges = np.linspace(0, n, n_blocks + 1).astype(np.int64)
        fit = fit_harmonics(x, None, 2 * np.pi * f / sample_rate_hz, 1, edges)
        phase = np.unwrap(np.angle(fit.phasors[0, :, 0]))
        centre_s = 0.5 * (edges[:-1] + edges[1:] - 1) / sample_rate_hz
        slope = np.polyfit(centre_s, phase, 1)[0]
        df = slope / (2 * np.pi)
        f = float(f + df)
        if abs(df) < 1e-10 * f:
            break
    return f
