"""The engine-neutral description of a mechanism: planar, or spatial (3-D) with the planar
ones as its special case.

A mechanism is data: rigid bodies, the joints that give its generalized coordinates, force
elements, applied loads, and (later mechanisms) closure constraints. The analytic layer
derives the exact model from it; every simulator backend translates it.

Conventions (all backends and the analytic layer honour them):

1. World frame: x to the right, y up, motion in the x-y plane, gravity (0, -g).
2. Every body has a frame whose origin is its centre of mass; `inertia` is the central
   moment of inertia about the z axis. Mass and inertia are non-negative. A body may be
   massless (mass 0, inertia 0): it is then a kinematic link only (the arm of Fig. 12);
   backends that reject massless moving bodies must fold its joints into its child. A
   body of mass > 0 and central inertia 0 is a point mass (the bob of a simple pendulum
   on a massless rod); a backend whose engine refuses it declares its substitute.
3. A body's pose is (x, y, theta); R(theta) rotates body-frame vectors to world axes.
4. `Revolute(parent, child)`: the anchor points coincide,
   ``p_parent + R(th_parent) parent_anchor = p_child + R(th_child) child_anchor``, and
   ``th_child = th_parent + q + angle_offset`` (relative angle), or, with
   ``absolute=True``, ``th_child = q + angle_offset`` (the monograph's absolute angles,
   e.g. phi2 of Fig. 37); with ``clockwise=True`` the coordinate turns the other way
   (q is replaced by -q, e.g. theta of Fig. 39). Engines with counter-clockwise relative
   hinges use ``th_child - th_parent - angle_offset`` (`Derivation.joint_values`).
5. `Prismatic(parent, child)`: ``p_parent + R(th_parent)(parent_anchor + q axis) =
   p_child + R(th_child) child_anchor`` and ``th_child = th_parent + angle_offset``.
6. Reaction at a joint: the force the parent exerts on the child through the joint, in
   world axes (x, y components), N.
7. Force elements are written once as SymPy expressions of placeholder symbols
   (`LENGTH`, `LENGTH_RATE` for point-to-point elements; `COORD`, `COORD_RATE` for
   elements on one coordinate; `TIME` everywhere) and of parameter symbols. The same
   expression feeds the derivation and, compiled with `compile_law`, every engine.
8. Positive `tension` of a point-to-point element pulls its two points together.
9. A `Prescribed` coordinate follows its motion q(t) for the whole run (monograph §9.6);
   its rate and acceleration are the motion's symbolic derivatives. The generalized force
   that imposes it (the actuator, acting between the joint's parent and child, positive
   in the direction of increasing coordinate: N along a slide, N m about a hinge) is an
   output, reported under the element's name. The other coordinates are the free ones.
10. Spatial (3-D) mechanisms use the same elements with three-component vectors: a body
   may carry its full central inertia tensor (`Body.inertia_tensor`, 3 x 3, body axes;
   `inertia` is then its zz entry), a `Revolute` may turn about any `axis` (three
   components, in the parent's frame, which is also the child's since the rotation is
   about it: R_child = R_parent Rot(axis, q + angle_offset)), a `Prismatic` may slide
   along a three-component axis, anchors may have three components, and the mechanism
   states which way is up (`Mechanism.up`, gravity along -up). A mechanism that uses none
   of these is planar (`Mechanism.spatial` is false) and follows conventions 1-5 exactly.
   Body frames coincide with the parent's frame at q = 0 (no orientation offset): a body
   whose principal axes are turned gives its tensor in those parent-aligned axes.
   A spatial loop closes with a `HingeClosure` (a hinge the tree does not hold: the
   point and the axis, five equations); the planar closures stay planar. An
   over-constrained loop (Bricard's) states how many of its closure equations the
   others imply everywhere on its motion (`Mechanism.redundant`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Callable, Mapping, Sequence, Union

import sympy as sp

Expr = Union[sp.Expr, float, int]
Vec = tuple[Expr, Expr]
Vec3 = tuple[Expr, Expr, Expr]
Tensor3 = tuple[Vec3, Vec3, Vec3]

WORLD = "world"
TIME = sp.Symbol("t", real=True)
LENGTH = sp.Symbol("_length", positive=True)
LENGTH_RATE = sp.Symbol("_length_rate", real=True)
COORD = sp.Symbol("_coord", real=True)
COORD_RATE = sp.Symbol("_coord_rate", real=True)
#: the gravity parameter: any finite value, zero included (a horizontal or a space
#: mechanism), negative too (gravity along +up)
GRAVITY = sp.Symbol("g", real=True)
STANDARD_GRAVITY = 9.81
#: the largest number of elements a count parameter admits unless it states its own: the
#: symbolic derivation of a chain and its generated code grow with it, and the largest
#: chain must still derive, compile and be analysed within `analyze`'s default time
#: budget (benchmarks/count_cost.py measures each size; its record shows where that
#: stops); the catalog's own studies go to this size
MAX_COUNT = 32


@dataclass(frozen=True)
class Parameter:
    """A named, overridable parameter (names as in the monograph, ASCII spelling).

    `default` is a number, or a formula: an expression of the other parameters in SymPy
    syntax (e.g. ``"m*(2*l)**2/12"``, the inertia of a uniform bar), evaluated after the
    scenario's and the user's values, so that a default defined by a formula follows the
    parameters it depends on; a value given explicitly still wins."""

    name: str
    default: float | str
    unit: str
    meaning: str
    source: str = "project default"
    #: "positive", "nonnegative" or "real": checked on every value (given or derived);
    #: "count": a structural parameter, an integer >= 1 that shapes the mechanism itself
    #: (the number of elements of a discretized continuum): `build` receives it as a
    #: Python int, never as a symbol (`System.with_structure`)
    domain: str = "positive"
    #: a count's largest value (default MAX_COUNT): the derivation, the equilibrium
    #: search and every engine run grow with it (benchmarks/count_cost.py measures how)
    maximum: int | None = None
    #: a real parameter that shapes the mechanism too, like a count: which element of a
    #: chain carries a load placed at a fraction of its length. `build` receives its
    #: value (a float), never a symbol, and the System is built for each value it takes
    #: (`System.with_structure`); a validity condition keeps it where the chain has a node
    shapes: bool = False

    def __post_init__(self) -> None:
        if self.domain == "count" and (isinstance(self.default, str)
                                       or int(self.default) != self.default
                                       or self.default < 1):
            raise ValueError(f"parameter {self.name}: a count's default must be an integer "
                             f">= 1, not {self.default!r}")
        if self.shapes and isinstance(self.default, str):
            raise ValueError(f"parameter {self.name}: a parameter that shapes the mechanism "
                             f"has a number for its default, not {self.default!r}")

    @property
    def derived(self) -> bool:
        """Whether the default is a formula of other parameters."""
        return isinstance(self.default, str)

    @property
    def structural(self) -> bool:
        """Whether the value shapes the mechanism (domain "count", or `shapes`)."""
        return self.domain == "count" or self.shapes

    def structural_value(self, value: float) -> int | float:
        """A structural value as `build` receives it: a count's integer, a float else."""
        return int(value) if self.domain == "count" else float(value)

    @property
    def symbol(self) -> sp.Symbol:
        if self.name == GRAVITY.name:
            # one symbol for gravity, whatever domain a module declares for it: the
            # mechanism's gravity is GRAVITY, and parameters substitute by symbol
            return GRAVITY
        if self.domain == "count":
            # never in an expression (build gets the integer); a placeholder argument
            # of the compiled functions, like every parameter
            return sp.Symbol(self.name, integer=True, positive=True)
        if self.domain == "positive":
            return sp.Symbol(self.name, positive=True)
        if self.domain == "nonnegative":
            return sp.Symbol(self.name, nonnegative=True)
        return sp.Symbol(self.name, real=True)

    def validate(self, value: float) -> None:
        if not math.isfinite(value):
            raise ValueError(f"parameter {self.name} must be finite, got {value}")
        if self.domain == "positive" and not value > 0:
            raise ValueError(f"parameter {self.name} must be > 0, got {value}")
        if self.domain == "nonnegative" and not value >= 0:
            raise ValueError(f"parameter {self.name} must be >= 0, got {value}")
        if self.domain == "count" and not (value >= 1 and value == int(value)):
            raise ValueError(f"parameter {self.name} must be an integer >= 1, got {value:g}")
        if self.domain == "count" and value > self.largest:
            raise ValueError(f"parameter {self.name} must be at most {self.largest} (the cost "
                             f"of deriving and running the chain grows with it), got "
                             f"{value:g}")

    @property
    def largest(self) -> float:
        """The largest value a count admits (inf for other domains)."""
        if self.domain != "count":
            return math.inf
        return self.maximum if self.maximum is not None else MAX_COUNT


# --- drawing / contact geometry (body frame) -------------------------------------------


@dataclass(frozen=True)
class Segment:
    a: Vec
    b: Vec
    width: Expr = 0.02


@dataclass(frozen=True)
class Circle:
    center: Vec
    radius: Expr


@dataclass(frozen=True)
class Rectangle:
    center: Vec
    width: Expr
    height: Expr


Shape = Union[Segment, Circle, Rectangle]


@dataclass(frozen=True)
class Body:
    name: str
    mass: Expr
    inertia: Expr
    shapes: tuple[Shape, ...] = ()
    #: full central inertia tensor in body axes (convention 10); None: planar body
    inertia_tensor: Tensor3 | None = None

    def __post_init__(self) -> None:
        tensor = self.inertia_tensor
        moments = [self.inertia] + ([tensor[i][i] for i in range(3)] if tensor else [])
        for what, value in [("mass", self.mass)] + [("inertia", v) for v in moments]:
            value = sp.sympify(value)
            if value.is_number and value.is_negative:
                raise ValueError(f"body {self.name}: {what} must be >= 0, got {float(value):g}")
        if tensor is None:
            return
        if len(tensor) != 3 or any(len(row) != 3 for row in tensor):
            raise ValueError(f"body {self.name}: the inertia tensor must be 3 x 3")
        for i in range(3):
            for j in range(i):
                if sp.simplify(sp.sympify(tensor[i][j]) - sp.sympify(tensor[j][i])) != 0:
                    raise ValueError(f"body {self.name}: the inertia tensor must be symmetric")
        if sp.simplify(sp.sympify(tensor[2][2]) - sp.sympify(self.inertia)) != 0:
            raise ValueError(f"body {self.name}: inertia must be the tensor's zz entry")

    @classmethod
    def spatial(cls, name: str, mass: Expr, tensor: Tensor3,
                shapes: tuple[Shape, ...] = ()) -> "Body":
        """A body given by its full central inertia tensor (body axes)."""
        return cls(name, mass, tensor[2][2], shapes, inertia_tensor=tensor)

    @property
    def massless(self) -> bool:
        if self.inertia_tensor is not None:
            return sp.sympify(self.mass) == 0 and all(
                sp.sympify(v) == 0 for row in self.inertia_tensor for v in row)
        return sp.sympify(self.mass) == 0 and sp.sympify(self.inertia) == 0


@dataclass(frozen=True)
class Revolute:
    name: str
    parent: str
    child: str
    coordinate: str
    parent_anchor: Vec = (0, 0)
    child_anchor: Vec = (0, 0)
    angle_offset: Expr = 0
    absolute: bool = False
    clockwise: bool = False
    #: hinge axis in the parent's frame (three components, convention 10); None: z
    axis: Vec3 | None = None


@dataclass(frozen=True)
class Prismatic:
    name: str
    parent: str
    child: str
    coordinate: str
    axis: Vec
    parent_anchor: Vec = (0, 0)
    child_anchor: Vec = (0, 0)
    angle_offset: Expr = 0
    #: open interval of admissible values (None = unbounded); the equilibrium search and
    #: the backends respect it (e.g. a distance from a pivot is positive).
    limits: tuple[Expr | None, Expr | None] = (None, None)


Joint = Union[Revolute, Prismatic]


@dataclass(frozen=True)
class PointToPoint:
    """Spring/damper/custom law acting along the line between two body points.

    `tension` is an expression of LENGTH, LENGTH_RATE, TIME and parameters; positive
    tension pulls the points together. `potential`, when the law is conservative, is the
    stored energy as a function of LENGTH (used by the energy route of the linearization
    and by energy-drift checks); `dissipation` is Rayleigh's function of LENGTH_RATE for
    linear viscous parts.
    """

    name: str
    body_a: str
    point_a: Vec
    body_b: str
    point_b: Vec
    tension: Expr
    potential: Expr | None = None
    dissipation: Expr | None = None


@dataclass(frozen=True)
class CoordinateForce:
    """Generalized force on one coordinate (torsional/linear spring-damper, custom law,
    applied load e(t)). `force` is an expression of COORD, COORD_RATE, TIME and
    parameters, positive in the direction of increasing coordinate. It acts between the
    parent and the child of the joint that owns the coordinate.

    With `relative_to`, COORD is the difference q[coordinate] - q[relative_to] and the
    element is a couple: +force on `coordinate`, -force on `relative_to`. Two absolute
    angles of hinged bodies make it the hinge's torsional spring-damper (the relative
    rotation is the engine's joint value)."""

    name: str
    coordinate: str
    force: Expr
    potential: Expr | None = None
    dissipation: Expr | None = None
    relative_to: str | None = None

    def weights(self, coordinates: Sequence[str]) -> dict[int, int]:
        """{coordinate index: sign}: COORD = sum(sign q[i]), and the generalized force
        is force * sign on each."""
        out = {coordinates.index(self.coordinate): 1}
        if self.relative_to is not None:
            out[coordinates.index(self.relative_to)] = -1
        return out

    @property
    def time_dependent(self) -> bool:
        return TIME in sp.sympify(self.force).free_symbols


ForceElement = Union[PointToPoint, CoordinateForce]


@dataclass(frozen=True)
class Prescribed:
    """A coordinate imposed as a function of time (convention 9): `motion` is an
    expression of TIME and parameters; `name` names its actuator force."""

    name: str
    coordinate: str
    motion: Expr

    @property
    def rate(self) -> sp.Expr:
        return sp.diff(sp.sympify(self.motion), TIME)

    @property
    def acceleration(self) -> sp.Expr:
        return sp.diff(sp.sympify(self.motion), TIME, 2)


# --- closure constraints (loops, slots, couplings) -------------------------------------
# Joints form a spanning tree; constraints close it. The analytic layer treats them with
# Lagrange multipliers (monograph §10) and by reduction to the independent coordinates the
# mechanism names. Sign convention: with Phi(q) = 0 and multipliers lam, the equations are
# M q'' + h - Q + Phi_q^T lam = 0, so the constraint's generalized force is -Phi_q^T lam.


@dataclass(frozen=True)
class PointOnPoint:
    """Loop closure: point_a of body_a coincides with point_b of body_b (2 equations,
    Phi = p_a - p_b). Its force: -lam on body_a at the point, +lam on body_b."""

    name: str
    body_a: str
    point_a: Vec
    body_b: str
    point_b: Vec

    @property
    def bodies(self) -> tuple[str, str]:
        """(the body its force is reported on, the other one)."""
        return self.body_a, self.body_b


@dataclass(frozen=True)
class PointOnLine:
    """Pin in slot: `point` of `body` stays on the line of `line_body` through
    `line_point` along `direction` (body frames). One equation, Phi = n . (P - L) with n
    the slot's unit normal (direction turned +90 degrees); the pin feels the force
    -lam n, the slot body +lam n (frictionless slot)."""

    name: str
    body: str
    point: Vec
    line_body: str
    line_point: Vec
    direction: Vec

    @property
    def bodies(self) -> tuple[str, str]:
        """(the pin's body, on which its force is reported; the slot's body)."""
        return self.body, self.line_body


@dataclass(frozen=True)
class LinearCoupling:
    """Sum of coefficient * coordinate = constant: belts, gears, rolling written on
    relative angles. Its multiplier is a generalized force (N m for angles)."""

    name: str
    coefficients: tuple[tuple[str, Expr], ...]
    constant: Expr = 0


@dataclass(frozen=True)
class RollingContact:
    """Rolling by friction contact, which a variant puts in place of the rolling
    `LinearCoupling` of the same name (`systems.Variant.constraints`): the disc body
    `disc`, hinged at its centre on the massless arm `arm`, touches from inside the
    circle of radius `track_radius` of `track` centred at the arm's hinge on it;
    `disc_radius` is the disc's. The arm no longer holds the disc at track_radius -
    disc_radius (engines free it along its length): the contact's normal force does, and
    its friction stands for the coupling, whose no-slip condition (`coefficients`,
    `constant`, as in `LinearCoupling`) then measures the slip. Its force is reported as
    the coupling's (-multiplier: the friction force of the track on the disc)."""

    name: str
    disc: str
    arm: str
    track: str
    disc_radius: Expr
    track_radius: Expr
    coefficients: tuple[tuple[str, Expr], ...]
    constant: Expr = 0

    @property
    def bodies(self) -> tuple[str, str]:
        """(the disc, on which its force is reported; the track)."""
        return self.disc, self.track

    @property
    def coupling(self) -> LinearCoupling:
        """The rolling constraint this contact stands for."""
        return LinearCoupling(self.name, self.coefficients, self.constant)


@dataclass(frozen=True)
class HingeClosure:
    """Spatial loop closure by a hinge (a revolute pair the joint tree does not hold):
    point_a of body_a coincides with point_b of body_b, and the hinge axis axis_a fixed in
    body_a stays parallel to axis_b fixed in body_b (body-frame three-component vectors).
    Five equations: the three of Phi = p_a - p_b (world axes), then n_a . u_b = 0 and
    n_a . w_b = 0 with n_a the world direction of axis_a and u_b, w_b two directions of
    body_b perpendicular to axis_b (`perpendicular_pair`). Its force: -lam[0:3] on body_a
    at the point (world axes), +lam[0:3] on body_b; the last two multipliers are the
    couple that keeps the axes parallel."""

    name: str
    body_a: str
    point_a: Vec3
    body_b: str
    point_b: Vec3
    axis_a: Vec3
    axis_b: Vec3

    @property
    def bodies(self) -> tuple[str, str]:
        """(the body its force is reported on, the other one)."""
        return self.body_a, self.body_b


def perpendicular_pair(axis: Vec3) -> tuple[sp.Matrix, sp.Matrix]:
    """Two directions perpendicular to `axis` and to each other (3 x 1, of the axis's
    length): u = axis x e, with e the coordinate axis least aligned with `axis` (the
    first such), and w = axis x u / |axis|."""
    a = as_column3(axis)
    magnitudes = [abs(float(c)) for c in a]
    e = sp.zeros(3, 1)
    e[magnitudes.index(min(magnitudes))] = 1
    norm = sp.sqrt(sum(c**2 for c in a))
    u = a.cross(e)
    u = u * norm / sp.sqrt(sum(c**2 for c in u))
    return u.applyfunc(sp.simplify), (a.cross(u) / norm).applyfunc(sp.simplify)


Constraint = Union[PointOnPoint, PointOnLine, LinearCoupling, RollingContact, HingeClosure]


def linear_spring_damper(k: Expr, l0: Expr, c: Expr = 0) -> dict:
    """Tension, potential and dissipation of a linear spring (free length l0) with a
    parallel viscous damper, for `PointToPoint(**...)`."""
    return dict(
        tension=k * (LENGTH - l0) + c * LENGTH_RATE,
        potential=k * (LENGTH - l0) ** 2 / 2,
        dissipation=c * LENGTH_RATE**2 / 2,
    )


def coordinate_spring_damper(k: Expr, q0: Expr, c: Expr = 0) -> dict:
    """Linear spring with neutral position q0 plus damper on a coordinate."""
    return dict(
        force=-k * (COORD - q0) - c * COORD_RATE,
        potential=k * (COORD - q0) ** 2 / 2,
        dissipation=c * COORD_RATE**2 / 2,
    )


@dataclass(frozen=True)
class Mechanism:
    """A mechanism, planar or spatial (convention 10), as data. Coordinates are the
    joints' coordinates in joint order."""

    bodies: tuple[Body, ...]
    joints: tuple[Joint, ...]
    forces: tuple[ForceElement, ...] = ()
    gravity: Expr = GRAVITY
    constraints: tuple[Constraint, ...] = ()
    #: independent coordinates when constraints remove degrees of freedom (None: all)
    independent: tuple[str, ...] | None = None
    #: coordinates imposed as functions of time, with their actuators (convention 9)
    prescribed: tuple[Prescribed, ...] = ()
    #: the world's up direction; gravity acts along -up (convention 10)
    up: Vec3 = (0, 1, 0)
    #: False for long chains (N segments in a row): SymPy's simplify of nested angle
    #: sums grows exponentially with N, so the derivation keeps its exact unsimplified
    #: expressions (lambdify's common-subexpression elimination compacts them)
    simplify: bool = True
    #: the assembly branch in closed form: (dependent coordinate, expression of the
    #: independent coordinates' symbols) for every dependent coordinate. Where the
    #: constraint Jacobian loses rank along the motion (a linkage passing a change point,
    #: where branches cross), solving the closure by Newton's method from the independent
    #: coordinates is singular; the branch the motion stays on, given so, keeps the
    #: reduced equations regular there (analytic/derivation.py checks that the
    #: constraints vanish on it identically)
    branch: tuple[tuple[str, Expr], ...] = ()
    #: the number of constraint equations the others imply everywhere on the motion (an
    #: over-constrained loop such as Bricard's: Grübler's count gives no mobility, the
    #: geometry gives some): the constraint Jacobian's rank is the number of rows minus
    #: this, and the independent coordinates number n - rank. The numeric model checks the
    #: rank at every configuration it assembles (analytic/numeric.py)
    redundant: int = 0

    @property
    def spatial(self) -> bool:
        """Whether the mechanism uses any 3-D element (convention 10)."""
        vectors = [a for j in self.joints for a in (j.parent_anchor, j.child_anchor)]
        vectors += [j.axis for j in self.joints if isinstance(j, Prismatic)]
        return (any(b.inertia_tensor is not None for b in self.bodies)
                or any(isinstance(j, Revolute) and j.axis is not None for j in self.joints)
                or any(len(v) == 3 for v in vectors)
                or any(isinstance(c, HingeClosure) for c in self.constraints)
                or tuple(sp.sympify(u) for u in self.up) != (0, 1, 0))

    def __post_init__(self) -> None:
        names = [b.name for b in self.bodies]
        if len(set(names)) != len(names) or WORLD in names:
            raise ValueError(f"body names must be unique and not {WORLD!r}: {names}")
        seen = {WORLD}
        for j in self.joints:
            if j.parent not in seen:
                raise ValueError(f"joint {j.name}: parent {j.parent!r} must come before it")
            if j.child in seen or j.child not in names:
                raise ValueError(f"joint {j.name}: child {j.child!r} unknown or already placed")
            seen.add(j.child)
        if seen != {WORLD, *names}:
            raise ValueError(f"bodies without a joint: {sorted(set(names) - seen)}")
        coords = self.coordinates
        if len(set(coords)) != len(coords):
            raise ValueError(f"duplicate coordinate names: {coords}")
        for f in self.forces:
            if isinstance(f, CoordinateForce) and f.coordinate not in coords:
                raise ValueError(f"force {f.name}: unknown coordinate {f.coordinate}")
            if isinstance(f, CoordinateForce) and f.relative_to is not None and (
                    f.relative_to not in coords or f.relative_to == f.coordinate):
                raise ValueError(f"force {f.name}: relative_to {f.relative_to!r} must be "
                                 f"another coordinate of the mechanism")
            if isinstance(f, CoordinateForce) and f.relative_to is not None and not all(
                    isinstance(self.joints[coords.index(c)], Revolute)
                    for c in (f.coordinate, f.relative_to)):
                raise ValueError(f"force {f.name}: relative_to joins two hinge angles "
                                 f"(a torsional couple)")
        for c in self.constraints:
            used = ([name for name, _ in c.coefficients]
                    if isinstance(c, (LinearCoupling, RollingContact)) else [])
            touched = (() if isinstance(c, LinearCoupling) else
                       (*c.bodies, c.arm) if isinstance(c, RollingContact) else c.bodies)
            for b in touched:
                if b != WORLD and b not in names:
                    raise ValueError(f"constraint {c.name}: unknown body {b!r}")
            for name in used:
                if name not in coords:
                    raise ValueError(f"constraint {c.name}: unknown coordinate {name!r}")
            if isinstance(c, RollingContact) and not (
                    self.joint_of_child(c.disc).parent == c.arm
                    and self.joint_of_child(c.arm).parent == c.track):
                raise ValueError(f"contact {c.name}: the disc must be hinged on the arm, the "
                                 "arm on the track")
        driven = [p.coordinate for p in self.prescribed]
        for p in self.prescribed:
            if p.coordinate not in coords:
                raise ValueError(f"prescribed motion {p.name}: unknown coordinate "
                                 f"{p.coordinate!r}")
            extra = sp.sympify(p.motion).free_symbols & {COORD, COORD_RATE, LENGTH,
                                                         LENGTH_RATE}
            if extra:
                raise ValueError(f"prescribed motion {p.name}: q(t) must be a function of "
                                 f"time and parameters only, not of {sorted(map(str, extra))}")
        if len(set(driven)) != len(driven):
            raise ValueError(f"a coordinate is prescribed twice: {driven}")
        if self.prescribed and (self.constraints or self.independent is not None):
            raise ValueError("prescribed motion in a mechanism with closure constraints is "
                             "not supported: prescribe a coordinate of an open tree")
        if len(driven) == len(coords) and coords:
            raise ValueError("every coordinate is prescribed: nothing is free to move")
        if self.spatial:
            planar_closures = [c.name for c in self.constraints
                               if not isinstance(c, HingeClosure)]
            if planar_closures:
                raise ValueError(f"closure constraints {planar_closures} are planar: a "
                                 "spatial mechanism closes its loops with HingeClosure")
            for c in self.constraints:
                if any(len(v) != 3 for v in (c.point_a, c.point_b, c.axis_a, c.axis_b)):
                    raise ValueError(f"hinge closure {c.name}: points and axes have three "
                                     "components")
            if len(self.up) != 3:
                raise ValueError(f"up must have three components, got {self.up}")
            for j in self.joints:
                if isinstance(j, Revolute) and j.axis is not None and len(j.axis) != 3:
                    raise ValueError(f"joint {j.name}: a hinge axis has three components")
                if isinstance(j, Revolute) and j.absolute and j.parent != WORLD:
                    raise ValueError(f"joint {j.name}: an absolute angle in a spatial "
                                     "mechanism must hang from the world")
        if self.independent is not None:
            unknown = set(self.independent) - set(coords)
            if unknown:
                raise ValueError(f"independent coordinates not in the mechanism: {unknown}")
        elif self.constraints:
            raise ValueError("a constrained mechanism must name its independent coordinates")
        if self.redundant and not (0 < self.redundant and self.constraints):
            raise ValueError(f"redundant = {self.redundant}: a count of constraint "
                             "equations, of a mechanism with closure constraints")
        if self.branch:
            given = [name for name, _ in self.branch]
            dependent = [c for c in coords if c not in (self.independent or ())]
            if sorted(given) != sorted(dependent) or len(set(given)) != len(given):
                raise ValueError(f"the branch gives {sorted(given)}: it must give every "
                                 f"dependent coordinate once, {sorted(dependent)}")

    @property
    def coordinates(self) -> tuple[str, ...]:
        return tuple(j.coordinate for j in self.joints)

    @property
    def independent_coordinates(self) -> tuple[str, ...]:
        """The coordinates the equations of motion are integrated in: the independent
        ones of a constrained mechanism, the free (not prescribed) ones of a driven one."""
        if self.independent is not None:
            return self.independent
        driven = {p.coordinate for p in self.prescribed}
        return tuple(c for c in self.coordinates if c not in driven)

    @property
    def driven_coordinates(self) -> tuple[str, ...]:
        return tuple(p.coordinate for p in self.prescribed)

    def body(self, name: str) -> Body:
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(name)

    def joint(self, name: str) -> Joint:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(name)

    def joint_of_child(self, body: str) -> Joint:
        for j in self.joints:
            if j.child == body:
                return j
        raise KeyError(body)

    def angular(self, coordinate: str) -> bool:
        return isinstance(self.joints[self.coordinates.index(coordinate)], Revolute)

    def wrap_groups(self) -> list[list[int]]:
        """Angular coordinates that shift by 2 pi together: those joined by couples
        (`CoordinateForce.relative_to`: a wound hinge spring is another state), each
        group in coordinate order; an angle without couples is its own group."""
        coords = self.coordinates
        group = {i: {i} for i, c in enumerate(coords) if self.angular(c)}
        for f in self.forces:
            if isinstance(f, CoordinateForce) and f.relative_to is not None:
                a, b = coords.index(f.coordinate), coords.index(f.relative_to)
                merged = group[a] | group[b]
                for i in merged:
                    group[i] = merged
        return sorted({tuple(sorted(g)) for g in group.values()})

    def subtree(self, body: str) -> list[str]:
        """The body and everything hanging from it."""
        out = [body]
        for j in self.joints:
            if j.parent in out:
                out.append(j.child)
        return out

    def without_time_loads(self) -> "Mechanism":
        """The autonomous mechanism: force elements that depend explicitly on time (the
        excitation e(t), monograph eq. 78) removed. Equilibria, linearizations and
        free-vibration tests use it."""
        def timed(f):
            law = f.tension if isinstance(f, PointToPoint) else f.force
            return TIME in sp.sympify(law).free_symbols
        return replace(self, forces=tuple(f for f in self.forces if not timed(f)))

    def substitute(self, values: Mapping[sp.Symbol, float]) -> "Mechanism":
        """The same mechanism with parameter symbols replaced by numbers (placeholders
        and TIME stay symbolic)."""
        subs = dict(values)

        def ev(x):
            if isinstance(x, tuple):
                return tuple(ev(v) for v in x)
            if x is None or isinstance(x, (str, bool)):
                return x
            return sp.sympify(x).xreplace(subs)

        def ev_obj(obj):
            changes = {}
            for name in obj.__dataclass_fields__:
                v = getattr(obj, name)
                if name == "shapes":
                    changes[name] = tuple(ev_obj(s) for s in v)
                elif isinstance(v, (str, bool)):
                    continue
                else:
                    changes[name] = ev(v)
            return replace(obj, **changes)

        def ev_constraint(c):
            if isinstance(c, (LinearCoupling, RollingContact)):
                c = replace(c, coefficients=tuple((n, ev(v)) for n, v in c.coefficients),
                            constant=ev(c.constant))
            if isinstance(c, RollingContact):
                return replace(c, disc_radius=ev(c.disc_radius),
                               track_radius=ev(c.track_radius))
            return c if isinstance(c, LinearCoupling) else ev_obj(c)

        return Mechanism(
            bodies=tuple(ev_obj(b) for b in self.bodies),
            joints=tuple(ev_obj(j) for j in self.joints),
            forces=tuple(ev_obj(f) for f in self.forces),
            gravity=ev(self.gravity),
            constraints=tuple(ev_constraint(c) for c in self.constraints),
            independent=self.independent,
            prescribed=tuple(replace(p, motion=ev(p.motion)) for p in self.prescribed),
            up=ev(self.up),
            branch=tuple((name, ev(e)) for name, e in self.branch),
            redundant=self.redundant,
        )


def compile_law(expr: Expr, args: Sequence[sp.Symbol]) -> Callable[..., float]:
    """Compile a (numeric-parameter) law to a fast scalar function of `args`."""
    expr = sp.sympify(expr)
    extra = expr.free_symbols - set(args)
    if extra:
        raise ValueError(f"law {expr} still has free symbols {sorted(map(str, extra))}")
    return sp.lambdify(args, expr, modules="math")


def rotation(theta: Expr) -> sp.Matrix:
    return sp.Matrix([[sp.cos(theta), -sp.sin(theta)], [sp.sin(theta), sp.cos(theta)]])


def as_column(v: Vec) -> sp.Matrix:
    return sp.Matrix([sp.sympify(v[0]), sp.sympify(v[1])])


def as_column3(v: Vec | Vec3) -> sp.Matrix:
    """A planar or spatial vector as a 3 x 1 column (planar: z = 0)."""
    return sp.Matrix([sp.sympify(c) for c in v] + [sp.Integer(0)] * (3 - len(v)))


def rotation3(axis: Vec3, angle: Expr) -> sp.Matrix:
    """Rotation by `angle` about `axis` (Rodrigues' formula; the axis is normalised)."""
    u = as_column3(axis)
    norm = sp.sqrt(sum(c**2 for c in u))
    u = u / norm
    K = sp.Matrix([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return sp.eye(3) + sp.sin(angle) * K + (1 - sp.cos(angle)) * K * K


def inertia_matrix(body: Body) -> sp.Matrix:
    """The body's central inertia as a 3 x 3 matrix (planar body: diag(0, 0, inertia),
    the in-plane moments playing no part in planar motion)."""
    if body.inertia_tensor is None:
        return sp.diag(0, 0, sp.sympify(body.inertia))
    return sp.Matrix([[sp.sympify(v) for v in row] for row in body.inertia_tensor])


@dataclass(frozen=True)
class Scenario:
    """One run of a mechanism: initial state (expressions of parameters), duration,
    parameter values it sets (the user's --param values win over them), and the checks
    that apply to it. The initial state may be a function of the parameters (as `build`
    gets them) giving the mapping, for a mechanism whose coordinates depend on a
    structural parameter (the N nodes of a chain)."""

    name: str
    q0: Mapping[str, Expr] | Callable[..., Mapping[str, Expr]]
    qd0: Mapping[str, Expr] | Callable[..., Mapping[str, Expr]] = field(default_factory=dict)
    t_end: float = 10.0
    overrides: Mapping[str, float] = field(default_factory=dict)
    checks: tuple[str, ...] = ("trajectory",)
    description: str = ""
