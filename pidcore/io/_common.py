"""Helpers shared by the readers and writers: hashing, naming, time bases, units (atomic
writes: :mod:`pidcore.atomic_files`)."""

from __future__ import annotations

import hashlib
import math
import os
from collections.abc import Sequence

import numpy as np

from ..constants import SI_UNITS
from ..errors import InputFileError
from ..records import Channel
from ..units import canonical_unit_text, lookup_unit

#: Largest deviation of a sample time from the fitted even grid, as a fraction of the sample
#: interval. Printed time columns carry rounding errors far below this; a dropped or repeated
#: sample moves later samples by a whole interval and is caught.
EVEN_SPACING_TOLERANCE = 0.05

#: Relative distance within which a sample rate read from float64 data is snapped to whole Hz
#: (removes only representation noise such as 1/0.0001).
FLOAT64_RATE_RESOLUTION = 1e-9


def reraise_interrupt(exc: BaseException) -> None:
    """Raise :class:`KeyboardInterrupt` when ``exc`` was caused by one.

    pyuff and scipy turn every failure, Ctrl-C included, into a plain ``Exception``; a reader
    that reported those as a corrupt file would turn an interruption into a wrong diagnosis.
    """
    seen = exc
    while seen is not None:
        if isinstance(seen, KeyboardInterrupt):
            raise KeyboardInterrupt from None
        seen = seen.__cause__ or seen.__context__
    from .. import interrupt

    interrupt.raise_if_interrupted()  # converted without a chain: the SIGINT flag still says so


def file_sha256(path: str | os.PathLike[str], *, chunk_bytes: int = 1 << 20) -> str:
    """SHA-256 (hex) of a file's bytes, read ``chunk_bytes`` at a time (stores can be large):
    the one hash of a file's content, for measurements, tables, stores and output records."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(chunk_bytes):
            digest.update(chunk)
    return digest.hexdigest()


def unique_names(names: Sequence[str]) -> list[str]:
    """Make names unique by suffixing repeats with ``" (2)"``, ``" (3)"``, ... in file order.

    >>> unique_names(["1+Z", "2+Z", "1+Z"])
    ['1+Z', '2+Z', '1+Z (2)']
    """
    seen: set[str] = set()
    counts: dict[str, int] = {}
    out = []
    for name in names:
        candidate = name
        if candidate in seen:
            k = counts.get(name, 1)
            while candidate in seen:
                k += 1
                candidate = f"{name} ({k})"
            counts[name] = k
        seen.add(candidate)
        out.append(candidate)
    return out


def snap_rate(rate_hz: float, relative_resolution: float) -> float:
    """The roundest rate (fewest significant digits, whole Hz at the finest) within the file's
    number resolution of ``rate_hz``; ``rate_hz`` itself where none is.

    UFF writes the sample interval with six significant digits, so 65 536 Hz reads back as
    1/1.52588e-05 = 65 535.95 Hz; snapping restores the rate the instrument used. The nearest
    whole Hz is not that rate once the resolution is wider than 1 Hz (above ~200 kHz for UFF):
    409 600 Hz read back as 1/2.44141e-06 = 409 599.37 Hz and was snapped to 409 599 Hz, and
    3 276 800 Hz to 3 276 798 Hz, each frequency and the record's duration off by that much.
    Every rate within the resolution reads the file alike, so the one of fewest digits is
    the one an instrument is set to (409 600, 3 276 800, 51 200, 65 536).
    """
    rate = float(rate_hz)
    if not (math.isfinite(rate) and rate >= 1.0):
        return rate
    tolerance = relative_resolution * rate
    for place in range(math.floor(math.log10(rate)), -1, -1):
        step = 10.0 ** place
        candidate = float(round(rate / step) * step)  # an integer: exact in float64
        if candidate > 0 and abs(rate - candidate) <= tolerance:
            return candidate
    return rate


#: Fewest significant digits whose rounding a printed time column is allowed (MATLAB
#: csvwrite: 5); a column of more digits is held to its own (:func:`printed_digits`).
PRINTED_TIME_DIGITS = 5


def overridden_rate(times: np.ndarray, rate_hz: float) -> str:
    """What a time column overridden by a given sample rate said, for the note that announces
    the override: ``"; the column gives 25600 Hz, 1000 x the rate given"`` where its mean
    interval is more than 0.5 % off ``rate_hz`` (a rate typed in kHz, or a column in ms
    labelled s), else ``""``. The column may be the reason for the override (uneven, not
    increasing): then its mean interval is not a rate and nothing is said."""
    t = np.asarray(times, dtype=np.float64).ravel()
    if t.size < 2 or not (np.isfinite(t[0]) and np.isfinite(t[-1])):
        return ""
    dt = (float(t[-1]) - float(t[0])) / (t.size - 1)
    if not dt > 0:
        return ""
    column_rate = 1.0 / dt
    ratio = column_rate / rate_hz
    if abs(ratio - 1.0) <= 0.005:
        return ""
    return f"; the column gives {column_rate:.6g} Hz, {ratio:.4g} x the rate given"


#: Most significant digits :func:`printed_digits` tells: beyond, the float64 round-off of
#: the scaled values (up to 1e11) nears the tolerance of the test (1e-3 of a unit).
MAX_PRINTED_DIGITS = 11


def printed_digits(times: np.ndarray) -> int | None:
    """Significant digits a time column was printed with: the most any of its values needs to
    lie on the decimal grid of its own magnitude (``%.5g`` gives 5; ``%.6f`` up to 2 s gives
    7); ``None`` beyond :data:`MAX_PRINTED_DIGITS` (a computed, unrounded column). Read in
    blocks: no copy of a long column."""
    t = np.asarray(times, dtype=np.float64)
    digits = 1
    for start in range(0, t.size, 1 << 16):
        block = t[start:start + (1 << 16)]
        pending = block[block != 0.0]
        exponents = np.floor(np.log10(np.abs(pending)))
        while pending.size:
            # on the grid of `digits` digits, then of any more: only the rest is looked at again
            scaled = pending * np.power(10.0, digits - 1 - exponents)
            off = np.abs(scaled - np.rint(scaled)) > 1e-3
            if not off.any():
                break
            if digits == MAX_PRINTED_DIGITS:
                return None
            pending, exponents = pending[off], exponents[off]
            digits += 1
    return digits


#: Samples of a time column compared with the even grid at a time.
_GRID_BLOCK = 1 << 16


def rate_from_times(times: np.ndarray, *, what: str, with_note: bool = False):
    """Sample rate (Hz) and start time (s) of an evenly spaced time vector.

    The samples must lie on an even grid within :data:`EVEN_SPACING_TOLERANCE` of the interval,
    or within the precision the column was printed with: a time printed with
    :data:`PRINTED_TIME_DIGITS` significant digits (MATLAB ``csvwrite``, UFF E13.5 abscissas)
    is off the grid by up to half a unit in its last digit, a column of more digits
    (:func:`printed_digits`) by less, a single-precision vector by half a float32 step; a
    missing sample in a column of 9 digits is refused. Such a column gives the rate and
    start of a least-squares line through it, snapped to whole Hz within its resolution, and
    (``with_note=True``) a note saying so, returned as a third element ('' otherwise).

    Raises :class:`InputFileError` naming ``what`` when the vector is too short, not
    increasing or not evenly spaced within either tolerance.
    """
    t = np.asarray(times, dtype=np.float64)
    if t.ndim != 1 or t.size < 2:
        raise InputFileError(f"{what}: a time base needs at least 2 samples, found {t.size}")
    if not np.all(np.isfinite(t)):
        # which sample: an empty row inside a spreadsheet's data was refused naming none
        first = int(np.argmin(np.isfinite(t)))
        raise InputFileError(f"{what}: the time column holds non-finite values, first at "
                             f"sample {first + 1} of {t.size} (an empty or non-numeric cell)")
    dt = (t[-1] - t[0]) / (t.size - 1)
    if not dt > 0:
        # as numbers: numpy 2's repr says "np.float64(0.0005)"
        raise InputFileError(f"{what}: time does not increase (first {float(t[0])!r}, "
                             f"last {float(t[-1])!r})")
    # the largest deviation from the grid, in blocks: over the whole column at once its
    # temporaries (index, grid, difference) were 3 more columns beside the file's table
    residual = max(float(np.max(np.abs(
        t[start:start + _GRID_BLOCK]
        - (t[0] + dt * np.arange(start, min(start + _GRID_BLOCK, t.size), dtype=np.float64)))))
        for start in range(0, t.size, _GRID_BLOCK))
    note = ""
    if residual <= EVEN_SPACING_TOLERANCE * dt:
        # the end points carry the column's rounding too: printed with 9 digits, 2 s at
        # 12 800 Hz gave 12 799.99997 Hz, and an x/y pair column of the same clock printed
        # exactly gave 12 800 Hz, so the two were refused as different rates ("12800 Hz
        # differs from 12800 Hz"). Whole Hz within what the scatter about the grid allows.
        span = float(t[-1] - t[0])
        rate = snap_rate(1.0 / dt, max(2.0 * float(residual) / span, FLOAT64_RATE_RESOLUTION))
        start = float(t[0])
    else:
        # half a unit in the last printed digit of the largest time: of the digits the column
        # has, not of the fewest assumed; assumed, a column of 9 digits with samples missing
        # (a 10-sample gap in 60 s) was taken as printed with 5 and read at 12 799.75 Hz
        magnitude = float(np.max(np.abs(t[[0, -1]])))
        exponent = math.floor(math.log10(magnitude))
        digits = printed_digits(t)
        if digits is not None:
            printed = 0.5 * 10.0 ** (exponent - (max(digits, PRINTED_TIME_DIGITS) - 1))
            precision = f"printed with {digits} significant digits"
        elif np.array_equal(t, t.astype(np.float32)):
            # a MATLAB single() time vector: rounded to float32, not to decimal digits
            printed = 0.5 * float(np.spacing(np.float32(magnitude)))
            precision = "stored in single precision"
        else:
            printed, precision = 0.0, "stored to full precision"
        index = np.arange(t.size, dtype=np.float64)
        slope, intercept = np.polyfit(index, t, 1)
        fitted_residual = float(np.max(np.abs(t - (intercept + slope * index))))
        # a dropped or repeated sample in a column whose rounding is finer than the interval
        # leaves ~1/4 interval off the fitted line: still refused
        if not (slope > 0 and fitted_residual <= printed + EVEN_SPACING_TOLERANCE * dt
                and np.all(np.diff(t) >= 0)):
            worst = int(np.argmax(np.abs(np.diff(t) - dt)))
            raise InputFileError(
                f"{what}: time is not evenly spaced (mean interval {dt:.6g} s, interval after "
                f"sample {worst} is {t[worst + 1] - t[worst]:.6g} s"
                + f"; {precision}"
                + "); expected a constant sample interval")
        span = float(slope) * (t.size - 1)
        rate = snap_rate(1.0 / float(slope), max(printed / span, FLOAT64_RATE_RESOLUTION))
        start = float(intercept)
        if t[0] == 0.0 and abs(start) <= printed:
            start = 0.0  # a record that starts at 0 as printed
        note = (f"{what}: time {precision} "
                f"(off an even grid by up to {fitted_residual:.3g} s); rate {rate:.9g} Hz from a "
                "line fitted through it")
    if with_note:
        return rate, start, note
    return rate, start


def interpret_unit(unit_text: str) -> tuple[str, float]:
    """Quantity and SI factor of a unit label; unknown or empty labels give ``("unknown", 1)``.

    Readers keep channels of unknown units (a voltage squared, a sound level) rather than fail:
    the analysis decides whether it needs them.
    """
    text = unit_text.strip()
    if not text or canonical_unit_text(text) in {"none", "-", "1", ""}:
        return "unknown", 1.0
    info = lookup_unit(text)
    if info is None:
        return "unknown", 1.0
    return info.quantity, info.factor


def refuse_unit_other_than_si(quantity: str, unit: str, *, where: str) -> None:
    """Refuse the unit a pidcore layout (HDF5, MATLAB) states for a channel's samples where it
    is not the SI unit of the channel's quantity: the layouts hold samples in SI, and a file
    written by another program that states its samples' own unit there ('mm/s') was read as
    m/s without a word (5000 g for 5 g). Which of the two is wrong, the samples or the unit,
    cannot be told. No unit stated, or a quantity without one, is not checked."""
    quantity, unit = quantity.strip(), unit.strip()
    si_unit = SI_UNITS.get(quantity)
    if not unit or si_unit is None or quantity == "unknown":
        return
    info = lookup_unit(unit)
    if info is not None and info.quantity == quantity and abs(info.factor - 1.0) <= 1e-12:
        return  # an SI spelling ('m/s2' for 'm/s^2')
    raise InputFileError(f"{where} is {unit!r}, not the SI unit of its quantity {quantity} "
                         f"({si_unit!r}); pidcore's layout holds samples in SI")


def make_channel(name: str, values: np.ndarray, *, sample_rate_hz: float, unit: str,
                 start_time_s: float = 0.0, quantity: str | None = None,
                 factor: float | None = None) -> Channel:
    """Build a SI :class:`Channel` from raw values in ``unit``."""
    if quantity is None or factor is None:
        quantity, factor = interpret_unit(unit)
    data = np.asarray(values, dtype=np.float64).reshape(-1)
    if factor != 1.0:
        data = data * factor
    return Channel(name=name, quantity=quantity, data=data, sample_rate_hz=float(sample_rate_hz),
                   source_unit=unit.strip(), start_time_s=float(start_time_s))


_KIND_WORDS = {"c": "complex numbers", "S": "text", "U": "text", "O": "objects (references, "
               "variable-length data or cells)", "V": "records (a compound type)",
               "M": "dates", "m": "time spans"}


def real_numbers(values: object, *, where: str) -> np.ndarray:
    """``values`` as an array of real numbers (integers, floats, booleans) of any shape, or an
    :class:`InputFileError` naming what they are instead (complex, text, records, ...)."""
    arr = np.asarray(values)
    kind = arr.dtype.kind
    if kind not in "biuf":
        raise InputFileError(f"{where}: samples are {_KIND_WORDS.get(kind, str(arr.dtype))}; "
                             "expected real numbers")
    return arr


def real_samples(values: object, *, where: str) -> np.ndarray:
    """``values`` as a 1-D float64 vector of real samples, or an :class:`InputFileError`.

    A channel's samples must be real numbers (integers, floats, booleans) in one vector; a
    MATLAB row or column (``1 x N``) counts as one. Complex samples are refused (casting them
    drops the imaginary part without a word), as are text, records, references and matrices
    (flattening a matrix interleaves its columns into one record).
    """
    arr = real_numbers(values, where=where)
    if sum(n > 1 for n in arr.shape) > 1:
        raise InputFileError(f"{where}: samples have shape {arr.shape}; expected one vector "
                             "per channel")
    if arr.size == 0:
        raise InputFileError(f"{where}: holds no samples")
    # copy=False: float64 samples as read (h5py, loadmat) are the channel's; a copy of each
    # doubled the peak of reading a MATLAB export while the file's arrays were still held
    return arr.astype(np.float64, copy=False).reshape(-1)


def real_scalar(value: object, *, where: str, positive: bool = False) -> float:
    """``value`` as one finite float (``positive``: also > 0), or an :class:`InputFileError`
    saying what it is and what was expected."""
    try:
        arr = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.size != 1 or not np.isfinite(arr[0]) or (positive and arr[0] <= 0):
        shown = value.decode("utf-8", "replace") if isinstance(value, bytes) else value
        raise InputFileError(f"{where} is {shown!r}; expected a finite "
                             f"{'positive ' if positive else ''}number")
    return float(arr[0])


#: The first 8 bytes of every HDF5 file (at 0, or at 512 behind a MATLAB v7.3 header).
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
