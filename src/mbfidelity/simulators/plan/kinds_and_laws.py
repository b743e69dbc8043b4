"""The element kinds of a description, its force laws and prescribed motions, and whether
it can be translated at all.

- the element kinds of the description (`ELEMENT_KINDS`, `element_kind`, `elements`): the
  vocabulary in which each backend declares how exactly it expresses an element
  (`base.Expression`), with the body conditions an expression asks for (`rigid_body`,
  `point_mass`, `massive_below`, `held_below`);
- the force laws, compiled once, with their classification (`ForceLaw`): linear (a
  spring of stiffness -b and free length -a/b, a damper of coefficient c, or a constant
  force, ``a + b x + c x'`` with no TIME) or custom; the coordinate laws' generalized
  force, as an engine's force callback evaluates it (`CoordinateLaws`);
- the prescribed motions (`Motion`, `motions`) and the start state they impose
  (`driven_start`); a driven run's consistent start in a tree of relative joints
  (`prescribed_start`) and a drive's first-step rate (`stepped_start`); for an engine
  without an exact imposed motion, the prescribed motions imposed by generalized forces
  (`ImposedMotions`, at the stage time `stage_time`), and whether a motion drives one
  engine joint value (`one_joint_value`);
- the bodies a closure acts on (`constrained_bodies`) and the mechanism with each
  RollingContact replaced by the rolling coupling it stands for (`coupled`);
- the checks that a description can be translated at all (`description_reason`: every
  entry numeric, no zero axis, slot direction or coupling).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property, singledispatch
from typing import Callable, Iterator, Mapping, Sequence

import numpy as np
import sympy as sp

from ...systems.model import (
    COORD,
    COORD_RATE,
    LENGTH,
    LENGTH_RATE,
    TIME,
    WORLD,
    Body,
    CoordinateForce,
    HingeClosure,
    LinearCoupling,
    Mechanism,
    PointOnLine,
    PointOnPoint,
    PointToPoint,
    Prescribed,
    Prismatic,
    Revolute,
    RollingContact,
    compile_law,
)
from .numeric import NotNumeric, linear_law, num
from .coordinates import CoordinateMap, coordinate_map


# --- element kinds ---------------------------------------------------------------------

BODY = "body"
MASSLESS_BODY = "massless body"
REVOLUTE = "Revolute"
PRISMATIC = "Prismatic"
POINT_TO_POINT_LINEAR = "PointToPoint, linear law"
POINT_TO_POINT_CUSTOM = "PointToPoint, custom law"
COORDINATE_FORCE_LINEAR = "CoordinateForce, linear law"
COORDINATE_FORCE_CUSTOM = "CoordinateForce, custom law"
TIME_LOAD = "time load"
POINT_ON_POINT = "PointOnPoint"
POINT_ON_LINE = "PointOnLine"
LINEAR_COUPLING = "LinearCoupling"
ROLLING_CONTACT = "RollingContact"
PRESCRIBED = "Prescribed"
HINGE_CLOSURE = "HingeClosure"

#: every kind of element a description holds, in the order backends declare them
ELEMENT_KINDS = (BODY, MASSLESS_BODY, REVOLUTE, PRISMATIC, POINT_TO_POINT_LINEAR,
                 POINT_TO_POINT_CUSTOM, COORDINATE_FORCE_LINEAR, COORDINATE_FORCE_CUSTOM,
                 TIME_LOAD, POINT_ON_POINT, POINT_ON_LINE, LINEAR_COUPLING, ROLLING_CONTACT,
                 PRESCRIBED, HINGE_CLOSURE)


@singledispatch
def element_kind(element) -> str:
    """The kind of one element of a numeric description."""
    raise TypeError(f"no element kind for {type(element).__name__}")


@element_kind.register
def _(element: Body) -> str:
    return MASSLESS_BODY if element.massless else BODY


def _force_kind(element) -> str:
    return ForceLaw.of(element).kind


element_kind.register(PointToPoint, _force_kind)
element_kind.register(CoordinateForce, _force_kind)
#: the element types whose kind does not depend on the element
_FIXED_KINDS = {Revolute: REVOLUTE, Prismatic: PRISMATIC, PointOnPoint: POINT_ON_POINT,
                PointOnLine: POINT_ON_LINE, LinearCoupling: LINEAR_COUPLING,
                RollingContact: ROLLING_CONTACT, Prescribed: PRESCRIBED,
                HingeClosure: HINGE_CLOSURE}
for _type, _kind in _FIXED_KINDS.items():
    element_kind.register(_type, lambda element, kind=_kind: kind)
del _type, _kind


def rigid_body(mech: Mechanism, body: Body) -> bool:
    """Mass and central inertia both positive (an `Expression.applies` condition)."""
    return num(body.mass) > 0 and num(body.inertia) > 0


def point_mass(mech: Mechanism, body: Body) -> bool:
    """Mass positive (with `rigid_body` false: central inertia zero)."""
    return num(body.mass) > 0


def massive_below(mech: Mechanism, body: Body) -> bool:
    """Some body of the subtree from `body` (itself included) has mass."""
    return any(not mech.body(b).massless for b in mech.subtree(body.name))


def held_below(mech: Mechanism, body: Body) -> bool:
    """Some body of the subtree from `body` (itself included) has mass or is acted on by a
    closure constraint (`constrained_bodies`): what keeps a massless link's coordinates
    determined in a tree of relative joints (an `Expression.applies` condition)."""
    return massive_below(mech, body) or bool(
        constrained_bodies(mech) & set(mech.subtree(body.name)))


def elements(mech: Mechanism) -> Iterator[tuple[str, object]]:
    """(kind, element) for every element of the description, in description order."""
    for group in (mech.bodies, mech.joints, mech.forces, mech.constraints, mech.prescribed):
        for element in group:
            yield element_kind(element), element


# --- force laws ------------------------------------------------------------------------


@dataclass(frozen=True)
class ForceLaw:
    """A force element's law, classified and compiled once: `linear` is (a, b, c) with
    law = a + b x + c x' when the law has that form and no TIME (None: custom law);
    `law` is the compiled scalar function of (x, x', t), with x, x' the length and its
    rate (PointToPoint) or the coordinate and its rate (CoordinateForce)."""

    element: PointToPoint | CoordinateForce

    @staticmethod
    def of(element: PointToPoint | CoordinateForce) -> "ForceLaw":
        return _force_law(element)

    @property
    def expr(self) -> sp.Expr:
        e = self.element
        return sp.sympify(e.tension if isinstance(e, PointToPoint) else e.force)

    @property
    def args(self) -> tuple[sp.Symbol, sp.Symbol, sp.Symbol]:
        if isinstance(self.element, PointToPoint):
            return LENGTH, LENGTH_RATE, TIME
        return COORD, COORD_RATE, TIME

    @cached_property
    def time_dependent(self) -> bool:
        return TIME in self.expr.free_symbols

    @cached_property
    def linear(self) -> tuple[float, float, float] | None:
        return linear_law(self.expr, *self.args[:2])

    @property
    def tendon_spring(self) -> tuple[float, float, float] | None:
        """(stiffness, free length, damping) where the law is linear and a tendon's own
        spring and damper hold it: a + k L + c L' with k > 0 and a free length -a/k >= 0,
        or a pure damper (k = a = 0), and c >= 0; None otherwise."""
        if self.linear is None:
            return None
        a, k, c = self.linear
        if k > 0 and -a / k >= 0 and c >= 0:
            return k, -a / k + 0.0, c
        if k == 0 and a == 0 and c >= 0:
            return 0.0, 0.0, c
        return None

    @property
    def kind(self) -> str:
        point = isinstance(self.element, PointToPoint)
        if self.time_dependent:
            return TIME_LOAD
        if self.linear is not None:
            return POINT_TO_POINT_LINEAR if point else COORDINATE_FORCE_LINEAR
        return POINT_TO_POINT_CUSTOM if point else COORDINATE_FORCE_CUSTOM

    @cached_property
    def law(self) -> Callable[[float, float, float], float]:
        return compile_law(self.expr, self.args)

    @cached_property
    def vector_law(self) -> Callable[..., np.ndarray]:
        """The law evaluated on arrays of samples (read-outs after a run)."""
        fn = sp.lambdify(self.args, self.expr, modules="numpy")

        def call(*arrays: np.ndarray) -> np.ndarray:
            out = np.asarray(fn(*arrays), dtype=float)
            return np.broadcast_to(out, np.shape(arrays[0])).astype(float)

        return call


class CoordinateLaws:
    """Coordinate laws (`CoordinateForce`) evaluated together, as an engine's force
    callback evaluates them at each stage: `generalized(q, qd, t)` is their generalized
    force on the description coordinates (each law F(COORD, COORD', t) acts with
    sign * F on each coordinate of its `weights`), as a list (q, qd: sequences)."""

    def __init__(self, mech: Mechanism, forces) -> None:
        self.n = len(mech.joints)
        self.terms = tuple((tuple(f.weights(mech.coordinates).items()), ForceLaw.of(f).law)
                           for f in forces)

    def __bool__(self) -> bool:
        return bool(self.terms)

    def generalized(self, q, qd, t: float) -> list[float]:
        Q = [0.0] * self.n
        for w, law in self.terms:
            F = law(sum(s * q[i] for i, s in w), sum(s * qd[i] for i, s in w), t)
            for i, s in w:
                Q[i] += s * F
        return Q


    def on_engine_values(self, T: np.ndarray, c: np.ndarray
                         ) -> Callable[[Sequence[float], Sequence[float], float], list]:
        """The generalized force on engine joint values u (q = T u + c) as a function of
        (u, u', t): T^T Q(T u + c, T u', t), or Q itself where the engine's values are the
        description's coordinates (T = I, c = 0)."""
        if np.array_equal(T, np.eye(self.n)) and not np.any(c):
            return self.generalized

        def mapped(u, u_t, t: float) -> list:
            Q = self.generalized(T @ np.asarray(u) + c, T @ np.asarray(u_t), t)
            return (T.T @ np.asarray(Q)).tolist()

        return mapped


_LAWS: dict[object, ForceLaw] = {}


def _force_law(element) -> ForceLaw:
    """One `ForceLaw` per element (its classification and compiled law are reused by
    every run of the same numeric mechanism)."""
    law = _LAWS.get(element)
    if law is None:
        if len(_LAWS) > 512:
            _LAWS.clear()
        law = _LAWS[element] = ForceLaw(element)
    return law


@dataclass(frozen=True)
class Motion:
    """A prescribed coordinate's motion (convention 9), compiled once: `position`,
    `rate`, `acceleration` are scalar functions of t (the rate and acceleration are the
    symbolic derivatives of q(t), never finite differences); `index` is the coordinate's
    place among the description coordinates."""

    element: Prescribed
    index: int

    @cached_property
    def position(self) -> Callable[[float], float]:
        return compile_law(self.element.motion, (TIME,))

    @cached_property
    def rate(self) -> Callable[[float], float]:
        return compile_law(self.element.rate, (TIME,))

    @cached_property
    def acceleration(self) -> Callable[[float], float]:
        return compile_law(self.element.acceleration, (TIME,))

    def along(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, q', q'') at the sample times `t`."""
        t = np.asarray(t, dtype=float)
        return tuple(np.array([f(x) for x in t]) for f in (self.position, self.rate,
                                                          self.acceleration))


def motions(mech: Mechanism) -> list[Motion]:
    """The prescribed motions of a numeric mechanism, in description order."""
    return [Motion(p, mech.coordinates.index(p.coordinate)) for p in mech.prescribed]


def one_joint_value(mech: Mechanism, prescribed: Prescribed) -> bool:
    """Whether a prescribed coordinate is one engine joint value, q_k = T_kk v_k + c_k (not
    a combination of them, as an absolute angle on a turning parent is): its row of
    v = A q + b has one entry, and then so has its row of T = A^-1 (A is triangular with
    a whole diagonal). An `Expression.applies` condition."""
    i = mech.coordinates.index(prescribed.coordinate)
    return int(np.count_nonzero(coordinate_map(mech).A[i])) == 1


class ImposedMotions:
    """The prescribed motions imposed through generalized forces, for an engine without
    an exact imposed motion. The prescribed coordinates are rows of q = T (v - b)
    (`rows`), so their accelerations are T_p v'' and their actuator forces Q_p enter as
    the engine forces T_p^T Q_p (virtual work; `Tp` spans the engine's `nv` velocity
    entries, the joints' at `dofs`). With v'' = H^-1 (f + T_p^T Q_p), f the engine's
    free force and H the matrix its integrator solves with, the k x k system
    (T_p H^-1 T_p^T) Q_p = target - T_p H^-1 f gives Q_p (`actuator_forces`). The target
    is q''(t) where the engine calls back at every stage with the stage time; for a
    first-order integrator (`discrete`, step h) it is the discrete acceleration
    ((q(t+h) - q)/h - q')/h that lands the coordinate on q(t+h) after the step."""

    def __init__(self, mech: Mechanism, cmap: CoordinateMap, dofs: np.ndarray, nv: int,
                 discrete: bool, h: float) -> None:
        moves = motions(mech)
        self.k = len(moves)
        self.rows = cmap.T[[mv.index for mv in moves]]  # q_p = rows (v - b)
        self.Tp = np.zeros((self.k, nv))
        self.Tp[:, dofs] = self.rows
        self.Tp_t = np.ascontiguousarray(self.Tp.T)
        self.b = cmap.b
        self.positions = [mv.position for mv in moves]
        self.accelerations = [mv.acceleration for mv in moves]
        self.discrete, self.h = discrete, float(h)

    def targets(self, t: float, values: np.ndarray | None, rates: np.ndarray) -> list[float]:
        """The prescribed coordinates' target accelerations at the stage time t; the
        engine joint values v and the engine's velocity entries are read by a first-order
        integrator's target only."""
        if not self.discrete:
            return [f(t) for f in self.accelerations]
        h = self.h
        q_now = self.rows @ (values - self.b)
        qd_now = self.Tp @ rates
        return [((f(t + h) - x) / h - xd) / h
                for f, x, xd in zip(self.positions, q_now.tolist(), qd_now.tolist())]

    def actuator_forces(self, solved: np.ndarray, target: Sequence[float],
                        actuator: np.ndarray, applied: np.ndarray) -> None:
        """Q_p into `actuator` and the engine forces T_p^T Q_p into `applied`, from
        `solved` = H^-1 [f, T_p^T] (one row per column: the free force's, then each
        prescribed coordinate's) and the `target` accelerations."""
        if self.k == 1:
            column = self.Tp[0]
            free, w = (solved @ column).tolist()  # T_p H^-1 f and T_p H^-1 T_p^T
            actuator[0] = (target[0] - free) / w
            np.multiply(column, actuator[0], out=applied)
        else:
            W = solved[1:] @ self.Tp_t  # T_p H^-1 T_p^T
            actuator[:] = np.linalg.solve(W, np.asarray(target) - self.Tp @ solved[0])
            np.dot(self.Tp_t, actuator, out=applied)


def stage_time(clock: float, half_step: float) -> float:
    """The stage time nearest an engine's clock in a fixed-step run from t = 0: the stage
    times are multiples of h/2, while a clock that adds h at every step drifts from them
    by ~N eps t after N steps, a phase error of time-dependent laws and motions that does
    not shrink with h."""
    return round(clock / half_step) * half_step


def driven_start(mech: Mechanism, q0, qd0) -> tuple[np.ndarray, np.ndarray]:
    """The initial state (copies) with each prescribed coordinate on its motion at t = 0
    (convention 9: it follows q(t) for the whole run, so its start is not free)."""
    q0, qd0 = np.array(q0, dtype=float), np.array(qd0, dtype=float)
    for motion in motions(mech):
        q0[motion.index], qd0[motion.index] = motion.position(0.0), motion.rate(0.0)
    return q0, qd0


def prescribed_start(mass: np.ndarray, rhs: np.ndarray, prescribed: Mapping[int, float]
                     ) -> tuple[np.ndarray, np.ndarray]:
    """(accelerations, multipliers) at the start of a driven run that meet the prescribed
    accelerations u_p'' (`prescribed`: coordinate index -> u_p'') of a system M u'' +
    C^T lam = f whose prescribed coordinates are held by constraints C = e_p^T: the free
    ones from M_ff u_f'' = f_f - M_fp u_p'', and lam_p = f_p - (M u'')_p (M, f: the
    engine's mass matrix and right-hand side at the initial state)."""
    acc = np.zeros(len(mass))
    held = list(prescribed)
    for index, value in prescribed.items():
        acc[index] = value
    free = [i for i in range(len(mass)) if i not in held]
    if free:
        acc[free] = np.linalg.solve(mass[np.ix_(free, free)],
                                    rhs[free] - mass[np.ix_(free, held)] @ acc[held])
    return acc, rhs[held] - (mass @ acc)[held]


def stepped_start(mech: Mechanism, q0, qd0, h: float) -> np.ndarray:
    """qd0 (a copy) with each prescribed coordinate's rate that of its first step,
    (q(h) - q0)/h, for an engine that moves a prescribed coordinate with (q(t + h) - q)/h
    in every step: started with q'(0), its first step would miss q(h) by h^2 q''/2."""
    qd0 = np.array(qd0, dtype=float)
    for motion in motions(mech):
        qd0[motion.index] = (motion.position(h) - q0[motion.index]) / h
    return qd0


def coupled(mech: Mechanism) -> Mechanism:
    """The mechanism with each RollingContact replaced by the rolling coupling it stands
    for (what an engine linearizes, or balances forces against)."""
    return replace(mech, constraints=tuple(
        c.coupling if isinstance(c, RollingContact) else c for c in mech.constraints))


def constrained_bodies(mech: Mechanism) -> set[str]:
    """The bodies a closure constraint acts on: the two bodies of a PointOnPoint or
    PointOnLine, the children of the joints whose coordinates a LinearCoupling involves
    (with a non-zero coefficient); the world excluded."""
    out: set[str] = set()
    for c in mech.constraints:
        if isinstance(c, LinearCoupling):
            out |= {mech.joints[mech.coordinates.index(name)].child
                    for name, coef in c.coefficients if num(coef)}
        else:
            out |= set(c.bodies)
    return out - {WORLD}


# --- whether a description can be translated at all ------------------------------------


def description_reason(mech: Mechanism) -> str:
    """Why the description cannot be translated by any backend (a parameter left
    symbolic, a zero axis, slot direction or coupling), or the empty string."""
    placeholders = {LENGTH, LENGTH_RATE, COORD, COORD_RATE, TIME}
    try:
        num(mech.gravity)
        for b in mech.bodies:
            num(b.mass), num(b.inertia)
        for j in mech.joints:
            for v in (*j.parent_anchor, *j.child_anchor, j.angle_offset):
                num(v)
            if isinstance(j, Prismatic):
                for v in j.limits:
                    if v is not None:
                        num(v)
                if math.hypot(num(j.axis[0]), num(j.axis[1])) == 0.0:
                    return f"joint {j.name}: zero prismatic axis"
        for f in mech.forces:
            law = ForceLaw.of(f).expr
            if law.free_symbols - placeholders:
                return (f"force element {f.name}: law has non-numeric parameters "
                        f"{sorted(map(str, law.free_symbols - placeholders))}")
            if isinstance(f, PointToPoint):
                for v in (*f.point_a, *f.point_b):
                    num(v)
        for c in mech.constraints:
            if isinstance(c, (LinearCoupling, RollingContact)):
                num(c.constant)
                if not any(num(v) for _, v in c.coefficients):
                    return f"constraint {c.name}: every coefficient is zero"
                if isinstance(c, RollingContact) and not 0 < num(c.disc_radius) < num(
                        c.track_radius):
                    return f"constraint {c.name}: the disc must be smaller than the track"
            elif isinstance(c, PointOnPoint):
                for v in (*c.point_a, *c.point_b):
                    num(v)
            elif isinstance(c, HingeClosure):
                for v in (*c.point_a, *c.point_b, *c.axis_a, *c.axis_b):
                    num(v)
                if not (any(num(v) for v in c.axis_a) and any(num(v) for v in c.axis_b)):
                    return f"constraint {c.name}: zero hinge axis"
            else:
                for v in (*c.point, *c.line_point):
                    num(v)
                if math.hypot(num(c.direction[0]), num(c.direction[1])) == 0.0:
                    return f"constraint {c.name}: zero slot direction"
        for p in mech.prescribed:
            extra = sp.sympify(p.motion).free_symbols - {TIME}
            if extra:
                return (f"prescribed motion {p.name}: q(t) has non-numeric parameters "
                        f"{sorted(map(str, extra))}")
    except NotNumeric as exc:
        return f"the mechanism is not numeric (use numeric_mechanism): {exc}"
    return ""
