"""Bundled sample data: the paper's Table 3, a DEM store of the Table 3 grid and
virtual shaker-test exports, all regenerable with ``pidcore samples make``.

The exports are **synthetic**: the DEM coupon driven at a few load cases, recorded as an
LMS/Testlab user would export them. Force = m_coupon * a + force of the particles on the cells
(scaled to 441 cells); velocity as a laser vibrometer sees it (with an output delay);
acceleration as the impedance head sees it; sensor noise; 25.6 kHz sampling. Each is written in
one of the formats users export (UFF58 ASCII, UFF58b binary, CSV, MAT, HDF5).
"""

from __future__ import annotations

import csv
import os
import shutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from io import StringIO
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .atomic_files import write_atomically
from .errors import ParameterError, StoreError
from .records import Channel, Measurement

if TYPE_CHECKING:
    from .dem.simulate import DemConfig, LoadCase
    from .specimen import Specimen

#: Sampling rate of the exports, Hz (a common Testlab setting).
EXPORT_SAMPLE_RATE_HZ = 25_600.0
#: Vibrometer output delay put into the exports, s (pass it with --velocity-delay).
EXPORT_VELOCITY_DELAY_S = 5e-5
#: Sensor signal-to-noise ratio of the exports, dB.
EXPORT_SNR_DB = 45.0
#: Drive periods dropped at each end of an export (the resampling filter's edges).
EXPORT_TRIM_PERIODS = 2


@dataclass(frozen=True)
class SampleCase:
    """One virtual shaker test: load case and the format it is exported in."""

    frequency_hz: float
    acceleration_g: float
    fill_percent: float
    file_format: str  # "uff", "uff58b", "csv", "mat", "hdf5"

    @property
    def file_name(self) -> str:
        ext = {"uff": "uff", "uff58b": "uff", "csv": "csv", "mat": "mat", "hdf5": "h5"}
        tag = "_58b" if self.file_format == "uff58b" else ""
        return (f"synthetic_f{self.frequency_hz:g}Hz_a{self.acceleration_g:g}g_"
                f"fill{self.fill_percent:g}_acrylic{tag}.{ext[self.file_format]}")


#: The bundled exports: the paper's experimental cases (50 % fill), one per format.
SAMPLE_CASES: tuple[SampleCase, ...] = (
    SampleCase(50, 5, 50, "uff"),
    SampleCase(100, 10, 50, "uff58b"),
    SampleCase(500, 1, 50, "csv"),
    SampleCase(500, 5, 50, "mat"),
    SampleCase(1000, 5, 50, "hdf5"),
)


def virtual_shaker_measurement(
    *, time_s: np.ndarray, shaker_force_n: np.ndarray, frequency_hz: float,
    acceleration_m_s2: float, source: str,
    sample_rate_hz: float = EXPORT_SAMPLE_RATE_HZ,
    velocity_delay_s: float = EXPORT_VELOCITY_DELAY_S,
    snr_db: float = EXPORT_SNR_DB, seed: int = 0,
) -> Measurement:
    """Turn a DEM shaker-force record into a sensor-like export at ``sample_rate_hz``.

    The coupon motion is known exactly (acceleration ``a sin wt``), so velocity and acceleration
    are written analytically at the export rate; only the force is resampled (polyphase, with
    anti-aliasing) from the DEM sampling rate. Edge cycles touched by the resampling filter are
    dropped.
    """
    fs_in = 1.0 / float(np.median(np.diff(time_s)))
    ratio = Fraction(sample_rate_hz / fs_in).limit_denominator(1000)
    from scipy.signal import resample_poly  # here: importing scipy.signal takes ~0.8 s

    force = resample_poly(shaker_force_n, ratio.numerator, ratio.denominator)
    t = time_s[0] + np.arange(force.size) / sample_rate_hz
    trim = int(round(EXPORT_TRIM_PERIODS * sample_rate_hz / frequency_hz))  # each end
    force, t = force[trim:-trim], t[trim:-trim]
    w = 2 * np.pi * frequency_hz
    accel = acceleration_m_s2 * np.sin(w * t)
    velocity = -acceleration_m_s2 / w * np.cos(w * (t - velocity_delay_s))
    rng = np.random.default_rng(seed)

    def noisy(x: np.ndarray) -> np.ndarray:
        rms = float(np.sqrt(np.mean((x - x.mean()) ** 2)))
        return x + rng.normal(0.0, rms * 10 ** (-snr_db / 20), x.size)

    channels = (
        Channel("Force", "force", noisy(force), sample_rate_hz, "N"),
        Channel("Velocity", "velocity", noisy(velocity), sample_rate_hz, "m/s"),
        Channel("Acceleration", "acceleration", noisy(accel), sample_rate_hz, "m/s^2"),
    )
    metadata = {"synthetic": "virtual shaker test from pidcore DEM",
                "nominal_frequency_hz": frequency_hz,
                "nominal_acceleration_m_s2": acceleration_m_s2,
                "velocity_delay_s": velocity_delay_s, "snr_db": snr_db}
    return Measurement(source, channels, "", "", metadata)


def make_samples(out_dir: str | os.PathLike = "data_samples", *, run_sweep: bool = True,
                 workers: int | None = None, progress: bool = True) -> dict[str, Path]:
    """Regenerate ``data_samples/``: Table 3 CSV, DEM grid store, virtual shaker exports."""
    from importlib import resources

    from .dem.persist import run_key_0_1
    from .dem.simulate import DemConfig
    from .dem.sweep import grid_cases, run_key
    from .dem.sweep import run_sweep as sweep
    from .store import Store

    out = Path(out_dir)
    (out / "exports").mkdir(parents=True, exist_ok=True)
    written: dict[str, Path] = {}
    table = out / "paper_table3.csv"
    with resources.as_file(resources.files("pidcore.data") / "paper_table3.csv") as src:
        shutil.copyfile(src, table)
    written["paper_table3"] = table

    store_path = out / "dem_table3.h5"
    config = DemConfig()
    cases = grid_cases("table3")
    if store_path.exists():
        # the bundled store must hold one consistent grid; never delete a user's runs
        wanted = {run_key(case, config) for case in cases} | {
            run_key_0_1(case, config) for case in cases}  # a store written by 0.1
        stale = set(Store(store_path).list_dem_runs().get("case_key", [])) - wanted
        if stale:
            raise StoreError(f"{store_path}: holds {len(stale)} DEM run(s) from other settings "
                             f"(e.g. {sorted(stale)[0]}); move or delete it to regenerate")
    if run_sweep:
        sweep(cases, config, store_path=store_path, workers=workers, progress=progress)
    written["dem_store"] = store_path
    store = Store(store_path)
    for i, sample in enumerate(SAMPLE_CASES):
        case = next(c for c in cases if (c.frequency_hz, c.acceleration_g, c.fill_percent)
                    == (sample.frequency_hz, sample.acceleration_g, sample.fill_percent))
        key = run_key(case, config)
        if not store.has_dem_run(key) and store.has_dem_run(run_key_0_1(case, config)):
            key = run_key_0_1(case, config)
        if not store.has_dem_run(key):
            raise StoreError(f"{store_path}: no DEM run {key}; run without --skip-sweep first")
        entry = store.get_dem_run(key)
        start = int(entry.record["steady_start_cycle"]) * int(
            round(entry.record["sample_rate_hz"] / case.frequency_hz))
        m = virtual_shaker_measurement(
            time_s=entry.arrays["sample_time_s"][start:],
            shaker_force_n=entry.arrays["shaker_force_n"][start:],
            frequency_hz=case.frequency_hz, acceleration_m_s2=case.acceleration_m_s2,
            source=sample.file_name, seed=1000 + i)
        path = out / "exports" / sample.file_name
        _write_export(m, path, sample.file_format)
        written[sample.file_name] = path
    sidecar = out / "loadcases.csv"
    # the exports' vibrometer delay too: `--sidecar loadcases.csv` (CLI) and the app's settings
    # table analyse them at it without a --velocity-delay
    write_atomically(sidecar, "file,fill_percent,material,direction,velocity_delay_us\n"
                     + "".join(f"{s.file_name},{s.fill_percent:g},acrylic,z,"
                               f"{EXPORT_VELOCITY_DELAY_S * 1e6:g}\n" for s in SAMPLE_CASES))
    written["loadcases"] = sidecar
    return written


def _write_export(measurement, path: Path, file_format: str) -> None:
    """``measurement`` written to ``path`` in an export format of the samples (``uff58b``:
    binary UFF 58b; ``uff``: ASCII)."""
    from .io import write_measurement

    write_measurement(measurement, path, "uff" if file_format.startswith("uff") else file_format,
                      binary=file_format == "uff58b")


#: File extension of each export format :func:`own_specimen_exports` writes.
OWN_EXPORT_EXTENSIONS = {"uff": "uff", "uff58b": "uff", "csv": "csv", "mat": "mat", "hdf5": "h5"}


def _check_export_periods(case: LoadCase, config: DemConfig) -> None:
    """Refuse a DEM config whose exports ``pidcore analyze`` would refuse, before any run.

    A run that reaches its transient cap measures ``steady_cycles`` cycles; the export drops
    :data:`EXPORT_TRIM_PERIODS` periods at each end, so ``steady_cycles = 10`` wrote files of 6
    drive periods, which the analysis refuses (at least ``MIN_PERIODS``) -- found only after
    every DEM run of the trial had been simulated and written.
    """
    from . import defaults
    from .dem.simulate import required_steady_cycles

    cycles = required_steady_cycles(case, config)
    periods = cycles - 2 * EXPORT_TRIM_PERIODS
    if periods < defaults.MIN_PERIODS:
        raise ParameterError(
            f"config: steady_cycles {cycles} gives exports of {periods} drive periods (the "
            f"export drops {EXPORT_TRIM_PERIODS} at each end), fewer than the "
            f"{defaults.MIN_PERIODS} pidcore analyze needs; expected steady_cycles >= "
            f"{defaults.MIN_PERIODS + 2 * EXPORT_TRIM_PERIODS}")


def own_specimen_exports(
    specimen: Specimen, cases: Sequence[tuple[float, float, float, str]],
    out_dir: str | os.PathLike, *, config: DemConfig, snr_db: float = 40.0,
    velocity_delay_s: float = EXPORT_VELOCITY_DELAY_S, first_noise_seed: int = 50,
    prefix: str = "trial", report: Callable[[str], None] | None = None,
) -> list[Path]:
    """Virtual shaker exports of ``specimen`` (its values the hidden truth) and their sidecar.

    One DEM run per case ``(frequency_hz, acceleration_g, fill_percent, file_format)``
    (``file_format`` one of :data:`OWN_EXPORT_EXTENSIONS`), the empty structure's loss factor
    ``[coupon] baseline_loss_factor`` added to the shaker force as the viscous force
    eta0 * omega * m_s * v, written as a sensor would record it (:func:`virtual_shaker_measurement`)
    into ``out_dir`` with a ``loadcases.csv`` naming each file's fill, the specimen's particle
    material and name, and the vibrometer delay. The material and name are the specimen's: a
    copy of the trial script for another specimen wrote the trial's ``alumina`` into every
    load case and failed (or, with a table material, mislabelled the tests). Each file name
    states its fill, so two fills of one frequency, acceleration and format are two files
    (they overwrote one another). Returns the export paths in ``cases`` order.
    """
    from .dem.simulate import LoadCase, simulate_load_case

    out = Path(out_dir)
    formats = set(OWN_EXPORT_EXTENSIONS)
    names: list[str] = []
    for f, a, fill, fmt in cases:
        if fmt not in formats:
            raise ParameterError(f"cases: format {fmt!r}; expected one of {sorted(formats)}")
        name = (f"{prefix}_f{f:g}Hz_a{a:g}g_fill{fill:g}pct"
                f"{'_58b' if fmt == 'uff58b' else ''}.{OWN_EXPORT_EXTENSIONS[fmt]}")
        if name in names:
            raise ParameterError(f"cases: two cases write {name}; give each load case once")
        names.append(name)
    eta0 = specimen.coupon.baseline_loss_factor
    material = specimen.particles.material
    for f, a, fill, _ in cases:
        _check_export_periods(LoadCase(float(f), float(a), float(fill), material=material),
                              config)
    out.mkdir(parents=True, exist_ok=True)
    sidecar = StringIO()
    rows = csv.writer(sidecar, lineterminator="\n")
    rows.writerow(["file", "fill_percent", "material", "direction", "velocity_delay_us",
                   "specimen"])
    paths: list[Path] = []
    for i, ((f, a, fill, fmt), name) in enumerate(zip(cases, names, strict=True)):
        case = LoadCase(float(f), float(a), float(fill), material=material)
        run = simulate_load_case(case, config, specimen=specimen)
        steady = run.steady_slice()
        force = (run.shaker_force_n[steady]
                 + eta0 * case.omega_rad_s * run.moving_mass_kg * run.velocity_m_s[steady])
        measurement = virtual_shaker_measurement(
            time_s=run.sample_time_s[steady], shaker_force_n=force, frequency_hz=float(f),
            acceleration_m_s2=case.acceleration_m_s2, source=name, snr_db=snr_db,
            velocity_delay_s=velocity_delay_s, seed=first_noise_seed + i)
        path = out / name
        _write_export(measurement, path, fmt)
        paths.append(path)
        rows.writerow([name, f"{fill:g}", material, case.direction,
                       f"{velocity_delay_s * 1e6:g}", specimen.name])
        if report is not None:
            report(f"wrote {path}")
    write_atomically(out / "loadcases.csv", sidecar.getvalue())
    return paths
