"""The store at the size of years of tests: reading entries by key costs the same whatever
the number of entries stored, and reading many of them opens the store once."""

from __future__ import annotations

import h5py
import numpy as np
import pandas as pd
import pytest

from pidcore.records import Channel, Measurement
from pidcore.store import Store


class _Counted:
    """Counts HDF5 link lookups (``Group.get``, which every check of an entry's link makes)
    and file openings, while installed."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.lookups = 0
        self.openings = 0
        get, counted = h5py.Group.get, self

        def counting_get(group, *args, **kwargs):
            counted.lookups += 1
            return get(group, *args, **kwargs)

        class CountingFile(h5py.File):
            def __init__(self, *args, **kwargs):
                counted.openings += 1
                super().__init__(*args, **kwargs)

        monkeypatch.setattr(h5py.Group, "get", counting_get)
        monkeypatch.setattr(h5py, "File", CountingFile)

    def reset(self) -> None:
        self.lookups = self.openings = 0


def _store(path, *, n_runs: int, n_analyses: int) -> Store:
    fs = 1000.0
    t = np.arange(200) / fs
    store = Store(path)
    key, _ = store.add_measurement(Measurement("a.csv", (
        Channel("Force", "force", np.sin(2 * np.pi * 10 * t), fs, "N"),
        Channel("Velocity", "velocity", np.cos(2 * np.pi * 10 * t), fs, "m/s")),
        sha256="ab" * 32, file_format="csv"))
    with store.transaction():
        store.add_dem_runs([{"case_key": f"run{i:04d}", "record": {"sdc": 0.1 * i},
                             "arrays": {"x": np.arange(3.0) + i}} for i in range(n_runs)])
        for i in range(n_analyses):
            store.add_analysis(key, {"sdc": 0.01 * i}, arrays={"phasors": np.arange(3.0) * i},
                               parameters={"replica": i})
    return store


@pytest.mark.parametrize("reading", ["get_dem_run", "has_dem_run", "get_analysis",
                                     "get_measurement"])
def test_reading_one_entry_looks_up_as_many_links_in_a_large_store_as_in_a_small_one(
        tmp_path, monkeypatch, reading):
    """Every read by key checked the link of every entry of every section first: a
    get_analysis in a store of 2700 entries cost as much as listing them (1.2 s), and a
    report drawing the loops of 2000 stored analyses ran for 40 minutes. The entry read is
    still checked (tests/test_store_foreign.py); the lookups must not grow with the others."""
    lookups = []
    for n in (2, 60):
        store = _store(tmp_path / f"s{n}.h5", n_runs=n, n_analyses=n)
        key = {"get_dem_run": "run0001", "has_dem_run": "run0001",
               "get_analysis": str(store.list_analyses()["key"].iloc[1]),
               "get_measurement": str(store.list_measurements()["key"].iloc[0])}[reading]
        counted = _Counted(monkeypatch)
        getattr(store, reading)(key)
        lookups.append(counted.lookups)
        monkeypatch.undo()
    assert lookups[0] == lookups[1], lookups


def test_many_analyses_are_read_through_one_opening_of_the_store(tmp_path, monkeypatch):
    store = _store(tmp_path / "s.h5", n_runs=0, n_analyses=12)
    keys = list(store.list_analyses()["key"])
    one_by_one = [store.get_analysis(k) for k in keys]
    counted = _Counted(monkeypatch)
    together = store.get_analyses(reversed(keys))
    assert counted.openings == 1
    assert [e.key for e in together] == keys[::-1]
    for entry, alone in zip(together[::-1], one_by_one, strict=True):
        assert entry.record == alone.record and entry.parameters == alone.parameters
        np.testing.assert_array_equal(entry.arrays["phasors"], alone.arrays["phasors"])


def test_the_app_reads_the_saved_analyses_through_a_fixed_number_of_openings(tmp_path,
                                                                              monkeypatch):
    """The Compare page's entries (one get_analysis per row: one opening each)."""
    from pidcore.report.case_view import saved_entries

    path = tmp_path / "s.h5"
    store = _store(path, n_runs=0, n_analyses=0)
    measurement_key = str(store.list_measurements()["key"].iloc[0])
    for i in range(8):
        store.add_analysis(measurement_key, {
            "frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": 50.0,
            "material": "acrylic", "direction": "z", "sdc": 0.5 + 0.01 * i,
            "sdc_stderr": 0.01, "loss_factor": 0.08},
            arrays={"harmonics": np.arange(1, 4), "force_phasors_n": np.ones(3, complex),
                    "velocity_phasors_m_s": np.ones(3, complex)},
            parameters={"replica": i})
    rows = Store(path).list_analyses().assign(load_case="f100Hz_a5g_fill50pct_acrylic_z",
                                               file="a.csv", date="2026", specimen="")
    assert isinstance(rows, pd.DataFrame) and len(rows) == 8
    counted = _Counted(monkeypatch)
    entries = saved_entries(path, rows)
    assert len(entries) == 8
    assert counted.openings <= 2  # Store() validates the file once, then one read of all rows


def test_verify_reports_its_progress_over_every_entry_and_finds_the_same(tmp_path, capsys):
    """verify() reads every array of the store (a minute for 2700 entries, more with long
    records) and `pidcore report --store` ran it without a sign of life."""
    from pidcore.report.pipeline import open_verified_store

    store = _store(tmp_path / "s.h5", n_runs=5, n_analyses=3)  # + 1 measurement: 9 entries
    calls: list[tuple[int, int]] = []
    assert store.verify(progress=lambda done, total: calls.append((done, total))) == []
    assert calls == [(k, 9) for k in range(1, 10)]
    capsys.readouterr()
    open_verified_store(store.path, must_exist=True, progress=True)
    # the bar is drawn (tqdm throttles its redraws, so which counts show depends on timing;
    # the counts are the callback's, checked above)
    assert "verifying s.h5" in capsys.readouterr().err


def test_the_store_benchmark_times_a_sound_store_of_the_size_asked(tmp_path):
    """`pidcore bench store`: its figures are per entry of the store it built, so that store
    must hold what was asked (colliding keys would silently make it smaller) and be sound."""
    from pidcore.store.bench import run_store_bench

    result = run_store_bench(30, n_measurements=7, n_dem_runs=4, directory=str(tmp_path))
    assert (result["n_measurements"], result["n_analyses"], result["n_dem_runs"]) == (7, 30, 4)
    assert result["verify_problems"] == 0
    assert result["list_analyses_s_per_entry"] == pytest.approx(result["list_analyses_s"] / 30)
