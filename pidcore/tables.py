"""User-written tables (the sidecar / settings table, the measured-SDC table of ``calibrate``):
one reader, one way of naming a row.

Such tables come out of spreadsheets as often as out of editors, so they are read as
spreadsheet tools write them, with the detection of the measurement CSV reader
(:mod:`pidcore.io.delimited`):

* encodings UTF-8 (with or without BOM), UTF-16, else cp1252 (a spreadsheet's "ANSI"
  export), else Latin-1;
* the separator is found from the header line: tab, ``;`` or ``,`` (a one-column table has
  none); with ``;`` or tab, the ``numeric`` columns may use a **decimal comma** (``50,5``);
* a line whose first non-blank character is ``#`` is a comment; a ``#`` anywhere else is data
  (file names such as ``MPSTD#Set001_...uff`` hold one); blank lines and lines of empty cells
  (a spreadsheet's ``;;;``) are skipped;
* every cell is text, stripped; quoted cells may hold the separator;
* a column with neither a name nor a value (the trailing ``;;`` a spreadsheet writes for a
  column that once held a cell) is left out; a value under no name is refused.

A row is named by its **line in the file**, as a spreadsheet or an editor shows it: the header
is line 1 when it is the first line, and comment and blank lines count (:func:`line_where`).
"""

from __future__ import annotations

import csv
import os
import re
from collections.abc import Iterable

import pandas as pd

from .errors import InputFileError

__all__ = ["decode_table", "header_cells", "line_where", "read_text_table",
           "read_text_table_file"]

#: A number written with a decimal comma (``50,5``, ``-1,2e-3``): only read as a number in a
#: ``;``- or tab-separated table, where the comma cannot be the separator.
_DECIMAL_COMMA = re.compile(r"^[+-]?(?:\d+,\d*|,\d+)(?:[eE][+-]?\d+)?$")


def line_where(where: str, line: int) -> str:
    """A table row as every message names it: ``"loadcases.csv, line 3"`` (the line in the
    file, counting the header, comments and blank lines, as a spreadsheet numbers rows)."""
    return f"{where}, line {line}"


def decode_table(data: bytes) -> str:
    """Table bytes as text, in the encoding the measurement CSV reader detects (BOM, UTF-16
    NUL pattern, UTF-8), else cp1252, else Latin-1 (a byte string is always Latin-1 text)."""
    from .io.delimited import _encoding

    encoding = _encoding(data)
    if encoding == "latin-1":
        # a spreadsheet's "ANSI" export is cp1252: Latin-1 but for 0x80-0x9F, where cp1252 has
        # letters a file name may hold (en dash, €) and Latin-1 control characters
        try:
            return data.decode("cp1252")
        except UnicodeDecodeError:
            pass
    return data.decode(encoding, errors="replace")


def _is_comment(line: str) -> bool:
    return line.lstrip().startswith("#")


def _separator(header: str) -> str:
    """The separator of a table, from its header line (:func:`pidcore.io.delimited._delimiter`
    picks tab, ``;``, ``,`` in that order); ``,`` for a one-column header."""
    from .io.delimited import _delimiter

    found = _delimiter([header])
    return "," if found == r"\s+" else found


#: A line of empty cells only (a spreadsheet's ``;;;;`` for an empty row; tab is blank).
_EMPTY_CELLS = re.compile(r"^[\s;,]*$")


#: Excel's separator hint, a first line ``sep=;`` that tells it how to split the file.
_SEPARATOR_HINT = re.compile(r'^\s*"?sep=(.)"?\s*$', re.IGNORECASE)


def _table_start(text: str) -> tuple[list[tuple[int, str]], str]:
    """The table's lines (:func:`_table_lines`) after any separator hint of Excel's
    (``sep=;`` as the first line), and the separator: the hint's, else the header's."""
    lines = _table_lines(text)
    if lines and (hint := _SEPARATOR_HINT.match(lines[0][1])):
        return lines[1:], hint.group(1)
    return lines, _separator(lines[0][1]) if lines else ","


def _table_lines(text: str) -> list[tuple[int, str]]:
    """(line number from 1, line) of the lines that are neither blank, a comment nor a row of
    empty cells. An empty spreadsheet row above the header (``;;;;``) was taken for the
    header: the table was refused ('file' in a column without a name) and the app read it as
    a measurement, analysing every file without its settings."""
    # line breaks as the measurement CSV reader counts them: a row's line is the same number
    from .io.delimited import _LINE_BREAK

    return [(n, ln) for n, ln in enumerate(_LINE_BREAK.split(text), start=1)
            if not _EMPTY_CELLS.match(ln) and not _is_comment(ln)]


def header_cells(data: bytes) -> list[str]:
    """The header cells of a table (its first line that is neither blank nor a comment),
    stripped of blanks and quotes; ``[]`` for none. For telling a table from a measurement
    without reading it all."""
    lines, separator = _table_start(decode_table(data[:1 << 16]))
    if not lines:
        return []
    cells = next(csv.reader([lines[0][1]], delimiter=separator, skipinitialspace=True))
    return [c.strip().strip('"').strip() for c in cells]


def header_key(name: str) -> str:
    """A column name as headers are matched: Unicode compatibility form (NFKC: the micro sign
    µ is the Greek mu μ a Greek keyboard or autocorrect types, a no-break space a space), runs
    of white space as one space, lower case. Both look alike in a spreadsheet; one was refused
    as an unknown column."""
    import unicodedata

    return " ".join(unicodedata.normalize("NFKC", str(name)).split()).lower()


def read_text_table(data: bytes, where: str, *, numeric: Iterable[str] = (),
                    example: str = "file,fill_percent,velocity_delay_us",
                    row: str = "file") -> pd.DataFrame:
    """Read a user-written table (see the module's conventions) as text cells.

    Parameters
    ----------
    data : bytes
        The file's bytes.
    where : str
        The table as messages name it (its path or upload name).
    numeric : iterable of str
        Columns (lower-case header names) whose decimal commas are read as decimal points in a
        ``;``- or tab-separated table.
    example, row : str
        The header line an empty table's message suggests, and what one row stands for
        (default: a sidecar / settings table's).

    Returns
    -------
    pandas.DataFrame
        Columns: the header cells, stripped and lower-cased; every cell a stripped string
        (``""`` for empty or missing trailing cells). The index, named ``"line"``, holds each
        row's line in the file (:func:`line_where`).

    Raises
    ------
    InputFileError
        No header line; a row with more cells than the header (naming its line and both
        counts); a header naming a column twice; a value in a column without a name (an
        unnamed column without values, a spreadsheet's trailing ``;;``, is left out).
    """
    kept, separator = _table_start(decode_table(data))
    if not kept:
        raise InputFileError(f"{where}: empty table; expected a header line such as "
                             f"'{example}' and one row per {row}")
    reader = csv.reader((ln for _, ln in kept), delimiter=separator, skipinitialspace=True)
    rows: list[tuple[int, list[str]]] = []
    try:
        start = 0
        for cells in reader:
            rows.append((kept[start][0], [c.strip() for c in cells]))
            start = reader.line_num  # a quoted cell may span lines
    except csv.Error as exc:
        line = kept[min(reader.line_num, len(kept)) - 1][0]
        raise InputFileError(f"{line_where(where, line)}: not a readable table row ({exc}); "
                             f"expected cells separated by {separator!r}") from None
    (_, header), body = rows[0], rows[1:]
    columns = [c.lower() for c in header]
    records, numbers = [], []
    for line, cells in body:
        if not any(cells):
            continue  # a spreadsheet's row of empty cells
        if len(cells) > len(columns):
            raise InputFileError(
                f"{line_where(where, line)}: {len(cells)} cells, but the header (line "
                f"{rows[0][0]}) names {len(columns)} columns separated by {separator!r}; "
                "expected one cell per column (quote a cell that holds the separator)")
        records.append(cells + [""] * (len(columns) - len(cells)))
        numbers.append(line)
    # A spreadsheet writes a separator for every column that once held a cell (``a;b;;``): a
    # column with neither a name nor a value states nothing and is left out. One with a value
    # but no name is refused: what it states cannot be told.
    unnamed = [i for i, c in enumerate(columns) if not c]
    for i in unnamed:
        for line, cells in zip(numbers, records, strict=True):
            if cells[i]:
                raise InputFileError(
                    f"{line_where(where, line)}: {cells[i]!r} in column {i + 1}, which the "
                    f"header (line {rows[0][0]}) leaves without a name; expected a column "
                    "name for every column that holds values")
    if unnamed:
        kept_columns = [i for i in range(len(columns)) if i not in unnamed]
        columns = [columns[i] for i in kept_columns]
        records = [[cells[i] for i in kept_columns] for cells in records]
    doubled = sorted({c for c in columns if columns.count(c) > 1})
    if doubled:
        raise InputFileError(f"{line_where(where, rows[0][0])}: column {doubled[0]!r} given "
                             "more than once; expected each column once")
    table = pd.DataFrame(records, columns=columns, index=pd.Index(numbers, name="line"),
                         dtype=object)
    if separator != ",":
        numeric_keys = {header_key(n) for n in numeric}
        for column in (c for c in columns if header_key(c) in numeric_keys):
            table[column] = [c.replace(",", ".") if _DECIMAL_COMMA.match(c) else c
                             for c in table[column]]
    return table


def read_text_table_file(path: str | os.PathLike[str], *, numeric: Iterable[str] = (),
                         example: str = "file,fill_percent,velocity_delay_us",
                         row: str = "file") -> pd.DataFrame:
    """:func:`read_text_table` of a file, named by its path (``InputFileError`` if missing)."""
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except FileNotFoundError:
        raise InputFileError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise InputFileError(f"{path}: is a folder; expected a CSV table") from None
    return read_text_table(data, str(path), numeric=numeric, example=example, row=row)

