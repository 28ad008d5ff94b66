"""Delimited text (CSV/TXT) of channels: names, optionally units, then numbers.

Understood as spreadsheet tools, MATLAB and acquisition software write them:

* header cells ``Time [s]``, ``Force (kN)``, ``Velocity [mm/s]``, DIN-style ``Time/s``,
  ``Force/N``, ``Velocity in m/s`` (only where the unit is one of the quantity the name says:
  ``Velocity/Force`` stays a name), or a bare name with the units in a **unit row** under the
  names (``s;N;mm/s`` or ``[s];[N];[mm/s]``); a bare name without a unit has quantity
  ``"unknown"`` (the analysis asks for its unit, never takes it as SI);
* **free-text lines** before the header (title, date, comments, ``#`` lines) are skipped: the
  header is the last text line before the numbers;
* delimiters comma, semicolon, tab or runs of blanks; a **decimal comma** when the delimiter is
  not a comma, recognised from any of the first data rows (the first may hold integers only);
* encodings UTF-8 (with or without BOM), **UTF-16** (BOM or NUL pattern), else Latin-1.

The time base is the first column whose unit is a time unit or whose name is ``time``/``t``
(``zeit``, ``temps``, ``x``); with ``time_unit`` given, else the first column named so whose
unit is not read (``Time [msek]``), else the first column where its header states no other
quantity (``Abscissa``, ``Zeit_ms``), read in that unit (noted). Without ``time_unit`` such a
column is refused by name, never taken as seconds. Later time columns (x/y pairs) are the
time base of the columns up to the next one.
It must be evenly spaced within the precision it was printed with (a column printed with 5-6
significant digits is fitted, see :func:`pidcore.io._common.rate_from_times`). Without one,
``sample_rate_hz`` must be given; with one, ``sample_rate_hz`` overrides it (noted).

The numbers are parsed by pandas' C parser straight from the file, in chunks, so that reading
needs about the size of the resulting float64 arrays (well under 3x the file size).
"""

from __future__ import annotations

import codecs
import csv
import math
import os
import re

import numpy as np
import pandas as pd

from ..atomic_files import atomic_path
from ..errors import InputFileError, ParameterError, a_or_an, clipped, listed
from ..records import Measurement
from ..units import (
    UnitReading,
    given_time_unit,
    overrides_stated_time,
    read_unit,
    why_not_a_time_unit,
)
from ._common import (
    file_sha256,
    interpret_unit,
    make_channel,
    overridden_rate,
    rate_from_times,
    unique_names,
)

_HEADER_CELL = re.compile(r"^\s*(?P<name>.*?)\s*(?:[\[(](?P<unit>[^\[\]()]*(?:\([^)]*\))?"
                          r"[^\[\]()]*)[\])])?\s*$")
_TIME_NAMES = {"time", "t", "zeit", "temps", "x"}
#: Bytes read to find the header, the unit row and the number format.
_HEAD_BYTES = 1 << 16
_NUMBER = re.compile(r"^[+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?$|^[+-]?(?:nan|inf)$",
                     re.IGNORECASE)
_LINE_BREAK = re.compile(r"\r\n|\n|\r")
#: Longest line (bytes) of a table read. A row of numbers is tens of bytes per column, so
#: this allows some 400 000 columns; pandas' tokenizer holds a whole line in memory several
#: times over, and a 500 MB file of one line took 1.6 GB before it was refused.
MAX_LINE_BYTES = 16 * 2**20
#: Most bytes read to find the first rows of numbers: a header line as long as a line may be
#: and a MiB of lines around it.
_HEAD_MAX_BYTES = MAX_LINE_BYTES + 2**20
_SCAN_CHUNK_BYTES = 1 << 20


def _split_header(cell: str) -> tuple[str, str]:
    """``"Velocity [mm/s]"`` -> ``("Velocity", "mm/s")``, ``"Time/s"`` or ``"Time in s"`` ->
    ``("Time", "s")`` (:func:`_quantity_and_unit`); a bare name has unit ``""``."""
    cell = cell.strip().strip('"').strip()
    match = _HEADER_CELL.match(cell)
    if match is None or not match.group("name"):
        return cell, ""
    if not match.group("unit"):
        return _quantity_and_unit(match.group("name")) or (match.group("name"), "")
    return match.group("name"), match.group("unit").strip()


#: Where a DIN-style header (DIN 1313 ``Quantity/unit``, German ``Größe in Einheit``) may
#: split into its quantity and unit.
_QUANTITY_UNIT_SEPARATOR = re.compile(r"\s*/\s*|\s+in\s+|\s+-\s+", re.IGNORECASE)
#: The header spellings of a unit read, as the refusals of a header not read list them.
#: Where a header named like a time splits into its name and unit, to say why its unit was
#: not read: the DIN-style separators or an opening bracket (``Time [msek]``).
_TIME_HEADER_SPLIT = re.compile(r"\s*[\[(]\s*|" + _QUANTITY_UNIT_SEPARATOR.pattern,
                                re.IGNORECASE)
ACCEPTED_HEADER_SPELLINGS = ("'Time [s]', 'Time (s)', 'Time/s', 'Time in s', 'Time - s' or "
                             "'Time' over a unit row 's'")


def _named_quantity(name: str) -> str | None:
    """The quantity a channel name says (time, force, velocity, acceleration), or None where
    it says none or several."""
    from .roles import name_suggests  # roles is the one place of the role words

    if name.strip().lower() in _TIME_NAMES:
        return "time"
    said = [role for role in ("force", "velocity", "acceleration") if name_suggests(name, role)]
    return said[0] if len(said) == 1 else None


def _quantity_and_unit(cell: str) -> tuple[str, str] | None:
    """Name and unit of a DIN-style header (``Time/s``, ``Velocity in m/s``, ``Force/kN``),
    or None where the cell is not one.

    Only where the unit is a known one of the quantity the name says: a ``/`` is also a ratio
    (``Velocity/Force`` a mobility, ``F/V`` a sensitivity) and ``in`` a word of a name, so a
    cell split any other way would read a name as a unit; such a cell stays a name without a
    unit (the analysis asks for its unit, never takes it as SI)."""
    for separator in _QUANTITY_UNIT_SEPARATOR.finditer(cell):
        name, unit = cell[:separator.start()].strip(), cell[separator.end():].strip()
        if not name or not unit:
            continue
        quantity = _named_quantity(name)
        if quantity is not None and read_unit(unit).quantity == quantity:
            return name, unit  # also a unit refused (Mm/s): the analysis says why
    return None


def _name_and_unit(cell: str, row_unit: str) -> tuple[str, str]:
    """Channel name and unit text of a header cell and its unit-row cell (``""``: none).

    Beside a unit row, text in brackets that is no unit belongs to the name (Testlab's
    ``Force (Drive point)``): taken as the unit, it hid the row's unit and cut the name. A
    name stating a unit the row contradicts (``Force (N)`` over ``kN``) gives a unit no table
    knows, which the analysis refuses (``--force-unit`` decides): either reading is a
    silent x1000 when it is the wrong one.
    """
    name, own = _split_header(cell)
    if not row_unit and own:
        return _unit_in_the_name(name, own)
    if not row_unit or not own:
        return name, own or row_unit
    own_reading, row_reading = _unit_key(own), _unit_key(row_unit)
    if own_reading is None:
        return cell.strip().strip('"').strip(), row_unit
    if row_reading is None or _same_unit(own_reading, row_reading):
        return name, own  # a row of '-' (no unit) does not contradict the name
    return name, f"{own} in the name, {row_unit} in the unit row"


def _unit_in_the_name(name: str, own: str) -> tuple[str, str]:
    """Name and unit of a cell whose name ends in brackets of its own (``Force (N) [kN]``,
    ``Force [N] (Drive point)``): the last brackets are taken for the unit unless they hold
    no unit and the name's do; two units that read differently give a unit no table knows,
    which the analysis refuses (``--force-unit`` decides). The last brackets alone made
    'Force (N) [kN]' of newtons a silent x1000."""
    inner_name, inner = _split_header(name)
    if not inner or not inner_name:
        return name, own
    inner_reading, own_reading = _unit_key(inner), _unit_key(own)
    if inner_reading is None:
        return name, own
    if own_reading is None:
        return f"{inner_name} ({own})", inner  # Testlab-like 'Force [N] (Drive point)'
    if _same_unit(own_reading, inner_reading):
        return inner_name, own
    return inner_name, f"{inner} in the name, {own} in brackets"


def _unit_key(text: str) -> tuple[str, float | str] | None:
    """Quantity and SI factor of a unit text; ``("refused", text)`` for a unit pidcore reads
    but refuses (``Mm/s``, ``MM/S``: a unit, not words of a name, whose refusal the analysis
    gives); None for text that is no unit (``Drive point``, ``-``)."""
    reading = read_unit(text)
    if reading.info is not None:
        return reading.info.quantity, reading.info.factor
    return ("refused", text.strip()) if reading.quantity is not None else None


def _same_unit(first: tuple[str, float | str], second: tuple[str, float | str]) -> bool:
    if first[0] == "refused" or second[0] == "refused":
        return first == second
    return first[0] == second[0] and math.isclose(first[1], second[1], rel_tol=1e-9)


def _encoding(head: bytes) -> str:
    """Encoding from a BOM, the NUL pattern of UTF-16 without BOM, or a UTF-8 trial."""
    if head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return "utf-16"
    if head.startswith(codecs.BOM_UTF8):
        return "utf-8-sig"
    sample = head[:512]
    if len(sample) >= 4 and sample[1::2].count(0) > 0.4 * len(sample) / 2 \
            and sample[0::2].count(0) == 0:
        return "utf-16-le"
    if len(sample) >= 4 and sample[0::2].count(0) > 0.4 * len(sample) / 2 \
            and sample[1::2].count(0) == 0:
        return "utf-16-be"
    try:
        head.decode("utf-8")
        return "utf-8"
    except UnicodeDecodeError as exc:
        if exc.start >= len(head) - 3:  # a character cut at the end of the head
            return "utf-8"
        return "latin-1"


def _cells(line: str, delimiter: str) -> list[str]:
    if delimiter == r"\s+":
        return line.split()
    if '"' in line:
        # a quoted cell may hold the delimiter: a decimal comma in a comma-separated export
        # ("0,0002","-0,005"), which split into twice the columns made the header row look
        # too short, and the file was refused as having "no header row"
        return [c.strip() for c in next(csv.reader([line], delimiter=delimiter,
                                                   skipinitialspace=True))]
    return [c.strip().strip('"').strip() for c in line.split(delimiter)]


def _delimiter(lines: list[str]) -> str:
    for delimiter in ("\t", ";", ","):
        if all(delimiter in ln for ln in lines):
            return delimiter
    return r"\s+"


def _is_numeric_row(line: str, delimiter: str) -> bool:
    cells = [c for c in _cells(line, delimiter) if c]
    return bool(cells) and all(_NUMBER.match(c) for c in cells)


def _looks_like_unit(cell: str) -> bool:
    text = cell.strip().strip("[]()").strip()
    return not text or text.lower() in {"-", "1", "none"} or _unit_key(text) is not None


class _HeadTooShort(Exception):
    """The head read holds no three rows of numbers yet, and more of the file can be read."""


def _layout(lines: list[str], where: str, *, read_bytes: int | None = None,
            more: bool = False) -> tuple[int, str, list[str], list[str], str]:
    """Index of the first data line, delimiter, names, units and decimal mark.

    ``read_bytes``: the lines are the first that many bytes of a longer file (None: all of
    it); ``more``: a longer head can be read, so a head without rows of numbers raises
    :class:`_HeadTooShort` rather than refusing the file."""
    candidates = [i for i, ln in enumerate(lines) if ln.strip()]
    first = None
    for pos, i in enumerate(candidates):
        window = [lines[j] for j in candidates[pos:pos + 3]]
        delimiter = _delimiter(window)
        if all(_is_numeric_row(ln, delimiter) for ln in window):
            first = i
            break
    if first is None and more:
        raise _HeadTooShort
    if first is None:  # a bad cell in the first rows: let the parser name it
        first = next((i for i in candidates if _is_numeric_row(lines[i], _delimiter([lines[i]]))),
                     None)
    if first is None:
        lines_of = "its" if read_bytes is None else (
            f"the first {read_bytes / 2**20:.3g} MiB of the file, its first")
        # "header but no data rows" was said of any text without a row of numbers: a report
        # CSV, a TOML file, a load-case table of 40 rows
        # the first line quoted whole up to 60 characters (62 with its quotes)
        what = "header but no data rows" if len(candidates) == 1 else \
            f"no rows of numbers in {lines_of} {len(candidates)} lines (the first: " \
            f"{clipped(repr(lines[candidates[0]].strip()), 62)})" if candidates \
            else "no rows of numbers"
        raise InputFileError(f"{where}: {what}; expected a header row such as "
                             "'Time [s],Force [N],Velocity [m/s]' and data rows")
    data = [lines[j] for j in candidates if j >= first][:200]
    delimiter = _delimiter(data[:3])
    n_cols = len(_cells(data[0], delimiter))
    before = [j for j in candidates if j < first and not lines[j].lstrip().startswith("#")]
    text_rows = [lines[j] for j in before if len(_cells(lines[j], delimiter)) >= n_cols
                 or (delimiter == r"\s+" and len(_cells(lines[j], delimiter)) >= 1)]
    if not text_rows and before and 2 <= len(_cells(lines[before[-1]], delimiter)) < n_cols:
        # a header of fewer names than the rows have cells: "no header row" sent the user
        # looking for a header that is there; a decimal comma in a comma-separated export
        # (0,5,12,3 under Time,Force) splits every number in two
        short = len(_cells(lines[before[-1]], delimiter))
        counts = [len(_cells(row, delimiter)) for row in data]
        low, high = min(counts), max(counts)
        # a number printed without decimals (0) stays one cell: rows of 4 to 6 under 3 names
        why = ("; numbers with a decimal comma in a comma-separated file split in two: "
               "export with ';' or tab as the separator, or quote the cells"
               if delimiter == "," and (high == 2 * short or low != high) else "")
        held = f"{low}" if low == high else f"{low} to {high}"
        raise InputFileError(f"{where}: the header (line {before[-1] + 1}) names {short} "
                             f"columns but the data rows hold {held} cells{why}; expected "
                             "one name per column, such as 'Time [s],Force [N],Velocity [m/s]'")
    if not text_rows:
        raise InputFileError(f"{where}: no header row before the numbers; expected names such "
                             "as 'Time [s],Force [N],Velocity [m/s]'")
    def header(row: str) -> list[str]:
        # one column has no delimiter: its header is the whole line ('Time [s]' split at its
        # space was two columns over data rows of one, refused for that, not for holding no
        # channel)
        if n_cols > 1:
            return _cells(row, delimiter)
        own = _delimiter([row])  # a header of more columns than the data says so
        return [row.strip().strip('"').strip()] if own == r"\s+" else _cells(row, own)

    names = header(text_rows[-1])
    units = [""] * len(names)
    if len(text_rows) >= 2 and all(_looks_like_unit(c) for c in names) \
            and any(c.strip() for c in names):
        units = [c.strip().strip("[]()").strip() for c in names]  # a unit row under the names
        names = header(text_rows[-2])
        units = (units + [""] * len(names))[:len(names)]
    decimal = "," if (any("," in ln for ln in data) if delimiter != "," else
                      any("," in c for ln in data for c in _cells(ln, delimiter))) else "."
    return first, delimiter, names, units, decimal


def _check_line_lengths(path: str | os.PathLike[str], where: str) -> None:
    """Refuse a line longer than :data:`MAX_LINE_BYTES`, streaming (1 MiB at a time), before
    pandas reads the file. Files no longer than the limit need no scan, and a chunk with a
    line break in it ends any line, so only the first and last break of a chunk are sought."""
    if os.path.getsize(path) <= MAX_LINE_BYTES:
        return
    run, line = 0, 1  # bytes since the last line break; number of the current line
    line_break = b""  # LF (also ends CRLF lines), else CR (classic Mac)
    with open(path, "rb") as fh:
        while chunk := fh.read(_SCAN_CHUNK_BYTES):
            if not line_break:
                line_break = b"\n" if b"\n" in chunk or b"\r" not in chunk else b"\r"
            first = chunk.find(line_break)
            if first < 0:
                run += len(chunk)
            elif run + first + 1 > MAX_LINE_BYTES:
                run += first + 1
            else:
                line += chunk.count(line_break)
                run = len(chunk) - chunk.rfind(line_break) - 1
            if run > MAX_LINE_BYTES:
                raise InputFileError(f"{where}: line {line} is longer than "
                                     f"{MAX_LINE_BYTES >> 20} MiB; expected rows of numbers "
                                     "(is the file one line, or binary?)")


#: Bytes read from a file's end to judge its last line against the rows before it.
_TAIL_BYTES = 1 << 16
#: Most rows before the last line it is compared with, and fewest that must agree on how
#: they write a column before a last value written otherwise counts as cut: a writer that
#: drops trailing zeros (%g) gives 20 rows of one shape by chance about 0.9^20 = 12 % of the
#: time, and only where its last value is also shorter does that matter.
_TAIL_ROWS = 200
_MIN_SHAPED_ROWS = 20
#: What a number cut short may look like ('-', '7.681693e-').
_NUMBER_BEGUN = re.compile(r"^[+-]?(?:\d|[.,]\d|$)[\d.,]*(?:[eE][+-]?\d*)?$")
_MANTISSA_EXPONENT = re.compile(r"^[+-]?(\d*)(?:[.,](\d*))?(?:[eE][+-]?(\d*))?$")


def _number_shape(cell: str) -> tuple[int, int] | None:
    """Digits after the decimal mark and digits of the exponent (-1: none) of a number as
    written, or None for a cell that is no number of that form."""
    match = _MANTISSA_EXPONENT.match(cell)
    if match is None or not match.group(1) and not match.group(2):
        return None
    decimals, exponent = match.group(2), match.group(3)
    return (len(decimals or ""), -1 if exponent is None else len(exponent))


def _tail_text(path: str | os.PathLike[str], encoding: str) -> tuple[str, bool]:
    """The last :data:`_TAIL_BYTES` of a file as text, and whether that is the whole file
    (else its first line may be cut by the read)."""
    size = os.path.getsize(path)
    start = max(size - _TAIL_BYTES, 0)
    with open(path, "rb") as fh:
        if encoding == "utf-16":  # which order a BOM said, for text read without it
            encoding = "utf-16-be" if fh.read(2) == codecs.BOM_UTF16_BE else "utf-16-le"
        if encoding.startswith("utf-16"):
            start -= start % 2
        elif encoding == "utf-8-sig" and start:
            encoding = "utf-8"
        fh.seek(start)
        tail = fh.read()
    text = tail.decode(encoding, errors="replace")
    return (text.removeprefix("\ufeff") if start == 0 else text), start == 0


def _check_last_line(path: str | os.PathLike[str], where: str, *, delimiter: str,
                     encoding: str) -> None:
    """Refuse a file whose last line has no line break after it and is visibly cut: an
    interrupted copy or export. It lacks a value that every row before it holds, or its last
    value is written with fewer decimals (or a shorter exponent, or none) than that column in
    every row before it, as a fixed format (``%.6e``) writes them all; read as data, a row
    ``...,7.681693`` for ``7.681693e-02`` took 13 % off a record's SDC without a word. A last
    line that lacks only the line break, as many writers leave it, is read."""
    text, whole = _tail_text(path, encoding)
    if not text or text[-1] in "\r\n":
        return
    lines = _LINE_BREAK.split(text)
    last = lines[-1]
    if not last.strip() or last.lstrip().startswith("#"):
        return
    rows = [_cells(ln, delimiter) for ln in lines[0 if whole else 1:-1][-_TAIL_ROWS - 1:]
            if ln.strip() and _is_numeric_row(ln, delimiter)][-_TAIL_ROWS:]
    cells = _cells(last, delimiter)
    given = [i for i, c in enumerate(cells) if c]
    if not rows or not given or not all(_NUMBER.match(cells[i]) for i in given[:-1]) \
            or not _NUMBER_BEGUN.match(cells[given[-1]]):
        return  # no row of numbers (a footer): the parser names it
    why = ""
    filled = [i for i in range(max(len(r) for r in rows))
              if all(i < len(r) and r[i] for r in rows)]
    missing = [i for i in filled if i >= len(cells) or not cells[i]]
    if missing:
        why = (f"it holds {len(given)} values where the {len(rows)} rows before it hold "
               f"{len(filled)}")
    elif len(rows) >= _MIN_SHAPED_ROWS:
        at = given[-1]
        shapes = {_number_shape(r[at]) for r in rows if at < len(r)}
        own = _number_shape(cells[at])
        if len(shapes) == 1 and None not in shapes:
            (decimals, exponent), = shapes
            if own is None or own[0] < decimals or own[1] < exponent:
                how = f"{decimals} decimals" + (f" and a {exponent}-digit exponent"
                                                 if exponent >= 0 else "")
                why = (f"its last value {cells[at]!r} is written shorter than the "
                       f"{len(rows)} rows before it write that column ({how}, as in "
                       f"{rows[-1][at]!r})")
    if why:
        raise InputFileError(f"{where}: line {_line_count(path)} is cut off: the file ends in "
                             f"it without a line break and {why} (an interrupted copy or "
                             "export?); expected complete rows: copy or export the file again")


def read_csv(path: str | os.PathLike[str], *, sample_rate_hz: float | None = None,
             time_unit: str | None = None) -> Measurement:
    """Read a delimited text file of channels into a SI :class:`Measurement`.

    Parameters
    ----------
    path : str or path-like
    sample_rate_hz : float, optional
        Sample rate, Hz, for files without a time column; with a time column it overrides the
        column (the measurement's ``reader_notes`` say so).
    time_unit : str, optional
        Unit of the time columns (``"ms"``): for a column without one, which is otherwise
        taken as seconds (noted); it overrides a column's own unit (noted). Where no header
        reads as a time, the time column is the first named as one whose unit is not read
        (``Time [msek]``), else the first column where its header states no other quantity
        (``Abscissa``; noted); without ``time_unit`` such a file is refused naming it.

    Examples
    --------
    A file ``Time [s],Force [kN]`` / ``0,1.5`` / ``0.001,1.6`` gives a channel ``Force`` of
    quantity ``force`` in N sampled at 1000 Hz.
    """
    where = str(path)
    given_time = given_time_unit(time_unit)
    _check_line_lengths(path, where)
    # the head grows until it holds the first rows of numbers: a metadata block of 68 kB
    # (or one header line of 5 MB) before them was refused as "no rows of numbers in its
    # 65 lines" of a file of 3961 lines
    size = _HEAD_BYTES
    while True:
        with open(path, "rb") as fh:
            head = fh.read(size)
            complete = not fh.read(1)
        if not head.strip():
            raise InputFileError(f"{where}: empty file; expected a header row such as "
                                 "'Time [s],Force [N],Velocity [m/s]' and data rows")
        encoding = _encoding(head)
        if "\x00" in head[:4096].decode("latin-1") and not encoding.startswith("utf-16"):
            raise InputFileError(f"{where}: binary content; expected delimited text")
        text = codecs.getincrementaldecoder(encoding)(errors="replace").decode(head,
                                                                             final=complete)
        lines = _LINE_BREAK.split(text)
        if not complete:
            lines = lines[:-1]  # possibly cut
        try:
            first, delimiter, header_cells, unit_cells, decimal = _layout(
                lines, where, read_bytes=None if complete else len(head),
                more=not complete and size < _HEAD_MAX_BYTES)
            break
        except _HeadTooShort:
            size *= 4
    _check_last_line(path, where, delimiter=delimiter, encoding=encoding)
    notes: list[str] = []
    try:
        # skiprows skips raw lines (blank ones included), as counted by _LINE_BREAK
        columns = _numeric_columns(path, sep=delimiter, decimal=decimal, skiprows=first,
                                   encoding=encoding)
    except (pd.errors.ParserError, ValueError, UnicodeDecodeError) as exc:
        first_line = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InputFileError(f"{where}: not a numeric delimited table ({first_line}); expected "
                             "one header row of names and units followed by numbers") from None
    _drop_trailing_empty_rows(columns, where, notes)
    # A trailing delimiter makes an empty last column; drop it.
    while header_cells and not header_cells[-1].strip() and len(columns) == len(header_cells) \
            and np.all(np.isnan(columns[-1])):
        header_cells.pop()
        unit_cells = unit_cells[:len(header_cells)]
        columns.pop()
    while len(columns) > len(header_cells) and np.all(np.isnan(columns[-1])):
        columns.pop()
    if len(columns) != len(header_cells):
        raise InputFileError(f"{where}: the header has {len(header_cells)} columns but the data "
                             f"rows have {len(columns)}")
    cells = [_name_and_unit(cell, unit) for cell, unit in zip(header_cells, unit_cells,
                                                               strict=True)]
    n_rows = columns[0].size if columns else 0
    if len(cells) < 1 or n_rows < 2:
        raise InputFileError(f"{where}: expected at least one channel and two data rows")

    time_index, by_rule = _time_column(cells, header_cells, given_time)
    if sample_rate_hz is not None:
        if not sample_rate_hz > 0:
            raise ParameterError(f"sample_rate_hz must be positive, got {sample_rate_hz!r}")
        rate, start_time = float(sample_rate_hz), 0.0
        if time_index is not None:
            name, unit = cells[time_index]
            factor = _seconds_per(unit, given_time)
            start_time = float(columns[time_index][0]) * factor
            notes.append(f"{where}: time column {name!r} ignored: the sample rate "
                         f"{rate:g} Hz was given (sample_rate_hz)"
                         + overridden_rate(_in_seconds(columns[time_index], factor), rate))
    elif time_index is not None:
        name, unit = cells[time_index]
        factor = _seconds_per(unit, given_time)
        if read_unit(unit).corrected and given_time is None:
            # 'Time [US]' is µs, a factor the header's case did not state: said
            notes.append(f"{where}: time column {name!r}: {read_unit(unit).correction}")
        rate, start_time, note = rate_from_times(_in_seconds(columns[time_index], factor),
                                                 what=f"{where}: column {name!r}" + (
                                                     f" (taken as the time with time_unit: "
                                                     f"{by_rule})" if by_rule else ""),
                                                 with_note=True)
        if note:
            notes.append(note)
        if given_time is not None:
            if overrides_stated_time(unit, given_time):
                notes.append(f"{where}: time column {name!r} ({unit or 'no unit'}) taken as "
                             f"{given_time.label!r} (time_unit), sample rate {rate:.6g} Hz"
                             + (f" ({by_rule})" if by_rule else ""))
        elif not unit:
            # a time in ms read as s makes the frequency, acceleration and energy per cycle
            # 1000 x off (the loss factor and SDC unchanged): the assumption is said
            notes.append(f"{where}: time column {name!r} has no unit: taken as seconds "
                         f"(sample rate {rate:.6g} Hz); if it is not, write its unit in the "
                         "header ('Time [ms]'), give it (time_unit=UNIT) or give the sample "
                         "rate (sample_rate_hz)")
    else:
        raise InputFileError(f"{where}: no time column"
                             f"{_why_no_time_column(cells, header_cells, given_time)} "
                             f"and no sample rate (a time column is headed "
                             f"{ACCEPTED_HEADER_SPELLINGS}); add a time column or give the "
                             "sample rate (sample_rate_hz)")

    pair_times = _pair_time_columns(cells, time_index, columns)
    keep = [i for i in range(len(cells)) if i != time_index and i not in pair_times]
    if not keep:
        raise InputFileError(f"{where}: only a time column ({cells[time_index][0]!r}), no force "
                             "or velocity channel; expected channel columns beside it, e.g. "
                             "'Time [s],Force [N],Velocity [m/s]'")
    names = unique_names([cells[i][0] or f"column {i + 1}" for i in keep])
    bases = _pair_time_bases(columns, cells, pair_times, keep, names, where=where,
                             main=(rate, start_time, n_rows),
                             given_rate=sample_rate_hz, notes=notes, given_time=given_time)
    for name, i in zip(names, keep, strict=True):
        ended = _channel_end(columns[i][:bases[i][2]], name, bases[i], where, notes)
        if ended < bases[i][2]:
            bases[i] = (bases[i][0], bases[i][1], ended)
    # each column is an array of its own: a channel holds its column, not the whole table
    # (time column and all) as a view of pandas' block did
    channels = tuple(make_channel(n, columns[i][:bases[i][2]], sample_rate_hz=bases[i][0],
                                  unit=cells[i][1], start_time_s=bases[i][1])
                     for n, i in zip(names, keep, strict=True))
    del columns
    metadata: dict = {"csv_encoding": encoding}
    if notes:
        metadata["reader_notes"] = notes
    return Measurement(source=where, channels=channels, sha256=file_sha256(path),
                       file_format="csv", metadata=metadata)


#: Rows parsed at a time: each chunk goes straight into the columns, so the table is held
#: once, not as pandas' block and then again as the channels' copies (2x the table).
_CSV_CHUNK_ROWS = 1 << 14


def _line_count(path: str | os.PathLike[str]) -> int:
    """Lines of a file at most (LF or CR line ends, a last line without one), counted in
    blocks: the rows a table can hold, to size its columns before parsing."""
    feeds = returns = 0
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(_SCAN_CHUNK_BYTES), b""):
            feeds += block.count(b"\n")
            returns += block.count(b"\r")
    return max(feeds, returns) + 1


def _numeric_columns(path: str | os.PathLike[str], *, sep: str, decimal: str, skiprows: int,
                     encoding: str) -> list[np.ndarray]:
    """The numbers of a delimited table, one float64 array per column, parsed by pandas' C
    parser :data:`_CSV_CHUNK_ROWS` rows at a time (the same parser and numbers as one call)
    into columns sized by the file's line count. Pieces joined at the end were 2x the table
    in resident memory (the heap kept the freed pieces)."""
    capacity = max(_line_count(path) - skiprows, 0)
    columns: list[np.ndarray] = []
    filled = 0
    with pd.read_csv(path, sep=sep, decimal=decimal, header=None, skiprows=skiprows,
                     dtype=np.float64, encoding=encoding, skipinitialspace=True,
                     skip_blank_lines=True, engine="c", comment="#",
                     chunksize=_CSV_CHUNK_ROWS) as reader:
        for chunk in reader:
            block = chunk.to_numpy(dtype=np.float64, copy=False)
            rows, width = block.shape
            if not columns:
                columns = [np.empty(capacity) for _ in range(width)]
            if width != len(columns) or filled + rows > capacity:
                raise ValueError(f"rows of {len(columns)} and of {width} columns, or more "
                                 f"rows ({filled + rows}) than lines ({capacity})")
            for column, values in zip(columns, block.T, strict=True):
                column[filled:filled + rows] = values
            filled += rows
            del chunk, block
    for column in columns:
        # the room blank, comment and the header's lines left: given back in place (a
        # realloc; the columns are ours, no view of them exists), so that each channel
        # holds its samples only
        column.resize(filled, refcheck=False)
    return columns


def _drop_trailing_empty_rows(columns: list[np.ndarray], where: str, notes: list[str]) -> None:
    """Cut the rows after the last that holds a value in any column, in place, and say so:
    a spreadsheet writes rows of bare delimiters (``,,,``, ``;;;``) below its data, which were
    refused as "the time column holds non-finite values". An empty row inside the data stays
    (a gap in the record is refused where it is)."""
    if not columns or columns[0].size == 0 or not all(np.isnan(c[-1]) for c in columns):
        return  # the usual file: its last row holds a value (nothing allocated for it)
    rows = 0
    for column in columns:  # each column's last value, from the end in blocks
        for end in range(column.size, 0, -_CSV_CHUNK_ROWS):
            given = np.flatnonzero(~np.isnan(column[max(end - _CSV_CHUNK_ROWS, 0):end]))
            if given.size:
                rows = max(rows, max(end - _CSV_CHUNK_ROWS, 0) + int(given[-1]) + 1)
                break
    if rows == 0:
        return  # no value at all: refused as such below
    total = columns[0].size
    for column in columns:
        column.resize(rows, refcheck=False)
    notes.append(f"{where}: {total - rows} row(s) after the last data row hold only "
                 "delimiters (a spreadsheet's empty rows); not read")


def _in_seconds(times: np.ndarray, factor: float) -> np.ndarray:
    """A time column in s: itself where it is in s already (x 1.0 changes no bit; the copy
    was one more column beside the table)."""
    return times if factor == 1.0 else times * factor


def _channel_end(column: np.ndarray, name: str, base: tuple[float, float, int], where: str,
                 notes: list[str]) -> int:
    """Rows of a channel up to its last value: a column whose last cells are empty while its
    time column goes on ends there, said in a note (the analysis cuts the channels it uses to
    their common span, and says so). A whole file was refused for an unused microphone column
    that ended after 1 s. A column of no value at all is refused."""
    if column.size == 0 or not np.isnan(column[-1]):
        return column.size
    given = np.flatnonzero(~np.isnan(column))
    last = int(given[-1]) if given.size else -1
    if last < 0:
        raise InputFileError(f"{where}: channel {name!r} holds no value in any of its "
                             f"{column.size} rows; expected a value in every row")
    rate, start, rows = base
    notes.append(f"{where}: channel {name!r} ends early, at data row {last + 1} of {rows} "
                 f"(t = {start + last / rate:.9g} s): the {rows - last - 1} rows after it hold "
                 "no value; read to there")
    return last + 1


def _pair_time_columns(cells: list[tuple[str, str]], time_index: int | None,
                       columns: list[np.ndarray]) -> list[int]:
    """Time columns after the first one: the x of x/y pairs (``Time;Force;Time;Point1:+Z``,
    as Testlab exports signals of their own time axis). Such a column has a time's name (the
    first time column's, or ``time``), or a time unit and times that advance; each is the time
    base of the columns up to the next one. A column in seconds that does not advance is a
    quantity of that unit (``Delay [ms]``, ``Time offset [s]``), kept as a channel as before:
    read as a time base, it refused the whole file."""
    if time_index is None:
        return []
    time_names = {cells[time_index][0].strip().lower(), "time"}
    pairs = []
    for i, (name, unit) in enumerate(cells):
        if i <= time_index:
            continue
        if name.strip().lower() in time_names and (not unit or _is_time_unit(unit)):
            pairs.append(i)
        elif _is_time_unit(unit):
            given = columns[i][np.isfinite(columns[i])]
            if given.size >= 2 and given[-1] > given[0]:
                pairs.append(i)
    return pairs


def _unread_time_header(header_cells: list[str]) -> tuple[int, str] | None:
    """Index of the first header cell named like a time whose unit was not read, and
    `` (header cell 'Time/xyz' not read: 'xyz' is no unit of time)``, or None: "no time
    column" of a file with one did not say which cell was meant nor why it was not taken."""
    for i, cell in enumerate(header_cells):
        text = cell.strip().strip('"').strip()
        parts = _TIME_HEADER_SPLIT.split(text, maxsplit=1)
        if len(parts) == 2 and parts[0].lower() in _TIME_NAMES - {"x"}:
            unit = parts[1].rstrip("])").strip()
            # the one reason of a time unit's refusal ('furlong' named a displacement's range)
            why = (why_not_a_time_unit(unit) or "").removeprefix(": ") \
                or f"{unit!r} is no unit of time such as s, ms"
            return i, f" (header cell {text!r} not read: {why}; give its unit with time_unit=UNIT)"
    return None


def _states_other_quantity(cell: tuple[str, str]) -> str | None:
    """The quantity other than time a column's header states by its unit or its name
    (``Force [N]``: force), or None."""
    name, unit = cell
    by_unit = interpret_unit(unit)[0] if unit else "unknown"
    if by_unit not in ("unknown", "time"):
        return by_unit
    by_name = _named_quantity(name)
    return by_name if by_name != "time" else None


def _time_column(cells: list[tuple[str, str]], header_cells: list[str],
                 given_time: UnitReading | None) -> tuple[int | None, str]:
    """Index of the time column and, where the rule for a header pidcore does not read as a
    time chose it, how (for the note); ``(None, "")`` for none.

    The first column of a time unit or a time's name without a unit; with ``time_unit``
    given, else the first named as a time whose unit is not read (``Time [msek]``), else the
    first column where its header states no other quantity (``Abscissa``, ``Zeit_ms``): the
    user's unit says what it is. Without ``time_unit`` these are refused
    (:func:`_why_no_time_column`): read as seconds or as a channel, a column in ms gave every
    frequency 1000 x off, or the file was refused without the column named."""
    for i, (name, unit) in enumerate(cells):
        if _is_time_unit(unit) or (not unit and name.strip().lower() in _TIME_NAMES):
            return i, ""
    if given_time is None:
        return None, ""
    unread = _unread_time_header(header_cells)
    if unread is not None:
        return unread[0], "its header's unit not read"
    if cells and _states_other_quantity(cells[0]) is None:
        return 0, "the first column, its header not read as a time"
    return None, ""


def _why_no_time_column(cells: list[tuple[str, str]], header_cells: list[str],
                        given_time: UnitReading | None) -> str:
    """Why no column was taken as the time, naming the column meant: a time header of an
    unread unit, or a first column whose header says no quantity (read with ``time_unit``)."""
    unread = _unread_time_header(header_cells)
    if unread is not None:
        return unread[1]
    if not cells:
        return ""
    name, unit = cells[0]
    shown = header_cells[0].strip().strip('"').strip() or "column 1"
    other = _states_other_quantity(cells[0])
    if given_time is not None:
        return (f" (time_unit={given_time.label!r} reads a first column whose header is not "
                f"read as a time, but {shown!r} is {a_or_an(other)} channel)") if other else ""
    if other is None:
        return (f" (the first column {shown!r} is not read as one: its header states no unit "
                "of time; if it is the time, give its unit with time_unit=UNIT)")
    return ""


def _is_time_unit(unit: str) -> bool:
    return interpret_unit(unit)[0] == "time"


def _seconds_per(unit: str, given: UnitReading | None = None) -> float:
    """Seconds per unit of a time column: ``given`` (the user's time_unit) where there is one;
    a column without a unit is taken as seconds, which the caller notes."""
    if given is not None:
        return given.info.factor
    return interpret_unit(unit)[1] if unit else 1.0


def _pair_time_bases(columns: list[np.ndarray], cells: list[tuple[str, str]],
                     pair_times: list[int],
                     keep: list[int], names: list[str], *, where: str,
                     main: tuple[float, float, int], given_rate: float | None,
                     notes: list[str], given_time: UnitReading | None = None
                     ) -> dict[int, tuple[float, float, int]]:
    """Rate, start and length of each channel column from the time column left of it.

    A later time column was read as a channel and ignored, so its channels took the first
    column's times: a force sampled 1 ms later than the velocity read as a 36 degree phase
    error (a wrong loss factor without a word). A pair's column that ends early (empty
    cells) gives its channels that length; the analysis cuts all to their common span."""
    bases = {i: main for i in keep}
    for k, t_index in enumerate(pair_times):
        end = pair_times[k + 1] if k + 1 < len(pair_times) else len(cells)
        owned = [i for i in keep if t_index < i < end]
        if not owned:
            continue
        times = columns[t_index]
        length = int(np.argmax(np.isnan(times))) if np.isnan(times).any() else times.size
        name, unit = cells[t_index]
        factor = _seconds_per(unit, given_time)
        what = f"{where}: column {name!r} (time of column {owned[0] + 1})"
        if given_time is not None:
            if overrides_stated_time(unit, given_time):
                notes.append(f"{what}: ({unit or 'no unit'}) taken as {given_time.label!r} "
                             "(time_unit)")
        elif read_unit(unit).corrected:
            notes.append(f"{what}: {read_unit(unit).correction}")
        if length < 2:
            raise InputFileError(f"{what}: holds {length} times; expected the time of each "
                                 "sample of its channels")
        if given_rate is not None:
            base = (float(given_rate), float(times[0]) * factor, length)
        else:
            rate, start = rate_from_times(_in_seconds(times[:length], factor), what=what)
            base = (rate, start, length)
        if base == main:
            continue
        for i in owned:
            bases[i] = base
        channels = listed(names[keep.index(i)] for i in owned)
        notes.append(f"{where}: column {name!r} is the time of {channels}: "
                     f"{base[2]} samples from {base[1]:.9g} s at {base[0]:.9g} Hz "
                     f"(the first time column: {main[2]} from {main[1]:.9g} s at "
                     f"{main[0]:.9g} Hz)")
    return bases


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
