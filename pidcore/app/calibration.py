"""The calibration page's boundary to :mod:`pidcore.calibrate` (written on another branch).

The page calls only :func:`calibration_api`; while the library is missing it shows why.
"""

from __future__ import annotations

import importlib
import importlib.util


def calibration_api() -> tuple[object | None, str]:
    """``(module, "")`` when :mod:`pidcore.calibrate` is importable, else ``(None, reason)``."""
    if importlib.util.find_spec("pidcore.calibrate") is None:
        return None, ("pidcore.calibrate is not part of this installation yet (it is being "
                      "written on the `calibrate` branch); use `pidcore calibrate` once merged")
    try:
        return importlib.import_module("pidcore.calibrate"), ""
    except ImportError as exc:
        return None, f"pidcore.calibrate cannot be imported: {exc}"
