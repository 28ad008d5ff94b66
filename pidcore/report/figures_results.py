"""Matplotlib figures of single results; drawing only, the data come from the results.

* :func:`plot_spectrum` - harmonic amplitudes of a measurement
  (:meth:`pidcore.signal.PowerAnalysis.spectrum_frame`).
* :func:`plot_loop` - a force-displacement loop (:class:`pidcore.loop.ForceDisplacementLoop`).
* :func:`plot_dem_run` - per-cycle dissipation and forces of a DEM run
  (:class:`pidcore.dem.DemResult`).

``PowerAnalysis.plot`` and ``DemResult.plot`` forward here (python-control style), so the
physics modules import no matplotlib. With ``ax=None`` a new pyplot figure is made, as an
interactive ``.plot()`` is expected to do.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from .. import defaults

if TYPE_CHECKING:  # pragma: no cover
    from ..dem.result import DemResult
    from ..loop import ForceDisplacementLoop


def plot_spectrum(frame: pd.DataFrame, *, ax: Any = None) -> Any:
    """Harmonic spectrum: |F_n| (N, left axis) and |V_n| (m/s, right axis). Returns ``ax``.

    ``frame`` is :meth:`pidcore.signal.PowerAnalysis.spectrum_frame` (its ``attrs`` give the
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


def plot_dem_run(result: DemResult, *, ax: Any = None) -> Any:
    """Per-cycle dissipation (top) and wall/shaker force over the last cycles (bottom).

    ``ax``: a pair of matplotlib axes, or None for a new figure. Returns the axes.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(2, 1, figsize=(7, 6), constrained_layout=True)
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
    a0.set_title(f"{result.case.key}: SDC {result.sdc:.4g} +- {result.sdc_stderr:.2g}, "
                 f"{result.particles_per_cell} particles/cell")
    return ax
