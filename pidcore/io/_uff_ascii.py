"""Fallback parser for ASCII dataset 58 records that pyuff rejects.

pyuff 2.5 parses numbers with Python's ``float()``, so a record that uses Fortran ``D``
exponents (``1.23456D-03``) or drops the ``E`` before a 3-digit exponent (``1.23456-100``, legal
Fortran output) fails as a whole. This parser reads the same fixed columns as pyuff but converts
each field with :func:`fortran_float`. It returns dictionaries with pyuff's keys, so the reader
treats both paths alike. Binary 58b records are not handled here (pyuff reads those).
"""

from __future__ import annotations

import re

import numpy as np

_MISSING_E = re.compile(r"^([+-]?(?:\d+\.?\d*|\.\d+))([+-]\d+)$")


def fortran_float(text: str) -> float:
    """Parse a Fortran real: ``D`` exponents and exponents without ``E`` included.

    >>> fortran_float("1.5D+02"), fortran_float("-2.5-100") == -2.5e-100
    (150.0, True)
    """
    t = text.strip().upper().replace("D", "E")
    match = _MISSING_E.match(t)
    if match:
        t = f"{match.group(1)}E{match.group(2)}"
    return float(t)


def _fields(line: str, widths: list[int]) -> list[str]:
    line = line.ljust(sum(widths))
    out, pos = [], 0
    for w in widths:
        out.append(line[pos:pos + w].strip())
        pos += w
    return out


def _int(text: str) -> int:
    return int(text) if text.strip() else 0


def _chunks(lines: list[str], width: int) -> list[str]:
    values = []
    for line in lines:
        line = line.rstrip("\r\n")
        for i in range(0, len(line), width):
            cell = line[i:i + width]
            if cell.strip():
                values.append(cell)
    return values


def _parse_block(block: list[str]) -> dict:
    """Parse the lines of one ASCII dataset 58 (after the ``58`` line, before ``-1``)."""
    if len(block) < 11:
        raise ValueError(f"dataset 58 needs 11 header lines, found {len(block)}")
    dset: dict = {"type": 58, "binary": 0}
    for k in range(5):
        dset[f"id{k + 1}"] = block[k].strip()
    f = _fields(block[5], [5, 10, 5, 10, 11, 10, 4, 11, 10, 4])
    dset.update(func_type=_int(f[0]), func_id=_int(f[1]), ver_num=_int(f[2]),
                load_case_id=_int(f[3]), rsp_ent_name=f[4], rsp_node=_int(f[5]),
                rsp_dir=_int(f[6]), ref_ent_name=f[7], ref_node=_int(f[8]), ref_dir=_int(f[9]))
    f = _fields(block[6], [10, 10, 10, 13, 13, 13])
    dset.update(ord_data_type=_int(f[0]), num_pts=_int(f[1]), abscissa_spacing=_int(f[2]),
                abscissa_min=fortran_float(f[3] or "0"), abscissa_inc=fortran_float(f[4] or "0"),
                z_axis_value=fortran_float(f[5] or "0"))
    for line, prefix in zip(block[7:11], ("abscissa", "ordinate", "orddenom", "z_axis"),
                            strict=True):
        f = _fields(line, [10, 5, 5, 5, 21, 21])
        dset.update({f"{prefix}_spec_data_type": _int(f[0]), f"{prefix}_len_unit_exp": _int(f[1]),
                     f"{prefix}_force_unit_exp": _int(f[2]),
                     f"{prefix}_temp_unit_exp": _int(f[3]), f"{prefix}_axis_lab": f[4],
                     f"{prefix}_axis_units_lab": f[5]})
    data_lines = block[11:]
    ord_type, even = dset["ord_data_type"], dset["abscissa_spacing"] == 1
    if ord_type == 2:
        values = np.array([fortran_float(c) for c in _chunks(data_lines, 13)])
    elif ord_type == 4 and even:
        values = np.array([fortran_float(c) for c in _chunks(data_lines, 20)])
    elif ord_type == 4:
        # 2(E13.5,E20.12): abscissa and ordinate pairs of different widths
        cells = []
        for line in data_lines:
            line = line.rstrip("\r\n")
            for start in range(0, len(line), 33):
                pair = line[start:start + 33]
                cells += [c for c in (pair[:13], pair[13:33]) if c.strip()]
        values = np.array([fortran_float(c) for c in cells])
    else:
        # Complex ordinates are never time records; keep the header, mark as complex.
        dset["x"], dset["data"] = np.zeros(0), np.zeros(0, dtype=complex)
        return dset
    if even:
        dset["x"] = dset["abscissa_min"] + np.arange(values.size) * dset["abscissa_inc"]
        dset["data"] = values
    else:
        dset["x"], dset["data"] = values[0::2], values[1::2]
    return dset


def parse_uff_ascii(text: str) -> list[tuple[int, dict]]:
    """All datasets of an ASCII UFF text: ``(type, dset)``; only type 58 has a parsed dset.

    Raises
    ------
    ValueError
        A dataset 58 that cannot be parsed even with Fortran number rules.
    """
    lines = text.splitlines()
    out: list[tuple[int, dict]] = []
    i = 0
    while i < len(lines):
        if lines[i].strip() != "-1":
            i += 1
            continue
        j = i + 1
        while j < len(lines) and lines[j].strip() != "-1":
            j += 1
        block = lines[i + 1:j]
        i = j + 1
        if not block:
            continue
        head = block[0][:6].strip()
        if not head.isdigit():
            raise ValueError(f"dataset type {block[0][:6]!r} is not a number")
        set_type = int(head)
        out.append((set_type, _parse_block(block[1:]) if set_type == 58 else {"type": set_type}))
    return out
