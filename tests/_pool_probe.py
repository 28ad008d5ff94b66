"""Functions run in DEM pool workers by tests/test_dem_pool_interrupt.py and the app's
calibration tests (a worker imports them by module name, so they cannot live in the test
module's fixtures), and :func:`alive`, how those tests tell a stopped worker."""

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


def alive(pid: int) -> bool:
    """Whether ``pid`` still runs. A terminated worker is the fork server's child and stays a
    zombie until that server reaps it (later on a loaded machine): it runs no code, so it
    counts as stopped."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # Linux: the state is the field after the parenthesised command name
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return True
    return state not in ("Z", "X")


#: The load case whose calibration DEM runs :func:`slow_calibration_run` ends at once.
QUICK_FREQUENCY_HZ = 500.0


def slow_calibration_run(folder: str, request) -> tuple[str, dict]:
    """A calibration's DEM run (:func:`pidcore.calibrate.runner._run_entry`'s place) that
    takes no DEM: at :data:`QUICK_FREQUENCY_HZ` it ends at once with a made-up run (leaving
    a file ``quick-PID`` in ``folder``); any other says "started" (a file ``slow-PID``) and
    waits 60 s, a run going on far longer than any stop may take."""
    case = request.case
    if case.frequency_hz == QUICK_FREQUENCY_HZ:
        Path(folder, f"quick-{os.getpid()}").touch()
    else:
        Path(folder, f"slow-{os.getpid()}").touch()
        time.sleep(60.0)
    record = {"frequency_hz": case.frequency_hz, "acceleration_g": case.acceleration_g,
              "fill_percent": case.fill_percent, "material": case.material,
              "direction": case.direction, "sdc": 0.3, "sdc_stderr": 0.01}
    return request.key(), {"record": record, "arrays": {}, "parameters": {}, "units": {}}


def wait_ignoring_sigterm(folder: str, seconds: float) -> int:
    """:func:`wait_in_worker` in a worker that ignores SIGTERM, as every worker does whose
    fork server was started while its parent ignored it."""
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    return wait_in_worker(folder, seconds)
