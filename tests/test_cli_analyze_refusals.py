"""``pidcore analyze`` refuses out-of-range corrections and unusable inputs: one line naming
the CLI flag, exit 2, the store byte-identical."""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np
import pytest
from _shaker_files import file_sha256, write_force_velocity

from pidcore.cli import main
from pidcore.constants import STANDARD_GRAVITY
from pidcore.signal.synthetic import synthesize_shaker_record

MASS, FREQ, FS = 0.25, 100.0, 25_600.0
C_VISCOUS = 2.0
ACCEL = 5 * STANDARD_GRAVITY


def truth_loss_factor() -> float:
    """Rigid mass with viscous damping: c / (m w)."""
    return C_VISCOUS / (MASS * 2 * math.pi * FREQ)


def export(path: Path, *, n_periods: float = 15.0) -> Path:
    rec = synthesize_shaker_record(mass_kg=MASS, acceleration_amplitude_m_s2=ACCEL,
                                   frequency_hz=FREQ, sample_rate_hz=FS, n_periods=n_periods,
                                   viscous_damping_n_s_m=C_VISCOUS, snr_db=60, seed=5)
    return write_force_velocity(path, rec.force_n, rec.velocity_m_s, FS)


@pytest.fixture
def record_and_store(tmp_path, capsys):
    path = export(tmp_path / "rec.csv")
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--store", str(store)]) == 0
    capsys.readouterr()
    return path, store


def _refused(args: list[str], store: Path, capsys) -> str:
    before = file_sha256(store)
    assert main(["analyze", *args, "--store", str(store)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert file_sha256(store) == before
    return err


# 15 periods of 100 Hz: 0.15 s, a drive period of 10 ms; 1 s is a unit slip (ms typed as s).
@pytest.mark.parametrize("delay", ["-1", "-2e-4", "1", "0.15"])
def test_velocity_delay_negative_or_beyond_a_few_periods_is_refused(record_and_store, capsys,
                                                                    delay):
    path, store = record_and_store
    err = _refused([str(path), f"--velocity-delay={delay}"], store, capsys)
    assert "--velocity-delay" in err and "velocity_delay_s" not in err
    if delay.startswith("-"):
        assert f"--velocity-delay: {float(delay):g} s, expected a delay >= 0 s" in err


def test_a_real_vibrometer_delay_is_accepted(record_and_store, capsys):
    path, store = record_and_store
    assert main(["analyze", str(path), "--velocity-delay", "2e-4", "--no-store"]) == 0


@pytest.mark.parametrize("baseline", ["-3", "-0.001"])
def test_negative_baseline_loss_factor_is_refused(record_and_store, capsys, baseline):
    path, store = record_and_store
    err = _refused([str(path), f"--baseline-loss-factor={baseline}"], store, capsys)
    assert "baseline" in err.lower()


# the record's loss factor is c / (m w) = 0.0127; 5 and a value 1 % above it leave no damping
@pytest.mark.parametrize("factor", [5.0, 1.01])
def test_baseline_at_or_above_the_measured_loss_factor_is_refused(record_and_store, capsys,
                                                                  factor):
    path, store = record_and_store
    baseline = f"{factor * truth_loss_factor():.6g}"
    err = _refused([str(path), f"--baseline-loss-factor={baseline}"], store, capsys)
    assert "baseline" in err.lower() and "rec.csv" in err


def test_a_baseline_below_the_loss_factor_is_subtracted(record_and_store, capsys):
    path, _ = record_and_store
    assert main(["analyze", str(path), "--no-store", "--json"]) == 0
    import json

    plain = json.loads(capsys.readouterr().out)["records"][0]["loss_factor"]
    assert main(["analyze", str(path), "--no-store", "--json",
                 "--baseline-loss-factor", "0.002"]) == 0
    minus = json.loads(capsys.readouterr().out)["records"][0]["loss_factor"]
    assert minus == pytest.approx(plain - 0.002, rel=1e-12)  # same record, exact arithmetic


def test_a_store_without_measurements_says_what_it_holds(tmp_path, capsys):
    import h5py

    # the layout of a store that holds only DEM runs (data_samples/dem_table3.h5)
    path = tmp_path / "dem_only.h5"
    with h5py.File(path, "w") as h5:
        h5.create_group("measurements")
        h5.create_group("analyses")
        runs = h5.create_group("dem_runs")
        for i in range(3):
            runs.create_group(f"run{i}")
    assert main(["analyze", str(path), "--no-store"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "dem_only.h5" in err and "no measurements" in err and "3 dem_runs" in err


def test_a_store_with_several_measurements_names_the_key_option(tmp_path, capsys):
    import json

    a, b = export(tmp_path / "a.csv"), export(tmp_path / "b.csv", n_periods=20.0)
    store = tmp_path / "s.h5"
    assert main(["analyze", str(a), str(b), "--store", str(store)]) == 0
    capsys.readouterr()
    assert main(["analyze", str(store), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert "--key NAME" in err and "key=" not in err and len(err.strip().splitlines()) == 1
    # each key is named with the file it came from: "KEY (a.csv), KEY (b.csv)"
    listed = re.findall(r"([0-9a-f]{16}) \(([^)]*)\)", err)
    assert sorted(name for _, name in listed) == ["a.csv", "b.csv"]
    keys = [key for key, _ in listed]
    found = []
    for key in keys:
        assert main(["analyze", str(store), "--key", key, "--no-store", "--json"]) == 0
        found.append(json.loads(capsys.readouterr().out)["records"][0]["n_periods"])
    # the two keys read the two records (15 and 20 periods), not one of them twice
    assert sorted(round(n) for n in found) == [15, 20]
    assert main(["analyze", str(a), "--key", keys[0], "--no-store"]) == 2  # not a store
    assert "--key" in capsys.readouterr().err


@pytest.mark.parametrize("args,flag,keyword", [
    (["--frequency", "20000"], "--frequency", "frequency_hz"),  # above Nyquist (12.8 kHz)
    (["--harmonics", "0"], "--harmonics", "n_harmonics"),
    (["--sample-rate=-5"], "--sample-rate", "sample_rate_hz"),
    (["--mass-below-gauge=-1"], "--mass-below-gauge", "mass_below_gauge_kg"),
])
def test_errors_name_the_cli_flag_not_the_library_keyword(tmp_path, capsys, args, flag,
                                                          keyword):
    path = export(tmp_path / "rec.csv")
    assert main(["analyze", str(path), "--no-store", *args]) == 2
    err = capsys.readouterr().err
    assert flag in err and keyword not in err, err


def test_clipping_error_names_allow_clipped(tmp_path, capsys):
    import numpy as np

    rec = synthesize_shaker_record(mass_kg=MASS, acceleration_amplitude_m_s2=ACCEL,
                                   frequency_hz=FREQ, sample_rate_hz=FS, n_periods=20)
    force = np.minimum(rec.force_n, 0.9 * float(np.max(rec.force_n)))
    path = tmp_path / "clipped.csv"
    write_force_velocity(path, force, rec.velocity_m_s, FS)
    assert main(["analyze", str(path), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert "--allow-clipped" in err and "allow_clipped" not in err


def test_too_large_mass_below_gauge_is_named_as_a_cause(tmp_path, capsys):
    # the coupon is 0.25 kg: cancelling 10 kg of inertia leaves Im(P_c) < 0
    path = export(tmp_path / "rec.csv")
    assert main(["analyze", str(path), "--no-store", "--mass-below-gauge", "10"]) == 2
    err = capsys.readouterr().err
    assert "--mass-below-gauge 10 kg" in err and "larger" in err and "inverted" in err
    # without mass cancellation an inverted channel is the only cause named
    assert main(["analyze", str(path), "--no-store", "--invert", "Force"]) == 2
    err = capsys.readouterr().err
    assert "inverted" in err and "--mass-below-gauge" not in err


@pytest.mark.parametrize("args,words", [
    (["analyze", "x.csv", "--bogus"], ["pidcore analyze: error:", "--bogus"]),
    (["analyze"], ["pidcore analyze: error:", "PATH"]),
    (["analyze", "x.csv", "--harmonics", "z"], ["pidcore analyze: error:", "--harmonics"]),
])
def test_usage_errors_are_one_line_naming_the_sub_command(capsys, args, words):
    with pytest.raises(SystemExit) as stop:
        main(args)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err  # no usage block
    for word in words:
        assert word in err


@pytest.mark.parametrize("how", ["option", "file name", "sidecar"])
def test_a_fill_that_puts_no_particle_in_a_cell_is_refused(tmp_path, capsys, how):
    # `analyze --fill 0.5` (50 % typed as a fraction) was saved as a 0.5 % load case, which
    # no DEM run can be made at (0.11 of the paper cell's 22 particles) and no report places
    from pidcore.specimen import paper_specimen

    capacity = paper_specimen().capacity_per_cell()
    fill = 0.5
    assert round(fill / 100 * capacity) == 0  # the premise: half a percent is no particle
    name = "rec_fill0.5pct.csv" if how == "file name" else "rec.csv"
    path = export(tmp_path / name)
    args = ["analyze", str(path), "--store", str(tmp_path / "s.h5")]
    if how == "option":
        args += ["--fill", str(fill)]
    if how == "sidecar":
        (tmp_path / "loadcases.csv").write_text(f"file,fill_percent\n{name},{fill}\n")
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    source = {"option": "--fill", "file name": "file name", "sidecar": "loadcases.csv"}[how]
    assert f"{name}: fill 0.5 % of {capacity} particles rounds to none" in err
    assert f"(fill: {source}" in err and "was 0.5 meant as 50 %?" in err
    assert not (tmp_path / "s.h5").exists()  # nothing written


def test_the_smallest_fill_holding_a_particle_is_saved(tmp_path, capsys):
    # the refusal's own bound: the least fill it names rounds to one particle and is kept
    import re

    path = export(tmp_path / "rec.csv")
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--store", str(store), "--fill", "1"]) == 2
    least = re.search(r"expected >= ([0-9.]+) %", capsys.readouterr().err).group(1)
    assert main(["analyze", str(path), "--store", str(store), "--fill", least]) == 0
    assert f"fill{least}pct" in capsys.readouterr().out


def _damped_export(path: Path, damping: float, *, snr_db: float = 60) -> Path:
    rec = synthesize_shaker_record(mass_kg=MASS, acceleration_amplitude_m_s2=ACCEL,
                                   frequency_hz=FREQ, sample_rate_hz=FS, n_periods=15,
                                   viscous_damping_n_s_m=damping, snr_db=snr_db, seed=5)
    return write_force_velocity(path, rec.force_n, rec.velocity_m_s, FS)


def test_a_negative_loss_factor_beyond_its_noise_is_refused_unless_accepted(tmp_path, capsys):
    # the CLI saved SDC -0.08 (energy created per cycle, 10^4 standard errors below zero)
    # with only a note, where the app warns and asks for confirmation before it saves
    from pidcore.store import Store

    path = _damped_export(tmp_path / "rec_fill50.csv", -C_VISCOUS)
    store = tmp_path / "s.h5"
    for command in (["analyze", str(path), "--store", str(store)],
                    ["report", str(path), "--store", str(store), "--out", str(tmp_path / "r"),
                     "--format", "csv"]):
        assert main(command) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1
        assert "rec_fill50.csv: implausible: negative loss factor" in err
        assert "Likely cause:" in err and "pass --accept-implausible" in err
        assert not store.exists() and not (tmp_path / "r").exists()  # nothing written
    assert main(["analyze", str(path), "--store", str(store), "--accept-implausible"]) == 0
    assert "note: implausible, kept as asked: negative loss factor" in capsys.readouterr().out
    (key,) = Store(store).list_analyses()["key"]
    assert -truth_loss_factor() == pytest.approx(
        Store(store).get_analysis(key).record["loss_factor"], rel=0.03)


def test_a_negative_loss_factor_within_its_noise_is_zero_damping_not_refused(tmp_path, capsys):
    # an undamped coupon at 20 dB: its loss factor scatters about 0 and may come out
    # slightly negative; that is no damping resolved, not a set-up error
    import json

    negative = 0
    for damping in (0.0, -1e-4, 1e-4):
        path = _damped_export(tmp_path / f"rec{damping}.csv", damping, snr_db=20)
        assert main(["analyze", str(path), "--no-store", "--json"]) == 0
        (rec,) = json.loads(capsys.readouterr().out)["records"]
        # within 3 standard errors of zero, whatever its sign
        assert abs(rec["sdc"]) <= 3 * rec["sdc_stderr"]
        if rec["sdc"] < 0:
            negative += 1
            assert any("zero within its uncertainty" in n for n in rec["notes"])
    assert negative  # the premise: this noise (seed 5) makes the SDC come out negative


def test_an_sdc_above_2_pi_is_refused_unless_accepted(tmp_path, capsys):
    # loss factor c / (m w) = 200 / (0.25 x 2 pi x 100) = 1.27: SDC 8.0 > 2 pi, more
    # dissipated per radian than the coupon stores; with no fill stated the particles' mass
    # is not known, and 2 pi is the bound
    damping = 200.0
    assert damping / (MASS * 2 * math.pi * FREQ) * 2 * math.pi > 2 * math.pi
    path = _damped_export(tmp_path / "rec.csv", damping)
    assert main(["analyze", str(path), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert "implausible: SDC 7.99" in err and "above the physical bound 6.28" in err
    assert main(["analyze", str(path), "--no-store", "--accept-implausible"]) == 0


def test_a_report_of_the_store_says_again_that_a_stored_result_was_kept_implausible(tmp_path,
                                                                                   capsys):
    # a result saved with --accept-implausible (SDC 20 above the paper coupon's bound at 50 %,
    # 8 m_p/m_s = 16.9) was reported from the store later as an ordinary measured SDC: report
    # FILES noted it, report --store said nothing
    damping = 500.0
    path = _damped_export(tmp_path / "rec_fill50.csv", damping)
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--store", str(store), "--accept-implausible"]) == 0
    capsys.readouterr()
    out = tmp_path / "r"
    assert main(["report", "--store", str(store), "--out", str(out), "--format", "csv"]) == 0
    said = capsys.readouterr().out
    provenance = (out / "report.provenance.txt").read_text(encoding="utf-8")
    for text in (said, provenance):
        assert "rec_fill50.csv: implausible, saved as accepted (--accept-implausible): " \
            "SDC 20" in text, text


def test_a_record_saved_as_implausible_is_named_so_by_a_report_of_the_store(tmp_path, capsys):
    # analyze --accept-implausible noted it, but the store keeps numbers, not notes: a later
    # report --store pooled its SDC (-0.16, energy created) into the row without a word
    path = _damped_export(tmp_path / "rec_fill50.csv", -C_VISCOUS)
    good = _damped_export(tmp_path / "ok_fill50.csv", C_VISCOUS)
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), str(good), "--store", str(store),
                 "--accept-implausible"]) == 0
    capsys.readouterr()
    assert main(["report", "--store", str(store), "--out", str(tmp_path / "r"),
                 "--format", "csv"]) == 0
    out = capsys.readouterr().out
    flagged = [ln for ln in out.splitlines() if "implausible, saved as accepted" in ln]
    assert len(flagged) == 1 and flagged[0].startswith("note: rec_fill50.csv: ")
    assert "negative loss factor" in flagged[0]
    provenance = (tmp_path / "r" / "report.provenance.txt").read_text(encoding="utf-8")
    assert "rec_fill50.csv: implausible, saved as accepted" in provenance
    assert "ok_fill50.csv: implausible" not in provenance


def test_a_fraction_hint_offers_only_a_fill_that_holds_a_particle(tmp_path, capsys):
    # --fill 1e-9 was asked "was 1e-09 meant as 1e-07 %?": a fill that rounds to none too
    from pidcore.specimen import paper_specimen

    capacity = paper_specimen().capacity_per_cell()
    path = export(tmp_path / "rec.csv")
    for fill in ("1e-9", "0.01"):
        assert round(float(fill) * 100 / 100 * capacity) == 0  # x100 holds none either
        assert main(["analyze", str(path), "--no-store", "--fill", fill]) == 2
        err = capsys.readouterr().err
        assert "meant as" not in err and "a fill is a percentage of the cell's capacity" in err
    assert main(["analyze", str(path), "--no-store", "--fill", "0.5"]) == 2
    assert "was 0.5 meant as 50 %?" in capsys.readouterr().err


@pytest.mark.parametrize("store_existed", [False, True])
def test_ctrl_c_after_the_analyses_were_saved_says_so(tmp_path, capsys, monkeypatch,
                                                      store_existed):
    # report FILES --store saves the analyses, then writes the report; a Ctrl-C in the write
    # said "no store write was left half-done" alone, as if nothing had been saved
    import pidcore.report.pipeline as pipeline
    from pidcore.store import Store

    path = export(tmp_path / "rec_fill50.csv")
    store = tmp_path / "s.h5"
    if store_existed:
        assert main(["analyze", str(export(tmp_path / "other_fill25.csv", n_periods=20)),
                     "--store", str(store)]) == 0
        capsys.readouterr()

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(pipeline, "write_report", interrupted)
    assert main(["report", str(path), "--store", str(store), "--out", str(tmp_path / "r"),
                 "--format", "csv"]) == 130
    err = capsys.readouterr().err
    assert len(Store(store).list_analyses()) == 1 + store_existed  # saved, whole
    assert f"the analyses of the 1 file(s) were saved to {store} before it (whole)" in err
    assert "unchanged" not in err


def test_every_implausible_file_of_a_batch_is_named_in_one_refusal(tmp_path, capsys):
    # with two implausible files among three only the first was named: the user fixed it,
    # ran again, and only then learnt of the second
    bad_a = _damped_export(tmp_path / "a_fill50.csv", -C_VISCOUS)
    good = _damped_export(tmp_path / "b_fill50.csv", C_VISCOUS)
    # SDC 20 > 16.9, the paper coupon's bound at 50 % (8 m_p/m_s)
    bad_c = _damped_export(tmp_path / "c_fill50.csv", 500.0)
    store = tmp_path / "s.h5"
    assert main(["analyze", str(bad_a), str(good), str(bad_c), "--store", str(store)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1  # (and "--accept-implausible" at its end)
    assert "a_fill50.csv: implausible: negative loss factor" in err
    assert "also implausible: c_fill50.csv" in err and "b_fill50.csv" not in err
    assert not store.exists()


def test_a_row_pooling_a_stored_implausible_result_says_so_and_judges_no_band(tmp_path,
                                                                             capsys):
    # report --store pooled an SDC of 20 (> 16.9, the paper coupon's bound at 50 %, kept with
    # --accept-implausible) with a
    # good one of the same case: the CSV row showed their mean with no word of it (the note
    # was apart from the rows), and its standard error, the scatter of the impossible SDC
    # about the good one, made the calibrated band wide enough to read 'inside', where
    # calibrate --store leaves that record out
    import json

    import pandas as pd

    from pidcore.report.table import CALIBRATED_INSIDE_COLUMN, NOT_COMPARED

    bad = _damped_export(tmp_path / "rec_fill50.csv", 500.0)
    good = _damped_export(tmp_path / "ok_fill50.csv", C_VISCOUS)
    store = tmp_path / "s.h5"
    assert main(["analyze", str(bad), str(good), "--store", str(store),
                 "--accept-implausible"]) == 0
    calibration = tmp_path / "calibration.json"
    calibration.write_text(json.dumps({
        "parameters": {"baseline_loss_factor": {"median": 0.01, "low95": 0.0, "high95": 0.02}},
        "predictions": [{"frequency_hz": FREQ, "acceleration_g": 5.0, "fill_percent": 50.0,
                         "material": "acrylic", "measured": 0.5, "predicted": 0.5,
                         "measured_stderr": 0.01, "low95": 0.4, "high95": 0.6,
                         "low95_without_stderr": 0.41, "high95_without_stderr": 0.59}]}),
        encoding="utf-8")
    capsys.readouterr()
    out = tmp_path / "r"
    assert main(["report", "--store", str(store), "--calibration", str(calibration),
                 "--out", str(out), "--format", "csv"]) == 0
    table = pd.read_csv(out / "report.csv")
    (pooled,) = (r for _, r in table[table["SDC measured (Eq. 11) [-]"].notna()].iterrows())
    # the premise: both records pooled, the mean's standard error wide enough for the band
    # of its own stderr to hold the mean (the old verdict 'yes')
    assert "2 measurements pooled" in pooled["note"]
    assert pooled["SDC measured (Eq. 11) [-]"] > 2 * math.pi / 2
    assert pooled["calibrated high 95 % [-]"] >= pooled["SDC measured (Eq. 11) [-]"]
    assert pooled[CALIBRATED_INSIDE_COLUMN] == NOT_COMPARED
    assert "kept as accepted: rec_fill50.csv (SDC 20" in pooled["note"]
    assert "ok_fill50.csv (" not in pooled["note"]


def _export_without_velocity(path: Path) -> Path:
    """Force and acceleration only (no vibrometer): the velocity comes from the acceleration."""
    from pidcore.io import write_measurement
    from pidcore.records import Channel, Measurement

    rec = synthesize_shaker_record(mass_kg=MASS, acceleration_amplitude_m_s2=ACCEL,
                                   frequency_hz=FREQ, sample_rate_hz=FS, n_periods=15.0,
                                   viscous_damping_n_s_m=C_VISCOUS, snr_db=60, seed=5)
    acceleration = np.gradient(rec.velocity_m_s, 1.0 / FS)
    write_measurement(Measurement(path.name, (
        Channel("Force", "force", rec.force_n, FS, "N"),
        Channel("Acc", "acceleration", acceleration, FS, "m/s^2"))), path, "csv")
    return path


@pytest.mark.parametrize("option, refused_file, said", [
    # the second file of the batch has no vibrometer: the delay given for every file cannot
    # apply to it ("--velocity-delay: a vibrometer delay needs a velocity channel" named no file)
    (["--velocity-delay", "2e-4"], "acc_only.csv", "--velocity-delay: a vibrometer delay needs "
     "a velocity channel"),
    # 0.1 s is beyond 4 periods of 100 Hz (0.04 s) of both files; the first one is refused
    (["--velocity-delay", "0.1"], "rec.csv", "--velocity-delay: 0.1 s is longer than 4 drive "
     "periods of 100 Hz"),
    # a hint above the Nyquist frequency of the files' rate (12.8 kHz)
    (["--frequency", "20000"], "rec.csv", "--frequency: 20000 Hz is not below the Nyquist "
     "frequency 12800 Hz"),
])
def test_a_per_file_refusal_of_an_option_names_the_file(tmp_path, capsys, option, refused_file,
                                                         said):
    # an option applies to every file of a batch, and these refusals depend on the file (its
    # channels, drive frequency, sample rate): without the file's name the user of a batch
    # could not tell which export to look at
    store = tmp_path / "s.h5"
    first = export(tmp_path / "rec.csv")
    assert main(["analyze", str(first), "--store", str(store), "--no-progress"]) == 0
    capsys.readouterr()
    second = _export_without_velocity(tmp_path / "acc_only.csv")
    err = _refused([str(first), str(second), *option, "--no-progress"], store, capsys)
    assert f"{tmp_path / refused_file}: {said}" in err, err


def test_a_store_name_too_long_for_its_working_copy_is_refused_before_any_analysis(tmp_path,
                                                                                   capsys):
    # 235 + 3 bytes: the working copy's name (+22 bytes) is over 255; refused after the
    # analyses, as "OSError: [Errno 36] File name too long" from the copy's removal
    path = export(tmp_path / "rec.csv")
    store = tmp_path / ("s" * 235 + ".h5")
    assert main(["analyze", str(path), "--store", str(store)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and len(err.strip().splitlines()) == 1, err
    assert f"{store.name}: the store's name is 238 bytes, too long for the working copy" in err
    assert "at most 233 bytes" in err
    assert os.listdir(tmp_path) == ["rec.csv"]


def test_a_pipe_is_refused_as_no_regular_file_not_as_a_file_not_found(record_and_store,
                                                                       capsys):
    # `analyze <(cat rec.csv)`: the shell passes /dev/fd/N, a pipe; its first bytes were read
    # to detect the format and it was then called "file not found"
    path, store = record_and_store
    read_end, write_end = os.pipe()
    try:
        os.write(write_end, path.read_bytes()[:4096])  # within a pipe's buffer: no reader needed
        os.close(write_end)
        err = _refused([f"/dev/fd/{read_end}"], store, capsys)
    finally:
        os.close(read_end)
    assert err == (f"pidcore analyze: error: /dev/fd/{read_end}: not a regular file (a pipe?); "
                   "give a file\n")
