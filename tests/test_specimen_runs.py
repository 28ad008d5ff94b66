"""DEM runs of a specimen: plumbing of masses and cell count, the run cache, provenance, CLI."""

from __future__ import annotations

import json
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from pidcore import defaults
from pidcore.cli import main
from pidcore.dem import persist
from pidcore.dem.persist import (
    dem_run_entry,
    load_dem_result,
    rekey_dem_store,
    run_key,
    run_or_load,
)
from pidcore.dem.simulate import (
    DemConfig,
    LoadCase,
    calibrated_contact_law,
    choose_time_step,
    drive_sampling,
    simulate_load_case,
)
from pidcore.errors import ParameterError
from pidcore.specimen import Specimen, contact_law, describe, load_specimen, paper_specimen
from pidcore.store import Store

REPO = Path(__file__).resolve().parents[1]
STEEL = REPO / "data_samples" / "specimens" / "steel_6mm.toml"
# Bookkeeping tests: one cell, few cycles (physics is tested elsewhere).
TINY = DemConfig(cells=1, steady_cycles=4, block_cycles=2, max_transient_cycles=2)
CASE = LoadCase(1000.0, 5.0, 25.0)


def _same_numbers(a, b) -> None:
    da, db = a.to_dict(), b.to_dict()
    assert da.keys() == db.keys()
    for k in da:
        assert da[k] == db[k] or (da[k] != da[k] and db[k] != db[k]), k  # NaN == NaN here
    for name in a.array_names():
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_run_cache_reuses_a_stored_run_and_never_recomputes(tmp_path, monkeypatch):
    path = tmp_path / "cache.h5"
    first = run_or_load(path, None, CASE, TINY)
    assert Store(path).has_dem_run(run_key(CASE, TINY))

    def no_simulation(*args, **kwargs):
        raise AssertionError("run_or_load simulated a run that is in the store")

    monkeypatch.setattr(persist, "simulate_load_case", no_simulation)
    again = run_or_load(path, paper_specimen(), CASE, TINY)  # the default, stated
    _same_numbers(first, again)
    assert again.specimen == paper_specimen()
    # another specimen is another run: not served from the cache
    heavier = paper_specimen().with_values({"coupon.fixture_mass_kg": 0.05})
    assert run_key(CASE, TINY, heavier) != run_key(CASE, TINY)
    with pytest.raises(AssertionError, match="simulated"):
        run_or_load(path, heavier, CASE, TINY)


def test_stored_run_carries_specimen_text_and_hash(tmp_path):
    path = tmp_path / "s.h5"
    heavier = paper_specimen().with_values({"coupon.fixture_mass_kg": 0.05})
    result = run_or_load(path, heavier, CASE, TINY)
    entry = Store(path).get_dem_run(run_key(CASE, TINY, heavier))
    stored = Specimen.from_text(entry.parameters["specimen_text"])
    assert stored == heavier and stored.hash == entry.parameters["specimen_sha256"]
    assert not entry.record["specimen_is_paper"]
    assert entry.parameters["dem_code_version"] == persist.DEM_CODE_VERSION
    _same_numbers(result, load_dem_result(entry))


def test_fixture_mass_changes_only_the_vibrated_mass():
    # the fixture moves rigidly with the cells: the particles see the same drive, so the
    # tallies are identical bit for bit and the SDC scales with 1 / m_c (Eq. 10)
    base = simulate_load_case(CASE, TINY)
    heavy = simulate_load_case(CASE, TINY, specimen=paper_specimen().with_values(
        {"coupon.fixture_mass_kg": 0.1}))
    assert heavy.energy_per_cycle_j == base.energy_per_cycle_j
    assert heavy.vibrated_mass_kg == pytest.approx(base.vibrated_mass_kg + 0.1, rel=1e-15)
    assert heavy.sdc == pytest.approx(
        base.sdc * base.vibrated_mass_kg / heavy.vibrated_mass_kg, rel=1e-12)
    # the virtual shaker carries the fixture too: F = (coupon + fixture) a + walls' force
    extra = (heavy.shaker_force_n - heavy.wall_force_n) - (base.shaker_force_n - base.wall_force_n)
    accel = (base.shaker_force_n - base.wall_force_n) / base.coupon_mass_kg
    np.testing.assert_allclose(extra, 0.1 * accel, rtol=1e-9, atol=1e-12)


def test_a_specimen_unlike_the_papers_runs_end_to_end():
    steel = load_specimen(STEEL)
    facts = describe(steel)
    assert not facts["is_paper"] and facts["cells_per_coupon"] == 286
    r = simulate_load_case(LoadCase(500.0, 5.0, 50.0, "steel"),
                           DemConfig(cells=2, steady_cycles=40),
                           specimen=steel)
    # particle count and masses follow from the specimen, not from the paper's coupon
    assert r.particles_full_cell == facts["capacity_per_cell"]
    assert r.particles_per_cell == round(0.5 * facts["capacity_per_cell"])
    m_particle = 7850.0 * 4.0 / 3.0 * np.pi * 1e-3**3
    assert r.vibrated_mass_kg == pytest.approx(
        0.0333 + 0.015 + 286 * r.particles_per_cell * m_particle, rel=1e-12)
    # coupon energies are 286 x the cell mean (not 441)
    steady = r.dissipation_per_cell_cycle_j[:, r.steady_start_cycle:]
    assert r.energy_per_cycle_j == pytest.approx(286 * steady.mean(), rel=1e-12)
    assert r.to_dict()["material"] == "steel" and r.coupon_cells == 286
    # the step the run took and reports (dem run's dt) is drive_sampling's, which README
    # quotes for this load case (6.79e-7 s, below the automatic 6.98e-7 s)
    contact_step = choose_time_step(r.case, contact_law(steel), steel.geometry(), "auto")
    assert r.time_step_s == drive_sampling(r.case, contact_step,
                                           DemConfig().samples_per_cycle)[1]
    # closure: the walls' energy balance, and the virtual shaker's Eq. 11 energy per cycle
    # against the tally (1 %: the criterion; measured 0.3-0.5 % for 4 cells)
    assert abs(r.energy_balance_error) < 0.01
    shaker = r.power_analysis().energy_per_cycle_j
    assert shaker == pytest.approx(r.energy_per_cycle_j + r.stored_energy_change_per_cycle_j,
                                   rel=0.01)
    assert r.sdc > 0


def test_rekey_gives_legacy_runs_todays_key_and_provenance(tmp_path):
    legacy = tmp_path / "legacy.h5"
    result = simulate_load_case(CASE, TINY)
    entry = dem_run_entry(result)
    for name in ("specimen_text", "specimen_sha256", "specimen_name", "dem_code_version"):
        entry["parameters"].pop(name)  # as stored before specimens existed
    Store(legacy).add_dem_run("old_key", **entry)
    assert rekey_dem_store(legacy, tmp_path / "new.h5") == 1
    new = Store(tmp_path / "new.h5").get_dem_run(run_key(CASE, TINY))
    assert new.parameters["specimen_sha256"] == paper_specimen().hash
    _same_numbers(result, load_dem_result(new))


def test_specimen_check_cli(capsys, tmp_path):
    assert main(["specimen", "check", str(STEEL)]) == 0
    out = capsys.readouterr().out
    assert "capacity 46 particles per cell" in out and "vibrated" in out and "time step" in out
    assert main(["specimen", "check", str(STEEL), "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert facts["capacity_per_cell"] == 46 and facts["time_step_s"] < facts["contact_time_s"]
    bad = tmp_path / "bad.toml"
    bad.write_text(STEEL.read_text().replace("mass_kg = 0.0333", "mass_kg = -0.0333"))
    assert main(["specimen", "check", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(bad) in err and "[coupon] mass_kg" in err


def test_a_specimen_file_is_labelled_by_its_name_and_six_hex_digits_in_every_command(
        capsys, tmp_path):
    """`specimen check` showed 16 hex digits of the file's sha256, `dem run` and `dem sweep` 12,
    the app and reports `steel_6mm [beeac8]` (6): one file read as three. Every command now
    labels it as the pages do (:func:`pidcore.specimen.hashed_name`)."""
    from pidcore.specimen import hashed_name, tested_label

    steel = load_specimen(STEEL)
    label = f"steel_6mm [{steel.hash[:6]}]"
    # the one rule: the label a test of this file is shown under, and a DEM run of it
    assert hashed_name(steel.name, steel.hash) == tested_label(steel.name, steel.hash) == label
    longer = steel.hash[:7]  # any longer prefix shown is another spelling of the label
    assert main(["specimen", "check", str(STEEL)]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"specimen        {label} ({STEEL}): OK, not the paper's coupon")
    assert longer not in out
    store = tmp_path / "s.h5"
    common = ["--specimen", str(STEEL), "--cells", "1", "--cycles", "4", "--no-progress",
              "--store", str(store)]
    assert main(["dem", "run", "--frequency", "1000", "--acceleration", "5", *common]) == 0
    out = capsys.readouterr().out
    assert f"specimen        {label} (own specimen): 286 hexagonal cells" in out
    assert longer not in out
    # the sweep (of the file's stated 50 %: the run above, reused) names the stored run's file
    assert main(["dem", "sweep", "--frequencies", "1000", "--accelerations", "5",
                 "--workers", "1", *common]) == 0
    out = capsys.readouterr().out
    # the summary line (the runs' own notes follow the case lines)
    (summary,) = [line for line in out.splitlines() if f"1 already in {store}" in line]
    assert summary.endswith(f"; specimen {label}")
    assert longer not in out


def test_dem_run_cli_with_specimen_and_run_cache(capsys, tmp_path):
    store = tmp_path / "s.h5"
    args = ["dem", "run", "--specimen", str(STEEL), "--frequency", "1000", "--acceleration",
            "5", "--cells", "1", "--cycles", "4", "--no-progress", "--json", "--store",
            str(store)]
    assert main(args) == 0  # --fill from the specimen's fill_percent
    first = json.loads(capsys.readouterr().out)
    assert first["reused_from_store"] is False and "_steel_z_seed" in first["store_key"]
    assert first["fill_percent"] == 50.0 and first["coupon_cells"] == 286
    before = store.read_bytes()
    assert main(args) == 0
    second = json.loads(capsys.readouterr().out)
    assert second["reused_from_store"] is True and second["sdc"] == first["sdc"]
    # one meaning per key, as in `specimen check --json`: the coupon alone, and the sum apart
    # (exact: the numbers are the file's, passed through)
    for out in (first, second):
        assert out["coupon_mass_kg"] == 0.0333 and out["fixture_mass_kg"] == 0.015
        assert out["moving_mass_kg"] == 0.0333 + 0.015
    assert main(["specimen", "check", str(STEEL), "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert (facts["coupon_mass_kg"], facts["moving_mass_kg"]) == (0.0333, 0.0333 + 0.015)
    assert store.read_bytes() == before  # reused, nothing written


def test_case_material_must_not_contradict_the_specimen():
    with pytest.raises(ParameterError, match="holds 'acrylic' particles"):
        simulate_load_case(LoadCase(1000, 5, 25, material="aluminium"), TINY,
                           specimen=paper_specimen())


@pytest.mark.usefixtures("undrawn_report_figures")
def test_report_compares_runs_of_one_specimen_and_the_paper_only_for_its_coupon(tmp_path,
                                                                                 capsys):
    import pandas as pd

    store = tmp_path / "runs.h5"
    own = paper_specimen().with_values({"coupon.fixture_mass_kg": 0.05, "cell.count": 400})
    own_file = tmp_path / "own.toml"
    own_file.write_text(own.to_toml())
    paper_run = run_or_load(store, None, CASE, TINY)
    own_run = run_or_load(store, own, CASE, TINY)
    assert own_run.sdc != paper_run.sdc

    def report(*extra):
        out = tmp_path / f"report{len(extra)}"
        assert main(["report", "--dem-store", str(store), "--out", str(out), "--format", "csv",
                     *extra]) == 0
        capsys.readouterr()
        return pd.read_csv(out / "report.csv", comment="#")

    default = report()  # the paper's coupon: its run, beside the paper's Table 3
    assert default["SDC DEM (ours) [-]"].tolist() == pytest.approx([paper_run.sdc])
    assert default["SDC DEM (paper) [-]"].notna().all()
    mine = report("--specimen", str(own_file))  # only the own specimen's run, no paper
    assert mine["SDC DEM (ours) [-]"].tolist() == pytest.approx([own_run.sdc])
    assert mine["SDC DEM (paper) [-]"].isna().all()


@pytest.mark.usefixtures("undrawn_report_figures")
def test_a_measurement_of_an_own_specimen_meets_its_dem_run_in_the_report(tmp_path, capsys):
    # steel spheres: with --specimen the measurement's material is the specimen's, so it
    # shares a row with the steel DEM run; without, it is an acrylic case of its own
    import pandas as pd

    from pidcore.constants import STANDARD_GRAVITY
    from pidcore.io import write_measurement
    from pidcore.records import Channel, Measurement
    from pidcore.signal import synthesize_shaker_record

    steel = load_specimen(STEEL)
    store = tmp_path / "runs.h5"
    run = run_or_load(store, steel, LoadCase(1000.0, 5.0, 50.0, material="steel"), TINY)
    rate = 51200.0
    rec = synthesize_shaker_record(mass_kg=0.05, acceleration_amplitude_m_s2=5 * STANDARD_GRAVITY,
                                   frequency_hz=1000.0, sample_rate_hz=rate, n_periods=40,
                                   viscous_damping_n_s_m=5.0)
    meas = tmp_path / "own_run_fill50.csv"  # no material in the name: the specimen's
    write_measurement(Measurement("m", (Channel("Force", "force", rec.force_n, rate, "N"),
                                        Channel("LDV", "velocity", rec.velocity_m_s, rate,
                                                "m/s"))), meas)

    def report(*extra):
        out = tmp_path / f"report{len(extra)}"
        assert main(["report", str(meas), "--dem-store", str(store), "--out", str(out),
                     "--format", "csv", *extra]) == 0
        return pd.read_csv(out / "report.csv", comment="#"), capsys.readouterr().out

    table, out = report("--specimen", str(STEEL))
    assert "material: specimen" in out
    both = table[table["SDC measured (Eq. 11) [-]"].notna()]
    assert len(table) == 1 and len(both) == 1  # one row: measurement and run together
    assert both["SDC DEM (ours) [-]"].tolist() == pytest.approx([run.sdc])
    table, _ = report()  # the paper's coupon: an acrylic measurement, no steel run
    assert table["SDC DEM (ours) [-]"].isna().all()


@pytest.fixture(scope="module")
def two_specimen_store(tmp_path_factory):
    """A store with one run of the paper's coupon and one of an own specimen (same name, other
    coupon: another hash), and that own specimen's file."""
    from types import SimpleNamespace

    where = tmp_path_factory.mktemp("two_specimens")
    own = paper_specimen().with_values({"coupon.fixture_mass_kg": 0.05, "cell.count": 400})
    own_file = where / "own.toml"
    own_file.write_text(own.to_toml())
    run_or_load(where / "runs.h5", None, CASE, TINY)
    run_or_load(where / "runs.h5", own, CASE, TINY)
    return SimpleNamespace(store=where / "runs.h5", own=own, own_file=own_file)


@pytest.mark.usefixtures("undrawn_report_figures")
def test_report_notes_name_the_dem_runs_of_other_specimens(tmp_path, two_specimen_store):
    """A store of another specimen's runs was reported as holding "no DEM runs"."""
    from pidcore.report import make_report

    store, own = two_specimen_store.store, two_specimen_store.own
    other = paper_specimen().with_values({"cell.count": 300})
    none = make_report([], out_dir=tmp_path / "none", dem_store=store, formats="csv",
                       specimen=other)
    # runs labelled as Compare labels them: the paper's coupon by name, an edit by its hash
    assert f"{store}: holds no DEM runs of specimen paper_coupon [{other.hash[:6]}] (2 run(s) " \
           f"of other specimens: 1 of paper_coupon, 1 of " \
           f"paper_coupon [{own.hash[:6]}])" in none.notes
    assert not any(n.endswith("holds no DEM runs") for n in none.notes)
    mine = make_report([], out_dir=tmp_path / "mine", dem_store=store, formats="csv",
                       specimen=own)
    assert f"{store}: 1 run(s) of other specimens: 1 of paper_coupon" \
           f"; not compared (the report is of specimen " \
           f"paper_coupon [{own.hash[:6]}])" in mine.notes


@pytest.mark.usefixtures("undrawn_report_figures")
def test_report_names_its_specimen_in_the_table_and_its_hash_in_the_provenance(
        tmp_path, capsys, two_specimen_store):
    """With --specimen the CSV's specimen column was empty and the provenance had no hash of
    the specimen whose runs were compared."""
    import pandas as pd

    own, out = two_specimen_store.own, tmp_path / "rep"
    assert main(["report", "--dem-store", str(two_specimen_store.store), "--specimen",
                 str(two_specimen_store.own_file), "--out", str(out), "--format", "csv"]) == 0
    capsys.readouterr()
    table = pd.read_csv(out / "report.csv", comment="#", keep_default_na=False)
    # the file keeps the paper's name with another coupon: the column names it as its runs and
    # tests are named (pidcore.specimen.measured_specimen_name), not as the paper's coupon
    assert table["specimen"].tolist() == [f"{own.name} [{own.hash[:6]}]"]
    provenance = (out / "report.provenance.txt").read_text(encoding="utf-8").splitlines()
    assert f"specimen: {own.name} ({two_specimen_store.own_file}) sha256 {own.hash}" \
        in provenance
    # the default names the paper's coupon (either particle material), the CSV column stays
    # empty: the bundled report's CSV is unchanged
    default = tmp_path / "default"
    assert main(["report", "--dem-store", str(two_specimen_store.store), "--out", str(default),
                 "--format", "csv"]) == 0
    capsys.readouterr()
    text = (default / "report.provenance.txt").read_text(encoding="utf-8")
    assert f"specimen: paper_coupon (the default, acrylic particles) sha256 " \
           f"{paper_specimen('acrylic').hash}" in text
    # only the material its rows hold: the aluminium coupon was named, never compared
    assert "aluminium particles" not in text
    assert pd.read_csv(default / "report.csv", keep_default_na=False)["specimen"].tolist() == [""]


def test_static_and_rolling_friction_of_a_specimen_reach_the_kernel():
    sticky = paper_specimen().with_values({"pairs.particle_wall.static_friction": 0.5,
                                           "pairs.particle_particle.static_friction": 0.5,
                                           "pairs.particle_wall.rolling_friction": 0.05})
    config = DemConfig(cells=1, steady_cycles=10, block_cycles=5, max_transient_cycles=5)
    case = LoadCase(500.0, 1.0, 50.0)
    base = simulate_load_case(case, config)
    r = simulate_load_case(case, config, specimen=sticky)
    assert r.specimen.pairs.particle_wall.static_friction == 0.5
    # same seed and packing: only the contact law differs, so any change in the tallies is
    # the static friction and rolling resistance acting in the kernel
    assert r.energy_per_cycle_j != base.energy_per_cycle_j
    assert abs(r.energy_balance_error) < 0.01  # the energy bookkeeping still closes


def test_dem_run_text_breaks_the_dissipation_down_into_parts_that_add_up(tmp_path, capsys):
    # the rolling-resistance part was missing from the line, so its parts did not add up
    import re

    from pidcore.cli import main

    sticky = paper_specimen().with_values({"pairs.particle_wall.static_friction": 0.5,
                                           "pairs.particle_particle.static_friction": 0.5,
                                           "pairs.particle_wall.rolling_friction": 0.05,
                                           "pairs.particle_particle.rolling_friction": 0.05})
    path = tmp_path / "sticky.toml"
    path.write_text(sticky.text, encoding="utf-8")
    code = main(["dem", "run", "--specimen", str(path), "--frequency", "500",
                 "--acceleration", "5", "--fill", "50", "--cells", "1", "--cycles", "10",
                 "--store", str(tmp_path / "s.h5"), "--no-progress"])
    out = capsys.readouterr().out
    assert code == 0
    line = next(x for x in out.splitlines() if x.startswith("dissipated"))
    total, normal, friction, rolling = (float(v) for v in re.findall(
        r"dissipated\s+(\S+) J/cycle.*normal damping (\S+) J, friction (\S+) J, "
        r"rolling (\S+) J", line)[0])
    assert rolling > 0
    # printed to 4 significant digits: the parts add up to the total within their rounding
    assert normal + friction + rolling == pytest.approx(total, rel=2e-3)


def test_run_stored_before_moving_mass_kg_reads_its_coupon_mass_kg_as_the_sum():
    # such stores held coupon + fixture under coupon_mass_kg; it is the rigid mass of the run
    steel = load_specimen(STEEL)
    case = LoadCase(1000.0, 5.0, 50.0, material="steel")
    entry = dem_run_entry(simulate_load_case(case, TINY, specimen=steel))
    record = dict(entry["record"])
    record["coupon_mass_kg"] = record.pop("moving_mass_kg")
    stored = SimpleNamespace(key="old", record=record, arrays=entry["arrays"],
                             parameters=entry["parameters"])
    old = load_dem_result(stored)
    assert old.moving_mass_kg == 0.0333 + 0.015 and old.coupon_mass_kg == 0.0333
    assert old.to_dict()["coupon_mass_kg"] == 0.0333


@pytest.fixture(scope="module")
def own_panel_store(tmp_path_factory):
    """A store (as the app's) holding one run of a user specimen named my_panel only."""
    where = tmp_path_factory.mktemp("own_panel")
    text = paper_specimen().with_values({"coupon.fixture_mass_kg": 0.05}).to_toml()
    own = Specimen.from_text(text.replace('name = "paper_coupon"', 'name = "my_panel"'),
                             source=str(where / "my_panel.toml"))
    (where / "my_panel.toml").write_text(own.to_toml())
    run = run_or_load(where / "app.h5", own, CASE, TINY)
    return SimpleNamespace(store=where / "app.h5", own=own, run=run,
                           file=where / "my_panel.toml")


@pytest.mark.usefixtures("undrawn_report_figures")
def test_app_report_chooses_specimen_runs_as_the_cli_does(tmp_path, own_panel_store):
    """The app's Report listed another specimen's DEM row with an empty specimen column and
    nothing naming it; `pidcore report` left the run out with a note. Both go through
    pidcore.report.pipeline.specimen_report_table now."""
    from pidcore.compare.specimens import specimen_label
    from pidcore.report import make_report
    from pidcore.report.downloads import report_files, store_report_table

    store, own = own_panel_store.store, own_panel_store.own
    label = specimen_label(own.name, own.hash)
    default = store_report_table(store)
    assert default.empty  # the paper's coupon (the default) has no run here
    left_out = f"1 run(s) of other specimens: 1 of {label}"
    assert any(left_out in n for n in default.attrs["notes"])
    cli = make_report([], out_dir=tmp_path / "cli", dem_store=store, formats="csv")
    assert any(left_out in n for n in cli.notes)
    # the app offers the store's specimens, rebuilt from the runs' stored text
    from pidcore.compare.specimens import run_specimens

    offered = run_specimens(Store(store).list_dem_runs())
    assert list(offered) == [label] and offered[label].hash == own.hash
    mine = store_report_table(store, specimen=offered[label])
    assert mine["specimen"].tolist() == [own.name]
    assert mine["SDC DEM (ours) [-]"].tolist() == [own_panel_store.run.sdc]
    assert mine["SDC DEM (paper) [-]"].isna().all()  # not the paper's coupon
    cli = make_report([], out_dir=tmp_path / "cli_own", dem_store=store, formats="csv",
                      specimen=own)
    pd_cols = ["specimen", "SDC DEM (ours) [-]", "DEM runs [-]", "load case", "note"]
    assert mine[pd_cols].equals(cli.table[pd_cols])
    # the downloads' provenance names the specimen and its hash, as the CLI's does
    files = report_files(store, specimen=offered[label])
    assert f"sha256 {own.hash}" in files["csv_provenance"][1].decode()


def test_runs_stored_before_specimens_stay_the_papers_beside_hashed_runs():
    """A listing mixing runs stored before specimens (no hash: the paper's coupon) with runs
    of another specimen: the default keeps the first, the other specimen only its own. (With
    pandas' string dtype, a mapped None became NaN and the hashless runs were dropped, the
    report saying the store held none of the paper's.)"""
    import pandas as pd

    steel = load_specimen(STEEL)
    runs = pd.DataFrame({"case_key": ["old", "steel"],
                         "specimen_sha256": pd.Series([None, steel.hash], dtype="str")})
    assert persist.runs_of_specimen(runs)["case_key"].tolist() == ["old"]
    assert persist.runs_of_specimen(runs, paper_specimen())["case_key"].tolist() == ["old"]
    assert persist.runs_of_specimen(runs, steel)["case_key"].tolist() == ["steel"]
    # no hash column at all: every run is the paper's
    bare = runs[["case_key"]]
    assert persist.runs_of_specimen(bare)["case_key"].tolist() == ["old", "steel"]
    assert persist.runs_of_specimen(bare, steel).empty


def test_specimen_check_states_the_particle_radius_it_simulates(capsys, tmp_path):
    # the check printed masses and gaps but not the radius: a 2 mm diameter typed as
    # radius_m = 2e-3 (or a table material's default radius) could not be seen; the sphere
    # mass it printed is 4/3 pi r^3 rho of that radius
    import math

    typed_diameter = tmp_path / "diameter.toml"
    typed_diameter.write_text(STEEL.read_text().replace("radius_m = 1.0e-3", "radius_m = 2.0e-3"))
    assert main(["specimen", "check", str(typed_diameter)]) == 0
    assert "radius 2 mm (diameter 4 mm)" in capsys.readouterr().out
    assert main(["specimen", "check", str(typed_diameter), "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert facts["particle_radius_m"] == 2.0e-3
    assert facts["particle_mass_kg"] == pytest.approx(4 / 3 * math.pi * 2.0e-3 ** 3 * 7850.0)


def test_readme_specimen_table_names_every_key_the_reader_takes():
    # the README's key table is the documented schema; schema_version, which every bundled
    # file starts with and the reader checks, was missing from it
    from pidcore.specimen import SCHEMA

    readme = (REPO / "README.md").read_text(encoding="utf-8")
    table = readme[readme.index("| key | unit | meaning |"):]
    table = table[:table.index("\n\n")]
    # a key is written `key` or within a cell's code span (`[cell] shape`, `wall_poisson_ratio`)
    missing = [key for section in SCHEMA.values() for key in section
               if not re.search(rf"[`\s]{key}`", table)]
    assert missing == []


def test_dem_run_says_the_specimens_baseline_is_not_in_its_sdc(capsys, tmp_path, monkeypatch):
    # a specimen stating [coupon] baseline_loss_factor 0.002 printed the particles' SDC with no
    # word of whether the empty coupon's damping was in it (it is not: SDC = dissipation / E)
    import math

    damped = tmp_path / "damped.toml"
    damped.write_text(STEEL.read_text().replace("baseline_loss_factor = 0.0",
                                                "baseline_loss_factor = 0.002"))
    args = ["dem", "run", "--specimen", str(damped), "--frequency", "1000", "--acceleration",
            "5", "--cells", "1", "--cycles", "2", "--no-progress", "--json"]
    assert main(args) == 0
    doc = json.loads(capsys.readouterr().out)
    (note,) = [n for n in doc["notes"] if "baseline_loss_factor" in n]
    # the empty structure (33.3 g coupon + 15 g fixture) dissipates 2 pi eta_0 of its own
    # kinetic energy, a share 48.3 g / m_c of E (calibrate's observation model), not 2 pi eta_0
    share = (0.0333 + 0.015) / doc["vibrated_mass_kg"]
    assert "baseline_loss_factor 0.002" in note
    assert f"i.e. {2 * math.pi * 0.002 * share:.3g} in this SDC" in note
    # the SDC is the dissipation over E alone, with no baseline added
    assert doc["sdc"] == pytest.approx(doc["energy_per_cycle_j"] / doc["max_kinetic_energy_j"],
                                       rel=1e-12)
    assert main(args[:-1]) == 0
    assert "note            SDC of the particles alone" in capsys.readouterr().out


def test_specimen_check_names_a_fixture_far_heavier_than_the_coupon(capsys, tmp_path):
    # a 35 g fixture typed as 35 (kg) passed in silence: inside the 0-1000 kg range, but 140 x
    # the steel_6mm coupon and its particles (33 g + 216 g), so E of Eq. 10 is nearly all
    # fixture
    heavy = tmp_path / "heavy.toml"
    heavy.write_text(STEEL.read_text().replace("fixture_mass_kg = 0.015", "fixture_mass_kg = 35"))
    spec = load_specimen(heavy)
    facts = describe(spec)
    carried = spec.coupon.mass_kg + spec.cell.count * facts["particles_per_cell"] * \
        spec.particles.mass_kg
    (note,) = [n for n in facts["notes"] if "fixture_mass_kg" in n]
    assert f"{35 / carried:.0f} x the coupon and its particles" in note and "was it g?" in note
    assert main(["specimen", "check", str(heavy)]) == 0  # a note, not a refusal
    assert "note: [coupon] fixture_mass_kg 35 kg" in capsys.readouterr().out
    assert not [n for n in describe(load_specimen(STEEL))["notes"] if "fixture_mass_kg" in n]


def test_heavy_particles_do_not_hide_a_fixture_typed_in_grams(tmp_path):
    # 2 mm steel spheres at 60 % fill (263 g) in a 40 g coupon: a 15 g fixture typed as 15 (kg)
    # is 375 x the coupon but only 50 x the coupon and its particles, and passed in silence
    heavy = tmp_path / "heavy.toml"
    heavy.write_text(STEEL.read_text().replace("fixture_mass_kg = 0.015", "fixture_mass_kg = 15")
                     .replace("mass_kg = 0.0333", "mass_kg = 0.040")
                     .replace("fill_percent = 50.0", "fill_percent = 60.0"))
    spec = load_specimen(heavy)
    facts = describe(spec)
    carried = spec.coupon.mass_kg + spec.cell.count * facts["particles_per_cell"] * \
        spec.particles.mass_kg
    assert 40 < 15 / carried < 100  # under the old rule's threshold: the case that was missed
    (note,) = [n for n in facts["notes"] if "fixture_mass_kg" in n]
    assert "is 375 x the coupon (40 g)" in note and "was it g?" in note
    assert f"{15 / (15 + carried):.1%} the fixture's" in note
    # the same fixture in grams, and the paper's calibrated 0.254 kg fixture (11 x its 22 g
    # coupon), are not named
    grams = load_specimen(heavy).with_values({"coupon.fixture_mass_kg": 0.015})
    assert not [n for n in describe(grams)["notes"] if "fixture_mass_kg" in n]
    calibrated = load_specimen(Path(__file__).resolve().parents[1] / "data_samples"
                               / "paper_calibrated_specimen.toml")
    assert not [n for n in describe(calibrated)["notes"] if "fixture_mass_kg" in n]


def test_calibrated_damping_runs_an_own_specimen_and_its_json_says_the_alpha_used(
        capsys, tmp_path):
    """`--damping-coefficient calibrated` with an own specimen was refused ("only for table
    particles with the tables' contact pairs"), so a file stating e = 0.3 ran at 0.40 with
    nothing to cure it. It now calibrates each pair to the file's own restitution in the
    file's own cell, and the run's record says the alphas it used."""
    specimen = load_specimen(STEEL).with_values({"pairs.particle_particle.restitution": 0.3,
                                                  "pairs.particle_wall.restitution": 0.3})
    path = tmp_path / "steel_e03.toml"
    path.write_text(specimen.to_toml())
    store = tmp_path / "runs.h5"
    docs = {}
    for coefficient in ("eq3", "calibrated"):
        assert main(["dem", "run", "--specimen", str(path), "--frequency", "500",
                     "--acceleration", "5", "--cells", "1", "--cycles", "4",
                     "--damping-coefficient", coefficient, "--store", str(store),
                     "--no-progress", "--json"]) == 0
        docs[coefficient] = json.loads(capsys.readouterr().out)
    eq3 = contact_law(specimen)
    assert (docs["eq3"]["alpha_pp"], docs["eq3"]["alpha_pw"]) == (eq3.pair_particle.alpha,
                                                                  eq3.pair_wall.alpha)
    calibrated = calibrated_contact_law(specimen, DemConfig(damping_coefficient="calibrated"),
                                        docs["calibrated"]["time_step_s"])
    # the same calibration at the run's step, so the same alphas to the last bit; clipped
    # damping needs more than Eq. 3's to give the stated e
    assert (docs["calibrated"]["alpha_pp"], docs["calibrated"]["alpha_pw"]) == (
        calibrated.pair_particle.alpha, calibrated.pair_wall.alpha)
    assert docs["calibrated"]["alpha_pw"] > eq3.pair_wall.alpha
    # which of the two made the alphas: two runs of one case looked alike in --json
    assert [docs[c]["damping_coefficient"] for c in docs] == ["eq3", "calibrated"]
    assert docs["calibrated"]["sdc"] != docs["eq3"]["sdc"]
    # the stored run reads back with them
    run = load_dem_result(Store(store).get_dem_run(docs["calibrated"]["store_key"]))
    assert run.alpha_pw == docs["calibrated"]["alpha_pw"]


def test_specimen_check_says_the_restitution_the_kernel_gives_and_how_to_get_the_stated(
        capsys, tmp_path):
    """A file stating e = 0.3 runs at 0.40 in the default (no_attraction) mode, and `specimen
    check` said nothing of it. It now prints per pair the restitution of a head-on impact
    through the kernel beside the stated one, with a note naming the cures where they differ
    by more than 0.01, and no note where they do not."""
    def check(e: float, *mode: str) -> tuple[dict, str]:
        path = tmp_path / f"steel_{e}.toml"
        path.write_text(load_specimen(STEEL).with_values(
            {"pairs.particle_particle.restitution": e,
             "pairs.particle_wall.restitution": e}).to_toml())
        assert main(["specimen", "check", str(path), *mode, "--json"]) == 0
        facts = json.loads(capsys.readouterr().out)
        assert main(["specimen", "check", str(path), *mode]) == 0
        return facts, capsys.readouterr().out

    facts, out = check(0.3)
    for pair in ("pp", "pw"):
        assert facts[f"restitution_{pair}_stated"] == 0.3
        # 0.40 measured (0.3998 at 1e-6 s); 0.01 holds the grid step's error
        assert facts[f"restitution_{pair}_simulated"] == pytest.approx(0.40, abs=0.01)
    assert facts["restitution_damping_mode"] == "no_attraction"
    assert facts["restitution_impact_speed_m_s"] == defaults.DEM_CALIBRATION_SPEED_M_S
    assert (f"restitution     particle-particle 0.3 stated, "
            f"{facts['restitution_pp_simulated']:.4g} simulated; particle-wall 0.3 stated, "
            f"{facts['restitution_pw_simulated']:.4g} simulated") in out
    (note,) = [n for n in facts["notes"] if n.startswith("restitution")]
    assert f"particle-particle {facts['restitution_pp_simulated']:.3f} for the stated 0.3" \
        in note
    assert "--damping-coefficient calibrated" in note and "--damping-mode literal" in note
    assert f"note: {note}" in out
    # Eq. 3 is exact for damping that may pull: literal mode gives the stated e (to the
    # step's error, below the note's 0.01), and no note
    facts, out = check(0.3, "--damping-mode", "literal")
    assert facts["restitution_pw_simulated"] == pytest.approx(0.3, abs=0.01)
    assert not [n for n in facts["notes"] if n.startswith("restitution")]
    assert "literal damping" in out and "note: restitution" not in out
    # at e = 0.9 the clipped end of the contact is small: 0.902, within 0.01, and no note
    facts, out = check(0.9)
    assert facts["restitution_pp_simulated"] == pytest.approx(0.9, abs=0.01)
    assert "note: restitution" not in out


def test_specimen_check_names_an_impact_that_gains_energy(capsys, tmp_path):
    """e = 1 gave a simulated particle-particle restitution of 1.001 (an impact that gains
    energy, the step's error) without a note: within the 0.01 of the stated 1."""
    path = tmp_path / "carbide_elastic.toml"  # 1.5 mm carbide beads in 1/8 in cells
    path.write_text(load_specimen(STEEL).with_values(
        {"particles.material": "tungsten_carbide", "particles.radius_m": 0.75e-3,
         "particles.density_kg_m3": 15600.0, "particles.youngs_modulus_pa": 600e9,
         "particles.poisson_ratio": 0.22, "cell.inscribed_diameter_m": 3.175e-3,
         "cell.height_m": 10e-3, "pairs.particle_particle.restitution": 1.0,
         "pairs.particle_wall.restitution": 1.0}).to_toml())
    assert main(["specimen", "check", str(path), "--json"]) == 0
    facts = json.loads(capsys.readouterr().out)
    simulated = facts["restitution_pp_simulated"]
    # 1.0011 at 10 steps per (pair) contact: the explicit step's energy error
    assert simulated > 1 + defaults.RESTITUTION_GAIN_NOTE
    (note,) = [n for n in facts["notes"] if n.startswith("restitution above 1")]
    assert f"particle-particle {simulated:.4f} ({simulated**2 - 1:.2%} of its kinetic" in note
    # the wall contact, longer, has more steps: 1.0002, shown as 1, and not named
    assert facts["restitution_pw_simulated"] < 1 + defaults.RESTITUTION_GAIN_NOTE
    assert "particle-wall" not in note


def test_an_impact_that_does_not_rebound_is_refused_by_specimen_check_naming_file_and_key(
        capsys, tmp_path):
    """"error: impact: particle still in contact after 3 contact times" named neither file
    nor key nor what to change."""
    path = tmp_path / "steel_dead.toml"
    path.write_text(load_specimen(STEEL).with_values(
        {"pairs.particle_wall.restitution": 0.001}).to_toml())
    # Eq. 3's damping of e 0.001 holds the sphere on the wall past 3 contact times when it
    # may pull (literal); clipped, it leaves
    assert main(["specimen", "check", str(path), "--damping-mode", "literal"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert str(path.name) in err and "pairs.particle_wall.restitution 0.001" in err
    assert "particle-wall impact" in err and "expected a larger restitution" in err


def test_a_calibrated_run_on_a_soft_wall_states_the_alpha_that_gives_the_stated_e(
        capsys, tmp_path):
    """Steel on a Nomex wall: `dem run --damping-coefficient calibrated` ended in brentq's
    traceback at 500 Hz / 5 g (the wall impact's run was cut before its rebound)."""
    from _hertz_tsuji import hertz_tsuji_restitution

    path = tmp_path / "steel_nomex.toml"
    specimen = load_specimen(STEEL).with_values(
        {"cell.wall_material": "nomex", "cell.wall_youngs_modulus_pa": 3.4e9,
         "cell.wall_poisson_ratio": 0.3, "cell.wall_density_kg_m3": 1400.0})
    path.write_text(specimen.to_toml())
    assert main(["dem", "run", "--specimen", str(path), "--frequency", "500",
                 "--acceleration", "5", "--cells", "1", "--cycles", "4",
                 "--damping-coefficient", "calibrated", "--store", str(tmp_path / "r.h5"),
                 "--no-progress", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    wall = contact_law(specimen).pair_wall
    # the run's step gives the 4.5 x longer wall contact ~45 steps: the step's error in e is
    # ~0.002 there (first order, 0.006 at 20 steps); 0.01 holds it
    assert hertz_tsuji_restitution(wall.stiffness, wall.effective_mass_kg, doc["alpha_pw"],
                                   0.3) == pytest.approx(0.8, abs=0.01)


def test_a_sweeps_json_and_summary_name_each_runs_specimen_file(capsys, tmp_path):
    """`dem sweep --json` gave per case its load case and results but not whose run it was:
    the sweeps of two files named x (the second an edit of the first) into one store read
    alike. Each case now carries the stored run's specimen_name and specimen_sha256 (the
    file's hash), and the text summary names them."""
    store = tmp_path / "runs.h5"
    first = Specimen.from_text(paper_specimen().to_toml().replace('name = "paper_coupon"',
                                                                  'name = "x"'))
    edited = first.with_values({"coupon.mass_kg": 0.03})
    said = {}
    for label, spec in (("first", first), ("edited", edited)):
        path = tmp_path / label / "x.toml"
        path.parent.mkdir()
        path.write_text(spec.to_toml())
        args = ["dem", "sweep", "--specimen", str(path), "--frequencies", "1000",
                "--accelerations", "5", "--fills", "25", "--cells", "1", "--cycles", "2",
                "--workers", "1", "--store", str(store), "--no-progress"]
        assert main([*args, "--json"]) == 0
        (case,) = json.loads(capsys.readouterr().out)["cases"]
        assert (case["specimen_name"], case["specimen_sha256"]) == ("x", spec.hash), label
        assert main(args) == 0  # stored already: the summary names the stored run's file
        said[label] = capsys.readouterr().out
        assert f"1 already in {store}; wall time" in said[label]
        (summary,) = [line for line in said[label].splitlines() if " already in " in line]
        assert summary.endswith(f"; specimen x [{spec.hash[:6]}]")
    assert first.hash != edited.hash
    assert len(Store(store).list_dem_runs()) == 2


def test_dem_run_and_sweep_take_the_specimens_own_material_by_name(capsys, tmp_path):
    """`--specimen steel_6mm.toml --material steel` was refused by argparse ("invalid choice:
    'steel' (choose from 'acrylic', 'aluminium')"), though the material is the specimen's and
    `analyze`/`report` take it by name."""
    store = tmp_path / "s.h5"
    common = ["--specimen", str(STEEL), "--frequency", "1000", "--acceleration", "5",
              "--cells", "1", "--cycles", "4", "--no-progress", "--json", "--store", str(store)]
    assert main(["dem", "run", *common]) == 0
    first = json.loads(capsys.readouterr().out)
    before = store.read_bytes()
    # the same run under its own material's name (and its capitalised spelling): reused, one key
    for name in ("steel", "Steel"):
        assert main(["dem", "run", *common, "--material", name]) == 0
        again = json.loads(capsys.readouterr().out)
        assert again["reused_from_store"] is True and again["store_key"] == first["store_key"]
    assert main(["dem", "sweep", "--specimen", str(STEEL), "--material", "steel",
                 "--frequencies", "1000", "--accelerations", "5", "--fills", "50",
                 "--cells", "1", "--cycles", "4", "--workers", "1", "--no-progress",
                 "--json", "--store", str(store)]) == 0
    swept = json.loads(capsys.readouterr().out)
    assert [c["store_key"] for c in swept["cases"]] == [first["store_key"]]
    assert swept["completed"] == 0 and swept["skipped"] == 1
    assert store.read_bytes() == before
    # without a specimen an own material has no numbers: one line naming both options
    assert main(["dem", "run", "--material", "steel", "--frequency", "1000",
                 "--acceleration", "5", "--fill", "50", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--material steel" in err and "--specimen" in err, err


def test_specimen_check_names_spheres_that_fit_only_as_a_column(capsys, tmp_path):
    """2 mm beads typed as radius_m = 2e-3 (the diameter) in the 6.35 mm steel_6mm cell:
    4 mm spheres, a column of 3 up a 12.7 mm core, which `specimen check` called OK without a
    word, 15 x heavier each than the beads meant."""
    column = tmp_path / "column.toml"
    column.write_text(STEEL.read_text().replace("radius_m = 1.0e-3", "radius_m = 2.0e-3"))
    facts = describe(load_specimen(column))
    # 12.7 mm of core holds 3 spheres of 4 mm one above another, and no two side by side
    assert facts["capacity_per_cell"] == int(12.7 // 4.0) == 3
    (note,) = [n for n in facts["notes"] if "radius_m" in n]
    assert note == ("[particles] radius_m 2 mm: the spheres (diameter 4 mm) fit the 6.35 mm "
                    "cell only one above another, a column of 3; was the diameter given as "
                    "the radius?")
    assert main(["specimen", "check", str(column)]) == 0  # a note, not a refusal
    assert f"note: {note}" in capsys.readouterr().out
    # the beads meant pack side by side: no note
    assert not [n for n in describe(load_specimen(STEEL))["notes"] if "radius_m" in n]


def test_dem_run_numerics_line_says_what_its_wall_time_and_rate_count(tmp_path, capsys):
    """`numerics ... 779520 steps, 30.4 s wall, 1.74e+07 particle-steps/s`: 4 cells of 6
    particles over those steps are 1.9e7 particle-steps, 0.6e6 per wall second; the wall time
    held the settle and the first Numba compile, the rate only the kernel's calls."""
    import re

    code = main(["dem", "run", "--frequency", "500", "--acceleration", "5", "--fill", "50",
                 "--cells", "1", "--cycles", "10", "--no-progress"])
    out = capsys.readouterr().out
    assert code == 0
    line = next(x for x in out.splitlines() if x.startswith("numerics"))
    steps, wall, rate = re.fullmatch(
        r"numerics\s+dt \S+ s, (\d+) driven steps, (\S+) s wall \(settle and any Numba compile "
        r"included\), (\S+) particle-steps/s in the kernel", line).groups()
    # the kernel's time for the driven steps alone (11 acrylic particles, one cell) is within
    # the wall time: the rate is not of the wall time, which holds more
    assert int(steps) * 11 / float(rate) <= float(wall) + 0.05  # 0.05: the wall's 0.1 s print


def test_a_specimens_sha256_is_of_its_canonical_text_not_the_files_bytes_as_the_docs_say(
        tmp_path, capsys):
    """README said each record keeps "its file's sha256" and a run is reused "for the same file
    content": `sha256sum` of the file gives another value, and a comment, spacing, number
    formatting or another file name change neither the hash nor which runs are reused."""
    import hashlib

    relaid = tmp_path / "another_name.toml"
    relaid.write_text("# a comment of my own\n" + STEEL.read_text(encoding="utf-8")
                      .replace("mass_kg = 0.0333", "mass_kg   =   3.33e-2")
                      .replace("radius_m = 1.0e-3", "radius_m = 0.001"), encoding="utf-8")
    steel, same = load_specimen(STEEL), load_specimen(relaid)
    assert same.hash == steel.hash == hashlib.sha256(steel.text.encode("utf-8")).hexdigest()
    # not the bytes' sha256 (what sha256sum prints), of either file
    assert steel.hash not in {hashlib.sha256(path.read_bytes()).hexdigest()
                              for path in (STEEL, relaid)}
    # the command the words name prints it
    assert main(["specimen", "check", str(relaid), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["sha256"] == steel.hash
    readme = " ".join((REPO / "README.md").read_text(encoding="utf-8").split())
    assert "its file's sha256" not in readme and "same file content" not in readme
    assert ("The hash is that of the canonical text, not of the file's bytes (`sha256sum x.toml` "
            "gives another value)") in readme
    assert "`pidcore specimen check FILE --json` prints it (`sha256`)" in readme


def test_runs_of_an_edited_file_of_the_same_name_are_said_not_reused(tmp_path, monkeypatch,
                                                                     capsys):
    # a specimen file edited after its runs were stored (even its description) is another
    # specimen: dem sweep simulated every case again saying "0 already in STORE", as if the
    # store held none of that name
    store = tmp_path / "runs.h5"
    case = LoadCase(1000.0, 5.0, 25.0, material="steel")
    steel = load_specimen(STEEL)
    run_or_load(store, steel, case, TINY)
    edited_path = tmp_path / "steel_6mm.toml"
    edited_path.write_text(STEEL.read_text().replace('description = "', 'description = "v2 '))
    edited = load_specimen(edited_path)
    assert edited.name == steel.name and edited.hash != steel.hash
    note = persist.other_files_runs_note(store, [case], TINY, edited)
    assert note.startswith(f"{store} holds 1 run(s) of these load cases (seed 12345, 1 cells) "
                           f"by other files named steel_6mm (steel_6mm [{steel.hash[:6]}]:")
    assert f"this file is steel_6mm [{edited.hash[:6]}] (any changed value" in note
    # it said "reused only for the same file content", though the hash is of the canonical
    # text (a comment or 5e-2 for 0.050 changes no run): what is hashed, and where to see it
    assert "by the sha256 of its canonical text" in note and "file content" not in note
    assert "the JSON of pidcore specimen check prints it" in note
    # nothing to say: the file's own run, another load case, another cell count, another name
    assert persist.other_files_runs_note(store, [case], TINY, steel) == ""
    assert persist.other_files_runs_note(
        store, [LoadCase(500.0, 5.0, 25.0, material="steel")], TINY, edited) == ""
    assert persist.other_files_runs_note(
        store, [case], DemConfig(cells=2, steady_cycles=4), edited) == ""
    renamed = Specimen.from_text(edited.to_toml().replace('name = "steel_6mm"',
                                                          'name = "other"'))
    assert persist.other_files_runs_note(store, [case], TINY, renamed) == ""
    # a library sweep says it in its notes (the --json document's)
    from pidcore.dem import sweep as sweep_module

    other_store = tmp_path / "copy.h5"
    other_store.write_bytes(store.read_bytes())
    summary = sweep_module.run_sweep([case], TINY, store_path=other_store, workers=1,
                                     progress=False, specimen=edited)
    assert summary.completed and note.replace(str(store), str(other_store)) in summary.notes
    # the CLI says it before the sweep runs (a Ctrl-C here: exit 130, the store unchanged)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(sweep_module, "run_sweep", interrupted)
    before = store.read_bytes()
    assert main(["dem", "sweep", "--specimen", str(edited_path), "--frequencies", "1000",
                 "--accelerations", "5", "--fills", "25", "--cells", "1", "--store",
                 str(store), "--no-progress"]) == 130
    err = capsys.readouterr().err
    assert f"pidcore dem sweep: note: {store} holds 1 run(s) of these load cases" in err
    assert store.read_bytes() == before


def test_a_run_of_a_fixture_far_heavier_than_the_coupon_names_it():
    # only `specimen check` named a fixture typed in kg for g: `dem run` of a 120 kg fixture on
    # a 41 g coupon printed an SDC of 0.003 with no note. The run's notes name it as check does.
    typed_kg = paper_specimen().with_values({"coupon.fixture_mass_kg": 5.0})  # 5 g meant
    run = simulate_load_case(CASE, TINY, specimen=typed_kg)
    (note,) = [n for n in run.notes if "fixture_mass_kg" in n]
    (checked,) = [n for n in describe(typed_kg)["notes"] if "fixture_mass_kg" in n]
    assert CASE.fill_percent == 25.0 and note.endswith("was it g?")
    # the same words as `specimen check` where the run's fill is the one check counts
    at_run_fill = typed_kg.with_values({"particles.count_per_cell": run.particles_per_cell})
    assert note == [n for n in describe(at_run_fill)["notes"] if "fixture_mass_kg" in n][0]
    assert checked.startswith("[coupon] fixture_mass_kg 5 kg is 226 x the coupon")
    grams = simulate_load_case(CASE, TINY, specimen=paper_specimen().with_values(
        {"coupon.fixture_mass_kg": 0.005}))
    assert not [n for n in grams.notes if "fixture_mass_kg" in n]


def test_a_run_of_spheres_that_fit_only_as_a_column_names_it():
    # as specimen check does (test above): a run of 2 mm beads typed as radius_m = 2e-3 in the
    # steel_6mm cell simulated a column of 4 mm spheres with no note
    column = Specimen.from_text(STEEL.read_text().replace("radius_m = 1.0e-3",
                                                          "radius_m = 2.0e-3"))
    run = simulate_load_case(LoadCase(1000.0, 5.0, 100.0, "steel"), TINY, specimen=column)
    (note,) = [n for n in run.notes if "radius_m" in n]
    assert note == ("[particles] radius_m 2 mm: the spheres (diameter 4 mm) fit the 6.35 mm "
                    "cell only one above another, a column of 3; was the diameter given as "
                    "the radius?")
    beads = simulate_load_case(LoadCase(1000.0, 5.0, 25.0, "steel"), TINY,
                               specimen=load_specimen(STEEL))
    assert not [n for n in beads.notes if "radius_m" in n]


def test_dem_run_baseline_note_does_not_put_the_structure_in_a_particles_only_m_c(capsys,
                                                                                  tmp_path):
    # under --mass-convention particles m_c is the particles' mass alone, yet the note said
    # "0.0483 kg of m_c = ... kg" as if the coupon and fixture were part of it; the share
    # 2 pi eta_0 m_structure / m_c it prints is right either way
    import math

    damped = tmp_path / "damped.toml"
    damped.write_text(STEEL.read_text().replace("baseline_loss_factor = 0.0",
                                                "baseline_loss_factor = 0.002"))
    args = ["dem", "run", "--specimen", str(damped), "--frequency", "1000", "--acceleration",
            "5", "--cells", "1", "--cycles", "2", "--no-progress", "--json"]
    assert main([*args, "--mass-convention", "particles"]) == 0
    doc = json.loads(capsys.readouterr().out)
    (note,) = [n for n in doc["notes"] if "baseline_loss_factor" in n]
    particles = doc["particles_per_cell"] * doc["coupon_cells"] * doc["particle_mass_kg"]
    # m_c is the particles alone (rel 1e-9: the same sum, another order of additions)
    assert doc["vibrated_mass_kg"] == pytest.approx(particles, rel=1e-9)
    assert " kg of m_c = " not in note
    assert (f"0.0483 kg beside m_c = {doc['vibrated_mass_kg']:.4g} kg of the particles alone"
            in note)
    share = 0.0483 / doc["vibrated_mass_kg"]
    assert f"i.e. {2 * math.pi * 0.002 * share:.3g} in this SDC" in note
    # the default convention keeps its wording: m_c holds the structure
    assert main(args) == 0
    (note,) = [n for n in json.loads(capsys.readouterr().out)["notes"]
               if "baseline_loss_factor" in n]
    assert " kg of m_c = " in note


def test_elastic_contacts_that_cannot_settle_a_dense_start_say_why_and_what_works(
        capsys, tmp_path):
    # restitution 1 for both pairs passed specimen check, then dem run ended in "settling:
    # kinetic energy still 2.55e-10 J ..." naming no cause: the dense start settles without
    # friction first, and undamped contacts never come to rest
    from pidcore.specimen import paper_specimen

    specimen = paper_specimen().with_values({"pairs.particle_particle.restitution": 1.0,
                                             "pairs.particle_wall.restitution": 1.0})
    path = tmp_path / "elastic.toml"
    path.write_text(specimen.to_toml())
    assert main(["dem", "run", "--specimen", str(path), "--frequency", "500",
                 "--acceleration", "5", "--fill", "50", "--cells", "2", "--cycles", "5",
                 "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "no contact is damped (restitution 1 for both pairs)" in err
    assert "start with --packing loose" in err and len(err.strip().splitlines()) == 1


def test_dem_run_prints_the_sdc_a_shaker_test_of_a_specimen_with_a_baseline_measures(
        capsys, tmp_path):
    # a calibrated file (fixture and baseline fitted) printed its Eq. 10 SDC and a note that
    # the baseline adds 0.173: the number compared with a measurement, Eq. 11 of the virtual
    # shaker SDC = 2 pi (d + eta_0 m_s) / (m_p + m_s), calibrate's prediction, was not shown
    import math

    from pidcore.calibrate.observation import observation_from_run
    from pidcore.store import Store

    damped = tmp_path / "damped.toml"
    damped.write_text(STEEL.read_text().replace("baseline_loss_factor = 0.0",
                                                "baseline_loss_factor = 0.02"))
    store = tmp_path / "runs.h5"
    assert main(["dem", "run", "--specimen", str(damped), "--frequency", "1000",
                 "--acceleration", "5", "--cells", "1", "--cycles", "2", "--no-progress",
                 "--store", str(store)]) == 0
    out = capsys.readouterr().out
    shown = float(re.search(r"^SDC measured    (\S+) \[-\]", out, re.M).group(1))
    (key,) = Store(store).list_dem_runs()["case_key"]
    entry = Store(store).get_dem_run(key)
    spec = load_specimen(damped)
    seen = observation_from_run(entry.record, entry.arrays, coupon_mass_kg=spec.coupon.mass_kg)
    structure = spec.coupon.mass_kg + spec.coupon.fixture_mass_kg
    truth = 2 * math.pi * (seen.dissipative_mass_kg + 0.02 * structure) / (
        seen.reactive_mass_kg + structure)
    assert shown == pytest.approx(truth, rel=5e-4)  # printed to 4 significant digits
