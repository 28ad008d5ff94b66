"""The library's parameter names in the command line's words: one table, keyword -> flag.

The library names a parameter as a Python caller writes it (``structure_mass_kg``,
``key=NAME``, ``allow_clipped=True``; :mod:`pidcore.errors`); the CLI prints every refusal and
note through :func:`cli_words`, which names the flag the user types instead
(``--structure-mass``, ``--key NAME``, ``--allow-clipped``), from the table of that
sub-command in :data:`COMMAND_FLAGS` (``dem sweep`` takes ``--frequencies``).
"""

from __future__ import annotations

import ast
import functools
import re
from collections.abc import Iterable

from ..errors import KEYWORD_NOT_AFTER_WORD, KEYWORD_NOT_BEFORE, outside_user_names
from ._options import command_line

#: Library keyword (as the message writes it) -> the flag of ``pidcore analyze`` and
#: ``pidcore report`` that sets it: the analysis options and the load case. A single word
#: (``key``, ``force``) is only a keyword with its ``=`` ("the force channel" stays as it is)
#: or, marked ``^``, as the message's first word before its value or colon ("material: ...",
#: "cells: expected >= 1", not "over 2 cells").
FLAG_OF_KEYWORD: dict[str, str] = {
    # analysis options (pidcore.measure.AnalysisOptions, analyze_power)
    "allow_clipped=True": "--allow-clipped",
    "allow_clipped": "--allow-clipped",
    "accept_implausible=True": "--accept-implausible",
    "accept_implausible": "--accept-implausible",
    "velocity_delay_s": "--velocity-delay",
    "mass_below_gauge_kg": "--mass-below-gauge",
    "baseline_loss_factor": "--baseline-loss-factor",
    "structure_mass_kg": "--structure-mass",
    "frequency_hz": "--frequency",
    "n_harmonics": "--harmonics",
    "sample_rate_hz": "--sample-rate",
    "force_unit": "--force-unit",
    "velocity_unit": "--velocity-unit",
    "acceleration_unit": "--acceleration-unit",
    "time_unit": "--time-unit",
    "force=": "--force ",
    "velocity=": "--velocity ",
    "acceleration=": "--acceleration ",
    "invert=": "--invert ",
    "key=": "--key ",
    # load case and specimen (pidcore.compare.loadcase)
    "fill_percent=": "--fill ",
    "fill_percent": "--fill",
    "material=": "--material ",
    "^material": "--material",
    "direction=": "--direction ",
    "^direction": "--direction",
    "specimen=": "--specimen ",
    "sidecar=": "--sidecar ",
}

#: The call that writes a calibration folder, as the command that does: named by the refusal
#: of a half-moved folder (:func:`pidcore.specimen.finish_calibration_moves`),
#: which every command that reads a calibration or a calibrated specimen file (``--specimen
#: DIR/calibrated_specimen.toml``: :func:`pidcore.specimen.load_specimen`) may say.
CALIBRATION_WRITER: dict[str, str] = {
    "write_outputs(result, out_dir)": "pidcore calibrate --out"}

#: Each sub-command's keywords and flags (a command not named here has no parameter a
#: library message names: its messages stay as they are). Only the command's own: a
#: calibration's fitted ``baseline_loss_factor`` is no ``--baseline-loss-factor``, and a
#: calibration table's ``frequency_hz`` column no ``--frequency``.
COMMAND_FLAGS: dict[str, dict[str, str]] = {
    "analyze": {**FLAG_OF_KEYWORD, **CALIBRATION_WRITER},
    "report": {
        **FLAG_OF_KEYWORD,
        "store=": "--store ", "dem_store=": "--dem-store ", "dem_store": "--dem-store",
        "calibration=": "--calibration ", "calibration_key=": "--calibration-key ",
        "calibration_key": "--calibration-key", "pool=True": "--pool", "out_dir": "--out",
        "case_sheets=True": "--case-sheets",
        # --calibration names the file `pidcore calibrate --out` writes, not the Python call
        # (longer, so matched before its "out_dir")
        "write_outputs(result, out_dir)": "pidcore calibrate --out",
        # the calibration a report reads from a DEM store is saved there by `pidcore calibrate`
        "calibrate with store_path=": "pidcore calibrate --dem-store ",
    },
    "dem run": {
        "fill_reference='capacity'": "--fill-reference capacity",
        "fill_reference='paper'": "--fill-reference paper",
        "fill_reference": "--fill-reference", "time_step": "--time-step",
        "^cells": "--cells", "frequency_hz": "--frequency", "acceleration_g": "--acceleration",
        "^material": "--material", "^direction": "--direction", "^seed": "--seed",
        "^steady_cycles": "--cycles",
        "damping_coefficient='calibrated'": "--damping-coefficient calibrated",
        "normal_damping_mode='literal'": "--damping-mode literal",
        "start_packing='loose'": "--packing loose",
        **CALIBRATION_WRITER,
    },
    "calibrate": {
        "^fit/priors": "--fit/--prior", "^fit": "--fit", "fit=": "--fit ",
        "^priors": "--prior", "priors=": "--prior ",
        "^discrepancy": "--discrepancy", "discrepancy=": "--discrepancy ",
        "discrepancy_floor": "--discrepancy-floor", "design_size": "--design-size",
        "cross_validate": "--cross-validate", "^method": "--method", "method=": "--method ",
        "specimen=": "--specimen ", "read_measured_table": "--data",
        "write_outputs(result, out_dir)": "pidcore calibrate --out",
        # the DEM runs' own refusals (more cells than memory holds, a seed past 2^63)
        "^cells": "--cells", "^seed": "--seed", "^steady_cycles": "--steady-cycles",
    },
    "bench signal": {"n_samples": "--samples"},
    "store remove": {"with_dependents=True": "--with-dependents"},
    # commands that read a --specimen file (or FILE) and no other library keyword
    "model damper": CALIBRATION_WRITER, "model figures": CALIBRATION_WRITER,
    "specimen check": {
        **CALIBRATION_WRITER,
        # the cures of a simulated restitution off the stated one (restitution_note)
        "damping_coefficient='calibrated' (DemConfig)":
            "pidcore dem run --damping-coefficient calibrated",
        "normal_damping_mode='literal'": "pidcore dem run --damping-mode literal",
    },
}
COMMAND_FLAGS["dem sweep"] = {
    **COMMAND_FLAGS["dem run"],
    "frequency_hz": "--frequencies", "acceleration_g": "--accelerations",
    "fills_percent": "--fills", "^grid": "--grid", "^workers": "--workers",
    "^scheduler": "--scheduler",
}


#: A command line the table says (its value the library's keyword's, a Python string literal:
#: ``store_path='c a l.h5'``) with that value as the shell reads it (:func:`command_line`): the
#: path was substituted raw, and "c a l.h5" pasted as three words
_COMMAND_VALUE = re.compile(r"(pidcore calibrate --dem-store )"
                            r"('(?:[^'\\\n]|\\.)*'|\"(?:[^\"\\\n]|\\.)*\")")


@functools.cache
def _table(command: str) -> tuple[dict[str, str], re.Pattern]:
    flags = COMMAND_FLAGS.get(command, {})
    if not flags:
        return {}, re.compile(r"(?!)")  # matches nothing
    alternatives = []
    for keyword in sorted(flags, key=len, reverse=True):  # "allow_clipped=True" first
        anchored = keyword.startswith("^")
        word = keyword.removeprefix("^")
        alternatives.append((r"^" if anchored else KEYWORD_NOT_BEFORE) + re.escape(word)
                            + (r"(?=[:\s])" if anchored else
                               KEYWORD_NOT_AFTER_WORD + "=?" if word[-1].isalnum() else ""))
    return ({k.removeprefix("^"): v for k, v in flags.items()},
            re.compile("|".join(alternatives)))


def _flag(flags: dict[str, str], m: re.Match) -> str:
    said = m.group(0)
    flag = flags[said] if said in flags else flags[said.removesuffix("=")] + " "
    # "force_unit='N'" is "--force-unit 'N'": a flag takes its value after a space, and
    # without one ("material=, direction=: only with FILES") it is the flag alone
    valued = m.end() < len(m.string) and m.string[m.end()] not in " ,:;)"
    return flag if valued else flag.rstrip()


def cli_words(message: str, command: str = "analyze", *, names: Iterable[str] = ()) -> str:
    """``message`` (a library refusal or note) with its parameter keywords named as the flags
    of ``pidcore COMMAND`` (``"dem sweep"``; the default: those of ``analyze``); the user's
    names in it (files, folders, channels, specimens, store keys, and ``names``: what the
    command line gave) stay as written."""
    flags, pattern = _table(command)
    said = outside_user_names(message, lambda text: pattern.sub(lambda m: _flag(flags, m), text),
                              names=names)
    return _COMMAND_VALUE.sub(
        lambda m: m.group(1) + command_line(ast.literal_eval(m.group(2))), said)
