"""Joint reactions (contract point 6) from what an engine measures, written once.

The reaction at a joint is the force its parent exerts on its child through it, in world
axes, as the derivation defines it (`analytic.derivation.Derivation.reaction`): Newton's
law on the child's subtree S,

    R = sum over the bodies b of S of m_b (a_b - g)  -  the forces entering S from outside,

where the forces from outside are

- those of the point-to-point elements and of the loop and slot constraints
  (PointOnPoint, PointOnLine) that join a body of S to a body outside it;
- on a prismatic joint, the generalized forces on its own coordinate, which act between
  parent and child along the slide: the coordinate laws (`CoordinateForce`) of that
  coordinate and the couplings (`LinearCoupling`) that involve it, each turned into the
  world force ``Q axis / |axis|^2`` with the axis turned with the parent (virtual power:
  `slide_direction`). A force on a hinge's coordinate is a couple, with no net force.

A prescribed coordinate's actuator is not among them: the derivation counts it as acting
through the joint. Nor is a rolling contact: it carries what the arm and the coupling it
replaces carried, which the description transmits through the joints.

An engine measures either the first sum (its centre-of-mass accelerations:
`subtree_force`) or a force it books as passing from parent to child (its own joint
reaction, an inverse-dynamics force, an internal force of its recursive algorithm). Such
a force holds the outside forces that the engine's build applies as joint forces or does
not see; `joint_reaction` takes out the ones the engine hands in, and the coordinate laws
of a prismatic joint's own slide, which every build applies as joint forces. An engine
that reports no force at all (only an impulse's magnitude) measures the bodies' motion
over each step: a prescribed coordinate's actuator force is Newton-Euler on its child
subtree (`actuator_force`), and with closure constraints the joint reactions and the
closure forces come together from the momentum balance of every body (`balance_forces`);
`motion_forces` gathers them all from the state rows of an engine in maximal coordinates.

Sign convention of every force handed in (the contract's, base.py point 6), by element
name: a pair element (PointToPoint, PointOnPoint, PointOnLine) gives the force on its first
body (``body_a``; the pin's body) in world axes, shape (N, 2), its second body feeling the
opposite; a LinearCoupling gives its generalized force (-multiplier), shape (N,) or
(N, 1), which acts on each coordinate times that coordinate's coefficient. The coordinate
laws are evaluated here, from the samples.
"""
from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np

from ..systems.model import (
    WORLD,
    CoordinateForce,
    LinearCoupling,
    Mechanism,
    PointOnLine,
    PointOnPoint,
    PointToPoint,
    Prismatic,
    Revolute,
)
from .plan import (CoordinateMap, ForceLaw, Load, coordinate_load, coordinate_map, cos_sin,
                   joint_coordinates, num, point_state, sample_columns, turned, wrench)
from .plan import PAIR_ELEMENTS, MaximalFrames, plane_point


def slide_direction(mech: Mechanism, joint: Prismatic, q: np.ndarray,
                    cmap: CoordinateMap | None = None) -> np.ndarray:
    """The world force on the child of a prismatic joint per unit generalized force on its
    coordinate, at each sample of q (rows): axis / |axis|^2, turned with the parent."""
    cmap = cmap or coordinate_map(mech)
    axis = np.array([num(joint.axis[0]), num(joint.axis[1])])
    axis = axis / float(axis @ axis)
    return turned(cmap.angle(joint.parent, q), axis[0], axis[1])


def subtree_force(mech: Mechanism, joint_name: str, t: np.ndarray,
                  accelerations: Mapping[str, np.ndarray]) -> np.ndarray:
    """sum m (a - g) over the massive bodies of the joint child's subtree, at the sample
    times t (N, 2), from the world acceleration (N, 2) of each one's centre of mass
    (`accelerations`, by body; massless bodies need none)."""
    joint = mech.joint(joint_name)
    g = np.array([0.0, -num(mech.gravity)])
    total = np.zeros((len(t), 2))
    for b in mech.subtree(joint.child):
        mass = num(mech.body(b).mass)
        if mass != 0:
            total += mass * (accelerations[b] - g)
    return total



def subtree_bodies(mech: Mechanism, joints: Sequence[str]) -> list[str]:
    """The bodies with mass in the child subtrees of `joints`, sorted: those whose
    centre-of-mass accelerations `subtree_force` needs."""
    return sorted({b for name in joints for b in mech.subtree(mech.joint(name).child)
                   if num(mech.body(b).mass) != 0})


def subtree_newton(mech: Mechanism, joints: Sequence[str], t: np.ndarray,
                   accelerations: Mapping[str, np.ndarray],
                   element_forces: Mapping[str, np.ndarray],
                   constraint_forces: Mapping[str, np.ndarray]) -> dict[str, dict]:
    """The reactions' part of `base.Samples` for an engine that measures its bodies'
    centre-of-mass `accelerations`: per joint the Newton force of the child's subtree
    (`subtree_force`) as `transmitted`, and the forces from outside that it holds, by the
    module's sign convention: the point-to-point elements' (`element_forces`) and the
    pair closures' among `constraint_forces` as `pair_forces`, the couplings' (the other
    closures) as `coupling_forces` (`outside_forces`)."""
    return {"transmitted": {name: subtree_force(mech, name, t, accelerations)
                            for name in joints},
            **outside_forces(mech, element_forces, constraint_forces)}


def outside_forces(mech: Mechanism, element_forces: Mapping[str, np.ndarray],
                   constraint_forces: Mapping[str, np.ndarray]) -> dict[str, dict]:
    """The forces from outside that an engine's transmitted force holds, as `base.Samples`
    takes them (`joint_reaction` takes them out): the point-to-point elements'
    (`element_forces`) and the pair closures' among the closures' `constraint_forces` as
    `pair_forces`, the couplings' (the other closures) as `coupling_forces`, each by the
    module's sign convention."""
    pairs = pair_element_names(mech)
    return {"pair_forces": {**element_forces, **{name: f for name, f in
                                                 constraint_forces.items() if name in pairs}},
            "coupling_forces": {name: f for name, f in constraint_forces.items()
                                if name not in pairs}}

def slide_generalized_force(mech: Mechanism, joint: Prismatic, t: np.ndarray,
                            q: np.ndarray, qd: np.ndarray,
                            coupling_forces: Mapping[str, np.ndarray]) -> np.ndarray:
    """The generalized force (N,) on a prismatic joint's own coordinate that acts between
    parent and child: its coordinate laws, evaluated on the samples, and the couplings
    among `coupling_forces` that involve it."""
    i = mech.coordinates.index(joint.coordinate)
    total = np.zeros(len(t))
    for f in mech.forces:
        if isinstance(f, CoordinateForce) and f.coordinate == joint.coordinate:
            # a couple (relative_to) joins hinge angles only (model validation)
            total += ForceLaw.of(f).vector_law(q[:, i], qd[:, i], t)
    for c in mech.constraints:
        if isinstance(c, LinearCoupling) and c.name in coupling_forces:
            coef = sum(num(v) for name, v in c.coefficients if name == joint.coordinate)
            if coef:
                total += coef * np.reshape(coupling_forces[c.name], len(t))
    return total


def joint_reaction(mech: Mechanism, joint_name: str, transmitted: np.ndarray,
                   t: np.ndarray, q: np.ndarray, qd: np.ndarray, *,
                   pair_forces: Mapping[str, np.ndarray] | None = None,
                   coupling_forces: Mapping[str, np.ndarray] | None = None,
                   cmap: CoordinateMap | None = None) -> np.ndarray:
    """The contract's reaction at a joint (N, 2) from `transmitted`, the force (N, 2) the
    engine books as passing from parent to child (or `subtree_force`): minus the forces
    entering the child's subtree from outside that it holds, namely the pair elements'
    forces in `pair_forces` that cross the cut, and on a prismatic joint its own slide's
    coordinate laws and the couplings in `coupling_forces` (module docstring: which
    elements, and the sign of each force). t, q, qd: the samples (description
    coordinates)."""
    pair_forces = pair_forces or {}
    coupling_forces = coupling_forces or {}
    joint = mech.joint(joint_name)
    known = {e.name for e in (*mech.forces, *mech.constraints)
             if isinstance(e, PAIR_ELEMENTS)}
    if set(pair_forces) - known:
        raise ValueError(f"not pair elements of the mechanism: {sorted(set(pair_forces) - known)}")
    inside = set(mech.subtree(joint.child))
    out = np.array(transmitted, dtype=float)
    for element in (*mech.forces, *mech.constraints):
        if element.name not in pair_forces or not isinstance(element, PAIR_ELEMENTS):
            continue
        first, second = ((element.body_a, element.body_b)
                         if isinstance(element, PointToPoint) else element.bodies)
        in_first, in_second = first in inside, second in inside
        if in_first != in_second:
            force = np.asarray(pair_forces[element.name], dtype=float)
            out -= force if in_first else -force
    if isinstance(joint, Prismatic):
        Q = slide_generalized_force(mech, joint, t, q, qd, coupling_forces)
        if Q.any():  # NaN too: an unknown force leaves the reaction unknown
            out -= Q[:, None] * slide_direction(mech, joint, q, cmap)
    return out


def joint_reactions(mech: Mechanism, joints: Sequence[str],
                    transmitted: Mapping[str, np.ndarray], t: np.ndarray, q: np.ndarray,
                    qd: np.ndarray, *, pair_forces: Mapping[str, np.ndarray] | None = None,
                    coupling_forces: Mapping[str, np.ndarray] | None = None
                    ) -> dict[str, np.ndarray]:
    """`joint_reaction` at each of `joints`, from the engine's force at each."""
    cmap = coordinate_map(mech)
    return {name: joint_reaction(mech, name, transmitted[name], t, q, qd,
                                 pair_forces=pair_forces, coupling_forces=coupling_forces,
                                 cmap=cmap)
            for name in joints}


def tension_pair_force(element: PointToPoint, length: np.ndarray, rate: np.ndarray,
                       t: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The force (N, 2) of a point-to-point element on its first body (`joint_reaction`'s
    sign), from its length, its rate and the world positions (N, 2) of its points on
    body_a (`a`) and body_b (`b`) at the sample times t: the tension along a -> b."""
    tension = ForceLaw.of(element).vector_law(length, rate, t)
    ab = b - a
    return tension[:, None] * (ab / np.linalg.norm(ab, axis=1)[:, None])


def pair_element_names(mech: Mechanism) -> set[str]:
    """The names of the mechanism's pair elements (`PAIR_ELEMENTS`: force elements and
    closure constraints whose force is a pair of opposite forces on two bodies)."""
    return {e.name for e in (*mech.forces, *mech.constraints) if isinstance(e, PAIR_ELEMENTS)}


# --- forces from Newton-Euler over each step, for an engine that reports none ----------
#
# `frames`: the description bodies' frame states (x, y, theta, vx, vy, omega) by body
# (plan.EliminatedFrames; a body with mass has its frame origin at its centre of mass),
# as arrays over the samples; `loads`: the element loads (`plan.Load`) as applied in each
# step, at the frames `ahead` where the engine evaluated them.


def _world_axis(states: Mapping, body: str, v) -> tuple:
    """A body-frame vector of `body` in world axes."""
    c, s = cos_sin(states[body][2])
    return c * v[0] - s * v[1], s * v[0] + c * v[1]


def actuator_force(mech: Mechanism, joint: Revolute | Prismatic, frames: Mapping,
                   ahead: Mapping, loads: Sequence[Load], h: float) -> np.ndarray:
    """Shape (N,): a prescribed coordinate's actuator force over each step n -> n+1 of h
    (frames over the samples 0..N), from Newton-Euler on the joint's child subtree: per
    body with mass (massless links carry nothing), at n+1, m (a - g) and I alpha. The
    joint's reaction has no component along a slide and no moment about a hinge's point,
    so the actuator's generalized force is, for a slide, d . sum m (a - g) and, for a
    hinge, s sum (I alpha + (r - A) x m (a - g)) (A the hinge point, s = -1 for a
    clockwise coordinate), minus the same of the element loads on the subtree. d is the
    slide's axis in world axes (dq = 1 moves the child by d)."""
    g = num(mech.gravity)
    subtree = mech.subtree(joint.child)
    slide = isinstance(joint, Prismatic)
    sign = -1.0 if not slide and joint.clockwise else 1.0

    def geometry(states: Mapping) -> tuple:  # a slide's world axis, or the hinge point
        if slide:
            return _world_axis(states, joint.parent, plane_point(joint.axis))
        return point_state(states[joint.child], plane_point(joint.child_anchor))[:2]

    n = len(frames[joint.child][0]) - 1
    gx, gy = (np.broadcast_to(np.asarray(v, float), (n + 1,))[1:] for v in geometry(frames))
    total = np.zeros(n)
    for name in subtree:
        if mech.body(name).massless:
            continue
        x, y, _, vx, vy, w = frames[name]
        m, inertia = num(mech.body(name).mass), num(mech.body(name).inertia)
        fx, fy = m * np.diff(vx) / h, m * (np.diff(vy) / h + g)
        if slide:
            total += gx * fx + gy * fy
        else:
            total += sign * (inertia * np.diff(w) / h + (x[1:] - gx) * fy - (y[1:] - gy) * fx)
    ax, ay = geometry(ahead)
    external = np.zeros(n)
    for load in loads:
        if load[0] not in subtree:
            continue
        if not slide:
            external = external + wrench(load, (ax, ay))[2]
        elif load[1] is not None:
            external = external + ax * load[1][0] + ay * load[1][1]
    return total - sign * external


def _balance_columns(mech: Mechanism, frames: Mapping) -> list[tuple]:
    """The unknowns of the momentum balance (`balance_forces`), one column each: (kind,
    name, its loads on the description bodies at unit value, its direction in world axes
    or None): two force components of a hinge or a point-on-point closure; the normal
    force and the moment of a slide; the normal force of a slot; the generalized force of
    a coupling."""
    out = []

    def pair(kind, name, a, b, force, w):
        out.append((kind, name, [(a, force, w, 0.0), (b, (-force[0], -force[1]), w, 0.0)],
                    force))

    def normal(body, d):  # the unit normal of direction d of `body`, in world axes
        direction = np.array(plane_point(d))
        dx, dy = _world_axis(frames, body, direction / float(np.linalg.norm(direction)))
        return -dy, dx

    def place(body, local):
        return point_state(frames[body], plane_point(local))[:2]

    for j in mech.joints:
        w = place(j.child, j.child_anchor)
        if isinstance(j, Revolute):
            for e in ((1.0, 0.0), (0.0, 1.0)):
                pair("joint", j.name, j.child, j.parent, e, w)
        else:
            pair("joint", j.name, j.child, j.parent, normal(j.parent, j.axis), w)
            out.append(("moment", j.name, [(j.child, None, None, 1.0),
                                           (j.parent, None, None, -1.0)], None))
    for c in mech.constraints:
        if isinstance(c, PointOnPoint):
            w = place(c.body_a, c.point_a)
            for e in ((1.0, 0.0), (0.0, 1.0)):
                pair("closure", c.name, c.body_a, c.body_b, e, w)
        elif isinstance(c, PointOnLine):
            pair("closure", c.name, c.body, c.line_body, normal(c.line_body, c.direction),
                 place(c.body, c.point))
        else:
            out.append(("closure", c.name, [
                load for name, coef in c.coefficients for load in coordinate_load(
                    mech.joints[mech.coordinates.index(name)])(frames, num(coef))], None))
    return out


def body_wrenches(bodies: list[str], loads: Sequence[Load], frames: Mapping,
                  n: int) -> np.ndarray:
    """(n, 3 per body): the loads' wrenches on every body about its frame origin."""
    out = np.zeros((n, 3 * len(bodies)))
    for load in loads:
        if load[0] != WORLD:
            i = bodies.index(load[0])
            out[:, 3 * i:3 * i + 3] += sample_columns(wrench(load, frames[load[0]][:2]), n)
    return out


def balance_forces(mech: Mechanism, frames: Mapping, needed: np.ndarray
                   ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray], float]:
    """(joint reactions, closure-constraint forces, relative residual) from the momentum
    balance of every description body at n samples: `needed` (n, 3 per body, in
    `mech.bodies` order) is the wrench (fx, fy, moment about the frame origin) that the
    unknown joint reactions and closure multipliers exert on each body, at the frames
    `frames` that give their directions and points. Solved in least squares
    (pseudo-inverse) per sample; massless bodies enter with zero inertia, so the force in
    a joint of a massless link is its static balance. The reactions are unknowns of the
    same solve as the closure forces (these cannot be had without them), so the subtree
    balance of `joint_reaction` would be a second path, not a replacement. The forces
    follow the contract's conventions (the reaction on the joint's child; a pair
    closure's on its first body; a coupling's generalized force)."""
    n = needed.shape[0]
    bodies = [b.name for b in mech.bodies]
    columns = _balance_columns(mech, frames)
    A = np.stack([body_wrenches(bodies, loads, frames, n) for _, _, loads, _ in columns],
                 axis=-1)
    x = (np.linalg.pinv(A) @ needed[..., None])[..., 0]
    resid = np.linalg.norm(np.einsum("nij,nj->ni", A, x) - needed, axis=1)
    residual = float(np.max(resid) / max(float(np.max(np.abs(needed))), 1e-300))
    grouped: dict[tuple[str, str], list[int]] = {}
    for i, (kind, name, _, _) in enumerate(columns):
        if kind != "moment":
            grouped.setdefault((kind, name), []).append(i)

    def assemble(indices: list[int]) -> np.ndarray:
        direction = columns[indices[0]][3]
        if len(indices) == 1 and direction is not None:  # magnitude along its direction
            return x[:, indices] * sample_columns(direction, n)
        return x[:, indices]

    joint_forces = {name: assemble(ix) for (kind, name), ix in grouped.items()
                    if kind == "joint"}
    constraint_forces = {c.name: assemble(grouped["closure", c.name]) for c in mech.constraints}
    return joint_forces, constraint_forces, residual


def motion_reactions(mech: Mechanism, joints: Sequence[str], frames: Mapping,
                     ahead: Mapping, element_loads: Sequence, t_applied: np.ndarray,
                     h: float) -> dict[str, np.ndarray]:
    """The contract's reaction (N, 2) at each of `joints` over each step n -> n+1 of h
    (`frames` over the samples 0..N), for an engine that reports no joint force: Newton
    on the child's subtree, sum m (v(n+1) - v(n))/h - m g (`subtree_force`), minus the
    forces from outside as applied in the step (`joint_reaction`): the force elements'
    (`element_loads`: each one's loads as a function of the frames and t, in
    `mech.forces` order) evaluated at the frames `ahead` and the times `t_applied`."""
    n = len(t_applied)
    accelerations = {b.name: np.column_stack([np.diff(frames[b.name][3]) / h,
                                              np.diff(frames[b.name][4]) / h])
                     for b in mech.bodies if not b.massless}
    # a pair element's force on its first body as applied (`plan.element_loads`: the
    # second load of a PointToPoint is the one on body_a)
    paired = pair_element_names(mech)
    pairs = {f.name: sample_columns(loads(ahead, t_applied)[1][1], n)
             for f, loads in zip(mech.forces, element_loads) if f.name in paired}
    q, qd = (sample_columns(cols, n) for cols in joint_coordinates(mech, ahead))
    transmitted = {j: subtree_force(mech, j, t_applied, accelerations) for j in joints}
    return joint_reactions(mech, joints, transmitted, t_applied, q, qd, pair_forces=pairs)


# --- every force of an engine in maximal coordinates that reports none -----------------


def after_first_step(values: np.ndarray) -> np.ndarray:
    """Forces over the steps n -> n+1 (N rows) given to samples 1..N; sample 0 has no
    step before it and is NaN."""
    values = np.asarray(values)
    out = np.full((len(values) + 1, *values.shape[1:]), np.nan)
    out[1:] = values
    return out


def maximal_balance(mech: Mechanism, parts: Sequence[tuple[str, float, float]],
                    S: np.ndarray, frames: Mapping, ahead: Mapping, loads: Sequence[Load],
                    h: float) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray], float]:
    """`balance_forces` over each step n -> n+1 of h for an engine in maximal coordinates:
    its state rows `S` (samples 0..N; per engine body its centre of gravity x, y, its
    angle and their rates) and per engine body, in the same order, `parts`: the
    description body it makes up (with the others of that body), its mass and its moment
    about its centre of gravity. For every description body, the parts give sum m (a - g)
    and sum (I alpha + r x m (a - g)) about its frame origin at n+1 (`frames`, samples
    1..N); minus the element `loads` as applied in the step (at `ahead`), that is the
    wrench of the unknown joint reactions and closure multipliers at n+1."""
    m_steps = len(S) - 1
    bodies = [b.name for b in mech.bodies]
    rhs = np.zeros((m_steps, 3 * len(bodies)))
    g = num(mech.gravity)
    for k, (host, m, inertia) in enumerate(parts):
        i = bodies.index(host)
        fx = m * np.diff(S[:, 6 * k + 3]) / h
        fy = m * (np.diff(S[:, 6 * k + 4]) / h + g)
        alpha = np.diff(S[:, 6 * k + 5]) / h
        cx, cy = sample_columns(frames.state(host)[:2], m_steps).T
        rx, ry = S[1:, 6 * k] - cx, S[1:, 6 * k + 1] - cy
        rhs[:, 3 * i] += fx
        rhs[:, 3 * i + 1] += fy
        rhs[:, 3 * i + 2] += inertia * alpha + rx * fy - ry * fx
    rhs -= body_wrenches(bodies, loads, ahead, m_steps)
    return balance_forces(mech, frames, rhs)


def motion_forces(mech: Mechanism, engine: MaximalFrames, S: np.ndarray,
                  parts: Sequence[tuple[str, float, float]], H: float, t_applied: np.ndarray,
                  h: float, reaction_joints: Sequence[str],
                  drives: Mapping[str, Revolute | Prismatic]
                  ) -> tuple[dict, dict, dict, float | None]:
    """The contract's forces of a run of an engine in maximal coordinates that reports no
    force, from its state rows `S` (samples 0..N; `parts`: see `maximal_balance`): over
    each step n -> n+1 of h, with the element loads as applied in it (at x + H v and
    `t_applied`), given to sample n+1 (`after_first_step`). With closure constraints, the
    reactions at `reaction_joints` and the closure forces from the balance of every body
    (`maximal_balance`); in a tree, the reactions on the joint child's subtree
    (`motion_reactions`); the actuator force of each prescribed coordinate (`drives`: its
    element's name -> its joint) on its child's subtree (`actuator_force`). Returns
    (reactions, constraint forces, actuator forces, the balance's relative residual or
    None in a tree)."""
    frames, ahead = engine.frames(S), engine.frames(S[:-1], H)
    loads = engine.body_loads(ahead, t_applied) if mech.constraints or drives else []
    reactions: dict[str, np.ndarray] = {}
    constraint_forces: dict[str, np.ndarray] = {}
    residual = None
    if mech.constraints:
        joint_forces, constraint_forces, residual = maximal_balance(
            mech, parts, S, engine.frames(S[1:]), ahead, loads, h)
        reactions = {j: joint_forces[j] for j in reaction_joints}
    elif reaction_joints:
        reactions = motion_reactions(mech, reaction_joints, frames, ahead, engine.elements,
                                     t_applied, h)
    actuator_forces = {name: actuator_force(mech, joint, frames, ahead, loads, h)
                       for name, joint in drives.items()}
    reactions, constraint_forces, actuator_forces = (
        {name: after_first_step(f) for name, f in forces.items()}
        for forces in (reactions, constraint_forces, actuator_forces))
    return reactions, constraint_forces, actuator_forces, residual
