"""Convergence and work-precision: for one engine on one scenario, the error against the
time step (max |q - q_ref| over the run, relative to the motion's amplitude) over a
sequence of halved steps, the observed order fitted on a log-log scale next to the order
the engine's scheme declares, and the CPU seconds of each run (work-precision).

The reference is solved once, at the finest step, and sampled at each coarser one (the
steps are integer multiples of the finest). The default steps are DEFAULT_STEPS, scaled
down where the motion's fastest frequency w puts the coarsest beyond the scheme's
asymptotic range (w h <= tolerances.asymptotic_limit, as for the gates); given steps beyond
it are run and drawn but not fitted. An error within REFERENCE_MARGIN times the
reference's own error (its tight solve's, estimated as the tight-loose difference scaled
by the ratio of their tolerances) measures the reference as much as the engine: those
points are left out of the fit (a closed-form reference has none). Where the error stops falling with the step, something
other than the step sets it (round-off, a constraint's compliance): the fit uses the steps
from the coarsest down to the last one that still lowered the error by `MIN_DECREASE`, and
needs `MIN_FIT_POINTS` of them; otherwise the order is not judged (`flattened`, metric
unresolved). The judged metric ``convergence.order`` is |fitted - declared| against
ORDER_TOLERANCE, with the expectations of comparisons (a system's or a backend's
declaration of the metric). Every mechanism x engine is one item of the sweep facility
(comparisons/sweep.py).

An engine that chooses its own steps for the mechanism (an error-controlled integrator:
the backend's `accuracy_knob`) is studied by its knob instead, the target accuracy eps,
swept by decades (DEFAULT_ACCURACIES) at one sampling step, its CPU seconds on the same
work-precision figure as the fixed-step engines' (the knob "step" runs it at a fixed step
under the backend's CONVERGENCE_SETTINGS, as the others). The sampling step is about 1/w
(`accuracy_sampling_step`), so that the controller, not the sampling, sets the steps
over the whole sweep. The judged metric ``convergence.accuracy`` is the largest ratio
per decade (e(eps / 100) / e(eps))^(1/2) over the judged accuracies (two decades apart:
tolerances.ACCURACY_SPAN_DECADES), against 1 / MIN_ACCURACY_DECREASE: the error must
fall with the accuracy until it reaches the reference's floor
(comparisons/tolerances.py gives the rule, its reason and its range: the mean step
T/N within w h <= asymptotic_limit, ACCURACY_CONTROLLED_STEPS steps per sample at
least). A model error stops the fall at its own floor, above the reference's, and fails
it. The slope of log(error) against log(eps) over the judged points is reported
(between q/(q+1) and 1 for an error estimate of order q).

A benchmark row (`System.benchmark_error`) is measured at every point in the benchmark's
own measure too (comparisons/benchmark_error.py: the published quantities' largest
absolute error, in their units, over the study's run): the work-precision figure the
benchmark asks for. It is recorded, not judged; a run that fails or diverges carries the
system's declared reason (`declared_failure`)."""
from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Mapping, Sequence

import numpy as np

from ..analytic.linear import operating_equilibrium
from ..analytic.reference import LOOSE, TIGHT, reference
from ..simulators import get_backend
from ..systems import get_system
from . import metrics, tolerances
from .benchmark_error import benchmark_errors, declared_failure
from .runner import Metric, _judge, expectation_for

#: the steps of a study (s): halvings, each an integer multiple of the finest; scaled down
#: where the motion is too fast for them (`automatic_steps`)
DEFAULT_STEPS = (4e-3, 2e-3, 1e-3, 5e-4)
#: a halving that lowers the error by less than this factor has reached a floor (an order
#: of 0.6 and above still lowers it by 1.5 per halving)
MIN_DECREASE = 1.5
MIN_FIT_POINTS = 3
#: the fitted order must match the declared one within this (issue 10)
ORDER_TOLERANCE = 0.5
#: a point is fitted when its error is at least this many times the reference's: the
#: reference then adds at most a third to it
REFERENCE_MARGIN = 3.0
#: simulated time of a study (s): several periods of every catalog mechanism, short
#: enough for the whole catalog in a report
DEFAULT_T_END = 2.0
#: the name of the judged metric
ORDER_METRIC = "convergence.order"
#: the judged metric of an error-controlled engine's study
ACCURACY_METRIC = "convergence.accuracy"
#: the target accuracies of an error-controlled engine's study, loose to tight
DEFAULT_ACCURACIES = tuple(10.0 ** -k for k in range(4, 13))
#: an accuracy study samples at about 1/w (w dt = SAMPLING_WH), at least MIN_SAMPLES times
SAMPLING_WH = 1.0
MIN_SAMPLES = 20


@dataclass
class ConvergencePoint:
    dt: float
    error: float          # max |q - q_ref| / amplitude
    wall_time: float      # s of stepping
    cpu_time: float       # CPU s of stepping
    steps: int            # samples
    #: an accuracy study's target accuracy and the steps its integrator took (else None)
    accuracy: float | None = None
    integrator_steps: int | None = None
    #: the benchmark's own error measure (`System.benchmark_error`, in its unit; NaN: the
    #: run did not complete); None for a system without one
    benchmark_error: float | None = None


@dataclass
class ConvergenceStudy:
    system: str
    scenario: str
    simulator: str
    engine_version: str
    integrator_order: int
    points: list[ConvergencePoint]
    #: slope of log(error) against log(dt) over the falling part (None: flattened)
    observed_order: float | None
    #: the steps the fit used (the falling part)
    fitted_steps: list[float] = field(default_factory=list)
    #: why the order is not judged, when it is not
    flattened: str = ""
    #: the reference's own error relative to the amplitude (0: a closed form), a floor
    #: for the errors
    reference_error: float = 0.0
    #: a run that failed (diverged, an engine error): the message
    failure: str = ""
    #: why the engine cannot build the mechanism, when it cannot
    unsupported: str = ""
    #: the motion's fastest angular frequency w (rad/s): steps with w h beyond the
    #: scheme's asymptotic range are not fitted
    frequency: float = 0.0
    #: the study's knob: "step" (fixed steps) or "accuracy" (an error-controlled engine)
    knob: str = "step"
    #: an accuracy study's judged accuracies (where the rule holds, above the floor), the
    #: largest error ratio per decade over them, and the slope of log(error) on log(eps)
    judged_accuracies: list[float] = field(default_factory=list)
    worst_decrease: float | None = None
    accuracy_slope: float | None = None
    #: the benchmark's error measure recorded at every point (`System.benchmark_error`):
    #: what it measures and its unit ('' for a system without one)
    benchmark_measure: str = ""
    benchmark_unit: str = ""
    #: why the engine does not complete the run, as the system declares it (its
    #: `<scenario>.completed` expected failure), where a run failed or diverged
    declared_failure: str = ""

    @property
    def order_matches(self) -> bool | None:
        """Whether the fitted order is the declared one within ORDER_TOLERANCE (None:
        not judged)."""
        if self.observed_order is None:
            return None
        return abs(self.observed_order - self.integrator_order) <= ORDER_TOLERANCE

    def as_dict(self) -> dict:
        d = asdict(self)
        d["order_matches"] = self.order_matches
        return d


def observed_order(dts: Sequence[float], errors: Sequence[float]) -> float:
    """Slope of log(error) against log(dt) (least squares)."""
    x, y = np.log(np.asarray(dts)), np.log(np.asarray(errors))
    return float(np.polyfit(x, y, 1)[0])


def falling_part(points: Sequence[ConvergencePoint],
                 floor: float = 0.0) -> list[ConvergencePoint]:
    """The points from the coarsest step down to the last halving that still lowered the
    error by MIN_DECREASE, without those whose error is below `floor`."""
    ordered = sorted(points, key=lambda p: -p.dt)
    kept = ordered[:1]
    for p in ordered[1:]:
        if not (np.isfinite(p.error) and p.error > floor
                and kept[-1].error / p.error >= MIN_DECREASE):
            break
        kept.append(p)
    return kept


def automatic_steps(w: float, order: int) -> tuple[float, ...]:
    """DEFAULT_STEPS, scaled down (halvings kept) so that the coarsest step is within the
    scheme's asymptotic range w h <= tolerances.asymptotic_limit(order), where the error's
    leading term, hence its order, dominates."""
    coarsest = min(DEFAULT_STEPS[0], tolerances.asymptotic_limit(order) / w) if w > 0 else \
        DEFAULT_STEPS[0]
    return tuple(coarsest * dt / DEFAULT_STEPS[0] for dt in DEFAULT_STEPS)


def convergence(system_id: str, simulator: str, scenario: str | None = None,
                dts: Sequence[float] | None = None, t_end: float | None = DEFAULT_T_END,
                settings: Mapping | None = None, knob: str = "auto",
                accuracies: Sequence[float] | None = None,
                engine_scale: Mapping[str, float] | None = None) -> ConvergenceStudy:
    """The study of one engine on one scenario (default: the system's first), over
    `t_end` seconds (None: the scenario's), at the steps `dts` (None: `automatic_steps`
    for the motion's fastest frequency). Steps outside the asymptotic range are run and
    shown but not fitted. `knob` "auto" studies an error-controlled engine by its target
    accuracy (`accuracies`, default DEFAULT_ACCURACIES) and the others by the step;
    "step" studies every engine by the step. `engine_scale` multiplies parameters in the
    engine's build only (an injected model error; the reference keeps the true values)."""
    from ..analytic.steady_state import excitation_frequencies
    from .runner import characteristic_frequency

    if knob not in ("auto", "step"):
        raise ValueError(f"the knob is 'auto' or 'step'; got {knob!r}")
    system = get_system(system_id)
    sc = system.scenario(scenario) if scenario else system.scenarios[0]
    values = system.parameter_values(scenario=sc)
    backend = get_backend(simulator)
    scale = engine_scale or {}
    mech = system.numeric_mechanism({k: v * scale.get(k, 1.0) for k, v in values.items()})
    by_accuracy = knob == "auto" and bool(backend.accuracy_knob(mech, settings))
    settings = {**({} if by_accuracy else backend.CONVERGENCE_SETTINGS), **(settings or {})}
    eq = operating_equilibrium(system, values)
    T = sc.t_end if t_end is None else min(t_end, sc.t_end)
    support = backend.support(mech)
    order = backend.scheme(mech, settings).order if support.ok else 0
    free = [i for i, c in enumerate(system.coordinates)
            if c not in system.mechanism.driven_coordinates]
    # the motion's fastest frequency, as the gates take it (runner.characteristic_frequency),
    # from a reference at the default step
    probe = reference(system, sc, values, DEFAULT_STEPS[2], T)
    w = characteristic_frequency(eq.modes, probe.q[:, free], probe.qd[:, free], eq.q[free])
    if system.driven:
        w = max([w] + excitation_frequencies(system, values))
    if by_accuracy:
        return _accuracy_study(system, sc.name, backend, mech, probe, free, eq.q[free], w,
                               T, order, settings, accuracies or DEFAULT_ACCURACIES, values)
    dts = tuple(sorted(dts if dts is not None else automatic_steps(w, max(order, 1)),
                       reverse=True))
    finest = min(dts)
    multiples = [int(round(dt / finest)) for dt in dts]
    if any(abs(k * finest - dt) > 1e-9 * dt for k, dt in zip(multiples, dts)):
        raise ValueError(f"the steps {list(dts)} must be integer multiples of the finest")
    ref = reference(system, sc, values, finest, T)
    scale = metrics.amplitude(ref.q[:, free], eq.q[free])
    # a closed form is exact to round-off (its error_estimate is DOP853's distance to it);
    # a DOP853 reference's own error is its tight solve's, about the tight-loose
    # difference times TIGHT / LOOSE
    exact = ref.method.startswith("closed form")
    reference_error = 0.0 if exact else float(
        np.max(np.asarray(ref.error_estimate)[free] / scale) * TIGHT / LOOSE)
    points: list[ConvergencePoint] = []
    study = ConvergenceStudy(system.id, sc.name, simulator, backend.version(), order, points,
                             None, reference_error=reference_error, frequency=w)
    _describe_benchmark(study, system)
    if not support.ok:
        study.unsupported = f"{simulator} cannot express {system.id}: {support.reason}"
        return study
    for dt, k in zip(dts, multiples):
        q_ref = ref.q[::k, free]
        try:
            run = backend.simulate(mech, ref.q[0], ref.qd[0], T, dt, settings)
        except Exception as exc:  # an engine's failure is a result of the study
            study.failure = f"dt = {dt:g}: {type(exc).__name__}: {exc}"
            study.declared_failure = declared_failure(system, simulator, sc.name)
            return study
        n = min(len(run.t), len(q_ref))
        err, _ = metrics.trajectory_errors(run.q[:n, free], q_ref[:n], scale)
        points.append(ConvergencePoint(dt, float(err), run.wall_time, run.cpu_time, n - 1,
                                       benchmark_error=_benchmark_error(
                                           system, values, mech, ref, run, k)))
        order = run.integrator_order
    _declare_diverged(study, system, sc.name)
    study.integrator_order = order
    limit = tolerances.asymptotic_limit(order)
    asymptotic = [p for p in points if w * p.dt <= limit * (1 + 1e-9)]
    falling = falling_part(asymptotic, REFERENCE_MARGIN * reference_error) if asymptotic \
        else []
    study.fitted_steps = [p.dt for p in falling]
    if len(falling) >= MIN_FIT_POINTS:
        study.observed_order = observed_order([p.dt for p in falling],
                                              [p.error for p in falling])
    elif len(asymptotic) < MIN_FIT_POINTS:
        study.flattened = (f"{len(asymptotic)} step(s) within the asymptotic range w h <= "
                           f"{limit:g} (w = {w:.4g} rad/s), {MIN_FIT_POINTS} needed for a fit")
    else:
        floor = falling[-1]
        study.flattened = (f"the error stops falling below dt = {floor.dt:g} (at "
                           f"{floor.error:.2g} of the amplitude; reference error "
                           f"{reference_error:.2g}): {len(falling)} falling point(s), "
                           f"{MIN_FIT_POINTS} needed for a fit")
    return study


def accuracy_sampling_step(w: float, t_end: float, finest: float) -> float:
    """The sampling step of an accuracy study: about SAMPLING_WH / w, at most t_end /
    MIN_SAMPLES, a multiple of the reference's step `finest`. The integrator's steps end
    on the samples, so a sampling step well above the controller's keeps the sampling from
    setting the steps."""
    wanted = min(SAMPLING_WH / w if w > 0 else t_end, t_end / MIN_SAMPLES)
    return max(1, int(wanted / finest + 1e-9)) * finest


def _describe_benchmark(study: ConvergenceStudy, system) -> None:
    """The study records the system's benchmark error measure, where it declares one."""
    if system.benchmark_error is not None:
        study.benchmark_measure = system.benchmark_error.description
        study.benchmark_unit = system.benchmark_error.unit


def _benchmark_error(system, values: Mapping[str, float], mech, ref, run,
                     stride: int) -> float | None:
    """The benchmark's error of `run`, sampled every `stride` samples of `ref` (None
    without a benchmark measure)."""
    if system.benchmark_error is None:
        return None
    return benchmark_errors(system, values, mech, ref, run.q, run.qd, stride)["error"]


def _declare_diverged(study: ConvergenceStudy, system, scenario: str) -> None:
    """A run that left the finite numbers: the system's declared reason, if any."""
    if any(not np.isfinite(p.error) for p in study.points):
        study.declared_failure = declared_failure(system, study.simulator, scenario)


def _accuracy_study(system, scenario: str, backend, mech, ref, free: list[int],
                    q_eq: np.ndarray, w: float, T: float, order: int, settings: Mapping,
                    accuracies: Sequence[float], values: Mapping[str, float]
                    ) -> ConvergenceStudy:
    """An error-controlled engine's study: its error at each target accuracy (loose to
    tight), sampled every `accuracy_sampling_step`, against the reference `ref` (sampled
    at DEFAULT_STEPS[2]), judged by the rule of tolerances.MIN_ACCURACY_DECREASE."""
    finest = DEFAULT_STEPS[2]
    dt = accuracy_sampling_step(w, T, finest)
    k = int(round(dt / finest))
    scale = metrics.amplitude(ref.q[:, free], q_eq)
    exact = ref.method.startswith("closed form")
    reference_error = 0.0 if exact else float(
        np.max(np.asarray(ref.error_estimate)[free] / scale) * TIGHT / LOOSE)
    points: list[ConvergencePoint] = []
    study = ConvergenceStudy(system.id, scenario, backend.id, backend.version(), order, points,
                             None, reference_error=reference_error, frequency=w,
                             knob="accuracy")
    _describe_benchmark(study, system)
    support = backend.support(mech)
    if not support.ok:
        study.unsupported = f"{backend.id} cannot express {system.id}: {support.reason}"
        return study
    q_ref = ref.q[::k, free]
    for eps in sorted(accuracies, reverse=True):
        try:
            run = backend.simulate(mech, ref.q[0], ref.qd[0], T, dt,
                                   {**settings, backend.ACCURACY_SETTING: float(eps)})
        except Exception as exc:  # an engine's failure is a result of the study
            study.failure = f"accuracy {eps:g}: {type(exc).__name__}: {exc}"
            study.declared_failure = declared_failure(system, backend.id, scenario)
            return study
        n = min(len(run.t), len(q_ref))
        err, _ = metrics.trajectory_errors(run.q[:n, free], q_ref[:n], scale)
        taken = run.error_control.steps if run.error_control else n - 1
        points.append(ConvergencePoint(dt, float(err), run.wall_time, run.cpu_time, n - 1,
                                       float(eps), int(taken),
                                       _benchmark_error(system, values, mech, ref, run, k)))
        study.integrator_order = run.integrator_order
    _declare_diverged(study, system, scenario)
    _judge_accuracy_points(study, T)
    return study


def _judge_accuracy_points(study: ConvergenceStudy, T: float) -> None:
    """The rule of tolerances.MIN_ACCURACY_DECREASE on the study's points, in place: the
    judged points (the controller's steps asymptotic and its own, down to the first at the
    reference's floor), the largest error ratio per decade over ACCURACY_SPAN_DECADES
    among them, and the slope."""
    limit = tolerances.asymptotic_limit(study.integrator_order)
    floor = REFERENCE_MARGIN * study.reference_error
    span = tolerances.ACCURACY_SPAN_DECADES
    judged = []
    for p in study.points:
        if (p.integrator_steps >= tolerances.ACCURACY_CONTROLLED_STEPS * p.steps
                and study.frequency * T / p.integrator_steps <= limit * (1 + 1e-9)):
            judged.append(p)
            if np.isfinite(p.error) and p.error <= floor:  # the floor: nothing further
                break
    ratios = []
    for i, a in enumerate(judged):
        later = [b for b in judged[i + 1:]
                 if np.log10(a.accuracy / b.accuracy) >= span * (1 - 1e-9)]
        if not later or (np.isfinite(later[0].error) and later[0].error <= floor):
            continue  # no point far enough, or the error fell to the floor
        b = later[0]
        ratios.append((b.error / a.error) ** (1.0 / np.log10(a.accuracy / b.accuracy))
                      if np.isfinite(b.error) and a.error > 0 else float("inf"))
    study.judged_accuracies = [p.accuracy for p in judged]
    if len(judged) < MIN_FIT_POINTS or not ratios:
        study.flattened = (
            f"{len(judged)} of {len(study.points)} accuracies where the controller sets "
            f"asymptotic steps (mean step T/N with w h <= {limit:g}, w = "
            f"{study.frequency:.4g} rad/s, and at least "
            f"{tolerances.ACCURACY_CONTROLLED_STEPS:g} steps per sample) above the "
            f"reference's floor {floor:.2g}: {MIN_FIT_POINTS} spanning {span} decades needed")
        return
    study.worst_decrease = float(max(ratios))
    fitted = [p for p in judged if p.error > floor]
    if len(fitted) >= 2:
        study.accuracy_slope = observed_order([p.accuracy for p in fitted],
                                              [p.error for p in fitted])


def judge_accuracy(study: ConvergenceStudy) -> Metric:
    """The metric ``convergence.accuracy`` of an accuracy study: the largest error ratio
    per decade of accuracy against 1 / MIN_ACCURACY_DECREASE; unresolved where too few
    accuracies are judged."""
    system = get_system(study.system)
    tolerance = 1.0 / tolerances.MIN_ACCURACY_DECREASE
    if study.unsupported:
        return Metric(ACCURACY_METRIC, float("nan"), tolerance, False, "unsupported",
                      study.unsupported, "ratio")
    if study.failure:
        return Metric(ACCURACY_METRIC, float("nan"), tolerance, False, "fail",
                      study.failure, "ratio")
    value = float("nan") if study.worst_decrease is None else study.worst_decrease
    metric = _judge(system, study.simulator, ACCURACY_METRIC, value,
                    tolerances.Gate(tolerance, study.flattened), "ratio")
    if metric.status == "pass" and metric.reason:
        metric.status = "xpass"
    return metric


def judge_order(study: ConvergenceStudy) -> Metric:
    """The metric ``convergence.order``: |fitted - declared order| against
    ORDER_TOLERANCE; unresolved where the curve flattened; failed for a failed study. A
    declared expected failure that passes is an unexpected pass (strict). An accuracy
    study is judged by `judge_accuracy`."""
    if study.knob == "accuracy":
        return judge_accuracy(study)
    system = get_system(study.system)
    if study.unsupported:
        return Metric(ORDER_METRIC, float("nan"), ORDER_TOLERANCE, False, "unsupported",
                      study.unsupported, "order")
    if study.failure:
        exp = expectation_for(system, study.simulator, ORDER_METRIC)
        if exp is not None and exp.kind == "xfail":  # a declared failure of the run
            return Metric(ORDER_METRIC, float("nan"), ORDER_TOLERANCE, False, "xfail",
                          f"{exp.reason} ({study.failure})", "order")
        return Metric(ORDER_METRIC, float("nan"), ORDER_TOLERANCE, False, "fail",
                      study.failure, "order")
    if study.observed_order is None:
        return _judge(system, study.simulator, ORDER_METRIC, float("nan"),
                      tolerances.Gate(ORDER_TOLERANCE, study.flattened), "order")
    metric = _judge(system, study.simulator, ORDER_METRIC,
                    abs(study.observed_order - study.integrator_order), ORDER_TOLERANCE,
                    "order")
    if metric.status == "pass" and metric.reason:
        metric.status = "xpass"  # declared an expected failure, and it passed
    return metric


def _study_item(item: tuple) -> dict:
    """One system x engine (`dts` None: automatic steps)."""
    system_id, simulator, dts, t_end, knob = item
    try:
        study = convergence(system_id, simulator, None, dts, t_end, knob=knob)
    except Exception as exc:  # one failed study fails its item only
        system = get_system(system_id)
        study = ConvergenceStudy(system.id, system.scenarios[0].name, simulator,
                                 get_backend(simulator).version(), 0, [], None,
                                 failure=" ".join(f"{type(exc).__name__}: {exc}".split())[:500])
    return {**study.as_dict(), "metric": judge_order(study).as_dict()}


def convergence_matrix(systems: Sequence[str], simulators: Sequence[str],
                       dts: Sequence[float] | None = None,
                       t_end: float | None = DEFAULT_T_END,
                       scheduler: str | None = None, workers: int | None = None,
                       knob: str = "auto") -> list[dict]:
    """Every system x engine as one item of the sweep (local pool, or a Dask cluster at
    `scheduler`); the studies as dictionaries with their judged `metric`, in matrix
    order. `knob` as in `convergence`."""
    from .sweep import sweep

    items = [(s, e, tuple(dts) if dts else None, t_end, knob)
             for s in systems for e in simulators]
    return sweep(_study_item, items, scheduler=scheduler, workers=workers)
