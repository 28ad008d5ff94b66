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


#: The exit status of a process :func:`run_killed_at_rename` ended (none of Python's own).
KILLED_STATUS = 86

#: Run first in the process of :func:`run_killed_at_rename`: ``arm_the_kill()``, called by
#: the script just before the write it tests, makes its rename number ``sys.argv[1]`` (from
#: 0) end the process with ``os._exit``, which runs no ``except``, ``finally`` or ``atexit``:
#: a SIGKILL's effect on the files. With ``sys.argv[2] == "exchange"`` the atomic swap of two
#: folders counts as one rename; otherwise it is made unavailable, so that the two-rename
#: fallback is what runs.
_KILLER = f'''
import os
import sys

import pidcore.atomic_files as atomic_files


def arm_the_kill():
    left = [int(sys.argv[1])]

    def killing(real):
        def step(*args, **kwargs):
            if left[0] == 0:
                os._exit({KILLED_STATUS})
            left[0] -= 1
            return real(*args, **kwargs)
        return step

    os.replace, os.rename = killing(os.replace), killing(os.rename)
    if sys.argv[2] == "exchange":
        atomic_files.exchange_paths = killing(atomic_files.exchange_paths)
    else:
        atomic_files.exchange_paths = lambda first, second: False
'''


def run_killed_at_rename(script: str, renames: int, *, exchange: bool, args: tuple[str, ...] = (),
                         cwd: Path) -> bool:
    """Run ``script`` (which calls ``arm_the_kill()`` before its write; ``sys.argv[3:]`` are
    ``args``) in a fresh interpreter killed at its rename number ``renames`` (counted from
    0); True if it was killed there, False if it finished with fewer renames. Any other end
    fails with its stderr."""
    import subprocess
    import sys

    import pidcore

    # the pidcore under test, wherever the interpreter's own install points
    here = str(Path(pidcore.__file__).resolve().parents[1])
    env = {**os.environ, "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join([here, *filter(None, [os.environ.get("PYTHONPATH")])])}
    done = subprocess.run([sys.executable, "-c", _KILLER + script, str(renames),
                           "exchange" if exchange else "two renames", *args],
                          cwd=cwd, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode in (0, KILLED_STATUS), done.stderr
    return done.returncode == KILLED_STATUS


def exchange_available(folder: Path) -> bool:
    """Whether the file system of ``folder`` swaps two folders in one step here."""
    from pidcore.atomic_files import exchange_paths

    first, second = folder / ".probe-first", folder / ".probe-second"
    first.mkdir()
    second.mkdir()
    try:
        return exchange_paths(first, second)
    finally:
        first.rmdir()
        second.rmdir()


def folder_contents(folder: Path) -> dict[str, bytes] | None:
    """Every file under ``folder`` by its path there -> its bytes; None where it is missing."""
    if not folder.exists():
        return None
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file()}


def calibration_outputs_script(stand_ins: str = "") -> str:
    """A script for :func:`run_killed_at_rename`: ``write_outputs`` of a calibration into
    ``sys.argv[3]``, each output a stand-in text naming ``sys.argv[4]`` (what the files hold
    is not what the kill tests test); ``stand_ins``, code run before the write, may replace
    some of them (``outputs.document_json``, ``outputs.specimen_text``)."""
    return (
        "from pathlib import Path\n"
        "from types import SimpleNamespace\n\n"
        "import pidcore.calibrate.outputs as outputs\n\n"
        "run = sys.argv[4]\n"
        'outputs.document_json = lambda document: f"calibration.json of {run}"\n'
        'for name in ("specimen_text", "summary_markdown", "summary_html"):\n'
        '    setattr(outputs, name, lambda result, name=name: f"{name} of {run}")\n'
        'for name in ("plot_predictions", "plot_pairs"):\n'
        "    setattr(outputs, name,\n"
        '            lambda result, path, name=name: Path(path).write_text(f"{name} of {run}"))\n'
        + stand_ins
        + "arm_the_kill()\n"
        "outputs.write_outputs(SimpleNamespace(full_document=dict), sys.argv[3])\n")


def fill_the_disk_at_file(monkeypatch, nth: int) -> list[Path]:
    """The disk full (ENOSPC) from the ``nth`` (from 1) file an output folder's build flushes
    on: :func:`pidcore.atomic_files.fsync_path` of it raises ``OSError(ENOSPC)`` naming it, as
    the write or flush of a file fails when the disk fills mid-way; returns the files flushed
    before it (the build got that far)."""
    import errno

    from pidcore import atomic_files

    real = atomic_files.fsync_path
    flushed: list[Path] = []

    def fsync_path(path, *, directory=False):
        if not directory:
            if len(flushed) + 1 >= nth:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
            flushed.append(Path(path))
        real(path, directory=directory)

    monkeypatch.setattr(atomic_files, "fsync_path", fsync_path)
    return flushed
