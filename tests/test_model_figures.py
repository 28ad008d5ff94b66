"""SDC figure families (paper Figs. 8-14): content of the drawn lines and saved files."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from pidcore.errors import ParameterError
from pidcore.report.figures import plot_sdc_vs_acceleration, plot_sdc_vs_frequency, save_figure

FREQS = [50.0, 100.0, 250.0, 500.0, 750.0, 1000.0]  # 4 with data, 2 interpolated
FILLS = [25.0, 40.0, 50.0, 60.0, 75.0, 90.0]


def _lines(ax) -> tuple[list, list]:
    curves = [ln for ln in ax.lines if ln.get_linestyle() != "None"]
    markers = [ln for ln in ax.lines if ln.get_linestyle() == "None"]
    return curves, markers


def test_sdc_vs_acceleration_content(paper_model, paper_table):
    fig = plot_sdc_vs_acceleration(paper_model, fills=[50.0, 90.0], frequencies=FREQS)
    assert len(fig.axes) == 2
    for ax, fill in zip(fig.axes, [50.0, 90.0], strict=True):
        curves, markers = _lines(ax)
        assert len(curves) == len(FREQS)
        for curve, freq in zip(curves, FREQS, strict=True):
            x, y = curve.get_xdata(), curve.get_ydata()
            np.testing.assert_allclose(y, paper_model(fill, x, freq), rtol=1e-14)
        data = {ln.get_label(): ln for ln in markers}
        for freq in [50.0, 100.0, 500.0, 1000.0]:
            t = paper_table
            rows = t[(t.fill_percent == fill) & (t.frequency_hz == freq)
                     & t.sdc_dem.notna()].sort_values("acceleration_g")
            line = data[f"{freq:g} Hz data"]
            np.testing.assert_array_equal(line.get_xdata(), rows.acceleration_g)
            np.testing.assert_array_equal(line.get_ydata(), rows.sdc_dem)
    # 90 %: the filled hole at 1000 Hz, 1 g is an extra open marker
    curves, markers = _lines(fig.axes[1])
    assert len(markers) == 5
    filled = [ln for ln in markers if ln.get_label() == "1000 Hz filled"]
    assert len(filled) == 1 and list(filled[0].get_xdata()) == [1.0]
    assert list(filled[0].get_ydata()) == [pytest.approx(0.8078, rel=1e-12)]
    assert len(_lines(fig.axes[0])[1]) == 4


def test_sdc_vs_frequency_content(paper_model, paper_table):
    fig = plot_sdc_vs_frequency(paper_model, accelerations=[5.0], fills=FILLS)
    (ax,) = fig.axes
    assert ax.get_xscale() == "log"
    curves, markers = _lines(ax)
    assert len(curves) == len(FILLS) and len(markers) == 4
    for curve, fill in zip(curves, FILLS, strict=True):
        np.testing.assert_allclose(curve.get_ydata(), paper_model(fill, 5.0, curve.get_xdata()),
                                   rtol=1e-14)
    for ln, fill in zip(markers, [25.0, 50.0, 75.0, 90.0], strict=True):
        rows = paper_table[(paper_table.fill_percent == fill) & (paper_table.acceleration_g == 5.0)]
        np.testing.assert_array_equal(ln.get_xdata(), rows.frequency_hz)
        np.testing.assert_array_equal(ln.get_ydata(), rows.sdc_dem)


def test_marks_points_of_a_given_table(paper_model):
    runs = pd.DataFrame({"fill_percent": [50.0, 50.0, 75.0], "acceleration_g": [2.0, 7.0, 2.0],
                         "frequency_hz": [100.0, 100.0, 100.0], "sdc": [0.1, 0.2, 0.3]})
    fig = plot_sdc_vs_acceleration(paper_model, fills=[50.0], frequencies=[100.0, 500.0],
                                   table=runs, value="sdc")
    curves, markers = _lines(fig.axes[0])
    assert len(curves) == 2 and len(markers) == 1
    np.testing.assert_array_equal(markers[0].get_xdata(), [2.0, 7.0])
    np.testing.assert_array_equal(markers[0].get_ydata(), [0.1, 0.2])


def test_into_given_axes_and_refusals(paper_model):
    from matplotlib.figure import Figure

    ax = Figure().subplots()
    fig = plot_sdc_vs_frequency(paper_model, accelerations=[10.0], fills=[50.0], ax=ax)
    assert fig is ax.figure and len(ax.lines) == 2
    with pytest.raises(ParameterError, match="single"):
        plot_sdc_vs_acceleration(paper_model, fills=[25.0, 50.0], ax=ax)
    with pytest.raises(ParameterError, match="outside the model range"):
        plot_sdc_vs_acceleration(paper_model, fills=[95.0])


def test_save_figure_writes_png_and_svg(paper_model, tmp_path):
    fig = plot_sdc_vs_acceleration(paper_model, fills=[25.0], frequencies=[50.0])
    paths = save_figure(fig, tmp_path / "figs", "fig8")
    assert [p.name for p in paths] == ["fig8.png", "fig8.svg"]
    assert paths[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert b"<svg" in paths[1].read_bytes()[:2000]
    with pytest.raises(ParameterError):
        save_figure(fig, tmp_path, "../escape")


def test_a_long_source_title_stays_inside_the_figure(paper_model):
    # `model figures --table store --where ...` titled the figure "DEM runs of X [hash] in
    # runs.h5 where {...}" on one line, cut off at both edges of the saved PNG
    import dataclasses

    source = ("DEM runs of my_panel_steel [30fbec] in /tmp/some/folder/runs.h5 where "
              "specimen_name=my_panel_steel, settings_hash=00039b")
    fig = plot_sdc_vs_frequency(dataclasses.replace(paper_model, source=source),
                                accelerations=[5.0], fills=[50.0])
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)  # as save_figure renders the PNG
    canvas.draw()
    box = fig._suptitle.get_window_extent(canvas.get_renderer())
    assert box.x0 >= fig.bbox.x0 and box.x1 <= fig.bbox.x1, (box, fig.bbox)
    assert fig._suptitle.get_text().replace("\n", " ") == source
