"""Virtual shaker exports: DEM -> sensor-like record -> file -> Eq. 11 recovers the DEM energy."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pidcore.dem import DemConfig, LoadCase, simulate_load_case
from pidcore.io import read_measurement, write_measurement
from pidcore.measure import AnalysisOptions, analyze_measurement
from pidcore.samples import EXPORT_SAMPLE_RATE_HZ, SAMPLE_CASES, virtual_shaker_measurement
from pidcore.signal import analyze_power


@pytest.fixture(scope="module")
def dem_run():
    # short but steady: 2 cells, 30 measured cycles at 500 Hz, 5 g (bed in flight)
    return simulate_load_case(LoadCase(500.0, 5.0, 50.0),
                              DemConfig(cells=2, steady_cycles=30))


@pytest.mark.parametrize("fmt,binary,suffix", [("uff", False, ".uff"), ("csv", False, ".csv"),
                                               ("mat", False, ".mat"), ("uff", True, ".uff")])
def test_export_round_trip_recovers_dem_energy_per_cycle(tmp_path, dem_run, fmt, binary, suffix):
    start = dem_run.steady_start_cycle * dem_run.samples_per_cycle
    delay = 5e-5
    m = virtual_shaker_measurement(
        time_s=dem_run.sample_time_s[start:], shaker_force_n=dem_run.shaker_force_n[start:],
        frequency_hz=500.0, acceleration_m_s2=dem_run.case.acceleration_m_s2,
        source="x", velocity_delay_s=delay, snr_db=45.0, seed=1)
    path = tmp_path / f"export{suffix}"
    write_measurement(m, path, fmt, binary=binary)
    back = read_measurement(path)
    assert back.channels[0].sample_rate_hz == pytest.approx(EXPORT_SAMPLE_RATE_HZ, rel=1e-6)
    result = analyze_measurement(back, AnalysisOptions(velocity_delay_s=delay)).analysis
    # The DEM's own virtual shaker (no resampling, noise or delay) is the reference: the export
    # chain (polyphase resampling, 45 dB noise, delay removal, file round trip) must not move the
    # energy per cycle by more than 2 %.
    # same window as the export, which drops two periods at each end (resampling edges)
    trim = 2 * dem_run.samples_per_cycle
    reference = analyze_power(dem_run.shaker_force_n[start + trim:-trim],
                              dem_run.velocity_m_s[start + trim:-trim], dem_run.sample_rate_hz,
                              frequency_hz=500.0)
    assert result.energy_per_cycle_j == pytest.approx(reference.energy_per_cycle_j, rel=0.02)
    assert result.acceleration_g == pytest.approx(5.0, rel=0.01)
    assert result.frequency_hz == pytest.approx(500.0, rel=1e-4)
    # and without removing the delay the phase error shows: the energy is clearly biased
    biased = analyze_measurement(back, AnalysisOptions()).analysis
    assert abs(biased.energy_per_cycle_j / reference.energy_per_cycle_j - 1) > 0.05


def test_export_carries_the_stated_noise_and_delay(dem_run):
    start = dem_run.steady_start_cycle * dem_run.samples_per_cycle
    a = dem_run.case.acceleration_m_s2
    m = virtual_shaker_measurement(
        time_s=dem_run.sample_time_s[start:], shaker_force_n=dem_run.shaker_force_n[start:],
        frequency_hz=500.0, acceleration_m_s2=a, source="x", velocity_delay_s=0.0,
        snr_db=40.0, seed=2)
    velocity, accel = m.channel("Velocity").data, m.channel("Acceleration").data
    t = np.arange(accel.size) / EXPORT_SAMPLE_RATE_HZ
    # acceleration a sin(wt) and velocity -(a/w) cos(wt) on the same clock: v' = a
    w = 2 * math.pi * 500.0
    assert np.sqrt(np.mean(accel**2)) == pytest.approx(a / math.sqrt(2), rel=0.01)
    assert np.sqrt(np.mean(velocity**2)) == pytest.approx(a / w / math.sqrt(2), rel=0.01)
    assert t.size > 10 * EXPORT_SAMPLE_RATE_HZ / 500.0  # at least 10 drive periods kept


def test_sample_cases_cover_every_export_format_and_state_their_load_case():
    from pidcore.compare.loadcase import parse_file_name

    formats = {c.file_format for c in SAMPLE_CASES}
    assert formats == {"uff", "uff58b", "csv", "mat", "hdf5"}
    for case in SAMPLE_CASES:
        assert case.file_name.startswith("synthetic_")  # labelled as synthetic
        stated = parse_file_name(case.file_name)
        assert stated == {"fill_percent": case.fill_percent, "material": "acrylic"}


def test_make_samples_refuses_a_store_holding_other_settings(tmp_path):
    # regenerating into a store of older runs would mix two models in the bundled grid
    from pidcore.dem.persist import save_dem_result
    from pidcore.errors import StoreError
    from pidcore.samples import make_samples

    path = tmp_path / "dem_table3.h5"
    old = simulate_load_case(LoadCase(500, 5, 50), DemConfig(cells=1, steady_cycles=2,
                                                             block_cycles=2))
    save_dem_result(path, old)
    before = path.read_bytes()
    with pytest.raises(StoreError, match="other settings"):
        make_samples(tmp_path, run_sweep=False, progress=False)
    assert path.read_bytes() == before  # untouched


def test_own_specimen_exports_carry_the_specimens_material_and_name(tmp_path, capsys):
    """The trial script (docs/trial_own_specimen/make_measurements.py), copied for another
    specimen as the README says, wrote the trial's 'alumina' into every load case (a DEM error
    for steel; for a table material, tests labelled with the wrong particles) and named its
    files without the fill, so two fills of one frequency, acceleration and format overwrote
    one another. The exports of a steel specimen at two fills must be two files that
    `pidcore analyze --sidecar --specimen` places as steel tests of that specimen at their fills."""
    import json

    from pidcore.cli import main
    from pidcore.samples import own_specimen_exports
    from pidcore.specimen import load_specimen

    specimen_file = "data_samples/specimens/steel_6mm.toml"
    truth = load_specimen(specimen_file).with_values({"coupon.fixture_mass_kg": 0.03})
    cases = [(500, 5, 25.0, "csv"), (500, 5, 50.0, "csv")]
    # 20 cycles: the export drops two periods each end and the analysis needs 10
    paths = own_specimen_exports(truth, cases, tmp_path,
                                 config=DemConfig(cells=1, steady_cycles=20))
    assert len({p.name for p in paths}) == 2 and all(p.is_file() for p in paths)
    code = main(["analyze", *map(str, paths), "--sidecar", str(tmp_path / "loadcases.csv"),
                 "--specimen", specimen_file, "--no-store", "--json", "--no-progress"])
    out, err = capsys.readouterr()
    assert code == 0, err
    records = {r["source"].rsplit("/", 1)[-1]: r for r in json.loads(out)["records"]}
    for path, (_, _, fill, _) in zip(paths, cases, strict=True):
        record = records[path.name]
        assert record["load_case"].endswith(f"_fill{fill:g}pct_steel_z"), record["load_case"]
        assert record["specimen"] == "steel_6mm"


def test_own_specimen_exports_refuse_one_file_written_twice(tmp_path):
    from pidcore.errors import ParameterError
    from pidcore.samples import own_specimen_exports
    from pidcore.specimen import paper_specimen

    with pytest.raises(ParameterError, match=r"two cases write trial_f500Hz_a5g_fill50pct\.csv"):
        own_specimen_exports(paper_specimen(), [(500, 5, 50, "csv"), (500, 5, 50, "csv")],
                             tmp_path, config=DemConfig(cells=1, steady_cycles=10))
    assert not any(tmp_path.iterdir())  # refused before any run or file


def _synthetic_dem_record(cycles: int, frequency_hz: float = 200.0):
    """A DEM-like shaker record of ``cycles`` whole drive periods at the DEM's 128 samples per
    period: a mass-like force with a damping part (Re(P_c) > 0, Im(P_c) > 0)."""
    n = cycles * 128
    t = np.arange(n) / (128 * frequency_hz)
    w = 2 * math.pi * frequency_hz
    # velocity is -a/w cos(wt) in virtual_shaker_measurement: damping force in phase with it
    return t, 0.2 * 49.0 * np.sin(w * t) - 0.5 * np.cos(w * t)


@pytest.mark.parametrize("cycles,accepted", [(13, False), (14, True)])
def test_export_trim_leaves_what_the_analysis_needs(cycles, accepted):
    """The bound own_specimen_exports checks is the real one: a steady record of 14 cycles
    exports 10 whole periods, which the analysis takes; 13 cycles export 9, refused."""
    from pidcore.errors import PidcoreError

    t, force = _synthetic_dem_record(cycles)
    m = virtual_shaker_measurement(time_s=t, shaker_force_n=force, frequency_hz=200.0,
                                   acceleration_m_s2=49.0, source="x", velocity_delay_s=0.0,
                                   snr_db=60.0, seed=1)
    if accepted:
        assert analyze_measurement(m, AnalysisOptions()).analysis.loss_factor > 0
    else:
        with pytest.raises(PidcoreError, match="expected at least 10"):
            analyze_measurement(m, AnalysisOptions())


def test_own_specimen_exports_refuse_too_few_cycles_before_any_run(tmp_path, monkeypatch):
    """steady_cycles = 10 (a quick trial of docs/trial_own_specimen/make_measurements.py) wrote
    exports of 6 drive periods wherever a run reached its transient cap (the export drops two
    periods each end), which `pidcore analyze` refuses (10 needed) -- found only after every
    DEM run. It must be refused before any run or file; 14 cycles, 10 periods, pass."""
    import pidcore.dem.simulate as simulate
    from pidcore.errors import ParameterError
    from pidcore.samples import own_specimen_exports
    from pidcore.specimen import paper_specimen

    class Ran(Exception):
        pass

    def no_run(*args, **kwargs):
        raise Ran

    monkeypatch.setattr(simulate, "simulate_load_case", no_run)
    with pytest.raises(ParameterError, match=r"steady_cycles 10 gives exports of 6 drive "
                                             r"periods.*expected steady_cycles >= 14"):
        own_specimen_exports(paper_specimen(), [(500, 5, 50, "csv")], tmp_path / "out",
                             config=DemConfig(cells=1, steady_cycles=10))
    assert not (tmp_path / "out").exists()
    with pytest.raises(Ran):  # 14 cycles pass the check and reach the DEM
        own_specimen_exports(paper_specimen(), [(500, 5, 50, "csv")], tmp_path / "out",
                             config=DemConfig(cells=1, steady_cycles=14))
