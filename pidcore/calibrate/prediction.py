"""Read a ``calibration.json`` written by ``pidcore calibrate`` and look up the calibrated DEM's
prediction (Eq. 11 SDC of the virtual shaker, 95 % band) for one load case.

Reports and the app use it to show the calibrated prediction beside the raw DEM and the
measurement; it reads only the file (no DEM, no store).
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path

from .. import defaults
from ..compare.align import Tolerances
from ..errors import ParameterError
from ..loadcase import LoadCase

_REQUIRED = ("frequency_hz", "acceleration_g", "fill_percent", "predicted", "low95", "high95")


@dataclass(frozen=True)
class CalibratedPrediction:
    """The calibrated DEM's prediction at one load case.

    Attributes
    ----------
    load_case : LoadCase
        Load case the calibration predicted (its measured point).
    sdc : float
        Posterior-predictive median of the Eq. 11 SDC [-].
    low95, high95 : float
        Bounds of the 95 % posterior-predictive band [-].
    measured : float
        SDC the calibration was fitted to at this load case [-] (NaN if not stated).
    """

    load_case: LoadCase
    sdc: float
    low95: float
    high95: float
    measured: float = math.nan

    def contains(self, sdc: float) -> bool:
        """True if ``sdc`` lies inside the 95 % band (bounds included); False for NaN."""
        return bool(self.low95 <= sdc <= self.high95)


@dataclass(frozen=True)
class Calibration:
    """A calibration read from ``calibration.json``.

    Attributes
    ----------
    path : Path
        The file read.
    parameters : dict
        ``{name: {"median", "low95", "high95"}}`` of the fitted parameters.
    predictions : tuple of CalibratedPrediction
        In-sample posterior-predictive predictions, one per measured load case.
    specimen_path : Path or None
        The calibrated specimen file beside it, if present.
    """

    path: Path
    parameters: dict
    predictions: tuple[CalibratedPrediction, ...]
    specimen_path: Path | None = None

    def lookup(self, case: LoadCase, *,
               tolerances: Tolerances | None = None) -> CalibratedPrediction | None:
        """The prediction at ``case`` (same material; frequency, acceleration and fill within
        ``tolerances``, default the report's ``COMPARE_*``), or None if it predicts none."""
        tolerances = tolerances or Tolerances()
        hits = [p for p in self.predictions
                if p.load_case.material == case.material and tolerances.matches(case,
                                                                                p.load_case)]
        if not hits:
            return None
        # the nearest in frequency, then acceleration, then fill, if tolerances admit several
        return min(hits, key=lambda p: (abs(p.load_case.frequency_hz - case.frequency_hz),
                                        abs(p.load_case.acceleration_g - case.acceleration_g),
                                        abs(p.load_case.fill_percent - case.fill_percent)))


def _number(value, what: str, path: Path) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not math.isfinite(value):
        raise ParameterError(f"{path}: {what} must be a finite number, got {value!r}")
    return float(value)


def load_calibration(path: str | os.PathLike) -> Calibration:
    """Read and check a ``calibration.json`` of ``pidcore calibrate``.

    Raises
    ------
    ParameterError
        One line naming the file and what was expected: missing, not JSON, not a
        calibration (no ``parameters``/``predictions``), or a prediction with a missing or
        non-finite field or ``low95 > high95``.
    """
    path = Path(path)
    if not path.is_file():
        raise ParameterError(f"{path}: no such calibration file (expected the calibration.json "
                             "written by pidcore calibrate --out)")
    calibration = calibration_from_json(path.read_bytes(), path)
    specimen = path.parent / "calibrated_specimen.toml"
    return Calibration(path=path, parameters=calibration.parameters,
                       predictions=calibration.predictions,
                       specimen_path=specimen if specimen.is_file() else None)


def calibration_from_json(text: str | bytes, source: str | os.PathLike) -> Calibration:
    """A calibration from the text of a ``calibration.json`` (``source`` names it in errors
    and in :attr:`Calibration.path`); checked as :func:`load_calibration` does."""
    path = Path(source)
    try:
        doc = json.loads(text)
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ParameterError(f"{path}: not a calibration.json of pidcore calibrate "
                             f"(not JSON: {exc})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("predictions"), list) \
            or not isinstance(doc.get("parameters"), dict) or not doc["predictions"]:
        raise ParameterError(f"{path}: not a calibration.json of pidcore calibrate (expected "
                             "'parameters' and a non-empty 'predictions' list)")
    predictions = []
    for i, row in enumerate(doc["predictions"]):
        if not isinstance(row, dict) or any(k not in row for k in _REQUIRED):
            raise ParameterError(f"{path}: predictions[{i}] must have {', '.join(_REQUIRED)}")
        f, a, fill, sdc, low, high = (_number(row[k], f"predictions[{i}].{k}", path)
                                      for k in _REQUIRED)
        if not low <= sdc <= high:
            raise ParameterError(f"{path}: predictions[{i}]: expected low95 <= predicted <= "
                                 f"high95, got {low} / {sdc} / {high}")
        material = row.get("material") or defaults.COMPARE_DEFAULT_MATERIAL
        measured = row.get("measured")
        measured = float(measured) if isinstance(measured, (int, float)) else math.nan
        predictions.append(CalibratedPrediction(LoadCase(f, a, fill, str(material)), sdc, low,
                                                high, measured))
    return Calibration(path=path, parameters=doc["parameters"], predictions=tuple(predictions))
