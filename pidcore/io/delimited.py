"""Delimited text (CSV/TXT) with one header row of names and units.

Supported header cells: ``Time [s]``, ``Force (kN)``, ``Velocity [mm/s]``, ``Acceleration [g]``
or a bare name (quantity ``"unknown"``, values kept as written). Delimiters: comma, semicolon,
tab or runs of blanks, detected from the header line. A decimal comma is recognised when the
delimiter is not a comma. Lines before the header that start with ``#`` are skipped.

The time base is the first column whose unit is a time unit or whose name is ``time``/``t``;
it must be evenly spaced. Without one, ``sample_rate_hz`` must be given.
"""

from __future__ import annotations

import io
import os
import re
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputFileError, ParameterError
from ..records import Measurement
from ._common import (
    atomic_path,
    file_sha256,
    interpret_unit,
    make_channel,
    rate_from_times,
    unique_names,
)

_HEADER_CELL = re.compile(r"^\s*(?P<name>.*?)\s*(?:[\[(](?P<unit>[^\[\]()]*(?:\([^)]*\))?"
                          r"[^\[\]()]*)[\])])?\s*$")
_TIME_NAMES = {"time", "t", "zeit", "temps"}


def _split_header(cell: str) -> tuple[str, str]:
    """``"Velocity [mm/s]"`` -> ``("Velocity", "mm/s")``; a bare name has unit ``""``."""
    cell = cell.strip().strip('"').strip()
    match = _HEADER_CELL.match(cell)
    if match is None or not match.group("name"):
        return cell, ""
    return match.group("name"), (match.group("unit") or "").strip()


def _decode(raw: bytes) -> str:
    for encoding in ("utf-8-sig", "latin-1"):
        try:
            return raw.decode(encoding)
        except UnicodeDecodeError:
            continue
    raise AssertionError("latin-1 decodes every byte")  # pragma: no cover


def _sniff(header: str, first_data: str) -> tuple[str, str]:
    """Delimiter (regex for blanks) and decimal mark from the header and a data line."""
    for delimiter in ("\t", ";", ","):
        if delimiter in header:
            decimal = "," if delimiter != "," and "," in first_data else "."
            return delimiter, decimal
    return r"\s+", "."


def read_csv(path: str | os.PathLike[str], *, sample_rate_hz: float | None = None) -> Measurement:
    """Read a delimited text file of channels into a SI :class:`Measurement`.

    Parameters
    ----------
    path : str or path-like
    sample_rate_hz : float, optional
        Sample rate, Hz, for files without a time column. With a time column it must agree
        with the column (relative 1e-6) or :class:`ParameterError` is raised.

    Examples
    --------
    A file ``Time [s],Force [kN]`` / ``0,1.5`` / ``0.001,1.6`` gives a channel ``Force`` of
    quantity ``force`` in N sampled at 1000 Hz.
    """
    where = str(path)
    text = _decode(Path(path).read_bytes())
    lines = text.splitlines()
    start = 0
    while start < len(lines) and (not lines[start].strip() or lines[start].lstrip()
                                  .startswith("#")):
        start += 1
    if start >= len(lines):
        raise InputFileError(f"{where}: empty file; expected a header row such as "
                             "'Time [s],Force [N],Velocity [m/s]' and data rows")
    header = lines[start]
    data_lines = [ln for ln in lines[start + 1:] if ln.strip()]
    if not data_lines:
        raise InputFileError(f"{where}: header but no data rows")
    if "\x00" in text[:4096]:
        raise InputFileError(f"{where}: binary content; expected delimited text")
    delimiter, decimal = _sniff(header, data_lines[0])
    engine = "python" if delimiter == r"\s+" else "c"
    try:
        # The header is read apart so that repeated names stay as written (pandas would
        # rename them 'a.1') and the data columns parse natively as float64 ('nan', 'inf' and
        # empty cells become NaN; the analysis judges them, not the reader).
        header_cells = [str(c) for c in pd.read_csv(
            io.StringIO(header), sep=delimiter, engine=engine, header=None, dtype=str,
            keep_default_na=False, skipinitialspace=True).iloc[0]]
        values = pd.read_csv(io.StringIO("\n".join(data_lines)), sep=delimiter, engine=engine,
                             decimal=decimal, header=None, dtype=np.float64,
                             skipinitialspace=True).to_numpy(dtype=np.float64)
    except (pd.errors.ParserError, ValueError) as exc:
        first_line = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputFileError(f"{where}: not a numeric delimited table ({first_line}); expected "
                             "one header row of names and units followed by numbers") from None
    # A trailing delimiter makes an empty last column; drop it.
    while header_cells and not header_cells[-1].strip() and values.shape[1] == len(header_cells) \
            and np.all(np.isnan(values[:, -1])):
        header_cells.pop()
        values = values[:, :-1]
    if values.shape[1] != len(header_cells):
        raise InputFileError(f"{where}: the header has {len(header_cells)} columns but the data "
                             f"rows have {values.shape[1]}")
    cells = [_split_header(c) for c in header_cells]
    if len(cells) < 1 or values.shape[0] < 2:
        raise InputFileError(f"{where}: expected at least one channel and two data rows")

    time_index = None
    for i, (name, unit) in enumerate(cells):
        quantity, _ = interpret_unit(unit)
        if quantity == "time" or (not unit and name.strip().lower() in _TIME_NAMES):
            time_index = i
            break
    if time_index is not None:
        name, unit = cells[time_index]
        _, factor = interpret_unit(unit) if unit else ("time", 1.0)
        rate, start_time = rate_from_times(values[:, time_index] * factor,
                                           what=f"{where}: column {name!r}")
        if sample_rate_hz is not None and abs(rate - sample_rate_hz) > 1e-6 * rate:
            raise ParameterError(f"{where}: the time column gives {rate:.9g} Hz but "
                                 f"sample_rate_hz={sample_rate_hz:.9g} was given")
    elif sample_rate_hz is None:
        raise InputFileError(f"{where}: no time column (e.g. 'Time [s]') and no sample rate; "
                             "add a time column or give the sample rate (--sample-rate)")
    else:
        if not sample_rate_hz > 0:
            raise ParameterError(f"sample_rate_hz must be positive, got {sample_rate_hz!r}")
        rate, start_time = float(sample_rate_hz), 0.0

    keep = [i for i in range(len(cells)) if i != time_index]
    if not keep:
        raise InputFileError(f"{where}: only a time column; expected channel columns beside it")
    names = unique_names([cells[i][0] or f"column {i + 1}" for i in keep])
    channels = tuple(make_channel(n, values[:, i], sample_rate_hz=rate, unit=cells[i][1],
                                  start_time_s=start_time)
                     for n, i in zip(names, keep, strict=True))
    return Measurement(source=where, channels=channels, sha256=file_sha256(path),
                       file_format="csv", metadata={})


def write_csv(measurement: Measurement, path: str | os.PathLike[str]) -> None:
    """Write ``Time [s],<name> [<SI unit>],...`` with full float64 precision, atomically.

    All channels must share one sample rate, start time and length. Channels of unknown
    quantity are labelled with their source unit so that they read back unchanged.
    """
    channels = measurement.channels
    if not channels:
        raise ParameterError(f"{measurement.source}: nothing to write (no channels)")
    first = channels[0]
    for ch in channels[1:]:
        if (ch.sample_rate_hz != first.sample_rate_hz or ch.n_samples != first.n_samples
                or ch.start_time_s != first.start_time_s):
            raise ParameterError(f"{path}: CSV needs channels of one sample rate, start and "
                                 f"length; {ch.name!r} differs from {first.name!r}")
    columns = {"Time [s]": first.start_time_s + np.arange(first.n_samples) / first.sample_rate_hz}
    for ch in channels:
        if ch.quantity == "unknown":
            label = f"{ch.name} [{ch.source_unit}]" if ch.source_unit else ch.name
        else:
            label = f"{ch.name} [{ch.unit}]"
        columns[label] = np.asarray(ch.data, dtype=np.float64)
    with atomic_path(path) as tmp:
        pd.DataFrame(columns).to_csv(tmp, index=False, float_format="%.17g")
