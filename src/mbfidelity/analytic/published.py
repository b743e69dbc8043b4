"""Published values (a benchmark's solution, `System.published`) against the reference.

A state value is the published expression of the coordinates and velocities at its
instant, integrated there as the reference is (DOP853, or Radau for a stiff system, at
the reference's tolerance, its error estimated by the change at a 10x looser one, which
bounds positions and velocities alike, and at least the tolerance relative to the value);
an energy is the total T + V of that state;
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

from ..systems import Published, System, coordinate_symbols, get_system

from .numeric import numeric_model
from .reference import LOOSE, TIGHT, consistent_initial_state, integrate, reference

#: samples of the reference per scenario duration for a period measurement
SAMPLES = 10000


def _applies(system: System, item: Published, values: Mapping[str, float],
             scenario) -> bool:
    """A published number holds at the published parameters (the defaults with the
    scenario's values); a closed form (a function) at any."""
    if callable(item.value):
        return True
    # the catalog's defaults (a specialisation's defaults are its own structure's, a count
    # the user chose)
    published = get_system(system.catalog_id).parameter_values(scenario=scenario)
    return all(math.isclose(values[k], v, rel_tol=1e-12, abs_tol=0.0)
               for k, v in published.items())


def _state_at(system: System, scenario, values, time: float, tol: float):
    """(q, qd) at `time` from the scenario's consistent initial state: the reference's
    integrator (DOP853, or Radau for a stiff system) at `tol` straight to the instant (no
    sampling), dependent coordinates completed there."""
    model = numeric_model(system.id, values)
    if model.driven:
        raise ValueError(f"{system.id}: published states of driven mechanisms are not "
                         "compared")
    q0, qd0 = consistent_initial_state(system, scenario, values)
    ind = model.independent
    model._warm, model._tangent = np.array(q0, dtype=float), None
    y = integrate(model, np.concatenate([q0[ind], qd0[ind]]), np.array([0.0, time]), tol,
                  system.stiff)[-1]
    k = len(ind)
    if not model.constrained:
        return y[:k], y[k:]
    return model.state_from_independent(y[:k], y[k:])


def _at_instant(system: System, item: Published, values, scenario, solved: dict,
                read) -> tuple[float, float]:
    """`read(q, qd)` of the state at the item's instant, and its error estimate: its change
    from the reference's tolerance to a 10x looser one (as the reference's own estimate),
    and at least that tolerance relative to the value (the solve is not asked to be
    closer; where both solves already meet it, their change is round-off and says
    nothing smaller). `solved` keeps the states already integrated (one solve per instant
    and tolerance)."""
    out = []
    for tol in (TIGHT, LOOSE):
        key = (scenario.name, item.time, tol)
        if key not in solved:
            solved[key] = _state_at(system, scenario, values, item.time, tol)
        out.append(float(read(*solved[key])))
    return out[0], max(abs(out[1] - out[0]), TIGHT * abs(out[0]))


def _state(system: System, item: Published, values, scenario,
           solved: dict) -> tuple[float, float]:
    """The expression at the instant, and its error estimate (`_at_instant`)."""
    names = list(system.coordinates)
    symbols = [s for c in names for s in coordinate_symbols(c)[:2]]
    expr = sp.sympify(item.expression).xreplace(system.subs(values))
    law = sp.lambdify(symbols, expr, modules="math")
    return _at_instant(system, item, values, scenario, solved,
                       lambda q, qd: law(*[x for pair in zip(q, qd) for x in pair]))


def _energy(system: System, item: Published, values, scenario,
            solved: dict) -> tuple[float, float]:
    """T + V at the instant, and its error estimate as for a state value."""
    model = numeric_model(system.id, values)
    return _at_instant(system, item, values, scenario, solved,
                       lambda q, qd: model.energy(np.atleast_2d(q), np.atleast_2d(qd))[0])


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
    quantity), beyond_reference_error (the difference exceeds it: the published value's
    own error, or a different model; `note` gives the source's account), source, and
    whether the published value applies at these parameters."""
    out, solved = [], {}
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
        try:
            published = (float(item.value(values)) if callable(item.value)
                         else float(item.value))
        except (ValueError, ArithmeticError) as exc:  # a closed form outside its domain
            entry.update(applies=False, published_value=None, reference_value=None,
                         relative_difference=None, reference_error=None, note=str(exc))
            out.append(entry)
            continue
        if item.kind == "period":
            ref = reference(system, scenario, values, scenario.t_end / SAMPLES)
            got, error = _period(system, item, ref)
        elif item.kind == "energy":
            got, error = _energy(system, item, values, scenario, solved)
        else:
            got, error = _state(system, item, values, scenario, solved)
        entry.update(applies=True, published_value=published, reference_value=got,
                     relative_difference=abs(got - published) / abs(published)
                     if published else abs(got),
                     reference_error=error,
                     beyond_reference_error=bool(abs(got - published) > error))
        if item.note:
            entry["note"] = item.note
        out.append(entry)
    return out
