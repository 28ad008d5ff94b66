"""A measurement records its specimen file's sha256 beside its name: two files of one name
(an edited ``panel.toml``) are two specimens whose tests are not pooled, and each meets only
its own DEM runs and calibration. Records saved before the hash was (name only) read as
before, by name."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from types import SimpleNamespace

import pandas as pd
import pytest
from _panel_tests import panel_export, panel_specimen

from pidcore.cli import main
from pidcore.dem.persist import run_or_load
from pidcore.dem.simulate import DemConfig, LoadCase
from pidcore.errors import ParameterError
from pidcore.specimen import (
    Specimen,
    calibrated_name,
    calibrated_provenance,
    paper_specimen,
)
from pidcore.store import Store

# Bookkeeping: one cell, few cycles (the physics is tested elsewhere).
TINY = DemConfig(cells=1, steady_cycles=4, block_cycles=2, max_transient_cycles=2)
CASE = LoadCase(1000.0, 5.0, 25.0)
SHA = "specimen sha256"


@pytest.fixture(scope="module")
def two_panels(tmp_path_factory):
    """Two specimen files named "panel" with different contents (fixture mass), one DEM run
    of each at CASE, and one test analysed with each (`pidcore analyze --specimen`)."""
    where = tmp_path_factory.mktemp("two_panels")
    first, second = panel_specimen(0.05), panel_specimen(0.08)
    assert first.name == second.name == "panel" and first.hash != second.hash
    (where / "a").mkdir()
    (where / "b").mkdir()
    first_file, second_file = where / "a" / "panel.toml", where / "b" / "panel.toml"
    first_file.write_text(first.to_toml())
    second_file.write_text(second.to_toml())
    runs = where / "runs.h5"
    run_a = run_or_load(runs, first, CASE, TINY)
    run_b = run_or_load(runs, second, CASE, TINY)
    tests = where / "tests.h5"
    docs = []
    for export, specimen_file, damping in (("ta_fill25.csv", first_file, 5.0),
                                           ("tb_fill25.csv", second_file, 9.0)):
        path = panel_export(where / export, damping)
        docs.append((path, specimen_file))
    return SimpleNamespace(where=where, first=first, second=second, first_file=first_file,
                           second_file=second_file, runs=runs, run_a=run_a, run_b=run_b,
                           tests=tests, exports=docs)


@pytest.fixture(scope="module")
def analysed(two_panels, tmp_path_factory):
    """The two tests analysed into one store, each with its own panel.toml; the JSON
    documents `pidcore analyze --json` printed."""
    import contextlib
    import io

    docs = []
    for path, specimen_file in two_panels.exports:
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            assert main(["analyze", str(path), "--specimen", str(specimen_file), "--store",
                         str(two_panels.tests), "--json"]) == 0
        docs.append(json.loads(out.getvalue()))
    return docs


def test_analyze_saves_and_prints_the_specimen_files_hash(two_panels, analysed):
    """Was: only the name "panel" was saved, the same for both files."""
    first, second = two_panels.first, two_panels.second
    assert [d["records"][0]["specimen"] for d in analysed] == ["panel", "panel"]
    assert [d["records"][0]["specimen_sha256"] for d in analysed] == [first.hash, second.hash]
    listing = Store(two_panels.tests).list_analyses().sort_values("source")
    assert listing["specimen"].tolist() == ["panel", "panel"]
    assert listing["specimen_sha256"].tolist() == [first.hash, second.hash]


def _report(two_panels, tmp_path, specimen_file: Path, *extra: str) -> pd.DataFrame:
    out = tmp_path / f"report_{specimen_file.parent.name}_{len(extra)}"
    assert main(["report", "--store", str(two_panels.tests), "--dem-store",
                 str(two_panels.runs), "--specimen", str(specimen_file), "--out", str(out),
                 "--format", "csv", *extra]) == 0
    table = pd.read_csv(out / "report.csv", comment="#", keep_default_na=False,
                        na_values=[""])
    measured = table[table["source file(s)"].fillna("") != ""].reset_index(drop=True)
    return measured.assign(**{"source file(s)": [Path(s).name
                                                 for s in measured["source file(s)"]]})


@pytest.mark.usefixtures("undrawn_report_figures")
def test_tests_of_two_files_of_one_name_are_not_pooled_and_meet_their_own_runs(
        two_panels, analysed, tmp_path):
    """Was: both tests were pooled into one row of specimen "panel", and met the DEM runs of
    either file (or none: "two different specimen files named panel; not pooled")."""
    sdc = {Path(d["records"][0]["source"]).name: d["records"][0]["sdc"] for d in analysed}
    for specimen_file, own, run, mine in (
            (two_panels.first_file, two_panels.first, two_panels.run_a, "ta_fill25.csv"),
            (two_panels.second_file, two_panels.second, two_panels.run_b, "tb_fill25.csv")):
        table = _report(two_panels, tmp_path, specimen_file)
        # one row per test: each row's measured SDC is its single record's, not a mean
        assert sorted(table["source file(s)"]) == ["ta_fill25.csv", "tb_fill25.csv"]
        for _, row in table.iterrows():
            assert row["SDC measured (Eq. 11) [-]"] == pytest.approx(sdc[row["source file(s)"]],
                                                            rel=1e-9)  # as printed: 6+ digits
        row = table[table["source file(s)"] == mine].iloc[0]
        other = table[table["source file(s)"] != mine].iloc[0]
        assert row[SHA] == own.hash and other[SHA] != own.hash
        # the report's runs are this file's: its test meets them, the other file's does not
        assert row["SDC DEM (ours) [-]"] == pytest.approx(run.sdc, rel=1e-9)
        assert math.isnan(other["SDC DEM (ours) [-]"])
        theirs = other[SHA][:6]
        assert other["note"].startswith(f"no DEM runs of panel [{theirs}] for acrylic")
        assert f"panel [{theirs}]'s are left out of a report of another specimen" \
            in other["note"]


def test_runs_are_chosen_by_the_tests_hash_and_by_name_without_one(two_panels):
    from pidcore.compare.specimens import runs_for_measurement

    runs = Store(two_panels.runs).list_dem_runs()
    for own in (two_panels.first, two_panels.second):
        met = runs_for_measurement(runs, "panel", "acrylic", "z", own.hash)
        assert met.runs is not None and met.runs["specimen_sha256"].tolist() == [own.hash]
        assert met.specimen == f"panel [{own.hash[:6]}]"
    # a record saved before the hash was: by name, and two files of the name are not pooled
    for old in ("", math.nan):
        met = runs_for_measurement(runs, "panel", "acrylic", "z", old)
        assert met.runs is None and met.refused and "2 different specimen files" in met.note


def test_calibrate_store_keeps_the_files_tests_apart(two_panels, analysed):
    """Was: the two tests were averaged into one measured point of "panel", and calibrating
    either file fitted the other's test too."""
    from pidcore.calibrate.calibrate import check_point_specimens
    from pidcore.calibrate.data import measured_from_store, points_for_specimen

    points = measured_from_store(two_panels.tests)
    assert sorted(p.specimen_sha256 for p in points) == sorted(
        [two_panels.first.hash, two_panels.second.hash])
    sdc = {d["records"][0]["specimen_sha256"]: d["records"][0]["sdc"] for d in analysed}
    for p in points:  # one test each: its own SDC, not the mean of both
        assert p.sdc == pytest.approx(sdc[p.specimen_sha256], rel=1e-12)
    kept, note = points_for_specimen(points, two_panels.first)
    assert [p.specimen_sha256 for p in kept] == [two_panels.first.hash]
    assert f"panel [{two_panels.second.hash[:6]}] (another file of that name)" in note
    first, second = two_panels.first.hash[:6], two_panels.second.hash[:6]
    with pytest.raises(ParameterError, match=rf"name specimen 'panel \[{second}\]'"
                       rf".*not 'panel \[{first}\]'"):
        check_point_specimens(points, two_panels.first)
    # the file calibrated from the first (its [provenance]) speaks for the first's tests only
    calibrated = dataclasses.replace(two_panels.first, name=calibrated_name("panel"),
                                     provenance=calibrated_provenance(two_panels.first))
    kept, _ = points_for_specimen(points, calibrated)
    assert [p.specimen_sha256 for p in kept] == [two_panels.first.hash]


def _calibration_of(specimen: Specimen, path: Path):
    from pidcore.calibrate.prediction import CalibratedPrediction, Calibration

    written = dataclasses.replace(specimen, name=calibrated_name(specimen.name),
                                  provenance=calibrated_provenance(specimen))
    # a band that can judge a measurement: 0 .. 10 spans every plausible SDC (uninformative)
    return Calibration(path, {}, (CalibratedPrediction(CASE, 0.2, 0.05, 0.5),),
                       specimen_text=written.to_toml())


def test_a_calibration_speaks_for_the_tests_of_its_own_file_only(two_panels, tmp_path):
    """Was: by name, a calibration of one panel.toml predicted the other's tests."""
    first, second = two_panels.first, two_panels.second
    calibration = _calibration_of(first, tmp_path / "calibration.json")
    assert calibration.speaks_for("panel", first.hash)
    assert not calibration.speaks_for("panel", second.hash)
    assert calibration.other_file_reason(second.hash, "panel") == (
        f"it calibrates specimen panel [{first.hash[:6]}], not panel [{second.hash[:6]}] "
        "(another file of the same name)")
    # a record without the hash (an older store) is matched by its name, as before
    assert calibration.speaks_for("panel", "") and calibration.speaks_for("panel", math.nan)


@pytest.mark.usefixtures("undrawn_report_figures")
def test_reports_calibrated_band_goes_to_the_rows_of_its_file_only(two_panels, analysed,
                                                                    tmp_path):
    folder = tmp_path / "cal"
    folder.mkdir()
    calibrated = dataclasses.replace(two_panels.first, name=calibrated_name("panel"),
                                     provenance=calibrated_provenance(two_panels.first))
    (folder / "calibrated_specimen.toml").write_text(calibrated.to_toml())
    from pidcore.report.table import CALIBRATED_INSIDE_COLUMN, add_calibration_columns

    calibration = _calibration_of(two_panels.first, folder / "calibration.json")
    table = pd.DataFrame({
        "frequency [Hz]": [1000.0, 1000.0], "acceleration [g]": [5.0, 5.0],
        "packing ratio [%]": [25.0, 25.0], "material": ["acrylic", "acrylic"],
        "SDC measured (Eq. 11) [-]": [0.1, 0.1], "SDC measured (Eq. 11) stderr [-]": [0.01, 0.01],
        "specimen": ["panel", "panel"],
        SHA: [two_panels.first.hash, two_panels.second.hash], "note": ["", ""]})
    out = add_calibration_columns(table, calibration)
    assert out[CALIBRATED_INSIDE_COLUMN].tolist() == ["yes", "not compared"]
    assert "another file of the same name" in out["note"].iloc[1]


@pytest.mark.usefixtures("undrawn_report_figures")
def test_a_store_saved_before_the_hash_reads_by_name(two_panels, tmp_path):
    """Records without specimen_sha256 (an older pidcore) still report: their rows say no
    hash, and runs of two files of their name are refused, not pooled, as before."""
    from pidcore.measure import AnalysisOptions, analyze_file, save_analyses

    old = tmp_path / "old.h5"
    results = [analyze_file(path) for path, _ in two_panels.exports]
    cases = [CASE, CASE]
    save_analyses(old, results, AnalysisOptions(),
                  [(p.name, c, "file name") for (p, _), c in zip(two_panels.exports, cases,
                                                                   strict=True)],
                  fields=[{"specimen": "panel"}, {"specimen": "panel"}])
    listing = Store(old).list_analyses()
    assert "specimen_sha256" not in listing.columns
    out = tmp_path / "old_report"
    assert main(["report", "--store", str(old), "--dem-store", str(two_panels.runs),
                 "--specimen", str(two_panels.first_file), "--out", str(out),
                 "--format", "csv"]) == 0
    table = pd.read_csv(out / "report.csv", comment="#", keep_default_na=False)
    measured = table[table["source file(s)"] != ""]
    # one name, no hash: one specimen, its two tests pooled in one row and compared with
    # the reported file's runs by their name, as before the hash was saved
    assert len(measured) == 1 and measured[SHA].tolist() == [""]
    assert measured["source file(s)"].iloc[0].count(".csv") == 2
    assert float(measured["SDC DEM (ours) [-]"].iloc[0]) == pytest.approx(
        two_panels.run_a.sdc, rel=1e-9)
    # without a report's choice of runs, two files' runs of that name are refused, not pooled
    from pidcore.compare.specimens import runs_for_measurement

    met = runs_for_measurement(Store(two_panels.runs).list_dem_runs(), "panel", "acrylic", "z",
                               listing["specimen_sha256"].iloc[0]
                               if "specimen_sha256" in listing.columns else "")
    assert met.refused and "2 different specimen files named panel" in met.note
    from pidcore.calibrate.data import measured_from_store

    points = measured_from_store(old)
    assert len(points) == 1 and points[0].specimen_sha256 == ""


def test_app_compare_groups_two_files_of_one_name_apart(two_panels, analysed):
    from pidcore.compare.case import MeasuredEntry
    from pidcore.report.case_view import group_entries, group_name
    from pidcore.store.listing import saved_analyses

    saved = saved_analyses(two_panels.tests)
    store = Store(two_panels.tests)
    entries = [MeasuredEntry.from_store(row, store.get_analysis(row["key"]).arrays)
               for _, row in saved.iterrows()]
    assert sorted(e.specimen_sha256 for e in entries) == sorted(
        [two_panels.first.hash, two_panels.second.hash])
    groups = group_entries(entries)
    assert len(groups) == 2 and all(len(g) == 1 for g in groups)
    names = sorted(group_name(entries, g) for g in groups)
    assert names == sorted(f"{CASE.full_label()}, specimen panel [{h[:6]}]"
                           for h in (two_panels.first.hash, two_panels.second.hash))


def test_report_rows_part_two_files_of_one_name_but_not_the_papers_coupon(two_panels):
    """Rows are per specimen file where the records saved one; the paper's coupon is one
    coupon whatever hash (either table material) or none a record saved."""
    from pidcore.report.table import build_report_table

    paper = paper_specimen()
    records = [("a.csv", "panel", two_panels.first.hash, 0.10),
               ("b.csv", "panel", two_panels.second.hash, 0.30),
               ("c.csv", "paper_coupon", paper.hash, 0.20),
               ("d.csv", "paper_coupon", math.nan, 0.22)]  # saved before the hash was
    analyses = pd.DataFrame([{"source": source, "frequency_hz": 1000.0, "acceleration_g": 5.0,
                              "fill_percent": 25.0, "material": "acrylic", "direction": "z",
                              "sdc": sdc, "sdc_stderr": 0.01, "specimen": name,
                              "specimen_sha256": sha} for source, name, sha, sdc in records])
    table = build_report_table(None, analyses, None)
    rows = {row["source file(s)"]: row for _, row in table.iterrows()}
    assert set(rows) == {"a.csv", "b.csv", "c.csv; d.csv"}
    assert rows["a.csv"]["SDC measured (Eq. 11) [-]"] == pytest.approx(0.10, rel=1e-12)
    assert rows["b.csv"]["SDC measured (Eq. 11) [-]"] == pytest.approx(0.30, rel=1e-12)
    assert [rows[k][SHA] for k in ("a.csv", "b.csv", "c.csv; d.csv")] == [
        two_panels.first.hash, two_panels.second.hash, ""]


def test_a_typed_name_resolves_to_its_one_known_file(two_panels):
    """The app's settings grid: a name meets the known file of that name (saved as
    `analyze --specimen` saves it); two files of the name need the hashed name."""
    from pidcore.specimen import hashed_name, resolve_specimen_name

    first, second = two_panels.first, two_panels.second
    one = resolve_specimen_name(" panel ", [paper_specimen(), first])
    assert (one.name, one.sha256, one.note) == ("panel", first.hash, "")
    both = resolve_specimen_name("panel", [first, second])
    assert (both.name, both.sha256) == ("panel", "")
    assert both.note.startswith("specimen panel: 2 known files of that name (")
    picked = resolve_specimen_name(hashed_name("panel", second.hash), [first, second])
    assert (picked.name, picked.sha256) == ("panel", second.hash)
    assert resolve_specimen_name("", [first]).name == ""
    # another file of the paper coupon's name is saved as its tests are by the CLI
    odd = Specimen.from_text(paper_specimen().with_values(
        {"coupon.fixture_mass_kg": 0.05}).to_toml())
    named = resolve_specimen_name("paper_coupon", [odd])
    assert (named.name, named.sha256) == (f"paper_coupon [{odd.hash[:6]}]", odd.hash)


def test_a_tests_specimen_is_labelled_by_one_rule():
    # calibrate's point labels and the app's Compare groups each wrote "name [hash6]" and its
    # exception (a name holding its hash already) themselves: one function now
    from pidcore.calibrate.data import MeasuredPoint
    from pidcore.specimen import hashed_name, tested_label

    sha = "ab94ff" + "0" * 58
    assert tested_label("panel", sha) == hashed_name("panel", sha) == "panel [ab94ff]"
    # the name a paper_coupon file's tests are saved under carries its hash once
    assert tested_label("paper_coupon [45d792]", sha) == "paper_coupon [45d792]"
    assert tested_label("panel", "") == "panel"  # saved before the hash was: by name
    assert tested_label("", sha) == ""  # no specimen named
    point = MeasuredPoint(500.0, 1.0, 50.0, 0.5, specimen="panel", specimen_sha256=sha)
    assert point.label() == "500 Hz, 1 g, 50 %, acrylic, specimen panel [ab94ff]"


def test_dem_only_rows_of_a_specimens_report_carry_its_files_hash(two_panels):
    """Was: a DEM-only row of `report --specimen panel.toml` named the specimen "panel" and
    left "specimen sha256" empty, though the footer named the file's hash and the rows of its
    tests carried it."""
    from pidcore.report.pipeline import specimen_report_table

    runs = Store(two_panels.runs).list_dem_runs()
    for own in (two_panels.first, two_panels.second):
        table = specimen_report_table(runs, None, specimen=own).table
        (row,) = [r for _, r in table.iterrows() if r["DEM runs [-]"] > 0]
        assert (row["specimen"], row[SHA]) == ("panel", own.hash)
    # the paper's coupon stays matched by name: its rows' cell is empty, as its tests' are
    paper = paper_specimen()
    Store(two_panels.where / "paper.h5").add_dem_run("coupon", {
        "frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": 50.0,
        "material": "acrylic", "direction": "z", "sdc": 0.2, "sdc_stderr": 0.01})
    table = specimen_report_table(Store(two_panels.where / "paper.h5").list_dem_runs(), None,
                                  specimen=paper).table
    assert table["specimen"].tolist() == ["paper_coupon"] and table[SHA].tolist() == [""]
