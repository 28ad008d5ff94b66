"""What the store accepts as names, record values, arrays and parameters, and how it writes them.

Record values are scalars written as HDF5 attributes: strings as UTF-8, integers and booleans
as int64, reals as float64, complex numbers as complex128. ``None`` is written as NaN and its
field is listed in the entry's ``null_fields_json`` attribute so that it reads back as ``None``.
Parameters are written as canonical JSON (sorted keys), which also defines the analysis key.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping
from pathlib import PurePath
from typing import Any

import numpy as np

from ..errors import StoreError

#: A value of one record field.
Scalar = str | int | float | bool | complex | None

#: Column names of the listing tables; record fields may not use them.
RESERVED_FIELDS = frozenset({
    "key", "measurement_key", "case_key", "source", "created_utc", "pidcore_version",
    "parameters_json",
})

#: Array dtype kinds the store writes: bool, signed/unsigned int, float, complex.
_ARRAY_KINDS = frozenset("biufc")

_INT64_MIN, _INT64_MAX = -(2**63), 2**63 - 1

#: Longest name of an HDF5 group, dataset or attribute the store writes, characters.
MAX_NAME_CHARS = 255
#: Longest text of a record field, characters: a name (a material, a channel, a specimen) is
#: at most :data:`MAX_NAME_CHARS`, a note of the analysis a sentence of a few hundred, the
#: longest a file's path (``source``), which Linux allows up to PATH_MAX, 4096 bytes. A
#: material of 40 KiB took 3 minutes in the messages quoting it (their cost grows with the
#: square of its length; 4 KiB: seconds), one of 1 MiB did not end; such a field is refused
#: where it is written and where it is read.
MAX_TEXT_CHARS = 4096


def check_name(name: object, *, what: str, where: str) -> str:
    """``name`` if it can be an HDF5 group, dataset or attribute name, else :class:`StoreError`."""
    if (not isinstance(name, str) or not name or "/" in name or name in {".", ".."}
            or name != name.strip() or any(ord(c) < 32 for c in name)
            or len(name) > MAX_NAME_CHARS):
        raise StoreError(f"{where}: {what} {name!r} is not valid (expected a non-empty "
                         f"string of at most {MAX_NAME_CHARS} characters without '/', control "
                         "characters or surrounding spaces)")
    return name


def to_attribute(value: object, *, field: str, where: str) -> tuple[Any, bool]:
    """Convert a record value to what is written; returns ``(value, was_none)``."""
    if value is None:
        return np.float64(math.nan), True
    if isinstance(value, bool | np.bool_):
        return np.int64(int(value)), False
    if isinstance(value, int | np.integer):
        if not _INT64_MIN <= int(value) <= _INT64_MAX:
            raise StoreError(f"{where}: record field {field!r} = {value} does not fit in int64")
        return np.int64(value), False
    if isinstance(value, float | np.floating):
        return np.float64(value), False
    if isinstance(value, complex | np.complexfloating):
        return np.complex128(value), False
    if isinstance(value, str):
        # HDF5's variable-length strings are UTF-8 and end at a NUL: h5py raised ValueError
        # or UnicodeEncodeError from inside the transaction, a traceback, not one line
        if "\x00" in value:
            raise StoreError(f"{where}: record field {field!r} = {value!r} holds a NUL "
                             "character, which an HDF5 string cannot hold")
        try:
            value.encode("utf-8")
        except UnicodeEncodeError:
            raise StoreError(f"{where}: record field {field!r} = {value!r} is not valid "
                             "Unicode (a lone surrogate); expected text UTF-8 can hold") from None
        if len(value) > MAX_TEXT_CHARS:
            raise StoreError(f"{where}: record field {field!r} is text of {len(value)} "
                             f"characters; expected at most {MAX_TEXT_CHARS}")
        return value, False
    raise StoreError(f"{where}: record field {field!r} has type {type(value).__name__}; expected a "
                     "scalar (str, int, float, bool, complex or None); put arrays in arrays=")


def from_attribute(value: Any) -> Scalar:
    """Python scalar of an attribute value read back from HDF5."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    if isinstance(value, np.generic):
        return value.item()
    return value


def to_array(value: object, *, name: str, where: str) -> np.ndarray:
    """``value`` as a numeric (bool, int, float, complex) array, else :class:`StoreError`."""
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise StoreError(f"{where}: array {name!r} cannot be converted to an array "
                         f"({exc})") from None
    if array.dtype.kind not in _ARRAY_KINDS:
        raise StoreError(f"{where}: array {name!r} has dtype {array.dtype}; expected a numeric "
                         "(bool, integer, float or complex) array")
    return array


def _json_default(value: object) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, PurePath):
        return str(value)
    raise TypeError(f"value of type {type(value).__name__} is not JSON-serialisable")


def parameters_to_json(parameters: object, *, where: str) -> str:
    """Canonical JSON text of ``parameters`` (sorted keys, no whitespace)."""
    if not isinstance(parameters, Mapping):
        raise StoreError(f"{where}: parameters must be a mapping, got {type(parameters).__name__}")
    try:
        return json.dumps(dict(parameters), sort_keys=True, separators=(",", ":"),
                          default=_json_default)
    except (TypeError, ValueError) as exc:
        raise StoreError(f"{where}: parameters cannot be written as JSON ({exc})") from None


def analysis_key(measurement_key: str, parameters_json: str) -> str:
    """Key of an analysis: first 16 hex digits of SHA-256 over measurement key and parameters.

    The same measurement analysed with the same parameters gets the same key, so re-analysing
    replaces the entry instead of adding a second one.
    """
    text = f"{measurement_key}\n{parameters_json}"
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]
