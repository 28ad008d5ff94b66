"""The one load case type, its one key, and stores written by pidcore 0.1."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from pidcore.compare import LoadCase as CompareLoadCase
from pidcore.constants import STANDARD_GRAVITY
from pidcore.dem import LoadCase as DemLoadCase
from pidcore.errors import ParameterError
from pidcore.loadcase import LoadCase, LoadCaseError, key_0_1, normalize_material, parse_key

BUNDLED_STORE = Path(__file__).resolve().parents[1] / "data_samples" / "dem_table3.h5"


def test_one_type_everywhere():
    assert DemLoadCase is LoadCase and CompareLoadCase is LoadCase
    assert issubclass(LoadCaseError, ParameterError)


def test_fields_are_si_floats_and_derived_quantities_follow():
    case = LoadCase(500, 5, 50)
    assert case == LoadCase(500.0, 5.0, 50.0, "acrylic", "z")
    assert isinstance(case.frequency_hz, float) and isinstance(case.fill_percent, float)
    assert case.omega_rad_s == pytest.approx(2 * math.pi * 500.0, rel=1e-15)
    assert case.acceleration_m_s2 == pytest.approx(5 * STANDARD_GRAVITY, rel=1e-15)


@pytest.mark.parametrize("case", [
    LoadCase(50.0, 5.0, 50.0), LoadCase(1000.0, 0.5, 62.5, "aluminium", "x"),
    LoadCase(73.25, 2.7, 37.5, direction="y"), LoadCase(123.456, 9.87654, 33.3333)])
def test_key_round_trips_in_both_formats(case):
    assert parse_key(case.key) == case
    assert parse_key(case.key + "_seed12345_cells8_0123456789") == case
    assert parse_key(key_0_1(case) + "_seed1_cells2_abc") == case


def test_key_format_is_the_one_of_store_cli_reports_and_app():
    assert LoadCase(50.0, 5.0, 50.0).key == "f50Hz_a5g_fill50pct_acrylic_z"
    assert key_0_1(LoadCase(50.0, 5.0, 50.0)) == "acrylic_z_f50_a5_fill50"
    record = LoadCase(50.0, 5.0, 50.0).as_record("sidecar")
    assert record["load_case_key"] == "f50Hz_a5g_fill50pct_acrylic_z"


@pytest.mark.parametrize("text", ["", "f50Hz_a5g", "9steel_z_f50_a5_fill50",
                                  "f50Hz_a5g_fill150pct_acrylic_z", "f50Hz_a5g_fill50pct_Steel_z"])
def test_bad_keys_are_refused(text):
    with pytest.raises(LoadCaseError):
        parse_key(text)


@pytest.mark.parametrize("material", ["steel", "tungsten_carbide"])
def test_a_specimen_material_round_trips_through_both_key_formats(material):
    # a specimen may bring its own particle material: the key names it and reads back
    case = LoadCase(500.0, 5.0, 50.0, material, "x")
    assert parse_key(case.key + "_seed1_cells2_0123456789") == case
    assert parse_key(key_0_1(case) + "_seed1_cells2_0123456789") == case


def test_edges_still_check_the_material_vocabulary():
    # sidecars and --material name table materials; a typo is refused there, not carried on
    with pytest.raises(LoadCaseError, match="acryllic"):
        normalize_material("acryllic", "loadcases.csv row 2")
    assert normalize_material("steel", "specimen", known=("acrylic", "steel")) == "steel"


@pytest.mark.parametrize("kwargs", [{"frequency_hz": math.nan}, {"acceleration_g": 0.0},
                                    {"fill_percent": 100.5}, {"frequency_hz": "fast"}])
def test_out_of_range_fields_are_refused(kwargs):
    with pytest.raises(LoadCaseError, match="load case"):
        LoadCase(**{"frequency_hz": 50.0, "acceleration_g": 1.0, "fill_percent": 50.0, **kwargs})


def _store_as_written_by_0_1(source: Path, target: Path) -> None:
    """The bundled grid as pidcore 0.1 stored it: 0.1 keys, the Eq. 10 mass as ``m_c_kg``, no
    specimen provenance (the layout 0.1 wrote; the numbers are the bundled ones)."""
    from pidcore.dem.persist import run_key_0_1
    from pidcore.dem.simulate import DemConfig
    from pidcore.store import Store

    old = Store(source)
    items = []
    for key in old.list_dem_runs()["case_key"]:
        entry = old.get_dem_run(key)
        record = {k: v for k, v in entry.record.items()
                  if not k.startswith("specimen_") and k not in (
                      "fixture_mass_kg", "coupon_cells", "samples_per_cycle",
                      "energy_dissipated_rolling_j")}
        record["m_c_kg"] = record.pop("vibrated_mass_kg")
        parameters = {k: v for k, v in entry.parameters.items()
                      if k.startswith(("case_", "config_"))}
        config = DemConfig(**{k[7:]: (None if v == "" else v) for k, v in parameters.items()
                              if k.startswith("config_")})
        items.append({"case_key": run_key_0_1(parse_key(key), config), "record": record,
                      "arrays": dict(entry.arrays), "parameters": parameters,
                      "units": {k: v for k, v in entry.units.items() if k in record
                                or k in entry.arrays}})
    Store(target).add_dem_runs(items)


@pytest.mark.skipif(not BUNDLED_STORE.is_file(), reason="bundled DEM store not present")
def test_store_written_by_0_1_opens_and_reports_the_same_numbers(tmp_path):
    from pidcore.dem.persist import run_key_0_1
    from pidcore.dem.simulate import DemConfig
    from pidcore.dem.sweep import grid_cases
    from pidcore.model import load_paper_table3
    from pidcore.report import build_report_table
    from pidcore.store import Store

    _store_as_written_by_0_1(BUNDLED_STORE, tmp_path / "v0_1.h5")
    store = Store(tmp_path / "v0_1.h5")
    runs = store.list_dem_runs()
    assert runs["case_key"].str.startswith("acrylic_z_f").all()
    assert len(runs) == 48
    # every 0.1 run name names the load case its record holds
    for _, row in runs.iterrows():
        case = parse_key(row["case_key"])
        assert (case.frequency_hz, case.acceleration_g, case.fill_percent) == (
            row["frequency_hz"], row["acceleration_g"], row["fill_percent"])
    # a sweep over the 0.1 store finds every Table 3 run (nothing re-run or duplicated)
    names = set(runs["case_key"])
    assert {run_key_0_1(c, DemConfig()) for c in grid_cases("table3")} <= names
    # the report shows each run's stored SDC and Eq. 10 mass (0.1's "m_c_kg" column) unchanged
    table = build_report_table(runs, None, load_paper_table3()).set_index("load case")
    for _, row in runs.iterrows():
        shown = table.loc[parse_key(row["case_key"]).key]
        assert shown["SDC DEM (ours) [-]"] == row["sdc"]
        assert shown["SDC DEM stderr [-]"] == row["sdc_stderr"]
    from pidcore.compare.align import dem_cases

    masses = {c.load_case.key: c.vibrated_mass_kg for c in dem_cases(runs)}
    np.testing.assert_array_equal(
        [masses[parse_key(k).key] for k in runs["case_key"]], runs["m_c_kg"].to_numpy(float))


def test_a_whole_number_typed_in_a_field_is_read_as_typed_or_refused():
    # the app's number boxes read "2,5" as 25 and "1e3" as 1 without a word
    from pidcore.loadcase import parse_count

    assert parse_count(" 8 ", name="cells") == 8
    assert parse_count("1e3", name="steady cycles") == 1000  # exactly a whole number
    for typed in ("2,5", "2.5", "", "nan", "inf", "eight"):
        with pytest.raises(ParameterError) as info:
            parse_count(typed, name="cells")
        assert str(info.value) == f"cells: {typed!r} is not a whole number"
    with pytest.raises(ParameterError, match=r"^cells simulated: '65', expected 1 to 64$"):
        parse_count("65", name="cells simulated", minimum=1, maximum=64)
    with pytest.raises(ParameterError, match=r"^seed: '-1', expected at least 0$"):
        parse_count("-1", name="seed")


def test_a_rate_typed_in_a_field_is_a_positive_number_or_none():
    # the sample rate box read "25,6" as 256 Hz without a word
    from pidcore.loadcase import parse_optional_rate

    assert parse_optional_rate(" 25600 ", name="rate [Hz]") == 25600.0
    assert parse_optional_rate("2.56e4", name="rate [Hz]") == 25600.0
    assert [parse_optional_rate(t, name="rate [Hz]") for t in ("", " ", "0", "0.0")] == [None] * 4
    with pytest.raises(ParameterError, match=r"^rate \[Hz\]: '25,6' is not a number$"):
        parse_optional_rate("25,6", name="rate [Hz]")
    for typed in ("-5", "inf", "nan"):
        with pytest.raises(ParameterError, match=re.escape(
                f"rate [Hz]: {typed!r}, expected a positive number (0 or blank: none)")):
            parse_optional_rate(typed, name="rate [Hz]")


def test_a_load_case_gives_its_columns_as_the_alignment_and_the_report_table_name_them():
    # the alignment's rows and the report's table each wrote the five load-case columns and
    # their units: one spelling now (LoadCase.columns), which the report's CSV readers rely on
    from pidcore.compare.align import AlignedCase

    case = LoadCase(500.0, 5.0, 50.0, "steel", "x")
    assert case.columns() == {"frequency [Hz]": 500.0, "acceleration [g]": 5.0,
                              "packing ratio [%]": 50.0, "material": "steel",
                              "direction": "x"}
    row = AlignedCase(case, "no_dem_runs").to_dict()
    assert list(row)[:6] == [*case.columns(), "load case"]
    assert {k: row[k] for k in case.columns()} == case.columns()
