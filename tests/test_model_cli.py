"""``pidcore model`` sub-command, driven through its own parser (thin layer over the library)."""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pidcore.cli import model as model_cli
from pidcore.errors import ParameterError
from pidcore.model import SdcModel, coupon_vibrated_mass_kg, load_paper_table3
from pidcore.out_folder import RECORD_NAME


def _run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="pidcore")
    sub = parser.add_subparsers(dest="command", required=True)
    model_cli.register(sub)
    args = parser.parse_args(argv)
    return args.func(args)


def _fake_store(monkeypatch, listing) -> None:
    """``pidcore.store.Store`` replaced by one whose DEM-run listing is ``listing()``."""
    import pidcore.store

    class FakeStore:
        def __init__(self, path):
            self.path = path

        def list_dem_runs(self):
            return listing()

    monkeypatch.setattr(pidcore.store, "Store", FakeStore, raising=False)


def test_damper_writes_the_paper_grid(tmp_path):
    assert _run(["model", "damper", "--out", str(tmp_path), "--mass-convention", "coupon"]) == 0
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    assert len(table) == 48
    np.testing.assert_allclose(table["coupon_vibrated_mass [kg]"], coupon_vibrated_mass_kg())
    ref = load_paper_table3().dropna(subset=["sdc_dem"])
    merged = table.merge(ref, left_on=["frequency [Hz]", "acceleration [g]", "packing ratio [%]"],
                         right_on=["frequency_hz", "acceleration_g", "fill_percent"])
    assert len(merged) == 47
    np.testing.assert_allclose(merged["sdc [-]"], merged["sdc_dem"], rtol=1e-12)
    doc = json.loads((tmp_path / "equivalent_damper.json").read_text())
    assert len(doc["records"]) == 48
    assert doc["provenance"]["filled_grid_points"][0]["frequency_hz"] == 1000.0
    # the flag reads back as bool under its bracketed name, in the CSV as in the JSON
    assert table["sdc_filled [True/False]"].dtype == bool
    flagged = table[table["sdc_filled [True/False]"]]
    assert flagged[["frequency [Hz]", "acceleration [g]", "packing ratio [%]"]].values.tolist() == [
        [1000.0, 1.0, 90.0]]
    assert doc["units"]["sdc_filled [True/False]"] == "True/False"
    # per honeycomb cell: the coupon's c_eq over the paper's 441 cells, the count named
    np.testing.assert_allclose(table["c_eq_per_cell [N s/m]"] * 441,
                               table["c_eq_per_coupon [N s/m]"],
                               rtol=1e-12)  # CSV's 17 significant digits, one division
    assert doc["units"]["c_eq_per_cell [N s/m]"] == "N s/m"
    assert doc["provenance"]["cells"].startswith("441 (specimen paper_coupon)")
    assert sum(r["sdc_filled [True/False]"] is True for r in doc["records"]) == 1


def test_damper_options(tmp_path):
    _run(["model", "damper", "--out", str(tmp_path), "--format", "csv", "--fills", "30",
          "--accelerations", "2", "--frequencies", "75,300", "--vibrated-mass", "0.5"])
    assert not (tmp_path / "equivalent_damper.json").exists()
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    assert len(table) == 2 and set(table["coupon_vibrated_mass [kg]"]) == {0.5}
    with pytest.raises(ParameterError, match="--fills 95: outside the model's range 25 .. 90"):
        _run(["model", "damper", "--out", str(tmp_path), "--fills", "95"])
    with pytest.raises(SystemExit):
        _run(["model", "damper", "--out", str(tmp_path), "--format", "xlsx"])


def test_damper_value_typed_twice_gives_one_row_and_says_so(tmp_path, capsys):
    # a FEM lookup table needs each (f, a, fill) key once: 2 distinct fills x 1 x 1 = 2 rows
    assert _run(["model", "damper", "--out", str(tmp_path), "--format", "csv", "--fills",
                 "50,75,50", "--accelerations", "5,5", "--frequencies", "100"]) == 0
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    assert table["packing ratio [%]"].tolist() == [50.0, 75.0]
    assert not table.duplicated(["frequency [Hz]", "acceleration [g]",
                                 "packing ratio [%]"]).any()
    err = capsys.readouterr().err
    assert "--fills 50,75,50: each value once (50,75)" in err
    assert "--accelerations 5,5: each value once (5)" in err


def test_damper_from_store_runs(tmp_path, monkeypatch):
    base = load_paper_table3().dropna(subset=["sdc_dem"]).rename(columns={"sdc_dem": "sdc"})
    runs = pd.concat([base.assign(sdc=base.sdc * 0.9), base.assign(sdc=base.sdc * 1.1)])
    runs = pd.concat([runs.assign(material="acrylic"), base.assign(material="aluminium", sdc=0.7)])
    # the paper coupon's masses as the runs store them (m_c with a capacity of 22 per cell)
    count = np.round(runs["fill_percent"].to_numpy() / 100 * 22)
    runs = runs.assign(vibrated_mass_convention="coupon_plus_particles", coupon_mass_kg=0.0222,
                       fixture_mass_kg=0.0, coupon_cells=441, particle_mass_kg=9.7e-6,
                       particles_full_cell=22, vibrated_mass_kg=0.0222 + 441 * count * 9.7e-6)

    _fake_store(monkeypatch, lambda: runs.assign(sdc_stderr=0.01, case_key="k"))
    argv = ["model", "damper", "--out", str(tmp_path), "--table", "store", "--store",
            str(tmp_path / "s.h5"), "--format", "csv"]
    with pytest.raises(ParameterError, match="differ in material"):
        _run(argv)
    _run([*argv, "--where", "material=acrylic"])
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    # duplicates averaged: mean of 0.9 x and 1.1 x is the paper value
    expected = SdcModel.from_table(load_paper_table3())
    np.testing.assert_allclose(table["sdc [-]"], expected(table["packing ratio [%]"],
                               table["acceleration [g]"], table["frequency [Hz]"]), rtol=1e-12)


@pytest.mark.slow
def test_figures_writes_every_family(tmp_path, monkeypatch):
    # Which files the command writes, not how they look: the figures are built as usual but
    # not rasterised (14 drawn files took ~4 s); test_model_figures draws and saves them.
    from matplotlib.figure import Figure

    built = []

    def save_undrawn(fig, target, **_):
        built.append(fig)
        target.write(b"x")  # drawn into memory, then written whole beside the others

    monkeypatch.setattr(Figure, "savefig", save_undrawn)
    assert _run(["model", "figures", "--out", str(tmp_path)]) == 0
    assert len({id(fig) for fig in built}) == 4 + 3  # one figure per family, saved twice
    names = sorted(p.name for p in tmp_path.iterdir() if p.name != RECORD_NAME)
    assert len(names) == 2 * (4 + 3)
    assert "sdc_vs_acceleration_fill90.svg" in names and "sdc_vs_frequency_10g.png" in names


BUNDLED_GRID = Path(__file__).resolve().parents[1] / "data_samples" / "dem_table3.h5"


def test_damper_from_store_runs_gives_back_their_dissipated_energy(tmp_path):
    # c_eq = SDC m_c w / (2 pi) is the dissipation only with the m_c the SDC was divided by:
    # at every grid point the damper's energy per cycle must be the run's own (it used the
    # paper's count of 36 per full cell, 27-43 % above the runs' m_c, capacity 22 per cell)
    from pidcore.store import Store

    assert _run(["model", "damper", "--out", str(tmp_path), "--table", "store", "--store",
                 str(BUNDLED_GRID), "--format", "csv,json"]) == 0
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    runs = Store(BUNDLED_GRID).list_dem_runs()
    merged = table.merge(runs, left_on=["frequency [Hz]", "acceleration [g]", "packing ratio [%]"],
                         right_on=["frequency_hz", "acceleration_g", "fill_percent"])
    assert len(merged) == len(runs) == 48
    # the same sums of the same stored numbers: equal to rounding
    np.testing.assert_allclose(merged["coupon_vibrated_mass [kg]"], merged["vibrated_mass_kg"],
                               rtol=1e-12)
    np.testing.assert_allclose(merged["coupon_energy_per_cycle [J]"], merged["energy_per_cycle_j"],
                               rtol=1e-9)
    provenance = json.loads((tmp_path / "equivalent_damper.json").read_text())["provenance"]
    assert "the m_c the DEM runs divided their SDC by" in provenance["vibrated_mass"]
    # the rows with SDC >= 1 have no damping ratio, and the output says why (it was blank)
    undefined = int((table["sdc [-]"] >= 1).sum())
    assert undefined > 0 and table["coupon_damping_ratio [-]"].isna().sum() == undefined
    assert "undefined where SDC >= 1" in provenance["damping_ratio"]
    # the runs' m_c convention is the only one that gives their energy back
    with pytest.raises(ParameterError, match="--mass-convention coupon: the DEM runs in .* "
                                             "are coupon_plus_particles"):
        _run(["model", "damper", "--out", str(tmp_path), "--table", "store", "--store",
              str(BUNDLED_GRID), "--mass-convention", "coupon"])
    with pytest.raises(ParameterError, match="--material aluminium: the DEM runs"):
        _run(["model", "damper", "--out", str(tmp_path), "--table", "store", "--store",
              str(BUNDLED_GRID), "--material", "aluminium"])


def _specimen_runs(name: str, sha: str, *, coupon_kg: float, fixture_kg: float,
                   sdc_scale: float) -> pd.DataFrame:
    """A full grid of runs of one specimen, as a store lists them (m_c of its masses)."""
    base = load_paper_table3().dropna(subset=["sdc_dem"])
    full, cells, particle_kg = 10, 100, 3.3e-5
    count = np.round(base["fill_percent"].to_numpy() / 100 * full)
    return base.rename(columns={"sdc_dem": "sdc"}).assign(
        sdc=base["sdc_dem"] * sdc_scale, material="acrylic", case_key=f"{name}-run",
        specimen_name=name, specimen_sha256=sha, specimen_is_paper=False,
        vibrated_mass_convention="coupon_plus_particles", coupon_mass_kg=coupon_kg,
        fixture_mass_kg=fixture_kg, coupon_cells=cells, particle_mass_kg=particle_kg,
        particles_full_cell=full, sdc_stderr=0.01,
        vibrated_mass_kg=coupon_kg + fixture_kg + cells * count * particle_kg)


def test_damper_takes_one_specimens_runs_with_its_masses_and_a_given_area(tmp_path,
                                                                          monkeypatch):
    mine = _specimen_runs("steel_6mm", "a" * 64, coupon_kg=0.05, fixture_kg=0.12,
                          sdc_scale=0.5)
    other = _specimen_runs("steel_6mm", "b" * 64, coupon_kg=0.07, fixture_kg=0.0,
                           sdc_scale=2.0)
    listing = pd.concat([mine, other.assign(specimen_name="thick_core")])

    listed = {"runs": listing}
    _fake_store(monkeypatch, lambda: listed["runs"])
    argv = ["model", "damper", "--out", str(tmp_path), "--table", "store", "--store",
            str(tmp_path / "s.h5"), "--format", "csv"]
    # two specimens' SDCs would be averaged into one model of neither
    with pytest.raises(ParameterError, match=r"DEM runs are of 2 specimens: steel_6mm \[aaaaaa\] "
                                             r"\(47 runs\), thick_core \[bbbbbb\] \(47 runs\); "
                                             "select one.*--where specimen_name=steel_6mm"):
        _run(argv)
    # its file states no coupon area: per-area damping is refused, not taken from the paper
    with pytest.raises(ParameterError, match="--area: the DEM runs are of specimen "
                                             "steel_6mm"):
        _run([*argv, "--where", "specimen_name=steel_6mm"])
    _run([*argv, "--where", "specimen_name=steel_6mm", "--area", "0.02"])
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    at_grid = table.merge(mine, left_on=["frequency [Hz]", "acceleration [g]", "packing ratio [%]"],
                          right_on=["frequency_hz", "acceleration_g", "fill_percent"])
    assert len(at_grid) == 47
    np.testing.assert_allclose(at_grid["coupon_vibrated_mass [kg]"], at_grid["vibrated_mass_kg"],
                               rtol=1e-12)
    np.testing.assert_allclose(at_grid["sdc [-]"], at_grid["sdc"], rtol=1e-12)
    np.testing.assert_allclose(table["c_eq_per_treated_area [N s/m^3]"],
                               table["c_eq_per_coupon [N s/m]"] / 0.02,
                               rtol=1e-12)
    # runs that store no specimen text: their cell count is not the paper's 441 (here 100),
    # so no per-cell damper is written from it
    assert "c_eq_per_cell [N s/m]" not in table.columns
    # two files of one name are two specimens: told apart by hash
    listed["runs"] = pd.concat([mine, other])
    with pytest.raises(ParameterError, match="--where specimen_sha256=a{64}"):
        _run(argv)
    # by the hash's first digits, as `specimen check` prints 16 of them
    _run([*argv, "--where", "specimen_sha256=aaaaaaaaaaaaaaaa", "--area", "0.02"])
    assert pd.read_csv(tmp_path / "equivalent_damper.csv")["coupon_vibrated_mass [kg]"].max() \
        == pytest.approx(mine["vibrated_mass_kg"].max(), rel=1e-12)


def test_runs_vibrated_mass_refuses_a_run_its_specimen_columns_do_not_give():
    from pidcore.model import runs_vibrated_mass

    runs = _specimen_runs("steel_6mm", "a" * 64, coupon_kg=0.05, fixture_kg=0.12,
                          sdc_scale=1.0)
    mass = runs_vibrated_mass(runs)
    # 50 % of 10 per cell in 100 cells of 33 mg, plus coupon and fixture
    assert mass(50.0) == pytest.approx(0.05 + 0.12 + 100 * 5 * 3.3e-5, rel=1e-12)
    # a store written when coupon_mass_kg held coupon + fixture: the fixture counted twice
    old = runs.assign(vibrated_mass_kg=runs["vibrated_mass_kg"] - 0.12)
    with pytest.raises(ParameterError, match="stored m_c .* but its specimen columns give"):
        runs_vibrated_mass(old)


def test_runs_of_two_numerical_settings_are_refused_and_chosen_by_settings_hash(tmp_path,
                                                                               monkeypatch):
    # one grid run with Eq. 3's damping and one with the calibrated coefficient: their SDCs
    # were averaged into a model of neither (0.87 from 0.71 and 1.02 in a trial)
    from pidcore.compare.align import settings_hash

    def params(damping: str, seed: int) -> str:
        return json.dumps({"case_frequency_hz": 100.0, "config_seed": seed,
                           "config_damping_coefficient": damping, "config_cells": 8})

    eq3 = _specimen_runs("steel_6mm", "a" * 64, coupon_kg=0.05, fixture_kg=0.0, sdc_scale=1.0)
    listing = pd.concat([eq3.assign(parameters_json=params("eq3", 1)),
                         eq3.assign(parameters_json=params("eq3", 2)),  # a second seed: pooled
                         eq3.assign(parameters_json=params("calibrated", 1), sdc=eq3.sdc * 3)])

    _fake_store(monkeypatch, lambda: listing)
    argv = ["model", "damper", "--out", str(tmp_path), "--table", "store", "--store",
            str(tmp_path / "s.h5"), "--format", "csv", "--area", "0.01"]
    wanted = settings_hash(params("eq3", 7))  # the seed is not a setting
    other = settings_hash(params("calibrated", 7))
    # each hash with what sets it apart (a trial could not tell which run was which)
    with pytest.raises(ParameterError, match=f"DEM runs of 2 different numerical settings "
                                             f"\\(settings hash {wanted} \\(94 runs\\): "
                                             f"config_damping_coefficient eq3; {other} "
                                             "\\(47 runs\\): config_damping_coefficient "
                                             "calibrated\\)"):
        _run(argv)
    _run([*argv, "--where", f"settings_hash={wanted}"])
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    at_grid = table.merge(eq3, left_on=["frequency [Hz]", "acceleration [g]", "packing ratio [%]"],
                          right_on=["frequency_hz", "acceleration_g", "fill_percent"])
    np.testing.assert_allclose(at_grid["sdc [-]"], at_grid["sdc"], rtol=1e-12)
    # the runs' own m_c is the only one: an explicit one is refused, not used
    with pytest.raises(ParameterError, match="--vibrated-mass 1: the DEM runs in .* divided "
                                             "their SDC by their own m_c"):
        _run([*argv, "--where", f"settings_hash={wanted}", "--vibrated-mass", "1"])


def test_damper_and_figures_refuse_an_out_file_and_non_finite_values(tmp_path, capsys):
    from pidcore.cli import main

    afile = tmp_path / "afile"
    afile.write_text("keep me")
    for command in (["model", "damper"], ["model", "figures"]):
        assert main([*command, "--out", str(afile)]) == 2
        assert capsys.readouterr().err.count("\n") == 1
    assert afile.read_text() == "keep me"
    for option, value in (("--fills", "nan"), ("--area", "-1"), ("--vibrated-mass", "inf")):
        with pytest.raises(SystemExit) as exit_code:  # argparse's own refusal
            main(["model", "damper", "--out", str(tmp_path / "d"), option, value])
        assert exit_code.value.code == 2
        assert re.search(f"argument {option}: expected (a )?finite", capsys.readouterr().err)
    assert not (tmp_path / "d").exists()


def test_figures_of_stored_runs_name_their_specimen(tmp_path, monkeypatch):
    # steel and paper-coupon figures looked alike ("SDC at 50 % fill")
    from matplotlib.figure import Figure

    built = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, path, **_: built.append(fig))
    mine = _specimen_runs("steel_6mm", "a" * 64, coupon_kg=0.05, fixture_kg=0.12,
                          sdc_scale=0.5)
    _fake_store(monkeypatch, lambda: mine)
    assert _run(["model", "figures", "--out", str(tmp_path), "--table", "store", "--store",
                 str(tmp_path / "s.h5")]) == 0
    titles = {fig._suptitle.get_text().replace("\n", " ")  # wrapped to the figure width
              for fig in built if fig._suptitle is not None}
    assert titles == {f"DEM runs of steel_6mm [aaaaaa] in {tmp_path / 's.h5'}"}
    assert len(built) == 2 * (4 + 3)  # every figure titled, each saved as PNG and SVG


@pytest.mark.parametrize("area, said", [
    ("100", "--area 100 m^2 is 1.16e+04 x the cross-section of specimen paper_coupon's 441 "
            "cells (0.008653 m^2); expected the coupon's face area in m^2; was it cm^2 or mm^2?"),
    ("1e-7", "--area 1e-07 m^2 is 1.16e-05 x the cross-section"),
])
def test_an_area_in_another_unit_is_refused(tmp_path, area, said):
    # `--area 100` (the 100 cm^2 coupon typed in cm^2) wrote c_eq per area 1e4 times too small
    # without a word. The paper's 441 cells of 4.76 mm: 441 x (sqrt(3)/2) x 4.76e-3^2 m^2.
    with pytest.raises(ParameterError) as refused:
        _run(["model", "damper", "--out", str(tmp_path / "o"), "--area", area])
    assert said in str(refused.value)
    assert not (tmp_path / "o").exists()
    # the coupon's face (0.01 m^2, 1.16 x its cells) and a panel 50 x larger are taken
    for ok in ("0.01", "0.5"):
        _run(["model", "damper", "--out", str(tmp_path / ok), "--area", ok, "--format", "csv"])
        table = pd.read_csv(tmp_path / ok / "equivalent_damper.csv")
        np.testing.assert_allclose(table["c_eq_per_treated_area [N s/m^3]"],
                                   table["c_eq_per_coupon [N s/m]"] / float(ok), rtol=1e-12)


def test_an_area_is_checked_against_the_stored_runs_specimen(tmp_path):
    from pidcore.model.damper import check_area, runs_specimen
    from pidcore.specimen import load_specimen

    steel = load_specimen(Path(__file__).resolve().parents[1] / "data_samples" / "specimens"
                          / "steel_6mm.toml")
    runs = pd.DataFrame({"parameters_json": [json.dumps({"specimen_text": steel.text})] * 2})
    assert runs_specimen(runs).hash == steel.hash
    check_area(0.01, runs_specimen(runs))  # its 286 cells of 6.35 mm: 0.00999 m^2
    with pytest.raises(ParameterError, match=r"area_m2 100 m\^2 is 1e\+04 x .* steel_6mm's "
                                             r"286 cells"):
        check_area(100.0, runs_specimen(runs))
    # runs of an older store (no specimen text) or of several specimens: nothing to check by
    assert runs_specimen(pd.DataFrame({"parameters_json": ["{}"]})) is None


def test_a_vibrated_mass_in_grams_is_refused(tmp_path):
    # `--vibrated-mass 115.8` (the 115.8 g of coupon and particles typed in g) wrote a c_eq
    # 1000 x too large without a word
    from pidcore.model.damper import paper_vibrated_mass

    grams = 1000 * paper_vibrated_mass("coupon_plus_particles", "acrylic")(50.0)
    with pytest.raises(ParameterError, match=r"--vibrated-mass .* kg is .* x the paper "
                                             r"coupon's vibrated masses .*was it grams\?"):
        _run(["model", "damper", "--out", str(tmp_path / "g"), "--vibrated-mass", f"{grams}",
              "--fills", "50"])
    assert not (tmp_path / "g").exists()
    # the same mass in kg, and one with a fixture 10 x the coupon's m_c, are taken; c_eq is
    # proportional to the m_c given (c_eq = SDC m_c w / (2 pi))
    tables = {}
    for mass in (grams / 1000, 10 * grams / 1000):
        out = tmp_path / f"{mass:g}"
        _run(["model", "damper", "--out", str(out), "--vibrated-mass", f"{mass}",
              "--fills", "50", "--format", "csv"])
        tables[mass] = pd.read_csv(out / "equivalent_damper.csv")[
            "c_eq_per_coupon [N s/m]"].to_numpy()
    small, large = tables.values()
    np.testing.assert_allclose(large, 10 * small, rtol=1e-9)


def test_a_missing_store_is_named_as_missing(tmp_path, capsys):
    # `model damper --table store --store runs.h6` (a typo) said "no DEM runs stored; run
    # `pidcore dem` first", sending the user to simulate again
    from pidcore.cli import main

    missing = tmp_path / "runs.h6"
    for command in ("damper", "figures"):
        assert main(["model", command, "--table", "store", "--store", str(missing), "--out",
                     str(tmp_path / command)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"{missing}: store not found" in err
        assert not missing.exists() and not (tmp_path / command).exists()


def test_a_selection_refusal_names_the_where_option_not_a_python_dict(tmp_path, monkeypatch):
    # the CLI said "select one, e.g. where={'specimen_name': 'steel_6mm'} (CLI: --where
    # specimen_name=steel_6mm)" and "none match {'material': 'steel'}": a Python dict to a
    # user who types --where; and "(1 runs)"
    mine = _specimen_runs("steel_6mm", "a" * 64, coupon_kg=0.05, fixture_kg=0.12,
                          sdc_scale=0.5)
    one = _specimen_runs("thick_core", "b" * 64, coupon_kg=0.07, fixture_kg=0.0,
                         sdc_scale=2.0).iloc[:1]
    _fake_store(monkeypatch, lambda: pd.concat([mine, one]))
    argv = ["model", "damper", "--out", str(tmp_path / "o"), "--table", "store", "--store",
            str(tmp_path / "s.h5")]
    with pytest.raises(ParameterError) as refused:
        _run(argv)
    said = str(refused.value)
    assert "thick_core [bbbbbb] (1 run)" in said and "{" not in said and "CLI:" not in said
    assert "select one, e.g. --where specimen_name=" in said
    with pytest.raises(ParameterError) as refused:
        _run([*argv, "--where", "material=steel"])
    assert str(refused.value) == "DEM runs: none match --where material=steel"
    assert not (tmp_path / "o").exists()


def test_table3_sdc_is_not_put_over_another_materials_mass(tmp_path):
    """Was: `--material aluminium` wrote c_eq = SDC m_c w / (2 pi) with Table 3's acrylic SDC
    over the m_c of aluminium spheres (1.18 x the acrylic m_c at 50 %): a damper dissipating
    energy no DEM run found, written as the paper's. The acrylic table (the default, or named)
    gives back each SDC's energy: c_eq = dE / (pi w X^2) with dE = SDC m_c a^2 / (2 w^2)."""
    out = tmp_path / "al"
    with pytest.raises(ParameterError, match=r"--material aluminium: the paper's Table 3 "
                                             r"holds the SDC of acrylic particles only") as no:
        _run(["model", "damper", "--out", str(out), "--material", "aluminium"])
    # the refusal names each way on, the m_c given (run below) included
    assert "give that m_c with --vibrated-mass" in str(no.value)
    assert not out.exists()
    _run(["model", "damper", "--out", str(tmp_path / "ac"), "--material", "acrylic",
          "--format", "csv"])
    table = pd.read_csv(tmp_path / "ac" / "equivalent_damper.csv")
    w = 2 * np.pi * table["frequency [Hz]"]
    a = 9.80665 * table["acceleration [g]"]
    energy = table["sdc [-]"] * table["coupon_vibrated_mass [kg]"] * a**2 / (2 * w**2)
    # the same products in another order: equal to round-off
    np.testing.assert_allclose(table["c_eq_per_coupon [N s/m]"],
                               energy / (np.pi * w * (a / w**2) ** 2),
                               rtol=1e-12)
    # an explicit m_c is the user's: the material then only sets its unit-slip range
    assert _run(["model", "damper", "--out", str(tmp_path / "m"), "--material", "aluminium",
                 "--vibrated-mass", "0.1", "--fills", "50", "--format", "csv"]) == 0


def test_the_damper_says_per_what_along_which_direction_and_gives_the_velocity(tmp_path):
    # a FEM user put the dashpot on a node: the files did not say it is the whole coupon's,
    # grounded, along z (normal to the faces), nor give the velocity its force is c_eq times
    assert _run(["model", "damper", "--out", str(tmp_path), "--fills", "50",
                 "--accelerations", "5", "--frequencies", "500"]) == 0
    (row,) = pd.read_csv(tmp_path / "equivalent_damper.csv").to_dict(orient="records")
    # by hand: a = 5 g at 500 Hz, v = a / w
    assert row["velocity_amplitude [m/s]"] == pytest.approx(5 * 9.80665 / (2 * np.pi * 500),
                                                            rel=1e-14)
    # the viscous damper's energy per cycle, pi F X with F = c_eq v, is the table's dE
    assert np.pi * row["c_eq_per_coupon [N s/m]"] * row["velocity_amplitude [m/s]"] \
        * row["displacement_amplitude [m]"] == pytest.approx(row["coupon_energy_per_cycle [J]"],
                                                             rel=1e-12)
    doc = json.loads((tmp_path / "equivalent_damper.json").read_text())
    assert doc["units"]["velocity_amplitude [m/s]"] == "m/s"
    assert set(doc["columns"]) == set(doc["units"]) and all(doc["columns"].values())
    assert "whole coupon" in doc["columns"]["c_eq_per_coupon [N s/m]"]
    assert "grounded" in doc["columns"]["c_eq_per_coupon [N s/m]"]
    assert "per m^2 of coupon face" in doc["columns"]["c_eq_per_treated_area [N s/m^3]"]
    assert doc["provenance"]["direction"].startswith("z (normal to the face sheets")
    assert doc["provenance"]["particle_material"] == "acrylic"
    assert doc["provenance"]["area"] == ("0.01 m^2 ([coupon] face_area_m2 of specimen "
                                         "paper_coupon: 1.16 x its 441 cells' 0.00865333 m^2)")
    assert _run(["model", "damper", "--out", str(tmp_path), "--table", "store", "--store",
                 str(BUNDLED_GRID), "--fills", "50", "--accelerations", "5", "--frequencies",
                 "500"]) == 0
    doc = json.loads((tmp_path / "equivalent_damper.json").read_text())
    assert doc["provenance"]["direction"] == "z (normal to the face sheets: the DEM runs')"
    # --material with --vibrated-mass sets the m_c check only: the SDC stays Table 3's acrylic
    assert _run(["model", "damper", "--out", str(tmp_path), "--fills", "50", "--material",
                 "aluminium", "--vibrated-mass", "0.1"]) == 0
    doc = json.loads((tmp_path / "equivalent_damper.json").read_text())
    assert doc["provenance"]["particle_material"] == "acrylic"


def test_the_damper_csv_read_alone_says_what_each_damper_is_per(tmp_path):
    # the CSV's "c_eq [N s/m]" and "loss_factor [-]" did not say they were the 0.01 m^2,
    # 441-cell coupon's: an analyst reading the CSV alone could put them on a whole panel
    assert _run(["model", "damper", "--out", str(tmp_path), "--format", "csv", "--fills", "50",
                 "--accelerations", "5", "--frequencies", "100"]) == 0
    (row,) = pd.read_csv(tmp_path / "equivalent_damper.csv").to_dict(orient="records")
    assert not {"c_eq [N s/m]", "c_eq_per_area [N s/m^3]", "loss_factor [-]",
                "damping_ratio [-]", "energy_per_cycle [J]"} & set(row)
    # by hand, Table 2 and Sect. 5.1: faces 2 x 0.01 m^2 x 0.25 mm x 2800 kg/m^3, core
    # 0.01 m^2 x 25.4 mm x 32.1 kg/m^3, 18 acrylic spheres (r 1.25 mm, 1180 kg/m^3) per cell
    m_c = 2 * 0.01 * 0.25e-3 * 2800 + 0.01 * 0.0254 * 32.1 \
        + 441 * 18 * 1180 * 4 / 3 * np.pi * 1.25e-3**3
    sdc = 0.1891  # Table 3, 50 %, 5 g, 100 Hz (a grid point)
    # c_eq = SDC m_c w / (2 pi) = SDC m_c f; the CSV's 17 digits: only round-off differs
    assert row["c_eq_per_coupon [N s/m]"] == pytest.approx(sdc * m_c * 100.0, rel=1e-12)
    assert row["coupon_area [m^2]"] == pytest.approx(0.01, rel=1e-15)  # 0.1 m squared
    assert row["coupon_cells [-]"] == 441
    assert row["c_eq_per_treated_area [N s/m^3]"] == pytest.approx(
        sdc * m_c * 100.0 / 0.01, rel=1e-12)
    assert row["c_eq_per_cell [N s/m]"] == pytest.approx(sdc * m_c * 100.0 / 441, rel=1e-12)
    assert row["coupon_loss_factor [-]"] == pytest.approx(sdc / (2 * np.pi), rel=1e-12)


def test_an_older_damper_csv_reads_into_the_present_names(tmp_path):
    from pidcore.model import DAMPER_COLUMNS, DAMPER_COLUMNS_RENAMED

    assert _run(["model", "damper", "--out", str(tmp_path), "--format", "csv"]) == 0
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    older = table.rename(columns={new: old for old, new in DAMPER_COLUMNS_RENAMED.items()})
    older = older.drop(columns=["coupon_area [m^2]", "coupon_cells [-]"])  # new columns
    assert set(DAMPER_COLUMNS_RENAMED.values()) <= set(DAMPER_COLUMNS)
    # the fill was "fill [%]" here and "packing ratio [%]" in the report for the same number
    assert "fill [%]" in older.columns and "packing ratio [%]" in table.columns
    back = older.rename(columns=DAMPER_COLUMNS_RENAMED)
    pd.testing.assert_frame_equal(back, table[list(back.columns)])


def test_the_panel_loss_factor_is_a_viscous_sdofs_by_its_free_decay(tmp_path):
    # an analyst knowing a panel's areal mass had no loss factor of it, only the coupon's
    # (over the coupon's own m_c). Truth: a 1 m^2 panel of 8 kg/m^2 as a rigid mass on a
    # spring tuned to the drive frequency, its treated half carrying c_eq_per_treated_area
    # x 0.5 m^2 as a dashpot; its free decay's logarithmic decrement gives zeta, and the
    # loss factor at resonance is 2 zeta (a viscous SDOF: exact, not a small-damping form).
    from scipy.integrate import solve_ivp

    assert _run(["model", "damper", "--out", str(tmp_path), "--format", "csv", "--fills", "50",
                 "--accelerations", "5", "--frequencies", "100", "--panel-areal-mass", "8",
                 "--panel-treated-fraction", "0.5"]) == 0
    (row,) = pd.read_csv(tmp_path / "equivalent_damper.csv").to_dict(orient="records")
    mass, w = 8.0 * 1.0, 2 * np.pi * 100.0
    c = row["c_eq_per_treated_area [N s/m^3]"] * 0.5
    k = mass * w**2

    def peak(t, y):
        return y[1]
    peak.direction = -1  # velocity crossing zero downwards: a displacement maximum

    sol = solve_ivp(lambda t, y: [y[1], -(c * y[1] + k * y[0]) / mass], (0.0, 0.2),
                    [1e-3, 0.0], method="DOP853", rtol=1e-12, atol=1e-18, events=peak)
    maxima = sol.y_events[0][:, 0]
    decrement = np.mean(np.log(maxima[:-1] / maxima[1:]))
    zeta = decrement / np.sqrt(4 * np.pi**2 + decrement**2)
    # both the product of the CSV's 17 digits and an integration at rtol 1e-12: 1e-7
    assert row["panel_loss_factor [-]"] == pytest.approx(2 * zeta, rel=1e-7)
    # and by the coupon's own numbers: its loss factor x (m_c / coupon area) / 8 x 0.5
    assert row["panel_loss_factor [-]"] == pytest.approx(
        row["coupon_loss_factor [-]"] * row["coupon_vibrated_mass [kg]"]
        / row["coupon_area [m^2]"] / 8.0 * 0.5, rel=1e-12)
    assert row["panel_areal_mass [kg/m^2]"] == 8.0 and row["panel_treated_fraction [-]"] == 0.5


@pytest.mark.parametrize("argv,message", [
    (["--panel-areal-mass", "8000"], "--panel-areal-mass 8000 kg/m^2 is 505 x the coupons' own "
                                     "areal mass (6.05 .. 15.8 kg/m^2, m_c / coupon area); "
                                     "expected the panel's mass per m^2 in kg/m^2; was it "
                                     "g/m^2?"),
    (["--panel-areal-mass", "8", "--panel-treated-fraction", "50"],
     "--panel-treated-fraction 50: expected the treated share of the panel's area, in (0, 1]; "
     "was it a percentage?"),
    (["--panel-treated-fraction", "0.5"], "--panel-treated-fraction 0.5: the share of a panel "
                                          "given by --panel-areal-mass; give that too"),
])
def test_a_panel_areal_mass_or_share_in_the_wrong_unit_is_refused(tmp_path, argv, message):
    out = tmp_path / "out"
    with pytest.raises(ParameterError) as caught:
        _run(["model", "damper", "--out", str(out), *argv])
    assert str(caught.value) == message
    assert not out.exists()  # nothing written


@pytest.mark.parametrize("argv,message", [
    (["--accelerations", "49"], "--accelerations 49: outside the model's range 1 .. 10 g (never "
                                "extrapolated); expected g: was it m/s^2?"),
    (["--fills", "0.5"], "--fills 0.5: outside the model's range 25 .. 90 % (never "
                         "extrapolated); expected %: was it a fraction?"),
    (["--frequencies", "0.2"], "--frequencies 0.2: outside the model's range 50 .. 1000 Hz "
                               "(never extrapolated); expected Hz: was it kHz?"),
    (["--frequencies", "1257"], "--frequencies 1257: outside the model's range 50 .. 1000 Hz "
                                "(never extrapolated); expected Hz: was it rad/s?"),
    (["--fills", "95"], "--fills 95: outside the model's range 25 .. 90 % (never "
                        "extrapolated)"),
])
def test_a_grid_value_outside_the_model_names_its_unit_and_a_likely_slip(tmp_path, argv,
                                                                         message):
    # "--accelerations 49: outside the model's range 1 .. 10" named no unit: 49 m/s^2 typed
    # for 5 g was left to guess
    with pytest.raises(ParameterError) as caught:
        _run(["model", "damper", "--out", str(tmp_path / "out"), *argv])
    assert str(caught.value) == message


# the steel_6mm coupon by hand: 286 regular hexagons 6.35 mm across the flats, each
# (sqrt(3)/2) d^2 = 34.9203 mm^2: 0.00998721 m^2
STEEL_CELLS_AREA_M2 = 286 * (3**0.5 / 2) * 6.35e-3**2


def test_damper_takes_a_specimens_area_from_its_cells_and_says_so(tmp_path, monkeypatch,
                                                                   capsys):
    # runs of a specimen stored with its text were refused without --area although its cell
    # count and size give the area its cells treat
    from pidcore.specimen import load_specimen

    steel = load_specimen(Path(__file__).resolve().parents[1] / "data_samples" / "specimens"
                          / "steel_6mm.toml")
    runs = _specimen_runs("steel_6mm", steel.hash, coupon_kg=0.05, fixture_kg=0.12,
                          sdc_scale=0.5).assign(
        parameters_json=json.dumps({"specimen_text": steel.text}))
    _fake_store(monkeypatch, lambda: runs)
    argv = ["model", "damper", "--out", str(tmp_path), "--table", "store", "--store",
            str(tmp_path / "s.h5"), "--format", "csv,json"]
    capsys.readouterr()
    _run(argv)
    table = pd.read_csv(tmp_path / "equivalent_damper.csv")
    # one product and one division each: to rounding
    np.testing.assert_allclose(table["coupon_area [m^2]"], STEEL_CELLS_AREA_M2, rtol=1e-12)
    np.testing.assert_allclose(table["c_eq_per_treated_area [N s/m^3]"],
                               table["c_eq_per_coupon [N s/m]"] / STEEL_CELLS_AREA_M2,
                               rtol=1e-12)
    said = ("0.00998721 m^2 (specimen steel_6mm's 286 cells x 34.9203 mm^2 each: the text its "
            "DEM runs stored (a run stores its specimen without it: give --specimen FILE for "
            "the one its file states) states no [coupon] face_area_m2, so the area its cells "
            "treat)")
    assert json.loads((tmp_path / "equivalent_damper.json").read_text())["provenance"][
        "area"] == said
    assert f"note: coupon area {said}" in capsys.readouterr().err
    # --area overrides; one 2 x the cells' is noted, one within rounding of them is not
    _run([*argv, "--area", "0.02"])
    err = capsys.readouterr().err
    assert "--area 0.02 m^2 is 2 x specimen steel_6mm's own 0.00998721 m^2" in err
    assert "c_eq per area is taken over the area given" in err
    assert pd.read_csv(tmp_path / "equivalent_damper.csv")["coupon_area [m^2]"].iloc[0] == 0.02
    _run([*argv, "--area", "0.01"])
    assert "x specimen" not in capsys.readouterr().err


def test_the_library_default_area_of_another_specimen_is_its_cells(paper_model):
    # the paper's 0.01 m^2 face was taken for any specimen without an area_m2
    from pidcore.model import equivalent_damper_table
    from pidcore.model.damper import area_override_note, specimen_area_m2
    from pidcore.specimen import load_specimen, paper_specimen

    steel = load_specimen(Path(__file__).resolve().parents[1] / "data_samples" / "specimens"
                          / "steel_6mm.toml")
    assert specimen_area_m2(steel)[0] == pytest.approx(STEEL_CELLS_AREA_M2, rel=1e-12)
    table = equivalent_damper_table(paper_model, fills_percent=[50], accelerations_g=[5],
                                    frequencies_hz=[100], vibrated_mass_kg=0.1, specimen=steel)
    assert table["coupon_area [m^2]"].iloc[0] == pytest.approx(STEEL_CELLS_AREA_M2, rel=1e-12)
    # the paper's coupon keeps its stated 0.1 m x 0.1 m face (its 441 cells cover 1/1.16 of it)
    assert specimen_area_m2(paper_specimen())[0] == pytest.approx(0.01, rel=1e-15)
    assert area_override_note(0.0104, paper_specimen()) == ""  # 4 %: within the tolerance
    assert area_override_note(0.0106, paper_specimen()).startswith(
        "area_m2 0.0106 m^2 is 1.06 x specimen paper_coupon's own 0.01 m^2")


def test_stored_runs_of_one_fill_are_refused_naming_the_store(tmp_path, monkeypatch, capsys):
    # `model damper --table store` of a store whose runs hold one fill said "SDC table:
    # column fill_percent has 1 distinct value(s)", naming neither the store nor the fill
    from pidcore.cli import main

    runs = _specimen_runs("steel_6mm", "a" * 64, coupon_kg=0.05, fixture_kg=0.12,
                          sdc_scale=0.5)
    one_fill = runs[runs["fill_percent"] == 50.0]
    _fake_store(monkeypatch, lambda: one_fill)
    store = tmp_path / "s.h5"
    assert main(["model", "damper", "--out", str(tmp_path / "out"), "--table", "store",
                 "--store", str(store)]) == 2
    err = capsys.readouterr().err
    assert err == (f"pidcore model damper: error: DEM runs of steel_6mm [aaaaaa] in {store}: "
                   "column fill_percent has 1 distinct value(s) (50); the model needs at "
                   "least 2 per axis\n")
    assert not (tmp_path / "out").exists()


def test_a_run_off_the_grid_is_left_out_of_the_stored_model_and_named(tmp_path, monkeypatch,
                                                                      capsys):
    # one run at 300 Hz, 5 g beside a full grid made `model damper/figures --table store`
    # exit 2 "SDC table: no value at any fill for 1 g, 300 Hz", naming neither the store nor
    # the run, and --where cannot leave a frequency out: the report's rule (complete_grid)
    # models the complete grid and the output names what it left out
    from matplotlib.figure import Figure

    from pidcore.cli import main

    grid = _specimen_runs("steel_6mm", "a" * 64, coupon_kg=0.05, fixture_kg=0.12,
                          sdc_scale=0.5)
    stray = grid[(grid["frequency_hz"] == 500.0) & (grid["acceleration_g"] == 5.0)
                 & (grid["fill_percent"] == 50.0)].assign(frequency_hz=300.0,
                                                          case_key="stray-300Hz")
    _fake_store(monkeypatch, lambda: pd.concat([grid, stray]))
    store = tmp_path / "s.h5"
    argv = ["--table", "store", "--store", str(store)]
    capsys.readouterr()
    assert main(["model", "damper", "--out", str(tmp_path / "d"), *argv, "--area", "0.02"]) == 0
    err = capsys.readouterr().err
    assert (f"pidcore model damper: note: DEM runs of steel_6mm [aaaaaa] in {store}: left out "
            "of the SDC model, off its complete frequency x acceleration grid: 300 Hz (not run "
            "at every acceleration); 1 run(s): stray-300Hz\n") in err
    table = pd.read_csv(tmp_path / "d" / "equivalent_damper.csv")
    # the model's grid is the complete one, each of its runs' SDC given back (to rounding)
    assert sorted(set(table["frequency [Hz]"])) == [50.0, 100.0, 500.0, 1000.0]
    at_grid = table.merge(grid, left_on=["frequency [Hz]", "acceleration [g]",
                                         "packing ratio [%]"],
                          right_on=["frequency_hz", "acceleration_g", "fill_percent"])
    assert len(at_grid) == len(grid) == 47
    np.testing.assert_allclose(at_grid["sdc [-]"], at_grid["sdc"], rtol=1e-12)
    provenance = json.loads((tmp_path / "d" / "equivalent_damper.json").read_text())
    assert provenance["provenance"]["sdc_source"].endswith(
        "the complete grid; left out: 300 Hz (not run at every acceleration)")
    monkeypatch.setattr(Figure, "savefig", lambda fig, path, **_: None)
    assert main(["model", "figures", "--out", str(tmp_path / "f"), *argv]) == 0
    assert "pidcore model figures: note: DEM runs of steel_6mm [aaaaaa] in " \
        f"{store}: left out of the SDC model" in capsys.readouterr().err
    # no complete grid left: the refusal names the store and the pairs without a value
    diagonal = grid[((grid["frequency_hz"] == 50.0) & (grid["acceleration_g"] == 1.0))
                    | ((grid["frequency_hz"] == 100.0) & (grid["acceleration_g"] == 5.0))]
    _fake_store(monkeypatch, lambda: diagonal)
    assert main(["model", "damper", "--out", str(tmp_path / "x"), *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pidcore model damper: error: DEM runs of steel_6mm [aaaaaa] in "
                          f"{store}: no value at any fill at 50 Hz, 5 g; 100 Hz, 1 g (a pchip "
                          "model needs one at every frequency x acceleration pair)")
    assert not (tmp_path / "x").exists()


PAPER = Path("/work/shared/reference/seed-paper.md")


@pytest.mark.skipif(not PAPER.is_file(), reason="the paper's text is not on this machine")
def test_model_help_cites_the_sections_where_the_paper_proposes_the_pchip_model():
    # each section the help cites for the interpolation model must speak of it: Sect. 4
    # (particle and coupon properties) was cited, though the paper proposes the model in 5.1
    parser = argparse.ArgumentParser(prog="pidcore")
    model_cli.register(parser.add_subparsers())
    help_text = parser._subparsers._group_actions[0].choices["model"].description
    cited = re.search(r"paper Sect\. ([\d., ]+)\)", help_text).group(1)
    sections = [s.strip() for s in cited.split(",")]
    text = PAPER.read_text(encoding="utf-8")
    heading = re.compile(r"^(\d+(?:\.\d+)?) [A-Z]", re.MULTILINE)
    starts = [(m.group(1), m.start()) for m in heading.finditer(text)]
    bodies = {num: text[start:(starts[k + 1][1] if k + 1 < len(starts) else len(text))]
              for k, (num, start) in enumerate(starts)}
    for section in sections:
        assert "interpolation" in bodies[section], section


@pytest.mark.parametrize("argv", [
    ["model", "damper", "--fills", "50"],
    ["model", "figures"],
    ["report", "--dem-store", "data_samples/dem_table3.h5", "--store", "{tmp}/s.h5"],
])
def test_an_out_folder_under_a_file_is_refused_in_one_line_before_any_work(tmp_path, capsys,
                                                                           argv):
    # `--out afile/sub` raised FileExistsError / NotADirectoryError with a traceback (exit 1)
    # from a mkdir, after `report FILES --store` had saved its records
    from pidcore.cli import main

    blocking = tmp_path / "afile"
    blocking.write_text("not a folder\n")
    root = Path(__file__).resolve().parents[1]
    given = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    given = [str(root / a) if a.startswith("data_samples") else a for a in given]
    files = [str(root / "data_samples" / "exports" / "synthetic_f50Hz_a5g_fill50_acrylic.uff")] \
        if argv[0] == "report" else []
    assert main([*given, *files, "--out", str(blocking / "sub")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{blocking} is a file, not a folder" in err
    assert not (tmp_path / "s.h5").exists()  # nothing saved before the refusal


def test_one_vibrated_mass_for_several_fills_is_refused_naming_them(tmp_path):
    # `--vibrated-mass 0.0988` (the 50 % m_c) went to the 25, 50, 75 and 90 % rows alike: each
    # Table 3 SDC was divided by its own fill's m_c, so c_eq was 1.63 x too high at 25 % and
    # 0.62 x too low at 90 %, without a word
    for fills in ([], ["--fills", "25,90"]):
        out = tmp_path / f"refused{len(fills)}"
        with pytest.raises(ParameterError) as refused:
            _run(["model", "damper", "--out", str(out), "--vibrated-mass", "0.0988", *fills])
        message = str(refused.value)
        assert message.startswith("--vibrated-mass 0.0988 kg: one m_c for the fills "
                                  + ("25, 50, 75, 90 %" if not fills else "25, 90 %"))
        assert "give one fill per m_c (--fills F)" in message and "\n" not in message
        assert not out.exists()
    # the fill that m_c is of: its rows carry it, and c_eq = SDC m_c w / (2 pi) of it (the
    # CSV's 17 digits, one product: 1e-14)
    _run(["model", "damper", "--out", str(tmp_path / "one"), "--vibrated-mass", "0.0988",
          "--fills", "50", "--format", "csv"])
    table = pd.read_csv(tmp_path / "one" / "equivalent_damper.csv")
    assert set(table["packing ratio [%]"]) == {50.0}
    np.testing.assert_allclose(table["c_eq_per_coupon [N s/m]"],
                               table["sdc [-]"] * 0.0988 * table["frequency [Hz]"], rtol=1e-14)


def test_a_material_given_with_the_vibrated_mass_is_said_to_set_only_its_unit_check(tmp_path,
                                                                                      capsys):
    # `--material aluminium --vibrated-mass 0.2` ran, its provenance saying acrylic without
    # a word on the aluminium typed: the SDC is Table 3's acrylic one, the material only
    # sets the range the m_c given is checked against
    assert _run(["model", "damper", "--out", str(tmp_path), "--fills", "50", "--material",
                 "aluminium", "--vibrated-mass", "0.2"]) == 0
    said = ("--material aluminium: the SDC is the paper's Table 3, of acrylic particles; "
            "aluminium sets only the range the m_c given (--vibrated-mass) is checked against "
            "for a unit slip")
    assert f"pidcore model damper: note: {said}" in capsys.readouterr().err
    provenance = json.loads((tmp_path / "equivalent_damper.json").read_text())["provenance"]
    assert provenance["particle_material"] == "acrylic"
    assert provenance["particle_material_note"] == said
    # Table 3's own material, or none: nothing to say
    assert _run(["model", "damper", "--out", str(tmp_path / "ac"), "--fills", "50",
                 "--material", "acrylic", "--vibrated-mass", "0.2"]) == 0
    assert "--material" not in capsys.readouterr().err
    provenance = json.loads((tmp_path / "ac" / "equivalent_damper.json").read_text())[
        "provenance"]
    assert "particle_material_note" not in provenance


def test_a_panel_lighter_than_its_own_particles_is_refused_naming_both(tmp_path):
    # --panel-areal-mass 0.5 at 50 % fill was taken, though the paper coupon's particles alone
    # are 441 x 18 acrylic spheres (r 1.25 mm, 1180 kg/m^3) over 0.01 m^2 = 7.66 kg/m^2: its
    # panel_loss_factor was of a panel lighter than what it carries
    sphere = 1180.0 * 4.0 / 3.0 * np.pi * 1.25e-3**3
    carried = 441 * 18 * sphere / 0.01
    argv = ["model", "damper", "--format", "csv", "--fills", "50", "--accelerations", "5",
            "--frequencies", "100"]
    with pytest.raises(ParameterError) as caught:
        _run([*argv, "--out", str(tmp_path / "a"), "--panel-areal-mass", "0.5"])
    assert str(caught.value) == (
        "--panel-areal-mass 0.5 kg/m^2 is less than its particles' own 7.66 kg/m^2 at 50 % "
        "fill (0.0766 kg in the coupon's 0.01 m^2 x treated fraction 1); expected the panel's "
        "mass per m^2 with its particles")
    assert not (tmp_path / "a").exists()
    # the bound is the particles' own areal mass, x the share of the panel they fill: 1e-6
    # either side of it (far from round-off, far inside any real panel's margin)
    for fraction, mu, taken in ((1.0, carried * (1 + 1e-6), True),
                                (1.0, carried * (1 - 1e-6), False),
                                (0.5, carried / 2 * (1 + 1e-6), True),
                                (0.5, carried / 2 * (1 - 1e-6), False)):
        run = [*argv, "--out", str(tmp_path / "b"), "--panel-areal-mass", repr(mu),
               "--panel-treated-fraction", repr(fraction)]
        if taken:
            assert _run(run) == 0
        else:
            with pytest.raises(ParameterError, match="less than its particles' own"):
                _run(run)
    # over the model's fills the panel is checked at the most (90 %: 441 x 32 spheres)
    with pytest.raises(ParameterError) as caught:
        _run(["model", "damper", "--out", str(tmp_path / "c"), "--panel-areal-mass", "8"])
    assert (f"8 kg/m^2 is less than its particles' own {441 * 32 * sphere / 0.01:.3g} kg/m^2 "
            "at 90 % fill, the most of the fills 25 .. 90 %") in str(caught.value)


def test_the_out_folder_holds_one_runs_outputs_alone_and_foreign_files_are_refused(
        tmp_path, monkeypatch, capsys):
    # `model damper --out DIR --format csv --fills 50` then `--format json --fills 75` left
    # the 50 % CSV beside the 75 % JSON, and `model figures` of a 2-fill store left the
    # paper's other fills' figures beside its own: each run replaces the folder's outputs whole
    from matplotlib.figure import Figure

    from pidcore.cli import main

    out = tmp_path / "d"
    grid = ["--accelerations", "5", "--frequencies", "100"]
    assert main(["model", "damper", "--out", str(out), "--format", "csv", "--fills", "50",
                 *grid]) == 0
    assert main(["model", "damper", "--out", str(out), "--format", "json", "--fills", "75",
                 *grid]) == 0
    assert sorted(p.name for p in out.iterdir()) == [RECORD_NAME, "equivalent_damper.json"]
    records = json.loads((out / "equivalent_damper.json").read_text())["records"]
    assert [r["packing ratio [%]"] for r in records] == [75.0]
    # no build folder left beside it
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d"]

    monkeypatch.setattr(Figure, "savefig", lambda fig, target, **_: target.write(b"x"))
    figures = tmp_path / "f"
    assert main(["model", "figures", "--out", str(figures)]) == 0
    # Table 3: 4 fills, 3 accelerations; and the record of the files written
    assert len(list(figures.iterdir())) == 2 * (4 + 3) + 1
    two_fills = _specimen_runs("steel_6mm", "a" * 64, coupon_kg=0.05, fixture_kg=0.12,
                               sdc_scale=0.5)
    _fake_store(monkeypatch, lambda: two_fills[two_fills["fill_percent"].isin([25.0, 50.0])])
    assert main(["model", "figures", "--out", str(figures), "--table", "store", "--store",
                 str(tmp_path / "s.h5")]) == 0
    assert sorted(p.name for p in figures.iterdir() if p.suffix == ".png") == [
        "sdc_vs_acceleration_fill25.png", "sdc_vs_acceleration_fill50.png",
        "sdc_vs_frequency_10g.png", "sdc_vs_frequency_1g.png", "sdc_vs_frequency_5g.png"]
    capsys.readouterr()

    # a file the command does not write is never deleted: the folder is refused, before any
    # work, naming it; so is the other command's output
    (out / "notes.txt").write_text("keep me")
    assert main(["model", "damper", "--out", str(out), "--fills", "50", *grid]) == 2
    assert capsys.readouterr().err == (
        f"pidcore model damper: error: --out {out}: holds 'notes.txt', which pidcore model "
        "damper did not write there and replacing its earlier outputs whole would delete; move "
        "it out or choose a new or empty folder for --out\n")
    assert (out / "notes.txt").read_text() == "keep me"
    assert (out / "equivalent_damper.json").is_file()
    assert main(["model", "figures", "--out", str(tmp_path / "d")]) == 2
    assert (f"holds the outputs of pidcore model damper (its {RECORD_NAME}), which pidcore "
            "model figures does not write") in capsys.readouterr().err


def _run_main(argv: list[str]) -> int:
    from pidcore.cli import main

    return main(argv)


def _files(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in folder.rglob("*") if p.is_file()}


def test_a_file_named_like_an_output_but_not_written_by_the_run_is_refused_and_kept(
        tmp_path, monkeypatch, capsys):
    # any sdc_vs_frequency_*.png was taken for model figures' own by its name and deleted
    # with the earlier figures: only the files the last run recorded are replaced
    from matplotlib.figure import Figure

    monkeypatch.setattr(Figure, "savefig", lambda fig, target, **_: target.write(b"x"))
    figures = tmp_path / "f"
    assert _run_main(["model", "figures", "--out", str(figures)]) == 0
    (figures / "sdc_vs_frequency_mydata.png").write_bytes(b"my plot")
    before = _files(figures)
    capsys.readouterr()
    assert _run_main(["model", "figures", "--out", str(figures)]) == 2
    assert capsys.readouterr().err == (
        f"pidcore model figures: error: --out {figures}: holds 'sdc_vs_frequency_mydata.png', "
        "which pidcore model figures did not write there and replacing its earlier outputs "
        "whole would delete; move it out or choose a new or empty folder for --out\n")
    assert _files(figures) == before
    # an output of the run edited since is refused too (the edit would be lost)...
    (figures / "sdc_vs_frequency_mydata.png").unlink()
    (figures / "sdc_vs_frequency_5g.png").write_bytes(b"annotated")
    assert _run_main(["model", "figures", "--out", str(figures)]) == 2
    assert "holds 'sdc_vs_frequency_5g.png' changed since pidcore model figures wrote it" \
        in capsys.readouterr().err
    # ...and one deleted since is no loss: the folder is replaced, the figure back as drawn
    (figures / "sdc_vs_frequency_5g.png").unlink()
    assert _run_main(["model", "figures", "--out", str(figures)]) == 0
    assert (figures / "sdc_vs_frequency_5g.png").read_bytes() == b"x"


def test_a_folder_of_an_earlier_pidcore_without_a_record_is_refused_not_guessed_at(
        tmp_path, capsys):
    out = tmp_path / "d"
    out.mkdir()
    (out / "equivalent_damper.csv").write_text("of a pidcore that kept no record")
    assert _run_main(["model", "damper", "--out", str(out), "--fills", "50"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"pidcore model damper: error: --out {out}: is not empty "
                          "('equivalent_damper.csv', ...) and holds no record of what pidcore "
                          f"wrote there ({RECORD_NAME}") and err.count("\n") == 1
    assert _files(out) == {"equivalent_damper.csv": b"of a pidcore that kept no record"}


def test_figures_say_once_which_characters_they_could_not_draw(tmp_path, monkeypatch, capsys):
    """DEM runs of a specimen named сталь_6мм_鋼: every figure's title printed matplotlib's
    "Glyph 37628 missing from font(s) DejaVu Sans" UserWarning, with its source line, on the
    terminal; one note names the character instead."""
    import warnings

    from pidcore.plot_text import installed_fallback_families

    mine = _specimen_runs("сталь_6мм_鋼", "a" * 64, coupon_kg=0.05, fixture_kg=0.12,
                          sdc_scale=0.5)
    _fake_store(monkeypatch, lambda: mine)
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        assert _run(["model", "figures", "--out", str(tmp_path / "f"), "--table", "store",
                     "--store", str(tmp_path / "s.h5")]) == 0
    assert not [w for w in shown if "Glyph" in str(w.message)]
    err = capsys.readouterr().err
    if not installed_fallback_families():  # none where these tests run (fc-list :lang=zh)
        assert err.count("could not be drawn") == 1
        assert "pidcore model figures: note: 1 character(s) could not be drawn in the " \
               "figures (鋼)" in err


def test_an_out_that_links_to_a_folder_keeps_the_link_and_its_folder_gets_the_outputs(
        tmp_path):
    # `ln -s realout linkout; model damper --out linkout` replaced the link by a real folder
    # and left realout empty
    real, link = tmp_path / "realout", tmp_path / "linkout"
    real.mkdir()
    link.symlink_to(real.name)  # relative, as ln -s writes it
    grid = ["--fills", "50", "--accelerations", "5", "--frequencies", "100"]
    assert _run_main(["model", "damper", "--out", str(link), "--format", "csv", *grid]) == 0
    assert link.is_symlink() and link.readlink() == Path("realout")
    assert sorted(p.name for p in real.iterdir()) == [RECORD_NAME, "equivalent_damper.csv"]
    # replaced again through the link: its folder holds this run's outputs alone
    assert _run_main(["model", "damper", "--out", str(link), "--format", "json", *grid]) == 0
    assert link.is_symlink()
    assert sorted(p.name for p in real.iterdir()) == [RECORD_NAME, "equivalent_damper.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["linkout", "realout"]


@pytest.mark.parametrize("command", ["damper", "figures"])
def test_the_file_systems_root_as_out_is_refused_in_one_line_directly_or_through_a_link(
        tmp_path, capsys, command):
    # `ln -sfn / lroot; model damper --out lroot` (or --out /) ended in a traceback: a
    # ValueError for the build folder's name beside '/', which has none
    (tmp_path / "lroot").symlink_to("/")
    for out in ("/", str(tmp_path / "lroot")):
        assert _run_main(["model", command, "--out", out]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "Traceback" not in err
        assert f"--out {out}: is the file system's root" in err
    assert (tmp_path / "lroot").readlink() == Path("/")


def test_an_out_that_is_the_current_folder_or_above_it_is_refused_before_any_work(
        tmp_path, monkeypatch, capsys):
    # `cd d1 && model damper --out .` ended in a traceback (PosixPath('.') has an empty
    # name), and `--out "$PWD"` replaced the shell's folder, the shell left in a deleted one
    here = tmp_path / "d1"
    here.mkdir()
    (here / "thesis.tex").write_text("mine")
    monkeypatch.chdir(here)
    grid = ["--fills", "50", "--accelerations", "5", "--frequencies", "100"]
    for out in (".", str(here), "sub/../.", "..", str(tmp_path)):
        assert _run_main(["model", "damper", "--out", out, "--format", "csv", *grid]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1
        assert f"--out {Path(out)}: is the current folder or holds it" in err
    # an empty current folder too: what it holds is not the reason
    (here / "thesis.tex").unlink()
    assert _run_main(["model", "damper", "--out", ".", "--format", "csv", *grid]) == 2
    assert "is the current folder" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d1"] and not any(here.iterdir())
    # a folder below it, named through '..', is resolved and written as named
    assert _run_main(["model", "damper", "--out", "../d1/./out", "--format", "csv", *grid]) == 0
    assert sorted(p.name for p in (here / "out").iterdir()) == [RECORD_NAME,
                                                                "equivalent_damper.csv"]


def test_a_hidden_earlier_output_folder_holding_a_users_file_is_refused_not_removed(
        tmp_path, capsys):
    # a '.d.<hex>.old' folder with model damper's record was deleted beside an existing d
    # whatever else it held: a user's thesis.tex copied into it went with it
    grid = ["--fills", "50", "--accelerations", "5", "--frequencies", "100"]
    hidden = tmp_path / ".d.0123456789abcdef.old"
    for out in (tmp_path / "d", hidden):
        assert _run_main(["model", "damper", "--out", str(out), "--format", "csv", *grid]) == 0
    (hidden / "thesis.tex").write_text("mine")
    capsys.readouterr()  # the two runs' notes
    assert _run_main(["model", "damper", "--out", str(tmp_path / "d"), "--format", "json",
                      *grid]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{hidden}: left hidden beside d by a killed write" in err
    assert "holds 'thesis.tex', which pidcore model damper did not write" in err
    assert (hidden / "thesis.tex").read_text() == "mine"
    assert sorted(p.name for p in (tmp_path / "d").iterdir()) == [RECORD_NAME,
                                                                  "equivalent_damper.csv"]
    # holding its record's files alone, it is removed as before and d replaced
    (hidden / "thesis.tex").unlink()
    assert _run_main(["model", "damper", "--out", str(tmp_path / "d"), "--format", "json",
                      *grid]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d"]
    assert sorted(p.name for p in (tmp_path / "d").iterdir()) == [RECORD_NAME,
                                                                  "equivalent_damper.json"]


@pytest.mark.parametrize("command, what", [("damper", "the damper table"),
                                           ("figures", "the figures")])
def test_a_disk_that_fills_while_the_outputs_are_written_is_one_line_and_keeps_the_earlier_ones(
        tmp_path, monkeypatch, capsys, command, what):
    # a full disk (ENOSPC) or quota (EDQUOT) mid-way through the files ended in an OSError
    # traceback: now one line naming the folder and the file, exit 2, and the folder holds
    # the earlier run's outputs as they were, with nothing built left beside it
    import os

    from _build_leftovers import fill_the_disk_at_file
    from matplotlib.figure import Figure

    monkeypatch.setattr(Figure, "savefig", lambda fig, target, **_: target.write(b"x"))
    out = tmp_path / "out"
    argv = ["model", command, "--out", str(out)]
    if command == "damper":
        argv += ["--fills", "50", "--accelerations", "5", "--frequencies", "100"]
    assert _run_main(argv) == 0
    before = _files(out)
    capsys.readouterr()
    flushed = fill_the_disk_at_file(monkeypatch, 2)
    assert _run_main(argv) == 2
    err = capsys.readouterr().err
    assert len(flushed) == 1  # mid-way: a file was written before the disk filled
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"pidcore model {command}: error: {out}: {what} could not be "
                          "written (No space left on device: "), err
    assert err.endswith(f"); {out} unchanged (written whole or not at all)\n"), err
    assert _files(out) == before and os.listdir(tmp_path) == ["out"]
