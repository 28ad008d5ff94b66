"""Calibrations in the HDF5 store: saved by ``pidcore calibrate`` and the app, read back by
reports and the app (which then survive a restart and travel with the store's DEM runs).

* :func:`calibration_key`: what a calibration is called in the store (the same calibration made
  again gets the same key and is not stored twice): its ``calibration.json`` and the
  calibrated specimen it writes, so that a fit whose calibrated file today's pidcore writes
  otherwise (``[provenance]`` added) is saved again rather than "stored already" with the
  earlier text;
* :func:`save_calibration`: a :class:`~pidcore.calibrate.calibrate.CalibrationResult` into a
  store: its whole ``calibration.json`` and calibrated specimen file, and a listing record;
  :class:`SavedCalibration` says what became of it, and which earlier entries of the same fit
  hold another calibrated specimen file (kept as they were: the store never loses data);
* :func:`stored_calibrations`: every calibration of a store, newest first, as
  :class:`~pidcore.calibrate.prediction.Calibration`;
* :func:`readable_calibrations`: those that can be read, and what is wrong with the others;
* :func:`stored_calibration`: one of them, by key (a store holding one needs none);
* :func:`calibration_design_runs`: which stored DEM runs are a calibration's design runs (inputs
  of its fit, kept apart from a report's predictions), each with every calibration fitted on it;
* :func:`missing_design_runs`: the calibrations of a store whose design runs it no longer holds
  (``pidcore store verify``);
* :func:`is_store_file`: whether a ``--calibration`` path names a store rather than a JSON file;
* :func:`stored_settings`: the settings (cells, seed, ...) a calibration's listing record states.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

from .. import defaults
from ..errors import ParameterError
from .outputs import document_json, specimen_text
from .prediction import Calibration, calibration_from_json

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

    from ..loadcase import LoadCase
    from .calibrate import CalibrationResult

#: Fields of calibration.json that describe how a calibration was made, not what it is: the
#: wall time, how many runs came from the cache, the path of the store that cached them.
_BOOKKEEPING = ("wall_s", "runs")
#: Units of the fields a calibration.json states since 2026-12 that follow from its keyed
#: rows (the verdicts and their counts): left out of its key, as the fields themselves.
_DERIVED_UNITS = ("inside95", "coverage95", "uninformative95", "loo_coverage95",
                  "loo_uninformative95")
_KEY_PREFIX = "cal_"


def calibration_key(document: dict, calibrated_specimen_text: str | None = None) -> str:
    """``"cal_"`` and 16 hex digits of SHA-256 of ``document`` (a calibration.json) without
    its bookkeeping (wall time, cached-run counts, the caching store's path), and of
    ``calibrated_specimen_text``, the canonical text of the calibrated specimen
    (:attr:`pidcore.specimen.Specimen.text`: its values, name, description and
    ``[provenance]``).

    The document alone does not say what the calibrated file holds (its ``[provenance]``,
    and, before the document named them, the starting specimen's name and hash), so two
    files of the same numbers, or a fit saved before today's pidcore added a table to the
    file, had one key and the second got the first's file. Without
    ``calibrated_specimen_text`` the key is that of the document alone, as calibrations were
    keyed before (:func:`save_calibration` finds those by it). The file's comment header
    (the starting file's path, the intervals in words) is not in the key: the same fit from
    another folder is the same calibration."""
    # its "specimen" names (start and calibrated file, by name and hash) are in the
    # calibrated specimen's text below: left out here, the JSON's key is the one a pidcore
    # that did not write them gave the same fit, so save_calibration still finds that entry
    # loo_uninformative95 follows from the loo rows and the specimen, both keyed: left out,
    # a fit saved before it existed keeps its key
    # so do the in-sample counts and each row's verdict (inside95), written since: they
    # follow from the keyed rows and the specimen
    what = {k: v for k, v in document.items()
            if k not in (*_BOOKKEEPING, "specimen", "loo_uninformative95", "coverage95",
                         "uninformative95")}
    for rows in ("predictions", "loo"):
        if isinstance(what.get(rows), list):
            what[rows] = [{k: v for k, v in r.items() if k != "inside95"}
                          if isinstance(r, dict) else r for r in what[rows]]
    if isinstance(what.get("units"), dict):  # and the units of those derived fields
        what["units"] = {k: v for k, v in what["units"].items() if k not in _DERIVED_UNITS}
    settings = dict(what.get("settings") or {})
    settings.pop("store", None)
    # where its tests were read (paths, a table's sha256, the analyses' keys): the measured
    # values themselves are in the rows keyed above, and the same fit of a table moved to
    # another folder, or saved before these were recorded, is the same calibration
    settings.pop("measured", None)
    what["settings"] = settings
    text = json.dumps(json.loads(document_json(what)), sort_keys=True, separators=(",", ":"))
    if calibrated_specimen_text is not None:
        # a separator no JSON text holds: the document's end cannot pass for the specimen's
        text += "\x00" + calibrated_specimen_text
    return _KEY_PREFIX + hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def measured_record(measured: Sequence[dict]) -> dict[str, str]:
    """The listing record's ``measured_source`` (each table's or store's path, ``"; "``
    between them) and ``measured_sha256`` (each table's sha256, "" for a store) of
    calibration.json's ``settings.measured``
    (:func:`pidcore.calibrate.data.measured_provenance`)."""
    return {"measured_source": "; ".join(str(e.get("source", "")) for e in measured),
            "measured_sha256": "; ".join(str(e.get("sha256", "")) for e in measured)}


class SavedCalibration(NamedTuple):
    """What :func:`save_calibration` did.

    Attributes
    ----------
    key : str
        The store key of the calibration (the new entry, or the one stored before).
    added : bool
        False where the same calibration, with the same calibrated specimen, was stored
        before (kept as it was).
    superseded : tuple of str
        Earlier entries of the same fit (the same calibration.json) whose calibrated specimen
        file differs from the one saved now, each ``"cal_... (why)"``: written by an earlier
        pidcore (no ``[provenance]``). They are kept as they were; this one is saved beside
        them, and readers taking the newest (the app) take it.
    """

    key: str
    added: bool
    superseded: tuple[str, ...] = ()


def _record(result) -> tuple[dict, dict]:
    """The listing record of a calibration and its units."""
    units = result.units()
    calibrated = result.calibrated_specimen()
    record: dict = {"specimen": result.specimen.name, "specimen_hash": result.specimen.hash,
                    # the file it wrote, by name and hash: the starting file's name and hash
                    # alone did not say which calibrated file the entry holds
                    "calibrated_specimen": calibrated.name,
                    "calibrated_specimen_hash": calibrated.hash,
                    # the key of its calibration.json alone: the same fit saved with another
                    # calibrated file (by an earlier or later pidcore) is found by it
                    "document_key": calibration_key(result.full_document()),
                    "fit": ",".join(result.settings["fit"]),
                    # the tests it was fitted to, as a measurement's record names its file
                    # (source, sha256); the analyses' keys are in its settings
                    **measured_record(result.settings.get("measured") or []),
                    "method_used": str(result.settings.get("method_used", "")),
                    "n_points": len(result.predictions), "rms_in_sample": result.rms,
                    "loo_rms": result.loo_rms, "loo_coverage95": result.loo_coverage,
                    # the folds counted apart from loo_coverage95's (absent in an entry of
                    # an older pidcore: none were)
                    "loo_uninformative95": result.loo_uninformative}
    out_units = {"n_points": "count", "rms_in_sample": "-", "loo_rms": "-",
                 "loo_coverage95": "count", "loo_uninformative95": "count"}
    for name, p in result.parameters.items():
        for stat in ("median", "low95", "high95"):
            record[f"{name}_{stat}"] = p[stat]
            out_units[f"{name}_{stat}"] = units.get(name, "-")
    return record, out_units


def save_calibration(result: CalibrationResult, store_path: str | os.PathLike
                     ) -> SavedCalibration:
    """Save ``result`` (:class:`~pidcore.calibrate.calibrate.CalibrationResult`) into the store
    at ``store_path`` in one transaction; returns a :class:`SavedCalibration` (``added``
    False: the same calibration, with the same calibrated specimen, was stored before and is
    kept as it was).

    An entry of the same fit whose calibrated specimen differs (saved by a pidcore that wrote
    the file otherwise, e.g. before ``[provenance]`` existed) is not "the same": this one is
    saved beside it under its own key, and :attr:`SavedCalibration.superseded` names it. It
    is kept, not replaced: the store never loses what it held, and a report made from it can
    still be read back."""
    from ..store import Store

    document = result.full_document()
    record, units = _record(result)
    calibrated_text = result.calibrated_specimen().text
    key = calibration_key(document, calibrated_text)
    store = Store(store_path)
    same_fit = _same_fit(store, record["document_key"]) if Path(store_path).is_file() else []
    superseded = []
    for earlier, earlier_text in same_fit:
        if earlier != key and earlier_text == calibrated_text:
            return SavedCalibration(earlier, False)  # stored before under another key
        if earlier != key:
            superseded.append(f"{earlier} ({_difference(earlier_text, calibrated_text)})")
    key, added = store.add_calibration(
        key, record, document=document_json(document),
        specimen_toml=specimen_text(result), units=units,
        parameters={"settings": result.settings})
    return SavedCalibration(key, added, tuple(superseded) if added else ())


def _same_fit(store, document_key: str) -> list[tuple[str, str | None]]:
    """The calibrations of ``store`` of the fit ``document_key`` (:func:`calibration_key` of
    the calibration.json alone: the key of one saved before the calibrated specimen entered
    it, or its ``document_key``), each with the canonical text of its calibrated specimen
    (None where that file cannot be read)."""
    from ..errors import PidcoreError
    from ..specimen import Specimen
    from ..store import calibration_texts

    listing = store.list_calibrations()
    if listing.empty:
        return []
    named = listing["document_key"] if "document_key" in listing.columns \
        else [None] * len(listing)
    out = []
    for key, of_document in zip(listing["key"], named, strict=True):
        if key != document_key and of_document != document_key:
            continue
        try:
            _, text = calibration_texts(store.get_calibration(key))
            out.append((key, Specimen.from_text(text, source=f"{store.path}:{key}").text))
        except PidcoreError:
            out.append((key, None))
    return out


def _difference(earlier: str | None, now: str) -> str:
    """Why an earlier calibrated specimen of the same fit is not the one saved now, in words."""
    if earlier is None:
        return "its calibrated specimen file cannot be read"
    if "[provenance]" in now and "[provenance]" not in earlier:
        return ("its calibrated specimen file, written by an earlier pidcore, lacks the "
                "[provenance] of the file it was calibrated from")
    return "its calibrated specimen file differs from the one written now"


def is_store_file(path: str | os.PathLike) -> bool:
    """Whether ``path`` is a file that starts with HDF5's signature (a store), not JSON."""
    path = Path(path)
    if not path.is_file():
        return False
    from ..io import HDF5_SIGNATURE

    with open(path, "rb") as handle:
        return handle.read(len(HDF5_SIGNATURE)) == HDF5_SIGNATURE


def _calibration(store, key: str) -> Calibration:
    from ..errors import PidcoreError
    from ..store import calibration_texts

    entry = store.get_calibration(key)
    try:
        document, specimen = calibration_texts(entry)
    except PidcoreError as exc:
        raise ParameterError(f"{store.path}: {exc}") from None
    calibration = calibration_from_json(document, f"{store.path}:{key}")
    return Calibration(path=calibration.path, parameters=calibration.parameters,
                       predictions=calibration.predictions,
                       specimen_name=str(entry.record.get("specimen") or ""),
                       specimen_text=specimen, document_text=document, store_key=key,
                       created_utc=str(entry.attrs.get("created_utc", "")))


def _calibrations(store_path: str | os.PathLike,
                  problems: list[str] | None, listing=None) -> list[Calibration]:
    """Every calibration of ``store_path``, newest first (no store yet: none). A damaged one
    raises, or, given ``problems``, is left out with its one line appended there.
    ``listing``: the store's :meth:`~pidcore.store.Store.list_calibrations` as the caller
    read it already (read here otherwise)."""
    from ..errors import PidcoreError
    from ..store import Store

    path = Path(store_path)
    if not path.is_file():
        return []
    store = Store(path)
    found: list[Calibration] = []
    if listing is None:
        listing = store.list_calibrations()
    for key in reversed(list(listing["key"])):
        try:
            found.append(_calibration(store, key))
        except PidcoreError as exc:
            if problems is None:
                raise
            problems.append(str(exc))
    return found


def stored_calibrations(store_path: str | os.PathLike) -> list[Calibration]:
    """Every calibration stored in ``store_path``, newest first (none: an empty list; no
    store yet: an empty list); a damaged one raises."""
    return _calibrations(store_path, None)


def readable_calibrations(store_path: str | os.PathLike, *, listing: pd.DataFrame | None = None,
                          ) -> tuple[list[Calibration], list[str]]:
    """Every calibration of ``store_path`` that can be read, newest first, and a one-line
    problem per one that cannot (a damaged entry): one damaged calibration does not hide the
    store's others, as :func:`stored_calibrations` (which raises on the first) would.
    ``listing``: the store's calibration listing as the caller read it already."""
    problems: list[str] = []
    return _calibrations(store_path, problems, listing), problems


def stored_calibration(store_path: str | os.PathLike, key: str | None = None) -> Calibration:
    """The calibration ``key`` of the store at ``store_path``; without a key, the store's only
    one. Raises :class:`ParameterError` (one line naming the store) where there is none, the
    key is not stored, or several are stored and no key says which."""
    from ..store import Store

    path = Path(store_path)
    store = Store(path)
    listing = store.list_calibrations()
    keys = list(listing["key"])
    if key is not None:
        if key not in keys:
            raise ParameterError(f"{path}: no calibration {key!r} in this store (it holds "
                                 f"{_keys_text(listing)})")
        return _calibration(store, key)
    if not keys:
        raise ParameterError(f"{path}: this store holds no calibration (calibrate "
                             f"with store_path={str(path)!r} to save one there, or give a "
                             "calibration.json)")
    if len(keys) > 1:
        raise ParameterError(f"{path}: this store holds {len(keys)} calibrations; choose one "
                             f"with key=KEY: {_keys_text(listing)}")
    return _calibration(store, keys[0])


def _keys_text(listing) -> str:
    """``"cal_... (specimen, fitted 'a,b'; 2026-11-30T17:02)"`` per calibration, newest
    first. The fitted names are quoted: they are the calibration's, and a front-end must not
    read a fitted ``baseline_loss_factor`` as its own option of that name."""
    if listing.empty:
        return "none"
    from ..specimen import hashed_name

    rows = listing.iloc[::-1]

    def written(r) -> str:
        # the same fit saved with another calibrated file (one stored before [provenance])
        # read alike but for the time: the file each holds tells them apart
        name, sha = r.get("calibrated_specimen"), r.get("calibrated_specimen_hash")
        if not isinstance(name, str) or not isinstance(sha, str) or not sha:
            return ""
        return f"; calibrated file {hashed_name(name, sha)}"

    return "; ".join(f"{r['key']} ({r.get('specimen', '')}, fitted '{r.get('fit', '')}'; "
                     f"{str(r['created_utc'])[:16]}{written(r)})" for _, r in rows.iterrows())


def stored_settings(parameters_json: object) -> dict:
    """The settings a stored calibration's listing record states (its ``parameters_json``'s
    ``"settings"``: cells, seed, fit, ...); ``{}`` where it states none (stored without them)
    or the record is damaged: the caller says what then lacks, it is no error here."""
    try:
        settings = json.loads(str(parameters_json or "{}"))["settings"]
    except (KeyError, TypeError, ValueError):
        return {}
    return settings if isinstance(settings, dict) else {}


def calibration_design_runs(runs: pd.DataFrame | None,
                            store_paths: Sequence[str | os.PathLike | None], *,
                            variants: bool = False) -> dict[str, tuple[str, ...]]:
    """The DEM runs of ``runs`` (a :func:`pidcore.store.listing.list_dem_runs` listing) that
    are the design runs of a calibration saved in one of ``store_paths``: run key -> the keys
    of every such calibration (oldest first). Two calibrations fitted on the same runs (other
    ``--fit``, the runs reused from the store) share them: each is a dependent of the run, and
    mapping a run to one calibration removed the run under the other without a word.

    A calibration runs its start specimen (fitting DEM parameters, variants of it with other
    hashes instead, which reports leave out as other specimens, and the start only where a
    design point is it) at its measured load cases with its own cells per run and seed,
    usually fewer cells than a prediction would use: such a run is an input of the fit, not a
    prediction of the specimen. A run is one where its specimen's hash is the calibration's,
    its cells and seed are the calibration's settings, and its load case (frequency,
    acceleration, fill, material) is one the calibration predicts: the inputs its cache key
    is made of, read from what the store holds of both, so the calibrations saved before
    this existed are recognised too; and, the calibration's design fitting DEM parameters,
    one of its points is the start itself (:func:`pidcore.calibrate.runner.is_design_start`,
    the start rebuilt from the run's stored specimen): a run of the file by another fit
    (``--fit fixture_mass_kg,baseline_loss_factor``) at the same cases is not its run. A
    calibration whose calibration.json states no readable design may have run either.

    With ``variants``, also the runs of its variants of the start specimen (their stored
    :func:`~pidcore.compare.specimens.run_origin` names the start's hash) that its design
    made (their stated values are one of the design points its calibration.json states):
    inputs of the fit too, which what removes runs must know of, while reports leave them
    out already as other specimens. Another calibration's variants of the same file (another
    design, or a fit of observation parameters alone, which makes none) are not its runs.
    """
    found: dict[str, tuple[str, ...]] = {}
    for path in dict.fromkeys(Path(p) for p in store_paths if p is not None):
        for design in _design_runs_by_case(runs, path, variants=variants):
            for key in design.runs:
                # a calibration met twice (one store given under two names) is one dependent
                found[key] = tuple(dict.fromkeys((*found.get(key, ()), design.calibration)))
    return found


class DesignCase(NamedTuple):
    """One load case a stored calibration was fitted at: ``calibration`` (its key), the
    ``case`` (a :class:`~pidcore.loadcase.LoadCase`), ``specimen_hash``, ``cells`` and
    ``seed`` its runs were made with, and the keys of those of ``runs`` that are its design
    runs there (empty: none is stored)."""

    calibration: str
    case: LoadCase
    specimen_hash: str
    cells: int
    seed: int
    runs: tuple[str, ...]


def missing_design_runs(path: str | os.PathLike) -> list[str]:
    """A line per load case at which a calibration stored at ``path`` was fitted while the
    store holds none of its design runs there (``pidcore store verify``): such a run removed
    without the calibration left a fit whose inputs are gone, and reports could no longer
    tell them apart from predictions. Runs and calibrations are read as
    :func:`calibration_design_runs` reads them (one rule), variants of the start included;
    a calibration stating no cells or seed, or unreadable, is not checked here (the entry's
    own check says what is wrong with it)."""
    from ..store import Store

    path = Path(path)
    runs = Store(path).list_dem_runs()
    lines = []
    for design in _design_runs_by_case(runs, path, variants=True, every_calibration=True):
        if design.runs:
            continue
        case = design.case
        lines.append(
            f"{path}:/calibrations/{design.calibration}: fitted on the DEM run(s) "
            f"{case.key}_seed{design.seed}_cells{design.cells}_* of specimen "
            f"{design.specimen_hash[:6]} ({case.frequency_hz:g} Hz, {case.acceleration_g:g} g, "
            f"fill {case.fill_percent:g} %), none of which is stored (a design run removed "
            "without its calibration)")
    return lines


def asked_steady_cycles(value: object,
                        block_cycles: object = defaults.DEM_STEADY_BLOCK_CYCLES) -> int:
    """Steady cycles a run measures, from what a calibration's settings or a run's
    ``config_steady_cycles`` state (None, "" or absent: the automatic count of its blocks,
    :func:`pidcore.defaults.dem_automatic_steady_cycles`). A run asked for the automatic
    count by number is stored as unstated (:func:`pidcore.compare.align.stored_parameters`),
    so a calibration of ``steady_cycles=80`` would not find its own runs by the value."""
    block = block_cycles if isinstance(block_cycles, int) and not isinstance(
        block_cycles, bool) else defaults.DEM_STEADY_BLOCK_CYCLES
    if value is None or value == "":
        return defaults.dem_automatic_steady_cycles(block)
    try:
        return int(value)
    except (TypeError, ValueError):
        return defaults.dem_automatic_steady_cycles(block)


def _design_runs_by_case(runs: pd.DataFrame | None, path: Path, *, variants: bool,
                         every_calibration: bool = False) -> list[DesignCase]:
    """Each load case of each calibration stored at ``path`` with its design runs among
    ``runs`` (the rule :func:`calibration_design_runs` states). Without
    ``every_calibration`` nothing where ``runs`` holds none (reports of a store of runs
    only)."""
    import numpy as np
    import pandas as pd

    from ..compare.align import stored_parameters
    from ..compare.specimens import CalibrationVariant, run_origins
    from ..store import Store

    needed = {"case_key", "specimen_sha256", "cells_simulated", "seed", "frequency_hz",
              "acceleration_g", "fill_percent", "material"}
    if runs is None or runs.empty or not needed <= set(runs.columns):
        if not every_calibration:
            return []
        runs = pd.DataFrame(columns=sorted(needed))
    if not path.is_file():
        return []
    listing = Store(path).list_calibrations()
    if listing.empty:
        return []
    origins = runs["specimen_sha256"]
    kinds = pd.Series([None] * len(runs), index=runs.index, dtype=object)
    if variants and not runs.empty:
        kinds = run_origins(runs)
        origins = pd.Series([o.of_sha256 if isinstance(o, CalibrationVariant) else own
                             for o, own in zip(kinds, runs["specimen_sha256"], strict=True)],
                            index=runs.index)
    calibrations, _ = readable_calibrations(path, listing=listing)  # damaged: said elsewhere
    params = pd.Series([stored_parameters(p) or {} for p in (
        runs["parameters_json"] if "parameters_json" in runs.columns else [None] * len(runs))],
        index=runs.index, dtype=object)
    steady_of_runs = pd.Series(
        [asked_steady_cycles(p.get("config_steady_cycles"),
                             p.get("config_block_cycles", defaults.DEM_STEADY_BLOCK_CYCLES))
         for p in params], index=runs.index, dtype=object)
    by_key = {c.store_key: c for c in calibrations}
    found = []
    for _, record in listing.iterrows():
        calibration = by_key.get(record["key"])
        settings = stored_settings(record.get("parameters_json"))
        try:
            cells, seed = int(settings["cells"]), int(settings["seed"])
        except (KeyError, TypeError, ValueError):
            continue  # a calibration that does not state its runs' settings
        if calibration is None:
            continue
        sha = str(record.get("specimen_hash") or "")
        same = runs[(origins == sha) & (runs["cells_simulated"] == cells)
                    & (runs["seed"] == seed)
                    # a run of the case along x, or with other steady cycles, made after the
                    # fit, was claimed as its design run: remove refused it, verify missed
                    # the real one gone
                    & (steady_of_runs == asked_steady_cycles(settings.get("steady_cycles")))]
        if not same.empty:
            # a variant of the start is an input of this fit only where its design made it:
            # a fit of observation parameters alone (no design) was named a dependent of
            # another fit's variants, and store remove refused them for it
            design = _design_of(calibration)
            # so is a run of the start itself: a design of variants alone claimed another
            # fit's run of the file (remove named it a dependent, verify took it for its own)
            plain = [i for i in same.index if not isinstance(kinds[i], CalibrationVariant)]
            start_made = design is None or not plain or _made_start(
                [params[i] for i in plain], sha, design)
            made = [(start_made if not isinstance(kinds[i], CalibrationVariant)
                     else design is None or _made_by(kinds[i], params[i], design))
                    for i in same.index]
            same = same[made]
        for p in calibration.predictions:
            case = p.load_case
            # the calibration made these runs from the cases it predicts: the same
            # numbers, so only float noise of a round trip through the store is allowed
            keys: tuple[str, ...] = ()
            if not same.empty:
                at = (np.isclose(same["frequency_hz"], case.frequency_hz, rtol=1e-9)
                      & np.isclose(same["acceleration_g"], case.acceleration_g, rtol=1e-9)
                      & np.isclose(same["fill_percent"], case.fill_percent, rtol=1e-9)
                      & (same["material"] == case.material)
                      & (same["direction"] == case.direction if "direction" in same.columns
                         else True))
                keys = tuple(str(k) for k in same.loc[at, "case_key"])
            found.append(DesignCase(str(record["key"]), case, sha, cells, seed, keys))
    return found


def _design_of(calibration: Calibration) -> tuple[list[str], list[list[float]]] | None:
    """The fitted DEM parameters' names and design points its calibration.json states
    (``design``: no names where it fitted none); None where the document states no readable
    design: then any run of its start or of a variant of it may be its run, as one cannot
    tell (a removal is refused rather than the fit's inputs lost)."""
    try:
        design = json.loads(calibration.document_text)["design"]
        names = [str(n) for n in design["names"]]
        points = [[float(v) for v in point] for point in design["points"]]
    except (KeyError, TypeError, ValueError):
        return None
    return names, points


def _made_by(origin, parameters: dict, design: tuple[list[str], list[list[float]]]) -> bool:
    """Whether a variant run (its :class:`~pidcore.compare.specimens.CalibrationVariant`
    ``origin`` and stored ``parameters``) is one of ``design``'s points
    (:func:`pidcore.calibrate.runner.is_design_variant`)."""
    from ..errors import PidcoreError
    from ..specimen import Specimen
    from .runner import is_design_variant

    names, points = design
    if is_design_variant(origin.values, names, points):
        return True
    text = parameters.get("specimen_text")
    if not names or not isinstance(text, str) or not text:
        return False
    try:  # its own specimen says which static friction a pair was raised to
        variant = Specimen.from_text(text, source="stored run")
    except PidcoreError:
        return False
    return is_design_variant(origin.values, names, points, variant)


def _made_start(parameters: Sequence[dict], sha: str,
                design: tuple[list[str], list[list[float]]]) -> bool:
    """Whether ``design`` ran its start specimen (hash ``sha``) itself
    (:func:`pidcore.calibrate.runner.is_design_start`), the start rebuilt from the first of
    its runs' stored ``parameters`` whose specimen text reads back as that hash; True where
    none does (which it ran cannot be told: a removal is refused rather than its inputs
    lost)."""
    from ..errors import PidcoreError
    from ..specimen import Specimen
    from .runner import is_design_start

    for params in parameters:
        text = params.get("specimen_text")
        if not isinstance(text, str) or not text:
            continue
        try:
            start = Specimen.from_text(text, source="stored run")
        except PidcoreError:
            continue
        if start.hash == sha:
            return is_design_start(start, *design)
    return True
