"""Calibration parameters: what can be fitted, its default value, bounds and prior.

Two kinds:

* ``"dem"``: changes the particle physics, so every value needs new DEM runs: named contact
  parameters (``friction``, ``static_friction``, ``rolling_friction``, ``restitution``, each
  for both pairs or suffixed ``_pp``/``_pw``) or any numeric specimen field by dotted path
  (``particles.radius_m``);
* ``"observation"``: enters only the observation model (:mod:`pidcore.calibrate.observation`),
  no DEM run: the fixture mass above the force gauge and the empty structure's loss factor.

The model-discrepancy scale ``model_discrepancy`` (relative standard deviation of the model
error) is always fitted unless fixed; it is a hyperparameter of the likelihood, reported
beside the others.

Priors: uniform between the bounds (default), or ``normal:MU:SD`` truncated to the bounds;
``model_discrepancy`` is log-uniform. Command-line spelling, e.g.
``--prior fixture_mass_kg=0:0.3`` or ``--prior friction_pw=normal:0.3:0.1:0.05:0.8``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ParameterError, as_given, real_number

if TYPE_CHECKING:  # pragma: no cover
    from ..specimen import Specimen

DISCREPANCY = "model_discrepancy"


@dataclass(frozen=True)
class ParameterSpec:
    """One fittable parameter: kind, uncalibrated value, bounds, prior (SI, unit in name)."""

    name: str
    kind: str  # "dem" | "observation" | "hyper"
    default: float
    low: float
    high: float
    description: str
    prior: str = "uniform"  # "uniform" | "normal" | "log-uniform"
    prior_mean: float = float("nan")
    prior_sd: float = float("nan")
    unit: str = "-"  # of the value, as calibration.json's "units" states it

    def check(self) -> None:
        """Refuse empty bounds and a prior that does not fit them (one-line
        :class:`~pidcore.errors.ParameterError` naming the parameter)."""
        if math.isnan(self.low) and math.isnan(self.high):
            # a field of value 0 has no default range (0.5x..1.5x its value): "bounds nan:nan
            # are empty" left the caller guessing what to give
            raise ParameterError(f"{self.name}: no default prior bounds (they are 0.5 .. 1.5 "
                                 f"x a positive value; this one is {as_given(self.default)}); "
                                 f"give priors={self.name}=LOW:HIGH")
        bounds = f"{self.name}: bounds {as_given(self.low)}:{as_given(self.high)}"
        if not (math.isfinite(self.low) and math.isfinite(self.high)):
            # 0:inf was said to be "empty"
            raise ParameterError(f"{bounds} are not finite (expected finite LOW < HIGH)")
        if not self.low < self.high:
            raise ParameterError(f"{bounds} are empty (expected LOW < HIGH)")
        if self.prior == "normal":
            if not self.prior_sd > 0:
                raise ParameterError(f"{self.name}: prior sd must be > 0, got "
                                     f"{as_given(self.prior_sd)}")
            if not self.low <= self.prior_mean <= self.high:
                raise ParameterError(
                    f"{self.name}: bounds {as_given(self.low)}:{as_given(self.high)} exclude "
                    f"the prior mean {as_given(self.prior_mean)}")
        if self.prior == "log-uniform" and self.low <= 0:
            raise ParameterError(f"{self.name}: a log-uniform prior needs bounds > 0")

    def log_prior(self, x: np.ndarray) -> np.ndarray:
        """Log prior density (unnormalised), -inf outside the bounds."""
        x = np.asarray(x, dtype=float)
        inside = (x >= self.low) & (x <= self.high)
        if self.prior == "normal":
            value = -0.5 * ((x - self.prior_mean) / self.prior_sd) ** 2
        elif self.prior == "log-uniform":
            value = -np.log(np.where(x > 0, x, 1.0))
        else:
            value = np.zeros_like(x)
        return np.where(inside, value, -np.inf)


#: Named DEM parameters: specimen fields they set (both pairs where not suffixed), bounds.
#: ``friction`` sets sliding and static friction to one value (one Coulomb coefficient);
#: ``static_friction`` below a pair's sliding friction is taken as that sliding friction.
_PAIR = {"pp": ("particle_particle",), "pw": ("particle_wall",),
         "": ("particle_particle", "particle_wall")}
_DEM_ALIASES: dict[str, tuple[str, float, float, str]] = {
    "friction": ("sliding_friction", 0.05, 0.8, "sliding friction"),
    "static_friction": ("static_friction", 0.1, 1.0, "static friction (stick limit)"),
    "rolling_friction": ("rolling_friction", 0.0, 0.1, "rolling friction mu_r"),
    "restitution": ("restitution", 0.3, 0.95, "normal restitution"),
}


def dem_alias_paths(name: str) -> tuple[str, tuple[str, ...]] | None:
    """(specimen pair field, pair names) of a named DEM parameter, None if not an alias."""
    for suffix in ("pp", "pw"):
        if name.endswith("_" + suffix) and name[:-3] in _DEM_ALIASES:
            return _DEM_ALIASES[name[:-3]][0], _PAIR[suffix]
    if name in _DEM_ALIASES:
        return _DEM_ALIASES[name][0], _PAIR[""]
    return None


def friction_paths(name: str) -> tuple[str, tuple[str, ...]] | None:
    """(pair field, pair names) of a parameter that sets a pair's friction by a rule of its
    own: a named alias (:func:`dem_alias_paths`), or a pair's static or sliding friction by
    dotted path (``pairs.particle_wall.static_friction``).

    One parameter, one rule: ``pairs.particle_wall.static_friction`` is
    ``static_friction_pw`` and is taken as the sliding friction where below it, as the
    documented alias is; the dotted path used to go to the specimen unchanged, so the same
    prior was refused as outside the physical domain under one name and fitted under the
    other. A dotted ``sliding_friction`` sets that field alone (unlike ``friction``, which
    sets the static one too); it is named here so that a static friction set with it is
    checked against it.
    """
    alias = dem_alias_paths(name)
    if alias is not None:
        return alias
    parts = name.split(".")
    if (len(parts) == 3 and parts[0] == "pairs" and parts[1] in _PAIR[""]
            and parts[2] in ("static_friction", "sliding_friction")):
        return parts[2], (parts[1],)
    return None


def fields_set(name: str) -> tuple[str, ...]:
    """Specimen fields (dotted paths) that fitting ``name`` sets: an alias's field of each
    pair it names (``restitution``: both pairs' ``restitution``), an observation parameter's
    coupon field, a dotted path itself. ``friction`` is counted as the sliding friction it
    stands for: the static friction it moves along is the one a ``static_friction`` fitted
    beside it replaces as the stick limit, by design (:func:`pidcore.calibrate.runner.
    specimen_with`), not an overlap."""
    name = OBSERVATION_PATHS.get(name, name)
    if name in CATALOGUE:
        return tuple(path for path, n in OBSERVATION_PATHS.items() if n == name)
    alias = dem_alias_paths(name)
    if alias is not None:
        field, pairs = alias
        return tuple(f"pairs.{pair}.{field}" for pair in pairs)
    return (name,)


def _check_no_overlap(given: Sequence[str]) -> None:
    """Refuse two fitted names that set one specimen field (:func:`fields_set`).

    ``restitution,restitution_pp`` was fitted as two parameters: each design point ran the
    specimen with the one named last (:func:`pidcore.calibrate.runner.specimen_with`), so the
    other's posterior was its prior, a whole design was spent on it, and the calibrated file's
    header stated a value its body did not hold.
    """
    owner: dict[str, str] = {}
    for name in given:
        for path in fields_set(name):
            if path not in owner:
                owner[path] = name
                continue
            first = owner[path]
            if first == name:
                raise ParameterError(f"fit: {name} is named twice; name it once")
            both = next((n for n in (first, name) if len(fields_set(n)) > 1), "")
            raise ParameterError(f"fit: {first} and {name} both set {path}; fit one of them"
                                 + (f" ({both} sets both pairs: fit {both}_pp and {both}_pw "
                                    "for each pair apart)" if both else ""))


def dem_parameter_names() -> list[str]:
    """Named DEM parameters ``--fit`` accepts besides dotted specimen paths."""
    return [f"{n}{s}" for n in _DEM_ALIASES for s in ("", "_pp", "_pw")]


#: Parameters of the observation model (no DEM run) and the discrepancy hyperparameter.
CATALOGUE: dict[str, ParameterSpec] = {spec.name: spec for spec in (
    ParameterSpec("fixture_mass_kg", "observation", 0.0, 0.0, 1.0,
                  "mass moving with the coupon above the force gauge", unit="kg"),
    ParameterSpec("baseline_loss_factor", "observation", 0.0, 0.0, 0.05,
                  "loss factor of the empty coupon and fixture"),
    ParameterSpec(DISCREPANCY, "hyper", 0.2, 0.02, 2.0,
                  "relative standard deviation of the model error", prior="log-uniform"),
)}
#: Specimen fields that are observation parameters.
OBSERVATION_PATHS = {"coupon.fixture_mass_kg": "fixture_mass_kg",
                     "coupon.baseline_loss_factor": "baseline_loss_factor"}

DEFAULT_FIT = ("fixture_mass_kg", "baseline_loss_factor")

#: The coupon's own mass: no DEM parameter (the cells follow the prescribed drive whatever
#: the coupon weighs) and in the measured SDC (Eq. 11, :mod:`pidcore.calibrate.observation`)
#: only beside the fixture's, as their sum: :func:`parse_fit` refuses it.
COUPON_MASS_PATH = "coupon.mass_kg"


#: Unit of a specimen field by the suffix of its name (the schema's naming rule: SI, the unit
#: in the name); a field without one (ratios, coefficients) is dimensionless.
_FIELD_UNITS = (("_kg_m3", "kg/m^3"), ("_pa", "Pa"), ("_kg", "kg"), ("_m", "m"),
                ("_percent", "%"))


def field_unit(path: str) -> str:
    """Unit of a specimen field by dotted path, e.g. ``"m"`` for ``particles.radius_m``."""
    return next((unit for suffix, unit in _FIELD_UNITS if path.endswith(suffix)), "-")


def _specimen(specimen):
    if specimen is None:
        from ..specimen import paper_specimen

        return paper_specimen()
    return specimen


def parameter_spec(name: str, specimen=None) -> ParameterSpec:
    """Default spec of a fittable name: an observation parameter, a named DEM parameter, or
    any numeric specimen field by dotted path (default bounds 0.5x..1.5x its value)."""
    from ..specimen import field_domain, numeric_fields

    name = OBSERVATION_PATHS.get(name, name)
    specimen = _specimen(specimen)
    if name in CATALOGUE:
        spec = CATALOGUE[name]
        if name == "fixture_mass_kg":
            return replace(spec, default=specimen.coupon.fixture_mass_kg)
        if name == "baseline_loss_factor":
            return replace(spec, default=specimen.coupon.baseline_loss_factor)
        return spec
    alias = dem_alias_paths(name)
    if alias is not None:
        field, pairs = alias
        base = name[:-3] if name.endswith(("_pp", "_pw")) else name
        _, low, high, text = _DEM_ALIASES[base]
        default = getattr(getattr(specimen.pairs, pairs[-1]), field)
        where = "both pairs" if len(pairs) == 2 else pairs[0].replace("_", "-")
        return ParameterSpec(name, "dem", float(default), low, high, f"{text}, {where}")
    if name in numeric_fields(specimen):
        value = float(_field_value(specimen, name))
        unit = field_unit(name)
        if value > 0:
            # 1.5 x a restitution of 0.9 is 1.35: the default prior of a field was refused
            # as outside the domain whatever its value, so it is cut to the field's own rule
            low, high = field_domain(name)
            cut = [f"{which} cut to {as_given(bound)}, the field's limit"
                   for which, bound, wanted in (("low", low, 0.5 * value),
                                                ("high", high, 1.5 * value))
                   if (wanted < bound if which == "low" else wanted > bound)]
            return ParameterSpec(name, "dem", value, max(0.5 * value, low),
                                 min(1.5 * value, high),
                                 f"specimen field {name}"
                                 + (f" (default prior 0.5 .. 1.5 x its value, "
                                    f"{'; '.join(cut)})" if cut else ""), unit=unit)
        return ParameterSpec(name, "dem", value, float("nan"), float("nan"),
                             f"specimen field {name} (give priors={name}=LOW:HIGH)",
                             unit=unit)
    raise ParameterError(f"fit: unknown parameter {name!r}; expected fixture_mass_kg, "
                         f"baseline_loss_factor, one of {', '.join(dem_parameter_names())}, or a "
                         "numeric specimen field by dotted path (pidcore specimen check)")


def _refuse_whole_number(name: str, specimen) -> None:
    """A whole-number specimen field (``cell.count``, ``particles.count_per_cell``) cannot be
    fitted: the design and the posterior vary parameters continuously, and a fractional count
    is no specimen (it failed mid-run with an error blaming the specimen file)."""
    from ..specimen import numeric_fields

    specimen = _specimen(specimen)
    if name in numeric_fields(specimen) and isinstance(_field_value(specimen, name), int):
        raise ParameterError(f"fit {name}: a whole-number field cannot be fitted (the fit "
                             "varies parameters continuously); set it in the specimen file and "
                             "calibrate once per value instead")


def _field_value(specimen, path: str):
    node = specimen.to_mapping()
    for part in path.split("."):
        node = node[part]
    return node


def parse_fit(text: str | Sequence[str] | None, specimen: Specimen | None = None
              ) -> list[str]:
    """Names from ``--fit a,b``; an unknown name, and two names that set one specimen field
    (an alias and a pair's own alias or dotted path, :func:`fields_set`), are a one-line
    error, before any DEM run."""
    if text is None:
        return list(DEFAULT_FIT)
    given = [n.strip() for n in (text.split(",") if isinstance(text, str) else text)]
    given = [n for n in given if n]
    names = [OBSERVATION_PATHS.get(n, n) for n in given]
    if not names:
        raise ParameterError("fit: no parameter named")
    for name in names:
        if name == DISCREPANCY:
            raise ParameterError(f"fit: {DISCREPANCY} is always fitted (fix it with "
                                 "discrepancy=TAU)")
        if name == COUPON_MASS_PATH:
            # fitted as a DEM parameter it cost a design of DEM runs that all came out alike,
            # and its posterior was its prior, beside or instead of fixture_mass_kg
            raise ParameterError(
                f"fit: {COUPON_MASS_PATH} cannot be fitted: the coupon's rigid mass moves no "
                "particle in the DEM (its cells follow the prescribed drive) and enters the "
                "measured SDC (Eq. 11) only as coupon + fixture mass, as fixture_mass_kg does, "
                "so the tests cannot tell the two apart; fit fixture_mass_kg (no DEM run) and "
                f"state the coupon's mass in the specimen file")
        parameter_spec(name, specimen)
        _refuse_whole_number(name, specimen)
    _check_no_overlap(given)
    return names


def parse_prior(text: str) -> tuple[str, dict]:
    """``NAME=LOW:HIGH`` or ``NAME=normal:MU:SD[:LOW:HIGH]`` -> (name, ParameterSpec fields)."""
    if "=" not in text:
        raise ParameterError(f"priors {text!r}: expected NAME=LOW:HIGH or "
                             "NAME=normal:MU:SD[:LOW:HIGH]")
    name, rhs = (s.strip() for s in text.split("=", 1))
    name = OBSERVATION_PATHS.get(name, name)
    parts = rhs.split(":")
    try:
        if parts[0] == "normal":
            numbers = [float(p) for p in parts[1:]]
            if len(numbers) not in (2, 4):
                raise ValueError
            fields = {"prior": "normal", "prior_mean": numbers[0], "prior_sd": numbers[1]}
            if len(numbers) == 4:
                fields.update(low=numbers[2], high=numbers[3])
        else:
            numbers = [float(p) for p in parts]
            if len(numbers) != 2:
                raise ValueError
            fields = {"low": numbers[0], "high": numbers[1]}
    except ValueError:
        raise ParameterError(f"priors {text!r}: expected NAME=LOW:HIGH or "
                             "NAME=normal:MU:SD[:LOW:HIGH] with numbers") from None
    return name, fields


def build_specs(fit: Sequence[str], priors: Sequence[str] = (), *,
                discrepancy: float | None = None, specimen: Specimen | None = None
                ) -> list[ParameterSpec]:
    """Specs of the fitted parameters (order of ``fit``, then ``model_discrepancy`` unless
    fixed by ``discrepancy``), with ``--prior`` changes applied and checked."""
    changes: dict[str, dict] = {}
    given: dict[str, str] = {}  # name -> the --prior text that set its bounds last
    for text in priors:
        name, fields = parse_prior(text)
        changes.setdefault(name, {}).update(fields)
        given[name] = text.strip()
    names = list(fit) + ([] if discrepancy is not None else [DISCREPANCY])
    for name in changes:
        if name not in names:
            raise ParameterError(f"priors {name}: not a fitted parameter (add it to fit=)")
    specs = []
    for name in names:
        spec = replace(parameter_spec(name, specimen), **changes.get(name, {}))
        spec.check()
        specs.append(spec)
    if discrepancy is not None and not (math.isfinite(real_number("discrepancy", discrepancy))
                                        and discrepancy >= 0):
        # inf ran every DEM run, then said "the posterior is zero everywhere"
        raise ParameterError(f"discrepancy: expected a finite fraction >= 0, got {discrepancy}")
    check_domains(specs, specimen, given)
    return specs


#: Most DEM parameters whose prior box is checked corner by corner (2**k specimens, each a
#: few milliseconds); beyond, each parameter's own bounds are still checked.
_MAX_CORNER_PARAMETERS = 6


def _prior_words(spec: ParameterSpec, given: Mapping[str, str]) -> str:
    """How the message names a prior: the ``--prior`` given, or the default bounds."""
    if spec.name in given:
        return f"priors={given[spec.name]}"
    return (f"the default prior bounds {spec.name}={spec.low:g}:{spec.high:g} (give "
            f"priors={spec.name}=LOW:HIGH)")


def check_domains(specs: Sequence[ParameterSpec], specimen=None,
                  given: Mapping[str, str] | None = None) -> None:
    """Refuse a prior range that leaves a parameter's physical domain, before any DEM run.

    The domain is the one the specimen file enforces (masses, loss factors and frictions
    >= 0, 0 < restitution <= 1, a particle that fits its cell, ...): the starting specimen is
    built with each parameter at each of its bounds, then with the DEM parameters at every
    corner of their prior box (e.g. a cell diameter and a particle radius fitted together), and
    the specimen's own one-line complaint is said naming the prior. Without this a negative
    baseline loss factor was fitted and reported (a negative predicted SDC), and a design point
    outside the domain failed mid-run blaming the bundled specimen file.
    """
    from .runner import specimen_with

    given = given or {}
    specimen = _specimen(specimen)
    prefix = f"{specimen.source}: "

    def build(values: Mapping[str, float]) -> str:
        """The specimen's complaint about ``values`` ("" where they make a valid one)."""
        dem = {n: v for n, v in values.items() if n not in CATALOGUE}
        coupon = {f"coupon.{n}": v for n, v in values.items()
                  if n in ("fixture_mass_kg", "baseline_loss_factor")}
        try:
            built = specimen_with(specimen, dem)
            if coupon:
                built.with_values(coupon)
        except ParameterError as exc:
            return str(exc).removeprefix(prefix)
        return ""

    def outside(spec: ParameterSpec, bound: float, complaint: str) -> ParameterError:
        return ParameterError(f"{_prior_words(spec, given)}: {spec.name}={as_given(bound)} "
                              f"is outside its physical domain ({complaint}); give a range "
                              f"inside it{_together_hint(spec.name, complaint)}")

    def check_each_bound(spec: ParameterSpec) -> None:
        """Each bound of ``spec`` alone, the other parameters at their starting values."""
        for bound in (spec.low, spec.high):
            complaint = build({spec.name: bound})
            if complaint:
                raise outside(spec, bound, complaint)

    for spec in specs:
        if spec.kind == "hyper" and spec.low < 0:  # a relative standard deviation
            raise ParameterError(f"{_prior_words(spec, given)}: {spec.name} is a relative "
                                 "standard deviation; expected bounds >= 0")
        if spec.kind == "observation":  # enters no DEM run: its own bounds are its domain
            check_each_bound(spec)
    dem = [s for s in specs if s.kind == "dem"]
    _check_static_friction(dem, specimen, given)
    if len(dem) > _MAX_CORNER_PARAMETERS:  # too many corners: each bound alone
        for spec in dem:
            check_each_bound(spec)
        return
    corners = list(itertools.product(*((s.low, s.high) for s in dem)))
    complaints = [build(dict(zip((s.name for s in dem), c, strict=True))) for c in corners]
    if not any(complaints):
        return
    # a bound invalid at every corner is that parameter's own fault (a negative friction):
    # named alone; else the combination is (a particle radius the cell diameter cannot hold)
    for i, spec in enumerate(dem):
        for bound in (spec.low, spec.high):
            at = [c for c, corner in zip(complaints, corners, strict=True) if corner[i] == bound]
            if all(at):
                raise outside(spec, bound, at[0])
    corner, complaint = next((c, m) for c, m in zip(corners, complaints, strict=True) if m)
    values = ", ".join(f"{s.name}={as_given(v)}" for s, v in zip(dem, corner, strict=True))
    priors = "; ".join(_prior_words(s, given) for s in dem)
    raise ParameterError(f"{priors}: the prior corner {values} is outside the physical "
                         f"domain ({complaint}); narrow the ranges")


def _together_hint(name: str, complaint: str) -> str:
    """The alias that moves a pair's sliding and static friction together, for a dotted
    sliding friction whose range passed the static one the file states (or left to its
    default, the sliding friction): the refusal only asked for another range, and a user of a
    file without static_friction did not know it was there to pass."""
    parts = name.split(".")
    if len(parts) != 3 or parts[2] != "sliding_friction" or "static_friction" not in complaint:
        return ""
    alias = {"particle_particle": "friction_pp", "particle_wall": "friction_pw"}.get(parts[1])
    if alias is None:
        return ""
    return f", or fit {alias} (sliding and static friction of that pair together)"


def _check_static_friction(dem: Sequence[ParameterSpec], specimen,
                           given: Mapping[str, str]) -> None:
    """Refuse a static friction range wholly at or below the sliding friction it stands on.

    Static friction is at least the sliding one (the specimen file's rule): a value below it
    is taken as it (:func:`pidcore.calibrate.runner.specimen_with`), so a range below the
    lowest sliding friction of the pairs it sets (the specimen's, or a fitted friction's lower
    bound) changes no DEM run, and the fit learns nothing from it.
    """
    lowest = {pair: getattr(specimen.pairs, pair).sliding_friction
              for pair in ("particle_particle", "particle_wall")}
    for spec in dem:
        alias = friction_paths(spec.name)
        if alias is not None and alias[0] == "sliding_friction":
            lowest.update((pair, spec.low) for pair in alias[1])
    for spec in dem:
        alias = friction_paths(spec.name)
        if alias is None or alias[0] != "static_friction":
            continue
        floor = {pair: lowest[pair] for pair in alias[1]}
        if spec.high <= min(floor.values()):
            stated = ", ".join(f"{v:g} {pair.replace('_', '-')}" for pair, v in floor.items())
            raise ParameterError(f"{_prior_words(spec, given)}: static friction below the "
                                 f"sliding friction (at least {stated}) is taken as the "
                                 "sliding friction, so this range changes no DEM run; give a "
                                 "range above it")
