"""Store transactions: rollback leaves the file byte-identical, locking, concurrent writers."""

from __future__ import annotations

import hashlib
import multiprocessing
import os
import signal
import stat
import threading

import numpy as np
import pytest
from _shaker_files import file_sha256

from pidcore.errors import StoreError
from pidcore.records import Channel, Measurement
from pidcore.store import Store


def make_measurement(seed: int) -> Measurement:
    rng = np.random.default_rng(seed)
    return Measurement(f"run{seed}.uff", (
        Channel("force", "force", rng.normal(size=128), 1024.0, "N"),
        Channel("accel", "acceleration", rng.normal(size=128), 1024.0, "g"),
    ), sha256=hashlib.sha256(f"run{seed}".encode()).hexdigest(), file_format="uff")


def leftovers(directory) -> list[str]:
    """Files beside the store other than the store and its lock file (temporary copies)."""
    return sorted(p.name for p in directory.iterdir()
                  if p.name not in {"pid_store.h5", "pid_store.h5.lock"})


@pytest.fixture(autouse=True, params=["in memory", "on disk"])
def working_copy(request, monkeypatch):
    """Every test here in both ways a commit changes its copy: in memory (stores up to
    STORE_IN_MEMORY_MAX_BYTES) and copied to disk (larger ones; here every store)."""
    from pidcore import defaults

    if request.param == "on disk":
        monkeypatch.setattr(defaults, "STORE_IN_MEMORY_MAX_BYTES", 0)
    return request.param


@pytest.fixture
def store(tmp_path):
    store = Store(tmp_path / "pid_store.h5")
    mkey, _ = store.add_measurement(make_measurement(0))
    store.add_analysis(mkey, {"sdc": 0.3})
    store.add_dem_run("existing", {"sdc": 0.2})
    return store


def test_exception_inside_transaction_leaves_file_identical(store, tmp_path):
    digest = file_sha256(store.path)
    with pytest.raises(RuntimeError, match="boom"):
        with store.transaction() as h5:
            store.add_dem_run("new", {"sdc": 0.4})
            store.add_measurement(make_measurement(1))
            h5.attrs["scribble"] = 1
            assert store.has_dem_run("new")  # the batch sees its own writes
            raise RuntimeError("boom")
    assert file_sha256(store.path) == digest
    assert leftovers(tmp_path) == []
    assert not store.has_dem_run("new") and len(store.list_measurements()) == 1


def test_unconvertible_channel_in_batch_rolls_back_everything(store, tmp_path):
    digest = file_sha256(store.path)
    bad = Measurement("bad.csv", (
        Channel("ok", "force", np.ones(8), 100.0),
        Channel("garbled", "force", np.array(["1.0", "x"], dtype=object), 100.0),
    ), sha256="cd" * 32, file_format="csv")
    with pytest.raises(StoreError, match="'garbled'.*float64"):
        with store.transaction():
            assert store.add_measurement(make_measurement(2))[1]  # written to the copy first
            store.add_measurement(bad)
    assert file_sha256(store.path) == digest
    assert leftovers(tmp_path) == []
    # Outside a batch the bad measurement alone is refused the same way.
    with pytest.raises(StoreError, match="garbled"):
        store.add_measurement(bad)
    assert file_sha256(store.path) == digest


def test_keyboard_interrupt_inside_transaction_leaves_original(store, tmp_path):
    digest = file_sha256(store.path)
    with pytest.raises(KeyboardInterrupt):
        with store.transaction():
            store.add_dem_runs([{"case_key": f"k{i}", "record": {"sdc": 0.1}} for i in range(5)])
            raise KeyboardInterrupt
    assert file_sha256(store.path) == digest
    assert leftovers(tmp_path) == []
    assert store.verify() == []


def test_failed_first_write_creates_no_store(tmp_path):
    store = Store(tmp_path / "pid_store.h5")
    with pytest.raises(RuntimeError):
        with store.transaction():
            store.add_dem_run("c", {"sdc": 0.1})
            raise RuntimeError
    assert not store.path.exists() and leftovers(tmp_path) == []


def test_batch_commits_once_and_nested_transactions_join(store):
    with store.transaction() as outer:
        with store.transaction() as inner:
            assert inner is outer
            store.add_dem_runs([{"case_key": "a", "record": {"sdc": 0.1}}])
        store.add_dem_run("b", {"sdc": 0.2})
        # Until the outermost block ends, the committed file is unchanged.
        assert not Store(store.path).has_dem_run("a")
    assert store.has_dem_run("a") and store.has_dem_run("b")
    assert store.verify() == []


def test_stale_temporary_is_removed_by_next_writer(store, tmp_path):
    stale = tmp_path / ".pid_store.h5.deadbeefdeadbeef.tmp"  # as left by a killed writer
    stale.write_bytes(b"partial")
    store.add_dem_run("after_crash", {"sdc": 0.1})
    assert not stale.exists() and leftovers(tmp_path) == []


def test_permissions_of_store_are_kept(store):
    os.chmod(store.path, 0o640)
    store.add_dem_run("n", {"sdc": 0.1})
    assert stat.S_IMODE(store.path.stat().st_mode) == 0o640


def test_second_writer_times_out_with_clear_error(store):
    other = Store(store.path, lock_timeout_s=0.2)
    with store.transaction():
        with pytest.raises(StoreError, match=r"write lock .*pid_store\.h5\.lock.* 0\.2 s"):
            other.add_dem_run("blocked", {"sdc": 0.1})
    assert other.add_dem_run("later", {"sdc": 0.1}) == "later"  # free again after the commit


def test_reader_sees_old_state_while_writer_holds_lock(store):
    reader = Store(store.path, lock_timeout_s=0.1)
    before = reader.list_dem_runs()
    with store.transaction():
        store.add_dem_run("pending", {"sdc": 0.9})
        during = reader.list_dem_runs()  # must neither block nor see the uncommitted run
        assert list(during["case_key"]) == list(before["case_key"]) == ["existing"]
        assert reader.verify() == []
    assert sorted(reader.list_dem_runs()["case_key"]) == ["existing", "pending"]


def _writer(path: str, worker: int, n_entries: int, start) -> None:
    start.wait()
    store = Store(path, lock_timeout_s=60)
    for i in range(n_entries):
        store.add_dem_run(f"w{worker}_e{i}", {"sdc": worker + i / 10, "worker": worker},
                          arrays={"trace": np.full(64, float(worker))})


def test_concurrent_writers_all_succeed(store):
    n_workers, n_entries = 4, 5
    context = multiprocessing.get_context("fork")
    start = context.Event()
    workers = [context.Process(target=_writer, args=(str(store.path), w, n_entries, start))
               for w in range(n_workers)]
    for process in workers:
        process.start()
    start.set()  # release all at once so that their transactions contend for the lock
    for process in workers:
        process.join(timeout=120)
    assert [p.exitcode for p in workers] == [0] * n_workers
    runs = store.list_dem_runs().set_index("case_key")
    expected = {f"w{w}_e{i}" for w in range(n_workers) for i in range(n_entries)}
    assert expected <= set(runs.index) and len(runs) == n_workers * n_entries + 1
    for w in range(n_workers):
        for i in range(n_entries):
            run = store.get_dem_run(f"w{w}_e{i}")
            assert run.record == {"sdc": w + i / 10, "worker": w}
            np.testing.assert_array_equal(run.arrays["trace"], np.full(64, float(w)))
    assert store.verify() == []
    assert leftovers(store.path.parent) == []


def _killed_writer(path: str, ready) -> None:
    store = Store(path)
    with store.transaction():
        store.add_dem_runs([{"case_key": f"lost{i}", "record": {"sdc": 0.1}} for i in range(50)])
        ready.set()
        threading.Event().wait(60)  # killed here, holding the lock, mid-transaction


def test_writer_killed_mid_transaction_loses_only_its_own_batch(store, tmp_path):
    digest = file_sha256(store.path)
    context = multiprocessing.get_context("fork")
    ready = context.Event()
    process = context.Process(target=_killed_writer, args=(str(store.path), ready))
    process.start()
    assert ready.wait(30)
    assert leftovers(tmp_path)  # its working copy exists while it runs
    os.kill(process.pid, signal.SIGKILL)
    process.join(30)
    assert file_sha256(store.path) == digest and store.verify() == []
    # The kernel released its lock: the next writer gets in at once and removes the orphan copy.
    Store(store.path, lock_timeout_s=5).add_dem_run("next", {"sdc": 0.5})
    assert leftovers(tmp_path) == []
    assert list(store.list_dem_runs()["case_key"]) == ["existing", "next"]


def test_a_store_above_the_in_memory_limit_is_changed_on_disk_not_read_into_memory(
        tmp_path, monkeypatch, working_copy):
    # A store of long records (G's scale trial: ~380 MB per ten-minute record) needed its whole
    # size in memory at every commit: 10 GB of RAM for ~25 records, per DEM case of a sweep.
    # Above the limit the copy is made on disk: Python's own allocations during a commit stay
    # far below the store's size (tracemalloc sees the in-memory copy, not HDF5's C buffers).
    import tracemalloc

    from pidcore import defaults

    store = Store(tmp_path / "pid_store.h5")
    samples = np.random.default_rng(0).standard_normal(2_000_000)  # 16 MB, incompressible
    store.add_dem_run("big", {"sdc": 0.1}, arrays={"samples": samples})
    size = store.path.stat().st_size
    assert size > 10e6  # compression takes a few %
    monkeypatch.setattr(defaults, "STORE_IN_MEMORY_MAX_BYTES",
                        size - 1 if working_copy == "on disk" else size)
    tracemalloc.start()
    try:
        store.add_dem_run("small", {"sdc": 0.2})
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    if working_copy == "on disk":
        assert peak < 0.1 * size, peak  # a few hundred kB of Python objects, not the 16 MB
    else:
        assert peak > size, peak  # the image itself
    assert sorted(store.list_dem_runs()["case_key"]) == ["big", "small"]
    np.testing.assert_array_equal(store.get_dem_run("big").arrays["samples"], samples)
    assert store.verify() == [] and leftovers(tmp_path) == []
