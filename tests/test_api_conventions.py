"""Conventions of the public API (python-control style): documented, strict about keywords."""

from __future__ import annotations

import importlib
import inspect
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

PUBLIC_MODULES = ("pidcore.io", "pidcore.signal", "pidcore.store", "pidcore.dem",
                  "pidcore.model", "pidcore.compare", "pidcore.report", "pidcore.loadcase",
                  "pidcore.loop", "pidcore.calibrate", "pidcore.measure", "pidcore.specimen",
                  "pidcore.records", "pidcore.errors",
                  # help(pidcore) points to it for the closed vocabularies; README: "each
                  # module's docstring listing its API" (it had no Public API section)
                  "pidcore.constants")


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


# ---------------------------------------------------------------- results: tables and plots
# python-control style: a result hands over its arrays as a pandas frame whose columns name
# their units, and ``plot`` draws into the axes given (or a new figure) and returns them.

_BUNDLED = Path(__file__).resolve().parents[1] / "data_samples"
#: Columns of a result frame that are labels, not quantities (no unit to name).
_LABEL_COLUMNS = {"material", "direction", "DEM settings", "specimen", "specimen sha256",
                  "source file(s)", "load case", "note"}
_UNIT_COLUMN = re.compile(r"^.+ \[[^\[\]]+\]$")


def _measurement():
    from pidcore.io import read_measurement

    return read_measurement(_BUNDLED / "exports" / "synthetic_f500Hz_a1g_fill50_acrylic.csv")


def _power_analysis():
    from pidcore.signal import analyze_power, synthesize_shaker_record

    rec = synthesize_shaker_record(mass_kg=0.05, acceleration_amplitude_m_s2=49.0,
                                   frequency_hz=100.0, sample_rate_hz=10_000.0, n_periods=40,
                                   viscous_damping_n_s_m=0.5)
    return analyze_power(rec.force_n, rec.velocity_m_s, rec.sample_rate_hz)


def _dem_result():
    from pidcore.dem.persist import load_dem_result
    from pidcore.store import Store

    store = Store(_BUNDLED / "dem_table3.h5")
    return load_dem_result(store.get_dem_run(store.list_dem_runs()["case_key"].iloc[0]))


def _harmonic_response():
    from pidcore.model import (
        SdcModel,
        TreatedMode,
        coupon_vibrated_mass_kg,
        harmonic_response,
        load_paper_table3,
        paper_particles_mass_kg,
    )

    mode = TreatedMode(natural_frequency_hz=300.0, modal_mass_kg=2.0,
                       structural_damping_ratio=0.01, treated_area_m2=0.2, fill_percent=50.0,
                       coupon_vibrated_mass_kg=coupon_vibrated_mass_kg(
                           particles_mass_kg=paper_particles_mass_kg(50)))
    return harmonic_response(SdcModel.from_table(load_paper_table3()), mode,
                             frequencies_hz=[280.0, 300.0, 320.0], force_amplitude_n=10.0)


def _calibration():
    from pidcore.calibrate import load_calibration

    return load_calibration(_BUNDLED / "paper_calibration")


def _report_result():
    from pidcore.model import load_paper_table3
    from pidcore.report import ReportResult, build_report_table
    from pidcore.store import Store

    runs = Store(_BUNDLED / "dem_table3.h5").list_dem_runs()
    return ReportResult(paths={}, table=build_report_table(runs, None, load_paper_table3()))


def _loop():
    return _power_analysis().loop()


_RESULTS = {"Measurement": _measurement, "PowerAnalysis": _power_analysis,
            "ForceDisplacementLoop": _loop, "DemResult": _dem_result,
            "HarmonicResponse": _harmonic_response, "Calibration": _calibration,
            "ReportResult": _report_result}


@pytest.mark.parametrize("name", sorted(_RESULTS))
def test_results_give_a_frame_whose_columns_name_their_units(name):
    result = _RESULTS[name]()
    frame = result.to_pandas()
    assert isinstance(frame, pd.DataFrame) and len(frame) > 0
    unnamed = [c for c in frame.columns
               if c not in _LABEL_COLUMNS and not _UNIT_COLUMN.match(str(c))]
    assert not unnamed, f"{name}.to_pandas(): columns without a unit: {unnamed}"
    assert inspect.getdoc(type(result).to_pandas)


def test_result_frames_hold_the_results_arrays():
    # each frame is the result's own arrays, not a copy that could drift from them
    measurement = _measurement()
    frame = measurement.to_pandas()
    for ch in measurement.channels:
        np.testing.assert_array_equal(frame[f"{ch.name} [{ch.unit}]"], ch.data)
    rate = measurement.channels[0].sample_rate_hz
    np.testing.assert_allclose(np.diff(frame["time [s]"]), 1 / rate, rtol=1e-9)  # t0 + i / fs
    analysis = _power_analysis()
    frame = analysis.to_pandas()
    np.testing.assert_array_equal(frame["force amplitude [N]"], np.abs(analysis.force_phasors_n))
    pd.testing.assert_frame_equal(analysis.spectrum_frame(), frame)  # the 0.2 name, kept
    dem = _dem_result()
    frame = dem.to_pandas()
    np.testing.assert_array_equal(frame["shaker force [N]"], dem.shaker_force_n)
    np.testing.assert_array_equal(frame["velocity [m/s]"], dem.velocity_m_s)
    # the steady rows are exactly the samples power_analysis measures
    assert int(frame["steady [True/False]"].sum()) == len(dem.velocity_m_s[dem.steady_slice()])
    response = _harmonic_response()
    np.testing.assert_array_equal(response.to_pandas()["amplitude [m]"], response.amplitude_m)
    calibration = _calibration()
    frame = calibration.to_pandas()
    assert len(frame) == len(calibration.predictions)
    np.testing.assert_array_equal(frame["calibrated high 95 % [-]"],
                                  [p.high95 for p in calibration.predictions])
    report = _report_result()
    assert report.to_pandas() is report.table


@pytest.mark.parametrize("name", sorted(_RESULTS))
def test_result_plot_draws_into_the_axes_given_and_returns_them(name, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    monkeypatch.setattr(plt, "show", lambda *a, **k: pytest.fail(f"{name}.plot() called show"))
    result = _RESULTS[name]()
    # a DEM run draws dissipation over forces, a measurement each channel apart
    n_axes = {"DemResult": 2, "Measurement": len(getattr(result, "channels", ()))}.get(name, 1)
    fig = matplotlib.figure.Figure()  # not a pyplot figure: no global state involved
    axes = fig.subplots(n_axes, 1)
    before_figures, before_rc = plt.get_fignums(), dict(matplotlib.rcParams)
    try:
        got = result.plot(ax=axes)
    finally:
        plt.close("all") if plt.get_fignums() != before_figures else None
    # the axes given, or (a report's figure of panels) the figure holding them
    assert got is axes or (name == "ReportResult" and got is fig)
    assert plt.get_fignums() == before_figures, f"{name}.plot(ax=...) opened a figure"
    assert dict(matplotlib.rcParams) == before_rc, f"{name}.plot() changed rcParams"
    assert all(a.has_data() for a in np.atleast_1d(axes))


def test_a_dem_run_plot_given_one_axes_says_it_draws_two():
    import matplotlib

    from pidcore.errors import ParameterError

    with pytest.raises(ParameterError, match=r"^ax: a DEM run draws two panels"):
        _dem_result().plot(ax=matplotlib.figure.Figure().subplots())


# ---------------------------------------------------------------- discoverability
def _api_section(doc: str) -> list[str]:
    """Names the numpydoc ``Public API`` section of a module docstring lists: its unindented
    lines of comma-separated names, up to the first unindented line of prose."""
    match = re.search(r"^Public API\n-+\n(.*)", doc, re.S | re.M)
    assert match, "no 'Public API' section"
    names = []
    lines = match.group(1).splitlines()
    for line, following in zip(lines, [*lines[1:], ""], strict=True):
        if not line or line[0].isspace():
            continue
        items = [n.strip() for n in line.split(",")]
        if set(following) == {"-"} or not all(n.isidentifier() for n in items):
            break  # the section's end: the next section's title, or prose
        names += items
    return names


@pytest.mark.parametrize("name", PUBLIC_MODULES)
def test_module_docstring_lists_exactly_its_api(name):
    module = importlib.import_module(name)
    listed = _api_section(module.__doc__ or "")
    exported = list(getattr(module, "__all__", ()))
    assert not [n for n in listed if not hasattr(module, n)], \
        f"{name}: the docstring lists names that do not exist"
    assert sorted(set(listed)) == sorted(set(exported)), (
        f"{name}: docstring and __all__ differ: only listed "
        f"{sorted(set(listed) - set(exported))}, only exported "
        f"{sorted(set(exported) - set(listed))}")


def test_package_docstring_says_where_each_job_starts():
    import pidcore

    doc = pidcore.__doc__
    modules = re.findall(r":mod:`(pidcore[.\w]*)`", doc)
    for name in ("pidcore.io", "pidcore.measure", "pidcore.store", "pidcore.specimen",
                 "pidcore.dem", "pidcore.model", "pidcore.calibrate", "pidcore.report"):
        assert name in modules, f"help(pidcore) does not point to {name}"
    for name in modules:
        importlib.import_module(name)  # each one named exists
    for qualified in re.findall(r":(?:func|class|meth):`~?(pidcore\.[\w.]+)`", doc):
        module, _, attr = qualified.rpartition(".")
        owner = None
        while module and owner is None:
            try:
                owner = importlib.import_module(module)
            except ModuleNotFoundError:  # a method: module.Class.method
                module, _, outer = module.rpartition(".")
                attr = f"{outer}.{attr}"
        for part in attr.split("."):
            owner = getattr(owner, part)


def _public_callables() -> list[str]:
    """``module:name`` of every public function, and ``module:Class.method`` of the public
    methods (including class and static methods) of every public class."""
    out = []
    for name in PUBLIC_MODULES:
        module = importlib.import_module(name)
        for attr in getattr(module, "__all__", ()):
            obj = getattr(module, attr)
            if inspect.isfunction(obj):
                out.append(f"{name}:{attr}")
            elif inspect.isclass(obj) and obj.__module__.startswith("pidcore"):
                for meth, value in vars(obj).items():
                    if meth.startswith("_"):
                        continue
                    if inspect.isfunction(value) or isinstance(value, (classmethod,
                                                                       staticmethod)):
                        out.append(f"{name}:{attr}.{meth}")
    return sorted(set(out))


@pytest.mark.parametrize("qualname", _public_callables())
def test_public_callables_are_typed_and_documented(qualname):
    module, path = qualname.split(":")
    owner, obj = importlib.import_module(module), None
    for part in path.split("."):
        owner, obj = (obj if obj is not None else owner), getattr(obj or owner, part)
    function = inspect.unwrap(obj)
    assert inspect.getdoc(function), f"{qualname} has no docstring"
    signature = inspect.signature(function)
    untyped = [p for p, v in signature.parameters.items()
               if p not in ("self", "cls") and v.annotation is inspect.Parameter.empty]
    assert not untyped, f"{qualname}: parameters without a type hint: {untyped}"
    assert signature.return_annotation is not inspect.Signature.empty, \
        f"{qualname}: no return type hint"


def test_closed_vocabularies_live_in_constants():
    # one place for every closed vocabulary (scikit-rf style): a Literal alias defined in
    # another module is a second place a word list can drift (AlignmentStatus, ImpactPair were)
    import pkgutil
    import typing

    import pidcore
    import pidcore.constants as constants

    known = {id(v) for v in vars(constants).values()}
    elsewhere = []
    for info in pkgutil.walk_packages(pidcore.__path__, "pidcore."):
        if info.name.startswith(("pidcore.app", "pidcore.__main__")):
            continue  # the Streamlit app imports streamlit; its words are its pages'
        module = importlib.import_module(info.name)
        elsewhere += [f"{info.name}.{name}" for name, value in vars(module).items()
                      if typing.get_origin(value) is typing.Literal and id(value) not in known]
    assert not elsewhere, f"Literal vocabularies outside pidcore.constants: {elsewhere}"


def test_results_with_a_table_have_a_plot_and_the_other_way_round():
    # python-control style: data and picture come together; every such class is in _RESULTS
    one_sided, classes = [], set()
    for name in PUBLIC_MODULES:
        module = importlib.import_module(name)
        for attr in getattr(module, "__all__", ()):
            obj = getattr(module, attr)
            if inspect.isclass(obj) and (hasattr(obj, "to_pandas") or hasattr(obj, "plot")):
                classes.add(obj.__name__)
                if hasattr(obj, "to_pandas") != hasattr(obj, "plot"):
                    one_sided.append(f"{name}.{attr}")
    assert not one_sided, f"to_pandas() without plot() or the other way round: {one_sided}"
    # a calibration needs DEM runs: its frame and plot are tested with them
    # (tests/test_calibrate_cli.py::test_a_calibration_result_reads_as_its_calibration_json)
    assert classes <= set(_RESULTS) | {"CalibrationResult"}, classes - set(_RESULTS)
