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


def test_a_csv_channel_shorter_than_its_time_column_says_where_it_ends(tmp_path, capsys):
    # 'Velocity' ends at row 4 of 6 (trailing empty cells): was "channel 'Velocity': 2
    # non-finite samples (NaN/inf), first at index 4", which did not say the column is short
    rows = [f"{k / 1000},{k},{'' if k >= 4 else k}" for k in range(6)]
    path = tmp_path / "short_fill50.csv"
    path.write_text("Time [s],Force [N],Velocity [m/s]\n" + "\n".join(rows) + "\n")
    # the 4th row's time: 3 ms, from the 1 kHz time column
    said = (f"{path}: channel 'Velocity' ends early, at data row 4 of 6 (t = 0.003 s): the 2 "
            "rows after it hold no value; expected a value in every row its time column has")
    _refused_alike_by_reader_and_cli(path, said, tmp_path, capsys)
    empty = tmp_path / "empty_column.csv"
    empty.write_text("Time [s],Force [N],Velocity [m/s]\n"
                     + "\n".join(f"{k / 1000},{k}," for k in range(6)) + "\n")
    with pytest.raises(InputFileError, match=r"channel 'Velocity' holds no value in any of "
                                             r"its 6 rows; expected a value in every row$"):
        read_measurement(empty)


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
