"""pidcore.store: the HDF5 store of measurements, analyses, DEM runs and calibrations.

See :mod:`pidcore.store.store` for the file layout and the transaction protocol.

Public API
----------
Store
    The store: ``add_measurement``/``add_analysis``/``add_dem_run``/``add_calibration``,
    their ``get_`` and ``list_`` (pandas frames), ``transaction()``, ``verify()``,
    ``summary()``.
StoredEntry
    One analysis, DEM run or calibration read back: its record, arrays, parameters, units.
calibration_texts
    The calibration.json and calibrated specimen texts of a stored calibration.
measurement_key
    The key a measurement is stored under (its content).
STORE_VERSION
    The layout version this pidcore writes.

Examples
--------
>>> from pidcore.store import Store                     # doctest: +SKIP
>>> Store("pid_store.h5").list_analyses()[["source", "sdc"]]  # doctest: +SKIP
"""

from ..records import measurement_key
from .store import STORE_VERSION, Store, StoredEntry, calibration_texts

__all__ = ["STORE_VERSION", "Store", "StoredEntry", "calibration_texts", "measurement_key"]
