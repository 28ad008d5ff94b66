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
