"""Gate power: what the comparison's gates catch (the mutation study), and what each
engine default the harness neutralises does when it is switched back on (the out-of-the-box
reading, comparisons/out_of_the_box.py, made from the same runs).

Model errors are injected into the engine's build only (`runner.compare(engine_scale=)`):
one parameter of each kind (a mass, an inertia, a length, g, a spring stiffness, a damping
coefficient) is multiplied by (1 + eps) while the reference and the gates keep the true
values. The parameter of a kind is the first one of the system (declaration order) with
that kind's unit whose change changes the numeric mechanism the engine is given (drawing
shapes aside); a kind without one is not applicable.

Rejection (`rejecting_metrics`): a metric that holds in the unmutated, neutralised run (the
baseline) rejects a run when it fails there, or when its value exceeds the baseline's
tolerance; a metric that does not hold in the baseline (a declared failure) rejects it when
its value exceeds the baseline's by more than the tolerance (the run is then farther from
the neutralised engine than the gate); a run that did not complete is rejected. The gates
are held at the harness's configuration: a default that changes the scheme the engine
declares (MuJoCo's Euler integrator, Exudyn's solver) would otherwise be judged against
the a-priori bound of its own, lower order, and pass while it moves the motion by far more
than the harness's gate. A model error's or a default's run is judged at the baseline's
gates outright (`runner.compare(held_gates=)`): a metric the baseline judged by the
engine's refinement keeps that gate instead of refining the run again (the gate is the
harness configuration's convergence; the rule above rejects a value beyond the baseline's
tolerance either way), and one whose limit the baseline judged on its run at h/K is
judged on the run at h/K against the baseline's bound on the limit (an error that moves
the engine's limit off the reference is caught there, where the bound at h is too wide
to catch it).

First, the change that a 1 % error (`PROBE`) makes in the exact model (reference with
the mutated parameter against the true one: the first scenario's trajectory and actuator
forces, and the modes' frequencies) is set against the gate of each of those quantities,
so that an error too small to move a judged quantity beyond its gate ("below the gates")
is told apart from a blind gate (`classify_error`). Then the smallest rejected eps on the
decade grid `EPSILONS` is found assuming rejection is monotone in eps (a larger error is
rejected whenever a smaller one is), by `first_rejected`: the search starts at the decade
that change predicts (`predicted_start`: a small error acts linearly, so the gate's
margin is first exceeded near PROBE times margin over change), tries its neighbour on the
side the first answer points to, and bisects what is left: two runs where the prediction
holds, at most five otherwise, as the plain bisection of the grid. The prediction only
orders the runs; the answer is that of the runs. `ErrorPower.monotone` records whether
the runs made agree with the assumption.

Each neutralised default (`Setting.engine_default`) is switched back on alone, and all
together (the engine as a user gets it), in comparisons/out_of_the_box.py. A default acts
when it changes a judged quantity by more than its gate, measured (`largest_change`): the
engine's motion with the default against the same run without it, relative to the
amplitude, against the scenario's trajectory gate; and each metric's change against its
tolerance (a lower bound of the change of the quantity it judges, by the triangle
inequality). `classify_default` gives each reading its verdict and why.

Cost: a model error's run is the system's first scenario plus the frequency checks
(free-vibration fits and the engine's linearization; `runner.compare(scenarios=[first])`):
a small relative error acts linearly at any amplitude. Held at the baseline's gates, a
model error's or a default's run adds no refinement runs but the one at the finest step
where the baseline judged the engine's limit. A default's run takes every
declared scenario and the frequency checks, since a default's effect depends on the
amplitude (an error-correction bias that is invisible on a small swing acts on a large
one). The neutralised run over every declared scenario is the baseline of both, made once
in the calling process (its solves are shared); every other run is a worker process
(comparisons/isolation.py), so an engine that crashes on a mutated model costs that run.
The near-equilibrium checks and the checks that build their own mechanisms (a stability
threshold's trials) are not run.
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
from . import metrics
from .runner import DEFAULT_DT, Comparison

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
#: wall-clock budget of one model error's run: this many times the baseline's engine
#: stepping, at least RUN_TIMEOUT_FLOOR s; a run beyond it is recorded as timed out (its
#: `run.completed` fails, so it counts as rejected). The budget exists for the
#: free-vibration fits, whose least squares can search for minutes on a motion that no
#: longer oscillates
RUN_TIMEOUT_FACTOR = 20.0
RUN_TIMEOUT_FLOOR = 30.0
#: statuses of a metric that holds
HOLDS = ("pass", "xpass")
#: statuses of a metric that fails (a declared failure included: it is a fail too)
FAILS = ("fail", "xfail")
#: the metrics of the out-of-the-box reading (name suffix or prefix)
EFFECT_SUFFIXES = (".trajectory_max", ".energy_drift", ".period")
EFFECT_PREFIXES = ("frequency.", "damping.")
#: verdicts of a default switched on, or of a 1 % model error (`classify_default`,
#: `classify_error`): caught; moves nothing; moves the judged quantities, each within its
#: gate; moves one beyond its gate and is not caught (a defect of the gates)
REJECTED, NO_EFFECT, BELOW_GATES, NOT_REJECTED = (
    "rejected", "no effect", "below the gates", "not rejected")
#: a default that moves the motion beyond the gate toward the reference: the metric
#: judging what it moves has a smaller error with it (nothing for a gate to reject)
CLOSER = "closer to the reference"
#: a default that moves a motion the engine does not produce without it (its run stops or
#: diverges there, a declared failure): no value of the neutralised run to compare with
ON_FAILED_RUN = "on a failed run"


@dataclass
class Trial:
    eps: float
    rejected: bool
    #: the metrics that hold in the baseline and reject this run
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
    #: whether the trials made agree with rejection monotone in eps
    monotone: bool = True
    #: the exact model's change at eps = PROBE against the gates (see the module doc)
    motion_change: dict = field(default_factory=dict)
    #: at eps = PROBE: REJECTED, BELOW_GATES or NOT_REJECTED, and why (`classify_error`)
    verdict: str = ""
    why: str = ""


@dataclass
class DefaultPower:
    setting: str
    #: the engine's out-of-the-box value (at this step) and the harness's
    engine_value: object
    harness_value: object
    rejected: bool
    rejected_by: list[str] = field(default_factory=list)
    passed: bool = True
    #: whether it changes a judged quantity by more than its gate (`largest_change`)
    acts: bool = True
    #: whether any metric moved at all (False: the setting does not act on this build)
    moved: bool = True
    #: the judged quantity it changes most against its gate: quantity, change, gate, ratio
    change: dict = field(default_factory=dict)
    #: REJECTED, NO_EFFECT, BELOW_GATES, CLOSER, ON_FAILED_RUN or NOT_REJECTED, and why
    #: (`classify_default`)
    verdict: str = ""
    why: str = ""
    #: per metric of the out-of-the-box reading: neutralised value, switched-on value,
    #: tolerance, unit
    effect: dict = field(default_factory=dict)
    note: str = ""
    #: a run that did not complete (crashed, timed_out, diverged), with its message
    incidents: list = field(default_factory=list)
    wall_time_s: float = 0.0
    #: per declared scenario ("scenarios"): `trajectory_change`, the largest
    #: |q_on - q_off| relative to the amplitude, against the scenario's trajectory gate,
    #: and the energy drift of both runs; at the top level, the scenario where the change
    #: is largest against its gate
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
    #: the neutralised, unmutated run: passed, and the metrics that do not hold in it
    #: (they cannot reject anything)
    baseline_passed: bool = True
    baseline_not_holding: list[str] = field(default_factory=list)
    errors: list[ErrorPower] = field(default_factory=list)
    defaults: list[DefaultPower] = field(default_factory=list)
    comparisons: int = 0
    wall_time_s: float = 0.0
    engine_time_s: float = 0.0
    #: taken from the persistent cache (comparisons/out_of_the_box.py, `cached_entry`):
    #: its timings are those of the run that made it
    from_cache: bool = False
    #: taken from a recorded study (`recorded_readings`): the state of the package that
    #: made it (its `git describe`); empty for a reading made by this study
    recorded: str = ""

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, d: Mapping) -> "PowerEntry":
        """The entry `as_dict` gave (a key this version does not know is an error)."""
        d = dict(d)
        d["errors"] = [ErrorPower(**{**p, "trials": [Trial(**t) for t in p.get("trials", [])]})
                       for p in d.get("errors", [])]
        d["defaults"] = [DefaultPower(**x) for x in d.get("defaults", [])]
        return cls(**d)


#: marks a metric that rejects a run by exceeding the baseline's own failing value by
#: more than its tolerance (`rejecting_metrics`)
BEYOND_BASELINE = " (beyond the baseline's error)"


def rejecting_metrics(baseline: Comparison, run: Comparison) -> list[str]:
    """The metrics of `run` that reject it (see the module doc): each metric that holds in
    `baseline` and fails in `run` or exceeds the baseline's tolerance (a value that is not
    finite exceeds it); each metric that does not hold in `baseline` (a declared failure,
    unresolved) and exceeds the baseline's value by more than the baseline's tolerance,
    marked `BEYOND_BASELINE`: the run then differs from the neutralised engine by more
    than the gate (triangle inequality), a change the engine's known error does not
    explain; a metric the baseline does not have (a run's `completed`) counts when it
    fails."""
    before = {m.name: m for m in baseline.metrics}
    out = []
    for m in run.metrics:
        b = before.get(m.name)
        if b is None:
            if m.status in FAILS:
                out.append(m.name)
        elif b.status in HOLDS:
            if m.status in FAILS or not m.value <= b.tolerance:
                out.append(m.name)
        elif (b.status in FAILS + ("unresolved",) and np.isfinite(b.value)
              and np.isfinite(b.tolerance) and not m.value <= b.value + b.tolerance):
            out.append(m.name + BEYOND_BASELINE)
    return out


def largest_change(baseline: Comparison, run: Comparison, scenarios: Mapping[str, dict]
                   ) -> dict:
    """The judged quantity `run` changes most against its gate, from `baseline`: each
    scenario's motion change (`trajectory_change` against `trajectory_gate`, in
    `scenarios`) and each metric holding in the baseline, |value - baseline's| against the
    baseline's tolerance. {} when nothing was measured."""
    found = []
    for name, m in scenarios.items():
        if "trajectory_change" in m and m.get("trajectory_gate"):
            found.append((f"{name}.motion", m["trajectory_change"], m["trajectory_gate"]))
    after = {m.name: m for m in run.metrics}
    for b in baseline.metrics:
        m = after.get(b.name)
        if m is None or b.status not in HOLDS or not b.tolerance > 0:
            continue
        with np.errstate(invalid="ignore"):
            moved = abs(float(m.value) - float(b.value))
        found.append((b.name, moved if np.isfinite(moved) else math.inf, b.tolerance))
    if not found:
        return {}
    quantity, change, gate = max(found, key=lambda f: f[1] / f[2])
    return {"quantity": quantity, "change": change, "gate": gate, "ratio": change / gate}


def classify_default(d: DefaultPower, baseline: Comparison) -> None:
    """`d.acts`, `d.verdict` and `d.why` from its reading (in place): rejected; no effect
    (no metric moved); below the gates (its largest change against a gate is within it);
    closer to the reference (the quantity it moves most beyond its gate is judged with a
    smaller error with it); on a failed run (the metric judging it has no finite value
    without it: the engine's run stops or diverges there); not rejected (a judged quantity
    moved beyond its gate, away from the reference or unjudged, and no gate caught it: the
    metric that judges it, named, and its status in the baseline). An incident of the run
    acts only where the baseline does not have it too; a change where no metric moved is
    none."""
    c = d.change
    shared = {(i["scenario"], i["stage"]) for i in baseline.incidents}
    d.acts = bool(c and c["ratio"] > 1.0) and d.moved or any(
        (i["scenario"], i["stage"]) not in shared for i in d.incidents)
    if d.rejected:
        d.verdict = REJECTED
        d.why = (f"rejected by {', '.join(d.rejected_by[:4])}"
                 + (f" (+{len(d.rejected_by) - 4})" if len(d.rejected_by) > 4 else ""))
    elif not d.moved:
        d.verdict, d.why = NO_EFFECT, "no metric moved: the setting does not act on this build"
    elif not d.acts:
        d.verdict = BELOW_GATES
        d.why = (f"largest change {c['change']:.3g} of {c['quantity']}, within its gate "
                 f"{c['gate']:.3g}" if c else "nothing measured beyond a gate")
    else:
        name = (c["quantity"][:-len(".motion")] + ".trajectory_max"
                if c["quantity"].endswith(".motion") else c["quantity"])
        judged = d.effect.get(name)
        moved = f"{c['quantity']} changes by {c['change']:.3g} against a gate of {c['gate']:.3g}"
        if judged is not None and judged["neutralised"] is not None \
                and not math.isfinite(judged["neutralised"]):
            d.verdict = ON_FAILED_RUN
            d.why = (f"{moved}: {name} is {judged['neutralised']:.3g} without it (the "
                     f"engine's run is not finite there), nothing to compare with")
        elif judged is not None and judged["switched_on"] < judged["neutralised"]:
            d.verdict = CLOSER
            d.why = (f"{moved}, toward the reference: {name} {judged['neutralised']:.3g} "
                     f"without it, {judged['switched_on']:.3g} with it")
        else:
            d.verdict = NOT_REJECTED
            d.why = f"{moved}, {_why_not_caught(c['quantity'], baseline)}"


def _why_not_caught(quantity: str, baseline: Comparison) -> str:
    """Why the metric judging `quantity` did not reject the change."""
    if quantity.endswith(".motion"):
        name = quantity[:-len(".motion")] + ".trajectory_max"
        m = metric_named(baseline, name)
        if m is None:
            return "and no trajectory metric judges that scenario"
        if m.status not in HOLDS:
            return (f"and {name} is {m.status} without it: what the change adds to that "
                    f"error stays within its gate")
        return (f"yet {name} stays within its gate: the change offsets the engine's own "
                f"error ({m.value:.3g} without it)")
    m = metric_named(baseline, quantity)
    return f"and {quantity} is {m.status if m is not None else 'absent'} without it"


def classify_error(power: ErrorPower) -> None:
    """`power.verdict` and `why` at eps = PROBE (in place): rejected when the smallest
    rejected eps is at most PROBE; otherwise below the gates when the exact model's change
    at PROBE is within the gate of each quantity measured (named, with its change), and
    not rejected (a blind gate) when one of them is beyond its gate."""
    if not power.applicable:
        return
    mc = power.motion_change
    if power.smallest_rejected is not None and power.smallest_rejected <= PROBE:
        power.verdict = REJECTED
        power.why = f"rejected from eps = {power.smallest_rejected:.0e}"
        return
    ratios = mc.get("against_gates", {})
    worst = max(ratios.items(), key=lambda kv: kv[1]["ratio"], default=None)
    if worst is None:
        power.verdict = NOT_REJECTED
        power.why = ("no judged quantity's change could be measured in the exact model"
                     + (f" ({mc['error']})" if "error" in mc else ""))
    elif not mc.get("beyond_gate"):
        power.verdict = BELOW_GATES
        name, w = worst
        power.why = (f"the exact model's judged quantities ({', '.join(ratios)}) do not "
                     f"depend on {power.parameter}: each changes by 0 at {PROBE:.0%}"
                     if all(v["change"] == 0 for v in ratios.values()) else
                     f"a {PROBE:.0%} error moves no judged quantity beyond its gate: "
                     f"largest {name} {w['change']:.3g} against {w['gate']:.3g}")
    else:
        power.verdict = NOT_REJECTED
        name, w = worst
        power.why = (f"a {PROBE:.0%} error moves {name} by {w['change']:.3g} against a gate "
                     f"of {w['gate']:.3g} ({w['status']}), and no gate rejects it")


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
    """The exact model's change when `parameter` is PROBE off, each judged quantity
    against the baseline's gate of the metric that judges it ("against_gates": change,
    gate, the metric's status, ratio): the largest trajectory difference on `scenario`
    relative to the amplitude (the trajectory gate's measure), each actuator's force
    relative to its largest (its `actuator_*` metric's) and the largest relative change of
    a mode's frequency (the tightest judged frequency gate). `beyond_gate`: a quantity
    beyond the gate of a metric that holds in the baseline."""
    ref = reference(system, scenario, values, dt)
    mutated = {**values, parameter: values[parameter] * (1 + PROBE)}
    other = reference(system, scenario, mutated, dt)
    free = free_coordinates(system, values)
    eq = operating_equilibrium(system, values)
    scale = metrics.amplitude(ref.q[:, free], eq.q[free])
    n = min(len(ref.t), len(other.t))
    trajectory, _ = metrics.trajectory_errors(other.q[:n, free], ref.q[:n, free], scale)
    out: dict = {"eps": PROBE, "trajectory": trajectory}
    against: dict = {}

    def judged(quantity: str, change: float, metric_name: str) -> None:
        m = metric_named(baseline, metric_name)
        if m is not None and m.tolerance > 0:
            against[quantity] = {"change": change, "gate": m.tolerance, "metric": m.name,
                                 "status": m.status, "ratio": change / m.tolerance}

    judged("trajectory", trajectory, f"{scenario.name}.trajectory_max")
    gate = metric_named(baseline, f"{scenario.name}.trajectory_max")
    if gate is not None:
        out["trajectory_gate"] = gate.tolerance
        out["trajectory_gate_status"] = gate.status
    forces = {}
    for a, f in (ref.actuator_forces or {}).items():
        if a not in (other.actuator_forces or {}):
            continue
        ok = np.isfinite(f[:n]) & np.isfinite(other.actuator_forces[a][:n])
        forces[a] = (float(np.max(np.abs(other.actuator_forces[a][:n][ok] - f[:n][ok])))
                     / max(float(np.max(np.abs(f[:n][ok]))), 1e-300))
        judged(f"actuator {a}", forces[a], f"{scenario.name}.actuator_{a}")
    if forces:
        out["actuator_force"] = max(forces.values())
    unexcited = unexcited_values(system, values) if system.mechanism.prescribed else values
    changes: list[float] = []
    try:
        # the oscillating modes, numbered as the frequency metrics number them
        before = [m.frequency_hz for m in operating_equilibrium(system, unexcited).modes
                  if m.frequency_hz > 0]
        after = [m.frequency_hz for m in operating_equilibrium(
            system, {**unexcited, parameter: unexcited[parameter] * (1 + PROBE)}).modes
            if m.frequency_hz > 0]
        changes = [abs(b - a) / a for a, b in zip(before, after)]
        out["frequency"] = max(changes) if changes else None
    except (ValueError, RuntimeError, np.linalg.LinAlgError):
        out["frequency"] = None
    gates = [m for m in baseline.metrics if m.name.startswith("frequency.")
             and m.status in HOLDS]
    if gates:
        out["frequency_gate"] = min(m.tolerance for m in gates)
    # each mode's change against the tightest gate that judges that mode (a mode no
    # frequency metric judges is left to the trajectory's gate)
    for i, change in enumerate(changes):
        mine = [m for m in gates if m.name.endswith(f"_mode{i + 1}")]
        if mine:
            judged(f"frequency mode {i + 1}", change,
                   min(mine, key=lambda m: m.tolerance).name)
    out["against_gates"] = against
    out["beyond_gate"] = any(v["ratio"] > 1.0 and v["status"] in HOLDS
                             for v in against.values())
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


def error_powers(system, simulator: str, kinds: Iterable[str], baseline: Comparison,
                 dt: float, run) -> list[ErrorPower]:
    """Each kind's smallest rejected eps against `baseline` (the neutralised, unmutated
    run); `run(engine_scale=)` makes one mutated comparison of the first scenario."""
    scenario = system.scenarios[0]
    values = system.parameter_values(None, scenario=scenario)
    system = system.with_structure(values)  # built for its number of elements
    return [_error_power(system, kind, values, scenario, baseline, dt, run) for kind in kinds]


def predicted_start(motion: Mapping, baseline: Comparison) -> int:
    """The grid index where the search for the smallest rejected eps starts: the smallest
    eps whose predicted change (linear in eps, from the exact model's change at PROBE)
    exceeds the margin of the metric that holds in `baseline` (tolerance minus its value)
    most nearly crossed; the grid's top where no such change was measured."""
    scale = 0.0
    for quantity in motion.get("against_gates", {}).values():
        m = metric_named(baseline, quantity["metric"])
        if m is None or m.status not in HOLDS or not quantity["change"] > 0:
            continue
        margin = m.tolerance - abs(m.value) if math.isfinite(m.value) else m.tolerance
        scale = max(scale, quantity["change"] / max(margin, 1e-300))
    if not scale > 0:
        return len(EPSILONS) - 1
    crossing = PROBE / scale
    return next((i for i, eps in enumerate(EPSILONS) if eps >= crossing), len(EPSILONS) - 1)


def first_rejected(rejects, start: int, size: int = len(EPSILONS)) -> int:
    """The first index of range(size) where `rejects(i)` holds (size: none), assuming it
    is monotone in i, found from `start`: `start`, its neighbour on the side its answer
    points to, then bisection of what remains."""
    lo, hi = 0, size  # the answer lies in [lo, hi]

    def probe(i: int) -> None:
        nonlocal lo, hi
        if rejects(i):
            hi = i
        else:
            lo = i + 1

    probe(start)
    neighbour = start - 1 if hi == start else start + 1
    if lo <= neighbour < hi:
        probe(neighbour)
    while lo < hi:
        mid = (lo + hi) // 2
        probe(mid)
    return hi


def _error_power(system, kind, values, scenario, baseline, dt, run) -> ErrorPower:
    parameter = mutated_parameter(system, kind, values)
    if parameter is None:
        return ErrorPower(kind, None, False,
                          f"no parameter of this kind enters the mechanism "
                          f"({', '.join(ERROR_KINDS[kind]) or GRAVITY_PARAMETER})")
    power = ErrorPower(kind, parameter, True)
    try:
        power.motion_change = motion_change(system, scenario, values, parameter, baseline, dt)
    except (ValueError, RuntimeError, np.linalg.LinAlgError) as exc:
        power.motion_change = {"eps": PROBE, "error": str(exc)}
    tried: dict[int, bool] = {}

    def trial(i: int) -> bool:
        eps = EPSILONS[i]
        started = time.perf_counter()
        c = run(engine_scale={parameter: 1 + eps})
        by = rejecting_metrics(baseline, c)
        power.trials.append(Trial(eps, bool(by), by, c.passed,
                                  time.perf_counter() - started))
        tried[i] = bool(by)
        return tried[i]

    hi = first_rejected(trial, predicted_start(power.motion_change, baseline))
    power.monotone = all(tried[j] for j in tried if j >= hi) and not any(
        tried[j] for j in tried if j < hi)
    power.smallest_rejected = EPSILONS[hi] if hi < len(EPSILONS) else None
    power.trials.sort(key=lambda t: t.eps)
    classify_error(power)
    return power


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


def summary_of(entries: list[dict]) -> dict:
    """Per engine and error kind, over the saved entries where the kind applies: the median
    (the lower one of an even count) smallest rejected eps, where an error the gates
    rejected not even at the largest eps counts as above the grid; how many systems, how
    many of them rejected nothing, and at eps = PROBE how many rejected, below the gates
    and not rejected (named: the blind spots). Per engine, the defaults switched on alone:
    how many act (beyond a gate), how many of those were rejected, those not rejected
    (blind spots), those that move the engine closer to the reference, and those that move
    it within the gates."""
    out: dict = {}
    for sim in dict.fromkeys(e["simulator"] for e in entries):
        mine = [e for e in entries if e["simulator"] == sim and e["supported"]]
        row = {}
        for kind in ERROR_KINDS:
            found = [(e["system"], p) for e in mine for p in e["errors"]
                     if p["kind"] == kind and p["applicable"]]
            ranked = [math.inf if p["smallest_rejected"] is None else p["smallest_rejected"]
                      for _, p in found]
            median = statistics.median_low(ranked) if ranked else None
            row[kind] = {"median_smallest_rejected": "above grid" if median == math.inf
                         else median,
                         "systems": len(found),
                         "not_rejected_at_largest": sum(
                             p["smallest_rejected"] is None for _, p in found),
                         "at_probe": {v: sum(p.get("verdict") == v for _, p in found)
                                      for v in (REJECTED, BELOW_GATES, NOT_REJECTED)},
                         "not_rejected": [s for s, p in found
                                          if p.get("verdict") == NOT_REJECTED]}
        alone = [(e["system"], d) for e in mine for d in e["defaults"] if d["setting"] != "all"]
        acting = [(s, d) for s, d in alone if d["acts"]]
        row["defaults"] = {"acting": len(acting),
                           "rejected": sum(d["rejected"] for _, d in acting),
                           "not_rejected": [f"{s}:{d['setting']}" for s, d in acting
                                            if d.get("verdict") == NOT_REJECTED],
                           "closer_to_reference": [f"{s}:{d['setting']}" for s, d in acting
                                                   if d.get("verdict") == CLOSER],
                           "on_failed_run": [f"{s}:{d['setting']}" for s, d in acting
                                             if d.get("verdict") == ON_FAILED_RUN],
                           "below_gates": [f"{s}:{d['setting']}" for s, d in alone
                                           if d.get("verdict") == BELOW_GATES]}
        out[sim] = row
    return out


def out_of_the_box_document(power: dict) -> dict:
    """The out-of-the-box reading of a power study (its saved document): per system x
    engine, each default switched on, its verdict and its effect against the neutralised
    run."""
    keep = ("setting", "engine_value", "harness_value", "acts", "moved", "change", "verdict",
            "why", "rejected", "rejected_by", "effect", "motion", "incidents", "note")
    doc = {"provenance": power["provenance"], "entries": [
        {**{k: e[k] for k in ("system", "simulator", "engine_version", "scenario",
                              "defaults_scenarios", "dt", "supported", "reason")},
         "recorded": e.get("recorded", ""),
         "defaults": [{k: d.get(k) for k in keep} for d in e["defaults"]]}
        for e in power["entries"]]}
    if "cost" in power:
        doc["cost"] = power["cost"]
    return doc


def power_document(entries: list[dict], provenance: dict, cost: dict | None = None) -> dict:
    """The saved power study (power.json): the grid, the error kinds, the summary, the
    entries and the study's cost."""
    doc = {"provenance": provenance, "epsilons": list(EPSILONS), "probe": PROBE,
           "error_kinds": {k: list(v) or [GRAVITY_PARAMETER] for k, v in ERROR_KINDS.items()},
           "summary": summary_of(entries), "entries": entries}
    if cost is not None:
        doc["cost"] = cost
    return doc
