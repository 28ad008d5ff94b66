"""One load case on paper: a PDF with the headline, SDC against fill, the loops and the
corrections each file was analysed with.

Drawn with matplotlib from the same frames the app's charts draw
(:func:`pidcore.compare.case.sdc_points`, :func:`pidcore.app.workbench.loop_frame`).
"""

from __future__ import annotations

import io
import math

import pandas as pd

from ..compare.align import PACKING_RATIO_COLUMN
from ..units import display_value_with_error

#: Page size of the sheet, inches (A4 landscape).
PAGE_IN = (11.69, 8.27)


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
    """Force-displacement loops of a :func:`pidcore.app.workbench.loop_frame`, in µm and N."""
    for series, group in loops.groupby("series", sort=False):
        ax.plot(group["displacement [m]"].to_numpy(float) * 1e6,
                group["force [N]"].to_numpy(float), label=series)
    ax.set_xlabel("displacement [µm]")
    ax.set_ylabel("force [N]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="x-small")


def case_pdf(view: dict, *, title: str) -> bytes:
    """PDF bytes of one load case from the app's case view
    (:func:`pidcore.app.workbench.case_view`: ``comparison``, ``headline``, ``sdc_points``,
    ``loops``, ``energies``, ``notes``)."""
    from matplotlib.backends.backend_pdf import PdfPages
    from matplotlib.figure import Figure

    head, comp = view["headline"], view["comparison"]
    buffer = io.BytesIO()
    with PdfPages(buffer) as pdf:
        fig = Figure(figsize=PAGE_IN, layout="constrained")
        top, bottom = fig.subfigures(2, 1, height_ratios=[1, 3])
        # without a DEM value the verdict says so and why ("vs our DEM none" read as a number)
        dem = (f"  vs  our DEM {display_value_with_error(head.dem, head.dem_stderr)}"
               if math.isfinite(head.dem) else "")
        lines = [title,
                 f"measured SDC ({head.measured_kind}) "
                 f"{display_value_with_error(head.measured, head.measured_stderr)}{dem}: "
                 f"{head.verdict}",
                 *([f"  ({head.basis})"] if head.basis else []),
                 f"DEM alignment: {comp.aligned.status}. {comp.aligned.message}"]
        lines += [f"note: {n}" for n in view["notes"]]
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
