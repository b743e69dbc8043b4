"""The planar kinematics of the description, on numbers, on arrays of samples or on symbols.

- forward kinematics: the bodies' frames from q (`body_states`) and a body point's
  position and velocity (`point_state`, `moving_point`); why a spatial build cannot hold
  a spatial mechanism (`spatial_tree_reason`); the bodies a pair element acts on
  (`PAIR_ELEMENTS`, `pair_element_bodies`);
- for an engine whose bodies carry chains of joints but not massless bodies, the massless
  links folded into them (`foldable_massless`, `joint_chains`);
- the functions that take numbers, arrays of samples or SymPy expressions (`cos_sin`,
  `sqrt`, `atan2`, `law_value`, `linear_solver`), `traced`, which compiles a step's
  function into straight-line code, and q from the frames (`coordinate_reader`,
  `joint_coordinates`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
import sympy as sp

from ...systems.model import (
    WORLD,
    Mechanism,
    PointOnLine,
    PointOnPoint,
    PointToPoint,
    Prismatic,
    Revolute,
)
from .numeric import num
from .kinds_and_laws import ForceLaw


# --- forward kinematics ----------------------------------------------------------------


def body_states(mech: Mechanism, q, qd) -> dict[str, tuple[float, ...]]:
    """(x, y, theta, vx, vy, omega) of every description body's frame at (q, qd), by
    planar forward kinematics in joint order (conventions 3-5 of `systems.model`)."""
    st: dict[str, tuple[float, ...]] = {WORLD: (0.0,) * 6}

    def turn(th: float, v) -> tuple[float, float]:
        c, s = math.cos(th), math.sin(th)
        return c * v[0] - s * v[1], s * v[0] + c * v[1]

    for j, qj, qdj in zip(mech.joints, q, qd):
        x, y, th_p, vx, vy, w_p = st[j.parent]
        pa = (num(j.parent_anchor[0]), num(j.parent_anchor[1]))
        ca = (num(j.child_anchor[0]), num(j.child_anchor[1]))
        off = num(j.angle_offset)
        if isinstance(j, Revolute):
            if j.clockwise:
                qj, qdj = -qj, -qdj
            th = (0.0 if j.absolute else th_p) + qj + off
            w = (0.0 if j.absolute else w_p) + qdj
            r = turn(th_p, pa)
            va = (vx - w_p * r[1], vy + w_p * r[0])
        else:
            th, w = th_p + off, w_p
            axis = (num(j.axis[0]), num(j.axis[1]))
            r = turn(th_p, (pa[0] + qj * axis[0], pa[1] + qj * axis[1]))
            slide = turn(th_p, axis)
            va = (vx - w_p * r[1] + qdj * slide[0], vy + w_p * r[0] + qdj * slide[1])
        a = (x + r[0], y + r[1])
        rc = turn(th, ca)
        st[j.child] = (a[0] - rc[0], a[1] - rc[1], th, va[0] + w * rc[1], va[1] - w * rc[0], w)
    return st


def moving_point(state: tuple, local) -> tuple:
    """World position and velocity (x, y, vx, vy) of a body point from the body's
    `EliminatedFrames.state`."""
    x, y, _, c, s, vx, vy, w = state
    rx, ry = c * local[0] - s * local[1], s * local[0] + c * local[1]
    return x + rx, y + ry, vx - w * ry, vy + w * rx


def point_state(st: tuple, local) -> tuple:
    """World position and velocity (x, y, vx, vy) of a body point, from the body frame's
    state (x, y, theta, vx, vy, omega), whose entries are numbers, arrays of samples or
    SymPy expressions (`cos_sin`)."""
    x, y, th, vx, vy, w = st
    return moving_point((x, y, th, *cos_sin(th), vx, vy, w), local)


def spatial_tree_reason(mech: Mechanism, *, closures: bool, slides: bool,
                        point_forces: bool = False) -> str:
    """Why an engine's spatial build (model convention 10) cannot hold a spatial
    mechanism, empty when it can: every such build takes relative, counter-clockwise
    hinges without an angle offset and folds no massless body; `closures`, `slides` and
    `point_forces` say whether it takes closure constraints (a spatial mechanism's are
    hinge closures), prismatic joints and point-to-point elements."""
    if mech.constraints and not closures:
        return "closure constraints in a spatial mechanism"
    for j in mech.joints:
        if isinstance(j, Prismatic) and not slides:
            return f"joint {j.name}: the spatial build has hinges only"
        if isinstance(j, Revolute) and (j.absolute or j.clockwise):
            return f"joint {j.name}: the spatial build takes relative, counter-clockwise hinges"
        if num(j.angle_offset) != 0:
            return f"joint {j.name}: the spatial build takes no angle offset"
    if any(b.massless for b in mech.bodies):
        return "a massless body in a spatial mechanism (the spatial build folds none)"
    if not point_forces and any(isinstance(f, PointToPoint) for f in mech.forces):
        return "a point-to-point element in a spatial mechanism (the spatial build has none)"
    return ""


#: the elements whose force is a pair of opposite forces on two bodies
PAIR_ELEMENTS = (PointToPoint, PointOnPoint, PointOnLine)


def pair_element_bodies(mech: Mechanism) -> set[str]:
    """The bodies a pair element (`PAIR_ELEMENTS`) acts on."""
    return ({b for c in mech.constraints if isinstance(c, PAIR_ELEMENTS) for b in c.bodies}
            | {b for f in mech.forces if isinstance(f, PointToPoint) for b in (f.body_a, f.body_b)})


# --- massless bodies folded into joint chains ------------------------------------------


def foldable_massless(mech: Mechanism) -> set[str]:
    """Massless bodies whose joints can be folded into their single child (exact) by an
    engine whose bodies carry a chain of joints. A massless body with another number of
    child joints, or that a constraint or a point-to-point element refers to, has no such
    child frame."""
    used = pair_element_bodies(mech)
    return {b.name for b in mech.bodies if b.massless and b.name not in used
            and sum(1 for j in mech.joints if j.parent == b.name) == 1}


@dataclass(frozen=True)
class JointChains:
    """The joints regrouped for an engine whose bodies carry a chain of joints but that
    has no massless bodies: each `foldable` body (`foldable_massless`) is folded, its
    joints join the chain of the body it carries. `carrier`: description body -> the
    engine body carrying it; `chains`: engine body -> description joint indices, in order
    (the engine applies a body's joints in order); `parent`: engine body -> its engine
    parent."""

    foldable: set[str]
    carrier: dict[str, str]
    chains: dict[str, list[int]]
    parent: dict[str, str]


def joint_chains(mech: Mechanism) -> JointChains:
    """The `JointChains` of a mechanism."""
    foldable = foldable_massless(mech)
    carrier: dict[str, str] = {}
    for body in reversed([j.child for j in mech.joints]):
        if body in foldable:
            child = next(j.child for j in mech.joints if j.parent == body)
            carrier[body] = carrier[child]
        else:
            carrier[body] = body
    chains: dict[str, list[int]] = {}
    for i, j in enumerate(mech.joints):
        chains.setdefault(carrier[j.child], []).append(i)
    parent = {name: WORLD if mech.joints[chain[0]].parent == WORLD
              else carrier[mech.joints[chain[0]].parent] for name, chain in chains.items()}
    return JointChains(foldable, carrier, chains, parent)


# --- planar kinematics on numbers or on arrays of samples ------------------------------


# The functions below take numbers (one step), arrays of samples (a run's read-out) or
# SymPy expressions (`traced`: a step's function compiled to straight-line code).


def _module(*values):
    """The functions for the kind of the values: NumPy, SymPy or `math`."""
    if all(type(v) is float for v in values):  # one step's numbers: the common case
        return math
    if any(isinstance(v, np.ndarray) for v in values):
        return np
    if any(isinstance(v, sp.Basic) for v in values):
        return sp
    return math


def cos_sin(theta):
    """(cos, sin) of an angle."""
    m = _module(theta)
    return m.cos(theta), m.sin(theta)


def sqrt(x):
    return _module(x).sqrt(x)


def atan2(y, x):
    m = _module(y, x)
    return m.atan2(y, x)


def law_value(law: ForceLaw, x, xd, t):
    """A force law at (x, x', t): compiled for numbers, vectorised for arrays, its
    expression for SymPy arguments."""
    m = _module(x, xd, t)
    if m is sp:
        return law.expr.xreplace(dict(zip(law.args, map(sp.sympify, (x, xd, t)))))
    return (law.vector_law if m is np else law.law)(x, xd, t)


def linear_solver(A: list[list]) -> Callable[[list], list]:
    """Solving A x = b for a small square A (nested lists) whose entries are numbers,
    arrays of samples (one matrix per sample) or SymPy expressions; the solver takes
    and gives lists of the same kind (b's entries may also be arrays over other
    right-hand sides when A's are numbers)."""
    flat = [e for row in A for e in row]
    m = len(A)
    if _module(*flat) is sp:
        M = sp.Matrix(A)
        return lambda b: list(M.LUsolve(sp.Matrix([sp.sympify(v) for v in b])))
    arrays = np.broadcast_arrays(*[np.asarray(e, dtype=float) for e in flat])
    M = np.array(arrays).reshape(m, m, *arrays[0].shape)
    if M.ndim == 2:
        inv = np.linalg.inv(M).tolist()
    else:
        full = np.linalg.inv(np.moveaxis(M, (0, 1), (-2, -1)))
        inv = [[full[..., i, j] for j in range(m)] for i in range(m)]
    return lambda b: [sum(inv[i][j] * b[j] for j in range(m)) for i in range(m)]


def traced(fn: Callable[..., Sequence], n_args: int) -> Callable[..., list]:
    """A numeric function of `n_args` numbers made of arithmetic and this module's
    functions, compiled to straight-line code: evaluated once on symbols and lambdified
    with its common subexpressions computed once (what a step's loads cost)."""
    # names unlike lambdify's common-subexpression temporaries (x0, x1, ...)
    args = sp.symbols(f"arg_0:{n_args}", real=True)
    return sp.lambdify(args, [sp.sympify(v) for v in fn(*args)], modules="math", cse=True)


def coordinate_reader(joint: Revolute | Prismatic) -> Callable[[tuple, tuple], tuple]:
    """A function giving a joint's coordinate and rate (q, qd) from the frame states
    (x, y, theta, vx, vy, omega) of its parent and its child, numbers or arrays of
    samples: the inverse of `body_states` for that joint. A hinge's coordinate is the
    relative angle, a slide's the travel of the child's anchor along the parent's axis
    (over the axis length). The joint's numbers are read once."""
    off = num(joint.angle_offset)
    if isinstance(joint, Revolute):
        sign = -1.0 if joint.clockwise else 1.0
        if joint.absolute:
            return lambda parent, child: (sign * (child[2] - off), sign * child[5])
        return lambda parent, child: (sign * (child[2] - parent[2] - off),
                                      sign * (child[5] - parent[5]))
    pa = (num(joint.parent_anchor[0]), num(joint.parent_anchor[1]))
    ca = (num(joint.child_anchor[0]), num(joint.child_anchor[1]))
    a = (num(joint.axis[0]), num(joint.axis[1]))
    norm2 = a[0] * a[0] + a[1] * a[1]

    def read(parent: tuple, child: tuple) -> tuple:
        xa, ya, vxa, vya = point_state(parent, pa)
        xb, yb, vxb, vyb = point_state(child, ca)
        c, s = cos_sin(parent[2])
        ax, ay = c * a[0] - s * a[1], s * a[0] + c * a[1]  # the axis in world axes
        dx, dy = xb - xa, yb - ya
        # d/dt (R a . d) = R a . d' + omega (perp R a) . d
        return ((ax * dx + ay * dy) / norm2,
                (ax * (vxb - vxa) + ay * (vyb - vya) + parent[5] * (ax * dy - ay * dx)) / norm2)

    return read


def joint_coordinates(mech: Mechanism, states) -> tuple[list, list]:
    """The coordinates and rates (q, qd) from the frame states of the description's
    bodies (a mapping from body name, the world included; numbers or arrays of samples)."""
    pairs = [coordinate_reader(j)(states[j.parent], states[j.child]) for j in mech.joints]
    return [p[0] for p in pairs], [p[1] for p in pairs]
