"""Characters the figures' fonts lack: said once by the command, not warned of per drawing."""

from __future__ import annotations

import io
import warnings

import pytest
from matplotlib.figure import Figure

from pidcore import plot_text
from pidcore.report.fonts import figure_fonts, missing_glyphs_note


def _draw(text: str) -> None:
    fig = Figure(figsize=(3, 2))
    fig.suptitle(text)
    fig.savefig(io.BytesIO(), format="png")


def test_a_character_no_font_has_is_collected_and_other_warnings_still_shown():
    """`pidcore report` of a specimen named сталь_6мм_鋼 printed matplotlib's "Glyph 37628
    missing from font(s) DejaVu Sans" with its source line on the terminal, per drawing."""
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        with figure_fonts() as missing:
            _draw("сталь_6мм_鋼")
            warnings.warn("another warning", UserWarning, stacklevel=1)
    # Cyrillic is in DejaVu Sans (no CJK font on the test machine: fc-list :lang=zh is
    # empty where these tests run; where one is installed 鋼 is drawn and nothing is missing)
    assert missing == ({"鋼"} if not plot_text.installed_fallback_families() else set())
    assert [str(w.message) for w in shown] == ["another warning"]
    # after it, matplotlib's warnings are as they were
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        _draw("鋼")
    assert plot_text.installed_fallback_families() or any(
        "Glyph 37628" in str(w.message) for w in shown)
    assert missing_glyphs_note(set()) == ""
    assert missing_glyphs_note({"鋼", "試"}, "the figures").startswith(
        "2 character(s) could not be drawn in the figures (試鋼): no font")


def test_an_installed_fallback_family_draws_what_the_default_font_lacks(monkeypatch):
    """A glyph DejaVu Sans lacks is taken from the next family installed (here STIXGeneral,
    which matplotlib ships, standing for a CJK font: ᶁ U+1D81 is in it, not in DejaVu
    Sans), so it is not missing."""
    monkeypatch.setattr(plot_text, "FALLBACK_FAMILIES", ("No Such Family", "STIXGeneral"))
    assert plot_text.installed_fallback_families() == ["STIXGeneral"]
    with figure_fonts() as missing:
        _draw("ᶁ")
    assert missing == set()
    monkeypatch.setattr(plot_text, "FALLBACK_FAMILIES", ())
    with figure_fonts() as missing:
        _draw("ᶁ")
    assert missing == {"ᶁ"}


def _glyph_warnings_of_a_library_plot(title: str) -> list[str]:
    """The missing-glyph warnings of a figure made and drawn by the library API alone
    (``Measurement.plot()``, its title the measurement's source), outside any command."""
    import matplotlib.pyplot as plt
    import numpy as np

    from pidcore.records import Channel, Measurement

    m = Measurement(source=title, channels=(Channel("F", "force", np.zeros(8), 100.0, "N"),))
    ax = m.plot()
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        ax.figure.savefig(io.BytesIO(), format="png")
    plt.close(ax.figure)
    return [str(w.message) for w in shown if "missing from font" in str(w.message)]


def test_a_library_figure_draws_what_the_default_font_lacks_in_an_installed_fallback(
        monkeypatch):
    """`Measurement.plot()` (and every other figure the library or the app draws) had no
    fallback font, only the commands' figures did: a title the default font lacks was boxes
    with a warning per drawing. STIXGeneral, which matplotlib ships, stands for a CJK font
    (ᶁ U+1D81 is in it, not in DejaVu Sans); without it the warning is there, so this test
    can tell the two apart."""
    monkeypatch.setattr(plot_text, "FALLBACK_FAMILIES", ("STIXGeneral",))
    assert _glyph_warnings_of_a_library_plot("specimen ᶁ") == []
    monkeypatch.setattr(plot_text, "FALLBACK_FAMILIES", ())
    assert _glyph_warnings_of_a_library_plot("specimen ᶁ") != []


def test_a_library_figure_titled_in_cjk_draws_it_where_a_cjk_font_is_installed():
    if not plot_text.installed_fallback_families():
        pytest.skip("no CJK font of FALLBACK_FAMILIES is installed here (matplotlib's "
                    "font_manager lists none): nothing to draw 鋼 with")
    assert _glyph_warnings_of_a_library_plot("сталь_6мм_鋼") == []
