"""Compile the Numba kernels into ``NUMBA_CACHE_DIR``: ``python tests/_numba_warmup.py DONE``.

Run in the background by ``tests/conftest.py`` while pytest-xdist workers start; writes ``ok``
(or why it failed) to the file DONE when finished, which the workers wait for before their
first test that calls the DEM kernel.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path


def warm_signal_kernels() -> None:
    """The harmonic fit and the clipping scan, on a record the analysis accepts."""
    import numpy as np

    from pidcore.signal import analyze_power
    from pidcore.signal.validate import clipped_samples

    # a damped mass: force leads velocity by a little less than 90 degrees (Im P > 0, loss
    # factor 0.1); a record the analysis refuses would stop the warm-up before the DEM kernel
    t = np.arange(2000) / 1000.0
    analyze_power(np.cos(100 * t) + 0.1 * np.sin(100 * t), np.sin(100 * t), 1000.0)
    clipped_samples(np.sin(100 * t))


def warm_numba_kernels() -> None:
    """Compile (or load from the cache) every Numba kernel the suite calls, with the argument
    types the library passes: the signal kernels first (most tests analyse a record, they
    take seconds), then the DEM step loop (via a single impact and a tiny load case)."""
    warm_signal_kernels()

    from pidcore.dem import DemConfig, LoadCase, simulate_impact, simulate_load_case

    simulate_impact(impact_speed_m_s=0.3, dt_s=1e-6)
    simulate_load_case(LoadCase(500.0, 5.0, 50.0),
                       DemConfig(cells=1, steady_cycles=2, block_cycles=1,
                                 max_transient_cycles=1))


def main(done: Path) -> int:
    try:
        warm_numba_kernels()
        status, code = "ok", 0
    except Exception as exc:  # the tests that call the kernel report it properly
        status, code = f"failed: {exc!r}", 1
    tmp = done.with_suffix(".tmp")
    tmp.write_text(status, encoding="utf-8")
    os.replace(tmp, done)  # appears complete or not at all
    return code


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1])))
