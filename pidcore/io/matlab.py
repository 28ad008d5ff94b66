"""MATLAB ``.mat`` files (v5 via :func:`scipy.io.loadmat`, v7.3 via :mod:`h5py`).

Three layouts are understood, tried in this order:

1. **pidcore layout** (what :func:`write_mat` writes): ``pidcore_layout = 'measurement'`` and
   ``pidcore_channels``, a cell array of structs with fields ``name``, ``quantity``, ``unit``
   (SI), ``source_unit``, ``data`` (SI samples), ``sample_rate_hz``, ``start_time_s``.
2. **LMS Test.Lab export**: a struct (or struct array) ``Signal`` with
   ``x_values.start_value``, ``x_values.increment`` (in the unit ``x_values.quantity`` states
   like ``y_values.quantity``, else s), ``x_values.number_of_values``,
   ``y_values.values`` (one column per channel) and, where present,
   ``function_record.name`` (channel name; a cell of names for several columns) and the unit in
   ``y_values.quantity`` (fields ``unit``/``units``/``unit_label``, a unit struct
   ``unit.label``, or ``quantity_terms(k).unit.label`` with exponents, else ``label``, its
   case kept: ``mN`` is no ``MN``; only a bare quantity name such as ``'Acceleration'``, in
   any case, is taken as that quantity in SI, the unit Test.Lab exports in). Test.Lab may
   store SI values and show them in the label's unit, ``quantity.unit_transformation.factor``
   taking one to the other (display = SI x factor: ``'g'`` with 0.10197, ``'mm/s'`` with
   1000): a factor that is the reciprocal of a stated unit's SI factor (within 1e-4) reads
   the values in SI, with a note; a factor of 1, or none, reads them in the stated unit;
   another factor, or an offset, on a unit pidcore reads is refused (a unit it does not
   read, a temperature's, stays unknown). The same holds for ``x_values``.
   v7.3 struct *arrays* (``Signal(1)``, ``Signal(2)``, ...) are read like v5 ones.
3. **simple layout**: a time vector ``time`` or ``t`` (s) plus one numeric vector per channel
   (the variable name is the channel name; beside a time vector only vectors of its length),
   optionally ``units`` as a struct (``units.Force = 'kN'``) or a cell of unit strings, one
   per channel variable in their order: a cell of another length is refused, naming the
   variables taken as channels (a helper vector such as ``window`` counts as one, and
   shifted every unit after it). Without a time vector, a scalar ``sample_rate_hz`` /
   ``fs`` or the reader's ``sample_rate_hz`` argument gives the time base.

Nothing in a ``.mat`` file is executed or unpickled: loadmat reads plain arrays and structs;
MATLAB objects (``MCOS``) are ignored.
"""

from __future__ import annotations

import os
import struct
import zlib
from collections.abc import Mapping

import h5py
import numpy as np
import scipy.io

from ..atomic_files import atomic_path
from ..constants import SI_UNITS
from ..errors import InputFileError, ParameterError, listed
from ..records import Channel, Measurement
from ..units import (
    UnitReading,
    given_time_unit,
    overrides_stated_time,
    read_unit,
    why_not_a_time_unit,
)
from ._common import (
    HDF5_SIGNATURE,
    file_sha256,
    make_channel,
    overridden_rate,
    rate_from_times,
    real_numbers,
    real_samples,
    real_scalar,
    refuse_unit_other_than_si,
    reraise_interrupt,
    unique_names,
)
from ._hdf5_safety import (
    EXPANSION_ALLOWANCE_BYTES,
    MAX_DECLARED_BYTES,
    MAX_EXPANSION_FACTOR,
    check_hdf5_input,
)

_TIME_VARIABLES = ("time", "t", "Time", "T")
_RATE_VARIABLES = ("sample_rate_hz", "fs", "Fs", "sample_rate")


def _as_list(value: object) -> list:
    if value is None:
        return []
    if isinstance(value, list | tuple):
        return list(value)
    if isinstance(value, np.ndarray) and value.dtype == object:
        return list(value.ravel())
    return [value]


def _text(value: object) -> str:
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, str):
        return value
    if isinstance(value, np.ndarray) and value.dtype.kind in "US":
        return "".join(str(v) for v in value.ravel())
    return ""


def _numeric_vector(value: object) -> np.ndarray | None:
    if isinstance(value, np.ndarray) and value.dtype.kind in "fiub" and value.size >= 2:
        squeezed = np.squeeze(value)
        if squeezed.ndim == 1:
            return squeezed.astype(np.float64, copy=False)  # float64 as loaded: no copy
    return None


# --- v7.3 (HDF5) -> the same nested dict/list/array shape loadmat(simplify_cells=True) gives


def _struct_array_fields(group: h5py.Group) -> list[str] | None:
    """Field names when ``group`` is a MATLAB struct *array* (not 1x1), else None.

    v7.3 stores a 1x1 struct as a group of its field values, but a struct array as a group
    whose every field is an array of object references (one per element) without a
    ``MATLAB_class`` of its own.
    """
    if _attr_text(group, "MATLAB_class") != "struct":
        return None
    fields = [k for k in group if not k.startswith("#")]
    shapes = set()
    for k in fields:
        item = group[k]
        if not isinstance(item, h5py.Dataset) or item.dtype != h5py.ref_dtype \
                or _attr_text(item, "MATLAB_class"):
            return None
        shapes.add(item.shape)
    return fields if fields and len(shapes) == 1 else None


def _attr_text(obj: h5py.Group | h5py.Dataset, name: str) -> str:
    value = obj.attrs.get(name, b"")
    return value.decode() if isinstance(value, bytes) else str(value)


#: Deepest nesting of structs, cells and references read from a v7.3 file (a reference can
#: point back at the cell that holds it).
MAX_V73_DEPTH = 32


def _member(group: h5py.Group, name: str) -> h5py.Group | h5py.Dataset:
    item = group.get(name)  # None for a soft link to nothing
    if item is None:
        raise InputFileError(f"{group.file.filename}: {group.name.rstrip('/')}/{name} is a link "
                             "to nothing; expected a MATLAB variable or field")
    return item


def _dereference(file: h5py.File, ref: object, where: str) -> h5py.Group | h5py.Dataset:
    try:
        return file[ref]
    except (ValueError, KeyError, TypeError) as exc:
        raise InputFileError(f"{file.filename}: {where} holds an invalid reference ({exc}); "
                             "expected a MATLAB cell or struct array") from None


def _chars(data: object, where: str) -> str:
    codes = np.asarray(data).T.ravel()
    if codes.dtype.kind not in "iu" or (codes.size and (codes.min() < 0
                                                        or codes.max() > 0x10FFFF)):
        raise InputFileError(f"{where} is a char array of values that are no characters")
    return "".join(chr(c) for c in codes)


def _h5_value(obj: h5py.Group | h5py.Dataset, file: h5py.File, depth: int = 0) -> object:
    if depth > MAX_V73_DEPTH:
        raise InputFileError(f"{file.filename}: {obj.name} nests cells, structs or references "
                             f"deeper than {MAX_V73_DEPTH} levels (a reference to itself?); "
                             "refused")
    if isinstance(obj, h5py.Group):
        fields = _struct_array_fields(obj)
        if fields is not None:  # struct array -> list of dicts, as loadmat gives
            columns = {k: [_h5_value(_dereference(file, ref, obj[k].name), file, depth + 1)
                           for ref in np.asarray(obj[k][()]).T.ravel()]
                       for k in fields}
            n = len(next(iter(columns.values())))
            return [{k: columns[k][i] for k in fields} for i in range(n)]
        return {k: _h5_value(_member(obj, k), file, depth + 1)
                for k in obj if not k.startswith("#")}
    matlab_class = obj.attrs.get("MATLAB_class", b"")
    matlab_class = matlab_class.decode() if isinstance(matlab_class, bytes) else matlab_class
    data = obj[()]
    if matlab_class == "char":
        return _chars(data, f"{file.filename}: {obj.name}")
    if obj.dtype == h5py.ref_dtype:
        return [_h5_value(_dereference(file, ref, obj.name), file, depth + 1)
                for ref in np.asarray(data).T.ravel()]
    if obj.attrs.get("MATLAB_empty", 0):
        return np.zeros(0)
    arr = np.asarray(data)
    return np.squeeze(arr.T) if arr.ndim > 1 else arr  # MATLAB is column-major


def _load_v73(path: str) -> dict:
    check_hdf5_input(path, what="MATLAB v7.3 (HDF5)")
    with h5py.File(path, "r") as h5:
        return {k: _h5_value(_member(h5, k), h5) for k in h5 if not k.startswith("#")}


_V5_COMPRESSED, _V5_CHUNK = 15, 1 << 20


def _check_v5_expansion(path: str) -> None:
    """Refuse a v5 file whose compressed variables inflate to far more than the file holds
    (a 2 MB file of zeros declaring 2 GB made scipy allocate them all), with the limits of
    HDF5 uploads (:mod:`pidcore.io._hdf5_safety`), streaming: nothing inflated is kept."""
    size = os.path.getsize(path)
    limit = min(MAX_DECLARED_BYTES, max(MAX_EXPANSION_FACTOR * size, EXPANSION_ALLOWANCE_BYTES))
    total = 0
    with open(path, "rb") as fh:
        header = fh.read(128)
        order = ">" if header[126:128] == b"MI" else "<"
        while len(tag := fh.read(8)) == 8:
            data_type, nbytes = struct.unpack(f"{order}II", tag)
            if data_type >> 16:  # small data element: its bytes are in the tag
                continue
            if data_type != _V5_COMPRESSED:
                total += nbytes
                fh.seek(nbytes + (-nbytes) % 8, os.SEEK_CUR)
            else:
                inflate, left = zlib.decompressobj(), nbytes
                while left > 0 and total <= limit and (chunk := fh.read(min(left, _V5_CHUNK))):
                    left -= len(chunk)
                    try:
                        total += len(inflate.decompress(chunk, _V5_CHUNK))
                        while inflate.unconsumed_tail and total <= limit:
                            total += len(inflate.decompress(inflate.unconsumed_tail, _V5_CHUNK))
                    except zlib.error:
                        return  # corrupt: scipy says so in its own words
            if total > limit:
                raise InputFileError(f"{path}: its variables inflate to more than "
                                     f"{limit / 2**20:.0f} MiB in a {size / 2**20:.2f} MiB "
                                     "file; refused before reading (a compressed 'bomb'?)")


def _load(path: str) -> dict:
    with open(path, "rb") as fh:
        head = fh.read(520)
    if not head:
        raise InputFileError(f"{path}: empty file; expected a MATLAB .mat file")
    if head.startswith(b"MATLAB 7.3") or head[512:520] == HDF5_SIGNATURE:
        try:
            return _load_v73(path)
        except OSError as exc:
            raise InputFileError(f"{path}: corrupt MATLAB v7.3 (HDF5) file ({exc})") from None
    _check_v5_expansion(path)
    try:
        return scipy.io.loadmat(path, simplify_cells=True)
    except NotImplementedError:
        return _load_v73(path)
    except Exception as exc:  # scipy raises ValueError, TypeError, MatReadError, ...
        reraise_interrupt(exc)
        raise InputFileError(f"{path}: not a readable MATLAB .mat file ({exc})") from None


# --- layouts -------------------------------------------------------------------------------


def _pidcore_layout(variables: Mapping, where: str) -> list[Channel]:
    channels = []
    for i, item in enumerate(_as_list(variables.get("pidcore_channels"))):
        what = f"{where}: pidcore_channels{{{i + 1}}}"
        if not isinstance(item, Mapping):
            raise InputFileError(f"{what} is not a struct")
        refuse_unit_other_than_si(_text(item.get("quantity")), _text(item.get("unit")),
                                  where=f"{what}: field unit")
        try:
            channels.append(Channel(
                name=_text(item["name"]), quantity=_text(item["quantity"]),
                data=real_samples(item["data"], where=f"{what}: field data"),
                sample_rate_hz=real_scalar(item["sample_rate_hz"], positive=True,
                                           where=f"{what}: field sample_rate_hz"),
                source_unit=_text(item.get("source_unit", "")),
                start_time_s=real_scalar(item.get("start_time_s", 0.0),
                                         where=f"{what}: field start_time_s")))
        except KeyError as exc:
            raise InputFileError(f"{where}: pidcore_channels{{{i + 1}}} lacks field "
                                 f"{exc}") from None
    return channels


def _unit_text(value: object) -> str:
    """A unit from text or from a unit struct (``unit.label``)."""
    if isinstance(value, Mapping):
        for key in ("label", "name", "unit", "symbol"):
            text = _text(value.get(key))
            if text:
                return text
        return ""
    return _text(value)


def _terms_unit(terms: object) -> str:
    """Unit of Test.Lab ``quantity_terms``: one term (``unit.label``) or a product of terms
    with ``unit_exponent`` / ``exponent`` (``m^1*s^-2``)."""
    parts = []
    for term in _as_list(terms):
        if not isinstance(term, Mapping):
            continue
        text = _unit_text(term.get("unit", term))
        if not text:
            continue
        exponent = term.get("unit_exponent", term.get("exponent"))
        try:
            power = 1.0 if exponent is None else real_scalar(exponent, where="exponent")
        except InputFileError:
            power = 1.0
        parts.append(text if power == 1 else f"{text}^{power:g}")
    return "*".join(parts)


#: Relative distance within which a Test.Lab ``unit_transformation.factor`` is 1, or the
#: reciprocal of the SI factor of the unit it shows: Test.Lab writes 1/9.80665 as 0.10197
#: (2e-5 off). A unit whose SI factor is within it of 1 reads alike either way.
TRANSFORMATION_TOLERANCE = 1e-4


def _lms_units(quantity_struct: object) -> list[tuple[str, str]]:
    """The units a Test.Lab ``quantity`` states, as (field, unit), in the order they are taken:
    a unit field, ``quantity_terms``, then ``label``. A label keeps its case (``mN`` is no
    ``MN``); only a bare quantity name (``'Acceleration'``, any case) is no unit: it is the SI
    unit of that quantity, the unit Test.Lab exports in (``'Time'`` is kept: the caller reads
    the time axis)."""
    if not isinstance(quantity_struct, Mapping):
        text = _text(quantity_struct).strip()
        return [("quantity", text)] if text else []
    units = []
    for key in ("unit", "units", "unit_label", "unit_name"):
        text = _unit_text(quantity_struct.get(key))
        if text:
            units.append((key, text))
            break
    text = _terms_unit(quantity_struct.get("quantity_terms"))
    if text:
        units.append(("quantity_terms", text))
    label = _text(quantity_struct.get("label")).strip()
    if label.lower() in SI_UNITS and label.lower() not in ("unknown", "time"):
        units.append((f"label {label!r}", SI_UNITS[label.lower()]))
    elif label:
        units.append(("label", label))
    return units


def _lms_unit(quantity_struct: object, what: str, notes: list[str]) -> str:
    """The unit of a Test.Lab quantity's values, after its ``unit_transformation``.

    Test.Lab may store values in SI and show them in the unit of its label, the factor
    taking one to the other (display = SI x factor: ``'g'`` with 0.10197, ``'mm/s'`` with
    1000); read as g, an acceleration was 9.8 x too large. Where the factor is the reciprocal
    of a stated unit's SI factor the values are SI (said in ``notes``); where it is 1 (or
    absent) they are in the stated unit. Any other factor, or an offset, on a unit pidcore
    reads is refused: the values could be in either unit. A unit pidcore does not read (a
    temperature's ``'°C'``) is returned as stated: such a channel is never taken as SI.
    """
    units = _lms_units(quantity_struct)
    stated = units[0][1] if units else ""
    transformation = (quantity_struct.get("unit_transformation")
                      if isinstance(quantity_struct, Mapping) else None)
    if not isinstance(transformation, Mapping):
        return stated
    field = f"{what}: quantity.unit_transformation"
    factor = real_scalar(transformation.get("factor", 1.0), where=f"{field}.factor")
    offset = real_scalar(transformation.get("offset", 0.0), where=f"{field}.offset")
    readings = [(key, text, info) for key, text in units
                if (info := read_unit(text).info) is not None]
    if not readings or (offset == 0.0 and abs(factor - 1.0) <= TRANSFORMATION_TOLERANCE):
        return stated
    shown = next(((key, text, info) for key, text, info in readings if offset == 0.0
                  and abs(info.factor * factor - 1.0) <= TRANSFORMATION_TOLERANCE), None)
    quantities = {info.quantity for _, _, info in readings}
    if shown is not None and len(quantities) == 1:
        key, text, info = shown
        notes.append(f"{what}: values read in {info.si_unit}: the file stores them in SI and "
                     f"shows them in {text!r} ({key}; unit_transformation.factor {factor:.6g} "
                     f"= 1/{info.factor:.6g})")
        return info.si_unit
    said = " and ".join(f"{text!r} ({key})" for key, text, _ in readings)
    if len(quantities) > 1:
        expected = "units of one quantity"
    else:
        expected = " or ".join(dict.fromkeys(
            [f"factor 1 (values in {readings[0][1]!r})"]
            + [f"factor {1.0 / info.factor:.6g} (values in SI, shown in {text!r})"
               for _, text, info in readings
               if abs(info.factor - 1.0) > TRANSFORMATION_TOLERANCE]))
        # a unit pidcore reads is a pure scale factor: an offset is no reading of it
        expected += " and offset 0" if offset != 0.0 else ""
    raise InputFileError(f"{what}: quantity states {said} with unit_transformation factor "
                         f"{factor:.6g} and offset {offset:.6g}; expected {expected}")


def _lms_seconds_per_unit(x_values: Mapping, what: str, given: UnitReading | None,
                          notes: list[str]) -> float:
    """Seconds per unit of a Test.Lab signal's ``x_values``: the unit its ``quantity``
    states (the increment is in it: ms read as s gave a rate 1000 x too low), seconds where
    it states none (Test.Lab's unit of time), ``given`` (the user's time_unit) over both."""
    quantity = x_values.get("quantity")
    if given is not None:  # the user's unit overrides the file's, its transformation too
        stated = next((text for _, text in _lms_units(quantity)), "")
    else:
        stated = _lms_unit(quantity, f"{what}: x_values", notes)
    if stated.strip().lower() == "time":  # a bare label names the quantity, not a unit
        stated = ""
    reading = read_unit(stated)
    if given is not None:
        if overrides_stated_time(stated, given):
            notes.append(f"{what}: x_values unit {stated or 'none'!r} overridden: taken as "
                         f"{given.label!r} (time_unit)")
        return given.info.factor
    if not stated:
        return 1.0
    if reading.info is not None and reading.quantity == "time":
        return reading.info.factor
    why = (why_not_a_time_unit(stated) or "").removeprefix(": ") \
        or f"{stated!r} is no unit of time pidcore reads"
    raise InputFileError(f"{what}: x_values unit {why}; expected a unit of time such as s or "
                         "ms (x_values.increment is in it, so it sets the sample rate); give "
                         "it with time_unit=UNIT")


def _channels_in_rows(shape: tuple[int, int], n_names: int) -> bool:
    """Whether a Test.Lab ``y_values.values`` matrix without ``number_of_values`` holds its
    channels as rows: where ``function_record.name`` counts one axis only, that one; else
    the shorter axis (a record holds more samples than channels). Read as columns, 2 x 10240
    values were 10240 channels of 2 samples."""
    rows, columns = shape
    if (rows == n_names) != (columns == n_names):
        return rows == n_names
    return columns > rows


def _lms_layout(signal: object, where: str, given_time: UnitReading | None = None,
                notes: list[str] | None = None) -> list[Channel]:
    notes = [] if notes is None else notes
    channels: list[Channel] = []
    for k, sig in enumerate(_as_list(signal)):
        what = f"{where}: Signal({k + 1})"
        if not isinstance(sig, Mapping) or "x_values" not in sig or "y_values" not in sig:
            raise InputFileError(f"{what}: expected fields x_values and y_values "
                                 "(LMS Test.Lab export)")
        x, y = sig["x_values"], sig["y_values"]
        try:
            start = real_scalar(x.get("start_value", 0.0), where=f"{what}: x_values.start_value")
            increment = real_scalar(x["increment"], where=f"{what}: x_values.increment")
            values = np.asarray(y["values"])
        except (KeyError, AttributeError, TypeError, ValueError) as exc:
            raise InputFileError(f"{what}: incomplete x_values/y_values ({exc})") from None
        # real numbers in any shape: a matrix holds one channel per column or row
        values = real_numbers(values, where=f"{what}: y_values.values").astype(np.float64,
                                                                             copy=False)
        if not increment > 0:
            raise InputFileError(f"{what}: x_values.increment is {increment!r}; expected a "
                                 "positive sample interval in s")
        seconds_per_unit = _lms_seconds_per_unit(x, what, given_time, notes)
        start, increment = start * seconds_per_unit, increment * seconds_per_unit
        values = values.reshape(values.shape[0], -1) if values.ndim > 1 else values[:, None]
        record = sig.get("function_record", {})
        given_names = [_text(v) for v in _as_list(record.get("name")
                                                  if isinstance(record, Mapping) else None)]
        if "number_of_values" not in x and _channels_in_rows(values.shape, len(given_names)):
            values = values.T
        if "number_of_values" in x:
            n_given = real_scalar(x["number_of_values"], where=f"{what}: x_values.number_of_values",
                                  positive=True)
            if n_given != int(n_given) or n_given > values.size:
                raise InputFileError(f"{what}: x_values.number_of_values is {n_given:.6g}; "
                                     f"expected a whole number of samples the file holds "
                                     f"(y_values holds {values.size} values)")
            n = int(n_given)
            if values.shape[0] != n and values.shape[1] == n:
                values = values.T  # channels stored as rows
            if values.shape[0] < n:
                raise InputFileError(f"{what}: y_values holds {values.shape[0]} of "
                                     f"{n} samples; the file is truncated")
            values = values[:n]
        names = [given_names[j] if j < len(given_names) and given_names[j]
                 else f"Signal {k + 1}.{j + 1}" for j in range(values.shape[1])]
        unit = _lms_unit(y.get("quantity") if isinstance(y, Mapping) else None,
                         f"{what} ({listed(names)}): y_values", notes)
        for j, name in enumerate(names):
            channels.append(make_channel(name, values[:, j], sample_rate_hz=1.0 / increment,
                                         unit=unit, start_time_s=start))
    return channels


def _simple_layout(variables: Mapping, where: str, sample_rate_hz: float | None,
                   time_unit: UnitReading | None = None) -> tuple[list[Channel], list[str]]:
    public = {k: v for k, v in variables.items() if not k.startswith("__")}
    time_key = next((k for k in _TIME_VARIABLES if _numeric_vector(public.get(k)) is not None),
                    None)
    rate_key = next((k for k in _RATE_VARIABLES if k in public), None)
    notes: list[str] = []
    if time_key is not None and sample_rate_hz is not None:
        rate, start = float(sample_rate_hz), float(_numeric_vector(public[time_key])[0])
        n = _numeric_vector(public[time_key]).size
        notes.append(f"{where}: time vector {time_key!r} ignored: the sample rate "
                     f"{rate:g} Hz was given (sample_rate_hz)"
                     + overridden_rate(_numeric_vector(public[time_key]), rate))
    elif time_key is not None:
        seconds_per_unit = 1.0 if time_unit is None else time_unit.info.factor
        rate, start, note = rate_from_times(
            _numeric_vector(public[time_key]) * seconds_per_unit,
            what=f"{where}: variable {time_key!r}", with_note=True)
        n = _numeric_vector(public[time_key]).size
        notes += [note] if note else []
        if time_unit is not None:
            notes.append(f"{where}: time vector {time_key!r} taken as {time_unit.label!r} "
                         f"(time_unit), sample rate {rate:.6g} Hz")
        else:
            # a vector states no unit: as for a CSV time column without one, the assumption
            # is said
            notes.append(f"{where}: time vector {time_key!r} states no unit: taken as seconds "
                         f"(sample rate {rate:.6g} Hz); if it is not, give its unit "
                         "(time_unit=UNIT) or the sample rate (sample_rate_hz)")
    elif rate_key is not None or sample_rate_hz is not None:
        try:
            rate = (real_scalar(public[rate_key], where=f"{where}: variable {rate_key}",
                                positive=True) if rate_key is not None
                    else float(sample_rate_hz))
        except InputFileError as exc:
            if sample_rate_hz is None:
                raise
            # the given sample rate overrides the file's rate, as it overrides a time vector: a file
            # rate that is no rate at all (0, NaN) is noted, not refused
            rate = float(sample_rate_hz)
            notes.append(f"{exc}; the sample rate {rate:g} Hz given is used (sample_rate_hz)")
        start, n = 0.0, None
    else:
        raise InputFileError(f"{where}: no time vector ('time' or 't') and no sample rate "
                             "('fs' or 'sample_rate_hz'); give the sample rate (sample_rate_hz)")
    if sample_rate_hz is not None and abs(rate - sample_rate_hz) > 1e-6 * rate:
        notes.append(f"{where}: the file's sample rate {rate:.9g} Hz overridden by "
                     f"{sample_rate_hz:.9g} Hz (sample_rate_hz)")
        rate = float(sample_rate_hz)
    skip = {time_key, rate_key, "units"}
    numeric = {k: vector for k, value in public.items()
               if k not in skip and (vector := _numeric_vector(value)) is not None}
    vectors = {k: v for k, v in numeric.items() if n is None or v.size == n}
    units_var = public.get("units")
    if isinstance(units_var, Mapping):
        units = {k: _text(units_var.get(k)) for k in vectors}
    else:
        unit_list = [_text(u) for u in _as_list(units_var)]
        if unit_list and len(unit_list) != len(vectors):
            # a cell pairs units with channels by position only: a helper vector ('window',
            # 'calib') taken as a channel, or one the cell leaves out, shifted every unit after
            # it onto the next channel (the velocity's 'mm/s' on the force)
            left_out = [k for k in numeric if k not in vectors]
            raise InputFileError(
                f"{where}: the cell 'units' holds {len(unit_list)} units for "
                f"{len(vectors)} channel variables ({listed(vectors)}"
                + (f"; left out, of another length than {time_key!r}: "
                   f"{listed(left_out)}" if left_out else "")
                + "); expected one unit per channel variable, in their order, or a struct "
                "'units' naming each channel (units.Force = 'N')")
        units = {k: (unit_list[i] if i < len(unit_list) else "")
                 for i, k in enumerate(vectors)}
    return [make_channel(k, v, sample_rate_hz=rate, unit=units[k], start_time_s=start)
            for k, v in vectors.items()], notes


def read_mat(path: str | os.PathLike[str], *, sample_rate_hz: float | None = None,
             time_unit: str | None = None) -> Measurement:
    """Read a MATLAB file in one of the layouts of this module into a SI measurement.

    ``time_unit`` (``"ms"``) is the unit of a simple layout's time vector, which states none
    (seconds without it, noted), and of a Test.Lab signal's ``x_values`` (the unit their
    ``quantity`` states, else seconds; one that is no unit of time is refused without it);
    the pidcore layout states its rate in Hz and keeps it (a note says the unit given was
    not applied).

    Raises
    ------
    InputFileError
        Unreadable file, or none of the layouts found (the message lists the variables).
    """
    where = str(path)
    given_time = given_time_unit(time_unit)
    variables = _load(where)
    notes: list[str] = []
    if _text(variables.get("pidcore_layout")) == "measurement":
        channels = _pidcore_layout(variables, where)
        layout = "pidcore"
    elif "Signal" in variables:
        channels = _lms_layout(variables["Signal"], where, given_time, notes)
        layout = "lms_testlab"
    else:
        channels, notes = _simple_layout(variables, where, sample_rate_hz, given_time)
        layout = "simple"
    if given_time is not None and layout == "pidcore":
        notes.append(f"{where}: the time unit {time_unit!r} given (time_unit) is not applied: "
                     "the pidcore layout states its rate in Hz")
    if not channels:
        names = ", ".join(k for k in variables if not k.startswith("__")) or "none"
        raise InputFileError(f"{where}: no channel found (variables: {names}); expected numeric "
                             "vectors beside 'time', an LMS 'Signal' struct or a pidcore layout")
    names = unique_names([c.name for c in channels])
    channels = [c if c.name == nm else Channel(nm, c.quantity, c.data, c.sample_rate_hz,
                                               c.source_unit, c.start_time_s)
                for c, nm in zip(channels, names, strict=True)]
    metadata: dict = {"mat_layout": layout}
    if notes:
        metadata["reader_notes"] = notes
    return Measurement(source=where, channels=tuple(channels), sha256=file_sha256(path),
                       file_format="mat", metadata=metadata)


def write_mat(measurement: Measurement, path: str | os.PathLike[str]) -> None:
    """Write the pidcore layout (MATLAB v5, float64, SI), atomically."""
    if not measurement.channels:
        raise ParameterError(f"{measurement.source}: nothing to write (no channels)")
    cell = np.empty(len(measurement.channels), dtype=object)
    for i, ch in enumerate(measurement.channels):
        cell[i] = {"name": ch.name, "quantity": ch.quantity, "unit": ch.unit,
                   "source_unit": ch.source_unit,
                   "data": np.asarray(ch.data, dtype=np.float64).reshape(-1, 1),
                   "sample_rate_hz": float(ch.sample_rate_hz),
                   "start_time_s": float(ch.start_time_s)}
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        scipy.io.savemat(fh, {"pidcore_layout": "measurement", "pidcore_channels": cell,
                              "source": measurement.source}, do_compression=True)
