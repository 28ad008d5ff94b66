"""Report figures that compare measurement, our DEM and the paper (plotting only).

* :func:`plot_sdc_comparison` - per load case: measured SDC ± standard error, our DEM mean ±
  standard error, the paper's DEM and experimental values.
* :func:`plot_loop_overlay` - force-displacement loop of a measurement over the DEM's loop at
  the same load case.

Loops come as data from :mod:`pidcore.signal.loops` (the app's charts draw the same data).

The model families (paper Figs. 8-14) are in :mod:`pidcore.report.figures`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .table import ALIGNMENT_COLUMN


def _new_figure(width: float, height: float):
    # A bare Figure needs no GUI backend and is not kept alive by pyplot's registry.
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")


def plot_sdc_comparison(table: pd.DataFrame, *, ax=None):
    """SDC per load case: measured, our DEM and the paper's values side by side.

    Parameters
    ----------
    table : pandas.DataFrame
        The report table (:func:`pidcore.report.build_report_table`). Rows with a measured
        value are drawn; if there is none, every row is.
    ax : matplotlib Axes, optional

    Returns
    -------
    matplotlib.figure.Figure
        Error bars are one standard error; interpolated DEM values are drawn as open markers
        without error bars (the model carries none).
    """
    rows = table[np.isfinite(table["SDC measured [-]"].astype(float))]
    if rows.empty:
        rows = table
    n = len(rows)
    if ax is None:
        fig = _new_figure(max(6.4, 0.55 * n + 2.0), 4.2)
        ax = fig.subplots()
    else:
        fig = ax.figure
    x = np.arange(n, dtype=float)
    width = 0.18
    labels = [f"{r['frequency [Hz]']:.4g} Hz\n{r['acceleration [g]']:.3g} g\n"
              f"{r['packing ratio [%]']:.3g} %" for _, r in rows.iterrows()]
    ax.errorbar(x - 1.5 * width, rows["SDC measured [-]"], yerr=rows["SDC measured stderr [-]"],
                fmt="o", color="C0", capsize=3, label="measured (ours) ± SE")
    on_grid = (rows[ALIGNMENT_COLUMN] == "grid").to_numpy()
    ax.errorbar(x[on_grid] - 0.5 * width, rows["SDC DEM (ours) [-]"][on_grid],
                yerr=rows["SDC DEM stderr [-]"][on_grid], fmt="s", color="C1", capsize=3,
                label="DEM (ours) ± SE")
    if (~on_grid).any():
        ax.plot(x[~on_grid] - 0.5 * width, rows["SDC DEM (ours) [-]"][~on_grid], "s",
                markerfacecolor="none", color="C1", label="DEM (ours), pchip-interpolated")
    ax.plot(x + 0.5 * width, rows["SDC DEM (paper) [-]"], "D", color="C2", label="DEM (paper)")
    ax.plot(x + 1.5 * width, rows["SDC measured (paper) [-]"], "^", color="C3",
            label="measured (paper)")
    ax.set_xticks(x, labels, fontsize="small")
    ax.set_ylabel("SDC [-]")
    ax.set_title("SDC per load case")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize="small")
    return fig


def loop_arrays(loop: object) -> tuple[np.ndarray, np.ndarray]:
    """(displacement m, force N) from a ``(displacement, force)`` tuple (as
    :meth:`PowerAnalysis.force_displacement_loop` returns) or a
    :class:`pidcore.signal.loops.LoopCurve`.
    """
    if isinstance(loop, tuple) and len(loop) == 2:
        return np.asarray(loop[0], dtype=float), np.asarray(loop[1], dtype=float)
    if hasattr(loop, "displacement_m") and hasattr(loop, "force_n"):
        return (np.asarray(loop.displacement_m, dtype=float), np.asarray(loop.force_n, dtype=float))
    raise TypeError(f"cannot read a force-displacement loop from {type(loop).__name__}")


def _closed(x: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Append the first point so a one-period loop is drawn closed."""
    return np.append(x, x[:1]), np.append(f, f[:1])


def plot_loop_overlay(measured: object, dem: tuple[np.ndarray, np.ndarray] | None, *,
                      title: str = "", ax=None):
    """Force-displacement loop of a measurement, with the DEM's at the same load case.

    Parameters
    ----------
    measured : loop or (displacement m, force N)
        The measured loop (see :func:`loop_arrays`).
    dem : (displacement m, force N) or None
        The DEM loop (:func:`pidcore.signal.loops.dem_loop_from_arrays`), or None to draw
        the measurement alone.
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

