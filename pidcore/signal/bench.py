"""Benchmark of :func:`pidcore.signal.analyze_power` on a long two-channel record, and of the
peak memory of reading long exports and analysing them (:func:`run_read_bench`).

Targets: >= 20 M samples per channel per second on one core, peak memory of the analysis call
<= 3 x the record's bytes (2 channels x n x 8 bytes).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..records import Channel, Measurement
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


# --- pidcore bench read ------------------------------------------------------------------

# Benchmark of the peak memory of reading a long export in each format, and of analysing
# it with ``pidcore analyze`` with and without a store (``pidcore bench read``).
#
# Each read or analysis runs in a fresh interpreter: the growth of its peak resident set
# (VmHWM) after the imports, and its tracemalloc peak (numpy buffers are traced; pandas'
# tokenizer and numba's code are not). Both are given as multiples of the bytes of the
# channels the analysis uses (force and velocity, float64), with ``--unused N`` further
# acceleration channels in the file that every read holds (a Testlab export of more
# channels than the analysis needs). An analysis's peaks are given less those of the same
# analysis of a 20 000-sample export (the modules it imports, numba's dispatchers): what
# grows with the record.
#
# Targets (structural, not timings), as multiples of the used channels' bytes with ``share``
# the file's channels over the used ones (1 + N/2): reading a format that stores float64
# samples (UFF, MAT, HDF5) holds the file's channels once, at most 1.5 x ``share``; a CSV
# also its time column, 2 x ``share``; the analysis adds the Eq. 11 analysis (``pidcore bench
# signal``: 1.06 x) and the checks of each used channel, at most ``share`` + 2; saved, the
# store holds its file in memory while it writes (README, "The store"), up to the
# measurement once more: 2 x ``share`` + 2.

#: Targets stated in the benchmark's output: multiples of the file's channels' bytes for a
#: read; the analysis may add :data:`TARGET_ANALYSIS_ADDED` x the used channels' bytes.
TARGET_READ_RATIO = {"csv": 2.0, "uff_ascii": 1.5, "uff_58b": 1.5, "mat": 1.5, "hdf5": 1.5}
TARGET_ANALYSIS_ADDED = 2.0
#: Samples per channel of the export whose analysis's peaks are subtracted.
BASELINE_SAMPLES = 20_000
#: The formats read, and the file each is written to (``uff_58b``: binary).
READ_FORMATS = ("csv", "uff_ascii", "uff_58b", "mat", "hdf5")

_READ_SCRIPT = r"""
import json, sys, tracemalloc
import numpy, pandas, scipy.io, h5py, pyuff, pidcore.io, pidcore.measure, pidcore.store
def hwm():  # VmHWM belongs to this process image (ru_maxrss survives exec from the parent)
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) * 1024
what, path, store = sys.argv[1], sys.argv[2], sys.argv[3]
base = hwm()
tracemalloc.start()
if what == "read":
    pidcore.io.read_measurement(path)
else:  # what `pidcore analyze` does with a file, without or with its store
    from pidcore.measure import AnalysisOptions, analyze_file, save_analyses
    options = AnalysisOptions()
    record = analyze_file(path, options)
    if what == "analyze_store":
        save_analyses(store, [record], options)
peak = tracemalloc.get_traced_memory()[1]
tracemalloc.stop()
print(json.dumps({"rc": 0, "rss_growth_bytes": hwm() - base, "traced_peak_bytes": peak}))
"""


def _long_export(n_samples: int, n_unused: int) -> Measurement:
    fs = 51_200.0
    rec = synthesize_shaker_record(mass_kg=0.25, acceleration_amplitude_m_s2=49.0,
                                   frequency_hz=100.0, sample_rate_hz=fs,
                                   n_periods=n_samples * 100.0 / fs, viscous_damping_n_s_m=2.0,
                                   snr_db=60.0, seed=1)
    channels = [Channel("Force", "force", rec.force_n[:n_samples], fs, "N"),
                Channel("Velocity", "velocity", rec.velocity_m_s[:n_samples], fs, "m/s")]
    acceleration = np.gradient(rec.velocity_m_s[:n_samples], 1.0 / fs)
    channels += [Channel(f"Acc {k + 1}", "acceleration", acceleration * (1.0 + 0.01 * k), fs,
                         "m/s^2") for k in range(n_unused)]
    return Measurement("bench", tuple(channels), sha256="", file_format="")


def _measure_read(what: str, path: Path, store: Path) -> dict:
    root = str(Path(__file__).resolve().parents[2])
    env = {**os.environ, "PYTHONPATH": root + os.pathsep + os.environ.get("PYTHONPATH", ""),
           "MPLBACKEND": "Agg"}
    out = subprocess.run([sys.executable, "-c", _READ_SCRIPT, what, str(path), str(store)],
                         env=env, capture_output=True, text=True, check=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def run_read_bench(n_samples: int = 1_000_000, *, n_unused: int = 0,
                   directory: str | None = None) -> dict:
    """``pidcore bench read``: peak memory of reading a force/velocity export of
    ``n_samples`` per channel (and ``n_unused`` acceleration channels) in each format, and
    of ``pidcore analyze`` of its CSV and 58b files without and with a store; what is
    measured and the targets: the comment above :data:`TARGET_READ_RATIO`.

    Returns
    -------
    dict
        Per case (``read_csv``, ``read_uff_ascii``, ..., ``analyze_no_store_csv``, ...):
        ``<case>_rss_ratio`` and ``<case>_traced_ratio`` (peaks / used channels' bytes),
        ``<case>_target_ratio`` and ``<case>_meets_target`` (by the traced peak, which
        neither the allocator's caching nor numba's code moves); ``used_channel_bytes``.
    """
    from ..io import write_measurement

    if n_samples < 10 * BASELINE_SAMPLES:
        raise ParameterError(f"n_samples {n_samples}: expected >= {10 * BASELINE_SAMPLES} "
                             "samples per channel")
    used = 2 * n_samples * 8
    share = 1.0 + n_unused / 2.0
    result: dict = {"n_samples_per_channel": n_samples, "n_unused_channels": n_unused,
                    "used_channel_bytes": used, "file_channels_share": share}
    files = {"csv": "export.csv", "uff_ascii": "export.uff", "uff_58b": "export_58b.uff",
             "mat": "export.mat", "hdf5": "export.h5"}
    with tempfile.TemporaryDirectory(dir=directory) as tmp:
        folder = Path(tmp)
        for fmt in READ_FORMATS:
            analysed = fmt in ("csv", "uff_58b")
            sizes = (n_samples, BASELINE_SAMPLES) if analysed else (n_samples,)
            measured: dict = {}
            for n in sizes:
                path = folder / f"{n}_{files[fmt]}"
                write_measurement(_long_export(n, n_unused), path, binary=fmt == "uff_58b")
                if n == n_samples:
                    result[f"read_{fmt}_file_bytes"] = path.stat().st_size
                    measured["read"] = _measure_read("read", path, folder / "store.h5")
                for what in ("analyze_no_store", "analyze_store") if analysed else ():
                    (folder / "store.h5").unlink(missing_ok=True)
                    measured[what, n] = _measure_read(what, path, folder / "store.h5")
                path.unlink()
            cases = {"read": (measured["read"], None, TARGET_READ_RATIO[fmt] * share)}
            for what in ("analyze_no_store", "analyze_store") if analysed else ():
                cases[what] = (measured[what, n_samples], measured[what, BASELINE_SAMPLES],
                               share * (2 if what == "analyze_store" else 1)
                               + TARGET_ANALYSIS_ADDED)
            for what, (peaks, baseline, target) in cases.items():
                if peaks["rc"] != 0 or (baseline is not None and baseline["rc"] != 0):
                    raise RuntimeError(f"{what} of the {fmt} export failed")
                case = f"{what}_{fmt}"
                less = baseline or {"rss_growth_bytes": 0, "traced_peak_bytes": 0}
                traced = (peaks["traced_peak_bytes"] - less["traced_peak_bytes"]) / used
                result[f"{case}_rss_ratio"] = (peaks["rss_growth_bytes"]
                                               - less["rss_growth_bytes"]) / used
                result[f"{case}_traced_ratio"] = traced
                result[f"{case}_target_ratio"] = target
                result[f"{case}_meets_target"] = traced <= target
    return result
