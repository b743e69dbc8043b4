"""The Strutt chart (monograph §8.4, eq. 83, Fig. 28) as each engine draws it: per grid
point (lambda, gamma), the engine simulates the catalog's mechanism that declares a
`mathieu_map` (System field: the parameter values at which its linearization about the
operating point is eq. 83 at (lambda, gamma), in time scaled by its excitation frequency;
the vertically driven pendulum of §8.3, whose mapping its module states), and its verdict,
growth or bounded, is compared with Floquet's (analytic/strutt.py).

Classification: the engine starts with the free coordinate START_ANGLE from the operating
point, at rest (the prescribed coordinate on its motion), and runs PERIODS periods; its
amplification is the largest |phi| over the last period over the largest over the first;
"growth" when it exceeds GROWTH_AMPLIFICATION, or when |phi| leaves the linear
neighbourhood, ESCAPE_ANGLE (a fast growth saturates within the first periods: the
pendulum falls or swings over, and the ratio of the periods' maxima no longer shows it);
else "bounded". Floquet's verdict (unstable = growth, stable = bounded; a marginal point
is reported, not counted) is the reference; the agreement fraction is over the points both
classify. A Floquet-unstable point whose multiplier grows by less than
GROWTH_AMPLIFICATION over the run (|mu|max^(PERIODS - 1)) cannot show its growth in the
engine's run: it is marked `slow_growth` so that its disagreement is read as the
horizon's, not the engine's.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: initial angle (rad): small, so that the start is linear
START_ANGLE = 0.01
#: periods simulated per point
PERIODS = 10
#: amplification over the run above which the engine's motion counts as growing
GROWTH_AMPLIFICATION = 3.0
#: |phi| (rad) beyond which the motion has left the linear neighbourhood of the rest state
ESCAPE_ANGLE = 0.5
#: time step of the engines' runs (s)
STEP = 1e-3


@dataclass(frozen=True)
class EnginePoint:
    """One grid point for one engine (picklable: it crosses process boundaries)."""

    simulator: str
    lam: float
    gamma: float


def chart_system():
    """The one mechanism of the catalog with a `mathieu_map`."""
    from ..systems import all_systems

    found = [s for s in all_systems().values() if s.mathieu_map is not None]
    if len(found) != 1:
        raise ValueError(f"the engines' Strutt chart needs one mechanism with a mathieu_map "
                         f"(found {len(found)})")
    return found[0]


def point_values(lam: float, gamma: float) -> dict[str, float]:
    """The chart mechanism's parameter values that map to (lambda, gamma)."""
    system = chart_system()
    return system.mathieu_map(lam, gamma, system.parameter_values())


def engine_verdict(point: EnginePoint) -> dict:
    """Simulate one point on one engine and classify it (module docstring)."""
    from ..analytic.floquet import excitation_period
    from ..analytic.numeric import numeric_model
    from ..simulators import get_backend

    system = chart_system()
    backend = get_backend(point.simulator)
    values = point_values(point.lam, point.gamma)
    mech = system.numeric_mechanism(values)
    model = numeric_model(system.id, values)
    q0 = system.operating_values(values)
    qd0 = np.zeros_like(q0)
    phi = model.independent[0]
    q0[phi] += START_ANGLE
    if model.driven:
        q0[model.driven], qd0[model.driven] = model.motion(0.0)[:2]
    period = excitation_period(system, values)
    t_end = PERIODS * period
    out = {"simulator": point.simulator, "lambda": point.lam, "gamma": point.gamma}
    try:
        run = backend.simulate(mech, q0, qd0, t_end, STEP,
                               backend.resolve_settings({}), ())
    except Exception as exc:  # an engine's failure at a point is data
        return {**out, "verdict": "crashed", "reason": str(exc)[:200]}
    angle = np.abs(np.asarray(run.q)[:, phi] - system.operating_values(values)[phi])
    t = np.asarray(run.t)
    first, last = angle[t <= period], angle[t >= t_end - period]
    if not np.all(np.isfinite(angle)) or len(last) == 0:
        return {**out, "verdict": "growth", "amplification": float("inf")}
    amplification = float(np.max(last) / max(float(np.max(first)), 1e-300))
    largest = float(np.max(angle))
    growth = amplification > GROWTH_AMPLIFICATION or largest > ESCAPE_ANGLE
    return {**out, "amplification": amplification, "largest_angle": largest,
            "verdict": "growth" if growth else "bounded"}


def engine_chart(simulator: str, chart, scheduler: str | None = None,
                 workers: int | None = None) -> dict:
    """Every point of the Floquet `chart` (analytic/strutt.py) simulated on `simulator`
    through comparisons/sweep.py, with the agreement fraction."""
    from .sweep import sweep

    floquet = chart.points()
    runs = sweep(engine_verdict, [EnginePoint(simulator, p["lambda"], p["gamma"])
                                  for p in floquet], scheduler=scheduler, workers=workers)
    points, agree, counted = [], 0, 0
    for f, r in zip(floquet, runs):
        expected = {"unstable": "growth", "stable": "bounded"}.get(f["verdict"])
        item = {**r, "floquet": f["verdict"],
                "floquet_max_abs_multiplier": f["floquet_max_abs_multiplier"]}
        if f["verdict"] == "unstable":
            item["slow_growth"] = bool(f["floquet_max_abs_multiplier"] ** (PERIODS - 1)
                                       < GROWTH_AMPLIFICATION)
        if expected is not None and r["verdict"] in ("growth", "bounded"):
            counted += 1
            item["agrees"] = r["verdict"] == expected
            agree += item["agrees"]
        points.append(item)
    return {"simulator": simulator, "mechanism": chart_system().id, "periods": PERIODS,
            "dt": STEP,
            "growth_amplification": GROWTH_AMPLIFICATION, "escape_angle": ESCAPE_ANGLE,
            "start_angle": START_ANGLE,
            "points": points, "classified": counted,
            "agreement": agree / counted if counted else None}
