"""What a store holds, and removing records with what depends on them (``pidcore store``).

* :func:`existing_store`: a store that must exist (a mistyped path is refused, not read as an
  empty store);
* :func:`store_contents`: one table per section, the keys that name each record and what a
  user tells records apart by, each column with its unit in :data:`COLUMN_HEADERS`;
* :func:`remove_records`: named records removed in one commit, with the analyses of a removed
  measurement; a DEM run a stored calibration was fitted on is refused unless
  ``with_dependents=True`` removes the calibration too. :class:`Removal` says what went.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from ..errors import StoreError
from .listing import latest_per_measurement
from .store import Store

#: Sections as the command line names them -> as the store's groups do.
SECTIONS = {"measurements": "measurements", "analyses": "analyses", "dem-runs": "dem_runs",
            "calibrations": "calibrations"}
#: One record of each section, in words.
_WHAT = {"measurements": "measurement", "analyses": "analysis", "dem_runs": "DEM run",
         "calibrations": "calibration"}
#: Column of :func:`store_contents` -> its header with its unit, as reports name theirs.
COLUMN_HEADERS = {
    "key": "key", "file": "file", "file_format": "format", "n_channels": "channels [-]",
    "n_analyses": "analyses [-]", "imported_utc": "imported [UTC]",
    "measurement_key": "measurement", "created_utc": "saved [UTC]",
    "frequency_hz": "frequency [Hz]", "acceleration_g": "acceleration [g]",
    "fill_percent": "fill [%]", "material": "material", "specimen": "specimen",
    "sdc": "SDC [-]", "reports": "of its measurement", "cells": "cells [-]", "seed": "seed [-]",
    "design_of": "design run of", "fit": "fitted", "n_points": "points [-]",
    "loo_rms": "LOO RMS [-]", "measured_source": "fitted to", "measured_sha256": "its sha256",
}
_COLUMNS = {
    "measurements": ["key", "file", "file_format", "n_channels", "n_analyses",
                     "imported_utc"],
    "analyses": ["key", "measurement_key", "file", "frequency_hz", "acceleration_g",
                 "fill_percent", "material", "specimen", "sdc", "reports", "created_utc"],
    "dem_runs": ["key", "specimen", "frequency_hz", "acceleration_g", "fill_percent",
                 "material", "cells", "seed", "sdc", "design_of", "created_utc"],
    # the tests a calibration was fitted to (a table and its sha256, or a store), as the
    # README's listing promises
    "calibrations": ["key", "specimen", "fit", "n_points", "loo_rms", "measured_source",
                     "measured_sha256", "created_utc"],
}


def existing_store(path: str | os.PathLike) -> Store:
    """The store at ``path``, which must exist: a store that is only read or changed here
    is never created, and a mistyped path read as an empty store said it held nothing.

    Raises
    ------
    StoreError
        No file at ``path`` ("store not found"), or one that is no readable pidcore store.
    """
    path = Path(path)
    if not path.exists():
        raise StoreError(f"{path}: store not found")
    return Store(path)


def verify_with_progress(store: Store, *, progress: bool, label: str) -> list[str]:
    """:meth:`Store.verify`, with a bar ``label`` over the store's entries on stderr where
    ``progress``: every array is read, a minute or more for years of tests."""
    if not progress:
        return store.verify()
    from tqdm import tqdm

    with tqdm(unit="entry", desc=label, leave=False, dynamic_ncols=True) as bar:
        def advance(done: int, total: int) -> None:
            bar.total = total
            bar.update(done - bar.n)

        return store.verify(progress=advance)


def _column(frame: pd.DataFrame, name: str, default: object = "") -> pd.Series:
    return frame[name] if name in frame.columns else pd.Series([default] * len(frame),
                                                               index=frame.index)


def _specimens(names: pd.Series, hashes: pd.Series) -> list[str]:
    # the one labelling of a recorded name and hash (a name already hashed kept as it is)
    from ..specimen import tested_label

    return [tested_label(str(n or ""), h if isinstance(h, str) else "")
            for n, h in zip(names.fillna(""), hashes, strict=True)]


def store_contents(path: str | os.PathLike,
                   sections: Iterable[str] = SECTIONS) -> dict[str, pd.DataFrame]:
    """What the store at ``path`` holds: ``{section: table}`` for each of ``sections``
    (command-line names, :data:`SECTIONS`), one row per record, oldest first (DEM runs by
    key), the columns of :data:`COLUMN_HEADERS` in SI-named fields (``frequency_hz``).

    Analyses: ``reports`` is ``newest`` for the newest analysis of its measurement, the one
    ``pidcore report --store`` and ``calibrate --store`` take (the one rule of
    :func:`pidcore.store.listing.latest_per_measurement`), else ``superseded``. DEM runs:
    ``design_of`` names every calibration whose fit it is an input of, ``", "``-separated
    (:func:`pidcore.calibrate.persist.calibration_design_runs`).

    Raises
    ------
    StoreError
        The store does not exist or cannot be read; a section of another name.
    """
    store = existing_store(path)
    wanted = list(sections)
    unknown = [s for s in wanted if s not in SECTIONS]
    if unknown:
        raise StoreError(f"section {unknown[0]!r}: expected one of {', '.join(SECTIONS)}")
    out: dict[str, pd.DataFrame] = {}
    for section in wanted:
        name = SECTIONS[section]
        table = _contents(store, name)
        if "design_of" in table.columns:
            table["design_of"] = [", ".join(keys) for keys in table["design_of"]]
        out[section] = table.reindex(columns=_COLUMNS[name]).reset_index(drop=True)
    return out


def _contents(store: Store, section: str) -> pd.DataFrame:
    if section == "measurements":
        frame = store.list_measurements()
        analyses = store.list_analyses()
        counts = analyses["measurement_key"].value_counts() if not analyses.empty else {}
        frame["file"] = [Path(str(s)).name for s in frame["source"]]
        frame["n_analyses"] = [int(counts.get(k, 0)) for k in frame["key"]]
        return frame
    if section == "analyses":
        from ..specimen import MEASURED_SHA256_FIELD

        frame = store.list_analyses()
        newest = set(latest_per_measurement(frame)["key"])
        frame["file"] = [Path(str(s)).name for s in frame["source"]]
        frame["reports"] = ["newest" if k in newest else "superseded" for k in frame["key"]]
        # two edited files of one name are two specimens whose tests are never pooled: the
        # listing tells them apart as the DEM runs' and calibrations' listings do
        frame["specimen"] = _specimens(_column(frame, "specimen"),
                                       _column(frame, MEASURED_SHA256_FIELD))
        return frame
    if section == "dem_runs":
        from ..calibrate.persist import calibration_design_runs

        frame = store.list_dem_runs().rename(columns={"case_key": "key"})
        design = calibration_design_runs(frame.rename(columns={"key": "case_key"}),
                                         [store.path], variants=True)
        frame["specimen"] = _specimens(_column(frame, "specimen_name"),
                                       _column(frame, "specimen_sha256"))
        frame["cells"] = _column(frame, "cells_simulated", None)
        # every calibration fitted on the run (a tuple; store_contents writes them as text)
        frame["design_of"] = [design.get(k, ()) for k in frame["key"]]
        return frame
    frame = store.list_calibrations()
    frame["specimen"] = _specimens(_column(frame, "specimen"), _column(frame, "specimen_hash"))
    return frame


@dataclass(frozen=True)
class RemovedRecord:
    """One record :func:`remove_records` removed (or would remove): its ``section`` (the
    store's group), ``key``, ``label`` (its file, specimen or load case, for people) and
    ``because``: "" for a record named, else why it went with one (``"an analysis of
    measurement 0a1b..."``)."""

    section: str
    key: str
    label: str
    because: str = ""

    @property
    def what(self) -> str:
        """The record in words: ``"DEM run"``."""
        return _WHAT[self.section]

    def to_dict(self) -> dict:
        """JSON-safe: ``section``, ``key``, ``label``, ``because`` (None for one named)."""
        return {"section": self.section, "key": self.key, "label": self.label,
                "because": self.because or None}


@dataclass(frozen=True)
class Removal:
    """What :func:`remove_records` did: ``store``; ``records`` removed (with ``dry_run``:
    those that would be); ``notes``: what changes for what is left (a measurement's earlier
    analysis that reports now take); ``unnamed_sha256``: the sha256s no record names any
    more (a specimen file the app keeps beside the store for them is unused from now on)."""

    store: Path
    records: tuple[RemovedRecord, ...]
    dry_run: bool
    notes: tuple[str, ...] = ()
    unnamed_sha256: tuple[str, ...] = field(default=())

    def to_dict(self) -> dict:
        """JSON-safe: ``store``, ``dry_run``, ``removed`` (each record's section, key, label
        and why it went), ``notes``, ``unnamed_sha256`` (``pidcore store remove --json``)."""
        return {"store": str(self.store), "dry_run": self.dry_run,
                "removed": [r.to_dict() for r in self.records], "notes": list(self.notes),
                "unnamed_sha256": list(self.unnamed_sha256)}


def _removed_before_commit() -> None:
    """Called inside the removal's transaction after the entries are deleted from the
    working copy, before the commit; a test's hook to interrupt it there."""


def remove_records(path: str | os.PathLike, keys: Sequence[str], *,
                   with_dependents: bool = False, dry_run: bool = False) -> Removal:
    """Remove the records ``keys`` of the store at ``path`` in one commit (the store's
    :meth:`~pidcore.store.Store.transaction`: an exception or Ctrl-C commits nothing and the
    file stays as it was; the commit replaces it whole).

    A key names a record of any section; ``SECTION/KEY`` (``dem_runs/f50Hz_...``, as
    ``pidcore specimen kept`` names records) one of a section. A removed measurement takes
    its analyses with it (an analysis of no stored measurement is damage ``verify`` finds).
    A DEM run that is a design run of a stored calibration (an input of its fit,
    :func:`pidcore.calibrate.persist.calibration_design_runs`) is refused unless the
    calibration is named too, or ``with_dependents`` removes it as well. ``dry_run``: what
    would be removed, the store only read. The file keeps its size (HDF5 does not give back
    the space of removed groups).

    Raises
    ------
    StoreError
        The store does not exist, cannot be read or written (read-only, locked by another
        writer past its wait), a key that names no record or records of two sections, or a
        record another needs; nothing is removed.
    """
    store = existing_store(path)
    if not keys:
        raise StoreError(f"{store.path}: no record named; expected the keys of the records "
                         "to remove (`pidcore store list` lists them)")
    if dry_run:
        records, notes = _plan(store, keys, with_dependents=with_dependents)
        return Removal(store.path, records, True, notes)
    store.check_writable()
    with store.transaction():
        # under the write lock: nothing is saved between the check of what needs a record
        # and its removal; the listings read the working copy
        records, notes = _plan(store, keys, with_dependents=with_dependents)
        named_before = store.sha256_references()
        store.remove_entries((r.section, r.key) for r in records)
        named_after = store.sha256_references()
        _removed_before_commit()
    unnamed = tuple(sorted(set(named_before) - set(named_after)))
    return Removal(store.path, records, False, notes, unnamed)


def _plan(store: Store, keys: Sequence[str], *,
          with_dependents: bool) -> tuple[tuple[RemovedRecord, ...], tuple[str, ...]]:
    """The records removing ``keys`` removes (named first, then what goes with them) and the
    notes on what is left; refuses as :func:`remove_records` says."""
    listings = {section: _contents(store, section) for section in _WHAT}
    labels = {section: dict(zip(frame["key"], _labels(section, frame), strict=True))
              for section, frame in listings.items()}
    named: dict[tuple[str, str], None] = {}
    for key in keys:
        named[_resolve(store, key, labels)] = None
    chosen: dict[tuple[str, str], str] = dict.fromkeys(named, "")
    analyses = listings["analyses"]
    for section, key in list(named):
        if section == "measurements":
            for analysis in analyses.loc[analyses["measurement_key"] == key, "key"]:
                chosen.setdefault(("analyses", analysis), f"an analysis of measurement {key}")
    runs = listings["dem_runs"]
    for section, key in list(named):
        if section != "dem_runs":
            continue
        # every calibration fitted on the run: one left behind names a run that is gone
        left = [c for c in runs.loc[runs["key"] == key, "design_of"].iloc[0]
                if ("calibrations", c) not in chosen]
        if left and not with_dependents:
            several = len(left) > 1
            raise StoreError(
                f"{store.path}: DEM run {key} is a design run of calibration"
                f"{'s' if several else ''} {', '.join(left)} (an input of "
                f"{'their fits' if several else 'its fit'}, which reports tell apart from "
                f"predictions by it); nothing was removed (name "
                f"{'them' if several else 'the calibration'} too, or with_dependents=True "
                f"removes {'them' if several else 'it'} with the run)")
        for calibration in left:
            chosen[("calibrations", calibration)] = f"fitted on DEM run {key}"
    records = tuple(RemovedRecord(section, key, labels[section][key], because)
                    for (section, key), because in chosen.items())
    return records, _notes(analyses, {(s, k) for s, k in chosen})


def _labels(section: str, frame: pd.DataFrame) -> list[str]:
    """What a user tells each record of ``frame`` by, beside its key."""
    if section in ("measurements", "analyses"):
        return [str(f) for f in frame["file"]]
    if section == "dem_runs":
        return [f"{s or 'unnamed specimen'}, {f:g} Hz, {a:g} g, fill {p:g} %"
                for s, f, a, p in zip(frame["specimen"],
                                      pd.to_numeric(_column(frame, "frequency_hz"), "coerce"),
                                      pd.to_numeric(_column(frame, "acceleration_g"), "coerce"),
                                      pd.to_numeric(_column(frame, "fill_percent"), "coerce"),
                                      strict=True)]
    return [f"{s}, fitted '{f}'" for s, f in zip(frame["specimen"], _column(frame, "fit"),
                                                   strict=True)]


def _resolve(store: Store, key: str, labels: dict[str, dict[str, str]]) -> tuple[str, str]:
    """``(section, key)`` of the record ``key`` (or ``SECTION/KEY``) names."""
    section, slash, bare = key.partition("/")
    if slash:
        group = SECTIONS.get(section, section)
        if group in labels and bare in labels[group]:
            return group, bare
    found = [(s, key) for s, keyed in labels.items() if key in keyed]
    if len(found) == 1:
        return found[0]
    if len(found) > 1:
        raise StoreError(f"{store.path}: {key!r} names records of "
                         f"{' and '.join(s for s, _ in found)}; nothing was removed (name one "
                         f"as {found[0][0]}/{key})")
    raise StoreError(f"{store.path}: no record {key!r} in this store; nothing was removed "
                     "(`pidcore store list` lists the keys of its records)")


def _notes(analyses: pd.DataFrame, chosen: set[tuple[str, str]]) -> tuple[str, ...]:
    """A measurement whose newest analysis is removed while an earlier one stays: reports
    take the earlier one from now on, which is said."""
    if analyses.empty:
        return ()
    gone = analyses["key"].isin([k for s, k in chosen if s == "analyses"])
    before = set(latest_per_measurement(analyses)["key"])
    left = analyses[~gone]
    notes = []
    for _, row in latest_per_measurement(left).iterrows():
        if row["key"] not in before:
            notes.append(f"measurement {row['measurement_key']} ({row['file']}): its analysis "
                         f"{row['key']} (saved {str(row['created_utc'])[:19]}) is now its "
                         "newest, the one reports and calibrations of the store take")
    return tuple(notes)
