"""The parameter value where the rest state of a self-excited system loses stability (the
belt speed of §7.2), found by each engine from its own simulations, against the analytic
threshold (analytic/stability.py: the root of the linearization's growth rate).

For a system that names a `stability_parameter` p: the engine runs the mechanism at a
trial value of p from its rest state x_eq(p) with a small velocity `PERTURBATION` (scaled
to the belt speed's units by the coordinate's), for `OBSERVED_PERIODS` periods of the rest
state's mode; a damped sinusoid fitted to its motion (comparisons/metrics.py) gives the
engine's growth rate sigma(p). Bisection on the sign of sigma over [p*/2, 3 p*/2] (p* the
analytic threshold; the engine's classification alone moves the bracket) until the
bracket is narrower than a quarter of the gate. Metric ``threshold_<p>``: |p_engine - p*| / p*.

Gate (comparisons/tolerances.py, "Stability threshold"): the scheme's error in the growth
rate at a neutral mode over the growth rate's slope d sigma / dp, plus the bisection's
final half-width.
"""
from __future__ import annotations

import numpy as np

from ...analytic.linear import operating_equilibrium
from ...analytic.stability import growth_rate, stability_threshold
from .. import metrics, tolerances
from . import ScenarioRun

CHECK = "threshold"

#: initial velocity of the perturbed rest state (m/s or rad/s): small enough that the
#: motion stays linear (far from sticking), large enough for a clean fit
PERTURBATION = 0.01
OBSERVED_PERIODS = 20
MAX_BISECTIONS = 14


def engine_growth_rate(run: ScenarioRun, name: str, value: float) -> float | None:
    """sigma of the engine's motion about the rest state with the parameter at `value`."""
    trial = dict(run.values)
    trial[name] = float(value)
    eq = operating_equilibrium(run.system, trial)
    mode = max(eq.modes, key=lambda m: m.frequency_hz)
    w = 2 * np.pi * mode.frequency_hz
    t_end = OBSERVED_PERIODS * 2 * np.pi / w
    qd0 = np.zeros_like(eq.q)
    qd0[0] = PERTURBATION
    result = run.simulate(run.system.numeric_mechanism(trial), eq.q, qd0, t_end)
    if result is None:
        return None
    w0, zeta = metrics.fit_damped_sinusoid(result.t, result.q[:, 0] - eq.q[0], w,
                                           mode.damping_ratio)
    return -zeta * w0


def measure(run: ScenarioRun) -> None:
    name = run.system.stability_parameter
    if name is None:
        raise ValueError(f"{run.system.id}: the threshold check needs a stability_parameter")
    analytic = stability_threshold(run.system, run.values, name).nearest
    label = f"threshold_{name}"
    if analytic is None:
        run.unresolved(label, float("nan"), "no change of stability near the parameter's "
                                            "value (analytic/stability.py)")
        return
    p_star = analytic.value
    eq = operating_equilibrium(run.system, {**run.values, name: p_star})
    w = max(abs(s) for s in eq.eigenvalues)
    span = 1e-6 * p_star
    slope = abs(growth_rate(run.system, run.values, name, p_star + span)
                - growth_rate(run.system, run.values, name, p_star - span)) / (2 * span)
    order = run.run.integrator_order
    shift = tolerances.threshold_tolerance(w, run.dt, order, slope) / p_star
    lo, hi = 0.5 * p_star, 1.5 * p_star
    sig_lo, sig_hi = (engine_growth_rate(run, name, p) for p in (lo, hi))
    if sig_lo is None or sig_hi is None:
        return  # the incident is recorded
    if np.sign(sig_lo) == np.sign(sig_hi):
        run.judge(label, float("inf"), shift)  # no change of stability in the bracket
        return
    for _ in range(MAX_BISECTIONS):
        if (hi - lo) / p_star < shift / 2:
            break
        mid = 0.5 * (lo + hi)
        sig = engine_growth_rate(run, name, mid)
        if sig is None:
            return
        if np.sign(sig) == np.sign(sig_lo):
            lo, sig_lo = mid, sig
        else:
            hi, sig_hi = mid, sig
    found = 0.5 * (lo + hi)
    run.series[label] = np.array([found, p_star, lo, hi])
    metric = run.judge(label, abs(found - p_star) / p_star, shift + (hi - lo) / (2 * p_star))
    metric.detail = {"analytic": p_star, "engine": found, "bracket": [lo, hi]}
