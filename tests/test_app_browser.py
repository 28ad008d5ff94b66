"""End to end: the app served by Streamlit, driven in Debian's chromium through Playwright.

Skipped (with the reason) only when chromium or Playwright is missing; CI installs both. No
browser is downloaded: Playwright drives the system chromium through ``executable_path``.
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest
from _app_samples import mass_damper_csv

from pidcore import app_support

pytestmark = [pytest.mark.browser, pytest.mark.slow]

REPO = Path(__file__).resolve().parents[1]
SHIM = REPO / "app" / "pidcore_app.py"
ARTIFACTS = REPO / "test-artifacts"
CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--no-first-run"]
#: Seconds to wait for the server to answer and for results to appear (cold imports included).
START_TIMEOUT_S = 45
RESULT_TIMEOUT_MS = 30_000


def _coloured_pixels(png: bytes) -> int:
    """Pixels whose colour channels differ clearly (not white, grey or black)."""
    import io

    from matplotlib.image import imread

    rgb = imread(io.BytesIO(png), format="png")[..., :3]
    return int(((rgb.max(axis=-1) - rgb.min(axis=-1)) > 0.25).sum())


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


def _sample(tmp_path: Path) -> Path:
    """A bundled sample export (CSV, else UFF) if there is one, else a synthetic CSV."""
    samples = Path(os.environ.get("PIDCORE_SAMPLES_DIR", REPO / "data_samples"))
    for pattern in ("exports/*.csv", "exports/*.uff", "**/*.uff"):
        found = sorted(p for p in samples.glob(pattern) if p.is_file())
        if found:
            return found[0]
    path = tmp_path / "synthetic_fill50_acrylic.csv"
    path.write_bytes(mass_damper_csv(frequency_hz=100.0, acceleration_g=5.0))
    return path


@pytest.fixture
def sample(tmp_path):
    return _sample(tmp_path)


@pytest.fixture
def store_with_dem_run(tmp_path, sample):
    """A store holding one short DEM run at the sample's load case (for the loop overlay)."""
    from pidcore.compare import parse_file_name
    from pidcore.dem import DemConfig
    from pidcore.dem import LoadCase as DemLoadCase
    from pidcore.measure import AnalysisOptions, analyze_file

    analysis = analyze_file(sample, AnalysisOptions()).analysis
    stated = parse_file_name(sample.name)
    case = DemLoadCase(analysis.frequency_hz, analysis.acceleration_g,
                       stated.get("fill_percent", app_support.DEFAULT_FILL_PERCENT),
                       stated.get("material", "acrylic"), stated.get("direction", "z"))
    path = tmp_path / "e2e_store.h5"
    app_support.run_dem_case(path, case, DemConfig(cells=2, steady_cycles=10,
                                                   max_transient_cycles=4))
    return path


@pytest.fixture
def app_url(tmp_path, store_with_dem_run):
    port = _free_port()
    env = {**os.environ, app_support.STORE_ENV_VAR: str(store_with_dem_run),
           "STREAMLIT_BROWSER_GATHER_USAGE_STATS": "false"}
    log = (tmp_path / "streamlit.log").open("wb")
    proc = subprocess.Popen(
        [sys.executable, "-m", "streamlit", "run", str(SHIM), "--server.headless", "true",
         "--server.address", "localhost", "--server.port", str(port),
         "--browser.gatherUsageStats", "false", "--server.fileWatcherType", "none"],
        cwd=tmp_path, env=env, stdout=log, stderr=subprocess.STDOUT)
    url = f"http://localhost:{port}"
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while True:
            try:
                with urllib.request.urlopen(f"{url}/_stcore/health", timeout=2) as r:
                    if r.read().strip() == b"ok":
                        break
            except OSError:
                pass
            if proc.poll() is not None or time.monotonic() > deadline:
                log.close()
                pytest.fail("streamlit did not start: "
                            + (tmp_path / "streamlit.log").read_text()[-2000:])
            time.sleep(0.2)
        yield url
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
        log.close()


def test_upload_shows_sdc_and_the_loop_overlay_renders(app_url, sample, tmp_path):
    if not CHROMIUM.exists():
        pytest.skip(f"{CHROMIUM} not installed (apt-get install chromium)")
    sync_api = pytest.importorskip("playwright.sync_api",
                                   reason="playwright for Python not installed")
    from pidcore.measure import AnalysisOptions, analyze_file

    expected = analyze_file(sample, AnalysisOptions()).analysis
    expected_text = app_support.format_sdc(expected.sdc, expected.sdc_stderr)
    ARTIFACTS.mkdir(exist_ok=True)
    with sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1500, "height": 1600})
            page.goto(app_url)
            page.locator("input[type=file]").first.wait_for(state="attached",
                                                            timeout=RESULT_TIMEOUT_MS)
            bad = tmp_path / "corrupt_export.uff"
            bad.write_bytes(b"    -1\n    58\nnot a dataset\n")
            page.locator("input[type=file]").first.set_input_files([str(sample), str(bad)])
            metric = page.locator('[data-testid="stMetric"]').filter(has_text="SDC ± stderr")
            metric.first.wait_for(timeout=RESULT_TIMEOUT_MS)
            # The browser shows the library's SDC for the same file ...
            assert expected_text in metric.first.inner_text()
            # ... and the bad file's error, without stopping the session.
            error = page.locator('[data-testid="stAlertContentError"]').filter(
                has_text="corrupt_export.uff")
            error.first.wait_for(timeout=RESULT_TIMEOUT_MS)
            page.get_by_role("button", name="Save 1 record(s) to the store").wait_for(
                timeout=RESULT_TIMEOUT_MS)
            page.screenshot(path=str(ARTIFACTS / "app_e2e_analyse.png"), full_page=True)

            page.get_by_role("tab", name="Compare").click()
            charts = page.locator('[data-testid="stVegaLiteChart"]')
            loop = charts.filter(has_text="force-displacement loop")
            # Vega draws into a canvas (or svg); its presence means the chart rendered.
            loop.first.locator("canvas, svg").first.wait_for(timeout=RESULT_TIMEOUT_MS)
            assert charts.count() == 3
            page.wait_for_timeout(500)  # let Vega finish drawing
            # Data were drawn, not just axes: the loop line is coloured, axes and text are grey.
            assert _coloured_pixels(loop.first.screenshot()) > 300
            sdc = charts.filter(has_text="SDC against fill")
            assert _coloured_pixels(sdc.first.screenshot()) > 300
            # Both loops are drawn: the measurement's and our DEM run's at this load case.
            energies = page.get_by_text("energy per cycle (loop area)")
            assert "measured" in energies.inner_text() and "our DEM" in energies.inner_text()
            dem_metric = page.locator('[data-testid="stMetric"]').filter(
                has_text="SDC our DEM ± stderr")
            assert "±" in dem_metric.first.inner_text()
            measured = page.locator('[data-testid="stMetric"]').filter(
                has_text="SDC measured ± stderr")
            assert expected_text in measured.first.inner_text()
            page.screenshot(path=str(ARTIFACTS / "app_e2e.png"), full_page=True)
            assert not page.locator('[data-testid="stException"]').count()
        finally:
            browser.close()
