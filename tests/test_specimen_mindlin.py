"""The k_t model as a user option: specimen key ``[pairs] tangential_stiffness_model``,
``pidcore specimen check``, ``pidcore dem run/sweep --tangential-stiffness``, the run cache."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from pidcore import defaults
from pidcore.cli import main
from pidcore.dem import persist
from pidcore.dem.persist import dem_run_entry, load_dem_result, run_key, run_key_0_1, run_or_load
from pidcore.dem.simulate import DemConfig, LoadCase, simulate_load_case
from pidcore.dem.sweep import run_sweep
from pidcore.errors import ParameterError
from pidcore.specimen import Specimen, contact_law, describe, load_specimen, paper_specimen
from pidcore.store import Store

REPO = Path(__file__).resolve().parents[1]
#: Every specimen file the package and the samples bundle (the calibration's included).
BUNDLED = sorted([*REPO.glob("data_samples/**/*.toml"),
                  *REPO.glob("pidcore/data/specimens/*.toml")])
KEY = "pairs.tangential_stiffness_model"
PAPER = paper_specimen()
MINDLIN = PAPER.with_values({KEY: "mindlin"})
# Bookkeeping runs: one cell, few cycles (the physics test below states its own).
TINY = DemConfig(cells=1, steady_cycles=4, block_cycles=2, max_transient_cycles=2)
CASE = LoadCase(1000.0, 5.0, 25.0)


def _with_model(text: str, model: str) -> str:
    # a [pairs] table after its sub-tables is valid TOML: the key added to any file
    return text + f'\n[pairs]\ntangential_stiffness_model = "{model}"\n'


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: str(p.relative_to(REPO)))
def test_default_model_leaves_every_bundled_hash_and_mindlin_changes_it(path):
    # bundled stores and calibrations are keyed on these hashes: stating the default must not
    # move them, while a Mindlin specimen is another physics and must have another hash
    specimen = load_specimen(path)
    assert specimen.pairs.tangential_stiffness_model == "constant"
    canonical = specimen.to_toml()
    assert "tangential_stiffness_model" not in canonical
    stated = Specimen.from_text(_with_model(canonical, "constant"))
    assert stated == specimen and stated.hash == specimen.hash
    mindlin = Specimen.from_text(_with_model(canonical, "mindlin"))
    assert mindlin.pairs.tangential_stiffness_model == "mindlin"
    assert mindlin.hash != specimen.hash
    assert Specimen.from_text(mindlin.to_toml()) == mindlin  # the key round-trips
    assert mindlin.with_values({KEY: "constant"}).hash == specimen.hash


def test_bundled_dem_runs_are_of_the_default_specimen_and_keep_their_keys():
    # data_samples/dem_table3.h5 is found by run_key: its runs must still be the paper's
    # (constant k_t) coupon under today's keys, or every cached grid would be recomputed
    store = Store(REPO / "data_samples" / "dem_table3.h5")
    runs = store.list_dem_runs()
    assert set(runs["specimen_sha256"]) == {PAPER.hash}
    for key in runs["case_key"][:6]:  # six of 48: each load costs a store read
        result = load_dem_result(store.get_dem_run(key))
        assert result.specimen.pairs.tangential_stiffness_model == "constant"
        assert run_key(result.case, result.config, result.specimen) == key
        assert run_key(result.case, result.config, MINDLIN) != key


def test_the_specimen_key_reaches_the_contact_law():
    assert contact_law(PAPER).tangential_stiffness_model == "constant"
    assert contact_law(MINDLIN).tangential_stiffness_model == "mindlin"
    # everything else of the law is the same: only the k_t model was changed
    assert contact_law(MINDLIN).with_parameters(tangential_stiffness_model="constant") \
        == contact_law(PAPER)


@pytest.mark.parametrize(("value", "message"), [
    ('"hertz"', r"\[pairs\] tangential_stiffness_model: expected one of "
                r"\('constant', 'mindlin'\), got 'hertz'"),
    ("3", r"\[pairs\] tangential_stiffness_model: expected text, got 3"),
])
def test_a_bad_model_is_one_line_naming_the_key_and_the_allowed_values(tmp_path, capsys,
                                                                       value, message):
    path = tmp_path / "bad.toml"
    path.write_text(PAPER.to_toml() + f"\n[pairs]\ntangential_stiffness_model = {value}\n")
    with pytest.raises(ParameterError, match=message):
        load_specimen(path)
    assert main(["specimen", "check", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and "tangential_stiffness_model" in err
    with pytest.raises(ParameterError, match="tangential_stiffness_model: expected one of"):
        PAPER.with_values({KEY: "hertz"})


def test_an_unknown_key_of_pairs_is_named(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(PAPER.to_toml() + "\n[pairs]\ntangential_model = \"mindlin\"\n")
    with pytest.raises(ParameterError, match=r"\[pairs\] tangential_model: unknown key"):
        load_specimen(path)


def test_specimen_check_gives_mindlins_k_t_at_the_hardest_impacts_overlap(tmp_path, capsys):
    path = tmp_path / "mindlin.toml"
    path.write_text(MINDLIN.to_toml())
    assert main(["specimen", "check", str(path), "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert facts["tangential_stiffness_model"] == "mindlin"
    # analytic: the Hertz overlap of an impact grows as v^(4/5), Mindlin's k_t as sqrt(delta),
    # so k_t(v) / k_t(v_ref) = (v / v_ref)^(2/5) for each pair (the constant k_t is Mindlin's
    # at the overlap of a v_ref impact); rel 1e-12: float round-off only
    ratio = (facts["reference_impact_speed_m_s"]
             / defaults.DEM_TANGENTIAL_REFERENCE_SPEED_M_S) ** 0.4
    for pair in ("pp", "pw"):
        assert facts[f"mindlin_tangential_stiffness_{pair}_n_m"] == pytest.approx(
            ratio * facts[f"tangential_stiffness_{pair}_n_m"], rel=1e-12)
    # the constant k_t is the same number for both models: only the model differs
    assert facts["tangential_stiffness_pp_n_m"] == describe(PAPER)["tangential_stiffness_pp_n_m"]
    assert main(["specimen", "check", str(path)]) == 0
    text = capsys.readouterr().out
    assert "k_t model       mindlin" in text
    assert f"{facts['mindlin_tangential_stiffness_pw_n_m']:.4g}" in text
    plain = describe(PAPER)
    assert plain["tangential_stiffness_model"] == "constant"
    assert plain["mindlin_tangential_stiffness_pp_n_m"] is None


def test_run_cache_keeps_mindlin_and_constant_runs_apart(tmp_path, monkeypatch):
    path = tmp_path / "cache.h5"
    assert run_key(CASE, TINY, MINDLIN) != run_key(CASE, TINY, PAPER)
    run_or_load(path, None, CASE, TINY)  # the constant run is stored

    def no_simulation(*args, **kwargs):
        raise AssertionError("simulated")

    with monkeypatch.context() as patch:
        patch.setattr(persist, "simulate_load_case", no_simulation)
        with pytest.raises(AssertionError, match="simulated"):  # not served the constant run
            run_or_load(path, MINDLIN, CASE, TINY)
    result = run_or_load(path, MINDLIN, CASE, TINY)
    entry = Store(path).get_dem_run(run_key(CASE, TINY, MINDLIN))
    # provenance: the stored specimen text says mindlin, and so does the record
    stored = Specimen.from_text(entry.parameters["specimen_text"])
    assert stored.pairs.tangential_stiffness_model == "mindlin"
    assert entry.parameters["specimen_sha256"] == MINDLIN.hash
    assert entry.record["tangential_stiffness_model"] == "mindlin"
    assert load_dem_result(entry).specimen == MINDLIN == result.specimen


def test_a_sweep_never_takes_a_01_paper_run_for_a_mindlin_one(tmp_path):
    # stores of pidcore 0.1 hold the paper's (constant k_t) runs under keys without a specimen
    store = tmp_path / "old.h5"
    Store(store).add_dem_run(run_key_0_1(CASE, TINY),
                             **dem_run_entry(simulate_load_case(CASE, TINY)))
    paper = run_sweep([CASE], TINY, store_path=store, workers=1, progress=False)
    assert paper.skipped == [run_key_0_1(CASE, TINY)] and not paper.completed
    mindlin = run_sweep([CASE], TINY, store_path=store, workers=1, progress=False,
                        specimen=MINDLIN)
    assert mindlin.completed == [run_key(CASE, TINY, MINDLIN)] and not mindlin.skipped


def test_the_run_cache_finds_a_01_paper_run_as_the_sweep_does(tmp_path, monkeypatch):
    """``dem run --store`` (the run cache) reuses a run a 0.1 store holds under its old key,
    as ``dem sweep`` does, instead of simulating it again; a Mindlin run is not taken from it."""
    from pidcore.dem import persist
    from pidcore.dem.simulate import config_parameters

    store = tmp_path / "old.h5"
    old = simulate_load_case(CASE, TINY)
    # as 0.1 stored it: its inputs without specimen or code version
    entry = {**dem_run_entry(old), "parameters": config_parameters(CASE, TINY)}
    Store(store).add_dem_run(run_key_0_1(CASE, TINY), **entry)
    assert persist.stored_run_key(store, CASE, TINY) == run_key_0_1(CASE, TINY)
    assert persist.stored_run_key(store, CASE, TINY, MINDLIN) is None
    simulate = persist.simulate_load_case

    def no_paper_simulation(case, config, *, specimen=None, progress=False):
        assert specimen is not None and not specimen.is_paper(), "simulated a stored run"
        return simulate(case, config, specimen=specimen, progress=progress)

    monkeypatch.setattr(persist, "simulate_load_case", no_paper_simulation)
    again = run_or_load(store, None, CASE, TINY)
    assert again.sdc == old.sdc and again.energy_per_cycle_j == old.energy_per_cycle_j
    assert not Store(store).has_dem_run(run_key(CASE, TINY))  # nothing stored twice
    assert run_or_load(store, MINDLIN, CASE, TINY).specimen == MINDLIN


def test_dem_run_flag_overrides_the_specimen_both_ways(tmp_path, capsys):
    store = tmp_path / "s.h5"
    mindlin_file = tmp_path / "mindlin.toml"
    mindlin_file.write_text(MINDLIN.to_toml())
    base = ["dem", "run", "--frequency", "1000", "--acceleration", "5", "--fill", "25",
            "--cells", "1", "--cycles", "4", "--no-progress", "--json", "--store", str(store)]

    def run(*extra):
        assert main([*base, *extra]) == 0
        return json.loads(capsys.readouterr().out)

    constant = run()
    mindlin = run("--tangential-stiffness", "mindlin")
    assert mindlin["store_key"] != constant["store_key"] and not mindlin["reused_from_store"]
    assert (constant["tangential_stiffness_model"], mindlin["tangential_stiffness_model"]) \
        == ("constant", "mindlin")
    assert mindlin["specimen_sha256"] == MINDLIN.hash
    # the specimen file's mindlin, overridden back to constant, is the paper's run again
    back = run("--specimen", str(mindlin_file), "--tangential-stiffness", "constant")
    assert back["store_key"] == constant["store_key"] and back["reused_from_store"]
    # and the file's own model holds without the flag
    assert run("--specimen", str(mindlin_file))["store_key"] == mindlin["store_key"]
    assert main([*base[:-3], "--tangential-stiffness", "mindlin"]) == 0
    assert ", k_t mindlin\n" in capsys.readouterr().out


def test_mindlin_load_case_closes_its_energy_balance_and_differs_from_constant():
    # same seed, packing and time step (8e-7 s: below both models' auto step), so the only
    # difference between the runs is the k_t the kernel uses
    config = DemConfig(cells=1, steady_cycles=10, block_cycles=5, max_transient_cycles=5,
                       time_step=8e-7)
    case = LoadCase(100.0, 5.0, 50.0)
    constant = simulate_load_case(case, config)
    mindlin = simulate_load_case(case, config, specimen=MINDLIN)
    assert mindlin.time_step_s == constant.time_step_s
    assert mindlin.energy_dissipated_friction_j != constant.energy_dissipated_friction_j
    # walls' work = change of mechanical energy + dissipation within 1 % (the issue's bound;
    # measured 0.2 % for this case), with the Mindlin spring's energy in the mechanical part
    assert abs(mindlin.energy_balance_error) <= 0.01
    assert mindlin.energy_dissipated_friction_j > 0


def test_calibrated_damping_accepts_mindlin_and_calibrates_the_same_head_on_impact(monkeypatch):
    # alpha is tuned on a head-on impact, where no tangential spring acts: the k_t model must
    # neither refuse the calibration nor change what is calibrated
    from pidcore.dem import impact

    calls = []

    class Reached(Exception):
        pass

    def record(*args, **kwargs):
        calls.append((args, kwargs))
        raise Reached

    monkeypatch.setattr(impact, "calibrate_damping_coefficient", record)
    config = DemConfig(cells=1, steady_cycles=4, time_step=8e-7,
                       damping_coefficient="calibrated")
    own = MINDLIN.with_values({"pairs.particle_wall.restitution": 0.5})
    for specimen in (PAPER, MINDLIN, own):
        with pytest.raises(Reached):
            simulate_load_case(CASE, config, specimen=specimen)
    assert len(calls) == 3
    # the same target, step, mode and cell; the laws tried differ in the k_t model alone
    assert calls[0][0] == calls[1][0]
    assert calls[0][1]["geometry"] == calls[1][1]["geometry"]
    laws = [kwargs["law"](0.3) for _, kwargs in calls]
    assert dataclasses.replace(laws[1], tangential_stiffness_model="constant") == laws[0]
    # a specimen whose contact differs from the tables' is calibrated to its own e_n (it
    # was refused while the calibration knew the tables' laws only)
    assert calls[2][0][:2] == (0.5, "wall") and laws[2].pair_wall.restitution == 0.5


def test_the_sdc_model_does_not_average_mindlin_with_constant_runs():
    import pandas as pd

    from pidcore.model.sdc_model import select_runs

    runs = pd.DataFrame({"frequency_hz": [50.0, 50.0], "acceleration_g": [5.0, 5.0],
                         "fill_percent": [50.0, 50.0], "sdc": [0.1, 0.2],
                         "tangential_stiffness_model": ["constant", "mindlin"]})
    with pytest.raises(ParameterError, match="differ in tangential_stiffness_model"):
        select_runs(runs)
    assert select_runs(runs, where={"tangential_stiffness_model": "mindlin"})["sdc"].tolist() \
        == [0.2]


def test_specimen_check_says_what_sets_the_time_step(tmp_path, capsys):
    """The step line said "(auto, for that impact)", the contact time's, also where Mindlin's
    spring at the largest overlap the DEM takes, a shorter period, set it (2.5 x shorter than
    the contact for 2 mm tungsten carbide spheres)."""
    lines = {}
    for name, specimen in (("constant", PAPER), ("mindlin", MINDLIN)):
        path = tmp_path / f"{name}.toml"
        path.write_text(specimen.to_toml())
        facts = describe(specimen)
        assert main(["specimen", "check", str(path)]) == 0
        lines[name] = {line[:16].strip(): line[16:] for line in
                       capsys.readouterr().out.splitlines()}
        step = f"{facts['time_step_s']:.4g} s at 50 Hz, 10 g (auto: 1/10 of "
        grid = ("), the smallest of the Table 3 grid; a run takes its own load case's, "
                "shortened to a whole number of steps per output sample (dem run prints that "
                "as dt)")
        # rel=1e-15 below: the step is that time divided by 10 once, as here (one rounding)
        if name == "constant":  # the contact is the shorter: its tenth is the step
            assert facts["contact_time_s"] < facts["tangential_period_s"]
            assert facts["time_step_s"] == pytest.approx(facts["contact_time_s"] / 10,
                                                         rel=1e-15)
            assert lines[name]["time step"] == step + "that contact time" + grid
        else:
            assert facts["tangential_period_s"] < facts["contact_time_s"]
            assert facts["time_step_s"] == pytest.approx(facts["tangential_period_s"] / 10,
                                                         rel=1e-15)
            assert lines[name]["time step"] == step + "the stuck tangential period" + grid
            assert lines[name]["contact time"].endswith(
                "(at the largest overlap the DEM takes, 5 % of the radius)")
    assert "largest overlap" not in lines["constant"]["contact time"]
