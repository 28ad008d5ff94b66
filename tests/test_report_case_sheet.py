"""The load case's PDF sheet (:func:`pidcore.report.case_sheet.case_pdf`) says the calibrated
DEM's prediction, 95 % band and verdict of the report's row of that case, or that there is
none: a sheet handed on showed the headline without the calibrated verdict the report gives.

The store holds one test analysed by ``pidcore analyze`` (the mass-damper upload: 100 Hz, 5 g,
fill 50 %, loss factor 0.05, Eq. 11 SDC 2 pi 0.05 = 0.314); the report row is
``pidcore report``'s CSV, the sheet is built as the Compare page builds it from the same
store, and its text is read back out of the PDF.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
import zlib
from pathlib import Path

import pandas as pd
import pytest

from pidcore.calibrate.prediction import band_text, load_calibration, sdc_text
from pidcore.cli import main
from pidcore.compare.align import (
    CALIBRATED_COLUMN,
    CALIBRATED_HIGH_COLUMN,
    CALIBRATED_INSIDE_COLUMN,
    CALIBRATED_LOW_COLUMN,
    MEASURED_BASELINE_COLUMN,
    MEASURED_EQ11_COLUMN,
    MEASURED_EQ11_STDERR_COLUMN,
)
from pidcore.model import load_paper_table3
from pidcore.report.case_sheet import calibrated_case, case_pdf, sheet_lines, sheet_stem
from pidcore.store import Store
from pidcore.units import display_value_with_error

TITLE = "100 Hz, 5 g, 50 %, acrylic, z (1 file(s))"
#: The bundled DEM runs of Table 3's grid, 100 Hz, 5 g, 50 % among them: the headline is the
#: Eq. 10 SDC of that case's m_c, and the Eq. 11 SDC the band judges is a line of its own.
DEM_STORE = Path(__file__).resolve().parents[1] / "data_samples" / "dem_table3.h5"


def _pdf_text(data: bytes) -> str:
    """The text of a matplotlib PDF, its lines joined by spaces (a wrapped line is split at a
    space): the strings of every text object's TJ/Tj operators, in the order drawn."""
    lines = []
    # the end-of-line before "endstream" is left to zlib, which stops at the end of its
    # data: a compressed page ending in a \r byte lost that byte to the pattern's \r?, and
    # with it the whole page (a sheet's first page read as empty)
    for stream in re.finditer(rb"stream\r?\n(.*?)endstream", data, re.S):
        unpack = zlib.decompressobj()
        try:
            content = unpack.decompress(stream.group(1))
        except zlib.error:  # an image or a font program, not a page's content
            continue
        if not unpack.eof:  # cut short: not one whole stream
            continue
        for block in re.findall(rb"BT(.*?)ET", content, re.S):
            # literal strings, with PDF's escapes: \( \) \\ and \ddd octal
            strings = re.findall(rb"\((.*?)(?<!\\)\)", block, re.S)
            text = b"".join(re.sub(rb"\\([()\\])", rb"\1", s) for s in strings)
            text = re.sub(rb"\\([0-7]{3})", lambda m: bytes([int(m.group(1), 8)]), text)
            lines.append(text.decode("latin-1"))
    return " ".join(" ".join(lines).split())


def _words(line: str) -> str:
    return " ".join(line.split())


def _store(tmp_path, baseline_loss_factor: float):
    from _app_samples import mass_damper_csv

    path = tmp_path / "c_fill50.csv"
    path.write_bytes(mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0, loss_factor=0.05))
    store = tmp_path / "s.h5"
    options = (["--baseline-loss-factor", str(baseline_loss_factor)]
               if baseline_loss_factor else [])
    assert main(["analyze", str(path), "--store", str(store), *options]) == 0
    return store


def _calibration(tmp_path, predicted: float, low: float, high: float, *, f: float = 100.0):
    """A calibration of one load case, fitted to a point of SDC stderr 0.02: the band of the
    test's own stderr (0.00013) is its band without stderr, 0.01 inside the fitted one's on
    each side, which the row's note says."""
    doc = {"parameters": {"fixture_mass_kg": {"median": 0.2, "low95": 0.1, "high95": 0.3}},
           "predictions": [{"frequency_hz": f, "acceleration_g": 5.0, "fill_percent": 50.0,
                            "material": "acrylic", "measured": predicted,
                            "measured_stderr": 0.02, "predicted": predicted, "low95": low,
                            "high95": high, "low95_without_stderr": low + 0.01,
                            "high95_without_stderr": high - 0.01}]}
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


def _report_row(tmp_path, store, calibration=None) -> dict:
    out = tmp_path / "report"
    extra = ["--calibration", str(calibration)] if calibration else []
    assert main(["report", "--store", str(store), "--dem-store", str(DEM_STORE), *extra,
                 "--format", "csv", "--out", str(out)]) == 0
    table = pd.read_csv(out / "report.csv", keep_default_na=False, na_values=[""])
    (row,) = table[table[MEASURED_EQ11_COLUMN].notna()].to_dict("records")
    return row


def _compare_view(store):
    """The Compare page's view of the store's one load case (as :func:`pidcore.app.state.
    case_view` builds it, without Streamlit)."""
    from pidcore.report import case_view as views
    from pidcore.store.listing import list_dem_runs, saved_analyses

    saved = saved_analyses(store)
    entries = views.matched_specimens(views.saved_entries(store, saved), saved)
    (group,) = views.group_entries(entries)
    members = [entries[i] for i in group]
    return members, views.case_view(members, list_dem_runs(store, DEM_STORE),
                                    load_paper_table3(), (store, DEM_STORE))


# 0.26 .. 0.39 (the test's band of 0.25 .. 0.40) holds the test's own 0.314 (judged before the
# 2 pi 0.02 = 0.126 taken off) and not the 0.188 left after it; 0.51 .. 0.89 holds neither:
# margins of ~0.05, far above the 0.1 % noise of the upload
@pytest.mark.usefixtures("undrawn_report_figures")
@pytest.mark.parametrize("baseline_loss_factor, band, verdict", [(0.02, (0.25, 0.40), "yes"),
                                                                 (0.0, (0.50, 0.90), "no")])
def test_the_case_sheet_gives_the_report_rows_calibrated_prediction_band_and_verdict(
        tmp_path, monkeypatch, baseline_loss_factor, band, verdict):
    monkeypatch.chdir(tmp_path)
    store = _store(tmp_path, baseline_loss_factor)
    cal = _calibration(tmp_path, (band[0] + band[1]) / 2, *band)
    row = _report_row(tmp_path, store, cal)
    assert row[CALIBRATED_INSIDE_COLUMN] == verdict
    members, view = _compare_view(store)
    shown = calibrated_case([(load_calibration(cal), "calibration.json")], view["comparison"],
                            members[0].specimen, specimen_sha256=members[0].specimen_sha256)
    judged = shown.judgement
    # the row's numbers: the CSV keeps every digit of the file's (read, not computed) and of
    # the band of the row's own stderr (16+ significant digits: rel 1e-12)
    assert judged.sdc == pytest.approx(row[CALIBRATED_COLUMN], rel=1e-12)
    assert (judged.low, judged.high) == pytest.approx(
        (row[CALIBRATED_LOW_COLUMN], row[CALIBRATED_HIGH_COLUMN]), rel=1e-12)
    assert judged.verdict == row[CALIBRATED_INSIDE_COLUMN]
    # the row's note ends with the verdict's words (the band's widening, and the part of the
    # baseline taken off)
    assert "calibrated band for this measurement's SDC stderr" in judged.note
    assert str(row["note"]).endswith(judged.note)
    taken = row[MEASURED_BASELINE_COLUMN]
    assert ("judged at the measured SDC before the empty coupon's damping "
            f"({sdc_text(taken)}) was taken off" in judged.note) == bool(baseline_loss_factor)
    lines = sheet_lines(view, title=TITLE, calibrated=shown)
    # the SDC the band judges, as the row's Eq. 11 columns give it, on a line of its own (the
    # headline's is the Eq. 10 SDC of the DEM case's m_c)
    comp = view["comparison"]
    assert view["headline"].measured_kind.startswith("Eq. 10")
    assert (comp.measured_sdc, comp.measured_stderr) == pytest.approx(
        (row[MEASURED_EQ11_COLUMN], row[MEASURED_EQ11_STDERR_COLUMN]), rel=1e-12)
    assert comp.measured_baseline_sdc == pytest.approx(taken, rel=1e-12)
    measured_line = ("measured SDC (Eq. 11) " + display_value_with_error(
        row[MEASURED_EQ11_COLUMN], row[MEASURED_EQ11_STDERR_COLUMN])
        + (f", the empty coupon's damping (SDC {sdc_text(taken)}) taken off" if taken else ""))
    assert measured_line in lines
    calibrated_lines = shown.sheet_lines()
    assert all(line in lines for line in calibrated_lines)
    assert calibrated_lines[0] == (
        f"calibrated DEM (calibration.json): SDC (Eq. 11) {sdc_text(row[CALIBRATED_COLUMN])}, "
        f"95 % band {band_text(row[CALIBRATED_LOW_COLUMN], row[CALIBRATED_HIGH_COLUMN])} [-]")
    assert calibrated_lines[1] == f"{CALIBRATED_INSIDE_COLUMN}: {row[CALIBRATED_INSIDE_COLUMN]}"
    assert calibrated_lines[2] == f"  ({judged.note})"
    # and the PDF shows them
    text = _pdf_text(case_pdf(view, title=TITLE, calibrated=shown))
    for line in [measured_line, *calibrated_lines]:
        assert _words(line) in text, line


@pytest.mark.usefixtures("undrawn_report_figures")
def test_a_case_sheet_without_a_calibration_gives_no_calibrated_verdict(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    store = _store(tmp_path, 0.02)
    row = _report_row(tmp_path, store)
    assert CALIBRATED_INSIDE_COLUMN not in row  # the report has no such column either
    members, view = _compare_view(store)
    for calibrated in (None, calibrated_case([], view["comparison"], members[0].specimen)):
        text = _pdf_text(case_pdf(view, title=TITLE, calibrated=calibrated))
        assert "calibrated DEM: no calibrated verdict (no calibration given)" in text
        assert "95 % band" not in text and CALIBRATED_INSIDE_COLUMN not in text


def test_a_case_sheet_refuses_a_dem_run_whose_sdc_no_run_saves_naming_store_and_run(tmp_path):
    # the page lists the runs once (the app keeps its listing) and reads the case's run for
    # its loop when it draws the sheet: a run damaged in between (SDC -0.5) was drawn as ours
    import shutil

    import h5py

    from pidcore.errors import StoreError
    from pidcore.report import case_view as views
    from pidcore.store.listing import list_dem_runs

    store = _store(tmp_path, 0.0)
    dem = tmp_path / "dem.h5"
    shutil.copyfile(DEM_STORE, dem)
    members, view = _compare_view(store)
    runs = list_dem_runs(store, dem)
    (key, *_) = view["comparison"].aligned.grid_case.run_keys
    with h5py.File(dem, "r+") as h5:
        h5[f"dem_runs/{key}/record"].attrs["sdc"] = -0.5
    with pytest.raises(StoreError, match=f"dem.h5: DEM run {key}: record field sdc = -0.5 is "
                                         "not a finite number >= 0"):
        views.case_view(members, runs, load_paper_table3(), (store, dem))


@pytest.mark.usefixtures("undrawn_report_figures")
def test_a_case_sheet_of_a_case_the_calibration_does_not_predict_gives_no_verdict(
        tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    store = _store(tmp_path, 0.0)
    cal = _calibration(tmp_path, 0.3, 0.2, 0.4, f=500.0)  # another frequency
    row = _report_row(tmp_path, store, cal)
    assert row[CALIBRATED_INSIDE_COLUMN] == "not compared" and pd.isna(row[CALIBRATED_COLUMN])
    members, view = _compare_view(store)
    shown = calibrated_case([(load_calibration(cal), "calibration.json")], view["comparison"],
                            members[0].specimen, specimen_sha256=members[0].specimen_sha256)
    assert shown.judgement is None
    text = _pdf_text(case_pdf(view, title=TITLE, calibrated=shown))
    assert ("calibrated DEM: no calibrated verdict (No calibration predicts 100 Hz, 5 g, 50 %, "
            "acrylic, z: calibration.json predicts 1 measured load case(s).)") in text
    assert "95 % band" not in text


# --- `pidcore report --case-sheets`: the Compare page's sheet of every measured case ---------

#: The two tests of :func:`_two_case_store`: (file, frequency [Hz], fill [%], calibrated band).
#: Analysed with baseline loss factor 0.02, each is judged at its SDC before the 2 pi 0.02 taken
#: off, 0.314: inside 0.25 .. 0.40, outside 0.50 .. 0.90 (margins of ~0.06 above the 0.1 %
#: noise of the upload), so the two sheets carry the report's two verdicts.
TWO_CASES = (("c_fill50.csv", 100.0, 50.0, (0.25, 0.40)),
             ("d_fill25.csv", 500.0, 25.0, (0.50, 0.90)))


def _two_case_store(tmp_path):
    """A store of two tests at two load cases of the bundled DEM grid, and a calibration that
    predicts both (a band each, :data:`TWO_CASES`)."""
    from _app_samples import mass_damper_csv

    store = tmp_path / "s.h5"
    predictions = []
    for name, f, fill, (low, high) in TWO_CASES:
        path = tmp_path / name
        path.write_bytes(mass_damper_csv(frequency_hz=f, acceleration_g=5.0, loss_factor=0.05))
        assert main(["analyze", str(path), "--store", str(store),
                     "--baseline-loss-factor", "0.02"]) == 0
        predictions.append({"frequency_hz": f, "acceleration_g": 5.0, "fill_percent": fill,
                            "material": "acrylic", "measured": (low + high) / 2,
                            "measured_stderr": 0.02, "predicted": (low + high) / 2,
                            "low95": low, "high95": high, "low95_without_stderr": low + 0.01,
                            "high95_without_stderr": high - 0.01})
    cal = tmp_path / "calibration.json"
    cal.write_text(json.dumps({"parameters": {"fixture_mass_kg": {
        "median": 0.2, "low95": 0.1, "high95": 0.3}}, "predictions": predictions}),
        encoding="utf-8")
    return store, cal


def _report_with_sheets(store, cal, out, *extra) -> int:
    # the stores the app's Compare page joins: its store's runs, then the reference's
    return main(["report", "--store", str(store), "--dem-store", str(store), "--dem-store",
                 str(DEM_STORE), "--calibration", str(cal), "--format", "csv", "--case-sheets",
                 *extra, "--out", str(out)])


def _compare_page_sheets(store, cal) -> dict[str, bytes]:
    """Each load case's sheet as the Compare page prints it from the same store and
    calibration (the page's own functions: entries, groups, view, calibrated verdict, title),
    by fill (one case each: the report names a sheet by its row's grid key, the page by the
    tests' measured one)."""
    from pidcore.report import case_view as views
    from pidcore.report.case_sheet import members_calibrated_case
    from pidcore.store.listing import list_dem_runs, saved_analyses

    saved = saved_analyses(store)
    entries = views.matched_specimens(views.saved_entries(store, saved), saved)
    calibrations = [(load_calibration(cal), str(cal))]  # the app labels a file by its path
    out = {}
    for group in views.group_entries(entries):
        members = [entries[i] for i in group]
        view = views.case_view(members, list_dem_runs(store, DEM_STORE), load_paper_table3(),
                               (store, DEM_STORE))
        shown = members_calibrated_case(calibrations, view["comparison"], members)
        out[view["comparison"].load_case.fill_percent] = case_pdf(
            view, title=views.case_title(entries, group), calibrated=shown)
    return out


@pytest.mark.usefixtures("undrawn_report_figures")
def test_report_case_sheets_agree_with_the_report_rows_and_the_compare_page(
        tmp_path, monkeypatch):
    from pidcore.loadcase import parse_key
    from pidcore.report.table import MEASURED_EQ10_COLUMN

    monkeypatch.chdir(tmp_path)
    store, cal = _two_case_store(tmp_path)
    out = tmp_path / "report"
    assert _report_with_sheets(store, cal, out) == 0
    table = pd.read_csv(out / "report.csv", keep_default_na=False, na_values=[""])
    rows = table[table[MEASURED_EQ11_COLUMN].notna()]
    sheets = sorted((out / "cases").iterdir())
    # one sheet per measured row, nothing else in the folder
    assert len(rows) == len(sheets) == len(TWO_CASES)
    assert all(p.suffix == ".pdf" for p in sheets)
    provenance = (out / "report.provenance.txt").read_text(encoding="utf-8")
    page = _compare_page_sheets(store, cal)
    verdicts = set()
    for path in sheets:
        case = parse_key(path.stem)
        (row,) = rows[rows["packing ratio [%]"] == case.fill_percent].to_dict("records")
        data = path.read_bytes()
        text = _pdf_text(data)
        # the row's numbers as the sheet prints them: its DEM SDC in the headline beside the
        # like-for-like measured one, the Eq. 11 SDC the band judges, the calibrated SDC, band
        # and verdict (the CSV keeps every digit; the sheet prints the display rounding of
        # the very same numbers, so equal text is equal numbers to that rounding)
        dem = display_value_with_error(row["SDC DEM (ours) [-]"], row["SDC DEM stderr [-]"])
        assert _words(f"vs our DEM {dem}") in text
        # the headline's measured SDC is the row's like-for-like one, to its last printed
        # digit (half a unit of it)
        printed = re.search(r"measured SDC \(Eq\. 10 \(DEM m_c\)\) ([0-9.]+)", text).group(1)
        assert abs(float(printed) - row[MEASURED_EQ10_COLUMN]) <= 0.5 * 10.0 ** -len(
            printed.partition(".")[2])
        taken = row[MEASURED_BASELINE_COLUMN]
        assert taken > 0  # each test had the empty coupon's damping taken off
        assert _words("measured SDC (Eq. 11) " + display_value_with_error(
            row[MEASURED_EQ11_COLUMN], row[MEASURED_EQ11_STDERR_COLUMN])
            + f", the empty coupon's damping (SDC {sdc_text(taken)}) taken off") in text
        band = band_text(row[CALIBRATED_LOW_COLUMN], row[CALIBRATED_HIGH_COLUMN])
        assert _words(f"calibrated DEM ({cal}): SDC (Eq. 11) {sdc_text(row[CALIBRATED_COLUMN])}, "
                      f"95 % band {band} [-]") in text
        assert f"{CALIBRATED_INSIDE_COLUMN}: {row[CALIBRATED_INSIDE_COLUMN]}" in text
        verdicts.add(row[CALIBRATED_INSIDE_COLUMN])
        # listed in the report's provenance with the hash of the bytes written
        assert re.search(rf"case sheet: cases/{re.escape(path.name)} \(.*\(1 file\(s\)\)\) "
                         rf"sha256 {hashlib.sha256(data).hexdigest()}", provenance)
        # the Compare page's sheet of the same case says the same, word for word
        assert _pdf_text(page[case.fill_percent]) == text
        # named by its row's load case: report.csv finds it
        assert path.name == f"{row['load case']}.pdf"
    assert verdicts == {"yes", "no"}


@pytest.mark.usefixtures("undrawn_report_figures")
def test_report_case_sheets_are_written_whole_or_not_at_all(tmp_path, monkeypatch, capsys):
    import pidcore.report.case_sheet as case_sheet

    monkeypatch.chdir(tmp_path)
    store, cal = _two_case_store(tmp_path)
    out = tmp_path / "report"
    assert _report_with_sheets(store, cal, out) == 0
    # an earlier report with its sheets is an earlier report: replaced, not refused
    assert _report_with_sheets(store, cal, out) == 0
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert sum(p.parts[0] == "cases" for p in before) == len(TWO_CASES)
    drawn = case_sheet.case_pdf

    def interrupted_on_the_second(view, **kwargs):
        if interrupted_on_the_second.calls:
            raise KeyboardInterrupt
        interrupted_on_the_second.calls += 1
        return drawn(view, **kwargs)

    interrupted_on_the_second.calls = 0
    monkeypatch.setattr(case_sheet, "case_pdf", interrupted_on_the_second)
    capsys.readouterr()
    assert _report_with_sheets(store, cal, out) == 130
    assert "is as it was (a report is written whole or not at all)" in capsys.readouterr().err
    assert {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
    # pooled rows are not the page's cases: refused in one line, nothing written
    monkeypatch.setattr(case_sheet, "case_pdf", drawn)
    pooled = tmp_path / "pooled"
    assert _report_with_sheets(store, cal, pooled, "--pool") == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "--case-sheets: not with --pool" in line
    assert not pooled.exists()


@pytest.mark.usefixtures("undrawn_report_figures")
def test_the_case_sheets_file_table_names_its_sdcs_as_the_report_does(tmp_path, monkeypatch):
    # the sheet's page 2 (and the Compare page's table) headed the report's "SDC measured
    # (Eq. 11) [-]" as "SDC [-]": one measured SDC, two names, one of them the DEM's too
    from pidcore.report.table import MEASURED_EQ10_COLUMN

    monkeypatch.chdir(tmp_path)
    store = _store(tmp_path, 0.0)
    row = _report_row(tmp_path, store)
    _, view = _compare_view(store)
    table = view["comparison"].measured
    # the bundled DEM case has an m_c: the Eq. 10 SDC is a column too
    names = (MEASURED_EQ11_COLUMN, MEASURED_EQ11_STDERR_COLUMN, MEASURED_EQ10_COLUMN)
    assert set(names) <= set(table.columns)
    assert not {"SDC [-]", "SDC stderr [-]", "SDC, E of Eq. 10 [-]"} & set(table.columns)
    # one file: its numbers are the row's (the CSV keeps every digit: rel 1e-12)
    (shown,) = table.to_dict("records")
    assert [shown[n] for n in names] == pytest.approx([row[n] for n in names], rel=1e-12)
    # page 1 says "measured SDC (Eq. 11)" in its lines: these names are page 2's headers
    text = _pdf_text(case_pdf(view, title=TITLE))
    assert all(_words(n) in text for n in names)
    assert "SDC stderr [-]" not in text


def test_a_case_sheet_of_a_file_named_like_tex_math_draws_the_name_as_typed(tmp_path):
    """A test file named ``r$\\x$_c$^$_fill50.csv`` failed the whole report with case sheets
    in matplotlib's mathtext ("ParseFatalException: Unknown symbol: \\x", exit 1). Its name
    is text, written on its sheet as it is spelt."""
    from _app_samples import mass_damper_csv

    path = tmp_path / "r$\\x$_c$^$_fill50.csv"
    path.write_bytes(mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0, loss_factor=0.05))
    out = tmp_path / "report"
    assert main(["report", str(path), "--dem-store", str(DEM_STORE), "--case-sheets",
                 "--format", "csv", "--out", str(out)]) == 0
    (sheet,) = (out / "cases").iterdir()
    text = _pdf_text(sheet.read_bytes())
    # the PDF splits a string at a kerning step, escapes its backslash and draws "fi" as a
    # ligature glyph: the parts between them
    assert "r$" in text and "x$_c$^$_" in text


# --- every option that changes the report's rows: each sheet is one row's -------------------

#: The bundled run of 100 Hz, 5 g, 50 % (the paper's coupon), copied as another specimen's.
GRID_RUN = "f100Hz_a5g_fill50pct_acrylic_z_seed12345_cells8_3e35b5c9af"
#: The SDC given to that copy: far from the bundled run's 0.894 (and both far above the 0.3
#: of the tests), so that a sheet showing the wrong specimen's run shows the wrong number.
OWN_RUN_SDC = 0.5


def _paper_and_own_tests(tmp_path, *, own_named: bool):
    """:func:`_own_specimen`, two tests at its run's load case (SDC 0.05 and 0.06) and a
    sidecar naming the first paper_coupon and, where ``own_named``, the second own_coupon."""
    own, runs = _own_specimen(tmp_path)
    files = _tests(tmp_path, [("pa_50pct.csv", 100.0, 5.0, 0.05),
                              ("ow_50pct.csv", 100.0, 5.0, 0.06)])
    sidecar = tmp_path / "specimens.csv"
    sidecar.write_text("file,specimen\npa_50pct.csv,paper_coupon\n"
                       + ("ow_50pct.csv,own_coupon\n" if own_named else ""), encoding="utf-8")
    return own, runs, files, sidecar


def _own_specimen(tmp_path):
    """A specimen file other than the paper's coupon (a heavier fixture), named own_coupon,
    and a store of one DEM run of it at 100 Hz, 5 g, 50 % (the bundled run's numbers but its
    SDC, :data:`OWN_RUN_SDC`, and its specimen)."""
    from pidcore.specimen import Specimen, paper_specimen
    from pidcore.store import Store

    text = paper_specimen().with_values({"coupon.fixture_mass_kg": 0.05}).to_toml()
    own = Specimen.from_text(text.replace('name = "paper_coupon"', 'name = "own_coupon"'))
    assert own.name == "own_coupon" and not own.is_paper()
    path = tmp_path / "own.toml"
    path.write_text(own.to_toml(), encoding="utf-8")
    run = Store(DEM_STORE).get_dem_run(GRID_RUN)
    # its loss factor and energy per cycle as a run of that SDC saves them: a run whose SDC
    # is not 2 pi x its loss factor is refused as damaged
    record = {**run.record, "sdc": OWN_RUN_SDC, "loss_factor": OWN_RUN_SDC / (2 * math.pi),
              "energy_per_cycle_j": OWN_RUN_SDC * run.record["max_kinetic_energy_j"],
              "specimen_name": own.name, "specimen_sha256": own.hash, "specimen_is_paper": 0}
    parameters = {**run.parameters, "specimen_text": own.text, "specimen_sha256": own.hash,
                  "specimen_name": own.name}
    store = tmp_path / "own_runs.h5"
    Store(store).add_dem_run(GRID_RUN.replace("3e35b5c9af", "0000000own"), record,
                             arrays=run.arrays, parameters=parameters)
    return path, store


def _tests(tmp_path, cases) -> list[Path]:
    """Mass-damper exports of ``cases`` [(file, frequency, acceleration, loss factor)]; the
    names hold no 'fi' (the sheet's font draws it as one glyph: a name with it is not found
    in the PDF's text)."""
    from _app_samples import mass_damper_csv

    paths = []
    for seed, (name, f, a, eta) in enumerate(cases, start=1):
        path = tmp_path / name
        path.write_bytes(mass_damper_csv(frequency_hz=f, acceleration_g=a, loss_factor=eta,
                                         seed=seed))
        paths.append(path)
    return paths


def _rows_and_sheets(out) -> list[tuple[dict, str]]:
    """(measured row of report.csv, text of its sheet) for every measured row; each sheet
    found by the files the row pools (its title counts them, page 2 names them) and every
    sheet one row's."""
    table = pd.read_csv(out / "report.csv", keep_default_na=False, na_values=[""])
    rows = table[table[MEASURED_EQ11_COLUMN].notna()].to_dict("records")
    texts = {p.name: _pdf_text(p.read_bytes()) for p in (out / "cases").iterdir()}
    assert len(texts) == len(rows), (sorted(texts), [r["source file(s)"] for r in rows])
    found = []
    for row in rows:
        files = [Path(s).name for s in str(row["source file(s)"]).split("; ")]
        names = [n for n, text in texts.items()
                 if f"({len(files)} file(s))" in text and all(f in text for f in files)]
        assert len(names) == 1, (files, sorted(texts))  # the row's one sheet
        name = names[0]
        found.append((row, texts.pop(name)))
    return found


def _label(value) -> str:
    """A label column of report.csv as written ("" where empty: read back as NaN)."""
    return value if isinstance(value, str) else ""


def _sheets_named_by_rows(out) -> list[tuple[dict, str]]:
    """(measured row of report.csv, text of its sheet) for every measured row, each sheet
    found by the name the README's join rule derives from the row alone: ``cases/`` + its
    ``load case`` (+ ``_`` and its specimen, :func:`sheet_stem`) + ``.pdf``, ``_2``, ``_3``,
    ... where an earlier row's name is the same as Windows compares names (case-folded)."""
    table = pd.read_csv(out / "report.csv", keep_default_na=False, na_values=[""])
    taken: set[str] = set()
    found = []
    for row in table[table[MEASURED_EQ11_COLUMN].notna()].to_dict("records"):
        stem = sheet_stem(row["load case"], _label(row["specimen"]),
                          _label(row["specimen sha256"]))
        name, n = f"{stem}.pdf", 1
        while name.casefold() in taken:
            n += 1
            name = f"{stem}_{n}.pdf"
        taken.add(name.casefold())
        path = out / "cases" / name
        assert path.is_file(), (name, sorted(p.name for p in (out / "cases").iterdir()))
        found.append((row, _pdf_text(path.read_bytes())))
    return found


def _found_by_name_as_by_content(out) -> None:
    """Every measured row's sheet found by name (:func:`_sheets_named_by_rows`) is the one
    its files and count find (:func:`_rows_and_sheets`), and every sheet is found."""
    by_name = [(row["source file(s)"], text) for row, text in _sheets_named_by_rows(out)]
    assert by_name == [(row["source file(s)"], text) for row, text in _rows_and_sheets(out)]


def _dem_agrees(row: dict, text: str) -> None:
    """The sheet's DEM SDC is the row's (as displayed), or, where the row has none, none."""
    dem = row["SDC DEM (ours) [-]"]
    if pd.isna(dem):
        assert "vs our DEM" not in text and "no DEM value at this case" in text, text[:600]
    else:
        shown = display_value_with_error(dem, row["SDC DEM stderr [-]"])
        assert _words(f"vs our DEM {shown}") in text, text[:600]


@pytest.mark.usefixtures("undrawn_report_figures")
@pytest.mark.parametrize("of_own", [True, False])
def test_a_case_sheet_meets_only_the_dem_runs_the_report_compares(tmp_path, monkeypatch,
                                                                   of_own):
    # a report compares the runs of its specimen (--specimen, default the paper's coupon);
    # the sheets met every stored run: a test naming another specimen showed that
    # specimen's DEM SDC on its sheet beside a row saying the report has no run of it
    monkeypatch.chdir(tmp_path)
    own, runs, files, sidecar = _paper_and_own_tests(tmp_path, own_named=True)
    out = tmp_path / "report"
    assert main(["report", *map(str, files), "--sidecar", str(sidecar), "--dem-store",
                 str(runs), "--dem-store", str(DEM_STORE), "--format", "csv", "--case-sheets",
                 *(["--specimen", str(own)] if of_own else []), "--out", str(out)]) == 0
    found = _rows_and_sheets(out)
    assert len(found) == 2  # a row (and a sheet) per specimen
    bundled = Store(DEM_STORE).get_dem_run(GRID_RUN).record["sdc"]
    for row, text in found:
        _dem_agrees(row, text)
        # the report's specimen's test meets its run; the other's none
        if (row["specimen"] == "own_coupon") == of_own:
            # the CSV keeps every digit of the stored SDC: rel 1e-12
            assert row["SDC DEM (ours) [-]"] == pytest.approx(
                OWN_RUN_SDC if of_own else bundled, rel=1e-12)
        else:
            assert pd.isna(row["SDC DEM (ours) [-]"])


#: The bundled calibration of the paper's coupon (it predicts 100 Hz, 5 g, 50 %).
PAPER_CALIBRATION = DEM_STORE.parent / "paper_calibration" / "calibration.json"


@pytest.mark.usefixtures("undrawn_report_figures")
def test_a_test_of_another_specimen_gets_no_verdict_of_the_paper_coupons_calibration(
        tmp_path, monkeypatch):
    # a report of the paper's coupon judged a test naming own_coupon (no DEM run in its row)
    # against the paper coupon's calibrated band; its sheet said no calibration is of it
    monkeypatch.chdir(tmp_path)
    files = _tests(tmp_path, [("pa_50pct.csv", 100.0, 5.0, 0.05),
                              ("ow_50pct.csv", 100.0, 5.0, 0.06)])
    sidecar = tmp_path / "specimens.csv"
    sidecar.write_text("file,specimen\npa_50pct.csv,paper_coupon\now_50pct.csv,own_coupon\n",
                       encoding="utf-8")
    out = tmp_path / "report"
    assert main(["report", *map(str, files), "--sidecar", str(sidecar), "--dem-store",
                 str(DEM_STORE), "--calibration", str(PAPER_CALIBRATION), "--format", "csv",
                 "--case-sheets", "--out", str(out)]) == 0
    verdicts = {}
    for row, text in _rows_and_sheets(out):
        verdict = row[CALIBRATED_INSIDE_COLUMN]
        verdicts[row["specimen"]] = verdict
        if verdict == "not compared":
            assert pd.isna(row[CALIBRATED_COLUMN])
            assert "it calibrates specimen paper_coupon, not own_coupon" in row["note"]
            assert "calibrated DEM: no calibrated verdict (No calibration is of specimen " \
                   "own_coupon" in text and "95 % band" not in text
        else:
            band = band_text(row[CALIBRATED_LOW_COLUMN], row[CALIBRATED_HIGH_COLUMN])
            assert _words(f"SDC (Eq. 11) {sdc_text(row[CALIBRATED_COLUMN])}, 95 % band {band}"
                          ) in text
            assert f"{CALIBRATED_INSIDE_COLUMN}: {verdict}" in text
    # the paper coupon's test is judged (0.314 inside its band of ~0.06 .. 0.47), the other not
    assert verdicts == {"paper_coupon": "yes", "own_coupon": "not compared"}


def _measured_agrees(row: dict, text: str) -> None:
    """The sheet's pooled Eq. 11 SDC is the row's (as displayed)."""
    shown = display_value_with_error(row[MEASURED_EQ11_COLUMN], row[MEASURED_EQ11_STDERR_COLUMN])
    assert _words(f"measured SDC (Eq. 11) {shown}") in text, text[:600]


@pytest.mark.usefixtures("undrawn_report_figures")
def test_each_case_sheet_pools_the_records_its_report_row_pools(tmp_path, monkeypatch):
    # the sheets grouped records as the Compare page does (within the tolerances of each
    # other), the report by the DEM case they meet, or off the grid by load case key: tests at
    # 4.8 g and 5.2 g (each within 5 % of the 5 g run, not of each other) were one row and two
    # sheets. Off the grid the report now groups as the page does: two tests at 2000 Hz, 5 g
    # (no run there), apart only by noise, were two rows; now one row and one sheet, and a
    # test at 2000 Hz, 6 g (20 % away, beyond the 5 % tolerance) a row and sheet of its own
    monkeypatch.chdir(tmp_path)
    files = _tests(tmp_path, [("low_50pct.csv", 100.0, 4.8, 0.05),
                              ("high_50pct.csv", 100.0, 5.2, 0.06),
                              ("one_50pct.csv", 2000.0, 5.0, 0.05),
                              ("two_50pct.csv", 2000.0, 5.0, 0.06),
                              ("far_50pct.csv", 2000.0, 6.0, 0.05)])
    out = tmp_path / "report"
    assert main(["report", *map(str, files), "--dem-store", str(DEM_STORE), "--format", "csv",
                 "--case-sheets", "--out", str(out)]) == 0
    found = _rows_and_sheets(out)  # one sheet per measured row, of the row's files
    sources = sorted(sorted(Path(s).name for s in row["source file(s)"].split("; "))
                     for row, _ in found)
    assert sources == [["far_50pct.csv"], ["high_50pct.csv", "low_50pct.csv"],
                       ["one_50pct.csv", "two_50pct.csv"]]
    for row, text in found:
        _dem_agrees(row, text)
        _measured_agrees(row, text)
        if row["frequency [Hz]"] == 100.0:  # the pair met the 5 g run
            assert row["SDC DEM (ours) [-]"] == pytest.approx(
                Store(DEM_STORE).get_dem_run(GRID_RUN).record["sdc"], rel=1e-12)
    # each row finds its sheet by name: the pooled grid row by the 5 g run's key (its sheet
    # was named by the tests' mean, 100 Hz at 5.0 g give or take noise, a name no row
    # showed), the pooled off-grid row by its pooled case, the lone far test by its own
    keys = sorted(row["load case"] for row, _ in found)
    assert sorted(p.name for p in (out / "cases").iterdir()) == [f"{k}.pdf" for k in keys]
    assert any(k.startswith("f100Hz_a5g_fill50pct_") for k in keys), keys
    _found_by_name_as_by_content(out)


@pytest.mark.usefixtures("undrawn_report_figures")
def test_a_calibration_of_another_specimen_than_the_reports_judges_no_sheet(tmp_path,
                                                                           monkeypatch):
    # a report of --specimen own predicts no row from the paper coupon's calibration (it is
    # of another specimen); the sheet of its test naming paper_coupon was judged by it,
    # "yes" beside the row's "not compared"
    monkeypatch.chdir(tmp_path)
    own, runs, files, sidecar = _paper_and_own_tests(tmp_path, own_named=False)
    out = tmp_path / "report"
    assert main(["report", *map(str, files), "--sidecar", str(sidecar), "--specimen", str(own),
                 "--dem-store", str(runs), "--dem-store", str(DEM_STORE), "--calibration",
                 str(PAPER_CALIBRATION), "--format", "csv", "--case-sheets",
                 "--out", str(out)]) == 0
    found = _rows_and_sheets(out)
    assert {row["specimen"] for row, _ in found} == {"paper_coupon", "own_coupon"}
    for row, text in found:
        assert row[CALIBRATED_INSIDE_COLUMN] == "not compared"
        assert "it calibrates specimen paper_coupon, not own_coupon" in row["note"]
        assert _words("calibrated DEM: no calibrated verdict (not predicted by the "
                      f"calibration {PAPER_CALIBRATION}: it calibrates specimen paper_coupon, "
                      "not own_coupon") in text
        assert "95 % band" not in text and f"{CALIBRATED_INSIDE_COLUMN}:" not in text


#: What Windows refuses in a file name (and a name ending in a dot or space), and the device
#: names it refuses as a name's stem.
WINDOWS_FORBIDDEN = re.compile(r'[<>:"/\\|?*\x00-\x1f]|[. ]$')
WINDOWS_RESERVED = {"con", "prn", "aux", "nul", *(f"com{i}" for i in range(1, 10)),
                    *(f"lpt{i}" for i in range(1, 10))}


@pytest.mark.usefixtures("undrawn_report_figures")
# a 300-character specimen name leaves page 2's table no room to lay out (said, not an error):
# the names are tested here, not the page
@pytest.mark.filterwarnings("ignore:constrained_layout not applied:UserWarning")
def test_case_sheet_file_names_are_windows_safe_short_and_never_shared(tmp_path, monkeypatch):
    # sheets are handed on and unpacked on Windows: "x_Own.pdf" and "x_own.pdf" are one file
    # there, and a specimen named at length in a sidecar gave a name over 255 characters
    # ("File name too long", a traceback); specimens whose names differ only in characters a
    # file name cannot keep ("a/b:c*?", "a_b_c") share a stem
    from _app_samples import mass_damper_csv

    from pidcore.report.render import MAX_SHEET_STEM

    monkeypatch.chdir(tmp_path)
    long = "coupon_" + "x" * 300
    named = {"s1_50pct.csv": "Own", "s2_50pct.csv": "own", "s3_50pct.csv": "a/b:c*?",
             "s4_50pct.csv": "a_b_c", "s5_50pct.csv": long, "s6_50pct.csv": long + "y"}
    files = []
    for k, name in enumerate(named):
        # one noise seed: the same measured frequency and acceleration, so one load case key
        files.append(tmp_path / name)
        files[-1].write_bytes(mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0,
                                              loss_factor=0.05 + 0.01 * k, seed=1))
    sidecar = tmp_path / "specimens.csv"
    sidecar.write_text("file,specimen\n" + "".join(f'{f},"{s}"\n' for f, s in named.items()),
                       encoding="utf-8")
    out = tmp_path / "report"
    assert main(["report", *map(str, files), "--sidecar", str(sidecar), "--dem-store",
                 str(DEM_STORE), "--format", "csv", "--case-sheets", "--out", str(out)]) == 0
    names = sorted(p.name for p in (out / "cases").iterdir())
    # a sheet per specimen, of one load case key
    assert len(names) == len(named) and len({n.split("_fill50pct")[0] for n in names}) == 1
    assert len({n.casefold() for n in names}) == len(names), names
    for name in names:
        stem = name.removesuffix(".pdf")
        assert name.endswith(".pdf") and not WINDOWS_FORBIDDEN.search(stem), name
        assert stem.split(".")[0].casefold() not in WINDOWS_RESERVED
        # the stem's limit and a "_NN" of a shared one
        assert len(stem) <= MAX_SHEET_STEM + 3, name
    for row, text in _rows_and_sheets(out):  # and each is its row's
        _dem_agrees(row, text)
        _measured_agrees(row, text)
    _found_by_name_as_by_content(out)  # which its row finds by name


@pytest.mark.usefixtures("undrawn_report_figures")
def test_case_sheets_are_refused_with_tolerances_the_compare_page_does_not_use(tmp_path):
    # a test at 103 Hz met the 100 Hz run within a frequency tolerance of 5 % (its row: the
    # run's SDC), while its sheet, the Compare page's, met runs within the default 1 % and
    # showed an SDC interpolated between 100 and 500 Hz
    from pidcore.compare.align import Tolerances
    from pidcore.errors import ParameterError
    from pidcore.report import make_report

    (path,) = _tests(tmp_path, [("at103_50pct.csv", 103.0, 5.0, 0.05)])
    out = tmp_path / "report"
    with pytest.raises(ParameterError, match=r"^case_sheets=True: not with tolerances="
                                             r"Tolerances\(frequency_rtol=0.05"):
        make_report([path], out_dir=out, dem_store=DEM_STORE, formats="csv",
                    tolerances=Tolerances(frequency_rtol=0.05), case_sheets=True)
    assert not out.exists()
    # the defaults, stated, are the page's
    make_report([path], out_dir=out, dem_store=DEM_STORE, formats="csv",
                tolerances=Tolerances(), case_sheets=True)
    assert len(list((out / "cases").iterdir())) == 1


@pytest.mark.usefixtures("undrawn_report_figures")
def test_a_case_sheet_shows_table_3_only_where_the_report_compares_it(tmp_path, monkeypatch):
    # a report of --specimen own compares no Table 3 (not the paper's coupon), on any row;
    # the sheet of its test naming paper_coupon drew Table 3's points and pchip curve
    monkeypatch.chdir(tmp_path)
    own, runs = _own_specimen(tmp_path)
    files = _tests(tmp_path, [("pa_50pct.csv", 100.0, 5.0, 0.05)])
    sidecar = tmp_path / "specimens.csv"
    sidecar.write_text("file,specimen\npa_50pct.csv,paper_coupon\n", encoding="utf-8")

    def sheet(*extra):
        out = tmp_path / f"report{len(extra)}"
        assert main(["report", *map(str, files), "--sidecar", str(sidecar), "--dem-store",
                     str(runs), "--dem-store", str(DEM_STORE), "--format", "csv",
                     "--case-sheets", *extra, "--out", str(out)]) == 0
        ((row, text),) = _rows_and_sheets(out)
        return row, text

    legend = ("pchip model (paper Table 3 DEM)", "paper DEM", "paper measured")
    row, text = sheet()  # the default: of the paper's coupon, Table 3 beside its test
    assert pd.notna(row["SDC DEM (paper) [-]"]) and all(w in text for w in legend)
    row, text = sheet("--specimen", str(own))
    assert pd.isna(row["SDC DEM (paper) [-]"]) and pd.isna(row["SDC measured (paper) [-]"])
    assert not any(w in text for w in legend), text
    assert "note: specimen own_coupon is not the paper's coupon: the paper's Table 3 is not " \
           "compared" in text


@pytest.mark.usefixtures("undrawn_report_figures")
def test_the_case_sheets_are_counted_on_the_reports_progress_bar(tmp_path, capsys):
    # each sheet takes about a second to draw, before the report's writing bar starts: a report
    # of many measured cases sat silent for most of a minute
    from pidcore.report import make_report

    paths = _tests(tmp_path, [("a_50pct.csv", 100.0, 5.0, 0.05),
                              ("b_50pct.csv", 500.0, 5.0, 0.05)])
    make_report(paths, out_dir=tmp_path / "report", dem_store=DEM_STORE, formats="csv",
                case_sheets=True, progress=True)
    err = capsys.readouterr().err
    # tqdm's last state of the bar: both sheets drawn, counted in its own unit
    assert "load case sheets" in err and "2/2" in err.split("load case sheets")[-1]
    assert len(list((tmp_path / "report" / "cases").iterdir())) == 2
