"""The self-excited oscillation of a system with a rate surface (dry friction at zero slip,
monograph §7.2, Fig. 23): its limit cycle, measured on the engine's run.

Where the reference sticks and slips (analytic/sliding.py), the motion after its first
release IS the limit cycle: every stick phase ends where the holding force reaches its
bound, one state, so each later cycle repeats the first. The cycle's amplitude
(x_max - x_min)/2 is computed on the reference's own slip arc from that release
(`analytic.sliding.limit_cycle`: the turning points located by events, error estimated at
two tolerances). Metrics:

- ``limit_cycle_amplitude``: the engine's half peak-to-peak of x over the samples after the
  reference has settled on the cycle (one period after its first release), relative
  error against the cycle's amplitude;
- ``limit_cycle_velocity``: the same for x', whose lowest value is the surface speed itself
  while the block sticks;
- without a stick phase (the rest state stable, or critical over the run):
  ``final_amplitude``, the half peak-to-peak of x - x_eq over the last fifth of the run
  against the reference's over the same window, relative to the motion's amplitude.

Gates: comparisons/tolerances.py, "Limit cycle".
"""
from __future__ import annotations

import numpy as np

from ...analytic.numeric import numeric_model
from ...analytic.sliding import limit_cycle, model_acceleration, rate_surfaces
from .. import metrics, tolerances
from . import ScenarioRun

CHECK = "limit_cycle"
#: the final amplitude compares the engine's run with the reference's over one window:
#: refined as the trajectory (the cycle's metrics compare with the analytic cycle)
REFINABLE = ("final_amplitude",)


def _cycle_shifts(system, values, reference, dt: float) -> float:
    """Sum over the reference's stick phases of the timing error each can add
    (tolerances.stick_slip_time_shift)."""
    surfaces = rate_surfaces(system, values)
    switches = reference.switches or []
    if not surfaces or not switches:
        return 0.0
    surface = surfaces[0]
    model = numeric_model(system.id, values)
    acc = model_acceleration(model, surface.coordinate)
    a_jump = abs(surface.jump) / float(model.mass_matrix(np.array([switches[0].q]))[0, 0])
    delta = 1e-9 * max(1.0, abs(surface.rate))
    total = 0.0
    for k, sw in enumerate(switches):
        if sw.kind != "stick":
            continue
        release = next((s.t for s in switches[k + 1:] if s.kind == "slip"),
                       float(reference.t[-1]))
        side = np.sign(reference.qd[0, 0] - surface.rate) or 1.0
        onset = acc(sw.q, surface.rate + side * delta, sw.t)
        total += tolerances.stick_slip_time_shift(a_jump, dt, onset, release - sw.t,
                                                  surface.rate)
    return total


def trajectory_allowance(system, scenario, values, reference, equilibrium, dt: float,
                         order: int) -> float:
    """The stick-slip phase drift relative to the amplitude (comparisons/tolerances.py,
    "Stick-slip"): max|x'| times the summed timing errors of the cycles."""
    shift = _cycle_shifts(system, values, reference, dt)
    if not shift:
        return 0.0
    amplitude = float(np.max(metrics.amplitude(reference.q, equilibrium.q)))
    return float(np.max(np.abs(reference.qd))) * shift / amplitude


def period_allowance(system, scenario, values, reference, equilibrium, dt: float,
                     order: int) -> float:
    """The summed timing errors of the cycles over the run's duration: what they add to
    the mean period's relative error."""
    return _cycle_shifts(system, values, reference, dt) / float(reference.t[-1])


def refinement_order(system, scenario, values, reference, order: int) -> int | None:
    """1 where the reference meets the rate surface: no engine locates the force's jump
    there, and the step that reaches it leaves a velocity error of at most a_J h whatever
    the scheme (comparisons/tolerances.py, "Stick-slip"), so the error falls at first
    order however high the scheme's; None for a motion that never reaches it."""
    return 1 if reference.switches else None


def half_range(x: np.ndarray) -> float:
    return float(np.max(x) - np.min(x)) / 2.0


def measure(run: ScenarioRun) -> None:
    ref, eng = run.reference, run.run
    t, n = run.t, run.n
    x_eng, v_eng = eng.q[:n, 0], eng.qd[:n, 0]
    # the phase portrait's velocities (its positions are the scenario's q and q_ref)
    run.series["phase_xd"] = v_eng
    run.series["phase_xd_reference"] = ref.qd[:n, 0]
    releases = [s for s in (ref.switches or []) if s.kind == "slip"]
    surfaces = rate_surfaces(run.system, run.values)
    if not releases or not surfaces:
        window = t >= 0.8 * t[-1]
        x_eq = run.equilibrium.q[0]
        value_ref = half_range(ref.q[:n, 0][window] - x_eq)
        value = half_range(x_eng[window] - x_eq)
        scale = half_range(ref.q[:n, 0] - x_eq)
        run.judge("final_amplitude", abs(value - value_ref) / scale, run.gate)
        return
    model = numeric_model(run.system.id, run.values)
    acc = model_acceleration(model, surfaces[0].coordinate)
    cycle = limit_cycle(acc, surfaces[0].rate, releases[0].q, releases[0].t)
    settled = t >= releases[0].t + cycle.period
    if np.count_nonzero(settled) < 2 * cycle.period / run.dt:
        run.unresolved("limit_cycle_amplitude", float("nan"),
                       "the run ends before two periods of the settled cycle")
        return
    gate = tolerances.gate(
        tolerances.limit_cycle_tolerance(run.w, run.dt, eng.integrator_order,
                                         cycle.period, abs(surfaces[0].jump) / model.mass_matrix(
                                             np.array([cycle.x_min]))[0, 0],
                                         cycle.velocity_amplitude)
        + cycle.error / cycle.amplitude,
        run.w, run.dt, eng.integrator_order, tolerances.MAX_TRAJECTORY_TOLERANCE)
    run.judge("limit_cycle_amplitude",
              abs(half_range(x_eng[settled]) - cycle.amplitude) / cycle.amplitude, gate)
    run.judge("limit_cycle_velocity",
              abs(half_range(v_eng[settled]) - cycle.velocity_amplitude)
              / cycle.velocity_amplitude, gate)
