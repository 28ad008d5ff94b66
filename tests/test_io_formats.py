"""Writers and readers: round trips, unit conversion, CSV time bases, MATLAB layouts, HDF5."""

from __future__ import annotations

import hashlib
import re

import h5py
import numpy as np
import pytest
import pyuff
import scipy.io

from pidcore.constants import STANDARD_GRAVITY
from pidcore.errors import InputFileError, ParameterError
from pidcore.io import file_sha256, read_measurement, read_measurements, write_measurement
from pidcore.io.hdf5_layout import write_measurement_group
from pidcore.records import Channel, Measurement

FS = 2560.0  # Hz; a whole number, so UFF's 6-digit interval snaps back exactly


def _measurement(rate: float = FS, n: int = 1280) -> Measurement:
    rng = np.random.default_rng(7)
    t = np.arange(n) / rate
    channels = (
        Channel("Drive point force", "force", 12.5 * np.sin(2 * np.pi * 40 * t)
                + rng.normal(0, 0.1, n), rate, "N"),
        Channel("LDV", "velocity", 3e-3 * np.cos(2 * np.pi * 40 * t), rate, "mm/s"),
        Channel("Acc 1", "acceleration", 9.81 * np.sin(2 * np.pi * 40 * t + 0.3), rate, "g"),
        Channel("Bridge", "unknown", rng.normal(0, 1, n), rate, "V^2"),
    )
    return Measurement("made-up.csv", channels, file_format="csv")


def _assert_same(read: Measurement, written: Measurement, *, rtol: float) -> None:
    assert read.channel_names == written.channel_names
    for r, w in zip(read.channels, written.channels, strict=True):
        assert r.quantity == w.quantity
        assert r.n_samples == w.n_samples
        assert r.sample_rate_hz == w.sample_rate_hz
        assert r.start_time_s == pytest.approx(w.start_time_s, abs=1e-12)
        np.testing.assert_allclose(r.data, w.data, rtol=rtol, atol=rtol * np.max(np.abs(w.data)))


# rtol per format: float64 stores (binary UFF, CSV with %.17g, MAT, HDF5) are exact; ASCII UFF
# writes E20.11, i.e. 12 significant digits (relative rounding <= 5e-12).
@pytest.mark.parametrize(("suffix", "file_format", "binary", "rtol"), [
    (".uff", "uff", False, 1e-11),
    (".uff", "uff", True, 0.0),
    (".csv", "csv", False, 0.0),
    (".mat", "mat", False, 0.0),
    (".h5", "hdf5", False, 0.0),
])
def test_round_trip(tmp_path, suffix, file_format, binary, rtol):
    written = _measurement()
    path = tmp_path / f"record{suffix}"
    write_measurement(written, path, file_format, binary=binary)
    read = read_measurement(path)
    assert read.file_format == file_format
    assert read.source == str(path)
    assert read.sha256 == hashlib.sha256(path.read_bytes()).hexdigest()
    _assert_same(read, written, rtol=rtol)
    # The unknown channel keeps its unit text, so it reads back as the same unknown unit.
    assert read.channel("Bridge").source_unit == "V^2"
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary file left


@pytest.mark.parametrize("size, chunk_bytes", [
    (3 * 7 + 2, 7),  # three whole chunks and part of a fourth
    ((1 << 20) + 1, 1 << 20),  # the default chunk, one byte over
    (0, 7),  # an empty file: the hash of no bytes
])
def test_a_files_sha256_is_hashlibs_of_its_bytes_whatever_its_chunks(tmp_path, size,
                                                                    chunk_bytes):
    # the one file hash of measurements, reports' stores and the out folders' records: read
    # in chunks, a chunk dropped or counted twice gives another digest, which hashlib's of the
    # whole bytes read at once would not equal
    data = np.random.default_rng(3).integers(0, 256, size, dtype=np.uint8).tobytes()
    path = tmp_path / "x.bin"
    path.write_bytes(data)
    assert file_sha256(path, chunk_bytes=chunk_bytes) == hashlib.sha256(data).hexdigest()


def test_uff_binary_flag_writes_58b(tmp_path):
    path = tmp_path / "b.uff"
    write_measurement(_measurement(), path, "uff", binary=True)
    raw = path.read_bytes()
    # Record 1 of a binary set reads "    58b" (pyuff's get_set_formats() misreports bytes).
    assert raw.count(b"\n    58b") + raw.startswith(b"    58b") == 4
    assert read_measurement(path).channels[0].n_samples == 1280


def test_uff_non_integer_rate_within_format_resolution(tmp_path):
    written = _measurement(rate=2000.232)  # not snapped: 0.232 Hz is far above 5e-6 relative
    path = tmp_path / "r.unv"
    write_measurement(written, path)
    rate = read_measurement(path).channels[0].sample_rate_hz
    assert rate == pytest.approx(2000.232, rel=5e-6)  # E13.5 interval: 6 significant digits


# Rates above ~200 kHz, where UFF's six-digit interval (and a time column printed with six
# digits) resolves the rate to more than 1 Hz: the nearest whole Hz of 1/2.44141e-06 s is
# 409 599 Hz, not the 409 600 Hz the instrument ran at.
@pytest.mark.parametrize("rate", [262144.0, 409600.0, 1e6, 1638400.0, 3276800.0, 5.12e6])
def test_high_rates_read_back_exactly_from_six_digit_time_bases(tmp_path, rate):
    from pidcore.io.delimited import read_csv

    written = _measurement(rate=rate, n=4096)
    path = tmp_path / "r.uff"
    write_measurement(written, path)
    assert read_measurement(path).channels[0].sample_rate_hz == rate
    times = np.arange(4096) / rate
    for scale, unit in ((1.0, "s"), (1e3, "ms")):  # in ms: the float round-off of the factor
        csv = tmp_path / f"r_{unit}.csv"
        np.savetxt(csv, np.column_stack([times * scale, np.sin(times)]), fmt=["%.6g", "%.6g"],
                   delimiter=",", header=f"Time [{unit}],Force [N]", comments="")
        assert read_csv(csv).channels[0].sample_rate_hz == rate


def test_drive_line_of_a_uff_export_at_409600_hz(tmp_path):
    from pidcore.measure import analyze_file
    from pidcore.signal.synthetic import synthesize_shaker_record

    rate = 409600.0
    record = synthesize_shaker_record(mass_kg=0.05, acceleration_amplitude_m_s2=49.0,
                                      frequency_hz=1000.0, sample_rate_hz=rate, n_periods=40,
                                      viscous_damping_n_s_m=2.0)
    path = tmp_path / "fast.uff"
    write_measurement(Measurement("fast", (
        Channel("Force", "force", record.force_n, rate, "N"),
        Channel("Velocity", "velocity", record.velocity_m_s, rate, "m/s"))), path)
    result = analyze_file(path)
    # noiseless 40 periods: the estimate is good to ~1e-15; the rate snapped to 409 599 Hz
    # read every frequency 2.4e-6 low (999.99756 Hz)
    assert result.analysis.frequency_hz == pytest.approx(1000.0, rel=1e-9)


def test_uff_refuses_to_write_nan(tmp_path):
    m = _measurement()
    bad = Measurement("x", (Channel("F", "force", np.array([0.0, np.nan, 1.0]), 10.0),))
    with pytest.raises(ParameterError, match="non-finite"):
        write_measurement(bad, tmp_path / "x.uff")
    assert m.channels  # the good one still writes
    write_measurement(m, tmp_path / "ok.uff")


def test_uff_units_from_data_type_code_and_dataset_164(tmp_path):
    """Without a units label, code 12 (acceleration) in a mm-based unit system is scaled."""
    path = tmp_path / "mm.uff"
    n = 64
    data = np.linspace(-500.0, 500.0, n)  # mm/s^2
    uff = pyuff.UFF(str(path))
    uff.write_sets(pyuff.prepare_164(units_code=5, units_description="mm (milli newton)",
                                     temp_mode=1, length=1000.0, force=1000.0, temp=1.0,
                                     temp_offset=273.15), mode="add")
    uff.write_sets(pyuff.prepare_58(binary=0, func_type=1, rsp_node=3, rsp_dir=3,
                                    ref_node=0, ref_dir=0, ordinate_spec_data_type=12,
                                    abscissa_spec_data_type=17, orddenom_spec_data_type=0,
                                    z_axis_spec_data_type=0, data=data,
                                    x=np.arange(n) / 100.0), mode="add")
    (ch,) = read_measurement(path).channels
    assert ch.name == "3+Z"  # no entity name or ID line: node and direction
    assert ch.quantity == "acceleration"
    # Dataset 164: SI = file value / length_factor**1. E20.11 keeps 12 significant digits.
    np.testing.assert_allclose(ch.data, data / 1000.0, rtol=1e-11)


@pytest.mark.parametrize("label,quantity,note", [
    ("lb", "unknown", False),       # a unit no table reads: it was taken as N (x 4.45)
    ("in/s pk", "unknown", False),  # it was taken as m/s (x 39)
    ("NONE", "force", True),        # no unit stated: the code's, in SI, said so
])
def test_uff_label_no_table_reads_is_not_replaced_by_the_code(tmp_path, label, quantity, note):
    path = tmp_path / "label.uff"
    data = np.linspace(-5.0, 5.0, 64)
    pyuff.UFF(str(path)).write_sets(pyuff.prepare_58(
        binary=0, func_type=1, rsp_node=1, rsp_dir=3, ref_node=0, ref_dir=0,
        ordinate_spec_data_type=13, ordinate_axis_units_lab=label, abscissa_spec_data_type=17,
        orddenom_spec_data_type=0, z_axis_spec_data_type=0, data=data,
        x=np.arange(64) / 100.0), mode="add")
    m = read_measurement(path)
    (ch,) = m.channels
    assert ch.quantity == quantity
    np.testing.assert_allclose(ch.data, data, rtol=1e-11)  # the file's numbers, unscaled
    said = [n for n in m.metadata.get("reader_notes", ()) if "has no unit label" in n]
    assert bool(said) == note


def test_csv_unit_conversion_and_delimiters(tmp_path):
    rows = [(0.0, 1.5, 2.0, 1.0), (0.001, 1.6, 3.0, -0.5), (0.002, 1.7, 4.0, 0.25)]
    variants = {
        "comma.csv": ("Time [s],Force (kN),Velocity [mm/s],Acceleration [g]", ",", "."),
        "semicolon.csv": ("Time [s];Force (kN);Velocity [mm/s];Acceleration [g]", ";", ","),
        "tab.txt": ("Time [s]\tForce (kN)\tVelocity [mm/s]\tAcceleration [g]", "\t", "."),
        "blank.txt": ("Time[s]  Force(kN)  Velocity[mm/s]  Acceleration[g]", "  ", "."),
    }
    for name, (header, sep, decimal) in variants.items():
        lines = [header] + [sep.join(repr(v).replace(".", decimal) for v in row)
                            for row in rows]
        path = tmp_path / name
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
        m = read_measurement(path)
        assert m.file_format == "csv", name
        assert m.channel_names == ["Force", "Velocity", "Acceleration"], name
        force, velocity, acceleration = m.channels
        assert force.quantity == "force" and force.source_unit == "kN"
        np.testing.assert_allclose(force.data, [1500.0, 1600.0, 1700.0], rtol=1e-15)
        np.testing.assert_allclose(velocity.data, [2e-3, 3e-3, 4e-3], rtol=1e-15)
        np.testing.assert_allclose(acceleration.data,
                                   np.array([1.0, -0.5, 0.25]) * STANDARD_GRAVITY, rtol=1e-15)
        assert force.sample_rate_hz == 1000.0, name


@pytest.mark.parametrize(("sep", "decimal"), [(",", "."), (";", ",")])
def test_a_spreadsheets_empty_rows_after_the_data_are_left_out_and_said(tmp_path, sep,
                                                                          decimal):
    # Excel writes rows of bare delimiters (",,," or ";;;") below the data; they were refused
    # as "the time column holds non-finite values", naming no row
    written = _measurement()
    path = tmp_path / "excel.csv"
    write_measurement(written, path, "csv")
    body = path.read_text(encoding="utf-8")
    if sep != ",":  # as a spreadsheet of a decimal-comma locale saves it
        body = body.replace(",", ";").replace(".", decimal)
    width = len(written.channels) + 1
    path.write_text(body + (sep * (width - 1) + "\n") * 3, encoding="utf-8")
    read = read_measurement(path)
    # the samples are the written ones: %.17g is exact, a decimal comma read back exactly
    _assert_same(read, written, rtol=0.0)
    assert any("3 row(s) after the last data row hold only delimiters" in note
               for note in read.metadata["reader_notes"])
    # an empty row inside the data is a gap in the record, still refused
    lines = body.splitlines()
    at = len(lines) // 2  # lines[0] is the header: data sample `at` is the empty row
    lines.insert(at, sep * (width - 1))
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(InputFileError, match=f"non-finite values, first at sample {at} of "):
        read_measurement(path)


@pytest.mark.parametrize("cell,name,unit,quantity,scale", [
    # two units in one cell that read differently: the last brackets were taken (kN) for a
    # column of newtons, a silent x1000; now no unit, which the analysis asks for
    ("Force (N) [kN]", "Force", "N in the name, kN in brackets", "unknown", 1.0),
    ("Force (kN) [kN]", "Force", "kN", "force", 1e3),
    # the unit in the name's brackets, a description in the last ones: it was no unit at all
    ("Force [kN] (Drive point)", "Force (Drive point)", "kN", "force", 1e3),
    ("Force (Drive point) [kN]", "Force (Drive point)", "kN", "force", 1e3),
])
def test_csv_header_cell_with_two_brackets(tmp_path, cell, name, unit, quantity, scale):
    path = tmp_path / "two.csv"
    path.write_text(f"Time [s],{cell}\n0,1.5\n0.001,2.5\n0.002,-1\n")
    (ch,) = read_measurement(path).channels
    assert (ch.name, ch.source_unit, ch.quantity) == (name, unit, quantity)
    np.testing.assert_allclose(ch.data, scale * np.array([1.5, 2.5, -1.0]), rtol=1e-15)


def test_csv_sample_rate_given_equals_time_column(tmp_path):
    t = np.arange(200) / 500.0
    force, vel = np.sin(t), np.cos(t)
    with_time = tmp_path / "with_time.csv"
    with_time.write_text("Time [s],F [N],V [m/s]\n" + "".join(
        f"{a:.17g},{b:.17g},{c:.17g}\n" for a, b, c in zip(t, force, vel, strict=True)))
    without = tmp_path / "without.csv"
    without.write_text("F [N],V [m/s]\n" + "".join(
        f"{b:.17g},{c:.17g}\n" for b, c in zip(force, vel, strict=True)))
    a = read_measurement(with_time)
    b = read_measurement(without, sample_rate_hz=500.0)
    _assert_same(b, a, rtol=0.0)
    # --sample-rate overrides a time column, and says so
    c = read_measurement(with_time, sample_rate_hz=400.0)
    assert c.channels[0].sample_rate_hz == 400.0
    assert "time column 'Time' ignored" in c.metadata["reader_notes"][0]
    with pytest.raises(InputFileError, match=r"without\.csv.*\(sample_rate_hz\)"):
        read_measurement(without)


@pytest.mark.parametrize("header", ["Time", "t"])
def test_csv_time_column_without_unit_is_taken_as_seconds_and_says_so(tmp_path, header):
    """A time column without a unit was read as seconds without a word: a column written in
    ms made the drive frequency 0.2 Hz for 200 Hz, the acceleration 0.005 g for 5 g and the
    energy per cycle 1000 x (loss factor and SDC unchanged, so nothing else showed it)."""
    t_ms = np.arange(200) / 25.6  # 25.6 kHz sampling, written in ms
    path = tmp_path / "ms.csv"
    path.write_text(f"{header},F [N]\n" + "".join(f"{x:.17g},1.0\n" for x in t_ms))
    m = read_measurement(path)
    assert m.channels[0].sample_rate_hz == pytest.approx(25.6)  # seconds, as before ...
    (note,) = [n for n in m.metadata["reader_notes"] if "no unit" in n]
    assert f"time column {header!r} has no unit: taken as seconds" in note  # ... and said
    assert "25.6 Hz" in note and "Time [ms]" in note
    path.write_text(f"{header} [ms],F [N]\n" + "".join(f"{x:.17g},1.0\n" for x in t_ms))
    m = read_measurement(path)
    assert m.channels[0].sample_rate_hz == pytest.approx(25600.0)
    assert not any("no unit" in n for n in m.metadata.get("reader_notes", ()))


def test_mat_time_vector_is_taken_as_seconds_and_says_so(tmp_path):
    """The MAT reader's plain layout (a 't' vector beside channel vectors) took the time as
    seconds without a word; a vector in ms gave a 1000 x low frequency. It is said."""
    t_ms = np.arange(200) / 25.6
    path = tmp_path / "plain.mat"
    scipy.io.savemat(path, {"t": t_ms, "F": np.ones(200), "units": np.array(["N"], dtype=object)})
    m = read_measurement(path)
    assert m.channels[0].sample_rate_hz == pytest.approx(25.6)
    assert any("time vector 't' states no unit: taken as seconds (sample rate 25.6 Hz)" in n
               for n in m.metadata["reader_notes"])


def test_csv_uneven_time_column_rejected(tmp_path):
    t = np.arange(100) / 1000.0
    t[50:] += 1e-3  # one dropped sample
    path = tmp_path / "gap.csv"
    path.write_text("Time [s],F [N]\n" + "".join(f"{x:.17g},1.0\n" for x in t))
    with pytest.raises(InputFileError, match=r"gap\.csv.*not evenly spaced"):
        read_measurement(path)


def _time_csv(path, times, digits):
    path.write_text("Time [s],F [N]\n" + "".join(f"{x:.{digits}g},1.0\n" for x in times))
    return path


def test_csv_missing_sample_is_refused_whatever_the_digits_assumed(tmp_path):
    # 20 s at 2048 Hz with one sample missing, printed with 9 digits: the rounding of 5
    # digits was assumed (5e-4 s, a whole interval) and the gap was read as rounding, noted
    # as "printed with about 5 significant digits", at 2047.95 Hz
    t = np.delete(np.arange(20 * 2048) / 2048.0, 30_000)
    with pytest.raises(InputFileError) as exc:
        read_measurement(_time_csv(tmp_path / "gap.csv", t, 9))
    message = str(exc.value)
    assert "not evenly spaced" in message and "interval after sample 29999 is 0.0009766 s" \
        in message and "printed with 9 significant digits" in message
    # the same clock printed with 5 digits (MATLAB csvwrite) is off the grid by rounding: read
    # at its rate, the digits said
    m = read_measurement(_time_csv(tmp_path / "csvwrite.csv", np.arange(20 * 2048) / 2048.0, 5))
    assert m.channels[0].sample_rate_hz == 2048.0
    assert any("time printed with 5 significant digits" in n
               for n in m.metadata["reader_notes"])


def test_mat_time_vector_single_precision_accepted_full_precision_gap_refused(tmp_path):
    t = np.arange(600 * 1000) / 1000.0
    single = tmp_path / "single.mat"
    scipy.io.savemat(single, {"time": t.astype(np.float32), "F": np.ones(t.size)})
    m = read_measurement(single)
    # float32 rounds 600 s to 3e-5 s, 0.03 of an interval: on the grid within its precision
    assert m.channels[0].sample_rate_hz == 1000.0
    assert any("time stored in single precision" in n for n in m.metadata["reader_notes"])
    # k/3000 s is on no decimal grid and not single precision; one sample missing in 60 s was
    # taken for the rounding of 5 printed digits (5e-4 s, 1.5 intervals)
    gap = tmp_path / "gap.mat"
    scipy.io.savemat(gap, {"time": np.delete(np.arange(60 * 3000) / 3000.0, 1000),
                           "F": np.ones(60 * 3000 - 1)})
    with pytest.raises(InputFileError, match=r"gap\.mat.*not evenly spaced.*interval after "
                                             r"sample 999 is 0\.000666667 s; stored to full "
                                             r"precision"):
        read_measurement(gap)


def test_csv_time_rounded_to_printed_digits_is_accepted(tmp_path):
    t = np.arange(5000) / 3000.0  # 1/3000 s does not print exactly
    path = tmp_path / "rounded.csv"
    path.write_text("Time [s],F [N]\n" + "".join(f"{x:.7g},1.0\n" for x in t))
    assert read_measurement(path).channels[0].sample_rate_hz == pytest.approx(3000.0, rel=1e-6)


def _bytes_kept_alive(array: np.ndarray) -> int:
    """Size of the memory ``array`` keeps alive: its own, or that of the array it views."""
    while isinstance(array.base, np.ndarray):
        array = array.base
    return array.nbytes


def test_csv_channels_do_not_keep_the_whole_table_alive(tmp_path):
    # channels in SI units were column views of the (rows x columns) table, which a
    # measurement then kept whole (time and every other column: 7 x the channel here) for as
    # long as `analyze` held its record, one per file given
    n = 2000
    t = np.arange(n) / 1000.0
    path = tmp_path / "wide.csv"
    path.write_text("Time [s],Force [N],Velocity [m/s],A1 [g],A2 [g],A3 [m/s^2],Mic [Pa]\n"
                    + "".join(f"{x:.6f},{np.sin(x)},{np.cos(x)},1,2,3,4\n" for x in t))
    m = read_measurement(path)
    assert [c.n_samples for c in m.channels] == [n] * 6
    for channel in m.channels:
        assert _bytes_kept_alive(channel.data) == n * 8, channel.name
    np.testing.assert_allclose(m.channel("Force").data, np.sin(t), rtol=1e-15)


def test_csv_nan_passes_through_reader(tmp_path):
    path = tmp_path / "nan.csv"
    path.write_text("Time [s],F [N],V [m/s]\n0,1,nan\n0.1,,2\n0.2,3,inf\n")
    m = read_measurement(path)
    assert np.isnan(m.channel("F").data[1]) and np.isnan(m.channel("V").data[0])
    assert np.isinf(m.channel("V").data[2])


def test_mat_simple_layout_with_units_struct_and_cell(tmp_path):
    t = np.arange(300) / 1000.0
    path = tmp_path / "simple.mat"
    scipy.io.savemat(path, {"time": t, "Force": np.sin(t), "Vel": np.cos(t),
                            "units": {"Force": "kN", "Vel": "mm/s"}})
    m = read_measurement(path)
    assert m.channel_names == ["Force", "Vel"] and m.metadata["mat_layout"] == "simple"
    np.testing.assert_allclose(m.channel("Force").data, 1e3 * np.sin(t), rtol=1e-15)
    np.testing.assert_allclose(m.channel("Vel").data, 1e-3 * np.cos(t), rtol=1e-15)
    assert m.channel("Force").sample_rate_hz == 1000.0
    cell = tmp_path / "cell.mat"
    scipy.io.savemat(cell, {"fs": 250.0, "a": np.ones(10), "b": np.zeros(10),
                            "units": np.array(["g", "N"], dtype=object)})
    m = read_measurement(cell)
    assert [c.quantity for c in m.channels] == ["acceleration", "force"]
    assert m.channels[0].sample_rate_hz == 250.0
    np.testing.assert_allclose(m.channels[0].data, STANDARD_GRAVITY)


def test_mat_units_cell_of_another_length_than_the_channel_variables_is_refused(tmp_path):
    # paired by position, a helper vector ('window') taken as a channel shifted the units: the
    # window got 'N', the force 'mm/s', and the refusal blamed a "purely resistive load"
    n = 64
    path = tmp_path / "win.mat"
    scipy.io.savemat(path, {"fs": 5120.0, "window": np.hanning(16), "Force": np.ones(n),
                            "Velocity": np.ones(n), "units": np.array(["N", "mm/s"],
                                                                      dtype=object)})
    with pytest.raises(InputFileError) as info:
        read_measurement(path)
    assert str(info.value) == (
        f"{path}: the cell 'units' holds 2 units for 3 channel variables ('window', 'Force', "
        "'Velocity'); expected one unit per channel variable, in their order, or a struct "
        "'units' naming each channel (units.Force = 'N')")
    # beside a time vector a vector of another length is no channel, and is named: a cell
    # that gives it a unit would pair the rest one off
    timed = tmp_path / "timed.mat"
    scipy.io.savemat(timed, {"t": np.arange(n) / 5120.0, "window": np.hanning(16),
                             "Force": np.ones(n), "Velocity": np.ones(n),
                             "units": np.array(["1", "N", "mm/s"], dtype=object)})
    with pytest.raises(InputFileError, match=r"holds 3 units for 2 channel variables \('Force', "
                                             r"'Velocity'; left out, of another length than "
                                             r"'t': 'window'\)"):
        read_measurement(timed)


def test_mat_lms_testlab_signal_struct(tmp_path):
    n, rate = 400, 1024.0
    values = np.column_stack([np.arange(n, dtype=float), -np.arange(n, dtype=float)])
    signal = {"x_values": {"start_value": 0.5, "increment": 1 / rate, "number_of_values": n},
              "y_values": {"values": values, "quantity": {"label": "Acceleration"}},
              "function_record": {"name": np.array(["P1:+Z", "P2:+Z"], dtype=object)}}
    path = tmp_path / "lms.mat"
    scipy.io.savemat(path, {"Signal": signal})
    m = read_measurement(path)
    assert m.metadata["mat_layout"] == "lms_testlab"
    assert m.channel_names == ["P1:+Z", "P2:+Z"]
    for ch, col in zip(m.channels, values.T, strict=True):
        assert ch.quantity == "acceleration" and ch.sample_rate_hz == rate
        assert ch.start_time_s == 0.5
        np.testing.assert_array_equal(ch.data, col)


def _testlab_signal(name: str, values: np.ndarray, quantity: dict) -> dict:
    return {"x_values": {"start_value": 0.0, "increment": 1 / 1024.0,
                         "number_of_values": values.size},
            "y_values": {"values": values, "quantity": quantity},
            "function_record": {"name": name}}


def _testlab_mat(path, *signals: dict):
    cell = np.empty((1, len(signals)), dtype=object)
    for i, signal in enumerate(signals):
        cell[0, i] = signal
    scipy.io.savemat(path, {"Signal": cell})
    return path


@pytest.mark.parametrize("names", [["Force", "Velocity"], None])
def test_mat_lms_testlab_channels_stored_as_rows_without_a_sample_count_are_channels(
        tmp_path, names):
    """A Signal of 2 x 10240 values and no x_values.number_of_values was read as 10240
    channels of 2 samples (and refused in a 173 kB line): the names' count, else the longer
    axis (samples outnumber channels), says where the channels lie. Read back bit for bit."""
    n, rate = 10240, 5120.0
    rows = np.vstack([np.sin(np.arange(n) / 7.0), np.cos(np.arange(n) / 7.0)])
    signal = {"x_values": {"start_value": 0.0, "increment": 1 / rate},
              "y_values": {"values": rows, "quantity": {"label": "N"}}}
    if names is not None:
        signal["function_record"] = {"name": np.array(names, dtype=object)}
    path = tmp_path / "rows.mat"
    scipy.io.savemat(path, {"Signal": signal})
    m = read_measurement(path)
    assert m.channel_names == (names or ["Signal 1.1", "Signal 1.2"])
    for ch, row in zip(m.channels, rows, strict=True):
        assert ch.n_samples == n and np.array_equal(ch.data, row)


def test_mat_lms_testlab_values_stored_in_si_and_shown_in_g_are_read_in_si_and_said(tmp_path):
    # Test.Lab stores SI and shows the label's unit, display = SI x factor: read as g, the
    # acceleration was 9.8 x too large (49 g for 5 g), silently
    acc = 49.03325 * np.sin(np.arange(64) / 3.0)  # 5 g in m/s^2
    vel = 0.078 * np.cos(np.arange(64) / 3.0)  # m/s
    path = _testlab_mat(tmp_path / "shown.mat",
                        _testlab_signal("Point1:+Z", acc, {"label": "g", "unit_transformation": {
                            "factor": 0.10197, "offset": 0.0, "log_reference": 1.0}}),
                        _testlab_signal("LDV", vel, {"label": "mm/s", "unit_transformation": {
                            "factor": 1000.0, "offset": 0.0}}))
    m = read_measurement(path)
    # the values as stored, bit for bit: the SI unit's factor is exactly 1
    np.testing.assert_array_equal(m.channel("Point1:+Z").data, acc)
    np.testing.assert_array_equal(m.channel("LDV").data, vel)
    assert [(c.quantity, c.source_unit) for c in m.channels] == [("acceleration", "m/s^2"),
                                                                 ("velocity", "m/s")]
    assert m.metadata["reader_notes"] == [
        f"{path}: Signal(1) ('Point1:+Z'): y_values: values read in m/s^2: the file stores them "
        "in SI and shows them in 'g' (label; unit_transformation.factor 0.10197 = 1/9.80665)",
        f"{path}: Signal(2) ('LDV'): y_values: values read in m/s: the file stores them in SI "
        "and shows them in 'mm/s' (label; unit_transformation.factor 1000 = 1/0.001)"]
    # a factor of 1 says the values are in the label's unit, as before
    same = read_measurement(_testlab_mat(tmp_path / "in_g.mat", _testlab_signal(
        "Point1:+Z", acc, {"label": "g", "unit_transformation": {"factor": 1.0}})))
    np.testing.assert_allclose(same.channels[0].data, acc * STANDARD_GRAVITY, rtol=1e-15)
    assert "reader_notes" not in same.metadata


@pytest.mark.parametrize(("quantity", "said", "expected"), [
    ({"label": "g", "unit_transformation": {"factor": 0.5}}, "'g' (label) with "
     "unit_transformation factor 0.5 and offset 0",
     "factor 1 (values in 'g') or factor 0.101972 (values in SI, shown in 'g')"),
    ({"label": "g", "unit_transformation": {"factor": 0.10197, "offset": 1.0}}, "'g' (label) "
     "with unit_transformation factor 0.10197 and offset 1",
     "factor 1 (values in 'g') or factor 0.101972 (values in SI, shown in 'g') and offset 0"),
    # a bare quantity name is its SI unit: no factor but 1 shows it otherwise
    ({"label": "Acceleration", "unit_transformation": {"factor": 0.10197}}, "'m/s^2' (label "
     "'Acceleration') with unit_transformation factor 0.10197 and offset 0",
     "factor 1 (values in 'm/s^2')"),
    ({"label": "N", "unit": "g", "unit_transformation": {"factor": 0.10197}}, "'g' (unit) and "
     "'N' (label) with unit_transformation factor 0.10197 and offset 0",
     "units of one quantity"),
], ids=["factor of neither reading", "offset", "quantity name shown otherwise",
        "units of two quantities"])
def test_mat_lms_testlab_transformation_of_neither_reading_is_refused(tmp_path, quantity, said,
                                                                      expected):
    path = _testlab_mat(tmp_path / "odd.mat", _testlab_signal("Acc", np.ones(16), quantity))
    with pytest.raises(InputFileError) as info:
        read_measurement(path)
    assert str(info.value) == (f"{path}: Signal(1) ('Acc'): y_values: quantity states {said}; "
                               f"expected {expected}")


def test_mat_lms_testlab_temperature_with_an_offset_is_kept_as_read(tmp_path):
    # a unit pidcore does not read is never taken as SI (no role takes it without an option):
    # its offset (degC shown from K) refuses nothing
    temperature = np.full(16, 296.15)
    path = _testlab_mat(tmp_path / "temp.mat", _testlab_signal("Temp", temperature, {
        "label": "degC", "unit_transformation": {"factor": 1.0, "offset": -273.15}}))
    (ch,) = read_measurement(path).channels
    assert (ch.quantity, ch.source_unit) == ("unknown", "degC")
    np.testing.assert_array_equal(ch.data, temperature)


def test_mat_v73_hdf5_simple_layout(tmp_path):
    """A v7.3 file is HDF5 behind a 512-byte MATLAB text header; arrays are column-major."""
    path = tmp_path / "v73.mat"
    t = np.arange(100) / 200.0
    with h5py.File(path, "w", userblock_size=512) as h5:
        for name, vec in {"t": t, "Force": np.cos(t)}.items():
            h5.create_dataset(name, data=vec[None, :]).attrs["MATLAB_class"] = np.bytes_("double")
        units = h5.create_group("units")
        units.attrs["MATLAB_class"] = np.bytes_("struct")
        units.create_dataset("Force", data=np.array([[ord("k")], [ord("N")]], dtype=np.uint16)
                             ).attrs["MATLAB_class"] = np.bytes_("char")
    with open(path, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, HDF5 schema 1.00 .".ljust(128))
    m = read_measurement(path)
    assert m.file_format == "mat"
    (ch,) = m.channels
    assert ch.name == "Force" and ch.sample_rate_hz == 200.0
    np.testing.assert_allclose(ch.data, 1e3 * np.cos(t), rtol=1e-15)


def _hand_made_hdf5(path, velocity_unit, velocity):
    """A measurement file another program wrote in pidcore's layout (h5py, no pidcore)."""
    with h5py.File(path, "w") as h5:
        h5.attrs["pidcore_layout"] = "measurement"
        channels = h5.create_group("channels")
        for i, (name, quantity, unit, data) in enumerate(
                [("Force", "force", "N", np.ones(64)),
                 ("Velocity", "velocity", velocity_unit, velocity)]):
            ds = channels.create_dataset(f"{i:03d}", data=data)
            ds.attrs.update(name=name, quantity=quantity, unit=unit, source_unit=unit,
                            sample_rate_hz=1000.0)
    return path


def test_hdf5_layout_channel_stating_a_unit_other_than_si_is_refused(tmp_path):
    # samples in mm/s with unit 'mm/s' were read as m/s: 5000 g and 1000 x the energy per
    # cycle for a 5 g test, the channel listed as 'm/s' from 'mm/s' as if converted
    velocity = np.full(64, 25.0)
    with pytest.raises(InputFileError, match=r"mm\.h5.*/channels/001: attribute unit is "
                                             r"'mm/s', not the SI unit of its quantity velocity "
                                             r"\('m/s'\)"):
        read_measurement(_hand_made_hdf5(tmp_path / "mm.h5", "mm/s", velocity))
    # an SI unit spelt otherwise is SI: the samples as they are
    m = read_measurement(_hand_made_hdf5(tmp_path / "si.h5", "m/sec", velocity))
    np.testing.assert_array_equal(m.channel("Velocity").data, velocity)


def test_mat_pidcore_layout_channel_stating_a_unit_other_than_si_is_refused(tmp_path):
    # the MATLAB form of the same layout ignored its 'unit' field the same way
    def write(path, unit):
        channels = np.empty((1, 2), dtype=object)
        for i, (name, quantity, u, data) in enumerate([("Force", "force", "N", np.ones(64)),
                                                        ("Acc", "acceleration", unit,
                                                         np.full(64, 2.0))]):
            channels[0, i] = {"name": name, "quantity": quantity, "unit": u, "source_unit": u,
                              "data": data, "sample_rate_hz": 1000.0, "start_time_s": 0.0}
        scipy.io.savemat(path, {"pidcore_layout": "measurement", "pidcore_channels": channels})
        return path

    with pytest.raises(InputFileError, match=r"g\.mat: pidcore_channels\{2\}: field unit is "
                                             r"'g', not the SI unit of its quantity "
                                             r"acceleration \('m/s\^2'\)"):
        read_measurement(write(tmp_path / "g.mat", "g"))
    m = read_measurement(write(tmp_path / "si.mat", "m/s2"))
    np.testing.assert_array_equal(m.channel("Acc").data, 2.0)


def test_hdf5_store_with_several_measurements(tmp_path):
    path = tmp_path / "store.h5"
    a, b = _measurement(), _measurement(rate=1000.0, n=50)
    with h5py.File(path, "w") as h5:
        write_measurement_group(h5.create_group("measurements/run_a"), a)
        write_measurement_group(h5.create_group("measurements/run_b"), b)
    with pytest.raises(InputFileError,
                       match=r"store\.h5.*run_a \(made-up\.csv\), run_b \(made-up\.csv\)"):
        read_measurement(path)
    got = read_measurement(path, key="run_b")
    _assert_same(got, b, rtol=0.0)
    assert got.metadata["original_source"] == "made-up.csv"
    assert got.source == str(path) and got.file_format == "hdf5"
    assert len(read_measurements(path)) == 2
    with pytest.raises(InputFileError, match="run_c"):
        read_measurement(path, key="run_c")


def test_failed_write_leaves_existing_file_untouched(tmp_path):
    path = tmp_path / "keep.csv"
    path.write_text("original")
    mixed = Measurement("m", (Channel("a", "force", np.zeros(4), 10.0),
                              Channel("b", "force", np.zeros(4), 20.0)))
    with pytest.raises(ParameterError, match="one sample rate"):
        write_measurement(mixed, path)
    assert path.read_text() == "original"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.csv"]


def test_write_format_from_extension_and_unknown_extension(tmp_path):
    m = _measurement()
    write_measurement(m, tmp_path / "x.hdf5")
    assert read_measurement(tmp_path / "x.hdf5").file_format == "hdf5"
    with pytest.raises(ParameterError, match=r"\.xyz"):
        write_measurement(m, tmp_path / "x.xyz")


def test_content_decides_over_extension(tmp_path):
    """DAQ exports often carry .txt or .dat extensions whatever their content."""
    path = tmp_path / "export.txt"
    write_measurement(_measurement(), path, "uff")
    assert read_measurement(path).file_format == "uff"


def test_uff_fortran_d_and_missing_e_exponents_use_fallback(tmp_path):
    """pyuff's float() rejects 1.0D+00 and 1.0-100; the fallback parser reads them."""
    written = _measurement(n=40)
    path = tmp_path / "fortran.uff"
    write_measurement(written, path)
    lines = path.read_text().splitlines(keepends=True)
    number_line = re.compile(r"^(\s*-?\d\.\d+e[+-]\d+)+\s*$")  # data lines only
    fortran = [ln.replace("e", "D") if number_line.match(ln) else ln for ln in lines]
    fortran_text = "".join(fortran)
    assert fortran_text.count("D+") + fortran_text.count("D-") >= written.channels[0].n_samples
    path.write_text(fortran_text)
    read = read_measurement(path)
    _assert_same(read, written, rtol=1e-11)  # E20.11: 12 significant digits


def test_fortran_float():
    from pidcore.io._uff_ascii import fortran_float

    assert fortran_float(" 1.25D+02") == 125.0
    assert fortran_float("-3.5-100") == -3.5e-100
    assert fortran_float("2.0+005") == 2.0e5
    assert fortran_float("  -0.00115633") == -0.00115633


def test_csv_writer_header_names_si_units(tmp_path):
    path = tmp_path / "h.csv"
    write_measurement(_measurement(n=3), path)
    header = path.read_text().splitlines()[0]
    assert header == "Time [s],Drive point force [N],LDV [m/s],Acc 1 [m/s^2],Bridge [V^2]"
    assert len(read_measurements(path)) == 1


@pytest.mark.parametrize(("suffix", "file_format"), [
    (".uff", "uff"), (".mat", "mat"), (".h5", "hdf5")])
def test_a_sample_rate_a_file_keeps_is_noted_not_ignored_silently(tmp_path, suffix,
                                                                  file_format):
    # `pidcore analyze run.uff --sample-rate 25.6` (kHz typed) printed the same result as
    # without the option and said nothing: UFF, HDF5 and pidcore/Testlab MAT files state each
    # channel's rate and keep it. Now a note says the value given was not applied.
    written = _measurement()
    path = tmp_path / f"record{suffix}"
    write_measurement(written, path, file_format)
    read = read_measurement(path, sample_rate_hz=25.6)
    assert [c.sample_rate_hz for c in read.channels] == [FS] * 4  # kept, as documented
    (note,) = read.metadata["reader_notes"]
    assert "the sample rate 25.6 Hz given (sample_rate_hz) is not applied" in note
    assert "(2560 Hz), which is kept" in note
    # the file's own rate given: nothing to say
    assert "reader_notes" not in read_measurement(path, sample_rate_hz=FS).metadata


def test_an_overridden_time_column_says_what_rate_it_gave(tmp_path):
    # "time column 'Time' ignored: the sample rate 25.6 Hz was given": the column's 25600 Hz
    # (a rate typed in kHz) was not shown, so the 1000-fold slip went unseen
    t = np.arange(200) / 500.0
    path = tmp_path / "with_time.csv"
    path.write_text("Time [s],F [N],V [m/s]\n" + "".join(
        f"{a:.17g},{np.sin(a):.17g},{np.cos(a):.17g}\n" for a in t))
    (note,) = read_measurement(path, sample_rate_hz=0.5).metadata["reader_notes"]
    assert note.endswith("(sample_rate_hz); the column gives 500 Hz, 1000 x the rate given")
    (note,) = read_measurement(path, sample_rate_hz=500.0 * 1.001).metadata["reader_notes"]
    assert note.endswith("(sample_rate_hz)")  # within 0.5 %: a correction, nothing to add
