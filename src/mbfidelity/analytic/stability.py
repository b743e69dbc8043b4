"""Where the operating equilibrium changes stability as one parameter varies (a system's
`stability_parameter`, e.g. the belt speed of §7.2).

The growth rate max Re(s) of the linearization (analytic/linear.py) is a continuous
function of the parameter; its sign changes are bracketed on a logarithmic grid around
the parameter's value (from 1/`SPAN` to `SPAN` times it, `GRID` points) and refined by
Brent's method to round-off of the parameter. Each crossing is reported with the side on
which the equilibrium is stable; the threshold is the crossing nearest the value given.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
import scipy.optimize

from ..systems import System
from . import memo
from .linear import solve_operating_equilibrium

#: the scan covers [value / SPAN, value * SPAN]
SPAN = 100.0
GRID = 81


@dataclass(frozen=True)
class Crossing:
    """The parameter value where max Re(s) = 0, and whether the equilibrium is stable
    above it (True) or below it (False)."""

    value: float
    stable_above: bool

    def as_dict(self) -> dict:
        return {"value": self.value, "stable_above": self.stable_above}


@dataclass(frozen=True)
class Threshold:
    parameter: str
    crossings: tuple[Crossing, ...]
    #: the crossing nearest the parameter's value, None when no crossing is in the scan
    nearest: Crossing | None
    scanned: tuple[float, float]

    def as_dict(self) -> dict:
        return {"parameter": self.parameter,
                "value": None if self.nearest is None else self.nearest.value,
                "stable_above": None if self.nearest is None else self.nearest.stable_above,
                "crossings": [c.as_dict() for c in self.crossings],
                "scanned": list(self.scanned)}


def growth_rate(system: System, values: Mapping[str, float], parameter: str,
                x: float) -> float:
    """max Re(s) of the operating equilibrium's linearization with the parameter at x."""
    trial = dict(values)
    trial[parameter] = float(x)
    return float(np.max(solve_operating_equilibrium(system, trial).eigenvalues.real))


def stability_threshold(system: System, values: Mapping[str, float],
                        parameter: str | None = None) -> Threshold:
    """The crossings of max Re(s) = 0 in the parameter (the system's
    `stability_parameter` by default), scanned around its value in `values`. Kept in the
    persistent cache (analytic/memo.py) under the parameter values and the scan."""
    name = parameter or system.stability_parameter
    return memo.cached(system, "stability_threshold", (dict(values), name, SPAN, GRID),
                       lambda: _stability_threshold(system, values, name))


def _stability_threshold(system: System, values: Mapping[str, float],
                         name: str | None) -> Threshold:
    if name is None:
        raise ValueError(f"{system.id} names no stability parameter")
    value = float(values[name])
    if not value > 0:
        raise ValueError(f"the stability scan needs a positive {name} (got {value:g})")
    grid = value * np.logspace(-np.log10(SPAN), np.log10(SPAN), GRID)
    rates = np.array([growth_rate(system, values, name, x) for x in grid])
    crossings = []
    for a, b, ra, rb in zip(grid[:-1], grid[1:], rates[:-1], rates[1:]):
        if ra == 0.0 or ra * rb < 0:
            root = a if ra == 0.0 else scipy.optimize.brentq(
                lambda x: growth_rate(system, values, name, x), a, b,
                xtol=1e-15, rtol=4 * np.finfo(float).eps)
            crossings.append(Crossing(float(root), stable_above=bool(rb < 0)))
    nearest = min(crossings, key=lambda c: abs(np.log(c.value / value)), default=None)
    return Threshold(name, tuple(crossings), nearest, (float(grid[0]), float(grid[-1])))
