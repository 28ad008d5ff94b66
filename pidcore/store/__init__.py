"""pidcore.store: the HDF5 store of measurements, analyses, DEM runs and calibrations.

See :mod:`pidcore.store.store` for the file layout and the transaction protocol.
"""

from ..records import measurement_key
from .store import STORE_VERSION, Store, StoredEntry, calibration_texts

__all__ = ["STORE_VERSION", "Store", "StoredEntry", "calibration_texts", "measurement_key"]
