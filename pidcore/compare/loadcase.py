"""What a measurement states about its load case (the :class:`~pidcore.loadcase.LoadCase` type
itself is :mod:`pidcore.loadcase`, shared with the DEM, store, reports and app).

A DEM run knows its load case from its parameters. A measurement knows only its frequency and
acceleration (both measured, from the power analysis); fill, particle material and drive direction
are what the user *states*, in one of three ways (later ones override earlier ones):

1. **File name.** Tokens are separated by ``_``, ``-``, ``.`` or blanks (case-insensitive):

   - fill: ``fill50``, ``fill-50``, ``fill_62.5``, ``50pct``, ``50percent`` (see
     :data:`FILL_PATTERN`),
   - material: ``acrylic`` / ``pmma``, ``aluminium`` / ``aluminum`` (see :data:`MATERIAL_PATTERN`),
   - direction: ``dirz``, ``dir-x``, ``zdir`` (see :data:`DIRECTION_PATTERN`).

   Example: ``coupon3_fill50_acrylic_dirz_500Hz_5g.uff``.
2. **Sidecar table** ``loadcases.csv`` beside the file (or given explicitly) with columns
   ``file, fill_percent, material, direction`` (only ``file`` required), read as spreadsheets
   write it (:mod:`pidcore.tables`); rows are looked up by file name (a folder in the cell is
   ignored, as in the app: :func:`find_row`). Empty cells state nothing. The same row may
   state how the file is analysed (vibrometer delay, channels, specimen, ...:
   :mod:`pidcore.file_settings`); any other column is refused.
3. **Options** ``--fill``, ``--material``, ``--direction`` (keyword arguments here).

Material and direction default to the paper's acrylic particles driven along z
(:data:`pidcore.defaults.COMPARE_DEFAULT_MATERIAL`, ``COMPARE_DEFAULT_DIRECTION``); the fill has no
default: a measurement without a stated fill raises :class:`LoadCaseError`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from .. import defaults
from ..constants import PARTICLE_MATERIALS, UNTABULATED_PARTICLE_MATERIALS
from ..errors import InputFileError, SettingsTableError
from ..loadcase import (
    LoadCase,
    LoadCaseError,
    normalize_direction,
    normalize_material,
)
from ..loadcase import check_fill as _check_fill
from ..tables import header_key, line_where, read_text_table_file


class FillNotStated(LoadCaseError):
    """No fill is stated for a measurement file (by name, sidecar or option): the one
    :class:`LoadCaseError` a caller may accept (``pidcore analyze`` saves the analysis without
    a load case). ``material``: the particle material the file states or takes from the
    specimen given ("" where neither says one), so that a file of the specimen's particles is
    still saved as its test."""

    # ``material`` has a default: the CLI re-raises errors from their message alone
    def __init__(self, message: str, material: str = "") -> None:
        super().__init__(message)
        self.material = material


class UntabulatedMaterial(LoadCaseError):
    """A file name states a particle material that neither the material table nor a specimen
    gives (``..._steel.csv``): it is not read as the default material. ``material``: that
    material."""

    # ``material`` has a default: the CLI re-raises errors from their message alone
    def __init__(self, message: str, material: str = "") -> None:
        super().__init__(message)
        self.material = material


#: Name of the sidecar table looked for beside each measurement file.
SIDECAR_NAME = "loadcases.csv"
#: Load case columns of the sidecar table (``file`` required: a table may state only settings,
#: the fill then comes from the file name or ``--fill``).
SIDECAR_COLUMNS: tuple[str, ...] = ("file", "fill_percent", "material", "direction")
#: Column naming the specimen tested (a name, saved with the analysis record as ``specimen``).
SPECIMEN_COLUMN = "specimen"
#: Columns stating how a file is analysed (read by :mod:`pidcore.file_settings`).
ANALYSIS_SETTINGS_COLUMNS: tuple[str, ...] = (
    "velocity_delay_us", "mass_below_gauge_g", "baseline_loss_factor", "structure_mass_g",
    "force", "velocity", "acceleration", "invert", "time_unit")
#: Every column of a sidecar / the app's settings table (its template's columns, in its order).
SETTINGS_COLUMNS: tuple[str, ...] = (*SIDECAR_COLUMNS, SPECIMEN_COLUMN,
                                     *ANALYSIS_SETTINGS_COLUMNS)
#: Columns holding numbers (a ``;``-separated table may write them with a decimal comma).
NUMERIC_COLUMNS: tuple[str, ...] = ("fill_percent", "velocity_delay_us", "mass_below_gauge_g",
                                    "baseline_loss_factor", "structure_mass_g")
#: The app's labels of the settings columns (its settings grid shows them, and an uploaded
#: table may use them) -> the settings table's columns. The CLI's sidecar reads them too, so
#: one table reads the same in both (a table typed after the app's grid was refused by the CLI).
SETTINGS_COLUMN_LABELS: dict[str, str] = {
    "file": "file",
    "fill [%]": "fill_percent",
    "material": "material",
    "direction": "direction",
    "specimen": "specimen",
    "vibrometer delay [µs]": "velocity_delay_us",
    "mass below gauge [g]": "mass_below_gauge_g",
    "baseline loss factor [-]": "baseline_loss_factor",
    "structure mass [g]": "structure_mass_g",
    "force channel": "force",
    "velocity channel": "velocity",
    "acceleration channel": "acceleration",
    "inverted channels": "invert",
    "time base unit": "time_unit",
}
#: Numeric columns by either name, as :func:`pidcore.tables.read_text_table` takes them.
NUMERIC_HEADERS: tuple[str, ...] = (
    *NUMERIC_COLUMNS,
    *(label.lower() for label, column in SETTINGS_COLUMN_LABELS.items()
      if column in NUMERIC_COLUMNS))
#: Channel cell meaning "the channel the readers detect" (the app's default, and its template's).
AUTO_CHANNEL = "(auto)"
#: Channel cell meaning "no channel named" (the app's choice for an unused acceleration): as
#: for ``(auto)`` the analysis names none, so the readers use a channel only where one is
#: needed and found.
NO_CHANNEL = "(none)"
#: Free-text columns accepted and ignored: a lab's table keeps its remarks beside the values,
#: and refusing them would make users delete documentation to run an analysis.
FREE_TEXT_COLUMNS: tuple[str, ...] = ("note", "notes", "comment", "comments")

_SEPARATOR = r"[_\-. ]"  # between the tokens of a file name
_SEP = rf"(?:^|(?<={_SEPARATOR}))"  # token start: beginning of the stem or after a separator
_END = rf"(?=$|{_SEPARATOR})"  # token end
#: Fill token in a file name: ``fill50``, ``fill-50``, ``fill_62.5``, ``50pct``, ``50percent``.
FILL_PATTERN = re.compile(
    _SEP + r"(?:fill[_\-]?(?P<fill>\d+(?:\.\d+)?)(?:pct|percent)?"
    r"|(?P<pct>\d+(?:\.\d+)?)(?:pct|percent))" + _END,
    re.IGNORECASE,
)
#: Particle material token in a file name.
MATERIAL_PATTERN = re.compile(_SEP + r"(?P<material>acrylic|pmma|aluminium|aluminum)" + _END,
                              re.IGNORECASE)
#: Drive direction token in a file name: ``dirz``, ``dir-x``, ``dir_y``, ``zdir``.
DIRECTION_PATTERN = re.compile(
    _SEP + r"(?:dir[_\-]?(?P<d1>[xyz])|(?P<d2>[xyz])[_\-]?dir)" + _END, re.IGNORECASE)

@dataclass(frozen=True)
class StatedLoadCase:
    """What the user states about a measurement: fill, material, direction and where from.

    Attributes
    ----------
    fill_percent : float
        Packing ratio, %.
    material, direction : str
        Particle material and drive direction.
    origin : str
        Where each value came from, e.g. ``"fill: file name; material: default; ..."``.
    notes : tuple of str
        Each value a later statement overrode with another (a sidecar's 75 % over the file
        name's 50 %, ``--fill`` over the sidecar), in words naming the file.
    """

    fill_percent: float
    material: str
    direction: str
    origin: str
    notes: tuple[str, ...] = ()

    def load_case(self, frequency_hz: float, acceleration_g: float) -> LoadCase:
        """The full load case with the measured frequency (Hz) and acceleration (g)."""
        return LoadCase(float(frequency_hz), float(acceleration_g), self.fill_percent,
                        self.material, self.direction)


def _material_tokens(stem: str, names) -> set[str]:
    """Tokens of ``stem`` that are one of ``names`` (lower case): a whole token only, so
    ``steel`` is not found in ``steelcase``."""
    names = list(names)
    if not names:
        return set()
    pattern = re.compile(_SEP + "(?P<material>" + "|".join(map(re.escape, names)) + ")"
                         + _END, re.IGNORECASE)
    return {m.group("material").lower() for m in pattern.finditer(stem)}


def _own_material_tokens(stem: str, materials: tuple[str, ...]) -> set[str]:
    """Tokens of ``stem`` that name one of ``materials`` beyond the table's (e.g. ``steel``
    of a user's specimen)."""
    return _material_tokens(stem, (m for m in materials if m not in PARTICLE_MATERIALS))


def _untabulated_names(stem: str, parts: set[str]) -> list[str]:
    """Particle materials the table lacks that ``stem`` names, in its order, each as a
    specimen file writes it: adjacent tokens joined by ``_`` (``..._tungsten_carbide`` is
    ``tungsten_carbide``; the refusal named ``'carbide'``, the first of its tokens in
    alphabetical order, and asked for a specimen "whose particles are carbide"). Tokens of
    ``parts`` (the known materials' words) are none."""
    names: list[str] = []
    run: list[str] = []
    for token in [*re.split(_SEPARATOR, stem.lower()), ""]:
        if token in UNTABULATED_PARTICLE_MATERIALS and token not in parts:
            run.append(token)
        elif run:
            names.append("_".join(run))
            run = []
    return names


def _refuse_untabulated_material(path: Path, known: tuple[str, ...],
                                 specimen_material: str | None = None) -> None:
    """A file name naming a particle material that neither the table nor a specimen knows
    (``..._steel.csv``) would be read as the default or the specimen's material: refused.
    With a specimen given, the message names its particles (it asked for "--specimen FILE
    whose particles are steel" of a user who had given one of tungsten carbide)."""
    # a specimen's "steel_440c" is the file name's "steel"
    parts = {part for k in known for part in k.split("_")}
    named = _untabulated_names(path.stem, parts)
    if named:
        lacks = f"material table ({', '.join(PARTICLE_MATERIALS)}) lacks"
        if specimen_material is not None and specimen_material not in PARTICLE_MATERIALS:
            lacks = (f"material table ({', '.join(PARTICLE_MATERIALS)}) and the specimen's "
                     f"{specimen_material} particles lack")
        elif specimen_material is not None:  # a specimen of a table material was given too
            lacks += f" (the specimen's particles are {specimen_material})"
        raise UntabulatedMaterial(
            f"{path.name}: file name states particle material {named[0]!r}, which the "
            f"{lacks}; give specimen=FILE whose particles are {named[0]}, or state the "
            "material with material=NAME or a sidecar", named[0])


def parse_file_name(name: str | Path,
                    materials: tuple[str, ...] = PARTICLE_MATERIALS) -> dict[str, float | str]:
    """Fill, material and direction stated in a file name (only those found).

    Parameters
    ----------
    name : str or Path
        File name or path; only the name without its last suffix is searched.
    materials : tuple of str
        Materials recognised besides the table's (:data:`MATERIAL_PATTERN`): the user's own,
        e.g. ``steel`` of a specimen file or a saved DEM run, as ``..._steel.csv``.

    Returns
    -------
    dict
        Subset of ``{"fill_percent": float, "material": str, "direction": str}``.

    Examples
    --------
    >>> parse_file_name("run7_fill75_aluminum_dirx.uff")
    {'fill_percent': 75.0, 'material': 'aluminium', 'direction': 'x'}
    >>> parse_file_name("coupon_50pct_500Hz.csv")
    {'fill_percent': 50.0}
    """
    path = Path(name)
    stem = path.stem
    found: dict[str, float | str] = {}
    fills = {float(m.group("fill") or m.group("pct")) for m in FILL_PATTERN.finditer(stem)}
    if len(fills) > 1:
        raise LoadCaseError(f"{path.name}: file name states several fills "
                            f"{sorted(fills)}; state one (or use fill_percent)")
    if fills:
        found["fill_percent"] = _check_fill(fills.pop(), path.name)
    stated = {normalize_material(m.group("material"), path.name)
              for m in MATERIAL_PATTERN.finditer(stem)} | _own_material_tokens(stem, materials)
    if len(stated) > 1:
        raise LoadCaseError(f"{path.name}: file name states several materials {sorted(stated)}")
    if stated:
        found["material"] = stated.pop()
    directions = {(m.group("d1") or m.group("d2")).lower()
                  for m in DIRECTION_PATTERN.finditer(stem)}
    if len(directions) > 1:
        raise LoadCaseError(f"{path.name}: file name states several directions "
                            f"{sorted(directions)}")
    if directions:
        found["direction"] = directions.pop()
    return found


def check_columns(columns, where: str) -> None:
    """Refuse a column that is neither in :data:`SETTINGS_COLUMNS` nor free text
    (:data:`FREE_TEXT_COLUMNS`): a misspelt ``velocity_delay_ms`` would otherwise be ignored,
    and the files analysed without their delay.

    Raises
    ------
    SettingsTableError
        One line naming the table (``where``), the unknown column(s) and the known ones.
    """
    unknown = [str(c) for c in columns
               if c not in SETTINGS_COLUMNS and c not in FREE_TEXT_COLUMNS]
    if unknown:
        raise SettingsTableError(
            f"{where}: unknown column(s) {', '.join(map(repr, unknown))}; known columns are "
            f"{', '.join(SETTINGS_COLUMNS)} (and free text: {', '.join(FREE_TEXT_COLUMNS)})")


def read_sidecar(path: str | Path) -> pd.DataFrame:
    """Read a ``loadcases.csv`` sidecar table.

    Parameters
    ----------
    path : str or Path
        CSV with a header row (:func:`pidcore.tables.read_text_table`: ``,``/``;``/tab
        separated, UTF-8 or Latin-1, a line starting with ``#`` is a comment, a ``#`` in a
        cell is data); column ``file`` required, the other columns of :data:`SETTINGS_COLUMNS`
        optional, free-text ``note``/``comment`` columns ignored.

    Returns
    -------
    pandas.DataFrame
        One row per file, columns :data:`SETTINGS_COLUMNS` (missing optional ones empty), text
        stripped; the index (``"line"``) is each row's line in the file.

    Raises
    ------
    LoadCaseError
        Not found, not a readable table, column ``file`` missing, a row without a file name,
        a file listed twice.
    SettingsTableError
        A column neither the CLI nor the app knows (:func:`check_columns`).
    """
    path = Path(path)
    if not path.is_file():
        raise LoadCaseError(f"{path}: sidecar table not found")
    try:
        return settings_table(read_text_table_file(path, numeric=NUMERIC_HEADERS), str(path))
    except InputFileError as exc:
        raise LoadCaseError(str(exc)) from None


def settings_table(raw: pd.DataFrame, where: str) -> pd.DataFrame:
    """A table read by :func:`pidcore.tables.read_text_table` as a settings table (the
    sidecar's and the app's): the checks of :func:`read_sidecar`, columns
    :data:`SETTINGS_COLUMNS` in order. A column may be named by its app label
    (:data:`SETTINGS_COLUMN_LABELS`, any case); one column under both names is refused."""
    by_label = {header_key(label): column for label, column in SETTINGS_COLUMN_LABELS.items()}
    by_label.update({header_key(c): c for c in (*SETTINGS_COLUMNS, *FREE_TEXT_COLUMNS)})
    named = [by_label.get(header_key(c), c) for c in raw.columns]
    for column in set(named):
        spelt = [str(c) for c, n in zip(raw.columns, named, strict=True) if n == column]
        if len(spelt) > 1:
            raise LoadCaseError(f"{where}: column {column!r} given more than once (as "
                                f"{' and '.join(map(repr, spelt))}); expected it once")
    raw = raw.set_axis(named, axis=1)
    if "file" not in raw.columns:
        found = ", ".join(map(repr, raw.columns)) or "none"
        raise LoadCaseError(f"{where}: settings table lacks column 'file' (found {found}); "
                            f"expected columns {', '.join(SETTINGS_COLUMNS)} (file required)")
    check_columns(raw.columns, f"{where} (settings table)")
    table = raw.copy()
    for optional in SETTINGS_COLUMNS:
        if optional not in table.columns:
            table[optional] = ""
    table = table.loc[:, list(SETTINGS_COLUMNS)]
    for line, file in table["file"].items():
        if not file:
            raise LoadCaseError(f"{line_where(where, int(line))}: no file name; expected the "
                                "name of the measurement file the row is for")
    seen: dict[str, int] = {}
    for line, file in table["file"].items():
        if file in seen:
            raise LoadCaseError(f"{where}: lists {file!r} more than once (lines {seen[file]} "
                                f"and {line}); expected one row per file")
        seen[file] = int(line)
    return table


def base_name(cell: str) -> str:
    """The file name of a ``file`` cell without its folder (``/`` or ``\\``): the app and the
    CLI match rows by it, so a table written on another machine still finds its files."""
    return re.split(r"[\\/]", cell)[-1]


@dataclass(frozen=True)
class SidecarRow:
    """The sidecar row of one measurement file.

    Attributes
    ----------
    values : dict of str to str
        Cell text by column ("" for an empty cell or a column the table lacks).
    name : str
        The table as an origin is named: its file name (``"loadcases.csv"``), or
        ``"sidecar table"`` for a table given as a DataFrame.
    where : str
        The row as errors name it: ``"data/loadcases.csv, line 3 (a.uff)"``
        (:func:`pidcore.tables.line_where`; the row's position from 1 for a DataFrame read
        otherwise).
    """

    values: dict[str, str]
    name: str
    where: str


def _row_label(table: pd.DataFrame, position: int) -> str:
    """``"line 3"`` for a table read from a file (its line there), else ``"row 1"``."""
    if table.index.name == "line":
        return line_where("", int(table.index[position]))[2:]
    return f"row {position + 1}"


def _row_where(table: pd.DataFrame, position: int, shown: str) -> str:
    return f"{shown}, {_row_label(table, position)}"


def _ends_with(parts: tuple[str, ...], cell: list[str]) -> bool:
    cell = [c for c in cell if c not in ("", ".")]
    return len(cell) <= len(parts) and list(parts[len(parts) - len(cell):]) == cell


def name_spellings(name: str) -> tuple[str, ...]:
    """``name`` as the file system gives it, and, where its bytes are not UTF-8 (a file named
    on Windows, ``Prüfung.uff`` in cp1252, copied to Linux: Python holds the byte 0xFC as a
    lone surrogate), as cp1252 reads them: the spelling a settings table saved by a Windows
    spreadsheet (read as cp1252, :mod:`pidcore.tables`) has in its ``file`` cell. Under an
    ASCII locale (``LC_ALL=C``) Python holds even UTF-8 bytes as surrogates: their UTF-8
    spelling is the one a table read as UTF-8 has."""
    import os

    spellings = [name]
    raw = os.fsencode(name)
    try:
        as_utf8 = raw.decode("utf-8")
        if as_utf8 != name:
            spellings.append(as_utf8)
    except UnicodeDecodeError:
        for encoding in ("cp1252", "latin-1"):
            try:
                spellings.append(raw.decode(encoding))
                break
            except UnicodeDecodeError:  # cp1252 leaves 5 bytes undefined; latin-1 none
                continue
    return tuple(spellings)


def find_row(table: pd.DataFrame, path: str | Path, shown: str) -> int | None:
    """Position of the row of file ``path`` in a settings ``table`` (None: no row).

    A row's ``file`` is matched by its base name (a folder in the cell is allowed, as in the
    app); exporters and file systems disagree on case, so a case-folded match is accepted when
    no exact one exists. Several rows matching equally (two cases of one name, or one name
    under two folders none of which is the file's) are refused: taking the first would be a
    silent guess.
    """
    path = Path(path)
    files = [str(f) for f in table["file"]]
    names = name_spellings(path.name)
    for same in (lambda a, b: a == b, lambda a, b: a.casefold() == b.casefold()):
        found = [i for i, f in enumerate(files)
                 if any(same(base_name(f), name) for name in names)]
        if len(found) > 1:
            # one name under several folders: the row whose folders end the file's path
            parts = path.absolute().parts
            tail = [i for i in found if _ends_with(parts, re.split(r"[\\/]", files[i]))]
            found = tail if len(tail) == 1 else found
        if len(found) > 1:
            rows = " and ".join(f"{_row_label(table, i)} ({files[i]!r})" for i in found[:2])
            raise LoadCaseError(f"{shown}: {rows} both match {path.name!r}; expected one "
                                "row per file (fix the name or the case of one)")
        if found:
            return found[0]
    return None


def sidecar_row(path: str | Path,
                sidecar: str | Path | pd.DataFrame | None = None, *,
                tables: dict[Path, pd.DataFrame] | None = None) -> SidecarRow | None:
    """The row of ``path``'s file name in its sidecar table (None: no table, or no row).

    ``sidecar``: the table (a path, read with :func:`read_sidecar`, or a DataFrame), else
    ``loadcases.csv`` beside the file if there is one. Rows are matched by :func:`find_row`.
    ``tables``: the tables read so far by path, filled here, so that the callers resolving
    many files against one table (load case and settings of each) read it once.
    """
    path = Path(path)
    if isinstance(sidecar, pd.DataFrame):
        table, shown, name = sidecar, "sidecar table", "sidecar table"
    else:
        sidecar_path = Path(sidecar) if sidecar is not None else path.parent / SIDECAR_NAME
        if sidecar is None and not sidecar_path.is_file():
            return None
        if path.is_file() and sidecar_path.is_file() and path.samefile(sidecar_path):
            # `pidcore analyze folder/*` with the table beside the files: refused as what it
            # is, not read as a measurement ("header but no data rows")
            raise LoadCaseError(
                f"{path}: is the sidecar table (the load case and settings of each file), "
                "not a measurement; leave it out of the files given (a "
                f"{SIDECAR_NAME} beside the files is read by itself; another with sidecar=PATH)")
        if tables is None:
            table = read_sidecar(sidecar_path)
        else:
            table = tables.get(sidecar_path)
            if table is None:
                table = tables[sidecar_path] = read_sidecar(sidecar_path)
        shown, name = str(sidecar_path), sidecar_path.name
    found = find_row(table, path, shown)
    if found is None:
        return None
    row = table.iloc[found]
    values = {str(c): ("" if v is None else str(v)) for c, v in row.items()}
    return SidecarRow(values, name, f"{_row_where(table, found, shown)} ({path.name})")


def _material(value: str, what: str, known: tuple[str, ...]) -> str:
    """:func:`normalize_material` of a measurement's stated material; an unknown name gets
    the hint that a specimen's own material is known only with its specimen file."""
    try:
        return normalize_material(value, what, known)
    except LoadCaseError as exc:
        if known != PARTICLE_MATERIALS:
            raise
        raise LoadCaseError(f"{exc} (a specimen's own material, e.g. steel, needs "
                            "specimen=FILE)") from None


def _sidecar_entry(row: SidecarRow,
                   known: tuple[str, ...] = PARTICLE_MATERIALS) -> dict[str, float | str]:
    what = row.where
    found: dict[str, float | str] = {}
    if row.values.get("fill_percent", ""):
        found["fill_percent"] = _check_fill(row.values["fill_percent"], what)
    if row.values.get("material", ""):
        found["material"] = _material(row.values["material"], what, known)
    if row.values.get("direction", ""):
        found["direction"] = normalize_direction(row.values["direction"], what)
    return found


def missing_fill_message(path: str | Path) -> str:
    """The error text for a measurement without a stated fill (names the three ways)."""
    from ..io import display_path

    return (f"{display_path(Path(path).name)}: no fill (packing ratio, %) stated; state it "
            "(1) in the file name, "
            f"e.g. '..._fill50_...' or '..._50pct_...', (2) in a sidecar table {SIDECAR_NAME} "
            # quoted: the CLI's words read a bare fill_percent as the flag --fill, and the
            # message named a sidecar column "--fill"
            f"beside the file or given with sidecar=PATH (columns "
            f"{', '.join(repr(c) for c in SIDECAR_COLUMNS)}), "
            "or (3) with fill_percent")


def resolve_load_case(
    path: str | Path,
    *,
    fill_percent: float | None = None,
    material: str | None = None,
    direction: str | None = None,
    sidecar: str | Path | pd.DataFrame | None = None,
    specimen_material: str | None = None,
    materials: tuple[str, ...] = (),
    tables: dict[Path, pd.DataFrame] | None = None,
) -> StatedLoadCase:
    """What the user states about a measurement file: file name < sidecar < options.

    Parameters
    ----------
    path : str or Path
        The measurement file (its name is parsed; its folder is searched for ``loadcases.csv``).
    fill_percent : float, optional
        Fill from the command line, %; overrides file name and sidecar.
    material, direction : str, optional
        Particle material and drive direction from the command line; override the others.
    sidecar : path or DataFrame, optional
        Sidecar table to use instead of ``loadcases.csv`` beside the file.
    specimen_material : str, optional
        Particle material of the specimen the measurement is compared with (``--specimen``):
        accepted besides the table's materials, and the default when none is stated.
    materials : tuple of str, optional
        Further own materials accepted (in the name, the sidecar and ``material``), e.g. those
        of the user's specimen files and saved DEM runs (the app's).

    Returns
    -------
    StatedLoadCase

    Raises
    ------
    LoadCaseError
        No fill stated anywhere (the message names the file and the three ways), or a value that
        is not a valid fill, material or direction.

    Examples
    --------
    >>> s = resolve_load_case("x_fill50_acrylic.uff", sidecar=None)
    >>> s.fill_percent, s.material, s.direction
    (50.0, 'acrylic', 'z')
    >>> s.load_case(500.2, 4.98).key
    'f500.2Hz_a4.98g_fill50pct_acrylic_z'
    """
    path = Path(path)
    values: dict[str, float | str] = {}
    origin: dict[str, str] = {}

    # per name, the statements a later one replaced, in order: said once, by the value that
    # stands (a chain file name < sidecar < option said the sidecar's value as standing)
    overridden: dict[str, list[tuple[float | str, str]]] = {}
    stated_in = {"file name"}  # the statements a later one overrides with a note

    def take(found: dict[str, float | str], where: str) -> None:
        for name, value in found.items():
            earlier = origin.get(name)
            if earlier in stated_in:
                overridden.setdefault(name, []).append((values[name], earlier))
            values[name] = value
            origin[name] = where

    known = (*PARTICLE_MATERIALS, *(m for m in materials if m not in PARTICLE_MATERIALS))
    if specimen_material is not None:
        specimen_material = normalize_material(specimen_material, "specimen", None)
        if specimen_material not in known:
            known = (*known, specimen_material)
        origin["material"] = "specimen"
        values["material"] = specimen_material
    take(parse_file_name(path, known), "file name")
    row = sidecar_row(path, sidecar, tables=tables)
    if row is not None:
        take(_sidecar_entry(row, known), row.name)
        stated_in.add(row.name)
    stated_by_user = {"file name"} | ({row.name} if row is not None else set())
    if origin.get("material") not in stated_by_user and material is None:
        _refuse_untabulated_material(path, known, specimen_material)
    options: dict[str, float | str] = {}
    if fill_percent is not None:
        options["fill_percent"] = _check_fill(fill_percent, "fill_percent")
    if material is not None:
        options["material"] = _material(material, "material", known)
    if direction is not None:
        options["direction"] = normalize_direction(direction, "direction")
    take(options, "option")

    if "fill_percent" not in values:
        raise FillNotStated(missing_fill_message(path), str(values.get("material", "")))
    values.setdefault("material", defaults.COMPARE_DEFAULT_MATERIAL)
    values.setdefault("direction", defaults.COMPARE_DEFAULT_DIRECTION)
    text = "; ".join(f"{name.split('_')[0]}: {origin.get(name, 'default')}"
                     for name in ("fill_percent", "material", "direction"))
    return StatedLoadCase(float(values["fill_percent"]), str(values["material"]),
                          str(values["direction"]), text,
                          _override_notes(path.name, values, origin, overridden))


def _override_notes(name_of_file: str, values: dict[str, float | str], origin: dict[str, str],
                    overridden: dict[str, list[tuple[float | str, str]]]) -> tuple[str, ...]:
    """One note per stated value that replaced others that differ from it: a typo in a sidecar
    row moved a test to another load case, named only by "(fill: loadcases.csv)"."""
    notes = []
    for name, replaced in overridden.items():
        final = values[name]
        differing = [(value, where) for value, where in reversed(replaced) if value != final]
        if not differing:
            continue
        where = origin[name]
        of = " and ".join(f"{_stated(name, value)} of "
                          f"{'the file name' if earlier == 'file name' else earlier}"
                          for value, earlier in differing)
        notes.append(f"{name_of_file}: {_STATED_WORDS[name]} {_stated(name, final)} "
                     f"({f'{name}=' if where == 'option' else where}) overrides {of}")
    return tuple(notes)


#: How a load case's stated values are named in notes.
_STATED_WORDS = {"fill_percent": "fill", "material": "material", "direction": "direction"}


def _stated(name: str, value: float | str) -> str:
    return f"{value:g} %" if name == "fill_percent" else repr(value)
