"""A stored DEM run's SDC is checked as an analysis's is: a negative or NaN SDC, or one that
is not 2 pi x its loss factor nor its energy per cycle over its peak kinetic energy, is damage
verify names and reports refuse. Before, an SDC of -0.5 was printed as "SDC DEM (ours)" and a
NaN one interpolated over without a note, both in a store verify called sound."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import h5py
import pytest

from pidcore.errors import StoreError
from pidcore.store import Store
from pidcore.store.listing import list_dem_runs

BUNDLED = Path(__file__).resolve().parents[1] / "data_samples" / "dem_table3.h5"


def _edited(tmp_path: Path, sdc: float) -> tuple[Path, str]:
    path = tmp_path / "dem.h5"
    shutil.copyfile(BUNDLED, path)
    with h5py.File(path, "r+") as h5:
        key = sorted(h5["dem_runs"])[0]
        h5[f"dem_runs/{key}/record"].attrs["sdc"] = sdc
    return path, key


def test_the_bundled_runs_hold_what_a_run_saves_and_verify_sound(tmp_path):
    path = tmp_path / "dem.h5"
    shutil.copyfile(BUNDLED, path)
    assert Store(path).verify() == []
    assert len(list_dem_runs(path)) == 48


@pytest.mark.parametrize("sdc, said", [(-0.5, "is not a finite number >= 0"),
                                       (math.nan, "is not a finite number >= 0"),
                                       # 10 % off: beside its own loss factor and energies
                                       (None, "is not 2 pi x its loss_factor")])
def test_a_dem_run_sdc_no_run_saves_is_damage_verify_names_and_reports_refuse(
        tmp_path, sdc, said):
    if sdc is None:
        with h5py.File(BUNDLED, "r") as h5:
            sdc = 1.1 * float(h5[f"dem_runs/{sorted(h5['dem_runs'])[0]}/record"].attrs["sdc"])
    path, key = _edited(tmp_path, sdc)
    problems = Store(path).verify()
    assert problems and all(f"DEM run {key}: record field sdc" in p for p in problems), problems
    assert any(said in p for p in problems)
    with pytest.raises(StoreError, match=f"dem.h5: DEM run {key}: record field sdc .*{said}"):
        list_dem_runs(path)


def test_a_dem_run_sdc_no_run_saves_is_refused_by_every_read_of_the_run_naming_store_and_run(
        tmp_path):
    path, key = _edited(tmp_path, -0.5)
    with pytest.raises(StoreError, match=f"dem.h5: DEM run {key}: record field sdc = -0.5 "
                                         "is not a finite number >= 0"):
        Store(path).get_dem_run(key)
    # verify still names it (and the other runs stay readable)
    assert any(f"DEM run {key}" in p for p in Store(path).verify())
    other = sorted(Store(path).list_dem_runs()["case_key"])[1]
    assert Store(path).get_dem_run(other).record["sdc"] >= 0


@pytest.mark.slow
def test_calibrate_refuses_to_reuse_a_stored_dem_run_whose_sdc_no_run_saves(
        tmp_path, capsys):
    from pidcore.cli import main

    table = tmp_path / "m.csv"
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc\n"
                     "500,5,50,0.6\n1000,5,50,0.6\n500,1,50,0.2\n")
    store = tmp_path / "dem.h5"
    argv = ["calibrate", "--data", str(table), "--fit", "fixture_mass_kg", "--discrepancy",
            "0.2", "--dem-store", str(store), "--cells", "2", "--steady-cycles", "10",
            "--workers", "1", "--no-progress"]
    assert main([*argv, "--out", str(tmp_path / "out")]) == 0
    with h5py.File(store, "r+") as h5:
        key = sorted(h5["dem_runs"])[0]
        h5[f"dem_runs/{key}/record"].attrs["sdc"] = math.nan
    capsys.readouterr()
    assert main([*argv, "--out", str(tmp_path / "again")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert f"dem.h5: DEM run {key}: record field sdc = nan is not a finite number" in err
    assert not (tmp_path / "again" / "calibration.json").exists()
