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
from contextlib import contextmanager, suppress
from pathlib import Path

from ..errors import StoreError

#: Seconds between attempts while waiting for a lock held by another writer.
_POLL_INTERVAL_S = 0.01


def lock_path_for(store_path: Path) -> Path:
    """Sidecar lock file of ``store_path``: the same name with ``.lock`` appended."""
    return store_path.with_name(store_path.name + ".lock")


def _open_lock_file(store_path: Path, lock_path: Path) -> int:
    try:
        return os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o666)
    except OSError as exc:
        raise StoreError(f"{store_path}: cannot create the lock file {lock_path} "
                         f"({exc.strerror or exc})") from None


def _is_current(fd: int, lock_path: Path) -> bool:
    """True if ``fd`` is the file now at ``lock_path`` (not one its holder removed)."""
    try:
        st = os.stat(lock_path)
    except FileNotFoundError:
        return False
    mine = os.fstat(fd)
    return (st.st_dev, st.st_ino) == (mine.st_dev, mine.st_ino)


@contextmanager
def exclusive_lock(store_path: Path, *, timeout_s: float) -> Iterator[None]:
    """Hold the exclusive write lock of ``store_path`` for the duration of the block.

    The lock file is removed on release so that none is left beside the store. That is safe
    because removal happens while the lock is held and every writer, once it has the lock,
    checks that its file is still the one at the path: a writer that opened the file before
    the previous holder removed it holds a lock on an orphan that newcomers cannot see, so it
    starts again on the path's current file (the classic flock-and-unlink race).

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
    deadline = time.monotonic() + timeout_s
    # One try/finally from the open to the release: an interrupt (Ctrl-C, SIGTERM, a
    # notebook's KeyboardInterrupt) between the flock and the block's own try left the
    # descriptor open and locked, so every later write of this process to the store waited
    # out its timeout ("another pidcore process is writing"), and the lock file stayed.
    fd: int | None = None
    held = False
    try:
        while True:
            fd = _open_lock_file(store_path, lock_path)
            while True:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    held = True
                    break
                except BlockingIOError:
                    if time.monotonic() >= deadline:
                        raise StoreError(
                            f"{store_path}: could not take the write lock {lock_path} within "
                            f"{timeout_s:g} s; another pidcore process is writing to this "
                            "store") from None
                    time.sleep(_POLL_INTERVAL_S)
            if _is_current(fd, lock_path):
                break
            held = False
            os.close(fd)  # the lock of a removed file: try again on the current one
            fd = None
        yield
    finally:
        if fd is not None:
            # closed here, not in the function: an interrupt is delivered on entry to a
            # function too, and closing the descriptor is what releases the lock
            try:
                _remove_lock_file(fd, lock_path, held=held)
            finally:
                os.close(fd)


def _remove_lock_file(fd: int, lock_path: Path, *, held: bool) -> None:
    """Remove the lock file and unlock ``fd`` (its caller closes it). The file is removed
    while the lock is held, so nobody can take the path's lock meanwhile (see
    :func:`exclusive_lock`); one this process opened but had not locked yet (interrupted
    while it waited, or created by it and free) is removed only where its lock can be taken
    at once and it is still the path's file, else another writer holds it and removes it."""
    if not held:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return  # another writer's: it removes the file
        if not _is_current(fd, lock_path):
            return
    with suppress(OSError):
        os.unlink(lock_path)
    fcntl.flock(fd, fcntl.LOCK_UN)
