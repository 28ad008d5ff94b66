"""Uploads of the app, kept free of Streamlit: reading, per-file settings, analysis, saving.

Uploaded bytes are only ever *parsed* by :mod:`pidcore.io` readers (text, UFF, HDF5 datasets,
MAT arrays) or read as a CSV table; nothing uploaded is unpickled or evaluated.

Every uploaded measurement has its own row of settings (:data:`FILE_TABLE_COLUMNS`): load case,
specimen, corrections and channel mapping, because files from different set-ups need different
corrections. A CSV whose header holds ``file`` and any other settings column is taken as a
settings table (under any name, uploaded at any time) and fills the rows of the files it names.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import tempfile
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, replace
from pathlib import Path, PurePosixPath
from typing import TYPE_CHECKING

import pandas as pd

from .. import defaults
from ..compare.loadcase import (
    AUTO_CHANNEL,
    FREE_TEXT_COLUMNS,
    NO_CHANNEL,  # noqa: F401 - the pages read it from here
    SETTINGS_COLUMN_LABELS,
)
from ..compare.settings_columns import setting_phrase
from ..constants import PARTICLE_MATERIALS
from ..errors import InputFileError, ParameterError, PidcoreError, SettingsTableError
from ..units import display_value_with_error
from .vocabulary import page_terms

if TYPE_CHECKING:
    from ..compare import LoadCase
    from ..measure import AnalysisOptions, AnalyzedRecord
    from ..records import Measurement
    from ..specimen import NamedSpecimen, Specimen

# NO_CHANNEL ("(none)": acceleration is optional) and AUTO_CHANNEL ("(auto)": the channel the
# readers detect) are the sidecar's words too (pidcore.compare.loadcase): one definition.

#: Per-file settings: column shown in the app -> column of the CSV template / uploaded table
#: (:data:`pidcore.compare.loadcase.SETTINGS_COLUMNS`, the sidecar's columns of the CLI, which
#: reads these labels too: one table for both).
FILE_TABLE_COLUMNS: dict[str, str] = SETTINGS_COLUMN_LABELS
_NUMERIC = ("fill [%]", "vibrometer delay [µs]", "mass below gauge [g]",
            "baseline loss factor [-]", "structure mass [g]")
#: Suffix of the specimen files that the DEM and Calibrate tabs read.
SPECIMEN_SUFFIX = ".toml"
#: The settings columns that the page edits as text (:func:`editor_settings`): the grid's
#: number editor drops what it does not read as a digit without a word ("1,5" -> 15,
#: "1e-3" -> -13, "2e1" -> 21); as text, the cell reaches the checks of a settings table
#: (:func:`fill_of`, :func:`options_of`) as typed, and a value they cannot read is refused.
TEXT_EDITED_NUMBERS = _NUMERIC


# --- reading ----------------------------------------------------------------------------------

def content_sha256(data: bytes) -> str:
    """SHA-256 hex digest of an upload (the cache and store key of its content)."""
    return hashlib.sha256(data).hexdigest()


def check_upload_size(name: str, n_bytes: int, *, limit_mb: float | None = None) -> None:
    """Raise :class:`ParameterError` if an upload is empty or larger than ``limit_mb`` MB.

    ``limit_mb`` defaults to :data:`pidcore.defaults.APP_MAX_UPLOAD_MB`; Streamlit enforces the
    same limit in the browser, this is the server-side guard.
    """
    limit_mb = defaults.APP_MAX_UPLOAD_MB if limit_mb is None else limit_mb
    if n_bytes > limit_mb * 1024 * 1024:
        raise ParameterError(f"{name}: {n_bytes / 1024 / 1024:.1f} MB is larger than the upload "
                             f"limit of {limit_mb:g} MB")
    if n_bytes == 0:
        from ..io import EMPTY_MEASUREMENT_FILE

        # in the words of `pidcore analyze` on the same file (the app said "the file is empty")
        raise ParameterError(f"{name}: {EMPTY_MEASUREMENT_FILE}")


def safe_file_name(name: str) -> str:
    """A file name safe to create in a temporary folder (no folders, no odd characters).

    >>> safe_file_name("../../etc/pass wd.csv")
    'pass_wd.csv'
    """
    base = re.split(r"[\\/]", name)[-1]
    base = re.sub(r"[^A-Za-z0-9._+-]", "_", base).lstrip(".")
    return base[:200] or "upload"


def read_upload(name: str, data: bytes, *, sample_rate_hz: float | None = None,
                time_unit: str | None = None) -> Measurement:
    """Parse uploaded bytes with :func:`pidcore.io.read_measurement` (via a private temporary
    file); the measurement's ``source`` is the uploaded name. ``time_unit``: the unit of a time
    base the file does not state readably (``pidcore analyze --time-unit``)."""
    from ..io import read_measurement

    check_upload_size(name, len(data))
    if is_specimen_file(name):
        # the Analyse tab takes these apart before reading (analysis_specimen); read as a
        # CSV, it was refused as "no rows of numbers in its 38 lines"
        # the file, not a parameter, is wrong here (errors.InputFileError: holds nothing usable)
        raise InputFileError(f"{name}: a specimen file (TOML), not a shaker-test export; "
                             f"the Analyse tab takes it with the exports as "
                             f"their specimen, the DEM and Calibrate tabs as 'or a specimen "
                             f"file (TOML)'")
    with tempfile.TemporaryDirectory(prefix="pidcore_upload_") as folder:
        path = Path(folder) / safe_file_name(name)
        path.write_bytes(data)
        measurement = read_measurement(path, sample_rate_hz=sample_rate_hz,
                                       time_unit=time_unit)
    # the readers' notes name the file they read: the private copy, whose folder is gone
    # once read ("/tmp/pidcore_upload_x1/a.txt: column 'Time' is the time of 'Velocity'",
    # shown on the card and saved with the record)
    notes = measurement.metadata.get("reader_notes")
    if notes:
        measurement = replace(measurement, metadata={
            **measurement.metadata,
            "reader_notes": [str(n).replace(str(path), name) for n in notes]})
    return replace(measurement, source=name, sha256=measurement.sha256 or content_sha256(data))


@dataclass(frozen=True)
class ChannelChoice:
    """Channels of one upload and the roles detected for them (``None`` = not found)."""

    names: tuple[str, ...]
    quantities: tuple[str, ...]
    force: str | None
    velocity: str | None
    acceleration: str | None


def detect_channels(measurement: Measurement) -> ChannelChoice:
    """Channel names and the roles :func:`pidcore.io.assign_roles` picks automatically
    (``None`` everywhere when detection fails; the user then maps them)."""
    from ..io import assign_roles

    force = velocity = acceleration = None
    try:
        roles = assign_roles(measurement)
        force = roles.force.name if roles.force is not None else None
        velocity = roles.velocity.name if roles.velocity is not None else None
        acceleration = roles.acceleration.name if roles.acceleration is not None else None
    except PidcoreError:
        pass
    return ChannelChoice(tuple(c.name for c in measurement.channels),
                         tuple(c.quantity for c in measurement.channels),
                         force, velocity, acceleration)


@dataclass(frozen=True)
class ParsedUpload:
    """One upload after reading: its measurement and detected channels, or the read error."""

    name: str
    sha256: str
    measurement: Measurement | None = None
    channels: ChannelChoice | None = None
    error: str | None = None


@dataclass(frozen=True)
class UploadOutcome:
    """Analysis of one uploaded file: a record, or the one-line error that stopped it."""

    name: str
    sha256: str
    record: AnalyzedRecord | None = None
    error: str | None = None

    @property
    def ok(self) -> bool:
        """Whether the analysis succeeded."""
        return self.record is not None


def app_words(text: str, *, names: Iterable[str] = ()) -> str:
    """A library message or note as the app says it: the parameters it names by their
    keywords (:func:`pidcore.app.vocabulary.page_terms`) as the page's fields and columns,
    and the hints whose advice differs on the page said as the page's: the app has no unit
    setting (it takes each channel's unit from its file), no choice of a store's record, and
    sets the inverted channels and the mass below gauge in the table; ``names`` (the
    upload's) stay as written."""
    text = text.replace(
        "check both units (velocity_unit, acceleration_unit)",
        "check both units in the export (the app takes each channel's unit from its file; "
        "`pidcore analyze --velocity-unit/--acceleration-unit` override them)")
    text = re.sub(r"give it with (force|velocity|acceleration)_unit=UNIT",
                  r"state it in the export (the app takes units from the file; "
                  r"`pidcore analyze --\1-unit UNIT` gives it)", text)
    text = text.replace("pass invert=NAME for the inverted channel",
                        "name the inverted channel in the 'inverted channels' column")
    # the channel hints that name a channel or an option the page sets in a column (they
    # said "confirm it with acceleration='Ref'", "mass_below_gauge_kg needs ...",
    # "invert='X': no such channel")
    text = re.sub(r"confirm it with (force|velocity|acceleration)=('[^']*')",
                  r"confirm it in the '\1 channel' column (\2)", text)
    text = text.replace("mass_below_gauge_kg needs", "the mass below gauge needs")
    text = text.replace("or remove the option", "or set 'mass below gauge [g]' to 0")
    text = re.sub(r"invert=('[^']*'): no such channel",
                  r"'inverted channels' \1: no such channel", text)
    text = re.sub(r" inverted \(invert='[^']*'\)", " inverted ('inverted channels' column)",
                  text)
    # the page has the time unit as a field (it said "give it with `pidcore analyze
    # --time-unit`", an option the page user has not got)
    text = text.replace("give it with time_unit=UNIT",
                        "give it as 'time base unit' under 'Options for every file'")
    # the reader's hint is a keyword of read_measurement; the page has no choice of record
    text = text.replace("choose one with key=NAME", "upload one measurement per file, or "
                                                    "analyse one with `pidcore analyze FILE "
                                                    "--key NAME`")
    # "structure_mass_kg 280 kg" is said in the field's g by page_terms
    text = text.replace("structure_mass_kg in kg", "'structure mass [g]' in g")
    # the fields are in g and µs: the hints gave kg and s ("structure mass 0.005 kg given"
    # for 5 typed in g; "expected a vibrometer delay in s (e.g. 2e-4)", which the µs field
    # then refuses as implausibly small)
    text = re.sub(r"(?<![\w'])structure mass ([-+]?[0-9.]+(?:e[-+]?[0-9]+)?) kg given",
                  lambda m: f"'structure mass [g]' {float(m[1]) * 1e3:g} g given", text)
    text = text.replace("expected a vibrometer delay in s (e.g. 2e-4)",
                        "expected a vibrometer delay in µs (e.g. 200)")
    return page_terms(text, names=names)


def error_message(name: str, exc: BaseException) -> str:
    """One-line message for a failed upload; library errors already name the file."""
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    text = app_words(text, names=[name])
    text = re.sub(r"\S*pidcore_upload_[^/\\\s]*[/\\][^:\s]*", name, text)
    if isinstance(exc, PidcoreError):
        return text if name in text else f"{name}: {text}"
    return f"{name}: could not be read ({type(exc).__name__}: {text})"


#: Exceptions that mean "this upload is bad": readers are the boundary to arbitrary bytes and
#: the parsers they use (pyuff, h5py, scipy.io, pandas) raise these on malformed input.
_BAD_INPUT_ERRORS = (PidcoreError, ValueError, OSError, KeyError, IndexError, TypeError,
                     UnicodeError, EOFError, OverflowError, AttributeError)


#: The Analyse page's field of the time unit (``time_unit``, ``pidcore analyze --time-unit``),
#: one of its options for every file.
TIME_UNIT_FIELD = "time base unit"


#: The settings table's help of its *time base unit* column. The cell is read as
#: ``pidcore analyze --time-unit`` reads it: it also overrides a unit the file's time column
#: states (noted under the file), which the help left unsaid ("where its time column states
#: none or one pidcore does not read"), so an 'ms' typed beside a time in s read as a guess.
TIME_UNIT_COLUMN_HELP = ("unit of this file's time base (s, ms, us); it overrides the unit its "
                         "time column states (a note says so) and is needed where that states "
                         "none or one pidcore does not read; empty: the one for every file")


def page_time_unit(typed: str) -> str | None:
    """The time unit typed in the page's :data:`TIME_UNIT_FIELD` (blank: None, each file's
    own), refused naming the field where it is not a unit of time: read with it, every file
    would be refused naming the keyword, or an HDF5 file analysed with it unsaid."""
    from ..units import why_not_a_time_unit

    typed = typed.strip()
    if not typed:
        return None
    why = why_not_a_time_unit(typed)
    if why is not None:
        raise ParameterError(f"{TIME_UNIT_FIELD}: {typed!r} is not a unit of time{why}; "
                             "expected s, ms or us")
    return typed


def parse_upload(name: str, data: bytes, *, sample_rate_hz: float | None = None,
                 time_unit: str | None = None) -> ParsedUpload:
    """Read one upload (``time_unit``: :func:`read_upload`) and detect its channel roles;
    never raises for bad data."""
    sha = content_sha256(data)
    try:
        measurement = read_upload(name, data, sample_rate_hz=sample_rate_hz,
                                  time_unit=time_unit)
        return ParsedUpload(name, sha, measurement, detect_channels(measurement))
    except _BAD_INPUT_ERRORS as exc:
        return ParsedUpload(name, sha, error=error_message(name, exc))


def analyze_parsed(parsed: ParsedUpload, options: AnalysisOptions) -> UploadOutcome:
    """Analyse a parsed upload with ``options``; any failure becomes the outcome's error."""
    from ..measure import analyze_measurement

    if parsed.measurement is None:
        return UploadOutcome(parsed.name, parsed.sha256, error=parsed.error)
    try:
        record = analyze_measurement(parsed.measurement, options)
    except _BAD_INPUT_ERRORS as exc:
        return UploadOutcome(parsed.name, parsed.sha256, error=error_message(parsed.name, exc))
    # the unit-slip note suggested `analyze` options the page does not have
    record = replace(record, notes=tuple(app_words(n, names=[parsed.name])
                                               for n in record.notes))
    return UploadOutcome(parsed.name, parsed.sha256, record=record)


def analyze_upload(name: str, data: bytes, options: AnalysisOptions) -> UploadOutcome:
    """Read and analyse one upload; never raises for bad user data."""
    return analyze_parsed(parse_upload(name, data, sample_rate_hz=options.sample_rate_hz,
                                       time_unit=options.time_unit), options)


def channels_caption(names: Sequence[str], outcome: UploadOutcome,
                     options: AnalysisOptions) -> str:
    """The line above a file's result: its channels, those the analysis used and the delay
    removed. A refused analysis used none: it read "used: force ?, velocity ?"."""
    used = ""
    if outcome.ok:
        roles = outcome.record.channels_used
        used = " · used: " + ", ".join(f"{role} {roles[role]}" for role in
                                       ("force", "velocity", "acceleration") if role in roles)
    return (f"channels: {', '.join(names)}{used} · "
            f"{setting_phrase('velocity_delay_s', options.velocity_delay_s)}")


def options_to_json(options: AnalysisOptions) -> str:
    """Canonical JSON of analysis options (a stable, hashable cache key)."""
    return json.dumps(asdict(options), sort_keys=True)


def options_from_json(text: str) -> AnalysisOptions:
    """Inverse of :func:`options_to_json`."""
    from ..measure import AnalysisOptions

    return AnalysisOptions(**json.loads(text))


def distinct_uploads(uploads: Sequence[tuple[str, str]]) -> tuple[list[int], list[str]]:
    """Indices of the uploads to analyse (``(name, sha256)`` pairs) and a note per one left out.

    Settings are kept per file name, so one name is one file: the same file selected again is
    analysed once (it made the settings table one row shorter than the uploads: a traceback),
    and of two different files under one name the last is used, and the note says so.
    """
    last: dict[str, int] = {}
    for i, (name, _) in enumerate(uploads):
        last[name] = i
    notes = []
    for i, (name, sha) in enumerate(uploads):
        j = last[name]
        if j != i and uploads[j][1] != sha:
            notes.append(f"{name}: uploaded twice with different contents; the last upload is "
                         "used (give the files different names to analyse both)")
    return sorted(set(last.values())), notes


def identical_uploads(uploads: Sequence[tuple[str, str]]) -> list[str]:
    """A note per upload whose bytes equal an earlier one's (``(name, sha256)`` pairs): the
    store keeps one record of them and Compare counts them once."""
    first: dict[str, str] = {}
    notes = []
    for name, sha in uploads:
        if sha in first:
            notes.append(f"{name} has the same contents as {first[sha]}: one measurement, "
                         "saved as one record (under the name saved last) and counted once")
        else:
            first[sha] = name
    return notes


# --- per-file settings --------------------------------------------------------------------------

def is_settings_table(data: bytes) -> bool:
    """Whether uploaded bytes are a per-file settings table (a load-case table is one): a CSV
    whose header names ``file`` and at least one other column of :data:`FILE_TABLE_COLUMNS`
    (its header read as ``pidcore analyze`` reads a sidecar's: ``,``/``;``/tab, any
    encoding the reader knows, ``#`` comment lines skipped)."""
    from ..tables import header_cells

    names = {c.lower() for c in header_cells(data)}
    known = set(FILE_TABLE_COLUMNS.values()) | {k.lower() for k in FILE_TABLE_COLUMNS}
    # A column that is neither known nor free text (a misspelt ``velocity_delay_ms``) still
    # makes a table: read as one, it is refused naming the column; read as a measurement it
    # was refused as "no data rows" and its files were analysed without their settings.
    other = names - {"file"} - set(FREE_TEXT_COLUMNS)
    return "file" in names and (len(names & known) >= 2 or bool(other - known))


def measurement_materials(extra: Iterable[object] = ()) -> tuple[str, ...]:
    """Particle materials a measurement may state: the table's, then the ``extra`` names
    (the materials of the store's DEM runs, i.e. of the user's own specimens) that are
    valid material names, once each."""
    from ..compare.loadcase import normalize_material

    names = list(PARTICLE_MATERIALS)
    for value in extra:
        try:
            name = normalize_material(str(value), "material", None)
        except PidcoreError:
            continue  # not a material name (e.g. an empty cell of an old store)
        if name not in names:
            names.append(name)
    return (*names[:len(PARTICLE_MATERIALS)], *sorted(names[len(PARTICLE_MATERIALS):]))


def specimen_files(folders: Iterable[str | os.PathLike]) -> list[Path]:
    """The specimen files (``*.toml``) in ``folders``, folder by folder, each sorted; a folder
    that does not exist has none."""
    return [path for folder in map(Path, folders) if folder.is_dir()
            for path in sorted(folder.glob("*.toml"))]


def specimen_materials(folders: Iterable[str | os.PathLike]) -> list[str]:
    """Particle materials of the specimen files (``*.toml``) in ``folders`` (the DEM page's
    specimen folders): a measurement of an own specimen may state its material before any DEM
    run of it is saved. Unreadable files are skipped (the DEM page reports them)."""
    from ..specimen import load_specimen

    found = []
    for path in specimen_files(folders):
        try:
            found.append(load_specimen(path).particles.material)
        except (PidcoreError, OSError, ValueError):
            continue
    return found


def known_specimens(folders: Iterable[str | os.PathLike],
                    uploaded: Iterable[tuple[str, bytes]] = ()) -> list:
    """The specimen files a page knows (:class:`pidcore.specimen.Specimen`), those the DEM
    tab offers: the paper's coupon, the ``*.toml`` files in ``folders`` and the uploaded ones
    (``(name, bytes)``, parsed, never executed). Unreadable files are skipped (the DEM page
    reports them)."""
    from ..specimen import Specimen, load_specimen, paper_specimen

    found = [paper_specimen()]
    for path in specimen_files(folders):
        try:
            found.append(load_specimen(path))
        except (PidcoreError, OSError, ValueError):
            continue
    for name, data in uploaded:
        try:
            found.append(Specimen.from_bytes(data, source=name))
        except (PidcoreError, ValueError):
            continue
    return found


def is_specimen_file(name: str) -> bool:
    """Whether the upload ``name`` is a specimen file (``*.toml``, any case), which the
    Analyse tab takes as the files' specimen rather than as an export."""
    return PurePosixPath(safe_file_name(name)).suffix.lower() == SPECIMEN_SUFFIX


def analysis_specimen(files: Sequence[tuple[str, bytes]]) -> Specimen | None:
    """The specimen file uploaded with the exports on the Analyse tab (``(name, bytes)`` of
    the :func:`is_specimen_file` uploads; None for none): the ``--specimen FILE`` of ``pidcore
    analyze``, checked as ``pidcore specimen check`` checks it (parsed, never executed).

    Raises
    ------
    ParameterError
        One line: the file is not a specimen file (naming it and the key), or more than one
        was uploaded (the CLI takes one; which one a file was tested on is not guessed).
    """
    from ..specimen import Specimen

    if len(files) > 1:
        raise ParameterError(f"{', '.join(name for name, _ in files)}: one specimen file at a "
                             "time, as `pidcore analyze --specimen FILE` takes one; remove all "
                             "but the specimen these files were tested on")
    if not files:
        return None
    name, data = files[0]
    return Specimen.from_bytes(data, source=name)


def file_specimen(typed: str, material: str, known: Sequence[Specimen], *,
                  given: Specimen | None = None, every_file: str = "") -> NamedSpecimen:
    """The specimen a file's record is saved with (:class:`pidcore.specimen.NamedSpecimen`:
    name, sha256 and a note): the one its settings row names (``typed``, among the ``known``
    files: :func:`pidcore.specimen.resolve_specimen_name`); for a row naming none, the
    specimen file uploaded with the exports (``given``) where the file's ``material`` is that
    specimen's particles, as ``pidcore analyze --specimen FILE`` saves it (a file of other
    particles is saved without a specimen, and the note says why), else the page's choice
    for every file (``every_file``)."""
    from ..specimen import (
        NamedSpecimen,
        measured_specimen_name,
        measured_specimen_sha256,
        resolve_specimen_name,
    )

    if typed.strip():
        if given is not None and typed.strip() == given.name:
            # the file uploaded here is the one its row names, as the CLI's sidecar naming
            # the --specimen's name: not another known file of that name
            return NamedSpecimen(measured_specimen_name(given), measured_specimen_sha256(given))
        return resolve_specimen_name(typed, known)
    if given is None:
        return resolve_specimen_name(every_file, known)
    if material == given.particles.material:
        return NamedSpecimen(measured_specimen_name(given), measured_specimen_sha256(given))
    return NamedSpecimen("", "", f"specimen {given.name} ({given.source}): its particles are "
                         f"{given.particles.material}, not {material}; the files of {material} "
                         "particles are saved without a specimen (the paper's coupon), as "
                         "`pidcore analyze --specimen` saves them; name their specimen in the "
                         "settings table")


def tested_specimen(named: NamedSpecimen, candidates: Iterable[Specimen | None]
                    ) -> Specimen | None:
    """The specimen file among ``candidates`` (the one uploaded with the exports, the known
    ones) whose hash is the one a record is saved with (``named``); None where it names
    none or only a name."""
    from ..specimen import measured_specimen_sha256

    return next((s for s in candidates if s is not None and named.sha256
                 and measured_specimen_sha256(s) == named.sha256), None)


def check_specimen_fill(name: str, fill_percent: float | None, material: str,
                        named: NamedSpecimen, tested: Specimen | None) -> None:
    """Refuse the fill of the file ``name`` where it rounds to no particle of the cell it
    was tested in, as ``pidcore analyze`` refuses it before any analysis: ``tested``'s (the
    specimen file of the record's specimen ``named``, :func:`tested_specimen`), the paper's
    coupon's where ``named`` names no specimen. 0.5 typed for 50 % was shown as a load case
    "0.5 %" and refused only at Save (at all for a specimen file: saved as a test without
    particles, a load case no DEM run can match). A specimen known by its name only, whose
    cell is not at hand, and no fill (None) are left alone.

    Raises
    ------
    LoadCaseError
        Naming the file and the column, with the cell's capacity and the fill expected.
    """
    from ..dem.simulate import particles_of_stated_fill
    from ..loadcase import LoadCaseError

    if fill_percent is None or (named.name and tested is None):
        return
    try:
        particles_of_stated_fill(fill_percent, material, specimen=tested, what="fill",
                                 typed=True)
    except PidcoreError as exc:
        cell = (f" (the cell of specimen {tested.name}, {tested.source})"
                if tested is not None else "")
        raise LoadCaseError(f"{name}, column fill [%]: {exc}{cell}") from None


def restate_default_material(previous: pd.DataFrame | None, before: Mapping[str, str],
                             now: Mapping[str, str],
                             given: Mapping[str, Iterable[str]]) -> pd.DataFrame | None:
    """The settings rows ``previous`` with the material of each file that still holds its
    default of ``before`` (file -> material nothing stated but the specimen file, or none)
    set to the one of ``now``: a specimen file uploaded (or removed) on the Analyse tab changes
    the material of a file stating none, as ``--specimen`` does, and the rows kept the
    former default. A material the user chose since, or that a settings table gives
    (``given``: file -> its columns given, :func:`columns_given`), stays."""
    if previous is None or previous.empty:
        return previous
    out = previous.copy()
    for i, name in zip(out.index, out["file"], strict=True):
        old, new = before.get(name), now.get(name)
        if (old is not None and new is not None and old != new
                and out.at[i, "material"] == old and "material" not in set(given.get(name, ()))):
            out.at[i, "material"] = new
    return out


#: Appended to an unknown material's error: how an own material becomes one to state.
MATERIAL_HINT = ("an own material can be stated once a specimen file of it is in the "
                 "specimen folders ("
                 + ", ".join(f"{folder.as_posix()}/" for folder in defaults.APP_SPECIMEN_FOLDERS)
                 + ") or a DEM run of it is saved")


def read_settings_table(name: str, data: bytes,
                        materials: tuple[str, ...] = PARTICLE_MATERIALS) -> pd.DataFrame:
    """An uploaded settings table as rows of :data:`FILE_TABLE_COLUMNS` (app column names).

    Columns may be given by their template or app names; missing ones stay empty (NaN or "")
    and leave a file's other settings alone (``attrs["given"]`` lists the columns given).
    Raises :class:`ParameterError` naming the table, row and column for a value that is not a
    number, material (one of ``materials``) or direction.
    """
    from ..compare.loadcase import (
        NUMERIC_HEADERS,
        normalize_direction,
        normalize_material,
        settings_table,
    )
    from ..file_settings import analysis_overrides
    from ..loadcase import check_fill
    from ..tables import line_where, read_text_table

    try:
        raw = read_text_table(data, name, numeric=NUMERIC_HEADERS)
    except PidcoreError as exc:
        raise ParameterError(str(exc)) from None
    by_name = {k.lower(): v for k, v in FILE_TABLE_COLUMNS.items()}
    given = {by_name.get(c, c) for c in raw.columns}
    # the checks of `pidcore analyze` (one table for both): known columns, a file name per
    # row, each file once; free-text remarks are accepted and ignored
    raw = settings_table(raw.rename(columns=by_name), name)
    labels = {v: k for k, v in FILE_TABLE_COLUMNS.items()}
    raw = raw.rename(columns=labels).loc[:, list(FILE_TABLE_COLUMNS)]
    out = raw.reset_index(drop=True)
    for column in _NUMERIC:
        values = []
        for line, file, text in zip(raw.index, raw["file"], raw[column], strict=True):
            where = f"{line_where(name, int(line))} ({file})"
            if text == "":
                values.append(math.nan)
            elif column == "fill [%]":
                # the CLI's check of a sidecar's fill, naming the line and file as it does: a
                # fill of 150 % was accepted and each file's card said "no valid load case"
                values.append(check_fill(text, where))
            else:
                # the CLI's check of a sidecar's setting (file_settings.analysis_overrides),
                # so a table is refused with the words `pidcore analyze --sidecar` uses; a
                # delay typed in s (5e-5) was accepted here and refused only on the file's card
                analysis_overrides({FILE_TABLE_COLUMNS[column]: text}, where)
                values.append(float(text))
        out[column] = values
    try:
        out["material"] = [normalize_material(v, f"{name}: material", materials) if v else ""
                           for v in out["material"]]
    except PidcoreError as exc:
        raise ParameterError(f"{exc} ({MATERIAL_HINT})") from None
    out["direction"] = [normalize_direction(v, f"{name}: direction") if v else ""
                        for v in out["direction"]]
    out.attrs["lines"] = [int(line) for line in raw.index]  # each row's line in the file
    out.attrs["given"] = [c for c in FILE_TABLE_COLUMNS
                          if FILE_TABLE_COLUMNS[c] in given and c != "file"]
    return out


def _file_column(files: Sequence[str], lines: Sequence[int] | None = None) -> pd.DataFrame:
    """A settings table's ``file`` cells as :func:`pidcore.compare.loadcase.find_row` reads a
    sidecar: indexed by each row's line in the file (a table built otherwise counts from the
    line after its header)."""
    files = [str(f) for f in files]
    lines = list(lines) if lines else list(range(2, 2 + len(files)))
    return pd.DataFrame({"file": files}, index=pd.Index(lines, name="line"))


def _upload_path(name: str) -> PurePosixPath:
    """An upload as a path for :func:`~pidcore.compare.loadcase.find_row`: it has no folder,
    so it is anchored at the root (a relative name would take the app's working folder for
    its folders, and match a cell naming that folder)."""
    return PurePosixPath("/", *[p for p in re.split(r"[\\/]", name) if p not in ("", ".", "..")])


def table_row(table: pd.DataFrame, name: str, shown: str) -> int | None:
    """Position of the row of the upload ``name`` in an app settings ``table`` (None: no
    row), matched as ``pidcore analyze`` matches a sidecar's rows: one function,
    :func:`pidcore.compare.loadcase.find_row` (base name, else a case-folded match).

    Raises
    ------
    LoadCaseError
        Several rows match ``name`` equally (names differing only by case, or one name under
        two folders), naming the table ``shown`` and the rows' lines, as the CLI does.
    """
    from ..compare.loadcase import find_row

    return find_row(_file_column(table["file"], table.attrs.get("lines")), _upload_path(name),
                    shown)


def check_table_rows(name: str, table: pd.DataFrame, uploaded: Sequence[str]) -> None:
    """Refuse the settings table ``name`` if a row of one of the ``uploaded`` files is
    ambiguous (:func:`table_row`): the CLI refuses it, and the app took the first match."""
    for upload in uploaded:
        table_row(table, upload, name)


@dataclass(frozen=True)
class RefusedTable:
    """An uploaded settings table that was refused: its ``error`` and the ``files`` its
    ``file`` column names (``None``: the table cannot be read at all, so it may name any)."""

    name: str
    error: str
    files: tuple[str, ...] | None

    def refuses(self, name: str) -> bool:
        """Whether this table holds back the upload ``name``: it names it, or cannot say."""
        from ..loadcase import LoadCaseError

        if self.files is None:
            return True
        try:
            return table_row(pd.DataFrame({"file": list(self.files)}), name, self.name) is not None
        except LoadCaseError:
            return True  # several of its rows name it


def refused_table(name: str, data: bytes, error: str) -> RefusedTable:
    """The refused settings table ``name`` with the file names it holds back: its ``file``
    column read as text by the one table reader (whatever else in the table is wrong), or
    ``None`` where the table cannot be read as one or has no ``file`` column (then it cannot
    say which files it is for, and every file would be analysed without settings meant for
    it)."""
    from ..tables import read_text_table

    try:
        raw = read_text_table(data, name)
    except PidcoreError:
        return RefusedTable(name, error, None)
    if "file" not in raw.columns:
        return RefusedTable(name, error, None)
    files = tuple(f for f in raw["file"] if f)
    return RefusedTable(name, error, files)


def refusal_of(name: str, refused: Sequence[RefusedTable]) -> str:
    """Why the upload ``name`` is not analysed: the refused settings tables that hold it back
    (:meth:`RefusedTable.refuses`), as one line; "" where none does. Analysing it without the
    settings meant for it (e.g. its vibrometer delay) would show and save a wrong SDC."""
    tables = [t.name for t in refused if t.refuses(name)]
    if not tables:
        return ""
    if len(tables) == 1:
        return (f"{name}: not analysed: the settings table {tables[0]} that gives its "
                "settings was refused (see the error above); fix the table and upload it "
                "again, or remove it")
    return (f"{name}: not analysed: the settings tables {', '.join(tables)} that give its "
            "settings were refused (see the errors above); fix the tables and upload them "
            "again, or remove them")


def refused_tables_text(refused: Sequence[RefusedTable]) -> str:
    """Why nothing is saved while settings tables are refused, as one line."""
    names = ", ".join(t.name for t in refused)
    if len(refused) == 1:
        return f"the settings table {names} is refused: fix it and upload it again, or remove it"
    return (f"the settings tables {names} are refused: fix them and upload them again, or "
            "remove them")


def table_match_note(name: str, table: pd.DataFrame, uploaded: Sequence[str]) -> tuple[str, str]:
    """``(info, warning)`` on an accepted settings table ``name``: how many of its rows match
    the ``uploaded`` measurement files (and the columns it gives), and the rows (by line of
    the CSV) that match none, e.g. a misspelt file name; the warning is "" when every row
    matches."""
    given = ", ".join(table.attrs.get("given", []))
    files = [str(f) for f in table["file"]]
    found = {_row_or_none(table, u, name) for u in uploaded}
    matched = [i in found for i in range(len(files))]
    info = (f"{name}: {sum(matched)} of {len(files)} row(s) match uploaded files"
            + (f" ({given})" if given else ""))
    # the line of each row in the file (read_settings_table keeps them); a table built
    # otherwise counts from the line after its header
    lines = table.attrs.get("lines") or range(2, 2 + len(files))
    unmatched = [f"line {line} {f!r}" for line, f, ok in zip(lines, files, matched, strict=True)
                 if not ok]
    warning = (f"{name}: row(s) matching no uploaded file: {', '.join(unmatched)}; their "
               "settings apply to no file uploaded (check the file names)" if unmatched else "")
    return info, warning


def default_settings_row(name: str, stated) -> dict:
    """Settings of a newly uploaded file: its stated load case, no corrections, auto channels."""
    return {"file": name, "fill [%]": float(stated.fill_percent), "material": stated.material,
            "direction": stated.direction, "specimen": "", "vibrometer delay [µs]": 0.0,
            "mass below gauge [g]": 0.0, "baseline loss factor [-]": 0.0,
            "structure mass [g]": 0.0, "force channel": AUTO_CHANNEL,
            "velocity channel": AUTO_CHANNEL, "acceleration channel": AUTO_CHANNEL,
            "inverted channels": "", "time base unit": ""}


def assumed_note(stated, row: Mapping, given: Iterable[str] = ()) -> str:
    """What a file's settings row still takes from no statement, e.g. ``'material: not
    stated, acrylic assumed'`` (``stated``: :func:`pidcore.compare.case.stated_case`), shown
    with its result; a value the user has set in the row since, or that a settings table states
    (``given``: its columns with a value for this file, :func:`columns_given`), is not
    assumed."""
    given = set(given)
    parts = []
    # a row stating no fill has no load case, hence no material (no_fill_note says so), as
    # `pidcore analyze` assumes none for it
    if _blank(row.get("fill [%]")):
        return ""
    if "material" not in given and str(row.get("material", "")) == stated.material:
        said = next((part for part in stated.origin.split("; ")
                     if part.startswith("material: ")), "")
        if said == "material: default":
            parts.append(f"material: not stated, {stated.material} assumed")
        elif " proposed: " in said:  # a material the table lacks, e.g. "..._steel.csv"
            parts.append(said.replace(" proposed: ", " assumed: ", 1))
    return "; ".join(parts)


def delay_note(row: Mapping, given: Iterable[str] = (), *, velocity_used: bool) -> str:
    """``'vibrometer delay: none given, 0 µs assumed ...'`` where a file's velocity channel is
    used and neither its settings row nor a settings table gives a delay: a laser
    vibrometer's output delay (tens of µs) shifts the phase of every harmonic, and an unset
    one changes the loss factor without a word (the bundled samples, 50 µs: SDC 2.80 instead
    of 4.09). "" otherwise."""
    if not velocity_used or "vibrometer delay [µs]" in set(given):
        return ""
    value = row.get("vibrometer delay [µs]")
    if not (_empty(value) or _same_number(value, 0.0)):
        return ""
    return ("vibrometer delay: none given, 0 µs assumed; a laser vibrometer's output delay "
            "(typically tens of µs, from its data sheet) changes the loss factor read")


def columns_given(tables: Sequence[pd.DataFrame], name: str) -> set[str]:
    """The settings columns that uploaded ``tables`` give a value for file ``name`` (matched
    as :func:`table_row` matches it, as ``pidcore analyze`` does)."""
    given: set[str] = set()
    for table in tables:
        found = _row_or_none(table, name, "settings table")
        if found is not None:
            row = table.iloc[found]
            given |= {k for k in FILE_TABLE_COLUMNS if k != "file" and not _empty(row.get(k))}
    return given


def _row_or_none(table: pd.DataFrame, name: str, shown: str) -> int | None:
    """:func:`table_row`, None where it is ambiguous (such a table is refused before its
    rows are used: :func:`check_table_rows`)."""
    from ..loadcase import LoadCaseError

    try:
        return table_row(table, name, shown)
    except LoadCaseError:
        return None


def _empty(value) -> bool:
    return value is None or value == "" or (isinstance(value, float) and math.isnan(value))


def _blank(value) -> bool:
    """Empty as a cell typed in the grid may be (spaces only)."""
    return _empty(value.strip() if isinstance(value, str) else value)


def _same_number(value, number: float) -> bool:
    try:
        return float(value) == float(number)
    except (TypeError, ValueError):
        return False


def merge_settings(names: Sequence[str], stated: Sequence, previous: pd.DataFrame | None,
                   tables: Sequence[pd.DataFrame] = (), *,
                   earlier_tables: Sequence[pd.DataFrame] = ()) -> pd.DataFrame:
    """The settings table of the files ``names``.

    In order, later wins: defaults from ``stated`` (what the names state), ``earlier_tables``
    (tables uploaded before: they fill files added since), the user's values (``previous``),
    then newly uploaded ``tables``. An empty table cell leaves the value alone.
    """
    rows = {n: default_settings_row(n, s) for n, s in zip(names, stated, strict=True)}
    _apply_tables(rows, earlier_tables)
    if previous is not None and not previous.empty:
        for _, old in previous.iterrows():
            if old["file"] in rows:
                rows[old["file"]].update({k: old[k] for k in FILE_TABLE_COLUMNS if k in old})
    _apply_tables(rows, tables)
    return pd.DataFrame(list(rows.values()), columns=list(FILE_TABLE_COLUMNS))


def _apply_tables(rows: dict[str, dict], tables: Sequence[pd.DataFrame]) -> None:
    for table in tables:
        for target in rows:
            found = _row_or_none(table, target, "settings table")
            if found is None:
                continue
            new = table.iloc[found]
            for k in FILE_TABLE_COLUMNS:
                value = new.get(k, "")
                if k != "file" and not _empty(value):
                    rows[target][k] = value


def editor_settings(settings: pd.DataFrame) -> pd.DataFrame:
    """``settings`` as the page's editor shows them: the :data:`TEXT_EDITED_NUMBERS` columns
    as text (``50.0`` -> ``"50"``, ``5e-05`` -> ``"5e-05"``, an empty cell -> ``""``), the
    others as they are. Text given (a cell typed before) is kept as typed."""
    out = settings.copy()
    for column in TEXT_EDITED_NUMBERS:
        if column in out.columns:
            out[column] = [_cell_text(v) for v in out[column]]
    return out


def _cell_text(value) -> str:
    if _empty(value):
        return ""
    if isinstance(value, str):
        return value
    text = repr(float(value))  # the shortest text that reads back as the same number
    return text[:-2] if text.endswith(".0") else text


def fill_of(row: Mapping) -> float | None:
    """The fill [%] of one file's settings row as typed in the page's editor (text) or given
    by a settings table (a number); None for an empty cell (no fill stated: the file has no
    load case, :func:`no_fill_note`); a :class:`pidcore.loadcase.LoadCaseError` naming the
    file and the column for anything but a number in (0, 100]."""
    from ..loadcase import check_fill

    value = row.get("fill [%]")
    # a cell cleared in the grid comes back as None (or NaN from a table): nothing stated
    if _blank(value):
        return None
    return check_fill(value.strip() if isinstance(value, str) else value,
                      f"{row['file']}, column fill [%]")


def no_fill_note(name: str) -> str:
    """What the page says of the file ``name`` whose row states no fill: it is shown and
    saved without a load case, as ``pidcore analyze`` saves a file stating none (a fill the
    page proposed was saved as stated, and the report compared it in that fill's row)."""
    return (f"{name}: fill not stated: no load case; saved without one, as `pidcore analyze` "
            "saves it (type its fill [%] in the settings table for Compare and `pidcore report "
            "--store` to place it)")


def settings_template(settings: pd.DataFrame) -> bytes:
    """The settings table as a CSV template (template column names), to fill in and upload."""
    return settings.rename(columns=FILE_TABLE_COLUMNS).to_csv(index=False).encode()


def options_of(row: Mapping, *, sample_rate_hz: float | None = None,
               time_unit: str | None = None) -> AnalysisOptions:
    """Analysis options of one file's settings row (SI inside: µs and g converted by
    :func:`pidcore.file_settings.analysis_overrides`, the parsing ``pidcore analyze`` applies
    to a sidecar row: one set of checks, errors naming the file and the column), with the
    page's options for every file (saved with the record, as ``pidcore analyze`` saves its
    ``--sample-rate`` and ``--time-unit``)."""
    from ..file_settings import analysis_overrides
    from ..measure import AnalysisOptions

    labels = {v: k for k, v in FILE_TABLE_COLUMNS.items()}  # errors name the app's columns
    # channel cells as the table holds them: the overrides read "(auto)", "(none)", blank and
    # NaN cells as no channel named (a NaN cell was passed on as a channel named "nan")
    cells = {column: row.get(label) for column, label in labels.items()}
    overrides = analysis_overrides(cells, str(row["file"]), labels=labels)
    overrides.pop("time_unit", None)
    return AnalysisOptions(**overrides, sample_rate_hz=sample_rate_hz,
                           time_unit=file_time_unit(row, time_unit))


def row_time_unit_notes(record: AnalyzedRecord, row: Mapping,
                        time_unit: str | None) -> AnalyzedRecord:
    """``record`` whose notes say the unit its row's *time base unit* cell stated came from
    that cell: read with it, the reader's note named the field for every file, which was
    empty (:func:`file_time_unit`). As it is where the page's field gave the unit."""
    from .vocabulary import LABEL_OF_KEYWORD

    if time_unit is not None or file_time_unit(row, None) is None:
        return record
    page, label = LABEL_OF_KEYWORD["time_unit"], _time_unit_label()
    notes = tuple(n.replace(f"({page})", f"(the settings table's column '{label}')")
                  for n in record.notes)
    return record if notes == record.notes else replace(record, notes=notes)


def _time_unit_label() -> str:
    return next(k for k, v in FILE_TABLE_COLUMNS.items() if v == "time_unit")


def file_time_unit(row: Mapping, time_unit: str | None = None) -> str | None:
    """The unit of one file's time base: its row's *time base unit* cell, else ``time_unit``
    (the page's, for every file); a cell and a page's unit that read the time otherwise are
    refused naming both, as ``pidcore analyze`` refuses ``--time-unit`` beside a sidecar's
    ``time_unit`` (one of the two is wrong, either a frequency 1000 x off)."""
    from ..file_settings import analysis_overrides, same_time_unit

    label = _time_unit_label()
    stated = analysis_overrides({"time_unit": row.get(label)}, str(row["file"]),
                                labels={"time_unit": label}).get("time_unit")
    if stated is None:
        return time_unit
    if not same_time_unit(time_unit, stated):
        raise SettingsTableError(
            f"{row['file']}: {TIME_UNIT_FIELD} {time_unit!r} (for every file) disagrees with "
            f"column {label} {stated!r}; expected one unit of the file's time base (leave the "
            f"cell or the {TIME_UNIT_FIELD} field empty)")
    return time_unit if time_unit is not None else stated


# --- results and saving ------------------------------------------------------------------------

#: Columns of the results table, units in the names.
RESULT_COLUMNS = ("file", "load case", "specimen", "frequency [Hz]", "acceleration [g]",
                  "loss factor [-]", "SDC [-]", "SDC stderr [-]", "vibrometer delay [µs]",
                  "force channel", "velocity channel", "warnings")


@dataclass(frozen=True)
class AnalysedFile:
    """One successfully analysed upload with everything needed to show and save it."""

    record: AnalyzedRecord
    #: None: its row states no fill (:func:`no_fill_note`), saved without a load case
    load_case: LoadCase | None
    options: AnalysisOptions
    specimen: str
    warnings: tuple = ()
    #: sha256 of the specimen file named (:func:`pidcore.specimen.resolve_specimen_name`),
    #: "" where only its name is known
    specimen_sha256: str = ""
    #: the SDC bound it was judged against (:func:`pidcore.compare.plausibility.
    #: tested_sdc_bound`; None: 2 pi)
    sdc_bound: object = None


def results_table(files: Sequence[AnalysedFile]) -> pd.DataFrame:
    """One row per analysed file: drive, loss factor, SDC, the corrections used, warnings."""
    rows = []
    for f in files:
        a = f.record.analysis
        rows.append({
            # with material and direction, as Compare lists it: a file set to aluminium
            # read the same as its acrylic twin
            "file": Path(f.record.measurement.source).name,
            "load case": _case_words(f),
            "specimen": f.specimen, "frequency [Hz]": a.frequency_hz,
            "acceleration [g]": a.acceleration_g, "loss factor [-]": a.loss_factor,
            "SDC [-]": a.sdc, "SDC stderr [-]": a.sdc_stderr,
            "vibrometer delay [µs]": f.options.velocity_delay_s * 1e6,
            "force channel": f.record.channels_used.get("force", ""),
            "velocity channel": f.record.channels_used.get("velocity", ""),
            "warnings": "; ".join(w.check for w in f.warnings),
        })
    return pd.DataFrame(rows, columns=list(RESULT_COLUMNS))


def unplaced_note(files: Sequence[AnalysedFile]) -> str:
    """Which of this session's analysed ``files`` Compare leaves out: those stating no fill
    (no load case, :func:`no_fill_note`); "" where none."""
    names = [Path(f.record.measurement.source).name for f in files if f.load_case is None]
    if not names:
        return ""
    return (f"not compared (fill not stated, no load case): {', '.join(names)}; type their "
            "fill [%] in the settings table on the Analyse tab")


def _case_words(f: AnalysedFile) -> str:
    from ..measure import NO_LOAD_CASE

    return f.load_case.full_label() if f.load_case is not None else NO_LOAD_CASE


def format_sdc(sdc: float, stderr: float) -> str:
    """SDC with its standard error as shown, e.g. ``'0.1856 ± 0.0042'``, ``'5.1e-05 ±
    4.4e-05'``, as ``pidcore analyze`` writes it (:func:`pidcore.units.
    display_value_with_error`); ``'—'`` for none."""
    return display_value_with_error(sdc, stderr)


@dataclass(frozen=True)
class SavedRecords:
    """What a save wrote: the analysis ``keys`` and ``notes`` naming each saved record it
    replaced (a byte-identical file is one record, under the name saved last)."""

    keys: list[str]
    notes: tuple[str, ...] = ()
    #: How many records were new and how many the store held already
    #: (:meth:`pidcore.measure.SavedAnalyses.breakdown`); "" where all were new.
    breakdown: str = ""


def check_one_load_case_per_content(files: Sequence[AnalysedFile]) -> None:
    """Refuse byte-identical files that state different load cases (or specimens): the store
    keeps one record of them, so one statement would silently replace the other (as
    ``pidcore report`` refuses them)."""
    from ..loadcase import refuse_identical_contents_stating_apart
    from ..records import measurement_key

    def words(f: AnalysedFile) -> str:
        return _case_words(f) + (f" on {f.specimen}" if f.specimen else "")

    refuse_identical_contents_stating_apart(
        ((Path(f.record.measurement.source).name, measurement_key(f.record.measurement),
          (f.load_case.key if f.load_case is not None else None, f.specimen,
           f.specimen_sha256), words(f)) for f in files),
        remedy="one measurement is one record: state one load case, or remove one of the files")


def load_case_conflict(files: Sequence[AnalysedFile]) -> str:
    """Why saving ``files`` would be refused (:func:`check_one_load_case_per_content`), to
    show before Save; "" when it would not."""
    try:
        check_one_load_case_per_content(files)
    except ParameterError as exc:
        return str(exc)
    return ""


def saved_count(files: Sequence[AnalysedFile]) -> int:
    """How many records saving ``files`` keeps: byte-identical files are one."""
    from ..records import measurement_key

    return len({measurement_key(f.record.measurement) for f in files})


def save_records(path: str | os.PathLike, files: Sequence[AnalysedFile], *,
                 confirm_implausible: bool = False) -> SavedRecords:
    """Save analysed files with their load cases to the store in one locked transaction.

    Each file's own corrections are its analysis parameters (with its channel mapping); the
    load case fields (stated in the app; a file whose row states no fill is saved without a
    load case and a note says so, :func:`no_fill_note`) and the specimen (its name, and its
    specimen's sha256 where known) go into its record. A file with plausibility warnings is
    only saved with ``confirm_implausible`` (the user's explicit confirmation). The notes say
    which saved record each byte-identical file replaces: :func:`pidcore.measure.save_analyses`,
    the save of ``pidcore analyze`` and ``pidcore report``, in the page's words
    (:func:`app_words`).
    """
    from ..measure import save_analyses
    from ..specimen import MEASURED_SHA256_FIELD

    if not files:
        raise ParameterError("nothing to save: no file was analysed successfully")
    flagged = [Path(f.record.measurement.source).name for f in files if f.warnings]
    if flagged and not confirm_implausible:
        raise ParameterError(f"{', '.join(flagged)}: implausible result(s); confirm to save "
                             "them anyway")
    check_one_load_case_per_content(files)
    saved = save_analyses(
        path, [f.record for f in files],
        # the channel mapping is the record's (channels used), not an analysis parameter
        [replace(f.options, force=None, velocity=None, acceleration=None) for f in files],
        [(Path(f.record.measurement.source).name, f.load_case,
          "stated in the app" if f.load_case is not None else "") for f in files],
        fields=[{**({"specimen": f.specimen} if f.specimen else {}),
                 **({MEASURED_SHA256_FIELD: f.specimen_sha256}
                    if f.specimen and f.specimen_sha256 else {}),
                 **({"plausibility_warnings": "; ".join(str(w) for w in f.warnings)}
                    if f.warnings else {}),
                 # as `pidcore analyze` keeps it: judged alike where the file is not at hand
                 **(f.sdc_bound.as_record() if f.sdc_bound is not None else {})}
                for f in files])
    names = [Path(f.record.measurement.source).name for f in files]
    unplaced = [no_fill_note(name) for name, f in zip(names, files, strict=True)
                if f.load_case is None]
    # the settings that changed since a file's last save, as the settings table names them
    return SavedRecords(saved.keys, (*unplaced, *(app_words(n, names=names)
                                                  for n in saved.notes)), saved.breakdown())
