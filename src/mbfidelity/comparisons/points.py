"""Named points (`System.points`) judged like the coordinates.

An engine reports its coordinates (mapped to the description's); every engine's points
come from them by one shared route, the planar forward kinematics of
simulators/plan (`body_states`, `point_state`), so that no backend needs an output of
its own. The reference's points come from the derivation (analytic/numeric.py
`point_states`): two independent routes of the same kinematics.

The metric is the largest distance between the engine's point and the reference's over
the run, relative to the point's excursion from its position at the equilibrium (as a
coordinate's error is relative to its excursion). Its gate follows from the trajectory
gate `tol` of the coordinates: a coordinate error within tol times its scale s_k moves
the point by at most sum_k |dp/dq_k| s_k tol to first order, so the point's gate is tol
times G = max over the run of sum_k |dp/dq_k| s_k / (the point's excursion), with dp/dq
the point's Jacobian along the reference. A point whose coordinates turn many times
(a crank's tip) has G well above 1: its gate is looser than the coordinates', as their
errors are relative to their whole travel.

The metric is named as a trajectory metric (`<scenario>.trajectory_point_<name>_max`):
a declaration about an engine's trajectories (a pattern `*.trajectory_*`) covers its
points too, since a point's error is its coordinates' error carried by the kinematics.
"""
from __future__ import annotations

from typing import Callable, Mapping

import numpy as np

from ..analytic.numeric import numeric_model
from ..simulators.plan import body_states, point_state
from ..systems import System
from ..systems.model import Mechanism
from .tolerances import Gate


def engine_points(system: System, values: Mapping[str, float], mech: Mechanism,
                  q: np.ndarray, qd: np.ndarray) -> dict[str, np.ndarray]:
    """Each named point's world position and velocity, (N, 4), along an engine's
    coordinates (planar forward kinematics, simulators/plan). A spatial mechanism's
    points come from the derivation's kinematics instead (the plan's is planar)."""
    points = system.points(system.symbols)
    if mech.spatial:
        return numeric_model(system.id, values).point_states(q, qd)
    local = {p.name: (system.evaluate(p.position[0], values),
                      system.evaluate(p.position[1], values)) for p in points}
    out = {p.name: np.empty((len(q), 4)) for p in points}
    for i, (qi, qdi) in enumerate(zip(q, qd)):
        states = body_states(mech, qi, qdi)
        for p in points:
            out[p.name][i] = point_state(states[p.body], local[p.name])
    return out


def point_gain(system: System, values: Mapping[str, float], ref, q_eq: np.ndarray,
               scale: np.ndarray) -> dict[str, tuple[float, float]]:
    """(excursion, G) of each named point along the reference: the largest distance of
    its position from that at the equilibrium `q_eq`, and the factor G of the module
    docstring that turns the coordinates' gate into the point's."""
    model = numeric_model(system.id, values)
    n = ref.q.shape[1]
    at_eq = model.point_states(q_eq[None, :], np.zeros((1, n)))
    # the point's Jacobian, column by column: its velocity for a unit rate of q_k
    columns = [model.point_states(ref.q, np.tile(np.eye(n)[k], (len(ref.q), 1)))
               for k in range(n)]
    out = {}
    for name, state in ref.points.items():
        d = state.shape[1] // 2
        excursion = float(np.max(np.linalg.norm(state[:, :d] - at_eq[name][0, :d], axis=1)))
        excursion = max(excursion, 1e-12)
        lever = sum(np.linalg.norm(c[name][:, d:], axis=1) * scale[k]
                    for k, c in enumerate(columns))
        out[name] = (excursion, float(np.max(lever)) / excursion)
    return out


def judge_points(system: System, values: Mapping[str, float], mech: Mechanism, ref, run,
                 n: int, q_eq: np.ndarray, scale: np.ndarray, tol: Gate, scenario: str,
                 judge: Callable[[str, float, Gate], object]) -> None:
    """One metric `<scenario>.trajectory_point_<name>_max` per named point (see the module
    docstring), recorded through `judge(name, value, gate)`."""
    if not ref.points:
        return
    got = engine_points(system, values, mech, run.q[:n], run.qd[:n])
    for name, (excursion, gain) in point_gain(system, values, ref, q_eq, scale).items():
        d = ref.points[name].shape[1] // 2
        distance = np.linalg.norm(got[name][:, :d] - ref.points[name][:n, :d], axis=1)
        value = float(np.max(distance)) / excursion if n else float("inf")
        judge(f"{scenario}.trajectory_point_{name}_max", value,
              Gate(tol.tolerance * gain, tol.unresolved))
