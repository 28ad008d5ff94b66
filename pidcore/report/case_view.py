"""One load case of measurements as the app's Compare page shows it and its PDF sheet prints
it (:mod:`pidcore.report.case_sheet`), as plain data: the records grouped per load case, the
comparison with our DEM and the paper, the loops and the notes.

The Compare page and ``pidcore report --case-sheets`` both build their views here, so a sheet
written by the command is the one the page gives for the same records and stores.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path

import pandas as pd

from ..compare.case import (
    CaseComparison,
    MeasuredEntry,
    compare_case,
    group_load_cases,
    headline,
    sdc_points,
)
from ..loop import ForceDisplacementLoop

#: Columns of :func:`loop_frame`.
LOOP_COLUMNS = ("series", "displacement [m]", "force [N]", "order")


def loop_frame(loops: Sequence[ForceDisplacementLoop]) -> pd.DataFrame:
    """Closed loops as one long table (SI units), one row per point in drawing order, for the
    app's chart: columns :data:`LOOP_COLUMNS`, ``series`` the loop's label."""
    parts = []
    for loop in loops:
        x, f = loop.closed()
        parts.append(pd.DataFrame({"series": loop.label, "displacement [m]": x,
                                   "force [N]": f, "order": range(x.size)}))
    return (pd.concat(parts, ignore_index=True) if parts
            else pd.DataFrame(columns=list(LOOP_COLUMNS)))


def saved_entries(path: str | os.PathLike, rows: pd.DataFrame,
                  known: Sequence = ()) -> list[MeasuredEntry]:
    """Entries of the saved analyses ``rows`` (from :func:`pidcore.store.listing.saved_analyses`),
    with their harmonic phasors read from the store; ``known``: the specimen files at hand,
    whose tests are judged against their SDC bound (:meth:`MeasuredEntry.from_store`)."""
    from ..store import Store

    if rows.empty:
        return []
    # one opening of the store for all of them, not one per row
    stored = Store(path).get_analyses(str(key) for key in rows["key"])
    return [MeasuredEntry.from_store(row, entry.arrays, known=known)
            for (_, row), entry in zip(rows.iterrows(), stored, strict=True)]


def matched_specimens(entries: Sequence[MeasuredEntry],
                      listing: pd.DataFrame | None = None, *,
                      given: Mapping[str, str] | None = None) -> list[MeasuredEntry]:
    """``entries`` with each record saved without its file's hash (an older pidcore's) met
    as ``pidcore calibrate --store`` and reports meet it
    (:func:`pidcore.specimen.match_hashless_records`): given the hash of its name's one file,
    or kept apart where the name means two, with :attr:`MeasuredEntry.specimen_note` saying
    which. Decided over the entries and every record of ``listing`` (the store's saved
    analyses before the page's filters), so that a filter does not change which file a
    record is of. ``given``: name -> hash of the specimen files given (a report's
    ``--specimen``), as its rows match them."""
    from dataclasses import replace

    from ..specimen import MEASURED_SHA256_FIELD, match_hashless_records

    others: list[tuple[object, object]] = []
    if listing is not None and not listing.empty and "specimen" in listing.columns:
        others = list(zip(listing["specimen"], listing.get(
            MEASURED_SHA256_FIELD, pd.Series([""] * len(listing), index=listing.index)),
            strict=True))
    matched = match_hashless_records([e.specimen for e in entries],
                                     [e.specimen_sha256 for e in entries], given=given,
                                     others=others)
    return [replace(e, specimen_sha256=sha256, specimen_note=note) if note else e
            for e, sha256, note in zip(entries, matched.sha256, matched.notes, strict=True)]


def group_entries(entries: Sequence[MeasuredEntry]) -> list[list[int]]:
    """Indices of ``entries`` grouped by load case (and specimen: specimens are never pooled)."""
    out: list[list[int]] = []
    # two specimen files of one name are two specimens (a record without the hash: by name)
    by_specimen: dict[tuple[str, str], list[int]] = {}
    for i, e in enumerate(entries):
        by_specimen.setdefault((e.specimen, e.specimen_sha256), []).append(i)
    for members in by_specimen.values():
        for group in group_load_cases([entries[i].load_case for i in members]):
            out.append([members[j] for j in group])
    return out


def group_name(entries: Sequence[MeasuredEntry], group: Sequence[int]) -> str:
    """The group's load case, e.g. ``'500 Hz, 5 g, 50 %, acrylic, z, specimen A'``.

    Stays the same when records are added to the group or the groups are listed in another
    order (a save re-sorts them), so it can name the user's choice of group.
    """
    from ..specimen import tested_label

    e = naming_entry(entries, group)
    specimen = f", specimen {tested_label(e.specimen, e.specimen_sha256)}" if e.specimen else ""
    return f"{e.load_case.full_label()}{specimen}"


#: The file count a load case's title ends with (:func:`case_title`), e.g. " (2 file(s))".
CASE_TITLE_FILE_COUNT = re.compile(r" \(\d+ file\(s\)\)$")


def case_title(entries: Sequence[MeasuredEntry], group: Sequence[int]) -> str:
    """The title of one load case: the Compare page's label of it and its PDF sheet's first
    line, :func:`group_name` and the files pooled, e.g. ``'100 Hz, 5 g, 50 %, acrylic, z (1
    file(s))'``."""
    return f"{group_name(entries, group)} ({len(group)} file(s))"


def naming_entry(entries: Sequence[MeasuredEntry], group: Sequence[int]) -> MeasuredEntry:
    """The record whose load case names the group: its first saved, then the unsaved ones in
    their order. The store lists its newest records first, so the group's first record was
    the latest saved, and a file saved to the case renamed it ("500 Hz" to "500.5 Hz")."""
    order = sorted(range(len(group)), key=lambda n: (not entries[group[n]].created_utc,
                                                     entries[group[n]].created_utc, n))
    return entries[group[order[0]]]



def dem_loop(paths: Sequence[str | os.PathLike | None],
             comparison: CaseComparison) -> ForceDisplacementLoop | str | None:
    """Our DEM's loop at the comparison's grid case (first store that holds the run), a note
    why it cannot be drawn, or None where there is no DEM run at the case."""
    from dataclasses import replace

    from ..dem.persist import run_key_case
    from ..report.comparison_figures import dem_loop_from_arrays
    from ..store import Store

    grid = getattr(comparison.aligned, "grid_case", None)
    if grid is None or not grid.run_keys:
        return None
    key = grid.run_keys[0]
    for where in paths:
        if where is not None and Path(where).is_file() and Store(where).has_dem_run(key):
            entry = Store(where).get_dem_run(key)
            found = dem_loop_from_arrays(entry.arrays, entry.record)
            if isinstance(found, str):
                return f"DEM run {key}: {found}"
            return replace(found, label=f"our DEM: {run_key_case(key)}")
    return None


def case_view(entries: Sequence[MeasuredEntry], dem_runs: pd.DataFrame | None,
              paper: pd.DataFrame, store_paths: Sequence[str | os.PathLike | None]) -> dict:
    """Everything the Compare page draws for one load case, as plain data.

    Keys: ``comparison``, ``headline``, ``sdc_points`` (frame), ``loops`` (frame, SI),
    ``energies`` (series -> J per cycle: the loop's area), ``energies_analysed`` (label ->
    J per cycle as the analysis states it, for the measurements analysed with a baseline loss
    factor, whose loop area holds the empty coupon's damping too), ``spectrum`` (frame of the
    first record), ``notes``,
    ``dem_specimen`` (the specimen of the DEM runs met, e.g. ``"steel_6mm_b [3e945a]"``; empty
    where none), ``dem_refused`` (why no DEM run is met although there are runs: several
    specimens' runs would be pooled; empty otherwise) and ``dem_warning`` (the report's note
    for a DEM case with unconverged runs; empty otherwise).
    """
    from ..calibrate.persist import calibration_design_runs
    from ..compare.specimens import runs_for_measurement
    from ..report.pipeline import whole_mass_baseline_note, without_design_runs
    from ..report.table import not_converged_note

    # a calibration's design runs (its 2-4 cell inputs) are no prediction to compare with,
    # as in the Report tab: they were the chart's "our DEM" points beside the real runs
    design_note = ""
    design = calibration_design_runs(dem_runs, store_paths)
    if design and dem_runs is not None:
        dem_runs, design_note = without_design_runs(dem_runs, design, poolable=False)
    # group_entries never pools specimens: the first entry names the group's
    first = entries[0]
    met = runs_for_measurement(dem_runs, first.specimen, first.load_case.material,
                               first.load_case.direction, first.specimen_sha256)
    comparison = compare_case(entries, met.runs, paper)
    notes = list(comparison.notes) + ([design_note] if design_note else [])
    # a record matched by name only (or kept apart) is said where it is shown
    notes.extend(dict.fromkeys(e.specimen_note for e in entries if e.specimen_note))
    if met.note and not met.refused:
        notes.append(met.note)
    # the Report tab and `pidcore report` say it; the Compare page showed such a low SDC
    # against the DEM without a word
    whole = whole_mass_baseline_note(e.settings for e in entries)
    if whole:
        notes.append(whole)
    # a stored bound that is not one was ignored (judged at 2 pi), said as report --store and
    # calibrate --store say it
    notes.extend(f"{e.file}: {e.bound_note}" for e in entries if e.bound_note)
    # a record the plausibility checks refuse, saved as confirmed, was pooled here without a
    # word (report --store names it, calibrate --store leaves it out)
    notes.extend(f"{e.file}: implausible, "
                 + ("saved as accepted" if e.origin == "store" else f"{e.origin}")
                 + f": {e.implausible}; pooled here, so the calibrated band is not judged"
                 for e in entries if e.implausible)
    grid = getattr(comparison.aligned, "grid_case", None)
    loops = []
    for e in entries:
        found = e.loop()
        if isinstance(found, str):
            notes.append(f"{e.file}: {found}")
        else:
            loops.append(found)
    found = dem_loop(store_paths, comparison)
    if isinstance(found, str):
        notes.append(found)
    elif found is not None:
        loops.append(found)
    # the runs the page's warning names are not "no runs"; another specimen's runs left out are
    # said in the note of the specimen rule, more precisely than the alignment's message
    why_no_dem = ("the DEM runs met are not pooled (named in the warning below)" if met.refused
                  else met.note if met.runs is None or met.runs.empty else "")
    return {"comparison": comparison,
            "headline": headline(comparison, why_no_dem=why_no_dem),
            "sdc_points": sdc_points(comparison), "loops": loop_frame(loops),
            "energies": {loop.label: loop.energy_per_cycle_j for loop in loops},
            # the energy `pidcore analyze` prints (and Eq. 10 uses) where it is not the loop's
            # area: an analysis with the empty coupon's damping taken off
            "energies_analysed": {
                e.loop_label: e.energy_per_cycle_j for e in entries
                if e.baseline_sdc != 0 and math.isfinite(e.energy_per_cycle_j)},
            "spectrum": entries[0].spectrum(), "notes": notes,
            "dem_specimen": met.specimen, "dem_refused": met.note if met.refused else "",
            "dem_warning": (not_converged_note(grid) if grid is not None and grid.not_converged
                            else "")}
