"""What the Compare page shows, assembled from records and stores (no Streamlit here).

Records come from this session's uploads and from every saved analysis of the store
(:func:`pidcore.store.listing.saved_analyses`), so a reload or another session sees them;
they are grouped and compared by :mod:`pidcore.report.case_view`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import pandas as pd

from ..compare.case import CaseComparison, Headline, MeasuredEntry
from ..report.case_view import CASE_TITLE_FILE_COUNT, group_name, naming_entry
from ..report.table import CONSISTENCY_COLUMN, MEASURED_EQ11_COLUMN, with_band_text
from .vocabulary import page_terms

# The records, their groups per load case and a case's view are the library's
# (pidcore.report.case_view), which `pidcore report --case-sheets` prints too; the page's
# address of a case and its layout helpers are here.


def case_address(entries: Sequence[MeasuredEntry], group: Sequence[int]) -> str:
    """The group's load case as the page address names it: the store's load-case key of the
    record that names it (:func:`group_name`'s), then its specimen as labels name it (name
    and start of its hash, :func:`pidcore.specimen.tested_label`) where one is named, e.g.
    ``'f500Hz_a4.99967g_fill50pct_acrylic_z steel_6mm [3e945a]'``.

    Not the label shown, which counts the group's files: a file saved to the group later
    made that address name nothing. :func:`case_at_address` reads it back."""
    from ..specimen import tested_label

    e = naming_entry(entries, group)
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
        named = CASE_TITLE_FILE_COUNT.sub("", str(address))
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
