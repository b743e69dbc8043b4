"""Gate power: what the comparison's gates catch (the mutation study), and what each
engine default the harness neutralises does when it is switched back on (the out-of-the-box
reading of the same runs).

Model errors are injected into the engine's build only (`runner.compare(engine_scale=)`):
one parameter of each kind (a mass, an inertia, a length, g, a spring stiffness, a damping
coefficient) is multiplied by (1 + eps) while the reference and the gates keep the true
values. The parameter of a kind is the first one of the system (declaration order) with
that kind's unit whose change changes the numeric mechanism the engine is given (drawing
shapes aside); a kind without one is not applicable. A run is rejected when a metric that
passes in the unmutated run (the baseline) fails in it, or a run that did not complete.

For each error kind the smallest rejected eps on the decade grid `EPSILONS` is found by
bisection on the grid, assuming rejection is monotone in eps (a larger error is rejected
whenever a smaller one is): three runs instead of six. Next to it, the motion change that
a 1 % error (`PROBE`) makes in the exact model (reference with the mutated parameter
against the true one, on the first scenario and on the modes) is set against the gates
it should trip, so that an error too small to move the motion beyond the gate is told
apart from a blind gate.

Each neutralised default (`Setting.engine_default`) is switched back on alone, and all
together (the engine as a user gets it); the gates' verdict and the effect against the
neutralised run are recorded: the trajectory error, the energy drift and the damping
ratio each default leaves (the metrics of both runs), and the motion change.

Cost: a model error's run is the system's first scenario plus the frequency checks
(free-vibration fits and the engine's linearization; `runner.compare(scenarios=[first])`):
a small relative error acts linearly at any amplitude. A default's run takes every
declared scenario and the frequency checks, since a default's effect depends on the
amplitude (an error-correction bias that is invisible on a small swing acts on a large
one). The near-equilibrium checks and the checks that build their own mechanisms (a
stability threshold's trials) are not run. The unmutated run is made in the calling
process (its solves are shared); every other run is a worker process
(comparisons/isolation.py), so an engine that crashes on a mutated model costs that run.
"""
from __future__ import annotations

import dataclasses
import math
import statistics
import time
from dataclasses import dataclass, field
from typing import Iterable, Mapping

import numpy as np

from ..analytic.linear import operating_equilibrium, unexcited_values
from ..analytic.numeric import numeric_model
from ..analytic.reference import reference
from ..simulators import get_backend
from ..systems import get_system
from . import metrics
from .isolation import WorkerCrashed, WorkerTimedOut, isolated
from .runner import DEFAULT_DT, Comparison, compare, isolated_compare

#: the decade grid of relative model errors, ascending
EPSILONS = tuple(10.0 ** -k for k in range(6, 0, -1))
#: the relative error at which the motion change is measured against the gates
PROBE = 1e-2
#: per error kind, the units of the parameters it applies to (gravity: the parameter g)
ERROR_KINDS: dict[str, tuple[str, ...]] = {
    "mass": ("kg",),
    "inertia": ("kg m^2",),
    "length": ("m",),
    "gravity": (),
    "stiffness": ("N/m", "N m/rad", "N m^2"),
    "damping": ("N s/m", "N m s"),
}
GRAVITY_PARAMETER = "g"
#: wall-clock budget of one run: this many times the unmutated run's engine stepping, at
#: least RUN_TIMEOUT_FLOOR s (per scenario run); a run beyond it is recorded as timed out (its `run.completed`
#: fails, so it counts as rejected). The budget exists for the free-vibration fits, whose
#: least squares can search for minutes on a motion that no longer oscillates (a joint
#: locked by a default motor)
RUN_TIMEOUT_FACTOR = 20.0
RUN_TIMEOUT_FLOOR = 30.0
#: statuses of a metric that holds
HOLDS = ("pass", "xpass")
#: statuses of a metric that fails (a declared failure included: it is a fail too)
FAILS = ("fail", "xfail")
#: the metrics of the out-of-the-box reading (name suffix or prefix)
EFFECT_SUFFIXES = (".trajectory_max", ".energy_drift", ".period")
EFFECT_PREFIXES = ("frequency.", "damping.")


@dataclass
class Trial:
    eps: float
    rejected: bool
    #: the metrics that hold in the baseline and fail here
    rejected_by: list[str] = field(default_factory=list)
    passed: bool = True
    wall_time_s: float = 0.0


@dataclass
class ErrorPower:
    kind: str
    parameter: str | None
    applicable: bool
    reason: str = ""
    #: smallest eps of the grid the gates reject (None: not even the largest)
    smallest_rejected: float | None = None
    trials: list[Trial] = field(default_factory=list)
    #: the exact model's change at eps = PROBE against the gates (see the module doc)
    motion_change: dict = field(default_factory=dict)


@dataclass
class DefaultPower:
    setting: str
    #: the engine's out-of-the-box value (at this step) and the harness's
    engine_value: object
    harness_value: object
    rejected: bool
    rejected_by: list[str] = field(default_factory=list)
    passed: bool = True
    #: whether any metric moved at all (False: the setting does not act on this build)
    acts: bool = True
    #: per metric of the out-of-the-box reading: neutralised value, switched-on value,
    #: tolerance, unit
    effect: dict = field(default_factory=dict)
    note: str = ""
    #: a run that did not complete (crashed, timed_out, diverged), with its message
    incidents: list = field(default_factory=list)
    wall_time_s: float = 0.0
    #: each declared scenario run with the default against the same run without it (one
    #: engine run each, whatever the comparison's fate), under "scenarios":
    #: `trajectory_change`, the largest |q_on - q_off| relative to the reference's
    #: amplitude, against the scenario's trajectory gate; `energy_drift` of each run
    #: (conservative mechanisms), relative to the largest kinetic energy. At the top
    #: level, the scenario where the change is largest against its gate
    motion: dict = field(default_factory=dict)


@dataclass
class PowerEntry:
    system: str
    simulator: str
    engine_version: str = ""
    supported: bool = True
    reason: str = ""
    scenario: str = ""
    #: the scenarios the defaults are switched on in (every declared one)
    defaults_scenarios: list[str] = field(default_factory=list)
    dt: float = DEFAULT_DT
    #: the unmutated run: passed, and the metrics that do not hold in it (they cannot
    #: reject anything)
    baseline_passed: bool = True
    baseline_not_holding: list[str] = field(default_factory=list)
    errors: list[ErrorPower] = field(default_factory=list)
    defaults: list[DefaultPower] = field(default_factory=list)
    comparisons: int = 0
    wall_time_s: float = 0.0
    engine_time_s: float = 0.0

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def rejecting_metrics(baseline: Comparison, run: Comparison) -> list[str]:
    """The metrics of `run` that fail while they hold in `baseline` (a metric the baseline
    does not have, such as a run's `completed`, counts when it fails)."""
    before = {m.name: m.status for m in baseline.metrics}
    return [m.name for m in run.metrics
            if m.status in FAILS and before.get(m.name, "pass") in HOLDS]


def _dynamics(mech):
    """The mechanism without its drawing shapes (what the engine's dynamics see)."""
    return dataclasses.replace(mech, bodies=tuple(dataclasses.replace(b, shapes=())
                                                  for b in mech.bodies))


def mutated_parameter(system, kind: str, values: Mapping[str, float]) -> str | None:
    """The parameter an error of `kind` is injected into (see the module doc), or None."""
    if kind == "gravity":
        names = [GRAVITY_PARAMETER] if GRAVITY_PARAMETER in values else []
    else:
        names = [p.name for p in system.parameters
                 if p.unit in ERROR_KINDS[kind] and not p.structural and p.name in values]
    true = _dynamics(system.numeric_mechanism(values))
    for name in names:
        if values[name] == 0:
            continue  # a zero coefficient scaled stays zero
        scaled = {**values, name: values[name] * (1 + PROBE)}
        if _dynamics(system.numeric_mechanism(scaled)) != true:
            return name
    return None


def free_coordinates(system, values) -> list[int]:
    """The coordinates the engine integrates (a driven system's prescribed ones aside)."""
    model = numeric_model(system.id, values)
    return (list(model.independent) if system.mechanism.prescribed
            else list(range(len(system.coordinates))))


def metric_named(c: Comparison, name: str):
    """The metric of `c` called `name`, or None."""
    return next((m for m in c.metrics if m.name == name), None)


def motion_change(system, scenario, values, parameter: str, baseline: Comparison,
                  dt: float) -> dict:
    """The exact model's change when `parameter` is PROBE off: the largest trajectory
    difference on `scenario` relative to the amplitude (as the trajectory gate measures)
    and the largest relative change of a mode's frequency, each against the baseline's
    gate (its tolerance)."""
    ref = reference(system, scenario, values, dt)
    mutated = {**values, parameter: values[parameter] * (1 + PROBE)}
    other = reference(system, scenario, mutated, dt)
    free = free_coordinates(system, values)
    eq = operating_equilibrium(system, values)
    scale = metrics.amplitude(ref.q[:, free], eq.q[free])
    n = min(len(ref.t), len(other.t))
    trajectory, _ = metrics.trajectory_errors(other.q[:n, free], ref.q[:n, free], scale)
    out: dict = {"eps": PROBE, "trajectory": trajectory}
    gate = metric_named(baseline, f"{scenario.name}.trajectory_max")
    if gate is not None:
        out["trajectory_gate"] = gate.tolerance
        out["trajectory_gate_status"] = gate.status
    # a driven mechanism: the actuator force the motion takes (judged on the same gate)
    forces = [float(np.max(np.abs(other.actuator_forces[a][:n] - f[:n])))
              / max(float(np.max(np.abs(f))), 1e-300)
              for a, f in (ref.actuator_forces or {}).items()
              if a in (other.actuator_forces or {})]
    if forces:
        out["actuator_force"] = max(forces)
    unexcited = unexcited_values(system, values) if system.mechanism.prescribed else values
    try:
        before = [m.frequency_hz for m in operating_equilibrium(system, unexcited).modes]
        after = [m.frequency_hz for m in operating_equilibrium(
            system, {**unexcited, parameter: unexcited[parameter] * (1 + PROBE)}).modes]
        changes = [abs(b - a) / a for a, b in zip(before, after) if a > 0]
        out["frequency"] = max(changes) if changes else None
    except (ValueError, RuntimeError, np.linalg.LinAlgError):
        out["frequency"] = None
    gates = [m for m in baseline.metrics if m.name.startswith("frequency.")
             and m.status != "unresolved"]
    if gates:
        out["frequency_gate"] = min(m.tolerance for m in gates)
    judged = gate is not None and gate.status != "unresolved"
    out["beyond_gate"] = bool(
        (judged and trajectory > gate.tolerance)
        or (judged and forces and out["actuator_force"] > gate.tolerance)
        or (out.get("frequency") is not None and gates
            and out["frequency"] > out["frequency_gate"]))
    return out


def effect_against(baseline: Comparison, run: Comparison) -> dict:
    """Per metric of the out-of-the-box reading (`EFFECT_SUFFIXES`, `EFFECT_PREFIXES`):
    its value in `baseline` and in `run`, the tolerance, unit and status."""
    before = {m.name: m for m in baseline.metrics}
    out = {}
    for m in run.metrics:
        if not (m.name.endswith(EFFECT_SUFFIXES) or m.name.startswith(EFFECT_PREFIXES)):
            continue
        b = before.get(m.name)
        out[m.name] = {"neutralised": b.value if b is not None else None,
                       "switched_on": m.value, "tolerance": m.tolerance, "unit": m.unit,
                       "status": m.status}
    return out


def same_metrics(a: Comparison, b: Comparison) -> bool:
    """Whether the two comparisons measured the same metrics with the same values."""
    va = {m.name: m.value for m in a.metrics}
    vb = {m.name: m.value for m in b.metrics}
    return va.keys() == vb.keys() and all(
        va[k] == vb[k] or (math.isnan(va[k]) and math.isnan(vb[k])) for k in va)


def power_entry(system_id: str, simulator: str, dt: float = DEFAULT_DT,
                kinds: Iterable[str] = tuple(ERROR_KINDS), defaults: bool = True
                ) -> PowerEntry:
    """The power study of one system on one engine (see the module doc)."""
    started = time.perf_counter()
    system = get_system(system_id)
    backend = get_backend(simulator)
    scenario = system.scenarios[0]
    entry = PowerEntry(system.id, simulator, scenario=scenario.name, dt=dt)
    ok, why = backend.available()
    if not ok:
        entry.supported, entry.reason = False, f"engine not available: {why}"
        return entry
    entry.engine_version = backend.version()
    values = system.parameter_values(None, scenario=scenario)
    system = system.with_structure(values)  # built for its number of elements

    # the unmutated run in this process: the reference solve, the derivations and the
    # equilibria it computes are then shared by every worker forked after it
    entry.comparisons += 1
    baseline = compare(system.id, simulator, dt=dt, scenarios=[scenario.name])
    entry.engine_time_s += baseline.wall_time
    budget = max(RUN_TIMEOUT_FLOOR, RUN_TIMEOUT_FACTOR * baseline.wall_time)

    def run(**kwargs) -> Comparison:
        entry.comparisons += 1
        c = isolated_compare(system.id, simulator, dt=dt, scenarios=[scenario.name],
                             timeout=budget, **kwargs)
        entry.engine_time_s += c.wall_time
        return c
    if not baseline.supported:
        entry.supported, entry.reason = False, baseline.reason
        entry.wall_time_s = time.perf_counter() - started
        return entry
    entry.baseline_passed = baseline.passed
    entry.baseline_not_holding = [m.name for m in baseline.metrics if m.status not in HOLDS
                                  and m.status != "measured"]
    for kind in kinds:
        entry.errors.append(_error_power(system, kind, values, scenario, baseline, dt, run))
    if defaults:
        declared = [sc.name for sc in system.scenarios]
        entry.defaults_scenarios = declared
        whole = (baseline if len(declared) == 1
                 else compare(system.id, simulator, dt=dt, scenarios=declared))
        entry.comparisons += len(declared) > 1

        def run_declared(**kwargs) -> Comparison:
            entry.comparisons += 1
            c = isolated_compare(system.id, simulator, dt=dt, scenarios=declared,
                                 timeout=budget * len(declared), **kwargs)
            entry.engine_time_s += c.wall_time
            return c

        entry.defaults = _defaults_power(system, backend, whole, dt, run_declared,
                                         budget)
    entry.wall_time_s = time.perf_counter() - started
    return entry


def _error_power(system, kind, values, scenario, baseline, dt, run) -> ErrorPower:
    parameter = mutated_parameter(system, kind, values)
    if parameter is None:
        return ErrorPower(kind, None, False,
                          f"no parameter of this kind enters the mechanism "
                          f"({', '.join(ERROR_KINDS[kind]) or GRAVITY_PARAMETER})")
    power = ErrorPower(kind, parameter, True)

    def trial(i: int) -> bool:
        eps = EPSILONS[i]
        started = time.perf_counter()
        c = run(engine_scale={parameter: 1 + eps})
        by = rejecting_metrics(baseline, c)
        power.trials.append(Trial(eps, bool(by), by, c.passed,
                                  time.perf_counter() - started))
        return bool(by)

    # bisection on the grid: the first index rejected, assuming monotone rejection
    lo, hi = 0, len(EPSILONS)
    while lo < hi:
        mid = (lo + hi) // 2
        if trial(mid):
            hi = mid
        else:
            lo = mid + 1
    power.smallest_rejected = EPSILONS[hi] if hi < len(EPSILONS) else None
    power.trials.sort(key=lambda t: t.eps)
    try:
        power.motion_change = motion_change(system, scenario, values, parameter, baseline, dt)
    except (ValueError, RuntimeError, np.linalg.LinAlgError) as exc:
        power.motion_change = {"eps": PROBE, "error": str(exc)}
    return power


def _defaults_power(system, backend, baseline: Comparison, dt: float, run,
                    budget: float) -> list[DefaultPower]:
    switched = engine_defaults(backend.id, dt)
    out = [_default_power(key, {key: value}, backend.SETTINGS[key].default, baseline, run,
                          backend.SETTINGS[key].note) for key, value in switched.items()]
    if len(switched) > 1:
        out.append(_default_power("all", switched, None, baseline, run,
                                  "every neutralised default switched back on together: "
                                  "the engine as it comes"))
    for scenario in system.scenarios:
        values = system.parameter_values(None, scenario=scenario)
        neutral = _scenario_run(system, backend, scenario, values, dt, {}, budget)
        gate = metric_named(baseline, f"{scenario.name}.trajectory_max")
        for d in out:
            chosen = switched if d.setting == "all" else {d.setting: switched[d.setting]}
            motion = _motion_against(neutral, _scenario_run(system, backend, scenario, values,
                                                            dt, chosen, budget))
            if gate is not None and "trajectory_change" in motion:
                motion["trajectory_gate"] = gate.tolerance
                motion["beyond_gate"] = bool(motion["trajectory_change"] > gate.tolerance)
            d.motion.setdefault("scenarios", {})[scenario.name] = motion
    for d in out:
        name, worst = worst_scenario(d.motion["scenarios"])
        d.motion.update(worst, scenario=name,
                        beyond_gate=any(m.get("beyond_gate", False)
                                        for m in d.motion["scenarios"].values()))
    return out


def engine_defaults(simulator: str, dt: float = DEFAULT_DT) -> dict[str, object]:
    """setting -> the engine's own value at step `dt`, for each setting the harness
    neutralises (its `engine_default` differs from the harness's value)."""
    out = {}
    for key, setting in get_backend(simulator).SETTINGS.items():
        value = setting.out_of_the_box(dt)
        if value is not None and value != setting.default:
            out[key] = value
    return out


def worst_scenario(scenarios: Mapping[str, dict]) -> tuple[str, dict]:
    """The scenario where a default moves the motion most against its gate (one without a
    measured change counts as infinitely moved)."""
    return max(scenarios.items(), key=lambda item: (
        item[1].get("trajectory_change", math.inf)
        / max(item[1].get("trajectory_gate", 1.0), 1e-300)))


def _default_power(key, settings, harness, baseline, run, note) -> DefaultPower:
    started = time.perf_counter()
    c = run(settings=settings)
    by = rejecting_metrics(baseline, c)
    return DefaultPower(key, settings[key] if key in settings else settings, harness,
                        bool(by), by, c.passed, acts=not same_metrics(baseline, c),
                        effect=effect_against(baseline, c), note=note, incidents=c.incidents,
                        wall_time_s=time.perf_counter() - started)


def _simulate_scenario(system, backend, scenario, values, dt, settings) -> dict:
    """One scenario on the engine with `settings` (a worker's task): the free
    coordinates relative to the reference's amplitude, and the energy drift."""
    ref = reference(system, scenario, values, dt)
    mech = system.numeric_mechanism(values)
    run = backend.simulate(mech, ref.q[0], ref.qd[0], scenario.t_end, dt,
                           backend.resolve_settings(settings), ())
    free = free_coordinates(system, values)
    eq = operating_equilibrium(system, values)
    scale = metrics.amplitude(ref.q[:, free], eq.q[free])
    n = min(len(ref.t), len(run.t))
    out = {"q": run.q[:n, free] / scale, "energy_drift": None}
    if ref.energy is not None:
        model = numeric_model(system.id, values)
        energy = model.energy(run.q[:n], run.qd[:n])
        kinetic = max(max(0.5 * v @ model.mass_matrix(x) @ v
                          for x, v in zip(ref.q[::10], ref.qd[::10])), 1e-300)
        out["energy_drift"] = float(np.max(np.abs(energy - energy[0]))) / kinetic
    return out


def _scenario_run(system, backend, scenario, values, dt, settings, budget) -> dict:
    try:
        return isolated(_simulate_scenario, system, backend, scenario, values, dt, settings,
                        timeout=budget)
    except (WorkerCrashed, WorkerTimedOut, ValueError, RuntimeError) as exc:
        return {"error": f"{type(exc).__name__}: {exc}"}


def _motion_against(neutral: dict, switched: dict) -> dict:
    if "error" in neutral or "error" in switched:
        return {"error": neutral.get("error") or switched.get("error")}
    q_off, q_on = neutral["q"], switched["q"]
    n = min(len(q_off), len(q_on))
    with np.errstate(invalid="ignore"):
        change = float(np.max(np.abs(q_on[:n] - q_off[:n]))) if n else float("nan")
    return {"trajectory_change": change if np.isfinite(change) else float("inf"),
            "energy_drift_neutralised": neutral["energy_drift"],
            "energy_drift_switched_on": switched["energy_drift"]}


@dataclass
class PowerStudy:
    entries: list[PowerEntry]
    provenance: dict = field(default_factory=dict)

    def summary(self) -> dict:
        """See `summary_of`."""
        return summary_of([e.as_dict() for e in self.entries])

    def as_dict(self) -> dict:
        return {"provenance": self.provenance, "epsilons": list(EPSILONS), "probe": PROBE,
                "error_kinds": {k: list(v) or [GRAVITY_PARAMETER]
                                for k, v in ERROR_KINDS.items()},
                "summary": self.summary(), "entries": [e.as_dict() for e in self.entries]}

    def out_of_the_box(self) -> dict:
        """The out-of-the-box reading (see `out_of_the_box_document`)."""
        return out_of_the_box_document(self.as_dict())


def summary_of(entries: list[dict]) -> dict:
    """Per engine and error kind, over the saved entries where the kind applies: the median
    (the lower one of an even count) smallest rejected eps, where an error the gates
    rejected not even at the largest eps counts as above the grid; how many systems, and
    how many of them rejected nothing. Per engine, how many switched-on defaults that act
    (alone) were rejected, and those that were not."""
    out: dict = {}
    for sim in dict.fromkeys(e["simulator"] for e in entries):
        mine = [e for e in entries if e["simulator"] == sim and e["supported"]]
        row = {}
        for kind in ERROR_KINDS:
            found = [p["smallest_rejected"] for e in mine for p in e["errors"]
                     if p["kind"] == kind and p["applicable"]]
            ranked = [math.inf if x is None else x for x in found]
            median = statistics.median_low(ranked) if ranked else None
            row[kind] = {"median_smallest_rejected": "above grid" if median == math.inf
                         else median,
                         "systems": len(found),
                         "not_rejected_at_largest": sum(x is None for x in found)}
        acting = [(e["system"], d) for e in mine for d in e["defaults"]
                  if d["acts"] and d["setting"] != "all"]
        row["defaults"] = {"acting": len(acting),
                           "rejected": sum(d["rejected"] for _, d in acting),
                           "not_rejected": [f"{system}:{d['setting']}"
                                            for system, d in acting if not d["rejected"]]}
        out[sim] = row
    return out


def out_of_the_box_document(power: dict) -> dict:
    """The out-of-the-box reading of a power study (its saved document): per system x
    engine, each default switched on, its verdict and its effect against the neutralised
    run."""
    keep = ("setting", "engine_value", "harness_value", "acts", "rejected", "rejected_by",
            "effect", "motion", "incidents", "note")
    return {"provenance": power["provenance"], "entries": [
        {**{k: e[k] for k in ("system", "simulator", "engine_version", "scenario",
                              "defaults_scenarios", "dt", "supported", "reason")},
         "defaults": [{k: d[k] for k in keep} for d in e["defaults"]]}
        for e in power["entries"]]}


def power_study(systems: Iterable[str], sims: Iterable[str], dt: float = DEFAULT_DT,
                progress=None) -> PowerStudy:
    """`power_entry` for every system x engine (in that order)."""
    from .runner import provenance

    entries = []
    for system_id in systems:
        for sim in sims:
            entry = power_entry(system_id, sim, dt)
            entries.append(entry)
            if progress is not None:
                progress(entry)
    return PowerStudy(entries, provenance())
