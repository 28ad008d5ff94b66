"""Units read from real exports keep their case: an SI prefix's case is its meaning (m = 1e-3,
M = 1e6). A unit parser that lower-cased its input read 'Mm/s' as mm/s and 'MM/S' as mm/s
(a factor of 1e9 chosen without a word). Each test derives an export from a real one (the
bundled sample CSV and UFF, the UFF fixtures of other software) by changing its unit text,
and checks the numbers against the original file or the refusal against what it must say."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import numpy as np
import pytest
import scipy.io
from _cli_runs import analyze_json, refusal

from pidcore.cli import main
from pidcore.constants import STANDARD_GRAVITY
from pidcore.errors import InputFileError
from pidcore.io import read_measurement

ROOT = Path(__file__).resolve().parents[1]
SAMPLE_CSV = ROOT / "data_samples" / "exports" / "synthetic_f500Hz_a1g_fill50_acrylic.csv"
SAMPLE_UFF = ROOT / "data_samples" / "exports" / "synthetic_f50Hz_a5g_fill50_acrylic.uff"
FIXTURES = Path("/work/shared/fixtures/real_exports")
TESTLAB_LIKE_UFF = FIXTURES / "UFFFilesjl_dataset58_time.unv"  # 'Force' in N, abscissa NONE
#: The sample CSV's header: 'Time [s],Force [N],Velocity [m/s],Acceleration [m/s^2]'.
COLUMN = {"Force": 1, "Velocity": 2, "Acceleration": 3}
#: A factor that scales and unscales a column round-trips to ~1e-16; 1e-9 still tells any
#: prefix apart (the smallest slip between two prefixes is x10).
SAME = 1e-9


def derived_csv(path: Path, renamed: dict[str, str], scale: dict[str, float] | None = None,
                drop: tuple[str, ...] = ()) -> Path:
    """The sample export with header cells ``renamed`` (``{"Velocity [m/s]": "Velocity
    [mm/s]"}``), columns multiplied by ``scale`` (a column's numbers in the new unit) and
    columns dropped, written as a spreadsheet would (17 significant digits)."""
    header = SAMPLE_CSV.read_text().splitlines()[0].split(",")
    values = np.loadtxt(SAMPLE_CSV, delimiter=",", skiprows=1)
    for name, factor in (scale or {}).items():
        values[:, COLUMN[name]] *= factor
    keep = [i for i, cell in enumerate(header) if cell.split(" [")[0] not in drop]
    cells = [renamed.get(header[i], header[i]) for i in keep]
    lines = [",".join(cells)] + [",".join(f"{x:.17g}" for x in row) for row in values[:, keep]]
    path.write_text("\n".join(lines) + "\n")
    return path


def same_power(record: dict, truth: dict) -> None:
    for key in ("complex_power_real_w", "complex_power_imag_w", "loss_factor"):
        assert record[key] == pytest.approx(truth[key], rel=SAME), key


@pytest.fixture(scope="module")
def truth(tmp_path_factory) -> dict:
    """A store holding the sample's analysis, which a refused file must leave as it is."""
    folder = tmp_path_factory.mktemp("truth")
    original = shutil.copy(SAMPLE_CSV, folder / "run_fill50.csv")
    store = folder / "pid_store.h5"
    assert main(["analyze", str(original), "--store", str(store), "--no-progress"]) == 0
    return {"store": store}


def sample_record(capsys) -> dict:
    return analyze_json(SAMPLE_CSV, capsys)


# --- velocity: mm/s exact, Mm/s and MM/S refused -------------------------------------------

def test_a_velocity_in_mm_s_is_read_exactly(tmp_path, capsys):
    truth = sample_record(capsys)
    path = derived_csv(tmp_path / "ldv_fill50.csv", {"Velocity [m/s]": "Velocity [mm/s]"},
                       {"Velocity": 1e3})
    velocity = read_measurement(path).channel("Velocity")
    original = np.loadtxt(SAMPLE_CSV, delimiter=",", skiprows=1)[:, COLUMN["Velocity"]]
    np.testing.assert_allclose(velocity.data, original, rtol=SAME)  # 1000 mm/s per m/s
    record = analyze_json(path, capsys)
    same_power(record, truth)
    assert not any("read as" in note for note in record["notes"])  # nothing was corrected


@pytest.mark.parametrize(("unit", "why"), [
    ("Mm/s", "'Mm/s' is 1e+06 m/s, not a plausible velocity unit (expected 1e-09 to 1 m/s per "
             "unit, such as 'mm/s')"),
    ("MM/S", "'MM/S' is ambiguous: unit prefixes are case-sensitive, and it reads as mm/s "
             "(0.001 m/s) or Mm/s (1e+06 m/s)"),
])
def test_a_velocity_in_mega_metre_per_second_is_refused_and_the_store_kept(
        tmp_path, capsys, truth, unit, why):
    # read as mm/s (lower-cased) it was analysed and saved without a word; as Mm/s, every
    # velocity would be 1e9 x that: neither is what a vibrometer gives, so neither is taken
    path = derived_csv(tmp_path / "ldv_fill50.csv", {"Velocity [m/s]": f"Velocity [{unit}]"},
                       {"Velocity": 1e3})
    store = tmp_path / "pid_store.h5"
    shutil.copy(truth["store"], store)
    before = hashlib.sha256(store.read_bytes()).hexdigest()
    err = refusal(["analyze", str(path), "--store", str(store), "--no-progress"], capsys)
    assert err == (f"pidcore analyze: error: {path}: channel 'Velocity' (velocity) has a unit "
                   f"pidcore refuses: {why}; give it with --velocity-unit UNIT (e.g. m/s, mm/s, "
                   "in/s)")
    assert hashlib.sha256(store.read_bytes()).hexdigest() == before
    # the unit confirmed by the option reads the numbers as mm/s
    same_power(analyze_json(path, capsys, "--velocity-unit", "mm/s"), sample_record(capsys))


# --- force: kN exact, KN/kn corrected and said, MN refused ---------------------------------

@pytest.mark.parametrize("unit", ["kN", "KN", "kn"])
def test_a_force_in_kilonewton_reads_as_1000_n_and_a_mis_cased_one_is_said(tmp_path, capsys,
                                                                           unit):
    # 'KN' (K is kelvin, no prefix) and 'kn' (pint: the knot, a ship's speed) have one force
    # reading, kN; taken, the case correction is said
    truth = sample_record(capsys)
    path = derived_csv(tmp_path / "head_fill50.csv", {"Force [N]": f"Force [{unit}]"},
                       {"Force": 1e-3})
    record = analyze_json(path, capsys)
    same_power(record, truth)
    said = [n for n in record["notes"] if "read as kN" in n]
    if unit == "kN":
        assert said == []
    else:
        assert said == [f"channel 'Force': unit {unit!r} read as kN (1000 N): unit symbols are "
                        "case-sensitive, and kN is the one force unit it can be"]


@pytest.mark.parametrize(("unit", "why"), [
    ("MN", "'MN' is 1e+06 N, not a plausible force unit (expected 1e-06 to 10000 N per unit, "
           "such as 'mN')"),
    ("mn", "'mn' is ambiguous: unit prefixes are case-sensitive, and it reads as mN (0.001 N) "
           "or MN (1e+06 N)"),
])
def test_a_force_in_meganewton_is_refused(tmp_path, capsys, unit, why):
    # 'MN' was read as meganewton: an impedance head's 1 N as 1e6 N (energy per cycle x 1e6)
    path = derived_csv(tmp_path / "head_fill50.csv", {"Force [N]": f"Force [{unit}]"},
                       {"Force": 1e3})
    err = refusal(["analyze", str(path), "--no-store", "--no-progress"], capsys)
    assert f"{path}: channel 'Force' (force) has a unit pidcore refuses: {why}; " in err
    # the option says which: mN
    same_power(analyze_json(path, capsys, "--force-unit", "mN"), sample_record(capsys))


# --- acceleration: g, G and m/s^2 ---------------------------------------------------------

@pytest.mark.parametrize(("unit", "scale", "read_as"), [
    ("m/s^2", 1.0, None),
    ("g", 1 / STANDARD_GRAVITY, None),  # standard gravity, never the gram
    ("G", 1 / STANDARD_GRAVITY, "g"),
    ("G's", 1 / STANDARD_GRAVITY, "g's"),
    ("mm/s^2", 1e3, None),
])
def test_an_acceleration_in_g_or_m_s2_is_read_exactly_and_a_capital_g_is_said(
        tmp_path, capsys, unit, scale, read_as):
    # the motion from the acceleration alone (no velocity column): its unit scales the
    # complex power, so the analysis of the file in m/s^2 is the truth
    truth = analyze_json(derived_csv(tmp_path / "acc_fill50.csv", {}, drop=("Velocity",)),
                         capsys)
    path = derived_csv(tmp_path / "acc_unit_fill50.csv",
                       {"Acceleration [m/s^2]": f"Acceleration [{unit}]"},
                       {"Acceleration": scale}, drop=("Velocity",))
    record = analyze_json(path, capsys)
    same_power(record, truth)
    said = [n for n in record["notes"] if " read as " in n]
    assert said == ([] if read_as is None else [
        f"channel 'Acceleration': unit {unit!r} read as {read_as} (9.80665 m/s^2): unit "
        f"symbols are case-sensitive, and {read_as} is the one acceleration unit it can be"])


def test_an_acceleration_in_mega_metre_per_second_squared_is_refused(tmp_path, capsys):
    path = derived_csv(tmp_path / "acc_fill50.csv",
                       {"Acceleration [m/s^2]": "Acceleration [MM/S^2]"}, drop=("Velocity",))
    err = refusal(["analyze", str(path), "--no-store", "--no-progress"], capsys)
    assert ("channel 'Acceleration' (acceleration) has a unit pidcore refuses: 'MM/S^2' is "
            "ambiguous: unit prefixes are case-sensitive, and it reads as mm/s^2 (0.001 m/s^2) "
            "or Mm/s^2 (1e+06 m/s^2)") in err


# --- the unit options are read as case-sensitively as the files ---------------------------

def test_a_unit_option_keeps_its_case(tmp_path, capsys):
    path = derived_csv(tmp_path / "ldv_fill50.csv", {"Velocity [m/s]": "Velocity"},
                       {"Velocity": 1e3})
    err = refusal(["analyze", str(path), "--no-store", "--no-progress", "--velocity-unit",
                   "Mm/s"], capsys)
    assert err == ("pidcore analyze: error: --velocity-unit 'Mm/s': not a velocity unit: 'Mm/s' "
                   "is 1e+06 m/s, not a plausible velocity unit (expected 1e-09 to 1 m/s per "
                   "unit, such as 'mm/s')")
    truth = sample_record(capsys)
    same_power(analyze_json(path, capsys, "--velocity-unit", "mm/s"), truth)
    forces = derived_csv(tmp_path / "head_fill50.csv", {"Force [N]": "Force"}, {"Force": 1e-3})
    record = analyze_json(forces, capsys, "--force-unit", "KN")
    same_power(record, truth)
    assert ("--force-unit: unit 'KN' read as kN (1000 N): unit symbols are case-sensitive, and "
            "kN is the one force unit it can be") in "\n".join(record["notes"])


# --- UFF 58 unit labels ---------------------------------------------------------------------

def _with_label(source: Path, path: Path, old: bytes, new: bytes) -> Path:
    data = source.read_bytes()
    assert data.count(old) >= 1
    path.write_bytes(data.replace(old, new, 1))
    return path


def test_uff_force_labels_keep_their_case(tmp_path):
    # UFFFiles.jl's 'Force'/'N' record: the label is the record's unit
    line = b"         0    0    0    0 Force                N"
    original = read_measurement(TESTLAB_LIKE_UFF).channels[0]
    assert original.quantity == "force" and original.data.max() == pytest.approx(114.8, abs=0.05)
    kilo = read_measurement(_with_label(TESTLAB_LIKE_UFF, tmp_path / "kilo.unv", line + b"\n",
                                        line[:-1] + b"kN\n")).channels[0]
    assert kilo.quantity == "force"
    np.testing.assert_allclose(kilo.data, original.data * 1e3, rtol=1e-15)
    mega = read_measurement(_with_label(TESTLAB_LIKE_UFF, tmp_path / "mega.unv", line + b"\n",
                                        line[:-1] + b"MN\n")).channels[0]
    # refused as a unit (the analysis asks for it), never taken as 1e6 N nor as mN
    assert (mega.quantity, mega.source_unit) == ("unknown", "MN")


def test_uff_abscissa_in_an_ambiguous_time_unit_is_refused(tmp_path):
    # 'MS' is ms or Ms: taken as ms (lower-cased) it set the rate 1000 x that of seconds
    line = b"        17    0    0    0 NONE                 NONE"
    path = _with_label(TESTLAB_LIKE_UFF, tmp_path / "ms.unv", line, line[:-4] + b"MS  ")
    with pytest.raises(InputFileError) as info:
        read_measurement(path)
    assert str(info.value) == (f"{path}: record 1 ('.1.Z-'): abscissa unit 'MS' is ambiguous: "
                               "unit prefixes are case-sensitive, and it reads as ms (0.001 s) or "
                               "Ms (1e+06 s); expected a unit of time such as s or ms (the "
                               "abscissa increment 0.000488281 is in it, so it sets the sample "
                               "rate); give it with time_unit=UNIT")


def test_uff_velocity_label_in_capitals(tmp_path, capsys):
    # the bundled UFF written in capitals, as older writers do: 'M/S' has one reading (noted);
    # 'MM/S' two of velocity, refused
    truth = analyze_json(SAMPLE_UFF, capsys)
    line = b"        11    1    0    0 velocity             m/s "
    capitals = _with_label(SAMPLE_UFF, tmp_path / "caps_fill50.uff", line,
                           line.replace(b"m/s ", b"M/S "))
    record = analyze_json(capitals, capsys)
    same_power(record, truth)
    assert ("channel 'Velocity': unit 'M/S' read as m/s (1 m/s): unit symbols are "
            "case-sensitive, and m/s is the one velocity unit it can be") in record["notes"]
    milli = _with_label(SAMPLE_UFF, tmp_path / "milli_fill50.uff", line,
                        line.replace(b"m/s ", b"MM/S"))
    err = refusal(["analyze", str(milli), "--no-store", "--no-progress"], capsys)
    assert "'MM/S' is ambiguous" in err and "--velocity-unit" in err


# --- MATLAB: a units struct --------------------------------------------------------------

def test_matlab_units_struct_keeps_its_case(tmp_path):
    t = np.arange(64) / 1000.0
    force = np.sin(2 * np.pi * 50 * t)
    path = tmp_path / "run.mat"
    scipy.io.savemat(path, {"time": t, "Force": force, "Velocity": force,
                            "units": {"Force": "KN", "Velocity": "Mm/s"}})
    channels = {c.name: c for c in read_measurement(path).channels}
    np.testing.assert_allclose(channels["Force"].data, force * 1e3, rtol=1e-15)
    assert (channels["Velocity"].quantity, channels["Velocity"].source_unit) == ("unknown",
                                                                                 "Mm/s")


def test_a_testlab_label_keeps_its_case(tmp_path):
    # the label was lowercased before it was read: 'mN' refused as ambiguous ('mn': mN or
    # MN), 'N' read as a corrected 'n' and stored so; only a bare quantity name ignores case
    def read(label):
        path = tmp_path / "label.mat"
        scipy.io.savemat(path, {"Signal": {
            "x_values": {"start_value": 0.0, "increment": 1e-3, "number_of_values": 8},
            "y_values": {"values": np.full(8, 2.0), "quantity": {"label": label}},
            "function_record": {"name": "Ch"}}})
        return read_measurement(path)

    milli = read("mN")
    assert (milli.channels[0].quantity, milli.channels[0].source_unit) == ("force", "mN")
    np.testing.assert_allclose(milli.channels[0].data, 2e-3, rtol=1e-15)
    newton = read("N")
    assert newton.channels[0].source_unit == "N" and "reader_notes" not in newton.metadata
    for name in ("Acceleration", "ACCELERATION", "acceleration"):
        ch = read(name).channels[0]
        assert (ch.quantity, ch.source_unit) == ("acceleration", "m/s^2")
        np.testing.assert_array_equal(ch.data, 2.0)  # SI, as Test.Lab exports


# --- the spellings exporters write, against factors from their definitions -----------------

INCH_M = 0.0254  # exact by definition (1959)
POUND_FORCE_N = 0.45359237 * 9.80665  # avoirdupois pound (exact) x standard gravity


@pytest.mark.parametrize(("label", "quantity", "factor"), [
    ("N", "force", 1.0), ("kN", "force", 1e3), ("mN", "force", 1e-3), ("lbf", "force",
                                                                         POUND_FORCE_N),
    ("m/s", "velocity", 1.0), ("mm/s", "velocity", 1e-3), ("µm/s", "velocity", 1e-6),
    ("μm/s", "velocity", 1e-6), ("um/s", "velocity", 1e-6), ("in/s", "velocity", INCH_M),
    ("m/s²", "acceleration", 1.0), ("m/s2", "acceleration", 1.0), ("g", "acceleration", 9.80665),
    ("mm/s^2", "acceleration", 1e-3), ("s", "time", 1.0), ("ms", "time", 1e-3),
    ("MPa", "pressure", 1e6), ("mV", "voltage", 1e-3), ("MV", "voltage", 1e6),
])
def test_exact_spellings_read_with_their_own_factor(label, quantity, factor):
    from pidcore.units import read_unit

    reading = read_unit(label)
    assert (reading.info.quantity, reading.corrected) == (quantity, False)
    assert reading.info.factor == pytest.approx(factor, rel=1e-12)  # definitions: exact


@pytest.mark.parametrize("label", ["Mm/s", "MM/S", "mm/S", "MN", "Mn", "mn", "Ms", "MS", "mS",
                                   "km/s", "MM/S^2", "Gm/s"])
def test_ambiguous_or_implausible_prefixes_are_refused(label):
    from pidcore.units import lookup_unit, read_unit

    reading = read_unit(label)
    assert lookup_unit(label) is None and reading.problem.startswith(repr(label))


# --- time columns and abscissas -------------------------------------------------------------

def test_a_time_column_in_capitals_is_read_and_said_or_refused(tmp_path):
    # the sample's time in µs headed 'Time [US]': its one reading is µs, said; 'MS' is ms or Ms
    original = read_measurement(SAMPLE_CSV).channels[0]
    lines = SAMPLE_CSV.read_text().splitlines()
    values = np.loadtxt(SAMPLE_CSV, delimiter=",", skiprows=1)
    values[:, 0] *= 1e6
    body = [",".join(f"{x:.17g}" for x in row) for row in values]
    micro = tmp_path / "micro.csv"
    micro.write_text("\n".join([lines[0].replace("Time [s]", "Time [US]"), *body]) + "\n")
    measurement = read_measurement(micro)
    assert measurement.channels[0].sample_rate_hz == original.sample_rate_hz == 25600.0
    assert measurement.metadata["reader_notes"] == [
        f"{micro}: time column 'Time': unit 'US' read as us (1e-06 s): unit symbols are "
        "case-sensitive, and us is the one time unit it can be"]
    milli = tmp_path / "milli.csv"
    milli.write_text("\n".join([lines[0].replace("Time [s]", "Time [MS]"), *body]) + "\n")
    with pytest.raises(InputFileError, match=r"header cell 'Time \[MS\]' not read: 'MS' is "
                                             r"ambiguous: .* ms \(0\.001 s\) or Ms \(1e\+06 s\)"):
        read_measurement(milli)


def test_a_uff_abscissa_label_of_another_case_is_said():
    # the DT9837-A export's abscissa '(Sec)': seconds, and the reading said
    path = FIXTURES / "UFFFilesjl_dataset58_nospacing.uff"
    measurement = read_measurement(path)
    assert measurement.channels[0].sample_rate_hz == pytest.approx(1 / 4.99942e-04, rel=1e-6)
    assert f"{path}: record 1 ('Time Waveform') abscissa unit '(Sec)' read as sec (1 s)" in \
        "\n".join(measurement.metadata["reader_notes"])


# --- the app reads an upload's units as the CLI reads the file's ---------------------------

def test_the_app_refuses_and_says_what_the_cli_does(tmp_path):
    from pidcore.app.uploads import analyze_upload
    from pidcore.measure import AnalysisOptions

    truth = analyze_upload("run_fill50.csv", SAMPLE_CSV.read_bytes(), AnalysisOptions())
    mega = derived_csv(tmp_path / "ldv_fill50.csv", {"Velocity [m/s]": "Velocity [Mm/s]"},
                       {"Velocity": 1e3})
    refused = analyze_upload("ldv_fill50.csv", mega.read_bytes(), AnalysisOptions())
    assert refused.record is None and refused.error.startswith(
        "ldv_fill50.csv: channel 'Velocity' (velocity) has a unit pidcore refuses: 'Mm/s' is "
        "1e+06 m/s, not a plausible velocity unit (expected 1e-09 to 1 m/s per unit, such as "
        "'mm/s'); state it in the export")
    kilo = derived_csv(tmp_path / "head_fill50.csv", {"Force [N]": "Force [KN]"},
                       {"Force": 1e-3})
    taken = analyze_upload("head_fill50.csv", kilo.read_bytes(), AnalysisOptions()).record
    assert taken.analysis.complex_power_w == pytest.approx(truth.record.analysis.complex_power_w,
                                                         rel=SAME)
    assert "channel 'Force': unit 'KN' read as kN (1000 N)" in "\n".join(taken.notes)


def test_a_vibrometer_channel_of_a_refused_unit_is_not_passed_over(tmp_path, capsys):
    # a Testlab point name says no role: its 'Mm/s' left it a channel of no unit, ignored, and
    # the acceleration channel was analysed as the motion instead without a word
    path = derived_csv(tmp_path / "point_fill50.csv",
                       {"Velocity [m/s]": "Point1:+Z [Mm/s]"}, {"Velocity": 1e3})
    err = refusal(["analyze", str(path), "--no-store", "--no-progress"], capsys)
    assert err == (f"pidcore analyze: error: {path}: channel 'Point1:+Z' (velocity) has a unit "
                   "pidcore refuses: 'Mm/s' is 1e+06 m/s, not a plausible velocity unit "
                   "(expected 1e-09 to 1 m/s per unit, such as 'mm/s'); give it with "
                   "--velocity-unit UNIT and name it with --velocity 'Point1:+Z'")
    record = analyze_json(path, capsys, "--velocity", "Point1:+Z", "--velocity-unit", "mm/s")
    same_power(record, sample_record(capsys))


@pytest.mark.parametrize("label", ["Nm", "IN/SEC", "A", "Hz"])
def test_another_case_of_a_unit_only_pint_reads_is_not_guessed(label):
    # 'Nm' (a torque) read as nm (pint's nanometre) with a note was a guess; such a label is
    # of no unit pidcore knows, and the analysis asks for the unit of a channel that has it
    from pidcore.units import read_unit

    reading = read_unit(label)
    assert (reading.info, reading.corrected, reading.problem) == (None, False, "")


def test_an_accelerometer_of_a_refused_unit_is_not_passed_over_for_mass_cancellation(
        tmp_path, capsys):
    # --mass-below-gauge cancels with the drive point's acceleration: one in 'MM/S^2' was
    # ignored ('not needed') and the velocity's derivative used instead, without a word
    path = derived_csv(tmp_path / "point_fill50.csv",
                       {"Acceleration [m/s^2]": "Point2 [MM/S^2]"}, {"Acceleration": 1e3})
    err = refusal(["analyze", str(path), "--no-store", "--no-progress", "--mass-below-gauge",
                   "0.001"], capsys)
    assert (f"{path}: channel 'Point2' (acceleration) has a unit pidcore refuses: 'MM/S^2' is "
            "ambiguous") in err and "--acceleration 'Point2'" in err
    truth = analyze_json(derived_csv(tmp_path / "acc_fill50.csv", {}), capsys,
                         "--mass-below-gauge", "0.001")
    same_power(analyze_json(path, capsys, "--mass-below-gauge", "0.001", "--acceleration",
                            "Point2", "--acceleration-unit", "mm/s^2"), truth)


def test_a_mega_unit_in_the_name_contradicts_a_milli_unit_row(tmp_path, capsys):
    # 'Velocity (Mm/s)' over a unit row 'mm/s': lower-cased, the two agreed and the row was
    # taken; they differ by 1e9, and which is right the option says
    values = np.loadtxt(SAMPLE_CSV, delimiter=",", skiprows=1)
    values[:, COLUMN["Velocity"]] *= 1e3
    path = tmp_path / "rowed_fill50.csv"
    path.write_text("\n".join(["Time,Force,Velocity (Mm/s),Acceleration", "s,N,mm/s,m/s^2",
                               *(",".join(f"{x:.17g}" for x in row) for row in values)]) + "\n")
    assert read_measurement(path).channel("Velocity").source_unit == \
        "Mm/s in the name, mm/s in the unit row"
    err = refusal(["analyze", str(path), "--no-store", "--no-progress"], capsys)
    assert "'Mm/s in the name, mm/s in the unit row'" in err and "--velocity-unit" in err
    same_power(analyze_json(path, capsys, "--velocity-unit", "mm/s"), sample_record(capsys))


# --- the SI brochure's notation: products and negative powers ------------------------------

@pytest.mark.parametrize(("velocity", "v_scale", "acceleration", "a_scale"), [
    ("m·s⁻¹", 1.0, "m·s⁻²", 1.0),
    ("mm·s⁻¹", 1e3, "mm·s⁻²", 1e3),
    ("m s⁻¹", 1.0, "m s⁻²", 1.0),  # the blank as the product, as SI also writes it
    ("mm⋅s⁻¹", 1e3, "m⋅s⁻²", 1.0),  # U+22C5, the dot operator
])
def test_units_written_as_products_of_powers_are_read(tmp_path, capsys, velocity, v_scale,
                                                      acceleration, a_scale):
    # 'm·s⁻¹' (how the SI brochure and ISO 80000 write m/s) was refused as no unit, and
    # 'm s⁻¹' with its blank taken out would read as 'ms^-1', per millisecond
    truth = sample_record(capsys)
    path = derived_csv(tmp_path / "iso_fill50.csv",
                       {"Velocity [m/s]": f"Velocity [{velocity}]",
                        "Acceleration [m/s^2]": f"Acceleration [{acceleration}]"},
                       {"Velocity": v_scale, "Acceleration": a_scale})
    measured = read_measurement(path)
    original = np.loadtxt(SAMPLE_CSV, delimiter=",", skiprows=1)
    for name in ("Velocity", "Acceleration"):  # each in SI as the original file holds it
        np.testing.assert_allclose(measured.channel(name).data, original[:, COLUMN[name]],
                                   rtol=SAME)
    same_power(analyze_json(path, capsys), truth)
