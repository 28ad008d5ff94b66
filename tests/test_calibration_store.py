"""Calibrations in the HDF5 store (:mod:`pidcore.calibrate.persist`): ``pidcore calibrate``
saves its result beside the DEM runs it was made from; reports and the app read it back as
they read calibration.json, with the same numbers; the same calibration is stored once; a
store of several needs a key; a damaged one is found by ``verify``."""

from __future__ import annotations

import json
import types
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest

from pidcore.calibrate import load_calibration, stored_calibration, stored_calibrations
from pidcore.calibrate.persist import calibration_key
from pidcore.cli import main
from pidcore.errors import ParameterError
from pidcore.store import Store

ROWS = "frequency_hz,acceleration_g,fill_percent,sdc\n500,5,50,0.6\n1000,5,50,0.6\n500,1,50,0.2\n"
TINY = ["--cells", "2", "--steady-cycles", "10", "--workers", "1", "--no-progress"]


def _calibrate(folder, store, discrepancy: str, capsys) -> str:
    table = folder / "m.csv"
    table.write_text(ROWS)
    out = folder / f"out_{discrepancy}"
    code = main(["calibrate", "--data", str(table), "--fit", "fixture_mass_kg", "--discrepancy",
                 discrepancy, "--dem-store", str(store), "--out", str(out), *TINY])
    assert code == 0
    return capsys.readouterr().out


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory):
    """A store holding the calibration of the tiny table, and its --out folder."""
    folder = tmp_path_factory.mktemp("calstore")
    store = folder / "dem.h5"
    table = folder / "m.csv"
    table.write_text(ROWS)
    assert main(["calibrate", "--data", str(table), "--fit", "fixture_mass_kg",
                 "--discrepancy", "0.2", "--dem-store", str(store), "--out",
                 str(folder / "out"), *TINY]) == 0
    return folder, store


def test_the_stored_calibration_is_the_json_written_beside_it(calibrated):
    folder, store = calibrated
    stored = stored_calibration(store)
    written = load_calibration(folder / "out")
    # the store keeps the very texts the --out folder got, so every number read back is the
    # same double (no tolerance: a round trip of text)
    assert stored.document_text == (folder / "out" / "calibration.json").read_text()
    assert stored.specimen_text == (folder / "out" / "calibrated_specimen.toml").read_text()
    assert stored.parameters == written.parameters
    assert stored.predictions == written.predictions
    assert stored.calibrated_specimen().hash == written.calibrated_specimen().hash
    assert stored.specimen_name == "paper_coupon"
    # the key is of what the calibration writes: its JSON and its calibrated specimen
    assert stored.store_key == calibration_key(json.loads(stored.document_text),
                                               stored.calibrated_specimen().text)
    # listed with its medians, each named with its unit, and a sound store
    listing = Store(store).list_calibrations()
    assert list(listing["key"]) == [stored.store_key]
    row = listing.iloc[0]
    p = written.parameters["fixture_mass_kg"]
    assert row["fixture_mass_kg_median"] == p["median"]
    assert row["fit"] == "fixture_mass_kg" and row["n_points"] == 3
    units = Store(store).get_calibration(stored.store_key).units
    assert units["fixture_mass_kg_median"] == "kg" and units["rms_in_sample"] == "-"
    assert Store(store).verify() == []
    assert Store(store).summary()["n_calibrations"] == 1


def test_the_same_calibration_again_is_not_stored_twice(calibrated, capsys):
    folder, store = calibrated
    before = Store(store).list_calibrations()
    out = _calibrate(folder, store, "0.2", capsys)  # every DEM run cached: same posterior
    key = before["key"].iloc[0]
    assert f"calibration {key} is stored in" in out and "already" in out
    after = Store(store).list_calibrations()
    assert list(after["key"]) == [key]
    assert list(after["created_utc"]) == list(before["created_utc"])  # kept as it was
    # one number, one text: the CLI, summary.md and the specimen's header showed the in-sample
    # RMS to 4 decimals, 3 decimals and 4 significant digits
    (rms,) = [line.split()[2].rstrip(",") for line in out.splitlines()
              if line.startswith("in-sample RMS")]
    summary = (folder / "out_0.2" / "summary.md").read_text()
    assert f"## In-sample posterior predictions: RMS {rms}," in summary
    header = (folder / "out_0.2" / "calibrated_specimen.toml").read_text()
    assert f"# in-sample RMS of the SDC: {rms}\n" in header


def test_the_key_ignores_bookkeeping_but_not_results(calibrated):
    folder, _ = calibrated
    doc = json.loads((folder / "out" / "calibration.json").read_text())
    key = calibration_key(doc)
    # how it was made (wall time, cached-run counts, the caching store's path) is not what
    # it is
    same = {**doc, "wall_s": doc["wall_s"] + 99, "runs": {"computed": 0, "cached": 99},
            "settings": {**doc["settings"], "store": "elsewhere.h5"}}
    assert calibration_key(same) == key
    moved = json.loads(json.dumps(doc))
    moved["predictions"][0]["predicted"] *= 1.0 + 1e-12
    assert calibration_key(moved) != key


def test_a_store_of_several_calibrations_needs_a_key(calibrated, capsys, tmp_path):
    folder, store = calibrated
    copy = tmp_path / "two.h5"
    copy.write_bytes(store.read_bytes())
    said = _calibrate(folder, copy, "0.3", capsys)
    keys = list(Store(copy).list_calibrations()["key"])
    assert len(keys) == 2
    # the command it advises reads the new one (without the key it was refused: two stored)
    new_key = (set(keys) - {Store(store).list_calibrations()["key"].iloc[0]}).pop()
    assert f"--calibration {copy} --calibration-key {new_key} --out report_out)" in said
    with pytest.raises(ParameterError, match="holds 2 calibrations; choose one with "
                                             "key=KEY") as refused:
        stored_calibration(copy)
    assert all(k in str(refused.value) for k in keys)
    assert stored_calibration(copy, keys[0]).store_key == keys[0]
    assert [c.store_key for c in stored_calibrations(copy)] == keys[::-1]  # newest first
    with pytest.raises(ParameterError, match="no calibration 'cal_0000000000000000'"):
        stored_calibration(copy, "cal_0000000000000000")
    with pytest.raises(ParameterError, match="not one"):  # a key for a calibration.json
        load_calibration(folder / "out", key=keys[0])
    # the CLI: refused in one line, exit 2, nothing written
    out = tmp_path / "report"
    assert main(["report", "--dem-store", str(copy), "--calibration", str(copy), "--out",
                 str(out), "--format", "csv"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--calibration-key" in err, err
    assert not out.exists()


def test_the_report_command_calibrate_prints_names_a_store_of_any_name_as_one_word(
        calibrated, capsys, tmp_path):
    # `report --calibration store % [1].h5 --calibration-key ...` was printed bare: pasted,
    # the shell split the path into three words and globbed the brackets
    import re
    import shlex

    folder, store = calibrated
    copy = tmp_path / "store % [1].h5"
    copy.write_bytes(store.read_bytes())
    said = _calibrate(folder, copy, "0.3", capsys)
    new_key = (set(Store(copy).list_calibrations()["key"])
               - {Store(store).list_calibrations()["key"].iloc[0]}).pop()
    (line,) = re.findall(r"\((pidcore report [^()]*)\)$", said, re.M)
    # the shell's reading of the printed line is the command that reads the new calibration,
    # of the DEM runs it was made from (--data's table is no report input)
    assert shlex.split(line) == ["pidcore", "report", "--dem-store", str(copy),
                                 "--calibration", str(copy), "--calibration-key", new_key,
                                 "--out", "report_out"]


def test_the_report_command_calibrate_prints_runs_as_pasted(calibrated, capsys, tmp_path):
    """The printed next step had no --out, which report requires: pasted, it failed "the
    following arguments are required: --out". Read by the real parser it is now a report of
    the calibration's store (the measurements of --store and runs of --dem-store it used)."""
    import shlex
    from argparse import Namespace

    from pidcore.cli import build_parser
    from pidcore.cli.calibrate import _saved_words

    store, runs, spec = tmp_path / "m s.h5", tmp_path / "runs.h5", tmp_path / "spec.toml"
    said = _saved_words(("cal_0123456789abcdef", True),
                        Namespace(store=store, dem_store=runs, specimen=spec))
    line = said.split("(", 1)[1].removesuffix(")")
    args = build_parser().parse_args(shlex.split(line)[1:])
    assert (args.command, args.out, args.calibration, args.calibration_key) == \
        ("report", Path("report_out"), runs, "cal_0123456789abcdef")
    assert (args.store, args.dem_store, args.specimen, args.files) == \
        (store, [runs], spec, [])


def _calibration_columns(folder) -> pd.DataFrame:
    table = pd.read_csv(folder / "report.csv")
    columns = [c for c in table.columns if "calibrated" in c and "note" not in c]
    assert columns, table.columns
    return table[columns]


def test_a_report_from_the_store_has_the_numbers_of_its_json(calibrated, capsys, tmp_path):
    folder, store = calibrated
    key = stored_calibration(store).store_key
    for name, source in (("from_store", [str(store), "--calibration-key", key]),
                         ("from_json", [str(folder / "out" / "calibration.json")])):
        # --pool: the store holds only the calibration's own design runs, which are no rows
        # of their own otherwise (no measurement either: nothing else to put its columns on)
        assert main(["report", "--dem-store", str(store), "--calibration", *source, "--pool",
                     "--out", str(tmp_path / name), "--format", "csv"]) == 0
    capsys.readouterr()
    from_store = _calibration_columns(tmp_path / "from_store")
    # the same doubles read from the same text: equal, and the rows it predicts are there
    pd.testing.assert_frame_equal(from_store, _calibration_columns(tmp_path / "from_json"))
    assert from_store.notna().any().any()


def test_verify_finds_a_damaged_calibration_and_accepts_a_store_from_before(calibrated,
                                                                            tmp_path):
    _, store = calibrated
    damaged = tmp_path / "damaged.h5"
    damaged.write_bytes(store.read_bytes())
    key = stored_calibration(damaged).store_key
    with h5py.File(damaged, "r+") as h5:
        arrays = h5[f"calibrations/{key}/arrays"]
        del arrays["calibration_json"]
        arrays.create_dataset("calibration_json", data=np.frombuffer(b"{not json", np.uint8))
    problems = Store(damaged).verify()
    assert len(problems) == 1 and key in problems[0], problems
    # a store written before calibrations were stored has no /calibrations: sound, none listed
    old = tmp_path / "old.h5"
    old.write_bytes(store.read_bytes())
    with h5py.File(old, "r+") as h5:
        del h5["calibrations"]
    assert Store(old).verify() == []
    assert stored_calibrations(old) == []
    assert Store(old).list_calibrations().empty


def test_the_app_offers_the_stores_calibrations_after_a_restart(calibrated, tmp_path):
    from pidcore.app.calibration import (
        CalibrationRunner,
        CalibrationTask,
        available_calibrations,
        saved_calibrations_table,
    )
    from pidcore.calibrate import calibrate, save_calibration, write_outputs
    from pidcore.calibrate.data import read_measured_table
    from pidcore.dem.simulate import DemConfig

    folder, store = calibrated
    app_store = tmp_path / "app.h5"
    app_store.write_bytes(store.read_bytes())
    # the Calibrate page's runner saves what it calibrated (the library's own functions;
    # calibrate() returns a result computed from the cached runs)
    points = read_measured_table(folder / "m.csv")
    config = DemConfig(cells=2, steady_cycles=10)
    result = calibrate(points, fit=["fixture_mass_kg"], discrepancy=0.4, store_path=app_store,
                       cells=2, steady_cycles=10, dem_config=config, workers=1, progress=False)
    api = types.SimpleNamespace(calibrate=lambda points, **kw: result,
                                write_outputs=write_outputs, save_calibration=save_calibration)
    task = CalibrationTask(("fixture_mass_kg",), 3)
    CalibrationRunner(app_store)._run(api, task, points, ["fixture_mass_kg"], 2, None, None)
    assert task.state == "done" and task.store_key.startswith("cal_"), task.message
    assert f"saved in the store as {task.store_key}" in task.message
    # a restarted app has no task: the store still offers both, newest (the page's) first,
    # and the task's, once saved, is not offered twice
    for running_task in (None, task):
        found = available_calibrations(running_task, {}, cwd=tmp_path, store_path=app_store)
        keys = [c.store_key for c, _ in found]
        assert keys == [task.store_key, stored_calibration(store).store_key], found
        assert all("this store's calibration cal_" in label for _, label in found)
    table = saved_calibrations_table(app_store)
    assert list(table["calibration"]) == keys
    assert list(table["load cases [-]"]) == [3, 3]
    assert list(table["inside 95 % band (LOO) [-]"]) == ["", ""]  # no leave-one-out asked
    assert all(c.endswith("]") for c in table.columns if c not in ("calibration", "specimen",
                                                                   "fitted"))


def test_the_listing_of_a_refused_report_keeps_the_fitted_names(calibrated, capsys, tmp_path):
    # "fitted fixture_mass_kg,--baseline-loss-factor": the report CLI read the calibration's
    # fitted baseline_loss_factor as its own option of that name
    folder, store = calibrated
    copy = tmp_path / "two.h5"
    copy.write_bytes(store.read_bytes())
    table = folder / "m.csv"
    assert main(["calibrate", "--data", str(table), "--fit",
                 "fixture_mass_kg,baseline_loss_factor", "--discrepancy", "0.2",
                 "--dem-store", str(copy), "--out", str(tmp_path / "out"), *TINY]) == 0
    capsys.readouterr()
    assert main(["report", "--dem-store", str(copy), "--calibration", str(copy), "--out",
                 str(tmp_path / "report"), "--format", "csv"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert "fitted 'fixture_mass_kg,baseline_loss_factor';" in err, err
    assert "fitted 'fixture_mass_kg';" in err and "--baseline-loss-factor" not in err, err
    # the library says the same names to a Python caller
    with pytest.raises(ParameterError, match="fitted 'fixture_mass_kg,baseline_loss_factor';"):
        stored_calibration(copy)


def _as_saved_before_provenance(store, tmp_path, *, strip: bool):
    """A copy of ``store`` whose calibration is stored as a pidcore of the previous round
    stored it: under the key of its calibration.json alone, without the record's newer
    fields, and (``strip``) with the calibrated specimen file that pidcore wrote, without
    the ``[provenance]`` table (the last table of the file). Returns (copy, key, text)."""
    copy = tmp_path / ("before.h5" if strip else "before_same.h5")
    copy.write_bytes(store.read_bytes())
    stored = stored_calibration(copy)
    document = json.loads(stored.document_text)
    text = stored.specimen_text
    if strip:
        assert "\n[provenance]\n" in text
        text = text[:text.index("\n[provenance]\n") + 1]
    entry = Store(copy).get_calibration(stored.store_key)
    with h5py.File(copy, "r+") as h5:
        del h5[f"calibrations/{stored.store_key}"]
    legacy = calibration_key(document)
    old_fields = ("calibrated_specimen", "calibrated_specimen_hash", "document_key")
    record = {k: v for k, v in entry.record.items() if k not in old_fields}
    Store(copy).add_calibration(legacy, record, document=stored.document_text,
                                specimen_toml=text)
    return copy, legacy, text


def test_a_fit_stored_before_provenance_is_saved_again_with_it(calibrated, capsys, tmp_path):
    # "stored already": re-running the calibration that the previous round stored gave the
    # user that round's calibrated specimen file, without [provenance]
    folder, store = calibrated
    copy, legacy, old_text = _as_saved_before_provenance(store, tmp_path, strip=True)
    before = Store(copy).get_calibration(legacy)
    out = _calibrate(folder, copy, "0.2", capsys)  # every DEM run cached: the same fit
    listing = Store(copy).list_calibrations()
    assert len(listing) == 2 and listing["key"].iloc[0] == legacy
    new_key = listing["key"].iloc[1]
    assert new_key != legacy
    assert (f"saved calibration {new_key} in {copy}" in out
            and f"the same fit was stored before as {legacy} (its calibrated specimen file, "
                "written by an earlier pidcore, lacks the [provenance]" in out
            and "kept as it was, this one saved beside it" in out), out
    # the new entry is today's file, [provenance] included, the very text --out got
    newest = stored_calibrations(copy)[0]
    assert newest.store_key == new_key
    written = (folder / "out_0.2" / "calibrated_specimen.toml").read_text()
    assert newest.specimen_text == written and "\n[provenance]\n" in written
    source = newest.calibrated_specimen().provenance
    assert source is not None and source.calibrated_from_name == "paper_coupon"
    # the earlier one is kept byte for byte (the store never loses what it held)
    kept = Store(copy).get_calibration(legacy)
    assert kept.attrs["created_utc"] == before.attrs["created_utc"]
    assert stored_calibration(copy, legacy).specimen_text == old_text
    assert Store(copy).verify() == []
    # the listing names the file each entry holds, and the fit they share
    row = listing.iloc[1]
    assert row["calibrated_specimen"] == "paper_coupon_calibrated"
    assert row["calibrated_specimen_hash"] == newest.calibrated_specimen().hash
    assert row["document_key"] == legacy
    # a report must choose: the listing tells the two apart by the file each holds
    with pytest.raises(ParameterError, match="holds 2 calibrations") as refused:
        stored_calibration(copy)
    hash6 = newest.calibrated_specimen().hash[:6]
    assert (f"{new_key} (paper_coupon, fitted 'fixture_mass_kg'; "
            in str(refused.value))
    assert f"; calibrated file paper_coupon_calibrated [{hash6}]); {legacy} (" \
        in str(refused.value), str(refused.value)
    # made again: this one is stored already, nothing added
    again = _calibrate(folder, copy, "0.2", capsys)
    assert f"calibration {new_key} is stored in {copy} already" in again, again
    assert list(Store(copy).list_calibrations()["key"]) == [legacy, new_key]


def test_a_fit_stored_before_with_todays_file_is_not_stored_twice(calibrated, capsys,
                                                                  tmp_path):
    # a store whose entry holds the file today's pidcore writes, under the earlier key of the
    # JSON alone: the same calibration, not a second entry beside it
    folder, store = calibrated
    copy, legacy, _ = _as_saved_before_provenance(store, tmp_path, strip=False)
    out = _calibrate(folder, copy, "0.2", capsys)
    assert f"calibration {legacy} is stored in {copy} already" in out, out
    assert list(Store(copy).list_calibrations()["key"]) == [legacy]


def test_the_key_covers_the_calibrated_specimen(calibrated):
    # two starting files of one set of numbers (another name, or the paper's coupon and a
    # user's paper_coupon.toml) give one calibration.json: the key of the JSON alone gave the
    # second the first's calibrated file, named and provenanced as the first
    from pidcore.specimen import Specimen

    folder, _ = calibrated
    doc = json.loads((folder / "out" / "calibration.json").read_text())
    text = Specimen.from_text((folder / "out" / "calibrated_specimen.toml").read_text()).text
    renamed = text.replace('name = "paper_coupon_calibrated"', 'name = "mine_calibrated"')
    assert renamed != text
    keys = {calibration_key(doc), calibration_key(doc, text), calibration_key(doc, renamed)}
    assert len(keys) == 3
    assert calibration_key(doc, text) == calibration_key(json.loads(json.dumps(doc)), text)


def test_a_reports_provenance_names_its_calibration_and_calibrated_file(calibrated, capsys,
                                                                         tmp_path):
    # the footer named the specimen and the stores but not the calibration of the calibrated
    # columns: two calibrations (or two calibrated files of one name) gave one footer
    import hashlib

    from pidcore.report.downloads import report_files
    from pidcore.specimen import load_specimen

    folder, store = calibrated
    written = folder / "out" / "calibration.json"
    digest = hashlib.sha256(written.read_bytes()).hexdigest()  # the text both hold
    spec = load_specimen(folder / "out" / "calibrated_specimen.toml")
    source = spec.provenance
    said = (f"calibrated specimen {spec.name} sha256 {spec.hash}, calibrated from "
            f"{source.calibrated_from_name} sha256 {source.calibrated_from_sha256}")
    key = stored_calibration(store).store_key
    for name, given, where in (
            ("from_json", [str(written)], f"{written}"),
            ("from_store", [str(store), "--calibration-key", key], f"{store} key {key}")):
        assert main(["report", "--dem-store", str(store), "--calibration", *given,
                     "--out", str(tmp_path / name), "--format", "csv"]) == 0
        lines = (tmp_path / name / "report.provenance.txt").read_text().splitlines()
        assert f"calibration: {where} sha256 {digest}; {said}" in lines, lines
    capsys.readouterr()
    # the app's downloads, from its store's calibration, say the same
    files = report_files(store, calibration=stored_calibration(store))
    text = files["csv_provenance"][1].decode("utf-8")
    assert f"calibration: {store} key {key} sha256 {digest}; {said}" in text.splitlines()
    # no calibration: no such line
    assert main(["report", "--dem-store", str(store), "--out", str(tmp_path / "none"),
                 "--format", "csv"]) == 0
    assert "calibration:" not in (tmp_path / "none" / "report.provenance.txt").read_text()


def test_the_output_and_summary_name_the_specimen_file_and_the_file_written(calibrated,
                                                                           capsys, tmp_path):
    # the command's text and summary.md named neither the specimen calibrated nor the file
    # written: calibrations of two files of one name read alike
    from pidcore.specimen import load_specimen, paper_specimen

    folder, store = calibrated
    copy = tmp_path / "copy.h5"
    copy.write_bytes(store.read_bytes())
    out = _calibrate(folder, copy, "0.2", capsys)
    written = load_specimen(folder / "out_0.2" / "calibrated_specimen.toml")
    start = paper_specimen()
    # the output labels files as the app, reports and dem run do (name [6 hex digits])
    assert (f"Specimen: paper_coupon [{start.hash[:6]}] (from {start.source}); "
            f"calibrated file: {written.name} [{written.hash[:6]}].") \
        in out.splitlines(), out
    summary = (folder / "out_0.2" / "summary.md").read_text()
    assert (f"Specimen: paper_coupon (sha256 {start.hash}, from {start.source}); "
            f"calibrated file: {written.name} (sha256 {written.hash}).") \
        in summary.splitlines()


def test_a_calibrations_design_runs_are_not_reported_as_predictions(calibrated, capsys,
                                                                     tmp_path):
    # the calibration's 2-cell runs showed as rows of their own, "DEM settings: cells 2", with
    # an SDC and no word that they were a fit's inputs; in a store holding no other run, as
    # the coupon's only DEM prediction
    import shutil

    from pidcore.dem import DemConfig, LoadCase
    from pidcore.dem.sweep import run_case
    from pidcore.report.downloads import store_report_table

    _, calibrated_store = calibrated
    store = tmp_path / "dem.h5"
    shutil.copyfile(calibrated_store, store)
    design = Store(store).list_dem_runs()
    assert len(design) == 3 and set(design["cells_simulated"]) == {2}
    # the user's own run at a calibrated load case with another seed is a prediction: kept
    own = run_case(LoadCase(500.0, 5.0, 50.0),
                   DemConfig(cells=2, seed=7, steady_cycles=10, max_transient_cycles=4))
    own.save_to(Store(store))
    cal_key = stored_calibration(store).store_key
    for pool in (False, True):
        out = tmp_path / f"pool_{pool}"
        assert main(["report", "--dem-store", str(store), "--out", str(out), "--format", "csv",
                     *(["--pool"] if pool else [])]) == 0
        printed = capsys.readouterr().out
        table = pd.read_csv(out / "report.csv")
        rows = table[table["DEM runs [-]"] > 0]
        if pool:  # asked for: every run pooled, the design's included
            assert rows["DEM runs [-]"].sum() == 4
            assert "are left out of the comparison" not in printed
            continue
        # one run per load case: at 500 Hz 5 g the user's run, with its own SDC (copied: no
        # tolerance), and not the design run beside it; at the other two cases the design
        # runs, the only runs of the coupon there (a store of a calibration alone had no DEM
        # value to compare with)
        assert len(rows) == 3 and set(rows["DEM runs [-]"]) == {1}
        at = rows[(rows["frequency [Hz]"] == 500) & (rows["acceleration [g]"] == 5)]
        assert list(at["SDC DEM (ours) [-]"]) == [own.record["sdc"]]
        kept = design[design["frequency_hz"].ne(500) | design["acceleration_g"].ne(5)]
        assert sorted(rows["SDC DEM (ours) [-]"]) == sorted([own.record["sdc"],
                                                             *kept["sdc"]])
        assert (f"note: 1 DEM run(s) of the design of calibration(s) {cal_key} (2 cells per "
                "run) are left out of the comparison: they are the inputs of its fit, not "
                "predictions of the specimen (the calibrated DEM is its prediction), and other "
                "runs of the specimen stand at their load cases; --pool pools them with the "
                f"other runs; 2 DEM run(s) of the design of calibration(s) {cal_key} (2 cells "
                "per run) are compared: the only DEM runs of the specimen at their load cases "
                "(a fit's inputs, with the few cells of a fit)") in printed
    # the app's Report tab builds the same table (its note in the library's words)
    app_table = store_report_table(store, None)
    assert (app_table["DEM runs [-]"] > 0).sum() == 3
    assert any(n.startswith("1 DEM run(s) of the design of calibration(s) ")
               and "pool=True pools them with the other runs; 2 DEM run(s)" in n
               for n in app_table.attrs["notes"])


def test_a_calibrations_stored_settings_are_read_by_one_reader():
    # the design-run lookup and the app's table of saved calibrations each parsed a record's
    # parameters_json and its "settings" themselves: one reader, {} for what states none
    from pidcore.calibrate.persist import stored_settings

    assert stored_settings('{"settings": {"cells": 3, "seed": 7}}') == {"cells": 3, "seed": 7}
    for damaged in (None, "", float("nan"), "{broken", "[1, 2]", '{"settings": [3]}',
                    '{"other": {}}'):
        assert stored_settings(damaged) == {}, damaged


def _printed_report_line(said: str) -> list[str] | None:
    """The `pidcore report ...` calibrate printed to paste, as the shell splits it."""
    import re
    import shlex

    lines = re.findall(r"\((pidcore report [^()]*)\)$", said, re.M)
    return shlex.split(lines[0]) if lines else None


def test_the_report_line_calibrate_prints_shows_the_calibrated_load_cases(
        calibrated, capsys, tmp_path, monkeypatch):
    folder, store = calibrated
    copy = tmp_path / "dem.h5"
    copy.write_bytes(store.read_bytes())
    line = _printed_report_line(_calibrate(folder, copy, "0.3", capsys))
    monkeypatch.chdir(tmp_path)  # as pasted: --out report_out is made where the user is
    assert main([*line[1:], "--format", "csv"]) == 0
    table = pd.read_csv(tmp_path / "report_out" / "report.csv")
    # a row of each of the table's 3 load cases, each with the calibration's prediction
    assert sorted(zip(table["frequency [Hz]"], table["acceleration [g]"], strict=True)) == \
        [(500.0, 1.0), (500.0, 5.0), (1000.0, 5.0)]
    assert np.isfinite(table["SDC calibrated DEM (Eq. 11) [-]"]).all()


def test_a_fit_of_a_dem_parameter_to_a_table_prints_no_report_line_of_no_rows(
        capsys, tmp_path, monkeypatch):
    # the line printed, run as pasted, reported "(no load cases)" and exit 0: the design runs
    # of a DEM parameter are variants of the specimen, which a report leaves out, and the
    # --data table is no report input
    table = tmp_path / "m.csv"
    table.write_text(ROWS)
    store = tmp_path / "dem.h5"
    assert main(["calibrate", "--data", str(table), "--fit", "rolling_friction",
                 "--design-size", "3", "--discrepancy", "0.2", "--dem-store", str(store),
                 *TINY]) == 0
    said = capsys.readouterr().out
    key = Store(store).list_calibrations()["key"].iloc[0]
    assert _printed_report_line(said) is None, said
    assert (f"saved calibration {key} in {store} (no report line to paste: its DEM runs are "
            "variants of the specimen") in said
    assert f"--calibration {store} --calibration-key {key} shows them" in said
    # what the line would have been does report nothing: the refusal hides no report of rows
    monkeypatch.chdir(tmp_path)
    assert main(["report", "--dem-store", str(store), "--calibration", str(store),
                 "--calibration-key", key, "--out", "r", "--format", "csv"]) == 0
    assert pd.read_csv(tmp_path / "r" / "report.csv").empty
