"""Plausibility checks and the one-line headline of a load case, on analytic mass-damper
records whose truth is known (tests/_app_samples.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _app_samples import mass_damper_csv

from pidcore.app import uploads
from pidcore.compare.case import MeasuredEntry, compare_case, headline, load_case_of, paper_table
from pidcore.compare.plausibility import SDC_UPPER_BOUND, check_analysis
from pidcore.measure import AnalysisOptions


def _analysis(data: bytes, **options):
    outcome = uploads.analyze_upload("x_fill50.csv", data, AnalysisOptions(**options))
    assert outcome.ok, outcome.error
    return outcome.record


def test_a_physical_record_raises_no_warning():
    assert check_analysis(_analysis(mass_damper_csv(loss_factor=0.05)).analysis) == ()


def test_uncorrected_delay_gives_a_negative_loss_factor_and_the_delay_that_explains_it():
    # A velocity recorded 200 µs late turns P by +w tau = 7.2° at 100 Hz: a loss factor of
    # 0.05 (2.9°) becomes about tan(2.9° - 7.2°) = -0.075.
    rec = _analysis(mass_damper_csv(loss_factor=0.05, velocity_late_s=200e-6))
    (w,) = check_analysis(rec.analysis)
    assert w.check == "negative_loss_factor" and rec.analysis.loss_factor < 0
    # the delay that brings the loss factor to zero: 200 µs minus the 0.05 damping's own
    # 2.86° (79.5 µs at 100 Hz) = 120 µs
    tau_us = float(w.likely_cause.split("about ")[1].split(" µs")[0])
    expected = 200.0 - math.degrees(math.atan(0.05)) / 360 / 100.0 * 1e6
    assert tau_us == pytest.approx(expected, abs=2.0)


def _flipped_force() -> bytes:
    data = mass_damper_csv(loss_factor=0.05).decode().splitlines()
    return "\n".join([data[0]] + [",".join([t, str(-float(f)), v]) for t, f, v in
                                  (line.split(",") for line in data[1:])]).encode()


def test_an_inverted_channel_is_refused_and_the_settings_column_corrects_it():
    # the library refuses Im(P) <= 0; the app's message points to its own column
    outcome = uploads.analyze_upload("x_fill50.csv", _flipped_force(), AnalysisOptions())
    assert not outcome.ok and "inverted" in outcome.error
    assert "--invert" not in outcome.error and "'inverted channels' column" in outcome.error
    row = {**uploads.default_settings_row("x_fill50.csv", _Stated()),
           "inverted channels": "Force"}
    fixed = uploads.analyze_upload("x_fill50.csv", _flipped_force(), uploads.options_of(row))
    truth = _analysis(mass_damper_csv(loss_factor=0.05)).analysis.sdc
    assert fixed.ok and fixed.record.analysis.sdc == pytest.approx(truth, rel=1e-9)


class _Stated:
    fill_percent, material, direction = 50.0, "acrylic", "z"


def test_force_lagging_velocity_is_named_as_an_inverted_channel():
    from types import SimpleNamespace

    # P = F V* / 2 with the force's sign flipped: Im P < 0
    analysis = SimpleNamespace(complex_power_w=complex(0.1, -2.0), loss_factor=-0.05,
                               sdc=-0.31, omega_rad_s=628.3)
    checks = {w.check: w for w in check_analysis(analysis)}
    assert "force_lags_velocity" in checks
    assert "inverted sign" in checks["force_lags_velocity"].likely_cause


def test_sdc_above_the_bound_is_flagged():
    rec = _analysis(mass_damper_csv(loss_factor=1.5))
    assert rec.analysis.sdc > SDC_UPPER_BOUND
    assert [w.check for w in check_analysis(rec.analysis)] == ["sdc_above_bound"]


def test_an_sdc_above_2_pi_without_a_specimen_file_names_the_file_as_a_cause():
    # 2 mm steel spheres (216 g on a 48 g structure) dissipate SDC 8: without their specimen
    # file the only causes named were set-up errors, none of which the user had made
    from pidcore.compare.plausibility import SdcBound

    rec = _analysis(mass_damper_csv(loss_factor=1.3))
    unknown = check_analysis(rec.analysis)[0]
    assert unknown.check == "sdc_above_bound"
    assert unknown.likely_cause.endswith(
        "; or particles heavier than their coupon whose specimen file is not given (without "
        "it the bound is 2 pi; with it, 8 m_p/m_s: give its specimen file, specimen=FILE)")
    # a bound from the specimen's masses that the result still exceeds: the file was given
    known = SdcBound(6.5, particle_mass_kg=0.04, structure_mass_kg=0.0492)
    [within_file] = check_analysis(rec.analysis, bound=known)
    assert "specimen file" not in within_file.likely_cause


def _entry(rec):
    return MeasuredEntry.from_record(rec, load_case_of(rec, fill_percent=50.0,
                                                       material="acrylic"))


def _dem(sdc: float, stderr: float, m_c: float = 0.3, cells: float | None = None):
    import pandas as pd

    frame = pd.DataFrame({"case_key": ["r"], "frequency_hz": [100.0], "acceleration_g": [5.0],
                          "fill_percent": [50.0], "material": ["acrylic"], "direction": ["z"],
                          "sdc": [sdc], "sdc_stderr": [stderr], "m_c_kg": [m_c]})
    if cells is not None:
        frame["cells_simulated"] = [cells]
    return frame


def _ws_quantile(stderrs_and_dofs):
    """Student t_0.975 of Welch-Satterthwaite's degrees of freedom, an unknown one (NaN)
    counted as infinite; the normal's 1.96 where none is known."""
    from scipy import stats

    total = sum(se**2 for se, _ in stderrs_and_dofs)
    known = [(se, dof) for se, dof in stderrs_and_dofs if math.isfinite(dof)]
    if not known:
        return stats.norm.ppf(0.975)
    return stats.t.ppf(0.975, total**2 / sum(se**4 / dof for se, dof in known))


def test_headline_compares_like_with_like_and_counts_sigmas():
    rec = _analysis(mass_damper_csv(loss_factor=0.05))
    paper = paper_table()
    probe = compare_case([_entry(rec)], _dem(0.3, 0.01), paper)
    m, se = probe.measured_sdc_eq10, probe.measured_stderr_eq10
    m_dof = rec.analysis.sdc_stderr_dof
    assert np.isfinite(m) and probe.measured_stderr_eq10_dof == m_dof
    # a 4-cell DEM run: its stderr (the scatter of 4 cells' SDCs) has 3 degrees of freedom
    agree = headline(compare_case([_entry(rec)], _dem(m + 0.01, 0.01, cells=4), paper))
    assert agree.measured_kind.startswith("Eq. 10") and agree.measured == m
    assert agree.sigmas == pytest.approx(0.01 / math.hypot(se, 0.01))
    q = _ws_quantile([(se, m_dof), (0.01, 3.0)])
    assert agree.interval_sigmas == pytest.approx(q, rel=1e-12) and agree.agrees is True
    # the verdict names the interval, and its basis what σ is and which quantile ("agrees
    # within 2 σ" before, with 2 neither the normal's 1.96 nor any t's); the verdict is short,
    # as the end of the app's heading (its basis inside it wrapped the heading), and the basis
    # states the same interval
    dof = (se**2 + 0.01**2) ** 2 / (se**4 / m_dof + 0.01**4 / 3.0)
    assert agree.verdict == (f"agrees: |measured − DEM| = {agree.sigmas:.3g} σ, inside the "
                             f"95 % interval ±{q:.3g} σ")
    assert agree.basis == (f"σ = √(measured stderr² + DEM stderr²); ±{q:.3g} σ: Student t of "
                           f"{dof:.3g} degrees of freedom, Welch-Satterthwaite")
    far = headline(compare_case([_entry(rec)], _dem(m + 1.0, 0.01), paper))
    assert far.verdict.startswith("differs: |measured − DEM| = ") and far.agrees is False
    # without the DEM case's m_c the Eq. 11 SDC is not passed off as comparable
    unknown = headline(compare_case([_entry(rec)], _dem(0.3, 0.01).drop(columns="m_c_kg"),
                                    paper))
    assert unknown.measured_kind == "Eq. 11" and math.isnan(unknown.sigmas)
    assert unknown.agrees is None
    # a DEM value without a standard error (a 1-cell run): the σ is the measurement's alone, so
    # the count is only an upper bound, and the verdict says so ("differs by 314.1 σ" before)
    one_cell = headline(compare_case([_entry(rec)], _dem(m + 1.0, float("nan")), paper))
    assert one_cell.sigmas == pytest.approx(1.0 / se)
    assert 1000 <= 1.0 / se < 10_000  # 3 significant digits: rounded to tens
    assert one_cell.verdict.startswith(f"differs by up to {round(1.0 / se, -1):.0f} σ: "
                                       "outside the 95 % interval")
    assert "the DEM value has no standard error" in one_cell.basis
    # a multiple in the thousands reads as its 3 significant digits ("differs by up to 4874.0
    # σ" before: a decimal the stderr does not carry)
    huge = headline(compare_case([_entry(rec)], _dem(m + 4874.04 * se, float("nan")), paper))
    assert huge.verdict.startswith("differs by up to 4870 σ: outside the 95 % interval")
    assert one_cell.agrees is None  # outside the measurement's interval, the whole unknown
    near = headline(compare_case([_entry(rec)], _dem(m + 0.5 * se, float("nan")), paper))
    q_measured = _ws_quantile([(se, m_dof)])
    assert near.verdict == (f"agrees: |measured − DEM| ≤ 0.5 σ, inside the 95 % interval "
                            f"±{q_measured:.3g} σ")
    assert near.basis == (f"σ: the measured stderr alone, the DEM value has no standard error; "
                          f"±{q_measured:.3g} σ: Student t of {m_dof:.3g} degrees of freedom")
    assert near.agrees is True


def _comparison(measured, measured_stderr, measured_dof, dem, dem_stderr, dem_dof):
    """A compared case built by hand: the Eq. 10 measured SDC against a DEM grid case."""
    import pandas as pd

    from pidcore.compare.align import AlignedCase, DemCase
    from pidcore.compare.case import CaseComparison
    from pidcore.compare.loadcase import LoadCase

    case = LoadCase(100.0, 5.0, 50.0)
    grid = DemCase(case, dem, dem_stderr, 1, vibrated_mass_kg=0.3, sdc_stderr_dof=dem_dof)
    aligned = AlignedCase(case, "grid", dem, dem_stderr, grid)
    return CaseComparison(case, pd.DataFrame(), measured, measured_stderr, aligned,
                          pd.DataFrame(), pd.DataFrame(), np.empty(0), np.empty(0),
                          measured_sdc_eq10=measured, measured_stderr_eq10=measured_stderr,
                          measured_stderr_dof=measured_dof,
                          measured_stderr_eq10_dof=measured_dof)


def test_the_count_of_agreeing_cases_uses_the_stated_95_percent_interval():
    # (measured, stderr, dof, DEM, stderr, dof); the hand count: |Δ| / σ against Student
    # t_0.975 of Welch-Satterthwaite's dof (1.96 where none is known). Cases 1 and 4 lie at
    # 2.2 σ: inside t's wider interval, outside the old "2 σ"; case 2 at 1.98 σ with no
    # degrees of freedom lies outside the normal's 1.96 though "within 2 σ"
    nan = math.nan
    cases = [(0.300, 0.010, 7.0, 0.300 + 2.2 * math.hypot(0.010, 0.010), 0.010, 3.0),
             (0.500, 0.020, nan, 0.500 - 1.98 * 0.020, 0.0, nan),
             (0.400, 0.010, 7.0, 0.400 + 0.5 * math.hypot(0.010, 0.005), 0.005, 3.0),
             (0.200, 0.030, 7.0, 0.200 + 2.2 * 0.030, nan, nan),
             (0.600, 0.010, 7.0, 0.600 + 4.0 * math.hypot(0.010, 0.020), 0.020, 3.0),
             (0.250, 0.010, nan, 0.250 + 1.5 * math.hypot(0.010, 0.010), 0.010, 3.0)]
    by_hand = []
    for m, m_se, m_dof, dem, dem_se, dem_dof in cases:
        parts = [(m_se, m_dof)] + ([(dem_se, dem_dof)] if math.isfinite(dem_se) else [])
        sigma = math.sqrt(sum(se**2 for se, _ in parts))
        by_hand.append(abs(m - dem) <= _ws_quantile(parts) * sigma)
    heads = [headline(_comparison(*c)) for c in cases]
    assert by_hand == [True, False, True, True, False, True]
    assert [h.agrees for h in heads] == by_hand
    assert sum(h.agrees is True for h in heads) == sum(by_hand) == 4
    # each verdict states the same check its count made
    assert [h.verdict.startswith("agrees") for h in heads] == by_hand
    for h in heads:
        assert f"±{h.interval_sigmas:.3g} σ" in h.verdict
        assert h.basis.count(f"±{h.interval_sigmas:.3g} σ: ") == 1  # the same interval


def test_model_curve_is_drawn_for_a_case_a_hair_below_the_grid_edge():
    # 49.999998 Hz lies 4e-8 outside the model's 50-1000 Hz: within the grid tolerance, so the
    # curve is drawn at 50 Hz with a note, never dropped silently
    rec = _analysis(mass_damper_csv(frequency_hz=50.0))
    entry = _entry(rec)
    edge = MeasuredEntry(**{**entry.__dict__, "load_case": entry.load_case.__class__(
        49.999998, 5.0, 50.0)})
    comp = compare_case([edge], None, paper_table())
    assert comp.model_sdc.size > 0
    assert any("edge of its range" in n for n in comp.notes)
    # pchip through the paper's DEM values at 50 Hz, 5 g
    at = np.interp(comp.paper_points["packing ratio [%]"], comp.model_fill_percent, comp.model_sdc)
    np.testing.assert_allclose(at, comp.paper_points["SDC DEM (paper) [-]"], rtol=2e-2)


def test_a_negative_loss_factor_within_its_noise_is_a_note_not_a_warning():
    # the app asked to confirm an undamped record whose noise made its SDC -0.04 +- 0.05,
    # as if it were a wrong delay; beyond 3 standard errors it is still a warning
    from types import SimpleNamespace

    from pidcore.compare.plausibility import NEGATIVE_WITHIN_STDERRS, implausible_findings

    def analysis(sdc, stderr):
        return SimpleNamespace(complex_power_w=complex(sdc, 2 * math.pi), loss_factor=sdc / (
            2 * math.pi), sdc=sdc, sdc_stderr=stderr, omega_rad_s=2 * math.pi * 100)

    edge = -NEGATIVE_WITHIN_STDERRS * 0.01
    warnings, notes = implausible_findings(analysis(edge, 0.01))
    assert warnings == () and "zero within its uncertainty" in notes[0]
    warnings, notes = implausible_findings(analysis(edge * 1.01, 0.01))
    assert [w.check for w in warnings] == ["negative_loss_factor"] and notes == ()
    # no standard error known: no noise to read it as, a warning
    warnings, _ = implausible_findings(analysis(-1e-6, math.nan))
    assert [w.check for w in warnings] == ["negative_loss_factor"]


def _bare_analysis(real_w: float, imag_w: float, sdc_stderr: float):
    """The fields the plausibility checks read, of a record with complex power P."""
    from types import SimpleNamespace

    eta = real_w / imag_w
    return SimpleNamespace(complex_power_w=complex(real_w, imag_w), loss_factor=eta,
                           sdc=2 * math.pi * eta, omega_rad_s=2 * math.pi * 100.0,
                           sdc_stderr=sdc_stderr)


def test_a_loss_factor_of_round_off_is_zero_damping_not_a_set_up_error():
    # a noise-free undamped record (pidcore analyze of F = m a exactly) gave Re P = -1.25e-16 W
    # of Im P 0.574 W and a block standard error of round-off (3.5e-16): it was refused as
    # "negative loss factor -2.18e-16 ... a vibrometer delay of about 0 µs"
    from pidcore.compare.plausibility import implausible_findings

    warnings, notes = implausible_findings(_bare_analysis(-1.25e-16, 0.574, 3.5e-16))
    assert warnings == ()
    assert len(notes) == 1 and "zero within round-off" in notes[0]
    # beyond round-off (1e-6 |P|) and beyond its standard error it is still refused
    warnings, _ = implausible_findings(_bare_analysis(-0.574e-6, 0.574, 3.5e-16))
    assert [w.check for w in warnings] == ["negative_loss_factor"]


def _force_acceleration_csv(path, *, lag_s: float, loss_factor: float = 0.02) -> None:
    """``Time [s],Force [N],Acceleration [g]`` of a 0.3 kg mass-damper at 100 Hz, 5 g, the
    acceleration recorded ``lag_s`` after the force (no velocity channel)."""
    fs, freq, mass = 5120.0, 100.0, 0.3
    w = 2 * math.pi * freq
    t = np.arange(int(2 * fs)) / fs
    v_amp = 5 * 9.80665 / w
    force = mass * v_amp * w * np.cos(w * t) + loss_factor * w * mass * v_amp * np.sin(w * t)
    acc_g = v_amp * w * np.cos(w * (t - lag_s)) / 9.80665
    rows = "\n".join(f"{a:.9g},{b:.9g},{c:.9g}" for a, b, c in zip(t, force, acc_g, strict=True))
    path.write_text("Time [s],Force [N],Acceleration [g]\n" + rows + "\n")


def test_a_record_without_a_vibrometer_is_not_told_to_correct_a_vibrometer_delay(tmp_path,
                                                                               capsys):
    # force and acceleration only (an impedance head), the acceleration 100 µs behind the
    # force: the negative loss factor was refused naming "an uncorrected vibrometer output
    # delay" and "a vibrometer delay of about 68 µs more", and --velocity-delay is then
    # refused for this very record ("a vibrometer delay needs a velocity channel")
    from pidcore.cli import main

    path = tmp_path / "impedance_head.csv"
    _force_acceleration_csv(path, lag_s=100e-6)
    assert main(["analyze", str(path), "--no-store", "--no-progress"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "impedance_head.csv" in err
    assert "negative loss factor" in err and "vibrometer delay" not in err
    assert "lag of the acceleration channel behind the force" in err
    # the lag that zeroes the loss factor: 100 µs less the 0.02 damping's own
    # atan(0.02)/w = 31.8 µs at 100 Hz; noise-free, so only the printed rounding (0.5 µs)
    tau_us = float(err.split("a lag of about ")[1].split(" µs")[0])
    assert tau_us == pytest.approx(100.0 - math.atan(0.02) / (2 * math.pi * 100) * 1e6, abs=0.6)
    assert main(["analyze", str(path), "--no-store", "--no-progress",
                 "--velocity-delay", f"{tau_us * 1e-6:g}"]) == 2
    assert "needs a velocity channel" in capsys.readouterr().err
    # a stored record of such a file (no velocity channel, an acceleration one) says the same
    from pidcore.compare.plausibility import stored_findings

    row = {"complex_power_real_w": -0.0246, "complex_power_imag_w": 0.574, "loss_factor": -0.0429,
           "sdc": -0.269, "sdc_stderr": 1e-9, "frequency_hz": 100.0, "velocity_channel": "",
           "acceleration_channel": "Acceleration"}
    (warning,), _ = stored_findings(row)
    assert "vibrometer delay" not in warning.likely_cause
    assert "lag of the acceleration channel" in warning.likely_cause
    (warning,), _ = stored_findings({**row, "velocity_channel": "LDV"})
    assert "vibrometer delay of about" in warning.likely_cause


def test_an_sdc_above_the_bound_without_a_vibrometer_names_the_channels_lead(tmp_path, capsys):
    # the acceleration 300 µs ahead of the force inflates a loss factor of 0.95 to 1.39: the
    # cause named "a wrong vibrometer delay" for a record that has no vibrometer
    from pidcore.cli import main

    path = tmp_path / "impedance_head.csv"
    _force_acceleration_csv(path, lag_s=-300e-6, loss_factor=0.95)
    assert main(["analyze", str(path), "--no-store", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "above the physical bound" in err and "vibrometer" not in err
    assert "lead of the acceleration channel over the force" in err


def test_the_paper_curve_over_table3s_gap_says_it_is_held_not_the_papers():
    # Table 3 prints no DEM value at 1000 Hz, 1 g, 90 %: the model holds the 75 % value
    # (0.8078) there, and the Compare page drew that flat stretch as the paper's curve
    rec = _analysis(mass_damper_csv(frequency_hz=50.0))
    entry = _entry(rec)
    at_gap = MeasuredEntry(**{**entry.__dict__, "load_case": entry.load_case.__class__(
        1000.0, 1.0, 50.0)})
    comp = compare_case([at_gap], None, paper_table())
    assert comp.model_sdc[-1] == pytest.approx(0.8078, rel=1e-12)  # the held 75 % value
    assert ("the paper's pchip curve has no Table 3 DEM value at 1000 Hz, 1 g, 90 %: the model "
            "holds the nearest printed fill's SDC there, not a value of the paper's") in comp.notes
    # where every point of the curve is printed, no such note
    full = MeasuredEntry(**{**entry.__dict__, "load_case": entry.load_case.__class__(
        500.0, 1.0, 50.0)})
    assert not any("no Table 3 DEM value" in n for n in compare_case([full], None,
                                                                       paper_table()).notes)


def test_an_interpolated_case_is_judged_like_for_like_as_the_report_judges_it():
    # 70 Hz, 7 g, 50 % lies between the bundled DEM grid's points: the report's row gives the
    # Eq. 10 SDC over the m_c a run at 50 % would have (11 spheres per cell), the Compare
    # headline said "not comparable: the DEM case has no m_c for the Eq. 10 energy"
    from pathlib import Path

    from pidcore.store import Store
    from pidcore.units import g_to_si

    bundled = Path(__file__).resolve().parents[1] / "data_samples" / "dem_table3.h5"
    runs = Store(bundled).list_dem_runs()
    rec = _analysis(mass_damper_csv(frequency_hz=70.0, acceleration_g=7.0))
    comp = compare_case([_entry(rec)], runs, paper_table())
    assert comp.aligned.status == "interpolated"
    # a run at 50 % holds the same 11 spheres, so its m_c is the one (any 50 % run's)
    m_c = float(runs.loc[runs["fill_percent"] == 50.0, "vibrated_mass_kg"].iloc[0])
    w = 2 * math.pi * rec.analysis.frequency_hz
    eq10 = rec.analysis.energy_per_cycle_j / (
        m_c * g_to_si(rec.analysis.acceleration_g) ** 2 / (2 * w ** 2))
    assert comp.measured_sdc_eq10 == pytest.approx(eq10, rel=1e-12)
    head = headline(comp)
    assert head.measured_kind == "Eq. 10 (DEM m_c)" and head.measured == comp.measured_sdc_eq10
    assert head.verdict.startswith(("agrees", "differs"))


def test_the_paper_curve_of_a_case_within_tolerance_of_a_grid_point_is_that_points():
    # the sample test at 500.0005 Hz, 4.99967 g is Table 3's 500 Hz, 5 g case (as the report
    # aligns it): its curve was drawn between the 500 and 1000 Hz grid points, leaning on the
    # 1000 Hz values by a part in a million, and its note named the 1000 Hz, 1 g, 90 % gap on
    # a 500 Hz, 5 g sheet
    rec = _analysis(mass_damper_csv(frequency_hz=50.0))
    entry = _entry(rec)
    near = MeasuredEntry(**{**entry.__dict__, "load_case": entry.load_case.__class__(
        500.0005, 4.99967, 50.0)})
    paper = paper_table()
    comp = compare_case([near], None, paper)
    assert not any("no Table 3 DEM value" in n for n in comp.notes), comp.notes
    assert any(n.startswith("model drawn at 500 Hz, 5 g: the case (500.0005 Hz, 4.99967 g) "
                            "lies at that grid point") for n in comp.notes), comp.notes
    # pchip passes through its nodes: the curve's ends are Table 3's printed 25 % and 90 %
    # values (to round-off; a part in a million off before)
    printed = paper[(paper["frequency_hz"] == 500.0) & (paper["acceleration_g"] == 5.0)]
    by_fill = dict(zip(printed["fill_percent"], printed["sdc_dem"], strict=True))
    assert (comp.model_sdc[0], comp.model_sdc[-1]) == pytest.approx(
        (by_fill[25.0], by_fill[90.0]), rel=1e-12)


@pytest.mark.parametrize("quantity", ["acceleration", "displacement"])
def test_a_velocity_channel_holding_another_quantity_is_named_before_the_sign_or_delay(
        quantity):
    """A rigid 0.1 kg mass at 500 Hz, loss factor 0.05, whose 'Velocity [m/s]' column holds
    its acceleration (read inverted, as --invert after the first refusal) or displacement:
    P turns by 90 degrees, a loss factor of -1/0.05 = -20, which was refused as 'a vibrometer
    delay of about 484 µs'. The vibrated mass Im(P)/(w |V|^2 / 2) is then eta m / w = 1.6 mg
    or eta m w = 15.7 kg, off the paper coupon's by far more than the factor 20 allowed: the
    first finding, the one a refusal names, is that unit slip."""
    from pidcore.compare.plausibility import sdc_bound

    f, m, eta = 500.0, 0.1, 0.05
    w = 2 * math.pi * f
    t = np.arange(20000) / 51200.0
    v = 5 * 9.80665 / w * np.cos(w * t)
    force = -m * 5 * 9.80665 * np.sin(w * t) + eta * m * w * v
    motion = (5 * 9.80665 * np.sin(w * t) if quantity == "acceleration"  # -a
              else 5 * 9.80665 / w**2 * np.sin(w * t))  # x
    csv = "Time [s],Force [N],Velocity [m/s]\n" + "".join(
        f"{a:.17g},{b:.17g},{c:.17g}\n" for a, b, c in zip(t, force, motion, strict=True))
    analysis = _analysis(csv.encode()).analysis
    assert analysis.loss_factor == pytest.approx(-1 / eta, rel=1e-6)
    found = check_analysis(analysis, bound=sdc_bound(fill_percent=50.0))
    assert found[0].check == "vibrated_mass_off"
    assert "negative_loss_factor" in [w.check for w in found[1:]]
    assert "a velocity channel that holds an acceleration or a displacement" in str(found[0])
