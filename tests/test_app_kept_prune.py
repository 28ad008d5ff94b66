"""``pidcore specimen kept``: the specimen files the app keeps beside a store (by sha256), and
removing those that no record of the store and no waiting job needs; never one a record
names, never a file outside the kept folder, the store only read."""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

import pytest

from pidcore.app import jobs
from pidcore.app.kept_specimens import (
    keep_specimen,
    kept_specimens_folder,
    prune_kept_specimens,
    restore_specimen,
)
from pidcore.cli import main
from pidcore.dem import DemConfig
from pidcore.dem.persist import run_key, run_parameters
from pidcore.errors import ParameterError
from pidcore.specimen import Specimen
from pidcore.store import Store

STEEL = Path(__file__).resolve().parents[1] / "data_samples" / "specimens" / "steel_6mm.toml"


def _variant(name: str) -> bytes:
    # a specimen file of its own (its own sha256): the steel one under another name
    text = STEEL.read_text(encoding="utf-8")
    return text.replace('name = "steel_6mm"', f'name = "{name}"', 1).encode()


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def app_store(tmp_path):
    """A store with one DEM run of ``in_store``, a journal with a queued job of ``queued``,
    and three kept files: those two and ``unused``, which nothing needs."""
    store_path = tmp_path / "app.h5"
    folder = kept_specimens_folder(store_path)
    kept = {name: keep_specimen(folder, f"{name}.toml", _variant(name))[0]
            for name in ("in_store", "queued", "unused")}
    (case,) = jobs.plan_dem_cases([50.0], [5.0], [50.0], material="steel", direction="z")
    config = DemConfig(cells=1, steady_cycles=5000)
    specimen = Specimen.from_bytes(_variant("in_store"), source="in_store.toml")
    # the record a finished run of that file is saved with: its parameters name the hash
    Store(store_path).add_dem_run(run_key(case, config, specimen), {"sdc": 0.25},
                                  parameters=run_parameters(case, config, specimen))
    waiting = Specimen.from_bytes(_variant("queued"), source="queued.toml")
    jobs.write_journal(jobs.journal_path(store_path),
                       [jobs.DemJob("job0001", case, config, "k", waiting)])
    _age(folder.iterdir(), hours=48)  # last used two days ago: past the grace period
    return store_path, folder, kept


def _age(paths, *, hours: float) -> None:
    """Set the files' times ``hours`` back: when the app last used them."""
    then = time.time() - hours * 3600
    for path in paths:
        os.utime(path, (then, then))


def test_unused_kept_files_are_listed_then_removed_and_those_needed_are_kept(app_store,
                                                                             capsys):
    store_path, folder, kept = app_store
    (folder / "notes.txt").write_text("the user's own")
    store_before = _digest(store_path)
    files_before = sorted(p.name for p in folder.iterdir())
    in_store, queued, unused = (kept[n].sha256 for n in ("in_store", "queued", "unused"))

    assert main(["specimen", "kept", "--store", str(store_path)]) == 0  # a dry run
    lines = capsys.readouterr().out.splitlines()
    assert sorted(p.name for p in folder.iterdir()) == files_before
    said = {line.split()[0]: line for line in lines}
    assert "kept: record dem_runs/f50Hz_a5g_fill50pct_steel_z" in said[in_store]
    assert said[queued].endswith("kept: job job0001 (queued or running)")
    assert said[unused].endswith("unused: would be removed with --remove")
    assert "notes.txt: not a file the app keeps; left as it is" in lines

    assert main(["specimen", "kept", "--store", str(store_path), "--remove", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    needs = {f["sha256"]: f["referred_by"] for f in document["files"]}
    assert needs[in_store] == said[in_store].split("kept: ")[1]
    assert (needs[queued], needs[unused], document["removed"]) == (
        "job job0001 (queued or running)", None, True)
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        [f"{in_store}.json", f"{in_store}.toml", f"{queued}.json", f"{queued}.toml",
         "notes.txt"])
    assert _digest(store_path) == store_before  # only read
    # no lock or temporary left but the job table's lock file, which the app keeps there
    assert sorted(p.name for p in store_path.parent.iterdir()) == [
        "app.h5", "app.h5.jobs.json", "app.h5.jobs.json.lock", "app.h5.specimens"]
    # the kept ones still restore a reload's file; the removed one asks for an upload
    assert restore_specimen(folder, in_store).data == _variant("in_store")
    with pytest.raises(ParameterError, match="upload the specimen file again"):
        restore_specimen(folder, unused)

    # once the job is no longer waiting, its file is unused too; the record's never is
    jobs.write_journal(jobs.journal_path(store_path), [])
    removed = prune_kept_specimens(store_path, remove=True)
    assert [f.sha256 for f in removed.unused] == [queued]
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        [f"{in_store}.json", f"{in_store}.toml", "notes.txt"])


def test_a_path_outside_the_kept_folder_is_refused_and_nothing_is_removed(app_store, tmp_path,
                                                                          capsys):
    store_path, folder, kept = app_store
    unused = kept["unused"].sha256
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    copy = outside / f"{unused}.toml"  # named as a kept file, but not in the kept folder
    copy.write_bytes(_variant("unused"))
    (folder / f"{'0' * 64}.toml").symlink_to(copy)  # a link in the folder is never followed
    files_before = sorted(p.name for p in folder.iterdir())
    for named in (str(copy), str(folder / ".." / "app.h5"), str(folder / f"{'0' * 64}.toml")):
        assert main(["specimen", "kept", "--store", str(store_path), "--remove", named]) == 2
        err = capsys.readouterr().err.strip()
        assert err == (f"pidcore specimen kept: error: {named}: not a specimen file kept in "
                       f"{folder} (expected the sha256 of one, or the path of its .toml or "
                       ".json there); nothing was removed"), err
    assert sorted(p.name for p in folder.iterdir()) == files_before
    assert copy.read_bytes() == _variant("unused") and store_path.is_file()
    # the link is listed as not the app's and left; the unused file, named by its path, goes
    assert main(["specimen", "kept", "--store", str(store_path), "--remove",
                 str(folder / f"{unused}.toml")]) == 0
    out = capsys.readouterr().out
    assert f"{unused}  unused.toml" in out and "removed" in out
    assert not (folder / f"{unused}.toml").exists() and (folder / f"{'0' * 64}.toml").is_symlink()
    assert copy.read_bytes() == _variant("unused")


def test_an_unreadable_job_table_removes_nothing(app_store, capsys):
    # what its jobs run is then unknown: no file they may need is called unused
    store_path, folder, _ = app_store
    jobs.journal_path(store_path).write_text("{not json")
    files_before = sorted(p.name for p in folder.iterdir())
    assert main(["specimen", "kept", "--store", str(store_path), "--remove"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pidcore specimen kept: error: the job table of the last run of the "
                          f"app ({jobs.journal_path(store_path)}) cannot be read")
    assert len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in folder.iterdir()) == files_before


def test_a_hash_named_by_any_stored_field_keeps_its_file(tmp_path):
    # a calibration names the file it calibrated in its record, not as a DEM run does: every
    # field of every entry counts, not a list of known ones
    store_path = tmp_path / "app.h5"
    folder = kept_specimens_folder(store_path)
    kept, _ = keep_specimen(folder, "mine.toml", _variant("mine"))
    Store(store_path).add_dem_run("other", {"sdc": 0.1, "note": f"from {kept.sha256}."})
    found = prune_kept_specimens(store_path, remove=True)
    assert [f.referred_by for f in found.files] == ["record dem_runs/other"]
    assert (folder / f"{kept.sha256}.toml").read_bytes() == _variant("mine")


# --- removal against the app's writers: locks, the grace period, temporary files -------------

def _hold_journal_lock(store_path: Path):
    """The lock a runner holds from reading the job table to writing it (a submission):
    taken here as any app server takes it, ``flock`` on ``<store>.jobs.json.lock``."""
    import fcntl

    fd = os.open(f"{store_path}.jobs.json.lock", os.O_RDWR | os.O_CREAT, 0o644)
    fcntl.flock(fd, fcntl.LOCK_EX)
    return fd


def test_a_job_submitted_while_the_removal_waits_keeps_its_file(app_store):
    # a submission holds the job table's lock from reading it to writing it; a removal that
    # did not take it removed the file of a job queued meanwhile
    import threading

    store_path, folder, kept = app_store
    unused = kept["unused"]
    store_before = _digest(store_path)
    fd = _hold_journal_lock(store_path)  # a submission under way
    found = {}
    removal = threading.Thread(target=lambda: found.update(
        result=prune_kept_specimens(store_path, remove=True)))
    removal.start()
    removal.join(0.5)
    waited = removal.is_alive()
    (case,) = jobs.plan_dem_cases([50.0], [5.0], [50.0], material="steel", direction="z")
    config = DemConfig(cells=1, steady_cycles=5000)
    jobs.write_journal(jobs.journal_path(store_path), [  # the fixture's job, and the new one
        jobs.DemJob("job0001", case, config, "k", kept["queued"].specimen),
        jobs.DemJob("job0002", case, config, "k2", unused.specimen)])
    os.close(fd)  # the submission done
    removal.join(30)
    assert waited, "the removal did not wait for the job table's lock"
    by_hash = {f.sha256: f for f in found["result"].files}
    assert by_hash[unused.sha256].referred_by == "job job0002 (queued or running)"
    assert restore_specimen(folder, unused.sha256).data == _variant("unused")
    assert _digest(store_path) == store_before


def test_a_page_keeping_a_file_during_the_removal_finds_it_after(app_store, monkeypatch):
    # a page re-uploading a kept file found it there and did not write it; a removal that had
    # checked it unused just before then removed it, and the page's reload asked for it again
    import threading

    from pidcore.app import kept_specimens

    store_path, folder, kept = app_store
    unused = kept["unused"]
    page = {}

    def page_keeps_the_file() -> None:
        page["thread"] = threading.Thread(target=lambda: page.update(
            kept=keep_specimen(folder, "unused.toml", _variant("unused"))))
        page["thread"].start()
        page["thread"].join(0.5)
        page["waited"] = page["thread"].is_alive()

    monkeypatch.setattr(kept_specimens, "_checked_before_removal", page_keeps_the_file)
    found = prune_kept_specimens(store_path, remove=True)
    page["thread"].join(30)
    assert page["waited"], "the page kept its file between the removal's check and removal"
    assert [f.sha256 for f in found.unused] == [unused.sha256]  # removed, then kept again
    assert page["kept"][1] == ""  # kept for a reload, no problem said
    assert restore_specimen(folder, unused.sha256).data == _variant("unused")
    # and just used, it is left by the next removal
    again = prune_kept_specimens(store_path, remove=True)
    assert again.unused == () and (folder / f"{unused.sha256}.toml").is_file()


def test_a_file_used_within_the_grace_period_is_left_and_the_period_is_an_option(app_store,
                                                                               capsys):
    store_path, folder, kept = app_store
    unused = kept["unused"].sha256
    _age(folder.glob(f"{unused}.*"), hours=23)  # used 23 h ago: within the default 24 h
    store_before = _digest(store_path)
    assert main(["specimen", "kept", "--store", str(store_path), "--remove"]) == 0
    out = capsys.readouterr().out.splitlines()
    said = {line.split()[0]: line for line in out}
    assert said[unused].endswith("left: used by the app 23.0 h ago, within "
                                 "--keep-recent-hours 24"), said[unused]
    assert out[-1].endswith("0 unused (0 B) removed; files the app used in the last 24 h are "
                            "left (--keep-recent-hours)"), out[-1]
    assert (folder / f"{unused}.toml").is_file()
    # a shorter period removes it, and the JSON says when it was last used
    assert main(["specimen", "kept", "--store", str(store_path), "--remove", "--json",
                 "--keep-recent-hours", "22.5"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["keep_recent_hours"] == 22.5
    assert [f["sha256"] for f in document["files"] if f["left_because"] is None
            and f["referred_by"] is None] == [unused]
    assert not (folder / f"{unused}.toml").exists()
    assert _digest(store_path) == store_before
    # a bad period is one line, exit 2, nothing removed
    files_before = sorted(p.name for p in folder.iterdir())
    for bad in ("-1", "nan"):
        assert main(["specimen", "kept", "--store", str(store_path), "--remove",
                     "--keep-recent-hours", bad, "--json"]) == 2
        err = capsys.readouterr().err.strip()
        assert err == (f"pidcore specimen kept: error: keep-recent-hours {float(bad)!r}: "
                       "expected a number of hours, 0 or more"), err
    assert sorted(p.name for p in folder.iterdir()) == files_before


def test_keeping_or_restoring_a_file_marks_it_used(tmp_path):
    # a page that uploads a file kept two days ago (same hash: not written again), or that a
    # reload restores it for, uses it now: its age is counted from then
    store_path = tmp_path / "app.h5"
    folder = kept_specimens_folder(store_path)
    for use in (lambda k: keep_specimen(folder, "mine.toml", _variant("mine")),
                lambda k: restore_specimen(folder, k.sha256)):
        kept, _ = keep_specimen(folder, "mine.toml", _variant("mine"))
        _age(folder.iterdir(), hours=48)
        use(kept)
        found = prune_kept_specimens(store_path, remove=True)
        assert found.unused == () and found.files[0].left_because.startswith(
            "used by the app 0.0 h ago"), found.files[0]
        assert (folder / f"{kept.sha256}.toml").read_bytes() == _variant("mine")


def test_the_apps_calibration_holds_its_uploaded_file_while_it_runs(app_store):
    # the app's calibration runs in its own process, in no job table: a removal while it ran
    # took the file its page names (and the grace period may be shorter than the run)
    import types

    from pidcore.app.calibration import CalibrationRunner, CalibrationTask
    from pidcore.errors import PidcoreError

    store_path, folder, kept = app_store
    unused = kept["unused"]
    during = {}

    def calibrate(points, **kw):
        during["found"] = prune_kept_specimens(store_path, remove=True, recent_hours=0)
        raise PidcoreError("stopped by the test")

    api = types.SimpleNamespace(calibrate=calibrate, write_outputs=lambda r, f, wording=None: [])
    task = CalibrationTask(("fixture_mass_kg",), 3)
    CalibrationRunner(store_path)._run(api, task, [], ["fixture_mass_kg"], 2, None,
                                       unused.specimen)
    assert task.state == "failed" and "stopped by the test" in task.message
    by_hash = {f.sha256: f for f in during["found"].files}
    assert by_hash[unused.sha256].left_because == (
        "in use by the app now (a calibration of it runs)")
    assert during["found"].unused == ()
    # once it ended the file is no longer held
    after = prune_kept_specimens(store_path, remove=True, recent_hours=0)
    assert [f.sha256 for f in after.unused] == [unused.sha256]
    assert not (folder / f"{unused.sha256}.toml").exists()


def test_temporary_files_of_killed_writes_are_removed_by_exact_name_once_old(app_store,
                                                                             capsys):
    # a kill -9 or a power loss during a write leaves .<name>.<16 hex>.tmp: never cleaned
    store_path, folder, kept = app_store
    sha = kept["in_store"].sha256
    hex16 = "0123456789abcdef"
    stale = [folder / f".{sha}.toml.{hex16}.tmp", folder / f".{sha}.json.{hex16}.tmp",
             store_path.parent / f".app.h5.jobs.json.{hex16}.tmp"]
    fresh = folder / f".{sha}.toml.fedcba9876543210.tmp"  # a write under way (or just killed)
    users = [folder / f".{sha}.toml.0123.tmp",            # not the helper's 16 hex digits
             folder / f".notes.txt.{hex16}.tmp",          # not of a file the app keeps there
             folder / f".{sha}.toml.{hex16}.tmp.keep",    # more after the suffix
             store_path.parent / f".app.h5.jobs.json.old.{hex16}.tmp",  # another file's
             store_path.parent / f".other.h5.jobs.json.{hex16}.tmp"]
    for path in [*stale, fresh, *users]:
        path.write_text("partial")
    (folder / f".{sha}.json.{'a' * 16}.tmp").mkdir()  # not a plain file
    _age([*stale, *users, folder / f".{sha}.json.{'a' * 16}.tmp"], hours=48)
    store_before = _digest(store_path)

    assert main(["specimen", "kept", "--store", str(store_path)]) == 0  # a dry run: none
    out = capsys.readouterr().out.splitlines()
    for path in stale:
        assert f"{path.name}: temporary file of a killed write; would be removed with " \
               "--remove" in out
    # limited to some kept files, it removes no temporary file either
    assert main(["specimen", "kept", "--store", str(store_path), "--remove", sha]) == 0
    capsys.readouterr()
    assert all(p.exists() for p in [*stale, fresh, *users])
    assert main(["specimen", "kept", "--store", str(store_path), "--remove"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert not any(p.exists() for p in stale)
    assert fresh.exists() and all(p.read_text() == "partial" for p in users)
    assert (folder / f".{sha}.json.{'a' * 16}.tmp").is_dir()
    for path in stale:
        assert f"{path.name}: temporary file of a killed write; removed" in out
    assert f"{fresh.name}: not a file the app keeps; left as it is" in out
    assert _digest(store_path) == store_before
    assert restore_specimen(folder, sha).data == _variant("in_store")


def test_a_calibration_starting_while_a_listing_looks_at_its_file_still_holds_it(app_store):
    # a listing looks whether the app holds a file by taking its lock for a moment; a
    # calibration that started in that moment held nothing, and a removal took its file
    import fcntl
    import threading

    from pidcore.app.kept_specimens import holding_kept_specimen

    store_path, folder, kept = app_store
    unused = kept["unused"].sha256
    fd = os.open(folder / f"{unused}.toml", os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)  # the listing's look
    looked = threading.Event()

    def look_over() -> None:
        os.close(fd)
        looked.set()

    threading.Timer(0.3, look_over).start()  # ... over a moment later
    with holding_kept_specimen(store_path, unused):
        assert looked.wait(10)
        found = prune_kept_specimens(store_path, remove=True, recent_hours=0)
    assert {f.sha256: f.left_because for f in found.files}[unused] == (
        "in use by the app now (a calibration of it runs)")
    assert (folder / f"{unused}.toml").is_file()


def test_a_store_no_app_ran_on_gets_no_job_table_lock_file(tmp_path, capsys):
    # --remove took the job table's lock by creating <store>.jobs.json.lock beside a store on
    # which no app ever ran (no journal, no lock file): a file left behind by a command that
    # says it only reads the store. No job can wait there: a runner makes the lock file
    # before it writes the journal, and queues a job only in that step.
    store_path = tmp_path / "app.h5"
    folder = kept_specimens_folder(store_path)
    kept, _ = keep_specimen(folder, "mine.toml", _variant("mine"))
    Store(store_path).add_dem_run("other", {"sdc": 0.1})
    _age(folder.iterdir(), hours=48)
    store_before = _digest(store_path)
    beside = sorted(p.name for p in tmp_path.iterdir())
    assert beside == ["app.h5", "app.h5.specimens"]
    assert main(["specimen", "kept", "--store", str(store_path)]) == 0
    assert f"{kept.sha256}  mine.toml" in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == beside
    assert main(["specimen", "kept", "--store", str(store_path), "--remove", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert [f["sha256"] for f in document["files"]] == [kept.sha256]
    assert document["removed"] is True and list(folder.iterdir()) == []  # removed, unused
    assert sorted(p.name for p in tmp_path.iterdir()) == beside  # no new file beside it
    assert _digest(store_path) == store_before
    # a submission under way (the lock file made, the journal not yet written): the
    # removal still waits for its lock
    import threading

    kept, _ = keep_specimen(folder, "mine.toml", _variant("mine"))
    _age(folder.iterdir(), hours=48)
    fd = _hold_journal_lock(store_path)
    removal = threading.Thread(target=prune_kept_specimens, args=(store_path,),
                               kwargs={"remove": True})
    try:
        removal.start()
        removal.join(0.5)
        waited = removal.is_alive()
        still_there = (folder / f"{kept.sha256}.toml").is_file()
    finally:
        os.close(fd)
        removal.join(30)
    assert waited and still_there, "the removal did not wait for the job table's lock"
    assert not (folder / f"{kept.sha256}.toml").exists()  # removed once the lock was free


def test_a_store_that_is_not_there_is_named_not_listed_as_keeping_nothing(tmp_path, capsys):
    # a mistyped --store read "no specimen files kept in ...", as if the app's store had none
    missing = tmp_path / "pidcore_stor.h5"
    assert main(["specimen", "kept", "--store", str(missing)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and f"{missing}: no such store" in err
    # a store with no kept folder keeps nothing, and says so
    from pidcore.store import Store

    with Store(tmp_path / "s.h5").transaction():
        pass  # an empty store, as the app makes
    assert main(["specimen", "kept", "--store", str(tmp_path / "s.h5")]) == 0
    assert "no specimen files kept" in capsys.readouterr().out
    assert not (tmp_path / "pidcore_stor.h5").exists()  # nothing was created for the typo
