"""Figures of the SDC model (paper Figs. 8-14); plotting only, the physics is in pidcore.model.

* :func:`plot_sdc_vs_acceleration` - SDC against acceleration amplitude, one panel per fill,
  one curve per frequency, data points marked (paper Figs. 8-11).
* :func:`plot_sdc_vs_frequency` - SDC against frequency, one panel per acceleration, one curve
  per fill, data points marked (paper Figs. 12-14).
* :func:`save_figure` - PNG and SVG.

Each curve is one ``Line2D``; the data points of a curve (grid points of the model or rows of a
given table at that curve's fill and frequency/acceleration) are one more ``Line2D`` with
markers only, drawn right after it, labelled ``"... data"``. Filled holes of the model grid are
drawn as open markers labelled ``"... filled"``.
"""

from __future__ import annotations

import io
import textwrap
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from ..atomic_files import write_atomically
from ..errors import ParameterError
from ..model.sdc_model import SdcModel
from ..plot_text import text_as_typed

#: Points per curve.
_CURVE_POINTS = 200


#: Characters per line of a figure's title: "small" text is ~80 characters across 6.4 in.
_SUPTITLE_CHARS = 80


def _figure_and_axes(n_panels: int, ax):
    if ax is not None:
        if n_panels != 1:
            raise ParameterError(f"ax given but {n_panels} panels requested; pass a single "
                                 f"value for the panel variable or ax=None")
        return ax.figure, [ax]
    # A bare Figure (no pyplot) needs no GUI backend and is not kept alive by pyplot's registry;
    # savefig renders it with Agg/SVG.
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.4, 4.0 * n_panels), layout="constrained")
    axes = fig.subplots(n_panels, 1, squeeze=False)[:, 0]
    return fig, list(axes)


def _points(model: SdcModel, table: pd.DataFrame | None, value: str | None) -> pd.DataFrame:
    """Data points (columns fill_percent, acceleration_g, frequency_hz, value, filled)."""
    if table is None:
        t = model.grid_table().rename(columns={model.value_name: "value"})
        return t
    value = value or model.value_name
    needed = ["fill_percent", "acceleration_g", "frequency_hz", value]
    missing = [c for c in needed if c not in table.columns]
    if missing:
        raise ParameterError(f"table: missing columns {missing}; expected {needed}")
    t = table.loc[:, needed].rename(columns={value: "value"})
    t = t[np.isfinite(t["value"].astype(float))].copy()
    t["filled"] = False
    return t


def _mark(ax, pts: pd.DataFrame, xcol: str, color, label: str) -> None:
    pts = pts.sort_values(xcol)
    data = pts[~pts["filled"].astype(bool)]
    filled = pts[pts["filled"].astype(bool)]
    if len(data):
        ax.plot(data[xcol].to_numpy(float), data["value"].to_numpy(float), linestyle="none",
                marker="o", color=color, label=f"{label} data")
    if len(filled):
        ax.plot(filled[xcol].to_numpy(float), filled["value"].to_numpy(float), linestyle="none",
                marker="o", markerfacecolor="none", color=color, label=f"{label} filled")


def _default(values: Sequence[float] | None, axis: np.ndarray) -> list[float]:
    return [float(v) for v in (axis if values is None else values)]


def _draw_family(model: SdcModel, *, panels: Sequence[float], panel_column: str,
                 curves: Sequence[float], curve_column: str, x_column: str, log_x: bool,
                 ax, table: pd.DataFrame | None, value: str | None,
                 curve_label: Callable[[float], str], title: Callable[[float], str],
                 xlabel: str):
    """One panel per value of ``panels``, in it one curve per value of ``curves`` along
    ``x_column`` over the model's bounds; the data points at the same panel and curve value
    are marked right after each curve (see :func:`_mark`). Returns the figure."""
    fig, axes = _figure_and_axes(len(panels), ax)
    pts = _points(model, table, value)
    lo, hi = model.bounds[x_column]
    x = np.geomspace(lo, hi, _CURVE_POINTS) if log_x else np.linspace(lo, hi, _CURVE_POINTS)
    for panel, panel_value in zip(axes, panels, strict=True):
        for curve_value in curves:
            point = {panel_column: panel_value, curve_column: curve_value, x_column: x}
            label = curve_label(curve_value)
            (line,) = panel.plot(x, model(point["fill_percent"], point["acceleration_g"],
                                          point["frequency_hz"]), label=label)
            sel = pts[np.isclose(pts[panel_column], panel_value)
                      & np.isclose(pts[curve_column], curve_value)]
            _mark(panel, sel, x_column, line.get_color(), label)
        if log_x:
            panel.set_xscale("log")
        panel.set_title(title(panel_value))
        panel.set_xlabel(xlabel)
        panel.set_ylabel("SDC [-]")
        panel.legend(fontsize="small", ncols=2)
    if ax is None and model.source:  # a figure of its own says what it draws
        # wrapped: a store's source (runs of a specimen in a store, where ...) ran past both
        # edges of the 6.4 in figure and was cut off at each end
        fig.suptitle(textwrap.fill(model.source, _SUPTITLE_CHARS, break_on_hyphens=False,
                                   break_long_words=False), fontsize="small")
    return fig


@text_as_typed
def plot_sdc_vs_acceleration(model: SdcModel, *, fills: Sequence[float] | None = None,
                             frequencies: Sequence[float] | None = None, ax=None,
                             table: pd.DataFrame | None = None, value: str | None = None):
    """SDC against acceleration amplitude: a panel per fill, a curve per frequency (Figs. 8-11).

    Parameters
    ----------
    model : SdcModel
        The interpolant drawn as curves.
    fills : sequence of float, optional
        Fill [%] of each panel (default: the model's fill grid).
    frequencies : sequence of float, optional
        Frequency [Hz] of each curve (default: the model's frequency grid).
    ax : matplotlib Axes, optional
        Draw into this Axes (only with a single fill).
    table : pandas.DataFrame, optional
        Points to mark (e.g. the store's DEM runs); default: the model's grid points.
    value : str, optional
        Value column of ``table`` (default: the model's ``value_name``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    return _draw_family(model, panels=_default(fills, model.axes[0]), panel_column="fill_percent",
                        curves=_default(frequencies, model.axes[2]),
                        curve_column="frequency_hz", x_column="acceleration_g", log_x=False,
                        ax=ax, table=table, value=value, curve_label=lambda f: f"{f:g} Hz",
                        title=lambda fill: f"SDC at {fill:g} % fill",
                        xlabel="acceleration amplitude [g]")


@text_as_typed
def plot_sdc_vs_frequency(model: SdcModel, *, accelerations: Sequence[float] | None = None,
                          fills: Sequence[float] | None = None, ax=None,
                          table: pd.DataFrame | None = None, value: str | None = None,
                          log_x: bool = True):
    """SDC against frequency: a panel per acceleration, a curve per fill (Figs. 12-14).

    Parameters
    ----------
    model : SdcModel
        The interpolant drawn as curves.
    accelerations : sequence of float, optional
        Acceleration amplitude [g] of each panel (default: the model's acceleration grid).
    fills : sequence of float, optional
        Fill [%] of each curve (default: the model's fill grid).
    ax : matplotlib Axes, optional
        Draw into this Axes (only with a single acceleration).
    table, value : optional
        Points to mark, as in :func:`plot_sdc_vs_acceleration`.
    log_x : bool
        Logarithmic frequency axis.

    Returns
    -------
    matplotlib.figure.Figure
    """
    return _draw_family(model, panels=_default(accelerations, model.axes[1]),
                        panel_column="acceleration_g", curves=_default(fills, model.axes[0]),
                        curve_column="fill_percent", x_column="frequency_hz", log_x=log_x,
                        ax=ax, table=table, value=value,
                        curve_label=lambda fill: f"{fill:g} %",
                        title=lambda acc: f"SDC at {acc:g} g", xlabel="frequency [Hz]")


def save_figure(fig, out_dir: str | Path, stem: str) -> list[Path]:
    """Write ``fig`` as ``<out_dir>/<stem>.png`` and ``.svg``; return both paths."""
    if not stem or any(c in stem for c in "/\\") or stem.startswith("."):
        raise ParameterError(f"save_figure: stem {stem!r} must be a plain file name")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / f"{stem}.png", out / f"{stem}.svg"]
    # both drawn before either is written, each then replaced whole: a Ctrl-C while drawing
    # (seconds for a large family) left a truncated PNG under the figure's name
    images = []
    for path, options in zip(paths, ({"dpi": 150}, {}), strict=True):
        buffer = io.BytesIO()
        fig.savefig(buffer, format=path.suffix[1:], **options)
        images.append(buffer.getvalue())
    for path, image in zip(paths, images, strict=True):
        write_atomically(path, image)
    return paths
