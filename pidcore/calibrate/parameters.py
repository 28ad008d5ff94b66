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

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ParameterError

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

    def check(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low < self.high):
            raise ParameterError(f"{self.name}: bounds {self.low:g}:{self.high:g} are empty "
                                 "(expected LOW < HIGH)")
        if self.prior == "normal":
            if not self.prior_sd > 0:
                raise ParameterError(f"{self.name}: prior sd must be > 0, got {self.prior_sd:g}")
            if not self.low <= self.prior_mean <= self.high:
                raise ParameterError(
                    f"{self.name}: bounds {self.low:g}:{self.high:g} exclude the prior mean "
                    f"{self.prior_mean:g}")
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


def dem_parameter_names() -> list[str]:
    """Named DEM parameters ``--fit`` accepts besides dotted specimen paths."""
    return [f"{n}{s}" for n in _DEM_ALIASES for s in ("", "_pp", "_pw")]


#: Parameters of the observation model (no DEM run) and the discrepancy hyperparameter.
CATALOGUE: dict[str, ParameterSpec] = {spec.name: spec for spec in (
    ParameterSpec("fixture_mass_kg", "observation", 0.0, 0.0, 1.0,
                  "mass moving with the coupon above the force gauge"),
    ParameterSpec("baseline_loss_factor", "observation", 0.0, 0.0, 0.05,
                  "loss factor of the empty coupon and fixture"),
    ParameterSpec(DISCREPANCY, "hyper", 0.2, 0.02, 2.0,
                  "relative standard deviation of the model error", prior="log-uniform"),
)}
#: Specimen fields that are observation parameters.
OBSERVATION_PATHS = {"coupon.fixture_mass_kg": "fixture_mass_kg",
                     "coupon.baseline_loss_factor": "baseline_loss_factor"}

DEFAULT_FIT = ("fixture_mass_kg", "baseline_loss_factor")


def _specimen(specimen):
    if specimen is None:
        from ..specimen import paper_specimen

        return paper_specimen()
    return specimen


def parameter_spec(name: str, specimen=None) -> ParameterSpec:
    """Default spec of a fittable name: an observation parameter, a named DEM parameter, or
    any numeric specimen field by dotted path (default bounds 0.5x..1.5x its value)."""
    from ..specimen import numeric_fields

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
        if value > 0:
            return ParameterSpec(name, "dem", value, 0.5 * value, 1.5 * value,
                                 f"specimen field {name}")
        return ParameterSpec(name, "dem", value, float("nan"), float("nan"),
                             f"specimen field {name} (give --prior {name}=LOW:HIGH)")
    raise ParameterError(f"--fit: unknown parameter {name!r}; expected fixture_mass_kg, "
                         f"baseline_loss_factor, one of {', '.join(dem_parameter_names())}, or a "
                         "numeric specimen field by dotted path (pidcore specimen check)")


def _field_value(specimen, path: str):
    node = specimen.to_mapping()
    for part in path.split("."):
        node = node[part]
    return node


def parse_fit(text: str | Sequence[str] | None, specimen=None) -> list[str]:
    """Names from ``--fit a,b``; unknown names are a one-line error."""
    if text is None:
        return list(DEFAULT_FIT)
    names = [n.strip() for n in (text.split(",") if isinstance(text, str) else text)]
    names = [OBSERVATION_PATHS.get(n, n) for n in names if n]
    if not names:
        raise ParameterError("--fit: no parameter named")
    for name in names:
        if name == DISCREPANCY:
            raise ParameterError(f"--fit: {DISCREPANCY} is always fitted (fix it with "
                                 "--discrepancy)")
        parameter_spec(name, specimen)
    if len(set(names)) != len(names):
        raise ParameterError(f"--fit: a parameter is named twice in {','.join(names)}")
    return names


def parse_prior(text: str) -> tuple[str, dict]:
    """``NAME=LOW:HIGH`` or ``NAME=normal:MU:SD[:LOW:HIGH]`` -> (name, ParameterSpec fields)."""
    if "=" not in text:
        raise ParameterError(f"--prior {text!r}: expected NAME=LOW:HIGH or "
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
        raise ParameterError(f"--prior {text!r}: expected NAME=LOW:HIGH or "
                             "NAME=normal:MU:SD[:LOW:HIGH] with numbers") from None
    return name, fields


def build_specs(fit: Sequence[str], priors: Sequence[str] = (), *,
                discrepancy: float | None = None, specimen=None) -> list[ParameterSpec]:
    """Specs of the fitted parameters (order of ``fit``, then ``model_discrepancy`` unless
    fixed by ``discrepancy``), with ``--prior`` changes applied and checked."""
    changes: dict[str, dict] = {}
    for text in priors:
        name, fields = parse_prior(text)
        changes.setdefault(name, {}).update(fields)
    names = list(fit) + ([] if discrepancy is not None else [DISCREPANCY])
    for name in changes:
        if name not in names:
            raise ParameterError(f"--prior {name}: not a fitted parameter (add it to --fit)")
    specs = []
    for name in names:
        spec = replace(parameter_spec(name, specimen), **changes.get(name, {}))
        spec.check()
        if name == "baseline_loss_factor":
            from ..specimen import PLAUSIBLE_RANGES

            # the fit is written to the calibrated specimen, which refuses a loss factor
            # above this bound: refuse the prior now, not after the DEM runs
            most = PLAUSIBLE_RANGES["baseline_loss_factor"].high
            if spec.high > most:
                raise ParameterError(
                    f"--prior baseline_loss_factor: upper bound {spec.high:g} is above {most:g}, "
                    "the most an empty coupon's loss factor may be (a specimen refuses more); "
                    "was it %?")
        specs.append(spec)
    if discrepancy is not None and not discrepancy >= 0:
        raise ParameterError(f"--discrepancy: expected >= 0, got {discrepancy}")
    return specs
