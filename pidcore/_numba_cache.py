"""Numba's on-disk cache of compiled functions, made optional when it cannot be written.

Functions compiled with ``cache=True`` save their machine code beside the module (or in
``NUMBA_CACHE_DIR``) at their first call. On Linux Numba lets any ``OSError`` of that save
through (it forgives only Windows' EACCES), so a full disk, a disk quota or a file size limit
(``ulimit -f``) on a cold cache ended ``pidcore analyze`` (even with ``--no-store``), ``dem run``
and the app in a Numba traceback after the work was done. The cache only saves the next run a
compilation: a save that fails is skipped (Numba writes each cache file to a temporary name and
renames it, so a failed save leaves no partial file to be loaded later).
"""

from __future__ import annotations

_PATCHED = "_pidcore_tolerates_unwritable_cache"


def tolerate_unwritable_cache() -> None:
    """Let a failed save of Numba's cache cost a recompilation, not the run (idempotent;
    call before the first call of a ``cache=True`` function)."""
    from numba.core import caching

    save = caching.Cache.save_overload
    if getattr(save, _PATCHED, False):
        return

    def save_overload(self, sig, data):
        try:
            save(self, sig, data)
        except OSError:
            pass  # not written: the next run compiles again

    setattr(save_overload, _PATCHED, True)
    caching.Cache.save_overload = save_overload
