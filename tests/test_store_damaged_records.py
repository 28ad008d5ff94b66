"""A stored analysis whose result fields were changed outside pidcore (hand-edited, damaged)
is refused in one line naming the store, the record and the field, by every reader that
turns the store's analyses into numbers: report, calibrate and the app's listing.

Before, a negative standard error crashed the report's figures with a matplotlib traceback
and one of 1e308 overflowed the pooled standard error.
"""

from __future__ import annotations

import hashlib
import math
import re
from pathlib import Path

import h5py
import numpy as np
import pytest

from pidcore.cli import main
from pidcore.errors import StoreError
from pidcore.store.listing import saved_analyses

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "data_samples" / "exports" / "synthetic_f500Hz_a1g_fill50_acrylic.csv"


@pytest.fixture(scope="module")
def analysed_store(tmp_path_factory) -> Path:
    store = tmp_path_factory.mktemp("damaged") / "store.h5"
    assert main(["analyze", str(SAMPLE), "--store", str(store), "--fill", "50"]) == 0
    return store


def _damaged(analysed_store: Path, tmp_path: Path, field: str, value: float) -> Path:
    copy = tmp_path / "store.h5"
    copy.write_bytes(analysed_store.read_bytes())
    with h5py.File(copy, "r+") as h5:
        (entry,) = h5["analyses"].values()
        entry["record"].attrs[field] = value
    return copy


@pytest.mark.parametrize(("field", "value"), [
    ("sdc_stderr", -0.5), ("sdc_stderr", 1e308), ("sdc_stderr", math.inf),
    ("sdc", math.nan), ("sdc", -math.inf), ("frequency_hz", 0.0), ("sdc", -5.0),
    ("energy_per_cycle_j", 1e308)])
def test_a_damaged_result_field_is_refused_by_report_calibrate_and_the_listing(
        analysed_store, tmp_path, capsys, field, value):
    store = _damaged(analysed_store, tmp_path, field, value)
    before = hashlib.sha256(store.read_bytes()).hexdigest()
    out = tmp_path / "report"
    rc = main(["report", "--store", str(store), "--dem-store",
               str(ROOT / "data_samples" / "dem_table3.h5"), "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2
    # one line naming the store, the record's file and the field
    assert len(err.splitlines()) == 1
    assert str(store) in err and SAMPLE.name in err and f"record field {field} = " in err
    assert not out.exists()  # nothing half-written
    rc = main(["calibrate", "--store", str(store), "--fit", "fixture_mass_kg",
               "--out", str(tmp_path / "calibration")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and f"record field {field} = " in err
    with pytest.raises(StoreError, match=f"record field {field} = "):
        saved_analyses(store)  # what the app's Compare and Report tabs list
    # and verify, which called such a store sound (exit 0) while report refused it
    assert main(["store", "verify", "--store", str(store), "--no-progress"]) == 1
    said = capsys.readouterr().out
    assert SAMPLE.name in said and f"record field {field} = " in said
    # read only: the store is as it was
    assert hashlib.sha256(store.read_bytes()).hexdigest() == before


def test_an_undamaged_store_and_an_unknown_stderr_are_read(analysed_store, tmp_path):
    # NaN is how a one-block analysis saves an unknown standard error: not a damage
    store = _damaged(analysed_store, tmp_path, "sdc_stderr", math.nan)
    listed = saved_analyses(store)
    assert len(listed) == 1 and math.isnan(float(listed["sdc_stderr"].iloc[0]))
    assert len(saved_analyses(analysed_store)) == 1
    from pidcore.store import Store

    assert Store(store).verify() == [] and Store(analysed_store).verify() == []


# --- an entry checked against what pidcore stores (pidcore.store.schema) -------------------

def _dem_store(path: Path) -> Path:
    """A store of one DEM run as pidcore saves it: the fields and arrays with their units."""
    from pidcore.dem.result import UNITS
    from pidcore.store import Store

    record = {"sdc": 0.5, "cells_simulated": 2, "frequency_hz": 50.0}
    arrays = {"sdc_per_cell": np.array([0.4, 0.6]), "wall_force_n": np.linspace(0, 1, 8)}
    Store(path).add_dem_run("run", record, arrays=arrays,
                            units={k: UNITS[k] for k in (*record, *arrays)})
    return path


def _replace(h5: h5py.File, path: str, **dataset) -> None:
    del h5[path]
    h5.create_dataset(path, **dataset)


_RUN = "dem_runs/run"
_PICKLED = np.frombuffer(b"\x80\x04\x95" + b"x" * 40, dtype=np.uint8)
#: edit -> (what verify and get_dem_run must say, whether the listing sees it: it reads no
#: array)
_SCHEMA_EDITS = {
    "sdc text": (lambda h5: h5[f"{_RUN}/record"].attrs.__setitem__("sdc", "abc"),
                 "record field sdc = 'abc' is not a real number; expected one in '-'", True),
    "sdc in %": (lambda h5: h5[f"{_RUN}/units"].attrs.__setitem__("sdc", "%"),
                 "unit of sdc is '%'; expected '-'", True),
    "frequency in rad/s": (lambda h5: h5[f"{_RUN}/units"].attrs.__setitem__(
        "frequency_hz", "rad/s"), "unit of frequency_hz is 'rad/s'; expected 'Hz'", True),
    "sdc unit deleted": (lambda h5: h5[f"{_RUN}/units"].attrs.__delitem__("sdc"),
                         "unit of sdc missing; expected '-'", True),
    "force in kN": (lambda h5: h5[f"{_RUN}/arrays/wall_force_n"].attrs.__setitem__(
        "unit", "kN"), "array wall_force_n states unit 'kN'; expected 'N'", False),
    "units a dataset": (lambda h5: _replace(h5, f"{_RUN}/units", data=np.arange(3)),
                        "units is not a group", False),
    "variable-length cells": (lambda h5: _replace(
        h5, f"{_RUN}/arrays/sdc_per_cell", shape=(2,), dtype=h5py.vlen_dtype(np.float64)),
        "array sdc_per_cell holds dtype object; expected a float array", False),
    "object reference": (lambda h5: _replace(
        h5, f"{_RUN}/arrays/sdc_per_cell", shape=(1,), dtype=h5py.ref_dtype),
        "array sdc_per_cell holds dtype object; expected a float array", False),
    "pickle bytes": (lambda h5: _replace(h5, f"{_RUN}/arrays/sdc_per_cell", data=_PICKLED),
                     "array sdc_per_cell holds dtype uint8; expected a float array", False),
    "one cell short": (lambda h5: _replace(h5, f"{_RUN}/arrays/sdc_per_cell",
                                           data=np.array([0.4])),
                       "array sdc_per_cell has 1 elements along cells_simulated; expected 2",
                       False),
    # no run writes a NaN or inf in its tallies or record: one set there passed verify
    "NaN force sample": (lambda h5: h5[f"{_RUN}/arrays/wall_force_n"].__setitem__(3, np.nan),
                         "array wall_force_n holds 1 non-finite value(s) (NaN/inf), first at "
                         "flat index 3", False),
    "infinite cell SDC": (lambda h5: h5[f"{_RUN}/arrays/sdc_per_cell"].__setitem__(0, np.inf),
                          "array sdc_per_cell holds 1 non-finite value(s) (NaN/inf), first at "
                          "flat index 0", False),
}


@pytest.mark.parametrize("edit", list(_SCHEMA_EDITS))
def test_a_dem_run_unlike_what_pidcore_stores_is_damage_to_verify_and_refused_where_read(
        tmp_path, edit):
    from pidcore.store import Store

    path = _dem_store(tmp_path / "s.h5")
    assert Store(path).verify() == []  # the run as saved is sound: the rule fits it
    change, said, listed = _SCHEMA_EDITS[edit]
    with h5py.File(path, "r+") as h5:
        change(h5)
    store = Store(path)
    problems = store.verify()
    assert len(problems) == 1 and f"{path}:/dem_runs/run" in problems[0] and said in problems[0]
    with pytest.raises(StoreError, match="dem_runs/run: damaged entry") as refused:
        store.get_dem_run("run")
    assert said in str(refused.value) and "\n" not in str(refused.value)
    if listed:  # what report, calibrate and `store list` read: refused, not a ValueError later
        with pytest.raises(StoreError, match=re.escape(said)):
            store.list_dem_runs()


def test_a_unit_spelled_otherwise_in_si_is_the_same_unit(tmp_path):
    # m/s2 is m/s^2 and '1' the dimensionless '-', at factor 1: the same numbers
    from pidcore.store import Store

    path = _dem_store(tmp_path / "s.h5")
    with h5py.File(path, "r+") as h5:
        h5[f"{_RUN}/units"].attrs["sdc"] = "1"
    assert Store(path).verify() == []


def test_an_analysis_whose_harmonics_are_text_is_refused_by_verify_and_report(
        analysed_store, tmp_path, capsys):
    from pidcore.store import Store

    store = tmp_path / "store.h5"
    store.write_bytes(analysed_store.read_bytes())
    with h5py.File(store, "r+") as h5:
        (entry,) = h5["analyses"].values()
        del entry["arrays/harmonics"]
        entry["arrays"].create_dataset("harmonics", data=np.array(["a", "b"], dtype=object),
                                       dtype=h5py.string_dtype())
    (problem,) = Store(store).verify()
    assert "array harmonics holds dtype object; expected an integer array" in problem
    rc = main(["report", "--store", str(store), "--out", str(tmp_path / "report")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "array harmonics" in err


def test_an_analysis_whose_phasor_is_nan_is_damage_verify_names_and_report_refuses(
        analysed_store, tmp_path, capsys):
    from pidcore.store import Store

    store = tmp_path / "store.h5"
    store.write_bytes(analysed_store.read_bytes())
    with h5py.File(store, "r+") as h5:
        (entry,) = h5["analyses"].values()
        entry["arrays/velocity_phasors_m_s"][1] = complex(np.nan, 0.0)
        key = entry.name
    (problem,) = Store(store).verify()
    assert f"{store}:{key}" in problem
    assert "array velocity_phasors_m_s holds 1 non-finite value(s) (NaN/inf), first at flat " \
           "index 1" in problem
    rc = main(["report", "--store", str(store), "--out", str(tmp_path / "report")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "array velocity_phasors_m_s" in err


def test_a_stored_text_longer_than_any_name_is_refused_where_written_and_where_read(tmp_path):
    from pidcore.store import Store
    from pidcore.store.values import MAX_TEXT_CHARS

    path = _dem_store(tmp_path / "s.h5")
    long = "A" * (MAX_TEXT_CHARS + 1)
    with pytest.raises(StoreError, match=f"'material' is text of {MAX_TEXT_CHARS + 1} "
                                         f"characters; expected at most {MAX_TEXT_CHARS}"):
        Store(path).add_dem_run("other", {"sdc": 0.5, "material": long})
    Store(path).add_dem_run("other", {"sdc": 0.5, "material": long[:MAX_TEXT_CHARS]})
    with h5py.File(path, "r+") as h5:
        h5[f"{_RUN}/record"].attrs["material"] = "A" * 2**20  # 1 MiB took report > 7 min
    said = (f"dem_runs/run: damaged entry (record field material is text of {2**20} "
            f"characters; expected at most {MAX_TEXT_CHARS})")
    with pytest.raises(StoreError, match=re.escape(said)):
        Store(path).list_dem_runs()
    assert said in Store(path).verify()[0]


def test_a_figure_named_by_a_long_text_is_saved_under_a_bounded_name(tmp_path):
    import matplotlib.pyplot as plt

    from pidcore.report.render import MAX_SHEET_STEM, bounded_stem, save_figure_files

    fig = plt.figure()
    try:
        # 1000 characters: within a stored text's limit, past the 255 of a file name
        png, svg = save_figure_files(fig, tmp_path, "loop_" + "A" * 1000)
    finally:
        plt.close(fig)
    assert png.is_file() and svg.is_file() and len(png.stem) == MAX_SHEET_STEM
    # two long names that begin alike stay two files
    assert bounded_stem("A" * 200 + "x") != bounded_stem("A" * 200 + "y")


def test_a_stored_material_that_is_no_name_is_refused_naming_the_record(analysed_store,
                                                                       tmp_path, capsys):
    store = tmp_path / "store.h5"
    store.write_bytes(analysed_store.read_bytes())
    with h5py.File(store, "r+") as h5:
        (key, entry), = h5["analyses"].items()
        entry["record"].attrs["material"] = "x/../../pwned"
    rc = main(["report", "--store", str(store), "--out", str(tmp_path / "report")])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and f"(analysis {key})" in err and SAMPLE.name in err and "pwned" in err
