"""Provenance of a report: software versions, parameters, seeds, inputs and their hashes."""

from __future__ import annotations

import hashlib
import platform
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from ..io import display_path, file_sha256

#: Packages whose versions every report lists.
PROVENANCE_PACKAGES: tuple[str, ...] = ("numpy", "scipy", "numba", "pandas", "matplotlib", "h5py")


def _package_version(name: str) -> str:
    try:
        return version(name)
    except PackageNotFoundError:
        return "not installed"


#: The comparison's parameters in words: keyword -> (words, value in words).
_COMPARISON_WORDS: dict[str, tuple[str, Callable[[object], str]]] = {
    "frequency_rtol": ("frequency tolerance", lambda v: f"{float(v) * 100:g} %"),
    "acceleration_rtol": ("acceleration tolerance", lambda v: f"{float(v) * 100:g} %"),
    "fill_atol_percent": ("fill tolerance", lambda v: f"{float(v):g} percentage points"),
    "pool": ("DEM settings and specimens pooled", lambda v: "yes" if v else "no"),
}


def parameter_in_words(name: str, value: object) -> str:
    """A report parameter as a reader of the report says it: ``"structure mass 22.2 g"``,
    not the keyword ``structure_mass_kg=0.0222`` (the analysis settings in the words and
    units of the notes and the settings table:
    :func:`pidcore.compare.settings_columns.setting_in_words`);
    one that differs between files as ``"vibrometer delay 0 µs (a.csv), 50 µs (b.csv)"``."""
    from ..compare.settings_columns import setting_in_words

    def said(v: object) -> tuple[str, str]:
        if name in _COMPARISON_WORDS:
            label, shown = _COMPARISON_WORDS[name]
            return label, shown(v)
        return setting_in_words(name, v)

    if isinstance(value, Mapping):
        values = [(display_path(str(file)), said(v)) for file, v in value.items()]
        label = values[0][1][0] if values else said(None)[0]
        return f"{label} " + ", ".join(f"{words[1]} ({file})" for file, words in values)
    return " ".join(said(value))


@dataclass(frozen=True)
class Provenance:
    """Everything needed to reproduce a report.

    Attributes
    ----------
    versions : mapping
        ``{"pidcore": ..., "python": ..., "numpy": ..., ...}``.
    parameters : mapping
        Analysis and comparison parameters (keyword -> value, SI, units in the name; a
        mapping file -> value for one that differs between the files); :meth:`lines` says
        them in words (:func:`parameter_in_words`).
    seeds : tuple of int
        Random seeds of the DEM runs in the report.
    inputs : tuple of (str, str)
        Input file names and their SHA-256.
    stores : tuple of (str, str)
        Store paths and their SHA-256 (at the time the report was made).
    created_utc : str
        ISO 8601 time stamp, UTC.
    specimens : tuple of (str, str)
        The specimens whose DEM runs the report compares: a label (name, and where it was read
        from) and its SHA-256 (:attr:`pidcore.specimen.Specimen.hash`).
    notes : tuple of str
        Records left out and why, and other remarks.
    calibrations : tuple of (str, str, str)
        The calibration whose columns the report holds: where it was read from (a
        calibration.json, or a store and its key), the SHA-256 of its ``calibration.json``
        text, and its calibrated specimen's name and hash with the file it was calibrated
        from (:func:`calibration_provenance`).
    case_sheets : tuple of (str, str, str)
        The load-case PDF sheets written with the report (``pidcore report --case-sheets``):
        the file's path in the report folder, its title (the load case) and its SHA-256.
    """

    versions: Mapping[str, str]
    parameters: Mapping[str, object] = field(default_factory=dict)
    seeds: tuple[int, ...] = ()
    inputs: tuple[tuple[str, str], ...] = ()
    stores: tuple[tuple[str, str], ...] = ()
    created_utc: str = ""
    notes: tuple[str, ...] = ()
    specimens: tuple[tuple[str, str], ...] = ()
    calibrations: tuple[tuple[str, str, str], ...] = ()
    case_sheets: tuple[tuple[str, str, str], ...] = ()

    def lines(self) -> list[str]:
        """The provenance as plain text lines (the footer of every format)."""
        out = [f"created (UTC): {self.created_utc}",
               "software: " + ", ".join(f"{k} {v}" for k, v in self.versions.items())]
        if self.parameters:
            out.append("parameters: " + "; ".join(parameter_in_words(k, v)
                                                  for k, v in self.parameters.items()))
        out.append("seeds: " + (", ".join(str(s) for s in self.seeds) or "none"))
        for name, digest in self.specimens:
            out.append(f"specimen: {name} sha256 {digest}")
        for name, digest, specimen in self.calibrations:
            out.append(f"calibration: {name} sha256 {digest}; {specimen}")
        for name, digest in self.stores:
            out.append(f"store: {name} sha256 {digest}")
        for name, digest in self.inputs:
            out.append(f"input: {name} sha256 {digest}")
        for name, title, digest in self.case_sheets:
            out.append(f"case sheet: {name} ({title}) sha256 {digest}")
        out.extend(f"note: {n}" for n in self.notes)
        return out

    def to_dict(self) -> dict[str, object]:
        """JSON-safe dict of every field (tuples as lists)."""
        return {"versions": dict(self.versions), "parameters": dict(self.parameters),
                "seeds": list(self.seeds), "inputs": [list(i) for i in self.inputs],
                "stores": [list(s) for s in self.stores], "created_utc": self.created_utc,
                "notes": list(self.notes), "specimens": [list(s) for s in self.specimens],
                "calibrations": [list(c) for c in self.calibrations],
                "case_sheets": [list(c) for c in self.case_sheets]}


def collect_provenance(*, parameters: Mapping[str, object] | None = None,
                       seeds: Iterable[int] = (), inputs: Iterable[str | Path] = (),
                       input_hashes: Mapping[str, str] | None = None,
                       stores: Iterable[str | Path] = (), notes: Iterable[str] = (),
                       created_utc: datetime | None = None,
                       specimens: Iterable[tuple[str, str]] = (),
                       calibrations: Iterable[tuple[str, str, str]] = (),
                       case_sheets: Iterable[tuple[str, str, bytes]] = ()) -> Provenance:
    """Collect versions, hashes and a time stamp into a :class:`Provenance`.

    Parameters
    ----------
    parameters : mapping, optional
        Parameters to list.
    seeds : iterable of int
        DEM seeds (duplicates removed, sorted).
    inputs : iterable of path
        Input files; hashed here unless ``input_hashes`` already has their SHA-256.
    input_hashes : mapping, optional
        Known SHA-256 per input path (as text), e.g. from :attr:`Measurement.sha256`.
    stores : iterable of path
        Store files, hashed here.
    notes : iterable of str
    created_utc : datetime, optional
        Time stamp (default: now).
    specimens : iterable of (str, str)
        (label, SHA-256) of each specimen compared.
    calibrations : iterable of (str, str, str)
        The calibration of the calibrated columns (:func:`calibration_provenance`).
    case_sheets : iterable of (str, str, bytes)
        (path in the report folder, title, PDF bytes) of each load-case sheet written with
        the report; its bytes are hashed here.
    """
    from .. import __version__

    versions = {"pidcore": __version__, "python": platform.python_version()}
    versions.update({name: _package_version(name) for name in PROVENANCE_PACKAGES})
    input_hashes = dict(input_hashes or {})
    hashed_inputs = []
    for path in inputs:
        digest = input_hashes.get(str(path)) or file_sha256(path)
        hashed_inputs.append((display_path(Path(path).name), digest))
    # display_path: a store or note naming a file that is not UTF-8 failed the report's
    # write (UnicodeEncodeError: surrogates not allowed) after its analyses were saved
    hashed_stores = tuple((display_path(p), file_sha256(p))
                          for p in dict.fromkeys(map(str, stores)))
    stamp = (created_utc or datetime.now(UTC)).astimezone(UTC)
    return Provenance(versions=versions, parameters=dict(parameters or {}),
                      seeds=tuple(sorted({int(s) for s in seeds})), inputs=tuple(hashed_inputs),
                      stores=hashed_stores, created_utc=stamp.isoformat(timespec="seconds"),
                      notes=tuple(map(display_path, notes)),
                      specimens=tuple((display_path(n), h) for n, h in specimens),
                      calibrations=tuple((display_path(n), h, display_path(c))
                                         for n, h, c in calibrations),
                      case_sheets=tuple((display_path(n), display_path(t),
                                         hashlib.sha256(pdf).hexdigest())
                                        for n, t, pdf in case_sheets))


def calibration_provenance(calibration) -> list[tuple[str, str, str]]:
    """(where, SHA-256, specimen) of the calibration a report's calibrated columns come from
    (:class:`pidcore.calibrate.prediction.Calibration`; None: none): where it was read from
    (the calibration.json, or the store and key), the SHA-256 of its calibration.json text,
    and its calibrated specimen's name and hash with the file it was calibrated from
    (``[provenance]``), in words. A report named no calibration: two calibrations of one name, or
    of two files of one name, gave the same footer."""
    if calibration is None:
        return []
    if calibration.document_text:
        digest = hashlib.sha256(calibration.document_text.encode("utf-8")).hexdigest()
    else:
        digest = file_sha256(calibration.path)
    where = calibration_source(calibration)
    specimen = calibration.calibrated_specimen()
    if specimen is None:
        said = "calibrated specimen unknown (no calibrated_specimen.toml beside it)"
    else:
        said = f"calibrated specimen {specimen.name} sha256 {specimen.hash}"
        source = specimen.provenance
        if source is not None:
            said += (f", calibrated from {source.calibrated_from_name} sha256 "
                     f"{source.calibrated_from_sha256}")
    return [(where, digest, said)]


def calibration_source(calibration) -> str:
    """Where a calibration (:class:`pidcore.calibrate.prediction.Calibration`) was read from,
    as a report names it: its calibration.json, or its store and key."""
    if not calibration.store_key:
        return f"{calibration.path}"
    return (f"{str(calibration.path).removesuffix(':' + calibration.store_key)} key "
            f"{calibration.store_key}")
