"""``pidcore report --calibration``: the calibrated DEM's Eq. 11 SDC and 95 % band per row.

The calibration files here are written by hand (three load cases, known bands), so every
expected value is read off the file, not recomputed.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pidcore.calibrate.prediction import Z95, judge_measurement, load_calibration
from pidcore.cli import main
from pidcore.compare import Tolerances
from pidcore.errors import ParameterError
from pidcore.loadcase import LoadCase
from pidcore.report.table import (
    CALIBRATED_COLUMN,
    CALIBRATED_HIGH_COLUMN,
    CALIBRATED_INSIDE_COLUMN,
    CALIBRATED_LOW_COLUMN,
    NOT_COMPARED,
    add_calibration_columns,
)

ROOT = Path(__file__).resolve().parents[1]
BUNDLED = ROOT / "data_samples" / "paper_calibration" / "calibration.json"


def _prediction(f, a, fill, pred, low, high, material="acrylic"):
    return {"frequency_hz": f, "acceleration_g": a, "fill_percent": fill, "material": material,
            "measured": pred, "predicted": pred, "low95": low, "high95": high}


def _write(path, predictions, **extra):
    doc = {"parameters": {"rolling_friction": {"median": 0.05, "low95": 0.01, "high95": 0.1}},
           "predictions": predictions, **extra}
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


@pytest.fixture
def calibration_file(tmp_path):
    return _write(tmp_path / "calibration.json", [
        _prediction(50, 5, 50, 0.24, 0.05, 0.43),
        _prediction(500, 5, 50, 0.49, 0.12, 0.88),
        _prediction(100, 1, 50, 0.09, 0.02, 0.20, material="steel"),
    ])


def test_lookup_within_tolerances_and_material(calibration_file):
    cal = load_calibration(calibration_file)
    # 1 % in frequency is COMPARE_FREQUENCY_RTOL: 50.4 Hz is the 50 Hz case, 51 Hz is not
    hit = cal.lookup(LoadCase(50.4, 5.0, 50.0))
    assert hit is not None and hit.sdc == 0.24 and (hit.low95, hit.high95) == (0.05, 0.43)
    assert cal.lookup(LoadCase(51.0, 5.0, 50.0)) is None
    assert cal.lookup(LoadCase(500.0, 5.0, 75.0)) is None          # other fill
    assert cal.lookup(LoadCase(100.0, 1.0, 50.0)) is None          # acrylic vs steel
    assert cal.lookup(LoadCase(100.0, 1.0, 50.0, "steel")).sdc == 0.09
    # a wider tolerance admits 51 Hz
    assert cal.lookup(LoadCase(51.0, 5.0, 50.0),
                      tolerances=Tolerances(frequency_rtol=0.05)).sdc == 0.24


def test_band_membership_bounds_included(calibration_file):
    hit = load_calibration(calibration_file).lookup(LoadCase(50, 5, 50))
    assert hit.contains(0.05) and hit.contains(0.43) and hit.contains(0.2)
    assert not hit.contains(0.0499) and not hit.contains(0.431) and not hit.contains(math.nan)


@pytest.mark.parametrize("content, words", [
    (None, "no such calibration file"),
    ("not json {", "not JSON"),
    ('{"runs": []}', "non-empty 'predictions'"),
    ('{"parameters": {}, "predictions": [{"frequency_hz": 50}]}', "must have"),
    (json.dumps({"parameters": {}, "predictions": [_prediction(50, 5, 50, 0.5, 0.6, 0.9)]}),
     "low95 <= predicted <= high95"),
    (json.dumps({"parameters": {}, "predictions": [_prediction(50, 5, 50, None, 0.1, 0.9)]}),
     "finite number"),
])
def test_bad_calibration_file_is_refused(tmp_path, content, words):
    path = tmp_path / "calibration.json"
    if content is not None:
        path.write_text(content, encoding="utf-8")
    with pytest.raises(ParameterError, match=words) as err:
        load_calibration(path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


def _table():
    return pd.DataFrame({
        "frequency [Hz]": [50.0, 500.0, 1000.0, 50.0],
        "acceleration [g]": [5.0, 5.0, 5.0, 5.0],
        "packing ratio [%]": [50.0, 50.0, 50.0, 75.0],
        "material": ["acrylic"] * 4,
        "SDC measured (Eq. 11) [-]": [0.30, 1.2, 0.5, math.nan],
        "SDC measured (Eq. 11) stderr [-]": [0.01] * 4,
        "note": ["", "kept note", "", ""],
    })


def test_a_row_driven_along_x_is_not_given_the_z_calibrations_prediction(calibration_file):
    # the x row of a load case the calibration predicts (its runs drive along z) showed the
    # z prediction and an in-band verdict
    table = _table().iloc[:1]
    table = pd.concat([table.assign(direction="z"), table.assign(direction="x")],
                      ignore_index=True)
    out = add_calibration_columns(table, load_calibration(calibration_file))
    assert out[CALIBRATED_COLUMN].iloc[0] == 0.24 and math.isnan(out[CALIBRATED_COLUMN].iloc[1])
    assert out[CALIBRATED_INSIDE_COLUMN].tolist() == ["yes", NOT_COMPARED]
    assert "driven along x, where the calibration's DEM runs drive along z" in \
        out["note"].iloc[1]


def test_calibration_columns_per_row(calibration_file):
    out = add_calibration_columns(_table(), load_calibration(calibration_file))
    assert out[CALIBRATED_COLUMN].iloc[0] == 0.24
    assert (out[CALIBRATED_LOW_COLUMN].iloc[1], out[CALIBRATED_HIGH_COLUMN].iloc[1]) == (0.12,
                                                                                          0.88)
    # 0.30 inside 0.05..0.43; 1.2 above 0.88; 1000 Hz not predicted; 75 % not predicted
    assert out[CALIBRATED_INSIDE_COLUMN].tolist() == ["yes", "no", NOT_COMPARED, NOT_COMPARED]
    assert math.isnan(out[CALIBRATED_COLUMN].iloc[2]) and math.isnan(out[CALIBRATED_COLUMN].iloc[3])
    assert "not predicted by the calibration" in out["note"].iloc[2]
    assert out["note"].iloc[1] == "kept note"
    # the band sits right after the measured Eq. 11 SDC
    cols = list(out.columns)
    assert cols[cols.index("SDC measured (Eq. 11) [-]") + 1] == CALIBRATED_COLUMN


@pytest.mark.usefixtures("undrawn_report_figures")
def test_cli_report_csv_reads_back_with_band(tmp_path, calibration_file, capsys, monkeypatch):
    import io

    from pidcore.report.downloads import store_report_table

    monkeypatch.chdir(tmp_path)  # no default store here: only the DEM store is reported
    dem = ROOT / "data_samples" / "dem_table3.h5"
    out = tmp_path / "report"
    rc = main(["report", "--dem-store", str(dem), "--calibration", str(calibration_file),
               "--format", "csv", "--out", str(out)])
    assert rc == 0
    table = pd.read_csv(out / "report.csv")
    # the app's Report tab shows and writes the same table (report_files writes this one)
    app = store_report_table(tmp_path / "none.h5", dem,
                             calibration=load_calibration(calibration_file))
    csv = io.StringIO(app.to_csv(index=False))
    pd.testing.assert_frame_equal(pd.read_csv(csv), table)
    assert any("predicts 2 of" in note for note in app.attrs["notes"])
    for col in (CALIBRATED_COLUMN, CALIBRATED_LOW_COLUMN, CALIBRATED_HIGH_COLUMN,
                CALIBRATED_INSIDE_COLUMN):
        assert col in table.columns
    # every verdict reads back as text (no NaN from 'n/a'); no measurements: none compared
    assert set(table[CALIBRATED_INSIDE_COLUMN]) == {NOT_COMPARED}
    predicted = table[table[CALIBRATED_COLUMN].notna()]
    assert len(predicted) == 2  # the two acrylic cases of the file
    assert (predicted[CALIBRATED_LOW_COLUMN] <= predicted[CALIBRATED_COLUMN]).all()
    assert table.loc[table[CALIBRATED_COLUMN].isna(), "note"].str.contains(
        "not predicted by the calibration").all()


def test_cli_refuses_foreign_file_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "report"
    foreign = _write(tmp_path / "x.json", [])
    rc = main(["report", "--dem-store", str(ROOT / "data_samples" / "dem_table3.h5"),
               "--calibration", str(foreign), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and not out.exists()
    assert len(err.splitlines()) == 1 and "x.json" in err


def test_bundled_calibration_predicts_the_paper_points():
    cal = load_calibration(BUNDLED)
    measured = pd.read_csv(ROOT / "data_samples" / "paper_measured_sdc.csv", comment="#")
    assert len(cal.predictions) == len(measured) == 12
    for _, row in measured.iterrows():
        hit = cal.lookup(LoadCase(row.frequency_hz, row.acceleration_g, row.fill_percent,
                                  row.material))
        assert hit is not None and hit.measured == pytest.approx(row.sdc)
    assert cal.specimen_path is not None and cal.specimen_path.is_file()


def test_not_predicted_rows_say_why(calibration_file):
    """The note said only "not predicted by the calibration X" (README: "and why")."""
    table = pd.DataFrame({
        "frequency [Hz]": [1000.0, 50.0, 100.0, 100.0],
        "acceleration [g]": [5.0, 5.0, 5.0, 1.0],
        "packing ratio [%]": [50.0, 75.0, 50.0, 50.0],
        "material": ["acrylic", "acrylic", "acrylic", "aluminium"],
        "SDC measured (Eq. 11) [-]": [math.nan] * 4,
        "SDC measured (Eq. 11) stderr [-]": [math.nan] * 4,
        "note": [""] * 4})
    notes = add_calibration_columns(table, load_calibration(calibration_file))["note"].tolist()
    head = "not predicted by the calibration calibration.json: "
    # acrylic predictions at 50 and 500 Hz, 5 g, 50 % (1 % / 5 % / 0.5 points tolerances)
    assert notes == [
        head + "outside its calibrated range (frequency 1000 Hz not in its 50-500 Hz)",
        head + "outside its calibrated range (fill 75 % not in its 50 %)",
        head + "not one of its 2 calibrated acrylic load cases (it predicts only where it was "
               "fitted)",
        head + "it calibrates acrylic and steel particles, not aluminium"]


def test_not_predicted_rows_name_another_specimen(calibration_file):
    from pidcore.specimen import paper_specimen

    paper = paper_specimen()
    calibrated = paper.with_values({"coupon.fixture_mass_kg": 0.25})
    (calibration_file.parent / "calibrated_specimen.toml").write_text(
        calibrated.to_toml().replace('name = "paper_coupon"', 'name = "paper_coupon_calibrated"'))
    cal = load_calibration(calibration_file)
    assert cal.calibrated_specimen().name == "paper_coupon_calibrated"
    table = _table().iloc[[2]]  # 1000 Hz: outside the range too, the specimen comes first
    own = paper.with_values({"cell.inscribed_diameter_m": 6.35e-3,
                             "coupon.face_area_m2": None})
    renamed = own.to_toml().replace('name = "paper_coupon"', 'name = "hc635"')
    from pidcore.specimen import Specimen

    def note(specimen):
        return add_calibration_columns(table, cal, specimen=specimen)["note"].iloc[0]

    assert note(Specimen.from_text(renamed)).endswith(
        ": it calibrates specimen paper_coupon, not hc635")
    assert note(own).endswith(": it calibrates another specimen named paper_coupon (its cell "
                              "differ)")
    # its own specimen, before or after calibration: the other reasons only
    as_file = Specimen.from_text(cal.specimen_path.read_text())  # README: use it as --specimen
    for same in (paper, calibrated, as_file):
        assert note(same).endswith(": outside its calibrated range (frequency 1000 Hz not in "
                                   "its 50-500 Hz)")


def test_a_calibration_of_another_specimen_predicts_no_row_even_at_its_load_cases(
        calibration_file):
    # lookup matches load cases only: the specimen must be checked first, or a calibration of
    # another coupon would put its band (and a yes/no) on a row at one of its load cases
    from pidcore.specimen import paper_specimen

    own = paper_specimen().with_values({"cell.inscribed_diameter_m": 6.35e-3,
                                        "coupon.face_area_m2": None})
    (calibration_file.parent / "calibrated_specimen.toml").write_text(
        own.to_toml().replace('name = "paper_coupon"', 'name = "hc635_calibrated"'))
    cal = load_calibration(calibration_file)
    table = _table().iloc[[0]]  # 50 Hz, 5 g, 50 % acrylic: a load case it predicts
    assert cal.lookup(LoadCase(50.0, 5.0, 50.0, "acrylic")) is not None
    for kwargs in ({"specimen": paper_specimen()}, {"paper": True}):
        out = add_calibration_columns(table, cal, **kwargs)
        assert math.isnan(out[CALIBRATED_COLUMN].iloc[0])
        assert out["note"].iloc[0].endswith(": it calibrates specimen hc635, not paper_coupon")
        assert "predicts 0 of 1 row(s)" in out.attrs["notes"][-1]
    # the default report (paper=True) checks each row against the paper's coupon with its own
    # particles: an aluminium row is the aluminium coupon, not the acrylic one
    (calibration_file.parent / "calibrated_specimen.toml").write_text(
        paper_specimen().to_toml().replace('name = "paper_coupon"',
                                           'name = "paper_coupon_calibrated"'))
    cal = load_calibration(calibration_file)
    rows = _table().iloc[[0, 0]].assign(material=["acrylic", "aluminium"])
    out = add_calibration_columns(rows, cal, paper=True)
    assert out[CALIBRATED_COLUMN].iloc[0] == 0.24
    assert out["note"].iloc[1].endswith(
        ": it calibrates specimen paper_coupon, not paper_coupon_aluminium")


def test_the_calibration_folder_is_accepted_and_another_folder_is_named(tmp_path):
    # `--calibration DIR` said "no such calibration file" for an existing folder
    from pidcore.errors import ParameterError

    folder = BUNDLED.parent
    assert load_calibration(folder).path == BUNDLED
    with pytest.raises(ParameterError, match="a folder without calibration.json"):
        load_calibration(tmp_path)


def _before_specimen_block() -> bytes:
    """The bundled calibration.json as pidcore wrote it before it named the specimen file it
    calibrated (no "specimen" block)."""
    doc = json.loads(BUNDLED.read_text(encoding="utf-8"))
    del doc["specimen"]
    return json.dumps(doc, indent=2).encode()


def test_a_calibration_speaks_for_its_own_specimen_or_an_unnamed_one(tmp_path):
    # the app's Compare asks this by name (its measurements carry a specimen label only)
    import shutil

    from pidcore.calibrate.prediction import calibration_from_json, load_calibration

    # as calibration.json was written before it named its specimen
    (tmp_path / "calibration.json").write_bytes(_before_specimen_block())
    bare = load_calibration(tmp_path / "calibration.json")  # no specimen file: unknown
    assert bare.speaks_for("my_panel")
    shutil.copy(ROOT / "data_samples" / "paper_calibrated_specimen.toml",
                tmp_path / "calibrated_specimen.toml")
    paper = load_calibration(tmp_path / "calibration.json")
    assert paper.speaks_for("") and paper.speaks_for("paper_coupon")
    assert paper.speaks_for("paper_coupon_calibrated")
    assert not paper.speaks_for("my_panel")
    app = calibration_from_json(BUNDLED.read_bytes(), "app", specimen_name="steel_6mm")
    assert app.speaks_for("steel_6mm") and not app.speaks_for("paper_coupon")


def test_bundled_calibration_states_a_unit_for_everything_it_reports():
    """The shipped calibration.json names the unit of each fitted parameter and of each number
    of its predictions and energy check, as a freshly written one does (its units table used
    to lack the first fitted parameter, rolling_friction)."""
    doc = json.loads(BUNDLED.read_text(encoding="utf-8"))
    units = doc["units"]
    assert set(doc["parameters"]) <= set(units)
    numbers = doc["predictions"] + (doc["loo"] or []) + doc["energy_check"]
    reported = {k for row in numbers for k, v in row.items()
                if isinstance(v, (int, float)) and not isinstance(v, bool)}
    reported |= {"rms_in_sample", "loo_rms", "wall_s"}
    assert reported <= set(units), sorted(reported - set(units))


def test_a_measurement_is_checked_against_the_band_of_its_own_stderr(tmp_path):
    # the report compared every measurement with the band of the fitted point's measurement
    # error (0.1 here): a precise new measurement (stderr 0.001) 0.3 off the prediction read
    # "inside". Its band is the error-free one widened by its own stderr.
    fitted = {**_prediction(50, 5, 50, 0.50, 0.20, 0.80), "measured_stderr": 0.1,
              "low95_without_stderr": 0.40, "high95_without_stderr": 0.62}
    cal = load_calibration(_write(tmp_path / "calibration.json", [fitted]))
    table = pd.DataFrame({
        "frequency [Hz]": [50.0, 50.0, 50.0], "acceleration [g]": [5.0] * 3,
        "packing ratio [%]": [50.0] * 3, "material": ["acrylic"] * 3,
        "SDC measured (Eq. 11) [-]": [0.25, 0.25, 0.25],
        "SDC measured (Eq. 11) stderr [-]": [0.1, 0.001, math.nan], "note": [""] * 3})
    out = add_calibration_columns(table, cal)
    low, high = out[CALIBRATED_LOW_COLUMN], out[CALIBRATED_HIGH_COLUMN]
    # the fitted point's own stderr, or none known: the band calibration.json states
    assert (low[0], high[0]) == (low[2], high[2]) == (0.20, 0.80)
    assert out[CALIBRATED_INSIDE_COLUMN].tolist() == ["yes", "no", "yes"]
    # stderr 0.001: 0.5 - hypot(0.1, 1.96 x 0.001), 0.5 + hypot(0.12, 1.96 x 0.001)
    assert low[1] == pytest.approx(0.5 - math.hypot(0.10, 1.959964 * 0.001), rel=1e-6)
    assert high[1] == pytest.approx(0.5 + math.hypot(0.12, 1.959964 * 0.001), rel=1e-6)
    assert out["note"][1] == ("calibrated band for this measurement's SDC stderr 0.001 (the "
                              "calibration's own measurement at this load case had SDC "
                              "stderr 0.1); its 95 % widening: normal quantile 1.96, the "
                              "degrees of freedom of the stderr unknown")
    assert out["note"][0] == out["note"][2] == ""
    # a calibration.json written before the error-free band was kept: the stated band
    old = load_calibration(_write(tmp_path / "old.json", [_prediction(50, 5, 50, 0.5, 0.2,
                                                                        0.8)]))
    assert add_calibration_columns(table, old)[CALIBRATED_LOW_COLUMN].tolist() == [0.2] * 3


@pytest.mark.usefixtures("undrawn_report_figures")
def test_format_help_says_the_figures_come_with_any_format(tmp_path, capsys):
    # `report --format csv` wrote figures/ as well, which its help ("all or a comma-separated
    # list of csv, md, html, tex, pdf") did not say
    from pidcore.cli import main

    out = tmp_path / "rep"
    assert main(["report", "--dem-store", str(ROOT / "data_samples" / "dem_table3.h5"),
                 "--format", "csv", "--out", str(out)]) == 0
    assert (out / "report.csv").is_file() and not (out / "report.md").exists()
    assert any((out / "figures").glob("*.png")) and any((out / "figures").glob("*.svg"))
    with pytest.raises(SystemExit):
        main(["report", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "the figures (PNG and SVG, figures/) are written with any" in help_text


@pytest.mark.parametrize("fields, words", [
    # a band without measurement error that misses its own median was folded about it by
    # the quadrature (low 0.6 > predicted 0.5 read as a band from 0.4)
    ({"low95_without_stderr": 0.6, "high95_without_stderr": 0.7},
     "low95_without_stderr <= predicted <= high95_without_stderr"),
    ({"low95_without_stderr": 0.3, "high95_without_stderr": 0.45},
     "low95_without_stderr <= predicted <= high95_without_stderr"),
    ({"low95_without_stderr": 1e308, "high95_without_stderr": 1e308},
     "low95_without_stderr <= predicted <= high95_without_stderr"),
    # a negative standard error was loaded, matched a row's -0.01 and printed in its note
    ({"measured_stderr": -0.01}, "measured_stderr must be a standard error >= 0"),
])
def test_a_calibration_whose_error_free_band_or_stderr_cannot_be_is_refused(tmp_path, fields,
                                                                          words):
    path = _write(tmp_path / "calibration.json",
                  [{**_prediction(50, 5, 50, 0.50, 0.20, 0.80), "measured_stderr": 0.1,
                    "low95_without_stderr": 0.40, "high95_without_stderr": 0.62, **fields}])
    with pytest.raises(ParameterError, match=words) as err:
        load_calibration(path)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


def test_a_row_whose_stderr_gives_no_band_is_not_compared_and_says_why(tmp_path):
    # a stderr of 1e308 gave a band up to inf (shown and saved), a negative one a
    # ParameterError naming neither the row nor the file
    fitted = {**_prediction(50, 5, 50, 0.50, 0.20, 0.80), "measured_stderr": 0.1,
              "low95_without_stderr": 0.40, "high95_without_stderr": 0.62}
    cal = load_calibration(_write(tmp_path / "calibration.json", [fitted]))
    table = pd.DataFrame({
        "frequency [Hz]": [50.0] * 3, "acceleration [g]": [5.0] * 3,
        "packing ratio [%]": [50.0] * 3, "material": ["acrylic"] * 3,
        "SDC measured (Eq. 11) [-]": [0.25] * 3,
        "SDC measured (Eq. 11) stderr [-]": [1e308, -0.01, 0.001],
        "note": [""] * 3})
    out = add_calibration_columns(table, cal)
    bounds = out[[CALIBRATED_LOW_COLUMN, CALIBRATED_HIGH_COLUMN]].to_numpy()
    assert not np.isinf(bounds).any()
    assert out[CALIBRATED_INSIDE_COLUMN].tolist() == ["not compared", "not compared", "no"]
    assert all("no calibrated band for this measurement's SDC stderr" in n
               for n in out["note"][:2])


@pytest.mark.parametrize("missing", ["nope.json", "folder"])
def test_a_missing_calibration_names_the_command_that_writes_one(tmp_path, capsys, missing):
    # the CLI said "... written by write_outputs(result, --out)": a Python call, half
    # translated, where the user needs the command that writes calibration.json
    path = tmp_path / missing
    if missing == "folder":
        path.mkdir()
    out = tmp_path / "report"
    rc = main(["report", "--dem-store", str(ROOT / "data_samples" / "dem_table3.h5"),
               "--calibration", str(path), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and not out.exists() and len(err.splitlines()) == 1
    assert "written by pidcore calibrate --out" in err, err
    assert "write_outputs" not in err and "result" not in err
    # the library, for a Python caller, names its own function
    with pytest.raises(ParameterError, match=r"write_outputs\(result, out_dir\)"):
        load_calibration(path)


@pytest.mark.parametrize(("edit", "said"), [
    (lambda row: row.update(fill_percent="fifty"),
     "predictions[5]['fill_percent'] must be a finite number, got 'fifty'"),
    (lambda row: row.pop("frequency_hz"),
     "predictions[5] must have the keys 'frequency_hz', 'acceleration_g', 'fill_percent'"),
])
def test_a_bad_calibration_json_is_named_by_its_keys_not_the_clis_flags(tmp_path, capsys,
                                                                         edit, said):
    # "predictions[5].--fill must be a finite number": a key no calibration.json has, for a
    # user fixing the file by hand
    doc = json.loads((ROOT / "data_samples" / "paper_calibration" / "calibration.json")
                     .read_text(encoding="utf-8"))
    edit(doc["predictions"][5])
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    rc = main(["report", "--dem-store", str(ROOT / "data_samples" / "dem_table3.h5"),
               "--calibration", str(path), "--out", str(tmp_path / "report")])
    err = capsys.readouterr().err
    assert rc == 2 and said in err and "--fill" not in err and "--frequency" not in err


def test_an_edited_file_of_the_same_name_is_not_the_calibrated_one(calibration_file):
    # x.toml calibrated, then edited (another coupon mass) and saved under its name: the
    # calibration's [provenance] names the earlier file's hash, and the name alone (with the
    # same cell and particles) showed its band beside the edited file's rows
    from pidcore.specimen import Specimen, calibrated_provenance, paper_specimen

    first = Specimen.from_text(paper_specimen().to_toml().replace(
        'name = "paper_coupon"', 'name = "x"'))
    edited = first.with_values({"coupon.mass_kg": 0.03})
    assert (first.name, first.cell, first.particles) == (edited.name, edited.cell,
                                                        edited.particles)
    assert first.hash != edited.hash
    calibrated = first.with_values({"coupon.fixture_mass_kg": 0.25})
    import dataclasses

    calibrated = dataclasses.replace(calibrated, name="x_calibrated",
                                     provenance=calibrated_provenance(first))
    (calibration_file.parent / "calibrated_specimen.toml").write_text(calibrated.to_toml())
    cal = load_calibration(calibration_file)
    table = _table().iloc[[0]]  # 50 Hz, 5 g, 50 % acrylic: a load case it predicts

    def out(specimen):
        return add_calibration_columns(table, cal, specimen=specimen)

    # the file it was made from, and the calibrated file itself: its band
    for same in (first, calibrated):
        assert out(same)[CALIBRATED_COLUMN].iloc[0] == 0.24, same.name
    # the edited file: not compared, both files named by their hashes
    refused = out(edited)
    assert math.isnan(refused[CALIBRATED_COLUMN].iloc[0])
    assert refused[CALIBRATED_INSIDE_COLUMN].iloc[0] == NOT_COMPARED
    assert refused["note"].iloc[0].endswith(
        f": it calibrates specimen x [{first.hash[:6]}], not x [{edited.hash[:6]}] (another "
        "file of the same name)")
    # a calibrated file without [provenance] (written before it) still goes by its name
    old = dataclasses.replace(calibrated, provenance=None)
    (calibration_file.parent / "calibrated_specimen.toml").write_text(old.to_toml())
    assert load_calibration(calibration_file).other_specimen_reason(edited) == ""


def test_a_calibration_json_alone_speaks_for_the_specimen_it_names(tmp_path):
    # without calibrated_specimen.toml beside it a calibration.json named no specimen and
    # spoke for the tests of any; one written now names the file it calibrated
    from pidcore.calibrate.prediction import calibration_from_json
    from pidcore.specimen import paper_specimen

    def stated(name, sha):
        doc = json.loads(BUNDLED.read_text())
        doc["specimen"] = {"name": name, "sha256": sha}
        path = tmp_path / f"{name}_{sha[:6]}.json"
        path.write_text(json.dumps(doc))
        return load_calibration(path)

    steel = stated("steel_6mm", "ab" * 32)
    assert steel.specimen_path is None and steel.specimen_name == "steel_6mm"
    assert steel.speaks_for("steel_6mm") and steel.speaks_for("steel_6mm_calibrated")
    assert not steel.speaks_for("paper_coupon") and steel.speaks_for("")
    # a user's own paper_coupon.toml: its tests are "paper_coupon [hash6]", never the paper's
    own = paper_specimen().with_values({"coupon.mass_kg": 0.03})
    mine = stated("paper_coupon", own.hash)
    assert mine.specimen_name == f"paper_coupon [{own.hash[:6]}]"
    assert mine.speaks_for(f"paper_coupon [{own.hash[:6]}]")
    assert not mine.speaks_for("paper_coupon")
    paper = stated("paper_coupon", paper_specimen().hash)
    assert paper.specimen_name == "paper_coupon" and paper.speaks_for("paper_coupon")
    # a file written before it stated one: unknown, as before
    assert calibration_from_json(_before_specimen_block(), "old").speaks_for("my_panel")
    # the bundled one names the paper's coupon
    assert not calibration_from_json(BUNDLED.read_bytes(), "new").speaks_for("my_panel")


def test_a_calibration_made_from_an_earlier_version_of_the_specimen_file_says_so(
        calibration_file):
    """`report --specimen wc_3mm.toml --calibration DIR` after the file was edited (another
    restitution, a corrected radius) showed the calibration's bands, made from the earlier
    file, beside the edited file's DEM runs without a word: the runs are kept apart by hash,
    the calibration was matched by name. Its bands are refused there now, with a note naming
    both files by hash."""
    from pidcore.specimen import Specimen, load_specimen

    steel = load_specimen(ROOT / "data_samples" / "specimens" / "steel_6mm.toml")
    calibrated = steel.with_values({"coupon.fixture_mass_kg": 0.2}).to_toml().replace(
        'name = "steel_6mm"', 'name = "steel_6mm_calibrated"')
    calibrated += ("\n[provenance]\ncalibrated_from_name = \"steel_6mm\"\n"
                   f"calibrated_from_sha256 = \"{steel.hash}\"\n")
    (calibration_file.parent / "calibrated_specimen.toml").write_text(calibrated)
    cal = load_calibration(calibration_file)
    assert cal.calibrated_specimen().provenance.calibrated_from_sha256 == steel.hash
    rows = pd.DataFrame({"frequency [Hz]": [100.0], "acceleration [g]": [1.0],
                         "packing ratio [%]": [50.0], "material": ["steel"],
                         "SDC measured (Eq. 11) [-]": [0.1],
                         "SDC measured (Eq. 11) stderr [-]": [0.01],
                         "note": [""]})
    edited = Specimen.from_text(
        steel.with_values({"pairs.particle_particle.restitution": 0.5}).to_toml(),
        source="edited/steel_6mm.toml")
    assert edited.name == steel.name and edited.hash != steel.hash
    out = add_calibration_columns(rows, cal, specimen=edited)
    # the earlier file's calibrated DEM is no prediction of the edited file: refused, said
    assert out[CALIBRATED_COLUMN].isna().all()
    assert out["note"].iloc[0] == (
        f"not predicted by the calibration {calibration_file.name}: it calibrates specimen "
        f"steel_6mm [{steel.hash[:6]}], not steel_6mm [{edited.hash[:6]}] (another file of "
        "the same name)")
    # the file it was made from, and the calibrated file itself, are its specimen: predicted
    for same in (steel, Specimen.from_text(calibrated)):
        assert add_calibration_columns(rows, cal, specimen=same)[CALIBRATED_COLUMN].iloc[0] \
            == 0.09  # copied from calibration.json: no tolerance


# --- a band past 2 pi is cut there and said ------------------------------------------------------

def test_a_band_cut_by_the_measurements_own_scatter_blames_the_measurement(tmp_path):
    # (at 10 % the paper coupon's particles, 8.5 g on 22.2 g, can dissipate at most SDC
    # 8 m_p/m_s = 3.07: the band is cut at 2 pi, as where the specimen is not known)
    # the bundled calibration at 500 Hz, 5 g, 50 %: prediction 0.492, band without
    # measurement error 0.121 .. 0.860; two records pooled there (SDC 4.09 and 0.50) have
    # stderr 1.795 of 1 degree of freedom, t = 12.71: the band reached 0.492 +
    # hypot(0.368, 22.8) = 23.3, all of it the measurement's. The note said "the calibration
    # does not constrain the SDC here (its model discrepancy ... dominate)".
    point = {**_prediction(500, 5, 10, 0.492, 0.121, 0.860), "measured_stderr": 0.0,
             "low95_without_stderr": 0.121, "high95_without_stderr": 0.860}
    hit = load_calibration(_write(tmp_path / "calibration.json", [point])).lookup(
        LoadCase(500, 5, 10))
    t_1 = 12.706204736174707  # Student t 0.975 quantile, 1 degree of freedom (tables)
    high = 0.492 + math.hypot(0.860 - 0.492, t_1 * 1.795)
    assert hit.model_band(1.795, 1.0)[1] == pytest.approx(high, rel=1e-12)
    note = hit.band_note(1.795, 1.0)
    assert note.startswith("calibrated 95 % band cut at 2 pi = 6.283")
    assert "does not constrain" not in note and "model discrepancy" not in note
    assert (f"the band's own upper bound {high:.3g} comes from this measurement's standard "
            f"error (stderr {1.795:.3g} x its 95 % quantile 12.71 = {t_1 * 1.795:.3g}, beside the "
            "calibrated model's 0.368 above its prediction)") in note
    # the model's own width past 2 pi (tau near its prior's top) is still the model's
    wide = {**_prediction(50, 5, 10, 3.0, 0.5, 12.7), "measured_stderr": 0.0,
            "low95_without_stderr": 0.6, "high95_without_stderr": 12.6}
    own = load_calibration(_write(tmp_path / "wide.json", [wide])).lookup(LoadCase(50, 5, 10))
    assert "does not constrain the SDC here" in own.band_note(0.5, 7.0)


def test_a_band_past_two_pi_is_cut_there_with_a_note(tmp_path):
    # a poorly constrained calibration: model discrepancy tau ~ 2 (its prior's top) at a model
    # SDC of 3 gives 3 + 1.96 * 2 * 3 ~ 14.8 as the normal model's upper bound; a measurement
    # above 2 pi is refused by `pidcore analyze` (plausibility.SDC_UPPER_BOUND), so the bound
    # shown is 2 pi and a note carries the model's own 12.7 (at 10 % the paper coupon's
    # particles bound the SDC at 8 m_p/m_s = 3.07 < 2 pi: the bound is 2 pi)
    two_pi = 2 * math.pi
    wide = {**_prediction(50, 5, 10, 3.0, 0.5, 12.7), "measured_stderr": 0.05,
            "low95_without_stderr": 0.6, "high95_without_stderr": 12.6}
    cal = load_calibration(_write(tmp_path / "calibration.json",
                                  [wide, _prediction(500, 5, 10, 0.49, 0.12, 0.88)]))
    hit = cal.lookup(LoadCase(50, 5, 10))
    assert hit.band() == (0.5, two_pi) and hit.model_band() == (0.5, 12.7)
    assert hit.contains(two_pi) and not hit.contains(two_pi + 1e-9)
    note = hit.band_note()
    assert note == ("calibrated 95 % band cut at 2 pi = 6.283 (a loss factor of 1, above which a "
                    "measured SDC is refused as implausible); the model's own upper bound 12.7 "
                    "says the calibration does not constrain the SDC here (its model discrepancy "
                    "and surrogate scatter dominate)")
    # another measurement's stderr widens the model's band (hypot(12.6 - 3, z 0.5)), and
    # the cut applies to it too
    assert hit.model_band(0.5)[1] == pytest.approx(3 + math.hypot(9.6, Z95 * 0.5), rel=1e-12)
    assert hit.band(0.5)[1] == two_pi and "12.7" not in hit.band_note(0.5)
    # a band under the bound: untouched, no note
    low = cal.lookup(LoadCase(500, 5, 10))
    assert low.band() == (0.12, 0.88) and low.band_note() == ""
    # the report's row shows the cut bound and says why; the fitted point's own stderr is
    # not mistaken for another measurement's
    table = pd.DataFrame({
        "frequency [Hz]": [50.0, 500.0], "acceleration [g]": [5.0, 5.0],
        "packing ratio [%]": [10.0, 10.0], "material": ["acrylic", "acrylic"],
        "SDC measured (Eq. 11) [-]": [3.2, 0.5], "SDC measured (Eq. 11) stderr [-]": [0.05, 0.01],
        "note": ["", ""]})
    out = add_calibration_columns(table, cal)
    assert out[CALIBRATED_HIGH_COLUMN].tolist() == [two_pi, 0.88]
    assert out["note"].iloc[0] == note and out["note"].iloc[1].count("cut at 2 pi") == 0
    assert out[CALIBRATED_INSIDE_COLUMN].tolist() == ["yes", "yes"]


def test_the_calibrate_summary_cuts_a_band_past_two_pi():
    from pidcore.calibrate.outputs import _band_text

    # the bounds as band_text writes every band (4 significant digits), the report's and the
    # app's "0.5 .. 6.283", not the summary's own "0.500 .. 6.283"
    assert _band_text(0.5, 12.7) == "0.5 .. 6.283 (cut at 2 pi; model 12.7: unconstrained)"
    assert _band_text(0.12, 0.88) == "0.12 .. 0.88"
    assert _band_text(0.0, 25.0, 16.9115) == ("0 .. 16.91 (cut at the specimen's SDC bound "
                                             "16.91; model 25: unconstrained)")


def test_the_calibrate_plot_cuts_a_band_past_two_pi():
    from pidcore.calibrate.outputs import shown_band_bars

    rows = [{"predicted": 3.0, "low95": 0.5, "high95": 12.7},
            {"predicted": 0.49, "low95": 0.12, "high95": 0.88}]
    pred, below, above, cut = shown_band_bars(rows)
    assert cut and pred.tolist() == [3.0, 0.49]
    # bars end at 2 pi and at the band's own bounds (0.88 - 0.49 exactly as subtracted)
    assert above.tolist() == [2 * math.pi - 3.0, 0.88 - 0.49]
    assert below.tolist() == [2.5, 0.49 - 0.12]
    assert not shown_band_bars(rows[1:])[3]


def test_a_pooled_pair_whose_band_reaches_past_2_pi_is_uninformative_whichever_bound_cuts_it(
        tmp_path):
    # the tester's pooled pair at 500 Hz, 1 g, 50 %: SDC 2.193 and 1.135, mean 1.664 +- 0.529
    # of 1 degree of freedom (t = 12.71, widening 6.72) beside a prediction of 0.197 whose
    # band without measurement error is 0.05 .. 0.48: widened to -3 x 0.529 = -1.587 (the
    # lowest kept SDC) .. 0.197 + hypot(0.283, 6.72) = 6.925. Judged against the paper
    # coupon's bound at 50 % (16.9) the report said "yes" and counted it inside 1 of 1;
    # loaded alone (bound 2 pi, the band cut to 6.283) it was "uninformative". A band from
    # below 0 past 2 pi refutes no plausible SDC: uninformative in both.
    from pidcore.compare.plausibility import UNKNOWN_SPECIMEN_BOUND, sdc_bound
    from pidcore.report.table import UNINFORMATIVE

    pooled = {**_prediction(500, 1, 50, 0.197, 0.02, 0.40), "measured_stderr": 0.04,
              "measured_stderr_dof": 7.0, "low95_without_stderr": 0.05,
              "high95_without_stderr": 0.48}
    cal = load_calibration(_write(tmp_path / "calibration.json", [pooled]))
    hit = cal.lookup(LoadCase(500, 1, 50))
    assert hit.sdc_bound == sdc_bound(fill_percent=50.0, material="acrylic")
    assert hit.sdc_bound.sdc > 16.9  # the premise: the report's bound, far above 2 pi
    low, high = hit.band(0.529, 1.0)
    # 4 significant digits, as the tester's page wrote the band
    assert (round(low, 3), round(high, 3)) == (-1.587, 6.925)
    alone = dataclasses.replace(hit, sdc_bound=UNKNOWN_SPECIMEN_BOUND)
    assert alone.band(0.529, 1.0) == (low, 2 * math.pi)
    for prediction in (hit, alone):
        assert prediction.judge(1.664, 0.529, 1.0)[0] == UNINFORMATIVE
        assert judge_measurement(prediction, 1.664, 0.529, 1.0).verdict == UNINFORMATIVE
    # through the report's rows: the pooled row is not counted; a precise one is still judged
    table = pd.DataFrame({
        "frequency [Hz]": [500.0, 500.0], "acceleration [g]": [1.0, 1.0],
        "packing ratio [%]": [50.0, 50.0], "material": ["acrylic"] * 2,
        "SDC measured (Eq. 11) [-]": [1.664, 0.25],
        "SDC measured (Eq. 11) stderr [-]": [0.529, 0.04],
        "SDC measured (Eq. 11) stderr dof [-]": [1.0, 7.0],
        "note": ["pooled 2 records", ""]})
    out = add_calibration_columns(table, cal)
    assert out[CALIBRATED_INSIDE_COLUMN].tolist() == [UNINFORMATIVE, "yes"]
    assert "inside the 95 % band at 1 of 1 measured row(s) (1 more uninformative" in \
        out.attrs["notes"][-1]
    # a band from 0 that stops short of 2 pi still judges: it refutes an SDC above its top
    short = dataclasses.replace(hit, high95_without_stderr=0.35)
    assert short.band(0.3, 7.0)[1] < 2 * math.pi
    assert short.judge(3.0, 0.3, 7.0)[0] == "no"


def test_a_band_spanning_every_plausible_sdc_is_uninformative_and_not_counted(tmp_path):
    # the bundled calibration at 500 Hz, 5 g, 50 %: band without measurement error
    # 0.121 .. 0.860 about 0.492. Two records pooled there (stderr 1.795 of 1 degree of
    # freedom, t = 12.71) widen it to 0.492 -/+ hypot(0.37, 22.8): below 0 and past the paper
    # coupon's SDC bound at 50 % (8 m_p/m_s = 16.9: 46.8 g of spheres on 22.2 g), so cut to
    # -5.385 .. 16.9 (below, -3 stderr: a measurement lower is refused as energy created
    # beyond its noise), every SDC that coupon can give. The row read "yes" and the report "inside 1
    # of 1"; a precise measurement at 50 Hz is still judged, as before.
    from pidcore.compare.plausibility import UNKNOWN_SPECIMEN_BOUND, sdc_bound
    from pidcore.constants import BAND_VERDICTS
    from pidcore.report.table import UNINFORMATIVE

    bound = sdc_bound(fill_percent=50.0, material="acrylic")
    assert bound.sdc > 2 * math.pi
    pooled = {**_prediction(500, 5, 50, 0.492, 0.121, 0.860), "measured_stderr": 0.0,
              "low95_without_stderr": 0.121, "high95_without_stderr": 0.860}
    cal = load_calibration(_write(tmp_path / "calibration.json",
                                  [pooled, _prediction(50, 5, 50, 0.24, 0.05, 0.43)]))
    hit = cal.lookup(LoadCase(500, 5, 50))
    assert hit.band(1.795, 1.0) == (-3 * 1.795, bound.sdc)
    reason = hit.uninformative_reason(1.795, 1.0)
    assert reason.startswith("uninformative: the calibrated 95 % band -5.385 .. 16.91 spans every "
                             "plausible SDC (0 to 2 pi, a loss factor of 1; "
                             "this measurement's own scatter widens it)")
    # a band cut at 0 only, or at the bound only, still tests the model
    assert hit.uninformative_reason(0.0, 1.0) == ""
    assert hit.uninformative_reason(0.3, 1.0) == ""   # 0.492 - hypot(0.371, 3.81) < 0 only
    assert hit.band(0.3, 1.0)[0] == -3 * 0.3 and hit.band(0.3, 1.0)[1] < bound.sdc
    # where the specimen is not known the bound is 2 pi, and the same rule holds there
    unknown = dataclasses.replace(hit, sdc_bound=UNKNOWN_SPECIMEN_BOUND)
    assert unknown.band(1.795, 1.0) == (-3 * 1.795, 2 * math.pi)
    assert unknown.uninformative_reason(1.795, 1.0).startswith(
        "uninformative: the calibrated 95 % band -5.385 .. 6.283 spans every plausible SDC (0 to "
        "2 pi, a loss factor of 1; this measurement's own scatter widens it)")
    table = pd.DataFrame({
        "frequency [Hz]": [500.0, 50.0, 500.0], "acceleration [g]": [5.0, 5.0, 5.0],
        "packing ratio [%]": [50.0, 50.0, 50.0], "material": ["acrylic"] * 3,
        "SDC measured (Eq. 11) [-]": [2.295, 0.30, 0.50],
        "SDC measured (Eq. 11) stderr [-]": [1.795, 0.01, 0.3],
        "SDC measured (Eq. 11) stderr dof [-]": [1.0, 9.0, 1.0],
        "note": ["pooled 2 records", "", ""]})
    out = add_calibration_columns(table, cal)
    assert out[CALIBRATED_INSIDE_COLUMN].tolist() == [UNINFORMATIVE, "yes", "yes"]
    assert UNINFORMATIVE in BAND_VERDICTS and f"/{UNINFORMATIVE}]" in CALIBRATED_INSIDE_COLUMN
    assert out["note"].iloc[0].startswith("pooled 2 records; " + reason)
    assert (out[CALIBRATED_LOW_COLUMN].iloc[0], out[CALIBRATED_HIGH_COLUMN].iloc[0]) == (
        -3 * 1.795, bound.sdc)
    summary = out.attrs["notes"][-1]
    assert summary.endswith("inside the 95 % band at 2 of 2 measured row(s) (1 more "
                            "uninformative: a band of 0 .. 2 pi, spanning every "
                            "plausible SDC, "
                            "cannot test the model)")


def test_the_report_files_show_the_uninformative_verdict(tmp_path):
    # the verdict reaches every format: the CSV reads it back, MD and HTML show it in the
    # row, the PDF's table has it under its short label
    from datetime import UTC, datetime

    from pidcore.model import load_paper_table3
    from pidcore.report import build_report_table
    from pidcore.report.provenance import collect_provenance
    from pidcore.report.render import pdf_table_cells, write_report
    from pidcore.report.table import UNINFORMATIVE

    pooled = {**_prediction(500, 5, 50, 0.492, 0.121, 0.860), "measured_stderr": 0.0,
              "low95_without_stderr": 0.121, "high95_without_stderr": 0.860}
    cal = load_calibration(_write(tmp_path / "calibration.json", [pooled]))
    dem = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [5.0],
                        "fill_percent": [50.0], "material": ["acrylic"], "direction": ["z"],
                        "sdc": [0.55], "sdc_stderr": [0.01], "case_key": ["b"]})
    analyses = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [5.0],
                             "fill_percent": [50.0], "sdc": [2.295], "sdc_stderr": [1.795],
                             "sdc_stderr_dof": [1.0], "source": ["pooled.uff"]})
    table = add_calibration_columns(build_report_table(dem, analyses, load_paper_table3()), cal)
    assert table[CALIBRATED_INSIDE_COLUMN].tolist() == [UNINFORMATIVE]
    prov = collect_provenance(parameters={}, seeds=[], inputs=[], input_hashes={}, stores=[],
                              notes=table.attrs["notes"],
                              created_utc=datetime(2026, 1, 2, tzinfo=UTC))
    out = tmp_path / "report"
    written = write_report(table, {}, prov, out, "all")
    assert pd.read_csv(written["csv"])[CALIBRATED_INSIDE_COLUMN].tolist() == [UNINFORMATIVE]
    for fmt in ("md", "html"):
        text = written[fmt].read_text(encoding="utf-8")
        # the row note: the paper coupon's bound at 50 %, 8 m_p/m_s (46.8 g on 22.2 g)
        assert f"{UNINFORMATIVE}: the calibrated 95 % band -5.385 .. 16.91" in text
        assert "(1 more uninformative: a band of 0 .. 2 pi" in text  # the report's note
    labels, rows = pdf_table_cells(table)
    shown = {label.replace("\n", " "): cell for label, cell in zip(labels, rows[0], strict=True)}
    assert shown["measured in calibrated 95 % band"] == UNINFORMATIVE
    assert table.attrs["notes"][-1].endswith("at 0 of 0 measured row(s) (1 more uninformative: a "
                                             "band of 0 .. 2 pi, spanning every "
                                             "plausible SDC, "
                                             "cannot test the model)")


def test_every_page_writes_the_band_as_band_text_beside_its_verdict(tmp_path):
    # the app's Report grid wrote the band's two numbers in its own format (0.0000, 16.9115),
    # the terminal's table wrote them without the verdict, the PDF not at all, while the row's
    # note said "0 .. 16.91": one band, now written one way (band_text) on every page
    from pidcore.app.workbench import report_display
    from pidcore.cli.report import short_table
    from pidcore.model import load_paper_table3
    from pidcore.report import build_report_table
    from pidcore.report.render import pdf_table_cells
    from pidcore.report.table import CALIBRATED_BAND_COLUMN, UNINFORMATIVE, with_band_text

    pooled = {**_prediction(500, 5, 50, 0.492, 0.121, 0.860), "measured_stderr": 0.0,
              "low95_without_stderr": 0.121, "high95_without_stderr": 0.860}
    fitted = {**_prediction(50, 5, 50, 0.30, 0.1234567, 0.5678912), "measured_stderr": 0.0}
    cal = load_calibration(_write(tmp_path / "calibration.json", [pooled, fitted]))
    dem = pd.DataFrame({"frequency_hz": [500.0, 50.0, 100.0], "acceleration_g": [5.0] * 3,
                        "fill_percent": [50.0] * 3, "material": ["acrylic"] * 3,
                        "direction": ["z"] * 3, "sdc": [0.55, 0.3, 0.4],
                        "sdc_stderr": [0.01] * 3, "case_key": ["b", "c", "d"]})
    # two records pooled at 500 Hz (stderr 1.795 of 1 dof): the band -5.385 (-3 stderr) .. the
    # paper coupon's bound at 50 %, 16.91; a measurement at 50 Hz with the fitted point's
    # stderr 0: its band
    analyses = pd.DataFrame({"frequency_hz": [500.0, 50.0], "acceleration_g": [5.0, 5.0],
                             "fill_percent": [50.0, 50.0], "sdc": [2.295, 0.3],
                             "sdc_stderr": [1.795, 0.0], "sdc_stderr_dof": [1.0, math.nan],
                             "source": ["pooled.uff", "fitted.uff"]})
    table = add_calibration_columns(build_report_table(dem, analyses, load_paper_table3()), cal)
    by_f = table.set_index("frequency [Hz]")
    assert by_f.loc[500.0, CALIBRATED_INSIDE_COLUMN] == UNINFORMATIVE
    assert by_f.loc[50.0, CALIBRATED_INSIDE_COLUMN] == "yes"
    # the bound 16.91 (8 m_p/m_s: 46.8 g of spheres on 22.2 g) and the file's band, 4 digits;
    # the 100 Hz row is not predicted: no band
    expected = {500.0: "-5.385 .. 16.91", 50.0: "0.1235 .. 0.5679", 100.0: ""}
    shown = with_band_text(table)
    assert CALIBRATED_LOW_COLUMN not in shown and CALIBRATED_HIGH_COLUMN not in shown
    assert dict(zip(shown["frequency [Hz]"], shown[CALIBRATED_BAND_COLUMN],
                    strict=True)) == expected
    assert f"{UNINFORMATIVE}: the calibrated 95 % band -5.385 .. 16.91 spans" in \
        by_f.loc[500.0, "note"]  # the note's words are the cell's
    # the app's Report grid
    grid = report_display(table)
    assert dict(zip(grid["frequency [Hz]"], grid[CALIBRATED_BAND_COLUMN], strict=True)) == \
        expected and CALIBRATED_LOW_COLUMN not in grid
    # the PDF's table
    labels, rows = pdf_table_cells(table)
    heads = [label.replace("\n", " ") for label in labels]
    cells = [dict(zip(heads, row, strict=True)) for row in rows]
    assert {float(c["frequency [Hz]"]): c["calibrated 95 % band [-]"] for c in cells} == expected
    assert {float(c["frequency [Hz]"]): c["measured in calibrated 95 % band"]
            for c in cells}[500.0] == UNINFORMATIVE
    # the terminal's table: the band and its verdict in the row
    text = short_table(table).splitlines()
    assert "calibrated 95 % band [-]" in text[0]
    assert "measured in calibrated 95 % band" in text[0]
    (row,) = [line for line in text[2:] if line.split()[0] == "500"]
    assert "-5.385 .. 16.91" in row and row.split().count(UNINFORMATIVE) == 1
    (row,) = [line for line in text[2:] if line.split()[0] == "50"]
    assert "0.1235 .. 0.5679" in row and "yes" in row.split()


def test_the_report_and_the_calibration_summaries_count_uninformative_bands_in_one_text(
        tmp_path, monkeypatch):
    # the words after "k of n inside" were written twice, in the report's note and in
    # coverage_text (summary.md/html and the command): now uninformative_count_text writes
    # them for both, so that a change in it reaches both
    import pidcore.calibrate.prediction as prediction
    from pidcore.calibrate.outputs import coverage_text

    pooled = {**_prediction(500, 5, 50, 0.492, 0.121, 0.860), "measured_stderr": 0.0,
              "low95_without_stderr": 0.121, "high95_without_stderr": 0.860}
    cal = load_calibration(_write(tmp_path / "calibration.json",
                                  [pooled, _prediction(50, 5, 50, 0.24, 0.05, 0.43)]))
    # the same two measurements: a pooled pair (stderr 1.795 of 1 dof: band 0 .. the bound)
    # and a precise one inside 0.05 .. 0.43
    measured = [(LoadCase(500, 5, 50), 2.295, 1.795, 1.0), (LoadCase(50, 5, 50), 0.30, 0.01, 9.0)]
    table = pd.DataFrame({
        "frequency [Hz]": [c.frequency_hz for c, *_ in measured],
        "acceleration [g]": [c.acceleration_g for c, *_ in measured],
        "packing ratio [%]": [c.fill_percent for c, *_ in measured],
        "material": ["acrylic"] * 2,
        "SDC measured (Eq. 11) [-]": [m[1] for m in measured],
        "SDC measured (Eq. 11) stderr [-]": [m[2] for m in measured],
        "SDC measured (Eq. 11) stderr dof [-]": [m[3] for m in measured],
        "note": ["", ""]})
    verdicts = [cal.lookup(case).judge(sdc, stderr, dof)[0]
                for case, sdc, stderr, dof in measured]
    assert verdicts == ["uninformative", "yes"]
    words = prediction.uninformative_count_text(1)
    assert words == (" (1 more uninformative: a band of 0 .. 2 pi, spanning every "
                     "plausible SDC, cannot test the model)")
    assert prediction.uninformative_count_text(0) == ""
    note = add_calibration_columns(table, cal).attrs["notes"][-1]
    assert note.endswith("at 1 of 1 measured row(s)" + words)
    assert coverage_text(verdicts) == "1/1 inside the 95 % band" + words
    # one function: another wording in it is the wording of both
    monkeypatch.setattr(prediction, "uninformative_count_text",
                        lambda count: f" [{count} apart: band spans every plausible SDC]")
    changed = " [1 apart: band spans every plausible SDC]"
    assert add_calibration_columns(table, cal).attrs["notes"][-1].endswith(
        "at 1 of 1 measured row(s)" + changed)
    assert coverage_text(verdicts) == "1/1 inside the 95 % band" + changed


def test_the_terminal_table_names_the_measured_sdcs_as_report_csv_and_the_pdf_do(tmp_path):
    # the terminal's table headed "SDC measured (Eq. 10) [-]" the column report.csv, the PDF
    # and the app call "SDC measured, E of Eq. 10 [-]": one measured SDC, two names, the short
    # one reading as an SDC given by Eq. 10 (Eq. 10 gives only the energy E it divides by)
    from pidcore.app.workbench import report_display
    from pidcore.cli.report import short_table
    from pidcore.model import load_paper_table3
    from pidcore.report import build_report_table
    from pidcore.report.render import pdf_table_cells
    from pidcore.report.table import MEASURED_EQ10_COLUMN, MEASURED_EQ11_COLUMN

    dem = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [5.0],
                        "fill_percent": [50.0], "material": ["acrylic"], "direction": ["z"],
                        "sdc": [0.55], "sdc_stderr": [0.01], "case_key": ["b"]})
    analyses = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [5.0],
                             "fill_percent": [50.0], "sdc": [0.6], "sdc_stderr": [0.01],
                             "source": ["a.uff"]})
    table = build_report_table(dem, analyses, load_paper_table3())
    names = (MEASURED_EQ10_COLUMN, MEASURED_EQ11_COLUMN)
    assert names == ("SDC measured, E of Eq. 10 [-]", "SDC measured (Eq. 11) [-]")
    labels, _ = pdf_table_cells(table)
    pdf_heads = [label.replace("\n", " ") for label in labels]
    terminal_head = short_table(table).splitlines()[0]
    for name in names:
        assert name in table.columns  # report.csv writes the table's columns
        assert name in pdf_heads and name in report_display(table).columns
        assert name in terminal_head
    assert "(Eq. 10)" not in terminal_head


def _drawn_points(ax) -> tuple[list, list]:
    """Every marker and every error-bar segment a calibration figure holds, in drawing order."""
    lines = [(line.get_label(), np.asarray(line.get_xydata()).tolist()) for line in ax.get_lines()]
    bars = [[np.asarray(s).tolist() for s in c.get_segments()] for c in ax.collections]
    return lines, bars


def test_calibration_frame_names_the_prediction_and_band_as_the_report(calibration_file):
    # Calibration.to_pandas() said "sdc predicted [-]", "low95 [-]", "high95 [-]" where the
    # report's table says "SDC calibrated DEM (Eq. 11) [-]" and "calibrated low/high 95 % [-]"
    # for the same numbers: a script joining the two had to know both spellings.
    import matplotlib.pyplot as plt

    from pidcore.calibrate import CALIBRATION_COLUMNS_RENAMED
    from pidcore.compare.align import CALIBRATED_COLUMN as ALIGN_CALIBRATED_COLUMN
    from pidcore.report.figures_results import plot_calibration

    assert (CALIBRATED_COLUMN, CALIBRATED_LOW_COLUMN, CALIBRATED_HIGH_COLUMN) == (
        "SDC calibrated DEM (Eq. 11) [-]", "calibrated low 95 % [-]", "calibrated high 95 % [-]")
    assert ALIGN_CALIBRATED_COLUMN is CALIBRATED_COLUMN  # one definition, imported
    calibration = load_calibration(calibration_file)
    frame = calibration.to_pandas()
    band = [CALIBRATED_COLUMN, CALIBRATED_LOW_COLUMN, CALIBRATED_HIGH_COLUMN]
    assert not {"sdc predicted [-]", "low95 [-]", "high95 [-]"} & set(frame.columns)
    # the numbers of the file, exactly, under the report's names
    assert frame[band].to_numpy().tolist() == [[0.24, 0.05, 0.43], [0.49, 0.12, 0.88],
                                               [0.09, 0.02, 0.20]]
    # the report's rows of the same load cases carry the same numbers under the same names
    report = add_calibration_columns(_table(), calibration)
    assert report.loc[:1, band].to_numpy().tolist() == frame.loc[:1, band].to_numpy().tolist()
    # an older frame reads into today's and plots the same points, exactly
    older = frame.rename(columns={new: old for old, new in CALIBRATION_COLUMNS_RENAMED.items()})
    assert {"sdc predicted [-]", "low95 [-]", "high95 [-]"} <= set(older.columns)
    pd.testing.assert_frame_equal(older.rename(columns=CALIBRATION_COLUMNS_RENAMED), frame)
    drawn = []
    for each in (frame, older):
        _, ax = plt.subplots()
        try:
            drawn.append(_drawn_points(plot_calibration(each, ax=ax)))
        finally:
            plt.close("all")
    assert drawn[0] == drawn[1]
    (points, *_), (bars,) = drawn[0]
    assert points[1] == [[0.0, 0.24], [1.0, 0.49], [2.0, 0.09]]  # the predictions, drawn
    # the bars end where the file's bands do (to rounding: errorbar adds pred - low back)
    assert np.allclose([[a[1], b[1]] for a, b in bars], [[0.05, 0.43], [0.12, 0.88], [0.02, 0.2]],
                       rtol=0, atol=1e-12)


def test_cli_report_of_a_calibration_folder_a_kill_left_half_moved_reads_the_new_one(
        tmp_path, capsys, monkeypatch):
    # `calibrate --out cal` killed while moving its outputs in: cal/calibration.json is still
    # the earlier one, the new one waits in the committed build folder. The report used to
    # read the earlier numbers silently; it finishes the moves first and says so
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "cal"
    out.mkdir()
    _write(out / "calibration.json", [_prediction(50, 5, 50, 0.11, 0.01, 0.21),
                                      _prediction(500, 5, 50, 0.12, 0.02, 0.22)])
    committed = tmp_path / f".cal.{'7c' * 8}.commit"
    committed.mkdir()
    _write(committed / "calibration.json", [_prediction(50, 5, 50, 0.24, 0.05, 0.43),
                                            _prediction(500, 5, 50, 0.49, 0.12, 0.88)])
    rc = main(["report", "--dem-store", str(ROOT / "data_samples" / "dem_table3.h5"),
               "--calibration", str(out / "calibration.json"), "--format", "csv",
               "--out", str(tmp_path / "report")])
    captured = capsys.readouterr()
    err = captured.out + captured.err
    assert rc == 0, err
    assert (f"{out}: a calibration killed while moving its outputs into it had left 1 of them "
            "to move (calibration.json); moved now") in err
    table = pd.read_csv(tmp_path / "report" / "report.csv")
    # exact: the new file's numbers pass through unchanged (read, not computed)
    assert sorted(table[CALIBRATED_COLUMN].dropna()) == [0.24, 0.49]


@pytest.mark.usefixtures("undrawn_report_figures")
def test_a_measurement_with_a_baseline_taken_off_is_judged_at_its_sdc_before_it(tmp_path,
                                                                                 monkeypatch):
    # `analyze --baseline-loss-factor` takes the empty coupon's damping off the SDC (as report
    # advises, to set it beside the raw DEM); the calibration's prediction adds a baseline of
    # its own, so the verdict compared a particles-only SDC with a prediction of the whole
    # coupon's: 2 pi 0.03 = 0.188 'outside' a band 0.25 .. 0.40 that holds the test's 0.314
    from _app_samples import mass_damper_csv

    from pidcore.compare import MEASURED_BASELINE_COLUMN

    monkeypatch.chdir(tmp_path)
    path = tmp_path / "c_fill50.csv"
    path.write_bytes(mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0, loss_factor=0.05))
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--store", str(store),
                 "--baseline-loss-factor", "0.02"]) == 0
    cal = _write(tmp_path / "calibration.json", [_prediction(100, 5, 50, 0.32, 0.25, 0.40)])
    out = tmp_path / "report"
    assert main(["report", "--store", str(store), "--calibration", str(cal),
                 "--format", "csv", "--out", str(out)]) == 0
    table = pd.read_csv(out / "report.csv")
    (row,) = table[table["SDC measured (Eq. 11) [-]"].notna()].to_dict("records")
    # without --structure-mass the whole loss factor 0.02 is taken off: 2 pi 0.02 exactly, up
    # to the round-off of one subtraction and the CSV's 15+ digits (rel 1e-9)
    assert row[MEASURED_BASELINE_COLUMN] == pytest.approx(2 * math.pi * 0.02, rel=1e-9)
    before = row["SDC measured (Eq. 11) [-]"] + row[MEASURED_BASELINE_COLUMN]
    # the test's own SDC, 2 pi 0.05, within its noise (0.1 % noise: 1e-3 absolute is ~10 sigma)
    assert before == pytest.approx(2 * math.pi * 0.05, abs=1e-3)
    assert row[CALIBRATED_INSIDE_COLUMN] == "yes"
    assert (f"judged at the measured SDC before the empty coupon's damping "
            f"({2 * math.pi * 0.02:.4g}) was taken off, {before:.4g}") in row["note"]
    # a record analysed without a baseline: nothing taken off, judged at its own SDC
    plain = tmp_path / "plain.h5"
    assert main(["analyze", str(path), "--store", str(plain)]) == 0
    assert main(["report", "--store", str(plain), "--calibration", str(cal),
                 "--format", "csv", "--out", str(tmp_path / "plain")]) == 0
    table = pd.read_csv(tmp_path / "plain" / "report.csv")
    (row,) = table[table["SDC measured (Eq. 11) [-]"].notna()].to_dict("records")
    assert row[MEASURED_BASELINE_COLUMN] == 0.0 and row[CALIBRATED_INSIDE_COLUMN] == "yes"
    assert "judged at the measured SDC before" not in str(row["note"])


def test_a_negative_measured_sdc_within_its_noise_is_judged_by_a_band_reaching_below_zero(
        tmp_path):
    # zero damping measured with noise, -0.057 +- 0.13 of 7 dof, beside a calibrated SDC of
    # 0.044 (band without measurement error 0.020 .. 0.080): the widened band was cut at 0 and
    # the measurement judged "no" by the report, the app and the case sheet. Widened in
    # quadrature it is 0.044 - hypot(0.024, t_7 0.13) = -0.264 .. 0.353: inside
    from scipy import stats

    row = {**_prediction(100, 1, 50, 0.044, 0.020, 0.080), "measured_stderr": 0.0,
           "low95_without_stderr": 0.020, "high95_without_stderr": 0.080}
    hit = load_calibration(_write(tmp_path / "calibration.json", [row])).lookup(
        LoadCase(100, 1, 50))
    q = stats.t.ppf(0.975, 7)
    judged = judge_measurement(hit, -0.057, 0.13, 7.0)
    assert judged.verdict == "yes"
    assert judged.low == pytest.approx(0.044 - math.hypot(0.024, q * 0.13), rel=1e-9)
    # a precise negative one is outside (and refused where it is read: 3 stderr below 0)
    assert judge_measurement(hit, -0.057, 0.01, 7.0).verdict == "no"
    # 1 degree of freedom (t = 12.7): the band stops at -3 stderr, the lowest measurement
    # that is kept (pidcore.compare.plausibility.lowest_kept_sdc), as its top at the SDC bound
    assert hit.band(0.13, 1.0)[0] == -3 * 0.13
    # without a stderr a negative SDC is not kept: the band stops at 0, as it did
    assert hit.band(0.0)[0] == 0.020


def test_a_row_of_other_dem_settings_names_the_row_its_load_cases_measurement_is_judged_on(
        calibration_file):
    # two DEM settings at 500 Hz, 5 g, 50 %: the measurement is on the 8-cell row, and the
    # 2-cell row said "no Eq. 11 measurement" although the load case has one
    table = pd.DataFrame({
        "frequency [Hz]": [500.0, 500.0, 50.0],
        "acceleration [g]": [5.0] * 3, "packing ratio [%]": [50.0] * 3,
        "material": ["acrylic"] * 3,
        "SDC measured (Eq. 11) [-]": [math.nan, 0.30, math.nan],
        "SDC measured (Eq. 11) stderr [-]": [math.nan, 0.01, math.nan],
        "DEM settings": ["cells 2, settings hash aaaaaa", "cells 8, settings hash bbbbbb",
                         "cells 8, settings hash bbbbbb"],
        "specimen": [""] * 3, "specimen sha256": [""] * 3,
        "load case": ["f500Hz_a5g_fill50pct_acrylic_z"] * 2 + ["f50Hz_a5g_fill50pct_acrylic_z"],
        "note": [""] * 3,
    })
    out = add_calibration_columns(table, load_calibration(calibration_file))
    assert out[CALIBRATED_INSIDE_COLUMN].tolist() == [NOT_COMPARED, "yes", NOT_COMPARED]
    assert out["note"].iloc[0] == ("the measurement at this load case is compared with the "
                                   "calibrated band on the row of DEM settings cells 8, "
                                   "settings hash bbbbbb")
    # a load case measured nowhere still says so
    assert out["note"].iloc[2] == "no Eq. 11 measurement to compare with the calibrated band"
