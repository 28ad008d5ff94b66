"""Logic behind the Streamlit app, kept free of Streamlit so that it is tested directly.

The app (:mod:`pidcore._app`) only lays out widgets; everything it shows comes from the
functions here: uploads to temporary files and back into domain records, per-file analysis with
errors turned into messages (one bad file never stops the others), load cases, the comparison
of one load case with our DEM, the pchip model and the paper, chart data as plain DataFrames,
DEM sweeps run one case at a time (each saved at once) and report downloads.

Uploaded bytes are only ever *parsed* by :mod:`pidcore.io` readers (text, UFF, HDF5 datasets,
MAT arrays); nothing uploaded is unpickled or evaluated.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from . import defaults
from .errors import ParameterError, PidcoreError

if TYPE_CHECKING:  # imported lazily at run time: the app starts even if a subpackage is broken
    from .compare import LoadCase
    from .measure import AnalysisOptions, AnalyzedRecord
    from .records import Measurement

#: Environment variable naming the store the app reads and writes.
STORE_ENV_VAR = "PIDCORE_STORE"
#: Environment variable naming a read-only store of reference DEM runs (optional).
DEM_STORE_ENV_VAR = "PIDCORE_DEM_STORE"
#: The DEM store of the bundled samples (``pidcore samples make``), relative to the working
#: folder; used as reference DEM runs when present and no other is named.
BUNDLED_DEM_STORE = Path("data_samples") / "dem_table3.h5"
#: Label of "no channel" in the role selectboxes (acceleration is optional).
NO_CHANNEL = "(none)"
#: Fill (packing ratio, %) proposed for an upload whose name states none (the paper's
#: experiments were all at 50 %).
DEFAULT_FILL_PERCENT = 50.0
#: Points on one force-displacement loop drawn in the app.
LOOP_POINTS = 256


# --- store ------------------------------------------------------------------------------------

def store_path(environ: Mapping[str, str] | None = None) -> Path:
    """Store used by the app: ``$PIDCORE_STORE`` or :data:`pidcore.defaults.STORE_PATH`."""
    env = os.environ if environ is None else environ
    value = env.get(STORE_ENV_VAR, "").strip()
    return Path(value) if value else Path(defaults.STORE_PATH)


def dem_store_path(environ: Mapping[str, str] | None = None, *,
                   cwd: Path | None = None) -> Path | None:
    """Read-only store of reference DEM runs: ``$PIDCORE_DEM_STORE``, else the bundled
    :data:`BUNDLED_DEM_STORE` if it exists in the working folder, else None.

    Its DEM runs join the app store's own in Compare and Report; the app never writes to it.
    """
    env = os.environ if environ is None else environ
    value = env.get(DEM_STORE_ENV_VAR, "").strip()
    if value:
        return Path(value)
    bundled = (cwd or Path.cwd()) / BUNDLED_DEM_STORE
    return bundled if bundled.is_file() else None


@dataclass(frozen=True)
class AppStores:
    """The stores of one app session: the app store (read and written) and an optional
    read-only store of reference DEM runs."""

    path: Path
    dem_reference: Path | None = None

    @classmethod
    def from_environment(cls, environ: Mapping[str, str] | None = None, *,
                         cwd: Path | None = None) -> AppStores:
        return cls(store_path(environ), dem_store_path(environ, cwd=cwd))

    def stamp(self) -> tuple:
        """(path, mtime, size) of each store: changes whenever a store is rewritten (the
        store replaces its file atomically on every commit), so it keys cached listings."""
        out = []
        for p in (self.path, self.dem_reference):
            try:
                stat = Path(p).stat() if p is not None else None
            except OSError:
                stat = None
            out.append((str(p), stat.st_mtime_ns, stat.st_size) if stat else (str(p), 0, 0))
        return tuple(out)


# --- uploads ----------------------------------------------------------------------------------

def content_sha256(data: bytes) -> str:
    """SHA-256 hex digest of an upload (the cache and store key of its content)."""
    return hashlib.sha256(data).hexdigest()


def check_upload_size(name: str, n_bytes: int, *, limit_mb: float | None = None) -> None:
    """Raise :class:`ParameterError` if an upload is larger than ``limit_mb`` megabytes.

    ``limit_mb`` defaults to :data:`pidcore.defaults.APP_MAX_UPLOAD_MB`. Streamlit enforces the
    same limit in the browser (``server.maxUploadSize`` and the uploader's
    ``max_upload_size``); this check is the server-side guard for clients that bypass it.
    """
    limit_mb = defaults.APP_MAX_UPLOAD_MB if limit_mb is None else limit_mb
    if n_bytes > limit_mb * 1024 * 1024:
        raise ParameterError(f"{name}: {n_bytes / 1024 / 1024:.1f} MB is larger than the upload "
                             f"limit of {limit_mb:g} MB")
    if n_bytes == 0:
        raise ParameterError(f"{name}: the file is empty")


def safe_file_name(name: str) -> str:
    """A file name safe to create in a temporary folder (no folders, no odd characters).

    The extension is kept because the readers choose the format from it.

    >>> safe_file_name("../../etc/pass wd.csv")
    'pass_wd.csv'
    """
    base = re.split(r"[\\/]", name)[-1]
    base = re.sub(r"[^A-Za-z0-9._+-]", "_", base).lstrip(".")
    return base[:200] or "upload"


def read_upload(name: str, data: bytes, *, sample_rate_hz: float | None = None) -> Measurement:
    """Parse uploaded bytes with :func:`pidcore.io.read_measurement`.

    The bytes go to a private temporary folder under their own (sanitised) name, are read, and
    the folder is removed. The measurement's ``source`` is the uploaded name, so stored records
    and tables name the user's file, not the temporary copy.
    """
    from .io import read_measurement

    check_upload_size(name, len(data))
    with tempfile.TemporaryDirectory(prefix="pidcore_upload_") as folder:
        path = Path(folder) / safe_file_name(name)
        path.write_bytes(data)
        measurement = read_measurement(path, sample_rate_hz=sample_rate_hz)
    return replace(measurement, source=name, sha256=measurement.sha256 or content_sha256(data))


@dataclass(frozen=True)
class ChannelChoice:
    """Channels of one upload and the roles detected for them (``None`` = not found)."""

    names: tuple[str, ...]
    quantities: tuple[str, ...]
    force: str | None
    velocity: str | None
    acceleration: str | None

    def options(self, role: str) -> list[str]:
        """Selectbox options for ``role``; acceleration may be left out."""
        names = list(self.names)
        return [*names, NO_CHANNEL] if role == "acceleration" else names

    def default_index(self, role: str) -> int:
        """Index of the detected channel; else the first of the role's quantity; else none."""
        detected = getattr(self, role)
        opts = self.options(role)
        if detected in opts:
            return opts.index(detected)
        if role in self.quantities:
            return self.quantities.index(role)
        return len(opts) - 1 if role == "acceleration" else 0


def detect_channels(measurement: Measurement) -> ChannelChoice:
    """Channel names and the roles :func:`pidcore.io.assign_roles` picks automatically.

    When automatic detection fails (ambiguous or missing channels) every role falls back to
    ``None`` and the user chooses in the app; the analysis then reports what is wrong.
    """
    from .io import assign_roles

    force = velocity = acceleration = None
    try:
        roles = assign_roles(measurement)
        force = roles.force.name if roles.force is not None else None
        velocity = roles.velocity.name if roles.velocity is not None else None
        acceleration = roles.acceleration.name if roles.acceleration is not None else None
    except PidcoreError:
        pass
    return ChannelChoice(tuple(c.name for c in measurement.channels),
                         tuple(c.quantity for c in measurement.channels),
                         force, velocity, acceleration)


def options_to_json(options: AnalysisOptions) -> str:
    """Canonical JSON of analysis options (a stable, hashable cache key)."""
    from dataclasses import asdict

    return json.dumps(asdict(options), sort_keys=True)


def options_from_json(text: str) -> AnalysisOptions:
    from .measure import AnalysisOptions

    return AnalysisOptions(**json.loads(text))


def role_options(base: AnalysisOptions, *, force: str | None, velocity: str | None,
                 acceleration: str | None) -> AnalysisOptions:
    """``base`` with the channel mapping chosen for one file (``NO_CHANNEL`` means none)."""
    def clean(value: str | None) -> str | None:
        return None if value in (None, "", NO_CHANNEL) else value

    return replace(base, force=clean(force), velocity=clean(velocity),
                   acceleration=clean(acceleration))


@dataclass(frozen=True)
class ParsedUpload:
    """One upload after reading: its measurement and detected channels, or the read error."""

    name: str
    sha256: str
    measurement: Measurement | None = None
    channels: ChannelChoice | None = None
    error: str | None = None


@dataclass(frozen=True)
class UploadOutcome:
    """Analysis of one uploaded file: a record, or the one-line error that stopped it."""

    name: str
    sha256: str
    record: AnalyzedRecord | None = None
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.record is not None


def error_message(name: str, exc: BaseException) -> str:
    """One-line message for a failed upload; library errors already name the file."""
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    # Readers name the temporary copy; show the user's own file name instead.
    text = re.sub(r"\S*pidcore_upload_[^/\\\s]*[/\\][^:\s]*", name, text)
    # The library's hints name CLI options; in the app the same choice is a selectbox.
    text = re.sub(r"--(force|velocity|acceleration) NAME", r"the '\1 channel' box", text)
    if isinstance(exc, PidcoreError):
        return text if name in text else f"{name}: {text}"
    return f"{name}: could not be read ({type(exc).__name__}: {text})"


#: Exceptions that mean "this upload is bad", shown as a message instead of ending the session.
#: Readers are the boundary to arbitrary bytes; besides PidcoreError, the parsers they use
#: (pyuff, h5py, scipy.io, pandas) raise these on malformed input.
_BAD_INPUT_ERRORS = (PidcoreError, ValueError, OSError, KeyError, IndexError, TypeError,
                     UnicodeError, EOFError, OverflowError, AttributeError)


def parse_upload(name: str, data: bytes, *, sample_rate_hz: float | None = None) -> ParsedUpload:
    """Read one upload and detect its channel roles; never raises for bad data."""
    sha = content_sha256(data)
    try:
        measurement = read_upload(name, data, sample_rate_hz=sample_rate_hz)
        return ParsedUpload(name, sha, measurement, detect_channels(measurement))
    except _BAD_INPUT_ERRORS as exc:
        return ParsedUpload(name, sha, error=error_message(name, exc))


def analyze_parsed(parsed: ParsedUpload, options: AnalysisOptions) -> UploadOutcome:
    """Analyse a parsed upload with ``options``; any failure becomes the outcome's error."""
    from .measure import analyze_measurement

    if parsed.measurement is None:
        return UploadOutcome(parsed.name, parsed.sha256, error=parsed.error)
    try:
        record = analyze_measurement(parsed.measurement, options)
    except _BAD_INPUT_ERRORS as exc:
        return UploadOutcome(parsed.name, parsed.sha256, error=error_message(parsed.name, exc))
    return UploadOutcome(parsed.name, parsed.sha256, record=record)


def analyze_upload(name: str, data: bytes, options: AnalysisOptions) -> UploadOutcome:
    """Read and analyse one upload; never raises for bad user data.

    One bad file therefore cannot stop a batch or a session.
    """
    return analyze_parsed(parse_upload(name, data, sample_rate_hz=options.sample_rate_hz),
                          options)


# --- load cases -------------------------------------------------------------------------------

def load_case_of(record: AnalyzedRecord, *, fill_percent: float, material: str,
                 direction: str = defaults.COMPARE_DEFAULT_DIRECTION) -> LoadCase:
    """Load case of an analysed record: measured frequency and acceleration, stated fill etc."""
    from .compare import LoadCase

    a = record.analysis
    return LoadCase(float(a.frequency_hz), float(a.acceleration_g), float(fill_percent),
                    material, direction)


#: Name of an uploaded sidecar table stating fill/material/direction per file.
SIDECAR_UPLOAD_NAME = "loadcases.csv"


def is_sidecar_upload(name: str) -> bool:
    """Whether an upload is a load case sidecar table rather than a measurement."""
    return Path(name).name.lower() == SIDECAR_UPLOAD_NAME


def read_sidecar_upload(data: bytes) -> pd.DataFrame:
    """An uploaded ``loadcases.csv`` (:func:`pidcore.compare.read_sidecar`), via a temp file."""
    from .compare import read_sidecar

    with tempfile.TemporaryDirectory(prefix="pidcore_upload_") as folder:
        path = Path(folder) / SIDECAR_UPLOAD_NAME
        path.write_bytes(data)
        try:
            return read_sidecar(path)
        except PidcoreError as exc:
            raise type(exc)(str(exc).replace(str(path), SIDECAR_UPLOAD_NAME)) from None


@dataclass(frozen=True)
class StatedCase:
    """Fill, material and direction proposed for an upload, and where they come from."""

    fill_percent: float
    material: str
    direction: str
    origin: str


def stated_case(name: str, sidecar: pd.DataFrame | None = None) -> StatedCase:
    """What the file name and an uploaded sidecar state about an upload (sidecar wins).

    Without a stated fill, :data:`DEFAULT_FILL_PERCENT` is proposed and the origin says so;
    the user confirms or corrects it in the app.
    """
    from .compare import SIDECAR_COLUMNS, resolve_load_case
    from .compare.loadcase import parse_file_name

    table = sidecar if sidecar is not None else pd.DataFrame(columns=list(SIDECAR_COLUMNS))
    try:
        s = resolve_load_case(Path(Path(name).name), sidecar=table)
        return StatedCase(s.fill_percent, s.material, s.direction, s.origin)
    except PidcoreError:
        try:  # no fill stated (or a bad sidecar row): keep what the name states, propose a fill
            found = parse_file_name(Path(name).name)
        except PidcoreError:
            found = {}
        return StatedCase(DEFAULT_FILL_PERCENT,
                          str(found.get("material", defaults.COMPARE_DEFAULT_MATERIAL)),
                          str(found.get("direction", defaults.COMPARE_DEFAULT_DIRECTION)),
                          f"fill: not stated, {DEFAULT_FILL_PERCENT:g} % proposed")


def group_load_cases(cases: Sequence[LoadCase]) -> list[list[int]]:
    """Indices of ``cases`` grouped into one load case each (within the compare tolerances).

    Two measurements of the same nominal case differ a little in measured frequency and
    acceleration; :class:`pidcore.compare.Tolerances` says when they are the same case.
    """
    from .compare import Tolerances

    tol = Tolerances()
    groups: list[list[int]] = []
    for i, case in enumerate(cases):
        for members in groups:
            if tol.matches(case, cases[members[0]]):
                members.append(i)
                break
        else:
            groups.append([i])
    return groups


#: Columns of the results table, units in the names.
RESULT_COLUMNS = ("file", "load case", "material", "frequency [Hz]", "acceleration [g]",
                  "loss factor [-]", "SDC [-]", "SDC stderr [-]", "force channel",
                  "velocity channel")


def results_table(records: Sequence[tuple[AnalyzedRecord, LoadCase]]) -> pd.DataFrame:
    """One row per analysed record: drive, loss factor and SDC with its standard error."""
    rows = []
    for r, case in records:
        a = r.analysis
        rows.append({
            "file": Path(r.measurement.source).name,
            "load case": case.label(),
            "material": case.material,
            "frequency [Hz]": a.frequency_hz,
            "acceleration [g]": a.acceleration_g,
            "loss factor [-]": a.loss_factor,
            "SDC [-]": a.sdc,
            "SDC stderr [-]": a.sdc_stderr,
            "force channel": r.channels_used.get("force", ""),
            "velocity channel": r.channels_used.get("velocity", ""),
        })
    return pd.DataFrame(rows, columns=list(RESULT_COLUMNS))


def format_sdc(sdc: float, stderr: float) -> str:
    """SDC with its standard error as shown in the app, e.g. ``'0.1856 ± 0.0042'``."""
    return f"{sdc:.4f} ± {stderr:.4f}"


def save_records(path: str | os.PathLike,
                 records: Sequence[tuple[AnalyzedRecord, LoadCase]],
                 options: AnalysisOptions) -> list[str]:
    """Save analysed records with their load cases to the store in one locked transaction.

    Like :func:`pidcore.measure.save_analyses`, plus the load case fields (``fill_percent``,
    ``material``, ``direction``) in each analysis record, which the report table needs. The
    corrections and each file's channel mapping are stored as the analysis parameters. Two
    sessions saving at once are serialised by the store's write lock.
    """
    from .measure import store_analysis
    from .store import Store

    if not records:
        raise ParameterError("nothing to save: no file was analysed successfully")
    # the channel mapping is per file: stored as each analysis's "channels", not as options
    parameters = replace(options, force=None, velocity=None, acceleration=None).parameters()
    store = Store(path)
    with store.transaction():
        return [store_analysis(store, r, parameters, fields=case.as_record("stated in the app"))
                for r, case in records]


# --- chart data -------------------------------------------------------------------------------

def loop_area(displacement_m: np.ndarray, force_n: np.ndarray) -> float:
    """Area enclosed by a closed force-displacement loop, J (shoelace formula).

    The sign follows the traversal; its magnitude is the energy dissipated per cycle.
    """
    x = np.asarray(displacement_m, dtype=float)
    f = np.asarray(force_n, dtype=float)
    if x.shape != f.shape or x.ndim != 1 or x.size < 3:
        raise ParameterError("loop: displacement and force must be 1-D arrays of equal length >= 3")
    return float(0.5 * np.sum(x * np.roll(f, -1) - np.roll(x, -1) * f))


@dataclass(frozen=True)
class LoopCurve:
    """One force-displacement loop ready to draw."""

    label: str
    displacement_m: np.ndarray
    force_n: np.ndarray

    @property
    def energy_per_cycle_j(self) -> float:
        return abs(loop_area(self.displacement_m, self.force_n))


def measured_loop(record: AnalyzedRecord, *, n_points: int = LOOP_POINTS) -> LoopCurve:
    """One drive period of the measured loop, rebuilt from the fitted harmonics."""
    from .report.comparison_figures import loop_arrays

    x, f = loop_arrays(record.analysis.force_displacement_loop(n_points))
    return LoopCurve(f"measured: {Path(record.measurement.source).name}", x, f)


def dem_loop(entry) -> LoopCurve | str:
    """The loop of a stored DEM run (:class:`pidcore.store.StoredEntry`), or why there is none.

    The run's virtual shaker record (``shaker_force_n``, ``velocity_m_s`` over its steady
    cycles) goes through the same harmonic analysis as a measurement
    (:func:`pidcore.signal.analyze_power`), so both loops are one drive period built the same
    way and their areas are comparable energies per cycle.
    """
    from .signal import analyze_power

    arrays, record = entry.arrays, entry.record
    force, velocity = arrays.get("shaker_force_n"), arrays.get("velocity_m_s")
    rate, freq = record.get("sample_rate_hz"), record.get("frequency_hz")
    if force is None or velocity is None or not rate or not freq:
        return f"DEM run {entry.key} has no virtual shaker record (shaker_force_n, velocity_m_s)"
    per_cycle = float(rate) / float(freq)
    start = int(round(float(record.get("steady_start_cycle") or 0) * per_cycle))
    cycles = int((len(force) - start) / per_cycle)
    if cycles < 2:
        return f"DEM run {entry.key} has fewer than 2 steady cycles"
    try:
        analysis = analyze_power(np.asarray(force[start:], float),
                                 np.asarray(velocity[start:], float), float(rate),
                                 frequency_hz=float(freq),
                                 min_periods=min(defaults.MIN_PERIODS, cycles),
                                 n_blocks=max(2, min(defaults.N_UNCERTAINTY_BLOCKS, cycles)))
    except PidcoreError as exc:
        return f"DEM run {entry.key}: no loop ({exc})"
    x, f = analysis.force_displacement_loop(LOOP_POINTS)
    return LoopCurve(f"our DEM: {entry.key.split('_seed')[0]}", np.asarray(x, float),
                     np.asarray(f, float))


def list_dem_runs(path: str | os.PathLike,
                  dem_store: str | os.PathLike | None = None) -> pd.DataFrame:
    """DEM runs of the app store and of the reference store (empty where a store is missing).

    A run in both (same case key) is taken from the app store. Column ``store`` says where each
    run is kept.
    """
    from .store import Store

    frames = []
    for where in (path, dem_store):
        if where is not None and Path(where).is_file():
            runs = Store(where).list_dem_runs()
            if not runs.empty:
                frames.append(runs.assign(store=str(where)))
    if not frames:
        return pd.DataFrame()
    runs = pd.concat(frames, ignore_index=True)
    return runs.drop_duplicates("case_key", keep="first").reset_index(drop=True)


def dem_loops(path: str | os.PathLike, comparison: CaseComparison,
              dem_store: str | os.PathLike | None = None) -> list[LoopCurve]:
    """The DEM loop at the comparison's load case, if our DEM has a run on that grid point."""
    from .store import Store

    grid = getattr(comparison.aligned, "grid_case", None)
    if grid is None or not grid.run_keys:
        return []
    for where in (path, dem_store):
        if where is not None and Path(where).is_file() and Store(where).has_dem_run(
                grid.run_keys[0]):
            found = dem_loop(Store(where).get_dem_run(grid.run_keys[0]))
            return [] if isinstance(found, str) else [found]
    return []


def spectrum_table(record: AnalyzedRecord) -> pd.DataFrame:
    """Amplitudes of the fitted force and velocity harmonics."""
    a = record.analysis
    return pd.DataFrame({
        "harmonic [-]": np.asarray(a.harmonics, dtype=int),
        "frequency [Hz]": np.asarray(a.harmonics, dtype=float) * a.frequency_hz,
        "force amplitude [N]": np.abs(np.asarray(a.force_phasors_n)),
        "velocity amplitude [m/s]": np.abs(np.asarray(a.velocity_phasors_m_s)),
    })


# --- paper table and model --------------------------------------------------------------------

def paper_table() -> pd.DataFrame:
    """The paper's Table 3 (:func:`pidcore.model.load_paper_table3`)."""
    from .model import load_paper_table3

    return load_paper_table3()


# --- comparison of one load case --------------------------------------------------------------

@dataclass(frozen=True)
class CaseComparison:
    """Everything the Compare page shows for one load case.

    Attributes
    ----------
    load_case : LoadCase
        The case: mean measured frequency [Hz] and acceleration [g] of its records, stated fill,
        material and direction.
    measured : pandas.DataFrame
        One row per record: ``file``, ``fill [%]``, ``SDC [-]``, ``SDC stderr [-]``.
    measured_sdc, measured_stderr : float
        Records pooled (:func:`pidcore.compare.pooled_mean`), [-].
    aligned : AlignedCase
        Our DEM (grid value or pchip interpolation) and the paper's values at the case.
    dem_points : pandas.DataFrame
        Our DEM cases at this frequency, acceleration, material and direction, every fill:
        ``fill [%]``, ``SDC [-]``, ``SDC stderr [-]``, ``runs [-]``.
    paper_points : pandas.DataFrame
        Table 3 rows at this frequency and acceleration: ``fill [%]``, ``SDC DEM (paper) [-]``,
        ``SDC measured (paper) [-]`` (empty off the paper's grid or for other materials).
    model_fill_percent, model_sdc : numpy.ndarray
        The pchip model over Table 3 (DEM) along fill at this frequency and acceleration
        (empty where the case lies outside the model's range; it is never extrapolated).
    measured_sdc_eq10, measured_stderr_eq10 : float
        The records' energy per cycle over the DEM case's ``E = m_c a^2 / (2 w^2)`` (Eq. 10),
        pooled: the like-for-like counterpart of our DEM SDC (the Eq. 11 SDC divides by the
        reactive energy instead). NaN without a DEM grid case that knows ``m_c``.
    """

    load_case: LoadCase
    measured: pd.DataFrame
    measured_sdc: float
    measured_stderr: float
    aligned: object
    dem_points: pd.DataFrame
    paper_points: pd.DataFrame
    model_fill_percent: np.ndarray
    model_sdc: np.ndarray
    measured_sdc_eq10: float = float("nan")
    measured_stderr_eq10: float = float("nan")


def _paper_model(paper: pd.DataFrame):
    from .model import SdcModel

    return SdcModel.from_table(paper, value="sdc_dem", source="paper Table 3 (DEM)")


def compare_case(records: Sequence[tuple[AnalyzedRecord, LoadCase]],
                 dem_runs: pd.DataFrame | None, paper: pd.DataFrame, *,
                 model_points: int = 121) -> CaseComparison:
    """Measured SDC of one load case next to our DEM, the pchip model and the paper.

    Parameters
    ----------
    records : sequence of (AnalyzedRecord, LoadCase)
        The records of one load case (see :func:`group_load_cases`); at least one.
    dem_runs : pandas.DataFrame or None
        :meth:`pidcore.store.Store.list_dem_runs` (may be empty).
    paper : pandas.DataFrame
        Table 3 (:func:`pidcore.model.load_paper_table3`).
    """
    from .compare import Aligner, LoadCase, Tolerances, pooled_mean
    from .compare.align import PAPER_DIRECTION, PAPER_MATERIAL

    if not records:
        raise ParameterError("compare_case: no records given")
    first = records[0][1]
    case = LoadCase(float(np.mean([c.frequency_hz for _, c in records])),
                    float(np.mean([c.acceleration_g for _, c in records])),
                    first.fill_percent, first.material, first.direction)
    measured = pd.DataFrame({
        "file": [Path(r.measurement.source).name for r, _ in records],
        "fill [%]": [c.fill_percent for _, c in records],
        "SDC [-]": [r.analysis.sdc for r, _ in records],
        "SDC stderr [-]": [r.analysis.sdc_stderr for r, _ in records],
    })
    sdc, stderr = pooled_mean(measured["SDC [-]"].to_numpy(float),
                              measured["SDC stderr [-]"].to_numpy(float))
    tol = Tolerances()
    runs = dem_runs if dem_runs is not None and not dem_runs.empty else None
    aligner = Aligner.from_tables(runs, paper, tolerances=tol)
    aligned = aligner.align(case)

    dem_rows = []
    for c in aligner.cases:
        probe = replace(case, fill_percent=c.load_case.fill_percent)
        if tol.matches(probe, c.load_case):
            dem_rows.append({"fill [%]": c.load_case.fill_percent, "SDC [-]": c.sdc,
                             "SDC stderr [-]": c.sdc_stderr, "runs [-]": c.n_runs})
    dem_points = pd.DataFrame(dem_rows, columns=["fill [%]", "SDC [-]", "SDC stderr [-]",
                                                 "runs [-]"])

    paper_cols = ["fill [%]", "SDC DEM (paper) [-]", "SDC measured (paper) [-]"]
    paper_points = pd.DataFrame(columns=paper_cols)
    model_x = model_y = np.empty(0)
    if case.material == PAPER_MATERIAL and case.direction == PAPER_DIRECTION:
        f = paper["frequency_hz"].to_numpy(float)
        a = paper["acceleration_g"].to_numpy(float)
        at_case = ((np.abs(f - case.frequency_hz) <= tol.frequency_rtol * f)
                   & (np.abs(a - case.acceleration_g) <= tol.acceleration_rtol * a))
        rows = paper[at_case].sort_values("fill_percent")
        paper_points = pd.DataFrame({
            "fill [%]": rows["fill_percent"].to_numpy(float),
            "SDC DEM (paper) [-]": rows["sdc_dem"].to_numpy(float),
            "SDC measured (paper) [-]": rows["sdc_experimental"].to_numpy(float)})
        model = _paper_model(paper)
        lo, hi = model.bounds["fill_percent"]
        if model.contains((lo, case.acceleration_g, case.frequency_hz)):
            model_x = np.linspace(lo, hi, model_points)
            model_y = np.asarray(model(model_x, case.acceleration_g, case.frequency_hz),
                                 dtype=float)
    sdc10 = stderr10 = float("nan")
    grid = getattr(aligned, "grid_case", None)
    m_c = float(getattr(grid, "vibrated_mass_kg", float("nan"))) if grid else float("nan")
    if np.isfinite(m_c):
        from .model import sdc_from_energy_per_cycle

        values = np.array([sdc_from_energy_per_cycle(
            r.analysis.energy_per_cycle_j, vibrated_mass_kg=m_c,
            acceleration_m_s2=r.analysis.acceleration_amplitude_m_s2,
            frequency_hz=r.analysis.frequency_hz) for r, _ in records])
        # Same relative error as the Eq. 11 SDC: only the reference energy differs.
        scale = values / measured["SDC [-]"].to_numpy(float)
        sdc10, stderr10 = pooled_mean(values, measured["SDC stderr [-]"].to_numpy(float) * scale)
        measured["SDC, E of Eq. 10 [-]"] = values
    return CaseComparison(case, measured, sdc, stderr, aligned, dem_points, paper_points,
                          model_x, model_y, sdc10, stderr10)


# --- chart data (long tables the app's Vega-Lite charts draw; rendered in the browser) ------

#: Series names of :func:`sdc_chart_data`.
SDC_SERIES = ("pchip model (paper Table 3 DEM)", "paper DEM", "paper measured",
              "our DEM (mean ± stderr)", "our DEM (pchip over our runs)", "measured (± stderr)",
              "measured, E of Eq. 10 (± stderr)")


def sdc_chart_data(comparison: CaseComparison) -> pd.DataFrame:
    """SDC against fill for one load case, one row per point.

    Columns ``series`` (one of :data:`SDC_SERIES`), ``fill [%]``, ``SDC [-]``, ``low [-]`` and
    ``high [-]`` (value ± standard error; equal to the value where there is no error).
    """
    c = comparison
    parts = []

    def add(series: str, fill, sdc, err=None) -> None:
        fill = np.asarray(fill, dtype=float)
        sdc = np.asarray(sdc, dtype=float)
        err = np.zeros_like(sdc) if err is None else np.nan_to_num(np.asarray(err, float))
        keep = np.isfinite(sdc)
        parts.append(pd.DataFrame({"series": series, "fill [%]": fill[keep],
                                   "SDC [-]": sdc[keep], "low [-]": (sdc - err)[keep],
                                   "high [-]": (sdc + err)[keep]}))

    add(SDC_SERIES[0], c.model_fill_percent, c.model_sdc)
    add(SDC_SERIES[1], c.paper_points["fill [%]"], c.paper_points["SDC DEM (paper) [-]"])
    add(SDC_SERIES[2], c.paper_points["fill [%]"], c.paper_points["SDC measured (paper) [-]"])
    add(SDC_SERIES[3], c.dem_points["fill [%]"], c.dem_points["SDC [-]"],
        c.dem_points["SDC stderr [-]"])
    if getattr(c.aligned, "status", "") == "interpolated":
        add(SDC_SERIES[4], [c.load_case.fill_percent], [c.aligned.sdc_dem])
    add(SDC_SERIES[5], [c.load_case.fill_percent], [c.measured_sdc], [c.measured_stderr])
    add(SDC_SERIES[6], [c.load_case.fill_percent], [c.measured_sdc_eq10],
        [c.measured_stderr_eq10])
    return pd.concat(parts, ignore_index=True)


def loop_chart_data(loops: Sequence[LoopCurve]) -> pd.DataFrame:
    """Closed force-displacement loops, one row per point, in drawing order.

    Columns ``series`` (label with the loop's energy per cycle), ``displacement [mm]``,
    ``force [N]``, ``order``; each loop's first point is repeated at its end to close it.
    """
    parts = []
    for loop in loops:
        x = np.append(loop.displacement_m, loop.displacement_m[:1]) * 1e3
        f = np.append(loop.force_n, loop.force_n[:1])
        parts.append(pd.DataFrame({
            "series": f"{loop.label} (ΔE = {loop.energy_per_cycle_j:.3e} J/cycle)",
            "displacement [mm]": x, "force [N]": f, "order": np.arange(x.size)}))
    columns = ["series", "displacement [mm]", "force [N]", "order"]
    return pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=columns)


# --- report -----------------------------------------------------------------------------------

#: Report downloads offered by the app: format -> (file extension, MIME type).
REPORT_DOWNLOADS: dict[str, tuple[str, str]] = {
    "csv": ("csv", "text/csv"),
    "html": ("html", "text/html"),
    "tex": ("tex", "application/x-tex"),
    "pdf": ("pdf", "application/pdf"),
}


def report_table(path: str | os.PathLike,
                 dem_store: str | os.PathLike | None = None) -> pd.DataFrame:
    """The Table 3-style report table of what the stores hold (empty if they hold nothing).

    Measurements: the newest analysis per measurement of the app store that states a fill
    (like ``pidcore report`` without files). DEM: the runs of both stores
    (:func:`list_dem_runs`).
    """
    from .report import build_report_table
    from .report.pipeline import latest_per_measurement
    from .store import Store

    analyses = pd.DataFrame()
    if Path(path).is_file():
        analyses = latest_per_measurement(Store(path).list_analyses())
    dem_runs = list_dem_runs(path, dem_store)
    if analyses.empty and dem_runs.empty:
        return pd.DataFrame()
    return build_report_table(dem_runs if not dem_runs.empty else None,
                              analyses if not analyses.empty else None, paper_table())


def report_files(path: str | os.PathLike,
                 dem_store: str | os.PathLike | None = None) -> dict[str, tuple[str, bytes, str]]:
    """The report of :func:`report_table` as downloads: format -> (file name, bytes, MIME type).

    Written by :func:`pidcore.report.write_report` (with the per-load-case SDC figure and
    provenance naming both stores and their hashes) into a temporary folder and read back, so
    the files hold exactly the table shown on screen. Stores are verified first: a corrupt
    store raises :class:`pidcore.errors.StoreError` and nothing is written.
    """
    from .compare import Tolerances
    from .report import collect_provenance, write_report
    from .report.comparison_figures import plot_sdc_comparison
    from .report.pipeline import open_verified_store

    stores = [Path(p) for p in (path, dem_store) if p is not None and Path(p).is_file()]
    for p in stores:
        open_verified_store(p, must_exist=True)
    table = report_table(path, dem_store)
    if table.empty:
        raise ParameterError("nothing to report: the stores hold no saved analyses with a "
                             "load case and no DEM runs")
    tol = Tolerances()
    runs = list_dem_runs(path, dem_store)
    seeds = sorted({int(s) for s in runs.get("seed", pd.Series(dtype=float)).dropna()})
    provenance = collect_provenance(
        parameters={"frequency_rtol": tol.frequency_rtol,
                    "acceleration_rtol": tol.acceleration_rtol,
                    "fill_atol_percent": tol.fill_atol_percent},
        seeds=seeds, stores=stores, notes=table.attrs.get("notes", []))
    figures = {"sdc_per_load_case": plot_sdc_comparison(table)}
    try:
        with tempfile.TemporaryDirectory(prefix="pidcore_report_") as folder:
            paths = write_report(table, figures, provenance, Path(folder) / "report",
                                 tuple(REPORT_DOWNLOADS))
            return {fmt: (f"pidcore_report.{ext}", paths[fmt].read_bytes(), mime)
                    for fmt, (ext, mime) in REPORT_DOWNLOADS.items()}
    finally:
        for fig in figures.values():
            fig.clear()


# --- DEM from the app ---------------------------------------------------------------------------

def plan_dem_cases(frequencies_hz: Sequence[float], accelerations_g: Sequence[float],
                   fills_percent: Sequence[float], *, material: str, direction: str,
                   max_cases: int = defaults.APP_MAX_DEM_CASES) -> list:
    """Every combination of the chosen values as :class:`pidcore.dem.LoadCase` (Table 3 order).

    Raises :class:`ParameterError` for an empty choice or more than ``max_cases`` cases (a
    page is no place for a long sweep; ``pidcore dem`` runs grids in parallel).
    """
    from .dem import LoadCase as DemLoadCase

    cases = [DemLoadCase(float(f), float(a), float(p), material, direction)
             for f in sorted(frequencies_hz) for a in sorted(accelerations_g)
             for p in sorted(fills_percent)]
    if not cases:
        raise ParameterError("choose at least one frequency, acceleration and fill")
    if len(cases) > max_cases:
        raise ParameterError(f"{len(cases)} load cases chosen; the app runs at most "
                             f"{max_cases} at a time (use `pidcore dem` for larger sweeps)")
    return cases


def dem_run_key(case, config) -> str:
    """Store key of a DEM run (the same as ``pidcore dem`` uses, so runs are shared)."""
    from .dem.sweep import run_key

    return run_key(case, config)


def dem_run_stored(path: str | os.PathLike, case, config) -> bool:
    """Whether the store already holds this exact run (same case and settings)."""
    from .store import Store

    return Path(path).exists() and Store(path).has_dem_run(dem_run_key(case, config))


def run_dem_case(path: str | os.PathLike, case, config) -> str:
    """Simulate one load case and save it to the store at once; returns its store key.

    Each finished case is its own transaction, so cancelling a sweep keeps every case that
    finished before.
    """
    from .dem.sweep import run_case
    from .store import Store

    return run_case(case, config).save_to(Store(path))
