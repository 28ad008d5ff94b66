"""A measurement saved by an older pidcore names its specimen but not its file's sha256. Beside
hashed tests of that name it is a test of their one file (matched by name only, said), or,
where the name means two files, kept apart (said): one rule
(:func:`pidcore.specimen.match_hashless_records`) for ``calibrate --store``, the report table
and the app's Compare grouping."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from _panel_tests import panel_export, panel_specimen

from pidcore.loadcase import LoadCase
from pidcore.specimen import MEASURED_SHA256_FIELD
from pidcore.store import Store

CASE = LoadCase(1000.0, 5.0, 25.0, "acrylic", "z")
SHA_COLUMN = "specimen sha256"


@pytest.fixture(scope="module")
def tests_analysed(tmp_path_factory):
    """Four synthetic tests at one load case, analysed once (different damping: different
    SDCs), to be saved with or without a specimen file's hash."""
    from pidcore.measure import analyze_file

    where = tmp_path_factory.mktemp("hashless")
    results = [analyze_file(panel_export(where / f"t{i}_fill25.csv", damping))
               for i, damping in enumerate((4.0, 6.0, 9.0, 12.0))]
    return SimpleNamespace(where=where, results=results, first=panel_specimen(0.05),
                           second=panel_specimen(0.08))


def _store(path: Path, results, hashes: list[str | None]) -> Path:
    """A store of ``results`` named "panel", each with its hash, or (None) without the field,
    as a pidcore before the hash was saved wrote it."""
    from pidcore.measure import AnalysisOptions, save_analyses

    fields = [{"specimen": "panel", **({MEASURED_SHA256_FIELD: h} if h else {})}
              for h in hashes]
    save_analyses(path, results, AnalysisOptions(),
                  [(Path(r.measurement.source).name, CASE, "file name") for r in results],
                  fields=fields)
    return path


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_a_hashless_record_joins_its_names_one_file_in_one_calibration_point(
        tests_analysed, tmp_path):
    """Was: two points at one load case, "panel [ab12cd]" (2 tests) and "panel" (1 test),
    both fitted as separate measurements of one specimen."""
    from pidcore.calibrate.data import measured_from_store, points_for_specimen

    results, first = tests_analysed.results[:3], tests_analysed.first
    store = _store(tmp_path / "mixed.h5", results, [first.hash, first.hash, None])
    assert Store(store).list_analyses()[MEASURED_SHA256_FIELD].isna().sum() == 1
    before = _digest(store)
    left_out: list[str] = []
    points = measured_from_store(store, left_out=left_out)
    assert len(points) == 1
    (point,) = points
    sdc = np.array([r.analysis.sdc for r in results])
    assert point.specimen == "panel" and point.specimen_sha256 == first.hash
    # the three tests pooled: their mean and the standard error of the mean, from the
    # analyses themselves (exact arithmetic on the same floats: 1e-12 is rounding)
    assert point.sdc == pytest.approx(sdc.mean(), rel=1e-12)
    assert point.sdc_stderr == pytest.approx(np.std(sdc, ddof=1) / math.sqrt(3), rel=1e-12)
    assert point.sdc_stderr_dof == 2
    assert left_out == [f"1 record(s) of specimen panel saved without its specimen's sha256 (an "
                        f"older pidcore, or no file given) matched by name only to panel "
                        f"[{first.hash[:6]}], the one file of that name its other tests "
                        "recorded"]
    # calibrating that file takes the pooled point; with the file given, the same
    kept, note = points_for_specimen(points, first)
    assert kept == points and note == ""
    again = measured_from_store(store, specimen=first)
    assert again == points and again[0].sdc_stderr == point.sdc_stderr
    assert _digest(store) == before  # reading never writes


def test_a_hashless_record_of_a_name_of_two_files_is_kept_apart_and_said(
        tests_analysed, tmp_path):
    from pidcore.calibrate.data import measured_from_store, points_for_specimen

    first, second = tests_analysed.first, tests_analysed.second
    store = _store(tmp_path / "two.h5", tests_analysed.results,
                   [first.hash, first.hash, second.hash, None])
    before = _digest(store)
    left_out: list[str] = []
    points = measured_from_store(store, left_out=left_out)
    by_hash = {p.specimen_sha256: p for p in points}
    assert sorted(by_hash) == sorted(["", first.hash, second.hash])
    hashless = by_hash[""]
    # the hashless test alone: its own SDC, never pooled with either file's
    assert hashless.sdc == pytest.approx(tests_analysed.results[3].analysis.sdc, rel=1e-12)
    assert hashless.specimen_ambiguous
    labels = sorted(f"panel [{h[:6]}]" for h in (first.hash, second.hash))
    assert len(left_out) == 1 and left_out[0].startswith(
        "1 record(s) of specimen panel saved without its specimen's sha256 kept apart")
    assert all(label in left_out[0] for label in labels)
    # a calibration of either file does not take it by its name
    kept, note = points_for_specimen(points, first)
    assert [p.specimen_sha256 for p in kept] == [first.hash]
    assert "panel saved without its specimen's sha256 (the name means several files)" in note
    # nor does the library fit it when a script passes it (a second point of the case)
    from pidcore.calibrate.calibrate import check_point_specimens
    from pidcore.errors import ParameterError

    with pytest.raises(ParameterError, match=r"name specimen \"panel \(saved without its "
                       r"specimen's sha256; several files of that name\)\", not 'panel'"):
        check_point_specimens([by_hash[first.hash], hashless], first)
    check_point_specimens([by_hash[first.hash]], first)
    assert _digest(store) == before


def test_a_given_file_other_than_the_stores_one_makes_the_hashless_record_ambiguous(
        tests_analysed, tmp_path):
    """The store's hashed tests are of the first file; calibrating the second, a test saved
    by name only may be of either: it is not fitted to the second by name."""
    from pidcore.calibrate.data import measured_from_store, points_for_specimen

    first, second = tests_analysed.first, tests_analysed.second
    store = _store(tmp_path / "given.h5", tests_analysed.results[:2], [first.hash, None])
    left_out: list[str] = []
    points = measured_from_store(store, left_out=left_out, specimen=second)
    assert sorted(p.specimen_sha256 for p in points) == sorted(["", first.hash])
    assert f"the specimen given is panel [{second.hash[:6]}]" in left_out[0]
    kept, _ = points_for_specimen(points, second)
    assert kept == []


def _analyses(records) -> pd.DataFrame:
    return pd.DataFrame([{"source": source, "frequency_hz": 1000.0, "acceleration_g": 5.0,
                          "fill_percent": 25.0, "material": "acrylic", "direction": "z",
                          "sdc": sdc, "sdc_stderr": 0.01, "specimen": "panel",
                          MEASURED_SHA256_FIELD: sha} for source, sha, sdc in records])


def test_report_rows_pool_a_hashless_record_with_its_names_one_file(tests_analysed):
    from pidcore.report.table import build_report_table

    first, second = tests_analysed.first, tests_analysed.second
    joined = build_report_table(None, _analyses([("a.csv", first.hash, 0.10),
                                                 ("old.csv", math.nan, 0.14)]), None)
    assert len(joined) == 1
    assert joined["source file(s)"].iloc[0] == "a.csv; old.csv"
    assert joined[SHA_COLUMN].iloc[0] == first.hash
    assert "old.csv" not in joined["note"].iloc[0]  # the note names the rule, not a file
    assert "matched by name only to panel [" in joined["note"].iloc[0]
    apart = build_report_table(None, _analyses([("a.csv", first.hash, 0.10),
                                                ("b.csv", second.hash, 0.30),
                                                ("old.csv", math.nan, 0.14)]), None)
    rows = {row["source file(s)"]: row for _, row in apart.iterrows()}
    assert set(rows) == {"a.csv", "b.csv", "old.csv"}
    assert rows["old.csv"][SHA_COLUMN] == ""
    assert "kept apart" in rows["old.csv"]["note"]
    # a report of the second file: the store's tests name only the first, so not joined
    given = build_report_table(None, _analyses([("a.csv", first.hash, 0.10),
                                                ("old.csv", math.nan, 0.14)]), None,
                               tested_files={"panel": second.hash})
    assert len(given) == 2 and "kept apart" in " ".join(given["note"])


def test_app_compare_groups_a_hashless_record_with_its_names_one_file(tests_analysed,
                                                                      tmp_path):
    from pidcore.model import load_paper_table3
    from pidcore.report.case_view import (
        case_view,
        group_entries,
        group_name,
        matched_specimens,
        saved_entries,
    )
    from pidcore.store.listing import filter_analyses, saved_analyses

    first = tests_analysed.first
    store = _store(tmp_path / "app.h5", tests_analysed.results[:3],
                   [first.hash, first.hash, None])
    before = _digest(store)
    listing = saved_analyses(store)
    entries = matched_specimens(saved_entries(store, listing), listing)
    groups = group_entries(entries)
    assert len(groups) == 1 and len(groups[0]) == 3
    assert group_name(entries, groups[0]) == (
        f"{CASE.full_label()}, specimen panel [{first.hash[:6]}]")
    view = case_view(entries, None, load_paper_table3(), [store])
    assert any("matched by name only" in note for note in view["notes"])
    assert sorted(view["comparison"].measured["specimen"]) == [
        "panel", "panel",
        f"panel (no file hash saved; matched by name to panel [{first.hash[:6]}])"]
    # a filter showing the hashless record alone does not make it another specimen
    old = [f for f in listing["file"] if f.startswith("t2")]
    shown = filter_analyses(listing, files=old)
    alone = matched_specimens(saved_entries(store, shown), listing)
    assert [e.specimen_sha256 for e in alone] == [first.hash]
    assert _digest(store) == before


def test_a_report_of_the_hashless_test_alone_still_reads_it_as_its_names_one_file(
        tests_analysed, tmp_path):
    """The app's Report of chosen files (and `report FILES --store`) decides with the whole
    store: chosen alone, the older record was "panel" by name, another row than its file's."""
    from pidcore.report.downloads import store_report_table
    from pidcore.report.table import build_report_table
    from pidcore.store.listing import saved_analyses

    first = tests_analysed.first
    store = _store(tmp_path / "chosen.h5", tests_analysed.results[:2], [first.hash, None])
    before = _digest(store)
    listing = saved_analyses(store)
    old = listing[listing[MEASURED_SHA256_FIELD].isna()]
    table = build_report_table(None, old, None, store_analyses=listing)
    assert table[SHA_COLUMN].tolist() == [first.hash]
    assert "matched by name only" in table["note"].iloc[0]
    app_table = store_report_table(store, analysis_keys=list(old["key"]))
    measured = app_table[app_table["source file(s)"].fillna("") != ""]
    assert measured[SHA_COLUMN].tolist() == [first.hash]
    assert _digest(store) == before


def test_compares_per_file_table_says_which_test_recorded_only_a_name(tests_analysed,
                                                                     tmp_path):
    from pidcore.model import load_paper_table3
    from pidcore.report.case_view import case_view, matched_specimens, saved_entries
    from pidcore.store.listing import saved_analyses

    first, second = tests_analysed.first, tests_analysed.second
    store = _store(tmp_path / "shown.h5", tests_analysed.results, [first.hash, first.hash,
                                                                   second.hash, None])
    listing = saved_analyses(store)
    entries = matched_specimens(saved_entries(store, listing), listing)
    hashless = [e for e in entries if e.specimen_note]
    assert len(hashless) == 1 and hashless[0].specimen_sha256 == ""
    view = case_view(hashless, None, load_paper_table3(), [store])
    assert view["comparison"].measured["specimen"].tolist() == [
        "panel (no file hash saved; several files of that name)"]
    assert any("kept apart" in note for note in view["notes"])
