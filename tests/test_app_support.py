"""pidcore.app_support: the app's logic, tested without Streamlit."""

from __future__ import annotations

import hashlib
import json
import math
import re
import threading
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from _app_samples import analytic_sdc, mass_damper_csv

from pidcore import app_support, defaults
from pidcore.errors import ParameterError

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def good_csv() -> bytes:
    return mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0, loss_factor=0.05)


@pytest.fixture(scope="module")
def options():
    from pidcore.measure import AnalysisOptions

    return AnalysisOptions()


# --- uploads -----------------------------------------------------------------------------------

@pytest.mark.parametrize("name, expected", [
    ("run_fill50.csv", "run_fill50.csv"),
    ("../../etc/pass wd.csv", "pass_wd.csv"),
    ("C:\\data\\x.uff", "x.uff"),
    (".hidden.h5", "hidden.h5"),
    ("", "upload"),
])
def test_safe_file_name_keeps_no_folder_and_the_extension(name, expected):
    assert app_support.safe_file_name(name) == expected


def test_upload_size_limit_is_the_configured_one():
    limit = defaults.APP_MAX_UPLOAD_MB * 1024 * 1024
    app_support.check_upload_size("a.csv", limit)  # exactly at the limit is allowed
    with pytest.raises(ParameterError, match=r"a\.csv.*limit of 200 MB"):
        app_support.check_upload_size("a.csv", limit + 1)
    with pytest.raises(ParameterError, match="empty"):
        app_support.check_upload_size("a.csv", 0)


def test_store_path_comes_from_the_environment(tmp_path):
    assert app_support.store_path({}) == defaults.STORE_PATH
    target = tmp_path / "s.h5"
    assert app_support.store_path({app_support.STORE_ENV_VAR: str(target)}) == target


def test_parse_upload_names_the_users_file_and_detects_roles(good_csv):
    parsed = app_support.parse_upload("coupon_fill50.csv", good_csv)
    assert parsed.error is None
    assert parsed.measurement.source == "coupon_fill50.csv"  # not the temporary copy
    assert parsed.sha256 == hashlib.sha256(good_csv).hexdigest()
    assert parsed.channels.force == "Force"
    assert parsed.channels.velocity == "Velocity"
    assert parsed.channels.options("acceleration")[-1] == app_support.NO_CHANNEL


def test_upload_analysis_equals_analyze_file_and_the_analytic_truth(tmp_path, good_csv, options):
    from pidcore.measure import analyze_file

    outcome = app_support.analyze_upload("coupon.csv", good_csv, options)
    path = tmp_path / "coupon.csv"
    path.write_bytes(good_csv)
    direct = analyze_file(path, options)
    assert outcome.ok and outcome.error is None
    # Same bytes, same code path: identical numbers.
    assert outcome.record.analysis.sdc == direct.analysis.sdc
    assert outcome.record.analysis.sdc_stderr == direct.analysis.sdc_stderr
    # Mass-damper truth SDC = 2 pi eta; 0.1 % noise on 100 periods moves it far below 1 %.
    assert outcome.record.analysis.sdc == pytest.approx(analytic_sdc(0.05), rel=1e-2)


@pytest.mark.parametrize("data", [b"not,a\nmeasurement\x00\x01", b"\x89HDF\r\n\x1a\ngarbage",
                                  b"    -1\n    58\ngarbage\n"])
def test_bad_upload_becomes_a_message_naming_the_file(data, options):
    outcome = app_support.analyze_upload("broken_export.uff", data, options)
    assert not outcome.ok
    assert "broken_export.uff" in outcome.error
    assert "pidcore_upload_" not in outcome.error  # the temporary copy is never shown
    assert "\n" not in outcome.error


def test_missing_channel_message_points_to_the_selectboxes(options):
    data = b"Time [s],Pressure [Pa]\n" + b"".join(
        f"{i / 1000:.4f},{np.sin(i / 10):.6f}\n".encode() for i in range(2000))
    outcome = app_support.analyze_upload("mic.csv", data, options)
    assert not outcome.ok and "mic.csv" in outcome.error
    assert "--force" not in outcome.error and "--velocity" not in outcome.error


def test_channel_mapping_is_applied(good_csv, options):
    from pidcore.measure import AnalysisOptions

    data = mass_damper_csv(extra_velocity_phase_rad=0.3)
    default = app_support.analyze_upload("x.csv", data, app_support.role_options(
        options, force="Force", velocity="Velocity", acceleration=app_support.NO_CHANNEL))
    moved = app_support.analyze_upload("x.csv", data, app_support.role_options(
        options, force="Force", velocity="Velocity 2", acceleration=app_support.NO_CHANNEL))
    assert moved.record.channels_used["velocity"] == "Velocity 2"
    assert moved.record.analysis.sdc != pytest.approx(default.record.analysis.sdc, rel=1e-3)
    assert app_support.options_from_json(app_support.options_to_json(
        AnalysisOptions(velocity="Velocity 2"))) == AnalysisOptions(velocity="Velocity 2")


# --- load cases, loops, spectrum -----------------------------------------------------------------

def _record(data: bytes, options, name="x.csv"):
    outcome = app_support.analyze_upload(name, data, options)
    assert outcome.ok, outcome.error
    return outcome.record


def test_load_cases_group_within_the_compare_tolerances(options):
    a = _record(mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0), options)
    b = _record(mass_damper_csv(frequency_hz=100.0, acceleration_g=5.1, seed=2), options)
    c = _record(mass_damper_csv(frequency_hz=500.0, acceleration_g=5.0, sample_rate_hz=20000),
                options)
    cases = [app_support.load_case_of(a, fill_percent=50, material="acrylic"),
             app_support.load_case_of(b, fill_percent=50, material="acrylic"),
             app_support.load_case_of(a, fill_percent=75, material="acrylic"),
             app_support.load_case_of(c, fill_percent=50, material="acrylic")]
    # 5.0 and 5.1 g are 2 % apart (< 5 % acceleration tolerance): one case.
    assert app_support.group_load_cases(cases) == [[0, 1], [2], [3]]


def test_loop_area_is_the_analytic_ellipse_area():
    theta = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    x, f = 2.0 * np.cos(theta), 3.0 * np.sin(theta)
    # The ellipse x = a cos, y = b sin has area pi a b (counter-clockwise: positive).
    assert app_support.loop_area(x, f) == pytest.approx(math.pi * 6.0, rel=1e-6)
    assert app_support.loop_area(x[::-1], f[::-1]) == pytest.approx(-math.pi * 6.0, rel=1e-6)
    with pytest.raises(ParameterError):
        app_support.loop_area(x, f[:-1])


def test_measured_loop_area_is_the_dissipated_energy(good_csv, options):
    from _app_samples import MASS_KG, damper_for

    rec = _record(good_csv, options)
    loop = app_support.measured_loop(rec)
    w = 2 * math.pi * rec.analysis.frequency_hz
    x_amp = rec.analysis.velocity_amplitude_m_s / w
    c = damper_for(0.05, 100.0)
    # A viscous damper dissipates pi c w X^2 per cycle; the mass adds no area.
    assert loop.energy_per_cycle_j == pytest.approx(math.pi * c * w * x_amp ** 2, rel=1e-2)
    assert loop.energy_per_cycle_j == pytest.approx(rec.analysis.energy_per_cycle_j, rel=1e-2)
    assert MASS_KG > 0


def test_spectrum_table_holds_the_fitted_phasor_amplitudes(good_csv, options):
    rec = _record(good_csv, options)
    table = app_support.spectrum_table(rec)
    a = rec.analysis
    np.testing.assert_array_equal(table["force amplitude [N]"], np.abs(a.force_phasors_n))
    np.testing.assert_array_equal(table["velocity amplitude [m/s]"],
                                  np.abs(a.velocity_phasors_m_s))
    fundamental = table.iloc[0]
    # Pure drive: the fundamental holds the velocity amplitude V = a / w.
    v_amp = 5.0 * 9.80665 / (2 * math.pi * 100.0)
    assert fundamental["velocity amplitude [m/s]"] == pytest.approx(v_amp, rel=1e-2)
    assert fundamental["frequency [Hz]"] == pytest.approx(100.0, rel=1e-4)


def test_compare_case_on_the_paper_grid(good_csv, options):
    from pidcore.model import load_paper_table3

    paper = load_paper_table3()
    rec = _record(good_csv, options)
    case = app_support.load_case_of(rec, fill_percent=50, material="acrylic")
    dem_runs = pd.DataFrame({
        "case_key": ["r1", "r2", "r3"], "frequency_hz": [100.0, 100.0, 100.0],
        "acceleration_g": [5.0, 5.0, 5.0], "fill_percent": [50.0, 50.0, 75.0],
        "material": ["acrylic"] * 3, "direction": ["z"] * 3,
        "sdc": [0.20, 0.22, 0.30], "sdc_stderr": [0.01, 0.01, 0.02]})
    comp = app_support.compare_case([(rec, case)], dem_runs, paper)
    # One record: pooled values are the record's own.
    assert comp.measured_sdc == rec.analysis.sdc
    assert comp.measured_stderr == rec.analysis.sdc_stderr
    # Two runs at 50 %: mean 0.21; stderr = max(sqrt(2)*0.01/2, std/sqrt(2)) = 0.01.
    assert comp.aligned.status == "grid"
    assert comp.aligned.sdc_dem == pytest.approx(0.21)
    assert comp.aligned.sdc_dem_stderr == pytest.approx(0.01)
    assert comp.dem_points["fill [%]"].tolist() == [50.0, 75.0]
    # Table 3 at 100 Hz, 5 g: DEM 0.1891 and measured 0.21 at 50 % fill.
    row = comp.paper_points.set_index("fill [%]").loc[50.0]
    assert row["SDC DEM (paper) [-]"] == 0.1891
    assert row["SDC measured (paper) [-]"] == 0.21
    # Without the DEM's m_c the like-for-like SDC is unknown.
    assert math.isnan(comp.measured_sdc_eq10)
    # pchip interpolates: the curve passes through the paper's DEM values at its grid fills.
    at_grid = np.interp(comp.paper_points["fill [%]"], comp.model_fill_percent, comp.model_sdc)
    np.testing.assert_allclose(at_grid, comp.paper_points["SDC DEM (paper) [-]"], rtol=2e-2)


def test_chart_data_hold_every_series_with_their_errors(good_csv, options):
    from pidcore.model import load_paper_table3

    rec = _record(good_csv, options)
    case = app_support.load_case_of(rec, fill_percent=50, material="acrylic")
    dem_runs = pd.DataFrame({
        "case_key": ["r1"], "frequency_hz": [100.0], "acceleration_g": [5.0],
        "fill_percent": [25.0], "material": ["acrylic"], "direction": ["z"],
        "sdc": [0.15], "sdc_stderr": [0.02]})
    comp = app_support.compare_case([(rec, case)], dem_runs, load_paper_table3())
    data = app_support.sdc_chart_data(comp)
    by = {name: g for name, g in data.groupby("series")}
    measured = by["measured (± stderr)"].iloc[0]
    a = rec.analysis
    assert (measured["fill [%]"], measured["SDC [-]"]) == (50.0, a.sdc)
    assert measured["low [-]"] == a.sdc - a.sdc_stderr
    assert measured["high [-]"] == a.sdc + a.sdc_stderr
    dem = by["our DEM (mean ± stderr)"].iloc[0]
    assert dem["fill [%]"] == 25.0
    assert (dem["low [-]"], dem["high [-]"]) == pytest.approx((0.13, 0.17), abs=1e-15)
    # Only 50 % fill has a measured value in Table 3: NaN rows are left out.
    assert by["paper measured"]["fill [%]"].tolist() == [50.0]
    assert by["paper DEM"]["fill [%]"].tolist() == [25.0, 50.0, 75.0, 90.0]
    loops = app_support.loop_chart_data([app_support.measured_loop(rec)])
    # Closed: last point repeats the first; displacement shown in mm.
    assert loops.iloc[0]["force [N]"] == loops.iloc[-1]["force [N]"]
    loop = app_support.measured_loop(rec)
    assert loops["displacement [mm]"].iloc[1] == pytest.approx(loop.displacement_m[1] * 1e3)
    assert f"{loop.energy_per_cycle_j:.3e} J/cycle" in loops["series"].iloc[0]


# --- store -------------------------------------------------------------------------------------

def test_save_writes_the_load_case_and_the_report_reads_it(tmp_path, good_csv, options):
    from pidcore.store import Store

    rec = _record(good_csv, options, name="coupon_fill50.csv")
    case = app_support.load_case_of(rec, fill_percent=50, material="acrylic")
    store_file = tmp_path / "store.h5"
    keys = app_support.save_records(store_file, [(rec, case)], options)
    listed = Store(store_file).list_analyses()
    assert listed["key"].tolist() == keys
    row = listed.iloc[0]
    assert row["sdc"] == rec.analysis.sdc
    assert (row["fill_percent"], row["material"], row["direction"]) == (50.0, "acrylic", "z")
    table = app_support.report_table(store_file)
    assert table["SDC measured [-]"].tolist() == [rec.analysis.sdc]
    assert table["SDC DEM (paper) [-]"].tolist() == [0.1891]


def test_two_sessions_saving_at_once_keep_the_store_whole(tmp_path, options):
    from pidcore.store import Store

    store_file = tmp_path / "store.h5"
    batches = []
    for i in range(2):
        recs = []
        for j in range(3):
            rec = _record(mass_damper_csv(seed=10 * i + j), options, name=f"s{i}_{j}.csv")
            recs.append((rec, app_support.load_case_of(rec, fill_percent=50,
                                                       material="acrylic")))
        batches.append(recs)
    barrier = threading.Barrier(2)
    errors = []

    def save(batch):
        try:
            barrier.wait()
            app_support.save_records(store_file, batch, options)
        except Exception as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=save, args=(b,)) for b in batches]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    store = Store(store_file)
    assert store.verify() == []
    # Every record of both sessions is there: neither commit overwrote the other.
    assert len(store.list_analyses()) == 6
    assert len(store.list_measurements()) == 6


def test_report_downloads_hold_the_saved_numbers(tmp_path, good_csv, options):
    rec = _record(good_csv, options, name="coupon.csv")
    case = app_support.load_case_of(rec, fill_percent=50, material="acrylic")
    store_file = tmp_path / "store.h5"
    app_support.save_records(store_file, [(rec, case)], options)
    files = app_support.report_files(store_file)
    assert set(files) == {"csv", "html", "tex", "pdf"}
    name, data, mime = files["pdf"]
    assert name.endswith(".pdf") and data.startswith(b"%PDF") and mime == "application/pdf"
    import io

    table = pd.read_csv(io.BytesIO(files["csv"][1]), comment="#")
    assert table["SDC measured [-]"].iloc[0] == pytest.approx(rec.analysis.sdc, rel=1e-9)
    assert b"<table" in files["html"][1]
    assert b"\\begin{" in files["tex"][1]


# --- launching ---------------------------------------------------------------------------------

@pytest.mark.parametrize("folder", [REPO, REPO / "app"])
def test_streamlit_config_matches_the_defaults(folder):
    config = tomllib.loads((folder / ".streamlit" / "config.toml").read_text())
    assert config["server"]["maxUploadSize"] == defaults.APP_MAX_UPLOAD_MB
    assert config["browser"]["gatherUsageStats"] is False


def test_app_command_serves_the_packaged_entry_on_localhost(tmp_path):
    import pidcore
    from pidcore._app import ENTRY_SCRIPT
    from pidcore.cli.app import app_environment, streamlit_command

    cmd = streamlit_command(8765, python="python")
    assert cmd[:4] == ["python", "-m", "streamlit", "run"]
    entry = Path(cmd[4])
    # Inside the installed package, so a non-editable install finds it too.
    assert entry == ENTRY_SCRIPT and entry.is_file()
    assert entry.parent.parent == Path(pidcore.__file__).parent
    opts = dict(zip(cmd[5::2], cmd[6::2], strict=True))
    assert opts["--server.address"] == "localhost"
    assert opts["--server.port"] == "8765"
    assert opts["--server.headless"] == "true"
    assert opts["--browser.gatherUsageStats"] == "false"
    assert opts["--server.maxUploadSize"] == str(defaults.APP_MAX_UPLOAD_MB)
    with pytest.raises(ParameterError, match="port"):
        streamlit_command(70000)
    env = app_environment(Path("rel.h5"), environ={})
    assert Path(env[app_support.STORE_ENV_VAR]).is_absolute()
    assert env["STREAMLIT_BROWSER_GATHER_USAGE_STATS"] == "false"
    assert app_support.DEM_STORE_ENV_VAR not in env
    with pytest.raises(ParameterError, match="dem-store"):
        app_environment(Path("rel.h5"), tmp_path / "missing.h5", environ={})
    # The repository shim runs the packaged app.
    shim = (REPO / "app" / "pidcore_app.py").read_text()
    assert "from pidcore._app.ui import main" in shim


# --- DEM from the app ----------------------------------------------------------------------------

def test_dem_sweep_plan_is_the_product_and_is_kept_small():
    cases = app_support.plan_dem_cases([100.0, 50.0], [5.0], [75.0, 25.0], material="acrylic",
                                       direction="z")
    assert [(c.frequency_hz, c.fill_percent) for c in cases] == [
        (50.0, 25.0), (50.0, 75.0), (100.0, 25.0), (100.0, 75.0)]
    with pytest.raises(ParameterError, match="at least one"):
        app_support.plan_dem_cases([], [5.0], [50.0], material="acrylic", direction="z")
    with pytest.raises(ParameterError, match="at most"):
        app_support.plan_dem_cases([50, 100, 500], [1, 5, 10], [25, 50], material="acrylic",
                                   direction="z")


def test_dem_case_is_saved_and_its_loop_area_is_the_shaker_work(tmp_path):
    from pidcore.dem import DemConfig, simulate_load_case
    from pidcore.store import Store

    store_file = tmp_path / "dem.h5"
    (case,) = app_support.plan_dem_cases([100.0], [5.0], [50.0], material="acrylic",
                                         direction="z")
    config = DemConfig(cells=2, steady_cycles=20)
    assert not app_support.dem_run_stored(store_file, case, config)
    key = app_support.run_dem_case(store_file, case, config)
    assert app_support.dem_run_stored(store_file, case, config)
    entry = Store(store_file).get_dem_run(key)
    # Deterministic (seeded): the stored SDC is the simulation's.
    assert entry.record["sdc"] == simulate_load_case(case, config).sdc
    loop = app_support.dem_loop(entry)
    assert not isinstance(loop, str), loop
    # With a sine drive only the fundamental carries power, so the loop's area is the shaker's
    # work per steady cycle: the dissipated energy per cycle up to the change of stored
    # mechanical energy over 20 cycles of 2 cells (a few percent), hence 5 %.
    assert loop.energy_per_cycle_j == pytest.approx(entry.record["energy_per_cycle_j"], rel=5e-2)


def test_pidcore_app_serves_on_localhost_until_stopped(tmp_path):
    import socket
    import subprocess
    import sys
    import time
    import urllib.request

    pytest.importorskip("streamlit")
    with socket.socket() as s:
        s.bind(("localhost", 0))
        port = s.getsockname()[1]
    proc = subprocess.Popen([sys.executable, "-m", "pidcore", "app", "--port", str(port),
                             "--store", str(tmp_path / "s.h5")], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        deadline = time.monotonic() + 45  # cold start imports streamlit
        while True:
            try:
                with urllib.request.urlopen(f"http://localhost:{port}/_stcore/health",
                                            timeout=2) as r:
                    assert r.read().strip() == b"ok"
                    break
            except OSError:
                assert proc.poll() is None, proc.stdout.read().decode()[-2000:]
                assert time.monotonic() < deadline, "pidcore app did not answer"
                time.sleep(0.2)
        with urllib.request.urlopen(f"http://localhost:{port}/", timeout=5) as r:
            assert b"<html" in r.read().lower()
    finally:
        proc.terminate()
        proc.wait(timeout=15)
    # Nothing was written: the app only writes the store when the user saves.
    assert not (tmp_path / "s.h5").exists()


def _dem_record(sdc: float, fill: float = 50.0) -> dict:
    return {"frequency_hz": 100.0, "acceleration_g": 5.0, "fill_percent": fill,
            "material": "acrylic", "direction": "z", "sdc": sdc, "sdc_stderr": 0.01}


def test_reference_dem_store_joins_the_app_store_read_only(tmp_path, good_csv, options):
    from pidcore.store import Store

    app_file, ref_file = tmp_path / "app.h5", tmp_path / "ref.h5"
    Store(ref_file).add_dem_run("shared", _dem_record(0.40))
    Store(ref_file).add_dem_run("ref_only", _dem_record(0.30, fill=75.0))
    Store(app_file).add_dem_run("shared", _dem_record(0.20))
    ref_bytes = ref_file.read_bytes()
    runs = app_support.list_dem_runs(app_file, ref_file).set_index("case_key")
    # A key in both comes from the app store; the reference adds its other runs.
    assert runs.loc["shared", "sdc"] == 0.20 and runs.loc["shared", "store"] == str(app_file)
    assert runs.loc["ref_only", "store"] == str(ref_file)
    assert app_support.list_dem_runs(tmp_path / "none.h5").empty

    rec = _record(good_csv, options, name="c.csv")
    app_support.save_records(app_file, [(rec, app_support.load_case_of(
        rec, fill_percent=50, material="acrylic"))], options)
    table = app_support.report_table(app_file, ref_file)
    assert table["packing ratio [%]"].tolist() == [50.0, 75.0]
    assert table["SDC DEM (ours) [-]"].tolist() == [0.20, 0.30]
    assert table["SDC measured [-]"].iloc[0] == rec.analysis.sdc
    files = app_support.report_files(app_file, ref_file)
    html = files["html"][1].decode()
    assert str(ref_file.name) in html and str(app_file.name) in html  # provenance: both stores
    assert ref_file.read_bytes() == ref_bytes  # never written


def test_stores_come_from_the_environment_or_the_bundled_samples(tmp_path):
    env = {app_support.STORE_ENV_VAR: str(tmp_path / "a.h5")}
    assert app_support.AppStores.from_environment(env, cwd=tmp_path) == app_support.AppStores(
        tmp_path / "a.h5", None)
    bundled = tmp_path / app_support.BUNDLED_DEM_STORE
    bundled.parent.mkdir(parents=True)
    bundled.write_bytes(b"")
    assert app_support.dem_store_path({}, cwd=tmp_path) == bundled
    named = {app_support.DEM_STORE_ENV_VAR: str(tmp_path / "ref.h5")}
    assert app_support.dem_store_path(named, cwd=tmp_path) == tmp_path / "ref.h5"
    stores = app_support.AppStores(tmp_path / "a.h5", bundled)
    before = stores.stamp()
    (tmp_path / "a.h5").write_bytes(b"x")
    assert stores.stamp() != before  # a rewritten store invalidates cached listings


def test_load_case_is_proposed_from_name_and_uploaded_sidecar():
    from pidcore.compare import LoadCaseError

    by_name = app_support.stated_case("run_fill75_aluminum_dirx.csv")
    assert (by_name.fill_percent, by_name.material, by_name.direction) == (75.0, "aluminium",
                                                                           "x")
    sidecar = app_support.read_sidecar_upload(
        b"file,fill_percent,material,direction\nrun_fill75_aluminum_dirx.csv,90,acrylic,z\n")
    # The sidecar overrides the file name (as in pidcore report).
    both = app_support.stated_case("run_fill75_aluminum_dirx.csv", sidecar)
    assert (both.fill_percent, both.material, both.direction) == (90.0, "acrylic", "z")
    assert "sidecar" in both.origin
    unstated = app_support.stated_case("plain.csv", sidecar)
    assert unstated.fill_percent == app_support.DEFAULT_FILL_PERCENT
    assert "not stated" in unstated.origin
    assert app_support.is_sidecar_upload("LoadCases.CSV")
    with pytest.raises(LoadCaseError, match=r"^loadcases\.csv: .*lacks column 'file'"):
        app_support.read_sidecar_upload(b"a,b\n1,2\n")


def test_chart_specs_are_valid_vega_lite(good_csv, options):
    # The app sends the specs unvalidated (speed); validate them here against the schema.
    from pidcore._app import charts

    rec = _record(good_csv, options)
    case = app_support.load_case_of(rec, fill_percent=50, material="acrylic")
    comp = app_support.compare_case([(rec, case)], None, app_support.paper_table())
    loops = [app_support.measured_loop(rec)]
    for chart in (charts.sdc_chart(app_support.sdc_chart_data(comp)),
                  charts.loop_chart(app_support.loop_chart_data(loops)),
                  charts.spectrum_chart(app_support.spectrum_table(rec))):
        spec = chart.to_dict(validate=True)
        assert spec["$schema"].startswith("https://vega.github.io/schema/vega-lite/")
        # Vega-Lite reads "[" and "." in field names as nested access: none may be used.
        fields = json.dumps(spec["layer"] if "layer" in spec else spec.get("hconcat", spec))
        assert "[" not in "".join(re.findall(r'"field": "([^"]*)"', fields))


def test_like_for_like_sdc_uses_the_dem_vibrated_mass_as_the_report_does(good_csv, options):
    from pidcore.report import build_report_table
    from pidcore.report.table import MEASURED_EQ10_COLUMN

    rec = _record(good_csv, options, name="c.csv")
    case = app_support.load_case_of(rec, fill_percent=50, material="acrylic")
    dem_runs = pd.DataFrame({
        "case_key": ["r1"], "frequency_hz": [100.0], "acceleration_g": [5.0],
        "fill_percent": [50.0], "material": ["acrylic"], "direction": ["z"],
        "sdc": [0.2], "sdc_stderr": [0.01], "m_c_kg": [0.9]})
    paper = app_support.paper_table()
    comp = app_support.compare_case([(rec, case)], dem_runs, paper)
    a = rec.analysis
    w = 2 * math.pi * a.frequency_hz
    e_ref = 0.9 * (a.acceleration_g * 9.80665) ** 2 / (2 * w ** 2)  # Eq. 10 with m_c = 0.9 kg
    assert comp.measured_sdc_eq10 == pytest.approx(a.energy_per_cycle_j / e_ref, rel=1e-12)
    # Only the reference energy differs from the Eq. 11 SDC: same relative error.
    assert comp.measured_stderr_eq10 / comp.measured_sdc_eq10 == pytest.approx(
        a.sdc_stderr / a.sdc, rel=1e-12)
    from pidcore.measure import analysis_record

    analyses = pd.DataFrame([{**analysis_record(rec), "fill_percent": 50.0,
                              "material": "acrylic", "direction": "z"}])
    table = build_report_table(dem_runs, analyses, paper)
    assert table[MEASURED_EQ10_COLUMN].iloc[0] == pytest.approx(comp.measured_sdc_eq10,
                                                                 rel=1e-12)
    series = app_support.sdc_chart_data(comp).groupby("series")
    assert series.get_group("measured, E of Eq. 10 (± stderr)")["SDC [-]"].iloc[0] == \
        comp.measured_sdc_eq10
