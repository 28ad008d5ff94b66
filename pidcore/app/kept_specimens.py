"""Specimen files uploaded to the app, kept over a page reload (free of Streamlit).

The DEM and Calibrate forms keep their fields in the page address, which cannot hold a file:
after a reload the uploader is empty and the form ran the paper's coupon (or the specimen
list's choice) instead. An uploaded specimen file is therefore kept, as uploaded, in a folder
beside the app store (:func:`kept_specimens_folder`), named by its specimen's sha256
(:attr:`pidcore.specimen.Specimen.hash`, the hash its DEM runs and saved tests carry and the
pages show, ``steel_6mm [beeac8]``); the address holds that hash, never the text, and a reload
restores the file from the folder.

The folder is written only with files that :meth:`pidcore.specimen.Specimen.from_bytes` (the
checker of ``pidcore specimen check``) accepts, and a kept file is checked again when it is
restored: an upload is only ever parsed as TOML, never executed or unpickled. An address is
only ever read as a hash (64 hexadecimal digits), so it cannot name another file.
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..atomic_files import write_atomically
from ..errors import ParameterError

if TYPE_CHECKING:
    from ..specimen import Specimen

#: Folder of the kept specimen files, beside the store (``<store>.specimens``), as the
#: jobs journal is (``<store>.jobs.json``): not in the store, whose every write changes its
#: stamp and re-reads every listing.
KEPT_FOLDER_SUFFIX = ".specimens"
#: A kept file's bytes are ``<sha256>.toml``; the name it was uploaded under ``<sha256>.json``.
_DATA_SUFFIX = ".toml"
_NAME_SUFFIX = ".json"
_SHA256 = re.compile(r"[0-9a-f]{64}")


def kept_specimens_folder(store_path: str | os.PathLike) -> Path:
    """The folder of the specimen files uploaded to the app of the store ``store_path``."""
    return Path(f"{store_path}{KEPT_FOLDER_SUFFIX}")


@dataclass(frozen=True)
class KeptSpecimen:
    """An uploaded specimen file: the ``name`` it was uploaded under, its specimen's
    ``sha256`` (what the page address holds), the bytes as uploaded and the specimen read from
    them."""

    name: str
    sha256: str
    data: bytes
    specimen: Specimen


def keep_specimen(folder: str | os.PathLike, name: str,
                  data: bytes) -> tuple[KeptSpecimen, str]:
    """Check the uploaded specimen file ``name`` (``data``) as ``pidcore specimen check``
    does and keep it in ``folder`` under its sha256; returns it and ``""``, or, where the
    folder cannot be written, the one-line reason it will not survive a reload (the file is
    still used for this page).

    Raises
    ------
    ParameterError
        The file is not a specimen file: one line naming ``name`` and the key.
    """
    from ..specimen import Specimen

    specimen = Specimen.from_bytes(data, source=name)  # before anything is written
    sha256 = specimen.hash
    kept = KeptSpecimen(name, sha256, data, specimen)
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        target = folder / f"{sha256}{_DATA_SUFFIX}"
        if not target.is_file():  # same hash, same specimen: written once
            # whole or not at all: another session may restore the same hash meanwhile
            write_atomically(target, data)
        label = folder / f"{sha256}{_NAME_SUFFIX}"
        if _kept_name(label) != name:  # the name it was uploaded under last
            write_atomically(label, json.dumps({"name": name}).encode())
    except OSError as exc:
        return kept, (f"{name}: not kept for a page reload: cannot write {folder} "
                      f"({exc.strerror or exc}); upload it again after a reload")
    return kept, ""


def _kept_name(path: Path) -> str | None:
    try:
        name = json.loads(path.read_text(encoding="utf-8")).get("name")
    except (OSError, ValueError, AttributeError):
        return None
    return name if isinstance(name, str) and name else None


def restore_specimen(folder: str | os.PathLike, sha256: str, *,
                     where: str = "the page address") -> KeptSpecimen:
    """The specimen file kept under ``sha256`` in ``folder`` (:func:`keep_specimen`), checked
    again as an upload is.

    Raises
    ------
    ParameterError
        One line, naming ``where`` the hash came from: it is not a sha256, no file of it is
        kept here (uploaded to another store's app, or the folder was cleared), or the kept
        file is no longer the one uploaded or no longer a specimen file.
    """
    from ..specimen import MAX_SPECIMEN_FILE_BYTES, Specimen

    if not isinstance(sha256, str) or not _SHA256.fullmatch(sha256):
        shown = repr(sha256[:80]) if isinstance(sha256, str) else repr(sha256)
        raise ParameterError(f"specimen file {shown} (from {where}): expected the sha256 of "
                             "an uploaded specimen file (64 lowercase hexadecimal digits); "
                             "upload the specimen file again")
    path = Path(folder) / f"{sha256}{_DATA_SUFFIX}"
    try:
        with path.open("rb") as file:
            data = file.read(MAX_SPECIMEN_FILE_BYTES + 1)
    except FileNotFoundError:
        raise ParameterError(f"specimen file {sha256[:12]} (from {where}): not an uploaded "
                             f"specimen file this app keeps (none in {folder}); upload the "
                             "specimen file again") from None
    except OSError as exc:
        raise ParameterError(f"specimen file {sha256[:12]} (from {where}): cannot read "
                             f"{path} ({exc.strerror or exc}); upload the specimen file "
                             "again") from None
    name = _kept_name(Path(folder) / f"{sha256}{_NAME_SUFFIX}") or f"{sha256[:12]}.toml"
    specimen = Specimen.from_bytes(data, source=name)
    if specimen.hash != sha256:
        raise ParameterError(f"{name} (specimen file {sha256[:12]}, from {where}): the kept "
                             f"file {path} was changed since it was uploaded; upload the "
                             "specimen file again")
    return KeptSpecimen(name, sha256, data, specimen)


@dataclass(frozen=True)
class SpecimenUpload:
    """A form's uploaded specimen file after one script run (:func:`specimen_upload`).

    ``kept``: the file in use (uploaded now, or restored from the page address); ``sha256``:
    what the address holds (None: nothing); ``upload_seen``: whether this session's uploader
    holds a file (removing it then forgets the file, a reload does not); ``error``: why the
    file is refused, one line; ``note``: a line to show beside it ("" for none)."""

    kept: KeptSpecimen | None = None
    sha256: str | None = None
    upload_seen: bool = False
    error: str | None = None
    note: str = ""


def specimen_upload(folder: str | os.PathLike, *, upload: tuple[str, bytes] | None,
                    sha256: str | None, upload_seen: bool) -> SpecimenUpload:
    """The uploaded specimen file of a form after a script run.

    ``upload``: what the uploader holds now (``(name, bytes)``); ``sha256`` and
    ``upload_seen``: the last run's :class:`SpecimenUpload` (a fresh session: the page
    address's hash and False). An upload is checked and kept (:func:`keep_specimen`) and its
    hash goes to the address; an empty uploader after a reload restores the address's file
    (:func:`restore_specimen`: an unknown hash is refused in one line, never replaced by
    another specimen); an uploader emptied by the user forgets it.
    """
    if upload is not None:
        name, data = upload
        try:
            kept, problem = keep_specimen(folder, name, data)
        except ParameterError as exc:
            # a refused file is not kept: the address must not name it after a reload
            return SpecimenUpload(upload_seen=True, error=str(exc))
        return SpecimenUpload(kept, None if problem else kept.sha256, True, note=problem)
    if upload_seen or not sha256:  # the user removed the file (or there was none)
        return SpecimenUpload()
    try:
        kept = restore_specimen(folder, sha256)
    except ParameterError as exc:
        return SpecimenUpload(sha256=sha256, error=str(exc))
    from ..specimen import hashed_name

    # named as the pages name its DEM runs and tests, so the three are seen to be one file
    return SpecimenUpload(kept, sha256, note=(
        f"{kept.name} ({hashed_name(kept.specimen.name, sha256)}): the specimen file uploaded "
        "before the page was reloaded, kept beside the store; upload another file to replace "
        "it"))
