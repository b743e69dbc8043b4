"""The engine-neutral numeric plan of a mechanism, written once for every backend.

A backend receives a numeric `Mechanism` (parameters substituted) and translates it into
its engine. What that translation needs before any engine enters is the same for all of
them and lives here:

- numbers from description entries (`num`), planar rotations (`rot`);
- the element kinds of the description (`ELEMENT_KINDS`, `elements`): the vocabulary in
  which each backend declares how exactly it expresses an element (`base.Expression`);
- the checks that a description can be translated at all (`description_reason`: every
  entry numeric, no zero axis, slot direction or coupling);
- the force laws, compiled once, with their classification (`ForceLaw`): linear (a
  spring of stiffness -b and free length -a/b, a damper of coefficient c, or a constant
  force, ``a + b x + c x'`` with no TIME) or custom; the coordinate laws' generalized
  force, as an engine's force callback evaluates it (`CoordinateLaws`);
- the prescribed motions (`Motion`, `motions`) and the start state they impose
  (`driven_start`);
- the map between the description coordinates q and the engine joint values v
  (`CoordinateMap`): every engine joint is relative (v = theta_child - theta_parent -
  angle_offset for a hinge, the slide along the unit axis for a prismatic joint), so
  ``v = A q + b`` with the inverse ``q = T v + c``, and the body angles are affine in
  both; a coordinate law whose argument is one engine joint value can sit on that joint
  (`CoordinateMap.law_target`);
- the planar kinematics: the bodies' frames from q (`body_states`) and q from the
  frames (`joint_coordinates`), and the force elements' loads on the bodies
  (`element_loads`), on numbers, on arrays of samples, or on symbols, which `traced`
  compiles into the straight-line code of a step;
- for an engine without massless bodies, the massless links eliminated by their shape
  (`Elimination`: folded, arms, free groups) and every body's frame from the bodies with
  mass (`EliminatedFrames`);
- for an engine in maximal coordinates, the description's frames and coordinates from
  its bodies' states and the element loads on those bodies (`MaximalFrames`), the
  joint and link geometry its constraints and drivers are placed by (`slide_path`,
  `joint_pose`, `joint_velocity`, `Fold.slot_line`, `coupled_angles`, `PitchPair`'s
  circles and pitch points, `ring_of_chords`), what a host keeps of its inertia beside
  its substitutes (`compensated_host`) and a drive's first-step rate (`stepped_start`);
- a coupling of hinge coordinates on the absolute body angles (`angle_coupling`) and as
  rolling of pitch circles on a carrier (`pitch_pairs`), and small facts a translation
  asks for (`line_through_origin`, `rotation_fixed`, `effective_mass`);
- for an engine with a tree of relative joints, its link frames (`LinkFrames`: one link
  per joint, its frame at the joint, a slide's joint frame turned to its axis), the
  conditions such a tree needs (`axis_aligned`, `one_joint_value`, `held_below`) and a
  driven run's consistent start (`prescribed_start`);
- for an engine whose bodies carry chains of joints but not massless bodies, the massless
  links folded into them (`joint_chains`); for one that holds a slot by a slider body, the
  sliders' masses taken out of the pin body (`slider_masses`); for one without an exact
  imposed motion, the prescribed motions imposed by generalized forces (`ImposedMotions`,
  at the stage time `stage_time`); for a linearization with the closures held exactly,
  the closure forces' geometric stiffness and the modes on the constraint's null space
  (`geometric_stiffness`, `constrained_modes`);
- what every translation starts from (`EnginePlan`), more conditions of an expression
  that follow from the description alone (`carries_child`, `held_by_closure`,
  `couples_two_engine_values`), and the elements between two bodies read from their
  frame states (`PairLoad`, `SlotGeometry`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property, singledispatch
from operator import itemgetter
from typing import Callable, Iterator, Mapping, Sequence

import numpy as np
import sympy as sp

from ..analytic.modes import quadratic_eigenvalues
from ..systems.model import (
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
    inertia_matrix,
)


class NotNumeric(TypeError, ValueError):
    """A description entry still holds a parameter symbol."""


def num(x) -> float:
    """A float from a numeric description entry (number or SymPy expression)."""
    value = sp.sympify(x)
    if value.free_symbols:
        raise NotNumeric(f"expression {value} still has free symbols")
    return float(value)


def vec3(vector) -> list[float]:
    """A description vector, planar or spatial, as three numbers (planar: z = 0)."""
    return [num(v) for v in vector] + [0.0] * (3 - len(vector))


def rot(theta: float) -> np.ndarray:
    """The planar rotation matrix R(theta) (body frame to world axes)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def turned(theta: np.ndarray, x, y) -> np.ndarray:
    """The vectors (x, y) turned by the angles theta, one row per sample (N, 2)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * x - s * y, s * x + c * y], axis=1)


def ring_of_boxes(centre, R: float, count: int
                  ) -> tuple[list[tuple[float, float, float]], float, float]:
    """The track of a rolling contact as `count` boxes whose inner faces are tangent to the
    circle of radius R about `centre` (a regular polygon with the circle as its incircle):
    each box's centre (x, y) and angle, the boxes' radial thickness (0.1 R) and the half
    length R tan(pi / count) at which neighbouring faces meet."""
    thick = 0.1 * R
    rho = R + thick / 2.0
    boxes = [(centre[0] + rho * math.cos(a), centre[1] + rho * math.sin(a), a)
             for a in (2.0 * math.pi * i / count for i in range(count))]
    return boxes, thick, R * math.tan(math.pi / count)


def ring_of_chords(centre, R: float, count: int) -> tuple[list[tuple[float, float]], float]:
    """The circle of radius R about `centre` as the `count` vertices of its inscribed
    regular polygon, and the polygon's sagitta R (1 - cos(pi / count)), the largest gap
    between a chord and the circle."""
    points = [(centre[0] + R * math.cos(2 * math.pi * i / count),
               centre[1] + R * math.sin(2 * math.pi * i / count)) for i in range(count)]
    return points, R * (1 - math.cos(math.pi / count))


def gravity_vector(mech: Mechanism) -> tuple[float, float, float]:
    """The acceleration of gravity in world axes: along -y, or in a spatial mechanism
    (model convention 10) against its `up`."""
    g = num(mech.gravity)
    if not mech.spatial:
        return 0.0, -g, 0.0
    up = np.array([num(u) for u in mech.up] + [0.0] * (3 - len(mech.up)), dtype=float)
    return tuple(float(v) for v in -g * up / np.linalg.norm(up))


def central_tensor(mech: Mechanism, body: Body) -> np.ndarray:
    """A body's 3 x 3 central inertia tensor in its frame (numbers): a spatial body's
    full tensor as given (model convention 10), a planar body's inertia about z."""
    if mech.spatial:
        return np.array(inertia_matrix(body).tolist(), dtype=float)
    return np.diag([0.0, 0.0, num(body.inertia)])


def linear_law(expr, x: sp.Symbol, xd: sp.Symbol) -> tuple[float, float, float] | None:
    """(a, b, c) with law = a + b x + c xd (numbers, no TIME), or None when the law is not
    of that form."""
    expr = sp.sympify(expr)
    if not expr.free_symbols <= {x, xd} or not expr.is_polynomial(x, xd):
        return None
    if expr.free_symbols and sp.Poly(expr, x, xd).total_degree() > 1:
        return None
    a = float(expr.xreplace({x: 0, xd: 0}))
    return a, float(sp.diff(expr, x)), float(sp.diff(expr, xd))


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


@element_kind.register
def _(element: Revolute) -> str:
    return REVOLUTE


@element_kind.register
def _(element: Prismatic) -> str:
    return PRISMATIC


@element_kind.register
def _(element: PointToPoint) -> str:
    return ForceLaw.of(element).kind


@element_kind.register
def _(element: CoordinateForce) -> str:
    return ForceLaw.of(element).kind


@element_kind.register
def _(element: PointOnPoint) -> str:
    return POINT_ON_POINT


@element_kind.register
def _(element: PointOnLine) -> str:
    return POINT_ON_LINE


@element_kind.register
def _(element: LinearCoupling) -> str:
    return LINEAR_COUPLING


@element_kind.register
def _(element: RollingContact) -> str:
    return ROLLING_CONTACT


@element_kind.register
def _(element: Prescribed) -> str:
    return PRESCRIBED


@element_kind.register
def _(element: HingeClosure) -> str:
    return HINGE_CLOSURE


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


# --- description coordinates and engine joint values -----------------------------------


@dataclass(frozen=True)
class CoordinateMap:
    """Description coordinates q and engine joint values v of a numeric mechanism:
    ``v = A q + b`` and ``q = T v + c`` (T = A^-1; A is lower triangular with +-1 or the
    axis length on the diagonal: absolute angles subtract the parent's angle, clockwise
    coordinates change sign, slides run along the unit axis). Body angles are affine in
    both: ``theta = angle_c[body] . q + angle_d[body] = angle_v[body] . v +
    angle_v0[body]``. Generalized forces map with the transposes (tau = T^T Q)."""

    A: np.ndarray
    b: np.ndarray
    c: np.ndarray
    angle_c: dict[str, np.ndarray]
    angle_d: dict[str, float]
    angle_v: dict[str, np.ndarray]
    angle_v0: dict[str, float]

    @cached_property
    def T(self) -> np.ndarray:
        return np.linalg.inv(self.A)

    @cached_property
    def identity(self) -> bool:
        """Whether the engine joint values are the description coordinates."""
        n = len(self.b)
        return bool(np.array_equal(self.A, np.eye(n)) and not self.b.any())

    def engine_values(self, q: np.ndarray) -> np.ndarray:
        return self.A @ np.asarray(q, dtype=float) + self.b

    def coordinates(self, v: np.ndarray) -> np.ndarray:
        """Engine joint values (one row per sample, or one vector) -> coordinates."""
        return (np.asarray(v) - self.b) @ self.T.T

    def rates(self, vd: np.ndarray) -> np.ndarray:
        return np.asarray(vd) @ self.T.T

    def angle(self, body: str, q: np.ndarray) -> np.ndarray:
        """The body's angle at q (rows of q give one angle per row)."""
        return q @ self.angle_c[body] + self.angle_d[body]

    def law_row(self, weights: dict[int, int]) -> np.ndarray:
        """The row r with COORD = sum sign q_i = r . (v - b) (`weights`, as in
        `CoordinateForce.weights`), so that the law's force acts with r F on the engine
        joint values; weights below 1e-12 are round-off of T and set to zero."""
        row = sum(sign * self.T[i] for i, sign in weights.items())
        return np.where(np.abs(row) < 1e-12, 0.0, row)

    def law_target(self, weights: dict[int, int]) -> tuple[int, float] | None:
        """(j, r) when a coordinate law's argument COORD = sum sign q_i (`weights`, as in
        `CoordinateForce.weights`) is r v_j, one engine joint value without offset (an
        engine can then hold the law on its joint j: force r F(r v_j, r v_j') on v_j);
        None otherwise. Weights below 1e-12 are round-off of T and set to zero."""
        row = sum(sign * self.T[i] for i, sign in weights.items())
        row = np.where(np.abs(row) < 1e-12, 0.0, row)
        shift = sum(sign * self.c[i] for i, sign in weights.items())
        target = np.flatnonzero(row)
        if len(target) != 1 or shift != 0:
            return None
        return int(target[0]), float(row[target[0]])

    def joint_spring(self, weights: dict[int, int], linear: tuple[float, float, float] | None
                     ) -> tuple[int, float, float, float] | None:
        """(j, force, stiffness, damping) where a linear coordinate law F = a + b COORD +
        c COORD' (`linear`; None: not linear) acts on one engine joint value, COORD = r v_j
        (`law_target`): tau_j = r F(r v_j, r v_j') = force - stiffness v_j - damping v_j'
        with force = r a, stiffness = -r^2 b, damping = -r^2 c; None otherwise."""
        target = self.law_target(weights)
        if linear is None or target is None:
            return None
        (j, r), (a, b, c) = target, linear
        return j, r * a, -r * r * b, -r * r * c

    def on_engine_values(self, coefficients: np.ndarray, constant: float
                         ) -> tuple[np.ndarray, float]:
        """A linear relation sum a_k q_k = C on the coordinates written on the engine
        joint values: (a T, C - a c), since q = T v + c; weights below 1e-12 of the
        largest are round-off of T and set to zero."""
        row = np.asarray(coefficients, dtype=float) @ self.T
        row = np.where(np.abs(row) <= 1e-12 * np.max(np.abs(row), initial=0.0), 0.0, row)
        return row, float(constant - np.asarray(coefficients, dtype=float) @ self.c)


def coordinate_map(mech: Mechanism) -> CoordinateMap:
    """The `CoordinateMap` of a numeric mechanism."""
    n = len(mech.joints)
    angle_c: dict[str, np.ndarray] = {WORLD: np.zeros(n)}
    angle_d: dict[str, float] = {WORLD: 0.0}
    angle_v: dict[str, np.ndarray] = {WORLD: np.zeros(n)}
    angle_v0: dict[str, float] = {WORLD: 0.0}
    A = np.zeros((n, n))
    b = np.zeros(n)
    c = np.zeros(n)
    for i, j in enumerate(mech.joints):
        cp, dp = angle_c[j.parent], angle_d[j.parent]
        off = num(j.angle_offset)
        e_i = np.eye(n)[i]
        if isinstance(j, Revolute):
            sign = -1.0 if j.clockwise else 1.0
            angle_v[j.child] = angle_v[j.parent] + e_i
            if j.absolute:
                angle_c[j.child] = sign * e_i
                angle_d[j.child] = off
                A[i] = sign * e_i - cp  # v = theta_child - theta_parent - offset
                b[i] = -dp
                c[i] = sign * angle_v0[j.parent]  # sign q = theta_parent + v
            else:
                angle_c[j.child] = cp + sign * e_i
                angle_d[j.child] = dp + off
                A[i, i] = sign
        else:
            angle_v[j.child] = angle_v[j.parent].copy()
            angle_c[j.child] = cp.copy()
            angle_d[j.child] = dp + off
            A[i, i] = math.hypot(num(j.axis[0]), num(j.axis[1]))  # the slide along the unit axis
        angle_v0[j.child] = angle_v0[j.parent] + off
    return CoordinateMap(A, b, c, angle_c, angle_d, angle_v, angle_v0)


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


# --- the loads of the force elements on the bodies --------------------------------------

#: a load on a body: (body, force (fx, fy) or None, its world point or None, torque)
Load = tuple


def wrench(load: Load, centre) -> tuple:
    """(fx, fy, moment about `centre`) of a load."""
    _, force, point, torque = load
    if force is None:
        return 0.0, 0.0, torque
    return (force[0], force[1],
            (point[0] - centre[0]) * force[1] - (point[1] - centre[1]) * force[0] + torque)


def joint_pose(joint: Revolute | Prismatic) -> Callable[[float], object]:
    """Where a joint's coordinate q puts its child, relative to the parent (the world for
    an absolute angle), as a function of q: a slide's point parent_anchor + q axis of the
    parent, on which the child's anchor sits; a hinge's angle s q + angle_offset of the
    child (s = -1 for a clockwise coordinate)."""
    if isinstance(joint, Revolute):
        s, offset = -1.0 if joint.clockwise else 1.0, num(joint.angle_offset)
        return lambda q: s * q + offset
    pa, axis = np.array(plane_point(joint.parent_anchor)), np.array(plane_point(joint.axis))
    return lambda q: tuple(pa + q * axis)


def slide_path(joint: Prismatic) -> tuple[np.ndarray, np.ndarray]:
    """The line base + q axis (parent frame) on which a prismatic joint's child's frame
    origin travels: parent_anchor - R(angle_offset) child_anchor + q axis."""
    return (np.array(plane_point(joint.parent_anchor))
            - rot(num(joint.angle_offset)) @ np.array(plane_point(joint.child_anchor)),
            np.array(plane_point(joint.axis)))


def joint_velocity(joint: Revolute | Prismatic, rate) -> tuple:
    """The velocity (vx, vy) of a joint's child at its anchor and its angular velocity,
    relative to the parent and in the parent's axes, when the coordinate moves at `rate`
    (a hinge turns the child about the anchor; a slide moves it along the axis)."""
    if isinstance(joint, Revolute):
        return 0.0, 0.0, -rate if joint.clockwise else rate
    axis = np.array(plane_point(joint.axis))
    return rate * axis[0], rate * axis[1], 0.0


def coordinate_load(joint: Revolute | Prismatic) -> Callable[[Mapping, object], list[Load]]:
    """The loads of a generalized force Q on a joint's coordinate (virtual power of
    Q q'), as a function of (the bodies' frame states, Q): torques s Q on a hinge's child
    and -s Q on its parent (none for an absolute angle; s = -1 for a clockwise
    coordinate); a slide's force Q R a / |a|^2 on the child at its anchor, opposite on
    the parent."""
    if isinstance(joint, Revolute):
        s = -1.0 if joint.clockwise else 1.0
        if joint.absolute:
            return lambda states, value: [(joint.child, None, None, s * value)]
        return lambda states, value: [(joint.child, None, None, s * value),
                                      (joint.parent, None, None, -s * value)]
    a = (num(joint.axis[0]), num(joint.axis[1]))
    anchor = (num(joint.child_anchor[0]), num(joint.child_anchor[1]))
    norm2 = a[0] * a[0] + a[1] * a[1]

    def loads(states: Mapping, value) -> list[Load]:
        c, s = cos_sin(states[joint.parent][2])
        force = (value * (c * a[0] - s * a[1]) / norm2, value * (s * a[0] + c * a[1]) / norm2)
        w = point_state(states[joint.child], anchor)[:2]
        return [(joint.child, force, w, 0.0), (joint.parent, (-force[0], -force[1]), w, 0.0)]

    return loads


def element_loads(mech: Mechanism, element: PointToPoint | CoordinateForce
                  ) -> Callable[[Mapping, object], list[Load]]:
    """A force element's loads on the bodies as a function of (the bodies' frame states,
    t): a PointToPoint's tension along the line of its points (on body b, opposite on
    body a); a CoordinateForce's generalized force by `coordinate_load` (a couple, +F on
    one coordinate and -F on the other, with relative_to)."""
    law = ForceLaw.of(element)
    if isinstance(element, PointToPoint):
        f = element
        pa = (num(f.point_a[0]), num(f.point_a[1]))
        pb = (num(f.point_b[0]), num(f.point_b[1]))

        def point_to_point(states: Mapping, t) -> list[Load]:
            a, b = point_state(states[f.body_a], pa), point_state(states[f.body_b], pb)
            dx, dy = b[0] - a[0], b[1] - a[1]
            length = sqrt(dx * dx + dy * dy)
            rate = (dx * (b[2] - a[2]) + dy * (b[3] - a[3])) / length
            tension = law_value(law, length, rate, t)
            ux, uy = dx / length, dy / length
            return [(f.body_b, (-tension * ux, -tension * uy), b[:2], 0.0),
                    (f.body_a, (tension * ux, tension * uy), a[:2], 0.0)]

        return point_to_point
    terms = [(sign, mech.joints[i], coordinate_reader(mech.joints[i]),
              coordinate_load(mech.joints[i]))
             for i, sign in element.weights(mech.coordinates).items()]

    def coordinate_force(states: Mapping, t) -> list[Load]:
        x = xd = 0.0
        for sign, j, read, _ in terms:
            q, qd = read(states[j.parent], states[j.child])
            x, xd = x + sign * q, xd + sign * qd
        value = law_value(law, x, xd, t)
        return [load for sign, _, _, apply in terms for load in apply(states, sign * value)]

    return coordinate_force


def coupling_row(mech: Mechanism, coupling: LinearCoupling | RollingContact
                 ) -> tuple[np.ndarray, float]:
    """A coupling sum a_k q_k = C as its row a over the description coordinates and its
    constant C (a RollingContact: the rolling coupling it stands for)."""
    row = np.zeros(len(mech.coordinates))
    for name, coefficient in coupling.coefficients:
        row[mech.coordinates.index(name)] += num(coefficient)
    return row, num(coupling.constant)


def force_bodies(mech: Mechanism, element: PointToPoint | CoordinateForce) -> tuple[str, ...]:
    """The bodies a force element joins (the world included): a PointToPoint's body_a and
    body_b; a CoordinateForce's, the parent and the child of each joint whose coordinate
    it weighs."""
    if isinstance(element, PointToPoint):
        return element.body_a, element.body_b
    return tuple(b for i in element.weights(mech.coordinates)
                 for b in (mech.joints[i].parent, mech.joints[i].child))


# --- massless links eliminated: their frames follow from the bodies with mass -----------


class NotEliminable(ValueError):
    """Massless bodies whose frames do not follow from the bodies around them (why)."""


def _closure_bodies(c) -> tuple[str, ...]:
    """The two bodies of a PointOnPoint or PointOnLine; () for other closures."""
    return c.bodies if isinstance(c, (PointOnPoint, PointOnLine)) else ()


@dataclass(frozen=True)
class Fold:
    """A massless link with one revolute and one prismatic joint (a guide arm carrying a
    slider, or a slider carrying a pin): it turns with `partner`, the body on the far side
    of its prismatic joint, about its revolute point, a point of `pin_body` (the near
    side); the pair of joints is one pin-in-slot between them."""

    link: str
    revolute: Revolute
    prismatic: Prismatic

    @property
    def turns_with_child(self) -> bool:
        """Whether the revolute joint is the link's inner one (the link turns with the
        prismatic joint's child, the pin is a point of the revolute joint's parent)."""
        return self.revolute.child == self.link

    @property
    def partner(self) -> str:
        return self.prismatic.child if self.turns_with_child else self.prismatic.parent

    @property
    def pin_body(self) -> str:
        return self.revolute.parent if self.turns_with_child else self.revolute.child

    @property
    def offset(self) -> float:
        """The link's angle minus its partner's."""
        offset = num(self.prismatic.angle_offset)
        return -offset if self.turns_with_child else offset

    @property
    def pin_point(self) -> tuple[float, float]:
        """The revolute point in the pin body's frame."""
        j = self.revolute
        return plane_point(j.parent_anchor if self.turns_with_child else j.child_anchor)

    @property
    def link_point(self) -> tuple[float, float]:
        """The revolute point in the link's frame."""
        j = self.revolute
        return plane_point(j.child_anchor if self.turns_with_child else j.parent_anchor)

    @property
    def slot_line(self) -> tuple[np.ndarray, np.ndarray]:
        """The line (base, direction) in the partner's frame on which the pin point
        (`pin_point`) runs, at base + q direction for the slide's coordinate q: the pair
        of joints as one pin-in-slot."""
        rev, pri = self.revolute, self.prismatic
        if self.turns_with_child:
            # the link turns with its child: the pivot (a point of the parent) slides on a
            # line of the child
            back = rot(-num(pri.angle_offset))
            base = np.array(plane_point(pri.child_anchor)) - back @ (
                np.array(plane_point(pri.parent_anchor)) - np.array(plane_point(rev.child_anchor)))
            return base, -back @ np.array(plane_point(pri.axis))
        # the link turns with its parent: the pin (a point of the child) slides on a line
        # of the parent
        base = np.array(plane_point(pri.parent_anchor)) + rot(num(pri.angle_offset)) @ (
            np.array(plane_point(rev.parent_anchor)) - np.array(plane_point(pri.child_anchor)))
        return base, np.array(plane_point(pri.axis))


@dataclass(frozen=True)
class Arm:
    """A massless link with revolute joints only, at two distinct points alpha, beta of
    the link (a fixed distance between the bodies at its two ends). `at_alpha`/`at_beta`:
    (body, point of that body) hinged there; the first is the representative (the world
    if it is one of them)."""

    link: str
    alpha: tuple[float, float]
    beta: tuple[float, float]
    at_alpha: tuple[tuple[str, tuple[float, float]], ...]
    at_beta: tuple[tuple[str, tuple[float, float]], ...]


@dataclass(frozen=True)
class FreeGroup:
    """Massless bodies that impose no constraint on the bodies with mass around them:
    their angles follow prismatic joints, their positions solve the (linear) joint
    equations."""

    bodies: tuple[str, ...]
    joints: tuple  # description joints with an end in `bodies`
    closures: tuple  # PointOnPoint / PointOnLine with an end in `bodies`
    #: (body, known body, offset): theta = theta_known + offset
    angles: tuple[tuple[str, str, float], ...]


def _arm(mech: Mechanism, name: str, massless: set[str]) -> Arm:
    joints = [j for j in mech.joints if name in (j.parent, j.child)]
    groups: list[tuple[np.ndarray, list[tuple[str, tuple[float, float]]]]] = []
    for j in joints:
        if j.parent == name:
            own, other, at = j.parent_anchor, j.child, j.child_anchor
        else:
            own, other, at = j.child_anchor, j.parent, j.parent_anchor
        own, at = np.array(plane_point(own)), np.array(plane_point(at))
        if other in massless:
            raise NotEliminable(f"massless body {name} is hinged to another massless body "
                                f"{other}")
        for point, members in groups:
            if np.allclose(point, own, rtol=0, atol=1e-12):
                members.append((other, tuple(at)))
                break
        else:
            groups.append((own, [(other, tuple(at))]))
    if len(groups) != 2:
        raise NotEliminable(f"massless body {name} has revolute joints at {len(groups)} "
                            "distinct points; only a link with two (an arm) can be eliminated")
    for _, members in groups:  # the world first: its point is exact
        members.sort(key=lambda m: m[0] != WORLD)
    seen = [m[0] for _, ms in groups for m in ms]
    if len(set(seen)) != len(seen):
        raise NotEliminable(f"massless body {name} is hinged twice to the same body")
    (pa, ma), (pb, mb) = groups
    return Arm(name, tuple(pa), tuple(pb), tuple(ma), tuple(mb))


def _free_group(mech: Mechanism, group: set[str], real: set[str],
                closures: list) -> FreeGroup:
    joints = tuple(j for j in mech.joints if j.parent in group or j.child in group)
    mine = tuple(c for c in closures if set(_closure_bodies(c)) & group)
    ends = ({b for j in joints for b in (j.parent, j.child)}
            | {b for c in mine for b in _closure_bodies(c)}) - group
    bad = [b for b in ends if b != WORLD and b not in real]
    if bad:
        raise NotEliminable(f"massless bodies {sorted(group)} are attached to other massless "
                            f"bodies {bad}")
    known = set(ends) | {WORLD}
    angles: list[tuple[str, str, float]] = []
    changed = True
    while changed:
        changed = False
        for j in joints:
            if not isinstance(j, Prismatic):
                continue
            off = num(j.angle_offset)
            if j.parent in known and j.child not in known:
                angles.append((j.child, j.parent, off))
                known.add(j.child)
                changed = True
            elif j.child in known and j.parent not in known:
                angles.append((j.parent, j.child, -off))
                known.add(j.parent)
                changed = True
    loose = sorted(group - known)
    if loose:
        raise NotEliminable(f"massless bodies {loose}: rotation not fixed by prismatic "
                            "joints, and not a foldable link or arm")
    unknowns = (2 * len(group) + sum(isinstance(j, Prismatic) for j in joints)
                + sum(isinstance(c, PointOnLine) for c in mine))
    equations = 2 * (len(joints) + len(mine))
    if unknowns != equations:
        raise NotEliminable(f"massless bodies {sorted(group)}: their joints and constraints "
                            f"impose {equations - unknowns:+d} conditions on the bodies "
                            "around them; only massless groups that leave them free (or fold "
                            "into one joint) can be eliminated")
    return FreeGroup(tuple(sorted(group)), joints, mine, tuple(angles))


def _group_equations(group: FreeGroup) -> tuple:
    """A free massless group's joint equations, read once: (column of each body's x,
    the number of unknowns, the angles (body, known body, offset), per equation pair the
    points (sign, body, local) whose sum vanishes and the travel (column, body,
    direction, sign) of a slide or a slot along a direction of a body, if any)."""
    column = {body: 2 * i for i, body in enumerate(group.bodies)}
    extra, equations = 2 * len(group.bodies), []
    for j in group.joints:
        slide = None
        if isinstance(j, Prismatic):
            slide, extra = (extra, j.parent, plane_point(j.axis), 1.0), extra + 1
        equations.append((((1.0, j.parent, plane_point(j.parent_anchor)),
                           (-1.0, j.child, plane_point(j.child_anchor))), slide))
    for c in group.closures:
        if isinstance(c, PointOnPoint):
            equations.append((((1.0, c.body_a, plane_point(c.point_a)),
                               (-1.0, c.body_b, plane_point(c.point_b))), None))
        else:
            equations.append((((1.0, c.body, plane_point(c.point)),
                               (-1.0, c.line_body, plane_point(c.line_point))),
                              (extra, c.line_body, plane_point(c.direction), -1.0)))
            extra += 1
    return column, extra, group.angles, tuple(equations)


class Elimination:
    """The massless bodies of a planar description eliminated, each by its shape: a link
    with one revolute and one prismatic joint is folded (`Fold`), a link with revolute
    joints at two points is an arm (`Arm`), and massless bodies whose angles are fixed by
    prismatic joints and whose joints and closures leave the bodies around them free
    (three relative degrees of freedom, e.g. two crossed carriages, or a pin running in
    two slots) form a free group (`FreeGroup`); other shapes raise `NotEliminable`.
    `joints`: the ids of the joints that an elimination stands for; `closures`: the ids of
    the closures that a free group consumes (its positions solve them); `kind`: per
    eliminated body, how its frame follows (`EliminatedFrames`); `follows`: the bodies
    with mass it follows."""

    def __init__(self, mech: Mechanism) -> None:
        massless = {b.name for b in mech.bodies if b.massless}
        geometric = [c for c in mech.constraints if _closure_bodies(c)]
        touched = {b for c in geometric for b in _closure_bodies(c)}
        self.folds: dict[str, Fold] = {}
        self.arms: dict[str, Arm] = {}
        self.groups: list[FreeGroup] = []
        self.joints: set[int] = set()
        rest = []
        for name in (b.name for b in mech.bodies if b.name in massless):
            inner = mech.joint_of_child(name)
            children = [j for j in mech.joints if j.parent == name]
            if name in touched:
                rest.append(name)
            elif (len(children) == 1
                    and {type(inner), type(children[0])} == {Revolute, Prismatic}
                    and inner.parent not in massless and children[0].child not in massless):
                outer = children[0]
                revolute, prismatic = ((inner, outer) if isinstance(inner, Revolute)
                                       else (outer, inner))
                self.folds[name] = Fold(name, revolute, prismatic)
                self.joints |= {id(inner), id(outer)}
            elif all(isinstance(j, Revolute) for j in [inner, *children]):
                self.arms[name] = _arm(mech, name, massless)
                self.joints |= {id(inner), *map(id, children)}
            else:
                rest.append(name)
        real = {b.name for b in mech.bodies} - massless
        remaining = set(rest)
        while remaining:
            group = {remaining.pop()}
            grown = True
            while grown:
                grown = False
                pairs = [(j.parent, j.child) for j in mech.joints] + [
                    _closure_bodies(c) for c in geometric]
                for a, b in pairs:
                    for x, y in ((a, b), (b, a)):
                        if x in group and y in remaining:
                            group.add(y)
                            remaining.discard(y)
                            grown = True
            self.groups.append(_free_group(mech, group, real, geometric))
        self.joints |= {id(j) for g in self.groups for j in g.joints}
        self.closures = {id(c) for g in self.groups for c in g.closures}
        self.kind: dict[str, tuple] = {}
        self.follows: dict[str, tuple[str, ...]] = {}
        for name, fold in self.folds.items():
            self.kind[name] = ("fold", fold.partner, fold.offset, fold.pin_body, fold.pin_point,
                               fold.link_point)
            self.follows[name] = (fold.partner, fold.pin_body)
        for name, arm in self.arms.items():
            (ra, pa), (rb, pb) = arm.at_alpha[0], arm.at_beta[0]
            ell = (arm.beta[0] - arm.alpha[0], arm.beta[1] - arm.alpha[1])
            self.kind[name] = ("link", ra, pa, rb, pb, ell, arm.alpha)
            self.follows[name] = (ra, rb)
        self.equations = [_group_equations(g) for g in self.groups]
        for i, (column, _, _, equations) in enumerate(self.equations):
            for name in column:
                self.kind[name] = ("group", i)
                self.follows[name] = tuple({p[1] for points, _ in equations
                                            for p in points} - column.keys())


def moving_point(state: tuple, local) -> tuple:
    """World position and velocity (x, y, vx, vy) of a body point from the body's
    `EliminatedFrames.state`."""
    x, y, _, c, s, vx, vy, w = state
    rx, ry = c * local[0] - s * local[1], s * local[0] + c * local[1]
    return x + rx, y + ry, vx - w * ry, vy + w * rx


def hung_frame(pin: tuple, th, w, local) -> tuple:
    """The `EliminatedFrames.state` of a body at angle th turning at w, whose point
    `local` is at the moving point `pin` (x, y, vx, vy)."""
    c, s = cos_sin(th)
    rx, ry = c * local[0] - s * local[1], s * local[0] + c * local[1]
    return pin[0] - rx, pin[1] - ry, th, c, s, pin[2] + w * ry, pin[3] - w * rx, w


class EliminatedFrames:
    """The frame state of each description body, computed when asked, from those of the
    bodies with mass (`massive`: body -> state): `state` gives (x, y, theta, cos theta,
    sin theta, vx, vy, omega), `frames[body]` the frame state (x, y, theta, vx, vy,
    omega). A folded link turns with its partner about its pin; an arm points from its
    end at alpha to its end at beta; a free massless group solves its joint equations,
    linear once its angles are known, and their time derivative for the rates. Numbers,
    arrays of samples or symbols (`traced`)."""

    def __init__(self, elimination: Elimination, massive: Callable[[str], tuple]):
        self.elimination, self.massive = elimination, massive
        self.cache: dict[str, tuple] = {WORLD: (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0)}

    def __getitem__(self, body: str) -> tuple:
        state = self.state(body)
        return state[:3] + state[5:]

    def state(self, body: str) -> tuple:
        if body in self.cache:
            return self.cache[body]
        kind = self.elimination.kind.get(body)
        if kind is None:
            state = self.massive(body)
        elif kind[0] == "fold":  # turns with `turner`, its point `local` on the pin
            _, turner, off, pin, pin_local, local = kind
            turning = self.state(turner)
            state = hung_frame(moving_point(self.state(pin), pin_local), turning[2] + off,
                          turning[7], local)
        elif kind[0] == "link":  # its alpha on the point a, its beta towards b
            _, ra, pa, rb, pb, ell, alpha = kind
            a, b = moving_point(self.state(ra), pa), moving_point(self.state(rb), pb)
            wx, wy = b[0] - a[0], b[1] - a[1]
            th = atan2(ell[0] * wy - ell[1] * wx, ell[0] * wx + ell[1] * wy)
            w = (wx * (b[3] - a[3]) - wy * (b[2] - a[2])) / (wx * wx + wy * wy)
            state = hung_frame(a, th, w, alpha)
        else:
            self._group(kind[1])
            return self.cache[body]
        self.cache[body] = state
        return state

    def _group(self, i: int) -> None:
        """A free group's positions (and its slides' and slots' travels) from its joint
        equations, then its rates from the same equations differentiated in time."""
        column, m, angles, equations = self.elimination.equations[i]
        turn: dict[str, tuple] = {}  # body -> (theta, omega)
        for body, known, off in angles:
            th, w = turn[known] if known in turn else itemgetter(2, 7)(self.state(known))
            turn[body] = (th + off, w)
        A = [[0.0] * m for _ in range(m)]
        known_p, known_v, slides = [], [], []
        for r, (points, slide) in enumerate(equations):
            gap = (0.0, 0.0, 0.0, 0.0)  # the known points' position and velocity
            for sign, body, local in points:
                if body in column:
                    A[2 * r][column[body]] += sign
                    A[2 * r + 1][column[body] + 1] += sign
                    th, w = turn[body]
                    c, s = cos_sin(th)
                    p = moving_point((0.0, 0.0, th, c, s, 0.0, 0.0, w), local)
                else:
                    p = moving_point(self.state(body), local)
                gap = tuple(g + sign * v for g, v in zip(gap, p))
            if slide is not None:  # the travel u along sign R d
                k, body, d, sign = slide
                th, w = turn[body] if body in turn else itemgetter(2, 7)(self.state(body))
                c, s = cos_sin(th)
                A[2 * r][k] = sign * (c * d[0] - s * d[1])
                A[2 * r + 1][k] = sign * (s * d[0] + c * d[1])
                slides.append((r, k, w))
            known_p += gap[:2]
            known_v += gap[2:]
        solve = linear_solver(A)
        x = solve([-v for v in known_p])
        for r, k, w in slides:  # d/dt (u sign R d) = u' sign R d + u omega perp(sign R d)
            known_v[2 * r] -= w * A[2 * r + 1][k] * x[k]
            known_v[2 * r + 1] += w * A[2 * r][k] * x[k]
        v = solve([-g for g in known_v])
        for body, c in column.items():
            th, w = turn[body]
            self.cache[body] = (x[c], x[c + 1], th, *cos_sin(th), v[c], v[c + 1], w)


def sample_columns(values: Sequence, n: int) -> np.ndarray:
    """(n, len(values)): each value, a number or n samples, as a column."""
    return np.column_stack([np.broadcast_to(np.asarray(v, float), (n,)) for v in values])


# --- an engine in maximal coordinates: its bodies' states and the description's frames ---

_ZERO = (0.0, 0.0, 0.0)
_UNITS = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def split_state_row(row: Sequence, H=0.0) -> tuple[list, list]:
    """Per engine body, (x, y, theta) moved by H times the rates, and the rates, from a
    state row (numbers, symbols or columns of samples; 6 entries per engine body)."""
    P = [tuple(row[k + i] + H * row[k + 3 + i] for i in range(3)) for k in range(0, len(row), 6)]
    V = [tuple(row[k + 3 + i] for i in range(3)) for k in range(0, len(row), 6)]
    return P, V


class MaximalFrames:
    """How every description body's frame follows from the states of an engine in maximal
    coordinates, read once. The engine's bodies (`engine`, in the order of its state rows:
    per body its centre of gravity x, y, its angle and their rates) are the description's
    bodies with mass, whose frames are placed from their centre of gravity (at the point
    `cogs` of the body's frame where it is off the frame's origin), and substitutes of the
    engine's own; an eliminated massless link follows them (`EliminatedFrames` of
    `elimination`). `elements`: per force element, its loads as a function of the frames
    and t (`element_loads`), which reach the engine bodies `loaded`."""

    def __init__(self, mech: Mechanism, elimination: Elimination, engine: Sequence[str],
                 cogs: Mapping[str, Sequence[float] | None], elements: Sequence[Callable]):
        self.mech, self.elimination = mech, elimination
        self.index = {name: k for k, name in enumerate(engine)}
        self.n = len(engine)
        self.cogs = {name: tuple(map(float, cog)) for name, cog in cogs.items() if cog}
        #: per eliminated body, the engine bodies it follows
        self.follows = {name: tuple(sorted(self.index[b] for b in set(bodies)
                                           if b in self.index))
                        for name, bodies in elimination.follows.items()}
        self.elements = list(elements)
        loaded: set[int] = set()
        for f in mech.forces:
            for body in set(force_bodies(mech, f)) - {WORLD}:
                loaded |= set(self.follows[body]) if body in self.follows else {self.index[body]}
        self.loaded = sorted(loaded)  # engine bodies that receive element loads
        self.phis: dict[str, Callable] = {}  # compiled `coupling_phi`s

    def at(self, P: Sequence, V: Sequence) -> EliminatedFrames:
        """The frames from the engine bodies' positions P and rates V (x, y, theta of the
        centre of gravity and their rates, per engine body)."""
        def massive(body: str) -> tuple:
            k, cog = self.index[body], self.cogs.get(body)
            (x, y, th), (vx, vy, w) = P[k], V[k]
            if cog:  # the frame whose point cog is the centre of gravity
                return hung_frame((x, y, vx, vy), th, w, cog)
            return (x, y, th, *cos_sin(th), vx, vy, w)

        return EliminatedFrames(self.elimination, massive)

    def frames(self, S: np.ndarray, H: float = 0.0) -> EliminatedFrames:
        """The frames over state rows S (one sample per row) at x + H v."""
        return self.at(*split_state_row(np.asarray(S, dtype=float).T, H))

    def coordinates(self, S: np.ndarray, q0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Engine body states (rows of `S`) -> the description's coordinates and rates;
        the angles of eliminated links, which come from atan2, continued from q0."""
        q, qd = (sample_columns(cols, len(S))
                 for cols in joint_coordinates(self.mech, self.frames(S)))
        return continued_angles(self.mech, q, q0), qd

    def body_loads(self, frames: EliminatedFrames, t) -> list[Load]:
        """The element loads on the description bodies."""
        return [load for element in self.elements for load in element(frames, t)]

    def coupling_phi(self, name: str) -> Callable[..., float]:
        """The residual Phi = sum k q - const of the coupling `name`, as a compiled
        function of the engine bodies' positions (x, y, theta each)."""
        if name in self.phis:
            return self.phis[name]
        residual = coupling_residual(self.mech, next(c for c in self.mech.constraints
                                                     if c.name == name))

        def phi(*pos: float) -> list:
            return [residual(self.at([pos[k:k + 3] for k in range(0, len(pos), 3)],
                                     [_ZERO] * self.n))]

        compiled = traced(phi, 3 * self.n)
        self.phis[name] = lambda *pos: compiled(*pos)[0]
        return self.phis[name]

    @cached_property
    def loads_math(self) -> Callable | None:
        """`engine_loads` compiled: (*state row, H, t) -> flat (fx, fy, tau) of the
        `loaded` engine bodies (None without force elements)."""
        if not self.elements:
            return None
        return traced(lambda *args: self.engine_loads(args[:-2], args[-2], args[-1]),
                      6 * self.n + 2)

    def engine_loads(self, row: Sequence, H, t) -> list:
        """The element loads (fx, fy at the centre of gravity, tau) on the `loaded`
        engine bodies at the position-updated state x + H v of one state row. A load on
        an eliminated massless body reaches the engine bodies it follows by virtual
        power, J^T f, J's columns its velocities for a unit rate of each engine state."""
        P, V = split_state_row(row, H)
        frames = self.at(P, V)
        out = {k: [0.0, 0.0, 0.0] for k in self.loaded}
        for load in self.body_loads(frames, t):
            body, force, point, torque = load
            if body == WORLD:
                continue
            if body not in self.follows:
                k = self.index[body]
                out[k] = [a + b for a, b in zip(out[k], wrench(load, P[k][:2]))]
                continue
            x, y = frames.state(body)[:2]
            for k in self.follows[body]:
                for i, unit in enumerate(_UNITS):
                    rates = [_ZERO] * len(P)
                    rates[k] = unit
                    vx, vy, w = self.at(P, rates).state(body)[5:]
                    out[k][i] += torque * w if force is None else (
                        torque * w + force[0] * (vx - w * (point[1] - y))
                        + force[1] * (vy + w * (point[0] - x)))
        return [v for k in self.loaded for v in out[k]]


# --- a coupling of hinge angles on the bodies' absolute angles --------------------------


def angle_coupling(mech: Mechanism, coupling: LinearCoupling) -> tuple[dict[str, float], float]:
    """A coupling of hinge coordinates, sum c_i q_i = C, written on the absolute body
    angles as sum k_b theta_b = k0: (k per body, the world included, k0). Every coordinate
    it weighs must be a hinge's."""
    k: dict[str, float] = {}
    k0 = num(coupling.constant)
    for name, coef in coupling.coefficients:
        j = mech.joints[mech.coordinates.index(name)]
        s = -1.0 if j.clockwise else 1.0
        coef = num(coef)
        k[j.child] = k.get(j.child, 0.0) + coef * s
        if not j.absolute:
            k[j.parent] = k.get(j.parent, 0.0) - coef * s
        k0 += coef * s * num(j.angle_offset)
    return k, k0


def coupled_angles(mech: Mechanism, coupling: LinearCoupling
                   ) -> tuple[dict[str, float], float, list[str], float]:
    """`angle_coupling` (k, k0), the bodies whose angle enters it (a coefficient above the
    round-off of the coefficients' size), in order, and that size."""
    k, k0 = angle_coupling(mech, coupling)
    scale = max((abs(v) for v in k.values()), default=0.0)
    return k, k0, [b for b, v in k.items() if b != WORLD and abs(v) > 1e-12 * scale], scale


@dataclass(frozen=True)
class PitchPair:
    """Two bodies a, b hinged on a common carrier (the world as b: a hinged on a carrier
    hinged on the world) whose angle coupling k_a theta_a + k_b theta_b + k_carrier
    theta_carrier = const has sum k = 0: an internal/external gear pair on the carrier,
    i.e. rolling of the pitch circles at the pitch point a + lam (b - a), lam = k_a /
    (k_a + k_b), on the line of the hubs, `d` apart on the carrier."""

    carrier: str
    a: str
    b: str
    hub_a: tuple[float, float]  # a's point at its hinge on the carrier
    hub_b: tuple[float, float]
    d: float
    k_a: float
    k_b: float

    @property
    def lam(self) -> float:
        return self.k_a / (self.k_a + self.k_b)

    @property
    def circles(self) -> tuple:
        """The pitch circles (a, its centre hub_a, radius, b, its centre hub_b, radius,
        internal): radii |lam| d and |lam - 1| d, one inside the other unless 0 < lam < 1."""
        return (self.a, self.hub_a, abs(self.lam) * self.d, self.b, self.hub_b,
                abs(self.lam - 1) * self.d, not 0.0 < self.lam < 1.0)

    def pitch_points(self, ha, hb, phi: float) -> tuple[tuple, tuple]:
        """The pitch point as a point of a and as a point of b (world axes), from the world
        positions ha, hb of the hubs: on the line of the hubs, lam d from a's hub; b's is
        moved along the pitch tangent by the coupling's residual phi as a length,
        phi d / (k_a + k_b), so that a joint holding the two points together holds the
        coupling, its position error the joint's gap."""
        scale = self.d / (self.k_a + self.k_b)
        dx, dy = hb[0] - ha[0], hb[1] - ha[1]
        dist = math.hypot(dx, dy)
        ux, uy = dx / dist, dy / dist
        e = scale * phi
        ra, rb = self.lam * self.d, (self.lam - 1.0) * self.d
        return ((ha[0] + ra * ux, ha[1] + ra * uy),
                (hb[0] + rb * ux + e * uy, hb[1] + rb * uy - e * ux))


def pitch_pairs(mech: Mechanism, k: Mapping[str, float], bodies: Sequence[str],
                scale: float) -> Iterator[PitchPair]:
    """The pitch pairs (`PitchPair`) that a coupling on the absolute angles of `bodies`
    (`angle_coupling`; coefficients k, of size `scale`) can be, one per carrier among
    them, in the order of `bodies`."""
    for K in bodies:
        others = [b for b in bodies if b != K]
        hubs: dict[str, tuple[tuple, tuple]] = {}  # body -> (its hub point, K's hub point)
        for j in mech.joints:
            if isinstance(j, Revolute) and K in (j.parent, j.child):
                if j.parent == K:
                    hubs[j.child] = (tuple(np.array(plane_point(j.child_anchor))),
                                     tuple(np.array(plane_point(j.parent_anchor))))
                else:
                    hubs[j.parent] = (tuple(np.array(plane_point(j.parent_anchor))),
                                      tuple(np.array(plane_point(j.child_anchor))))
        if not set(others) <= set(hubs):
            continue
        if len(others) == 2:
            A, B = others
            if abs(sum(k[b] for b in bodies)) > 1e-12 * scale:
                continue
            ka, kb = k[A], k[B]
        elif len(others) == 1 and WORLD in hubs:
            A, B = others[0], WORLD
            ka = k[A]
            kb = -(k[K] + ka)
        else:
            continue
        d = float(np.linalg.norm(np.subtract(hubs[B][1], hubs[A][1])))
        if d == 0.0 or abs(ka + kb) <= 1e-12 * scale:
            continue
        yield PitchPair(K, A, B, hubs[A][0], hubs[B][0], d, ka, kb)


# --- small facts of the description an engine's translation asks for ---------------------


def line_through_origin(base: np.ndarray, direction: np.ndarray) -> bool:
    """Whether the line base + u direction (in a body's frame) passes through the frame's
    origin, the body's centre of mass."""
    scale = float(np.linalg.norm(direction)) * max(float(np.linalg.norm(base)), 1.0)
    return abs(float(base[0] * direction[1] - base[1] * direction[0])) <= 1e-12 * scale


def rotation_fixed(mech: Mechanism, body: str) -> bool:
    """Whether the body's angle is constant: every joint from the world to it is
    prismatic (its moment of inertia then enters no equation of motion)."""
    while body != WORLD:
        j = mech.joint_of_child(body)
        if not isinstance(j, Prismatic):
            return False
        body = j.parent
    return True


def effective_mass(m: float, inertia: float, d: float) -> float:
    """Mass of a rigid body felt at a point at distance d from its centre of mass, across
    the radius: m I / (I + m d^2)."""
    return m * inertia / (inertia + m * d * d)


def compensated_host(m: float, inertia: float, parts: Sequence[tuple[float, tuple, float]]
                     ) -> tuple[float, np.ndarray, float]:
    """What is left of a body of mass m and central moment `inertia` when substitute
    bodies take over part of it (`parts`: each one's mass, its centre of gravity in the
    body's frame and its own central moment), so that the body and its substitutes
    together have exactly the described inertia: (mass m1 = m - sum m_i, centre of
    gravity c1 = -sum m_i p_i / m1 in the body's frame, central moment I - sum (I_i +
    m_i |p_i|^2) - m1 |c1|^2); the caller checks that m1 and the moment stay positive."""
    m1 = m - sum(mi for mi, _, _ in parts)
    first = sum(mi * np.array(p) for mi, p, _ in parts)
    c1 = -first / m1 if m1 > 0 else np.zeros(2)
    i1 = inertia - sum(ii + mi * float(np.dot(p, p)) for mi, p, ii in parts
                       ) - m1 * float(c1 @ c1)
    return m1, c1, i1


def continued_angles(mech: Mechanism, q: np.ndarray, q0: np.ndarray) -> np.ndarray:
    """The samples q (rows) with every hinge angle unwrapped and continued from q0 (an
    angle read by atan2 jumps by 2 pi); q is changed in place and returned."""
    for i, j in enumerate(mech.joints):
        if isinstance(j, Revolute):
            col = np.unwrap(q[:, i])
            q[:, i] = col + 2 * math.pi * round((q0[i] - col[0]) / (2 * math.pi))
    return q


def coupling_residual(mech: Mechanism, coupling: LinearCoupling
                      ) -> Callable[[Mapping], object]:
    """The residual sum c_i q_i - C of a coupling as a function of the bodies' frame
    states (numbers, arrays of samples or symbols), the coordinates read by
    `coordinate_reader`."""
    terms = [(num(coef), coordinate_reader(mech.joints[i]), mech.joints[i])
             for name, coef in coupling.coefficients for i in [mech.coordinates.index(name)]]
    return lambda frames: (sum(coef * read(frames[j.parent], frames[j.child])[0]
                               for coef, read, j in terms) - num(coupling.constant))


def principal_inertia(tensor: np.ndarray) -> tuple[list[float], list[float]]:
    """(principal moments, quaternion x y z w of the principal axes) of a symmetric
    3 x 3 central tensor: the eigenvectors, made a right-handed frame."""
    values, vectors = np.linalg.eigh(tensor)
    if np.linalg.det(vectors) < 0:
        vectors[:, 2] = -vectors[:, 2]
    from scipy.spatial.transform import Rotation

    return [float(v) for v in values], [float(v) for v in Rotation.from_matrix(vectors).as_quat()]


@dataclass
class RollingGeometry:
    """Where a RollingContact's friction stand-in sits: a disc (inner circle of radius r)
    on a radius arm about the centre of a circular track (outer circle, radius R)."""

    coupling: str
    outer: str
    inner: str
    R: float
    r: float
    centre: tuple[float, float]       # outer circle centre, outer body frame
    inner_centre: tuple[float, float]  # inner circle centre, inner body frame
    hub: int                          # joint index of the inner body (its parent: the arm)
    radial: tuple[float, float]        # unit direction track centre -> hub, arm frame


def rolling_geometry(mech: Mechanism, c: RollingContact) -> RollingGeometry:
    """The geometry of a RollingContact: the ring is centred at the arm's hinge on the
    track, the disc's circle at its hub, and the radial direction runs along the arm from
    that hinge to the hub."""
    hub, hinge = mech.joint_of_child(c.disc), mech.joint_of_child(c.arm)
    centre = tuple(num(v) for v in hinge.parent_anchor)
    arm = (np.array([num(v) for v in hub.parent_anchor])
           - np.array([num(v) for v in hinge.child_anchor]))
    u = arm / np.linalg.norm(arm)
    return RollingGeometry(c.name, c.track, c.disc, num(c.track_radius), num(c.disc_radius),
                           centre, tuple(num(v) for v in hub.child_anchor),
                           mech.joints.index(hub), (float(u[0]), float(u[1])))


@dataclass(frozen=True)
class SliderSplit:
    """The masses of the sliders of the slots whose pin is on one body (`slider_masses`),
    by slot name, and what the pin body keeps: (mass, planar inertia about its centre of
    mass, centre of mass in its frame), or None where it keeps its own."""

    masses: dict[str, float]
    kept: tuple[float, float, np.ndarray] | None


def slider_masses(mech: Mechanism, pin_body: str, ratio: float, lightest: float,
                  substitute: float | None = None) -> SliderSplit:
    """The point masses of the sliders of the PointOnLine constraints whose pin is on
    `pin_body`, for an engine that holds a slot by a slider body sliding along it,
    connected to the pin. The slider follows the pin point, so its mass is taken out of
    the pin body (mass, centre of mass and inertia adjusted so that body + sliders have
    the description's mass, first and second moments: exact while the constraints hold):
    `ratio` times the largest equal point masses at the pins that leave a positive
    inertia. A slider on a fixed pin does not move: `ratio` times the slot body's mass
    (`lightest`, the lightest body's, where the slot body is the world or massless); on a
    massless pin body, `ratio` times its `substitute` mass, which carries the sliders."""
    cons = [c for c in mech.constraints
            if element_kind(c) == POINT_ON_LINE and c.body == pin_body]
    if pin_body == WORLD:
        masses = {}
        for c in cons:
            lb = c.line_body
            heavy = lb != WORLD and not mech.body(lb).massless
            masses[c.name] = ratio * (num(mech.body(lb).mass) if heavy else lightest)
        return SliderSplit(masses, None)
    if substitute is not None:
        return SliderSplit({c.name: ratio * substitute for c in cons}, None)
    body = mech.body(pin_body)
    pts = [np.array([num(c.point[0]), num(c.point[1])]) for c in cons]
    mp, ip = num(body.mass), num(body.inertia)
    # the largest point masses at the pins that leave a positive inertia
    bound = mp * ip / (ip + mp * sum(float(p @ p) for p in pts)) / len(cons)
    masses = [ratio * bound for _ in cons]
    rest, com, inertia = compensated_host(mp, ip, [(mc, p, 0.0) for mc, p in zip(masses, pts)])
    return SliderSplit({c.name: mc for c, mc in zip(cons, masses)}, (rest, inertia, com))


def geometric_stiffness(jacobian_at: Callable[[int, float], np.ndarray],
                        forces: np.ndarray, n: int, eps: float) -> np.ndarray:
    """d(J^T f)/dq at fixed closure forces f, by central differences: column i from the
    constraint Jacobian J at the state moved by +eps and by -eps along coordinate i
    (`jacobian_at(i, h)`)."""
    G = np.zeros((n, n))
    for i in range(n):
        cols = [jacobian_at(i, h).T @ forces for h in (eps, -eps)]
        G[:, i] = (cols[0] - cols[1]) / (2 * eps)
    return G


def constrained_modes(M: np.ndarray, C: np.ndarray, K: np.ndarray, J: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, ...]]:
    """The eigenvalues of M, C, K with the constraints of Jacobian J held exactly: with
    T a basis of J's null space (the right singular vectors beyond its numerical rank),
    those of T^T M T, T^T C T, T^T K T. Returns (eigenvalues, T, the reduced matrices)."""
    U, sv, Vt = np.linalg.svd(J)
    rank = int(np.sum(sv > 1e-9 * max(sv.max(initial=0.0), 1e-300)))
    T = Vt[rank:].T
    Mr, Cr, Kr = (T.T @ X @ T for X in (M, C, K))
    eig = quadratic_eigenvalues(Mr, Cr, Kr)
    # rigid modes (a free pulley) come out as round-off: make them exact zeros
    eig[np.abs(eig) < 1e-10 * max(np.max(np.abs(eig)), 1e-300)] = 0.0
    return eig, T, (Mr, Cr, Kr)


def rolling_contact_report(mech: Mechanism, coupling: LinearCoupling,
                           geometry: RollingGeometry, cmap: CoordinateMap, q: np.ndarray,
                           qd: np.ndarray, penetration: np.ndarray, force: np.ndarray,
                           points: np.ndarray) -> dict[str, np.ndarray]:
    """Measured errors of a RollingContact's friction stand-in, from the force of the
    track on the disc (`force`, world x, y per sample): slip (the coupling's Phi, m), slip
    rate (m/s), the `penetration` of the disc into the track (m), normal and friction
    force (N), the friction ratio |f| / N and the number of contact `points`; `friction`
    (the tangential component f, track on disc, along t = k x u with u from the track
    centre to the disc) is what the coupling's -lambda stands for."""
    cvec, const = coupling_row(mech, coupling)
    u = turned(cmap.angle(mech.joints[geometry.hub].parent, q), *geometry.radial)
    ux, uy = u[:, 0], u[:, 1]
    normal = -(force[:, 0] * ux + force[:, 1] * uy)
    friction = force[:, 0] * -uy + force[:, 1] * ux
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.abs(friction) / normal
    return {"slip": q @ cvec - const, "slip_rate": qd @ cvec, "penetration": penetration,
            "normal_force": normal, "friction": friction, "friction_ratio": ratio,
            "contact_points": points}


def length_scale(mech: Mechanism) -> float:
    """A length of the mechanism's own size: the largest distance of a joint anchor or a
    hinge closure's point from the frame it is given in."""
    points = [a for j in mech.joints for a in (j.parent_anchor, j.child_anchor)]
    points += [p for c in mech.constraints if isinstance(c, HingeClosure)
               for p in (c.point_a, c.point_b)]
    return max((math.sqrt(sum(num(v) ** 2 for v in p)) for p in points), default=1.0) or 1.0


# --- the link frames of a tree of relative joints -------------------------------------


def unit_axis(joint: Revolute | Prismatic) -> tuple[float, float, float]:
    """A hinge's unit axis (z where none is given) or a slide's, three components."""
    given = joint.axis if joint.axis is not None else (0, 0, 1)
    axis = np.array([num(v) for v in given] + [0.0] * (3 - len(given)))
    return tuple(float(v) for v in axis / np.linalg.norm(axis))


#: the coordinate axes x, y, z as unit vectors (`link_axis`)
_LINK_AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def link_axis(joint: Revolute | Prismatic) -> str:
    """'X', 'Y' or 'Z' when the joint's unit axis is that axis of its link frame (frames
    aligned with their parents: model convention 10), '' when it is none of them."""
    axis = unit_axis(joint)
    return next(("XYZ"[i] for i, e in enumerate(_LINK_AXES) if axis == e), "")


def axis_aligned(mech: Mechanism, joint: Revolute | Prismatic) -> bool:
    """A planar joint, or a spatial one whose axis is a link axis (`link_axis`): what a
    tree whose joints turn about or run along a link axis holds (an `Expression.applies`
    condition)."""
    return not mech.spatial or bool(link_axis(joint))


def rot_z(angle: float) -> np.ndarray:
    """The 3 x 3 rotation by `angle` about z (a planar rotation in 3-D)."""
    out = np.eye(3)
    out[:2, :2] = rot(angle)
    return out


@dataclass
class LinkFrames:
    """The link frames of a tree of relative joints for a numeric mechanism, one link per
    joint in joint order (parents first). Each link frame sits at its joint point on the
    child body, oriented at ``theta_body + beta`` (beta = 0 for a hinge, the axis angle
    minus the angle offset for a planar slide, whose joint frame's x axis is turned to the
    slide's axis; a spatial tree's frames are aligned with their parents: beta = 0, model
    convention 10); link i's joint frame sits at `offsets[i]` in its parent link's frame,
    turned by `rotations[i]`, and each body's centre of mass is at `com[body]` in its link
    frame, so the description's body frames are reproduced exactly. The map between the
    description's coordinates and the joint values is the shared one (`cmap`)."""

    cmap: CoordinateMap
    link_of: dict[str, int]          # body name -> link index
    parents: list[int]               # parent link index, -1 for the world
    offsets: list[np.ndarray]        # joint offsets (parent link frame), 3-vectors
    rotations: list[float]           # joint frame rotation against the parent link frame
    beta: dict[str, float]           # link frame orientation minus body angle
    com: dict[str, np.ndarray]       # centre of mass in the link frame

    @property
    def n(self) -> int:
        return len(self.parents)

    def local_point(self, body: str, point: Sequence[float]) -> np.ndarray:
        """A description body-frame point expressed in the body's link frame."""
        padded = [*point, 0.0, 0.0][:3]  # a planar point lies at z = 0
        return self.com[body] + rot_z(-self.beta[body]) @ np.array(padded)

    def frame_angle(self, body: str, u: np.ndarray) -> np.ndarray:
        """Orientation of the body's link frame (world: 0) for joint values u (rows)."""
        return u @ self.cmap.angle_v[body] + self.cmap.angle_v0[body] + self.beta[body]

    def coordinates(self, u: np.ndarray, ut: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Joint values and rates (rows) -> the description's coordinates and rates."""
        T = self.cmap.T
        return u @ T.T + self.cmap.c, ut @ T.T

    def values(self, q, qd) -> tuple[np.ndarray, np.ndarray]:
        """The description's coordinates and rates (one state) -> joint values and rates,
        by the inverse of `coordinates`."""
        Tinv = np.linalg.inv(self.cmap.T)
        return (Tinv @ (np.asarray(q, dtype=float) - self.cmap.c),
                Tinv @ np.asarray(qd, dtype=float))

    def local_normal(self, body: str, direction) -> np.ndarray:
        """The unit normal (turned +90 degrees) of a planar body-frame direction, in the
        body's link frame (2 components)."""
        d = np.array([num(v) for v in direction])
        d = d / float(np.hypot(*d))
        return rot(-self.beta[body]) @ np.array([-d[1], d[0]])


def joint_frame_turn(mech: Mechanism, joint: Revolute | Prismatic) -> tuple[float, float]:
    """(the joint frame's angle in the parent body's frame, the child's link frame angle
    minus the child body's angle): a hinge's angle offset and 0; a planar slide's axis
    angle alpha, its joint frame's x axis along the slide, and alpha minus the offset; a
    spatial slide's offset and 0 (frames aligned with the parent's)."""
    if isinstance(joint, Revolute) or mech.spatial:
        return num(joint.angle_offset), 0.0
    axis = np.array([num(v) for v in joint.axis])
    alpha = math.atan2(axis[1], axis[0])
    return alpha, alpha - num(joint.angle_offset)


def link_frames(mech: Mechanism) -> LinkFrames:
    """The `LinkFrames` of a numeric mechanism."""
    link_of: dict[str, int] = {}
    parents: list[int] = []
    offsets: list[np.ndarray] = []
    rotations: list[float] = []
    beta: dict[str, float] = {WORLD: 0.0}
    com: dict[str, np.ndarray] = {WORLD: np.zeros(3)}

    def column(v) -> np.ndarray:
        """An anchor in 3-D: a planar one's in-plane components, a spatial one's all."""
        values = [num(c) for c in v][:3 if mech.spatial else 2]
        return np.array(values + [0.0] * (3 - len(values)))

    for i, j in enumerate(mech.joints):
        p = j.parent
        parents.append(link_of[p] if p != WORLD else -1)
        link_of[j.child] = i
        # the joint point in the parent's link frame
        offsets.append(com[p] + rot_z(-beta[p]) @ column(j.parent_anchor))
        angle, beta[j.child] = joint_frame_turn(mech, j)
        rotations.append(angle - beta[p])
        com[j.child] = -rot_z(-beta[j.child]) @ column(j.child_anchor)
    return LinkFrames(coordinate_map(mech), link_of, parents, offsets, rotations, beta, com)


# --- conditions of an element's expression that follow from the description alone -------


def carries_child(mech: Mechanism, body: Body) -> bool:
    """Some joint of the description has `body` as its parent."""
    return any(j.parent == body.name for j in mech.joints)


def held_by_closure(mech: Mechanism, body: Body) -> bool:
    """A closure constraint acts on `body` (`constrained_bodies`)."""
    return body.name in constrained_bodies(mech)


def engine_coupling(mech: Mechanism, coupling: LinearCoupling) -> tuple[np.ndarray, float]:
    """A coupling written on the engine joint values: (its row, its constant)
    (`CoordinateMap.on_engine_values` of `coupling_row`)."""
    return coordinate_map(mech).on_engine_values(*coupling_row(mech, coupling))


def couples_two_engine_values(mech: Mechanism, coupling: LinearCoupling) -> bool:
    """The coupling, written on the engine joint values, involves exactly two of them."""
    return int(np.count_nonzero(engine_coupling(mech, coupling)[0])) == 2


def smallest_mass_and_inertia(mech: Mechanism) -> tuple[float, float]:
    """The smallest positive body mass and central inertia (1 where there is none): the
    scale of a substitute's small mass or inertia."""
    masses = [num(b.mass) for b in mech.bodies]
    inertias = [num(b.inertia) for b in mech.bodies]
    return (min((m for m in masses if m > 0), default=1.0),
            min((i for i in inertias if i > 0), default=1.0))


# --- the geometry of elements between two bodies, from the bodies' frame states ----------
#
# `states` and the arguments `pin`, `line`, `state_a`, `state_b` are frame states
# (x, y, theta, vx, vy, omega) of description bodies, as `body_states` gives them.


@dataclass(frozen=True)
class PairLoad:
    """A point-to-point element in numbers: its bodies, its points (body frames), its
    loads (`element_loads`) and whether its law reads the time."""

    name: str
    body_a: str
    body_b: str
    point_a: tuple[float, float]
    point_b: tuple[float, float]
    loads: Callable[[Mapping, float], list]
    time_dependent: bool

    def force(self, states: Mapping, t: float
              ) -> tuple[float, float, float, float, float, float]:
        """(force on b x, y, point a x, y, point b x, y) at the bodies' frame states; the
        force on a is opposite."""
        try:
            (_, (fx, fy), (bx, by), _), (_, _, (ax, ay), _) = self.loads(states, t)
        except ZeroDivisionError:  # the points coincide: the force has no direction
            ax, ay = point_state(states[self.body_a], self.point_a)[:2]
            bx, by = point_state(states[self.body_b], self.point_b)[:2]
            return 0.0, 0.0, ax, ay, bx, by
        return fx, fy, ax, ay, bx, by


def pair_load(mech: Mechanism, f: PointToPoint) -> PairLoad:
    """The `PairLoad` of a point-to-point element."""
    return PairLoad(f.name, f.body_a, f.body_b, plane_point(f.point_a), plane_point(f.point_b),
                    element_loads(mech, f), ForceLaw.of(f).time_dependent)


@dataclass(frozen=True)
class SlotGeometry:
    """A PointOnLine in numbers (body frames): the pin's body and point, the slot body,
    the point L of its line and the line's unit direction u."""

    pin_body: str
    pin_point: tuple[float, float]
    line_body: str
    line_point: tuple[float, float]
    direction: tuple[float, float]

    def frame(self, pin: tuple, line: tuple
              ) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, float]]:
        """World position and velocity of the pin P and of the slot body's point L, and
        the slot's direction u in world axes."""
        c, s = math.cos(line[2]), math.sin(line[2])
        u = (c * self.direction[0] - s * self.direction[1],
             s * self.direction[0] + c * self.direction[1])
        return point_state(pin, self.pin_point), point_state(line, self.line_point), u

    def along(self, pin: tuple, line: tuple) -> tuple[float, float]:
        """Where the pin is along the slot, s = (P - L) . u, and its rate (v_P - v_L) . u
        with v_L the velocity of the slot body's material point L ((P - L) is along u, so
        the rotation of u adds nothing)."""
        (px, py, pvx, pvy), (lx, ly, lvx, lvy), (ux, uy) = self.frame(pin, line)
        return (px - lx) * ux + (py - ly) * uy, (pvx - lvx) * ux + (pvy - lvy) * uy

    def line_point_at(self, s: float) -> tuple[float, float]:
        """The slot body's point of its line at s along it: L + s u (body frame)."""
        ux, uy = self.direction
        return self.line_point[0] + s * ux, self.line_point[1] + s * uy


def slot_geometry(c: PointOnLine) -> SlotGeometry:
    """The `SlotGeometry` of a PointOnLine (its direction made a unit vector)."""
    u = np.array([num(c.direction[0]), num(c.direction[1])])
    u = u / float(np.hypot(*u))
    return SlotGeometry(c.body, plane_point(c.point), c.line_body, plane_point(c.line_point),
                        (float(u[0]), float(u[1])))


def parents_first(parents: Sequence[int]) -> list[int]:
    """An order of the links of a tree (`parents[i]`: the index of link i's parent, < 0 for
    the root) with every parent before its children, the given order where it allows."""
    done: set[int] = set()
    order: list[int] = []
    while len(order) < len(parents):
        for i, parent in enumerate(parents):
            if i not in done and (parent < 0 or parent in done):
                order.append(i)
                done.add(i)
    return order


class EnginePlan:
    """What every engine's translation of a numeric mechanism starts from, computed once:
    the mechanism and the backend's resolved settings (`cfg`), the number of joints `n`,
    the coordinate map (`map`), the gravity vector, the smallest mass and inertia (the
    scale of a substitute's: `m_min`, `i_min`), the coordinate laws (`coordinate_laws`)
    and the prescribed motions (`driven`). A backend's translation extends it with its
    engine's terms, built element by element by its builders (`build`)."""

    def __init__(self, mech: Mechanism, cfg: Mapping) -> None:
        self.mech, self.cfg = mech, cfg
        self.n = len(mech.joints)
        self.map = coordinate_map(mech)
        self.gravity_vector = gravity_vector(mech)
        self.m_min, self.i_min = smallest_mass_and_inertia(mech)
        self.coordinate_laws = CoordinateLaws(
            mech, [f for f in mech.forces if isinstance(f, CoordinateForce)])
        self.driven = motions(mech)

    def build(self, builders: Mapping[str, Callable]) -> None:
        """Every element of the description into this translation, by its kind's builder
        (`base.ElementBuilders`), in description order."""
        for kind, element in elements(self.mech):
            builders[kind](self, element)

    def joint_forces(self, q, qd, t: float) -> np.ndarray:
        """The engine joint forces tau = T^T Q of the coordinate laws at the description
        state (q, qd)."""
        return self.map.T.T @ np.asarray(self.coordinate_laws.generalized(q, qd, t))


def plane_point(point) -> tuple[float, float]:
    """A description point's (x, y) as numbers."""
    return num(point[0]), num(point[1])


def slide_axis(j: Prismatic) -> tuple[float, float]:
    """A prismatic joint's unit axis in its joint frame (the parent's frame turned by the
    angle offset): the description's axis, given in the parent's frame, turned by
    -angle_offset and normalised (its length is the slide's scale in `CoordinateMap.A`)."""
    length = math.hypot(num(j.axis[0]), num(j.axis[1]))
    ax, ay = num(j.axis[0]) / length, num(j.axis[1]) / length
    c, s = math.cos(-num(j.angle_offset)), math.sin(-num(j.angle_offset))
    return c * ax - s * ay, s * ax + c * ay
