"""A 95 % band built on a standard error of few blocks uses Student's t quantile.

`pidcore analyze` gives ``sdc_stderr`` as the scatter of ``n_blocks`` (8) block estimates about
their mean: (estimate - truth) / stderr follows Student's t with n_blocks - 1 = 7 degrees of
freedom, whose 97.5 % quantile is 2.365. Widened by 1.96 stderr, the measurement's part of a
"95 %" band covered ~91 %. The truth here is known: coverage is counted, not asserted from the
code's own numbers.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from pidcore.calibrate.data import MeasuredPoint, read_measured_table
from pidcore.calibrate.parameters import ParameterSpec
from pidcore.calibrate.posterior import Model, predictive
from pidcore.calibrate.prediction import (
    CalibratedPrediction,
    band_quantile,
    calibration_from_json,
    quantile_label,
)
from pidcore.compare.align import pooled_stderr_dof
from pidcore.errors import InputFileError, ParameterError
from pidcore.loadcase import LoadCase

N_BLOCKS = 8
TRUTH = 0.30
BLOCK_SD = 0.04  # scatter of one block's SDC estimate: stderr ~ 0.014, far from SDC 0


def _eight_block_measurements(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(mean SDC, its stderr) of ``n`` synthetic measurements, each the mean of 8 normal
    block estimates about TRUTH, the stderr their std(ddof=1) / sqrt(8) as analyze_power
    computes it."""
    blocks = TRUTH + BLOCK_SD * np.random.default_rng(seed).standard_normal((n, N_BLOCKS))
    return blocks.mean(axis=1), blocks.std(axis=1, ddof=1) / math.sqrt(N_BLOCKS)


def _binomial_band(n: int, p: float = 0.95, k: float = 4.0) -> tuple[float, float]:
    # 4 binomial standard deviations: a correct 95 % fails this once in ~16000 runs, while
    # 1.96 stderr (coverage 2 t7.cdf(1.96) - 1 = 0.909) lies > 10 of them away
    half = k * math.sqrt(p * (1 - p) / n)
    return p - half, p + half


def test_the_quantile_is_students_t_of_the_stated_degrees_of_freedom():
    assert band_quantile(7) == pytest.approx(2.364624, rel=1e-6)
    assert band_quantile(math.nan) == 1.959963984540054  # unknown: the normal, as before
    assert band_quantile(math.inf) == pytest.approx(1.959964, rel=1e-6)  # t's limit
    assert quantile_label(7) == "Student t quantile 2.365 of 7 degrees of freedom"
    assert quantile_label() == ("normal quantile 1.96, the degrees of freedom of the stderr "
                                "unknown")
    for bad in (0, -1):
        with pytest.raises(ParameterError, match="dof"):
            band_quantile(bad)


def test_the_band_of_an_8_block_measurement_covers_95_percent_of_them():
    # the model is exact (band without measurement error of zero width at TRUTH): the band
    # of a measurement is TRUTH +- q stderr, which holds the measurement as often as
    # |t| <= q
    n = 20_000
    sdc, stderr = _eight_block_measurements(n, seed=11)
    exact = CalibratedPrediction(LoadCase(100.0, 1.0, 50.0), TRUTH, TRUTH, TRUTH, TRUTH, 0.0,
                                 TRUTH, TRUTH)
    inside_t = np.mean([exact.contains(v, s, N_BLOCKS - 1)
                        for v, s in zip(sdc, stderr, strict=True)])
    inside_normal = np.mean([exact.contains(v, s) for v, s in zip(sdc, stderr, strict=True)])
    low, high = _binomial_band(n)
    assert low < inside_t < high
    # the old quantile, still used where the degrees of freedom are unknown, covers ~91 %
    expected_normal = 2 * stats.t.cdf(1.959964, N_BLOCKS - 1) - 1
    assert inside_normal == pytest.approx(expected_normal, abs=high - 0.95)
    assert inside_normal < low


class _ConstantSurrogate:
    """A surrogate with a fixed dissipative and reactive mass and no variance: the model's
    SDC is known exactly, so the predictive band is only the measurement's error."""

    frequency_hz, acceleration_g, fill_percent = 100.0, 1.0, 50.0
    coupon_mass_kg = 0.02215

    def predict(self, theta):
        n = np.atleast_2d(theta).shape[0]
        return (np.full(n, 1.0e-3), np.zeros(n), np.full(n, 0.005), np.zeros(n))


def _exact_model(point: MeasuredPoint) -> tuple[Model, np.ndarray, float]:
    spec = ParameterSpec("baseline_loss_factor", "observation", 0.0, 0.0, 0.2, "eta")
    model = Model((spec,), (_ConstantSurrogate(),), (point,),
                  {"fixture_mass_kg": 0.0, "model_discrepancy": 0.0}, 0.0)
    samples = np.zeros((4000, 1))  # the posterior: the one parameter value known
    truth = float(model.predict(samples[:1], 0)[0][0])
    return model, samples, truth


def test_the_posterior_predictive_band_of_an_8_block_measurement_covers_95_percent():
    # each synthetic measurement of the model's exact SDC is fitted as the point with its
    # own stderr (7 degrees of freedom): its posterior-predictive band must hold it 95 %
    # of the time. Normal draws for the error gave ~91 %.
    probe, samples, truth = _exact_model(MeasuredPoint(100.0, 1.0, 50.0, 0.3, 0.01))
    n = 3000
    blocks = truth + BLOCK_SD * np.random.default_rng(5).standard_normal((n, N_BLOCKS))
    sdc, stderr = blocks.mean(axis=1), blocks.std(axis=1, ddof=1) / math.sqrt(N_BLOCKS)
    rng = np.random.default_rng(17)
    inside = inside_normal = 0
    for v, s in zip(sdc, stderr, strict=True):
        point = MeasuredPoint(100.0, 1.0, 50.0, float(v), float(s),
                              sdc_stderr_dof=N_BLOCKS - 1)
        band = predictive(replace(probe, points=(point,)), samples, 0, rng=rng)
        inside += band["low95"] <= v <= band["high95"]
        old = predictive(replace(probe, points=(replace(point, sdc_stderr_dof=math.nan),)),
                         samples, 0, rng=rng)
        inside_normal += old["low95"] <= v <= old["high95"]
    # the band's percentiles of 4000 draws add their own scatter (~0.3 % of coverage) to the
    # binomial one: 4.5 sd instead of 4
    low, high = _binomial_band(n, k=4.5)
    assert low < inside / n < high
    assert inside_normal / n < low  # ~0.91: the normal draws of the old code


def test_a_point_without_degrees_of_freedom_draws_as_before():
    # a table without sdc_stderr_dof (the bundled calibration's): the same normal draws,
    # bit for bit, as the code before the degrees of freedom were kept
    point = MeasuredPoint(100.0, 1.0, 50.0, 0.3, 0.02)
    model, samples, _ = _exact_model(point)
    got = predictive(model, samples, 0, rng=np.random.default_rng(3))
    sdc, variance = model.predict(samples, 0)
    draws = sdc + np.random.default_rng(3).standard_normal(sdc.shape) * np.sqrt(variance)
    assert (got["low95"], got["high95"]) == tuple(np.percentile(np.maximum(draws, 0.0),
                                                                [2.5, 97.5]))


def test_the_degrees_of_freedom_go_through_the_measured_table(tmp_path):
    table = tmp_path / "measured.csv"
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc,sdc_stderr,sdc_stderr_dof\n"
                     "50,5,50,0.2,0.01,7\n500,1,50,0.3,0.02,\n", encoding="utf-8")
    first, second = read_measured_table(table)
    assert first.sdc_stderr_dof == 7.0
    assert math.isnan(second.sdc_stderr_dof)  # empty: unknown
    old = tmp_path / "old.csv"
    old.write_text("frequency_hz,acceleration_g,fill_percent,sdc,sdc_stderr\n50,5,50,0.2,0.01\n",
                   encoding="utf-8")
    (point,) = read_measured_table(old)
    assert math.isnan(point.sdc_stderr_dof) and point == MeasuredPoint(50, 5, 50, 0.2, 0.01)
    bad = tmp_path / "bad.csv"
    bad.write_text("frequency_hz,acceleration_g,fill_percent,sdc,sdc_stderr,sdc_stderr_dof\n"
                   "50,5,50,0.2,0.01,0\n", encoding="utf-8")
    with pytest.raises(InputFileError, match=r"bad.csv.*line 2.*sdc_stderr_dof 0: expected"):
        read_measured_table(bad)


def _calibration_row(**extra) -> dict:
    return {"frequency_hz": 50.0, "acceleration_g": 5.0, "fill_percent": 50.0,
            "predicted": 0.5, "low95": 0.40, "high95": 0.62, "measured": 0.5,
            "measured_stderr": 0.02, "low95_without_stderr": 0.45,
            "high95_without_stderr": 0.56, **extra}


def test_the_degrees_of_freedom_go_through_calibration_json():
    new = calibration_from_json(json.dumps({"parameters": {}, "predictions": [
        _calibration_row(measured_stderr_dof=7)]}), "calibration.json")
    old = calibration_from_json(json.dumps({"parameters": {}, "predictions": [
        _calibration_row()]}), "old.json")
    (hit,), (hit_old,) = new.predictions, old.predictions
    assert hit.measured_stderr_dof == 7.0 and math.isnan(hit_old.measured_stderr_dof)
    assert new.to_pandas()["SDC measured (Eq. 11) stderr dof [-]"].tolist() == [7.0]
    # its own stderr and dof: the stated band; another measurement's: widened by its quantile
    assert hit.band(0.02, 7) == (0.40, 0.62)
    assert hit_old.band(0.02) == (0.40, 0.62)
    t_low, t_high = hit.band(0.01, 7)
    assert t_high == pytest.approx(0.5 + math.hypot(0.06, 2.364624 * 0.01), rel=1e-6)
    assert t_low == pytest.approx(0.5 - math.hypot(0.05, 2.364624 * 0.01), rel=1e-6)
    # an older file, or a stderr of unknown dof: 1.96 as before
    assert hit_old.band(0.01)[1] == pytest.approx(0.5 + math.hypot(0.06, 1.959964 * 0.01),
                                                  rel=1e-6)
    with pytest.raises(ParameterError, match=r"calibration.json: predictions\[0\]"
                                             r".measured_stderr_dof must be degrees"):
        calibration_from_json(json.dumps({"parameters": {}, "predictions": [
            _calibration_row(measured_stderr_dof=-1)]}), "calibration.json")



def test_calibration_frame_names_the_measured_sdc_as_align_measured_and_the_report_do():
    # Calibration.to_pandas() said "sdc measured [-]" where align_measured and report.csv say
    # "SDC measured (Eq. 11) [-]" for the same Eq. 11 SDC: a third spelling of one quantity.
    # A frame saved with the old names reads into the present ones and still plots.
    import matplotlib.pyplot as plt

    from pidcore.calibrate import CALIBRATION_COLUMNS_RENAMED
    from pidcore.compare.align import (
        MEASURED_COLUMNS_RENAMED,
        MEASURED_EQ11_COLUMN,
        MEASURED_EQ11_DOF_COLUMN,
        MEASURED_EQ11_STDERR_COLUMN,
    )
    from pidcore.report.figures_results import plot_calibration
    from pidcore.report.table import MEASURED_EQ11_COLUMN as REPORT_EQ11_COLUMN

    frame = calibration_from_json(json.dumps({"parameters": {}, "predictions": [
        _calibration_row(measured_stderr_dof=7)]}), "calibration.json").to_pandas()
    assert REPORT_EQ11_COLUMN == MEASURED_EQ11_COLUMN == "SDC measured (Eq. 11) [-]"
    assert frame.loc[0, [MEASURED_EQ11_COLUMN, MEASURED_EQ11_STDERR_COLUMN,
                         MEASURED_EQ11_DOF_COLUMN]].tolist() == [0.5, 0.02, 7.0]
    assert not [c for c in frame.columns if c.startswith("sdc measured")]
    # one mapping mechanism, one target name per quantity: the old names map to align's
    assert set(MEASURED_COLUMNS_RENAMED.values()) <= set(CALIBRATION_COLUMNS_RENAMED.values())
    older = frame.rename(columns={new: old for old, new in CALIBRATION_COLUMNS_RENAMED.items()})
    assert "sdc measured [-]" in older.columns
    pd.testing.assert_frame_equal(older.rename(columns=CALIBRATION_COLUMNS_RENAMED), frame)
    for drawn in (frame, older):
        _, ax = plt.subplots()
        try:
            (crosses,) = [line for line in plot_calibration(drawn, ax=ax).get_lines()
                          if line.get_label() == "measured"]
            assert list(crosses.get_ydata()) == [0.5]  # the measured SDC, exact
        finally:
            plt.close("all")


def _one_analysis_store(tmp_path):
    """A store of one analysed 500 Hz, 5 g record (a viscous mass, 50 % fill, acrylic)."""
    from _shaker_files import write_force_velocity

    from pidcore.cli import main
    from pidcore.constants import STANDARD_GRAVITY
    from pidcore.signal.synthetic import synthesize_shaker_record

    rec = synthesize_shaker_record(mass_kg=0.25, acceleration_amplitude_m_s2=5 * STANDARD_GRAVITY,
                                   frequency_hz=500.0, sample_rate_hz=25_600.0, n_periods=40.3,
                                   viscous_damping_n_s_m=2.0, snr_db=50, seed=3)
    path = write_force_velocity(tmp_path / "run_fill50_acrylic.csv", rec.force_n,
                                rec.velocity_m_s, 25_600.0, "csv")
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--store", str(store)]) == 0
    return store


def test_an_analysis_in_the_store_keeps_n_blocks_minus_1(tmp_path, monkeypatch):
    from pidcore.calibrate import measured_from_store
    from pidcore.store import Store

    store = _one_analysis_store(tmp_path)
    analyses = Store(store).list_analyses()
    assert analyses["sdc_stderr_dof"].tolist() == [N_BLOCKS - 1]  # the default 8 blocks
    (point,) = measured_from_store(store)
    assert point.sdc_stderr == analyses["sdc_stderr"].iloc[0] > 0
    assert point.sdc_stderr_dof == N_BLOCKS - 1
    # a store of records without it (an older pidcore's): unknown, as before
    frame = analyses.drop(columns=["sdc_stderr_dof"])
    monkeypatch.setattr(Store, "list_analyses", lambda self: frame)
    (old,) = measured_from_store(store)
    assert math.isnan(old.sdc_stderr_dof) and old.sdc_stderr == point.sdc_stderr
    # repeated tests: the stderr of their mean has repeats - 1
    twice = pd.concat([frame, frame.assign(key="k2", measurement_key="m2",
                                           sdc=frame["sdc"] * 1.1,
                                           loss_factor=frame["loss_factor"] * 1.1)],
                      ignore_index=True)
    monkeypatch.setattr(Store, "list_analyses", lambda self: twice)
    (pooled,) = measured_from_store(store)
    assert pooled.sdc_stderr_dof == 1.0


def test_pooled_degrees_of_freedom():
    # scatter between them taken: n - 1; propagated errors taken: Welch-Satterthwaite, which
    # for equal errors of dof 7 is 7 n
    assert pooled_stderr_dof(np.array([0.3]), np.array([0.01]), np.array([7.0])) == 7.0
    assert pooled_stderr_dof(np.array([0.2, 0.4, 0.3]), np.full(3, 0.001),
                             np.full(3, 7.0)) == 2.0
    assert pooled_stderr_dof(np.array([0.3, 0.3001]), np.full(2, 0.01),
                             np.full(2, 7.0)) == pytest.approx(14.0)
    assert math.isnan(pooled_stderr_dof(np.array([0.3, 0.3001]), np.full(2, 0.01),
                                        np.array([7.0, math.nan])))


def test_the_report_widens_by_the_t_quantile_and_says_so(tmp_path):
    from pidcore.calibrate.prediction import load_calibration
    from pidcore.report import table as report_table

    path = tmp_path / "calibration.json"
    path.write_text(json.dumps({"parameters": {}, "predictions": [_calibration_row()]}),
                    encoding="utf-8")
    table = pd.DataFrame({
        "frequency [Hz]": [50.0, 50.0], "acceleration [g]": [5.0] * 2,
        "packing ratio [%]": [50.0] * 2, "material": ["acrylic"] * 2,
        "SDC measured (Eq. 11) [-]": [0.45, 0.45], "SDC measured (Eq. 11) stderr [-]": [0.01, 0.01],
        "SDC measured (Eq. 11) stderr dof [-]": [7.0, math.nan], "note": [""] * 2})
    out = report_table.add_calibration_columns(table, load_calibration(path))
    high = out[report_table.CALIBRATED_HIGH_COLUMN].tolist()
    assert high[0] == pytest.approx(0.5 + math.hypot(0.06, 2.364624 * 0.01), rel=1e-6)
    assert high[1] == pytest.approx(0.5 + math.hypot(0.06, 1.959964 * 0.01), rel=1e-6)
    assert out["note"][0].endswith("Student t quantile 2.365 of 7 degrees of freedom")
    assert out["note"][1].endswith("normal quantile 1.96, the degrees of freedom of the "
                                   "stderr unknown")



def test_tests_driven_along_x_are_no_load_case_of_the_calibrations_z_runs(tmp_path,
                                                                         monkeypatch):
    # an x-drive test of SDC 0.2 was pooled with a z-drive one of 0.02 as two repeats (0.11
    # +- 0.09) and fitted against a z-drive DEM run; report kept them apart
    from pidcore.calibrate import measured_from_store, read_measured_table
    from pidcore.errors import InputFileError
    from pidcore.store import Store

    store = _one_analysis_store(tmp_path)
    frame = Store(store).list_analyses()
    (alone,) = measured_from_store(store)
    both = pd.concat([frame, frame.assign(key="k2", measurement_key="m2", direction="x",
                                          source="xdrive_fill50_acrylic.csv",
                                          sdc=frame["sdc"] * 10,
                                          loss_factor=frame["loss_factor"] * 10)],
                     ignore_index=True)
    monkeypatch.setattr(Store, "list_analyses", lambda self: both)
    said: list[str] = []
    (point,) = measured_from_store(store, left_out=said)
    assert point.sdc == alone.sdc and point.analyses == alone.analyses  # the z test alone
    assert any("xdrive_fill50_acrylic.csv: left out, driven along x: the calibration's DEM "
               "runs drive along z" in s for s in said), said
    # a table's row of another direction is refused, naming its line
    table = tmp_path / "m.csv"
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc,direction\n"
                     "500,5,50,0.2,z\n500,5,75,0.2,x\n")
    with pytest.raises(InputFileError, match=r"m\.csv, line 3: direction 'x': the "
                                             r"calibration's DEM runs drive along z"):
        read_measured_table(table)
    table.write_text("frequency_hz,acceleration_g,fill_percent,sdc,direction\n500,5,50,0.2,Z\n")
    assert len(read_measured_table(table)) == 1


def test_the_error_model_note_quotes_the_quantile_of_the_points_own_degrees_of_freedom():
    # it said "t_0.975,7 = 2.365" beside points whose standard error had 1 degree of freedom
    # (two repeated tests), whose quantile is 12.71
    from scipy.stats import t

    from pidcore.calibrate.calibrate import error_model_notes
    from pidcore.calibrate.data import MeasuredPoint

    def point(dof: float) -> MeasuredPoint:
        return MeasuredPoint(500.0, 5.0, 50.0, 0.3, 0.02, sdc_stderr_dof=dof)

    (note,) = error_model_notes([point(1.0), point(7.0)])
    assert f"(1, 7) is sdc_stderr times Student's t with them (t_0.975,1 = " \
        f"{t.ppf(0.975, 1):.4g}, not 1.96" in note
    assert "12.71" in note
    (note,) = error_model_notes([point(7.0)])
    assert "t_0.975,7 = 2.365" in note
    assert error_model_notes([point(math.nan)]) == []  # unknown: normal, nothing to say
