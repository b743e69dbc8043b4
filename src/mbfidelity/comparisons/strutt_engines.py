"""The Strutt chart by simulation (monograph §8.4, eq. 83, Fig. 28): each engine runs, at
every (lambda, gamma) grid point, the pendulum whose linearization is eq. 83, and its
motion is classified as growing or bounded over PERIODS periods.

The mapping (chosen here). A compound pendulum (mass m, centre of mass at l below the pin,
central inertia I_G) hangs from a pivot moved vertically as y(t) = Y cos t. With
I_O = I_G + m l^2 and kappa = m l / I_O its equation is
phi'' + kappa (g - Y cos t) sin(phi) = 0, so about phi = 0, lambda = kappa g and
gamma = -kappa Y; about phi = pi (psi = phi - pi) lambda = -kappa g and gamma = kappa Y.
A point with lambda >= 0 is therefore the hanging pendulum with g = lambda / kappa,
Y = -gamma / kappa; one with lambda < 0 the inverted pendulum with g = -lambda / kappa,
Y = gamma / kappa. Time is eq. 83's (period 2 pi).

Each run starts at rest, PERTURBATION rad from the equilibrium, and lasts PERIODS periods
at STEPS_PER_PERIOD steps (both can be chosen: fewer steps per period show a first-order
scheme moving the tongues). Its growth is max |psi| / PERTURBATION; it grows when that
exceeds GROWTH. The same growth of eq. 83 itself (DOP853 at 1e-10 from the same start)
classifies the point; a point whose exact growth lies within a factor DECISION_MARGIN of
GROWTH is undecided at this length and left out of the agreement fractions. Each point
also carries its Floquet verdict (analytic/strutt.py). Where an engine and eq. 83 differ,
the engine's scheme has moved a tongue's boundary (its order, its step).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.integrate
import sympy as sp

from ..analytic.strutt import PERIOD
from ..simulators import get_backend
from ..systems.model import (TIME, WORLD, Body, Mechanism, Prescribed, Prismatic,
                             Revolute)

PERIODS = 10
STEPS_PER_PERIOD = 200
PERTURBATION = 1e-3
GROWTH = 10.0
DECISION_MARGIN = 2.0
#: the pendulum (chosen here): kappa = M L / (I_G + M L^2)
MASS, LENGTH, CENTRAL_INERTIA = 1.0, 1.0, 0.01
KAPPA = MASS * LENGTH / (CENTRAL_INERTIA + MASS * LENGTH**2)


@dataclass
class PendulumPoint:
    """The pendulum of one grid point: gravity, pivot amplitude, equilibrium angle."""
    gravity: float
    amplitude: float
    equilibrium: float


def pendulum_for(lam: float, gamma: float) -> PendulumPoint:
    """The mapping of the module docstring."""
    if lam >= 0:
        return PendulumPoint(lam / KAPPA, -gamma / KAPPA, 0.0)
    return PendulumPoint(-lam / KAPPA, gamma / KAPPA, float(np.pi))


def pendulum_mechanism(point: PendulumPoint) -> Mechanism:
    """The numeric mechanism: a pivot body on a vertical slide imposed as Y cos t, the
    pendulum hinged on it."""
    return Mechanism(
        bodies=(Body("pivot", 1.0, 0.01), Body("pendulum", MASS, CENTRAL_INERTIA)),
        joints=(Prismatic("lift", WORLD, "pivot", "y", axis=(0, 1)),
                Revolute("pin", "pivot", "pendulum", "phi", child_anchor=(0, LENGTH))),
        gravity=sp.Float(point.gravity),
        prescribed=(Prescribed("lift_actuator", "y", sp.Float(point.amplitude) * sp.cos(TIME)),),
    )


def exact_growth(lam: float, gamma: float, periods: int = PERIODS,
                 steps_per_period: int = STEPS_PER_PERIOD) -> float:
    """max |phi| / phi(0) of eq. 83 over `periods` periods from (PERTURBATION, 0),
    sampled as the engines are."""
    def rhs(t, y):
        return [y[1], -(lam + gamma * np.cos(t)) * y[0]]
    t = np.linspace(0.0, periods * PERIOD, periods * steps_per_period + 1)
    sol = scipy.integrate.solve_ivp(rhs, (0.0, t[-1]), [PERTURBATION, 0.0], method="DOP853",
                                    rtol=1e-10, atol=1e-10 * PERTURBATION, t_eval=t)
    return float(np.max(np.abs(sol.y[0])) / PERTURBATION)


def engine_growth(simulator: str, lam: float, gamma: float, periods: int = PERIODS,
                  steps_per_period: int = STEPS_PER_PERIOD) -> float:
    """max |psi| / PERTURBATION of the engine's pendulum over `periods` periods (inf for
    a run that failed)."""
    point = pendulum_for(lam, gamma)
    mech = pendulum_mechanism(point)
    dt = PERIOD / steps_per_period
    q0 = np.array([point.amplitude, point.equilibrium + PERTURBATION])
    qd0 = np.zeros(2)
    try:
        run = get_backend(simulator).simulate(mech, q0, qd0, periods * PERIOD, dt)
    except Exception:  # an engine's failure at a point counts as a wrong classification
        return float("inf")
    psi = run.q[:, 1] - point.equilibrium
    return float(np.max(np.abs(psi)) / PERTURBATION) if np.all(np.isfinite(psi)) else float("inf")


#: the sweep's name for eq. 83 itself (its rows run in the sweep like the engines')
EXACT = "eq83"


def _row(item: tuple) -> list[float]:
    simulator, points, periods, steps = item
    if simulator == EXACT:
        return [exact_growth(lam, gamma, periods, steps) for lam, gamma in points]
    return [engine_growth(simulator, lam, gamma, periods, steps) for lam, gamma in points]


def classify(growth: float) -> str:
    return "grows" if growth > GROWTH else "bounded"


def decided(exact: float) -> bool:
    return not (GROWTH / DECISION_MARGIN <= exact <= GROWTH * DECISION_MARGIN)


def engine_chart(points: list[dict], simulators: list[str], scheduler: str | None = None,
                 workers: int | None = None, periods: int = PERIODS,
                 steps_per_period: int = STEPS_PER_PERIOD) -> dict:
    """Adds to every chart point (dicts with lambda, gamma and the Floquet verdict) its
    exact growth and class, and per engine its growth and class; returns the summary per
    engine: the agreement with eq. 83's class over the decided points, with the
    Floquet verdict over the points Floquet decides (stable or unstable) and that grow or
    stay bounded within the run, and the points where they differ. The runs are rows of
    the grid, items of the sweep facility (a local pool or a Dask cluster)."""
    from .sweep import sweep

    if EXACT in simulators:
        raise ValueError(f"{EXACT!r} is the reference, not an engine")
    rows: dict[float, list[dict]] = {}
    for p in points:
        p["engines"] = {}
        rows.setdefault(p["gamma"], []).append(p)
    # the reference rows in the same sweep: no serial work before the engines' rows
    jobs = [(sim, row) for sim in (EXACT, *simulators) for row in rows.values()]
    results = sweep(_row, [(sim, [(p["lambda"], p["gamma"]) for p in row], periods,
                            steps_per_period) for sim, row in jobs],
                    scheduler=scheduler, workers=workers)
    for (sim, row), growths in zip(jobs, results):
        for p, growth in zip(row, growths):
            if sim == EXACT:
                p["exact_growth"] = growth
                p["exact_class"] = classify(growth)
                p["decided"] = decided(growth)
            else:
                p["engines"][sim] = {"growth": growth, "class": classify(growth)}
    judged = [p for p in points if p["decided"]]
    # Floquet's verdict seen within the run: unstable points that grow, stable ones that
    # stay bounded (a slow instability may not show in PERIODS periods)
    floquet_seen = [p for p in judged
                    if (p["verdict"], p["exact_class"]) in (("unstable", "grows"),
                                                           ("stable", "bounded"))]
    summary = {}
    for sim in simulators:
        agree = [p for p in judged if p["engines"][sim]["class"] == p["exact_class"]]
        summary[sim] = {
            "decided_points": len(judged),
            "agreement_with_eq83": len(agree) / len(judged) if judged else None,
            "agreement_with_floquet": (
                sum(p["engines"][sim]["class"] == p["exact_class"] for p in floquet_seen)
                / len(floquet_seen) if floquet_seen else None),
            "disagreements": [{"lambda": p["lambda"], "gamma": p["gamma"],
                               "exact_growth": p["exact_growth"],
                               "engine_growth": p["engines"][sim]["growth"]}
                              for p in judged if p not in agree],
        }
    return {"periods": periods, "steps_per_period": steps_per_period,
            "perturbation": PERTURBATION, "growth_threshold": GROWTH,
            "decision_margin": DECISION_MARGIN, "kappa": KAPPA, "engines": summary}
