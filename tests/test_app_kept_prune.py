"""``pidcore specimen kept``: the specimen files the app keeps beside a store (by sha256), and
removing those that no record of the store and no waiting job needs; never one a record
names, never a file outside the kept folder, the store only read."""

from __future__ import annotations

import hashlib
import json
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
    return store_path, folder, kept


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
    assert sorted(p.name for p in store_path.parent.iterdir()) == [
        "app.h5", "app.h5.jobs.json", "app.h5.specimens"]  # no lock or temporary left
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
