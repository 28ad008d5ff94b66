"""Checks of channels before a power analysis: small pure functions, one-line errors.

Each check raises :class:`~pidcore.errors.ChannelError` naming the source and the channel and
saying what was found and what was expected; it returns None when the channel passes.
"""

from __future__ import annotations

import numpy as np

from .. import defaults
from ..errors import ChannelError


def _label(source: str, channel: str) -> str:
    return f"{source}: channel {channel!r}" if source else f"channel {channel!r}"


def check_finite(data: np.ndarray, *, source: str, channel: str) -> None:
    """Reject NaN/inf samples, saying how many and where the first one is.

    Examples
    --------
    >>> check_finite(np.array([0.0, np.nan]), source="a.uff", channel="F")
    Traceback (most recent call last):
    ...
    pidcore.errors.ChannelError: a.uff: channel 'F': 1 non-finite sample (NaN/inf), first at index 1
    """
    if np.isfinite(np.sum(data)):  # fast path: one pass, no temporary
        return
    bad = ~np.isfinite(data)
    count = int(bad.sum())
    if count == 0:  # the sum overflowed although every sample is finite
        return
    first = int(np.argmax(bad))
    plural = "s" if count > 1 else ""
    raise ChannelError(f"{_label(source, channel)}: {count} non-finite sample{plural} (NaN/inf), "
                       f"first at index {first}")


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
    run of identical extreme values means the amplifier or ADC saturated.

    Examples
    --------
    >>> clipped_samples(np.array([0., 1., 1., 1., 1., 0., -1.]))
    (4, 1.0)
    """
    best = (0, float("nan"))
    hi, lo = float(np.max(data)), float(np.min(data))
    span = hi - lo
    for level, sign in ((hi, 1.0), (lo, -1.0)):
        tol = relative_tolerance * max(span, abs(level))
        # one boolean temporary (N bytes) instead of |data - level| (two float temporaries)
        at = data >= level - tol if sign > 0 else data <= level + tol
        padded = np.zeros(data.shape[0] + 2, dtype=np.int8)
        padded[1:-1] = at
        edges = np.flatnonzero(np.diff(padded))
        runs = edges[1::2] - edges[::2]
        count = int(runs[runs >= min_run].sum())
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


def check_same_sampling(names: list[str], sample_rates_hz: list[float], lengths: list[int], *,
                        source: str) -> None:
    """Reject channels of different sample rate or length (they must be simultaneous)."""
    ref_rate, ref_len = sample_rates_hz[0], lengths[0]
    for name, rate, length in zip(names[1:], sample_rates_hz[1:], lengths[1:], strict=True):
        if abs(rate - ref_rate) > 1e-9 * ref_rate:
            raise ChannelError(f"{_label(source, name)}: sample rate {rate:g} Hz differs from "
                               f"{ref_rate:g} Hz of channel {names[0]!r}; expected simultaneous "
                               "channels")
        if length != ref_len:
            raise ChannelError(f"{_label(source, name)}: {length} samples differs from "
                               f"{ref_len} samples of channel {names[0]!r}; expected channels "
                               "of equal length")


def check_quantity(quantity: str, expected: str, *, source: str, channel: str) -> None:
    """Reject a channel of another physical quantity ('unknown' is accepted)."""
    if quantity not in (expected, "unknown"):
        raise ChannelError(f"{_label(source, channel)}: is a {quantity} channel, expected a "
                           f"{expected} channel")
