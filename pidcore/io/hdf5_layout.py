"""pidcore's HDF5 layout of one measurement group, shared by the HDF5 reader and the store.

A measurement group holds one dataset per channel under ``channels/``. Attributes carry units
and provenance so that the file explains itself without pidcore::

    <group>/                attrs: pidcore_layout="measurement", source, sha256, file_format,
                                   metadata_json
    <group>/channels/<i>    samples in SI, float64, or float32 where every sample is one
                            (read back as float64, the same bits); shuffle + gzip;
                            attrs: name, quantity, unit (SI), source_unit, sample_rate_hz,
                            start_time_s, order

Channel datasets are keyed by position (``"000"``, ``"001"``) because channel names may hold
characters HDF5 treats as path separators.
"""

from __future__ import annotations

import json

import h5py
import numpy as np

from ..errors import InputFileError
from ..records import Channel, Measurement
from ._common import real_samples, real_scalar, refuse_unit_other_than_si

LAYOUT_TAG = "measurement"
#: Samples compared at a time when deciding whether a channel is float32 (8 MB widened).
_EXACTNESS_BLOCK = 2**20


def _stored_samples(data: object) -> np.ndarray:
    """The samples of a channel as written: float32 where every sample is a float32 value,
    else float64. Binary exports (UFF58b, MATLAB single) hold float32 samples; written as
    float64, half of each sample's bytes were zeros, which shuffle and gzip do not take away
    entirely: as float32, two real 58b exports take 8-9 % fewer bytes in the store, a
    10-minute 8-channel record 4.5 % (and 28 % less CPU time to compress). Widening a float32
    is exact, so readers get the same float64 bits; the test is on the bits, so a NaN whose
    payload float32 cannot hold stays float64."""
    samples = np.asarray(data, dtype=np.float64)
    with np.errstate(over="ignore"):  # beyond float32's range: inf, and the test below fails
        narrow = samples.astype(np.float32)
    bits = samples.view(np.uint64)
    # in blocks: the widened copy of a whole 10-minute channel added 120 MB to the peak
    for start in range(0, samples.size, _EXACTNESS_BLOCK):
        block = slice(start, start + _EXACTNESS_BLOCK)
        if not np.array_equal(narrow[block].astype(np.float64).view(np.uint64), bits[block]):
            return samples
    return narrow


def write_measurement_group(group: h5py.Group, measurement: Measurement) -> None:
    """Write ``measurement`` into an (empty) HDF5 group."""
    group.attrs["pidcore_layout"] = LAYOUT_TAG
    group.attrs["source"] = measurement.source
    group.attrs["sha256"] = measurement.sha256
    group.attrs["file_format"] = measurement.file_format
    group.attrs["metadata_json"] = json.dumps(dict(measurement.metadata), default=str)
    # track_order makes HDF5 write version-2 object headers, which carry a checksum that
    # every read checks: a bit flipped in a channel's sample_rate_hz (25600 -> 27648) was read
    # as it stood (54 Hz for 50 Hz) where the same flip in an analysis's record is refused.
    # The caller creates ``group`` the same way (:func:`metadata_checksummed`).
    channels = group.create_group("channels", track_order=True)
    for order, ch in enumerate(measurement.channels):
        ds = channels.create_dataset(f"{order:03d}", data=_stored_samples(ch.data),
                                     compression="gzip", compression_opts=4, shuffle=True,
                                     track_order=True)
        ds.attrs["name"] = ch.name
        ds.attrs["quantity"] = ch.quantity
        ds.attrs["unit"] = ch.unit
        ds.attrs["source_unit"] = ch.source_unit
        ds.attrs["sample_rate_hz"] = float(ch.sample_rate_hz)
        ds.attrs["start_time_s"] = float(ch.start_time_s)
        ds.attrs["order"] = order


def metadata_checksummed(obj: h5py.Group | h5py.Dataset) -> bool:
    """Whether HDF5 checks a checksum of ``obj``'s attributes and links on every read (a
    version-2 object header, which :func:`write_measurement_group` writes; earlier pidcore
    versions wrote version 1, without one)."""
    return h5py.h5o.get_info(obj.id).hdr.version >= 2


def _text(value: object) -> str:
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def _channel_dataset(channels: h5py.Group, key: str, where: str) -> h5py.Dataset:
    # opened where hard-linked, so a header failing its checksum is HDF5's error, not None
    # (then "a link to nothing"); get() is None for a soft link to nothing
    link = channels.get(key, getlink=True)
    try:
        item = channels[key] if isinstance(link, h5py.HardLink) else channels.get(key)
    except KeyError as exc:  # h5py's KeyError for an object HDF5 could not open
        raise InputFileError(f"{where}/channels/{key}: cannot be read "
                             f"({exc.args[0] if exc.args else exc})") from None
    if not isinstance(item, h5py.Dataset):
        what = "a link to nothing" if item is None else "a group"
        raise InputFileError(f"{where}/channels/{key}: is {what}; expected a dataset of samples")
    if h5py.check_enum_dtype(item.dtype) is not None:
        raise InputFileError(f"{where}/channels/{key}: samples are enumerated labels; "
                             "expected real numbers")
    return item


def read_measurement_group(group: h5py.Group, *, where: str = "") -> Measurement:
    """Read a measurement group written by :func:`write_measurement_group`.

    Raises
    ------
    InputFileError
        Not a measurement group, or a channel that is not a vector of real numbers (complex,
        text, compound, enumerated, references, a matrix, no samples), a link to nothing, or a
        sample rate or start time that is not a finite number (the rate also > 0).
    """
    where = where or f"{group.file.filename}:{group.name}"
    channels_group = group.get("channels")
    if _text(group.attrs.get("pidcore_layout", "")) != LAYOUT_TAG \
            or not isinstance(channels_group, h5py.Group):
        raise InputFileError(f"{where}: not a pidcore measurement group "
                             "(expected attribute pidcore_layout='measurement' and 'channels/')")
    channels = []
    for key in sorted(channels_group):
        ds = _channel_dataset(channels_group, key, where)
        at = f"{where}/channels/{key}"
        refuse_unit_other_than_si(_text(ds.attrs.get("quantity", "")),
                                  _text(ds.attrs.get("unit", "")), where=f"{at}: attribute unit")
        try:
            channels.append(Channel(
                name=_text(ds.attrs["name"]),
                quantity=_text(ds.attrs["quantity"]),
                data=real_samples(ds[()], where=at),
                sample_rate_hz=real_scalar(ds.attrs["sample_rate_hz"],
                                           where=f"{at}: attribute sample_rate_hz",
                                           positive=True),
                source_unit=_text(ds.attrs.get("source_unit", "")),
                start_time_s=real_scalar(ds.attrs.get("start_time_s", 0.0),
                                         where=f"{at}: attribute start_time_s"),
            ))
        except KeyError as exc:
            raise InputFileError(f"{at}: missing attribute {exc}") from None
    try:
        metadata = json.loads(_text(group.attrs.get("metadata_json", "{}")))
    except json.JSONDecodeError:
        raise InputFileError(f"{where}: attribute metadata_json is not valid JSON") from None
    if not isinstance(metadata, dict):
        raise InputFileError(f"{where}: attribute metadata_json holds a "
                             f"{type(metadata).__name__}; expected a JSON object")
    notes = metadata.get("reader_notes", [])
    if not isinstance(notes, list) or not all(isinstance(n, str) for n in notes):
        raise InputFileError(f"{where}: metadata_json's reader_notes is not a list of text")
    return Measurement(
        source=_text(group.attrs.get("source", where)),
        channels=tuple(channels),
        sha256=_text(group.attrs.get("sha256", "")),
        file_format=_text(group.attrs.get("file_format", "hdf5")),
        metadata=metadata,
    )
