"""pidcore HDF5 files: one measurement group (:mod:`pidcore.io.hdf5_layout`) at the root, or a
store whose ``/measurements/<key>`` groups are measurement groups.

The file read is what the user named, so ``source`` and ``sha256`` describe this file; the
provenance stored in the group (the original file's name, hash and format) is kept in
``metadata`` as ``original_source``, ``original_sha256`` and ``original_file_format``.
"""

from __future__ import annotations

import os
from dataclasses import replace

import h5py

from ..atomic_files import atomic_path
from ..errors import InputFileError, ParameterError
from ..records import Measurement
from ._common import file_sha256, unique_names
from ._hdf5_safety import check_hdf5_input
from .hdf5_layout import LAYOUT_TAG, read_measurement_group, write_measurement_group

MEASUREMENTS_GROUP = "measurements"


def _is_measurement(group: h5py.Group | None) -> bool:
    if not isinstance(group, h5py.Group):  # a dataset, or None for a soft link to nothing
        return False
    tag = group.attrs.get("pidcore_layout", "")
    return (tag.decode() if isinstance(tag, bytes) else str(tag)) == LAYOUT_TAG


def _as_read(measurement: Measurement, where: str, sha256: str) -> Measurement:
    metadata = dict(measurement.metadata)
    metadata.update(original_source=measurement.source, original_sha256=measurement.sha256,
                    original_file_format=measurement.file_format)
    # two datasets may carry one name; as every reader does, the second becomes 'Force (2)',
    # so that a channel can be chosen by name (a name given chose the first without a word)
    names = unique_names([c.name for c in measurement.channels])
    channels = tuple(c if c.name == n else replace(c, name=n)
                     for c, n in zip(measurement.channels, names, strict=True))
    return Measurement(source=where, channels=channels, sha256=sha256,
                       file_format="hdf5", metadata=metadata)


def hdf5_keys(path: str | os.PathLike[str]) -> list[str]:
    """Keys of the measurements in a pidcore HDF5 file (``[""]`` for a root measurement).

    The file is checked first (:func:`pidcore.io._hdf5_safety.check_hdf5_input`): external
    storage, external links and virtual datasets are refused before any data is read.
    """
    where = str(path)
    check_hdf5_input(where)
    try:
        with h5py.File(where, "r") as h5:
            if _is_measurement(h5):
                return [""]
            group = h5.get(MEASUREMENTS_GROUP)
            if isinstance(group, h5py.Group):
                keys = sorted(k for k in group if _is_measurement(group.get(k)))
                if keys:
                    return keys
            holds = _contents(h5)
    except OSError as exc:
        raise InputFileError(f"{where}: not a readable HDF5 file ({exc})") from None
    raise InputFileError(f"{where}: holds no measurements ({holds}); expected a root group with "
                         f"pidcore_layout='measurement' or measurements under "
                         f"'/{MEASUREMENTS_GROUP}/'")


def hdf5_key_sources(path: str | os.PathLike[str], keys: list[str]) -> dict[str, str]:
    """The file name each measurement ``key`` of a store was imported from (its ``source``,
    without folders), for a message that asks the user to choose one by key: the keys alone
    are hashes that say nothing of which test is which. A key without one is left out."""
    names: dict[str, str] = {}
    with h5py.File(str(path), "r") as h5:  # checked by hdf5_keys before any key is known
        group = h5.get(MEASUREMENTS_GROUP)
        for key in keys:
            item = group.get(key) if isinstance(group, h5py.Group) else None
            source = item.attrs.get("source") if isinstance(item, h5py.Group) else None
            if isinstance(source, bytes):
                source = source.decode("utf-8", "replace")
            if isinstance(source, str) and source.strip():
                names[key] = os.path.basename(source.strip())
    return names


def _contents(h5: h5py.File) -> str:
    """What a file without measurements holds, for the message: ``48 dem_runs, ...``."""
    parts = [f"{len(item)} {name}" if isinstance(item, h5py.Group) else name
             for name, item in ((name, h5.get(name)) for name in h5)]
    nonempty = [p for p in parts if not p.startswith("0 ")]
    return ", ".join(nonempty) if nonempty else "nothing"


def read_hdf5(path: str | os.PathLike[str], *, key: str | None = None) -> list[Measurement]:
    """Read the measurement(s) of a pidcore HDF5 file.

    Parameters
    ----------
    path : str or path-like
    key : str, optional
        Read only ``/measurements/<key>``; an unknown key raises :class:`InputFileError`
        listing the keys there are.
    """
    where = str(path)
    keys = hdf5_keys(where)
    if key is not None and keys != [""]:
        if key not in keys:
            raise InputFileError(f"{where}: no measurement {key!r}; keys are "
                                 f"{', '.join(keys) or 'none'}")
        keys = [key]
    sha = file_sha256(where)
    try:
        with h5py.File(where, "r") as h5:
            if keys == [""]:
                return [_as_read(read_measurement_group(h5, where=where), where, sha)]
            return [_as_read(read_measurement_group(h5[MEASUREMENTS_GROUP][k],
                                                    where=f"{where}:/{MEASUREMENTS_GROUP}/{k}"),
                             where, sha) for k in keys]
    except OSError as exc:  # h5py raises OSError for damaged chunks
        raise InputFileError(f"{where}: corrupt HDF5 data ({exc})") from None


def write_hdf5(measurement: Measurement, path: str | os.PathLike[str]) -> None:
    """Write one measurement group at the root of a new HDF5 file, atomically."""
    if not measurement.channels:
        raise ParameterError(f"{measurement.source}: nothing to write (no channels)")
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
        write_measurement_group(h5, measurement)
