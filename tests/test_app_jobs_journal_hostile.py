"""A crafted ``<store>.jobs.json`` (:mod:`pidcore.app.jobs`): every entry the runner cannot
trust costs its own row, said in the runner's note, never a traceback, and nothing runs
without Resubmit. Before: JSON or a specimen's TOML nested past Python's stack, a job id
``job²`` or of 5000 digits and a cycle count of Infinity ended the runner's start (the app's
DEM tab) in a traceback; a started/finished time that was text did so on the first row drawn;
two jobs of one id were both listed (Cancel names a job by its id)."""

from __future__ import annotations

import dataclasses
import json
import os
import socket

import pytest

from pidcore.app import jobs
from pidcore.dem import DemConfig
from pidcore.loadcase import LoadCase

CASE = LoadCase(500.0, 5.0, 50.0, "acrylic", "z")
CONFIG = DemConfig(cells=1, steady_cycles=10)


def _entry(**changes) -> dict:
    """A journal entry as the runner writes it (a finished job), with ``changes``."""
    entry = {"job_id": "job0001", "state": "saved", "run_key": "k", "submitted": 1.0,
             "started": 2.0, "finished": 3.0, "cycles_done": 10, "cycles_expected": 10,
             "message": "", "same_as": "", "case": dataclasses.asdict(CASE),
             "config": dataclasses.asdict(CONFIG), "specimen": None}
    return {**entry, **changes}


def _journal(tmp_path, text: str):
    store = tmp_path / "app.h5"
    jobs.journal_path(store).write_text(text)
    return store


def _runner_rows(store):
    """The runner's jobs and note, and the table's rows drawn (as the DEM tab does)."""
    runner = jobs.DemJobRunner(store)
    listed = runner.jobs()
    rows = [j.row() for j in listed]
    assert not runner.busy()  # nothing runs without Resubmit
    return listed, rows, runner.journal_problem


DAMAGED = {
    "job id with a superscript digit": {"job_id": "job\u00b2"},
    "job id of 5000 digits": {"job_id": "job" + "9" * 5000},
    "job id not a string": {"job_id": 7},
    "cycles Infinity": {"cycles_done": float("inf")},
    "negative cycles": {"cycles_done": -5},
    "started is text": {"started": "yesterday"},
    "finished is a list": {"finished": [1]},
    "started NaN": {"started": float("nan")},
    "specimen TOML nested too deeply": {"specimen": {"text": "a = " + "[" * 100_000,
                                                     "source": "deep.toml"}},
    # JSON integers have no size limit; as a float they overflowed (a traceback at start)
    "submitted an integer of 400 digits": {"submitted": 10**400},
    "a load case's frequency of 400 digits": {"case": {**dataclasses.asdict(CASE),
                                                       "frequency_hz": 10**400}},
}


@pytest.mark.parametrize("name", list(DAMAGED))
def test_a_damaged_entry_costs_its_row_with_a_note(tmp_path, name):
    good = _entry(job_id="job0002")
    store = _journal(tmp_path, json.dumps({"pidcore_jobs_version": 1, "jobs": [
        _entry(**DAMAGED[name]), good]}))
    listed, rows, note = _runner_rows(store)
    assert [j.job_id for j in listed] == ["job0002"] and len(rows) == 1
    assert "1 job(s)" in note and "cannot be read" in note


def test_json_nested_past_the_stack_is_an_empty_table_with_a_note(tmp_path):
    store = _journal(tmp_path, '{"pidcore_jobs_version": 1, "jobs": ['
                     + "[" * 100_000 + "]" * 100_000 + "]}")
    listed, _, note = _runner_rows(store)
    assert listed == [] and "cannot be read" in note and "RecursionError" in note


def test_a_job_id_listed_twice_keeps_the_first(tmp_path):
    store = _journal(tmp_path, json.dumps({"pidcore_jobs_version": 1, "jobs": [
        _entry(state="saved"), _entry(state="queued")]}))
    listed, _, note = _runner_rows(store)
    assert [(j.job_id, j.state) for j in listed] == [("job0001", "saved")]
    assert "job0001" in note and "listed twice" in note


@pytest.mark.parametrize("owner", [
    {"host": socket.gethostname(), "pid": 1, "started": 10**400, "runner": "r"},
    {"host": socket.gethostname(), "pid": 10**30, "started": 1.0, "runner": "r"},
    {"host": socket.gethostname(), "pid": os.getpid(), "started": 4e9, "runner": "r"},
    {"host": ["lab3"], "pid": "812", "started": "now", "runner": None}, "me"])
def test_an_owner_that_cannot_be_trusted_is_a_stopped_server(tmp_path, owner):
    # a start time of 400 digits was an OverflowError traceback at the runner's start; any
    # owner this host cannot confirm running (pid 1 started at another time, no such pid,
    # this process under a runner it never made, fields of the wrong type) has stopped:
    # its running job is taken over as interrupted, its finished job listed as it was
    store = _journal(tmp_path, json.dumps({"pidcore_jobs_version": 1, "jobs": [
        _entry(owner=owner, state="running", finished=None),
        _entry(owner=owner, job_id="job0002")]}))
    listed, rows, note = _runner_rows(store)
    assert [(j.job_id, j.state) for j in listed] == [("job0001", jobs.INTERRUPTED_STATE),
                                                     ("job0002", "saved")]
    assert len(rows) == 2 and note == ""


def _ownerless_running_journal(tmp_path):
    # a job of a server that stopped: the runner takes it over under the journal's lock
    return _journal(tmp_path, json.dumps({"pidcore_jobs_version": 1, "jobs": [
        _entry(owner=None, state="running", finished=None)]}))


def test_a_folder_in_the_lock_files_place_is_said_and_the_journal_still_kept(tmp_path):
    store = _ownerless_running_journal(tmp_path)
    lock = jobs.journal_path(store).with_name(jobs.journal_path(store).name + ".lock")
    lock.mkdir()
    listed, _, note = _runner_rows(store)
    assert [(j.job_id, j.state) for j in listed] == [("job0001", jobs.INTERRUPTED_STATE)]
    # the take-over was written (unlocked), and that it was is said, naming the lock file
    written = json.loads(jobs.journal_path(store).read_text())["jobs"]
    assert [e["state"] for e in written] == [jobs.INTERRUPTED_STATE]
    assert note.startswith(f"{lock} cannot be opened (IsADirectoryError); the job table was "
                           "read and written without it")


@pytest.mark.skipif(jobs.fcntl is None, reason="no journal lock without fcntl")
def test_a_lock_held_by_a_hung_server_delays_the_runner_not_forever(tmp_path, monkeypatch):
    import subprocess
    import sys
    import threading

    store = _ownerless_running_journal(tmp_path)
    lock = jobs.journal_path(store).with_name(jobs.journal_path(store).name + ".lock")
    holder = subprocess.Popen(
        [sys.executable, "-c", "import fcntl, os, sys, time; "
         f"fd = os.open({str(lock)!r}, os.O_RDWR | os.O_CREAT); fcntl.flock(fd, "
         "fcntl.LOCK_EX); print('held', flush=True); time.sleep(600)"],
        stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        monkeypatch.setattr(jobs, "JOURNAL_LOCK_WAIT_S", 0.2, raising=False)
        made = []
        start = threading.Thread(target=lambda: made.append(jobs.DemJobRunner(store)),
                                 daemon=True)
        start.start()
        # the runner waited on the lock for as long as the holder held it (the app's page
        # hung); 60 s is far beyond the 0.2 s wait and a runner's start
        start.join(timeout=60)
        assert made, "the runner still waits for the journal's lock"
        (runner,) = made
        assert [(j.job_id, j.state) for j in runner.jobs()] == \
            [("job0001", jobs.INTERRUPTED_STATE)]
        assert runner.journal_problem.startswith(
            f"{lock} was held by another process for over 0.2 s")
    finally:
        holder.kill()
        holder.wait()
