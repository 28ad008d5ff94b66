"""Specimen files: schema, checks with one-line errors, canonical text and hash, overrides."""

from __future__ import annotations

import pytest

from pidcore.dem.contact import ContactLaw
from pidcore.dem.geometry import CellGeometry, cell_capacity
from pidcore.dem.simulate import coupon_mass_kg
from pidcore.errors import ParameterError
from pidcore.specimen import (
    Specimen,
    contact_law,
    load_specimen,
    numeric_fields,
    paper_specimen,
)

PAPER = paper_specimen()


def _edit(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def test_paper_specimen_is_the_papers_coupon_to_the_last_bit():
    # every earlier DEM result used these numbers; the specimen must give the same floats
    assert PAPER.coupon.mass_kg == coupon_mass_kg()
    assert PAPER.cell.count == 441
    assert PAPER.geometry() == CellGeometry()
    for material in ("acrylic", "aluminium"):
        assert contact_law(paper_specimen(material)) == ContactLaw.for_material(material)
    assert PAPER.capacity_per_cell() == cell_capacity(CellGeometry(), 1.25e-3)
    # the paper's coupon with either table material is the specimen of the paper's Table 3
    assert PAPER.is_paper() and paper_specimen("aluminium").is_paper()
    assert not PAPER.with_values({"coupon.fixture_mass_kg": 0.01}).is_paper()


def test_canonical_text_round_trips_and_hash_ignores_layout():
    again = Specimen.from_text(PAPER.to_toml())
    assert again == PAPER and again.hash == PAPER.hash
    # comments, key order and number spelling are not physics: same hash
    text = PAPER.to_toml()
    text = _edit(text, "height_m = 0.0254", "# core height\nheight_m = 25.4e-3")
    assert Specimen.from_text(text).hash == PAPER.hash
    # a changed number is: different hash
    other = PAPER.with_values({"coupon.fixture_mass_kg": 0.1})
    assert other.hash != PAPER.hash
    assert Specimen.from_text(other.to_toml()) == other


def test_with_values_addresses_every_numeric_field_and_checks_the_result():
    paths = numeric_fields(PAPER)
    assert "pairs.particle_wall.static_friction" in paths and "cell.count" in paths
    s = PAPER.with_values({"pairs.particle_wall.static_friction": 0.3,
                           "particles.radius_m": 1.0e-3})
    assert s.pairs.particle_wall.static_friction == 0.3 and s.particles.radius_m == 1.0e-3
    assert PAPER.pairs.particle_wall.static_friction == 0.14  # the original is unchanged
    with pytest.raises(ParameterError, match="unknown specimen field 'pairs.wall.mu'"):
        PAPER.with_values({"pairs.wall.mu": 0.3})
    with pytest.raises(ParameterError, match="static_friction.*below sliding_friction"):
        PAPER.with_values({"pairs.particle_wall.static_friction": 0.1})


@pytest.mark.parametrize(("old", "new", "message"), [
    ("count = 441\n", "", r"\[cell\] count: missing key"),
    ("mass_kg = 0.022153400000000004", "mass_kg = -0.02", r"\[coupon\] mass_kg: expected > 0"),
    ("radius_m = 0.00125", "radius_m = 0.003", r"radius_m: a sphere of radius 3 mm does not fit"),
    ("static_friction = 0.14", "static_friction = 0.1", r"particle_wall\] static_friction"),
    ('material = "acrylic"\nradius_m = 0.00125\ndensity_kg_m3 = 1180.0',
     'material = "unobtainium"\nradius_m = 0.00125',
     r"\[particles\] material: unknown material 'unobtainium' \(not in materials.csv\) and no "
     r"inline density_kg_m3"),
    # the same rule for the cell wall: a key neither inline nor in materials.csv is named
    ('wall_material = "aluminium_wall"\nwall_youngs_modulus_pa = 72000000000.0',
     'wall_material = "unobtainium"',
     r"\[cell\] wall_material: unknown material 'unobtainium' \(not in materials.csv\) and "
     r"no inline wall_youngs_modulus_pa"),
    ("count = 441", "count = 441\ncolour = 3", r"\[cell\] colour: unknown key"),
    ('shape = "hexagonal"', 'shape = "round"', r"\[cell\] shape: expected one of"),
    ("poisson_ratio = 0.402", "poisson_ratio = 0.402\ncount_per_cell = 23",
     r"count_per_cell: 23 particles do not fit the cell \(capacity 22\)"),
    ("count = 441", "count = 44.5", r"\[cell\] count: expected a whole number"),
])
def test_bad_specimen_is_one_line_naming_file_and_key(tmp_path, old, new, message):
    path = tmp_path / "bad.toml"
    path.write_text(_edit(PAPER.to_toml(), old, new))
    with pytest.raises(ParameterError, match=message) as info:
        load_specimen(path)
    text = str(info.value)
    assert "\n" not in text and text.startswith(str(path))


@pytest.mark.parametrize(("old", "said"), [
    # a user writing a specimen from scratch learns from the refusal what the key holds
    ("count = 441\n", "[cell] count: missing key; expected a whole number"),
    ("mass_kg = 0.022153400000000004\n", "[coupon] mass_kg: missing key; expected a number"),
    ('shape = "hexagonal"\n', "[cell] shape: missing key; expected text"),
])
def test_a_missing_key_says_what_to_write(tmp_path, old, said):
    path = tmp_path / "bad.toml"
    path.write_text(_edit(PAPER.to_toml(), old, ""))
    with pytest.raises(ParameterError) as info:
        load_specimen(path)
    assert str(info.value) == f"{path}: {said}"


def test_inline_particle_properties_need_no_table_row():
    text = _edit(PAPER.to_toml(), 'material = "acrylic"', 'material = "steel"')
    text = _edit(text, "density_kg_m3 = 1180.0", "density_kg_m3 = 7850.0")
    steel = Specimen.from_text(text)
    assert steel.particles.material == "steel"
    assert steel.particles.mass_kg == pytest.approx(7850 * 4 / 3 * 3.141592653589793
                                                    * 1.25e-3**3, rel=1e-14)


def test_vibrated_mass_counts_fixture_coupon_and_particles():
    s = PAPER.with_values({"coupon.fixture_mass_kg": 0.5})
    n = 11
    particles = 441 * n * s.particles.mass_kg
    assert s.vibrated_mass_kg(n) == pytest.approx(PAPER.coupon.mass_kg + 0.5 + particles,
                                                  rel=1e-15)
    assert s.vibrated_mass_kg(n, "coupon") == pytest.approx(PAPER.coupon.mass_kg + 0.5)
    assert s.vibrated_mass_kg(n, "particles") == pytest.approx(particles)


def test_a_specimen_file_nested_past_the_stack_is_one_line(tmp_path, capsys):
    """tomllib parses nested arrays recursively: a file of 100 000 '[' was a RecursionError
    traceback (dem run --specimen, the app's upload, a job journal's specimen)."""
    from pidcore.cli import main

    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "[" * 100_000)
    code = main(["dem", "run", "--specimen", str(deep), "--frequency", "500",
                 "--acceleration", "5"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and str(deep) in err, err
    assert "nested too deeply" in err


@pytest.mark.parametrize(("old", "new", "message"), [
    # [cell] header left out: its keys are the top level's, and the error named `shape` (typed
    # right) as unknown, listing only name, description and schema_version
    ("[cell]\n", "", r"top level shape: unknown key; expected one of \['schema_version', "
                     r"'name', 'description'\]; shape belongs in \[cell\]: is that table's "
                     r"header missing or below it\?$"),
    # a coupon key typed under [particles] (header of [coupon] below it)
    ("poisson_ratio = 0.402", "poisson_ratio = 0.402\nfixture_mass_kg = 0.01",
     r"\[particles\] fixture_mass_kg: unknown key; .*; fixture_mass_kg belongs in \[coupon\]"),
    # a contact value in [pairs] itself belongs in both pair tables
    ("[pairs.particle_particle]", "[pairs]\nrestitution = 0.5\n[pairs.particle_particle]",
     r"\[pairs\] restitution: unknown key; .*; restitution belongs in "
     r"\[pairs.particle_particle\] and \[pairs.particle_wall\]"),
])
def test_a_key_of_another_table_names_the_table_it_belongs_in(tmp_path, old, new, message):
    path = tmp_path / "bad.toml"
    path.write_text(_edit(PAPER.to_toml(), old, new))
    with pytest.raises(ParameterError, match=message) as info:
        load_specimen(path)
    assert "\n" not in str(info.value)
    # a key of no table keeps the message it had
    path.write_text(_edit(PAPER.to_toml(), "count = 441", "count = 441\ncolour = 3"))
    with pytest.raises(ParameterError, match=r"colour: unknown key; expected one of \[[^]]*\]$"):
        load_specimen(path)


def test_specimen_check_labels_its_time_step_with_the_load_case_it_is_for(tmp_path, capsys):
    """`specimen check` printed "time step 6.009e-07 s", read as a run's step, though a run at
    500 Hz, 5 g takes 6.8e-07 s: the step is 50 Hz, 10 g's, the Table 3 grid's hardest
    impact. The line now names that load case and that it is the grid's smallest."""
    import json
    from pathlib import Path

    from pidcore.cli import main
    from pidcore.dem.simulate import LoadCase, choose_time_step
    from pidcore.dem.sweep import grid_cases
    from pidcore.specimen import describe

    steel = Path(__file__).resolve().parents[1] / "data_samples" / "specimens" / "steel_6mm.toml"
    for path in (steel, None):
        specimen = load_specimen(path) if path else PAPER
        if path is None:
            path = tmp_path / "paper_coupon.toml"
            path.write_text(PAPER.to_toml())
        law, geometry = contact_law(specimen), specimen.geometry()

        def step(frequency_hz: float, acceleration_g: float, law=law,
                 geometry=geometry) -> float:
            # what a run at that load case takes (time_step "auto", the default k_t model)
            return choose_time_step(LoadCase(frequency_hz, acceleration_g, 50.0), law,
                                    geometry, "auto")

        facts = describe(specimen)
        assert (facts["reference_frequency_hz"], facts["reference_acceleration_g"]) == (50, 10)
        # exact: the same function of the same inputs
        assert facts["time_step_s"] == step(50.0, 10.0)
        assert facts["time_step_s"] == min(step(c.frequency_hz, c.acceleration_g)
                                           for c in grid_cases("table3"))
        # why the label is needed: another load case of the grid runs at another step
        assert step(500.0, 5.0) > 1.1 * facts["time_step_s"]
        assert main(["specimen", "check", str(path)]) == 0
        lines = {line[:16].strip(): line[16:] for line in capsys.readouterr().out.splitlines()}
        assert lines["time step"] == (
            f"{facts['time_step_s']:.4g} s at 50 Hz, 10 g (auto: 1/10 of that contact time), "
            "the smallest of the Table 3 grid; a run takes its own load case's, shortened "
            "to a whole number of steps per output sample (dem run prints that as dt)")
        assert "(50 Hz, 10 g)" in lines["contact time"]
        assert main(["specimen", "check", str(path), "--json"]) == 0
        doc = json.loads(capsys.readouterr().out)
        assert (doc["reference_frequency_hz"], doc["reference_acceleration_g"]) == (50, 10)


@pytest.mark.parametrize(("old", "new", "message"), [
    # a typo of the wall row: the error said 'unknown' and named one inline key, so a user
    # added wall_youngs_modulus_pa, then met wall_poisson_ratio, then the density
    ('wall_material = "aluminium_wall"\nwall_youngs_modulus_pa = 72000000000.0\n'
     'wall_poisson_ratio = 0.33\nwall_density_kg_m3 = 2800.0',
     'wall_material = "aluminum_wall"',
     "[cell] wall_material: unknown material 'aluminum_wall' (not in materials.csv) and no "
     "inline wall_youngs_modulus_pa, wall_poisson_ratio, wall_density_kg_m3; expected a wall "
     "material of materials.csv (aluminium_wall), or those keys inline; did you mean "
     "'aluminium_wall'?"),
    ('material = "acrylic"\nradius_m = 0.00125\ndensity_kg_m3 = 1180.0\n'
     'youngs_modulus_pa = 2840000000.0\npoisson_ratio = 0.402',
     'material = "acrylc"\nradius_m = 0.00125',
     "[particles] material: unknown material 'acrylc' (not in materials.csv) and no inline "
     "density_kg_m3, youngs_modulus_pa, poisson_ratio; expected a particle material of "
     "materials.csv (acrylic, aluminium), or those keys inline; did you mean 'acrylic'?"),
    # a material of one's own, partly inline: every key still missing, no guess
    ('material = "acrylic"\nradius_m = 0.00125\ndensity_kg_m3 = 1180.0',
     'material = "steel"\ndensity_kg_m3 = 7850.0',
     "[particles] material: unknown material 'steel' (not in materials.csv) and no inline "
     "radius_m; expected a particle material of materials.csv (acrylic, aluminium), or those "
     "keys inline"),
])
def test_unknown_material_names_every_missing_key_and_the_closest_table_row(tmp_path, old, new,
                                                                            message):
    path = tmp_path / "typo.toml"
    path.write_text(_edit(PAPER.to_toml(), old, new))
    with pytest.raises(ParameterError) as info:
        load_specimen(path)
    assert str(info.value) == f"{path}: {message}"


def test_a_file_of_ones_own_without_a_fixture_is_named_in_a_note():
    """A fixture left out reads as 0 kg (the same specimen as 0 stated), and specimen check
    said nothing: a forgotten adapter plate changes m_c of Eq. 10, so the DEM's SDC, silently."""
    from pidcore.specimen import describe

    steel = load_specimen("data_samples/specimens/steel_6mm.toml")
    assert steel.coupon.fixture_mass_kg > 0
    assert not [n for n in describe(steel)["notes"] if "fixture_mass_kg" in n]
    text = steel.to_toml()
    left_out = Specimen.from_text(_edit(text, "fixture_mass_kg = 0.015\n", ""))
    stated_zero = Specimen.from_text(_edit(text, "fixture_mass_kg = 0.015", "fixture_mass_kg = 0"))
    assert left_out.hash == stated_zero.hash  # one specimen: the note says both readings
    for specimen in (left_out, stated_zero):
        (note,) = [n for n in describe(specimen)["notes"] if "fixture_mass_kg" in n]
        assert note.startswith("[coupon] fixture_mass_kg is 0 kg (stated, or left out: 0 is its "
                               "default)")
    # the paper's coupon runs without one: no note on the bundled file
    assert not [n for n in describe(PAPER)["notes"] if "fixture_mass_kg" in n]


@pytest.mark.parametrize(("key_line", "hint"), [
    # 2 mm beads, as sold: by their diameter
    ("diameter_m = 2.0e-3", "write radius_m = 0.001 (half the diameter, in m)"),
    ("diameter_mm = 2.5", "write radius_m = 0.00125 (half the diameter, in m)"),
    ('diameter = "2 mm"', "write radius_m, half the diameter, in m"),
])
def test_a_sphere_diameter_key_says_the_file_takes_the_radius(key_line, hint):
    text = _edit(PAPER.to_toml(), "radius_m = 0.00125", key_line)
    with pytest.raises(ParameterError) as info:
        Specimen.from_text(text, source="beads.toml")
    message = str(info.value)
    assert message.startswith(f"beads.toml: [particles] {key_line.split(' ')[0]}: unknown key")
    assert message.endswith(f"; the spheres are given by their radius: {hint}")


def test_with_values_raising_a_sliding_friction_past_the_static_names_the_static_key():
    # the trial script's TRUTH {"pairs.particle_wall.sliding_friction": 0.4} on a file stating
    # no static friction was refused naming a static 0.3 the user never wrote
    text = _edit(PAPER.to_toml(), "static_friction = 0.14\n", "")
    wall_default = Specimen.from_text(text, source="mine.toml")
    assert wall_default.pairs.particle_wall.static_friction == 0.14  # its sliding friction
    with pytest.raises(ParameterError) as info:
        wall_default.with_values({"pairs.particle_wall.sliding_friction": 0.4})
    assert str(info.value) == (
        "mine.toml: [pairs.particle_wall] static_friction: 0.14 is below sliding_friction 0.4; "
        "expected static >= sliding; set pairs.particle_wall.static_friction too (a file "
        "without it holds its sliding friction there)")
    both = wall_default.with_values({"pairs.particle_wall.sliding_friction": 0.4,
                                     "pairs.particle_wall.static_friction": 0.4})
    assert both.pairs.particle_wall.static_friction == 0.4


def test_with_values_names_the_static_key_only_of_the_pair_whose_sliding_friction_was_raised():
    # the hint comes from the refusal's pair, not from its text: a static friction lowered by
    # the user gets no hint (the user wrote it), and raising one pair's sliding friction never
    # sends the user to the other pair's static key
    with pytest.raises(ParameterError) as info:
        PAPER.with_values({"pairs.particle_particle.static_friction": 0.05})
    assert str(info.value).endswith("expected static >= sliding")
    with pytest.raises(ParameterError) as info:
        PAPER.with_values({"pairs.particle_particle.sliding_friction": 0.9,
                           "pairs.particle_wall.sliding_friction": 0.1})
    message = str(info.value)
    assert "[pairs.particle_particle] static_friction" in message
    assert message.endswith("; set pairs.particle_particle.static_friction too (a file without "
                            "it holds its sliding friction there)")
    assert "pairs.particle_wall.static_friction" not in message


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-16-be"])
def test_a_utf16_file_behind_its_byte_order_mark_is_the_same_specimen(tmp_path, encoding):
    # Notepad's "Unicode" (UTF-16 with a byte-order mark) was refused as "not UTF-8 text
    # (byte 0xff on line 1)"; the mark makes it unambiguous, and its text is the file's
    import codecs

    mark = {"utf-16": b"", "utf-16-le": codecs.BOM_UTF16_LE, "utf-16-be": codecs.BOM_UTF16_BE}
    path = tmp_path / "notepad.toml"
    text = PAPER.to_toml().replace("\n", "\r\n")
    path.write_bytes(mark[encoding] + text.encode(encoding))
    assert path.read_bytes()[:2] in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)
    assert load_specimen(path).hash == PAPER.hash
    # without the mark UTF-16 is not read as text: refused in one line, not guessed
    path.write_bytes(text.encode("utf-16-le"))
    with pytest.raises(ParameterError, match=r"^.*notepad\.toml: not valid TOML"):
        load_specimen(path)


@pytest.mark.parametrize(("fill", "count", "shown"), [(25.0, 6, "27.3 % filled"),
                                                      (75.0, 16, "72.7 % filled"),
                                                      (50.0, 11, None)])
def test_a_stated_fill_the_rounded_count_does_not_make_is_shown_beside_its_share(
        tmp_path, capsys, fill, count, shown):
    # 25 % and 75 % of the 22 that fit are 5.5 and 16.5 particles: rounded to the even count
    # (6 and 16, the counts of the bundled grid), two shares the check did not print
    import json

    from pidcore.cli import main
    from pidcore.specimen import describe

    path = tmp_path / "filled.toml"
    path.write_text(PAPER.to_toml().replace("[particles]\n",
                                            f"[particles]\nfill_percent = {fill}\n", 1))
    facts = describe(load_specimen(path))
    assert facts["capacity_per_cell"] == 22 and facts["particles_per_cell"] == count
    assert facts["fill_percent"] == fill
    assert facts["filled_percent"] == pytest.approx(100 * count / 22, rel=1e-15)
    assert main(["specimen", "check", str(path)]) == 0
    particles = next(line for line in capsys.readouterr().out.splitlines()
                     if line.startswith("particles "))
    assert (shown in particles) if shown else ("filled" not in particles), particles
    assert main(["specimen", "check", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["filled_percent"] == facts["filled_percent"]
