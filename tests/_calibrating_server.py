"""Stand-in for the Streamlit server process of ``pidcore app`` with the Calibrate page's
calibration running (tests/test_app_signals.py runs it as the app's server command).

What matters of Streamlit is kept: its SIGTERM (and SIGINT) handler stops the server, whose
main thread then returns (``streamlit.web.bootstrap``), and the page's calibration runs in a
daemon thread of the same process (:class:`pidcore.app.calibration.CalibrationRunner`), on
the store the app was given (``PIDCORE_STORE``). Its DEM runs are
:func:`_pool_probe.slow_calibration_run`: the quick ones are saved at once, the others take
60 s.

``python _calibrating_server.py FOLDER``: the workers' pid files go to FOLDER; ``ready`` there
once the quick runs are saved and both workers run a slow one, ``server-PID``,
``forkserver-PID`` and ``tracker-PID`` name this process and its helpers, and ``exited`` is
written by the interpreter's last exit hook (absent when the process was killed): the
:func:`time.monotonic` at which it ran, after the calibration's stop and the pools' joins
(CLOCK_MONOTONIC on Linux: one clock for every process, so the test compares it with the
moment it sent the signal).
"""

from __future__ import annotations

import atexit
import functools
import os
import signal
import sys
import threading
import time
from pathlib import Path

if __name__ == "__main__":
    from _pool_probe import QUICK_FREQUENCY_HZ, slow_calibration_run

    import pidcore.calibrate as api
    from pidcore.app.calibration import runner_for
    from pidcore.calibrate import MeasuredPoint
    from pidcore.calibrate import runner as calibration_runs

    folder = Path(sys.argv[1])
    # runs after threading's hooks: the calibration's stop and concurrent.futures' joins
    atexit.register(lambda: (folder / "exited").write_text(repr(time.monotonic())))
    stopped = threading.Event()
    for signum in (signal.SIGTERM, signal.SIGINT):  # as Streamlit handles them
        signal.signal(signum, lambda signum, frame: stopped.set())
    calibration_runs._run_entry = functools.partial(slow_calibration_run, str(folder))
    points = [MeasuredPoint(QUICK_FREQUENCY_HZ, 5, 50, 0.6), MeasuredPoint(1000, 5, 50, 0.6),
              MeasuredPoint(1000, 1, 50, 0.2)]
    task = runner_for(os.environ["PIDCORE_STORE"]).start(
        api, points, fit=["restitution"], cells=2, design_size=3)
    ready = False
    while not stopped.wait(0.02):  # the server's event loop
        if not ready and task.runs_done == 3 and len(list(folder.glob("slow-*"))) == 2:
            from multiprocessing import forkserver, resource_tracker

            for name, pid in (("server", os.getpid()),
                              ("forkserver", forkserver._forkserver._forkserver_pid),
                              ("tracker", resource_tracker._resource_tracker._pid)):
                (folder / f"{name}-{pid}").touch()
            (folder / "ready").touch()
            ready = True
    # the server stopped: the main thread returns, and the interpreter exits
