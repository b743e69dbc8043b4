"""Reference trajectories: exact where a closed form exists, otherwise DOP853 at tight
tolerance whose own error is estimated by a second solve at a 10x looser tolerance. A
force law that jumps with the rate (dry friction at zero slip) is followed through its
stick phases by analytic/sliding.py, with the same two tolerances.

A stiff system (`System.stiff`: rates of decay far above the motion's own, such as a
stiff spring-damper's c/m) is integrated instead by Radau IIA (SciPy's "Radau", implicit,
order 5, stable for any step on the decaying modes) with the model's exact Jacobian
(`NumericModel.ode_jacobian`), at the same two tolerances: DOP853's stability bound,
a step below about 3.3 over the fastest decay rate, would otherwise set its step for the
whole run however smooth the motion, at no gain in accuracy."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
from scipy.integrate import solve_ivp

from ..systems import System
from ..systems.model import Scenario
from . import memo
from .closed_forms import SOLUTIONS
from .numeric import numeric_model
from .sliding import Switch, integrate_with_sliding, model_acceleration, rate_surfaces

TIGHT = 1e-12
LOOSE = 1e-11
#: rtol = atol of the two solves `sensitivity` compares (the reference's integrator)
SENSITIVITY_TOLERANCE = 1e-11


@dataclass
class Reference:
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    reactions: dict[str, np.ndarray]
    energy: np.ndarray | None
    #: max |error| estimate of q over the run (per coordinate)
    error_estimate: np.ndarray
    method: str
    #: Lagrange multipliers (N, m) of the closure constraints (empty without)
    multipliers: np.ndarray | None = None
    #: physical constraint forces by constraint name (see simulators/base.py point 6)
    constraint_forces: dict | None = None
    #: instants the motion sticks to / slips off a rate surface (analytic/sliding.py)
    switches: list[Switch] | None = None
    #: actuator force of each prescribed coordinate, (N,) by actuator name (model
    #: convention 9; empty without prescribed motion)
    actuator_forces: dict | None = None
    #: each named point's world position and velocity, (N, 2 d) by name
    #: (`System.points`, `NumericModel.point_states`; empty without points)
    points: dict | None = None
    #: max distance, over the run, between each point's position and its position on the
    #: comparison solve the coordinates' `error_estimate` comes from, by name
    point_error_estimate: dict | None = None


class ReferenceFailed(RuntimeError):
    """The reference could not be solved over the scenario; `t_reached` is the last time
    the solver reached."""

    def __init__(self, message: str, t_reached: float | None = None) -> None:
        super().__init__(message)
        self.t_reached = t_reached


def integrate(model, y0: np.ndarray, t: np.ndarray, tol: float,
              stiff: bool = False) -> np.ndarray:
    """The independent states y = (q_i, q_i') at the instants t (rows), from y0 at t[0]:
    DOP853 at rtol = atol = tol, or for a stiff system Radau IIA with the exact
    Jacobian."""
    if stiff:
        sol = solve_ivp(model.ode_rhs, (t[0], t[-1]), y0, method="Radau", rtol=tol,
                        atol=tol, t_eval=t, jac=model.ode_jacobian)
    else:
        sol = solve_ivp(model.ode_rhs, (t[0], t[-1]), y0, method="DOP853", rtol=tol,
                        atol=tol, t_eval=t)
    if not sol.success:
        reached = float(sol.t[-1]) if len(sol.t) else float(t[0])
        raise ReferenceFailed(f"reference solve failed at t = {reached:.6g} s: {sol.message}",
                              reached)
    return sol.y.T


def consistent_initial_state(system: System, scenario: Scenario, values):
    """The scenario's initial state on the constraint manifold: the independent
    coordinates and velocities as given, the dependent ones solved (the scenario's values
    for them are only Newton's starting guess)."""
    q0, qd0 = system.initial_state(scenario, values)
    model = numeric_model(system.id, values)
    if model.driven:
        # a prescribed coordinate starts where its motion does
        qp, qdp, _ = model.motion(0.0)
        q0[model.driven], qd0[model.driven] = qp, qdp
        return q0, qd0
    if not model.constrained:
        return q0, qd0
    q = model.complete(q0)
    if not model.on_branch(q):
        raise ValueError(f"{system.id}: the initial state of {scenario.name} is not on the "
                         f"mechanism's assembly branch (Mechanism.branch), the only one "
                         f"the reference follows")
    return q, model.velocity_basis(q) @ qd0[model.independent]


#: at most this many samples share one anchor (a sequential Newton solve whose result,
#: with its tangent, is the starting guess of the batched solve of the samples after it)
ANCHOR_SPACING = 25
#: the largest change of the independent coordinates (rad or m) between an assembly and
#: the one solved from it: a sample farther from its anchor becomes an anchor itself,
#: reached from the last one in steps of at most this size (continuation)
ANCHOR_REACH = 0.05
#: halvings of a continuation step whose Newton solve does not converge
CONTINUATION_HALVINGS = 12


def _continue(model, q: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The assembly at the independent coordinates `target`, followed from the assembly
    `q` along the straight segment between their independent coordinates in steps of at
    most ANCHOR_REACH, each started from the tangent predictor q + S dq_i (the motion
    stays on the branch it is on: the segment is the motion's path for one independent
    coordinate, and a chord of it for several). A step whose Newton solve fails is
    halved."""
    ind = model.independent
    start = q[ind].copy()
    span = np.asarray(target, dtype=float) - start
    steps = max(1, int(np.ceil(np.max(np.abs(span)) / ANCHOR_REACH)))
    done, size, halvings = 0.0, 1.0 / steps, 0
    while done < 1.0:
        step = min(size, 1.0 - done)
        guess = q + model.velocity_basis(q) @ (span * step)
        guess[ind] = start + span * (done + step)
        try:
            q = model.complete(guess)
        except (RuntimeError, np.linalg.LinAlgError):
            halvings += 1
            if halvings > CONTINUATION_HALVINGS:
                raise RuntimeError("the constraint equations did not converge (assembly "
                                   "lost) while following the motion between two samples")
            size /= 2
            continue
        done += step
    return q


def _sampled_positions(model, y: np.ndarray, q0: np.ndarray) -> np.ndarray:
    """The coordinates along the independent ones sampled in `y`: in closed form where the
    constraints solve so, otherwise by Newton's method: anchors solved in sequence, each
    followed from the last one (`_continue`), a new one wherever a sample is more than
    ANCHOR_REACH from its anchor or ANCHOR_SPACING samples after it, whatever the output
    step; the samples in between are solved all at once, each started from its anchor
    and the anchor's tangent."""
    k = len(model.independent)
    if model._explicit is not None:
        return np.array([model._explicit[0](*row[:k]) for row in y], dtype=float)
    qi = y[:, :k]
    q = np.array(q0, dtype=float)
    owner = np.zeros(len(y), dtype=int)
    anchors: list[np.ndarray] = []
    anchor_rows: list[int] = []
    for i in range(len(y)):
        if (not anchor_rows or i - anchor_rows[-1] >= ANCHOR_SPACING
                or np.max(np.abs(qi[i] - qi[anchor_rows[-1]])) > ANCHOR_REACH):
            q = _continue(model, q, qi[i])
            anchors.append(q)
            anchor_rows.append(i)
        owner[i] = len(anchors) - 1
    anchored = np.array(anchors)
    bases = np.array([model.velocity_basis(a) for a in anchors])
    shift = qi - qi[anchor_rows][owner]
    guesses = anchored[owner] + np.einsum("nij,nj->ni", bases[owner], shift)
    return model.complete_along(qi, guesses)


def _full_states(model, y: np.ndarray, q0: np.ndarray, t: np.ndarray):
    k = len(model.independent)
    if model.driven:
        return model.driven_state(y, t)
    if not model.constrained:
        return y[:, :k], y[:, k:]
    q = _sampled_positions(model, y, q0)
    if model._explicit is not None:
        qd = np.array([model._explicit[1](*row) for row in y], dtype=float)
    else:
        qd = model.velocities_along(q, y[:, k:])
    model._warm = q[-1].copy()
    return q, qd


def _positions(model, y: np.ndarray, q0: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The coordinates of `_full_states` alone, without the velocities: for the error
    estimate, which compares positions."""
    k = len(model.independent)
    if model.driven:
        return model.driven_state(y, t)[0]
    if not model.constrained:
        return y[:, :k]
    q = _sampled_positions(model, y, q0)
    model._warm = q[-1].copy()
    return q


_CACHE: dict = {}
_CACHE_SIZE = 64


def reference(system: System, scenario: Scenario, values: Mapping[str, float],
              dt: float, t_end: float | None = None,
              q0: np.ndarray | None = None, qd0: np.ndarray | None = None) -> Reference:
    """Sampled every dt from 0 to t_end (the scenario's by default). Cached: every engine
    of a comparison matrix is measured against the same solve."""
    key = (system.id, scenario.name, tuple(sorted(values.items())), dt, t_end,
           None if q0 is None else (tuple(q0), tuple(qd0)))
    if key not in _CACHE:
        if len(_CACHE) >= _CACHE_SIZE:
            _CACHE.pop(next(iter(_CACHE)))
        _CACHE[key] = _stored_reference(system, scenario, values, dt, t_end, q0, qd0)
    return _CACHE[key]


def _stored_reference(system, scenario, values, dt, t_end, q0, qd0) -> Reference:
    """`_reference`, kept in the persistent cache (analytic/memo.py) under what it depends
    on: the parameters, the initial state it starts from, t_end, the step and the
    tolerances (the scenario's name is no part of it: two scenarios that start alike
    share the solve)."""
    t_end = scenario.t_end if t_end is None else t_end
    if q0 is None:
        q0, qd0 = consistent_initial_state(system, scenario, values)
    q0, qd0 = np.asarray(q0, dtype=float), np.asarray(qd0, dtype=float)
    inputs = (dict(values), q0, qd0, dt, t_end, TIGHT, LOOSE)
    return memo.cached(system, "reference", inputs,
                       lambda: _reference(system, scenario, values, dt, t_end, q0, qd0),
                       remember=False)  # `reference` keeps its own


def _reference(system, scenario, values, dt, t_end, q0, qd0) -> Reference:
    t_end = scenario.t_end if t_end is None else t_end
    steps = int(round(t_end / dt))
    t = np.arange(steps + 1) * dt
    if q0 is None:
        q0, qd0 = consistent_initial_state(system, scenario, values)
    model = numeric_model(system.id, values)
    ind = model.independent
    y0 = np.concatenate([q0[ind], qd0[ind]])
    model._warm = np.array(q0, dtype=float)
    surfaces = rate_surfaces(system, values)
    switches = None
    if surfaces:
        return _sliding_reference(system, model, surfaces, t, q0, qd0)
    stiff = system.stiff
    tight = integrate(model, y0, t, TIGHT, stiff)
    q, qd = _full_states(model, tight, q0, t)
    exact = SOLUTIONS.get(system.exact_solution or "")
    if exact is not None:
        q_exact, qd_exact = exact(values, q0, qd0, t)
        # the closed form is exact to round-off; its distance to DOP853 bounds both
        error = np.max(np.abs(q_exact - q), axis=0)
        other_q, q, qd = q, q_exact, qd_exact
        method = f"closed form ({system.exact_solution}); DOP853 rtol=atol={TIGHT:g} agrees"
    else:
        model._warm = np.array(q0, dtype=float)
        other_q = _positions(model, integrate(model, y0, t, LOOSE, stiff), q0, t)
        error = np.max(np.abs(other_q - q), axis=0)
        scheme = ("Radau IIA (implicit, order 5, exact Jacobian; a stiff system)" if stiff
                  else "DOP853")
        method = f"{scheme} rtol=atol={TIGHT:g}; error estimated against rtol=atol={LOOSE:g}"
    points, point_error = _points(model, q, qd, other_q)
    if model.constrained:
        qdd, lam = model.dynamics_along(q, qd, t)
        constraint_forces = model.constraint_forces(q, lam)
    else:
        qdd = model.accelerations(q, qd, t)
        lam = np.zeros((len(t), 0))
        constraint_forces = {}
    # the reaction checks' joints and those the contact forces are read from
    joints = dict.fromkeys(system.reaction_joints)
    joints.update(dict.fromkeys(c.target for c in system.contacts(system.symbols)
                                if c.kind == "reaction"))
    reactions = {j: model.reaction(j, q, qd, qdd, t, lam) for j in joints}
    energy = model.energy(q, qd) if model.conservative else None
    return Reference(t, q, qd, qdd, reactions, energy, error, method, lam, constraint_forces,
                     switches, model.actuator_forces(q, qd, qdd, t), points, point_error)


def _points(model, q: np.ndarray, qd: np.ndarray, other_q: np.ndarray) -> tuple[dict, dict]:
    """(states, error estimates) of the system's named points: their states along (q, qd),
    and the largest distance between their positions on q and on `other_q` (the solve
    the coordinates' error estimate comes from)."""
    states = model.point_states(q, qd)
    if not states:
        return {}, {}
    other = model.point_states(other_q, np.zeros_like(other_q))
    error = {}
    for name, state in states.items():
        d = state.shape[1] // 2
        error[name] = float(np.max(np.linalg.norm(other[name][:, :d] - state[:, :d], axis=1)))
    return states, error


def _check_sliding(system, model, surfaces) -> None:
    if len(surfaces) > 1 or model.driven or model.constrained:
        raise ValueError(f"{system.id}: the sliding reference handles one rate surface on "
                         f"one unconstrained, undriven coordinate")


def _sliding_reference(system, model, surfaces, t, q0, qd0) -> Reference:
    """One coordinate with a force that jumps across x' = s: analytic/sliding.py at TIGHT,
    its error estimated against LOOSE."""
    _check_sliding(system, model, surfaces)
    acc = model_acceleration(model, surfaces[0].coordinate)
    x, v, a, switches = integrate_with_sliding(acc, q0[0], qd0[0], t, surfaces[0].rate, TIGHT)
    loose = integrate_with_sliding(acc, q0[0], qd0[0], t, surfaces[0].rate, LOOSE)[0]
    error = np.array([float(np.max(np.abs(loose - x)))])
    method = (f"DOP853 rtol=atol={TIGHT:g} on the slip phases, stick phases exact "
              f"(Filippov, analytic/sliding.py); error estimated against rtol=atol={LOOSE:g}")
    reactions = {j: model.reaction(j, x[:, None], v[:, None], a[:, None], t, np.zeros((len(t), 0)))
                 for j in system.reaction_joints}
    points, point_error = _points(model, x[:, None], v[:, None], loose[:, None])
    return Reference(t, x[:, None], v[:, None], a[:, None], reactions, None, error, method,
                     np.zeros((len(t), 0)), {}, switches, model.actuator_forces(
                         x[:, None], v[:, None], a[:, None], t), points, point_error)


def sensitivity(system: System, scenario: Scenario, values: Mapping[str, float],
                perturbation: float = 1e-7) -> float:
    """Growth factor, over the scenario, of a small change of the first independent
    coordinate: ~1-20 for regular motion, orders of magnitude more for chaotic motion,
    where trajectory gates (which assume linear error growth) are meaningless. Kept in
    the persistent cache (analytic/memo.py) under the parameters, the initial state, the
    scenario's duration and the perturbation."""
    q0, qd0 = consistent_initial_state(system, scenario, values)
    inputs = (dict(values), np.asarray(q0, dtype=float), np.asarray(qd0, dtype=float),
              scenario.t_end, perturbation, SENSITIVITY_TOLERANCE)
    return memo.cached(system, "sensitivity", inputs, lambda: _sensitivity(
        system, scenario.t_end, values, q0, qd0, perturbation))


def _sensitivity(system: System, t_end: float, values: Mapping[str, float], q0: np.ndarray,
                 qd0: np.ndarray, perturbation: float) -> float:
    model = numeric_model(system.id, values)
    stiff = system.stiff
    ind = model.independent
    y0 = np.concatenate([q0[ind], qd0[ind]])
    t = np.linspace(0.0, t_end, 501)
    surfaces = rate_surfaces(system, values)
    if surfaces:  # a force that jumps across a rate surface: the Filippov integration
        _check_sliding(system, model, surfaces)
        acc = model_acceleration(model, surfaces[0].coordinate)

        def positions(x0: float) -> np.ndarray:
            return integrate_with_sliding(acc, x0, qd0[0], t, surfaces[0].rate,
                                         SENSITIVITY_TOLERANCE)[0]
        return float(np.max(np.abs(positions(q0[0]) - positions(q0[0] + perturbation)))
                     / perturbation)
    model._warm = np.array(q0, dtype=float)
    a = integrate(model, y0, t, SENSITIVITY_TOLERANCE, stiff)
    y1 = y0.copy()
    y1[0] += perturbation
    model._warm = np.array(q0, dtype=float)
    b = integrate(model, y1, t, SENSITIVITY_TOLERANCE, stiff)
    k = len(ind)
    return float(np.max(np.abs(a[:, :k] - b[:, :k])) / perturbation)
