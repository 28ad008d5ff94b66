"""An output folder whose outputs a command replaces whole (``report --out``, ``model damper
--out``, ``model figures --out``): built in a folder beside it, then swapped into place in one
step (:func:`pidcore.atomic_files.replace_folder`), so that the folder never holds the files of
two runs (a CSV at 50 % beside a JSON at 75 %, the figures of fills the last model did not
have) nor half of one.

Replacing a folder deletes everything in it, so each run leaves a record of exactly the files
it wrote (:data:`RECORD_NAME`: their paths in the folder and their SHA-256), and the next one
replaces the folder only where it holds those files alone, as they were written. A name
pattern was not enough: a user's ``figures/my_plot.png`` in a report, or
``sdc_vs_frequency_mydata.png`` beside the model's figures, looked like an output and was
deleted. So is refused, naming it:

* any file or folder the record does not list (a user's, or a link: no run writes one);
* a listed file whose content changed since (a user's edit of a written report, which the
  replacement would lose; a listed file deleted since loses nothing and is no refusal);
* a folder that is not empty and holds no record, or another command's: an earlier pidcore
  kept none, and its outputs cannot be told from files added to them since.

An ``--out`` that is a link to a folder stays a link: the folder it points to is the one
replaced, built beside that folder (a link renamed over was replaced by a real folder, and the
folder it pointed to left as it was).
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Callable, Iterable
from pathlib import Path

from . import interrupt
from .atomic_files import (
    fsync_tree,
    new_temporary_folder_for,
    real_folder,
    replace_folder,
    restore_previous_folder,
)
from .errors import ParameterError
from .interrupt import untouched

#: The record a run writes into its output folder: ``{"written_by": "pidcore <command>",
#: "files": {path in the folder (``/``-separated): SHA-256 of its bytes}}``.
RECORD_NAME = ".pidcore-outputs.json"


def _read_record(folder: Path) -> tuple[str, dict[str, str]] | None:
    """``(written_by, files)`` of ``folder``'s record; None where it has none that can be
    read (absent, not JSON, or not of the record's form)."""
    try:
        record = json.loads((folder / RECORD_NAME).read_text(encoding="utf-8"))
        written_by, files = record["written_by"], record["files"]
    except (OSError, ValueError, TypeError, KeyError):
        return None
    if not isinstance(written_by, str) or not isinstance(files, dict) or not all(
            isinstance(k, str) and isinstance(v, str) for k, v in files.items()):
        return None
    return written_by, files


def written_by(folder: str | os.PathLike[str], command: str) -> bool:
    """Whether ``folder`` holds the record of a run of ``pidcore command``: an earlier run's
    outputs, which a run killed while swapping may have left hidden beside its place."""
    record = _read_record(Path(folder))
    return record is not None and record[0] == f"pidcore {command}"


def _write_record(work: Path, command: str) -> None:
    """Record every file under the build folder ``work`` (the run's outputs) in it."""
    from .io import file_sha256

    files = {}
    for root, dirs, names in os.walk(work):
        dirs.sort()
        for name in sorted(names):
            path = Path(root, name)
            files[path.relative_to(work).as_posix()] = file_sha256(path)
    # ASCII JSON: a file name that is not UTF-8 is kept as its escapes, read back the same
    (work / RECORD_NAME).write_text(
        json.dumps({"written_by": f"pidcore {command}", "files": files}, indent=1) + "\n",
        encoding="ascii")


def _not_its_own(out: Path, command: str) -> str:
    """Why replacing the existing folder ``out`` would lose something that is not an unchanged
    output of ``pidcore command``'s last run there ("" where nothing)."""
    from .io import display_path, file_sha256

    entries = sorted(out.iterdir())
    if not entries:
        return ""
    record = _read_record(out)
    if record is None:
        return (f"is not empty ({display_path(entries[0].name)!r}, ...) and holds no record of "
                f"what pidcore wrote there ({RECORD_NAME}; an earlier pidcore kept none), so "
                "files added to it cannot be told from its outputs, and replacing them whole "
                "would delete them")
    by, files = record
    if by != f"pidcore {command}":
        return (f"holds the outputs of {by} (its {RECORD_NAME}), which pidcore {command} does "
                "not write and replacing them would delete")
    folders = {parent.as_posix() for name in files for parent in Path(name).parents}
    for root, dirs, names in os.walk(out):  # a link to a folder is listed, never followed
        dirs.sort()
        for name in sorted(dirs + names):
            path = Path(root, name)
            rel = path.relative_to(out).as_posix()
            if rel == RECORD_NAME:
                continue
            shown = display_path(rel)
            kept = rel in folders if name in dirs and not path.is_symlink() else (
                rel in files and path.is_file() and not path.is_symlink())
            if not kept:
                return (f"holds {shown!r}, which pidcore {command} did not write there and "
                        "replacing its earlier outputs whole would delete")
            if name in names and file_sha256(path) != files[rel]:
                return (f"holds {shown!r} changed since pidcore {command} wrote it, which "
                        "replacing its earlier outputs whole would lose")
    return ""


def _in_use(real: Path) -> str:
    """Why the folder ``real`` (:func:`real_folder`'s) cannot be replaced whole whatever it
    holds ("" where it can)."""
    if real.parent == real:  # nothing to build it beside nor rename
        return "is the file system's root, which cannot be an output folder replaced whole"
    try:
        here = Path(os.getcwd())  # resolved, as real is
    except OSError:  # the current folder was deleted: none to keep
        return ""
    if real == here or real in here.parents:
        # the shell's folder would be the one deleted, and it left in a folder that is gone
        return (f"is the current folder or holds it ({real}), which replacing whole would pull "
                "out from under the shell")
    return ""


def restore_previous(out: str | os.PathLike[str], command: str, *,
                     is_previous: Callable[[Path], bool] | None = None) -> Path | None:
    """:func:`pidcore.atomic_files.restore_previous_folder` for ``out`` (its link's folder):
    the earlier outputs of ``pidcore command`` a killed swap left hidden beside it
    (``is_previous``: which hidden folder is one, default one of this command's records) put
    back, or removed where ``out`` exists, and then only where they hold the files their record
    lists, unchanged (a user's file copied into one since is not deleted: refused, naming it).
    Returns the folder restored, None if none was."""
    return restore_previous_folder(
        real_folder(out), is_previous=is_previous or (lambda folder: written_by(folder, command)),
        why_kept=lambda folder: _not_its_own(folder, command))


def check_replaceable(out: str | os.PathLike[str], command: str, *, option: str) -> None:
    """Refuse an output folder ``out`` that replacing whole with ``pidcore command``'s
    outputs would lose anything of (see the module's docstring), naming it, in ``option``'s
    words (the library's ``"out_dir"``, the command line's flag); a new or empty folder, or the
    unchanged outputs of the command's last run there, are taken."""
    out = Path(out)
    real = real_folder(out)
    why = _in_use(real)
    if why:
        raise ParameterError(f"{option} {out}: {why}; choose a new or empty folder for "
                             f"{option}")
    if not real.is_dir():
        return
    why = _not_its_own(real, command)
    if why:
        raise ParameterError(f"{option} {out}: {why}; move it out or choose a new or empty "
                             f"folder for {option}")


def write_folder_whole(out: str | os.PathLike[str], command: str,
                       build: Callable[[Path], Iterable[str | os.PathLike[str]]], *,
                       option: str, mode: int | None = None,
                       is_previous: Callable[[Path], bool] | None = None) -> list[Path]:
    """Write ``pidcore command``'s outputs into ``out`` (its link's folder), replacing those of
    its last run there: ``build`` writes them into the folder it is given and returns their
    paths, which are returned as they lie under ``out``.

    ``out`` is checked first (:func:`check_replaceable`); the folder built gets the record of
    its files (:data:`RECORD_NAME`) and, where given, the permissions ``mode``. A run killed
    while swapping (where the system cannot swap in one step) left the earlier folder hidden
    beside it, which is put back first (:func:`restore_previous`, ``is_previous`` its)."""
    out = Path(out)
    real = real_folder(out)
    restore_previous(out, command, is_previous=is_previous)  # first: a hidden one is the earlier
    check_replaceable(out, command, option=option)
    real.parent.mkdir(parents=True, exist_ok=True)
    work = new_temporary_folder_for(real)
    try:
        paths = [Path(p) for p in build(work)]
        _write_record(work, command)
        if mode is not None:
            os.chmod(work, mode)
        fsync_tree(work)  # the files on disk before the rename that names them
        # the swap and the earlier folder's removal are one step for Ctrl-C: cut between
        # them, a '.<name>.*.old' folder was left beside it
        with interrupt.deferred():
            replace_folder(work, real)
    except BaseException:
        shutil.rmtree(work, ignore_errors=True)
        raise
    interrupt.raise_if_interrupted()
    return [out / p.relative_to(work) for p in paths]


def folder_identity(folder: str | os.PathLike[str]) -> tuple[int, int] | None:
    """``(device, inode)`` of a folder (a link's: the one it points to), None if there is
    none: :func:`write_folder_whole` puts a new folder in place, so a caller that took this
    before can tell after a Ctrl-C whether the outputs were written (identity changed) or the
    folder is as it was."""
    try:
        st = os.stat(folder)
    except OSError:
        return None
    return st.st_dev, st.st_ino


def identity_before(out: str | os.PathLike[str], command: str) -> tuple[int, int] | None:
    """:func:`folder_identity` of ``out`` before a run of ``pidcore command`` writes it, an
    earlier folder a killed swap hid put back first (:func:`restore_previous`, which the write
    does anyway): else the restored folder would pass for this run's after a Ctrl-C."""
    restore_previous(out, command)
    return folder_identity(out)


def interrupted_outputs(out: str | os.PathLike[str], before: tuple[int, int] | None) -> str:
    """What a Ctrl-C left of an output folder :func:`write_folder_whole` writes, from its
    :func:`identity_before` the run: the run's whole set of files, or the folder as it was
    (never part of them: it is replaced in one step)."""
    if folder_identity(out) != before:
        return f"{out} holds this run's whole set of files (written before the interrupt)"
    kept = f"{out} is as it was" if Path(out).exists() else untouched(out)
    return f"{kept} (its files are replaced whole or not at all)"
