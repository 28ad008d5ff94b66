"""Functions run in DEM pool workers by tests/test_dem_pool_interrupt.py (a worker imports
them by module name, so they cannot live in the test module's fixtures)."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path


def wait_in_worker(folder: str, seconds: float) -> int:
    """Say "started" (a file named by the worker's pid), then wait: a case still running."""
    Path(folder, str(os.getpid())).touch()
    time.sleep(seconds)
    return os.getpid()


def sigint_state(_: int) -> tuple[bool, bool]:
    """(SIGINT ignored, SIGINT blocked) in the worker."""
    ignored = signal.getsignal(signal.SIGINT) == signal.SIG_IGN
    blocked = signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, [])
    return ignored, blocked
