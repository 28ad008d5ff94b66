"""Inter-process write lock of a store: ``fcntl.flock`` on a sidecar ``<store>.lock`` file.

``flock`` (not ``lockf``) because its locks belong to an open file description: two
:class:`~pidcore.store.Store` objects in one process exclude each other like two processes do,
and the kernel drops the lock when its holder dies, so a crashed writer never leaves a stale lock.
"""

from __future__ import annotations

import fcntl
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from ..errors import StoreError

#: Seconds between attempts while waiting for a lock held by another writer.
_POLL_INTERVAL_S = 0.01


def lock_path_for(store_path: Path) -> Path:
    """Sidecar lock file of ``store_path``: the same name with ``.lock`` appended."""
    return store_path.with_name(store_path.name + ".lock")


@contextmanager
def exclusive_lock(store_path: Path, *, timeout_s: float) -> Iterator[None]:
    """Hold the exclusive write lock of ``store_path`` for the duration of the block.

    Parameters
    ----------
    store_path : pathlib.Path
        Store file the lock protects (the lock itself lives in ``<store>.lock``).
    timeout_s : float
        Seconds to wait for another writer to finish, s.

    Raises
    ------
    StoreError
        The lock could not be taken within ``timeout_s`` or the lock file cannot be created.
    """
    lock_path = lock_path_for(store_path)
    try:
        fd = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o666)
    except OSError as exc:
        raise StoreError(f"{store_path}: cannot create the lock file {lock_path} "
                         f"({exc.strerror or exc})") from None
    try:
        deadline = time.monotonic() + timeout_s
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() >= deadline:
                    raise StoreError(
                        f"{store_path}: could not take the write lock {lock_path} within "
                        f"{timeout_s:g} s; another pidcore process is writing to this store"
                    ) from None
                time.sleep(_POLL_INTERVAL_S)
        try:
            yield
        finally:
            fcntl.flock(fd, fcntl.LOCK_UN)
    finally:
        os.close(fd)
