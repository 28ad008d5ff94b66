"""``pidcore calibrate``: priors outside a parameter's physical domain, whole-number fields,
measurements of another specimen and too few cases for leave-one-out are refused up front in
one line naming the option; Ctrl-C says what it kept; calibration.json's units are those of
the parameters fitted."""

from __future__ import annotations

import dataclasses
import importlib
import math
from pathlib import Path

import numpy as np
import pytest

from pidcore.calibrate import MeasuredPoint, calibrate
from pidcore.calibrate.calibrate import CalibrationResult, base_specimen
from pidcore.calibrate.data import check_enough_points
from pidcore.calibrate.parameters import build_specs, field_unit
from pidcore.calibrate.runner import run_requests
from pidcore.cli import main
from pidcore.errors import ParameterError
from pidcore.specimen import paper_specimen
from pidcore.store import Store

HEADER = "frequency_hz,acceleration_g,fill_percent,sdc\n"
ROWS = "500,5,50,0.6\n1000,5,50,0.6\n500,1,50,0.2\n"
# the module, not the function pidcore.calibrate exports under its name
calibrate_module = importlib.import_module("pidcore.calibrate.calibrate")
TINY = ["--cells", "2", "--steady-cycles", "10", "--workers", "1", "--no-progress"]


def _table(tmp_path: Path, text: str = HEADER + ROWS, name: str = "m.csv") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _refused(capsys, tmp_path: Path, argv: list[str], *words: str) -> str:
    """Exit 2, one line holding ``words``, no DEM store and no --out folder made."""
    store = tmp_path / "dem.h5"
    out = tmp_path / "out"
    code = main(["calibrate", *argv, "--dem-store", str(store), "--out", str(out), *TINY])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1, err
    for word in words:
        assert word in err, err
    # refused before any DEM run, and before the output folder was made
    assert not store.exists() and not out.exists()
    return err


@pytest.mark.parametrize("prior, words", [
    # a negative loss factor was fitted and reported (a negative predicted SDC)
    ("baseline_loss_factor=-0.5:-0.1", ("baseline_loss_factor=-0.5", "expected >= 0")),
    # a negative fixture mass ran the whole fit, then failed writing --out blaming the
    # bundled specimen file, with an empty folder left behind
    ("fixture_mass_kg=-1:-0.5", ("fixture_mass_kg=-1", "expected >= 0 kg")),
    # a range reaching below 0 was accepted silently
    ("fixture_mass_kg=-1:0.5", ("fixture_mass_kg=-1", "expected >= 0 kg")),
])
def test_an_observation_prior_outside_its_domain_is_refused_naming_it(capsys, tmp_path, prior,
                                                                      words):
    err = _refused(capsys, tmp_path, ["--data", str(_table(tmp_path)), "--prior", prior],
                   f"--prior {prior}", *words)
    assert "paper_coupon.toml" not in err  # the prior's fault, not the specimen file's


@pytest.mark.parametrize("fit, prior, words", [
    ("friction", "friction=-0.1:0.5", ("friction=-0.1", "sliding_friction: expected >= 0")),
    ("restitution", "restitution=0.5:1.2", ("restitution=1.2", "expected 0 < e <= 1")),
    # the particle (radius 1.25 mm) does not fit a 2 mm cell: failed mid-run, blaming the
    # bundled specimen file
    ("cell.inscribed_diameter_m", "cell.inscribed_diameter_m=2.0e-3:2.6e-3",
     ("cell.inscribed_diameter_m=0.002", "does not fit")),
])
def test_a_dem_prior_outside_its_domain_is_refused_before_any_run(capsys, tmp_path, fit, prior,
                                                                  words):
    err = _refused(capsys, tmp_path, ["--data", str(_table(tmp_path)), "--fit", fit,
                                      "--prior", prior], f"--prior {prior}", *words)
    assert "paper_coupon.toml" not in err


def test_default_bounds_outside_the_domain_name_them_and_the_way_out():
    # 0.5x the cell diameter holds no particle: the default bounds are said, with --prior
    with pytest.raises(ParameterError) as refused:
        build_specs(["cell.inscribed_diameter_m"])
    text = str(refused.value)
    assert "the default prior bounds cell.inscribed_diameter_m=" in text
    assert "priors=cell.inscribed_diameter_m=LOW:HIGH" in text and "does not fit" in text


def test_a_prior_box_is_checked_at_its_corners():
    # each range alone holds a valid specimen (a 1.1 mm particle fits a 2.3 mm cell), but the
    # corner of the largest particle in the smallest cell does not
    priors = ["particles.radius_m=1e-3:1.1e-3", "cell.inscribed_diameter_m=2.3e-3:3e-3"]
    fit = ["particles.radius_m", "cell.inscribed_diameter_m"]
    build_specs(fit, priors)  # every corner valid
    wider = ["particles.radius_m=1e-3:1.2e-3", priors[1]]
    with pytest.raises(ParameterError, match=r"priors=particles.radius_m=1e-3:1.2e-3; priors="
                                             r"cell.inscribed_diameter_m=2.3e-3:3e-3: the prior "
                                             r"corner particles.radius_m=0.0012, "
                                             r"cell.inscribed_diameter_m=0.0023 is outside"):
        build_specs(fit, wider)


def test_a_static_friction_range_below_the_sliding_friction_is_refused():
    # static >= sliding (the specimen file's rule): below it a value is taken as the sliding
    # friction, so such a range ran a design whose runs were all alike
    paper = paper_specimen().pairs  # sliding friction 0.096 particle-particle, 0.14 wall
    assert (paper.particle_particle.sliding_friction, paper.particle_wall.sliding_friction) \
        == (0.096, 0.14)
    with pytest.raises(ParameterError, match=r"^priors=static_friction_pw=0.01:0.12: static "
                                             r"friction below the sliding friction \(at least "
                                             r"0.14 particle-wall\)"):
        build_specs(["static_friction_pw"], ["static_friction_pw=0.01:0.12"])
    # with friction fitted, its lower bound is the floor
    with pytest.raises(ParameterError, match="at least 0.3 particle-particle, 0.3 particle"):
        build_specs(["friction", "static_friction"],
                    ["friction=0.3:0.5", "static_friction=0.1:0.3"])
    build_specs(["static_friction_pp"], ["static_friction_pp=0.01:0.12"])  # reaches above
    build_specs(["static_friction"])  # the default bounds (0.1..1.0) reach above both


@pytest.mark.parametrize("name", ["static_friction_pw", "pairs.particle_wall.static_friction"])
def test_a_static_friction_follows_one_rule_under_either_name(name):
    # pairs.particle_wall.static_friction=0.1:0.3 was refused as outside its physical domain
    # while static_friction_pw=0.1:0.3 was fitted, its points below 0.14 taken as 0.14 (the
    # documented rule): one parameter, one rule, the documented one
    from pidcore.calibrate.runner import specimen_with

    spec = next(s for s in build_specs([name], [f"{name}=0.1:0.3"]) if s.name == name)
    assert (spec.low, spec.high) == (0.1, 0.3)
    paper = paper_specimen()
    wall = [specimen_with(paper, {name: v}).pairs.particle_wall.static_friction
            for v in (0.1, 0.3)]
    assert wall == [0.14, 0.3]  # below the sliding friction 0.14: taken as it
    # a range wholly below it changes no run: refused alike under both names
    with pytest.raises(ParameterError, match=rf"^priors={name}=0.05:0.12: static friction "
                                             r"below the sliding friction \(at least 0.14"):
        build_specs([name], [f"{name}=0.05:0.12"])
    # a sliding friction set by dotted path in the same call is the floor
    both = specimen_with(paper, {name: 0.1, "pairs.particle_wall.sliding_friction": 0.05})
    assert both.pairs.particle_wall.static_friction == 0.1


def test_a_design_point_outside_the_domain_names_it_not_the_specimen_file():
    # a constraint the corners cannot see would fail inside the design: the design point is
    # named, not the bundled specimen file
    specimen = paper_specimen()
    (spec,) = build_specs(["cell.inscribed_diameter_m"], ["cell.inscribed_diameter_m=3e-3:4e-3"],
                          discrepancy=0.2)
    point = MeasuredPoint(500, 5, 50, 0.6)
    from pidcore.dem.simulate import DemConfig

    with pytest.raises(ParameterError) as refused:
        calibrate_module._requests([point], [spec], np.array([[2.1e-3]]), DemConfig(), specimen)
    text = str(refused.value)
    assert text.startswith("fit/priors: the design point cell.inscribed_diameter_m=0.0021 ")
    assert "does not fit" in text and specimen.source not in text


@pytest.mark.parametrize("field", ["cell.count", "particles.count_per_cell"])
def test_a_whole_number_field_cannot_be_fitted(capsys, tmp_path, field):
    argv = ["--data", str(_table(tmp_path)), "--fit", field]
    if field == "particles.count_per_cell":  # the paper's coupon states a fill, not a count
        spec = tmp_path / "counted.toml"
        text = paper_specimen().to_toml().replace("[particles]\n",
                                                  "[particles]\ncount_per_cell = 10\n")
        spec.write_text(text)
        argv += ["--specimen", str(spec)]
    _refused(capsys, tmp_path, argv, f"--fit {field}", "whole-number field cannot be fitted")


def test_rows_of_another_specimen_are_refused(capsys, tmp_path):
    # they were fitted against the paper's coupon with no note
    table = _table(tmp_path, "frequency_hz,acceleration_g,fill_percent,sdc,specimen\n"
                             "500,5,50,0.6,someone_elses_coupon\n1000,5,50,0.6,\n"
                             "500,1,50,0.2,someone_elses_coupon\n")
    _refused(capsys, tmp_path, ["--data", str(table)],
             "m.csv lines 2, 4 name specimen 'someone_elses_coupon'", "not 'paper_coupon'")
    # with --specimen: rows naming another one are refused, its own name is its (and its
    # calibrated file's name is the specimen it was calibrated from)
    mine = tmp_path / "my.toml"
    mine.write_text(paper_specimen().to_toml().replace('name = "paper_coupon"',
                                                       'name = "my_coupon"'))
    table = _table(tmp_path, "frequency_hz,acceleration_g,fill_percent,sdc,specimen\n"
                             "500,5,50,0.6,my_coupon\n1000,5,50,0.6,other_specimen\n"
                             "500,1,50,0.2,my_coupon_calibrated\n", name="n.csv")
    _refused(capsys, tmp_path, ["--data", str(table), "--specimen", str(mine)],
             "n.csv line 3 name specimen 'other_specimen'", "not 'my_coupon'")
    from pidcore.specimen import load_specimen

    specimen = load_specimen(mine)
    named = [MeasuredPoint(500, 5, 50, 0.6, specimen="my_coupon"),
             MeasuredPoint(500, 1, 50, 0.2, specimen="my_coupon_calibrated"),
             MeasuredPoint(1000, 5, 50, 0.6)]
    assert base_specimen(named, specimen) is specimen
    calibrated = dataclasses.replace(specimen, name="my_coupon_calibrated")
    assert base_specimen(named, calibrated) is calibrated
    # a store's load cases have no rows: they are counted
    stored = [MeasuredPoint(500, 5, 50, 0.6, specimen="steel_6mm_b", source="s.h5"),
              MeasuredPoint(500, 1, 50, 0.2, specimen="steel_6mm_b", source="s.h5")]
    with pytest.raises(ParameterError, match=r"^2 measured load case\(s\) of s.h5 name specimen "
                                             r"'steel_6mm_b', not 'my_coupon', the specimen "
                                             r"calibrated"):
        base_specimen(stored, specimen)


def test_a_calibrated_file_calibrated_again_is_still_of_the_specimen_tested(tmp_path):
    # trial 14h: calibrating alumina_6mm_trial_calibrated.toml again wrote
    # alumina_6mm_trial_calibrated_calibrated, and calibrating that one refused the tests of
    # alumina_6mm_trial ("--data rows name specimen 'alumina_6mm_trial', not '..._calibrated_
    # calibrated'"; --store: "no measurement of specimen ..."): one suffix was taken off
    from pidcore.calibrate.data import points_for_specimen
    from pidcore.calibrate.parameters import parameter_spec
    from pidcore.specimen import calibrated_name, uncalibrated_name

    assert uncalibrated_name("my_coupon_calibrated_calibrated") == "my_coupon"
    assert uncalibrated_name("my_coupon") == "my_coupon"
    # the library's name and the app's download name of the calibrated file come from here
    assert calibrated_name("my_coupon") == "my_coupon_calibrated"
    assert calibrated_name("my_coupon_calibrated_calibrated") == "my_coupon_calibrated"
    mine = dataclasses.replace(paper_specimen(), name="my_coupon")
    tested = [MeasuredPoint(500, 5, 50, 0.6, specimen="my_coupon"),
              MeasuredPoint(1000, 5, 50, 0.6, specimen="my_coupon_calibrated")]
    twice = dataclasses.replace(mine, name="my_coupon_calibrated_calibrated")  # an old file's
    assert base_specimen(tested, twice) is twice
    assert points_for_specimen(tested, twice) == (tested, "")
    # calibrating a calibrated file names the result after the specimen tested, once
    once = dataclasses.replace(mine, name="my_coupon_calibrated")
    specs = [parameter_spec("fixture_mass_kg", once)]
    result = CalibrationResult(
        specimen=once, specs=specs, samples=np.zeros((1, 1)),
        parameters={"fixture_mass_kg": {"median": 0.05, "low95": 0.04, "high95": 0.06}},
        correlations=[], predictions=[], loo=None, fixed={"baseline_loss_factor": 0.0},
        design=np.zeros((1, 0)), observations=[], runs={}, settings={})
    calibrated = result.calibrated_specimen()
    assert calibrated.name == "my_coupon_calibrated"
    assert calibrated.coupon.fixture_mass_kg == 0.05


def test_loo_says_it_needs_one_case_more_than_parameters(capsys, tmp_path):
    # 3 cases given, 3 fitted quantities: it said "2 measured load case(s) ... give at least
    # 3 load cases" although 3 were given
    _refused(capsys, tmp_path, ["--data", str(_table(tmp_path)), "--cross-validate", "loo"],
             "leave-one-out fits each fold on 2 of the 3 measured load case(s)",
             "at least 4 load cases (parameters + 1)")
    points = [MeasuredPoint(f, 5, 50, 0.6) for f in (100, 200, 300)]
    check_enough_points(points, ["a", "b"], leave_one_out=True)  # 2 per fold fit 2


def test_interrupt_says_how_many_runs_are_kept_where_and_that_a_rerun_resumes(
        capsys, tmp_path, monkeypatch):
    # it printed only the generic "no store write was left half-done"
    store = tmp_path / "dem.h5"

    def interrupted_after_one(requests, **kw):
        def stop(key):
            raise KeyboardInterrupt

        return run_requests(requests, **kw, on_done=stop)

    monkeypatch.setattr(calibrate_module, "run_requests", interrupted_after_one)
    argv = ["calibrate", "--data", str(_table(tmp_path)), "--fit", "fixture_mass_kg",
            "--discrepancy", "0.2", "--dem-store", str(store), *TINY]
    assert main(argv) == 130
    err = capsys.readouterr().err.strip()
    assert err == (f"pidcore calibrate: interrupted; 1 DEM run(s) finished before the interrupt "
                   f"are saved in {store} (1 of the calibration's 3 stored now); re-run the same "
                   "command to resume: stored runs are reused, the other 2 computed"), err
    assert len(Store(store).list_dem_runs()) == 1
    monkeypatch.undo()
    points = [MeasuredPoint(500, 5, 50, 0.6), MeasuredPoint(1000, 5, 50, 0.6),
              MeasuredPoint(500, 1, 50, 0.2)]
    again = calibrate(points, fit=["fixture_mass_kg"], store_path=store, discrepancy=0.2,
                      cells=2, steady_cycles=10, workers=1, progress=False)
    assert (again.runs["computed"], again.runs["cached"]) == (2, 1)


def test_units_are_those_of_the_fitted_and_fixed_parameters():
    # a fixed table: rolling_friction and particles.radius_m had none, and parameters that
    # were not fitted were listed
    specimen = paper_specimen()
    specs = build_specs(["rolling_friction", "particles.radius_m"], specimen=specimen)
    result = CalibrationResult(
        specimen=specimen, specs=specs, samples=np.zeros((1, len(specs))), parameters={},
        correlations=[], predictions=[], loo=None,
        fixed={"fixture_mass_kg": 0.0, "baseline_loss_factor": 0.0}, design=np.zeros((1, 2)),
        observations=[], runs={}, settings={})
    units = result.units()
    assert units["rolling_friction"] == "-" and units["particles.radius_m"] == "m"
    assert units["model_discrepancy"] == "-"
    assert units["fixture_mass_kg"] == "kg" and units["baseline_loss_factor"] == "-"  # fixed
    assert units["frequency_hz"] == "Hz" and units["low95_j"] == "J"
    assert "friction" not in units and "restitution" not in units
    # one rule for every specimen field: the unit its name ends in
    assert [field_unit(p) for p in ("cell.wall_youngs_modulus_pa", "particles.density_kg_m3",
                                    "coupon.mass_kg", "cell.height_m",
                                    "particles.poisson_ratio", "particles.fill_percent")] \
        == ["Pa", "kg/m^3", "kg", "m", "-", "%"]


def test_an_interrupt_names_a_store_that_never_existed_not_created(tmp_path):
    # "no DEM run was started; dem.h5 unchanged" of a store the calibration would have made
    from pidcore.calibrate.runner import RunTally

    store = tmp_path / "dem.h5"
    tally = RunTally(store)
    assert tally.interrupted() == f"no DEM run was started; {store} not created"
    tally.design(["a", "b"])
    assert tally.interrupted() == f"no DEM run finished in this call; {store} not created"
    Store(store).add_dem_run("other", {"sdc": 0.1})
    assert tally.interrupted().startswith(f"no DEM run finished in this call; {store} holds 0 ")
    assert RunTally(store).interrupted() == f"no DEM run was started; {store} unchanged"


def test_outputs_that_cannot_be_made_leave_no_folder(tmp_path):
    from pidcore.calibrate.outputs import write_outputs

    class Broken:
        def full_document(self):
            raise ParameterError("cannot be written")

    out = tmp_path / "out"
    with pytest.raises(ParameterError):
        write_outputs(Broken(), out)
    assert not out.exists()


def test_a_ctrl_c_while_the_outputs_are_written_leaves_out_as_it_was_and_says_so(
        capsys, tmp_path, monkeypatch):
    # ~4 s into a tiny run (the figures) it said the generic "no store write was left
    # half-done (an output folder may hold part of this run's files)", and --out held a
    # calibration.json without figures: a folder that looked finished
    import pidcore.calibrate.outputs as outputs

    store, out = tmp_path / "dem.h5", tmp_path / "out"
    argv = ["calibrate", "--data", str(_table(tmp_path)), "--fit", "fixture_mass_kg",
            "--discrepancy", "0.2", "--dem-store", str(store), "--out", str(out), *TINY]
    plot_pairs = outputs.plot_pairs

    def interrupted(*args, **kwargs):  # the last figure: every other file made before it
        raise KeyboardInterrupt

    monkeypatch.setattr(outputs, "plot_pairs", interrupted)
    assert main(argv) == 130
    err = capsys.readouterr().err.strip()
    assert err == (f"pidcore calibrate: interrupted; 3 DEM run(s) finished before the interrupt "
                   f"are saved in {store} (3 of the calibration's 3 stored now); a re-run of "
                   f"the same command computes no DEM run again; the calibration was not saved "
                   f"in {store}; {out} not created"), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dem.h5", "m.csv"]  # no temp folder
    assert Store(store).list_calibrations().empty  # Ctrl-C commits nothing of the result
    # a folder from an earlier run keeps its files, none of them half-replaced
    monkeypatch.setattr(outputs, "plot_pairs", plot_pairs)
    assert main(argv) == 0
    (out / "calibration.json").write_text("earlier")
    monkeypatch.setattr(outputs, "plot_pairs", interrupted)
    assert main(argv) == 130
    assert (out / "calibration.json").read_text() == "earlier"
    assert len(list(out.iterdir())) == 6 and len(list(tmp_path.iterdir())) == 3


def test_a_fill_the_dem_cannot_run_is_refused_naming_its_line(capsys, tmp_path):
    # a fraction typed for a percentage (0.5 for 50 %): "fill 0.5 % of 22 particles rounds to
    # none", naming neither the table nor the row, after the DEM store was opened
    table = _table(tmp_path, HEADER + "500,5,50,0.6\n1000,5,0.5,0.6\n500,1,50,0.2\n")
    _refused(capsys, tmp_path, ["--data", str(table)],
             "m.csv, line 3 (1000 Hz, 5 g, 0.5 %, acrylic): fill_percent: fill 0.5 % of 22 "
             "particles rounds to none")


@pytest.mark.parametrize("option, value", [
    ("--workers", "0"), ("--workers", "-2"), ("--steady-cycles", "0"), ("--design-size", "-3")])
def test_a_count_below_one_is_refused_as_dem_sweep_refuses_it(capsys, tmp_path, option, value):
    # `calibrate --workers 0` (or -2) ran without a word, where `dem sweep --workers 0` is
    # refused; `--steady-cycles 0` named the library's field ("steady_cycles: expected >= 1")
    store = tmp_path / "dem.h5"
    with pytest.raises(SystemExit) as stop:  # argparse's refusal, as from the shell
        main(["calibrate", "--data", str(_table(tmp_path)), "--dem-store", str(store),
              *TINY[:-3], option, value])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and f"argument {option}: expected a whole number >= 1, got " \
        f"'{value}'" in err and len(err.strip().splitlines()) == 1
    assert not store.exists()


def test_an_sdc_in_percent_is_refused_naming_its_line(capsys, tmp_path):
    # 42 typed for 0.42 (an SDC in %) ran the whole calibration, exit 0, and only said the
    # posterior piled against a prior bound. The bound is the analysis' plausibility check's
    # (pidcore.compare.plausibility.sdc_bound): the paper coupon's 46.8 g of acrylic at 50 %
    # on its 22.2 g can dissipate at most SDC 8 m_p/m_s = 16.9
    table = _table(tmp_path, HEADER + "500,5,50,0.6\n1000,5,50,42\n500,1,50,0.2\n")
    _refused(capsys, tmp_path, ["--data", str(table)],
             "m.csv, line 3: sdc 42 is above 16.91 (particles of 46.8 g on a 22.2 g structure "
             "can dissipate at most SDC 8 m_p/m_s = 16.9")


def test_a_field_of_value_zero_asks_for_its_prior_by_name(capsys, tmp_path):
    # the paper's particle-wall rolling friction is 0: no 0.5x..1.5x default range, and the
    # refusal said "bounds nan:nan are empty (expected LOW < HIGH)", naming no way out
    field = "pairs.particle_wall.rolling_friction"
    assert paper_specimen().pairs.particle_wall.rolling_friction == 0
    err = _refused(capsys, tmp_path, ["--data", str(_table(tmp_path)), "--fit", field],
                   f"give --prior {field}=LOW:HIGH", "no default prior bounds")
    assert "nan" not in err
    with pytest.raises(ParameterError, match=rf"give priors={field}=LOW:HIGH$"):
        build_specs([field], [])
    # the way out it names works: with a prior, the specs build
    (spec,) = [s for s in build_specs([field], [f"{field}=0:0.1"]) if s.name == field]
    assert (spec.low, spec.high) == (0.0, 0.1)


@pytest.mark.parametrize(("keywords", "said"), [
    ({"sdc": float("nan")}, "sdc nan: expected a finite number"),
    ({"sdc_stderr": -0.01}, "sdc_stderr -0.01: expected >= 0"),
    ({"fill_percent": 0.0}, "fill_percent 0: expected a fill in (0, 100] %"),
    ({"frequency_hz": float("inf")}, "frequency_hz inf: expected a finite number"),
    ({"acceleration_g": -5.0}, "acceleration_g -5: expected > 0"),
    ({"sdc": 42.0}, "sdc 42 is above 6.283 (2 pi, a loss factor of 1: more dissipated per "
                    "radian than the coupon stores; Table 3's largest is 0.88); expected the "
                    "SDC as a ratio; was it %?"),
    ({"sdc": "0.6"}, "sdc: expected a number, got '0.6'"),
])
def test_a_scripts_measured_point_is_held_to_the_tables_rules(tmp_path, keywords, said):
    # `pidcore calibrate --data` refused these rows; MeasuredPoint(..., sdc=nan) was fitted
    # (a NaN likelihood) and sdc_stderr=-0.01 weighed the point as if measured exactly
    point = {"frequency_hz": 500.0, "acceleration_g": 5.0, "fill_percent": 50.0, "sdc": 0.6,
             "sdc_stderr": 0.01}
    with pytest.raises(ParameterError) as refused:
        MeasuredPoint(**{**point, **keywords})
    assert str(refused.value) == said
    # the table names the row, with the same rule
    column, value = next(iter(keywords.items()))
    table = _table(tmp_path, "frequency_hz,acceleration_g,fill_percent,sdc,sdc_stderr\n"
                   + ",".join(str({**point, column: value}[c]) for c in point) + "\n"
                   "1000,5,50,0.6,0.01\n500,1,50,0.2,0.01\n")
    if column != "sdc" or value != "0.6":  # text is what a table holds
        from pidcore.calibrate import read_measured_table
        from pidcore.errors import InputFileError

        with pytest.raises(InputFileError) as in_table:
            read_measured_table(table)
        if column == "sdc" and value == 42.0:
            # a script's point states no specimen (2 pi); a table's row is of the paper's
            # coupon, whose 46.8 g of acrylic at 50 % on 22.2 g bound the SDC at 16.9
            said = ("sdc 42 is above 16.91 (particles of 46.8 g on a 22.2 g structure can "
                    "dissipate at most SDC 8 m_p/m_s = 16.9, two fully inelastic impacts per "
                    "cycle; Table 3's largest is 0.88); expected the SDC as a ratio; was it %?")
        assert str(in_table.value) == f"{table}, line 2: {said}"


def test_a_negative_measured_sdc_is_refused_in_a_table_and_kept_for_a_synthetic_study(tmp_path):
    # the docs' calibration audit fits noise draws below 0 as they are; a measured table
    # (what `pidcore calibrate --data` reads) without a standard error holds no negative SDC
    from pidcore.calibrate import read_measured_table
    from pidcore.errors import InputFileError

    assert MeasuredPoint(500.0, 5.0, 50.0, -0.01, 0.02).sdc == -0.01
    table = _table(tmp_path, HEADER + "500,5,50,-0.01\n1000,5,50,0.6\n500,1,50,0.2\n")
    with pytest.raises(InputFileError, match=r"m\.csv, line 2: sdc -0\.01: expected >= 0 "
                       r"without an sdc_stderr \(a negative SDC within 3 standard errors of 0 "
                       r"is zero damping measured with noise: give its sdc_stderr\)$"):
        read_measured_table(table)


# (SDC, its stderr, kept): zero damping measured with noise, -0.0569 +- 0.13 (an analysis's,
# 7 dof), was refused by `calibrate --data` and fitted by `calibrate --store`; exactly 3
# stderr below 0 is still noise (pidcore.compare.plausibility.NEGATIVE_WITHIN_STDERRS); beyond
# it, or negative with no stderr, energy created: refused from a table, left out of a store
@pytest.mark.parametrize(("sdc", "stderr", "kept"), [(-0.0569, 0.13, True), (-0.3, 0.1, True),
                                                     (-0.5, 0.1, False), (-0.01, 0.0, False)])
def test_a_table_and_a_store_keep_the_same_negative_sdcs(tmp_path, monkeypatch, sdc, stderr,
                                                          kept):
    import pandas as pd

    from pidcore.calibrate import measured_from_store, read_measured_table
    from pidcore.errors import InputFileError
    from pidcore.store import Store

    table = _table(tmp_path, "frequency_hz,acceleration_g,fill_percent,sdc,sdc_stderr,"
                   f"sdc_stderr_dof\n100,1,50,{sdc},{stderr},7\n500,1,50,0.2,0.01,7\n")
    # the same measurement as a stored analysis: Re P / Im P = SDC / 2 pi
    imag = 0.1
    real = [sdc / (2 * math.pi) * imag, 0.2 / (2 * math.pi) * imag]
    frame = pd.DataFrame({"frequency_hz": [100.0, 500.0], "acceleration_g": [1.0, 1.0],
                          "fill_percent": [50.0, 50.0], "sdc": [sdc, 0.2],
                          "sdc_stderr": [stderr, 0.01], "sdc_stderr_dof": [7.0, 7.0],
                          "complex_power_real_w": real, "complex_power_imag_w": [imag] * 2,
                          "loss_factor": [r / imag for r in real],
                          "source": ["neg.csv", "pos.csv"]})
    monkeypatch.setattr(Store, "list_analyses", lambda self: frame)
    left_out: list[str] = []
    stored = measured_from_store(tmp_path / "s.h5", left_out=left_out)
    if kept:
        (point, _) = read_measured_table(table)
        assert (point.sdc, point.sdc_stderr) == (sdc, stderr)
        assert [(p.sdc, p.sdc_stderr) for p in stored if p.frequency_hz == 100.0] == \
            [(sdc, stderr)]
        assert not left_out
    else:
        with pytest.raises(InputFileError, match=rf"m\.csv, line 2: sdc {sdc}: "):
            read_measured_table(table)
        assert [p.frequency_hz for p in stored] == [500.0]
        assert len(left_out) == 1 and left_out[0].startswith("neg.csv: left out, implausible")


@pytest.mark.parametrize(("keywords", "said"), [
    # ran every DEM run, then "calibration: the posterior is zero everywhere within the bounds"
    ({"discrepancy": float("inf")}, "discrepancy: expected a finite fraction >= 0, got inf"),
    ({"discrepancy_floor": float("inf")},
     "discrepancy_floor: expected a finite SDC >= 0, got inf"),
    ({"seed": -1}, "seed: expected a whole number >= 0, got -1"),  # numpy's, naming nothing
    # numpy's "expected non-negative integer", after every DEM run
    ({"posterior_seed": -1}, "posterior_seed: expected a whole number >= 0, got -1"),
    ({"workers": 0}, "workers: expected a whole number >= 1, got 0"),  # ran; --workers 0 not
    ({"workers": 1.5}, "workers: expected a whole number, got 1.5"),
    ({"priors": "rolling_friction=0:inf"},  # was "are empty"
     "rolling_friction: bounds 0:inf are not finite (expected finite LOW < HIGH)"),
])
def test_calibrate_refuses_what_its_options_refuse_before_any_dem_run(tmp_path, monkeypatch,
                                                                      keywords, said):
    def no_dem_run(*args, **kwargs):
        raise AssertionError("a DEM run was asked for")

    monkeypatch.setattr(calibrate_module, "run_requests", no_dem_run)
    points = [MeasuredPoint(f, a, 50.0, sdc, 0.01)
              for f, a, sdc in ((500, 5, 0.6), (1000, 5, 0.6), (500, 1, 0.2), (100, 5, 0.3))]
    store = tmp_path / "dem.h5"
    with pytest.raises(ParameterError) as refused:
        calibrate(points, fit="rolling_friction", store_path=store, progress=False,
                  **{"workers": 1, **keywords})
    assert str(refused.value) == said
    assert not store.exists()


def test_store_without_the_specimens_measurements_says_why_in_one_sentence(tmp_path):
    # round 17: the left-out note, a sentence of its own, was appended after "; " as it was:
    # "...of an unnamed specimen of them; Not used for steel_6mm (...): ... ." mid-sentence
    from pidcore.cli.calibrate import _store_points
    from pidcore.specimen import load_specimen

    steel = load_specimen(Path(__file__).resolve().parents[1] / "data_samples" / "specimens"
                          / "steel_6mm.toml")
    acrylic = [MeasuredPoint(500, 5, 50, 0.6, material="acrylic", source="s.h5")]
    store = tmp_path / "s.h5"
    left_out: list[str] = []
    with pytest.raises(ParameterError) as raised:
        _store_points(acrylic, steel, store, left_out)
    assert str(raised.value) == (
        f"--store {store}: no measurement of specimen steel_6mm (steel particles) or of an "
        "unnamed specimen of them; not used for steel_6mm (steel particles): 1 measured load "
        "case(s) of acrylic particles")
    assert left_out == []  # refused: nothing said as left out of a calibration


def test_a_mistyped_store_is_named_not_found_and_none_is_created(capsys, tmp_path):
    # `calibrate --store nope.h5` said "nope.h5: no analysed measurements with frequency_hz
    # and sdc", as of an empty store: the user looked for what the store lacked
    missing = tmp_path / "nope.h5"
    assert main(["calibrate", "--store", str(missing), "--dem-store",
                 str(tmp_path / "cal.h5"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err == (f"pidcore calibrate: error: {missing}: store not found; expected the store "
                   "that pidcore analyze saved the measurements in\n")
    assert sorted(tmp_path.iterdir()) == []


def test_calibrate_help_names_every_column_the_data_table_reader_takes(capsys):
    # --help listed the optional columns without sdc_stderr_dof, which the reader takes (and
    # its missing-column error names), so a user could not learn it from the help
    from pidcore.calibrate.data import OPTIONAL_COLUMNS, REQUIRED_COLUMNS
    from pidcore.cli import build_parser

    with pytest.raises(SystemExit):
        build_parser().parse_args(["calibrate", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    listed = help_text[help_text.index("--data TABLE.csv measured SDCs:"):
                       help_text.index("; a row without a material")]
    assert [c for c in (*REQUIRED_COLUMNS, *OPTIONAL_COLUMNS) if c not in listed] == []


def test_calibrate_help_says_the_fewest_cells_it_takes(capsys, tmp_path):
    # --help said "cells per DEM run (default 4)"; --cells 1 was then refused as below 2
    from pidcore.calibrate.calibrate import CALIBRATION_CELLS
    from pidcore.cli import build_parser

    with pytest.raises(SystemExit):
        build_parser().parse_args(["calibrate", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert (f"--cells K cells per DEM run, at least 2: the run's error is their scatter "
            f"(default {CALIBRATION_CELLS})") in help_text
    assert main(["calibrate", "--data", str(tmp_path / "none.csv"), "--cells", "1",
                 "--dem-store", str(tmp_path / "cal.h5")]) == 2
    assert "--cells: expected >= 2" in capsys.readouterr().err


def test_a_dotted_sliding_friction_past_the_static_one_names_the_alias_moving_both():
    # a file without static_friction has it equal to its sliding friction: a dotted sliding
    # friction's default prior (0.5 .. 1.5 x) then passes it, and the refusal only asked for
    # another range, without the alias that moves both (the paper's wall pair: 0.14 static)
    with pytest.raises(ParameterError) as caught:
        build_specs(["pairs.particle_wall.sliding_friction"],
                    ["pairs.particle_wall.sliding_friction=0.1:0.2"])
    message = str(caught.value)
    assert message.startswith("priors=pairs.particle_wall.sliding_friction=0.1:0.2: "
                              "pairs.particle_wall.sliding_friction=0.2 is outside its physical "
                              "domain ([pairs.particle_wall] static_friction: 0.14 is below "
                              "sliding_friction 0.2")
    assert message.endswith("; set pairs.particle_wall.static_friction too (a file without it "
                            "holds its sliding friction there)); give a range inside it, or "
                            "fit friction_pw (sliding and static friction of that pair "
                            "together)")
    # the alias named fits the same range
    build_specs(["friction_pw"], ["friction_pw=0.1:0.2"])


def test_fills_of_the_same_particles_per_cell_are_one_load_case_refused_naming_both_lines(
        capsys, tmp_path, monkeypatch):
    # a table of a load case at 50 % and again at 52 % (both 11 of the paper coupon's 22
    # spheres) ran two bit-identical DEM runs as two load cases, and leave-one-out kept each
    # one's twin in the fit that held it out: 7/7 inside where the outlier alone was out
    def no_dem_run(*args, **kwargs):
        raise AssertionError("a DEM run was asked for")

    monkeypatch.setattr(calibrate_module, "run_requests", no_dem_run)
    table = _table(tmp_path, HEADER + ROWS + "500,5,52,0.6\n")
    _refused(capsys, tmp_path, ["--data", str(table), "--fit", "fixture_mass_kg"],
             "m.csv, lines 2 and 5 (500 Hz, 5 g, 50 %, acrylic; 500 Hz, 5 g, 52 %, acrylic) "
             "state the same load case: fills 50 % and 52 % are both 11 of 22 particles per "
             "cell of specimen paper_coupon, one DEM simulation; give one row per load case")


@pytest.mark.parametrize(("fill", "same"), [(52.0, True), (47.8, True), (47.6, False),
                                            (45.0, False)])
def test_fills_are_one_load_case_exactly_where_they_round_to_one_particle_count(
        tmp_path, monkeypatch, fill, same):
    # 11 of 22 spheres are the fills from 10.5/22 = 47.73 % up (half to even: 10.5 -> 10):
    # 47.8 % is 10.52 -> 11, the same run as 50 %; 47.6 % is 10.47 -> 10, another one
    class DemRunsAsked(Exception):
        pass

    def dem_runs(*args, **kwargs):
        raise DemRunsAsked

    monkeypatch.setattr(calibrate_module, "run_requests", dem_runs)
    points = [MeasuredPoint(500, 5, 50.0, 0.6, 0.01), MeasuredPoint(500, 5, fill, 0.6, 0.01),
              MeasuredPoint(1000, 5, 50.0, 0.6, 0.01)]
    if same:
        with pytest.raises(ParameterError, match=rf"fills 50 % and {fill:g} % are both 11 of "
                                                 "22 particles per cell"):
            calibrate(points, fit="fixture_mass_kg", discrepancy=0.2,
                      store_path=tmp_path / "dem.h5", progress=False, workers=1)
    else:
        with pytest.raises(DemRunsAsked):  # two load cases: on to their DEM runs
            calibrate(points, fit="fixture_mass_kg", discrepancy=0.2,
                      store_path=tmp_path / "dem.h5", progress=False, workers=1)


@pytest.mark.parametrize("fit", ["fixture_mass_kg,coupon.mass_kg", "coupon.mass_kg"])
def test_the_coupon_mass_is_refused_as_a_fit_parameter_naming_the_fixture_mass(
        capsys, tmp_path, fit):
    # fitted beside fixture_mass_kg (or alone) as a DEM parameter, it cost a design of DEM
    # runs that all came out alike, and its posterior was its prior
    _refused(capsys, tmp_path, ["--data", str(_table(tmp_path)), "--fit", fit],
             "fit: coupon.mass_kg cannot be fitted", "coupon + fixture mass", "fixture_mass_kg")


def test_the_coupon_mass_moves_no_particle_and_the_fit_observes_the_start_specimens():
    # the refusal's reason: two coupons of other masses give the bit-identical wall force of
    # the particles (the drive is prescribed), so their observations (Eq. 11) agree exactly;
    # only the Eq. 10 SDC the DEM states, normalised by the vibrated mass, differs
    from pidcore.calibrate.observation import observation_from_run
    from pidcore.dem.persist import dem_run_entry
    from pidcore.dem.simulate import DemConfig, LoadCase, simulate_load_case

    config = DemConfig(cells=2, steady_cycles=10, block_cycles=5, max_transient_cycles=5)
    case = LoadCase(500.0, 5.0, 50.0)
    start = paper_specimen()
    heavier = start.with_values({"coupon.mass_kg": 1.5 * start.coupon.mass_kg})
    entries = [dem_run_entry(simulate_load_case(case, config, specimen=s))
               for s in (start, heavier)]
    assert np.array_equal(entries[0]["arrays"]["wall_force_n"],
                          entries[1]["arrays"]["wall_force_n"])
    assert entries[0]["record"]["sdc"] != entries[1]["record"]["sdc"]
    seen = [observation_from_run(e["record"], e["arrays"], coupon_mass_kg=start.coupon.mass_kg)
            for e in entries]
    assert (seen[0].dissipative_mass_kg, seen[0].reactive_mass_kg) == \
        (seen[1].dissipative_mass_kg, seen[1].reactive_mass_kg)
    # the app's Run goes through the same library function
    import pidcore.calibrate as api

    with pytest.raises(ParameterError, match=r"^fit: coupon\.mass_kg cannot be fitted"):
        api.parse_fit(["fixture_mass_kg", "coupon.mass_kg"], start)


@pytest.mark.parametrize("fit, first, second, field", [
    # restitution_pp overrode restitution's particle-particle value: 54 DEM runs, and a
    # calibrated file whose header said 0.86 for both pairs above a body holding 0.54
    ("restitution,restitution_pp,fixture_mass_kg", "restitution", "restitution_pp",
     "pairs.particle_particle.restitution"),
    # docs/calibration.md calls them the same parameter; the one named last won
    ("static_friction_pw,pairs.particle_wall.static_friction", "static_friction_pw",
     "pairs.particle_wall.static_friction", "pairs.particle_wall.static_friction"),
    ("pairs.particle_wall.restitution,restitution", "pairs.particle_wall.restitution",
     "restitution", "pairs.particle_wall.restitution"),
    ("fixture_mass_kg,coupon.fixture_mass_kg", "fixture_mass_kg", "coupon.fixture_mass_kg",
     "coupon.fixture_mass_kg"),
])
def test_two_fit_names_that_set_one_field_are_refused_naming_both_and_the_field(
        capsys, tmp_path, fit, first, second, field):
    _refused(capsys, tmp_path, ["--data", str(_table(tmp_path)), "--fit", fit],
             f"fit: {first} and {second} both set {field}; fit one of them")


@pytest.mark.parametrize("fit", ["restitution_pp,restitution_pw", "friction,static_friction",
                                 "friction,pairs.particle_wall.static_friction"])
def test_names_that_set_other_fields_are_fitted_together(fit):
    # each pair's own value, and a stick limit above a Coulomb friction (specimen_with's rule:
    # static friction replaces the one friction moved along) are parameters of their own
    import pidcore.calibrate as api

    assert api.parse_fit(fit) == fit.split(",")


@pytest.mark.parametrize("pair, stated", [("particle_particle", 0.9), ("particle_wall", 0.8)])
def test_a_restitutions_default_prior_is_cut_at_one_and_said(pair, stated):
    # 1.5 x 0.9 = 1.35 > 1: --fit pairs.particle_particle.restitution alone was always refused
    # as outside the physical domain, whatever the specimen stated
    name = f"pairs.{pair}.restitution"
    start = paper_specimen().with_values({name: stated})
    spec, _ = build_specs([name], specimen=start)
    assert (spec.low, spec.high) == (0.5 * stated, 1.0)  # exact: min(1.5 x, 1) and 0.5 x
    assert "high cut to 1, the field's limit" in spec.description
    # a field whose 1.5 x stays inside keeps the documented 0.5 .. 1.5 x, said as nothing
    density, _ = build_specs(["particles.density_kg_m3"], specimen=start)
    value = start.particles.density_kg_m3
    assert (density.low, density.high) == (0.5 * value, 1.5 * value)
    assert "cut" not in density.description


def test_sdcs_in_percent_below_the_bound_are_refused_after_the_fit_asking_so(capsys, tmp_path):
    # a tester's own specimen, 1 mm steel spheres at 6-10 % on a 40 g structure: its SDC bound
    # is 2 pi, so SDCs typed in percent (1.7 .. 4.3) passed the plausibility check and were
    # fitted to exit 0 with notes; the DEM reaches ~0.2-0.7 here (> 2 x below each of them)
    specimen = tmp_path / "steel1mm.toml"
    specimen.write_text(STEEL_1MM)
    table = _table(tmp_path, "frequency_hz,acceleration_g,fill_percent,sdc,sdc_stderr,"
                   "sdc_stderr_dof,material\n200,1,6,4.0,0.3,7,steel\n400,3,10,3.7,0.19,7,steel\n"
                   "800,5,10,4.3,0.2,7,steel\n800,12,6,1.7,0.08,7,steel\n")
    out = tmp_path / "out"
    code = main(["calibrate", "--data", str(table), "--specimen", str(specimen),
                 "--dem-store", str(tmp_path / "dem.h5"), "--out", str(out), *TINY])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    last = err.splitlines()[-1]
    assert "m.csv: every measured SDC (1.7 .. 4.3) is above 1" in last, err
    assert "was the SDC given in percent?" in last
    assert not out.exists()


STEEL_1MM = """schema_version = 1
name = "steel1mm_own"

[cell]
shape = "hexagonal"
inscribed_diameter_m = 6.35e-3
height_m = 6.0e-3
count = 286
wall_material = "aluminium_wall"

[coupon]
mass_kg = 0.030
fixture_mass_kg = 0.010
baseline_loss_factor = 0.0

[particles]
material = "steel"
radius_m = 0.5e-3
density_kg_m3 = 7850.0
youngs_modulus_pa = 200e9
poisson_ratio = 0.29
count_per_cell = 12

[pairs.particle_particle]
restitution = 0.9
sliding_friction = 0.3
static_friction = 0.4
rolling_friction = 0.01

[pairs.particle_wall]
restitution = 0.8
sliding_friction = 0.35
static_friction = 0.45
rolling_friction = 0.01
"""


def test_a_fit_that_reaches_sdcs_above_one_is_not_taken_for_percent():
    # the bundled exports' SDCs are 1.1 .. 4.1: real, and fitted where the model reaches them;
    # a point within 2 x of its prediction is one the fit reaches
    from pidcore.calibrate.calibrate import check_not_percent

    points = [MeasuredPoint(frequency_hz=f, acceleration_g=5.0, fill_percent=50.0, sdc=sdc,
                            source="t.csv") for f, sdc in ((100.0, 1.1), (500.0, 4.1))]
    check_not_percent(points, [0.6, 3.0])  # 1.1 / 0.6 = 1.8 < 2: reached
    with pytest.raises(ParameterError, match=r"^t\.csv: .* at least 2\.05 x .* in percent\?"):
        check_not_percent(points, [0.5, 2.0])
    # the same values as fractions of percent are left alone whatever the fit gives
    check_not_percent([dataclasses.replace(p, sdc=p.sdc / 100) for p in points], [1e-4, 1e-4])


def test_a_prediction_above_the_sdc_bound_is_refused_naming_its_case_and_fold():
    # the tester's leave-one-out fold at 200 Hz / 5 g predicted SDC 99.4 beside a band cut at
    # 2 pi, and its RMS of 40.5 was written to the summary, the calibrated file and the store
    # listing with exit 0; an SDC no measurement is kept at (above 2 pi here: the point's
    # specimen is not known) is no prediction
    point = MeasuredPoint(200, 5, 6, 0.269, 0.0144)
    above = {"predicted": 99.4, "low95": -0.043, "high95": 8.6e7}
    with pytest.raises(ParameterError) as refused:
        calibrate_module._row(point, above, fold="leave-one-out")
    message = str(refused.value)
    assert "\n" not in message
    assert "leave-one-out prediction at 200 Hz, 5 g, 6 %" in message
    assert "99.4" in message and "2 pi = 6.283" in message
    # at the bound itself it is a prediction (the bound is the largest SDC kept)
    row = calibrate_module._row(point, {**above, "predicted": 2 * math.pi})
    assert row["error"] == pytest.approx(2 * math.pi - 0.269)
