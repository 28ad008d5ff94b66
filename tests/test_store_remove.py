"""Removing records from a store (pidcore.store.manage): one commit, what depends on a record
goes with it or the removal is refused, every other record left bit for bit."""

from __future__ import annotations

import h5py
import pytest
from _shaker_files import file_sha256
from _store_records import contents, second_calibration, without

from pidcore.calibrate.persist import calibration_design_runs, stored_calibrations
from pidcore.errors import StoreError
from pidcore.report.pipeline import without_design_runs
from pidcore.store import Store, manage
from pidcore.store.listing import list_dem_runs, saved_analyses
from pidcore.store.manage import remove_records, store_contents


def test_removing_a_measurement_takes_its_analyses_and_leaves_every_other_record_bit_for_bit(
        records_store_copy):
    path, keys = records_store_copy
    first = keys["measurements"][0]
    before = contents(path)
    removal = remove_records(path, [first])
    assert [(r.section, r.key, r.because) for r in removal.records] == [
        ("measurements", first, ""),
        ("analyses", keys["older"], f"an analysis of measurement {first}"),
        ("analyses", keys["newer"], f"an analysis of measurement {first}")]
    # what report --store reads no longer holds them; the other measurement's does
    assert list(saved_analyses(path)["key"]) == [keys["other"]]
    listed = store_contents(path)
    assert list(listed["measurements"]["key"]) == [keys["measurements"][1]]
    assert list(listed["analyses"]["key"]) == [keys["other"]]
    after = contents(path)
    assert after == without(before, f"/measurements/{first}", f"/analyses/{keys['older']}",
                            f"/analyses/{keys['newer']}")
    assert Store(path).verify() == []


def test_removing_the_newest_analysis_says_the_earlier_one_reports_take_now(records_store_copy):
    path, keys = records_store_copy
    assert list(saved_analyses(path)["key"]) == [keys["other"], keys["newer"]]
    removal = remove_records(path, [keys["newer"]])
    assert [r.key for r in removal.records] == [keys["newer"]]
    assert len(removal.notes) == 1 and f"its analysis {keys['older']}" in removal.notes[0]
    assert set(saved_analyses(path)["key"]) == {keys["other"], keys["older"]}


def test_a_design_run_of_a_stored_calibration_is_refused_and_nothing_is_removed(records_store_copy):
    path, keys = records_store_copy
    run, calibration = keys["design"][1], keys["calibration"]
    digest = file_sha256(path)
    with pytest.raises(StoreError, match=f"DEM run {run} is a design run of calibration "
                                         f"{calibration} .*nothing was removed"):
        remove_records(path, [keys["own_run"], run])  # the removable one is kept too
    assert file_sha256(path) == digest


def test_with_dependents_the_calibration_fitted_on_the_run_goes_with_it(records_store_copy):
    path, keys = records_store_copy
    run, calibration = keys["design"][1], keys["calibration"]
    before = contents(path)
    removal = remove_records(path, [run], with_dependents=True)
    assert [(r.section, r.key, r.because) for r in removal.records] == [
        ("dem_runs", run, ""), ("calibrations", calibration, f"fitted on DEM run {run}")]
    assert stored_calibrations(path) == []
    runs = list_dem_runs(path)
    assert run not in set(runs["case_key"]) and calibration_design_runs(runs, [path]) == {}
    assert contents(path) == without(before, f"/dem_runs/{run}",
                                     f"/calibrations/{calibration}")


def test_naming_the_calibration_with_its_run_needs_no_option(records_store_copy):
    path, keys = records_store_copy
    run, calibration = keys["design"][0], keys["calibration"]
    removal = remove_records(path, [run, calibration])
    assert {(r.section, r.key) for r in removal.records} == {("dem_runs", run),
                                                           ("calibrations", calibration)}


def test_an_interrupted_removal_leaves_the_store_byte_identical(records_store_copy, monkeypatch):
    path, keys = records_store_copy
    digest = file_sha256(path)

    def interrupted() -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(manage, "_removed_before_commit", interrupted)
    with pytest.raises(KeyboardInterrupt):
        remove_records(path, [keys["measurements"][0], keys["own_run"]])
    assert file_sha256(path) == digest
    assert sorted(p.name for p in path.parent.iterdir()) == ["s.h5"]  # no copy, no lock


def test_an_unknown_key_is_refused_and_nothing_is_removed(records_store_copy):
    path, keys = records_store_copy
    digest = file_sha256(path)
    with pytest.raises(StoreError, match="no record 'nope' in this store; nothing was removed"
                                         r" \(`pidcore store list`"):
        remove_records(path, [keys["own_run"], "nope"])
    assert file_sha256(path) == digest


def test_a_dry_run_lists_exactly_what_the_removal_removes_and_leaves_the_file(records_store_copy):
    path, keys = records_store_copy
    digest = file_sha256(path)
    named = [keys["measurements"][1], keys["design"][2]]
    planned = remove_records(path, named, with_dependents=True, dry_run=True)
    assert planned.dry_run and file_sha256(path) == digest
    done = remove_records(path, named, with_dependents=True)
    assert planned.records == done.records and len(done.records) == 4


def test_a_section_key_names_a_record_of_that_section(records_store_copy):
    path, keys = records_store_copy
    removal = remove_records(path, [f"dem_runs/{keys['own_run']}"])
    assert [(r.section, r.key) for r in removal.records] == [("dem_runs", keys["own_run"])]


def test_a_missing_store_is_refused_not_read_as_empty(tmp_path):
    with pytest.raises(StoreError, match="nope.h5: store not found"):
        remove_records(tmp_path / "nope.h5", ["x"], dry_run=True)
    assert not (tmp_path / "nope.h5").exists()


def test_a_variant_of_the_start_no_design_of_the_calibration_made_is_no_run_of_it(
        records_store_copy):
    # fitting the fixture mass alone, a calibration makes no variant of its start specimen
    # (its design names no DEM parameter): another fit's variant of the same file at its load
    # case, cells and seed was refused as its design run, and --with-dependents took it along
    # (a variant its design did make is refused: test_calibration_variant_runs)
    path, keys = records_store_copy
    store = Store(path)
    start = str(store.list_calibrations()["specimen_hash"].iloc[0])
    run = store.get_dem_run(keys["design"][0])
    assert run.record["specimen_sha256"] == start
    variant = {**run.parameters, "calibration_variant": {
        "of_name": "paper_coupon", "of_sha256": start, "values": [["rolling_friction", 0.05]]}}
    store.add_dem_run("variant_run", {**run.record, "specimen_sha256": "f" * 64},
                      arrays=run.arrays, units=run.units, parameters=variant)
    listed = store_contents(path, ["dem-runs"])["dem-runs"].set_index("key")["design_of"]
    assert listed["variant_run"] == "" and listed[keys["design"][0]] == keys["calibration"]
    removal = remove_records(path, ["variant_run"], with_dependents=True, dry_run=True)
    assert [r.key for r in removal.records] == ["variant_run"]
    assert [r.key for r in remove_records(path, ["variant_run"]).records] == ["variant_run"]
    assert Store(path).verify() == []


def test_a_run_two_calibrations_were_fitted_on_is_removed_with_both_or_refused(
        records_store_copy):
    # a second fit on the same runs reuses them: each calibration depends on every run, and
    # a run mapped to one of them was removed with it, the other left naming a run gone
    path, keys = records_store_copy
    first, run = keys["calibration"], keys["design"][0]
    second = second_calibration(path)
    both = f"{first}, {second}"  # oldest first
    digest = file_sha256(path)
    with pytest.raises(StoreError, match=f"DEM run {run} is a design run of calibrations "
                                         f"{both} .*nothing was removed"):
        remove_records(path, [run])
    # naming one of them leaves the other, which is refused by name
    with pytest.raises(StoreError, match=f"design run of calibration {second} .*nothing"):
        remove_records(path, [run, first])
    assert file_sha256(path) == digest
    removal = remove_records(path, [run], with_dependents=True)
    assert [(r.section, r.key, r.because) for r in removal.records] == [
        ("dem_runs", run, ""), *[("calibrations", c, f"fitted on DEM run {run}")
                                 for c in (first, second)]]
    assert stored_calibrations(path) == [] and Store(path).verify() == []


def test_list_and_reports_name_every_calibration_a_run_is_a_design_run_of(records_store_copy):
    path, keys = records_store_copy
    first, second = keys["calibration"], second_calibration(path)
    listed = store_contents(path, ["dem-runs"])["dem-runs"].set_index("key")["design_of"]
    assert listed.to_dict() == {**dict.fromkeys(keys["design"], f"{first}, {second}"),
                                keys["own_run"]: ""}
    runs = list_dem_runs(path)
    design = calibration_design_runs(runs, [path, path])  # one store given twice: once each
    assert design == dict.fromkeys(keys["design"], (first, second))
    # the report's note on the design runs it leaves out names both fits they are inputs of
    _, note = without_design_runs(runs, design)
    assert f"calibration(s) {', '.join(sorted((first, second)))} (2 cells per run)" in note


def test_a_run_of_a_design_case_with_another_direction_or_steady_cycles_is_no_design_run(
        records_store_copy):
    # a run of the calibration's load case along x, or with 30 steady cycles (the fit ran
    # 10), made after the fit, was listed as its design run: remove refused it, and verify
    # called the store sound once the real design run was gone (the look-alike matched)
    import json

    path, keys = records_store_copy
    store = Store(path)
    run = store.get_dem_run(keys["design"][0])
    looks = {"along_x": ({**run.record, "direction": "x"}, run.parameters),
             "cycles_30": (run.record, {**run.parameters, "config_steady_cycles": 30})}
    for key, (record, parameters) in looks.items():
        store.add_dem_run(key, record, arrays=run.arrays, units=run.units,
                          parameters=parameters)
    assert json.loads(list_dem_runs(path).set_index("case_key").loc[
        "cycles_30", "parameters_json"])["config_steady_cycles"] == 30
    listed = store_contents(path, ["dem-runs"])["dem-runs"].set_index("key")["design_of"]
    assert listed["along_x"] == listed["cycles_30"] == ""
    assert listed[keys["design"][0]] == keys["calibration"]
    assert [r.key for r in remove_records(path, list(looks)).records] == list(looks)
    for key, (record, parameters) in looks.items():  # back, then the real run goes
        store.add_dem_run(key, record, arrays=run.arrays, units=run.units,
                          parameters=parameters)
    with h5py.File(path, "r+") as h5:  # damage done outside pidcore
        del h5["dem_runs"][keys["design"][0]]
    assert any("none of which is stored" in p for p in Store(path).verify())


def test_verify_names_a_calibration_whose_design_run_is_gone_and_the_run(records_store_copy):
    # what the removal of a shared run with one calibration left: the other calibration
    # fitted on a run the store no longer holds, which verify called sound
    path, keys = records_store_copy
    run = keys["design"][0]
    assert Store(path).verify() == []
    with h5py.File(path, "r+") as h5:  # damage done outside pidcore
        del h5["dem_runs"][run]
    problems = Store(path).verify()
    case = run.split("_seed")[0]
    assert len(problems) == 1
    assert problems[0].startswith(f"{path}:/calibrations/{keys['calibration']}: fitted on "
                                  f"the DEM run(s) {case}_seed")
    assert "none of which is stored" in problems[0]


def test_a_calibration_asked_for_the_automatic_steady_cycles_by_number_keeps_its_runs():
    # a run asked for --steady-cycles 80 (the automatic count of 10-cycle blocks) is stored
    # as unstated (""), while the calibration's settings keep 80: compared by value, the
    # calibration of --steady-cycles 80 had no design run, and verify would call it damaged
    from pidcore import defaults
    from pidcore.calibrate.persist import asked_steady_cycles

    automatic = defaults.dem_automatic_steady_cycles(10)
    assert asked_steady_cycles("", 10) == asked_steady_cycles(None, 10) \
        == asked_steady_cycles(automatic, 10) == automatic
    assert asked_steady_cycles(10, 10) == 10 != asked_steady_cycles("", 10)
    # a run of other blocks runs another automatic count
    assert asked_steady_cycles("", 100) == defaults.dem_automatic_steady_cycles(100)
