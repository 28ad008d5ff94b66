"""The Table 3-style report table: rows, order, and numbers equal to the store's."""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd
import pytest

from pidcore.model import load_paper_table3
from pidcore.records import Channel, Measurement
from pidcore.report import ALIGNMENT_COLUMN, REPORT_COLUMNS, build_report_table
from pidcore.report.table import CONSISTENCY_COLUMN, DIFFERENCE_COLUMN
from pidcore.store import Store

FILLS = (25.0, 50.0)
ACCS = (1.0, 5.0)
FREQS = (50.0, 100.0)


def _sdc(fill, acc, freq):
    # irrational-looking values so that any rounding on the way would show
    return math.sqrt(fill) / 17.0 + acc / 31.0 + freq / 7001.0


def _dem_items():
    items = []
    for freq in FREQS:
        for acc in ACCS:
            for fill in FILLS:
                items.append({
                    "case_key": f"f{freq:g}_a{acc:g}_fill{fill:g}_acrylic_z_seed7",
                    "record": {"frequency_hz": freq, "acceleration_g": acc, "fill_percent": fill,
                               "material": "acrylic", "direction": "z",
                               "sdc": _sdc(fill, acc, freq),
                               "sdc_stderr": _sdc(fill, acc, freq) / 97.0,
                               "particles_per_cell": int(round(fill * 36 / 100)), "seed": 7,
                               "cells_simulated": 8},
                    "units": {"frequency_hz": "Hz", "acceleration_g": "g", "sdc": "1"},
                })
    return items


def _measurement(name: str, seed: int) -> Measurement:
    rng = np.random.default_rng(seed)
    channels = (Channel("force", "force", rng.standard_normal(64), 1000.0, "N"),
                Channel("velocity", "velocity", rng.standard_normal(64), 1000.0, "m/s"))
    return Measurement(source=name, channels=channels, file_format="csv")


MEASURED = [  # (file, frequency, acceleration, fill, sdc, stderr)
    ("on_grid_fill50.csv", 100.3, 4.93, 50.0, 0.3141592653589793, 0.0123456789),
    ("off_grid_fill40.csv", 70.0, 3.0, 40.0, 0.2718281828459045, 0.0234567891),
    ("outside_fill50.csv", 300.0, 3.0, 50.0, 0.1414213562373095, 0.0345678912),
]


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    path = tmp_path_factory.mktemp("store") / "pid_store.h5"
    s = Store(path)
    s.add_dem_runs(_dem_items())
    for i, (name, freq, acc, fill, sdc, se) in enumerate(MEASURED):
        key, _ = s.add_measurement(_measurement(name, i))
        s.add_analysis(key, {"frequency_hz": freq, "acceleration_g": acc, "fill_percent": fill,
                             "material": "acrylic", "direction": "z", "sdc": sdc,
                             "sdc_stderr": se})
    return s


@pytest.fixture(scope="module")
def table(store):
    return build_report_table(store.list_dem_runs(), store.list_analyses(), load_paper_table3())


def test_columns_and_rows(table):
    assert tuple(table.columns) == REPORT_COLUMNS
    # 8 DEM grid cases + the two measured cases off the grid; the on-grid one shares a row
    assert len(table) == 10
    assert set(table[ALIGNMENT_COLUMN]) == {"grid", "interpolated", "out_of_range"}


def test_sorted_like_table3(table):
    keys = list(zip(table["frequency [Hz]"], table["acceleration [g]"],
                    table["packing ratio [%]"], strict=True))
    assert keys == sorted(keys)


def test_dem_numbers_equal_the_stores_exactly(store, table):
    runs = store.list_dem_runs()
    assert len(runs) == 8
    for case_key in runs["case_key"]:
        rec = store.get_dem_run(case_key).record
        row = table[(table["frequency [Hz]"] == rec["frequency_hz"])
                    & (table["acceleration [g]"] == rec["acceleration_g"])
                    & (table["packing ratio [%]"] == rec["fill_percent"])]
        assert len(row) == 1
        row = row.iloc[0]
        assert row["SDC DEM (ours) [-]"] == rec["sdc"]  # exact, not approx
        assert row["SDC DEM stderr [-]"] == rec["sdc_stderr"]
        assert row["particles per cell [-]"] == rec["particles_per_cell"]
        assert row["DEM runs [-]"] == 1


def test_measured_numbers_equal_the_stores_exactly(store, table):
    analyses = store.list_analyses()
    for name, freq, _acc, _fill, sdc, se in MEASURED:
        stored = analyses[analyses["source"] == name].iloc[0]
        row = table[table["source file(s)"] == name].iloc[0]
        assert row["SDC measured (Eq. 11) [-]"] == stored["sdc"] == sdc
        assert row["SDC measured (Eq. 11) stderr [-]"] == stored["sdc_stderr"] == se
        assert row["measured frequency [Hz]"] == freq


def test_on_grid_measurement_shares_the_dem_row_and_paper_values(table):
    row = table[table["source file(s)"] == "on_grid_fill50.csv"].iloc[0]
    assert (row["frequency [Hz]"], row["acceleration [g]"], row["packing ratio [%]"]) == \
        (100.0, 5.0, 50.0)
    assert row[ALIGNMENT_COLUMN] == "grid"
    assert row["SDC DEM (paper) [-]"] == 0.1891 and row["SDC measured (paper) [-]"] == 0.21
    assert row["difference ours - paper DEM [-]"] == row["SDC DEM (ours) [-]"] - 0.1891
    # the DEM runs of this fixture record no m_c: no like-for-like difference, and no Eq. 11
    # value passed off as one
    assert math.isnan(row[DIFFERENCE_COLUMN]) and "no DEM m_c" in row["note"]


def test_off_grid_measurement_is_interpolated_within_its_neighbours(table):
    row = table[table["source file(s)"] == "off_grid_fill40.csv"].iloc[0]
    assert row[ALIGNMENT_COLUMN] == "interpolated"
    assert (row["frequency [Hz]"], row["packing ratio [%]"]) == (70.0, 40.0)
    # pchip does not overshoot: the value lies within the 8 surrounding grid values
    corners = [_sdc(f, a, z) for f in FILLS for a in ACCS for z in FREQS]
    assert min(corners) <= row["SDC DEM (ours) [-]"] <= max(corners)
    assert math.isnan(row["SDC DEM (paper) [-]"])  # 70 Hz is no Table 3 point
    assert pd.isna(row["particles per cell [-]"]) and row["DEM runs [-]"] == 0


def test_out_of_range_measurement_has_no_dem_value(table):
    row = table[table["source file(s)"] == "outside_fill50.csv"].iloc[0]
    assert row[ALIGNMENT_COLUMN] == "out_of_range"
    assert math.isnan(row["SDC DEM (ours) [-]"])
    assert math.isnan(row[DIFFERENCE_COLUMN])
    assert "not extrapolated" in row["note"]


def test_repeated_measurements_at_one_case_are_pooled():
    dem = pd.DataFrame([{**i["record"], "case_key": i["case_key"]} for i in _dem_items()])
    analyses = pd.DataFrame({"frequency_hz": [50.1, 49.9], "acceleration_g": [1.0, 1.02],
                             "fill_percent": [25.0, 25.0], "sdc": [0.2, 0.3],
                             "sdc_stderr": [0.001, 0.001], "source": ["a.csv", "b.csv"]})
    t = build_report_table(dem, analyses, None)
    row = t[t["source file(s)"] == "a.csv; b.csv"].iloc[0]
    assert row["SDC measured (Eq. 11) [-]"] == pytest.approx(0.25)
    assert row["SDC measured (Eq. 11) stderr [-]"] == pytest.approx(0.05)  # std(ddof=1)/sqrt(2)
    assert row["measured frequency [Hz]"] == pytest.approx(50.0)


def _analyses(cases) -> pd.DataFrame:
    """Analyses of ``cases`` [(file, frequency, acceleration, fill, sdc, stderr)]."""
    return pd.DataFrame(cases, columns=["source", "frequency_hz", "acceleration_g",
                                        "fill_percent", "sdc", "sdc_stderr"])


def test_repeated_measurements_off_the_grid_are_pooled_as_on_the_grid():
    # two tests at 70 Hz, 3 g, 40 % (off the grid) differing only by noise were two rows, each
    # its own SDC, where the same two tests on the grid (50 Hz, 1 g, 25 %) were one pooled row
    # and the Compare page pooled both pairs
    from pidcore.compare import pooled_mean

    dem = pd.DataFrame([{**i["record"], "case_key": i["case_key"]} for i in _dem_items()])
    sdcs, errors = (0.2, 0.3), (0.001, 0.002)
    analyses = _analyses([
        ("off_a.csv", 70.0, 2.99998, 40.0, sdcs[0], errors[0]),
        ("off_b.csv", 70.0, 3.00002, 40.0, sdcs[1], errors[1]),
        ("on_a.csv", 50.0, 0.99998, 25.0, sdcs[0], errors[0]),
        ("on_b.csv", 50.0, 1.00002, 25.0, sdcs[1], errors[1])])
    t = build_report_table(dem, analyses, None)
    measured = t[t["source file(s)"] != ""]
    assert sorted(measured["source file(s)"]) == ["off_a.csv; off_b.csv", "on_a.csv; on_b.csv"]
    off = measured[measured["source file(s)"] == "off_a.csv; off_b.csv"].iloc[0]
    on = measured[measured["source file(s)"] == "on_a.csv; on_b.csv"].iloc[0]
    assert (off[ALIGNMENT_COLUMN], on[ALIGNMENT_COLUMN]) == ("interpolated", "grid")
    # the project's pooling of the two analyses, as the grid row pools them: same numbers in,
    # same operations, so equal to rounding (rel 1e-12)
    expected = pooled_mean(np.array(sdcs), np.array(errors))
    for row in (off, on):
        assert (row["SDC measured (Eq. 11) [-]"], row["SDC measured (Eq. 11) stderr [-]"]) \
            == pytest.approx(expected, rel=1e-12)
    assert off["measured acceleration [g]"] == pytest.approx(3.0, rel=1e-12)
    # the row is the pooled load case, its DEM value interpolated there, as the Compare page
    # interpolates it for the pair (pchip of the same runs at the same point: rel 1e-12)
    assert off["acceleration [g]"] == pytest.approx(3.0, rel=1e-12)
    alone = build_report_table(dem, _analyses([("one.csv", 70.0, 3.0, 40.0, 0.2, 0.001)]), None)
    assert off["SDC DEM (ours) [-]"] == pytest.approx(
        alone[alone["source file(s)"] == "one.csv"].iloc[0]["SDC DEM (ours) [-]"], rel=1e-12)
    assert "2 measurements pooled" in off["note"]


@pytest.mark.parametrize("axis", ["frequency_hz", "acceleration_g", "fill_percent"])
def test_off_grid_measurements_further_apart_than_the_tolerance_are_separate_rows(axis):
    # the grouping is the grid match's tolerance: just inside it one row, just outside two
    from pidcore.compare import Tolerances

    tol = Tolerances()
    dem = pd.DataFrame([{**i["record"], "case_key": i["case_key"]} for i in _dem_items()])
    base = {"frequency_hz": 70.0, "acceleration_g": 3.0, "fill_percent": 40.0}
    step = {"frequency_hz": tol.frequency_rtol * 70.0,
            "acceleration_g": tol.acceleration_rtol * 3.0,
            "fill_percent": tol.fill_atol_percent}[axis]
    for factor, rows in ((0.9, 1), (1.1, 2)):  # 10 % of the tolerance either side of its edge
        other = {**base, axis: base[axis] + factor * step}
        analyses = _analyses([
            ("a.csv", base["frequency_hz"], base["acceleration_g"], base["fill_percent"],
             0.2, 0.001),
            ("b.csv", other["frequency_hz"], other["acceleration_g"], other["fill_percent"],
             0.3, 0.001)])
        t = build_report_table(dem, analyses, None)
        measured = t[t["source file(s)"] != ""]
        assert len(measured) == rows, (axis, factor, list(measured["source file(s)"]))
        assert set(measured[ALIGNMENT_COLUMN]) == {"interpolated"}
        if rows == 2:  # each its own SDC, unpooled
            assert sorted(measured["SDC measured (Eq. 11) [-]"]) == [0.2, 0.3]


def test_analyses_without_fill_are_left_out_with_a_note():
    analyses = pd.DataFrame({"frequency_hz": [50.0], "acceleration_g": [1.0], "sdc": [0.2],
                             "sdc_stderr": [0.01], "source": ["x.csv"]})
    t = build_report_table(None, analyses, load_paper_table3())
    assert t.empty and "no fill" in t.attrs["notes"][0]
    analyses["fill_percent"] = [float("nan")]
    t = build_report_table(None, analyses, load_paper_table3())
    assert t.empty and "x.csv" in t.attrs["notes"][0]


def test_measured_only_table_shows_paper_values():
    analyses = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [5.0],
                             "fill_percent": [50.0], "sdc": [0.6], "sdc_stderr": [0.02],
                             "source": ["m.csv"]})
    t = build_report_table(None, analyses, load_paper_table3())
    row = t.iloc[0]
    assert row[ALIGNMENT_COLUMN] == "no_dem_runs"  # no runs at all: no range to be out of
    assert (row["SDC DEM (paper) [-]"], row["SDC measured (paper) [-]"]) == (0.5417, 0.65)


def test_measured_case_sorts_into_its_grid_block():
    dem = pd.DataFrame([{**i["record"], "case_key": i["case_key"]} for i in _dem_items()])
    analyses = pd.DataFrame({"frequency_hz": [99.7], "acceleration_g": [0.98],
                             "fill_percent": [90.0], "sdc": [0.2], "sdc_stderr": [0.01],
                             "source": ["m.csv"]})
    t = build_report_table(dem, analyses, None)
    # 99.7 Hz, 0.98 g sorts as 100 Hz, 1 g: after every 50 Hz row, before 100 Hz / 5 g
    pos = int(np.flatnonzero(t["source file(s)"] == "m.csv")[0])
    assert list(t["frequency [Hz]"][:pos]) == [50.0] * 4 + [100.0] * 2
    assert list(t["acceleration [g]"][pos + 1:]) == [5.0, 5.0]


def test_measured_sdc_with_eq10_energy_uses_the_dem_vibrated_mass(one_measured_case):
    """ΔE_measured / (m_c a^2 / (2 w^2)) with m_c of the aligned DEM case, computed by hand."""
    import math

    from pidcore.constants import STANDARD_GRAVITY
    from pidcore.model import load_paper_table3
    from pidcore.report import build_report_table
    from pidcore.report.table import MEASURED_EQ10_COLUMN

    case = one_measured_case
    m_c, energy = case.vibrated_mass_kg, case.energy_per_cycle_j
    dem, measured = case.dem, case.measured
    table = build_report_table(dem, measured, load_paper_table3())
    row = table[table["load case"].str.startswith("f500Hz_a5g_fill50")].iloc[0]
    w = 2 * math.pi * 500.2
    expected = energy / (m_c * (4.98 * STANDARD_GRAVITY) ** 2 / (2 * w**2))
    assert row[MEASURED_EQ10_COLUMN] == pytest.approx(expected, rel=1e-12)
    assert row["SDC measured (Eq. 11) [-]"] == 4.3  # Eq. 11 value kept as measured
    # the same SDC (Eq. 10 energy) on both sides of the difference, named in its header
    assert "Eq. 10" in DIFFERENCE_COLUMN
    assert row[DIFFERENCE_COLUMN] == pytest.approx(expected - 1.5, rel=1e-12)
    # without m_c there is no like-for-like value: the difference is empty, never Eq. 11 - DEM
    table = build_report_table(dem.drop(columns="m_c_kg"), measured, load_paper_table3())
    row = table[table["load case"].str.startswith("f500Hz_a5g_fill50")].iloc[0]
    assert math.isnan(row[MEASURED_EQ10_COLUMN]) and math.isnan(row[DIFFERENCE_COLUMN])


def _run(cells: int, sdc: float, seed: int = 1) -> dict:
    import json

    params = {"case_frequency_hz": 500.0, "config_cells": cells, "config_seed": seed,
              "config_steady_cycles": 10 if cells < 8 else ""}
    return {"frequency_hz": 500.0, "acceleration_g": 5.0, "fill_percent": 50.0,
            "material": "acrylic", "direction": "z", "sdc": sdc, "sdc_stderr": 0.01,
            "m_c_kg": 0.07, "cells_simulated": cells, "case_key": f"k{cells}_{seed}",
            "parameters_json": json.dumps(params)}


def test_dem_runs_of_different_settings_are_separate_rows_unless_pooled():
    # a 2-cell smoke run and two seeds of a 32-cell run at one load case
    dem = pd.DataFrame([_run(2, 0.9), _run(32, 0.5, 1), _run(32, 0.52, 2)])
    t = build_report_table(dem, None, None)
    assert len(t) == 2
    by_cells = {s.split(",")[0]: r for s, (_, r) in zip(t["DEM settings"], t.iterrows(),
                                                         strict=True)}
    assert by_cells["cells 2"]["SDC DEM (ours) [-]"] == 0.9  # not averaged with the 32-cell runs
    assert by_cells["cells 32"]["SDC DEM (ours) [-]"] == pytest.approx(0.51)
    assert by_cells["cells 32"]["DEM runs [-]"] == 2
    # the settings' hash says what it is: beside the specimen's "name [hash]" a bare
    # "[hash]" read as a second specimen hash
    settings = by_cells["cells 32"]["DEM settings"]
    assert re.fullmatch(r"cells 32, steady cycles auto, settings hash [0-9a-f]{6}", settings)
    assert "[" not in settings
    pooled = build_report_table(dem, None, None, pool=True)
    assert len(pooled) == 1 and pooled.iloc[0]["DEM runs [-]"] == 3
    assert "(pool=True)" in pooled.iloc[0]["note"]


def test_a_measurement_is_compared_with_the_largest_dem_run():
    dem = pd.DataFrame([_run(2, 0.9), _run(32, 0.5)])
    measured = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [5.0],
                             "fill_percent": [50.0], "sdc": [0.6], "sdc_stderr": [0.02],
                             "energy_per_cycle_j": [1e-5], "source": ["m.csv"]})
    t = build_report_table(dem, measured, None)
    row = t[t["source file(s)"] == "m.csv"].iloc[0]
    assert row["DEM settings"].startswith("cells 32")


def test_specimens_are_separate_rows_and_pooled_files_get_a_consistency_check():
    measured = pd.DataFrame({
        "frequency_hz": [500.0] * 3, "acceleration_g": [5.0] * 3, "fill_percent": [50.0] * 3,
        "sdc": [0.6, 0.62, 0.9], "sdc_stderr": [0.01, 0.01, 0.01],
        "source": ["a1.csv", "a2.csv", "b.csv"], "specimen": ["A", "A", "B"]})
    t = build_report_table(None, measured, None)
    assert sorted(t["specimen"]) == ["A", "B"]
    row_a = t[t["specimen"] == "A"].iloc[0]
    assert row_a["SDC measured (Eq. 11) [-]"] == pytest.approx(0.61)
    # two values 0.02 apart with errors 0.01: chi2 = 2 * (0.01 / 0.01)^2 = 2, dof 1
    assert row_a[CONSISTENCY_COLUMN] == pytest.approx(2.0)
    assert math.isnan(t[t["specimen"] == "B"].iloc[0][CONSISTENCY_COLUMN])
    # pool=True pools DEM settings, never two specimens' tests (B's 0.9 lies 29 sigma off
    # A's: a pooled mean of the two is of no specimen)
    pooled = build_report_table(None, measured, None, pool=True)
    assert sorted(pooled["specimen"]) == ["A", "B"]
    assert sorted(pooled["source file(s)"]) == ["a1.csv; a2.csv", "b.csv"]


def test_particles_per_cell_is_written_as_a_whole_number(table, tmp_path):
    # a count: the CSV wrote 18.0 (a float column, NaN where no DEM ran); now 18, and empty
    from pidcore.report.render import format_cell

    path = tmp_path / "t.csv"
    table.to_csv(path, index=False)
    column = pd.read_csv(path, dtype=str, keep_default_na=False)["particles per cell [-]"]
    assert set(column) - {""} <= {"9", "18"} and "" in set(column)
    missing = table[table["DEM runs [-]"] == 0]["particles per cell [-]"].iloc[0]
    assert format_cell(missing) == ""


def test_dem_runs_that_did_not_converge_are_named_in_the_row_note_and_counted():
    """A run measured from the transient cap (`dem run`: "NOT converged, transient cap") had an
    empty note: its SDC, possibly still holding the transient, read like any other."""
    dem = pd.DataFrame({"frequency_hz": [100.0, 200.0, 500.0, 500.0],
                        "acceleration_g": [5.0, 5.0, 1.0, 1.0], "fill_percent": [40.0] * 4,
                        "material": ["acrylic"] * 4, "direction": ["z"] * 4,
                        "sdc": [1.09, 0.93, 0.0058, 0.0060], "sdc_stderr": [0.03, 0.04, 2e-4, 2e-4],
                        "steady_detected": [1, 0, 1, 0], "steady_start_cycle": [20, 100, 20, 100],
                        "steady_cycles": [40, 20, 20, 20]})
    table = build_report_table(dem, None, None).set_index("frequency [Hz]")
    assert table.loc[100.0, "note"] == ""
    assert table.loc[200.0, "note"].startswith(
        "DEM run did not converge: steady state from cycle 100 (NOT converged, transient cap), "
        "20 cycles measured")
    # two seeds pooled at 500 Hz, one of them never steady
    assert "1 of 2 DEM runs did not converge" in table.loc[500.0, "note"]
    # the notes name the rows (the console's short table has no note column)
    (said,) = [n for n in table.attrs["notes"]
               if n.startswith("2 row(s) rest on DEM runs that did not converge")]
    assert said.endswith("the transient: 200 Hz, 5 g, 40 %; 500 Hz, 1 g, 40 %")
    # a store that does not record convergence is not flagged
    quiet = build_report_table(dem.drop(columns="steady_detected"), None, None)
    assert not any("converge" in n for n in [*quiet["note"], *quiet.attrs["notes"]])


def test_an_interpolated_sdc_resting_on_a_run_that_did_not_converge_says_so():
    """A grid row on a run measured from the transient cap is flagged, but a measurement
    between grid points got the pchip value interpolated from that run with no word of it."""
    from pidcore.compare.align import Aligner
    from pidcore.loadcase import LoadCase

    rows = []
    for freq in FREQS:
        for acc in ACCS:
            for fill in FILLS:
                rows.append({"frequency_hz": freq, "acceleration_g": acc, "fill_percent": fill,
                             "material": "acrylic", "direction": "z",
                             "sdc": _sdc(fill, acc, freq), "sdc_stderr": 0.01,
                             # one corner of the grid never reached a steady state
                             "steady_detected": int((freq, acc, fill) != (100.0, 5.0, 50.0)),
                             "steady_start_cycle": 100, "steady_cycles": 20})
    dem = pd.DataFrame(rows)
    aligner = Aligner.from_tables(dem)

    inside = aligner.align(LoadCase(70.0, 3.0, 40.0))  # in the cell that has the corner
    assert inside.status == "interpolated"
    assert inside.unconverged_nodes == ("100 Hz, 5 g, 50 %",)
    assert inside.message.endswith(
        "it rests on DEM runs that did not converge (no steady state before the transient "
        "cap) at 100 Hz, 5 g, 50 %: the interpolated SDC may include the transient")
    analyses = pd.DataFrame({"frequency_hz": [70.0], "acceleration_g": [3.0],
                             "fill_percent": [40.0], "material": ["acrylic"],
                             "direction": ["z"], "sdc": [0.27], "sdc_stderr": [0.01],
                             "source": ["between.csv"]})
    table = build_report_table(dem, analyses, None)
    row = table[table[ALIGNMENT_COLUMN] == "interpolated"].iloc[0]
    assert "did not converge" in row["note"] and "100 Hz, 5 g, 50 %" in row["note"]
    (said,) = [n for n in table.attrs["notes"]
               if n.startswith("2 row(s) rest on DEM runs that did not converge")]
    assert said.endswith("the transient: 100 Hz, 5 g, 50 %; 70 Hz, 3 g, 40 % (interpolated "
                         "from 100 Hz, 5 g, 50 %)"), said


# --- an interpolated row's particle count and m_c ------------------------------------------------

def _runs_of(specimen_text: str, **settings) -> pd.DataFrame:
    """The 8 grid runs of :func:`_dem_items` as a listing with what a DEM run stores: the
    specimen file and the fill reference and vibrated-mass convention it ran with."""
    import json

    rows = []
    for item in _dem_items():
        rec = dict(item["record"])
        rec.update({"case_key": item["case_key"], "fill_reference": "capacity",
                    "vibrated_mass_convention": "coupon_plus_particles", **settings,
                    "parameters_json": json.dumps({"specimen_text": specimen_text})})
        rows.append(rec)
    return pd.DataFrame(rows)


def _off_grid_analysis(energy_per_cycle_j: float) -> pd.DataFrame:
    # 70 Hz, 3 g, 40 %: inside the 50-100 Hz, 1-5 g, 25-50 % grid, on no grid point
    return pd.DataFrame([{"frequency_hz": 70.0, "acceleration_g": 3.0, "fill_percent": 40.0,
                          "material": "acrylic", "direction": "z", "sdc": 0.25,
                          "sdc_stderr": 0.01, "energy_per_cycle_j": energy_per_cycle_j,
                          "source": "off_grid_fill40.csv"}])


def test_an_interpolated_row_gets_the_count_and_eq10_sdc_of_its_specimen_and_fill():
    from pidcore.specimen import paper_specimen

    runs = _runs_of(paper_specimen("acrylic").to_toml())
    energy = 3.0e-6  # J per cycle, measured
    table = build_report_table(runs, _off_grid_analysis(energy), None)
    row = table[table["source file(s)"] == "off_grid_fill40.csv"].iloc[0]
    assert row[ALIGNMENT_COLUMN] == "interpolated"
    # by hand: the paper's coupon holds 22 acrylic spheres (r 1.25 mm) per cell at 100 %
    # ("capacity"), so 40 % is round(8.8) = 9 per cell; m_c = coupon 22.1534 g + 441 cells x
    # 9 x (4/3 pi r^3 1180 kg/m^3); E = m_c a^2 / (2 w^2) (Eq. 10); SDC = dE / E
    assert row["particles per cell [-]"] == 9
    sphere = 4.0 / 3.0 * math.pi * 1.25e-3**3 * 1180.0
    m_c = 0.0221534 + 441 * 9 * sphere
    omega, accel = 2 * math.pi * 70.0, 3.0 * 9.80665
    expected = energy / (m_c * accel**2 / (2 * omega**2))
    # the coupon's 22.1534 g is written to 7 digits in the paper's specimen file's sum of
    # face sheets and core (22.153400000000004): relative 1e-9 holds any such rounding
    assert row["SDC measured, E of Eq. 10 [-]"] == pytest.approx(expected, rel=1e-9)
    assert row[DIFFERENCE_COLUMN] == pytest.approx(expected - row["SDC DEM (ours) [-]"],
                                                   rel=1e-12)
    assert "no DEM m_c" not in row["note"]


def test_a_row_measured_a_hair_outside_the_grids_edge_is_compared_at_the_edge():
    # a lab batch's 49.99998 Hz, 0.999992 g tests were out_of_range: no DEM value, and the
    # "SDC measured, E of Eq. 10" column went blank with it, though the report states a 1 %
    # frequency and 5 % acceleration tolerance
    from pidcore.compare import Aligner, LoadCase
    from pidcore.specimen import paper_specimen

    runs = _runs_of(paper_specimen("acrylic").to_toml())
    energy = 3.0e-6
    analysis = _off_grid_analysis(energy).assign(frequency_hz=49.99998,
                                                 acceleration_g=0.999992)
    table = build_report_table(runs, analysis, None)
    row = table[table["source file(s)"] == "off_grid_fill40.csv"].iloc[0]
    assert row[ALIGNMENT_COLUMN] == "interpolated"
    # the value at 50 Hz, 1 g, 40 % (a point inside the grid), bit for bit
    at_edge = Aligner.from_tables(runs).align(LoadCase(50.0, 1.0, 40.0))
    assert row["SDC DEM (ours) [-]"] == at_edge.sdc_dem
    assert "model evaluated at 50 Hz, 1 g: the case (49.99998 Hz, 0.999992 g)" in row["note"]
    # the Eq. 10 SDC divides by the measured a and w (as the interpolated row's test above
    # works it by hand: 9 spheres per cell at 40 %)
    sphere = 4.0 / 3.0 * math.pi * 1.25e-3**3 * 1180.0
    m_c = 0.0221534 + 441 * 9 * sphere
    omega, accel = 2 * math.pi * 49.99998, 0.999992 * 9.80665
    assert row["SDC measured, E of Eq. 10 [-]"] == pytest.approx(
        energy / (m_c * accel**2 / (2 * omega**2)), rel=1e-9)  # rel: as the test above


def test_an_interpolated_row_without_one_specimen_or_convention_says_why():
    from pidcore.specimen import paper_specimen

    text = paper_specimen("acrylic").to_toml()
    mixed = _runs_of(text)
    mixed.loc[0, "vibrated_mass_convention"] = "coupon"
    row = build_report_table(mixed, _off_grid_analysis(3.0e-6), None)
    row = row[row["source file(s)"] == "off_grid_fill40.csv"].iloc[0]
    assert pd.isna(row["particles per cell [-]"])
    assert math.isnan(row["SDC measured, E of Eq. 10 [-]"])
    assert ("no DEM m_c: no like-for-like difference (its DEM runs do not share one vibrated "
            "mass convention)") in row["note"]
    # runs that stored no specimen file (the older stores, the fixture above): no guess
    bare = _runs_of(text).drop(columns=["parameters_json"])
    row = build_report_table(bare, _off_grid_analysis(3.0e-6), None)
    row = row[row["source file(s)"] == "off_grid_fill40.csv"].iloc[0]
    assert pd.isna(row["particles per cell [-]"])
    assert "(its DEM runs do not record one specimen file" in row["note"]


def test_the_paper_dem_gap_is_explained_in_the_row_not_left_blank():
    # Table 3 prints no DEM value at 1000 Hz, 1 g, 90 % (the transcription keeps the row with
    # an empty value): the report's row showed empty paper and difference cells and no word
    dem = pd.DataFrame({"frequency_hz": [1000.0, 1000.0], "acceleration_g": [1.0, 1.0],
                        "fill_percent": [90.0, 75.0], "material": ["acrylic"] * 2,
                        "direction": ["z"] * 2, "sdc": [2.742, 2.6], "sdc_stderr": [0.3, 0.3]})
    table = build_report_table(dem, None, load_paper_table3()).set_index("load case")
    gap = table.loc["f1000Hz_a1g_fill90pct_acrylic_z"]
    assert math.isnan(gap["SDC DEM (paper) [-]"])
    assert math.isnan(gap["difference ours - paper DEM [-]"])
    assert ("the paper's Table 3 prints no DEM value at 1000 Hz, 1 g, 90 %: no paper DEM SDC and "
            "no difference ours - paper DEM here") in gap["note"]
    # beside it the table has a value (0.8078) and the row says nothing of a gap
    printed = table.loc["f1000Hz_a1g_fill75pct_acrylic_z"]
    assert printed["SDC DEM (paper) [-]"] == 0.8078 and "prints no" not in printed["note"]


def test_rows_beside_table3_say_the_papers_particle_count_differs_from_ours():
    # Table 3's packing ratio counts 36 spheres per cell as 100 % (paper Sect. 5.1); our runs
    # count the cell's capacity (22 acrylic spheres): at 50 % ours hold 11, the paper's 18.
    # The report set them side by side in one row, with a difference column, and no word.
    dem = pd.DataFrame({"frequency_hz": [50.0, 50.0], "acceleration_g": [5.0, 5.0],
                        "fill_percent": [50.0, 75.0], "material": ["acrylic"] * 2,
                        "direction": ["z"] * 2, "sdc": [0.6, 0.7], "sdc_stderr": [0.01, 0.01],
                        "particles_per_cell": [11, 16]})
    notes = build_report_table(dem, None, load_paper_table3()).attrs["notes"]
    said = [n for n in notes if n.startswith("Table 3's packing ratio counts 36 spheres")]
    assert len(said) == 1
    # round(0.50 * 36) = 18, round(0.75 * 36) = 27: the paper's own rule
    assert "particles per cell at 50 %: ours 11, the paper's 18; 75 %: ours 16, the paper's 27" \
        in said[0]
    # runs that hold the paper's count (18 at 50 %) need no such note
    same = dem.assign(particles_per_cell=[18, 27])
    assert not any("packing ratio counts" in n for n in
                   build_report_table(same, None, load_paper_table3()).attrs["notes"])
