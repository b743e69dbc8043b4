"""Stability of a parametrically excited rest state (monograph §8.4) as the engine meets
it, against Floquet theory (analytic/floquet.py `driven_floquet`).

The scenario starts near a rest state of the unexcited system (the nearest one is taken).
Floquet's verdict there, with the excitation on, says whether the engine must keep the
motion near it or leave:

- ``floquet_kept`` (verdict stable): the largest excursion of the free coordinates from
  the rest state over the run, over the neighbourhood radius: NEIGHBOURHOOD times the
  largest excursion over the first excitation period (a start from rest or with a
  velocity alike); at most 1 (the engine kept the rest state).
- ``floquet_left`` (verdict unstable): the neighbourhood radius over the largest
  excursion; at most 1 (the engine left).
- ``growth_rate`` (verdict unstable): the engine's exponential rate against ln|mu|max / T.
  The rate is read from the per-period maxima of the excursion (a Floquet solution is
  p(t) exp(sigma t), p of period T), by a straight line through their logarithms over
  the periods from SKIP_PERIODS periods or SKIP_E_FOLDINGS / sigma after the start
  (whichever is later: the decaying partner solution has faded) until the excursion
  reaches LINEAR_EXCURSION (the motion is still linear). Gate: `tolerances.floquet_growth_tolerance`, the scheme's error in the rate
  plus the same estimator's error on the exact (reference) motion of the scenario.
"""
from __future__ import annotations

import math

import numpy as np

from ...analytic.floquet import driven_floquet
from ...analytic.linear import wrap_angles
from ...analytic.numeric import numeric_model
from .. import tolerances
from . import ScenarioRun

CHECK = "floquet"
#: the growth rate, measured between two of the engine's own runs as the difference of
#: their rates (the same estimator on both), is refined as the trajectory; its
#: reference error is the estimator's on the exact motion
REFINABLE = ("growth_rate",)

#: radius of the rest state's neighbourhood, in units of the initial excursion
NEIGHBOURHOOD = 10.0
#: periods skipped before the growth is read, and the e-foldings sigma t skipped: the
#: decaying partner solution, exp(-sigma t), has faded by exp(-2 SKIP_E_FOLDINGS) of the
#: growing one
SKIP_PERIODS = 3
SKIP_E_FOLDINGS = 2.0
#: largest excursion (rad or m) still read as linear growth
LINEAR_EXCURSION = 0.1
#: fewest periods a rate is read from
MIN_PERIODS = 4


def _excursion(system, q: np.ndarray, rest: np.ndarray, free) -> np.ndarray:
    return np.array([np.max(np.abs((wrap_angles(system, x, rest) - rest)[free])) for x in q])


def periodic_growth_rate(t: np.ndarray, excursion: np.ndarray, period: float,
                         sigma: float) -> float | None:
    """Rate of exp growth from the per-period maxima (module docstring), or None when
    fewer than MIN_PERIODS periods qualify; `sigma` (the Floquet rate) sets the skip."""
    n_periods = int((t[-1] - t[0]) / period)
    skip = max(SKIP_PERIODS, int(np.ceil(SKIP_E_FOLDINGS / (sigma * period))))
    times, peaks = [], []
    for k in range(skip, n_periods):
        window = (t >= t[0] + k * period) & (t < t[0] + (k + 1) * period)
        if not np.any(window):
            continue
        peak = float(np.max(excursion[window]))
        if not np.isfinite(peak) or peak > LINEAR_EXCURSION:
            break
        times.append(t[window][np.argmax(excursion[window])])
        peaks.append(peak)
    if len(peaks) < MIN_PERIODS:
        return None
    return float(np.polyfit(times, np.log(peaks), 1)[0])


def measure(run: ScenarioRun) -> None:
    system, values = run.system, run.values
    model = numeric_model(system.id, dict(values))
    free = model.independent
    start = run.reference.q[0]
    found = driven_floquet(system, values)
    if not found:
        run.unresolved("floquet_kept", float("nan"),
                       "no rest state of the unexcited system (analytic/linear.py)")
        return
    rest, result = min(found, key=lambda r: float(np.max(np.abs(
        (wrap_angles(system, start, r[0]) - r[0])[free]))))
    t = run.t
    engine = _excursion(system, run.run.q[: run.n], rest, free)
    first = t < t[0] + result.period
    radius = NEIGHBOURHOOD * max(float(np.max(engine[first])), 1e-12)
    largest = float(np.max(engine)) if np.all(np.isfinite(engine)) else float("inf")
    run.series["floquet_excursion"] = engine
    if result.verdict == "stable":
        run.judge("floquet_kept", largest / radius, 1.0, "absolute")
    elif result.verdict == "unstable":
        run.judge("floquet_left", radius / largest, 1.0, "absolute")
        sigma = result.growth_rate
        exact = periodic_growth_rate(t, _excursion(system, run.reference.q[: run.n], rest,
                                                   free), result.period, sigma)
        got = periodic_growth_rate(t, engine, result.period, sigma)
        name = "growth_rate"
        if exact is None or got is None:
            run.unresolved(name, float("nan"), f"fewer than {MIN_PERIODS} periods of linear "
                                               f"growth to read the rate from")
            return
        if run.refinement:  # the reference is the engine's finer run
            run.judge(name, abs(got - exact) / sigma, math.inf)
            return
        w = max(2 * np.pi / result.period, float(np.max(np.abs(
            np.log(result.multipliers.astype(complex)) / result.period))))
        order = run.run.integrator_order
        estimator = abs(exact - sigma) / sigma
        gate = tolerances.gate(tolerances.floquet_growth_tolerance(w, run.dt, order, estimator),
                               w, run.dt, order, tolerances.MAX_FREQUENCY_TOLERANCE, "relative")
        metric = run.judge(name, abs(got - sigma) / sigma, gate)
        metric.detail = {"floquet_per_s": sigma, "reference_fit_per_s": exact,
                         "engine_fit_per_s": got, "reference_error": estimator}
    else:
        run.unresolved("floquet_kept", float("nan"),
                       "Floquet's verdict is marginal here (a tongue's boundary)")
