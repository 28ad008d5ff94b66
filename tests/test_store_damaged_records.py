"""A stored analysis whose result fields were changed outside pidcore (hand-edited, damaged)
is refused in one line naming the store, the record and the field, by every reader that
turns the store's analyses into numbers: report, calibrate and the app's listing.

Before, a negative standard error crashed the report's figures with a matplotlib traceback
and one of 1e308 overflowed the pooled standard error.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import h5py
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
    # read only: the store is as it was
    assert hashlib.sha256(store.read_bytes()).hexdigest() == before


def test_an_undamaged_store_and_an_unknown_stderr_are_read(analysed_store, tmp_path):
    # NaN is how a one-block analysis saves an unknown standard error: not a damage
    store = _damaged(analysed_store, tmp_path, "sdc_stderr", math.nan)
    listed = saved_analyses(store)
    assert len(listed) == 1 and math.isnan(float(listed["sdc_stderr"].iloc[0]))
    assert len(saved_analyses(analysed_store)) == 1
