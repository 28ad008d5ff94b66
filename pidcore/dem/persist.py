"""Saving DEM results to the HDF5 store (:mod:`pidcore.store`)."""

from __future__ import annotations

from pathlib import Path

from .result import UNITS, DemResult
from .simulate import config_parameters


def run_key(result: DemResult) -> str:
    """Store key of a run, the same as a sweep gives it (so a sweep skips it on resume):
    case, seed, cell count and a hash of every other input, e.g.
    ``acrylic_z_f50_a5_fill50_seed12345_cells8_<hash>``."""
    try:
        from .sweep import run_key as sweep_key
    except ImportError:  # sweep module not installed in this tree
        return f"{result.case.key()}_seed{result.config.seed}_cells{result.cells_simulated}"
    return sweep_key(result.case, result.config)


def save_dem_result(store_path: str | Path, result: DemResult, *,
                    replace: bool = False) -> str:
    """Add ``result`` (scalars, arrays, every input, units) to the store; returns its key."""
    from ..store import Store

    record = result.to_dict()
    record.pop("case_key", None)  # reserved listing column; the key is the entry name
    units = {k: v for k, v in UNITS.items() if k in record or k in result.array_names()}
    return Store(store_path).add_dem_run(
        run_key(result), record, arrays=result.arrays(),
        parameters=config_parameters(result.case, result.config), units=units,
        replace=replace)
