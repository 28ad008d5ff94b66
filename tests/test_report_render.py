"""Report files: CSV round trip, Markdown, self-contained HTML, booktabs LaTeX, PDF, atomicity."""

from __future__ import annotations

import base64
import re
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from pidcore.errors import ParameterError
from pidcore.model import load_paper_table3
from pidcore.out_folder import RECORD_NAME
from pidcore.report import (
    RENDERERS,
    REPORT_MARKER,
    build_report_table,
    collect_provenance,
    parse_formats,
    write_report,
)

INPUT_SHA = "ab" * 32


@pytest.fixture(scope="module")
def table():
    dem = pd.DataFrame({"frequency_hz": [50.0, 500.0, 500.0], "acceleration_g": [5.0, 5.0, 5.0],
                        "fill_percent": [50.0, 50.0, 25.0], "material": ["acrylic"] * 3,
                        "direction": ["z"] * 3, "sdc": [0.19, 0.55, 1.5702e-4],
                        "sdc_stderr": [0.004, 0.01, 2e-6], "case_key": ["a", "b", "c"]})
    analyses = pd.DataFrame({"frequency_hz": [500.2], "acceleration_g": [4.95],
                             "fill_percent": [50.0], "sdc": [0.62], "sdc_stderr": [0.03],
                             "source": ["run_50%_a&b_#1.uff"]})  # LaTeX/Markdown specials
    return build_report_table(dem, analyses, load_paper_table3())


@pytest.fixture(scope="module")
def provenance(tmp_path_factory):
    store = tmp_path_factory.mktemp("prov") / "store.h5"
    store.write_bytes(b"not really a store, just bytes to hash")
    return collect_provenance(parameters={"velocity_delay_s": 0.0}, seeds=[3, 1, 3],
                              inputs=["in/run.uff"], input_hashes={"in/run.uff": INPUT_SHA},
                              stores=[store], notes=["a note"],
                              created_utc=datetime(2026, 1, 2, 3, 4, 5, tzinfo=UTC))


def _figures():
    fig = Figure(figsize=(3, 2))
    ax = fig.subplots()
    ax.plot(np.arange(5), np.arange(5) ** 2)
    return {"parabola": fig}


@pytest.fixture(scope="module")
def report(tmp_path_factory, table, provenance):
    out = tmp_path_factory.mktemp("rep") / "report"
    return out, write_report(table, _figures(), provenance, out, "all")


def test_every_format_and_figure_is_written(report):
    out, paths = report
    for name in ("csv", "csv_provenance", "md", "html", "tex", "pdf", "figure:parabola.png",
                 "figure:parabola.svg"):
        assert paths[name].is_file() and paths[name].parent.is_relative_to(out)
    assert paths["figure:parabola.png"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert b"<svg" in paths["figure:parabola.svg"].read_bytes()[:1000]
    assert (out / REPORT_MARKER).is_file()


def test_csv_reads_back_equal_to_the_table(report, table):
    # No comment= option: the CSV holds exactly the table (notes go to a sidecar file), so a
    # spreadsheet or a plain read_csv reads no junk rows.
    back = pd.read_csv(report[1]["csv"])
    assert len(back) == len(table)
    text_cols = [c for c in table.columns if not pd.api.types.is_numeric_dtype(table[c])]
    for c in text_cols:  # an all-empty text column reads back as NaN floats
        back[c] = back[c].astype(object).where(back[c].notna(), "")
    # exact: floats are written as repr and parsed back bit for bit
    pd.testing.assert_frame_equal(back, table, check_dtype=False, check_exact=True)


def test_provenance_footer_in_every_text_format(report, provenance):
    store_sha = provenance.stores[0][1]
    for name in ("csv_provenance", "md", "html", "tex"):
        text = report[1][name].read_text(encoding="utf-8")
        assert INPUT_SHA in text and store_sha in text, name
        assert "2026-01-02T03:04:05+00:00" in text and "seeds: 1, 3" in text
        assert f"numpy {np.__version__}" in text


def test_markdown_table_shape(report, table):
    lines = report[1]["md"].read_text(encoding="utf-8").splitlines()
    rows = [ln for ln in lines if ln.startswith("|")]
    assert len(rows) == len(table) + 2  # header, separator, rows
    # an escaped pipe does not split a cell: every row has as many cells as the header
    cells = [len(re.split(r"(?<!\\)\|", r)) for r in rows]
    assert len(set(cells)) == 1 and cells[0] == len(table.columns) + 2
    assert "![parabola](figures/parabola.png)" in lines


def test_html_is_self_contained(report):
    text = report[1]["html"].read_text(encoding="utf-8")
    assert not re.search(r"""(src|href)\s*=\s*["']?\s*(https?:|//)""", text, re.I)
    assert "<script" not in text.lower() and "<link" not in text.lower()
    match = re.search(r'<img [^>]*src="data:image/png;base64,([A-Za-z0-9+/=]+)"', text)
    assert match and base64.b64decode(match.group(1))[:4] == b"\x89PNG"
    assert "run_50%_a&amp;b_#1.uff" in text  # escaped, not raw HTML


def test_latex_uses_booktabs_and_escapes(report, table):
    text = report[1]["tex"].read_text(encoding="utf-8")
    assert r"\usepackage{booktabs}" in text
    top, mid, bottom = text.index(r"\toprule"), text.index(r"\midrule"), \
        text.index(r"\bottomrule")
    assert top < mid < bottom
    body = text[mid:bottom].splitlines()[1:]
    assert len([ln for ln in body if ln.endswith(r"\\")]) == len(table)
    assert r"run\_50\%\_a\&b\_\#1.uff" in text
    assert text.count(r"\begin{") == text.count(r"\end{")


def test_latex_braces_a_dotted_figure_name_off_its_extension(tmp_path, table, provenance):
    """A loop figure is named by its load case (loop_00_f62.5Hz_a1.5g_...): graphicx before
    2019 took the first dot for the extension's and the .tex did not compile. The base name
    is braced, leaving ".png" the only dot graphicx reads, and names the file written."""
    stem = "loop_00_f62.5Hz_a1.5g_fill50pct_acrylic_z"
    paths = write_report(table, {stem: _figures()["parabola"]}, provenance,
                         tmp_path / "report", "all")
    text = paths["tex"].read_text(encoding="utf-8")
    links = re.findall(r"\\includegraphics\[[^]]*\]\{\{([^{}]+)\}(\.[a-z]+)\}", text)
    assert links == [(f"figures/{stem}", ".png")]
    assert (paths["tex"].parent / (links[0][0] + links[0][1])).read_bytes()[:4] == b"\x89PNG"


def test_pdf_has_table_figure_and_provenance_pages(report):
    data = report[1]["pdf"].read_bytes()
    assert data.startswith(b"%PDF")
    pages = len(re.findall(rb"/Type\s*/Page\b(?!s)", data))
    assert pages >= 3  # table, the one figure, provenance


def test_failure_in_one_renderer_leaves_the_earlier_report_unchanged(
        tmp_path, table, provenance, monkeypatch):
    out = tmp_path / "out"
    write_report(table, _figures(), provenance, out, ("csv", "md"))
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}

    def broken(*args, **kwargs):
        raise RuntimeError("renderer failed")

    monkeypatch.setitem(RENDERERS, "html", broken)
    with pytest.raises(RuntimeError, match="renderer failed"):
        write_report(table.iloc[:1], _figures(), provenance, out, "all")
    after = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert after == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no temporary left


def test_failure_on_a_new_folder_creates_nothing(tmp_path, table, provenance, monkeypatch):
    monkeypatch.setitem(RENDERERS, "pdf", lambda *a, **k: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        write_report(table, {}, provenance, tmp_path / "new", "all")
    assert list(tmp_path.iterdir()) == []


def test_success_replaces_an_earlier_report(tmp_path, table, provenance):
    out = tmp_path / "out"
    write_report(table, _figures(), provenance, out, "all")
    paths = write_report(table, {}, provenance, out, "csv")
    assert sorted(p.name for p in out.iterdir()) == sorted([REPORT_MARKER, RECORD_NAME,
                                                            "report.csv",
                                                            "report.provenance.txt"])
    assert paths == {"csv": out / "report.csv", "csv_provenance": out / "report.provenance.txt"}


def test_unrelated_folder_is_never_replaced(tmp_path, table, provenance):
    (tmp_path / "mine.txt").write_text("precious")
    with pytest.raises(ParameterError, match="choose a new or empty folder"):
        write_report(table, {}, provenance, tmp_path, "csv")
    assert [p.name for p in tmp_path.iterdir()] == ["mine.txt"]


def _snapshot(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in folder.rglob("*") if p.is_file()}


@pytest.mark.parametrize("added", ["figures/my_annotated_plot.png", "cases/mysheet.pdf"])
def test_a_file_added_to_an_earlier_report_is_refused_naming_it_and_kept(tmp_path, table,
                                                                         provenance, added):
    # a user's figures/*.png or cases/*.pdf was taken for the report's own by its name alone,
    # and deleted with the earlier report (exit 0); only what the report wrote is replaced
    out = tmp_path / "rp"
    write_report(table, _figures(), provenance, out, "csv", case_sheets={"c1.pdf": b"%PDF-1"})
    (out / added).parent.mkdir(exist_ok=True)
    (out / added).write_bytes(b"mine")
    before = _snapshot(out)
    with pytest.raises(ParameterError) as caught:
        write_report(table, {}, provenance, out, "csv")
    assert str(caught.value) == (
        f"out_dir {out}: holds {added!r}, which pidcore report did not write there and "
        "replacing its earlier outputs whole would delete; move it out or choose a new or "
        "empty folder for out_dir")
    assert _snapshot(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rp"]  # no build folder left
    # moved out, the earlier report alone is replaced as before
    (out / added).unlink()
    write_report(table, {}, provenance, out, "csv")
    assert sorted(p.name for p in out.iterdir()) == sorted([REPORT_MARKER, RECORD_NAME,
                                                            "report.csv",
                                                            "report.provenance.txt"])


def test_an_edited_report_file_is_refused_and_a_deleted_one_is_no_loss(tmp_path, table,
                                                                        provenance):
    out = tmp_path / "rp"
    write_report(table, _figures(), provenance, out, ("csv", "md"))
    # the user's edit of the written report.md would be lost with it: refused
    (out / "report.md").write_text("my annotated report", encoding="utf-8")
    before = _snapshot(out)
    with pytest.raises(ParameterError, match=r"holds 'report.md' changed since pidcore report "
                                             r"wrote it, which replacing its earlier outputs "
                                             r"whole would lose"):
        write_report(table, {}, provenance, out, "csv")
    assert _snapshot(out) == before
    # a written file removed since loses nothing: the report is replaced
    (out / "report.md").unlink()
    (out / "figures" / "parabola.svg").unlink()
    write_report(table, {}, provenance, out, "csv")
    assert not (out / "figures").exists() and (out / "report.csv").is_file()


def test_a_folder_with_no_record_of_its_files_is_refused_even_an_earlier_versions_report(
        tmp_path, table, provenance):
    # an earlier pidcore's report folder records no files: a figure of the user's in it
    # cannot be told from the report's, so it is refused rather than guessed at
    out = tmp_path / "rp"
    write_report(table, _figures(), provenance, out, "csv")
    (out / RECORD_NAME).unlink(missing_ok=True)  # as an earlier pidcore wrote it
    before = _snapshot(out)
    with pytest.raises(ParameterError) as caught:
        write_report(table, {}, provenance, out, "csv")
    assert str(caught.value).startswith(f"out_dir {out}: is not empty (") and \
        f"holds no record of what pidcore wrote there ({RECORD_NAME}" in str(caught.value)
    assert _snapshot(out) == before


def test_an_out_dir_that_links_to_a_folder_is_replaced_where_it_points_and_stays_a_link(
        tmp_path, table, provenance):
    # `ln -s real link; pidcore report --out link`: the link was renamed over by a real
    # folder and the report it pointed to left as it was
    real, link = tmp_path / "real", tmp_path / "link"
    write_report(table, _figures(), provenance, real, "all")
    link.symlink_to(real)
    paths = write_report(table, {}, provenance, link, "csv")
    assert link.is_symlink() and link.resolve() == real.resolve()
    assert sorted(p.name for p in real.iterdir()) == sorted([REPORT_MARKER, RECORD_NAME,
                                                             "report.csv",
                                                             "report.provenance.txt"])
    assert paths["csv"] == link / "report.csv"  # as the user named it
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]
    # a link to a folder yet to be made gets it, made where it points
    (tmp_path / "dangling").symlink_to(tmp_path / "later")
    write_report(table, {}, provenance, tmp_path / "dangling", "csv")
    assert (tmp_path / "dangling").is_symlink() and (tmp_path / "later" / "report.csv").is_file()


def test_parse_formats():
    assert parse_formats("all") == ("csv", "md", "html", "tex", "pdf")
    assert parse_formats("pdf,csv,pdf") == ("pdf", "csv")
    with pytest.raises(ParameterError, match="docx"):
        parse_formats("docx")


@pytest.mark.parametrize("moment", ["before the write", "during the swap"])
def test_ctrl_c_says_whether_the_report_was_written(tmp_path, table, provenance, monkeypatch,
                                                    capsys, moment):
    # `timeout -s INT 4 pidcore report ... --out rp` said "rp may hold part of this run's
    # files" (and "no store write was left half-done" with no FILES and no write): rp is
    # replaced whole or not at all, and was as it was. A Ctrl-C during the swap is delivered
    # once the swap and the old report's removal are done (no '.rp.*.old' folder left).
    import os
    import signal

    import pidcore.out_folder as out_folder
    import pidcore.report.pipeline as pipeline
    from pidcore.cli import main

    out = tmp_path / "rp"
    write_report(table, {}, provenance, out, "csv")
    old_csv = (out / "report.csv").read_bytes()
    move = out_folder.replace_folder

    def sigint_during_the_swap(tmp, out_dir):
        move(tmp, out_dir)
        os.kill(os.getpid(), signal.SIGINT)  # lands in the handler main() installed

    def make_report(files, *, out_dir, **kwargs):
        if moment == "before the write":
            raise KeyboardInterrupt
        monkeypatch.setattr(out_folder, "replace_folder", sigint_during_the_swap)
        write_report(table.iloc[:1], {}, provenance, out_dir, "csv")
        raise AssertionError("the interrupt was not delivered after the swap")

    monkeypatch.setattr(pipeline, "make_report", make_report)
    assert main(["report", "--store", str(tmp_path / "s.h5"), "--out", str(out)]) == 130
    err = capsys.readouterr().err
    if moment == "before the write":
        assert err == f"pidcore report: interrupted; {out} is as it was (a report is written " \
                      "whole or not at all)\n"
        assert (out / "report.csv").read_bytes() == old_csv
        # a folder that never existed is "not created", not "as it was"
        new = tmp_path / "new_rp"
        assert main(["report", "--store", str(tmp_path / "s.h5"), "--out", str(new)]) == 130
        assert capsys.readouterr().err == (f"pidcore report: interrupted; {new} not created (a "
                                           "report is written whole or not at all)\n")
        assert not new.exists()
    else:
        assert err == f"pidcore report: interrupted; the report was written to {out} before " \
                      "it\n"
        assert (out / "report.csv").read_bytes() != old_csv
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rp"]  # no temporary or .old left


def test_writing_shows_a_bar_over_figures_and_formats_only_when_asked(tmp_path, table,
                                                                      provenance, capsys):
    """A report of forty files spent 35 s on its figures and PDF with no sign of life."""
    write_report(table, _figures(), provenance, tmp_path / "quiet", ("csv", "md"))
    assert capsys.readouterr().err == ""
    write_report(table, _figures(), provenance, tmp_path / "shown", ("csv", "md"),
                 progress=True)
    err = capsys.readouterr().err
    # one figure and two formats: three files (tqdm skips redraws closer than 0.1 s: which)
    assert "writing report" in err and "0/3" in err, repr(err)
    assert re.search(r"\b[123]/3\b", err), repr(err)


def test_provenance_says_its_parameters_as_quantities_with_units_not_keywords():
    # the footer read "parameters: velocity_delay_s=5e-05, structure_mass_kg=0.0222, ...", the
    # Python keywords, where a reader of the report expects the quantity and its unit (the
    # words and units of the notes and the settings table, the app's fields)
    from dataclasses import fields

    from pidcore.compare import Tolerances
    from pidcore.measure import AnalysisOptions

    options = AnalysisOptions(
        force="Fz", velocity="V", acceleration="A", velocity_delay_s=5e-5,
        mass_below_gauge_kg=0.012, baseline_loss_factor=0.002, structure_mass_kg=0.0222,
        frequency_hz=500.0, n_harmonics=3, sample_rate_hz=25600.0, allow_clipped=True,
        force_unit="kN", velocity_unit="mm/s", acceleration_unit="g", invert=("Fz", "V"))
    tolerances = Tolerances()
    parameters = {**options.parameters(),
                  **{f.name: getattr(tolerances, f.name) for f in fields(tolerances)},
                  "pool": True}
    line = collect_provenance(parameters=parameters).lines()[2]
    assert line == (
        "parameters: force channel 'Fz'; velocity channel 'V'; acceleration channel 'A'; "
        "vibrometer delay 50 µs; mass below gauge 12 g; baseline loss factor 0.002; "
        "structure mass 22.2 g; drive frequency hint 500 Hz; harmonics analysed 3; "
        "sample rate 25600 Hz; clipped samples kept; force unit 'kN'; velocity unit 'mm/s'; "
        "acceleration unit 'g'; inverted 'Fz', 'V'; frequency tolerance 1 %; acceleration "
        "tolerance 5 %; fill tolerance 0.5 percentage points; DEM settings and specimens "
        "pooled yes")
    # every option a report can list has words: a keyword in the line is one without
    assert not re.search(r"\w_\w|=", line)
    # one that differs between files: per file, in the same words
    per_file = collect_provenance(parameters={
        "velocity_delay_s": {"a_fill50.csv": 0.0, "b_fill50.csv": 2e-4},
        "structure_mass_kg": {"a_fill50.csv": None, "b_fill50.csv": 0.0483}}).lines()[2]
    assert per_file == ("parameters: vibrometer delay 0 µs (a_fill50.csv), 200 µs "
                        "(b_fill50.csv); structure mass none (a_fill50.csv), 48.3 g "
                        "(b_fill50.csv)")


def test_a_saved_analysis_parameters_read_alike_by_the_report_and_compare():
    # the report's provenance and Compare's corrections each read a record's parameters_json
    # (and its refusal of a non-object or broken text) themselves: one reader now
    import pandas as pd

    from pidcore.compare.case import saved_parameters
    from pidcore.report.pipeline import stored_parameters

    texts = ['{"velocity_delay_s": 5e-05}', "[1, 2]", "{not json", float("nan")]
    assert [saved_parameters(t) for t in texts] == [{"velocity_delay_s": 5e-05}, {}, {}, {}]
    analyses = pd.DataFrame({"file": ["a.csv", "b.csv", "c.csv", "d.csv"],
                             "parameters_json": texts})
    # one file's delay, none known of the others: said per file, not taken as shared
    assert stored_parameters(analyses) == {
        "velocity_delay_s": {"a.csv": 5e-05, "b.csv": None, "c.csv": None, "d.csv": None}}


def test_pdf_table_sets_the_like_for_like_measured_sdc_beside_ours():
    # the PDF showed only the Eq. 11 SDC (1.139) beside our DEM's 0.6054 at 50 Hz, 5 g, 50 %:
    # a reader saw a factor 2 where the like-for-like Eq. 10 value, 0.624, agrees within
    # 0.019; nor did it show the calibrated prediction or the band verdict
    from pidcore.report.render import pdf_table_cells
    from pidcore.report.table import (
        ALIGNMENT_COLUMN,
        CALIBRATED_COLUMN,
        CALIBRATED_INSIDE_COLUMN,
        DIFFERENCE_COLUMN,
        MEASURED_EQ10_COLUMN,
        REPORT_COLUMNS,
    )

    row = dict.fromkeys(REPORT_COLUMNS, float("nan"))
    row.update({"frequency [Hz]": 50.0, "acceleration [g]": 5.0, "packing ratio [%]": 50.0,
                "SDC DEM (ours) [-]": 0.6054300359935463, "SDC measured (Eq. 11) [-]": 1.1394946,
                MEASURED_EQ10_COLUMN: 0.6239845632800883,
                DIFFERENCE_COLUMN: 0.6239845632800883 - 0.6054300359935463,
                CALIBRATED_COLUMN: 0.2399096, CALIBRATED_INSIDE_COLUMN: "no",
                ALIGNMENT_COLUMN: "grid"})
    labels, rows = pdf_table_cells(pd.DataFrame([row]))
    shown = {label.replace("\n", " "): cell for label, cell in zip(labels, rows[0], strict=True)}
    assert shown["SDC DEM (ours) [-]"] == "0.6054"
    assert shown["SDC measured, E of Eq. 10 [-]"] == "0.624"
    assert shown["difference measured (E of Eq. 10) - ours [-]"] == "0.01855"
    # the Eq. 11 value says it is the other SDC
    assert shown["SDC measured (Eq. 11) [-]"] == "1.139"
    assert shown["SDC calibrated DEM (Eq. 11) [-]"] == "0.2399"
    assert shown["measured in calibrated 95 % band"] == "no"


def test_every_report_file_is_on_disk_before_the_rename_that_names_it(tmp_path, table,
                                                                      provenance, monkeypatch):
    # the folder is renamed into place whole; a rename can reach the disk before the data it
    # names, so without a flush a power loss just after `pidcore report` ended could leave
    # the report's files empty under their names
    import os
    import stat

    flushed: set[int] = set()
    renamed_after: list[set[int]] = []
    real_fsync, real_replace = os.fsync, os.replace

    def fsync(fd: int) -> None:
        info = os.fstat(fd)
        if stat.S_ISREG(info.st_mode):
            flushed.add(info.st_ino)  # an inode survives the rename
        real_fsync(fd)

    def replace(source, target) -> None:
        renamed_after.append(set(flushed))
        real_replace(source, target)

    monkeypatch.setattr(os, "fsync", fsync)
    monkeypatch.setattr(os, "replace", replace)
    out = tmp_path / "report"
    write_report(table, _figures(), provenance, out, ("csv", "md"))
    files = {p.stat().st_ino for p in out.rglob("*") if p.is_file()}
    assert len(files) == 7  # csv, its notes, md, marker, record, the figure's png and svg
    assert renamed_after and files <= renamed_after[0]


def test_every_file_names_the_eq11_sdc_as_such_and_an_older_csv_reads_into_the_new_names(
        report, table):
    # report.csv, .md, .html and .tex headed the Eq. 11 SDC "SDC measured [-]" beside "SDC DEM
    # (ours) [-]" (whose like-for-like counterpart is Eq. 10's), while the PDF and the terminal
    # called the one column "SDC measured (Eq. 11) [-]"
    from pidcore.report import REPORT_COLUMNS, REPORT_COLUMNS_RENAMED

    assert REPORT_COLUMNS_RENAMED == {
        "SDC measured [-]": "SDC measured (Eq. 11) [-]",
        "SDC measured stderr [-]": "SDC measured (Eq. 11) stderr [-]",
        "SDC measured stderr dof [-]": "SDC measured (Eq. 11) stderr dof [-]"}
    assert set(REPORT_COLUMNS_RENAMED.values()) <= set(REPORT_COLUMNS)
    assert not set(REPORT_COLUMNS_RENAMED) & set(REPORT_COLUMNS)
    _, written = report
    back = pd.read_csv(written["csv"])
    assert back["SDC measured (Eq. 11) [-]"].dropna().tolist() == [0.62]  # the analysis's
    assert back["SDC measured (Eq. 11) stderr [-]"].dropna().tolist() == [0.03]
    # Markdown escapes the brackets (a link otherwise)
    for fmt, head in (("md", "SDC measured (Eq. 11) \\[-\\]"),
                      ("html", "SDC measured (Eq. 11) [-]")):
        text = written[fmt].read_text(encoding="utf-8")
        assert head in text and "SDC measured [-]" not in text and \
            "SDC measured \\[-\\]" not in text
    # a report.csv of an earlier pidcore reads into the present names, every value as it was
    older = back.rename(columns={new: old for old, new in REPORT_COLUMNS_RENAMED.items()})
    assert "SDC measured [-]" in older.columns
    pd.testing.assert_frame_equal(older.rename(columns=REPORT_COLUMNS_RENAMED), back)


def test_a_killed_reports_build_folder_is_removed_by_the_next_report_of_that_folder(
        tmp_path, table, provenance):
    # `pidcore report --out rp` killed outright left its hidden build folder beside rp for
    # ever; the next report of rp removes it once a day old, and nothing else beside rp
    from _build_leftovers import leave_build_folders

    out = tmp_path / "rp"
    names = leave_build_folders(out, "report.csv", ('3c', '4d'))
    paths = write_report(table, {}, provenance, out, "csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["rp", names["fresh"],
                                                                 names["user's"]])
    # the report itself landed whole: the marker, the table and its notes, nothing else
    assert sorted(p.name for p in out.iterdir()) == sorted([REPORT_MARKER, RECORD_NAME,
                                                            "report.csv",
                                                            "report.provenance.txt"])
    assert len(pd.read_csv(paths["csv"])) == len(table)


def test_a_write_killed_between_its_renames_loses_no_earlier_report(tmp_path, table, provenance,
                                                                    monkeypatch):
    # The earlier report is moved aside, then the new one renamed into place: a SIGKILL
    # between the two left no rp and the earlier report hidden as '.rp.<hex>.old'. The kill
    # is stood for by an exception os.replace raises at the second rename, with the first
    # one's undo (the except branch a SIGKILL never reaches) disabled too. Only where the
    # system cannot swap the two folders in one step (the swap's kill points:
    # test_a_report_killed_at_any_rename_leaves_the_earlier_or_the_new_report_whole).
    import os

    import pidcore.atomic_files as atomic_files

    out = tmp_path / "rp"
    write_report(table, {}, provenance, out, "csv")
    earlier = {p.name: p.read_bytes() for p in out.iterdir()}
    renames = []

    def killed_at_the_second_rename(src, dst):
        renames.append((src, dst))
        if len(renames) >= 2:  # the second rename, and the undo of the first
            raise SystemExit("killed")
        os.rename(src, dst)

    monkeypatch.setattr(atomic_files.os, "replace", killed_at_the_second_rename)
    monkeypatch.setattr(atomic_files, "exchange_paths", lambda first, second: False)
    with pytest.raises(SystemExit):
        write_report(table.iloc[:1], {}, provenance, out, "csv")
    monkeypatch.undo()
    # the state a kill leaves: no rp, the earlier report hidden beside it
    hidden = [p for p in tmp_path.iterdir() if p.name.endswith(".old")]
    assert not out.exists() and len(hidden) == 1, sorted(os.listdir(tmp_path))
    assert re.fullmatch(r"\.rp\.[0-9a-f]{16}\.old", hidden[0].name)
    # the next write finds it, and a failing one leaves it back in place, whole
    import pidcore.report.render as render

    def failing_renderer(*args, **kwargs):
        raise OSError("disk full")

    with monkeypatch.context() as patch:
        patch.setitem(render.RENDERERS, "csv", failing_renderer)
        with pytest.raises(OSError, match="disk full"):
            write_report(table, {}, provenance, out, "csv")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == earlier
    # and a write that succeeds replaces it as any earlier report
    paths = write_report(table.iloc[:1], {}, provenance, out, "csv")
    assert paths["csv"].read_bytes() != earlier["report.csv"]
    assert sorted(os.listdir(tmp_path)) == ["rp"]


def test_only_a_hidden_earlier_report_of_the_exact_name_is_restored(tmp_path):
    from pidcore.report.render import restore_previous_report

    (tmp_path / ".rp.backup.old").mkdir()  # a user's: not the pattern
    (tmp_path / ".rp.backup.old" / REPORT_MARKER).write_text("x")
    (tmp_path / ".rp.0123456789abcdef.old").mkdir()  # the pattern, but no report in it
    assert restore_previous_report(tmp_path / "rp") is None
    assert not (tmp_path / "rp").exists()
    (tmp_path / ".rp.0123456789abcdef.old" / REPORT_MARKER).write_text("x")
    assert restore_previous_report(tmp_path / "rp") == tmp_path / "rp"
    assert (tmp_path / "rp" / REPORT_MARKER).read_text() == "x"
    assert sorted(p.name for p in tmp_path.iterdir()) == [".rp.backup.old", "rp"]


def test_a_hidden_earlier_report_beside_an_existing_one_is_removed_and_rp_untouched(
        tmp_path, table, provenance):
    # a write killed after the new report was in place, before the earlier one moved aside
    # was removed, left it hidden for ever (it was put back only where rp was missing); and
    # had rp been removed later, a report it had replaced came back in its place
    from pidcore.report.render import restore_previous_report

    (tmp_path / "rp").mkdir()
    (tmp_path / "rp" / REPORT_MARKER).write_text("the new one")
    for name in (".rp.0123456789abcdef.old", ".rp.backup.old"):  # the pattern; a user's
        write_report(table, {}, provenance, tmp_path / name, "csv")  # an earlier report
    assert restore_previous_report(tmp_path / "rp") is None
    assert sorted(p.name for p in tmp_path.iterdir()) == [".rp.backup.old", "rp"]
    assert (tmp_path / "rp" / REPORT_MARKER).read_text() == "the new one"


def test_a_hidden_earlier_report_holding_a_users_file_is_refused_not_removed(
        tmp_path, table, provenance):
    # the hidden earlier report beside an existing rp was deleted for holding the marker,
    # whatever else was in it: a user's thesis.tex copied there went with it
    from pidcore.report.render import restore_previous_report

    hidden = tmp_path / ".rp.0123456789abcdef.old"
    write_report(table, {}, provenance, tmp_path / "rp", "csv")
    write_report(table, {}, provenance, hidden, "csv")
    (hidden / "thesis.tex").write_text("mine")
    before = {p.relative_to(tmp_path): p.read_bytes() for p in tmp_path.rglob("*")
              if p.is_file()}
    with pytest.raises(ParameterError) as refused:
        restore_previous_report(tmp_path / "rp")
    assert str(refused.value) == (
        f"{hidden}: left hidden beside rp by a killed write, with its earlier outputs, to be "
        "removed, but it holds 'thesis.tex', which pidcore report did not write there and "
        "replacing its earlier outputs whole would delete; move what you keep out of it, then "
        "remove it")
    # nothing removed, the report's write refused the same
    with pytest.raises(ParameterError, match="thesis.tex"):
        write_report(table.iloc[:1], {}, provenance, tmp_path / "rp", "csv")
    assert {p.relative_to(tmp_path): p.read_bytes() for p in tmp_path.rglob("*")
            if p.is_file()} == before
    # a listed file changed since is kept the same way
    (hidden / "thesis.tex").unlink()
    (hidden / "report.csv").write_text("edited")
    with pytest.raises(ParameterError, match="'report.csv' changed since"):
        restore_previous_report(tmp_path / "rp")
    assert (hidden / "report.csv").read_text() == "edited"


def test_several_hidden_earlier_reports_are_refused_not_guessed_at(tmp_path):
    # which was moved aside last is no longer certain (a change time is not a write order
    # a user can check): none is put back or removed, the error names each
    from pidcore.report.render import restore_previous_report

    names = [".rp.0123456789abcdef.old", ".rp.fedcba9876543210.old"]
    for name in names:
        (tmp_path / name).mkdir()
        (tmp_path / name / REPORT_MARKER).write_text(name)
    with pytest.raises(ParameterError) as refused:
        restore_previous_report(tmp_path / "rp")
    assert str(refused.value) == (
        f"{tmp_path / 'rp'}: missing, and 2 earlier folders that killed writes left hidden "
        f"beside it ({', '.join(names)}); rename the one to keep to rp and remove the others")
    assert sorted(p.name for p in tmp_path.iterdir()) == names
    for name in names:
        assert (tmp_path / name / REPORT_MARKER).read_text() == name


#: A report of the first ``sys.argv[4]`` rows of a fixed table into ``sys.argv[3]``, for
#: :func:`_build_leftovers.run_killed_at_rename`.
_REPORT_SCRIPT = '''
from datetime import UTC, datetime
from pathlib import Path

import pandas as pd

from pidcore.model import load_paper_table3
from pidcore.out_folder import RECORD_NAME
from pidcore.report import build_report_table, collect_provenance, write_report

dem = pd.DataFrame({"frequency_hz": [50.0, 500.0], "acceleration_g": [5.0, 5.0],
                    "fill_percent": [50.0, 50.0], "material": ["acrylic"] * 2,
                    "direction": ["z"] * 2, "sdc": [0.19, 0.55], "sdc_stderr": [0.004, 0.01],
                    "case_key": ["a", "b"]})
table = build_report_table(dem, dem.iloc[:0], load_paper_table3()).iloc[:int(sys.argv[4])]
provenance = collect_provenance(created_utc=datetime(2026, 1, 2, tzinfo=UTC))
arm_the_kill()
write_report(table, {}, provenance, sys.argv[3], ("csv", "md"))
'''


@pytest.mark.parametrize("exchange", [True, False], ids=["exchange", "two renames"])
def test_a_report_killed_at_any_rename_leaves_the_earlier_or_the_new_report_whole(
        tmp_path, exchange):
    # `pidcore report --out rp` killed (SIGKILL, power loss) between the renames that put a
    # new report in place of an earlier one left no rp and the earlier one hidden. Where the
    # system swaps two folders in one step there is no such point; elsewhere the next run
    # puts the hidden one back. Killed at each rename in turn, rp is the earlier report or
    # the new one, file for file, at once or after the next run's clean-up, and nothing
    # beside it but what a user put there.
    import os
    import shutil
    import time

    from _build_leftovers import (
        exchange_available,
        folder_contents,
        run_killed_at_rename,
    )

    from pidcore.atomic_files import remove_stale_temporary_folders
    from pidcore.defaults import STALE_TEMPORARY_FILE_AGE_S
    from pidcore.report.render import restore_previous_report

    if exchange and not exchange_available(tmp_path):
        pytest.skip("this file system cannot swap two folders in one step")
    references = tmp_path / "references"
    references.mkdir()
    for rows in ("1", "2"):
        assert not run_killed_at_rename(_REPORT_SCRIPT, 99, exchange=exchange, cwd=tmp_path,
                                        args=(str(references / rows), rows))
    earlier, new = folder_contents(references / "1"), folder_contents(references / "2")
    assert earlier != new and REPORT_MARKER in earlier
    work = tmp_path / "work"
    outcomes = []
    for renames in range(10):
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir()
        out = work / "rp"
        shutil.copytree(references / "1", out)
        (work / "notes.txt").write_text("a user's")
        (work / ".rp.backup").mkdir()  # a user's, named like ours
        killed = run_killed_at_rename(_REPORT_SCRIPT, renames, exchange=exchange, cwd=tmp_path,
                                      args=(str(out), "2"))
        left = folder_contents(out)
        if exchange or not killed:  # no point without an rp
            assert left in (earlier, new), (renames, sorted(os.listdir(work)))
        # the next run's clean-up: the hidden earlier report back, and the build folders
        # removed as they will be once a day old (their age is the only thing not simulated)
        restore_previous_report(out)
        remove_stale_temporary_folders(out, now=time.time() + STALE_TEMPORARY_FILE_AGE_S + 1)
        after = folder_contents(out)
        assert after in (earlier, new), (renames, sorted(os.listdir(work)))
        assert after == left or left is None  # a report in place stays as it was
        assert sorted(os.listdir(work)) == [".rp.backup", "notes.txt", "rp"], renames
        assert (work / "notes.txt").read_text() == "a user's"
        outcomes.append("new" if after == new else "earlier")
        if not killed:
            break
    # every point was reached: before the swap the earlier report, after it the new one
    renames_needed = 1 if exchange else 3  # swap | aside, into place, the earlier to removal
    assert len(outcomes) == renames_needed + 1
    assert outcomes == ["earlier"] * (1 if exchange else 2) + ["new"] * (len(outcomes) - (
        1 if exchange else 2))


def test_every_page_writes_an_sdc_beside_its_stderr_by_the_one_rule(tmp_path, provenance):
    """Four significant digits per cell wrote 8.168123 ± 0.0003 as 8.168 and 0.0003 (the SDC
    coarser than its own error) and a noise-free 0.25 ± 1.1e-14 as 0.25 and 1.1e-14 in the
    Markdown, HTML, LaTeX, PDF and terminal tables, where the app, ``analyze`` and the case
    sheet write 8.16812 ± 0.00030 and 0.250000 ± <0.000001
    (:func:`pidcore.units.value_and_error_texts`)."""
    from pidcore.cli.report import short_table
    from pidcore.report import render
    from pidcore.report.render import pdf_table_cells
    from pidcore.report.table import MEASURED_EQ11_COLUMN, MEASURED_EQ11_STDERR_COLUMN

    dem = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [5.0], "fill_percent": [50.0],
                        "material": ["acrylic"], "direction": ["z"], "sdc": [8.168123],
                        "sdc_stderr": [0.0003], "case_key": ["a"]})
    analyses = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [5.0],
                             "fill_percent": [50.0], "sdc": [0.25], "sdc_stderr": [1.1e-14],
                             "source": ["run.uff"]})
    table = build_report_table(dem, analyses, load_paper_table3())
    paths = write_report(table, {}, provenance, tmp_path / "report", "md,html,tex")
    markdown = paths["md"].read_text(encoding="utf-8")
    assert "| 8.16812 | 0.00030 |" in markdown
    assert r"| 0.250000 | \<0.000001 |" in markdown  # "<" escaped: no HTML tag
    assert '<td class="num">8.16812</td><td class="num">0.00030</td>' in (
        paths["html"].read_text(encoding="utf-8"))
    assert "8.16812 & 0.00030" in paths["tex"].read_text(encoding="utf-8")
    labels, rows = pdf_table_cells(table)
    cols = render.pdf_columns(table)
    shown = dict(zip(cols, rows[0], strict=True))
    assert (shown["SDC DEM (ours) [-]"], shown["SDC DEM stderr [-]"]) == ("8.16812", "0.00030")
    assert (shown[MEASURED_EQ11_COLUMN], shown[MEASURED_EQ11_STDERR_COLUMN]) == (
        "0.250000", "<0.000001")
    header, _, row = short_table(table).splitlines()[:3]
    assert row.split()[3] == "8.16812"  # our DEM's SDC, rounded at its error's place


def _two_settings_table():
    """Two DEM runs of one load case at other settings (a 2-cell smoke run beside the 8-cell
    grid's run, ``pidcore dem run --cells 2`` stored beside the bundled Table 3 runs), and
    Table 3's 1000 Hz, 1 g, 90 %, whose paper DEM cell is empty for a reason the row's note
    gives."""
    dem = pd.DataFrame({"frequency_hz": [100.0, 100.0, 1000.0],
                        "acceleration_g": [5.0, 5.0, 1.0], "fill_percent": [50.0, 50.0, 90.0],
                        "material": ["acrylic"] * 3, "direction": ["z"] * 3,
                        "sdc": [0.71, 0.89, 2.7], "sdc_stderr": [0.12, 0.06, 0.3],
                        "cells_simulated": [2, 8, 8]})
    return build_report_table(dem, None, load_paper_table3())


def test_pdf_table_tells_rows_of_one_load_case_apart_and_numbers_their_notes(tmp_path,
                                                                             provenance):
    """Two rows "100 | 5 | 50" of SDCs 0.71 and 0.89 with nothing saying which run is which,
    and blank cells with no reason: the PDF showed neither the DEM settings nor the notes
    that every other format has. The settings the rows differ in are a column, the ones they
    share a line under the title, and each note is numbered in its row and written under the
    table; the PDF's own text is read back."""
    from test_report_case_sheet import _pdf_text

    from pidcore.report.render import numbered_notes, pdf_table_cells

    table = _two_settings_table()
    labels, rows = pdf_table_cells(table)
    heads = [label.replace("\n", " ") for label in labels]
    cells = [dict(zip(heads, row, strict=True)) for row in rows]
    assert [(c["SDC DEM (ours) [-]"], c["DEM settings"]) for c in cells] == [
        ("0.71", "cells 2"), ("0.890", "cells 8"), ("2.70", "cells 8")]  # at their errors
    # material and direction are the same in every row: no column, said once
    assert "material" not in heads and "direction" not in heads
    note = table["note"].iloc[2]
    assert note.startswith("the paper's Table 3 prints no DEM value at 1000 Hz, 1 g, 90 %")
    assert [c["note"] for c in cells] == ["", "", "1"]
    assert numbered_notes(table["note"]) == (["", "", "1"], [note])
    text = _pdf_text(write_report(table, {}, provenance, tmp_path / "r", "pdf")["pdf"]
                     .read_bytes())
    assert "Every row: material acrylic; direction z" in text
    assert "cells 2" in text and "cells 8" in text
    # up to "difference": the PDF draws its "ff" as a glyph of its own, not a letter of the text
    assert "1. the paper's Table 3 prints no DEM value at 1000 Hz, 1 g, 90 %: no paper DEM" in text


def test_pdf_writes_a_name_that_reads_as_mathtext_as_its_text(tmp_path, provenance):
    """A specimen or material named like TeX math ("$\\x$", "$^$") failed the whole PDF in
    matplotlib's mathtext parser (table cells, notes and provenance are parsed as math by
    default): they are written as the characters they are."""
    from test_report_case_sheet import _pdf_text

    table = _two_settings_table()
    table["material"] = ["a$\\x$b", "c$^$d", "acrylic"]  # differing: a column of the PDF
    table.loc[2, "note"] = "a note naming $\\frac{$ as typed"
    text = _pdf_text(write_report(table, {}, provenance, tmp_path / "r", "pdf")["pdf"]
                     .read_bytes())
    # the extraction splits a string at a kerning step and keeps the PDF's "\\" escape: the
    # parts on either side of the backslash are what can be asserted
    assert "c$^$d" in text and "a$" in text and "x$b" in text
    assert "frac{$ as typed" in text


def test_numbered_notes_give_one_note_one_number_in_the_order_rows_first_name_it():
    from pidcore.report.render import numbered_notes

    marks, notes = numbered_notes(["b", "", "a", "b", float("nan"), "a"])
    assert marks == ["1", "", "2", "1", "", "2"] and notes == ["b", "a"]


def test_pdf_table_pages_hold_their_rows_and_the_notes_they_number(tmp_path, provenance):
    """48 rows, each a note of ~300 characters of its own: each page's table and the notes it
    numbers fit on the page (none past its bottom edge), and every note is written."""
    from test_report_case_sheet import _pdf_text

    from pidcore.report.render import (
        _PDF_TABLE_ROOM,
        _pdf_height,
        _pdf_pages,
        _pdf_row_height,
        numbered_notes,
        pdf_table_cells,
    )

    table = build_report_table(pd.DataFrame({
        "frequency_hz": np.repeat([50.0, 100.0, 500.0, 1000.0], 12),
        "acceleration_g": np.tile(np.repeat([1.0, 5.0, 10.0], 4), 4),
        "fill_percent": np.tile([25.0, 50.0, 75.0, 90.0], 12), "material": ["acrylic"] * 48,
        "direction": ["z"] * 48, "sdc": np.linspace(0.01, 3.0, 48),
        "sdc_stderr": [0.01] * 48}), None, None)
    table["note"] = [f"row {i}: " + "a long reason " * 22 for i in range(48)]
    labels, rows = pdf_table_cells(table)
    marks, notes = numbered_notes(table["note"])
    header = max(label.count("\n") + 1 for label in labels)
    pages = _pdf_pages(rows, marks, notes, header)
    assert [i for page in pages for i in page] == list(range(48)) and len(pages) > 2
    for page in pages:
        used = _pdf_row_height(header) + sum(_pdf_height(rows[i], marks[i], notes, set())
                                             for i in page)
        assert used <= _PDF_TABLE_ROOM
    text = _pdf_text(write_report(table, {}, provenance, tmp_path / "r", "pdf")["pdf"]
                     .read_bytes())
    assert all(f"{k}. row {k - 1}:" in text for k in range(1, 49))


def test_latex_tables_fit_the_page_at_their_own_size_with_the_notes_numbered_below(
        tmp_path, provenance):
    """All ~32 columns in one tabular inside \\resizebox{\\textwidth}, a 300-character note and
    the source files among them: rows ~1200 characters wide, scaled to 0.12 (1.2 pt text).
    Now no table is scaled (\\scriptsize, 7 pt), each table's columns add up to at most the
    text width, and each note is an item under the tables, its number in its row."""
    from pidcore.report.render import _TEX_PAD, _TEX_TEXT_WIDTH, numbered_notes

    table = build_report_table(pd.DataFrame({
        "frequency_hz": np.repeat([50.0, 100.0, 500.0, 1000.0], 12),
        "acceleration_g": np.tile(np.repeat([1.0, 5.0, 10.0], 4), 4),
        "fill_percent": np.tile([25.0, 50.0, 75.0, 90.0], 12), "material": ["acrylic"] * 48,
        "direction": ["z"] * 48, "sdc": np.linspace(0.01, 3.0, 48),
        "sdc_stderr": [0.01] * 48}), None, load_paper_table3())
    table["note"] = [f"row {i % 5}: " + "a long reason " * 22 for i in range(48)]
    table["source file(s)"] = "data_samples/exports/synthetic_f1000Hz_a5g_fill50_acrylic.h5"
    text = write_report(table, {}, provenance, tmp_path / "r", "tex")["tex"].read_text(
        encoding="utf-8")
    assert r"\resizebox" not in text
    specs = re.findall(r"\\begin\{longtable\}\{(.*)\}$", text, re.M)
    assert len(specs) >= 2  # the numbers split over tables, the text by row beside
    for spec in specs:
        widths = [float(w) for w in re.findall(r"p\{([0-9.]+)cm\}", spec)]
        # the widths are written to 2 decimals: 0.005 cm each at most
        assert sum(widths) + _TEX_PAD * len(widths) <= _TEX_TEXT_WIDTH + 0.005 * len(widths)
    marks, notes = numbered_notes(table["note"])
    assert len(notes) == 5
    items = re.findall(r"^\\item (row \d: .*)$", text, re.M)
    assert items == notes  # in the order of their numbers
    # the note's number ends the row's line in the text table, never the note itself
    rows = [ln for ln in text.splitlines() if ln.endswith(r"\\") and "a long reason" in ln]
    assert rows == []
    by_row = {int(m.group(1)): m.group(2) for m in re.finditer(
        r"^(\d+) & f\S+ & .* & (\d+) \\\\$", text, re.M)}
    assert by_row == {i + 1: mark for i, mark in enumerate(marks)}


def test_latex_writes_a_name_past_latin1_so_that_pdflatex_reads_it(tmp_path, provenance):
    """A specimen named "Ω-купон 試験" was written raw under inputenc's utf8 and T1, and
    pdflatex stopped at "Unicode character Ω not set up for use with LaTeX". Every character
    past Latin-1 is now a command every engine reads: a symbol's (Ω, ω, ≤, σ), else the
    preamble's \\pidcorechar{code}{character}, the character under xelatex and lualatex and
    its code point under pdflatex, which never reads the character itself."""
    from pidcore.report.render import tex_escape

    name = "Ω-купон 試験"
    table = _two_settings_table()
    table["specimen"] = [name, "", ""]
    table["note"] = ["|measured − DEM| ≤ 2 σ at ω — said", "", ""]
    text = write_report(table, {}, provenance, tmp_path / "r", "tex")["tex"].read_text(
        encoding="utf-8")
    assert tex_escape(name) == (r"\ensuremath{\Omega}-\pidcorechar{043A}{к}\pidcorechar{0443}{у}"
                                r"\pidcorechar{043F}{п}\pidcorechar{043E}{о}"
                                r"\pidcorechar{043D}{н} \pidcorechar{8A66}{試}"
                                r"\pidcorechar{9A13}{験}")
    assert tex_escape(name) in text
    assert r"\item |measured \ensuremath{-} DEM| \ensuremath{\leq} 2 \ensuremath{\sigma} at " \
           r"\ensuremath{\omega} --- said" in text
    # what pdflatex reads: no character past Latin-1 outside \pidcorechar's second argument
    read = re.sub(r"\\pidcorechar\{([0-9A-F]{4,6})\}\{(.)\}",
                  lambda m: "" if int(m.group(1), 16) == ord(m.group(2)) else m.group(0), text)
    assert max(map(ord, read)) <= 0xFF
    # the engines' branches of the preamble
    preamble = text[:text.index(r"\begin{document}")]
    assert re.search(r"\\iftutex\s+\\usepackage\{fontspec\}\s+\\newcommand\{\\pidcorechar\}"
                     r"\[2\]\{#2\}\s+\\else\s+\\usepackage\[utf8\]\{inputenc\}\s+"
                     r"\\usepackage\[T1\]\{fontenc\}\s+\\newcommand\{\\pidcorechar\}\[2\]"
                     r"\{\\texttt\{\[U\+#1\]\}\\allowbreak\{\}\}\s+\\fi", preamble)


def _pdf_placed_text(data: bytes) -> list[tuple[float, float, float, str]]:
    """Each text object of a matplotlib PDF: the x and y (pt from the page's left and bottom
    edges) of its baseline's start, its font size and its text (its literal strings;
    matplotlib places each line of a text on its own, ``1 0 -0 1 x y cm`` before its
    ``BT``)."""
    import zlib

    out = []
    for stream in re.finditer(rb"stream\r?\n(.*?)endstream", data, re.S):
        unpack = zlib.decompressobj()
        try:
            content = unpack.decompress(stream.group(1))
        except zlib.error:
            continue
        for x, y, size, block in re.findall(
                rb"1 0 -?0 1 (-?[0-9.]+) (-?[0-9.]+) cm\s+BT\s+/F\d+ ([0-9.]+) Tf(.*?)ET",
                content, re.S):
            strings = re.findall(rb"\((.*?)(?<!\\)\)", block, re.S)
            text = b"".join(re.sub(rb"\\([()\\])", rb"\1", s) for s in strings)
            out.append((float(x), float(y), float(size), text.decode("latin-1")))
    return out


def test_pdf_shared_line_is_wrapped_to_the_page_and_keeps_the_whole_sha256(tmp_path,
                                                                           provenance):
    """The line of what every row shares was wrapped at 200 characters where ~145 fit A4
    landscape at 10 pt: an own specimen's material, direction, settings, name and sha256 ran
    past both edges of the page, the sha256 (written nowhere else in the PDF) losing its last
    digits. Each line of the title is now measured: the whole sha256 is on one line, and
    every line starts and ends on the page (its width measured in the font the PDF embeds),
    a long name's lines too."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import text_to_path

    from pidcore.report.render import _PDF_PAGE

    sha = "296c220d8209d22bc0278b69f122274ac239d783c35f2bbe672b36d1cee67bcd"
    for name in ("steel_6mm_aluminium_honeycomb_2mm_spheres", "honeycomb " * 60):
        table = _two_settings_table().iloc[:2].copy()
        table["material"] = "steel"
        table["DEM settings"] = "cells 2, steady cycles 20, settings hash 60eac2"
        table["specimen"] = name
        table["specimen sha256"] = sha
        out = tmp_path / name[:10].strip()
        placed = _pdf_placed_text(write_report(table, {}, provenance, out, "pdf")["pdf"]
                                  .read_bytes())
        with_sha = [p for p in placed if sha in p[3]]
        assert with_sha, "the whole sha256 on one line"
        # the title's size (the table's is 6.5); a line of a glyph the PDF's font subset
        # numbers below 32 (its "fi" of "Specific") is the fixed title, not measured here
        titles = [p for p in placed if p[2] == 10.0 and min(map(ord, p[3])) >= 32]
        assert any("Every row" in p[3] for p in titles) and with_sha[0] in titles
        for x, y, size, text in titles:
            width = text_to_path.get_text_width_height_descent(
                text, FontProperties(size=size), ismath=False)[0]
            # the PDF sets the advances and kerning matplotlib measures: 0.5 pt of slack
            assert 0.0 <= x and x + width <= _PDF_PAGE[0] * 72 + 0.5, (x, width, text)
            assert 0.0 <= y and y + size <= _PDF_PAGE[1] * 72, (y, text)


def test_pdf_says_a_value_is_every_rows_only_where_every_row_states_it(tmp_path, provenance):
    """A --pool report of tests of a specimen file (its sha256 296c22...) beside a test named
    only steel_6mm (no sha256): the PDF showed the specimen column and said "specimen sha256
    296c22..." of every row that states it, as if the name-only test's too. A value is now
    under the title only where every row states it; the sha256 is a column wherever the
    specimen is (they identify a specimen together), and so are DEM settings some rows lack."""
    from test_report_case_sheet import _pdf_text

    from pidcore.report.render import pdf_columns, pdf_shared_line, pdf_table_cells

    sha = "296c220d8209d22bc0278b69f122274ac239d783c35f2bbe672b36d1cee67bcd"
    table = _two_settings_table()
    table["material"] = "steel"
    table["specimen"] = ["сталь_6мм_鋼", "steel_6mm", "сталь_6мм_鋼"]
    table["specimen sha256"] = [sha, "", sha]
    table["DEM settings"] = ["cells 2", "", "cells 2"]
    cols = pdf_columns(table)
    assert {"specimen", "specimen sha256", "DEM settings"} <= set(cols)
    assert pdf_shared_line(table) == "Every row: material steel; direction z"
    labels, rows = pdf_table_cells(table)
    sha_cells = [row[cols.index("specimen sha256")].replace("\n", "") for row in rows]
    assert sha_cells == [sha, "", sha]  # whole, in its rows only
    text = _pdf_text(write_report(table, {}, provenance, tmp_path / "r", "pdf")["pdf"]
                     .read_bytes())
    assert "Every row: material steel; direction z" in text and "sha256 296c" not in text
    # one specimen throughout: its name and sha256 said once, under the title
    table["specimen"] = "сталь_6мм_鋼"
    table["specimen sha256"] = sha
    assert "specimen" not in pdf_columns(table) and "specimen sha256" not in pdf_columns(table)
    assert pdf_shared_line(table).endswith(f"specimen сталь_6мм_鋼; specimen sha256 {sha}")


def test_latex_columns_hold_what_pdflatex_prints_of_a_name_past_latin1(tmp_path, provenance):
    """pdflatex prints a character past Latin-1 as its code point, [U+0441]: the column of
    "сталь_6мм_鋼" was sized for 12 characters (1.28 cm) where pdflatex prints 66 in pieces
    no line could break, overprinting the sha256 beside it (20 overfull boxes). Each piece
    pdflatex cannot break, as the .tex's preamble defines \\pidcorechar for it, now fits its
    column (TeX not needed: the widths and breaks are read from the .tex)."""
    from pidcore.report.render import _TEX_CHAR

    table = _two_settings_table()
    table["material"] = "сталь"
    table["specimen"] = ["сталь_6мм_鋼", "x鋼", "сталь_6мм_鋼"]
    table["specimen sha256"] = "296c220d8209d22bc0278b69f122274ac239d783c35f2bbe672b36d1cee67bcd"
    text = write_report(table, {}, provenance, tmp_path / "r", "tex")["tex"].read_text(
        encoding="utf-8")
    pdflatex = re.search(r"\\else\s.*?\\newcommand\{\\pidcorechar\}\[2\]\{(.*)\}\s*\\fi",
                         text, re.S).group(1)
    tables = re.findall(r"\\begin\{longtable\}\{(.*?)\}$(.*?)\\end\{longtable\}", text,
                        re.M | re.S)
    assert any("& specimen &" in body for _, body in tables)
    checked = 0
    for spec, body in tables:
        widths = [float(w) for w in re.findall(r"p\{([0-9.]+)cm\}", spec)]
        for line in body.split(r"\endhead")[1].splitlines():
            if not line.endswith(r"\\") or line.startswith("\\"):
                continue
            cells = line[:-2].split(" & ")
            assert len(cells) == len(widths)
            for cell, width in zip(cells, widths, strict=True):
                shown = re.sub(r"\\pidcorechar\{([0-9A-F]+)\}\{.\}",
                               lambda m: pdflatex.replace("#1", m.group(1)), cell)
                for piece in re.split(r"\\allowbreak\{\}|\s+", shown):
                    printed = re.sub(r"\\texttt|[{}]", "", piece).replace("\\_", "_")
                    # _TEX_CHAR is the widest letter of 7 pt; the widths have 2 decimals
                    assert len(printed) * _TEX_CHAR <= width + 0.005, (printed, width)
                    checked += "[U+" in printed
    # each code point a piece of its own: 8 of each long name, 1 of "x鋼", 5 of each material
    assert checked == 8 + 1 + 8 + 3 * 5


def test_report_says_once_which_characters_its_figures_could_not_draw(tmp_path, provenance,
                                                                     monkeypatch, capsys):
    """A report of a specimen named сталь_6мм_鋼 printed matplotlib's "Glyph 37628 missing
    from font(s) DejaVu Sans" UserWarning, with its source line, for each drawing of the
    name (the PDF table, its notes, the figures): a note says it once instead."""
    import warnings

    import pidcore.report.pipeline as pipeline
    from pidcore.cli import main
    from pidcore.plot_text import installed_fallback_families

    table = _two_settings_table()
    table["specimen"] = ["сталь_6мм_鋼", "steel_6mm", "сталь_6мм_鋼"]

    def make_report(files, *, out_dir, **kwargs):
        fig = Figure(figsize=(3, 2))  # made within the command, as the report's figures
        fig.suptitle("DEM runs of сталь_6мм_鋼")
        return pipeline.ReportResult(write_report(table, {"f": fig}, provenance, out_dir,
                                                  "pdf"), table)

    monkeypatch.setattr(pipeline, "make_report", make_report)
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        assert main(["report", "--store", str(tmp_path / "s.h5"), "--out",
                     str(tmp_path / "rp")]) == 0
    assert not [w for w in shown if "Glyph" in str(w.message)]
    out = capsys.readouterr().out
    if not installed_fallback_families():  # none where these tests run (fc-list :lang=zh)
        assert out.count("could not be drawn") == 1
        assert "note: 1 character(s) could not be drawn in the figures and PDF pages (鋼)" in out


def test_the_file_systems_root_as_out_dir_is_refused_as_the_root_directly_or_through_a_link(
        tmp_path, table, provenance, capsys):
    # `report --out /` was refused as a folder holding no record, which moving files out of
    # '/' would not make replaceable; through `ln -sfn / lroot` the same
    from pidcore.cli import main

    (tmp_path / "lroot").symlink_to("/")
    for out in (Path("/"), tmp_path / "lroot"):
        with pytest.raises(ParameterError) as refused:
            write_report(table, {}, provenance, out, "csv")
        assert str(refused.value) == (f"out_dir {out}: is the file system's root, which cannot "
                                      "be an output folder replaced whole; choose a new or "
                                      "empty folder for out_dir")
        assert main(["report", "--store", str(tmp_path / "s.h5"), "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "file system's root" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lroot"]  # no store made either


def test_an_out_dir_that_is_the_current_folder_or_above_it_is_refused_before_any_analysis(
        tmp_path, table, provenance, monkeypatch, capsys):
    # `cd e4 && report ../x.csv --out .` analysed everything, then ended in a traceback
    # (PosixPath('.') has an empty name); `--out "$PWD"` replaced the shell's own folder
    import pidcore.report.pipeline as pipeline
    from pidcore.cli import main

    here = tmp_path / "e4"
    here.mkdir()
    monkeypatch.chdir(here)
    for out in (Path("."), here, Path("..")):
        with pytest.raises(ParameterError, match=r"is the current folder or holds it \("):
            write_report(table, {}, provenance, out, "csv")

    def analysed(*args, **kwargs):
        raise AssertionError("analysed before the refusal")

    monkeypatch.setattr(pipeline, "analyze_files", analysed)
    assert main(["report", str(tmp_path / "x.csv"), "--out", "."]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is the current folder or holds it" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e4"] and not any(here.iterdir())
