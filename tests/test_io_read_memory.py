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
