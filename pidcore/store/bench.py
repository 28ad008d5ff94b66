"""Benchmark of the store at the size of years of tests: listing, reading entries by key,
reading many through one opening, and verify, on a store of many small entries.

Targets (per entry, so that they carry over store sizes): reading one entry by key costs
the same in a store of any size (the store's ``get_*`` once checked every entry's link,
~0.4 ms per entry stored, on each call); listing, batch reading and verify are linear.
"""

from __future__ import annotations

import hashlib
import tempfile
import time
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..records import Channel, Measurement
from .store import Store

#: Wall time of one ``get_analysis`` in a store of any size, s.
TARGET_GET_ONE_S = 0.02
#: Wall time per entry of a listing, of ``get_analyses`` of every analysis and of verify, s.
TARGET_PER_ENTRY_S = {"list_analyses": 0.002, "get_analyses": 0.005, "verify": 0.02}


def _fill(store: Store, n_measurements: int, n_analyses: int, n_dem_runs: int) -> None:
    fs = 51_200.0
    t = np.arange(5120) / fs
    rng = np.random.default_rng(1)
    with store.transaction():
        keys = []
        for i in range(n_measurements):
            force = np.sin(2 * np.pi * 100 * t) + 1e-3 * rng.standard_normal(t.size)
            keys.append(store.add_measurement(Measurement(f"run_{i:05d}.csv", (
                Channel("Force", "force", force, fs, "N"),
                Channel("Velocity", "velocity", 0.01 * np.cos(2 * np.pi * 100 * t), fs, "m/s")),
                sha256=hashlib.sha256(b"%d" % i).hexdigest(), file_format="csv"))[0])
        for i in range(n_analyses):
            store.add_analysis(keys[i % len(keys)], {
                "frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": 50.0,
                # sdc = 2 pi loss_factor, as an analysis saves it (verify checks it)
                "material": "acrylic", "direction": "z", "sdc": 2 * np.pi * 0.08,
                "sdc_stderr": 0.01, "loss_factor": 0.08},
                arrays={"harmonics": np.arange(1, 6),
                        "force_phasors_n": np.ones(5, complex),
                        "velocity_phasors_m_s": np.ones(5, complex)},
                parameters={"velocity_delay_s": 1e-6 * (i // len(keys))})
        store.add_dem_runs([{"case_key": f"f100Hz_a5g_fill50pct_acrylic_z_seed{i}",
                             "record": {"sdc": 0.4, "frequency_hz": 100.0},
                             "arrays": {"wall_force_n": rng.standard_normal(10240)}}
                            for i in range(n_dem_runs)])


def run_store_bench(n_analyses: int = 2000, *, n_measurements: int = 400,
                    n_dem_runs: int = 300, directory: str | None = None) -> dict:
    """Build a store of ``n_measurements`` measurements (2 x 5120 samples each),
    ``n_analyses`` analyses and ``n_dem_runs`` DEM runs (10240 samples each) and time what
    the report, the app and calibrate do with it.

    Returns
    -------
    dict
        Entries, store size, wall times (``list_analyses_s``, ``get_one_analysis_s``: mean
        of 50 calls, ``get_analyses_s``: every analysis through one opening, ``verify_s``),
        the same per entry, the targets and whether they are met.
    """
    if n_analyses < 1 or n_measurements < 1 or n_dem_runs < 0:
        raise ParameterError("expected >= 1 analysis and measurement and >= 0 DEM runs")
    with tempfile.TemporaryDirectory(dir=directory) as tmp:
        store = Store(Path(tmp) / "bench_store.h5")
        t0 = time.perf_counter()
        _fill(store, n_measurements, n_analyses, n_dem_runs)
        build = time.perf_counter() - t0
        entries = n_measurements + n_analyses + n_dem_runs
        t0 = time.perf_counter()
        keys = list(store.list_analyses()["key"])
        listing = time.perf_counter() - t0
        t0 = time.perf_counter()
        for key in keys[:50]:
            store.get_analysis(key)
        get_one = (time.perf_counter() - t0) / min(50, len(keys))
        t0 = time.perf_counter()
        store.get_analyses(keys)
        batch = time.perf_counter() - t0
        t0 = time.perf_counter()
        problems = store.verify()
        verify = time.perf_counter() - t0
        size = store.path.stat().st_size
        counts = store.summary()  # what was built, not what was asked: keys may collide
    per_entry = {"list_analyses": listing / n_analyses, "get_analyses": batch / n_analyses,
                 "verify": verify / entries}
    return {
        **{name: counts[name] for name in ("n_measurements", "n_analyses", "n_dem_runs")},
        "store_bytes": size, "build_s": build, "list_analyses_s": listing,
        "get_one_analysis_s": get_one, "get_analyses_s": batch, "verify_s": verify,
        "verify_problems": len(problems),
        **{f"{name}_s_per_entry": value for name, value in per_entry.items()},
        "target_get_one_analysis_s": TARGET_GET_ONE_S,
        **{f"target_{name}_s_per_entry": value for name, value in TARGET_PER_ENTRY_S.items()},
        "meets_targets": get_one <= TARGET_GET_ONE_S and all(
            per_entry[name] <= target for name, target in TARGET_PER_ENTRY_S.items()),
    }
