"""``pidcore app``: start the Streamlit app on localhost with the default store."""

from __future__ import annotations

import argparse
import importlib.util
import os
import shlex
import signal
import subprocess
import sys
from pathlib import Path

from .. import defaults
from ..errors import ParameterError
from ._options import add_store_option, command_line


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "app",
        help="start the web app (Streamlit) on localhost",
        description="Start the pidcore app (upload & analyse, compare with DEM and the paper, "
                    "run DEM cases, download reports) on http://localhost:PORT. It reads and "
                    "writes the store given by --store; no other server is involved. Needs "
                    "the 'app' extra: pip install 'pidcore[app]'.",
    )
    p.add_argument("--port", type=int, default=defaults.APP_PORT,
                   help=f"TCP port on localhost (default {defaults.APP_PORT})")
    add_store_option(p, help=f"HDF5 store the app uses (default ./{defaults.STORE_PATH})")
    add_store_option(p, flag="--dem-store", default=None,
                     help="read-only store of reference DEM runs shown next to the store's own "
                          "(default: data_samples/dem_table3.h5 if it exists here)")
    p.add_argument("--print-command", action="store_true",
                   help="print the streamlit command line instead of running it, with the "
                        "environment variables that name --store and --dem-store to it")
    p.set_defaults(func=run)


def streamlit_command(port: int, *, python: str | None = None) -> list[str]:
    """The command line that serves the packaged app on ``localhost:port``, headless.

    The entry script is located through the installed package
    (:data:`pidcore.app.ENTRY_SCRIPT`), so it works for editable and regular installs alike.
    """
    from ..app import ENTRY_SCRIPT

    if not 1 <= int(port) <= 65535:
        raise ParameterError(f"--port {port}: expected a TCP port number 1..65535")
    return [
        python or sys.executable, "-m", "streamlit", "run", str(ENTRY_SCRIPT),
        "--server.address", "localhost",
        "--server.port", str(int(port)),
        "--server.headless", "true",
        "--server.maxUploadSize", str(defaults.APP_MAX_UPLOAD_MB),
        "--browser.gatherUsageStats", "false",
        "--client.toolbarMode", "minimal",
        "--global.developmentMode", "false",
        # Streamlit runs a full garbage collection after every script run by default: ~0.1 s
        # per click with numpy/pandas/numba loaded, for memory that Python's own collector
        # frees anyway (the served browser tests: 8.5 -> 6.2 CPU-s on the server)
        "--runner.postScriptGC", "false",
    ]


def app_environment(store: Path, dem_store: Path | None = None,
                    environ: dict[str, str] | None = None) -> dict[str, str]:
    """Environment of the app process: store paths (absolute) and usage statistics off."""
    from ..app.stores import DEM_STORE_ENV_VAR, STORE_ENV_VAR

    env = dict(os.environ if environ is None else environ)
    env[STORE_ENV_VAR] = str(Path(store).expanduser().resolve())
    if dem_store is not None:
        if not Path(dem_store).is_file():
            raise ParameterError(f"--dem-store {dem_store}: no such file")
        env[DEM_STORE_ENV_VAR] = str(Path(dem_store).expanduser().resolve())
    env["STREAMLIT_BROWSER_GATHER_USAGE_STATS"] = "false"
    return env


def printed_command(command: list[str], env: dict[str, str]) -> str:
    """``command`` as one shell line that serves what ``pidcore app`` would: the app reads
    its stores from the environment, so the line sets those variables first (printed without
    them it served ./pid_store.h5 whatever --store said)."""
    from ..app.stores import DEM_STORE_ENV_VAR, STORE_ENV_VAR

    assignments = [f"{name}={shlex.quote(env[name])}"
                   for name in (STORE_ENV_VAR, DEM_STORE_ENV_VAR) if name in env]
    return " ".join([*assignments, command_line(*command)])


def _dem_store(given: Path | None) -> Path | None:
    """``--dem-store``, else the bundled one found here, named to the app absolutely: the app
    looked for it relative to its own working folder, so a printed line run elsewhere served
    no reference runs."""
    from ..app.stores import BUNDLED_DEM_STORE, DEM_STORE_ENV_VAR, path_from_env_or_bundled

    if given is not None or os.environ.get(DEM_STORE_ENV_VAR, "").strip():
        return given  # one the user named (the environment's is passed on as it is)
    return path_from_env_or_bundled(DEM_STORE_ENV_VAR, BUNDLED_DEM_STORE, environ={})


def run(args: argparse.Namespace) -> int:
    command = streamlit_command(args.port)
    # the environment first: --print-command refuses a missing --dem-store as a start does
    env = app_environment(args.store, _dem_store(args.dem_store))
    if args.print_command:
        print(printed_command(command, env))
        return 0
    if importlib.util.find_spec("streamlit") is None:
        raise ParameterError("the app needs Streamlit, which is not installed; "
                             "install it with: pip install 'pidcore[app]'")
    print(f"pidcore app: http://localhost:{args.port}  (store {env['PIDCORE_STORE']}); "
          "Ctrl-C stops it", file=sys.stderr)
    server = subprocess.Popen(command, env=env)
    # SIGTERM (a service manager, a test) must stop the server too: turn it into SystemExit
    # so that the cleanup below runs instead of the interpreter dying on the spot.
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    try:
        return server.wait()
    finally:
        if server.poll() is None:  # interrupted: never leave the server running behind us
            server.terminate()
            try:
                server.wait(timeout=10)
            except subprocess.TimeoutExpired:
                server.kill()
        signal.signal(signal.SIGTERM, previous)
