"""``pidcore report`` end to end: analyse, store, align, render; refusals leave nothing behind."""

from __future__ import annotations

import os
from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest

from pidcore.cli import main
from pidcore.compare import LoadCaseError
from pidcore.constants import STANDARD_GRAVITY
from pidcore.errors import StoreError
from pidcore.io import file_sha256, write_measurement
from pidcore.records import Channel, Measurement
from pidcore.report import make_report
from pidcore.report.table import ALIGNMENT_COLUMN
from pidcore.signal import synthesize_shaker_record
from pidcore.store import Store

ROOT = Path(__file__).resolve().parents[1]
FREQ_HZ = 500.0
ACC_G = 5.0
RATE_HZ = 20000.0


def _record(seed: int, damping: float):
    # rigid 0.2 kg mass with viscous damping: a clean record the analysis handles exactly
    return synthesize_shaker_record(mass_kg=0.2, acceleration_amplitude_m_s2=ACC_G
                                    * STANDARD_GRAVITY, frequency_hz=FREQ_HZ,
                                    sample_rate_hz=RATE_HZ, n_periods=40,
                                    viscous_damping_n_s_m=damping, seed=seed)


def _write_measurement(path, seed=0, damping=3.0):
    rec = _record(seed, damping)
    m = Measurement(source=str(path), channels=(
        Channel("Force", "force", rec.force_n, rec.sample_rate_hz, "N"),
        Channel("Velocity", "velocity", rec.velocity_m_s, rec.sample_rate_hz, "m/s")))
    write_measurement(m, path)
    return path


def _dem_store(path):
    """A DEM store with grid runs around the measurement, one with a virtual shaker record."""
    rec = _record(1, 2.0)
    items = []
    for fill in (25.0, 50.0):
        for acc in (1.0, 5.0):
            for freq in (100.0, 500.0):
                arrays = None
                record = {"frequency_hz": freq, "acceleration_g": acc, "fill_percent": fill,
                          "material": "acrylic", "direction": "z",
                          "sdc": 0.1 + fill / 500 + acc / 50 + freq / 5000,
                          "sdc_stderr": 0.01, "particles_per_cell": int(fill * 36 / 100),
                          "seed": 11, "cells_simulated": 8}
                if (freq, acc, fill) == (FREQ_HZ, ACC_G, 50.0):
                    arrays = {"shaker_force_n": rec.force_n, "velocity_m_s": rec.velocity_m_s,
                              "sample_time_s": np.arange(rec.force_n.size) / RATE_HZ}
                    record.update(sample_rate_hz=RATE_HZ, steady_start_cycle=2)
                items.append({"case_key": f"f{freq:g}_a{acc:g}_fill{fill:g}_seed11",
                              "record": record, "arrays": arrays})
    Store(path).add_dem_runs(items)
    return path


@pytest.fixture(scope="module")
def dem_store(tmp_path_factory):
    return _dem_store(tmp_path_factory.mktemp("dem") / "dem.h5")


@pytest.fixture(scope="module")
def e2e(tmp_path_factory, dem_store):
    folder = tmp_path_factory.mktemp("e2e")
    file = _write_measurement(folder / "coupon1_fill50_acrylic.csv")
    dem_sha = file_sha256(dem_store)
    store = folder / "store.h5"
    result = make_report([file], out_dir=folder / "report", store=store, dem_store=dem_store,
                         formats="all")
    return file, store, dem_sha, result


@pytest.mark.slow
def test_report_end_to_end(e2e, dem_store):
    file, store, dem_sha, result = e2e
    # the dem store is only read
    assert file_sha256(dem_store) == dem_sha
    # the analysis is in the store with its load case, and the table shows the stored numbers
    analyses = Store(store).list_analyses()
    assert len(analyses) == 1
    stored = analyses.iloc[0]
    assert (stored["fill_percent"], stored["material"], stored["direction"]) == \
        (50.0, "acrylic", "z")
    row = result.table[result.table["source file(s)"] != ""].iloc[0]
    assert row["SDC measured (Eq. 11) [-]"] == stored["sdc"] == result.measured[0].analysis.sdc
    assert row["SDC measured (Eq. 11) stderr [-]"] == stored["sdc_stderr"]
    assert row[ALIGNMENT_COLUMN] == "grid"
    dem_rec = Store(dem_store).get_dem_run("f500_a5_fill50_seed11").record
    assert row["SDC DEM (ours) [-]"] == dem_rec["sdc"]
    assert row["SDC DEM (paper) [-]"] == 0.5417  # Table 3, 500 Hz, 5 g, 50 %
    # every format, the comparison figure, the model families and the loop with DEM overlay
    for name in ("csv", "md", "html", "tex", "pdf", "figure:sdc_per_load_case.png",
                 "figure:sdc_vs_acceleration_acrylic_z.svg"):
        assert result.paths[name].is_file(), name
    loops = [k for k in result.paths if k.startswith("figure:loop_") and k.endswith(".png")]
    assert len(loops) == 1
    assert not any("without DEM overlay" in n for n in result.notes)
    # provenance names the input's hash and the store's hash after the analysis was added
    text = result.paths["md"].read_text(encoding="utf-8")
    assert file_sha256(file) in text and file_sha256(store) in text and dem_sha in text


@pytest.mark.usefixtures("undrawn_report_figures")
def test_report_from_store_only_uses_stored_analyses(e2e, dem_store, tmp_path):
    _, store, _, first = e2e
    again = make_report([], out_dir=tmp_path / "r2", store=store, dem_store=dem_store,
                        formats="csv")
    pd.testing.assert_frame_equal(again.table, first.table)
    # the measured loop is rebuilt from the stored phasors, with the DEM overlay
    assert [k for k in again.paths if k.startswith("figure:loop_")] == \
        [k for k in first.paths if k.startswith("figure:loop_")]
    assert not any("without DEM overlay" in n for n in again.notes)


@pytest.mark.parametrize("flag", [["--material", "stel"], ["--fill", "40"],
                                  ["--velocity-delay", "5e-5"]])
def test_load_case_and_analysis_options_without_files_are_refused(tmp_path, dem_store, capsys,
                                                                  flag):
    # a report of stored analyses keeps their load cases and corrections: such an option
    # was silently ignored (a typo in --material too, once its choices were opened)
    out = tmp_path / "out"
    assert main(["report", "--dem-store", str(dem_store), "--out", str(out), *flag]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "only with measurement FILES" in err
    assert not out.exists()


@pytest.mark.usefixtures("undrawn_report_figures")
def test_cli_with_dem_store_only_stores_nothing(tmp_path, dem_store, capsys):
    file = _write_measurement(tmp_path / "coupon2_75pct.csv", seed=3)
    code = main(["report", str(file), "--dem-store", str(dem_store), "--out",
                 str(tmp_path / "out"), "--format", "md,html"])
    out = capsys.readouterr().out
    assert code == 0
    assert "wrote md:" in out and "wrote html:" in out and "out_of_range" in out
    # the console shows the like-for-like (Eq. 10) measured SDC beside ours, and names the
    # Eq. 11 one as such (it showed only "SDC measured", the Eq. 11 value). Under report.csv's
    # name: it was headed "SDC measured (Eq. 10) [-]" here, as if Eq. 10 gave the SDC, where
    # the CSV, PDF and app say "SDC measured, E of Eq. 10 [-]" (Eq. 10 gives the energy E)
    header = out.splitlines()[0]
    assert header.index("SDC DEM (ours) [-]") < header.index("SDC measured, E of Eq. 10 [-]") \
        < header.index("SDC measured (Eq. 11) [-]")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["coupon2_75pct.csv", "out"]
    # 75 % is above our DEM fills (25, 50): never extrapolated
    html = (tmp_path / "out" / "report.html").read_text(encoding="utf-8")
    assert "not extrapolated" in html


def _corrupt_garbage(path):
    path.write_bytes(b"\x89HDF\r\n\x1a\n" + b"garbage" * 100)


def _corrupt_partial(path):
    with h5py.File(path, "w") as h5:  # root attributes but none of the groups
        h5.attrs["pidcore_store_version"] = 1


@pytest.mark.parametrize("corrupt", [_corrupt_garbage, _corrupt_partial])
def test_corrupt_store_gives_one_line_error_and_no_report(tmp_path, corrupt, capsys):
    store = tmp_path / "store.h5"
    corrupt(store)
    file = _write_measurement(tmp_path / "x_fill50.csv")
    out = tmp_path / "out"
    with pytest.raises(StoreError, match="store.h5"):
        make_report([file], out_dir=out, store=store)
    code = main(["report", str(file), "--store", str(store), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "store.h5" in err
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["store.h5", "x_fill50.csv"]


def test_missing_fill_stops_before_anything_is_stored(tmp_path, capsys):
    file = _write_measurement(tmp_path / "no_fill_here.csv")
    store = tmp_path / "store.h5"
    with pytest.raises(LoadCaseError, match="no_fill_here.csv"):
        make_report([file], out_dir=tmp_path / "out", store=store)
    assert not store.exists() and not (tmp_path / "out").exists()
    # the option states it
    code = main(["report", str(file), "--store", str(store), "--out", str(tmp_path / "out"),
                 "--fill", "50", "--format", "csv"])
    out = capsys.readouterr().out
    assert code == 0 and "wrote csv" in out and "SDC measured" in out
    assert Store(store).list_analyses().iloc[0]["fill_percent"] == 50.0


def test_identical_files_with_different_load_cases_are_refused(tmp_path):
    a = _write_measurement(tmp_path / "a_fill50.csv")
    b = tmp_path / "b_fill75.csv"
    b.write_bytes(a.read_bytes())
    with pytest.raises(LoadCaseError, match="identical contents"):
        make_report([a, b], out_dir=tmp_path / "out", store=tmp_path / "s.h5")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_fill50.csv", "b_fill75.csv"]


def test_a_later_report_replacing_a_saved_record_says_so(tmp_path):
    # The same bytes reported again under another name and fill moved the stored measurement
    # to the new load case with no word (given together, the two are refused, above).
    a = _write_measurement(tmp_path / "a_fill50.csv")
    b = tmp_path / "b_fill75.csv"
    b.write_bytes(a.read_bytes())
    store = tmp_path / "s.h5"
    first = make_report([a], out_dir=tmp_path / "one", store=store, formats="csv")
    assert not any("replaces" in n for n in first.notes)
    second = make_report([b], out_dir=tmp_path / "two", store=store, formats="csv")
    (note,) = [n for n in second.notes if "replaces" in n]
    assert note.startswith("b_fill75.csv has the same contents as the saved record a_fill50.csv")
    assert "50 %" in note and "75 %" in note
    assert Store(store).list_analyses()["fill_percent"].tolist() == [75.0]


def test_missing_dem_store_is_an_error(tmp_path):
    file = _write_measurement(tmp_path / "x_fill50.csv")
    with pytest.raises(StoreError, match="not found"):
        make_report([file], out_dir=tmp_path / "out", dem_store=tmp_path / "nope.h5")
    assert not (tmp_path / "out").exists()


@pytest.mark.usefixtures("undrawn_report_figures")
def test_cli_pool_merges_dem_settings_that_are_separate_rows_by_default(tmp_path, dem_store):
    import shutil

    # a 2-cell smoke run beside the store's 8-cell run at 500 Hz, 5 g, 50 %
    store = tmp_path / "dem.h5"
    shutil.copy(dem_store, store)
    Store(store).add_dem_run("smoke", {
        "frequency_hz": FREQ_HZ, "acceleration_g": ACC_G, "fill_percent": 50.0,
        "material": "acrylic", "direction": "z", "sdc": 9.0, "sdc_stderr": 0.5,
        "cells_simulated": 2, "seed": 11},
        parameters={"config_cells": 2, "config_seed": 11, "config_steady_cycles": 4})
    at_case = (f"{FREQ_HZ:g}", f"{ACC_G:g}", "50")

    def rows(*extra):
        out = tmp_path / ("pooled" if extra else "separate")
        assert main(["report", "--dem-store", str(store), "--out", str(out), "--format",
                     "csv", *extra]) == 0
        table = pd.read_csv(out / "report.csv")  # the CSV is the table, nothing else
        keep = [(f"{f:g}", f"{a:g}", f"{p:g}") == at_case for f, a, p in zip(
            table["frequency [Hz]"], table["acceleration [g]"], table["packing ratio [%]"],
            strict=True)]
        assert (out / "report.provenance.txt").is_file()  # notes and provenance go here
        return table[keep]

    separate = rows()
    assert len(separate) == 2 and sorted(separate["DEM runs [-]"]) == [1, 1]
    # the smoke run's 9.0 is never averaged into the 8-cell run's value
    assert 9.0 in separate["SDC DEM (ours) [-]"].tolist()
    pooled = rows("--pool")
    assert len(pooled) == 1 and pooled["DEM runs [-]"].iloc[0] == 2
    assert "--pool" in pooled["note"].iloc[0]


@pytest.mark.parametrize("content", [None, b""])
def test_missing_or_empty_file_is_named_before_its_load_case(tmp_path, capsys, content):
    # a new user's typo must read "file not found" / "empty file", not "no fill stated"
    from pidcore.cli import main

    path = tmp_path / "run.csv"
    if content is not None:
        path.write_bytes(content)
    rc = main(["report", str(path), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and str(path) in err
    assert ("file not found" if content is None else "empty file") in err
    assert not (tmp_path / "out").exists()


@pytest.mark.usefixtures("undrawn_report_figures")
def test_a_store_whose_name_is_not_utf8_is_reported_with_escapes(tmp_path, dem_store, capsys):
    # a store named s\xe9.h5 (Latin-1 bytes) failed the report after its analyses were saved:
    # "UnicodeEncodeError: 'utf-8' codec can't encode character '\udce9' ... surrogates not
    # allowed" (a traceback) where its provenance was written
    import os

    file = _write_measurement(tmp_path / "coupon1_fill50_acrylic.csv")
    store = tmp_path / os.fsdecode(b"s\xe9.h5")
    assert main(["report", str(file), "--store", str(store), "--dem-store", str(dem_store),
                 "--out", str(tmp_path / "r"), "--format", "csv,md,html"]) == 0
    capsys.readouterr()
    assert main(["report", "--store", str(store), "--out", str(tmp_path / "r2"),
                 "--format", "csv,md"]) == 0
    for folder in ("r", "r2"):
        text = (tmp_path / folder / "report.provenance.txt").read_text(encoding="utf-8")
        assert f"store: {tmp_path}/s\\xe9.h5 sha256 {file_sha256(store)}" in text


@pytest.mark.usefixtures("undrawn_report_figures")
def test_one_dem_store_given_under_several_spellings_is_read_and_listed_once(tmp_path,
                                                                              dem_store):
    # --dem-store d.h5 --dem-store /abs/d.h5 --dem-store link.h5 listed the one file three
    # times in the provenance (each "store: ... sha256" the same digest)
    import os

    link = tmp_path / "link.h5"
    link.symlink_to(dem_store)
    rel = os.path.relpath(dem_store)
    result = make_report([], out_dir=tmp_path / "r", dem_store=[dem_store, rel, link],
                         formats="csv")
    text = (tmp_path / "r" / "report.provenance.txt").read_text(encoding="utf-8")
    digest = file_sha256(dem_store)
    assert text.count(f"sha256 {digest}") == 1
    assert f"store: {dem_store} sha256 {digest}" in text  # the first spelling given
    alone = make_report([], out_dir=tmp_path / "r1", dem_store=dem_store, formats="csv")
    pd.testing.assert_frame_equal(result.table, alone.table)


def test_a_store_kept_in_an_earlier_report_folder_is_never_replaced_with_it(tmp_path,
                                                                           dem_store, capsys):
    # report FILES --store rp/s.h5 --out rp (rp an earlier report): the analyses were saved
    # to rp/s.h5, then rp was replaced whole by the new report, the store with it
    out = tmp_path / "rp"
    assert main(["report", "--dem-store", str(dem_store), "--out", str(out),
                 "--format", "csv"]) == 0
    store = out / "s.h5"
    file = _write_measurement(tmp_path / "coupon1_fill50_acrylic.csv")
    assert main(["analyze", str(file), "--store", str(store)]) == 0
    before = store.read_bytes()
    report_csv = (out / "report.csv").read_bytes()
    capsys.readouterr()
    assert main(["report", str(file), "--store", str(store), "--dem-store", str(dem_store),
                 "--out", str(out), "--format", "csv"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "holds 's.h5', which pidcore report did not write" in err
    assert store.read_bytes() == before and (out / "report.csv").read_bytes() == report_csv
    # an earlier report holding only what a report writes is replaced as before
    store.unlink()
    assert main(["report", "--dem-store", str(dem_store), "--out", str(out),
                 "--format", "all"]) == 0
    assert main(["report", "--dem-store", str(dem_store), "--out", str(out),
                 "--format", "csv"]) == 0
    assert not (out / "report.md").exists()


@pytest.mark.slow
def test_a_baseline_taken_off_the_whole_vibrated_mass_is_said_in_the_report(tmp_path,
                                                                            dem_store):
    # `pidcore analyze --baseline-loss-factor` without --structure-mass notes that the
    # subtraction is too large; the report compared that SDC with the DEM without a word,
    # whether from the files, from the files saved in a store, or from the store alone
    file = _write_measurement(tmp_path / "coupon1_fill50_acrylic.csv")
    said = "subtracted as if the whole vibrated mass were the empty structure's"

    def notes(*args, out):
        assert main(["report", *args, "--dem-store", str(dem_store), "--format", "md",
                     "--out", str(tmp_path / out)]) == 0
        return (tmp_path / out / "report.md").read_text(encoding="utf-8")

    baseline = ["--baseline-loss-factor", "0.001"]  # below the record's 0.0048
    assert said in notes(str(file), *baseline, out="files")
    assert said in notes(str(file), *baseline, "--store", str(tmp_path / "s.h5"), out="saved")
    assert said in notes("--store", str(tmp_path / "s.h5"), out="stored")
    # the exact subtraction (half the 0.2 kg rigid mass the structure) and none: no note
    assert said not in notes(str(file), *baseline, "--structure-mass", "0.1", out="exact")
    assert said not in notes(str(file), out="none")


def test_a_store_of_several_measurements_is_reported_with_the_key_its_refusal_names(
        tmp_path, capsys):
    # `report STORE.h5` said "choose one with --key NAME", a flag report did not have
    import json
    from pathlib import Path

    samples = Path(__file__).resolve().parents[1] / "data_samples" / "exports"
    files = [str(samples / "synthetic_f500Hz_a1g_fill50_acrylic.csv"),
             str(samples / "synthetic_f500Hz_a5g_fill50_acrylic.mat")]
    held = tmp_path / "held.h5"
    assert main(["analyze", *files, "--store", str(held), "--fill", "50", "--no-progress"]) == 0
    capsys.readouterr()
    out = tmp_path / "report"
    assert main(["report", str(held), "--fill", "50", "--out", str(out), "--format", "csv",
                 "--dem-store", str(samples.parent / "dem_table3.h5")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "choose one with --key NAME" in err, err
    assert not out.exists()
    # each key beside the file it was imported from: the bare hashes said nothing of which
    # test is which (`analyze STORE.h5` lists them the same way)
    listing = Store(held).list_measurements()
    for key, source in zip(listing["key"], listing["source"], strict=True):
        assert f"{key} ({Path(source).name})" in err, err
    assert {Path(f).name for f in files} == {Path(s).name for s in listing["source"]}
    key = listing["key"].iloc[0]
    assert main(["report", str(held), "--key", key, "--fill", "50", "--out", str(out),
                 "--format", "csv", "--dem-store", str(samples.parent / "dem_table3.h5")]) == 0
    capsys.readouterr()
    assert main(["analyze", str(held), "--key", key, "--fill", "50", "--no-store",
                 "--json"]) == 0
    (analyzed,) = json.loads(capsys.readouterr().out)["records"]
    table = pd.read_csv(out / "report.csv")
    # the measurement the key names, analysed as `analyze --key` analyses it, bit for bit
    assert list(table["SDC measured (Eq. 11) [-]"].dropna()) == [analyzed["sdc"]]


@pytest.mark.usefixtures("undrawn_report_figures")
def test_markup_in_a_file_name_reads_as_typed_in_the_markdown_report(tmp_path, dem_store):
    # report.md passed a file name's raw HTML and link syntax to the viewer: "<b>" turned the
    # row bold and "[x](javascript:...)" became a link (the HTML and LaTeX were escaped)
    name = "<b>c<img src=x onerror=alert(1)>[x](javascript:alert(1))`k`_fill50_acrylic.csv"
    file = _write_measurement(tmp_path / name)
    result = make_report([file], out_dir=tmp_path / "r", dem_store=dem_store, formats="md")
    text = result.paths["md"].read_text(encoding="utf-8")
    assert (r"\<b\>c\<img src=x onerror=alert(1)\>\[x\](javascript:alert(1))\`k\`"
            "_fill50_acrylic.csv") in text
    assert "<b>" not in text.replace(r"\<b\>", "") and "<img" not in text.replace(r"\<img", "")
    assert "[x](" not in text.replace(r"\[x\](", "")


def test_report_files_without_a_store_keep_only_the_channels_used(tmp_path):
    # a report of files it saves nowhere held every channel of every file until the last was
    # analysed; saved to a store, each file keeps all of its channels
    from pidcore.report.pipeline import analyze_files

    rec = _record(0, 3.0)
    path = tmp_path / "wide.csv"
    write_measurement(Measurement(source=str(path), channels=(
        Channel("Force", "force", rec.force_n, rec.sample_rate_hz, "N"),
        Channel("Mic", "pressure", np.ones(rec.force_n.size), rec.sample_rate_hz, "Pa"),
        Channel("Velocity", "velocity", rec.velocity_m_s, rec.sample_rate_hz, "m/s"))), path)
    (whole,) = analyze_files([path], fill_percent=50.0)
    (lean,) = analyze_files([path], fill_percent=50.0, keep_unused_channels=False)
    assert whole.measurement.channel_names == ["Force", "Mic", "Velocity"]
    assert lean.measurement.channel_names == ["Force", "Velocity"]
    assert lean.analyzed.to_dict() == whole.analyzed.to_dict()


@pytest.mark.usefixtures("undrawn_report_figures")
def test_the_load_case_table_a_report_read_is_listed_with_its_hash(tmp_path, dem_store):
    # the sidecar sets each file's load case and settings (a 50 us delay moves the bundled
    # 500 Hz SDC from 2.81 to 4.09), but the provenance listed only the exports and stores
    file = _write_measurement(tmp_path / "coupon1.csv")
    table = tmp_path / "cases.csv"
    table.write_text("file,fill_percent,velocity_delay_us\ncoupon1.csv,50,20\n",
                     encoding="utf-8")
    make_report([file], out_dir=tmp_path / "r", dem_store=dem_store, formats="csv",
                sidecar=table)
    text = (tmp_path / "r" / "report.provenance.txt").read_text(encoding="utf-8")
    assert f"input: cases.csv sha256 {file_sha256(table)}" in text
    # one beside the files, read by default, is listed as well
    beside = tmp_path / "loadcases.csv"
    beside.write_text("file,fill_percent\ncoupon1.csv,50\n", encoding="utf-8")
    make_report([file], out_dir=tmp_path / "r2", dem_store=dem_store, formats="csv")
    text = (tmp_path / "r2" / "report.provenance.txt").read_text(encoding="utf-8")
    assert f"input: loadcases.csv sha256 {file_sha256(beside)}" in text


@pytest.mark.usefixtures("undrawn_report_figures")
def test_what_the_reader_corrected_is_said_in_the_report_as_analyze_says_it(tmp_path,
                                                                             dem_store):
    # a spreadsheet's empty rows after the data were left out with a note that `analyze`
    # printed and the report did not
    file = _write_measurement(tmp_path / "coupon1_fill50_acrylic.csv")
    file.write_text(file.read_text(encoding="utf-8") + ",,\n" * 2, encoding="utf-8")
    result = make_report([file], out_dir=tmp_path / "r", dem_store=dem_store, formats="csv")
    said = [n for n in result.notes if "hold only delimiters" in n]
    assert said == ["coupon1_fill50_acrylic.csv: 2 row(s) after the last data row hold only "
                    "delimiters (a spreadsheet's empty rows); not read"]
    text = (tmp_path / "r" / "report.provenance.txt").read_text(encoding="utf-8")
    assert said[0] in text


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc, where no "
                    "folder can be made, not even by root")
def test_an_output_folder_that_cannot_be_made_is_refused_in_one_line_before_any_analysis(
        tmp_path, dem_store, capsys):
    # /proc/x: a FileNotFoundError traceback at the write, after the files were analysed
    # and saved; chmod cannot stand in, as root may write a read-only folder
    file = _write_measurement(tmp_path / "coupon_fill50.csv")
    store = tmp_path / "store.h5"
    code = main(["report", str(file), "--store", str(store), "--dem-store", str(dem_store),
                 "--out", "/proc/pidcore_report", "--format", "csv"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert "/proc/pidcore_report" in err and "No such file or directory" in err
    assert not store.exists()  # refused before the analysis was saved
    for command in (["model", "figures", "--out", "/proc/pidcore_out"],
                    ["samples", "make", "--skip-sweep", "--out", "/proc/pidcore_out"]):
        assert main(command) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "/proc/pidcore_out" in err, err


def test_a_report_past_a_file_size_limit_is_one_line_and_leaves_no_part_of_it(tmp_path,
                                                                              dem_store):
    # a full disk fails the same writes (ENOSPC) as a file size limit (EFBIG, Python ignores
    # SIGXFSZ): an OSError traceback after the whole computation, where the README promises
    # one line, exit 2; 20 kB holds the CSV but no report's figure PNG (a few 10 kB each)
    import resource
    import subprocess
    import sys

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))

    out = tmp_path / "report"
    run = subprocess.run([sys.executable, "-m", "pidcore", "report", "--dem-store",
                          str(dem_store), "--out", str(out), "--format", "csv"],
                         capture_output=True, text=True, timeout=300, preexec_fn=limit,
                         env={**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"})
    assert run.returncode == 2, run.stderr[-2000:]
    assert run.stderr.count("\n") == 1 and "File too large" in run.stderr, run.stderr
    assert f"{out} not created" in run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nor a build folder beside it


def _with_smoke_run(tmp_path, dem_store, sdc=9.0):
    """A copy of ``dem_store`` with a 2-cell run beside its 8-cell run at 500 Hz, 5 g, 50 %."""
    import shutil

    store = tmp_path / "dem.h5"
    shutil.copy(dem_store, store)
    Store(store).add_dem_run("smoke", {
        "frequency_hz": FREQ_HZ, "acceleration_g": ACC_G, "fill_percent": 50.0,
        "material": "acrylic", "direction": "z", "sdc": sdc, "sdc_stderr": 0.5,
        "cells_simulated": 2, "seed": 11},
        parameters={"config_cells": 2, "config_seed": 11, "config_steady_cycles": 4})
    return store


def test_the_model_figures_mark_only_the_runs_their_caption_says_the_model_rests_on(
        tmp_path, dem_store):
    # the 2-cell run's 9.0 was drawn as a data point of the model whose caption says the
    # runs of other settings at that load case are left out of it
    from pidcore.report.pipeline import report_figures, specimen_report_table

    runs = Store(_with_smoke_run(tmp_path, dem_store)).list_dem_runs()
    built = specimen_report_table(runs, None)
    notes: list[str] = []
    figures = report_figures(built.table, built.dem_runs, built.aligner, [], [], notes)
    for name in ("sdc_vs_acceleration_acrylic_z", "sdc_vs_frequency_acrylic_z"):
        fig = figures[name]
        assert "runs of other settings left out" in fig._suptitle.get_text()
        marked = [float(y) for ax in fig.axes for line in ax.get_lines()
                  if line.get_label().endswith(" data") for y in line.get_ydata()]
        # every 8-cell run is marked (8 grid points, each drawn in one panel), the 2-cell
        # one's value exactly never (the grid's SDCs are below 0.5)
        assert len(marked) == 8 and 9.0 not in marked, (name, marked)
        fig.clear()


def test_a_pooled_report_keeps_each_tests_specimen_and_the_runs_it_meets(tmp_path, dem_store):
    # tests of a specimen of one's own (steel particles) lost their specimen under pool=True
    # and were said to have "no DEM runs of paper_coupon"; they are compared as without it
    from pidcore.report.pipeline import specimen_report_table

    runs = Store(_with_smoke_run(tmp_path, dem_store)).list_dem_runs()
    analyses = pd.DataFrame({
        "frequency_hz": [FREQ_HZ] * 2, "acceleration_g": [ACC_G] * 2, "fill_percent": [50.0] * 2,
        "material": ["steel", "acrylic"], "direction": ["z"] * 2, "sdc": [0.4, 0.6],
        "sdc_stderr": [0.01, 0.01], "energy_per_cycle_j": [1e-5] * 2,
        "source": ["own.csv", "paper.csv"], "specimen": ["own", ""]})
    apart, pooled = (specimen_report_table(runs, analyses, pool=pool).table
                     for pool in (False, True))
    for table in (apart, pooled):
        own = table[table["source file(s)"] == "own.csv"]
        assert own["specimen"].tolist() == ["own"], table
        assert own[ALIGNMENT_COLUMN].tolist() == ["no_dem_runs"]
        assert "own" in own["note"].iloc[0] and "paper_coupon for steel" not in \
            own["note"].iloc[0], own["note"].iloc[0]
    # the specimens' tests are never one row; the DEM settings are, pooled
    assert pooled["source file(s)"].tolist().count("own.csv") == 1
    paper = pooled[pooled["source file(s)"] == "paper.csv"].iloc[0]
    assert paper["DEM runs [-]"] == 2 and "(pool=True)" in paper["note"]
