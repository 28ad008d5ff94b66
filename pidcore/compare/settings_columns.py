"""The analysis settings of a settings table (sidecar ``loadcases.csv``, the app's table):
what each column sets, in which unit, and how every analysis setting is said in words.

One wording for every front end: the notes and summaries of :mod:`pidcore.file_settings`, the
corrections column of a comparison (:mod:`pidcore.compare.case`) and a report's parameters
(:mod:`pidcore.report.provenance`) all say ``vibrometer delay 50 µs``, not
``velocity_delay_s=5e-05``. It sits in the analysis layer beside the table's columns
(:mod:`.loadcase`) so that the comparison may import it as well as the store's workflow.

Public API
----------
SettingsColumn, ANALYSIS_COLUMNS
    How each analysis column of the table sets its options field (unit, plausible range,
    label).
COLUMN_WORDS
    Options field -> its words, factor and unit, of the columns that state a number.
setting_in_words, setting_phrase
    One setting (an options field or the specimen) in words with its unit.
describe_corrections
    The corrections of an analysis in words.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from .loadcase import SPECIMEN_COLUMN

__all__ = ["ANALYSIS_COLUMNS", "COLUMN_WORDS", "SettingsColumn", "describe_corrections",
           "setting_in_words", "setting_phrase"]


@dataclass(frozen=True)
class SettingsColumn:
    """A table column that sets one :class:`~pidcore.measure.AnalysisOptions` field.

    Attributes
    ----------
    field : str
        The options field it sets.
    kind : str
        ``"number"`` (finite, >= 0), ``"channel"`` (a name), ``"channels"`` (``;``-separated)
        or ``"time unit"`` (a unit of time, as ``time_unit=`` / ``--time-unit`` takes it).
    scale : float
        Column value / ``scale`` = the field's SI value (µs -> s: 1e6). A division, not a
        product with 1e-6: 50 / 1e6 is the double nearest 5e-5, as the literal ``5e-5`` of
        ``--velocity-delay 5e-5`` is, so both give the same analysis to the last bit.
    expected : str
        What a valid value is, for the error message.
    smallest : float
        Smallest plausible positive value in the column's unit: a positive value below it is
        refused as a unit slip (0 for no such check).
    slip : str
        The unit the value was probably typed in: the field's SI unit (``"s"``), whose value
        times ``scale`` is the column's (``unit``), for the message.
    unit : str
        The column's unit (``"µs"``).
    label : str
        How messages name the setting (``"vibrometer delay"``); "" for a channel column.
    """

    field: str
    kind: str
    scale: float = 1.0
    expected: str = ""
    smallest: float = 0.0
    slip: str = ""
    unit: str = ""
    label: str = ""


#: How each column of :data:`~pidcore.compare.loadcase.ANALYSIS_SETTINGS_COLUMNS` sets its
#: options field.
ANALYSIS_COLUMNS: dict[str, SettingsColumn] = {
    # A laser vibrometer's output delay is µs to ms (tens of µs typically, from its data
    # sheet); 0.01 µs = 10 ns is a thousandth of a sample at 100 kHz and would correct
    # nothing measurable, so a positive value below it is a delay typed in s (5e-5 for 50 µs).
    "velocity_delay_us": SettingsColumn("velocity_delay_s", "number", 1e6,
                                        "a vibrometer output delay in µs >= 0",
                                        0.01, "s", "µs", "vibrometer delay"),
    # The mass between force gauge and coupon is the gauge's top half, a screw or an adapter:
    # grams to hundreds of grams; a positive value below 0.1 g weighs less than an M1 screw
    # and would change nothing measurable, so it is a mass typed in kg (0.012 for 12 g).
    "mass_below_gauge_g": SettingsColumn("mass_below_gauge_kg", "number", 1e3,
                                         "a mass in g >= 0", 0.1, "kg", "g",
                                         "mass below gauge"),
    "baseline_loss_factor": SettingsColumn("baseline_loss_factor", "number", 1.0,
                                           "the empty coupon's loss factor >= 0",
                                           label="baseline loss factor"),
    # The empty structure (coupon and fixture above the gauge) weighs tens of grams to kilos;
    # below 1 g it is a mass typed in kg (0.0222 for the paper's 22.2 g coupon).
    "structure_mass_g": SettingsColumn("structure_mass_kg", "number", 1e3,
                                       "the empty structure's mass in g >= 0", 1.0, "kg", "g",
                                       "structure mass"),
    "force": SettingsColumn("force", "channel"),
    "velocity": SettingsColumn("velocity", "channel"),
    "acceleration": SettingsColumn("acceleration", "channel"),
    "invert": SettingsColumn("invert", "channels"),
    # per file, so that a batch of exports in s and in ms is read each in its own unit
    "time_unit": SettingsColumn("time_unit", "time unit", expected="a unit of time: s, ms or us"),
}

#: How each numeric setting a column states is said in words: its options field -> label,
#: factor and unit as the table's, not SI (``velocity_delay_s`` -> vibrometer delay, 1e6, µs).
COLUMN_WORDS: dict[str, tuple[str, float, str]] = {
    c.field: (c.label, c.scale, f" {c.unit}" if c.unit else "")
    for c in ANALYSIS_COLUMNS.values() if c.label}


#: The analysis settings no settings column states, in words with their unit (those of the
#: columns: :data:`ANALYSIS_COLUMNS`' labels and units).
_OTHER_WORDS = {"frequency_hz": ("drive frequency hint", 1.0, " Hz"),
                "sample_rate_hz": ("sample rate", 1.0, " Hz"),
                "n_harmonics": ("harmonics analysed", 1.0, "")}


def setting_in_words(name: str, value: object) -> tuple[str, str]:
    """An analysis setting (a :class:`~pidcore.measure.AnalysisOptions` field, or the
    specimen) as the notes and reports say it: its name in words and its value with the unit
    of its settings column, e.g. ``("vibrometer delay", "50 µs")`` for ``velocity_delay_s``
    5e-5, ``("structure mass", "22.2 g")``, ``("force channel", "'Fz'")``. ``None`` is
    ``"none"``."""
    if name in COLUMN_WORDS or name in _OTHER_WORDS:
        label, factor, unit = COLUMN_WORDS.get(name) or _OTHER_WORDS[name]
        return label, "none" if value is None else f"{float(value) * factor:g}{unit}"
    if value is None:
        shown = "none"
    elif isinstance(value, (tuple, list)):
        shown = ", ".join(map(repr, value))
    elif isinstance(value, str):
        shown = repr(value)
    else:
        shown = str(value)
    if name == "invert":
        return "inverted", shown
    if name == SPECIMEN_COLUMN:
        return "specimen", shown
    if name == "allow_clipped":
        return "clipped samples", "kept" if value else "refused"
    if name.endswith("_unit"):
        return f"{name.removesuffix('_unit')} unit", shown
    if name in ("force", "velocity", "acceleration"):
        return f"{name} channel", shown
    return name, shown


def setting_phrase(name: str, value: object) -> str:
    """:func:`setting_in_words` as one phrase, ``"vibrometer delay 50 µs"``."""
    return " ".join(setting_in_words(name, value))


def describe_corrections(parameters: Mapping[str, object]) -> str:
    """The corrections of an analysis (its options' parameters, as saved) in words, each
    setting as :func:`setting_in_words` says it (units of the settings table: µs, g); a value
    not saved is 0. "" for no parameters (a record saved without them)."""
    if not parameters:
        return ""

    def stated(name: str) -> float:
        return float(parameters.get(name) or 0.0)

    said = ", ".join(setting_phrase(name, stated(name)) for name in (
        "velocity_delay_s", "mass_below_gauge_kg", "baseline_loss_factor"))
    # how the baseline went off: of the structure's own reactive power, or of the whole
    # (too much); two records of one baseline differ by that, and read the same without it
    structure_kg = stated("structure_mass_kg")
    how = ("" if stated("baseline_loss_factor") <= 0 else
           f" (of a {setting_phrase('structure_mass_kg', structure_kg)})" if structure_kg > 0
           else " (off the whole vibrated mass)")
    return said + how


# --- an analysis saved again with other settings (pidcore analyze, the app's Save and Compare)

#: Fields of :class:`pidcore.measure.AnalysisOptions` that name channels: a record keeps the
#: channels it used (the app saves its options without them), so these may differ from the
#: analysis's.
CHANNEL_FIELDS = ("force", "velocity", "acceleration")


def analysis_parameters_to_store(result: Any, parameters: Mapping) -> dict:
    """The parameters an analysis is stored (and keyed) with: ``parameters`` and the
    channels it used (``result``: a :class:`pidcore.measure.AnalyzedRecord`)."""
    return {**parameters, "channels": result.channels_used}


def other_settings_note(name: str, old: Mapping | None, new: Mapping | None,
                        old_sdc: float, new_sdc: float, *, saved_as: str = "",
                        this: str = "this analysis",
                        now: str = "the one reports and calibrations use now, the earlier is "
                                   "kept in the store") -> str:
    """That ``name`` was saved before (``saved_as``: under that other name) with other
    analysis settings: the parameters that differ (``old`` -> ``new``, as stored:
    :func:`analysis_parameters_to_store`), the saved SDC, and ``this`` analysis's SDC and what it is
    ``now``; "" where the settings are the same or either is not known (None)."""
    changed = _changed_settings(_parameters_of(old), _parameters_of(new))
    if not changed:
        return ""
    return (f"{name} was saved before{f' as {saved_as}' if saved_as else ''} with other "
            f"settings ({changed}; SDC {_shown(old_sdc)}); {this} (SDC {_shown(new_sdc)}) is "
            f"{now}")


def _parameters_of(value: object) -> dict | None:
    """Analysis parameters as the store's canonical JSON reads back (None: not known)."""
    if isinstance(value, Mapping):
        return json.loads(json.dumps(value, sort_keys=True))
    if isinstance(value, str) and value:
        try:
            loaded = json.loads(value)
        except ValueError:
            return None
        return loaded if isinstance(loaded, dict) else None
    return None


def _shown(sdc: float) -> str:
    return f"{sdc:.4g}" if math.isfinite(sdc) else "not known"


def _changed_settings(old: dict | None, new: dict | None) -> str:
    """``"velocity_delay_s 5e-05 -> 0.0"`` for each parameter that differs ("" where either
    is not known: a record whose parameters_json is not read)."""
    if old is None or new is None:
        return ""
    return ", ".join(f"{name} {json.dumps(old.get(name))} -> {json.dumps(new.get(name))}"
                     for name in sorted({*old, *new}) if old.get(name) != new.get(name))
