"""Benchmark of :func:`pidcore.signal.analyze_power` on a long two-channel record.

Targets: >= 20 M samples per channel per second on one core, peak memory of the analysis call
<= 3 x the record's bytes (2 channels x n x 8 bytes).
"""

from __future__ import annotations

import os
import time
import tracemalloc

from ..errors import ParameterError
from .power import analyze_power
from .synthetic import synthesize_shaker_record

#: Targets stated in the benchmark's output.
TARGET_SAMPLES_PER_S = 20e6
TARGET_PEAK_MEMORY_RATIO = 3.0


def run_signal_bench(n_samples: int = 10_000_000, *, repeat: int = 3) -> dict:
    """Time :func:`analyze_power` on a synthetic force/velocity record of ``n_samples`` each.

    Returns
    -------
    dict
        ``samples_per_s``: samples *per channel* analysed per second (best of ``repeat``),
        ``total_samples_per_s``: both channels together, ``wall_s``: best wall time of one
        analysis, ``wall_s_all``: every repeat (the first includes numba compilation if the
        cache is cold; a warm-up call is made before timing), ``peak_memory_bytes``:
        tracemalloc peak of one analysis call (numpy buffers are traced),
        ``record_bytes``: 2 x n x 8, ``peak_memory_ratio``: their quotient, the targets, and
        whether they are met.
    """
    if n_samples < 10_000:
        raise ParameterError(f"n_samples {n_samples}: expected >= 10000 samples per channel")
    fs = 51_200.0
    f = 500.0 * 1.0007  # a drive slightly off its nominal value, as a controller leaves it
    rec = synthesize_shaker_record(mass_kg=0.25, acceleration_amplitude_m_s2=49.0,
                                   frequency_hz=f, sample_rate_hz=fs,
                                   n_periods=n_samples * f / fs, viscous_damping_n_s_m=2.0,
                                   coulomb_friction_n=0.3, force_harmonics_n=(0.2, 0.1),
                                   snr_db=40.0, seed=1)
    force, vel = rec.force_n[:n_samples], rec.velocity_m_s[:n_samples]
    n = force.shape[0]

    def once():
        return analyze_power(force, vel, fs, frequency_hz=500.0, source="bench")

    once()  # warm-up: numba compile / cache load
    walls = []
    for _ in range(max(1, int(repeat))):
        t0 = time.perf_counter()
        result = once()
        walls.append(time.perf_counter() - t0)
    tracemalloc.start()
    try:
        once()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    wall = min(walls)
    record_bytes = 2 * n * 8
    rate = n / wall
    return {
        "n_samples_per_channel": n,
        "n_channels": 2,
        "samples_per_s": rate,
        "total_samples_per_s": 2 * rate,
        "wall_s": wall,
        "wall_s_all": walls,
        "peak_memory_bytes": int(peak),
        "record_bytes": record_bytes,
        "peak_memory_ratio": peak / record_bytes,
        "target_samples_per_s": TARGET_SAMPLES_PER_S,
        "target_peak_memory_ratio": TARGET_PEAK_MEMORY_RATIO,
        "meets_speed_target": rate >= TARGET_SAMPLES_PER_S,
        "meets_memory_target": peak / record_bytes <= TARGET_PEAK_MEMORY_RATIO,
        "cpu_count": os.cpu_count(),
        "numba_threads": 1,
        "frequency_hz": result.frequency_hz,
        "loss_factor": result.loss_factor,
    }


_CSV_READ_SCRIPT = """
import json, sys, time
import numpy, pandas, pidcore.io
def hwm():  # VmHWM belongs to this process image (ru_maxrss survives exec from the parent)
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) * 1024
base = hwm()
t0 = time.perf_counter()
m = pidcore.io.read_measurement(sys.argv[1])
wall = time.perf_counter() - t0
peak = hwm()
print(json.dumps({"wall_s": wall, "rss_growth_bytes": peak - base,
                  "n_samples": m.channels[0].n_samples}))
"""


def run_csv_read_bench(n_samples: int = 5_000_000, *, directory: str | None = None) -> dict:
    """Peak memory of reading a ``Time [s],Force [N],Velocity [m/s]`` CSV export of
    ``n_samples`` rows (9 significant digits), in a fresh process (resident set growth after
    the imports, so that the C parser's buffers count too).

    Target (issue 9): ``rss_ratio`` = growth / file size <= 3.
    """
    import json
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    import numpy as np

    fs = 51_200.0
    rec = synthesize_shaker_record(mass_kg=0.25, acceleration_amplitude_m_s2=30.0,
                                   frequency_hz=100.0, sample_rate_hz=fs,
                                   n_periods=n_samples * 100.0 / fs, viscous_damping_n_s_m=2.0,
                                   snr_db=60.0, seed=1)
    with tempfile.TemporaryDirectory(dir=directory) as tmp:
        path = Path(tmp) / "export.csv"
        table = np.column_stack([np.arange(rec.force_n.size) / fs, rec.force_n,
                                 rec.velocity_m_s])
        np.savetxt(path, table, delimiter=",", fmt="%.9g",
                   header="Time [s],Force [N],Velocity [m/s]", comments="")
        size = path.stat().st_size
        root = str(Path(__file__).resolve().parents[2])
        env = {**os.environ, "PYTHONPATH": root + os.pathsep + os.environ.get("PYTHONPATH", "")}
        out = subprocess.run([sys.executable, "-c", _CSV_READ_SCRIPT, str(path)], env=env,
                             capture_output=True, text=True, check=True).stdout
    result = json.loads(out)
    return {**result, "file_bytes": size, "rss_ratio": result["rss_growth_bytes"] / size,
            "target_rss_ratio": TARGET_PEAK_MEMORY_RATIO,
            "meets_memory_target": result["rss_growth_bytes"] / size <= TARGET_PEAK_MEMORY_RATIO}
