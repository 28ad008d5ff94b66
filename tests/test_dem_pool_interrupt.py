"""Ctrl-C during a pooled DEM run (``dem sweep``, ``calibrate``): the workers are stopped and
waited for, and nothing but the CLI's one line reaches the terminal."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest
from _pool_probe import alive as _alive

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent


def _pooled_waits(tmp_path: Path) -> subprocess.Popen:
    """A fresh interpreter running 4 cases of 60 s on 2 pool workers (a test process's own
    signal state, e.g. a pytest-xdist worker's, is not the CLI's), exit 130 on Ctrl-C."""
    code = textwrap.dedent(f"""
        import sys
        from pidcore import interrupt
        from pidcore.dem.sweep import run_pooled
        from _pool_probe import wait_in_worker
        if __name__ == "__main__":
            interrupt.install()
            try:
                run_pooled(wait_in_worker, [({str(tmp_path)!r}, 60.0)] * 4, workers=2,
                           finish=print)
            except KeyboardInterrupt:
                print("interrupted", file=sys.stderr)
                sys.exit(130)
    """)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), str(TESTS)])}
    p = subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.monotonic() + 90
    while len(list(tmp_path.iterdir())) < 2 and time.monotonic() < deadline:
        time.sleep(0.02)
    return p


@pytest.mark.slow
def test_an_interrupted_pool_has_stopped_its_workers_when_the_interrupt_goes_on(tmp_path):
    # Left running (shutdown(wait=False)), a worker outlived the CLI: one still starting found
    # the pool's semaphores removed and printed multiprocessing's FileNotFoundError traceback
    # after the one line. 60 s of waiting per case: only a terminated worker is gone at once.
    p = _pooled_waits(tmp_path)
    os.kill(p.pid, signal.SIGINT)  # the caller alone (a kill, not a terminal's Ctrl-C)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 130 and err == "interrupted\n", err
    assert out == ""  # no case finished: the interrupt came mid-case
    pids = [int(f.name) for f in tmp_path.iterdir()]
    assert len(pids) == 2 and not any(_alive(pid) for pid in pids)


@pytest.mark.slow
def test_dem_workers_never_see_ctrl_c_the_parent_stops_them():
    # A terminal's Ctrl-C reaches every process of the group; a worker that handled it printed
    # a KeyboardInterrupt traceback when it came during the worker's start-up. SIGINT is
    # blocked from the fork server's start (no window) and ignored once the worker is set up.
    # In a fresh interpreter: the fork server of this one may have been started by other code.
    code = textwrap.dedent("""
        from _pool_probe import sigint_state
        from pidcore.dem.sweep import run_pooled
        if __name__ == "__main__":
            states = []
            run_pooled(sigint_state, [(0,), (1,)], workers=2, finish=states.append)
            print(sorted(set(states)))
    """)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), str(TESTS)])}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[(True, True)]"  # ignored and blocked in every worker


@pytest.mark.slow
def test_ctrl_c_to_the_whole_group_prints_only_the_callers_line(tmp_path):
    # As a terminal sends it: to the caller and its workers at once, the workers mid-case.
    # Before: a worker's own KeyboardInterrupt; a terminated worker's Numba lock left for the
    # resource tracker to report ("leaked semaphore objects") after the caller's line.
    p = _pooled_waits(tmp_path)
    os.killpg(p.pid, signal.SIGINT)
    out, err = p.communicate(timeout=60)  # waits for the resource tracker's stderr too
    assert p.returncode == 130 and err == "interrupted\n", err
    pids = [int(f.name) for f in tmp_path.iterdir()]
    assert len(pids) == 2 and not any(_alive(pid) for pid in pids)


@pytest.mark.slow
def test_a_stopped_pool_kills_workers_that_ignore_sigterm_instead_of_waiting_their_case_out(
        tmp_path):
    # A fork server started while its parent ignored SIGTERM (console_main ignores it once
    # its command is over; a test process calls it) hands that on to every worker: the stop
    # terminated them, and the pool's shutdown then waited for their running case, here 60 s,
    # a DEM case minutes. Now a worker still alive after the grace is killed.
    from _pool_probe import wait_ignoring_sigterm

    from pidcore.dem.sweep import run_pooled
    from pidcore.interrupt import TERMINATE_GRACE_S, StopRequested

    stop, raised = threading.Event(), []

    def pooled() -> None:
        try:
            run_pooled(wait_ignoring_sigterm, [(str(tmp_path), 60.0)] * 2, workers=2,
                       finish=lambda result: None, stop=stop)
        except StopRequested as exc:
            raised.append(exc)

    thread = threading.Thread(target=pooled, daemon=True)
    thread.start()
    deadline = time.monotonic() + 90  # cold fork server and worker starts on a loaded machine
    while len(list(tmp_path.iterdir())) < 2 and time.monotonic() < deadline:
        time.sleep(0.02)
    pids = [int(f.name) for f in tmp_path.iterdir()]
    assert len(pids) == 2
    sent = time.monotonic()
    stop.set()
    thread.join(45)
    # the stop is seen within STOP_POLL_S, the kill follows the grace: ~1.1 s idle; 30 s is
    # room for a loaded machine and half the 60 s the old code waited
    assert not thread.is_alive() and time.monotonic() - sent < 30 + TERMINATE_GRACE_S
    assert len(raised) == 1
    assert not any(_alive(pid) for pid in pids)
