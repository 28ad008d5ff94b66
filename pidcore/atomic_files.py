"""Files written whole or not at all: a temporary file beside the target, renamed over it.

Every file pidcore writes that a user relies on (exported measurements, CSV and JSON tables,
figures, the app's job journal and kept specimen files; the store commits the same way, with
its own lock and buffer, through :func:`fsync_path` and :func:`new_file_mode`) is first
written to a temporary file in the target's own folder, so that the final
:func:`os.replace` is a rename on one file system: atomic, never a copy. Ctrl-C
(KeyboardInterrupt), SIGTERM, a full disk or a failing writer therefore leave the previous file
as it was and no temporary file behind; a reader sees the old file or the new one, never half
of one. A folder of several outputs is built beside its place
(:func:`new_temporary_folder_for`) and moved there whole, after :func:`fsync_tree`
(:func:`replace_folder`: swapped with the earlier folder in one step where the system can);
the next build of that folder removes the build folders a killed one left, by the files'
rule, and puts back an earlier folder a kill left moved aside. Files moved one by one into a
folder that keeps others (:func:`move_files_into_folder`) are moved from a committed build
folder that the next write finishes moving (:func:`finish_committed_moves`).

``durable`` (the default) fsyncs the new file before the rename and the folder after it: a
power loss right after the call then finds the new file, not an empty one under its name (a
rename can reach the disk before the data it names). Files rewritten many times a second
and rebuilt from the store at will may pass ``durable=False``.

The temporary file gets the permissions the target has (a new target: those any new file
gets, 0o666 less the umask); :func:`tempfile.mkstemp`'s 0o600 made an exported file
unreadable to the colleagues its plain write had let read it.
"""

from __future__ import annotations

import os
import re
import secrets
import stat
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from pathlib import Path

#: Marks a temporary file of :func:`atomic_path` (``.<name>.<16 hex>.tmp``), so that a folder
#: listing can leave out one that a killed process (SIGKILL, power loss) left behind.
TEMPORARY_SUFFIX = ".tmp"


def file_in_the_way(path: str | os.PathLike[str]) -> Path | None:
    """The nearest existing ancestor of ``path`` where it is no folder (a file), else None:
    a folder cannot be made under it (``--out afile/sub`` raised FileExistsError with a
    traceback from a mkdir, after a report had saved its records)."""
    for parent in Path(path).absolute().parents:
        if parent.exists():
            return None if parent.is_dir() else parent
    return None


def real_folder(out: str | os.PathLike[str]) -> Path:
    """The folder an output path names, as an absolute path with every link, ``.`` and ``..``
    resolved: where it is a link, the folder the link points to, which is written (and its
    build folders made beside it) while the link is kept. ``--out .`` has no name to build a
    folder beside, and ``sub/..`` is the current folder, which only its resolved path tells
    (:func:`pidcore.out_folder.check_replaceable`)."""
    return Path(os.path.realpath(out))


def new_file_mode() -> int:
    """The permissions a new file gets here: 0o666 less the process's umask."""
    return 0o666 & ~_process_umask()


def _process_umask() -> int:
    # os.umask can only be read by setting it, and the app writes files from worker threads:
    # a file another thread created between the two calls would get umask 0 (world-writable).
    # Linux states the umask in /proc (since 4.7); only where it does not is it set and reset.
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    umask = os.umask(0o077)  # the strictest mask meanwhile, should another thread create a file
    os.umask(umask)
    return umask


def fsync_path(path: str | os.PathLike[str], *, directory: bool = False) -> None:
    """Flush the file (or, with ``directory``, the folder's entries) at ``path`` to the disk;
    an ``OSError`` where that fails."""
    fd = os.open(path, os.O_RDONLY | (os.O_DIRECTORY if directory else 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def fsync_tree(folder: str | os.PathLike[str]) -> None:
    """Flush every file under ``folder``, then each folder's entries, to the disk: for a
    folder of outputs built beside its place and moved there whole (a report, a
    calibration's files), whose rename could otherwise reach the disk before their data.
    An ``OSError`` where a file cannot be flushed; a folder that cannot be is no error
    (some file systems cannot fsync one)."""
    for root, _, names in os.walk(folder):
        for name in names:
            fsync_path(Path(root, name))
        with suppress(OSError):
            fsync_path(root, directory=True)


def temporary_path_for(target: str | os.PathLike[str]) -> Path:
    """A fresh hidden name beside ``target`` (``.<name>.<16 hex>.tmp``), in its folder, so that
    the rename over ``target`` stays on one file system."""
    target = Path(target)
    return target.with_name(f".{target.name}.{secrets.token_hex(8)}{TEMPORARY_SUFFIX}")


def longest_name_with_a_temporary(target: str | os.PathLike[str]) -> int:
    """The most bytes ``target``'s name may have for :func:`temporary_path_for`'s name beside
    it to fit its folder's limit on a name's length (NAME_MAX, 255 bytes on most file systems;
    the temporary name adds 22 to the target's)."""
    target = Path(target)
    try:
        name_max = os.pathconf(target.parent, "PC_NAME_MAX")
    except (OSError, ValueError):  # no such folder (yet), or a system without the query
        name_max = 255
    if name_max < 0:  # the system states no limit
        return sys.maxsize
    added = len(os.fsencode(temporary_path_for(target).name)) - len(os.fsencode(target.name))
    return name_max - added


#: Any name :func:`temporary_path_for` gives, its target's name as ``target``: the hex part
#: and suffix are fixed, so the target is whatever stands before them.
_TEMPORARY_NAME = re.compile(r"\.(?P<target>.+)\.[0-9a-f]{16}" + re.escape(TEMPORARY_SUFFIX))


def remove_stale_temporaries(folder: str | os.PathLike[str], is_target: Callable[[str], bool],
                             *, min_age_s: float = 0.0, now: float | None = None,
                             dry_run: bool = False) -> list[Path]:
    """Remove the temporary files :func:`atomic_path` made in ``folder`` for a target whose
    name ``is_target`` accepts, and that were last changed at least ``min_age_s`` ago; returns
    those removed (``dry_run``: those it would remove, none removed).

    Call it only where no live writer of those targets can hold one: under the lock every
    writer of them takes (the store's write lock, the kept specimens' folder lock), so that a
    file left is one whose writer was killed (SIGKILL, a power loss). ``min_age_s`` guards
    against a writer that does not take that lock (an older pidcore). Only exact names
    (``.<target>.<16 hex>.tmp``, a plain file, no link) are ever removed: a user's
    ``.notes.tmp`` is not one.
    """
    def named(name: str) -> bool:
        match = _TEMPORARY_NAME.fullmatch(name)
        return match is not None and is_target(match["target"])

    removed = []
    for entry in _stale_entries(Path(folder), named, stat.S_ISREG, min_age_s, now):
        with suppress(FileNotFoundError):
            if not dry_run:
                entry.unlink()
            removed.append(entry)
    return removed


def _stale_entries(folder: Path, named: Callable[[str], bool], of_kind: Callable[[int], bool],
                   min_age_s: float, now: float | None) -> Iterator[Path]:
    """The entries of ``folder`` whose name ``named`` takes, whose own kind (``lstat``: a
    link is no file and no folder) ``of_kind`` takes, last changed at least ``min_age_s``
    before ``now``: the one rule of both clean-ups."""
    now = time.time() if now is None else now
    for entry in folder.iterdir():
        if not named(entry.name):
            continue
        try:
            info = entry.lstat()
        except FileNotFoundError:
            continue
        if of_kind(info.st_mode) and now - info.st_mtime >= min_age_s:
            yield entry


#: Marks a folder :func:`new_temporary_folder_for` builds beside its target
#: (``.<name>.<16 hex>.tmpdir``): a suffix of its own, so that neither clean-up rule can take
#: the other's kind (a file rule that met a folder, or the reverse).
TEMPORARY_FOLDER_SUFFIX = ".tmpdir"


def temporary_folder_path_for(target: str | os.PathLike[str]) -> Path:
    """A fresh hidden name beside the folder ``target`` (``.<name>.<16 hex>.tmpdir``), for a
    folder of outputs built there and renamed into place (a report, a calibration's files).
    ``.`` or ``..`` is taken as the folder it names (``calibrate --out .`` failed with "has
    an empty name" after its DEM runs)."""
    target = Path(os.path.abspath(target))
    return target.with_name(f".{target.name}.{secrets.token_hex(8)}{TEMPORARY_FOLDER_SUFFIX}")


def temporary_folder_name_pattern(target: str | os.PathLike[str]) -> re.Pattern[str]:
    """The names :func:`temporary_folder_path_for` gives beside ``target``, and no others (a
    user's ``.<name>.backup`` is not one)."""
    return re.compile(re.escape(f".{Path(os.path.abspath(target)).name}.") + r"[0-9a-f]{16}"
                      + re.escape(TEMPORARY_FOLDER_SUFFIX))


def remove_stale_temporary_folders(target: str | os.PathLike[str], *, min_age_s: float = 0.0,
                                   now: float | None = None,
                                   dry_run: bool = False) -> list[Path]:
    """Remove the build folders :func:`new_temporary_folder_for` made beside ``target`` that
    were last changed at least ``min_age_s`` ago; returns those removed (``dry_run``: those it
    would remove, none removed).

    The rule of :func:`remove_stale_temporaries`, for folders: only an exact name
    (:func:`temporary_folder_name_pattern`) that is a folder itself, not a link to one, is
    removed, and a link inside it is removed as a link (:func:`shutil.rmtree` never follows
    one), so that nothing outside the folder is ever touched.
    """
    import shutil

    target = Path(target)
    pattern = temporary_folder_name_pattern(target)
    removed = []
    for entry in _stale_entries(target.parent, lambda name: pattern.fullmatch(name) is not None,
                                stat.S_ISDIR, min_age_s, now):
        if not dry_run:
            # a file in it that cannot be removed leaves the rest for the next write to retry
            shutil.rmtree(entry, ignore_errors=True)
        removed.append(entry)
    return removed


def new_temporary_folder_for(target: str | os.PathLike[str]) -> Path:
    """Create and return an empty build folder beside the folder ``target``
    (:func:`temporary_folder_path_for`), with the permissions of any new folder (it may
    become ``target`` itself), after removing those a build of ``target`` killed outright
    left (SIGKILL, a power loss) once older than
    :data:`pidcore.defaults.STALE_TEMPORARY_FILE_AGE_S`: a live build's is younger, as its
    files set its time. ``target``'s parent must exist."""
    from .defaults import STALE_TEMPORARY_FILE_AGE_S

    # a folder that cannot be listed (write-only) still gets the build
    with suppress(OSError):
        remove_stale_temporary_folders(target, min_age_s=STALE_TEMPORARY_FILE_AGE_S)
    work = temporary_folder_path_for(target)
    work.mkdir()
    return work


def check_folder_can_be_made(target: str | os.PathLike[str], *, label: str = "") -> None:
    """Refuse, before any work is done for it, an output ``target`` no folder can be made
    beside: a build folder (:func:`new_temporary_folder_for`'s name) is created there and
    removed again, in ``target``'s parent or, where that is still to be made, in its nearest
    existing ancestor (where the first missing folder would be made). A report or a
    calibration computed for minutes first and then ended in a traceback at its write
    (``--out /sys/x``: "Operation not permitted"; ``/proc/x``: "No such file or directory").

    Raises
    ------
    ParameterError
        One line: ``label`` (default: ``target``), the folder and the system's reason.
    """
    from .errors import ParameterError

    place = Path(target).absolute()
    if place.parent == place:  # no name to build beside: temporary_folder_path_for has none
        raise ParameterError(f"{label or target}: is the file system's root, beside which no "
                             "folder can be built; expected an output folder under it")
    while not place.parent.exists() and place.parent != place:
        place = place.parent
    probe = temporary_folder_path_for(place)
    try:
        probe.mkdir()
    except OSError as exc:
        raise ParameterError(
            f"{label or target}: no folder can be made in {place.parent} "
            f"({exc.strerror or exc}); expected an output folder where pidcore may write "
            "(choose another)") from None
    with suppress(OSError):  # made, so removable: one left would be removed as stale
        probe.rmdir()


@contextmanager
def refused_unless_written(folder: str | os.PathLike[str], what: str, *,
                           then: str = "") -> Iterator[None]:
    """Around the write of ``what`` (``"the report"``) into the output folder ``folder``,
    whole or not at all: an ``OSError`` (a full disk or quota, ENOSPC or EDQUOT; a folder made
    read-only since it was checked) becomes one line, a ``ParameterError`` naming ``folder``,
    the system's reason and the file it failed on, and saying that ``folder`` is as it was
    (:func:`pidcore.interrupt.untouched`), ``then`` appended. The one rule of every command
    that writes such a folder: the error came as a traceback after all the work. Only around
    a write that leaves ``folder`` as it was when it fails (its build folder removed)."""
    from .errors import ParameterError
    from .interrupt import untouched

    try:
        yield
    except OSError as exc:
        raise ParameterError(
            f"{folder}: {what} could not be written ({exc.strerror or exc}"
            f"{': ' + str(exc.filename) if exc.filename else ''}); {untouched(folder)} "
            f"(written whole or not at all){then}") from None


#: Marks an earlier folder moved aside (``.<name>.<16 hex>.old``) while :func:`replace_folder`
#: renames its replacement into place, where the system cannot swap the two in one step.
PREVIOUS_FOLDER_SUFFIX = ".old"


def previous_folder_name_pattern(target: str | os.PathLike[str]) -> re.Pattern[str]:
    """The names :func:`replace_folder` moves the earlier ``target`` to, and no others: 16 hex
    digits, or the 8 characters of :func:`tempfile.mkdtemp` that earlier versions used (a
    user's ``.<name>.backup.old`` is not one)."""
    return re.compile(re.escape(f".{Path(target).name}.") + r"(?:[0-9a-f]{16}|[a-z0-9_]{8})"
                      + re.escape(PREVIOUS_FOLDER_SUFFIX))


#: ``renameat2``'s flag that swaps its two paths (linux/fs.h).
_RENAME_EXCHANGE = 2
#: ``renameat2``'s "path relative to the current folder" (fcntl.h's AT_FDCWD).
_AT_FDCWD = -100


def exchange_paths(first: str | os.PathLike[str], second: str | os.PathLike[str]) -> bool:
    """Swap the entries at ``first`` and ``second`` in one atomic step; True if done, False
    where this system or file system cannot (nothing changed then). An ``OSError`` for any
    other failure (a path missing, no permission).

    The standard library renames one path over another, and a folder cannot be renamed over
    a non-empty one; only Linux's ``renameat2(RENAME_EXCHANGE)`` (3.15, glibc 2.28) swaps
    two, so it is called through :mod:`ctypes`. Without it (another system, an older glibc)
    or where the file system refuses the flag (EINVAL) or the kernel lacks the call (ENOSYS),
    False lets the caller fall back to two renames.
    """
    import ctypes
    import errno
    import sys

    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p,
                          ctypes.c_uint]
    renameat2.restype = ctypes.c_int
    if renameat2(_AT_FDCWD, os.fsencode(first), _AT_FDCWD, os.fsencode(second),
                 _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
        return False
    raise OSError(code, os.strerror(code), os.fspath(first), None, os.fspath(second))


def _fsync_folder_of(path: Path) -> None:
    # the renames in it made durable; some file systems cannot fsync a folder, and the
    # renames are done either way, so a failure here is not an error
    with suppress(OSError):
        fsync_path(path.parent if str(path.parent) else ".", directory=True)


def replace_folder(new: str | os.PathLike[str], target: str | os.PathLike[str]) -> None:
    """Rename the folder ``new`` to ``target``, replacing the folder there, if any.

    Where the system can (:func:`exchange_paths`), the two are swapped in one step and the
    earlier folder, now under ``new``'s name (a build folder's), is removed: a process killed
    at any point (SIGKILL, a power loss) leaves ``target`` whole, earlier or new, and at most
    a build folder that the next build's clean-up removes (:func:`new_temporary_folder_for`).

    Elsewhere a folder cannot be renamed over a non-empty one, so the earlier ``target`` is
    first moved aside (:func:`previous_folder_name_pattern`), then removed. An exception
    between the two renames puts it back; a process killed there leaves no ``target`` and
    the earlier one hidden beside it, which :func:`restore_previous_folder` (called by the
    next write, before anything else) puts back: no earlier folder is lost.
    """
    new, target = Path(new), Path(target)
    if not os.path.lexists(target):  # a dangling link is no folder a folder renames over
        os.replace(new, target)
        _fsync_folder_of(target)
        return
    if exchange_paths(new, target):
        _fsync_folder_of(target)
        _remove_folder_or_link(new)
        return
    old = target.with_name(f".{target.name}.{secrets.token_hex(8)}{PREVIOUS_FOLDER_SUFFIX}")
    os.replace(target, old)
    try:
        os.replace(new, target)
    except BaseException:
        os.replace(old, target)
        raise
    _fsync_folder_of(target)
    # under a build folder's name before it is removed: a removal cut short leaves part of
    # the earlier folder where the build folders' clean-up takes it, never as a '.old' that
    # the next write would put back in place of a folder it had replaced
    trash = temporary_folder_path_for(target)
    try:
        os.replace(old, trash)
    except OSError:
        trash = old  # the next write's restore_previous_folder removes what is left
    _remove_folder_or_link(trash)


def _remove_folder_or_link(path: Path) -> None:
    # a target that was a link to a folder was moved as the link: removed as one, never
    # followed (rmtree refuses a link, which was left for ever beside the target)
    import shutil

    if path.is_symlink():
        with suppress(OSError):
            path.unlink()
    else:
        shutil.rmtree(path, ignore_errors=True)


def restore_previous_folder(target: str | os.PathLike[str], *,
                            is_previous: Callable[[Path], bool] = lambda folder: True,
                            why_kept: Callable[[Path], str] = lambda folder: ""
                            ) -> Path | None:
    """Settle what a killed :func:`replace_folder` left beside ``target``; returns the folder
    restored (None: none was). Call it before any other write of ``target``.

    Where ``target`` is missing, the earlier folder moved aside (SIGKILL, a power loss
    between the two renames) is renamed back. Where ``target`` exists, such folders are
    what remained of a replacement that had finished (killed before they were removed) and
    are removed. Only an exact name (:func:`previous_folder_name_pattern`) that is a folder
    itself, not a link, and that ``is_previous`` accepts (a report's marker) is taken, by
    the rule of the build folders' clean-up. Several beside a missing ``target`` are
    refused (a ``ParameterError`` naming them): which was the last is no longer certain,
    and none is removed or guessed at. An existing ``target`` is never touched. Nor is one to
    be removed that ``why_kept`` says removing would lose something of (a file added to it
    since): refused, naming it and why, none removed.
    """
    import shutil

    from .errors import ParameterError

    target = Path(target)
    pattern = previous_folder_name_pattern(target)
    try:
        found = [entry for entry in _stale_entries(
            target.parent, lambda name: pattern.fullmatch(name) is not None, stat.S_ISDIR,
            0.0, None) if is_previous(entry)]
    except OSError:  # no parent yet, or one that cannot be listed: nothing left there
        return None
    if os.path.lexists(target):
        for entry in found:
            why = why_kept(entry)
            if why:
                raise ParameterError(
                    f"{entry}: left hidden beside {target.name} by a killed write, with its "
                    f"earlier outputs, to be removed, but it {why}; move what you keep out of "
                    "it, then remove it")
        for entry in found:
            shutil.rmtree(entry, ignore_errors=True)
        return None
    if not found:
        return None
    if len(found) > 1:
        raise ParameterError(
            f"{target}: missing, and {len(found)} earlier folders that killed writes left "
            f"hidden beside it ({', '.join(sorted(entry.name for entry in found))}); rename "
            f"the one to keep to {target.name} and remove the others")
    os.replace(found[0], target)
    _fsync_folder_of(target)
    return target


#: Marks a build folder whose files are being moved into their folder
#: (``.<name>.<16 hex>.commit``, :func:`move_files_into_folder`): renamed so once complete, it
#: is the journal of the moves still to do, which no clean-up of build folders may take.
COMMITTED_FOLDER_SUFFIX = ".commit"


def committed_folder_name_pattern(target: str | os.PathLike[str]) -> re.Pattern[str]:
    """The names :func:`move_files_into_folder` gives its committed build folder beside
    ``target``, and no others."""
    return re.compile(re.escape(f".{Path(os.path.abspath(target)).name}.") + r"[0-9a-f]{16}"
                      + re.escape(COMMITTED_FOLDER_SUFFIX))


def move_files_into_folder(work: str | os.PathLike[str], target: str | os.PathLike[str]) -> None:
    """Move every file of the build folder ``work`` into the existing folder ``target``,
    replacing those of the same names, as one step for anyone who looks after a kill.

    A folder whose other files must be kept cannot be swapped whole, and files are moved
    one rename each, so a kill (SIGKILL, a power loss) between two renames left some files
    new and the others earlier. Here ``work`` (complete, flushed by the caller) is first
    renamed to a committed name (:func:`committed_folder_name_pattern`): that rename is the
    commit point, and the folder's files are the moves still to do. A kill before it leaves
    ``target`` as it was (and a build folder, removed by the build folders' clean-up); a
    kill after it, moves that :func:`finish_committed_moves`, called by the next write
    before anything else, completes (rolls forward). Files of other names in ``target`` are
    never touched. A ``target`` that is a link to a folder stays a link: the commit is made
    beside the folder it points to (:func:`real_folder`), where ``work`` is to be built, so
    that every move is a rename on that folder's file system.
    """
    work, target = Path(work), real_folder(target)
    commit = target.with_name(f".{target.name}.{secrets.token_hex(8)}{COMMITTED_FOLDER_SUFFIX}")
    os.replace(work, commit)
    _fsync_folder_of(target)  # the commit on disk before the moves it allows
    _finish_moves(commit, target)


def _finish_moves(commit: Path, target: Path) -> list[Path]:
    """Move the plain files left in ``commit`` into ``target`` and remove ``commit``;
    returns the files moved."""
    import shutil

    moved = []
    with suppress(FileNotFoundError):  # all moved, and the folder removed, by another finisher
        for entry in sorted(_stale_entries(commit, lambda name: True, stat.S_ISREG, 0.0, None)):
            with suppress(FileNotFoundError):  # this one moved meanwhile by another finisher
                os.replace(entry, target / entry.name)
                moved.append(target / entry.name)
    with suppress(OSError):
        fsync_path(target, directory=True)  # the moves on disk before the journal goes
    shutil.rmtree(commit, ignore_errors=True)
    return moved


def finish_committed_moves(target: str | os.PathLike[str]) -> list[Path]:
    """Complete the moves into the folder ``target`` that a killed
    :func:`move_files_into_folder` left after its commit; returns the files moved now
    (empty: nothing was left), for the caller to say so.

    Only an exact name (:func:`committed_folder_name_pattern`) that is a folder itself, not
    a link, is taken (by the rule of the build folders' clean-up), and of it only plain
    files; of several (only writes running at once leave more than one), the least recently
    changed first. Where ``target`` is no folder (removed since, with the files already moved
    into it), the rest cannot make a whole set and is removed. For a ``target`` that is a link
    to a folder, both beside the folder (where the commit is made) and beside the link (where
    an earlier pidcore made it) are looked in.
    """
    import shutil

    target = Path(target)
    found = []
    for place in dict.fromkeys((Path(os.path.abspath(target)), real_folder(target))):
        pattern = committed_folder_name_pattern(place)
        # no parent yet, or one that cannot be listed: nothing left there
        with suppress(OSError):
            found += [(entry.lstat().st_ctime, entry) for entry in _stale_entries(
                place.parent, lambda name, pattern=pattern: pattern.fullmatch(name) is not None,
                stat.S_ISDIR, 0.0, None)]
    found.sort()
    moved: list[Path] = []
    for _, commit in found:
        if target.is_dir():  # a link to a folder too: the outputs were moved through it
            moved += _finish_moves(commit, target)
        else:
            shutil.rmtree(commit, ignore_errors=True)
    return moved


def finished_moves_note(target: str | os.PathLike[str], *, kind: str) -> str:
    """:func:`finish_committed_moves` of ``target``, the folder a ``kind`` (``"calibration"``)
    writes its outputs into; returns the note that says what was moved ("" where nothing was
    left), for the caller to say."""
    moved = finish_committed_moves(target)
    if not moved:
        return ""
    return (f"{target}: a {kind} killed while moving its outputs into it had left "
            f"{len(moved)} of them to move ({', '.join(sorted(p.name for p in moved))}); "
            f"moved now, so it holds that {kind}'s whole set, not a mix with the earlier "
            "one")


def finish_moves_before_reading(target: str | os.PathLike[str], *, kind: str,
                                writer: str) -> str:
    """For every reader of the folder ``target`` a ``kind`` writes with ``writer`` (the call
    that writes it): finish the moves a killed write left (:func:`finished_moves_note`, as a
    database replays its journal on open), so that a reader never gets a mix of two; returns
    the note.

    Raises
    ------
    ParameterError
        Where the moves cannot be finished (a read-only folder): naming the folder and what
        to run.
    """
    from .errors import ParameterError

    try:
        return finished_moves_note(target, kind=kind)
    except OSError as exc:
        raise ParameterError(
            f"{target}: holds the half-moved outputs of a killed {kind} (a mix of two "
            f"{kind}s) and they cannot be finished here ({exc.strerror}); make it writable "
            f"and read it again, or write the {kind} into it again ({writer})") from None


@contextmanager
def atomic_path(path: str | os.PathLike[str], *, durable: bool = True) -> Iterator[Path]:
    """Yield a new empty temporary file beside ``path`` for a writer to fill (by its path:
    h5py, pyuff, pandas, matplotlib); when the block ends without an exception, the file is
    fsync'ed (``durable``) and moved over ``path`` in one step.

    Any exception, KeyboardInterrupt included, removes the temporary file and leaves the file
    at ``path`` as it was (absent, if it was). Temporary files of ``path`` that a write killed
    outright left (SIGKILL, a power loss) are removed first, once older than
    :data:`pidcore.defaults.STALE_TEMPORARY_FILE_AGE_S`: the next write of a file cleans up
    after its killed one, as the store's next write does.
    """
    from .defaults import STALE_TEMPORARY_FILE_AGE_S

    target = Path(path)
    # a folder that cannot be listed (write-only) still gets the file
    with suppress(OSError):
        remove_stale_temporaries(target.parent, target.name.__eq__,
                                 min_age_s=STALE_TEMPORARY_FILE_AGE_S)
    tmp = temporary_path_for(target)
    os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
    try:
        yield tmp
        try:
            mode = stat.S_IMODE(target.stat().st_mode)
        except OSError:  # a new file (or none readable there: the rename will say)
            mode = new_file_mode()
        # after the writer: a read-only target's mode would have refused the writer's open
        os.chmod(tmp, mode)
        if durable:
            fsync_path(tmp)
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)  # gone after a rename; the failed write's otherwise
    if durable:
        # the rename itself made durable; some file systems cannot fsync a folder, and the
        # file is in place either way, so a failure here is not an error
        with suppress(OSError):
            fsync_path(target.parent if str(target.parent) else ".", directory=True)


def write_atomically(path: str | os.PathLike[str], data: bytes | str, *,
                     durable: bool = True, encoding: str = "utf-8") -> None:
    """Write ``data`` (text is encoded with ``encoding``) as the whole file at ``path``
    (:func:`atomic_path`): the previous file stays until the new one is complete."""
    raw = data.encode(encoding) if isinstance(data, str) else bytes(data)
    with atomic_path(path, durable=durable) as tmp, open(tmp, "wb") as file:
        file.write(raw)
