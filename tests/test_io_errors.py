"""Unreadable input gives one InputFileError naming the file and what was expected."""

from __future__ import annotations

import numpy as np
import pytest

from pidcore.errors import InputFileError, ParameterError
from pidcore.io import detect_file_format, read_measurement, write_measurement
from pidcore.records import Channel, Measurement


def _measurement() -> Measurement:
    t = np.arange(600) / 1200.0
    return Measurement("m", (Channel("F", "force", np.sin(2 * np.pi * 60 * t), 1200.0, "N"),
                             Channel("V", "velocity", np.cos(2 * np.pi * 60 * t), 1200.0, "m/s")))


@pytest.mark.parametrize("suffix", [".uff", ".csv", ".mat", ".h5"])
def test_empty_file(tmp_path, suffix):
    path = tmp_path / f"empty{suffix}"
    path.write_bytes(b"")
    with pytest.raises(InputFileError, match=rf"empty{suffix}.*empty file"):
        read_measurement(path)


def test_missing_file(tmp_path):
    with pytest.raises(InputFileError, match=r"nothere\.uff: file not found"):
        read_measurement(tmp_path / "nothere.uff")


@pytest.mark.parametrize(("suffix", "file_format", "binary"), [
    (".uff", "uff", False), (".uff", "uff", True), (".mat", "mat", False),
    (".h5", "hdf5", False),
])
def test_truncated_file(tmp_path, suffix, file_format, binary):
    good = tmp_path / f"good{suffix}"
    write_measurement(_measurement(), good, file_format, binary=binary)
    raw = good.read_bytes()
    cut = tmp_path / f"cut{suffix}"
    cut.write_bytes(raw[: len(raw) * 2 // 3])
    with pytest.raises(InputFileError, match=rf"cut\{suffix}"):
        read_measurement(cut)


def test_garbage_with_known_extensions(tmp_path):
    rng = np.random.default_rng(1)
    noise = rng.integers(0, 256, 4000, dtype=np.uint8).tobytes()
    for suffix in (".mat", ".h5", ".uff"):
        path = tmp_path / f"noise{suffix}"
        path.write_bytes(b"\x00" + noise)
        with pytest.raises(InputFileError, match=rf"noise\{suffix}"):
            read_measurement(path)


def test_binary_content_with_unknown_extension(tmp_path):
    path = tmp_path / "blob.bin"
    path.write_bytes(b"\x00\x01\x02" * 100)
    with pytest.raises(InputFileError, match=r"blob\.bin: unknown file format"):
        detect_file_format(path)


def test_csv_header_only_and_text_cells(tmp_path):
    header_only = tmp_path / "header_only.csv"
    header_only.write_text("Time [s],F [N]\n")
    with pytest.raises(InputFileError, match=r"header_only\.csv: header but no data rows"):
        read_measurement(header_only)
    words = tmp_path / "words.csv"
    words.write_text("Time [s],F [N]\n0,1\n0.1,abc\n")
    with pytest.raises(InputFileError, match=r"words\.csv.*abc"):
        read_measurement(words)


def _sine_rows(fmt: str, sep: str = ",", decimal: str = ".") -> list[str]:
    """300 rows of time, force and velocity of a 60 Hz sine at 1200 Hz, written with ``fmt``."""
    t = np.arange(300) / 1200.0
    w = 2 * np.pi * 60
    return [sep.join((fmt % x).replace(".", decimal) for x in row)
            for row in zip(t, 0.8 * np.sin(w * t), 0.07 * np.cos(w * t), strict=True)]


@pytest.mark.parametrize(("fmt", "sep", "decimal", "cut", "said"), [
    # the tester's file: '7.681693e-02' cut to '7.681693', a value 13 % of the record's SDC
    ("%.6e", ",", ".", lambda row: row[:-4], "written shorter"),
    ("%.6e", ";", ",", lambda row: row[:-4], "written shorter"),  # decimal comma
    ("%.6e", ",", ".", lambda row: row[:-1], "2-digit exponent"),  # 'e-0'
    ("%.6f", "\t", ".", lambda row: row[:-3], "6 decimals"),
    ("%.9g", ",", ".", lambda row: row[:row.rindex(",")], "2 values where"),  # a field gone
    ("%.9g", ",", ".", lambda row: row[:row.rindex(",") + 1], "2 values where"),
])
def test_a_csv_whose_last_row_is_cut_off_is_refused_naming_its_line(tmp_path, capsys, fmt, sep,
                                                                     decimal, cut, said):
    """An interrupted copy or export ends in a part of its last row, with no line break after
    it: read as data, it took 13 % off an SDC with a standard error 5000 x smaller than that
    and no word. Refused, naming the file and the line (the header is line 1, so the 300th
    row is line 301); through the CLI one line, exit 2."""
    rows = _sine_rows(fmt, sep, decimal)
    path = tmp_path / "cut.csv"
    path.write_text(sep.join(("Time [s]", "Force [N]", "Velocity [m/s]")) + "\n"
                    + "\n".join(rows[:-1] + [cut(rows[-1])]))
    with pytest.raises(InputFileError, match=rf"cut\.csv: line 301 is cut off: .*{said}"):
        read_measurement(path)
    from pidcore.cli import main

    assert main(["analyze", str(path), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cut.csv: line 301 is cut off" in err


@pytest.mark.parametrize(("fmt", "last"), [
    ("%.6e", None),  # a fixed format's whole last row
    ("%.9g", "0.25"),  # a writer dropping trailing zeros: a last value shorter than the rows'
    ("%.6f", "12.500000"),  # longer than the rows' (a larger value) is no cut
    ("%.9g", ""),  # a channel ending early, its cells empty in the rows before too
])
def test_a_csv_lacking_only_its_final_line_break_reads_as_with_it(tmp_path, fmt, last):
    """Many writers leave the last row without a line break: such a file reads to the same
    numbers as with one (a complete last row is no cut, whatever its width)."""
    rows = _sine_rows(fmt)
    if last is not None:
        cells = rows[-1].split(",")
        rows[-1] = ",".join(cells[:-1] + [last])
        if last == "":
            rows[-3:] = [",".join(row.split(",")[:-1] + [""]) for row in rows[-3:]]
    text = "Time [s],Force [N],Velocity [m/s]\n" + "\n".join(rows)
    ended, open_ = tmp_path / "ended.csv", tmp_path / "open.csv"
    ended.write_text(text + "\n")
    open_.write_text(text)
    for a, b in zip(read_measurement(ended).channels, read_measurement(open_).channels,
                    strict=True):
        assert np.array_equal(a.data, b.data) and a.sample_rate_hz == b.sample_rate_hz


def test_mat_without_channels_lists_variables(tmp_path):
    import scipy.io

    path = tmp_path / "odd.mat"
    scipy.io.savemat(path, {"comment": "no data here", "fs": 100.0})
    with pytest.raises(InputFileError, match=r"odd\.mat: no channel found.*comment"):
        read_measurement(path)


def test_hdf5_without_pidcore_layout(tmp_path):
    import h5py

    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as h5:
        h5["x"] = np.arange(3)
    with pytest.raises(InputFileError, match=r"other\.h5.*pidcore_layout"):
        read_measurement(path)


def test_uff_time_record_with_fewer_samples_than_declared(tmp_path):
    good = tmp_path / "good.uff"
    write_measurement(_measurement(), good)
    lines = good.read_text().splitlines(keepends=True)
    # Drop one data line of the first record (4 values of E20.11 per line) but keep the "-1".
    short = tmp_path / "short.uff"
    short.write_text("".join(lines[:20] + lines[21:]))
    with pytest.raises(InputFileError, match=r"short\.uff: record 1 holds 596 of its 600"):
        read_measurement(short)


def test_bad_parameters():
    with pytest.raises(ParameterError, match="file_format"):
        read_measurement("x.csv", file_format="xls")


def test_text_without_numbers_is_not_called_a_header_without_data(tmp_path):
    # `pidcore analyze rp/report.csv` (a report's table, 48 data rows of text and numbers) said
    # "header but no data rows", as it did of a TOML file: wrong of both
    table = tmp_path / "report.csv"
    table.write_text('"frequency [Hz]","material","note"\n50.0,"acrylic","a"\n'
                     '100.0,"acrylic","b"\n')
    with pytest.raises(InputFileError, match=r"report\.csv: no rows of numbers in its 3 lines "
                                             r"\(the first: '\"frequency \[Hz\]\","):
        read_measurement(table)


def _refused_alike_by_reader_and_cli(path, said: str, tmp_path, capsys) -> None:
    """``path`` is refused with ``said`` by the reader, and by ``pidcore analyze`` in that
    one line with exit code 2 and no store written."""
    with pytest.raises(InputFileError) as refused:
        read_measurement(path)
    assert str(refused.value) == said
    from pidcore.cli import main

    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--store", str(store)]) == 2
    assert capsys.readouterr().err == f"pidcore analyze: error: {said}\n"
    assert not store.exists()


@pytest.mark.parametrize("text", ["Time [s]\n0\n0.001\n0.002\n", "Time\n[s]\n0\n0.001\n0.002\n",
                                  '"Time [s]",\n0,\n0.001,\n0.002,\n'])
def test_a_csv_of_only_a_time_column_says_it_has_no_channel(tmp_path, capsys, text):
    # was "the header has 2 columns but the data rows have 1": 'Time [s]' split at its space
    path = tmp_path / "times_fill50.csv"
    path.write_text(text)
    said = (f"{path}: only a time column ('Time'), no force or velocity channel; expected "
            "channel columns beside it, e.g. 'Time [s],Force [N],Velocity [m/s]'")
    _refused_alike_by_reader_and_cli(path, said, tmp_path, capsys)


def test_a_one_column_csv_is_that_column_and_a_wider_header_still_says_so(tmp_path):
    # a lone channel is read as one (named without its unit) and asks for the sample rate;
    # a header of two columns over data rows of one is still refused as such
    lone = tmp_path / "force.csv"
    lone.write_text("Force [kN]\n1\n2\n3\n")
    (channel,) = read_measurement(lone, sample_rate_hz=1000.0).channels
    assert (channel.name, channel.quantity) == ("Force", "force")
    np.testing.assert_array_equal(channel.data, [1e3, 2e3, 3e3])  # kN -> N, exact
    wider = tmp_path / "wider.csv"
    wider.write_text("Time [s]\tForce [N]\n0\n0.001\n0.002\n")
    with pytest.raises(InputFileError, match=r"the header has 2 columns but the data rows "
                                             r"have 1$"):
        read_measurement(wider)


def test_a_csv_channel_shorter_than_its_time_column_is_read_to_its_end_and_said(tmp_path):
    # 'Velocity' ends at row 4 of 6 (trailing empty cells): it was refused, and with it the
    # whole file where the short column was one no role needs (a microphone)
    import numpy as np

    rows = [f"{k / 1000},{k},{'' if k >= 4 else k}" for k in range(6)]
    path = tmp_path / "short_fill50.csv"
    path.write_text("Time [s],Force [N],Velocity [m/s]\n" + "\n".join(rows) + "\n")
    m = read_measurement(path)
    force, velocity = m.channels
    np.testing.assert_array_equal(force.data, [0, 1, 2, 3, 4, 5])
    np.testing.assert_array_equal(velocity.data, [0, 1, 2, 3])  # its values, none invented
    assert velocity.start_time_s == force.start_time_s == 0.0
    # the 4th row's time: 3 ms, from the 1 kHz time column
    assert m.metadata["reader_notes"] == [
        f"{path}: channel 'Velocity' ends early, at data row 4 of 6 (t = 0.003 s): the 2 rows "
        "after it hold no value; read to there"]
    empty = tmp_path / "empty_column.csv"
    empty.write_text("Time [s],Force [N],Velocity [m/s]\n"
                     + "\n".join(f"{k / 1000},{k}," for k in range(6)) + "\n")
    with pytest.raises(InputFileError, match=r"channel 'Velocity' holds no value in any of "
                                             r"its 6 rows; expected a value in every row$"):
        read_measurement(empty)


def test_an_unused_channel_ending_early_leaves_the_analysis_as_without_it(tmp_path, capsys):
    # a microphone column that stopped after 1 s refused the whole 2 s record
    import json

    import numpy as np

    from pidcore.cli import main
    from pidcore.signal.synthetic import synthesize_shaker_record

    rec = synthesize_shaker_record(mass_kg=0.05, acceleration_amplitude_m_s2=49.0,
                                   frequency_hz=100.0, sample_rate_hz=5120.0, n_periods=200,
                                   viscous_damping_n_s_m=1.5, snr_db=60.0, seed=3)
    f, v = rec.force_n.tolist(), rec.velocity_m_s.tolist()
    t = (np.arange(len(f)) / 5120.0).tolist()
    plain = tmp_path / "plain.csv"
    plain.write_text("Time [s],Force [N],Velocity [m/s]\n" + "\n".join(
        f"{a!r},{b!r},{c!r}" for a, b, c in zip(t, f, v, strict=True)) + "\n")
    mic = tmp_path / "mic.csv"
    mic.write_text("Time [s],Force [N],Velocity [m/s],Mic [Pa]\n" + "\n".join(
        f"{a!r},{b!r},{c!r}," + (f"{np.sin(k):.6f}" if a < 1.0 else "")
        for k, (a, b, c) in enumerate(zip(t, f, v, strict=True))) + "\n")

    def analysed(path):
        assert main(["analyze", str(path), "--no-store", "--json"]) == 0
        return json.loads(capsys.readouterr().out)["records"][0]

    without, with_mic = analysed(plain), analysed(mic)
    for key in ("loss_factor", "sdc", "energy_per_cycle_j", "frequency_hz"):
        assert with_mic[key] == without[key], key  # the same samples: the same bits
    assert any("channel 'Mic' ends early" in n for n in with_mic["notes"])


def test_a_long_first_line_is_quoted_by_its_start_and_size(tmp_path):
    # the line was cut at 60 characters without a word of it (the reader may think the file
    # holds that short line); every message now says a cut and the size alike
    # (pidcore.errors.clipped, as a specimen's long value)
    line = "text," * 2000
    table = tmp_path / "notes.csv"
    table.write_text(f"{line}\n{line}\n")
    with pytest.raises(InputFileError) as refused:
        read_measurement(table)
    said = str(refused.value)
    shown = repr(line.strip())
    assert f"(the first: {shown[:42]}... ({len(shown)} characters))" in said, said
    assert len(said) < 300, said


def test_instance_of_quotes_a_long_value_by_its_start_and_size():
    # instance_of cut a long repr at 57 characters with "...", the specimen's refusals at 60
    # with the size: one helper, one way of saying a cut
    from pidcore.errors import clipped, instance_of

    value = list(range(10_000))
    with pytest.raises(ParameterError) as refused:
        instance_of("cells", value, int)
    shown = repr(value)
    assert str(refused.value) == (f"cells: expected an int, got list {shown[:40]}... "
                                  f"({len(shown)} characters)")
    assert clipped("short", 60) == "short"  # a value that fits is quoted whole
    assert clipped("x" * 81) == "x" * 60 + "... (81 characters)"


def _shaker_rows(separator: str) -> tuple[str, float]:
    """Rows of F = F0 sin(wt), V = V0 sin(wt - phi) with decimal commas, and the loss factor
    cot(phi) they hold (paper Eq. 11: P_c = 1/2 F0 V0 e^{j phi})."""
    fs, f, phi = 5120.0, 100.0, np.radians(80.0)
    t = np.arange(int(fs)) / fs
    force, velocity = 10.0 * np.sin(2 * np.pi * f * t), 0.05 * np.sin(2 * np.pi * f * t - phi)
    rows = "".join(separator.join(f"{x:.9g}".replace(".", ",") for x in row) + "\n"
                   for row in zip(t, force, velocity, strict=True))
    return rows, 1.0 / np.tan(phi)


def test_a_decimal_comma_in_a_comma_separated_export_is_named_not_a_missing_header(tmp_path):
    # German Excel saving "CSV (comma delimited)" writes 0,5,12,3: every number split in two,
    # six cells under three names; refused as "no header row before the numbers", which sent
    # the user looking for a header that is there
    rows, _ = _shaker_rows(",")
    path = tmp_path / "run 7.csv"
    path.write_text("Testlab export\nTime [s],Force [N],Velocity [m/s]\n" + rows)
    with pytest.raises(InputFileError) as refused:
        read_measurement(path)
    said = str(refused.value)
    # the first row (t = 0, F = 0) is "0,0,-0,0492..." (4 cells), the others 6
    assert said.startswith(f"{path}: the header (line 2) names 3 columns but the data rows "
                           "hold 4 to 6 cells; numbers with a decimal comma"), said
    assert "';' or tab" in said and "\n" not in said
    # the same numbers separated by ';' (the advice) read and analyse to the truth
    from pidcore.measure import analyze_measurement

    rows, eta = _shaker_rows(";")
    path.write_text("Testlab export\nTime [s];Force [N];Velocity [m/s]\n" + rows)
    # noise-free, 9 significant digits (relative rounding 5e-9 per sample): 1e-6 catches any
    # mis-split column (a loss factor off by 100 %) and any unit or phase slip
    assert analyze_measurement(read_measurement(path)).analysis.loss_factor == \
        pytest.approx(eta, rel=1e-6)


def test_a_header_of_fewer_names_than_columns_says_so(tmp_path):
    rows, _ = _shaker_rows(";")
    path = tmp_path / "short.csv"
    path.write_text("Time [s];Force [N]\n" + rows)  # the velocity column has no name
    with pytest.raises(InputFileError, match=r"short\.csv: the header \(line 1\) names 2 "
                                             r"columns but the data rows hold 3 cells; expected "
                                             r"one name per column"):
        read_measurement(path)


def test_a_58b_record_declaring_more_samples_than_its_block_holds_is_refused(tmp_path):
    # record 7's num_pts 100 above the ID line's byte count: the samples were read on into the
    # next dataset's header bytes (100 values of ~1e-157 appended to the force, kept: only
    # the last record of a file ran into its end and was refused)
    import re

    from pidcore.measure import analyze_measurement

    fs, f, phi, n = 5120.0, 100.0, np.radians(80.0), 10240
    t = np.arange(n) / fs
    channels = (Channel("Force", "force", 10.0 * np.sin(2 * np.pi * f * t), fs, "N"),
                Channel("Velocity", "velocity", 0.05 * np.sin(2 * np.pi * f * t - phi), fs,
                        "m/s"),
                Channel("Tacho", "voltage", np.sign(np.sin(2 * np.pi * f * t)), fs, "V"))
    good = tmp_path / "good.uff"
    write_measurement(Measurement("m", channels), good, "uff", binary=True)
    # the intact file reads to its samples and the analytic loss factor cot(phi) (paper
    # Eq. 11, P_c = 1/2 F0 V0 e^{j phi}); float64 samples, noise-free: 1e-9 of it
    read = read_measurement(good)
    assert [c.data.size for c in read.channels] == [n, n, n]
    assert analyze_measurement(read).analysis.loss_factor == pytest.approx(1 / np.tan(phi),
                                                                           rel=1e-9)
    raw = good.read_bytes()
    record_7 = re.compile(rb"(\n\s+4\s+)" + str(n).encode() + rb"(\s)")
    assert len(record_7.findall(raw)) == 3
    bad = tmp_path / "num_pts.uff"
    bad.write_bytes(record_7.sub(lambda m: m.group(1) + str(n + 100).encode() + m.group(2), raw,
                                 count=1))
    with pytest.raises(InputFileError, match=r"num_pts\.uff: record 1 holds 10240 of its 10340 "
                                             r"samples; the file is truncated or corrupt"):
        read_measurement(bad)


def test_a_metadata_block_longer_than_the_first_read_is_read_past(tmp_path, monkeypatch):
    # 68 kB of '#' metadata lines before the header (a Testlab export with its channel
    # table) was refused as "no rows of numbers in its 65 lines" of a file of ~1000 lines
    import numpy as np

    from pidcore.io import delimited

    rows = "\n".join(f"{k / 1000},{np.sin(k / 7):.9g},{np.cos(k / 7):.9g}" for k in range(1000))
    table = "Time [s],Force [N],Velocity [m/s]\n" + rows + "\n"
    plain = tmp_path / "plain.csv"
    plain.write_text(table)
    meta = "".join(f"# channel {i}: sensitivity {i * 1.01:.4f} mV/N, serial {i:08d} "
                   f"{'x' * 40}\n" for i in range(700))
    assert len(meta.encode()) > 4 * 2**14  # past the 64 KiB first read
    long = tmp_path / "long_meta.csv"
    long.write_text(meta + table)
    expected = read_measurement(plain).channels
    got = read_measurement(long).channels
    for a, b in zip(got, expected, strict=True):
        assert (a.name, a.quantity, a.sample_rate_hz) == (b.name, b.quantity, b.sample_rate_hz)
        np.testing.assert_array_equal(a.data, b.data)  # the same numbers, bit for bit
    # beyond the most read, the refusal says that it read the first part only (the count of
    # lines was of the first 64 KiB, though the file held ten times more)
    monkeypatch.setattr(delimited, "_HEAD_MAX_BYTES", 2**16)
    with pytest.raises(InputFileError, match=r"no rows of numbers in the first 0\.0625 MiB of "
                                             r"the file, its first \d+ lines"):
        read_measurement(long)


#: 100 Hz at 5 kHz: 50 samples a period, 205 periods in 10 250 samples, which fill neither
#: a 6E13.5 nor a 4E20.12 last line (2 values in each).
_FS, _F, _N = 5000.0, 100.0, 10250
#: Velocity lagging the force by 80 deg: the loss factor is cot(80 deg) (paper Eq. 11,
#: P_c = 1/2 F0 V0 e^{j phi}).
_PHI = np.radians(80.0)


def _force_and_velocity() -> Measurement:
    t = np.arange(_N) / _FS
    return Measurement("m", (
        Channel("Force", "force", 10.0 * np.sin(2 * np.pi * _F * t), _FS, "N"),
        Channel("Velocity", "velocity", 0.05 * np.sin(2 * np.pi * _F * t - _PHI), _FS, "m/s")))


def _loss_factor(path) -> float:
    from pidcore.measure import analyze_measurement

    return analyze_measurement(read_measurement(path)).analysis.loss_factor


def _write_ascii_uff(path, ord_data_type: int) -> list[str]:
    """The force and velocity as ASCII UFF 58 lines: ordinate data type 2 (6E13.5 a line) or
    4 (4E20.12 a line)."""
    import pyuff

    from pidcore.io.uff import _dataset_58

    sets = []
    for i, ch in enumerate(_force_and_velocity().channels):
        d = _dataset_58(ch, i)
        d["ord_data_type"] = ord_data_type
        sets.append(d)
    pyuff.UFF(str(path)).write_sets(sets, mode="add", force_double=ord_data_type == 4)
    return path.read_text().splitlines(keepends=True)


def _data_lines(lines: list[str], record: int) -> range:
    """Indices of the data lines of ``record`` (from 0): after its 13 header lines (the
    opening '-1' and '58' included), before its closing '-1'."""
    tags = [k for k, line in enumerate(lines) if line.strip() == "-1"]
    return range(tags[2 * record] + 13, tags[2 * record + 1])


# 6 significant digits a sample (E13.5, relative rounding 5e-6): the phase is off by some
# 5e-6 rad at most, cot(80 deg) by 5e-6 / sin^2(80 deg) of 0.18, 3e-5 of it; 1e-4 is far
# below the 87 % and 128 % errors of a shifted record
_ASCII_LF_RTOL = 1e-4


@pytest.mark.parametrize(("ord_data_type", "per_line"), [(2, 6), (4, 4)],
                         ids=["E13.5", "E20.12"])
def test_a_uff_record_holding_a_line_more_than_its_header_states_is_refused(
        tmp_path, ord_data_type, per_line):
    good = tmp_path / "good.uff"
    lines = _write_ascii_uff(good, ord_data_type)
    assert _loss_factor(good) == pytest.approx(1 / np.tan(_PHI), rel=_ASCII_LF_RTOL)
    # one line of the velocity written twice: its values were cut to num_pts, the rest of
    # the record read shifted by a line (a loss factor of 0.0067 for 0.05), unsaid
    middle = _data_lines(lines, 1)[len(_data_lines(lines, 1)) // 2]
    bad = tmp_path / "twice.uff"
    bad.write_text("".join(lines[:middle + 1] + lines[middle:]))
    with pytest.raises(InputFileError) as info:
        read_measurement(bad)
    said = str(info.value)
    assert said == (f"{bad}: record 2 holds {_N + per_line} samples where its header states "
                    f"{_N} (record 7, field 2); only zeros padding its last line may follow "
                    "them; the file is corrupt"), said


@pytest.mark.parametrize(("ord_data_type", "per_line", "field"),
                         [(2, 6, "%13.5e"), (4, 4, "%20.11e")], ids=["E13.5", "E20.12"])
def test_only_zeros_filling_the_last_line_of_a_uff_record_are_dropped(
        tmp_path, ord_data_type, per_line, field):
    lines = _write_ascii_uff(tmp_path / "good.uff", ord_data_type)
    fill = per_line - _N % per_line  # 4 fields of E13.5, 2 of E20.12

    def padded(with_value: float, count: int) -> list[str]:
        out = list(lines)
        for record in (0, 1):
            last = _data_lines(out, record)[-1]
            out[last] = out[last].rstrip("\n") + field % with_value * count + "\n"
        return out

    # zeros to the end of the last line, as UFFFiles.jl's real force record has them
    zeros = tmp_path / "zeros.uff"
    zeros.write_text("".join(padded(0.0, fill)))
    assert [c.n_samples for c in read_measurement(zeros).channels] == [_N, _N]
    assert _loss_factor(zeros) == pytest.approx(1 / np.tan(_PHI), rel=_ASCII_LF_RTOL)
    # a value that is not zero is a sample the header does not count: no padding
    ones = tmp_path / "ones.uff"
    ones.write_text("".join(padded(1.0, fill)))
    with pytest.raises(InputFileError, match=rf"ones\.uff: record 1 holds {_N + fill} samples "
                                             rf"where its header states {_N} "):
        read_measurement(ones)
    # nor are zeros a whole line holds (a silent stretch written twice): no last line's fill
    line = tmp_path / "line.uff"
    line.write_text("".join(padded(0.0, fill + per_line)))
    with pytest.raises(InputFileError, match=rf"line\.uff: record 1 holds "
                                             rf"{_N + fill + per_line} samples where"):
        read_measurement(line)


def _binary_force_block(tmp_path) -> tuple[bytes, int, int]:
    """The force and velocity as 58b (float64): the file's bytes and the first and end byte
    of the force record's samples, which its closing '    -1' follows at once."""
    good = tmp_path / "good.uff"
    write_measurement(_force_and_velocity(), good, "uff", binary=True)
    raw = good.read_bytes()
    start = 0
    for _ in range(13):  # the header lines, its opening '-1' included
        start = raw.index(b"\n", start) + 1
    end = start + 8 * _N
    assert b"    58b" in raw[:start] and raw[end:end + 7] == b"    -1\n"
    # float64 samples, noise-free: 1e-9 of the analytic loss factor
    assert _loss_factor(good) == pytest.approx(1 / np.tan(_PHI), rel=1e-9)
    return raw, start, end


@pytest.mark.parametrize(("change", "found"), [("short", 8 * _N - 24), ("long", 8 * _N + 24)])
def test_a_58b_block_of_another_size_than_its_id_line_states_is_refused(tmp_path, change,
                                                                       found):
    raw, start, end = _binary_force_block(tmp_path)
    middle = (start + end) // 2
    # 24 bytes lost or written twice: the samples were read from the header on as if whole,
    # shifted past that point (a loss factor 13 % low, 31 % high), unsaid
    bad = tmp_path / f"{change}.uff"
    bad.write_bytes(raw[:middle] + raw[middle + 24:] if change == "short"
                    else raw[:middle] + raw[middle:middle + 24] + raw[middle:])
    with pytest.raises(InputFileError) as info:
        read_measurement(bad)
    said = str(info.value)
    assert said == (f"{bad}: record 1 ('Force') holds {found} bytes of binary samples before "
                    f"its closing '    -1' where its ID line states {8 * _N}; the file is "
                    "truncated or corrupt"), said


@pytest.mark.parametrize("between", [b"\r\n", b"\n", b"  \r\n"], ids=["CRLF", "LF", "blanks"])
def test_line_breaks_between_58b_samples_and_their_closing_tag_are_read_past(tmp_path,
                                                                            between):
    # MPSTD's DAQ writes CR LF there (the real fixture, pyuff's fix_58b case)
    raw, _, end = _binary_force_block(tmp_path)
    path = tmp_path / "breaks.uff"
    path.write_bytes(raw[:end] + between + raw[end:])
    assert [c.n_samples for c in read_measurement(path).channels] == [_N, _N]
    assert _loss_factor(path) == pytest.approx(1 / np.tan(_PHI), rel=1e-9)


def test_a_58b_id_line_counting_more_bytes_than_num_pts_samples_is_refused(tmp_path):
    # block and ID line agree on 3 samples more than record 7's num_pts: the 3 were dropped
    raw, _, end = _binary_force_block(tmp_path)
    stated = f"{8 * _N:12d}".encode()
    assert raw.count(stated) >= 1 and raw.index(stated) < end
    bad = tmp_path / "more.uff"
    bad.write_bytes((raw[:end] + raw[end - 24:end] + raw[end:]).replace(
        stated, f"{8 * _N + 24:12d}".encode(), 1))
    with pytest.raises(InputFileError, match=rf"more\.uff: record 1 holds {_N + 3} samples "
                                             rf"where its header states {_N} "):
        read_measurement(bad)


@pytest.mark.parametrize("binary", [True, False], ids=["58b", "ASCII 58"])
def test_a_pyuff_without_header_only_is_named_as_the_installation_not_a_corrupt_file(
        tmp_path, monkeypatch, binary):
    # pyuff 2.4 to 2.4.4: _extract58 takes no header_only, and a sound 58b export was refused
    # as "dataset 58 (block 1) is corrupt (_extract58() got an unexpected keyword argument
    # 'header_only')", blaming the user's file for pidcore's dependency
    import pyuff
    from pyuff.datasets import dataset_58

    from pidcore.errors import DependencyError

    real = dataset_58._extract58

    def extract58_of_pyuff_2_4_4(block_data):  # that release's signature
        return real(block_data)

    path = tmp_path / "sound.uff"
    write_measurement(_measurement(), path, "uff", binary=binary)
    monkeypatch.setattr(dataset_58, "_extract58", extract58_of_pyuff_2_4_4)
    monkeypatch.setattr(pyuff, "__version__", "2.4.4")
    with pytest.raises(DependencyError) as info:
        read_measurement(path)
    said = str(info.value)
    assert said == (f"{path}: not read: pyuff 2.4.4 does not support reading a dataset 58 "
                    "header alone (_extract58's header_only); pidcore needs pyuff >= 2.4.5 "
                    "(pip install 'pyuff>=2.4.5')"), said
    assert not isinstance(info.value, InputFileError)  # not counted among unreadable files


def test_the_pyuff_bound_pidcore_states_is_the_first_release_its_reader_runs_on():
    # pyproject.toml asked for pyuff>=2.4, whose 2.4 to 2.4.4 lack _extract58's header_only
    import tomllib
    from pathlib import Path

    from pidcore.io.uff import PYUFF_MIN_VERSION

    project = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())
    assert f"pyuff>={PYUFF_MIN_VERSION}" in project["project"]["dependencies"]
    assert PYUFF_MIN_VERSION == "2.4.5"
