"""One load case on paper: a PDF with the headline, the calibrated DEM's prediction, band and
verdict (as the report's row of the case gives them), SDC against fill, the loops and the
corrections each file was analysed with.

Drawn with matplotlib from the same frames the app's charts draw
(:func:`pidcore.compare.case.sdc_points`, :func:`pidcore.report.case_view.loop_frame`). The
Compare page prints one case's sheet; ``pidcore report --case-sheets`` writes every measured
case's (:func:`case_sheets`), both from :func:`pidcore.report.case_view.case_view`.
"""

from __future__ import annotations

import io
import math
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass

import pandas as pd

from ..calibrate.prediction import (
    MeasurementJudgement,
    band_text,
    judge_measurement,
    sdc_text,
)
from ..compare.align import CALIBRATED_INSIDE_COLUMN, PACKING_RATIO_COLUMN
from ..compare.case import CaseComparison, MeasuredEntry
from ..plot_text import text_as_typed
from ..units import display_value_with_error
from .case_view import case_title, case_view, group_entries
from .render import bounded_stem

#: Page size of the sheet, inches (A4 landscape).
PAGE_IN = (11.69, 8.27)


@dataclass(frozen=True)
class CalibratedCase:
    """The calibrated DEM beside one load case's measurement, as the Compare page and the
    load-case PDF sheet (:func:`case_pdf`) show it
    (:func:`calibrated_case`).

    ``label`` names the calibration shown ("" where none speaks for the measurement's
    specimen); ``judgement`` is its prediction, band and verdict (:func:`pidcore.calibrate.
    prediction.judge_measurement`, the report row's rule), None where it predicts nothing
    here; ``said`` is what is said instead or besides: calibrations that cannot be read, none
    of this specimen, none predicting this load case.
    """

    label: str = ""
    judgement: MeasurementJudgement | None = None
    said: tuple[str, ...] = ()

    def sheet_lines(self) -> list[str]:
        """The lines a printed page gives it: the calibrated SDC, its 95 % band and the
        verdict in the words of the report's columns and note; without a judgement, that
        there is no calibrated verdict and why (a sheet with nothing read as one judged by
        no calibration, or as one whose calibration was lost)."""
        j = self.judgement
        if j is None:
            why = "; ".join(self.said) or "no calibration given"
            return [f"calibrated DEM: no calibrated verdict ({why})"]
        lines = [f"calibrated DEM ({self.label}): SDC (Eq. 11) {sdc_text(j.sdc)}, 95 % band "
                 f"{band_text(j.low, j.high)} [-]",
                 f"{CALIBRATED_INSIDE_COLUMN}: {j.verdict}"]
        if j.note:
            lines.append(f"  ({j.note})")
        return lines


def calibrated_case(calibrations: Sequence[tuple[object | None, str]],
                    comparison: CaseComparison, specimen: str, *,
                    implausible: bool = False, specimen_sha256: str = "") -> CalibratedCase:
    """The calibrated DEM's Eq. 11 SDC, 95 % band and verdict at ``comparison``'s load case.

    ``calibrations``: [(calibration or None, label)] of
    :func:`pidcore.app.calibration.available_calibrations`; the first that predicts the case
    is shown (a calibration of one specimen does not hide another's), of those that speak for
    the measurement's ``specimen`` ("": not named) and its file (``specimen_sha256``: a
    calibration of another file of that name is not its). ``implausible``: the measurement
    pools a record the plausibility checks refuse (not judged, as the report's row)."""
    said = [reason for c, reason in calibrations if c is None]  # none, or unreadable
    usable = [(c, label) for c, label in calibrations if c is not None]
    if not usable:
        return CalibratedCase(said=tuple(said))
    mine = [(c, label) for c, label in usable if c.speaks_for(specimen, specimen_sha256)]
    if not mine:  # the report refuses another specimen's calibration too
        reasons = [c.other_file_reason(specimen_sha256, specimen) for c, _ in usable]
        said.append(f"No calibration is of specimen {specimen}: "
                    + "; ".join(label + (f" ({why})" if why else "")
                                for (_, label), why in zip(usable, reasons, strict=True)) + ".")
        return CalibratedCase(said=tuple(said))
    hits = [(c, label, c.lookup(comparison.load_case)) for c, label in mine]
    _, label, hit = next((h for h in hits if h[2] is not None), hits[0])
    if hit is None:
        said.append(f"No calibration predicts {comparison.load_case.full_label()}: "
                    + "; ".join(f"{label} predicts {len(c.predictions)} measured load case(s)"
                                for c, label, _ in hits) + ".")
        return CalibratedCase(label=label, said=tuple(said))
    return CalibratedCase(label=label, said=tuple(said), judgement=judge_measurement(
        hit, comparison.measured_sdc, comparison.measured_stderr,
        comparison.measured_stderr_dof, comparison.measured_baseline_sdc,
        pools_implausible=implausible))


def members_calibrated_case(calibrations: Sequence[tuple[object | None, str]],
                            comparison: CaseComparison,
                            members: Sequence[MeasuredEntry]) -> CalibratedCase:
    """:func:`calibrated_case` of a load case's pooled ``members``: of their specimen (one:
    :func:`pidcore.report.case_view.group_entries` never pools two) and file, not judged where
    one of them is implausible (as the report's row)."""
    return calibrated_case(calibrations, comparison, members[0].specimen,
                           implausible=any(e.implausible for e in members),
                           specimen_sha256=members[0].specimen_sha256)


_NO_CALIBRATION = CalibratedCase()


def plot_sdc_points(points: pd.DataFrame, ax) -> None:
    """SDC against fill: the model as a line, every other series as points with error bars."""
    for k, (series, group) in enumerate(points.groupby("series", sort=False)):
        x, y = group[PACKING_RATIO_COLUMN].to_numpy(float), group["SDC [-]"].to_numpy(float)
        if series.startswith("pchip model"):
            ax.plot(x, y, color="0.5", label=series)
            continue
        err = [y - group["low [-]"].to_numpy(float), group["high [-]"].to_numpy(float) - y]
        ax.errorbar(x, y, yerr=err, fmt="os^Dv<>"[k % 7], capsize=3, label=series)
    ax.set_xlabel(PACKING_RATIO_COLUMN)
    ax.set_ylabel("SDC [-]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="x-small")


def plot_loops(loops: pd.DataFrame, ax) -> None:
    """Force-displacement loops of a :func:`pidcore.report.case_view.loop_frame`, in µm and N."""
    for series, group in loops.groupby("series", sort=False):
        ax.plot(group["displacement [m]"].to_numpy(float) * 1e6,
                group["force [N]"].to_numpy(float), label=series)
    ax.set_xlabel("displacement [µm]")
    ax.set_ylabel("force [N]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="x-small")


def sheet_lines(view: dict, *, title: str, calibrated: CalibratedCase | None = None
                ) -> list[str]:
    """The text lines at the top of :func:`case_pdf`'s first page: the title, the headline
    (measured SDC against our DEM and the verdict), the measured Eq. 11 SDC (where the headline's
    is Eq. 10's), the calibrated DEM's SDC, 95 % band and
    verdict in the words of the report's row (``calibrated``:
    :func:`calibrated_case`; None: no calibration given, said so), the
    DEM alignment and the view's notes."""
    head, comp = view["headline"], view["comparison"]
    # without a DEM value the verdict says so and why ("vs our DEM none" read as a number)
    dem = (f"  vs  our DEM {display_value_with_error(head.dem, head.dem_stderr)}"
           if math.isfinite(head.dem) else "")
    lines = [title,
             f"measured SDC ({head.measured_kind}) "
             f"{display_value_with_error(head.measured, head.measured_stderr)}{dem}: "
             f"{head.verdict}",
             *([f"  ({head.basis})"] if head.basis else [])]
    if head.measured_kind != "Eq. 11":
        # the SDC the calibrated band judges, the report's "SDC measured (Eq. 11)": the sheet
        # gave the verdict on a number it did not show
        taken = comp.measured_baseline_sdc
        lines.append(f"measured SDC (Eq. 11) "
                     f"{display_value_with_error(comp.measured_sdc, comp.measured_stderr)}"
                     + (f", the empty coupon's damping (SDC {sdc_text(taken)}) taken off"
                        if taken and math.isfinite(taken) else
                        ", the empty coupon's damping taken off (SDC not stored)"
                        if not math.isfinite(taken) else ""))
    # the report's row of this case says the calibrated verdict; a sheet handed on without it
    # read as if no calibration had been asked for
    lines += (calibrated or _NO_CALIBRATION).sheet_lines()
    lines.append(f"DEM alignment: {comp.aligned.status}. {comp.aligned.message}")
    lines += [f"note: {n}" for n in view["notes"]]
    return lines


@text_as_typed
def case_pdf(view: dict, *, title: str, calibrated: CalibratedCase | None = None) -> bytes:
    """PDF bytes of one load case from the Compare page's case view
    (:func:`pidcore.report.case_view.case_view`: ``comparison``, ``headline``, ``sdc_points``,
    ``loops``, ``energies``, ``notes``) and the calibrated DEM beside it (``calibrated``, see
    :func:`sheet_lines`)."""
    from matplotlib.backends.backend_pdf import PdfPages
    from matplotlib.figure import Figure

    comp = view["comparison"]
    lines = sheet_lines(view, title=title, calibrated=calibrated)
    buffer = io.BytesIO()
    with PdfPages(buffer) as pdf:
        fig = Figure(figsize=PAGE_IN, layout="constrained")
        top, bottom = fig.subfigures(2, 1, height_ratios=[1, 3])
        top.text(0.01, 0.95, "\n".join(lines), va="top", fontsize=9, family="monospace",
                 wrap=True)
        left, right = bottom.subplots(1, 2)
        plot_sdc_points(view["sdc_points"], left)
        plot_loops(view["loops"], right)
        pdf.savefig(fig)
        fig = Figure(figsize=PAGE_IN, layout="constrained")
        ax = fig.subplots()
        ax.axis("off")
        table = comp.measured.copy()
        for column in table.columns:
            if pd.api.types.is_float_dtype(table[column]):
                table[column] = table[column].map(lambda v: f"{v:.5g}")
        ax.set_title("files, corrections used and results", loc="left")
        cells = ax.table(cellText=table.astype(str).to_numpy(), colLabels=list(table.columns),
                         loc="upper left", cellLoc="left")
        cells.auto_set_font_size(False)
        cells.set_fontsize(7)
        cells.auto_set_column_width(list(range(len(table.columns))))
        pdf.savefig(fig)
    return buffer.getvalue()




def sheet_stem(key: str, specimen: str = "", specimen_sha256: str = "") -> str:
    """The file name (without ``.pdf``) of a load case's sheet: the load-case ``key``, and
    where its tests name a ``specimen``, that specimen as labels name it (name and start of
    its file's hash ``specimen_sha256``), in characters any file system keeps, e.g.
    ``'f100Hz_a5g_fill50pct_acrylic_z_steel_6mm_3e945a'``: two specimens' sheets of one load
    case are two files. A name longer than :data:`pidcore.report.render.MAX_SHEET_STEM` is
    cut there (:func:`pidcore.report.render.bounded_stem`), ending in 8 hex digits of the
    whole name's sha256 (two long names that begin alike stay two).

    A report's sheet is named from its row (``load case``, ``specimen``, ``specimen sha256``
    of ``report.csv``), so that the row finds it (:func:`case_sheets`)."""
    from ..specimen import tested_label

    label = tested_label(specimen, specimen_sha256)
    safe = re.sub(r"[^A-Za-z0-9._+-]+", "_", label).strip("_.")
    stem = f"{key}_{safe}" if safe else key
    return bounded_stem(stem)


def case_sheet_stem(comparison: CaseComparison, members: Sequence[MeasuredEntry]) -> str:
    """:func:`sheet_stem` of a load case the Compare page shows: its measured load-case key
    and its tests' specimen."""
    return sheet_stem(comparison.load_case.key, members[0].specimen,
                      members[0].specimen_sha256)


@dataclass(frozen=True)
class CaseSheet:
    """One load case's PDF sheet (:func:`case_sheets`): ``name`` the file's
    (:func:`sheet_stem` and ``.pdf``), ``title`` its first line, ``pdf`` its bytes."""

    name: str
    title: str
    pdf: bytes


def case_sheets(entries: Sequence[MeasuredEntry], dem_runs: pd.DataFrame | None,
                paper: pd.DataFrame, store_paths: Sequence[str | os.PathLike | None],
                calibrations: Sequence[tuple[object | None, str]] = (), *,
                groups: Sequence[Sequence[int]] | None = None,
                group_calibrations: Sequence[Sequence[tuple[object | None, str]]] | None = None,
                group_keys: Sequence[str] | None = None,
                notes: Sequence[str] = (), progress: bool = False) -> list[CaseSheet]:
    """The sheet of every load case of ``entries``, as the Compare page prints each: grouped
    (:func:`pidcore.report.case_view.group_entries`), viewed
    (:func:`pidcore.report.case_view.case_view` with the DEM runs ``dem_runs`` of the stores
    ``store_paths`` and Table 3 ``paper``), judged by ``calibrations`` ([(calibration,
    label)], :func:`members_calibrated_case`; empty: no calibration given, said on the
    sheet) and titled (:func:`pidcore.report.case_view.case_title`). ``entries``: each
    measured data set once (:func:`pidcore.compare.case.unique_entries`), specimens matched
    (:func:`pidcore.report.case_view.matched_specimens`). In the order of the groups; a file
    name two cases would share (as Windows compares names: case-folded) gets ``_2``,
    ``_3``, ... .

    ``groups``: the indices of ``entries`` each sheet pools, of one specimen each (a report's
    rows, :func:`pidcore.report.pipeline.report_case_sheets`); default the page's groups.
    ``group_calibrations``: per group, the calibrations judging it in place of
    ``calibrations``. ``group_keys``: per group, the load-case key its file is named by (a
    report's rows: the row's ``load case``, the DEM grid case a row on the grid shows, where
    its tests' mean measured case named the sheet and no row of ``report.csv`` found it);
    default each group's measured one (:func:`case_sheet_stem`, the page's).
    ``notes``: said on every sheet (once). ``progress``: a bar over the sheets on stderr
    (about a second each: a report of 50 measured cases drew for most of a minute without
    one)."""
    sheets: list[CaseSheet] = []
    # compared case-folded: Windows and macOS keep "x_Own.pdf" and "x_own.pdf" as one file,
    # so unpacked there one sheet replaced the other
    taken: set[str] = set()
    groups = group_entries(entries) if groups is None else groups
    numbered = enumerate(groups)
    if progress:
        from tqdm import tqdm

        numbered = tqdm(numbered, total=len(groups), unit="sheet", desc="load case sheets",
                        leave=False, dynamic_ncols=True)
    for k, group in numbered:
        members = [entries[i] for i in group]
        view = case_view(members, dem_runs, paper, store_paths)
        view["notes"] = list(dict.fromkeys([*view["notes"], *notes]))
        comparison = view["comparison"]
        title = case_title(entries, group)
        stem = sheet_stem(comparison.load_case.key if group_keys is None else group_keys[k],
                          members[0].specimen, members[0].specimen_sha256)
        name, n = f"{stem}.pdf", 1
        while name.casefold() in taken:
            n += 1
            name = f"{stem}_{n}.pdf"
        taken.add(name.casefold())
        sheets.append(CaseSheet(name, title, case_pdf(
            view, title=title,
            calibrated=members_calibrated_case(
                calibrations if group_calibrations is None else group_calibrations[k],
                comparison, members))))
    return sheets
