"""``pidcore dem run`` command line."""

import json
from pathlib import Path

import pytest

from pidcore.cli import main
from pidcore.cli.dem import JSON_KEYS

ARGS = ["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", "50",
        "--cells", "2", "--cycles", "5", "--no-progress"]


def test_json_is_one_document_with_the_agreed_keys(capsys):
    assert main(ARGS + ["--json"]) == 0
    out = capsys.readouterr().out
    doc = json.loads(out)  # exactly one JSON document: json.loads rejects trailing data
    assert set(JSON_KEYS) <= set(doc)
    assert doc["particles_per_cell"] == 11 and doc["cells_simulated"] == 2
    assert doc["sdc"] == pytest.approx(doc["energy_per_cycle_j"] / doc["max_kinetic_energy_j"])
    # every number of the document names its unit (as calibrate --json does): a run total
    # in J beside per-cycle values was readable only from the docstring
    numbers = {k for k, v in doc.items() if isinstance(v, (int, float))
               and not isinstance(v, bool) and k != "seed"}
    assert numbers <= set(doc["units"]), numbers - set(doc["units"])
    assert doc["units"]["sdc"] == "-" and doc["units"]["work_walls_j"] == "J"
    assert doc["units"]["particles_per_cell"] == "1" and doc["units"]["wall_s"] == "s"


def test_readable_summary_names_units_and_particle_count(capsys):
    assert main(ARGS + ["--start", "rest", "--damping-mode", "literal"]) == 0
    out = capsys.readouterr().out
    assert "11 of 22 acrylic particles per cell" in out and "J/cycle" in out and "[-]" in out
    assert "friction stick_slip, normal damping literal, start dense packing rest" in out
    assert "filled" not in out  # 11 of 22 is the 50 % asked


def test_the_summary_says_the_share_a_rounded_count_makes_of_the_cell(capsys):
    # 75 % of 22 is 16.5 particles, run as 16 (round half to even, as the bundled grid):
    # the summary said "fill 75 %" beside 16 of 22 without the 72.7 % they are
    args = [a if a != "50" else "75" for a in ARGS]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "fill 75 % (16 of 22 acrylic particles per cell, 72.7 % filled, reference" in out


def test_one_cell_has_no_standard_error_and_says_why(capsys):
    # one cell printed "+- nan"; its error is from batches of its motion, and --cycles 5 is
    # raised to the least steady window, 20 cycles: 2 batches of 10, fewer than 4
    one = [a if a != "2" else "1" for a in ARGS]
    assert main(one) == 0
    out = capsys.readouterr().out
    assert "nan" not in out and "no standard error (see the note)" in out
    assert "its one cell is one motion" in out
    assert "holds 2 batches of 10 cycles, fewer than the 4" in out


def test_model_options_reach_the_simulation(capsys):
    # the named options land in the result (and so in the store): not silently defaults
    assert main(ARGS + ["--json", "--tangential-model", "coulomb", "--packing", "loose"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["tangential_model"] == "coulomb" and doc["start_packing"] == "loose"
    assert main(ARGS + ["--json"]) == 0
    default = json.loads(capsys.readouterr().out)
    assert default["tangential_model"] == "stick_slip" and default["start_packing"] == "dense"
    assert default["sdc"] != doc["sdc"]  # a different model gives a different number


def test_the_time_step_printed_is_the_one_taken_as_its_help_says(capsys):
    # --help said the step is the one asked (or min(2e-6 s, ...)); a run takes it shortened
    # to whole steps per output sample: 1e-6 s asked at 500 Hz is 2e-3 s / (16 x 128)
    # = 9.765625e-7 s, which --json and the text's dt show, and --help now says so
    from pidcore.cli import build_parser

    assert main(ARGS + ["--json", "--time-step", "1e-6"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["time_step_s"] == pytest.approx(2e-3 / (16 * 128), rel=1e-15)
    assert doc["samples_per_cycle"] == 128
    parser = build_parser()
    with pytest.raises(SystemExit):
        parser.parse_args(["dem", "run", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert ("either is shortened to a whole number of steps per output sample (128 per drive "
            "period; dem run prints the step taken as dt))") in help_text


def test_unsafe_time_step_is_one_line_error_exit_2(capsys):
    code = main(["dem", "run", "--frequency", "50", "--acceleration", "10", "--fill", "50",
                 "--time-step", "2e-6", "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "use --time-step <=" in err


def test_paper_fill_reference_refused(capsys):
    code = main(ARGS + ["--fill-reference", "paper"])
    assert code == 2 and "do not fit" in capsys.readouterr().err


def test_store_round_trip(tmp_path, capsys):
    store_mod = pytest.importorskip("pidcore.store")
    path = tmp_path / "s.h5"
    assert main(ARGS + ["--json", "--store", str(path)]) == 0
    doc = json.loads(capsys.readouterr().out)
    store = store_mod.Store(path)
    assert doc["store_key"].startswith("f500Hz_a5g_fill50pct_acrylic_z_seed12345_cells2")
    assert store.has_dem_run(doc["store_key"])


def test_a_reused_run_says_its_wall_time_is_the_stored_runs(tmp_path, capsys):
    """A reused run printed the stored run's "25.4 s wall" as if this command had spent it
    (the reuse was said only on the last line)."""
    path = tmp_path / "s.h5"
    assert main(ARGS + ["--store", str(path)]) == 0
    (simulated,) = [line for line in capsys.readouterr().out.splitlines()
                    if line.startswith("numerics")]
    assert main(ARGS + ["--store", str(path)]) == 0
    (reused,) = [line for line in capsys.readouterr().out.splitlines()
                 if line.startswith("numerics")]
    assert "stored run" not in simulated
    # the same stored numbers, said to be the stored run's
    assert reused == simulated + " (the stored run's; nothing simulated now)"


def test_steady_window_longer_than_asked_is_announced(capsys):
    # --cycles 5 with blocks of 10 cycles: the window measured is whole blocks, never 5
    assert main(ARGS + ["--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["steady_cycles"] > 5 and doc["steady_cycles"] % 10 == 0
    rounded = [n for n in doc["notes"] if n.startswith("steady window rounded up")]
    assert rounded == [n for n in doc["notes"] if "steady window" in n]
    assert f"{doc['steady_cycles']} cycles measured for the 5 asked" in rounded[0]
    assert "blocks of 10 cycles" in rounded[0]
    assert main(ARGS) == 0  # the readable summary says it too
    assert f"{doc['steady_cycles']} cycles measured for the 5 asked" in capsys.readouterr().out
    # two whole blocks asked: exactly what is measured, and no note
    assert main(ARGS[:-3] + ["--cycles", "20", "--no-progress", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["steady_cycles"] == 20
    assert not [n for n in doc["notes"] if "steady window" in n]


def _interrupt(*args, **kwargs):
    raise KeyboardInterrupt


def test_ctrl_c_before_a_run_finishes_says_nothing_saved(tmp_path, monkeypatch, capsys):
    import pidcore.dem
    import pidcore.dem.persist

    monkeypatch.setattr(pidcore.dem, "simulate_load_case", _interrupt)
    assert main(ARGS) == 130
    err = capsys.readouterr().err
    assert "nothing saved" in err and "are saved" not in err
    from pidcore.store import Store

    monkeypatch.setattr(pidcore.dem.persist, "cached_run", _interrupt)
    path = tmp_path / "s.h5"
    assert main(ARGS + ["--store", str(path)]) == 130
    err = capsys.readouterr().err
    # a store that never existed was said to be "unchanged"
    assert f"nothing saved, {path} not created" in err and not path.exists()
    Store(path).add_dem_run("kept", {"sdc": 0.5})  # one that exists is left unchanged
    assert main(ARGS + ["--store", str(path)]) == 130
    assert f"nothing saved, {path} unchanged" in capsys.readouterr().err


def test_ctrl_c_after_the_run_was_stored_says_it_was_saved(tmp_path, monkeypatch, capsys):
    import pidcore.dem.persist
    from pidcore.store import Store

    real = pidcore.dem.persist.cached_run

    def run_then_interrupt(*args, **kwargs):
        real(*args, **kwargs)
        raise KeyboardInterrupt

    monkeypatch.setattr(pidcore.dem.persist, "cached_run", run_then_interrupt)
    path = tmp_path / "s.h5"
    assert main(ARGS + ["--store", str(path)]) == 130
    err = capsys.readouterr().err
    assert "1 finished run(s) saved to" in err and len(Store(path).list_dem_runs()) == 1


def test_ctrl_c_in_a_sweep_counts_the_cases_stored(tmp_path, monkeypatch, capsys):
    import pidcore.dem.sweep
    from pidcore.dem.persist import run_key
    from pidcore.store import Store

    path = tmp_path / "s.h5"

    def store_cases(cases, config, n, specimen=None):
        for case in cases[:n]:
            key = run_key(case, config, specimen)
            if not (path.exists() and Store(path).has_dem_run(key)):  # the sweep skips those
                Store(path).add_dem_run(key, {"sdc": 0.1})

    def three_then_interrupt(cases, config, *, store_path, specimen, **kwargs):
        # the first case was in the store before the sweep; two more are stored, and the
        # interrupt comes as the last save commits (no hook after it could count that one)
        store_cases(cases, config, 3, specimen)
        raise KeyboardInterrupt

    sweep = ["dem", "sweep", "--store", str(path), "--no-progress"]

    def first_only(cases, config, *, store_path, specimen, **kwargs):
        store_cases(cases, config, 1, specimen)
        raise KeyboardInterrupt

    monkeypatch.setattr(pidcore.dem.sweep, "run_sweep", first_only)
    assert main(sweep) == 130
    err = capsys.readouterr().err
    assert "interrupted; 1 finished run(s) saved to" in err and "re-run to resume" in err
    monkeypatch.setattr(pidcore.dem.sweep, "run_sweep", three_then_interrupt)
    assert main(sweep) == 130
    assert "interrupted; 2 finished run(s) saved to" in capsys.readouterr().err
    assert len(Store(path).list_dem_runs()) == 3
    monkeypatch.setattr(pidcore.dem.sweep, "run_sweep", _interrupt)
    assert main(sweep) == 130
    err = capsys.readouterr().err
    assert "nothing saved" in err and "are saved" not in err


def test_sweep_json_names_the_unit_of_every_number(tmp_path, capsys):
    # dem run --json and calibrate --json carry a units map; a sweep's document named none,
    # so its sdc, loss_factor and particles_per_cell were numbers without a unit
    assert main(["dem", "sweep", "--frequencies", "500", "--accelerations", "5",
                 "--fills", "50", "--cells", "1", "--cycles", "2", "--workers", "1",
                 "--store", str(tmp_path / "s.h5"), "--no-progress", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    (case,) = doc["cases"]
    numbers = {k for k, v in case.items() if isinstance(v, int | float)
               and not isinstance(v, bool)} - {"seed"}  # a name of the packings
    assert numbers >= {"sdc", "loss_factor", "particles_per_cell", "frequency_hz",
                       "acceleration_g", "fill_percent"}
    assert numbers | {"wall_s"} <= set(doc["units"])
    assert doc["units"]["sdc_stderr"] == "-"  # named though one cell gives none (null)
    assert {k: doc["units"][k] for k in ("sdc", "loss_factor", "frequency_hz",
                                         "acceleration_g", "fill_percent",
                                         "stored_fill_percent", "particles_per_cell",
                                         "wall_s")} == {
        "sdc": "-", "loss_factor": "-", "frequency_hz": "Hz", "acceleration_g": "g",
        "fill_percent": "%", "stored_fill_percent": "%", "particles_per_cell": "1",
        "wall_s": "s"}


def test_sweep_states_each_cases_sdc_energy_balance_and_steady_state_as_dem_run_does(
        tmp_path, capsys):
    """A sweep's text output was one summary line (no SDC, energy balance or steady state of
    any run) and its --json no energy_balance_error, where the README says every run reports
    an energy balance. Each case's line must say what `dem run` says of the same stored run,
    in its words."""
    import re

    store = tmp_path / "s.h5"
    stored = ["--store", str(store), "--cells", "2", "--cycles", "2", "--no-progress"]
    assert main(["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", "50",
                 *stored]) == 0
    said = capsys.readouterr().out.splitlines()
    sdc = re.match(r"SDC +(.+?) \[-\]", next(line for line in said
                                             if line.startswith("SDC "))).group(1)
    assert "±" in sdc  # two cells: an SDC with its error
    balance = next(line for line in said
                   if line.startswith("energy balance ")).removeprefix("energy balance").strip()
    steady = re.search(r"\((detected|NOT converged, transient cap)\)",
                       next(line for line in said if line.startswith("steady state "))).group(1)
    assert main(["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", "50",
                 *stored, "--json"]) == 0  # the same run, reused
    run_doc = json.loads(capsys.readouterr().out)
    sweep = ["dem", "sweep", "--frequencies", "500,1000", "--accelerations", "5", "--fills",
             "50", "--workers", "1", *stored]
    assert main(sweep) == 0  # 500 Hz reused, 1000 Hz simulated now
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == (f"500 Hz, 5 g, fill 50 %: SDC {sdc} [-], energy balance {balance}, "
                        f"steady state {steady} (reused: already stored)"), lines
    assert re.fullmatch(r"1000 Hz, 5 g, fill 50 %: SDC \S+ ± \S+ \[-\], energy balance "
                        r"closure error -?[0-9.]+%, steady state (detected|NOT converged, "
                        r"transient cap) \(simulated now\)", lines[1]), lines
    assert lines[2].startswith(f"1 case(s) simulated and saved, 1 already in {store}")
    assert main([*sweep, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    case = next(c for c in doc["cases"] if c["frequency_hz"] == 500)
    # the stored run's own number, under dem run --json's name and unit
    assert case["energy_balance_error"] == run_doc["energy_balance_error"]
    assert doc["units"]["energy_balance_error"] == run_doc["units"]["energy_balance_error"]
    assert all(isinstance(c["energy_balance_error"], float) for c in doc["cases"])


def test_sweep_says_each_runs_notes_as_dem_run_does_reused_runs_included(tmp_path, capsys):
    """`dem sweep --cycles 10` stored 20 steady cycles (whole blocks of 10, the two that
    detect the steady state both measured) where `dem run` of the same case says "steady
    window rounded up"; the sweep said only "steady state detected" and its --json had
    `"notes": []`, though --cycles promises "(noted)". Each case must carry the notes `dem
    run` gives of its run, simulated now or reused."""
    store = tmp_path / "s.h5"
    # --cycles 2 in blocks of 10: the window is rounded up in every run (the note's
    # trigger), one cell: no standard error (a second note, said why)
    stored = ["--store", str(store), "--cells", "1", "--cycles", "2", "--no-progress"]
    assert main(["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", "50",
                 *stored, "--json"]) == 0
    run_notes = json.loads(capsys.readouterr().out)["notes"]
    assert [n for n in run_notes if n.startswith("steady window rounded up: ")
            and "cycles measured for the 2 asked" in n], run_notes
    sweep = ["dem", "sweep", "--frequencies", "500,1000", "--accelerations", "5", "--fills",
             "50", "--workers", "1", *stored]
    assert main([*sweep, "--json"]) == 0  # 500 Hz reused, 1000 Hz simulated now
    reused, simulated = json.loads(capsys.readouterr().out)["cases"]
    assert (reused["status"], simulated["status"]) == ("already stored", "simulated")
    assert reused["notes"] == run_notes  # the stored run's notes, in dem run's words
    assert main(["dem", "run", "--frequency", "1000", "--acceleration", "5", "--fill", "50",
                 *stored, "--json"]) == 0  # the run the sweep simulated, reused
    assert simulated["notes"] == json.loads(capsys.readouterr().out)["notes"]
    assert any(n.startswith("steady window rounded up: ") for n in simulated["notes"])
    # the text output says each note once, naming the cases it is of
    assert main(sweep) == 0
    said = [line for line in capsys.readouterr().out.splitlines() if line.startswith("note (")]
    for case in (reused, simulated):
        where = f"{case['frequency_hz']:g} Hz, 5 g, fill 50 %"
        for note in case["notes"]:
            (line,) = [line for line in said if line.endswith(f"): {note}")]
            assert line.startswith(("note (every case): ", f"note ({where}")) or \
                f"; {where})" in line, line
    assert len(said) == len(set(reused["notes"]) | set(simulated["notes"]))


def test_sweep_runs_the_values_given_in_place_of_the_grids(tmp_path, capsys):
    from pidcore.loadcase import parse_key
    from pidcore.store import Store

    path = tmp_path / "s.h5"
    # fills given, frequencies and accelerations given: 1 x 1 x 2 cases, not the 48 of table3
    assert main(["dem", "sweep", "--frequencies", "500", "--accelerations", "5",
                 "--fills", "50,25,50", "--cells", "1", "--cycles", "2", "--workers", "1",
                 "--store", str(path), "--no-progress", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    runs = Store(path).list_dem_runs()
    assert len(runs) == 2 and doc["completed"] == 2  # the repeated 50 runs once
    assert sorted((c.frequency_hz, c.acceleration_g, c.fill_percent)
                  for c in map(parse_key, runs["case_key"])) == [(500, 5, 25), (500, 5, 50)]


def test_sweep_json_lists_cases_in_the_order_it_documents(tmp_path, capsys):
    """Documented as "in the order asked", the cases came in Table 3's order (--fills 52,48
    listed 48 first): the order is ascending, and the docs now say so and which of two fills
    that round alike was simulated."""
    from pathlib import Path

    from pidcore.dem.sweep import SweepSummary

    assert main(["dem", "sweep", "--frequencies", "1000,500", "--accelerations", "5",
                 "--fills", "52,48", "--cells", "1", "--cycles", "2", "--workers", "1",
                 "--store", str(tmp_path / "s.h5"), "--no-progress", "--json"]) == 0
    cases = json.loads(capsys.readouterr().out)["cases"]
    assert [(c["frequency_hz"], c["fill_percent"]) for c in cases] == [
        (500.0, 48.0), (500.0, 52.0), (1000.0, 48.0), (1000.0, 52.0)]
    # 48 % and 52 % of 22 acrylic particles both round to 11: the lower fill is simulated
    assert [c["status"] for c in cases[:2]] == [
        "simulated", "same simulation as another case of this sweep"]
    assert cases[1]["store_key"] == cases[0]["store_key"]
    assert cases[1]["stored_fill_percent"] == 48.0
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    for text in (" ".join(readme.split()), " ".join(SweepSummary.__doc__.split())):
        assert "in the order asked" not in text and "each ascending" in text
        assert "the lower fill" in text or "the lower is simulated" in text
    with pytest.raises(SystemExit):
        main(["dem", "sweep", "--help"])
    assert "whatever the order given" in " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize("value", ["25,x", "25,-5", "nan", ""])
def test_sweep_refuses_a_bad_value_list_in_one_line(tmp_path, capsys, value):
    try:
        code = main(["dem", "sweep", "--fills", value, "--store", str(tmp_path / "s.h5")])
    except SystemExit as usage:  # the parser's refusal of the list (an empty item), exit 2
        code = usage.code
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--fills" in err[0]
    assert not (tmp_path / "s.h5").exists()


@pytest.mark.parametrize("command", [
    ["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", "1"],
    ["dem", "sweep", "--frequencies", "500", "--accelerations", "5", "--fills", "50,1"]])
def test_a_fill_of_no_particle_names_its_option_and_writes_nothing(tmp_path, capsys, command):
    # 1 % of the 22 acrylic spheres a cell holds rounds to none: refused before anything runs
    store = tmp_path / "s.h5"
    code = main([*command, "--store", str(store), "--no-progress"])
    err = capsys.readouterr().err
    option = command[-2]
    assert code == 2 and err.count("\n") == 1
    assert f"error: {option} 1 % of 22 particles rounds to none; expected >= 2.28 %" in err
    assert not store.exists()


@pytest.mark.parametrize("command", [
    ["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill"],
    ["dem", "sweep", "--frequencies", "500", "--accelerations", "5", "--fills"]])
def test_a_fill_typed_as_a_fraction_gets_the_hint_analyze_gives(tmp_path, capsys, command):
    # analyze --fill 0.5 asks 'was 0.5 meant as 50 %?'; dem run/sweep refused it without
    # the hint. 0.01 x 100 = 1 % holds none of 22 either: no such offer, as in analyze
    for fill, hint in (("0.5", "was 0.5 meant as 50 %?"), ("0.01", None)):
        store = tmp_path / "s.h5"
        assert main([*command, fill, "--store", str(store), "--no-progress"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "rounds to none" in err, err
        assert (hint in err) if hint else ("meant as" not in err)
        assert not store.exists()
        export = (Path(__file__).resolve().parents[1] / "data_samples" / "exports"
                  / "synthetic_f50Hz_a5g_fill50_acrylic.uff")
        assert main(["analyze", str(export), "--no-store", "--fill", fill]) == 2
        said = capsys.readouterr().err
        assert (hint in said) if hint else ("meant as" not in said)  # the same words


@pytest.mark.parametrize("fill", ["nan", "inf", "0", "150", "100.0000001"])
def test_a_fill_outside_0_100_is_one_line_naming_the_option(capsys, fill):
    # 100.0000001 was shown as "--fill 100", a fill that is accepted
    # "nan" and "inf" raised a traceback from the particle count's rounding
    code = main(["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", fill])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert f"--fill {fill}: expected a fill in (0, 100] %" in err


@pytest.mark.parametrize("command", [
    ["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", "50"],
    ["dem", "sweep", "--frequencies", "500", "--accelerations", "5", "--fills", "50"]])
def test_a_negative_seed_is_one_line_naming_the_option(tmp_path, capsys, command):
    # numpy's generators take no negative seed: it was a traceback from inside the run
    store = tmp_path / "s.h5"
    with pytest.raises(SystemExit) as stop:  # argparse's own refusal, as from the shell
        main([*command, "--seed", "-1", "--store", str(store), "--no-progress"])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "--seed: expected a whole number >= 0" in err
    assert not store.exists()


@pytest.mark.parametrize("command", [
    ["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", "50"],
    ["dem", "sweep", "--frequencies", "500", "--accelerations", "5", "--fills", "50"]])
def test_a_seed_past_the_largest_is_one_line_naming_the_option(tmp_path, capsys, command):
    # DemConfig's refusal was printed with its keyword: "seed: expected ..."
    store = tmp_path / "s.h5"
    assert main([*command, "--seed", str(2**63), "--store", str(store), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.endswith(": error: --seed: expected a whole number below 2^63 "
                        f"({2**63}), got {2**63}\n")
    assert not store.exists()


def test_a_negative_seed_is_refused_by_the_library_too():
    from pidcore.dem.simulate import DemConfig
    from pidcore.errors import ParameterError

    with pytest.raises(ParameterError, match="seed: expected a whole number >= 0, got -1"):
        DemConfig(seed=-1)


def test_no_fill_and_no_specimen_says_what_to_give(capsys):
    # it said "the specimen states no count_per_cell" where no specimen was given
    code = main(["dem", "run", "--frequency", "500", "--acceleration", "5"])
    err = capsys.readouterr().err
    assert code == 2 and "--fill: required (or a --specimen file stating count_per_cell" in err


@pytest.mark.parametrize("command", [
    ["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", "50"],
    ["dem", "sweep", "--frequencies", "500", "--accelerations", "5", "--fills", "50"]])
@pytest.mark.parametrize("option, said", [
    # "use fill_reference='capacity'": the Python keyword, not the flag the user types
    (["--fill-reference", "paper"],
     "error: --fill-reference paper: 36 acrylic particles (r = 1.25 mm) do not fit a 4.76 x "
     "25.4 mm cell (capacity 22); use --fill-reference capacity\n"),
    (["--cells", "0"], "error: --cells: expected >= 1, got 0\n"),  # was "cells: ..."
    (["--time-step", "0"], "error: --time-step: expected > 0 s, got 0.0\n"),
])
def test_dem_refusals_name_the_flags_not_the_library_keywords(tmp_path, capsys, command,
                                                              option, said):
    store = tmp_path / "s.h5"
    assert main([*command, *option, "--store", str(store), "--no-progress"]) == 2
    assert capsys.readouterr().err == f"pidcore {' '.join(command[:2])}: {said}"
    assert not store.exists()


def test_the_flag_wording_leaves_other_words_alone():
    from pidcore.cli._vocabulary import cli_words

    # "cells" names the option only as a message's first word; paths keep their names
    said = "over 2 cells: my_time_step.toml: acceleration_g must be > 0"
    assert cli_words(said, "dem run") == \
        "over 2 cells: my_time_step.toml: --acceleration must be > 0"
    assert cli_words("frequency_hz must be > 0", "dem sweep") == "--frequencies must be > 0"


def _steel_stating_count(tmp_path, monkeypatch, count: int) -> tuple[Path, Path]:
    """The bundled steel_6mm.toml, and a copy of it stating ``count_per_cell = count`` for its
    fill; `dem sweep` stops (Ctrl-C) before its first case: what it says before is the test."""
    import pidcore.dem.sweep as sweep_module

    def stop(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(sweep_module, "run_sweep", stop)
    spec = Path(__file__).resolve().parents[1] / "data_samples" / "specimens" / "steel_6mm.toml"
    mine = tmp_path / "mine.toml"
    mine.write_text(spec.read_text().replace("fill_percent = 50.0", f"count_per_cell = {count}"))
    return spec, mine


def test_a_sweep_without_fills_runs_the_fill_the_specimen_states(tmp_path, capsys,
                                                                  monkeypatch):
    # a specimen stating its fill (steel_6mm: fill_percent = 50; a file stating count_per_cell
    # 20) swept without --fills ran Table 3's 25, 50, 75, 90 % (4 x the runs), where `dem run`
    # and the app's DEM tab simulate the stated fill; the paper's coupon keeps its grid
    import pidcore.dem.sweep as sweep_module
    from pidcore.dem.simulate import particles_per_cell
    from pidcore.dem.sweep import GRIDS
    from pidcore.specimen import load_specimen

    spec, mine = _steel_stating_count(tmp_path, monkeypatch, 20)
    swept: list = []

    def stop(cases, *args, **kwargs):
        swept.append(sorted({case.fill_percent for case in cases}))
        raise KeyboardInterrupt

    monkeypatch.setattr(sweep_module, "run_sweep", stop)
    specimen = load_specimen(mine)
    capacity = specimen.capacity_per_cell()
    argv = ["dem", "sweep", "--specimen", str(mine), "--frequencies", "500",
            "--accelerations", "5", "--store", str(tmp_path / "s.h5"), "--no-progress"]
    assert main(argv) == 130
    assert swept.pop() == [pytest.approx(100 * 20 / capacity, rel=1e-12)]
    # the fill swept is the file's 20 particles per cell, not a neighbour of it
    stated = specimen.stated_fill()[0]
    assert particles_per_cell(stated, specimen=specimen)[0] == 20
    grid_fills = "25, 50, 75, 90"
    assert capsys.readouterr().err.startswith(
        f"pidcore dem sweep: note: fill {100 * 20 / capacity:.6g} % is the one specimen "
        f"steel_6mm states ([particles] count_per_cell 20 of capacity {capacity}), as a run "
        f"of it without a fill simulates; give --fills for others (grid table3's: "
        f"{grid_fills} %)\n")
    assert main([*argv[:3], str(spec), *argv[4:]]) == 130  # steel_6mm: fill_percent = 50.0
    assert swept.pop() == [50.0]
    assert "fill 50 % is the one specimen steel_6mm states ([particles] fill_percent)" in \
        capsys.readouterr().err
    # a file stating no fill: the grid's, and the note says why
    none = tmp_path / "none.toml"
    none.write_text(spec.read_text().replace("fill_percent = 50.0", ""))
    assert load_specimen(none).stated_fill() is None
    assert main([*argv[:3], str(none), *argv[4:]]) == 130
    assert swept.pop() == list(GRIDS["table3"]["fill_percent"])
    assert capsys.readouterr().err.startswith(
        f"pidcore dem sweep: note: fills {grid_fills} % are grid table3's: specimen steel_6mm "
        "states no fill (count_per_cell or fill_percent); give --fills to choose\n")
    # the paper's coupon, named or not, keeps the bundled Table 3 grid, without a note
    paper = Path(__file__).resolve().parents[1] / "pidcore" / "data" / "specimens" / \
        "paper_coupon.toml"
    for more in ([], ["--specimen", str(paper)], ["--tangential-stiffness", "mindlin"]):
        assert main([*argv[:2], *argv[4:], *more]) == 130
        assert swept.pop() == [25.0, 50.0, 75.0, 90.0]
        assert "note" not in capsys.readouterr().err
    # fills given: those, and what they override is said (ran 30 % without a word)
    assert main([*argv, "--fills", "30,50"]) == 130
    assert swept.pop() == [30.0, 50.0]
    assert capsys.readouterr().err.startswith(
        f"pidcore dem sweep: note: fills 30, 50 % override the {100 * 20 / capacity:.6g} % "
        f"specimen steel_6mm states ([particles] count_per_cell 20 of capacity {capacity})\n")


def test_a_sweeps_json_notes_say_which_fills_run_and_why(tmp_path, capsys, monkeypatch):
    # the note on which fills a sweep of one's own specimen runs (the one it states, or the
    # grid's as it states none) was on stderr only: --json, read by a script, had no word of it
    import pidcore.dem.sweep as sweep_module
    from pidcore.dem.sweep import SweepSummary

    spec, mine = _steel_stating_count(tmp_path, monkeypatch, 20)
    given: list = []

    def summarize(cases, config, *, store_path, **kwargs):
        # the cases run_sweep was given, and no note of its own: what is in --json's notes
        # then came from the command
        given.append(sorted({case.fill_percent for case in cases}))
        return SweepSummary(store_path=str(store_path))

    monkeypatch.setattr(sweep_module, "run_sweep", summarize)
    none = tmp_path / "none.toml"
    none.write_text(spec.read_text().replace("fill_percent = 50.0", ""))
    argv = ["dem", "sweep", "--frequencies", "500", "--accelerations", "5", "--store",
            str(tmp_path / "s.h5"), "--no-progress", "--json"]
    assert main([*argv, "--specimen", str(none)]) == 0
    captured = capsys.readouterr()
    said = ("fills 25, 50, 75, 90 % are grid table3's: specimen steel_6mm states no fill "
            "(count_per_cell or fill_percent); give --fills to choose")
    assert json.loads(captured.out)["notes"] == [said]
    assert f"pidcore dem sweep: note: {said}\n" in captured.err  # the same words on stderr
    assert given.pop() == [25.0, 50.0, 75.0, 90.0]
    assert main([*argv, "--specimen", str(spec)]) == 0  # steel_6mm states fill_percent 50
    (note,) = json.loads(capsys.readouterr().out)["notes"]
    assert note.startswith("fill 50 % is the one specimen steel_6mm states ([particles] "
                           "fill_percent), as a run of it without a fill simulates; give "
                           "--fills for others")
    assert given.pop() == [50.0]
    # the paper's coupon runs its grid as always, and nothing is said
    assert main(argv) == 0
    assert json.loads(capsys.readouterr().out)["notes"] == []


def test_a_fill_of_the_specimens_particle_count_is_no_override(tmp_path, capsys, monkeypatch):
    # `dem sweep --fills 8.7` of a file stating 4 particles of 46 per cell (8.69565 %) said
    # "fill 8.7 % overrides the 8.69565 % specimen ... states", though 8.7 % of 46 is 4.002,
    # which rounds to the same 4 particles: the same simulation, nothing overridden
    from pidcore.specimen import fill_override_note, load_specimen

    _, mine = _steel_stating_count(tmp_path, monkeypatch, 4)
    specimen = load_specimen(mine)
    assert specimen.capacity_per_cell() == 46  # 4 particles: fills 7.61 .. 9.78 % round to 4
    argv = ["dem", "sweep", "--specimen", str(mine), "--frequencies", "500",
            "--accelerations", "5", "--store", str(tmp_path / "s.h5"), "--no-progress"]
    assert main([*argv, "--fills", "8.7"]) == 130
    assert "note" not in capsys.readouterr().err
    # a fill of another count beside it is still said, and it alone
    assert main([*argv, "--fills", "8.7,30"]) == 130
    assert capsys.readouterr().err.startswith(
        f"pidcore dem sweep: note: fill 30 % overrides the {400 / 46:.6g} % specimen "
        "steel_6mm states ([particles] count_per_cell 4 of capacity 46)\n")
    # counted against the run's 100 %: of the paper's 36, 9.75 % is 3.51 -> 4 particles, the
    # stated 4; the capacity's 8.69565 % is 3.13 -> 3 there (of the capacity's 46 both are 4)
    assert fill_override_note(specimen, [9.75]) == ""
    assert fill_override_note(specimen, [9.75], "paper") == ""
    assert fill_override_note(specimen, [400 / 46], "paper").startswith(
        f"fill {400 / 46:.6g} % overrides the {400 / 36:.6g} % specimen steel_6mm states")


def test_a_fill_given_for_a_specimen_stating_its_count_is_said_to_override_it(tmp_path,
                                                                              capsys):
    # `dem run --fill 30 --specimen FILE` of a file stating count_per_cell = 20 simulated 30 %
    # without a word that the count written in the file was not used
    from pidcore.dem import DemConfig, LoadCase, simulate_load_case
    from pidcore.dem.sweep import run_sweep
    from pidcore.specimen import load_specimen

    spec = Path(__file__).resolve().parents[1] / "data_samples" / "specimens" / "steel_6mm.toml"
    mine = tmp_path / "mine.toml"
    mine.write_text(spec.read_text().replace("fill_percent = 50.0", "count_per_cell = 20"))
    specimen = load_specimen(mine)
    capacity = specimen.capacity_per_cell()
    stated = f"{100 * 20 / capacity:.6g} % specimen steel_6mm states ([particles] " \
             f"count_per_cell 20 of capacity {capacity})"
    argv = ["dem", "run", "--specimen", str(mine), "--frequency", "500", "--acceleration", "5",
            "--cells", "1", "--cycles", "4", "--no-progress"]
    assert main([*argv, "--fill", "30", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    said = [n for n in doc["notes"] if "override" in n]
    assert said == [f"fill 30 % overrides the {stated}: {doc['particles_per_cell']} particles "
                    "per cell simulated"]
    assert doc["particles_per_cell"] != 20  # the count the file states was indeed not run
    assert main([*argv, "--fill", "30"]) == 0
    assert f"note            fill 30 % overrides the {stated}" in capsys.readouterr().out
    # without --fill the file's own count runs, and nothing is said
    assert main([*argv, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["particles_per_cell"] == 20 and not any("override" in n for n in doc["notes"])
    # the library's result and sweep summary say the same
    config = DemConfig(cells=1, steady_cycles=4)
    result = simulate_load_case(LoadCase(500.0, 5.0, 30.0, material=specimen.particles.material),
                                config, progress=False, specimen=specimen)
    assert f"fill 30 % overrides the {stated}: {result.particles_per_cell} particles per cell " \
           "simulated" in result.notes
    summary = run_sweep([LoadCase(500.0, 5.0, 30.0, material=specimen.particles.material)],
                        config, store_path=tmp_path / "s.h5", workers=1, progress=False,
                        specimen=specimen)
    assert summary.notes == [f"fill 30 % overrides the {stated}"]
    assert summary.to_dict()["notes"] == summary.notes


def test_a_read_only_store_is_refused_before_any_simulation(tmp_path, monkeypatch, capsys,
                                                              read_only):
    # dem run / dem sweep / calibrate simulated first and then lost the work at the commit
    # ("cannot commit the changes ([Errno 1] Operation not permitted ...)"); a stored run is
    # still read from a read-only store
    import pidcore.calibrate.runner  # noqa: F401 - the module patched below
    import pidcore.dem.persist
    import pidcore.dem.sweep
    from pidcore.store import Store

    store = tmp_path / "runs.h5"
    assert main(ARGS + ["--store", str(store)]) == 0
    capsys.readouterr()
    before = store.read_bytes()
    read_only(store)

    def never(*args, **kwargs):
        raise AssertionError("simulated for a store it cannot save to")

    monkeypatch.setattr(pidcore.dem.persist, "simulate_load_case", never)
    monkeypatch.setattr(pidcore.dem.sweep, "_run_local", never)
    other = [a if a != "500" else "400" for a in ARGS]
    for argv in (other + ["--store", str(store)],
                 ["dem", "sweep", "--frequencies", "400", "--accelerations", "5", "--fills",
                  "50", "--cells", "2", "--cycles", "5", "--no-progress", "--store",
                  str(store)]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "runs.h5: the store file is read-only" in err
    # calibrate's DEM runs: refused before the first
    from pidcore.calibrate.runner import RunRequest, run_requests
    from pidcore.dem import DemConfig, LoadCase
    from pidcore.errors import StoreError
    from pidcore.specimen import paper_specimen

    request = RunRequest(LoadCase(400, 5, 50), paper_specimen(), DemConfig(cells=2))
    with pytest.raises(StoreError, match="the store file is read-only"):
        run_requests([request], store_path=store, workers=1, progress=False)
    # the cached run is read as before, and the store is untouched
    assert main(ARGS + ["--store", str(store)]) == 0
    assert "reused from" in capsys.readouterr().out
    assert store.read_bytes() == before and len(Store(store).list_dem_runs()) == 1


def test_a_drive_no_shaker_makes_is_refused_before_any_simulation(tmp_path, capsys):
    # 0.2 typed for 200 Hz: 5 g at 0.2 Hz is a displacement amplitude a/w^2 of 31 m; the DEM
    # simulated its cycles (~100 s of simulated time) for many minutes without a word
    import math

    from pidcore.dem import LoadCase, simulate_load_case
    from pidcore.errors import ParameterError

    stroke = 5 * 9.80665 / (2 * math.pi * 0.2) ** 2
    assert stroke == pytest.approx(31.05, rel=1e-3)
    slow = [a if a != "500" else "0.2" for a in ARGS]
    assert main(slow) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "--frequency/--acceleration 0.2 Hz, 5 g: a displacement amplitude of 31.1 m" in err
    assert "kHz" in err
    store = tmp_path / "runs.h5"
    assert main(["dem", "sweep", "--frequencies", "200,0.2", "--accelerations", "5", "--fills",
                 "50", "--cells", "2", "--cycles", "5", "--no-progress", "--store",
                 str(store)]) == 2
    assert "--frequencies/--accelerations 0.2 Hz" in capsys.readouterr().err
    assert not store.exists()  # the 200 Hz case was not run either
    with pytest.raises(ParameterError, match="displacement amplitude"):
        simulate_load_case(LoadCase(0.2, 5, 50))
    # Table 3's largest stroke (50 Hz, 10 g: 1 mm) is far inside the 50 mm limit
    assert 10 * 9.80665 / (2 * math.pi * 50) ** 2 < 1.0e-3


def test_a_far_too_long_time_step_states_its_steps_per_contact(capsys):
    # --time-step 1e-3 s said "gives 0.0 steps per acrylic contact": 1.74e-5 s / 1e-3 s is
    # 0.0174 steps, which one decimal rounded to nothing
    assert main(["dem", "run", "--frequency", "100", "--acceleration", "5", "--fill", "50",
                 "--time-step", "1e-3", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "gives 0.0 steps" not in err and "gives 0.017 steps per acrylic contact" in err


def test_a_drive_far_above_the_papers_accelerations_asks_whether_it_was_m_s2(capsys):
    # `--acceleration 49` (5 g typed in m/s^2) strokes 50 µm at 500 Hz, which a shaker makes:
    # the stroke check cannot tell; the run says what it would be in g
    from pidcore import defaults
    from pidcore.constants import STANDARD_GRAVITY

    high = ["dem", "run", "--frequency", "500", "--acceleration", "49", "--fill", "50",
            "--cells", "1", "--cycles", "2", "--no-progress", "--json"]
    assert 49 > defaults.DEM_NOTE_ACCELERATION_G
    assert main(high) == 0
    notes = json.loads(capsys.readouterr().out)["notes"]
    (note,) = [n for n in notes if "m/s^2" in n]
    assert f"it is {49 / STANDARD_GRAVITY:.3g} g" in note
    # the paper's 10 g says nothing of the kind
    assert main([a if a != "49" else "10" for a in high]) == 0
    assert not any("m/s^2" in n for n in json.loads(capsys.readouterr().out)["notes"])


@pytest.mark.parametrize("frequency", ["1e-300", "1e300", "1e6"])
def test_a_tiny_or_huge_frequency_is_one_line_not_a_traceback(capsys, frequency):
    # --frequency 1e-300 raised ZeroDivisionError ((2 pi f)^2 underflows to 0), 1e300 an
    # OverflowError (the settling's step count), and 1e6 ran for hours: 128 samples per
    # 1 µs period need a time step ~230 x shorter than the contacts' ~1.8 µs
    args = [a if a != "500" else frequency for a in ARGS]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert "inf" not in err and "nan" not in err
    if frequency == "1e-300":
        assert "displacement amplitude of more than 1e308 m" in err
    else:
        assert f"--frequency {float(frequency):g} Hz: 128 samples per drive period" in err


def test_a_sweep_refuses_a_frequency_it_cannot_sample_before_any_case_runs(tmp_path, capsys,
                                                                           monkeypatch):
    # --frequencies 200,1e6 ran the 200 Hz case before the 1 MHz one was refused in its worker
    import pidcore.dem.sweep as sweep

    def no_run(*args, **kwargs):
        raise AssertionError("a case ran")

    monkeypatch.setattr(sweep, "run_sweep", no_run)
    store = tmp_path / "runs.h5"
    assert main(["dem", "sweep", "--frequencies", "200,1e6", "--accelerations", "5", "--fills",
                 "50", "--cells", "2", "--cycles", "5", "--no-progress", "--store",
                 str(store)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--frequencies 1e+06 Hz: 128 samples per drive period" in err
    assert not store.exists()


def test_the_highest_frequency_the_dem_takes_follows_from_its_time_step():
    # at the frequency the refusal names, a period's 128 samples shorten the contacts' step
    # by exactly DEM_MAX_STEP_SHORTENING: 1 % below it runs, 1 % above it is refused
    import re

    from pidcore import defaults
    from pidcore.dem import LoadCase
    from pidcore.dem.simulate import check_drive_sampling
    from pidcore.errors import ParameterError

    step = 1.81e-6
    highest = defaults.DEM_MAX_STEP_SHORTENING / (defaults.DEM_SAMPLES_PER_CYCLE * step)
    for f, refused in ((highest * 0.99, False), (highest * 1.01, True)):
        dt = 1 / f / defaults.DEM_SAMPLES_PER_CYCLE
        try:
            check_drive_sampling(LoadCase(f, 5, 50), dt_s=dt, contact_step_s=step,
                                 samples_per_cycle=defaults.DEM_SAMPLES_PER_CYCLE)
        except ParameterError as exc:
            assert refused
            named = float(re.search(r"at most (\S+) Hz", str(exc)).group(1))
            assert named == pytest.approx(highest, rel=1e-2)  # 3 significant digits
        else:
            assert not refused


@pytest.mark.parametrize("command", ["sweep", "run"])
def test_ctrl_c_as_the_result_prints_still_says_what_was_saved(tmp_path, monkeypatch, capsys,
                                                               command):
    """A Ctrl-C after the last case was stored, while the summary printed, was answered by
    the generic "no store write was left half-done", not by what was saved."""
    import pidcore.cli.dem as dem_cli

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(dem_cli, f"_print_{command}", interrupted)
    store = tmp_path / "s.h5"
    argv = (["dem", "sweep", "--frequencies", "1000", "--accelerations", "5", "--fills", "25",
             "--workers", "1"] if command == "sweep" else
            ["dem", "run", "--frequency", "1000", "--acceleration", "5", "--fill", "25"])
    assert main([*argv, "--cells", "1", "--cycles", "2", "--no-progress",
                 "--store", str(store)]) == 130
    err = capsys.readouterr().err.strip().splitlines()
    # every case had finished: "re-run to resume" sent the user to re-run for nothing
    assert err == [f"pidcore dem {command}: interrupted; 1 finished run(s) saved to {store}; "
                   "every case is stored, nothing left to run"], err


def test_sweep_says_what_it_saved_not_what_another_sweep_saved(tmp_path, monkeypatch, capsys):
    """A second sweep on one store whose runs the first saved meanwhile printed
    "1 case(s) simulated" although it saved none."""
    import pidcore.dem.sweep
    from pidcore.dem.sweep import STORED_MEANWHILE, SweepSummary

    def stored_by_another(cases, config, *, store_path, specimen, **kwargs):
        return SweepSummary(skipped=["k"], store_path=str(store_path),
                            cases=[{"frequency_hz": 1000.0, "acceleration_g": 5.0,
                                    "fill_percent": 25.0, "store_key": "k",
                                    "status": STORED_MEANWHILE}])

    monkeypatch.setattr(pidcore.dem.sweep, "run_sweep", stored_by_another)
    store = tmp_path / "s.h5"
    assert main(["dem", "sweep", "--frequencies", "1000", "--accelerations", "5", "--fills",
                 "25", "--no-progress", "--store", str(store)]) == 0
    case, summary = capsys.readouterr().out.splitlines()
    assert case.endswith(f"(reused: {STORED_MEANWHILE})"), case
    assert summary.startswith(f"0 case(s) simulated and saved, 1 already in {store} (1 of "
                              "them saved meanwhile by another process"), summary


def test_a_far_too_short_time_step_is_refused_before_any_work(capsys, tmp_path):
    # --time-step 1e-15 (a unit typed twice) had no lower limit: ~1e9 x the automatic step's
    # steps, a run of years with nothing said; the automatic step of this case is
    # min(2e-6 s, t_contact / 10) with the paper's acrylic contacts
    from pidcore import defaults
    from pidcore.dem import LoadCase
    from pidcore.dem.contact import ContactLaw
    from pidcore.dem.simulate import choose_time_step, resolve_specimen
    from pidcore.errors import ParameterError

    case = LoadCase(100, 5, 50)
    specimen = resolve_specimen(case, None)
    law = ContactLaw.for_material(case.material)
    automatic = choose_time_step(case, law, specimen.geometry(), "auto")
    store = tmp_path / "s.h5"
    assert main(["dem", "run", "--frequency", "100", "--acceleration", "5", "--fill", "50",
                 "--time-step", "1e-15", "--store", str(store), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--time-step 1e-15 s is" in err
    assert f"expected >= {automatic / defaults.DEM_MAX_STEP_SHORTENING:.3g} s" in err
    assert not store.exists()
    # just above the limit is accepted: a convergence check at up to 10 x the steps
    shortest = automatic / defaults.DEM_MAX_STEP_SHORTENING
    assert choose_time_step(case, law, specimen.geometry(), shortest * 1.0000001) \
        == shortest * 1.0000001
    with pytest.raises(ParameterError, match=r"time_step .* x shorter than the automatic"):
        choose_time_step(case, law, specimen.geometry(), shortest * 0.999)


def test_more_cells_than_memory_holds_are_refused_before_any_work(capsys, tmp_path):
    # --cells 1000000000 packed cells for hours before running out of memory
    import numpy as np

    from pidcore.dem.simulate import (
        _physical_memory_bytes,
        check_cells_fit_memory,
        particles_per_cell,
    )
    from pidcore.dem.state import CellsState

    n, _ = particles_per_cell(50, "acrylic")
    # the estimate is the state's real size: the arrays CellsState allocates
    state = CellsState.from_positions(np.zeros((3, n, 3)), mass_kg=1e-5)
    arrays = [state.pos, state.vel, state.omg, state.frc, state.trq, state.spring_pp,
              state.spring_pw]
    assert sum(a.nbytes for a in arrays) == 3 * CellsState.bytes_per_cell(n)
    total = _physical_memory_bytes()
    most = total // CellsState.bytes_per_cell(n)
    check_cells_fit_memory(most, n)  # the largest that fits is accepted
    store = tmp_path / "s.h5"
    for command in (["dem", "run", "--fill", "50", "--frequency", "100", "--acceleration", "5"],
                    ["dem", "sweep", "--fills", "50", "--frequencies", "100,200",
                     "--accelerations", "5"]):
        assert main([*command, "--cells", str(most + 1), "--store", str(store),
                     "--no-progress"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"--cells {most + 1}: the state of" in err
        assert f"expected at most {most} cells" in err
        assert not store.exists()


STEEL = Path(__file__).resolve().parents[1] / "data_samples" / "specimens" / "steel_6mm.toml"


@pytest.mark.parametrize("command", [["dem", "run"], ["dem", "sweep"]])
def test_material_option_takes_the_specimens_own_material(command):
    # `--specimen steel_6mm.toml --material steel` was refused by argparse ("invalid choice:
    # 'steel' (choose from 'acrylic', 'aluminium')") though steel is the specimen's particles
    # and `report --material steel --specimen ...` takes it
    from pidcore.cli import build_parser
    from pidcore.cli.dem import _specimen

    args = build_parser().parse_args(
        [*command, "--specimen", str(STEEL), "--material", "Steel", "--frequency"
         if command[1] == "run" else "--frequencies", "500", "--acceleration"
         if command[1] == "run" else "--accelerations", "5"])
    specimen, material = _specimen(args)
    assert (specimen.name, material) == ("steel_6mm", "steel")


def test_a_material_the_papers_coupon_lacks_names_the_specimen_option(capsys):
    assert main(ARGS + ["--material", "steel"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert "--material steel" in err and "acrylic or aluminium" in err and "--specimen" in err


def test_a_material_other_than_the_specimens_is_refused_naming_both(capsys):
    assert main(["dem", "run", "--specimen", str(STEEL), "--frequency", "500",
                 "--acceleration", "5", "--material", "acrylic"]) == 2
    err = capsys.readouterr().err
    assert "'acrylic'" in err and "'steel'" in err


def test_time_step_help_names_every_limit_of_the_automatic_step(capsys):
    # the help said min(2e-6 s, contact time / 10); a Mindlin spring's period / 10 sets the
    # automatic step of the paper's coupon with --tangential-stiffness mindlin (8.9e-7 s,
    # where the contact time gives 1.6e-6 s), as `specimen check` and the README say
    with pytest.raises(SystemExit):
        main(["dem", "run", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "contact time / 10, a stuck tangential spring's period / 10" in text


def test_the_specimens_stated_fill_keeps_its_particle_count_under_the_papers_reference(
        tmp_path, capsys, monkeypatch):
    # `dem run --fill-reference paper` of a file stating count_per_cell = 20 (of a capacity
    # of 46) took the capacity's 43.5 % as a share of the paper's 36 and simulated 16
    # particles per cell, without a word; `dem sweep` (its stated fill now its default) too
    import pidcore.dem.sweep as sweep_module
    from pidcore.dem.simulate import particles_per_cell
    from pidcore.specimen import fill_override_note, load_specimen

    spec, mine = _steel_stating_count(tmp_path, monkeypatch, 20)
    for path, count in ((mine, 20), (spec, 23)):  # steel_6mm: fill_percent 50 of 46 -> 23
        specimen = load_specimen(path)
        for reference in ("capacity", "paper"):
            fill = specimen.stated_fill(reference)[0]
            assert particles_per_cell(fill, specimen=specimen,
                                      fill_reference=reference)[0] == count, (path, reference)
        # the capacity's percentage unchanged (the run keys of stored runs hold it)
        assert specimen.stated_fill("capacity") == specimen.stated_fill()
    specimen = load_specimen(mine)
    paper_fill = 100 * 20 / 36
    # a fill typed as that count's share of 36 overrides nothing; 50 % of 36 (18) does
    assert fill_override_note(specimen, [paper_fill], "paper") == ""
    assert fill_override_note(specimen, [50.0], "paper").startswith("fill 50 % overrides")
    swept: list = []

    def stop(cases, *args, **kwargs):
        swept.append(sorted({case.fill_percent for case in cases}))
        raise KeyboardInterrupt

    monkeypatch.setattr(sweep_module, "run_sweep", stop)
    assert main(["dem", "sweep", "--specimen", str(mine), "--frequencies", "500",
                 "--accelerations", "5", "--fill-reference", "paper", "--store",
                 str(tmp_path / "s.h5"), "--no-progress"]) == 130
    assert swept == [[pytest.approx(paper_fill, rel=1e-12)]]
    assert ("count_per_cell 20 of capacity 46: 20 particles, of the paper's 36 per full cell"
            in capsys.readouterr().err)
    assert main(["dem", "run", "--specimen", str(mine), "--frequency", "1000",
                 "--acceleration", "5", "--fill-reference", "paper", "--cells", "1",
                 "--cycles", "4", "--json", "--no-progress"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert (doc["particles_per_cell"], doc["fill_reference"]) == (20, "paper")
