"""Specimen files uploaded to the app, kept over a page reload (free of Streamlit).

The DEM and Calibrate forms keep their fields in the page address, which cannot hold a file:
after a reload the uploader is empty and the form ran the paper's coupon (or the specimen
list's choice) instead. An uploaded specimen file is therefore kept, as uploaded, in a folder
beside the app store (:func:`kept_specimens_folder`), named by its specimen's sha256
(:attr:`pidcore.specimen.Specimen.hash`, the hash its DEM runs and saved tests carry and the
pages show, ``steel_6mm [beeac8]``); the address holds that hash, never the text, and a reload
restores the file from the folder.

The folder is written only with files that :meth:`pidcore.specimen.Specimen.from_bytes` (the
checker of ``pidcore specimen check``) accepts, and a kept file is checked again when it is
restored: an upload is only ever parsed as TOML, never executed or unpickled. An address is
only ever read as a hash (64 hexadecimal digits), so it cannot name another file.
"""

from __future__ import annotations

import json
import math
import os
import re
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..atomic_files import remove_stale_temporaries, write_atomically
from ..errors import ParameterError, StoreError

try:  # POSIX: keeping a file and removing unused ones exclude each other
    import fcntl
except ImportError:  # pragma: no cover - Windows: no exclusion
    fcntl = None

if TYPE_CHECKING:
    from ..specimen import Specimen

#: Folder of the kept specimen files, beside the store (``<store>.specimens``), as the
#: jobs journal is (``<store>.jobs.json``): not in the store, whose every write changes its
#: stamp and re-reads every listing.
KEPT_FOLDER_SUFFIX = ".specimens"
#: A kept file's bytes are ``<sha256>.toml``; the name it was uploaded under ``<sha256>.json``.
_DATA_SUFFIX = ".toml"
_NAME_SUFFIX = ".json"
_SHA256 = re.compile(r"[0-9a-f]{64}")
#: Seconds a page waits for the kept folder's lock (held by ``pidcore specimen kept --remove``
#: for milliseconds) before it goes on without it, and the command waits for the pages'.
KEPT_FOLDER_LOCK_WAIT_S = 10.0
_LOCK_POLL_S = 0.02


@contextmanager
def _folder_locked(folder: Path, *, exclusive: bool,
                   wait_s: float = KEPT_FOLDER_LOCK_WAIT_S) -> Iterator[bool]:
    """Hold ``flock`` on the kept folder itself (no lock file among the kept ones): shared by
    every page that keeps, restores or holds a file there, exclusive by the removal of unused
    ones, so a file a page is keeping is never removed between its check and its use. Yields
    whether the lock is held (False: the folder cannot be opened, it was held by others for
    ``wait_s``, or the file system has no locks)."""
    try:
        fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    except OSError:
        yield False
        return
    try:
        yield _flock_within(fd, fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH, wait_s) \
            if fcntl is not None else False
    finally:
        os.close(fd)  # releases the lock


def _flock_within(fd: int, operation: int, wait_s: float) -> bool:
    deadline = time.monotonic() + wait_s
    while True:
        try:
            fcntl.flock(fd, operation | fcntl.LOCK_NB)
            return True
        except BlockingIOError:
            if time.monotonic() >= deadline:
                return False
            time.sleep(_LOCK_POLL_S)
        except OSError:  # a file system without locks
            return False


def _mark_used(path: Path) -> None:
    """Set the kept file's time to now: its mtime is when the app last used it, the age that
    ``pidcore specimen kept --remove`` compares with its grace period (a read-only folder:
    left as it is)."""
    with suppress(OSError):
        os.utime(path)


def kept_specimens_folder(store_path: str | os.PathLike) -> Path:
    """The folder of the specimen files uploaded to the app of the store ``store_path``."""
    return Path(f"{store_path}{KEPT_FOLDER_SUFFIX}")


def kept_specimen_file(store_path: str | os.PathLike, sha256: str) -> Path:
    """Where the app keeps the uploaded specimen file of ``sha256`` beside the store
    ``store_path`` (which may not exist)."""
    return kept_specimens_folder(store_path) / f"{sha256}{_DATA_SUFFIX}"


@dataclass(frozen=True)
class KeptSpecimen:
    """An uploaded specimen file: the ``name`` it was uploaded under, its specimen's
    ``sha256`` (what the page address holds), the bytes as uploaded and the specimen read from
    them."""

    name: str
    sha256: str
    data: bytes
    specimen: Specimen


def keep_specimen(folder: str | os.PathLike, name: str,
                  data: bytes) -> tuple[KeptSpecimen, str]:
    """Check the uploaded specimen file ``name`` (``data``) as ``pidcore specimen check``
    does and keep it in ``folder`` under its sha256; returns it and ``""``, or, where the
    folder cannot be written, the one-line reason it will not survive a reload (the file is
    still used for this page).

    Raises
    ------
    ParameterError
        The file is not a specimen file: one line naming ``name`` and the key.
    """
    from ..specimen import Specimen

    specimen = Specimen.from_bytes(data, source=name)  # before anything is written
    sha256 = specimen.hash
    kept = KeptSpecimen(name, sha256, data, specimen)
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        # shared with other pages, exclusive of a removal of unused files: one that found
        # this file unused cannot remove it between the check below and the mark of its use
        with _folder_locked(folder, exclusive=False):
            target = folder / f"{sha256}{_DATA_SUFFIX}"
            if not target.is_file():  # same hash, same specimen: written once
                # whole or not at all: another session may restore the same hash meanwhile
                write_atomically(target, data)
            else:
                _mark_used(target)
            label = folder / f"{sha256}{_NAME_SUFFIX}"
            if _kept_name(label) != name:  # the name it was uploaded under last
                write_atomically(label, json.dumps({"name": name}).encode())
    except OSError as exc:
        return kept, (f"{name}: not kept for a page reload: cannot write {folder} "
                      f"({exc.strerror or exc}); upload it again after a reload")
    return kept, ""


def _kept_name(path: Path) -> str | None:
    try:
        name = json.loads(path.read_text(encoding="utf-8")).get("name")
    except (OSError, ValueError, AttributeError):
        return None
    return name if isinstance(name, str) and name else None


def restore_specimen(folder: str | os.PathLike, sha256: str, *,
                     where: str = "the page address") -> KeptSpecimen:
    """The specimen file kept under ``sha256`` in ``folder`` (:func:`keep_specimen`), checked
    again as an upload is.

    Raises
    ------
    ParameterError
        One line, naming ``where`` the hash came from: it is not a sha256, no file of it is
        kept here (uploaded to another store's app, or the folder was cleared), or the kept
        file is no longer the one uploaded or no longer a specimen file.
    """
    from ..specimen import MAX_SPECIMEN_FILE_BYTES, Specimen

    if not isinstance(sha256, str) or not _SHA256.fullmatch(sha256):
        shown = repr(sha256[:80]) if isinstance(sha256, str) else repr(sha256)
        raise ParameterError(f"specimen file {shown} (from {where}): expected the sha256 of "
                             "an uploaded specimen file (64 lowercase hexadecimal digits); "
                             "upload the specimen file again")
    path = Path(folder) / f"{sha256}{_DATA_SUFFIX}"
    try:
        with _folder_locked(Path(folder), exclusive=False), path.open("rb") as file:
            data = file.read(MAX_SPECIMEN_FILE_BYTES + 1)
            _mark_used(path)  # a page in use: not removed within the grace period
    except FileNotFoundError:
        raise ParameterError(f"specimen file {sha256[:12]} (from {where}): not an uploaded "
                             f"specimen file this app keeps (none in {folder}); upload the "
                             "specimen file again") from None
    except OSError as exc:
        raise ParameterError(f"specimen file {sha256[:12]} (from {where}): cannot read "
                             f"{path} ({exc.strerror or exc}); upload the specimen file "
                             "again") from None
    name = _kept_name(Path(folder) / f"{sha256}{_NAME_SUFFIX}") or f"{sha256[:12]}.toml"
    specimen = Specimen.from_bytes(data, source=name)
    if specimen.hash != sha256:
        raise ParameterError(f"{name} (specimen file {sha256[:12]}, from {where}): the kept "
                             f"file {path} was changed since it was uploaded; upload the "
                             "specimen file again")
    return KeptSpecimen(name, sha256, data, specimen)


@dataclass(frozen=True)
class SpecimenUpload:
    """A form's uploaded specimen file after one script run (:func:`specimen_upload`).

    ``kept``: the file in use (uploaded now, or restored from the page address); ``sha256``:
    what the address holds (None: nothing); ``upload_seen``: whether this session's uploader
    holds a file (removing it then forgets the file, a reload does not); ``error``: why the
    file is refused, one line; ``note``: a line to show beside it ("" for none)."""

    kept: KeptSpecimen | None = None
    sha256: str | None = None
    upload_seen: bool = False
    error: str | None = None
    note: str = ""


def specimen_upload(folder: str | os.PathLike, *, upload: tuple[str, bytes] | None,
                    sha256: str | None, upload_seen: bool) -> SpecimenUpload:
    """The uploaded specimen file of a form after a script run.

    ``upload``: what the uploader holds now (``(name, bytes)``); ``sha256`` and
    ``upload_seen``: the last run's :class:`SpecimenUpload` (a fresh session: the page
    address's hash and False). An upload is checked and kept (:func:`keep_specimen`) and its
    hash goes to the address; an empty uploader after a reload restores the address's file
    (:func:`restore_specimen`: an unknown hash is refused in one line, never replaced by
    another specimen); an uploader emptied by the user forgets it.
    """
    if upload is not None:
        name, data = upload
        try:
            kept, problem = keep_specimen(folder, name, data)
        except ParameterError as exc:
            # a refused file is not kept: the address must not name it after a reload
            return SpecimenUpload(upload_seen=True, error=str(exc))
        return SpecimenUpload(kept, None if problem else kept.sha256, True, note=problem)
    if upload_seen or not sha256:  # the user removed the file (or there was none)
        return SpecimenUpload()
    try:
        kept = restore_specimen(folder, sha256)
    except ParameterError as exc:
        return SpecimenUpload(sha256=sha256, error=str(exc))
    from ..specimen import hashed_name

    # named as the pages name its DEM runs and tests, so the three are seen to be one file
    return SpecimenUpload(kept, sha256, note=(
        f"{kept.name} ({hashed_name(kept.specimen.name, sha256)}): the specimen file uploaded "
        "before the page was reloaded, kept beside the store; upload another file to replace "
        "it"))


@contextmanager
def holding_kept_specimen(store_path: str | os.PathLike, sha256: str) -> Iterator[None]:
    """While the block runs, the kept file of ``sha256`` beside the store ``store_path`` is
    in use: ``pidcore specimen kept --remove`` (another process) leaves it and says so. For
    work that is not in the app's job table and may outlast the grace period, such as the
    app's calibration, which runs in the app's own process. No kept file of that hash (a
    specimen of a folder, not an upload): nothing to hold.

    A shared ``flock`` on the file, taken under the folder's lock, so that the removal, which
    tries the file's exclusive lock under the folder's, cannot have removed it in between.
    """
    folder = kept_specimens_folder(store_path)
    fd = None
    if _SHA256.fullmatch(sha256 or ""):
        with _folder_locked(folder, exclusive=False):
            try:
                fd = os.open(folder / f"{sha256}{_DATA_SUFFIX}", os.O_RDONLY | os.O_NOFOLLOW)
            except OSError:
                fd = None
            if fd is not None and fcntl is not None:
                # only a listing's look (:func:`_held_by_the_app`, a moment) can hold it
                # exclusively now: a removal takes it under the folder's lock, held here
                _flock_within(fd, fcntl.LOCK_SH, KEPT_FOLDER_LOCK_WAIT_S)
                _mark_used(folder / f"{sha256}{_DATA_SUFFIX}")
    try:
        yield
    finally:
        if fd is not None:
            os.close(fd)  # releases the lock


def _held_by_the_app(path: Path) -> bool:
    """Whether a process holds the kept file ``path`` (:func:`holding_kept_specimen`): its
    exclusive lock cannot be taken. Taken and released at once."""
    if fcntl is None:
        return False
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError:
        return False
    try:
        return not _flock_within(fd, fcntl.LOCK_EX, 0.0) and _locks_work(fd)
    finally:
        os.close(fd)


def _locks_work(fd: int) -> bool:
    # a file system without locks refuses every flock: nothing is then known to hold it
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    except OSError:
        return False
    return True


@dataclass(frozen=True)
class KeptFile:
    """One uploaded specimen kept in a store's kept folder (:func:`keep_specimen`):
    its ``sha256``, the ``name`` it was uploaded under ("" where its label is lost), its
    ``files`` there (``<sha256>.toml`` and ``<sha256>.json``, those present), their
    ``size_bytes``, ``referred_by``: what still needs it ("" where nothing does), e.g.
    ``record dem_runs/f50Hz_a5g_...`` or ``job job0003 (queued or running)``; ``used_at``:
    when the app last used it (kept it from an upload, restored it for a page: its newest
    mtime, UNIX s); ``left_because``: why it is left though nothing names it ("" where it
    is not): the app holds it now (a calibration of it runs), or it was used within the
    grace period."""

    sha256: str
    name: str
    files: tuple[Path, ...]
    size_bytes: int
    referred_by: str
    used_at: float = 0.0
    left_because: str = ""

    def to_dict(self) -> dict:
        return {"sha256": self.sha256, "name": self.name, "files": [str(f) for f in self.files],
                "size_bytes": self.size_bytes, "referred_by": self.referred_by or None,
                "last_used_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(self.used_at)),
                "left_because": self.left_because or None}


@dataclass(frozen=True)
class KeptFolder:
    """What :func:`prune_kept_specimens` found in (and removed from) a store's kept folder:
    ``folder``; ``files`` (:class:`KeptFile`, by sha256); ``removed``: whether the unused
    ones (:attr:`unused`) were removed; ``others``: entries the app did not write there
    (never touched); ``recent_hours``: the grace period, h (a file the app used within it
    is left); ``temporaries_removed``: temporary files of killed writes removed (in the
    folder, and of the app's job table beside the store; without ``removed``: those
    ``--remove`` removes)."""

    folder: Path
    files: tuple[KeptFile, ...]
    removed: bool
    others: tuple[Path, ...]
    recent_hours: float = 0.0
    temporaries_removed: tuple[Path, ...] = ()

    @property
    def unused(self) -> tuple[KeptFile, ...]:
        """The kept files that no record of the store and no waiting job refers to, that the
        app does not hold and did not use within the grace period: those removed."""
        return tuple(f for f in self.files if not f.referred_by and not f.left_because)

    def to_dict(self) -> dict:
        return {"folder": str(self.folder), "removed": self.removed,
                "keep_recent_hours": self.recent_hours,
                "files": [f.to_dict() for f in self.files],
                "others": [str(p) for p in self.others],
                "temporaries_removed": [str(p) for p in self.temporaries_removed]}


def _kept_entries(folder: Path) -> tuple[dict[str, list[Path]], list[Path]]:
    """The app's files in ``folder`` by sha256, and every other entry (a file of another
    name, a link, a folder, a temporary file a killed write left)."""
    by_hash: dict[str, list[Path]] = {}
    others = []
    for entry in sorted(folder.iterdir()):
        if _is_kept_file(entry):
            by_hash.setdefault(entry.stem, []).append(entry)
        else:
            others.append(entry)
    return by_hash, others


def _is_kept_name(name: str) -> bool:
    stem, dot, suffix = name.rpartition(".")
    return bool(dot) and f".{suffix}" in (_DATA_SUFFIX, _NAME_SUFFIX) \
        and bool(_SHA256.fullmatch(stem))


def _is_kept_file(path: Path) -> bool:
    """Whether ``path`` is named and made as the app keeps a file (``<sha256>.toml`` or
    ``.json``, a plain file): a link is never the app's, and is never followed."""
    return _is_kept_name(path.name) and not path.is_symlink() and path.is_file()


def _remove_kept(folder: Path, path: Path) -> None:
    """Remove one file the app kept in ``folder``; anything else is refused in one line."""
    if path.parent.resolve() != folder.resolve() or not _is_kept_file(path):
        raise ParameterError(f"{path}: not a specimen file kept in {folder} (<sha256>.toml "
                             "or .json); only those are ever removed")
    path.unlink()


def _checked_before_removal() -> None:
    """Called between the check of what needs each file and the removal (under every lock);
    a test's hook to make a writer try to run in between."""


def prune_kept_specimens(store_path: str | os.PathLike, *, remove: bool = False,
                         only: Sequence[str | os.PathLike] = (),
                         recent_hours: float | None = None) -> KeptFolder:
    """The specimen files kept beside the store ``store_path`` (:func:`kept_specimens_folder`)
    and what still needs each: a record of the store naming its sha256 anywhere
    (:meth:`pidcore.store.Store.sha256_references`), a queued or running job of the app
    (:func:`pidcore.app.jobs.waiting_job_specimens`), work of the app that holds it
    (:func:`holding_kept_specimen`: a calibration), or a page that used it within
    ``recent_hours`` (default :data:`pidcore.defaults.KEPT_SPECIMEN_RECENT_HOURS`; a page's
    address names it before any record or job does). With ``remove``, those nothing needs
    are removed, and so are temporary files of killed writes in the folder and of the job
    table beside the store (:func:`pidcore.atomic_files.remove_stale_temporaries`, older
    than the grace period); a file a record names is never removed. ``only``: the kept files
    to look at (each a sha256 or a path of one in the folder; default all).

    A kept file serves a page reload of the app only (a job and a calibration hold their
    specimen's text): one removed while a page names it asks for the file to be uploaded
    again. Files of other names in the folder are listed and never touched. The store is
    only read. The check and the removal are made under the locks its writers take: the
    store's write lock (no record naming a file is saved in between), the job table's (no
    job is queued in between) and the kept folder's (no page keeps or restores a file in
    between).

    Raises
    ------
    ParameterError
        An ``only`` entry that is not a kept file of this store (a path outside the folder),
        ``recent_hours`` negative or not finite, or the app's job table cannot be read (with
        ``remove``: what its jobs need is then unknown); nothing is removed.
    StoreError
        The store cannot be read, or (``remove``) one of the locks cannot be taken.
    """
    from ..defaults import KEPT_SPECIMEN_RECENT_HOURS, STORE_LOCK_TIMEOUT_S
    from ..store import Store
    from ..store.lock import exclusive_lock
    from .jobs import exclusive_journal_lock, journal_path, waiting_job_specimens

    recent_hours = KEPT_SPECIMEN_RECENT_HOURS if recent_hours is None else recent_hours
    if not (isinstance(recent_hours, (int, float)) and math.isfinite(recent_hours)
            and recent_hours >= 0):
        raise ParameterError(f"keep-recent-hours {recent_hours!r}: expected a number of hours, "
                             "0 or more")
    grace_s = recent_hours * 3600.0
    folder = kept_specimens_folder(store_path)
    if not folder.exists():
        if not Path(store_path).exists():
            # a mistyped --store read "no specimen files kept", as if the app's store had none
            raise ParameterError(f"{store_path}: no such store, and no kept specimen folder "
                                 f"{folder.name} beside it; expected the app's store file "
                                 "(--store)")
        return KeptFolder(folder, (), remove, (), recent_hours)
    if not folder.is_dir() or folder.is_symlink():
        raise ParameterError(f"{folder}: expected the folder of the specimen files the app "
                             "keeps beside the store (a plain folder)")
    by_hash, others = _kept_entries(folder)
    if only:  # refused before any lock is waited for
        chosen = {_chosen_hash(folder, entry, by_hash) for entry in only}

    def survey() -> tuple[tuple[KeptFile, ...], list[Path]]:
        listed, others = _kept_entries(folder)  # again: under the locks, with --remove
        if only:
            listed = {h: paths for h, paths in listed.items() if h in chosen}
            others = []
        records = Store(store_path).sha256_references()
        waiting = waiting_job_specimens(store_path)
        now = time.time()
        files = []
        for sha256, paths in sorted(listed.items()):
            used_at = max(p.stat().st_mtime for p in paths)
            left = ""
            if sha256 in records:
                why = f"record {records[sha256]}"
            elif sha256 in waiting:
                why = f"job {waiting[sha256]} (queued or running)"
            else:
                why = ""
                if _held_by_the_app(folder / f"{sha256}{_DATA_SUFFIX}"):
                    left = "in use by the app now (a calibration of it runs)"
                elif now - used_at < grace_s:
                    left = (f"used by the app {(now - used_at) / 3600:.1f} h ago, within "
                            f"--keep-recent-hours {recent_hours:g}")
            size = sum(p.stat().st_size for p in paths)
            name = _kept_name(folder / f"{sha256}{_NAME_SUFFIX}") or ""
            files.append(KeptFile(sha256, name, tuple(paths), size, why, used_at, left))
        return tuple(files), others

    def stale_temporaries(dry_run: bool) -> list[Path]:
        journal = journal_path(store_path)
        return [*remove_stale_temporaries(folder, _is_kept_name, min_age_s=grace_s,
                                          dry_run=dry_run),
                *remove_stale_temporaries(journal.parent, journal.name.__eq__,
                                          min_age_s=grace_s, dry_run=dry_run)]

    if not remove:
        files, others = survey()
        temporaries = [] if only else stale_temporaries(dry_run=True)
        return KeptFolder(folder, files, False, tuple(p for p in others if p not in temporaries),
                          recent_hours, tuple(temporaries))
    # the writers' own locks, in the order a worker saving a run takes them (the store's,
    # then the job table's), so that none of them changes what needs a file in between
    with exclusive_lock(Path(store_path), timeout_s=STORE_LOCK_TIMEOUT_S), \
            exclusive_journal_lock(store_path, only_where_used=True), \
            _folder_locked(folder, exclusive=True) as held:
        if not held and fcntl is not None:
            raise StoreError(f"{folder}: could not take its lock within "
                             f"{KEPT_FOLDER_LOCK_WAIT_S:g} s (the app is keeping a file "
                             "there?); nothing was removed, try again")
        files, others = survey()
        _checked_before_removal()
        for kept in files:
            if not kept.referred_by and not kept.left_because:
                for path in kept.files:
                    _remove_kept(folder, path)
        # under the folder's lock every page that writes there waits: a temporary file left
        # is a killed write's (the grace period also spares a writer of an older pidcore)
        temporaries = [] if only else stale_temporaries(dry_run=False)
    others = [p for p in others if p not in temporaries]
    return KeptFolder(folder, files, True, tuple(others), recent_hours, tuple(temporaries))


def _chosen_hash(folder: Path, entry: str | os.PathLike,
                 by_hash: dict[str, list[Path]]) -> str:
    """The sha256 of the kept file ``entry`` names (its sha256, or the path of its
    ``.toml`` or ``.json`` in ``folder``); anything else is refused in one line."""
    text = os.fspath(entry)
    if _SHA256.fullmatch(text) and text in by_hash:
        return text
    path = Path(text)
    if path.parent.resolve() == folder.resolve() and _is_kept_file(path) \
            and path.stem in by_hash:
        return path.stem
    raise ParameterError(f"{text}: not a specimen file kept in {folder} (expected the "
                         "sha256 of one, or the path of its .toml or .json there); nothing "
                         "was removed")
