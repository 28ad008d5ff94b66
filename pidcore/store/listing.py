"""Listings across stores for the app and reports: DEM runs of several stores, saved analyses
with their load cases, filtered.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import StoreError
from .store import Store

#: Columns a saved analysis needs to be placed in a load case.
LOAD_CASE_FIELDS = ("frequency_hz", "acceleration_g", "fill_percent", "material", "direction")


#: Result fields of an analysis and what a stored value must be: a hand-edited or damaged
#: record with a negative standard error crashed the report's figures, one of 1e308
#: overflowed the pooled error, and a NaN or infinite SDC was averaged into a load case; each
#: is refused naming the store and the record. 1e6 is no physical limit but far above any
#: SDC an analysis saves (the plausibility bound of a dense tungsten bed is ~40) and far below
#: where squares and sums overflow.
_MAGNITUDE_LIMIT = 1e6
_RESULT_FIELDS = {
    "frequency_hz": ("a positive finite number", lambda v: math.isfinite(v) and v > 0),
    "acceleration_g": ("a positive finite number", lambda v: math.isfinite(v) and v > 0),
    "sdc": (f"a number of magnitude at most {_MAGNITUDE_LIMIT:g}",
            lambda v: abs(v) <= _MAGNITUDE_LIMIT),
    "loss_factor": (f"a number of magnitude at most {_MAGNITUDE_LIMIT:g}",
                    lambda v: abs(v) <= _MAGNITUDE_LIMIT),
    # J per cycle of a coupon on a shaker: far below 1e6 J; 1e308 gave an Eq. 10 SDC of inf
    "energy_per_cycle_j": (f"a number of magnitude at most {_MAGNITUDE_LIMIT:g} J, or empty",
                           lambda v: math.isnan(v) or abs(v) <= _MAGNITUDE_LIMIT),
    # NaN: unknown (one block), as the analysis saves it
    "sdc_stderr": (f"a number from 0 to {_MAGNITUDE_LIMIT:g}, or empty (unknown)",
                   lambda v: math.isnan(v) or 0 <= v <= _MAGNITUDE_LIMIT),
    "loss_factor_stderr": (f"a number from 0 to {_MAGNITUDE_LIMIT:g}, or empty (unknown)",
                           lambda v: math.isnan(v) or 0 <= v <= _MAGNITUDE_LIMIT),
}


def checked_analyses(analyses: pd.DataFrame, where: str | os.PathLike) -> pd.DataFrame:
    """``analyses`` (a :meth:`Store.list_analyses` listing of the store ``where``) if every
    result field holds what an analysis saves, else :class:`StoreError` naming the store,
    the record, the field, its value and what was expected."""
    for _, row in analyses.iterrows():
        problems = analysis_row_problems(row)
        if problems:
            raise damaged_analysis(where, row, problems[0])
    return analyses


def analysis_row_problems(row: pd.Series) -> list[str]:
    """What a stored analysis's result fields (a row of :meth:`Store.list_analyses`) hold
    that no analysis saves: a value out of its range, an SDC other than 2 pi x its loss
    factor. The one rule of :func:`checked_analyses` (report, calibrate) and
    :meth:`Store.verify`, which called such a record sound."""
    problems = []
    for field, (expected, holds) in _RESULT_FIELDS.items():
        value = row.get(field)
        if value is None:  # absent, or saved as null: the analysis did not give it
            continue
        # text is no number, even where NaN (unknown) would be
        if isinstance(value, bool | str) or not holds(_float(value)):
            problems.append(f"record field {field} = {value!r} is not {expected}")
    if "sdc" in row.index and "loss_factor" in row.index:
        # an analysis saves sdc = 2 pi loss_factor (Eq. 9) to the last bit: an SDC edited
        # to -5 beside its loss factor 0.65 was calibrated against without a word
        sdc, loss = _float(row["sdc"]), _float(row["loss_factor"])
        if math.isfinite(sdc) and math.isfinite(loss) and not math.isclose(
                sdc, 2 * math.pi * loss, rel_tol=1e-9, abs_tol=1e-15):
            problems.append(f"record field sdc = {sdc!r} is not 2 pi x its loss_factor "
                            f"{loss!r} ({2 * math.pi * loss:.6g}), as an analysis saves it")
    return problems


def dem_run_row_problems(row: pd.Series | Mapping[str, object]) -> list[str]:
    """What a stored DEM run's result fields (a row of :meth:`Store.list_dem_runs`, or a
    record with its case_key as :meth:`Store.get_dem_run` checks it) hold that
    no run saves: an SDC that is not a finite number >= 0 (a run's is its dissipation over
    the peak kinetic energy), or one other than 2 pi x its loss factor or its
    energy_per_cycle_j / max_kinetic_energy_j (:meth:`pidcore.dem.result.DemResult.
    from_tallies` makes both from the same numbers: equal but for rounding). An SDC of -0.5
    was printed as "SDC DEM (ours)", and a NaN one interpolated over without a note."""
    sdc = row.get("sdc")
    if sdc is None:  # not stored: the run is no result a report reads
        return []
    value = _float(sdc)
    if isinstance(sdc, bool | str) or not (math.isfinite(value) and value >= 0):
        return [f"record field sdc = {sdc!r} is not a finite number >= 0"]
    problems = []
    loss, energy, peak = (_float(row.get(name)) for name in
                          ("loss_factor", "energy_per_cycle_j", "max_kinetic_energy_j"))
    # rel_tol 1e-9: both ways of computing differ by a few ulp (2e-16 over the Table 3 grid)
    if math.isfinite(loss) and not math.isclose(value, 2 * math.pi * loss, rel_tol=1e-9,
                                                abs_tol=1e-15):
        problems.append(f"record field sdc = {value!r} is not 2 pi x its loss_factor {loss!r}")
    if math.isfinite(energy) and math.isfinite(peak) and peak > 0 and not math.isclose(
            value, energy / peak, rel_tol=1e-9, abs_tol=1e-15):
        problems.append(f"record field sdc = {value!r} is not its energy_per_cycle_j / "
                        f"max_kinetic_energy_j ({energy / peak:.6g}), as a run saves it")
    return problems


def check_dem_run(where: str | os.PathLike, row: pd.Series | Mapping[str, object]) -> None:
    """:class:`StoreError` naming the store ``where``, the run and the field where a DEM run's
    result fields (``row``, with its case_key) hold what no run saves
    (:func:`dem_run_row_problems`)."""
    problems = dem_run_row_problems(row)
    if problems:
        raise damaged_dem_run(where, row, problems[0])


def checked_dem_runs(runs: pd.DataFrame, where: str | os.PathLike) -> pd.DataFrame:
    """``runs`` (a :meth:`Store.list_dem_runs` listing of the store ``where``) if every run's
    result fields hold what a run saves, else :class:`StoreError` (:func:`check_dem_run`)."""
    for _, row in runs.iterrows():
        check_dem_run(where, row)
    return runs


def damaged_dem_run(where: str | os.PathLike, row: pd.Series | Mapping[str, object],
                    what: str) -> StoreError:
    """The refusal of a DEM run changed outside pidcore, naming the store and the run."""
    return StoreError(f"{where}: DEM run {row.get('case_key', '')}: {what}; it was changed or "
                      "damaged outside pidcore (run it again into a fresh store)")


def damaged_analysis(where: str | os.PathLike, row: pd.Series, what: str) -> StoreError:
    """The refusal of a record changed outside pidcore, naming the store and the record."""
    name = Path(str(row.get("source", "") or "")).name or row.get("key", "")
    return StoreError(f"{where}: analysis {row.get('key', '')} ({name}): {what}; it was "
                      "changed or damaged outside pidcore (analyse the file again into a "
                      "fresh store)")


def _float(value: object) -> float:
    try:
        return math.nan if isinstance(value, bool | str) or value is None else float(value)
    except (TypeError, ValueError):
        return math.nan


def list_dem_runs(*paths: str | os.PathLike | None) -> pd.DataFrame:
    """DEM runs of every existing store in ``paths`` (empty where none holds any).

    A run in several stores (same case key) is taken from the first. Column ``store`` says
    where each run is kept.
    """
    frames = []
    for where in paths:
        if where is not None and Path(where).is_file():
            runs = checked_dem_runs(Store(where).list_dem_runs(), where)
            if not runs.empty:
                frames.append(runs.assign(store=str(where)))
    if not frames:
        return pd.DataFrame()
    runs = pd.concat(frames, ignore_index=True)
    return runs.drop_duplicates("case_key", keep="first").reset_index(drop=True)


def latest_per_measurement(analyses: pd.DataFrame) -> pd.DataFrame:
    """The newest analysis of each measurement (a file re-analysed with other corrections is
    one measurement, not a repeat of it); unchanged where the listing has no
    ``measurement_key`` and ``created_utc``."""
    if not {"measurement_key", "created_utc"} <= set(analyses.columns):
        return analyses
    return (analyses.sort_values("created_utc", kind="stable")
            .groupby("measurement_key", sort=False).tail(1))


def saved_analyses(path: str | os.PathLike, *, latest_only: bool = True) -> pd.DataFrame:
    """Analyses of a store that state a load case (a fill), newest first.

    ``latest_only`` keeps the newest analysis of each measurement (a file re-analysed with
    other corrections replaces its earlier result rather than being counted twice, as
    ``pidcore report`` does). Adds ``file`` (the source's name) and ``date`` (``YYYY-MM-DD`` of
    ``created_utc``). Empty for a missing store.
    """
    if not Path(path).is_file():
        return pd.DataFrame()
    analyses = checked_analyses(Store(path).list_analyses(), path)
    if analyses.empty or "fill_percent" not in analyses.columns:
        return analyses.iloc[0:0]
    fill = pd.to_numeric(analyses["fill_percent"], errors="coerce")
    out = analyses[np.isfinite(fill.to_numpy(float))].copy()
    if latest_only:
        out = latest_per_measurement(out)
    out["file"] = [Path(str(s)).name for s in out["source"]]
    out["date"] = out["created_utc"].astype(str).str[:10]
    if "specimen" not in out.columns:
        out["specimen"] = ""
    out["specimen"] = out["specimen"].fillna("").astype(str)
    return out.sort_values("created_utc", ascending=False, kind="stable").reset_index(drop=True)


def filter_analyses(analyses: pd.DataFrame, *, specimens=(), dates=(), files=(),
                    load_cases=()) -> pd.DataFrame:
    """Rows of :func:`saved_analyses` whose specimen, date, file and ``load_case`` column are
    among the values given (an empty choice keeps every row)."""
    keep = np.ones(len(analyses), dtype=bool)
    for column, values in (("specimen", specimens), ("date", dates), ("file", files),
                           ("load_case", load_cases)):
        if values and column in analyses.columns:
            keep &= analyses[column].isin(list(values)).to_numpy()
    return analyses[keep].reset_index(drop=True)
