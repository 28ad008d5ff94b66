"""The Streamlit app's pages driven headless with streamlit.testing.v1.AppTest."""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import pytest
from _app_samples import mass_damper_csv

from pidcore import app_support

pytest.importorskip("streamlit")
from streamlit.testing.v1 import AppTest  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
SHIM = REPO / "app" / "pidcore_app.py"
ARTIFACTS = REPO / "test-artifacts"
#: AppTest waits this long for one script run; the first run imports pandas/matplotlib/h5py.
RUN_TIMEOUT_S = 60


@pytest.fixture
def store_file(tmp_path, monkeypatch):
    import streamlit as st

    st.cache_data.clear()
    st.cache_resource.clear()
    path = tmp_path / "app_store.h5"
    monkeypatch.setenv(app_support.STORE_ENV_VAR, str(path))
    # No reference DEM store unless a test names one (the bundled samples' store would be
    # picked up from the repository root otherwise).
    monkeypatch.delenv(app_support.DEM_STORE_ENV_VAR, raising=False)
    monkeypatch.chdir(tmp_path)
    yield path
    st.cache_data.clear()
    st.cache_resource.clear()


def _app() -> AppTest:
    at = AppTest.from_file(str(SHIM), default_timeout=RUN_TIMEOUT_S)
    at.run()
    assert not at.exception, at.exception
    return at


def _upload(at: AppTest, files: list[tuple[str, bytes]]) -> AppTest:
    at.file_uploader(key="uploads").set_value([(n, d, "text/csv") for n, d in files])
    at.run()
    assert not at.exception, at.exception
    return at


def _metric(at: AppTest, label: str) -> list[str]:
    return [m.value for m in at.metric if m.label == label]


def _table(at: AppTest, column: str):
    """The first dataframe shown that has ``column`` (results: "velocity channel";
    report: "SDC measured [-]")."""
    return next(d.value for d in at.dataframe if column in d.value.columns)


def _options(**kwargs):
    from pidcore.measure import AnalysisOptions

    return AnalysisOptions(**kwargs)


def test_upload_shows_the_library_sdc_and_bad_files_do_not_stop_the_others(store_file,
                                                                           tmp_path):
    from pidcore.measure import analyze_file

    good = mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0, loss_factor=0.05)
    other = mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0, loss_factor=0.02, seed=3)
    at = _upload(_app(), [("good_fill50.csv", good), ("broken.uff", b"    -1\n    58\nxx\n"),
                          ("other_fill50.csv", other)])
    errors = [e.value for e in at.error]
    assert len(errors) == 1 and "broken.uff" in errors[0]
    expected = []
    for name, data in (("good_fill50.csv", good), ("other_fill50.csv", other)):
        path = tmp_path / name
        path.write_bytes(data)
        expected.append(analyze_file(path, _options()).analysis)
    shown = _metric(at, "SDC ± stderr [-]")
    assert shown == [app_support.format_sdc(a.sdc, a.sdc_stderr) for a in expected]
    table = _table(at, "velocity channel")
    assert table["file"].tolist() == ["good_fill50.csv", "other_fill50.csv"]
    assert table["SDC [-]"].tolist() == [a.sdc for a in expected]
    assert table["SDC stderr [-]"].tolist() == [a.sdc_stderr for a in expected]
    assert table["loss factor [-]"].tolist() == [a.loss_factor for a in expected]
    # Nothing is written until Save.
    assert not store_file.exists()


def test_save_writes_to_the_store_only_when_pressed(store_file):
    from pidcore.store import Store

    data = mass_damper_csv()
    at = _upload(_app(), [("coupon_fill75_aluminium.csv", data)])
    at.number_input(key="delay_us").set_value(0.0)
    at.run()
    assert not store_file.exists()
    at.button(key="save").click()
    at.run()
    assert not at.exception
    assert any("saved 1" in s.value for s in at.success)
    listed = Store(store_file).list_analyses()
    assert len(listed) == 1
    row = listed.iloc[0]
    # The load case stated in the file name reached the store.
    assert (row["fill_percent"], row["material"]) == (75.0, "aluminium")
    shown = _table(at, "velocity channel")
    assert row["sdc"] == shown["SDC [-]"].iloc[0]


def test_mapping_and_corrections_change_the_analysis_like_the_library(store_file, tmp_path):
    from pidcore.measure import analyze_file

    data = mass_damper_csv(extra_velocity_phase_rad=0.3)
    path = tmp_path / "two_velocities.csv"
    path.write_bytes(data)
    at = _upload(_app(), [("two_velocities.csv", data)])
    velocity_box = next(s for s in at.selectbox if s.label == "velocity channel")
    velocity_box.set_value("Velocity 2")
    at.number_input(key="baseline_eta").set_value(0.002)
    at.run()
    assert not at.exception
    want = analyze_file(path, _options(velocity="Velocity 2", baseline_loss_factor=0.002,
                                       force="Force")).analysis
    table = _table(at, "velocity channel")
    assert table["velocity channel"].iloc[0] == "Velocity 2"
    assert table["SDC [-]"].iloc[0] == pytest.approx(want.sdc, rel=1e-12)


@pytest.fixture
def analysis_calls(monkeypatch) -> list[str]:
    """Names of the uploads the app analyses (a spy on app_support.analyze_parsed)."""
    calls: list[str] = []
    real = app_support.analyze_parsed

    def counting(parsed, options):
        calls.append(parsed.name)
        return real(parsed, options)

    monkeypatch.setattr(app_support, "analyze_parsed", counting)
    return calls


def test_compare_shows_dem_model_and_paper_and_switching_uses_the_cache(store_file,
                                                                       analysis_calls):
    calls = analysis_calls
    # Our DEM at 100 Hz, 5 g, 50 %: two runs in the store.
    from pidcore.store import Store

    store = Store(store_file)
    for key, sdc in (("dem_a", 0.20), ("dem_b", 0.22)):
        store.add_dem_run(key, {"frequency_hz": 100.0, "acceleration_g": 5.0,
                                "fill_percent": 50.0, "material": "acrylic", "direction": "z",
                                "sdc": sdc, "sdc_stderr": 0.01})
    files = [("a_fill50.csv", mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0)),
             ("b_fill90.csv", mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0,
                                              loss_factor=0.08, seed=4))]
    at = _upload(_app(), files)
    assert calls == ["a_fill50.csv", "b_fill90.csv"]
    assert _metric(at, "SDC our DEM ± stderr [-]") == ["0.2100 ± 0.0100"]
    assert _metric(at, "SDC paper DEM / measured [-]") == ["0.1891 / 0.2100"]
    specs = [json.loads(c.proto.spec) for c in at.get("vega_lite_chart")]
    titles = sorted(json.dumps(s.get("title", "")) for s in specs)
    assert len(specs) == 3 and any("loop" in t for t in titles)  # SDC, loop, spectrum
    timings = []
    for choice in (1, 0, 1, 0):
        at.selectbox(key="compare_case").set_value(choice)
        start = time.perf_counter()
        at.run()
        timings.append(time.perf_counter() - start)
        assert not at.exception
    # Table 3 at 100 Hz, 5 g, 90 %: DEM 0.3190, no measured value.
    assert _metric(at, "SDC paper DEM / measured [-]") == ["0.1891 / 0.2100"]
    at.selectbox(key="compare_case").set_value(1)
    at.run()
    assert _metric(at, "SDC paper DEM / measured [-]") == ["0.3190 / nan"]
    # Switching load cases never re-analyses a file (content-hash cache).
    assert calls == ["a_fill50.csv", "b_fill90.csv"]
    ARTIFACTS.mkdir(exist_ok=True)
    (ARTIFACTS / "app_switch_timing.json").write_text(json.dumps(
        {"load_case_switch_s": timings,
         "note": "AppTest script run (whole page) after changing the load case; every case "
                 "was warmed in the cache after the upload"}, indent=1))


def test_report_tab_shows_the_table_and_offers_downloads(store_file):
    data = mass_damper_csv()
    at = _upload(_app(), [("coupon_fill50.csv", data)])
    at.button(key="save").click()
    at.run()
    shown_sdc = _table(at, "velocity channel")["SDC [-]"].iloc[0]
    at.run()  # the report tab reads the store written by the previous run
    table = _table(at, "SDC measured [-]")
    assert table["SDC measured [-]"].tolist() == [shown_sdc]
    assert table["SDC DEM (paper) [-]"].tolist() == [0.1891]
    at.button(key="build_report").click()
    at.run(timeout=RUN_TIMEOUT_S)
    assert not at.exception
    labels = sorted(b.label for b in at.get("download_button"))
    assert labels == ["CSV", "HTML", "PDF", "TEX"]


def test_dem_tab_runs_saves_and_the_compare_tab_uses_the_run(store_file):
    from pidcore.dem import DemConfig, LoadCase, simulate_load_case
    from pidcore.store import Store

    at = _upload(_app(), [("coupon_fill50.csv", mass_damper_csv(frequency_hz=100.0,
                                                                 acceleration_g=5.0))])
    assert _metric(at, "SDC our DEM ± stderr [-]") == ["none"]
    at.multiselect(key="dem_freqs").set_value([100.0])
    at.multiselect(key="dem_accs").set_value([5.0])
    at.multiselect(key="dem_fills").set_value([50.0])
    at.number_input(key="dem_cells").set_value(2)
    at.number_input(key="dem_steady").set_value(20)
    at.run()
    assert not store_file.exists()
    at.button(key="dem_run").click()
    at.run(timeout=RUN_TIMEOUT_S)
    assert not at.exception, at.exception
    assert any("1 case(s) run and saved" in s.value for s in at.success)
    runs = Store(store_file).list_dem_runs()
    assert len(runs) == 1
    want = simulate_load_case(LoadCase(100.0, 5.0, 50.0), DemConfig(cells=2, steady_cycles=20))
    assert runs["sdc"].iloc[0] == want.sdc
    # The Compare tab now shows our DEM (mean ± stderr of the one run) for the measured case,
    # and its loop (with its energy per cycle) next to the measurement's.
    assert _metric(at, "SDC our DEM ± stderr [-]") == [
        app_support.format_sdc(want.sdc, want.sdc_stderr)]
    energies = [m.value for m in at.markdown if m.value.startswith("energy per cycle")]
    assert len(energies) == 1 and "our DEM" in energies[0] and "measured" in energies[0]
    # A second run of the same case is recognised as stored and not simulated again.
    at.button(key="dem_run").click()
    at.run(timeout=RUN_TIMEOUT_S)
    assert any("0 case(s) run and saved, 1 already in the store" in s.value for s in at.success)
    assert len(Store(store_file).list_dem_runs()) == 1


def test_upload_limit_is_shown_and_enforced_per_file(store_file, monkeypatch):
    from pidcore import defaults

    monkeypatch.setattr(defaults, "APP_MAX_UPLOAD_MB", 1)
    small = mass_damper_csv()  # about 0.5 MB
    large = mass_damper_csv(duration_s=4.0)  # about 2 MB
    assert len(small) < 2**20 < len(large)
    at = _upload(_app(), [("large.csv", large), ("small_fill50.csv", small)])
    assert any("Upload limit: 1 MB per file" in c.value for c in at.caption)
    errors = [e.value for e in at.error]
    assert len(errors) == 1 and "large.csv" in errors[0] and "limit of 1 MB" in errors[0]
    assert _table(at, "velocity channel")["file"].tolist() == ["small_fill50.csv"]


def test_dem_cancel_keeps_finished_cases_and_drops_the_rest(store_file, monkeypatch):
    import streamlit as st

    from pidcore.store import Store

    real = app_support.run_dem_case
    finished = []

    def run_then_press_cancel(path, case, config):
        key = real(path, case, config)
        finished.append(key)
        # The user presses Cancel while this case runs: Streamlit runs the button's callback
        # at the start of the rerun that follows; here it is set directly.
        st.session_state["dem_cancel_requested"] = True
        return key

    monkeypatch.setattr(app_support, "run_dem_case", run_then_press_cancel)
    at = _app()
    at.multiselect(key="dem_freqs").set_value([500.0])
    at.multiselect(key="dem_accs").set_value([5.0])
    at.multiselect(key="dem_fills").set_value([25.0, 50.0, 75.0])
    at.number_input(key="dem_cells").set_value(1)
    at.number_input(key="dem_steady").set_value(4)
    at.run()
    at.button(key="dem_run").click()
    at.run(timeout=RUN_TIMEOUT_S)
    assert not at.exception, at.exception
    assert len(finished) == 1
    assert any("cancelled: 2 case(s) not run; 1 finished case(s) are saved" in w.value
               for w in at.warning)
    assert Store(store_file).list_dem_runs()["case_key"].tolist() == finished
    assert at.button(key="dem_cancel").disabled  # nothing left to cancel


def test_reference_dem_store_is_compared_but_never_written(store_file, tmp_path, monkeypatch):
    from pidcore.store import Store

    ref = tmp_path / "reference.h5"
    Store(ref).add_dem_run("ref_run", {"frequency_hz": 100.0, "acceleration_g": 5.0,
                                       "fill_percent": 50.0, "material": "acrylic",
                                       "direction": "z", "sdc": 0.25, "sdc_stderr": 0.02})
    ref_bytes = ref.read_bytes()
    monkeypatch.setenv(app_support.DEM_STORE_ENV_VAR, str(ref))
    at = _upload(_app(), [("coupon_fill50.csv", mass_damper_csv())])
    assert any(str(ref) in m.value for m in at.sidebar.markdown)
    assert _metric(at, "SDC our DEM ± stderr [-]") == ["0.2500 ± 0.0200"]
    at.button(key="save").click()
    at.run()
    assert len(Store(store_file).list_analyses()) == 1
    assert ref.read_bytes() == ref_bytes


#: The bundled samples (``pidcore samples make``); PIDCORE_SAMPLES_DIR points elsewhere.
SAMPLES = Path(os.environ.get("PIDCORE_SAMPLES_DIR", REPO / "data_samples"))


@pytest.mark.slow
def test_bundled_samples_switch_load_cases_from_the_cache(store_file, monkeypatch,
                                                          analysis_calls):
    calls = analysis_calls
    from pidcore.measure import AnalysisOptions, analyze_file

    exports = sorted(p for p in (SAMPLES / "exports").glob("*") if p.is_file())
    dem_store = SAMPLES / "dem_table3.h5"
    if not exports or not dem_store.is_file():
        pytest.skip(f"no bundled samples in {SAMPLES} (pidcore samples make)")
    from pidcore.samples import EXPORT_VELOCITY_DELAY_S

    monkeypatch.setenv(app_support.DEM_STORE_ENV_VAR, str(dem_store))
    at = _app()
    at.number_input(key="delay_us").set_value(EXPORT_VELOCITY_DELAY_S * 1e6)
    at.run()
    at = _upload(at, [(p.name, p.read_bytes()) for p in exports])
    assert not at.error, [e.value for e in at.error]
    options = AnalysisOptions(velocity_delay_s=EXPORT_VELOCITY_DELAY_S)
    want = {p.name: analyze_file(p, options).analysis.sdc for p in exports}
    table = _table(at, "velocity channel")
    assert dict(zip(table["file"], table["SDC [-]"], strict=True)) == pytest.approx(want,
                                                                                   rel=1e-12)
    n_cases = len(at.selectbox(key="compare_case").options)
    assert n_cases == len(exports)  # one load case per sample export
    analysed = len(calls)
    timings = []
    for _ in range(2):
        for choice in range(n_cases):
            at.selectbox(key="compare_case").set_value(choice)
            start = time.perf_counter()
            at.run()
            timings.append(time.perf_counter() - start)
            assert not at.exception
            # Every sample lies on the DEM grid of the bundled store, whose runs know m_c.
            assert "DEM alignment: grid" in " ".join(c.value for c in at.caption)
            assert "±" in _metric(at, "SDC measured, E of Eq. 10 [-]")[0]
    assert len(calls) == analysed  # switching never re-analyses
    ARTIFACTS.mkdir(exist_ok=True)
    (ARTIFACTS / "app_switch_timing_samples.json").write_text(json.dumps(
        {"load_case_switch_s": timings, "cases": n_cases,
         "note": "AppTest whole-page run after choosing another load case with the bundled "
                 "samples uploaded (the Compare tab warms every case's comparison after the "
                 "upload, so every switch is a cache hit)"},
        indent=1))


def test_uploaded_sidecar_states_the_load_case(store_file):
    at = _upload(_app(), [("loadcases.csv", b"file,fill_percent,material\nrun7.csv,75,aluminium\n"),
                          ("run7.csv", mass_damper_csv())])
    assert any("loadcases.csv: load cases of 1 file(s) stated" in i.value for i in at.info)
    table = _table(at, "velocity channel")
    assert table["file"].tolist() == ["run7.csv"]  # the sidecar is not a measurement
    assert table["material"].tolist() == ["aluminium"]
    assert table["load case"].iloc[0].endswith("75 %")
