"""The library's parameter names in the app's words: one table, keyword -> the page's label.

The library names a parameter as a Python caller writes it (``structure_mass_kg``,
``force=NAME``; :mod:`pidcore.errors`), the CLI as its flag (:mod:`pidcore.cli._vocabulary`);
the app names the field or column the user sets it in ("'structure mass [g]'"), and what it
has no field for as the command that sets it. :func:`page_terms` does it; the pages show
every library refusal and note through it (:func:`pidcore.app.uploads.app_words`).
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from ..errors import KEYWORD_NOT_AFTER_WORD, KEYWORD_NOT_BEFORE, outside_user_names

#: Library keyword (as the message writes it) -> the app's label of it. A single word
#: (``force``) is a keyword only with its ``=``, and a ``=VALUE`` after a keyword stays as the
#: value (``force='Fz'`` is "the 'force channel' column ('Fz')").
LABEL_OF_KEYWORD: dict[str, str] = {
    "structure_mass_kg": "'structure mass [g]'",
    "baseline_loss_factor": "'baseline loss factor [-]'",
    "mass_below_gauge_kg": "'mass below gauge [g]'",
    "velocity_delay_s": "'vibrometer delay [µs]'",
    "sample_rate_hz": "'sample rate if no time column' under 'Options for every file'",
    "time_unit": "'time base unit' under 'Options for every file'",
    "force=": "the 'force channel' column",
    "velocity=": "the 'velocity channel' column",
    "acceleration=": "the 'acceleration channel' column",
    "invert=": "the 'inverted channels' column",
    "fill_percent": "'fill [%]'",
    "material=": "the 'material' column",
    "direction=": "the 'direction' column",
    "specimen=": "the 'specimen' choice",
    "calibration_key": "'calibration for the calibrated DEM columns'",
    "accept_implausible=True": "the 'Save ... anyway' confirmation",
    "accept_implausible": "the 'Save ... anyway' confirmation",
    # no field on the pages: the command that sets it
    "frequency_hz": "`pidcore analyze --frequency`",
    "n_harmonics": "`pidcore analyze --harmonics`",
    "allow_clipped=True": "`pidcore analyze --allow-clipped`",
    "allow_clipped": "`pidcore analyze --allow-clipped`",
    "force_unit": "`pidcore analyze --force-unit`",
    "velocity_unit": "`pidcore analyze --velocity-unit`",
    "acceleration_unit": "`pidcore analyze --acceleration-unit`",
    "key=": "`pidcore analyze --key`",
    "dem_store": "the DEM store",
    "pool=True": "'pool DEM settings'",
    "calibration_key=": "`pidcore report --calibration-key`",
    # the call that writes a calibration folder, named by the refusal of a half-moved one
    # (pidcore.specimen.finish_calibration_moves): the page writes no folder, the CLI does
    "write_outputs(result, out_dir)": "`pidcore calibrate --out`",
}

#: The SI unit a message gives after a keyword, the page's unit of its field where it is not
#: the keyword's SI unit, and the page's units per SI unit. A value given with the keyword
#: (``structure_mass_kg=0.0483``) is shown in it ("'structure mass [g]' (48.3)"), and so is a
#: number after it (``mass_below_gauge_kg 0.5 kg`` is "'mass below gauge [g]' 500 g"), not
#: in kg beside a label in g.
_PAGE_UNIT: dict[str, tuple[str, str, float]] = {"structure_mass_kg": ("kg", "g", 1e3),
                                                 "mass_below_gauge_kg": ("kg", "g", 1e3),
                                                 "velocity_delay_s": ("s", "µs", 1e6)}

# a value the user's name held (pidcore.errors.outside_user_names) is a placeholder
_VALUE = r"(?P<value>'[^']*'|\ue000\d+\ue001|[\w.+-]+)"
_PATTERNS = tuple(
    (re.compile(KEYWORD_NOT_BEFORE + re.escape(k.removesuffix("="))
                + (f"={_VALUE}?" if k.endswith("=") else
                   KEYWORD_NOT_AFTER_WORD if k[-1].isalnum() else "")
                + ("" if k.endswith("=") or not k[-1].isalnum() else f"(?:={_VALUE})?")),
     label, _PAGE_UNIT[k][2] if k in _PAGE_UNIT else 1.0)
    for k, label in sorted(LABEL_OF_KEYWORD.items(), key=lambda kv: -len(kv[0])))


_AMOUNT = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_NUMBER = f"(?P<number>{_AMOUNT})"
_WITH_UNIT = tuple(
    (re.compile(KEYWORD_NOT_BEFORE + re.escape(k) + r"(?P<colon>:?) " + _NUMBER + " "
                + re.escape(si) + r"(?![\w/])"),
     LABEL_OF_KEYWORD[k], scale, page_unit)
    for k, (si, page_unit, scale) in _PAGE_UNIT.items())
# a setting changed, as a note on a file saved before with other settings writes it
# (pidcore.compare.settings_columns.other_settings_note: "velocity_delay_s 5e-05 -> 0.0",
# JSON values, null for none given): in the field's unit ("'vibrometer delay [µs]' 50 -> 0
# µs"), not in SI beside a label in µs
_CHANGED = tuple(
    (re.compile(KEYWORD_NOT_BEFORE + re.escape(k) + f" (?P<old>{_AMOUNT}|null) -> "
                f"(?P<new>{_AMOUNT}|null)" + r"(?![\w.])"),
     LABEL_OF_KEYWORD[k], scale, page_unit)
    for k, (_, page_unit, scale) in _PAGE_UNIT.items())


def page_terms(message: str, *, names: Iterable[str] = ()) -> str:
    """``message`` (a library refusal or note) with its parameter keywords named as the app's
    fields and columns; a value given with one follows in parentheses (a placeholder such as
    ``NAME`` is left out). The user's names in it (files, channels, specimens, and ``names``:
    the upload's) stay as written."""
    return outside_user_names(message, _in_page_terms, names=names)


def _in_page_terms(message: str) -> str:
    def labelled(named: str, scale: float, m: re.Match) -> str:
        value = m.groupdict().get("value")  # a call's name takes none
        if value is None or (value.isupper() and not value.startswith("'")):
            return named
        try:
            value = f"{float(value) * scale:g}" if scale != 1.0 else value
        except ValueError:  # not a number: as given
            pass
        return f"{named} ({value})"

    def amount(value: str, scale: float) -> str:
        return "none" if value == "null" else f"{float(value) * scale:g}"

    for pattern, named, scale, unit in _CHANGED:
        message = pattern.sub(
            lambda m, n=named, s=scale, u=unit:
            f"{n} {amount(m['old'], s)} -> {amount(m['new'], s)} {u}", message)
    for pattern, named, scale, unit in _WITH_UNIT:
        message = pattern.sub(
            lambda m, n=named, s=scale, u=unit:
            f"{n}{m['colon']} {float(m['number']) * s:g} {u}", message)
    for pattern, named, scale in _PATTERNS:
        message = pattern.sub(lambda m, n=named, s=scale: labelled(n, s, m), message)
    return message
