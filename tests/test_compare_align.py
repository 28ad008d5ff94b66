"""Alignment of measured cases with our DEM grid, the pchip model and the paper's Table 3."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from pidcore.compare import (
    ALIGNMENT_STATUSES,
    Aligner,
    LoadCase,
    Tolerances,
    align_measured,
    dem_cases,
    pooled_mean,
)
from pidcore.model import load_paper_table3


def linear_sdc(fill, acc, freq):
    """A field linear in each coordinate: on a 2-point-per-axis grid the tensor-product pchip is
    trilinear, so it reproduces this field exactly anywhere inside the box (analytic truth)."""
    return 0.01 + 0.004 * fill + 0.02 * acc + 0.0005 * freq


def dem_grid(material="acrylic", direction="z"):
    rows = []
    for fill in (25.0, 50.0):
        for acc in (1.0, 5.0):
            for freq in (50.0, 100.0):
                rows.append({"case_key": f"run_{freq:g}_{acc:g}_{fill:g}_{material}",
                             "frequency_hz": freq, "acceleration_g": acc, "fill_percent": fill,
                             "material": material, "direction": direction,
                             "sdc": linear_sdc(fill, acc, freq), "sdc_stderr": 0.001 * acc,
                             "particles_per_cell": fill * 36 / 100, "seed": 1})
    return pd.DataFrame(rows)


@pytest.fixture(scope="module")
def aligner():
    return Aligner.from_tables(dem_grid(), load_paper_table3())


def test_grid_match_within_tolerances_copies_the_run_exactly(aligner):
    runs = dem_grid()
    case = LoadCase(50.4, 5.2, 50.2)  # 0.8 % in f, 4 % in a, 0.2 points in fill
    out = aligner.align(case)
    assert out.status == "grid"
    stored = runs[(runs.frequency_hz == 50) & (runs.acceleration_g == 5)
                  & (runs.fill_percent == 50)].iloc[0]
    assert out.sdc_dem == stored.sdc and out.sdc_dem_stderr == stored.sdc_stderr
    assert out.grid_case.run_keys == (stored.case_key,)
    assert out.load_case == case  # the measured values are kept, not snapped to the grid


@pytest.mark.parametrize(("case", "status"), [
    (LoadCase(50.0 * 1.0099, 5.0, 50.0), "grid"),          # inside 1 % in frequency
    (LoadCase(50.0 * 1.0101, 5.0, 50.0), "interpolated"),  # just outside
    (LoadCase(50.0, 5.0 * 1.0499, 50.0), "grid"),          # inside 5 % in acceleration
    (LoadCase(50.0, 5.0 * 0.9490, 50.0), "interpolated"),  # just outside
    (LoadCase(50.0, 5.0, 50.49), "grid"),                  # inside 0.5 points of fill
    (LoadCase(50.0, 5.0, 49.4), "interpolated"),           # outside, inside the fill range
    (LoadCase(50.0, 5.0, 50.6), "out_of_range"),           # outside, above the fill range
])
def test_tolerance_edges(aligner, case, status):
    assert aligner.align(case).status == status


def test_off_grid_case_is_interpolated_exactly_for_a_linear_field(aligner):
    case = LoadCase(73.0, 2.7, 37.5)
    out = aligner.align(case)
    assert out.status == "interpolated"
    # trilinear reproduction of a linear field: equal to round-off (a few ulp of 0.3)
    assert out.sdc_dem == pytest.approx(linear_sdc(37.5, 2.7, 73.0), rel=1e-12)
    assert math.isnan(out.sdc_dem_stderr)
    assert "pchip" in out.message
    # the empty stderr cell is explained, not left blank
    assert "(no DEM stderr: the model interpolates the runs' SDCs, not their errors)" \
        in out.message


@pytest.mark.parametrize("case", [
    LoadCase(200.0, 2.0, 30.0),   # frequency above the grid
    LoadCase(75.0, 10.0, 30.0),   # acceleration above
    LoadCase(75.0, 2.0, 10.0),    # fill below
])
def test_outside_the_model_range_is_refused_not_extrapolated(aligner, case):
    out = aligner.align(case)
    assert out.status == "out_of_range"
    assert math.isnan(out.sdc_dem)
    assert "not extrapolated" in out.message


@pytest.mark.parametrize(("case", "outside", "inside"), [
    (LoadCase(200.0, 2.0, 30.0), "frequency 200 Hz outside 50-100 Hz",
     "fill 25-50 %, acceleration 1-5 g"),
    (LoadCase(75.0, 2.0, 10.0), "fill 10 % outside 25-50 %",
     "acceleration 1-5 g, frequency 50-100 Hz"),
])
def test_out_of_range_note_names_the_axis_outside_and_each_range_with_its_unit(
        aligner, case, outside, inside):
    # report.csv showed "(--fill in [25, 90], acceleration_g in [1, 10], --frequency in
    # [50, 1000])": keywords without units, two of them turned into CLI flags by its wording
    from pidcore.cli._vocabulary import cli_words

    message = aligner.align(case).message
    assert f"({outside}; {inside})" in message
    assert cli_words(message, "report") == message  # no keyword left for the CLI to rewrite


@pytest.mark.parametrize(("frequency", "acceleration"), [
    (49.9995, 1.0),       # 1e-5 below 50 Hz (the 1 % tolerance is 0.5 Hz)
    (50.0, 0.99999),      # 1e-5 below 1 g (the 5 % tolerance is 0.05 g)
    (49.99998, 0.999992),  # both, as a lab batch measured them
    (100.004, 5.00003),   # above the grid's other corner
])
def test_a_case_within_the_tolerances_of_the_grids_edge_is_taken_at_the_edge(
        aligner, frequency, acceleration):
    # a noise-free 49.9995 Hz, 1 g export was out_of_range with "acceleration 1 g outside
    # 1-10 g, frequency 49.9995 Hz outside 50-1000 Hz" where 50.0005 Hz was interpolated,
    # and the Compare page's curve took 49.999998 Hz as the 50 Hz case
    out = aligner.align(LoadCase(frequency, acceleration, 37.5))
    assert out.status == "interpolated"
    f_edge, a_edge = min(max(frequency, 50.0), 100.0), min(max(acceleration, 1.0), 5.0)
    # the model at the edge reproduces the linear field there to round-off (trilinear, as in
    # the off-grid test); at the measured point it would differ by 2.5e-7 or 2e-5 (>> 1e-12)
    assert out.sdc_dem == pytest.approx(linear_sdc(37.5, a_edge, f_edge), rel=1e-12)
    assert out.load_case == LoadCase(frequency, acceleration, 37.5)  # the measured case kept
    assert (f"model evaluated at {f_edge:g} Hz, {a_edge:g} g: the case ({frequency:.8g} Hz, "
            f"{acceleration:.8g} g) lies at the edge of its range, within the grid "
            "tolerance") in out.message


def test_a_case_beyond_the_tolerance_of_the_edge_stays_out_of_range_saying_so(aligner):
    out = aligner.align(LoadCase(45.0, 0.99999, 37.5))  # 10 % below 50 Hz
    assert out.status == "out_of_range" and math.isnan(out.sdc_dem)
    # 0.99999 g is the 1 g edge: the note names the frequency alone as outside
    assert "(frequency 45 Hz outside 50-100 Hz; fill 25-50 %, acceleration 1-5 g)" \
        in out.message
    # a fill outside stays outside though the frequency is taken at the edge
    fill = aligner.align(LoadCase(49.9995, 1.0, 60.0))
    assert fill.status == "out_of_range"
    assert "(fill 60 % outside 25-50 %; acceleration 1-5 g, frequency 50-100 Hz)" \
        in fill.message


def test_an_out_of_range_note_never_prints_a_value_rounded_onto_the_range():
    # without tolerance 49.9999999 Hz is outside 50-100 Hz; printed to 6 digits it read
    # "frequency 50 Hz outside 50-100 Hz"
    strict = Aligner.from_tables(dem_grid(), tolerances=Tolerances(frequency_rtol=0.0,
                                                                   acceleration_rtol=0.0))
    out = strict.align(LoadCase(49.9999999, 0.9999999, 37.5))
    assert out.status == "out_of_range"
    assert ("(acceleration 0.9999999 g outside 1-5 g, frequency 49.9999999 Hz outside "
            "50-100 Hz; fill 25-50 %)") in out.message


def test_an_interior_case_is_interpolated_where_it_was_measured(aligner):
    # only a case outside the grid's box is taken at its edge: 50.0005 Hz, 1.00001 g lies
    # inside and is evaluated there, not at 50 Hz, 1 g (the linear field tells them apart by
    # 2.5e-7 + 2e-7, far above the 1e-12 round-off)
    out = aligner.align(LoadCase(50.0005, 1.00001, 37.5))
    assert out.status == "interpolated"
    assert out.sdc_dem == pytest.approx(linear_sdc(37.5, 1.00001, 50.0005), rel=1e-12)
    assert "model evaluated at" not in out.message
    # and between grid points nothing is snapped
    mid = aligner.align(LoadCase(73.0, 2.7, 37.5))
    assert mid.sdc_dem == pytest.approx(linear_sdc(37.5, 2.7, 73.0), rel=1e-12)
    assert "model evaluated at" not in mid.message


@pytest.mark.parametrize(("frequency", "acceleration"), [(49.9995, 1.0), (50.0, 0.99999),
                                                         (45.0, 1.0)])
def test_the_report_and_the_compare_pages_case_agree_at_the_grids_edge(
        frequency, acceleration):
    # the report dropped the DEM value of a 49.9995 Hz test the Compare page's curve took
    # at 50 Hz: one rule (pidcore.compare.align.model_point) decides both
    from pidcore.compare.case import MeasuredEntry, compare_case
    from pidcore.report import ALIGNMENT_COLUMN, build_report_table

    case = LoadCase(frequency, acceleration, 37.5)
    entry = MeasuredEntry(
        key="upload:x", file="edge.csv", origin="this session (unsaved)", load_case=case,
        frequency_hz=frequency, acceleration_m_s2=acceleration * 9.80665, loss_factor=0.05,
        sdc=0.3, sdc_stderr=0.01, energy_per_cycle_j=1e-3, harmonics=np.array([1]),
        force_phasors_n=np.array([1j]), velocity_phasors_m_s=np.array([1.0]),
        specimen="paper_coupon")
    compared = compare_case([entry], dem_grid(), load_paper_table3()).aligned
    analyses = pd.DataFrame([{"frequency_hz": frequency, "acceleration_g": acceleration,
                              "fill_percent": 37.5, "material": "acrylic", "direction": "z",
                              "sdc": 0.3, "sdc_stderr": 0.01, "source": "edge.csv",
                              "specimen": "paper_coupon"}])
    table = build_report_table(dem_grid(), analyses, load_paper_table3())
    (row,) = table[table["source file(s)"] == "edge.csv"].to_dict("records")
    assert row[ALIGNMENT_COLUMN] == compared.status
    assert compared.status == ("out_of_range" if frequency == 45.0 else "interpolated")
    # the same number (NaN for both out of range), and the same words
    np.testing.assert_equal(row["SDC DEM (ours) [-]"], compared.sdc_dem)
    assert compared.message in row["note"]


def test_an_interpolated_value_resting_on_a_filled_grid_point_says_so(aligner):
    # an interrupted sweep: no run at 50 Hz, 1 g, 25 %; the model holds the 50 % run's SDC
    # there (nearest fill) and the row was labelled "interpolated" with no word of it
    runs = dem_grid()
    holed = runs[~((runs.frequency_hz == 50) & (runs.acceleration_g == 1)
                   & (runs.fill_percent == 25))]
    out = Aligner.from_tables(holed).align(LoadCase(73.0, 2.7, 37.5))
    assert out.status == "interpolated"
    assert "no DEM run at 50 Hz, 1 g, 25 %, a grid point its pchip value rests on" in out.message
    # the held value, not the linear field's: the note is about a real difference
    assert out.sdc_dem != pytest.approx(linear_sdc(37.5, 2.7, 73.0), rel=1e-6)
    # with every corner run there is no such note
    assert "no DEM run at" not in aligner.align(LoadCase(73.0, 2.7, 37.5)).message


def test_other_material_or_direction_never_borrows_acrylic_results(aligner):
    out = aligner.align(LoadCase(50.0, 5.0, 50.0, "aluminium"))
    assert out.status == "no_dem_runs" and math.isnan(out.sdc_dem)
    assert "aluminium" in out.message
    assert math.isnan(out.sdc_paper_dem)  # Table 3 is for acrylic only
    assert aligner.align(LoadCase(50.0, 5.0, 50.0, direction="x")).status == "no_dem_runs"


def test_paper_values_attached_only_at_table3_points(aligner):
    out = aligner.align(LoadCase(100.5, 4.9, 50.0))
    assert (out.sdc_paper_dem, out.sdc_paper_experimental) == (0.1891, 0.21)  # Table 3
    off = aligner.align(LoadCase(73.0, 2.7, 37.5))
    assert math.isnan(off.sdc_paper_dem) and math.isnan(off.sdc_paper_experimental)
    hole = Aligner([], load_paper_table3()).align(LoadCase(1000.0, 1.0, 90.0))
    assert math.isnan(hole.sdc_paper_dem)  # the printed table has no value there


def test_no_dem_runs_gives_no_dem_runs_with_a_reason():
    # not "out_of_range": there is no range at all (user trial defect 10)
    out = Aligner.from_tables(None).align(LoadCase(50.0, 5.0, 50.0))
    assert out.status == "no_dem_runs" and "no DEM runs" in out.message


def test_grid_that_cannot_be_modelled_is_labelled_no_model_and_says_why():
    # labelled out_of_range beside "no pchip model ... fill_percent has 1 distinct value":
    # the label contradicted its own note (the point lies inside the runs' span here)
    one_fill = dem_grid()
    one_fill = one_fill[one_fill.fill_percent == 50]
    out = Aligner.from_tables(one_fill).align(LoadCase(75.0, 3.0, 50.0))
    assert out.status == "no_model" and "no_model" in ALIGNMENT_STATUSES
    assert "no pchip model" in out.message and "fill_percent" in out.message
    # the runs named once: "no pchip model over our DEM runs (acrylic, z): our DEM runs
    # (acrylic, z): column fill_percent ..." said it twice
    assert out.message.count("our DEM runs (acrylic, z)") == 1
    assert "no pchip model over our DEM runs (acrylic, z): column fill_percent" in out.message
    assert math.isnan(out.sdc_dem)


def test_pooled_mean_of_repeated_runs():
    # one run: returned unchanged, bit for bit
    assert pooled_mean(np.array([0.1 + 0.2]), np.array([0.3])) == (0.1 + 0.2, 0.3)
    # two seeds 0.2 and 0.3 with tiny within-run errors: between-seed scatter dominates,
    # std(ddof=1) = 0.0707..., / sqrt(2) = 0.05
    mean, se = pooled_mean(np.array([0.2, 0.3]), np.array([0.001, 0.001]))
    assert mean == pytest.approx(0.25) and se == pytest.approx(0.05)
    # equal values with real within-run errors: propagated sqrt(2 * 0.02^2) / 2
    mean, se = pooled_mean(np.array([0.2, 0.2]), np.array([0.02, 0.02]))
    assert se == pytest.approx(math.sqrt(2) * 0.02 / 2)


def test_runs_of_one_case_pool_into_one_dem_case():
    runs = dem_grid()
    extra = runs.iloc[[0]].assign(case_key="seed2", sdc=runs.iloc[0].sdc + 0.02,
                                  frequency_hz=50.2)
    cases = dem_cases(pd.concat([runs, extra], ignore_index=True))
    assert len(cases) == 8
    pooled = [c for c in cases if c.n_runs == 2]
    assert len(pooled) == 1 and set(pooled[0].run_keys) == {runs.iloc[0].case_key, "seed2"}
    assert pooled[0].sdc == pytest.approx(runs.iloc[0].sdc + 0.01)


def test_align_measured_returns_unit_suffixed_rows():
    measured = pd.DataFrame({
        "frequency_hz": [50.2, 73.0, 300.0], "acceleration_g": [5.1, 2.7, 3.0],
        "fill_percent": [25.0, 37.5, 30.0], "material": ["acrylic"] * 3, "direction": ["z"] * 3,
        "sdc": [0.3, 0.4, 0.5], "sdc_stderr": [0.01, 0.02, 0.03],
        "source": ["a.uff", "b.uff", "c.uff"]})
    out = align_measured(measured, dem_grid(), load_paper_table3())
    assert list(out["alignment"]) == ["grid", "interpolated", "out_of_range"]
    assert list(out["SDC measured (Eq. 11) [-]"]) == [0.3, 0.4, 0.5]
    assert out.loc[0, "SDC DEM (paper) [-]"] == 0.2210  # Table 3: 50 Hz, 5 g, 25 %
    for column in ("frequency [Hz]", "acceleration [g]", "packing ratio [%]",
                   "SDC DEM (ours) [-]", "SDC measured (Eq. 11) stderr [-]"):
        assert column in out.columns


def test_align_measured_names_the_measured_sdc_as_the_report_does():
    # the frame said "SDC measured [-]" beside "SDC DEM (ours) [-]" while the report's files
    # say "SDC measured (Eq. 11) [-]" for the same Eq. 11 SDC: one name for one concept, and
    # a frame saved with the old names reads into the present ones, as a report.csv does
    from pidcore.compare import (
        MEASURED_COLUMNS_RENAMED,
        MEASURED_EQ11_COLUMN,
        MEASURED_EQ11_STDERR_COLUMN,
    )
    from pidcore.report import REPORT_COLUMNS_RENAMED
    from pidcore.report.table import MEASURED_EQ11_COLUMN as REPORT_EQ11_COLUMN
    from pidcore.report.table import MEASURED_EQ11_STDERR_COLUMN as REPORT_EQ11_STDERR_COLUMN

    measured = pd.DataFrame({
        "frequency_hz": [50.0], "acceleration_g": [5.0], "fill_percent": [25.0],
        "material": ["acrylic"], "direction": ["z"], "sdc": [0.3], "sdc_stderr": [0.01],
        "source": ["a.uff"]})
    out = align_measured(measured, dem_grid(), load_paper_table3())
    assert (MEASURED_EQ11_COLUMN, MEASURED_EQ11_STDERR_COLUMN) == (
        REPORT_EQ11_COLUMN, REPORT_EQ11_STDERR_COLUMN)
    assert (out.loc[0, MEASURED_EQ11_COLUMN], out.loc[0, MEASURED_EQ11_STDERR_COLUMN]) == (
        0.3, 0.01)
    assert "SDC measured [-]" not in out.columns and "SDC measured stderr [-]" not in out.columns
    older = out.rename(columns={MEASURED_EQ11_COLUMN: "SDC measured [-]",
                                MEASURED_EQ11_STDERR_COLUMN: "SDC measured stderr [-]"})
    pd.testing.assert_frame_equal(older.rename(columns=MEASURED_COLUMNS_RENAMED), out)
    assert REPORT_COLUMNS_RENAMED == MEASURED_COLUMNS_RENAMED


def test_tolerances_are_validated():
    with pytest.raises(ValueError, match="frequency_rtol"):
        Tolerances(frequency_rtol=-0.1)


def test_a_run_off_the_grid_leaves_the_rest_of_the_grid_modelled():
    # the app's DEM tab runs any case: one run at 70 Hz, 5 g (no 70 Hz run at 1 g) left the
    # pair (70 Hz, 1 g) without a value, and the model of every off-grid measurement was
    # refused ("no value at any fill for 1 g, 70 Hz"); the complete 2 x 2 grid still models
    # the linear field exactly (trilinear pchip, analytic truth) and the message says what
    # was left out of it
    runs = dem_grid()
    extra = runs[(runs.frequency_hz == 50) & (runs.acceleration_g == 5)].assign(
        frequency_hz=70.0, sdc=lambda r: r.sdc + 1.0,
        case_key=lambda r: r.case_key + "_70Hz")
    case = LoadCase(80.0, 3.0, 40.0)
    out = Aligner.from_tables(pd.concat([runs, extra], ignore_index=True)).align(case)
    assert out.status == "interpolated", out.message
    assert out.sdc_dem == pytest.approx(linear_sdc(40.0, 3.0, 80.0), rel=1e-12)
    assert "left out: 70 Hz (not run at every acceleration)" in out.message
    # a grid that is complete is modelled over all its runs, with no such words
    plain = Aligner.from_tables(runs).align(case)
    assert plain.sdc_dem == out.sdc_dem and "left out" not in plain.message


def test_the_model_takes_one_settings_case_per_load_case_as_a_grid_case_does():
    # the app's calibration stores 4-cell runs at grid load cases beside the 8-cell grid: the
    # pchip model averaged both at those points (an interpolated 250 Hz row moved 1.238 ->
    # 1.254), while the grid case itself is the 8-cell one. The model now keeps, at each
    # load case, the case a grid match would take (the most cells).
    runs = dem_grid().assign(cells_simulated=8.0)
    other = runs[(runs.frequency_hz == 50) & (runs.acceleration_g == 5)].assign(
        cells_simulated=4.0, sdc=lambda r: r.sdc + 1.0, seed=2,
        case_key=lambda r: r.case_key + "_4cells")
    both = pd.concat([runs, other], ignore_index=True)
    case = LoadCase(80.0, 3.0, 40.0)
    aligner = Aligner.from_tables(both)
    out = aligner.align(case)
    assert out.status == "interpolated", out.message
    # the linear field of the 8-cell runs, exactly (trilinear pchip): no 4-cell value in it
    assert out.sdc_dem == pytest.approx(linear_sdc(40.0, 3.0, 80.0), rel=1e-12)
    assert "the runs of other settings left out" in out.message
    # the grid case at that point is the 8-cell one too: model and grid agree
    grid = aligner.align(LoadCase(50.0, 5.0, 50.0))
    assert grid.status == "grid" and grid.sdc_dem == linear_sdc(50.0, 5.0, 50.0)
    # pooled explicitly (--pool), the settings are one case and the model averages them
    pooled = Aligner.from_tables(both, pool_settings=True).align(case)
    assert pooled.sdc_dem != pytest.approx(out.sdc_dem, rel=1e-6)


@pytest.mark.parametrize("field", ["frequency_hz", "acceleration_g", "fill_percent"])
def test_a_dem_run_without_its_load_case_is_refused_naming_the_run(field):
    # A run stored through the library without its load case (Store.add_dem_run("handmade",
    # {"sdc": 0.3})): `pidcore report` said "load case: --frequency must be a positive finite
    # number, got nan", naming neither the run nor the stored field
    from pidcore.errors import ParameterError

    runs = dem_grid()
    runs.loc[3, field] = math.nan
    with pytest.raises(ParameterError, match=rf"DEM run '{runs.loc[3, 'case_key']}': record "
                                             rf"field {field} is nan; expected a positive"):
        dem_cases(runs)
