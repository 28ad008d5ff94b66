"""The HDF5 store: measurements, analyses and DEM runs with units and provenance.

Layout (every group explains itself through its attributes)::

    /                          attrs: pidcore_store_version (1), created_utc, pidcore_version
    /measurements/<key>        pidcore.io.hdf5_layout measurement group
                               + attrs imported_utc, pidcore_version, key_basis
    /analyses/<key>            attrs: pidcore_layout="analysis", measurement_key, created_utc,
                                      pidcore_version, parameters_json, null_fields_json
                                      (first_created_utc where saved again since: created_utc
                                      is its newest save, which reports take)
    /analyses/<key>/record     one attribute per scalar field
    /analyses/<key>/units      one attribute per field or array: its unit
    /analyses/<key>/arrays/<name>   dataset (complex allowed), attr unit; fletcher32, and
                               from 1024 elements shuffle + gzip (built-in filters)
    /dem_runs/<case_key>       as an analysis, with case_key instead of measurement_key
    /calibrations/<key>        as an analysis (pidcore_layout="calibration"; record: specimen,
                               fit, posterior medians and intervals, RMS), with the whole
                               calibration.json and the calibrated specimen file as UTF-8 byte
                               arrays (arrays/calibration_json, arrays/calibrated_specimen_toml)

Writes are transactions: under an exclusive lock on ``<store>.lock`` the store is read into
memory (h5py on a :class:`io.BytesIO`) and changed there; at the commit the buffer is written to
a temporary file beside the store, fsync'ed and moved over the original with
:func:`os.replace`; any exception (KeyboardInterrupt included) discards the copy. The file at
the store's path therefore only ever holds a complete, committed state. HDF5 itself never writes
to disk: a write it fails (file size limit, full disk) surfaced as errors inside h5py's object
destructors, a two-line message and a segmentation fault at exit; a failed write of the image
is one ``OSError`` of Python's own. A store larger than
:data:`pidcore.defaults.STORE_IN_MEMORY_MAX_BYTES` is copied to the temporary file instead and
changed there (its size in memory per commit was the price otherwise); the room for the copy
is checked before (:meth:`Store.check_writable`), the room for each entry before HDF5 writes it
(:meth:`Store._check_room_to_write`; a disk filled by another process in between still ends in
h5py's errors, store intact), and the rename is the same.

Readers take no lock. Because the path is only ever swapped atomically and an open HDF5 handle
keeps reading the file it opened, a reader sees the last committed state even while a writer
works, instead of waiting for it.
"""

from __future__ import annotations

import errno
import io
import json
import os
import re
import resource
import shutil
import threading
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import h5py
import numpy as np
import pandas as pd

from .. import __version__, defaults, interrupt
from ..atomic_files import (
    fsync_path,
    longest_name_with_a_temporary,
    new_file_mode,
    remove_stale_temporaries,
    temporary_path_for,
)
from ..errors import InputFileError, ParameterError, StoreError
from ..io._hdf5_safety import check_self_contained
from ..io.hdf5_layout import (
    metadata_checksummed,
    read_measurement_group,
    write_measurement_group,
)
from ..records import Measurement
from ..records import measurement_key_and_basis as _measurement_key
from .lock import exclusive_lock, lock_path_for
from .schema import ANALYSIS, DEM_RUN, array_problems, record_problems
from .values import (
    RESERVED_FIELDS,
    Scalar,
    analysis_key,
    check_name,
    from_attribute,
    parameters_to_json,
    to_array,
    to_attribute,
)

#: Layout version written to the root attribute ``pidcore_store_version``.
STORE_VERSION = 1
#: Room a commit needs beyond the store's size before work is started for it, bytes: a DEM
#: run's entry is ~10-300 kB (an analysis with its measurement may be more; it is quick to
#: redo, and its commit fails in one line). More would refuse saves that fit.
_COMMIT_HEADROOM_BYTES = 2**20

_MEASUREMENTS, _ANALYSES, _DEM_RUNS = "measurements", "analyses", "dem_runs"
_CALIBRATIONS = "calibrations"
#: Every section; a store written before calibrations were stored has no /calibrations (it is
#: made by the next write), so verify() does not count its absence as damage.
_SECTIONS = (_MEASUREMENTS, _ANALYSES, _DEM_RUNS, _CALIBRATIONS)
_LAYOUT_ANALYSIS, _LAYOUT_DEM_RUN, _LAYOUT_CALIBRATION = "analysis", "dem_run", "calibration"
#: Arrays of a stored calibration holding text (UTF-8 bytes, checksummed like every array).
CALIBRATION_DOCUMENT, CALIBRATION_SPECIMEN = "calibration_json", "calibrated_specimen_toml"
_ROOT_ATTRS = ("pidcore_store_version", "created_utc", "pidcore_version")
_MEASUREMENT_ATTRS = ("pidcore_layout", "source", "sha256", "file_format", "metadata_json",
                      "imported_utc", "pidcore_version")
_ENTRY_ATTRS = ("pidcore_layout", "created_utc", "pidcore_version", "parameters_json",
                "null_fields_json")
_DEM_ITEM_FIELDS = frozenset({"case_key", "record", "arrays", "parameters", "units"})
#: The schema (:mod:`pidcore.store.schema`) each section's entries are checked against.
_SCHEMA_OF = {_ANALYSES: ANALYSIS, _DEM_RUNS: DEM_RUN}
#: Refusals of a damaged entry end with the way out.
_DAMAGED = "it was changed or damaged outside pidcore (save it again into a fresh store)"


@dataclass(frozen=True)
class StoredEntry:
    """One analysis or DEM run read back from the store.

    Attributes
    ----------
    key : str
        Analysis key or DEM case key.
    record : dict
        Scalar fields as stored (``None`` where ``None`` was given).
    arrays : dict of numpy.ndarray
        Array fields (complex arrays stay complex).
    parameters : dict
        Parameters the result was computed with (decoded ``parameters_json``).
    attrs : dict
        Provenance attributes of the entry group (pidcore_version, created_utc, ...).
    units : dict of str
        Unit of each field or array that was given one.
    """

    key: str
    record: dict[str, Scalar]
    arrays: dict[str, np.ndarray]
    parameters: dict[str, Any]
    attrs: dict[str, Any]
    units: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class _PreparedEntry:
    """A validated analysis or DEM run, ready to be written."""

    values: dict[str, Any]
    null_fields: tuple[str, ...]
    arrays: dict[str, np.ndarray]
    units: dict[str, str]
    parameters_json: str

    @property
    def nbytes(self) -> int:
        """Bytes of its arrays, uncompressed (its attributes are within the headroom)."""
        return sum(array.nbytes for array in self.arrays.values())


def _utc_now() -> str:
    return datetime.now(UTC).isoformat(timespec="microseconds")


def _text(value: Any) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def _one_line(reason: object) -> str:
    # HDF5's messages hold newlines ("file write failed: time = ...\n, filename = ..."); an
    # error of pidcore is one line
    return " ".join(str(reason).split())


def _room_in(directory: Path) -> tuple[int | None, int | None]:
    """(free bytes on the disk of ``directory``, this process's file size limit in bytes),
    each None where unknown (a file system that cannot say: the write will tell) or
    unlimited."""
    free = None
    with suppress(OSError):
        free = shutil.disk_usage(directory).free
    limit = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
    return free, None if limit == resource.RLIM_INFINITY else limit


def _write_image(path: Path, image: memoryview) -> None:
    """Write ``image`` over the file at ``path`` and fsync it (an ``OSError`` on failure)."""
    with open(path, "r+b") as file:
        file.truncate(0)
        file.write(image)
        file.flush()
        os.fsync(file.fileno())


#: A sha256 in a stored text: 64 hexadecimal digits, not part of a longer run of them.
_SHA256_IN_TEXT = re.compile(r"(?<![0-9a-fA-F])[0-9a-fA-F]{64}(?![0-9a-fA-F])")


def _texts_of(value: object) -> Iterator[str]:
    """The texts an HDF5 attribute holds (a string, bytes, or an array of them); none for
    a number."""
    if isinstance(value, bytes):
        yield value.decode("utf-8", errors="replace")
    elif isinstance(value, str):
        yield value
    elif isinstance(value, np.ndarray) and value.dtype.kind in "SUO":
        for item in value.ravel():
            yield from _texts_of(item)


def _prepare_entry(record: Mapping[str, Any], arrays: Mapping[str, Any] | None,
                   parameters: Mapping[str, Any] | None, units: Mapping[str, str] | None,
                   *, where: str) -> _PreparedEntry:
    if not isinstance(record, Mapping):
        raise StoreError(f"{where}: record must be a mapping of field name to scalar, "
                         f"got {type(record).__name__}")
    arrays = {} if arrays is None else arrays
    units = {} if units is None else units
    if not isinstance(arrays, Mapping) or not isinstance(units, Mapping):
        raise StoreError(f"{where}: arrays and units must be mappings")
    values: dict[str, Any] = {}
    nulls = []
    for name, value in record.items():
        check_name(name, what="record field", where=where)
        if name in RESERVED_FIELDS:
            raise StoreError(f"{where}: record field {name!r} is reserved for the listing "
                             f"columns ({', '.join(sorted(RESERVED_FIELDS))})")
        values[name], was_none = to_attribute(value, field=name, where=where)
        if was_none:
            nulls.append(name)
    prepared_arrays = {}
    for name, value in arrays.items():
        check_name(name, what="array", where=where)
        if name in values:
            raise StoreError(f"{where}: {name!r} is both a record field and an array")
        prepared_arrays[name] = to_array(value, name=name, where=where)
    for name, unit in units.items():
        if name not in values and name not in prepared_arrays:
            raise StoreError(f"{where}: units given for {name!r}, which is neither a record field "
                             "nor an array")
        if not isinstance(unit, str):
            raise StoreError(f"{where}: unit of {name!r} must be a string, "
                             f"got {type(unit).__name__}")
    return _PreparedEntry(values, tuple(nulls), prepared_arrays, dict(units),
                          parameters_to_json({} if parameters is None else parameters,
                                             where=where))


def _write_entry(parent: h5py.Group, key: str, entry: _PreparedEntry, *, layout: str,
                 link_attrs: Mapping[str, str]) -> None:
    group = parent.create_group(key)
    group.attrs["pidcore_layout"] = layout
    for name, value in link_attrs.items():
        group.attrs[name] = value
    group.attrs["created_utc"] = _utc_now()
    group.attrs["pidcore_version"] = __version__
    group.attrs["parameters_json"] = entry.parameters_json
    group.attrs["null_fields_json"] = json.dumps(list(entry.null_fields))
    # track_order keeps the caller's field order, which becomes the listing's column order.
    record = group.create_group("record", track_order=True)
    for name, value in entry.values.items():
        record.attrs[name] = value
    units = group.create_group("units", track_order=True)
    for name, unit in entry.units.items():
        units.attrs[name] = unit
    arrays = group.create_group("arrays", track_order=True)
    for name, array in entry.arrays.items():
        # fletcher32 makes verify() detect flipped bits in stored arrays; gzip only for arrays
        # large enough for it to pay (small chunked datasets cost more than they save), after
        # HDF5's shuffle: it groups the bytes of equal rank (sign and exponent bytes change
        # little from sample to sample), which made the DEM runs of the Table 3 grid 20 %
        # smaller than gzip alone, lossless and readable by any HDF5 reader (both built in).
        big = array.size >= 1024
        dataset = arrays.create_dataset(name, data=array, fletcher32=array.ndim > 0,
                                        compression="gzip" if big else None, shuffle=big)
        dataset.attrs["unit"] = entry.units.get(name, "")


def _holds_entry(group: h5py.Group, entry: _PreparedEntry,
                 link_attrs: Mapping[str, str]) -> bool:
    """Whether ``group`` holds exactly what :func:`_write_entry` would write of ``entry`` (its
    creation time aside), bit for bit, by this pidcore version."""
    def same(stored: Any, value: Any) -> bool:
        stored, value = np.asarray(stored), np.asarray(value)
        return stored.dtype == value.dtype and stored.shape == value.shape and \
            stored.tobytes() == value.tobytes()

    try:
        attrs = group.attrs
        if (_text(attrs.get("pidcore_version", "")) != __version__
                or _text(attrs.get("parameters_json", "")) != entry.parameters_json
                or _text(attrs.get("null_fields_json", "")) != json.dumps(
                    list(entry.null_fields))
                or any(_text(attrs.get(k, "")) != v for k, v in link_attrs.items())):
            return False
        record, units, arrays = group["record"].attrs, group["units"].attrs, group["arrays"]
        if (set(record) != set(entry.values) or set(units) != set(entry.units)
                or set(arrays) != set(entry.arrays)):
            return False
        return (all(isinstance(record[k], bytes | str) == isinstance(v, bytes | str)
                    and (_text(record[k]) == _text(v) if isinstance(v, bytes | str)
                         else same(record[k], v)) for k, v in entry.values.items())
                and all(_text(units[k]) == v for k, v in entry.units.items())
                and all(same(arrays[k][()], v) for k, v in entry.arrays.items()))
    except (KeyError, TypeError, ValueError, OSError):  # a damaged entry: written anew
        return False


def _read_entry(group: h5py.Group, key: str, *, where: str, section: str) -> StoredEntry:
    """The entry ``group`` of ``section`` as written by :func:`_write_entry`; one damaged in
    its layout (a subgroup missing or not a group, a JSON attribute that is not JSON, a record
    field that is not a scalar, a dangling soft link) or against its schema
    (:mod:`pidcore.store.schema`: a field, unit or array that is not what pidcore stores) is a
    one-line :class:`StoreError` naming ``where``: a KeyError or JSONDecodeError traceback
    before (report --calibration, the app's Compare page), or a ValueError deep in a report."""
    for name in ("record", "units", "arrays"):
        if not isinstance(group.get(name), h5py.Group):
            raise StoreError(f"{where}: damaged entry ({name} is not a group)")
    try:
        attrs = {name: from_attribute(value) for name, value in group.attrs.items()}
        nulls = set(json.loads(_text(group.attrs.get("null_fields_json", "[]"))))
        record = {name: (None if name in nulls else from_attribute(value))
                  for name, value in group["record"].attrs.items()}
        units = {name: _text(value) for name, value in group["units"].attrs.items()}
        arrays = {name: dataset[()] for name, dataset in group["arrays"].items()}
        array_units = {name: _text(dataset.attrs.get("unit", ""))
                       for name, dataset in group["arrays"].items()}
        parameters = json.loads(_text(group.attrs.get("parameters_json", "{}")))
    except (KeyError, TypeError, ValueError, AttributeError, RecursionError) as exc:
        raise StoreError(f"{where}: damaged entry ({type(exc).__name__}: "
                         f"{_one_line(exc)[:200]})") from None
    odd = [name for name, value in record.items()
           if value is not None and not isinstance(value, str | int | float | complex)]
    if odd or not isinstance(parameters, dict):
        what = f"record field {odd[0]!r} is not a scalar" if odd else \
            "parameters_json is not a JSON object"
        raise StoreError(f"{where}: damaged entry ({what})")
    layout = _SCHEMA_OF.get(section, "")
    problems = [*record_problems(layout, record, units),
                *array_problems(layout, record, arrays, array_units)]
    if problems:
        raise StoreError(f"{where}: damaged entry ({'; '.join(problems)}); {_DAMAGED}")
    return StoredEntry(key=key, record=record, arrays=arrays, parameters=parameters, attrs=attrs,
                       units=units)


def calibration_texts(entry: StoredEntry) -> tuple[str, str]:
    """``(calibration.json, calibrated specimen file)`` of a stored calibration."""
    where = f"calibration {entry.key!r}"
    out = []
    for name in (CALIBRATION_DOCUMENT, CALIBRATION_SPECIMEN):
        array = entry.arrays.get(name)
        # an HDF5 string dataset reads back as bytes, not an array
        if not isinstance(array, np.ndarray) or array.dtype != np.uint8 or array.ndim != 1:
            raise StoreError(f"{where}: array {name} missing or not UTF-8 bytes")
        try:
            out.append(array.tobytes().decode("utf-8"))
        except UnicodeDecodeError as exc:
            raise StoreError(f"{where}: array {name} is not UTF-8 text ({exc})") from None
    return out[0], out[1]


def _calibration_text_problems(entry: StoredEntry, where: str) -> list[str]:
    """What makes the calibration unreadable, checked as reports read it (a NaN prediction
    or a negative frequency passed verify, then report --calibration refused it)."""
    from ..calibrate.prediction import calibration_from_json

    try:
        document, _ = calibration_texts(entry)
    except StoreError as exc:
        return [f"{where}: {exc}"]
    try:
        calibration_from_json(document, where)
    except ParameterError as exc:
        return [str(exc)]
    return []


def _check_measurement(measurement: Measurement) -> None:
    if not isinstance(measurement, Measurement):
        raise StoreError("expected a pidcore.records.Measurement, "
                         f"got {type(measurement).__name__}")
    if not measurement.channels:
        raise StoreError(f"{measurement.source}: measurement has no channels; nothing to store")
    for ch in measurement.channels:
        where = f"{measurement.source}: channel {ch.name!r}"
        try:
            data = np.asarray(ch.data, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise StoreError(f"{where}: samples cannot be stored as float64 ({exc})") from None
        if data.ndim != 1:
            raise StoreError(f"{where}: expected 1-D samples, got shape {data.shape}")
        rate = float(ch.sample_rate_hz)
        if not np.isfinite(rate) or rate <= 0:
            raise StoreError(f"{where}: sample_rate_hz must be finite and > 0, got {rate}")


class Store:
    """pidcore's HDF5 store of measurements, analyses and DEM runs.

    Parameters
    ----------
    path : str or os.PathLike, optional
        Store file; created on the first write. Default :data:`pidcore.defaults.STORE_PATH`.
    lock_timeout_s : float, optional
        Seconds a write waits for another writer's lock, s.
        Default :data:`pidcore.defaults.STORE_LOCK_TIMEOUT_S`.

    Raises
    ------
    StoreError
        A file exists at ``path`` but is not a readable pidcore store (it is never modified).

    Examples
    --------
    >>> store = Store("pid_store.h5")                        # doctest: +SKIP
    >>> key, added = store.add_measurement(measurement)       # doctest: +SKIP
    >>> with store.transaction():                             # doctest: +SKIP
    ...     for case_key, record in results.items():
    ...         store.add_dem_run(case_key, record, units={"sdc": "1"})
    """

    def __init__(self, path: str | os.PathLike[str] = defaults.STORE_PATH, *,
                 lock_timeout_s: float = defaults.STORE_LOCK_TIMEOUT_S) -> None:
        self.path = Path(os.fspath(path))
        timeout = float(lock_timeout_s)
        if not np.isfinite(timeout) or timeout < 0:
            raise ParameterError(f"lock_timeout_s must be finite and >= 0 s, got {lock_timeout_s}")
        self.lock_timeout_s = timeout
        self._active: h5py.File | None = None
        self._active_thread: int | None = None
        #: Transactions this object has committed (read after a Ctrl-C: was anything saved?)
        self.commits = 0
        if self.path.is_dir():  # HDF5's own message is two lines of C-library internals
            raise StoreError(f"{self.path}: is a folder; expected a store file (e.g. "
                             f"{defaults.STORE_PATH})")
        if self.path.is_symlink():
            try:
                os.stat(self.path)
            except OSError as exc:
                # exists() is False for a loop (a -> b -> a), so the first save replaced the
                # link with a new store; a dangling link is a store yet to be made, kept
                if exc.errno == errno.ELOOP:
                    raise StoreError(f"{self.path}: is a symbolic link that leads in a loop "
                                     "(too many levels of links); expected a store file or a "
                                     "link to one") from None
        if self.path.exists():
            # refuse a corrupt or foreign file now rather than at first use; a link at its
            # root is refused by every read and write, and named by verify as damage
            with self._reading(root_links=False):
                pass

    def __repr__(self) -> str:
        return f"Store({str(self.path)!r})"

    @property
    def lock_path(self) -> Path:
        """Sidecar file whose ``flock`` serialises writers."""
        return lock_path_for(self._file)

    @property
    def _file(self) -> Path:
        """The file a commit replaces: the target of a store path that is a symbolic link
        (a shared store linked into a project folder). The rename replaced the link itself
        with a file of its own, so that the shared store never got the record (and writers
        through two links, each locking beside its link, did not exclude each other)."""
        return Path(os.path.realpath(self.path)) if self.path.is_symlink() else self.path

    def check_writable(self) -> None:
        """Refuse, before any work is done for it, a store this process may not write: a
        read-only (or immutable) file, a folder it may not create the working copy and
        lock file in, or no room for the copy every save writes (free disk space, the file
        size limit). A DEM run, sweep or calibration finished its simulations first and then
        lost them at the commit ("cannot commit the changes ([Errno 1] Operation not
        permitted ...)").

        Raises
        ------
        StoreError
            One line naming the store, what is read-only and the way out.
        """
        self._check_name_length()
        directory = self._file.parent
        # no write bit for anyone (chmod 444) is read-only for root too, whom os.access lets
        # write anything: the store marked read-only was replaced by the commit's copy
        if self.path.exists() and (not os.access(self.path, os.W_OK)
                                   or not self.path.stat().st_mode & 0o222):
            raise StoreError(f"{self.path}: the store file is read-only; expected a store "
                             "pidcore may write (make it writable, or give another store file)")
        if directory.is_dir() and not os.access(directory, os.W_OK | os.X_OK):
            raise StoreError(f"{self.path}: its folder {directory} is read-only (the store is "
                             "written as a copy beside it, then renamed); expected a writable "
                             "folder (give a store file in another one)")
        self._check_single_link()
        self._remove_stale_temporaries_if_idle()
        self._check_room(directory)

    def _remove_stale_temporaries_if_idle(self) -> None:
        """Remove the working copies of writers killed outright (``kill -9``, the OOM killer)
        when no writer holds the lock now: such a copy (hidden, as large as the store) stayed
        until the next commit, and its space counted as used refused that commit's run for
        want of the room removing it gives. A live writer's copy is not stale: nothing is
        removed while the lock is taken."""
        with suppress(StoreError, OSError), exclusive_lock(self._file, timeout_s=0):
            self._remove_stale_temporaries()

    def _check_name_length(self) -> None:
        """Refuse a store whose name leaves no room for its working copy's name beside it: the
        copy could not be made, after the work to save was done (an analysis, a DEM run)."""
        size, most = len(os.fsencode(self._file.name)), longest_name_with_a_temporary(self._file)
        if size > most:
            raise StoreError(
                f"{self.path}: the store's name is {size} bytes, too long for the working "
                "copy every save writes beside it (.NAME.<16 hex>.tmp, within the folder's "
                f"limit on a name's length); expected a name of at most {most} bytes")

    def _check_single_link(self) -> None:
        """Refuse a store file with more than one name (a hard link): a save replaces the
        file, so every other name kept the old content without a word, and records saved
        through one name were missing under the other."""
        with suppress(OSError):  # gone or unreadable: the transaction says what is wrong
            links = self._file.stat().st_nlink
            if links > 1:
                raise StoreError(
                    f"{self.path}: the store file has {links} names (hard links), and a save "
                    "replaces the file, so the other names would keep the old content; "
                    "expected a store file with one name (give a copy of it, or a symbolic link "
                    "in place of the hard link)")

    def _check_room(self, directory: Path) -> None:
        """Refuse a commit that cannot fit: every commit writes a whole copy of the store
        beside it, so a disk with less free space than the store (or a file size limit,
        ``ulimit -f``, below its size) fails it. Found at the commit, that lost a DEM run or
        sweep case just simulated. The new entries' size is not known yet: the headroom is a
        guess, so a commit may still fail, in one line, store unchanged."""
        if not directory.is_dir():
            return
        size = self.path.stat().st_size if self.path.exists() else 0
        needed = size + _COMMIT_HEADROOM_BYTES
        free, limit = _room_in(directory)
        if free is not None and free < needed:
            raise StoreError(
                f"{self.path}: {free / 2**20:.1f} MiB free in {directory}, and every save "
                f"writes a copy of the store ({size / 2**20:.1f} MiB) beside it; expected "
                f"at least {needed / 2**20:.1f} MiB free (free some space, or give a "
                "store file on another disk)")
        if limit is not None and limit < needed:
            raise StoreError(
                f"{self.path}: the file size limit of this process (ulimit -f) is "
                f"{limit / 2**20:.1f} MiB, and every save writes a copy of the store "
                f"({size / 2**20:.1f} MiB); expected a limit of at least "
                f"{needed / 2**20:.1f} MiB (raise it, or give a smaller store file)")

    # --- transactions and file access ----------------------------------------------------------

    def _in_transaction(self) -> bool:
        return self._active is not None and self._active_thread == threading.get_ident()

    def _unreadable(self, reason: object) -> StoreError:
        said = _one_line(reason)
        if "file signature not found" in said:
            # h5py's "Unable to synchronously open file (...)" is HDF5's wording for a file
            # of another kind: say that in the user's terms
            said = "not an HDF5 file: a store is the .h5 file pidcore writes"
        if "unable to lock file" in said and "errno = 11" in said:
            # HDF5's own file lock (EAGAIN): a program holds the file open to write, which
            # says nothing of the store being damaged
            return StoreError(f"{self.path}: another program has the store open (HDF5 could "
                              "not lock it: errno 11, resource temporarily unavailable); "
                              "expected it free: close that program, or wait for it, and "
                              "try again")
        return StoreError(f"{self.path}: not a readable pidcore store ({said})")

    def _check_root(self, h5: h5py.File, *, every_entry: bool = True,
                    root_links: bool = True) -> None:
        """Refuse a file that is not a store of a version this pidcore reads, with
        ``root_links`` one with a link at its root (:meth:`_root_links`), and, with
        ``every_entry``, a foreign layout anywhere in its sections (:meth:`_check_sections`)."""
        version = h5.attrs.get("pidcore_store_version")
        if version is None:
            raise self._unreadable("HDF5 file without the root attribute pidcore_store_version")
        stated = from_attribute(version)
        try:
            version = int(stated)
            # int() cuts 1.5 to 1: a version no pidcore wrote was read and written to
            whole = version == stated
        except (TypeError, ValueError):
            whole = False
        if not whole:
            raise self._unreadable(f"pidcore_store_version {stated!r} is not an integer")
        if version < 1:  # no pidcore wrote it: another program's file (or a damaged one)
            raise self._unreadable(f"pidcore_store_version {version} is not one pidcore "
                                   f"writes (1 to {STORE_VERSION})")
        if version > STORE_VERSION:
            raise StoreError(f"{self.path}: store version {version} is newer than this pidcore "
                             f"({__version__}) understands (version {STORE_VERSION}); "
                             "upgrade pidcore")
        links = self._root_links(h5)
        if links and root_links:
            raise self._unreadable(next(iter(links.values())))
        if every_entry:  # a section that is a link is not followed
            self._check_sections(h5, skip=links)

    def _root_links(self, h5: h5py.File) -> dict[str, str]:
        """``{name: what is wrong}`` of each link at the root: one leads out of the store's own
        objects (/zz = an external link that an entry's soft link pointed at), whatever its
        name. Every read refuses the store; verify names each as damage (exit 1) and checks
        the rest, as it does a link inside a record: it said 'not a readable pidcore store'
        (exit 2, as for a file that is none)."""
        return {name: f"/{name} is {self._what(link, None)}; expected the store's own groups "
                      f"at its root ({', '.join(_SECTIONS)})"
                for name in h5 if not isinstance(link := h5.get(name, getlink=True),
                                                 h5py.HardLink)}

    def _check_sections(self, h5: h5py.File, skip: Iterable[str] = ()) -> None:
        """Refuse a foreign layout before anything reads or copies it: each section a group of
        the file itself, each entry a group of the file itself (an external link would make
        every listing open another file on the machine; a soft link to nothing, a dataset
        where a group belongs, crashed every listing and every write)."""
        for section in _SECTIONS:
            parent = None if section in skip else self._section(h5, section)
            for name in () if parent is None else parent:
                self._entry_of(parent, section, name)

    @staticmethod
    def _what(link: object, item: object) -> str:
        if isinstance(link, h5py.ExternalLink):
            return f"an external link to {link.filename!r}"
        if isinstance(link, h5py.SoftLink):
            return f"a soft link to {link.path!r}"
        return "a dataset" if isinstance(item, h5py.Dataset) else "not a group"

    def _section(self, h5: h5py.File, section: str) -> h5py.Group | None:
        """The section group (None where absent), refused as :meth:`_check_sections` refuses
        it where it is not a group of the store's own file."""
        return self._own_group(h5, section, f"/{section}", "a group of entries")

    def _stored_entry(self, h5: h5py.File | None, section: str,
                      key: str) -> h5py.Group | None:
        """The entry group ``section/key`` (None where not stored), its link checked before
        it is followed, as :meth:`_check_sections` checks every entry."""
        parent = None if h5 is None else self._section(h5, section)
        return None if parent is None else self._entry_of(parent, section, key)

    def _entry_of(self, parent: h5py.Group, section: str, key: str) -> h5py.Group | None:
        """The entry ``key`` of the section group ``parent`` (None where not stored), refused
        where it is not a group of the store's own file."""
        return self._own_group(parent, key, f"/{section}/{key}",
                               "an entry group in the store's own file")

    def _own_group(self, parent: h5py.Group, name: str, where: str,
                   expected: str) -> h5py.Group | None:
        """The group ``name`` of ``parent`` (None where absent), its link checked before it is
        followed: refused, saying ``where`` it is and what was ``expected``, where it is not a
        hard-linked group of the store's own file (an external or soft link, a dataset)."""
        link = parent.get(name, getlink=True)
        if link is None:
            return None
        item = parent.get(name) if isinstance(link, h5py.HardLink) else None
        if not isinstance(item, h5py.Group):
            raise self._unreadable(f"{where} is {self._what(link, item)}; expected {expected}")
        return item

    @contextmanager
    def _reading(self, *, every_entry: bool = True,
                 root_links: bool = True) -> Iterator[h5py.File | None]:
        """Open the committed store read-only (``None`` when it does not exist yet).

        ``every_entry=False`` is for reading a few entries by key: their links are checked
        where they are read (:meth:`_stored_entry`). The check of every entry of every
        section made each ``get_analysis`` cost as much as a listing, and a report drawing
        the loops of 2000 stored analyses (one ``get_analysis`` each) take over 40 minutes.
        """
        if self._in_transaction():
            try:
                yield self._active
            except (OSError, RuntimeError) as exc:
                # a damaged object read from the working copy: the one line of a read
                # outside a transaction (analyze and remove printed h5py's traceback)
                raise self._unreadable(exc) from None
            return
        if not self.path.exists():
            yield None
            return
        try:
            h5 = h5py.File(self.path, "r")
        except OSError as exc:
            raise self._unreadable(exc) from None
        try:
            self._check_root(h5, every_entry=every_entry, root_links=root_links)
            yield h5
        except (OSError, RuntimeError) as exc:
            # h5py reports damaged objects inside an openable file as OSError/RuntimeError.
            raise self._unreadable(exc) from None
        finally:
            h5.close()

    def _remove_stale_temporaries(self) -> None:
        # Called under the write lock: no other writer is running, so any temporary copy left
        # beside the store was abandoned by a writer that was killed before it could clean up.
        # Exactly this store's names (see transaction()): a prefix match took the working copy
        # of a store named like this one plus a suffix ("s.h5" and "s.h5.old.h5"), whose
        # writer, not excluded by this store's lock, then failed its commit.
        remove_stale_temporaries(self._file.parent, self._file.name.__eq__)

    @contextmanager
    def transaction(self) -> Iterator[h5py.File]:
        """Batch writes into one atomic commit; yields the working copy opened ``r+``.

        Every ``add_*`` call made inside the block (same thread) joins it, so a batch copies the
        store once. Leaving the block normally commits; any exception, KeyboardInterrupt
        included, discards every change of the batch and leaves the store file untouched.
        Nested ``transaction()`` blocks join the outermost one. The room on disk for each
        ``add_*`` call is checked before it is written; data written straight into the
        yielded file of a store above :data:`pidcore.defaults.STORE_IN_MEMORY_MAX_BYTES`
        is not, and a write HDF5 fails there ends in h5py's destructor errors (store intact).

        Raises
        ------
        StoreError
            The write lock cannot be taken in time, the directory does not exist, or the file
            at the path is not a readable pidcore store (it is never overwritten).
        """
        if self._in_transaction():
            yield self._active
            return
        target = self._file
        directory = target.parent
        if not directory.is_dir():
            raise StoreError(f"{self.path}: directory {directory} does not exist")
        self._check_name_length()
        with exclusive_lock(target, timeout_s=self.lock_timeout_s):
            self._remove_stale_temporaries()
            exists = target.exists()
            if exists:
                self._check_single_link()
                with self._reading():
                    pass  # validates: a foreign or corrupt file must never be replaced
            tmp = temporary_path_for(target)
            try:
                h5, buffer = self._working_copy(tmp, exists=exists)
                try:
                    self._active, self._active_thread = h5, threading.get_ident()
                    yield h5
                except BaseException:
                    with suppress(Exception):  # the copy is discarded anyway
                        h5.close()
                    raise
                finally:
                    self._active, self._active_thread = None, None
                try:
                    h5.close()  # flushes every change into the buffer (or the copy on disk)
                    if buffer is None:
                        fsync_path(tmp)
                    else:
                        _write_image(tmp, buffer.getbuffer())
                    # The rename and its count are one step for Ctrl-C (a caller reads
                    # `commits` to say whether its work was saved); a Ctrl-C swallowed on the
                    # way (weakref callback, Numba) never commits.
                    with interrupt.deferred():
                        interrupt.raise_if_interrupted()
                        os.replace(tmp, target)
                        self.commits += 1
                except OSError as exc:
                    raise StoreError(f"{self.path}: cannot commit the changes "
                                     f"({_one_line(exc)}); the store is unchanged") from None
                # Makes the rename itself durable; the commit has happened either way, and some
                # file systems cannot fsync a directory, so a failure here is not an error.
                with suppress(OSError):
                    fsync_path(directory, directory=True)
                interrupt.raise_if_interrupted()  # one that came during the commit
            except BaseException:
                # a failure to remove the copy must not hide why the transaction failed
                with suppress(OSError):
                    tmp.unlink(missing_ok=True)
                raise

    def _check_room_to_write(self, h5: h5py.File, nbytes: int, *, what: str) -> None:
        """Refuse, before HDF5 writes them, ``nbytes`` of new data that do not fit in the
        working copy on disk (free space, the file size limit): HDF5 writes that copy itself,
        and a write it fails ended in h5py's destructor errors and a segmentation fault (the
        room checked before the copy only covers the copy and a guess of a few entries; a
        long record or a big array did not fit in that guess). No check for a copy in
        memory: its image is written by Python, whose failure is one line."""
        if h5.driver == "fileobj":  # the copy in memory (an io.BytesIO)
            return
        directory = Path(h5.filename).parent
        size = h5.id.get_filesize()
        # uncompressed, as gzip may save nothing, plus 1 % for what grows with them (zlib's
        # worst case is +0.03 %, fletcher32 4 bytes and the chunk index ~32 bytes per chunk)
        needed = nbytes + nbytes // 100 + _COMMIT_HEADROOM_BYTES
        free, limit = _room_in(directory)
        problem = ""
        if free is not None and free < needed:
            problem = f"{free / 2**20:.1f} MiB free in {directory}"
        elif limit is not None and limit < size + needed:
            problem = (f"the file size limit of this process (ulimit -f) is "
                       f"{limit / 2**20:.1f} MiB and its working copy is "
                       f"{size / 2**20:.1f} MiB already")
        if problem:
            raise StoreError(
                f"{self.path}: {what} needs up to {needed / 2**20:.1f} MiB more, and "
                f"{problem}; expected room for it (free some space, raise the limit, or give "
                "a store file on another disk); the store is unchanged")

    def _working_copy(self, tmp: Path, *,
                      exists: bool) -> tuple[h5py.File, io.BytesIO | None]:
        """The committed store (or a new store) opened for writing, and its buffer: in memory,
        ``tmp`` created beside the store, empty, with the store's permissions, for the commit
        to write the buffer to; a store above :data:`pidcore.defaults.
        STORE_IN_MEMORY_MAX_BYTES` copied to ``tmp`` and opened there (buffer ``None``)."""
        try:
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
            if exists:
                shutil.copymode(self._file, tmp)
            else:
                os.chmod(tmp, new_file_mode())
            if exists and self._file.stat().st_size > defaults.STORE_IN_MEMORY_MAX_BYTES:
                # HDF5 writes this copy itself: a write it fails (no room, a file size limit)
                # ends in errors from h5py's destructors, not one line, so the room is checked
                # first (the store stays intact either way: it is never written in place)
                self._check_room(self._file.parent)
                shutil.copyfile(self._file, tmp)
                buffer = None
                h5 = h5py.File(tmp, "r+")
            else:
                # the only reference to the bytes read: the buffer grows them in place
                buffer = io.BytesIO(self._file.read_bytes() if exists else b"")
                h5 = h5py.File(buffer, "r+" if exists else "w")
        except OSError as exc:
            raise StoreError(f"{self.path}: cannot make the working copy {tmp.name} "
                             f"({_one_line(exc)}); the store is unchanged") from None
        try:
            if not exists:
                h5.attrs["pidcore_store_version"] = np.int64(STORE_VERSION)
                h5.attrs["created_utc"] = _utc_now()
                h5.attrs["pidcore_version"] = __version__
            for name in _SECTIONS:
                h5.require_group(name)
        except BaseException:
            h5.close()
            raise
        return h5, buffer

    # --- measurements --------------------------------------------------------------------------

    def add_measurement(self, measurement: Measurement) -> tuple[str, bool]:
        """Store a measurement unless the same file is stored already.

        Parameters
        ----------
        measurement : pidcore.records.Measurement

        Returns
        -------
        key : str
            First 16 hex digits of the file's SHA-256 (of the channel contents when the
            measurement has no ``sha256``).
        added : bool
            False when the measurement was stored before (its channels are not written
            again; a byte-identical file saved under another name takes that name, so the
            store names the file the user saved last).
        """
        _check_measurement(measurement)
        key, basis = _measurement_key(measurement)
        with self._reading(every_entry=False) as h5:
            group = self._stored_entry(h5, _MEASUREMENTS, key)
            if group is not None:
                self._check_same_measurement(group, measurement, key)
                if _text(group.attrs.get("source", "")) == measurement.source:
                    return key, False
        with self.transaction() as h5:
            parent = h5[_MEASUREMENTS]
            if key in parent:  # stored before (or by another process since the check above)
                self._check_same_measurement(parent[key], measurement, key)
                parent[key].attrs["source"] = measurement.source
                return key, False
            self._check_room_to_write(
                h5, sum(np.asarray(ch.data).size * 8 for ch in measurement.channels),
                what=f"measurement {measurement.source}")  # stored as float64
            # a version-2 header: its attributes checksummed as the channels' are
            group = parent.create_group(key, track_order=True)
            try:
                write_measurement_group(group, measurement)
            except (TypeError, ValueError) as exc:
                raise StoreError(f"{measurement.source}: cannot be stored ({exc})") from None
            group.attrs["imported_utc"] = _utc_now()
            group.attrs["pidcore_version"] = __version__
            group.attrs["key_basis"] = basis
        return key, True

    def _check_same_measurement(self, group: h5py.Group, measurement: Measurement,
                                key: str) -> None:
        stored = _text(group.attrs.get("sha256", ""))
        if measurement.sha256 and stored and stored.lower() != measurement.sha256.lower():
            raise StoreError(f"{self.path}: measurement key {key} already holds {stored}, not "
                             f"{measurement.sha256} ({measurement.source}); keys collide")

    def get_measurement(self, key: str) -> Measurement:
        """The measurement stored under ``key``."""
        check_name(key, what="measurement key", where=str(self.path))
        with self._reading(every_entry=False) as h5:
            group = self._entry_group(h5, _MEASUREMENTS, key, "measurement")
            try:
                return read_measurement_group(group, where=f"{self.path}:{group.name}")
            except InputFileError as exc:
                raise StoreError(str(exc)) from None

    def has_measurement(self, key: str) -> bool:
        """Whether a measurement is stored under ``key``."""
        check_name(key, what="measurement key", where=str(self.path))
        with self._reading(every_entry=False) as h5:
            return self._stored_entry(h5, _MEASUREMENTS, key) is not None

    def list_measurements(self) -> pd.DataFrame:
        """One row per measurement: key, source, file_format, n_channels, channel_names,
        sha256, imported_utc, pidcore_version (sorted by import time)."""
        columns = ["key", "source", "file_format", "n_channels", "channel_names", "sha256",
                   "imported_utc", "pidcore_version"]
        rows = []
        with self._reading() as h5:
            for key, group in ({} if h5 is None else h5.get(_MEASUREMENTS, {})).items():
                channels = self._own_child(group, "channels") or {}
                names = tuple(_text(self._own_child(channels, c).attrs.get("name", c))
                              for c in sorted(channels))
                rows.append({
                    "key": key,
                    "source": _text(group.attrs.get("source", "")),
                    "file_format": _text(group.attrs.get("file_format", "")),
                    "n_channels": len(names),
                    "channel_names": names,
                    "sha256": _text(group.attrs.get("sha256", "")),
                    "imported_utc": _text(group.attrs.get("imported_utc", "")),
                    "pidcore_version": _text(group.attrs.get("pidcore_version", "")),
                })
        frame = pd.DataFrame(rows, columns=columns)
        return frame.sort_values(["imported_utc", "key"], ignore_index=True)

    # --- analyses ------------------------------------------------------------------------------

    def add_analysis(self, measurement_key: str, record: Mapping[str, Scalar], *,
                     arrays: Mapping[str, np.ndarray] | None = None,
                     parameters: Mapping[str, Any] | None = None,
                     units: Mapping[str, str] | None = None) -> str:
        """Store one analysis result of a stored measurement.

        Parameters
        ----------
        measurement_key : str
            Key of the analysed measurement (must be stored).
        record : mapping of str to scalar
            Result fields, e.g. ``frequency_hz``, ``loss_factor``, ``sdc``, ``sdc_stderr``.
        arrays : mapping of str to numpy.ndarray, optional
            Array results, e.g. complex harmonic phasors.
        parameters : mapping, optional
            JSON-safe parameters the analysis ran with; with ``measurement_key`` they define
            the key, so re-analysing with the same parameters replaces the entry.
        units : mapping of str to str, optional
            Unit of each field or array, e.g. ``{"frequency_hz": "Hz", "sdc": "1"}``.

        Returns
        -------
        str
            The analysis key.
        """
        where = f"{self.path}: analysis of measurement {measurement_key!r}"
        check_name(measurement_key, what="measurement key", where=str(self.path))
        entry = _prepare_entry(record, arrays, parameters, units, where=where)
        key = analysis_key(measurement_key, entry.parameters_json)
        with self.transaction() as h5:
            if measurement_key not in h5[_MEASUREMENTS]:
                raise StoreError(f"{where}: no measurement with that key is stored; "
                                 "add the measurement first")
            parent = h5[_ANALYSES]
            if key in parent:
                if _holds_entry(parent[key], entry, {"measurement_key": measurement_key}):
                    # the same analysis saved again: rewriting it grew the file by the space
                    # HDF5 does not give back (1.53 -> 1.59 MB over 12 identical saves). Its
                    # time is renewed in place: the newest save of a measurement is the one
                    # reports use (saved with a delay, without, then with it again); the
                    # first save's time is kept beside it, the provenance of the result
                    attrs = parent[key].attrs
                    if "first_created_utc" not in attrs:
                        attrs["first_created_utc"] = attrs.get("created_utc", "")
                    attrs["created_utc"] = _utc_now()
                    return key
                del parent[key]
            self._check_room_to_write(h5, entry.nbytes, what=f"analysis {key!r}")
            _write_entry(parent, key, entry, layout=_LAYOUT_ANALYSIS,
                         link_attrs={"measurement_key": measurement_key})
        return key

    def get_analysis(self, key: str) -> StoredEntry:
        """The analysis stored under ``key``."""
        return self._get_entry(_ANALYSES, key, "analysis")

    def get_analyses(self, keys: Iterable[str]) -> list[StoredEntry]:
        """The analyses stored under ``keys``, in their order, read through one opening of
        the store (a report of many stored analyses opened it once per analysis)."""
        return self._get_entries(_ANALYSES, list(keys), "analysis")

    def list_analyses(self) -> pd.DataFrame:
        """One row per analysis: key, measurement_key, source, created_utc, every scalar field,
        parameters_json, pidcore_version (sorted by creation time)."""
        with self._reading() as h5:
            sources = {}
            if h5 is not None:
                sources = {k: _text(g.attrs.get("source", ""))
                           for k, g in h5.get(_MEASUREMENTS, {}).items()}

            def link(group: h5py.Group) -> dict[str, Any]:
                measurement_key = _text(group.attrs.get("measurement_key", ""))
                return {"measurement_key": measurement_key,
                        "source": sources.get(measurement_key, "")}

            return self._listing(h5, _ANALYSES, ["key", "measurement_key", "source"], link)

    # --- DEM runs ------------------------------------------------------------------------------

    def add_dem_run(self, case_key: str, record: Mapping[str, Scalar], *,
                    arrays: Mapping[str, np.ndarray] | None = None,
                    parameters: Mapping[str, Any] | None = None,
                    units: Mapping[str, str] | None = None, replace: bool = False) -> str:
        """Store one DEM run under a key chosen by the caller.

        Parameters
        ----------
        case_key : str
            E.g. ``"f50_a5_fill50_acrylic_z_seed12345_cells8"``.
        record, arrays, parameters, units
            As for :meth:`add_analysis`.
        replace : bool, optional
            Overwrite an existing run with this key; without it an existing key is a StoreError.

        Returns
        -------
        str
            ``case_key``.
        """
        return self.add_dem_runs([{"case_key": case_key, "record": record, "arrays": arrays,
                                   "parameters": parameters, "units": units}],
                                 replace=replace)[0]

    def add_dem_runs(self, items: Iterable[Mapping[str, Any]], *,
                     replace: bool = False) -> list[str]:
        """Store several DEM runs in one transaction (all or none).

        Parameters
        ----------
        items : iterable of mapping
            Each with key ``case_key`` and ``record``, optionally ``arrays``, ``parameters``,
            ``units`` (the arguments of :meth:`add_dem_run`).
        replace : bool, optional
            Overwrite runs whose case key is stored already.

        Returns
        -------
        list of str
            The case keys, in order.
        """
        prepared: dict[str, _PreparedEntry] = {}
        for index, item in enumerate(items):
            if not isinstance(item, Mapping):
                raise StoreError(f"{self.path}: DEM run #{index} must be a mapping, "
                                 f"got {type(item).__name__}")
            unknown = set(item) - _DEM_ITEM_FIELDS
            if unknown or "case_key" not in item or "record" not in item:
                raise StoreError(f"{self.path}: DEM run #{index} needs keys case_key and record "
                                 f"(optional: arrays, parameters, units); "
                                 f"unknown: {sorted(map(str, unknown))}")
            case_key = check_name(item["case_key"], what="DEM case key", where=str(self.path))
            if case_key in prepared:
                raise StoreError(f"{self.path}: DEM case key {case_key!r} appears twice "
                                 "in one batch")
            prepared[case_key] = _prepare_entry(
                item["record"], item.get("arrays"), item.get("parameters"), item.get("units"),
                where=f"{self.path}: DEM run {case_key!r}")
        with self.transaction() as h5:
            parent = h5[_DEM_RUNS]
            for case_key, entry in prepared.items():
                if case_key in parent:
                    if not replace:
                        raise StoreError(f"{self.path}: DEM run {case_key!r} is stored already; "
                                         "pass replace=True to overwrite it")
                    del parent[case_key]
                self._check_room_to_write(h5, entry.nbytes, what=f"DEM run {case_key!r}")
                _write_entry(parent, case_key, entry, layout=_LAYOUT_DEM_RUN,
                             link_attrs={"case_key": case_key})
        return list(prepared)

    def has_dem_run(self, case_key: str) -> bool:
        """Whether a DEM run is stored under ``case_key``."""
        check_name(case_key, what="DEM case key", where=str(self.path))
        with self._reading(every_entry=False) as h5:
            return self._stored_entry(h5, _DEM_RUNS, case_key) is not None

    def get_dem_run(self, case_key: str) -> StoredEntry:
        """The DEM run stored under ``case_key``; one whose SDC no run saves (negative, NaN,
        not 2 pi x its loss factor: :func:`pidcore.store.listing.dem_run_row_problems`) is
        refused naming the store and the run. Every reader of a run for use passes here
        (calibrate's reuse and observations, a case sheet's loop, re-keying): an SDC of -0.5
        reached a calibration and a case sheet, checked by the listings only. verify reads
        entries on its own and names such a run rather than stopping at it."""
        from .listing import check_dem_run

        entry = self._get_entry(_DEM_RUNS, case_key, "DEM run", key_name="DEM case key")
        check_dem_run(self.path, {**entry.record, "case_key": case_key})
        return entry

    def list_dem_runs(self) -> pd.DataFrame:
        """One row per DEM run: case_key, created_utc, every scalar field, parameters_json,
        pidcore_version (sorted by case key)."""
        with self._reading() as h5:
            frame = self._listing(h5, _DEM_RUNS, [], lambda group: {})
        return frame.rename(columns={"key": "case_key"}).sort_values("case_key",
                                                                     ignore_index=True)

    # --- calibrations --------------------------------------------------------------------------

    def add_calibration(self, key: str, record: Mapping[str, Scalar], *, document: str,
                        specimen_toml: str, units: Mapping[str, str] | None = None,
                        parameters: Mapping[str, Any] | None = None) -> tuple[str, bool]:
        """Store a calibration (the text of its ``calibration.json`` and of its calibrated
        specimen file) unless one is stored under ``key`` already.

        Parameters
        ----------
        key : str
            Chosen by the caller from what the calibration is (:func:`pidcore.calibrate.
            persist.calibration_key`): the same calibration made again is not stored twice.
        record : mapping
            Scalars listed by :meth:`list_calibrations` (specimen, fit, medians, RMS).
        document : str
            The whole ``calibration.json``.
        specimen_toml : str
            The calibrated specimen file.
        units, parameters
            As for :meth:`add_analysis` (``units`` names the record's units).

        Returns
        -------
        key : str
        added : bool
            False when a calibration was stored under ``key`` before (it is kept as it was).
        """
        check_name(key, what="calibration key", where=str(self.path))
        where = f"{self.path}: calibration {key!r}"
        texts = {}
        for name, text in ((CALIBRATION_DOCUMENT, document),
                           (CALIBRATION_SPECIMEN, specimen_toml)):
            if not isinstance(text, str):
                raise StoreError(f"{where}: {name} must be text, got {type(text).__name__}")
            texts[name] = np.frombuffer(text.encode("utf-8"), dtype=np.uint8)
        units = {**({} if units is None else units),
                 **{name: "UTF-8 bytes" for name in texts}}
        entry = _prepare_entry(record, texts, parameters, units, where=where)
        if self.has_calibration(key):
            return key, False
        with self.transaction() as h5:
            parent = h5[_CALIBRATIONS]
            if key in parent:  # stored by another process since the check above
                return key, False
            self._check_room_to_write(h5, entry.nbytes, what=f"calibration {key!r}")
            _write_entry(parent, key, entry, layout=_LAYOUT_CALIBRATION,
                         link_attrs={"calibration_key": key})
        return key, True

    def has_calibration(self, key: str) -> bool:
        """Whether a calibration is stored under ``key``."""
        check_name(key, what="calibration key", where=str(self.path))
        with self._reading(every_entry=False) as h5:
            return self._stored_entry(h5, _CALIBRATIONS, key) is not None

    def get_calibration(self, key: str) -> StoredEntry:
        """The calibration stored under ``key`` (its texts: :func:`calibration_texts`)."""
        return self._get_entry(_CALIBRATIONS, key, "calibration")

    def list_calibrations(self) -> pd.DataFrame:
        """One row per calibration: key, created_utc, every scalar field, parameters_json,
        pidcore_version (oldest first)."""
        with self._reading() as h5:
            return self._listing(h5, _CALIBRATIONS, [], lambda group: {})

    def sha256_references(self) -> dict[str, str]:
        """``{sha256: the entry that names it first}`` for every sha256 (64 hexadecimal
        digits, lowercase) that the store names anywhere: in any attribute of any entry (a
        record's fields, its parameters) or in a text array (a calibration's document and its
        calibrated specimen file), e.g. ``{"beeac8...": "dem_runs/f50Hz_a5g_..."}``; empty
        for a store not written yet.

        Where a file kept by its hash (the app's uploaded specimen files) may be deleted only
        when no record refers to it, every field is searched, not the few known to hold a
        specimen's hash: a field added later, or a calibrated file's source hash inside its
        text, still keeps its file.

        Raises
        ------
        StoreError
            The file at the path is not a readable pidcore store.
        """
        found: dict[str, str] = {}

        def note(text: str, where: str) -> None:
            for match in _SHA256_IN_TEXT.finditer(text):
                found.setdefault(match.group(0).lower(), where)

        def visit(name: str, item: h5py.Group | h5py.Dataset) -> None:
            entry = "/".join(name.split("/")[:2])  # "dem_runs/<key>": what a user can find
            for value in item.attrs.values():
                for text in _texts_of(value):
                    note(text, entry)
            if isinstance(item, h5py.Dataset) and item.dtype == np.uint8 and item.ndim == 1:
                note(item[()].tobytes().decode("utf-8", errors="replace"), entry)

        with self._reading() as h5:
            if h5 is None:
                return {}
            h5.visititems(visit)  # hard links only: a link to another file is never followed
        return found

    # --- removal -------------------------------------------------------------------------------

    def remove_entries(self, entries: Iterable[tuple[str, str]]) -> None:
        """Remove the entries ``(section, key)`` (section: ``measurements``, ``analyses``,
        ``dem_runs`` or ``calibrations``) in one transaction (all or none; inside an open
        :meth:`transaction` they join it). What other entries need them is not checked here:
        :func:`pidcore.store.manage.remove_records` removes with what depends on them. The
        file keeps its size: HDF5 does not give back the space of a removed group.

        Raises
        ------
        StoreError
            A section that is none of the store's, or an entry that is not stored (nothing
            removed).
        """
        entries = list(entries)
        for section, key in entries:
            if section not in _SECTIONS:
                raise StoreError(f"{self.path}: {section!r} is no section of a store (one of "
                                 f"{', '.join(_SECTIONS)})")
            check_name(key, what="key", where=str(self.path))
        with self.transaction() as h5:
            # a record linked into another (a soft link, a dataset of two names) is damage that
            # removing one of them spreads to the other (its link left to nothing), or
            # hides: refused, as verify names it
            for section in _SECTIONS:
                parent = self._section(h5, section)
                for name in () if parent is None else parent:
                    try:
                        check_self_contained(self._entry_of(parent, section, name),
                                             where=f"{self.path}:/{section}/{name}")
                    except InputFileError as exc:
                        raise StoreError(f"{exc}; nothing was removed (`pidcore store verify` "
                                         "names what is damaged)") from None
            for section, key in entries:
                if self._stored_entry(h5, section, key) is None:
                    raise StoreError(f"{self.path}: no entry {key!r} in /{section}; nothing "
                                     "was removed")
                try:
                    del h5[section][key]
                except (OSError, RuntimeError) as exc:
                    # HDF5 reads an entry's metadata to delete it (a bad checksum fails it)
                    raise StoreError(f"{self.path}: cannot remove /{section}/{key} "
                                     f"({_one_line(exc)}); nothing was removed") from None

    # --- shared reading helpers ----------------------------------------------------------------

    def _get_entry(self, section: str, key: str, what: str, *,
                   key_name: str | None = None) -> StoredEntry:
        """The entry ``key`` of ``section`` read whole (``what`` names it in errors, and
        ``key_name``, default "<what> key", names its key)."""
        return self._get_entries(section, [key], what, key_name=key_name)[0]

    def _get_entries(self, section: str, keys: list[str], what: str, *,
                     key_name: str | None = None) -> list[StoredEntry]:
        """The entries ``keys`` of ``section``, each read whole, through one opening."""
        for key in keys:
            check_name(key, what=key_name or f"{what} key", where=str(self.path))
        entries = []
        with self._reading(every_entry=False) as h5:
            for key in keys:
                group = self._entry_group(h5, section, key, what)
                entries.append(_read_entry(group, key, where=f"{self.path}:{group.name}",
                                           section=section))
        return entries

    def _entry_group(self, h5: h5py.File | None, section: str, key: str, what: str) -> h5py.Group:
        if h5 is None:
            raise StoreError(f"{self.path}: no {what} {key!r}; the store does not exist yet")
        group = self._stored_entry(h5, section, key)
        if group is None:
            parent = self._section(h5, section)
            raise StoreError(f"{self.path}: no {what} {key!r} "
                             f"({0 if parent is None else len(parent)} stored)")
        self._check_self_contained(group)
        return group

    def _check_self_contained(self, group: h5py.Group) -> None:
        """Refuse an entry holding, at any depth, what makes HDF5 read another file (an
        external link, external storage, a virtual dataset) or load a plugin, before any of
        it is read: a store handed over with an external link at /dem_runs/K/arrays/X made
        get_dem_run (and report --store) read whichever file it named, and verify() saw
        nothing (only sections and entries themselves were checked)."""
        try:
            check_self_contained(group, where=f"{self.path}:{group.name}")
        except InputFileError as exc:
            raise self._unreadable(exc) from None

    def _own_child(self, group: h5py.Group, name: str) -> h5py.Group | h5py.Dataset | None:
        """``group[name]`` where it is an object of this file (None where absent); what a
        listing reads of each entry, without a walk of the whole entry."""
        link = group.get(name, getlink=True)
        if link is None:
            return None
        if not isinstance(link, h5py.HardLink):
            raise self._unreadable(f"{group.name}/{name} is {self._what(link, None)}; "
                                   "expected an object of the store's own file")
        return group[name]

    def _listing(self, h5: h5py.File | None, section: str, leading: list[str],
                 link: Any) -> pd.DataFrame:
        rows = []
        fields: dict[str, None] = {}  # ordered set of field names over all entries
        for key, group in ({} if h5 is None else h5.get(section, {})).items():
            try:
                row: dict[str, Any] = {"key": key, **link(group),
                                       "created_utc": _text(group.attrs.get("created_utc", ""))}
                record = self._own_child(group, "record")
                values = {name: from_attribute(value)
                          for name, value in ({} if record is None else record.attrs).items()}
                # what a report turns into numbers is checked here, as every get_ checks it (the
                # arrays aside: only get_ reads them); an SDC of 'abc' was a ValueError in report
                units = self._own_child(group, "units")
                problems = record_problems(
                    _SCHEMA_OF.get(section, ""), values,
                    {} if not isinstance(units, h5py.Group) else
                    {name: _text(unit) for name, unit in units.attrs.items()})
                if problems:
                    raise StoreError(f"{self.path}:/{section}/{key}: damaged entry "
                                     f"({'; '.join(problems)}); {_DAMAGED}")
                row.update(values)
                fields.update(dict.fromkeys(values))
                row["parameters_json"] = _text(group.attrs.get("parameters_json", "{}"))
                row["pidcore_version"] = _text(group.attrs.get("pidcore_version", ""))
            except (OSError, RuntimeError) as exc:  # a bad checksum: say which record
                raise self._unreadable(f"/{section}/{key}: {_one_line(exc)}") from None
            rows.append(row)
        leading = ["key", *[c for c in leading if c != "key"], "created_utc"]
        columns = [*leading, *fields, "parameters_json", "pidcore_version"]
        frame = pd.DataFrame(rows, columns=columns)
        return frame.sort_values(["created_utc", "key"], ignore_index=True)

    # --- integrity -----------------------------------------------------------------------------

    def verify(self, *, progress: Callable[[int, int], None] | None = None) -> list[str]:
        """Integrity check: one line per problem found (empty list: the store is sound).

        Checks the root attributes, that every measurement, analysis and DEM run has its
        provenance attributes and readable datasets (checksummed arrays are read in full), that
        keys match their contents, that every analysis refers to a stored measurement and that
        every calibration's design runs are stored
        (:func:`pidcore.calibrate.persist.missing_design_runs`).

        ``progress``, where given, is called with (entries checked, entries in all) after
        each entry: every array is read, a minute for some 3000 entries, more with long
        records stored, which ``pidcore report --store`` spent without a sign of life.
        """
        if not self.path.exists():
            return [f"{self.path}: store does not exist"]
        try:
            h5 = h5py.File(self.path, "r")
        except OSError as exc:
            return [str(self._unreadable(exc))]
        problems: list[str] = []
        try:
            try:
                self._check_root(h5, root_links=False)
            except StoreError as exc:
                return [str(exc)]
            links = self._root_links(h5)  # damage named; the sections linked are not read
            problems += [f"{self.path}: {said}" for said in links.values()]
            problems += [f"{self.path}: root attribute {name} missing"
                         for name in _ROOT_ATTRS if name not in h5.attrs]
            sections = [section for section in _SECTIONS if section not in links]
            total = sum(len(h5[section]) for section in sections if section in h5)
            done = 0
            for section in sections:
                if section not in h5:
                    if section == _CALIBRATIONS:
                        continue  # written before calibrations were stored: not damage
                    problems.append(f"{self.path}: group /{section} missing")
                    continue
                for key in h5[section]:
                    done += 1
                    if progress is not None:
                        progress(done, total)
                    where = f"{self.path}:/{section}/{key}"
                    try:
                        # a key no add_* accepts (a tab, surrounding spaces) is one get_*
                        # refuses: verify called such a store sound
                        check_name(key, what="key", where=f"{self.path}:/{section}")
                    except StoreError as exc:
                        problems.append(str(exc))
                        continue
                    try:
                        problems += self._verify_entry(h5, section, key, where)
                    except Exception as exc:  # report any damage; verify must never crash
                        problems.append(f"{where}: unreadable ({type(exc).__name__}: {exc})")
        finally:
            h5.close()
        return problems + self._analysis_values() + self._dem_run_values() + \
            self._missing_design_runs()

    def _analysis_values(self) -> list[str]:
        """Analyses whose result fields hold what no analysis saves (an SDC of NaN or not
        2 pi x its loss factor, a negative frequency): refused by report and calibrate
        (:func:`pidcore.store.listing.analysis_row_problems`), called sound here before."""
        from .listing import analysis_row_problems, damaged_analysis

        return self._row_values(self.list_analyses, analysis_row_problems, damaged_analysis)

    def _dem_run_values(self) -> list[str]:
        """DEM runs whose SDC is no result a run saves (negative, NaN, not 2 pi x its loss
        factor nor its energy per cycle over its peak kinetic energy), refused by reports
        (:func:`pidcore.store.listing.dem_run_row_problems`)."""
        from .listing import damaged_dem_run, dem_run_row_problems

        return self._row_values(self.list_dem_runs, dem_run_row_problems, damaged_dem_run)

    def _row_values(self, listing: Callable[[], pd.DataFrame],
                    problems_of: Callable[[pd.Series], list[str]],
                    damaged: Callable[[Path, pd.Series, str], StoreError]) -> list[str]:
        """Each problem ``problems_of`` finds in a row of ``listing``, as ``damaged`` says it.
        Not checked where the listing cannot be read: the entries' own problems are said by
        :meth:`verify` before."""
        try:
            rows = listing()
        except StoreError:
            return []
        return [str(damaged(self.path, row, problem))
                for _, row in rows.iterrows() for problem in problems_of(row)]

    def _missing_design_runs(self) -> list[str]:
        """A calibration whose design runs were removed without it (a run shared by two
        calibrations removed with one of them): its fit names inputs that are gone, and
        reports take what is left of them for predictions. Not checked where the listings
        cannot be read: the entries' own problems are said above."""
        from ..calibrate.persist import missing_design_runs

        try:
            return missing_design_runs(self.path)
        except StoreError:
            return []

    def _verify_entry(self, h5: h5py.File, section: str, key: str, where: str) -> list[str]:
        group = h5[section][key]
        try:
            check_self_contained(group, where=where)
        except InputFileError as exc:
            return [str(exc)]
        if section == _MEASUREMENTS:
            problems = [f"{where}: attribute {name} missing"
                        for name in _MEASUREMENT_ATTRS if name not in group.attrs]
            try:
                measurement = read_measurement_group(group, where=where)
            except InputFileError as exc:
                return [*problems, str(exc)]
            basis = _text(group.attrs.get("key_basis", "file_sha256"))
            if basis == "file_sha256":
                expected = measurement.sha256.lower()[:16]
            else:
                expected = _measurement_key(
                    Measurement(measurement.source, measurement.channels))[0]
            if expected != key:
                problems.append(f"{where}: key does not match its contents (expected {expected})")
            return problems
        problems = [f"{where}: attribute {name} missing"
                    for name in _ENTRY_ATTRS if name not in group.attrs]
        problems += [f"{where}: group {name}/ missing"
                     for name in ("record", "units", "arrays") if name not in group]
        if problems:
            return problems
        try:  # reads every array, so checksums are checked
            entry = _read_entry(group, key, where=where, section=section)
        except StoreError as exc:
            return [*problems, str(exc)]
        if section == _ANALYSES:
            measurement_key = _text(group.attrs.get("measurement_key", ""))
            if measurement_key not in h5.get(_MEASUREMENTS, {}):
                problems.append(f"{where}: refers to measurement {measurement_key!r}, "
                                "which is not stored")
            canonical = parameters_to_json(entry.parameters, where=where)
            if analysis_key(measurement_key, canonical) != key:
                problems.append(f"{where}: key does not match measurement_key and parameters")
        elif section == _CALIBRATIONS:
            problems += _calibration_text_problems(entry, where)
        elif _text(group.attrs.get("case_key", "")) != key:
            problems.append(f"{where}: attribute case_key does not match the group name")
        return problems

    def unchecked(self) -> list[str]:
        """What :meth:`verify` could not check: one line per measurement written by an earlier
        pidcore, whose channels' sample rates, units and names carry no checksum (a bit flipped
        in one is read as it stands); empty for a store without any, or none yet. Not damage:
        the store is as sound as verify says; saving the file again into a fresh store gives
        it the checksum."""
        unchecked = []
        with self._reading(every_entry=False) as h5:
            for key, group in ({} if h5 is None else h5.get(_MEASUREMENTS, {})).items():
                try:
                    channels = self._own_child(group, "channels")
                    objects = [group, *([] if not isinstance(channels, h5py.Group) else
                                        [channels, *(self._own_child(channels, name)
                                                     for name in channels)])]
                    if all(metadata_checksummed(obj) for obj in objects if obj is not None):
                        continue
                except (KeyError, OSError, RuntimeError, StoreError):
                    continue  # damaged, which verify says
                if _text(group.attrs.get("key_basis", "file_sha256")) == "file_sha256":
                    said = ("its channels' sample rates, start times, units and names could "
                            "not be checked (its samples were, by their compression's checksum)")
                else:
                    said = ("its channels' units could not be checked (their sample rates, "
                            "start times, names and samples were, against its key)")
                unchecked.append(f"{self.path}:/{_MEASUREMENTS}/{key}: no checksum of its "
                                 f"metadata (written by an earlier pidcore): {said}")
        return unchecked

    def summary(self) -> dict[str, Any]:
        """Counts and identity of the store: path, exists, store_version, created_utc,
        n_measurements, n_analyses, n_dem_runs, n_calibrations, size_bytes."""
        # counts of the sections of the store's own file only, a link at the root not
        # followed: verify's summary of a store it names such a link in
        with self._reading(every_entry=False, root_links=False) as h5:
            if h5 is None:
                return {"path": str(self.path), "exists": False, "store_version": None,
                        "created_utc": None, "n_measurements": 0, "n_analyses": 0,
                        "n_dem_runs": 0, "n_calibrations": 0, "size_bytes": 0}
            return {
                "path": str(self.path),
                "exists": True,
                "store_version": int(from_attribute(h5.attrs["pidcore_store_version"])),
                "created_utc": _text(h5.attrs.get("created_utc", "")),
                "n_measurements": self._count(h5, _MEASUREMENTS),
                "n_analyses": self._count(h5, _ANALYSES),
                "n_dem_runs": self._count(h5, _DEM_RUNS),
                "n_calibrations": self._count(h5, _CALIBRATIONS),
                "size_bytes": self.path.stat().st_size,
            }

    @staticmethod
    def _count(h5: h5py.File, section: str) -> int:
        """Entries of ``section``: 0 where it is absent or no group of the store's own file
        (a link, never followed)."""
        link = h5.get(section, getlink=True)
        group = h5.get(section) if isinstance(link, h5py.HardLink) else None
        return len(group) if isinstance(group, h5py.Group) else 0
