"""What the Compare page shows, assembled from records and stores (no Streamlit here).

Records come from this session's uploads and from every saved analysis of the store
(:func:`pidcore.store.listing.saved_analyses`), so a reload or another session sees them.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from ..compare.case import (
    CaseComparison,
    Headline,
    MeasuredEntry,
    compare_case,
    group_load_cases,
    headline,
    sdc_points,
)
from ..loop import ForceDisplacementLoop
from ..report.table import CONSISTENCY_COLUMN, MEASURED_EQ11_COLUMN, with_band_text
from .vocabulary import page_terms

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
                      listing: pd.DataFrame | None = None) -> list[MeasuredEntry]:
    """``entries`` with each record saved without its file's hash (an older pidcore's) met
    as ``pidcore calibrate --store`` and reports meet it
    (:func:`pidcore.specimen.match_hashless_records`): given the hash of its name's one file,
    or kept apart where the name means two, with :attr:`MeasuredEntry.specimen_note` saying
    which. Decided over the entries and every record of ``listing`` (the store's saved
    analyses before the page's filters), so that a filter does not change which file a
    record is of."""
    from dataclasses import replace

    from ..specimen import MEASURED_SHA256_FIELD, match_hashless_records

    others: list[tuple[object, object]] = []
    if listing is not None and not listing.empty and "specimen" in listing.columns:
        others = list(zip(listing["specimen"], listing.get(
            MEASURED_SHA256_FIELD, pd.Series([""] * len(listing), index=listing.index)),
            strict=True))
    matched = match_hashless_records([e.specimen for e in entries],
                                     [e.specimen_sha256 for e in entries], others=others)
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

    e = _naming_entry(entries, group)
    specimen = f", specimen {tested_label(e.specimen, e.specimen_sha256)}" if e.specimen else ""
    return f"{e.load_case.full_label()}{specimen}"


def _naming_entry(entries: Sequence[MeasuredEntry], group: Sequence[int]) -> MeasuredEntry:
    """The record whose load case names the group: its first saved, then the unsaved ones in
    their order. The store lists its newest records first, so the group's first record was
    the latest saved, and a file saved to the case renamed it ("500 Hz" to "500.5 Hz")."""
    order = sorted(range(len(group)), key=lambda n: (not entries[group[n]].created_utc,
                                                     entries[group[n]].created_utc, n))
    return entries[group[order[0]]]


#: The file count the Compare page's load-case labels end with, e.g. " (2 file(s))".
_FILE_COUNT = re.compile(r" \(\d+ file\(s\)\)$")


def case_address(entries: Sequence[MeasuredEntry], group: Sequence[int]) -> str:
    """The group's load case as the page address names it: the store's load-case key of the
    record that names it (:func:`group_name`'s), then its specimen as labels name it (name
    and start of its hash, :func:`pidcore.specimen.tested_label`) where one is named, e.g.
    ``'f500Hz_a4.99967g_fill50pct_acrylic_z steel_6mm [3e945a]'``.

    Not the label shown, which counts the group's files: a file saved to the group later
    made that address name nothing. :func:`case_at_address` reads it back."""
    from ..specimen import tested_label

    e = _naming_entry(entries, group)
    specimen = tested_label(e.specimen, e.specimen_sha256)
    return f"{e.load_case.key} {specimen}" if specimen else e.load_case.key


def case_at_address(address: str, entries: Sequence[MeasuredEntry],
                    groups: Sequence[Sequence[int]]) -> int | None:
    """Index into ``groups`` (:func:`group_entries` of ``entries``) of the load case that
    :func:`case_address` wrote ``address`` for, or None where no group is that case any more.

    The case is met within the Compare tolerances (:class:`pidcore.compare.align.Tolerances`,
    the nearest group of its specimen where several are): the record that names a group may
    be another one by now (its first saved, re-saved since), whose measured frequency and
    acceleration differ in the last digits, and a hand-typed ``f500Hz_a5g...`` meets it. The
    label an older pidcore wrote there (:func:`group_name` and a file count) is read too,
    whatever the count."""
    from ..compare.align import Tolerances
    from ..loadcase import KEY_PATTERN, LoadCaseError, parse_key
    from ..specimen import tested_label

    key, _, specimen = str(address).strip().partition(" ")
    found = KEY_PATTERN.match(key)
    if found is None or found.end() != len(key):  # a DEM run key is not a load case's
        named = _FILE_COUNT.sub("", str(address))
        return next((n for n, group in enumerate(groups)
                     if named and group_name(entries, group) == named), None)
    try:
        case = parse_key(key)
    except LoadCaseError:  # e.g. a fill over 100 % typed into the address
        return None
    tolerances = Tolerances()
    near = [(tolerances.distance(entries[i].load_case, case), n)
            for n, group in enumerate(groups)
            if tested_label(entries[group[0]].specimen,
                            entries[group[0]].specimen_sha256) == specimen.strip()
            for i in group if tolerances.matches(entries[i].load_case, case)]
    return min(near)[1] if near else None


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



def headline_heading(head: Headline, dem_specimen: str = "") -> str:
    """The Compare page's heading of one load case: the like-for-like measured SDC, our DEM's
    (naming the specimen of its runs, ``dem_specimen``: another specimen's are never met) and
    the verdict; without a DEM value only the measured SDC and the verdict saying so and why
    ("vs our DEM none" read as a number)."""
    from .uploads import format_sdc

    measured = (f"measured ({head.measured_kind.split(' (')[0]}) "
                f"{format_sdc(head.measured, head.measured_stderr)}")
    if not math.isfinite(head.dem):
        return f"{measured} — {head.verdict}"
    dem = format_sdc(head.dem, head.dem_stderr) + (f" (specimen {dem_specimen})"
                                                   if dem_specimen else "")
    return f"{measured} vs our DEM {dem} — {head.verdict}"


def paper_details(comparison: CaseComparison, specimen: str) -> tuple[dict[str, str], str]:
    """The paper's Table 3 beside one load case of the Compare page: its metrics (label ->
    shown value; ``"none"`` where Table 3 has no value, which fits a metric's width) and a
    caption saying why a value is missing. A test of another specimen than the paper's
    coupon (``specimen``, the name its tests are saved under) gets no metrics, only the
    caption: Table 3 is not compared for it ("SDC paper DEM: none" read as if the paper had
    no value at a case it tabulates for its own coupon)."""
    from ..calibrate.prediction import sdc_text
    from ..compare.specimens import NOT_PAPER_SPECIMEN_NOTE
    from ..specimen import is_paper_coupon

    # by name: a test of another file of the coupon's name is saved as "paper_coupon
    # [45d792]" (measured_specimen_name), which is not the paper's
    if not is_paper_coupon(specimen):
        return {}, (NOT_PAPER_SPECIMEN_NOTE.format(name=specimen.strip())
                    + " (it tabulates the paper's coupon)")
    aligned = comparison.aligned
    values = (aligned.sdc_paper_dem, aligned.sdc_paper_experimental)
    # an SDC alone reads as the report's cells and Compare's DEM metric write it
    metrics = {label: sdc_text(v) if math.isfinite(v) else "none"
               for label, v in zip(("SDC paper DEM [-]", "SDC paper measured [-]"), values,
                                   strict=True)}
    caption = ("" if all(math.isfinite(v) for v in values) else
               "paper: none where Table 3 has no value at this case (it tabulates the paper's "
               "coupon, acrylic spheres driven along z, at its grid of load cases)")
    return metrics, caption

#: Report columns whose missing number is a result without a value, shown with the reason.
REPORT_STDERR_COLUMN = "SDC DEM stderr [-]"
REPORT_CHI2_COLUMN = CONSISTENCY_COLUMN


def _one_cell(settings: object) -> bool:
    """Whether a report row's "DEM settings" (:func:`pidcore.compare.align.dem_cases`: ``"cells
    1, steady cycles ..."``) say its runs simulated one cell (pooled settings say nothing)."""
    return str(settings).startswith("cells 1,") or str(settings) == "cells 1"


def _with_reason(values: pd.Series, present: pd.Series, reasons: list[str],
                 number: str) -> list[str]:
    """``values`` as text (format ``number``); a missing one is "" where ``present`` is false
    (nothing to have a value of), else its ``reasons`` entry."""
    import math

    values = pd.to_numeric(values, errors="coerce")
    return [format(v, number) if math.isfinite(v) else reason if there else ""
            for v, there, reason in zip(values, present, reasons, strict=True)]


#: The printf format (the grid's ``NumberColumn(format=...)``) of the report grid's SDC
#: columns: four significant digits, as :func:`pidcore.calibrate.prediction.sdc_text` writes a
#: report cell. The grid's default wrote four decimals: an SDC of 0.001101 as "0.0011" beside
#: its stderr "0.000254", the value coarser than its own error.
REPORT_SDC_FORMAT = "%.4g"


def report_number_formats(table: pd.DataFrame) -> dict[str, str]:
    """Column -> printf format for the Report tab's grid of :func:`report_display`'s ``table``
    (and the DEM tab's runs table, :func:`pidcore.app.jobs.dem_runs_table`):
    each numeric SDC column (``SDC ... [-]``) by :data:`REPORT_SDC_FORMAT`. The values stay
    numbers (the grid sorts them); only their text changes."""
    return {column: REPORT_SDC_FORMAT for column in table.columns
            if str(column).startswith("SDC ") and str(column).endswith("[-]")
            and pd.api.types.is_numeric_dtype(table[column])}


def report_display(table: pd.DataFrame) -> pd.DataFrame:
    """The Report tab's view of :func:`pidcore.report.downloads.store_report_table`: the grid
    shows a cell empty by design (a measured column of a DEM-only row) empty (its
    ``placeholder``), and two results that can lack a value as text saying why. The DEM
    standard error: ``"n/a (1 cell)"`` where the run
    simulated one cell (one cell has no scatter to take a standard error from; the DEM tab says
    the same), ``"n/a"`` where it is missing otherwise, empty where no DEM ran. The measured
    chi2/dof: ``"n/a (1 measurement)"`` for one measurement (nothing to scatter), empty where
    none. The calibrated band in one cell, as :func:`pidcore.report.table.with_band_text`
    writes it (the grid wrote its two numbers ``0.0000`` and ``16.9115``). The downloads keep
    the table as ``pidcore report`` writes it (empty cells, the band's two numbers)."""
    import numpy as np

    if table.empty or not {REPORT_STDERR_COLUMN, REPORT_CHI2_COLUMN} <= set(table.columns):
        return with_band_text(table)
    out = with_band_text(table).copy()
    dem = np.isfinite(pd.to_numeric(table["SDC DEM (ours) [-]"], errors="coerce"))
    settings = table.get("DEM settings", pd.Series("", index=table.index))
    out[REPORT_STDERR_COLUMN] = _with_reason(  # 3 digits, as the DEM tab's runs table
        table[REPORT_STDERR_COLUMN], dem,
        ["n/a (1 cell)" if _one_cell(s) else "n/a" for s in settings], ".3g")
    measured = np.isfinite(pd.to_numeric(table[MEASURED_EQ11_COLUMN], errors="coerce"))
    sources = table.get("source file(s)", pd.Series("", index=table.index))
    out[REPORT_CHI2_COLUMN] = _with_reason(  # 2 digits, as the Compare tab says it
        table[REPORT_CHI2_COLUMN], measured,
        ["n/a (1 measurement)" if s and "; " not in str(s) else "n/a" for s in sources], ".2g")
    # the notes name parameters by the library's keywords: here by the page's fields
    if "note" in out.columns:
        out["note"] = [page_terms(n) if isinstance(n, str) else n for n in out["note"]]
    out.attrs = dict(table.attrs)
    if "notes" in table.attrs:
        out.attrs["notes"] = [page_terms(n) for n in table.attrs["notes"]]
    return out
