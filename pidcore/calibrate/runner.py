"""DEM runs for calibration: one callable (parameter values, load case, cells, seed) -> run,
cached in the HDF5 store so that a calibration computes every design point once.

The runner is the only place that knows how a named DEM parameter reaches the simulation: it
becomes a specimen (:meth:`pidcore.specimen.Specimen.with_values` by dotted path), and the run
goes through the DEM's run cache key (:func:`pidcore.dem.persist.run_key`: load case,
configuration, specimen hash, code version) and its one save path, so a run stored by
``pidcore dem run``/``sweep`` or the app is reused here and vice versa.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..dem.persist import dem_run_entry, run_key, save_dem_entry, stored_keys
from ..dem.simulate import DemConfig, LoadCase, simulate_load_case
from ..errors import ParameterError
from ..interrupt import raise_if_stopped, untouched
from ..specimen import Specimen
from .parameters import friction_paths


def specimen_with(specimen: Specimen, values: Mapping[str, float]) -> Specimen:
    """``specimen`` with named DEM parameter values set (aliases or dotted paths).

    ``friction`` sets the sliding friction and the static friction to the same value (one
    Coulomb coefficient, today's model); a ``static_friction`` given as well is then the stick
    limit, taken as the sliding friction where below it (static >= sliding always); so is a
    static friction by dotted path (``pairs.particle_wall.static_friction``, the same
    parameter as ``static_friction_pw``: :func:`pidcore.calibrate.parameters.friction_paths`).
    """
    changes: dict[str, float] = {}
    # sliding friction first: a static friction set in the same call is checked against it
    order = sorted(values, key=lambda n: 0 if (friction_paths(n) or ("",))[0]
                   == "sliding_friction" else 1)
    for name in order:
        value = float(values[name])
        # a static friction by dotted path follows the alias's rule (friction_paths)
        alias = friction_paths(name)
        if alias is None or name.endswith(".sliding_friction"):
            changes[name] = value  # a dotted sliding friction sets that field alone
            continue
        field, pairs = alias
        for pair in pairs:
            path = f"pairs.{pair}."
            if field == "sliding_friction":
                changes[path + "sliding_friction"] = value
                changes[path + "static_friction"] = value
            elif field == "static_friction":
                sliding = changes.get(path + "sliding_friction",
                                      getattr(specimen.pairs, pair).sliding_friction)
                changes[path + field] = max(value, sliding)
            else:
                changes[path + field] = value
    if not changes:
        return specimen
    return specimen.with_values(changes)


@dataclass(frozen=True)
class RunRequest:
    """One DEM run of a calibration design: load case, specimen (with the design's values).

    ``variant``: where ``specimen`` is the calibration's variant of the file it started from
    (another hash), which file and design values (:func:`variant_provenance`), stored with the
    run so that pages name it as such, not as another file of that name; None: the file."""

    case: LoadCase
    specimen: Specimen
    config: DemConfig
    variant: Mapping[str, object] | None = field(default=None, compare=False)

    def key(self) -> str:
        """The DEM run cache key (:func:`pidcore.dem.persist.run_key`)."""
        return run_key(self.case, self.config, self.specimen)


def simulate_request(request: RunRequest):
    """Run one request (in this process); returns the DemResult."""
    return simulate_load_case(request.case, request.config, specimen=request.specimen)


def _run_entry(request: RunRequest) -> tuple[str, dict]:
    return request.key(), dem_run_entry(simulate_request(request),
                                        calibration_variant=request.variant)


def variant_provenance(start: Specimen, variant: Specimen,
                       values: Mapping[str, float]) -> dict[str, object] | None:
    """What a run of ``variant`` (``start`` with the design's ``values``, by the names the fit
    takes) stores of its origin (:data:`pidcore.compare.align.CALIBRATION_VARIANT_FIELD`);
    None where the design point is ``start`` itself (same hash: its runs are the file's)."""
    if variant.hash == start.hash:
        return None
    return {"of_name": start.name, "of_sha256": start.hash,
            # pairs, in the order of the fit: a store's JSON sorts an object's keys
            "values": [[name, value] for name, value in _values_as_set(variant, values)]}


def _values_as_set(variant: Specimen, values: Mapping[str, float]) -> list[tuple[str, float]]:
    """The design's ``values`` as ``variant`` holds them: a static friction that
    :func:`specimen_with` raised to a pair's sliding friction is given per pair by its dotted
    path (``static_friction 0.12`` of the paper's coupon is 0.12 between particles and 0.14,
    the sliding friction, at the wall: a label of 0.12 misstated the run)."""
    out: list[tuple[str, float]] = []
    for name, value in values.items():
        alias = friction_paths(name)
        if alias is None or alias[0] != "static_friction":
            out.append((name, float(value)))
            continue
        held = {pair: float(getattr(variant.pairs, pair).static_friction) for pair in alias[1]}
        if all(v == float(value) for v in held.values()):
            out.append((name, float(value)))
        else:
            out.extend((f"pairs.{pair}.static_friction", v) for pair, v in held.items())
    return out


def is_design_variant(stated: Sequence[tuple[str, float]], names: Sequence[str],
                      points: Sequence[Sequence[float]], variant: Specimen | None = None
                      ) -> bool:
    """Whether a run of a calibration's variant that states ``stated`` (the ``values`` of
    :func:`variant_provenance`) is a variant of one of the design ``points`` of the fitted DEM
    parameters ``names`` (a calibration.json's ``design``): a point's values as
    :func:`variant_provenance` states them. ``variant``: the run's specimen, without which a
    static friction raised to a pair's sliding friction (stated per pair, the value asked for
    lost) is not recognised: with it, such a point is one that states the same and, set on
    the variant, changes nothing.

    Both are the design's floats through JSON, compared exactly: any other variant of the same
    file (another calibration's design) is not this calibration's run."""
    if not names:
        return False
    wanted = [(str(name), float(value)) for name, value in stated]
    for values in _design_values(names, points):
        if list(values.items()) == wanted:
            return True
        # stated per pair as run: the same statement and the point setting nothing anew
        if variant is not None and _values_as_set(variant, values) == wanted \
                and _leaves_unchanged(variant, values):
            return True
    return False


def is_design_start(start: Specimen, names: Sequence[str],
                    points: Sequence[Sequence[float]]) -> bool:
    """Whether one of the design ``points`` of the fitted DEM parameters ``names`` (a
    calibration.json's ``design``) is ``start`` itself: set on it (:func:`specimen_with`), a
    point that changes nothing, whose runs are the file's own (:func:`variant_provenance`
    None). A fit of no DEM parameter has one such point (no values); a design whose points
    all vary the file runs none of it, and a run of the file is no run of that design.

    The design's floats through JSON are the ones the runner set, so a point rebuilds its
    specimen exactly."""
    return any(_leaves_unchanged(start, values) for values in _design_values(names, points))


def _design_values(names: Sequence[str],
                   points: Sequence[Sequence[float]]) -> list[dict[str, float]]:
    """The values each design point of ``names`` sets, by name (a point of another length,
    which no design of these names made, left out)."""
    return [{str(n): float(v) for n, v in zip(names, point, strict=True)}
            for point in points if len(point) == len(names)]


def _leaves_unchanged(specimen: Specimen, values: dict[str, float]) -> bool:
    """Whether setting ``values`` on ``specimen`` (:func:`specimen_with`) gives it back."""
    try:
        return specimen_with(specimen, values).hash == specimen.hash
    except ParameterError:
        return False  # a point outside the specimen's domain did not make it


def run_requests(requests: Sequence[RunRequest], *, store_path: str | os.PathLike,
                 workers: int = 2, progress: bool = True,
                 on_done: Callable[[str], None] | None = None,
                 stop: threading.Event | None = None) -> dict[str, float]:
    """Run every request whose key is not yet in the store, saving each as it finishes.

    An interrupted call (Ctrl-C) keeps every finished run; a re-run skips them. Returns
    ``{"computed": n, "cached": n, "wall_s": s}``.

    ``stop``: a caller in a background thread (the app's calibration) sets it to stop the
    runs within a fraction of a second (:func:`pidcore.dem.sweep.run_pooled`): the running
    ones are discarded, the saved ones kept, and :class:`~pidcore.interrupt.StopRequested`
    raised. Every run then goes to a worker process, even a single one: a run in this
    process could not be stopped before its end (a minute or more).
    """
    from ..store import Store

    start = time.perf_counter()
    store = Store(store_path)
    exists = store.path.exists()
    todo, seen = [], set()
    for request in requests:
        # a key is a hash of the run's inputs, and the store is asked for each: a stop set
        # meanwhile is not kept waiting for the whole list
        raise_if_stopped(stop, _STOPPED)
        key = request.key()
        if key not in seen and not (exists and store.has_dem_run(key)):
            todo.append(request)
        seen.add(key)
    cached = len(seen) - len(todo)
    if todo:
        store.check_writable()  # before the DEM runs, not at the first commit
    bar = None
    if progress and todo:
        from tqdm import tqdm

        bar = tqdm(total=len(todo), unit="run", desc="DEM runs", dynamic_ncols=True)

    def finish(key: str, entry: dict) -> None:
        save_dem_entry(store, key, entry)
        if bar is not None:
            bar.update(1)
        if on_done is not None:
            on_done(key)

    try:
        if stop is None and (workers <= 1 or len(todo) <= 1):
            for request in todo:
                finish(*_run_entry(request))
        elif todo:
            from ..dem.sweep import run_pooled

            # on Ctrl-C or a stop the workers are stopped and waited for; finished runs are
            # saved
            run_pooled(_run_entry, [(request,) for request in todo], workers=max(workers, 1),
                       finish=lambda result: finish(*result), stop=stop)
    finally:
        if bar is not None:
            bar.close()
    return {"computed": len(todo), "cached": cached, "wall_s": time.perf_counter() - start}


#: What a stop before any DEM run says (:func:`pidcore.interrupt.raise_if_stopped`).
_STOPPED = "the DEM runs were stopped before any started; the runs stored before are kept"


@dataclass
class RunTally:
    """The DEM runs a calibration asks for and those its store held before: after Ctrl-C,
    :meth:`interrupted` says how many finished runs are kept, and where.

    Pass :meth:`design` as ``calibrate(on_design=...)``.
    """

    store_path: Path
    keys: list[str] = field(default_factory=list)
    before: set[str] = field(default_factory=set)
    known: bool = False

    def design(self, keys: Sequence[str]) -> None:
        """Called with the run keys of the design before any run starts."""
        self.keys = list(dict.fromkeys(keys))
        self.before = stored_keys(self.store_path, self.keys)
        self.known = True

    def specimens(self) -> str:
        """The specimens of the design's runs the store holds, as every listing of runs names
        them (:func:`pidcore.compare.specimens.runs_per_specimen_text`: a variant of the file
        calibrated as such), e.g. ``"2 of mycoupon [65a6d7]: calibration variant of mycoupon
        [072027] (static_friction 0.325, rolling_friction 0.025), ..."``; "" where none."""
        from ..compare.specimens import runs_per_specimen_text

        runs = self.stored_runs()
        return runs_per_specimen_text(runs) if runs is not None else ""

    def stored_runs(self):
        """The store's listing (:meth:`pidcore.store.Store.list_dem_runs`) of the design's
        runs it holds; None where it holds none."""
        from ..store import Store

        if not self.keys or not Path(self.store_path).exists():
            return None
        runs = Store(self.store_path).list_dem_runs()
        runs = runs[runs["case_key"].isin(self.keys)]
        return runs if not runs.empty else None

    def interrupted(self) -> str:
        """What an interrupted calibration kept, e.g. ``"3 DEM run(s) finished before the
        interrupt are saved in dem.h5 (10 of the calibration's 24 stored now); re-run the same
        command to resume: stored runs are reused"``."""
        if not self.known:
            return f"no DEM run was started; {untouched(self.store_path)}"
        now = stored_keys(self.store_path, self.keys)
        if not now and not Path(self.store_path).exists():
            return f"no DEM run finished in this call; {untouched(self.store_path)}"
        saved = len(now - self.before)
        held = f"{len(now)} of the calibration's {len(self.keys)} stored now"
        if saved:
            what = (f"{saved} DEM run(s) finished before the interrupt are saved in "
                    f"{self.store_path} ({held})")
        else:
            what = f"no DEM run finished in this call; {self.store_path} holds {held}"
        if len(now) == len(self.keys):
            return f"{what}; a re-run of the same command computes no DEM run again"
        return f"{what}; re-run the same command to resume: stored runs are reused, the " \
               f"other {len(self.keys) - len(now)} computed"
