"""Reading a long export holds its samples about once: no float64 copy of samples that are
float64 already, no second copy of a file's text or blocks beside the channels. Bounds are
tracemalloc peaks (numpy buffers are traced) as multiples of the channels' bytes, structural
and generous, not timings; every read is also checked to give the very samples written."""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from pidcore.io import read_measurement, write_measurement
from pidcore.records import Channel, Measurement

N_SAMPLES = 1_000_000
RATE_HZ = 51_200.0


def _export(path, n: int = N_SAMPLES) -> Measurement:
    t = np.arange(n) / RATE_HZ
    measurement = Measurement("x", (
        Channel("Force", "force", np.sin(600 * t) * 3.0 + 0.1, RATE_HZ, "N"),
        Channel("Velocity", "velocity", 0.01 * np.cos(600 * t + 0.2), RATE_HZ, "m/s")),
        sha256="", file_format="")
    write_measurement(measurement, path)
    return measurement


def _read_peak(path) -> tuple[Measurement, int]:
    tracemalloc.start()
    try:
        measurement = read_measurement(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return measurement, peak


def _same_samples(read: Measurement, written: Measurement) -> None:
    for got, want in zip(read.channels, written.channels, strict=True):
        # bit for bit: the layouts store float64 as given, nothing is computed on the way
        np.testing.assert_array_equal(got.data, want.data)
        assert got.data.dtype == np.float64


def test_a_long_matlab_export_is_read_without_a_second_copy_of_its_samples(tmp_path):
    """loadmat gives float64 arrays; each was copied once more as it became a channel (the
    peak 2x the samples, 6x the two channels used of a six-channel export). Now the channels
    are those arrays: 1x, checked with 0.5x for loadmat's headers and small buffers."""
    written = _export(tmp_path / "long.mat")
    read, peak = _read_peak(tmp_path / "long.mat")
    _same_samples(read, written)
    assert peak <= 1.5 * 2 * N_SAMPLES * 8, peak / (2 * N_SAMPLES * 8)


FIXTURES = Path(__file__).resolve().parents[1] / "data_samples" / "exports"
#: The third-party exports (../shared/fixtures/real_exports beside the checkout).
REAL_EXPORTS = next((p for p in (
    Path(__file__).resolve().parents[1] / ".." / "shared" / "fixtures" / "real_exports",
    Path("/work/shared/fixtures/real_exports")) if p.is_dir()), None)


@pytest.mark.skipif(REAL_EXPORTS is None, reason="real UFF fixtures not present")
@pytest.mark.parametrize("chunk_bytes", [1 << 24, 4096, 97, 7])
def test_the_chunked_block_scan_finds_the_blocks_pyuff_finds(monkeypatch, chunk_bytes):
    """The index the chunked scan builds is pyuff's, block for block and type for type, on
    real exports (the 58b fixture with a stray CR LF before its closing tag, Fortran D
    exponents, Latin-1 headers, blocks padded to column 80) and the bundled samples, also
    with chunks so small that tags and the 80-column look-ahead straddle chunk ends."""
    import pyuff

    from pidcore.io import uff

    monkeypatch.setattr(uff, "_SCAN_CHUNK_BYTES", chunk_bytes)
    files = [p for p in [*REAL_EXPORTS.glob("*"), *FIXTURES.glob("*.uff")]
             if p.suffix.lower() in (".uff", ".unv", ".frf")]
    assert len(files) >= 10
    for path in files:
        theirs, ours = pyuff.UFF(str(path)), uff._BlockScannedUFF(str(path))
        assert ours._n_sets == theirs._n_sets, path.name
        np.testing.assert_array_equal(np.asarray(ours._block_ind),
                                      np.asarray(theirs._block_ind), err_msg=path.name)
        np.testing.assert_array_equal(ours._set_types, theirs._set_types, err_msg=path.name)
        np.testing.assert_array_equal(ours._set_formats, theirs._set_formats,
                                      err_msg=path.name)


def _read_by_pyuff(monkeypatch, path) -> Measurement:
    """``read_uff(path)`` with every ASCII record parsed by pyuff (the path before)."""
    from pidcore.io import read_uff, uff

    with monkeypatch.context() as patch:
        patch.setattr(uff, "_ascii_58_record", lambda *args: None)
        return read_uff(path)


def _bit_identical(first: Measurement, second: Measurement) -> None:
    assert [c.name for c in first.channels] == [c.name for c in second.channels]
    for a, b in zip(first.channels, second.channels, strict=True):
        assert (a.quantity, a.sample_rate_hz, a.start_time_s, a.source_unit) == \
            (b.quantity, b.sample_rate_hz, b.start_time_s, b.source_unit)
        np.testing.assert_array_equal(a.data.view(np.uint64), b.data.view(np.uint64))


@pytest.mark.skipif(REAL_EXPORTS is None, reason="real UFF fixtures not present")
def test_ascii_records_read_bit_for_bit_as_pyuff_reads_them(monkeypatch):
    """Every ASCII 58 time record of the real exports (E13.5 and E20.12, fields without
    separating blanks, lines padded to column 80, a zero-padded last line, 3-digit
    exponents) and of the bundled samples gives the very float64 bits pyuff's parse gave:
    the same fields, each converted by float()."""
    from pidcore.io import read_uff

    files = [p for p in [*REAL_EXPORTS.glob("*"), *FIXTURES.glob("*.uff")]
             if p.suffix.lower() in (".uff", ".unv") and b"58b" not in p.read_bytes()[:4096]]
    read = 0
    for path in files:
        try:
            ours = read_uff(path)
        except Exception as exc:  # a file without time records: refused alike both ways
            with pytest.raises(type(exc)):
                _read_by_pyuff(monkeypatch, path)
            continue
        _bit_identical(ours, _read_by_pyuff(monkeypatch, path))
        read += 1
    assert read >= 4


def test_a_long_ascii_uff_export_is_read_in_a_bounded_multiple_of_its_samples(
        tmp_path, monkeypatch):
    """pyuff parses an ASCII record by decoding its block, splitting it into line objects
    and collecting a list of Python floats (32 bytes a sample): 13x the two channels used of
    a six-channel E20.12 export, of which each block is 2.5x its channel's samples. Now the
    fields are parsed from views of 256 KiB of lines at a time straight into the channel's
    array: the channels (1x), checked with 0.5x for the chunk's masks, the block scan's
    4 MiB and pyuff's header parse. The samples are pyuff's, bit for bit."""
    from pidcore.io import read_uff, write_uff

    n = N_SAMPLES // 2
    t = np.arange(n) / RATE_HZ
    path = tmp_path / "long_ascii.uff"
    write_uff(Measurement("x", (
        Channel("Force", "force", np.sin(600 * t) * 3.0 + 0.1, RATE_HZ, "N"),
        Channel("Velocity", "velocity", 0.01 * np.cos(600 * t + 0.2), RATE_HZ, "m/s")),
        sha256="", file_format=""), path)
    del t
    tracemalloc.start()
    try:
        read = read_uff(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    samples_bytes = 2 * n * 8
    assert peak <= 1.5 * samples_bytes, peak / samples_bytes
    _bit_identical(read, _read_by_pyuff(monkeypatch, path))


def _crlf(text: bytes) -> bytes:
    return text.replace(b"\n", b"\r\n")


def _line_split(text: bytes) -> bytes:
    lines = text.split(b"\n")
    lines[40:41] = [lines[40][:60], lines[40][60:]]  # 3 fields, then 1, amid full lines
    return b"\n".join(lines)


def _bare_cr(text: bytes) -> bytes:
    lines = text.split(b"\n")
    lines[50] = lines[50][:20] + b"\r" + lines[50][20:]  # a line break str.splitlines sees
    return b"\n".join(lines)


def _blank_line(text: bytes) -> bytes:
    return text.replace(b"\n    -1\n", b"\n\n    -1\n", 2)


@pytest.mark.parametrize("variant", [_crlf, _line_split, _bare_cr, _blank_line])
def test_ascii_records_of_odd_line_layouts_read_as_pyuff_reads_them(tmp_path, monkeypatch,
                                                                    variant):
    """Lines of another length amid full ones, CR LF endings, a bare CR inside a line, a
    blank line before the closing tag: where the lines stop being of one layout the rest
    is parsed line by line as pyuff does, and the samples are pyuff's, bit for bit."""
    from pidcore.io import read_uff

    path = tmp_path / "variant.uff"
    path.write_bytes(variant((FIXTURES / "synthetic_f50Hz_a5g_fill50_acrylic.uff").read_bytes()))
    _bit_identical(read_uff(path), _read_by_pyuff(monkeypatch, path))


def test_a_long_csv_export_is_read_holding_its_table_once(tmp_path):
    """The table was parsed as one pandas block (time column and all: 1.5x the two channels
    here), each channel then copied out of it (1x more) and the time column compared with
    its grid over its whole length (3 temporaries of its size): 3.5x by tracemalloc, and the
    resident set as much. Now the rows are parsed a chunk at a time straight into columns
    sized by the line count, each channel is its column, and the grid is compared in blocks:
    the table (1.5x), checked with 0.5x for a chunk's block and pandas' buffers. The samples
    are the file's, bit for bit (written with 17 digits)."""
    written = _export(tmp_path / "long.csv", N_SAMPLES // 2)
    read, peak = _read_peak(tmp_path / "long.csv")
    _same_samples(read, written)
    assert peak <= 2.0 * 2 * (N_SAMPLES // 2) * 8, peak / (2 * (N_SAMPLES // 2) * 8)
