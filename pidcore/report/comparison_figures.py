"""Report figures that compare measurement, our DEM and the paper (plotting only).

* :func:`plot_sdc_comparison` - per load case: measured SDC over Eq. 10's E ± standard error
  beside our DEM's (Eq. 10) SDC ± standard error, the paper's DEM and experimental values, and
  the measured Eq. 11 SDC marked as the different quantity it is.
* :func:`plot_loop_overlay` - force-displacement loop of a measurement over the DEM's loop at
  the same load case.
* :func:`dem_loop_from_arrays` - the DEM loop from a stored run's decimated time series.

The model families (paper Figs. 8-14) are in :mod:`pidcore.report.figures`.
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping

import numpy as np
import pandas as pd

from .. import defaults
from ..loop import ForceDisplacementLoop
from ..plot_text import text_as_typed
from .table import (
    ALIGNMENT_COLUMN,
    MEASURED_EQ10_COLUMN,
    MEASURED_EQ11_COLUMN,
    MEASURED_EQ11_STDERR_COLUMN,
    PACKING_RATIO_COLUMN,
    SPECIMEN_SHA256_COLUMN,
    differing_columns,
)

#: Force arrays looked for in a DEM run, in order: the force a shaker's gauge would measure
#: (coupon inertia + particles, :class:`pidcore.dem.result.DemResult`), comparable with a
#: measured force; then the particles' force on the walls alone.
DEM_FORCE_ARRAYS: tuple[str, ...] = ("shaker_force_n", "wall_force_n")
#: Coupon velocity arrays looked for in a DEM run.
DEM_VELOCITY_ARRAYS: tuple[str, ...] = ("velocity_m_s",)
#: Time arrays (sample instants) looked for in a DEM run.
DEM_TIME_ARRAYS: tuple[str, ...] = ("sample_time_s",)


def _new_figure(width: float, height: float):
    # A bare Figure needs no GUI backend and is not kept alive by pyplot's registry.
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")


#: Most load cases on one panel of the SDC-per-load-case figure; more wrap onto further panels.
SDC_FIGURE_ROWS_PER_PANEL = 16
#: Table columns the SDC-per-load-case figure draws: a row with a finite value in any is drawn.
_DRAWN_COLUMNS: tuple[str, ...] = (MEASURED_EQ10_COLUMN, "SDC DEM (ours) [-]",
                                   "SDC DEM (paper) [-]", "SDC measured (paper) [-]",
                                   MEASURED_EQ11_COLUMN)


@text_as_typed
def plot_sdc_comparison(table: pd.DataFrame, *, ax=None):
    """SDC per load case: measured, our DEM and the paper's values side by side.

    Our DEM's SDC divides the energy dissipated per cycle by Eq. 10's ``E = m_c a^2 / (2 w^2)``,
    so the measurement drawn beside it is the same SDC, the measured energy per cycle over that
    E (:data:`pidcore.report.table.MEASURED_EQ10_COLUMN`, the value the table's difference column
    uses). The Eq. 11 SDC (over the reactive energy ``Im(P_c)/w``) is a different quantity,
    typically a few times larger; where the table has it, it is drawn apart as hollow markers
    with a legend saying so.

    Parameters
    ----------
    table : pandas.DataFrame
        The report table (:func:`pidcore.report.build_report_table`). Every row with a value
        to draw (measured, our DEM, the paper's) is drawn, in the table's order; a series with
        no value in any row is left out, and so is its legend entry. More rows than
        :data:`SDC_FIGURE_ROWS_PER_PANEL` wrap onto panels stacked below (not with ``ax``).
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Error bars are one standard error; the Eq. 10 measured value carries the relative
        standard error of the Eq. 11 value (only the reference energy differs; exact for a
        single record, the pooled relative error for several). Interpolated DEM values are drawn
        as open markers without error bars (the model carries none).
    """
    drawn = np.column_stack([table[c].astype(float).to_numpy() for c in _DRAWN_COLUMNS])
    rows = table[np.isfinite(drawn).any(axis=1)]
    labels = sdc_tick_labels(rows)
    if ax is not None:
        _draw_sdc_rows(ax, rows, labels)
        axes = [ax]
    else:
        # the paper's 48 load cases in one row of ticks made a 37-inch strip, unreadable in the
        # HTML and PDF: long tables wrap onto panels of at most SDC_FIGURE_ROWS_PER_PANEL
        n_panels = max(1, -(-len(rows) // SDC_FIGURE_ROWS_PER_PANEL))
        per_panel = -(-len(rows) // n_panels) if len(rows) else 0
        fig = _new_figure(max(6.4, 0.65 * per_panel + 2.0) + 3.6, 4.2 * n_panels)
        axes = list(fig.subplots(n_panels, 1, squeeze=False)[:, 0])
        for i, panel in enumerate(axes):
            part = slice(i * per_panel, (i + 1) * per_panel)
            _draw_sdc_rows(panel, rows.iloc[part], labels[part])
    axes[0].set_title("SDC per load case (ours: dissipated energy over Eq. 10's E)")
    handles: dict[str, object] = {}
    for panel in axes:  # a series may be drawn on a later panel only
        for handle, label in zip(*panel.get_legend_handles_labels(), strict=True):
            handles.setdefault(label, handle)
    # outside the axes: six long entries would hide the markers they describe
    if handles:
        axes[0].legend(list(handles.values()), list(handles), fontsize="small",
                       loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return axes[0].figure


#: Characters of a line of a tick label's setting (:func:`sdc_tick_labels`): about a tick's
#: width at the labels' size.
_TICK_LINE = 14


def sdc_tick_labels(rows: pd.DataFrame) -> list[str]:
    """The tick label of each row of :func:`plot_sdc_comparison`: its frequency, acceleration
    and fill; its material where the rows differ in it (an acrylic measurement beside a steel
    DEM run at one load case); and where two labels would still read the same, the settings
    those rows differ in (:func:`~pidcore.report.table.differing_columns`: two DEM runs of
    one load case at other settings had two identical ticks of different SDCs)."""
    several = "material" in differing_columns(rows)
    labels = [f"{r['frequency [Hz]']:.4g} Hz\n{r['acceleration [g]']:.3g} g\n"
              f"{r[PACKING_RATIO_COLUMN]:.3g} %" + (f"\n{r['material']}" if several else "")
              for _, r in rows.iterrows()]
    for label in {label for label in labels if labels.count(label) > 1}:
        alike = [i for i, other in enumerate(labels) if other == label]
        for column in differing_columns(rows.iloc[alike]):
            for i in alike:
                value = str(rows.iloc[i][column] or "")
                if column == SPECIMEN_SHA256_COLUMN and value:
                    value = f"sha256 {value[:8]}"  # 64 digits: the first tell files apart
                labels[i] += "".join(f"\n{line}" for line in textwrap.wrap(value, _TICK_LINE))
    return labels


def _draw_sdc_rows(ax, rows: pd.DataFrame, labels: list[str]) -> None:
    """One panel of :func:`plot_sdc_comparison`: a tick per row (``labels``), the row's values
    beside it."""
    n = len(rows)
    x = np.arange(n, dtype=float)
    width = 0.15
    sdc11 = rows[MEASURED_EQ11_COLUMN].astype(float).to_numpy()
    sdc11_se = rows[MEASURED_EQ11_STDERR_COLUMN].astype(float).to_numpy()
    sdc10 = rows[MEASURED_EQ10_COLUMN].astype(float).to_numpy()
    with np.errstate(divide="ignore", invalid="ignore"):
        # a standard error is >= 0 whatever the signs (a negative SDC within its noise)
        sdc10_se = np.abs(sdc11_se * sdc10 / sdc11)
    has10 = np.isfinite(sdc10)
    # a series without a finite value is not drawn, so the legend names only what is drawn
    if has10.any():
        ax.errorbar(x[has10] - 2 * width, sdc10[has10], yerr=sdc10_se[has10], fmt="o",
                    color="C0", capsize=3, label="measured (ours), SDC of Eq. 10 E ± SE")
    ours = rows["SDC DEM (ours) [-]"].astype(float).to_numpy()
    ours_se = rows["SDC DEM stderr [-]"].astype(float).to_numpy()
    on_grid = (rows[ALIGNMENT_COLUMN] == "grid").to_numpy() & np.isfinite(ours)
    if on_grid.any():
        ax.errorbar(x[on_grid] - width, ours[on_grid], yerr=ours_se[on_grid], fmt="s",
                    color="C1", capsize=3, label="DEM (ours), SDC of Eq. 10 E ± SE")
    interpolated = ~on_grid & np.isfinite(ours)
    if interpolated.any():
        ax.plot(x[interpolated] - width, ours[interpolated], "s", markerfacecolor="none",
                color="C1", label="DEM (ours), SDC of Eq. 10 E, pchip-interpolated")
    for offset, column, marker, color, label in (
            (0.0, "SDC DEM (paper) [-]", "D", "C2", "DEM (paper)"),
            (width, "SDC measured (paper) [-]", "^", "C3", "measured (paper)")):
        values = rows[column].astype(float).to_numpy()
        if np.isfinite(values).any():
            ax.plot(x + offset, values, marker, color=color, label=label)
    has11 = np.isfinite(sdc11)
    if has11.any():
        ax.errorbar(x[has11] + 2 * width, sdc11[has11], yerr=sdc11_se[has11], fmt="v",
                    markerfacecolor="none", color="0.4", capsize=3,
                    label="measured (ours), Eq. 11 SDC over Im(P_c)/w ± SE:\n"
                          "a different quantity, not comparable with the Eq. 10 SDC")
    ax.set_xticks(x, labels, fontsize="small")
    # autoscaling fits the markers, which sit up to 2 widths off their tick: with one load case
    # its tick landed on the axes' left edge and its marker on the right one
    if n:
        ax.set_xlim(-0.5, n - 0.5)
    ax.set_ylabel("SDC [-]")
    ax.grid(axis="y", alpha=0.3)


def _first(arrays: Mapping[str, np.ndarray], names: tuple[str, ...]) -> np.ndarray | None:
    for name in names:
        if name in arrays:
            return np.asarray(arrays[name], dtype=float)
    return None


def dem_loop_from_arrays(arrays: Mapping[str, np.ndarray],
                         record: Mapping[str, object] | None = None,
                         ) -> ForceDisplacementLoop | str:
    """One period of a DEM run's force-displacement loop, or a note why there is none.

    The stored virtual shaker record (force :data:`DEM_FORCE_ARRAYS`, coupon velocity
    :data:`DEM_VELOCITY_ARRAYS`) from the steady state on (``steady_start_cycle`` of the record)
    is analysed like a measurement (:func:`pidcore.signal.analyze_power`) and the loop
    synthesised from its harmonics, so measured and DEM loops are drawn the same way.

    Parameters
    ----------
    arrays : mapping
        The run's arrays (:attr:`pidcore.store.StoredEntry.arrays`).
    record : mapping, optional
        The run's scalars: ``frequency_hz``, ``sample_rate_hz`` (else from the time array),
        ``steady_start_cycle`` (default 0).

    Returns
    -------
    ForceDisplacementLoop or str
    """
    from ..errors import PidcoreError
    from ..signal import analyze_power

    record = record or {}
    force = _first(arrays, DEM_FORCE_ARRAYS)
    velocity = _first(arrays, DEM_VELOCITY_ARRAYS)
    if force is None or velocity is None:
        return (f"DEM run keeps no force ({', '.join(DEM_FORCE_ARRAYS)}) or velocity "
                f"({', '.join(DEM_VELOCITY_ARRAYS)}) time series")
    if force.shape != velocity.shape or force.ndim != 1:
        return "DEM run's force and velocity arrays differ in shape"
    rate = record.get("sample_rate_hz")
    time = _first(arrays, DEM_TIME_ARRAYS)
    if not isinstance(rate, int | float) and time is not None and time.size > 1:
        rate = 1.0 / float(np.mean(np.diff(time)))
    freq = record.get("frequency_hz")
    if not isinstance(rate, int | float) or not isinstance(freq, int | float):
        return "DEM run lacks sample_rate_hz or frequency_hz"
    start_cycle = record.get("steady_start_cycle") or 0
    start = int(round(float(start_cycle) * float(rate) / float(freq)))
    try:
        analysis = analyze_power(force[start:], velocity[start:], float(rate),
                                 frequency_hz=float(freq), source="DEM run")
    except PidcoreError as exc:
        return f"DEM time series cannot be analysed ({exc})"
    return analysis.loop()


def loop_from_phasors(arrays: Mapping[str, np.ndarray], frequency_hz: object, *,
                      n_points: int = defaults.LOOP_POINTS) -> ForceDisplacementLoop | str:
    """One period of a stored analysis' force-displacement loop, or a note why there is none.

    Reads the stored harmonic phasors (``harmonics``, ``force_phasors_n``,
    ``velocity_phasors_m_s``, as :func:`pidcore.measure.analysis_arrays` stores them) into
    :meth:`pidcore.loop.ForceDisplacementLoop.from_phasors`, the synthesis behind
    :meth:`pidcore.signal.PowerAnalysis.loop`.
    """
    needed = ("harmonics", "force_phasors_n", "velocity_phasors_m_s")
    if any(name not in arrays for name in needed):
        return f"stored analysis keeps no harmonic phasors ({', '.join(needed)})"
    if not isinstance(frequency_hz, int | float) or not frequency_hz > 0:
        return "stored analysis has no drive frequency"
    return ForceDisplacementLoop.from_phasors(
        arrays["harmonics"], arrays["force_phasors_n"], arrays["velocity_phasors_m_s"],
        float(frequency_hz), n_points=n_points)


def loop_arrays(loop: ForceDisplacementLoop | tuple) -> tuple[np.ndarray, np.ndarray]:
    """(displacement m, force N) from a :class:`~pidcore.loop.ForceDisplacementLoop` or a
    ``(displacement, force)`` 2-tuple."""
    if isinstance(loop, ForceDisplacementLoop):
        return loop.displacement_m, loop.force_n
    if isinstance(loop, tuple) and len(loop) == 2:
        return np.asarray(loop[0], dtype=float), np.asarray(loop[1], dtype=float)
    raise TypeError(f"cannot read a force-displacement loop from {type(loop).__name__}")


def _closed(x: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Append the first point so a one-period loop is drawn closed."""
    return np.append(x, x[:1]), np.append(f, f[:1])


@text_as_typed
def plot_loop_overlay(measured: ForceDisplacementLoop | tuple,
                      dem: ForceDisplacementLoop | tuple | None, *,
                      title: str = "", ax=None):
    """Force-displacement loop of a measurement, with the DEM's at the same load case.

    Parameters
    ----------
    measured : ForceDisplacementLoop or (displacement m, force N)
        The measured loop (see :func:`loop_arrays`).
    dem : ForceDisplacementLoop or (displacement m, force N) or None
        The DEM loop (:func:`dem_loop_from_arrays`), or None to draw the measurement alone.
    title : str
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Displacement in µm, force in N; the enclosed area is the energy per cycle.
    """
    if ax is None:
        fig = _new_figure(5.5, 4.2)
        ax = fig.subplots()
    else:
        fig = ax.figure
    x, f = _closed(*loop_arrays(measured))
    ax.plot(x * 1e6, f, color="C0", label="measured")
    if dem is not None:
        xd, fd = _closed(*loop_arrays(dem))
        ax.plot(xd * 1e6, fd, color="C1", alpha=0.8, label="DEM (ours)")
    ax.set_xlabel("displacement [µm]")
    ax.set_ylabel("force [N]")
    ax.set_title(title or "force-displacement loop")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    return fig

