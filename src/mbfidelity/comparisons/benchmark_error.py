"""A benchmark's own error measure (`System.benchmark_error`): the error of an engine's
run as the benchmark's specification defines it, in the published quantities' own units,
next to the harness's relative measures.

A published quantity is a named point's component (its position or velocity, from the
engine's coordinates by the shared planar kinematics of comparisons/points.py, and from
the derivation for the reference) or a coordinate. The error is the largest absolute
difference from the reference over the run's samples ("run") or at its last instant
("end"), the largest over the quantities. The convergence study records it at every step
(or target accuracy) beside its own measure, so that the work-precision figure of a
benchmark row plots the benchmark's accuracy against CPU time; `default_step_error`
gives each engine's error and CPU time at the default step over the benchmark's full
run (the table a code reports on the problem).

A run that stops (the engine raises) or leaves the finite numbers (NaN) has no error:
it is reported as failed, with the reason the system declares for it (its
`<scenario>.completed` expected failure) where it declares one.
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from ..analytic.reference import reference
from ..simulators import get_backend
from ..systems import BenchmarkError, System, get_system
from ..systems.model import Mechanism
from .points import engine_points
from .runner import DEFAULT_DT, expectation_for


def components(dimension: int) -> list[str]:
    """The component names of a point's state of `dimension` position coordinates
    (x, y[, z], then their rates vx, vy[, vz])."""
    axes = list("xyz"[:dimension])
    return axes + [f"v{a}" for a in axes]


def quantity_series(system: System, measure: BenchmarkError, q: np.ndarray,
                    points: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Each published quantity along a run: a coordinate's column of `q`, or a named
    point's component of its state in `points` (name -> (N, 2 d))."""
    out = {}
    for name in measure.quantities:
        if name in system.coordinates:
            out[name] = np.asarray(q)[:, system.coordinates.index(name)]
            continue
        point, _, component = name.partition(".")
        if point not in points:
            raise ValueError(f"{system.id}: the benchmark quantity {name!r} is neither a "
                             f"coordinate nor a named point's component (points: "
                             f"{', '.join(points) or 'none'})")
        state = points[point]
        names = components(state.shape[1] // 2)
        if component not in names:
            raise ValueError(f"{system.id}: {name!r}: a point's component is one of "
                             f"{', '.join(names)}")
        out[name] = state[:, names.index(component)]
    return out


def benchmark_errors(system: System, values: Mapping[str, float], mech: Mechanism, ref,
                     q: np.ndarray, qd: np.ndarray, stride: int = 1) -> dict[str, float]:
    """The benchmark's error of a run with coordinates `q`, `qd` sampled every `stride`
    samples of the reference `ref` (from its first): {quantity: error, ..., "error": the
    largest}. NaN where the run did not reach the samples the measure needs (or left the
    finite numbers)."""
    measure = system.benchmark_error
    expected = len(ref.q[::stride])
    n = min(len(q), expected)
    got = quantity_series(system, measure, q[:n],
                          engine_points(system, values, mech, q[:n], qd[:n])
                          if system.points(system.symbols) else {})
    want = quantity_series(system, measure, ref.q[::stride][:n],
                           {k: v[::stride][:n] for k, v in (ref.points or {}).items()})
    out = {}
    for name in measure.quantities:
        difference = np.abs(got[name] - want[name])
        if n < expected or not np.all(np.isfinite(difference)):
            out[name] = float("nan")
        elif measure.at == "end":
            out[name] = float(difference[-1])
        else:
            out[name] = float(np.max(difference))
    out["error"] = float(max(out.values()))
    return out


def declared_failure(system: System, simulator: str, scenario: str) -> str:
    """The reason the system declares for the engine not completing the scenario (its
    `<scenario>.completed` expected failure), or ''."""
    exp = expectation_for(system, simulator, f"{scenario}.completed")
    return exp.reason if exp is not None and exp.kind == "xfail" else ""


def default_step_error(system_id: str, simulator: str, dt: float | None = None) -> dict:
    """One engine on one benchmark row at its default settings and the step `dt` (None:
    the row's own step, `System.step`, else DEFAULT_DT), over
    the benchmark's whole scenario: the benchmark's error (each quantity's and the
    largest), the CPU and wall seconds of the stepping, and the run's status ("completed",
    "diverged": non-finite states, "crashed": the engine raised, "unsupported"), with the
    system's declared reason (`declared`) for a run that does not complete, or for a
    completed run whose trajectory it declares an expected failure or unresolved at this
    step."""
    system = get_system(system_id)
    dt = (system.step or DEFAULT_DT) if dt is None else dt
    measure = system.benchmark_error
    if measure is None:
        raise ValueError(f"{system.id} declares no benchmark error measure")
    sc = system.scenario(measure.scenario) if measure.scenario else system.scenarios[0]
    values = system.parameter_values(scenario=sc)
    backend = get_backend(simulator)
    settings = backend.resolve_settings({})
    mech = system.numeric_mechanism(values)
    entry = {"system": system.id, "scenario": sc.name, "simulator": simulator,
             "engine_version": backend.version(), "dt": dt, "t_end": sc.t_end,
             "measure": measure.description, "unit": measure.unit,
             "error": float("nan"), "errors": {}, "cpu_time": None, "wall_time": None,
             "declared": declared_failure(system, simulator, sc.name), "message": ""}
    support = backend.support(mech)
    if not support.ok:
        return {**entry, "status": "unsupported", "message": support.reason}
    entry["scheme"] = backend.scheme(mech, settings).name
    ref = reference(system, sc, values, dt)
    try:
        run = backend.simulate(mech, ref.q[0], ref.qd[0], sc.t_end, dt, settings)
    except Exception as exc:  # an engine's failure is a result
        return {**entry, "status": "crashed",
                "message": " ".join(f"{type(exc).__name__}: {exc}".split())[:500]}
    errors = benchmark_errors(system, values, mech, ref, run.q, run.qd)
    finite = np.all(np.isfinite(run.q), axis=1) & np.all(np.isfinite(run.qd), axis=1)
    status, message = "completed", ""
    if not np.all(finite):
        k = int(np.argmin(finite))
        status, message = "diverged", f"non-finite state at t = {run.t[k]:.6g} s"
    if status == "completed":  # what the system declares about the run's trajectory
        exp = expectation_for(system, simulator, f"{sc.name}.trajectory_max")
        if exp is not None and exp.kind in ("xfail", "unresolved"):
            entry["declared"] = f"{exp.kind}: {exp.reason}"
    return {**entry, "status": status, "message": message, "error": errors.pop("error"),
            "errors": errors, "cpu_time": run.cpu_time, "wall_time": run.wall_time}
