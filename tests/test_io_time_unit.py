"""The unit of a file's time base sets the sample rate and every frequency: a UFF record whose
abscissa is in ms (its increment in ms) read as seconds gave a rate and a drive frequency
1000 x too low without a word. A UFF abscissa label pidcore does not read as a unit of time is
refused, naming the file, the record, the label and what was expected, until ``--time-unit``
states it; a time base that states no unit is taken as seconds and said. Each export is
derived from a bundled or real one (its label or increment changed) and its numbers are
checked against the original's and against the rate computed here from the increment."""

from __future__ import annotations

import hashlib
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
import scipy.io
from _cli_runs import analyze_json, refusal

from pidcore.cli import main
from pidcore.errors import InputFileError, ParameterError
from pidcore.io import read_measurement

ROOT = Path(__file__).resolve().parents[1]
SAMPLE_UFF = ROOT / "data_samples" / "exports" / "synthetic_f50Hz_a5g_fill50_acrylic.uff"
SAMPLE_CSV = ROOT / "data_samples" / "exports" / "synthetic_f500Hz_a1g_fill50_acrylic.csv"
SAMPLE_H5 = ROOT / "data_samples" / "exports" / "synthetic_f1000Hz_a5g_fill50_acrylic.h5"
UNLABELLED_UFF = Path("/work/shared/fixtures/real_exports/UFFFilesjl_dataset58_time.unv")
#: Record 7 of every record of the sample UFF: 38912 samples, increment 3.90625e-05 s.
SECONDS_RECORD_7 = b"  0.00000e+00  3.90625e-05  0.00000e+00"
MILLISECONDS_RECORD_7 = b"  0.00000e+00  3.90625e-02  0.00000e+00"
SECONDS_LABEL = b"Time                 s   "
#: The rate of the derived export, from its increment: 1 / (3.90625e-02 ms * 1e-3 s/ms).
RATE_HZ = 1.0 / (3.90625e-02 * 1e-3)
#: Same samples, same rate: the analysis repeats to the last bits (1e-9 tells any slip apart).
SAME = 1e-9


def uff_in_ms(folder: Path, label: bytes) -> Path:
    """The sample UFF as an exporter writing its abscissa in ms would: every increment x1000
    and the abscissa units label ``label`` (4 characters, the field keeps its width)."""
    raw = SAMPLE_UFF.read_bytes()
    assert raw.count(SECONDS_RECORD_7) == 3 and raw.count(SECONDS_LABEL) == 3
    folder.mkdir(exist_ok=True)
    path = folder / SAMPLE_UFF.name  # the name states the load case, as the original's
    path.write_bytes(raw.replace(SECONDS_RECORD_7, MILLISECONDS_RECORD_7)
                     .replace(SECONDS_LABEL, SECONDS_LABEL[:-4] + label))
    return path


@pytest.fixture(scope="module")
def original(tmp_path_factory) -> dict:
    """The sample UFF's analysis and a store holding it, which a refused file must keep."""
    folder = tmp_path_factory.mktemp("original")
    store = folder / "pid_store.h5"
    assert main(["analyze", str(SAMPLE_UFF), "--store", str(store), "--no-progress"]) == 0
    return {"store": store}


# --- UFF abscissa -------------------------------------------------------------------------

def test_an_abscissa_label_of_no_unit_is_refused_and_the_store_kept(tmp_path, capsys,
                                                                     original):
    # taken as seconds, this export gave 25.6 Hz and a drive at 0.05 Hz, saved without a word
    path = uff_in_ms(tmp_path / "ms", b"msek")
    store = tmp_path / "pid_store.h5"
    shutil.copy(original["store"], store)
    before = hashlib.sha256(store.read_bytes()).hexdigest()
    err = refusal(["analyze", str(path), "--store", str(store), "--no-progress"], capsys)
    assert err == (f"pidcore analyze: error: {path}: record 1 ('Force'): abscissa unit "
                   "'msek' is no unit of time pidcore reads; expected a unit of time such as "
                   "s or ms (the abscissa increment 0.0390625 is in it, so it sets the sample "
                   "rate); give it with --time-unit UNIT")
    assert hashlib.sha256(store.read_bytes()).hexdigest() == before


@pytest.mark.parametrize(("label", "why"), [
    (b"m   ", "abscissa unit 'm' is a displacement unit, not a unit of time"),
    (b"Hz  ", "abscissa unit 'Hz' is no unit of time pidcore reads"),
    (b"MS  ", "abscissa unit 'MS' is ambiguous: unit prefixes are case-sensitive, and it reads "
              "as ms (0.001 s) or Ms (1e+06 s)"),
])
def test_an_abscissa_label_of_another_quantity_is_refused(tmp_path, label, why):
    path = uff_in_ms(tmp_path / "other", label)
    with pytest.raises(InputFileError) as info:
        read_measurement(path)
    assert str(info.value) == (f"{path}: record 1 ('Force'): {why}; expected a unit of time "
                               "such as s or ms (the abscissa increment 0.0390625 is in it, so "
                               "it sets the sample rate); give it with time_unit=UNIT")


def test_time_unit_reads_the_export_in_ms_as_the_original(tmp_path, capsys):
    truth = analyze_json(SAMPLE_UFF, capsys)
    path = uff_in_ms(tmp_path / "ms", b"msek")
    record = analyze_json(path, capsys, "--time-unit", "ms")
    assert record["sample_rate_hz"] == RATE_HZ == truth["sample_rate_hz"]
    # the drive frequency found is the load case's 50 Hz (the file name's), not 0.05 Hz: the
    # synthetic drive sits within 2e-7 of it (the fit's resolution over 76 periods)
    assert record["frequency_hz"] == pytest.approx(50.0, rel=2e-7)
    for key in ("frequency_hz", "loss_factor", "complex_power_real_w", "complex_power_imag_w"):
        assert record[key] == pytest.approx(truth[key], rel=SAME), key
    assert (f"{path}: record 1 ('Force') abscissa unit 'msek' overridden: taken as 'ms' "
            "(--time-unit), sample rate 25600 Hz") in record["notes"]


def test_time_unit_overrides_a_label_that_reads_as_another_time_unit(tmp_path):
    # the label says s but the increments are in ms (an exporter that always writes 's')
    path = uff_in_ms(tmp_path / "s", b"s   ")
    assert read_measurement(path).channels[0].sample_rate_hz == pytest.approx(RATE_HZ / 1e3)
    measurement = read_measurement(path, time_unit="ms")
    assert [c.sample_rate_hz for c in measurement.channels] == [RATE_HZ] * 3
    assert (f"{path}: record 2 ('Velocity') abscissa unit 's' overridden: taken as 'ms' "
            "(time_unit), sample rate 25600 Hz") in measurement.metadata["reader_notes"]


def test_an_abscissa_without_a_label_is_seconds_and_said():
    # UFF unit systems (dataset 164) scale length, force and temperature: time is seconds
    measurement = read_measurement(UNLABELLED_UFF)
    assert measurement.channels[0].sample_rate_hz == 2048.0  # 1 / 4.88281e-04 s, snapped
    assert measurement.metadata["reader_notes"] == [
        f"{UNLABELLED_UFF}: record 1 ('.1.Z-') abscissa states no unit: taken as seconds, the "
        "unit of time of every UFF unit system (sample rate 2048 Hz); if it is not, give it "
        "with time_unit=UNIT"]


def test_a_time_unit_that_is_no_time_is_refused(tmp_path, capsys):
    with pytest.raises(ParameterError) as info:
        read_measurement(SAMPLE_UFF, time_unit="m")
    assert str(info.value) == "time_unit='m': not a unit of time; expected s, ms or us"
    err = refusal(["analyze", str(SAMPLE_UFF), "--no-store", "--no-progress", "--time-unit",
                   "MS"], capsys)
    assert err == ("pidcore analyze: error: --time-unit 'MS': not a unit of time: 'MS' is "
                   "ambiguous: unit prefixes are case-sensitive, and it reads as ms (0.001 s) "
                   "or Ms (1e+06 s); expected s, ms or us")
    # a unit of another quantity is only that: 'furlong' was refused with the plausible range
    # of a displacement unit, which the user never gave
    with pytest.raises(ParameterError) as info:
        read_measurement(SAMPLE_UFF, time_unit="furlong")
    assert str(info.value) == "time_unit='furlong': not a unit of time; expected s, ms or us"
    # an implausible unit of time still says why (an hour per sample)
    with pytest.raises(ParameterError, match=r"'h' is 3600 s, not a plausible time unit"):
        read_measurement(SAMPLE_UFF, time_unit="h")
    # nor in a CSV header's time unit, which said the displacement range too
    csv = tmp_path / "furlong.csv"
    csv.write_text("Time [furlong],Force [N],Velocity [m/s]\n"
                   + "".join(f"{k},{k},{k}\n" for k in range(4)))
    with pytest.raises(InputFileError) as info:
        read_measurement(csv)
    assert "header cell 'Time [furlong]' not read: 'furlong' is no unit of time such as s, " \
        "ms;" in str(info.value) and "displacement" not in str(info.value)


# --- CSV, MATLAB and HDF5 time bases -------------------------------------------------------

def test_a_csv_time_column_without_unit_in_ms(tmp_path):
    lines = SAMPLE_CSV.read_text().splitlines()
    values = np.loadtxt(SAMPLE_CSV, delimiter=",", skiprows=1)
    values[:, 0] *= 1e3
    path = tmp_path / "time_ms.csv"
    path.write_text("\n".join([lines[0].replace("Time [s]", "Time"),
                               *(",".join(f"{x:.17g}" for x in row) for row in values)]) + "\n")
    rate = 1.0 / ((values[1, 0] - values[0, 0]) * 1e-3)  # 25600 Hz from the column itself
    assumed = read_measurement(path)
    assert assumed.channels[0].sample_rate_hz == pytest.approx(rate / 1e3, rel=1e-9)
    assert "has no unit: taken as seconds (sample rate 25.6 Hz)" in \
        assumed.metadata["reader_notes"][-1]
    given = read_measurement(path, time_unit="ms")
    assert given.channels[0].sample_rate_hz == pytest.approx(rate, rel=1e-9) == 25600.0
    assert given.metadata["reader_notes"] == [
        f"{path}: time column 'Time' (no unit) taken as 'ms' (time_unit), sample rate "
        "25600 Hz"]


def test_a_matlab_time_vector_in_ms(tmp_path):
    t = np.arange(2560) / 25600.0 * 1e3  # ms
    path = tmp_path / "vectors.mat"
    scipy.io.savemat(path, {"t": t, "Force": np.sin(2 * np.pi * 0.5 * t),
                            "units": {"Force": "N"}})
    assert read_measurement(path).channels[0].sample_rate_hz == pytest.approx(25.6)
    given = read_measurement(path, time_unit="ms")
    assert given.channels[0].sample_rate_hz == pytest.approx(25600.0, rel=1e-9)
    assert f"{path}: time vector 't' taken as 'ms' (time_unit), sample rate 25600 Hz" in \
        given.metadata["reader_notes"]


def test_a_time_unit_is_not_applied_to_an_hdf5_rate(tmp_path):
    with h5py.File(SAMPLE_H5, "r"):
        pass  # the sample opens as HDF5: its channels state their rate in Hz
    kept = read_measurement(SAMPLE_H5, time_unit="ms")
    assert [c.sample_rate_hz for c in kept.channels] == \
        [c.sample_rate_hz for c in read_measurement(SAMPLE_H5).channels]
    assert kept.metadata["reader_notes"][-1] == (
        f"{SAMPLE_H5}: the time unit 'ms' given (time_unit) is not applied: an HDF5 file "
        "states its channels' rate in Hz; the option sets the unit of UFF abscissas, CSV time "
        "columns and MATLAB time vectors and x_values")


# --- the drive frequency the user expects tells a time base read in the wrong unit ---------

def test_a_hint_above_the_rate_of_a_time_base_in_ms_names_the_time_unit(tmp_path, capsys):
    # the label says s, the increments are ms: the rate read is 25.6 Hz, and the 50 Hz the
    # user expects cannot be in it
    path = uff_in_ms(tmp_path / "s", b"s   ")
    err = refusal(["analyze", str(path), "--no-store", "--no-progress", "--frequency", "50"],
                  capsys)
    assert err == (f"pidcore analyze: error: {path}: --frequency: 50 Hz is not below the Nyquist "
                   "frequency 12.8 Hz of the sample rate 25.6 Hz; correct the hint, or the "
                   "file's time unit (--time-unit UNIT) where its time base is in ms or us "
                   "read as s")
    record = analyze_json(path, capsys, "--frequency", "50", "--time-unit", "ms")
    assert record["frequency_hz"] == pytest.approx(50.0, rel=2e-7)


def test_a_drive_found_1000_x_the_hint_names_the_time_unit(tmp_path, capsys):
    # the label says ms, the increments are seconds: the drive is found at 50 kHz
    raw = SAMPLE_UFF.read_bytes()
    path = tmp_path / SAMPLE_UFF.name
    path.write_bytes(raw.replace(SECONDS_LABEL, SECONDS_LABEL[:-4] + b"ms  "))
    err = refusal(["analyze", str(path), "--no-store", "--no-progress", "--frequency", "50"],
                  capsys)
    assert err.startswith(f"pidcore analyze: error: {path}: ")
    assert err.endswith("the frequency hint 50 Hz more than 5 % off it; it is 1000 x the hint, as "
                        "from a time base read in the wrong unit (s read as ms): give the "
                        "file's time unit (--time-unit UNIT) or correct the hint (--frequency) "
                        "or leave it out")
    assert "50000 Hz" in err  # the line found: 1000 x the 50 Hz drive


# --- MATLAB Test.Lab signals: x_values in the unit their quantity states ------------------

def exported_testlab_mat(path: Path, x_quantity: dict) -> Path:
    """A Test.Lab ``Signal`` struct of the sample CSV's force whose x_values are written in
    ms (increment 3.90625e-02) under ``x_quantity``."""
    force = np.loadtxt(SAMPLE_CSV, delimiter=",", skiprows=1)[:, 1]
    scipy.io.savemat(path, {"Signal": {
        "x_values": {"start_value": 0.0, "increment": 3.90625e-02,
                     "number_of_values": force.size, "quantity": x_quantity},
        "y_values": {"values": force, "quantity": {"label": "Force", "unit": "N"}},
        "function_record": {"name": "Force"}}})
    return path


def test_a_testlab_increment_in_ms_is_read_in_ms(tmp_path):
    path = exported_testlab_mat(tmp_path / "ms.mat", {"label": "Time", "unit": "ms"})
    assert read_measurement(path).channels[0].sample_rate_hz == pytest.approx(RATE_HZ, rel=1e-12)
    seconds = exported_testlab_mat(tmp_path / "s.mat", {"label": "Time"})  # no unit: Test.Lab's s
    assert read_measurement(seconds).channels[0].sample_rate_hz == pytest.approx(RATE_HZ / 1e3)


def test_a_testlab_increment_stored_in_s_and_shown_in_ms_is_read_in_s(tmp_path):
    # Test.Lab stores SI and shows the label's unit (display = SI x factor): an increment in s
    # under 'ms' with factor 1000 read as ms gave a rate 1000 x too high
    force = np.loadtxt(SAMPLE_CSV, delimiter=",", skiprows=1)[:, 1]
    path = tmp_path / "shown_ms.mat"
    scipy.io.savemat(path, {"Signal": {
        "x_values": {"start_value": 0.0, "increment": 1 / RATE_HZ, "number_of_values": force.size,
                     "quantity": {"label": "ms", "unit_transformation": {"factor": 1000.0}}},
        "y_values": {"values": force, "quantity": {"label": "N"}},
        "function_record": {"name": "Force"}}})
    m = read_measurement(path)
    assert m.channels[0].sample_rate_hz == pytest.approx(RATE_HZ, rel=1e-12)
    assert m.metadata["reader_notes"] == [
        f"{path}: Signal(1): x_values: values read in s: the file stores them in SI and shows "
        "them in 'ms' (label; unit_transformation.factor 1000 = 1/0.001)"]


def test_a_testlab_increment_of_no_time_unit_is_refused_until_given(tmp_path):
    path = exported_testlab_mat(tmp_path / "msek.mat", {"label": "Time", "unit": "msek"})
    with pytest.raises(InputFileError) as info:
        read_measurement(path)
    assert str(info.value) == (f"{path}: Signal(1): x_values unit 'msek' is no unit of time "
                               "pidcore reads; expected a unit of time such as s or ms "
                               "(x_values.increment is in it, so it sets the sample rate); give "
                               "it with time_unit=UNIT")
    given = read_measurement(path, time_unit="ms")
    assert given.channels[0].sample_rate_hz == pytest.approx(RATE_HZ, rel=1e-12)
    assert given.metadata["reader_notes"] == [
        f"{path}: Signal(1): x_values unit 'msek' overridden: taken as 'ms' (time_unit)"]


@pytest.mark.parametrize("label", [b"Seconds ", b"SECS    "])
def test_an_abscissa_in_seconds_written_as_a_word_is_read_and_said(tmp_path, label):
    # no prefix in the word, so its case is no factor: read as seconds (it was, by luck, when
    # every label pidcore did not read was taken as seconds), and the reading said
    path = tmp_path / SAMPLE_UFF.name
    path.write_bytes(SAMPLE_UFF.read_bytes().replace(SECONDS_LABEL + b"    ",
                                                     SECONDS_LABEL[:-4] + label + b"    "))
    measurement = read_measurement(path)
    assert [c.sample_rate_hz for c in measurement.channels] == [25600.0] * 3  # 1 / 3.90625e-05
    word = label.decode().strip()
    assert (f"{path}: record 1 ('Force') abscissa unit {word!r} read as "
            f"{word.lower()} (1 s)") in "\n".join(measurement.metadata["reader_notes"])
