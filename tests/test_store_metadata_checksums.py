"""A measurement's attributes (sample rate, units, names) are checksummed as an analysis's
record is: a bit flipped in a channel's sample_rate_hz (25600 -> 27648) passed verify and
analyze --key read 54 Hz for 50 Hz. Measurements of earlier stores, written without the
checksum, still read and verify sound, and verify says what it could not check of them."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import h5py
import numpy as np
import pytest

from pidcore.cli import main
from pidcore.errors import StoreError
from pidcore.records import Channel, Measurement
from pidcore.store import Store

RATE = 25600.0


def _measurement() -> Measurement:
    rng = np.random.default_rng(3)
    return Measurement("coupon.uff", (
        Channel("force", "force", rng.normal(size=512), RATE, "N"),
        Channel("accel", "acceleration", rng.normal(size=512), RATE, "g"),
    ), sha256=hashlib.sha256(b"coupon").hexdigest(), file_format="uff")


def _flip_first_rate(path: Path) -> None:
    """The tester's flip: bit 1 of byte 6 of the float64 25600.0 gives 27648.0."""
    raw = bytearray(path.read_bytes())
    offset = raw.find(np.float64(RATE).tobytes())
    assert offset >= 0
    raw[offset + 6] ^= 0x02
    assert np.frombuffer(bytes(raw[offset:offset + 8]), np.float64)[0] == 27648.0
    path.write_bytes(bytes(raw))


def test_a_bit_flipped_in_a_stored_sample_rate_is_damage_verify_names_and_reads_refuse(tmp_path):
    store = Store(tmp_path / "s.h5")
    key, _ = store.add_measurement(_measurement())
    _flip_first_rate(store.path)
    problems = store.verify()
    assert len(problems) == 1 and f"/measurements/{key}" in problems[0], problems
    assert "checksum" in problems[0]
    with pytest.raises(StoreError, match=r"s\.h5:/measurements/\w+/channels/000: cannot be "
                       r"read \(.*incorrect metadata checksum"):
        store.get_measurement(key)
    assert store.unchecked() == []  # written with its checksum: nothing left unchecked


def _earlier_measurement(store: Store, measurement: Measurement) -> str:
    """The measurement as pidcore wrote it before its metadata was checksummed (version-1
    object headers: groups and datasets made without track_order)."""
    store.add_dem_run("other", {"sdc": 0.1})  # makes the store
    key = measurement.sha256[:16]
    with h5py.File(store.path, "r+") as h5:
        group = h5["measurements"].create_group(key)
        for name, value in (("pidcore_layout", "measurement"), ("source", measurement.source),
                            ("sha256", measurement.sha256), ("file_format", "uff"),
                            ("metadata_json", "{}"), ("imported_utc", "2024-01-01T00:00:00+00:00"),
                            ("pidcore_version", "0.9"), ("key_basis", "file_sha256")):
            group.attrs[name] = value
        channels = group.create_group("channels")
        for order, ch in enumerate(measurement.channels):
            ds = channels.create_dataset(f"{order:03d}", data=ch.data, compression="gzip",
                                         shuffle=True)
            for name, value in (("name", ch.name), ("quantity", ch.quantity),
                                ("unit", ch.unit), ("source_unit", ch.source_unit),
                                ("sample_rate_hz", ch.sample_rate_hz),
                                ("start_time_s", 0.0), ("order", order)):
                ds.attrs[name] = value
    return key


def test_a_measurement_of_an_earlier_store_verifies_sound_and_verify_says_what_it_could_not_check(
        tmp_path, capsys):
    store = Store(tmp_path / "old.h5")
    key = _earlier_measurement(store, _measurement())
    assert store.verify() == []
    assert store.get_measurement(key).channels[0].sample_rate_hz == RATE
    (line,) = store.unchecked()
    assert f"/measurements/{key}: no checksum of its metadata (written by an earlier pidcore)" \
        in line and "sample rates" in line
    assert main(["store", "verify", "--store", str(store.path), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "sound (" in out and line in out
    assert main(["store", "verify", "--store", str(store.path), "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    assert said["sound"] and said["unchecked"] == [line]
