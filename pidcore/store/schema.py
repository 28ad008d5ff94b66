"""What a stored analysis or DEM run holds: the SI unit of each of its fields and arrays, and
the shape of its arrays; one rule that :meth:`Store.verify`, every ``get_`` and every listing
check a stored entry against.

A record edited or damaged outside pidcore (an SDC of 'abc', a unit changed from '-' to '%',
an array of text or of pickled bytes) passed verify and then crashed ``report`` with a
traceback deep in the comparison, or was read in the wrong unit without a word. The units are
those pidcore writes (:data:`pidcore.measure.ANALYSIS_UNITS`, :data:`pidcore.dem.result.UNITS`);
a field not named there (a caller's own) is not checked. A stated unit is the schema's or an
SI spelling of it at factor 1 (``m/s2`` for ``m/s^2``), as a measurement channel's unit
(:func:`pidcore.io._common.refuse_unit_other_than_si`); dimensionless counts and ratios
(``'1'``, ``'-'``) are one unit.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from types import MappingProxyType

import numpy as np

from ..constants import COUNT_UNIT, RATIO_UNIT
from ..errors import a_or_an, clipped
from ..units import lookup_unit
from .values import MAX_TEXT_CHARS

#: Layouts whose fields have a schema (a calibration's fields follow its parameters).
ANALYSIS, DEM_RUN = "analysis", "dem_run"

#: Dimensions of each array, by name: a record field (its value is the length) or a name
#: shared by arrays that must agree (a DEM run's samples).
_DIMENSIONS: dict[str, dict[str, tuple[str, ...]]] = {
    ANALYSIS: {"harmonics": ("harmonics",), "force_phasors_n": ("harmonics",),
               "velocity_phasors_m_s": ("harmonics",)},
    DEM_RUN: {"sdc_per_cell": ("cells_simulated",), "dissipation_per_cycle_j": ("cycles",),
              "dissipation_per_cell_cycle_j": ("cells_simulated", "cycles"),
              "sample_time_s": ("samples",), "wall_force_n": ("samples",),
              "shaker_force_n": ("samples",), "velocity_m_s": ("samples",)},
}
#: Arrays that hold complex phasors (every other is real).
_COMPLEX_ARRAYS = frozenset({"force_phasors_n", "velocity_phasors_m_s"})
#: Arrays whose every value is finite as pidcore writes them: an analysis's phasors are fits
#: of samples it refuses unless finite, a DEM run's arrays are its tallies and virtual shaker
#: record (sdc_per_cell is NaN only where the run's SDC is, refused on its own). A NaN set in
#: one passed verify and was drawn or summed over. Measurement samples are not among them: a
#: channel no analysis used (or a gap an analysis refuses) is stored as read, NaN and all.
_FINITE_ARRAYS = frozenset(name for dims in _DIMENSIONS.values() for name in dims)
_DIMENSIONLESS = frozenset({COUNT_UNIT, RATIO_UNIT})
#: Fields whose unit must be stated where an entry states any: the result itself, which every
#: report and calibration compares (a caller of the API states its own fields' units as it
#: likes: tests and scripts store a frequency and an SDC with their units and nothing else).
_UNIT_REQUIRED = frozenset({"sdc"})


@functools.cache
def stored_units(layout: str) -> Mapping[str, str]:
    """``{field or array: its unit}`` of what pidcore stores under ``layout`` (empty for a
    layout without a schema)."""
    # imported here: both modules import the store
    if layout == ANALYSIS:
        from ..compare.plausibility import RECORDED_BOUND_UNITS
        from ..measure import ANALYSIS_UNITS

        return MappingProxyType({**ANALYSIS_UNITS, **RECORDED_BOUND_UNITS})
    if layout == DEM_RUN:
        from ..dem.result import UNITS

        return MappingProxyType(dict(UNITS))
    return MappingProxyType({})


def _same_unit(stated: str, expected: str) -> bool:
    stated = stated.strip()
    if stated == expected or {stated, expected} <= _DIMENSIONLESS:
        return True
    info, wanted = lookup_unit(stated), lookup_unit(expected)
    return (info is not None and wanted is not None and info.quantity == wanted.quantity
            and math.isclose(info.factor, wanted.factor, rel_tol=1e-12))


def record_problems(layout: str, record: Mapping[str, object],
                    units: Mapping[str, str]) -> list[str]:
    """What is wrong with the scalar fields and units of a stored entry (one phrase each,
    naming the field and what was expected; empty: nothing)."""
    schema = stored_units(layout)
    problems = [f"record field {name} is text of {len(value)} characters; expected at most "
                f"{MAX_TEXT_CHARS}" for name, value in record.items()
                if isinstance(value, str) and len(value) > MAX_TEXT_CHARS]
    problems += [f"record field {name} = {clipped(repr(value))} is not a real number; expected "
                 f"one in {schema[name]!r}" for name, value in record.items()
                 if name in schema and value is not None
                 and (isinstance(value, bool) or not isinstance(value, int | float))]
    # pidcore states the unit of each field it saves: one of those a report compares left out
    # was deleted. Where none is stated the entry was written without units, and a caller of
    # the API may state some only (its own fields' units are not checked beyond these).
    stated_any = any(name in schema for name in units)
    for name in [*record, *units]:
        if name not in schema:
            continue
        unit = units.get(name)
        if unit is None:
            if stated_any and name in record and name in _UNIT_REQUIRED:
                problems.append(f"unit of {name} missing; expected {schema[name]!r}")
        elif not _same_unit(unit, schema[name]):
            problems.append(f"unit of {name} is {unit!r}; expected {schema[name]!r}, the "
                            "unit pidcore stores it in")
    return list(dict.fromkeys(problems))


def array_problems(layout: str, record: Mapping[str, object], arrays: Mapping[str, object],
                   array_units: Mapping[str, str]) -> list[str]:
    """What is wrong with the arrays of a stored entry (their kind, shape and the unit each
    dataset states); one phrase each."""
    schema = stored_units(layout)
    dimensions = _DIMENSIONS.get(layout, {})
    lengths: dict[str, tuple[int, str]] = {}
    problems = []
    for name, array in arrays.items():
        if name not in schema:
            continue
        kinds = "c" if name in _COMPLEX_ARRAYS else "iuf" if schema[name] == COUNT_UNIT else "f"
        expected = "complex" if kinds == "c" else "integer" if kinds == "iuf" else "float"
        if not isinstance(array, np.ndarray) or array.dtype.kind not in kinds:
            what = f"dtype {array.dtype}" if isinstance(array, np.ndarray) else \
                type(array).__name__
            problems.append(f"array {name} holds {what}; expected {a_or_an(expected)} "
                            "array")
            continue
        if name in _FINITE_ARRAYS and array.size and not np.all(np.isfinite(array)):
            bad = ~np.isfinite(array.ravel())
            problems.append(f"array {name} holds {int(bad.sum())} non-finite value(s) (NaN/inf), "
                            f"first at flat index {int(np.argmax(bad))}; expected finite "
                            "numbers, as pidcore writes them")
        unit = array_units.get(name, "")
        if unit and not _same_unit(unit, schema[name]):
            problems.append(f"array {name} states unit {unit!r}; expected {schema[name]!r}")
        names = dimensions.get(name)
        if names is None:
            continue
        if array.ndim != len(names):
            problems.append(f"array {name} has shape {array.shape}; expected {len(names)} "
                            "dimension(s)")
            continue
        for size, dim in zip(array.shape, names, strict=True):
            stated = record.get(dim)
            if isinstance(stated, int | float) and not isinstance(stated, bool):
                lengths.setdefault(dim, (int(stated), f"record field {dim}"))
            known = lengths.setdefault(dim, (size, f"array {name}"))
            if known[0] != size:
                problems.append(f"array {name} has {size} elements along {dim}; expected "
                                f"{known[0]} (as {known[1]})")
    return problems
