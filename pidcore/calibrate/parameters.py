"""Calibration parameters: what can be fitted, its default value, bounds and prior.

Two kinds:

* ``"dem"``: changes the particle physics, so every value needs new DEM runs (friction,
  restitution; the runner in :mod:`pidcore.calibrate.runner` says which exist);
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


#: Every parameter `--fit` accepts, with its default prior. The DEM defaults are the materials
#: table's acrylic values (Table 1).
CATALOGUE: dict[str, ParameterSpec] = {spec.name: spec for spec in (
    ParameterSpec("fixture_mass_kg", "observation", 0.0, 0.0, 1.0,
                  "mass moving with the coupon above the force gauge"),
    ParameterSpec("baseline_loss_factor", "observation", 0.0, 0.0, 0.05,
                  "loss factor of the empty coupon and fixture"),
    ParameterSpec("friction", "dem", 0.14, 0.05, 0.8,
                  "sliding friction, particle-particle and particle-wall"),
    ParameterSpec("friction_pp", "dem", 0.096, 0.05, 0.8, "sliding friction particle-particle"),
    ParameterSpec("friction_pw", "dem", 0.14, 0.05, 0.8, "sliding friction particle-wall"),
    ParameterSpec("restitution", "dem", 0.7, 0.3, 0.95,
                  "normal restitution, particle-particle and particle-wall"),
    ParameterSpec("restitution_pp", "dem", 0.7, 0.3, 0.95,
                  "normal restitution particle-particle"),
    ParameterSpec("restitution_pw", "dem", 0.7, 0.3, 0.95, "normal restitution particle-wall"),
    ParameterSpec(DISCREPANCY, "hyper", 0.2, 0.02, 2.0,
                  "relative standard deviation of the model error", prior="log-uniform"),
)}

DEFAULT_FIT = ("fixture_mass_kg", "baseline_loss_factor")


def parse_fit(text: str | Sequence[str] | None) -> list[str]:
    """Names from ``--fit a,b``; unknown names are a one-line error."""
    if text is None:
        return list(DEFAULT_FIT)
    names = [n.strip() for n in (text.split(",") if isinstance(text, str) else text)]
    names = [n for n in names if n]
    if not names:
        raise ParameterError("--fit: no parameter named")
    for name in names:
        if name not in CATALOGUE or name == DISCREPANCY:
            raise ParameterError(f"--fit: unknown parameter {name!r}; expected names from "
                                 f"{', '.join(n for n in CATALOGUE if n != DISCREPANCY)}")
    if len(set(names)) != len(names):
        raise ParameterError(f"--fit: a parameter is named twice in {','.join(names)}")
    return names


def parse_prior(text: str) -> tuple[str, dict]:
    """``NAME=LOW:HIGH`` or ``NAME=normal:MU:SD[:LOW:HIGH]`` -> (name, ParameterSpec fields)."""
    if "=" not in text:
        raise ParameterError(f"--prior {text!r}: expected NAME=LOW:HIGH or "
                             "NAME=normal:MU:SD[:LOW:HIGH]")
    name, rhs = (s.strip() for s in text.split("=", 1))
    if name not in CATALOGUE:
        raise ParameterError(f"--prior: unknown parameter {name!r}; expected one of "
                             f"{', '.join(CATALOGUE)}")
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
                discrepancy: float | None = None) -> list[ParameterSpec]:
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
        spec = replace(CATALOGUE[name], **changes.get(name, {}))
        spec.check()
        specs.append(spec)
    if discrepancy is not None and not discrepancy >= 0:
        raise ParameterError(f"--discrepancy: expected >= 0, got {discrepancy}")
    return specs
