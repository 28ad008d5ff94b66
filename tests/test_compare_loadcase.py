"""Load cases: from file names, sidecar tables and options; the missing-fill error."""

from __future__ import annotations

import math

import pytest

from pidcore.compare import (
    LoadCase,
    LoadCaseError,
    parse_file_name,
    read_sidecar,
    resolve_load_case,
)
from pidcore.errors import PidcoreError


@pytest.mark.parametrize(("name", "expected"), [
    ("coupon3_fill50_acrylic_dirz_500Hz_5g.uff", {"fill_percent": 50.0, "material": "acrylic",
                                                   "direction": "z"}),
    ("run-fill-62.5-ALUMINUM-xdir.csv", {"fill_percent": 62.5, "material": "aluminium",
                                          "direction": "x"}),
    ("shaker_75pct_100Hz.mat", {"fill_percent": 75.0}),
    ("shaker 90percent pmma.txt", {"fill_percent": 90.0, "material": "acrylic"}),
    ("fill25.uff", {"fill_percent": 25.0}),
    # tokens must stand alone: "refill50" and "50pcts" are not fill statements
    ("refill50_50pcts.uff", {}),
    ("acrylics_dirzz.uff", {}),
])
def test_file_name_patterns(name, expected):
    assert parse_file_name(name) == expected


def test_file_name_with_two_different_fills_is_refused():
    with pytest.raises(LoadCaseError, match="several fills"):
        parse_file_name("x_fill50_75pct.uff")


def test_file_name_fill_out_of_range_is_refused():
    with pytest.raises(LoadCaseError, match=r"\(0, 100\]"):
        parse_file_name("x_fill150.uff")


def test_key_is_stable_against_float_noise_and_distinguishes_cases():
    a = LoadCase(500.0, 5.0, 50.0)
    b = LoadCase(500.0 * (1 + 1e-12), 5.0, 50.0)
    assert a.key == b.key == "f500Hz_a5g_fill50pct_acrylic_z"
    assert LoadCase(500.0, 5.0, 50.0, "aluminium").key != a.key
    assert LoadCase(500.0, 5.0, 50.0, direction="x").key != a.key
    assert LoadCase(500.0, 5.0, 50.0, "Aluminum", "X").material == "aluminium"


@pytest.mark.parametrize("kwargs", [
    {"frequency_hz": 0.0}, {"acceleration_g": -1.0}, {"fill_percent": 0.0},
    {"material": "Steel!"}, {"direction": "w"},
])
def test_invalid_load_case_is_refused(kwargs):
    values = {"frequency_hz": 50.0, "acceleration_g": 1.0, "fill_percent": 50.0, **kwargs}
    with pytest.raises(LoadCaseError):
        LoadCase(**values)


def _write_sidecar(folder, text):
    path = folder / "loadcases.csv"
    path.write_text(text, encoding="utf-8")
    return path


def test_sidecar_beside_file_is_found_and_overrides_file_name(tmp_path):
    _write_sidecar(tmp_path, "file,fill_percent,material,direction\n"
                             "a_fill25.uff,75,aluminium,\n"
                             "other.uff,90,,\n")
    stated = resolve_load_case(tmp_path / "a_fill25.uff")
    assert (stated.fill_percent, stated.material, stated.direction) == (75.0, "aluminium", "z")
    assert "fill: loadcases.csv" in stated.origin and "direction: default" in stated.origin


def test_sidecar_without_the_file_leaves_file_name(tmp_path):
    _write_sidecar(tmp_path, "file,fill_percent\nother.uff,90\n")
    assert resolve_load_case(tmp_path / "a_fill25.uff").fill_percent == 25.0


def test_explicit_sidecar_and_options_override(tmp_path):
    side = tmp_path / "cases" / "my.csv"
    side.parent.mkdir()
    side.write_text("file,fill_percent,direction\nrun1.uff,50,x\n", encoding="utf-8")
    stated = resolve_load_case(tmp_path / "run1.uff", sidecar=side)
    assert (stated.fill_percent, stated.direction) == (50.0, "x")
    stated = resolve_load_case(tmp_path / "run1.uff", sidecar=side, fill_percent=90,
                               material="aluminium", direction="y")
    assert (stated.fill_percent, stated.material, stated.direction) == (90.0, "aluminium", "y")
    assert stated.origin == "fill: option; material: option; direction: option"


def test_a_value_overriding_another_statement_is_said_and_an_agreeing_one_is_not(tmp_path):
    # a typo in a sidecar row (75 for 50) moved a test named ..._fill50_acrylic to the 75 %
    # load case, and --fill over the sidecar's value, both said only by "(fill: ...)"
    side = tmp_path / "my.csv"
    side.write_text("file,fill_percent,material,direction\n"
                    "run_fill50_acrylic.uff,75,aluminium,z\n", encoding="utf-8")
    stated = resolve_load_case(tmp_path / "run_fill50_acrylic.uff", sidecar=side)
    assert stated.notes == (
        "run_fill50_acrylic.uff: fill 75 % (my.csv) overrides 50 % of the file name",
        "run_fill50_acrylic.uff: material 'aluminium' (my.csv) overrides 'acrylic' of the "
        "file name")
    stated = resolve_load_case(tmp_path / "run_fill50_acrylic.uff", sidecar=side,
                               fill_percent=60, direction="z")
    assert stated.fill_percent == 60.0
    # the value that stands is said once with each it replaced: the sidecar's 75 % was said
    # as overriding the file name although the option's 60 % stood
    assert stated.notes == (
        "run_fill50_acrylic.uff: fill 60 % (fill_percent=) overrides 75 % of my.csv and 50 % "
        "of the file name",
        "run_fill50_acrylic.uff: material 'aluminium' (my.csv) overrides 'acrylic' of the "
        "file name")
    # an option back to the file name's value overrides only the sidecar's
    assert resolve_load_case(tmp_path / "run_fill50_acrylic.uff", sidecar=side,
                             fill_percent=50).notes[0] == \
        "run_fill50_acrylic.uff: fill 50 % (fill_percent=) overrides 75 % of my.csv"
    assert not any("direction" in n for n in stated.notes)  # z over z: nothing overridden
    # statements that agree (and a default replaced) say nothing
    side.write_text("file,fill_percent,material\nrun_fill50_acrylic.uff,50,acrylic\n",
                    encoding="utf-8")
    assert resolve_load_case(tmp_path / "run_fill50_acrylic.uff", sidecar=side,
                             direction="x").notes == ()


def test_sidecar_errors_name_the_file(tmp_path):
    bad = _write_sidecar(tmp_path, "name,fill\nx.uff,50\n")
    with pytest.raises(LoadCaseError, match=r"loadcases\.csv.*'file'"):
        read_sidecar(bad)
    dup = _write_sidecar(tmp_path, "file,fill_percent\nx.uff,50\nx.uff,75\n")
    with pytest.raises(LoadCaseError, match="more than once"):
        read_sidecar(dup)
    _write_sidecar(tmp_path, "file,fill_percent\nx.uff,half\n")
    with pytest.raises(LoadCaseError, match="not a number"):
        resolve_load_case(tmp_path / "x.uff")
    with pytest.raises(LoadCaseError, match="not found"):
        resolve_load_case(tmp_path / "x.uff", sidecar=tmp_path / "missing.csv")


def test_a_specimens_own_material_is_accepted_and_the_default_with_its_specimen(tmp_path):
    # a steel-sphere specimen's measurement must reach the steel DEM runs: its material is
    # accepted in the sidecar and by --material only with the specimen, and is the default
    _write_sidecar(tmp_path, "file,fill_percent,material\nsteel.uff,40,steel_440c\n"
                             "plain.uff,40,\n")
    with pytest.raises(LoadCaseError, match=r"'steel_440c'.*needs specimen=FILE"):
        resolve_load_case(tmp_path / "steel.uff")
    stated = resolve_load_case(tmp_path / "steel.uff", specimen_material="steel_440c")
    assert stated.material == "steel_440c" and "material: loadcases.csv" in stated.origin
    stated = resolve_load_case(tmp_path / "plain.uff", specimen_material="steel_440c")
    assert stated.material == "steel_440c" and "material: specimen" in stated.origin
    assert stated.load_case(500.0, 1.0).key.endswith("_steel_440c_z")
    assert resolve_load_case(tmp_path / "plain.uff").material == "acrylic"  # no specimen
    with pytest.raises(LoadCaseError, match="specimen=FILE"):
        resolve_load_case(tmp_path / "plain.uff", material="steel_440c")
    # the specimen's material in the file name is read too (it was the sidecar and option
    # only, and the name's "_steel" was passed over)
    stated = resolve_load_case(tmp_path / "run_fill40_steel_440c.uff",
                               specimen_material="steel_440c")
    assert stated.material == "steel_440c" and "material: file name" in stated.origin
    # the table's materials stay accepted beside the specimen's
    stated = resolve_load_case(tmp_path / "plain.uff", material="aluminum",
                               specimen_material="steel_440c")
    assert stated.material == "aluminium" and "material: option" in stated.origin
    with pytest.raises(LoadCaseError, match="steel_440c"):  # the list names the specimen's
        resolve_load_case(tmp_path / "plain.uff", material="brass",
                          specimen_material="steel_440c")


def test_missing_fill_names_file_and_the_three_ways(tmp_path):
    with pytest.raises(LoadCaseError) as info:
        resolve_load_case(tmp_path / "run_500Hz_acrylic.uff")
    message = str(info.value)
    assert isinstance(info.value, PidcoreError) and "\n" not in message
    assert message.startswith("run_500Hz_acrylic.uff:")
    for way in ("_fill50_", "_50pct_", "loadcases.csv", "with fill_percent"):
        assert way in message


def test_stated_load_case_takes_measured_frequency_and_acceleration():
    stated = resolve_load_case("x_fill50.uff", sidecar=None)
    case = stated.load_case(499.7, 5.1)
    assert case == LoadCase(499.7, 5.1, 50.0, "acrylic", "z")


def test_an_own_material_in_the_file_name_is_recognised_when_known():
    # steel (a user's specimen material) is stated by the name once it is a known material;
    # unknown, the name states none and the default is said to be assumed
    from pidcore.app.uploads import assumed_note
    from pidcore.compare.case import stated_case

    def unstated_note(stated):  # what the app says of a row holding the stated values
        return assumed_note(stated, {"fill [%]": stated.fill_percent,
                                     "material": stated.material})

    name = "coupon2_f500Hz_a1g_fill50_steel.csv"
    assert parse_file_name(name, ("acrylic", "aluminium", "steel"))["material"] == "steel"
    assert "material" not in parse_file_name("coupon_steelcase_fill50.csv", ("steel",))
    stated = stated_case(name, materials=("steel",))
    assert (stated.material, unstated_note(stated)) == ("steel", "")
    plain = stated_case("coupon_500Hz.csv")
    assert math.isnan(plain.fill_percent)  # no fill proposed in its place: none stated
    assert assumed_note(plain, {"fill [%]": 50.0, "material": plain.material}) == \
        "material: not stated, acrylic assumed"


def test_the_apps_column_labels_read_as_the_sidecars_columns(tmp_path):
    # a table typed after the app's settings grid ("fill [%]", "vibrometer delay [µs]") was
    # refused by `pidcore analyze` ("unknown column") while the app took it
    from pidcore.compare.loadcase import SETTINGS_COLUMN_LABELS, read_sidecar

    labelled = tmp_path / "labelled.csv"
    labelled.write_text("File;Fill [%];vibrometer delay [µs];Force channel\n"
                        "a.uff;62,5;50;Kraft\n", encoding="utf-8")
    plain = tmp_path / "plain.csv"
    plain.write_text("file;fill_percent;velocity_delay_us;force\na.uff;62,5;50;Kraft\n",
                     encoding="utf-8")
    assert read_sidecar(labelled).equals(read_sidecar(plain))
    assert read_sidecar(labelled).loc[2, "fill_percent"] == "62.5"  # decimal comma read
    # every label names a settings column (one vocabulary)
    from pidcore.compare.loadcase import SETTINGS_COLUMNS

    assert set(SETTINGS_COLUMN_LABELS.values()) == set(SETTINGS_COLUMNS)
    both = tmp_path / "both.csv"
    both.write_text("file,fill [%],fill_percent\na.uff,50,50\n")
    with pytest.raises(PidcoreError, match=r"column 'fill_percent' given more than once "
                                           r"\(as 'fill \[%\]' and 'fill_percent'\)"):
        read_sidecar(both)


def test_a_file_named_in_cp1252_finds_its_row_of_a_cp1252_table(tmp_path):
    # a file named on Windows (Prüfung: byte 0xFC) copied to Linux never matched the row of
    # the cp1252 table saved beside it, and its fill was silently taken from elsewhere
    import os

    from pidcore.compare import resolve_load_case
    from pidcore.compare.loadcase import name_spellings

    try:
        path = tmp_path / os.fsdecode(b"Pr\xfcfung_fill50.uff")
        path.write_bytes(b"")
    except (OSError, UnicodeError):
        pytest.skip("the file system refuses names that are not UTF-8")
    (tmp_path / "loadcases.csv").write_bytes("file,fill_percent\nPrüfung_fill50.uff,75\n"
                                             .encode("cp1252"))
    assert "Prüfung_fill50.uff" in name_spellings(path.name)
    stated = resolve_load_case(path, sidecar=None)
    assert stated.fill_percent == 75.0 and "fill: loadcases.csv" in stated.origin
    # a UTF-8 name is only itself
    assert name_spellings("Prüfung.uff") == ("Prüfung.uff",)


def test_a_utf8_file_name_under_an_ascii_locale_finds_its_row(tmp_path):
    # LC_ALL=C (PYTHONUTF8=0): Python holds the UTF-8 bytes of "é" as two surrogates, so the
    # row of the UTF-8 table was not found, and the file's fill silently taken from elsewhere
    from pidcore.compare import resolve_load_case
    from pidcore.compare.loadcase import name_spellings

    (tmp_path / "essai é_fill50.uff").write_bytes(b"")
    as_held = "essai é_fill50.uff".encode().decode("ascii", "surrogateescape")
    (tmp_path / "loadcases.csv").write_text("file,fill_percent\nessai é_fill50.uff,75\n",
                                            encoding="utf-8")
    assert name_spellings(as_held) == (as_held, "essai é_fill50.uff")
    stated = resolve_load_case(tmp_path / as_held, sidecar=None)
    assert stated.fill_percent == 75.0 and "fill: loadcases.csv" in stated.origin
