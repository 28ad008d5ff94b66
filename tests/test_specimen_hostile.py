"""Hostile specimen files (found by an own-specimen trial of the Predict workflow): each is
one line naming the file and key, exit 2, before anything is simulated or stored."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from pidcore.cli import main
from pidcore.errors import ParameterError
from pidcore.specimen import (
    MAX_COUPON_AREA_M2,
    MAX_SPECIMEN_FILE_BYTES,
    Specimen,
    load_specimen,
)

REPO = Path(__file__).resolve().parents[1]
STEEL = REPO / "data_samples" / "specimens" / "steel_6mm.toml"
TEXT = STEEL.read_text(encoding="utf-8")
#: One 6.35 mm hexagonal cell's cross-section, m^2: (sqrt(3)/2) d^2.
STEEL_CELL_AREA_M2 = 3**0.5 / 2 * 6.35e-3**2


def _edit(old: str, new: str, text: str = TEXT) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def _one_line_exit_2(argv: list[str], capsys) -> str:
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    return err


def test_an_integer_past_pythons_digit_limit_is_one_line_naming_the_file(tmp_path, capsys):
    """tomllib reads a 5000-digit integer into int(), which raised a bare ValueError
    (traceback, exit 1) through `specimen check` and `dem run --specimen`."""
    path = tmp_path / "long.toml"
    path.write_text(_edit("count = 286", "count = " + "9" * 5000))
    with pytest.raises(ParameterError, match=r"long.toml: not a specimen file \(an integer "
                                             r"of more than 4300 digits"):
        Specimen.from_text(path.read_text(), source=str(path))
    err = _one_line_exit_2(["specimen", "check", str(path)], capsys)
    assert str(path) in err and "integer of more than" in err


@pytest.mark.parametrize("count, shown", [
    (10**20, "1e+20"),  # fits a float, but not the store's int64: the run was lost at saving
    ("9" * 4000, "about 10^3999"),  # the float area overflowed: a traceback
])
def test_a_cell_count_of_no_coupon_is_refused_naming_the_key(count, shown):
    message = (rf"s.toml: \[cell\] count: {re.escape(shown)} cells of 34.92 mm\^2 are more than "
               r"100 m\^2 of coupon")
    with pytest.raises(ParameterError, match=message):
        Specimen.from_text(_edit("count = 286", f"count = {count}"), source="s.toml")


def test_the_largest_coupon_area_is_kept_and_one_more_cell_refused():
    # the bound is on the cells' area: the last whole count inside it passes
    largest = int(MAX_COUPON_AREA_M2 / STEEL_CELL_AREA_M2)
    kept = Specimen.from_text(_edit("count = 286", f"count = {largest}"))
    # the library's area is the cell's volume over its height, this one the hexagon's formula:
    # two float routes to one number agree to a few ulps, far inside 1e-12
    assert kept.cells_area_m2() == pytest.approx(largest * STEEL_CELL_AREA_M2, rel=1e-12)
    assert kept.cells_area_m2() <= MAX_COUPON_AREA_M2 < (largest + 1) * STEEL_CELL_AREA_M2
    with pytest.raises(ParameterError, match=r"\[cell\] count"):
        Specimen.from_text(_edit("count = 286", f"count = {largest + 1}"))


def test_dem_run_refuses_a_cell_count_of_no_coupon_before_simulating(tmp_path, capsys):
    path = tmp_path / "many_cells.toml"
    path.write_text(_edit("count = 286", "count = 100000000000000000000"))
    store = tmp_path / "runs.h5"
    err = _one_line_exit_2(["dem", "run", "--specimen", str(path), "--frequency", "400",
                            "--acceleration", "5", "--cells", "1", "--cycles", "10",
                            "--store", str(store), "--no-progress"], capsys)
    assert str(path) in err and "[cell] count" in err
    assert not store.exists()


def _padded(size: int) -> bytes:
    """The steel specimen padded with a comment to exactly ``size`` bytes."""
    head = TEXT.encode() + b"# "
    return head + b"x" * (size - len(head) - 1) + b"\n"


def test_a_file_past_the_size_limit_is_refused_unparsed_and_one_at_it_is_read(tmp_path,
                                                                               capsys):
    """A 4 MB file of one array took 12 s to parse before its key was refused (the app
    parses an upload in its script run), and /dev/zero was read until a MemoryError."""
    at_limit = tmp_path / "at_limit.toml"
    at_limit.write_bytes(_padded(MAX_SPECIMEN_FILE_BYTES))
    assert load_specimen(at_limit).hash == Specimen.from_text(TEXT).hash
    over = tmp_path / "over.toml"
    over.write_bytes(_padded(MAX_SPECIMEN_FILE_BYTES + 1))
    message = rf"over.toml: not a specimen file \(more than {MAX_SPECIMEN_FILE_BYTES // 1024} KiB"
    with pytest.raises(ParameterError, match=message):
        load_specimen(over)
    # an upload's bytes (the app's DEM and Calibrate pages) meet the same limit
    with pytest.raises(ParameterError, match=r"upload.toml: not a specimen file"):
        Specimen.from_bytes(over.read_bytes(), source="upload.toml")
    err = _one_line_exit_2(["specimen", "check", str(over)], capsys)
    assert str(over) in err


@pytest.mark.parametrize("old, key", [
    ("mass_kg = 0.0333", r"\[coupon\] mass_kg"),
    ("fill_percent = 50.0", r"\[particles\] fill_percent"),
    ("restitution = 0.9", r"\[pairs.particle_particle\] restitution"),
])
def test_an_integer_past_the_float_range_is_one_line_naming_the_key(old, key):
    """An integer literal past 1.8e308 for a number key was an OverflowError traceback (a
    float literal there reads as inf and was refused by the range checks)."""
    text = _edit(old, old.split("=")[0] + "= " + "9" * 400)
    with pytest.raises(ParameterError,
                       match=rf"^s.toml: {key}: expected a number, got about 10\^399, beyond "
                             r"any float$"):
        Specimen.from_text(text, source="s.toml")


@pytest.mark.parametrize("old, new, start", [
    # a 100 000-item array for a count: its 300 000 characters were the error line
    ("fill_percent = 50.0", "count_per_cell = [" + "8, " * 100_000 + "]",
     r"\[particles\] count_per_cell: expected a whole number, got an array of 100000 items "
     r"\(\[8, 8, "),
    ("count = 286", "count = 286\n" + "k" * 100_000 + " = 1", r"\[cell\] kkkk"),
    ("[cell]", "[" + "t" * 100_000 + "]\n[cell]", r"\[tttt"),
    ('material = "steel"', 'material = "' + "m" * 100_000 + '"',
     r"\[particles\] material: unknown material 'mmmm"),
    ('shape = "hexagonal"', 'shape = "' + "h" * 100_000 + '"',
     r"\[cell\] shape: expected one of \('hexagonal',\), got 'hhhh"),
    ('name = "steel_6mm"', 'name = "' + "x" * 100_000 + '\\n"',
     r"name: expected a name of printable characters, got 'xxxx"),
])
def test_a_long_value_or_key_is_quoted_by_its_start_and_size(old, new, start):
    text = _edit(old, new)
    if "material = " in new:  # an unknown material: its inline density left out
        text = _edit("density_kg_m3 = 7850.0\n", "", text)
    with pytest.raises(ParameterError) as info:
        Specimen.from_text(text, source="s.toml")
    message = str(info.value)
    assert re.match(rf"s.toml: {start}", message), message[:300]
    # the value's start and its size, not its whole text: a message stays a line to read
    assert len(message) < 400 and "characters)" in message, message[:300]


@pytest.mark.parametrize("old, new, message", [
    ("[pairs.particle_wall]", "[[pairs.particle_wall]]",
     r"\[pairs.particle_wall\]: expected one table \[pairs.particle_wall\], got an array of "
     r"tables \[\[pairs.particle_wall\]\]$"),
    ("[cell]", "[[cell]]",
     r"\[cell\]: expected one table \[cell\], got an array of tables \[\[cell\]\]$"),
    ("[pairs.particle_particle]", "[pairs]\nparticle_particle = 3\n[pairs.unused]",
     r"\[pairs.particle_particle\]: expected one table \[pairs.particle_particle\], got "
     r"pairs.particle_particle = 3$"),
])
def test_a_known_table_written_as_an_array_or_a_value_is_named_as_such(old, new, message):
    """`[[pairs.particle_wall]]` was "[pairs] particle_wall: unknown key; expected one of
    ['tangential_stiffness_model']": a known table called unknown."""
    with pytest.raises(ParameterError, match="^s.toml: " + message):
        Specimen.from_text(_edit(old, new), source="s.toml")


@pytest.mark.parametrize("written, message", [
    # a table material under another spelling: its load cases say "acrylic", the file "Acrylic"
    ("Acrylic", r"'Acrylic' is written 'acrylic' in load cases, file names and stored runs; "
                r"write material = \"acrylic\"$"),
    ("PMMA", r"'PMMA' is written 'acrylic' .*write material = \"acrylic\"$"),
    ("aluminum", r"'aluminum' is written 'aluminium' .*write material = \"aluminium\"$"),
    ("steel ", r"'steel ' is written 'steel' .*write material = \"steel\"$"),
    # no load case can carry a space: file names and run keys are split at '_'
    ("tungsten carbide", r"'tungsten carbide' is not a material name a load case can carry; "
                         r"expected lower-case letters, digits and '_' starting with a letter "
                         r"\(e.g. 'tungsten_carbide'\)$"),
])
def test_a_particle_material_name_no_load_case_carries_is_refused_by_check(
        written, message, tmp_path, capsys):
    """`specimen check` said OK to `material = "Acrylic"` (or "PMMA", "tungsten carbide"),
    and `dem run --specimen` then refused it as "--material: the load case says 'acrylic' but
    specimen ... holds 'Acrylic' particles", naming an option nobody had given."""
    text = _edit('material = "steel"', f'material = "{written}"')
    with pytest.raises(ParameterError, match=r"^s.toml: \[particles\] material: " + message):
        Specimen.from_text(text, source="s.toml")
    path = tmp_path / "own.toml"
    path.write_text(text)
    for argv in (["specimen", "check", str(path)],
                 ["dem", "run", "--specimen", str(path), "--frequency", "200",
                  "--acceleration", "5", "--cells", "1", "--no-progress"]):
        err = _one_line_exit_2(argv, capsys)
        assert "[particles] material" in err and "--material" not in err, err
    # the name as a load case writes it is an own material, simulated with its inline numbers
    own = Specimen.from_text(_edit('material = "steel"', 'material = "tungsten_carbide"'),
                             source="s.toml")
    assert own.particles.material == "tungsten_carbide"


def test_a_fill_fraction_that_holds_a_particle_is_refused_as_typed_for_a_percentage(
        tmp_path, capsys):
    """In a cell of more than 50 particles a fraction typed for a percentage holds one: 0.7
    (70 %) ran 1 of 120 particles per cell without a word, in `specimen check`, `dem run`
    and `analyze` alike. A specimen stating that count confirms such a small fill."""
    import shutil

    from pidcore.dem.simulate import particles_per_cell

    small = _edit("radius_m = 1.0e-3", "radius_m = 0.75e-3")  # 120 spheres fit the cell
    with pytest.raises(ParameterError,
                       match=r"^s.toml: \[particles\] fill_percent: fill 0.7 % is 1 of 120 "
                             r"particles per cell; a fill of at most 1 % reads as a fraction: "
                             r"was 0.7 meant as 70 %\?"):
        Specimen.from_text(_edit("fill_percent = 50.0", "fill_percent = 0.7", small),
                           source="s.toml")
    two = tmp_path / "two.toml"
    two.write_text(_edit("fill_percent = 50.0", "count_per_cell = 2", small))
    store = tmp_path / "runs.h5"
    err = _one_line_exit_2(["dem", "run", "--specimen", str(two), "--frequency", "200",
                            "--acceleration", "5", "--fill", "0.7", "--cells", "1",
                            "--store", str(store), "--no-progress"], capsys)
    assert "--fill 0.7 % is 1 of 120 particles per cell" in err and "70 %?" in err, err
    assert not store.exists()
    export = tmp_path / "run_f500Hz_a1g_fill1.csv"  # fill 1 % of 120: one particle
    shutil.copy(REPO / "data_samples" / "exports" / "synthetic_f500Hz_a1g_fill50_acrylic.csv",
                export)
    err = _one_line_exit_2(["analyze", str(export), "--specimen", str(two), "--no-store",
                            "--no-progress"], capsys)
    assert err.endswith("run_f500Hz_a1g_fill1.csv: fill 1 % is 1 of 120 particles per cell; "
                        "a fill of at most 1 % reads as a fraction: was 1 meant as 100 %? "
                        "(for so few particles, a specimen file stating [particles] "
                        "count_per_cell = 1 confirms it) (fill: file name)"), err
    # a count stated in the file is its own share (0.833 %), and confirms a typed fill of it
    one = Specimen.from_text(_edit("fill_percent = 50.0", "count_per_cell = 1", small),
                             source="one.toml")
    assert one.stated_fill()[0] == pytest.approx(100 / 120, rel=1e-15)
    assert particles_per_cell(0.7, specimen=one, typed=True) == (1, 120)
    # a fill above the fractions' range is a percentage, whatever the count
    assert particles_per_cell(1.5, specimen=one, typed=True) == (2, 120)
