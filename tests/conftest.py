"""Fixtures shared by several test modules, and the Numba cache shared by pytest-xdist workers.

Numba kernels (``@njit(cache=True)``) compile in ~1-2 min from a cold cache. The cache lives in
``.numba_cache/`` of this checkout (``NUMBA_CACHE_DIR``, set here before anything imports
numba; an explicit ``NUMBA_CACHE_DIR`` wins), and with ``-n N`` the controller process compiles
the kernels once in ``pytest_configure`` -- before pytest-xdist starts its workers, which then
inherit the variable and load the compiled kernels instead of each compiling them again.
``PIDCORE_NUMBA_WARMUP=0`` skips the warm-up.
"""

import os
import time
from pathlib import Path

os.environ.setdefault("NUMBA_CACHE_DIR",
                      str(Path(__file__).resolve().parents[1] / ".numba_cache"))

import pandas as pd  # noqa: E402  (NUMBA_CACHE_DIR must be set before numba is imported)
import pytest  # noqa: E402

from pidcore.model import SdcModel, load_paper_table3  # noqa: E402

_WARMUP_SECONDS = pytest.StashKey[float]()


def warm_numba_kernels() -> None:
    """Compile (or load from the cache) every Numba kernel the suite calls, with the argument
    types the library passes: one DEM step loop (both specialisations of the cell kernel, via
    a tiny load case and a single impact) and the harmonic fit."""
    import numpy as np

    from pidcore.dem import DemConfig, LoadCase, simulate_impact, simulate_load_case
    from pidcore.signal import analyze_power

    simulate_impact(impact_speed_m_s=0.3, dt_s=1e-6)
    simulate_load_case(LoadCase(500.0, 5.0, 50.0),
                       DemConfig(cells=1, steady_cycles=2, block_cycles=1,
                                 max_transient_cycles=1))
    t = np.arange(2000) / 1000.0
    analyze_power(np.sin(100 * t), np.cos(100 * t), 1000.0)


def pytest_configure(config: pytest.Config) -> None:
    # Only the xdist controller warms up: it runs before the workers are started
    # (DSession.pytest_sessionstart), so they find a warm cache. A single process compiles
    # on first use anyway, and a run of a few test files need not compile the DEM at all.
    if hasattr(config, "workerinput") or os.environ.get("PIDCORE_NUMBA_WARMUP") == "0":
        return
    if not getattr(config.option, "numprocesses", None):
        return
    start = time.perf_counter()
    try:
        warm_numba_kernels()
    except Exception as exc:  # the tests that call the kernel will report it properly
        config.issue_config_time_warning(
            pytest.PytestWarning(f"numba warm-up failed, workers compile on their own: {exc}"),
            stacklevel=2)
        return
    config.stash[_WARMUP_SECONDS] = time.perf_counter() - start


def pytest_report_header(config: pytest.Config) -> str:
    seconds = config.stash.get(_WARMUP_SECONDS, None)
    warmed = "" if seconds is None else f", kernels warmed in {seconds:.1f} s"
    return f"numba cache: {os.environ['NUMBA_CACHE_DIR']}{warmed}"


@pytest.fixture(scope="session")
def paper_table() -> pd.DataFrame:
    """The paper's Table 3 as bundled with pidcore."""
    return load_paper_table3()


@pytest.fixture(scope="session")
def paper_model(paper_table) -> SdcModel:
    """The pchip SDC model over the paper's Table 3 DEM values."""
    return SdcModel.from_table(paper_table)
