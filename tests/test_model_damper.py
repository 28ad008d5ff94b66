"""Equivalent viscous damper from SDC: definitions, energy balance, round trip, table, files."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import quad

from pidcore.constants import STANDARD_GRAVITY
from pidcore.errors import ParameterError
from pidcore.model import (
    DAMPER_COLUMNS,
    SDC_FILLED_COLUMN,
    SDC_FILLED_NOTE,
    SDC_HELD_COLUMN,
    SDC_HELD_ERROR_COLUMN,
    SdcModel,
    coupon_vibrated_mass_kg,
    damping_ratio,
    energy_per_cycle,
    equivalent_damper_table,
    equivalent_damping_coefficient,
    loss_factor,
    paper_particles_mass_kg,
    paper_vibrated_mass,
    sdc_from_damping_coefficient,
    write_damper_table,
)


@pytest.fixture
def model(paper_model) -> SdcModel:
    return paper_model


def test_round_trip_sdc_to_c_eq_to_sdc():
    sdc = np.array([1.5e-4, 0.01, 0.3, 0.8843, 0.99])
    m = np.array([0.02, 0.1, 1.0, 3.0, 10.0])
    f = np.array([50.0, 100.0, 333.0, 500.0, 1000.0])
    c = equivalent_damping_coefficient(sdc, vibrated_mass_kg=m, frequency_hz=f)
    # two multiplications and two divisions: a few ulps
    np.testing.assert_allclose(sdc_from_damping_coefficient(c, vibrated_mass_kg=m,
                                                            frequency_hz=f), sdc, rtol=1e-14)


def test_c_eq_of_a_linear_viscous_damper():
    # A viscous damper c on mass m vibrating at w has loss factor c w / (m w^2) = c / (m w)
    # (at resonance this is 2 zeta). SDC = 2 pi * loss factor, so SDC = 2 pi 0.01 must give back
    # c = 0.01 m w = 2 zeta m w with zeta = 0.005.
    m, f = 1.7, 120.0
    w = 2 * np.pi * f
    c = equivalent_damping_coefficient(2 * np.pi * 0.01, vibrated_mass_kg=m, frequency_hz=f)
    assert c == pytest.approx(2 * 0.005 * m * w, rel=1e-14)
    assert loss_factor(2 * np.pi * 0.01) == pytest.approx(0.01, rel=1e-15)


@pytest.mark.parametrize("sdc,a_g,f", [(0.1891, 5.0, 100.0), (0.8843, 5.0, 1000.0),
                                       (1.5702e-4, 1.0, 50.0)])
def test_c_eq_dissipates_sdc_times_peak_kinetic_energy(sdc, a_g, f):
    # Integrate the viscous power c v^2 over one cycle of the coupon's motion (acceleration
    # amplitude a) numerically; it must equal SDC * m a^2 / (2 w^2) (Eq. 8-10).
    m = 0.0988
    w = 2 * np.pi * f
    a = a_g * STANDARD_GRAVITY
    c = float(equivalent_damping_coefficient(sdc, vibrated_mass_kg=m, frequency_hz=f))
    v_amp = a / w
    dissipated, _ = quad(lambda t: c * (v_amp * np.cos(w * t)) ** 2, 0, 2 * np.pi / w,
                         epsabs=0, epsrel=1e-12)
    kinetic_peak = 0.5 * m * v_amp**2
    assert dissipated == pytest.approx(sdc * kinetic_peak, rel=1e-10)
    assert energy_per_cycle(sdc, vibrated_mass_kg=m, acceleration_m_s2=a,
                            frequency_hz=f) == pytest.approx(sdc * kinetic_peak, rel=1e-14)


def test_damping_ratio_limits():
    s = np.array([1e-6, 1e-3, 0.5, 1.0, 1.2])
    z = damping_ratio(s)
    # small damping: -ln(1-s)/(4 pi) -> s/(4 pi) = loss factor / 2, relative error ~ s/2
    assert z[0] == pytest.approx(loss_factor(s[0]) / 2, rel=1e-6)
    assert z[1] == pytest.approx(loss_factor(s[1]) / 2, rel=1e-3)
    # free decay losing half its energy per cycle: exp(-4 pi zeta) = 1/2
    assert np.exp(-4 * np.pi * z[2]) == pytest.approx(0.5, rel=1e-14)
    assert np.isnan(z[3]) and np.isnan(z[4])


def test_coupon_mass_from_table_2():
    faces = 2 * 0.1 * 0.1 * 0.25e-3 * 2800
    core = 0.1 * 0.1 * 25.4e-3 * 32.1
    assert coupon_vibrated_mass_kg() == pytest.approx(faces + core, rel=1e-14)
    assert coupon_vibrated_mass_kg(particles_mass_kg=0.05) == pytest.approx(faces + core + 0.05)
    with pytest.raises(ParameterError):
        coupon_vibrated_mass_kg(particles_mass_kg=-1.0)


def test_paper_particle_mass():
    one = 1180 * 4 / 3 * np.pi * 1.25e-3**3  # acrylic, Table 1
    assert paper_particles_mass_kg(50) == pytest.approx(441 * 18 * one, rel=1e-14)
    assert paper_particles_mass_kg(100, "aluminium") == pytest.approx(
        441 * 36 * 2850 * 4 / 3 * np.pi * 1e-3**3, rel=1e-14)
    with pytest.raises(ParameterError, match="not a particle material"):
        paper_particles_mass_kg(50, "aluminium_wall")


def test_damper_table_content(model):
    def mass(fill):
        return 0.02 + fill / 1000

    t = equivalent_damper_table(model, fills_percent=[25, 90], accelerations_g=[1, 5],
                                frequencies_hz=[100, 1000], vibrated_mass_kg=mass)
    assert list(t.columns) == list(DAMPER_COLUMNS)
    assert len(t) == 8
    # every column names its unit; the flag's brackets name its values, as the report's
    # category columns do (it had no brackets: the one column without a unit marker)
    for column, unit in DAMPER_COLUMNS.items():
        assert column.endswith(f" [{unit}]"), column
        if pd.api.types.is_bool_dtype(t[column]):
            assert column in (SDC_FILLED_COLUMN, SDC_HELD_COLUMN) and unit == "True/False"
        elif column == SDC_HELD_ERROR_COLUMN:  # its brackets name its values
            assert set(t[column]) <= {"overstated", "understated", "unknown", "not held"}
        elif column == "coupon_cells [-]":  # a count
            assert pd.api.types.is_integer_dtype(t[column])
        else:
            assert pd.api.types.is_float_dtype(t[column])
    sdc = model(t["packing ratio [%]"].to_numpy(), t["acceleration [g]"].to_numpy(),
                t["frequency [Hz]"].to_numpy())
    np.testing.assert_array_equal(t["sdc [-]"], sdc)
    np.testing.assert_allclose(t["coupon_vibrated_mass [kg]"], 0.02 + t["packing ratio [%]"] / 1000)
    np.testing.assert_allclose(t["c_eq_per_treated_area [N s/m^3]"],
                               t["c_eq_per_coupon [N s/m]"] / 0.01,
                               rtol=1e-14)
    w = 2 * np.pi * t["frequency [Hz]"]
    x = t["displacement_amplitude [m]"]
    np.testing.assert_allclose(x * w**2, t["acceleration [g]"] * STANDARD_GRAVITY, rtol=1e-14)
    # c_eq = dE / (pi w X^2) by definition of the equivalent damper
    np.testing.assert_allclose(t["c_eq_per_coupon [N s/m]"],
                               t["coupon_energy_per_cycle [J]"] / (np.pi * w * x**2),
                               rtol=1e-13)
    flagged = t[t[SDC_FILLED_COLUMN]]
    assert flagged[["packing ratio [%]", "acceleration [g]", "frequency [Hz]"]].values.tolist() == [
        [90.0, 1.0, 1000.0]]


def test_damper_table_takes_a_value_given_twice_once(model):
    # an FEM lookup needs each (f, a, fill) key once; the Python call gave two identical rows
    # where pidcore model damper gave one (the CLI had deduplicated its options itself)
    # m_c as a function of fill: one number for two fills is refused
    once = equivalent_damper_table(model, fills_percent=[50, 75], accelerations_g=[5],
                                   frequencies_hz=[100], vibrated_mass_kg=paper_vibrated_mass())
    twice = equivalent_damper_table(model, fills_percent=[50, 75, 50], accelerations_g=[5, 5],
                                    frequencies_hz=[100], vibrated_mass_kg=paper_vibrated_mass())
    pd.testing.assert_frame_equal(twice, once)


def test_damper_table_refuses_out_of_range(model):
    with pytest.raises(ParameterError, match="outside the model range"):
        equivalent_damper_table(model, fills_percent=[50], accelerations_g=[20],
                                frequencies_hz=[100], vibrated_mass_kg=0.1)
    with pytest.raises(ParameterError, match="vibrated_mass_kg"):
        equivalent_damper_table(model, fills_percent=[50], accelerations_g=[5],
                                frequencies_hz=[100], vibrated_mass_kg=0.0)


def test_damper_table_refuses_a_vibrated_mass_in_grams(model):
    # the paper coupon's m_c with particles is 0.02-0.2 kg: 98.8 is grams typed for kg, which
    # gave c_eq and energies 1000 x too large (pidcore model damper --vibrated-mass refused it)
    with pytest.raises(ParameterError, match=r"^vibrated_mass_kg 98.8 kg is .*was it grams\?"):
        equivalent_damper_table(model, fills_percent=[50], accelerations_g=[5],
                                frequencies_hz=[100], vibrated_mass_kg=98.8)
    kept = equivalent_damper_table(model, fills_percent=[50], accelerations_g=[5],
                                   frequencies_hz=[100], vibrated_mass_kg=0.0988)
    assert kept["coupon_vibrated_mass [kg]"].tolist() == [0.0988]


def test_written_files_round_trip(tmp_path):
    grid = pd.MultiIndex.from_product([[25.0, 90.0], [1.0, 10.0], [50.0, 1000.0]],
                                      names=["fill_percent", "acceleration_g", "frequency_hz"])
    t = grid.to_frame(index=False)
    t["sdc"] = np.linspace(1e-7, 1.0, len(t))  # includes SDC = 1: damping ratio undefined
    m = SdcModel.from_table(t, value="sdc", source="synthetic")
    table = equivalent_damper_table(m, fills_percent=[25, 90], accelerations_g=[1, 10],
                                    frequencies_hz=[50, 1000],
                                    vibrated_mass_kg=lambda fill: 0.02 + fill / 1000)
    paths = write_damper_table(table, tmp_path, provenance={"sdc_source": m.source})
    assert [p.name for p in paths] == ["equivalent_damper.csv", "equivalent_damper.json"]
    back = pd.read_csv(paths[0])
    pd.testing.assert_frame_equal(back, table, check_exact=False, rtol=1e-15)
    doc = json.loads(paths[1].read_text())
    assert doc["units"]["c_eq_per_treated_area [N s/m^3]"] == "N s/m^3"
    assert doc["provenance"]["sdc_source"] == "synthetic"
    energies = [r["coupon_energy_per_cycle [J]"] for r in doc["records"]]
    assert energies == table["coupon_energy_per_cycle [J]"].tolist()  # full precision in JSON
    assert doc["records"][-1]["coupon_damping_ratio [-]"] is None
    with pytest.raises(ParameterError, match="formats"):
        write_damper_table(table, tmp_path, formats=("xlsx",))


def test_sdc_from_energy_per_cycle_inverts_energy_per_cycle():
    import math

    from pidcore.model import energy_per_cycle, sdc_from_energy_per_cycle

    for sdc, m, a, f in ((0.35, 0.069, 49.0, 500.0), (1.7, 0.02, 98.1, 50.0)):
        energy = float(energy_per_cycle(sdc, vibrated_mass_kg=m, acceleration_m_s2=a,
                                        frequency_hz=f))
        back = sdc_from_energy_per_cycle(energy, vibrated_mass_kg=m, acceleration_m_s2=a,
                                         frequency_hz=f)
        assert back == pytest.approx(sdc, rel=1e-14)  # two float operations each way
    # no reference energy (unknown m_c): NaN, not an exception or a number
    assert math.isnan(sdc_from_energy_per_cycle(1e-3, vibrated_mass_kg=float("nan"),
                                                acceleration_m_s2=9.8, frequency_hz=100.0))


def test_damper_table_axes_name_their_units_and_the_old_names_still_work(model):
    # fills=, accelerations=, frequencies= named no unit (g here, m/s^2 in energy_per_cycle;
    # harmonic_response says frequencies_hz=): the names with units, the old ones warned
    new = equivalent_damper_table(model, fills_percent=[50], accelerations_g=[5],
                                  frequencies_hz=[100], vibrated_mass_kg=0.1)
    with pytest.warns(DeprecationWarning) as caught:
        old = equivalent_damper_table(model, fills=[50], accelerations=[5], frequencies=[100],
                                      vibrated_mass_kg=0.1)
    assert sorted(str(w.message).split(": ")[1] for w in caught) == [
        "accelerations= is now accelerations_g= (the unit in the name)",
        "fills= is now fills_percent= (the unit in the name)",
        "frequencies= is now frequencies_hz= (the unit in the name)"]
    assert {w.filename for w in caught} == {__file__}  # pointed at the caller's line
    pd.testing.assert_frame_equal(new, old)
    with pytest.raises(ParameterError, match="^fills_percent and fills name the same axis"):
        equivalent_damper_table(model, fills_percent=[50], fills=[50], accelerations_g=[5],
                                frequencies_hz=[100], vibrated_mass_kg=0.1)


def test_points_held_at_the_edge_are_flagged(model):
    # with clip_to_range=True a 20 g row carried the 10 g SDC and a c_eq made of it, nothing
    # in the table telling it from a modelled row
    t = equivalent_damper_table(model, fills_percent=[50], accelerations_g=[5, 10, 20],
                                frequencies_hz=[100, 2000], vibrated_mass_kg=0.0988,
                                clip_to_range=True)
    outside = (t["acceleration [g]"] > 10) | (t["frequency [Hz]"] > 1000)
    assert t[SDC_HELD_COLUMN].tolist() == outside.tolist()
    assert outside.sum() == 4  # 20 g at both frequencies, 5 and 10 g at 2000 Hz
    held = t[(t["acceleration [g]"] == 20) & (t["frequency [Hz]"] == 100)]
    assert held["sdc [-]"].item() == float(model(50, 10, 100))  # the edge value, as flagged
    inside = equivalent_damper_table(model, fills_percent=[50], accelerations_g=[1, 10],
                                     frequencies_hz=[50, 1000], vibrated_mass_kg=0.0988)
    assert not inside[SDC_HELD_COLUMN].any()  # the grid's own edges are modelled points


def test_an_area_in_cm2_or_mm2_is_refused_by_the_library(model):
    # area_m2=100 (cm^2 of the paper's 0.01 m^2 coupon) gave a c_eq per area 1e4 x too small
    # without a word: only the CLI's --area was checked against the specimen's cells
    from pidcore.specimen import Specimen

    grid = dict(fills_percent=[50], accelerations_g=[5], frequencies_hz=[100],
                vibrated_mass_kg=0.0988)
    for typed, slip in ((100.0, "cm^2 or mm^2"), (1e4, "cm^2 or mm^2"),
                        (1e-6, "one cell's area")):
        with pytest.raises(ParameterError) as caught:
            equivalent_damper_table(model, area_m2=typed, **grid)
        message = str(caught.value)
        assert message.startswith(f"area_m2 {typed:g} m^2 is ")
        assert "specimen paper_coupon's 441 cells" in message
        assert "expected the coupon's face area in m^2" in message and slip in message
        assert "\n" not in message
    # the coupon's own area passes; another specimen's cells are what it is checked against
    ok = equivalent_damper_table(model, area_m2=0.01, **grid)
    np.testing.assert_allclose(ok["c_eq_per_treated_area [N s/m^3]"],
                               ok["c_eq_per_coupon [N s/m]"] / 0.01,
                               rtol=1e-15)  # one division
    text = (Path(__file__).parents[1] / "data_samples" / "specimens"
            / "steel_6mm.toml").read_text()
    steel = Specimen.from_text(text, source="steel_6mm.toml")
    equivalent_damper_table(model, area_m2=0.01, specimen=steel, **grid)  # 286 cells, 0.00999
    with pytest.raises(ParameterError, match="specimen steel_6mm's 286 cells"):
        equivalent_damper_table(model, area_m2=100.0, specimen=steel, **grid)


def test_c_eq_per_cell_is_the_coupons_c_eq_shared_by_its_cells(model, tmp_path):
    # a FEM model of the panel cell by cell needs c_eq per honeycomb cell, which the table did
    # not give: the coupon's c_eq / its cell count, whichever specimen the SDC is of
    from pidcore.specimen import Specimen

    grid = dict(fills_percent=[25, 90], accelerations_g=[1, 5], frequencies_hz=[100, 1000],
                vibrated_mass_kg=paper_vibrated_mass())
    paper = equivalent_damper_table(model, **grid)
    text = (Path(__file__).parents[1] / "data_samples" / "specimens"
            / "steel_6mm.toml").read_text()
    steel = equivalent_damper_table(model, specimen=Specimen.from_text(text, source="s"),
                                    area_m2=0.01, **grid)
    # one division each: to rounding
    np.testing.assert_allclose(paper["c_eq_per_cell [N s/m]"] * 441,
                               paper["c_eq_per_coupon [N s/m]"],
                               rtol=1e-15)
    np.testing.assert_allclose(steel["c_eq_per_cell [N s/m]"] * 286,
                               steel["c_eq_per_coupon [N s/m]"],
                               rtol=1e-15)
    # the cells' dashpots in parallel dissipate the coupon's energy per cycle
    w = 2 * np.pi * paper["frequency [Hz]"]
    x = paper["displacement_amplitude [m]"]
    np.testing.assert_allclose(441 * np.pi * paper["c_eq_per_cell [N s/m]"] * w * x**2,
                               paper["coupon_energy_per_cycle [J]"], rtol=1e-13)
    path = write_damper_table(paper, tmp_path, formats=("json",))[0]
    doc = json.loads(path.read_text())
    assert doc["units"]["c_eq_per_cell [N s/m]"] == "N s/m"
    assert "per honeycomb cell (one cell)" in doc["columns"]["c_eq_per_cell [N s/m]"]


@pytest.mark.parametrize("frequency_slope,acceleration_slope", [(+2e-4, -0.01), (-2e-4, +0.01)])
def test_a_held_sdc_says_which_way_it_errs(frequency_slope, acceleration_slope):
    # a 20 g or 2000 Hz row was flagged held, but not whether its SDC (and its c_eq) is too
    # high or too low there. SDC linear along each axis: pchip reproduces it, so its
    # continuation beyond the grid is the truth the held value is measured against.
    grid = pd.MultiIndex.from_product([[25.0, 90.0], [1.0, 5.0, 10.0], [50.0, 500.0, 1000.0]],
                                      names=["fill_percent", "acceleration_g", "frequency_hz"])
    t = grid.to_frame(index=False)

    def truth(a, f):
        return 0.4 + acceleration_slope * (a - 5.0) + frequency_slope * (f - 500.0)

    t["sdc"] = truth(t["acceleration_g"], t["frequency_hz"])
    linear = SdcModel.from_table(t, value="sdc", source="linear")
    # beyond one edge each, then two edges whose trends agree (both held values too high or
    # both too low), then a point inside
    points = [(5.0, 2000.0), (5.0, 20.0), (20.0, 500.0), (0.5, 500.0), (0.5, 2000.0),
              (5.0, 500.0)]
    table = pd.concat([equivalent_damper_table(linear, fills_percent=[50],
                                               accelerations_g=[a], frequencies_hz=[f],
                                               vibrated_mass_kg=0.1, clip_to_range=True)
                       for a, f in points], ignore_index=True)
    held_minus_truth = table["sdc [-]"] - truth(table["acceleration [g]"],
                                                 table["frequency [Hz]"])
    said = {"overstated": 1.0, "understated": -1.0, "not held": 0.0}
    # the sign the column states is the sign of (held - truth), row by row
    np.testing.assert_array_equal(np.sign(held_minus_truth.round(12)),
                                  table[SDC_HELD_ERROR_COLUMN].map(said))
    assert table[SDC_HELD_ERROR_COLUMN].iloc[-1] == "not held"
    assert table[SDC_HELD_ERROR_COLUMN].iloc[-2] == ("understated" if frequency_slope > 0
                                                     else "overstated")
    # beyond two edges whose trends disagree (both held above, one rising, one falling) the
    # model does not tell which wins
    (two,) = equivalent_damper_table(linear, fills_percent=[50], accelerations_g=[20],
                                     frequencies_hz=[2000], vibrated_mass_kg=0.1,
                                     clip_to_range=True)[SDC_HELD_ERROR_COLUMN]
    assert two == "unknown"


def test_a_held_sdc_at_a_flat_edge_is_said_unknown():
    # pchip sets the edge slope to 0 where its end formula turns against the first interval
    # (here a slow rise from 1 to 5 g before a steep one to 10 g):
    # the model then says nothing of the SDC beyond the edge
    grid = pd.MultiIndex.from_product([[25.0, 90.0], [1.0, 5.0, 10.0], [50.0, 1000.0]],
                                      names=["fill_percent", "acceleration_g", "frequency_hz"])
    t = grid.to_frame(index=False)
    t["sdc"] = t["acceleration_g"].map({1.0: 0.1, 5.0: 0.11, 10.0: 0.5})
    turning = SdcModel.from_table(t, value="sdc", source="turning")
    assert turning.held_edges(50.0, 0.5, 100.0)[0].slope == 0.0  # pchip's own edge slope
    (said,) = equivalent_damper_table(turning, fills_percent=[50], accelerations_g=[0.5],
                                      frequencies_hz=[100], vibrated_mass_kg=0.1,
                                      clip_to_range=True)[SDC_HELD_ERROR_COLUMN]
    assert said == "unknown"


def test_one_vibrated_mass_for_several_fills_is_refused_as_each_fills_sdc_is_over_its_own(model):
    # vibrated_mass_kg=0.0988 (the 50 % m_c) put every fill's SDC over it: Table 3's 25 % SDC
    # was divided by 0.0605 kg, so c_eq = SDC m_c w / (2 pi) was 1.63 x too high there
    with pytest.raises(ParameterError, match=r"^vibrated_mass_kg 0.0988 kg: one m_c for the "
                                             r"fills 25, 90 %, but each fill's SDC was divided "
                                             r"by that fill's own m_c .*function of fill"):
        equivalent_damper_table(model, fills_percent=[25, 90], accelerations_g=[5],
                                frequencies_hz=[100], vibrated_mass_kg=0.0988)
    # each fill with its own m_c, one table per fill, is the table of m_c as a function of
    # fill: the same products, so equal
    by_fill = equivalent_damper_table(model, fills_percent=[25, 90], accelerations_g=[5],
                                      frequencies_hz=[100],
                                      vibrated_mass_kg=paper_vibrated_mass())
    for fill in (25.0, 90.0):
        (row,) = equivalent_damper_table(model, fills_percent=[fill], accelerations_g=[5],
                                         frequencies_hz=[100],
                                         vibrated_mass_kg=paper_vibrated_mass()(fill)
                                         ).to_dict(orient="records")
        (same,) = by_fill[by_fill["packing ratio [%]"] == fill].to_dict(orient="records")
        assert row == same


def test_damper_rows_resting_on_the_held_hole_are_flagged(model):
    # only the hole's own row (90 %, 1 g, 1000 Hz) was flagged, though (90 %, 1.5 g, 1000 Hz)
    # moves by +0.116 and (90 %, 1 g, 900 Hz) by +0.129 with the hole set to 0.95
    t = equivalent_damper_table(model, fills_percent=[25, 80, 85, 90],
                                accelerations_g=[1, 1.5, 3, 5], frequencies_hz=[50, 900, 1000],
                                vibrated_mass_kg=paper_vibrated_mass())
    key = t.set_index(["packing ratio [%]", "acceleration [g]", "frequency [Hz]"])
    flag = key[SDC_FILLED_COLUMN]
    for point in [(90, 1.5, 1000), (90, 1, 900), (90, 1, 1000), (85, 3, 900)]:
        assert flag[point], point
    # far from it, and a grid point beside it (exact at its own data), are not
    for point in [(25, 5, 50), (25, 1, 1000), (90, 5, 1000), (90, 1, 50)]:
        assert not flag[point], point
    # the flag is the model's own test, and the note names the hole and the rows
    dependence = model.filled_dependence(t["packing ratio [%]"], t["acceleration [g]"],
                                         t["frequency [Hz]"])
    np.testing.assert_array_equal(t[SDC_FILLED_COLUMN], dependence.any)
    note = t.attrs[SDC_FILLED_NOTE]
    assert note.startswith(f"{int(flag.sum())} row(s) rest on the filled grid value at "
                           "1000 Hz, 1 g, 90 % (0.8078")
