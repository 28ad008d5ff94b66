"""Vega-Lite (Altair) charts of the app: layout only, the data come from pidcore.app_support.

Drawn in the browser, so switching load cases costs the server only the (small) chart data.
Vega-Lite reads ``[`` and ``.`` in field names as nested access, so the unit-suffixed columns
of the data tables are renamed to plain identifiers here and the units go into axis titles.
"""

from __future__ import annotations

import altair as alt
import pandas as pd

from pidcore.app_support import SDC_SERIES

_MODEL = "pchip model (paper Table 3 DEM)"
#: One fixed colour per series of pidcore.app_support.SDC_SERIES, whatever series a case has.
_SDC_COLOURS = ("#7f7f7f", "#1f77b4", "#2ca02c", "#ff7f0e", "#ffbb78", "#d62728",
                "#9467bd")


def sdc_chart(data: pd.DataFrame) -> alt.LayerChart:
    """SDC against fill: model curve, paper points, our DEM and measured with error bars."""
    plain = data.rename(columns={"fill [%]": "fill", "SDC [-]": "sdc", "low [-]": "low",
                                 "high [-]": "high"})
    base = alt.Chart(plain).encode(
        x=alt.X("fill:Q", title="packing ratio (fill) [%]"),
        color=alt.Color("series:N", title=None,
                        scale=alt.Scale(domain=list(SDC_SERIES), range=list(_SDC_COLOURS)),
                        legend=alt.Legend(orient="bottom", columns=2, labelLimit=400)),
    )
    curve = base.transform_filter(alt.datum.series == _MODEL).mark_line().encode(
        y=alt.Y("sdc:Q", title="SDC [-]"))
    others = base.transform_filter(alt.datum.series != _MODEL)
    bars = others.mark_errorbar(ticks=True).encode(y=alt.Y("low:Q", title="SDC [-]"),
                                                   y2="high:Q")
    points = others.mark_point(size=90, filled=True).encode(
        y="sdc:Q", shape=alt.Shape("series:N", legend=None),
        tooltip=[alt.Tooltip("series:N"), alt.Tooltip("fill:Q", title="fill [%]"),
                 alt.Tooltip("sdc:Q", title="SDC [-]", format=".4f"),
                 alt.Tooltip("low:Q", title="- stderr", format=".4f"),
                 alt.Tooltip("high:Q", title="+ stderr", format=".4f")])
    return alt.layer(curve, bars, points).properties(height=360, title="SDC against fill")


def loop_chart(data: pd.DataFrame) -> alt.Chart:
    """Force-displacement loops overlaid (line drawn in point order, so loops close)."""
    plain = data.rename(columns={"displacement [mm]": "displacement_mm", "force [N]": "force_n"})
    return alt.Chart(plain).mark_line().encode(
        x=alt.X("displacement_mm:Q", title="displacement [mm]"),
        y=alt.Y("force_n:Q", title="force [N]"),
        order="order:Q",
        color=alt.Color("series:N", title=None,
                        legend=alt.Legend(orient="bottom", columns=1, labelLimit=600)),
    ).properties(height=360, title="force-displacement loop (area = energy per cycle)")


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
