"""Files a user relies on are written whole or not at all (:mod:`pidcore.atomic_files`): a
failing writer, Ctrl-C or a full disk leaves the previous file and no temporary file."""

from __future__ import annotations

import hashlib
import json
import os
import resource
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pidcore import atomic_files
from pidcore.app import jobs, kept_specimens
from pidcore.io import write_measurement
from pidcore.records import Channel, Measurement
from pidcore.report.figures import save_figure

ROOT = Path(__file__).resolve().parents[1]


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _only(folder: Path) -> list[str]:
    # every entry, hidden ones included: a left temporary file is one of them
    return sorted(p.name for p in folder.iterdir())


def _with_file_size_limit(limit_bytes: int):
    """A ``preexec_fn``: the child may write no file beyond ``limit_bytes`` (``ulimit -f``;
    a full disk fails the same writes with ENOSPC). Python ignores SIGXFSZ, so the write
    fails with EFBIG instead of killing the child."""
    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    return limit


def test_a_writer_that_fails_half_way_leaves_the_previous_file_and_no_temporary(tmp_path):
    target = tmp_path / "table.csv"
    target.write_text("old,whole\n1,2\n")
    before = _digest(target)
    for failure in (KeyboardInterrupt, OSError):
        with pytest.raises(failure), atomic_files.atomic_path(target) as tmp:
            tmp.write_text("new,half")  # the writer got this far
            raise failure()
        assert _digest(target) == before and _only(tmp_path) == ["table.csv"]
    atomic_files.write_atomically(target, "new,whole\n3,4\n")
    assert target.read_text() == "new,whole\n3,4\n" and _only(tmp_path) == ["table.csv"]


def test_the_rename_comes_after_the_file_and_before_the_folder_is_flushed(tmp_path,
                                                                          monkeypatch):
    # a rename can reach the disk before the data it names: without the fsync a power loss
    # right after a journal's rewrite left an empty journal, whose queued jobs were lost
    steps: list[str] = []
    real_fsync, real_replace = os.fsync, os.replace

    def fsync(fd: int) -> None:
        steps.append("fsync folder" if stat.S_ISDIR(os.fstat(fd).st_mode) else "fsync file")
        real_fsync(fd)

    def replace(source, target) -> None:
        steps.append("rename")
        real_replace(source, target)

    monkeypatch.setattr(os, "fsync", fsync)
    monkeypatch.setattr(os, "replace", replace)
    jobs.write_journal(jobs.journal_path(tmp_path / "app.h5"), [])
    assert steps == ["fsync file", "rename", "fsync folder"]
    assert json.loads((tmp_path / "app.h5.jobs.json").read_text())["jobs"] == []


def test_a_full_disk_at_the_flush_keeps_no_kept_specimen_and_no_temporary(tmp_path,
                                                                          monkeypatch):
    # the kept file is the one a reload restores: one the disk could not hold must not be
    # left under its hash as an empty file (which a restore then refused as another file)
    data = (ROOT / "data_samples" / "specimens" / "steel_6mm.toml").read_bytes()
    folder = tmp_path / "app.h5.specimens"

    def full(fd: int) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", full)
    kept, problem = kept_specimens.keep_specimen(folder, "steel_6mm.toml", data)
    assert problem == (f"steel_6mm.toml: not kept for a page reload: cannot write {folder} "
                       "(No space left on device); upload it again after a reload")
    assert _only(folder) == []
    monkeypatch.undo()
    kept, problem = kept_specimens.keep_specimen(folder, "steel_6mm.toml", data)
    assert problem == "" and _only(folder) == [f"{kept.sha256}.json", f"{kept.sha256}.toml"]
    assert (folder / f"{kept.sha256}.toml").read_bytes() == data


def test_model_tables_past_a_file_size_limit_leave_the_previous_tables_whole(tmp_path):
    # `pidcore model damper --out` wrote the CSV in place: a full disk (or Ctrl-C) left half
    # a CSV that read as a shorter table of plausible numbers
    from pidcore.model import write_damper_table

    small = pd.DataFrame({"fill_percent": [50.0], "c_eq_per_coupon": [1.5]})
    write_damper_table(small, tmp_path, provenance={"model": "old"})
    before = {name: _digest(tmp_path / name) for name in _only(tmp_path)}
    code = textwrap.dedent(f"""
        import numpy as np, pandas as pd
        from pidcore.model import write_damper_table
        rows = 20_000  # about 1 MB of CSV: past the limit below
        table = pd.DataFrame({{"fill_percent": np.linspace(0, 100, rows),
                               "c_eq_per_coupon": np.linspace(1, 2, rows)}})
        try:
            write_damper_table(table, {str(tmp_path)!r})
        except OSError as exc:
            print(exc.errno)
    """)
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120, env={**os.environ, "PYTHONPATH": str(ROOT)},
                         preexec_fn=_with_file_size_limit(200_000))
    assert run.returncode == 0 and run.stdout.strip() == "27", run.stderr[-2000:]  # EFBIG
    assert {name: _digest(tmp_path / name) for name in _only(tmp_path)} == before
    assert sorted(before) == ["equivalent_damper.csv", "equivalent_damper.json"]


def test_a_figure_interrupted_while_drawn_leaves_the_previous_figure(tmp_path, monkeypatch):
    # save_figure wrote the PNG in place while matplotlib drew it: Ctrl-C mid-way left a
    # truncated PNG under the figure's name
    import matplotlib.figure

    fig = matplotlib.figure.Figure()
    fig.subplots().plot([0, 1], [0, 1])
    old = save_figure(fig, tmp_path, "sdc")
    before = {p.name: _digest(p) for p in old}
    real = matplotlib.figure.Figure.savefig

    def interrupted(self, target, *args, **kwargs):
        # the first bytes reach the target, then Ctrl-C
        if hasattr(target, "write"):
            target.write(b"\x89PNG\r\n")
        else:
            Path(target).write_bytes(b"\x89PNG\r\n")
        raise KeyboardInterrupt

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", interrupted)
    with pytest.raises(KeyboardInterrupt):
        save_figure(fig, tmp_path, "sdc")
    assert {p.name: _digest(p) for p in old} == before
    assert _only(tmp_path) == ["sdc.png", "sdc.svg"]
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", real)


def test_an_exported_measurement_has_the_permissions_of_any_new_file(tmp_path):
    # the temporary file of the atomic write was made by mkstemp, 0o600: an exported CSV
    # was unreadable to the colleagues a plain write (0o666 less the umask) let read it
    channel = Channel(name="Force", quantity="force", data=np.sin(np.arange(64.0)),
                      sample_rate_hz=1024.0, source_unit="N")
    measurement = Measurement(channels=(channel,), source="f.csv")
    previous = os.umask(0o022)
    try:
        write_measurement(measurement, tmp_path / "f.csv", "csv")
        assert stat.S_IMODE((tmp_path / "f.csv").stat().st_mode) == 0o644
        os.chmod(tmp_path / "f.csv", 0o640)  # a file the user restricted stays so
        write_measurement(measurement, tmp_path / "f.csv", "csv")
        assert stat.S_IMODE((tmp_path / "f.csv").stat().st_mode) == 0o640
    finally:
        os.umask(previous)
    assert _only(tmp_path) == ["f.csv"]


def test_the_new_file_mode_reads_the_umask_without_opening_it_to_other_threads(monkeypatch):
    # os.umask can only be read by setting it; set to 0 even for a moment, a file the app's
    # job thread created meanwhile would be world-writable. The mode must follow the real
    # umask, read from /proc where Linux states it, by set-and-reset (never 0) elsewhere.
    previous = os.umask(0o027)
    try:
        assert atomic_files.new_file_mode() == 0o640
        seen = []
        real_umask = os.umask

        def recording_umask(mask):
            seen.append(mask)
            return real_umask(mask)

        monkeypatch.setattr(atomic_files.os, "umask", recording_umask)
        if Path("/proc/self/status").is_file():
            assert atomic_files.new_file_mode() == 0o640
            assert seen == []  # read, not set
        real_open = open

        def no_proc(path, *args, **kwargs):
            if str(path).startswith("/proc/"):
                raise OSError("no /proc here")
            return real_open(path, *args, **kwargs)

        monkeypatch.setattr("builtins.open", no_proc)
        assert atomic_files.new_file_mode() == 0o640
        assert seen and 0 not in seen  # the fallback never opens the mask
        assert real_umask(0o027) == 0o027  # and leaves it as it was
    finally:
        os.umask(previous)


def test_the_next_write_of_a_file_removes_the_temporary_files_killed_writes_of_it_left(
        tmp_path):
    # a kill -9 or a power loss mid-write leaves .<name>.<16 hex>.tmp beside an export, and
    # nothing ever removed it; only that file's exact names, and only once a day old (a live
    # writer's is younger: its writes set its time)
    import time

    target = tmp_path / "case.csv"
    stale = tmp_path / ".case.csv.0123456789abcdef.tmp"
    fresh = tmp_path / ".case.csv.fedcba9876543210.tmp"  # another writer's, under way
    users = [tmp_path / ".case.csv.backup.tmp",           # not 16 hex digits
             tmp_path / ".case.csv.old.csv.0123456789abcdef.tmp",  # case.csv.old.csv's
             tmp_path / ".case.csv.0123456789abcdef.tmp.txt"]
    for path in [stale, fresh, *users]:
        path.write_text("partial")
    day_and_a_minute = time.time() - 24 * 3600 - 60
    for path in [stale, *users]:
        os.utime(path, (day_and_a_minute, day_and_a_minute))
    hour_ago = time.time() - 3600
    os.utime(fresh, (hour_ago, hour_ago))
    atomic_files.write_atomically(target, "f [Hz]\n50\n")
    assert target.read_text() == "f [Hz]\n50\n"
    assert not stale.exists()
    assert fresh.read_text() == "partial" and all(p.read_text() == "partial" for p in users)


def _left_build_folder(target: Path, name: str, *, age_s: float) -> Path:
    """A folder ``name`` beside ``target`` as a killed build leaves it: holding a file, last
    changed ``age_s`` ago (the file's creation set the folder's time, so it is set after)."""
    folder = target.parent / name
    folder.mkdir()
    (folder / "calibration.json").write_text("{}")
    old = os.stat(folder).st_mtime - age_s
    os.utime(folder, (old, old))
    return folder


def test_a_killed_builds_folder_is_removed_by_the_next_build_of_its_target_only(tmp_path):
    # `pidcore calibrate --out cal` / `pidcore report --out rp` killed outright (kill -9, a
    # power loss) left their hidden build folders beside the target for ever
    from pidcore.defaults import STALE_TEMPORARY_FILE_AGE_S

    target = tmp_path / "cal"
    day = STALE_TEMPORARY_FILE_AGE_S
    stale = _left_build_folder(target, f".cal.{'0a' * 8}.tmpdir", age_s=day + 60)
    fresh = _left_build_folder(target, f".cal.{'0b' * 8}.tmpdir", age_s=day - 60)  # live
    kept = [fresh,
            _left_build_folder(target, ".cal.backup", age_s=10 * day),  # a user's
            _left_build_folder(target, f".cal.{'0c' * 8}.tmpdir.keep", age_s=10 * day),
            _left_build_folder(target, f".cal.x.{'0d' * 8}.tmpdir", age_s=10 * day),  # cal.x's
            _left_build_folder(target, f".cal.{'0e' * 7}.tmpdir", age_s=10 * day)]  # 14 hex
    work = atomic_files.new_temporary_folder_for(target)
    assert atomic_files.temporary_folder_name_pattern(target).fullmatch(work.name)
    assert work.is_dir() and list(work.iterdir()) == []
    assert not stale.exists()
    for folder in kept:
        assert (folder / "calibration.json").read_text() == "{}", folder.name
    assert _only(tmp_path) == sorted([work.name, *(f.name for f in kept)])


def test_clearing_build_folders_never_follows_a_link(tmp_path):
    # a link named like a build folder, and a link inside a stale one: what they point at is
    # not the build's and must survive (rmtree of the link's target would delete it)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    precious = elsewhere / "precious.txt"
    precious.write_text("keep")
    beside = tmp_path / "work"
    beside.mkdir()
    target = beside / "rp"
    linked = beside / f".rp.{'1f' * 8}.tmpdir"
    linked.symlink_to(elsewhere, target_is_directory=True)
    stale = _left_build_folder(target, f".rp.{'2e' * 8}.tmpdir", age_s=1e9)
    (stale / "into_elsewhere").symlink_to(elsewhere, target_is_directory=True)
    (stale / "the_file").symlink_to(precious)
    os.utime(stale, (1.0, 1.0))
    os.utime(linked, (1.0, 1.0), follow_symlinks=False)
    os.utime(elsewhere, (1.0, 1.0))
    removed = atomic_files.remove_stale_temporary_folders(target, min_age_s=3600.0)
    assert removed == [stale] and not stale.exists()
    assert linked.is_symlink() and precious.read_text() == "keep"
    assert sorted(p.name for p in elsewhere.iterdir()) == ["precious.txt"]


def test_finishing_committed_moves_takes_only_plain_files_of_its_own_exact_name(tmp_path):
    # the roll-forward of a killed move_files_into_folder: only the committed folder of
    # this target is finished, its links are no file of the build's (moving one would put a
    # link where the output was), and a target removed since leaves nothing to finish into
    elsewhere = tmp_path / "elsewhere.txt"
    elsewhere.write_text("keep")
    target = tmp_path / "cal"
    target.mkdir()
    (target / "summary.md").write_text("earlier")
    (target / "notes.txt").write_text("a user's")
    committed = tmp_path / f".cal.{'1a' * 8}.commit"
    committed.mkdir()
    (committed / "summary.md").write_text("new")
    (committed / "calibration.json").symlink_to(elsewhere)
    others = [tmp_path / ".cal.backup.commit", tmp_path / f".cal.x.{'2b' * 8}.commit"]
    for folder in others:  # a user's; target cal.x's
        folder.mkdir()
        (folder / "summary.md").write_text("not cal's")
    moved = atomic_files.finish_committed_moves(target)
    assert moved == [target / "summary.md"]
    assert {p.name: p.read_text() for p in target.iterdir()} == {"summary.md": "new",
                                                                "notes.txt": "a user's"}
    assert _only(tmp_path) == sorted(["cal", "elsewhere.txt", *(f.name for f in others)])
    assert elsewhere.read_text() == "keep"
    # nothing left: nothing said
    assert atomic_files.finish_committed_moves(target) == []
    # a target that is a link to a folder (--out given as one) is finished through the link
    linked = tmp_path / "cal"
    target = tmp_path / "link"
    target.symlink_to(linked, target_is_directory=True)
    through = tmp_path / f".link.{'3c' * 8}.commit"
    through.mkdir()
    (through / "summary.md").write_text("newer")
    assert atomic_files.finish_committed_moves(target) == [target / "summary.md"]
    assert (linked / "summary.md").read_text() == "newer" and not through.exists()
    # where move_files_into_folder commits now, beside the folder the link points to: found
    # through the link too (a reader given the link's path missed it and read a mix of two)
    beside = tmp_path / f".cal.{'4d' * 8}.commit"
    beside.mkdir()
    (beside / "summary.md").write_text("newest")
    assert atomic_files.finish_committed_moves(target) == [target / "summary.md"]
    assert (linked / "summary.md").read_text() == "newest" and not beside.exists()
    target.unlink()
    target = linked
    # cal removed after the kill: the files moved before it went with it, the rest is no set
    committed.mkdir()
    (committed / "summary.md").write_text("new")
    (target / "summary.md").unlink()
    (target / "notes.txt").unlink()
    target.rmdir()
    assert atomic_files.finish_committed_moves(target) == []
    assert _only(tmp_path) == sorted(["elsewhere.txt", *(f.name for f in others)])


def test_exchanging_paths_swaps_two_folders_or_says_it_cannot(tmp_path, monkeypatch):
    # the swap is what keeps a replaced report folder in place at every instant; where it
    # cannot be made, False (nothing changed) lets the caller fall back, any other failure
    # is an error naming the paths
    first, second = tmp_path / "first", tmp_path / "second"
    for folder in (first, second):
        folder.mkdir()
        (folder / "name.txt").write_text(folder.name)
    if not atomic_files.exchange_paths(first, second):
        pytest.skip("this file system cannot swap two folders in one step")
    assert (first / "name.txt").read_text() == "second"
    assert (second / "name.txt").read_text() == "first"
    with pytest.raises(FileNotFoundError, match="missing"):
        atomic_files.exchange_paths(tmp_path / "missing", first)
    assert (first / "name.txt").read_text() == "second"
    monkeypatch.setattr(sys, "platform", "darwin")
    assert atomic_files.exchange_paths(first, second) is False
    assert (first / "name.txt").read_text() == "second"


@pytest.mark.parametrize("exchange", [True, False], ids=["exchange", "two renames"])
def test_a_folder_replacing_a_link_leaves_what_it_linked_and_nothing_beside(tmp_path,
                                                                          monkeypatch, exchange):
    # a target that is a link to a folder is moved aside (or swapped) as the link: what it
    # linked is never removed, and the link itself is not left beside the target for ever
    # (rmtree refuses a link); a dangling link is replaced as before
    if not exchange:
        monkeypatch.setattr(atomic_files, "exchange_paths", lambda first, second: False)
    linked = tmp_path / "linked"
    linked.mkdir()
    (linked / "report.csv").write_text("linked")
    beside = tmp_path / "beside"
    beside.mkdir()
    for target_of_link in (linked, tmp_path / "gone"):
        target = beside / "rp"
        target.symlink_to(target_of_link, target_is_directory=True)
        new = atomic_files.new_temporary_folder_for(target)
        (new / "report.csv").write_text("new")
        atomic_files.replace_folder(new, target)
        assert not target.is_symlink() and (target / "report.csv").read_text() == "new"
        assert _only(beside) == ["rp"]
        assert _only(linked) == ["report.csv"] and (linked / "report.csv").read_text() == "linked"
        (target / "report.csv").unlink()
        target.rmdir()


def test_a_build_folder_for_dot_is_made_beside_the_folder_dot_names(tmp_path, monkeypatch):
    # `calibrate --out .` built its files in Path(".").with_name(...): "PosixPath('.') has an
    # empty name" after its DEM runs; "." and ".." are the folders they name
    from pidcore.atomic_files import temporary_folder_name_pattern, temporary_folder_path_for

    here = tmp_path / "work"
    (here / "sub").mkdir(parents=True)
    monkeypatch.chdir(here / "sub")
    for given, named in ((".", here / "sub"), ("..", here), ("../sub/.", here / "sub")):
        work = temporary_folder_path_for(given)
        assert work.parent == named.parent
        assert temporary_folder_name_pattern(given).fullmatch(work.name)
