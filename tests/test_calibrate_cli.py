"""``pidcore calibrate``: bad input refused in one line (exit 2, nothing written), the --json
document, leave-one-out independence, and Ctrl-C keeping finished DEM runs."""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from pidcore.calibrate import MeasuredPoint, calibrate
from pidcore.calibrate.runner import RunRequest, run_requests
from pidcore.cli import main
from pidcore.dem.simulate import DemConfig, LoadCase
from pidcore.specimen import load_specimen, paper_specimen
from pidcore.store import Store

REPO = Path(__file__).resolve().parents[1]
HEADER = "frequency_hz,acceleration_g,fill_percent,sdc\n"
ROWS = "500,5,50,0.6\n1000,5,50,0.6\n500,1,50,0.2\n"
TINY = ["--cells", "2", "--steady-cycles", "10", "--workers", "1", "--no-progress"]


def _table(tmp_path, text=HEADER + ROWS):
    path = tmp_path / "m.csv"
    path.write_text(text)
    return path


def _refused(capsys, tmp_path, argv, *words):
    store = tmp_path / "dem.h5"
    code = main(["calibrate", *argv, "--dem-store", str(store), *TINY])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1, err
    for word in words:
        assert word in err, err
    assert not store.exists()  # nothing computed or written before the input was checked


def test_missing_column_is_refused(capsys, tmp_path):
    path = _table(tmp_path, "frequency_hz,acceleration_g,sdc\n500,5,0.6\n")
    _refused(capsys, tmp_path, ["--data", str(path)], "m.csv", "fill_percent")


def test_unknown_parameter_is_refused(capsys, tmp_path):
    _refused(capsys, tmp_path, ["--data", str(_table(tmp_path)), "--fit", "fixture_mass,friction"],
             "fixture_mass")


def test_bounds_excluding_the_prior_are_refused(capsys, tmp_path):
    _refused(capsys, tmp_path, ["--data", str(_table(tmp_path)), "--fit", "friction",
                                "--prior", "friction=normal:0.9:0.1:0.05:0.8"],
             "friction", "exclude")
    _refused(capsys, tmp_path, ["--data", str(_table(tmp_path)), "--prior",
                                "fixture_mass_kg=0.5:0.1"], "fixture_mass_kg", "empty")


def test_an_out_that_is_a_file_and_a_negative_seed_are_refused_before_any_run(capsys,
                                                                              tmp_path):
    # --out FILE gave a FileExistsError traceback after the whole calibration had run;
    # --seed -1 a traceback from numpy's generator
    existing = tmp_path / "existing.txt"
    existing.write_text("keep")
    _refused(capsys, tmp_path, ["--data", str(_table(tmp_path)), "--fit", "fixture_mass_kg",
                                "--out", str(existing)], "--out", "existing.txt", "not a folder")
    assert existing.read_text() == "keep"
    with pytest.raises(SystemExit) as stop:  # argparse's own refusal, as from the shell
        main(["calibrate", "--data", str(_table(tmp_path)), "--fit", "fixture_mass_kg",
              "--seed", "-1", "--dem-store", str(tmp_path / "dem.h5"), *TINY])
    assert stop.value.code == 2 and "--seed: expected a whole number >= 0" in \
        capsys.readouterr().err
    assert not (tmp_path / "dem.h5").exists()


def test_the_dem_runs_own_refusals_name_the_options(capsys, tmp_path, monkeypatch):
    # more cells than memory holds, and a seed past 2^63, were refused as "cells 2: ..." and
    # "seed: ...", keywords `pidcore calibrate` has as options
    import pidcore.dem.simulate as simulate

    table = str(_table(tmp_path))
    _refused(capsys, tmp_path, ["--data", table, "--fit", "restitution", "--seed",
                                str(2**63)],
             "error: --seed: expected a whole number below 2^63")
    monkeypatch.setattr(simulate, "_physical_memory_bytes", lambda: 1)  # no cell fits
    _refused(capsys, tmp_path, ["--data", table, "--fit", "restitution"],
             "error: --cells 2: the state of 2 cells of ")


def test_fewer_load_cases_than_parameters_are_refused(capsys, tmp_path):
    # two points cannot fix fixture mass, baseline and the model discrepancy
    path = _table(tmp_path, HEADER + "500,5,50,0.6\n1000,5,50,0.6\n")
    _refused(capsys, tmp_path, ["--data", str(path)], "2 measured load case")


@pytest.fixture(scope="module")
def tiny_store(tmp_path_factory):
    return tmp_path_factory.mktemp("cal") / "dem.h5"


@pytest.mark.slow
def test_non_ascii_paths_under_an_ascii_locale_are_written_as_their_names(tmp_path):
    # LC_ALL=C with PYTHONUTF8=0: Python holds the UTF-8 bytes of "é" in a path as surrogates,
    # which the UTF-8 outputs could not encode (UnicodeEncodeError: surrogates not allowed,
    # after the DEM runs) and calibration.json held as "\udcc3\udca9"
    folder = tmp_path / "dir é Ω"
    folder.mkdir()
    data = _table(folder).rename(folder / "measured é.csv")
    specimen = folder / "coupon é.toml"
    specimen.write_text((REPO / "pidcore/data/specimens/paper_coupon.toml").read_text())
    env = {**os.environ, "PYTHONPATH": str(REPO), "LC_ALL": "C", "PYTHONUTF8": "0",
           "PYTHONCOERCECLOCALE": "0", "MPLBACKEND": "Agg"}
    p = subprocess.run([sys.executable, "-m", "pidcore", "calibrate", "--data", str(data),
                        "--specimen", str(specimen), "--fit", "fixture_mass_kg",
                        "--discrepancy", "0.2", "--dem-store", str(folder / "dem é.h5"),
                        "--out", str(folder / "out"), *TINY],
                       capture_output=True, env=env, timeout=300)
    assert p.returncode == 0, p.stderr.decode("ascii", "backslashreplace")[-2000:]
    # each name read back from the files as it is on disk (a round trip of the bytes)
    document = json.loads((folder / "out" / "calibration.json").read_text(encoding="utf-8"))
    assert [m["source"] for m in document["settings"]["measured"]] == [str(data)]
    summary = (folder / "out" / "summary.md").read_text(encoding="utf-8")
    assert str(data) in summary and str(specimen) in summary
    calibrated = (folder / "out" / "calibrated_specimen.toml").read_text(encoding="utf-8")
    assert f"table {data} (sha256" in calibrated


def test_json_document(capsys, tmp_path, tiny_store):
    code = main(["calibrate", "--data", str(_table(tmp_path)), "--fit", "fixture_mass_kg",
                 "--discrepancy", "0.2", "--cross-validate", "loo", "--json",
                 "--dem-store", str(tiny_store), "--out", str(tmp_path / "out"), *TINY])
    assert code == 0
    doc = json.loads(capsys.readouterr().out)
    assert set(doc) == {"specimen", "parameters", "predictions", "loo", "loo_rms",
                        "loo_coverage95", "loo_uninformative95", "units", "rms_in_sample",
                        "coverage95", "uninformative95"}
    # which file was calibrated and which it wrote (the document named neither: a
    # calibration.json apart from its folder spoke for the tests of any specimen)
    from pidcore.calibrate.persist import calibration_key
    from pidcore.specimen import load_specimen, paper_specimen

    written = load_specimen(tmp_path / "out" / "calibrated_specimen.toml")
    assert doc["specimen"] == {"name": "paper_coupon", "sha256": paper_specimen().hash,
                               "calibrated_name": written.name,
                               "calibrated_sha256": written.hash}
    full = json.loads((tmp_path / "out" / "calibration.json").read_text())
    assert full["specimen"] == doc["specimen"]
    # the names are in the calibrated file's text, which the store key covers: the JSON's own
    # key is the one a pidcore that did not write them gave the same fit
    bare = {k: v for k, v in full.items() if k != "specimen"}
    assert calibration_key(full) == calibration_key(bare)
    alone = tmp_path / "alone"
    alone.mkdir()
    (alone / "calibration.json").write_bytes((tmp_path / "out" / "calibration.json").read_bytes())
    from pidcore.calibrate import load_calibration

    apart = load_calibration(alone)
    assert apart.specimen_path is None and apart.specimen_name == "paper_coupon"
    assert apart.speaks_for("paper_coupon") and not apart.speaks_for("steel_6mm")
    assert set(doc["parameters"]) == {"fixture_mass_kg"}
    # every number of the document names its unit, as calibration.json's table does
    assert doc["units"] == {"fixture_mass_kg": "kg", "loo_rms": "-",
                            "frequency_hz": "Hz", "acceleration_g": "g", "fill_percent": "%",
                            "measured": "-", "measured_stderr": "-", "predicted": "-",
                            "low95": "-", "high95": "-", "low95_without_stderr": "-",
                            "high95_without_stderr": "-", "rms_in_sample": "-",
                            "inside95": "yes/no/uninformative", "coverage95": "count",
                            "uninformative95": "count", "loo_coverage95": "count",
                            "loo_uninformative95": "count"}
    p = doc["parameters"]["fixture_mass_kg"]
    assert set(p) == {"median", "low95", "high95"} and p["low95"] <= p["median"] <= p["high95"]
    keys = {"frequency_hz", "acceleration_g", "fill_percent", "material", "measured",
            "measured_stderr", "predicted", "low95", "high95", "low95_without_stderr",
            "high95_without_stderr"}
    assert len(doc["predictions"]) == len(doc["loo"]) == 3
    assert all(set(r) == keys | {"inside95"} for r in doc["predictions"] + doc["loo"])
    rms = math.sqrt(sum((r["predicted"] - r["measured"]) ** 2 for r in doc["loo"]) / 3)
    assert doc["loo_rms"] == pytest.approx(rms, rel=1e-12)
    out = tmp_path / "out"
    full = json.loads((out / "calibration.json").read_text())
    assert full["loo_rms"] == doc["loo_rms"]
    # no DEM parameter fitted: the calibrated DEM's energy per cycle is the starting one
    for row in full["energy_check"]:
        assert row["energy_per_cycle_per_cell_calibrated_j"] == pytest.approx(
            row["energy_per_cycle_per_cell_start_j"], rel=1e-12)
    for name in ("calibrated_specimen.toml", "summary.md", "summary.html", "predictions.png",
                 "posterior_pairs.png"):
        assert (out / name).stat().st_size > 0
    # every column of the summary's prediction tables names its unit (it said "measured SDC",
    # "error", "inside"); parameters carry theirs in their names (fixture_mass_kg)
    summary = (out / "summary.md").read_text()
    heads = [line for line in summary.splitlines() if line.startswith("| frequency [Hz]")]
    assert len(heads) == 2  # in-sample and leave-one-out
    for head in heads:
        cells = [c.strip() for c in head.strip("|").split("|")]
        assert all(c.endswith("]") for c in cells), cells
    # the calibrated specimen is a valid specimen file holding the fitted value, all else
    # as the paper's coupon
    spec = load_specimen(out / "calibrated_specimen.toml")
    assert spec.coupon.fixture_mass_kg == pytest.approx(p["median"], rel=1e-12)
    paper = paper_specimen()
    assert (spec.cell, spec.particles, spec.pairs) == (paper.cell, paper.particles, paper.pairs)
    assert spec.coupon.mass_kg == paper.coupon.mass_kg
    assert spec.name == "paper_coupon_calibrated"
    # the description states the fitted values, not only the starting file's words
    # (each to the digits its Monte-Carlo error leaves: summary_texts)
    from pidcore.calibrate.posterior import summary_texts

    full = json.loads((out / "calibration.json").read_text())
    median, low, high = summary_texts(full["parameter_details"]["fixture_mass_kg"])
    assert float(median) == pytest.approx(p["median"], rel=0.01)
    assert (f"calibrated by pidcore calibrate: fixture_mass_kg {median} "
            f"(95 % {low} .. {high})") in spec.description


def test_every_parameter_row_names_its_unit_in_the_command_and_the_summaries(capsys, tmp_path,
                                                                             tiny_store):
    # the table of medians and intervals had no unit anywhere: only a name such as
    # fixture_mass_kg carried one, and baseline_loss_factor's or model_discrepancy's
    # dimensionless numbers read as of no stated unit (every output column names its unit)
    import html

    code = main(["calibrate", "--data", str(_table(tmp_path)), "--fit",
                 "fixture_mass_kg,baseline_loss_factor", "--discrepancy", "0.2",
                 "--dem-store", str(tiny_store), "--out", str(tmp_path / "out"), *TINY])
    assert code == 0
    out = capsys.readouterr().out.splitlines()
    doc = json.loads((tmp_path / "out" / "calibration.json").read_text())
    units = {"fixture_mass_kg": "kg", "baseline_loss_factor": "-"}  # the vocabulary's
    assert {name: doc["units"][name] for name in units} == units
    from pidcore.calibrate.posterior import summary_texts

    summary = (tmp_path / "out" / "summary.md").read_text().splitlines()
    page = (tmp_path / "out" / "summary.html").read_text()
    assert "| parameter | unit | median | 95 % interval | prior bounds |" in summary
    # the page's table as summary.md's, prior bounds included (it left them out)
    assert ("<tr><th>parameter</th><th>unit</th><th>median</th><th>95 % interval</th>"
            "<th>prior bounds</th></tr>") in page
    for name, unit in units.items():
        p = doc["parameter_details"][name]
        median, low, high = summary_texts(p)
        assert f"{name} [{unit}]: {median} (95 % {low} .. {high})" in out
        assert (f"| {name} | {unit} | {median} | {low} .. {high} | {p['prior_low']:g} .. "
                f"{p['prior_high']:g} |") in summary
        assert (f"<tr><td>{name}</td><td>{html.escape(unit)}</td><td>{median}</td>"
                f"<td>{low} .. {high}</td><td>{p['prior_low']:g} .. {p['prior_high']:g}</td>"
                "</tr>") in page


def test_a_calibration_result_reads_as_its_calibration_json(tmp_path, tiny_store):
    # a script's calibrate() result had neither to_pandas() nor plot() nor lookup(): only
    # lists of dicts, while the same numbers read back from calibration.json had them all
    import matplotlib
    import pandas as pd

    from pidcore.calibrate import load_calibration, write_outputs

    points = [MeasuredPoint(500, 5, 50, 0.6), MeasuredPoint(1000, 5, 50, 0.6),
              MeasuredPoint(500, 1, 50, 0.2)]
    result = calibrate(points, fit=["fixture_mass_kg"], store_path=tiny_store,
                       discrepancy=0.2, cells=2, steady_cycles=10,
                       dem_config=DemConfig(steady_cycles=10), workers=1, progress=False)
    write_outputs(result, tmp_path / "out")
    read_back = load_calibration(tmp_path / "out")
    pd.testing.assert_frame_equal(result.to_pandas(), read_back.to_pandas())
    case = LoadCase(500.0, 1.0, 50.0)
    assert result.calibration().lookup(case) == read_back.lookup(case)
    assert result.calibration().lookup(case).sdc == result.predictions[2]["predicted"]
    ax = matplotlib.figure.Figure().subplots()
    assert result.plot(ax=ax) is ax and ax.has_data()


def test_loo_prediction_never_sees_the_held_out_value(tiny_store):
    # a fold's prediction must not move when the held-out measurement changes
    config = DemConfig(steady_cycles=10)
    points = [MeasuredPoint(500, 5, 50, 0.6), MeasuredPoint(1000, 5, 50, 0.6),
              MeasuredPoint(500, 1, 50, 0.2)]
    kw = dict(fit=["fixture_mass_kg"], store_path=tiny_store, discrepancy=0.2, cells=2,
              steady_cycles=10, dem_config=config, workers=1, progress=False,
              cross_validate="loo")
    a = calibrate(points, **kw)
    changed = list(points)
    changed[0] = MeasuredPoint(500, 5, 50, 5.0)
    b = calibrate(changed, **kw)
    assert b.loo[0]["predicted"] == a.loo[0]["predicted"]
    assert b.loo[0]["low95"] == a.loo[0]["low95"]
    assert b.predictions[0]["predicted"] != a.predictions[0]["predicted"]  # the full fit sees it


PREDICTION_FIELDS = ("predicted", "low95", "high95", "predicted_low95", "predicted_high95",
                     "low95_without_stderr", "high95_without_stderr")


def test_no_loo_fold_sees_its_held_out_value_and_every_other_fold_does(tiny_store):
    # Every fold, with the model discrepancy fitted and the measurements' t likelihood (stderr
    # with 7 degrees of freedom): moving one measurement far away must leave its own held-out
    # prediction bit for bit as it was (a leak of the held-out value into its fold's fit
    # would move it), while the folds that hold it in their fit must move (else the check
    # could not see a leak at all).
    config = DemConfig(steady_cycles=10)
    points = [MeasuredPoint(500, 5, 50, 0.6, 0.05, sdc_stderr_dof=7),
              MeasuredPoint(1000, 5, 50, 0.5, 0.05, sdc_stderr_dof=7),
              MeasuredPoint(500, 1, 50, 0.2, 0.05, sdc_stderr_dof=7)]
    kw = dict(fit=["fixture_mass_kg"], store_path=tiny_store, cells=2, steady_cycles=10,
              dem_config=config, workers=1, progress=False, cross_validate="loo")
    base = calibrate(points, **kw)
    for i, point in enumerate(points):
        changed = list(points)
        changed[i] = MeasuredPoint(point.frequency_hz, point.acceleration_g,
                                   point.fill_percent, point.sdc + 2.0, point.sdc_stderr,
                                   sdc_stderr_dof=point.sdc_stderr_dof)
        moved = calibrate(changed, **kw)
        assert {k: moved.loo[i][k] for k in PREDICTION_FIELDS} \
            == {k: base.loo[i][k] for k in PREDICTION_FIELDS}, f"fold {i} saw its own point"
        # scored against the value it did not see: the row's error is the new one's
        assert moved.loo[i]["error"] == pytest.approx(base.loo[i]["error"] - 2.0)
        for j in range(len(points)):
            if j != i:
                assert moved.loo[j]["predicted"] != base.loo[j]["predicted"], (i, j)


def test_interrupt_keeps_finished_runs(tmp_path):
    config = DemConfig(cells=2, steady_cycles=10, block_cycles=5, max_transient_cycles=10)
    requests = [RunRequest(LoadCase(f, 5, 50), paper_specimen(), config)
                for f in (500.0, 1000.0)]
    store = tmp_path / "dem.h5"

    def interrupt(key):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_requests(requests, store_path=store, workers=1, progress=False, on_done=interrupt)
    assert Store(store).has_dem_run(requests[0].key())
    assert not Store(store).has_dem_run(requests[1].key())
    again = run_requests(requests, store_path=store, workers=1, progress=False)
    assert (again["computed"], again["cached"]) == (1, 1)


def test_store_measurements_are_grouped_per_load_case(monkeypatch, tmp_path):
    # repeated tests of one load case (measured f and a scatter about the nominal ones) give
    # their mean and the standard error of the mean; a single test keeps its own error
    import pandas as pd

    from pidcore.calibrate import measured_from_store

    frame = pd.DataFrame({"frequency_hz": [50.02, 49.98, 500.1],
                          "acceleration_g": [4.97, 5.02, 1.01],
                          "fill_percent": [50.0, 50.0, 50.0],
                          "sdc": [0.20, 0.26, 0.22], "sdc_stderr": [0.01, 0.01, 0.015]})
    monkeypatch.setattr(Store, "list_analyses", lambda self: frame)
    points = {(p.frequency_hz, p.acceleration_g): p for p in measured_from_store(tmp_path / "s.h5")}
    assert set(points) == {(50.0, 5.0), (500.0, 1.0)}
    assert points[(50.0, 5.0)].sdc == pytest.approx(0.23)
    assert points[(50.0, 5.0)].sdc_stderr == pytest.approx(0.03)  # std 0.0424 / sqrt(2)
    assert points[(500.0, 1.0)].sdc_stderr == pytest.approx(0.015)


def test_store_tests_at_fills_of_one_particle_count_are_repeats_of_one_load_case(monkeypatch,
                                                                                 tmp_path):
    # tests saved at 50 % and at 52 % (both 11 of the paper coupon's 22 spheres, one DEM
    # simulation) were two load cases of one mean each: calibrate ran the one simulation
    # twice and leave-one-out kept each one's twin in its fit. They are repeated tests of
    # one case (mean and standard error of the mean), at the fill most of them state, and
    # said; 25 % (6 spheres) is another case
    import pandas as pd

    from pidcore.calibrate import measured_from_store

    frame = pd.DataFrame({"frequency_hz": [500.0, 500.0, 500.0, 500.0],
                          "acceleration_g": [5.0, 5.0, 5.0, 5.0],
                          "fill_percent": [50.0, 52.0, 50.0, 25.0],
                          "sdc": [0.20, 0.26, 0.23, 0.4], "sdc_stderr": [0.01] * 4,
                          "key": ["a1", "a2", "a3", "a4"]})
    monkeypatch.setattr(Store, "list_analyses", lambda self: frame)
    left_out: list[str] = []
    points = {p.fill_percent: p for p in measured_from_store(tmp_path / "s.h5",
                                                             left_out=left_out)}
    assert set(points) == {50.0, 25.0}
    # the mean and the standard error of the mean of 0.20, 0.26, 0.23: std 0.03 / sqrt(3)
    # (rel 1e-12: a mean and a standard deviation of three numbers)
    assert points[50.0].sdc == pytest.approx(0.23, rel=1e-12)
    assert points[50.0].sdc_stderr == pytest.approx(0.03 / math.sqrt(3), rel=1e-12)
    assert points[50.0].sdc_stderr_dof == 2.0 and points[50.0].analyses == ("a1", "a2", "a3")
    assert points[25.0].sdc == 0.4 and points[25.0].analyses == ("a4",)
    assert left_out == ["500 Hz, 5 g, 50 %, acrylic: tests stated at fills 50 % (2), 52 % (1) "
                        "are all 11 of 22 particles per cell of specimen paper_coupon, one "
                        "DEM simulation: pooled as repeated tests of one load case at 50 %"]


def test_store_measurements_of_other_materials_are_other_points(monkeypatch, tmp_path):
    # acrylic and steel particles at one load case are two specimens: averaging them would fit
    # neither; the material and specimen label saved with each record are kept
    import pandas as pd

    from pidcore.calibrate import measured_from_store

    frame = pd.DataFrame({"frequency_hz": [500.0, 500.0, 500.0],
                          "acceleration_g": [1.0, 1.0, 1.0], "fill_percent": [50.0] * 3,
                          "sdc": [0.20, 0.40, 0.42], "sdc_stderr": [0.01, 0.01, 0.01],
                          "material": ["acrylic", "steel", "steel"],
                          "specimen": ["", "steel_6mm_b", "steel_6mm_c"]})
    monkeypatch.setattr(Store, "list_analyses", lambda self: frame)
    points = {(p.material, p.specimen): p for p in measured_from_store(tmp_path / "s.h5")}
    assert set(points) == {("acrylic", ""), ("steel", "steel_6mm_b"), ("steel", "steel_6mm_c")}
    assert points[("acrylic", "")].sdc == 0.20  # its own value, not a mean with steel
    assert points[("steel", "steel_6mm_b")].label() == \
        "500 Hz, 1 g, 50 %, steel, specimen steel_6mm_b"


def test_a_point_of_another_material_than_the_specimens_is_refused():
    # a steel measurement fitted with acrylic particles (or the reverse) would be fitted
    # silently against the wrong DEM; the error names both materials and the way out
    from pidcore.calibrate import base_specimen
    from pidcore.errors import ParameterError

    steel = load_specimen(REPO / "data_samples" / "specimens" / "steel_6mm.toml")
    acrylic_point = MeasuredPoint(500, 1, 50, 0.2)
    steel_point = MeasuredPoint(500, 1, 50, 0.4, material="steel")
    with pytest.raises(ParameterError, match="acrylic particles, the specimen .* holds steel"):
        base_specimen([acrylic_point], steel)
    with pytest.raises(ParameterError, match="steel particles, which are not in the materials "
                                             "table: give the specimen file"):
        base_specimen([steel_point], None)
    with pytest.raises(ParameterError, match="several particle materials"):
        base_specimen([acrylic_point, steel_point], steel)
    assert base_specimen([steel_point], steel) is steel
    assert base_specimen([acrylic_point], None).particles.material == "acrylic"


def test_a_table_without_materials_is_of_the_specimen_given(tmp_path):
    # as `pidcore compare --specimen`: a row stating no material is of the specimen's
    # particles; a row stating another one keeps it (and is then refused by base_specimen)
    from pidcore.calibrate import read_measured_table

    table = tmp_path / "m.csv"
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc,material\n"
                     "500,1,50,0.4,\n500,5,50,0.5,acrylic\n")
    points = read_measured_table(table, default_material="steel")
    assert [p.material for p in points] == ["steel", "acrylic"]
    assert [p.material for p in read_measured_table(table)] == ["acrylic", "acrylic"]


def test_a_tables_material_is_read_as_the_sidecar_reads_it(tmp_path):
    # 'Tungsten_Carbide' or 'PMMA' typed in a spreadsheet: the sidecar of `analyze` reads them
    # as tungsten_carbide and acrylic, while the calibrate --data table kept them verbatim and
    # refused the points as "of Tungsten_Carbide particles, the specimen holds tungsten_carbide"
    from pidcore.calibrate import read_measured_table
    from pidcore.errors import InputFileError

    table = tmp_path / "m.csv"
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc,material\n"
                     "500,1,50,0.4,Tungsten_Carbide\n500,5,50,0.5, tungsten_carbide\n"
                     "500,8,50,0.5,PMMA\n500,10,50,0.5,Aluminum\n")
    assert [p.material for p in read_measured_table(table)] == [
        "tungsten_carbide", "tungsten_carbide", "acrylic", "aluminium"]
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc,material\n"
                     "500,1,50,0.4,Tungsten Carbide\n")
    with pytest.raises(InputFileError) as caught:
        read_measured_table(table)
    assert str(caught.value) == (f"{table}, line 2: material: particle material 'Tungsten "
                                 "Carbide' is not a name (expected lower-case letters, digits "
                                 "and '_', e.g. 'acrylic')")


def test_repeated_rows_of_one_load_case_are_refused(tmp_path):
    # three rows of 500 Hz, 1 g, 40 % passed as three load cases: a 3-parameter fit ran on
    # one case (two distinct cases were refused as too few)
    from pidcore.calibrate import read_measured_table
    from pidcore.errors import InputFileError

    table = tmp_path / "dup.csv"
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc\n"
                     "500,1,40,0.21\n500,5,40,0.3\n500,1,40,0.22\n")
    with pytest.raises(InputFileError, match=r"lines 2 and 4 state the same load case "
                                             r"\(500 Hz, 1 g, 40 %, acrylic\)"):
        read_measured_table(table)
    # another material at the same load case is another point
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc,material\n"
                     "500,1,40,0.21,acrylic\n500,1,40,0.3,aluminium\n")
    assert len(read_measured_table(table)) == 2


def test_too_few_load_cases_name_the_fitted_parameters():
    # "cannot determine 3 fitted parameter(s)" with 2 asked for: the third, the model
    # discrepancy, is fitted unless fixed, and the message now says so and how
    from pidcore.calibrate.data import MeasuredPoint, check_enough_points
    from pidcore.errors import ParameterError

    points = [MeasuredPoint(500.0, 1.0, 50.0, 0.3), MeasuredPoint(500.0, 5.0, 50.0, 0.5)]
    with pytest.raises(ParameterError, match=r"2 measured load case\(s\) cannot determine 3 "
                                             r"fitted parameter\(s\): fixture_mass_kg, "
                                             r"baseline_loss_factor, model_discrepancy; .*"
                                             r"discrepancy=TAU"):
        check_enough_points(points, ["fixture_mass_kg", "baseline_loss_factor",
                                     "model_discrepancy"])
    check_enough_points(points, ["fixture_mass_kg", "baseline_loss_factor"])


def test_a_semicolon_table_with_decimal_commas_and_capitalised_headers_reads(tmp_path):
    # a spreadsheet's export ("Frequency_Hz;...;0,21") was refused as missing every column
    from pidcore.calibrate import read_measured_table

    comma = tmp_path / "comma.csv"
    comma.write_text("frequency_hz,acceleration_g,fill_percent,sdc,sdc_stderr\n"
                     "500,1,40,0.21,0.01\n1000,5,40,0.5,0.02\n")
    semi = tmp_path / "semi.csv"
    semi.write_text("Frequency_Hz;Acceleration_g;Fill_Percent;SDC;SDC_stderr\n"
                    "500;1;40;0,21;0,01\n1000;5;40;0,5;0,02\n", encoding="utf-8-sig")
    assert read_measured_table(semi) == read_measured_table(comma)


def test_cli_refuses_measurements_of_another_material_than_the_specimens(capsys, tmp_path):
    # the same check as the app's (base_specimen, inside calibrate): before any DEM run
    steel = REPO / "data_samples" / "specimens" / "steel_6mm.toml"
    path = _table(tmp_path, HEADER.strip() + ",material\n" +
                  ROWS.replace("\n", ",acrylic\n"))
    _refused(capsys, tmp_path, ["--data", str(path), "--specimen", str(steel)],
             "acrylic particles", "holds steel particles")


# 0: how the store reads a stored False back (the first version of this note compared the
# text with "false" and never fired on a real store); np.False_ and False as other callers
# may hold it
@pytest.mark.parametrize("unsteady", [0, np.False_, False])
def test_runs_that_never_reached_steady_state_are_named_in_the_notes(tiny_store, tmp_path,
                                                                     monkeypatch, unsteady):
    # a trial's calibration used a DEM run the DEM tab flagged "NOT reached" and said nothing
    from pidcore.calibrate.data import read_measured_table

    points = read_measured_table(_table(tmp_path))
    settings = {"fit": ["fixture_mass_kg"], "discrepancy": 0.2, "store_path": tiny_store,
                "cells": 2, "steady_cycles": 10, "workers": 1, "progress": False}
    quiet = calibrate(points, **settings)
    assert not any("steady state" in note for note in quiet.notes)
    stored = Store.get_dem_run

    def one_unsteady(self, key):
        entry = stored(self, key)
        if key.startswith("f500Hz_a1g"):
            entry.record["steady_detected"] = unsteady
        return entry

    monkeypatch.setattr(Store, "get_dem_run", one_unsteady)
    flagged = calibrate(points, **settings)
    assert "1 of 3 DEM run(s) never reached steady state" in " ".join(flagged.notes)
    # the share its stored energy fell by: the tallies' 1 - work/dissipation, checked against
    # the stored energy's change the run measured from its state at the window's ends (another
    # path), within 0.05 % of printed rounding plus the run's energy-balance closure error
    record = stored(Store(tiny_store), next(k for k in Store(tiny_store).list_dem_runs()
                                            ["case_key"] if k.startswith("f500Hz_a1g"))).record
    found = re.search(r"500 Hz, 1 g, 50 %, acrylic \(1: ([-+][0-9.]+)%\)", " ".join(flagged.notes))
    assert found
    from_state = -record["stored_energy_change_per_cycle_j"] / record["energy_per_cycle_j"]
    assert float(found[1]) / 100 == pytest.approx(
        from_state, abs=5e-4 + 2 * abs(record["energy_balance_error"]))


def test_energy_check_calls_a_start_outside_only_beyond_its_own_uncertainty():
    # a trial's table read "start 2.06e-05, band 2.06e-05 .. 2.06e-05, start inside: no":
    # the fitted parameter does not move that load case, and the start missed the
    # zero-width band by a last digit
    from types import SimpleNamespace

    from pidcore.calibrate.calibrate import energy_check

    class Surrogate:
        frequency_hz, acceleration_g, fill_percent = 50.0, 1.0, 50.0

        def __init__(self, slope):
            self.slope = slope

        def predict(self, theta):
            d = 1e-3 * (1.0 + self.slope * theta[:, 0])
            # a wide variance, as an extrapolation to a start outside the prior gives
            return d, np.full(d.shape, 1e-6), d, d

    samples = np.linspace(0.01, 0.1, 201)[:, None]  # the posterior of a rolling friction
    specimen = SimpleNamespace(cell=SimpleNamespace(count=441))

    def within(slope):
        model = SimpleNamespace(specs=[SimpleNamespace(kind="dem", default=0.0)],
                                dem_theta=lambda s: s, surrogates=[Surrogate(slope)])
        return energy_check(model, samples, specimen)[0]["within"]

    # a trend of 1e-7 per unit of the parameter: the start misses the band by 1e-9 relative
    assert within(1e-7)
    # the physics moved (the paper's 500 Hz, 1 g: 2.0e-9 J at the start, band 0.25e-9 ..
    # 1.5e-9 J): outside, however uncertain the surrogate is at the start
    assert not within(5.0)
    # the band's low end (2.5 % of the posterior, theta 0.012) 0.25 % above the start:
    # outside the 0.1 % resolution; 0.06 % above it: inside
    assert not within(0.2)
    assert within(0.05)


def test_method_help_states_the_grid_limit_the_posterior_applies(capsys):
    """`pidcore calibrate --help` said "exact grid (<= 3 quantities)" while auto picks the grid
    for up to GRID_MAX_DIMENSIONS (4: three parameters plus the discrepancy)."""
    from pidcore.calibrate.posterior import GRID_MAX_DIMENSIONS
    from pidcore.cli import build_parser

    with pytest.raises(SystemExit):
        build_parser("calibrate").parse_args(["calibrate", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert f"exact grid (<= {GRID_MAX_DIMENSIONS} fitted quantities" in text, text


def test_design_size_0_and_workers_0_are_refused_not_taken_as_defaults(capsys, tmp_path):
    """`--design-size 0 --fit friction` silently ran the default 5-point design (60 DEM runs)
    while 1 and -1 were refused; `--workers 0` was accepted where every other command's
    --workers refuses it."""
    table = _table(tmp_path)
    for option in (["--fit", "friction", "--design-size", "0"], ["--workers", "0"]):
        with pytest.raises(SystemExit) as exited:  # argparse's one line, as from the shell
            main(["calibrate", "--data", str(table), *option,
                  "--dem-store", str(tmp_path / "dem.h5")])
        assert exited.value.code == 2
        assert f"argument {option[-2]}: expected a whole number >= 1, got '0'" in \
            capsys.readouterr().err
        assert not (tmp_path / "dem.h5").exists()
    # the library too: 0 is not "the default design"
    from pidcore.calibrate.data import read_measured_table
    from pidcore.errors import ParameterError

    with pytest.raises(ParameterError, match="design_size: expected >= 2 with DEM "
                                             "parameters, got 0"):
        calibrate(read_measured_table(table), fit=["friction"], design_size=0,
                  store_path=tmp_path / "dem.h5")
    assert not (tmp_path / "dem.h5").exists()


class _StopAfter(threading.Event):
    """A stop that is found set once it has been looked at ``checks`` times: a Cancel clicked
    while the calibration is still being set up."""

    def __init__(self, checks: int) -> None:
        super().__init__()
        self.left = checks

    def is_set(self) -> bool:
        self.left -= 1
        return self.left < 0 or super().is_set()


def test_a_design_size_over_the_cap_is_refused_before_anything_is_made(capsys, tmp_path):
    """`--design-size 100000 --fit friction` was taken: 500000 run requests were built (over
    30 s, and the app's Cancel unheard) before any DEM run."""
    from pidcore import defaults
    from pidcore.calibrate.data import read_measured_table
    from pidcore.errors import ParameterError
    from pidcore.interrupt import StopRequested

    cap = defaults.CALIBRATION_MAX_DESIGN_SIZE
    table = _table(tmp_path)
    _refused(capsys, tmp_path, ["--data", str(table), "--fit", "friction", "--design-size",
                                str(cap + 1)],
             f"--design-size: expected at most {cap} design points (each is one DEM run per "
             f"load case), got {cap + 1}")
    points = read_measured_table(table)
    with pytest.raises(ParameterError, match=rf"^design_size: expected at most {cap} "):
        calibrate(points, fit=["friction"], design_size=100_000, store_path=tmp_path / "d.h5")
    # the cap itself is taken: a stop set from the start ends it, not a refusal
    with pytest.raises(StopRequested):
        calibrate(points, fit=["friction"], design_size=cap, store_path=tmp_path / "d.h5",
                  progress=False, stop=_StopAfter(0))
    assert not (tmp_path / "d.h5").exists()


def test_a_stop_while_the_design_is_built_ends_the_calibration_before_its_requests_are(
        tmp_path, monkeypatch):
    """The app's Cancel was looked at only once every run request of the design was made
    (~0.6 ms a variant): minutes for a large design, the page saying 'cancelling' meanwhile."""
    import importlib

    from pidcore import defaults
    from pidcore.calibrate.data import read_measured_table
    from pidcore.interrupt import StopRequested

    pipeline = importlib.import_module("pidcore.calibrate.calibrate")  # the package's function
    made, told = [], []
    real = pipeline.specimen_with
    monkeypatch.setattr(pipeline, "specimen_with",
                        lambda specimen, values: made.append(values) or real(specimen, values))
    monkeypatch.setattr(pipeline, "run_requests",
                        lambda *a, **kw: pytest.fail("no DEM run was to be asked for"))
    n_design = defaults.CALIBRATION_MAX_DESIGN_SIZE
    with pytest.raises(StopRequested, match="calibration stopped"):
        calibrate(read_measured_table(_table(tmp_path)), fit=["friction"],
                  design_size=n_design, store_path=tmp_path / "d.h5", progress=False,
                  on_design=told.append, stop=_StopAfter(5))
    # the stop is looked at before each variant: found set at the 6th look, after 5 of the
    # 200 variants were made, never after all of them
    assert len(made) == 5
    assert not told and not (tmp_path / "d.h5").exists()


def test_a_stop_while_the_run_keys_are_looked_up_ends_before_the_rest(tmp_path, monkeypatch):
    """run_requests hashed every request's key and asked the store for it before it first
    looked at its stop."""
    from pidcore.interrupt import StopRequested

    keys = []
    real = RunRequest.key
    monkeypatch.setattr(RunRequest, "key", lambda self: keys.append(1) or real(self))
    specimen = paper_specimen()
    requests = [RunRequest(LoadCase(100.0 + i, 5.0, 50.0, "acrylic"), specimen,
                           DemConfig(cells=2)) for i in range(50)]
    with pytest.raises(StopRequested, match="stopped before any started"):
        run_requests(requests, store_path=tmp_path / "d.h5", progress=False,
                     stop=_StopAfter(3))
    assert len(keys) == 3  # looked at before each key: the 4th look found it set
    assert not (tmp_path / "d.h5").exists()


def test_an_empty_data_table_suggests_the_measured_sdc_header(capsys, tmp_path):
    """`pidcore calibrate --data empty.csv` suggested the sidecar's header
    'file,fill_percent,velocity_delay_us' and "one row per file"."""
    table = _table(tmp_path, text="# nothing yet\n")
    _refused(capsys, tmp_path, ["--data", str(table)], "empty table",
             "'frequency_hz,acceleration_g,fill_percent,sdc'", "one row per load case")


def test_auto_falling_back_from_the_grid_to_emcee_is_said(tiny_store, tmp_path, monkeypatch):
    # --method auto sampled with emcee where the grid could not box the posterior, and the
    # summary, notes and settings still read as if the grid had been used
    from pidcore.calibrate import posterior
    from pidcore.calibrate.data import read_measured_table
    from pidcore.calibrate.outputs import summary_markdown

    points = read_measured_table(_table(tmp_path))
    settings = {"fit": ["fixture_mass_kg"], "discrepancy": 0.2, "store_path": tiny_store,
                "cells": 2, "steady_cycles": 10, "workers": 1, "progress": False,
                "cross_validate": "loo"}
    on_grid = calibrate(points, **settings)
    assert on_grid.settings["method_used"] == "grid"
    assert not any("emcee" in note for note in on_grid.notes)
    assert "posterior by grid" in summary_markdown(on_grid)
    # a box the posterior never spans enough of: the grid cannot settle in its one pass
    monkeypatch.setattr(posterior, "GRID_MAX_PASSES", 1)
    monkeypatch.setattr(posterior, "GRID_ZOOM_SHARE", 2.0)
    fallen = calibrate(points, **settings)
    assert fallen.settings["method"] == "auto" and fallen.settings["method_used"] == "emcee"
    notes = " ".join(fallen.notes)
    assert "method=auto: the grid posterior did not settle" in notes
    assert "3 of 3 leave-one-out fold(s)" in notes
    assert "posterior by emcee" in summary_markdown(fallen)


def test_summary_table_shows_small_sdc_with_its_digits():
    """The summary's prediction table printed SDCs with three fixed decimals: a load case of
    SDC 2.97e-4 (the paper's 100 Hz, 1 g, 25 %) read 0.000 measured, predicted and in its
    band, as if there were no damping. Every SDC is written as the report writes it, 4
    significant digits (0.23, 0.052 .. 0.436, +0.01), a small one too."""
    from pidcore.calibrate.outputs import _table_rows

    rows = [{"frequency_hz": 100.0, "acceleration_g": 1.0, "fill_percent": 25.0,
             "measured": 2.9705e-4, "predicted": 4.1e-4, "low95": 1.2e-4, "high95": 8.8e-4},
            {"frequency_hz": 50.0, "acceleration_g": 5.0, "fill_percent": 50.0,
             "measured": 0.23, "predicted": 0.24, "low95": 0.052, "high95": 0.436}]
    small, usual = _table_rows(rows, [2 * math.pi] * 2, ["yes", "yes"])
    assert small[3:8] == ["0.000297", "0.00041", "0.00012 .. 0.00088", "+0.000113", "yes"]
    assert usual[3:8] == ["0.23", "0.24", "0.052 .. 0.436", "+0.01", "yes"]


def _mixed_store(monkeypatch):
    """A store's analyses: acrylic of the paper's coupon, steel of steel_6mm (unnamed) and of
    another steel specimen."""
    import pandas as pd

    frame = pd.DataFrame({"frequency_hz": [500.0, 1000.0, 500.0, 1000.0, 500.0],
                          "acceleration_g": [1.0, 5.0, 1.0, 5.0, 5.0],
                          "fill_percent": [50.0] * 5, "sdc": [0.2, 0.5, 0.4, 0.6, 0.5],
                          "sdc_stderr": [0.01] * 5,
                          "material": ["acrylic", "acrylic", "steel", "steel", "steel"],
                          "specimen": ["", "", "", "", "steel_other"]})
    monkeypatch.setattr(Store, "list_analyses", lambda self: frame)


def test_store_of_two_materials_calibrates_the_specimens_points(capsys, monkeypatch, tmp_path):
    # `calibrate --store` on a store holding acrylic and steel measurements was refused as a
    # whole ("choose the points of one material") with no option to choose them; with
    # --specimen it takes that specimen's points, as the app's Calibrate page does, and says
    # what it leaves out
    import importlib

    from pidcore.errors import ParameterError

    # the module, not the function pidcore.calibrate exports under the same name
    library = importlib.import_module("pidcore.calibrate.calibrate")

    _mixed_store(monkeypatch)
    with Store(tmp_path / "s.h5").transaction():  # an empty store, listed as the frame above
        pass
    seen = {}

    def fake_calibrate(points, **kwargs):
        seen["points"] = points
        raise ParameterError("stopped before any DEM run")

    monkeypatch.setattr(library, "calibrate", fake_calibrate)
    steel = REPO / "data_samples" / "specimens" / "steel_6mm.toml"
    code = main(["calibrate", "--store", str(tmp_path / "s.h5"), "--specimen", str(steel),
                 "--dem-store", str(tmp_path / "dem.h5"), *TINY])
    err = capsys.readouterr().err
    assert code == 2 and "stopped before any DEM run" in err
    assert sorted((p.frequency_hz, p.material, p.specimen) for p in seen["points"]) == [
        (500.0, "steel", ""), (1000.0, "steel", "")]
    assert ("note: Not used for steel_6mm (steel particles): 1 measured load case(s) of "
            "specimen steel_other; 2 measured load case(s) of acrylic particles.") in err
    # without --specimen (the paper's coupon) the two materials are refused with the way out
    _refused(capsys, tmp_path, ["--store", str(tmp_path / "s.h5")],
             "measurements of acrylic, steel particles", "--specimen FILE")


def test_a_file_analysed_twice_is_one_measured_point_of_its_newest_analysis(tmp_path):
    # one file analysed again with a baseline loss factor was taken for two repeated tests:
    # the mean of both analyses, with a standard error from their difference (0.006 instead
    # of the analysis's own 0.03), and the same raw data counted twice
    from _shaker_files import write_force_velocity

    from pidcore.calibrate import measured_from_store
    from pidcore.constants import STANDARD_GRAVITY
    from pidcore.signal.synthetic import synthesize_shaker_record

    rec = synthesize_shaker_record(mass_kg=0.25, acceleration_amplitude_m_s2=5 * STANDARD_GRAVITY,
                                   frequency_hz=500.0, sample_rate_hz=25_600.0, n_periods=40.3,
                                   viscous_damping_n_s_m=2.0, coulomb_friction_n=0.3,
                                   snr_db=50, seed=3)
    path = tmp_path / "run_fill50_acrylic.csv"
    write_force_velocity(path, rec.force_n, rec.velocity_m_s, 25_600.0, "csv")
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--store", str(store)]) == 0
    # another vibrometer delay too: the two analyses' P_c differ, not only their baselines
    assert main(["analyze", str(path), "--store", str(store), "--baseline-loss-factor",
                 "0.002", "--velocity-delay", "2e-6"]) == 0
    analyses = Store(store).list_analyses().sort_values("created_utc")
    assert len(analyses) == 2  # the store keeps both analyses of the one measurement
    oldest, newest = analyses.iloc[0], analyses.iloc[-1]
    (point,) = measured_from_store(store)
    # the newest one, not the mean of both; its SDC before the baseline it took off, which
    # the calibration's observation model adds (rel 1e-12: one division and product)
    assert point.sdc == pytest.approx(2 * math.pi * newest["complex_power_real_w"]
                                      / newest["complex_power_imag_w"], rel=1e-12)
    assert point.sdc != pytest.approx(oldest["sdc"], rel=1e-6)
    assert point.sdc_stderr == newest["sdc_stderr"]


def test_help_states_the_design_size_and_seed_defaults(capsys):
    """--design-size said 'enough for a quadratic surrogate' (the surrogate is a Gaussian
    process; the default is default_design_size's 5 + 4 per further DEM parameter) and --seed
    gave no default."""
    from pidcore import defaults
    from pidcore.calibrate.surrogate import default_design_size

    with pytest.raises(SystemExit):
        main(["calibrate", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "quadratic" not in text
    assert f"default {default_design_size(1)} for one DEM parameter" in text
    assert f"{default_design_size(2) - default_design_size(1)} more per further one" in text
    assert f"DEM seed (default {defaults.DEM_SEED})" in text


def test_store_of_only_another_specimens_tests_says_why_none_is_used(capsys, monkeypatch,
                                                                     tmp_path):
    # calibrate --store (the paper's coupon) on a store of steel_6mm's tests said only 'no
    # measured points to calibrate against': the note naming what was left out, and how to
    # calibrate it, was dropped when nothing was kept
    import pandas as pd

    frame = pd.DataFrame({"frequency_hz": [500.0, 1000.0], "acceleration_g": [1.0, 5.0],
                          "fill_percent": [50.0] * 2, "sdc": [0.4, 0.6],
                          "sdc_stderr": [0.01] * 2, "material": ["steel"] * 2,
                          "specimen": ["steel_6mm"] * 2})
    monkeypatch.setattr(Store, "list_analyses", lambda self: frame)
    with Store(tmp_path / "s.h5").transaction():  # an empty store, listed as the frame above
        pass
    _refused(capsys, tmp_path, ["--store", str(tmp_path / "s.h5")],
             "no measurement of the paper's coupon",
             "2 measured load case(s) of specimen steel_6mm", "--specimen FILE of theirs")


def _store_with_an_implausible_record(tmp_path, capsys) -> Path:
    """A store of two 500 Hz, 5 g, 50 % tests: a damped one and one of negative damping (SDC
    < 0, energy created) saved with --accept-implausible."""
    from _shaker_files import write_force_velocity

    from pidcore.constants import STANDARD_GRAVITY
    from pidcore.signal.synthetic import synthesize_shaker_record

    store = tmp_path / "s.h5"
    paths = []
    for name, damping in (("good_fill50_acrylic.csv", 2.0), ("neg_fill50_acrylic.csv", -2.0)):
        rec = synthesize_shaker_record(mass_kg=0.25,
                                       acceleration_amplitude_m_s2=5 * STANDARD_GRAVITY,
                                       frequency_hz=500.0, sample_rate_hz=25_600.0,
                                       n_periods=40, viscous_damping_n_s_m=damping,
                                       snr_db=60, seed=3)
        paths.append(write_force_velocity(tmp_path / name, rec.force_n, rec.velocity_m_s,
                                          25_600.0, "csv"))
    assert main(["analyze", *map(str, paths), "--store", str(store),
                 "--accept-implausible"]) == 0
    capsys.readouterr()
    return store


def test_a_record_saved_as_implausible_is_left_out_of_a_store_calibration(tmp_path, capsys):
    # calibrate --store fitted an SDC of -1.26 (energy created, kept with
    # --accept-implausible) averaged with the load case's real tests, without a word
    from pidcore.calibrate import measured_from_store

    store = _store_with_an_implausible_record(tmp_path, capsys)
    good = Store(store).list_analyses().set_index("source")
    good_sdc = next(v for k, v in good["sdc"].items() if k.endswith("good_fill50_acrylic.csv"))
    left_out: list[str] = []
    (point,) = measured_from_store(store, left_out=left_out)
    assert point.sdc == good_sdc > 0  # the good test alone, not the mean with -SDC
    assert len(left_out) == 1 and left_out[0].startswith("neg_fill50_acrylic.csv: left out, "
                                                         "implausible")


def test_a_store_of_implausible_records_only_says_so_not_that_no_load_case_is_complete(
        tmp_path, capsys):
    # calibrate --store on a store whose only test was kept with --accept-implausible said
    # "no analysed measurement has a complete load case", though its load case was complete
    from _shaker_files import write_force_velocity

    from pidcore.calibrate import measured_from_store
    from pidcore.constants import STANDARD_GRAVITY
    from pidcore.errors import InputFileError
    from pidcore.signal.synthetic import synthesize_shaker_record

    only_bad = tmp_path / "bad.h5"

    rec = synthesize_shaker_record(mass_kg=0.25, acceleration_amplitude_m_s2=5 * STANDARD_GRAVITY,
                                   frequency_hz=500.0, sample_rate_hz=25_600.0, n_periods=40,
                                   viscous_damping_n_s_m=-2.0, snr_db=60, seed=3)
    path = write_force_velocity(tmp_path / "neg_fill50_acrylic.csv", rec.force_n,
                                rec.velocity_m_s, 25_600.0, "csv")
    assert main(["analyze", str(path), "--store", str(only_bad), "--accept-implausible"]) == 0
    capsys.readouterr()
    with pytest.raises(InputFileError) as info:
        measured_from_store(only_bad)
    message = str(info.value)
    assert message.startswith(f"{only_bad}: no analysed measurement to calibrate against: 1 "
                              "record(s) with a complete load case, all implausible and saved "
                              "as accepted (first: negative loss factor")
    assert "complete load case" in message and "\n" not in message
    before = only_bad.read_bytes()
    assert main(["calibrate", "--store", str(only_bad), "--dem-store", str(only_bad),
                 *TINY]) == 2
    assert "all implausible and saved as accepted" in capsys.readouterr().err
    assert only_bad.read_bytes() == before


def test_a_record_left_out_of_a_store_calibration_is_named_in_its_outputs(tmp_path, capsys,
                                                                        monkeypatch):
    # calibrate --store said on stderr that a record saved as implausible was left out, but
    # summary.md and calibration.json (what a later report --calibration reads) counted their
    # measured load cases with no word of it
    import importlib
    from types import SimpleNamespace

    library = importlib.import_module("pidcore.calibrate.calibrate")
    outputs = importlib.import_module("pidcore.calibrate.outputs")
    store = _store_with_an_implausible_record(tmp_path, capsys)
    written = {}
    monkeypatch.setattr(outputs, "write_outputs",
                        lambda result, out, **_: written.setdefault("notes",
                                                                    list(result.notes)))
    monkeypatch.setattr(outputs, "document_json", lambda document: "{}")
    fake = SimpleNamespace(notes=["the fit's own note"], document=dict,
                           runs={"computed": 0, "cached": 0})
    monkeypatch.setattr(library, "calibrate", lambda points, **kwargs: fake)
    # the store keeps what full_document() gives, with the same notes (checked for a real
    # result in tests/test_calibration_store.py); the fake has no document to keep
    monkeypatch.setattr(importlib.import_module("pidcore.calibrate.persist"),
                        "save_calibration", lambda result, store: ("cal_0", True))
    assert main(["calibrate", "--store", str(store), "--dem-store", str(tmp_path / "d.h5"),
                 "--out", str(tmp_path / "cal"), "--json", *TINY]) == 0
    err = capsys.readouterr().err
    (left,) = [n for n in written["notes"] if "left out" in n]
    assert left.startswith("neg_fill50_acrylic.csv: left out, implausible")
    assert written["notes"][-1] == "the fit's own note"
    # said once each on stderr, as before
    assert err.count("neg_fill50_acrylic.csv: left out") == 1
    assert err.count("the fit's own note") == 1


def test_the_html_summary_carries_the_notes_of_the_markdown_one():
    # summary.md listed its notes (a median set by the prior, a record left out as
    # implausible); summary.html, 'the Markdown summary's content', dropped them
    import html
    from types import SimpleNamespace

    from pidcore.calibrate.outputs import summary_html

    notes = ["neg_fill50.csv: left out, implausible (saved as accepted): SDC -1.26 < 0",
             "fixture_mass_kg: the posterior piles against its prior's lower bound 0 & <more>"]
    from pidcore.specimen import paper_specimen

    # the page names the specimen calibrated and the file written: the fake has both
    page = summary_html(SimpleNamespace(parameters={}, predictions=[], loo=None, notes=notes,
                                        units=dict, specimen=paper_specimen(),
                                        calibrated_specimen=paper_specimen, specs=[],
                                        correlations=[], energy_check=[], wall_s=0.0,
                                        file_predicted=[],
                                        runs={"computed": 0, "cached": 0},
                                        settings={"cells": 2, "design_size": 1,
                                                  "method_used": "grid"}))
    for note in notes:
        assert f"<li>{html.escape(note)}</li>" in page


def test_an_emcee_posterior_that_did_not_converge_is_flagged(tiny_store, tmp_path, monkeypatch):
    # emcee's chains were never checked: a posterior, and leave-one-out folds, from chains
    # too short for their autocorrelation were reported as results. Now the notes, the
    # settings and the summary say so (a rule no chain can meet forces the case)
    from pidcore.calibrate import posterior
    from pidcore.calibrate.data import read_measured_table
    from pidcore.calibrate.outputs import summary_markdown

    points = read_measured_table(_table(tmp_path))
    settings = {"fit": ["fixture_mass_kg"], "discrepancy": 0.2, "store_path": tiny_store,
                "cells": 2, "steady_cycles": 10, "workers": 1, "progress": False,
                "cross_validate": "loo", "method": "emcee"}
    converged = calibrate(points, **settings)
    assert converged.settings["sampler"]["converged"] is True
    assert not any("NOT CONVERGED" in note for note in converged.notes)
    assert ", converged)" in summary_markdown(converged)
    monkeypatch.setattr(posterior, "EMCEE_TAU_LENGTHS", 10**9)
    monkeypatch.setattr(posterior, "EMCEE_MAX_STEPS", 2000)
    flagged = calibrate(points, **settings)
    notes = " ".join(flagged.notes)
    assert "NOT CONVERGED: the emcee posterior did not converge within 2000 steps" in notes
    assert "the medians, intervals and bands are not reliable" in notes
    assert "NOT CONVERGED: the emcee chains of 3 of 3 leave-one-out fold(s)" in notes
    sampler = flagged.settings["sampler"]
    assert sampler["converged"] is False and sampler["steps"] == 2000
    assert "NOT converged)" in summary_markdown(flagged)


def test_on_run_done_tells_each_computed_run_of_the_design_once(tmp_path):
    # the app's calibration said only "N s elapsed" for minutes: it now counts the design's
    # runs done through these hooks, which must name each computed run once, cached ones never
    from pidcore.store import Store

    store = tmp_path / "dem.h5"
    points = [MeasuredPoint(500, 5, 50, 0.6), MeasuredPoint(1000, 5, 50, 0.6),
              MeasuredPoint(500, 1, 50, 0.2)]
    kw = dict(fit=["fixture_mass_kg"], store_path=store, discrepancy=0.2, cells=2,
              steady_cycles=10, dem_config=DemConfig(steady_cycles=10), workers=1,
              progress=False)
    design, done = [], []
    calibrate(points, on_design=design.extend, on_run_done=done.append, **kw)
    assert len(design) == 3 and sorted(done) == sorted(set(design))
    assert all(Store(store).has_dem_run(key) for key in done)
    again: list[str] = []
    calibrate(points, on_run_done=again.append, **kw)
    assert again == []  # every run reused from the store


def test_a_killed_calibrations_build_folder_is_removed_by_the_next_out(capsys, tmp_path,
                                                                       tiny_store):
    # `pidcore calibrate --out cal` killed outright (kill -9, a power loss) left its hidden
    # build folder beside cal for ever; the next --out cal removes it once a day old, and
    # keeps a younger one (a live run's) and a user's folder named like it. One killed while
    # it moved its outputs into cal left them half-moved: the next --out cal completes the
    # moves first and says so (kill points: test_outputs_killed_at_any_move_...)
    from _build_leftovers import leave_build_folders

    out = tmp_path / "cal"
    names = leave_build_folders(out, "calibration.json", ('5a', '6b'))
    out.mkdir()
    (out / "notes.txt").write_text("a user's")
    committed = tmp_path / f".cal.{'7c' * 8}.commit"  # its commit made, one file left
    committed.mkdir()
    (committed / "summary.md").write_text("the killed run's")
    code = main(["calibrate", "--data", str(_table(tmp_path)), "--fit", "fixture_mass_kg",
                 "--discrepancy", "0.2", "--dem-store", str(tiny_store), "--out", str(out),
                 *TINY])
    err = capsys.readouterr().err
    assert code == 0, err
    assert (f"pidcore calibrate: note: {out}: a calibration killed while moving its outputs "
            "into it had left 1 of them to move (summary.md); moved now, so it holds that "
            "calibration's whole set, not a mix with the earlier one") in err
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["cal", "m.csv", names["fresh"], names["user's"]])
    # the outputs landed whole, and the calibration reads back from them; a user's file kept
    assert sorted(p.name for p in out.iterdir()) == sorted(
        ["calibration.json", "calibrated_specimen.toml", "summary.md", "summary.html",
         "predictions.png", "posterior_pairs.png", "notes.txt"])
    assert (out / "notes.txt").read_text() == "a user's"
    assert (out / "summary.md").read_text() != "the killed run's"
    assert set(json.loads((out / "calibration.json").read_text())["parameters"]) == \
        {"fixture_mass_kg"}


def test_outputs_killed_at_any_move_are_the_earlier_or_the_new_set_after_the_next_run(tmp_path):
    # `pidcore calibrate --out cal` into an existing cal renamed its six outputs into it one
    # by one: killed (SIGKILL, power loss) between two, cal held some new files and some of
    # the earlier calibration, for ever. Killed at each rename in turn, cal now holds the
    # earlier set or the new one, file for file, once the next run's clean-up has run (as it
    # does first), a user's files in cal untouched and nothing left beside it.
    import os
    import shutil
    import time

    from _build_leftovers import calibration_outputs_script, folder_contents, run_killed_at_rename

    from pidcore.atomic_files import remove_stale_temporary_folders
    from pidcore.calibrate import finish_interrupted_outputs
    from pidcore.defaults import STALE_TEMPORARY_FILE_AGE_S

    script = calibration_outputs_script()
    references = tmp_path / "references"
    references.mkdir()
    for run in ("earlier", "new"):
        assert not run_killed_at_rename(script, 99, exchange=False, cwd=tmp_path,
                                        args=(str(references / run), run))
    earlier, new = folder_contents(references / "earlier"), folder_contents(references / "new")
    assert len(earlier) == len(new) == 6 and not set(earlier.values()) & set(new.values())
    users = {"notes.txt": b"a user's", "summary.md.bak": b"a user's copy"}
    work = tmp_path / "work"
    outcomes = []
    for renames in range(12):
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir()
        out = work / "cal"
        shutil.copytree(references / "earlier", out)
        for name, data in users.items():
            (out / name).write_bytes(data)
        (work / ".cal.backup.commit").mkdir()  # a user's, named like ours
        killed = run_killed_at_rename(script, renames, exchange=False, cwd=tmp_path,
                                      args=(str(out), "new"))
        note = finish_interrupted_outputs(out)
        # a kill before the commit leaves a build folder, removed once a day old (only its
        # age is not simulated)
        remove_stale_temporary_folders(out, now=time.time() + STALE_TEMPORARY_FILE_AGE_S + 1)
        after = folder_contents(out)
        assert after in ({**earlier, **users}, {**new, **users}), renames
        assert sorted(os.listdir(work)) == [".cal.backup.commit", "cal"], renames
        outcomes.append("new" if after == {**new, **users} else "earlier")
        # said where moves were finished: the commit made, 6 - (renames - 1) files left
        left = 6 - (renames - 1) if killed and renames >= 1 else 0
        assert (f"left {left} of them to move" in note) if left else note == "", (renames, note)
        if not killed:
            break
    # every point reached: killed before the commit (the first rename) the earlier set,
    # after it (at each of the 6 moves) the new one, and a run that finished
    assert outcomes == ["earlier"] + ["new"] * 7


def test_store_measurements_analysed_with_a_baseline_are_calibrated_before_it(monkeypatch,
                                                                             tmp_path):
    # `analyze --baseline-loss-factor 0.003 --structure-mass 0.17` (what report advises, to set
    # the measurement beside the raw DEM's particles-only SDC) saved the SDC with the empty
    # coupon's damping taken off; calibrate --store fitted that SDC with an observation model
    # that adds the baseline again (predicted_sdc): counted twice, a fixed baseline
    # over-predicted every point and a fitted one went to about 0. The stored complex power is
    # that before the subtraction: 2 pi Re/Im is the SDC the observation model predicts.
    import pandas as pd

    from pidcore.calibrate import measured_from_store

    re_w, im_w = 0.0491936, 0.160121  # a 200 Hz, 5 g tungsten carbide test's P_c
    raw = 2 * math.pi * re_w / im_w
    # taken off: eta_0 Q_s / Im with Q_s = 1/2 w m_s V^2 = 0.16258 W (0.17 kg, 0.039 m/s)
    subtracted = raw - 2 * math.pi * 0.003 * 0.16258 / im_w
    frame = pd.DataFrame({
        "source": ["with.uff", "without.uff"],
        "frequency_hz": [200.0, 400.0], "acceleration_g": [5.0, 5.0],
        "fill_percent": [20.0, 20.0], "sdc": [subtracted, 2.22], "sdc_stderr": [0.69, 0.77],
        "complex_power_real_w": [re_w, 0.0305], "complex_power_imag_w": [im_w, 0.0863],
        "parameters_json": [json.dumps({"baseline_loss_factor": 0.003,
                                        "structure_mass_kg": 0.17}),
                            json.dumps({"baseline_loss_factor": 0.0})]})
    monkeypatch.setattr(Store, "list_analyses", lambda self: frame)
    notes: list[str] = []
    points = {p.frequency_hz: p for p in measured_from_store(tmp_path / "s.h5", left_out=notes)}
    # exactly the SDC before the subtraction (rel 1e-12: one division and product)
    assert points[200.0].sdc == pytest.approx(raw, rel=1e-12)
    assert points[200.0].sdc != pytest.approx(subtracted, rel=1e-3)  # 0.0319 apart
    assert points[200.0].sdc_stderr == pytest.approx(0.69)
    # a record analysed without a baseline keeps its stored SDC, whatever its P_c says
    assert points[400.0].sdc == pytest.approx(2.22, rel=1e-12)
    (note,) = notes
    assert note.startswith(f"with.uff: analysed with the empty coupon's damping "
                           f"(baseline_loss_factor, SDC {raw - subtracted:.3g}) taken off")
    assert f"{raw:.4g} (not {subtracted:.4g})" in note


def test_a_calibration_records_the_table_it_was_fitted_to_in_its_files_and_store(
        capsys, tmp_path, tiny_store):
    # calibration.json's settings named the DEM cache but not the --data table, nor did
    # summary.md or the store's entry: a calibration did not lead back to its tests
    import hashlib

    from pidcore.calibrate.persist import calibration_key, stored_settings

    table = _table(tmp_path)
    out = tmp_path / "out"
    # a discrepancy no other test of this module's store fits: the entry is this test's own
    assert main(["calibrate", "--data", str(table), "--fit", "fixture_mass_kg",
                 "--discrepancy", "0.25", "--dem-store", str(tiny_store), "--out", str(out),
                 *TINY]) == 0
    key = re.search(r"saved calibration (cal_[0-9a-f]{16})", capsys.readouterr().out).group(1)
    sha256 = hashlib.sha256(table.read_bytes()).hexdigest()
    measured = [{"kind": "table", "source": str(table), "points": 3, "sha256": sha256}]
    document = json.loads((out / "calibration.json").read_text())
    assert document["settings"]["measured"] == measured
    said = f"Measured: 3 load case(s) of table {table} (sha256 {sha256})."
    assert said in (out / "summary.md").read_text()
    assert said in (out / "summary.html").read_text()
    assert f"# {said}" in (out / "calibrated_specimen.toml").read_text()
    listing = Store(tiny_store).list_calibrations().set_index("key")
    assert listing.loc[key, "measured_source"] == str(table)
    assert listing.loc[key, "measured_sha256"] == sha256
    assert stored_settings(listing.loc[key, "parameters_json"])["measured"] == measured
    # and `pidcore store list`, whose calibrations showed neither (the README says it does)
    assert main(["store", "list", "--store", str(tiny_store), "--section", "calibrations",
                 "--json"]) == 0
    (row,) = [r for r in json.loads(capsys.readouterr().out)["calibrations"]
              if r["key"] == key]
    assert (row["measured_source"], row["measured_sha256"]) == (str(table), sha256)
    # where the tests were read is not what the calibration is: the same fit of the table
    # moved elsewhere (or saved before this was recorded) keeps its key
    moved = {**document, "settings": {k: v for k, v in document["settings"].items()
                                      if k != "measured"}}
    assert calibration_key(document) == calibration_key(moved)


def test_a_store_calibration_records_the_store_and_the_analyses_it_pooled(capsys, tmp_path,
                                                                         tiny_store):
    # of a --store calibration neither the measurement store nor which analyses it fitted
    # were recorded; the one left out as implausible is not among them
    from pidcore.calibrate.persist import stored_settings

    store = _store_with_an_implausible_record(tmp_path, capsys)
    analyses = Store(store).list_analyses()
    good = [k for k, source in zip(analyses["key"], analyses["source"], strict=True)
            if source.endswith("good_fill50_acrylic.csv")]
    out = tmp_path / "out"
    assert main(["calibrate", "--store", str(store), "--fit", "fixture_mass_kg",
                 "--discrepancy", "0.25", "--dem-store", str(tiny_store), "--out", str(out),
                 *TINY]) == 0
    key = re.search(r"saved calibration (cal_[0-9a-f]{16})", capsys.readouterr().out).group(1)
    measured = [{"kind": "store", "source": str(store), "points": 1, "analyses": good}]
    assert len(good) == 1
    assert json.loads((out / "calibration.json").read_text())["settings"]["measured"] == \
        measured
    assert (f"Measured: 1 load case(s) of store {store} (1 analyses: {good[0]})."
            in (out / "summary.md").read_text())
    listing = Store(tiny_store).list_calibrations().set_index("key")
    assert listing.loc[key, "measured_source"] == str(store)
    assert stored_settings(listing.loc[key, "parameters_json"])["measured"] == measured


def test_the_out_files_say_the_notes_in_the_commands_words(capsys, tmp_path, tiny_store):
    # the command printed "widen the prior (--prior fixture_mass_kg=LOW:HIGH)" while
    # summary.md, summary.html and the calibrated file's header of the same run said
    # "(priors=fixture_mass_kg=LOW:HIGH)", a keyword the command line has not
    out = tmp_path / "out"
    # a fixture of at least 1 kg where the data want ~0.29 kg: the posterior piles at 1
    assert main(["calibrate", "--data", str(_table(tmp_path)), "--fit", "fixture_mass_kg",
                 "--prior", "fixture_mass_kg=1:2", "--discrepancy", "0.25",
                 "--dem-store", str(tiny_store), "--out", str(out), *TINY]) == 0
    err = capsys.readouterr().err
    assert "(--prior fixture_mass_kg=LOW:HIGH)" in err
    for name in ("summary.md", "summary.html", "calibrated_specimen.toml"):
        text = (out / name).read_text()
        assert "(--prior fixture_mass_kg=LOW:HIGH)" in text and "priors=" not in text, name
    # the document keeps the library's words, as the store keeps it (its key covers them)
    notes = json.loads((out / "calibration.json").read_text())["notes"]
    assert any("(priors=fixture_mass_kg=LOW:HIGH)" in note for note in notes)


def _stand_in_outputs(monkeypatch, during_build=lambda: None) -> None:
    """write_outputs with each output a stand-in text (what the files hold is not what the
    folder tests test); ``during_build`` is called while the figures are drawn, mid-build."""
    import pidcore.calibrate.outputs as outputs

    monkeypatch.setattr(outputs, "document_json", lambda document: "calibration.json")
    for name in ("specimen_text", "summary_markdown", "summary_html"):
        monkeypatch.setattr(outputs, name, lambda result, name=name: name)

    def plot(result, path):
        during_build()
        Path(path).write_text("figure")
    for name in ("plot_predictions", "plot_pairs"):
        monkeypatch.setattr(outputs, name, plot)


def test_an_out_that_links_to_a_folder_keeps_the_link_and_its_folder_gets_the_outputs(
        tmp_path, monkeypatch):
    # `ln -s elsewhere/cal cal; pidcore calibrate --out cal` built the outputs beside the
    # link, and a link to a folder yet to be made was replaced by a real folder: now as
    # report --out and model --out, the link stays and its folder gets them, built beside it
    from types import SimpleNamespace

    from pidcore.calibrate import write_outputs

    links, elsewhere = tmp_path / "links", tmp_path / "elsewhere"
    links.mkdir()
    elsewhere.mkdir()
    seen = []
    _stand_in_outputs(monkeypatch, lambda: seen.append(sorted(os.listdir(links))))
    outputs = ["calibration.json", "calibrated_specimen.toml", "summary.md", "summary.html",
               "predictions.png", "posterior_pairs.png"]
    link = links / "cal"
    link.symlink_to(Path("..") / "elsewhere" / "cal")  # relative, as ln -s writes it
    for run in ("a folder yet to be made", "an existing folder with a user's file"):
        paths = write_outputs(SimpleNamespace(full_document=dict, notes=[]), link)
        assert link.is_symlink() and link.readlink() == Path("..") / "elsewhere" / "cal", run
        assert sorted(p.name for p in (elsewhere / "cal").iterdir()) == sorted(
            outputs + (["notes.txt"] if run.endswith("file") else [])), run
        assert paths == [link / name for name in outputs]  # as the user named it
        (elsewhere / "cal" / "notes.txt").write_text("a user's")
    assert (elsewhere / "cal" / "notes.txt").read_text() == "a user's"
    # nothing built beside the link while the figures were drawn, nor left there after
    assert seen == [["cal"]] * 4 and os.listdir(links) == ["cal"]
    assert os.listdir(elsewhere) == ["cal"]


def test_an_out_that_links_to_a_folder_on_another_file_system_gets_the_outputs(
        tmp_path, monkeypatch):
    # a link to a folder on another disk: the files built beside the link could not be
    # renamed into it (OSError: Invalid cross-device link, a traceback after the DEM runs)
    import tempfile
    from types import SimpleNamespace

    from pidcore.calibrate import write_outputs

    shm = Path("/dev/shm")
    if not shm.is_dir() or shm.stat().st_dev == tmp_path.stat().st_dev:
        pytest.skip("no second file system (/dev/shm) here to put the link's folder on")
    _stand_in_outputs(monkeypatch)
    with tempfile.TemporaryDirectory(dir=shm) as other:
        real = Path(other) / "cal"
        real.mkdir()
        link = tmp_path / "cal"
        link.symlink_to(real)
        write_outputs(SimpleNamespace(full_document=dict, notes=[]), link)
        assert link.is_symlink() and len(os.listdir(real)) == 6
        assert os.listdir(tmp_path) == ["cal"] and os.listdir(other) == ["cal"]


def test_a_disk_that_fills_while_the_outputs_are_written_is_one_line_and_keeps_the_earlier_ones(
        capsys, tmp_path, tiny_store, monkeypatch):
    # a full disk (ENOSPC) or quota (EDQUOT) while the figures were written ended in an
    # OSError traceback after the DEM runs and the fit: now one line naming the folder and
    # the file, exit 2, the folder's earlier outputs and a user's file as they were, and
    # nothing built left beside it
    import errno

    import pidcore.calibrate.outputs as outputs

    out = tmp_path / "cal"
    out.mkdir()
    earlier = {"calibration.json": b"{}", "summary.md": b"the earlier calibration's",
               "notes.txt": b"a user's"}
    for name, data in earlier.items():
        (out / name).write_bytes(data)

    def full(result, path):
        Path(path).write_bytes(b"\x89PNG half")  # the disk filled mid-file
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))

    monkeypatch.setattr(outputs, "plot_predictions", full)
    code = main(["calibrate", "--data", str(_table(tmp_path)), "--fit", "fixture_mass_kg",
                 "--discrepancy", "0.2", "--dem-store", str(tiny_store), "--out", str(out),
                 *TINY])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert re.fullmatch(
        rf"pidcore calibrate: error: {re.escape(str(out))}: the calibration's outputs could "
        r"not be written \(No space left on device: \S+/predictions\.png\); "
        rf"{re.escape(str(out))} unchanged \(written whole or not at all\)\n", err), err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == earlier
    assert sorted(os.listdir(tmp_path)) == ["cal", "m.csv"]
