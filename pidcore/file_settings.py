"""Per-file settings of a sidecar / settings table: how each measurement file is analysed.

One table, two readers: the sidecar ``loadcases.csv`` of ``pidcore analyze`` and ``pidcore
report`` (beside the files or ``--sidecar CSV``) and the app's uploaded settings table have the
same columns (:data:`SETTINGS_COLUMNS`). Besides the load case (``file, fill_percent, material,
direction``: :mod:`pidcore.compare.loadcase`) a row states:

=========================  ==================================================================
column                     meaning (:class:`~pidcore.measure.AnalysisOptions` field)
=========================  ==================================================================
``velocity_delay_us``      vibrometer output delay, µs, 0 or >= 0.01 (``velocity_delay_s``)
``mass_below_gauge_g``     mass between gauge and coupon, g, 0 or >= 0.1 (``mass_below_gauge_kg``)
``baseline_loss_factor``   loss factor of the empty coupon, >= 0 (``baseline_loss_factor``)
``structure_mass_g``       mass of that empty structure, g, 0 (none) or >= 1
                           (``structure_mass_kg``): its dissipation is what the baseline
                           subtracts
``force``, ``velocity``,   channel names (``force``, ``velocity``, ``acceleration``);
``acceleration``           ``(auto)`` and ``(none)`` (the app's template) name none: detected
``invert``                 channels whose sign is flipped, ``;``-separated (``invert``)
``time_unit``              unit of the file's time base (``s``, ``ms``, ``us``; ``time_unit``):
                           as ``--time-unit`` reads it, for this file only
``specimen``               the specimen tested (a name, saved with the analysis record)
``note``, ``notes``,       free text for the user's own remarks: read and ignored
``comment``, ``comments``
=========================  ==================================================================

The columns' units, ranges and words live in :mod:`pidcore.compare.settings_columns`
(:data:`ANALYSIS_COLUMNS`, re-exported here), where the comparison's corrections column reads
them too. Any other column is refused (:func:`~pidcore.compare.loadcase.check_columns`): a
misspelt ``velocity_delay_ms`` would otherwise be ignored and the file analysed at 0 µs
without a word. An empty cell states nothing. Precedence is that of the load case: file
name (states no analysis setting) < table < options given explicitly (the command line's
``--velocity-delay`` etc.), and an explicit option that overrides a different table value
is said in a note (:func:`resolve_file_settings`); but a time unit given for every file that
reads a file's time otherwise than its row's ``time_unit`` is refused: one of the two is
wrong, and either gives every frequency 1000 x off.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields, replace
from numbers import Real
from pathlib import Path
from typing import TYPE_CHECKING

from .compare.loadcase import (
    ANALYSIS_SETTINGS_COLUMNS,
    AUTO_CHANNEL,
    FREE_TEXT_COLUMNS,
    NO_CHANNEL,
    SETTINGS_COLUMNS,
    SIDECAR_NAME,
    SPECIMEN_COLUMN,
    FillNotStated,
    LoadCaseError,
    StatedLoadCase,
    check_columns,
    resolve_load_case,
    sidecar_row,
)
from .compare.settings_columns import (
    ANALYSIS_COLUMNS,
    COLUMN_WORDS,
    SettingsColumn,
    setting_in_words,
    setting_phrase,
)
from .errors import PidcoreError, SettingsTableError
from .io import display_path

if TYPE_CHECKING:
    import os

    import pandas as pd

    from .measure import AnalysisOptions, AnalyzedRecord
    from .specimen import Specimen

__all__ = ["ANALYSIS_COLUMNS", "ANALYSIS_SETTINGS_COLUMNS", "AUTO_CHANNEL", "FREE_TEXT_COLUMNS",
           "NO_CHANNEL",
           "SETTINGS_COLUMNS", "SPECIMEN_COLUMN", "FileSettings", "SettingsColumn",
           "analysis_overrides", "analyze_with_settings", "assumed", "assumption_notes",
           "files_assumption_notes",
           "check_columns", "stored_assumption_notes",
           "resolve_file_settings", "resolve_files", "setting_in_words"]


_COLUMN_OF_FIELD = {c.field: name for name, c in ANALYSIS_COLUMNS.items()}
def _stated(value: object) -> bool:
    """Whether a cell states something: None and blank text state nothing (NaN does: it is
    refused as a value, since a float cell that is NaN is no setting anyone meant)."""
    return value is not None and not (isinstance(value, str) and not value.strip())


def _number(value: object, column: str, spec: SettingsColumn, where: str) -> float:
    shown = value.strip() if isinstance(value, str) else value

    def refused(what: str) -> SettingsTableError:
        return SettingsTableError(f"{where}, column {column}: {shown!r} {what}; "
                                  f"expected {spec.expected}")

    if isinstance(value, bool) or not isinstance(value, (str, Real)):
        raise refused("is not a number")
    try:
        number = float(value)
    except ValueError:
        raise refused("is not a number") from None
    if not math.isfinite(number):
        raise refused("is not a finite number")
    if number < 0:
        # a vibrometer only ever lags (AnalysisOptions refuses a negative delay too, without
        # the cell), and a negative mass or baseline would add what they are meant to remove
        raise refused("is negative")
    if 0 < number < spec.smallest:
        raise SettingsTableError(
            f"{where}, column {column}: {shown!r} is implausibly small (below "
            f"{spec.smallest:g} {spec.unit}); it looks like a value in {spec.slip} "
            f"({number:g} {spec.slip} = {number * spec.scale:g} {spec.unit}); expected "
            f"0 or at least {spec.smallest:g} {spec.unit}")
    return number / spec.scale


def _time_unit(value: object, column: str, spec: SettingsColumn, where: str) -> str:
    """A time unit cell as ``time_unit=`` takes it (its text), refused as
    :func:`pidcore.units.given_time_unit` refuses the keyword, naming the cell instead."""
    from .units import why_not_a_time_unit

    text = str(value).strip()
    why = why_not_a_time_unit(text)
    if why is not None:
        raise SettingsTableError(f"{where}, column {column}: {text!r} is not a unit of "
                                 f"time{why}; expected {spec.expected}")
    return text


def same_time_unit(first: str | None, second: str | None) -> bool:
    """Whether two time units given (``time_unit=``, a ``time_unit`` cell) read a time base
    alike (``ms`` and ``msec``); None (none given) agrees with anything."""
    from .units import given_time_unit, overrides_stated_time

    if first is None or second is None:
        return True
    return not overrides_stated_time(first, given_time_unit(second))


def analysis_overrides(values: Mapping[str, object], where: str, *,
                       labels: Mapping[str, str] | None = None) -> dict[str, object]:
    """The :class:`~pidcore.measure.AnalysisOptions` fields one settings row states.

    Parameters
    ----------
    values : mapping
        Cells of the row by column (:data:`ANALYSIS_COLUMNS`; other keys are ignored): text as
        read from a CSV, or numbers / names as the app's editor holds them. ``None`` or blank
        text states nothing.
    where : str
        The row, as errors name it, e.g. ``"loadcases.csv, line 2 (a.uff)"``.
    labels : mapping, optional
        Column -> the name errors use for it (the app's ``"vibrometer delay [µs]"``).

    Returns
    -------
    dict
        Field -> value in SI (µs -> s, g -> kg); ``invert`` as a tuple of names.

    Raises
    ------
    SettingsTableError
        One line naming ``where``, the column, the value and what was expected: not a
        number, NaN or infinite, negative.

    Examples
    --------
    >>> analysis_overrides({"velocity_delay_us": "50", "invert": "Force; Accel"}, "t.csv")
    {'velocity_delay_s': 5e-05, 'invert': ('Force', 'Accel')}
    """
    labels = labels or {}
    out: dict[str, object] = {}
    for column, spec in ANALYSIS_COLUMNS.items():
        value = values.get(column)
        if not _stated(value):
            continue
        name = labels.get(column, column)
        if spec.kind == "number":
            out[spec.field] = _number(value, name, spec, where)
            continue
        if spec.kind == "time unit":
            if not (isinstance(value, float) and math.isnan(value)):
                out[spec.field] = _time_unit(value, name, spec, where)
            continue
        if isinstance(value, float) and math.isnan(value):
            continue  # a text column's empty cell, as pandas holds it
        if spec.kind == "channel":
            channel = str(value).strip()
            # the app's words for "detect it" and "none named": the analysis names no channel
            # (the app's template round-trips through the CLI to the same numbers)
            if channel not in (AUTO_CHANNEL, NO_CHANNEL):
                out[spec.field] = channel
        else:
            names = value.split(";") if isinstance(value, str) else (
                list(value) if isinstance(value, (list, tuple)) else [value])
            found = tuple(n for n in (str(x).strip() for x in names) if n)
            if found:
                out[spec.field] = found
    return out


def _same(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        # µs / 1e6 and a delay typed in s meet in the last bit at most
        return math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-15)
    if isinstance(a, tuple) and isinstance(b, tuple):
        return set(a) == set(b)  # the channels inverted, in any order
    return a == b


@dataclass(frozen=True)
class FileSettings:
    """How one measurement file is analysed, and who said so.

    Attributes
    ----------
    options : AnalysisOptions
        The options to analyse it with.
    specimen : str
        The specimen its table row names ("" for none).
    sources : dict of str to str
        Setting (options field or ``"specimen"``) -> the table that stated it (e.g.
        ``"loadcases.csv"``), for the values the table set.
    notes : tuple of str
        Explicit options that override a different table value, one line each.
    cells : dict of str to tuple
        Options field -> (column, cell text, row) of each value the table set (errors of the
        analysis name the cell, not the option it became).
    unmatched : str
        A note when a table given explicitly (``--sidecar``) has no row for the file: not an
        error (one table may cover several runs), but a misspelt row would otherwise leave the
        file at the defaults without a word. "" otherwise.
    specimen_sha256 : str
        The sha256 of the specimen file tested where ``specimen`` is the file given
        (:func:`pidcore.specimen.measured_specimen_sha256`), saved beside its name; "" where
        only a name is known (a table naming another specimen).
    """

    options: AnalysisOptions
    specimen: str = ""
    sources: dict[str, str] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    cells: dict[str, tuple[str, str, str]] = field(default_factory=dict)
    unmatched: str = ""
    specimen_sha256: str = ""

    def record_fields(self) -> dict[str, str]:
        """The record fields naming the specimen tested (none where no specimen is named): its
        name and, where its file was given, the file's hash."""
        from .specimen import MEASURED_SHA256_FIELD

        if not self.specimen:
            return {}
        return {SPECIMEN_COLUMN: self.specimen,
                **({MEASURED_SHA256_FIELD: self.specimen_sha256} if self.specimen_sha256
                   else {})}

    def summary(self) -> str:
        """The settings the table set, in words with their table, e.g. ``'vibrometer delay
        50 µs, specimen 'B' (loadcases.csv)'``; "" when it set none."""
        by_source: dict[str, list[str]] = {}
        for name, source in self.sources.items():
            value = self.specimen if name == SPECIMEN_COLUMN else getattr(self.options, name)
            by_source.setdefault(source, []).append(setting_phrase(name, value))
        return "; ".join(f"{', '.join(words)} ({source})" for source, words in by_source.items())

    def statement(self) -> tuple[str, str]:
        """What this file's settings state, comparable between files: (specimen, options)."""
        return self.specimen, json.dumps(self.options.parameters(), sort_keys=True)

    def label(self) -> str:
        """The specimen and every option not at its default, in words ("" for none)."""
        from .measure import AnalysisOptions

        default = AnalysisOptions()
        parts = [setting_phrase(SPECIMEN_COLUMN, self.specimen)] if self.specimen else []
        for f in fields(default):
            value = getattr(self.options, f.name)
            if value != getattr(default, f.name) and (f.name in COLUMN_WORDS or f.name in (
                    "force", "velocity", "acceleration", "invert")):
                parts.append(setting_phrase(f.name, value))
        return ", ".join(parts)

    def explain(self, message: str) -> str:
        """``message`` (an analysis error) saying which values came from the table: the
        options keyword of a number it set is its words and its cell (``velocity_delay_s``
        becomes ``vibrometer delay (column velocity_delay_us '1e6' of loadcases.csv, line 2
        (a.uff))``), not the option the CLI would translate the keyword to; a channel name it
        set that the message quotes gets its cell appended."""
        appended = []
        for name, (column, text, where) in self.cells.items():
            cell = f"column {column} {text!r} of {where}"
            if name in COLUMN_WORDS:
                message = re.sub(rf"(?<![\w-]){re.escape(name)}(?!\w)",
                                 lambda _, n=name, c=cell: f"{COLUMN_WORDS[n][0]} ({c})",
                                 message)
                continue
            value = getattr(self.options, name)
            names = value if isinstance(value, tuple) else (value,)
            if any(f"{n!r}" in message for n in names):
                appended.append(cell)
        return message + "".join(f"; {cell}" for cell in appended)


def _stem_hint(path: str | os.PathLike, table_path: Path,
               tables: dict[Path, pd.DataFrame] | None) -> str:
    """``"; line 3 names 'run 13', without the extension"`` where a row names the file's name
    without its extension (as a spreadsheet user types it), else ``""``."""
    from .compare.loadcase import base_name, read_sidecar

    table = tables.get(table_path) if tables is not None else None
    if table is None:
        table = read_sidecar(table_path)
    stem = Path(path).stem.casefold()
    for line, cell in table["file"].items():
        if base_name(str(cell)).casefold() == stem:
            return (f"; line {line} names {cell!r}, without the extension: write "
                    f"{display_path(Path(path).name)!r}")
    return ""


def resolve_file_settings(path: str | os.PathLike, options: AnalysisOptions | None = None, *,
                          given: Mapping[str, str] | None = None,
                          sidecar: str | os.PathLike | pd.DataFrame | None = None,
                          tables: dict[Path, pd.DataFrame] | None = None) -> FileSettings:
    """The analysis settings of one measurement file: table row < explicit options.

    Parameters
    ----------
    path : path
        The measurement file (its name is looked up in the table; its folder holds the default
        ``loadcases.csv``).
    options : AnalysisOptions, optional
        The options for every file (the command line's, its defaults filled in).
    given : mapping, optional
        Options fields given explicitly -> how to name them in notes (``{"velocity_delay_s":
        "--velocity-delay"}``): these override the table. Default: the fields of ``options``
        that differ from :class:`~pidcore.measure.AnalysisOptions`'s defaults.
    sidecar : path or DataFrame, optional
        The table to use instead of ``loadcases.csv`` beside the file
        (:func:`pidcore.compare.loadcase.sidecar_row`).
    tables : dict, optional
        Tables read so far by path (:func:`~pidcore.compare.loadcase.sidecar_row`).

    Returns
    -------
    FileSettings

    Raises
    ------
    SettingsTableError
        A table with an unknown column (:func:`check_columns`) or a bad value in this file's
        row (:func:`analysis_overrides`).
    """
    import pandas as pd

    from .measure import AnalysisOptions

    options = options if options is not None else AnalysisOptions()
    if given is None:
        default = AnalysisOptions()
        given = {f.name: f.name for f in fields(default)
                 if getattr(options, f.name) != getattr(default, f.name)}
    row = sidecar_row(path, sidecar, tables=tables)
    if row is None:
        # A table given: a file without a row there is said to have none. The loadcases.csv
        # found beside the file may state only some files, so only a row that names this
        # one without its extension is said (it left the file's 50 µs delay out silently).
        unmatched, hint, shown = "", "", None
        if sidecar is not None and not isinstance(sidecar, pd.DataFrame):
            hint = _stem_hint(path, Path(sidecar), tables)
            shown = sidecar
        elif sidecar is None and (Path(path).parent / SIDECAR_NAME).is_file():
            shown = Path(path).parent / SIDECAR_NAME
            hint = _stem_hint(path, shown, tables)
        if hint or (sidecar is not None and not isinstance(sidecar, pd.DataFrame)):
            unmatched = (f"{display_path(Path(path).name)}: no row in {display_path(shown)} "
                         "(rows are matched by file "
                         f"name{hint}); its load case and settings come from its name and the "
                         "options")
        return FileSettings(options, unmatched=unmatched)
    stated = analysis_overrides(row.values, row.where)
    changes: dict[str, object] = {}
    sources: dict[str, str] = {}
    cells: dict[str, tuple[str, str, str]] = {}
    notes = []
    for name, value in stated.items():
        column = _COLUMN_OF_FIELD[name]
        text = str(row.values[column]).strip()
        if name in given:
            mine = getattr(options, name)
            if name == "time_unit" and not same_time_unit(mine, value):
                # not an override to note: one of the two is wrong, and either reading gives
                # every frequency of the file 1000 x off the other's
                raise SettingsTableError(
                    f"{display_path(Path(path).name)}: {given[name]} {mine!r} disagrees with "
                    f"column {column} {text!r} of {row.where}; expected one unit of the "
                    f"file's time base (leave the cell empty or {given[name]} out)")
            if name != "time_unit" and not _same(value, mine):
                notes.append(f"{display_path(Path(path).name)}: {given[name]} "
                             f"({setting_phrase(name, mine)}) "
                             f"overrides column {column} {text!r} of {row.where}")
            continue
        changes[name] = value
        sources[name] = row.name
        cells[name] = (column, text, row.where)
    specimen = str(row.values.get(SPECIMEN_COLUMN, "") or "").strip()
    if specimen:
        sources[SPECIMEN_COLUMN] = row.name
    return FileSettings(replace(options, **changes), specimen, sources, tuple(notes), cells)


def analyze_each(paths: Sequence[str | os.PathLike], settings: Sequence[FileSettings], *,
                 key: str | None = None, progress: bool = False,
                 keep_unused_channels: bool = True) -> list[AnalyzedRecord]:
    """:func:`analyze_with_settings` of every file with its own settings, in order.

    ``progress``: a bar with the files done and the time left on stderr where there are
    several (the caller asks for it on a terminal only); forty exports took 7-12 s with no
    sign of life.
    ``keep_unused_channels=False``: each record's measurement keeps only the channels its
    analysis used, the others dropped as soon as the file is analysed; for a caller that
    saves no measurement (``analyze --no-store``): every record is held until the last file
    is done, and an export of eight channels held all eight."""
    pairs = list(zip(paths, settings, strict=True))

    def analyzed(path: str | os.PathLike, fs: FileSettings) -> AnalyzedRecord:
        record = analyze_with_settings(path, fs, key=key)
        return record if keep_unused_channels else _without_unused_channels(record)

    if not progress or len(pairs) < 2:
        return [analyzed(path, fs) for path, fs in pairs]
    from tqdm import tqdm

    records = []
    # closed (its line cleared) as an error or Ctrl-C leaves, before the caller's one line:
    # a bar iterating the files was closed only when collected, after that line
    with tqdm(total=len(pairs), unit="file", desc="analysing", leave=False,
              dynamic_ncols=True) as bar:
        for path, fs in pairs:
            records.append(analyzed(path, fs))
            bar.update(1)
    return records


def _without_unused_channels(record: AnalyzedRecord) -> AnalyzedRecord:
    """``record`` whose measurement holds only the channels its analysis used (its source,
    SHA-256 and metadata as read)."""
    used = set(record.channels_used.values())
    measurement = record.measurement
    return replace(record, measurement=replace(
        measurement, channels=tuple(c for c in measurement.channels if c.name in used)))


def analyze_with_settings(path: str | os.PathLike, settings: FileSettings, *,
                          key: str | None = None) -> AnalyzedRecord:
    """:func:`pidcore.measure.analyze_file` with ``settings.options``; an error that names an
    option the table set names the table's cell instead (:meth:`FileSettings.explain`)."""
    from .measure import analyze_file

    invert_cell = settings.cells.get("invert")
    try:
        record = analyze_file(path, settings.options, key=key)
    except PidcoreError as exc:
        message = str(exc)
        if invert_cell is not None:  # the table's cell, appended below, not the option
            message = message.replace("invert='", "invert '")
        explained = settings.explain(message)
        if explained == str(exc):
            raise
        raise type(exc)(explained) from None
    notes = record.notes
    time_unit_cell = settings.cells.get("time_unit")
    if time_unit_cell is not None:
        # "taken as 'ms' (time_unit)" of a unit the table's row stated: said of the option
        # for every file, which was not given
        column, _, where = time_unit_cell
        notes = tuple(n.replace(" (time_unit)", f" (column {column} of {where})")
                      for n in notes)
    if invert_cell is not None:
        # "channel 'V' inverted (invert='V')" of a channel the table's invert column named:
        # the note names the cell, as the settings line and the errors do
        column, _, where = invert_cell
        notes = tuple(
            re.sub(r" inverted \(invert='[^']*'\)", f" inverted (column {column} of {where})",
                   n) for n in notes)
    return record if notes == record.notes else replace(record, notes=notes)


def _refuse_fill_of_no_particle(path: str | os.PathLike, stated: StatedLoadCase | None,
                                specimen: Specimen | None) -> None:
    """Refuse a stated fill that rounds to no particle of its cell (the rule `dem run`
    applies), naming the file and where the fill came from."""
    from .dem.simulate import particles_of_stated_fill

    if stated is None:
        return
    try:
        # "fill", not the keyword: the fill may come from the file name or a sidecar
        particles_of_stated_fill(stated.fill_percent, stated.material, specimen=specimen,
                                 what="fill", typed=True)
    except PidcoreError as exc:
        if not str(exc).startswith("fill "):  # not about the fill
            raise
        origin = next((part.strip() for part in stated.origin.split(";")
                       if part.strip().startswith("fill")), "")
        origin = origin.replace("fill: option", "fill: fill_percent")
        # (particles_for_fill asks whether a fraction was typed where that holds a particle)
        hint = "" if "meant as" in str(exc) else "; a fill is a percentage of the cell's capacity"
        raise LoadCaseError(f"{display_path(Path(path).name)}: {exc} ({origin}{hint})") \
            from None


def resolve_files(paths: Sequence[str | os.PathLike], *, options: AnalysisOptions | None = None,
                  given: Mapping[str, str] | None = None, fill_percent: float | None = None,
                  material: str | None = None, direction: str | None = None,
                  sidecar: str | os.PathLike | None = None,
                  specimen_material: str | None = None, fill_required: bool = True,
                  specimen_name: str | None = None, specimen: Specimen | None = None,
                  ) -> tuple[list[StatedLoadCase | None], list[FileSettings]]:
    """What each file states about its load case (:func:`resolve_load_case`) and how it is
    analysed (:func:`resolve_file_settings`), file by file, before any analysis, so that a bad
    sidecar or option is refused at once; each sidecar is read once for all files.

    ``fill_required=False`` gives None for a file that states no fill (``pidcore analyze``
    saves it without a load case); otherwise :class:`FillNotStated` is raised.
    ``specimen_name`` (of ``--specimen``): the specimen of every file of its particles
    (``specimen_material``) whose sidecar row names none, with source ``--specimen``. Such
    files were saved unnamed, and a later report of another specimen of those particles took
    them for its own tests. A stated fill that rounds to no particle of the cell of its
    material (``specimen``'s for its particles, the paper's coupon for the table's) is refused
    naming the file: 0.5 typed for 50 % was analysed and saved as a coupon without particles.
    A file named like the paper's coupon with other content (``specimen``, named
    ``specimen_name``) is saved under :func:`pidcore.specimen.measured_specimen_name`
    (``"paper_coupon [45d792]"``), and so is a file whose sidecar names that name. Every
    file of that specimen carries its file's hash too (:attr:`FileSettings.specimen_sha256`).
    A sidecar's specimen is the file given where it names it as the app's settings table
    does (:func:`pidcore.specimen.resolve_specimen_name`: by its name or by its label
    ``"panel [3e945a]"``), so that both front ends save one test alike.
    """
    from .specimen import resolve_specimen_name

    def named(fs: FileSettings) -> FileSettings:
        """``fs`` with the file given where its specimen names it; as it is otherwise (a
        sidecar naming another specimen keeps that name, whose runs are met by name)."""
        if specimen is None or not fs.specimen:
            return fs
        found = resolve_specimen_name(fs.specimen, [specimen])
        if found.note:  # not the file given
            return fs
        return replace(fs, specimen=found.name, specimen_sha256=found.sha256)

    tables: dict = {}
    stated: list[StatedLoadCase | None] = []
    settings: list[FileSettings] = []
    for path in paths:
        try:
            stated.append(resolve_load_case(path, fill_percent=fill_percent, material=material,
                                            direction=direction, sidecar=sidecar,
                                            specimen_material=specimen_material,
                                            tables=tables))
            particles = stated[-1].material
        except FillNotStated as exc:
            if fill_required:
                raise
            stated.append(None)
            # a file stating no fill is still a test of --specimen where its particles are
            # the specimen's: it was saved unnamed, and the output said "no specimen named,
            # the paper's coupon assumed ... name another with --specimen FILE" beside it
            particles = exc.material
        _refuse_fill_of_no_particle(path, stated[-1], specimen)
        fs = resolve_file_settings(path, options, given=given, sidecar=sidecar, tables=tables)
        if specimen_name and not fs.specimen and particles == specimen_material:
            fs = replace(fs, specimen=specimen_name,
                         sources={**fs.sources, SPECIMEN_COLUMN: "--specimen"})
        # the file given is saved by the name its tests are compared under (the bare name of
        # another paper_coupon file would claim the paper's coupon) and by its hash, which
        # tells it from another file of its name
        settings.append(named(fs))
    return stated, settings


#: A material name in :data:`StatedLoadCase.origin` that nothing stated (the paper's acrylic).
_DEFAULT_ORIGIN = "material: default"


def assumed(stated: StatedLoadCase | None, specimen: str,
            specimen_given: Specimen | None = None) -> dict[str, str]:
    """What a measurement file takes from no statement, by field: ``{"material": "acrylic",
    "specimen": "paper_coupon"}`` for a file that names neither (``{}`` when both are stated).

    An unnamed measurement is the paper's coupon to ``pidcore report``, ``calibrate`` and the
    app's Compare; nylon beads analysed without ``specimen=FILE`` were saved as that coupon's
    acrylic and the output said only "material: default", so the front ends say it in words
    (:func:`assumption_notes`). ``specimen``: the name saved with the file ("" for none:
    :attr:`FileSettings.specimen`); ``specimen_given``: ``specimen=FILE``, whose particles a
    file of another named specimen (a sidecar's ``coupon_B``) takes where nothing states its
    own (``"material_from"``: the name of ``specimen_given``). A file without a stated fill has no
    load case, hence no material: only its specimen is assumed. A file that is the paper's
    coupon's although ``specimen_given`` was given is so because its particles are others
    than that specimen's (:func:`resolve_settings` names only a file of its particles): the
    note said "no specimen named ... name another with specimen=FILE" beside the one named,
    so ``"specimen_given"`` and ``"specimen_given_material"`` say which it was and its
    particles, ``"file_material"`` the file's (where it states a load case).
    """
    from .specimen import PAPER_SPECIMEN_NAME

    found: dict[str, str] = {}
    said = next((part for part in stated.origin.split("; ") if part.startswith("material:")),
                "") if stated is not None else ""
    if said == _DEFAULT_ORIGIN:
        found["material"] = stated.material
    elif said == "material: specimen" and specimen_given is not None and specimen:
        from .specimen import measured_specimen_name

        if specimen not in (specimen_given.name, measured_specimen_name(specimen_given)):
            found["material"] = stated.material
            found["material_from"] = specimen_given.name
    if not specimen:
        found[SPECIMEN_COLUMN] = PAPER_SPECIMEN_NAME
        if specimen_given is not None and (
                stated is None or stated.material != specimen_given.particles.material):
            found["specimen_given"] = specimen_given.name
            found["specimen_given_material"] = specimen_given.particles.material
            if stated is not None:
                found["file_material"] = stated.material
    return found


def assumption_notes(name: str, assumptions: Mapping[str, str], *, files: int = 1) -> list[str]:
    """:func:`assumed` in words, one line each, naming the file ``name`` and how to state the
    value (library keywords: the CLI names its flags, :func:`pidcore.cli._vocabulary.cli_words`).
    ``files``: how many files ``name`` stands for (:func:`files_assumption_notes`), whose
    sentence then speaks of them in the plural."""
    notes = []
    it, its, names = ("it", "its", "names") if files == 1 else ("them", "their", "name")
    if "material_from" in assumptions:
        notes.append(f"{name}: particle material not stated, {assumptions['material']} assumed "
                     f"(those of specimen {assumptions['material_from']!r}, specimen=, although "
                     f"the file{'' if files == 1 else 's'} {names} another specimen); if "
                     f"{its} particles are others, state them with material=NAME or a "
                     "sidecar's material column")
    elif "material" in assumptions:
        notes.append(f"{name}: particle material not stated, {assumptions['material']} assumed "
                     "(the paper's coupon's particles); if they are others, state them with "
                     "material=NAME, a sidecar's material column or specimen=FILE")
    if "specimen_given" in assumptions:
        given, particles = assumptions["specimen_given"], assumptions["specimen_given_material"]
        mine = assumptions.get("file_material")
        files_ = "the file's" if files == 1 else "the files'"
        notes.append(f"{name}: specimen {given!r} (specimen=) is of other particles "
                     f"({particles}) than {files_}" + (f" ({mine})" if mine else "")
                     + f", so the paper's coupon ({assumptions[SPECIMEN_COLUMN]})"
                     + (f" with {mine} particles" if mine else "") + " is assumed: reports "
                     f"and calibrations compare {it} with that coupon's DEM runs; name a "
                     f"specimen of {mine or its} particles with specimen=FILE or a sidecar's "
                     "specimen column")
    elif SPECIMEN_COLUMN in assumptions:
        notes.append(f"{name}: no specimen named, the paper's coupon "
                     f"({assumptions[SPECIMEN_COLUMN]}) assumed: reports and calibrations "
                     f"compare {it} with that coupon's DEM runs; name another with "
                     "specimen=FILE or a sidecar's specimen column")
    return notes


#: What :func:`assumed` says of a ``specimen_given`` that a file is not of.
_SPECIMEN_GIVEN_KEYS = ("specimen_given", "specimen_given_material", "file_material")


def _listed(names: Sequence[str]) -> str:
    """The first five ``names`` and how many more: a note of forty files stays one line."""
    return ", ".join(names[:5]) + (f" and {len(names) - 5} more" if len(names) > 5 else "")


def files_assumption_notes(found: Sequence[tuple[str, Mapping[str, str]]]) -> list[str]:
    """:func:`assumption_notes` of several files (``(name, assumed(...))`` each), one note per
    assumption that names the files it holds for and counts them (``"a.csv, b.csv (2 files):
    no specimen named, ..."``): the README's report of five exports said the same sentence
    five times. A note of one file reads as :func:`assumption_notes` of it."""
    grouped: dict[tuple[str, ...], list[str]] = {}
    for name, assumptions in found:
        if "material" in assumptions:
            grouped.setdefault(("material", assumptions["material"],
                                assumptions.get("material_from", "")), []).append(name)
        if SPECIMEN_COLUMN in assumptions:
            grouped.setdefault((SPECIMEN_COLUMN, assumptions[SPECIMEN_COLUMN],
                                *(assumptions.get(k, "") for k in _SPECIMEN_GIVEN_KEYS)),
                               []).append(name)
    notes = []
    for key, names in grouped.items():
        if key[0] == "material":
            one = {"material": key[1], **({"material_from": key[2]} if key[2] else {})}
        else:
            one = {SPECIMEN_COLUMN: key[1],
                   **{k: v for k, v in zip(_SPECIMEN_GIVEN_KEYS, key[2:], strict=True) if v}}
        subject = names[0] if len(names) == 1 else f"{_listed(names)} ({len(names)} files)"
        notes.extend(assumption_notes(subject, one, files=len(names)))
    return notes


def stored_assumption_notes(analyses: pd.DataFrame) -> list[str]:
    """:func:`assumed` of stored analysis records (a store's listing: ``source``,
    ``material``, ``load_case_origin``, ``specimen``), one note per assumption naming the
    records' files: a report of a store said nothing of the acrylic and the coupon that
    ``pidcore analyze`` had assumed for them."""
    from collections import defaultdict

    by_assumption: dict[tuple[str, str], list[str]] = defaultdict(list)
    for _, record in analyses.iterrows():
        origin, material = record.get("load_case_origin"), record.get("material")
        stated = (StatedLoadCase(math.nan, material, "", origin)
                  if isinstance(origin, str) and isinstance(material, str) else None)
        specimen = record.get("specimen")
        found = assumed(stated, specimen if isinstance(specimen, str) else "")
        name = display_path(Path(str(record.get("source", "") or record.get("key", ""))).name)
        for what in ("material", SPECIMEN_COLUMN):
            if what in found:
                by_assumption[(what, found[what])].append(name)
    notes = []
    for (what, value), names in by_assumption.items():
        shown = _listed(names)
        if what == "material":
            notes.append(f"{len(names)} stored measurement(s) state no particle material, "
                         f"{value} assumed (the paper's coupon's particles): {shown}")
        else:
            notes.append(f"{len(names)} stored measurement(s) name no specimen, the paper's "
                         f"coupon ({value}) assumed: {shown}")
    return notes
