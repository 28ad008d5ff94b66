"""Build folders a killed ``--out`` would have left beside its target, for the clean-up tests."""

from __future__ import annotations

import os
from pathlib import Path

from pidcore.defaults import STALE_TEMPORARY_FILE_AGE_S


def leave_build_folders(target: Path, holding: str, hex_pairs: tuple[str, str]) -> dict[str, str]:
    """Beside ``target``: a build folder older than the clean-up age ("stale"), one a minute
    younger than it ("fresh", a live run's) and a user's ``.<name>.backup`` as old as the stale
    one, each holding a file ``holding``; returns their names by those keys."""
    stale_hex, fresh_hex = hex_pairs
    names = {"stale": f".{target.name}.{stale_hex * 8}.tmpdir",
             "fresh": f".{target.name}.{fresh_hex * 8}.tmpdir",
             "user's": f".{target.name}.backup"}
    for key, name in names.items():
        folder = target.parent / name
        folder.mkdir()
        (folder / holding).write_text("{}" if holding.endswith(".json") else "left")
        age = STALE_TEMPORARY_FILE_AGE_S + (60 if key != "fresh" else -60)
        when = os.stat(folder).st_mtime - age
        os.utime(folder, (when, when))
    return names
