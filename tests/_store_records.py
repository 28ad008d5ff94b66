"""A store holding records of every section, for the tests of listing and removing them: a
calibration with its three design DEM runs (a real tiny `pidcore calibrate`), a DEM run of
another seed, two measurements, the first analysed twice."""

from __future__ import annotations

import functools
import hashlib
import math
import shutil
from pathlib import Path

import h5py
import numpy as np

from pidcore.records import Channel, Measurement
from pidcore.store import Store

ROWS = "frequency_hz,acceleration_g,fill_percent,sdc\n500,5,50,0.6\n1000,5,50,0.6\n500,1,50,0.2\n"
TINY = ["--cells", "2", "--steady-cycles", "10", "--workers", "1", "--no-progress"]


def measurement(seed: int) -> Measurement:
    rng = np.random.default_rng(seed)
    return Measurement(f"test{seed}.uff", (
        Channel("force", "force", rng.normal(size=256), 2048.0, "N"),
        Channel("accel", "acceleration", rng.normal(size=256), 2048.0, "g"),
    ), sha256=hashlib.sha256(f"test{seed}".encode()).hexdigest(), file_format="uff")


def analysis(loss_factor: float, fill: float) -> dict:
    # an analysis saves sdc = 2 pi loss_factor to the last bit (checked by report's reader)
    return {"frequency_hz": 500.0, "acceleration_g": 5.0, "fill_percent": fill,
            "material": "acrylic", "direction": "z", "loss_factor": loss_factor,
            "sdc": 2 * math.pi * loss_factor}


@functools.cache
def _calibrated(folder: Path) -> Path:
    from pidcore.cli import main

    table = folder / "m.csv"
    table.write_text(ROWS)
    store = folder / "calibrated.h5"
    assert main(["calibrate", "--data", str(table), "--fit", "fixture_mass_kg",
                 "--discrepancy", "0.2", "--dem-store", str(store), *TINY]) == 0
    return store


def records_store(cache: Path, path: Path) -> dict:
    """A copy at ``path`` of the store this module describes (the calibration made once in
    ``cache``); returns its keys by role."""
    shutil.copyfile(_calibrated(cache), path)
    store = Store(path)
    design = list(store.list_dem_runs()["case_key"])
    calibration = store.list_calibrations()["key"].iloc[0]
    run = store.get_dem_run(design[0])
    store.add_dem_run("own_run_seed7", {**run.record, "seed": 7}, arrays=run.arrays,
                      units=run.units, parameters=run.parameters)
    first, _ = store.add_measurement(measurement(1))
    second, _ = store.add_measurement(measurement(2))
    older = store.add_analysis(first, analysis(0.05, 50.0), parameters={"delay": 0})
    newer = store.add_analysis(first, analysis(0.06, 50.0), parameters={"delay": 1})
    other = store.add_analysis(second, analysis(0.07, 75.0))
    return {"design": design, "calibration": calibration, "own_run": "own_run_seed7",
            "measurements": [first, second], "older": older, "newer": newer, "other": other}


def contents(path: Path) -> dict[str, tuple]:
    """Every object of the HDF5 file by path: its attributes and, for a dataset, its dtype,
    shape and bytes, all as bytes (what a bit-for-bit comparison needs)."""
    def attrs(item) -> tuple:
        return tuple(sorted((k, np.asarray(v).dtype.str, np.asarray(v).tobytes())
                            for k, v in item.attrs.items()))

    out: dict[str, tuple] = {}
    with h5py.File(path, "r") as h5:
        out["/"] = attrs(h5)

        def visit(name: str, item) -> None:
            data = (item.dtype.str, item.shape, item[()].tobytes()) \
                if isinstance(item, h5py.Dataset) else ()
            out[f"/{name}"] = (attrs(item), data)

        h5.visititems(visit)
    return out


def without(objects: dict[str, tuple], *entries: str) -> dict[str, tuple]:
    """``objects`` less the entries ``/section/key`` and everything under them."""
    return {k: v for k, v in objects.items()
            if not any(k == e or k.startswith(e + "/") for e in entries)}


def second_calibration(path: Path) -> str:
    """A second calibration fitted into the store at ``path`` on the same design runs (the
    same rows, cells and seed, another ``--fit``: every run reused from the store, none
    simulated); returns its key."""
    from pidcore.cli import main

    table = path.parent / "m.csv"
    table.write_text(ROWS)
    before = set(Store(path).list_calibrations()["key"])
    assert main(["calibrate", "--data", str(table), "--fit", "baseline_loss_factor",
                 "--dem-store", str(path), *TINY]) == 0
    added = set(Store(path).list_calibrations()["key"]) - before
    assert len(added) == 1
    return added.pop()
