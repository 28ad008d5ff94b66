"""Vega-Lite (Altair) charts of the app: layout only; they draw the frames of the library
(:func:`pidcore.compare.case.sdc_points`, :func:`pidcore.app.workbench.loop_frame`,
:meth:`pidcore.compare.case.MeasuredEntry.spectrum`), the same data the report's matplotlib
figures draw.

Drawn in the browser, so switching load cases costs the server only the (small) chart data.
Vega-Lite reads ``[`` and ``.`` in field names as nested access, so the unit-suffixed columns
are renamed to plain identifiers here and the units go into axis titles.
"""

from __future__ import annotations

import altair as alt
import pandas as pd

from pidcore.compare.case import SDC_SERIES

_MODEL = SDC_SERIES[0]
#: One fixed, clearly distinct colour per series of SDC_SERIES (no two blues).
_SDC_COLOURS = dict(zip(SDC_SERIES, ("#7f7f7f", "#1f77b4", "#2ca02c", "#ff7f0e", "#c49c94",
                                     "#d62728", "#9467bd"), strict=True))
#: Colours of measured loops, in turn; our DEM's loop is always orange as in the SDC chart.
_LOOP_COLOURS = ("#d62728", "#9467bd", "#17becf", "#e377c2", "#8c564b", "#bcbd22")
_DEM_COLOUR = "#ff7f0e"
#: Marker of each series; the model curve's legend symbol is a line ("stroke").
_SDC_SHAPES = dict(zip(SDC_SERIES, ("stroke", "square", "triangle-up", "diamond", "diamond",
                                    "circle", "circle"), strict=True))
_LEGEND = {"orient": "bottom", "columns": 1, "labelLimit": 0, "title": None}
#: Fit the width to the column, keep the plot's height: the legend below adds to it (with
#: "fit" on both axes a long legend squeezes the plot away).
_AUTOSIZE = alt.AutoSizeParams(type="fit-x", contains="padding")


def sdc_chart(data: pd.DataFrame) -> alt.LayerChart:
    """SDC against fill: model curve, paper points, our DEM and measured with error bars.

    The legend lists exactly the series present (the model curve included), one per line so
    that no label is cut.
    """
    present = [s for s in SDC_SERIES if s in set(data["series"])]
    plain = data.rename(columns={"fill [%]": "fill", "SDC [-]": "sdc", "low [-]": "low",
                                 "high [-]": "high"})
    colour = alt.Color("series:N", scale=alt.Scale(domain=present,
                                                   range=[_SDC_COLOURS[s] for s in present]),
                       legend=alt.Legend(**_LEGEND))
    base = alt.Chart(plain).encode(x=alt.X("fill:Q", title="packing ratio (fill) [%]"),
                                   color=colour)
    curve = base.transform_filter(alt.datum.series == _MODEL).mark_line().encode(
        y=alt.Y("sdc:Q", title="SDC [-]"))
    others = base.transform_filter(alt.datum.series != _MODEL)
    bars = others.mark_errorbar(ticks=True).encode(y=alt.Y("low:Q", title="SDC [-]"),
                                                   y2="high:Q")
    # colour and shape share domain and legend, so the legend lists every series present,
    # the model curve (drawn as a line symbol) included
    shape = alt.Shape("series:N", scale=alt.Scale(domain=present,
                                                  range=[_SDC_SHAPES[s] for s in present]),
                      legend=alt.Legend(**_LEGEND))
    points = others.mark_point(size=90, filled=True).encode(
        y="sdc:Q", shape=shape,
        tooltip=[alt.Tooltip("series:N"), alt.Tooltip("fill:Q", title="fill [%]"),
                 alt.Tooltip("sdc:Q", title="SDC [-]", format=".4f"),
                 alt.Tooltip("low:Q", title="- stderr", format=".4f"),
                 alt.Tooltip("high:Q", title="+ stderr", format=".4f")])
    return alt.layer(curve, bars, points).properties(height=300, title="SDC against fill",
                                                     autosize=_AUTOSIZE)


def loop_chart(frame: pd.DataFrame) -> alt.Chart:
    """Force-displacement loops overlaid, displacement in µm (a coupon moves micrometres).

    ``frame`` is :func:`pidcore.app.workbench.loop_frame` (SI). Legend labels are the loops'
    names only (the page prints their energies per cycle below), so none is cut.
    """
    series = list(dict.fromkeys(frame["series"]))
    labels = {s: s for s in series}
    colours, k = [], 0
    for s in series:
        if s.startswith("our DEM"):
            colours.append(_DEM_COLOUR)
        else:
            colours.append(_LOOP_COLOURS[k % len(_LOOP_COLOURS)])
            k += 1
    plain = pd.DataFrame({"series": frame["series"].map(labels),
                          "displacement_um": frame["displacement [m]"].astype(float) * 1e6,
                          "force_n": frame["force [N]"].astype(float),
                          "order": frame["order"]})
    return alt.Chart(plain).mark_line().encode(
        x=alt.X("displacement_um:Q", title="displacement [µm]", axis=alt.Axis(format=".4~r")),
        y=alt.Y("force_n:Q", title="force [N]", axis=alt.Axis(format=".4~r")),
        order="order:Q",
        color=alt.Color("series:N", scale=alt.Scale(domain=[labels[s] for s in series],
                                                    range=colours),
                        legend=alt.Legend(**_LEGEND)),
    ).properties(height=300, title="force-displacement loop (area = energy per cycle)",
                 autosize=_AUTOSIZE)


def spectrum_chart(table: pd.DataFrame) -> alt.HConcatChart:
    """Force and velocity harmonic amplitudes (log scale), side by side."""
    plain = pd.DataFrame({
        "harmonic": table["harmonic [-]"], "frequency": table["frequency [Hz]"],
        "force": table["force amplitude [N]"],
        "velocity": table["velocity amplitude [m/s]"] * 1e3,
    })

    def stems(column: str, title: str, color: str) -> alt.LayerChart:
        # Bars cannot start at 0 on a log axis: stems from a floor a decade below the smallest
        # amplitude, with a dot on top.
        positive = plain[column][plain[column] > 0]
        floor = float(positive.min()) / 10 if len(positive) else 1e-12
        base = alt.Chart(plain.assign(floor=floor)).encode(
            x=alt.X("harmonic:O", title="harmonic [-]"))
        y = alt.Y(f"{column}:Q", title=title, scale=alt.Scale(type="log"))
        rule = base.mark_rule(color=color, strokeWidth=3).encode(y=y, y2="floor:Q")
        dots = base.mark_point(color=color, filled=True, size=70).encode(
            y=y, tooltip=[alt.Tooltip("harmonic:O"), alt.Tooltip("frequency:Q", title="[Hz]"),
                          alt.Tooltip(f"{column}:Q", title=title, format=".4g")])
        return alt.layer(rule, dots).properties(width=220, height=220)

    return alt.hconcat(stems("force", "force amplitude [N]", "#e67e22"),
                       stems("velocity", "velocity amplitude [mm/s]", "#8e44ad")) \
        .properties(title="harmonic spectrum of force and velocity")
