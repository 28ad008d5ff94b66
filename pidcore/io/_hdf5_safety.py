"""Checks of an HDF5 (or MATLAB v7.3) file from someone else, made before any data is read.

HDF5 lets a file make the library read *other* files on the machine: a dataset whose raw data
lives in an external file (``external=`` storage), an external link to an object of another
file, a virtual dataset mapping other files. A file uploaded to the app, or handed over with a
measurement, must never do that: :func:`check_hdf5_input` refuses all three. It also refuses a
file whose datasets declare far more bytes than the file holds (a compressed "bomb", or a
contiguous dataset larger than the file), before anything is decompressed into memory.
"""

from __future__ import annotations

import os

import h5py

from ..errors import InputFileError

#: Declared dataset bytes may exceed the file size by this factor (compressed data; measured
#: signals compress 1-3x, constant blocks far more).
MAX_EXPANSION_FACTOR = 50.0
#: ... and may always reach this many bytes (small files of constant data).
EXPANSION_ALLOWANCE_BYTES = 64 * 2**20
#: Declared dataset bytes never read, whatever the file size (the upload limit of the app is
#: far below it).
MAX_DECLARED_BYTES = 4 * 2**30
#: Filters HDF5 and h5py build in (deflate, shuffle, fletcher32, szip, n-bit, scale-offset,
#: LZF). Reading a dataset with any other filter makes HDF5 search its plugin directory and
#: load shared libraries from the machine, so such a dataset is refused before it is read.
BUILT_IN_FILTERS = frozenset({1, 2, 3, 4, 5, 6, 32000})
#: Deepest group nesting and most objects walked (a file can hard-link a group into itself).
MAX_DEPTH = 32
MAX_OBJECTS = 100_000


def _walk(group: h5py.Group, where: str, depth: int, counter: list[int], *,
          own_objects: bool = False) -> int:
    """Declared bytes of the datasets below ``group``; raises on links out of the file, and
    with ``own_objects`` on any soft link and any object linked under another name too."""
    if depth > MAX_DEPTH:
        raise InputFileError(f"{where}: groups nested deeper than {MAX_DEPTH} levels at "
                             f"{group.name!r}; refused (a group linked into itself?)")
    total = 0
    for name in group:
        counter[0] += 1
        if counter[0] > MAX_OBJECTS:
            raise InputFileError(f"{where}: more than {MAX_OBJECTS} HDF5 objects; refused")
        path = f"{group.name.rstrip('/')}/{name}"
        link = group.get(name, getlink=True)
        if isinstance(link, h5py.ExternalLink):
            raise InputFileError(f"{where}: {path!r} is an external link to "
                                 f"{link.filename!r}; refused: a file from elsewhere must not make "
                                 "pidcore read other files")
        if isinstance(link, h5py.SoftLink):
            if own_objects:
                raise InputFileError(f"{where}: {path!r} is a soft link to {link.path!r}; "
                                     "expected an object of its own (a link may lead out of it, "
                                     "to another record or to another file)")
            continue  # a path inside this file; its target is walked where it lives
        obj = group.get(name)
        if own_objects and obj is not None:
            _refuse_shared(obj, path, where)
        if isinstance(obj, h5py.Group):
            total += _walk(obj, where, depth + 1, counter, own_objects=own_objects)
        elif isinstance(obj, h5py.Dataset):
            if obj.is_virtual:
                raise InputFileError(f"{where}: dataset {path!r} is a virtual dataset (data "
                                     "mapped from other files); refused")
            plist = obj.id.get_create_plist()
            if plist.get_external_count() > 0:
                raise InputFileError(f"{where}: dataset {path!r} keeps its data in external "
                                     "file(s); refused: a file from elsewhere must not make "
                                     "pidcore read other files")
            for index in range(plist.get_nfilters()):
                filter_id = plist.get_filter(index)[0]
                if filter_id not in BUILT_IN_FILTERS:
                    raise InputFileError(
                        f"{where}: dataset {path!r} is compressed with HDF5 filter "
                        f"{filter_id}, which is not built in; refused: reading it would load "
                        "a plugin library from this machine (export without that filter, "
                        "or with gzip)")
            total += int(obj.size) * int(obj.dtype.itemsize)
    return total


def _refuse_shared(obj: h5py.Group | h5py.Dataset, path: str, where: str) -> None:
    links = h5py.h5o.get_info(obj.id).rc
    if links > 1:
        raise InputFileError(f"{where}: {path!r} is linked under {links} names in the file "
                             "(shared with another record); expected an object of its own")


def check_self_contained(group: h5py.Group, *, where: str) -> None:
    """Refuse what below ``group`` would make HDF5 read other files or load a plugin library
    (external links, external storage, virtual datasets, filters not built in), before any
    dataset below it is read: :func:`check_hdf5_input` for one part of an open file (an entry
    of a store, whose whole walk on every open would cost more than the reads it guards).
    ``group`` holds its own objects only, at any depth: a soft link (one to a root link to
    another file made get_dem_run read that file; one to another record's array gave its
    values) and an object hard-linked under a second name (another record's too) are
    refused as well.

    Raises
    ------
    InputFileError
        Naming ``where`` and the offending object.
    """
    _refuse_shared(group, group.name, where)
    _walk(group, where, 0, [0], own_objects=True)


def check_hdf5_input(path: str | os.PathLike[str], *, what: str = "HDF5") -> None:
    """Refuse external storage, external links, virtual datasets, filters that are not built
    in (HDF5 would load a plugin library for them) and oversized declarations.

    Raises
    ------
    InputFileError
        Naming the file and the offending object, before any dataset is read.
    """
    where = str(path)
    size = os.path.getsize(path)
    try:
        with h5py.File(path, "r") as h5:
            declared = _walk(h5, where, 0, [0])
    except OSError as exc:
        raise InputFileError(f"{where}: not a readable {what} file ({exc})") from None
    limit = min(MAX_DECLARED_BYTES, max(MAX_EXPANSION_FACTOR * size, EXPANSION_ALLOWANCE_BYTES))
    if declared > limit:
        raise InputFileError(f"{where}: its datasets declare {declared / 2**20:.1f} MiB in a "
                             f"{size / 2**20:.2f} MiB file (limit {limit / 2**20:.0f} MiB); "
                             "refused before reading")
