"""Comparison figures: DEM loop from stored time series, loop overlay, SDC per load case."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from pidcore.measure import analysis_arrays
from pidcore.report import ALIGNMENT_COLUMN, build_report_table
from pidcore.report.comparison_figures import (
    dem_loop_from_arrays,
    loop_from_phasors,
    plot_loop_overlay,
    plot_sdc_comparison,
)
from pidcore.signal import analyze_power, synthesize_shaker_record

FREQ_HZ, RATE_HZ, ACC_M_S2, DAMPING = 200.0, 10000.0, 20.0, 4.0


def _shoelace(x, y):
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


@pytest.fixture(scope="module")
def dem_arrays():
    rec = synthesize_shaker_record(mass_kg=0.3, acceleration_amplitude_m_s2=ACC_M_S2,
                                   frequency_hz=FREQ_HZ, sample_rate_hz=RATE_HZ, n_periods=30,
                                   viscous_damping_n_s_m=DAMPING)
    return {"shaker_force_n": rec.force_n, "velocity_m_s": rec.velocity_m_s,
            "sample_time_s": np.arange(rec.force_n.size) / RATE_HZ}


def test_dem_loop_encloses_the_viscous_energy_per_cycle(dem_arrays):
    loop = dem_loop_from_arrays(dem_arrays, {"frequency_hz": FREQ_HZ, "steady_start_cycle": 3})
    x, f = loop.displacement_m, loop.force_n
    w = 2 * math.pi * FREQ_HZ
    amplitude_m = ACC_M_S2 / w**2
    expected_j = math.pi * DAMPING * w * amplitude_m**2  # energy per cycle of a viscous damper
    # noise-free record, harmonic fit over whole periods: agreement to the polygon's
    # discretisation error (256 points: relative 1 - sin(2pi/N)/(2pi/N) ~ 1e-4)
    assert _shoelace(x, f) == pytest.approx(expected_j, rel=1e-3)
    assert np.ptp(x) / 2 == pytest.approx(amplitude_m, rel=1e-6)


def test_dem_loop_uses_time_array_when_rate_is_missing(dem_arrays):
    with_rate = dem_loop_from_arrays(dem_arrays, {"frequency_hz": FREQ_HZ,
                                                  "sample_rate_hz": RATE_HZ})
    from_time = dem_loop_from_arrays(dem_arrays, {"frequency_hz": FREQ_HZ})
    np.testing.assert_allclose(from_time.force_n, with_rate.force_n, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize(("arrays", "record", "says"), [
    ({"sdc_per_cell": np.ones(3)}, {"frequency_hz": FREQ_HZ}, "no force"),
    ({"shaker_force_n": np.ones(5), "velocity_m_s": np.ones(4)}, {"frequency_hz": 1.0},
     "differ in shape"),
    ({"shaker_force_n": np.ones(5), "velocity_m_s": np.ones(5)}, {}, "lacks"),
])
def test_dem_loop_missing_series_gives_a_note(arrays, record, says):
    note = dem_loop_from_arrays(arrays, record)
    assert isinstance(note, str) and says in note


def test_loop_overlay_draws_both_closed_loops(dem_arrays):
    dem = dem_loop_from_arrays(dem_arrays, {"frequency_hz": FREQ_HZ})
    measured = (dem.displacement_m * 1.1, dem.force_n * 0.9)
    fig = plot_loop_overlay(measured, dem, title="t")
    lines = fig.axes[0].get_lines()
    assert [ln.get_label() for ln in lines] == ["measured", "DEM (ours)"]
    xd, yd = lines[1].get_data()
    np.testing.assert_allclose(xd[:-1], dem.displacement_m * 1e6)  # µm
    assert (xd[0], yd[0]) == (xd[-1], yd[-1])  # closed
    alone = plot_loop_overlay(measured, None)
    assert len(alone.axes[0].get_lines()) == 1


def test_sdc_comparison_plots_the_table_values():
    dem = pd.DataFrame({"frequency_hz": [50.0, 50.0, 100.0, 100.0] * 2,
                        "acceleration_g": [1.0, 5.0] * 4,
                        "fill_percent": [25.0] * 4 + [50.0] * 4,
                        "material": ["acrylic"] * 8, "direction": ["z"] * 8,
                        "sdc": np.linspace(0.1, 0.8, 8), "sdc_stderr": [0.01] * 8})
    analyses = pd.DataFrame({"frequency_hz": [50.1, 75.0], "acceleration_g": [5.0, 3.0],
                             "fill_percent": [50.0, 30.0], "sdc": [0.31, 0.42],
                             "sdc_stderr": [0.02, 0.03], "source": ["a", "b"]})
    table = build_report_table(dem, analyses, None)
    fig = plot_sdc_comparison(table)
    ax = fig.axes[0]
    # every row has a value: 8 DEM rows (one shared with the 50.1 Hz measurement) + 75 Hz
    assert len(table) == 9
    assert len(ax.get_xticks()) == len(table)
    by_label = {ln.get_label(): ln for ln in ax.get_lines()}
    interp = by_label["DEM (ours), SDC of Eq. 10 E, pchip-interpolated"].get_ydata()
    assert list(interp) == list(table.loc[table[ALIGNMENT_COLUMN] == "interpolated",
                                          "SDC DEM (ours) [-]"])


def _own_specimen_table():
    """As an own specimen's report: steel DEM runs at 3 load cases, no paper, and one measured
    row the DEM does not cover (acrylic: out of range), which alone has an Eq. 11 value."""
    dem = pd.DataFrame({"frequency_hz": [100.0, 200.0, 500.0], "acceleration_g": [5.0, 5.0, 1.0],
                        "fill_percent": [40.0] * 3, "material": ["steel_440c"] * 3,
                        "direction": ["z"] * 3, "sdc": [1.09, 0.93, 0.0059],
                        "sdc_stderr": [0.03, 0.04, 0.0002]})
    analyses = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [1.0],
                             "fill_percent": [40.0], "sdc": [1.135], "sdc_stderr": [0.003],
                             "source": ["run_200Hz.csv"]})
    return build_report_table(dem, analyses, None)


def test_sdc_comparison_draws_every_row_under_its_tick_with_only_drawn_legend():
    """The own-specimen figure the trial found: the DEM-only rows were dropped once a row was
    measured, the legend named the paper's series and an interpolation never drawn, and the
    one tick sat at the left edge while its marker sat at the right one."""
    table = _own_specimen_table()
    ax = plot_sdc_comparison(table).axes[0]
    assert len(table) == 4
    ticks = ax.get_xticks()
    assert list(ticks) == [0.0, 1.0, 2.0, 3.0]
    labels = [t.get_text() for t in ax.get_xticklabels()]
    # same frequency, acceleration and fill, different material: the ticks must differ
    assert len(set(labels)) == 4 and "acrylic" in labels[2] and "steel_440c" in labels[3]
    _, legend = ax.get_legend_handles_labels()
    assert not [lb for lb in legend if "paper" in lb or "pchip" in lb]
    assert sorted(lb.split(",")[0] for lb in legend) == ["DEM (ours)", "measured (ours)"]
    lo, hi = ax.get_xlim()
    # half a category either side: every marker (at most 2 x 0.15 off its tick) lies inside
    # its own category, and so closer to its tick than to any other
    assert (lo, hi) == (-0.5, 3.5)
    for container in ax.containers:
        for x in container.lines[0].get_xdata():
            assert min(abs(ticks - x)) <= 0.3


def test_sdc_comparison_wraps_long_tables_onto_panels():
    from pidcore.report.comparison_figures import SDC_FIGURE_ROWS_PER_PANEL

    n = 2 * SDC_FIGURE_ROWS_PER_PANEL + 3
    dem = pd.DataFrame({"frequency_hz": np.arange(1.0, n + 1) * 10, "acceleration_g": [5.0] * n,
                        "fill_percent": [50.0] * n, "material": ["acrylic"] * n,
                        "direction": ["z"] * n, "sdc": np.linspace(0.1, 1.0, n),
                        "sdc_stderr": [0.01] * n})
    fig = plot_sdc_comparison(build_report_table(dem, None, None))
    assert len(fig.axes) == 3
    assert sum(len(a.get_xticks()) for a in fig.axes) == n
    assert all(len(a.get_xticks()) <= SDC_FIGURE_ROWS_PER_PANEL for a in fig.axes)


def test_loop_from_stored_phasors_equals_the_analysis_loop(dem_arrays):
    a = analyze_power(dem_arrays["shaker_force_n"], dem_arrays["velocity_m_s"], RATE_HZ)
    stored = loop_from_phasors(analysis_arrays(a), a.frequency_hz)
    x, f = stored.displacement_m, stored.force_n
    x0, f0 = a.loop().displacement_m, a.loop().force_n
    # same formula; only omega = 2 pi f vs the stored omega differ, by round-off
    np.testing.assert_allclose(x, x0, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(f, f0, rtol=1e-12, atol=1e-12)
    assert "phasors" in loop_from_phasors({}, 100.0)


def test_sdc_comparison_sets_the_eq10_measured_sdc_beside_our_dem(one_measured_case):
    """The measurement drawn beside our DEM (Eq. 10 SDC) is the table's Eq. 10 measured SDC,
    the value its difference column uses; the Eq. 11 SDC is drawn apart and labelled so."""
    from pidcore.report.table import DIFFERENCE_COLUMN, MEASURED_EQ10_COLUMN

    # one record whose Eq. 11 SDC (4.3) is ~3x its Eq. 10 SDC: the gap the old figure showed
    dem, measured = one_measured_case.dem, one_measured_case.measured
    table = build_report_table(dem, measured, None)
    row = table.iloc[0]
    fig = plot_sdc_comparison(table)
    ax = fig.axes[0]
    _, labels = ax.get_legend_handles_labels()
    eq10 = [lb for lb in labels if lb.startswith("measured (ours)") and "Eq. 10" in lb
            and "Eq. 11" not in lb]
    eq11 = [lb for lb in labels if lb.startswith("measured (ours)") and "Eq. 11" in lb]
    assert len(eq10) == 1 and len(eq11) == 1 and "different quantity" in eq11[0]
    assert any(lb.startswith("DEM (ours)") and "Eq. 10" in lb for lb in labels)
    # errorbar containers: (data line, caps, bars); find each series' drawn y value
    drawn = {c.get_label(): c.lines[0].get_ydata() for c in ax.containers}
    assert list(drawn[eq10[0]]) == [row[MEASURED_EQ10_COLUMN]]
    assert list(drawn[eq11[0]]) == [row["SDC measured (Eq. 11) [-]"]]
    # what the figure sets side by side is what the table subtracts
    dem_label = next(lb for lb in drawn if lb.startswith("DEM (ours)"))
    assert drawn[eq10[0]][0] - drawn[dem_label][0] == pytest.approx(row[DIFFERENCE_COLUMN],
                                                                    rel=1e-12)
    # Eq. 10 error bar keeps the Eq. 11 relative error: one record, only E differs
    bars = next(c for c in ax.containers if c.get_label() == eq10[0]).lines[2][0]
    (lo, hi), = [seg[:, 1] for seg in bars.get_segments()]
    assert (hi - lo) / 2 == pytest.approx(0.1 / 4.3 * row[MEASURED_EQ10_COLUMN], rel=1e-12)


def test_sdc_comparison_ticks_of_one_load_case_name_the_settings_they_differ_in():
    """A 2-cell DEM run stored beside the 8-cell grid's run at 100 Hz, 5 g, 50 % drew two
    ticks reading "100 Hz 5 g 50 %" over SDCs 0.71 and 0.89; each now names its settings,
    and only those two ticks (the others stay three lines)."""
    from test_report_render import _two_settings_table

    table = _two_settings_table()
    ax = plot_sdc_comparison(table).axes[0]
    labels = [t.get_text() for t in ax.get_xticklabels()]
    assert labels == ["100 Hz\n5 g\n50 %\ncells 2", "100 Hz\n5 g\n50 %\ncells 8",
                      "1000 Hz\n1 g\n90 %"]
