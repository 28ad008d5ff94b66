"""A calibration's own outputs judge its bands as the report does: a fold (or in-sample point)
whose 95 % band spans every plausible SDC (0 .. 2 pi) is "uninformative", counted
neither inside nor among those judged (summary.md, summary.html, calibration.json's
``loo_coverage95``, the store's listing, the command's line). Before, such a band counted as
"inside": a calibration that constrains nothing at a load case scored a hit there."""

from __future__ import annotations

import html
import importlib
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pidcore.calibrate.calibrate import CalibrationResult
from pidcore.calibrate.parameters import parameter_spec
from pidcore.calibrate.prediction import calibrated_sdc_bound, row_verdict
from pidcore.cli import main
from pidcore.compare.plausibility import SDC_UPPER_BOUND
from pidcore.specimen import paper_specimen

REPO = Path(__file__).resolve().parents[1]


def _row(frequency_hz: float, measured: float, predicted: float, low: float,
         high: float) -> dict:
    # no measurement stderr: the band is the fitted point's as it stands
    return {"frequency_hz": frequency_hz, "acceleration_g": 5.0, "fill_percent": 50.0,
            "material": "acrylic", "measured": measured, "measured_stderr": 0.0,
            "predicted": predicted, "low95": low, "high95": high,
            "low95_without_stderr": low, "high95_without_stderr": high,
            "predicted_low95": low, "predicted_high95": high}


#: Three leave-one-out folds: one inside, one outside, one whose band 0 .. 30 reaches past
#: the paper coupon's SDC bound (16.9 at 50 % acrylic) from 0: it holds any measurement.
LOO = [_row(100, 0.30, 0.32, 0.10, 0.60), _row(500, 0.90, 0.40, 0.20, 0.70),
       _row(1000, 0.50, 0.45, 0.0, 30.0)]
PREDICTIONS = [_row(100, 0.30, 0.31, 0.12, 0.55), _row(500, 0.90, 0.60, 0.30, 0.95),
               _row(1000, 0.50, 0.47, 0.0, 25.0)]


def _result() -> CalibrationResult:
    specimen = paper_specimen()
    spec = parameter_spec("fixture_mass_kg", specimen)
    return CalibrationResult(
        specimen=specimen, specs=[spec], samples=np.full((4, 1), 0.02),
        parameters={"fixture_mass_kg": {"median": 0.02, "low95": 0.015, "high95": 0.025,
                                        "prior_low": spec.low, "prior_high": spec.high}},
        correlations=[[1.0]], predictions=[dict(r) for r in PREDICTIONS],
        loo=[dict(r) for r in LOO], fixed={"baseline_loss_factor": 0.0},
        design=np.zeros((1, 0)), observations=[], runs={"computed": 0, "cached": 3},
        settings={"fit": ["fixture_mass_kg"], "cells": 2, "design_size": 1,
                  "method_used": "grid"})


def test_the_bound_of_the_constructed_folds_is_the_one_their_band_spans():
    # the premise: the third band reaches from 0 past the bound, the others judge
    bound = calibrated_sdc_bound(paper_specimen(), fill_percent=50.0, material="acrylic")
    assert SDC_UPPER_BOUND < bound.sdc < 25.0
    assert [row_verdict(r, bound) for r in LOO] == ["yes", "no", "uninformative"]
    # a band from 0 that stops below 2 pi (a loss factor of 1) still judges: 0.5 is inside
    # 0 .. 2 pi - 0.5; one from 0 past 2 pi, short of the bound, spans every plausible SDC
    below = SDC_UPPER_BOUND - 0.5
    assert row_verdict({**LOO[2], "high95": below, "high95_without_stderr": below},
                       bound) == "yes"
    past = bound.sdc - 1.0
    assert row_verdict({**LOO[2], "high95": past, "high95_without_stderr": past},
                       bound) == "uninformative"
    # and one reaching past it from above 0 judges too (0.5 is below 0.6: outside)
    assert row_verdict({**LOO[2], "low95": 0.6, "low95_without_stderr": 0.6, "predicted": 1.0},
                       bound) == "no"


def test_an_uninformative_fold_is_not_counted_inside():
    result = _result()
    # was 2: the 0 .. 2 pi band counted as holding its measurement
    assert result.loo_coverage == 1
    assert result.loo_uninformative == 1
    document = result.full_document()
    assert document["loo_coverage95"] == 1 and document["loo_uninformative95"] == 1
    # the RMS is of every fold, as before: the prediction is a number all the same
    errors = [r["predicted"] - r["measured"] for r in LOO]
    assert result.loo_rms == pytest.approx(math.sqrt(np.mean(np.square(errors))), rel=1e-12)


def test_the_summaries_say_k_of_n_with_the_uninformative_apart():
    from pidcore.calibrate.outputs import rms_text, summary_html, summary_markdown

    result = _result()
    text = summary_markdown(result)
    said = ("inside the 95 % band (1 more uninformative: a band of 0 .. 2 pi, "
            "spanning every plausible SDC, cannot test the model)")
    loo_rms, rms = rms_text(result.loo_rms), rms_text(result.rms)  # 0.2903, 0.1742
    assert f"## Leave-one-out predictions: RMS {loo_rms}, 1/2 {said}" in text.splitlines()
    assert f"## In-sample posterior predictions: RMS {rms}, 2/2 {said}" in text.splitlines()
    # each table's rows, in-sample then leave-one-out (the third was "yes")
    verdicts = [line.rstrip(" |").rsplit("| ", 1)[1] for line in text.splitlines()
                if line.startswith(("| 100 | 5 |", "| 500 | 5 |", "| 1000 | 5 |"))
                and line.count("|") == 9]
    assert verdicts == ["yes", "yes", "uninformative", "yes", "**no**", "uninformative"]
    assert "| measured in calibrated 95 % band [yes/no/not compared/uninformative] |" in text
    page = summary_html(_result())
    assert f"<h2>Leave-one-out predictions: RMS {loo_rms}, 1/2 {said}</h2>" in page
    assert page.count("<td>uninformative</td>") == 2


def test_the_command_prints_the_leave_one_out_count_without_the_uninformative_fold(
        tmp_path, capsys, monkeypatch):
    library = importlib.import_module("pidcore.calibrate.calibrate")
    outputs = importlib.import_module("pidcore.calibrate.outputs")
    monkeypatch.setattr(library, "calibrate", lambda points, **kwargs: _result())
    monkeypatch.setattr(outputs, "write_outputs", lambda result, out: [])
    monkeypatch.setattr(importlib.import_module("pidcore.calibrate.persist"),
                        "save_calibration", lambda result, store: ("cal_0", True))
    table = tmp_path / "m.csv"
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc\n100,5,50,0.3\n"
                     "500,5,50,0.9\n1000,5,50,0.5\n")
    assert main(["calibrate", "--data", str(table), "--fit", "fixture_mass_kg",
                 "--dem-store", str(tmp_path / "d.h5"), "--cells", "2", "--workers", "1",
                 "--no-progress"]) == 0
    out = capsys.readouterr().out.splitlines()
    (line,) = [s for s in out if s.startswith("leave-one-out RMS")]
    assert line.startswith("leave-one-out RMS 0.2903, 1/2 inside the 95 % band (1 more "
                           "uninformative: ")


def _calibrate_args_of_the_constructed_result(tmp_path, monkeypatch) -> tuple[list[str], Path]:
    """``pidcore calibrate`` arguments (without --json/--out) whose calibration is
    :func:`_result` (the library's calibrate and the store's save stood in for), and the
    ``--out`` folder to give them."""
    library = importlib.import_module("pidcore.calibrate.calibrate")
    monkeypatch.setattr(library, "calibrate", lambda points, **kwargs: _result())
    monkeypatch.setattr(importlib.import_module("pidcore.calibrate.persist"),
                        "save_calibration", lambda result, store: ("cal_0", True))
    table = tmp_path / "m.csv"
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc\n100,5,50,0.3\n"
                     "500,5,50,0.9\n1000,5,50,0.5\n")
    return (["calibrate", "--data", str(table), "--fit", "fixture_mass_kg", "--dem-store",
             str(tmp_path / "d.h5"), "--cells", "2", "--workers", "1", "--no-progress"],
            tmp_path / "out")


def test_the_commands_json_carries_the_leave_one_out_counts(tmp_path, capsys, monkeypatch):
    # --json had loo_rms but not the k/n the text line prints: a script could not tell 1/2
    # inside with 1 uninformative from 2/3 inside without recomputing every fold's SDC bound
    args, out = _calibrate_args_of_the_constructed_result(tmp_path, monkeypatch)
    assert main([*args, "--json", "--out", str(out)]) == 0
    document = json.loads(capsys.readouterr().out)
    # the constructed folds: one inside, one outside, one uninformative
    assert document["loo_coverage95"] == 1 and document["loo_uninformative95"] == 1
    # the same names and numbers as calibration.json beside it
    written = json.loads((out / "calibration.json").read_text())
    assert (written["loo_coverage95"], written["loo_uninformative95"]) == (1, 1)


def test_the_stores_listing_counts_the_uninformative_folds_and_reads_older_entries(tmp_path):
    from pidcore.app.calibration import saved_calibrations_table
    from pidcore.calibrate.persist import save_calibration
    from pidcore.store import Store

    store = tmp_path / "s.h5"
    save_calibration(_result(), store)
    listing = Store(store).list_calibrations()
    assert listing["loo_coverage95"].tolist() == [1]
    assert listing["loo_uninformative95"].tolist() == [1]
    table = saved_calibrations_table(listing=listing)
    assert table["inside 95 % band (LOO) [-]"].tolist() == [1]
    assert table["uninformative 95 % band (LOO) [-]"].tolist() == [1]
    # an entry of an older pidcore has no such field: none counted apart; one without
    # leave-one-out stays blank
    older = pd.DataFrame({"key": ["cal_a", "cal_b"], "specimen": ["paper_coupon"] * 2,
                          "fit": ["fixture_mass_kg"] * 2, "n_points": [12.0, 12.0],
                          "rms_in_sample": [0.08, 0.09], "loo_rms": [0.097, np.nan],
                          "loo_coverage95": [10.0, np.nan],
                          "created_utc": ["2026-12-01T00:00:00+00:00",
                                          "2026-12-01T00:01:00+00:00"]})
    table = saved_calibrations_table(listing=older)
    assert table["inside 95 % band (LOO) [-]"].tolist() == ["", 10]
    assert table["uninformative 95 % band (LOO) [-]"].tolist() == ["", 0]


def test_the_bundled_paper_calibration_has_no_uninformative_fold_and_keeps_its_counts():
    # judged by the rule, the bundled files give what they state (calibration.json's
    # loo_coverage95 10 and loo_uninformative95 0, summary.md's 11/12 and 10/12); made again
    # from the cached runs, they differ from the files made before the rule only by that count
    # and the summary's column header
    folder = REPO / "data_samples" / "paper_calibration"
    document = json.loads((folder / "calibration.json").read_text())
    assert document["loo_uninformative95"] == 0

    from pidcore.calibrate.prediction import load_calibration
    from pidcore.loadcase import LoadCase

    # each row cut where the report cuts it: the bound of the specimen the calibration is of
    calibration = load_calibration(folder)

    def verdicts(rows):
        return [row_verdict(r, calibration.sdc_bound(LoadCase(
            r["frequency_hz"], r["acceleration_g"], r["fill_percent"], r["material"])))
            for r in rows]

    loo, in_sample = verdicts(document["loo"]), verdicts(document["predictions"])
    assert "uninformative" not in loo + in_sample
    assert loo.count("yes") == document["loo_coverage95"] == 10 and len(loo) == 12
    summary = (folder / "summary.md").read_text()
    assert f"RMS 0.0970, {loo.count('yes')}/12 inside the 95 % band" in summary
    assert f"{in_sample.count('yes')}/12 inside the 95 % band" in summary


def test_the_new_count_leaves_the_key_of_a_fit_saved_before_it_as_it_was():
    # a calibration saved by a pidcore that wrote no loo_uninformative95 is found again by its
    # key (save_calibration keeps the same fit once): the count follows from the keyed loo rows
    from pidcore.calibrate.persist import calibration_key

    document = _result().full_document()
    older = {k: v for k, v in document.items() if k != "loo_uninformative95"}
    assert calibration_key(document) == calibration_key(older)
    assert calibration_key(document) != calibration_key({**older, "loo_rms": 0.5})


def test_the_predictions_figure_draws_an_uninformative_band_apart():
    # predictions.png drew the 0 .. 25 band (in-sample) and the 0 .. 30 fold (LOO) as filled
    # points like the others: a reader took a band that holds any measurement for a hit
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_rgba

    from pidcore.calibrate.outputs import UNINFORMATIVE_LABEL, predictions_figure

    figure = predictions_figure(_result())
    try:
        (ax,) = figure.axes
        drawn = {c.get_label(): c for c in ax.containers}
        # per series, the two judging bands (x 0 and 1 shifted) and the uninformative one apart
        expected = {("calibrated (all points)", -0.12): ([0, 1], [2]),
                    ("leave-one-out", 0.12): ([0, 1], [2])}
        for (series, offset), (judging, apart) in expected.items():
            filled = drawn[f"{series}, 95 % band"].lines[0]
            hollow = drawn[f"{series}, {UNINFORMATIVE_LABEL}"].lines[0]
            # positions exact: the index plus a fixed offset, as drawn
            assert filled.get_xdata() == pytest.approx(np.add(judging, offset), abs=1e-12)
            assert hollow.get_xdata() == pytest.approx(np.add(apart, offset), abs=1e-12)
            assert to_rgba(hollow.get_markerfacecolor())[3] == 0.0  # hollow
            assert to_rgba(filled.get_markerfacecolor())[3] == 1.0
            # the bars: dashed (a dash pattern) for the uninformative, solid (none) otherwise
            (dashed,) = drawn[f"{series}, {UNINFORMATIVE_LABEL}"].lines[2][0].get_linestyle()
            (solid,) = drawn[f"{series}, 95 % band"].lines[2][0].get_linestyle()
            assert dashed[1] is not None and solid[1] is None
        legend = [t.get_text() for t in ax.get_legend().get_texts()]
        assert f"leave-one-out, {UNINFORMATIVE_LABEL}" in legend
        assert f"calibrated (all points), {UNINFORMATIVE_LABEL}" in legend
    finally:
        plt.close(figure)


def test_calibration_plot_draws_an_uninformative_band_apart_and_cut_at_its_bound():
    # Calibration.plot (plot_calibration) drew the 0 .. 25 band as a filled point with a bar
    # up to 25, past the SDC bound 16.9 no measurement is kept at, beside the judging ones
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_rgba

    from pidcore.calibrate.outputs import UNINFORMATIVE_LABEL
    from pidcore.calibrate.prediction import VERDICT_COLUMN

    result = _result()
    bound = calibrated_sdc_bound(paper_specimen(), fill_percent=50.0, material="acrylic").sdc
    frame = result.to_pandas()
    assert list(frame[VERDICT_COLUMN]) == ["yes", "yes", "uninformative"]
    assert list(frame["SDC bound [-]"]) == [bound] * 3
    assert list(frame[VERDICT_COLUMN]) == result.band_verdicts(result.predictions)
    _, ax = plt.subplots()
    try:
        assert result.plot(ax=ax) is ax
        drawn = {c.get_label(): c for c in ax.containers}
        assert set(drawn) == {"calibrated DEM, 95 % band",
                              f"calibrated DEM, {UNINFORMATIVE_LABEL}"}
        filled = drawn["calibrated DEM, 95 % band"]
        hollow = drawn[f"calibrated DEM, {UNINFORMATIVE_LABEL}"]
        assert list(filled.lines[0].get_xdata()) == [0, 1]
        assert list(hollow.lines[0].get_xdata()) == [2]
        assert to_rgba(hollow.lines[0].get_markerfacecolor())[3] == 0.0
        assert to_rgba(filled.lines[0].get_markerfacecolor())[3] == 1.0
        (dashed,) = hollow.lines[2][0].get_linestyle()
        (solid,) = filled.lines[2][0].get_linestyle()
        assert dashed[1] is not None and solid[1] is None
        # the bar ends at the bound, as predictions.png and the report cut it (exact: the
        # bar is drawn as predicted + (min(high, bound) - predicted))
        (segment,) = hollow.lines[2][0].get_segments()
        assert segment[:, 1] == pytest.approx([0.0, bound], abs=1e-12)
        cut = [line for line in ax.get_lines()
               if line.get_label() == f"SDC bound {bound:.3g}: bands cut here (model "
                                      "unconstrained above)"]
        assert len(cut) == 1 and list(cut[0].get_ydata()) == [bound, bound]
        legend = [t.get_text() for t in ax.get_legend().get_texts()]
        assert f"calibrated DEM, {UNINFORMATIVE_LABEL}" in legend
    finally:
        plt.close("all")


def test_the_summary_writes_an_uninformative_band_as_its_reason_does():
    # summary.md wrote the in-sample 0 .. 25 band "0.000 .. 16.911 (cut ...)" where the
    # report's reason, the app and the notes write "0 .. 16.91" (band_text)
    from pidcore.calibrate.outputs import summary_html, summary_markdown
    from pidcore.calibrate.prediction import CalibratedPrediction, band_text
    from pidcore.loadcase import LoadCase

    bound = calibrated_sdc_bound(paper_specimen(), fill_percent=50.0, material="acrylic")
    cell = "0 .. 16.91 (cut at the specimen's SDC bound 16.91; model 25: unconstrained)"
    assert band_text(0.0, bound.sdc) == "0 .. 16.91"  # 8 m_p/m_s of 46.8 g on 22.2 g
    rows = [line for line in summary_markdown(_result()).splitlines()
            if line.startswith("| 1000 | 5 | 50 |")]
    assert rows[0] == f"| 1000 | 5 | 50 | 0.5 | 0.47 | {cell} | -0.03 | uninformative |"
    assert f"<td>{html.escape(cell)}</td>" in summary_html(_result())  # its ' escaped
    # and the reason the report gives such a row names the same band
    hit = CalibratedPrediction(LoadCase(1000, 5, 50), 0.47, 0.0, 25.0, 0.5, 0.0, 0.0, 25.0,
                               sdc_bound=bound)
    assert hit.uninformative_reason(0.0).startswith(
        "uninformative: the calibrated 95 % band 0 .. 16.91 spans every plausible SDC")
    # a judging band is written the same way: 4 significant digits
    assert any(line.startswith("| 100 | 5 | 50 | 0.3 | 0.31 | 0.12 .. 0.55 |")
               for line in summary_markdown(_result()).splitlines())


def test_every_file_states_each_rows_verdict_and_the_in_sample_count_as_the_summary(
        tmp_path, capsys, monkeypatch):
    # summary.md judged each row (yes / no / uninformative) and counted the in-sample rows
    # (2/2 and 1 more uninformative); calibration.json and --json carried neither, so a script
    # judging low95 <= measured <= high95 itself read "yes" at the 0 .. 25 band, and the
    # command printed the in-sample RMS without its count
    from pidcore.calibrate.calibrate import ROW_VERDICT_KEY
    from pidcore.calibrate.outputs import coverage_text, summary_markdown
    from pidcore.calibrate.persist import calibration_key

    args, out = _calibrate_args_of_the_constructed_result(tmp_path, monkeypatch)
    assert main([*args, "--json", "--out", str(out)]) == 0
    printed = json.loads(capsys.readouterr().out)
    written = json.loads((out / "calibration.json").read_text())
    summary = (out / "summary.md").read_text()
    table_verdicts = [line.rstrip(" |").rsplit("| ", 1)[1].strip("*")
                      for line in summary.splitlines()
                      if line.startswith(("| 100 | 5 |", "| 500 | 5 |", "| 1000 | 5 |"))]
    for document in (printed, written):
        rows = [r[ROW_VERDICT_KEY] for r in document["predictions"] + document["loo"]]
        # the constructed rows: in-sample yes, yes, uninformative; folds yes, no, uninf.
        assert rows == table_verdicts == ["yes", "yes", "uninformative", "yes", "no",
                                          "uninformative"]
        assert (document["coverage95"], document["uninformative95"]) == (2, 1)
        assert document["units"][ROW_VERDICT_KEY] == "yes/no/uninformative"
        assert document["rms_in_sample"] == pytest.approx(_result().rms, rel=1e-12)
    assert f"RMS {rms_text_of(_result().rms)}, 2/2 inside the 95 % band (1 more " in summary
    # the command's text line says the summary's count
    assert main(args) == 0
    (line,) = [s for s in capsys.readouterr().out.splitlines()
               if s.startswith("in-sample RMS")]
    assert line == (f"in-sample RMS {rms_text_of(_result().rms)}, "
                    + coverage_text(["yes", "yes", "uninformative"]))
    assert summary_markdown(_result()) == summary
    # derived from the keyed rows: a fit saved before these fields keeps its key
    document = _result().full_document()
    older = {k: v for k, v in document.items() if k not in ("coverage95", "uninformative95")}
    older["predictions"] = [{k: v for k, v in r.items() if k != ROW_VERDICT_KEY}
                            for r in document["predictions"]]
    older["loo"] = [{k: v for k, v in r.items() if k != ROW_VERDICT_KEY}
                    for r in document["loo"]]
    older["units"] = {k: v for k, v in document["units"].items()
                      if k not in (ROW_VERDICT_KEY, "coverage95", "uninformative95",
                                   "loo_coverage95", "loo_uninformative95")}
    assert set(older["units"]) < set(document["units"])  # the units were keyed, and differ
    assert calibration_key(document) == calibration_key(older)
    moved = [dict(r) for r in older["predictions"]]
    moved[0]["predicted"] += 0.01
    assert calibration_key(document) != calibration_key({**older, "predictions": moved})


def rms_text_of(value: float) -> str:
    from pidcore.calibrate.outputs import rms_text

    return rms_text(value)


def test_summary_html_holds_the_lines_headings_and_tables_of_summary_md():
    # summary.html left out the prior bounds, the RMS of each prediction table, the
    # correlations and the energy check with its "start inside: no" verdicts, and titled the
    # in-sample table otherwise: a reader of one file saw other numbers and verdicts than a
    # reader of the other. Both are written from one content now.
    import dataclasses
    import re

    from pidcore.calibrate.outputs import summary_html, summary_markdown

    specimen = paper_specimen()
    dem = parameter_spec("rolling_friction", specimen)
    base = _result()
    result = dataclasses.replace(
        base, specs=[dem, *base.specs],
        parameters={"rolling_friction": {"median": 0.05, "low95": 0.01, "high95": 0.09,
                                         "prior_low": dem.low, "prior_high": dem.high},
                    **base.parameters},
        correlations=[[1.0, -0.25], [-0.25, 1.0]],
        energy_check=[{"frequency_hz": f, "acceleration_g": 5.0,
                       "energy_per_cycle_per_cell_start_j": start,
                       "energy_per_cycle_per_cell_calibrated_j": 1e-9, "low95_j": 5e-10,
                       "high95_j": 2e-9, "within": within}
                      for f, start, within in ((100, 1e-9, True), (500, 3e-9, False))],
        notes=["a note"], wall_s=1.5)
    text, page = summary_markdown(result), summary_html(result)

    def plain(cell: str) -> str:
        return cell.strip().strip("*")

    md_rows = [[plain(c) for c in line.strip().strip("|").split("|")]
               for line in text.splitlines() if line.startswith("|")
               and not line.startswith("|---")]
    html_rows = [[re.sub(r"</?b>", "", html.unescape(c)) for c in
                  re.findall(r"<t[dh]>(.*?)</t[dh]>", row)]
                 for row in re.findall(r"<tr>(.*?)</tr>", page)]
    assert html_rows == md_rows
    assert ["500", "5", "3e-09", "1e-09", "5e-10 .. 2e-09", "no"] in html_rows  # the miss
    assert "<td><b>no</b></td>" in page  # a miss stands out as **no** does in summary.md
    md_headings = [line[3:] for line in text.splitlines() if line.startswith("## ")]
    html_headings = [html.unescape(h) for h in re.findall(r"<h2>(.*?)</h2>", page)]
    assert html_headings == ["Posterior correlations", *md_headings, "Notes"]
    assert md_headings[0].startswith("In-sample posterior predictions: RMS ")
    for line in text.splitlines()[2:5:2]:  # the "Fitted: ..." and the specimen's lines
        assert f"<p>{html.escape(line)}</p>" in page


def test_the_summaries_write_each_sdc_as_the_report_writes_it():
    # summary.md and summary.html wrote the calibrated SDC at 3 decimals (0.083, 0.492) where
    # the report's column (format_cell) and the band beside it show 4 significant digits
    # (0.08264, 0.4921; band 0.01469 .. 0.2024): one SDC, two roundings between files
    import dataclasses

    from pidcore.calibrate.outputs import summary_html, summary_markdown
    from pidcore.report.render import format_cell

    # the bundled calibration's in-sample row at 50 Hz, 1 g
    row = {**_row(50, 0.1, 0.08264491889512958, 0.014692871979610054, 0.20244814105328074),
           "acceleration_g": 1.0}
    result = dataclasses.replace(_result(), predictions=[row], loo=None)
    text = summary_markdown(result)
    cells = next(line for line in text.splitlines() if line.startswith("| 50 | 1 | 50 |"))
    shown = [c.strip() for c in cells.strip("|").split("|")]
    assert shown[3:7] == [format_cell(0.1), format_cell(row["predicted"]),
                          f"{format_cell(row['low95'])} .. {format_cell(row['high95'])}",
                          "-0.01736"]  # 0.08264 - 0.1, to 4 significant digits
    assert shown[3:5] == ["0.1", "0.08264"]
    assert "<td>0.08264</td>" in summary_html(result)


def test_the_apps_list_of_saved_calibrations_writes_each_rms_as_the_command_does():
    # a listing with one calibration without leave-one-out (a blank) showed the other's RMS
    # as stored, 0.08119027550622598, where the command, summary.md and the calibrated file
    # write 0.0812
    from pidcore.app.calibration import saved_calibrations_table
    from pidcore.calibrate.outputs import rms_text

    listing = pd.DataFrame({"key": ["cal_a", "cal_b"], "specimen": ["paper_coupon"] * 2,
                            "fit": ["fixture_mass_kg"] * 2, "n_points": [12.0, 12.0],
                            "rms_in_sample": [0.08119027550622598, 0.14133994501447378],
                            "loo_rms": [0.0969918244662864, np.nan],
                            "loo_coverage95": [10.0, np.nan],
                            "created_utc": ["2026-12-01T00:00:00+00:00",
                                            "2026-12-01T00:01:00+00:00"]})
    table = saved_calibrations_table(listing=listing)  # newest first
    assert table["in-sample RMS [-]"].tolist() == ["0.1413", "0.0812"]
    assert table["leave-one-out RMS [-]"].tolist() == ["", "0.0970"]
    assert rms_text(0.0969918244662864) == "0.0970"


def test_the_posterior_pairs_figure_names_each_axis_unit():
    # posterior_pairs.png labelled its axes "rolling_friction", "fixture_mass_kg" and its
    # histograms' counts not at all: numbers without a unit beside the summary's table that
    # names them (parameter_units)
    import dataclasses

    import matplotlib.pyplot as plt

    from pidcore.calibrate.outputs import pairs_figure, parameter_units

    specimen = paper_specimen()
    dem = parameter_spec("rolling_friction", specimen)
    base = _result()
    result = dataclasses.replace(
        base, specs=[dem, *base.specs], samples=np.column_stack([
            np.linspace(0.01, 0.09, 50), np.linspace(0.2, 0.3, 50)]),
        parameters={"rolling_friction": {"median": 0.05, "low95": 0.01, "high95": 0.09,
                                         "prior_low": dem.low, "prior_high": dem.high},
                    **base.parameters})
    fig = pairs_figure(result)
    try:
        axes = fig.axes
        bottom = [ax.get_xlabel() for ax in axes[2:]]  # the last row: scatter, histogram
        assert bottom == ["rolling_friction [-]", "fixture_mass_kg [kg]"]
        assert parameter_units(result) == {"rolling_friction": "-", "fixture_mass_kg": "kg"}
        assert axes[2].get_ylabel() == "fixture_mass_kg [kg]"
        assert axes[0].get_ylabel() == axes[3].get_ylabel() == "posterior samples [count]"
    finally:
        plt.close(fig)


def test_the_calibrated_specimens_header_names_each_parameters_unit():
    # its header wrote "rolling_friction = 0.05  (95 %: ...)": a number without its unit,
    # where the command and the summaries write "rolling_friction [-]" and "fixture_mass_kg
    # [kg]"; the file's values (and so its hash) are not in the comments
    from pidcore.calibrate.outputs import specimen_text
    from pidcore.calibrate.posterior import summary_texts
    from pidcore.specimen import Specimen

    result = _result()
    text = specimen_text(result)
    _, low, high = summary_texts(result.parameters["fixture_mass_kg"])
    assert f"#   fixture_mass_kg [kg] = 0.02  (95 %: {low} .. {high})" in text.splitlines()
    assert Specimen.from_text(text).hash == result.calibrated_specimen().hash


def test_the_frame_the_report_and_the_summary_name_each_quantity_alike(tmp_path):
    # Calibration.to_pandas() named its verdict "measured in 95 % band [...]" where the report
    # says "measured in calibrated 95 % band [...]", and summary.md said "f [Hz]", "measured
    # SDC [-]", "predicted SDC [-]", "95 % band [-]", "inside [...]" for the same quantities:
    # a script joining them had to know three spellings. The fill of the cells was "fill [%]"
    # in the frame, the summary and the app's tables but "packing ratio [%]" in the report.
    from pidcore.app.calibration import POINT_COLUMNS
    from pidcore.app.jobs import DEM_RUN_COLUMNS
    from pidcore.calibrate.outputs import summary_markdown
    from pidcore.calibrate.prediction import CALIBRATION_COLUMNS_RENAMED
    from pidcore.compare.align import (
        CALIBRATED_BAND_COLUMN,
        CALIBRATED_COLUMN,
        CALIBRATED_HIGH_COLUMN,
        CALIBRATED_INSIDE_COLUMN,
        CALIBRATED_LOW_COLUMN,
        MEASURED_EQ11_COLUMN,
        MEASURED_EQ11_STDERR_COLUMN,
        PACKING_RATIO_COLUMN,
    )
    from pidcore.report.table import REPORT_COLUMNS, add_calibration_columns, with_band_text

    result = _result()
    frame = result.to_pandas()
    report = add_calibration_columns(pd.DataFrame({
        "frequency [Hz]": [r["frequency_hz"] for r in PREDICTIONS],
        "acceleration [g]": [r["acceleration_g"] for r in PREDICTIONS],
        PACKING_RATIO_COLUMN: [r["fill_percent"] for r in PREDICTIONS],
        "material": ["acrylic"] * 3,
        MEASURED_EQ11_COLUMN: [r["measured"] for r in PREDICTIONS],
        # the fitted points' own stderr: the report judges each by the band the frame holds
        MEASURED_EQ11_STDERR_COLUMN: [r["measured_stderr"] for r in PREDICTIONS],
        "note": [""] * 3}), result.calibration())
    head = next(line for line in summary_markdown(result).splitlines()
                if line.startswith("| frequency [Hz] |"))
    summary = [cell.strip() for cell in head.strip("|").split("|")]
    shared = ["frequency [Hz]", "acceleration [g]", PACKING_RATIO_COLUMN, MEASURED_EQ11_COLUMN,
              CALIBRATED_COLUMN, CALIBRATED_INSIDE_COLUMN]
    assert PACKING_RATIO_COLUMN == "packing ratio [%]" and PACKING_RATIO_COLUMN in REPORT_COLUMNS
    # the app's measured points and DEM runs show the fill under the report's name
    assert POINT_COLUMNS["fill_percent"] == DEM_RUN_COLUMNS["fill_percent"] == PACKING_RATIO_COLUMN
    assert not any("fill" in name for name in [*frame.columns, *summary]), (
        list(frame.columns), summary)
    for name in shared:
        assert name in frame.columns and name in report.columns and name in summary, name
    for name in (CALIBRATED_LOW_COLUMN, CALIBRATED_HIGH_COLUMN):
        assert name in frame.columns and name in report.columns
    assert CALIBRATED_BAND_COLUMN in summary and CALIBRATED_BAND_COLUMN in with_band_text(
        report).columns
    # the same quantity under the same name holds the same values in frame and report
    for name in shared:
        assert frame[name].tolist() == report[name].tolist(), name
    assert frame[CALIBRATED_INSIDE_COLUMN].tolist() == ["yes", "yes", "uninformative"]
    # every column names its unit or is a word of a closed vocabulary
    assert all(name.endswith("]") for name in frame.columns
               if name not in ("material", "direction")), list(frame.columns)
    assert all(name.endswith("]") for name in summary), summary
    # a frame of an older pidcore reads as today's
    older = frame.rename(columns={new: old for old, new in CALIBRATION_COLUMNS_RENAMED.items()})
    assert {"measured in 95 % band [yes/no/not compared/uninformative]",
            "low95 without stderr [-]", "sdc bound [-]", "fill [%]"} <= set(older.columns)
    pd.testing.assert_frame_equal(older.rename(columns=CALIBRATION_COLUMNS_RENAMED), frame)
