"""Checks of channels before a power analysis: small pure functions, one-line errors.

Each check raises :class:`~pidcore.errors.ChannelError` naming the source and the channel and
saying what was found and what was expected; it returns None when the channel passes.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .. import defaults
from ..errors import ChannelError, a_or_an, apart

#: A run of identical samples longer than this fraction of a drive period, away from the
#: channel's extremes, is a dropout (a sampled sine changes value at every sample except within
#: one quantisation step of its peaks, see :func:`dropout_runs`).
DROPOUT_MIN_PERIOD_FRACTION = 0.125
#: ... and at least this many samples.
DROPOUT_MIN_RUN = 16
#: Quantisation coarser than this fraction of the amplitude is not allowed for when judging
#: clipping (at 1/4 of the amplitude a flat top can no longer be told from a clipped one).
QUANTISATION_MAX_STEP_FRACTION = 0.25


@njit(cache=True)
def _scan(x, min_run, max_runs):  # pragma: no cover - numba
    """One pass: smallest non-zero step, hysteresis mean crossings, runs of equal samples.

    Returns (min_step, n_crossings, starts, lengths) with runs of >= ``min_run`` samples
    (at most ``max_runs``).
    """
    n = x.shape[0]
    lo = x[0]
    hi = x[0]
    total = 0.0
    for i in range(n):
        v = x[i]
        total += v
        if v < lo:
            lo = v
        if v > hi:
            hi = v
    mean = total / n
    h = 0.1 * (hi - lo)
    step = np.inf
    crossings = 0
    state = 0
    starts = np.empty(max_runs, dtype=np.int64)
    lengths = np.empty(max_runs, dtype=np.int64)
    n_runs = 0
    run_start = 0
    for i in range(n):
        v = x[i]
        if v > mean + h:
            if state < 0:
                crossings += 1
            state = 1
        elif v < mean - h:
            if state > 0:
                crossings += 1
            state = -1
        if i > 0:
            d = abs(v - x[i - 1])
            if d > 0.0:
                if d < step:
                    step = d
                if i - run_start >= min_run and n_runs < max_runs:
                    starts[n_runs] = run_start
                    lengths[n_runs] = i - run_start
                    n_runs += 1
                run_start = i
    if n - run_start >= min_run and n_runs < max_runs:
        starts[n_runs] = run_start
        lengths[n_runs] = n - run_start
        n_runs += 1
    return step, crossings, starts[:n_runs], lengths[:n_runs]


def samples_per_period(data: np.ndarray) -> float:
    """Rough samples per period from hysteresis crossings of the mean (N when none)."""
    _, crossings, _, _ = _scan(data, data.shape[0] + 1, 0)
    return 2.0 * data.shape[0] / crossings if crossings >= 2 else float(data.shape[0])


def dropout_runs(data: np.ndarray) -> list[tuple[int, int, float]]:
    """Runs of identical samples that no sampled vibration produces: ``(start, length, value)``.

    A run counts when it is at least :data:`DROPOUT_MIN_RUN` samples and
    :data:`DROPOUT_MIN_PERIOD_FRACTION` of a period long and its value is not the channel's
    maximum or minimum (flat extremes are clipping, see :func:`clipped_samples`). Exact zeros
    of a disconnected or dropped-out channel and a stuck ADC both show as such runs.
    """
    x = np.asarray(data, dtype=np.float64)
    period = samples_per_period(x)
    min_run = max(DROPOUT_MIN_RUN, int(math.ceil(DROPOUT_MIN_PERIOD_FRACTION * period)))
    _, _, starts, lengths = _scan(x, min_run, 10_000)
    hi, lo = float(np.max(x)), float(np.min(x))
    return [(int(a), int(n), float(x[a])) for a, n in zip(starts, lengths, strict=True)
            if x[a] != hi and x[a] != lo]


def _label(source: str, channel: str) -> str:
    return f"{source}: channel {channel!r}" if source else f"channel {channel!r}"


#: Largest sample magnitude analysed, in SI units. Far beyond any force (N), velocity (m/s)
#: or acceleration (m/s^2) a shaker makes, and far enough below the float64 range (1.8e308)
#: that the squares and sums of the spectrum and the least-squares fit stay finite; a sample
#: of 1e306 overflowed them into NaN and a traceback.
MAX_SAMPLE_MAGNITUDE = 1e100


def check_finite(data: np.ndarray, *, source: str, channel: str) -> None:
    """Reject NaN/inf samples, saying how many and where the first one is, and samples beyond
    :data:`MAX_SAMPLE_MAGNITUDE` (a corrupt file: the analysis would overflow).

    Examples
    --------
    >>> check_finite(np.array([0.0, np.nan]), source="a.uff", channel="F")
    Traceback (most recent call last):
    ...
    pidcore.errors.ChannelError: a.uff: channel 'F': 1 non-finite sample (NaN/inf), first at index 1
    """
    if not np.isfinite(np.sum(data)):  # fast path: one pass, no temporary
        bad = ~np.isfinite(data)
        count = int(bad.sum())
        if count:  # else the sum overflowed although every sample is finite
            first = int(np.argmax(bad))
            plural = "s" if count > 1 else ""
            raise ChannelError(f"{_label(source, channel)}: {count} non-finite "
                               f"sample{plural} (NaN/inf), first at index {first}")
    if data.size and max(float(np.max(data)), -float(np.min(data))) > MAX_SAMPLE_MAGNITUDE:
        big = np.abs(data) > MAX_SAMPLE_MAGNITUDE
        first = int(np.argmax(big))
        raise ChannelError(f"{_label(source, channel)}: {int(big.sum())} sample(s) of magnitude "
                           f"above {MAX_SAMPLE_MAGNITUDE:g} (SI units), first at index {first} "
                           f"({data[first]:g}); expected physical values: a corrupt file")


#: How far beyond the range of 99 % of its samples a sample may lie, as a multiple of that
#: range's half width. A channel's input range is set within a few decades of the signal it
#: resolves (a 24-bit ADC spans 1.7e7 of its step), and an analysable record is dominated by
#: its drive line, so no measured sample lies a million times its amplitude out; an overload
#: or "no value" marker does (float32 max 3.4e38, 9.9e37), and a single one makes the range,
#: the clipping test and the fit meaningless.
MAX_OUTLIER_FACTOR = 1e6


#: A sample this large in magnitude is an overflow or "no value" marker whatever the rest of
#: the channel holds (float32 max 3.4e38, Testlab's 9.9e37): no force, velocity or
#: acceleration in any unit comes near it. Markers on over 0.5 % of the samples moved the
#: central range itself, and the channel was called clipped (or its power unresolved).
MARKER_MAGNITUDE = 1e30


def check_outliers(data: np.ndarray, *, source: str, channel: str, unit: str = "") -> None:
    """Reject samples of :data:`MARKER_MAGNITUDE` or more, and samples more than
    :data:`MAX_OUTLIER_FACTOR` half-ranges of the channel's central 99 % (without those) outside
    it: overflow markers and corrupt values. Without this, one 3.4e38 made every other sample
    count as clipped at the channel's minimum."""
    if data.size < 2:
        return
    marker = np.abs(data) >= MARKER_MAGNITUDE
    # without markers the samples themselves (percentile copies them; their copy without
    # markers, which percentile may then sort in place, is ours): one copy of a long
    # channel, not two, and the same percentiles
    clean = data[~marker] if marker.any() else data
    if clean.size:
        low, high = (float(v) for v in np.percentile(clean, [0.5, 99.5],
                                                     overwrite_input=clean is not data))
    else:
        low = high = float("nan")
    half_range, middle = 0.5 * (high - low), 0.5 * (high + low)
    if not marker.any():
        if not half_range > 0:
            return  # over 99 % equal: the constant and dropout checks say what it is
        limit = MAX_OUTLIER_FACTOR * half_range
        if float(np.max(data)) - middle <= limit and middle - float(np.min(data)) <= limit:
            return
    far = marker | (np.abs(data - middle) > MAX_OUTLIER_FACTOR * half_range
                    if half_range > 0 else marker)
    first = int(np.argmax(far))
    count = int(far.sum())
    in_unit = f" {unit}" if unit else ""
    rest = (f"99 % of the other samples lie within {low:.6g} .. {high:.6g}{in_unit}"
            if clean.size else "no other samples")
    raise ChannelError(
        f"{_label(source, channel)}: {count} sample{'s' if count > 1 else ''} far outside the "
        f"signal, first at index {first} ({data[first]:.6g}{in_unit}; {rest}); expected "
        "measured values, not an overload or 'no value' marker: cut them out of the export")


def check_length(data: np.ndarray, *, source: str, channel: str, min_samples: int) -> None:
    """Reject a channel that is not 1-D or holds fewer than ``min_samples`` samples."""
    if data.ndim != 1:
        raise ChannelError(f"{_label(source, channel)}: expected a 1-D record, got shape "
                           f"{data.shape}")
    if data.shape[0] < min_samples:
        raise ChannelError(f"{_label(source, channel)}: {data.shape[0]} samples, expected at "
                           f"least {min_samples}")


def check_not_constant(data: np.ndarray, *, source: str, channel: str, unit: str = "") -> None:
    """Reject a channel whose samples are all equal (zero, disconnected, or a DC level)."""
    lo, hi = float(np.min(data)), float(np.max(data))
    if hi - lo <= 1e-12 * max(abs(hi), abs(lo)) or hi == lo:
        what = "zero" if hi == 0 and lo == 0 else f"constant at {hi:+.6g} {unit}".rstrip()
        raise ChannelError(f"{_label(source, channel)}: all samples are {what}; expected a "
                           "vibration signal")


def clipped_samples(data: np.ndarray, *, min_run: int = defaults.CLIPPING_MIN_RUN,
                    relative_tolerance: float = defaults.CLIPPING_RELATIVE_TOLERANCE
                    ) -> tuple[int, float]:
    """Samples in runs of >= ``min_run`` consecutive samples at the channel's max or min.

    Returns the count and the clipping level (the extreme with more clipped samples; 0 and NaN
    when nothing is clipped). A sampled sine reaches its extreme at isolated samples only, so a
    run of identical extreme values means the amplifier or ADC saturated -- unless the samples
    are coarsely quantised: then runs as long as a sine spends within one quantisation step of
    its peak are expected and not counted.

    Examples
    --------
    >>> clipped_samples(np.array([0., 1., 1., 1., 1., 0., -1.]))
    (4, 1.0)
    """
    best = (0, float("nan"))
    hi, lo = float(np.max(data)), float(np.min(data))
    span = hi - lo
    # A coarsely quantised sine stays on its extreme level for a while without being clipped:
    # within one step q of the peak for a fraction acos(1 - q/A)/pi of a period. Runs up to
    # 1.5x that (+1 sample) are quantisation, not saturation.
    step = _scan(data, data.shape[0] + 1, 0)[0] if data.shape[0] > 1 else math.inf
    amplitude = 0.5 * span
    for level, sign in ((hi, 1.0), (lo, -1.0)):
        tol = relative_tolerance * max(span, abs(level))
        # one boolean temporary (N bytes) instead of |data - level| (two float temporaries)
        at = data >= level - tol if sign > 0 else data <= level + tol
        padded = np.zeros(data.shape[0] + 2, dtype=np.int8)
        padded[1:-1] = at
        edges = np.flatnonzero(np.diff(padded))
        runs = edges[1::2] - edges[::2]
        needed = min_run
        if amplitude > 0 and step < QUANTISATION_MAX_STEP_FRACTION * amplitude and runs.size:
            period = data.shape[0] / runs.size  # one visit of the extreme per period
            flat = period * math.acos(1.0 - step / amplitude) / math.pi
            needed = max(min_run, int(math.ceil(1.5 * flat)) + 1)
        count = int(runs[runs >= needed].sum())
        if count > best[0]:
            best = (count, level)
    return best


def clipping_description(data: np.ndarray, *, source: str, channel: str, unit: str = "",
                         min_run: int = defaults.CLIPPING_MIN_RUN) -> str:
    """'<source>: channel 'F' clipped: 37 samples at +10 N (...)', or '' when not clipped."""
    count, level = clipped_samples(data, min_run=min_run)
    if not count:
        return ""
    return (f"{_label(source, channel)} clipped: {count} samples at {level:+.6g} {unit}".rstrip()
            + f" (runs of >= {min_run} equal extreme samples)")


def check_clipping(data: np.ndarray, *, source: str, channel: str, unit: str = "",
                   min_run: int = defaults.CLIPPING_MIN_RUN) -> None:
    """Reject a clipped channel ('clipped: 37 samples at +10 N')."""
    message = clipping_description(data, source=source, channel=channel, unit=unit,
                                   min_run=min_run)
    if message:
        raise ChannelError(f"{message}; pass allow_clipped=True to analyse anyway")


#: Relative difference within which two channels' sample rates are one rate (one clock whose
#: rate two files or columns state with different round-off).
SAME_RATE_RELATIVE_TOLERANCE = 1e-9


def check_same_sampling(names: list[str], sample_rates_hz: list[float], lengths: list[int], *,
                        source: str) -> None:
    """Reject channels of different sample rate or length (they must be simultaneous)."""
    ref_rate, ref_len = sample_rates_hz[0], lengths[0]
    for name, rate, length in zip(names[1:], sample_rates_hz[1:], lengths[1:], strict=True):
        if abs(rate - ref_rate) > SAME_RATE_RELATIVE_TOLERANCE * ref_rate:
            # as many digits as show the difference: '12800 Hz differs from 12800 Hz' (6
            # digits of rates 2.5e-9 apart) read as a contradiction
            shown, ref_shown = apart(rate, ref_rate)
            raise ChannelError(f"{_label(source, name)}: sample rate {shown} Hz differs from "
                               f"{ref_shown} Hz of channel {names[0]!r}; expected "
                               "simultaneous channels")
        if length != ref_len:
            raise ChannelError(f"{_label(source, name)}: {length} samples differs from "
                               f"{ref_len} samples of channel {names[0]!r}; expected channels "
                               "of equal length")


def check_quantity(quantity: str, expected: str, *, source: str, channel: str) -> None:
    """Reject a channel of another physical quantity ('unknown' is accepted)."""
    if quantity not in (expected, "unknown"):
        raise ChannelError(f"{_label(source, channel)}: is {a_or_an(quantity)} channel, "
                           f"expected {a_or_an(expected)} channel")
