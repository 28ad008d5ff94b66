"""Measured rows of a report of one specimen (``pidcore report --specimen``): whose specimen a
row is, and what a row with no DEM run of its specimen says (user trial defect 10)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from pidcore.compare.align import Aligner
from pidcore.compare.loadcase import LoadCase
from pidcore.report.pipeline import specimen_report_table
from pidcore.report.table import ALIGNMENT_COLUMN, build_report_table
from pidcore.specimen import load_specimen, paper_specimen

STEEL = Path(__file__).resolve().parents[1] / "data_samples" / "specimens" / "steel_6mm.toml"


def _run(key: str, material: str, sdc: float, specimen) -> dict:
    return {"case_key": key, "frequency_hz": 1000.0, "acceleration_g": 5.0,
            "fill_percent": 50.0, "material": material, "direction": "z", "sdc": sdc,
            "sdc_stderr": 0.01, "specimen_name": specimen.name,
            "specimen_sha256": specimen.hash}


@pytest.fixture(scope="module")
def steel():
    return load_specimen(STEEL)


@pytest.fixture(scope="module")
def store_runs(steel) -> pd.DataFrame:
    """Two acrylic z runs of the paper's coupon and one steel z run of steel_6mm."""
    paper = paper_specimen("acrylic")
    return pd.DataFrame([_run("p1", "acrylic", 0.50, paper),
                         {**_run("p2", "acrylic", 0.40, paper), "frequency_hz": 500.0},
                         _run("s1", "steel", 1.75, steel)])


@pytest.fixture(scope="module")
def analyses() -> pd.DataFrame:
    """An acrylic measurement naming no specimen and a steel one of another specimen."""
    return pd.DataFrame({
        "frequency_hz": [1000.0, 1000.0], "acceleration_g": [5.0, 5.0],
        "fill_percent": [50.0, 50.0], "material": ["acrylic", "steel"],
        "direction": ["z", "z"], "sdc": [3.5, 3.6], "sdc_stderr": [0.05, 0.05],
        "source": ["acrylic.h5", "other.h5"], "specimen": ["", "other_coupon"]})


def _measured(table: pd.DataFrame, source: str) -> pd.Series:
    return table[table["source file(s)"] == source].iloc[0]


def test_rows_without_runs_of_their_specimen_name_it_and_the_other_specimens_runs(
        steel, store_runs, analyses):
    """Was: status out_of_range, note "no DEM runs of ours for acrylic, direction z" though
    the store holds the paper coupon's acrylic runs; the other_coupon row said "no DEM runs
    of ours for steel" beside a steel row (steel_6mm's)."""
    table = specimen_report_table(store_runs, analyses, specimen=steel).table
    acrylic = _measured(table, "acrylic.h5")
    assert acrylic[ALIGNMENT_COLUMN] == "no_dem_runs"
    assert acrylic["note"] == ("no DEM runs of steel_6mm for acrylic, direction z (the store "
                               "has 2 of paper_coupon, another specimen's: report without "
                               "specimen= to compare them)")
    other = _measured(table, "other.h5")
    assert other[ALIGNMENT_COLUMN] == "no_dem_runs"
    assert other["note"] == (f"no DEM runs of other_coupon for steel, direction z (the store "
                             f"has 1 of steel_6mm [{steel.hash[:6]}], another specimen's: not "
                             f"compared with a test of other_coupon)")
    assert "of ours" not in " ".join(table["note"])


def test_a_measured_row_names_its_own_specimen_not_the_reports(steel, store_runs, analyses):
    """Was: the acrylic measurement's row had specimen steel_6mm (the --specimen's label on a
    row of another material)."""
    table = specimen_report_table(store_runs, analyses, specimen=steel).table
    assert _measured(table, "acrylic.h5")["specimen"] == ""  # unknown: not steel_6mm's test
    assert _measured(table, "other.h5")["specimen"] == "other_coupon"
    dem_row = table[table["source file(s)"] == ""].iloc[0]
    assert (dem_row["material"], dem_row["specimen"]) == ("steel", "steel_6mm")
    # a measurement of the specimen's own material is its test and keeps its label
    steel_test = analyses.assign(specimen=["", ""], source=["acrylic.h5", "steel.h5"])
    table = specimen_report_table(store_runs, steel_test, specimen=steel).table
    row = _measured(table, "steel.h5")
    assert (row["specimen"], row[ALIGNMENT_COLUMN]) == ("steel_6mm", "grid")


def test_default_report_names_other_specimens_runs_and_how_to_compare_them(
        store_runs, analyses):
    """Without --specimen a steel measurement of no named specimen meets no paper run; the
    note names the steel_6mm run and the --specimen that compares it."""
    steel_only = analyses.assign(specimen=["", ""])
    table = specimen_report_table(store_runs, steel_only).table
    row = _measured(table, "other.h5")
    assert row[ALIGNMENT_COLUMN] == "no_dem_runs"
    assert row["note"].startswith("no DEM runs of paper_coupon for steel, direction z (the "
                                  "store has 1 of steel_6mm [")
    assert row["note"].endswith("report with their specimen=FILE to compare them)")
    assert _measured(table, "acrylic.h5")[ALIGNMENT_COLUMN] == "grid"


def test_aligner_without_runs_of_the_material_says_no_dem_runs_not_out_of_range(store_runs):
    aligner = Aligner.from_tables(store_runs)
    out = aligner.align(LoadCase(1000.0, 5.0, 50.0, material="aluminium"))
    assert out.status == "no_dem_runs" and "no DEM runs" in out.message
    # a table built without a store listing names "ours" as before
    table = build_report_table(store_runs.iloc[:1], pd.DataFrame({
        "frequency_hz": [1000.0], "acceleration_g": [5.0], "fill_percent": [50.0],
        "material": ["aluminium"], "direction": ["z"], "sdc": [1.0], "sdc_stderr": [0.1],
        "source": ["al.h5"]}), None)
    assert _measured(table, "al.h5")["note"] == "no DEM runs of ours for aluminium, direction z"


def test_the_apps_report_tab_says_how_to_compare_the_other_runs_in_its_own_words(
        steel, store_runs, analyses):
    from pidcore.report.downloads import CHOOSE_SPECIMEN_APP

    table = specimen_report_table(store_runs, analyses, specimen=steel,
                                  choose_another=CHOOSE_SPECIMEN_APP).table
    assert _measured(table, "acrylic.h5")["note"].endswith(
        "another specimen's: choose theirs with the Report tab's specimen choice to compare "
        "them)")


def test_a_specimen_baseline_the_measurements_did_not_subtract_is_said(steel, store_runs,
                                                                        analyses):
    # the specimen file's [coupon] baseline_loss_factor (the empty coupon's damping) was used
    # only by calibrate: a report of the specimen compared measured SDCs that include it with
    # the DEM's (particles alone), and its provenance said baseline_loss_factor=0.0
    import dataclasses
    import json
    import math

    damped = steel.with_values({"coupon.baseline_loss_factor": 0.002})
    mine = analyses.assign(material="steel", specimen=["", "other_coupon"],
                           parameters_json=[json.dumps({"baseline_loss_factor": 0.0})] * 2)
    notes = specimen_report_table(store_runs, mine, specimen=damped).table.attrs["notes"]
    (note,) = [n for n in notes if "baseline_loss_factor" in n]
    # one record: the other_coupon one is not this specimen's test
    assert "states [coupon] baseline_loss_factor 0.002" in note and "1 measured record(s)" in note
    assert f"at most {2 * math.pi * 0.002:.3g}" in note and "baseline_loss_factor=0.002" in note
    # the exact subtraction needs the structure's mass: the specimen's coupon and fixture
    structure = damped.coupon.mass_kg + damped.coupon.fixture_mass_kg
    assert f"structure_mass_kg={structure:.4g}" in note
    # subtracted at analysis, or no baseline stated: nothing to say
    done = mine.assign(parameters_json=[json.dumps({"baseline_loss_factor": 0.002})] * 2)
    for specimen, frame in ((damped, done), (steel, mine),
                            (dataclasses.replace(damped), analyses)):
        notes = specimen_report_table(store_runs, frame, specimen=specimen).table.attrs["notes"]
        assert not [n for n in notes if "baseline_loss_factor" in n]


def test_a_test_of_a_specimen_whose_runs_the_store_holds_says_how_to_compare_them(
        steel, store_runs, analyses):
    # a report of the paper's coupon with a steel measurement named steel_6mm, whose run the
    # store holds: the note said the steel_6mm run was "another specimen's: not compared with
    # a test of steel_6mm", of the test's own specimen
    named = analyses.assign(specimen=["", "steel_6mm"])
    row = _measured(specimen_report_table(store_runs, named).table, "other.h5")
    assert row[ALIGNMENT_COLUMN] == "no_dem_runs"
    assert row["note"] == (f"no DEM runs of steel_6mm for steel, direction z among this "
                           f"report's runs (the store has 1 of steel_6mm [{steel.hash[:6]}]; "
                           "steel_6mm's are left out of a report of another specimen: report "
                           "with their specimen=FILE to compare them)")
    assert "another specimen's: not compared" not in row["note"]
    # with its --specimen the same test meets that run
    row = _measured(specimen_report_table(store_runs, named, specimen=steel).table, "other.h5")
    assert row[ALIGNMENT_COLUMN] == "grid"


def test_a_test_of_another_acrylic_specimen_gets_no_paper_table3_columns(store_runs):
    """Was: the default report put the paper's Table 3 (DEM 0.5612, measured 0.63 at 1000 Hz,
    5 g, 50 %) beside a measurement naming another acrylic specimen, a coupon the paper never
    tested. The unnamed measurement at the same case is the paper's coupon's and keeps them."""
    analyses = pd.DataFrame({
        "frequency_hz": [1000.0, 1000.0], "acceleration_g": [5.0, 5.0],
        "fill_percent": [50.0, 50.0], "material": ["acrylic", "acrylic"],
        "direction": ["z", "z"], "sdc": [3.5, 3.6], "sdc_stderr": [0.05, 0.05],
        "source": ["paper.h5", "mine.h5"], "specimen": ["", "my_acrylic"]})
    table = specimen_report_table(store_runs, analyses).table
    mine = _measured(table, "mine.h5")
    assert mine["specimen"] == "my_acrylic"
    assert pd.isna(mine["SDC DEM (paper) [-]"]) and pd.isna(mine["SDC measured (paper) [-]"])
    assert "not the paper's coupon" in mine["note"]
    paper = _measured(table, "paper.h5")  # Table 3 values, transcribed in paper_table3.csv
    assert (paper["SDC DEM (paper) [-]"], paper["SDC measured (paper) [-]"]) == (0.5612, 0.63)


def test_a_test_of_a_specimen_meets_the_runs_of_its_calibrated_file(steel):
    """Trial 14h: measurements named alumina_6mm_trial, a calibration from them, and DEM runs
    of the calibrated file (alumina_6mm_trial_calibrated) at the tested load cases: `report
    --specimen alumina_6mm_trial_calibrated.toml` put every test on a no_dem_runs row of its
    own ("another specimen's: not compared with a test of alumina_6mm_trial") beside the DEM
    row of its own load case, while the calibration's band was compared with it."""
    import dataclasses

    calibrated = dataclasses.replace(
        steel.with_values({"coupon.fixture_mass_kg": 0.05}), name="steel_6mm_calibrated")
    runs = pd.DataFrame([_run("c1", "steel", 1.75, calibrated)])
    tests = pd.DataFrame({
        "frequency_hz": [1000.0], "acceleration_g": [5.0], "fill_percent": [50.0],
        "material": ["steel"], "direction": ["z"], "sdc": [1.7], "sdc_stderr": [0.05],
        "source": ["steel.h5"], "specimen": ["steel_6mm"]})
    table = specimen_report_table(runs, tests, specimen=calibrated).table
    assert len(table) == 1  # the test's row is the DEM row of its load case
    row = _measured(table, "steel.h5")
    assert row[ALIGNMENT_COLUMN] == "grid"
    assert row["SDC DEM (ours) [-]"] == pytest.approx(1.75)  # the calibrated file's run
    assert row["specimen"] == "steel_6mm"  # the specimen tested, and the note names the runs'
    assert (f"a test of steel_6mm compared with the DEM runs of steel_6mm_calibrated "
            f"[{calibrated.hash[:6]}], the file pidcore calibrate made from it") in row["note"]
    # the file's own runs, where the store holds them, are still the ones a test of it meets
    both = pd.concat([runs, pd.DataFrame([_run("s1", "steel", 1.60, steel)])])
    table = specimen_report_table(both, tests, specimen=steel).table
    row = _measured(table, "steel.h5")
    assert row["SDC DEM (ours) [-]"] == pytest.approx(1.60)
    assert "calibrate made from it" not in str(row["note"])
    # another specimen's calibrated file is not this one's
    other = tests.assign(specimen=["steel_6mm_b"])
    row = _measured(specimen_report_table(runs, other, specimen=calibrated).table, "steel.h5")
    assert row[ALIGNMENT_COLUMN] == "no_dem_runs"



def test_a_report_of_an_edited_file_names_the_stored_runs_as_another_file_of_its_name(
        steel, store_runs, analyses):
    # steel_6mm.toml edited (another coupon mass) and reported with its test named
    # steel_6mm: the store's runs of the earlier file were said to be "left out of a report
    # of another specimen", of a report of steel_6mm itself
    edited = steel.with_values({"coupon.mass_kg": 0.04})
    assert edited.name == steel.name and edited.hash != steel.hash
    named = analyses.assign(specimen=["", "steel_6mm"])
    row = _measured(specimen_report_table(store_runs, named, specimen=edited).table,
                    "other.h5")
    assert row[ALIGNMENT_COLUMN] == "no_dem_runs"
    assert row["note"] == (f"no DEM runs of steel_6mm for steel, direction z among this "
                           f"report's runs (the store has 1 of steel_6mm [{steel.hash[:6]}]: "
                           "another file named steel_6mm than the one reported, whose hash "
                           "differs; report with their specimen=FILE to compare them)")


def test_a_calibrated_files_baseline_is_said_beside_the_tests_of_the_file_it_was_made_from(
        steel, store_runs, analyses):
    # report --specimen x_calibrated.toml: its tests are saved as "x" (with x's sha256), and
    # the baseline loss factor calibrate fitted into the file went unsaid beside them
    import dataclasses
    import json

    from pidcore.specimen import calibrated_name, calibrated_provenance

    calibrated = dataclasses.replace(
        steel.with_values({"coupon.baseline_loss_factor": 0.0187}),
        name=calibrated_name(steel.name), provenance=calibrated_provenance(steel))
    tests = analyses.assign(material="steel", specimen=[steel.name, "other_coupon"],
                            specimen_sha256=[steel.hash, ""],
                            parameters_json=[json.dumps({"baseline_loss_factor": 0.0})] * 2)
    notes = specimen_report_table(store_runs, tests, specimen=calibrated).table.attrs["notes"]
    (note,) = [n for n in notes if "baseline_loss_factor" in n]
    # the steel_6mm test only: other_coupon's is another specimen's
    assert "states [coupon] baseline_loss_factor 0.0187" in note
    assert "1 measured record(s)" in note
    # a test of another file of that name (another sha256) is not this file's
    other_file = tests.assign(specimen_sha256=["f" * 64, ""])
    notes = specimen_report_table(store_runs, other_file,
                                  specimen=calibrated).table.attrs["notes"]
    assert not [n for n in notes if "baseline_loss_factor" in n]


def test_the_baseline_notes_sidecar_columns_stay_column_names_in_the_cli(steel, store_runs,
                                                                        analyses):
    # pidcore report printed "or a sidecar's --baseline-loss-factor and structure_mass_g":
    # a flag where the sidecar's column name belongs
    import json

    from pidcore.cli._vocabulary import cli_words

    damped = steel.with_values({"coupon.baseline_loss_factor": 0.002})
    mine = analyses.assign(material="steel", specimen=["", "other_coupon"],
                           parameters_json=[json.dumps({"baseline_loss_factor": 0.0})] * 2)
    notes = specimen_report_table(store_runs, mine, specimen=damped).table.attrs["notes"]
    (note,) = [cli_words(n, "report") for n in notes if "baseline_loss_factor" in n]
    structure = damped.coupon.mass_kg + damped.coupon.fixture_mass_kg
    assert f"with --baseline-loss-factor 0.002 --structure-mass {structure:.4g} " in note
    assert "sidecar's baseline_loss_factor column and structure_mass_g column" in note
    assert note.count("--baseline-loss-factor") == 1


def test_a_test_of_the_runs_particle_count_meets_the_run_whatever_fill_it_states(steel):
    # a specimen stating count_per_cell = 28 (of 46) runs at 60.87 %; its test at 60 % (28
    # spheres, the same simulation) was "out_of_range" beside that run: outside the 0.5-point
    # fill tolerance and no second fill for a pchip model
    from pidcore.compare.align import Aligner

    fill = 100 * 28 / 46
    runs = pd.DataFrame([{**_run("k28", "steel", 1.889, steel), "frequency_hz": 500.0,
                          "fill_percent": fill, "particles_per_cell": 28,
                          "particles_full_cell": 46}])
    aligner = Aligner.from_tables(runs)
    for measured, status in ((60.0, "grid"), (59.8, "grid"), (61.9, "grid"),
                             # 27 and 29 spheres of 46: another bed, not this run's
                             # and one fill gives no pchip model to interpolate
                             (58.0, "no_model"), (62.0, "no_model")):
        out = aligner.align(LoadCase(500.0, 5.0, measured, material="steel"))
        assert out.status == status, measured
        if status == "grid":
            assert out.sdc_dem == 1.889
    # a nearer fill of another count (59.7 % of 46: 27 spheres) is another bed: the 28's run
    # is met first
    beside = pd.concat([runs, pd.DataFrame([{**runs.iloc[0].to_dict(), "case_key": "k27",
                                             "fill_percent": 59.7, "particles_per_cell": 27,
                                             "sdc": 1.7}])], ignore_index=True)
    out = Aligner.from_tables(beside).align(LoadCase(500.0, 5.0, 60.0, material="steel"))
    assert out.status == "grid" and out.sdc_dem == 1.889
    # another frequency is another case, whatever the count
    assert aligner.align(LoadCase(1000.0, 5.0, 60.0, material="steel")).status != "grid"
    tests = pd.DataFrame({
        "frequency_hz": [500.0], "acceleration_g": [5.0], "fill_percent": [60.0],
        "material": ["steel"], "direction": ["z"], "sdc": [1.571], "sdc_stderr": [0.01],
        "source": ["t60.csv"], "specimen": [""]})
    table = specimen_report_table(runs, tests, specimen=steel).table
    assert len(table) == 1  # one row: the run and its test
    row = _measured(table, "t60.csv")
    assert row[ALIGNMENT_COLUMN] == "grid" and row["SDC DEM (ours) [-]"] == 1.889
    # (the runs here record no m_c: the note says so after)
    assert row["note"].startswith("measured at 60 % fill: 28 of 46 particles per cell, as the "
                                  f"DEM runs at {fill:g} %: the same simulation")


def test_tests_near_no_run_sort_by_their_load_case_not_their_last_digits(steel):
    """Two tests at 100 Hz (measured 99.999977 and 99.999986 Hz) of a specimen with runs at
    1000 Hz only were listed 70 % before 30 %: they sorted by those digits first, since only
    values near a DEM run's or the paper's were taken as one frequency."""
    runs = pd.DataFrame([_run("s1", "steel", 1.75, steel)])
    tests = pd.DataFrame({
        "frequency_hz": [99.999977, 99.999986, 1000.0], "acceleration_g": [4.99966, 4.9999, 5.0],
        "fill_percent": [70.0, 30.0, 50.0], "material": ["steel"] * 3, "direction": ["z"] * 3,
        "sdc": [3.6, 2.6, 1.7], "sdc_stderr": [0.1] * 3,
        "source": ["f100_fill70.uff", "f100_fill30.uff", "f1000.uff"], "specimen": [""] * 3})
    table = specimen_report_table(runs, tests, specimen=steel).table
    measured = table[table["source file(s)"] != ""]
    assert list(measured["source file(s)"]) == ["f100_fill30.uff", "f100_fill70.uff",
                                                "f1000.uff"]
    # the measured values themselves are kept: only the order groups them
    assert list(measured["frequency [Hz]"][:2]) == [99.999986, 99.999977]
