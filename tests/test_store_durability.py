"""The store when the machine says no: a file size limit (``ulimit -f``; a full disk fails the
same writes with ENOSPC), a writer killed or terminated mid-run, the workers of a killed pool."""

from __future__ import annotations

import contextlib
import os
import resource
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from _shaker_files import file_sha256, write_force_velocity

from pidcore.errors import ParameterError, StoreError
from pidcore.signal.synthetic import synthesize_shaker_record
from pidcore.specimen import load_specimen
from pidcore.store import Store
from pidcore.store.lock import exclusive_lock

ROOT = Path(__file__).resolve().parents[1]


def _with_file_size_limit(limit_bytes: int):
    """A ``preexec_fn``: the child may write no file beyond ``limit_bytes`` (``ulimit -f``).
    Python ignores SIGXFSZ, so a write past it fails with EFBIG instead of killing it."""
    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    return limit


def test_a_store_changed_on_disk_is_refused_in_one_line_where_its_copy_cannot_fit(tmp_path):
    # A store above STORE_IN_MEMORY_MAX_BYTES is copied to disk and HDF5 writes that copy
    # itself, so a write it fails would end in h5py's destructor errors and a segfault (as the
    # test above found for every store before the in-memory copy): the room is checked before
    # the copy is made, in one line, store unchanged.
    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"sdc": 0.25}, arrays={"trace": np.arange(1000.0)})
    digest, size = file_sha256(store.path), store.path.stat().st_size
    code = textwrap.dedent(f"""
        from pidcore import defaults
        from pidcore.errors import StoreError
        from pidcore.store import Store
        defaults.STORE_IN_MEMORY_MAX_BYTES = 0  # every store is "large"
        try:
            Store({str(store.path)!r}).add_dem_run("new", {{"sdc": 0.5}})
        except StoreError as exc:
            print(exc)
    """)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=60, env={**os.environ, "PYTHONPATH": str(ROOT)},
                       preexec_fn=_with_file_size_limit(size - 4000))
    assert p.returncode == 0 and p.stderr == "", (p.returncode, p.stderr[-2000:])
    lines = p.stdout.splitlines()
    assert len(lines) == 1 and "s.h5: the file size limit of this process" in lines[0]
    assert file_sha256(store.path) == digest and sorted(os.listdir(tmp_path)) == ["s.h5"]


def test_new_data_that_does_not_fit_a_store_changed_on_disk_is_one_line_store_unchanged(
        tmp_path):
    # The room checked before the copy is the store plus 1 MiB of headroom: an 8 MB array
    # saved under a file size limit 3 MiB above the store passed that check, HDF5 failed its
    # own write of the copy, and the process printed h5py's destructor tracebacks and died of
    # a segmentation fault (status -11). Now the entry's size is checked before HDF5 writes it.
    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"sdc": 0.25}, arrays={"trace": np.arange(1000.0)})
    digest, size = file_sha256(store.path), store.path.stat().st_size
    code = textwrap.dedent(f"""
        import numpy as np
        from pidcore import defaults
        from pidcore.errors import StoreError
        from pidcore.store import Store
        defaults.STORE_IN_MEMORY_MAX_BYTES = 0  # every store is "large"
        samples = np.random.default_rng(0).standard_normal(1_000_000)  # 8 MB, incompressible
        try:
            Store({str(store.path)!r}).add_dem_run("new", {{"sdc": 0.5}},
                                                    arrays={{"samples": samples}})
        except StoreError as exc:
            print(exc)
    """)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=60, env={**os.environ, "PYTHONPATH": str(ROOT)},
                       preexec_fn=_with_file_size_limit(size + 3 * 2**20))
    assert p.returncode == 0 and p.stderr == "", (p.returncode, p.stderr[-2000:])
    lines = p.stdout.splitlines()
    assert len(lines) == 1, lines
    assert ("s.h5: DEM run 'new' needs up to 8.7 MiB more, and the file size limit of this "
            "process (ulimit -f) is 3.0 MiB") in lines[0]
    assert lines[0].endswith("the store is unchanged")
    assert file_sha256(store.path) == digest and sorted(os.listdir(tmp_path)) == ["s.h5"]


def test_new_data_that_does_not_fit_the_disk_of_a_store_changed_on_disk_is_refused(
        tmp_path, monkeypatch):
    # As above for a full disk (HDF5's write fails with ENOSPC the same way): room for the
    # copy of the store, not for the measurement's channels that come into it.
    import shutil

    from pidcore import defaults

    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"sdc": 0.25})
    digest = file_sha256(store.path)
    rec = synthesize_shaker_record(mass_kg=0.25, acceleration_amplitude_m_s2=49.0,
                                   frequency_hz=100.0, sample_rate_hz=25_600.0, n_periods=400,
                                   viscous_damping_n_s_m=2.0, snr_db=50, seed=3)
    csv = write_force_velocity(tmp_path / "run.csv", rec.force_n, rec.velocity_m_s, 25_600.0)
    from pidcore.io import read_measurement

    measurement = read_measurement(csv)
    channel_bytes = sum(np.asarray(ch.data).size * 8 for ch in measurement.channels)
    usage = shutil.disk_usage(tmp_path)
    # 1.5 MiB: the copy of the store and its 1 MiB headroom fit, the channels (~1.6 MB +
    # 1 MiB of headroom for HDF5's own structures) do not
    assert channel_bytes + 2**20 > 1.5 * 2**20
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage._replace(free=3 * 2**19))
    monkeypatch.setattr(defaults, "STORE_IN_MEMORY_MAX_BYTES", 0)
    with pytest.raises(StoreError, match=r"s\.h5: measurement .*run\.csv needs up to "
                                         r"[\d.]+ MiB more, and 1\.5 MiB free in .*the store "
                                         r"is unchanged$"):
        store.add_measurement(measurement)
    assert file_sha256(store.path) == digest
    assert sorted(os.listdir(tmp_path)) == ["run.csv", "s.h5"]
    monkeypatch.setattr(defaults, "STORE_IN_MEMORY_MAX_BYTES", 2**30)
    store.add_measurement(measurement)  # in memory: the image is written by Python, no check
    assert store.verify() == [] and len(store.list_measurements()) == 1


@pytest.mark.parametrize("room", [-4000, 1_000_000], ids=["below-the-store", "above-it"])
def test_a_write_past_the_file_size_limit_is_one_line_and_leaves_the_store(tmp_path, room):
    # The limit is just below the store's size or 1 MB above it (a copy of the store fits,
    # the new run's 2 MB of incompressible samples do not). In the second case HDF5 wrote
    # the working copy itself: its failed writes came out of h5py's object destructors
    # ("Exception ignored in: 'h5py._objects.ObjectID.__dealloc__'", ~50-300 lines), the
    # error spanned two lines (HDF5's message holds a newline) and the process died of a
    # segmentation fault at exit (status -11), its working copy left beside the store.
    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"sdc": 0.25}, arrays={"trace": np.arange(1000.0)},
                      units={"sdc": "1"})
    digest, size = file_sha256(store.path), store.path.stat().st_size
    code = textwrap.dedent(f"""
        import numpy as np
        from pidcore.errors import StoreError
        from pidcore.store import Store
        try:
            Store({str(store.path)!r}).add_dem_run(
                "too_big", {{"sdc": 0.5}},
                arrays={{"noise": np.random.default_rng(1).normal(size=250_000)}})
        except StoreError as exc:
            print(exc)
    """)
    limit = size + room
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=60, env={**os.environ, "PYTHONPATH": str(ROOT)},
                       preexec_fn=_with_file_size_limit(limit))
    assert p.returncode == 0 and p.stderr == "", (p.returncode, p.stderr[-2000:])
    lines = p.stdout.splitlines()
    assert len(lines) == 1 and "s.h5: cannot commit the changes" in lines[0], p.stdout
    assert "File too large" in lines[0] and "the store is unchanged" in lines[0]
    assert file_sha256(store.path) == digest
    assert sorted(os.listdir(tmp_path)) == ["s.h5"]  # no working copy left
    assert list(store.list_dem_runs()["case_key"]) == ["kept"] and store.verify() == []
    # the next write, with room, works without any repair
    store.add_dem_run("next", {"sdc": 0.5}, arrays={"noise": np.ones(250_000)})
    assert store.verify() == [] and store.get_dem_run("kept").units == {"sdc": "1"}


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs code (a zombie awaiting its reaper does not)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads /proc (Linux)")
@pytest.mark.parametrize("signum", [signal.SIGKILL, signal.SIGTERM, signal.SIGHUP],
                         ids=["kill-9", "sigterm", "sighup"])
def test_the_workers_of_a_killed_sweep_end_with_it(tmp_path, signum):
    # `kill -9` of a sweep (or calibrate) left its pool workers waiting for work forever,
    # with the fork server and the killed command's stdout and stderr: a caller reading those
    # to their end (`$(pidcore dem sweep ...)`, a harness) never returned. SIGTERM did the
    # same (the parent ended on the spot, status -15); now it is the CLI's interruption, which
    # stops the workers and says so. 4 calls of 60 s on 2 workers: only workers that end with
    # their parent are gone within the 20 s given.
    tests = Path(__file__).resolve().parent
    code = textwrap.dedent(f"""
        import signal, sys
        from _pool_probe import wait_in_worker
        from pidcore import interrupt
        from pidcore.dem.sweep import run_pooled
        if __name__ == "__main__":
            # as a shell starts it: a suite run under nohup passes SIGHUP ignored, which
            # pidcore rightly keeps ignoring
            signal.signal(signal.SIGHUP, signal.SIG_DFL)
            interrupt.install()  # as pidcore.cli.main does
            try:
                run_pooled(wait_in_worker, [({str(tmp_path)!r}, 60.0)] * 4, workers=2,
                           finish=print)
            except KeyboardInterrupt:
                print("interrupted", file=sys.stderr)
                sys.exit(interrupt.exit_status())
    """)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), str(tests)])}
    p = subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        while len(os.listdir(tmp_path)) < 2 and time.monotonic() < deadline:
            time.sleep(0.02)
        workers = [int(name) for name in os.listdir(tmp_path)]
        assert len(workers) == 2
        p.send_signal(signum)
        out, err = p.communicate(timeout=20)  # EOF: no worker holds the pipes any more
        assert out == ""
        if signum == signal.SIGKILL:
            assert p.returncode == -signal.SIGKILL
        else:
            assert (p.returncode, err) == (128 + signum, "interrupted\n")
        deadline = time.monotonic() + 5
        while any(map(_alive, workers)) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(map(_alive, workers))
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(p.pid, signal.SIGKILL)  # whatever is left of this test's processes


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP], ids=["sigterm", "sighup"])
def test_sigterm_mid_commit_is_an_interruption_exit_143_store_unchanged(tmp_path, signum):
    # `kill PID`, `timeout`, a batch scheduler: SIGTERM ended the process on the spot (status
    # -15, no word on stderr), the store's working copy left beside it. Now it is Ctrl-C's
    # interruption with the shell's status for SIGTERM, 128 + 15. The signal is sent from
    # inside the store's transaction (the analysis saved, before the rename) so that it lands
    # there every time, not at a moment a loaded machine chooses. SIGHUP (the terminal of a
    # sweep closed) ended the process on the spot too; now the same, with status 128 + 1.
    rec = synthesize_shaker_record(mass_kg=0.25, acceleration_amplitude_m_s2=49.0,
                                   frequency_hz=100.0, sample_rate_hz=25_600.0, n_periods=40,
                                   viscous_damping_n_s_m=2.0, snr_db=50, seed=3)
    small = write_force_velocity(tmp_path / "run_fill50.csv", rec.force_n, rec.velocity_m_s,
                                 25_600.0)
    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"sdc": 0.25})
    digest = file_sha256(store.path)
    code = textwrap.dedent(f"""
        import os, signal, sys
        # as a shell starts it: a suite run under nohup passes SIGHUP ignored, which pidcore
        # rightly keeps ignoring
        signal.signal(signal.SIGHUP, signal.SIG_DFL)
        import pidcore.measure as measure
        from pidcore.cli import console_main
        saved = measure.store_analysis
        def store_then_sigterm(*args, **kwargs):
            key = saved(*args, **kwargs)
            os.kill(os.getpid(), {int(signum)})
            return key
        measure.store_analysis = store_then_sigterm
        sys.exit(console_main(["analyze", {str(small)!r}, "--store", {str(store.path)!r}]))
    """)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=120, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert p.returncode == 128 + signum, (p.returncode, p.stderr[-2000:])
    assert p.stderr == ("pidcore analyze: interrupted; nothing saved, the store is "
                        "unchanged\n") and p.stdout == ""
    assert file_sha256(store.path) == digest
    assert sorted(os.listdir(tmp_path)) == ["run_fill50.csv", "s.h5"]  # no working copy


@pytest.mark.parametrize("text", ["st\x00eel", "caf\udce9"], ids=["nul", "lone-surrogate"])
def test_a_record_string_hdf5_cannot_hold_is_one_line_and_leaves_the_store(tmp_path, text):
    # h5py raised ValueError ("VLEN strings do not support embedded NULLs") or
    # UnicodeEncodeError from inside the transaction: a traceback from the CLI, not one line
    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"specimen_name": "steel"})
    digest = file_sha256(store.path)
    with pytest.raises(StoreError, match=r"s\.h5: DEM run 'new': record field 'specimen_name'"):
        store.add_dem_run("new", {"specimen_name": text})
    assert file_sha256(store.path) == digest and sorted(os.listdir(tmp_path)) == ["s.h5"]


def test_a_specimen_named_with_a_nul_is_refused_before_any_simulation(tmp_path):
    # TOML allows "\u0000" in a string; the name goes into every stored run's record, where
    # HDF5 cannot hold it: `dem run --specimen F --store S` simulated, then lost the run to
    # that traceback at the commit (exit 1)
    text = (ROOT / "data_samples" / "specimens" / "steel_6mm.toml").read_text()
    assert 'name = "steel_6mm"' in text
    path = tmp_path / "nul.toml"
    path.write_text(text.replace('name = "steel_6mm"', 'name = "steel\\u0000_6mm"'))
    with pytest.raises(ParameterError, match=r"nul\.toml: name: expected a name of printable"):
        load_specimen(path)


def test_a_writer_leaves_the_working_copy_of_a_store_named_like_it_alone(tmp_path):
    # Stale working copies were found by prefix, ".s.h5." ... ".tmp": that took the live
    # working copy of "s.h5.old.h5" (another store, another lock, a writer running), whose
    # commit then failed with FileNotFoundError and lost its batch.
    store, other = Store(tmp_path / "s.h5"), Store(tmp_path / "s.h5.old.h5")
    other.add_dem_run("kept", {"sdc": 0.1})
    with other.transaction():
        other.add_dem_run("pending", {"sdc": 0.2})
        store.add_dem_run("meanwhile", {"sdc": 0.3})  # removes stale copies of s.h5 only
    assert list(other.list_dem_runs()["case_key"]) == ["kept", "pending"]
    assert store.has_dem_run("meanwhile")
    assert sorted(os.listdir(tmp_path)) == ["s.h5", "s.h5.old.h5"]


@pytest.mark.parametrize("version", [0, -1])
def test_a_store_version_pidcore_never_wrote_is_refused_and_left_untouched(tmp_path, version):
    # Only versions above this pidcore's were refused: a file claiming version 0 (no pidcore
    # wrote one) was read and written to as a store of version 1, its claim left as it was.
    import h5py

    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"sdc": 0.1})
    with h5py.File(store.path, "r+") as h5:
        h5.attrs["pidcore_store_version"] = np.int64(version)
    digest = file_sha256(store.path)
    with pytest.raises(StoreError, match=rf"s\.h5: not a readable pidcore store "
                                         rf"\(pidcore_store_version {version} is not one"):
        Store(store.path)
    with pytest.raises(StoreError, match="not one pidcore writes"):
        store.add_dem_run("new", {"sdc": 0.2})
    assert file_sha256(store.path) == digest


@pytest.mark.parametrize("where", ["arrays/evil", "record"], ids=["array", "record-group"])
def test_an_external_link_deep_in_an_entry_is_refused_before_it_is_followed(tmp_path, where):
    # Only sections and entries were checked for links: an external link inside an entry
    # (a store handed over by someone) made get_dem_run, report --store and the app's
    # listing read the file it named, and verify() found nothing wrong.
    import h5py

    secret = tmp_path / "secret.h5"
    with h5py.File(secret, "w") as h5:
        h5["data"] = np.arange(5.0)
        h5.create_group("group").attrs["sdc"] = 99.0
    store = Store(tmp_path / "s.h5")
    store.add_dem_run("run", {"sdc": 0.1}, arrays={"trace": np.ones(3)})
    with h5py.File(store.path, "r+") as h5:
        entry = h5["dem_runs/run"]
        if where == "record":
            del entry["record"]
            entry["record"] = h5py.ExternalLink(str(secret), "/group")
        else:
            entry["arrays"]["evil"] = h5py.ExternalLink(str(secret), "/data")
    digest = file_sha256(store.path)
    reopened = Store(store.path)
    refused = rf"s\.h5: not a readable pidcore store .*{where}.* external link to '.*secret\.h5'"
    with pytest.raises(StoreError, match=refused):
        reopened.get_dem_run("run")
    if where == "record":
        with pytest.raises(StoreError, match=refused):
            reopened.list_dem_runs()
    problems = reopened.verify()
    assert len(problems) == 1 and "external link to" in problems[0], problems
    assert file_sha256(store.path) == digest


def test_a_disk_without_room_for_the_copy_is_refused_before_the_work(tmp_path, monkeypatch):
    # Every save writes a whole copy of the store beside it: with less room than that, a
    # `dem run`/sweep/calibrate simulated first and lost the run at the commit ("cannot make
    # the working copy ... No space left on device").
    import shutil

    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"sdc": 0.1}, arrays={"trace": np.ones(200_000)})
    size = store.path.stat().st_size
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(shutil, "disk_usage", lambda path: usage._replace(free=size))
    with pytest.raises(StoreError, match=r"s\.h5: 0\.\d MiB free in .*copy of the store "
                                         r"\(0\.\d MiB\).*at least [12]\.\d MiB free"):
        store.check_writable()


def test_a_file_size_limit_below_the_store_is_refused_before_the_simulation(tmp_path):
    # as above for `ulimit -f` below the store's size: the run was simulated, then lost
    # ("cannot make the working copy ... File too large"); the limit is known before any work
    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"sdc": 0.1}, arrays={"trace": np.ones(200_000)})
    digest, size = file_sha256(store.path), store.path.stat().st_size
    p = subprocess.run([sys.executable, "-m", "pidcore", "dem", "run", "--frequency", "1000",
                        "--acceleration", "5", "--fill", "50", "--cells", "1", "--cycles", "10",
                        "--no-progress", "--store", str(store.path)],
                       capture_output=True, text=True, timeout=120,
                       env={**os.environ, "PYTHONPATH": str(ROOT)},
                       preexec_fn=_with_file_size_limit(size - 1))
    assert p.returncode == 2 and p.stdout == "", (p.returncode, p.stdout, p.stderr)
    lines = p.stderr.splitlines()
    assert len(lines) == 1 and "s.h5: the file size limit of this process (ulimit -f)" in lines[0]
    assert file_sha256(store.path) == digest


def test_a_store_reached_through_a_symbolic_link_is_written_where_it_lives(tmp_path):
    # The commit's rename replaced the link with a file of its own: the shared store never got
    # the record, and writers through the link and to the store itself locked beside different
    # names, so neither waited for the other.
    (tmp_path / "shared").mkdir()
    (tmp_path / "project").mkdir()
    shared = Store(tmp_path / "shared" / "store.h5")
    shared.add_dem_run("kept", {"sdc": 0.1})
    link = tmp_path / "project" / "pid_store.h5"
    link.symlink_to(Path("..") / "shared" / "store.h5")
    linked = Store(link)
    linked.add_dem_run("through_the_link", {"sdc": 0.2})
    assert link.is_symlink()
    assert sorted(shared.list_dem_runs()["case_key"]) == ["kept", "through_the_link"]
    with linked.transaction():  # one lock for both names
        with pytest.raises(StoreError, match="could not take the write lock"):
            Store(shared.path, lock_timeout_s=0.2).add_dem_run("blocked", {"sdc": 0.3})
    assert sorted(os.listdir(tmp_path / "project")) == ["pid_store.h5"]
    assert sorted(os.listdir(tmp_path / "shared")) == ["store.h5"] and shared.verify() == []


def test_a_store_file_with_two_names_is_refused_before_any_write(tmp_path):
    # A hard link: the commit's rename gave one name a new file and left the other with the
    # old content, so a record saved through one name was missing under the other, without a
    # word. Refused at the write-ability check (before a DEM run is simulated for it) and by
    # the transaction itself (library callers), both names unchanged.
    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"sdc": 0.1})
    other = tmp_path / "other_name.h5"
    os.link(store.path, other)
    digest = file_sha256(store.path)
    with pytest.raises(StoreError, match=r"s\.h5: the store file has 2 names \(hard links\)"):
        store.check_writable()
    with pytest.raises(StoreError, match="hard links"):
        Store(other).add_dem_run("new", {"sdc": 0.2})
    assert file_sha256(store.path) == file_sha256(other) == digest
    assert os.stat(store.path).st_ino == os.stat(other).st_ino  # still one file
    assert sorted(os.listdir(tmp_path)) == ["other_name.h5", "s.h5"]  # no working copy
    os.unlink(other)  # one name again: saving works
    store.add_dem_run("new", {"sdc": 0.2})
    assert list(store.list_dem_runs()["case_key"]) == ["kept", "new"]


def test_a_numba_cache_that_cannot_be_written_costs_a_compile_not_the_run(tmp_path):
    # A cold cache on a full disk (or under a quota, or `ulimit -f`): Numba's save of the
    # compiled code raised OSError ("[Errno 27] File too large" from numba/core/caching.py)
    # out of the first call, so `pidcore analyze --no-store` ended in that traceback (exit 1).
    # An empty NUMBA_CACHE_DIR makes the cache cold; the limit makes every file write fail.
    code = textwrap.dedent("""
        import numpy as np
        from pidcore.signal.validate import _scan
        min_step, crossings, starts, lengths = _scan(np.sin(np.arange(1000.0)), 5, 10)
        print(crossings > 0)
    """)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=120, preexec_fn=_with_file_size_limit(1),
                       env={**os.environ, "PYTHONPATH": str(ROOT),
                            "NUMBA_CACHE_DIR": str(tmp_path / "cache")})
    assert (p.returncode, p.stdout, p.stderr) == (0, "True\n", "")


def test_a_store_name_leaving_no_room_for_its_working_copys_name_is_refused_in_one_line(
        tmp_path):
    # The working copy is named .NAME.<16 hex>.tmp beside the store: a 238-byte store name
    # made it 260 bytes, over the 255 a name may have, and the removal of the copy that was
    # never made raised "[Errno 36] File name too long" itself, over the StoreError.
    assert os.pathconf(tmp_path, "PC_NAME_MAX") == 255  # ext4, tmpfs, xfs, btrfs
    longest = "s" * (255 - 22 - 3) + ".h5"
    Store(tmp_path / longest).add_dem_run("kept", {"sdc": 0.25})
    assert list(Store(tmp_path / longest).list_dem_runs()["case_key"]) == ["kept"]
    # bytes, not characters: 119 characters, 235 bytes
    for name in ["s" * (255 - 22 - 2) + ".h5", "é" * 116 + ".h5"]:
        store = Store(tmp_path / name)
        said = (rf"name is {len(name.encode())} bytes, too long for the working copy .* "
                r"at most 233 bytes")
        with pytest.raises(StoreError, match=said):
            store.check_writable()
        with pytest.raises(StoreError, match=said):
            store.add_dem_run("new", {"sdc": 0.2})
    assert os.listdir(tmp_path) == [longest]


def _run_with_no_writable_numba_cache(tmp_path: Path, code: str) -> subprocess.CompletedProcess:
    """Run ``code`` on a copy of pidcore where Numba's own cache places cannot be made, even by
    root (for whom a read-only folder is writable): every ``__pycache__`` of the copy is a
    file, HOME is a file (no ~/.cache/numba), NUMBA_CACHE_DIR unset; TMPDIR is tmp_path/tmp."""
    site = tmp_path / "site"
    if not site.exists():
        shutil.copytree(ROOT / "pidcore", site / "pidcore",
                        ignore=shutil.ignore_patterns("__pycache__"))
        for folder in [site / "pidcore", *(site / "pidcore").rglob("*")]:
            if folder.is_dir():
                (folder / "__pycache__").write_text("")
        (tmp_path / "home").write_text("")
        (tmp_path / "tmp").mkdir(exist_ok=True)
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME", "PYTHONPATH")}
    env.update(PYTHONPATH=str(site), HOME=str(tmp_path / "home"), TMPDIR=str(tmp_path / "tmp"),
               PYTHONDONTWRITEBYTECODE="1")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, env=env, cwd=tmp_path)


_SCAN_AND_COUNT = textwrap.dedent("""
    import numpy as np
    import pidcore.signal
    from pidcore.signal.validate import _scan
    min_step, crossings, starts, lengths = _scan(np.sin(np.arange(1000.0)), 5, 10)
    print(crossings > 0, len(_scan.stats.cache_hits), len(_scan.stats.cache_misses),
          type(_scan._cache).__name__)
""")


@pytest.mark.slow
def test_a_user_who_can_write_neither_site_packages_nor_home_gets_a_private_temp_cache(tmp_path):
    # A wheel in a root-owned site-packages run by a service account (HOME=/nonexistent):
    # Numba found no place for the cache and raised "cannot cache function
    # '_project_segments': no locator available" at import, so not even --version ran; with
    # a read-only site-packages the kernel was compiled at every run (`specimen check` 1m34).
    first = _run_with_no_writable_numba_cache(tmp_path, _SCAN_AND_COUNT)
    assert (first.returncode, first.stdout, first.stderr) == (0, "True 0 1 FunctionCache\n", "")
    root = tmp_path / "tmp" / f"pidcore-numba-cache-{os.geteuid()}"
    assert stat.S_IMODE(root.stat().st_mode) == 0o700
    assert list(root.rglob("validate._scan-*.nbi"))  # the index of the saved machine code
    # the next run loads the code saved there instead of compiling it again
    second = _run_with_no_writable_numba_cache(tmp_path, _SCAN_AND_COUNT)
    assert (second.returncode, second.stdout, second.stderr) == (0, "True 1 0 FunctionCache\n", "")


@pytest.mark.slow
def test_a_temp_cache_folder_another_user_could_write_is_not_used_and_the_code_runs_uncached(
        tmp_path):
    # Another user creating /tmp/pidcore-numba-cache-UID first (open to all) could plant
    # machine code there that this user would load: the folder is left alone and the function
    # compiled for this run only.
    (tmp_path / "tmp").mkdir()
    planted = tmp_path / "tmp" / f"pidcore-numba-cache-{os.geteuid()}"
    planted.mkdir()
    planted.chmod(0o777)
    p = _run_with_no_writable_numba_cache(tmp_path, _SCAN_AND_COUNT)
    # compiled (a miss) by a dispatcher without a cache to save it to
    assert (p.returncode, p.stdout, p.stderr) == (0, "True 0 1 NullCache\n", "")
    assert list(planted.iterdir()) == []


def test_the_private_temp_cache_folder_is_refused_unless_it_is_a_folder_only_its_user_writes(
        tmp_path, monkeypatch):
    from pidcore import _numba_cache

    monkeypatch.setattr(tempfile, "gettempdir", lambda: str(tmp_path))
    uid = os.geteuid()
    made = _numba_cache.private_temp_cache_root()
    assert made == str(tmp_path / f"pidcore-numba-cache-{uid}")
    assert stat.S_IMODE(os.stat(made).st_mode) == 0o700
    assert _numba_cache.private_temp_cache_root() == made  # found again as it was left
    os.chmod(made, 0o770)
    assert _numba_cache.private_temp_cache_root() is None  # the group could plant code
    os.rmdir(made)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir(mode=0o700)
    os.symlink(elsewhere, made)  # a link planted under the name: not followed
    assert _numba_cache.private_temp_cache_root() is None
    os.unlink(made)
    # a folder of another user's (this test's folder, seen by a process of another uid)
    os.mkdir(tmp_path / f"pidcore-numba-cache-{uid + 1}", 0o700)
    monkeypatch.setattr(os, "geteuid", lambda: uid + 1)
    assert _numba_cache.private_temp_cache_root() is None
    # nowhere to make it: none, the caller compiles uncached
    monkeypatch.setattr(tempfile, "gettempdir", lambda: str(tmp_path / "missing"))
    assert _numba_cache.private_temp_cache_root() is None


def test_a_sigterm_ignored_by_whoever_started_pidcore_stays_ignored():
    # nohup-like launchers that ignore SIGTERM: routing it through the interrupt flag would
    # let a signal the caller chose to ignore stop the run
    from pidcore import interrupt

    previous = signal.signal(signal.SIGTERM, signal.SIG_IGN)
    try:
        restore = interrupt.install()
        try:
            assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN
        finally:
            restore()
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_the_copy_of_a_writer_killed_outright_does_not_refuse_the_next_run(
        tmp_path, monkeypatch):
    # A writer killed by `kill -9` (or the OOM killer) mid-commit leaves its working copy, a
    # hidden file as large as the store, until the next commit removes it. check_writable()
    # counted its space as used and refused the next `dem run`/sweep for want of room ("0.5
    # MiB free ... expected at least 1.4 MiB free") that removing the copy gave.
    import shutil

    store = Store(tmp_path / "s.h5")
    store.add_dem_run("kept", {"sdc": 0.1}, arrays={"trace": np.ones(50_000)})
    digest = file_sha256(store.path)
    stale = tmp_path / ".s.h5.0123456789abcdef.tmp"
    shutil.copyfile(store.path, stale)  # what the killed writer of a large store left
    capacity = 2 * store.path.stat().st_size + 2**20 + 4096  # a disk with room for one copy
    usage = shutil.disk_usage(tmp_path)

    def disk_of_fixed_capacity(path):
        used = sum(p.stat().st_size for p in Path(path).iterdir() if p.is_file())
        return usage._replace(free=capacity - used)

    monkeypatch.setattr(shutil, "disk_usage", disk_of_fixed_capacity)
    with exclusive_lock(store.path, timeout_s=1):  # a writer at work: its copy is not stale
        with pytest.raises(StoreError, match=r"s\.h5: 1\.0 MiB free in "):
            store.check_writable()
        assert stale.exists()
    store.check_writable()  # the lock is free: the copy is stale, and removed
    assert sorted(os.listdir(tmp_path)) == ["s.h5"] and file_sha256(store.path) == digest
