"""Which stores an app session uses: the app store (read and written) and an optional read-only
store of reference DEM runs."""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from .. import defaults

#: Environment variable naming the store the app reads and writes.
STORE_ENV_VAR = "PIDCORE_STORE"
#: Environment variable naming a read-only store of reference DEM runs (optional).
DEM_STORE_ENV_VAR = "PIDCORE_DEM_STORE"
#: The DEM store of the bundled samples (``pidcore samples make``), relative to the working
#: folder; used as reference DEM runs when present and no other is named.
BUNDLED_DEM_STORE = Path("data_samples") / "dem_table3.h5"


def store_path(environ: Mapping[str, str] | None = None) -> Path:
    """Store used by the app: ``$PIDCORE_STORE`` or :data:`pidcore.defaults.STORE_PATH`."""
    env = os.environ if environ is None else environ
    value = env.get(STORE_ENV_VAR, "").strip()
    return Path(value) if value else Path(defaults.STORE_PATH)


def dem_store_path(environ: Mapping[str, str] | None = None, *,
                   cwd: Path | None = None) -> Path | None:
    """Read-only store of reference DEM runs: ``$PIDCORE_DEM_STORE``, else the bundled
    :data:`BUNDLED_DEM_STORE` if it exists in the working folder, else None."""
    return path_from_env_or_bundled(DEM_STORE_ENV_VAR, BUNDLED_DEM_STORE,
                                    environ=environ, cwd=cwd)


def path_from_env_or_bundled(variable: str, bundled: Path, *,
                             environ: Mapping[str, str] | None = None,
                             cwd: Path | None = None) -> Path | None:
    """The file an environment variable names, else ``bundled`` (relative to the working
    folder) if it exists there, else None."""
    env = os.environ if environ is None else environ
    value = env.get(variable, "").strip()
    if value:
        return Path(value)
    found = (cwd or Path.cwd()) / bundled
    return found if found.is_file() else None


@dataclass(frozen=True)
class AppStores:
    """The stores of one app session.

    Attributes
    ----------
    path : Path
        The app store (read and written).
    dem_reference : Path or None
        Read-only store of reference DEM runs, joined to the app store's own.
    """

    path: Path
    dem_reference: Path | None = None

    @classmethod
    def from_environment(cls, environ: Mapping[str, str] | None = None, *,
                         cwd: Path | None = None) -> AppStores:
        """Stores named by the environment (see :func:`store_path`, :func:`dem_store_path`)."""
        return cls(store_path(environ), dem_store_path(environ, cwd=cwd))

    def stamp(self) -> tuple:
        """(path, mtime, size, inode) of each store: changes whenever a store is rewritten
        (the store replaces its file atomically on every commit, a new inode even within the
        file system's mtime resolution), so it keys cached listings."""
        out = []
        for p in (self.path, self.dem_reference):
            try:
                stat = Path(p).stat() if p is not None else None
            except OSError:
                stat = None
            out.append((str(p), stat.st_mtime_ns, stat.st_size, stat.st_ino) if stat
                       else (str(p), 0, 0, 0))
        return tuple(out)
