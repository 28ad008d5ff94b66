"""The store's write lock: no lock file left behind, and still mutual exclusion."""

from __future__ import annotations

import threading
import time

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
