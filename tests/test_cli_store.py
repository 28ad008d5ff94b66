"""``pidcore store list / verify / remove``: the store's records seen, checked and removed from
the command line, with the one-line refusals of every other command."""

from __future__ import annotations

import json
import os

import h5py
from _cli_runs import refusal
from _shaker_files import file_sha256

from pidcore.cli import main
from pidcore.store import Store, manage
from pidcore.store.lock import exclusive_lock


def test_list_names_every_record_by_key_with_units_in_the_headers(records_store_copy, capsys):
    path, keys = records_store_copy
    assert main(["store", "list", "--store", str(path), "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert [r["key"] for r in listed["measurements"]] == keys["measurements"]
    assert {r["key"]: r["reports"] for r in listed["analyses"]} == {
        keys["older"]: "superseded", keys["newer"]: "newest", keys["other"]: "newest"}
    runs = {r["key"]: r["design_of"] for r in listed["dem-runs"]}
    assert runs == {**dict.fromkeys(keys["design"], keys["calibration"]), keys["own_run"]: ""}
    assert [r["key"] for r in listed["calibrations"]] == [keys["calibration"]]
    assert main(["store", "list", "--store", str(path), "--section", "dem-runs"]) == 0
    text = capsys.readouterr().out
    assert "dem-runs (4):" in text and "measurements" not in text
    assert all(h in text for h in ("frequency [Hz]", "acceleration [g]", "fill [%]",
                                   "SDC [-]", "saved [UTC]"))


def test_verify_exits_0_when_sound_and_1_with_the_problems_when_damaged(records_store_copy, capsys):
    path, keys = records_store_copy
    assert main(["store", "verify", "--store", str(path), "--no-progress"]) == 0
    assert "sound (2 measurement(s), 3 analysis(es), 4 DEM run(s), 1 calibration(s)" in \
        capsys.readouterr().out
    with h5py.File(path, "r+") as h5:  # damage done outside pidcore
        del h5["measurements"][keys["measurements"][1]]
    assert main(["store", "verify", "--store", str(path), "--no-progress"]) == 1
    out = capsys.readouterr().out
    assert f"refers to measurement '{keys['measurements'][1]}', which is not stored" in out


def test_remove_prints_what_went_and_why(records_store_copy, capsys):
    path, keys = records_store_copy
    first = keys["measurements"][0]
    assert main(["store", "remove", first, "--store", str(path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"removed measurement {first} (test1.uff)"
    assert out[1] == (f"removed analysis {keys['older']} (test1.uff): an analysis of "
                      f"measurement {first}")
    assert out[-1].startswith(f"{path}: 3 record(s) removed in one commit")
    assert len(Store(path).list_analyses()) == 1


def test_a_dry_run_prints_what_would_go_and_removes_nothing(records_store_copy, capsys):
    path, keys = records_store_copy
    digest = file_sha256(path)
    run, calibration = keys["design"][0], keys["calibration"]
    assert main(["store", "remove", run, "--store", str(path), "--dry-run",
                 "--with-dependents"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[1] == (f"would remove calibration {calibration} (paper_coupon [720ba2], "
                      f"fitted 'fixture_mass_kg'): fitted on DEM run {run}")
    assert "nothing was removed" in out[-1] and file_sha256(path) == digest


def test_a_design_run_is_refused_in_one_line_naming_the_option(records_store_copy, capsys):
    path, keys = records_store_copy
    digest = file_sha256(path)
    err = refusal(["store", "remove", keys["design"][0], "--store", str(path)], capsys)
    assert f"is a design run of calibration {keys['calibration']}" in err
    assert "or --with-dependents removes it with the run)" in err
    assert file_sha256(path) == digest


def test_an_unknown_key_exits_2_naming_it_and_where_to_look(records_store_copy, capsys):
    path, _ = records_store_copy
    digest = file_sha256(path)
    err = refusal(["store", "remove", "nope", "--store", str(path)], capsys)
    assert err == (f"pidcore store remove: error: {path}: no record 'nope' in this store; "
                   "nothing was removed (`pidcore store list` lists the keys of its records)")
    assert file_sha256(path) == digest


def test_ctrl_c_during_the_removal_exits_130_and_commits_nothing(records_store_copy, capsys,
                                                                 monkeypatch):
    path, keys = records_store_copy
    digest = file_sha256(path)

    def interrupted() -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(manage, "_removed_before_commit", interrupted)
    assert main(["store", "remove", keys["own_run"], "--store", str(path)]) == 130
    assert capsys.readouterr().err == ("pidcore store remove: interrupted; no store write was "
                                       "left half-done\n")
    assert file_sha256(path) == digest


def test_missing_foreign_read_only_and_locked_stores_give_pidcores_one_line_errors(
        records_store_copy, capsys, monkeypatch, tmp_path):
    path, keys = records_store_copy
    missing = tmp_path / "nope.h5"
    for command in (["list"], ["verify"], ["remove", "k"]):
        err = refusal(["store", *command, "--store", str(missing)], capsys)
        assert err.endswith(f"error: {missing}: store not found")
    # the same line report --store gives
    assert refusal(["report", "--store", str(missing), "--out", str(tmp_path / "o")],
                   capsys).endswith(f"error: {missing}: store not found")
    foreign = tmp_path / "foreign.h5"
    foreign.write_text("not a store")
    assert refusal(["store", "verify", "--store", str(foreign)], capsys).endswith(
        f"{foreign}: not a readable pidcore store (not an HDF5 file: a store is the .h5 "
        "file pidcore writes)")
    os.chmod(path, 0o444)
    try:
        assert "s.h5: the store file is read-only" in refusal(
            ["store", "remove", keys["own_run"], "--store", str(path)], capsys)
    finally:
        os.chmod(path, 0o644)
    monkeypatch.setitem(Store.__init__.__kwdefaults__, "lock_timeout_s", 0.2)
    with exclusive_lock(path, timeout_s=1):
        err = refusal(["store", "remove", keys["own_run"], "--store", str(path)], capsys)
    assert "could not take the write lock" in err and "another pidcore process is writing" \
        in err
    assert keys["own_run"] in set(Store(path).list_dem_runs()["case_key"])


def test_a_record_hdf5_cannot_read_inside_a_removal_is_one_line_naming_it(records_store_copy,
                                                                          capsys, monkeypatch):
    # a bad metadata checksum (bit rot) makes h5py raise RuntimeError when the record's
    # attributes are read; inside the removal's transaction it came out as a traceback
    path, keys = records_store_copy
    digest = file_sha256(path)
    damaged = keys["other"]
    own_child = Store._own_child

    def rotten(self, group, name):
        if group.name == f"/analyses/{damaged}":
            raise RuntimeError("Error iterating over attributes (incorrect metadata checksum "
                               "after all read attempts)")
        return own_child(self, group, name)

    monkeypatch.setattr(Store, "_own_child", rotten)
    err = refusal(["store", "remove", keys["own_run"], "--store", str(path)], capsys)
    assert err == (f"pidcore store remove: error: {path}: not a readable pidcore store "
                   f"(/analyses/{damaged}: Error iterating over attributes (incorrect "
                   "metadata checksum after all read attempts))")
    assert file_sha256(path) == digest


def test_the_specimen_kept_command_a_removal_points_to_names_the_store_as_one_word(tmp_path):
    # "`pidcore specimen kept --remove --store runs % [1].h5` removes them" was printed bare:
    # pasted, the shell split the store's path into three words and globbed the brackets
    import re
    import shlex

    from pidcore.app.kept_specimens import kept_specimen_file
    from pidcore.cli.store import format_removal

    store = tmp_path / "runs % [1].h5"
    sha = "ab" * 32
    kept = kept_specimen_file(store, sha)
    kept.parent.mkdir(parents=True)
    kept.write_bytes(b"kept")
    said = format_removal(manage.Removal(store=store, records=(), dry_run=False,
                                         unnamed_sha256=(sha,)))
    (line,) = re.findall(r"`(pidcore specimen kept [^`]*)` removes them", said)
    assert shlex.split(line) == ["pidcore", "specimen", "kept", "--remove", "--store",
                                 str(store)]


def _strict_json(text: str):
    """``text`` read as JSON a strict reader takes: no lone surrogate in any string (Python's
    reader takes ``"\\udcff"``, a strict one refuses it), so it encodes to UTF-8 as it is."""
    document = json.loads(text)
    json.dumps(document, ensure_ascii=False).encode("utf-8")  # raises on a lone surrogate
    return document


def test_list_and_verify_json_name_a_non_utf8_store_with_escapes_as_analyze_does(
        records_store_copy, capsys):
    # `store list --json` on st_\xff.h5 printed "st_\udcff.h5", a lone surrogate strict JSON
    # readers refuse, where analyze --json printed its file as "ex2_\\xff...": one rule
    path, _ = records_store_copy
    store = path.with_name(os.fsdecode(b"st_\xff.h5"))
    os.replace(path, store)
    for action in ("list", "verify"):
        assert main(["store", action, "--store", str(store), "--json"]) == 0
        listed = _strict_json(capsys.readouterr().out)
        assert listed["store"] == f"{store.parent}/st_\\xff.h5", action
