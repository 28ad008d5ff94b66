"""Which specimen is the paper's coupon: one rule (:func:`pidcore.specimen.is_paper_coupon`) for
DEM runs, measurements and specimen files, by hash where the content is known, else by name."""

from __future__ import annotations

import dataclasses
import json
import math
import re
from pathlib import Path
from types import SimpleNamespace

import pandas as pd
import pytest

from pidcore.calibrate import MeasuredPoint
from pidcore.calibrate.calibrate import base_specimen
from pidcore.calibrate.data import points_for_paper
from pidcore.cli import main
from pidcore.compare.specimens import runs_for_measurement
from pidcore.report.pipeline import specimen_report_table
from pidcore.specimen import (
    is_paper_coupon,
    load_specimen,
    measured_specimen_name,
    paper_specimen,
)
from pidcore.store import Store

PAPER = paper_specimen("acrylic")
ALUMINIUM = paper_specimen("aluminium")
# the paper's cell with 1/4 in cells instead of 3/16 in: another coupon, same name (without
# the paper's stated face: 441 such cells cover more than its 0.1 m x 0.1 m)
OTHER_CELL = PAPER.with_values({"cell.inscribed_diameter_m": 6.35e-3,
                                "coupon.face_area_m2": None})


def test_the_hash_decides_where_the_content_is_known_else_the_name():
    assert OTHER_CELL.name == "paper_coupon" and not is_paper_coupon(OTHER_CELL.name,
                                                                     OTHER_CELL.hash)
    assert not OTHER_CELL.is_paper()
    # the paper's content under another name is the paper's coupon (same physics)
    assert is_paper_coupon("renamed_copy", PAPER.hash)
    assert is_paper_coupon(ALUMINIUM.name, ALUMINIUM.hash) and ALUMINIUM.is_paper()
    # by name: unnamed (the default), either table material, and what calibrate made of them
    for name in ("", "  ", "paper_coupon", "paper_coupon_aluminium", "paper_coupon_calibrated",
                 "paper_coupon_aluminium_calibrated_calibrated", None, float("nan")):
        assert is_paper_coupon(name), name
    for name in ("steel_6mm", "paper_coupon_steel", "my_paper_coupon", "paper_coupon [45d792]",
                 "paper_coupon_calibrated_x"):
        assert not is_paper_coupon(name), name


def _table3_columns(specimen_name: str) -> tuple[float, float, str]:
    """Table 3's DEM and measured SDC beside an acrylic test at 1000 Hz, 5 g, 50 % naming
    ``specimen_name``, and its note."""
    runs = pd.DataFrame([{"case_key": "p1", "frequency_hz": 1000.0, "acceleration_g": 5.0,
                          "fill_percent": 50.0, "material": "acrylic", "direction": "z",
                          "sdc": 0.5, "sdc_stderr": 0.01, "specimen_name": PAPER.name,
                          "specimen_sha256": PAPER.hash}])
    analyses = pd.DataFrame({
        "frequency_hz": [1000.0], "acceleration_g": [5.0], "fill_percent": [50.0],
        "material": ["acrylic"], "direction": ["z"], "sdc": [3.5], "sdc_stderr": [0.05],
        "source": ["t.h5"], "specimen": [specimen_name]})
    row = specimen_report_table(runs, analyses).table
    row = row[row["source file(s)"] == "t.h5"].iloc[0]
    return row["SDC DEM (paper) [-]"], row["SDC measured (paper) [-]"], str(row["note"])


def test_a_test_named_after_the_coupons_calibrated_file_is_compared_with_table3():
    """Was: calibration counted a test naming paper_coupon_calibrated as the paper's coupon's
    (uncalibrated name) while the report said "not the paper's coupon" and dropped Table 3:
    two rules for one question. The values are paper_table3.csv's at 1000 Hz, 5 g, 50 %."""
    assert _table3_columns("paper_coupon_calibrated")[:2] == (0.5612, 0.63)
    paper_dem, paper_measured, note = _table3_columns("steel_6mm_b")
    assert pd.isna(paper_dem) and pd.isna(paper_measured)
    assert "specimen steel_6mm_b is not the paper's coupon" in note


def test_the_paper_coupon_with_aluminium_is_calibrated_with_its_tests():
    """Was: points_for_paper left out tests naming paper_coupon_aluminium (the name of the
    coupon calibrate chooses for aluminium points), and the library then refused aluminium
    tests naming paper_coupon as "not 'paper_coupon_aluminium', the specimen calibrated"."""
    named = [MeasuredPoint(100, 1, 50, 0.2, material="aluminium", specimen="paper_coupon"),
             MeasuredPoint(200, 1, 50, 0.3, material="aluminium",
                           specimen="paper_coupon_aluminium"),
             MeasuredPoint(300, 1, 50, 0.3, material="aluminium")]
    other = MeasuredPoint(400, 1, 50, 0.2, material="aluminium", specimen="steel_6mm_b")
    assert points_for_paper([*named, other]) == (
        named, "Not used for the paper's coupon: 1 measured load case(s) of specimen "
               "steel_6mm_b.")
    assert base_specimen(named, None) == ALUMINIUM  # accepted: one coupon, either name
    from pidcore.errors import ParameterError

    with pytest.raises(ParameterError, match=r"name specimen 'steel_6mm_b', not "
                                             r"'paper_coupon_aluminium'"):
        base_specimen([*named, other], None)


def test_a_test_naming_the_aluminium_coupon_meets_the_papers_runs():
    """Was: a test naming paper_coupon_aluminium met no run of the paper's coupon with
    aluminium spheres (their runs are labelled paper_coupon) and said no_dem_runs."""
    runs = pd.DataFrame([{"case_key": "a1", "material": "aluminium", "direction": "z",
                          "specimen_name": ALUMINIUM.name, "specimen_sha256": ALUMINIUM.hash},
                         {"case_key": "o1", "material": "aluminium", "direction": "z",
                          "specimen_name": OTHER_CELL.name,
                          "specimen_sha256": OTHER_CELL.hash}])
    met = runs_for_measurement(runs, "paper_coupon_aluminium", "aluminium", "z")
    assert met.runs is not None and met.runs["case_key"].tolist() == ["a1"]
    assert met.specimen == "paper_coupon"


# --- a file named paper_coupon with other content -------------------------------------------

REPO = Path(__file__).resolve().parents[1]
CALIBRATED_PAPER = REPO / "data_samples" / "paper_calibrated_specimen.toml"
OTHER_LABEL = f"paper_coupon [{OTHER_CELL.hash[:6]}]"


@pytest.fixture(scope="module")
def other_cell_tests(tmp_path_factory):
    """A test at 1000 Hz, 5 g, 50 % analysed with a user's ``paper_coupon.toml`` of 1/4 in
    cells (`pidcore analyze --specimen`), saved in a store, and that file."""
    from pidcore.constants import STANDARD_GRAVITY
    from pidcore.io import write_measurement
    from pidcore.records import Channel, Measurement
    from pidcore.signal import synthesize_shaker_record

    where = tmp_path_factory.mktemp("other_cell")
    (where / "mine").mkdir()
    specimen_file = where / "mine" / "paper_coupon.toml"
    specimen_file.write_text(OTHER_CELL.to_toml())
    rate = 51200.0
    rec = synthesize_shaker_record(mass_kg=0.05,
                                   acceleration_amplitude_m_s2=5 * STANDARD_GRAVITY,
                                   frequency_hz=1000.0, sample_rate_hz=rate, n_periods=40,
                                   viscous_damping_n_s_m=5.0)
    test = where / "test_fill50.csv"
    write_measurement(Measurement("m", (Channel("Force", "force", rec.force_n, rate, "N"),
                                        Channel("LDV", "velocity", rec.velocity_m_s, rate,
                                                "m/s"))), test)
    return SimpleNamespace(dir=where, specimen_file=specimen_file, test=test,
                           store=where / "tests.h5")


def _analyze(capsys, tests, specimen_file: Path, store: Path) -> str:
    assert main(["analyze", str(tests.test), "--specimen", str(specimen_file), "--store",
                 str(store)]) == 0
    out = capsys.readouterr().out
    return out


def test_analyze_saves_a_test_of_another_file_named_paper_coupon_under_its_label(
        capsys, other_cell_tests):
    """Was: saved as specimen 'paper_coupon', the paper's coupon by name everywhere after."""
    out = _analyze(capsys, other_cell_tests, other_cell_tests.specimen_file,
                   other_cell_tests.store)
    assert f"specimen '{OTHER_LABEL}' (--specimen)" in out
    assert Store(other_cell_tests.store).list_analyses()["specimen"].tolist() == [OTHER_LABEL]
    assert not is_paper_coupon(OTHER_LABEL)
    # the paper's own file, and the coupon's calibrated file (fitted values, the paper's cell
    # and spheres), keep their names: their tests are the paper's coupon's
    assert measured_specimen_name(PAPER) == "paper_coupon"
    assert measured_specimen_name(load_specimen(CALIBRATED_PAPER)) == "paper_coupon_calibrated"
    # another file calibrated from the other-cell coupon is not the paper's either
    calibrated_other = dataclasses.replace(OTHER_CELL, name="paper_coupon_calibrated")
    assert measured_specimen_name(calibrated_other) == \
        f"paper_coupon_calibrated [{calibrated_other.hash[:6]}]"


@pytest.mark.usefixtures("undrawn_report_figures")
def test_report_of_that_test_sets_no_table3_beside_it(tmp_path, capsys, other_cell_tests):
    """Was: `pidcore report --store` put the paper's Table 3 (DEM 0.5612, measured 0.63 at
    1000 Hz, 5 g, 50 %) beside the test of the other coupon, and `report --specimen FILE`
    said "specimen paper_coupon is not the paper's coupon"."""
    store = tmp_path / "tests.h5"
    _analyze(capsys, other_cell_tests, other_cell_tests.specimen_file, store)
    out = tmp_path / "default"
    assert main(["report", "--store", str(store), "--out", str(out), "--format", "csv"]) == 0
    capsys.readouterr()
    row = pd.read_csv(out / "report.csv", comment="#").iloc[0]
    assert row["specimen"] == OTHER_LABEL
    assert pd.isna(row["SDC DEM (paper) [-]"]) and pd.isna(row["SDC measured (paper) [-]"])
    assert f"specimen {OTHER_LABEL} is not the paper's coupon" in row["note"]
    mine = tmp_path / "mine"
    assert main(["report", "--store", str(store), "--specimen",
                 str(other_cell_tests.specimen_file), "--out", str(mine),
                 "--format", "csv"]) == 0
    said = capsys.readouterr().out
    assert f"note: specimen {OTHER_LABEL} is not the paper's coupon: the paper's Table 3 is " \
           "not compared" in said
    row = pd.read_csv(mine / "report.csv", comment="#").iloc[0]
    assert row["specimen"] == OTHER_LABEL and pd.isna(row["SDC DEM (paper) [-]"])


def test_calibrating_the_papers_coupon_refuses_the_test_of_the_other_file(
        tmp_path, capsys, other_cell_tests):
    """Was: the test was pooled with the paper coupon's (`calibrate --store` without
    --specimen kept every test naming paper_coupon). Two parameters are asked for so that the
    old code stops, before any DEM run, at "1 measured load case(s) cannot determine 3"
    (the two and the model discrepancy)."""
    store = tmp_path / "tests.h5"
    _analyze(capsys, other_cell_tests, other_cell_tests.specimen_file, store)
    before = Store(store).list_analyses()
    code = main(["calibrate", "--store", str(store), "--fit",
                 "fixture_mass_kg,baseline_loss_factor", "--out", str(tmp_path / "cal")])
    err = capsys.readouterr().err
    assert code == 2
    assert err.strip().splitlines() == [
        f"pidcore calibrate: error: --store {store}: no measurement of the paper's coupon or of "
        f"an unnamed specimen; not used for the paper's coupon: 1 measured load case(s) of "
        f"specimen {OTHER_LABEL} (--specimen FILE of theirs)"]
    assert not (tmp_path / "cal").exists()
    pd.testing.assert_frame_equal(Store(store).list_analyses(), before)


def test_the_other_files_tests_and_runs_are_its_own_not_the_papers():
    """Its calibration takes its tests, not the paper coupon's that name paper_coupon; its
    tests meet its runs, not the paper's (both labelled as the pages label them)."""
    from pidcore.calibrate.data import points_for_specimen

    own = MeasuredPoint(100, 1, 50, 0.2, specimen=OTHER_LABEL)
    papers = MeasuredPoint(200, 1, 50, 0.3, specimen="paper_coupon")
    unnamed = MeasuredPoint(300, 1, 50, 0.3)
    assert points_for_specimen([own, papers, unnamed], OTHER_CELL) == (
        [own, unnamed], f"Not used for {OTHER_LABEL} (acrylic particles): 1 measured load "
                        "case(s) of specimen paper_coupon.")
    assert points_for_paper([own, papers, unnamed])[0] == [papers, unnamed]
    from pidcore.errors import ParameterError

    with pytest.raises(ParameterError, match=r"name specimen 'paper_coupon', not "
                                             + re.escape(repr(OTHER_LABEL))):
        base_specimen([own, papers], OTHER_CELL)
    runs = pd.DataFrame([{"case_key": key, "material": "acrylic", "direction": "z",
                          "specimen_name": s.name, "specimen_sha256": s.hash}
                         for key, s in (("p1", PAPER), ("o1", OTHER_CELL))])
    met = runs_for_measurement(runs, OTHER_LABEL, "acrylic", "z")
    assert met.runs["case_key"].tolist() == ["o1"] and met.specimen == OTHER_LABEL
    met = runs_for_measurement(runs, "paper_coupon", "acrylic", "z")
    assert met.runs["case_key"].tolist() == ["p1"] and met.specimen == "paper_coupon"


def _stored_run(key: str, specimen) -> dict:
    """A store listing's row of a DEM run of ``specimen`` (its file's text stored with it, as
    pidcore.dem.persist stores it)."""
    import json

    return {"case_key": key, "material": "acrylic", "direction": "z",
            "specimen_name": specimen.name, "specimen_sha256": specimen.hash,
            "parameters_json": json.dumps({"specimen_text": specimen.text})}


def test_a_test_of_the_papers_coupon_meets_no_runs_of_another_coupons_calibrated_file():
    """Was: `pidcore calibrate --specimen mine/paper_coupon.toml` (1/4 in cells) writes
    paper_coupon_calibrated.toml, and a test of the paper's coupon met that file's DEM runs
    ("the file pidcore calibrate made from it") in a store without runs of the coupon itself.
    The bundled calibration of the paper's coupon (its cell and spheres) is still met."""
    other = dataclasses.replace(OTHER_CELL.with_values({"coupon.fixture_mass_kg": 0.25}),
                                name="paper_coupon_calibrated")
    papers = load_specimen(CALIBRATED_PAPER)
    label = f"paper_coupon_calibrated [{other.hash[:6]}]"
    met = runs_for_measurement(pd.DataFrame([_stored_run("o1", other)]), "paper_coupon",
                               "acrylic", "z")
    assert met.runs is None and met.calibrated_from == ""
    assert met.note == ("no DEM runs of specimen paper_coupon at acrylic, z; DEM runs of other "
                        f"specimens not compared: {label} (1 run(s))")
    both = pd.DataFrame([_stored_run("o1", other), _stored_run("c1", papers)])
    met = runs_for_measurement(both, "paper_coupon", "acrylic", "z")
    assert met.runs["case_key"].tolist() == ["c1"] and met.calibrated_from == "paper_coupon"
    # a run that stored no specimen text is taken as its name says (as before)
    bare = pd.DataFrame([{k: v for k, v in _stored_run("o1", other).items()
                          if k != "parameters_json"}])
    assert runs_for_measurement(bare, "paper_coupon", "acrylic", "z").runs is not None


def test_a_test_of_the_papers_coupon_meets_no_runs_of_another_file_of_its_name():
    """Was: with no run of the paper's coupon at its material and direction (`report
    --specimen mine/paper_coupon.toml`, the app's Compare on a store of such runs), a test
    naming paper_coupon met the runs of the other file named paper_coupon (1/4 in cells)."""
    runs = pd.DataFrame([_stored_run("o1", OTHER_CELL)])
    for named in ("paper_coupon", "paper_coupon_aluminium"):
        met = runs_for_measurement(runs, named, "acrylic", "z")
        assert met.runs is None, named
        assert met.note == (f"no DEM runs of specimen {named} at acrylic, z; DEM runs of other "
                            f"specimens not compared: {OTHER_LABEL} (1 run(s))")
    # its own test meets it
    assert runs_for_measurement(runs, OTHER_LABEL, "acrylic", "z").runs is not None
    # a calibration's design point (the coupon with another rolling friction) still models
    # the coupon: met, under its hash (test_app_logic pins it for runs without stored text)
    design = PAPER.with_values({"pairs.particle_wall.rolling_friction": 0.05})
    met = runs_for_measurement(pd.DataFrame([_stored_run("d1", design)]), "paper_coupon",
                               "acrylic", "z")
    assert met.runs["case_key"].tolist() == ["d1"]
    assert met.specimen == f"paper_coupon [{design.hash[:6]}]"


def test_a_calibration_of_another_file_named_paper_coupon_speaks_not_for_the_coupons_tests(
        tmp_path):
    """Was: the app's Compare showed the band of a calibration of mine/paper_coupon.toml (1/4
    in cells; its calibrated file is paper_coupon_calibrated too) beside a test of the
    paper's coupon, by name. The coupon's own calibration speaks for a test naming either
    table material's coupon (is_paper_coupon; the material is lookup's)."""
    import shutil

    from pidcore.calibrate.prediction import load_calibration

    bundled = REPO / "data_samples" / "paper_calibration" / "calibration.json"
    shutil.copy(bundled, tmp_path / "calibration.json")
    other = dataclasses.replace(OTHER_CELL, name="paper_coupon_calibrated")
    (tmp_path / "calibrated_specimen.toml").write_text(other.to_toml())
    cal = load_calibration(tmp_path / "calibration.json")
    assert not cal.speaks_for("paper_coupon") and not cal.speaks_for("paper_coupon_aluminium")
    assert cal.speaks_for("")  # an unnamed test: unknown, as before
    shutil.copy(CALIBRATED_PAPER, tmp_path / "calibrated_specimen.toml")
    cal = load_calibration(tmp_path / "calibration.json")
    assert cal.speaks_for("paper_coupon") and cal.speaks_for("paper_coupon_aluminium")
    assert not cal.speaks_for(OTHER_LABEL) and not cal.speaks_for("steel_6mm")


# --- a calibrated file records the file it was made from ([provenance]) ---------------------

# the paper's cell and spheres on a heavier coupon: a user's own paper_coupon.toml that models
# the coupon's cells (so neither the name nor the cell tells its calibrated file apart)
HEAVIER = PAPER.with_values({"coupon.mass_kg": 0.03})
HEAVIER_LABEL = f"paper_coupon [{HEAVIER.hash[:6]}]"


def _write_test(path: Path, frequency_hz: float, acceleration_g: float) -> Path:
    """A synthetic shaker record (force and velocity of a 50 g mass with 5 N s/m of viscous
    damping), as LMS Testlab exports it."""
    from pidcore.constants import STANDARD_GRAVITY
    from pidcore.io import write_measurement
    from pidcore.records import Channel, Measurement
    from pidcore.signal import synthesize_shaker_record

    rate = 51200.0
    rec = synthesize_shaker_record(mass_kg=0.05,
                                   acceleration_amplitude_m_s2=acceleration_g * STANDARD_GRAVITY,
                                   frequency_hz=frequency_hz, sample_rate_hz=rate, n_periods=40,
                                   viscous_damping_n_s_m=5.0)
    write_measurement(Measurement("m", (Channel("Force", "force", rec.force_n, rate, "N"),
                                        Channel("LDV", "velocity", rec.velocity_m_s, rate,
                                                "m/s"))), path)
    return path


@pytest.mark.usefixtures("undrawn_report_figures")
def test_a_calibration_of_a_users_paper_coupon_file_meets_its_tests_not_the_coupons(
        tmp_path, capsys):
    """Was: `calibrate --specimen mine/paper_coupon.toml` wrote paper_coupon_calibrated, whose
    calibration and runs were taken for the paper coupon's (its cell and spheres) and never met
    the file's own tests, saved as "paper_coupon [hash]": `report --specimen` of the
    calibrated file showed them with no calibrated band. Now the file records its source
    ([provenance]) and is named as that source's tests are."""
    from pidcore.calibrate.prediction import load_calibration
    from tests.test_calibrate_cli import TINY

    (tmp_path / "mine").mkdir()
    mine = tmp_path / "mine" / "paper_coupon.toml"
    mine.write_text(HEAVIER.to_toml())
    store = tmp_path / "tests.h5"
    # the load cases of test_calibrate_cli's tiny calibrations (one parameter and a set model
    # discrepancy need three)
    for i, (f, a) in enumerate(((500.0, 5.0), (1000.0, 5.0), (500.0, 1.0))):
        test = _write_test(tmp_path / f"t{i}_fill50.csv", f, a)
        assert main(["analyze", str(test), "--specimen", str(mine), "--store", str(store)]) == 0
    assert set(Store(store).list_analyses()["specimen"]) == {HEAVIER_LABEL}
    out, dem = tmp_path / "cal", tmp_path / "dem.h5"
    assert main(["calibrate", "--store", str(store), "--specimen", str(mine), "--fit",
                 "fixture_mass_kg", "--discrepancy", "0.2", "--dem-store", str(dem),
                 "--out", str(out), *TINY]) == 0
    cal = load_calibration(out)
    # a DEM run of the calibrated file (`dem run --specimen`), in a store of its own
    runs_store = tmp_path / "calibrated_runs.h5"
    assert main(["dem", "run", "--specimen", str(out / "calibrated_specimen.toml"),
                 "--frequency", "1000", "--acceleration", "5", "--fill", "50", "--cells", "1",
                 "--cycles", "2", "--no-progress", "--store", str(runs_store)]) == 0
    capsys.readouterr()
    rep = tmp_path / "rep"
    assert main(["report", "--store", str(store), "--specimen",
                 str(out / "calibrated_specimen.toml"), "--calibration", str(out),
                 "--dem-store", str(runs_store), "--out", str(rep), "--format", "csv"]) == 0
    said = capsys.readouterr().out
    assert f"note: specimen {HEAVIER_LABEL} is not the paper's coupon: the paper's Table 3 is " \
           "not compared" in said
    rows = pd.read_csv(rep / "report.csv", comment="#")
    assert len(rows) == 3 and set(rows["specimen"]) == {HEAVIER_LABEL}
    assert rows["SDC DEM (paper) [-]"].isna().all()
    assert rows["SDC measured (paper) [-]"].isna().all()
    # each test beside the calibrated band of its own load case (the calibration's in-sample
    # prediction there: calibration.json, read back independently of the report)
    from pidcore.dem.simulate import LoadCase
    from pidcore.report.table import (
        CALIBRATED_COLUMN,
        CALIBRATED_HIGH_COLUMN,
        CALIBRATED_LOW_COLUMN,
    )

    for _, row in rows.iterrows():
        hit = cal.lookup(LoadCase(row["frequency [Hz]"], row["acceleration [g]"],
                                  row["packing ratio [%]"], "acrylic"))
        assert hit is not None
        # the CSV's text holds the value to its last digits: 1e-6 is far below any SDC's
        # sampling error and far above the text's rounding
        assert row[CALIBRATED_COLUMN] == pytest.approx(hit.sdc, rel=1e-6)
        assert row[CALIBRATED_LOW_COLUMN] < row[CALIBRATED_COLUMN] < row[CALIBRATED_HIGH_COLUMN]

    # the test at 1000 Hz meets that run (the old code: "no DEM runs of paper_coupon [...]")
    ran = rows[rows["frequency [Hz]"] == 1000.0].iloc[0]
    assert math.isfinite(ran["SDC DEM (ours) [-]"]), ran["note"]
    assert "no DEM runs" not in str(ran["note"])

    # a test of the paper's coupon is never given that calibration's band (the old code gave
    # it: the calibrated file has the coupon's cell and spheres and its name)
    paper_store, paper_rep = tmp_path / "paper_tests.h5", tmp_path / "paper_rep"
    assert main(["analyze", str(tmp_path / "t1_fill50.csv"), "--store", str(paper_store)]) == 0
    assert main(["report", "--store", str(paper_store), "--calibration", str(out),
                 "--out", str(paper_rep), "--format", "csv"]) == 0
    capsys.readouterr()
    (paper_row,) = pd.read_csv(paper_rep / "report.csv", comment="#").to_dict("records")
    assert math.isnan(paper_row[CALIBRATED_COLUMN])
    assert (f"not predicted by the calibration calibration.json: it calibrates specimen "
            f"{HEAVIER_LABEL}, not paper_coupon") in paper_row["note"]

    from pidcore.specimen import ProvenanceSpec

    calibrated = load_specimen(out / "calibrated_specimen.toml")
    assert calibrated.name == "paper_coupon_calibrated"
    assert calibrated.provenance == ProvenanceSpec("paper_coupon", HEAVIER.hash)
    assert measured_specimen_name(calibrated) == HEAVIER_LABEL
    # the table is part of the text it is read back from, and of the hash
    assert load_specimen(out / "calibrated_specimen.toml").to_toml() == calibrated.to_toml()
    assert dataclasses.replace(calibrated, provenance=None).hash != calibrated.hash
    assert cal.speaks_for(HEAVIER_LABEL)
    assert not cal.speaks_for("paper_coupon") and not cal.speaks_for("paper_coupon_calibrated")
    assert cal.other_specimen_reason(PAPER) == \
        f"it calibrates specimen {HEAVIER_LABEL}, not paper_coupon"

    # calibrated again, it takes the file's tests and leaves the paper coupon's out
    from pidcore.calibrate.data import points_for_specimen

    own, papers = (MeasuredPoint(100, 1, 50, 0.2, specimen=HEAVIER_LABEL),
                   MeasuredPoint(200, 1, 50, 0.3, specimen="paper_coupon"))
    assert points_for_specimen([own, papers], calibrated)[0] == [own]

    # the runs of that calibrated file meet its tests, never the paper coupon's (whose cell
    # and spheres it has: the old code met them as the coupon's calibrated file's)
    runs = pd.DataFrame([_stored_run("c1", calibrated)])
    met = runs_for_measurement(runs, HEAVIER_LABEL, "acrylic", "z")
    assert met.runs["case_key"].tolist() == ["c1"] and met.calibrated_from == HEAVIER_LABEL
    for named in ("paper_coupon", "paper_coupon_calibrated"):
        assert runs_for_measurement(runs, named, "acrylic", "z").runs is None, named


def test_a_calibrated_file_of_the_papers_coupon_with_its_provenance_reads_as_without():
    """The paper coupon's calibrated file written now ([provenance]: the paper's hash) is the
    coupon's, as the bundled one written before the table is: same name for its tests, same
    runs met, same calibration spoken for."""
    from pidcore.specimen import ProvenanceSpec, calibrated_provenance

    bundled = load_specimen(CALIBRATED_PAPER)  # regenerated with the table
    assert bundled.provenance == ProvenanceSpec("paper_coupon", PAPER.hash)
    # a file written before the table: the bundled one without it
    text = Path(CALIBRATED_PAPER).read_text(encoding="utf-8")
    old = load_specimen_text(text[:text.index("\n[provenance]\n")] + "\n")
    assert old.provenance is None and calibrated_provenance(old) is None  # source unknown
    assert calibrated_provenance(PAPER) == ProvenanceSpec("paper_coupon", PAPER.hash)
    new = dataclasses.replace(old, provenance=calibrated_provenance(PAPER))
    assert new.to_toml() == bundled.to_toml()
    assert "\n[provenance]\ncalibrated_from_name = \"paper_coupon\"\n" \
           f"calibrated_from_sha256 = \"{PAPER.hash}\"\n" in new.to_toml()
    assert load_specimen_text(new.to_toml()) == new  # round trip, provenance included
    assert measured_specimen_name(new) == measured_specimen_name(old) == \
        "paper_coupon_calibrated"
    # calibrated again: the tested file stays the one recorded, not the calibrated file
    assert calibrated_provenance(new) == new.provenance
    for test in ("paper_coupon", "paper_coupon_calibrated", OTHER_LABEL):
        met_new = runs_for_measurement(pd.DataFrame([_stored_run("c1", new)]), test,
                                       "acrylic", "z")
        met_old = runs_for_measurement(pd.DataFrame([_stored_run("c1", old)]), test,
                                       "acrylic", "z")
        assert (met_new.runs is None) == (met_old.runs is None), test
        assert met_new.calibrated_from == met_old.calibrated_from, test
    assert runs_for_measurement(pd.DataFrame([_stored_run("c1", new)]), "paper_coupon",
                                "acrylic", "z").calibrated_from == "paper_coupon"


def load_specimen_text(text: str):
    from pidcore.specimen import Specimen

    return Specimen.from_text(text, source="x.toml")


@pytest.mark.parametrize("table, said", [
    ('calibrated_from_name = "paper_coupon"\ncalibrated_from_sha256 = "45d792"',
     "x.toml: [provenance] calibrated_from_sha256: expected the sha256 of the specimen it "
     "was calibrated from (64 lowercase hexadecimal digits), got '45d792'"),
    ('calibrated_from_name = "paper_coupon"',
     "x.toml: [provenance] calibrated_from_sha256: missing key; expected text"),
    (f'calibrated_from_name = ""\ncalibrated_from_sha256 = "{"0" * 64}"',
     "x.toml: [provenance] calibrated_from_name: expected a non-empty name, got ''"),
])
def test_a_bad_provenance_table_is_one_line_naming_its_key(table, said):
    from pidcore.errors import ParameterError

    with pytest.raises(ParameterError) as caught:
        load_specimen_text(PAPER.to_toml() + f"\n[provenance]\n{table}\n")
    assert str(caught.value) == said


def test_specimen_check_says_which_file_a_calibrated_one_was_made_from(capsys):
    # the [provenance] table decides which tests a calibrated file models, but `specimen
    # check` showed nothing of it
    import json

    assert main(["specimen", "check", str(CALIBRATED_PAPER)]) == 0
    out = capsys.readouterr().out
    assert f"calibrated from paper_coupon [{PAPER.hash[:6]}]: the tests it models" in out
    assert main(["specimen", "check", str(CALIBRATED_PAPER), "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert (facts["calibrated_from_name"], facts["calibrated_from_sha256"]) == \
        ("paper_coupon", PAPER.hash)
    # a file without the table (the paper's own coupon) says nothing of it
    bundled = REPO / "pidcore" / "data" / "specimens" / "paper_coupon.toml"
    assert main(["specimen", "check", str(bundled)]) == 0
    assert "calibrated from" not in capsys.readouterr().out


# --- Table 3 for a calibrated file of the coupon: one rule for a report of the file and a row

def _table3_cells(csv: Path) -> tuple[float, float, str]:
    row = pd.read_csv(csv, comment="#").iloc[0]
    return row["SDC DEM (paper) [-]"], row["SDC measured (paper) [-]"], str(row["note"])


@pytest.mark.usefixtures("undrawn_report_figures")
@pytest.mark.parametrize("fitted, tabulated", [
    ({}, True),  # the bundled calibration: contact, fixture and baseline fitted
    ({"particles.density_kg_m3": 1300.0}, False),  # another sphere mass: not the paper's
])
def test_a_report_of_a_calibrated_file_and_a_row_of_its_tests_agree_on_table3(
        tmp_path, capsys, other_cell_tests, fitted, tabulated):
    """Was: `report --specimen paper_calibrated_specimen.toml` dropped Table 3 (the file's
    hash is not the paper's) while `report --store` set it beside the same tests, saved as
    paper_coupon_calibrated (by name). Table 3 holds at 1000 Hz, 5 g, 50 %: DEM 0.5612,
    measured 0.63 (the paper's)."""
    calibrated = load_specimen(CALIBRATED_PAPER).with_values(fitted) if fitted else \
        load_specimen(CALIBRATED_PAPER)
    specimen_file = tmp_path / "calibrated.toml"
    specimen_file.write_text(calibrated.to_toml())
    store = tmp_path / "tests.h5"
    _analyze(capsys, other_cell_tests, specimen_file, store)
    by_row, by_file = tmp_path / "by_row", tmp_path / "by_file"
    assert main(["report", "--store", str(store), "--out", str(by_row),
                 "--format", "csv"]) == 0
    assert main(["report", "--store", str(store), "--specimen", str(specimen_file),
                 "--out", str(by_file), "--format", "csv"]) == 0
    said = capsys.readouterr().out
    row_dem, row_measured, row_note = _table3_cells(by_row / "report.csv")
    file_dem, file_measured, file_note = _table3_cells(by_file / "report.csv")
    name = measured_specimen_name(calibrated)
    if tabulated:
        assert name == "paper_coupon_calibrated"
        assert (row_dem, row_measured) == (file_dem, file_measured) == (0.5612, 0.63)
        assert "not the paper's coupon" not in said + row_note + file_note
    else:
        assert name == f"paper_coupon_calibrated [{calibrated.hash[:6]}]"
        assert all(math.isnan(v) for v in (row_dem, row_measured, file_dem, file_measured))
        assert f"specimen {name} is not the paper's coupon" in row_note
        assert f"note: specimen {name} is not the paper's coupon" in said


BUNDLED = Path(__file__).resolve().parents[1] / "pidcore" / "data" / "specimens"


def test_the_bundled_coupon_is_named_by_its_name_where_no_file_of_that_name_exists(
        tmp_path, monkeypatch, capsys):
    # `pidcore specimen check paper_coupon` was "cannot read specimen file (No such file or
    # directory)": after a wheel install the file lies in site-packages alone
    monkeypatch.chdir(tmp_path)
    named = load_specimen("paper_coupon")
    # the bundled file itself: the same canonical text (its sha256), face area included
    assert named == PAPER and named.hash == PAPER.hash and named.is_paper()
    assert named.source == str(BUNDLED / "paper_coupon.toml")
    assert named.read_note == ("specimen 'paper_coupon': no file of that name in the current "
                               "folder; the bundled specimen paper_coupon is taken "
                               f"({BUNDLED / 'paper_coupon.toml'})")
    assert main(["specimen", "check", "paper_coupon"]) == 0
    said = capsys.readouterr()
    assert said.err == f"pidcore specimen check: note: {named.read_note}\n"
    assert said.out.startswith(f"specimen        paper_coupon [{PAPER.hash[:6]}] "
                               f"({BUNDLED / 'paper_coupon.toml'}): OK, the paper's coupon")


def test_a_file_of_a_bundled_specimens_name_is_read_as_given(tmp_path, monkeypatch):
    # a path given always wins: a file named paper_coupon in the current folder is that file
    monkeypatch.chdir(tmp_path)
    steel = REPO / "data_samples" / "specimens" / "steel_6mm.toml"
    Path("paper_coupon").write_bytes(steel.read_bytes())
    given = load_specimen("paper_coupon")
    assert given.hash == load_specimen(steel).hash != PAPER.hash
    assert given.source == "paper_coupon" and given.read_note == ""


def test_a_missing_specimen_file_is_refused_naming_the_bundled_specimens_and_where(
        tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    for typed in ("paper_coupn", "specimens/paper_coupon", "paper_coupon.toml"):
        assert main(["specimen", "check", typed]) == 2
        assert capsys.readouterr().err == (
            f"pidcore specimen check: error: {typed}: cannot read specimen file (No such file "
            f"or directory); a bundled specimen is taken by its name alone (paper_coupon, in "
            f"{BUNDLED})\n")


def test_dem_run_by_the_bundled_name_is_the_run_of_the_bundled_file(tmp_path, monkeypatch,
                                                                     capsys):
    # the one loader every --specimen goes through: named, the run is the file's, reused
    monkeypatch.chdir(tmp_path)
    common = ["dem", "run", "--frequency", "1000", "--acceleration", "5", "--cells", "1",
              "--fill", "50", "--cycles", "4", "--no-progress", "--json", "--store", "s.h5"]
    assert main([*common, "--specimen", str(BUNDLED / "paper_coupon.toml")]) == 0
    by_path = json.loads(capsys.readouterr().out)
    assert main([*common, "--specimen", "paper_coupon"]) == 0
    said = capsys.readouterr()
    by_name = json.loads(said.out)
    assert by_name["reused_from_store"] is True and by_path["reused_from_store"] is False
    assert by_name["store_key"] == by_path["store_key"] and by_name["sdc"] == by_path["sdc"]
    assert "the bundled specimen paper_coupon is taken" in said.err
