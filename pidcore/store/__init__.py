"""pidcore.store: the HDF5 store of measurements, analyses, DEM runs and calibrations.

See :mod:`pidcore.store.store` for the file layout and the transaction protocol.

Public API
----------
Store
    The store: ``add_measurement``/``add_analysis``/``add_dem_run``/``add_calibration``,
    their ``get_`` and ``list_`` (pandas frames), ``remove_entries``, ``transaction()``,
    ``verify()``, ``summary()``.
StoredEntry
    One analysis, DEM run or calibration read back: its record, arrays, parameters, units.
calibration_texts
    The calibration.json and calibrated specimen texts of a stored calibration.
measurement_key
    The key a measurement is stored under (its content).
STORE_VERSION
    The layout version this pidcore writes.
existing_store
    A store that must exist (``store not found`` otherwise).
store_contents
    What a store holds: one table per section, keys and units (``pidcore store list``).
remove_records, Removal
    Records removed in one commit with what depends on them (``pidcore store remove``).

Examples
--------
>>> from pidcore.store import Store                     # doctest: +SKIP
>>> Store("pid_store.h5").list_analyses()[["source", "sdc"]]  # doctest: +SKIP
"""

from ..records import measurement_key
from .manage import Removal, existing_store, remove_records, store_contents
from .store import STORE_VERSION, Store, StoredEntry, calibration_texts

__all__ = ["STORE_VERSION", "Removal", "Store", "StoredEntry", "calibration_texts",
           "existing_store", "measurement_key", "remove_records", "store_contents"]
