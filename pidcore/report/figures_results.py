"""Matplotlib figures of single results; drawing only, the data come from the results.

* :func:`plot_measurement` - the channels of a measurement against time
  (:meth:`pidcore.records.Measurement.to_pandas`).
* :func:`plot_spectrum` - harmonic amplitudes of a measurement
  (:meth:`pidcore.signal.PowerAnalysis.to_pandas`).
* :func:`plot_loop` - a force-displacement loop (:class:`pidcore.loop.ForceDisplacementLoop`).
* :func:`plot_dem_run` - per-cycle dissipation and forces of a DEM run
  (:class:`pidcore.dem.DemResult`).
* :func:`plot_harmonic_response` - a treated mode's amplitude against frequency
  (:meth:`pidcore.model.HarmonicResponse.to_pandas`).
* :func:`plot_calibration` - a calibration's predictions with their 95 % bands beside the
  SDCs it was fitted to (:meth:`pidcore.calibrate.Calibration.to_pandas`);
  :func:`calibration_png` draws it as a PNG for a page.

``Measurement.plot``, ``PowerAnalysis.plot``, ``ForceDisplacementLoop.plot``,
``DemResult.plot``, ``HarmonicResponse.plot`` and ``Calibration.plot`` forward here
(python-control style), so the physics modules import no matplotlib. With ``ax=None`` a new
pyplot figure is made, as an interactive ``.plot()`` is expected to do.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from .. import defaults
from ..errors import ParameterError
from ..plot_text import text_as_typed
from ..units import display_value_with_error

if TYPE_CHECKING:  # pragma: no cover
    from ..dem.result import DemResult
    from ..loop import ForceDisplacementLoop


@text_as_typed
def plot_spectrum(frame: pd.DataFrame, *, ax: Any = None) -> Any:
    """Harmonic spectrum: |F_n| (N, left axis) and |V_n| (m/s, right axis). Returns ``ax``.

    ``frame`` is :meth:`pidcore.signal.PowerAnalysis.to_pandas` (its ``attrs`` give the
    title).
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots()
    n = frame["harmonic [-]"].to_numpy(dtype=float)
    ax.bar(n - 0.2, frame["force amplitude [N]"].to_numpy(float), width=0.4, color="C0",
           label="|F_n| [N]")
    ax.set_xlabel("harmonic order n [-]")
    ax.set_ylabel("force amplitude [N]")
    ax.set_yscale("log")
    ax2 = ax.twinx()
    ax2.bar(n + 0.2, frame["velocity amplitude [m/s]"].to_numpy(float), width=0.4, color="C1",
            label="|V_n| [m/s]")
    ax2.set_ylabel("velocity amplitude [m/s]")
    ax2.set_yscale("log")
    ax.set_xticks(n)
    attrs = frame.attrs
    if "frequency_hz" in attrs:
        ax.set_title(f"{attrs.get('source', '')} {attrs['frequency_hz']:.4g} Hz, "
                     f"sdc = {attrs.get('sdc', float('nan')):.4g}".strip())
    return ax


@text_as_typed
def plot_loop(loop: ForceDisplacementLoop, *, ax: Any = None, **line_kw: Any) -> Any:
    """One closed force-displacement loop, displacement in µm. Returns ``ax``.

    The legend text is the loop's label with its energy per cycle (the enclosed area).
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots()
    x, f = loop.closed()
    label = f"{loop.label} (ΔE = {loop.energy_per_cycle_j:.3e} J/cycle)".strip()
    ax.plot(x * 1e6, f, label=label, **line_kw)
    ax.set_xlabel("displacement [µm]")
    ax.set_ylabel("force [N]")
    return ax


@text_as_typed
def plot_dem_run(result: DemResult, *, ax: Any = None) -> Any:
    """Per-cycle dissipation (top) and wall/shaker force over the last cycles (bottom).

    ``ax``: a pair of matplotlib axes, or None for a new figure. Returns the axes.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(2, 1, figsize=(7, 6), constrained_layout=True)
    if len(np.atleast_1d(ax)) != 2:  # one axes was "cannot unpack non-iterable Axes"
        raise ParameterError("ax: a DEM run draws two panels (dissipation per cycle, forces); "
                             "expected a pair of axes, e.g. fig.subplots(2, 1)")
    a0, a1 = ax
    cycles = np.arange(len(result.dissipation_per_cycle_j))
    a0.plot(cycles, result.dissipation_per_cycle_j, ".-", label="coupon")
    a0.axvline(result.steady_start_cycle, color="k", ls="--", label="steady from")
    a0.set_xlabel("cycle [-]")
    a0.set_ylabel("dissipated per cycle [J]")
    a0.legend()
    n = defaults.FIGURE_DEM_FORCE_CYCLES * result.samples_per_cycle
    a1.plot(result.sample_time_s[-n:], result.wall_force_n[-n:], label="walls on particles")
    a1.plot(result.sample_time_s[-n:], result.shaker_force_n[-n:], label="shaker force")
    a1.set_xlabel("time [s]")
    a1.set_ylabel("force [N]")
    a1.legend()
    # the SDC with its error as dem run's summary, analyze and the app write it (it wrote
    # "+- nan" for a run whose cells all ran one motion and so keep no standard error)
    a0.set_title(f"{result.case.key}: SDC {display_value_with_error(result.sdc, result.sdc_stderr)}"
                 f", {result.particles_per_cell} particles/cell")
    return ax


@text_as_typed
def plot_calibration(frame: pd.DataFrame, *, ax: Any = None) -> Any:
    """Calibrated predictions (points, 95 % band as error bars, cut at each case's SDC bound)
    and the measured SDCs they were fitted to (crosses), one position per load case. A band
    that spans every plausible SDC (verdict ``uninformative``) is drawn hollow and dashed
    under a legend entry of its own, as predictions.png draws it
    (:func:`pidcore.calibrate.outputs.draw_bands`). Returns ``ax``.

    ``frame`` is :meth:`pidcore.calibrate.Calibration.to_pandas` (a frame without its
    ``SDC bound [-]`` and verdict columns is cut at 2 pi and judged by nothing).
    """
    import matplotlib.pyplot as plt

    from ..calibrate.outputs import draw_bands, draw_cut_bounds
    from ..calibrate.prediction import (
        CALIBRATION_COLUMNS_RENAMED,
        SDC_BOUND_COLUMN,
        VERDICT_COLUMN,
    )
    from ..compare.align import (
        CALIBRATED_COLUMN,
        CALIBRATED_HIGH_COLUMN,
        CALIBRATED_LOW_COLUMN,
        MEASURED_EQ11_COLUMN,
        PACKING_RATIO_COLUMN,
    )
    from ..compare.plausibility import SDC_UPPER_BOUND

    frame = frame.rename(columns=CALIBRATION_COLUMNS_RENAMED)  # a frame saved before 2026-12
    if ax is None:
        _, ax = plt.subplots(figsize=(max(6.0, 0.5 * len(frame)), 4.0), constrained_layout=True)
    x = np.arange(len(frame))
    bounds = frame.get(SDC_BOUND_COLUMN, pd.Series(SDC_UPPER_BOUND, index=frame.index))
    verdicts = frame.get(VERDICT_COLUMN, pd.Series("", index=frame.index))
    draw_cut_bounds(ax, draw_bands(ax, x, frame[CALIBRATED_COLUMN], frame[CALIBRATED_LOW_COLUMN],
                                   frame[CALIBRATED_HIGH_COLUMN], bounds, verdicts,
                                   label="calibrated DEM", color="C0"))
    ax.plot(x, frame[MEASURED_EQ11_COLUMN].to_numpy(float), "x", color="k", label="measured")
    ax.set_xticks(x)
    ax.set_xticklabels([f"{f:g} Hz, {a:g} g, {p:g} %" for f, a, p in zip(
        frame["frequency [Hz]"], frame["acceleration [g]"], frame[PACKING_RATIO_COLUMN],
        strict=True)],
        rotation=60, ha="right", fontsize="small")
    ax.set_ylabel("SDC [-]")
    ax.legend()
    return ax


@text_as_typed
def calibration_png(frame: pd.DataFrame, *, dpi: int = 150) -> bytes:
    """PNG of :func:`plot_calibration` of ``frame`` (:meth:`pidcore.calibrate.Calibration.
    to_pandas`) on a figure of its own, for a page that shows an image (the app's list of
    saved calibrations): a bare matplotlib Figure, so that a server drawing it for every
    session keeps no pyplot figure alive and needs no GUI backend."""
    import io

    from matplotlib.figure import Figure

    fig = Figure(figsize=(max(6.0, 0.5 * len(frame)), 5.5), layout="constrained")
    ax = plot_calibration(frame, ax=fig.subplots())
    # below the axes: inside them its long entries (the uninformative band's, the cut bound's)
    # were wider than a 6 in axes and covered the points, their markers cut off at its edge
    ax.get_legend().remove()
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center",
               fontsize="small")
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()


@text_as_typed
def plot_harmonic_response(frame: pd.DataFrame, *, ax: Any = None) -> Any:
    """Displacement amplitude against frequency, with and without the particle damper; points
    where the SDC was held at the model's edge marked. Returns ``ax``.

    ``frame`` is :meth:`pidcore.model.HarmonicResponse.to_pandas`.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots()
    f = frame["frequency [Hz]"].to_numpy(float)
    x = frame["amplitude [m]"].to_numpy(float)
    clipped = frame["clipped [True/False]"].to_numpy(bool)
    ax.plot(f, frame["amplitude untreated [m]"].to_numpy(float), "--", label="untreated")
    ax.plot(f, x, "-", label="with particle damper")
    if clipped.any():
        ax.plot(f[clipped], x[clipped], "x", label="SDC held at model edge")
    ax.set_yscale("log")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("displacement amplitude [m]")
    ax.legend()
    return ax


@text_as_typed
def plot_measurement(frame: pd.DataFrame, *, ax: Any = None) -> Any:
    """Each channel of a measurement against time, one axes per channel, stacked with a shared
    time axis. Returns the axes (one, or an array of them).

    ``frame`` is :meth:`pidcore.records.Measurement.to_pandas`; ``ax``: as many axes as it has
    channels, or None for a new figure.
    """
    import matplotlib.pyplot as plt

    names = [c for c in frame.columns if c != "time [s]"]
    if ax is None:
        _, ax = plt.subplots(len(names), 1, sharex=True, squeeze=False,
                             figsize=(7.0, 1.8 + 1.6 * len(names)), constrained_layout=True)
        ax = ax[:, 0] if len(names) > 1 else ax[0, 0]
    axes = np.atleast_1d(ax)
    if len(axes) != len(names):
        raise ParameterError(f"ax: {len(names)} channels need as many axes, got {len(axes)}")
    t = frame["time [s]"].to_numpy(float)
    for a, name in zip(axes, names, strict=True):
        a.plot(t, frame[name].to_numpy(float), lw=0.8)
        a.set_ylabel(name)
    axes[-1].set_xlabel("time [s]")
    if "source" in frame.attrs:
        axes[0].set_title(str(frame.attrs["source"]))
    return ax
