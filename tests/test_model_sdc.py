"""SDC interpolation model: Table 3 loader, pchip grid model, holes, range handling."""

from __future__ import annotations

import dataclasses
import itertools
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.interpolate import PchipInterpolator, RegularGridInterpolator

from pidcore.errors import ParameterError
from pidcore.model import SdcModel

SHARED_TABLE = Path("/work/shared/reference/table3.csv")
# Round-off of a cubic evaluated at an interval end: a few ulps of values <= 1.
RTOL_GRID = 1e-12
ATOL_ROUNDOFF = 1e-12


@pytest.fixture
def table(paper_table) -> pd.DataFrame:
    return paper_table


@pytest.fixture
def model(paper_model) -> SdcModel:
    return paper_model


def _synthetic_table(rng: np.random.Generator, *, shape=(4, 4, 5)) -> pd.DataFrame:
    fills = np.sort(rng.uniform(10, 95, shape[0]))
    accs = np.sort(rng.uniform(0.5, 12, shape[1]))
    freqs = np.sort(rng.uniform(20, 1200, shape[2]))
    rows = [(p, a, f, rng.uniform(0, 1))
            for p, a, f in itertools.product(fills, accs, freqs)]
    return pd.DataFrame(rows, columns=["fill_percent", "acceleration_g", "frequency_hz", "sdc"])


# --------------------------------------------------------------------------- Table 3
def test_table3_matches_transcription_notes(table):
    assert list(table.columns) == ["frequency_hz", "acceleration_g", "fill_percent", "sdc_dem",
                                   "sdc_experimental"]
    assert len(table) == 4 * 3 * 4
    missing = table[table["sdc_dem"].isna()]
    assert missing[["frequency_hz", "acceleration_g", "fill_percent"]].values.tolist() == [
        [1000.0, 1.0, 90.0]]
    reattributed = table[(table.frequency_hz == 500) & (table.acceleration_g == 10)
                         & (table.fill_percent == 90)]
    assert reattributed["sdc_dem"].item() == 0.4756
    exp = table[table["sdc_experimental"].notna()]
    assert len(exp) == 12 and set(exp["fill_percent"]) == {50.0}


@pytest.mark.skipif(not SHARED_TABLE.exists(), reason="shared reference not available")
def test_packaged_table_equals_shared_reference(table):
    shared = pd.read_csv(SHARED_TABLE)
    pd.testing.assert_frame_equal(table, shared.astype(float))


# --------------------------------------------------------------------------- grid model
@pytest.mark.parametrize("log_frequency", [False, True])
def test_reproduces_every_grid_point(table, log_frequency):
    m = SdcModel.from_table(table, log_frequency=log_frequency)
    data = table[table["sdc_dem"].notna()]
    got = m(data.fill_percent.to_numpy(), data.acceleration_g.to_numpy(),
            data.frequency_hz.to_numpy())
    np.testing.assert_allclose(got, data.sdc_dem.to_numpy(), rtol=RTOL_GRID, atol=0)


def test_equals_scipy_regular_grid_pchip_on_4_point_axes():
    # RegularGridInterpolator(pchip) needs >= 4 points per axis (Table 3 has 3 accelerations),
    # so compare on a synthetic 4x4x5 grid. RGI folds the last axis first, then the others in
    # descending order; our pass order frequency, fill, acceleration is RGI on axes
    # (acceleration, fill, frequency).
    rng = np.random.default_rng(1)
    t = _synthetic_table(rng)
    m = SdcModel.from_table(t, value="sdc")
    fills, accs, freqs = m.axes
    rgi = RegularGridInterpolator((accs, fills, freqs), np.transpose(m.values, (1, 0, 2)),
                                  method="pchip")
    q = np.column_stack([rng.uniform(accs[0], accs[-1], 300), rng.uniform(fills[0], fills[-1], 300),
                         rng.uniform(freqs[0], freqs[-1], 300)])
    np.testing.assert_allclose(m(q[:, 1], q[:, 0], q[:, 2]), rgi(q), rtol=1e-12, atol=1e-14)


def test_grid_lines_equal_one_dimensional_pchip(model, table):
    # On a line through grid nodes the tensor model is the 1-D pchip of that line's data.
    t = model.grid_table()
    x = np.linspace(1, 10, 57)
    line = t[(t.fill_percent == 75) & (t.frequency_hz == 500)].sort_values("acceleration_g")
    ref = PchipInterpolator(line.acceleration_g, line.sdc_dem)(x)
    np.testing.assert_allclose(model(75, x, 500), ref, rtol=1e-12)
    f = np.linspace(50, 1000, 77)
    line = t[(t.fill_percent == 25) & (t.acceleration_g == 5)].sort_values("frequency_hz")
    ref = PchipInterpolator(line.frequency_hz, line.sdc_dem)(f)
    np.testing.assert_allclose(model(25, 5, f), ref, rtol=1e-12)


def test_bounded_by_neighbouring_corners(model):
    # pchip is monotone on every interval, so each 1-D pass stays between its two neighbours
    # and the result within min/max of the 8 corners of the grid cell.
    rng = np.random.default_rng(7)
    n = 20000
    q = [rng.uniform(ax[0], ax[-1], n) for ax in model.axes]
    v = model(*q)
    idx = [np.clip(np.searchsorted(ax, c, side="right") - 1, 0, ax.size - 2)
           for ax, c in zip(model.axes, q, strict=True)]
    corners = np.stack([model.values[idx[0] + i, idx[1] + j, idx[2] + k]
                        for i, j, k in itertools.product((0, 1), repeat=3)])
    assert np.all(v >= corners.min(axis=0) - ATOL_ROUNDOFF)
    assert np.all(v <= corners.max(axis=0) + ATOL_ROUNDOFF)
    assert np.all((v >= 0) & (v <= 1))


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_monotone_between_monotone_data(model, axis):
    others = [i for i in range(3) if i != axis]
    ax = model.axes[axis]
    for i0, i1 in itertools.product(range(model.axes[others[0]].size),
                                    range(model.axes[others[1]].size)):
        for k in range(ax.size - 1):
            x = np.linspace(ax[k], ax[k + 1], 101)
            coords = [None, None, None]
            coords[axis] = x
            coords[others[0]] = model.axes[others[0]][i0]
            coords[others[1]] = model.axes[others[1]][i1]
            y = model(*coords)
            node = [slice(None)] * 3
            node[others[0]], node[others[1]] = i0, i1
            data = model.values[tuple(node)]
            step = np.sign(data[k + 1] - data[k])
            assert np.all(step * np.diff(y) >= -ATOL_ROUNDOFF)


def test_broadcasting_shape(model):
    out = model(np.array([30.0, 60.0]), np.array([[2.0], [3.0], [4.0]]), 300.0)
    assert out.shape == (3, 2)
    assert out[1, 0] == model(30.0, 3.0, 300.0)


def test_acceleration_section_is_the_model(model):
    a = np.linspace(1, 10, 41)
    for fill, freq in [(60.0, 300.0), (25.0, 50.0), (90.0, 1000.0)]:
        np.testing.assert_allclose(model.acceleration_section(fill, freq)(a),
                                   model(fill, a, freq), rtol=1e-13)


# --------------------------------------------------------------------------- hole filling
def test_paper_hole_is_filled_and_flagged(model):
    value = model(90.0, 1.0, 1000.0)
    # rule: beyond the last known fill the nearest known value (75 %) is held
    assert value == pytest.approx(0.8078, rel=1e-12)
    filled = model.filled_points()
    assert filled[["fill_percent", "acceleration_g", "frequency_hz"]].values.tolist() == [
        [90.0, 1.0, 1000.0]]
    assert model.filled.sum() == 1
    assert not model.data_points()[["fill_percent", "acceleration_g", "frequency_hz"]].apply(
        tuple, axis=1).isin([(90.0, 1.0, 1000.0)]).any()


def test_interior_hole_uses_pchip_along_fill():
    rng = np.random.default_rng(3)
    t = _synthetic_table(rng)
    fills = np.sort(t.fill_percent.unique())
    a0, f0 = t.acceleration_g.min(), t.frequency_hz.max()
    line = t[(t.acceleration_g == a0) & (t.frequency_hz == f0)].sort_values("fill_percent")
    hole = (t.fill_percent == fills[1]) & (t.acceleration_g == a0) & (t.frequency_hz == f0)
    t2 = t.copy()
    t2.loc[hole, "sdc"] = np.nan
    m = SdcModel.from_table(t2, value="sdc")
    known = line[line.fill_percent != fills[1]]
    expected = PchipInterpolator(known.fill_percent, known.sdc)(fills[1])
    assert m(fills[1], a0, f0) == pytest.approx(expected, rel=1e-12)
    assert m.filled.sum() == 1


def test_missing_rows_are_holes_too():
    rng = np.random.default_rng(4)
    t = _synthetic_table(rng)
    top = t.fill_percent.max()
    drop = (t.fill_percent == top) & (t.acceleration_g == t.acceleration_g.min())
    m = SdcModel.from_table(t[~drop], value="sdc")
    assert m.filled.sum() == drop.sum() and m.filled[-1, 0, :].all()


def test_line_without_any_value_is_refused():
    rng = np.random.default_rng(5)
    t = _synthetic_table(rng)
    t.loc[(t.acceleration_g == t.acceleration_g.min()) & (t.frequency_hz == t.frequency_hz.min()),
          "sdc"] = np.nan
    with pytest.raises(ParameterError, match="no value at any fill"):
        SdcModel.from_table(t, value="sdc")


def test_a_line_without_any_value_is_named_by_its_acceleration_and_frequency():
    # a report row's note said "no value at any fill for acceleration index 1, frequency
    # index 0": the model's array indices, which the user cannot map to a load case
    t = pd.DataFrame({"fill_percent": [20.0, 40.0, 20.0, 40.0, 43.5],
                      "acceleration_g": [5.0, 5.0, 10.0, 10.0, 5.0],
                      "frequency_hz": [500.0, 500.0, 500.0, 500.0, 200.0],
                      "sdc": [0.7, 1.1, 0.4, 0.5, 1.3]})
    with pytest.raises(ParameterError, match=r"no value at any fill for 10 g, 200 Hz \("):
        SdcModel.from_table(t, value="sdc")


def test_a_run_without_a_value_stays_a_filled_hole_when_an_off_grid_run_is_left_out():
    # the complete grid kept only the runs with a value: a run that gave none (the only one at
    # 90 %) lost the 90 % fill from the model once a stray 300 Hz run was left out, while the
    # same runs without the stray one keep it as a hole, filled along fill and flagged
    from pidcore.model.sdc_model import complete_grid_model

    grid = pd.DataFrame(list(itertools.product([30.0, 60.0], [2.0, 8.0], [100.0, 500.0])),
                        columns=["fill_percent", "acceleration_g", "frequency_hz"])
    grid["sdc"] = 0.001 * grid["fill_percent"] + 0.01 * grid["acceleration_g"]
    failed = pd.DataFrame({"fill_percent": [90.0], "acceleration_g": [2.0],
                           "frequency_hz": [100.0], "sdc": [np.nan]})
    stray = pd.DataFrame({"fill_percent": [30.0], "acceleration_g": [2.0],
                          "frequency_hz": [300.0], "sdc": [0.5]})
    plain, _, none = complete_grid_model(pd.concat([grid, failed]))
    model, kept, left_out = complete_grid_model(pd.concat([grid, failed, stray]))
    assert none == "" and left_out == "300 Hz (not run at every acceleration)"
    assert len(kept) == len(grid) + 1 and 300.0 not in set(kept["frequency_hz"])
    for axis_kept, axis_plain in zip(model.axes, plain.axes, strict=True):
        np.testing.assert_array_equal(axis_kept, axis_plain)
    # same data, same construction: bit for bit
    np.testing.assert_array_equal(model.values, plain.values)
    np.testing.assert_array_equal(model.filled, plain.filled)
    assert model.filled_points()[["fill_percent", "acceleration_g", "frequency_hz"]
                                 ].values.tolist()[0] == [90.0, 2.0, 100.0]


# --------------------------------------------------------------------------- range handling
@pytest.mark.parametrize("point", [(24.9, 5, 100), (95, 5, 100), (50, 0.5, 100), (50, 11, 100),
                                   (50, 5, 40), (50, 5, 1001)])
def test_refuses_extrapolation(model, point):
    assert not model.contains(point)
    with pytest.raises(ParameterError, match="outside the model range"):
        model(*point)


def test_clip_to_range_holds_edge_value(model):
    assert model.evaluate(50, 12, 2000, clip_to_range=True) == model(50, 10, 1000)
    assert model.evaluate(10, 0.2, 10, clip_to_range=True) == model(25, 1, 50)


@pytest.mark.parametrize(("point", "shown"), [
    ((0.0, 5.0, 500.0), "fill_percent=0 %, acceleration_g=5 g, frequency_hz=500 Hz"),
    ((150.0, 5.0, 500.0), "fill_percent=150 %, acceleration_g=5 g, frequency_hz=500 Hz"),
    ((50.0, -5.0, 500.0), "fill_percent=50 %, acceleration_g=-5 g, frequency_hz=500 Hz"),
    ((50.0, 5.0, 0.0), "fill_percent=50 %, acceleration_g=5 g, frequency_hz=0 Hz"),
])
def test_clip_to_range_holds_no_edge_for_what_is_no_load_case(model, point, shown):
    # a fill of 0 % (no particle) or 150 % got the 25 or 90 % SDC, and equivalent_damper_table
    # (clip_to_range=True) a c_eq for it; `pidcore model damper --fills 0` is refused
    from pidcore.model import equivalent_damper_table

    said = (f"SdcModel: point ({shown}) is no load case (expected fill_percent in (0, 100] %, "
            "acceleration_g and frequency_hz > 0); clip_to_range=True holds the edge value of "
            "load cases beyond the grid only")
    with pytest.raises(ParameterError) as refused:
        model.evaluate(*point, clip_to_range=True)
    assert str(refused.value) == said
    fill, acceleration, frequency = point
    with pytest.raises(ParameterError) as in_table:
        equivalent_damper_table(model, fills_percent=[fill], accelerations_g=[acceleration],
                                frequencies_hz=[frequency], vibrated_mass_kg=0.07,
                                clip_to_range=True)
    assert str(in_table.value) == said


def test_clip_to_range_is_a_bool(model):
    # "no" is truthy: it clipped
    with pytest.raises(ParameterError, match=r"^clip_to_range: expected True or False, "
                                             r"got 'no'$"):
        model.evaluate(50, 12, 2000, clip_to_range="no")


def test_contains_edges(model):
    assert model.contains((25, 1, 50)) and model.contains((90, 10, 1000))
    assert model.contains((50, 10 * (1 + 1e-12), 1000))  # float noise from unit conversions
    with pytest.raises(ParameterError):
        model.contains((50, 5))


def test_log_frequency_changes_interior_not_grid(table):
    lin = SdcModel.from_table(table)
    log = SdcModel.from_table(table, log_frequency=True)
    np.testing.assert_allclose(lin.values, log.values, rtol=0)
    assert abs(lin(50, 5, 300) - log(50, 5, 300)) > 1e-3
    assert log(50, 5, 500) == pytest.approx(lin(50, 5, 500), rel=1e-12)


# --------------------------------------------------------------------------- other tables
def test_store_like_table_averages_duplicates():
    rng = np.random.default_rng(6)
    t = _synthetic_table(rng, shape=(2, 3, 2))
    up, down = t.copy(), t.copy()
    up["sdc"] += 0.05
    down["sdc"] -= 0.05
    runs = pd.concat([up, down], ignore_index=True)
    runs["sdc_stderr"] = 0.01
    m = SdcModel.from_table(runs, value="sdc")
    got = m(t.fill_percent.to_numpy(), t.acceleration_g.to_numpy(), t.frequency_hz.to_numpy())
    np.testing.assert_allclose(got, t.sdc.to_numpy(), rtol=1e-12)


def test_bad_tables_are_refused(table):
    with pytest.raises(ParameterError, match="missing columns"):
        SdcModel.from_table(table, value="sdc")
    one_freq = table[table.frequency_hz == 50]
    with pytest.raises(ParameterError, match="frequency_hz has 1 distinct"):
        SdcModel.from_table(one_freq)


def test_select_runs_refuses_mixed_conditions():
    from pidcore.model import select_runs

    rng = np.random.default_rng(8)
    t = _synthetic_table(rng, shape=(2, 2, 2))
    runs = pd.concat([t.assign(material="acrylic"), t.assign(material="aluminium", sdc=0.5)],
                     ignore_index=True)
    with pytest.raises(ParameterError, match="differ in material"):
        select_runs(runs)
    acrylic = select_runs(runs, where={"material": "acrylic"})
    m = SdcModel.from_table(acrylic, value="sdc")
    np.testing.assert_allclose(m(t.fill_percent, t.acceleration_g, t.frequency_hz), t.sdc,
                               rtol=1e-12)
    with pytest.raises(ParameterError, match="none match"):
        select_runs(runs, where={"material": "steel"})
    with pytest.raises(ParameterError, match="no column 'seed'"):
        select_runs(runs, where={"seed": "1"})


def test_a_point_a_hair_outside_the_model_is_named_as_given(model):
    # 1000.001 Hz was refused as "frequency_hz=1000 Hz is outside ... [50, 1000]" (:g), a
    # message naming a value inside the range; in the damper table too
    from pidcore.model import equivalent_damper_table

    said = "(fill_percent=90 %, acceleration_g=10 g, frequency_hz=1000.001 Hz) is outside"
    with pytest.raises(ParameterError) as refused:
        model(90, 10, 1000.001)
    assert said in str(refused.value)
    with pytest.raises(ParameterError) as in_table:
        equivalent_damper_table(model, fills_percent=[90], accelerations_g=[10],
                                frequencies_hz=[1000.001], vibrated_mass_kg=0.15)
    assert said in str(in_table.value)
    with pytest.raises(ParameterError, match=r"\(fill_percent=100.0000001 %, .*\) is no load "
                                             r"case"):
        model.evaluate(100.0000001, 5, 100, clip_to_range=True)


# --------------------------------------------------------------------------- resting on a hole
_HOLE = (3, 0, 3)  # Table 3's 90 %, 1 g, 1000 Hz in the grid's (fill, acceleration, frequency)


def _with_hole_at(model: SdcModel, value: float) -> SdcModel:
    values = model.values.copy()
    values[_HOLE] = value
    return dataclasses.replace(model, values=values)


def test_values_resting_on_the_held_hole_are_flagged_not_only_the_hole(model):
    # the damper table flagged (90 %, 1 g, 1000 Hz) alone, though the hole set to 0.95 moves
    # (90 %, 1.5 g, 1000 Hz) by +0.116 and (90 %, 1 g, 900 Hz) by +0.129
    points = np.array([(90, 1.5, 1000), (90, 1, 900), (90, 1, 1000), (85, 1, 1000),
                       (25, 5, 50), (90, 10, 1000), (75, 1, 1000), (50, 8.18, 800)], float).T
    dep = model.filled_dependence(*points)
    assert dep.points[["fill_percent", "acceleration_g", "frequency_hz"]].values.tolist() == [
        [90.0, 1.0, 1000.0]]
    assert dep.depends.shape == (8, 1)
    assert dep.any.tolist() == [True, True, True, True, False, False, False, False]
    moved = _with_hole_at(model, 0.95)(*points) - model(*points)
    np.testing.assert_allclose(moved[:2], [0.1156, 0.1293], atol=5e-5)  # the trial's numbers
    # the hole itself is its own value: SDC moves 1:1 with it
    assert dep.slope_rising[2, 0] == pytest.approx(1.0, abs=1e-9)
    # 85 % lies where the held value (equal to the 75 % one) makes pchip's fill slope turn:
    # the SDC moves faster as the hole rises than as it falls, and the note says both
    assert dep.slope_rising[3, 0] > 2 * dep.slope_falling[3, 0] > 0
    assert "per unit it rises" in dep.summary() and "1000 Hz, 1 g, 90 %" in dep.summary()


def test_a_value_not_flagged_is_the_same_bit_for_bit_whatever_the_held_value(model):
    # the dependence test must be exact, not a neighbourhood: where it says no, the derivative
    # with respect to the hole is 0 (no change at all, not a small one, even in round-off)
    rng = np.random.default_rng(11)
    random = [rng.uniform(ax[0], ax[-1], 3000) for ax in model.axes]
    grid = [g.ravel() for g in np.meshgrid(*model.axes, indexing="ij")]
    points = [np.concatenate([r, g]) for r, g in zip(random, grid, strict=True)]
    dep = model.filled_dependence(*points)
    flagged = dep.any
    assert 0 < flagged.sum() < flagged.size - grid[0].size
    assert np.all(dep.slope_rising[~flagged] == 0) and np.all(dep.slope_falling[~flagged] == 0)
    base = model(*points)
    moved = np.zeros(flagged.shape, dtype=bool)
    # hole values other than the method's own probes, over the SDC's range and beyond
    for value in (*rng.uniform(-1, 2, 16), 0.95, 1.5):
        other = _with_hole_at(model, value)(*points)
        np.testing.assert_array_equal(other[~flagged], base[~flagged])
        moved |= other != base
    # and where it says yes the value moves for some of them (points where pchip turns
    # for every hole value stay unflagged: 1 in 25 of these would be flagged by the stencil)
    assert np.all(moved[flagged])
    # of the grid points, only the hole rests on the hole
    on_grid = flagged[-grid[0].size:].reshape(model.values.shape)
    np.testing.assert_array_equal(on_grid, model.filled)


def test_the_slopes_given_are_the_model_s_own(model):
    # one-sided differences of 1e-4 on the hole, against the method's 1e-6 ones: the value is
    # smooth in the hole on either side of the turn, so the two differ by curvature x 1e-4
    # (the SDC's second derivative in the hole is O(1..10) here): 1e-3 covers it
    points = np.array([(90, 1.5, 1000), (90, 1, 900), (85, 1, 1000), (80, 3, 950)], float).T
    dep = model.filled_dependence(*points)
    base, step = model(*points), 1e-4
    up = (_with_hole_at(model, 0.8078 + step)(*points) - base) / step
    down = (base - _with_hole_at(model, 0.8078 - step)(*points)) / step
    np.testing.assert_allclose(dep.slope_rising[:, 0], up, atol=1e-3)
    np.testing.assert_allclose(dep.slope_falling[:, 0], down, atol=1e-3)


def test_select_runs_compares_numbers_as_numbers():
    # --where fill_percent=50 matched none of the 12 runs stored at 50.0 %, fixture_mass_kg=0
    # none at 0.0 (compared as text), though fill_percent=50.0 did
    from pidcore.model import select_runs

    rng = np.random.default_rng(8)
    t = _synthetic_table(rng, shape=(2, 2, 2))
    fills = sorted(t.fill_percent.unique())
    t = t.assign(fill_percent=t.fill_percent.map({fills[0]: 50.0, fills[1]: 75.0}),
                 fixture_mass_kg=0.0, material="acrylic")
    for wanted in ("50", "50.0", "5e1"):
        chosen = select_runs(t, where={"fill_percent": wanted})
        assert len(chosen) == 4 and set(chosen.fill_percent) == {50.0}
    assert len(select_runs(t, where={"fixture_mass_kg": "0"})) == 8
    with pytest.raises(ParameterError, match="none match"):
        select_runs(t, where={"fill_percent": "50.5"})
    # text stays text
    assert len(select_runs(t, where={"material": "acrylic"})) == 8


def test_readme_says_what_holds_between_grid_lines(model):
    # it said the model is "monotone with the data between them": at 50 %, 8.18 g the SDC
    # falls from 500 to 1000 Hz though the four data around it rise
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    assert "monotone with the data between them" not in readme
    sdc = model(50.0, 8.18, np.array([500.0, 1000.0]))
    corners = model.values[1, 1:3][:, [2, 3]]  # 50 %, 5 and 10 g, 500 and 1000 Hz
    assert np.all(corners[:, 1] > corners[:, 0]) and sdc[1] < sdc[0]
    assert f"falls from {sdc[0]:.3f} at 500 Hz to {sdc[1]:.3f} at 1000 Hz" in readme
