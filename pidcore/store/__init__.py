"""pidcore.store: the HDF5 store of measurements, analyses and DEM runs.

See :mod:`pidcore.store.store` for the file layout and the transaction protocol.
"""

from ..records import measurement_key
from .store import STORE_VERSION, Store, StoredEntry

__all__ = ["STORE_VERSION", "Store", "StoredEntry", "measurement_key"]
