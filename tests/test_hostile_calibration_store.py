"""Hand-crafted, damaged calibrations in the store (h5py writes what pidcore never would):
each is refused in one line naming the store and the entry, by ``report --calibration``,
``Store.verify`` and the app's readers, and the store is left as it was. Before, a string
dataset, JSON nested deeper than Python's stack, a missing subgroup, a JSON attribute that is
not JSON, a record field that is an array and a dangling soft link were tracebacks; verify
called a NaN prediction sound that report refused; a bad load case did not name the store."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from pidcore.app.calibration import available_calibrations, saved_calibrations_table
from pidcore.calibrate.persist import readable_calibrations, stored_calibration
from pidcore.cli import main
from pidcore.store import Store

BUNDLED = Path(__file__).resolve().parents[1] / "data_samples" / "paper_calibration"
KEY = "cal_0123456789abcdef"


def _document() -> dict:
    return json.loads((BUNDLED / "calibration.json").read_text())


@pytest.fixture(scope="module")
def sound_store(tmp_path_factory) -> Path:
    """A store holding the bundled paper calibration (written by pidcore, not by hand)."""
    store = tmp_path_factory.mktemp("hostile_cal") / "sound.h5"
    Store(store).add_calibration(KEY, {"specimen": "paper_coupon", "n_points": 12},
                                 document=(BUNDLED / "calibration.json").read_text(),
                                 specimen_toml="", units={"n_points": "count"})
    return store


def _arrays(h5):
    return h5[f"calibrations/{KEY}/arrays"]


def _replace(name: str, data) -> callable:
    def damage(h5):
        del _arrays(h5)[name]
        _arrays(h5)[name] = data
    return damage


def _document_with(change) -> callable:
    def damage(h5):
        document = _document()
        change(document)
        _replace("calibration_json", np.frombuffer(json.dumps(document).encode(), np.uint8))(h5)
    return damage


def _set_prediction(field, value):
    return _document_with(lambda d: d["predictions"][0].__setitem__(field, value))


DAMAGE = {
    # an HDF5 string dataset reads back as bytes: 'bytes' object has no attribute 'dtype'
    "string dataset": _replace("calibration_json", json.dumps(_document())),
    # json.loads is recursive: RecursionError
    "nested JSON": _replace("calibration_json",
                            np.frombuffer(b"[" * 100_000 + b"]" * 100_000, np.uint8)),
    "no record group": lambda h5: h5[f"calibrations/{KEY}"].__delitem__("record"),
    "no units group": lambda h5: h5[f"calibrations/{KEY}"].__delitem__("units"),
    "dangling soft link": _replace("calibration_json", h5py.SoftLink("/nowhere")),
    "null_fields_json not JSON": lambda h5: h5[f"calibrations/{KEY}"].attrs.__setitem__(
        "null_fields_json", "{"),
    "parameters_json a number": lambda h5: h5[f"calibrations/{KEY}"].attrs.__setitem__(
        "parameters_json", "5"),
    "record field an array": lambda h5: h5[f"calibrations/{KEY}/record"].attrs.__setitem__(
        "specimen", np.arange(5)),
    "prediction NaN": _set_prediction("predicted", float("nan")),
    "negative frequency": _set_prediction("frequency_hz", -500.0),
}


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("name", list(DAMAGE))
def test_a_damaged_calibration_is_one_line_naming_the_store(sound_store, tmp_path, capsys,
                                                            name):
    store = tmp_path / "damaged.h5"
    store.write_bytes(sound_store.read_bytes())
    with h5py.File(store, "r+") as h5:
        DAMAGE[name](h5)
    before = _sha256(store)
    code = main(["report", "--calibration", str(store), "--dem-store", str(sound_store),
                 "--out", str(tmp_path / "out"), "--format", "csv", "--no-progress"])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and str(store) in err and KEY in err, err
    problems = Store(store).verify()
    assert len(problems) == 1 and str(store) in problems[0] and KEY in problems[0], problems
    readable, damaged = readable_calibrations(store)
    assert readable == [] and len(damaged) == 1 and KEY in damaged[0], damaged
    (calibration, reason), = available_calibrations(None, {}, cwd=tmp_path, store_path=store)
    assert calibration is None and KEY in reason
    assert len(saved_calibrations_table(store)) == 1  # listed, so that it can be seen
    assert _sha256(store) == before  # read only


def test_the_sound_store_reads(sound_store):
    """The fixture itself is sound: what the damage above breaks is read without it."""
    assert Store(sound_store).verify() == []
    assert len(stored_calibration(sound_store).predictions) == len(_document()["predictions"])


@pytest.mark.parametrize("value", ["many", float("inf"), 2.5])
def test_the_calibrate_tab_lists_a_count_that_is_not_one_as_stored(sound_store, tmp_path,
                                                                    value):
    """int() of a damaged count ended the Calibrate tab in a traceback; it is shown as
    stored, said not to be a count."""
    store = tmp_path / "odd.h5"
    store.write_bytes(sound_store.read_bytes())
    with h5py.File(store, "r+") as h5:
        h5[f"calibrations/{KEY}/record"].attrs["n_points"] = value
    cell = saved_calibrations_table(store)["load cases [-]"].iloc[0]
    assert cell == f"{value!r} (not a count)"
    assert saved_calibrations_table(sound_store)["load cases [-]"].iloc[0] == 12


def test_verify_names_a_key_the_store_would_refuse(sound_store, tmp_path):
    """A second entry under a key with a tab (copied by hand): readers refuse that key, and
    verify called the store sound."""
    store = tmp_path / "odd_key.h5"
    store.write_bytes(sound_store.read_bytes())
    with h5py.File(store, "r+") as h5:
        h5["calibrations"].copy(KEY, "odd key\t")
    problems = Store(store).verify()
    assert len(problems) == 1 and "'odd key\\t' is not valid" in problems[0], problems
    readable, damaged = readable_calibrations(store)
    assert [c.store_key for c in readable] == [KEY] and len(damaged) == 1
