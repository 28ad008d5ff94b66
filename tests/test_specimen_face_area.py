"""``[coupon] face_area_m2``: the one rule for the area ``model damper``'s per-area damper is per.

The paper's coupon took its 0.1 m x 0.1 m face, any other specimen file its cells' area, and no
file could state its face. Now a file states it (``[coupon] face_area_m2``) or is taken over its
cells; the paper's bundled file states its face, so its numbers are those of the old rule.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pidcore.cli import main
from pidcore.cli import model as model_cli
from pidcore.errors import ParameterError
from pidcore.model import (
    TreatedMode,
    coupon_area_m2,
    equivalent_damper_table,
    load_paper_table3,
    panel_loss_factor,
    paper_vibrated_mass,
)
from pidcore.model.damper import runs_specimen, specimen_area_m2
from pidcore.specimen import Specimen, describe, load_specimen, paper_specimen
from pidcore.store import Store

ROOT = Path(__file__).resolve().parents[1]
STEEL_FILE = ROOT / "data_samples" / "specimens" / "steel_6mm.toml"
PAPER_FILE = ROOT / "pidcore" / "data" / "specimens" / "paper_coupon.toml"
BUNDLED_GRID = ROOT / "data_samples" / "dem_table3.h5"
# steel_6mm by hand: 286 regular hexagons 6.35 mm across the flats, (sqrt(3)/2) d^2 each
STEEL_CELLS_AREA_M2 = 286 * (3**0.5 / 2) * 6.35e-3**2
# a 0.11 m x 0.11 m face around those cells (1.21 x their area): a margin of unfilled core
STEEL_FACE_M2 = 0.0121


def _steel_text(face_line: str) -> str:
    """steel_6mm.toml with ``face_line`` added to its [coupon] table."""
    text = STEEL_FILE.read_text(encoding="utf-8")
    return re.sub(r"(?m)^\[coupon\]$", "[coupon]\n" + face_line, text, count=1)


def _steel_with_face(tmp_path: Path, face_line: str = f"face_area_m2 = {STEEL_FACE_M2}") -> Path:
    path = tmp_path / "steel_face.toml"
    path.write_text(_steel_text(face_line), encoding="utf-8")
    return path


def _run_model(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="pidcore")
    model_cli.register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    return args.func(args)


# --- the file ----------------------------------------------------------------------------------

def test_a_stated_face_area_round_trips_and_keeps_the_files_hash(tmp_path):
    stated = load_specimen(_steel_with_face(tmp_path))
    plain = load_specimen(STEEL_FILE)
    assert stated.coupon.face_area_m2 == STEEL_FACE_M2
    # the file written back holds the key and reads back to the same specimen
    written = stated.to_toml()
    assert f"face_area_m2 = {STEEL_FACE_M2!r}" in written
    again = Specimen.from_text(written, source="written")
    # (equality, as the hash, leaves the face out: the key compared on its own)
    assert again == stated and again.coupon.face_area_m2 == STEEL_FACE_M2
    # no DEM physics: the canonical text a run stores, and so the hash, are the file's without it
    assert "face_area_m2" not in stated.text
    assert stated.text == plain.text and stated.hash == plain.hash
    # with_values keeps it (a calibrated file written from this one states the same face)
    fitted = stated.with_values({"coupon.fixture_mass_kg": 0.2})
    assert fitted.coupon.face_area_m2 == STEEL_FACE_M2
    # a variant whose cells outgrow the face: refused, unless it leaves the face out (None)
    with pytest.raises(ParameterError, match=r"\[coupon\] face_area_m2: 0\.0121 m\^2 is 0\.99 x"):
        stated.with_values({"cell.count": 350})
    larger = stated.with_values({"cell.count": 350, "coupon.face_area_m2": None})
    assert larger.coupon.face_area_m2 is None and "face_area_m2" not in larger.to_toml()


def test_the_bundled_paper_coupon_states_its_face_and_keeps_its_hash():
    paper = paper_specimen()
    # the old rule's area for the paper's cells, to the last bit
    assert paper.coupon.face_area_m2 == coupon_area_m2()
    # the file without the key is the hash every stored run of the coupon was saved under
    text = PAPER_FILE.read_text(encoding="utf-8")
    without = re.sub(r"(?m)^face_area_m2 = .*\n", "", text)
    assert without != text
    assert paper.hash == Specimen.from_text(without, source="old").hash
    stored = set(Store(BUNDLED_GRID).list_dem_runs()["specimen_sha256"])
    assert stored == {paper.hash}
    assert hashlib.sha256(paper.text.encode()).hexdigest() == paper.hash
    # the paper's coupon with another table material is the same coupon, with the same face
    assert paper_specimen("aluminium").coupon.face_area_m2 == coupon_area_m2()


@pytest.mark.parametrize("line,said", [
    # below the cells' area: the cells cannot lie within that face
    ("face_area_m2 = 0.009", "[coupon] face_area_m2: 0.009 m^2 is 0.901 x the cross-section of "
                            "its 286 cells (0.00998721 m^2, [cell] count x one hexagon); "
                            "expected the area of one face of the coupon in m^2, at least its "
                            "cells' (leave the key out to take the cells' area); was it one "
                            "cell's area, or is [cell] count wrong?"),
    ("face_area_m2 = -0.0121", "[coupon] face_area_m2: expected > 0 m^2, got -0.0121"),
    ("face_area_m2 = 0.0", "[coupon] face_area_m2: expected > 0 m^2, got 0.0"),
    # 121 cm^2 typed for 0.0121 m^2
    ("face_area_m2 = 121", "[coupon] face_area_m2: 121 m^2 is 1.21e+04 x the cross-section of "
                          "its 286 cells (0.00998721 m^2, [cell] count x one hexagon); expected "
                          "the area of one face of the coupon in m^2; was it cm^2 or mm^2?"),
    ("face_area_cm2 = 121", "[coupon] face_area_cm2: unknown key; expected one of ['mass_kg', "
                           "'fixture_mass_kg', 'baseline_loss_factor', 'face_area_m2']; units "
                           "are in the key names (SI): write face_area_m2, with the value in "
                           "that unit"),
    ('face_area_m2 = "0.0121"', "[coupon] face_area_m2: expected a number, got '0.0121'"),
])
def test_a_bad_face_area_is_one_line_naming_the_file_and_key(tmp_path, capsys, line, said):
    path = _steel_with_face(tmp_path, line)
    with pytest.raises(ParameterError) as caught:
        load_specimen(path)
    assert str(caught.value) == f"{path}: {said}"
    assert main(["specimen", "check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith(f"{path}: {said}") and "\n" not in err


def test_specimen_check_says_which_area_and_from_where(tmp_path, capsys):
    facts = describe(load_specimen(_steel_with_face(tmp_path)))
    assert facts["coupon_area_m2"] == STEEL_FACE_M2
    assert facts["coupon_area_from"] == ("0.0121 m^2 ([coupon] face_area_m2 of specimen "
                                         "steel_6mm: 1.21 x its 286 cells' 0.00998721 m^2)")
    plain = describe(load_specimen(STEEL_FILE))
    assert plain["coupon_area_m2"] == pytest.approx(STEEL_CELLS_AREA_M2, rel=1e-12)
    assert "its file states no [coupon] face_area_m2" in plain["coupon_area_from"]
    assert main(["specimen", "check", str(PAPER_FILE)]) == 0
    assert ("coupon area     0.01 m^2 ([coupon] face_area_m2 of specimen paper_coupon: 1.16 x "
            "its 441 cells' 0.00865333 m^2)") in capsys.readouterr().out


# --- the damper --------------------------------------------------------------------------------

def test_the_per_area_damper_of_a_stated_face_is_the_coupons_over_that_face(tmp_path,
                                                                            paper_model):
    stated = load_specimen(_steel_with_face(tmp_path))
    table = equivalent_damper_table(paper_model, fills_percent=[25, 50],
                                    accelerations_g=[2, 5], frequencies_hz=[100, 500],
                                    vibrated_mass_kg=lambda fill: 0.05 + fill / 1000,
                                    specimen=stated,
                                    # above its steel particles' 17.9 kg/m^2 at 50 % (a
                                    # lighter panel is refused)
                                    panel_areal_mass_kg_m2=20.0)
    assert (table["coupon_area [m^2]"] == STEEL_FACE_M2).all()
    # one division: exact
    np.testing.assert_array_equal(table["c_eq_per_treated_area [N s/m^3]"],
                                  table["c_eq_per_coupon [N s/m]"] / STEEL_FACE_M2)
    np.testing.assert_array_equal(table["panel_loss_factor [-]"], panel_loss_factor(
        table["c_eq_per_coupon [N s/m]"].to_numpy() / STEEL_FACE_M2,
        frequency_hz=table["frequency [Hz]"].to_numpy(), panel_areal_mass_kg_m2=20.0))
    # the same file without the key: its cells' area (the one rule), 1.21 x more per m^2
    plain = equivalent_damper_table(paper_model, fills_percent=[50], accelerations_g=[5],
                                    frequencies_hz=[100], vibrated_mass_kg=0.1,
                                    specimen=load_specimen(STEEL_FILE))
    assert plain["coupon_area [m^2]"].iloc[0] == pytest.approx(STEEL_CELLS_AREA_M2, rel=1e-12)
    # a mode of structure treated like this coupon takes the same area by default (it took
    # the paper's 0.01 m^2 whatever its coupon_specimen)
    mode = TreatedMode(natural_frequency_hz=200.0, modal_mass_kg=1.0,
                       structural_damping_ratio=0.01, treated_area_m2=0.05, fill_percent=50.0,
                       coupon_vibrated_mass_kg=0.1, coupon_specimen=stated)
    assert mode.coupon_area_m2 == STEEL_FACE_M2
    assert TreatedMode(natural_frequency_hz=200.0, modal_mass_kg=1.0,
                       structural_damping_ratio=0.01, treated_area_m2=0.05, fill_percent=50.0,
                       coupon_vibrated_mass_kg=0.1).coupon_area_m2 == coupon_area_m2()


def test_the_papers_damper_is_the_old_rules_to_the_last_bit(tmp_path, capsys):
    # the old rule: the paper coupon's cells took coupon_area_m2(), the 0.1 m side squared
    old_area = coupon_area_m2()
    for source in ([], ["--table", "store", "--store", str(BUNDLED_GRID)]):
        out = tmp_path / ("store" if source else "paper")
        # above the particles' own 13.6 kg/m^2 at 90 % (a lighter panel is refused)
        assert _run_model(["model", "damper", "--out", str(out), "--panel-areal-mass", "15",
                           *source]) == 0
        table = pd.read_csv(out / "equivalent_damper.csv")
        assert (table["coupon_area [m^2]"] == old_area).all()
        np.testing.assert_array_equal(table["c_eq_per_treated_area [N s/m^3]"],
                                      table["c_eq_per_coupon [N s/m]"] / old_area)
        np.testing.assert_array_equal(table["panel_loss_factor [-]"], panel_loss_factor(
            table["c_eq_per_coupon [N s/m]"].to_numpy() / old_area,
            frequency_hz=table["frequency [Hz]"].to_numpy(), panel_areal_mass_kg_m2=15.0))
        provenance = json.loads((out / "equivalent_damper.json").read_text())["provenance"]
        assert provenance["area"].startswith("0.01 m^2 ([coupon] face_area_m2 of specimen "
                                             "paper_coupon: 1.16 x its 441 cells'")
    # the runs' stored text leaves the face out: the bundled file of their hash gives it back
    runs = Store(BUNDLED_GRID).list_dem_runs()
    assert runs_specimen(runs).coupon.face_area_m2 == old_area
    # the library's default, with the paper's Table 3
    model_table = equivalent_damper_table(
        model_cli.build_model(argparse.Namespace(table="paper", where=[],
                                                 log_frequency=False))[0],
        fills_percent=[50], accelerations_g=[5], frequencies_hz=[100],
        vibrated_mass_kg=paper_vibrated_mass("coupon_plus_particles", "acrylic"))
    assert model_table["coupon_area [m^2]"].iloc[0] == old_area


def _steel_runs(steel: Specimen) -> pd.DataFrame:
    """A full grid of runs of ``steel`` as a store lists them (its canonical text stored)."""
    base = load_paper_table3().dropna(subset=["sdc_dem"])
    full, cells, particle_kg = 10, 100, 3.3e-5
    count = np.round(base["fill_percent"].to_numpy() / 100 * full)
    return base.rename(columns={"sdc_dem": "sdc"}).assign(
        sdc=base["sdc_dem"] * 0.5, material="acrylic", case_key="steel-run",
        specimen_name=steel.name, specimen_sha256=steel.hash, specimen_is_paper=False,
        vibrated_mass_convention="coupon_plus_particles", coupon_mass_kg=0.05,
        fixture_mass_kg=0.12, coupon_cells=cells, particle_mass_kg=particle_kg,
        particles_full_cell=full, sdc_stderr=0.01,
        vibrated_mass_kg=0.05 + 0.12 + cells * count * particle_kg,
        parameters_json=json.dumps({"specimen_text": steel.text}))


def _store_of_runs(monkeypatch, *runs: pd.DataFrame) -> None:
    """pidcore.store.Store replaced by one whose DEM-run listing is ``runs`` in that order
    (runs of two specimens in one store, without computing them)."""
    import pidcore.store

    class FakeStore:
        def __init__(self, _path):
            pass

        def list_dem_runs(self):
            return pd.concat(list(runs), ignore_index=True)

    monkeypatch.setattr(pidcore.store, "Store", FakeStore, raising=False)


def test_damper_of_stored_runs_takes_the_face_of_the_specimen_file_given(tmp_path, monkeypatch,
                                                                         capsys):
    path = _steel_with_face(tmp_path)
    stated = load_specimen(path)
    runs = _steel_runs(stated)

    _store_of_runs(monkeypatch, runs)
    argv = ["model", "damper", "--out", str(tmp_path / "out"), "--table", "store", "--store",
            str(tmp_path / "s.h5"), "--format", "csv,json"]
    capsys.readouterr()
    # the runs' text states no face: their cells' area, and the note says how to give the file's
    assert _run_model(argv) == 0
    err = capsys.readouterr().err
    assert ("the text its DEM runs stored (a run stores its specimen without it: give "
            "--specimen FILE for the one its file states) states no [coupon] face_area_m2"
            ) in err
    table = pd.read_csv(tmp_path / "out" / "equivalent_damper.csv")
    assert table["coupon_area [m^2]"].iloc[0] == pytest.approx(STEEL_CELLS_AREA_M2, rel=1e-12)
    # the file given: its face
    assert _run_model([*argv, "--specimen", str(path)]) == 0
    said = ("0.0121 m^2 ([coupon] face_area_m2 of specimen steel_6mm: 1.21 x its 286 cells' "
            "0.00998721 m^2)")
    assert f"note: coupon area {said}" in capsys.readouterr().err
    assert json.loads((tmp_path / "out" / "equivalent_damper.json").read_text())[
        "provenance"]["area"] == said
    table = pd.read_csv(tmp_path / "out" / "equivalent_damper.csv")
    np.testing.assert_array_equal(table["c_eq_per_treated_area [N s/m^3]"],
                                  table["c_eq_per_coupon [N s/m]"] / STEEL_FACE_M2)
    # another specimen's file would divide an SDC that is not its own
    with pytest.raises(ParameterError) as caught:
        _run_model([*argv, "--specimen", str(PAPER_FILE)])
    assert str(caught.value) == (
        f"--specimen {PAPER_FILE}: {tmp_path / 's.h5'} holds no DEM runs of paper_coupon "
        f"[{paper_specimen().hash[:6]}] (it holds {len(runs)} of steel_6mm "
        f"[{stated.hash[:6]}]); run them with pidcore dem sweep --specimen {PAPER_FILE} "
        f"--store {tmp_path / 's.h5'}")
    with pytest.raises(ParameterError, match=r"is not the specimen of the paper's Table 3 "
                                             r"\(--table paper\), paper_coupon"):
        _run_model(["model", "damper", "--out", str(tmp_path / "p"), "--specimen", str(path)])


def test_the_sweep_a_refused_specimen_file_is_pointed_to_names_each_path_as_one_word(
        tmp_path, monkeypatch):
    # "run them with pidcore dem sweep --specimen my coupon.toml --store runs % [1].h5" was
    # printed bare: pasted, the shell split both paths and globbed the brackets
    import shlex

    runs = _steel_runs(load_specimen(_steel_with_face(tmp_path)))
    _store_of_runs(monkeypatch, runs)
    own = tmp_path / "my coupon.toml"
    own.write_bytes(PAPER_FILE.read_bytes())
    store = tmp_path / "runs % [1].h5"
    with pytest.raises(ParameterError) as caught:
        _run_model(["model", "damper", "--out", str(tmp_path / "out"), "--table", "store",
                    "--store", str(store), "--specimen", str(own)])
    line = str(caught.value).split("; run them with ", 1)[1]
    assert shlex.split(line) == ["pidcore", "dem", "sweep", "--specimen", str(own), "--store",
                                 str(store)]


def test_the_old_rule_gave_a_copy_of_the_papers_cells_its_face_whatever_its_file():
    # one rule now: a file of the paper's cells that states no face (a copy, or a calibrated
    # file written before the key) is taken over its cells, as any other file is
    copy = Specimen.from_text(paper_specimen().text.replace('name = "paper_coupon"',
                                                           'name = "my_coupon"'),
                              source="copy")
    area, said = specimen_area_m2(copy)
    assert area == copy.cells_area_m2() and area < coupon_area_m2() / 1.15
    assert "its file states no [coupon] face_area_m2" in said


def test_damper_specimen_file_selects_its_runs_in_a_store_of_two_specimens(tmp_path,
                                                                          monkeypatch):
    """A store holding runs of an edited file of the same name (or of the paper's coupon)
    beside the file's own was refused as "DEM runs are of 2 specimens ... select one, e.g.
    --where specimen_sha256=...", although --specimen had named the file: its runs are the
    SDC, the other file's are left out."""
    path = _steel_with_face(tmp_path)
    stated = load_specimen(path)
    edited = stated.with_values({"coupon.fixture_mass_kg": 0.5})
    mine, other = _steel_runs(stated), _steel_runs(edited)
    other = other.assign(sdc=other["sdc"] * 3)  # a different SDC: a mix-up would show

    _store_of_runs(monkeypatch, other, mine)
    argv = ["model", "damper", "--out", str(tmp_path / "out"), "--table", "store", "--store",
            str(tmp_path / "s.h5"), "--format", "csv"]
    with pytest.raises(ParameterError, match="DEM runs are of 2 specimens"):
        _run_model(argv)  # without a file: which one is not guessed
    assert _run_model([*argv, "--specimen", str(path)]) == 0
    table = pd.read_csv(tmp_path / "out" / "equivalent_damper.csv")
    grid = mine.set_index(["frequency_hz", "acceleration_g", "fill_percent"])["sdc"]
    # the model's grid points are the runs' own load cases: the SDC there is the run's
    at = table.set_index(["frequency [Hz]", "acceleration [g]", "packing ratio [%]"])["sdc [-]"]
    common = at.index.intersection(grid.index)
    assert len(common) > 10
    np.testing.assert_allclose(at.loc[common].to_numpy(), grid.loc[common].to_numpy(),
                               rtol=1e-12)  # the pchip model passes through its nodes


def test_figures_specimen_file_selects_its_runs_in_a_store_of_two_specimens(tmp_path,
                                                                           monkeypatch, capsys):
    """`model figures` of a store holding two files' runs asked for --where specimen_sha256=
    and had no --specimen, as damper now has: it draws the file's runs."""
    path = _steel_with_face(tmp_path)
    stated = load_specimen(path)
    mine = _steel_runs(stated)
    other = _steel_runs(stated.with_values({"coupon.fixture_mass_kg": 0.5}))

    _store_of_runs(monkeypatch, other, mine)
    argv = ["model", "figures", "--out", str(tmp_path / "figs"), "--table", "store", "--store",
            str(tmp_path / "s.h5")]
    with pytest.raises(ParameterError, match="DEM runs are of 2 specimens"):
        _run_model(argv)
    seen = {}
    real = model_cli.build_model

    def spy(args):
        seen["model"], seen["runs"] = real(args)
        return seen["model"], seen["runs"]

    monkeypatch.setattr(model_cli, "build_model", spy)
    assert _run_model([*argv, "--specimen", str(path)]) == 0
    assert set(seen["runs"]["specimen_sha256"]) == {stated.hash}
    assert len(seen["runs"]) == len(mine)
    assert (tmp_path / "figs").is_dir() and any((tmp_path / "figs").iterdir())
    with pytest.raises(ParameterError, match=r"selects DEM runs: use it with --table store"):
        _run_model(["model", "figures", "--out", str(tmp_path / "p"), "--specimen", str(path)])
