"""Readers and writers of measurement files, and channel role detection.

Every reader returns a :class:`~pidcore.records.Measurement` whose channels are in SI units,
whose ``source`` is the path as given, whose ``sha256`` is the hash of the file's bytes and whose
``file_format`` is one of :data:`pidcore.constants.FileFormat`. Readers do not judge the samples
(NaN and inf are passed on; the analysis rejects them naming the channel). A file that cannot be
read raises :class:`~pidcore.errors.InputFileError` naming the file and what was expected.

Formats (detected from the content first, the extension second):

========  =====================================================  ==========================
format    content                                                module
========  =====================================================  ==========================
uff       UFF dataset 58/58b time records (``.uff``, ``.unv``)   :mod:`pidcore.io.uff`
csv       delimited text with a ``Name [unit]`` header           :mod:`pidcore.io.delimited`
mat       MATLAB v5 / v7.3                                       :mod:`pidcore.io.matlab`
hdf5      pidcore measurement group or store                     :mod:`pidcore.io.hdf5`
========  =====================================================  ==========================

Public API
----------
read_measurement, read_measurements
    Read a file of any format (detected) into :class:`~pidcore.records.Measurement`.
write_measurement
    Write one, the format from the extension.
read_uff, read_csv, read_mat, read_hdf5, hdf5_keys
    The readers of one format; the measurements a pidcore HDF5 file holds.
write_uff, write_csv, write_mat, write_hdf5
    The writers of one format (atomic).
detect_file_format, FILE_FORMAT_EXTENSIONS, EMPTY_MEASUREMENT_FILE
    Format detection: from the content, else the extension; why an empty file is refused.
assign_roles, RoleAssignment, name_suggests
    Which channels are force, velocity and acceleration (units, then names).
display_path
    A path as printable text (undecodable bytes escaped).
file_sha256
    SHA-256 of a file's bytes (a measurement's ``sha256``, a report's input and store hashes).

Examples
--------
>>> from pidcore.io import read_measurement, assign_roles  # doctest: +SKIP
>>> m = read_measurement("run_012.uff")                     # doctest: +SKIP
>>> roles = assign_roles(m, force="Drive point force")      # doctest: +SKIP
"""

from __future__ import annotations

import os
import re
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

from ..constants import FileFormat
from ..errors import InputFileError, ParameterError, PidcoreError, instance_of
from ..records import Measurement
from ..units import given_time_unit
from ._common import HDF5_SIGNATURE, file_sha256, reraise_interrupt
from .delimited import read_csv, write_csv
from .hdf5 import hdf5_key_sources, hdf5_keys, read_hdf5, write_hdf5
from .matlab import read_mat, write_mat
from .roles import RoleAssignment, assign_roles, name_suggests
from .uff import read_uff, write_uff

__all__ = [
    "EMPTY_MEASUREMENT_FILE", "FILE_FORMAT_EXTENSIONS", "RoleAssignment", "assign_roles",
    "detect_file_format", "display_path", "file_sha256",
    "hdf5_keys", "name_suggests", "read_csv", "read_hdf5", "read_mat", "read_measurement",
    "read_measurements", "read_uff", "write_csv", "write_hdf5", "write_mat",
    "write_measurement", "write_uff",
]

#: File name extensions of each format (lower case), used when the content does not decide.
FILE_FORMAT_EXTENSIONS: dict[str, tuple[str, ...]] = {
    "uff": (".uff", ".unv", ".bunv", ".frf"),
    "csv": (".csv", ".txt", ".tsv", ".dat"),
    "mat": (".mat",),
    "hdf5": (".h5", ".hdf5", ".hdf"),
}
_FORMATS = tuple(FILE_FORMAT_EXTENSIONS)
#: Why an empty file is refused, after its name (one wording for the CLI and the app's uploads).
EMPTY_MEASUREMENT_FILE = "empty file; expected a UFF, CSV, MAT or HDF5 measurement file"
_UFF_START = re.compile(rb"\A\s*-1[ \t]*\r?\n\s*\d+")


def detect_file_format(path: str | os.PathLike[str]) -> str:
    """Format of a file from its first bytes, else from its extension.

    Raises
    ------
    InputFileError
        Missing, unreadable or empty file, or neither content nor extension decides.
    """
    # an int is a file descriptor to open(): read_measurement(0) read stdin
    instance_of("path", path, (str, os.PathLike), hint="a file name")
    where = str(path)
    _refuse_unless_a_file(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(1024)
    except FileNotFoundError:
        raise InputFileError(f"{where}: file not found") from None
    except OSError as exc:
        raise InputFileError(f"{where}: cannot open ({exc.strerror})") from None
    if not head:
        raise InputFileError(f"{where}: {EMPTY_MEASUREMENT_FILE}")
    if head.startswith(b"MATLAB"):
        return "mat"  # v5 header text; v7.3 is HDF5 behind the same 128-byte text header
    if head.startswith(HDF5_SIGNATURE) or head[512:520] == HDF5_SIGNATURE:
        return "hdf5"
    if _UFF_START.match(head):
        return "uff"
    suffix = Path(where).suffix.lower()
    for fmt, extensions in FILE_FORMAT_EXTENSIONS.items():
        if suffix in extensions:
            return fmt
    if b"\x00" not in head:
        return "csv"
    raise InputFileError(f"{where}: unknown file format; expected UFF (.uff/.unv), CSV/TXT, "
                         "MATLAB (.mat) or pidcore HDF5 (.h5)")


def _refuse_unless_a_file(path: str | os.PathLike[str]) -> None:
    """Refuse a path that exists but holds no file to read twice: a named pipe or process
    substitution (``analyze <(cat f.csv)``) was called "file not found" once its first bytes
    were read to detect the format, and opening a pipe with no writer waits for ever. A
    missing path or a folder is left to what opening it says."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        raise InputFileError(f"{path}: not a regular file (a pipe?); give a file")


def display_path(path: str | os.PathLike[str]) -> str:
    """The path as text that can be printed and stored: bytes that are not UTF-8 (a file name
    from another system) become ``\\xNN`` escapes instead of failing later.

    >>> display_path(b"run_\\xff.csv".decode("utf-8", "surrogateescape"))
    'run_\\\\xff.csv'
    """
    text = os.fsdecode(path)
    try:
        text.encode("utf-8")
        return text
    except UnicodeEncodeError:
        return os.fsencode(text).decode("utf-8", "backslashreplace")


def _displayed(measurement: Measurement, path: str | os.PathLike[str]) -> Measurement:
    shown = display_path(path)
    if shown == measurement.source or measurement.source != os.fsdecode(path):
        return measurement
    notes = [*measurement.metadata.get("reader_notes", ()),
             f"{shown}: the file name is not valid UTF-8; stored with \\x escapes"]
    return replace(measurement, source=shown,
                   metadata={**measurement.metadata, "reader_notes": notes})


def _rate_kept(measurement: Measurement, sample_rate_hz: float | None,
               path: str | os.PathLike[str]) -> Measurement:
    """``measurement`` with a reader note where ``sample_rate_hz`` was given but not applied:
    UFF, HDF5 and the structured MATLAB layouts (Testlab ``Signal``, pidcore's) state each
    channel's rate and keep it. Without the note the option was ignored without a word, and
    a rate typed to correct the file's changed nothing that the output showed."""
    if sample_rate_hz is None or not measurement.channels or any(
            abs(c.sample_rate_hz - sample_rate_hz) <= 1e-9 * sample_rate_hz
            for c in measurement.channels):
        return measurement
    rates = ", ".join(f"{r:.9g}" for r in sorted({c.sample_rate_hz
                                                  for c in measurement.channels}))
    notes = [*measurement.metadata.get("reader_notes", ()),
             f"{display_path(path)}: the sample rate {sample_rate_hz:g} Hz given "
             f"(sample_rate_hz) is not applied: the file states its channels' rate ({rates} Hz), "
             "which is kept; the option sets the rate of CSV/TXT files and of MATLAB files of "
             "plain vectors"]
    return replace(measurement, metadata={**measurement.metadata, "reader_notes": notes})


def _check_format(file_format: str | None) -> None:
    if file_format is not None and file_format not in _FORMATS:
        raise ParameterError(f"file_format must be one of {', '.join(_FORMATS)}; "
                             f"got {file_format!r}")


def read_measurements(path: str | os.PathLike[str], *, sample_rate_hz: float | None = None,
                      file_format: FileFormat | None = None) -> list[Measurement]:
    """All measurements in a file: several for a pidcore store, otherwise one.

    See :func:`read_measurement` for the parameters.
    """
    instance_of("path", path, (str, os.PathLike), hint="a file name")
    _check_format(file_format)
    _refuse_unless_a_file(path)
    fmt = file_format or detect_file_format(path)
    if fmt == "hdf5":
        with _one_line_errors(path, fmt):
            return [_displayed(m, path) for m in read_hdf5(path)]
    return [read_measurement(path, sample_rate_hz=sample_rate_hz, file_format=fmt)]


def read_measurement(path: str | os.PathLike[str], *, sample_rate_hz: float | None = None,
                     file_format: FileFormat | None = None, key: str | None = None,
                     time_unit: str | None = None) -> Measurement:
    """Read one measurement file into SI channels.

    Parameters
    ----------
    path : str or path-like
        UFF (58/58b), CSV/TXT, MATLAB or pidcore HDF5 file.
    sample_rate_hz : float, optional
        Sample rate, Hz, for CSV or MATLAB files of plain vectors without a time vector; where
        they have one (or a rate variable), it overrides it, with a reader note. UFF, HDF5 and
        the structured MATLAB layouts state each channel's rate and keep it, with a reader
        note saying the value given was not applied.
    file_format : {"uff", "csv", "mat", "hdf5"}, optional
        Skip detection.
    key : str, optional
        Which measurement of a pidcore store (``/measurements/<key>``) to read.
    time_unit : str, optional
        Unit of the file's time base (``"ms"``): a UFF abscissa, a CSV time column, a MATLAB
        time vector or Test.Lab ``x_values``, where the file states none (taken as seconds,
        noted) or one that is no unit of time pidcore reads (refused without it); it
        overrides the file's (noted). A CSV whose time header is not read (``Abscissa``) takes
        its first column as the time base in this unit (:func:`pidcore.io.delimited.read_csv`).
        HDF5 files and pidcore's MATLAB layout state their rate
        in Hz: a reader note says the unit given was not applied.

    Returns
    -------
    Measurement

    Raises
    ------
    InputFileError
        The file is missing, empty, truncated, corrupt or holds no time record; a store holds
        several measurements and no ``key`` was given (the message lists the keys).
    """
    instance_of("path", path, (str, os.PathLike), hint="a file name")
    _check_format(file_format)
    _refuse_unless_a_file(path)
    fmt = file_format or detect_file_format(path)
    if not Path(path).is_file():
        raise InputFileError(f"{path}: file not found")
    if sample_rate_hz is not None and not sample_rate_hz > 0:
        raise ParameterError(f"sample_rate_hz must be positive, got {sample_rate_hz!r}")
    if key is not None and fmt != "hdf5":
        raise ParameterError(f"{display_path(path)}: key={key!r} picks a measurement of a "
                             f"pidcore HDF5 store; this is a {fmt} file")
    given_time_unit(time_unit)  # refused before the file is read, naming the keyword
    with _one_line_errors(path, fmt):
        return _time_unit_kept(_read(path, fmt, sample_rate_hz, key, time_unit), fmt,
                               time_unit, path)


@contextmanager
def _one_line_errors(path: str | os.PathLike[str], fmt: str) -> Iterator[None]:
    """Any other exception a reader lets out (a blind spot of its checks) becomes an
    :class:`InputFileError` naming the file: one line and exit code 2, not a traceback."""
    try:
        yield
    except (PidcoreError, MemoryError):
        raise
    except Exception as exc:
        reraise_interrupt(exc)
        raise InputFileError(f"{display_path(path)}: not a readable {fmt} measurement file "
                             f"({type(exc).__name__}: {exc})") from None


def _time_unit_kept(measurement: Measurement, fmt: str, time_unit: str | None,
                    path: str | os.PathLike[str]) -> Measurement:
    """``measurement`` with a reader note where ``time_unit`` was given for an HDF5 file,
    which states its channels' rate in Hz (the MATLAB reader says so for its layouts)."""
    if time_unit is None or fmt != "hdf5":
        return measurement
    notes = [*measurement.metadata.get("reader_notes", ()),
             f"{display_path(path)}: the time unit {time_unit!r} given (time_unit) is not "
             f"applied: an HDF5 file states its channels' rate in Hz; the option sets the unit "
             "of UFF abscissas, CSV time columns and MATLAB time vectors and x_values"]
    return replace(measurement, metadata={**measurement.metadata, "reader_notes": notes})


def _read(path: str | os.PathLike[str], fmt: str, sample_rate_hz: float | None,
          key: str | None, time_unit: str | None) -> Measurement:
    if fmt == "uff":
        return _rate_kept(_displayed(read_uff(path, time_unit=time_unit), path),
                          sample_rate_hz, path)
    if fmt == "csv":
        return _displayed(read_csv(path, sample_rate_hz=sample_rate_hz, time_unit=time_unit),
                          path)
    if fmt == "mat":
        return _rate_kept(_displayed(read_mat(path, sample_rate_hz=sample_rate_hz,
                                              time_unit=time_unit), path),
                          sample_rate_hz, path)
    keys = hdf5_keys(path)
    if key is None and len(keys) > 1:
        sources = hdf5_key_sources(path, keys)
        listed = ", ".join(f"{k} ({sources[k]})" if k in sources else k for k in keys)
        raise InputFileError(f"{display_path(path)}: holds {len(keys)} measurements "
                             f"({listed}); choose one with key=NAME")
    return _rate_kept(_displayed(read_hdf5(path, key=key)[0], path), sample_rate_hz, path)


def write_measurement(measurement: Measurement, path: str | os.PathLike[str],
                      file_format: FileFormat | None = None, *, binary: bool = False) -> None:
    """Write ``measurement`` to ``path`` atomically (temporary file, then rename).

    Parameters
    ----------
    measurement : Measurement
    path : str or path-like
    file_format : {"uff", "csv", "mat", "hdf5"}, optional
        Defaults to the format of the extension of ``path``.
    binary : bool
        UFF only: write 58b (float64) instead of ASCII 58.
    """
    _check_format(file_format)
    fmt = file_format
    if fmt is None:
        suffix = Path(path).suffix.lower()
        fmt = next((f for f, exts in FILE_FORMAT_EXTENSIONS.items() if suffix in exts), None)
        if fmt is None:
            raise ParameterError(f"{path}: cannot tell the format from the extension "
                                 f"{suffix!r}; give file_format ({', '.join(_FORMATS)})")
    if binary and fmt != "uff":
        raise ParameterError(f"binary=True applies to UFF only, not {fmt}")
    if fmt == "uff":
        write_uff(measurement, path, binary=binary)
    elif fmt == "csv":
        write_csv(measurement, path)
    elif fmt == "mat":
        write_mat(measurement, path)
    else:
        write_hdf5(measurement, path)
