"""pidcore: particle impact damping for honeycomb sandwich coupons.

Measure (Eq. 8-11 of Ahmad, Ranganath & Ghosal), predict by DEM (Eq. 1-7) and compare the
specific damping capacity (SDC) of particle-filled honeycomb coupons.

Where each job starts (each module's docstring lists its API; SI units inside, every table
column names its unit; results have ``to_pandas()`` and ``plot()``):

* Read an export (UFF58/58b, CSV/TXT, MAT, HDF5): :mod:`pidcore.io`
  (:func:`pidcore.io.read_measurement`).
* Analyse it (Eq. 11: complex power, loss factor, SDC, standard error): :mod:`pidcore.measure`
  (:func:`pidcore.measure.analyze_file`, :class:`pidcore.measure.AnalysisOptions`); arrays
  alone: :mod:`pidcore.signal` (:func:`pidcore.signal.analyze_power`).
* Keep analyses and DEM runs: :mod:`pidcore.store` (:class:`pidcore.store.Store`,
  :func:`pidcore.measure.save_analyses`).
* Describe a specimen (cell, coupon, particles, contact pairs; TOML): :mod:`pidcore.specimen`
  (:func:`pidcore.specimen.load_specimen`, :func:`pidcore.specimen.paper_specimen`).
* Simulate a load case by DEM: :mod:`pidcore.dem` (:class:`pidcore.dem.LoadCase`,
  :class:`pidcore.dem.DemConfig`, :func:`pidcore.dem.simulate_load_case`).
* SDC model (pchip over fill, acceleration, frequency) and equivalent damper:
  :mod:`pidcore.model` (:class:`pidcore.model.SdcModel`,
  :func:`pidcore.model.equivalent_damper_table`, :func:`pidcore.model.harmonic_response`).
* Calibrate the DEM against measured SDCs, predict with a 95 % band: :mod:`pidcore.calibrate`
  (:func:`pidcore.calibrate.calibrate`, :func:`pidcore.calibrate.load_calibration`).
* Measurement beside DEM and the paper, Table 3-style report: :mod:`pidcore.compare`,
  :mod:`pidcore.report` (:func:`pidcore.report.build_report_table`,
  :func:`pidcore.report.make_report`).
* Load cases, closed vocabularies, errors: :mod:`pidcore.loadcase`, :mod:`pidcore.constants`,
  :mod:`pidcore.errors`.

The command line (``python -m pidcore --help``) runs the same functions.
"""

__all__ = ["__version__"]


def __getattr__(name: str) -> str:
    # Looked up on first use, not at import: importlib.metadata costs ~0.1 s, and the CLI must
    # install its Ctrl-C handler (pidcore.interrupt) before anything slow runs.
    if name != "__version__":
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from importlib.metadata import PackageNotFoundError, version

    try:
        found = version("pidcore")
    except PackageNotFoundError:  # running from a source tree without installation
        found = "0.0.0+unknown"
    globals()["__version__"] = found
    return found
