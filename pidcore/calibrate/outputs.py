"""Outputs of a calibration: calibration.json, the calibrated specimen file, figures and a
Markdown/HTML summary, written into one directory (each file complete or absent)."""

from __future__ import annotations

import dataclasses
import html
import json
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..atomic_files import (
    finished_moves_note,
    fsync_tree,
    move_files_into_folder,
    new_temporary_folder_for,
    real_folder,
    refused_unless_written,
)
from ..plot_text import text_as_typed
from ..records import json_safe
from ..specimen import CALIBRATED_SPECIMEN_FILE
from ..units import display_number
from .calibrate import CalibrationResult
from .data import measured_words
from .posterior import summary_texts

#: The calibrated specimen's file among the outputs (one name with the specimen loader's, which
#: finishes a killed calibration's moves before reading it).
SPECIMEN_FILE = CALIBRATED_SPECIMEN_FILE


def document_json(document: dict) -> str:
    """JSON text of a calibration document (non-finite numbers as null)."""
    return json.dumps(json_safe(document), indent=2)


def rms_text(value: float) -> str:
    """An RMS error of the SDC as every output shows it (the CLI, summary.md, the calibrated
    specimen's header: they showed 0.0822, 0.082 and 0.08218 for one number)."""
    return display_number(value, decimals=4)


def specimen_text(result: CalibrationResult) -> str:
    """TOML text of the calibrated specimen (every fitted specimen field at its posterior
    median), headed by comments with the 95 % intervals; any command takes it as --specimen.
    """
    lines = ["# pidcore calibrated specimen: posterior medians of `pidcore calibrate`",
             f"# started from {result.specimen.name} ({result.specimen.source}); "
             f"fitted: {', '.join(result.settings['fit'])}"]
    units = parameter_units(result)
    for name, p in result.parameters.items():
        # the value the file sets, in full; the interval to the digits its sampling leaves;
        # its unit as the command and the summaries name it (rolling_friction had none)
        _, low, high = summary_texts(p)
        lines.append(f"#   {name} [{units[name]}] = {p['median']:.6g}  "
                     f"(95 %: {low} .. {high})")
    if result.loo_rms is not None:
        lines.append(f"# leave-one-out RMS of the SDC: {rms_text(result.loo_rms)}")
    lines.append(f"# in-sample RMS of the SDC: {rms_text(result.rms)}")
    if result.file_predicted:
        lines.append(f"# {FILE_PREDICTS}:")
        lines += [f"#   {case}: {own} (posterior median {median}, {difference})"
                  for case, own, median, difference in file_prediction_rows(result)]
    measured = measured_words(result.settings.get("measured") or [])
    if measured:  # the tests it speaks for, by file and hash or by analysis keys
        lines.append(f"# {measured}")
    lines += [f"# note: {note}" for note in result.notes]  # e.g. a value set by its prior
    return "\n".join(lines) + "\n" + result.calibrated_specimen().to_toml()


#: What :func:`file_prediction_rows` are, as the file's header and the summaries say it.
FILE_PREDICTS = ("this file's own values (each parameter's posterior median) predict the SDC "
                 "(Eq. 11, with its fixture and baseline; a DEM re-run of the file should "
                 "give it, within the DEM's scatter), beside the calibration's posterior "
                 "median of the SDC, which marginal medians of correlated parameters do not "
                 "reproduce")
#: Head of :func:`file_prediction_rows`' table in the summaries.
FILE_PREDICTION_HEAD = ["load case", "calibrated file's values predict [-]",
                        "SDC calibrated DEM, posterior median (Eq. 11) [-]",
                        "file vs posterior median [%]"]


def file_prediction_rows(result: CalibrationResult) -> list[list[str]]:
    """Per load case: its frequency, acceleration and fill, the SDC the calibrated file's
    values predict (:attr:`CalibrationResult.file_predicted`), the posterior median SDC, and
    their difference in percent of the latter."""
    from .prediction import sdc_text

    return [[f"{r['frequency_hz']:g} Hz, {r['acceleration_g']:g} g, {r['fill_percent']:g} %",
             sdc_text(own), sdc_text(r["predicted"]),
             f"{100 * (own - r['predicted']) / r['predicted']:+.1f} %"
             if r["predicted"] > 0 else "-"]
            for r, own in zip(result.predictions, result.file_predicted, strict=True)]


def _band_text(low: float, high: float, bound: float | None = None) -> str:
    """A 95 % band as the summary shows it: as every page writes a band
    (:func:`~pidcore.calibrate.prediction.band_text`: the summary wrote ``0.000 .. 6.283``
    where the report and the app wrote ``0 .. 6.283``), an upper bound past ``bound`` (an SDC
    no measurement is kept at: :func:`pidcore.compare.plausibility.sdc_bound` of the specimen
    at this fill; default 2 pi, :data:`~pidcore.compare.plausibility.SDC_UPPER_BOUND`) cut
    there with the model's own bound said, as the report and the app cut it
    (:meth:`pidcore.calibrate.prediction.CalibratedPrediction.band`)."""
    from ..compare.plausibility import SDC_UPPER_BOUND
    from .prediction import band_text

    bound = SDC_UPPER_BOUND if bound is None else bound
    if high > bound:
        at = "2 pi" if bound == SDC_UPPER_BOUND else f"the specimen's SDC bound {bound:.4g}"
        return (f"{band_text(min(low, bound), bound)} (cut at {at}; "
                f"model {high:.3g}: unconstrained)")
    return band_text(low, high)


def parameter_units(result: CalibrationResult) -> dict[str, str]:
    """Unit of each parameter of ``result`` (:attr:`~pidcore.calibrate.parameters.
    ParameterSpec.unit`, ``"-"`` where dimensionless): the summary's, the app's and the
    command's table of medians and intervals name it in every row, as calibration.json's
    ``units`` does; only a name such as fixture_mass_kg said it before."""
    units = result.units()
    return {name: units.get(name, "-") for name in result.parameters}


#: Head of the table of parameters (their medians, intervals and prior bounds are in the
#: row's unit).
PARAMETER_HEAD = ("parameter", "unit", "median", "95 % interval", "prior bounds")


def row_sdc_bounds(result: CalibrationResult | None, rows: list[dict]) -> list[float]:
    """The SDC bound of each prediction row (:func:`pidcore.calibrate.prediction.
    calibrated_sdc_bound` at the row's fill), where the summary and the plot cut its band, as
    the report does; 2 pi where the specimen is not known (``result`` None)."""
    from ..compare.plausibility import SDC_UPPER_BOUND

    if result is None:
        return [SDC_UPPER_BOUND] * len(rows)
    return [bound.sdc for bound in result.sdc_bounds(rows)]


def coverage_text(verdicts: list[str]) -> str:
    """How many rows' 95 % bands hold their measurement, of those that can judge it, as
    every output of a calibration says it (summary.md, summary.html, the command):
    ``"10/12 inside the 95 % band"``, with ``" (1 more uninformative: ...)"`` where bands
    span every plausible SDC (``verdicts``: :meth:`~pidcore.calibrate.calibrate.
    CalibrationResult.band_verdicts`), counted neither inside nor among those judged, as the
    report counts them."""
    from ..constants import BAND_VERDICTS
    from .prediction import uninformative_count_text

    inside, outside, _, uninformative = BAND_VERDICTS
    judged = verdicts.count(inside) + verdicts.count(outside)
    return (f"{verdicts.count(inside)}/{judged} inside the 95 % band"
            + uninformative_count_text(verdicts.count(uninformative)))


def _table_rows(rows: list[dict], bounds: list[float], verdicts: list[str]
                ) -> list[list[str]]:
    from ..constants import BAND_VERDICTS
    from .prediction import sdc_text

    outside = BAND_VERDICTS[1]
    out = []
    for r, bound, verdict in zip(rows, bounds, verdicts, strict=True):
        # every SDC as its band and the report write one: they were at 3 decimals (0.492,
        # 0.083) beside a band of 4 significant digits (0.01469 .. 0.2024)
        out.append([f"{r['frequency_hz']:g}", f"{r['acceleration_g']:g}",
                    f"{r['fill_percent']:g}", sdc_text(r["measured"]),
                    sdc_text(r["predicted"]), _band_text(r["low95"], r["high95"], bound),
                    sdc_text(r["predicted"] - r["measured"], signed=True),
                    f"**{verdict}**" if verdict == outside else verdict])
    return out


def _prediction_head() -> list[str]:
    """Head of the summary's tables of predictions: every column names its unit, by the names
    the report and :meth:`pidcore.calibrate.Calibration.to_pandas` give the same quantity
    (the summary said "measured SDC", "predicted SDC", "95 % band" and "inside" where they
    say "SDC measured (Eq. 11)", "SDC calibrated DEM (Eq. 11)", "calibrated 95 % band" and
    "measured in calibrated 95 % band")."""
    from .prediction import (
        CALIBRATED_BAND_COLUMN,
        CALIBRATED_COLUMN,
        CALIBRATED_DIFFERENCE_COLUMN,
        MEASURED_EQ11_COLUMN,
        PACKING_RATIO_COLUMN,
        VERDICT_COLUMN,
    )

    return ["frequency [Hz]", "acceleration [g]", PACKING_RATIO_COLUMN, MEASURED_EQ11_COLUMN,
            CALIBRATED_COLUMN, CALIBRATED_BAND_COLUMN, CALIBRATED_DIFFERENCE_COLUMN,
            VERDICT_COLUMN]


def _sampler_words(result: CalibrationResult) -> str:
    """emcee's convergence figures, as the summary states them (nothing for the grid)."""
    sampler = result.settings.get("sampler")
    if not sampler:
        return ""
    return (f" ({sampler['steps']} steps x {sampler['walkers']} walkers, acceptance "
            f"{sampler['acceptance']:.2f}, autocorrelation time "
            f"{max(sampler['autocorrelation_steps']):.0f} steps, effective sample "
            f"{sampler['effective_size']:.0f}, "
            f"{'converged' if sampler['converged'] else 'NOT converged'})")


def specimen_words(result: CalibrationResult, *, full_hash: bool = True) -> str:
    """Which specimen file was calibrated and which it wrote, by name and sha256:
    ``"Specimen: my_steel (sha256 9a19..., from my_steel.toml); calibrated file:
    my_steel_calibrated (sha256 b083...)."`` with the whole hash (the summary's provenance),
    else by the label the app, reports and ``dem run`` show (``full_hash=False``, the
    command's output: ``"Specimen: my_steel [9a19aa] (from my_steel.toml); ..."``,
    :func:`pidcore.specimen.hashed_name`). The summary and the command's output named
    neither: two files of one name calibrated alike read alike."""
    from ..specimen import hashed_name

    start, written = result.specimen, result.calibrated_specimen()
    if not full_hash:
        return (f"Specimen: {hashed_name(start.name, start.hash)} (from {start.source}); "
                f"calibrated file: {hashed_name(written.name, written.hash)}.")
    return (f"Specimen: {start.name} (sha256 {start.hash}, from {start.source}); "
            f"calibrated file: {written.name} (sha256 {written.hash}).")


def _fitted_words(result: CalibrationResult) -> str:
    """The summary's first line: what was fitted, against what, and how."""
    return (f"Fitted: {', '.join(s.name for s in result.specs)}; "
            f"{len(result.predictions)} measured load cases; "
            f"{result.settings['cells']} cells per DEM run, design of "
            f"{result.settings['design_size']} point(s); "
            f"posterior by {result.settings['method_used']}{_sampler_words(result)}; "
            f"runs computed {result.runs['computed']}, cached {result.runs['cached']}; "
            f"{result.wall_s:.1f} s.")


#: Head of the energy check's table (:attr:`CalibrationResult.energy_check`).
_ENERGY_HEAD = ["frequency [Hz]", "acceleration [g]", "start [J]", "calibrated median [J]",
                "95 % band [J]", "start inside [yes/no]"]


def _summary_tables(result: CalibrationResult) -> list[tuple[str, list[str], list[list[str]]]]:
    """Every table of the summary as ``(heading, head, rows of cells)``, the one content
    summary.md and summary.html write (a verdict that is a miss in ``**bold**``; heading ""
    for the parameters' table, which follows the specimen's line). summary.html showed four of
    the five columns of the parameters, its prediction headings without their RMS, and neither
    the correlations nor the energy check with its verdicts."""
    units = parameter_units(result)
    parameters = []
    for name, p in result.parameters.items():
        median, low, high = summary_texts(p)
        parameters.append([name, units[name], median, f"{low} .. {high}",
                           f"{p['prior_low']:g} .. {p['prior_high']:g}"])
    tables = [("", list(PARAMETER_HEAD), parameters)]
    names = [s.name for s in result.specs]
    tables.append(("Posterior correlations", ["", *names],
                   [[name, *(f"{c:+.2f}" for c in row)]
                    for name, row in zip(names, result.correlations, strict=True)]))
    for title, rows in (("In-sample posterior predictions", result.predictions),
                        ("Leave-one-out predictions", result.loo)):
        if not rows:
            continue
        rms = float(np.sqrt(np.mean([(r["predicted"] - r["measured"]) ** 2 for r in rows])))
        verdicts = result.band_verdicts(rows)
        tables.append((f"{title}: RMS {rms_text(rms)}, {coverage_text(verdicts)}",
                       _prediction_head(),
                       _table_rows(rows, row_sdc_bounds(result, rows), verdicts)))
    if result.file_predicted:
        tables.append((f"What the calibrated file predicts: {FILE_PREDICTS}",
                       list(FILE_PREDICTION_HEAD), file_prediction_rows(result)))
    if any(s.kind == "dem" for s in result.specs):
        tables.append(("Energy per cycle per cell: starting specimen vs calibrated DEM",
                       list(_ENERGY_HEAD),
                       [[f"{r['frequency_hz']:g}", f"{r['acceleration_g']:g}",
                         f"{r['energy_per_cycle_per_cell_start_j']:.3g}",
                         f"{r['energy_per_cycle_per_cell_calibrated_j']:.3g}",
                         f"{r['low95_j']:.3g} .. {r['high95_j']:.3g}",
                         "yes" if r["within"] else "**no**"] for r in result.energy_check]))
    return tables


def summary_markdown(result: CalibrationResult) -> str:
    """Markdown summary: parameters, correlations, predictions, LOO table, energy check."""
    lines = ["# Calibration summary", "", _fitted_words(result), "", specimen_words(result)]
    measured = measured_words(result.settings.get("measured") or [])
    if measured:
        lines += ["", measured]
    for heading, head, rows in _summary_tables(result):
        if heading.startswith("Posterior correlations"):
            lines += ["", f"{heading}:"]
        elif heading:
            lines += ["", f"## {heading}"]
        lines += ["", "| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
        # a blank head cell (the correlations' corner) as "| |", as it was written
        lines[-2] = lines[-2].replace("|  |", "| |")
        lines += ["| " + " | ".join(cells) + " |" for cells in rows]
    if result.notes:
        lines += ["", "Notes:", ""] + [f"- {n}" for n in result.notes]
    return "\n".join(lines) + "\n"


def summary_html(result: CalibrationResult) -> str:
    """The Markdown summary's content as a standalone HTML page: the same lines and tables
    (:func:`_summary_tables`), a miss in bold."""
    def cell(text: str, tag: str = "td") -> str:
        bold = text.startswith("**") and text.endswith("**") and len(text) > 4
        inner = html.escape(text[2:-2] if bold else text)
        return f"<{tag}>{'<b>' + inner + '</b>' if bold else inner}</{tag}>"

    parts = ["<!doctype html><html><head><meta charset='utf-8'><title>Calibration</title>",
             "<style>body{font-family:sans-serif}td,th{border:1px solid #ccc;padding:2px 6px}"
             "table{border-collapse:collapse}</style></head><body><h1>Calibration summary</h1>",
             f"<p>{html.escape(_fitted_words(result))}</p>",
             f"<p>{html.escape(specimen_words(result))}</p>"]
    measured = measured_words(result.settings.get("measured") or [])
    if measured:
        parts.append(f"<p>{html.escape(measured)}</p>")
    for heading, head, rows in _summary_tables(result):
        if heading:
            parts.append(f"<h2>{html.escape(heading)}</h2>")
        parts.append("<table><tr>" + "".join(cell(h, "th") for h in head) + "</tr>")
        parts += ["<tr>" + "".join(cell(c) for c in cells) + "</tr>" for cells in rows]
        parts.append("</table>")
    if result.notes:  # summary.md's notes (a value set by its prior, records left out)
        parts.append("<h2>Notes</h2><ul>"
                     + "".join(f"<li>{html.escape(n)}</li>" for n in result.notes) + "</ul>")
    parts.append("<p><img src='predictions.png' alt='measured vs predicted'></p>"
                 "<p><img src='posterior_pairs.png' alt='posterior pairs'></p></body></html>")
    return "\n".join(parts)


def cut_band_bars(predicted, low, high, bounds) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                           np.ndarray]:
    """(distance down to the low bound, distance up to the high bound, whether each upper
    bound was cut) of 95 % bands as every figure draws them: an upper bound past its SDC bound
    (``bounds``, one per band) is cut there, as :func:`_band_text` and the report cut it
    (:meth:`~pidcore.calibrate.prediction.CalibratedPrediction.band`)."""
    pred, low, high, limit = (np.asarray(v, dtype=float) for v in (predicted, low, high,
                                                                      bounds))
    shown = np.minimum(high, limit)
    # a median past the bound has no band below it: its bar ends at its point
    return pred - np.minimum(low, pred), np.maximum(shown - pred, 0.0), high > limit


def shown_band_bars(rows: list[dict], bounds: list[float] | None = None
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    """(predicted, distance down to low95, distance up to high95, whether a bound was cut) of
    prediction rows as the plot draws them (:func:`cut_band_bars`; ``bounds``:
    :func:`row_sdc_bounds`, default 2 pi)."""
    from ..compare.plausibility import SDC_UPPER_BOUND

    pred = np.array([r["predicted"] for r in rows], dtype=float)
    limit = np.full(len(rows), SDC_UPPER_BOUND) if bounds is None else bounds
    below, above, cut = cut_band_bars(pred, [r["low95"] for r in rows],
                                      [r["high95"] for r in rows], limit)
    return pred, below, above, bool(cut.any())


#: The legend's words for points whose band spans 0 .. 2 pi, drawn hollow with a
#: dashed bar (:func:`draw_bands`).
UNINFORMATIVE_LABEL = "95 % band uninformative (0 .. 2 pi: cannot test the model)"


def draw_bands(ax: Any, x, predicted, low, high, bounds, verdicts, *, label: str,
               color: str | None = None) -> set[float]:
    """Calibrated predictions at ``x`` with their 95 % bands as error bars, cut at their SDC
    bounds (:func:`cut_band_bars`), as predictions.png, :meth:`~pidcore.calibrate.prediction.
    Calibration.plot` and the report's and the app's figures draw them: a band whose verdict
    (``verdicts``, words of :data:`pidcore.constants.BAND_VERDICTS`) is ``uninformative``
    spans every plausible SDC, and is drawn with a hollow marker and a dashed bar under a
    legend entry of its own (``"<label>, "`` + :data:`UNINFORMATIVE_LABEL`); drawn like the
    others, a band that holds any measurement read as a hit. Returns the bounds a band was
    cut at (:func:`draw_cut_bounds` draws them)."""
    from ..constants import BAND_VERDICTS

    x, pred = np.asarray(x, dtype=float), np.asarray(predicted, dtype=float)
    bounds = np.asarray(bounds, dtype=float)
    below, above, cut = cut_band_bars(pred, low, high, bounds)
    apart = np.array([v == BAND_VERDICTS[3] for v in verdicts], dtype=bool)
    for chosen, style, words in ((~apart, {"fmt": "o"}, "95 % band"),
                                 (apart, {"fmt": "o", "mfc": "none"}, UNINFORMATIVE_LABEL)):
        if not chosen.any():
            continue
        drawn = ax.errorbar(x[chosen], pred[chosen], yerr=[below[chosen], above[chosen]],
                            capsize=3, color=color, label=f"{label}, {words}", **style)
        if chosen is apart:
            drawn.lines[2][0].set_linestyle("--")
    return {float(b) for b in bounds[cut]}


def draw_cut_bounds(ax: Any, bounds: set[float]) -> None:
    """One dashed line per SDC bound a band was cut at (:func:`draw_bands`): a band past its
    bound reached a value no measurement is kept at (a fill of its own has its own bound)."""
    from ..compare.plausibility import SDC_UPPER_BOUND

    for bound in sorted(bounds):
        ax.axhline(bound, color="0.5", ls="--", lw=1,
                   label=("2 pi" if bound == SDC_UPPER_BOUND else f"SDC bound {bound:.3g}")
                   + ": bands cut here (model unconstrained above)")


@text_as_typed
def predictions_figure(result: CalibrationResult) -> Any:
    """The figure of predictions.png: measured SDC per load case with the
    posterior-predictive 95 % bands (and LOO's), drawn by :func:`draw_bands` (an
    uninformative band apart, as the summary marks and counts it); returns the matplotlib
    figure (not closed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = result.predictions
    x = np.arange(len(rows))
    fig, ax = plt.subplots(figsize=(max(6, 0.7 * len(rows)), 4.5), constrained_layout=True)
    cut_at: set[float] = set()
    for offset, data, label, color in ((-0.12, rows, "calibrated (all points)", "C0"),
                                       (0.12, result.loo, "leave-one-out", "C1")):
        if not data:
            continue
        cut_at |= draw_bands(ax, x + offset, [r["predicted"] for r in data],
                             [r["low95"] for r in data], [r["high95"] for r in data],
                             row_sdc_bounds(result, data), result.band_verdicts(data),
                             label=label, color=color)
    draw_cut_bounds(ax, cut_at)
    ax.plot(x, [r["measured"] for r in rows], "k*", ms=10, label="measured")
    ax.set_xticks(x, [f"{r['frequency_hz']:g} Hz\n{r['acceleration_g']:g} g" for r in rows],
                  fontsize=8)
    ax.set_ylabel("SDC [-]")
    ax.legend(fontsize=8)
    return fig


def plot_predictions(result: CalibrationResult, path: Path) -> None:
    """predictions.png (:func:`predictions_figure`) written to ``path``."""
    _write_and_close(predictions_figure(result), path, dpi=120)


def _write_and_close(fig: Any, path: Path, *, dpi: int) -> None:
    # the figure is closed even where writing fails: pyplot keeps every open figure alive
    import matplotlib.pyplot as plt

    try:
        fig.savefig(path, dpi=dpi)
    finally:
        plt.close(fig)


@text_as_typed
def pairs_figure(result: CalibrationResult) -> Any:
    """The figure of posterior_pairs.png: histograms of the posterior samples on the diagonal
    (their count on its axis), scatter below it, each axis labelled with its parameter and
    unit as the summary's table names them (``fixture_mass_kg [kg]``; the axes named the
    parameter alone, so 0.25 of a dimensionless friction read like 0.25 kg); returns the
    matplotlib figure (not closed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    units = parameter_units(result)
    names = [s.name for s in result.specs]
    labels = [f"{name} [{units.get(name, '-')}]" for name in names]
    k = len(names)
    fig, axes = plt.subplots(k, k, figsize=(2.6 * k, 2.6 * k), squeeze=False,
                             constrained_layout=True)
    s = result.samples
    for i in range(k):
        for j in range(k):
            ax = axes[i][j]
            if j > i:
                ax.axis("off")
            elif i == j:
                ax.hist(s[:, i], bins=40, color="C0")
                ax.set_ylabel("posterior samples [count]", fontsize=7)
            else:
                ax.plot(s[:, j], s[:, i], ".", ms=1, alpha=0.3)
            if i == k - 1:
                ax.set_xlabel(labels[j], fontsize=8)
            if j == 0 and i > 0:
                ax.set_ylabel(labels[i], fontsize=8)
    return fig


def plot_pairs(result: CalibrationResult, path: Path) -> None:
    """posterior_pairs.png (:func:`pairs_figure`) written to ``path``."""
    _write_and_close(pairs_figure(result), path, dpi=100)


def finish_interrupted_outputs(out_dir: str | os.PathLike) -> str:
    """Complete the outputs a calibration killed while moving them into ``out_dir``
    (SIGKILL, a power loss) left half-moved, so that it holds that calibration's whole set;
    returns a note saying so ("" where nothing was left). :func:`write_outputs` calls it
    first; a front-end calls it before its work, to say so at once."""
    return finished_moves_note(out_dir, kind="calibration")


def write_outputs(result: CalibrationResult, out_dir: str | os.PathLike, *,
                  wording: Callable[[str], str] | None = None) -> list[Path]:
    """Write every output into ``out_dir`` (created); returns the paths written.

    ``wording``: the notes of summary.md, summary.html and the calibrated specimen's header
    in the front-end's words, as it prints them (the CLI's
    :func:`pidcore.cli._vocabulary.cli_words`: ``--prior``, not ``priors=``), as
    :func:`pidcore.report.pipeline.make_report` takes it; calibration.json keeps the
    library's, the words the store keeps it in.

    All or nothing, as the store commits: the files are made in a hidden folder beside
    ``out_dir`` and moved into it in one step that Ctrl-C cannot cut in two
    (:func:`pidcore.interrupt.deferred`). A Ctrl-C while they were written (the figures take
    seconds) used to leave a folder with a calibration.json and no figures, which looked like
    a finished calibration; now ``out_dir`` is as it was, or holds the whole new set (files
    of other names in it are kept). A kill (SIGKILL, a power loss) while the files are moved
    into an existing ``out_dir`` is completed by the next write
    (:func:`finish_interrupted_outputs`, :func:`pidcore.atomic_files.move_files_into_folder`).
    An ``out_dir`` that is a link to a folder stays a link, and the folder it points to gets
    the outputs, built beside it, as a report's ``out_dir`` does. A write that fails (a full
    disk) is a ``ParameterError`` naming the file, ``out_dir`` left as it was
    (:func:`pidcore.atomic_files.refused_unless_written`).
    """
    import shutil

    from .. import interrupt

    out = Path(out_dir)
    said = result if wording is None else \
        dataclasses.replace(result, notes=[wording(note) for note in result.notes])
    # every text first: one that cannot be made (a calibrated specimen outside the domain)
    # refuses before any folder is created, not after, leaving it empty
    texts = (("calibration.json", document_json(result.full_document())),
             (SPECIMEN_FILE, specimen_text(said)),
             ("summary.md", summary_markdown(said)),
             ("summary.html", summary_html(said)))
    # a link to a folder stays a link: the folder it points to gets the outputs, built beside
    # it (beside the link, a link to another disk's folder failed to move them there, and one
    # to a folder yet to be made was replaced by a real folder)
    real = real_folder(out)
    work = None
    try:
        # a full disk or quota up to the commit below leaves out_dir as it was: one line
        with refused_unless_written(out, "the calibration's outputs"):
            real.parent.mkdir(parents=True, exist_ok=True)
            # before this write's: the earlier set whole, then replaced
            finish_interrupted_outputs(out)
            # beside out_dir: on its file system, so that the moves below are renames
            work = new_temporary_folder_for(real)
            names = []
            for name, text in texts:
                (work / name).write_text(text, encoding="utf-8")
                names.append(name)
            for name, plot in (("predictions.png", plot_predictions),
                               ("posterior_pairs.png", plot_pairs)):
                plot(result, work / name)
                names.append(name)
            fsync_tree(work)  # the files on disk before the renames that name them
        with interrupt.deferred():
            if not real.exists():
                os.replace(work, real)
            else:  # a folder (check_out_folder): each file replaced, the set in one step
                move_files_into_folder(work, real)
    finally:
        if work is not None:
            shutil.rmtree(work, ignore_errors=True)
    return [out / name for name in names]
