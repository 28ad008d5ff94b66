"""The calibration page's boundary to :mod:`pidcore.calibrate` and its background task.

The page calls only what is here. :func:`calibration_api` says whether the calibration library
is installed (it is written on its own branch); :class:`CalibrationRunner` runs
``pidcore.calibrate.calibrate`` on the store's measurements in a thread outside the script
runs (it starts DEM runs, minutes), saves the calibration in the store
(:func:`pidcore.calibrate.persist.save_calibration`, so that it outlives a restart of the app
and :func:`available_calibrations` offers it from there) and keeps the outputs of
``write_outputs`` in memory for the page to show and offer for download. The DEM runs it needs
are cached in the store, so a calibration started again reuses them.
"""

from __future__ import annotations

import importlib
import math
import tempfile
import threading
import time
import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ..compare.align import (
    MEASURED_EQ11_COLUMN,
    MEASURED_EQ11_DOF_COLUMN,
    MEASURED_EQ11_STDERR_COLUMN,
    PACKING_RATIO_COLUMN,
)
from ..compare.plausibility import SDC_BOUND_COLUMN
from ..constants import BackgroundState
from ..interrupt import StopRequested

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

    from .jobs import JournalOwner

#: Module the page wraps.
CALIBRATE_MODULE = "pidcore.calibrate"
#: Functions and tables the page needs from it.
REQUIRED = ("calibrate", "measured_from_store", "write_outputs", "CATALOGUE", "parse_fit")


def calibration_api() -> tuple[object | None, str]:
    """``(module, "")`` when :mod:`pidcore.calibrate` offers :data:`REQUIRED`, else
    ``(None, reason)``."""
    try:
        module = importlib.import_module(CALIBRATE_MODULE)
    except ModuleNotFoundError as exc:
        if exc.name not in (CALIBRATE_MODULE, "pidcore"):
            return None, f"{CALIBRATE_MODULE} cannot be imported: {exc}"
        return None, (f"{CALIBRATE_MODULE} is not part of this installation yet (it is written "
                      "on the `calibrate` branch); `pidcore calibrate` will be there once "
                      "merged")
    except ImportError as exc:
        return None, f"{CALIBRATE_MODULE} cannot be imported: {exc}"
    missing = [name for name in REQUIRED if not hasattr(module, name)]
    if missing:
        return None, f"{CALIBRATE_MODULE} lacks {', '.join(missing)}"
    return module, ""


def fittable_names(api) -> list[str]:
    """Names the page offers to fit: the library's observation parameters (not the
    discrepancy hyperparameter, which is always fitted) and its named DEM parameters."""
    names = [n for n, spec in api.CATALOGUE.items() if getattr(spec, "kind", "") != "hyper"]
    dem = getattr(api, "dem_parameter_names", None)
    return sorted(names) + (list(dem()) if dem is not None else [])


def points_by_material(points: Sequence) -> dict[str, list]:
    """The measured points per particle material (sorted by name): the page calibrates one
    material at a time, as :func:`pidcore.calibrate.calibrate.base_specimen` requires."""
    out: dict[str, list] = {}
    for point in points:
        out.setdefault(str(point.material), []).append(point)
    return dict(sorted(out.items()))


def points_for_specimen(points: Sequence, specimen) -> tuple[list, str]:
    """:func:`pidcore.calibrate.data.points_for_specimen` (imported when called, as the rest
    of the library: :func:`calibration_api`)."""
    from ..calibrate.data import points_for_specimen as library_points_for_specimen

    return library_points_for_specimen(points, specimen)


def points_for_paper(points: Sequence) -> tuple[list, str]:
    """:func:`pidcore.calibrate.data.points_for_paper` with the page's way out in its note."""
    from ..calibrate.data import points_for_paper as library_points_for_paper

    return library_points_for_paper(points, hint="choose their specimen file above")


def specimen_label(specimen) -> str:
    """The name a calibration's result goes by: the specimen's, or the paper's coupon."""
    from ..specimen import PAPER_SPECIMEN_NAME

    return PAPER_SPECIMEN_NAME if specimen is None else specimen.name


def check_points(api, points: Sequence, specimen=None, fit: Sequence[str] = ()) -> None:
    """Raise the library's one-line error for points it would refuse (several materials, or
    points of particles not in the materials table without their specimen file), before a
    background run is started; a library without ``base_specimen`` checks in the run."""
    from ..constants import PARTICLE_MATERIALS
    from ..errors import ParameterError

    own = sorted({str(p.material) for p in points} - set(PARTICLE_MATERIALS))
    if own and specimen is None:  # the library's message names a command-line flag
        raise ParameterError(
            f"the paper's coupon holds acrylic or aluminium particles; the chosen points are "
            f"of {', '.join(own)} particles: choose their specimen file above")
    check = getattr(api, "base_specimen", None)
    if check is not None:
        check(list(points), specimen)
    needed = points_needed(fit)
    if len(points) < needed:  # the library's message names --discrepancy, not on this page
        raise ParameterError(points_needed_text(len(points), fit))


def points_needed(fit: Sequence[str]) -> int:
    """Measured load cases a calibration of ``fit`` needs on this page: one per parameter,
    and one for the model discrepancy, which the page always fits."""
    return len(set(fit)) + 1


#: The measured points' table on the page: field -> column head naming its unit. A field not
#: named here is not shown (a new field of MeasuredPoint once showed as its raw name, the SDC
#: bound as a dict of masses in kg with no unit). The measured SDC, its stderr and that
#: error's degrees of freedom by the names of the report and of
#: :meth:`pidcore.calibrate.Calibration.to_pandas` (this table said "SDC measured, Eq. 11",
#: "SDC stderr" and "SDC stderr degrees of freedom" for them).
POINT_COLUMNS = {
    "frequency_hz": "frequency [Hz]", "acceleration_g": "acceleration [g]",
    "fill_percent": PACKING_RATIO_COLUMN, "sdc": MEASURED_EQ11_COLUMN,
    "sdc_stderr": MEASURED_EQ11_STDERR_COLUMN, "sdc_stderr_dof": MEASURED_EQ11_DOF_COLUMN,
    "material": "material", "specimen": "specimen", "specimen_sha256": "specimen sha256",
    "sdc_bound": SDC_BOUND_COLUMN}


def points_table(points: Sequence) -> pd.DataFrame:
    """The measured points (:class:`pidcore.calibrate.MeasuredPoint`) as the page shows them:
    one row each, the columns of :data:`POINT_COLUMNS`; ``SDC bound [-]`` is the SDC above
    which the point would be refused (its specimen's, 2 pi where not known)."""
    import pandas as pd

    rows = [{**{name: getattr(p, name) for name in POINT_COLUMNS},
             "sdc_bound": float(p.sdc_bound.sdc)} for p in points]
    return pd.DataFrame(rows, columns=list(POINT_COLUMNS)).rename(columns=POINT_COLUMNS)


#: The page's one column of the measured SDC and its standard error, written by the one rule
#: of every page and report (:func:`pidcore.units.display_value_with_error`).
MEASURED_EQ11_WITH_ERROR_COLUMN = "SDC measured (Eq. 11) ± stderr [-]"


def points_display(points: Sequence) -> pd.DataFrame:
    """:func:`points_table` as the Calibrate page shows it: the SDC and its standard error in
    one text column as ``pidcore analyze`` and the other pages write them (``1.038 ± 0.024``);
    the grid wrote the two numbers apart at its own precision (``1.0378`` beside ``0.024``,
    ``0.6285`` beside ``0.00008``), digits the error does not support."""
    from ..units import display_value_with_error

    table = points_table(points)
    texts = [display_value_with_error(sdc, stderr) for sdc, stderr in
             zip(table[MEASURED_EQ11_COLUMN], table[MEASURED_EQ11_STDERR_COLUMN], strict=True)]
    at = table.columns.get_loc(MEASURED_EQ11_COLUMN)
    table = table.drop(columns=[MEASURED_EQ11_COLUMN, MEASURED_EQ11_STDERR_COLUMN])
    table.insert(at, MEASURED_EQ11_WITH_ERROR_COLUMN, texts)
    return table


def points_needed_text(n_points: int, fit: Sequence[str]) -> str:
    """Why ``n_points`` load cases are too few for ``fit``, in the page's terms."""
    return (f"{n_points} measured load case(s) cannot determine {', '.join(fit)} and the "
            f"model discrepancy (always fitted here): choose at least {points_needed(fit)} "
            "load cases or fit fewer parameters")


#: The library's words for the calibration's parameters (its keywords), and the page's for
#: the same thing; the rest as every page says it (:func:`pidcore.app.vocabulary.page_terms`).
#: The page fits the default priors and the parameters chosen in its form; it has no prior
#: input.
_PAGE_WORDS: tuple[tuple[str, str], ...] = (
    (r"\(give priors=(\S+)=LOW:HIGH\)",
     r"(the page fits the default prior; `pidcore calibrate --prior \1=LOW:HIGH` changes it)"),
    (r"\(priors=(\S+)=LOW:HIGH\)",
     r"(the page fits the default prior; `pidcore calibrate --prior \1=LOW:HIGH` widens it)"),
    (r"narrow the ranges of priors=", "narrow the prior ranges (`pidcore calibrate --prior`)"),
    (r"(?<![\w-])fit/priors: ", ""),
    (r"(?<![\w-])fit (\S+): ", r"parameter to fit \1: "),
    (r"(?<![\w-])fit: ", "parameters to fit: "),
    (r"design_size (\d+)", r"design points \1"),
    (r"design_size", "design points"),
    (r"\(specimen=FILE\)", "(choose their specimen file above)"),
    (r"\(pidcore specimen check\)", "(as `pidcore specimen check` lists them)"),
)


def page_words(text: str) -> str:
    """A library message or note in the page's terms: its fields, not the library's keywords
    nor the command line's flags.

    The calibration's parameters keep their names (:func:`fittable_names`): the page's
    'parameters to fit' offers them so, and ``baseline_loss_factor`` here is the specimen's
    fitted coupon loss factor, not the Analyse tab's per-file 'baseline loss factor [-]'
    column that :func:`pidcore.app.vocabulary.page_terms` names it as (the summary's
    table read "'baseline loss factor [-]'" beside "fixture_mass_kg", and an unknown
    parameter's error offered a name the field refuses).
    """
    import re

    from .vocabulary import page_terms

    for pattern, replacement in _PAGE_WORDS:
        text = re.sub(pattern, replacement, text)
    api, _ = calibration_api()
    # kept as written, as the user's own names are (pidcore.errors.outside_user_names)
    return page_terms(text, names=fittable_names(api) if api is not None else ())


class CalibrationCancelled(StopRequested):
    """Raised in the calibration's thread where it tells the page of its design or of a DEM
    run saved after a cancel (the library's own stop, :class:`~pidcore.interrupt.StopRequested`,
    comes sooner: within a fraction of a second while DEM runs go)."""


@dataclass
class CalibrationTask:
    """One calibration: its state (:data:`pidcore.constants.BACKGROUND_STATES`) and
    outputs."""

    fit: tuple[str, ...]
    n_points: int
    specimen: str = ""  # :func:`specimen_label` of the specimen calibrated
    state: BackgroundState = "running"
    started: float = field(default_factory=time.time)
    finished: float | None = None
    message: str = ""
    outputs: dict[str, bytes] = field(default_factory=dict)
    #: Its key in the store once saved there ("" : not saved).
    store_key: str = ""
    #: The DEM runs of its design (0 until the design is made), those the store held at the
    #: start, and those saved since: the page said only "N s elapsed" for many minutes.
    runs_total: int = 0
    runs_stored_before: int = 0
    runs_done: int = 0
    #: Set by :meth:`CalibrationRunner.cancel`.
    cancel_requested: bool = False
    #: The library's stop (``calibrate(stop=)``): set on a cancel or at the process's exit,
    #: it stops the running DEM runs within a fraction of a second.
    stop: threading.Event = field(default_factory=threading.Event, repr=False, compare=False)
    #: The calibration is being saved in the store: too late for a cancel.
    saving: bool = False
    #: Stopped by the app's exit, not by a Cancel: its journal entry is left for the restarted
    #: app to say (:func:`interrupted_calibrations`).
    stopped_at_exit: bool = False

    def elapsed_s(self) -> float:
        """Seconds since the start (to the end once finished)."""
        return (self.finished or time.time()) - self.started

    def design(self, keys: Sequence[str], store_path: str | Path) -> None:
        """Told the design's DEM run keys before any run starts (``calibrate(on_design=)``)."""
        from ..dem.persist import stored_keys

        unique = list(dict.fromkeys(keys))
        self.runs_stored_before = len(stored_keys(store_path, unique))
        self.runs_total = len(unique)
        if self.cancel_requested:
            raise CalibrationCancelled

    def run_done(self, key: str) -> None:
        """Told a DEM run's key as it is saved (``calibrate(on_run_done=)``); raises
        :class:`CalibrationCancelled` once a cancel is requested (the run stays saved)."""
        self.runs_done += 1
        if self.cancel_requested:
            raise CalibrationCancelled

    def progress_text(self) -> str:
        """``"3 of 12 DEM runs (2 from the store), 40 s elapsed, ETA 60 s"``; before the
        design is made ``"40 s elapsed"``. The ETA extrapolates the runs computed so far."""
        elapsed = self.elapsed_s()
        if self.runs_total <= 0:
            return f"{elapsed:.0f} s elapsed"
        done = self.runs_stored_before + self.runs_done
        stored = f" ({self.runs_stored_before} from the store)" if self.runs_stored_before \
            else ""
        left = self.runs_total - done
        eta = (f", ETA {elapsed * left / self.runs_done:.0f} s"
               if self.runs_done > 0 and left > 0 else "")
        return f"{done} of {self.runs_total} DEM runs{stored}, {elapsed:.0f} s elapsed{eta}"

    def cancelled_text(self, store_name: str) -> str:
        """What a cancel kept: the DEM runs computed and whether any was still to run (stopped
        and discarded). A cancel after the last run (while the posterior was sampled) said
        "the running ones were stopped" of runs that had all finished."""
        if self.runs_total <= 0:
            return (f"cancelled before its DEM runs started; {store_name} holds nothing "
                    "new of it")
        computed = f"{self.runs_done} DEM run(s) computed before the cancel are kept in " \
                   f"{store_name}"
        if self.runs_stored_before + self.runs_done < self.runs_total:
            return (f"{computed}; the running ones were stopped and nothing of them saved; "
                    "run the same calibration again to resume (stored runs are reused)")
        stored = f" ({self.runs_stored_before} from the store before)" \
            if self.runs_stored_before else ""
        return (f"every one of its {self.runs_total} DEM runs had finished{stored} and none "
                f"was running: {computed}, and the fit was stopped before a calibration was "
                "saved; run the same calibration again to fit on the stored runs (no DEM run "
                "is computed again)")


class CalibrationRunner:
    """One calibration at a time for one store, in a background thread."""

    def __init__(self, store_path: str | Path) -> None:
        from .jobs import JournalOwner

        self.store_path = Path(store_path)
        self._lock = threading.Lock()
        self.task: CalibrationTask | None = None
        self._thread: threading.Thread | None = None
        #: This runner in the calibration journal (:func:`interrupted_calibrations`).
        self.owner = JournalOwner.live_of_this_process()
        self._entry: dict = {}  # the running calibration's journal entry

    def start(self, api, points: Sequence, *, fit: Sequence[str], cells: int,
              design_size: int | None, specimen=None,
              notes: Sequence[str] = ()) -> CalibrationTask | None:
        """Start a calibration of ``specimen`` (None: the paper's coupon); None (nothing
        started) while one is running. Points the library refuses raise its error here
        (:func:`check_points`), not in the background. ``notes``: what the store held but
        the page left out (records saved as implausible, other specimens' tests), kept with
        the outputs' notes as ``pidcore calibrate --store`` keeps them."""
        check_points(api, points, specimen, fit)
        with self._lock:
            if self.task is not None and self.task.state == "running":
                return None
            task = self.task = CalibrationTask(tuple(fit), len(points),
                                               specimen_label(specimen))
            # kept beside the store while it runs: a restarted app says it was interrupted
            self._entry = {"specimen": task.specimen, "fit": list(task.fit),
                           "n_points": task.n_points, "cells": cells,
                           "design_size": design_size, "started": task.started,
                           "run_keys": []}
            _change_journal(self.store_path, self.owner, self._entry)
            _stop_at_exit_registered()
            _STARTED.add(self)
            self._thread = threading.Thread(
                target=self._run, args=(api, task, list(points), list(fit), cells,
                                        design_size, specimen, list(notes)),
                name="pidcore-calibration", daemon=True)
            self._thread.start()
        return task

    def cancel(self, *, at_exit: bool = False) -> bool:
        """Ask the running calibration to stop (True if one runs): its running DEM runs are
        stopped within a fraction of a second and discarded, every saved run is kept for a
        later calibration to reuse, and no calibration is saved. ``at_exit``: the app is
        stopping, no one cancelled: the restarted app says it was interrupted."""
        with self._lock:
            if self.task is None or self.task.state != "running" or self.task.saving:
                return False
            # a Cancel clicked before the exit's stop is the user's: nothing to say later
            self.task.stopped_at_exit = self.task.stopped_at_exit or (
                at_exit and not self.task.cancel_requested)
            self.task.cancel_requested = True
            self.task.stop.set()
            return True

    def stop_and_wait(self, timeout_s: float, *, at_exit: bool = False) -> None:
        """Cancel the running calibration and wait up to ``timeout_s`` for its thread to end
        (its DEM workers then are gone)."""
        self.cancel(at_exit=at_exit)
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout_s)

    def _run(self, api, task: CalibrationTask, points, fit, cells, design_size,
             specimen, notes: Sequence[str] = ()) -> None:
        from .kept_specimens import holding_kept_specimen

        # not in the job table: an uploaded specimen's kept file is held while it runs, so
        # `pidcore specimen kept --remove` leaves it for the page that names it
        with holding_kept_specimen(self.store_path, getattr(specimen, "hash", "")):
            self._run_calibration(api, task, points, fit, cells, design_size, specimen, notes)

    def _run_calibration(self, api, task: CalibrationTask, points, fit, cells, design_size,
                         specimen, notes: Sequence[str] = ()) -> None:
        from ..errors import PidcoreError

        # the paper's coupon is the library's default: no specimen argument for it
        given = {} if specimen is None else {"specimen": specimen}
        try:
            result = api.calibrate(
                points, fit=fit, store_path=self.store_path, cells=cells,
                design_size=design_size, progress=False,
                on_design=lambda keys: self._design(task, keys),
                on_run_done=task.run_done, stop=task.stop, **given)
            if notes:
                result.notes = [*notes, *result.notes]
            with tempfile.TemporaryDirectory(prefix="pidcore_calibration_") as folder:
                # the downloads say the notes as the page does ('parameters to fit', not
                # the library's priors=), as `pidcore calibrate --out` says its flags
                paths = api.write_outputs(result, folder, wording=page_words)
                outputs = {Path(p).name: Path(p).read_bytes() for p in paths}
            state, message = "done", f"{len(points)} load case(s), fitted {', '.join(fit)}"
            with self._lock:  # a cancel that came while the outputs were written wins
                if task.cancel_requested:
                    raise CalibrationCancelled
                task.saving = True  # from here on a cancel is refused: it is saved
            key, saved = _save(api, result, self.store_path)
            message += saved
        except StopRequested:
            outputs, state, key = {}, "cancelled", ""
            message = task.cancelled_text(self.store_path.name)
        except Exception as exc:  # noqa: BLE001 - shown on the page as the task's error
            # a library refusal is its one line (the class name is no news to a user); an
            # unexpected error keeps its name, without which "KeyError: 'x'" says nothing
            outputs, state, key = {}, "failed", ""
            message = page_words(str(exc)) if isinstance(exc, PidcoreError) \
                else f"{type(exc).__name__}: {exc}"
        with self._lock:
            task.outputs, task.state, task.message = outputs, state, message
            task.store_key, task.finished = key, time.time()
        if not task.stopped_at_exit:  # ended here and said here: nothing left to say later
            _change_journal(self.store_path, self.owner, None)

    def _design(self, task: CalibrationTask, keys: Sequence[str]) -> None:
        """``calibrate(on_design=)``: the design's run keys in the journal entry (what an
        interrupted calibration kept is counted from them), then the task told."""
        self._entry = {**self._entry, "run_keys": list(dict.fromkeys(keys))}
        _change_journal(self.store_path, self.owner, self._entry)
        task.design(keys, self.store_path)


#: The journal of a store's running calibrations: ``<store>`` + this suffix, beside the store
#: as the DEM jobs' (:data:`pidcore.app.jobs.JOURNAL_SUFFIX`), and changed under that one's
#: lock. A calibration lives in its server's memory: without it, one a stop of the app ended
#: vanished from the Calibrate page, though the DEM runs it saved are kept.
CALIBRATION_JOURNAL_SUFFIX = ".calibrations.json"
#: Layout version written into the calibration journal.
_CALIBRATION_JOURNAL_VERSION = 1


def calibration_journal_path(store_path: str | Path) -> Path:
    """The journal of a store's running calibrations: ``<store>.calibrations.json``."""
    from .jobs import journal_path

    return journal_path(store_path, CALIBRATION_JOURNAL_SUFFIX)


def _journal_calibrations(path: Path) -> list[tuple[dict, object]]:
    """The entries of a calibration journal with the owner each names (None: none); none
    where there is no journal or it cannot be read (it is rewritten by the next change): the
    DEM jobs' reader, whose refusals of a damaged journal (JSON nested past the stack
    included) hold for this one too."""
    from .jobs import _journal_entries

    entries, _ = _journal_entries(path, kind="calibrations",
                                  version=_CALIBRATION_JOURNAL_VERSION)
    return [(entry, owner) for entry, owner in entries if isinstance(entry, dict)]


def _change_journal(store_path: str | Path, owner: JournalOwner | None, entry: dict | None, *,
                    keep=lambda other: True) -> None:
    """Replace ``owner``'s entry of the store's calibration journal with ``entry`` (None:
    remove it; an owner of None: the entries naming none), keeping the others that ``keep``
    keeps; the file is removed once it holds
    none. A journal that cannot be changed costs the notice after a restart, never the
    calibration: nothing is raised."""
    import json

    from ..atomic_files import write_atomically
    from ..errors import PidcoreError
    from .jobs import exclusive_journal_lock

    path = calibration_journal_path(store_path)
    try:
        with exclusive_journal_lock(store_path):  # two servers on one store: one at a time
            others = [e for e, o in _journal_calibrations(path) if o != owner and keep(e)]
            if entry is not None:
                others.append({**entry, "owner": owner.document()})
            if others:
                write_atomically(path, json.dumps(
                    {"pidcore_calibrations_version": _CALIBRATION_JOURNAL_VERSION,
                     "calibrations": others}, indent=1))
            else:
                path.unlink(missing_ok=True)
    except (OSError, PidcoreError, TypeError, ValueError):
        pass


@dataclass(frozen=True)
class InterruptedCalibration:
    """A calibration that was running when its app server stopped (read from the store's
    calibration journal): no calibration was saved, the DEM runs it saved are kept."""

    specimen: str
    fit: tuple[str, ...]
    n_points: int
    cells: object
    design_size: object
    started: float
    runs_total: int
    runs_kept: int

    def text(self, store_name: str) -> str:
        """What the Calibrate page says of it."""
        when = time.strftime("%Y-%m-%d %H:%M", time.localtime(self.started))
        design = (f"{self.design_size} design points" if self.design_size
                  else "the default design")
        what = (f"The calibration of {self.specimen or 'the paper coupon'} "
                f"({', '.join(self.fit)}; {self.n_points} load case(s), {self.cells} cells per "
                f"DEM run, {design}) started {when} was interrupted by a stop of the app; no "
                "calibration was saved")
        if not self.runs_total:
            return f"{what}; it had started no DEM run."
        return (f"{what}. Its {self.runs_kept} finished DEM run(s) of {self.runs_total} are "
                f"kept in {store_name}: running the same calibration again reuses them and "
                f"computes the other {self.runs_total - self.runs_kept}.")


def interrupted_calibrations(store_path: str | Path) -> list[InterruptedCalibration]:
    """The calibrations of the store's journal whose app server stopped (or crashed) while
    they ran, oldest first; those of a server still running (this one's included) are not."""
    from ..dem.persist import stored_keys
    from ..errors import PidcoreError
    from .jobs import _still_runs

    found = []
    for entry, owner in _journal_calibrations(calibration_journal_path(store_path)):
        if _still_runs(owner):
            continue
        try:
            keys = [k for k in entry.get("run_keys") or () if isinstance(k, str)]
            kept = len(stored_keys(store_path, keys)) if keys and Path(store_path).is_file() \
                else 0
            started = float(entry.get("started"))
            found.append(InterruptedCalibration(
                str(entry.get("specimen") or ""), tuple(str(n) for n in entry.get("fit") or ()),
                int(entry.get("n_points") or 0), entry.get("cells"), entry.get("design_size"),
                started if math.isfinite(started) else 0.0, len(keys), kept))
        except (TypeError, ValueError, OverflowError, PidcoreError):
            continue  # a damaged entry (or store): dismissed with the others
    return sorted(found, key=lambda c: c.started)


def dismiss_interrupted_calibrations(store_path: str | Path) -> None:
    """Forget the interrupted calibrations of the store's journal (their runs stay stored);
    the running ones' entries are kept."""
    from .jobs import JournalOwner, _still_runs

    _change_journal(store_path, None, None,
                    keep=lambda entry: _still_runs(JournalOwner.from_document(
                        entry.get("owner"))))


def _save(api, result, store_path: Path) -> tuple[str, str]:
    """Save a finished calibration in the store (``api.save_calibration``:
    :func:`pidcore.calibrate.persist.save_calibration`); ``(key, words for the task's
    message)`` (``key`` "" where it was not saved: the outputs are still offered, and the
    message says so)."""
    from ..errors import PidcoreError

    save = getattr(api, "save_calibration", None)
    if save is None:
        return "", "; not saved in the store (this pidcore cannot): download calibration.json below"
    try:
        saved = save(result, store_path)
    except PidcoreError as exc:
        return "", f"; NOT saved in the store ({exc}): download calibration.json below"
    key, added = saved[0], saved[1]
    superseded = tuple(saved[2]) if len(saved) > 2 else ()
    if not added:
        return key, f"; the same result is in the store already as {key}"
    return key, (f"; saved in the store as {key}"
                 + (f" (the same fit was stored before as {'; '.join(superseded)}: kept as it "
                    "was, this one saved beside it)" if superseded else ""))


_RUNNERS: dict[str, CalibrationRunner] = {}
_RUNNERS_LOCK = threading.Lock()
#: Runners that started a calibration in this process (:func:`_stop_calibrations_at_exit`).
_STARTED: weakref.WeakSet[CalibrationRunner] = weakref.WeakSet()
_EXIT_HOOK_REGISTERED: list[bool] = []
#: Seconds the process's exit waits for a calibration to stop: its DEM workers end in a
#: fraction of one; a Numba compilation or a posterior sample under way ends first.
EXIT_STOP_WAIT_S = 30.0


def _stop_at_exit_registered() -> None:
    """Have the process's exit stop the calibrations still running (once per process).

    SIGTERM to the app (``pidcore app`` passes it on to Streamlit, whose handler stops the
    server, and the main thread returns) left the process running until the whole
    calibration had ended: concurrent.futures' exit hook joins every process pool, waiting
    for its pending DEM runs. This hook runs before that one (threading calls its exit hooks
    last-registered first, and concurrent.futures registers its own on import), sets each
    calibration's stop and waits for its thread: the thread stops its pool itself, the one
    place a pool is shut down (stopping it from here raced the thread's own shutdown and
    printed 'Bad file descriptor' at exit).
    """
    import concurrent.futures.process  # noqa: F401 - registers its exit hook first

    if not _EXIT_HOOK_REGISTERED:
        threading._register_atexit(_stop_calibrations_at_exit)  # noqa: SLF001 - as futures does
        _EXIT_HOOK_REGISTERED.append(True)


def _stop_calibrations_at_exit() -> None:
    runners = list(_STARTED)
    for runner in runners:  # every stop first: they end side by side
        runner.cancel(at_exit=True)
    for runner in runners:
        runner.stop_and_wait(EXIT_STOP_WAIT_S, at_exit=True)


def runner_for(store_path: str | Path) -> CalibrationRunner:
    """The process-wide calibration runner of a store."""
    key = str(Path(store_path).resolve())
    with _RUNNERS_LOCK:
        return _RUNNERS.setdefault(key, CalibrationRunner(key))


#: Environment variable naming the calibration.json the Compare page shows (optional).
CALIBRATION_ENV_VAR = "PIDCORE_CALIBRATION"
#: The bundled calibration of the paper's 12 measured points, relative to the working folder.
BUNDLED_CALIBRATION = Path("data_samples") / "paper_calibration" / "calibration.json"


def calibration_path(environ: Mapping[str, str] | None = None, *,
                     cwd: Path | None = None) -> Path | None:
    """``$PIDCORE_CALIBRATION``, else the bundled :data:`BUNDLED_CALIBRATION` if it exists in
    the working folder, else None."""
    from .stores import path_from_env_or_bundled

    return path_from_env_or_bundled(CALIBRATION_ENV_VAR, BUNDLED_CALIBRATION,
                                    environ=environ, cwd=cwd)


def calibration_digest(calibration) -> str:
    """A short digest of a calibration's content ("" for none): what cached views key on
    (a new calibration object is read on every script run)."""
    import hashlib

    if calibration is None:
        return ""
    return hashlib.sha256(repr(calibration).encode()).hexdigest()[:16]


#: Caption of the figure of a saved calibration on the Calibrate tab (after its key).
SAVED_FIGURE_CAPTION = ("calibrated SDC per load case with its 95 % band beside the SDC "
                        "measured there; a hollow point with a dashed band is uninformative "
                        "(0 .. 2 pi: it cannot test the model)")


def stored_calibration_label(calibration) -> str:
    """How the pages name a calibration saved in the app's store: its key, the specimen file
    it calibrated (by name and hash, as the pages label DEM runs, where its calibrated file
    records it: two files of one name read alike), what it fitted and when."""
    fitted = ", ".join(calibration.parameters)
    of = calibration.specimen_name or "the paper coupon"
    spec = calibration.calibrated_specimen()
    if spec is not None and spec.provenance is not None:
        from ..compare.specimens import specimen_label

        of = specimen_label(spec.provenance.calibrated_from_name,
                            spec.provenance.calibrated_from_sha256)
    return (f"this store's calibration {calibration.store_key} of "
            f"{of} ({fitted}; saved "
            f"{calibration.created_utc[:16].replace('T', ' ')} UTC)")


def default_calibration_index(usable: Sequence[tuple[object, str]], specimen_name: str,
                              specimen: object | None = None) -> int:
    """Which of ``usable`` ([(calibration, label)], newest first) the Report tab shows by
    default for a report of specimen ``specimen_name``: the first that speaks for it, as the
    Compare tab takes the first (a steel calibration saved last left the paper coupon's
    report without a calibrated column); 0 where none does (the report then says why).

    ``specimen``: the specimen file reported (:class:`pidcore.specimen.Specimen`), where the
    page knows it: then its hash decides as the report's columns do
    (:meth:`~pidcore.calibrate.prediction.Calibration.other_specimen_reason`), not its name
    alone, which an edited file keeps (the calibration of the earlier file was the default,
    and every row said "not compared")."""
    return next((i for i, (calibration, _) in enumerate(usable)
                 if calibration.speaks_for(specimen_name)
                 and (specimen is None or not calibration.other_specimen_reason(specimen))), 0)


#: Columns of :func:`saved_calibrations_table`: listing column -> name shown (units named).
SAVED_CALIBRATION_COLUMNS = {"key": "calibration", "specimen": "specimen", "fit": "fitted",
                             "n_points": "load cases [-]", "rms_in_sample": "in-sample RMS [-]",
                             "loo_rms": "leave-one-out RMS [-]",
                             "loo_coverage95": "inside 95 % band (LOO) [-]",
                             "loo_uninformative95": "uninformative 95 % band (LOO) [-]",
                             "created_utc": "saved [UTC]"}


@dataclass(frozen=True)
class StoreCalibrations:
    """The calibrations of the app's store as one page draw shows them (read once by
    :func:`read_store_calibrations`; the Compare, Report and Calibrate tabs all use it).

    Attributes
    ----------
    readable : list
        The calibrations that can be read, newest first.
    damaged : list of str
        One line per calibration that cannot be read (or the listing's own problem).
    listing : pandas.DataFrame or None
        :meth:`pidcore.store.Store.list_calibrations` as read (None: no store, or unreadable).
    """

    readable: list
    damaged: list[str]
    listing: object = None


def read_store_calibrations(store_path: str | Path) -> StoreCalibrations:
    """Every calibration of the store at ``store_path`` and its listing, each read once (no
    store yet: none). A store whose listing cannot be read gives none and says why in
    ``damaged``; one damaged calibration does not hide the others."""
    from ..calibrate.persist import readable_calibrations
    from ..errors import PidcoreError
    from ..store import Store

    path = Path(store_path)
    if not path.is_file():
        return StoreCalibrations([], [])
    try:
        listing = Store(path).list_calibrations()
        readable, damaged = readable_calibrations(path, listing=listing)
    except PidcoreError as exc:  # the store's listing itself cannot be read
        return StoreCalibrations([], [str(exc)])
    return StoreCalibrations(readable, damaged, listing)


def saved_calibrations_table(store_path: str | Path | None = None, *,
                             listing: pd.DataFrame | None = None) -> pd.DataFrame:
    """The Calibrate tab's table of the calibrations saved in the store, newest first
    (:meth:`pidcore.store.Store.list_calibrations` of ``store_path``, or that ``listing`` as
    already read; columns :data:`SAVED_CALIBRATION_COLUMNS`, a blank where a calibration has
    no leave-one-out)."""
    from ..store import Store

    if listing is None:
        listing = Store(store_path).list_calibrations()
    listing = listing.iloc[::-1]
    if "loo_coverage95" in listing.columns:
        # an entry of an older pidcore has no such field: it counted no fold apart (a
        # calibration without leave-one-out keeps its blank)
        import pandas as pd

        stated = (listing["loo_uninformative95"] if "loo_uninformative95" in listing.columns
                  else pd.Series(math.nan, index=listing.index))
        listing = listing.assign(loo_uninformative95=stated.where(
            stated.notna() | listing["loo_coverage95"].isna(), 0))
    shown = {c: n for c, n in SAVED_CALIBRATION_COLUMNS.items() if c in listing.columns}
    table = listing[list(shown)].rename(columns=shown).reset_index(drop=True)
    if "specimen" in shown and "specimen_hash" in listing.columns:
        # by name and hash, as the pages label DEM runs: calibrations of two files of one
        # name (an edited x.toml) read alike
        from ..compare.specimens import specimen_label

        table["specimen"] = [
            specimen_label(n, h) if isinstance(n, str) and isinstance(h, str) and h else n
            for n, h in zip(listing["specimen"], listing["specimen_hash"], strict=True)]
    table["saved [UTC]"] = table["saved [UTC]"].str[:19].str.replace("T", " ")
    # two calibrations of the same fit read alike though one ran 2 cells per DEM run and the
    # other 8: the cells its design ran, from its stored settings
    if "parameters_json" in listing.columns:
        table.insert(list(table.columns).index("fitted") + 1 if "fitted" in table.columns
                     else len(table.columns), CELLS_COLUMN,
                     [_stored_cells(p) for p in listing["parameters_json"]])
    table = table.astype(object).where(table.notna(), "")
    for column in ("load cases [-]", "inside 95 % band (LOO) [-]",  # counts, not 10.0
                   "uninformative 95 % band (LOO) [-]"):
        if column in table.columns:
            table[column] = [_count_cell(v) for v in table[column]]
    for column in ("in-sample RMS [-]", "leave-one-out RMS [-]"):
        # as the command, summary.md and the calibrated file write it (0.0812): a column
        # with a blank showed 0.08119027550622598 beside them
        if column in table.columns:
            table[column] = [_rms_cell(v) for v in table[column]]
    return table


def _rms_cell(value: object) -> object:
    """A stored RMS as :func:`pidcore.calibrate.outputs.rms_text` writes it; blank stays
    blank; anything else (a damaged record) shown as stored."""
    from ..calibrate.outputs import rms_text

    if isinstance(value, int | float) and not isinstance(value, bool) \
            and math.isfinite(value):
        return rms_text(float(value))
    return value


#: The saved calibrations table's column of the cells per DEM run of each calibration.
CELLS_COLUMN = "cells per DEM run [-]"


def _stored_cells(parameters_json: object) -> object:
    """The cells per DEM run a stored calibration's settings state; blank where they state
    none (a calibration stored without them, or a damaged record: the table still lists it)."""
    from ..calibrate.persist import stored_settings

    settings = stored_settings(parameters_json)
    return _count_cell(settings["cells"]) if "cells" in settings else ""


def _count_cell(value: object) -> object:
    """A stored count as a whole number; blank stays blank; anything else (a damaged record:
    text, inf, an array) is shown as stored, said, not raised: int() of it ended the page in a
    traceback."""
    if isinstance(value, str) and value == "":
        return ""
    if isinstance(value, int | float) and not isinstance(value, bool) \
            and math.isfinite(value) and value == int(value):
        return int(value)
    return f"{value!r} (not a count)"


def available_calibrations(task: CalibrationTask | None,
                           environ: Mapping[str, str] | None = None, *,
                           cwd: Path | None = None,
                           store_path: str | Path | None = None,
                           stored: StoreCalibrations | None = None,
                           ) -> list[tuple[object | None, str]]:
    """The calibrations the Compare and Report pages offer, as ``(calibration, label)``: those
    saved in the app's store (``store_path``), newest first, then the Calibrate page's finished
    calibration where the store did not take it, then :func:`calibration_path`'s file (the
    bundled paper calibration by default). A calibration of one specimen does not hide the
    other's bands: Compare takes the first that predicts a case. One that cannot be read comes
    last as ``(None, reason)``; ``[(None, reason)]`` when there is none or none can be read
    (the reason is shown). ``stored``: :func:`read_store_calibrations` of ``store_path`` as
    the caller read it already (read here otherwise)."""
    from ..calibrate.prediction import calibration_from_json, load_calibration
    from ..errors import PidcoreError

    found: list[tuple[object | None, str]] = []
    problems: list[str] = []
    if stored is None and store_path is not None:
        stored = read_store_calibrations(store_path)
    if stored is not None:
        found += [(c, stored_calibration_label(c)) for c in stored.readable]
        problems += [f"calibration of the store not shown: {problem}"
                     for problem in stored.damaged]
    saved = {c.store_key for c, _ in found}
    if task is not None and task.state == "done" and "calibration.json" in task.outputs \
            and task.store_key not in saved:
        try:
            found.append((calibration_from_json(task.outputs["calibration.json"],
                                                "calibration.json (Calibrate page)",
                                                specimen_name=task.specimen),
                          f"this store's calibration of {task.specimen or 'the paper coupon'} "
                          f"on the Calibrate page ({', '.join(task.fit)})"))
        except PidcoreError as exc:
            problems.append(f"calibration not shown: {page_words(str(exc))}")
    path = calibration_path(environ, cwd=cwd)
    if path is not None:
        label = ("the bundled calibration of the paper's 12 measured points"
                 if path.name == BUNDLED_CALIBRATION.name and path.parent.name ==
                 BUNDLED_CALIBRATION.parent.name else str(path))
        try:
            found.append((load_calibration(path), label))
        except PidcoreError as exc:
            problems.append(f"calibration not shown: {page_words(str(exc))}")
    if found:  # a calibration that cannot be read is still said, after those that can
        return found + [(None, problem) for problem in problems]
    if problems:
        return [(None, problems[0])]
    return [(None, "no calibration: run one on the Calibrate page (or set "
                   f"{CALIBRATION_ENV_VAR})")]


def calibration_read_notes(calibrations: Sequence[tuple[object | None, str]]) -> list[str]:
    """What reading the offered calibrations (:func:`available_calibrations`) did first, to
    be shown: the note of each whose folder a killed ``pidcore calibrate --out`` had left
    half-moved, the moves then finished (:attr:`pidcore.calibrate.Calibration.read_note`);
    the CLI says it on stderr, the page said nothing. Empty where nothing was done."""
    return [note for calibration, _ in calibrations if calibration is not None
            for note in [getattr(calibration, "read_note", "")] if note]


def remember_read_notes(kept: list[str], notes: Sequence[str]) -> list[str]:
    """Add each of ``notes`` not yet in ``kept`` (the session's, kept across reruns: the moves
    are finished once, by the read of one rerun, and the next reads have nothing to say) to
    it; returns ``kept``, the notes to show, oldest first. Fed by
    :func:`calibration_read_notes` and by the specimen files the pages load
    (:func:`pidcore.specimen.hearing_read_notes`)."""
    for note in notes:
        if note and note not in kept:
            kept.append(note)
    return kept
