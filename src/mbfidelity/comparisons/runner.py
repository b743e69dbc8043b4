"""One comparison (system x simulator x settings) and the runner over the matrix."""
from __future__ import annotations

import datetime
import fnmatch
import math
import platform
import subprocess
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from types import SimpleNamespace
from typing import Iterable, Mapping

import numpy as np

from .. import __version__
from ..analytic.linear import (find_equilibria, operating_equilibrium, unexcited_values,
                               wrap_angles)
from ..analytic.modes import ZERO_REAL_PART, companion_matrix, oscillatory_instability
from ..analytic.numeric import contact_forces, numeric_model
from ..analytic.reference import reference, sensitivity
from ..analytic.steady_state import (excitation_frequencies, observable_functions,
                                     steady_state)
from ..simulators import get_backend
from ..simulators.base import expected_failures
from ..systems import Expectation, System, get_system
from ..systems.model import inertia_matrix
from . import budget, checks, metrics, tolerances
from .isolation import WorkerCrashed, WorkerTimedOut, isolated
from .points import judge_points
from .verdict import PASS
from .verdict import verdict as verdict_of

DEFAULT_DT = 1e-3


@dataclass
class Metric:
    name: str
    value: float
    tolerance: float
    passed: bool
    #: pass | fail | xfail | xpass | unresolved | unsupported | measured (variants)
    status: str
    reason: str = ""
    unit: str = "relative"
    #: the compared quantities themselves (e.g. reference and engine frequency in Hz)
    detail: dict = field(default_factory=dict)
    #: an unresolved metric the system declares (it does not fail the comparison)
    expected: bool = False
    #: which rule set the gate: "a_priori" (tolerances.py's bounds), "refinement" (the
    #: engine's own halvings, tolerances.py "A posteriori") or "refinement_limit" (the
    #: same, the engine's limit judged on its finest run: its bound at h is above the
    #: ceiling)
    rule: str = "a_priori"
    #: the refinement's numbers (observed and declared order, predicted error, ...)
    refinement: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        d = {"name": self.name, "value": self.value, "tolerance": self.tolerance,
             "passed": self.passed, "status": self.status, "unit": self.unit,
             "rule": self.rule}
        if self.refinement:
            d["refinement"] = self.refinement
        if self.reason:
            d["reason"] = self.reason
        if self.detail:
            d["detail"] = self.detail
        if self.status == "unresolved":
            d["expected"] = self.expected
        return d


@dataclass
class Comparison:
    system: str
    simulator: str
    engine_version: str
    settings: dict
    parameters: dict
    dt: float
    metrics: list[Metric] = field(default_factory=list)
    supported: bool = True
    reason: str = ""
    wall_time: float = 0.0
    simulated_time: float = 0.0
    #: sampled series for the report: scenario -> dict of arrays
    series: dict = field(default_factory=dict)
    #: name of the system's variant the engine built ("" for the description itself)
    variant: str = ""
    #: runs that did not complete: {"scenario", "outcome" (diverged | crashed |
    #: timed_out), "t_reached", "message"}; each also fails a `<scenario>.completed` metric
    incidents: list = field(default_factory=list)
    #: engine time (s) of the refinement runs (part of wall_time)
    refinement_wall_time: float = 0.0

    @property
    def outcome(self) -> str:
        """completed, or the first incident's outcome."""
        return self.incidents[0]["outcome"] if self.incidents else "completed"

    @property
    def passed(self) -> bool:
        """Supported and every metric holds (`verdict.verdict` is "pass")."""
        return verdict_of(self) == PASS

    @property
    def verdict(self) -> str:
        """pass | fail | unsupported (`comparisons/verdict.py`)."""
        return verdict_of(self)

    def as_dict(self) -> dict:
        return {
            "system": self.system, "simulator": self.simulator,
            "engine_version": self.engine_version, "settings": self.settings,
            "parameters": self.parameters, "dt": self.dt, "supported": self.supported,
            "reason": self.reason, "metrics": [m.as_dict() for m in self.metrics],
            "passed": self.passed, "wall_time_s": self.wall_time,
            "simulated_time_s": self.simulated_time, "variant": self.variant,
            "outcome": self.outcome, "incidents": self.incidents,
            "verdict": self.verdict,
            "refinement_wall_time_s": self.refinement_wall_time,
        }


#: the parameter values of the comparison under way (`compare`), at which a declaration's
#: `when` is evaluated; outside a comparison, the system's defaults
_COMPARED_VALUES: ContextVar[Mapping[str, float] | None] = ContextVar("compared_values",
                                                                      default=None)


#: per parameter, the factor applied to its value in the engine's build only (a model error
#: injected by the power study, comparisons/power.py); the reference keeps the true values
_ENGINE_SCALE: ContextVar[Mapping[str, float]] = ContextVar("engine_scale", default={})


#: metric name -> that metric of a baseline comparison (`Metric.as_dict`): the gates a
#: comparison's a-priori unresolved metrics are judged by instead of the engine's own
#: refinement (`compare(held_gates=)`: the power study's mutated runs, comparisons/power.py)
_HELD_GATES: ContextVar[Mapping[str, dict] | None] = ContextVar("held_gates", default=None)


@contextmanager
def _context(variable: ContextVar, value):
    token = variable.set(value)
    try:
        yield
    finally:
        variable.reset(token)


def _engine_scaled(scale: Mapping[str, float]):
    return _context(_ENGINE_SCALE, dict(scale))


def _engine_mechanism(system: System, values: Mapping[str, float], variant=None):
    scale = _ENGINE_SCALE.get()
    return system.numeric_mechanism(
        {k: v * scale.get(k, 1.0) for k, v in values.items()} if scale else values, variant)


def _declarations_judged_at(values: Mapping[str, float]):
    return _context(_COMPARED_VALUES, values)


def expectations(system: System, simulator: str) -> tuple[tuple[Expectation, ...], ...]:
    """The declarations that judge `simulator` on `system`, in matching order: the system's
    own (mechanism-specific), each one declaration, then those the backend's declared
    soft or substitute expressions of the system's elements imply
    (`simulators.base.expected_failures`), each a group of patterns declared together."""
    values = _COMPARED_VALUES.get()
    if values is None:
        values = system.parameter_values()
    return tuple((e,) for e in system.expectations
                 if _applies(e, tuple(sorted(system.structure.items())),
                             tuple(sorted(values.items())))) + _declared(system.id, simulator)


@lru_cache(maxsize=4096)
def _applies(e: Expectation, structure: tuple, values: tuple) -> bool:
    # parsed once per condition and parameter values, not once per metric judged
    return e.applies(dict(structure), dict(values))


@lru_cache(maxsize=None)
def _declared(system_id: str, simulator: str) -> tuple[tuple[Expectation, ...], ...]:
    system = get_system(system_id)
    backend = get_backend(simulator)
    mech = system.numeric_mechanism(system.parameter_values())
    return expected_failures(backend, mech) if backend.support(mech).ok else ()


def expectation_for(system: System, simulator: str, metric: str):
    for group in expectations(system, simulator):
        for e in group:
            if fnmatch.fnmatch(simulator, e.simulator) and fnmatch.fnmatch(metric, e.metric):
                return e
    return None


def _judge(system: System, simulator: str, name: str, value: float,
           tol: "float | tolerances.Gate", unit: str = "relative") -> Metric:
    """Pass or fail against the gate; `unresolved` where the gate's bound says nothing
    (tolerances: range of w h, ceilings), which fails the comparison unless the system
    declares the metric (an "unresolved" or "xfail" expectation)."""
    gate = tol if isinstance(tol, tolerances.Gate) else tolerances.Gate(tol)
    exp = expectation_for(system, simulator, name)
    declared = exp is not None and exp.kind in ("xfail", "unresolved")
    if gate.unresolved and not np.isfinite(value) and exp is not None and exp.kind == "xfail":
        # a quantity the engine does not give fails whatever the gate's width, as declared
        return Metric(name, value, gate.tolerance, False, "xfail", exp.reason, unit)
    if gate.unresolved:
        reason = gate.unresolved + (f"; declared: {exp.reason}" if declared else "")
        return Metric(name, value, gate.tolerance, False, "unresolved", reason, unit,
                      expected=declared)
    ok = bool(np.isfinite(value) and value <= gate.tolerance)
    if exp is not None and exp.kind == "xfail":
        return Metric(name, value, gate.tolerance, ok, "pass" if ok else "xfail", exp.reason,
                      unit)
    return Metric(name, value, gate.tolerance, ok, "pass" if ok else "fail", "", unit)


#: what an unexpected pass says when the comparison is not the one declarations describe
NOT_DECLARED_RUN = ("declared an expected failure for the scenario's own duration at the "
                    "default step; this comparison ran another, where it did not occur")


def _strict_expectations(system: System, result: "Comparison", strict: bool = True) -> None:
    """An expected failure covers the metrics its patterns match (those it is the first
    match for) and is met when at least one of them does not pass (an "unresolved"
    declaration: when one of them is unresolved); otherwise its passes are unexpected
    (strict): the problem was fixed and the declaration must go. Declarations describe
    the scenarios as declared (their duration, the default step): in a comparison with
    another duration or step (`strict` false) a declared failure that does not occur is
    a pass, with a note saying so."""
    for group in expectations(system, result.simulator):
        mine = [e for e in group if e.kind in ("xfail", "unresolved")
                and fnmatch.fnmatch(result.simulator, e.simulator)]
        covered = [m for m in result.metrics
                   if any(expectation_for(system, result.simulator, m.name) is e for e in mine)]
        if any(e.kind == "unresolved" for e in mine):
            met = any(m.status == "unresolved" for m in covered)
        else:
            met = not all(m.passed for m in covered)
        if covered and not met:
            for m in covered:
                if m.passed and strict:
                    m.status = "xpass"
                elif m.passed:
                    m.reason = NOT_DECLARED_RUN


def characteristic_frequency(eq_modes, ref_q, ref_qd, q_eq) -> float:
    """Fastest angular frequency of the motion (rad/s): see `tolerances`."""
    w_lin = max((abs(m.eigenvalue) for m in eq_modes), default=0.0)
    amp = metrics.amplitude(ref_q, q_eq)
    w_traj = float(np.max(np.max(np.abs(ref_qd), axis=0) / amp))
    return max(w_lin, w_traj)


def _coordinate_scales(system: System, q_eq: np.ndarray) -> np.ndarray:
    return np.array([1.0 if system.mechanism.angular(c) else max(abs(q), 0.1)
                     for c, q in zip(system.coordinates, q_eq)])


def own_step(system_id: str, dt: float | None = None) -> float:
    """`dt`, or where None the system's own comparison step (`System.step`: a stiff row's),
    else DEFAULT_DT."""
    return dt if dt is not None else (get_system(system_id).step or DEFAULT_DT)


def compare(system_id: str, simulator: str, params: Mapping[str, float] | None = None,
            dt: float | None = None, t_end: float | None = None,
            settings: Mapping | None = None, scenarios: Iterable[str] | None = None,
            keep_series: bool = False, variant: str | None = None,
            engine_scale: Mapping[str, float] | None = None,
            held_gates: Mapping[str, dict] | None = None) -> Comparison:
    """One system on one engine, every scenario and the frequency checks. With `variant`
    the engine builds the system's named variant (its settings first, then `settings`);
    the metrics are then measurements of the variant's own error (status "measured"
    where the description's gate is not met). `engine_scale` multiplies parameters in the
    engine's build only (an injected model error; the reference and gates keep the true
    values). `held_gates` (name -> a baseline comparison's metric, `Metric.as_dict`):
    the metrics unresolved a priori are judged by the baseline's refinement gates instead
    of the engine's own refinement, and where the baseline judged the engine's limit, on
    one run at the baseline's finest step (`_judge_held`). `dt` None: the system's own
    step (`System.step`), else DEFAULT_DT."""
    system = get_system(system_id)
    default_dt = own_step(system_id)
    dt = default_dt if dt is None else dt
    chosen_variant = system.variant(variant) if variant else None
    base_values = system.parameter_values(params)
    with _declarations_judged_at(base_values), _engine_scaled(engine_scale or {}), \
            _context(_HELD_GATES, held_gates):
        backend = get_backend(simulator)
        system = system.with_structure(base_values)  # built for the user's number of elements
        ok, why = backend.available()
        if not ok:
            return Comparison(system.id, simulator, "", {}, base_values, dt, supported=False,
                              reason=f"engine not available: {why}", variant=variant or "")
        if chosen_variant is not None and simulator not in chosen_variant.settings:
            return Comparison(system.id, simulator, backend.version(), {}, base_values, dt,
                              supported=False, variant=variant,
                              reason=f"variant {variant!r} is built in "
                                     f"{', '.join(chosen_variant.settings)} only")
        wanted = {**(chosen_variant.settings[simulator] if chosen_variant else {}),
                  **(settings or {})}
        merged = backend.resolve_settings(wanted)
        result = Comparison(system.id, simulator, backend.version(), merged, base_values, dt,
                            variant=variant or "")
        for name in scenarios or ():
            if name not in {sc.name for sc in system.scenarios} | {
                    sc.name for sc, _ in _contained_near_equilibrium(system, base_values)}:
                raise ValueError(f"{system.id} has no scenario {name!r}; scenarios: "
                                 f"{', '.join(sc.name for sc in system.scenarios)}")
        # declarations describe the scenarios as declared, at the default step
        strict = t_end is None and dt == default_dt
        # from here on every stage's failure is an incident of this comparison
        with contained(result, "*", "description") as stage:
            mech = _engine_mechanism(system, base_values, variant)
        if stage.failed:
            return _finished(system, result, chosen_variant, strict)
        support = backend.support(mech)
        unsupported = expectation_for(system, simulator, "*")
        if not support.ok or (unsupported is not None and unsupported.kind == "unsupported"):
            result.supported = False
            result.reason = support.reason if not support.ok else unsupported.reason
            return result
        _refuse_unstable_step(system, backend, mech, merged, base_values, dt)
        budget.refuse_over_budget(comparison_cost(system, base_values, dt, t_end, scenarios))
        every = [(sc, None) for sc in system.scenarios]
        with contained(result, "*", "equilibrium"):
            every += near_equilibrium_scenarios(system, base_values)
        by_name = {sc.name: (sc, eq) for sc, eq in every}
        for name in scenarios or by_name:
            sc, eq = by_name[name]
            with contained(result, name, "comparison"):
                _compare_scenario(system, backend, sc, params, dt, t_end, merged, result,
                                  keep_series, eq, variant)
        with contained(result, "frequency", "comparison"):
            _compare_frequencies(system, backend, base_values, dt, t_end, merged, result,
                                 keep_series, variant)
        if mech.spatial:
            with contained(result, "inertia", "engine build"):
                _compare_stored_inertia(system, backend, mech, merged, result)
        return _finished(system, result, chosen_variant, strict)


def _contained_near_equilibrium(system: System, values: Mapping[str, float]) -> list:
    try:
        return near_equilibrium_scenarios(system, values)
    except Exception:  # recorded as an incident by the comparison itself
        return []


def _finished(system: System, result: Comparison, chosen_variant, strict: bool) -> Comparison:
    """The strict expectations of the description, or a variant's own measurements."""
    if chosen_variant is None:
        _strict_expectations(system, result, strict)
    else:
        for m in result.metrics:
            if m.status != "pass":
                m.status, m.reason = "measured", chosen_variant.reason
    return result


#: a stored tensor is the description's up to the rounding of one diagonalisation
INERTIA_TOLERANCE = 1e-12


def _compare_stored_inertia(system, backend, mech, settings, result) -> None:
    """Each body's central tensor as the engine stored it (principal moments and axes,
    read back from the built model) against the description's: the largest entry of the
    difference, relative to the largest entry of the tensor. The detail lists both."""
    stored = backend.stored_inertia(mech, settings)
    for body in mech.bodies:
        if body.name not in stored:
            continue
        moments, axes = stored[body.name]
        tensor = np.array(inertia_matrix(body).tolist(), dtype=float)
        rebuilt = axes @ np.diag(moments) @ axes.T
        scale = max(float(np.max(np.abs(tensor))), 1e-300)
        value = float(np.max(np.abs(rebuilt - tensor))) / scale
        metric = _judge(system, backend.id, f"inertia.{body.name}", value, INERTIA_TOLERANCE)
        own_moments, own_axes = np.linalg.eigh(tensor)
        metric.detail = {"engine_principal_moments": [float(v) for v in moments],
                         "engine_principal_axes": axes.T.tolist(),
                         "description_principal_moments": [float(v) for v in own_moments],
                         "description_principal_axes": own_axes.T.tolist()}
        result.metrics.append(metric)


class UnstableStep(ValueError):
    """The engine's scheme, with these settings, cannot be stable at this step on the
    mechanism's fastest mode (`tolerances.stability_refusal`): bad input where a user chose
    the settings and the step, a property of the engine where its own defaults did (the
    out-of-the-box study records it as that default's run)."""


def _refuse_unstable_step(system, backend, mech, settings, values, dt: float) -> None:
    """`UnstableStep` (a ValueError, one line) when the engine's scheme cannot be stable at this step on the
    fastest mode of the operating point's linearization (before any reference solve,
    which a stiff system would make endless). Where the equilibrium cannot be found the
    comparison's own stages record why."""
    scheme = backend.scheme(mech, settings)
    if scheme is None or scheme.stability_limit is None:
        return
    try:
        eq = operating_equilibrium(system, values)
    except Exception:
        return
    w = float(np.max(np.abs(eq.eigenvalues))) if len(eq.eigenvalues) else 0.0
    refusal = tolerances.stability_refusal(w, dt, f"{backend.id}'s {scheme.name}",
                                           scheme.stability_limit)
    if refusal:
        raise UnstableStep(refusal)


def isolated_compare(system_id: str, simulator: str,
                     params: Mapping[str, float] | None = None, *, timeout: float | None = None,
                     **kwargs) -> Comparison:
    """`compare` in a worker process (comparisons/isolation.py): a worker that dies or
    exceeds `timeout` seconds gives a failed comparison with the incident (crashed,
    timed_out) instead of taking the caller down; a ValueError or KeyError (bad input) is
    raised; any other exception that escaped the comparison's stages (a memory limit hit
    outside them) is a failed comparison too."""
    try:
        return isolated(compare, system_id, simulator, params, timeout=timeout, **kwargs)
    except (ValueError, KeyError):
        raise
    except Exception as exc:
        outcome = ("timed_out" if isinstance(exc, WorkerTimedOut) else
                   "crashed" if isinstance(exc, WorkerCrashed) else "failed")
        return failed_comparison(system_id, simulator, params, kwargs.get("dt", DEFAULT_DT),
                                 kwargs.get("variant") or "", "worker", exc, outcome)


def failed_comparison(system_id: str, simulator: str, params: Mapping[str, float] | None,
                      dt: float, variant: str, stage: str, exc: BaseException,
                      outcome: str = "failed") -> Comparison:
    """A comparison that could not be made at all: its incident (see `record_incident`)
    and a failed `*.<stage>` metric."""
    try:
        version = get_backend(simulator).version()
    except Exception:  # an engine that cannot even say its version
        version = ""
    try:
        values = get_system(system_id).parameter_values(params)
    except Exception:
        values = dict(params or {})
    result = Comparison(system_id, simulator, version, {}, values, dt, variant=variant)
    record_incident(result, "*", stage, exc, outcome)
    return result


#: start of the generated checks near the other stable equilibria: this far from the
#: equilibrium on each independent coordinate (rad, or relative to the coordinate scale)
NEAR_EQUILIBRIUM_OFFSET = 0.05
NEAR_EQUILIBRIUM_T_END = 5.0


def near_equilibrium_scenarios(system: System, values: Mapping[str, float]) -> list:
    """See `_near_equilibrium_scenarios`; computed once per system and parameter set (every
    engine of a system is compared on the same ones)."""
    return list(_near_equilibrium_cached(system.id, tuple(sorted(values.items()))))


@lru_cache(maxsize=64)
def _near_equilibrium_cached(system_id: str, items: tuple) -> tuple:
    return tuple(_near_equilibrium_scenarios(get_system(system_id), dict(items)))


def _near_equilibrium_scenarios(system: System, values: Mapping[str, float]) -> list:
    """A trajectory check started near every stable equilibrium other than the operating
    point (the monograph studies one; the others are where a user's mechanism may rest):
    the independent coordinates NEAR_EQUILIBRIUM_OFFSET away from it, from rest, for
    NEAR_EQUILIBRIUM_T_END s (or the system's `near_equilibrium_t_end`). Named
    eq<k>_small after the equilibrium's index in `analyze`. Returns (scenario,
    equilibrium) pairs."""
    from ..systems.model import Scenario

    if system.mechanism.prescribed:
        return []  # a driven system is tested along its driven motion only
    op = operating_equilibrium(system, values)
    model = numeric_model(system.id, values)
    checks = ("trajectory", "constraint_force") if system.mechanism.constraints else (
        "trajectory",)
    out = []
    for k, eq in enumerate(find_equilibria(system, values)):
        if not eq.stable or np.allclose(wrap_angles(system, eq.q, op.q), op.q, atol=1e-6):
            continue
        if not model.on_branch(eq.q):
            continue  # an assembly on another branch than the one the description names
        q0 = {}
        for i, c in enumerate(system.coordinates):
            step = NEAR_EQUILIBRIUM_OFFSET * (
                1.0 if system.mechanism.angular(c) else max(abs(eq.q[i]), 0.1))
            q0[c] = float(eq.q[i] + (step if i in model.independent else 0.0))
        pretty = ", ".join(f"{c} = {x:.4g}" for c, x in zip(system.coordinates, eq.q))
        t_end = system.near_equilibrium_t_end or NEAR_EQUILIBRIUM_T_END
        out.append((Scenario(f"eq{k}_small", q0, t_end=t_end, checks=checks,
                             description=f"near the stable equilibrium ({pretty}), "
                                         f"{NEAR_EQUILIBRIUM_OFFSET} off, from rest"), eq))
    return out


def _compare_scenario(system, backend, sc, params, dt, t_end, settings, result, keep_series,
                      eq=None, variant=None):
    values = system.parameter_values(params, scenario=sc)
    mech = _engine_mechanism(system, values, variant)
    T = sc.t_end if t_end is None else t_end
    with contained(result, sc.name, "reference") as stage:
        ref = reference(system, sc, values, dt, T)
    if stage.failed:
        return
    q0, qd0 = ref.q[0], ref.qd[0]
    joints = system.reaction_joints if "reaction" in sc.checks else ()
    contacts = system.contacts(system.symbols) if "constraint_force" in sc.checks else ()
    contact_joints = tuple(c.target for c in contacts
                           if c.kind == "reaction" and c.target not in joints)
    name = sc.name
    run = _guarded_run(backend, result, name, T, mech, q0, qd0, T, dt, settings,
                       joints + contact_joints)
    if run is None:
        return
    result.wall_time += run.wall_time
    result.simulated_time += T
    if eq is None:
        with contained(result, sc.name, "equilibrium") as stage:
            eq = operating_equilibrium(system, values)
        if stage.failed:
            return
    first = len(result.metrics)
    by_checks = _measure_scenario(system, backend, sc, values, mech, ref, run, dt, settings,
                                  result, keep_series, eq)
    _refine_scenario(system, backend, sc, values, mech, ref, run, T, dt, settings, result, eq,
                     [m for m in result.metrics[first:] if m.name not in by_checks])


def _measure_scenario(system, backend, sc, values, mech, ref, run, dt, settings, result,
                      keep_series, eq, refinement=False, refined_checks=()) -> set:
    """The metrics of one scenario from the engine's `run` against `ref`; returns the names
    of those its checks (comparisons/checks) recorded that the refinement leaves alone.
    With `refinement` the `ref` is the engine's own finer run (`_refine_scenario`): the
    checks, which run engines of their own and judge on their own terms, are left out,
    but for `refined_checks` (whose ``REFINABLE`` metrics are wanted)."""
    name = sc.name
    joints = system.reaction_joints if "reaction" in sc.checks else ()
    contacts = system.contacts(system.symbols) if "constraint_force" in sc.checks else ()
    # a driven system's trajectory is that of its free coordinates (the prescribed ones
    # are judged as the engine's imposed motion, below)
    free = list(numeric_model(system.id, values).independent) if mech.prescribed else list(
        range(len(system.coordinates)))
    w = characteristic_frequency(eq.modes, ref.q[:, free], ref.qd[:, free], eq.q[free])
    if system.driven:
        w = max([w] + excitation_frequencies(system, values))
    order = run.integrator_order
    scale_free = metrics.amplitude(ref.q[:, free], eq.q[free])
    scale = np.ones(len(system.coordinates))
    scale[free] = scale_free
    ref_err = float(np.max(ref.error_estimate[free] / scale_free))
    zeta = max((max(m.damping_ratio, 0.0) for m in eq.modes), default=0.0)
    T_eff = tolerances.effective_duration(ref.t, metrics.envelope(ref.q, eq.q, scale))
    allowances = sum(allowance(system, sc, values, ref, eq, dt, order)
                     for allowance in checks.trajectory_allowances(sc.checks))
    bound = tolerances.trajectory_tolerance(w, dt, order, T_eff, zeta) + allowances
    if system.driven and eq.stable:
        driven = _driven_trajectory_bound(system, values, eq, dt, order, T_eff, zeta)
        if driven is not None:
            bound = min(bound, driven)
    roundoff = max(tolerances.roundoff_floor(len(ref.t) - 1, float(np.max(np.abs(ref.q[:, c]))),
                                             scale_free[k]) for k, c in enumerate(free))
    tol = tolerances.gate(bound + ref_err + roundoff, w, dt, order,
                          tolerances.MAX_TRAJECTORY_TOLERANCE)
    control = run.error_control
    if control is not None:  # the engine chose its steps: the gate follows its accuracy
        tol = tolerances.error_controlled_gate(tolerances.error_controlled_trajectory_tolerance(
            control.accuracy, control.steps, w, T_eff, float(np.min(scale_free)),
            max(1.0, sensitivity(system, sc, values))) + allowances + ref_err + roundoff)
    elif not system.driven:
        modal = _modal_trajectory_gate(system, values, eq, ref, free, scale_free, dt, order,
                                       T_eff, allowances + ref_err + roundoff)
        if modal is not None and (tol.unresolved or modal.tolerance < tol.tolerance):
            tol = modal
    n = min(len(run.t), len(ref.t))
    emax, erms = metrics.trajectory_errors(run.q[:n, free], ref.q[:n, free], scale_free)
    result.metrics.append(_judge(system, backend.id, f"{name}.trajectory_max", emax, tol))
    result.metrics.append(_judge(system, backend.id, f"{name}.trajectory_rms", erms, tol))
    # the named points, by the engine-independent kinematics of its coordinates
    judge_points(system, values, mech, ref, run, n, eq.q, scale, tol, name,
                 lambda label, value, gate: result.metrics.append(
                     _judge(system, backend.id, label, value, gate)))
    if system.driven:
        _compare_driven(system, backend, sc, values, ref, run, n, tol, w, dt, eq, result)
    scenario_series: dict = {}
    before_checks = len(result.metrics)
    for check in refined_checks if refinement else sc.checks:
        measure = checks.registry().get(check)
        if measure is None:
            continue
        measure(checks.ScenarioRun(
            system, backend, sc, values, mech, ref, run, n, tol, w, dt, eq, settings,
            judge=lambda label, value, gate, unit="relative": _record(
                result, _judge(system, backend.id, f"{name}.{label}", value, gate, unit)),
            unresolved=lambda label, tolerance, reason, unit="relative": _record(
                result, Metric(f"{name}.{label}", float("nan"), tolerance, False, "unresolved",
                               reason, unit, expected=_is_declared(system, backend.id,
                                                                f"{name}.{label}"))),
            simulate=lambda m, a, b, t: _guarded_run(backend, result, f"{name}.{check}", t,
                                                     m, a, b, t, dt, settings, ()),
            series=scenario_series, refinement=refinement))
    refinable = {f"{name}.{label}" for check in sc.checks for label in checks.refinable(check)}
    by_checks = {m.name for m in result.metrics[before_checks:] if m.name not in refinable}
    if len(system.coordinates) == 1:
        p_ref = metrics.mean_period(ref.t, ref.q[:, 0] - eq.q[0])
        p_run = metrics.mean_period(run.t[:n], run.q[:n, 0] - eq.q[0])
        if p_ref is not None:
            value = abs(p_run - p_ref) / p_ref if p_run is not None else float("inf")
            result.metrics.append(_judge(system, backend.id, f"{name}.period", value, tolerances.gate(
                tolerances.period_tolerance(w, dt, order, p_ref, zeta) + sum(
                    allowance(system, sc, values, ref, eq, dt, order)
                    for allowance in checks.period_allowances(sc.checks)), w, dt, order,
                tolerances.MAX_FREQUENCY_TOLERANCE, "relative")))
    if ref.energy is not None:
        model_energy = _energy_of(system, values, run.q[:n], run.qd[:n])
        e_scale = max(_kinetic_amplitude(system, values, ref.q, ref.qd), 1e-300)
        # the departure from the reference's own energy history (conserved to its
        # tolerance; the engine's finer run's, in a refinement)
        drift = float(np.max(np.abs(model_energy - model_energy[0]
                                    - (ref.energy[:n] - ref.energy[0]))) / e_scale)
        # the energy's own level (a potential far from its zero) rounds like the state
        floor = tolerances.roundoff_floor(n - 1, float(np.max(np.abs(model_energy))), e_scale)
        energy_gate = (tol if floor <= tol.tolerance else
                       tolerances.Gate(tol.tolerance + floor, tol.unresolved))
        result.metrics.append(_judge(system, backend.id, f"{name}.energy_drift", drift,
                                     energy_gate))
    for j in joints:
        r_run = run.reactions.get(j)
        value = (metrics.relative_vector_error(r_run[:n], ref.reactions[j][:n])
                 if r_run is not None else float("inf"))
        result.metrics.append(_judge(system, backend.id, f"{name}.reaction_{j}", value, tol))
    if "constraint_force" in sc.checks:
        # relative to the largest force any constraint of the mechanism carries in the
        # run: a force that vanishes by symmetry is not divided by its own round-off (a
        # force the reference cannot give, NaN throughout, takes no part)
        carried = [np.abs(f)[np.isfinite(f)] for f in (ref.constraint_forces or {}).values()]
        force_scale = max((float(np.max(a)) for a in carried if a.size), default=1.0)
        for cname, f_ref in (ref.constraint_forces or {}).items():
            f_run = run.constraint_forces.get(cname)
            value = (metrics.relative_vector_error(f_run[:n], f_ref[:n], force_scale)
                     if f_run is not None else float("inf"))
            result.metrics.append(_judge(system, backend.id, f"{name}.constraint_{cname}",
                                         value, tol))
    contact_series = (_compare_contacts(system, backend, values, ref, run, n, tol, name, result)
                      if contacts else {})
    if keep_series:
        result.series[name] = {
            "t": ref.t[:n], "q_ref": ref.q[:n], "q": run.q[:n],
            "reactions": {j: (ref.reactions[j][:n], run.reactions[j][:n])
                          for j in joints if j in run.reactions},
            "tolerance": tol.tolerance, "scale": scale, "checks": scenario_series,
            # actuator forces are drawn with the contact forces (same panel, N or N m)
            "contacts": {**contact_series, **{
                f"actuator {a}": (ref.actuator_forces[a][:n],
                                  np.asarray(run.actuator_forces.get(a, np.full(n, np.nan)),
                                             dtype=float)[:n])
                for a in (ref.actuator_forces or {})}},
        }
    return by_checks


#: largest condition number of the modal basis for a mode-by-mode bound (beyond it the
#: modes are nearly parallel, a rigid drift or a defective eigenvalue: no modal split)
MODAL_BASIS_CONDITION = 1e8


def _modal_trajectory_gate(system, values, eq, ref, free, scale_free, dt: float, order: int,
                           duration: float, allowance: float) -> "tolerances.Gate | None":
    """The mode-by-mode trajectory gate (comparisons/tolerances.py) of an undriven motion
    about a stable static equilibrium, or None where it does not apply: the initial state's
    modal coordinates give each mode's amplitude in every coordinate; the reference's
    departure from that linear prediction is the nonlinear part, counted twice."""
    if not eq.stable or eq.acceleration is not None or eq.M is None:
        return None
    model = numeric_model(system.id, values)
    ind = list(model.independent)
    k = len(ind)
    s, V = np.linalg.eig(companion_matrix(eq.M, eq.C, eq.K))
    if not np.all(np.isfinite(s)) or np.linalg.cond(V) > MODAL_BASIS_CONDITION:
        return None
    dq = ref.q - eq.q
    modal = np.linalg.solve(V, np.concatenate([dq[0, ind], ref.qd[0, ind]]))
    # each mode's displacement in every coordinate (dependent ones through the tangent map)
    shapes = (model.velocity_basis(eq.q) @ V[:k])[free] * modal
    linear = np.real(np.exp(np.outer(ref.t, s)) @ shapes.T)
    departure = float(np.max(np.abs(dq[:, free] - linear) / scale_free))
    # one term per oscillation: a conjugate pair's two halves add to twice either one
    keep = s.imag >= 0
    weights = np.where(np.abs(s.imag) > 0, 2.0, 1.0)[keep]
    omegas = np.abs(s[keep])
    zetas = np.where(omegas > 0, -s[keep].real / np.maximum(omegas, 1e-300), 0.0)
    bound = tolerances.modal_trajectory_tolerance(
        np.abs(shapes[:, keep]) * weights, omegas, zetas, scale_free, dt, order, duration)
    tolerance = bound + 2.0 * departure + allowance
    if not tolerance <= tolerances.MAX_TRAJECTORY_TOLERANCE:
        return tolerances.Gate(tolerance, f"the mode-by-mode error bound {tolerance:.3g} "
                               f"exceeds {tolerances.MAX_TRAJECTORY_TOLERANCE:g} of the "
                               f"amplitude: a pass would mean nothing")
    return tolerances.Gate(tolerance)


def _record(result: "Comparison", metric: Metric) -> Metric:
    result.metrics.append(metric)
    return metric


def _is_declared(system: System, simulator: str, name: str) -> bool:
    exp = expectation_for(system, simulator, name)
    return exp is not None and exp.kind in ("xfail", "unresolved")


def _compare_driven(system, backend, sc, values, ref, run, n, tol, w, dt, eq, result) -> None:
    """The checks of a driven scenario: the engine's imposed motion against q(t), the
    actuator forces, and (where the scenario asks) the steady-state amplitudes or the
    growth rate of an unstable motion."""
    model = numeric_model(system.id, values)
    name = sc.name
    for k, actuator in zip(model.driven, model.actuators):
        coordinate = system.coordinates[k]
        motion = ref.q[:n, k]
        span = float(np.max(np.abs(motion - motion[0])))
        # a motion that stays put (its amplitude set to zero) is judged on the
        # coordinate's own scale: 1 rad, or its distance from the origin (at least 0.1 m)
        scale = (1.0 if system.mechanism.angular(coordinate)
                 else max(abs(float(motion[0])), 0.1))
        if not span > 1e-12 * scale:
            span = scale
        value = float(np.max(np.abs(run.q[:n, k] - motion))) / span
        metric = _judge(system, backend.id, f"{name}.imposed_{coordinate}", value, tol)
        metric.detail = {"span": span, "unit": "rad" if system.mechanism.angular(coordinate)
                         else "m"}
        result.metrics.append(metric)
        if "actuator" not in sc.checks:
            continue
        f_ref = ref.actuator_forces[actuator][:n]
        f_run = run.actuator_forces.get(actuator)
        if f_run is None:
            value = float("inf")
        else:
            f_run = np.asarray(f_run[:n], dtype=float)
            # samples where the engine reports no force (its first step) are skipped;
            # in a refinement the finer run stands for the reference, with the same gaps
            ok = np.isfinite(f_run) & np.isfinite(f_ref)
            value = (float(np.max(np.abs(f_run[ok] - f_ref[ok]))
                           / max(float(np.max(np.abs(f_ref[ok]))), 1e-300))
                     if np.any(ok) else float("inf"))
        metric = _judge(system, backend.id, f"{name}.actuator_{actuator}", value, tol)
        metric.detail = {"reference_max": float(np.nanmax(np.abs(f_ref)))}
        result.metrics.append(metric)
    if "steady_state" in sc.checks:
        _compare_steady_state(system, backend, values, ref, run, n, dt, eq, name, result)
    if "growth_rate" in sc.checks:
        _compare_growth_rate(system, backend, values, ref, run, n, dt, eq, name, result)


def _amplification(eq, w: float) -> float:
    """2 |K| |D^-1| with D = K - w^2 M + i w C: how much a relative stiffness error moves
    the steady response at w (tolerances.py)."""
    D = eq.K - w**2 * eq.M + 1j * w * eq.C
    return float(2 * np.linalg.norm(eq.K, 2) * np.linalg.norm(np.linalg.inv(D), 2))


def _driven_trajectory_bound(system, values, eq, dt, order, t_end, zeta) -> float | None:
    """The driven trajectory bound of tolerances.py for a stable, damped driven system
    (None where it does not apply)."""
    sigma = min((-s.real for s in eq.eigenvalues), default=0.0)
    freqs = excitation_frequencies(system, values)
    if not sigma > 0 or not freqs:
        return None
    w_modes = max(abs(s) for s in eq.eigenvalues)
    amplification = max(_amplification(eq, w) for w in freqs)
    return tolerances.driven_trajectory_tolerance(max(freqs), w_modes, dt, order, t_end, sigma,
                                                  amplification, zeta)


#: the steady-state fit starts once the transient is below this fraction of the response
SETTLED = 1e-2


def _compare_steady_state(system, backend, values, ref, run, n, dt, eq, name, result) -> None:
    """Steady-state amplitude of each free coordinate (and observable) at each excitation
    frequency, fitted on the engine's run over the whole periods after the transient
    (decaying like exp(-sigma t), sigma the slowest modal decay rate) has fallen below
    SETTLED of the response, against the reference's fitted over the same window; the
    analytic linear amplitude (analytic/steady_state.py) is reported beside them."""
    response = steady_state(system, values)
    sigma = min((-s.real for s in eq.eigenvalues), default=0.0)
    order = run.integrator_order
    observables = observable_functions(system, values)
    for h in response.harmonics:
        if h.quantity == "actuator_force":
            continue
        if h.quantity == "position":
            k = system.coordinates.index(h.coordinate)

            def series(q, k=k):
                return q[:, k] - eq.q[k]
        else:
            value_of = observables[h.coordinate][0]

            def series(q, value_of=value_of):
                return np.broadcast_to(np.asarray(value_of(*q.T), dtype=float), (len(q),))
        W = 2 * np.pi * h.frequency_hz
        w_top = max(W, max((abs(s) for s in eq.eigenvalues), default=0.0))
        g = tolerances.gate(tolerances.steady_state_tolerance(w_top, dt, order,
                                                              _amplification(eq, W)),
                            w_top, dt, order, tolerances.MAX_TRAJECTORY_TOLERANCE)
        t = ref.t[:n]
        x_ref = series(ref.q[:n])
        # transient: at most the largest excursion over the run, decaying at sigma
        initial = max(float(np.max(np.abs(x_ref))), h.amplitude)
        settle = (np.log(initial / (SETTLED * h.amplitude)) / sigma
                  if sigma > 0 and h.amplitude > 0 else np.inf)
        periods = np.floor((t[-1] - settle) * W / (2 * np.pi)) if np.isfinite(settle) else 0
        label = f"{name}.steady_state_{h.coordinate}"
        if periods < 2:
            result.metrics.append(Metric(
                label, float("nan"), g.tolerance, False, "unresolved",
                f"the transient (slowest decay {sigma:.3g} 1/s) does not fall below "
                f"{SETTLED:g} of the response within the run: two whole periods after "
                f"{settle:.3g} s are needed",
                expected=False))
            continue
        window = t >= t[-1] - periods * 2 * np.pi / W
        a_ref = _harmonic_amplitude(t[window], x_ref[window], W)
        a_run = _harmonic_amplitude(t[window], series(run.q[:n])[window], W)
        value = abs(a_run - a_ref) / a_ref
        metric = _judge(system, backend.id, label, value, g)
        metric.detail = {"linear_amplitude": h.amplitude, "reference_fit": a_ref,
                         "engine_fit": a_run, "frequency_hz": h.frequency_hz,
                         "window_s": [float(t[window][0]), float(t[-1])]}
        result.metrics.append(metric)


def _harmonic_amplitude(t: np.ndarray, x: np.ndarray, w: float) -> float:
    """Amplitude of the harmonic at w in x(t), least squares on (1, cos, sin)."""
    A = np.column_stack([np.ones_like(t), np.cos(w * t), np.sin(w * t)])
    coef, *_ = np.linalg.lstsq(A, x, rcond=None)
    return float(np.hypot(coef[1], coef[2]))


def _compare_growth_rate(system, backend, values, ref, run, n, dt, eq, name, result) -> None:
    """Exponential growth rate of an unstable driven motion (e.g. the rotating slot above
    its critical speed), fitted on the engine's run, against the largest real part of the
    linearization's eigenvalues."""
    sigma = max(s.real for s in eq.eigenvalues)
    if not sigma > 0:
        return
    order = run.integrator_order
    w_top = max(abs(s) for s in eq.eigenvalues)
    freqs = excitation_frequencies(system, values)
    g = tolerances.gate(tolerances.growth_rate_tolerance(max([w_top] + freqs), dt, order),
                        max([w_top] + freqs), dt, order, tolerances.MAX_FREQUENCY_TOLERANCE,
                        "relative")
    model = numeric_model(system.id, values)
    t = ref.t[:n]
    k = model.independent[0]
    fit_ref = metrics.fit_growth_rate(t, ref.q[:n, k] - eq.q[k], eq.eigenvalues, freqs)
    fit_run = metrics.fit_growth_rate(t, run.q[:n, k] - eq.q[k], eq.eigenvalues, freqs)
    value = abs(fit_run - sigma) / sigma
    metric = _judge(system, backend.id, f"{name}.growth_rate", value, g)
    metric.detail = {"analytic_per_s": sigma, "reference_fit_per_s": fit_ref,
                     "engine_fit_per_s": fit_run}
    result.metrics.append(metric)


def _incident_message(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return f"{type(exc).__name__}: {text}"[:500]


def record_incident(result: Comparison, scenario: str, stage: str, exc: BaseException,
                    outcome: str = "failed", t_reached: float | None = None) -> None:
    """A stage that raised (description, derivation, equilibrium, reference, engine run,
    linearization, fit, report files) is data: the incident with its stage, message and
    the time reached, and a failed `<scenario>.<stage>` metric, so that this comparison
    fails and nothing else is lost."""
    if t_reached is None:
        t_reached = getattr(exc, "t_reached", None)
    message = _incident_message(exc)
    result.incidents.append({"scenario": scenario, "stage": stage, "outcome": outcome,
                             "t_reached": t_reached, "message": message})
    result.metrics.append(Metric(f"{scenario}.{stage.replace(' ', '_')}", 0.0, 1.0, False,
                                 "fail", message, unit="stage completed"))


@contextmanager
def contained(result: Comparison, scenario: str, stage: str):
    """Runs the block; an exception it raises becomes an incident of `result` (see
    `record_incident`) and the code after the block goes on. `.failed` tells."""
    state = SimpleNamespace(failed=False)
    try:
        yield state
    except (Exception, SystemExit) as exc:  # a stage's failure is data, not a traceback
        state.failed = True
        record_incident(result, scenario, stage, exc)


def _guarded_run(backend, result: Comparison, label: str, t_end: float, *args):
    """`backend.simulate(*args)`, or None when the engine raised: the run is recorded as
    an incident (crashed, with the engine's message) and `<label>.completed` fails. A run
    that returns non-finite states is recorded as diverged at the first such sample (its
    metrics, computed on NaN, fail too)."""
    try:
        run = backend.simulate(*args)
    except Exception as exc:  # an engine's own failure is data, not a traceback
        message = " ".join(str(exc).split()) or type(exc).__name__
        result.incidents.append({"scenario": label, "stage": "engine run",
                                 "outcome": "crashed", "t_reached": None,
                                 "message": _incident_message(exc)})
        result.metrics.append(_incomplete(result, backend, label, 0.0, message))
        return None
    finite = np.all(np.isfinite(run.q), axis=1) & np.all(np.isfinite(run.qd), axis=1)
    if not np.all(finite):
        k = int(np.argmin(finite))
        reached = float(run.t[k - 1]) if k > 0 else 0.0
        result.incidents.append({"scenario": label, "stage": "engine run",
                                 "outcome": "diverged", "t_reached": reached,
                                 "message": f"non-finite state at t = {run.t[k]:.6g} s"})
        result.metrics.append(_incomplete(result, backend, label, reached / t_end,
                                          "the engine's state diverged"))
    return run


def _incomplete(result: Comparison, backend, label: str, fraction: float,
                message: str) -> Metric:
    """The failed `<label>.completed` metric: an expected failure where the system
    declares it (a run the engine cannot finish at this step, with the reason)."""
    name = f"{label}.completed"
    exp = expectation_for(get_system(result.system), backend.id, name)
    if exp is not None and exp.kind == "xfail":
        return Metric(name, fraction, 1.0, False, "xfail", f"{exp.reason} ({message})",
                      unit="fraction of the run")
    return Metric(name, fraction, 1.0, False, "fail", message, unit="fraction of the run")


def _first_negative(t: np.ndarray, f: np.ndarray) -> float | None:
    below = np.flatnonzero(f < 0)
    return float(t[below[0]]) if below.size else None


def _compare_contacts(system, backend, values, ref, run, n, tol, name, result) -> dict:
    """Contact forces (normal, friction) on the scale of the largest one; for a unilateral
    contact, where and how far the bilateral model pulls (a real contact would open).
    Returns the series, name -> (reference, engine), for the report."""
    f_ref = contact_forces(system, values, ref.q[:n],
                           {k: v[:n] for k, v in ref.reactions.items()},
                           {k: v[:n] for k, v in (ref.constraint_forces or {}).items()})
    f_run = contact_forces(system, values, run.q[:n],
                           {k: v[:n] for k, v in run.reactions.items()},
                           {k: v[:n] for k, v in run.constraint_forces.items()})
    scale = max((float(np.nanmax(np.abs(f))) for f in f_ref.values()), default=1.0)
    t = ref.t[:n]
    for c in system.contacts(system.symbols):
        a, b = f_run[c.name], f_ref[c.name]
        ok = ~np.isnan(a) & ~np.isnan(b)  # b has gaps where a finer run stands for it
        value = (float(np.max(np.abs(a[ok] - b[ok])) / max(scale, 1e-300))
                 if np.any(ok) else float("inf"))
        metric = _judge(system, backend.id, f"{name}.contact_{c.name}", value, tol)
        rms = (float(np.sqrt(np.mean((a[ok] - b[ok]) ** 2))) / max(scale, 1e-300)
               if np.any(ok) else float("inf"))
        metric.detail = {"rms_error": rms,
                         "reference_min": float(np.min(b)), "reference_max": float(np.max(b)),
                         "engine_min": float(np.nanmin(a)) if np.any(ok) else None,
                         "unilateral": c.unilateral}
        if c.unilateral:
            metric.detail["reference_first_negative_s"] = _first_negative(t, b)
            metric.detail["engine_first_negative_s"] = _first_negative(t[ok], a[ok])
        result.metrics.append(metric)
    return {c.name: (f_ref[c.name], f_run[c.name]) for c in system.contacts(system.symbols)}


def _energy_of(system, values, q, qd):

    return numeric_model(system.id, values).energy(q, qd)


def _kinetic_amplitude(system, values, q, qd) -> float:

    model = numeric_model(system.id, values)
    T = np.array([0.5 * v @ model.mass_matrix(x) @ v for x, v in zip(q[::10], qd[::10])])
    return float(np.max(T))


#: a free-vibration fit's release lasts at least FIT_PERIODS periods of its mode (fewer
#: cannot separate frequency from damping) and at most FIT_PERIODS_MAX, or 10 s between
FIT_PERIODS = 10
FIT_PERIODS_MAX = 40


def fit_duration(frequency_hz: float, t_end: float | None) -> float:
    """Simulated seconds of the fit of a mode of `frequency_hz`; never beyond `t_end`."""
    T = max(min(t_end or 10.0, FIT_PERIODS_MAX / frequency_hz), FIT_PERIODS / frequency_hz)
    return T if t_end is None else min(T, t_end)


def comparison_cost(system: System, values: Mapping[str, float], dt: float,
                    t_end: float | None, scenarios: Iterable[str] | None = None
                    ) -> list[budget.PlannedRun]:
    """The engine runs a comparison will make, from the description (before any work):
    each scenario at its duration, each generated run near another equilibrium, and each
    oscillatory mode's free-vibration fit."""
    chosen = set(scenarios or ())
    runs = [budget.PlannedRun(sc.name, sc.t_end if t_end is None else t_end, dt)
            for sc in system.scenarios if not chosen or sc.name in chosen]
    try:
        near = near_equilibrium_scenarios(system, values)
        fit_values = unexcited_values(system, values) if system.mechanism.prescribed else values
        modes = operating_equilibrium(system, fit_values).modes
    except Exception:  # the comparison's own stages record why
        return runs
    runs += [budget.PlannedRun(sc.name, sc.t_end if t_end is None else t_end, dt)
             for sc, _ in near if not chosen or sc.name in chosen]
    runs += [budget.PlannedRun(f"fit of mode {i + 1} ({m.frequency_hz:.3g} Hz)",
                               fit_duration(m.frequency_hz, t_end), dt)
             for i, m in enumerate(modes) if m.damped_frequency_hz > 0]
    return runs


def _compare_frequencies(system, backend, values, dt, t_end, settings, result, keep_series,
                         variant=None):
    """Modes of the operating equilibrium: the engine's own linearization, and a
    free-vibration fit of each modal coordinate after a small modal release."""
    if system.mechanism.prescribed:
        values = unexcited_values(system, values)
    with contained(result, "frequency", "equilibrium") as stage:
        eq = operating_equilibrium(system, values)
    if stage.failed:
        return
    if not (eq.stable or oscillatory_instability(eq.eigenvalues)):
        return  # a divergent equilibrium: a release departs without oscillating
    # free vibration: the excitation e(t) is off, as for the equilibrium (eq. 78)
    mech = _engine_mechanism(system, values, variant).without_time_loads()
    modes = [m for m in eq.modes if m.frequency_hz > 0]
    ref_w = np.array([abs(m.eigenvalue) for m in modes])
    lin = None
    with contained(result, "frequency", "linearization"):
        lin = backend.linearize(mech, eq.q, settings, dt)
    if lin is not None:
        from ..analytic.modes import modes_from_eigenvalues

        got = [m for m in modes_from_eigenvalues(lin.eigenvalues) if m.frequency_hz > 0]
        discrete_order = lin.extra.get("discrete_order")
        for i, m in enumerate(modes):
            # a discrete map moves each eigenvalue by its own (w h)^p
            tol = (tolerances.gate(tolerances.discrete_linearization_tolerance(
                       ref_w[i], dt, discrete_order), ref_w[i], dt, discrete_order,
                       tolerances.MAX_FREQUENCY_TOLERANCE, "relative")
                   if discrete_order else tolerances.FD_FREQUENCY)
            if i < len(got):
                value = abs(got[i].frequency_hz - m.frequency_hz) / m.frequency_hz
                dz = abs(got[i].damping_ratio - m.damping_ratio)
            else:
                value = dz = float("inf")
            metric = _judge(system, backend.id, f"frequency.linearization_mode{i + 1}", value, tol)
            metric.detail = {"reference_hz": m.frequency_hz, "method": lin.method,
                             "engine_hz": got[i].frequency_hz if i < len(got) else None}
            result.metrics.append(metric)
            # not round-off of an undamped mode (a negative ratio: a self-excited mode)
            if abs(m.damping_ratio) > ZERO_REAL_PART:
                result.metrics.append(_judge(system, backend.id,
                                             f"damping.linearization_mode{i + 1}", dz, tol,
                                             unit="absolute"))
    # free-vibration fit (every engine): each oscillatory mode released alone from its
    # state-space eigenvector (exact for non-proportional damping too), fitted on the
    # coordinate where it is largest

    model = numeric_model(system.id, values)
    ind = model.independent
    k_dof = len(ind)
    s_all, vecs = np.linalg.eig(companion_matrix(eq.M, eq.C, eq.K))
    scales = _coordinate_scales(system, eq.q)[ind]
    oscillatory = [m for m in modes if m.damped_frequency_hz > 0]
    tol = None
    for i, m in enumerate(modes):
        if m not in oscillatory:
            continue
        v = vecs[:, int(np.argmin(np.abs(s_all - m.eigenvalue)))]
        v = v / np.max(np.abs(v[:k_dof] / scales))  # largest coordinate excursion = scale
        guess = eq.q.copy()
        guess[ind] += tolerances.FIT_AMPLITUDE * np.real(v[:k_dof])
        q0 = model.complete(guess)
        qd0 = model.velocity_basis(q0) @ (tolerances.FIT_AMPLITUDE * np.real(v[k_dof:]))
        if model.driven:
            q0[model.driven], qd0[model.driven] = model.motion(0.0)[:2]
        T = fit_duration(m.frequency_hz, t_end)
        if T * m.frequency_hz < FIT_PERIODS * (1 - 1e-9):
            for kind in ("frequency", "damping"):
                result.metrics.append(Metric(
                    f"{kind}.fit_mode{i + 1}", float("nan"), float("nan"), False,
                    "unresolved", f"not measured: a fit needs {FIT_PERIODS} periods of this "
                    f"mode ({FIT_PERIODS / m.frequency_hz:.3g} s), longer than --t-end",
                    expected=True))
            continue
        run = _guarded_run(backend, result, f"fit_mode{i + 1}", T,
                           mech, q0, qd0, T, dt, settings, ())
        if run is None:
            continue
        result.wall_time += run.wall_time
        result.simulated_time += T
        # the release is that mode alone (others enter at the amplitude squared), so its
        # own frequency sets the scheme's error
        w_mode = ref_w[i]
        tol = tolerances.gate(tolerances.fit_tolerance(w_mode, dt, run.integrator_order,
                                                        m.damping_ratio),
                              w_mode, dt, run.integrator_order,
                              tolerances.MAX_FREQUENCY_TOLERANCE, "relative")
        j = int(np.argmax(np.abs(v[:k_dof]) / scales))
        try:
            w_fit, z_fit = metrics.fit_damped_sinusoid(run.t, run.q[:, ind[j]] - eq.q[ind[j]],
                                                       abs(m.eigenvalue), m.damping_ratio)
            value = abs(w_fit - abs(m.eigenvalue)) / abs(m.eigenvalue)
            dz = abs(z_fit - m.damping_ratio)
        except (RuntimeError, ValueError):  # no convergence, or a diverged (NaN) run
            w_fit, value, dz = float("nan"), float("inf"), float("inf")
        metric = _judge(system, backend.id, f"frequency.fit_mode{i + 1}", value, tol)
        metric.detail = {"reference_hz": m.frequency_hz, "method": "free-vibration fit",
                         "engine_hz": w_fit / (2 * np.pi) if np.isfinite(value) else None}
        result.metrics.append(metric)
        result.metrics.append(_judge(system, backend.id, f"damping.fit_mode{i + 1}", dz, tol,
                                     unit="absolute"))
        _refine_fit(system, backend, mech, q0, qd0, T, dt, settings, result,
                    result.metrics[-2:], eq.q[ind[j]], ind[j], m,
                    (w_fit, z_fit) if np.isfinite(value) else (np.nan, np.nan))


# --- the a-posteriori rule: the engine's own refinement (tolerances.py) ----------------

#: the refinement's steps, as divisors of the comparison's: h/8 only where the pair
#: before it does not show the order or the engine's limit is not yet within the ceiling,
#: h/16 (the step budget) only where the order is still not shown or the limit's observed
#: order brings it within the ceiling (tolerances.py, "A posteriori")
REFINEMENT_DIVISORS = (2, 4, 8, 16)


#: metrics measured against something other than the reference's same quantity (the
#: growth rate against the linearization's eigenvalue): not refined, unless a check of
#: the scenario names them refinable (the Floquet check's rate, comparisons/checks)
NOT_REFINED = ("growth_rate",)


def _refine_scenario(system, backend, sc, values, mech, ref, run, t_end, dt, settings,
                     result, eq, measured_here: list) -> None:
    """Judge the scenario's unresolved metrics (of `measured_here`) by the engine's own
    refinement: the engine re-run at h/2, h/4 (h/8, h/16 where needed) from the same state, the
    scenario's metrics measured between successive runs on the samples of h
    (`_measure_scenario` with the finer run in the reference's place), and each metric
    judged by `tolerances.refinement_gate`. The a-priori verdicts stay as they are."""
    refinable = {f"{sc.name}.{label}" for check in sc.checks for label in checks.refinable(check)}
    pending = [m for m in measured_here if m.status == "unresolved" and np.isfinite(m.value)
               and (m.name in refinable or not m.name.endswith(NOT_REFINED))]
    if not pending:
        return
    joints = system.reaction_joints if "reaction" in sc.checks else ()
    contacts = system.contacts(system.symbols) if "constraint_force" in sc.checks else ()
    joints = joints + tuple(c.target for c in contacts
                            if c.kind == "reaction" and c.target not in joints)
    free = (list(numeric_model(system.id, values).independent) if mech.prescribed
            else list(range(len(system.coordinates))))
    scale = metrics.amplitude(ref.q[:, free], eq.q[free])
    reference_error = float(np.max(ref.error_estimate[free] / scale))
    scratch = Comparison(system.id, backend.id, "", dict(settings), dict(values), dt)
    order = _refinement_order(system, sc, values, ref, run.integrator_order)
    capped = _declared_order(system, backend.id, order)
    top = run.integrator_order if capped < order else None
    order = capped
    wanted = {m.name for m in pending}
    refined_checks = tuple(c for c in sc.checks if any(
        f"{sc.name}.{label}" in wanted for label in checks.refinable(c)))
    held = _HELD_GATES.get()
    if held is not None:
        _judge_held(system, backend, sc, values, mech, ref, t_end, dt, settings, eq, joints,
                    refined_checks, pending, held)
        return
    runs, differences = [run], {m.name: [] for m in pending}
    # the same differences on the samples of h, for the engine's limit
    on_h = {m.name: [] for m in pending}
    gates: dict = {}
    limit_gates: dict = {}
    # the reference's own error in each metric: the trajectory's, or what a check's
    # estimator misses on the exact motion (its detail)
    own_error = {m.name: float(m.detail.get("reference_error", reference_error))
                 for m in pending}
    for k in REFINEMENT_DIVISORS:
        if k > 4 and all(not g.unresolved and (
                g.tolerance <= _ceiling(name)
                or limit_gates[name].limit_tolerance <= _ceiling(name))
                for name, g in gates.items()):
            break
        # h/16, the step budget: where the order is still not confirmed, or where the
        # engine's limit is predicted to come within the ceiling
        if k > 8 and not any((g.unresolved and g.observed_order is not None)
                             or _limit_within_reach(name, g, limit_gates.get(name))
                             for name, g in gates.items()):
            break
        fine = _guarded_run(backend, scratch, f"{sc.name}.refinement", t_end, mech, ref.q[0],
                            ref.qd[0], t_end, dt / k, settings, joints)
        if fine is None or scratch.incidents:
            if k <= 4:
                for m in pending:
                    m.rule = "refinement"
                    m.reason += (f"; refinement: the engine's run at h/{k} did not complete"
                                 f" ({scratch.incidents[0]['message']})")
                return
            break
        result.wall_time += fine.wall_time
        result.refinement_wall_time += fine.wall_time
        # each pair on the samples of its coarser run: the max over the samples of h is
        # at most that over the finer samples, so the telescoping bound still holds, and a
        # one-step error that every run makes at its first step is not hidden
        measured = _measured_between(system, backend, sc, values, mech, ref, eq, settings,
                                     _on_steps_of(fine, 2), runs[-1], dt * 2 / k,
                                     refined_checks)
        # and on the samples of h, where the finest run meets the reference
        measured_on_h = measured if k == 2 else _measured_between(
            system, backend, sc, values, mech, ref, eq, settings, _on_steps_of(fine, k),
            _on_steps_of(runs[-1], k // 2), dt, refined_checks)
        runs.append(fine)
        for name, d in differences.items():
            d.append(measured.get(name, float("nan")))
            on_h[name].append(measured_on_h.get(name, float("nan")))
            if len(d) >= 2 and (name not in gates or gates[name].unresolved):
                gates[name] = tolerances.refinement_gate(d, order, own_error[name],
                                                         top=top)
            if len(d) >= 2:
                limit_gates[name] = tolerances.refinement_gate(on_h[name], order,
                                                               own_error[name], top=top)
    limits = _limits(system, backend, sc, values, mech, ref, runs, dt, settings, eq, gates,
                     limit_gates, refined_checks)
    for m in pending:
        if m.name in gates:
            _judge_refined(system, backend.id, m, gates[m.name], limits.get(m.name))


def _held_gate(baseline: dict | None) -> "tolerances.RefinementGate | None":
    """The refinement gate a baseline's metric (`Metric.as_dict`) was judged by, or None
    where the baseline did not judge it by its refinement."""
    numbers = (baseline or {}).get("refinement")
    if not numbers or not baseline["rule"].startswith("refinement"):
        return None
    return tolerances.RefinementGate(
        baseline["tolerance"], numbers["observed_order"], numbers["declared_order"],
        numbers["predicted_error"], tuple(numbers["differences"]),
        numbers["reference_error"], numbers.get("unresolved", ""),
        (numbers.get("limit") or {}).get("tolerance", math.inf))


def _judge_held(system, backend, sc, values, mech, ref, t_end, dt, settings, eq, joints,
                refined_checks, pending, held: Mapping[str, dict]) -> None:
    """`pending` judged by the baseline's refinement gates (`compare(held_gates=)`): a
    metric the baseline judged at h against that bound; one whose limit the baseline
    judged on its run at h/K, on the engine's run at h/K (the same K) against the
    baseline's bound on the limit. A metric the baseline did not judge by its refinement
    stays unresolved."""
    gates = {m.name: _held_gate(held.get(m.name)) for m in pending}
    divisors = {name: held[name]["refinement"]["limit"]["divisor"]
                for name, g in gates.items()
                if g is not None and "limit" in held[name]["refinement"]}
    measured: dict = {}
    if divisors:
        k = max(divisors.values())
        scratch = Comparison(system.id, backend.id, "", dict(settings), dict(values), dt)
        fine = _guarded_run(backend, scratch, f"{sc.name}.refinement", t_end, mech,
                            ref.q[0], ref.qd[0], t_end, dt / k, settings, joints)
        if fine is not None and not scratch.incidents:
            _measure_scenario(system, backend, sc, values, mech, ref, _on_steps_of(fine, k),
                              dt, settings, scratch, False, eq, refinement=True,
                              refined_checks=refined_checks)
            measured = {m.name: m.value for m in scratch.metrics}
    for m in pending:
        gate = gates[m.name]
        if gate is None:
            continue
        limit = ((measured.get(m.name, math.inf), gate.limit_tolerance, divisors[m.name])
                 if m.name in divisors else None)
        _judge_refined(system, backend.id, m, gate, limit)
        m.refinement["held"] = True


def _limit_within_reach(name: str, gate, limit_gate) -> bool:
    """Whether one more halving is predicted to bring the bound on the engine's limit
    within the ceiling where it is not yet: at the limit's observed order, or, where its
    differences fall faster than any term of the scheme (they leave a pre-asymptotic
    range: the order is not yet confirmed), at the scheme's fastest order."""
    if gate.unresolved or gate.tolerance <= _ceiling(name) or limit_gate is None \
            or limit_gate.limit_tolerance <= _ceiling(name):
        return False
    order, observed = limit_gate.declared_order, limit_gate.observed_order
    if limit_gate.unresolved:
        if observed is None or not observed > (tolerances.highest_order(order)
                                               + tolerances.REFINEMENT_ORDER_MARGIN):
            return False
        predicted = (limit_gate.differences[-1] * 2.0 ** -tolerances.highest_order(order)
                     * tolerances.limit_factor(order) + limit_gate.reference_error)
    else:
        predicted = limit_gate.limit_tolerance * 2.0 ** -(observed if observed is not None
                                                          else order)
    return predicted <= _ceiling(name)


def _measured_between(system, backend, sc, values, mech, ref, eq, settings, finer, coarser,
                      dt: float, refined_checks=()) -> dict:
    """name -> value of the scenario's metrics (of the checks, `refined_checks` only)
    between two of the engine's runs sampled alike, the `finer` in the reference's
    place."""
    scratch = Comparison(system.id, backend.id, "", dict(settings), dict(values), dt)
    _measure_scenario(system, backend, sc, values, mech,
                      _as_reference(system, values, ref, coarser, finer), coarser, dt,
                      settings, scratch, False, eq, refinement=True,
                      refined_checks=refined_checks)
    return {m.name: m.value for m in scratch.metrics}


def _refinement_order(system, sc, values, ref, order: int) -> int:
    """The order the refinement judges a scenario at: the scheme's, or lower where one of
    the scenario's checks names an event that caps it (tolerances.py, "A posteriori")."""
    capped = [f(system, sc, values, ref, order) for f in checks.refinement_orders(sc.checks)]
    return min([order] + [q for q in capped if q is not None])


def _declared_order(system, simulator: str, order: int) -> int:
    """The order the system declares for the engine's convergence where its model, not
    its scheme, sets it (systems `OrderCap`; tolerances.py, "A declared order cap")."""
    caps = [c.order for c in system.order_caps if fnmatch.fnmatch(simulator, c.simulator)]
    return min([order] + caps)


def _limits(system, backend, sc, values, mech, ref, runs, dt, settings, eq, gates,
            limit_gates, refined_checks=()) -> dict:
    """For each metric whose refinement bound at h is above its ceiling, the engine's
    limit judged on its finest run against the reference, both on the samples of h
    (tolerances.py, "A posteriori"): name -> (v_K, its bound, the divisor 2^K), where
    the differences on those samples confirm the order on their last pair."""
    wanted = {name: limit_gates[name].limit_tolerance for name, g in gates.items()
              if not g.unresolved and not g.tolerance <= _ceiling(name)
              and name in limit_gates and not limit_gates[name].unresolved}
    if not wanted:
        return {}
    divisor = 2 ** (len(runs) - 1)
    scratch = Comparison(system.id, backend.id, "", dict(settings), dict(values), dt)
    _measure_scenario(system, backend, sc, values, mech, ref, _on_steps_of(runs[-1], divisor),
                      dt, settings, scratch, False, eq, refinement=True,
                      refined_checks=refined_checks)
    measured = {m.name: m.value for m in scratch.metrics}
    return {name: (measured[name], bound, divisor) for name, bound in wanted.items()
            if np.isfinite(measured.get(name, float("nan")))}


def _refine_fit(system, backend, mech, q0, qd0, t_end, dt, settings, result, fitted,
                q_eq: float, coordinate: int, mode, first_fit) -> None:
    """The free-vibration fit's frequency and damping metrics (`fitted`), where unresolved
    a priori, judged by the engine's own refinement: the same release at h/2, h/4 (h/8
    where needed) fitted alike; d_k are the differences of successive fits, relative to
    the mode's frequency (the damping ratio's, absolute), tolerances.refinement_gate."""
    pending = [m for m in fitted if m.status == "unresolved" and np.isfinite(m.value)]
    held = _HELD_GATES.get()
    if held is not None:
        for metric in pending:
            gate = _held_gate(held.get(metric.name))
            if gate is not None:
                _judge_refined(system, backend.id, metric, gate)
                metric.refinement["held"] = True
        return
    if not pending or not np.all(np.isfinite(first_fit)):
        return
    w_ref = abs(mode.eigenvalue)
    fits, gates = [first_fit], {}
    scratch = Comparison(system.id, backend.id, "", dict(settings), {}, dt)
    for k in REFINEMENT_DIVISORS:
        if k > 4 and all(not g.unresolved for g in gates.values()):
            break
        run = _guarded_run(backend, scratch, "fit.refinement", t_end, mech, q0, qd0, t_end,
                           dt / k, settings, ())
        if run is None or scratch.incidents:
            break
        result.wall_time += run.wall_time
        result.refinement_wall_time += run.wall_time
        try:
            fits.append(metrics.fit_damped_sinusoid(run.t, run.q[:, coordinate] - q_eq, w_ref,
                                                    mode.damping_ratio))
        except (RuntimeError, ValueError):
            break
        if len(fits) < 3:
            continue
        w_fits, z_fits = np.array(fits).T
        for metric, d in zip(fitted, (np.abs(np.diff(w_fits)) / w_ref,
                                      np.abs(np.diff(z_fits)))):
            if metric in pending and (metric.name not in gates
                                      or gates[metric.name].unresolved):
                # a fit is precise to FIT_RESOLUTION: its floor, and the exact motion's
                # own fitted error
                gates[metric.name] = tolerances.refinement_gate(
                    d, run.integrator_order, tolerances.FIT_RESOLUTION,
                    floor=tolerances.FIT_RESOLUTION)
    for metric in pending:
        if metric.name in gates:
            _judge_refined(system, backend.id, metric, gates[metric.name])


def _on_steps_of(fine, k: int):
    """An engine's run at h/k sampled on the steps of h (every k-th sample)."""
    from dataclasses import replace

    def every(x):
        return None if x is None else np.asarray(x)[::k]

    return replace(fine, t=fine.t[::k], q=fine.q[::k], qd=fine.qd[::k],
                   reactions={j: every(v) for j, v in fine.reactions.items()},
                   constraint_forces={c: every(v) for c, v in fine.constraint_forces.items()},
                   actuator_forces={a: every(v) for a, v in fine.actuator_forces.items()})


def _as_reference(system, values, ref, coarse, run):
    """The engine's finer `run` (sampled as `coarse`) in the place of the reference `ref`:
    its states, forces and energy, with no error of its own."""
    from dataclasses import replace

    n = min(len(coarse.t), len(run.t))
    return replace(ref, t=coarse.t[:n], q=run.q[:n], qd=run.qd[:n], qdd=None,
                   reactions={j: np.asarray(v)[:n] for j, v in run.reactions.items()},
                   constraint_forces={c: np.asarray(v)[:n]
                                      for c, v in run.constraint_forces.items()},
                   actuator_forces={a: np.asarray(v, dtype=float)[:n]
                                    for a, v in run.actuator_forces.items()},
                   energy=(None if ref.energy is None
                           else _energy_of(system, values, run.q[:n], run.qd[:n])),
                   error_estimate=np.zeros_like(ref.error_estimate),
                   points=(numeric_model(system.id, values).point_states(run.q[:n], run.qd[:n])
                           if ref.points else ref.points))


def _ceiling(name: str) -> float:
    """What the metric can still discriminate (tolerances.py): a frequency, damping ratio
    or period 0.05, a trajectory-like error 0.1 of the amplitude."""
    if name.startswith(("frequency.", "damping.")) or name.endswith((".period",
                                                                       ".growth_rate")):
        return tolerances.MAX_FREQUENCY_TOLERANCE
    return tolerances.MAX_TRAJECTORY_TOLERANCE


def _judge_refined(system: System, simulator: str, metric: Metric,
                   gate: "tolerances.RefinementGate", limit: tuple | None = None) -> None:
    """`metric` (unresolved a priori) judged by the refinement gate, in place: pass or
    fail (xfail where declared so), or still unresolved with the refinement's reason.
    Where the bound at h is above the ceiling, `limit` (v_K, its bound, 2^K) judges the
    engine's limit on its finest run (tolerances.py, "A posteriori")."""
    exp = expectation_for(system, simulator, metric.name)
    metric.rule = "refinement"
    metric.refinement = {**gate.as_dict(), "a_priori_tolerance": metric.tolerance}
    metric.tolerance = gate.tolerance
    if gate.unresolved:
        shrinks = gate.observed_order is not None and not (
            gate.observed_order < gate.declared_order - tolerances.REFINEMENT_ORDER_MARGIN)
        if exp is not None and exp.kind == "xfail" and not shrinks:
            # declared not to converge to the reference, and its differences do not
            # shrink ("A declared order cap": a soft constraint's force)
            metric.passed, metric.expected = False, False
            metric.status, metric.reason = "xfail", f"{exp.reason}; refinement: {gate.unresolved}"
            return
        metric.reason = f"{metric.reason}; refinement: {gate.unresolved}"
        return
    ok = bool(metric.value <= gate.tolerance)
    ceiling = _ceiling(metric.name)
    why = ""
    if ok and not gate.tolerance <= ceiling:
        if limit is not None:
            value, bound, divisor = limit
            metric.refinement["limit"] = {"divisor": divisor, "value": value,
                                          "tolerance": bound}
        if limit is None or not bound <= ceiling:
            metric.reason = (f"{metric.reason}; refinement: the engine's own error bound "
                             f"{gate.tolerance:.3g} exceeds {ceiling:g}"
                             + (f", and so does its remaining error at h/{divisor}, "
                                f"{bound:.3g}: within the step budget" if limit else "")
                             + ": a pass would mean nothing")
            return
        metric.rule = "refinement_limit"
        ok = bool(value <= bound)
        if not ok:
            why = (f"the engine's run at h/{divisor} is {value:.3g} from the reference, "
                   f"beyond its own remaining error {bound:.3g}: its limit is another motion")
    metric.passed, metric.expected = ok, False
    if exp is not None and exp.kind == "xfail":
        metric.status, metric.reason = ("pass" if ok else "xfail"), exp.reason
    else:
        metric.status, metric.reason = ("pass" if ok else "fail"), why


# --- provenance and the matrix ---------------------------------------------------------


def provenance() -> dict:
    try:
        describe = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True,
                                  text=True, cwd=Path(__file__).parent, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        describe = ""
    return {
        "mbfidelity": __version__, "git_describe": describe or "unknown",
        "python": platform.python_version(), "platform": platform.platform(),
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }
