"""The app refuses what the CLI refuses, in the CLI's words (findings of a browser trial of the
app against ``pidcore analyze`` on the same files and tables)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from _app_samples import mass_damper_csv

from pidcore.app import uploads
from pidcore.cli import main
from pidcore.errors import ParameterError

SAMPLES_ROOT = Path(__file__).parents[1] / "data_samples"


def cli_error(args: list[str], capsys) -> str:
    """The one-line message of a refused CLI command (exit 2), without its program prefix."""
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err.split("error: ", 1)[1]


@pytest.mark.parametrize("column,value", [
    ("velocity_delay_us", "fifty"),     # not a number
    ("velocity_delay_us", "nan"),       # not finite
    ("velocity_delay_us", "-50"),       # negative
    ("velocity_delay_us", "5e-05"),     # a delay typed in s
    ("mass_below_gauge_g", "0.012"),    # a mass typed in kg
    ("baseline_loss_factor", "-0.001"),  # negative
])
def test_a_settings_table_with_a_bad_value_is_refused_in_the_words_of_the_cli(
        tmp_path, capsys, column, value):
    # the app said "t.csv, line 2: velocity_delay_us 'fifty' is not a number" (no file, no
    # expected value), and took a delay typed in s or a mass in kg into the table, to be
    # refused on the file's card only; `pidcore analyze --sidecar` refuses the table itself
    text = f"# set-up A\nfile,fill_percent,{column}\nok.csv,50,\nbad.csv,50,{value}\n"
    table = tmp_path / "loadcases.csv"
    table.write_text(text)
    for name, seed in (("ok.csv", 1), ("bad.csv", 2)):
        (tmp_path / name).write_bytes(mass_damper_csv(seed=seed))
    expected = cli_error(["analyze", str(tmp_path / "ok.csv"), str(tmp_path / "bad.csv"),
                          "--sidecar", str(table), "--no-store"], capsys)
    with pytest.raises(ParameterError) as refused:
        uploads.read_settings_table("loadcases.csv", text.encode())
    assert str(refused.value) == expected.replace(str(table), "loadcases.csv")


def test_a_settings_table_with_good_values_is_read_in_the_apps_units():
    table = uploads.read_settings_table(
        "t.csv", b"file,velocity_delay_us,mass_below_gauge_g,baseline_loss_factor\n"
                 b"a.csv,50,12,0.001\nb.csv,,0,\n")
    assert table["vibrometer delay [\u00b5s]"].tolist()[0] == 50.0
    assert table["mass below gauge [g]"].tolist() == [12.0, 0.0]
    assert table["baseline loss factor [-]"].tolist()[0] == 0.001


def test_an_empty_upload_is_refused_in_the_words_of_the_cli(tmp_path, capsys):
    # the app said "empty.csv: the file is empty"; the CLI names what it expected
    empty = tmp_path / "empty.csv"
    empty.write_bytes(b"")
    expected = cli_error(["analyze", str(empty), "--no-store"], capsys)
    for refuse in (lambda: uploads.check_upload_size("empty.csv", 0),
                   lambda: uploads.read_upload("empty.csv", b"")):
        with pytest.raises(ParameterError) as refused:
            refuse()
        assert str(refused.value) == expected.replace(str(empty), "empty.csv")


def test_the_compare_pages_loop_energy_is_the_energy_pidcore_analyze_prints(tmp_path, capsys):
    # Compare showed "energy per cycle (loop area): 3.0366e-06 J" for the bundled 1000 Hz
    # export, `pidcore analyze --json` 3.0369e-06 J: the 256-gon's area is 1e-4 short of the
    # loop's; the page prints 5 digits (.4e), so they must agree to rounding
    import json
    from pathlib import Path

    from pidcore.compare.case import MeasuredEntry, load_case_of
    from pidcore.measure import AnalysisOptions

    sample = Path(__file__).parents[1] / "data_samples" / "exports" / \
        "synthetic_f1000Hz_a5g_fill50_acrylic.h5"
    assert main(["analyze", str(sample), "--velocity-delay", "5e-5", "--fill", "50",
                 "--no-store", "--json"]) == 0
    (cli,) = json.loads(capsys.readouterr().out)["records"]
    record = uploads.analyze_upload(sample.name, sample.read_bytes(),
                                    AnalysisOptions(velocity_delay_s=5e-5)).record
    case = load_case_of(record, fill_percent=50, material="acrylic")
    loop = MeasuredEntry.from_record(record, case).loop()
    assert f"{loop.energy_per_cycle_j:.4e}" == f"{cli['energy_per_cycle_j']:.4e}"
    assert loop.energy_per_cycle_j == pytest.approx(cli["energy_per_cycle_j"], rel=1e-12)


def _bundled_sample_compared(fill_percent: float):
    """(record, entry, comparison): the bundled 1000 Hz, 5 g export as the app analyses it,
    stated at ``fill_percent``, compared with the bundled DEM store as Compare does."""
    from pidcore.compare.case import MeasuredEntry, compare_case, load_case_of, paper_table
    from pidcore.measure import AnalysisOptions
    from pidcore.store.listing import list_dem_runs

    sample = SAMPLES_ROOT / "exports" / "synthetic_f1000Hz_a5g_fill50_acrylic.h5"
    record = uploads.analyze_upload(sample.name, sample.read_bytes(),
                                    AnalysisOptions(velocity_delay_s=5e-5)).record
    entry = MeasuredEntry.from_record(record, load_case_of(record, fill_percent=fill_percent,
                                                           material="acrylic"))
    comparison = compare_case([entry], list_dem_runs(SAMPLES_ROOT / "dem_table3.h5"),
                              paper_table())
    return record, entry, comparison


def _measured_damper(record) -> float:
    """The damper that dissipates the measured energy per cycle: dE / (pi w X^2), X = a/w^2
    (computed here from the analysis, apart from pidcore.model)."""
    w = 2 * math.pi * record.analysis.frequency_hz
    x = record.analysis.acceleration_amplitude_m_s2 / w**2
    return record.analysis.energy_per_cycle_j / (math.pi * w * x**2)


def test_the_compare_pages_equivalent_damper_is_pidcore_model_dampers(tmp_path, capsys):
    # the app had no equivalent damper; Compare now gives c_eq at a DEM grid case, which must
    # be the c_eq_per_coupon [N s/m] `pidcore model damper --table store` writes for the same runs
    import pandas as pd

    from pidcore.compare.case import compare_case, equivalent_dampers, paper_table

    record, entry, comparison = _bundled_sample_compared(50)
    dampers = equivalent_dampers(comparison)
    assert main(["model", "damper", "--table", "store", "--store",
                 str(SAMPLES_ROOT / "dem_table3.h5"),
                 "--fills", "50", "--accelerations", "5", "--frequencies", "1000",
                 "--format", "csv", "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    (cli,) = pd.read_csv(tmp_path / "equivalent_damper.csv")["c_eq_per_coupon [N s/m]"]
    # the same SDC and m_c (rebuilt from the runs' specimen columns, equal to rounding)
    assert dampers["our DEM"] == pytest.approx(cli, rel=1e-12)
    assert dampers["measured"] == pytest.approx(_measured_damper(record), rel=1e-12)
    # a DEM value without m_c (no grid case) gives no damper rather than a guessed one
    assert equivalent_dampers(compare_case([entry], None, paper_table())) == {}


def test_the_compare_pages_damper_of_an_interpolated_case_is_pidcore_model_dampers(tmp_path,
                                                                                   capsys):
    # at 40 % fill (between the store's 25 and 50 %) the DEM value is the pchip model's and
    # no grid case states m_c: the page showed no damper, though the report knows the m_c a
    # run at this fill would have. `pidcore model damper --table store` interpolates the same
    # runs and takes m_c of the fill from their specimen: an independent path to c_eq
    import pandas as pd

    from pidcore.compare.case import INTERPOLATED_DAMPER_NAME, equivalent_dampers

    record, _, comparison = _bundled_sample_compared(40)
    assert comparison.aligned.status == "interpolated" and comparison.aligned.grid_case is None
    dampers = equivalent_dampers(comparison)
    case = comparison.load_case
    assert main(["model", "damper", "--table", "store", "--store",
                 str(SAMPLES_ROOT / "dem_table3.h5"),
                 "--fills", "40", "--accelerations", repr(case.acceleration_g),
                 "--frequencies", repr(case.frequency_hz), "--format", "csv",
                 "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    cli = pd.read_csv(tmp_path / "equivalent_damper.csv", comment="#")
    # the same pchip value and m_c computed by the same functions: equal to rounding
    assert comparison.vibrated_mass_kg == pytest.approx(cli["coupon_vibrated_mass [kg]"][0],
                                                        rel=1e-12)
    assert set(dampers) == {INTERPOLATED_DAMPER_NAME, "measured"}
    assert dampers[INTERPOLATED_DAMPER_NAME] == pytest.approx(
        cli["c_eq_per_coupon [N s/m]"][0], rel=1e-12)
    assert dampers["measured"] == pytest.approx(_measured_damper(record), rel=1e-12)


def _dem_record(sdc: float, fill: float) -> dict:
    return {"frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": fill,
            "material": "acrylic", "direction": "z", "sdc": sdc, "sdc_stderr": 0.01}


def test_the_apps_report_of_two_stores_is_the_clis_with_both_dem_stores(tmp_path, capsys):
    # the app's Report joins the DEM runs of its store (DEM tab, calibration) with the
    # reference runs; `pidcore report --dem-store` took one store, so the app's CSV (57 rows
    # in the trial: 9 of the app store's runs) could not be had from the CLI at all
    import pandas as pd

    from pidcore.compare.case import load_case_of
    from pidcore.measure import AnalysisOptions
    from pidcore.report.downloads import report_files
    from pidcore.store import Store

    app, ref = tmp_path / "app.h5", tmp_path / "ref.h5"
    Store(ref).add_dem_run("shared", _dem_record(0.40, 50.0))
    Store(ref).add_dem_run("ref_only", _dem_record(0.30, 75.0))
    Store(app).add_dem_run("shared", _dem_record(0.20, 50.0))   # the app store's wins
    Store(app).add_dem_run("app_only", _dem_record(0.25, 25.0))
    options = AnalysisOptions()
    record = uploads.analyze_upload("m_fill50.csv", mass_damper_csv(), options).record
    uploads.save_records(app, [uploads.AnalysedFile(
        record, load_case_of(record, fill_percent=50, material="acrylic"), options, "")])
    _, data, _ = report_files(app, ref)["csv"]
    (tmp_path / "app.csv").write_bytes(data)
    shown = pd.read_csv(tmp_path / "app.csv")
    assert shown["SDC DEM (ours) [-]"].tolist() == [0.25, 0.20, 0.30]
    assert main(["report", "--store", str(app), "--dem-store", str(app), "--dem-store", str(ref),
                 "--format", "csv", "--out", str(tmp_path / "cli")]) == 0
    capsys.readouterr()
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "cli" / "report.csv"), shown)
    provenance = (tmp_path / "cli" / "report.provenance.txt").read_text()
    assert f"store: {app}" in provenance and f"store: {ref}" in provenance


@pytest.mark.parametrize("fill", ["150", "100.5"])
def test_a_dem_fill_over_100_percent_is_refused_naming_the_field_as_the_cli_does(fill, capsys):
    # the DEM tab said "load case: fill must be in (0, 100] % (packing ratio), got 150.0",
    # not naming its field; `pidcore dem sweep --fills 150` names its option
    from pidcore.app import jobs

    expected = cli_error(["dem", "sweep", "--frequencies", "100", "--accelerations", "5",
                          "--fills", fill, "--store", "unused.h5"], capsys)
    with pytest.raises(ParameterError) as refused:
        jobs.dem_fills(f"50, {fill}")
    assert str(refused.value) == expected.replace("--fills", "fills [%]")
    assert jobs.dem_fills("25, 100") == ([25.0, 100.0], None)  # the bounds' inside


def test_every_number_column_of_the_dem_runs_table_names_its_unit():
    # "cells simulated" and "seed" were the DEM tab's only number columns without a unit,
    # where the report writes counts as "particles per cell [-]", "DEM runs [-]"
    import pandas as pd

    from pidcore.app import jobs

    runs = pd.DataFrame({"frequency_hz": [100.0], "acceleration_g": [5.0], "fill_percent": [50.0],
                         "material": ["acrylic"], "direction": ["z"], "sdc": [1.1],
                         "sdc_stderr": [0.01], "steady_detected": [True], "cells_simulated": [8],
                         "seed": [12345], "wall_s": [1.5], "case_key": ["k"]})
    table = jobs.dem_runs_table(runs)
    numbers = [c for c in table.columns if pd.api.types.is_numeric_dtype(table[c])]
    assert {"cells simulated [-]", "seed [-]"} <= set(numbers)
    assert all(c.endswith("]") for c in numbers), numbers


def test_a_store_reports_provenance_names_the_settings_its_records_were_analysed_with(
        tmp_path, capsys):
    # `pidcore report --store S` wrote "parameters: velocity_delay_s=0.0, ..." (the unused
    # options' defaults) for records analysed with 50 µs; the app's notes file named none
    from pidcore.compare.case import load_case_of
    from pidcore.measure import AnalysisOptions
    from pidcore.report.downloads import report_files

    store = tmp_path / "s.h5"
    files = []
    for name, delay in (("b_fill50.csv", 5e-5), ("a_fill75.csv", 0.0)):
        options = AnalysisOptions(velocity_delay_s=delay)
        record = uploads.analyze_upload(name, mass_damper_csv(seed=len(name) + int(delay > 0)),
                                        options).record
        fill = 50 if name.startswith("b") else 75
        files.append(uploads.AnalysedFile(
            record, load_case_of(record, fill_percent=fill, material="acrylic"), options, ""))
    uploads.save_records(store, files)
    assert main(["report", "--store", str(store), "--format", "csv",
                 "--out", str(tmp_path / "cli")]) == 0
    capsys.readouterr()
    cli = (tmp_path / "cli" / "report.provenance.txt").read_text().splitlines()
    app = report_files(store)["csv_provenance"][1].decode().splitlines()
    line = next(x for x in cli if x.startswith("parameters: "))
    assert "vibrometer delay 0 µs (a_fill75.csv), 50 µs (b_fill50.csv)" in line
    assert line == next(x for x in app if x.startswith("parameters: "))


def test_an_uploaded_file_of_several_measurements_says_what_to_do_in_the_app(tmp_path):
    # a pidcore store of 2 measurements uploaded: "choose one with key=", a keyword of the
    # library the page does not have
    from pidcore.compare.case import load_case_of
    from pidcore.measure import AnalysisOptions

    store = tmp_path / "s.h5"
    files = []
    for seed, fill in ((1, 50), (2, 75)):
        options = AnalysisOptions()
        record = uploads.analyze_upload(f"m{seed}.csv", mass_damper_csv(seed=seed),
                                        options).record
        files.append(uploads.AnalysedFile(
            record, load_case_of(record, fill_percent=fill, material="acrylic"), options, ""))
    uploads.save_records(store, files)
    parsed = uploads.parse_upload("lab.h5", store.read_bytes())
    assert parsed.measurement is None
    assert parsed.error.startswith("lab.h5: holds 2 measurements (")
    assert "key=" not in parsed.error and "`pidcore analyze FILE --key NAME`" in parsed.error


def _shaker_csv(header: str, columns) -> bytes:
    import numpy as np

    rows = "\n".join(",".join(f"{v:.9g}" for v in row) for row in np.column_stack(columns))
    return f"{header}\n{rows}\n".encode()


def test_channel_refusals_name_the_pages_columns_not_cli_options():
    # the page said "confirm it with --acceleration 'Shaker reference'", "--mass-below-gauge
    # needs the acceleration at the drive point", "--invert 'Nope': no such channel"
    import numpy as np

    from pidcore.measure import AnalysisOptions

    fs, f, amp = 10_000, 100.0, 5 * 9.80665
    t = np.arange(fs) / fs
    w = 2 * np.pi * f
    acc = amp * np.sin(w * t)
    force = 0.3 * acc + 0.5 * np.cos(w * t)
    reference = _shaker_csv("Time [s],Force [N],Shaker reference [m/s^2]", (t, force, acc))
    two = _shaker_csv("Time [s],Force [N],Velocity [m/s],Drive acc [m/s^2],Other acc [m/s^2]",
                      (t, force, -amp / w * np.cos(w * t), acc, 1.01 * acc))
    said = [uploads.analyze_upload("ref_fill50.csv", reference, AnalysisOptions()).error,
            uploads.analyze_upload("two_fill50.csv", two,
                                   AnalysisOptions(mass_below_gauge_kg=0.01)).error,
            uploads.analyze_upload("two_fill50.csv", two,
                                   AnalysisOptions(invert=("Nope",))).error]
    assert all(s is not None and " --" not in s for s in said), said
    assert "confirm it in the 'acceleration channel' column ('Shaker reference')" in said[0]
    assert "the mass below gauge needs the acceleration at the drive point" in said[1]
    assert "'inverted channels' 'Nope': no such channel" in said[2]


def test_an_analysis_note_names_the_pages_column_not_a_cli_option():
    # a file analysed with a channel inverted on the page noted "channel 'Force' inverted
    # (--invert)"; notes pass through the same words as errors
    from pidcore.measure import AnalysisOptions

    flipped = mass_damper_csv().decode().splitlines()
    rows = [flipped[0]] + [",".join([t, str(-float(f)), v]) for t, f, v in
                           (line.split(",")[:3] for line in flipped[1:] if line)]
    outcome = uploads.analyze_upload("flipped_fill50.csv", "\n".join(rows).encode(),
                                     AnalysisOptions(invert=("Force",)))
    assert outcome.ok, outcome.error
    assert "channel 'Force' inverted ('inverted channels' column)" in outcome.record.notes
    assert not any("--" in n for n in outcome.record.notes), outcome.record.notes


def test_the_apps_report_files_hold_the_notes_and_figures_of_the_clis_store_report(
        tmp_path, capsys):
    # the app's report files of a store said nothing of the paper's coupon assumed for its
    # records (`pidcore report --store` does) and held the SDC figure alone, without the
    # records' force-displacement loops the CLI draws
    import io
    import zipfile

    from pidcore.compare.case import load_case_of
    from pidcore.measure import AnalysisOptions
    from pidcore.report.downloads import report_files, store_report_table
    from pidcore.store import Store

    store = tmp_path / "s.h5"
    options = AnalysisOptions()
    files = []
    for seed, fill in ((1, 50), (2, 75)):
        record = uploads.analyze_upload(f"m_fill{fill}.csv", mass_damper_csv(seed=seed),
                                        options).record
        files.append(uploads.AnalysedFile(
            record, load_case_of(record, fill_percent=fill, material="acrylic"), options, ""))
    uploads.save_records(store, files)
    Store(store).add_dem_run("at50", _dem_record(0.20, 50.0))  # one record meets a DEM run
    assert main(["report", "--store", str(store), "--dem-store", str(store),
                 "--out", str(tmp_path / "cli")]) == 0
    capsys.readouterr()
    cli = tmp_path / "cli"
    app = report_files(store, store)

    def notes(text: str) -> list[str]:
        return [line for line in text.splitlines() if line.startswith("note: ")]

    cli_notes = notes((cli / "report.provenance.txt").read_text())
    assert any("name no specimen, the paper's coupon (paper_coupon) assumed: "
               "m_fill50.csv, m_fill75.csv" in n for n in cli_notes), cli_notes
    assert notes(app["csv_provenance"][1].decode()) == cli_notes
    # the Report tab's notes under its table too (those of the table, not of its figures)
    assert cli_notes[0].removeprefix("note: ") in store_report_table(store, store).attrs["notes"]
    # and in the formats a reader opens (the LaTeX escapes the names' underscores)
    for fmt, names in (("md", "m_fill50.csv, m_fill75.csv"), ("html", "m_fill50.csv, m_fill75.csv"),
                       ("tex", r"m\_fill50.csv, m\_fill75.csv")):
        assert names in app[fmt][1].decode(), fmt
    with zipfile.ZipFile(io.BytesIO(app["zip"][1])) as archive:
        figures = sorted(n.removeprefix("figures/") for n in archive.namelist()
                         if n.startswith("figures/"))
    assert figures == sorted(p.name for p in (cli / "figures").iterdir())
    # one loop per record, as PNG and SVG
    assert sorted(n.split("_f")[0] for n in figures if n.startswith("loop_")) == [
        "loop_00", "loop_00", "loop_01", "loop_01"], figures
