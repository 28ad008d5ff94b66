"""The app's DEM job table outlives the server (:mod:`pidcore.app.jobs` journal): a runner
started after a stop lists the finished jobs as they were, the queued and running ones as
interrupted (nothing saved) and can run them again; a journal that cannot be read costs the
table, never the store or a traceback."""

from __future__ import annotations

import json
import time
from pathlib import Path

from pidcore.app import jobs
from pidcore.dem import DemConfig
from pidcore.specimen import load_specimen

REPO = Path(__file__).resolve().parents[1]
#: A case that runs for minutes (thousands of steady cycles) so that it is surely still
#: running when the test looks; cancelled at the end.
LONG = DemConfig(cells=1, steady_cycles=5000)


def _wait_running(runner, timeout_s: float = 120.0):
    deadline = time.monotonic() + timeout_s
    while not any(j.state == "running" for j in runner.jobs()):
        assert time.monotonic() < deadline, [j.row() for j in runner.jobs()]
        time.sleep(0.05)


def _steel():
    return load_specimen(REPO / "data_samples" / "specimens" / "steel_6mm.toml")


#: An app server of its own (another process): a runner on ``argv[1]`` that submits two long
#: cases of the steel specimen, says "running" once the first runs, and waits to be killed.
_SERVER = """
import sys, time
from pidcore.app import jobs
from pidcore.dem import DemConfig
from pidcore.specimen import load_specimen
specimen = load_specimen(sys.argv[2])
cases = jobs.plan_dem_cases([50.0, 60.0], [5.0], [50.0], material=specimen.particles.material,
                            direction="z")
runner = jobs.DemJobRunner(sys.argv[1])
runner.submit(cases, DemConfig(cells=1, steady_cycles=5000), specimen)
deadline = time.monotonic() + 120
while not any(j.state == "running" for j in runner.jobs()):
    if time.monotonic() > deadline:  # ends, so that the test's readline ends too
        sys.exit(f"no job running after 120 s: {[j.row() for j in runner.jobs()]}")
    time.sleep(0.05)
print(" ".join(j.job_id for j in runner.jobs()), flush=True)
time.sleep(600)
"""


class _Server:
    """Another app server on ``store`` (:data:`_SERVER`), its jobs running once started."""

    def __init__(self, store: Path) -> None:
        import subprocess
        import sys

        self.process = subprocess.Popen(
            [sys.executable, "-c", _SERVER, str(store),
             str(REPO / "data_samples" / "specimens" / "steel_6mm.toml")],
            stdout=subprocess.PIPE, text=True, start_new_session=True)
        #: The ids of its jobs, once the first runs (read from its output).
        self.job_ids = (self.process.stdout.readline() or "").split()
        assert self.job_ids, f"the other server ended (exit code {self.process.poll()})"

    def crash(self) -> None:
        """Kill it and its DEM processes at once, as a crash or SIGKILL does."""
        import os
        import signal

        import psutil

        for child in psutil.Process(self.process.pid).children(recursive=True):
            child.kill()
        os.killpg(self.process.pid, signal.SIGKILL)
        self.process.wait(10)


def test_jobs_running_or_queued_at_a_stop_come_back_interrupted(tmp_path):
    store = tmp_path / "app.h5"
    specimen = _steel()
    first = _Server(store)  # the first app server: its jobs are running and queued
    try:
        submitted = jobs.DemJobRunner(store).jobs()
    finally:
        first.crash()  # the server stops; a new server starts a runner on the same store
    second = jobs.DemJobRunner(store)
    restored = second.jobs()
    assert [j.job_id for j in restored] == [j.job_id for j in submitted]
    assert [j.state for j in restored] == [jobs.INTERRUPTED_STATE] * 2
    assert all("nothing of it was saved" in j.message for j in restored)
    for old, new in zip(submitted, restored, strict=True):
        # everything needed to run it again, read back equal (the specimen by its text)
        assert (new.case, new.config, new.run_key) == (old.case, old.config, old.run_key)
        assert new.specimen.hash == specimen.hash
    assert not second.busy()  # an interrupted job is not run without being asked
    # asked: each is submitted again under a new number, and the old one says by which
    created = second.resubmit_interrupted()
    try:
        assert [j.case for j in created] == [j.case for j in submitted]
        assert all(j.specimen.hash == specimen.hash for j in created)
        assert min(jobs._job_number(j.job_id) for j in created) > max(
            jobs._job_number(j.job_id) for j in submitted)
        by_id = {j.job_id: j for j in second.jobs()}
        for old, new in zip(submitted, created, strict=True):
            assert by_id[old.job_id].message.endswith(f"submitted again as {new.job_id}")
            # not "cancelled" (the page counted "1 cancelled" where no one had cancelled)
            assert by_id[old.job_id].state == jobs.RESUBMITTED_STATE
    finally:
        second.cancel()
        second.wait_cancelled(5.0)
    # the journal says what the runner says, and no temporary file is left beside the store
    listed = json.loads(jobs.journal_path(store).read_text())["jobs"]
    assert [d["state"] for d in listed] == [j.state for j in second.jobs()]
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")) == []


def test_a_second_server_on_the_store_leaves_the_first_ones_running_jobs_running(tmp_path):
    # Before, a second app server on the store read the first's running and queued jobs as
    # left by a stop: it listed them "interrupted, nothing saved", offered to run them again
    # (twice the same simulation) and rewrote the journal without them.
    import os
    import socket

    store = tmp_path / "app.h5"
    first = _Server(store)
    try:
        second = jobs.DemJobRunner(store)  # this process: the second server
        listed = second.jobs()
        assert [j.job_id for j in listed] == first.job_ids
        assert [j.state for j in listed] == ["running", "queued"]
        theirs = f"pid {first.process.pid} on host {socket.gethostname()}"
        assert all(j.server == theirs for j in listed)
        assert listed[0].row()["message"].startswith(f"on another app server ({theirs})")
        assert second.busy()  # the page keeps refreshing while the first server runs them
        # the same cases are not queued a second time here (and never run twice) ...
        cases, config, specimen = listed[0].case, listed[0].config, listed[0].specimen
        assert second.submit([cases, listed[1].case], config, specimen) == []
        # ... nor cancelled from here, and a rewrite by this server keeps the first's entries
        assert second.cancel() == 0
        second.clear_finished()
        entries = json.loads(jobs.journal_path(store).read_text())["jobs"]
        assert [(e["job_id"], e["state"], e["owner"]["pid"]) for e in entries] == [
            (first.job_ids[0], "running", first.process.pid),
            (first.job_ids[1], "queued", first.process.pid)]
        # a third runner (another server of this host) sees them the same way
        assert [j.state for j in jobs.DemJobRunner(store).jobs()] == ["running", "queued"]
    finally:
        first.crash()
    # once the first server is gone its jobs are interrupted, taken over by one server only
    after = second.jobs()
    assert [j.state for j in after] == [jobs.INTERRUPTED_STATE] * 2
    assert all(j.server == "" and "nothing of it was saved" in j.message for j in after)
    entries = json.loads(jobs.journal_path(store).read_text())["jobs"]
    assert {e["owner"]["pid"] for e in entries} == {os.getpid()}
    third = jobs.DemJobRunner(store).jobs()
    assert [(j.state, j.server) for j in third] == [
        (jobs.INTERRUPTED_STATE, f"pid {os.getpid()} on host {socket.gethostname()}")] * 2
    assert not second.busy()


def test_an_owner_is_alive_while_its_process_runs_and_not_under_a_reused_id(tmp_path):
    import subprocess
    import sys

    import psutil

    me = jobs.JournalOwner.of_this_process()
    assert me.alive() is False  # a runner token this process never made
    runner = jobs.DemJobRunner(tmp_path / "app.h5")
    assert runner.owner.alive()
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        started = psutil.Process(sleeper.pid).create_time()
        other = jobs.JournalOwner(me.host, sleeper.pid, started, "r")
        assert other.alive()
        # the same process id with another start time is another process (a reused id)
        assert not jobs.JournalOwner(me.host, sleeper.pid, started - 3600.0, "r").alive()
    finally:
        sleeper.kill()
        sleeper.wait()
    assert not other.alive()  # ended
    # an owner written by an older pidcore (none), or one that cannot be trusted
    assert jobs.JournalOwner.from_document(None) is None
    assert jobs.JournalOwner.from_document({**other.document(), "pid": True}) is None
    assert jobs.JournalOwner.from_document(other.document()) == other


def test_finished_jobs_are_listed_as_they_were(tmp_path):
    store = tmp_path / "app.h5"
    (case,) = jobs.plan_dem_cases([100.0], [5.0], [50.0], material="acrylic", direction="z")
    done = jobs.DemJob("job0007", case, DemConfig(cells=2), "k", state="saved",
                       started=1.0, finished=3.5, cycles_done=20, cycles_expected=20,
                       message="saved as k")
    jobs.write_journal(jobs.journal_path(store), [done])
    (back,) = jobs.DemJobRunner(store).jobs()
    assert back.row() == done.row()  # every column of the table, elapsed time included
    assert back.specimen is None


def test_a_journal_that_cannot_be_read_gives_an_empty_table_and_says_why(tmp_path):
    store = tmp_path / "app.h5"
    journal = jobs.journal_path(store)
    for text in ("{not json", json.dumps({"pidcore_jobs_version": 99, "jobs": []}),
                 json.dumps({"pidcore_jobs_version": 1, "jobs": [{"job_id": "job0001"}]})):
        journal.write_text(text)
        runner = jobs.DemJobRunner(store)
        assert runner.jobs() == []
        assert str(journal) in runner.journal_problem and "cannot be read" in \
            runner.journal_problem
        assert journal.read_text() == text  # kept until the next change replaces it
        assert not store.exists()  # the store is not touched


def test_a_job_whose_run_was_saved_just_before_the_stop_is_not_said_unsaved(tmp_path):
    # a stop between the run's save and the journal's "saved" showed the job as
    # "interrupted: nothing of it was saved" while the store held its run
    from pidcore.store import Store

    store = tmp_path / "app.h5"
    saved_case, lost_case = jobs.plan_dem_cases([100.0, 200.0], [5.0], [50.0],
                                                material="acrylic", direction="z")
    config = DemConfig(cells=2)
    running = [jobs.DemJob("job0001", saved_case, config, "k_saved", state="running",
                           started=1.0),
               jobs.DemJob("job0002", lost_case, config, "k_lost", state="queued")]
    record = {"frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": 50.0,
              "material": "acrylic", "direction": "z", "sdc": 0.5, "sdc_stderr": 0.01}
    Store(store).add_dem_runs([{"case_key": "k_saved", "record": record, "arrays": None}])
    jobs.write_journal(jobs.journal_path(store), running)
    runner = jobs.DemJobRunner(store)
    states = {j.job_id: (j.state, j.message) for j in runner.jobs()}
    assert states["job0001"][0] == "in store" and "k_saved" in states["job0001"][1]
    assert states["job0002"][0] == jobs.INTERRUPTED_STATE
    assert "nothing of it was saved" in states["job0002"][1]
    # the journal says so too (Resubmit then offers only the one that was lost)
    listed = json.loads(jobs.journal_path(store).read_text())["jobs"]
    assert [d["state"] for d in listed] == ["in store", jobs.INTERRUPTED_STATE]
    runner.cancel()


def test_one_job_that_cannot_be_read_costs_its_row_not_the_table(tmp_path):
    # a journal holding one job this version cannot rebuild (its specimen file is refused
    # now, or the entry is damaged) lost every job of the table
    store = tmp_path / "app.h5"
    (case,) = jobs.plan_dem_cases([100.0], [5.0], [50.0], material="acrylic", direction="z")
    done = jobs.DemJob("job0001", case, DemConfig(cells=2), "k", state="saved",
                       started=1.0, finished=3.5, message="saved as k")
    jobs.write_journal(jobs.journal_path(store), [done])
    doc = json.loads(jobs.journal_path(store).read_text())
    bad = dict(doc["jobs"][0], job_id="job0002",
               specimen={"text": "schema_version = 1\nname = 'x'\n", "source": "x.toml"})
    doc["jobs"].append(bad)
    jobs.journal_path(store).write_text(json.dumps(doc))
    runner = jobs.DemJobRunner(store)
    assert [j.row() for j in runner.jobs()] == [done.row()]
    assert runner.journal_problem.startswith("1 job(s) of the job table")
    assert "job0002" in runner.journal_problem and "\n" not in runner.journal_problem
