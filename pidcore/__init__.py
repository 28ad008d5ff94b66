"""pidcore: particle impact damping for honeycomb sandwich coupons.

Measure (Eq. 8-11 of Ahmad, Ranganath & Ghosal), predict by DEM (Eq. 1-7) and compare the
specific damping capacity (SDC) of particle-filled honeycomb coupons.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("pidcore")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
