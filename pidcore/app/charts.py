"""Vega-Lite charts of the app, as JSON specs: layout only; they draw the frames of the library
(:func:`pidcore.compare.case.sdc_points`, :func:`pidcore.report.case_view.loop_frame`,
:meth:`pidcore.compare.case.MeasuredEntry.spectrum`), the same data the report's matplotlib
figures draw.

Drawn in the browser, so switching load cases costs the server only the (small) chart data.
Vega-Lite reads ``[`` and ``.`` in field names as nested access, so the unit-suffixed columns
are renamed to plain identifiers here and the units go into axis titles.

Written as the Vega-Lite dictionaries ``st.vega_lite_chart`` takes, not through Altair:
Altair's object model (built, deep-copied and serialised to this same dictionary) took ~0.1 s
per load case, most of a Compare view's server time. The tests validate every spec against
the Vega-Lite schema that Altair ships.
"""

from __future__ import annotations

import math
from typing import Any

import pandas as pd

from pidcore.compare.align import PACKING_RATIO_COLUMN
from pidcore.compare.case import SDC_SERIES
from pidcore.units import display_value_with_error

#: The Vega-Lite major version the specs are written for (Streamlit >= 1.56 draws v6).
VEGA_LITE_SCHEMA = "https://vega.github.io/schema/vega-lite/v6.json"

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
_AUTOSIZE = {"type": "fit-x", "contains": "padding"}
#: Size of a continuous view without an explicit width or height (Altair's default theme).
_CONFIG = {"view": {"continuousHeight": 300, "continuousWidth": 300}}


def _records(frame: pd.DataFrame) -> list[dict[str, Any]]:
    """Rows as JSON-ready dicts: Python numbers, NaN as null (JSON has no NaN)."""
    return [{k: None if isinstance(v, float) and math.isnan(v) else v for k, v in row.items()}
            for row in frame.to_dict(orient="records")]


def _field(name: str, kind: str, **more: Any) -> dict[str, Any]:
    return {"field": name, "type": kind, **more}


def _top(name: str, frame: pd.DataFrame, **spec: Any) -> dict[str, Any]:
    """A top-level spec whose data is ``frame``, sent as the named dataset ``name``."""
    return {"$schema": VEGA_LITE_SCHEMA, "config": _CONFIG, "data": {"name": name},
            "datasets": {name: _records(frame)}, **spec}


def sdc_chart(data: pd.DataFrame) -> dict[str, Any]:
    """SDC against fill: model curve, paper points, our DEM and measured with error bars.

    The legend lists exactly the series present (the model curve included), one per line so
    that no label is cut.
    """
    present = [s for s in SDC_SERIES if s in set(data["series"])]
    plain = data.rename(columns={PACKING_RATIO_COLUMN: "fill", "SDC [-]": "sdc", "low [-]": "low",
                                 "high [-]": "high"})
    # the tooltip's SDC as every page writes it with its error (value_and_error_texts):
    # four fixed decimals showed the paper's 1.5702e-4 as 0.0002 and an undamped mass's
    # 5.1e-5 ± 4.4e-5 as 0.0001 between 0.0000 and 0.0001; a point without an error has
    # low == high == sdc (sdc_points), shown alone
    plain = plain.assign(sdc_text=[
        display_value_with_error(float(s), float(h) - float(s) if h > s else math.nan)
        for s, h in zip(plain["sdc"], plain["high"], strict=True)])
    # ticks at the fills that carry points (Vega's own ticks left 25 % unlabelled) and at the
    # model curve's ends: beside one point (a case off the paper's grid) the curve had no
    # scale under it, one tick labelled "40" under a curve from 25 to 90 %
    model_fills = plain.loc[plain["series"] == _MODEL, "fill"].astype(float)
    ends = {model_fills.min(), model_fills.max()} if not model_fills.empty else set()
    fills = sorted({float(f) for f in plain.loc[plain["series"] != _MODEL, "fill"]} | ends) \
        if (plain["series"] != _MODEL).any() else []
    x = _field("fill", "quantitative", title=PACKING_RATIO_COLUMN,
               # ".6~g": 40 and 37.5, not Vega's 40.000000 for a list of floats; the precision
               # stated, or Vega takes it from the tick step and writes 25 as "3e+1"
               **({"axis": {"values": fills, "format": ".6~g"}} if fills else {}))
    colour = _field("series", "nominal", legend=_LEGEND,
                    scale={"domain": present, "range": [_SDC_COLOURS[s] for s in present]})
    model = {"field": "series", "equal": _MODEL}
    curve = {"mark": {"type": "line"}, "transform": [{"filter": model}],
             "encoding": {"x": x, "color": colour,
                          "y": _field("sdc", "quantitative", title="SDC [-]")}}
    others = [{"filter": {"not": model}}]
    bars = {"mark": {"type": "errorbar", "ticks": True}, "transform": others,
            "encoding": {"x": x, "color": colour,
                         "y": _field("low", "quantitative", title="SDC [-]"),
                         "y2": {"field": "high"}}}
    # colour and shape share domain and legend, so the legend lists every series present,
    # the model curve (drawn as a line symbol) included
    shape = _field("series", "nominal", legend=_LEGEND,
                   scale={"domain": present, "range": [_SDC_SHAPES[s] for s in present]})
    points = {"mark": {"type": "point", "size": 90, "filled": True}, "transform": others,
              "encoding": {"x": x, "color": colour, "y": _field("sdc", "quantitative"),
                           "shape": shape, "tooltip": [
                               _field("series", "nominal"),
                               _field("fill", "quantitative", title=PACKING_RATIO_COLUMN),
                               _field("sdc_text", "nominal", title="SDC ± stderr [-]")]}}
    return _top("sdc", plain, layer=[curve, bars, points], height=300,
                title="SDC against fill", autosize=_AUTOSIZE)


def loop_chart(frame: pd.DataFrame) -> dict[str, Any]:
    """Force-displacement loops overlaid, displacement in µm (a coupon moves micrometres).

    ``frame`` is :func:`pidcore.report.case_view.loop_frame` (SI). Legend labels are the loops'
    names only (the page prints their energies per cycle below), so none is cut.
    """
    series = list(dict.fromkeys(frame["series"]))
    colours, k = [], 0
    for s in series:
        if s.startswith("our DEM"):
            colours.append(_DEM_COLOUR)
        else:
            colours.append(_LOOP_COLOURS[k % len(_LOOP_COLOURS)])
            k += 1
    plain = pd.DataFrame({"series": frame["series"],
                          "displacement_um": frame["displacement [m]"].astype(float) * 1e6,
                          "force_n": frame["force [N]"].astype(float),
                          "order": frame["order"]})
    axis = {"format": ".4~r"}
    return _top("loop", plain, mark={"type": "line"}, encoding={
        "x": _field("displacement_um", "quantitative", title="displacement [µm]", axis=axis),
        "y": _field("force_n", "quantitative", title="force [N]", axis=axis),
        "order": _field("order", "quantitative"),
        "color": _field("series", "nominal", legend=_LEGEND,
                        scale={"domain": series, "range": colours})},
        height=300, title="force-displacement loop (area = energy per cycle)",
        autosize=_AUTOSIZE)


def spectrum_chart(table: pd.DataFrame) -> dict[str, Any]:
    """Force and velocity harmonic amplitudes (log scale), side by side."""
    plain = pd.DataFrame({
        "harmonic": table["harmonic [-]"], "frequency": table["frequency [Hz]"],
        "force": table["force amplitude [N]"],
        "velocity": table["velocity amplitude [m/s]"] * 1e3,
    })
    datasets = {}

    def stems(column: str, title: str, color: str) -> dict[str, Any]:
        # Bars cannot start at 0 on a log axis: stems from a floor a decade below the smallest
        # amplitude, with a dot on top.
        positive = plain[column][plain[column] > 0]
        floor = float(positive.min()) / 10 if len(positive) else 1e-12
        datasets[column] = _records(plain.assign(floor=floor))
        x = _field("harmonic", "ordinal", title="harmonic [-]")
        y = _field(column, "quantitative", title=title, scale={"type": "log"})
        rule = {"mark": {"type": "rule", "color": color, "strokeWidth": 3},
                "encoding": {"x": x, "y": y, "y2": {"field": "floor"}}}
        dots = {"mark": {"type": "point", "color": color, "filled": True, "size": 70},
                "encoding": {"x": x, "y": y, "tooltip": [
                    _field("harmonic", "ordinal"),
                    _field("frequency", "quantitative", title="[Hz]"),
                    _field(column, "quantitative", title=title, format=".4g")]}}
        # 2 x 170 px plots with their axes fit a 1024 px wide window beside the sidebar
        return {"data": {"name": column}, "layer": [rule, dots], "width": 170, "height": 200}

    charts = [stems("force", "force amplitude [N]", "#e67e22"),
              stems("velocity", "velocity amplitude [mm/s]", "#8e44ad")]
    return {"$schema": VEGA_LITE_SCHEMA, "config": _CONFIG, "datasets": datasets,
            "hconcat": charts, "title": "harmonic spectrum of force and velocity"}
