"""Specimen values in the wrong unit, fills of no particle, overridden table materials: refused
with one line naming the key, before anything large is computed."""

from __future__ import annotations

from pathlib import Path

import pytest

from pidcore import defaults
from pidcore.cli import main
from pidcore.dem.geometry import (
    MAX_PACKING_GRID_POINTS,
    CellGeometry,
    check_packing_size,
    drop_packing,
)
from pidcore.dem.simulate import DemConfig, particles_per_cell
from pidcore.errors import ParameterError
from pidcore.specimen import (
    PAPER_SPECIMEN_NAME,
    PLAUSIBLE_RANGES,
    Specimen,
    describe,
    load_specimen,
    paper_specimen,
)

REPO = Path(__file__).resolve().parents[1]
STEEL = REPO / "data_samples" / "specimens" / "steel_6mm.toml"
TEXT = STEEL.read_text(encoding="utf-8")
#: The paper coupon's hash: the bundled stores (data_samples/dem_table3.h5, the calibration
#: bundle) hold its runs under keys made from it.
PAPER_SHA256 = "720ba2da93f08f5f54695ae784c140ce3fb7c42c155adce50f224cd8a0e644c9"


def _edit(old: str, new: str, text: str = TEXT) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


@pytest.mark.parametrize("old, new, message", [
    ("inscribed_diameter_m = 6.35e-3", "inscribed_diameter_m = 6.35",
     r"\[cell\] inscribed_diameter_m: 6.35 m: expected metres .*was it mm\?"),
    ("height_m = 12.7e-3", "height_m = 12.7",
     r"\[cell\] height_m: 12.7 m: expected metres \(a core is 0.5 mm-1 m high\); was it mm\?"),
    ("radius_m = 1.0e-3", "radius_m = 1.0", r"\[particles\] radius_m: 1 m: .*was it mm\?"),
    ("radius_m = 1.0e-3", "radius_m = 1.0e-6", r"\[particles\] radius_m: 1e-06 m: expected"),
    ("mass_kg = 0.0333", "mass_kg = 333.0", r"\[coupon\] mass_kg: 333 kg: .*was it g\?"),
    ("mass_kg = 0.0333", "mass_kg = 33.3",  # under 100 kg, but 3340 kg/m^2 of coupon
     r"\[coupon\] mass_kg: 33.3 kg on 286 cells .*was it g, or is \[cell\] count wrong\?"),
    ("fixture_mass_kg = 0.015", "fixture_mass_kg = 1500.0",
     r"\[coupon\] fixture_mass_kg: 1500 kg: .*was it g\?"),
    ("youngs_modulus_pa = 200e9", "youngs_modulus_pa = 200000",
     r"\[particles\] youngs_modulus_pa: 200000 Pa: .*was it MPa or GPa\?"),
    ("density_kg_m3 = 7850.0", "density_kg_m3 = 7.85",
     r"\[particles\] density_kg_m3: 7.85 kg/m\^3: .*was it g/cm\^3\?"),
    ('wall_material = "aluminium_wall"',
     'wall_material = "nomex"\nwall_youngs_modulus_pa = 3.4e3\nwall_poisson_ratio = 0.3\n'
     'wall_density_kg_m3 = 48.0', r"\[cell\] wall_youngs_modulus_pa: 3400 Pa"),
    ("baseline_loss_factor = 0.0", "baseline_loss_factor = 5.0",  # 5 % typed as 5
     r"\[coupon\] baseline_loss_factor: 5: expected a fraction \(the empty coupon's loss "
     r"factor is 0-1, .*\); was it %\?$"),
    # 30 % or a friction angle of 30 degrees typed for the coefficient 0.3
    ("sliding_friction = 0.3\n", "sliding_friction = 30.0\n",
     r"\[pairs.particle_particle\] sliding_friction: 30: expected a coefficient .*was it % or "
     r"an angle\?$"),
    ("static_friction = 0.45", "static_friction = 45.0",
     r"\[pairs.particle_wall\] static_friction: 45: expected a coefficient"),
    ("rolling_friction = 0.01           #", "rolling_friction = 10.0           #",
     r"\[pairs.particle_particle\] rolling_friction: 10: expected a coefficient .*was it %\?$"),
])
def test_a_value_in_the_wrong_unit_is_refused_naming_key_value_unit_and_slip(old, new,
                                                                             message):
    with pytest.raises(ParameterError, match=message):
        Specimen.from_text(_edit(old, new), source="s.toml")


def test_ranges_hold_the_bundled_specimens():
    for path in [*(REPO / "data_samples" / "specimens").glob("*.toml"),
                 REPO / "data_samples" / "paper_calibrated_specimen.toml",
                 REPO / "data_samples" / "paper_calibration" / "calibrated_specimen.toml"]:
        load_specimen(path)
    for material in ("acrylic", "aluminium"):
        paper_specimen(material).with_values({})  # re-parsed like a file
    assert all(r.low < r.high for r in PLAUSIBLE_RANGES.values())


def test_a_cell_of_many_radii_is_refused_before_the_packing_grid_is_allocated():
    # 0.635 m cell, 1 mm spheres: the grid would be 3.3e8 points (2.5 GiB); refused by size
    cell = CellGeometry(inscribed_diameter_m=0.635, height_m=12.7e-3)
    with pytest.raises(ParameterError, match="packing grid of 3.3.e\\+08 points"):
        check_packing_size(cell, 1e-3)
    with pytest.raises(ParameterError, match="packing grid"):
        drop_packing(cell, 1e-3, None)
    with pytest.raises(ParameterError, match=r"\[particles\] radius_m: .*packing grid"):
        Specimen.from_text(_edit("inscribed_diameter_m = 6.35e-3",
                                 "inscribed_diameter_m = 0.635"), source="s.toml")
    # a tall cell of small spheres: few grid points, but millions of spheres to place
    with pytest.raises(ParameterError, match="holds up to .* spheres"):
        check_packing_size(CellGeometry(5e-3, 1.0), 0.1e-3)
    # 0.25 mm shot in a 1/4 inch x 1 inch core: each limit alone admitted it, and its packing
    # ran for an hour; ~8e4 spheres are beyond the DEM's pair history (N^2 per cell)
    with pytest.raises(ParameterError, match=r"at most 2000 per cell"):
        check_packing_size(CellGeometry(6.35e-3, 25.4e-3), 0.125e-3)
    # a wide flat cell: a few hundred spheres, but 1.9e6 candidate points each scans (2.1 mm
    # high: a 2 mm core holds no 1 mm sphere beside the packing's gap, refused before this)
    with pytest.raises(ParameterError, match="too fine to pack"):
        check_packing_size(CellGeometry(50e-3, 2.1e-3), 1e-3)
    # the limits still admit a cell 25 radii across (the paper's is 3.8)
    check_packing_size(CellGeometry(25e-3, 5e-3), 1e-3)
    assert MAX_PACKING_GRID_POINTS <= 2_000_000


def test_a_baseline_loss_factor_up_to_1_is_kept_and_a_calibration_prior_beyond_refused():
    from pidcore.calibrate.parameters import build_specs

    # 1 is the bound itself (a lossy viscoelastic layer near its glass transition); 0.05 the
    # top of calibrate's default prior
    for value in (0.05, 1.0):
        spec = Specimen.from_text(_edit("baseline_loss_factor = 0.0",
                                        f"baseline_loss_factor = {value}"))
        assert spec.coupon.baseline_loss_factor == value
    # a calibration writes its fit to the calibrated specimen, which would refuse it: the
    # prior is refused before any DEM run
    with pytest.raises(ParameterError, match=r"^priors=baseline_loss_factor=0:2: "
                                             r"baseline_loss_factor=2 is outside .*was it %\?"):
        build_specs(["baseline_loss_factor"], ["baseline_loss_factor=0:2"])
    assert build_specs(["baseline_loss_factor"], ["baseline_loss_factor=0:1"])[0].high == 1.0


def test_a_particle_material_row_is_refused_as_the_wall_naming_the_wall_materials(tmp_path,
                                                                                   capsys):
    # "aluminium" is the particles' alloy (E 70 GPa): as a wall it silently gave another k_n
    # than "aluminium_wall" (72 GPa); the reverse was already refused
    bad = tmp_path / "wall.toml"
    bad.write_text(_edit('wall_material = "aluminium_wall"', 'wall_material = "aluminium"'),
                   encoding="utf-8")
    assert main(["specimen", "check", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and (
        f"{bad}: [cell] wall_material: material 'aluminium' is a particle material in "
        "materials.csv, expected a wall material (aluminium_wall), or another name with "
        "inline properties") in err
    with pytest.raises(ParameterError, match=r"\[particles\] material: material "
                                             r"'aluminium_wall' is a wall material in "
                                             r"materials.csv, expected a particle material "
                                             r"\(acrylic, aluminium\)"):
        Specimen.from_text(_edit('material = "steel"', 'material = "aluminium_wall"'))


def test_unit_slips_are_one_line_and_exit_2_in_the_cli(tmp_path, capsys):
    for old, new in (("inscribed_diameter_m = 6.35e-3", "inscribed_diameter_m = 6.35"),
                     ("inscribed_diameter_m = 6.35e-3", "inscribed_diameter_m = 0.635")):
        bad = tmp_path / "bad.toml"
        bad.write_text(_edit(old, new), encoding="utf-8")
        assert main(["specimen", "check", str(bad)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(bad) in err and "Traceback" not in err
        assert main(["dem", "run", "--specimen", str(bad), "--frequency", "100",
                     "--acceleration", "5", "--no-progress"]) == 2
        assert str(bad) in capsys.readouterr().err


def test_a_fill_of_no_particle_is_refused_by_check_as_by_dem_run():
    text = _edit("fill_percent = 50.0", "fill_percent = 1.0")
    with pytest.raises(ParameterError, match=r"\[particles\] fill_percent: fill 1 % of "
                                             r"(\d+) particles rounds to none"):
        Specimen.from_text(text, source="s.toml")
    steel = load_specimen(STEEL)
    capacity = steel.capacity_per_cell()
    with pytest.raises(ParameterError,
                       match=f"^fill_percent 1 % of {capacity} particles rounds to none"):
        particles_per_cell(1.0, specimen=steel, fill_reference="capacity")
    # the least fill the message names does give one particle
    import re

    said = str(pytest.raises(ParameterError, particles_per_cell, 1.0, specimen=steel,
                             fill_reference="capacity").value)
    least = float(re.search(r">= ([0-9.]+) %", said).group(1))
    assert particles_per_cell(least, specimen=steel, fill_reference="capacity")[0] == 1
    ok = Specimen.from_text(_edit("fill_percent = 50.0", f"fill_percent = {least}"))
    assert describe(ok)["particles_per_cell"] == 1


def test_a_typed_fill_of_no_particle_names_a_fill_that_is_then_accepted(tmp_path):
    # a cell of 600+ particles: "--fill 0.1" said "expected >= 0.09 %", and 0.15 was then
    # refused as a fraction typed for a percentage (at most 1 %); the bound it names now is
    # the one a typed fill must pass
    import re

    from pidcore.specimen import MAX_AMBIGUOUS_FILL_PERCENT, particles_for_fill

    full = 700
    said = str(pytest.raises(ParameterError, particles_for_fill, 0.05, full,
                             typed=True).value)
    assert "count_per_cell" in said
    bound = float(re.search(r"expected > ([0-9.]+) %", said).group(1))
    assert bound == MAX_AMBIGUOUS_FILL_PERCENT
    assert particles_for_fill(bound + 0.01, full, typed=True) >= 1
    with pytest.raises(ParameterError, match="reads as a fraction"):
        particles_for_fill(bound, full, typed=True)
    # a specimen stating its count gave the untyped message first (the count's check)
    # (0.5 mm spheres: a cell of several hundred, whose least fill holding one is < 1 %)
    counted = Specimen.from_text(_edit("fill_percent = 50.0", "count_per_cell = 8",
                                       _edit("radius_m = 1.0e-3", "radius_m = 0.5e-3")))
    assert counted.capacity_per_cell() > 100
    said = str(pytest.raises(ParameterError, particles_per_cell, 0.05, specimen=counted,
                             fill_reference="capacity", typed=True).value)
    assert "rounds to none; expected > 1 %" in said
    # not typed (a count's own share), the least fill holding a particle stays the bound
    said = str(pytest.raises(ParameterError, particles_for_fill, 0.05, full).value)
    least = float(re.search(r">= ([0-9.]+) %", said).group(1))
    assert particles_for_fill(least, full) == 1


def test_a_table_material_with_other_inline_properties_is_kept_and_said():
    # kept (a calibration fits such fields, e.g. --fit particles.youngs_modulus_pa), but the
    # name then claims one material and the numbers another: check and every run say so
    from pidcore.calibrate.runner import specimen_with
    from pidcore.specimen import table_overrides

    acrylic = Specimen.from_text(_edit('material = "steel"', 'material = "acrylic"'))
    assert acrylic.particles.density_kg_m3 == 7850.0  # the numbers are simulated
    notes = describe(acrylic)["notes"]
    assert any(n.startswith("[particles] density_kg_m3 7850 overrides 1180 of table material "
                            "'acrylic'") for n in notes)
    wall = Specimen.from_text(_edit('wall_material = "aluminium_wall"',
                                    'wall_material = "aluminium_wall"\n'
                                    'wall_youngs_modulus_pa = 200e9'))
    assert any(n.startswith("[cell] wall_youngs_modulus_pa 2e+11 overrides")
               for n in table_overrides(wall))
    # the table's own values inline are no override (the paper's file states them)
    same = Specimen.from_text(_edit(
        "density_kg_m3 = 7850.0\nyoungs_modulus_pa = 200e9\npoisson_ratio = 0.29",
        "density_kg_m3 = 1180.0\nyoungs_modulus_pa = 2.84e9\npoisson_ratio = 0.402",
        _edit('material = "steel"', 'material = "acrylic"')))
    assert table_overrides(same) == () and table_overrides(paper_specimen()) == ()
    # a radius other than the table's default is the user's choice, not an override
    assert same.particles.radius_m == 1.0e-3
    # a calibration of a table material's modulus builds its specimen, and says what it did
    fitted = specimen_with(paper_specimen(), {"particles.youngs_modulus_pa": 3.0e9})
    assert [n.split(" overrides")[0] for n in table_overrides(fitted)] == [
        "[particles] youngs_modulus_pa 3e+09"]


def test_hash_covers_name_and_description_and_the_papers_is_unchanged():
    # bundled runs are keyed by this hash: it must not move (so name/description stay in it)
    assert paper_specimen().hash == PAPER_SHA256
    assert paper_specimen().name == PAPER_SPECIMEN_NAME
    steel = load_specimen(STEEL)
    renamed = Specimen.from_text(_edit('description = "', 'description = "edited: '))
    assert renamed.hash != steel.hash  # as README and `specimen check` now say


def test_check_names_pairs_among_the_tables_and_says_what_the_hash_covers(tmp_path, capsys):
    bad = tmp_path / "t.toml"
    bad.write_text(TEXT + "\n[damping]\nfoo = 1\n", encoding="utf-8")
    assert main(["specimen", "check", str(bad)]) == 2
    assert "[particles], [pairs], [pairs.particle_particle]" in capsys.readouterr().err
    assert main(["specimen", "check", str(STEEL)]) == 0
    out = capsys.readouterr().out
    assert ("starts the sha256 of its canonical text (of every value, name and description "
            "included, but [coupon] face_area_m2, which no DEM run simulates; not of the file's "
            "bytes") in out


@pytest.mark.parametrize("cycles", [0, 10_001, 1_000_000_000])
def test_dem_run_cycles_out_of_range_names_the_option(capsys, tmp_path, cycles):
    # 1e9 steady cycles was taken (10^7 s simulated, an ETA read as minutes, until its 128
    # samples per cycle outgrew memory); 0 and the cap are refused naming the flag typed
    store = tmp_path / "s.h5"
    assert main(["dem", "run", "--frequency", "100", "--acceleration", "5", "--fill", "50",
                 "--cycles", str(cycles), "--store", str(store), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert f"--cycles: expected 1 .. {defaults.DEM_MAX_STEADY_CYCLES} cycles, got {cycles}" \
        in err and "steady_cycles" not in err
    assert not store.exists()
    with pytest.raises(ParameterError, match="steady_cycles: expected 1 .. 10000"):
        DemConfig(steady_cycles=cycles)
    assert DemConfig(steady_cycles=defaults.DEM_MAX_STEADY_CYCLES).steady_cycles == 10_000


def test_a_file_not_in_utf8_is_one_line_and_a_byte_order_mark_is_accepted(tmp_path, capsys):
    # a Latin-1 "µ" in the description gave a UnicodeDecodeError traceback (exit 1); a BOM
    # (Windows editors) gave "not valid TOML at line 1, column 1" for a file that looks fine
    latin = tmp_path / "latin1.toml"
    latin.write_bytes(TEXT.replace('description = "', 'description = "\xb5 ').encode("latin-1"))
    assert main(["specimen", "check", str(latin)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not UTF-8 text (byte 0xb5 on line" in err
    bom = tmp_path / "bom.toml"
    bom.write_bytes(b"\xef\xbb\xbf" + TEXT.encode("utf-8"))
    assert load_specimen(bom) == load_specimen(STEEL)


def test_a_refused_value_is_shown_as_given_not_rounded_to_look_valid():
    # 1.0000001 was refused as "baseline_loss_factor: 1: expected a fraction", a message
    # about 1, which is accepted: ":g" keeps 6 digits
    with pytest.raises(ParameterError, match=r"\[coupon\] baseline_loss_factor: 1\.0000001: "
                                             r"expected a fraction"):
        Specimen.from_text(_edit("baseline_loss_factor = 0.0",
                                 "baseline_loss_factor = 1.0000001"))
    # the same in a calibration prior beyond the domain (1 is its bound too)
    from pidcore.calibrate.parameters import build_specs

    with pytest.raises(ParameterError, match=r"baseline_loss_factor=1\.0000001 is outside"):
        build_specs(["baseline_loss_factor"], ["baseline_loss_factor=0:1.0000001"])


def test_as_given_keeps_short_numbers_short_and_long_ones_whole():
    from pidcore.errors import as_given

    assert [as_given(v) for v in (5.0, 0.05, 3400.0, 1e-7)] == ["5", "0.05", "3400", "1e-07"]
    assert as_given(1.0000001) == "1.0000001" and as_given(100.0000001) == "100.0000001"
    assert float(as_given(0.1 + 0.2)) == 0.1 + 0.2  # reads back to the same float


def test_check_help_says_inline_properties_override_a_table_material(tmp_path, capsys):
    """`pidcore specimen check --help` listed "one whose inline properties differ from the
    table's" among the refusals, while such a file is accepted (exit 0) with a note per
    overriding value, as the README says."""
    with pytest.raises(SystemExit):
        main(["specimen", "check", "--help"])
    helptext = " ".join(capsys.readouterr().out.split())
    path = tmp_path / "alu.toml"
    text = STEEL.read_text(encoding="utf-8")
    path.write_text(text.replace('material = "steel"', 'material = "aluminium"'),
                    encoding="utf-8")
    assert main(["specimen", "check", str(path)]) == 0
    assert "overrides 2850 of table material 'aluminium'" in capsys.readouterr().out
    assert "one whose inline properties differ from the table's)" not in helptext
    assert "keeps them" in helptext
