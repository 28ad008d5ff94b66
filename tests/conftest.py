"""Fixtures shared by several test modules, and the Numba cache shared by pytest-xdist workers.

Numba kernels (``@njit(cache=True)``) compile in ~1 min from a cold cache. The cache lives in
``.numba_cache/`` of this checkout (``NUMBA_CACHE_DIR``, set here before anything imports
numba; an explicit ``NUMBA_CACHE_DIR`` wins). With ``-n N`` the controller process starts
``tests/_numba_warmup.py`` in the background in ``pytest_configure``, before pytest-xdist starts
its workers (``DSession.pytest_sessionstart``); the workers inherit the cache location and a
path that the warm-up writes when it is done. Workers run the tests of the DEM modules last
(:data:`DEM_KERNEL_TESTS`) and wait for the warm-up only where it is needed, so the kernel is
compiled once, while the other tests run, instead of once per worker: a worker about to
compile a ``pidcore.dem`` function waits for the warm-up first (and then loads it from the
cache), and a test marked ``dem_subprocess`` (it runs the kernel in a process of its own: app
jobs, process pools, a served app) waits before it starts. ``PIDCORE_NUMBA_WARMUP=0`` skips
all this.

Settings for ``-n 2`` on two cores: one DEM kernel thread per worker (see
:func:`_one_kernel_thread_per_worker`) and one BLAS thread per process (see
:data:`ONE_BLAS_THREAD`).
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("NUMBA_CACHE_DIR",
                      str(Path(__file__).resolve().parents[1] / ".numba_cache"))
#: One BLAS thread in the test processes and everything they start (workers, the warm-up,
#: CLI runs, servers): the xdist workers already keep the cores busy, and OpenBLAS's extra
#: threads spin-wait after every call (the harmonic fits' least squares, the calibration's
#: linear algebra), taking the core from the other worker: with them the suite needed ~17
#: more CPU-seconds (160 against 143, warm cache, 2 cores) for the same results. Read when
#: numpy loads its BLAS, hence set before anything imports numpy; an explicit value wins.
ONE_BLAS_THREAD = {"OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
for _name, _value in ONE_BLAS_THREAD.items():
    os.environ.setdefault(_name, _value)

import pytest  # noqa: E402

# pandas and pidcore are imported inside the fixtures: the xdist controller imports this file
# too and needs neither (~1 s of imports); NUMBA_CACHE_DIR must be set before numba is imported

#: Test modules that call the DEM kernel (directly, through the CLI, sweeps or the app): run
#: after the others, whose tests need no wait.
DEM_KERNEL_TESTS = re.compile(r"^test_(dem_|app_|samples|specimen|calibrat|readme)")
#: Environment variable naming the file the background warm-up writes when it is done.
WARMUP_DONE_ENV = "PIDCORE_NUMBA_WARMUP_DONE"
#: Longest wait for the warm-up before a worker compiles on its own, s.
WARMUP_TIMEOUT_S = 900.0

_WARMUP = pytest.StashKey[subprocess.Popen]()
_waited = False


def pytest_configure(config: pytest.Config) -> None:
    if hasattr(config, "workerinput"):
        _one_kernel_thread_per_worker()
        if WARMUP_DONE_ENV in os.environ:
            # The warm-up (one core, ~30 s) must not share a core with the workers: they run
            # out of tests that need no DEM kernel at about the time it ends, and each idle
            # second then is a core idle. Nice 5 leaves it a whole core, the workers the rest.
            os.nice(5)
    # Only the xdist controller starts the warm-up; a single process compiles on first use.
    if hasattr(config, "workerinput") or os.environ.get("PIDCORE_NUMBA_WARMUP") == "0":
        return
    if not getattr(config.option, "numprocesses", None):
        return
    done = Path(tempfile.mkdtemp(prefix="pidcore-numba-warmup-")) / "done"
    os.environ[WARMUP_DONE_ENV] = str(done)  # inherited by the workers started after this
    config.stash[_WARMUP] = subprocess.Popen(
        [sys.executable, str(Path(__file__).with_name("_numba_warmup.py")), str(done)],
        stdout=subprocess.DEVNULL)


def _one_kernel_thread_per_worker() -> None:
    """In a pytest-xdist worker, run the DEM kernel of in-process tests on one thread.

    ``-n N`` already keeps N cores busy; the kernel's threads (one per core, a new thread pool
    per kernel call in ``pidcore.dem.state``) would only compete with the other workers: ~10 %
    more CPU time for the same numbers (the results do not depend on the thread count,
    test_dem_simulate checks that). Subprocesses (app jobs, the CLI) keep their default.
    """
    import numba

    numba.set_num_threads(1)


def pytest_unconfigure(config: pytest.Config) -> None:
    process = config.stash.get(_WARMUP, None)
    if process is None:
        return
    if process.poll() is None:  # the session ended first (e.g. -x); nothing is half-cached:
        process.kill()           # numba writes each cache file whole
    process.wait()
    shutil.rmtree(Path(os.environ.pop(WARMUP_DONE_ENV)).parent, ignore_errors=True)


def pytest_terminal_summary(terminalreporter, config: pytest.Config) -> None:
    # A warm-up that fails (it did once, silently: a refused synthetic record stopped it
    # before the DEM kernel) costs a compile in every worker; say so rather than be slow.
    if config.stash.get(_WARMUP, None) is None:
        return
    done = Path(os.environ[WARMUP_DONE_ENV])
    status = done.read_text(encoding="utf-8") if done.exists() else "did not finish"
    if status != "ok":
        terminalreporter.write_line(f"numba warm-up {status}: each worker compiled on its own",
                                    yellow=True)


def pytest_report_header(config: pytest.Config) -> str:
    process = config.stash.get(_WARMUP, None)
    background = "" if process is None else \
        f", kernels compiled once in the background (pid {process.pid})"
    return f"numba cache: {os.environ['NUMBA_CACHE_DIR']}{background}"


def _calls_dem_kernel(item: pytest.Item) -> bool:
    return bool(DEM_KERNEL_TESTS.match(item.path.name))


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    # In xdist workers while the warm-up runs: DEM kernel tests last (a stable sort, the same
    # in every worker, so their collections still agree; modules stay contiguous).
    if WARMUP_DONE_ENV in os.environ and hasattr(config, "workerinput"):
        items.sort(key=_calls_dem_kernel)
        _wait_before_compiling_dem_functions()


def _wait_for_warmup() -> None:
    global _waited
    if _waited:
        return
    done = Path(os.environ[WARMUP_DONE_ENV])
    deadline = time.monotonic() + WARMUP_TIMEOUT_S
    while not done.exists() and time.monotonic() < deadline:
        time.sleep(0.2)
    _waited = True  # ready, failed (the test will say why) or timed out: compile here


def _wait_before_compiling_dem_functions() -> None:
    """Make this worker wait for the warm-up before Numba compiles (or looks up in the cache)
    a function of ``pidcore.dem`` for the first time; any other function compiles at once.

    Hooks ``numba``'s ``Dispatcher.compile`` (where a call with new argument types goes,
    before the disk cache is tried); where a Numba version lacks it, the worker compiles on its
    own as before the warm-up existed: slower, never wrong.
    """
    try:
        from numba.core.dispatcher import Dispatcher
    except ImportError:
        return
    compile_now = getattr(Dispatcher, "compile", None)
    if compile_now is None:
        return

    def compile_after_warmup(self, sig):
        if getattr(self.py_func, "__module__", "").startswith("pidcore.dem"):
            _wait_for_warmup()
        return compile_now(self, sig)

    Dispatcher.compile = compile_after_warmup


def pytest_runtest_setup(item: pytest.Item) -> None:
    if WARMUP_DONE_ENV in os.environ and item.get_closest_marker("dem_subprocess"):
        _wait_for_warmup()


@pytest.fixture(scope="session")
def paper_table():
    """The paper's Table 3 as bundled with pidcore (a pandas DataFrame)."""
    from pidcore.model import load_paper_table3

    return load_paper_table3()


@pytest.fixture(scope="session")
def _store_records_cache(tmp_path_factory):
    """Folder of the one store of every section's records the store tests copy (its tiny
    calibration takes ~30 s: made once per session)."""
    return tmp_path_factory.mktemp("store_records")


@pytest.fixture
def records_store_copy(_store_records_cache, tmp_path):
    """(path, keys by role) of a fresh copy of the store of ``tests/_store_records.py``."""
    from _store_records import records_store

    path = tmp_path / "s.h5"
    return path, records_store(_store_records_cache, path)


@pytest.fixture(scope="session")
def paper_model(paper_table):
    """The pchip SDC model over the paper's Table 3 DEM values (a pidcore.model.SdcModel)."""
    from pidcore.model import SdcModel

    return SdcModel.from_table(paper_table)


@pytest.fixture
def one_measured_case():
    """One DEM run and one measurement of the same load case (500 Hz, 5 g, 50 %) as the
    report table takes them: the measurement's Eq. 11 SDC (4.3) is ~3x its Eq. 10 SDC, the
    gap between the two SDCs that report tests must not mix up."""
    from types import SimpleNamespace

    import pandas as pd

    m_c, energy = 0.069, 1.25e-5
    dem = pd.DataFrame({"frequency_hz": [500.0], "acceleration_g": [5.0], "fill_percent": [50.0],
                        "material": ["acrylic"], "direction": ["z"], "sdc": [1.5],
                        "sdc_stderr": [0.03], "m_c_kg": [m_c]})
    measured = pd.DataFrame({"frequency_hz": [500.2], "acceleration_g": [4.98],
                             "fill_percent": [50.0], "sdc": [4.3], "sdc_stderr": [0.1],
                             "energy_per_cycle_j": [energy], "source": ["x.csv"]})
    return SimpleNamespace(dem=dem, measured=measured, vibrated_mass_kg=m_c,
                           energy_per_cycle_j=energy)


@pytest.fixture
def undrawn_report_figures(monkeypatch):
    """Report figures saved as a 1x1 PNG and a minimal SVG instead of being drawn.

    For report tests that check tables, text and which files exist, not pictures: drawing and
    saving the report's figures (PNG and SVG, tight bounding boxes) takes seconds per report.
    The figures are still built, named and listed; tests/test_report_render.py and
    test_report_end_to_end save them for real.
    """
    import io

    from matplotlib.image import imsave

    from pidcore.report import render

    buffer = io.BytesIO()
    imsave(buffer, [[0.0]], format="png")
    png_bytes = buffer.getvalue()

    def save_figure_files(fig, folder: Path, stem: str, **_) -> tuple[Path, Path]:
        folder.mkdir(parents=True, exist_ok=True)
        png, svg = folder / f"{stem}.png", folder / f"{stem}.svg"
        png.write_bytes(png_bytes)
        svg.write_text('<svg xmlns="http://www.w3.org/2000/svg"/>', encoding="utf-8")
        return png, svg

    monkeypatch.setattr(render, "save_figure_files", save_figure_files)


@pytest.fixture
def read_only(monkeypatch):
    """``read_only(path)``: make a store file read-only. As root (who may write it anyway) the
    store's permission check is answered from the mode bits, as the kernel answers every other
    user."""
    import stat

    import pidcore.store.store as store_module

    made: list[Path] = []
    real = os.access

    def access(target, mode, **kw):
        if Path(target) in made and mode & os.W_OK:
            return bool(Path(target).stat().st_mode & stat.S_IWUSR)
        return real(target, mode, **kw)

    def make(path: Path) -> None:
        path.chmod(0o444)
        made.append(Path(path))
        if os.geteuid() == 0:
            monkeypatch.setattr(store_module.os, "access", access)

    return make


@pytest.fixture(autouse=True)
def _signal_handlers_restored():
    """Each test leaves SIGINT, SIGTERM and SIGHUP as it found them: ``console_main`` ignores
    them once its command is over (as the ``pidcore`` process then ends), and run in-process
    by a test it left the worker ignoring them, so a later test's subprocess inherited
    SIGTERM ignored and (rightly) kept it so, and an interrupt of pytest itself went
    unheard."""
    import signal

    saved = {signum: signal.getsignal(signum)
             for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    yield
    for signum, handler in saved.items():
        if signal.getsignal(signum) is not handler and handler is not None:
            signal.signal(signum, handler)
