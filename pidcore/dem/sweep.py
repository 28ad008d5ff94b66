"""Sweeps of DEM load cases: local process pool by default, dask.distributed on request.

A case whose run the store holds under another key (another fill of the same particle count
and seed: :func:`pidcore.dem.persist.stored_run_key`), or that repeats another case of the
sweep so, is not simulated again; :attr:`SweepSummary.cases` says so per case.

Every finished case is written to the store at once, in its own transaction, by the parent
process (the store's lock serialises writers, but one writer is simpler and faster). An
interrupted sweep therefore keeps every finished case, and a re-run skips them: the case key
holds every input that changes the result (load case, cells, seed, numerical options,
specimen, code version; :func:`pidcore.dem.persist.run_key`).
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager, nullcontext
from dataclasses import dataclass, field
from pathlib import Path

from .. import defaults
from ..constants import DriveDirection, ParticleMaterial
from ..errors import ParameterError, SimulationError, instance_of, whole_number
from ..interrupt import raise_if_stopped, stop_processes
from ..records import json_safe
from ..specimen import Specimen, fill_override_note, is_paper_coupon
from .persist import (
    dem_run_entry,
    load_dem_result,
    other_files_runs_note,
    own_run_keys,
    run_identity,
    run_key,
    run_key_case,
    save_dem_entry,
    stored_identities,
    stored_keys,
    stored_run_key,
)
from .simulate import DemConfig, LoadCase, simulate_load_case

#: Named grids. ``table3`` is the paper's Table 3: 4 frequencies x 3 accelerations x 4 fills.
GRIDS: dict[str, dict[str, tuple[float, ...]]] = {
    "table3": {
        "frequency_hz": (50.0, 100.0, 500.0, 1000.0),
        "acceleration_g": (1.0, 5.0, 10.0),
        "fill_percent": (25.0, 50.0, 75.0, 90.0),
    },
}


def grid_axes(grid: str = "table3") -> dict[str, tuple[float, ...]]:
    """The values of a named grid: ``frequency_hz``, ``acceleration_g``, ``fill_percent``."""
    if grid not in GRIDS:
        raise ParameterError(f"grid: unknown grid {grid!r}; expected one of {sorted(GRIDS)}")
    return GRIDS[grid]


def sweep_fills(specimen: Specimen | None, grid: str = "table3",
                fill_reference: str = "capacity") -> tuple[tuple[float, ...], str]:
    """The fills a sweep of ``specimen`` runs when none are given, and why, in words (``""``
    for the paper's coupon, whose sweep is ``grid``'s as it always was).

    A specimen file of one's own stating its fill (``count_per_cell`` or ``fill_percent``:
    :meth:`~pidcore.specimen.Specimen.stated_fill`) is swept at that fill alone, the one
    ``dem run`` and the app's DEM tab simulate without a fill: a sweep of a file stating 20
    particles per cell ran Table 3's 25, 50, 75 and 90 %, four times the runs asked for. The
    paper's coupon (which states no fill) keeps ``grid``'s fills, so the bundled Table 3 grid
    and its benchmark are unchanged; so does a file stating none, and the words say so.
    ``fill_reference``: the sweep's :attr:`~pidcore.dem.DemConfig.fill_reference`, in which
    the stated fill is given (the same particles per cell in either).
    """
    grid_fills = grid_axes(grid)["fill_percent"]
    shown = ", ".join(f"{f:g}" for f in sorted(grid_fills))
    if specimen is None or specimen.is_paper():
        return grid_fills, ""
    stated = specimen.stated_fill(fill_reference)
    if stated is None:
        if is_paper_coupon(specimen.name):
            return grid_fills, ""  # the paper's coupon with another k_t model: its grid
        return grid_fills, (f"fills {shown} % are grid {grid}'s: specimen {specimen.name} "
                            "states no fill (count_per_cell or fill_percent); give "
                            "fills_percent to choose")
    return (stated[0],), (f"fill {stated[0]:.6g} % is the one specimen {specimen.name} "
                          f"states ({stated[1]}), as a run of it without a fill simulates; "
                          f"give fills_percent for others (grid {grid}'s: {shown} %)")


def cross_cases(frequencies_hz: Iterable[float], accelerations_g: Iterable[float],
                fills_percent: Iterable[float], *, material: ParticleMaterial = "acrylic",
                direction: DriveDirection = "z") -> list[LoadCase]:
    """Every combination of the values, each once, ordered like the paper's Table 3
    (frequency, then acceleration, then fill, each ascending)."""
    axes = {"frequency": sorted(set(map(float, frequencies_hz))),
            "acceleration": sorted(set(map(float, accelerations_g))),
            "fill": sorted(set(map(float, fills_percent)))}
    for name, values in axes.items():
        if not values:
            raise ParameterError(f"choose at least one {name}")
    return [LoadCase(f, a, p, material, direction) for f in axes["frequency"]
            for a in axes["acceleration"] for p in axes["fill"]]


def grid_cases(grid: str = "table3", *, material: ParticleMaterial = "acrylic",
               direction: DriveDirection = "z") -> list[LoadCase]:
    """Load cases of a named grid, ordered like the paper's Table 3 (f, a, fill)."""
    g = grid_axes(grid)
    return cross_cases(g["frequency_hz"], g["acceleration_g"], g["fill_percent"],
                       material=material, direction=direction)


@dataclass(frozen=True)
class CaseOutcome:
    """What a worker sends back: plain data, cheap to pickle, ready for the store."""

    key: str
    record: dict
    arrays: dict
    parameters: dict
    units: dict

    def save_to(self, store) -> bool:
        """Add this run to ``store`` unless stored already (:func:`~.persist.save_dem_entry`);
        True if this call added it (False: another process stored it meanwhile)."""
        return save_dem_entry(store, self.key, {"record": self.record, "arrays": self.arrays,
                                                "parameters": self.parameters,
                                                "units": self.units})


def run_case(case: LoadCase, config: DemConfig,
             specimen: Specimen | None = None) -> CaseOutcome:
    """Simulate one case (in a worker) and package it for the store."""
    return CaseOutcome(run_key(case, config, specimen),
                       **dem_run_entry(simulate_load_case(case, config, specimen=specimen)))


#: Modules a DEM worker process needs, imported once by the fork server (see
#: :func:`dem_process_context`).
_WORKER_MODULES = ["pidcore.dem.simulate", "pidcore.dem.persist", "pidcore.dem.sweep"]


def dem_process_context():
    """The :mod:`multiprocessing` context for processes that run DEM cases.

    Never ``fork`` from the calling process: forking a process that has started threads
    (Numba's threading layer, a Streamlit server, a thread pool) is unsafe. Where the
    platform has it, a fork *server*: one clean process started on first use that imports
    the DEM modules once and forks every worker from itself, so a worker starts in
    milliseconds instead of re-importing numpy, scipy, pandas and numba (~1 s each time);
    elsewhere ``spawn``. Workers load the kernels from Numba's disk cache. Note that a fork
    server keeps the environment it was started with.
    """
    import multiprocessing

    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(_WORKER_MODULES)
    _start_fork_server_deaf_to_ctrl_c()
    return context


def _start_fork_server_deaf_to_ctrl_c() -> None:
    """Start the fork server (if not yet running) with SIGINT blocked, so that it and every
    process it forks never see Ctrl-C: the parent stops them (:func:`run_pooled`).

    A terminal's Ctrl-C goes to the whole process group. A worker still starting up when it
    lands printed ``KeyboardInterrupt`` from inside multiprocessing's bootstrap, before any
    initializer could ignore it. A blocked signal stays blocked across the fork server's
    fork/exec and its forks, so there is no such window. Blocking (not ignoring) in the
    calling thread for these few milliseconds loses nothing: a Ctrl-C that comes meanwhile is
    delivered when the mask is put back. A fork server started earlier by other code is left
    as it is.
    """
    import signal
    from multiprocessing import forkserver, resource_tracker

    # the fork server starts the resource tracker first, which unblocks SIGINT when it has
    # started it (resource_tracker.ensure_running): started before the block, it is left as is
    resource_tracker.ensure_running()
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        forkserver.ensure_running()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def _exit_with(pid: int) -> None:
    """End this process as soon as process ``pid`` has ended (a daemon thread's loop).

    ``os.pidfd_open`` (Linux): the descriptor turns readable when the process exits, a zombie
    not yet reaped included, which a probe of the pid by ``os.kill(pid, 0)`` takes for alive.
    Elsewhere that probe, once a second.
    """
    import select

    try:
        fd = os.pidfd_open(pid)
    except ProcessLookupError:
        os._exit(1)
    except (AttributeError, OSError):  # no pidfd: another OS, or a kernel before 5.3
        while True:
            time.sleep(1.0)
            try:
                os.kill(pid, 0)
            except ProcessLookupError:
                os._exit(1)
            except OSError:
                pass  # alive, only not ours to signal
    select.select([fd], [], [])
    os._exit(1)


def init_dem_worker(parent_pid: int | None = None) -> None:
    """Set up a process that runs DEM cases (sweeps, calibration design runs, the app's jobs).

    One kernel thread: the parallelism is across cases, threads inside each would
    oversubscribe the cores. Ctrl-C ignored: the parent terminates its workers on an
    interrupt (:func:`run_pooled`), which stops a case at once, even inside a Numba kernel;
    a worker that handled Ctrl-C itself printed a traceback when the signal came while it
    waited for work (``spawn`` start-up; with the fork server SIGINT is already blocked).

    ``parent_pid``: the process that owns the pool; the worker ends when it ends. A parent
    killed outright (``kill -9``, the out-of-memory killer) stops no worker: each waited for
    work forever (it holds both ends of the pool's call queue, so it never reads its end),
    and kept the fork server and the killed command's stdout and stderr open, so that a
    caller reading them to their end (``$(pidcore dem sweep ...)``, a test harness) hung.
    """
    import multiprocessing
    import signal
    import threading

    import numba

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if parent_pid is not None:
        threading.Thread(target=_exit_with, args=(parent_pid,), daemon=True,
                         name="pidcore-exit-with-parent").start()
    # Numba makes a named (file-backed) process lock when the start method contains "fork",
    # "forkserver" included; a worker terminated on Ctrl-C leaves it behind, and the resource
    # tracker warns of a "leaked semaphore" after the CLI's one line. Each worker makes its
    # own, so it guards nothing between workers; a worker starts no process of its own, so
    # its default start method is free to change.
    multiprocessing.set_start_method("spawn", force=True)
    numba.set_num_threads(1)


#: Seconds between two looks at a pool's stop event (:func:`run_pooled`): a Cancel or an
#: exit stops the workers this soon, a fraction of the "few seconds" a user waits.
STOP_POLL_S = 0.1


def run_pooled(function: Callable, calls: Sequence[tuple], *, workers: int,
               finish: Callable[[object], None],
               stop: threading.Event | None = None) -> None:
    """``function(*call)`` for each of ``calls`` in up to ``workers`` DEM processes; ``finish``
    (in this process) gets each result as it comes, in the order they finish.

    On Ctrl-C or a failed call the workers are terminated and waited for before the exception
    goes on: the results already given to ``finish`` are all that is kept. Leaving them
    running (``shutdown(wait=False)``) let this process exit first; a worker still starting
    then found the pool's semaphores removed and printed ``FileNotFoundError`` from
    multiprocessing's ``forkserver.py`` after the CLI's one line.

    ``stop``: for a pool run in a background thread, which no Ctrl-C reaches (the app's
    calibration). Once it is set the workers are stopped the same way, their running calls
    discarded, no result is given to ``finish`` any more, and
    :class:`~pidcore.interrupt.StopRequested` is raised; it is looked at every
    :data:`STOP_POLL_S`. The pool is shut down here, in its own thread, and nowhere else.
    """
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    from .. import interrupt

    raise_if_stopped(stop, _STOPPED)  # before any worker starts
    pool = ProcessPoolExecutor(max_workers=min(workers, len(calls)),
                               mp_context=dem_process_context(),
                               initializer=init_dem_worker, initargs=(os.getpid(),))
    finished = 0
    try:
        # submit() starts the workers: a Ctrl-C inside Process.start() could leave a worker
        # forked but not yet in the pool's table, out of reach of _stop_pool; held back until
        # every submit is done (milliseconds)
        with interrupt.deferred():
            futures = [pool.submit(function, *call) for call in calls]
        interrupt.raise_if_interrupted()
        for future in _finished(futures, stop):
            finish(future.result())
            finished += 1
    except BrokenProcessPool:
        # a worker killed from outside (the kernel's OOM killer, kill -9): a traceback of
        # concurrent.futures and exit 1 said neither what happened nor what was kept
        _stop_pool(pool)
        raise SimulationError(
            "a DEM worker process ended abruptly (killed, or out of memory?) while running "
            f"a case; {_kept(finished)}") from None
    except BaseException:
        _stop_pool(pool)
        raise
    pool.shutdown()


def _kept(finished: int) -> str:
    """What a sweep ended by a lost worker or scheduler keeps, ``finished`` cases having been
    handed on before: "the cases finished before are kept" said so where none had."""
    return ("the cases finished before are kept" if finished else
            "no case had finished, so none is kept")


#: What a stop says (:func:`pidcore.interrupt.raise_if_stopped`).
_STOPPED = "the DEM runs were stopped; the runs finished before are kept"


def _finished(futures: list, stop: threading.Event | None) -> Iterator:
    """``futures`` as they finish; with ``stop``, :class:`~pidcore.interrupt.StopRequested`
    once it is set (a finished one is then not handed on: nothing is saved after a stop)."""
    from concurrent.futures import FIRST_COMPLETED, as_completed, wait

    if stop is None:
        yield from as_completed(futures)
        return
    pending = set(futures)
    while pending:
        done, pending = wait(pending, timeout=STOP_POLL_S, return_when=FIRST_COMPLETED)
        for future in done:
            raise_if_stopped(stop, _STOPPED)
            yield future
        raise_if_stopped(stop, _STOPPED)


def _stop_pool(pool) -> None:
    """Terminate a ProcessPoolExecutor's workers and wait until they are gone."""
    # The executor has no public way to stop running work before Python 3.14
    # (terminate_workers); its process table is read before shutdown() clears it.
    processes = list((getattr(pool, "_processes", None) or {}).values())
    # stopped before the shutdown: it waits for the calls its workers are running
    stop_processes(processes)
    pool.shutdown(wait=True, cancel_futures=True)


#: Status of a case another process (a second sweep on the same store) stored while this
#: sweep ran: this sweep's run of it, if it made one, was not saved.
STORED_MEANWHILE = "stored meanwhile by another process"
#: How a sweep got each case's run (:attr:`SweepSummary.cases`).
SWEEP_CASE_STATUSES = ("simulated", "already stored",
                       "same simulation as a stored run",
                       "same simulation as another case of this sweep",
                       STORED_MEANWHILE)
#: Result fields of each case in :meth:`SweepSummary.to_dict`, named (units as suffixes) as
#: ``pidcore dem run --json`` names them, read from the stored run.
SWEEP_CASE_FIELDS = ("sdc", "sdc_stderr", "sdc_stderr_dof", "loss_factor", "particles_per_cell",
                     "cells_simulated", "seed", "steady_detected",
                     # the README's "every run reports an energy balance": a sweep's did not
                     "energy_balance_error",
                     # whose run it is, as stored: --json named no specimen, so a sweep's
                     # document could not tell the runs of two files of one name apart
                     "specimen_name", "specimen_sha256")


@dataclass
class SweepSummary:
    """What a sweep did: keys run now, keys skipped as already stored, wall time, and per case
    its run's key, how it was got and its stored results.

    ``cases``: one dict per case, in the order of the ``cases`` given to :func:`run_sweep`;
    ``pidcore dem sweep`` and the app build them with :func:`cross_cases`, so that order is
    Table 3's (frequency, then acceleration, then fill, each ascending and each value once),
    not the order the values were typed in. Of two fills that round to one particle count
    (neither stored yet) the first in that order (the lower fill) is simulated (status
    ``simulated``); the other says ``same simulation as another case of this sweep`` and
    names the simulated case's ``store_key``, its ``stored_fill_percent`` that case's fill.
    Each dict holds
    ``frequency_hz``, ``acceleration_g``,
    ``fill_percent`` (as asked), ``material``, ``direction``, ``store_key``, ``status`` (one of
    :data:`SWEEP_CASE_STATUSES`) and, once the run is stored, ``stored_fill_percent`` (the
    fill its run is stored with: another where the same simulation was found under another
    fill), :data:`SWEEP_CASE_FIELDS` and ``notes``, the stored run's
    :attr:`~pidcore.dem.result.DemResult.notes` (those ``pidcore dem run`` prints of it).
    """

    completed: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    wall_s: float = 0.0
    store_path: str = ""
    cases: list[dict] = field(default_factory=list)
    #: What a reader of the runs should know: the fills given override the one the specimen
    #: states (:func:`pidcore.specimen.fill_override_note`).
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        """The JSON document of ``pidcore dem sweep --json``, with ``units`` naming the unit of
        every number in it (as ``dem run --json`` and ``calibrate --json`` do: a case's
        ``sdc``, ``loss_factor`` and ``particles_per_cell`` named none)."""
        from .result import UNITS

        cases = [dict(c) for c in self.cases]
        # the seed is a name of the packings, not a quantity: no unit, as in dem run --json
        units = {**UNITS, "wall_s": "s", "stored_fill_percent": "%"}
        named = {name for case in cases for name in case} | {"wall_s"}
        return {"completed": len(self.completed), "skipped": len(self.skipped),
                "wall_s": self.wall_s, "store": self.store_path, "cases": cases,
                "notes": list(self.notes),
                "units": {name: units[name] for name in sorted(named) if name in units}}

    def fill_results(self, store) -> None:
        """Read each case's results from ``store`` (the runs as stored)."""
        if not self.cases or not store.path.exists():
            return
        runs = store.list_dem_runs()
        if runs.empty:
            return
        by_key = runs.set_index("case_key")
        notes: dict[str, list[str]] = {}  # by key: two cases of one simulation read it once
        for case in self.cases:
            key = case["store_key"]
            if key not in by_key.index:
                continue  # not finished (interrupted)
            row = by_key.loc[key]
            case["stored_fill_percent"] = float(row["fill_percent"])
            for name in SWEEP_CASE_FIELDS:
                case[name] = json_safe(row.get(name))
            if case.get("steady_detected") is not None:  # the store reads a bool back as 0/1
                case["steady_detected"] = bool(case["steady_detected"])
            # derived from the whole run, not stored: a steady window rounded up past
            # --cycles was said by `dem run` of the same run and by no sweep
            if key not in notes:
                notes[key] = list(load_dem_result(store.get_dem_run(key)).notes)
            case["notes"] = list(notes[key])


def run_sweep(cases: Sequence[LoadCase], config: DemConfig, *,
              store_path: str | os.PathLike, workers: int | None = None,
              scheduler: str | None = None, progress: bool = True,
              on_case: Callable[[CaseOutcome], None] | None = None,
              specimen: Specimen | None = None) -> SweepSummary:
    """Run every case not yet in the store and save each one as soon as it finishes.

    Parameters
    ----------
    cases : sequence of LoadCase
    config : DemConfig
        Numerical settings shared by all cases (cells, seed, time step, ...).
    store_path : path
        HDF5 store; finished cases found there are skipped (resume).
    workers : int, optional
        Local processes (default: all cores). Refused with ``scheduler``
        (:func:`check_workers_or_scheduler`).
    scheduler : str, optional
        Address of a dask.distributed scheduler (``tcp://host:8786``); needs the
        ``distributed`` extra. Refused (:class:`ParameterError`) unless a scheduler answers
        there within dask's connect timeout and ``DEM_SCHEDULER_ANSWER_TIMEOUT_S`` more.
    progress : bool
        tqdm bar on stderr.
    on_case : callable, optional
        Called with each finished :class:`CaseOutcome` after it is stored (a library caller's
        own progress or bookkeeping; the CLI counts saved runs from the store itself).
    specimen : Specimen, optional
        What every case simulates (:mod:`pidcore.specimen`); the paper's coupon by default.
    """
    from ..store import Store

    # before the store is read, as simulate_load_case and `dem sweep` refuse them: a config of
    # None or a fraction of a worker were TypeErrors naming nothing, workers=0 ran on every
    # core where `dem sweep --workers 0` is refused
    if isinstance(cases, LoadCase):
        raise ParameterError("cases: expected a sequence of LoadCase, got one LoadCase; give "
                             "[case]")
    cases = list(cases)
    for case in cases:
        instance_of("cases", case, LoadCase, hint="e.g. [LoadCase(500.0, 5.0, 50.0)]")
    instance_of("config", config, DemConfig, hint="e.g. DemConfig(cells=2)")
    instance_of("specimen", specimen, (Specimen, type(None)),
                hint="read a file with pidcore.specimen.load_specimen(path)")
    if workers is not None and whole_number("workers", workers) < 1:
        raise ParameterError(f"workers: expected a positive number of processes, got {workers}")
    check_workers_or_scheduler(workers, scheduler)
    start = time.perf_counter()
    store = Store(store_path)
    summary = SweepSummary(store_path=str(Path(store_path)))
    overridden = fill_override_note(specimen, [case.fill_percent for case in cases],
                                    config.fill_reference)
    if overridden:
        summary.notes.append(overridden)
    todo: list[tuple[LoadCase, str]] = []
    identities = stored_identities(store)  # read once, not once per case
    planned: dict[str, str] = {}  # simulation identity -> key of a case to simulate
    for case in cases:
        key = run_key(case, config, specimen)
        # its own key, the key a 0.1 store holds it by, or a stored run of the same simulation
        found = stored_run_key(store, case, config, specimen, identities=identities)
        record = {"frequency_hz": case.frequency_hz, "acceleration_g": case.acceleration_g,
                  "fill_percent": case.fill_percent, "material": case.material,
                  "direction": case.direction}
        if found is not None:
            status = ("already stored" if found in own_run_keys(case, config, specimen)
                      else "same simulation as a stored run")
            summary.skipped.append(found)
            summary.cases.append({**record, "store_key": found, "status": status})
            continue
        # another fill of the same particle count and seed is the same simulation
        identity = run_identity(case, config, specimen)
        if identity in planned:
            summary.cases.append({**record, "store_key": planned[identity],
                                  "status": "same simulation as another case of this sweep"})
        else:
            planned[identity] = key
            todo.append((case, key))
            summary.cases.append({**record, "store_key": key, "status": "simulated"})
    # an edited specimen file (another hash, the same name) reuses none of its stored runs:
    # said, as `dem sweep` says it before the run, to a library caller and in --json
    other_files = other_files_runs_note(store_path, [case for case, _ in todo], config,
                                        specimen)
    if other_files:
        summary.notes.append(other_files)
    bar = None
    if todo:
        store.check_writable()  # before the simulations, not at the first commit
        if scheduler:
            _check_scheduler(scheduler)  # before the bar: a refusal is its one line
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(cases), initial=len(cases) - len(todo), unit="case",
                   desc="DEM sweep")

    asked = {key for _, key in todo}

    def finish(outcome: CaseOutcome) -> None:
        if outcome.key not in asked:
            from .. import __version__

            # a dask worker with another pidcore (DEM code version, key rules) keys its run
            # otherwise: stored, the sweep listed its case as unfinished and every re-run
            # simulated it again
            raise SimulationError(
                f"a worker returned run {outcome.key}, which this sweep did not ask for (it "
                f"asked for {len(asked)} run(s) such as {min(asked)}): the workers run "
                f"another pidcore than this one ({__version__}); install the same on them")
        if outcome.save_to(store):
            summary.completed.append(outcome.key)
        else:
            _stored_meanwhile(summary, outcome.key)
        if bar is not None:
            bar.update(1)
            bar.set_postfix_str(run_key_case(outcome.key))
        if on_case is not None:
            on_case(outcome)

    def finish_or_skip(outcome: CaseOutcome | str) -> None:
        if isinstance(outcome, str):  # stored by another process before it was simulated
            _stored_meanwhile(summary, outcome)
            if bar is not None:
                bar.update(1)
        else:
            finish(outcome)

    try:
        if todo and scheduler:
            _run_dask(todo, config, scheduler, finish, specimen)
        elif todo:
            _run_local(todo, config, workers, finish_or_skip, specimen, store_path)
    finally:
        if bar is not None:
            bar.close()
        summary.wall_s = time.perf_counter() - start
    summary.fill_results(store)
    return summary


def check_workers_or_scheduler(workers: int | None, scheduler: str | None) -> None:
    """Refuse a number of local ``workers`` given with a ``scheduler``: the cluster's workers
    run the cases, and the number was ignored without a word (``dem sweep --workers 2
    --scheduler ADDR``)."""
    if workers is not None and scheduler:
        raise ParameterError(f"workers {workers}: a number of local processes, which a sweep "
                             f"on the dask.distributed scheduler {scheduler} does not use (its "
                             "cluster's workers run the cases); give one of them, not both")


def _stored_meanwhile(summary: SweepSummary, key: str) -> None:
    """Count ``key`` as found stored (by another process while this sweep ran), not as
    simulated and saved by this sweep."""
    summary.skipped.append(key)
    for case in summary.cases:
        if case["store_key"] == key and case["status"] == "simulated":
            case["status"] = STORED_MEANWHILE


def run_case_unless_stored(case: LoadCase, config: DemConfig, specimen: Specimen | None,
                           store_path: str | os.PathLike, key: str) -> CaseOutcome | str:
    """:func:`run_case`, or ``key`` where the store holds that run already: another process
    (a second sweep on the same store) saved it since this sweep listed what to run, and it
    is not simulated twice. Read as the case starts (in its worker)."""
    if stored_keys(store_path, [key]):
        return key
    return run_case(case, config, specimen)


def _run_local(todo: Iterable[tuple[LoadCase, str]], config: DemConfig, workers: int | None,
               finish: Callable[[CaseOutcome | str], None], specimen: Specimen | None,
               store_path: str | os.PathLike) -> None:
    todo = list(todo)
    workers = workers or os.cpu_count() or 1  # a given number is checked by run_sweep
    calls = [(case, config, specimen, store_path, key) for case, key in todo]
    if workers == 1 or len(todo) == 1:
        for call in calls:
            finish(run_case_unless_stored(*call))
        return
    # Ctrl-C or a failed case stops the workers; finished cases are already stored
    run_pooled(run_case_unless_stored, calls, workers=workers, finish=finish)


#: How a ``--scheduler`` refusal names what it expected.
_EXPECTED_SCHEDULER = ("expected the address of a running scheduler, e.g. tcp://host:8786 (a "
                       "scheduler's usual port; 8787 is usually its dashboard, which speaks "
                       "HTTP)")


def _check_scheduler(scheduler: str) -> None:
    """Refuse ``scheduler`` unless a dask.distributed scheduler answers there as one.

    ``Client(address)`` waits for the answer to its handshake without a limit: a port that
    accepts and never replies (an HTTP server reading a request line) hung the sweep for ever,
    and an HTTP reply (a scheduler's dashboard) came out as numpy's "Unable to allocate 3.07
    EiB" (dask read "HTTP/1.0" as a count of frames). Asked here, as the Client connects, for
    its identity within dask's connect timeout and ``DEM_SCHEDULER_ANSWER_TIMEOUT_S`` more.

    Raises
    ------
    ParameterError
        One line naming the address and what was expected.
    """
    try:
        import asyncio

        import dask
        from dask.utils import parse_timedelta
        from distributed import Security
        from distributed.comm.core import FatalCommClosedError
        from distributed.core import rpc
    except ImportError:
        raise ParameterError("scheduler: needs dask.distributed: "
                             "pip install 'pidcore[distributed]'") from None
    connect_s = parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"),
                                default="seconds")
    limit = connect_s + defaults.DEM_SCHEDULER_ANSWER_TIMEOUT_S
    # the TLS settings of dask's configuration, as the Client takes them
    connection_args = Security().get_connection_args("client")

    async def identity() -> object:
        async with rpc(scheduler, connection_args=connection_args) as remote:
            return await remote.identity()

    outcome: dict[str, object] = {}

    def ask() -> None:
        # a thread and event loop of its own: a caller's running loop (a notebook's) is
        # left alone, as the Client leaves it
        try:
            outcome["identity"] = asyncio.run(asyncio.wait_for(identity(), limit))
        except BaseException as exc:  # noqa: BLE001 - every failure is the caller's one line
            outcome["error"] = exc

    thread = threading.Thread(target=ask, name="pidcore-scheduler-probe", daemon=True)
    thread.start()
    thread.join(limit + 5.0)  # the cancelled probe's own clean-up, not waited for without end
    error = outcome.get("error")
    # dask's connect retries until its timeout and then raises a plain OSError (refused, no
    # such host); a bad address is a ValueError, tls:// without a TLS configuration a
    # TypeError, a failed TLS handshake fatal: dask's words say which
    if type(error) is OSError or isinstance(error, (ValueError, TypeError,
                                                    FatalCommClosedError)):
        raise _cannot_connect(scheduler, error)
    if thread.is_alive() or isinstance(error, asyncio.TimeoutError):
        raise ParameterError(f"scheduler {scheduler}: the connection was accepted but no "
                             f"dask.distributed scheduler answered within {limit:g} s; "
                             f"{_EXPECTED_SCHEDULER}")
    answer = outcome.get("identity")
    kind = answer.get("type") if isinstance(answer, dict) else None
    # after the connection, anything (MemoryError for an HTTP reply, the stream closed, an
    # error reply) is something else answering
    if error is not None or not isinstance(kind, str):
        raise ParameterError(f"scheduler {scheduler}: something other than a dask.distributed "
                             f"scheduler answered there (an HTTP server?); "
                             f"{_EXPECTED_SCHEDULER}")
    if kind != "Scheduler":
        raise ParameterError(f"scheduler {scheduler}: a dask.distributed {kind} answered "
                             f"there, not a scheduler; {_EXPECTED_SCHEDULER}")


def _cannot_connect(scheduler: str, error: BaseException) -> ParameterError:
    """The one line of a connection to ``scheduler`` that failed, in dask's words."""
    return ParameterError(f"scheduler {scheduler}: cannot connect to a dask.distributed "
                          f"scheduler there ({' '.join(str(error).split())}); "
                          f"{_EXPECTED_SCHEDULER}")


def _run_dask(todo: Iterable[tuple[LoadCase, str]], config: DemConfig, scheduler: str,
              finish: Callable[[CaseOutcome], None], specimen: Specimen | None) -> None:
    from distributed import Client, as_completed  # there: _check_scheduler asked it
    from distributed.client import FutureCancelledError
    from distributed.comm.core import CommClosedError

    try:
        client = Client(scheduler)
    # refused or timed out (OSError), a bad address (ValueError), and whatever else the
    # connection raises: tls:// without a TLS configuration is a TypeError, which came out
    # as a traceback
    except Exception as exc:  # noqa: BLE001 - every failure to connect is one line
        raise _cannot_connect(scheduler, exc) from None
    lost = False
    try:
        futures = [client.submit(run_case, case, config, specimen, key=f"pidcore-{key}",
                                 pure=False)
                   for case, key in todo]
        finished = 0
        try:
            for future in as_completed(futures):
                finish(future.result())
                finished += 1
        except (FutureCancelledError, CommClosedError) as exc:
            if not _connection_lost(client, exc):
                client.cancel(futures)
                raise
            # the scheduler stopped (killed, its machine gone) or the network failed: dask
            # cancels every future with a two-line reason, which came out as a 65-line
            # traceback and exit 1 saying nothing of the runs already stored
            lost = True
            raise SimulationError(
                f"scheduler {scheduler}: the connection to the dask.distributed scheduler "
                "was lost while the sweep ran (the scheduler stopped, or the network "
                f"failed?); {_kept(finished)}") from None
        except BaseException:
            client.cancel(futures)
            raise
    finally:
        # with the connection lost, closing ends the client's attempts to reconnect, which
        # dask logs as an ERROR (asyncio's CancelledError with its traceback, or "Failed to
        # reconnect") after the one line
        with _distributed_silenced() if lost else nullcontext():
            client.close()


def _connection_lost(client, error: BaseException) -> bool:
    """Whether ``error``, raised by a future of ``client``, is the lost connection to its
    scheduler (dask's reason ``scheduler-connection-lost``, or the client no longer running),
    not a cancellation of one run by someone else."""
    return (getattr(error, "reason", None) == "scheduler-connection-lost"
            or getattr(client, "status", "running") != "running")


@contextmanager
def _distributed_silenced() -> Iterator[None]:
    """Drop every record of dask.distributed's loggers meanwhile (each set its own level, so
    the parent's level does not reach them)."""
    import logging

    loggers = [logging.getLogger(name) for name in list(logging.root.manager.loggerDict)
               if name == "distributed" or name.startswith("distributed.")]
    was = [logger.disabled for logger in loggers]
    for logger in loggers:
        logger.disabled = True
    try:
        yield
    finally:
        for logger, disabled in zip(loggers, was, strict=True):
            logger.disabled = disabled
