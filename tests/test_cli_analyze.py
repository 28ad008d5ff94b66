"""End to end: ``pidcore analyze`` on exported files, JSON contract, store, bad input."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from _shaker_files import file_sha256, write_force_velocity

from pidcore.cli import main
from pidcore.constants import STANDARD_GRAVITY
from pidcore.io import write_measurement
from pidcore.records import Channel, Measurement
from pidcore.signal.synthetic import synthesize_shaker_record
from pidcore.store import Store

MASS, FREQ, FS = 0.25, 100.0, 25_600.0
ACCEL = 5 * STANDARD_GRAVITY
C_VISCOUS, F_COULOMB = 2.0, 0.3


def truth_loss_factor() -> float:
    """Rigid mass with viscous + Coulomb damping: energy per cycle over 2 pi E_kin."""
    w = 2 * math.pi * FREQ
    v = ACCEL / w
    x = v / w
    dissipated = math.pi * C_VISCOUS * w * x**2 + 4 * F_COULOMB * x
    return dissipated / (2 * math.pi * 0.5 * MASS * v**2)


def export(path: Path, *, fmt: str, force_unit_scale: float = 1.0, binary: bool = False,
           corrupt_velocity: bool = False) -> Path:
    rec = synthesize_shaker_record(mass_kg=MASS, acceleration_amplitude_m_s2=ACCEL,
                                   frequency_hz=FREQ, sample_rate_hz=FS, n_periods=40.3,
                                   viscous_damping_n_s_m=C_VISCOUS,
                                   coulomb_friction_n=F_COULOMB, snr_db=50, seed=3)
    velocity = rec.velocity_m_s.copy()
    if corrupt_velocity:
        velocity[100] = np.nan
    write_force_velocity(path, rec.force_n * force_unit_scale, velocity, FS, fmt, binary=binary)
    return path


def run_json(args: list[str], capsys) -> dict:
    assert main(["analyze", *args, "--json"]) == 0
    out = capsys.readouterr().out
    return json.loads(out)  # exactly one JSON document on stdout


@pytest.mark.parametrize("fmt,suffix,binary", [("csv", ".csv", False), ("uff", ".uff", False),
                                               ("uff", ".uff", True), ("mat", ".mat", False),
                                               ("hdf5", ".h5", False)])
def test_analyze_json_matches_analytic_truth(tmp_path, capsys, fmt, suffix, binary):
    path = export(tmp_path / f"rec{suffix}", fmt=fmt, binary=binary)
    doc = run_json([str(path), "--store", str(tmp_path / "s.h5")], capsys)
    (rec,) = doc["records"]
    assert set(rec) >= {"source", "frequency_hz", "acceleration_g", "complex_power_real_w",
                        "complex_power_imag_w", "loss_factor", "sdc", "sdc_stderr",
                        "damping_ratio", "energy_per_cycle_j"}
    # P_c once, each key naming its unit (a {"real", "imag"} pair duplicated it, unit-less)
    assert "complex_power" not in rec
    eta = truth_loss_factor()
    # issue tolerance: max(3 % relative, 1.5e-4 absolute) at 50 dB SNR
    assert abs(rec["loss_factor"] - eta) <= max(0.03 * eta, 1.5e-4)
    assert rec["sdc"] == pytest.approx(2 * math.pi * rec["loss_factor"], rel=1e-12)
    assert rec["frequency_hz"] == pytest.approx(FREQ, rel=1e-5)
    assert rec["acceleration_g"] == pytest.approx(5.0, rel=5e-3)  # 50 dB noise on velocity
    w = 2 * math.pi * FREQ
    # Re(P_c) = mean power = energy per cycle / T
    assert rec["energy_per_cycle_j"] == pytest.approx(rec["complex_power_real_w"]
                                                      / rec["frequency_hz"],
                                                      rel=1e-9)
    # Im(P_c) = w E_kin,max = w m V^2 / 2 for the rigid mass
    assert rec["complex_power_imag_w"] == pytest.approx(w * 0.5 * MASS * (ACCEL / w) ** 2,
                                                        rel=1e-2)
    zeta = -math.log(1 - rec["sdc"]) / (4 * math.pi)
    assert rec["damping_ratio"] == pytest.approx(zeta, rel=1e-12)


def test_store_keeps_one_copy_per_file_and_the_numbers(tmp_path, capsys):
    path = export(tmp_path / "rec.csv", fmt="csv")
    store_path = tmp_path / "s.h5"
    first = run_json([str(path), "--store", str(store_path)], capsys)
    run_json([str(path), "--store", str(store_path)], capsys)
    store = Store(store_path)
    assert len(store.list_measurements()) == 1
    analyses = store.list_analyses()
    assert len(analyses) == 1  # same parameters replace, never duplicate
    assert analyses["sdc"].iloc[0] == first["records"][0]["sdc"]
    assert analyses["frequency_hz"].iloc[0] == first["records"][0]["frequency_hz"]


def test_the_saved_count_is_of_records_not_of_files(tmp_path, capsys):
    # two byte-identical files are one record: it said "saved 2 record(s)"
    path = export(tmp_path / "a.csv", fmt="csv")
    (tmp_path / "b.csv").write_bytes(path.read_bytes())
    store_path = tmp_path / "s.h5"
    assert main(["analyze", str(path), str(tmp_path / "b.csv"), "--store",
                 str(store_path)]) == 0
    out = capsys.readouterr().out
    assert len(Store(store_path).list_analyses()) == 1
    assert (f"saved 1 record(s) (1 file(s) with the same contents as another file given: "
            f"one record) to {store_path}") in out


def test_saving_the_same_records_again_says_they_were_already_held(tmp_path, capsys):
    # the second `analyze FILES --store S` said "saved 2 record(s)" as the first did, though
    # it only rewrote what the store held
    a = export(tmp_path / "a_fill50.csv", fmt="csv")
    b = tmp_path / "b_fill50.csv"
    b.write_bytes(a.read_bytes().replace(b"\n", b"\r\n"))  # other bytes: another record
    store_path = tmp_path / "s.h5"
    argv = ["analyze", str(a), "--store", str(store_path)]
    assert main(argv) == 0
    assert f"saved 1 record(s) to {store_path}\n" in capsys.readouterr().out  # all new
    assert main([*argv[:2], str(b), *argv[2:]]) == 0
    assert (f"saved 2 record(s) to {store_path} (1 new, 1 already held with identical "
            "content)\n") in capsys.readouterr().out
    first = Store(store_path).list_analyses().set_index("key")
    assert main([*argv[:2], str(b), *argv[2:], "--json"]) == 0
    assert "saved 0 new, 2 already held with identical content" in \
        json.loads(capsys.readouterr().out)["notes"]
    again = Store(store_path).list_analyses().set_index("key")
    assert again.index.tolist() == first.index.tolist()  # the store semantics: replaced,
    assert again["sdc"].tolist() == first["sdc"].tolist()  # never duplicated
    # another load case for the same bytes is no identical content: replaced, and said so
    assert main([*argv, "--fill", "75"]) == 0
    out = capsys.readouterr().out
    assert (f"saved 1 record(s) to {store_path} (0 new, 1 replacing the held record of the "
            "same file under another name, load case or specimen, or one saved without a "
            "field saved now)\n") in out \
        and "replaces it" in out


def test_a_stated_load_case_is_saved_so_that_a_store_report_places_it(tmp_path, capsys):
    # `analyze` saved no load case (it had no way to), so `report --store` never showed a
    # measured row: "stored measurement(s) have no analysis stating a fill"
    from pidcore.report import make_report

    named = export(tmp_path / "coupon_fill50_acrylic.csv", fmt="csv")
    # no fill stated: still analysed and saved, without a case (its line ends differ, so its
    # bytes are another measurement's, not the named file's stating nothing)
    bare = tmp_path / "bare.csv"
    bare.write_bytes(named.read_bytes().replace(b"\n", b"\r\n"))
    store_path = tmp_path / "s.h5"
    assert main(["analyze", str(named), str(bare), "--store", str(store_path)]) == 0
    out = capsys.readouterr().out
    assert "coupon_fill50_acrylic.csv: load case f100Hz_a" in out and "fill: file name" in out
    assert "bare.csv: no fill stated: saved without a load case" in out
    stored = Store(store_path).list_analyses().set_index("source")
    assert stored.loc[str(named), "fill_percent"] == 50.0
    assert not np.isfinite(float(stored.loc[str(bare), "fill_percent"]))
    report = make_report([], out_dir=tmp_path / "rep", store=store_path, formats="csv")
    assert report.table["SDC measured (Eq. 11) [-]"].notna().sum() == 1
    # analysed again stating another fill: the saved record is replaced, and that is said
    assert main(["analyze", str(named), "--fill", "75", "--store", str(store_path)]) == 0
    out = capsys.readouterr().out
    assert "note: coupon_fill50_acrylic.csv has the same contents as the saved record " \
           "coupon_fill50_acrylic.csv (100 Hz, 5 g, 50 %, acrylic, z); saved as one record" in out
    assert Store(store_path).list_analyses().set_index("source").loc[
        str(named), "fill_percent"] == 75.0
    # --fill states it for every file; the JSON names each record's load case
    doc = run_json([str(bare), "--fill", "75", "--no-store"], capsys)
    assert doc["records"][0]["load_case"].startswith("f100Hz_a") and \
        "_fill75pct_acrylic_z" in doc["records"][0]["load_case"]


def test_a_file_saved_again_with_other_settings_says_which_result_reports_use_now(
        tmp_path, capsys):
    # the newest analysis of a measurement is the one report --store and calibrate --store
    # take: saved again without the vibrometer delay of the first save, it replaced a
    # delay-corrected SDC and "saved 1 record(s)" was all that was said
    from pidcore.store.listing import latest_per_measurement

    named = export(tmp_path / "coupon_fill50_acrylic.csv", fmt="csv")
    store_path = tmp_path / "s.h5"
    argv = ["analyze", str(named), "--store", str(store_path)]
    assert main([*argv, "--velocity-delay", "5e-5"]) == 0
    capsys.readouterr()
    assert main(argv) == 0
    out = capsys.readouterr().out
    listed = Store(store_path).list_analyses().sort_values("created_utc")
    first, second = (f"{v:.4g}" for v in listed["sdc"])
    assert first != second  # a 50 us delay at 100 Hz moves the phase by 1.8 degrees
    assert (f"note: coupon_fill50_acrylic.csv was saved before with other settings "
            f"(velocity_delay_s 5e-05 -> 0.0; SDC {first}); this analysis (SDC {second}) is "
            "the one reports and calibrations use now") in out
    newest = latest_per_measurement(Store(store_path).list_analyses())
    assert f"{float(newest['sdc'].iloc[0]):.4g}" == second  # what the note says is used
    # the same settings again: nothing replaced, and the save still says which is used (a
    # second save said nothing of it, as if the earlier analysis were gone)
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "use now" not in out
    assert (f"this analysis (SDC {second}) is still the one reports and calibrations use, the "
            "earlier is kept in the store") in out
    assert "(0 new, 1 already held with identical content)" in out


@pytest.mark.parametrize("scale", [1e-3, 1e3])
def test_a_force_in_another_unit_than_its_header_is_refused_by_the_vibrated_mass(
        tmp_path, capsys, scale):
    # a force in kN under a header of N keeps the Eq. 11 loss factor (a ratio) but makes the
    # energy per cycle 1000 x small: a report pooled Eq. 10 SDCs 1000 x apart with no word.
    # The record's vibrated mass, Im(P_c)/(omega |V|^2/2), is the rigid 0.25 kg x scale,
    # against the paper coupon's 22.15 g (a fill-named file is of the paper's coupon)
    path = export(tmp_path / "coupon_fill50_acrylic.csv", fmt="csv", force_unit_scale=scale)
    assert main(["analyze", str(path), "--no-store"]) == 2
    err = capsys.readouterr().err
    shown_g = float(err.split("(omega |V|^2/2) = ")[1].split(" g")[0])
    # the fundamental's mass: the drive is one sine; 0.5 % for the record's noise and the
    # friction's harmonics
    assert shown_g == pytest.approx(MASS * scale * 1e3, rel=5e-3)
    # what the paper's coupon can show: its 22.15 g structure below (m_s of Table 1's coupon),
    # with its 46.83 g of acrylic at 50 % above (22 x 441 spheres of r 1.25 mm, 1190 kg/m^3)
    assert "another unit than its header" in err
    assert ("below 1/20 of the specimen's coupon and fixture (22.15 g)" if scale < 1 else
            "over 20 x the specimen's coupon, fixture and particles (68.98 g)") in err
    # stated in its unit, it is the true record: the energy per cycle of the unscaled file
    unit = "kN" if scale == 1e-3 else "mN"
    doc = run_json([str(path), "--force-unit", unit, "--no-store"], capsys)
    truth = run_json([str(export(tmp_path / "true_fill50_acrylic.csv", fmt="csv")),
                      "--no-store"], capsys)
    assert doc["records"][0]["energy_per_cycle_j"] == pytest.approx(
        truth["records"][0]["energy_per_cycle_j"], rel=1e-9)  # one scale, exactly undone


def test_saving_the_same_analyses_again_does_not_grow_the_store_and_the_newest_save_counts(
        tmp_path, capsys):
    # each identical save deleted and rewrote its entries: the file grew by the space HDF5
    # does not give back (1.53 -> 1.59 MB over 12 saves of the bundled exports)
    from pidcore.store.listing import latest_per_measurement

    files = [str(export(tmp_path / f"r{i}_fill50_acrylic.csv", fmt="csv")) for i in range(3)]
    for i, path in enumerate(files):  # three measurements: other bytes, same physics
        Path(path).write_text(Path(path).read_text() + "#" * i + "\n")
    store_path = tmp_path / "s.h5"
    assert main(["analyze", *files, "--store", str(store_path)]) == 0
    assert main(["analyze", *files, "--store", str(store_path)]) == 0
    size = store_path.stat().st_size
    for _ in range(8):
        assert main(["analyze", *files, "--store", str(store_path)]) == 0
    # an entry's time is renewed in place; HDF5 may move its attributes to a larger heap once
    # (4 kB seen), where rewriting three entries grew it by ~3 kB on every save
    assert store_path.stat().st_size - size <= 8192
    # saved with a delay, without, then with it again: the last save is the one used, though
    # its analysis was held already
    argv = ["analyze", files[0], "--store", str(store_path)]
    times = []
    for delay in ("5e-5", "0", "5e-5"):
        assert main([*argv, "--velocity-delay", delay]) == 0
        listing = Store(store_path).list_analyses()
        times.append(dict(zip(listing["key"], listing["created_utc"], strict=True)))
    newest = latest_per_measurement(Store(store_path).list_analyses())
    used = newest[newest["source"] == files[0]]
    assert json.loads(used["parameters_json"].iloc[0])["velocity_delay_s"] == 5e-5
    # its first save's time is kept beside the renewed one (it was overwritten: the
    # provenance lost when the result was first made)
    key = used["key"].iloc[0]
    with h5py.File(store_path, "r") as h5:
        attrs = h5[f"analyses/{key}"].attrs
        assert attrs["first_created_utc"] == times[0][key] < attrs["created_utc"]
    capsys.readouterr()


def test_a_force_in_kn_under_n_of_a_file_stating_no_fill_is_refused_too(tmp_path, capsys):
    # without a fill the particles' mass is unknown, but the assumed coupon's structure is
    # not: such a file was saved with its energy per cycle 1000 x small
    path = export(tmp_path / "rec.csv", fmt="csv", force_unit_scale=1e-3)
    assert main(["analyze", str(path), "--store", str(tmp_path / "s.h5")]) == 2
    err = capsys.readouterr().err
    assert "below 1/20 of the specimen's coupon and fixture (22.15 g)" in err
    assert not (tmp_path / "s.h5").exists()
    # the true record (0.25 kg, over 20 x the coupon but within 20 x the coupon with every
    # cell full of particles: the fill could explain it) is taken
    assert main(["analyze", str(export(tmp_path / "true.csv", fmt="csv")), "--no-store"]) == 0
    # a force in N under "kN" (250 kg shown) had no upper limit without the fill, and was
    # saved; full cells of the paper's coupon hold 22 x 441 acrylic spheres of r 1.25 mm
    # (Table 1's 1180 kg/m^3) beside its 22.15 g structure
    full_g = 1e3 * (22 * 441 * 4 / 3 * math.pi * 1.25e-3**3 * 1180 + 0.0221534)
    path = export(tmp_path / "mn.csv", fmt="csv", force_unit_scale=1e3)
    assert main(["analyze", str(path), "--store", str(tmp_path / "s.h5")]) == 2
    err = capsys.readouterr().err
    assert (f"over 20 x the specimen's coupon, fixture and particles of full cells (no fill "
            f"stated) ({full_g:.4g} g)") in err
    assert not (tmp_path / "s.h5").exists()


def test_identical_files_stating_different_load_cases_are_refused_before_saving(tmp_path,
                                                                                capsys):
    a = export(tmp_path / "a_fill50.csv", fmt="csv")
    b = tmp_path / "b_fill75.csv"
    b.write_bytes(a.read_bytes())
    store_path = tmp_path / "s.h5"
    assert main(["analyze", str(a), str(b), "--store", str(store_path)]) == 2
    err = capsys.readouterr().err
    assert "identical contents but state different load cases" in err and err.count("\n") == 1
    assert not store_path.exists()


def test_identical_files_of_one_load_case_stating_different_settings_say_so(tmp_path, capsys):
    # the refusal said "state different load cases" beside two identical load cases (50 Hz,
    # 5 g, 50 %, ... vs the same with a vibrometer delay): what differs is the setting
    a = export(tmp_path / "a_fill50.csv", fmt="csv")
    b = tmp_path / "b_fill50.csv"
    b.write_bytes(a.read_bytes())
    (tmp_path / "loadcases.csv").write_text(
        "file,velocity_delay_us\na_fill50.csv,50\nb_fill50.csv,0\n", encoding="utf-8")
    assert main(["analyze", str(a), str(b), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert "identical contents but state different load cases, specimens or settings" in err
    assert "vibrometer delay 50 µs" in err and err.count("\n") == 1


def test_bad_file_leaves_store_untouched_and_exits_nonzero(tmp_path, capsys):
    store_path = tmp_path / "s.h5"
    good = export(tmp_path / "good.csv", fmt="csv")
    run_json([str(good), "--store", str(store_path)], capsys)
    before = file_sha256(store_path)

    bad_nan = export(tmp_path / "nan.csv", fmt="csv", corrupt_velocity=True)
    garbage = tmp_path / "garbage.uff"
    garbage.write_bytes(b"\x00\x01 not a universal file \xff" * 10)
    for bad in (bad_nan, garbage):
        code = main(["analyze", str(good), str(bad), "--store", str(store_path)])
        err = capsys.readouterr().err.strip()
        assert code != 0
        assert len(err.splitlines()) == 1 and bad.name in err
        assert file_sha256(store_path) == before
    assert "Velocity" in _last_error(main, ["analyze", str(bad_nan), "--no-store"], capsys)


def _last_error(entry, args, capsys) -> str:
    assert entry(args) != 0
    return capsys.readouterr().err


def test_missing_velocity_names_the_option(tmp_path, capsys):
    rec = synthesize_shaker_record(mass_kg=MASS, acceleration_amplitude_m_s2=ACCEL,
                                   frequency_hz=FREQ, sample_rate_hz=FS, n_periods=20)
    path = tmp_path / "force_only.csv"
    write_measurement(Measurement(path.name, (Channel("Force", "force", rec.force_n, FS, "N"),)),
                      path, "csv")
    err = _last_error(main, ["analyze", str(path), "--no-store"], capsys)
    assert "force_only.csv" in err and "velocity" in err.lower()


def test_table_output_names_units_and_whole_file_names(tmp_path, capsys):
    # a long name's start says the load case; it was cut to its last 40 characters
    path = export(tmp_path / "synthetic_f100Hz_a10g_fill50_acrylic_run_0042_58b.csv", fmt="csv")
    assert main(["analyze", str(path), "--no-store"]) == 0
    out = capsys.readouterr().out
    for unit in ("[Hz]", "[g]", "[-]", "[J]"):
        assert unit in out
    header, rule, row = out.splitlines()[:3]
    assert row.startswith(path.name + " ") and len(rule) == len(header)
    value = row[len(path.name):].split()[0]  # the frequency, right-aligned under its head
    end = row.index(value, len(path.name)) + len(value)
    assert end == header.index("frequency [Hz]") + len("frequency [Hz]")


def _table_cells(out: str, heads: tuple[str, ...]) -> dict[str, str]:
    """The first row's cell under each head (right-aligned under it)."""
    header, _, row = out.splitlines()[:3]
    return {head: row[:header.index(head) + len(head)].split()[-1] for head in heads}


def test_table_shows_small_values_with_their_digits(tmp_path, capsys):
    """A lightly damped mass (loss factor 1.6e-5, zeta 8.0e-6): the table printed the loss
    factor 0.000016 and zeta 0.00001 (fixed decimals: two digits and one; a damping ratio
    below 5e-6 as 0.00000). Every number is now shown to at least four significant digits,
    right-aligned under its head."""
    eta = 1.6e-5
    c = eta * 2 * math.pi * FREQ * MASS  # loss factor c/(m w)
    rec = synthesize_shaker_record(mass_kg=MASS, acceleration_amplitude_m_s2=ACCEL,
                                   frequency_hz=FREQ, sample_rate_hz=FS, n_periods=20.3,
                                   viscous_damping_n_s_m=c)
    path = tmp_path / "light.csv"
    write_force_velocity(path, rec.force_n, rec.velocity_m_s, FS, "csv")
    assert main(["analyze", str(path), "--no-store"]) == 0
    cells = _table_cells(capsys.readouterr().out, ("loss factor [-]", "SDC [-]", "zeta [-]"))
    sdc = 2 * math.pi * eta
    zeta = -math.log1p(-sdc) / (4 * math.pi)  # 8.0e-6: printed 0.00001 by 9.5f
    # noise-free: the printed digits are the truth's
    for head, truth in (("loss factor [-]", eta), ("SDC [-]", sdc), ("zeta [-]", zeta)):
        shown = cells[head]
        digits = len(shown.split("e")[0].replace(".", "").replace("-", "").lstrip("0"))
        assert digits >= 4, (head, shown)
        assert float(shown) == pytest.approx(truth, rel=10 ** (1 - digits)), (head, shown)


def test_table_shows_a_missing_standard_error_as_na_not_nan(tmp_path, capsys):
    """A record whose first of 8 blocks is not mass-like has no standard error (NaN, with its
    note): the table printed 'nan' in the ± SE column."""
    w = 2 * math.pi * FREQ
    t = np.arange(int(40 * FS / FREQ)) / FS
    v = 0.01 * np.sin(w * t)
    x = -0.01 / w * np.cos(w * t)
    # the first block (5 periods: 39 whole ones make 8 blocks of 4 or 5, the first of 5) a
    # spring (Im < 0), then a mass with a damper; k = m w^2 gives the spring's force the
    # mass's amplitude (a block whose line is weaker is refused as a dropout) and keeps the
    # record's Im resolved
    force = np.where(t < 5 / FREQ, MASS * w**2 * x,
                     MASS * 0.01 * w * np.cos(w * t) + C_VISCOUS * v)
    path = tmp_path / "spring_block.csv"
    write_force_velocity(path, force, v, FS, "csv")
    assert main(["analyze", str(path), "--no-store"]) == 0
    out = capsys.readouterr().out
    assert "no standard error" in out
    assert "nan" not in out.lower()
    assert _table_cells(out, ("± SE [-]",))["± SE [-]"] == "n/a"


def test_allow_clipped_analyses_and_reports_the_clipping(tmp_path, capsys):
    rec = synthesize_shaker_record(mass_kg=MASS, acceleration_amplitude_m_s2=ACCEL,
                                   frequency_hz=FREQ, sample_rate_hz=FS, n_periods=20)
    level = 0.9 * float(np.max(rec.force_n))
    force = np.minimum(rec.force_n, level)
    path = tmp_path / "clipped.csv"
    write_force_velocity(path, force, rec.velocity_m_s, FS)
    assert main(["analyze", str(path), "--no-store"]) != 0  # refused by default
    assert "clipped" in capsys.readouterr().err
    assert main(["analyze", str(path), "--no-store", "--allow-clipped"]) == 0
    out = capsys.readouterr().out
    assert "note:" in out and "'Force' clipped" in out


def test_a_file_naming_an_untabulated_material_needs_its_specimen(tmp_path, capsys):
    # "..._fill20_steel.csv" was saved as acrylic (the default): steel is not in the material
    # table, so the name's token went unread, and analyze had no --specimen to make it known
    steel = export(tmp_path / "coupon_fill20_steel.csv", fmt="csv")
    store_path = tmp_path / "s.h5"
    assert main(["analyze", str(steel), "--store", str(store_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "coupon_fill20_steel.csv" in err \
        and "particle material 'steel'" in err and "--specimen" in err
    assert not store_path.exists()
    # the paper's coupon (acrylic) does not make it steel either
    paper = Path(__file__).resolve().parents[1] / "pidcore" / "data" / "specimens" / \
        "paper_coupon.toml"
    assert main(["analyze", str(steel), "--specimen", str(paper), "--no-store"]) == 2
    assert "particle material 'steel'" in capsys.readouterr().err
    spec = tmp_path / "steel.toml"
    spec.write_text(STEEL_SPECIMEN)
    doc = run_json([str(steel), "--specimen", str(spec), "--store", str(store_path)], capsys)
    assert doc["records"][0]["load_case"].endswith("_fill20pct_steel_z")
    assert Store(store_path).list_analyses()["material"].tolist() == ["steel"]
    # a material stated explicitly is the user's word
    doc = run_json([str(steel), "--material", "acrylic", "--no-store"], capsys)
    assert doc["records"][0]["load_case"].endswith("_fill20pct_acrylic_z")
    # a name stating a tabulated material beside the word is read as before
    both = export(tmp_path / "steel_fixture_fill20_acrylic.csv", fmt="csv")
    doc = run_json([str(both), "--no-store"], capsys)
    assert doc["records"][0]["load_case"].endswith("_fill20pct_acrylic_z")


STEEL_SPECIMEN = """schema_version = 1
name = "my_steel"

[cell]
shape = "hexagonal"
inscribed_diameter_m = 6.35e-3
height_m = 12.7e-3
count = 286
wall_material = "aluminium_wall"

[coupon]
mass_kg = 0.0333

[particles]
material = "steel"
radius_m = 1.0e-3
density_kg_m3 = 7850.0
youngs_modulus_pa = 200e9
poisson_ratio = 0.29
count_per_cell = 10

[pairs.particle_particle]
restitution = 0.9
sliding_friction = 0.3

[pairs.particle_wall]
restitution = 0.8
sliding_friction = 0.35
"""


def test_files_of_a_specimens_particles_are_saved_as_its_tests(tmp_path, capsys):
    # `analyze --specimen A` saved its steel records unnamed: a later `report --specimen B` (B
    # another steel specimen) took them for B's tests and compared them with B's DEM runs
    spec_a = tmp_path / "a.toml"
    spec_a.write_text(STEEL_SPECIMEN.replace('name = "my_steel"', 'name = "panel_a"'))
    spec_b = tmp_path / "b.toml"
    spec_b.write_text(STEEL_SPECIMEN.replace('name = "my_steel"', 'name = "panel_b"'))
    store = tmp_path / "s.h5"
    steel_a = export(tmp_path / "a_fill20_steel.csv", fmt="csv")
    acrylic = export(tmp_path / "c_fill20_acrylic.uff", fmt="uff")
    doc = run_json([str(steel_a), str(acrylic), "--specimen", str(spec_a), "--store",
                    str(store)], capsys)
    assert [r["specimen"] for r in doc["records"]] == ["panel_a", None]  # acrylic: not its
    steel_b = export(tmp_path / "b_fill30_steel.mat", fmt="mat")  # other bytes: another record
    assert main(["analyze", str(steel_b), "--specimen", str(spec_b), "--store",
                 str(store)]) == 0
    assert "specimen 'panel_b' (--specimen)" in capsys.readouterr().out
    saved = Store(store).list_analyses()
    named = {Path(src).name: (spec if isinstance(spec, str) else "")
             for src, spec in zip(saved["source"], saved.get("specimen", [""] * len(saved)),
                                  strict=True)}
    assert {k: named.get(k) for k in ("a_fill20_steel.csv", "b_fill30_steel.mat")} == {
        "a_fill20_steel.csv": "panel_a", "b_fill30_steel.mat": "panel_b"}
    assert named.get("c_fill20_acrylic.uff", "") == ""
    # a sidecar's specimen is the file's own, as before
    (tmp_path / "loadcases.csv").write_text("file,specimen\nb_fill30_steel.mat,rig_c\n")
    doc = run_json([str(steel_b), "--specimen", str(spec_a), "--no-store"], capsys)
    assert doc["records"][0]["specimen"] == "rig_c"


def test_store_list_tells_apart_the_tests_of_two_edited_files_of_one_specimen_name(
        tmp_path, capsys):
    # two edits of one file are two specimens whose tests are never pooled; `store list`
    # showed both sets of tests under the bare name (the DEM runs' listing hashes them)
    from pidcore.specimen import hashed_name, load_specimen, measured_specimen_sha256
    from pidcore.store.manage import store_contents

    first = tmp_path / "a" / "panel.toml"
    second = tmp_path / "b" / "panel.toml"
    for path, count in ((first, 10), (second, 12)):
        path.parent.mkdir()
        path.write_text(STEEL_SPECIMEN.replace("count_per_cell = 10",
                                               f"count_per_cell = {count}"))
    store = tmp_path / "s.h5"
    # other formats: other bytes, so two measurements
    for path, name in ((first, "a_fill20_steel.csv"), (second, "b_fill20_steel.mat")):
        assert main(["analyze", str(export(tmp_path / name, fmt=name[-3:])), "--specimen",
                     str(path), "--store", str(store)]) == 0
    capsys.readouterr()
    listed = store_contents(store, ["analyses"])["analyses"]
    expected = {name: hashed_name("my_steel", measured_specimen_sha256(load_specimen(p)))
                for p, name in ((first, "a_fill20_steel.csv"), (second, "b_fill20_steel.mat"))}
    assert dict(zip(listed["file"], listed["specimen"], strict=True)) == expected
    assert len(set(expected.values())) == 2
    assert main(["store", "list", "--store", str(store), "--section", "analyses"]) == 0
    out = capsys.readouterr().out
    assert all(label in out for label in expected.values())


def test_a_file_stating_no_fill_is_saved_as_a_test_of_the_specimen_given(tmp_path, capsys):
    # `analyze run7.csv --specimen panel.toml` (no fill in the name): saved unnamed, and the
    # output said "no specimen named, the paper's coupon assumed ... name another with
    # --specimen FILE" beside the --specimen given
    from pidcore.specimen import load_specimen

    spec = tmp_path / "panel.toml"
    spec.write_text(STEEL_SPECIMEN)
    store = tmp_path / "s.h5"
    bare = export(tmp_path / "run7.csv", fmt="csv")
    acrylic = export(tmp_path / "run8_acrylic.uff", fmt="uff")  # no fill, other particles
    doc = run_json([str(bare), str(acrylic), "--specimen", str(spec), "--store", str(store)],
                   capsys)
    mine, other = doc["records"]
    assert mine["load_case"] is None and mine["specimen"] == "my_steel"
    assert mine["specimen_sha256"] == load_specimen(spec).hash and mine["assumed"] == {}
    assert not [n for n in mine["notes"] if "paper's coupon" in n]
    # a file stating other particles is not the specimen's test: the coupon is assumed, said
    # naming the specimen given (no fill stated: the file's particles are not in the record)
    assert other["specimen"] is None and other["assumed"] == {
        "specimen": "paper_coupon", "specimen_given": "my_steel",
        "specimen_given_material": "steel"}
    saved = Store(store).list_analyses().set_index("source")
    assert saved.loc[str(bare), "specimen"] == "my_steel"
    assert saved.loc[str(bare), "specimen_sha256"] == load_specimen(spec).hash


def test_a_file_of_other_particles_than_the_specimens_names_the_specimens(tmp_path, capsys):
    # `analyze coupon_fill20_steel.csv --specimen wc.toml` (tungsten carbide) said the table
    # lacks steel and to "give --specimen FILE whose particles are steel", as if none was given
    steel = export(tmp_path / "coupon_fill20_steel.csv", fmt="csv")
    spec = tmp_path / "wc.toml"
    spec.write_text(STEEL_SPECIMEN.replace('material = "steel"', 'material = "tungsten_carbide"'))
    assert main(["analyze", str(steel), "--specimen", str(spec), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert ("which the material table (acrylic, aluminium) and the specimen's "
            "tungsten_carbide particles lack") in err


def test_a_fill_of_no_particle_is_refused_naming_the_file(tmp_path, capsys):
    # `--fill 0.5` (a fraction typed for 50 %) was analysed and saved as a load case of 0.5 %,
    # a coupon without a particle in its cells (22 acrylic spheres fill the paper's cell:
    # 0.5 % of 22 is 0.11, rounded to none), which no DEM run can ever match
    path = export(tmp_path / "rec_fill50_acrylic.csv", fmt="csv")
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--fill", "0.5", "--store", str(store)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "rec_fill50_acrylic.csv: fill 0.5 % of 22 particles " \
        "rounds to none" in err and "fill: --fill" in err
    assert not store.exists()
    # against a specimen's cell: 46 steel spheres of 1 mm radius fill the 6.35 mm cell
    spec = tmp_path / "steel.toml"
    spec.write_text(STEEL_SPECIMEN)
    steel = export(tmp_path / "rec_fill1_steel.csv", fmt="csv")
    assert main(["analyze", str(steel), "--specimen", str(spec), "--no-store"]) == 2
    assert "fill 1 % of 46 particles rounds to none" in capsys.readouterr().err
    assert main(["report", str(steel), "--specimen", str(spec), "--out",
                 str(tmp_path / "rep")]) == 2
    assert "fill 1 % of 46 particles rounds to none" in capsys.readouterr().err
    assert not (tmp_path / "rep").exists()


def test_a_read_only_store_is_named_as_such_before_any_analysis(tmp_path, capsys, read_only):
    # a read-only store ended the analysis in "cannot make the working copy .s.h5.<hex>.tmp
    # ([Errno 13] Unable to synchronously open file (unable to open file: name = ...))"
    path = export(tmp_path / "rec_fill50_acrylic.csv", fmt="csv")
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--store", str(store)]) == 0
    capsys.readouterr()
    before = store.read_bytes()
    read_only(store)
    other = export(tmp_path / "rec_fill25_acrylic.uff", fmt="uff")
    assert main(["analyze", str(other), "--store", str(store)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "s.h5: the store file is read-only" in err
    assert main(["report", str(other), "--store", str(store), "--out",
                 str(tmp_path / "rep")]) == 2
    assert "s.h5: the store file is read-only" in capsys.readouterr().err
    assert store.read_bytes() == before and not (tmp_path / "rep").exists()
    # only read: a report of what it holds is made as before
    assert main(["report", "--store", str(store), "--out", str(tmp_path / "rep"),
                 "--format", "csv"]) == 0


def test_an_earlier_report_a_killed_report_left_hidden_is_put_back_and_said_so(tmp_path,
                                                                               capsys):
    # the next report of rp put back an earlier report that a report killed between its two
    # renames had left hidden, without a word: the user saw a report appear, or be replaced,
    # that no run of theirs had just made. Said by the command, and by make_report's notes
    # (not in the report's own provenance: it is of this run, not of the report)
    import os

    from pidcore.report import make_report

    path = export(tmp_path / "rec_fill50_acrylic.csv", fmt="csv")
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--store", str(store)]) == 0
    out = tmp_path / "rep"
    report = ["report", "--store", str(store), "--out", str(out), "--format", "csv"]
    assert main(report) == 0
    said = (f"note: {out}: put back the earlier report, which a report killed while replacing "
            "it had left hidden beside it")
    assert said not in capsys.readouterr().out  # nothing hidden, nothing said
    os.replace(out, tmp_path / ".rep.0123456789abcdef.old")  # the kill's state
    assert main(report) == 0
    printed = capsys.readouterr().out
    assert printed.count(said) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rec_fill50_acrylic.csv", "rep", "s.h5"]
    os.replace(out, tmp_path / ".rep.0123456789abcdef.old")
    result = make_report([], out_dir=out, store=store, formats="csv")
    assert result.notes[-1] == said.removeprefix("note: ")
    assert "put back the earlier report" not in result.paths["csv_provenance"].read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rec_fill50_acrylic.csv", "rep", "s.h5"]


def test_a_file_of_other_particles_than_a_table_material_specimens_names_them(tmp_path, capsys):
    # with a --specimen of acrylic particles (a table material) the refusal of a ..._steel
    # file still read as if no specimen was given ("give --specimen FILE whose particles are
    # steel"), not saying that the one given holds acrylic
    from pidcore.specimen import paper_specimen

    steel = export(tmp_path / "coupon_fill20_steel.csv", fmt="csv")
    spec = tmp_path / "acrylic_coupon.toml"
    spec.write_text(paper_specimen().to_toml(), encoding="utf-8")
    assert main(["analyze", str(steel), "--specimen", str(spec), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "lacks (the specimen's particles are acrylic); give --specimen FILE whose " \
           "particles are steel" in err


def test_a_store_named_in_latin1_bytes_is_printed_with_escapes(tmp_path, capsys):
    # in a UTF-8 terminal (stdout errors 'strict') analyze printed 'saved 1 record(s) to
    # s\udce9.h5' as a UnicodeEncodeError traceback, after the record was saved
    import os

    from _shaker_files import write_force_velocity

    from pidcore.signal.synthetic import synthesize_shaker_record

    rec = synthesize_shaker_record(mass_kg=0.25, acceleration_amplitude_m_s2=49.0,
                                   frequency_hz=100.0, sample_rate_hz=25_600.0, n_periods=15,
                                   viscous_damping_n_s_m=2.0, snr_db=60, seed=5)
    path = write_force_velocity(tmp_path / "rec_fill50.csv", rec.force_n, rec.velocity_m_s,
                                25_600.0)
    store = tmp_path / os.fsdecode(b"s\xe9.h5")
    assert sys.stdout.errors == "strict"  # the premise: capsys encodes as a UTF-8 terminal
    assert main(["analyze", str(path), "--store", str(store)]) == 0
    assert "saved 1 record(s) to " + str(tmp_path) + "/s\\xe9.h5" in capsys.readouterr().out
    assert sys.stdout.errors == "strict"  # put back for the caller


def test_a_store_chmod_444_is_read_only_for_root_too(tmp_path, capsys):
    # as root (containers) os.access lets anything be written: analyze, report FILES, dem run
    # and calibrate replaced a store its owner had made read-only (chmod 444) by their copy
    path = export(tmp_path / "rec_fill50_acrylic.csv", fmt="csv")
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--store", str(store)]) == 0
    capsys.readouterr()
    store.chmod(0o444)
    before = store.read_bytes()
    other = export(tmp_path / "rec_fill25_acrylic.uff", fmt="uff")
    assert main(["analyze", str(other), "--store", str(store)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "s.h5: the store file is read-only" in err
    assert store.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
    store.chmod(0o644)  # made writable again: written as before
    assert main(["analyze", str(other), "--store", str(store)]) == 0


def test_a_structure_mass_without_a_baseline_is_said_to_change_nothing(tmp_path, capsys):
    # --structure-mass alone (or a structure_mass_g column with no baseline) was taken in
    # silence: the user believed the structure's damping taken off, and nothing was
    rec = synthesize_shaker_record(mass_kg=0.3, acceleration_amplitude_m_s2=5 * STANDARD_GRAVITY,
                                   frequency_hz=100.0, sample_rate_hz=10000.0, n_periods=30,
                                   viscous_damping_n_s_m=2.0)
    path = write_force_velocity(tmp_path / "a.csv", rec.force_n, rec.velocity_m_s, 10000.0)

    def notes(*options):
        assert main(["analyze", str(path), "--no-store", "--json", *options]) == 0
        (record,) = json.loads(capsys.readouterr().out)["records"]
        return record, [n for n in record["notes"] if "given without a baseline" in n]

    alone, said = notes("--structure-mass", "0.28")
    assert len(said) == 1 and "nothing subtracted" in said[0]
    plain, _ = notes()
    assert alone["loss_factor"] == plain["loss_factor"]  # indeed nothing subtracted
    assert notes("--structure-mass", "0.28", "--baseline-loss-factor", "0.001")[1] == []


def test_unused_channels_are_dropped_only_where_no_measurement_is_saved(tmp_path, capsys):
    # `analyze --no-store` held every channel of every file until the last was analysed
    # (8 exports of 7 columns: 640 MB above the interpreter, 263 MB with only the channels
    # used); a store keeps the file's every channel, so with one nothing may be dropped
    from pidcore.file_settings import FileSettings, analyze_each
    from pidcore.measure import AnalysisOptions

    rec = synthesize_shaker_record(mass_kg=MASS, acceleration_amplitude_m_s2=ACCEL,
                                   frequency_hz=FREQ, sample_rate_hz=FS, n_periods=40.3,
                                   viscous_damping_n_s_m=C_VISCOUS, snr_db=50, seed=3)
    n = rec.force_n.size
    path = tmp_path / "wide.csv"
    write_measurement(Measurement("wide.csv", (
        Channel("Force", "force", rec.force_n, FS, "N"),
        Channel("Mic", "pressure", np.ones(n), FS, "Pa"),
        Channel("Velocity", "velocity", rec.velocity_m_s, FS, "m/s"),
        Channel("Volt", "voltage", np.zeros(n), FS, "V"))), path)
    settings = [FileSettings(AnalysisOptions())]
    (whole,) = analyze_each([path], settings)
    (lean,) = analyze_each([path], settings, keep_unused_channels=False)
    assert whole.measurement.channel_names == ["Force", "Mic", "Velocity", "Volt"]
    assert lean.measurement.channel_names == ["Force", "Velocity"]
    assert lean.measurement.sha256 == whole.measurement.sha256 == file_sha256(path)
    # the same analysis, notes included ("ignored channels (not needed): 'Mic', 'Volt'")
    assert lean.to_dict() == whole.to_dict()
    store_path = tmp_path / "s.h5"
    run_json([str(path), "--store", str(store_path)], capsys)
    (key,) = Store(store_path).list_measurements()["key"]
    assert Store(store_path).get_measurement(key).channel_names == ["Force", "Mic", "Velocity",
                                                                    "Volt"]


@pytest.mark.parametrize(("sdc", "stderr", "shown"), [
    (0.01234, 0.00056, "0.01234 ± 0.00056"),  # the app wrote 0.0123 ± 0.0006
    (4.09, 0.2, "4.09 ± 0.20"),  # the app wrote 4.0900 ± 0.2000, analyze 4.09000 and 0.2
    (0.21, 0.01, "0.210 ± 0.010"),  # the app wrote 0.2100 ± 0.0100
])
def test_analyze_table_and_app_write_one_sdc_with_its_error(tmp_path, sdc, stderr, shown):
    """One record's SDC ± stderr read the same in the terminal and the app (GUM 7.2.6: the
    error with two significant digits, the value rounded at its last digit): ``analyze``
    wrote 6 significant digits beside a 2-digit error, the Analyse and Compare pages and the
    case sheet four decimals of each."""
    from dataclasses import replace
    from types import SimpleNamespace

    from pidcore.app import workbench
    from pidcore.app.uploads import format_sdc
    from pidcore.cli.analyze import format_table
    from pidcore.measure import analyze_file

    record = analyze_file(export(tmp_path / "one.csv", fmt="csv"))
    record = replace(record, analysis=replace(record.analysis, sdc=sdc, sdc_stderr=stderr))
    table = format_table([record])
    cells = _table_cells(table, ("SDC [-]", "± SE [-]"))
    assert f"{cells['SDC [-]']} ± {cells['± SE [-]']}" == shown
    assert format_sdc(sdc, stderr) == shown
    # the fields the Compare heading reads of a pidcore.compare.case.Headline
    head = SimpleNamespace(measured=sdc, measured_stderr=stderr, measured_kind="Eq. 10",
                           dem=sdc, dem_stderr=stderr, verdict="v")
    assert workbench.headline_heading(head) == f"measured (Eq. 10) {shown} vs our DEM {shown} — v"


def test_a_two_word_material_in_a_file_name_is_named_whole(tmp_path, capsys):
    # `analyze panel_fill40_tungsten_carbide.csv` without --specimen said the file name states
    # 'carbide' (the alphabetically first of its words) and to "give --specimen FILE whose
    # particles are carbide": a specimen of tungsten_carbide, as its file spells it, is meant
    path = export(tmp_path / "panel_fill40_tungsten_carbide.csv", fmt="csv")
    assert main(["analyze", str(path), "--no-store"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "file name states particle material 'tungsten_carbide'" in err
    assert "whose particles are tungsten_carbide" in err
    # the same file analysed with the tungsten carbide specimen is that specimen's test
    spec = tmp_path / "wc.toml"
    spec.write_text(STEEL_SPECIMEN.replace('material = "steel"', 'material = "tungsten_carbide"'))
    doc = run_json([str(path), "--specimen", str(spec), "--no-store"], capsys)
    assert doc["records"][0]["load_case"].endswith("_fill40pct_tungsten_carbide_z")


def test_json_names_a_non_utf8_file_with_the_escapes_store_list_now_uses_too(tmp_path, capsys):
    # analyze --json printed a file's name as "ex2_\\xff..." and store list a store's as a
    # lone surrogate "st_\udcff.h5": every name in a --json document now takes the first
    import os

    path = export(tmp_path / os.fsdecode(b"ex2_\xff_fill50.csv"), fmt="csv")
    store = tmp_path / os.fsdecode(b"st_\xff.h5")
    assert main(["analyze", str(path), "--store", str(store), "--json"]) == 0
    text = capsys.readouterr().out
    document = json.loads(text)
    json.dumps(document, ensure_ascii=False).encode("utf-8")  # no lone surrogate anywhere
    (record,) = document["records"]
    assert record["source"].endswith("ex2_\\xff_fill50.csv")
    assert "\\udc" not in text
