"""An ``--out`` folder whose outputs a command replaces whole, as ``report --out`` replaces its
report: built in a folder beside it, then swapped into place in one step
(:func:`pidcore.atomic_files.replace_folder`), so that the folder never holds the files of two
runs (a CSV at 50 % beside a JSON at 75 %, the figures of fills the last model did not have)
nor half of one. A folder holding anything the command does not write is refused, never
replaced: replacing it would delete that.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

from .. import interrupt
from ..atomic_files import (
    fsync_tree,
    new_temporary_folder_for,
    replace_folder,
    restore_previous_folder,
)
from ..errors import ParameterError


def _foreign_entry(out: Path, ours: Callable[[str], bool]) -> str:
    """The first entry of ``out`` that is not a plain file named as ``ours`` accepts ("" if
    none)."""
    for entry in sorted(out.iterdir()):
        if not ours(entry.name) or entry.is_symlink() or not entry.is_file():
            return entry.name
    return ""


def check_replaceable(out: Path, ours: Callable[[str], bool], command: str) -> None:
    """Refuse an ``--out`` folder holding an entry that ``command`` (``"model damper"``) does
    not write (``ours``: its file names), which replacing the folder would delete; a new or
    empty folder, or one of the command's earlier outputs alone, is taken."""
    if not out.is_dir():
        return
    foreign = _foreign_entry(out, ours)
    if foreign:
        raise ParameterError(
            f"--out {out}: holds {foreign!r}, which pidcore {command} does not write and "
            "replacing its earlier outputs whole would delete; move it out or choose a new or "
            "empty folder for --out")


def write_folder_whole(out: Path, ours: Callable[[str], bool], command: str,
                       build: Callable[[Path], list[Path]]) -> list[Path]:
    """Write ``command``'s outputs into ``out``, replacing whatever of them is there: ``build``
    writes them into the folder it is given and returns their paths, which are returned as
    they lie in ``out``. ``out`` is checked first (:func:`check_replaceable`); a run killed
    while swapping (where the system cannot swap in one step) is settled by the next one
    (:func:`pidcore.atomic_files.restore_previous_folder`)."""
    def earlier(folder: Path) -> bool:
        return not _foreign_entry(folder, ours)

    restore_previous_folder(out, is_previous=earlier)  # first: a hidden one is the earlier
    check_replaceable(out, ours, command)
    out.parent.mkdir(parents=True, exist_ok=True)
    work = new_temporary_folder_for(out)
    try:
        paths = build(work)
        fsync_tree(work)  # the files on disk before the rename that names them
        # the swap and the earlier folder's removal are one step for Ctrl-C
        with interrupt.deferred():
            replace_folder(work, out)
    except BaseException:
        shutil.rmtree(work, ignore_errors=True)
        raise
    interrupt.raise_if_interrupted()
    return [out / Path(p).relative_to(work) for p in paths]

