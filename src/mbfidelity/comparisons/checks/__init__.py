"""Scenario checks beyond the trajectory (the catalog's X checks), one module per check,
discovered automatically (the pattern of `systems`): a module defines ``CHECK``, the name
a `Scenario` lists in its ``checks``, and ``measure(run: ScenarioRun) -> None``, which
appends its metrics through ``run.judge`` / ``run.unresolved``. The runner calls every
check a scenario lists after its trajectory metrics, with the engine's run and the
reference of the same scenario. A check whose physics widens the trajectory's error bound
(a force law with corners that the engines step across) may also define
``trajectory_allowance(system, scenario, values, reference, equilibrium, dt, order)``:
the error it adds, relative to the amplitude, with its derivation; and
``period_allowance`` with the same arguments: what it adds to the mean period's relative
error; and ``refinement_order(system, scenario, values, reference, order)``: the order at
which an engine's error can fall with the step in the scenario when a non-smooth element
caps it below the scheme's (an event the engine does not locate), or None (the a-posteriori
rule of comparisons/tolerances.py then judges the engine's refinement at that order).
``REFINABLE`` names the metrics (labels) a check measures as a quantity of the engine's
run against the same quantity of the reference's: measured between two of the engine's
own runs they are their difference, so the refinement judges them as it does the
trajectory (the other checks' metrics it leaves alone)."""
from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np


@dataclass
class ScenarioRun:
    """What a check sees: the system, the engine (`backend`, its resolved `settings`),
    the scenario and its parameter `values`, the numeric `mechanism` the engine built,
    the `reference` and the engine's `run` (first `n` samples comparable), the trajectory
    `gate` (tolerances.Gate) with the motion's fastest angular frequency `w`, the step
    `dt`, the operating `equilibrium`, and how to record metrics."""

    system: Any
    backend: Any
    scenario: Any
    values: Mapping[str, float]
    mechanism: Any
    reference: Any
    run: Any
    n: int
    gate: Any
    w: float
    dt: float
    equilibrium: Any
    settings: Mapping[str, Any]
    #: (name, value, gate, unit) -> Metric, appended to the comparison
    judge: Callable[..., Any]
    #: (name, tolerance, reason) -> Metric with status unresolved, appended
    unresolved: Callable[..., Any]
    #: (mechanism, q0, qd0, t_end) -> RunResult or None (an incident is recorded)
    simulate: Callable[..., Any]
    #: arrays for the report's figures, by name (saved with the scenario's series)
    series: dict = field(default_factory=dict)
    #: the `reference` is the engine's own finer run (the a-posteriori rule): a REFINABLE
    #: metric then measures the distance between the two runs' quantities
    refinement: bool = False

    @property
    def name(self) -> str:
        return self.scenario.name

    @property
    def t(self) -> np.ndarray:
        return self.reference.t[: self.n]


_REGISTRY: dict[str, Callable[[ScenarioRun], None]] | None = None
_ALLOWANCES: dict[str, Callable[..., float]] = {}
_PERIOD_ALLOWANCES: dict[str, Callable[..., float]] = {}
_REFINEMENT_ORDERS: dict[str, Callable[..., int | None]] = {}
_REFINABLE: dict[str, tuple[str, ...]] = {}


def trajectory_allowances(check_names) -> list[Callable[..., float]]:
    """The `trajectory_allowance` functions of the checks named."""
    registry()
    return [_ALLOWANCES[c] for c in check_names if c in _ALLOWANCES]


def period_allowances(check_names) -> list[Callable[..., float]]:
    """The `period_allowance` functions of the checks named."""
    registry()
    return [_PERIOD_ALLOWANCES[c] for c in check_names if c in _PERIOD_ALLOWANCES]


def refinement_orders(check_names) -> list[Callable[..., int | None]]:
    """The `refinement_order` functions of the checks named."""
    registry()
    return [_REFINEMENT_ORDERS[c] for c in check_names if c in _REFINEMENT_ORDERS]


def refinable(check_name: str) -> tuple[str, ...]:
    """The labels of the check's metrics the refinement judges (its ``REFINABLE``)."""
    registry()
    return _REFINABLE.get(check_name, ())


def registry() -> dict[str, Callable[[ScenarioRun], None]]:
    """check name -> measure function, from the modules of this package."""
    global _REGISTRY
    if _REGISTRY is None:
        found = {}
        for info in pkgutil.iter_modules(__path__):
            module = importlib.import_module(f"{__name__}.{info.name}")
            name = getattr(module, "CHECK", None)
            if name is not None:
                if name in found:
                    raise ValueError(f"check {name!r} is defined twice")
                found[name] = module.measure
                if hasattr(module, "trajectory_allowance"):
                    _ALLOWANCES[name] = module.trajectory_allowance
                if hasattr(module, "period_allowance"):
                    _PERIOD_ALLOWANCES[name] = module.period_allowance
                if hasattr(module, "refinement_order"):
                    _REFINEMENT_ORDERS[name] = module.refinement_order
                _REFINABLE[name] = tuple(getattr(module, "REFINABLE", ()))
        _REGISTRY = found
    return _REGISTRY
