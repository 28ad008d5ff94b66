"""Saving DEM results to the HDF5 store (:mod:`pidcore.store`): one key, one entry layout."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from ..loadcase import key_0_1
from .result import UNITS, DemResult
from .simulate import DemConfig, LoadCase, config_parameters


def run_key(case: LoadCase, config: DemConfig) -> str:
    """Store key of one DEM run: readable load case plus a hash of every other input.

    The same for ``pidcore dem run --store``, sweeps and the app, so a sweep skips a run saved
    by any of them, e.g. ``f50Hz_a5g_fill50pct_acrylic_z_seed12345_cells8_<hash>``.
    """
    return f"{case.key}_{_run_suffix(case, config)}"


def run_key_0_1(case: LoadCase, config: DemConfig) -> str:
    """The key pidcore 0.1 stored the same run under (``acrylic_z_f50_a5_fill50_seed...``), so
    a sweep over a 0.1 store skips the runs it holds."""
    return f"{key_0_1(case)}_{_run_suffix(case, config)}"


def _run_suffix(case: LoadCase, config: DemConfig) -> str:
    params = config_parameters(case, config)
    digest = hashlib.sha256(json.dumps(params, sort_keys=True, default=str).encode()).hexdigest()
    return f"seed{config.seed}_cells{config.cells}_{digest[:10]}"


def dem_run_entry(result: DemResult) -> dict:
    """``record``, ``arrays``, ``parameters`` and ``units`` of a run, as the store takes them."""
    record = result.to_dict()
    record.pop("case_key", None)  # reserved listing column; the key is the entry name
    arrays = result.arrays()
    units = {k: v for k, v in UNITS.items() if k in record or k in arrays}
    return {"record": record, "arrays": arrays,
            "parameters": config_parameters(result.case, result.config), "units": units}


def save_dem_result(store_path: str | Path, result: DemResult, *,
                    replace: bool = False) -> str:
    """Add ``result`` (scalars, arrays, every input, units) to the store; returns its key."""
    from ..store import Store

    key = run_key(result.case, result.config)
    Store(store_path).add_dem_run(key, **dem_run_entry(result), replace=replace)
    return key
