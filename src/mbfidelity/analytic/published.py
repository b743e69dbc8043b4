"""Published values (a benchmark's solution, `System.published`) against the reference.

A state value is the published expression of the coordinates evaluated on the reference
at its instant (a sample: the reference is sampled at a step that divides the instant);
a period is measured on the reference as the mean spacing of the coordinate's upward
crossings of its centre value (the mean of its extremes), located on the cubic Hermite
interpolant of the samples (positions and velocities) to the reference's own tolerance.
Each comparison carries the reference's error estimate for the quantity, so that a
difference beyond it is told apart from the reference's own error.
"""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np
import sympy as sp
from scipy.interpolate import CubicHermiteSpline

from ..systems import Published, System, coordinate_symbols
from .reference import reference

#: samples per published instant (the instant is a whole number of steps)
SAMPLES = 2000


def _applies(system: System, item: Published, values: Mapping[str, float],
             scenario) -> bool:
    """A published number holds at the published parameters (the defaults with the
    scenario's values); a closed form (a function) at any."""
    if callable(item.value):
        return True
    published = system.parameter_values(scenario=scenario)
    return all(math.isclose(values[k], v, rel_tol=1e-12, abs_tol=0.0)
               for k, v in published.items())


def _state(system: System, item: Published, values, scenario, ref, k: int):
    names = list(system.coordinates)
    symbols = [s for c in names for s in coordinate_symbols(c)[:2]]
    expr = sp.sympify(item.expression).xreplace(system.subs(values))
    law = sp.lambdify(symbols, expr, modules="numpy")
    args = [col for i in range(len(names)) for col in (ref.q[k, i], ref.qd[k, i])]
    value = float(law(*args))
    # the reference's position error propagated through the expression (first order)
    grad = [sp.diff(expr, coordinate_symbols(c)[0]) for c in names]
    at = dict(zip(symbols, args))
    error = sum(abs(float(g.xreplace(at))) * e for g, e in zip(grad, ref.error_estimate))
    return value, error


def _period(system: System, item: Published, ref) -> tuple[float, float]:
    i = list(system.coordinates).index(item.coordinate)
    q, qd = ref.q[:, i], ref.qd[:, i]
    centre = (q.max() + q.min()) / 2
    spline = CubicHermiteSpline(ref.t, q - centre, qd)
    roots = np.array([r for r in spline.roots(extrapolate=False)
                      if spline.derivative()(r) > 0])
    if len(roots) < 2:
        raise ValueError(f"{system.id}: fewer than two upward crossings of {item.coordinate} "
                         "within the scenario: no period to measure")
    periods = len(roots) - 1
    value = (roots[-1] - roots[0]) / periods
    # the crossing times move by the position error over the speed at the crossing
    speed = abs(np.interp(roots[[0, -1]], ref.t, qd)).min()
    return float(value), float(2 * ref.error_estimate[i] / speed / periods)


def compare_published(system: System, values: Mapping[str, float]) -> list[dict]:
    """One entry per published value: quantity, time, published_value, reference_value,
    relative_difference, reference_error (the reference's estimated error of the
    quantity), source, and whether the published value applies at these parameters."""
    out = []
    for item in system.published(system.symbols):
        scenario = (system.scenario(item.scenario) if item.scenario
                    else system.scenarios[0])
        entry = {"quantity": item.quantity, "time": item.time, "source": item.source,
                 "scenario": scenario.name}
        if not _applies(system, item, values, scenario):
            entry.update(applies=False, published_value=None, reference_value=None,
                         relative_difference=None, reference_error=None,
                         note="published for the source's parameters, not these")
            out.append(entry)
            continue
        published = float(item.value(values)) if callable(item.value) else float(item.value)
        if item.kind == "period":
            ref = reference(system, scenario, values, scenario.t_end / SAMPLES / 5)
            got, error = _period(system, item, ref)
        else:
            steps = SAMPLES
            ref = reference(system, scenario, values, item.time / steps, t_end=item.time)
            got, error = _state(system, item, values, scenario, ref, steps)
        entry.update(applies=True, published_value=published, reference_value=got,
                     relative_difference=abs(got - published) / abs(published)
                     if published else abs(got),
                     reference_error=error)
        out.append(entry)
    return out
