"""Write a report (table, figures, provenance) as CSV, Markdown, HTML, LaTeX and PDF.

All formats are written into a temporary folder beside the output folder and moved into place
only when every one succeeded, so a failure leaves no partial report and an earlier report in
the output folder untouched.

Markdown and LaTeX are written here rather than through ``DataFrame.to_markdown`` (needs
``tabulate``) or ``Styler.to_latex`` (needs ``jinja2``): both are ~20 lines of escaping and
joining, not worth a dependency. The PDF is drawn by matplotlib (``PdfPages``), so no LaTeX
toolchain is needed.
"""

from __future__ import annotations

import base64
import csv
import hashlib
import html
import math
import re
import textwrap
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path

import pandas as pd

from .. import defaults
from ..constants import REPORT_FORMATS
from ..errors import ParameterError
from ..out_folder import check_replaceable, restore_previous, write_folder_whole
from ..plot_text import text_as_typed
from ..units import value_and_error_texts
from .provenance import Provenance
from .table import (
    ALIGNMENT_COLUMN,
    CALIBRATED_BAND_COLUMN,
    CALIBRATED_COLUMN,
    CALIBRATED_INSIDE_COLUMN,
    DIFFERENCE_COLUMN,
    MEASURED_EQ10_COLUMN,
    MEASURED_EQ11_COLUMN,
    MEASURED_EQ11_STDERR_COLUMN,
    PACKING_RATIO_COLUMN,
    SPECIMEN_SHA256_COLUMN,
    shared_identity,
)

#: File written into every report folder: a folder a killed replacement left hidden beside its
#: place is put back only where it holds it (:func:`restore_previous_report`).
REPORT_MARKER = ".pidcore-report"
#: The command whose outputs a report folder's record lists (:mod:`pidcore.out_folder`).
REPORT_COMMAND = "report"
#: Base name of the table files (``report.csv``, ``report.md``...).
REPORT_STEM = "report"
#: Folder of a report's load-case PDF sheets (``pidcore report --case-sheets``).
CASE_SHEETS_FOLDER = "cases"
#: Columns shown in the PDF table (the full table is in every other format).
#: The like-for-like measured SDC (Eq. 10's E) and its difference stand beside our DEM: with
#: the Eq. 11 SDC alone the PDF set 1.14 against our 0.61 where the like-for-like 0.62 agrees;
#: the calibrated columns only where the table has them.
PDF_COLUMNS: tuple[str, ...] = (
    "frequency [Hz]", "acceleration [g]", PACKING_RATIO_COLUMN, "SDC DEM (ours) [-]",
    "SDC DEM stderr [-]", MEASURED_EQ10_COLUMN, DIFFERENCE_COLUMN, MEASURED_EQ11_COLUMN,
    MEASURED_EQ11_STDERR_COLUMN, CALIBRATED_COLUMN, CALIBRATED_BAND_COLUMN,
    CALIBRATED_INSIDE_COLUMN,
    "SDC DEM (paper) [-]", "SDC measured (paper) [-]", ALIGNMENT_COLUMN,
)
#: The PDF's header of a column whose name alone does not say which SDC it is.
PDF_LABELS: dict[str, str] = {CALIBRATED_INSIDE_COLUMN: "measured in calibrated 95 % band"}
_TITLE = "Specific damping capacity: our DEM, our measurements and the paper (Table 3)"


def format_cell(value: object) -> str:
    """Display text of one cell: 4 significant digits, empty for NaN."""
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.4g}"
    if value is None or value is pd.NA:  # pd.NA: a missing whole number (Int64 column)
        return ""
    return str(value)


#: The report's SDCs beside a column of their standard error: each pair is written by
#: :func:`pidcore.units.value_and_error_texts`, the rule of the app, ``analyze`` and the case
#: sheet (four significant digits each wrote 8.168123 ± 0.0003 as 8.168 and 0.0003, and a
#: noise-free 0.25 ± 1.1e-14 as 0.25 and 1.1e-14); the value so rounded also where its error's
#: column is not shown (the terminal's table).
VALUE_STDERR_COLUMNS: dict[str, str] = {"SDC DEM (ours) [-]": "SDC DEM stderr [-]",
                                        MEASURED_EQ11_COLUMN: MEASURED_EQ11_STDERR_COLUMN}


def display_rows(table: pd.DataFrame, columns: Sequence[str] | None = None) -> list[list[str]]:
    """Display text of each row's ``columns`` (default all): :func:`format_cell`, except each
    SDC of :data:`VALUE_STDERR_COLUMNS` and its standard error, written as one pair."""
    cols = list(columns) if columns is not None else list(table.columns)
    names = list(table.columns)
    out = []
    for row in table.itertuples(index=False):
        cells = dict(zip(names, row, strict=True))
        texts = {c: format_cell(cells[c]) for c in cols}
        for value_column, error_column in VALUE_STDERR_COLUMNS.items():
            value, error = cells.get(value_column), cells.get(error_column)
            if isinstance(value, float) and isinstance(error, float) and math.isfinite(value):
                value_text, error_text = value_and_error_texts(value, error)
                if value_column in texts:
                    texts[value_column] = value_text
                if error_column in texts and error_text:
                    texts[error_column] = error_text
        out.append([texts[c] for c in cols])
    return out


def parse_formats(formats: str | Iterable[str]) -> tuple[str, ...]:
    """Validate report formats; ``"all"`` means every one of :data:`REPORT_FORMATS`."""
    items = [formats] if isinstance(formats, str) else list(formats)
    out: list[str] = []
    for item in items:
        for name in str(item).split(","):
            name = name.strip().lower()
            if name == "all":
                out.extend(REPORT_FORMATS)
            elif name in REPORT_FORMATS:
                out.append(name)
            else:
                raise ParameterError(f"report format {name!r} unknown; expected all or one of "
                                     f"{', '.join(REPORT_FORMATS)}")
    if not out:
        raise ParameterError("no report format given")
    return tuple(dict.fromkeys(out))


# ---------------------------------------------------------------------------- formats
#: Sidecar of the CSV: provenance and notes, one per line (the CSV itself holds only the table,
#: so ``pandas.read_csv`` and spreadsheets read exactly the table's rows).
CSV_NOTES_SUFFIX = ".provenance.txt"


def _write_csv(table: pd.DataFrame, figures: Mapping[str, Path], prov: Provenance,
               folder: Path) -> Path:
    path = folder / f"{REPORT_STEM}.csv"
    # Floats are written as repr (read back bit for bit); text is quoted.
    table.to_csv(path, index=False, quoting=csv.QUOTE_NONNUMERIC)
    notes = folder / f"{REPORT_STEM}{CSV_NOTES_SUFFIX}"
    notes.write_text("".join(f"{line}\n" for line in prov.lines()), encoding="utf-8")
    return path


#: Characters a Markdown viewer would read as markup in a file or specimen name: raw HTML
#: (``<b>``, ``<img onerror=...>``), links and images (``[x](javascript:...)``), code spans.
#: Escaped with a backslash (CommonMark), so the name reads as typed, in a viewer and as text.
_MD_MARKUP = str.maketrans({c: "\\" + c for c in "\\|<>[]`"})


def _md_escape(text: str) -> str:
    return text.translate(_MD_MARKUP).replace("\n", " ")


def _write_md(table: pd.DataFrame, figures: Mapping[str, Path], prov: Provenance,
              folder: Path) -> Path:
    path = folder / f"{REPORT_STEM}.md"
    lines = [f"# {_TITLE}", ""]
    lines.append("| " + " | ".join(_md_escape(c) for c in table.columns) + " |")
    numeric = [pd.api.types.is_numeric_dtype(table[c]) for c in table.columns]
    lines.append("|" + "|".join("---:" if n else "---" for n in numeric) + "|")
    for row in display_rows(table):
        lines.append("| " + " | ".join(_md_escape(c) for c in row) + " |")
    lines.append("")
    for stem, png in figures.items():
        lines += [f"![{stem}](figures/{png.name})", ""]
    lines += ["## Provenance", ""]
    lines += [f"- {_md_escape(line)}" for line in prov.lines()]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


_CSS = """
body { font-family: system-ui, sans-serif; margin: 2em; color: #222; }
table { border-collapse: collapse; font-size: 0.85em; }
th, td { border-bottom: 1px solid #ccc; padding: 0.25em 0.6em; }
th { border-bottom: 2px solid #444; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
figure { margin: 1.5em 0; }
figure img { max-width: 100%; }
footer { margin-top: 2em; font-size: 0.8em; color: #555; }
"""


def _write_html(table: pd.DataFrame, figures: Mapping[str, Path], prov: Provenance,
                folder: Path) -> Path:
    path = folder / f"{REPORT_STEM}.html"
    numeric = [pd.api.types.is_numeric_dtype(table[c]) for c in table.columns]
    head = "".join(f"<th>{html.escape(c)}</th>" for c in table.columns)
    body = []
    for row in display_rows(table):
        cells = "".join(f'<td class="num">{html.escape(v)}</td>' if n
                        else f"<td>{html.escape(v)}</td>" for v, n in zip(row, numeric,
                                                                            strict=True))
        body.append(f"<tr>{cells}</tr>")
    figs = []
    for stem, png in figures.items():  # embedded: the file must open offline, alone
        data = base64.b64encode(png.read_bytes()).decode("ascii")
        figs.append(f'<figure><img alt="{html.escape(stem)}" src="data:image/png;base64,{data}">'
                    f"<figcaption>{html.escape(stem)}</figcaption></figure>")
    foot = "".join(f"<li>{html.escape(line)}</li>" for line in prov.lines())
    text = (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f"<title>{html.escape(_TITLE)}</title><style>{_CSS}</style></head><body>"
            f"<h1>{html.escape(_TITLE)}</h1><table><thead><tr>{head}</tr></thead>"
            f"<tbody>{''.join(body)}</tbody></table>{''.join(figs)}"
            f"<footer><h2>Provenance</h2><ul>{foot}</ul></footer></body></html>\n")
    path.write_text(text, encoding="utf-8")
    return path


_TEX_SPECIAL = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#",
                "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
                "^": r"\textasciicircum{}"}
#: Characters past Latin-1 that pidcore's own notes and verdicts write (ω of Eq. 10, σ, ≤,
#: the dashes and −), as commands every engine typesets. pdflatex with inputenc's utf8 stops
#: at a character it has not set up ("Unicode character Ω not set up for use with LaTeX").
_TEX_SYMBOLS = {"—": "---", "–": "--", "−": r"\ensuremath{-}", "…": r"\dots{}",
                "‘": "`", "’": "'", "“": "``", "”": "''", "≤": r"\ensuremath{\leq}",
                "≥": r"\ensuremath{\geq}", "≈": r"\ensuremath{\approx}",
                "≠": r"\ensuremath{\neq}", "→": r"\ensuremath{\rightarrow}",
                "∞": r"\ensuremath{\infty}", "√": r"\ensuremath{\surd}",
                "Γ": r"\ensuremath{\Gamma}", "Δ": r"\ensuremath{\Delta}",
                "Θ": r"\ensuremath{\Theta}", "Λ": r"\ensuremath{\Lambda}",
                "Ξ": r"\ensuremath{\Xi}", "Π": r"\ensuremath{\Pi}", "Σ": r"\ensuremath{\Sigma}",
                "Φ": r"\ensuremath{\Phi}", "Ψ": r"\ensuremath{\Psi}", "Ω": r"\ensuremath{\Omega}",
                **{chr(0x3B1 + i): rf"\ensuremath{{\{name}}}" for i, name in enumerate(
                    "alpha beta gamma delta epsilon zeta eta theta iota kappa lambda mu nu xi "
                    "omicron pi rho varsigma sigma tau upsilon phi chi psi omega".split())
                   if name != "omicron"}}
#: A character past Latin-1 that is none of :data:`_TEX_SYMBOLS` (a specimen named in
#: Cyrillic or CJK): the command of the .tex's preamble, which typesets the character itself
#: under XeLaTeX and LuaLaTeX (fontspec) and its code point, ``[U+03A9]``, under pdflatex,
#: whose fonts have no such glyph; the character, its second argument, is never read there.
_TEX_CHAR_COMMAND = "pidcorechar"
_TEX_PREAMBLE = (
    r"% pdflatex, xelatex or lualatex: a character past Latin-1 in a name (a specimen in"
    "\n"
    r"% Cyrillic or CJK) is \pidcorechar{code point}{character}, set as the character under"
    "\n"
    r"% xelatex and lualatex (fontspec; a font with its glyph: \setmainfont) and as its code"
    "\n"
    r"% point under pdflatex, which has no such glyph",
    r"\usepackage{iftex}",
    r"\iftutex",
    r"  \usepackage{fontspec}",
    rf"  \newcommand{{\{_TEX_CHAR_COMMAND}}}[2]{{#2}}",
    r"\else",
    r"  \usepackage[utf8]{inputenc}",
    r"  \usepackage[T1]{fontenc}",
    # a line may break after each: a name of 12 such characters is 90 unbroken under pdflatex
    rf"  \newcommand{{\{_TEX_CHAR_COMMAND}}}[2]{{\texttt{{[U+#1]}}\allowbreak{{}}}}",
    r"\fi",
)


def tex_escape(text: str) -> str:
    r"""Escape LaTeX special characters; a character past Latin-1 written so that pdflatex
    too reads it (:data:`_TEX_SYMBOLS`, else the preamble's ``\pidcorechar``), a control
    character as a space."""
    out = []
    for ch in text:
        if ch in _TEX_SPECIAL:
            out.append(_TEX_SPECIAL[ch])
        elif ch in _TEX_SYMBOLS:
            out.append(_TEX_SYMBOLS[ch])
        elif ord(ch) > 0xFF:
            out.append(rf"\{_TEX_CHAR_COMMAND}{{{ord(ch):04X}}}{{{ch}}}")
        elif ord(ch) < 0x20 or 0x7F <= ord(ch) < 0xA0:
            out.append(" ")  # a blank line in a cell ends a paragraph inside the tabular
        else:
            out.append(ch)
    return "".join(out)


def tex_printed_length(text: str) -> int:
    r"""Characters pdflatex prints of :func:`tex_escape`'s ``text``: a ``\pidcorechar``'s
    code point, ``[U+0441]``, counts its 8, a symbol of :data:`_TEX_SYMBOLS` 2 (a dash, ≤ or
    Ω is up to two digits wide). A column sized for "сталь_6мм_鋼"'s 12 characters was 1.3 cm
    for its 66, which ran 4 cm into the next column."""
    return sum(len(f"[U+{ord(ch):04X}]") if ord(ch) > 0xFF and ch not in _TEX_SYMBOLS
               else 2 if ch in _TEX_SYMBOLS else 1 for ch in text)


#: Columns of long text (a note of 230-390 characters, the source files, a sha256), set out of
#: the LaTeX table's numbers: in one line of the tabular they made rows ~1200 characters wide,
#: scaled to 0.12 (1.2 pt text). The LaTeX writes them in a table of their own, by row number,
#: the notes numbered below it (:func:`numbered_notes`).
TEX_TEXT_COLUMNS: tuple[str, ...] = ("load case", "DEM settings", "specimen",
                                     SPECIMEN_SHA256_COLUMN, "source file(s)", "note")
#: The LaTeX tables' geometry: the text width of A4 landscape with 1.5 cm margins, the width
#: of a character of ``\scriptsize`` (7 pt: a digit is 0.5 em, 0.12 cm; the widest header
#: words, "measured" and "out_of_range/", need 0.145 cm a letter) and the padding of a column
#: (2 x ``\tabcolsep`` of 3 pt), all in cm.
_TEX_TEXT_WIDTH = 29.7 - 2 * 1.5
_TEX_CHAR = 0.15
_TEX_PAD = 2 * 3 / 72.27 * 2.54


def _tex_breakable(text: str, most: int) -> str:
    """``text`` escaped, a line break allowed in a word of more than ``most`` characters as
    pdflatex prints them (:func:`tex_printed_length`; a file name or a sha256 has no space to
    break at in a narrow column) after each of its ``_ / . , -`` and every ``most``
    characters."""
    words = []
    for word in re.split(r"(\s+)", text):
        if tex_printed_length(word) <= most:
            words.append(tex_escape(word))
            continue
        out, run = [], 0
        for ch in word:
            printed = tex_printed_length(ch)
            if run and run + printed > most:  # a code point's 8 would end past the column
                out.append(r"\allowbreak{}")
                run = 0
            out.append(tex_escape(ch))
            run += printed
            if ch in "_/.,-" or run >= most:
                out.append(r"\allowbreak{}")
                run = 0
        words.append("".join(out))
    return "".join(words)


def _tex_header(name: str) -> str:
    # a break allowed after each "/" of "[grid/interpolated/...]"
    return tex_escape(name).replace("/", r"/\allowbreak{}")


def _tex_longtable(columns: Sequence[str], widths: Sequence[float], numeric: Sequence[bool],
                   rows: Sequence[Sequence[str]]) -> list[str]:
    """A longtable (broken across pages, its header on each) of p columns of ``widths`` cm,
    numbers set right; ``rows`` already escaped."""
    spec = "".join(rf">{{\{'raggedleft' if n else 'raggedright'}\arraybackslash}}p{{{w:.2f}cm}}"
                   for w, n in zip(widths, numeric, strict=True))
    return [r"{\scriptsize", rf"\begin{{longtable}}{{@{{}}{spec}@{{}}}}", r"\toprule",
            " & ".join(_tex_header(c) for c in columns) + r" \\", r"\midrule", r"\endhead",
            *(" & ".join(row) + r" \\" for row in rows), r"\bottomrule", r"\end{longtable}}"]


def _tex_parts(columns: Sequence[str], texts: Sequence[Sequence[str]]) -> list[list[int]]:
    """The positions of ``columns`` in each LaTeX table of numbers: as many as fit the text
    width beside the row number, in order, an SDC beside its standard error
    (:data:`VALUE_STDERR_COLUMNS`)."""
    room = _TEX_TEXT_WIDTH - _tex_width(["row"], [[str(len(texts))]])[0] - _TEX_PAD
    widths = _tex_width(columns, texts)
    parts: list[list[int]] = [[]]
    used = 0.0
    for i, column in enumerate(columns):
        paired = i > 0 and VALUE_STDERR_COLUMNS.get(columns[i - 1]) == column
        if parts[-1] and not paired and used + widths[i] + _TEX_PAD > room:
            parts.append([])
            used = 0.0
        parts[-1].append(i)
        used += widths[i] + _TEX_PAD
    return parts


def _tex_width(columns: Sequence[str], texts: Sequence[Sequence[str]]) -> list[float]:
    """Each column's width in cm: its longest cell, or its header's longest word (the header
    wraps at its spaces and slashes)."""
    out = []
    for i, column in enumerate(columns):
        words = column.replace("/", "/ ").split()
        # at least 5: the capitals of "DEM" are as wide as 5 digits
        chars = max([tex_printed_length(row[i]) for row in texts] + [max(map(len, words)), 5])
        out.append(chars * _TEX_CHAR)
    return out


def _write_tex(table: pd.DataFrame, figures: Mapping[str, Path], prov: Provenance,
               folder: Path) -> Path:
    path = folder / f"{REPORT_STEM}.tex"
    number_columns = [c for c in table.columns if c not in TEX_TEXT_COLUMNS]
    text_columns = [c for c in TEX_TEXT_COLUMNS if c in table.columns and c != "note"
                    and any(isinstance(v, str) and v for v in table[c])]
    numbers = display_rows(table, number_columns)
    ids = [str(i) for i in range(1, len(table) + 1)]
    marks, notes = numbered_notes(table["note"]) if "note" in table.columns \
        else ([""] * len(table), [])
    lines = [r"\documentclass[a4paper,landscape]{article}", *_TEX_PREAMBLE,
             r"\usepackage[margin=1.5cm]{geometry}", r"\usepackage{booktabs}",
             r"\usepackage{longtable}", r"\usepackage{array}", r"\usepackage{graphicx}",
             r"\setlength{\tabcolsep}{3pt}", r"\begin{document}",
             rf"\section*{{{tex_escape(_TITLE)}}}"]
    numeric = {c: pd.api.types.is_numeric_dtype(table[c]) for c in table.columns}
    row_width = _tex_width(["row"], [[ids[-1] if ids else "1"]])
    for part in _tex_parts(number_columns, numbers):
        columns = ["row", *(number_columns[i] for i in part)]
        rows = [[n, *(tex_escape(row[i]) for i in part)] for n, row in zip(ids, numbers,
                                                                            strict=True)]
        lines += _tex_longtable(columns, row_width + _tex_width(
            [number_columns[i] for i in part], [[row[i] for i in part] for row in numbers]),
            [True] + [numeric[number_columns[i]] for i in part], rows)
    # the text by row: the columns share the width left by the row and note numbers, each
    # as much as its longest cell asks (up to 60 characters) of it
    texts = display_rows(table, text_columns)
    asked = [max([min(tex_printed_length(row[i]), 60) for row in texts] + [len(c) // 2, 6])
             for i, c in enumerate(text_columns)]
    room = _TEX_TEXT_WIDTH - 2 * (row_width[0] + _TEX_PAD) - _TEX_PAD * len(text_columns)
    # a code point, [U+0441], cannot break: each column at least as wide as its widest
    least = [max((tex_printed_length(ch) for row in texts for ch in row[i] if ord(ch) > 0xFF),
                 default=0) * _TEX_CHAR for i in range(len(text_columns))]
    widths = [b + (room - sum(least)) * a / sum(asked) for a, b in zip(asked, least,
                                                                         strict=True)]
    rows = [[n, *(_tex_breakable(v, int(w / _TEX_CHAR)) for v, w in zip(row, widths,
                                                                         strict=True)), mark]
            for n, row, mark in zip(ids, texts, marks, strict=True)]
    lines += _tex_longtable(["row", *text_columns, "note"], [*row_width, *widths, *row_width],
                            [True] + [False] * len(text_columns) + [True], rows)
    if notes:
        lines += [r"\paragraph{Notes} (the number in a row's note column)",
                  r"{\footnotesize\begin{enumerate}"]
        lines += [rf"\item {tex_escape(note)}" for note in notes]
        lines += [r"\end{enumerate}}"]
    for stem, png in figures.items():
        # the base name braced off its extension: graphicx before 2019 took the first dot of
        # a load case's name (loop_00_f62.5Hz_...) as the extension's and did not compile
        lines += [r"\begin{figure}[ht]\centering",
                  rf"\includegraphics[width=0.8\textwidth]{{{{figures/{png.stem}}}{png.suffix}}}",
                  rf"\caption{{{tex_escape(stem)}}}", r"\end{figure}"]
    lines += [r"\section*{Provenance}", r"{\footnotesize\begin{itemize}"]
    lines += [rf"\item {tex_escape(line)}" for line in prov.lines()]
    lines += [r"\end{itemize}}", r"\end{document}"]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def numbered_notes(notes: Iterable[object]) -> tuple[list[str], list[str]]:
    """Each row's note number as text ("" for a row without a note) and the notes in the
    order of their numbers, 1 first: rows of one note share its number. The PDF and the LaTeX
    table carry the number in the row and the note under the table (a note of 230-390
    characters in a cell made the row unreadable or was left out)."""
    numbers: dict[str, int] = {}
    marks = []
    for note in notes:
        text = note if isinstance(note, str) else ""
        if text:
            marks.append(str(numbers.setdefault(text, len(numbers) + 1)))
        else:
            marks.append("")
    return marks, list(numbers)


#: Characters of one line of a text cell of the PDF table, and most characters of the cell
#: (:func:`bounded_stem` cuts a longer one, ending in its hash: two long names that begin
#: alike still read apart). "cells 8, steady cycles auto, settings hash b277b3" on one line
#: took a sixth of the page's width.
_PDF_CELL_LINE = 22
_PDF_CELL_MOST = 3 * _PDF_CELL_LINE


def _pdf_text_cell(text: str) -> str:
    return "\n".join(textwrap.wrap(bounded_stem(text, _PDF_CELL_MOST), _PDF_CELL_LINE)) \
        or text


def pdf_columns(table: pd.DataFrame) -> list[str]:
    """The columns of the PDF table: the :data:`PDF_COLUMNS` the table has, then those of
    :data:`~pidcore.report.table.ROW_IDENTITY_COLUMNS` some row states that not every row
    shares (:func:`~pidcore.report.table.shared_identity`; a value every row shares is said
    once under the title, :func:`pdf_shared_line`), the specimen's sha256 wherever its name
    is shown (a name and its file's hash identify a specimen together), then ``note`` (its
    rows' numbers, :func:`numbered_notes`). Two DEM runs of one load case at other settings
    read as two identical rows of different SDCs: the PDF showed none of these columns."""
    from .table import ROW_IDENTITY_COLUMNS, with_band_text

    shown = list(with_band_text(table.iloc[:0]).columns)
    shared = shared_identity(table)
    identity = [c for c in ROW_IDENTITY_COLUMNS if c in table.columns and c not in shared
                and any(isinstance(v, str) and v for v in table[c])]
    if "specimen" in identity and SPECIMEN_SHA256_COLUMN in shared:
        identity.append(SPECIMEN_SHA256_COLUMN)
    cols = [c for c in PDF_COLUMNS if c in shown] + identity
    return cols + (["note"] if "note" in table.columns else [])


def pdf_shared_line(table: pd.DataFrame) -> str:
    """What every row of ``table`` shares of the row identity columns the PDF leaves out
    (e.g. "material acrylic; direction z; DEM settings cells 8, ..."); "" where none. A
    constant column tells no row apart and costs A4 width beside the SDC columns, but its
    value is still the reader's to know."""
    shown = pdf_columns(table)
    # cut as in the table's cells: a specimen or material named at 4 KiB would take the page
    # (a sha256's 64 digits are kept whole)
    parts = [f"{column} {bounded_stem(value, _PDF_CELL_MOST)}"
             for column, value in shared_identity(table).items() if column not in shown]
    return f"Every row: {'; '.join(parts)}" if parts else ""


def pdf_table_cells(table: pd.DataFrame) -> tuple[list[str], list[list[str]]]:
    """The PDF table's header labels (wrapped) and its rows' display text, of
    :func:`pdf_columns` (the calibrated band in one cell, as
    :func:`~pidcore.report.table.with_band_text` writes it; a long text cell wrapped; the note
    as its number, :func:`numbered_notes`, the note under the table)."""
    from .table import ROW_IDENTITY_COLUMNS, with_band_text

    cols = pdf_columns(table)
    table = with_band_text(table)
    labels = ["\n".join(textwrap.wrap(PDF_LABELS.get(c, c.split(" [grid/")[0]), 12))
              for c in cols]
    rows = display_rows(table, [c for c in cols if c != "note"])
    wrapped = [i for i, c in enumerate(cols) if c in ROW_IDENTITY_COLUMNS]
    for row in rows:
        for i in wrapped:
            row[i] = _pdf_text_cell(row[i])
    if "note" in cols:
        for row, mark in zip(rows, numbered_notes(table["note"])[0], strict=True):
            row.append(mark)
    return labels, rows


#: The PDF table's page (A4 landscape, inches) and what is laid out on it, in inches: a line
#: of a cell's text (6.5 pt, matplotlib's 1.2 line spacing), a cell's padding, a line of a
#: note (6 pt), and the height the header, the rows and the notes share (the page less the
#: title and the margins).
_PDF_PAGE = (11.69, 8.27)
_PDF_ROW_LINE = 6.5 / 72 * 1.2
_PDF_ROW_PAD = 0.09
_PDF_NOTE_LINE = 6 / 72 * 1.25
_PDF_TABLE_ROOM = 6.9
#: Characters of a line of a note under the PDF table.
_PDF_NOTE_WIDTH = 190
#: The PDF table page's title: its size (pt), line height (in, matplotlib's 1.2 spacing) and
#: gap to the table (``axes.titlepad``, 6 pt); the table's axes span the page's width between
#: ``left`` and ``right`` and reach up to ``top`` (fractions of the page) where the title
#: leaves room, its lines centred over them: a line is wrapped to the axes' width, so it never
#: reaches past the page's edges (wrapped at 200 characters, ~145 fit the page, a specimen's
#: sha256 lost its last digits at the right edge and "Every row" its first at the left).
_PDF_TITLE_SIZE = 10.0
_PDF_TITLE_LINE = _PDF_TITLE_SIZE / 72 * 1.2
_PDF_TITLE_PAD = 6 / 72
_PDF_AXES = {"left": 0.125, "right": 0.9, "top": 0.88}
#: Inches kept free above the title's first line.
_PDF_TOP_MARGIN = 0.3


def _text_width(text: str, size: float) -> float:
    """Points ``text`` takes at ``size`` pt in matplotlib's default font (its glyphs'
    advances and kerning, as the PDF sets them)."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import text_to_path

    return text_to_path.get_text_width_height_descent(text, FontProperties(size=size),
                                                      ismath=False)[0]


def wrap_to_width(text: str, width: float, size: float) -> list[str]:
    """``text`` in lines of at most ``width`` points at ``size`` pt, broken at its spaces, a
    word wider than a line on its own (a long name) inside it."""
    lines: list[str] = []
    line = ""
    for word in text.split():
        joined = f"{line} {word}" if line else word
        if _text_width(joined, size) <= width:
            line = joined
            continue
        if line:
            lines.append(line)
        while _text_width(word, size) > width:
            cut = 1
            while cut < len(word) and _text_width(word[:cut + 1], size) <= width:
                cut += 1
            lines.append(word[:cut])
            word = word[cut:]
        line = word
    return lines + ([line] if line else [])


def _pdf_title_lines(title: str, shared: str) -> list[str]:
    """The PDF table page's title and :func:`pdf_shared_line` under it, each wrapped to the
    table's axes' width (:data:`_PDF_AXES`)."""
    width = (_PDF_AXES["right"] - _PDF_AXES["left"]) * _PDF_PAGE[0] * 72
    return [line for text in (title, shared) if text
            for line in wrap_to_width(text, width, _PDF_TITLE_SIZE)]


def _pdf_axes_top(title_lines: int) -> float:
    """The top of the PDF table's axes (fraction of the page): :data:`_PDF_AXES`'s, lower
    where the title's lines would reach within :data:`_PDF_TOP_MARGIN` of the page's top."""
    title = _PDF_TOP_MARGIN + title_lines * _PDF_TITLE_LINE + _PDF_TITLE_PAD
    return min(_PDF_AXES["top"], 1 - title / _PDF_PAGE[1])


def _note_lines(number: int, note: str) -> list[str]:
    return textwrap.wrap(f"{number}. {note}", _PDF_NOTE_WIDTH, subsequent_indent="    ")


def _pdf_pages(rows: list[list[str]], marks: list[str], notes: list[str],
               header_lines: int, room: float = _PDF_TABLE_ROOM) -> list[range]:
    """The rows of each page of the PDF table: as many as fit with the notes they number
    (each page lists the notes of its own rows under its table) in ``room`` inches."""
    room -= _pdf_row_height(header_lines)
    pages: list[range] = []
    start, used, listed = 0, 0.0, set()
    for i, row in enumerate(rows):
        if i > start and used + _pdf_height(row, marks[i], notes, listed) > room:
            pages.append(range(start, i))
            start, used, listed = i, 0.0, set()
        used += _pdf_height(row, marks[i], notes, listed)
        listed.add(marks[i])
    pages.append(range(start, len(rows)))
    return pages


def _pdf_row_height(lines: int) -> float:
    return lines * _PDF_ROW_LINE + _PDF_ROW_PAD


def _pdf_height(row: list[str], mark: str, notes: list[str], listed: set[str]) -> float:
    """Inches a row takes on its page: its lines, and its note's where the page lists it
    first."""
    height = _pdf_row_height(max(cell.count("\n") + 1 for cell in row))
    if mark and mark not in listed:
        height += len(_note_lines(int(mark), notes[int(mark) - 1])) * _PDF_NOTE_LINE
    return height


@text_as_typed  # its pages' text too: a specimen's CJK name in the table
def _write_pdf(table: pd.DataFrame, figures: Mapping[str, Path], prov: Provenance,
               folder: Path, *, figure_objects: Mapping[str, object] | None = None) -> Path:
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_pdf import PdfPages

    path = folder / f"{REPORT_STEM}.pdf"
    labels, rows = pdf_table_cells(table)
    marks, notes = numbered_notes(table["note"]) if "note" in table.columns \
        else ([""] * len(rows), [])
    shared = pdf_shared_line(table)
    header_lines = max(label.count("\n") + 1 for label in labels)
    # "(continued)" may take a line more
    titles = [_pdf_title_lines(t, shared) for t in (_TITLE, f"{_TITLE} (continued)")]
    top = _pdf_axes_top(max(map(len, titles)))
    # the table's room less what a long title took of the page
    room = _PDF_TABLE_ROOM - (_PDF_AXES["top"] - top) * _PDF_PAGE[1]
    with PdfPages(path) as pdf:
        for n, page in enumerate(_pdf_pages(rows, marks, notes, header_lines, room)):
            fig, ax = plt.subplots(figsize=_PDF_PAGE)
            fig.subplots_adjust(left=_PDF_AXES["left"], right=_PDF_AXES["right"], top=top)
            ax.axis("off")
            # parse_math off: a "$" of a specimen's name is text, and measured as such
            ax.set_title("\n".join(titles[min(n, 1)]), fontsize=_PDF_TITLE_SIZE,
                         parse_math=False)
            chunk = [rows[i] for i in page] or [[""] * len(labels)]
            tab = ax.table(cellText=chunk, colLabels=labels, loc="upper center",
                           cellLoc="right")
            tab.auto_set_font_size(False)
            tab.set_fontsize(6.5)
            # each column as wide as its widest text, none cut at its edge
            tab.auto_set_column_width(list(range(len(labels))))
            # each row as high as its cell of most lines (in axes units, as cells are sized)
            inches = _PDF_PAGE[1] * ax.get_position().height
            heights = [_pdf_row_height(header_lines)] + [
                _pdf_row_height(max(c.count("\n") + 1 for c in row)) for row in chunk]
            for (row, _), cell in tab.get_celld().items():
                cell.set_height(heights[row] / inches)
                # a name's "$\x$" is text: mathtext failed the whole PDF on it
                cell.get_text().set_parse_math(False)
            listed = list(dict.fromkeys(int(marks[i]) for i in page if marks[i]))
            if listed:
                # under the table as drawn: its height follows its rows' lines
                fig.draw_without_rendering()
                bottom = ax.transAxes.inverted().transform(
                    tab.get_window_extent().get_points())[0][1]
                text = [line for k in sorted(listed) for line in _note_lines(k, notes[k - 1])]
                ax.text(0.0, bottom - 0.02, "Notes (the number in a row's note column):\n"
                        + "\n".join(text), transform=ax.transAxes, va="top", ha="left",
                        fontsize=6, parse_math=False)
            pdf.savefig(fig)
            plt.close(fig)
        for fig in (figure_objects or {}).values():
            # cropped to the drawing like the PNG and SVG: the layout kept from the PNG
            # (see save_figure_files) would put a legend past a fixed page's edge
            pdf.savefig(fig, bbox_inches="tight")
        fig = plt.figure(figsize=_PDF_PAGE)
        lines = [part for line in prov.lines()
                 for part in textwrap.wrap(line, 150, subsequent_indent="    ") or [""]]
        fig.text(0.03, 0.97, "Provenance\n\n" + "\n".join(lines), va="top",
                 family="monospace", fontsize=6, parse_math=False)
        pdf.savefig(fig)
        plt.close(fig)
    return path


#: One writer per format: ``(table, figure PNG paths, provenance, folder) -> path``.
RENDERERS: dict[str, Callable[..., Path]] = {
    "csv": _write_csv, "md": _write_md, "html": _write_html, "tex": _write_tex,
    "pdf": _write_pdf,
}


#: Most characters of a report's file name before its extension (a figure, a load case's
#: sheet). A report is handed on and unpacked on Windows, whose paths end at 260 characters
#: (MAX_PATH) with the folder's; a specimen named in a sidecar has no length limit, and its
#: sheet's name failed with "File name too long" (255) and a traceback, as a figure named by
#: a stored material of 4 KiB did.
MAX_SHEET_STEM = 96


def bounded_stem(stem: str, most: int = MAX_SHEET_STEM) -> str:
    """``stem`` where it has at most ``most`` characters, else cut there, ending in 8 hex
    digits of the whole stem's sha256 (two long names that begin alike stay two files)."""
    if len(stem) <= most:
        return stem
    digest = hashlib.sha256(stem.encode("utf-8")).hexdigest()[:8]
    return f"{stem[:most - len(digest) - 1].rstrip('_.')}_{digest}"


def save_figure_files(fig: object, folder: Path, stem: str, *,
                      dpi: int = defaults.REPORT_FIGURE_DPI) -> tuple[Path, Path]:
    """Save a matplotlib figure as ``<stem>.png`` and ``<stem>.svg`` in ``folder`` (a stem
    longer than :data:`MAX_SHEET_STEM` cut by :func:`bounded_stem`).

    The figure's layout is solved once, for the PNG, and then kept (the figure's layout
    engine is set to none): the SVG, and the report's PDF page of the same figure, reuse it
    instead of solving the constrained layout again per format (a third of a report's time).
    Each is cropped to what is drawn (``bbox_inches="tight"``, the PDF page too), so text
    that measures a little wider in another format is never cut at the edge.
    """
    folder.mkdir(parents=True, exist_ok=True)
    stem = bounded_stem(stem)
    png, svg = folder / f"{stem}.png", folder / f"{stem}.svg"
    fig.savefig(png, dpi=dpi, bbox_inches="tight")
    fig.set_layout_engine("none")
    fig.savefig(svg, bbox_inches="tight")
    return png, svg


def check_out_dir(out_dir: Path) -> None:
    """Refuse an output path that is a file, one under a file (no folder can be made there),
    or a folder whose replacement would lose anything that is not an earlier report's
    unchanged output (:func:`pidcore.out_folder.check_replaceable`)."""
    from ..atomic_files import file_in_the_way

    blocking = file_in_the_way(out_dir)
    if blocking is not None:
        raise ParameterError(f"{out_dir}: {blocking} is a file, not a folder; expected a "
                             "report output folder under a folder")
    if out_dir.exists() and not out_dir.is_dir():
        raise ParameterError(f"{out_dir}: report output exists and is not a folder")
    # the folder is replaced whole: a store kept in an earlier report's folder (report FILES
    # --store rp/s.h5 --out rp) was deleted with the analyses just saved, and a user's
    # figures/my_plot.png with it
    check_replaceable(out_dir, REPORT_COMMAND, option="out_dir")


def restore_previous_report(out_dir: str | Path) -> Path | None:
    """Where ``out_dir`` is missing, put back the earlier report a write killed between its
    two renames (SIGKILL, a power loss; only where the system cannot swap folders in one
    step) left hidden beside it (``.<name>.<16 hex>.old``); where it exists, remove such a
    folder left after the replacement had finished. Returns the folder restored, None if
    none was (:func:`restored_report_note` says so); a ``ParameterError`` where several are
    hidden beside a missing ``out_dir``. :func:`write_report` calls it first."""
    return restore_previous(out_dir, REPORT_COMMAND, is_previous=_is_report)


def _is_report(folder: Path) -> bool:
    return (folder / REPORT_MARKER).is_file()


def restored_report_note(out_dir: str | Path) -> str:
    """The note that :func:`restore_previous_report` put the earlier report back."""
    return (f"{out_dir}: put back the earlier report, which a report killed while replacing "
            "it had left hidden beside it")


def write_report(table: pd.DataFrame, figures: Mapping[str, object], provenance: Provenance,
                 out_dir: str | Path, formats: str | Iterable[str] = REPORT_FORMATS,
                 *, progress: bool = False,
                 case_sheets: Mapping[str, bytes] | None = None) -> dict[str, Path]:
    """Write the report into ``out_dir``, atomically.

    Parameters
    ----------
    table : pandas.DataFrame
        The report table (:func:`pidcore.report.build_report_table`).
    figures : mapping of str to matplotlib Figure
        Figures by file stem; each is saved as ``figures/<stem>.png`` and ``.svg`` and shown in
        every format (HTML embeds the PNG as base64, so the page is self-contained).
    provenance : Provenance
        Footer of every format.
    out_dir : path
        Output folder (a link's: the folder it points to). It must be new, empty or an
        earlier pidcore report holding its own unchanged files alone (which is replaced;
        :mod:`pidcore.out_folder`).
    formats : str or iterable of str
        Any of ``csv, md, html, tex, pdf`` or ``"all"``.
    progress : bool
        A bar over the figures and formats written, on stderr (the figures and the PDF are
        most of a report's time).
    case_sheets : mapping of str to bytes, optional
        Load-case PDF sheets by file name (:func:`pidcore.report.case_sheet.case_sheets`),
        written into :data:`CASE_SHEETS_FOLDER` with the rest, atomically.

    Returns
    -------
    dict of str to Path
        Format name -> file, ``"csv_provenance"`` -> the CSV's provenance and notes sidecar
        (with csv), ``"figure:<stem>.png"`` / ``".svg"`` -> figure file and
        ``"case:<name>.pdf"`` -> load-case sheet.

    Raises
    ------
    ParameterError
        Unknown format, or ``out_dir`` is an unrelated non-empty folder.
    """
    formats = parse_formats(formats)
    case_sheets = dict(case_sheets or {})
    for name in case_sheets:  # a name is the caller's: never a path out of the folder
        if Path(name).name != name or not name.endswith(".pdf") or name.startswith("."):
            raise ParameterError(f"case sheet {name!r}: expected a file name ending in .pdf")
    out_dir = Path(out_dir)
    restore_previous_report(out_dir)  # before the check: a hidden report is the earlier one
    check_out_dir(out_dir)
    written: dict[str, Path] = {}
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(figures) + len(formats) + len(case_sheets), unit="file",
                   desc="writing report",
                   leave=False, dynamic_ncols=True)

    def build(tmp: Path) -> list[Path]:
        pngs: dict[str, Path] = {}
        for stem, fig in figures.items():
            png, svg = save_figure_files(fig, tmp / "figures", stem)
            pngs[stem] = png
            written[f"figure:{png.name}"] = png
            written[f"figure:{svg.name}"] = svg
            if bar is not None:
                bar.update(1)
        for name, pdf in case_sheets.items():
            path = tmp / CASE_SHEETS_FOLDER / name
            path.parent.mkdir(exist_ok=True)
            path.write_bytes(pdf)
            written[f"case:{name}"] = path
            if bar is not None:
                bar.update(1)
        for name in formats:
            if bar is not None:
                bar.set_postfix_str(name)
            if name == "pdf":
                written[name] = RENDERERS[name](table, pngs, provenance, tmp,
                                                figure_objects=figures)
            else:
                written[name] = RENDERERS[name](table, pngs, provenance, tmp)
            if name == "csv":
                written["csv_provenance"] = tmp / f"{REPORT_STEM}{CSV_NOTES_SUFFIX}"
            if bar is not None:
                bar.update(1)
        if bar is not None:
            bar.close()  # before the "wrote ..." lines
        (tmp / REPORT_MARKER).write_text("written by pidcore report\n", encoding="utf-8")
        return list(written.values())

    try:
        # a report folder is meant to be shared, whatever the umask: mode 0o755
        paths = write_folder_whole(out_dir, REPORT_COMMAND, build, option="out_dir",
                                   mode=0o755, is_previous=_is_report)
    finally:
        if bar is not None:
            bar.close()
    return dict(zip(written, paths, strict=True))
