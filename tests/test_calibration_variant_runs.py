"""A calibration's DEM runs of its specimen's variants (the file with the design point's
friction, ...) are named as such, never as "another file of that name": the calibration
stores with each run which file it varied and the design values, and Compare, the report,
the DEM tab and ``dem run`` read it. Runs stored before that was recorded are labelled as
either, since which they are is unknown."""

from __future__ import annotations

import dataclasses
import json

import pytest

from pidcore.calibrate import calibrate
from pidcore.calibrate.data import MeasuredPoint
from pidcore.calibrate.runner import specimen_with
from pidcore.compare.specimens import runs_for_measurement
from pidcore.dem.simulate import DemConfig, LoadCase
from pidcore.specimen import paper_specimen
from pidcore.store import Store

CONFIG = DemConfig(cells=2, steady_cycles=10, block_cycles=5, max_transient_cycles=5)
CASE = LoadCase(500.0, 5.0, 50.0)


@pytest.fixture(scope="module")
def variants(tmp_path_factory):
    """A store holding a calibration's runs of an own specimen (the paper's coupon renamed),
    fitting the rolling friction over a design of 2 points at one measured load case."""
    store = tmp_path_factory.mktemp("variants") / "dem.h5"
    mine = dataclasses.replace(paper_specimen(), name="mycoupon")
    point = MeasuredPoint(CASE.frequency_hz, CASE.acceleration_g, CASE.fill_percent, 0.5,
                          0.01, specimen="mycoupon", specimen_sha256=mine.hash)
    result = calibrate([point], fit=["rolling_friction"], discrepancy=0.3, store_path=store,
                       cells=CONFIG.cells, steady_cycles=CONFIG.steady_cycles,
                       dem_config=CONFIG, design_size=2, workers=1, progress=False,
                       specimen=mine)
    return store, mine, result


def _label(sha256: str) -> str:
    return f"mycoupon [{sha256[:6]}]"


def _without_provenance(runs):
    """``runs`` as a store written before pidcore recorded which runs are variants."""
    def strip(text: str) -> str:
        params = json.loads(text)
        params.pop("calibration_variant")
        return json.dumps(params)

    return runs.assign(parameters_json=runs["parameters_json"].map(strip))


def test_the_variant_runs_store_the_file_they_vary_and_the_design_values(variants):
    from pidcore.compare.specimens import CalibrationVariant, run_origin

    store, mine, result = variants
    runs = Store(store).list_dem_runs()
    # a design of 2 rolling frictions at one load case: 2 runs, none of the file itself
    assert len(runs) == 2 and mine.hash not in set(runs["specimen_sha256"])
    designed = sorted(float(v) for v in result.design[:, 0])
    stated = []
    for sha, params in zip(runs["specimen_sha256"], runs["parameters_json"], strict=True):
        origin = run_origin(params)
        assert isinstance(origin, CalibrationVariant)
        assert (origin.of_name, origin.of_sha256) == ("mycoupon", mine.hash)
        assert [name for name, _ in origin.values] == ["rolling_friction"]
        # what it stored rebuilds the stored specimen exactly: the variant is that file with
        # those values, not another file of its name
        assert specimen_with(mine, dict(origin.values)).hash == sha
        stated.append(origin.values[0][1])
    assert sorted(stated) == designed  # the design's numbers, as floats through JSON: exact


def test_compare_names_them_as_the_calibrations_variants_not_another_file(variants):
    store, mine, result = variants
    runs = Store(store).list_dem_runs()
    met = runs_for_measurement(runs, "mycoupon", "acrylic", "z", mine.hash)
    assert met.runs is None  # kept out of the comparison as before: they are not the file
    for sha, value in zip(runs["specimen_sha256"], runs["parameters_json"], strict=True):
        rolling = json.loads(value)["calibration_variant"]["values"][0][1]
        assert (f"{_label(sha)}: calibration variant of {_label(mine.hash)} "
                f"(rolling_friction {rolling:.4g}) (1 run(s))") in met.note
    assert "another file of that name" not in met.note
    # the same runs from a store written before the provenance: which they are is unknown,
    # so both are said, not the edited file alone
    old = runs_for_measurement(_without_provenance(runs), "mycoupon", "acrylic", "z",
                               mine.hash)
    assert old.runs is None and "calibration variant" not in old.note
    assert ("runs named mycoupon hold other content than the test's file (its sha256 "
            f"starts {mine.hash[:6]}): another file of that name, or a calibration's variants "
            "of one, stored before pidcore recorded which") in old.note


def test_a_run_of_another_file_as_given_is_still_another_file(variants, tmp_path):
    # pidcore dem run of an edited mycoupon.toml: it states that it is no variant
    from pidcore.dem.persist import run_or_load

    store, mine, _ = variants
    edited = mine.with_values({"coupon.mass_kg": 0.03})
    own = tmp_path / "own.h5"
    run_or_load(own, edited, CASE, CONFIG)
    runs = Store(own).list_dem_runs()
    assert json.loads(runs["parameters_json"].iloc[0])["calibration_variant"] is None
    met = runs_for_measurement(runs, "mycoupon", "acrylic", "z", mine.hash)
    assert met.runs is None
    assert (f"runs named mycoupon are of another file of that name than the test's (its "
            f"specimen's sha256 starts {mine.hash[:6]})") in met.note
    assert "calibration variant" not in met.note


def test_report_dem_tab_and_dem_run_name_them_alike(variants):
    from pidcore.app.jobs import dem_runs_table
    from pidcore.dem import persist
    from pidcore.report.table import no_runs_note

    store, mine, _ = variants
    runs = Store(store).list_dem_runs()
    described = {f"{_label(sha)}: calibration variant of {_label(mine.hash)} (rolling_friction "
                 f"{json.loads(p)['calibration_variant']['values'][0][1]:.4g})"
                 for sha, p in zip(runs["specimen_sha256"], runs["parameters_json"],
                                   strict=True)}
    # the DEM tab's table, one row per run
    assert set(dem_runs_table(runs)["specimen"]) == described
    # a report row of the file's test (named by name, the report of that file)
    note = no_runs_note("mycoupon", "acrylic", "z", runs, named=True, report_of="mycoupon")
    assert all(f"1 of {d}" in note for d in described), note
    assert "another file named mycoupon" not in note
    assert "a calibration's variants, not a file named mycoupon as given" in note
    # dem run of the file itself at the calibrated load case: not "an earlier version"
    said = persist.other_files_runs_note(store, [CASE], dataclasses.replace(
        CONFIG, seed=12345), mine)
    assert "of a calibration's variants named mycoupon (" in said, said
    assert all(d in said for d in described) and "earlier version" not in said


def test_the_provenance_is_no_input_the_same_simulation_is_found(variants):
    # the run a calibration stored is the run of its specimen whoever asks: same key, same
    # simulation identity and settings as without the statement
    from pidcore.compare.align import settings_hash, simulation_identity
    from pidcore.dem.persist import run_identity, run_key, stored_run_key

    store, mine, result = variants
    runs = Store(store).list_dem_runs()
    bare = _without_provenance(runs)
    for i, (key, params, count) in enumerate(zip(runs["case_key"], runs["parameters_json"],
                                                 runs["particles_per_cell"], strict=True)):
        assert simulation_identity(params, count) == simulation_identity(
            bare["parameters_json"].iloc[i], count)
        assert settings_hash(params) == settings_hash(bare["parameters_json"].iloc[i])
        variant = specimen_with(mine, {"rolling_friction": json.loads(params)[
            "calibration_variant"]["values"][0][1]})
        config = dataclasses.replace(CONFIG, seed=12345)
        assert run_key(CASE, config, variant) == key
        assert simulation_identity(params, count) == run_identity(CASE, config, variant)
        assert stored_run_key(store, CASE, config, variant) == key


def test_rekeying_keeps_what_a_run_says_of_its_origin(variants, tmp_path):
    from pidcore.dem.persist import rekey_dem_store

    store, _, _ = variants
    runs_only = tmp_path / "runs.h5"
    source = Store(store)
    items = []
    for n, key in enumerate(source.list_dem_runs()["case_key"]):
        entry = source.get_dem_run(key)
        parameters = dict(entry.parameters)
        if n == 0:  # one run as a store written before the provenance holds it
            parameters.pop("calibration_variant")
        items.append({"case_key": key, "record": entry.record, "arrays": entry.arrays,
                      "parameters": parameters, "units": entry.units})
    Store(runs_only).add_dem_runs(items)
    target = tmp_path / "rekeyed.h5"
    assert rekey_dem_store(runs_only, target) == 2
    before = {i["case_key"]: i["parameters"].get("calibration_variant", "absent")
              for i in items}
    after = Store(target)
    for key in after.list_dem_runs()["case_key"]:
        stated = after.get_dem_run(key).parameters.get("calibration_variant", "absent")
        assert stated == before[key]  # unstated stays unstated, not "the file as given"
    assert sorted(map(str, before.values())).count("absent") == 1


def test_calibrate_lists_its_runs_as_the_dem_tab_and_the_report_do(tmp_path, capsys):
    # pidcore calibrate said "DEM runs: 2 computed" and no more; the store's listings then
    # named the same runs
    from pidcore.app.jobs import dem_runs_table
    from pidcore.cli import main
    from pidcore.compare.specimens import runs_per_specimen_text
    from pidcore.specimen import load_specimen

    text = paper_specimen().to_toml().replace('name = "paper_coupon"', 'name = "mycoupon"')
    (tmp_path / "mycoupon.toml").write_text(text)
    mine = load_specimen(tmp_path / "mycoupon.toml")
    (tmp_path / "m.csv").write_text("frequency_hz,acceleration_g,fill_percent,sdc\n"
                                    "500,5,50,0.5\n")
    store = tmp_path / "dem.h5"
    assert main(["calibrate", "--data", str(tmp_path / "m.csv"), "--specimen",
                 str(tmp_path / "mycoupon.toml"), "--fit", "rolling_friction",
                 "--discrepancy", "0.3", "--design-size", "2", "--cells", "2",
                 "--steady-cycles", "10", "--workers", "1", "--no-progress",
                 "--dem-store", str(store)]) == 0
    printed = capsys.readouterr().out
    runs = Store(store).list_dem_runs()
    listed = set(dem_runs_table(runs)["specimen"])
    assert len(listed) == 2 and all(
        f": calibration variant of {_label(mine.hash)} (rolling_friction " in d for d in listed)
    line = next(x for x in printed.splitlines() if x.startswith("DEM runs: 2 computed"))
    assert line == (f"DEM runs: 2 computed, 0 reused from {store} "
                    f"({runs_per_specimen_text(runs)})")
    assert all(f"1 of {d}" in line for d in listed)


def test_a_static_friction_raised_to_a_pairs_sliding_friction_is_stated_as_run():
    """A design's static friction below a pair's sliding friction is run at the sliding one
    (specimen_with): the paper coupon's 0.096 between particles and 0.14 at the wall make a
    design value of 0.12 into 0.12 and 0.14. The run's statement gives what was run, per pair,
    not the 0.12 asked for."""
    from pidcore.calibrate.runner import variant_provenance
    from pidcore.compare.specimens import run_origin

    start = paper_specimen()
    values = {"static_friction": 0.12, "rolling_friction": 0.02}
    variant = specimen_with(start, values)
    stated = variant_provenance(start, variant, values)
    origin = run_origin(json.dumps({"calibration_variant": stated}))
    held = dict(origin.values)
    assert held == {"pairs.particle_particle.static_friction": 0.12,
                    "pairs.particle_wall.static_friction":
                        start.pairs.particle_wall.sliding_friction,
                    "rolling_friction": 0.02}
    assert held["pairs.particle_wall.static_friction"] == \
        variant.pairs.particle_wall.static_friction
    # a value no pair raises is stated by the name the fit took, as before
    plain = {"static_friction": 0.5}
    assert variant_provenance(start, specimen_with(start, plain), plain)["values"] == \
        [["static_friction", 0.5]]


def _two_calibrations(source, mine, result, tmp_path):
    """A copy of the ``variants`` store with its rolling-friction design saved (``designed``)
    beside a fit of ``baseline_loss_factor`` alone at the same load case, cells and seed
    (``observed``, which runs the start file itself): (store, designed, observed, the
    design's variant run keys, the store's runs, the start's run key)."""
    import shutil

    from pidcore.calibrate.persist import save_calibration

    store = tmp_path / "dem.h5"
    shutil.copyfile(source, store)
    designed = save_calibration(result, store).key
    point = MeasuredPoint(CASE.frequency_hz, CASE.acceleration_g, CASE.fill_percent, 0.5,
                          0.01, specimen="mycoupon", specimen_sha256=mine.hash)
    observed = save_calibration(calibrate(
        [point], fit=["baseline_loss_factor"], discrepancy=0.3, store_path=store,
        cells=CONFIG.cells, steady_cycles=CONFIG.steady_cycles, dem_config=CONFIG,
        workers=1, progress=False, specimen=mine), store).key
    variant_keys = list(Store(source).list_dem_runs()["case_key"])
    runs = Store(store).list_dem_runs()
    start_key = next(k for k, sha in zip(runs["case_key"], runs["specimen_sha256"],
                                         strict=True) if sha == mine.hash)
    return store, designed, observed, variant_keys, runs, start_key


def test_a_variant_run_is_a_design_run_only_of_the_calibration_whose_design_made_it(
        variants, tmp_path):
    # a fit of observation parameters alone (no DEM design, no variant) at the same load case,
    # cells and seed was named a dependent of every variant of its start: store list said
    # "design run of" it, remove refused the runs for it and --with-dependents took it along

    import h5py

    from pidcore.calibrate.persist import calibration_design_runs
    from pidcore.errors import StoreError
    from pidcore.store.manage import remove_records

    source, mine, result = variants
    store, designed, observed, variant_keys, runs, start_key = _two_calibrations(
        source, mine, result, tmp_path)
    # a variant of the same file another design made (another rolling friction): no run of
    # either calibration here
    other = Store(store).get_dem_run(variant_keys[0])
    stated = {**other.parameters["calibration_variant"],
              "values": [["rolling_friction", 0.0777]]}
    Store(store).add_dem_run("other_design_run", {**other.record, "specimen_sha256": "f" * 64},
                             arrays=other.arrays, units=other.units,
                             parameters={**other.parameters, "calibration_variant": stated})
    design = calibration_design_runs(Store(store).list_dem_runs(), [store], variants=True)
    assert {k: design[k] for k in variant_keys} == dict.fromkeys(variant_keys, (designed,))
    assert "other_design_run" not in design and observed in design[start_key]
    # what the store's commands make of it: the other design's variant goes alone, a real
    # variant is refused for its own calibration only and takes that one alone with it
    assert [r.key for r in remove_records(store, ["other_design_run"]).records] == \
        ["other_design_run"]
    with pytest.raises(StoreError, match=f"DEM run {variant_keys[0]} is a design run of "
                                         f"calibration {designed} .*nothing was removed"):
        remove_records(store, [variant_keys[0]])
    removal = remove_records(store, [variant_keys[0]], with_dependents=True, dry_run=True)
    assert [(r.section, r.key) for r in removal.records] == [
        ("dem_runs", variant_keys[0]), ("calibrations", designed)]
    # verify: every run of both fits gone, the other design's look-alike (put back) stands in
    # for neither
    Store(store).add_dem_run("other_design_run", {**other.record, "specimen_sha256": "f" * 64},
                             arrays=other.arrays, units=other.units,
                             parameters={**other.parameters, "calibration_variant": stated})
    assert Store(store).verify() == []
    with h5py.File(store, "r+") as h5:  # damage done outside pidcore
        for key in [*variant_keys, start_key]:
            del h5["dem_runs"][key]
    problems = Store(store).verify()
    assert sorted(p.split(": fitted on")[0] for p in problems) == sorted(
        f"{store}:/calibrations/{key}" for key in (designed, observed))


def test_a_design_point_of_a_raised_static_friction_is_known_by_the_run_it_made():
    # a static friction below a pair's sliding friction is stated per pair as run: the
    # design point (0.12) is found from the run's own specimen, and not another point's
    from pidcore.calibrate.runner import is_design_variant, variant_provenance
    from pidcore.compare.specimens import run_origin

    start = paper_specimen()
    names, points = ["static_friction"], [[0.5], [0.12]]
    variant = specimen_with(start, {"static_friction": 0.12})
    origin = run_origin(json.dumps({"calibration_variant": variant_provenance(
        start, variant, {"static_friction": 0.12})}))
    assert is_design_variant(origin.values, names, points, variant)
    assert not is_design_variant(origin.values, names, [[0.5], [0.13]], variant)
    assert not is_design_variant(origin.values, [], [[]], variant)  # no design: no variant


def test_a_run_of_the_start_is_a_design_run_only_of_a_calibration_whose_design_ran_it(
        variants, tmp_path):
    # a design of variants alone (rolling frictions 0.25, 0.75: none the start's 0) claimed
    # another fit's run of the start at its load case, cells and seed: store remove named it
    # a dependent of that run, and verify took the run for its own when its variants were gone

    import h5py
    import numpy as np

    from pidcore.calibrate.persist import calibration_design_runs, save_calibration
    from pidcore.calibrate.runner import is_design_start
    from pidcore.errors import StoreError
    from pidcore.store.manage import remove_records

    source, mine, result = variants
    assert not is_design_start(mine, ["rolling_friction"], result.design.tolist())
    store, designed, observed, variant_keys, runs, start_key = _two_calibrations(
        source, mine, result, tmp_path)
    assert calibration_design_runs(runs, [store], variants=True)[start_key] == (observed,)
    with pytest.raises(StoreError, match=f"DEM run {start_key} is a design run of "
                                         f"calibration {observed} \\(an input of its fit"):
        remove_records(store, [start_key])
    removal = remove_records(store, [start_key], with_dependents=True, dry_run=True)
    assert [(r.section, r.key) for r in removal.records] == [
        ("dem_runs", start_key), ("calibrations", observed)]
    # a design one of whose points is the start's own rolling friction ran the start itself:
    # its run is that calibration's as well (the point [0.0] rebuilds the file exactly)
    with_start = save_calibration(dataclasses.replace(
        result, design=np.array([[0.0], *result.design.tolist()])), store).key
    assert calibration_design_runs(Store(store).list_dem_runs(), [store],
                                   variants=True)[start_key] == (observed, with_start)
    # verify: the variants gone, the start's run (kept) stands in for neither design
    with h5py.File(store, "r+") as h5:  # damage done outside pidcore
        for key in variant_keys:
            del h5["dem_runs"][key]
    problems = Store(store).verify()
    assert sorted(p.split(": fitted on")[0] for p in problems) == [
        f"{store}:/calibrations/{designed}"]
