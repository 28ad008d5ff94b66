"""The per-load-case surrogate of the DEM's masses over the design (Gaussian process)."""

from __future__ import annotations

import numpy as np

from pidcore.calibrate.observation import Observation
from pidcore.calibrate.parameters import ParameterSpec
from pidcore.calibrate.surrogate import build_surrogate, design_points, predicted_sdc
from pidcore.compare.plausibility import SDC_UPPER_BOUND

RESTITUTION = ParameterSpec("restitution", "dem", 0.6, 0.3, 0.95, "test")
COUPON_KG, FIXTURE_KG, ETA0 = 0.030, 0.05, 0.008
RUN_SE_KG = 8e-4  # the runs' dissipative mass scatter, as 2-cell runs of the tester's had
MP_KG, MP_SE_KG = 3e-4, 5e-4


def _truth_d(e: np.ndarray) -> np.ndarray:
    """Smooth dissipative mass, 4 g at e 0.3 falling to 0 at e 0.95 (kg)."""
    return 4e-3 * (0.95 - np.asarray(e)) / 0.65


def _observation(d: float, d_se: float, mp: float, mp_se: float) -> Observation:
    return Observation(200.0, 5.0, 6.0, d, d_se, mp, mp_se, COUPON_KG, 0.0)


def test_runs_that_dissipate_nothing_enter_as_noisy_observations_not_exact_logs():
    # The tester's 200 Hz / 5 g case: one run with no wall force at all (d = m_p = 0 +- 0
    # exactly) and one giving back energy (Re P < 0 within its noise) entered log space as
    # log(1e-12 kg), the first with zero error: d went to 121 kg +- 6.9e6 between the runs,
    # its sd to exactly 0 at others, and the SDC to 99 (bound 2 pi).
    design = design_points([RESTITUTION], 5)
    e = design[:, 0]
    truth = _truth_d(e)
    zero = int(np.argmax(e))                     # e 0.885, truth 0.4 g: observed 0 +- 0
    negative = int(np.argsort(e)[-2])            # e 0.755, truth 1.2 g: observed -0.3 g
    offsets = np.array([0.5, -0.5, 0.3, 0.0, 0.0]) * RUN_SE_KG
    runs = []
    for i, (value, off) in enumerate(zip(truth, offsets[np.argsort(np.argsort(e))], strict=True)):
        if i == zero:
            runs.append(_observation(0.0, 0.0, 0.0, 0.0))
        elif i == negative:
            runs.append(_observation(value - 1.9 * RUN_SE_KG, RUN_SE_KG, MP_KG, MP_SE_KG))
        else:
            runs.append(_observation(value + off, RUN_SE_KG, MP_KG, MP_SE_KG))
    surrogate = build_surrogate(runs, design, [RESTITUTION])

    others = [i for i in range(len(e)) if i not in (zero, negative)]
    d, var_d, mp, var_mp = surrogate.predict(design[others])
    # within the runs' noise of the truth: 2 standard errors of one run (95 %), and the
    # surrogate no surer and no vaguer than the runs it rests on (0 < sd <= 2 se)
    assert np.all(np.abs(d - truth[others]) <= 2 * RUN_SE_KG)
    assert np.all((np.sqrt(var_d) > 0) & (np.sqrt(var_d) <= 2 * RUN_SE_KG))
    assert np.all(np.abs(mp - MP_KG) <= 2 * MP_SE_KG)

    grid = np.linspace(RESTITUTION.low, RESTITUTION.high, 201)[:, None]
    d, var_d, mp, var_mp = surrogate.predict(grid)
    # positive everywhere, between the runs too (the old explicit inverse cancelled to below
    # 0 and was clipped to exactly 0 at e 0.45 .. 0.6)
    assert np.all(var_d > 0) and np.all(var_mp > 0)
    # a zero run is 0 within the other runs' noise, so d nowhere strays beyond a few of it
    assert np.all(np.abs(d - _truth_d(grid[:, 0])) <= 3 * RUN_SE_KG)
    sdc, var_sdc = predicted_sdc(surrogate, grid, np.full(len(grid), FIXTURE_KG),
                                 np.full(len(grid), ETA0))
    assert np.all(np.abs(sdc) + 1.96 * np.sqrt(var_sdc) < SDC_UPPER_BOUND)


def test_resolved_runs_keep_the_log_surrogate_and_its_exact_fit_of_a_power_law():
    # every run resolves d (10 standard errors and more): the surrogate stays of log d, as
    # the bundled paper calibration's is, and a power law d = 1e-3 (e / 0.3)^-2 over a
    # factor 10 is reproduced between the runs within a few times the runs' 1 % error
    design = design_points([RESTITUTION], 5)
    d_true = 1e-3 * (design[:, 0] / 0.3) ** -2
    runs = [_observation(v, 0.01 * v, MP_KG, MP_SE_KG) for v in d_true]
    surrogate = build_surrogate(runs, design, [RESTITUTION])
    assert surrogate.logarithmic
    e = np.array([[0.43], [0.69]])
    d, var_d, *_ = surrogate.predict(e)
    truth = 1e-3 * (e[:, 0] / 0.3) ** -2
    assert np.all(np.abs(d / truth - 1) <= 0.05)
    assert np.all(var_d > 0)
