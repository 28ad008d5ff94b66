"""The store's write lock: no lock file left behind, and still mutual exclusion."""

from __future__ import annotations

import subprocess
import sys
import threading
import time

import pytest

from pidcore.errors import StoreError
from pidcore.store import Store
from pidcore.store.lock import exclusive_lock, lock_path_for


def test_no_lock_file_is_left_after_a_write(tmp_path):
    store = Store(tmp_path / "pid_store.h5")
    store.add_dem_run("a", {"sdc": 0.1})
    assert store.path.exists()
    assert not lock_path_for(store.path).exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pid_store.h5"]


def test_removing_the_lock_file_keeps_writers_exclusive(tmp_path):
    # The flock-and-unlink race: a waiter that opened the lock file before its holder removed
    # it gets a lock on the orphan while a newcomer locks a new file at the path. Threads use
    # separate open file descriptions, so flock excludes them like processes. Each section
    # sleeps 1 ms so that waiters pile up on the file being removed; 6 threads x 40 sections
    # gave overlaps in every run of the unchecked scheme here.
    path = tmp_path / "pid_store.h5"
    inside, overlaps, done = [0], [0], []
    guard = threading.Lock()

    def writer() -> None:
        for _ in range(40):
            with exclusive_lock(path, timeout_s=60):
                with guard:
                    inside[0] += 1
                    overlaps[0] += inside[0] > 1
                time.sleep(0.001)
                with guard:
                    inside[0] -= 1
        done.append(1)

    threads = [threading.Thread(target=writer) for _ in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert len(done) == 6 and overlaps[0] == 0
    assert not lock_path_for(path).exists()



class _InterruptAfter:
    """``fcntl`` for the lock module whose ``flock`` does its work and then raises
    KeyboardInterrupt on its ``call``-th call: a Ctrl-C handled as the call returns (Python
    runs signal handlers there), the lock taken but its holder not yet in its block."""

    def __init__(self, call: int) -> None:
        import fcntl

        self._fcntl, self.call, self.calls = fcntl, call, 0
        self.LOCK_EX, self.LOCK_NB, self.LOCK_UN = fcntl.LOCK_EX, fcntl.LOCK_NB, fcntl.LOCK_UN

    def flock(self, fd: int, operation: int) -> None:
        self._fcntl.flock(fd, operation)
        self.calls += 1
        if self.calls == self.call:
            raise KeyboardInterrupt


def test_an_interrupt_as_the_lock_is_taken_releases_it(tmp_path, monkeypatch):
    # Found by interrupting a store write at every line of the store's code: a Ctrl-C (or a
    # notebook's KeyboardInterrupt) after the flock and before the block's own try left the
    # descriptor open and locked, so every later write of the process waited out its timeout
    # and failed ("another pidcore process is writing"), and the lock file stayed beside the
    # store.
    from pidcore.store import lock

    path = tmp_path / "pid_store.h5"
    monkeypatch.setattr(lock, "fcntl", _InterruptAfter(call=1))
    with pytest.raises(KeyboardInterrupt), exclusive_lock(path, timeout_s=5):
        pytest.fail("the block ran after the interrupt")
    monkeypatch.undo()
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    with exclusive_lock(path, timeout_s=0):  # free at once, in this very process
        pass
    store = Store(path, lock_timeout_s=0)
    store.add_dem_run("a", {"sdc": 0.1})
    assert store.has_dem_run("a")


def test_an_interrupt_while_waiting_leaves_the_holders_lock_alone(tmp_path, monkeypatch):
    # A waiter interrupted in its wait removes nothing: the lock file is the holder's, and
    # removing it would let a third writer in beside the holder.
    from pidcore.store import lock

    path = tmp_path / "pid_store.h5"
    with exclusive_lock(path, timeout_s=0):
        def interrupted_sleep(seconds: float) -> None:
            raise KeyboardInterrupt

        monkeypatch.setattr(lock.time, "sleep", interrupted_sleep)
        with pytest.raises(KeyboardInterrupt), exclusive_lock(path, timeout_s=5):
            pytest.fail("two holders")
        monkeypatch.undo()
        assert lock_path_for(path).exists()
        with pytest.raises(StoreError, match="could not take the write lock"), \
                exclusive_lock(path, timeout_s=0):
            pytest.fail("two holders")
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_an_interrupt_as_the_lock_is_released_still_frees_it(tmp_path, monkeypatch):
    # Found by interrupting a store write at every line of the store's code: Python delivers
    # a pending Ctrl-C on entry to a function, and one landing as the release began left the
    # descriptor open and locked (every later write of the process timed out). Closing the
    # descriptor is what frees the lock; a lock file left then is harmless (the next writer
    # takes and removes it).
    from pidcore.store import lock

    path = tmp_path / "pid_store.h5"

    def interrupted_on_entry(*args, **kwargs) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(lock, "_remove_lock_file", interrupted_on_entry)
    with pytest.raises(KeyboardInterrupt), exclusive_lock(path, timeout_s=5):
        pass
    monkeypatch.undo()
    with exclusive_lock(path, timeout_s=0):  # free at once, in this very process
        pass
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_store_another_program_holds_open_is_said_to_be_open_not_damaged(tmp_path):
    path = tmp_path / "s.h5"
    Store(path).add_dem_run("a", {"sdc": 0.1})
    holder = subprocess.Popen(
        [sys.executable, "-c", "import h5py, sys, time; f = h5py.File(sys.argv[1], 'r+'); "
         "print('open', flush=True); time.sleep(60)", str(path)],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "open"
        with pytest.raises(StoreError) as refused:
            Store(path)
    finally:
        holder.kill()
        holder.wait()
    said = str(refused.value)
    assert "another program has the store open" in said and "not a readable" not in said
