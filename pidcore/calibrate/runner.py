"""DEM runs for calibration: one callable (parameter values, load case, cells, seed) -> run,
cached in the HDF5 store so that a calibration computes every design point once.

The runner is the only place that knows how a named DEM parameter reaches the simulation.
Today (before the specimen file) the contact law is built inside
:func:`pidcore.dem.simulate.simulate_load_case`; restitution reaches it through
``DemConfig.alpha_*`` (Eq. 3) and the sliding friction through a law factory swapped in for
the duration of one run (:func:`_law_overrides`). Every run is stored with the standard DEM
entry layout (so ``pidcore report`` and the app can read it) under a key holding the load
case, the numerical settings and the parameter values.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import os
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass

from ..dem.contact import damping_constant_from_restitution
from ..dem.persist import dem_run_entry, run_key
from ..dem.simulate import DemConfig, LoadCase, simulate_load_case
from ..errors import ParameterError

#: DEM parameters the runner can set, and the ContactLaw/DemConfig field each one sets.
DEM_PARAMETERS: dict[str, str] = {
    "friction_pp": "sliding friction particle-particle [-]",
    "friction_pw": "sliding friction particle-wall [-]",
    "friction": "sliding friction of both pairs [-]",
    "restitution_pp": "normal restitution particle-particle [-]",
    "restitution_pw": "normal restitution particle-wall [-]",
    "restitution": "normal restitution of both pairs [-]",
}


@dataclass(frozen=True)
class RunRequest:
    """One DEM run of a calibration design: load case, DEM parameter values, settings."""

    case: LoadCase
    values: tuple[tuple[str, float], ...]
    config: DemConfig

    def key(self) -> str:
        """Store key: the standard DEM run key plus a hash of the parameter values."""
        base = run_key(self.case, self.config)
        if not self.values:
            return base
        text = json.dumps([[k, float(v)] for k, v in self.values])
        return f"{base}_cal{hashlib.sha256(text.encode()).hexdigest()[:10]}"


def _split_values(values: Mapping[str, float]) -> tuple[dict, dict]:
    """(ContactLaw field overrides, DemConfig overrides) for named DEM parameter values."""
    law: dict[str, float] = {}
    config: dict[str, float] = {}
    for name, value in values.items():
        if name not in DEM_PARAMETERS:
            raise ParameterError(f"DEM parameter {name!r}: expected one of "
                                 f"{sorted(DEM_PARAMETERS)}")
        pairs = ("pp", "pw") if name in ("friction", "restitution") else (name[-2:],)
        base = name.split("_")[0]
        for pair in pairs:
            if base == "friction":
                law[f"friction_{pair}"] = float(value)
            else:
                config[f"alpha_{pair}"] = damping_constant_from_restitution(float(value))
    return law, config


@contextlib.contextmanager
def _law_overrides(fields: Mapping[str, float]) -> Iterator[None]:
    """Build every ContactLaw of the DEM with ``fields`` replaced, for one run (this process)."""
    from ..dem import simulate

    if not fields:
        yield
        return
    original = simulate.ContactLaw

    class _Overridden:
        @staticmethod
        def for_material(*args, **kwargs):
            return dataclasses.replace(original.for_material(*args, **kwargs), **fields)

    simulate.ContactLaw = _Overridden
    try:
        yield
    finally:
        simulate.ContactLaw = original


def simulate_request(request: RunRequest):
    """Run one request (in this process); returns the DemResult."""
    law_fields, config_fields = _split_values(dict(request.values))
    config = dataclasses.replace(request.config, **config_fields) if config_fields \
        else request.config
    with _law_overrides(law_fields):
        return simulate_load_case(request.case, config)


def _run_entry(request: RunRequest) -> tuple[str, dict]:
    result = simulate_request(request)
    entry = dem_run_entry(result)
    entry["parameters"] = dict(entry["parameters"])
    for name, value in request.values:
        entry["parameters"][f"calibrate_{name}"] = float(value)
    return request.key(), entry


def _single_thread_worker() -> None:
    # Parallel over runs; numba threads inside each would oversubscribe the cores.
    import numba

    numba.set_num_threads(1)


def run_requests(requests: Sequence[RunRequest], *, store_path: str | os.PathLike,
                 workers: int = 2, progress: bool = True,
                 on_done: Callable[[str], None] | None = None) -> dict[str, float]:
    """Run every request whose key is not yet in the store, saving each as it finishes.

    An interrupted call (Ctrl-C) keeps every finished run; a re-run skips them. Returns
    ``{"computed": n, "cached": n, "wall_s": s}``.
    """
    from ..store import Store

    start = time.perf_counter()
    store = Store(store_path)
    todo, seen = [], set()
    for request in requests:
        key = request.key()
        if key not in seen and not store.has_dem_run(key):
            todo.append(request)
        seen.add(key)
    cached = len(seen) - len(todo)
    bar = None
    if progress and todo:
        from tqdm import tqdm

        bar = tqdm(total=len(todo), unit="run", desc="DEM runs", dynamic_ncols=True)

    def finish(key: str, entry: dict) -> None:
        store.add_dem_run(key, **entry, replace=True)
        if bar is not None:
            bar.update(1)
        if on_done is not None:
            on_done(key)

    try:
        if workers <= 1 or len(todo) <= 1:
            for request in todo:
                finish(*_run_entry(request))
        elif todo:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor, as_completed

            # spawn: forking after numba started its threads is unsafe (see dem.sweep)
            pool = ProcessPoolExecutor(max_workers=min(workers, len(todo)),
                                       mp_context=multiprocessing.get_context("spawn"),
                                       initializer=_single_thread_worker)
            try:
                futures = [pool.submit(_run_entry, request) for request in todo]
                for future in as_completed(futures):
                    finish(*future.result())
            except BaseException:
                pool.shutdown(wait=False, cancel_futures=True)
                raise
            pool.shutdown()
    finally:
        if bar is not None:
            bar.close()
    return {"computed": len(todo), "cached": cached, "wall_s": time.perf_counter() - start}
