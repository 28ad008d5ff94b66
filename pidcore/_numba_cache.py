"""Numba's on-disk cache of compiled functions, made optional where it cannot be written.

Importing this module sets it up; :mod:`pidcore.signal` and :mod:`pidcore.dem` import it before
any of their modules decorates a ``cache=True`` function, because Numba chooses where a
function's cache lives when it is decorated.

* Where the cache lives. Numba keeps it in ``NUMBA_CACHE_DIR``, else beside the module
  (``__pycache__``), else in the user's cache folder (``~/.cache/numba``), each only if it can
  be written, and raises ``RuntimeError: cannot cache function ...: no locator available`` at
  decoration when none can: a user who can write neither site-packages nor HOME (a service
  account, ``HOME=/nonexistent``) could not even run ``pidcore --version``. After Numba's own
  places, the cache goes to a folder of this user's under the system's temporary folder
  (``pidcore-numba-cache-UID``, made 0700); one there that is not a folder of this user's
  that no one else can write (planted by another user) is not used. Where no place is left,
  the function is compiled at each run, uncached.
* Saving it. Numba saves the machine code at a function's first call and, on Linux, lets any
  ``OSError`` of that save through (it forgives only Windows' EACCES), so a full disk, a disk
  quota or a file size limit (``ulimit -f``) on a cold cache ended ``pidcore analyze`` (even
  with ``--no-store``), ``dem run`` and the app in a Numba traceback after the work was done. A
  save that fails is skipped (Numba writes each cache file to a temporary name and renames it,
  so a failed save leaves no partial file to be loaded later).
"""

from __future__ import annotations

import os
import stat
import tempfile

from numba.core import caching, dispatcher

_PATCHED = "_pidcore_tolerates_unwritable_cache"
_NO_LOCATOR = "cannot cache function"  # the start of Numba's RuntimeError when no place is left


def private_temp_cache_root() -> str | None:
    """This user's cache folder under the system's temporary folder, made if missing; None
    where it cannot be made or is not a folder that only this user can write."""
    if not hasattr(os, "geteuid"):
        return None
    root = os.path.join(tempfile.gettempdir(), f"pidcore-numba-cache-{os.geteuid()}")
    try:
        os.mkdir(root, 0o700)
    except FileExistsError:
        pass
    except OSError:
        return None
    try:
        st = os.lstat(root)  # lstat: a link planted under that name is refused, not followed
    except OSError:
        return None
    # Another user able to write there could plant machine code that this user would load.
    if (not stat.S_ISDIR(st.st_mode) or st.st_uid != os.geteuid()
            or st.st_mode & (stat.S_IWGRP | stat.S_IWOTH)):
        return None
    return root


class PrivateTempCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
    """Numba's last place for a cache: :func:`private_temp_cache_root`."""

    def __init__(self, py_func, py_file, root: str):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = os.path.join(root, self.get_suitable_cache_subpath(py_file))

    def get_cache_path(self):
        return self._cache_path

    @classmethod
    def from_function(cls, py_func, py_file):
        root = private_temp_cache_root()
        if root is None or not os.path.exists(py_file):
            return None
        self = cls(py_func, py_file, root)
        try:
            self.ensure_cache_path()  # as Numba's locators: the folder made and written to
        except OSError:
            return None
        return self


def _tolerate_unsaved_cache() -> None:
    save = caching.Cache.save_overload

    def save_overload(self, sig, data):
        try:
            save(self, sig, data)
        except OSError:
            pass  # not written: the next run compiles again

    caching.Cache.save_overload = save_overload


def _compile_uncached_where_no_place_is_left() -> None:
    enable = dispatcher.Dispatcher.enable_caching

    def enable_caching(self):
        try:
            enable(self)
        except RuntimeError as error:
            if not str(error).startswith(_NO_LOCATOR):
                raise
            # the dispatcher keeps its NullCache: compiled at each run

    dispatcher.Dispatcher.enable_caching = enable_caching


def tolerate_unwritable_cache() -> None:
    """Let a cache that cannot be written cost a recompilation, not the run (idempotent;
    call before the first ``cache=True`` decoration)."""
    if getattr(caching.Cache.save_overload, _PATCHED, False):
        return
    # appended: Numba's own places (NUMBA_CACHE_DIR, beside the module, ~/.cache) come first;
    # the list is the one the base class (CacheImpl or _CacheImpl, by Numba version) holds
    caching.CompileResultCacheImpl._locator_classes.append(PrivateTempCacheLocator)
    _tolerate_unsaved_cache()
    _compile_uncached_where_no_place_is_left()
    setattr(caching.Cache.save_overload, _PATCHED, True)


tolerate_unwritable_cache()
