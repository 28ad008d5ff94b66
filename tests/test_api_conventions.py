"""Conventions of the public API (python-control style): documented, strict about keywords."""

from __future__ import annotations

import importlib
import inspect

import numpy as np
import pytest

PUBLIC_MODULES = ("pidcore.io", "pidcore.signal", "pidcore.store", "pidcore.dem",
                  "pidcore.model", "pidcore.compare", "pidcore.report", "pidcore.loadcase",
                  "pidcore.loop", "pidcore.calibrate")


def _public_names() -> list[str]:
    names = []
    for name in PUBLIC_MODULES:
        module = importlib.import_module(name)
        for attr in getattr(module, "__all__", ()):
            obj = getattr(module, attr)
            if inspect.isfunction(obj) or inspect.isclass(obj):
                names.append(f"{name}:{attr}")
    return names


# parametrised by name only: ids must be identical in every pytest-xdist worker
@pytest.mark.parametrize("qualname", _public_names())
def test_public_functions_and_classes_have_docstrings(qualname):
    module, attr = qualname.split(":")
    assert inspect.getdoc(getattr(importlib.import_module(module), attr)), \
        f"{qualname} has no docstring"


def test_every_public_module_declares_its_api():
    for name in PUBLIC_MODULES:
        assert getattr(importlib.import_module(name), "__all__", None), name


def test_unknown_keyword_arguments_are_rejected():
    from pidcore.dem import DemConfig
    from pidcore.io import read_measurement
    from pidcore.model import SdcModel, load_paper_table3
    from pidcore.signal import analyze_power

    t = np.arange(2000) / 1000.0
    with pytest.raises(TypeError):
        analyze_power(np.sin(t), np.cos(t), 1000.0, velocity_dealy_s=1e-3)  # misspelt
    with pytest.raises(TypeError):
        read_measurement("x.csv", samplerate=10.0)
    with pytest.raises(TypeError):
        DemConfig(cell=4)
    with pytest.raises(TypeError):
        SdcModel.from_table(load_paper_table3(), log_freq=True)
    from pidcore.calibrate import calibrate, load_calibration

    with pytest.raises(TypeError):  # refused at the call, before any DEM run
        calibrate([], fit=["fixture_mass_kg"], store_path="unused.h5", cell=4)
    with pytest.raises(TypeError):
        load_calibration("calibration.json", tolerance=0.1)
