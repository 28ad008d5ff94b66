"""Sweeps: every finished case is stored, a re-run resumes, an interruption loses nothing."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from pidcore.dem.simulate import DemConfig, LoadCase
from pidcore.dem.sweep import GRIDS, grid_cases, run_case, run_key, run_sweep
from pidcore.errors import ParameterError
from pidcore.store import Store

# Tiny cases: one cell, few cycles. Physics is tested elsewhere; here only bookkeeping counts.
CONFIG = DemConfig(cells=1, steady_cycles=10, max_transient_cycles=10)
CASES = [LoadCase(1000.0, 5.0, 25.0), LoadCase(1000.0, 10.0, 25.0), LoadCase(500.0, 5.0, 25.0)]


def test_table3_grid_is_the_papers_48_cases():
    cases = grid_cases("table3")
    assert len(cases) == 48 == len(set(cases))
    g = GRIDS["table3"]
    assert {c.frequency_hz for c in cases} == set(g["frequency_hz"]) == {50, 100, 500, 1000}
    assert {c.acceleration_g for c in cases} == {1, 5, 10}
    assert {c.fill_percent for c in cases} == {25, 50, 75, 90}
    with pytest.raises(ParameterError, match="unknown grid"):
        grid_cases("table4")


def test_run_key_changes_with_every_input():
    base = run_key(CASES[0], CONFIG)
    assert run_key(CASES[0], CONFIG) == base
    assert run_key(CASES[1], CONFIG) != base
    assert run_key(CASES[0], DemConfig(cells=1, steady_cycles=10, max_transient_cycles=10,
                                       seed=CONFIG.seed + 1)) != base
    assert run_key(CASES[0], DemConfig(cells=2, steady_cycles=10,
                                       max_transient_cycles=10)) != base


def test_sweep_stores_every_case_and_resumes_without_redoing(tmp_path):
    store_path = tmp_path / "s.h5"
    first = run_sweep(CASES[:2], CONFIG, store_path=store_path, workers=1, progress=False)
    assert len(first.completed) == 2 and not first.skipped
    runs = Store(store_path).list_dem_runs()
    assert set(runs["case_key"]) == {run_key(c, CONFIG) for c in CASES[:2]}
    created = dict(zip(runs["case_key"], runs["created_utc"], strict=True))

    second = run_sweep(CASES, CONFIG, store_path=store_path, workers=1, progress=False)
    assert sorted(second.skipped) == sorted(created)
    assert second.completed == [run_key(CASES[2], CONFIG)]
    runs = Store(store_path).list_dem_runs()
    assert len(runs) == 3
    # finished cases were not redone: their entries are untouched
    for key, stamp in created.items():
        assert runs.set_index("case_key").loc[key, "created_utc"] == stamp


def test_interrupted_sweep_keeps_finished_cases(tmp_path):
    store_path = tmp_path / "s.h5"
    seen = []

    def interrupt_after_first(outcome):
        seen.append(outcome.key)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(CASES, CONFIG, store_path=store_path, workers=1, progress=False,
                  on_case=interrupt_after_first)
    store = Store(store_path)
    assert store.verify() == []
    assert list(store.list_dem_runs()["case_key"]) == seen  # the finished case survived
    resumed = run_sweep(CASES, CONFIG, store_path=store_path, workers=1, progress=False)
    assert resumed.skipped == seen and len(resumed.completed) == 2


def test_stored_record_carries_parameters_seed_and_units(tmp_path):
    store_path = tmp_path / "s.h5"
    run_sweep(CASES[:1], CONFIG, store_path=store_path, workers=1, progress=False)
    entry = Store(store_path).get_dem_run(run_key(CASES[0], CONFIG))
    assert entry.record["seed"] == CONFIG.seed
    assert entry.parameters["config_seed"] == CONFIG.seed
    assert entry.parameters["case_frequency_hz"] == 1000.0
    assert entry.units["frequency_hz"] == "Hz" and entry.units["energy_per_cycle_j"] == "J"
    assert "shaker_force_n" in entry.arrays


def test_dem_worker_processes_are_never_forked_from_the_caller():
    import multiprocessing

    from pidcore.dem.sweep import dem_process_context

    # forking a process that runs threads (Numba's, a Streamlit server's) is unsafe: a fork
    # server (one clean process that imported the DEM modules) or spawn, never fork
    context = dem_process_context()
    want = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    assert context.get_start_method() == want


@pytest.mark.dem_subprocess
@pytest.mark.slow
def test_process_pool_gives_the_same_numbers_as_serial(tmp_path):
    serial = run_sweep(CASES[:2], CONFIG, store_path=tmp_path / "a.h5", workers=1,
                       progress=False)
    pooled = run_sweep(CASES[:2], CONFIG, store_path=tmp_path / "b.h5", workers=2,
                       progress=False)
    assert sorted(serial.completed) == sorted(pooled.completed)
    a = Store(tmp_path / "a.h5").list_dem_runs().set_index("case_key")
    b = Store(tmp_path / "b.h5").list_dem_runs().set_index("case_key")
    # deterministic per seed: identical SDC regardless of process layout
    assert (a.loc[serial.completed, "sdc"] == b.loc[serial.completed, "sdc"]).all()


def test_dask_scheduler_path(tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        summary = run_sweep(CASES[:1], CONFIG, store_path=tmp_path / "d.h5",
                            scheduler=cluster.scheduler_address, progress=False)
    assert summary.completed == [run_key(CASES[0], CONFIG)]
    assert Store(tmp_path / "d.h5").has_dem_run(summary.completed[0])
    # the same run, bit for bit, as the local processes store it (the key promises it)
    run_sweep(CASES[:1], CONFIG, store_path=tmp_path / "l.h5", workers=1, progress=False)
    remote = Store(tmp_path / "d.h5").get_dem_run(summary.completed[0])
    local = Store(tmp_path / "l.h5").get_dem_run(summary.completed[0])
    assert remote.arrays.keys() == local.arrays.keys()
    for name, values in local.arrays.items():
        np.testing.assert_array_equal(remote.arrays[name], values, err_msg=name)
    timing = {"wall_s", "kernel_s", "particle_steps_per_s"}  # how long it took, not what
    assert {k: v for k, v in remote.record.items() if k not in timing} == \
        {k: v for k, v in local.record.items() if k not in timing}


def test_a_run_saved_by_dem_run_is_skipped_by_a_sweep(tmp_path):
    from pidcore.dem import simulate_load_case
    from pidcore.dem.persist import save_dem_result
    from pidcore.dem.result import UNITS

    store_path = tmp_path / "s.h5"
    key = save_dem_result(store_path, simulate_load_case(CASES[0], CONFIG))
    assert key == run_key(CASES[0], CONFIG)
    summary = run_sweep(CASES[:1], CONFIG, store_path=store_path, workers=1, progress=False)
    assert summary.skipped == [key] and not summary.completed
    entry = Store(store_path).get_dem_run(key)
    assert entry.units["sdc"] == UNITS["sdc"] and entry.units["shaker_force_n"] == "N"


def test_sweep_of_a_specimen_stores_its_runs_with_provenance_and_resumes(tmp_path):
    from pidcore.specimen import paper_specimen

    own = paper_specimen().with_values({"coupon.fixture_mass_kg": 0.02})
    store_path = tmp_path / "s.h5"
    first = run_sweep(CASES[:1], CONFIG, store_path=store_path, workers=1, progress=False,
                      specimen=own)
    key = run_key(CASES[0], CONFIG, own)
    assert first.completed == [key] and key != run_key(CASES[0], CONFIG)
    entry = Store(store_path).get_dem_run(key)
    assert entry.parameters["specimen_sha256"] == own.hash
    # the fixture is in the vibrated mass
    assert entry.record["vibrated_mass_kg"] > 0.02 + own.coupon.mass_kg
    again = run_sweep(CASES[:1], CONFIG, store_path=store_path, workers=1, progress=False,
                      specimen=own)
    assert again.skipped == [key] and not again.completed
    # the paper's coupon is another run: not skipped
    paper = run_sweep(CASES[:1], CONFIG, store_path=store_path, workers=1, progress=False)
    assert paper.completed == [run_key(CASES[0], CONFIG)]


def test_an_unreachable_scheduler_is_one_line_exit_2_and_nothing_stored(tmp_path, capsys):
    """`pidcore dem sweep --scheduler tcp://host:8786` with no scheduler there printed a
    30-line dask traceback and exited 1 (the README: one line, exit code 2)."""
    pytest.importorskip("distributed")
    import dask

    from pidcore.cli import main

    store = tmp_path / "s.h5"
    with dask.config.set({"distributed.comm.timeouts.connect": "2s"}):
        code = main(["dem", "sweep", "--frequencies", "1000", "--accelerations", "5",
                     "--fills", "25", "--cells", "1", "--cycles", "2", "--no-progress",
                     "--scheduler", "tcp://127.0.0.1:1", "--store", str(store)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and "--scheduler tcp://127.0.0.1:1" in err[0], err
    assert not store.exists() or not Store(store).list_dem_runs().shape[0]


def test_local_workers_given_with_a_scheduler_are_refused_in_one_line_before_anything(
        tmp_path, capsys):
    """`dem sweep --workers 2 --scheduler ADDR` ran on the cluster and ignored --workers
    without a word."""
    import contextlib

    from pidcore.cli import main

    store = tmp_path / "s.h5"
    # the refusal needs no dask; the old code went on to the (absent) scheduler: refused
    # within 1 s for another reason (or for want of dask)
    try:
        import dask
    except ImportError:
        quick = contextlib.nullcontext()
    else:
        quick = dask.config.set({"distributed.comm.timeouts.connect": "1s"})
    with quick:
        code = main(["dem", "sweep", "--frequencies", "1000", "--accelerations", "5",
                     "--fills", "25", "--cells", "1", "--cycles", "2", "--no-progress",
                     "--workers", "2", "--scheduler", "tcp://127.0.0.1:1",
                     "--store", str(store)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and err[0].startswith("pidcore dem sweep: error: --workers 2: "), err
    assert "tcp://127.0.0.1:1" in err[0] and err[0].endswith("not both"), err
    assert not store.exists()
    # a library caller is refused so too
    with pytest.raises(ParameterError, match="^workers 1: .* not both$"):
        run_sweep(CASES[:1], CONFIG, store_path=store, workers=1,
                  scheduler="tcp://127.0.0.1:1", progress=False)
    assert not store.exists()


def _listener(reply: bytes | None) -> int:
    """Port of a local TCP listener that accepts every connection and sends ``reply`` to
    each (then closes it), or nothing ever (``None``: the connections are held open)."""
    import socket
    import threading

    server = socket.create_server(("127.0.0.1", 0))
    held = []

    def serve() -> None:
        while True:
            conn, _ = server.accept()
            if reply is None:
                held.append(conn)
                continue
            conn.recv(4096)  # the client's handshake, as an HTTP server reads a request
            conn.sendall(reply)
            conn.close()

    threading.Thread(target=serve, daemon=True).start()
    return server.getsockname()[1]


@pytest.mark.timeout(60)  # the old code waited for an answer for ever: fail, not hang
@pytest.mark.parametrize(("reply", "said"), [
    (None, "the connection was accepted but no dask.distributed scheduler answered within "
           "1.5 s"),
    (b"HTTP/1.0 400 Bad Request\r\nContent-Length: 0\r\n\r\n",
     "something other than a dask.distributed scheduler answered there"),
])
def test_an_address_where_no_scheduler_answers_is_refused_in_one_line_within_the_limit(
        tmp_path, capsys, monkeypatch, reply, said):
    """`--scheduler` at a port that accepts and never answers waited for ever; at an HTTP
    server, dask read "HTTP/1.0" as a count of frames and the line passed on numpy's "Unable
    to allocate 3.07 EiB"."""
    pytest.importorskip("distributed")
    import time

    import dask

    from pidcore import defaults
    from pidcore.cli import main

    monkeypatch.setattr(defaults, "DEM_SCHEDULER_ANSWER_TIMEOUT_S", 0.5, raising=False)
    address = f"tcp://127.0.0.1:{_listener(reply)}"
    store = tmp_path / "s.h5"
    start = time.perf_counter()
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):  # 1 s + 0.5 s
        code = main(["dem", "sweep", "--frequencies", "1000", "--accelerations", "5",
                     "--fills", "25", "--cells", "1", "--cycles", "2", "--no-progress",
                     "--scheduler", address, "--store", str(store)])
    elapsed = time.perf_counter() - start
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and f"--scheduler {address}: {said}" in err[0], err
    assert "tcp://host:8786" in err[0] and "EiB" not in err[0], err
    # the 1.5 s limit and the CLI's own setup (a fraction of a second; 10 s for a loaded
    # machine), not the minutes of a hang
    assert elapsed < 1.5 + 10.0
    assert not store.exists()


def test_a_dask_worker_is_not_taken_for_the_scheduler_and_the_scheduler_is(tmp_path):
    """Refused by what the address answers as (its identity), not by where it listens."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        worker = next(iter(cluster.scheduler.workers))
        with pytest.raises(ParameterError, match=f"scheduler {worker}: a dask.distributed "
                                                 "Worker answered there, not a scheduler"):
            run_sweep(CASES[:1], CONFIG, store_path=tmp_path / "w.h5", scheduler=worker,
                      progress=False)
        assert not (tmp_path / "w.h5").exists()
        summary = run_sweep(CASES[:1], CONFIG, store_path=tmp_path / "s.h5",
                            scheduler=cluster.scheduler_address, progress=False)
    assert summary.completed == [run_key(CASES[0], CONFIG)]


#: Set once the scheduler is gone: the cases after the first wait for it
#: (:func:`_first_case_then_held`).
_HELD = threading.Event()


def _first_case_then_held(case, config, specimen=None):
    """:func:`~pidcore.dem.sweep.run_case`, every case but the first only once :data:`_HELD`
    is set, so that none of them can finish before the scheduler is gone however fast the
    machine is (a function of the module: dask pickles it, by reference)."""
    if case != CASES[0]:
        _HELD.wait(60)
    return run_case(case, config, specimen)


@pytest.mark.timeout(120)  # dask's client tries to reconnect for 30 s: fail, not wait
def test_a_scheduler_lost_mid_sweep_is_one_error_naming_it_and_the_runs_stored_are_kept(
        tmp_path, monkeypatch):
    """The dask scheduler killed after the first run was stored ended `pidcore dem sweep` with
    dask's FutureCancelledError traceback (scheduler-connection-lost) and its logged ERROR,
    exit 1, where a killed local worker is one line (exit 2) saying what is kept."""
    import contextlib
    import logging

    import pidcore.dem.sweep as sweep_module
    from pidcore.errors import SimulationError

    distributed = pytest.importorskip("distributed")
    _HELD.clear()
    monkeypatch.setattr(sweep_module, "run_case", _first_case_then_held)
    store = tmp_path / "s.h5"
    seen: list[str] = []
    # over TCP, as a real scheduler: the client's attempts to reconnect then fail as they do
    # on a killed one (refused), and dask logged their end
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                       protocol="tcp", dashboard_address=None)
    address = cluster.scheduler_address

    def lose_the_scheduler(outcome) -> None:
        seen.append(outcome.key)
        # it drops the client's connection as a killed one does
        cluster.sync(cluster.scheduler.close)

    # dask's loggers write to the stderr they found when imported (not the test's): their
    # records are read at the logger all of them hand theirs to
    logged: list[logging.LogRecord] = []
    catch = logging.Handler(logging.ERROR)
    catch.emit = logged.append
    logging.getLogger("distributed").addHandler(catch)
    try:
        with pytest.raises(SimulationError, match=f"^scheduler {address}: the connection to "
                                                  "the dask.distributed scheduler was lost.*"
                                                  "; the cases finished before are kept$"):
            run_sweep(CASES, CONFIG, store_path=store, scheduler=address, progress=False,
                      on_case=lose_the_scheduler)
    finally:
        logging.getLogger("distributed").removeHandler(catch)
        _HELD.set()
        # a cluster whose scheduler is closed waits out dask's 30 s for it to say so
        with contextlib.suppress(Exception):
            cluster.close(timeout=2)
    assert seen == [run_key(CASES[0], CONFIG)]
    stored = Store(store)
    assert stored.verify() == [] and list(stored.list_dem_runs()["case_key"]) == seen
    # no ERROR of dask's (its client's reconnection, cancelled) after the CLI's one line
    assert [record.getMessage() for record in logged] == []


#: Set once a case has started on a dask worker (:func:`_every_case_held`).
_STARTED = threading.Event()


def _every_case_held(case, config, specimen=None):
    """:func:`~pidcore.dem.sweep.run_case` once :data:`_HELD` is set: no case can finish
    before the scheduler is gone."""
    _STARTED.set()
    _HELD.wait(60)
    return run_case(case, config, specimen)


@pytest.mark.timeout(120)  # dask's client tries to reconnect for 30 s: fail, not wait
def test_a_scheduler_lost_before_any_case_finished_says_none_is_kept(tmp_path, monkeypatch):
    """The scheduler lost before any case finished said "the cases finished before are kept"
    though none had finished and nothing was stored."""
    import contextlib

    import pidcore.dem.sweep as sweep_module
    from pidcore.errors import SimulationError

    distributed = pytest.importorskip("distributed")
    _HELD.clear()
    _STARTED.clear()
    monkeypatch.setattr(sweep_module, "run_case", _every_case_held)
    store = tmp_path / "s.h5"
    seen: list[str] = []
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                       protocol="tcp", dashboard_address=None)
    address = cluster.scheduler_address

    def lose_the_scheduler() -> None:
        # once a case runs (the sweep is under way), as a killed scheduler drops it
        if _STARTED.wait(60):
            cluster.sync(cluster.scheduler.close)

    losing = threading.Thread(target=lose_the_scheduler, daemon=True)
    losing.start()
    try:
        with pytest.raises(SimulationError, match=f"^scheduler {address}: the connection to "
                                                  "the dask.distributed scheduler was lost.*"
                                                  "; no case had finished, so none is kept$"):
            run_sweep(CASES, CONFIG, store_path=store, scheduler=address, progress=False,
                      on_case=lambda outcome: seen.append(outcome.key))
    finally:
        _HELD.set()
        losing.join(60)
        with contextlib.suppress(Exception):
            cluster.close(timeout=2)
    assert seen == [] and not Store(store).list_dem_runs().shape[0]


def test_a_killed_pool_worker_is_one_error_not_a_traceback():
    """A DEM worker killed from outside (OOM killer, kill -9) ended `pidcore dem sweep` and
    `calibrate` with concurrent.futures' BrokenProcessPool traceback, exit 1."""
    import os

    from pidcore.dem.sweep import run_pooled
    from pidcore.errors import SimulationError

    finished: list = []
    # os._exit ends the worker process at once, as SIGKILL would (picklable by reference)
    # none finished: said so, not "the cases finished before it are kept"
    with pytest.raises(SimulationError, match="worker process ended abruptly .*; no case had "
                                              "finished, so none is kept$"):
        run_pooled(os._exit, [(9,), (9,)], workers=2, finish=finished.append)
    assert finished == []


def test_a_sweep_that_fails_after_some_cases_says_they_are_saved(tmp_path, monkeypatch, capsys):
    import pidcore.dem.sweep
    from pidcore.cli import main
    from pidcore.errors import SimulationError

    store = tmp_path / "s.h5"

    def first_then_fail(cases, config, *, store_path, **kwargs):
        Store(store_path).add_dem_run(run_key(cases[0], config), {"sdc": 0.1})
        raise SimulationError("a DEM worker process ended abruptly")

    monkeypatch.setattr(pidcore.dem.sweep, "run_sweep", first_then_fail)
    argv = ["dem", "sweep", "--frequencies", "1000", "--accelerations", "5,10", "--fills", "25",
            "--cells", "1", "--cycles", "10", "--no-progress", "--store", str(store)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].endswith(
        f"ended abruptly; 1 finished run(s) saved to {store}; re-run to resume"), err
    # nothing stored: the error as it was, with no word of saved runs
    monkeypatch.setattr(pidcore.dem.sweep, "run_sweep", lambda *a, **k: (_ for _ in ()).throw(
        SimulationError("refused")))
    assert main([*argv[:-1], str(tmp_path / "t.h5")]) == 2
    assert capsys.readouterr().err.strip() == "pidcore dem sweep: error: refused"


def test_a_run_keyed_otherwise_by_a_worker_is_refused_not_stored(tmp_path, monkeypatch):
    """A dask worker with another pidcore (another DEM code version) returns its run under
    another key: it was stored, the sweep listed the case as unfinished, and every re-run
    simulated it again."""
    import dataclasses

    import pidcore.dem.sweep
    from pidcore.errors import SimulationError

    real = pidcore.dem.sweep.run_case

    def other_code(case, config, specimen=None):
        outcome = real(case, config, specimen)
        return dataclasses.replace(outcome, key=outcome.key[:-10] + "0123456789")

    monkeypatch.setattr(pidcore.dem.sweep, "run_case", other_code)
    store = tmp_path / "s.h5"
    with pytest.raises(SimulationError, match="another pidcore than this one"):
        run_sweep(CASES[:1], CONFIG, store_path=store, workers=1, progress=False)
    assert not store.exists() or Store(store).list_dem_runs().empty


def test_a_run_another_sweep_stored_meanwhile_is_not_counted_or_simulated_again(tmp_path,
                                                                              monkeypatch):
    """Two sweeps on one store: the second said "N case(s) simulated" for runs the first had
    saved (its own save was skipped), and simulated cases the first had stored meanwhile."""
    import pidcore.dem.sweep as sweep_module

    store_path = tmp_path / "s.h5"
    real_run_case = sweep_module.run_case
    simulated = []

    def other_process_saves_first(case, config, specimen=None):
        # the "other sweep" finishes this case and the next one before this sweep saves
        simulated.append(case)
        outcome = real_run_case(case, config, specimen)
        for other in CASES[:2]:
            theirs = real_run_case(other, config, specimen)
            assert theirs.save_to(Store(store_path))
        return outcome

    monkeypatch.setattr(sweep_module, "run_case", other_process_saves_first)
    summary = run_sweep(CASES[:2], CONFIG, store_path=store_path, workers=1, progress=False)
    assert simulated == [CASES[0]]  # the second case was found stored before it was run
    assert not summary.completed  # this sweep saved nothing
    assert sorted(summary.skipped) == sorted(run_key(c, CONFIG) for c in CASES[:2])
    assert [c["status"] for c in summary.cases] == [sweep_module.STORED_MEANWHILE] * 2
    assert len(Store(store_path).list_dem_runs()) == 2


def test_pooled_workers_skip_a_run_stored_after_the_sweep_listed_its_cases(tmp_path,
                                                                          monkeypatch):
    """With several workers (the default) a second sweep simulated every case the first had
    saved since it listed the store; each worker now reads the store as its case starts."""
    import pidcore.dem.sweep as sweep_module

    store_path = tmp_path / "s.h5"
    run_sweep(CASES[:1], CONFIG, store_path=store_path, workers=1, progress=False)
    stamp = Store(store_path).list_dem_runs()["created_utc"].iloc[0]
    # the listing as it was before the other sweep saved CASES[0] (the workers, forked from
    # a clean server, read the real store)
    monkeypatch.setattr(sweep_module, "stored_run_key", lambda *args, **kwargs: None)
    returned = []  # what each worker sent back: a run it simulated, or the key it found
    real_pooled = sweep_module.run_pooled

    def spy(function, calls, *, workers, finish):
        def kept(outcome):
            returned.append(outcome)
            finish(outcome)
        real_pooled(function, calls, workers=workers, finish=kept)

    monkeypatch.setattr(sweep_module, "run_pooled", spy)
    summary = run_sweep(CASES[:2], CONFIG, store_path=store_path, workers=2, progress=False)
    # CASES[0] was not simulated again: its worker sent back the key it found stored
    assert sorted(o if isinstance(o, str) else o.key for o in returned) == sorted(
        run_key(c, CONFIG) for c in CASES[:2])
    assert run_key(CASES[0], CONFIG) in returned
    assert summary.completed == [run_key(CASES[1], CONFIG)]
    assert summary.skipped == [run_key(CASES[0], CONFIG)]
    assert [c["status"] for c in summary.cases] == [sweep_module.STORED_MEANWHILE,
                                                    "simulated"]
    runs = Store(store_path).list_dem_runs().set_index("case_key")
    assert runs.loc[run_key(CASES[0], CONFIG), "created_utc"] == stamp  # the first kept


@pytest.mark.parametrize(("arguments", "said"), [
    ({"workers": 0},  # ran on every core; `dem sweep --workers 0` is refused
     "workers: expected a positive number of processes, got 0"),
    ({"workers": 1.5}, "workers: expected a whole number, got 1.5"),  # a TypeError of range()
    ({"config": None},  # a TypeError of asdict() naming nothing
     "config: expected a DemConfig, got NoneType None (e.g. DemConfig(cells=2))"),
    ({"cases": LoadCase(500.0, 5.0, 50.0)},  # "'LoadCase' object is not iterable"
     "cases: expected a sequence of LoadCase, got one LoadCase; give [case]"),
    ({"cases": [(500.0, 5.0, 50.0)]},
     "cases: expected a LoadCase, got tuple (500.0, 5.0, 50.0) (e.g. [LoadCase(500.0, 5.0, "
     "50.0)])"),
])
def test_run_sweep_refuses_what_dem_sweep_refuses_before_the_store_is_touched(tmp_path,
                                                                             arguments, said):
    store = tmp_path / "dem.h5"
    call = {"cases": [LoadCase(500.0, 5.0, 50.0)], "config": DemConfig(cells=1),
            "store_path": store, "workers": 1, "progress": False, **arguments}
    with pytest.raises(ParameterError) as refused:
        run_sweep(**call)
    assert str(refused.value) == said
    assert not store.exists()
