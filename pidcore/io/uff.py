"""Universal File Format (UFF/UNV) dataset 58 time records, ASCII and binary (58b).

Reading and writing go through :mod:`pyuff`, but for memory: the blocks are found by a
chunked scan of the file (pyuff's index, not its whole-file read), and the samples of 58b
records and of evenly spaced real ASCII records are read straight into one array each (as
pyuff reads them, bit for bit) instead of through Python lists. What this module adds on top:

* Only time records become channels: function type 1 ("time response"), or type 0
  ("general") with a time abscissa (specific data type 17). FRFs, spectra and geometry are
  refused with a message listing what the file holds.
* One file is one :class:`~pidcore.records.Measurement`; its time records are the channels, in
  file order. Records of different sample rates are kept; the analysis refuses them.
* Channel name: the response entity name (``"1+Z"``, ``"Mic 01"``); where the entity names do
  not tell the records apart (``"pt"`` on every record) and the ID lines 1 do, ID line 1;
  else ID line 1, node and direction (``"12+Z"``), ``"record <k>"``. Repeated names get
  ``" (2)"``, ...
* Direction: a record measured in a negative direction (record 6 ``-Z`` etc.) is negated, so
  that every channel follows the +axis convention (noted in ``reader_notes``).
* Units: the ordinate units label when :mod:`pidcore.units` recognises it (``"m/s2"``, ``"g"``,
  ``"N"``, ``"Pa"``); where it states none (empty, ``"NONE"``), the specific data type code
  (8, 9, 11, 12, 13, 15) with the dataset 164 unit factors of the file (SI when the file has no
  dataset 164), noted; otherwise (a label no table reads: ``"V^2"``, ``"lb"``) the channel keeps
  its values with quantity ``"unknown"``, whose unit the analysis asks for.
* Quirks handled: the zero padding of the last data line (zeros beyond ``num_pts``, fewer
  than a line holds, are dropped; more values, or others, are refused as corrupt), blanks and
  line breaks between 58b binary data and its closing ``-1`` (an extra CR LF; a block of
  another size than its ID line states is refused), E13.5 fields
  without separating blanks and 3-digit exponents (pyuff reads fixed columns), header text
  that is not UTF-8 (read as Windows-1252, as Windows exporters write ``µm/s`` and
  ``Prüfling``: decoded with replacement, the unit was refused and the name could not be
  typed).
* The sample interval is written with six significant digits (E13.5), so the rate is snapped to
  the roundest one within that resolution (65 535.95 Hz -> 65 536 Hz, 409 599.37 Hz ->
  409 600 Hz).
"""

from __future__ import annotations

import datetime as _dt
import os
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pyuff

from ..atomic_files import atomic_path
from ..constants import SI_UNITS
from ..errors import DependencyError, InputFileError, ParameterError, a_or_an
from ..records import Channel, Measurement
from ..units import (
    UnitReading,
    canonical_unit_text,
    given_time_unit,
    overrides_stated_time,
    read_unit,
)
from ._common import (
    file_sha256,
    interpret_unit,
    rate_from_times,
    reraise_interrupt,
    snap_rate,
    unique_names,
)
from ._uff_ascii import parse_uff_ascii

#: Relative resolution of an E13.5 field (six significant digits): half a unit in the sixth.
UFF_INTERVAL_RESOLUTION = 5e-6
#: Significant digits of a record's start time, its abscissa minimum (an E13.5 field): two
#: records that start 0.37 samples apart at 0.5 s and 51.2 kHz read 0.358 samples apart.
UFF_START_TIME_DIGITS = 6

_DATASET_NAMES = {
    15: "nodes", 18: "coordinate systems", 55: "data at nodes", 58: "functions",
    82: "trace lines", 151: "header", 164: "units", 1858: "function qualifiers",
    2400: "model header", 2411: "nodes", 2412: "elements", 2414: "analysis data",
    2420: "coordinate systems", 2429: "coordinate groups", 2467: "groups",
}
_FUNCTION_TYPES = {
    0: "general", 1: "time response", 2: "auto spectrum", 3: "cross spectrum",
    4: "frequency response function", 5: "transmissibility", 6: "coherence",
    7: "auto correlation", 8: "cross correlation", 9: "power spectral density",
    10: "energy spectral density", 11: "probability density function", 12: "spectrum",
}
#: SDRC specific data type -> (quantity, length exponent, force exponent) for translational DOFs.
_DATA_TYPE_CODES = {
    8: ("displacement", 1, 0), 9: ("force", 0, 1), 11: ("velocity", 1, 0),
    12: ("acceleration", 1, 0), 13: ("force", 0, 1), 15: ("pressure", -2, 1),
    17: ("time", 0, 0),
}
_QUANTITY_CODES = {"displacement": 8, "force": 13, "velocity": 11, "acceleration": 12,
                   "pressure": 15, "time": 17}
#: Quantity -> (length exponent, force exponent) written with each code.
_EXPONENTS = {q: _DATA_TYPE_CODES[c][1:] for q, c in _QUANTITY_CODES.items()}
_DIRECTIONS = {1: "+X", 2: "+Y", 3: "+Z", 4: "+RX", 5: "+RY", 6: "+RZ",
               -1: "-X", -2: "-Y", -3: "-Z", -4: "-RX", -5: "-RY", -6: "-RZ"}


def _label(value: object) -> str:
    text = str(value or "").strip()
    return "" if text.upper() == "NONE" else text


def _channel_name(dset: dict, index: int) -> str:
    for key in ("rsp_ent_name", "id1"):
        text = _label(dset.get(key))
        if text:
            return text
    node = int(dset.get("rsp_node", 0) or 0)
    if node:
        return f"{node}{_DIRECTIONS.get(int(dset.get('rsp_dir', 0) or 0), '')}"
    return f"record {index + 1}"


def _described_names(records: list[dict]) -> list[str] | None:
    """Names from ID line 1 when the entity names do not tell the records apart.

    Test.Lab and other tools write a bare point name (``"pt"``) as the response entity of
    every record and the channel's description in ID line 1 (``"Point1:+Z Force"``); a name
    shown to the user must be that description, not ``"pt (2)"``.
    """
    entities = [_label(d.get("rsp_ent_name")) for d in records]
    if all(entities) and len(set(entities)) == len(entities):
        return None
    ids = [_label(d.get("id1")) for d in records]
    if all(ids) and len(set(ids)) == len(ids):
        return ids
    return None


#: Unit labels (as :func:`~pidcore.units.canonical_unit_text` writes them) that state no unit.
_NO_UNIT_LABELS = frozenset({"", "none", "-", "1"})


def _ordinate_unit(dset: dict, unit_factors: tuple[float, float]) -> tuple[str, float, str]:
    """Quantity, SI factor and source-unit text of a record's ordinate."""
    label = _label(dset.get("ordinate_axis_units_lab"))
    quantity, factor = interpret_unit(label)
    if quantity != "unknown":
        return quantity, factor, label
    code = int(dset.get("ordinate_spec_data_type", 0) or 0)
    # only a record that states no unit takes the code's in the file's units: a label no
    # table reads ('lb', 'LBS', 'in/s pk') states one, and read as N or m/s it was a silent
    # x4.45 or x39; left unknown, the analysis asks for the unit naming the channel
    if code in _DATA_TYPE_CODES and canonical_unit_text(label) in _NO_UNIT_LABELS:
        quantity, len_exp, force_exp = _DATA_TYPE_CODES[code]
        length_factor, force_factor = unit_factors
        # Dataset 164: "to convert from universal file units to SI divide by the factor".
        factor = 1.0 / (length_factor**len_exp * force_factor**force_exp)
        return quantity, factor, f"UFF data type {code}"
    return "unknown", 1.0, label


def _time_factor(dset: dict, what: str, given: UnitReading | None) -> float:
    """Seconds per abscissa unit.

    The abscissa increment is in the abscissa's unit, so that unit sets the sample rate (a
    record in ms read as seconds gave every frequency 1000 x too low). Record 8 states the
    quantity (specific data type 17, time) but not the unit: dataset 164 scales length, force
    and temperature only, so a record without a label is in seconds, the time unit of every
    UFF unit system (noted by :func:`read_uff`). A label overrides that (the format gives it
    precedence); one that reads as no unit of time (``msek``, ``Hz``) or as two (``MS``: ms
    or Ms) is refused, naming what states it instead: ``given``, the user's ``time_unit``,
    which overrides the label (noted)."""
    if given is not None:
        return given.info.factor
    label = _label(dset.get("abscissa_axis_units_lab"))
    if not label:
        return 1.0
    reading = read_unit(label)
    if reading.info is not None and reading.quantity == "time":
        return reading.info.factor
    if reading.quantity == "time":
        why = f"abscissa unit {reading.problem}"
    elif reading.quantity is not None:
        why = (f"abscissa unit {label!r} is {a_or_an(reading.quantity)} unit, not a unit of "
               "time")
    else:
        why = f"abscissa unit {label!r} is no unit of time pidcore reads"
    raise InputFileError(f"{what}: {why}; expected a unit of time such as s or ms (the "
                         f"abscissa increment {float(dset.get('abscissa_inc', 0.0)):.6g} is in "
                         "it, so it sets the sample rate); give it with time_unit=UNIT")


def _is_time_record(dset: dict) -> bool:
    func_type = int(dset.get("func_type", -1))
    time_abscissa = int(dset.get("abscissa_spec_data_type", 0) or 0) == 17
    return func_type == 1 or (func_type == 0 and time_abscissa)


def _describe(set_types: list[int], func_types: list[int]) -> str:
    seen: list[int] = []
    for t in set_types:
        if t not in seen:
            seen.append(t)
    words = []
    for t in seen:
        if t == 58 and func_types:
            kinds = sorted({_FUNCTION_TYPES.get(f, f"function type {f}") for f in func_types})
            words.append(", ".join(kinds))
        else:
            words.append(_DATASET_NAMES.get(t, "unsupported"))
    return f"datasets {', '.join(str(t) for t in seen)} ({', '.join(words)})"


def _last_line_padding(dset: dict, extra: np.ndarray) -> bool:
    """Whether the values past a record's ``num_pts`` are the zeros that fill its last ASCII
    line (``UFFFiles.jl``'s force record: 4098 values for 4096 samples, 6 to a line): fewer
    than a line holds. A binary record has no lines to fill."""
    width = _ASCII_58_WIDTHS.get(int(dset.get("ord_data_type", 0) or 0))
    if dset.get("binary") or width is None:
        return False
    if int(dset.get("abscissa_spacing", 1)) != 1:
        width += _ASCII_58_WIDTHS[2]  # (abscissa E13.5, ordinate) pairs
    return extra.size < _ASCII_58_LINE_COLUMNS // width and not np.any(extra)


def _record_channel(dset: dict, index: int, where: str, unit_factors: tuple[float, float],
                    time_unit: UnitReading | None) -> Channel:
    num_pts = int(dset["num_pts"])
    if num_pts < 1:  # values[:num_pts] would keep all but |num_pts| samples, or none
        raise InputFileError(f"{where}: record {index + 1} declares {num_pts} samples (record "
                             "7, field 2); expected a positive number of samples")
    if "binary_block_bytes" in dset:
        stated, found = dset["binary_block_bytes"]
        raise InputFileError(f"{where}: record {index + 1} ({_channel_name(dset, index)!r}) "
                             f"holds {found} bytes of binary samples before its closing "
                             f"'    -1' where its ID line states {stated}; the file is "
                             "truncated or corrupt")
    values = np.asarray(dset["data"])
    if np.iscomplexobj(values):
        raise InputFileError(f"{where}: record {index + 1} is a time record with complex "
                             "ordinates; expected real samples")
    if values.size < num_pts:
        raise InputFileError(f"{where}: record {index + 1} holds {values.size} of its "
                             f"{num_pts} samples; the file is truncated or corrupt")
    if values.size > num_pts and not _last_line_padding(dset, values[num_pts:]):
        # a line written twice or a num_pts too small: cut to num_pts, the record read on
        # shifted (a loss factor of 0.0067 for 0.05) where the rest was dropped unsaid
        raise InputFileError(f"{where}: record {index + 1} holds {values.size} samples where "
                             f"its header states {num_pts} (record 7, field 2); only zeros "
                             "padding its last line may follow them; the file is corrupt")
    values = values[:num_pts].astype(np.float64, copy=False)
    time_factor = _time_factor(
        dset, f"{where}: record {index + 1} ({_channel_name(dset, index)!r})", time_unit)
    if int(dset.get("abscissa_spacing", 1)) == 1:
        dt = float(dset["abscissa_inc"]) * time_factor
        start = float(dset.get("abscissa_min", 0.0)) * time_factor
    else:
        x = np.asarray(dset["x"], dtype=np.float64)[:num_pts] * time_factor
        rate, start = rate_from_times(x, what=f"{where}: record {index + 1}")
        dt = 1.0 / rate
    if not (np.isfinite(dt) and dt > 0):
        raise InputFileError(f"{where}: record {index + 1} has abscissa increment {dt!r}; "
                             "expected a positive sample interval in seconds")
    quantity, factor, source_unit = _ordinate_unit(dset, unit_factors)
    if factor != 1.0:
        values = values * factor
    return Channel(name=_channel_name(dset, index), quantity=quantity, data=values,
                   sample_rate_hz=snap_rate(1.0 / dt, UFF_INTERVAL_RESOLUTION),
                   source_unit=source_unit, start_time_s=start)


_BINARY_58 = re.compile(rb"^ *58b", re.MULTILINE)
#: Lines of a dataset 58 header, its opening '    -1' line included; 58b data follows them.
_HEADER_LINES_58 = 13
#: numpy type of 58b real ordinates by (ordinate data type, byte ordering): 2 single, 4 double
#: precision; byte ordering 1 little, 2 big endian.
_BINARY_DTYPES = {(2, 1): "<f4", (2, 2): ">f4", (4, 1): "<f8", (4, 2): ">f8"}


_BLOCK_TAG = b"    -1"
#: Bytes after a tag that pyuff looks at to tell a block delimiter (74 blanks up to column 80).
_TAG_LOOKAHEAD = 81
#: Bytes of the file read at a time while looking for block delimiters.
_SCAN_CHUNK_BYTES = 1 << 22
#: Bytes read of a block to find its dataset type (the line after its opening tag).
_BLOCK_HEAD_BYTES = 4096


class _BlockScannedUFF(pyuff.UFF):
    """:class:`pyuff.UFF` whose block index is found by reading the file in chunks.

    pyuff's ``refresh`` reads the whole file into one bytes object and copies every block,
    split into lines, to read its type: for a long export the file once and its largest
    block about twice more, beside the channels read afterwards (58b: 1.6x the samples,
    ASCII 58 more). This finds the same delimiters by the same rule and reads only the
    head of each block, so the index (``_block_ind``, ``_set_types``) is pyuff's own and
    pyuff reads the blocks from it as before.
    """

    def refresh(self) -> bool:
        self._refreshed = False
        if not self.file_exists():
            return False
        try:
            with open(self._filename, "rb") as fh:
                size = fh.seek(0, os.SEEK_END)
                tags = self._tag_offsets(fh, size)
                n_blocks = len(tags) // 2
                if n_blocks == 0:
                    self._refreshed = True
                    return True
                self._block_ind = np.zeros((n_blocks, 2), dtype="int64")
                self._block_ind[:, 0] = tags[:-1:2][:n_blocks]
                self._block_ind[:, 1] = np.asarray(tags[1::2][:n_blocks]) - 1
                self._n_sets = n_blocks
                self._set_types = np.zeros(n_blocks).astype(int)
                # pyuff never marks a set binary here (it compares an int with 'b'); its
                # reader tells 58b from the dataset line itself
                self._set_formats = np.zeros(n_blocks)
                for ii in range(n_blocks):
                    set_type = self._block_type(fh, int(self._block_ind[ii, 0]),
                                                int(self._block_ind[ii, 1]))
                    if set_type is not None:
                        self._set_types[ii] = set_type
        except Exception as exc:
            reraise_interrupt(exc)
            raise Exception(f"Error refreshing UFF file: {self._filename}") from None
        self._refreshed = True
        return True

    @staticmethod
    def _tag_offsets(fh, size: int) -> list[int]:
        """Offsets of the ``'    -1'`` tags pyuff counts as delimiters: at the end of the
        file, before a line break, or followed by blanks up to column 80."""
        offsets = []
        blanks = b" " * (80 - len(_BLOCK_TAG))
        for start in range(0, size, _SCAN_CHUNK_BYTES):
            fh.seek(start)
            window = fh.read(_SCAN_CHUNK_BYTES + _TAG_LOOKAHEAD)
            ind = -1
            while True:
                ind = window.find(_BLOCK_TAG, ind + 1)
                if ind == -1 or ind >= _SCAN_CHUNK_BYTES:
                    break  # a tag from there on starts in the next chunk
                at = start + ind
                end = ind + len(_BLOCK_TAG)
                if at + len(_BLOCK_TAG) == size \
                        or (at + len(_BLOCK_TAG) < size and window[end] in (10, 13)) \
                        or (at + 80 < size and window[end:ind + 80] == blanks):
                    offsets.append(at)
            del window  # else held while the next one is read: two chunks at a time
        return offsets

    @staticmethod
    def _block_type(fh, first: int, last: int) -> int | None:
        """Dataset type of the block from ``first`` to ``last`` (bytes, inclusive): the
        first six characters of its second line, as pyuff reads them; None where they are
        not a number (pyuff leaves such a block's type 0)."""
        length = last - first + 1
        fh.seek(first)
        head = fh.read(min(length, _BLOCK_HEAD_BYTES))
        lines = head.splitlines()
        if len(head) < length and len(lines) < 3:  # the second line goes on: read it all
            fh.seek(first)
            lines = fh.read(length).splitlines()
        try:
            return int(lines[1][0:6])
        except (IndexError, ValueError):
            return None


def _utf8_header(header: bytes) -> bytes:
    """A record's header lines as UTF-8, which pyuff decodes (with replacement: every other
    byte above 0x7F became U+FFFD). Header text that is not UTF-8 is Windows-1252, which
    Test.Lab and other Windows exporters write: ``µm/s`` (0xB5) was refused as no unit and a
    channel ``Prüfling`` (0xFC) could not be named with ``--force``. Each byte is one
    character either way, so pyuff's fixed columns stay where they were."""
    return _utf8_text(header).encode("utf-8")


def _utf8_text(raw: bytes) -> str:
    """Header or whole-file text (the fallback parser's): UTF-8, else Windows-1252."""
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return raw.decode("cp1252", errors="replace")


#: The first pyuff whose ``_extract58`` parses a dataset 58 header alone (``header_only``),
#: which both record readers below call: pyproject.toml's lower bound of pyuff.
PYUFF_MIN_VERSION = "2.4.5"


def _header_58(header: bytes) -> dict:
    """A dataset 58 record's header fields, parsed by pyuff's ``_extract58`` alone (no data).

    Its ``header_only`` keyword is pyuff's since 2.4.5: with an older pyuff the call raised a
    TypeError, which the reader reported as the user's file being corrupt. The keyword is
    looked for first, so that a TypeError of pyuff's parsing itself still reads as a bad
    record."""
    import inspect

    from pyuff.datasets.dataset_58 import _extract58

    parameters = inspect.signature(_extract58).parameters
    takes_keywords = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters.values())
    if "header_only" not in parameters and not takes_keywords:
        raise DependencyError(
            f"pyuff {getattr(pyuff, '__version__', '(version unknown)')} does not support "
            "reading a dataset 58 header alone (_extract58's header_only); pidcore needs "
            f"pyuff >= {PYUFF_MIN_VERSION} (pip install 'pyuff>={PYUFF_MIN_VERSION}')")
    return _extract58(_utf8_header(header), header_only=True)


def _binary_58_record(path: str | os.PathLike[str], start: int, end: int) -> dict | None:
    """The dataset 58b record whose block starts at byte ``start`` and whose closing
    ``'    -1'`` is at byte ``end``: its header parsed by pyuff, its samples read straight
    from the file into one array. None for an ASCII record and for one this does not read
    (complex, uneven abscissa): pyuff reads those whole. A record whose binary block is not
    the size its ID line states comes back with its header and ``binary_block_bytes``
    (stated, found) instead of samples, for :func:`_record_channel` to refuse.

    pyuff unpacks 58b samples into a tuple of Python floats (32 bytes a sample) and keeps
    the abscissa as a second float64 array: reading a 10-minute export of two channels at
    51.2 kHz (469 MiB of samples) took 2.9 GiB and 2.5 minutes.
    """
    with open(path, "rb") as fh:
        fh.seek(start)
        header = b"".join(fh.readline() for _ in range(_HEADER_LINES_58))
        lines = header.splitlines()
        if len(lines) < _HEADER_LINES_58 or lines[1][6:7].lower() != b"b":
            return None
        dset = _header_58(header)
        dtype = _BINARY_DTYPES.get((int(dset.get("ord_data_type", 0)),
                                    int(dset.get("byte_ordering", 0))))
        num_pts = int(dset.get("num_pts", 0))
        readable = dtype is not None and int(dset.get("abscissa_spacing", 0)) == 1 \
            and num_pts >= 1
        # the block's bytes as the ID line states them (field 6), else as num_pts does
        stated = int(dset.get("n_bytes", 0) or 0)
        if stated <= 0 and readable:
            stated = num_pts * np.dtype(dtype).itemsize
        if stated > 0:
            # a block 24 bytes short or long was read from the header on as if whole,
            # silently (a loss factor 13 % low or 31 % high): the closing tag tells
            found = _binary_block_misfit(fh, fh.tell(), end, stated)
            if found is not None:
                dset["binary_block_bytes"] = (stated, found)
                return dset
        if not readable:
            return None
        # all the block holds: samples beyond num_pts (an ID line's count above it) are
        # refused by _record_channel, as fewer are
        values = np.fromfile(fh, dtype=dtype, count=stated // np.dtype(dtype).itemsize)
    dset["data"] = values.astype(np.float64, copy=False)
    return dset


#: Blanks and line breaks allowed between 58b data and its closing tag: the format puts the
#: tag right after the data, MPSTD's DAQ writes CR LF first (pyuff's fix_58b case).
_BLOCK_END_BLANKS = b" \r\n"
#: Bytes before a 58b closing tag looked at for those blanks and line breaks.
_BLOCK_END_LOOKBACK = 256


def _binary_block_misfit(fh, data_start: int, tag: int, stated: int) -> int | None:
    """None where the 58b data from byte ``data_start`` ends ``stated`` bytes on with only
    blanks and line breaks up to its closing tag at byte ``tag``; else the bytes found
    before the tag, those blanks and line breaks not counted. ``fh`` is left at
    ``data_start``."""
    gap = tag - data_start
    look = max(0, min(gap, _BLOCK_END_LOOKBACK))
    fh.seek(tag - look)
    tail = fh.read(look)
    fh.seek(data_start)
    # data may end in bytes that read as blanks (a float whose last byte is 0x20): the
    # stated end need only fall among the blanks and line breaks before the tag
    found = gap - (len(tail) - len(tail.rstrip(_BLOCK_END_BLANKS)))
    return None if found <= stated <= gap else max(found, 0)


#: Bytes an ASCII dataset 58 holds in its data lines where pidcore parses them (digits,
#: signs, points, exponents, blanks, LF or CR LF): anything else is left to pyuff.
_ASCII_58_DATA_BYTES = np.zeros(256, dtype=bool)
_ASCII_58_DATA_BYTES[list(b"0123456789+-.Ee \r\n")] = True
#: Field width of ASCII 58 real ordinates by ordinate data type: 2 E13.5, 4 E20.12.
_ASCII_58_WIDTHS = {2: 13, 4: 20}
#: Columns of an ASCII 58 data line: 6E13.5, 4E20.12, 2(E13.5,E20.12) fill at most 80.
_ASCII_58_LINE_COLUMNS = 80
#: Bytes of data lines read and parsed at a time (their masks: some 5x this, transient).
_ASCII_58_CHUNK_BYTES = 1 << 18


def _regular_lines(raw: np.ndarray, line_bytes: int, ending: int) -> int:
    """How many of the lines that start ``raw`` are ``line_bytes`` long, end in LF (``ending``
    1) or CR LF (2) and hold only :data:`_ASCII_58_DATA_BYTES` with no other line break."""
    complete = raw.size // line_bytes
    lines = raw[:complete * line_bytes].reshape(complete, line_bytes)
    body = lines[:, :line_bytes - ending]
    good = _ASCII_58_DATA_BYTES[body].all(axis=1) & (lines[:, -1] == 10)
    good &= ~((body == 10) | (body == 13)).any(axis=1)
    if ending == 2:
        good &= lines[:, -2] == 13
    return int(np.argmin(np.append(good, False)))


def _ascii_58_record(path: str | os.PathLike[str], first: int, last: int) -> dict | None:
    """The ASCII dataset 58 record in bytes ``first`` to ``last`` (inclusive) of the file,
    its header parsed by pyuff and its evenly spaced real samples parsed as pyuff parses
    them (each fixed-width field by ``float``), a chunk of lines at a time straight into
    one array. None for a record this does not read (complex, uneven abscissa, a header
    pyuff would split otherwise): pyuff reads those whole.

    pyuff decodes the block, splits it into line objects and collects the samples as a list
    of Python floats: some 5x the block, 13x the samples of an E20.12 record, beside the
    channels read before it.
    """
    with open(path, "rb") as fh:
        fh.seek(first)
        header = b"".join(fh.readline() for _ in range(_HEADER_LINES_58))
        lines = header.splitlines()
        # pyuff splits the decoded text (str.splitlines): where that finds the same 13 lines
        # as the line feeds, its data lines are the ones that follow
        if len(lines) < _HEADER_LINES_58 or not header.endswith(b"\n") \
                or lines[1][6:7].lower() == b"b" or len(header.decode(
                    "utf-8", "replace").splitlines(True)) != _HEADER_LINES_58:
            return None
        dset = _header_58(header)
        width = _ASCII_58_WIDTHS.get(int(dset.get("ord_data_type", 0)))
        if width is None or int(dset.get("abscissa_spacing", 0)) != 1:
            return None
        remaining = last - first + 1 - len(header)
        start = fh.tell()
        first_line = fh.readline(remaining)
        fh.seek(start)
        line_bytes = len(first_line)
        ending = 2 if first_line.endswith(b"\r\n") else 1
        n_fields = line_bytes // width  # pyuff: len(line) // width, the line ending counted
        if not first_line.endswith(b"\n") or n_fields == 0 \
                or n_fields * width > line_bytes - ending:
            return None
        # room for the last line too: appended by a concatenation, it copied the samples
        values = np.empty((remaining // line_bytes + 1) * n_fields)
        filled = 0
        per_chunk = max(1, _ASCII_58_CHUNK_BYTES // line_bytes) * line_bytes
        tail = b""
        try:
            while remaining > 0:
                chunk = fh.read(min(per_chunk, remaining))
                remaining -= len(chunk)
                raw = np.frombuffer(chunk, np.uint8)
                regular = _regular_lines(raw, line_bytes, ending)
                if remaining == 0:
                    # pyuff's own rule for the last line of a record (blank fields skipped)
                    regular = min(regular, -(-raw.size // line_bytes) - 1)
                fields = np.ndarray((regular, n_fields), dtype=f"S{width}", buffer=chunk,
                                    strides=(line_bytes, width))
                values[filled:filled + fields.size] = fields.astype(np.float64).reshape(-1)
                filled += fields.size
                if regular * line_bytes < len(chunk):
                    tail = chunk[regular * line_bytes:] + fh.read(remaining)
                    break
            rest = []
            text = tail.decode("ascii").splitlines(True)
            for k, line in enumerate(text):
                cells = [line[width * i:width * (i + 1)] for i in range(len(line) // width)]
                if width == 13 and k == len(text) - 1:
                    cells = [c for c in cells if c != " " * 13]  # pyuff's last E13.5 line
                rest.extend(float(c) for c in cells)
        except (ValueError, UnicodeDecodeError):
            return None  # a field float() refuses: pyuff refuses it too, then the fallback
    if filled + len(rest) <= values.size:
        values[filled:filled + len(rest)] = rest
        values = values[:filled + len(rest)]
    else:  # lines of other lengths at the end
        values = np.concatenate([values[:filled], np.asarray(rest, dtype=np.float64)])
    dset["data"] = values
    return dset


def _fallback_records(where: str, raw: bytes, expected: int) -> list[dict]:
    """Dataset 58 records parsed by :mod:`._uff_ascii` (Fortran number rules)."""
    try:
        # UTF-8, else Windows-1252 as the fast paths read a header (_utf8_header)
        records = [d for t, d in parse_uff_ascii(_utf8_text(raw)) if t == 58]
    except ValueError as exc:
        raise InputFileError(f"{where}: dataset 58 is corrupt ({exc}); expected E13.5 or "
                             "E20.12 numbers in fixed columns") from None
    if len(records) != expected:
        raise InputFileError(f"{where}: found {len(records)} datasets 58 where the block "
                             f"structure shows {expected}; the file is corrupt")
    return records


def read_uff(path: str | os.PathLike[str], *, time_unit: str | None = None) -> Measurement:
    """Read the dataset 58 time records of a UFF file (ASCII or binary) as one measurement.

    Parameters
    ----------
    path : str or path-like
        ``.uff`` / ``.unv`` file.
    time_unit : str, optional
        Unit of the records' abscissa (``"ms"``), for a file whose abscissa label pidcore
        does not read as a unit of time (refused without it); it overrides the label (noted).

    Returns
    -------
    Measurement
        One channel per time record, in SI units; ``file_format="uff"``.

    Raises
    ------
    InputFileError
        The file is missing, truncated or corrupt, or holds no time record (the message lists
        the datasets it does hold), or an abscissa label is no unit of time.
    """
    where = str(path)
    given_time = given_time_unit(time_unit)
    # the whole file is read only where pyuff fails on an ASCII record (the fallback parser
    # needs it): kept all along, it was one more copy of a long 58b export in memory
    with open(path, "rb") as fh:
        size = fh.seek(0, os.SEEK_END)
        fh.seek(max(0, size - 4096))
        tail = fh.read()
    if not tail.strip() and not Path(path).read_bytes().strip():
        raise InputFileError(f"{where}: empty file; expected UFF datasets")
    if not tail.rstrip().endswith(b"-1"):
        raise InputFileError(f"{where}: the file ends inside a UFF dataset (no closing '    -1' "
                             "line); it is truncated or not a UFF file")
    try:
        uff = _BlockScannedUFF(where)
        set_types = [int(t) for t in uff.get_set_types()]
    except Exception as exc:  # pyuff raises bare Exception for every failure
        reraise_interrupt(exc)
        raise InputFileError(f"{where}: cannot parse as UFF ({exc})") from None
    if not set_types:
        raise InputFileError(f"{where}: no UFF dataset found (expected blocks that start and "
                             "end with a '    -1' line)")
    unit_factors = (1.0, 1.0)
    has_units_dataset = 164 in set_types
    records: list[dict] = []
    fallback: list[dict] | None = None
    n58 = 0
    for i, set_type in enumerate(set_types):
        if set_type not in (58, 164):
            continue
        try:
            dset = None
            if set_type == 58 and hasattr(uff, "_block_ind"):  # pyuff's block offsets
                dset = _binary_58_record(path, int(uff._block_ind[i][0]),
                                         int(uff._block_ind[i][1]) + 1) \
                    or _ascii_58_record(path, int(uff._block_ind[i][0]),
                                        int(uff._block_ind[i][1]))
            if dset is None:
                dset = uff.read_sets(i)
        except DependencyError as exc:  # the installation, not this file: said as such
            raise DependencyError(f"{where}: not read: {exc}") from None
        except Exception as exc:
            reraise_interrupt(exc)
            raw = Path(path).read_bytes()
            if set_type != 58 or _BINARY_58.search(raw):
                raise InputFileError(f"{where}: dataset {set_type} (block {i + 1}) is corrupt "
                                     f"({exc})") from None
            if fallback is None:
                fallback = _fallback_records(where, raw, set_types.count(58))
            dset = fallback[n58]
        if set_type == 58:
            n58 += 1
        if set_type == 164:
            unit_factors = (float(dset.get("length", 1.0)), float(dset.get("force", 1.0)))
        else:
            records.append(dset)
    time_records = [d for d in records if _is_time_record(d)]
    if not time_records:
        what = _describe(set_types, [int(d.get("func_type", -1)) for d in records])
        raise InputFileError(f"{where}: holds {what} but no UFF58 time record "
                             "(function type 1); expected time histories")
    channels = [_record_channel(d, k, where, unit_factors, given_time)
                for k, d in enumerate(time_records)]
    notes: list[str] = []
    for k, (c, d) in enumerate(zip(channels, time_records, strict=True)):
        label = _label(d.get("abscissa_axis_units_lab"))
        abscissa = read_unit(label)
        said = f"{where}: record {k + 1} ({c.name!r}) abscissa"
        if given_time is not None:
            if overrides_stated_time(label, given_time):
                notes.append(f"{said} unit {label or 'none'!r} overridden: taken as "
                             f"{given_time.label!r} (time_unit), sample rate "
                             f"{c.sample_rate_hz:.6g} Hz")
        elif not label:
            # an abscissa in ms without a label gives a rate 1000 x too low: the reading is said
            notes.append(f"{said} states no unit: taken as seconds, the unit of time of every "
                         f"UFF unit system (sample rate {c.sample_rate_hz:.6g} Hz); if it is "
                         "not, give it with time_unit=UNIT")
        elif abscissa.corrected and abscissa.quantity == "time":
            notes.append(f"{said} {abscissa.correction}")
        if c.source_unit.startswith("UFF data type"):
            basis = ("the file's dataset 164 unit factors" if has_units_dataset
                     else "SI (no dataset 164 in the file)")
            notes.append(f"{where}: record {k + 1} ({c.name!r}) has no unit label; unit from "
                         f"its {c.source_unit} ({c.quantity}) in {basis}")
    described = _described_names(time_records)
    if described is not None:
        channels = [replace(c, name=n) for c, n in zip(channels, described, strict=True)]
    for k, (c, d) in enumerate(zip(channels, time_records, strict=True)):
        direction = int(d.get("rsp_dir", 0) or 0)
        if direction < 0:
            # the record holds the component along -X/-Y/-Z: in the +axis convention of the
            # other channels its sign is the opposite
            channels[k] = replace(c, data=-c.data)
            notes.append(f"{where}: record {k + 1} ({c.name!r}) is measured in direction "
                         f"{_DIRECTIONS.get(direction, direction)}: sign applied (values "
                         f"negated to {_DIRECTIONS.get(-direction, -direction)})")
    names = unique_names([c.name for c in channels])
    channels = [c if c.name == n else Channel(n, c.quantity, c.data, c.sample_rate_hz,
                                              c.source_unit, c.start_time_s)
                for c, n in zip(channels, names, strict=True)]
    # the analysis judges from it how well a start offset between two records is known
    metadata: dict = {"uff_time_records": len(channels),
                      "start_time_significant_digits": UFF_START_TIME_DIGITS}
    if notes:
        metadata["reader_notes"] = notes
    date = _label(time_records[0].get("id3"))
    if date:
        metadata["uff_id3"] = date
    return Measurement(source=where, channels=tuple(channels), sha256=file_sha256(path),
                       file_format="uff", metadata=metadata)


def _dataset_58(ch: Channel, index: int) -> dict:
    if ch.n_samples < 2:
        raise ParameterError(f"channel {ch.name!r}: UFF needs at least 2 samples, "
                             f"has {ch.n_samples}")
    quantity = ch.quantity
    if quantity in _QUANTITY_CODES:
        code, unit_label = _QUANTITY_CODES[quantity], SI_UNITS[quantity]
        len_exp, force_exp = _EXPONENTS[quantity]
    else:
        # Unknown quantities keep their values as read; keep their label so that they read
        # back as the same (unknown) unit.
        code, len_exp, force_exp = 0, 0, 0
        unit_label = SI_UNITS["voltage"] if quantity == "voltage" else (ch.source_unit or "NONE")
    if not np.all(np.isfinite(ch.data)):
        # pyuff silently replaces NaN/inf by numbers (np.nan_to_num); refuse instead.
        raise ParameterError(f"channel {ch.name!r}: non-finite samples cannot be written to UFF")
    x = ch.start_time_s + np.arange(ch.n_samples) / ch.sample_rate_hz
    # Fixed-width header fields: an entity name has 10 columns, labels 20; longer text would
    # shift the following fields, so the full name goes to ID line 1 (80 columns).
    entity = ch.name if len(ch.name) <= 10 and ch.name.strip() else "NONE"
    return {
        "type": 58, "binary": 0, "func_type": 1, "func_id": index + 1, "ver_num": 0,
        "load_case_id": 0, "id1": ch.name[:80] or "NONE", "id2": "pidcore",
        "id3": _dt.datetime.now().strftime("%d-%b-%y %H:%M:%S"), "id4": "NONE", "id5": "NONE",
        "rsp_ent_name": entity, "rsp_node": index + 1, "rsp_dir": 0,
        "ref_ent_name": "NONE", "ref_node": 0, "ref_dir": 0,
        "abscissa_spacing": 1, "abscissa_spec_data_type": 17, "abscissa_axis_lab": "Time",
        "abscissa_axis_units_lab": "s", "abscissa_len_unit_exp": 0,
        "abscissa_force_unit_exp": 0, "abscissa_temp_unit_exp": 0,
        "ordinate_spec_data_type": code, "ordinate_len_unit_exp": len_exp,
        "ordinate_force_unit_exp": force_exp, "ordinate_temp_unit_exp": 0,
        "ordinate_axis_lab": quantity[:20], "ordinate_axis_units_lab": unit_label[:20],
        "orddenom_spec_data_type": 0, "z_axis_spec_data_type": 0, "z_axis_value": 0.0,
        "x": x, "data": np.asarray(ch.data, dtype=np.float64),
    }


def write_uff(measurement: Measurement, path: str | os.PathLike[str], *,
              binary: bool = False) -> None:
    """Write every channel as a dataset 58 time record (double precision), atomically.

    Parameters
    ----------
    measurement : Measurement
    path : str or path-like
    binary : bool
        ``True`` writes 58b (IEEE 754 float64, native byte order) via pyuff; ``False`` writes
        ASCII (E20.11, twelve significant digits).

    Notes
    -----
    The sample interval is stored with six significant digits (the E13.5 field of the
    format); readers snap rates to the roundest one within that resolution
    (:func:`pidcore.io._common.snap_rate`).
    """
    if not measurement.channels:
        raise ParameterError(f"{measurement.source}: nothing to write (no channels)")
    sets = [_dataset_58(ch, i) for i, ch in enumerate(measurement.channels)]
    for dset in sets:
        dset["binary"] = 1 if binary else 0
    with atomic_path(path) as tmp:
        # mode="add" on the empty temporary file: in "overwrite" mode pyuff 2.5 reopens the
        # file with "wb" before the binary samples of the first set, erasing its header.
        try:
            pyuff.UFF(str(tmp)).write_sets(sets, mode="add", force_double=True)
        except Exception as exc:  # pyuff raises bare Exception
            reraise_interrupt(exc)
            raise ParameterError(f"{path}: cannot write UFF ({exc})") from None
