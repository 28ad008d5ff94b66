"""The SDC bound of the plausibility check: 2 pi where the specimen is not known, the most the
specimen's particles can dissipate (8 m_p/m_s) where it is. A user's panel of 263 g of steel
spheres on a 55 g structure, whose DEM virtual shaker predicts an Eq. 11 SDC of 8.4, was refused
by ``analyze`` as "above the physical bound 6.28", left out by ``calibrate --store`` and its
calibrated band was cut at 2 pi."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from _shaker_files import write_force_velocity

from pidcore.cli import main
from pidcore.compare.plausibility import (
    RECORDED_BOUND_FIELD,
    RECORDED_BOUND_ORIGIN,
    RECORDED_BOUND_UNITS,
    RECORDED_PARTICLE_MASS_FIELD,
    RECORDED_STRUCTURE_MASS_FIELD,
    SDC_UPPER_BOUND,
    particle_impact_sdc,
    recorded_sdc_bound,
    sdc_bound,
    stored_findings,
    stored_sdc_bound,
)
from pidcore.compare.plausibility import tested_sdc_bound as bound_of_tested
from pidcore.constants import STANDARD_GRAVITY
from pidcore.signal import analyze_power
from pidcore.signal.synthetic import synthesize_shaker_record
from pidcore.specimen import Specimen

ROOT = Path(__file__).resolve().parents[1]
MASS, FREQ, FS = 0.25, 100.0, 25_600.0
ACCEL = 5 * STANDARD_GRAVITY


def heavy_specimen() -> Specimen:
    """The user's panel: 6.35 mm aluminium cells, 2 mm steel spheres at 60 %, a 40 g coupon on
    a 15 g fixture (the bundled steel_6mm with its coupon and fill)."""
    text = (ROOT / "data_samples" / "specimens" / "steel_6mm.toml").read_text(encoding="utf-8")
    text = (text.replace('name = "steel_6mm"', 'name = "heavy_panel"')
            .replace("mass_kg = 0.0333", "mass_kg = 0.040")
            .replace("fill_percent = 50.0", "fill_percent = 60.0"))
    return Specimen.from_text(text, source="heavy_panel.toml")


def _heavy_masses() -> tuple[float, float]:
    spec = heavy_specimen()
    per_cell = round(0.6 * spec.capacity_per_cell())  # 60 % of 46: 28 spheres
    return (per_cell * spec.cell.count * spec.particles.mass_kg,
            spec.coupon.mass_kg + spec.coupon.fixture_mass_kg)


def test_the_bound_is_eight_particle_masses_over_the_structure():
    m_p, m_s = _heavy_masses()
    assert m_p == pytest.approx(0.2633, abs=5e-4) and m_s == pytest.approx(0.055, rel=1e-12)
    bound = sdc_bound(fill_percent=60.0, specimen=heavy_specimen())
    # the same numbers the specimen gives: no tolerance beyond round-off
    assert bound.particle_mass_kg == pytest.approx(m_p, rel=1e-12)
    assert bound.structure_mass_kg == pytest.approx(m_s, rel=1e-12)
    assert bound.sdc == pytest.approx(8 * m_p / m_s, rel=1e-12) and bound.sdc > 38
    # a light fill stays at 2 pi (the paper's coupon at 10 %: 8.5 g on 22.2 g, 8 m_p/m_s 3.1)
    light = sdc_bound(fill_percent=10.0, material="acrylic")
    assert particle_impact_sdc(light.particle_mass_kg, light.structure_mass_kg) < 2 * math.pi
    assert light.sdc == SDC_UPPER_BOUND
    # unknown: no fill, an own material without its file, a specimen named but not at hand
    assert sdc_bound(fill_percent=None).sdc == SDC_UPPER_BOUND
    assert sdc_bound(fill_percent=50.0, material="tungsten").sdc == SDC_UPPER_BOUND
    assert bound_of_tested(fill_percent=60.0, material="steel",
                            specimen_name="heavy_panel").sdc == SDC_UPPER_BOUND


def test_a_particle_mass_on_a_dashpot_stays_below_the_bound():
    # Analytic truth: a mass m_p joined by a dashpot c = x w m_p to a base of mass m_s moving
    # at V e^{iwt} loads it with Z = iw m_p c / (c + iw m_p): Re Z = w m_p x / (1 + x^2) (at
    # most w m_p / 2), Im Z = w m_p x^2 / (1 + x^2) >= 0. The loss factor
    # m_p x / ((m_s + m_p) x^2 + m_s) peaks at x* = sqrt(m_s / (m_s + m_p)) at
    # m_p / (2 sqrt(m_s (m_s + m_p))), below m_p / (2 m_s): SDC < pi m_p / m_s < 8 m_p / m_s.
    m_p, m_s = _heavy_masses()
    w = 2 * math.pi * FREQ
    t = np.arange(int(40 * FS / FREQ)) / FS
    velocity = 0.05 * np.cos(w * t)
    x_best = math.sqrt(m_s / (m_s + m_p))
    sdcs = {}
    for c in np.append(np.geomspace(0.05, 20, 9), x_best) * w * m_p:
        z = 1j * w * m_p * c / (c + 1j * w * m_p) + 1j * w * m_s
        force = np.real(z * 0.05 * np.exp(1j * w * t))
        sdcs[c] = analyze_power(force, velocity, FS, frequency_hz=FREQ).sdc
        truth = 2 * math.pi * z.real / z.imag
        # whole periods of a pure sine: the analysis is exact to round-off and its drift fit
        assert sdcs[c] == pytest.approx(truth, rel=1e-6)
    best = max(sdcs.values())
    assert best == pytest.approx(2 * math.pi * m_p / (2 * math.sqrt(m_s * (m_s + m_p))),
                                 rel=1e-6)
    assert best < math.pi * m_p / m_s < particle_impact_sdc(m_p, m_s)


@pytest.mark.slow
def test_the_dem_virtual_shaker_of_heavy_particles_stays_below_the_bound():
    # pidcore's own DEM of the user's panel: Eq. 11 of its virtual shaker (with the 15 g
    # fixture) and the dissipation per cycle against 4 m_p V^2 (two fully inelastic impacts
    # per cycle at 2 V), the bound's own premise
    from pidcore.calibrate.observation import observation_from_run
    from pidcore.calibrate.runner import RunRequest, simulate_request
    from pidcore.dem.persist import dem_run_entry
    from pidcore.dem.simulate import DemConfig, LoadCase

    spec = heavy_specimen()
    bound = sdc_bound(fill_percent=60.0, specimen=spec)
    f, a = 50.0, 10.0
    run = simulate_request(RunRequest(LoadCase(f, a, 60.0, "steel"), spec,
                                      DemConfig(cells=2, steady_cycles=20, block_cycles=5,
                                                max_transient_cycles=10)))
    entry = dem_run_entry(run)
    obs = observation_from_run(entry["record"], entry["arrays"])
    eq11 = float(obs.sdc(spec.coupon.fixture_mass_kg))
    v = a * STANDARD_GRAVITY / (2 * math.pi * f)
    assert 0 < run.energy_per_cycle_j < 4 * bound.particle_mass_kg * v**2
    # the premise: above 2 pi, which the old bound refused (12.9 with this seed and cells)
    assert 2 * math.pi < eq11 < bound.sdc


def _export(path: Path, damping: float) -> Path:
    # a rigid mass with a viscous damper: SDC = 2 pi c / (m w) = c / (m f) = c / 25
    rec = synthesize_shaker_record(mass_kg=MASS, acceleration_amplitude_m_s2=ACCEL,
                                   frequency_hz=FREQ, sample_rate_hz=FS, n_periods=15,
                                   viscous_damping_n_s_m=damping, snr_db=60, seed=5)
    return write_force_velocity(path, rec.force_n, rec.velocity_m_s, FS)


@pytest.fixture
def heavy_file(tmp_path) -> Path:
    path = tmp_path / "heavy_panel.toml"
    path.write_text(heavy_specimen().to_toml(), encoding="utf-8")
    return path


def test_analyze_keeps_a_heavy_particle_sdc_above_2_pi_and_calibrate_keeps_it(
        tmp_path, capsys, heavy_file):
    from pidcore.calibrate.data import measured_from_store

    path = _export(tmp_path / "rec.csv", 210.0)  # SDC 8.4, the DEM's prediction of the panel
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--specimen", str(heavy_file), "--fill", "60",
                 "--store", str(store)]) == 0
    said = capsys.readouterr()
    assert "implausible" not in said.out + said.err
    left_out: list[str] = []
    (point,) = measured_from_store(store, left_out=left_out, specimen=heavy_specimen())
    # the stored SDC, kept (8.4 = 210 / 25 within the record's 60 dB noise)
    assert point.sdc == pytest.approx(8.4, rel=1e-2) and left_out == []
    assert point.sdc_bound.sdc == pytest.approx(sdc_bound(fill_percent=60.0,
                                                          specimen=heavy_specimen()).sdc)
    # read without the specimen file (the store keeps its name and hash, not its masses) it
    # is judged against the bound analyze saved with it: kept, as analyze kept it (it was
    # judged at 2 pi and left out as "all implausible")
    left_out = []
    (alone,) = measured_from_store(store, left_out=left_out)
    assert alone.sdc == point.sdc and left_out == []
    # the same bound as the file's (equal by construction), said to come from the record
    assert alone.sdc_bound == point.sdc_bound and alone.sdc_bound.origin == RECORDED_BOUND_ORIGIN
    # the app's Compare page judges the saved record as analyze did, file known or not
    from pidcore.report.case_view import saved_entries
    from pidcore.store.listing import saved_analyses

    (entry,) = saved_entries(store, saved_analyses(store), [heavy_specimen()])
    assert entry.implausible == ""
    (unknown,) = saved_entries(store, saved_analyses(store))
    assert unknown.implausible == ""
    # and so does report --store, with --specimen or without: no note of an implausible record
    for given in (["--specimen", str(heavy_file)], []):
        capsys.readouterr()
        assert main(["report", "--store", str(store), *given, "--out",
                     str(tmp_path / f"r{len(given)}"), "--format", "csv"]) == 0
        said = capsys.readouterr()
        assert "implausible" not in said.out + said.err


def _saved_heavy_record(tmp_path, heavy_file) -> tuple[Path, str]:
    """A store holding the 8.4 SDC record of the heavy panel saved by analyze --specimen, and
    its analysis key."""
    from pidcore.store import Store

    path = _export(tmp_path / "rec.csv", 210.0)
    store = tmp_path / "s.h5"
    assert main(["analyze", str(path), "--specimen", str(heavy_file), "--fill", "60",
                 "--store", str(store)]) == 0
    (key,) = Store(store).list_analyses()["key"]
    return store, key


def _edit_record(store: Path, key: str, **values: float | None) -> None:
    """Set (None: delete) record fields of a stored analysis in place, as an older pidcore
    (no bound stored) or a hand-edited store (a bound below 2 pi) left them."""
    import h5py

    with h5py.File(store, "r+") as h5:
        group = h5["analyses"][key]
        for name, value in values.items():
            if value is None:
                del group["record"].attrs[name]
                del group["units"].attrs[name]
            else:
                group["record"].attrs[name] = value


def test_the_store_keeps_the_bound_analyze_judged_with_its_basis_and_units(tmp_path,
                                                                            heavy_file):
    from pidcore.store import Store

    store, key = _saved_heavy_record(tmp_path, heavy_file)
    entry = Store(store).get_analysis(key)
    expected = sdc_bound(fill_percent=60.0, specimen=heavy_specimen())
    particles, structure = _heavy_masses()
    # the round trip is exact (HDF5 keeps float64 as written)
    assert entry.record[RECORDED_BOUND_FIELD] == expected.sdc
    assert entry.record[RECORDED_PARTICLE_MASS_FIELD] == expected.particle_mass_kg
    assert entry.record[RECORDED_STRUCTURE_MASS_FIELD] == expected.structure_mass_kg
    # the masses are the specimen's own (263 g of spheres, 55 g of coupon and fixture)
    assert expected.particle_mass_kg == pytest.approx(particles, rel=1e-12)
    assert expected.structure_mass_kg == pytest.approx(structure, rel=1e-12)
    assert {name: entry.units[name] for name in RECORDED_BOUND_UNITS} == {
        RECORDED_BOUND_FIELD: "1", RECORDED_PARTICLE_MASS_FIELD: "kg",
        RECORDED_STRUCTURE_MASS_FIELD: "kg"}
    # with the file at hand (its hash the record's) the file's bound is used; it equals the
    # stored one by construction
    row = Store(store).list_analyses().iloc[0]
    from_file = stored_sdc_bound(row, given=heavy_specimen())
    from_record, note = recorded_sdc_bound(row)
    assert from_file == from_record == expected and note == ""
    assert from_file.origin == "" and from_record.origin == RECORDED_BOUND_ORIGIN
    assert stored_sdc_bound(row).origin == RECORDED_BOUND_ORIGIN
    # a record of the paper's coupon (no specimen named) keeps its bound too, though never
    # read back: the coupon is always at hand (specimen_at_hand)
    plain = _export(tmp_path / "plain.csv", 2.5)  # SDC 0.1
    assert main(["analyze", str(plain), "--fill", "50", "--store", str(tmp_path / "p.h5")]) == 0
    entry = Store(tmp_path / "p.h5").get_analysis(Store(tmp_path / "p.h5").list_analyses()[
        "key"].iloc[0])
    assert entry.record[RECORDED_BOUND_FIELD] == sdc_bound(fill_percent=50.0).sdc


def test_a_record_saved_before_the_bound_was_stored_is_judged_at_2_pi_as_before(
        tmp_path, capsys, heavy_file):
    from pidcore.calibrate.data import measured_from_store

    store, key = _saved_heavy_record(tmp_path, heavy_file)
    _edit_record(store, key, **dict.fromkeys(RECORDED_BOUND_UNITS))
    left_out: list[str] = []
    with pytest.raises(Exception, match="all implausible"):
        measured_from_store(store, left_out=left_out)
    assert "above the physical bound 6.28 (loss factor" in left_out[0]
    # with its file it is kept as before
    (point,) = measured_from_store(store, specimen=heavy_specimen())
    assert point.sdc == pytest.approx(8.4, rel=1e-2)  # 210 / 25 within the 60 dB noise
    capsys.readouterr()
    assert main(["report", "--store", str(store), "--out", str(tmp_path / "r"),
                 "--format", "csv"]) == 0
    assert "implausible, saved as accepted" in capsys.readouterr().out


@pytest.mark.parametrize("stored, problem", [
    (3.0, "is below 2 pi (6.283), the least bound of any specimen"),
    (20.0, "is not max(2 pi, 8 m_p/m_s) of its stored masses"),
])
def test_a_stored_bound_that_is_not_one_is_ignored_with_a_note(tmp_path, heavy_file, stored,
                                                              problem):
    from pidcore.store import Store

    store, key = _saved_heavy_record(tmp_path, heavy_file)
    _edit_record(store, key, **{RECORDED_BOUND_FIELD: stored})
    row = Store(store).list_analyses().iloc[0]
    assert recorded_sdc_bound(row)[0] is None
    warnings, notes = stored_findings(row)
    # judged without it: at 2 pi, never below it (a bound of 3 would flag an SDC of 4)
    assert "above the physical bound 6.28 (loss factor" in warnings[0].message
    assert notes[0] == (f"the SDC bound stored with the record ({RECORDED_BOUND_FIELD} "
                        f"{stored:.4g}) {problem}" + notes[0].split(problem)[1])
    assert notes[0].endswith(": ignored, judged as without it")
    # the file at hand decides alone: no note of the stored value
    assert stored_findings(row, given=heavy_specimen()) == ((), ())


def test_a_flagged_record_says_its_bound_came_from_the_record(tmp_path, heavy_file):
    from pidcore.store import Store

    store, key = _saved_heavy_record(tmp_path, heavy_file)
    _edit_record(store, key, sdc=50.0)  # above the panel's 38.3
    (warning,), _ = stored_findings(Store(store).list_analyses().iloc[0])
    assert warning.message.startswith("SDC 50 is above the physical bound 38.3 (particles of "
                                      "263 g on a 55 g structure")
    assert warning.message.endswith(f"; {RECORDED_BOUND_ORIGIN})")


def test_analyze_refuses_an_sdc_above_the_particles_bound_naming_it(tmp_path, capsys,
                                                                    heavy_file):
    path = _export(tmp_path / "rec.csv", 1000.0)  # SDC 40 > 38.3
    assert main(["analyze", str(path), "--specimen", str(heavy_file), "--fill", "60",
                 "--no-store"]) == 2
    err = capsys.readouterr().err
    shown = float(err.split("rec.csv: implausible: SDC ")[1].split()[0])
    assert shown == pytest.approx(40.0, rel=1e-2)  # 1000 / 25, within the 60 dB noise
    assert ("above the physical bound 38.3 (particles of 263 g on a 55 g structure can "
            "dissipate at most SDC 8 m_p/m_s = 38.3, two fully inelastic impacts per cycle)"
            ) in err
    assert main(["analyze", str(path), "--specimen", str(heavy_file), "--fill", "60",
                 "--no-store", "--accept-implausible"]) == 0
    # the same SDC of 8.4 without a fill: the particles' mass is unknown, the bound 2 pi
    light = _export(tmp_path / "nofill.csv", 210.0)
    capsys.readouterr()
    assert main(["analyze", str(light), "--no-store"]) == 2
    assert "above the physical bound 6.28 (loss factor" in capsys.readouterr().err


def test_the_calibrated_band_of_heavy_particles_is_cut_at_their_bound(tmp_path):
    import dataclasses
    import json

    from pidcore.calibrate.prediction import calibration_from_json
    from pidcore.loadcase import LoadCase

    doc = {"parameters": {"rolling_friction": {"median": 0.05, "low95": 0.01, "high95": 0.1}},
           "predictions": [{"frequency_hz": 50.0, "acceleration_g": 10.0, "fill_percent": 60.0,
                            "material": "steel", "measured": 8.4, "predicted": 8.5,
                            "low95": 6.0, "high95": 11.0}]}
    cal = calibration_from_json(json.dumps(doc), tmp_path / "calibration.json",
                                specimen_name="heavy_panel")
    case = LoadCase(50.0, 10.0, 60.0, "steel")
    # without the specimen file its masses are unknown: cut at 2 pi, as before
    assert cal.lookup(case).band() == (6.0, SDC_UPPER_BOUND)
    with_file = dataclasses.replace(cal, specimen_text=heavy_specimen().to_toml())
    hit = with_file.lookup(case)
    assert hit.band() == (6.0, 11.0) and hit.band_note() == ""  # [6.283, 6.283] before
    assert hit.contains(8.4)
    wide = dataclasses.replace(hit, high95=50.0)
    bound = sdc_bound(fill_percent=60.0, specimen=heavy_specimen()).sdc
    assert wide.band()[1] == bound
    assert wide.band_note().startswith(f"calibrated 95 % band cut at {bound:.4g}, the SDC "
                                       "bound of the specimen's particles (particles of 263 g "
                                       "on a 55 g structure")


def test_the_bundled_paper_calibration_keeps_its_bands():
    # the paper coupon's bound rises with its fill (16.9 at 50 %), not with the calibration's
    # fitted 254 g fixture (which would keep it at 2 pi); every bundled band is below both,
    # so none is cut and none changes
    from pidcore.calibrate.prediction import load_calibration

    cal = load_calibration(ROOT / "data_samples" / "paper_calibration" / "calibration.json")
    for p in cal.predictions:
        hit = cal.lookup(p.load_case)
        assert hit.sdc_bound.sdc == pytest.approx(sdc_bound(
            fill_percent=p.load_case.fill_percent, material=p.load_case.material).sdc,
            rel=1e-12)
        assert hit.band() == (p.low95, p.high95) and hit.band_note() == ""


def test_the_apps_save_keeps_the_bound_and_calibrate_without_the_file_keeps_the_record(
        tmp_path):
    # the app's Analyse page judges a known specimen's upload against its particles' bound
    # and saves it; read later without that file (calibrate --store, report --store) it was
    # judged at 2 pi and left out
    from pidcore.app import uploads
    from pidcore.calibrate.data import measured_from_store
    from pidcore.compare.case import load_case_of
    from pidcore.compare.plausibility import implausible_findings, tested_sdc_bound
    from pidcore.measure import AnalysisOptions
    from pidcore.specimen import measured_specimen_name, measured_specimen_sha256
    from pidcore.store import Store

    heavy = heavy_specimen()
    data = _export(tmp_path / "rec.csv", 210.0).read_bytes()
    options = AnalysisOptions()
    record = uploads.analyze_upload("rec.csv", data, options).record
    case = load_case_of(record, fill_percent=60, material="steel")
    name, sha256 = measured_specimen_name(heavy), measured_specimen_sha256(heavy)
    bound = tested_sdc_bound(fill_percent=60.0, material="steel", specimen_name=name,
                             specimen_sha256=sha256, given=heavy)
    assert implausible_findings(record.analysis, bound=bound) == ((), ())  # as the page shows
    store = tmp_path / "app.h5"
    uploads.save_records(store, [uploads.AnalysedFile(record, case, options, name,
                                                      specimen_sha256=sha256, sdc_bound=bound)])
    entry = Store(store).get_analysis(Store(store).list_analyses()["key"].iloc[0])
    assert entry.record[RECORDED_BOUND_FIELD] == bound.sdc  # exact round trip
    assert entry.units[RECORDED_BOUND_FIELD] == "1"
    left_out: list[str] = []
    (point,) = measured_from_store(store, left_out=left_out)
    assert left_out == [] and point.sdc == pytest.approx(8.4, rel=1e-2)  # 60 dB noise


@pytest.mark.parametrize("stored, sdc", [
    (3.0, 5.0),    # below 2 pi: ignored; an SDC of 5 is kept at 2 pi (a bound of 3 refused it)
    (20.0, None),  # not the stored masses' 38.3: ignored; the 8.4 record is left out at 2 pi
])
def test_calibrate_store_and_compare_say_why_a_stored_bound_was_ignored(
        tmp_path, capsys, heavy_file, stored, sdc):
    # report --store said "the SDC bound stored with the record ... ignored"; calibrate
    # --store (and the app's Calibrate page) and the app's Compare page judged the record at
    # 2 pi alike, and said nothing of why
    from pidcore.calibrate.data import measured_from_store
    from pidcore.compare.case import paper_table
    from pidcore.report.case_view import case_view, saved_entries
    from pidcore.store import Store
    from pidcore.store.listing import saved_analyses

    store, key = _saved_heavy_record(tmp_path, heavy_file)
    _edit_record(store, key, **{RECORDED_BOUND_FIELD: stored},
                 # an analysis saves sdc = 2 pi loss_factor; an edit of one alone is refused
                 **({} if sdc is None else {"sdc": sdc, "loss_factor": sdc / (2 * math.pi)}))
    note = recorded_sdc_bound(Store(store).list_analyses().iloc[0])[1]
    assert note.startswith(f"the SDC bound stored with the record ({RECORDED_BOUND_FIELD} "
                           f"{stored:.4g}) is ") and note.endswith(": ignored, judged as "
                                                                   "without it")
    line = f"rec.csv: {note}"
    left_out: list[str] = []
    if sdc is None:
        with pytest.raises(Exception, match="all implausible") as refused:
            measured_from_store(store, left_out=left_out)
        # the error, all that calibrate --store prints then, says why too
        assert f"(loss factor 1.34 > 1); {note}); a fit takes none of them" in \
            str(refused.value)
        assert main(["calibrate", "--store", str(store), "--fit", "fixture_mass_kg",
                     "--dem-store", str(tmp_path / "d.h5"), "--no-progress"]) == 2
        assert f"; {note}); a fit takes none of them" in capsys.readouterr().err
        assert left_out[0] == line  # first: why it is judged at 2 pi, then what that left out
        assert left_out[1].startswith("rec.csv: left out, implausible (saved as accepted): "
                                      "SDC 8.399 is above the physical bound 6.28 (loss")
        assert len(left_out) == 2
    else:
        (point,) = measured_from_store(store, left_out=left_out)
        assert point.sdc == sdc and point.sdc_bound.sdc == SDC_UPPER_BOUND
        assert left_out == [line]
    # with the file at hand its own bound decides: nothing ignored, nothing said
    left_out = []
    (point,) = measured_from_store(store, left_out=left_out, specimen=heavy_specimen())
    assert left_out == []
    # the app's Compare page: the entry carries the note, and the case's notes say it
    (entry,) = saved_entries(store, saved_analyses(store))
    assert entry.bound_note == note
    view = case_view([entry], None, paper_table(), (store, None))
    assert view["notes"].count(line) == 1
    (known,) = saved_entries(store, saved_analyses(store), [heavy_specimen()])
    assert known.bound_note == ""
    # report --store says the same line
    capsys.readouterr()
    assert main(["report", "--store", str(store), "--out", str(tmp_path / "r"),
                 "--format", "csv"]) == 0
    assert f"note: {line}\n" in capsys.readouterr().out
