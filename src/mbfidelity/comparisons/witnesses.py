"""The simulators as witnesses of the monograph's misprints: each engine runs the
mechanism, and its motion (or its own linearization) is compared with the derived model
and with the model that has the printed formula in place (the printed models are built in
`analytic/errata.py`); an engine sides with the model it is closer to.

- Equations of motion without multipliers (`_trajectory_witness`): the engines on the
  largest-amplitude scenario against the printed equations integrated as printed; where
  those are singular on the motion, each engine's motion is put into both sets of
  equations instead (`_residual_witness`).
- Equations of motion with multipliers (`_multiplier_witness`; the system row and every
  row of it cite the same one): each engine's trajectory on the first
  `MULTIPLIER_WITNESS_SECONDS` of the largest scenario against the derived one and against
  the printed equations integrated on the derived constraint manifold
  (`printed_multiplier_trajectory`); modes too where the engines linearize, against the
  printed system's modes at the derived equilibrium (`printed_model_frequencies`).
- Matrices, energies and frequencies (`_modal_witness`): each engine's own linearization
  against the modes of the derived model and of the model with the printed formula.
"""
from __future__ import annotations

import warnings
from functools import lru_cache
from typing import Iterable

import numpy as np
import sympy as sp

from ..analytic.errata import (Erratum, SingularPrintedModel, _equilibrium_at, _num,
                               _one_equation_each, _term_scale, _with_relations, errata,
                               printed_model_frequencies, printed_model_trajectory,
                               printed_multiplier_trajectory)
from ..analytic.modes import modes_from_eigenvalues
from ..analytic.numeric import numeric_model
from ..analytic.reference import reference
from ..simulators import all_backends
from ..systems import PrintedFormula, System, coordinate_symbols, get_system
from ..systems.model import TIME

#: the witness of printed equations with multipliers integrates the printed model on the
#: true manifold (Newton completion at every step, like the reference): the first seconds
#: of the scenario keep `mbfidelity errata` quick, and a misprinted inertia separates the
#: printed motion from the derived one within a fraction of a second
MULTIPLIER_WITNESS_SECONDS = 3.0


def _witness_engines(mech):
    """(id, backend) of every installed engine that can express the mechanism."""
    for sim, backend in all_backends().items():
        if backend.available()[0] and backend.support(mech).ok:
            yield sim, backend


@lru_cache(maxsize=None)
def _trajectory_witness(system_id: str) -> dict:
    """Engines on the largest-amplitude scenario, against the derived model and against
    the printed equations of motion integrated as printed (independent coordinates)."""
    system = get_system(system_id)
    full = [pf for pf in system.printed(system.symbols) if pf.kind == "eom"
            and not pf.multipliers]
    if not full:
        return {}
    scenario = system.scenarios[-1]
    values = system.parameter_values(scenario=scenario)
    dt = 1e-3
    ref = reference(system, scenario, values, dt)
    ind = numeric_model(system.id, values).independent
    printed_q = printed_model_trajectory(system, full[0], values, ref.q[0], ref.qd[0], ref.t)
    if printed_q is None:
        return _residual_witness(system, full[0], scenario, values, dt)
    mech = system.numeric_mechanism(values)
    out = {}
    for sim, backend in _witness_engines(mech):
        run = backend.simulate(mech, ref.q[0], ref.qd[0], scenario.t_end, dt)
        n = min(len(run.t), len(ref.t))
        to_derived = float(np.max(np.abs(run.q[:n, ind] - ref.q[:n, ind])))
        to_printed = float(np.max(np.abs(run.q[:n, ind] - printed_q[:n])))
        side = "derivation" if to_derived < to_printed else "printed"
        out[sim] = {"scenario": scenario.name, "max_error_to_derived": to_derived,
                    "max_error_to_printed": to_printed,
                    "verdict": f"sides with the {side} (max |dq| {to_derived:.2e} to the derived "
                               f"model, {to_printed:.2e} to the printed one)"}
    return out


#: every this many samples of an engine's run enter the residual witness
RESIDUAL_STRIDE = 10


def _residual_witness(system: System, pf: PrintedFormula, scenario, values, dt: float) -> dict:
    """For printed equations that cannot be integrated (singular on the motion): each
    engine's motion, with accelerations by central differences of its velocities (error
    (w h)^2, far below the misprints' O(1e-2..1)), put into the derived equations
    (relative acceleration error) and into each printed row (residual over the sum of
    its terms' magnitudes). An engine sides with the equations its motion satisfies."""
    ref = reference(system, scenario, values, dt)
    model = numeric_model(system.id, values)
    ind = model.independent
    syms = [s for c in system.coordinates for s in coordinate_symbols(c)]
    rows = [sp.sympify(r).xreplace(system.subs(values)) for r in pf.expr]
    mech = system.numeric_mechanism(values)
    out = {}
    for sim, backend in _witness_engines(mech):
        run = backend.simulate(mech, ref.q[0], ref.qd[0], scenario.t_end, dt)
        qdd = np.gradient(run.qd, dt, axis=0)
        picks = range(1, len(run.t) - 1, RESIDUAL_STRIDE)
        derived, printed = 0.0, np.zeros(len(rows))
        acc_scale = max(float(np.max(np.abs(qdd[:, ind]))), 1e-300)
        for k in picks:
            q, qd, t = run.q[k], run.qd[k], float(run.t[k])
            a = model.acceleration(q, qd, t)
            derived = max(derived, float(np.max(np.abs(a[ind] - qdd[k, ind]))) / acc_scale)
            env = dict(zip(syms, [v for trio in zip(q, qd, qdd[k]) for v in trio]))
            env[TIME] = t
            printed = np.maximum(printed, [abs(_num(r, env)) / _term_scale(r, env)
                                           for r in rows])
        side = "derivation" if derived < 0.1 * float(np.min(printed)) else "printed"
        out[sim] = {"scenario": scenario.name, "sides_with": side,
                    "derived_relative_residual": derived,
                    "printed_relative_residuals": printed.tolist(),
                    "verdict": f"sides with the {side} (its motion satisfies the derived "
                               f"equations to {derived:.1e}; the printed rows leave "
                               f"{', '.join(f'{x:.2g}' for x in printed)}; the printed "
                               "equations cannot be integrated: singular on the motion)"}
    return out


def _modal_witness(system: System, pf: PrintedFormula) -> dict:
    """Each engine's own linearization at the equilibrium, against the modes of the
    derived model and of the model with the printed formula in place."""
    values = _with_relations(system, system.parameter_values(), pf)
    printed = printed_model_frequencies(system, pf, values)
    if printed is None:
        return {}
    eq = _equilibrium_at(system, values, pf)
    derived = np.sort([abs(m.eigenvalue) for m in eq.modes])
    if np.allclose(printed, derived, rtol=1e-9):
        return {}  # the misprint does not change the modes: no modal witness
    mech = system.numeric_mechanism(values).without_time_loads()
    out = {}
    for sim, backend in _witness_engines(mech):
        lin = backend.linearize(mech, eq.q)
        if lin is None:
            continue
        got = np.sort([abs(m.eigenvalue) for m in modes_from_eigenvalues(lin.eigenvalues)])
        k = min(len(got), len(derived), len(printed))
        to_derived = float(np.max(np.abs(got[:k] - derived[:k]) / derived[:k]))
        to_printed = float(np.max(np.abs(got[:k] - printed[:k]) / printed[:k]))
        side = "derivation" if to_derived < to_printed else "printed"
        out[sim] = {"max_error_to_derived": to_derived, "max_error_to_printed": to_printed,
                    "verdict": f"sides with the {side} (modes {to_derived:.1e} from the derived "
                               f"model, {to_printed:.1e} from the printed one)"}
    return out


def _constrained_trajectory_witness(system: System, pf: PrintedFormula) -> tuple[dict, str]:
    """({engine: distances}, note): engines on the first `MULTIPLIER_WITNESS_SECONDS` of
    the largest-amplitude scenario against the derived model and against the printed
    equations with multipliers integrated on the derived manifold. The note says why
    there is no trajectory witness (singular printed model), else it is empty."""
    scenario = system.scenarios[-1]
    values = system.parameter_values(scenario=scenario)
    dt = 1e-3
    t_end = min(scenario.t_end, MULTIPLIER_WITNESS_SECONDS)
    ref = reference(system, scenario, values, dt, t_end=t_end)
    try:
        printed_q, drift = printed_multiplier_trajectory(system, pf, values, ref.q[0],
                                                         ref.qd[0], ref.t)
    except SingularPrintedModel as err:
        return {}, f"no trajectory witness: {err}"
    ind = numeric_model(system.id, values).independent
    mech = system.numeric_mechanism(values)
    out = {}
    for sim, backend in _witness_engines(mech):
        run = backend.simulate(mech, ref.q[0], ref.qd[0], t_end, dt)
        n = min(len(run.t), len(ref.t))
        to_derived = float(np.max(np.abs(run.q[:n, ind] - ref.q[:n, ind])))
        to_printed = float(np.max(np.abs(run.q[:n, ind] - printed_q[:n, ind])))
        out[sim] = {"scenario": scenario.name, "t_end": t_end,
                    "max_error_to_derived": to_derived, "max_error_to_printed": to_printed,
                    "derived_to_printed": float(np.max(np.abs(ref.q[:n, ind]
                                                              - printed_q[:n, ind]))),
                    "printed_constraint_drift": drift}
    return out, ""


@lru_cache(maxsize=None)
def _multiplier_witness(system_id: str, label: str) -> dict:
    """The engines on printed equations with multipliers (module docstring): trajectories
    and, where the engine linearizes, modes; one entry per engine, its verdict saying which
    model it sides with (both measures when they agree, "split" when they do not)."""
    system = get_system(system_id)
    (pf,) = [pf for pf in system.printed(system.symbols) if pf.label == label]
    trajectories, note = _constrained_trajectory_witness(system, pf)
    modes = _modal_witness(system, pf)
    out = {}
    for sim in list(trajectories) + [s for s in modes if s not in trajectories]:
        entry, sides, said = {}, [], []
        if sim in trajectories:
            w = trajectories[sim]
            entry.update(w)
            sides.append("derivation" if w["max_error_to_derived"] < w["max_error_to_printed"]
                         else "printed")
            said.append(f"trajectory: max |dq| {w['max_error_to_derived']:.2e} to the derived "
                        f"model, {w['max_error_to_printed']:.2e} to the printed one "
                        f"({w['scenario']} scenario, {w['t_end']:g} s)")
        elif note:
            said.append(note)
        if sim in modes:
            w = modes[sim]
            entry.update(modes_error_to_derived=w["max_error_to_derived"],
                         modes_error_to_printed=w["max_error_to_printed"])
            sides.append("derivation" if w["max_error_to_derived"] < w["max_error_to_printed"]
                         else "printed")
            said.append(f"modes: {w['max_error_to_derived']:.1e} from the derived model, "
                        f"{w['max_error_to_printed']:.1e} from the printed one")
        if len(set(sides)) == 1:
            entry["sides_with"] = sides[0]
            entry["verdict"] = f"sides with the {sides[0]} ({'; '.join(said)})"
        else:
            entry["sides_with"] = "split"
            entry["verdict"] = "split: " + "; ".join(
                f"{x} sides with the {y}" for x, y in zip(said, sides))
        out[sim] = entry
    return out


def _multiplier_formula(system: System, label: str | None) -> PrintedFormula | None:
    """The printed "eom" with multipliers an erratum label refers to (its system row or
    one of its rows); the first one when label is None."""
    for pf in system.printed(system.symbols):
        if pf.kind != "eom" or not pf.multipliers:
            continue
        if label is None or label == pf.label or label.startswith(
                (f"{pf.label} (", f"{pf.label}, row ")):
            return pf
    return None


def witness(system: System, erratum: Erratum | None = None) -> dict:
    """The engines' verdict on a misprint: trajectories for equations of motion (with
    multipliers: on the derived manifold, and modes), their own linearizations for
    matrices, energies and frequencies."""
    # a printed model may divide by zero on the motion (then it has no trajectory
    # witness, said in the result): numpy's warnings would only repeat that on stderr
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return _witness(system, erratum)


def _witness(system: System, erratum: Erratum | None) -> dict:
    if erratum is None or erratum.kind == "eom":
        pf = _multiplier_formula(system, None if erratum is None else erratum.label)
        if pf is not None and (erratum is not None or not _trajectory_witness(system.id)):
            return _multiplier_witness(system.id, pf.label)
        return _trajectory_witness(system.id)
    for pf in _one_equation_each(system.printed(system.symbols)):
        if pf.label == erratum.label:
            return _modal_witness(system, pf)
    return {}


def witnessed_errata(systems: Iterable[System], witnesses: bool = True) -> list[dict]:
    """Every printed formula of the systems against the derivation (`analytic.errata`),
    each misprint with the engines' verdicts when `witnesses`, as plain dicts."""
    entries = []
    for system in systems:
        for e in errata(system):
            if witnesses and e.verdict != "agrees":
                e.witnesses = witness(system, e)
            entries.append(e.as_dict())
    return entries
