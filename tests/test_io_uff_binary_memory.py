"""Binary UFF 58b records are read straight into arrays: the samples as the file states them
(byte order, single or double precision), in memory bounded by a small multiple of them."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from pidcore.io import read_uff, write_uff
from pidcore.records import Channel, Measurement


def _write(path, channels, fs=51_200.0):
    write_uff(Measurement("x", tuple(Channel(name, quantity, data, fs, unit)
                                     for name, quantity, data, unit in channels),
                          sha256="", file_format="uff"), path, binary=True)


def _as_variant(path, samples: np.ndarray, *, big_endian: bool, single: bool) -> None:
    """Rewrite the one-record 58b file at ``path`` (written little-endian, double precision)
    with the byte order and precision given: the header fields (byte ordering on the 58b
    line, ordinate data type on record 7, byte count) and the bytes of the samples."""
    raw = path.read_bytes()
    lines = raw.split(b"\n", 13)
    head = lines[1]
    assert head.startswith(b"    58b     1     2")
    dtype = np.dtype((">" if big_endian else "<") + ("f4" if single else "f8"))
    data = samples.astype(dtype).tobytes()
    lines[1] = (head[:7] + b"%6d" % (2 if big_endian else 1) + head[13:31]
                + b"%12d" % len(data) + head[43:])
    if single:
        assert lines[8].startswith(b"         4")
        lines[8] = b"         2" + lines[8][10:]
    rest = lines[13]
    lines[13] = data + rest[samples.size * 8:]
    path.write_bytes(b"\n".join(lines))


@pytest.mark.parametrize(("big_endian", "single"), [(False, False), (True, False),
                                                    (False, True), (True, True)])
def test_binary_samples_read_back_in_every_byte_order_and_precision(tmp_path, big_endian,
                                                                    single):
    samples = np.sin(np.arange(1000) * 0.37) * 12.5 + 0.25
    path = tmp_path / "one.uff"
    _write(path, [("Force", "force", samples, "N")])
    _as_variant(path, samples, big_endian=big_endian, single=single)
    read = read_uff(path).channels[0]
    # exact: the samples are the float32 (or float64) numbers written, nothing computed
    expected = samples.astype(np.float32).astype(np.float64) if single else samples
    np.testing.assert_array_equal(read.data, expected)
    assert read.data.dtype == np.float64 and read.sample_rate_hz == 51_200.0


def test_reading_a_long_binary_export_needs_a_bounded_multiple_of_its_samples(tmp_path):
    """A 10-minute 58b export of force and velocity (469 MiB of samples) took 2.9 GiB to read
    (pyuff unpacks the samples into a tuple of Python floats, 32 bytes each, and adds an
    abscissa array): 5.5x the samples by tracemalloc here. Then pyuff's scan of the blocks
    held the whole file (1x) and a copy of each block split into lines (up to 1x more): 2.7x.
    The scan now reads the file in chunks and each block's head only, so what is left is the
    channels (1x): checked with 0.5x for the 4 MiB scan chunk and pyuff's header parse."""
    n = 1_000_000
    t = np.arange(n) / 51_200.0
    path = tmp_path / "long_58b.uff"
    _write(path, [("Force", "force", np.sin(600 * t), "N"),
                  ("Velocity", "velocity", 0.01 * np.cos(600 * t), "m/s")])
    del t
    tracemalloc.start()
    try:
        measurement = read_uff(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    samples_bytes = 2 * n * 8
    assert [c.n_samples for c in measurement.channels] == [n, n]
    assert peak <= 1.5 * samples_bytes, peak / samples_bytes
