"""Stored DEM runs that are the same simulation under two keys (two fills that round to the
same particle count, the same seed and settings): counted once in pooling, found by the run
cache and by sweeps instead of simulated again, and said so."""

from __future__ import annotations

import json
import math

import pandas as pd
import pytest

from pidcore.cli import main
from pidcore.compare.align import Aligner, dem_cases, simulation_identity
from pidcore.dem import persist
from pidcore.dem.persist import run_key, run_or_load, stored_run_key
from pidcore.dem.simulate import DemConfig, LoadCase, particles_per_cell
from pidcore.dem.sweep import run_sweep
from pidcore.report.table import build_report_table
from pidcore.store import Store

# Bookkeeping tests: one cell, few cycles (physics is tested elsewhere).
TINY = DemConfig(cells=1, steady_cycles=4, block_cycles=2, max_transient_cycles=2)
CASE = LoadCase(1000.0, 5.0, 25.0)
# 25 % and 26 % of the acrylic cell's 22 particles both round to 6 particles per cell
SAME = LoadCase(1000.0, 5.0, 26.0)


def _params(fill: float, seed: int = 12345) -> str:
    return json.dumps({"case_frequency_hz": 1000.0, "case_acceleration_g": 5.0,
                       "case_fill_percent": fill, "case_material": "acrylic",
                       "case_direction": "z", "config_seed": seed, "config_cells": 2,
                       "specimen_sha256": "abc", "specimen_text": "x",
                       "dem_code_version": 1})


def _runs(*rows: tuple[str, float, int, int]) -> pd.DataFrame:
    """A listing of runs (key, fill, seed, particles per cell), all with SDC 1.475 and
    standard error 0.010788: the numbers of the trial's duplicate runs."""
    return pd.DataFrame({
        "case_key": [r[0] for r in rows], "frequency_hz": 1000.0, "acceleration_g": 5.0,
        "fill_percent": [r[1] for r in rows], "material": "acrylic", "direction": "z",
        "sdc": 1.4751179850178764, "sdc_stderr": 0.010788269155923347,
        "particles_per_cell": [r[3] for r in rows],
        "parameters_json": [_params(r[1], r[2]) for r in rows]})


def test_identity_ignores_the_stated_fill_but_not_the_particle_count_or_seed():
    base = simulation_identity(_params(50.0), 11)
    assert base is not None and simulation_identity(_params(50.2), 11) == base
    assert simulation_identity(_params(50.0), 12) != base
    assert simulation_identity(_params(50.0, seed=1), 11) != base
    assert simulation_identity("", 11) is None and simulation_identity(_params(50.0), None) is None


def test_the_same_simulation_under_two_keys_is_counted_once():
    """The trial: fills 50 and 50.2 % (11 particles each, seed 12345) pooled as two runs with
    standard error 0.010788 / sqrt(2) = 0.007628."""
    runs = _runs(("a", 50.0, 12345, 11), ("b", 50.2, 12345, 11))
    (case,) = dem_cases(runs)
    assert case.n_runs == 1 and case.run_keys == ("a",) and case.duplicate_keys == ("b",)
    # one run: its own numbers, bit for bit (pooled_mean returns a single run unchanged)
    assert case.sdc_stderr == 0.010788269155923347
    table = build_report_table(runs, None, None)
    assert table["DEM runs [-]"].tolist() == [1]
    assert table["SDC DEM stderr [-]"].tolist() == [0.010788269155923347]
    note = table["note"].iloc[0]
    assert "1 stored DEM run(s) counted once" in note and "fill 50.2 %" in note
    assert "DEM runs pooled" not in note
    # and in the notes the console prints (its short table has no note column)
    assert any("1 row(s) have stored DEM runs counted once" in n
               for n in table.attrs["notes"])
    # the app's Compare tab aligns through the same cases and says it too
    aligned = Aligner.from_tables(runs).align(LoadCase(1000.0, 5.0, 50.0))
    assert aligned.sdc_dem_stderr == 0.010788269155923347 and "counted once" in aligned.message
    # guards against counting too few: another seed is another simulation, pooled ...
    runs = _runs(("a", 50.0, 12345, 11), ("b", 50.2, 777, 11))
    (case,) = dem_cases(runs)
    assert case.n_runs == 2 and case.duplicate_keys == ()
    # (identical values: the within-run error sqrt(2 se^2) / 2 = se / sqrt(2), to rounding)
    assert case.sdc_stderr == pytest.approx(0.010788269155923347 / math.sqrt(2), rel=1e-12)
    # ... and runs that do not record their inputs are all counted (nothing shows a repeat)
    runs = _runs(("a", 50.0, 12345, 11), ("b", 50.2, 12345, 11)).drop(columns="parameters_json")
    assert dem_cases(runs)[0].n_runs == 2


def test_of_one_simulation_the_run_nearest_the_measured_fill_is_kept_and_names_the_row():
    """The trial: runs at 50 % (seed 12345), 50.2 % (seed 12345, the same simulation) and
    50 % (seed 7), listed 50.2 % first (its key sorts first): the 50 % run was dropped and
    the row said packing ratio 50.2 %, load case ...fill50.2pct, as did Compare's message."""
    runs = _runs(("b", 50.2, 12345, 11), ("a", 50.0, 12345, 11), ("c", 50.0, 7, 11))
    measured = pd.DataFrame({"frequency_hz": [1000.0], "acceleration_g": [5.0],
                             "fill_percent": [50.0], "sdc": [1.5], "sdc_stderr": [0.02],
                             "source": ["m.csv"]})
    table = build_report_table(runs, measured, None)
    assert (table["packing ratio [%]"].tolist(), table["load case"].tolist()) == (
        [50.0], ["f1000Hz_a5g_fill50pct_acrylic_z"])
    assert table["DEM runs [-]"].tolist() == [2] and "fill 50.2 %" in table["note"].iloc[0]
    aligned = Aligner.from_tables(runs, reference_fills=[50.0]).align(
        LoadCase(1000.0, 5.0, 50.0))
    assert aligned.grid_case.run_keys == ("a", "c") and aligned.grid_case.duplicate_keys == ("b",)
    assert aligned.message.startswith("DEM grid case f1000Hz_a5g_fill50pct_acrylic_z (2 run(s)")
    # with nothing measured the fill most runs state wins (two of three say 50 %)
    (case,) = dem_cases(runs)
    assert (case.load_case.fill_percent, case.run_keys) == (50.0, ("a", "c"))
    # a measurement at 50.2 % keeps the 50.2 % run of the pair; the case is named by the fill
    # its kept runs state most, of a tie the one nearest the measurement
    pair = _runs(("a", 50.0, 12345, 11), ("b", 50.2, 12345, 11))
    (case,) = dem_cases(pair, reference_fills=[50.2])
    assert (case.load_case.fill_percent, case.run_keys) == (50.2, ("b",))
    (case,) = dem_cases(runs, reference_fills=[50.2])
    assert case.run_keys == ("b", "c") and case.load_case.fill_percent == 50.2


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    """A store holding the run of CASE (fill 25 %)."""
    path = tmp_path_factory.mktemp("same") / "runs.h5"
    result = run_or_load(path, None, CASE, TINY)
    return path, result


def _no_simulation(*args, **kwargs):
    raise AssertionError("simulated a run whose simulation is in the store")


def test_run_cache_finds_the_run_of_another_fill_with_the_same_particle_count(stored,
                                                                              monkeypatch):
    path, first = stored
    assert particles_per_cell(25.0, "acrylic")[0] == particles_per_cell(26.0, "acrylic")[0] == 6
    monkeypatch.setattr(persist, "simulate_load_case", _no_simulation)
    assert run_key(SAME, TINY) != run_key(CASE, TINY)  # keys are not changed
    assert stored_run_key(path, SAME, TINY) == run_key(CASE, TINY)
    again = run_or_load(path, None, SAME, TINY)
    assert again.sdc == first.sdc and again.energy_per_cycle_j == first.energy_per_cycle_j
    assert again.case.fill_percent == 25.0  # stated at the fill it was stored with
    assert len(Store(path).list_dem_runs()) == 1
    # another seed is another simulation: not found
    other = DemConfig(cells=1, steady_cycles=4, block_cycles=2, max_transient_cycles=2, seed=7)
    assert stored_run_key(path, SAME, other) is None


def test_dem_run_cli_reuse_note(stored, monkeypatch, capsys, tmp_path):
    """`dem run --fill 26` after a run of fill 25 (6 particles per cell either way) reuses it
    and says so; it simulated again before."""
    import shutil

    path = tmp_path / "runs.h5"
    shutil.copy(stored[0], path)
    config = DemConfig(cells=1, steady_cycles=4)  # what the options below ask for
    run_or_load(path, None, CASE, config)  # the run of fill 25 % with the CLI's settings
    monkeypatch.setattr(persist, "simulate_load_case", _no_simulation)
    args = ["dem", "run", "--frequency", "1000", "--acceleration", "5", "--fill", "26",
            "--cells", "1", "--cycles", "4", "--store", str(path), "--no-progress"]
    assert main([*args, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["reused_from_store"] is True and doc["store_key"] == run_key(CASE, config)
    assert doc["fill_percent"] == 25.0 and doc["particles_per_cell"] == 6
    assert any("fill 26 % asked; reused the stored run of fill 25 %" in n for n in doc["notes"])
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "fill 26 % asked; reused the stored run of fill 25 %" in text
    assert f"reused from {path} as {run_key(CASE, config)}" in text


def test_dem_run_reuse_note_prints_fills_as_the_other_lines_do(tmp_path, monkeypatch,
                                                              capsys):
    """A stored fill of 6 of 22 particles read "reused the stored run of fill
    27.272727272727273 %" where the summary line of the same run says 27.2727 %."""
    from pidcore.errors import apart

    path = tmp_path / "runs.h5"
    config = DemConfig(cells=1, steady_cycles=4)  # what the options below ask for
    stored_fill = 100 * 6 / 22  # exactly 6 of the acrylic cell's 22 particles
    run_or_load(path, None, LoadCase(1000.0, 5.0, stored_fill), config)
    monkeypatch.setattr(persist, "simulate_load_case", _no_simulation)
    assert main(["dem", "run", "--frequency", "1000", "--acceleration", "5", "--fill", "26",
                 "--cells", "1", "--cycles", "4", "--store", str(path), "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "fill 26 % asked; reused the stored run of fill 27.2727 %: " in text
    assert "fill 27.2727 % (6 of 22" in text  # the summary's own spelling of the same fill
    # two fills alike in 6 digits get the digits that tell them apart, no more
    assert apart(27.2727, stored_fill) == ("27.2727", "27.27273")
    assert apart(26.0, stored_fill) == ("26", "27.2727")
    assert apart(0.1 + 0.2, 0.3) == ("0.30000000000000004", "0.3")


def test_sweep_skips_a_fill_whose_simulation_is_stored_and_says_so(stored, tmp_path,
                                                                  monkeypatch):
    import shutil

    import pidcore.dem.sweep as sweep

    path = tmp_path / "runs.h5"
    shutil.copy(stored[0], path)
    monkeypatch.setattr(sweep, "simulate_load_case", _no_simulation)
    summary = run_sweep([CASE, SAME], TINY, store_path=path, workers=1, progress=False)
    assert not summary.completed and summary.skipped == [run_key(CASE, TINY)] * 2
    assert [c["status"] for c in summary.cases] == ["already stored",
                                                    "same simulation as a stored run"]
    assert [c["fill_percent"] for c in summary.cases] == [25.0, 26.0]
    assert [c["stored_fill_percent"] for c in summary.cases] == [25.0, 25.0]
    assert len(Store(path).list_dem_runs()) == 1


def test_sweep_runs_two_fills_of_one_particle_count_once(tmp_path):
    path = tmp_path / "runs.h5"
    summary = run_sweep([CASE, SAME], TINY, store_path=path, workers=1, progress=False)
    assert summary.completed == [run_key(CASE, TINY)]
    assert [c["status"] for c in summary.cases] == [
        "simulated", "same simulation as another case of this sweep"]
    assert {c["store_key"] for c in summary.cases} == {run_key(CASE, TINY)}
    assert len(Store(path).list_dem_runs()) == 1


def test_sweep_json_gives_each_cases_key_and_results(stored, tmp_path, capsys):
    """`dem sweep --json` printed only counts: {"completed": 0, "skipped": 2, ...}."""
    import shutil

    path = tmp_path / "runs.h5"
    shutil.copy(stored[0], path)
    assert main(["dem", "sweep", "--frequencies", "1000", "--accelerations", "5",
                 "--fills", "25,50", "--cells", "2", "--cycles", "4", "--workers", "1",
                 "--store", str(path), "--no-progress", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    runs = Store(path).list_dem_runs().set_index("case_key")
    assert doc["completed"] == 2 and len(doc["cases"]) == 2
    for case, fill in zip(doc["cases"], (25.0, 50.0), strict=True):
        row = runs.loc[case["store_key"]]
        assert case["status"] == "simulated"
        assert (case["frequency_hz"], case["acceleration_g"], case["fill_percent"]) == (
            1000.0, 5.0, fill)
        # the stored numbers, unchanged
        for name in ("sdc", "sdc_stderr", "loss_factor", "particles_per_cell", "seed",
                     "cells_simulated"):
            assert case[name] == row[name], name
        assert isinstance(case["steady_detected"], bool)
    assert doc["cases"][0]["particles_per_cell"] == 6


def test_runs_of_two_particle_counts_within_the_fill_tolerance_are_two_cases():
    """The trial: runs at 40 % (18 particles per cell) and 40.5 % (19) of one specimen, within
    the 0.5-point fill tolerance, were pooled into one row with 2 runs (a standard error as of
    two replicates, of two different beds), its label moving with the measurements present.
    They are two cases now; a measurement at 40 % meets the 18-particle one, at 40.5 % the
    other. Pooling (``pool``) still pools them, as asked."""
    runs = _runs(("a", 40.0, 12345, 18), ("b", 40.5, 12345, 19))
    cases = dem_cases(runs)
    assert [(c.load_case.fill_percent, c.particles_per_cell, c.n_runs) for c in cases] == [
        (40.0, 18.0, 1), (40.5, 19.0, 1)]
    aligner = Aligner.from_tables(runs)
    assert aligner.align(LoadCase(1000.0, 5.0, 40.0)).grid_case.run_keys == ("a",)
    assert aligner.align(LoadCase(1000.0, 5.0, 40.5)).grid_case.run_keys == ("b",)
    (pooled,) = dem_cases(runs, pool_settings=True)
    assert pooled.n_runs == 2
    # a run that does not state its count joins either (nothing shows it is another bed)
    unknown = _runs(("a", 40.0, 12345, 18), ("c", 40.2, 777, 18))
    unknown["particles_per_cell"] = [18.0, math.nan]
    assert [c.n_runs for c in dem_cases(unknown)] == [2]


def _stated_cycles(cycles: object, block: int = 10) -> str:
    params = json.loads(_params(50.0))
    params.update({"config_steady_cycles": cycles, "config_block_cycles": block})
    return json.dumps(params)


def test_the_automatic_steady_cycles_stated_are_the_defaults_key_identity_and_settings():
    """`--cycles 80` is the documented default (80 cycles, blocks of 10), the same simulation
    to the bit, but it was keyed apart from the default's run: simulated again, and a report
    row of its own ("steady cycles 80" beside "auto")."""
    from pidcore.compare.align import settings_hash

    assert run_key(CASE, DemConfig(cells=1, steady_cycles=80)) == run_key(CASE,
                                                                           DemConfig(cells=1))
    assert run_key(CASE, DemConfig(cells=1, steady_cycles=90)) != run_key(CASE,
                                                                           DemConfig(cells=1))
    # with blocks of 100 cycles the automatic count is 100: 80 asks for another run
    assert run_key(CASE, DemConfig(cells=1, steady_cycles=80, block_cycles=100)) \
        != run_key(CASE, DemConfig(cells=1, block_cycles=100))
    # runs stored with 80 stated before: the same simulation and settings as the default's
    automatic = simulation_identity(_stated_cycles(""), 11)
    assert simulation_identity(_stated_cycles(80), 11) == automatic
    assert simulation_identity(_stated_cycles(90), 11) != automatic
    assert simulation_identity(_stated_cycles(80, block=100), 11) \
        != simulation_identity(_stated_cycles("", block=100), 11)
    assert settings_hash(_stated_cycles(80)) == settings_hash(_stated_cycles(""))
    assert settings_hash(_stated_cycles(90)) != settings_hash(_stated_cycles(""))
    # one report row of one run, not two rows of "steady cycles 80" and "auto"
    runs = _runs(("auto", 50.0, 12345, 11), ("stated", 50.0, 12345, 11))
    runs["parameters_json"] = [_stated_cycles(""), _stated_cycles(80)]
    table = build_report_table(runs, None, None)
    assert table["DEM runs [-]"].tolist() == [1]
    assert table["DEM settings"].str.contains("steady cycles auto").all()
    assert any("counted once" in n and "the automatic count of steady cycles stated" in n
               for n in table.attrs["notes"])


def test_dem_run_with_the_default_cycles_stated_reuses_the_defaults_run(tmp_path, capsys):
    store = tmp_path / "runs.h5"
    case = ["--frequency", "1000", "--acceleration", "5", "--fill", "25", "--cells", "1",
            "--no-progress", "--store", str(store)]
    assert main(["dem", "run", *case]) == 0
    assert "saved to" in capsys.readouterr().out
    before = store.read_bytes()
    assert main(["dem", "run", *case, "--cycles", "80"]) == 0
    assert "reused from" in capsys.readouterr().out
    assert store.read_bytes() == before  # nothing simulated, nothing written


def test_a_runs_key_and_its_identity_hash_its_inputs_by_one_rule():
    # run_key, run_key_0_1, simulation_identity and the settings hash each wrote the sha256
    # of the sorted JSON themselves; a run meets its cached copy only where they agree
    import hashlib
    import json

    from pidcore.compare.align import parameters_digest, simulation_identity
    from pidcore.dem.persist import run_key, run_parameters
    from pidcore.dem.simulate import DemConfig, LoadCase

    case, config = LoadCase(50.0, 5.0, 50.0), DemConfig(cells=2, seed=7)
    params = run_parameters(case, config)
    keyed = {k: v for k, v in params.items() if k != "specimen_text"}
    # the stored spelling, to the letter: a key written by any earlier pidcore is found again
    expected = hashlib.sha256(json.dumps(keyed, sort_keys=True, default=str).encode())
    assert parameters_digest(keyed) == expected.hexdigest()
    assert run_key(case, config).endswith(f"_seed7_cells2_{expected.hexdigest()[:10]}")
    identity = {k: v for k, v in keyed.items() if k != "case_fill_percent"}
    assert simulation_identity(params, 11) == parameters_digest({**identity,
                                                                 "particles_per_cell": 11})
