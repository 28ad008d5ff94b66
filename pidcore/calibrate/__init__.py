"""Calibration of the DEM against measured SDCs, with uncertainty and cross-validation.

Modules, one concern each:

* :mod:`~pidcore.calibrate.data`: measured points (table or store);
* :mod:`~pidcore.calibrate.parameters`: what can be fitted, bounds and priors;
* :mod:`~pidcore.calibrate.runner`: DEM runs for named parameter values, cached in the store;
* :mod:`~pidcore.calibrate.observation`: the SDC a shaker test of the DEM would measure (Eq. 11
  with fixture mass and baseline loss factor);
* :mod:`~pidcore.calibrate.surrogate`: space-filling design and per-load-case surrogate;
* :mod:`~pidcore.calibrate.likelihood`: the density of a measured SDC about the model's (a
  measurement error of Student's t where its degrees of freedom are known, normal model terms);
* :mod:`~pidcore.calibrate.posterior`: likelihood (measurement error, DEM scatter, model
  discrepancy), exact grid or emcee;
* :mod:`~pidcore.calibrate.calibrate`: the pipeline and leave-one-out;
* :mod:`~pidcore.calibrate.outputs`: calibration.json, specimen file, figures, summary;
* :mod:`~pidcore.calibrate.prediction`: reading a calibration.json back and looking up the
  calibrated prediction of a load case (reports, app);
* :mod:`~pidcore.calibrate.persist`: calibrations saved in and read from the HDF5 store.

Public API
----------
calibrate, CalibrationResult, base_specimen
    Fit specimen parameters to measured SDCs (posterior, 95 % bands, leave-one-out);
    the result's ``calibration()``, ``to_pandas()`` and ``plot()``.
read_measured_table, measured_from_store, MeasuredPoint
    The measured SDCs to fit: a table, or the analyses of a store.
CATALOGUE, ParameterSpec, build_specs, parse_fit, dem_parameter_names
    What can be fitted, its bounds and priors.
Observation, observation_from_run
    The SDC a shaker test of a DEM run would measure.
write_outputs, finish_interrupted_outputs
    calibration.json, the calibrated specimen, figures and summary; the moves of a write
    killed while it moved them into its folder, completed.
save_calibration, SavedCalibration, stored_calibration, stored_calibrations
    Calibrations saved in and read from the HDF5 store (and what a save did).
load_calibration, calibration_from_json, Calibration, CalibratedPrediction
    A calibration read back (``to_pandas()``, ``plot()``); its prediction and 95 % band at
    a calibrated load case (``Calibration.lookup(case).band(stderr)``).
CALIBRATION_COLUMNS_RENAMED
    The older names of ``Calibration.to_pandas()``'s columns -> the present ones.
"""

from .calibrate import CalibrationResult, base_specimen, calibrate
from .data import MeasuredPoint, measured_from_store, read_measured_table
from .observation import Observation, observation_from_run
from .outputs import finish_interrupted_outputs, write_outputs
from .parameters import CATALOGUE, ParameterSpec, build_specs, dem_parameter_names, parse_fit
from .persist import (
    SavedCalibration,
    save_calibration,
    stored_calibration,
    stored_calibrations,
)
from .prediction import (
    CALIBRATION_COLUMNS_RENAMED,
    CalibratedPrediction,
    Calibration,
    calibration_from_json,
    load_calibration,
)

__all__ = ["calibrate", "base_specimen", "CalibrationResult", "MeasuredPoint",
           "read_measured_table", "measured_from_store", "Observation", "observation_from_run",
           "write_outputs", "finish_interrupted_outputs",
           "CATALOGUE", "ParameterSpec", "build_specs", "parse_fit", "dem_parameter_names",
           "Calibration", "CalibratedPrediction", "load_calibration", "calibration_from_json",
           "CALIBRATION_COLUMNS_RENAMED",
           "save_calibration", "SavedCalibration", "stored_calibration", "stored_calibrations"]
