"""Recovery: measurements synthesised by our own DEM with known parameter values (plus noise
at their standard errors) are calibrated back with every true value inside its 95 % interval.

Small, fast configuration: 4 cells, 10 steady cycles, three load cases where runs are cheap.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from pidcore.calibrate import MeasuredPoint, calibrate, observation_from_run
from pidcore.calibrate.runner import RunRequest, simulate_request, specimen_with
from pidcore.dem.persist import dem_run_entry
from pidcore.dem.simulate import DemConfig, LoadCase
from pidcore.specimen import paper_specimen

CASES = ((500.0, 5.0), (1000.0, 5.0), (500.0, 1.0))
BASE = DemConfig(cells=4, steady_cycles=10, block_cycles=5, max_transient_cycles=10)
#: Relative standard error given to the synthetic measurements (a good shaker test: 3 %).
STDERR = 0.03


def _synthetic_points(truth: dict, dem_values: tuple, seed: int) -> list[MeasuredPoint]:
    rng = np.random.default_rng(seed)
    points = []
    for f, a in CASES:
        entry = dem_run_entry(simulate_request(RunRequest(LoadCase(f, a, 50.0), specimen_with(
            paper_specimen(), dict(dem_values)), BASE)))
        obs = observation_from_run(entry["record"], entry["arrays"])
        fixture = truth["fixture_mass_kg"]
        sdc = float(obs.sdc(fixture, truth.get("baseline_loss_factor", 0.0)))
        # the synthetic "truth" is one DEM realisation (4 cells): its own standard error
        # belongs to the measurement's, beside the shaker test's STDERR
        den = obs.reactive_mass_kg + obs.coupon_mass_kg + fixture
        se_dem = math.hypot(2 * math.pi / den * obs.dissipative_mass_stderr_kg,
                            sdc / den * obs.reactive_mass_stderr_kg)
        se = STDERR * sdc
        points.append(MeasuredPoint(f, a, 50.0, sdc + se * rng.standard_normal(),
                                    math.hypot(se, se_dem)))
    return points


def _inside(result, truth):
    for name, value in truth.items():
        p = result.parameters[name]
        assert p["low95"] <= value <= p["high95"], (name, value, p)


def test_fixture_mass_and_baseline_are_recovered(tmp_path):
    truth = {"fixture_mass_kg": 0.06, "baseline_loss_factor": 0.01}
    points = _synthetic_points(truth, (), seed=1)
    result = calibrate(points, fit=["fixture_mass_kg", "baseline_loss_factor"],
                       store_path=tmp_path / "s.h5", discrepancy=0.0, discrepancy_floor=0.0,
                       cells=BASE.cells, steady_cycles=BASE.steady_cycles, dem_config=BASE,
                       workers=1, progress=False)
    _inside(result, truth)
    # informative, not just the prior: the fixture interval is a small part of its 0..1 kg
    p = result.parameters["fixture_mass_kg"]
    assert p["high95"] - p["low95"] < 0.1
    # the synthetic runs are the design's runs (same key): the fit reproduces the points
    assert result.rms < 3 * STDERR * max(pt.sdc for pt in points)
    assert not any("piles against" in n for n in result.notes)  # the data decide inside
    # a prior that excludes the truth (0.06 kg): the posterior piles against its upper bound,
    # and the result says so instead of presenting the bound as a fitted value (same runs)
    capped = calibrate(points, fit=["fixture_mass_kg", "baseline_loss_factor"],
                       priors=["fixture_mass_kg=0:0.03"], store_path=tmp_path / "s.h5",
                       discrepancy=0.0, discrepancy_floor=0.0, cells=BASE.cells,
                       steady_cycles=BASE.steady_cycles, dem_config=BASE, workers=1,
                       progress=False, design_size=3)
    # no DEM parameter fitted: a design size is ignored, and said (the summary claimed a
    # design of 3 points while one run per load case was made)
    assert "design_size 3 ignored: no DEM parameter is fitted" in " ".join(capped.notes)
    assert capped.settings["design_size"] == 1
    piled = [n for n in capped.notes if "piles against" in n]
    assert any(n.startswith("fixture_mass_kg:") and "upper bound 0.03" in n for n in piled)
    # percentages written as everywhere else ("95 %"; it read "(87% of the samples in the 5%")
    assert all(re.search(r"\(\d+ % of the samples in the 5 % of the prior's range", n)
               for n in piled), piled
    # the calibrated specimen file carries the warning, and still reads
    from pidcore.calibrate.outputs import specimen_text
    from pidcore.specimen import Specimen

    text = specimen_text(capped)
    assert "# note: fixture_mass_kg: the posterior piles against" in text
    assert Specimen.from_text(text) == capped.calibrated_specimen()


@pytest.mark.slow
def test_dem_parameter_is_recovered_through_the_surrogate(tmp_path):
    truth = {"friction": 0.4, "fixture_mass_kg": 0.06}
    points = _synthetic_points({"fixture_mass_kg": 0.06}, (("friction", 0.4),), seed=2)
    result = calibrate(points, fit=["friction", "fixture_mass_kg"], store_path=tmp_path / "s.h5",
                       discrepancy=0.0, discrepancy_floor=0.0, cells=BASE.cells,
                       steady_cycles=BASE.steady_cycles, dem_config=BASE, workers=1,
                       progress=False, design_size=5)
    _inside(result, truth)
    assert result.runs["computed"] == len(CASES) * 5
    p = result.parameters["friction"]
    assert p["high95"] - p["low95"] < 0.75 * (0.8 - 0.05)  # learnt something about friction
    again = calibrate(points, fit=["friction", "fixture_mass_kg"],
                      store_path=tmp_path / "s.h5", discrepancy=0.0, discrepancy_floor=0.0,
                      cells=BASE.cells, steady_cycles=BASE.steady_cycles, dem_config=BASE,
                      workers=1, progress=False, design_size=5)
    assert again.runs == pytest.approx({"computed": 0, "cached": 15, "wall_s": again.runs[
        "wall_s"]})
    assert again.parameters == result.parameters  # cached runs, same seeds: same posterior
