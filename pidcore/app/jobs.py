"""DEM jobs of the app: run outside Streamlit's script runs, cancellable, each saved as it ends.

Streamlit reruns the page script on every click, so a computation inside a script run is
interrupted or repeated by the next click. Here cases run in a worker thread owned by a
module-level registry (one :class:`DemJobRunner` per store, living as long as the server
process); the page only submits, cancels and reads snapshots. Each case runs in a process of
its own (:func:`pidcore.dem.sweep.dem_process_context`), so *Cancel* terminates it at once (a
Numba kernel cannot be interrupted from inside); its result comes back through a pipe and the
worker thread saves it to the store in its own transaction, so a killed case never leaves a
half-written store.

A case is never started twice: a submission is dropped when the same run (same store key: load
case and every numerical setting) is queued, running, or already in the store, and a case that
is the same simulation as another (a fill rounding to the same particle count:
:func:`pidcore.dem.persist.run_identity`) is not run again.

The job table outlives the server process: the runner keeps it in a JSON journal beside the
store (``<store>.jobs.json``, replaced atomically on every change of state). Each job there
names its owner (:class:`JournalOwner`: host, process id and start time of the app server, and
its runner), and every change re-reads the journal under a lock file
(``<store>.jobs.json.lock``) and keeps the entries of the other owners, so two app servers on
one store share the journal. A job whose owner still runs is shown as that server wrote it;
one whose owner stopped or crashed (no such process, or another process under a reused id) is
taken over: a job still queued or running comes back as :data:`INTERRUPTED_STATE`, nothing
saved, ready to run again (:meth:`DemJobRunner.resubmit_interrupted`); finished jobs are listed
as they were.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import os
import re
import secrets
import socket
import threading
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from .. import defaults
from ..atomic_files import write_atomically
from ..compare.align import PACKING_RATIO_COLUMN
from ..errors import ParameterError, PidcoreError, StoreError, clipped
from ..interrupt import TERMINATE_GRACE_S, stop_processes
from .vocabulary import page_terms

if TYPE_CHECKING:  # pragma: no cover - for the hints; the functions import them where used
    from ..dem.simulate import DemConfig
    from ..loadcase import LoadCase
    from ..specimen import Specimen

try:  # POSIX: the journal's read-modify-write is exclusive between app servers
    import fcntl
except ImportError:  # pragma: no cover - Windows: no exclusion (one server per store there)
    fcntl = None

#: Job states, in the order a job passes through them.
JOB_STATES = ("queued", "running", "saved", "in store", "same run", "cancelled", "failed",
              "interrupted", "resubmitted")
#: State of a job that was queued or running when the app stopped (read from the journal):
#: nothing of it was saved; :meth:`DemJobRunner.resubmit_interrupted` runs it again.
INTERRUPTED_STATE = "interrupted"
#: State of an interrupted job once *Resubmit interrupted* submitted it again (its message
#: names the new job): not "cancelled", which no one asked for.
RESUBMITTED_STATE = "resubmitted"
#: The journal of a store's jobs: ``<store>`` + this suffix, beside the store.
JOURNAL_SUFFIX = ".jobs.json"
#: Layout version written into the journal.
_JOURNAL_VERSION = 1
#: State of a job that is the same simulation as another job queued or running (another fill
#: rounding to the same particle count): not run, the other job's run is its run.
SAME_RUN_STATE = "same run"
#: A journal owner's recorded process start time and the running process's may differ by
#: this much and still be the same process, s (both are boot time + start ticks; a process
#: that reused the id starts later than that).
_START_TOLERANCE_S = 1.0
#: Runners of this process (:attr:`JournalOwner.runner`): runners live as long as the process.
_LIVE_RUNNERS: set[str] = set()
#: Seconds a runner waits for the journal's lock file before it goes on without it (a
#: journal change takes milliseconds; a holder this long hangs).
JOURNAL_LOCK_WAIT_S = 10.0
#: Seconds between checks of the running case (progress, cancel).
_POLL_S = 0.05
#: Least wall seconds between two reports of the settle's progress by a worker (a report per
#: kernel call would be thousands a second).
_SETTLE_REPORT_S = 0.5


@dataclass
class DemJob:
    """One DEM case submitted to the runner (mutated by the worker thread only)."""

    job_id: str
    case: object
    config: object
    run_key: str
    specimen: object = None
    state: str = "queued"
    submitted: float = field(default_factory=time.time)
    started: float | None = None
    finished: float | None = None
    cycles_done: int = 0
    cycles_expected: int = 0
    #: Simulated seconds of the bed's settle so far, told before the first block of cycles
    #: (that phase takes seconds to tens of seconds: "starting" said nothing meanwhile).
    settled_s: float = 0.0
    message: str = ""
    #: The job that runs this one's simulation (state :data:`SAME_RUN_STATE`), else "".
    same_as: str = ""
    #: The other app server running this job (``"pid 812 on host lab3"``); "": this one.
    server: str = ""

    def elapsed_s(self, now: float | None = None) -> float:
        """Seconds the case has run (0 while queued)."""
        if self.started is None:
            return 0.0
        return (self.finished or now or time.time()) - self.started

    def fraction(self) -> float:
        """Fraction of the expected cycles done, 0..1 (1 once saved)."""
        if self.state in ("saved", "in store"):
            return 1.0
        if self.cycles_expected <= 0:
            return 0.0
        return min(1.0, self.cycles_done / self.cycles_expected)

    def eta_s(self, now: float | None = None) -> float | None:
        """Seconds left, extrapolated from the cycles done so far (None before any block)."""
        if self.state != "running" or self.cycles_done <= 0:
            return None
        f = self.fraction()
        return self.elapsed_s(now) * (1.0 - f) / f if f > 0 else None

    def specimen_label(self) -> str:
        """The job's specimen as the DEM runs table names it (``"steel_6mm_b [3e945a]"``;
        ``"paper_coupon"`` for the paper's: :func:`pidcore.compare.specimens.specimen_label`)."""
        from ..compare.specimens import specimen_label

        s = self.specimen
        return specimen_label("", "") if s is None else specimen_label(s.name, s.hash)

    def cycles_text(self) -> str:
        """``"120/300"`` cycles done of expected; while running before the first block
        reports (the expected count is not known yet) ``"settling the bed (40 ms
        simulated)"`` once the settle reports, ``"starting"`` before; empty otherwise."""
        if self.cycles_expected > 0:
            return f"{self.cycles_done}/{self.cycles_expected}"
        if self.state != "running":
            return ""
        if self.settled_s > 0:
            return f"settling the bed ({self.settled_s * 1e3:.0f} ms simulated)"
        return "starting"

    def progress_text(self, now: float | None = None) -> str:
        """The progress bar's line, e.g. ``"job0001 f100Hz_...: 120/300 cycles, 12 s elapsed,
        ETA 18 s"``."""
        eta = self.eta_s(now)
        cycles = self.cycles_text()
        done = f"{cycles} cycles" if "/" in cycles else cycles or self.state
        return (f"{self.job_id} {self.case.key}: {done}, {self.elapsed_s(now):.0f} s elapsed"
                + (f", ETA {eta:.0f} s" if eta is not None else ""))

    def row(self, now: float | None = None) -> dict:
        """One row of the job table shown in the app (units in the column names), the
        specimen and the progress first so that they show without scrolling. Unknowns are
        blank, never "None" (the ETA before the first block of cycles)."""
        eta = self.eta_s(now)
        return {"job": self.job_id, "state": self.state, "specimen": self.specimen_label(),
                "load case": self.case.key, "progress [%]": round(100 * self.fraction(), 1),
                "cycles [-]": self.cycles_text(),
                "elapsed [s]": round(self.elapsed_s(now), 1),
                # text: a blank beside numbers would make the column "None" or mixed
                "ETA [s]": "" if eta is None else f"{eta:.0f}",
                "message": (f"on another app server ({self.server}); {self.message}"
                            if self.server else self.message),
                "store key": self.run_key}


def _job_process(case, config, specimen, conn, parent_pid: int) -> None:
    """The process of one job: set up as a pool's DEM worker (:func:`pidcore.dem.sweep.
    init_dem_worker`), then :func:`_child`.

    Set up so, Numba makes no named process lock in it: one made because the start method
    the app's process passed on contains "fork" was left behind when the app's exit (Ctrl-C)
    terminated a running job, and the resource tracker warned of a "leaked semaphore" after
    the app had stopped. The worker also ends with the app's process (``parent_pid``) where
    that is killed outright.
    """
    from ..dem.sweep import init_dem_worker

    init_dem_worker(parent_pid)
    _child(case, config, specimen, conn)


def _child(case, config, specimen, conn) -> None:
    """Worker process: simulate one case, report progress, send the store entry back."""
    try:
        import numba

        numba.set_num_threads(1)  # one case per process; threads would oversubscribe
        from ..dem.persist import dem_run_entry
        from ..dem.simulate import simulate_load_case

        last = [0.0]

        def settling(simulated_s: float) -> None:
            now = time.monotonic()
            if now - last[0] >= _SETTLE_REPORT_S:
                last[0] = now
                conn.send(("settling", simulated_s))

        result = simulate_load_case(
            case, config, specimen=specimen,
            on_block=lambda done, expected: conn.send(("progress", done, expected)),
            on_settle=settling)
        conn.send(("done", dem_run_entry(result)))
    except PidcoreError as exc:  # a refusal is its one line, as the report build says it
        conn.send(("error", page_terms(str(exc))))
    except BaseException as exc:  # noqa: BLE001 - reported to the parent as the job's error
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        conn.close()


@dataclass(frozen=True)
class JournalOwner:
    """The app server (and its runner) a journal entry belongs to: whether it still runs
    decides whether its queued and running jobs are live or interrupted.

    Attributes
    ----------
    host : str
        Host name of the server's machine.
    pid : int
        Its process id.
    started : float
        Its process's start time, s since the epoch (a process id is reused; this is not).
    runner : str
        Token of its :class:`DemJobRunner` (several runners of one process are told apart).
    """

    host: str
    pid: int
    started: float
    runner: str

    @classmethod
    def of_this_process(cls) -> JournalOwner:
        """A new owner: this process, with a new runner token."""
        import psutil

        return cls(socket.gethostname(), os.getpid(), psutil.Process().create_time(),
                   secrets.token_hex(8))

    @classmethod
    def live_of_this_process(cls) -> JournalOwner:
        """A new owner of this process that is :meth:`alive` as long as the process runs: a
        runner's (the DEM jobs', a calibration's), whose entries another server, or this one
        after a restart, reads as interrupted once the process is gone."""
        owner = cls.of_this_process()
        _LIVE_RUNNERS.add(owner.runner)
        return owner

    def document(self) -> dict:
        """The owner as the journal stores it."""
        return dataclasses.asdict(self)

    @classmethod
    def from_document(cls, doc: object) -> JournalOwner | None:
        """The owner a journal entry names; None where it names none (a journal of an older
        pidcore) or none that can be trusted (then its jobs are taken over as a stopped
        server's)."""
        if not isinstance(doc, dict):
            return None
        host, pid, started, runner = (doc.get(k) for k in ("host", "pid", "started", "runner"))
        if not (isinstance(host, str) and isinstance(runner, str)
                and isinstance(pid, int) and not isinstance(pid, bool) and pid > 0
                and _finite_number(started)):
            return None
        return cls(host, pid, float(started), runner)

    def describe(self) -> str:
        """``"pid 812 on host lab3"``."""
        return f"pid {self.pid} on host {self.host}"

    def alive(self) -> bool:
        """Whether the owner still runs: its process lives (same id and start time) and, in
        this process, its runner was made here. A server on another host cannot be seen from
        here: it is taken to run (its jobs are shown as it last wrote them)."""
        import psutil

        if self.host != socket.gethostname():
            return True
        if self.pid == os.getpid():
            return self.runner in _LIVE_RUNNERS
        try:
            process = psutil.Process(self.pid)
            started = process.create_time()
            zombie = process.status() == psutil.STATUS_ZOMBIE
        except psutil.NoSuchProcess:
            return False
        except psutil.AccessDenied:  # another user's process of that id lives: assume it
            return True
        return not zombie and abs(started - self.started) <= _START_TOLERANCE_S


class SubmittedJobs(list):
    """The jobs :meth:`DemJobRunner.submit` created (a list of :class:`DemJob`), and
    :attr:`already`: the jobs queued or running that cases of the submission are, so not
    submitted twice (a double click on Run said only "1 already queued or running", naming
    no job)."""

    def __init__(self, created: Sequence[DemJob] = (), already: Sequence[DemJob] = ()):
        super().__init__(created)
        self.already: list[DemJob] = list(already)


class DemJobRunner:
    """Queue of DEM cases for one store, run one at a time by a background thread.

    Parameters
    ----------
    store_path : path
        Store every finished case is saved to.
    """

    def __init__(self, store_path: str | Path, reference_store: str | Path | None = None,
                 ) -> None:
        self.store_path = Path(store_path)
        #: Read-only store of reference DEM runs (the app's ``$PIDCORE_DEM_STORE``): a run
        #: it holds is never run again, as ``pidcore dem sweep`` reuses stored runs.
        self.reference_store = None if reference_store is None else Path(reference_store)
        self._lock = threading.Lock()
        self._wake = threading.Condition(self._lock)
        self._cancel: set[str] = set()
        #: This runner in the journal (:class:`JournalOwner`).
        self.owner = JournalOwner.live_of_this_process()
        #: Why the journal could not be read or written ("" : all well).
        self.journal_problem = ""
        self._jobs: list[DemJob] = []
        #: Jobs of other app servers on this store that still run (read from the journal).
        self._foreign: list[DemJob] = []
        #: Their journal entries, written back as they are.
        self._foreign_entries: list[dict] = []
        self._counter = 0
        self._journal_lock_depth = 0
        with self._lock:
            self._refresh()  # a stopped server's jobs are taken over, interrupted ones as such
        self._thread = threading.Thread(target=self._work, name="pidcore-dem-jobs", daemon=True)
        self._thread.start()

    # --- used by the page ---------------------------------------------------------------------

    def submit(self, cases: Sequence, config, specimen=None) -> SubmittedJobs:
        """Queue ``cases`` with ``config`` on ``specimen`` (:class:`pidcore.specimen.Specimen`;
        None: the paper's coupon); returns the jobs created (duplicates are skipped: a run
        queued or running is not submitted again, and :attr:`SubmittedJobs.already` names its
        job; a run already in the store, or the same simulation as a job queued or running,
        this submission's included, gets a job that says so and is not run:
        :data:`SAME_RUN_STATE`)."""
        from ..dem.persist import own_run_keys, run_identity, run_key

        lookup = self._stored_runs()  # the stores' runs, read once per submission
        created, already = SubmittedJobs(), []
        # the journal locked from reading it to writing it: job numbers are unique across
        # every app server of the store, and another server's queued runs are seen
        with self._lock, self._journal_locked():
            self._merge_journal()
            # the simulations queued or running, this submission's included, by identity
            # (pidcore.compare.align.simulation_identity), as `pidcore dem sweep` plans them:
            # fills 50 and 50.2 % of one particle count are run once; on any server
            active = {run_identity(j.case, j.config, j.specimen): j
                      for j in [*self._foreign, *self._jobs]
                      if j.state in ("queued", "running")}
            for case in cases:
                key = run_key(case, config, specimen)
                try:
                    identity = run_identity(case, config, specimen)
                except PidcoreError as exc:
                    # a case the DEM cannot run (a fill rounding to no particle): its job
                    # says why, as `pidcore dem run` refuses it; the other cases run
                    self._counter += 1
                    job = DemJob(f"job{self._counter:04d}", case, config, key, specimen,
                                 state="failed", message=f"not run: {page_terms(str(exc))}")
                    job.finished = time.time()
                    self._jobs.append(job)
                    created.append(job)
                    continue
                running = active.get(identity)
                if running is not None and running.run_key == key:
                    already.append(running)  # this very run is queued or running
                    continue
                self._counter += 1
                job = DemJob(f"job{self._counter:04d}", case, config, key, specimen)
                found, where = lookup(case, config, specimen)
                if found is not None and found in own_run_keys(case, config, specimen):
                    job.state, job.message = "in store", f"already in {where}; not run again"
                    job.finished = time.time()
                    job.run_key = found  # its own key, or the paper's 0.1 key it is held by
                elif (same := found) is not None:
                    job.state, job.finished = "in store", time.time()
                    job.message = (f"the same simulation (particles per cell, seed, settings) "
                                   f"as stored run {same} of another fill in {where}; not run "
                                   "again")
                    job.run_key = same  # the jobs table's store key names the run it is
                elif running is not None:
                    job.state, job.finished = SAME_RUN_STATE, time.time()
                    job.message = (f"the same simulation (particles per cell, seed, settings) "
                                   f"as {running.job_id} (fill {running.case.fill_percent:g} %),"
                                   " which runs it; not run twice")
                    job.run_key = running.run_key  # the run it will be stored as
                    job.same_as = running.job_id
                else:
                    active[identity] = job
                self._jobs.append(job)
                created.append(job)
            if created:
                self._write_journal()
            self._wake.notify_all()
        # a case given twice names its job once
        created.already = list({j.job_id: j for j in already}.values())
        return created

    def _stored_runs(self):
        """A lookup ``(case, config, specimen) -> (key, where)`` of the runs the app store and
        the reference store hold (:func:`pidcore.dem.persist.stored_run_key`: the run's own
        key, or a stored run of the same simulation under another fill), ``(None, "")`` where
        neither does; each store's runs are read once, here. A reference store that cannot
        be read holds nothing for this lookup (the DEM page says why it cannot be read)."""
        from ..dem.persist import stored_identities, stored_run_key
        from ..store import Store

        stores = []
        reference = self.reference_store
        if reference is not None and reference.resolve() == self.store_path.resolve():
            reference = None  # the app store itself, looked up already
        for path, where in ((self.store_path, "the store"),
                            (reference, f"the reference store {reference}")):
            if path is None or not path.is_file():
                continue
            try:
                store = Store(path)
                # runs of another fill with the same particle count (and seed, settings,
                # specimen) are the same simulation: found by the stored runs' inputs
                stores.append((store, stored_identities(store), where))
            except PidcoreError:
                if path == self.store_path:
                    raise  # the app store must be readable to save anything in it
                continue

        def lookup(case, config, specimen) -> tuple[str | None, str]:
            for store, identities, where in stores:
                found = stored_run_key(store, case, config, specimen, identities=identities)
                if found is not None:
                    return found, where
            return None, ""

        return lookup

    def resubmit_interrupted(self) -> list[DemJob]:
        """Submit again every job the app's last stop interrupted (:data:`INTERRUPTED_STATE`);
        returns the jobs created. Each interrupted job then says which job runs it."""
        with self._lock:
            interrupted = [j for j in self._jobs if j.state == INTERRUPTED_STATE]
        created = []
        for old in interrupted:
            new = self.submit([old.case], old.config, old.specimen)
            created += new
            with self._lock:
                old.state = RESUBMITTED_STATE
                old.message = (f"interrupted by a stop of the app; submitted again as "
                               f"{new[0].job_id}" if new else
                               "interrupted by a stop of the app; already queued or running")
        with self._lock:
            self._write_journal()
        return created

    @contextlib.contextmanager
    def _journal_locked(self):
        """The journal's lock file held (lock held; re-entrant): no other runner, of this
        process or another, reads and rewrites the journal meanwhile. Where the lock file
        cannot be made (a read-only folder) the journal cannot be written either, which
        :meth:`_write_journal` says."""
        if self._journal_lock_depth:
            self._journal_lock_depth += 1
            try:
                yield
            finally:
                self._journal_lock_depth -= 1
            return
        lock_path = journal_lock_path(self.store_path)
        unlocked = ""  # why the journal is changed without the lock
        try:
            fd = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as exc:
            fd = None
            # a read-only folder: the journal cannot be written either, which
            # _write_journal says; a folder or an unreadable file in the lock's place is said
            if lock_path.exists():
                unlocked = f"{lock_path} cannot be opened ({type(exc).__name__})"
        try:
            if fd is not None and fcntl is not None \
                    and not _lock_within(fd, JOURNAL_LOCK_WAIT_S):
                unlocked = (f"{lock_path} was held by another process for over "
                            f"{JOURNAL_LOCK_WAIT_S:g} s (an app server that hangs?)")
            self._journal_lock_depth = 1
            yield
        finally:
            self._journal_lock_depth = 0
            if fd is not None:
                os.close(fd)
            if unlocked:  # said after the body, whose journal note it would replace
                self.journal_problem = (
                    f"{unlocked}; the job table was read and written without it: a change "
                    "another app server made meanwhile may be lost"
                    + (f"; {self.journal_problem}" if self.journal_problem else ""))

    def _merge_journal(self) -> tuple[str, int]:
        """Read the journal (lock and journal lock held): the jobs of other servers that still
        run are kept apart as theirs (:attr:`_foreign`); those of servers that stopped (or of
        a journal that names no owner) become this runner's, interrupted where they were
        queued or running. Returns why entries could not be read ("" : none) and how many
        jobs were taken over."""
        entries, problem = _journal_entries(journal_path(self.store_path))
        own_ids = {j.job_id for j in self._jobs}
        foreign, foreign_entries, taken, lost = [], [], [], []
        for number, (entry, owner) in enumerate(entries, start=1):
            if owner == self.owner:
                continue  # this runner's own: its memory is newer
            live = _still_runs(owner)
            if not live and isinstance(entry, dict) and entry.get("job_id") in own_ids:
                continue  # taken over already, the journal not rewritten since
            try:
                job = _job_from_document(entry, live=live)
                if job.job_id in own_ids or any(j.job_id == job.job_id
                                                for j in [*foreign, *taken]):
                    # Cancel and the jobs waiting for a run name a job by its id
                    raise ValueError(f"job id {job.job_id} listed twice")
            except _UNREADABLE as exc:
                if live:  # another running server's: written back as it is
                    foreign_entries.append(entry)
                    continue
                lost.append(_unreadable_entry(entry, number, exc))
                continue
            if live:
                job.server = owner.describe()
                foreign.append(job)
                foreign_entries.append(entry)
            else:
                taken.append(job)
        _settle_saved_before_stop(taken, self.store_path)
        self._jobs = sorted([*self._jobs, *taken], key=lambda j: _job_number(j.job_id))
        self._foreign, self._foreign_entries = foreign, foreign_entries
        self._counter = max([self._counter, *(_job_number(j.job_id)
                                               for j in [*self._jobs, *foreign])])
        if lost:
            path = journal_path(self.store_path)
            problem = (f"{len(lost)} job(s) of the job table of the last run of the app ({path}) "
                       f"cannot be read: {'; '.join(lost)}; their saved runs are in the store")
        return problem, len(taken)

    def _refresh(self) -> None:
        """Bring the other servers' jobs up to date from the journal (lock held); where a
        server stopped, take its jobs over and rewrite the journal (under its lock, so that
        two servers never both take them)."""
        entries, problem = _journal_entries(journal_path(self.store_path))
        if problem:  # said; the file is left for a look until the next change replaces it
            self.journal_problem = problem
            self._foreign, self._foreign_entries = [], []
            return
        if not any(owner != self.owner and not _still_runs(owner) for _, owner in entries):
            self._merge_journal()
            return
        with self._journal_locked():  # taken over by one server only
            read_problem, taken = self._merge_journal()
            if taken:
                self._write_journal()  # the interrupted ones as such, and as this server's
            # a job that could not be read is said, and still after the journal is rewritten
            self.journal_problem = self.journal_problem or read_problem

    def _write_journal(self) -> None:
        """Replace the journal with this runner's jobs as they are now and the other running
        servers' as they wrote them (lock held). A journal that cannot be written costs the
        table after a restart, never a run: said, not raised."""
        with self._journal_locked():
            read_problem, _ = self._merge_journal()
            try:
                write_journal(journal_path(self.store_path), self._jobs, owner=self.owner,
                              foreign=self._foreign_entries)
                # a job that could not be read is said after the journal is rewritten
                self.journal_problem = read_problem
            except (OSError, TypeError, ValueError) as exc:
                self.journal_problem = (f"the job table cannot be kept in "
                                        f"{journal_path(self.store_path)} ({exc}); it is lost "
                                        "when the app stops")

    def cancel(self, job_ids: Sequence[str] | None = None) -> int:
        """Cancel queued and running jobs (all of them, or ``job_ids``); returns how many.

        A running case's process is terminated within :data:`_POLL_S` + the grace time.
        """
        n = 0
        with self._lock:
            for job in self._jobs:
                if job.state in ("queued", "running") and (job_ids is None
                                                           or job.job_id in job_ids):
                    self._cancel.add(job.job_id)
                    if job.state == "queued":
                        job.state, job.finished = "cancelled", time.time()
                        job.message = "cancelled before it started"
                        self._settle_same(job)
                    n += 1
            if n:
                self._write_journal()
            self._wake.notify_all()
        return n

    def wait_cancelled(self, timeout_s: float) -> bool:
        """Wait until no running job awaits its cancellation (its process is gone), at most
        ``timeout_s``; returns whether none does."""
        deadline = time.monotonic() + timeout_s
        with self._lock:
            while any(j.state == "running" and j.job_id in self._cancel for j in self._jobs):
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._wake.wait(remaining)
            return True

    def jobs(self) -> list[DemJob]:
        """Copies of every job of the store, this server's and the other running servers'
        (:attr:`DemJob.server`), oldest first (safe to read while the worker runs)."""
        with self._lock:
            self._refresh()
            listed = sorted([*self._jobs, *self._foreign], key=lambda j: _job_number(j.job_id))
            return [DemJob(**vars(j)) for j in listed]

    def busy(self) -> bool:
        """Whether a job is queued or running, here or on another running app server of the
        store (as it last wrote the journal)."""
        with self._lock:
            return any(j.state in ("queued", "running") for j in [*self._jobs, *self._foreign])

    def clear_finished(self) -> None:
        """Forget finished jobs (the store keeps their runs)."""
        with self._lock:
            self._jobs = [j for j in self._jobs if j.state in ("queued", "running")]
            self._write_journal()

    # --- worker thread ------------------------------------------------------------------------

    def _next(self) -> DemJob | None:
        with self._lock:
            while True:
                for job in self._jobs:
                    if job.state == "queued":
                        job.state, job.started = "running", time.time()
                        self._write_journal()
                        return job
                self._wake.wait()

    def _work(self) -> None:
        while True:
            job = self._next()
            try:
                self._run(job)
            except Exception as exc:  # noqa: BLE001 - a failed save must not stop the queue
                self._finish(job, "failed", f"{type(exc).__name__}: {exc}")

    def _settle_same(self, job: DemJob) -> None:
        """The jobs waiting for ``job``'s run (:data:`SAME_RUN_STATE`), once it ended (lock
        held): in the store where it was saved, else not run."""
        for same in self._jobs:
            if same.state == SAME_RUN_STATE and same.same_as == job.job_id:
                if job.state == "saved":
                    same.state = "in store"
                    same.message += f"; saved by it as {job.run_key}"
                elif job.state == "in store":  # found stored as it was about to run
                    same.state = "in store"
                    same.message += f"; stored as {job.run_key}"
                else:
                    same.state = "cancelled"
                    same.message = (f"not run: {job.job_id}, the same simulation, is "
                                    f"{job.state}; run it again")

    def _finish(self, job: DemJob, state: str, message: str = "") -> None:
        with self._lock:
            job.state, job.message, job.finished = state, message, time.time()
            self._cancel.discard(job.job_id)
            self._settle_same(job)
            self._write_journal()
            self._wake.notify_all()  # wait_cancelled

    def _run(self, job: DemJob) -> None:
        from ..dem.sweep import CaseOutcome, dem_process_context
        from ..store import Store

        # stored since it was queued (by `pidcore dem`, another app server, a calibration):
        # not run again
        found, where = self._stored_runs()(job.case, job.config, job.specimen)
        if found is not None:
            with self._lock:
                job.run_key = found
            self._finish(job, "in store", f"stored in {where} as {found} after it was queued; "
                                          "not run again")
            return
        ctx = dem_process_context()
        parent, child = ctx.Pipe(duplex=False)
        proc = ctx.Process(target=_job_process,
                           args=(job.case, job.config, job.specimen, child, os.getpid()),
                           daemon=True,
                           name=f"pidcore-dem-{job.job_id}")
        proc.start()
        child.close()
        outcome = None
        try:
            while True:
                with self._lock:
                    cancelled = job.job_id in self._cancel
                if cancelled:
                    stop_processes([proc])
                    self._finish(job, "cancelled", "cancelled while running; nothing saved")
                    return
                if parent.poll(_POLL_S):
                    try:
                        message = parent.recv()
                    except EOFError:
                        proc.join(TERMINATE_GRACE_S)
                        self._finish(job, "failed",
                                     f"the DEM process ended (exit code {proc.exitcode})")
                        return
                    if message[0] == "progress":
                        with self._lock:
                            job.cycles_done = message[1]
                            job.cycles_expected = max(message[1], message[2])
                    elif message[0] == "settling":
                        with self._lock:
                            job.settled_s = message[1]
                    elif message[0] == "error":
                        self._finish(job, "failed", message[1])
                        return
                    else:
                        outcome = message[1]
                        break
        finally:
            parent.close()
            if proc.is_alive():
                proc.join(TERMINATE_GRACE_S)
                if proc.is_alive():
                    proc.kill()
        with self._lock:
            if job.job_id in self._cancel:  # cancelled after the result came: not saved
                job.state, job.finished = "cancelled", time.time()
                job.message = "cancelled as it finished; nothing saved"
                self._settle_same(job)
                self._cancel.discard(job.job_id)
                self._write_journal()
                self._wake.notify_all()  # wait_cancelled
                return
        CaseOutcome(job.run_key, **outcome).save_to(Store(self.store_path))
        self._finish(job, "saved", f"saved as {job.run_key}")


def _settle_saved_before_stop(jobs: Sequence[DemJob], store_path: Path) -> None:
    """Interrupted jobs whose run the store holds: the stop came after the run was saved
    and before the journal said so (or the job was waiting for that run), so the table
    says "in store", not "nothing of it was saved"; a store that cannot be read leaves
    them interrupted (Resubmit then finds the run and does not run it again)."""
    from ..store import Store

    interrupted = [j for j in jobs if j.state == INTERRUPTED_STATE]
    if not interrupted or not store_path.is_file():
        return
    try:
        store = Store(store_path)
        held = [j for j in interrupted if store.has_dem_run(j.run_key)]
    except PidcoreError:
        return
    for job in held:
        job.state = "in store"
        job.message = (f"the app stopped after its run was saved as {job.run_key}: in the "
                       "store, not run again")


def journal_path(store_path: str | Path, suffix: str = JOURNAL_SUFFIX) -> Path:
    """The journal of a store's jobs: ``<store>.jobs.json`` beside it (``suffix``: another
    journal of the store's, e.g. its running calibrations')."""
    path = Path(store_path)
    return path.with_name(path.name + suffix)


def journal_lock_path(store_path: str | Path) -> Path:
    """The lock file every change of a store's journal is made under:
    ``<store>.jobs.json.lock``."""
    path = journal_path(store_path)
    return path.with_name(path.name + ".lock")


@contextlib.contextmanager
def exclusive_journal_lock(store_path: str | Path, *,
                           wait_s: float = JOURNAL_LOCK_WAIT_S,
                           only_where_used: bool = False) -> Iterator[None]:
    """Hold the lock a runner holds from reading the journal to writing it (a submission,
    a job's change of state), for a reader whose decision must not meet a job queued
    meanwhile (``pidcore specimen kept --remove``). Where the folder has no locks (a file
    system without them, Windows) nothing is excluded.

    ``only_where_used``: where neither the journal nor its lock file exists, no app ever
    queued a job on this store (a runner creates the lock file before it writes the journal,
    and a job is queued only in the step that writes it), so nothing is locked and no lock
    file is left beside a store no app ran on. A submission that creates them after this
    look is one made after the reader's decision, as one that waited for the lock would be.

    Raises
    ------
    StoreError
        Another process held the lock for ``wait_s`` (an app server that hangs?), or the lock
        file cannot be made: one line naming it.
    """
    lock_path = journal_lock_path(store_path)
    if only_where_used and not lock_path.exists() and not journal_path(store_path).exists():
        yield
        return
    try:
        fd = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as exc:
        raise StoreError(f"{lock_path}: cannot open the lock file of the app's job table "
                         f"({exc.strerror or exc})") from None
    try:
        if fcntl is not None and not _lock_within(fd, wait_s):
            raise StoreError(f"{lock_path}: held by another process for over {wait_s:g} s "
                             "(an app server that hangs?); try again later")
        yield
    finally:
        os.close(fd)  # releases the lock


#: A job id as the runner makes them (``job0001``): ASCII digits only (``str.isdigit`` also
#: takes "job²", which int() refuses, and 5000 digits are past int()'s limit).
_JOB_ID = re.compile(r"job[0-9]{4,18}")


def _lock_within(fd: int, wait_s: float) -> bool:
    """Take the exclusive lock of ``fd`` (released when it is closed, or the process dies)
    within ``wait_s``; False when another process held it all that time (True where the file
    system has no locks). Waiting without end
    hung the app's page on a server that holds it and hangs (stopped, a dead NFS mount)."""
    deadline = time.monotonic() + wait_s
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return True
        except BlockingIOError:
            if time.monotonic() >= deadline:
                return False
            time.sleep(_POLL_S)
        except OSError:  # a file system without locks: as where no lock file can be made
            return True


def _job_number(job_id: str) -> int:
    return int(job_id[3:]) if _JOB_ID.fullmatch(job_id) else 0


def _unreadable_entry(entry: object, number: int, exc: Exception) -> str:
    """A journal entry left out, for the note of those lost: its job id (or its place) and
    why, clipped (:func:`pidcore.errors.clipped`): an id or error of a hostile journal can be
    megabytes long."""
    name = entry.get("job_id") if isinstance(entry, dict) else None
    return (f"{clipped(str(name), 40) if name else f'entry {number}'} "
            f"({type(exc).__name__}: {clipped(str(exc), 200)})")


def _time_s(value: object, name: str) -> float | None:
    """A journal's time stamp: None (not yet) or a finite number of seconds since the epoch
    (a text there made every row of the job table a TypeError)."""
    if value is None:
        return None
    if not _finite_number(value):
        raise ValueError(f"{name} must be a time in s or null, got {clipped(repr(value), 40)}")
    return float(value)


def _finite_number(value: object) -> bool:
    """Whether a journal's value is a finite int or float: an integer of 400 digits is no
    float (math.isfinite raised OverflowError, a traceback at the app's start)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _count(value: object, name: str) -> int:
    """A journal's cycle count: a whole number >= 0 (inf was an OverflowError traceback)."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"{name} must be a whole number >= 0, got {value!r}")
    return value


def _job_document(job: DemJob, owner: JournalOwner | None = None) -> dict:
    specimen = job.specimen
    return {"owner": None if owner is None else owner.document(), "job_id": job.job_id,
            "state": job.state, "run_key": job.run_key,
            "submitted": job.submitted, "started": job.started, "finished": job.finished,
            "cycles_done": job.cycles_done, "cycles_expected": job.cycles_expected,
            "message": job.message, "same_as": job.same_as,
            "case": dataclasses.asdict(job.case), "config": dataclasses.asdict(job.config),
            "specimen": None if specimen is None else {"text": specimen.text,
                                                       "source": str(specimen.source)}}


def _still_runs(owner: JournalOwner | None) -> bool:
    """Whether a journal entry's server still runs: its jobs stay its own. An entry naming no
    owner (an older journal's, or written as no one's) is taken over like a stopped one's."""
    return owner is not None and owner.alive()


def write_journal(path: Path, jobs: Sequence[DemJob], *, owner: JournalOwner | None = None,
                  foreign: Sequence[dict] = ()) -> None:
    """Write the jobs' journal at ``path`` in one step (a temporary file renamed over it): a
    stop while it is written leaves the previous journal, never half of one. ``owner``: the
    runner the jobs belong to (None: no one's, taken over by the next runner);
    ``foreign``: the other servers' entries, written as they are."""
    text = json.dumps({"pidcore_jobs_version": _JOURNAL_VERSION,
                       "jobs": [*foreign, *(_job_document(j, owner) for j in jobs)]},
                      indent=1)
    # fsync'ed: a power loss must not leave an empty journal, whose queued jobs were then lost
    write_atomically(path, text)


def _job_from_document(doc: dict, *, live: bool = False) -> DemJob:
    """The job of a journal entry; ``live``: its server still runs (shown as written),
    else one queued or running is :data:`INTERRUPTED_STATE`."""
    from ..dem.simulate import DemConfig
    from ..loadcase import LoadCase
    from ..specimen import Specimen

    job_id = doc["job_id"]
    if not isinstance(job_id, str) or not _JOB_ID.fullmatch(job_id):
        raise ValueError(f"job id {job_id!r} is not one the app writes (job0001)")
    spec = doc["specimen"]
    specimen = None if spec is None else Specimen.from_text(spec["text"],
                                                            source=str(spec["source"]))
    submitted = _time_s(doc["submitted"], "submitted")
    if submitted is None:
        raise ValueError("submitted must be a time in s, got null")
    job = DemJob(job_id, LoadCase(**doc["case"]), DemConfig(**doc["config"]),
                 str(doc["run_key"]), specimen, state=str(doc["state"]),
                 submitted=submitted,
                 started=_time_s(doc["started"], "started"),
                 finished=_time_s(doc["finished"], "finished"),
                 cycles_done=_count(doc["cycles_done"], "cycles_done"),
                 cycles_expected=_count(doc["cycles_expected"], "cycles_expected"),
                 message=str(doc["message"]), same_as=str(doc["same_as"]))
    if job.state not in JOB_STATES:
        raise ValueError(f"unknown job state {job.state!r}")
    if not live and job.state in ("queued", "running", SAME_RUN_STATE):
        # the app stopped before it ran (or before the job running it finished): nothing saved
        job.state, job.finished = INTERRUPTED_STATE, job.finished or time.time()
        job.message = ("the app stopped before this case finished; nothing of it was saved: "
                       "run it again with Resubmit interrupted")
        job.cycles_done = 0
    return job


#: What a journal that cannot be trusted raises while it is read (RecursionError: JSON nested
#: deeper than Python's stack, json.loads is recursive; OverflowError: an integer of
#: hundreds of digits where the load case holds a float).
_UNREADABLE = (OSError, ValueError, TypeError, KeyError, AttributeError, RecursionError,
               OverflowError, PidcoreError)


def _journal_entries(path: Path, *, kind: str = "jobs", version: int = _JOURNAL_VERSION
                     ) -> tuple[list[tuple[object, JournalOwner | None]], str]:
    """The entries of a journal beside a store with the owner each names (None: none), and
    "" ; no journal: ``([], "")``. One that cannot be read gives no entry and says why (it is
    JSON, parsed, never executed; it is replaced by the next change). ``kind``: its list's
    key, ``"jobs"`` (the DEM jobs') or ``"calibrations"`` (the running calibrations' of
    :mod:`pidcore.app.calibration`), of the layout ``version``."""
    if not path.is_file():
        return [], ""
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        if not isinstance(doc, dict) or doc.get(f"pidcore_{kind}_version") != version \
                or not isinstance(doc.get(kind), list):
            raise ValueError(f"not a pidcore {kind} journal of version {version}")
    except _UNREADABLE as exc:
        return [], (f"the job table of the last run of the app ({path}) cannot be read "
                    f"({type(exc).__name__}: {exc}); its saved runs are in the store")
    return [(entry, JournalOwner.from_document(entry.get("owner"))
             if isinstance(entry, dict) else None) for entry in doc[kind]], ""


def read_journal(path: Path) -> tuple[list[DemJob], str]:
    """The jobs of a journal (:func:`write_journal`) and "" , each job queued or running
    there as :data:`INTERRUPTED_STATE` (whoever owns it); no journal: ``([], "")``. One that
    cannot be read gives no job and says why; one job that cannot be read costs its own row,
    said, not the table."""
    entries, problem = _journal_entries(path)
    if problem:
        return [], problem
    found: list[DemJob] = []
    lost = []
    for number, (entry, _) in enumerate(entries, start=1):
        try:
            job = _job_from_document(entry)
            if any(j.job_id == job.job_id for j in found):
                # Cancel and the jobs waiting for a run name a job by its id
                raise ValueError(f"job id {job.job_id} listed twice")
            found.append(job)
        except _UNREADABLE as exc:
            lost.append(_unreadable_entry(entry, number, exc))
    if not lost:
        return found, ""
    return found, (f"{len(lost)} job(s) of the job table of the last run of the app ({path}) "
                   f"cannot be read: {'; '.join(lost)}; their saved runs are in the store")


def waiting_job_specimens(store_path: str | Path) -> dict[str, str]:
    """``{sha256: job id}`` of the specimen of every job that the store's journal lists as
    queued or running (or waiting for the same run), whichever server wrote it, as written
    (a stopped server's too: whether it still runs is not told apart here).

    Raises
    ------
    ParameterError
        The journal, or one of those jobs, cannot be read (one line naming the journal): what
        it runs is then unknown, so no file it may need can be called unused.
    """
    path = journal_path(store_path)
    entries, problem = _journal_entries(path)
    if problem:
        raise ParameterError(problem)
    found: dict[str, str] = {}
    for number, (entry, _) in enumerate(entries, start=1):
        try:
            job = _job_from_document(entry, live=True)  # the state as written
        except _UNREADABLE as exc:
            raise ParameterError(f"the job table of the app ({path}) cannot be read: "
                                 f"{_unreadable_entry(entry, number, exc)}") from None
        if job.state in ("queued", "running", SAME_RUN_STATE) and job.specimen is not None:
            found.setdefault(job.specimen.hash, job.job_id)
    return found


_RUNNERS: dict[str, DemJobRunner] = {}
_RUNNERS_LOCK = threading.Lock()


def runner_for(store_path: str | Path,
               reference_store: str | Path | None = None) -> DemJobRunner:
    """The process-wide job runner of a store (created on first use; outlives script runs and
    browser sessions, so a reload shows the jobs still running). ``reference_store``: the
    read-only store of reference DEM runs whose runs are not run again (kept from the first
    call that names one)."""
    key = str(Path(store_path).resolve())
    with _RUNNERS_LOCK:
        if key not in _RUNNERS:
            _RUNNERS[key] = DemJobRunner(key, reference_store)
        elif reference_store is not None:
            _RUNNERS[key].reference_store = Path(reference_store)
        return _RUNNERS[key]


def dem_fills(text: str, specimen=None) -> tuple[list[float], str | None]:
    """The fills [%] typed on the DEM page, and a note when they are not what was typed.

    An empty field takes the chosen specimen's own fill (:meth:`pidcore.specimen.Specimen.
    stated_fill`), as ``pidcore dem run --specimen`` does without ``--fill``; the note says
    so. Otherwise the typed values (:func:`pidcore.loadcase.parse_values`), or a one-line
    error naming the field.
    """
    from ..loadcase import check_fill_range, parse_values

    stated = specimen.stated_fill() if specimen is not None and not text.strip() else None
    if stated is None:
        try:
            fills = parse_values(text, name="fills [%]")
            for fill in fills:  # as `pidcore dem` refuses --fills 150 (the page said "load
                check_fill_range(fill, "fills [%]")  # case: fill must be ...", no field)
            return fills, None
        except ParameterError as exc:
            if text.strip():
                raise
            # empty, and no specimen fill to fall back on: say where one could come from
            raise ParameterError(f"{exc} (or choose a specimen file stating count_per_cell "
                                 "or fill_percent)") from None
    fill, source = stated
    return [fill], f"fills [%] empty: the specimen's own fill, {fill:.4g} % ({source})"


def plan_dem_cases(frequencies_hz: Sequence[float], accelerations_g: Sequence[float],
                   fills_percent: Sequence[float], *, material: str, direction: str,
                   max_cases: int = defaults.APP_MAX_DEM_CASES) -> list:
    """Every combination of the chosen values as :class:`pidcore.dem.LoadCase` (Table 3 order).

    Any positive frequency and acceleration is accepted, not only grid values. Raises
    :class:`ParameterError` for an empty choice or more than ``max_cases`` cases.
    """
    from ..dem.sweep import cross_cases

    cases = cross_cases(frequencies_hz, accelerations_g, fills_percent, material=material,
                        direction=direction)
    if len(cases) > max_cases:
        raise ParameterError(f"{len(cases)} load cases chosen; the app runs at most "
                             f"{max_cases} at a time (use `pidcore dem` for larger sweeps)")
    return cases


def check_dem_cases(cases: Sequence[LoadCase], config: DemConfig,
                    specimen: Specimen | None = None) -> None:
    """Refuse, before any is submitted, a case the DEM refuses (a stroke no shaker makes, a
    frequency its sampling cannot afford: :func:`pidcore.dem.simulate.check_drive`), naming
    the page's fields as `pidcore dem sweep` names its options. The job failed instead, its
    message the exception's class and the library's words ("ParameterError: frequency 1e+09
    Hz: ..."), after the cases before it had run."""
    from ..dem.simulate import check_drive

    for case in cases:
        check_drive(case, config, specimen, what="frequencies [Hz]/accelerations [g]")


#: Columns of :func:`dem_runs_table`: store listing column -> name shown (units in the names).
#: The specimen, the load case and the result come first: at 1280 px the table shows about
#: eight columns before it scrolls, and the SDC was cut off behind the run key.
DEM_RUN_COLUMNS = {"specimen": "specimen", "frequency_hz": "frequency [Hz]",
                   "acceleration_g": "acceleration [g]", "fill_percent": PACKING_RATIO_COLUMN,
                   "material": "material", "sdc": "SDC [-]", "sdc_stderr": "SDC stderr [-]",
                   "steady state": "steady state", "direction": "direction",
                   "cells_simulated": "cells simulated [-]", "seed": "seed [-]",
                   "wall_s": "wall time [s]", "case_key": "run", "store": "store"}


def cancelled_text(n_cancelled: int, listed: Sequence[DemJob]) -> tuple[str, str]:
    """(level, words) of what a click on Cancel did: ``n_cancelled`` jobs of this server
    (:meth:`DemJobRunner.cancel`), and ``listed`` (:meth:`DemJobRunner.jobs`) to name the
    jobs of another app server that cannot be cancelled from here. Nothing to cancel is
    said as such ("cancel requested for 0 job(s)" read as a failed cancel)."""
    theirs = sum(j.state in ("queued", "running") and bool(j.server) for j in listed)
    other = (f"; {theirs} job(s) queued or running on another app server of this store "
             "cannot be cancelled here (cancel them on that server's page)" if theirs else "")
    if n_cancelled == 0:
        return "info", f"nothing to cancel: no job of this app server is queued or running{other}"
    return "warning", (f"cancel requested for {n_cancelled} job(s); finished cases stay saved"
                       f"{other}")


def submitted_text(n_cases: int, created: Sequence[DemJob]) -> str:
    """What a click on Run did: jobs that will run, runs already in the store (not run
    again), cases that are the same simulation as another job (run once), cases the DEM
    cannot run (a fill rounding to no particle: not run, the first one's reason said), and
    cases already queued or running (not submitted twice: by their jobs where ``created``
    is :meth:`DemJobRunner.submit`'s :class:`SubmittedJobs`, else counted)."""
    stored = sum(j.state == "in store" for j in created)
    same = sum(j.state == SAME_RUN_STATE for j in created)
    refused = [j for j in created if j.state == "failed"]  # cases the DEM cannot run
    parts = [f"{len(created) - stored - same - len(refused)} job(s) submitted"]
    if refused:
        parts.append(f"{len(refused)} not run ({refused[0].message.removeprefix('not run: ')})")
    if stored:
        parts.append(f"{stored} already in the store, not run again")
    if same:
        parts.append(f"{same} the same simulation as another job (same particle count and "
                     "seed), run once")
    skipped = n_cases - len(created)
    already = getattr(created, "already", ())
    if already and not created:  # nothing else to say: "0 job(s) submitted" read as a failure
        return f"{_jobs_words(already)} already queued or running: not submitted twice"
    if already:
        parts.append(f"{_jobs_words(already)} already queued or running, not submitted twice")
    elif skipped:
        parts.append(f"{skipped} already queued or running, not submitted again")
    return "; ".join(parts)


def _jobs_words(listed: Sequence[DemJob]) -> str:
    """Jobs by id and load case, ``"job0003 (500 Hz, 1 g, 50 %)"``, ", "-joined."""
    return ", ".join(f"{j.job_id} ({j.case.label()})" if hasattr(j.case, "label")
                     else j.job_id for j in listed)


def steady_state_text(detected) -> str:
    """A run's ``steady_detected`` in a word that fits its column at 1280 px: "reached", or
    "NOT reached" (``pidcore dem run``: "NOT converged, transient cap"); empty where the run
    does not say."""
    from ..compare.align import steady_stated

    stated = steady_stated(detected)
    return "" if stated is None else "reached" if stated else "NOT reached"


def dem_runs_table(runs):
    """The DEM tab's table of stored runs (:func:`pidcore.store.listing.list_dem_runs`):
    columns :data:`DEM_RUN_COLUMNS` present, with each run's specimen
    (:func:`pidcore.compare.specimens.run_specimen_descriptions`: a calibration's variant
    as such) and whether it converged."""
    from ..compare.specimens import run_specimen_descriptions

    runs = runs.assign(
        specimen=run_specimen_descriptions(runs),
        **{"steady state": runs["steady_detected"].map(steady_state_text)
           if "steady_detected" in runs.columns else ""})
    import pandas as pd

    if "sdc_stderr" in runs.columns:
        # the grid shows a missing number as "None", which read as a fault: say why instead
        # (one cell simulated has no scatter to take a standard error from)
        cells = pd.to_numeric(runs["cells_simulated"], errors="coerce") \
            if "cells_simulated" in runs.columns else pd.Series(math.nan, index=runs.index)
        stderr = pd.to_numeric(runs["sdc_stderr"], errors="coerce")
        runs = runs.assign(sdc_stderr=[
            f"{v:.3g}" if math.isfinite(v) else "n/a (1 cell)" if n == 1 else "n/a"
            for v, n in zip(stderr, cells, strict=True)])
    shown = {c: name for c, name in DEM_RUN_COLUMNS.items() if c in runs.columns}
    return runs[list(shown)].rename(columns=shown)


def specimen_from_upload(name: str, data: bytes):
    """The specimen of an uploaded TOML file (parsed, never executed); a bad file raises
    :class:`ParameterError` naming the user's file, not a temporary copy."""
    from ..specimen import Specimen

    # decoded as a file on disk is (a byte-order mark allowed): an upload refused it
    return Specimen.from_bytes(data, source=name)
