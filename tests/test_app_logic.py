"""The app's logic, tested without Streamlit: uploads and per-file settings, stores, the
comparison of one load case, loops, chart specs, report downloads, DEM jobs."""

from __future__ import annotations

import hashlib
import json
import math
import re
import threading
import time
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _app_samples import analytic_sdc, mass_damper_csv

from pidcore import defaults
from pidcore.app import jobs, stores, uploads
from pidcore.app.uploads import AnalysedFile
from pidcore.compare.case import (
    MeasuredEntry,
    compare_case,
    group_load_cases,
    load_case_of,
    paper_table,
    sdc_points,
    stated_case,
)
from pidcore.errors import ParameterError
from pidcore.report.case_view import loop_frame
from pidcore.report.comparison_figures import dem_loop_from_arrays
from pidcore.report.downloads import report_files, store_report_table
from pidcore.store.listing import list_dem_runs

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def good_csv() -> bytes:
    return mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0, loss_factor=0.05)


@pytest.fixture(scope="module")
def options():
    from pidcore.measure import AnalysisOptions

    return AnalysisOptions()


# --- uploads -----------------------------------------------------------------------------------

@pytest.mark.parametrize("name, expected", [
    ("run_fill50.csv", "run_fill50.csv"),
    ("../../etc/pass wd.csv", "pass_wd.csv"),
    ("C:\\data\\x.uff", "x.uff"),
    (".hidden.h5", "hidden.h5"),
    ("", "upload"),
])
def test_safe_file_name_keeps_no_folder_and_the_extension(name, expected):
    assert uploads.safe_file_name(name) == expected


def test_upload_size_limit_is_the_configured_one():
    limit = defaults.APP_MAX_UPLOAD_MB * 1024 * 1024
    uploads.check_upload_size("a.csv", limit)  # exactly at the limit is allowed
    with pytest.raises(ParameterError, match=r"a\.csv.*limit of 200 MB"):
        uploads.check_upload_size("a.csv", limit + 1)
    with pytest.raises(ParameterError, match="empty"):
        uploads.check_upload_size("a.csv", 0)


def test_store_path_comes_from_the_environment(tmp_path):
    assert stores.store_path({}) == defaults.STORE_PATH
    target = tmp_path / "s.h5"
    assert stores.store_path({stores.STORE_ENV_VAR: str(target)}) == target


def test_parse_upload_names_the_users_file_and_detects_roles(good_csv):
    parsed = uploads.parse_upload("coupon_fill50.csv", good_csv)
    assert parsed.error is None
    assert parsed.measurement.source == "coupon_fill50.csv"  # not the temporary copy
    assert parsed.sha256 == hashlib.sha256(good_csv).hexdigest()
    assert parsed.channels.force == "Force"
    assert parsed.channels.velocity == "Velocity"


def test_upload_analysis_equals_analyze_file_and_the_analytic_truth(tmp_path, good_csv, options):
    from pidcore.measure import analyze_file

    outcome = uploads.analyze_upload("coupon.csv", good_csv, options)
    path = tmp_path / "coupon.csv"
    path.write_bytes(good_csv)
    direct = analyze_file(path, options)
    assert outcome.ok and outcome.error is None
    # Same bytes, same code path: identical numbers.
    assert outcome.record.analysis.sdc == direct.analysis.sdc
    assert outcome.record.analysis.sdc_stderr == direct.analysis.sdc_stderr
    # Mass-damper truth SDC = 2 pi eta; 0.1 % noise on 100 periods moves it far below 1 %.
    assert outcome.record.analysis.sdc == pytest.approx(analytic_sdc(0.05), rel=1e-2)


@pytest.mark.parametrize("data", [b"not,a\nmeasurement\x00\x01", b"\x89HDF\r\n\x1a\ngarbage",
                                  b"    -1\n    58\ngarbage\n"])
def test_bad_upload_becomes_a_message_naming_the_file(data, options):
    outcome = uploads.analyze_upload("broken_export.uff", data, options)
    assert not outcome.ok
    assert "broken_export.uff" in outcome.error
    assert "pidcore_upload_" not in outcome.error  # the temporary copy is never shown
    assert "\n" not in outcome.error


def test_reader_notes_of_an_upload_name_the_upload_not_its_temporary_copy(options):
    # an x/y pair export (Time;Force;Time;Velocity, the velocity's own time 0.1 ms later)
    # showed "note: /tmp/pidcore_upload_c_4macox/xy.txt: column 'Time' is the time of
    # 'Velocity' ..." on its card, and the record saved that folder, gone once read
    w, rate, delay = 2 * math.pi * 100.0, 10_000.0, 1e-4
    t = np.arange(10_000) / rate
    v_amp = 5 * 9.80665 / w
    rows = "".join(f"{a:.9g};{0.1 * v_amp * w * math.cos(w * a):.9g};{a + delay:.9g};"
                   f"{v_amp * math.sin(w * (a + delay)):.9g}\n" for a in t)
    data = ("Time;Force;Time;Velocity\ns;N;s;m/s\n" + rows).encode()
    outcome = uploads.analyze_upload("xy_pairs.txt", data, options)
    assert outcome.ok, outcome.error
    reader = outcome.record.measurement.metadata["reader_notes"]
    pair = [n for n in reader if "is the time of 'Velocity'" in n]
    assert pair and pair[0].startswith("xy_pairs.txt: column 'Time'")
    for note in (*reader, *outcome.record.notes):
        assert "pidcore_upload_" not in note, note


@pytest.mark.parametrize("typed, said, not_said", [
    # 500 typed in 'mass below gauge [g]': "'mass below gauge [g]' 0.5 kg is probably larger"
    ({"mass below gauge [g]": 500.0}, "'mass below gauge [g]' 500 g is probably larger", " kg "),
    # 500000 typed in the µs field: "0.5 s ...; expected a vibrometer delay in s (e.g.
    # 2e-4)", advice the field then refuses (2e-4 µs is "implausibly small")
    ({"vibrometer delay [µs]": 5e5}, "'vibrometer delay [µs]': 500000 µs is longer than 4 "
     "drive periods", "in s (e.g. 2e-4)"),
    # 5 typed in 'structure mass [g]': "structure mass 0.005 kg given without a baseline"
    ({"structure mass [g]": 5.0}, "'structure mass [g]' 5 g given without a baseline "
     "loss factor", "0.005 kg"),
])
def test_messages_give_a_typed_mass_or_delay_in_the_fields_unit(typed, said, not_said):
    name = "synthetic_f500Hz_a1g_fill50_acrylic.csv"
    data = (REPO / "data_samples" / "exports" / name).read_bytes()
    row = {**uploads.default_settings_row(name, stated_case(name)),
           "vibrometer delay [µs]": 50.0, **typed}
    outcome = uploads.analyze_upload(name, data, uploads.options_of(row))
    text = outcome.error or " ".join(outcome.record.notes)
    assert said in text
    assert not_said not in text
    if "vibrometer delay" in said:
        assert "expected a vibrometer delay in µs (e.g. 200)" in text
        # the advice is a value the field takes
        assert uploads.options_of({**row, "vibrometer delay [µs]": 200.0}).velocity_delay_s \
            == pytest.approx(2e-4, rel=1e-12)


def test_a_refused_sign_names_the_channel_the_user_already_inverted():
    # a correct export with 'Force' typed in 'inverted channels' was refused with "one of the
    # channels is probably inverted: ... name the inverted channel in the 'inverted channels'
    # column", as if none was: the user's own inversion is the slip to undo
    name = "synthetic_f500Hz_a1g_fill50_acrylic.csv"
    data = (REPO / "data_samples" / "exports" / name).read_bytes()
    row = {**uploads.default_settings_row(name, stated_case(name)), "vibrometer delay [µs]": 50.0}
    refused = uploads.analyze_upload(
        name, data, uploads.options_of({**row, "inverted channels": "Force"})).error
    assert refused.endswith("(inverted on request already: the 'inverted channels' column "
                            "('Force'); is that one right?)")
    # as exported, it is analysed (the sign refusal was the inversion's)
    assert uploads.analyze_upload(name, data, uploads.options_of(row)).ok


def test_missing_channel_message_points_to_the_selectboxes(options):
    data = b"Time [s],Pressure [Pa]\n" + b"".join(
        f"{i / 1000:.4f},{np.sin(i / 10):.6f}\n".encode() for i in range(2000))
    outcome = uploads.analyze_upload("mic.csv", data, options)
    assert not outcome.ok and "mic.csv" in outcome.error
    assert "--force" not in outcome.error and "--velocity" not in outcome.error


def _row(name: str, **changes) -> dict:
    row = uploads.default_settings_row(name, stated_case(name))
    row.update(changes)
    return row


def test_channel_mapping_is_applied(good_csv, options):
    from pidcore.measure import AnalysisOptions

    data = mass_damper_csv(extra_velocity_phase_rad=0.3)
    default = uploads.analyze_upload("x.csv", data, uploads.options_of(_row(
        "x.csv", **{"force channel": "Force", "velocity channel": "Velocity",
                    "acceleration channel": uploads.NO_CHANNEL})))
    moved = uploads.analyze_upload("x.csv", data, uploads.options_of(_row(
        "x.csv", **{"velocity channel": "Velocity 2"})))
    assert moved.record.channels_used["velocity"] == "Velocity 2"
    assert moved.record.analysis.sdc != pytest.approx(default.record.analysis.sdc, rel=1e-3)
    assert uploads.options_from_json(uploads.options_to_json(
        AnalysisOptions(velocity="Velocity 2"))) == AnalysisOptions(velocity="Velocity 2")


def test_per_file_settings_convert_units_and_each_file_keeps_its_own():
    row = _row("a.csv", **{"vibrometer delay [µs]": 50.0, "mass below gauge [g]": 2.5,
                           "baseline loss factor [-]": 0.001})
    o = uploads.options_of(row, sample_rate_hz=1000.0)
    # µs and g at the edge, SI inside
    assert (o.velocity_delay_s, o.mass_below_gauge_kg) == (pytest.approx(50e-6),
                                                           pytest.approx(2.5e-3))
    assert o.baseline_loss_factor == 0.001 and o.sample_rate_hz == 1000.0
    assert o.force is None  # "(auto)": the readers' detection
    # an empty channel cell as the editor holds it (NaN) names no channel, as "(auto)" does
    assert uploads.options_of({**row, "velocity channel": float("nan")}).velocity is None
    with pytest.raises(ParameterError, match="a.csv"):
        uploads.options_of({**row, "mass below gauge [g]": -1.0})


def test_a_settings_table_is_detected_by_its_columns_under_any_name():
    table_bytes = (b"file,fill_percent,velocity_delay_us,specimen\n"
                   b"b_fill75.csv,,200,B\n")
    assert uploads.is_settings_table(table_bytes)
    assert uploads.is_settings_table(b"file,fill_percent,material,direction\nx.uff,50,,\n")
    assert not uploads.is_settings_table(mass_damper_csv())
    assert not uploads.is_settings_table(b"file,notes\nx,y\n")  # no settings column
    table = uploads.read_settings_table("my setup.csv", table_bytes)
    assert table.attrs["given"] == ["fill [%]", "specimen", "vibrometer delay [µs]"]
    names = ["a_fill50.csv", "b_fill75.csv"]
    settings = uploads.merge_settings(names, [stated_case(n) for n in names], None, [table])
    a, b = settings.iloc[0], settings.iloc[1]
    assert (a["fill [%]"], a["vibrometer delay [µs]"], a["specimen"]) == (50.0, 0.0, "")
    # the table fills b's delay and specimen; its empty fill cell keeps the name's 75 %
    assert (b["fill [%]"], b["vibrometer delay [µs]"], b["specimen"]) == (75.0, 200.0, "B")
    # the user's edits survive a later upload; a table uploaded later wins over them
    edited = settings.copy()
    edited.loc[0, "vibrometer delay [µs]"] = 50.0
    again = uploads.merge_settings(names, [stated_case(n) for n in names], edited, [],
                                   earlier_tables=[table])
    assert again["vibrometer delay [µs]"].tolist() == [50.0, 200.0]
    # the template round-trips through the reader
    back = uploads.read_settings_table("t.csv", uploads.settings_template(again))
    assert back["vibrometer delay [µs]"].tolist() == [50.0, 200.0]
    with pytest.raises(ParameterError,
                       match=r"t\.csv, line 2 \(a\.csv\), column velocity_delay_us: 'x'"):
        uploads.read_settings_table("t.csv", b"file,velocity_delay_us\na.csv,x\n")


def test_the_settings_grid_edits_numbers_as_text_and_pidcore_reads_them_as_typed(tmp_path):
    """The grid's number editor turned a typed "1,5" into 15 µs and "1e-3" into -13 µs: the
    numbers are edited as text and read by the checks a settings table gets."""
    from pidcore.errors import SettingsTableError
    from pidcore.loadcase import LoadCaseError

    names = ["a_fill50.csv"]
    settings = uploads.merge_settings(names, [stated_case(n) for n in names], None)
    settings.loc[0, "vibrometer delay [µs]"] = 1 / 3  # a value with all 17 digits
    settings.loc[0, "structure mass [g]"] = math.nan  # an empty cell
    shown = uploads.editor_settings(settings)
    row = shown.iloc[0]
    for column in uploads.TEXT_EDITED_NUMBERS:
        assert isinstance(row[column], str), column
    assert (row["fill [%]"], row["mass below gauge [g]"], row["structure mass [g]"]) == (
        "50", "0", "")
    # shown as text, read back to the same number (no digit lost to the display)
    assert uploads.options_of(row).velocity_delay_s == (1 / 3) / 1e6
    assert uploads.editor_settings(shown).equals(shown)  # text typed is kept as typed
    assert uploads.fill_of({**row, "fill [%]": " 2e1 "}) == 20.0
    typed = {**row, "vibrometer delay [µs]": "1,5"}
    with pytest.raises(SettingsTableError, match=re.escape(
            "a_fill50.csv, column vibrometer delay [µs]: '1,5' is not a number; expected a "
            "vibrometer output delay in µs >= 0")):
        uploads.options_of(typed)
    with pytest.raises(SettingsTableError, match=r"column vibrometer delay \[µs\]: '1e-3' is "
                                                 r"implausibly small"):
        uploads.options_of({**row, "vibrometer delay [µs]": "1e-3"})
    with pytest.raises(SettingsTableError, match=r"column mass below gauge \[g\]: '-2' is "
                                                 r"negative"):
        uploads.options_of({**row, "mass below gauge [g]": "-2"})
    for fill in ("12,5", "-30"):
        with pytest.raises(LoadCaseError, match=re.escape("a_fill50.csv, column fill [%]: ")):
            uploads.fill_of({**row, "fill [%]": fill})
    # a cell cleared in the grid is None (or blank text): no fill stated, the file has no
    # load case (as a sidecar's empty fill cell to `pidcore analyze`), not "fill None"
    for cleared in (None, "", "  ", math.nan):
        assert uploads.fill_of({**row, "fill [%]": cleared}) is None


def test_a_file_stating_no_fill_gets_an_empty_fill_cell_not_a_proposed_one():
    # the grid held 50 for a file whose name states no fill ("50 % proposed"), and Save
    # saved it as a load case "stated in the app"; `pidcore analyze` saves it without one
    names = ["nofill_f100Hz_a5g.csv", "run_fill75.csv"]
    settings = uploads.editor_settings(uploads.merge_settings(
        names, [stated_case(n) for n in names], None))
    assert settings["fill [%]"].tolist() == ["", "75"]
    assert [uploads.fill_of(row) for _, row in settings.iterrows()] == [None, 75.0]
    # the template downloaded from it states none either (an empty sidecar cell)
    template = uploads.settings_template(settings).decode().splitlines()
    assert template[1].startswith("nofill_f100Hz_a5g.csv,,")


def test_a_fill_of_no_particle_of_the_papers_coupon_is_refused_at_entry_as_the_cli_does(
        tmp_path, capsys):
    # 0.5 typed in the grid's fill cell for the paper's acrylic (22 particles a cell) showed a
    # load case "500 Hz, 1 g, 0.5 %" and was refused only at Save; `pidcore analyze --fill
    # 0.5` refuses it before any analysis: the app's card now refuses it in the same words
    from pidcore.cli import main
    from pidcore.loadcase import LoadCaseError
    from pidcore.specimen import NamedSpecimen

    path = tmp_path / "run_f500Hz.csv"
    path.write_bytes(mass_damper_csv(frequency_hz=500.0, acceleration_g=1.0,
                                     sample_rate_hz=20000))
    assert main(["analyze", str(path), "--fill", "0.5", "--no-store"]) == 2
    said = "fill 0.5 % of 22 particles rounds to none; expected >= 2.28 %; was 0.5 meant as 50 %?"
    assert said in capsys.readouterr().err
    unnamed = NamedSpecimen("", "")  # no specimen named: the paper's coupon
    with pytest.raises(LoadCaseError) as refused:
        uploads.check_specimen_fill(path.name, 0.5, "acrylic", unnamed, None)
    assert str(refused.value) == f"{path.name}, column fill [%]: {said}"
    # 22 x 2.28 % = 0.5 rounds to 1 particle (the least fill holding one), and 50 % to 11
    uploads.check_specimen_fill(path.name, 2.28, "acrylic", unnamed, None)
    uploads.check_specimen_fill(path.name, 50.0, "acrylic", unnamed, None)
    # no fill stated, or a specimen known by its name only (its cell not at hand): no rule
    uploads.check_specimen_fill(path.name, None, "acrylic", unnamed, None)
    uploads.check_specimen_fill(path.name, 0.5, "acrylic", NamedSpecimen("panel_B", ""), None)


def test_a_file_without_a_load_case_is_saved_without_one_and_said(tmp_path, good_csv,
                                                                  options):
    # what `pidcore analyze FILE --store S` saves for a file stating no fill: no fill, no load
    # case key, no origin claiming the app stated one; and the save says so
    from pidcore.store import Store

    rec = _record(good_csv, options, name="nofill.csv")
    store_file = tmp_path / "store.h5"
    saved = uploads.save_records(store_file, [AnalysedFile(rec, None, options, "")])
    assert saved.notes == (uploads.no_fill_note("nofill.csv"),)
    assert "saved without one" in saved.notes[0]
    row = Store(store_file).list_analyses().iloc[0]
    for field in ("fill_percent", "load_case_key", "load_case_origin"):
        assert field not in row.index or pd.isna(row[field]), (field, row[field])
    # neither listed as a load case beside the saved ones nor compared in the report
    unplaced = uploads.results_table([AnalysedFile(rec, None, options, "")])
    assert unplaced["load case"].tolist() == ["no load case"]
    assert "nofill.csv" in uploads.unplaced_note([AnalysedFile(rec, None, options, "")])
    assert uploads.unplaced_note([_file(rec, options)]) == ""


def test_an_own_specimens_material_is_offered_once_its_dem_runs_are_stored():
    # a steel-sphere measurement must be labelled steel to meet its steel DEM runs; the
    # store's runs make the name known (the table's materials come first)
    materials = uploads.measurement_materials(["steel_440c", "acrylic", "steel_440c", "", "Cu"])
    assert materials == ("acrylic", "aluminium", "cu", "steel_440c")
    table = b"file,material\nx_fill40.csv,steel_440c\n"
    with pytest.raises(ParameterError, match="unknown particle material 'steel_440c'"):
        uploads.read_settings_table("t.csv", table)
    assert uploads.read_settings_table("t.csv", table, materials)["material"].tolist() == [
        "steel_440c"]


# --- load cases, loops, spectrum -----------------------------------------------------------------

def _record(data: bytes, options, name="x.csv"):
    outcome = uploads.analyze_upload(name, data, options)
    assert outcome.ok, outcome.error
    return outcome.record


def _entry(rec, fill=50.0, **kw):
    return MeasuredEntry.from_record(rec, load_case_of(rec, fill_percent=fill,
                                                       material="acrylic"), **kw)


def _file(rec, options, fill=50.0, specimen=""):
    return AnalysedFile(rec, load_case_of(rec, fill_percent=fill, material="acrylic"), options,
                        specimen)


def test_load_cases_group_within_the_compare_tolerances(options):
    a = _record(mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0), options)
    b = _record(mass_damper_csv(frequency_hz=100.0, acceleration_g=5.1, seed=2), options)
    c = _record(mass_damper_csv(frequency_hz=500.0, acceleration_g=5.0, sample_rate_hz=20000),
                options)
    cases = [load_case_of(a, fill_percent=50, material="acrylic"),
             load_case_of(b, fill_percent=50, material="acrylic"),
             load_case_of(a, fill_percent=75, material="acrylic"),
             load_case_of(c, fill_percent=50, material="acrylic")]
    # 5.0 and 5.1 g are 2 % apart (< 5 % acceleration tolerance): one case.
    assert group_load_cases(cases) == [[0, 1], [2], [3]]


def test_load_cases_group_alike_in_any_order():
    # a chain of tests each within 5 % of the next, not of the one after (4.8 and 5.2 g are
    # 8 % apart): matched against the first case of a group, 5.0 g given first took both
    # (one case), 4.8 g given first only 5.0 g (two cases), so the Compare page's cases and
    # the report's off-grid rows hung on the order the files were given in
    from itertools import permutations

    from pidcore.compare.align import Tolerances
    from pidcore.compare.loadcase import LoadCase

    tol = Tolerances(frequency_rtol=0.01, acceleration_rtol=0.05, fill_atol_percent=1.0)
    chain = [LoadCase(2000.0, a, 50.0, "acrylic", "z") for a in (4.8, 5.0, 5.2, 5.0)]
    seen = set()
    for order in permutations(range(len(chain))):
        given = [chain[k] for k in order]
        groups = group_load_cases(given, tol)
        # every case once, the groups listed by their first index, each ascending
        assert sorted(i for g in groups for i in g) == list(range(len(chain)))
        assert groups == sorted(sorted(g) for g in groups)
        # each member within the tolerance of its group's first case, the rule's promise
        assert all(tol.matches(given[i], given[g[0]]) or tol.matches(given[g[0]], given[i])
                   for g in groups for i in g)
        seen.add(tuple(sorted(tuple(sorted(given[i].acceleration_g for i in g))
                              for g in groups)))
    # the same groups from all 24 orders: 4.8 g and both 5.0 g (0.2 g <= 5 % of 4.8 g =
    # 0.24 g), 5.2 g alone (0.4 g from 4.8 g)
    assert seen == {((4.8, 5.0, 5.0), (5.2,))}


def test_a_pooled_load_case_is_the_same_in_any_order():
    # stated fills within the fill tolerance (50 and 50.4 %) pooled as the first file's: the
    # row's load case and its sheet's name hung on the order the files were given in
    from itertools import permutations

    from pidcore.compare.case import pooled_load_case
    from pidcore.compare.loadcase import LoadCase

    tests = [LoadCase(2000.0, 5.0, 50.4, "acrylic", "z"),
             LoadCase(2000.2, 4.9, 50.0, "acrylic", "z"),
             LoadCase(1999.9, 5.1, 50.4, "acrylic", "z")]
    pooled = {pooled_load_case([tests[k] for k in order])
              for order in permutations(range(len(tests)))}
    assert len(pooled) == 1
    case, = pooled
    # the mean frequency and acceleration (float sums may differ by order: to 1e-12)
    assert case.frequency_hz == pytest.approx(np.mean([t.frequency_hz for t in tests]),
                                              rel=1e-12)
    assert case.acceleration_g == pytest.approx(5.0, rel=1e-12)
    # the stated fill of the first in load-case order (frequency first): 1999.9 Hz's
    assert case.fill_percent == 50.4


def test_a_load_case_address_names_its_case_when_files_are_saved_to_it_later(good_csv,
                                                                               options):
    # The Compare page's address held the case's label, which counts its files: a file saved
    # to the case later made the old address refused although the case was still there.
    from dataclasses import replace

    from pidcore.app.workbench import case_address, case_at_address
    from pidcore.compare.case import LoadCase
    from pidcore.report.case_view import group_entries

    one = _entry(_record(good_csv, options))

    def at(f, a, fill=50.0, specimen="", sha256="", key=""):
        return replace(one, key=key or f"k{f}_{a}_{fill}_{specimen}{sha256[:1]}",
                       load_case=LoadCase(f, a, fill, "acrylic", "z"), specimen=specimen,
                       specimen_sha256=sha256)

    entries = [at(100.0, 5.0), at(500.0, 5.0), at(100.0, 5.0, fill=75.0),
               at(100.0, 5.0, specimen="steel_6mm", sha256="a" * 64),
               at(100.0, 5.0, specimen="steel_6mm", sha256="b" * 64),
               at(100.0, 5.0, specimen="old_name")]  # a record saved without the hash
    groups = group_entries(entries)
    assert len(groups) == len(entries)  # each its own case (load case or specimen file)
    addresses = [case_address(entries, g) for g in groups]
    assert len(set(addresses)) == len(groups)
    assert addresses[0] == "f100Hz_a5g_fill50pct_acrylic_z"  # the store's load-case key
    assert "steel_6mm [aaaaaa]" in addresses[3] and "steel_6mm [bbbbbb]" in addresses[4]
    for n, address in enumerate(addresses):  # the round trip
        assert case_at_address(address, entries, groups) == n
    # a file saved later, 0.2 % off in frequency and listed first in its case: the old
    # address still names the case (the label, "... (2 file(s))", did not), now 2 files
    # (0.2 % and 0.4 % are inside the Compare tolerances, asserted so the test means it)
    later = [at(100.2, 5.02, key="later"), *entries]
    regrouped = group_entries(later)
    assert any(len(g) == 2 for g in regrouped)
    for n, address in enumerate(addresses):
        found = case_at_address(address, later, regrouped)
        assert found is not None
        assert {later[i].key for i in regrouped[found]} >= {entries[groups[n][0]].key}
    assert [later[i].key for i in regrouped[case_at_address(addresses[0], later, regrouped)]
            ] == ["later", entries[0].key]
    # what no longer exists is not met: another load case, specimen, hash, or no key at all
    for gone in ("f200Hz_a5g_fill50pct_acrylic_z", "f100Hz_a5g_fill60pct_acrylic_z",
                 "f100Hz_a5g_fill50pct_steel_z", "f100Hz_a5g_fill50pct_acrylic_x",
                 "f100Hz_a5g_fill50pct_acrylic_z steel_6mm [cccccc]",
                 "f100Hz_a5g_fill50pct_acrylic_z other", "acrylic_z_f100_a5_fill50",
                 "f100Hz_a5g_fill50pct_acrylic_z_seed1", "f100Hz_a5g_fill500pct_acrylic_z",
                 "200 Hz, 5 g, 50 %, acrylic, z (1 file(s))", "", "steel_6mm [aaaaaa]"):
        assert case_at_address(gone, entries, groups) is None, gone
    # the label an older page address held still names its case, whatever its file count
    assert case_at_address("500 Hz, 5 g, 50 %, acrylic, z (1 file(s))", later,
                           regrouped) == case_at_address(addresses[1], later, regrouped)
    assert case_at_address("100 Hz, 5 g, 50 %, acrylic, z, specimen steel_6mm [bbbbbb] "
                           "(7 file(s))", entries, groups) == 4


def test_a_load_case_keeps_its_name_when_a_later_file_is_saved_to_it(good_csv, options):
    # the store lists its newest records first, and the first record named the case: a file
    # saved later at 500.5 Hz renamed "500 Hz, 5 g, ..." to "500.5 Hz, 5 g, ..." (and wrote
    # another page address)
    from dataclasses import replace

    from pidcore.app.workbench import case_address
    from pidcore.compare.case import LoadCase
    from pidcore.report.case_view import group_entries, group_name

    one = _entry(_record(good_csv, options))

    def saved(f, when, key):
        return replace(one, key=key, created_utc=when, origin="store",
                       load_case=LoadCase(f, 5.0, 50.0, "acrylic", "z"))

    first = [saved(500.0, "2026-11-30T10:00:00Z", "a")]
    later = [saved(500.5, "2026-12-01T09:00:00Z", "b"), *first]  # as the store lists them
    unsaved = replace(one, key="upload:x", created_utc="",
                      load_case=LoadCase(499.6, 5.0, 50.0, "acrylic", "z"))
    for entries in (first, later, [unsaved, *later], [*later, unsaved]):
        (group,) = group_entries(entries)
        assert group_name(entries, group) == "500 Hz, 5 g, 50 %, acrylic, z"
        assert case_address(entries, group) == "f500Hz_a5g_fill50pct_acrylic_z"
    # unsaved records only: the first of them, as before
    (group,) = group_entries([unsaved, replace(unsaved, key="upload:y")])
    assert group_name([unsaved], [0]) == "499.6 Hz, 5 g, 50 %, acrylic, z"
    assert len(group) == 2


def test_measured_loop_area_is_the_dissipated_energy(good_csv, options):
    from _app_samples import MASS_KG, damper_for

    rec = _record(good_csv, options)
    loop = _entry(rec).loop()
    w = 2 * math.pi * rec.analysis.frequency_hz
    x_amp = rec.analysis.velocity_amplitude_m_s / w
    c = damper_for(0.05, 100.0)
    # A viscous damper dissipates pi c w X^2 per cycle; the mass adds no area.
    assert loop.energy_per_cycle_j == pytest.approx(math.pi * c * w * x_amp ** 2, rel=1e-2)
    assert loop.energy_per_cycle_j == pytest.approx(rec.analysis.energy_per_cycle_j, rel=1e-2)
    assert MASS_KG > 0


def test_spectrum_table_holds_the_fitted_phasor_amplitudes(good_csv, options):
    rec = _record(good_csv, options)
    table = _entry(rec).spectrum()
    a = rec.analysis
    np.testing.assert_array_equal(table["force amplitude [N]"], np.abs(a.force_phasors_n))
    np.testing.assert_array_equal(table["velocity amplitude [m/s]"],
                                  np.abs(a.velocity_phasors_m_s))
    fundamental = table.iloc[0]
    # Pure drive: the fundamental holds the velocity amplitude V = a / w.
    v_amp = 5.0 * 9.80665 / (2 * math.pi * 100.0)
    assert fundamental["velocity amplitude [m/s]"] == pytest.approx(v_amp, rel=1e-2)
    assert fundamental["frequency [Hz]"] == pytest.approx(100.0, rel=1e-4)


def test_compare_case_on_the_paper_grid(good_csv, options):
    from pidcore.model import load_paper_table3

    paper = load_paper_table3()
    rec = _record(good_csv, options)
    dem_runs = pd.DataFrame({
        "case_key": ["r1", "r2", "r3"], "frequency_hz": [100.0, 100.0, 100.0],
        "acceleration_g": [5.0, 5.0, 5.0], "fill_percent": [50.0, 50.0, 75.0],
        "material": ["acrylic"] * 3, "direction": ["z"] * 3,
        "sdc": [0.20, 0.22, 0.30], "sdc_stderr": [0.01, 0.01, 0.02]})
    comp = compare_case([_entry(rec)], dem_runs, paper)
    # One record: pooled values are the record's own.
    assert comp.measured_sdc == rec.analysis.sdc
    assert comp.measured_stderr == rec.analysis.sdc_stderr
    # Two runs at 50 %: mean 0.21; stderr = max(sqrt(2)*0.01/2, std/sqrt(2)) = 0.01.
    assert comp.aligned.status == "grid"
    assert comp.aligned.sdc_dem == pytest.approx(0.21)
    assert comp.aligned.sdc_dem_stderr == pytest.approx(0.01)
    assert comp.dem_points["packing ratio [%]"].tolist() == [50.0, 75.0]
    # Table 3 at 100 Hz, 5 g: DEM 0.1891 and measured 0.21 at 50 % fill.
    row = comp.paper_points.set_index("packing ratio [%]").loc[50.0]
    assert row["SDC DEM (paper) [-]"] == 0.1891
    assert row["SDC measured (paper) [-]"] == 0.21
    # Without the DEM's m_c the like-for-like SDC is unknown.
    assert math.isnan(comp.measured_sdc_eq10)
    # pchip interpolates: the curve passes through the paper's DEM values at its grid fills.
    at_grid = np.interp(comp.paper_points["packing ratio [%]"], comp.model_fill_percent,
                        comp.model_sdc)
    np.testing.assert_allclose(at_grid, comp.paper_points["SDC DEM (paper) [-]"], rtol=2e-2)


def test_compare_case_of_another_specimen_shows_no_paper_table3(good_csv, options):
    """Was: the Compare page drew the paper's Table 3 points, its pchip curve and its DEM
    0.1891 / measured 0.21 beside a test of another acrylic specimen (my_acrylic), a coupon
    the paper never tested; `pidcore report` left them out of such a row only for the report
    of that specimen. The paper's coupon (unnamed, or named paper_coupon) keeps them."""
    from pidcore.model import load_paper_table3

    paper = load_paper_table3()
    rec = _record(good_csv, options)
    mine = compare_case([_entry(rec, specimen="my_acrylic")], None, paper)
    assert mine.paper_points.empty and mine.model_sdc.size == 0
    assert math.isnan(mine.aligned.sdc_paper_dem)
    assert math.isnan(mine.aligned.sdc_paper_experimental)
    assert ("specimen my_acrylic is not the paper's coupon: the paper's Table 3 is not "
            "compared") in mine.notes
    for name in ("", "paper_coupon"):
        theirs = compare_case([_entry(rec, specimen=name)], None, paper)
        assert theirs.aligned.sdc_paper_dem == 0.1891  # Table 3: 100 Hz, 5 g, 50 %
        assert theirs.paper_points.set_index("packing ratio [%]").loc[50.0,
                                                             "SDC measured (paper) [-]"] == 0.21


def test_chart_data_hold_every_series_with_their_errors(good_csv, options):
    from pidcore.model import load_paper_table3

    rec = _record(good_csv, options)
    dem_runs = pd.DataFrame({
        "case_key": ["r1"], "frequency_hz": [100.0], "acceleration_g": [5.0],
        "fill_percent": [25.0], "material": ["acrylic"], "direction": ["z"],
        "sdc": [0.15], "sdc_stderr": [0.02]})
    comp = compare_case([_entry(rec)], dem_runs, load_paper_table3())
    data = sdc_points(comp)
    by = {name: g for name, g in data.groupby("series")}
    measured = by["measured (± stderr)"].iloc[0]
    a = rec.analysis
    assert (measured["packing ratio [%]"], measured["SDC [-]"]) == (50.0, a.sdc)
    assert measured["low [-]"] == a.sdc - a.sdc_stderr
    assert measured["high [-]"] == a.sdc + a.sdc_stderr
    dem = by["our DEM (mean ± stderr)"].iloc[0]
    assert dem["packing ratio [%]"] == 25.0
    assert (dem["low [-]"], dem["high [-]"]) == pytest.approx((0.13, 0.17), abs=1e-15)
    # Only 50 % fill has a measured value in Table 3: NaN rows are left out.
    assert by["paper measured"]["packing ratio [%]"].tolist() == [50.0]
    assert by["paper DEM"]["packing ratio [%]"].tolist() == [25.0, 50.0, 75.0, 90.0]
    loop = _entry(rec).loop()
    loops = loop_frame([loop])
    # Closed: last point repeats the first; SI units (the chart converts to µm).
    assert loops.iloc[0]["force [N]"] == loops.iloc[-1]["force [N]"]
    assert loops["displacement [m]"].iloc[1] == loop.displacement_m[1]
    assert loops["series"].iloc[0] == f"measured: {Path(rec.measurement.source).name}"


# --- store -------------------------------------------------------------------------------------

def test_save_writes_the_load_case_and_the_report_reads_it(tmp_path, good_csv, options):
    from pidcore.store import Store

    rec = _record(good_csv, options, name="coupon_fill50.csv")
    store_file = tmp_path / "store.h5"
    keys = uploads.save_records(store_file, [_file(rec, options, specimen="S1")]).keys
    listed = Store(store_file).list_analyses()
    assert listed["key"].tolist() == keys
    row = listed.iloc[0]
    assert row["sdc"] == rec.analysis.sdc
    assert (row["fill_percent"], row["material"], row["direction"]) == (50.0, "acrylic", "z")
    assert row["specimen"] == "S1"
    table = store_report_table(store_file)
    assert table["SDC measured (Eq. 11) [-]"].tolist() == [rec.analysis.sdc]
    # S1 is not the paper's coupon: Table 3 (DEM 0.1891 here) is not set beside its test
    assert table["SDC DEM (paper) [-]"].isna().all()
    assert "specimen S1 is not the paper's coupon" in table["note"].iloc[0]


def test_saving_again_says_the_store_already_held_the_records(tmp_path, good_csv, options):
    # the app's second Save said "saved 1 analysis record(s)" as the first had
    rec = _record(good_csv, options, name="coupon_fill50.csv")
    store_file = tmp_path / "store.h5"
    first = uploads.save_records(store_file, [_file(rec, options)])
    assert first.breakdown == ""  # all new: nothing to add to the count
    again = uploads.save_records(store_file, [_file(rec, options)])
    assert again.keys == first.keys
    assert again.breakdown == "0 new, 1 already held with identical content"
    other = uploads.save_records(store_file, [_file(rec, options, fill=75.0)])
    # the same file, stated otherwise: not "a record of other content" beside the note that
    # says its contents are the same
    assert other.breakdown == ("0 new, 1 replacing the held record of the same file under "
                               "another name, load case or specimen, or one saved without a "
                               "field saved now")


def test_two_sessions_saving_at_once_keep_the_store_whole(tmp_path, options):
    from pidcore.store import Store

    store_file = tmp_path / "store.h5"
    batches = []
    for i in range(2):
        recs = []
        for j in range(3):
            rec = _record(mass_damper_csv(seed=10 * i + j), options, name=f"s{i}_{j}.csv")
            recs.append(_file(rec, options))
        batches.append(recs)
    barrier = threading.Barrier(2)
    errors = []

    def save(batch):
        try:
            barrier.wait()
            uploads.save_records(store_file, batch)
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=save, args=(b,)) for b in batches]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    store = Store(store_file)
    assert store.verify() == []
    # Every record of both sessions is there: neither commit overwrote the other.
    assert len(store.list_analyses()) == 6
    assert len(store.list_measurements()) == 6


def test_report_downloads_hold_the_saved_numbers(tmp_path, good_csv, options):
    rec = _record(good_csv, options, name="coupon.csv")
    store_file = tmp_path / "store.h5"
    uploads.save_records(store_file, [_file(rec, options)])
    files = report_files(store_file)
    assert set(files) == {"csv", "md", "html", "tex", "pdf", "csv_provenance", "zip"}
    name, data, mime = files["pdf"]
    assert name.endswith(".pdf") and data.startswith(b"%PDF") and mime == "application/pdf"
    import io

    # a plain read_csv reads exactly the table: no footer lines
    table = pd.read_csv(io.BytesIO(files["csv"][1]))
    assert len(table) == 1 and b"sha256" in files["csv_provenance"][1]
    assert table["SDC measured (Eq. 11) [-]"].iloc[0] == pytest.approx(rec.analysis.sdc, rel=1e-9)
    assert b"<table" in files["html"][1]
    assert b"\\begin{" in files["tex"][1]



def test_report_downloads_say_the_pool_choice_as_the_page_names_it(tmp_path, good_csv, options):
    from pidcore.app.tabs.report import page_terms

    rec = _record(good_csv, options, name="coupon.csv")
    store_file = tmp_path / "store.h5"
    uploads.save_records(store_file, [_file(rec, options)])
    plain = report_files(store_file, pool=True)
    files = report_files(store_file, pool=True, wording=page_terms)
    # the library's keyword was in the files the app offered, where the page has a checkbox
    assert b"pool=True" in plain["csv"][1]
    for fmt in ("csv", "md", "html", "csv_provenance"):
        assert b"pool=True" not in files[fmt][1], fmt
    assert b"'pool DEM settings'" in files["csv"][1]
    # only the words changed: the numbers are the same bytes
    import io

    assert pd.read_csv(io.BytesIO(files["csv"][1])).drop(columns="note").equals(
        pd.read_csv(io.BytesIO(plain["csv"][1])).drop(columns="note"))

# --- launching ---------------------------------------------------------------------------------

def test_one_streamlit_config_matching_the_defaults():
    def in_a_virtualenv(path: Path) -> bool:
        # CI installs into .venv-ci/ inside the checkout; packages there may ship their own
        # .streamlit folders (streamlit's app templates), which are not the project's
        return any((REPO / parent / "pyvenv.cfg").is_file()
                   for parent in path.relative_to(REPO).parents if parent != Path("."))

    found = sorted(p.relative_to(REPO) for p in REPO.rglob("config.toml")
                   if p.parent.name == ".streamlit" and not in_a_virtualenv(p))
    assert found == [Path(".streamlit/config.toml")]
    config = tomllib.loads((REPO / ".streamlit" / "config.toml").read_text())
    assert config["server"]["maxUploadSize"] == defaults.APP_MAX_UPLOAD_MB
    assert config["browser"]["gatherUsageStats"] is False
    assert config["runner"]["postScriptGC"] is False  # as `pidcore app` starts it


def test_app_command_serves_the_packaged_entry_on_localhost(tmp_path):
    import pidcore
    from pidcore.app import ENTRY_SCRIPT
    from pidcore.cli.app import app_environment, streamlit_command

    cmd = streamlit_command(8765, python="python")
    assert cmd[:4] == ["python", "-m", "streamlit", "run"]
    entry = Path(cmd[4])
    # Inside the installed package, so a non-editable install finds it too.
    assert entry == ENTRY_SCRIPT and entry.is_file()
    # Streamlit lists the scripts of a pages/ folder beside the entry as pages of their own
    for script in (entry, REPO / "app" / "pidcore_app.py"):
        assert not (script.parent / "pages").exists(), script
    assert entry.parent.parent == Path(pidcore.__file__).parent
    opts = dict(zip(cmd[5::2], cmd[6::2], strict=True))
    assert opts["--server.address"] == "localhost"
    assert opts["--server.port"] == "8765"
    assert opts["--server.headless"] == "true"
    assert opts["--browser.gatherUsageStats"] == "false"
    assert opts["--server.maxUploadSize"] == str(defaults.APP_MAX_UPLOAD_MB)
    assert opts["--runner.postScriptGC"] == "false"  # ~0.1 s of each click otherwise
    with pytest.raises(ParameterError, match="port"):
        streamlit_command(70000)
    env = app_environment(Path("rel.h5"), environ={})
    assert Path(env[stores.STORE_ENV_VAR]).is_absolute()
    assert env["STREAMLIT_BROWSER_GATHER_USAGE_STATS"] == "false"
    assert stores.DEM_STORE_ENV_VAR not in env
    with pytest.raises(ParameterError, match="dem-store"):
        app_environment(Path("rel.h5"), tmp_path / "missing.h5", environ={})
    # The repository shim runs the packaged app.
    shim = (REPO / "app" / "pidcore_app.py").read_text()
    assert "from pidcore.app.main import main" in shim


def test_print_command_names_the_stores_the_app_would_serve(tmp_path, monkeypatch, capsys):
    # `pidcore app --store X --print-command` printed the bare streamlit line: run as printed,
    # the app read no PIDCORE_STORE and served ./pid_store.h5 instead of X; a missing
    # --dem-store was refused only when the app was started, not when its line was printed
    import shlex

    from pidcore.cli import main
    from pidcore.cli.app import streamlit_command

    monkeypatch.delenv(stores.STORE_ENV_VAR, raising=False)
    monkeypatch.delenv(stores.DEM_STORE_ENV_VAR, raising=False)
    monkeypatch.chdir(tmp_path)
    reference = tmp_path / "reference runs.h5"
    reference.write_bytes(b"")
    assert main(["app", "--port", "8777", "--store", "my store.h5",
                 "--dem-store", reference.name, "--print-command"]) == 0
    words = shlex.split(capsys.readouterr().out)
    assert words[:2] == [f"{stores.STORE_ENV_VAR}={tmp_path / 'my store.h5'}",
                         f"{stores.DEM_STORE_ENV_VAR}={reference}"]
    assert words[2:] == streamlit_command(8777)
    assert main(["app", "--dem-store", "missing.h5", "--print-command"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "--dem-store missing.h5" in err
    # the bundled reference runs found here are named absolutely: the app looked for them
    # relative to its own folder, so the line run elsewhere served none
    (tmp_path / stores.BUNDLED_DEM_STORE).parent.mkdir()
    (tmp_path / stores.BUNDLED_DEM_STORE).write_bytes(b"")
    assert main(["app", "--print-command"]) == 0
    words = shlex.split(capsys.readouterr().out)
    assert words[1] == f"{stores.DEM_STORE_ENV_VAR}={tmp_path / stores.BUNDLED_DEM_STORE}"


@pytest.mark.parametrize("script", ["pidcore/app/entry.py", "app/pidcore_app.py"])
def test_a_worker_process_rerunning_the_entry_script_draws_nothing(script, monkeypatch):
    # multiprocessing re-runs the parent's main script in each worker as "__mp_main__";
    # during a Streamlit script run that is the entry script, which drew the whole page in
    # every DEM worker (hundreds of warnings per job in the server log)
    import runpy
    import sys
    import types

    drawn = []
    fake = types.ModuleType("pidcore.app.main")
    fake.main = lambda: drawn.append(True)
    monkeypatch.setitem(sys.modules, "pidcore.app.main", fake)
    runpy.run_path(str(REPO / script), run_name="__mp_main__")
    assert drawn == []
    runpy.run_path(str(REPO / script), run_name="__main__")  # what `streamlit run` does
    assert drawn == [True]


# --- DEM from the app ----------------------------------------------------------------------------

def test_dem_sweep_plan_is_the_product_and_is_kept_small():
    cases = jobs.plan_dem_cases([100.0, 50.0], [5.0], [75.0, 25.0], material="acrylic",
                                       direction="z")
    assert [(c.frequency_hz, c.fill_percent) for c in cases] == [
        (50.0, 25.0), (50.0, 75.0), (100.0, 25.0), (100.0, 75.0)]
    with pytest.raises(ParameterError, match="at least one"):
        jobs.plan_dem_cases([], [5.0], [50.0], material="acrylic", direction="z")
    with pytest.raises(ParameterError, match="at most"):
        jobs.plan_dem_cases([50, 100, 500], [1, 5, 10], [25, 50], material="acrylic",
                                   direction="z")


def _wait(runner, timeout_s: float = 300.0) -> None:
    import time

    deadline = time.monotonic() + timeout_s
    while runner.busy():
        assert time.monotonic() < deadline, [j.row() for j in runner.jobs()]
        time.sleep(0.1)


@pytest.mark.dem_subprocess
def test_dem_job_is_saved_once_and_its_loop_area_is_the_shaker_work(tmp_path):
    from pidcore.dem import DemConfig, simulate_load_case
    from pidcore.store import Store

    store_file = tmp_path / "dem.h5"
    (case,) = jobs.plan_dem_cases([100.0], [5.0], [50.0], material="acrylic", direction="z")
    config = DemConfig(cells=2, steady_cycles=20)
    runner = jobs.DemJobRunner(store_file)
    first = runner.submit([case], config)
    again = runner.submit([case], config)  # a rerun's second click: not queued twice
    assert len(first) == 1 and again == []
    _wait(runner)
    (job,) = runner.jobs()
    assert job.state == "saved", job.message
    assert job.cycles_done == job.cycles_expected > 0 and job.fraction() == 1.0
    # already in the store: a later submission is recorded but not run
    (later,) = runner.submit([case], config)
    assert later.state == "in store"
    entry = Store(store_file).get_dem_run(job.run_key)
    assert len(Store(store_file).list_dem_runs()) == 1
    # Deterministic (seeded): the stored SDC is the simulation's.
    assert entry.record["sdc"] == simulate_load_case(case, config).sdc
    loop = dem_loop_from_arrays(entry.arrays, entry.record)
    assert not isinstance(loop, str), loop
    # With a sine drive only the fundamental carries power, so the loop's area is the shaker's
    # work per steady cycle: the dissipated energy per cycle up to the change of stored
    # mechanical energy over 20 cycles of 2 cells (a few percent), hence 5 %.
    assert loop.energy_per_cycle_j == pytest.approx(entry.record["energy_per_cycle_j"], rel=5e-2)


@pytest.mark.dem_subprocess
def test_cancel_stops_a_running_dem_case_within_two_seconds_and_saves_nothing(tmp_path):
    import time

    from pidcore.dem import DemConfig
    from pidcore.store import Store

    store_file = tmp_path / "dem.h5"
    runner = jobs.DemJobRunner(store_file)
    cases = jobs.plan_dem_cases([50.0], [5.0], [50.0, 75.0], material="acrylic",
                                direction="z")
    # long enough to be running when cancelled (thousands of steady cycles); one cell: the
    # wait for the first block of cycles is the test's cost
    runner.submit(cases, DemConfig(cells=1, steady_cycles=5000))
    deadline = time.monotonic() + 120
    while not any(j.state == "running" and j.cycles_done > 0 for j in runner.jobs()):
        assert time.monotonic() < deadline
        time.sleep(0.05)
    t0 = time.monotonic()
    assert runner.cancel() == 2
    # returns once the running case's process has ended (what the page's Cancel waits for)
    assert runner.wait_cancelled(2.0), "cancel took longer than 2 s"
    assert time.monotonic() - t0 < 2.0
    assert not runner.busy()
    assert [j.state for j in runner.jobs()] == ["cancelled", "cancelled"]
    assert not store_file.exists() or Store(store_file).list_dem_runs().empty


@pytest.mark.dem_subprocess
def test_a_queued_dem_job_whose_run_is_stored_meanwhile_is_not_run(tmp_path):
    # Before, a job looked for its run only when submitted: a run that `pidcore dem`, a
    # calibration or another app server stored while the job waited was simulated again.
    from pidcore.dem import DemConfig
    from pidcore.dem.persist import dem_run_entry, load_dem_result, run_key, save_dem_entry
    from pidcore.store import Store

    store_file = tmp_path / "dem.h5"
    reference = Store(REPO / "data_samples" / "dem_table3.h5")
    runner = jobs.DemJobRunner(store_file)
    try:
        (first,) = runner.submit(
            jobs.plan_dem_cases([50.0], [5.0], [50.0], material="acrylic", direction="z"),
            DemConfig(cells=1, steady_cycles=5000))  # long: still running below
        (case,) = jobs.plan_dem_cases([100.0], [5.0], [50.0], material="acrylic",
                                      direction="z")
        (queued,) = runner.submit([case], DemConfig())
        assert queued.state == "queued"
        deadline = time.monotonic() + 120
        while not any(j.state == "running" for j in runner.jobs()):
            assert time.monotonic() < deadline
            time.sleep(0.05)
        # stored meanwhile by someone else (the bundled reference run of this very key)
        key = run_key(case, DemConfig())
        save_dem_entry(store_file, key, dem_run_entry(load_dem_result(reference.get_dem_run(
            key))))
        runner.cancel([first.job_id])
        deadline = time.monotonic() + 30  # a 8-cell run would take minutes, the check none
        while runner.busy():
            assert time.monotonic() < deadline, [j.row() for j in runner.jobs()]
            time.sleep(0.05)
        by_id = {j.job_id: j for j in runner.jobs()}
    finally:
        runner.cancel()
        runner.wait_cancelled(5.0)
    done = by_id[queued.job_id]
    assert done.state == "in store" and done.run_key == key
    assert done.message == (f"stored in the store as {key} after it was queued; not run "
                            "again")
    runs = Store(store_file).list_dem_runs()
    assert list(runs["case_key"]) == [key]  # the run saved above, nothing else
    assert runs["sdc"].iloc[0] == reference.get_dem_run(key).record["sdc"]


def test_dem_values_are_any_positive_numbers():
    from pidcore.loadcase import parse_values

    assert parse_values("50, 123.5;7", name="f") == [50.0, 123.5, 7.0]
    with pytest.raises(ParameterError, match="f: 'x' is not a number"):
        parse_values("50 x", name="f")
    with pytest.raises(ParameterError, match="positive"):
        parse_values("-5", name="f")


def test_pidcore_app_serves_on_localhost_until_stopped(tmp_path):
    import socket
    import subprocess
    import sys
    import time
    import urllib.request

    pytest.importorskip("streamlit")
    with socket.socket() as s:
        s.bind(("localhost", 0))
        port = s.getsockname()[1]
    proc = subprocess.Popen([sys.executable, "-m", "pidcore", "app", "--port", str(port),
                             "--store", str(tmp_path / "s.h5")], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        deadline = time.monotonic() + 45  # cold start imports streamlit
        while True:
            try:
                with urllib.request.urlopen(f"http://localhost:{port}/_stcore/health",
                                            timeout=2) as r:
                    assert r.read().strip() == b"ok"
                    break
            except OSError:
                assert proc.poll() is None, proc.stdout.read().decode()[-2000:]
                assert time.monotonic() < deadline, "pidcore app did not answer"
                time.sleep(0.2)
        with urllib.request.urlopen(f"http://localhost:{port}/", timeout=5) as r:
            assert b"<html" in r.read().lower()
    finally:
        proc.terminate()
        proc.wait(timeout=15)
    # Nothing was written: the app only writes the store when the user saves.
    assert not (tmp_path / "s.h5").exists()


def _dem_record(sdc: float, fill: float = 50.0) -> dict:
    return {"frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": fill,
            "material": "acrylic", "direction": "z", "sdc": sdc, "sdc_stderr": 0.01}


def test_reference_dem_store_joins_the_app_store_read_only(tmp_path, good_csv, options):
    from pidcore.store import Store

    app_file, ref_file = tmp_path / "app.h5", tmp_path / "ref.h5"
    Store(ref_file).add_dem_run("shared", _dem_record(0.40))
    Store(ref_file).add_dem_run("ref_only", _dem_record(0.30, fill=75.0))
    Store(app_file).add_dem_run("shared", _dem_record(0.20))
    ref_bytes = ref_file.read_bytes()
    runs = list_dem_runs(app_file, ref_file).set_index("case_key")
    # A key in both comes from the app store; the reference adds its other runs.
    assert runs.loc["shared", "sdc"] == 0.20 and runs.loc["shared", "store"] == str(app_file)
    assert runs.loc["ref_only", "store"] == str(ref_file)
    assert list_dem_runs(tmp_path / "none.h5").empty

    rec = _record(good_csv, options, name="c.csv")
    uploads.save_records(app_file, [_file(rec, options)])
    table = store_report_table(app_file, ref_file)
    assert table["packing ratio [%]"].tolist() == [50.0, 75.0]
    assert table["SDC DEM (ours) [-]"].tolist() == [0.20, 0.30]
    assert table["SDC measured (Eq. 11) [-]"].iloc[0] == rec.analysis.sdc
    files = report_files(app_file, ref_file)
    html = files["html"][1].decode()
    assert str(ref_file.name) in html and str(app_file.name) in html  # provenance: both stores
    assert ref_file.read_bytes() == ref_bytes  # never written


def test_stores_come_from_the_environment_or_the_bundled_samples(tmp_path):
    env = {stores.STORE_ENV_VAR: str(tmp_path / "a.h5")}
    assert stores.AppStores.from_environment(env, cwd=tmp_path) == stores.AppStores(
        tmp_path / "a.h5", None)
    bundled = tmp_path / stores.BUNDLED_DEM_STORE
    bundled.parent.mkdir(parents=True)
    bundled.write_bytes(b"")
    assert stores.dem_store_path({}, cwd=tmp_path) == bundled
    named = {stores.DEM_STORE_ENV_VAR: str(tmp_path / "ref.h5")}
    assert stores.dem_store_path(named, cwd=tmp_path) == tmp_path / "ref.h5"
    app_stores = stores.AppStores(tmp_path / "a.h5", bundled)
    before = app_stores.stamp()
    (tmp_path / "a.h5").write_bytes(b"x")
    assert app_stores.stamp() != before  # a rewritten store invalidates cached listings


def test_load_case_is_taken_from_the_name_and_no_fill_is_proposed_for_a_name_stating_none():
    by_name = stated_case("run_fill75_aluminum_dirx.csv")
    assert (by_name.fill_percent, by_name.material, by_name.direction) == (75.0, "aluminium",
                                                                           "x")
    # no fill stated: none proposed in its place (a proposed 50 % was saved as stated)
    unstated = stated_case("plain.csv")
    assert math.isnan(unstated.fill_percent)
    assert "fill: not stated" in unstated.origin
    # a material the table lacks is not passed off as acrylic: the row says what to set, and
    # the fill the name states is kept; with a steel specimen known it is steel
    steel = stated_case("coupon_fill20_steel.csv")
    assert steel.fill_percent == 20.0 and "says 'steel'" in steel.origin
    assert "--" not in steel.origin  # in the app's words, not the command line's
    assert stated_case("coupon_fill20_steel.csv", materials=("steel",)).material == "steel"
    row = uploads.default_settings_row("coupon_fill20_steel.csv", steel)
    note = uploads.assumed_note(steel, row)
    assert note.startswith("material: acrylic assumed: the file name says 'steel'")
    assert uploads.assumed_note(steel, {**row, "material": "aluminium"}) == ""  # set by the user


def test_chart_specs_are_valid_vega_lite(good_csv, options):
    # The app writes the specs as dicts and sends them unvalidated (speed); validate them here
    # against the Vega-Lite schema that Altair ships (an independent statement of the format).
    import jsonschema
    from altair import SCHEMA_VERSION
    from altair.vegalite.v6.schema.core import load_schema

    from pidcore.app import charts

    schema = load_schema()
    validator = jsonschema.validators.validator_for(schema)(schema)
    assert charts.VEGA_LITE_SCHEMA.endswith(f"/{SCHEMA_VERSION.split('.')[0]}.json")
    rec = _record(good_csv, options)
    comp = compare_case([_entry(rec)], None, paper_table())
    specs = (charts.sdc_chart(sdc_points(comp)),
             charts.loop_chart(loop_frame([_entry(rec).loop()])),
             charts.spectrum_chart(_entry(rec).spectrum()))
    for spec in specs:
        # what Streamlit sends: JSON without NaN (a NaN would be invalid JSON)
        spec = json.loads(json.dumps(spec, allow_nan=False))
        validator.validate(spec)
        # every dataset a spec names is there, and every dataset is used
        names = set(re.findall(r'"data": \{"name": "([^"]*)"\}', json.dumps(spec)))
        assert names == set(spec["datasets"]) and all(spec["datasets"].values())
        # Vega-Lite reads "[" and "." in field names as nested access: none may be used.
        fields = json.dumps(spec["layer"] if "layer" in spec else spec.get("hconcat", spec))
        assert "[" not in "".join(re.findall(r'"field": "([^"]*)"', fields))
    # the validator does refuse a spec Vega-Lite would not draw
    assert not validator.is_valid({**specs[1], "mark": {"type": "lines"}})


def test_like_for_like_sdc_uses_the_dem_vibrated_mass_as_the_report_does(good_csv, options):
    from pidcore.report import build_report_table
    from pidcore.report.table import MEASURED_EQ10_COLUMN

    rec = _record(good_csv, options, name="c.csv")
    dem_runs = pd.DataFrame({
        "case_key": ["r1"], "frequency_hz": [100.0], "acceleration_g": [5.0],
        "fill_percent": [50.0], "material": ["acrylic"], "direction": ["z"],
        "sdc": [0.2], "sdc_stderr": [0.01], "m_c_kg": [0.9]})
    paper = paper_table()
    comp = compare_case([_entry(rec)], dem_runs, paper)
    a = rec.analysis
    w = 2 * math.pi * a.frequency_hz
    e_ref = 0.9 * (a.acceleration_g * 9.80665) ** 2 / (2 * w ** 2)  # Eq. 10 with m_c = 0.9 kg
    assert comp.measured_sdc_eq10 == pytest.approx(a.energy_per_cycle_j / e_ref, rel=1e-12)
    # Only the reference energy differs from the Eq. 11 SDC: same relative error.
    assert comp.measured_stderr_eq10 / comp.measured_sdc_eq10 == pytest.approx(
        a.sdc_stderr / a.sdc, rel=1e-12)
    from pidcore.measure import analysis_record

    analyses = pd.DataFrame([{**analysis_record(rec), "fill_percent": 50.0,
                              "material": "acrylic", "direction": "z"}])
    table = build_report_table(dem_runs, analyses, paper)
    assert table[MEASURED_EQ10_COLUMN].iloc[0] == pytest.approx(comp.measured_sdc_eq10,
                                                                 rel=1e-12)
    series = sdc_points(comp).groupby("series")
    assert series.get_group("measured, E of Eq. 10 (± stderr)")["SDC [-]"].iloc[0] == \
        comp.measured_sdc_eq10


def test_load_case_pdf_has_the_plots_and_the_corrections_page(good_csv, options):
    from dataclasses import replace

    from pidcore.report.case_sheet import case_pdf
    from pidcore.report.case_view import case_view

    rec = _record(good_csv, options, name="c_fill50.csv")
    corrected = replace(options, velocity_delay_s=50e-6, mass_below_gauge_kg=2e-3)
    entry = MeasuredEntry.from_record(rec, load_case_of(rec, fill_percent=50,
                                                        material="acrylic"),
                                      options=corrected)
    assert entry.corrections == ("vibrometer delay 50 µs, mass below gauge 2 g, "
                                 "baseline loss factor 0")
    view = case_view([entry], None, paper_table(), ())
    assert view["comparison"].measured["corrections"].tolist() == [entry.corrections]
    data = case_pdf(view, title="100 Hz, 5 g, 50 %")
    assert data.startswith(b"%PDF")
    # two pages (plots; files with their corrections): two page objects besides /Pages
    assert data.count(b"/Type /Page /") == 2


def test_a_file_saved_again_with_other_corrections_counts_once(tmp_path, good_csv, options):
    from dataclasses import replace

    from pidcore.store.listing import saved_analyses

    store_file = tmp_path / "s.h5"
    rec = _record(good_csv, options, name="c_fill50.csv")
    uploads.save_records(store_file, [_file(rec, options)])
    delayed = replace(options, velocity_delay_s=20e-6)
    rec2 = uploads.analyze_upload("c_fill50.csv", good_csv, delayed).record
    uploads.save_records(store_file, [_file(rec2, delayed)])
    saved = saved_analyses(store_file)
    # both analyses are kept in the store, the newest one is the file's result
    assert len(saved) == 1 and saved["sdc"].iloc[0] == rec2.analysis.sdc
    assert saved["file"].tolist() == ["c_fill50.csv"]
    table = store_report_table(store_file)
    assert table["SDC measured (Eq. 11) [-]"].dropna().tolist() == [rec2.analysis.sdc]


def test_an_empty_fills_field_takes_the_specimens_own_fill_as_the_cli_does():
    from pidcore.dem.simulate import particles_per_cell
    from pidcore.specimen import Specimen

    text = (REPO / "data_samples" / "specimens" / "steel_6mm.toml").read_text(encoding="utf-8")
    steel = Specimen.from_text(text)
    assert steel.particles.fill_percent == 50.0
    assert jobs.dem_fills("", steel) == (
        [50.0], "fills [%] empty: the specimen's own fill, 50 % ([particles] fill_percent)")
    # a count is its share of the capacity (what `pidcore dem run --specimen` runs), which
    # rounds back to that count
    counted = Specimen.from_text(text.replace("fill_percent = 50.0", "count_per_cell = 10"))
    capacity = counted.capacity_per_cell()
    (fill,), note = jobs.dem_fills("  ", counted)
    assert fill == 100.0 * 10 / capacity
    assert note == (f"fills [%] empty: the specimen's own fill, {fill:.4g} % ([particles] "
                    f"count_per_cell 10 of capacity {capacity})")
    assert particles_per_cell(fill, specimen=counted, fill_reference="capacity")[0] == 10
    # the very fill `pidcore dem run --specimen` runs without --fill
    from argparse import Namespace

    from pidcore.cli.dem import _fill

    for specimen in (steel, counted):
        # the app's runs take the capacity as 100 %, as dem run's default
        args = Namespace(fill=None, fill_reference="capacity")
        assert [_fill(args, specimen, "steel")] == jobs.dem_fills("", specimen)[0]
    # typed values win over the specimen's; an empty field with nothing to fall back on is
    # one line that says where a fill could come from
    assert jobs.dem_fills("25, 75", counted) == ([25.0, 75.0], None)
    bare = Specimen.from_text(text.replace("fill_percent = 50.0", ""))
    for specimen in (None, bare):
        with pytest.raises(ParameterError, match=r"^fills \[%\]: give at least one value \(or "
                                                 r"choose a specimen file stating count_per"):
            jobs.dem_fills("", specimen)
    with pytest.raises(ParameterError, match=r"^fills \[%\]: 'x' is not a number$"):
        jobs.dem_fills("x", steel)


@pytest.mark.dem_subprocess
def test_dem_jobs_run_on_the_chosen_specimen(tmp_path):
    from pidcore.dem import DemConfig
    from pidcore.dem.persist import run_key
    from pidcore.specimen import load_specimen

    steel = load_specimen(REPO / "data_samples" / "specimens" / "steel_6mm.toml")
    (case,) = jobs.plan_dem_cases([100.0], [5.0], [50.0], material=steel.particles.material,
                                  direction="z")
    config = DemConfig(cells=1, steady_cycles=4)
    runner = jobs.DemJobRunner(tmp_path / "s.h5")
    (job,) = runner.submit([case], config, steel)
    runner.cancel()
    _wait(runner)
    # the run is keyed (and would be stored) as the specimen's, not the paper coupon's
    assert job.run_key == run_key(case, config, steel) != run_key(
        jobs.plan_dem_cases([100.0], [5.0], [50.0], material="acrylic", direction="z")[0],
        config)
    assert job.specimen is steel


def test_calibration_digest_follows_the_content():
    # The Report tab's cached table is keyed by this digest: a new calibration (another band)
    # must give another key, the same file read again the same key.
    from pidcore.app.calibration import calibration_digest
    from pidcore.calibrate.prediction import calibration_from_json

    def doc(high95: float) -> str:
        return json.dumps({
            "parameters": {"rolling_friction": {"median": 0.05, "low95": 0.01, "high95": 0.1}},
            "predictions": [{"frequency_hz": 50, "acceleration_g": 5, "fill_percent": 50,
                             "material": "acrylic", "measured": 0.2, "predicted": 0.24,
                             "low95": 0.05, "high95": high95}]})

    first = calibration_from_json(doc(0.43), "calibration.json")
    again = calibration_from_json(doc(0.43), "calibration.json")
    other = calibration_from_json(doc(0.44), "calibration.json")
    assert calibration_digest(None) == ""
    assert calibration_digest(first) == calibration_digest(again) != calibration_digest(other)


# --- which DEM runs a measurement meets ----------------------------------------------------------

def _runs_at_100hz_5g_50(material: str, **columns: list) -> pd.DataFrame:
    """DEM runs at one load case (100 Hz, 5 g, 50 %, z) of ``material``, one per entry of the
    per-run ``columns`` (case_key, sdc, sdc_stderr, specimen_name, ...)."""
    n = len(columns["case_key"])
    return pd.DataFrame({"frequency_hz": [100.0] * n, "acceleration_g": [5.0] * n,
                         "fill_percent": [50.0] * n, "material": [material] * n,
                         "direction": ["z"] * n, **columns})


def _two_specimens_runs() -> pd.DataFrame:
    """One DEM run each of two specimens at one load case (as the new-user trial stored them:
    steel_6mm and its copy steel_6mm_b, both steel); b's never converged."""
    return _runs_at_100hz_5g_50(
        "steel", case_key=["run_a", "run_b"], sdc=[0.0197, 0.02308], sdc_stderr=[0.001, 0.001],
        steady_detected=[True, False], steady_start_cycle=[40, 200], steady_cycles=[30, 12],
        specimen_name=["steel_6mm", "steel_6mm_b"], specimen_sha256=["a" * 64, "b" * 64])


def _steel_entry(rec, specimen=""):
    return MeasuredEntry.from_record(rec, load_case_of(rec, fill_percent=50.0, material="steel"),
                                     specimen=specimen)


def test_a_measurement_meets_only_the_dem_runs_of_its_specimen(good_csv, options):
    from pidcore.report.case_view import case_view

    rec = _record(good_csv, options)
    runs = _two_specimens_runs()
    # named: that specimen's run only (the old code took steel_6mm's 0.0197 for either)
    for name, sdc in (("steel_6mm_b", 0.02308), ("steel_6mm", 0.0197)):
        view = case_view([_steel_entry(rec, name)], runs, paper_table(), ())
        assert view["headline"].dem == sdc
        assert view["dem_specimen"].startswith(f"{name} [")
        assert view["dem_refused"] == ""
    # not named, two specimens' runs at the case: neither is met, and the page says which
    view = case_view([_steel_entry(rec)], runs, paper_table(), ())
    assert math.isnan(view["headline"].dem)
    assert "steel_6mm [aaaaaa]" in view["dem_refused"]
    assert "steel_6mm_b [bbbbbb]" in view["dem_refused"] and "specimen" in view["dem_refused"]
    # not named, one specimen's runs: those
    view = case_view([_steel_entry(rec)], runs.iloc[:1], paper_table(), ())
    assert view["headline"].dem == 0.0197 and view["dem_specimen"] == "steel_6mm [aaaaaa]"
    # a name no run has: no DEM value, and why
    view = case_view([_steel_entry(rec, "brass_4mm")], runs, paper_table(), ())
    assert math.isnan(view["headline"].dem)
    assert any("no DEM runs of specimen brass_4mm" in n for n in view["notes"])


def test_unnamed_acrylic_measurements_still_meet_the_papers_coupon(good_csv, options):
    from pidcore.report.case_view import case_view
    from pidcore.specimen import paper_specimen

    rec = _record(good_csv, options)
    # a run stored before specimens (no hash) and one of the bundled paper coupon: one specimen
    runs = _runs_at_100hz_5g_50(
        "acrylic", case_key=["old", "new"], sdc=[0.20, 0.22], sdc_stderr=[0.01, 0.01],
        specimen_name=[None, "paper_coupon"], specimen_sha256=[None, paper_specimen().hash])
    view = case_view([_entry(rec)], runs, paper_table(), ())
    assert view["headline"].dem == pytest.approx(0.21)  # both pooled, as before
    assert view["dem_specimen"] == "paper_coupon" and view["dem_refused"] == ""


def test_a_calibrations_design_runs_do_not_hide_the_papers_coupon(good_csv, options):
    # a calibration's store as the app's: beside the coupon's own runs, its design runs (the
    # coupon's file with another rolling friction ..., named paper_coupon, another hash).
    # Compare refused every case ("the DEM runs ... are of 2 specimens"; named paper_coupon:
    # "2 different specimen files named paper_coupon"); `pidcore report` on the same store
    # compares the paper's coupon and names the others left out: so does Compare now
    from pidcore.report.case_view import case_view
    from pidcore.specimen import paper_specimen

    rec = _record(good_csv, options)
    runs = _runs_at_100hz_5g_50(
        "acrylic", case_key=["coupon", "design"], sdc=[0.20, 0.50], sdc_stderr=[0.01, 0.01],
        specimen_name=["paper_coupon"] * 2, specimen_sha256=[paper_specimen().hash, "c" * 64])
    for named in ("", "paper_coupon"):
        view = case_view([_entry(rec, specimen=named)], runs, paper_table(), ())
        assert view["headline"].dem == 0.20  # the coupon's run alone, not pooled
        assert view["dem_specimen"] == "paper_coupon" and view["dem_refused"] == ""
        (note,) = [n for n in view["notes"] if "other specimens" in n]
        assert "paper_coupon [cccccc] (1 run(s))" in note and "design point" in note
        assert "`specimen` column" in note  # how to choose another
    # without the coupon's own runs the design run is still not taken for it silently
    view = case_view([_entry(rec, specimen="paper_coupon")], runs.iloc[1:], paper_table(), ())
    assert view["headline"].dem == 0.50 and view["dem_specimen"] == "paper_coupon [cccccc]"


def test_compare_and_report_say_a_dem_run_did_not_converge_alike(good_csv, options):
    from pidcore.measure import analysis_record
    from pidcore.report import build_report_table
    from pidcore.report.case_view import case_view

    rec = _record(good_csv, options)
    runs = _two_specimens_runs()
    view = case_view([_steel_entry(rec, "steel_6mm_b")], runs, paper_table(), ())
    assert view["dem_warning"] == ("DEM run did not converge: steady state from cycle 200 (NOT "
                                   "converged, transient cap), 12 cycles measured; the DEM SDC "
                                   "may include the transient")
    assert case_view([_steel_entry(rec, "steel_6mm")], runs, paper_table(),
                     ())["dem_warning"] == ""
    # the report table's row of that run says the same words
    analyses = pd.DataFrame([{**analysis_record(rec), "fill_percent": 50.0, "material": "steel",
                              "direction": "z", "specimen": "steel_6mm_b"}])
    table = build_report_table(runs, analyses, paper_table())
    row = table[table["SDC measured (Eq. 11) [-]"].notna()]
    assert view["dem_warning"] in row["note"].iloc[0]


def test_the_report_table_pairs_a_measurement_with_its_specimens_dem_run(good_csv, options):
    from pidcore.measure import analysis_record
    from pidcore.report import build_report_table

    rec = _record(good_csv, options)
    runs = _two_specimens_runs()

    def measured_row(specimen):
        analyses = pd.DataFrame([{**analysis_record(rec), "fill_percent": 50.0,
                                  "material": "steel", "direction": "z",
                                  "specimen": specimen}])
        table = build_report_table(runs, analyses, paper_table())
        return table[table["SDC measured (Eq. 11) [-]"].notna()].iloc[0]

    assert measured_row("steel_6mm_b")["SDC DEM (ours) [-]"] == 0.02308
    assert measured_row("steel_6mm")["SDC DEM (ours) [-]"] == 0.0197
    unnamed = measured_row("")
    assert math.isnan(unnamed["SDC DEM (ours) [-]"]) and "not pooled" in unnamed["note"]


def test_a_job_before_its_first_block_shows_starting_and_no_eta(tmp_path):
    from pidcore.dem import DemConfig, LoadCase

    case = LoadCase(100.0, 5.0, 50.0, "acrylic", "z")
    job = jobs.DemJob("job0001", case, DemConfig(cells=1), "key")
    row = job.row()
    assert row["cycles [-]"] == "" and row["ETA [s]"] == ""  # queued: blank, not "0/?"/None
    assert row["specimen"] == "paper_coupon"
    job.state, job.started = "running", 100.0
    row = job.row(now=103.0)
    assert row["cycles [-]"] == "starting" and row["ETA [s]"] == ""
    assert job.progress_text(now=103.0) == f"job0001 {case.key}: starting, 3 s elapsed"
    job.settled_s = 0.0404  # the worker told the settle's simulated time (s)
    assert job.row(now=103.0)["cycles [-]"] == "settling the bed (40 ms simulated)"
    assert job.progress_text(now=103.0) == (f"job0001 {case.key}: settling the bed (40 ms "
                                             "simulated), 3 s elapsed")
    job.cycles_done, job.cycles_expected = 10, 40
    # 10 of 40 cycles in 3 s: 9 s left
    assert job.progress_text(now=103.0) == (f"job0001 {case.key}: 10/40 cycles, 3 s elapsed, "
                                             "ETA 9 s")
    assert list(row)[:4] == ["job", "state", "specimen", "load case"]


def test_an_uploaded_specimen_error_names_the_users_file():
    with pytest.raises(ParameterError, match=r"^syntax\.toml: not valid TOML"):
        jobs.specimen_from_upload("syntax.toml", b"name = 'x'\n[cell\n")
    with pytest.raises(ParameterError, match=r"syntax\.toml: not UTF-8 text \(byte 0xff on "
                                             r"line 1\)"):
        # (not b"\xff\xfe": that is UTF-16's byte-order mark, read as Notepad writes it)
        jobs.specimen_from_upload("syntax.toml", b"\xff\x00")
    # decoded as a file on disk is: an editor's byte-order mark was refused as "not valid
    # TOML" on upload while the same file loaded from disk
    from pidcore.specimen import load_specimen

    path = Path(__file__).resolve().parents[1] / "data_samples" / "specimens" / "steel_6mm.toml"
    uploaded = jobs.specimen_from_upload("steel_6mm.toml", b"\xef\xbb\xbf" + path.read_bytes())
    assert uploaded.hash == load_specimen(path).hash


@pytest.mark.parametrize("fills", [[40.0], [25.0, 50.0, 75.0, 90.0], [37.5, 39.13, 50.0]])
def test_sdc_chart_ticks_read_the_fills(fills):
    # Rendered by Vega itself (vl-convert), as the browser draws it: with "~g" Vega took the
    # precision from the tick step and labelled 25, 50, 75, 90 % "3e+1, 5e+1, 8e+1, 9e+1"
    # (before that, 40.000000 for a list of floats)
    vl_convert = pytest.importorskip("vl_convert")
    from pidcore.app.charts import sdc_chart

    data = pd.DataFrame({"series": ["paper DEM"] * len(fills), "packing ratio [%]": fills,
                         "SDC [-]": [0.2] * len(fills), "low [-]": [0.2] * len(fills),
                         "high [-]": [0.2] * len(fills)})
    svg = vl_convert.vegalite_to_svg(json.dumps(sdc_chart(data)))
    labels = re.findall(r'<text[^>]*>([^<]*)</text>', svg)
    title = labels.index("packing ratio [%]")
    assert labels[title - len(fills):title] == [f"{f:g}" for f in fills]


def test_sdc_chart_labels_the_model_curves_ends_beside_a_single_point():
    # a case off the paper's grid (150 Hz, 40 %): one tick, "40", under a pchip curve from 25
    # to 90 %: where the curve rose could not be read
    vl_convert = pytest.importorskip("vl_convert")
    from pidcore.app.charts import sdc_chart
    from pidcore.compare.case import SDC_SERIES

    model = np.linspace(25.0, 90.0, 14)
    data = pd.DataFrame({"series": [SDC_SERIES[0]] * len(model) + ["measured"],
                         "packing ratio [%]": [*model, 40.0], "SDC [-]": [0.2] * (len(model) + 1),
                         "low [-]": [0.2] * (len(model) + 1),
                         "high [-]": [0.2] * (len(model) + 1)})
    svg = vl_convert.vegalite_to_svg(json.dumps(sdc_chart(data)))
    labels = re.findall(r'<text[^>]*>([^<]*)</text>', svg)
    title = labels.index("packing ratio [%]")
    assert labels[title - 3:title] == ["25", "40", "90"]


def test_calibrate_page_keeps_saved_materials_apart_and_refuses_a_mixed_or_unknown_one(
        tmp_path, options):
    # a saved steel record (specimen steel_6mm_b) and an acrylic one of one load case: the
    # page's points name their material and are not averaged; the page calibrates the paper's
    # coupon, so steel points are refused before a background run starts (as the CLI does)
    import pidcore.calibrate as api
    from pidcore.app.calibration import points_by_material, points_for_specimen, runner_for

    store_file = tmp_path / "s.h5"
    acrylic = _record(mass_damper_csv(frequency_hz=100.0), options, name="a_fill50.csv")
    steel = _record(mass_damper_csv(frequency_hz=100.0, seed=3), options, name="b_fill50.csv")
    steel_case = load_case_of(steel, fill_percent=50.0, material="steel")
    uploads.save_records(store_file, [_file(acrylic, options),
                                      AnalysedFile(steel, steel_case, options, "steel_6mm_b")])
    points = api.measured_from_store(store_file)
    by = points_by_material(points)
    assert list(by) == ["acrylic", "steel"]
    assert by["steel"][0].specimen == "steel_6mm_b"
    assert by["steel"][0].sdc == steel.analysis.sdc  # its own value, not a mean with acrylic
    assert by["acrylic"][0].sdc == acrylic.analysis.sdc
    runner = runner_for(store_file)
    import dataclasses

    mixed = [*by["acrylic"], dataclasses.replace(by["acrylic"][0], material="aluminium")]
    # steel without its specimen file: the message points to the page's specimen chooser
    # (the library's names a command-line flag the page does not have)
    own = r"paper's coupon holds acrylic or aluminium .* of steel particles: choose their " \
          r"specimen file above"
    for chosen, words in ((mixed, "several particle materials"), (points, own),
                          (by["steel"], own)):
        with pytest.raises(ParameterError, match=words):
            runner.start(api, chosen, fit=["fixture_mass_kg"], cells=2, design_size=None)
    # with a specimen file, its particles must be the points': acrylic points are refused
    from pidcore.specimen import load_specimen

    steel_file = load_specimen(Path(__file__).resolve().parents[1] / "data_samples"
                               / "specimens" / "steel_6mm.toml")
    with pytest.raises(ParameterError, match="are of acrylic particles, the specimen "
                                             "'steel_6mm' holds steel particles"):
        runner.start(api, by["acrylic"], fit=["fixture_mass_kg"], cells=2, design_size=None,
                     specimen=steel_file)
    assert runner.task is None  # nothing started
    # the points a specimen is calibrated on: its particles, measured on it or on no named one
    kept, note = points_for_specimen(points, steel_file)
    # each left out with its reason (another specimen's steel is not this specimen's)
    assert kept == [] and note == ("Not used for steel_6mm (steel particles): 1 measured load "
                                   "case(s) of specimen steel_6mm_b; 1 measured load case(s) "
                                   "of acrylic particles.")
    # the calibrated file of a specimen is calibrated again on that specimen's measurements
    calibrated = dataclasses.replace(steel_file, name="steel_6mm_calibrated")
    named_b = dataclasses.replace(by["steel"][0], specimen="steel_6mm")
    assert points_for_specimen([named_b], calibrated) == ([named_b], "")
    named = dataclasses.replace(by["steel"][0], specimen="steel_6mm")
    unnamed = dataclasses.replace(by["steel"][0], specimen="")
    kept, _ = points_for_specimen([*points, named, unnamed], steel_file)
    assert kept == [named, unnamed]
    assert points_for_specimen([named], steel_file) == ([named], "")


def test_a_byte_identical_file_under_another_name_says_what_it_replaces(tmp_path, good_csv,
                                                                        options):
    # the store keys a measurement by its bytes: saving a copy under another name (and another
    # load case) is one record; the save names the record it replaces and keeps the new name
    from pidcore.store.listing import saved_analyses

    store_file = tmp_path / "s.h5"
    first = _record(good_csv, options, name="a_fill50.csv")
    assert uploads.save_records(store_file, [_file(first, options)]).notes == ()
    copy = _record(good_csv, options, name="b_fill75.csv")
    saved = uploads.save_records(store_file, [_file(copy, options, fill=75.0)])
    (note,) = saved.notes
    assert "b_fill75.csv has the same contents as the saved record a_fill50.csv" in note
    assert ", 50 %, acrylic, z)" in note and ", 75 %, acrylic, z) replaces it" in note
    rows = saved_analyses(store_file)
    assert rows["file"].tolist() == ["b_fill75.csv"]
    assert rows["fill_percent"].tolist() == [75.0]
    assert uploads.identical_uploads([("a.csv", "1"), ("b.csv", "1"), ("c.csv", "2")]) == [
        "b.csv has the same contents as a.csv: one measurement, saved as one record (under "
        "the name saved last) and counted once"]


def test_a_file_saved_again_with_another_delay_says_its_new_sdc_is_the_one_used(
        tmp_path, good_csv):
    # a second session uploaded the file without its settings table (delay 0 µs) and Save
    # said only "saved 1 analysis record(s)": Compare and Report moved to its SDC
    from pidcore.measure import AnalysisOptions
    from pidcore.store.listing import saved_analyses

    store_file = tmp_path / "s.h5"
    delayed = AnalysisOptions(velocity_delay_s=2e-5)
    first = _record(good_csv, delayed, name="a_fill50.csv")
    assert uploads.save_records(store_file, [_file(first, delayed)]).notes == ()
    plain = AnalysisOptions()
    again = _record(good_csv, plain, name="a_fill50.csv")
    (note,) = uploads.save_records(store_file, [_file(again, plain)]).notes
    # the page's field and unit (the library's words, "velocity_delay_s 2e-05 -> 0.0", are
    # the CLI's: tests/test_cli_analyze.py)
    assert note == (f"a_fill50.csv was saved before with other settings ('vibrometer delay "
                    f"[µs]' 20 -> 0 µs; SDC {first.analysis.sdc:.4g}); this analysis (SDC "
                    f"{again.analysis.sdc:.4g}) is the one reports and calibrations use now, "
                    "the earlier is kept in the store")
    assert f"{first.analysis.sdc:.4g}" != f"{again.analysis.sdc:.4g}"  # 0.72 deg at 100 Hz
    assert saved_analyses(store_file)["sdc"].tolist() == [again.analysis.sdc]


def test_saving_again_keeps_saying_which_analysis_reports_use_and_what_the_save_did(
        tmp_path, good_csv):
    # a second click on Save replaced "...saved before with other settings (...); this
    # analysis is the one reports use now" with only "(0 new, 1 already held with identical
    # content)"; and saving the earlier settings again made them the ones used, under "0 new,
    # 1 already held with identical content" beside a note saying the SDC used changed
    from pidcore.measure import AnalysisOptions
    from pidcore.store.listing import saved_analyses

    store_file = tmp_path / "s.h5"
    delayed, plain = AnalysisOptions(velocity_delay_s=2e-5), AnalysisOptions()
    first = _record(good_csv, delayed, name="a_fill50.csv")
    again = _record(good_csv, plain, name="a_fill50.csv")
    uploads.save_records(store_file, [_file(first, delayed)])
    (replaced,) = uploads.save_records(store_file, [_file(again, plain)]).notes
    twice = uploads.save_records(store_file, [_file(again, plain)])
    # the supersede is said again, as still so, and the count says it was held unchanged
    assert twice.notes == (replaced.replace("is the one reports and calibrations use now",
                                            "is still the one reports and calibrations use"),)
    assert f"SDC {first.analysis.sdc:.4g}); this analysis (SDC {again.analysis.sdc:.4g}) is " \
        "still the one" in twice.notes[0]
    assert twice.breakdown == "0 new, 1 already held with identical content"
    assert saved_analyses(store_file)["sdc"].tolist() == [again.analysis.sdc]
    # the earlier settings saved again: held, and now the one used again, as the count says
    back = uploads.save_records(store_file, [_file(first, delayed)])
    assert back.notes[0].endswith(f"this analysis (SDC {first.analysis.sdc:.4g}) is the one "
                                  "reports and calibrations use now, the earlier is kept in "
                                  "the store")
    assert back.breakdown == ("0 new, 1 already held, made the one reports and calibrations "
                              "use again")
    assert saved_analyses(store_file)["sdc"].tolist() == [first.analysis.sdc]


def test_the_page_says_a_changed_setting_in_its_field_and_unit():
    # the Analyse page's warning after a save said "velocity_delay_s 5e-05 -> 0.0" beside a
    # settings column in µs; null is a setting not given (a structure mass left at 0)
    from pidcore.app.vocabulary import page_terms

    said = page_terms("a.uff was saved before with other settings (baseline_loss_factor 0.0 "
                      "-> 0.02, mass_below_gauge_kg 0.0 -> 0.005, structure_mass_kg null -> "
                      "0.0483, velocity_delay_s 5e-05 -> 0.0; SDC 1.139)")
    assert said == ("a.uff was saved before with other settings ('baseline loss factor [-]' "
                    "0.0 -> 0.02, 'mass below gauge [g]' 0 -> 5 g, 'structure mass [g]' none "
                    "-> 48.3 g, 'vibrometer delay [µs]' 50 -> 0 µs; SDC 1.139)")


def test_a_session_reanalysis_with_other_settings_is_compared_in_place_of_the_saved_one(
        tmp_path, good_csv):
    # the trial saved a file with a 50 µs delay and uploaded it again with 0 µs: Analyse showed
    # SDC 1.038, Compare the saved 1.139 (its Eq. 10 too) with "left out, this session"
    from pidcore.compare.case import unique_entries
    from pidcore.measure import AnalysisOptions
    from pidcore.report.case_view import saved_entries
    from pidcore.store.listing import saved_analyses

    store_file = tmp_path / "s.h5"
    delayed = AnalysisOptions(velocity_delay_s=2e-5)
    first = _record(good_csv, delayed, name="a_fill50.csv")
    uploads.save_records(store_file, [_file(first, delayed)])
    saved = saved_entries(store_file, saved_analyses(store_file))
    # the app's channel mapping (a column of its table, saved as the channels used) is no
    # other setting
    plain = AnalysisOptions(force="Force")
    again = _record(good_csv, plain, name="a_fill50.csv")
    kept, notes = unique_entries([*saved, _entry(again, options=plain)])
    (shown,) = kept
    assert (shown.origin, shown.sdc) == ("this session (unsaved)", again.analysis.sdc)
    assert f"{first.analysis.sdc:.4g}" != f"{again.analysis.sdc:.4g}"  # 0.72 deg at 100 Hz
    assert notes == [
        f"a_fill50.csv was saved before with other settings (velocity_delay_s 2e-05 -> 0.0; "
        f"SDC {first.analysis.sdc:.4g}); this session's unsaved analysis (SDC "
        f"{again.analysis.sdc:.4g}) is the one compared, the saved one is left out (the same "
        "data are counted once); Save makes it the one reports and calibrations use"]
    # as the Compare tab says it, and the same data under another name: counted once
    assert "('vibrometer delay [µs]' 20 -> 0 µs; SDC " in uploads.app_words(notes[0])
    kept, notes = unique_entries([*saved, _entry(
        _record(good_csv, plain, name="b_fill50.csv"), options=plain)])
    assert [(e.file, e.sdc) for e in kept] == [("b_fill50.csv", again.analysis.sdc)]
    assert notes[0].startswith("b_fill50.csv was saved before as a_fill50.csv with other "
                               "settings (velocity_delay_s 2e-05 -> 0.0; ")
    # the settings saved: the saved record is compared, as before
    kept, notes = unique_entries([*saved, _entry(first, options=delayed)])
    assert [e.origin for e in kept] == ["store"] and notes == []


def test_identical_contents_are_pooled_once(tmp_path, good_csv, options):
    # the saved a.csv and this session's b.csv (same bytes) and a second session copy: one
    # measurement; pooling them would count the data three times (stderr / sqrt(3))
    from pidcore.compare.case import unique_entries
    from pidcore.report.case_view import saved_entries
    from pidcore.store.listing import saved_analyses

    store_file = tmp_path / "s.h5"
    uploads.save_records(store_file, [_file(_record(good_csv, options, name="a.csv"), options)])
    saved = saved_entries(store_file, saved_analyses(store_file))
    session = [_entry(_record(good_csv, options, name=n)) for n in ("b.csv", "c.csv")]
    other = _entry(_record(mass_damper_csv(seed=7), options, name="d.csv"))
    kept, notes = unique_entries([*saved, *session, other])
    assert [e.file for e in kept] == ["a.csv", "d.csv"]
    assert notes == [f"{n} left out, this session (unsaved): the same contents as a.csv "
                     "(saved); the same data are counted once" for n in ("b.csv", "c.csv")]
    # a.csv still in the session after its Save is its own saved copy: left out silently
    kept, notes = unique_entries([*saved, _entry(_record(good_csv, options, name="a.csv"))])
    assert [e.file for e in kept] == ["a.csv"] and notes == []


def test_specimen_files_offer_their_material_and_an_unknown_one_says_how(tmp_path):
    # a settings table stating brass: refused with the way to make brass known; a specimen
    # file of steel makes steel a material to state before any DEM run of it is saved
    from pidcore.compare.case import stated_case

    folder = tmp_path / "specimens"
    folder.mkdir()
    (folder / "steel.toml").write_bytes(
        (REPO / "data_samples" / "specimens" / "steel_6mm.toml").read_bytes())
    (folder / "broken.toml").write_text("not = [toml")
    found = uploads.specimen_materials([folder, tmp_path / "missing"])
    assert found == ["steel"]
    assert "steel" in uploads.measurement_materials(found)
    table = b"file,material\nx.csv,brass\n"
    with pytest.raises(ParameterError, match=r"unknown particle material 'brass'.*once a "
                                             r"specimen file of it is in the specimen folders"):
        uploads.read_settings_table("settings_brass.csv", table)
    row = {"fill [%]": 50.0, "material": "acrylic"}
    stated = stated_case("coupon.csv")
    assert uploads.assumed_note(stated, row) == "material: not stated, acrylic assumed"
    # a row stating no fill has no load case, hence no material (uploads.no_fill_note)
    assert uploads.assumed_note(stated, {**row, "fill [%]": ""}) == ""
    assert uploads.assumed_note(stated, {"fill [%]": 62.0, "material": "steel"}) == ""


def test_one_name_is_one_file_and_a_table_statement_is_not_assumed():
    # the same file selected again made the settings table a row shorter than the uploads (a
    # traceback); two different files under one name: the last is used, and said
    kept, notes = uploads.distinct_uploads([("a.csv", "1"), ("b.csv", "2"), ("a.csv", "1")])
    assert kept == [1, 2] and notes == []
    kept, notes = uploads.distinct_uploads([("a.csv", "1"), ("a.csv", "3")])
    assert kept == [1] and notes == ["a.csv: uploaded twice with different contents; the last "
                                     "upload is used (give the files different names to "
                                     "analyse both)"]
    # a table stating the default value (50 %, acrylic) states it: no "not stated" note
    table = uploads.read_settings_table("t.csv", b"file,fill_percent,material\n"
                                                 b"run.csv,50,acrylic\nother.csv,,steel\n",
                                        ("acrylic", "aluminium", "steel"))
    given = uploads.columns_given([table], "run.csv")
    assert given == {"fill [%]", "material"}
    row = {"fill [%]": 50.0, "material": "acrylic"}
    assert uploads.assumed_note(stated_case("run.csv"), row, given) == ""
    assert uploads.assumed_note(stated_case("run.csv"), row) != ""  # nothing given: said
    assert uploads.columns_given([table], "other.csv") == {"material"}


def test_an_unset_vibrometer_delay_is_said_where_a_velocity_channel_is_used():
    # the bundled samples (50 µs) were analysed at 0 µs in the app, SDC 2.80 instead of 4.09,
    # with no word; a fill or material not stated was said, a delay not
    row = {"vibrometer delay [µs]": 0.0}
    note = uploads.delay_note(row, velocity_used=True)
    assert note.startswith("vibrometer delay: none given, 0 µs assumed")
    assert uploads.delay_note({"vibrometer delay [µs]": float("nan")}, velocity_used=True)
    # given in the row or by a settings table (even as 0), or no vibrometer: nothing to say
    assert uploads.delay_note({"vibrometer delay [µs]": 50.0}, velocity_used=True) == ""
    assert uploads.delay_note(row, {"vibrometer delay [µs]"}, velocity_used=True) == ""
    assert uploads.delay_note(row, velocity_used=False) == ""


def test_the_bundled_sample_table_gives_the_samples_delay_to_the_app():
    # data_samples/loadcases.csv is the app's settings table for the samples: 50 µs each
    table = uploads.read_settings_table(
        "loadcases.csv", (REPO / "data_samples" / "loadcases.csv").read_bytes())
    assert table["vibrometer delay [µs]"].astype(float).tolist() == [50.0] * 5


def test_identical_files_stating_different_load_cases_are_not_saved_together(tmp_path,
                                                                             good_csv, options):
    # one content is one record: saving both would keep one statement and drop the other
    from pidcore.store import Store

    a = _record(good_csv, options, name="a_fill50.csv")
    b = _record(good_csv, options, name="b_fill75.csv")
    both = [_file(a, options), _file(b, options, fill=75.0)]
    assert uploads.saved_count(both) == 1
    with pytest.raises(ParameterError, match=r"b_fill75\.csv and a_fill50\.csv have identical "
                                             r"contents but state different load cases"):
        uploads.save_records(tmp_path / "s.h5", both)
    assert not (tmp_path / "s.h5").exists() or Store(tmp_path / "s.h5").list_analyses().empty
    # said before Save (the page promised "one record", then Save refused), naming every
    # clash: a third copy at 90 % was only found after the first was fixed
    c = _record(good_csv, options, name="c_fill90.csv")
    three = [*both, _file(c, options, fill=90.0)]
    said = uploads.load_case_conflict(three)
    assert "b_fill75.csv and a_fill50.csv" in said and "c_fill90.csv and a_fill50.csv" in said
    assert uploads.load_case_conflict([both[0]]) == ""
    # the same load case stated on two specimens: the message tells the statements apart
    # (it read "(case vs case)" when only the specimen differed)
    apart = [_file(a, options, specimen="panel_A"), _file(b, options, specimen="panel_B")]
    with pytest.raises(ParameterError, match=r"on panel_B vs .* on panel_A\)"):
        uploads.save_records(tmp_path / "s.h5", apart)
    same = [_file(a, options), _file(_record(good_csv, options, name="copy.csv"), options)]
    assert len(set(uploads.save_records(tmp_path / "s.h5", same).keys)) == 1


def test_the_dem_runs_table_says_why_a_run_has_no_standard_error():
    # a one-cell run's missing stderr showed as a literal "None" in the grid
    import pandas as pd

    runs = pd.DataFrame({"frequency_hz": [100.0, 100.0, 50.0], "acceleration_g": [5.0] * 3,
                         "fill_percent": [50.0] * 3, "material": ["acrylic"] * 3,
                         "sdc": [1.09, 1.10, 0.6], "sdc_stderr": [None, 0.0123456, float("nan")],
                         "cells_simulated": [1, 8, 4], "case_key": ["a", "b", "c"]})
    table = jobs.dem_runs_table(runs)
    assert table["SDC stderr [-]"].tolist() == ["n/a (1 cell)", "0.0123", "n/a"]
    assert table["SDC [-]"].tolist() == [1.09, 1.10, 0.6]  # the values stay numbers


def test_run_says_which_cases_are_already_stored():
    # re-running a stored case said "1 job(s) submitted" while the job said "in store"
    queued = jobs.DemJob("job0001", None, None, "k1", None)
    stored = jobs.DemJob("job0002", None, None, "k2", None, state="in store")
    assert jobs.submitted_text(3, [queued, stored]) == (
        "1 job(s) submitted; 1 already in the store, not run again; 1 already queued or "
        "running, not submitted again")
    assert jobs.submitted_text(1, [queued]) == "1 job(s) submitted"


def test_run_clicked_twice_names_the_job_already_queued_or_running(tmp_path):
    # a double click on Run said "0 job(s) submitted; 1 already queued or running": no job
    # named, and "0 submitted" read as a failure
    from pidcore.dem import DemConfig

    runner = jobs.DemJobRunner(tmp_path / "dem.h5")
    cases = jobs.plan_dem_cases([50.0], [5.0], [50.0], material="acrylic", direction="z")
    config = DemConfig(cells=1, steady_cycles=5000)  # long: still queued or running below
    try:
        (first,) = runner.submit(cases, config)
        again = runner.submit(cases, config)
        assert list(again) == [] and again.already == [first]
        assert jobs.submitted_text(1, again) == (
            f"{first.job_id} (50 Hz, 5 g, 50 %) already queued or running: not submitted twice")
        # beside a case that is submitted, the one not submitted is named too
        more = runner.submit([*cases, *jobs.plan_dem_cases(
            [60.0], [5.0], [50.0], material="acrylic", direction="z")], config)
        assert [j.case.frequency_hz for j in more] == [60.0] and more.already == [first]
        assert jobs.submitted_text(2, more) == (
            f"1 job(s) submitted; {first.job_id} (50 Hz, 5 g, 50 %) already queued or "
            "running, not submitted twice")
    finally:
        runner.cancel()
        runner.wait_cancelled(5.0)


def test_available_calibrations_list_this_stores_first_and_say_what_cannot_be_read(tmp_path):
    from pidcore.app.calibration import CALIBRATION_ENV_VAR, CalibrationTask, available_calibrations

    doc = {"parameters": {"fixture_mass_kg": {"median": 0.2, "low95": 0.1, "high95": 0.3}},
           "predictions": [{"frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": 50.0,
                            "material": "acrylic", "measured": 0.3, "predicted": 0.3,
                            "low95": 0.1, "high95": 0.6}]}
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps(doc))
    env = {CALIBRATION_ENV_VAR: str(path)}
    done = CalibrationTask(("fixture_mass_kg",), 1, "steel_6mm", state="done",
                           outputs={"calibration.json": json.dumps(doc).encode()})
    found = available_calibrations(done, env)
    assert [label.split(" (")[0] for _, label in found] == [
        "this store's calibration of steel_6mm on the Calibrate page", str(path)]
    assert all(c is not None for c, _ in found)
    # this store's cannot be read: the file's is still offered, and the problem is said last
    broken = CalibrationTask(("fixture_mass_kg",), 1, "steel_6mm", state="done",
                             outputs={"calibration.json": b'{"runs": 1}'})
    found = available_calibrations(broken, env)
    assert found[0][1] == str(path) and found[-1][0] is None
    assert found[-1][1].startswith("calibration not shown: ")
    assert available_calibrations(None, {CALIBRATION_ENV_VAR: str(tmp_path / "none.json")})[0][0] \
        is None


def test_a_failed_calibration_says_the_librarys_line_in_the_pages_terms(tmp_path):
    # it showed "calibration of paper_coupon failed: ParameterError: pidcore:paper_coupon.toml:
    # ...", and the library's notes and errors advised command-line flags the page lacks
    import types

    from pidcore.app.calibration import CalibrationRunner, CalibrationTask, page_words

    def failing(error):
        def calibrate(points, **kw):
            raise error
        return types.SimpleNamespace(calibrate=calibrate)

    runner = CalibrationRunner(tmp_path / "s.h5")
    for error, said in (
            (ParameterError("fit: unknown parameter 'frction'; expected ... "
                            "(pidcore specimen check)"),
             "parameters to fit: unknown parameter 'frction'; expected ... (as `pidcore "
             "specimen check` lists them)"),
            (KeyError("x"), "KeyError: 'x'")):  # an unexpected error keeps its name
        task = CalibrationTask(("friction",), 3)
        runner._run(failing(error), task, [], ["friction"], 2, None, None)
        assert (task.state, task.message) == ("failed", said)
    # a bound note (summary.md) advises the page's default prior, not a flag to type here
    from pidcore.calibrate.parameters import build_specs
    from pidcore.calibrate.posterior import bound_notes

    (spec,) = build_specs(["fixture_mass_kg"], discrepancy=0.2)
    (note,) = bound_notes([spec], np.zeros((100, 1)))  # piled on the lower bound 0
    assert "(priors=fixture_mass_kg=LOW:HIGH)" in note
    assert "(the page fits the default prior; `pidcore calibrate --prior fixture_mass_kg=LOW:" \
           "HIGH` widens it)" in page_words(note)
    assert page_words("design_size 5 ignored: no DEM parameter") == \
        "design points 5 ignored: no DEM parameter"


def test_the_paper_coupon_page_leaves_out_measurements_of_another_specimen():
    # the library refuses them for the paper's coupon; the page leaves them out and says so
    from pidcore.app.calibration import points_for_paper
    from pidcore.calibrate import MeasuredPoint

    mine = [MeasuredPoint(100, 1, 50, 0.2), MeasuredPoint(200, 1, 50, 0.2,
                                                          specimen="paper_coupon")]
    other = MeasuredPoint(300, 1, 50, 0.2, specimen="steel_6mm_b")
    assert points_for_paper([*mine, other]) == (mine, "Not used for the paper's coupon: 1 "
                                                "measured load case(s) of specimen steel_6mm_b "
                                                "(choose their specimen file above).")
    assert points_for_paper(mine) == (mine, "")


def test_dem_job_of_a_fill_whose_simulation_is_stored_is_not_run_again(tmp_path):
    """The DEM tab queued a run of fill 26 % although the store held the run of fill 25 %:
    6 acrylic particles per cell either way, the same seed and settings, the same numbers."""
    from pidcore.dem import DemConfig
    from pidcore.dem.persist import run_key, run_or_load

    store_file = tmp_path / "dem.h5"
    config = DemConfig(cells=1, steady_cycles=4, block_cycles=2, max_transient_cycles=2)
    (stored, same) = jobs.plan_dem_cases([1000.0], [5.0], [25.0, 26.0], material="acrylic",
                                         direction="z")
    run_or_load(store_file, None, stored, config)
    runner = jobs.DemJobRunner(store_file)
    (job,) = runner.submit([same], config)
    assert job.state == "in store" and "same simulation" in job.message
    assert job.run_key == run_key(stored, config)  # the run it is, as stored


# --- refused and unmatched settings tables; the report's missing numbers ------------------------

def test_a_refused_settings_table_holds_back_the_files_it_names():
    # the app analysed and saved a file whose table it had refused (no delay: SDC 1.034 for
    # 1.136); the files it names wait for it, and a table that cannot be read holds back all
    table = b"file,velocity_delay_us\nrun_a.uff,50 us\nsub/run_b.uff,40\n"
    with pytest.raises(ParameterError) as refused:
        uploads.read_settings_table("settings.csv", table)
    held = uploads.refused_table("settings.csv", table, str(refused.value))
    assert held.files == ("run_a.uff", "sub/run_b.uff")
    assert held.refuses("run_a.uff") and held.refuses("run_b.uff")  # by base name, as merged
    assert not held.refuses("run_c.uff")
    line = uploads.refusal_of("run_a.uff", [held])
    assert line.startswith("run_a.uff: not analysed") and "settings.csv" in line
    assert "\n" not in line and uploads.refusal_of("run_c.uff", [held]) == ""
    # a table the reader cannot read cannot say which files it names: it holds back all
    broken = b"file,velocity_delay_us\nrun_a.uff,50,7\n"  # a row longer than the header
    assert uploads.refused_table("settings.csv", broken, "bad").files is None
    assert uploads.refusal_of("any.uff", [uploads.refused_table("s.csv", broken, "bad")])
    # a Latin-1 (cp1252) table is read by the same reader: its "ö" file name is matched
    latin = "file,velocity_delay_us\nrün_a.uff,50 us\n".encode("latin-1")
    assert uploads.refused_table("settings.csv", latin, "bad").files == ("rün_a.uff",)


def test_a_table_with_an_unknown_column_is_read_as_a_table_and_refused():
    # read as a measurement it was refused as "no data rows", and its file was analysed as if
    # the table had never been uploaded
    table = b"file,velocity_delay_ms\nrun_a.uff,0.05\n"
    assert uploads.is_settings_table(table)
    with pytest.raises(ParameterError, match=r"unknown column\(s\) 'velocity_delay_ms'"):
        uploads.read_settings_table("settings.csv", table)
    assert not uploads.is_settings_table(b"file,notes\nx,y\n")  # remarks only: no settings


def test_a_settings_table_says_which_rows_match_no_uploaded_file():
    # "settings of 1 file(s) read" was said of a table whose only row named no upload
    table = uploads.read_settings_table(
        "settings.csv", b"file,velocity_delay_us\nsynthetic_typo.uff,50\nrun_a.uff,40\n")
    info, warning = uploads.table_match_note("settings.csv", table, ["run_a.uff", "b.uff"])
    assert info == "settings.csv: 1 of 2 row(s) match uploaded files (vibrometer delay [µs])"
    assert "line 2 'synthetic_typo.uff'" in warning and "run_a.uff" not in warning
    assert uploads.table_match_note("settings.csv", table,
                                    ["synthetic_typo.uff", "x/run_a.uff"])[1] == ""
    # lines as the file numbers them (comment and blank lines counted), as every other
    # message names a row: it said line 3 of a row on line 6
    commented = uploads.read_settings_table(
        "settings.csv", b"# delays from the lab book\nfile,velocity_delay_us\n\nrun_a.uff,40\n"
                        b"# next coupon\nsynthetic_typo.uff,50\n")
    assert "line 6 'synthetic_typo.uff'" in uploads.table_match_note(
        "settings.csv", commented, ["run_a.uff"])[1]


def test_the_report_tab_says_why_a_result_has_no_number():
    # the grid showed a 1-cell run's missing standard error as a literal "None"
    from pidcore.app.workbench import report_display

    table = pd.DataFrame({
        "SDC DEM (ours) [-]": [1.1, 0.5, math.nan, 0.7],
        "SDC DEM stderr [-]": [math.nan, 0.0123456, math.nan, math.nan],
        "SDC measured (Eq. 11) [-]": [1.13, math.nan, 0.9, 0.8],
        "measured chi2/dof [-]": [math.nan, math.nan, 1.234, math.nan],
        "DEM settings": ["cells 1, steady cycles auto, settings hash 44136f",
                         "cells 4, steady cycles auto, settings hash 44136f", "", ""],
        "source file(s)": ["a.uff", "", "a.uff; b.uff", "c.uff; d.uff"]})
    shown = report_display(table)
    assert shown["SDC DEM stderr [-]"].tolist() == ["n/a (1 cell)", "0.0123", "", "n/a"]
    assert shown["measured chi2/dof [-]"].tolist() == ["n/a (1 measurement)", "", "1.2", "n/a"]
    assert math.isnan(table["SDC DEM stderr [-]"].iloc[0])  # the table itself is unchanged


def test_report_zip_holds_the_figures_that_the_markdown_and_latex_files_link(
        tmp_path, good_csv, options):
    """The downloaded pidcore_report.md showed a broken image and the .tex did not compile:
    both link figures/<stem>.png, which no download held."""
    import io
    import re
    import zipfile

    rec = _record(good_csv, options, name="coupon.csv")
    store_file = tmp_path / "store.h5"
    uploads.save_records(store_file, [_file(rec, options)])
    files = report_files(store_file)
    name, data, mime = files["zip"]
    assert name == "pidcore_report.zip" and mime == "application/zip"
    archive = zipfile.ZipFile(io.BytesIO(data))
    # every other download, byte for byte, under its own download name
    for fmt in ("csv", "md", "html", "tex", "pdf", "csv_provenance"):
        assert archive.read(files[fmt][0]) == files[fmt][1]
    md_links = re.findall(r"!\[[^]]*\]\(([^)]+)\)", files["md"][1].decode())
    # {{figures/<stem>}.png}: the base name braced, as old graphicx needs for the dots of a
    # load case's name in it
    tex_links = ["".join(parts) for parts in re.findall(
        r"\\includegraphics(?:\[[^]]*\])?\{\{([^}]+)\}(\.png)\}", files["tex"][1].decode())]
    assert md_links and tex_links
    for link in md_links + tex_links:
        assert archive.read(link).startswith(b"\x89PNG"), link


def test_report_download_names_the_seeds_of_the_specimens_runs_only(tmp_path):
    """The provenance of the app's report lists the seeds of the runs of the specimen
    reported (the paper's coupon by default), not another specimen's in the same store."""
    from pidcore.store import Store

    store_file = tmp_path / "app.h5"
    Store(store_file).add_dem_run("paper", {**_dem_record(0.40), "seed": 11})
    Store(store_file).add_dem_run("other", {**_dem_record(0.30, fill=75.0), "seed": 22,
                                            "specimen_sha256": "f" * 64})
    files = report_files(store_file)
    provenance = files["csv_provenance"][1].decode()
    assert "seeds: 11\n" in provenance or provenance.rstrip().endswith("seeds: 11")
    assert "22" not in provenance.split("seeds:")[1].splitlines()[0]


@pytest.mark.parametrize("rows", [
    ["RUN_A.uff", "Run_A.uff"],            # names differing only by case
    ["lab1/run_a.uff", "lab2/run_a.uff"],  # one base name under two folders
], ids=["case", "folders"])
def test_an_ambiguous_settings_row_is_refused_as_the_cli_refuses_it(tmp_path, rows):
    # the app applied the first base-name match (or none) where `pidcore analyze` refuses the
    # table: the rows are matched by the CLI's find_row, with its message
    from pidcore.compare.loadcase import sidecar_row

    data = ("file,velocity_delay_us\n" + "".join(f"{r},{40 + i}\n" for i, r in
                                                  enumerate(rows))).encode()
    table = uploads.read_settings_table("settings.csv", data)
    with pytest.raises(ParameterError) as app:
        uploads.check_table_rows("settings.csv", table, ["other.uff", "run_a.uff"])
    sidecar = tmp_path / "settings.csv"
    sidecar.write_bytes(data)
    with pytest.raises(ParameterError) as cli:
        sidecar_row(tmp_path / "run_a.uff", sidecar)
    assert str(app.value) == str(cli.value).replace(str(sidecar), "settings.csv")
    assert str(app.value).startswith(f"settings.csv: line 2 ({rows[0]!r}) and line 3 "
                                     f"({rows[1]!r}) both match 'run_a.uff'")
    held = uploads.refused_table("settings.csv", data, str(app.value))
    assert held.refuses("run_a.uff") and not held.refuses("other.uff")
    uploads.check_table_rows("settings.csv", table, ["other.uff"])  # concerns no upload


def test_a_settings_row_is_found_as_the_cli_finds_it():
    # a case-folded match is the row (the CLI's); the app left such a file without settings
    table = uploads.read_settings_table("s.csv", b"file,velocity_delay_us\nRUN_A.uff,50\n")
    settings = uploads.merge_settings(["run_a.uff"], [stated_case("run_a.uff")], None, [table])
    assert settings["vibrometer delay [µs]"].tolist() == [50.0]
    assert uploads.columns_given([table], "run_a.uff") == {"vibrometer delay [µs]"}
    assert uploads.table_match_note("s.csv", table, ["run_a.uff"])[1] == ""
    # an exact name is preferred to a case-folded one, as the CLI prefers it
    both = uploads.read_settings_table("s.csv", b"file,velocity_delay_us\nRUN_A.uff,50\n"
                                                b"run_a.uff,40\n")
    uploads.check_table_rows("s.csv", both, ["run_a.uff"])
    assert uploads.merge_settings(["run_a.uff"], [stated_case("run_a.uff")], None, [both])[
        "vibrometer delay [µs]"].tolist() == [40.0]
    # a cell naming the app's working folder is not taken for the upload's folder
    cwd = Path.cwd().name
    folders = uploads.read_settings_table("s.csv", f"file,velocity_delay_us\n{cwd}/run_a.uff,"
                                                   f"50\nother/run_a.uff,40\n".encode())
    with pytest.raises(ParameterError, match="both match 'run_a.uff'"):
        uploads.check_table_rows("s.csv", folders, ["run_a.uff"])


def test_two_fills_of_one_simulation_in_one_submission_are_run_once(tmp_path):
    """The DEM tab ran and stored fills 25 and 26 % of one submission twice: 6 acrylic
    particles per cell either way, the same seed and settings, the same numbers (the CLI's
    `dem sweep` runs them once)."""
    from pidcore.dem import DemConfig
    from pidcore.dem.persist import run_key
    from pidcore.store import Store

    store_file = tmp_path / "dem.h5"
    config = DemConfig(cells=1, steady_cycles=4, block_cycles=2, max_transient_cycles=2)
    cases = jobs.plan_dem_cases([1000.0], [5.0], [25.0, 26.0], material="acrylic",
                                direction="z")
    runner = jobs.DemJobRunner(store_file)
    first, second = runner.submit(cases, config)
    assert first.state in ("queued", "running")
    assert second.state == "same run" and second.run_key == run_key(cases[0], config)
    assert f"as {first.job_id} (fill 25 %)" in second.message
    assert jobs.submitted_text(2, [first, second]) == (
        "1 job(s) submitted; 1 the same simulation as another job (same particle count and "
        "seed), run once")
    # submitted again while it runs: the same run is not queued a second time either
    (again,) = runner.submit(cases[1:], config)
    assert again.state == "same run"
    deadline = time.monotonic() + 300
    while runner.busy():
        assert time.monotonic() < deadline
        time.sleep(0.05)
    # once saved, the jobs of its other fills are in the store (under its key), as the CLI's
    assert [j.state for j in runner.jobs()] == ["saved", "in store", "in store"]
    assert runner.jobs()[1].message.endswith(f"; saved by it as {first.run_key}")
    assert runner.jobs()[1].fraction() == 1.0
    assert Store(store_file).list_dem_runs()["case_key"].tolist() == [first.run_key]


def test_a_job_waiting_for_a_cancelled_same_simulation_says_it_was_not_run(tmp_path):
    # its partner cancelled, the "same run" job would wait for a run that never comes
    from pidcore.dem import DemConfig

    config = DemConfig(cells=1, steady_cycles=4, block_cycles=2, max_transient_cycles=2)
    cases = jobs.plan_dem_cases([1000.0], [5.0], [25.0, 26.0], material="acrylic",
                                direction="z")
    runner = jobs.DemJobRunner(tmp_path / "dem.h5")
    first, second = runner.submit(cases, config)
    assert runner.cancel() == 1  # the one queued or running; the other never runs
    assert runner.wait_cancelled(30)
    states = {j.job_id: j for j in runner.jobs()}
    assert states[second.job_id].state == "cancelled"
    assert states[second.job_id].message.startswith(f"not run: {first.job_id}")


def test_a_fill_rounding_to_no_particle_is_a_job_that_says_so_not_a_traceback(tmp_path):
    # Run with fills "1, 25" on the DEM page: submit computed each case's simulation identity
    # (particles per cell) and raised "fill 1 % of 22 particles rounds to none" out of the
    # page's script, a Streamlit traceback, and the valid case was not queued either
    from pidcore.dem import DemConfig

    config = DemConfig(cells=1, steady_cycles=4, block_cycles=2, max_transient_cycles=2)
    cases = jobs.plan_dem_cases([1000.0], [5.0], [1.0, 25.0], material="acrylic",
                                direction="z")
    runner = jobs.DemJobRunner(tmp_path / "dem.h5")
    refused, queued = runner.submit(cases, config)
    assert refused.state == "failed" and "rounds to none" in refused.message
    assert queued.state in ("queued", "running")
    assert jobs.submitted_text(2, [refused, queued]).startswith(
        "1 job(s) submitted; 1 not run ('fill [%]' 1 % of 22 particles rounds to none")
    assert runner.cancel() == 1 and runner.wait_cancelled(30)


def test_a_unit_slip_note_in_the_app_does_not_point_at_options_the_page_lacks():
    # a velocity in m/s under 'Velocity [mm/s]' beside an acceleration channel: the note
    # (added for `pidcore analyze`) told the app user to "check both units (--velocity-unit,
    # --acceleration-unit)", options the app does not have
    from pidcore.measure import AnalysisOptions

    fs, f0 = 10_000.0, 100.0
    t = np.arange(10_000) / fs
    w = 2 * math.pi * f0
    v = 0.05 * np.sin(w * t)
    rows = "\n".join(f"{a:.9e},{0.2 * np.cos(w * a):.9e},{b:.9e},{w * 0.05 * np.cos(w * a):.9e}"
                     for a, b in zip(t, v, strict=True))
    data = ("Time [s],Force [N],Velocity [mm/s],Acceleration [m/s^2]\n" + rows + "\n").encode()
    outcome = uploads.analyze_upload("slip.csv", data, AnalysisOptions())
    (note,) = [n for n in outcome.record.notes if "unit slip" in n]
    assert "1000 x" in note and "--velocity-unit," not in note
    assert "the app takes each channel's unit from its file" in note
    # a unit the file does not give: the error says where the unit comes from in the app
    bare = data.replace(b"Force [N]", b"Force")
    error = uploads.analyze_upload("bare.csv", bare, AnalysisOptions()).error
    assert error is not None and "give it with --force-unit" not in error
    assert "the app takes units from the file" in error


def test_two_refused_settings_tables_are_named_in_the_plural():
    # "the settings table unknown.csv, ambiguous.csv that gives its settings was refused"
    one = uploads.RefusedTable("a.csv", "bad", None)
    two = uploads.RefusedTable("b.csv", "bad", None)
    assert "the settings table a.csv that gives its settings was refused" in \
        uploads.refusal_of("x.uff", [one])
    assert "the settings tables a.csv, b.csv that give its settings were refused" in \
        uploads.refusal_of("x.uff", [one, two])
    assert uploads.refused_tables_text([one]).startswith("the settings table a.csv is refused")
    assert uploads.refused_tables_text([one, two]).startswith(
        "the settings tables a.csv, b.csv are refused")


@pytest.mark.parametrize("cell", ["150", "0", "fifty"])
def test_a_settings_table_with_a_fill_out_of_range_is_refused_as_the_cli_refuses_it(
        tmp_path, cell):
    # the app accepted the table ("1 of 1 row(s) match") and each file's card said "no valid
    # load case ... set it in the settings table"; `pidcore analyze` refuses the table, naming
    # its line and file
    from pidcore.compare.loadcase import resolve_load_case

    data = f"file,fill_percent\nrun_a.uff,{cell}\n".encode()
    with pytest.raises(ParameterError) as app:
        uploads.read_settings_table("settings.csv", data)
    sidecar = tmp_path / "settings.csv"
    sidecar.write_bytes(data)
    with pytest.raises(ParameterError) as cli:
        resolve_load_case(tmp_path / "run_a.uff", sidecar=sidecar)
    assert str(app.value) == str(cli.value).replace(str(sidecar), "settings.csv")
    assert str(app.value).startswith("settings.csv, line 2 (run_a.uff): fill ")


def test_the_sample_rate_hint_names_the_apps_option():
    # "give the sample rate (--sample-rate)": the app has no such option, but a field
    outcome = uploads.parse_upload("no_time.csv", b"Force [N],Velocity [m/s]\n1,2\n3,4\n")
    assert "--sample-rate" not in outcome.error
    assert "'sample rate if no time column' under 'Options for every file'" in outcome.error


@pytest.mark.parametrize(("sdc", "stderr", "shown"), [
    (0.1856, 0.0042, "0.1856 ± 0.0042"),  # the usual look is kept
    (0.0231, 0.0010, "0.0231 ± 0.0010"),
    (1.5702e-4, float("nan"), "0.000157"),  # the paper's 50 Hz, 1 g, 25 % DEM value
    # a mass without damping, within noise: rounded at the error's last digit
    (5.09e-5, 4.4e-5, "5.1e-05 ± 4.4e-05"),
    # a noise-free record's round-off error: six significant digits at most, and the error
    # said to be below their last place (it read 0.250000 ± 1.1e-14)
    (0.25, 1.1e-14, "0.250000 ± <0.000001"),
    # never coarser than its own error where six digits reach it (it showed 8.168 ± 0.00030)
    (8.168123, 0.0003, "8.16812 ± 0.00030"),
])
def test_sdc_shown_on_the_pages_keeps_its_digits(sdc, stderr, shown):
    """Four fixed decimals showed the paper's SDC 1.5702e-4 as 0.0002 and an undamped
    mass's 5.1e-5 ± 4.4e-5 as 0.0001 ± 0.0000 (a nonzero error shown as zero) on the
    Analyse and Compare pages and the case sheet."""
    from pidcore.app.uploads import format_sdc

    assert format_sdc(sdc, stderr) == shown
    for text in shown.split(" ± "):  # each number shown reads back within its last digit
        assert "0.0000" != text
    assert float(shown.split(" ± ")[0]) == pytest.approx(sdc, rel=5e-3)


def test_the_pages_calibration_keeps_what_it_left_out_in_its_outputs(tmp_path):
    # the Calibrate page named records left out as implausible in a caption, but its
    # downloadable summary and calibration.json (what Compare and Report then read) did not,
    # unlike `pidcore calibrate --store`'s
    import types

    from pidcore.app.calibration import CalibrationRunner, CalibrationTask

    written = {}

    def write_outputs(result, folder, *, wording=None):
        written["notes"] = list(result.notes)
        written["wording"] = wording
        return []

    api = types.SimpleNamespace(
        calibrate=lambda points, **kw: types.SimpleNamespace(notes=["the fit's own note"]),
        write_outputs=write_outputs)
    task = CalibrationTask(("fixture_mass_kg",), 3)
    left = "bad.csv: left out, implausible (saved as accepted): SDC 9.4 above 6.28"
    CalibrationRunner(tmp_path / "s.h5")._run(api, task, [], ["fixture_mass_kg"], 2, None,
                                              None, [left])
    assert task.state == "done"
    assert written["notes"] == [left, "the fit's own note"]
    # the downloaded summary said the library's keywords (priors=...), which the page has
    # no field of; it says the notes as the page shows them
    note = "widen the prior (priors=model_discrepancy=LOW:HIGH)"
    from pidcore.app.calibration import page_words

    assert written["wording"] is not None and written["wording"](note) == page_words(note)
    assert "priors=" not in written["wording"](note)


def test_the_report_tab_defaults_to_the_newest_calibration_of_the_specimen_reported(tmp_path):
    # a steel calibration saved after the paper's was the Report tab's default for the paper
    # coupon's report: every calibrated cell empty while Compare showed the paper's band
    from pidcore.app.calibration import default_calibration_index
    from pidcore.calibrate.prediction import calibration_from_json

    doc = {"parameters": {"fixture_mass_kg": {"median": 0.2, "low95": 0.1, "high95": 0.3}},
           "predictions": [{"frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": 50.0,
                            "material": "acrylic", "measured": 0.3, "predicted": 0.3,
                            "low95": 0.1, "high95": 0.6}]}

    def of(name):
        return calibration_from_json(json.dumps(doc).encode(), f"{name}.json",
                                     specimen_name=name)

    newest_first = [(of("steel_6mm"), "steel"), (of("paper_coupon"), "paper"),
                    (of("steel_6mm"), "older steel")]
    assert default_calibration_index(newest_first, "paper_coupon") == 1
    assert default_calibration_index(newest_first, "steel_6mm") == 0
    # a calibration naming no specimen speaks for any; none speaking for it: the first
    assert default_calibration_index([(of(""), "file")], "my_panel") == 0
    assert default_calibration_index(newest_first[:1], "my_panel") == 0


def _two_files_named_x():
    """Two specimen files named x (the second an edit of the first: another coupon mass) and
    the calibration.json text of a fit of one of them."""
    from pidcore.specimen import Specimen, paper_specimen

    first = Specimen.from_text(paper_specimen().to_toml().replace(
        'name = "paper_coupon"', 'name = "x"'))
    edited = first.with_values({"coupon.mass_kg": 0.03})
    text = json.dumps({"parameters": {"fixture_mass_kg": {"median": 0.2, "low95": 0.1,
                                                          "high95": 0.3}},
                       "predictions": [{"frequency_hz": 100.0, "acceleration_g": 5.0,
                                        "fill_percent": 50.0, "material": "acrylic",
                                        "measured": 0.3, "predicted": 0.3, "low95": 0.1,
                                        "high95": 0.6}]})
    return first, edited, text


def test_the_report_tab_default_goes_by_the_reported_files_hash(tmp_path):
    # two files named x (the second an edit of the first): the calibration of the earlier x
    # saved last was the default for a report of the edited x (by its name), and every
    # calibrated cell said "not compared" while the edited file's own calibration was offered
    import dataclasses

    from pidcore.app.calibration import default_calibration_index
    from pidcore.calibrate.prediction import calibration_from_json
    from pidcore.specimen import calibrated_provenance

    first, edited, text = _two_files_named_x()
    doc = text.encode()

    def of(start):
        made = dataclasses.replace(start.with_values({"coupon.fixture_mass_kg": 0.2}),
                                   name="x_calibrated", provenance=calibrated_provenance(start))
        read = calibration_from_json(doc, f"{start.hash[:6]}.json", specimen_name="x")
        return dataclasses.replace(read, specimen_text=made.to_toml())

    newest_first = [(of(first), "of the first x"), (of(edited), "of the edited x")]
    assert default_calibration_index(newest_first, "x") == 0  # by the name alone: both
    assert default_calibration_index(newest_first, "x", edited) == 1
    assert default_calibration_index(newest_first, "x", first) == 0


def test_the_app_names_a_saved_calibrations_specimen_file_by_its_hash(tmp_path):
    # calibrations of two files named x (an edited x.toml) were listed and offered as "of x"
    # alike: which file each was made from is said by its hash, as the DEM runs are labelled
    import dataclasses

    from pidcore.app.calibration import saved_calibrations_table, stored_calibration_label
    from pidcore.calibrate import stored_calibrations
    from pidcore.specimen import calibrated_provenance, paper_specimen
    from pidcore.store import Store

    first, edited, text = _two_files_named_x()
    store = tmp_path / "app.h5"
    for i, start in enumerate((first, edited)):
        made = dataclasses.replace(start, name="x_calibrated",
                                   provenance=calibrated_provenance(start))
        Store(store).add_calibration(f"cal_{i}", {"specimen": "x", "specimen_hash": start.hash},
                                     document=text, specimen_toml=made.to_toml())
    labels = [f"x [{s.hash[:6]}]" for s in (edited, first)]  # newest first
    assert list(saved_calibrations_table(store)["specimen"]) == labels
    said = [stored_calibration_label(c) for c in stored_calibrations(store)]
    assert [f"of {label} (" in text for label, text in zip(labels, said, strict=True)] == \
        [True, True], said
    # the paper's coupon keeps its one name
    paper = paper_specimen()
    Store(store).add_calibration("cal_p", {"specimen": "paper_coupon", "specimen_hash": paper.hash},
                                 document=text, specimen_toml=dataclasses.replace(
                                     paper, name="paper_coupon_calibrated",
                                     provenance=calibrated_provenance(paper)).to_toml())
    assert saved_calibrations_table(store)["specimen"].iloc[0] == "paper_coupon"
    assert " of paper_coupon (" in stored_calibration_label(stored_calibrations(store)[0])

def test_a_damaged_calibration_in_the_store_does_not_hide_the_others(tmp_path):
    # one calibration of the store whose calibration.json was cut short hid every one of
    # them on Compare, Report and the Calibrate page ("calibrations of the store not shown")
    from pidcore.app.calibration import available_calibrations
    from pidcore.calibrate.persist import readable_calibrations
    from pidcore.store import Store

    doc = {"parameters": {"fixture_mass_kg": {"median": 0.2, "low95": 0.1, "high95": 0.3}},
           "predictions": [{"frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": 50.0,
                            "material": "acrylic", "measured": 0.3, "predicted": 0.3,
                            "low95": 0.1, "high95": 0.6}]}
    store = tmp_path / "s.h5"
    text = json.dumps(doc)
    Store(store).add_calibration("cal_good", {"specimen": "paper_coupon"}, document=text,
                                 specimen_toml="")
    Store(store).add_calibration("cal_cut", {"specimen": "steel_6mm"},
                                 document=text[:len(text) // 2], specimen_toml="")
    readable, damaged = readable_calibrations(store)
    assert [c.store_key for c in readable] == ["cal_good"]
    assert len(damaged) == 1 and "cal_cut" in damaged[0] and "\n" not in damaged[0]
    found = available_calibrations(None, {}, cwd=tmp_path, store_path=store)
    assert found[0][0] is not None and found[0][0].store_key == "cal_good"
    assert found[-1][0] is None and "cal_cut" in found[-1][1]
    assert readable_calibrations(tmp_path / "none.h5") == ([], [])


def test_a_structure_mass_typed_in_mg_is_refused_in_the_pages_unit():
    # 280000 typed in 'structure mass [g]' was refused as "structure_mass_kg 280 kg ...
    # expected ... in kg (was it in g?)": the field's name and a unit the column does not
    # take; typing kg there (0.28) is refused as a unit slip in turn
    from pidcore.measure import AnalysisOptions

    parsed = uploads.parse_upload("c_fill50.csv", mass_damper_csv())
    outcome = uploads.analyze_parsed(parsed, AnalysisOptions(baseline_loss_factor=0.01,
                                                             structure_mass_kg=280.0))
    # the field named as everywhere on the page, quoted (it was unquoted here alone, beside
    # "('structure mass [g]' in g" in the same sentence)
    assert outcome.error.startswith("c_fill50.csv: 'structure mass [g]' 280000 g is ")
    assert "structure_mass_kg" not in outcome.error
    assert "('structure mass [g]' in g; a structure_mass_g column of the settings table in g)" \
        in outcome.error


def test_the_corrections_say_how_the_baseline_went_off():
    # Compare's corrections column read "baseline loss factor 0.0152" for a record with the
    # exact subtraction (structure mass given) and one off the whole vibrated mass, whose
    # SDCs differ by the baseline x the particles' share
    from pidcore.compare.case import describe_corrections

    exact = describe_corrections({"baseline_loss_factor": 0.0152, "structure_mass_kg": 0.28})
    whole = describe_corrections({"baseline_loss_factor": 0.0152, "structure_mass_kg": None})
    assert exact.endswith("baseline loss factor 0.0152 (of a structure mass 280 g)")
    assert whole.endswith("baseline loss factor 0.0152 (off the whole vibrated mass)")
    # no baseline: the structure mass changes nothing and is not named
    assert describe_corrections({"structure_mass_kg": 0.28}).endswith("baseline loss factor 0")


def test_the_corrections_word_each_setting_as_the_settings_notes_do():
    # Compare's corrections column and the settings' notes (FileSettings.label, the report's
    # parameters) each wrote the words and units of the delay, masses and baseline: one
    # table now (pidcore.compare.settings_columns), which the comparison layer may import
    from pidcore.compare.case import describe_corrections
    from pidcore.file_settings import FileSettings
    from pidcore.measure import AnalysisOptions
    from pidcore.report.provenance import parameter_in_words

    options = AnalysisOptions(velocity_delay_s=5e-5, mass_below_gauge_kg=0.012,
                              baseline_loss_factor=0.0152, structure_mass_kg=0.0222)
    corrections = describe_corrections(vars(options))
    assert corrections == ("vibrometer delay 50 µs, mass below gauge 12 g, baseline loss "
                           "factor 0.0152 (of a structure mass 22.2 g)")
    label = FileSettings(options).label().split(", ")
    for name in ("velocity_delay_s", "mass_below_gauge_kg", "baseline_loss_factor",
                 "structure_mass_kg"):
        said = parameter_in_words(name, getattr(options, name))
        assert said in label and said in corrections, (said, label, corrections)


def test_compare_notes_a_saved_baseline_off_the_whole_vibrated_mass(tmp_path, good_csv,
                                                                   options):
    # the Report tab and `pidcore report` note a record whose baseline loss factor went off
    # the whole vibrated mass (its SDC low); Compare showed the saved record without it
    from dataclasses import replace

    from pidcore.report.case_view import case_view, saved_entries
    from pidcore.report.pipeline import whole_mass_baseline_note
    from pidcore.store.listing import saved_analyses

    whole = replace(options, baseline_loss_factor=0.01, structure_mass_kg=None)
    exact = replace(options, baseline_loss_factor=0.01, structure_mass_kg=0.28)
    for name, opts in (("whole.h5", whole), ("exact.h5", exact)):
        store_file = tmp_path / name
        rec = _record(good_csv, opts, name="a.csv")
        uploads.save_records(store_file, [_file(rec, opts)])
        (saved,) = saved_entries(store_file, saved_analyses(store_file))
        notes = case_view([saved], None, paper_table(), ())["notes"]
        # the same note, word for word, as the report's for the same stored settings
        expected = whole_mass_baseline_note([vars(opts)])
        assert bool(expected) == (opts is whole)
        assert (expected in notes) if expected else not any(
            "whole vibrated mass" in n for n in notes), notes
        # the session's unsaved analysis says the same
        unsaved = case_view([_entry(rec, options=opts)], None, paper_table(), ())["notes"]
        assert ((expected in unsaved) if expected
                else not any("whole vibrated mass" in n for n in unsaved))


def test_a_report_build_runs_in_the_background_and_says_why_it_failed():
    from pidcore.app.report_builds import start_report_build

    release = threading.Event()

    def slow():
        release.wait(30.0)
        return {"csv": ("r.csv", b"x", "text/csv")}

    build = start_report_build(("stamp", 1), slow)
    assert build.state == "running" and build.files == {}  # returned before the build ended
    # the same report asked again while it runs: the running build, not a second one
    assert start_report_build(("stamp", 1), slow, build) is build
    release.set()
    deadline = time.monotonic() + 30
    while build.state == "running":
        assert time.monotonic() < deadline
        time.sleep(0.01)
    assert build.state == "done" and build.files["csv"][1] == b"x" and build.message == ""

    def refused():
        raise ParameterError("store.h5: no DEM runs of specimen steel")

    def broken():
        raise KeyError("x")

    for fn, said in ((refused, "store.h5: no DEM runs of specimen steel"),
                     (broken, "KeyError: 'x'")):
        failed = start_report_build(("stamp", 2), fn, build)
        assert failed is not build  # another state of the store: a new build
        while failed.state == "running":
            assert time.monotonic() < deadline
            time.sleep(0.01)
        assert (failed.state, failed.message, failed.files) == ("failed", said, {})


def test_cancel_says_when_there_is_nothing_to_cancel_and_what_it_cannot_cancel():
    # Before, Cancel with no job running warned "cancel requested for 0 job(s)", and a job of
    # another app server of the store went unmentioned though it kept running.
    mine = jobs.DemJob("job0001", None, None, "k1", None, state="saved")
    theirs = jobs.DemJob("job0002", None, None, "k2", None, state="running",
                         server="pid 812 on host lab3")
    assert jobs.cancelled_text(0, [mine]) == (
        "info", "nothing to cancel: no job of this app server is queued or running")
    level, said = jobs.cancelled_text(2, [mine, theirs])
    assert level == "warning" and said == (
        "cancel requested for 2 job(s); finished cases stay saved; 1 job(s) queued or running "
        "on another app server of this store cannot be cancelled here (cancel them on that "
        "server's page)")


def test_the_calibrate_page_names_its_fitted_parameters_as_its_fit_field_offers_them():
    # the Calibrate page's summary read "Fitted: rolling_friction, fixture_mass_kg,
    # 'baseline loss factor [-]'" (the Analyse tab's per-file column, another quantity) and an
    # unknown parameter's error offered "'baseline loss factor [-]'", a name the 'parameters
    # to fit' field does not hold and 'more parameters' refuses
    import pidcore.calibrate as api
    from pidcore.app.calibration import fittable_names, page_words

    summary = (REPO / "data_samples" / "paper_calibration" / "summary.md").read_text()
    shown = page_words(summary)
    assert "'baseline loss factor [-]'" not in shown
    assert shown.splitlines()[2] == summary.splitlines()[2]  # the "Fitted: ..." line as is
    # the fitted table's row keeps its parameter's name (read from the file: the bundled
    # calibration's numbers change when it is regenerated; 0.01518 was hard-coded here)
    row = next(line for line in summary.splitlines()
               if line.startswith("| baseline_loss_factor | "))
    assert row in shown.splitlines()
    with pytest.raises(ParameterError) as refused:
        api.parse_fit(["bogus_field"])
    said = page_words(str(refused.value))
    assert said.startswith("parameters to fit: unknown parameter 'bogus_field'")
    offered = fittable_names(api)
    assert "baseline_loss_factor" in offered
    # every parameter the error lists is one the page's fit field offers, by that name
    for name in ("fixture_mass_kg", "baseline_loss_factor", "rolling_friction"):
        assert re.search(rf"(?<![\w']){name}(?![\w'])", said), name
    # the keywords the page does have fields for are still said as those fields
    assert page_words("structure_mass_kg=0.28 refused; baseline_loss_factor fitted") == \
        "'structure mass [g]' (280) refused; baseline_loss_factor fitted"


def test_a_dem_worker_reports_a_refusal_as_its_line_not_its_exception_class():
    # the job table read "ParameterError: frequency 1e+09 Hz: ..." for a case the DEM refuses
    import multiprocessing

    from pidcore.dem import DemConfig
    from pidcore.dem import LoadCase as DemLoadCase

    parent, child = multiprocessing.Pipe()
    jobs._child(DemLoadCase(1e9, 5.0, 50.0), DemConfig(cells=1), None, child)
    kind, message = parent.recv()
    assert kind == "error"
    assert message.startswith("frequency 1e+09 Hz: 128 samples per drive period need")
    assert "Error" not in message


def test_a_dem_worker_reports_the_settle_before_its_first_block_of_cycles():
    # the job said "starting" through the whole settle of the bed (20 s at 50 Hz, 8 cells)
    import contextlib
    import multiprocessing

    from pidcore.dem import DemConfig
    from pidcore.dem import LoadCase as DemLoadCase
    from pidcore.dem.simulate import clear_settled_beds

    clear_settled_beds()  # a kept bed is copied, not settled: make this one settle
    parent, child = multiprocessing.Pipe()
    jobs._child(DemLoadCase(1000.0, 5.0, 25.0, "acrylic", "z"),
                DemConfig(cells=1, steady_cycles=4, max_transient_cycles=4), None, child)
    messages = []
    with contextlib.suppress(EOFError):  # the worker closed its end after "done"
        while parent.poll():
            messages.append(parent.recv())
    kinds = [m[0] for m in messages]
    assert kinds[0] == "settling" and kinds[-1] == "done"
    first_block = kinds.index("progress")
    assert set(kinds[:first_block]) == {"settling"} and "settling" not in kinds[first_block:]
    settled = [m[1] for m in messages[:first_block]]
    # simulated seconds, growing; never past the run's own settle time (the last report may
    # be short of it: reports are at most one per 0.5 s of wall time)
    settle_time_s = messages[-1][1]["record"]["settle_time_s"]
    assert settled == sorted(settled) and 0 < settled[-1] <= settle_time_s


def test_a_specimen_file_uploaded_as_a_measurement_is_told_where_it_belongs():
    # the Analyse uploader read a specimen TOML as a CSV: "no rows of numbers in its 38 lines"
    toml = (Path(__file__).resolve().parents[1] / "data_samples" / "specimens" /
            "steel_6mm.toml").read_bytes()
    parsed = uploads.parse_upload("my coupon.TOML", toml)
    assert parsed.measurement is None
    assert parsed.error == ("my coupon.TOML: a specimen file (TOML), not a shaker-test export; "
                            "the Analyse tab takes it with the exports as their specimen, "
                            "the DEM and Calibrate tabs as 'or a specimen file (TOML)'")
    # the Analyse tab takes it apart before reading, any case of its suffix
    assert uploads.is_specimen_file("my coupon.TOML") and not uploads.is_specimen_file("a.csv")
    # the file is what is wrong, as for any other upload that holds no measurement
    from pidcore.errors import InputFileError

    with pytest.raises(InputFileError, match=r"^my coupon\.TOML: a specimen file"):
        uploads.read_upload("my coupon.TOML", toml)


def test_a_running_calibration_counts_its_design_runs_done(tmp_path):
    # the page said "calibrating ...: 340 s elapsed" and nothing else for many minutes
    from pidcore.app.calibration import CalibrationTask
    from pidcore.store import Store

    store = tmp_path / "s.h5"
    Store(store).add_dem_run("held", {"frequency_hz": 100.0, "acceleration_g": 5.0,
                                      "fill_percent": 50.0, "material": "acrylic",
                                      "direction": "z", "sdc": 0.25, "sdc_stderr": 0.02})
    task = CalibrationTask(("friction",), 3)
    task.started, task.finished = 1000.0, 1040.0  # 40 s elapsed, whatever the clock says
    assert task.progress_text() == "40 s elapsed"  # before the design is made
    task.design(["held", "a", "b", "a", "c"], store)  # a key asked twice is one run
    assert (task.runs_total, task.runs_stored_before) == (4, 1)
    assert task.progress_text() == "1 of 4 DEM runs (1 from the store), 40 s elapsed"
    task.run_done("a")
    # one run computed in 40 s, two left: 80 s
    assert task.progress_text() == ("2 of 4 DEM runs (1 from the store), 40 s elapsed, "
                                    "ETA 80 s")
    task.run_done("b")
    task.run_done("c")
    assert task.progress_text() == "4 of 4 DEM runs (1 from the store), 40 s elapsed"


def test_a_cancelled_calibration_stops_at_its_next_run_and_keeps_the_saved_ones(tmp_path):
    # a calibration of the page could not be stopped (minutes to hours of DEM runs)
    import pidcore.calibrate as api
    from pidcore.app.calibration import CalibrationRunner, CalibrationTask
    from pidcore.calibrate import MeasuredPoint
    from pidcore.store import Store

    store = tmp_path / "s.h5"
    points = [MeasuredPoint(500, 5, 50, 0.6), MeasuredPoint(1000, 5, 50, 0.6),
              MeasuredPoint(500, 1, 50, 0.2)]
    runner = CalibrationRunner(store)
    task = runner.task = CalibrationTask(("restitution",), len(points))
    counted = task.run_done

    def first_run_then_cancel(key: str) -> None:  # the user's click as the first run ends
        assert runner.cancel()
        counted(key)

    task.run_done = first_run_then_cancel
    runner._run(api, task, points, ["restitution"], 2, 3, None)  # 3 design points: 9 runs
    assert (task.state, task.runs_total, task.runs_done) == ("cancelled", 9, 1)
    assert task.message == ("1 DEM run(s) computed before the cancel are kept in s.h5; the "
                            "running ones were stopped and nothing of them saved; run the same "
                            "calibration again to resume (stored runs are reused)")
    saved = Store(store)
    # the run saved before the cancel, and nothing after it (the other worker was stopped)
    assert len(saved.list_dem_runs()) == 1
    assert saved.list_calibrations().empty  # no calibration of a cancelled run
    assert not runner.cancel()  # nothing runs any more


def test_a_cancel_after_every_dem_run_finished_says_none_was_running(tmp_path):
    # clicked as the last run was saved ("25 of 25 DEM runs (5 from the store)"), the page
    # said "20 DEM run(s) computed ...; the running ones were stopped and nothing of them
    # saved" though no run was left to stop
    import pidcore.calibrate as api
    from pidcore.app.calibration import CalibrationRunner, CalibrationTask
    from pidcore.calibrate import MeasuredPoint
    from pidcore.store import Store

    store = tmp_path / "s.h5"
    points = [MeasuredPoint(500, 5, 50, 0.6), MeasuredPoint(1000, 5, 50, 0.6),
              MeasuredPoint(500, 1, 50, 0.2)]
    # the first point's run stored before (by an earlier fit of the same tests): 1 of 3
    api.calibrate(points[:1], fit=["baseline_loss_factor"], discrepancy=0.2, store_path=store,
                  cells=2, progress=False, workers=1)
    runner = CalibrationRunner(store)
    task = runner.task = CalibrationTask(("fixture_mass_kg",), len(points))
    counted = task.run_done

    def cancel_at_the_last_run(key: str) -> None:  # the user's click as the last run ends
        if task.runs_stored_before + task.runs_done + 1 == task.runs_total:
            assert runner.cancel()
        counted(key)

    task.run_done = cancel_at_the_last_run
    runner._run(api, task, points, ["fixture_mass_kg"], 2, None, None)
    assert (task.state, task.runs_total, task.runs_stored_before, task.runs_done) == \
        ("cancelled", 3, 1, 2)
    assert task.message == (
        "every one of its 3 DEM runs had finished (1 from the store before) and none was "
        "running: 2 DEM run(s) computed before the cancel are kept in s.h5, and the fit was "
        "stopped before a calibration was saved; run the same calibration again to fit on the "
        "stored runs (no DEM run is computed again)")
    saved = Store(store)
    assert len(saved.list_dem_runs()) == 3 and saved.list_calibrations().empty
    # before the design was made no run had started, and none is said to have been stopped
    assert CalibrationTask(("friction",), 3).cancelled_text("s.h5") == (
        "cancelled before its DEM runs started; s.h5 holds nothing new of it")


def test_cancel_stops_the_running_calibration_runs_within_seconds(tmp_path, monkeypatch):
    # Cancel stopped a calibration only when its next DEM run was saved: a minute or more
    # with a run going. Here each run but the quick ones takes 60 s (_pool_probe), so only a
    # stop of the running ones ends the calibration within the budget.
    import functools

    from _pool_probe import QUICK_FREQUENCY_HZ, alive, slow_calibration_run

    import pidcore.calibrate as api
    from pidcore.app.calibration import CalibrationRunner
    from pidcore.calibrate import MeasuredPoint
    from pidcore.calibrate import runner as calibration_runs
    from pidcore.store import Store

    folder = tmp_path / "workers"
    folder.mkdir()
    monkeypatch.setattr(calibration_runs, "_run_entry",
                        functools.partial(slow_calibration_run, str(folder)))
    store = tmp_path / "s.h5"
    held = {"frequency_hz": 50.0, "acceleration_g": 1.0, "fill_percent": 25.0,
            "material": "acrylic", "direction": "z", "sdc": 0.1, "sdc_stderr": 0.01}
    Store(store).add_dem_run("held", held)  # a run of another calibration, kept untouched
    # the quick point's 3 runs come first in the design (points in order): both workers then
    # take a run of 60 s
    points = [MeasuredPoint(QUICK_FREQUENCY_HZ, 5, 50, 0.6), MeasuredPoint(1000, 5, 50, 0.6),
              MeasuredPoint(1000, 1, 50, 0.2)]
    runner = CalibrationRunner(store)
    task = runner.start(api, points, fit=["restitution"], cells=2, design_size=3)
    deadline = time.monotonic() + 60  # cold imports of the workers on a loaded machine
    while (task.runs_done < 3 or len(list(folder.glob("slow-*"))) < 2) \
            and task.state == "running" and time.monotonic() < deadline:
        time.sleep(0.02)
    assert (task.state, task.runs_total, task.runs_done) == ("running", 9, 3)
    assert runner.cancel()
    asked = time.monotonic()
    while task.state == "running" and time.monotonic() - asked < 60:
        time.sleep(0.02)
    # the stop itself takes ~0.1 s (a look at the stop event, a terminate of 2 workers); 10 s
    # leaves room for a loaded machine and is far short of the 60 s a running run takes
    assert time.monotonic() - asked < 10
    assert task.state == "cancelled"
    assert task.message == ("3 DEM run(s) computed before the cancel are kept in s.h5; the "
                            "running ones were stopped and nothing of them saved; run the same "
                            "calibration again to resume (stored runs are reused)")
    runs = Store(store).list_dem_runs()
    # the quick point's 3 runs are kept for a resume, nothing of the stopped ones, the
    # other calibration's run as it was, and no calibration
    assert sorted(runs["frequency_hz"]) == [50.0, QUICK_FREQUENCY_HZ, QUICK_FREQUENCY_HZ,
                                            QUICK_FREQUENCY_HZ]
    assert Store(store).get_dem_run("held").record["sdc"] == 0.1
    assert Store(store).list_calibrations().empty
    workers = {int(f.name.split("-")[1]) for f in folder.iterdir()}
    assert len(workers) == 2 and not any(alive(pid) for pid in workers)
    assert not runner.cancel()


def test_a_cancel_after_the_dem_runs_saves_no_calibration(tmp_path):
    # Cancel was looked at only as a DEM run was saved: one clicked after the last (while the
    # posterior was sampled or the outputs written) was dropped, and the calibration saved
    import types

    from pidcore.app.calibration import CalibrationRunner, CalibrationTask

    runner = CalibrationRunner(tmp_path / "s.h5")
    task = runner.task = CalibrationTask(("friction",), 3)
    saved = []

    def write_outputs(result, folder, *, wording=None):  # the user's click meanwhile
        assert runner.cancel()
        (Path(folder) / "summary.md").write_text("# summary\n")
        return [Path(folder) / "summary.md"]

    api = types.SimpleNamespace(
        calibrate=lambda points, **kw: types.SimpleNamespace(notes=[]),
        write_outputs=write_outputs,
        save_calibration=lambda result, store_path: saved.append(result) or ("c1", True))
    runner._run(api, task, [], ["friction"], 2, None, None)
    assert task.state == "cancelled" and not saved and task.outputs == {}
    assert not runner.cancel()


def test_a_stop_reaches_the_last_run_of_a_resumed_calibration_too(tmp_path, monkeypatch):
    # One run left (a resume) ran in the calibration's own thread, where nothing can stop it
    # before its end; with a stop it goes to a worker process like the others.
    import functools
    import threading

    from _pool_probe import alive, slow_calibration_run

    from pidcore.calibrate import runner as calibration_runs
    from pidcore.calibrate.runner import RunRequest
    from pidcore.dem import DemConfig
    from pidcore.dem import LoadCase as DemLoadCase
    from pidcore.interrupt import StopRequested
    from pidcore.specimen import paper_specimen
    from pidcore.store import Store

    folder = tmp_path / "workers"
    folder.mkdir()
    monkeypatch.setattr(calibration_runs, "_run_entry",
                        functools.partial(slow_calibration_run, str(folder)))
    request = RunRequest(DemLoadCase(1000.0, 5.0, 50.0, "acrylic", "z"), paper_specimen(),
                         DemConfig(cells=2))
    stop = threading.Event()
    errors = []

    def resume() -> None:
        try:
            calibration_runs.run_requests([request], store_path=tmp_path / "s.h5",
                                          progress=False, stop=stop)
        except StopRequested as exc:
            errors.append(exc)

    thread = threading.Thread(target=resume)
    thread.start()
    deadline = time.monotonic() + 60
    while not list(folder.glob("slow-*")) and time.monotonic() < deadline:
        time.sleep(0.02)
    stop.set()
    thread.join(10)  # as the test above: the stop takes ~0.1 s, the run 60 s
    assert not thread.is_alive() and len(errors) == 1
    assert not (tmp_path / "s.h5").exists() or Store(tmp_path / "s.h5").list_dem_runs().empty
    pids = [int(f.name.split("-")[1]) for f in folder.iterdir()]
    assert len(pids) == 1 and not alive(pids[0])


def test_the_saved_calibrations_table_says_each_calibrations_cells_per_dem_run():
    # two calibrations of the same fit and cases read alike (fitted, load cases, RMS) though
    # one ran 2 cells per DEM run and the other 3: the cells come from the stored settings
    from pidcore.app.calibration import CELLS_COLUMN, saved_calibrations_table

    listing = pd.DataFrame({
        "key": ["cal_a", "cal_b", "cal_c"], "specimen": ["paper_coupon"] * 3,
        "fit": ["fixture_mass_kg"] * 3, "n_points": [5.0, 5.0, 5.0],
        "rms_in_sample": [0.2, 0.1, 0.3], "loo_rms": [np.nan] * 3,
        "loo_coverage95": [np.nan] * 3,
        "created_utc": ["2026-12-01T00:00:00+00:00", "2026-12-01T00:01:00+00:00",
                        "2026-12-01T00:02:00+00:00"],
        "parameters_json": ['{"settings": {"cells": 2, "seed": 12345}}',
                            '{"settings": {"cells": 3, "seed": 12345}}',
                            "{not json"]})
    table = saved_calibrations_table(listing=listing)
    # newest first; a record whose settings cannot be read is listed with a blank
    assert list(table["calibration"]) == ["cal_c", "cal_b", "cal_a"]
    assert list(table[CELLS_COLUMN]) == ["", 3, 2]
    assert list(table.columns).index(CELLS_COLUMN) == list(table.columns).index("fitted") + 1


def test_a_users_material_survives_a_specimen_file_changing_the_default():
    # the rows kept acrylic, the default before a steel specimen file was uploaded; a
    # material the user chose, or a table gave, is not the default and stays
    previous = pd.DataFrame({"file": ["a.csv", "b.csv", "c.csv", "d_acrylic.csv"],
                             "material": ["acrylic", "aluminium", "acrylic", "acrylic"]})
    before = {"a.csv": "acrylic", "b.csv": "acrylic", "c.csv": "acrylic",
              "d_acrylic.csv": "acrylic"}
    now = {"a.csv": "steel", "b.csv": "steel", "c.csv": "steel", "d_acrylic.csv": "acrylic"}
    out = uploads.restate_default_material(previous, before, now,
                                           {"c.csv": {"material", "fill [%]"}})
    assert out["material"].tolist() == ["steel", "aluminium", "acrylic", "acrylic"]
    assert previous["material"].tolist()[0] == "acrylic"  # the session's copy is not changed


def test_a_file_of_other_particles_is_not_saved_as_the_uploaded_specimens():
    from pidcore.specimen import Specimen, hashed_name, load_specimen

    path = REPO / "data_samples" / "specimens" / "steel_6mm.toml"
    given = Specimen.from_bytes(b"# edited\n" + path.read_bytes(), source="panel.toml")
    other = load_specimen(path).with_values({"coupon.fixture_mass_kg": 0.08})
    known = [load_specimen(path), other, given]
    steel = uploads.file_specimen("", "steel", known, given=given, every_file="ignored")
    assert (steel.name, steel.sha256, steel.note) == ("steel_6mm", given.hash, "")
    acrylic = uploads.file_specimen("", "acrylic", known, given=given)
    assert (acrylic.name, acrylic.sha256) == ("", "")
    assert acrylic.note.startswith("specimen steel_6mm (panel.toml): its particles are steel, "
                                   "not acrylic")
    # a row naming the given file's name means the given file, not another of that name
    named = uploads.file_specimen("steel_6mm", "acrylic", known, given=given)
    assert (named.name, named.sha256) == ("steel_6mm", given.hash)
    # a row naming another file by its hashed name gets that one
    picked = uploads.file_specimen(hashed_name("steel_6mm", other.hash), "steel", known,
                                   given=given)
    assert picked.sha256 == other.hash
    # no specimen uploaded: the page's choice for every file, as before
    chosen = uploads.file_specimen("", "acrylic", known,
                                   every_file=hashed_name("steel_6mm", other.hash))
    assert chosen.sha256 == other.hash


def test_calibrate_points_table_names_a_unit_per_number_and_shows_the_sdc_bound_as_one():
    # The Calibrate page listed the measured points with dataclasses.asdict: the newer fields
    # showed as their raw names, and the SDC bound as a dict of masses in kg without a unit.
    from pidcore.app.calibration import points_table
    from pidcore.calibrate import MeasuredPoint
    from pidcore.compare.plausibility import SDC_UPPER_BOUND, sdc_bound
    from pidcore.specimen import load_specimen

    steel = load_specimen(Path(__file__).resolve().parents[1]
                          / "data_samples/specimens/steel_6mm.toml")
    heavy = sdc_bound(fill_percent=50.0, specimen=steel)
    assert heavy.sdc > SDC_UPPER_BOUND  # heavy particles: a bound above 2 pi to show
    points = [MeasuredPoint(500.0, 5.0, 50.0, 7.0, 0.1, material="steel", specimen="steel_6mm",
                            specimen_sha256="ab" * 32, sdc_bound=heavy, sdc_stderr_dof=7.0),
              MeasuredPoint(100.0, 10.0, 50.0, 0.5)]
    table = points_table(points)
    assert len(table) == 2
    for column in table.columns:
        numeric = pd.api.types.is_numeric_dtype(table[column])
        assert not numeric or re.search(r"\[.+\]$", column), column
        assert "_" not in column, column  # no raw field name
    assert table["SDC bound [-]"].tolist() == [heavy.sdc, SDC_UPPER_BOUND]
    # the report's and Calibration.to_pandas()'s name (it said "SDC measured, Eq. 11 [-]")
    assert table["SDC measured (Eq. 11) [-]"].tolist() == [7.0, 0.5]
    assert table["specimen sha256"].tolist() == ["ab" * 32, ""]


@pytest.mark.parametrize(("sdc", "stderr", "shown"), [
    (1.5702e-4, math.nan, "0.000157"),  # the paper's 50 Hz, 1 g, 25 % DEM value: was 0.0002
    (5.09e-5, 4.4e-5, "5.1e-05 ± 4.4e-05"),  # was 0.0001, "- stderr" 0.0000, "+" 0.0001
    (0.1856, 0.0042, "0.1856 ± 0.0042"),
])
def test_the_sdc_charts_tooltip_writes_the_sdc_as_the_pages_do(sdc, stderr, shown):
    # the Compare page's SDC chart wrote its points' SDC and bounds with four fixed decimals
    from pidcore.app.charts import sdc_chart
    from pidcore.app.uploads import format_sdc

    err = 0.0 if math.isnan(stderr) else stderr  # as sdc_points writes a point without one
    data = pd.DataFrame({"series": ["measured (± stderr)"], "packing ratio [%]": [50.0],
                         "SDC [-]": [sdc], "low [-]": [sdc - err], "high [-]": [sdc + err]})
    spec = sdc_chart(data)
    (row,) = spec["datasets"]["sdc"]
    assert row["sdc_text"] == shown == format_sdc(sdc, stderr)
    tooltips = [t for layer in spec["layer"] for t in layer["encoding"].get("tooltip", [])]
    assert {"field": "sdc_text", "type": "nominal", "title": "SDC ± stderr [-]"} in tooltips
    assert not any(t.get("format", "").endswith("f") for t in tooltips)  # no fixed decimals


def test_calibrate_points_display_writes_sdc_and_stderr_by_the_one_rule():
    # The Calibrate page's grid showed the SDC and its stderr as two numbers at the grid's own
    # precision (1.0378 beside 0.024; 0.6285 beside 0.00008): digits the error does not
    # support, unlike `pidcore analyze` and the other pages (1.038 ± 0.024).
    from pidcore.app.calibration import MEASURED_EQ11_WITH_ERROR_COLUMN, points_display
    from pidcore.calibrate import MeasuredPoint

    points = [MeasuredPoint(50.0, 5.0, 50.0, 1.037812, 0.02412, sdc_stderr_dof=7.0),
              MeasuredPoint(200.0, 5.0, 50.0, 0.628512, 0.0000812, sdc_stderr_dof=7.0),
              MeasuredPoint(100.0, 10.0, 50.0, 0.012, 0.5, sdc_stderr_dof=7.0)]
    table = points_display(points)
    # analytic: two significant digits of the error, the value rounded at its place
    assert table[MEASURED_EQ11_WITH_ERROR_COLUMN].tolist() == [
        "1.038 ± 0.024", "0.628512 ± 0.000081", "0.01 ± 0.50"]
    assert "SDC measured (Eq. 11) [-]" not in table.columns
    assert "SDC measured (Eq. 11) stderr [-]" not in table.columns
    # the column sits where the SDC was; the rest of points_table is kept
    assert list(table.columns)[3] == MEASURED_EQ11_WITH_ERROR_COLUMN
    assert table["SDC measured (Eq. 11) stderr dof [-]"].tolist()[:2] == [7.0, 7.0]


def test_the_dem_pages_steady_cycles_are_capped_as_the_cli_caps_them():
    # 1e9 typed was queued (10^7 s simulated, an ETA of minutes); the field names its cap
    from pidcore import defaults
    from pidcore.app.tabs import dem as dem_page

    with pytest.raises(ParameterError, match=r"^steady cycles \(0 = automatic\): '1e9', "
                                             rf"expected 0 to {defaults.DEM_MAX_STEADY_CYCLES}$"):
        dem_page._config("1", "0", "1e9")
    assert dem_page._config("1", "0", "10000").steady_cycles == defaults.DEM_MAX_STEADY_CYCLES


def test_a_calibration_a_stop_of_the_app_ended_is_said_after_a_restart_with_its_kept_runs(
        tmp_path):
    # the DEM tab lists its jobs a stop of the app ended as interrupted; a calibration it ended
    # vanished from the Calibrate page, though the DEM runs it had saved were kept
    import threading
    import types

    from pidcore.app import jobs
    from pidcore.app.calibration import (
        CalibrationRunner,
        calibration_journal_path,
        dismiss_interrupted_calibrations,
        interrupted_calibrations,
    )
    from pidcore.calibrate import MeasuredPoint
    from pidcore.interrupt import raise_if_stopped
    from pidcore.store import Store

    store = tmp_path / "s.h5"
    record = {"frequency_hz": 500.0, "acceleration_g": 5.0, "fill_percent": 50.0,
              "material": "acrylic", "direction": "z", "sdc": 0.1, "sdc_stderr": 0.01}
    Store(store).add_dem_run("run_a", record)  # the one design run saved before the stop
    designed = threading.Event()

    def calibrate(points, *, on_design, stop, **kwargs):  # the library, stopped mid-runs
        on_design(["run_a", "run_b", "run_c", "run_a"])
        designed.set()
        stop.wait(30)
        raise_if_stopped(stop, "calibration stopped")

    api = types.SimpleNamespace(calibrate=calibrate)
    points = [MeasuredPoint(500, 5, 50, 0.6), MeasuredPoint(1000, 5, 50, 0.6),
              MeasuredPoint(500, 1, 50, 0.2)]

    def started(runner: CalibrationRunner):
        task = runner.start(api, points, fit=["fixture_mass_kg"], cells=2, design_size=7)
        assert designed.wait(30)
        designed.clear()
        return task

    runner = CalibrationRunner(store)
    started(runner)
    assert interrupted_calibrations(store) == []  # running on a live server: its own page says
    # the app's exit (SIGTERM, Ctrl-C) stops it, as its exit hook does: every stop, then waits
    assert runner.cancel(at_exit=True)
    runner.stop_and_wait(10, at_exit=True)
    assert runner.task.state == "cancelled"
    assert interrupted_calibrations(store) == []  # the server still runs
    jobs._LIVE_RUNNERS.discard(runner.owner.runner)  # the server's process is gone
    [said] = interrupted_calibrations(store)
    # run_a is kept (3 distinct runs in the design): counted from the store itself
    assert (said.fit, said.n_points, said.runs_total, said.runs_kept) == \
        (("fixture_mass_kg",), 3, 3, 1)
    when = time.strftime("%Y-%m-%d %H:%M", time.localtime(runner.task.started))
    assert said.text("s.h5") == (
        f"The calibration of paper_coupon (fixture_mass_kg; 3 load case(s), 2 cells per DEM "
        f"run, 7 design points) started {when} was interrupted by a stop of the app; no "
        "calibration was saved. Its 1 finished DEM run(s) of 3 are kept in s.h5: running the "
        "same calibration again reuses them and computes the other 2.")
    # the restarted server's own calibration, cancelled by its user (and then the app
    # stopped), leaves nothing to say later, and leaves the interrupted one as it was
    again = CalibrationRunner(store)
    started(again)
    assert again.cancel()
    again.cancel(at_exit=True)
    deadline = time.monotonic() + 10
    while again.task.state == "running":
        assert time.monotonic() < deadline
        time.sleep(0.02)
    jobs._LIVE_RUNNERS.discard(again.owner.runner)
    assert interrupted_calibrations(store) == [said]
    dismiss_interrupted_calibrations(store)
    assert interrupted_calibrations(store) == []
    assert not calibration_journal_path(store).exists()
    assert Store(store).has_dem_run("run_a")  # its runs stay


def test_a_calibration_journal_nested_past_the_stack_is_read_as_none(tmp_path):
    # its own reader caught OSError and ValueError only: JSON nested deeper than Python's
    # stack (json.loads is recursive) raised RecursionError through the Calibrate page; it is
    # read by the DEM jobs' reader now, which refuses a damaged journal as a whole
    from pidcore.app.calibration import calibration_journal_path, interrupted_calibrations

    store = tmp_path / "s.h5"
    calibration_journal_path(store).write_text("[" * 100_000 + "]" * 100_000)
    assert interrupted_calibrations(store) == []
