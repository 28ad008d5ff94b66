"""pidcore: particle impact damping for honeycomb sandwich coupons.

Measure (Eq. 8-11 of Ahmad, Ranganath & Ghosal), predict by DEM (Eq. 1-7) and compare the
specific damping capacity (SDC) of particle-filled honeycomb coupons.
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
