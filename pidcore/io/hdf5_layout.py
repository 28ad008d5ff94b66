"""pidcore's HDF5 layout of one measurement group, shared by the HDF5 reader and the store.

A measurement group holds one dataset per channel under ``channels/``. Attributes carry units
and provenance so that the file explains itself without pidcore::

    <group>/                attrs: pidcore_layout="measurement", source, sha256, file_format,
                                   metadata_json
    <group>/channels/<i>    float64 samples in SI; attrs: name, quantity, unit (SI),
                            source_unit, sample_rate_hz, start_time_s, order

Channel datasets are keyed by position (``"000"``, ``"001"``) because channel names may hold
characters HDF5 treats as path separators.
"""

from __future__ import annotations

import json

import h5py
import numpy as np

from ..errors import InputFileError
from ..records import Channel, Measurement

LAYOUT_TAG = "measurement"


def write_measurement_group(group: h5py.Group, measurement: Measurement) -> None:
    """Write ``measurement`` into an (empty) HDF5 group."""
    group.attrs["pidcore_layout"] = LAYOUT_TAG
    group.attrs["source"] = measurement.source
    group.attrs["sha256"] = measurement.sha256
    group.attrs["file_format"] = measurement.file_format
    group.attrs["metadata_json"] = json.dumps(dict(measurement.metadata), default=str)
    channels = group.create_group("channels")
    for order, ch in enumerate(measurement.channels):
        ds = channels.create_dataset(f"{order:03d}", data=np.asarray(ch.data, dtype=np.float64),
                                     compression="gzip", compression_opts=4, shuffle=True)
        ds.attrs["name"] = ch.name
        ds.attrs["quantity"] = ch.quantity
        ds.attrs["unit"] = ch.unit
        ds.attrs["source_unit"] = ch.source_unit
        ds.attrs["sample_rate_hz"] = float(ch.sample_rate_hz)
        ds.attrs["start_time_s"] = float(ch.start_time_s)
        ds.attrs["order"] = order


def _text(value: object) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def read_measurement_group(group: h5py.Group, *, where: str = "") -> Measurement:
    """Read a measurement group written by :func:`write_measurement_group`."""
    where = where or f"{group.file.filename}:{group.name}"
    if _text(group.attrs.get("pidcore_layout", "")) != LAYOUT_TAG or "channels" not in group:
        raise InputFileError(f"{where}: not a pidcore measurement group "
                             "(expected attribute pidcore_layout='measurement' and 'channels/')")
    channels = []
    for key in sorted(group["channels"]):
        ds = group["channels"][key]
        try:
            channels.append(Channel(
                name=_text(ds.attrs["name"]),
                quantity=_text(ds.attrs["quantity"]),
                data=np.asarray(ds[()], dtype=np.float64),
                sample_rate_hz=float(ds.attrs["sample_rate_hz"]),
                source_unit=_text(ds.attrs.get("source_unit", "")),
                start_time_s=float(ds.attrs.get("start_time_s", 0.0)),
            ))
        except KeyError as exc:
            raise InputFileError(f"{where}/channels/{key}: missing attribute {exc}") from None
    try:
        metadata = json.loads(_text(group.attrs.get("metadata_json", "{}")))
    except json.JSONDecodeError:
        raise InputFileError(f"{where}: attribute metadata_json is not valid JSON") from None
    return Measurement(
        source=_text(group.attrs.get("source", where)),
        channels=tuple(channels),
        sha256=_text(group.attrs.get("sha256", "")),
        file_format=_text(group.attrs.get("file_format", "hdf5")),
        metadata=metadata,
    )
