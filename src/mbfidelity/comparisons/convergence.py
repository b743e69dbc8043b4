"""Convergence and work-precision studies: error against time step for one engine on one
scenario, the observed order fitted on a log-log scale, and the cost of each run."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from ..analytic.linear import operating_equilibrium
from ..analytic.reference import reference
from ..simulators import get_backend
from ..systems import get_system
from . import metrics


@dataclass
class ConvergencePoint:
    dt: float
    error: float          # max |q - q_ref| / amplitude
    wall_time: float      # s of stepping
    steps: int


@dataclass
class ConvergenceStudy:
    system: str
    scenario: str
    simulator: str
    engine_version: str
    integrator_order: int
    points: list[ConvergencePoint]
    observed_order: float

    def as_dict(self) -> dict:
        return {"system": self.system, "scenario": self.scenario, "simulator": self.simulator,
                "engine_version": self.engine_version, "integrator_order": self.integrator_order,
                "observed_order": self.observed_order,
                "points": [p.__dict__ for p in self.points]}


def observed_order(dts: Sequence[float], errors: Sequence[float]) -> float:
    """Slope of log(error) against log(dt) (least squares)."""
    x, y = np.log(np.asarray(dts)), np.log(np.asarray(errors))
    return float(np.polyfit(x, y, 1)[0])


def convergence(system_id: str, simulator: str, scenario: str, dts: Sequence[float],
                t_end: float | None = None, settings: Mapping | None = None) -> ConvergenceStudy:
    system = get_system(system_id)
    sc = system.scenario(scenario)
    values = system.parameter_values(scenario=sc)
    backend = get_backend(simulator)
    mech = system.numeric_mechanism(values)
    eq = operating_equilibrium(system, values)
    T = sc.t_end if t_end is None else t_end
    points, order = [], 0
    for dt in dts:
        ref = reference(system, sc, values, dt, T)
        run = backend.simulate(mech, ref.q[0], ref.qd[0], T, dt, settings)
        n = min(len(run.t), len(ref.t))
        err, _ = metrics.trajectory_errors(run.q[:n], ref.q[:n], metrics.amplitude(ref.q, eq.q))
        points.append(ConvergencePoint(dt, err, run.wall_time, n - 1))
        order = run.integrator_order
    return ConvergenceStudy(system_id, scenario, simulator, backend.version(), order, points,
                            observed_order([p.dt for p in points], [p.error for p in points]))
