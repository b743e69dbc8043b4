"""Drake backend (pydrake): the continuous-time `MultibodyPlant` integrated by the
`Simulator` with an error-controlled scheme.

Translation (generic over the description, conventions 1-8 of `systems.model`): each
element kind (`plan.ELEMENT_KINDS`) has one builder, registered with `_builds` together
with the `Expression`(s) it declares (contract point 5: the Drake construct of each case
and why it is exact or not), so that the declaration and the code that builds the
element are one thing; the build runs them over the description's elements in order,
each adding its plant calls to a `_Built` (on the shared plan, `plan.EnginePlan`):

- every description body becomes a rigid body whose frame is the description's
  centre-of-mass frame, with its mass and central inertia (the planar moment on z, a
  lamina's half of it on x and y so that the tensor is physical; they cannot act in planar
  motion);
- the joint values are the engine values of `plan.CoordinateMap` (relative angles,
  slides along the unit axis), so q = T v + c maps them back;
- gravity is the plant's gravity field;
- the laws that Drake's own force elements express exactly are those elements (springs,
  dampers, a bushing: `_point_to_point`, `_native_coordinate_laws`). Every other law
  (custom, time loads e(t), springs Drake's elements cannot hold) is evaluated by one
  Python ``LeafSystem`` from the plan's compiled laws at every integrator stage (the
  stage's time and state): coordinate laws as the plant's applied generalized force
  (tau = T^T Q), point-to-point laws as externally applied spatial forces on the two
  bodies (so that they are not booked as forces through the joints). The same system
  imposes the prescribed motions (convention 9), which start on q(0), q'(0), through
  their acceleration (`_force_system`): the coordinates follow q(t) to the integrator's
  accuracy;
- the run is sampled at t = k dt by ``Simulator.AdvanceTo`` (the integrator's own steps
  are error-controlled between samples and end on them);
- reactions: the plant's reaction forces output (the force on the child at its joint
  frame, in that frame) turned to world axes. Drake counts the generalized forces on a
  joint's own coordinate (springs, damping, applied generalized force) as transmitted
  through the joint; along a prismatic joint's slide the coordinate's force elements,
  which the contract's reaction excludes, are taken out (`reactions.joint_reaction`),
  while a prescribed coordinate's actuator stays in, as in the derivation (a coupler
  constraint on a slide, whose force Drake does not report, leaves its reaction NaN);
- linearization: Drake's ``Linearize`` (automatic differentiation) of the plant when no
  Python force system is needed, otherwise central differences of the diagram's own time
  derivatives; the eigenvalues of the 2n x 2n state matrix.

`export` writes the plant calls of the build, recorded as they are made, as a standalone
pydrake script.

A continuous-time plant refuses constraints, and its error control has no event location
for a law that jumps (dry friction). A mechanism with a closure, a coupling or a jumping
law is built on the discrete plant instead (time step dt, Drake's SAP solver): a
first-order step whose velocity update is implicit in the constraint impulses and
explicit in the forces (every law then goes through the LeafSystem, evaluated at the
step's start), whose positions follow the new velocities (semi-implicit Euler). Its
constraints are compliant (declared soft in `EXPRESSIONS`, with the construct of each;
a slot, for which Drake has no constraint, is a slider substitute) and their forces are
not reported (NaN). A discrete step's reactions are those of the step that starts at the
sample. The convergence study sweeps the target accuracy of the continuous plant
(`ACCURACY_SETTING`); its step study runs Runge-Kutta 3 at a fixed step
(`CONVERGENCE_SETTINGS`), and the discrete plant at its step.
"""
from __future__ import annotations

import inspect
from functools import lru_cache
from typing import Mapping, Sequence

import numpy as np

from ..systems.model import (WORLD, CoordinateForce, LinearCoupling, Mechanism, PointOnLine,
                             PointOnPoint, PointToPoint)
from .base import (
    ElementBuilders,
    EXACT,
    RK3_STABILITY,
    SEMI_IMPLICIT_EULER_STABILITY,
    SOFT,
    SUBSTITUTE,
    UNSUPPORTED,
    Backend,
    ErrorControl,
    Expression,
    Linearization,
    BareLoop,
    Samples,
    Stopwatch,
    Scheme,
    Setting,
    central_jacobian,
)
from .plan import (
    CoordinateLaws,
    BODY,
    COORDINATE_FORCE_CUSTOM,
    COORDINATE_FORCE_LINEAR,
    LINEAR_COUPLING,
    MASSLESS_BODY,
    POINT_ON_LINE,
    POINT_ON_POINT,
    POINT_TO_POINT_CUSTOM,
    POINT_TO_POINT_LINEAR,
    PRESCRIBED,
    HINGE_CLOSURE,
    PRISMATIC,
    REVOLUTE,
    ROLLING_CONTACT,
    TIME_LOAD,
    CoordinateMap,
    EnginePlan,
    ForceLaw,
    couples_two_engine_values,
    engine_coupling,
    element_kind,
    elements,
    motions,
    num,
    massive_below,
    unit_axis,
    vec3,
)
from .reactions import outside_forces
from .script_export import literal

#: order of the solution each integrator propagates (Drake's documentation of each class)
_ORDER = {"runge_kutta5": 5, "runge_kutta3": 3, "bogacki_shampine3": 3, "radau3": 3,
          "implicit_euler": 1}
#: integrators whose fixed-step mode has a known stability limit on the imaginary axis
#: (explicit: the 3-stage third-order scheme, R = the cubic Taylor polynomial) or none
#: (implicit); Drake's runge_kutta5 is meant for error control and is not offered fixed
_FIXED_STABILITY = {"runge_kutta3": RK3_STABILITY, "radau3": None, "implicit_euler": None}
#: what the discrete plant's constraints cost (the numbers per mechanism are measured)
SAP_CONSTRAINT = (
    "Drake's constraints are held by its discrete plant (SAP), whose step is first order "
    "and whose constraints are compliant: near-rigid, with a stiffness and a dissipation "
    "time scale tied to the step, so each closure gives a little and dissipates a little "
    "energy at every step; the constraint forces, and the contact forces read from them, "
    "are not reported by the plant.")
#: the metrics a SAP constraint is expected to push beyond the first-order gates: its own
#: force (not reported) and the contact forces read from it, the motion and the energy it
#: carries (its compliance follows the step: the order of convergence stays the step's)
SAP_CONSTRAINT_METRICS = ("*.constraint_*", "*.contact_*", "*.trajectory_*", "*.energy_drift")


@lru_cache(maxsize=None)
def _jumps(expr) -> bool:
    """Whether a law is discontinuous: a sign or step function, or a Piecewise whose
    pieces differ across one of its boundaries (checked on either side of each root of
    the conditions, the law's other arguments at zero)."""
    import sympy as sp

    if expr.atoms(sp.sign, sp.Heaviside):
        return True
    for piecewise in expr.atoms(sp.Piecewise):
        for _, condition in piecewise.args:
            # a condition's relations (a relation's atoms include itself)
            for relation in condition.atoms(sp.core.relational.Relational):
                boundary = relation.lhs - relation.rhs
                for x in boundary.free_symbols:
                    others = {y: 0 for y in expr.free_symbols - {x}}
                    f = sp.lambdify(x, expr.xreplace(others))
                    for root in sp.solve(boundary.xreplace(others), x):
                        if not root.is_real:
                            continue
                        d = 1e-7 * max(1.0, abs(float(root)))
                        left, right = float(f(float(root) - d)), float(f(float(root) + d))
                        if abs(left - right) > 1e-4 * max(1.0, abs(left), abs(right)):
                            return True
    return False


def _slider_mass(mech: Mechanism, slot: PointOnLine) -> float:
    """The point mass a slot's slider takes from the pin's body at the pin (`EXPRESSIONS`).
    SAP regularizes a constraint by the inverse masses it joins, so a light slider makes
    the pin's constraint soft; the pin's body keeps a physical inertia (in-plane central
    moments izz/2 and izz/2 - m_s m |p|^2 / (m - m_s) >= 0 for a pin at p from its centre
    of mass: m_s / (m - m_s) <= rho = izz / (2 m |p|^2)). Half the largest share that
    allows, at most half the mass, divided among the body's slots; 0 where it has none
    to lend (massless, the world, a point mass pinned off its centre)."""
    if slot.body == WORLD:
        return 0.0
    body = mech.body(slot.body)
    mass, izz = num(body.mass), num(body.inertia)
    pin = np.hypot(num(slot.point[0]), num(slot.point[1]))
    if not mass > 0:
        return 0.0
    rho = izz / (2 * mass * pin ** 2) if pin > 0 else np.inf
    share = 0.5 if rho == np.inf else min(0.5, 0.5 * rho / (1 + rho))
    slots = sum(1 for c in mech.constraints
                if element_kind(c) == POINT_ON_LINE and c.body == body.name)
    return share * mass / slots


def _can_lend(mech: Mechanism, slot: PointOnLine) -> bool:
    """Whether the pin's body can lend the slider its point mass and keep a physical
    inertia (in-plane central moments non-negative, checked on the body as built)."""
    if not _slider_mass(mech, slot) > 0:
        return False
    mass, com, unit = _inertia(mech, mech.body(slot.body))
    c = np.asarray(com)
    central = (np.array([[unit[0], unit[3]], [unit[3], unit[1]]])
               - (c @ c * np.eye(3) - np.outer(c, c))[:2, :2])
    return bool(np.min(np.linalg.eigvalsh(central)) >= 0)


def _inertia(mech: Mechanism, body) -> tuple[float, list, tuple]:
    """(mass, centre of mass in the body frame, unit inertia about the frame: Ixx, Iyy,
    Izz, Ixy, Ixz, Iyz) of a body as built: its planar moment on z and half of it on x and
    y (a lamina), less the point masses it lends at the pins of its slots (`_slider_mass`)."""
    mass, izz = num(body.mass), num(body.inertia)
    if not mass:  # Drake stores the inertia per unit mass; a massless body has none
        return 0.0, [0.0] * 3, (0.0,) * 6
    tensor = np.diag([izz / 2, izz / 2, izz])
    first_moment = np.zeros(3)
    kept = mass
    for c in mech.constraints:
        if element_kind(c) == POINT_ON_LINE and c.body == body.name:
            lent, pin = _slider_mass(mech, c), np.array([num(c.point[0]), num(c.point[1]), 0.0])
            tensor -= lent * (pin @ pin * np.eye(3) - np.outer(pin, pin))
            first_moment -= lent * pin
            kept -= lent
    unit = tensor / kept
    return kept, list(first_moment / kept), (unit[0, 0], unit[1, 1], unit[2, 2], unit[0, 1],
                                             0.0, 0.0)


def _discrete(mech: Mechanism, cfg: Mapping) -> bool:
    """Whether the mechanism is built on the discrete plant: asked for, or needed (a
    closure or coupling, which a continuous plant refuses; a law that jumps, which its
    error control cannot cross)."""
    return (cfg["plant"] == "discrete" or bool(mech.constraints)
            or any(element_kind(f) in (COORDINATE_FORCE_CUSTOM, POINT_TO_POINT_CUSTOM,
                                       TIME_LOAD)
                   and _jumps(ForceLaw.of(f).expr) for f in mech.forces))


class _Built(EnginePlan):
    """A diagram built from a mechanism on its shared plan (`plan.EnginePlan`: the
    mechanism, the settings, the coordinate map): what each element's builder adds to
    (every plant call through the recorder, which `export` writes), then what the force
    system and the read-out need."""

    def __init__(self, mech: Mechanism, cfg: Mapping, rec: "_Recorder", plant,
                 discrete: bool) -> None:
        super().__init__(mech, cfg)
        self.rec, self.plant = rec, plant
        rec("", plant.mutable_gravity_field().set_gravity_vector,
            "plant.mutable_gravity_field().set_gravity_vector", list(self.gravity_vector))
        #: laws as Drake's own elements where they express them (`native_elements`); on
        #: the discrete plant every law is explicit, as semi-implicit Euler's gates assume:
        #: its solver would take the joints' damping implicitly
        self.native = bool(cfg["native_elements"]) and not discrete
        #: per native coordinate law (by name): (its joint, stiffness, nominal value, damping)
        self.springs = _native_coordinate_laws(mech, self.map) if self.native else {}
        #: per description joint: the viscous damping its native coordinate laws give it
        self.damping = [sum((d for j, _, _, d in self.springs.values() if j == i), 0.0)
                        for i in range(self.n)]
        #: description body (and WORLD) -> Drake body
        self.bodies = {WORLD: rec("world", plant.world_body, "plant.world_body")}
        self.joints: list = []       # Drake joints, in description order
        self.python_laws: list = []  # CoordinateForce laws of the LeafSystem
        self.python_p2p: list = []   # PointToPoint laws of the LeafSystem
        self.driven: list = []       # motions the LeafSystem imposes (their builders')
        #: per slot: (its slider joint, the pin's body, the pin point, the slot's frame, the
        #: slot's unit direction), for the slider's initial state (`_place_slider`)
        self.slots: list = []
        self.build(_BUILDERS)
        #: whether a Python LeafSystem computes forces
        self.python_forces = bool(self.python_laws or self.python_p2p or self.driven)
        self.diagram = None
        self.positions: np.ndarray | None = None   # plant position index of each joint
        self.velocities: np.ndarray | None = None  # plant velocity index of each joint
        #: where the description's joints sit in the plant's state vector (q, then v)
        self.state_index: np.ndarray | None = None
        self.forces = None                         # the Python force system, if any

    def frame(self, body: str, name: str, anchor, angle: float):
        """A frame on `body` at `anchor` (its frame's coordinates), turned by `angle`."""
        from pydrake.math import RigidTransform, RotationMatrix
        from pydrake.multibody.tree import FixedOffsetFrame

        rec = self.rec
        pose = rec(None, RigidTransform, "RigidTransform",
                   rec(None, RotationMatrix.MakeZRotation, "RotationMatrix.MakeZRotation",
                       angle), vec3(anchor))
        parent = rec(None, self.bodies[body].body_frame,
                     f"{rec.code(self.bodies[body])}.body_frame")
        return rec(f"frame_{name}", self.plant.AddFrame, "plant.AddFrame",
                   rec(None, FixedOffsetFrame, "FixedOffsetFrame", name, parent, pose))


def _native_coordinate_laws(mech: Mechanism, cmap: CoordinateMap
                            ) -> dict[str, tuple[int, float, float, float]]:
    """Per coordinate law that Drake's own elements hold (by name): (joint, stiffness,
    nominal value, damping). A law goes to them when it is linear on one engine joint
    value v_j (`CoordinateMap.joint_spring`: tau_j = force - k v_j - d v_j'), a spring of
    stiffness k >= 0 and nominal value force / k, and a damper d >= 0. The joints take
    the damping when they are built, so it is known before the laws' own builders run."""
    held = {}
    for kind, f in elements(mech):
        if kind != COORDINATE_FORCE_LINEAR:
            continue
        spring = cmap.joint_spring(f.weights(mech.coordinates), ForceLaw.of(f).linear)
        if spring is None:
            continue
        j, force, k, d = spring
        if k >= 0 and d >= 0 and (k > 0 or force == 0):
            held[f.name] = (j, k, force / k if k > 0 else 0.0, d)
    return held


#: element kind -> its builder (taking the `_Built` and the element), with its expressions
_BUILDERS = ElementBuilders()
_builds = _BUILDERS.builds


@_builds(BODY, Expression(EXACT, "a rigid body with its mass and central inertia (zero "
                                 "central inertia accepted: point masses are exact)"))
@_builds(
    MASSLESS_BODY,
    Expression(EXACT, "a zero-mass body: the articulated inertia stays regular while a "
                      "massive descendant carries its coordinates",
               when="a massive body below it", applies=massive_below),
    Expression(UNSUPPORTED, "it carries no mass and no massive body below it: the plant's "
                            "mass matrix would be singular",
               when="only massless bodies below it"))
def _body(build: _Built, body) -> None:
    from pydrake.multibody.tree import SpatialInertia, UnitInertia

    rec = build.rec
    mass, com, unit = _inertia(build.mech, body)
    build.bodies[body.name] = rec(
        f"body_{len(build.bodies)}", build.plant.AddRigidBody, "plant.AddRigidBody",
        body.name, rec(None, SpatialInertia, "SpatialInertia", mass, com,
                       rec(None, UnitInertia, "UnitInertia", *unit)))


@_builds(REVOLUTE, Expression(EXACT, "RevoluteJoint about z between frames at the anchors "
                                     "(the parent's turned by the angle offset)"))
@_builds(PRISMATIC, Expression(EXACT, "PrismaticJoint along the unit axis"))
def _joint(build: _Built, joint) -> None:
    """A description joint into the plant, in description order (a hinge's frame on the
    parent turned by the angle offset, a slide's frame on the child by minus it)."""
    from pydrake.multibody.tree import PrismaticJoint, RevoluteJoint

    hinge, offset = element_kind(joint) == REVOLUTE, num(joint.angle_offset)
    jp = build.frame(joint.parent, f"{joint.name}_on_parent", joint.parent_anchor,
                     offset if hinge else 0.0)
    jc = build.frame(joint.child, f"{joint.name}_on_child", joint.child_anchor,
                     0.0 if hinge else -offset)
    kind, axis = ((RevoluteJoint, [0.0, 0.0, 1.0]) if hinge
                  else (PrismaticJoint, np.array(unit_axis(joint))))
    build.joints.append(build.rec(
        f"joint_{len(build.joints)}", build.plant.AddJoint, "plant.AddJoint",
        build.rec(None, kind, kind.__name__, joint.name, jp, jc, axis,
                  damping=build.damping[len(build.joints)])))


def _point_to_point(build: _Built, f: PointToPoint) -> None:
    """Drake's own spring element where it expresses the law exactly, a spring of
    tension k (L - L0) + c L' (`ForceLaw.tendon_spring`) with k > 0 and L0 > 0
    (LinearSpringDamper) or L0 = 0 and c = 0 (LinearBushingRollPitchYaw), else the law
    in the LeafSystem; a force between two points of one body is internal."""
    from pydrake.multibody.tree import LinearBushingRollPitchYaw, LinearSpringDamper

    if f.body_a == f.body_b:
        return
    spring = ForceLaw.of(f).tendon_spring if build.native else None
    if spring is None or spring[0] == 0 or (spring[1] == 0 and spring[2] != 0):
        build.python_p2p.append(f)
        return
    rec = build.rec
    stiffness, free_length, damper = spring
    if free_length == 0:
        # a spring of zero free length pulls each point towards the other with k times
        # their separation: a bushing with isotropic force stiffness and no torque, whose
        # force acts on the line between its frames' origins
        element = rec(None, LinearBushingRollPitchYaw, "LinearBushingRollPitchYaw",
                      build.frame(f.body_a, f"{f.name}_a", f.point_a, 0.0),
                      build.frame(f.body_b, f"{f.name}_b", f.point_b, 0.0),
                      [0.0] * 3, [0.0] * 3, [stiffness] * 3, [0.0] * 3)
    else:
        element = rec(None, LinearSpringDamper, "LinearSpringDamper",
                      build.bodies[f.body_a], vec3(f.point_a), build.bodies[f.body_b],
                      vec3(f.point_b), free_length, stiffness, damper)
    rec("", build.plant.AddForceElement, "plant.AddForceElement", element)


def _coordinate_force(build: _Built, f: CoordinateForce) -> None:
    """Drake's joint spring (its damping went to the joint) where the law is held
    natively (`_native_coordinate_laws`), else the law in the LeafSystem."""
    from pydrake.multibody.tree import PrismaticSpring, RevoluteSpring

    if f.name not in build.springs:
        build.python_laws.append(f)
        return
    j, stiffness, nominal, _ = build.springs[f.name]
    if stiffness > 0:
        spring = (RevoluteSpring if element_kind(build.mech.joints[j]) == REVOLUTE
                  else PrismaticSpring)
        build.rec("", build.plant.AddForceElement, "plant.AddForceElement",
                  build.rec(None, spring, spring.__name__, build.joints[j], nominal, stiffness))


_builds(POINT_TO_POINT_LINEAR,
        Expression(EXACT, "LinearSpringDamper where the law is a spring of positive free "
                          "length with a non-negative damper, an isotropic "
                          "LinearBushingRollPitchYaw without torque for a spring of zero free "
                          "length, otherwise the law as externally applied spatial forces "
                          "from a LeafSystem at every integrator stage"))(_point_to_point)
_builds(POINT_TO_POINT_CUSTOM,
        Expression(EXACT, "externally applied spatial forces on both bodies from a "
                          "LeafSystem, evaluated at every integrator stage (at the start of "
                          "each step where the plant is discrete, as for a law that jumps: "
                          "the error control has no event location)"))(_point_to_point)
_builds(COORDINATE_FORCE_LINEAR,
        Expression(EXACT, "RevoluteSpring or PrismaticSpring and the joint's damping where "
                          "the law acts on one joint value with non-negative stiffness and "
                          "damping, otherwise the plant's applied generalized "
                          "force"))(_coordinate_force)
_builds(COORDINATE_FORCE_CUSTOM,
        Expression(EXACT, "the plant's applied generalized force from a LeafSystem, "
                          "evaluated at every integrator stage",
                   when="the law is continuous",
                   applies=lambda mech, law: not _jumps(ForceLaw.of(law).expr)),
        Expression(EXACT, "the plant's applied generalized force from a LeafSystem, "
                          "evaluated at the start of each step of the discrete plant (the "
                          "error control cannot cross a jump: it has no event location)",
                   when="the law jumps (dry friction)"))(_coordinate_force)
_BUILDERS.builds_time_load(Expression(EXACT, "a LeafSystem evaluated at every integrator stage "
                                             "with the stage time"))


@_builds(POINT_ON_POINT, Expression(SOFT, "AddBallConstraint between the two points on the "
                                          "discrete plant (its out-of-plane row is void: "
                                          "every body moves in the plane)",
                                    expected_failures=SAP_CONSTRAINT_METRICS,
                                    reason=SAP_CONSTRAINT))
def _point_on_point(build: _Built, c: PointOnPoint) -> None:
    build.rec("", build.plant.AddBallConstraint, "plant.AddBallConstraint",
              build.bodies[c.body_a], vec3(c.point_a), build.bodies[c.body_b], vec3(c.point_b))


@_builds(
    POINT_ON_LINE,
    Expression(SUBSTITUTE, "no point-on-line constraint: a slider body on a PrismaticJoint "
                           "along the slot, held to the pin by AddBallConstraint on the "
                           "discrete plant; it carries a point mass taken out of the pin's "
                           "body at the pin (exact while the constraints hold: the pin point "
                           "carries it either way)",
               when="the pin's body can lend the slider a point mass at the pin",
               applies=lambda mech, slot: _can_lend(mech, slot),
               expected_failures=SAP_CONSTRAINT_METRICS, reason=SAP_CONSTRAINT),
    Expression(UNSUPPORTED, "Drake has no point-on-line constraint, and the pin's body "
                            "cannot lend the substitute slider a point mass at the pin "
                            "(massless, the world, or too little inertia about the pin): a "
                            "slider without mass makes the plant's mass matrix singular",
               when="the pin's body cannot lend it"))
def _point_on_line(build: _Built, c: PointOnLine) -> None:
    """The slot's slider, held to the pin, with the point mass its body lends (`_slider_mass`)."""
    from pydrake.multibody.tree import PrismaticJoint, SpatialInertia, UnitInertia

    rec, plant = build.rec, build.plant
    slider = rec(f"body_{len(build.bodies) + len(build.slots)}", plant.AddRigidBody,
                 "plant.AddRigidBody", f"{c.name}_slider",
                 rec(None, SpatialInertia, "SpatialInertia", _slider_mass(build.mech, c),
                     [0.0] * 3, rec(None, UnitInertia, "UnitInertia", 0.0, 0.0, 0.0)))
    axis = np.array([num(c.direction[0]), num(c.direction[1]), 0.0])
    axis /= np.linalg.norm(axis)
    line = build.frame(c.line_body, f"{c.name}_line", c.line_point, 0.0)
    pin = [num(c.point[0]), num(c.point[1]), 0.0]
    slide = rec(f"slider_{len(build.slots)}", plant.AddJoint, "plant.AddJoint",
                rec(None, PrismaticJoint, "PrismaticJoint", f"{c.name}_slide", line,
                    rec(None, slider.body_frame, f"{rec.code(slider)}.body_frame"), axis))
    rec("", plant.AddBallConstraint, "plant.AddBallConstraint", build.bodies[c.body],
        pin, slider, [0.0] * 3)
    build.slots.append((slide, build.bodies[c.body], np.array(pin), line, axis))


@_builds(
    LINEAR_COUPLING,
    Expression(SOFT, "AddCouplerConstraint v0 = rho v1 + offset on the discrete plant, the "
                     "coupling written on the engine joint values",
               when="it relates two joint values",
               applies=couples_two_engine_values,
               expected_failures=SAP_CONSTRAINT_METRICS, reason=SAP_CONSTRAINT),
    Expression(UNSUPPORTED, "Drake's coupler constraint relates two joints; this coupling "
                            "involves one or more than two joint values",
               when="it relates one or more than two joint values"))
def _linear_coupling(build: _Built, c: LinearCoupling) -> None:
    row, constant = engine_coupling(build.mech, c)
    i0, i1 = (int(i) for i in np.flatnonzero(row))
    build.rec("", build.plant.AddCouplerConstraint, "plant.AddCouplerConstraint",
              build.joints[i0], build.joints[i1], float(-row[i1] / row[i0]),
              constant / float(row[i0]))


_BUILDERS.refuses(ROLLING_CONTACT, "no contact geometry is built: the continuous plant's "
                                   "point contact is a penalty (compliant) model", "drake")


@_builds(PRESCRIBED, Expression(EXACT, "the acceleration imposed by the LeafSystem's applied "
                                       "generalized force at every integrator stage (from the "
                                       "plant's mass matrix and its other generalized forces "
                                       "at the stage's state and time); that force is the "
                                       "actuator force"))
def _prescribed(build: _Built, p) -> None:
    # nothing in the plant: the LeafSystem imposes it
    build.driven += [m for m in motions(build.mech) if m.element is p]


_BUILDERS.refuses(HINGE_CLOSURE, "the build is planar: a spatial closed loop has no "
                                  "constraint in it", "drake")


#: per element kind, the expression(s) its registered builder makes, in the kinds' order
EXPRESSIONS = _BUILDERS.declared()


class DrakeBackend(Backend):
    id = "drake"
    SETTINGS = {
        "integrator": Setting(
            "runge_kutta5", tuple(_ORDER),
            "Drake's Simulator integrates with runge_kutta3; runge_kutta5 (Dormand-Prince, "
            "fifth order with a fourth-order error estimate) is its most accurate explicit "
            "scheme. Also offered: runge_kutta3, bogacki_shampine3, radau3, implicit_euler "
            "(integrator_order reports the order of the one used). Engine default: Drake's "
            "SimulatorConfig (systems/analysis/simulator_config.h), integration_scheme.",
            engine_default="runge_kutta3"),
        "target_accuracy": Setting(
            1e-10, float,
            "Drake's default target accuracy replaced by 1e-10: the local error the "
            "integrator keeps each step below (unit weights: rad, m, rad/s, m/s); tight, so "
            "that the comparison sees Drake's model of the mechanism more than its "
            "integration error. The run records "
            "it with the number of steps taken (the error-controlled trajectory gate follows "
            "from both). Engine default: Drake's SimulatorConfig "
            "(systems/analysis/simulator_config.h), accuracy 1e-4.",
            engine_default=1e-4),
        "max_step": Setting(
            None, (float, type(None)),
            "Drake's largest step capped at the sampling step dt (null); a number caps it "
            "further. Engine default: Drake's SimulatorConfig "
            "(systems/analysis/simulator_config.h), max_step_size 0.1 s.",
            engine_default=0.1),
        "fixed_step": Setting(
            False, bool,
            "Drake default (error control) kept; True runs the integrator at the fixed "
            "step dt (the knob of the convergence study by steps), for runge_kutta3, "
            "radau3 and implicit_euler."),
        "plant": Setting(
            "auto", ("auto", "discrete"),
            "Backend choice: auto builds the continuous-time plant (error-controlled) "
            "unless the mechanism has a closure, a coupling or a jumping law, which need "
            "the discrete plant (time step dt, the SAP solver); discrete builds every "
            "mechanism on it."),
        "sap_near_rigid_threshold": Setting(
            1.0, float,
            "Drake's default (1.0) kept: the SAP solver's near-rigid threshold beta, which "
            "caps a constraint's stiffness at the value the step resolves (smaller: stiffer, "
            "worse conditioned). Discrete plant only."),
        "native_elements": Setting(
            True, bool,
            "Backend choice: springs and dampers that Drake's own elements express exactly "
            "(LinearSpringDamper, RevoluteSpring, PrismaticSpring, joint damping) use them; "
            "False sends every law through the Python force system (same model, slower). "
            "The discrete plant always does: its solver takes the joints' damping "
            "implicitly, a step other than the semi-implicit Euler its gates derive."),
        "linearization_step": Setting(
            1e-6, float,
            "linearize() with a Python force system: step of the central differences of "
            "the diagram's time derivatives (truncation O(h^2), round-off O(u/h) with u the "
            "machine epsilon: both small at the default step); without "
            "one Drake's Linearize differentiates automatically and this is unused."),
    }

    #: the step study (`mbfidelity convergence --knob step`): Runge-Kutta 3 at a fixed step dt
    CONVERGENCE_SETTINGS = {"integrator": "runge_kutta3", "fixed_step": True}
    #: the work-precision study's knob: the error-controlled default at a swept accuracy
    ACCURACY_SETTING = "target_accuracy"

    # --- identity --------------------------------------------------------------------------
    ENGINE_MODULES = ('pydrake.multibody.plant', 'pydrake.systems.analysis')
    ENGINE_DISTRIBUTION = "drake"

    # --- support ---------------------------------------------------------------------------
    EXPRESSIONS = EXPRESSIONS

    def accuracy_knob(self, mechanism: Mechanism, settings: Mapping | None = None) -> str:
        return "" if _discrete(mechanism, self.resolve_settings(settings)) else \
            self.ACCURACY_SETTING

    # --- the scheme --------------------------------------------------------------------------
    def scheme(self, mechanism: Mechanism, settings: Mapping | None = None) -> Scheme:
        cfg = self.resolve_settings(settings)
        name = str(cfg["integrator"])
        if _discrete(mechanism, cfg):
            return Scheme("discrete plant, SAP (semi-implicit Euler)", 1,
                          SEMI_IMPLICIT_EULER_STABILITY)
        if cfg["fixed_step"]:
            if name not in _FIXED_STABILITY:
                raise ValueError(f"drake fixed_step runs {', '.join(_FIXED_STABILITY)}; "
                                 f"got {name!r}")
            return Scheme(f"{name} (fixed step)", _ORDER[name], _FIXED_STABILITY[name])
        # an error-controlled scheme shrinks its step until the error estimate, and with
        # it the growth of every mode, is small: no stability limit at the sampling step
        return Scheme(f"{name} (error-controlled, accuracy {cfg['target_accuracy']:g})",
                      _ORDER[name], None)

    # --- building ----------------------------------------------------------------------------
    def _build(self, mech: Mechanism, cfg: dict, dt: float) -> _Built:
        """The diagram (a discrete plant of step `dt` where `_discrete`): each element
        built by the builder registered for its kind; every plant call goes through the
        build's recorder (`export` writes them)."""
        from pydrake.multibody.plant import DiscreteContactApproximation, MultibodyPlant
        from pydrake.systems.framework import DiagramBuilder

        self.check_support(mech)
        rec = _Recorder()
        builder = DiagramBuilder()
        discrete = _discrete(mech, cfg)
        plant = rec("plant", builder.AddSystem, "builder.AddSystem",
                    rec(None, MultibodyPlant, "MultibodyPlant",
                        time_step=float(dt) if discrete else 0.0))
        if discrete:
            rec.names[id(DiscreteContactApproximation.kSap)] = "DiscreteContactApproximation.kSap"
            rec("", plant.set_discrete_contact_approximation,
                "plant.set_discrete_contact_approximation", DiscreteContactApproximation.kSap)
            rec("", plant.set_sap_near_rigid_threshold, "plant.set_sap_near_rigid_threshold",
                float(cfg["sap_near_rigid_threshold"]))
        built = _Built(mech, cfg, rec, plant, discrete)
        plant.Finalize()
        built.positions = np.array([j.position_start() for j in built.joints], dtype=int)
        built.velocities = np.array([j.velocity_start() for j in built.joints], dtype=int)
        built.state_index = np.concatenate([built.positions,
                                            plant.num_positions() + built.velocities])
        if built.python_forces:
            built.forces = builder.AddSystem(_force_system(built))
            builder.Connect(plant.get_state_output_port(), built.forces.get_input_port(0))
            builder.Connect(built.forces.get_output_port(0),
                            plant.get_applied_generalized_force_input_port())
            builder.Connect(built.forces.get_output_port(1),
                            plant.get_applied_spatial_force_input_port())
        built.diagram = builder.Build()
        return built

    def export(self, mechanism: Mechanism, coordinates: Sequence[str],
               initial_states: Mapping[str, tuple[np.ndarray, np.ndarray]],
               settings: Mapping | None = None, dt: float = 1e-3) -> tuple[str, list[str]]:
        """(a standalone pydrake script, what it does not reproduce): the plant calls of
        `simulate`'s build as recorded, the first scenario's initial state, the same
        integrator, one second advanced sample by sample, and the description's
        coordinates at the end. The Python force system (laws Drake's own elements do not
        hold) cannot be written out: its laws are listed."""
        name, q0, qd0 = self.export_start(initial_states)
        cfg = self.resolve_settings(settings)
        built = self._build(mechanism, cfg, dt)
        recorder = built.rec
        accuracy = ("integrator.set_fixed_step_mode(True)" if cfg["fixed_step"] else
                    f"integrator.set_target_accuracy({float(cfg['target_accuracy'])!r})")
        max_step = dt if cfg["max_step"] is None else min(dt, float(cfg["max_step"]))
        text = "\n".join([
            f'"""{self.script_title("Drake", name, cfg)}\n"""',
            "import numpy as np",
            "from pydrake.math import RigidTransform, RotationMatrix",
            "from pydrake.multibody.plant import DiscreteContactApproximation, MultibodyPlant",
            "from pydrake.multibody.tree import (FixedOffsetFrame, LinearBushingRollPitchYaw, "
            "LinearSpringDamper,",
            "                                    PrismaticJoint, PrismaticSpring, RevoluteJoint, "
            "RevoluteSpring,",
            "                                    SpatialInertia, UnitInertia)",
            "from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator",
            "from pydrake.systems.framework import DiagramBuilder",
            "",
            "builder = DiagramBuilder()",
            *recorder.lines,
            "plant.Finalize()",
            "diagram = builder.Build()",
            "simulator = Simulator(diagram)",
            "context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())",
            "joints = [" + ", ".join(f"joint_{i}" for i in range(len(built.joints))) + "]",
            f"v0 = {[float(v) for v in built.map.engine_values(q0)]!r}",
            f"vd0 = {[float(v) for v in built.map.A @ np.asarray(qd0, dtype=float)]!r}",
            "positions, velocities = np.zeros(plant.num_positions()), "
            "np.zeros(plant.num_velocities())",
            "for joint, value, rate in zip(joints, v0, vd0):  # the engine's joint values",
            "    positions[joint.position_start()] = value",
            "    velocities[joint.velocity_start()] = rate",
            "plant.SetPositions(context, positions)",
            "plant.SetVelocities(context, velocities)",
            *([f"{inspect.getsource(_place_slider)}"] if built.slots else []),
            *[f"_place_slider(plant, context, {recorder.code(slide)}, {recorder.code(body)}, "
              f"{recorder.code(pin)}, {recorder.code(line)}, np.array({recorder.code(axis)}))"
              for slide, body, pin, line, axis in built.slots],
            f"integrator = ResetIntegratorFromFlags(simulator, {cfg['integrator']!r}, "
            f"{max_step!r})",
            accuracy,
            "simulator.Initialize()",
            f"dt = {dt!r}",
            "for k in range(1, int(round(1.0 / dt)) + 1):",
            "    simulator.AdvanceTo(k * dt)",
            "v = np.array([plant.GetPositions(context)[j.position_start()] for j in joints])",
            f"T = np.array({built.map.T.tolist()!r})",
            f"c = np.array({built.map.c.tolist()!r})",
            f"print(dict(zip({list(coordinates)!r}, (T @ v + c).tolist())))",
            ""])
        python = [f.name for f in mechanism.forces
                  if any(f is w for w in built.python_p2p + built.python_laws)]
        return text, ([f"the force laws computed by the Python force system: "
                       f"{', '.join(python)}"] if python else [])

    # --- running -----------------------------------------------------------------------------
    def _simulator(self, built: _Built, q0: np.ndarray, qd0: np.ndarray, dt: float, cfg: dict):
        from pydrake.systems.analysis import ResetIntegratorFromFlags, Simulator

        simulator = Simulator(built.diagram)
        context = simulator.get_mutable_context()
        plant_context = built.plant.GetMyMutableContextFromRoot(context)
        x0 = np.zeros(built.plant.num_positions() + built.plant.num_velocities())
        x0[built.state_index] = np.concatenate([built.map.engine_values(q0),
                                                built.map.A @ np.asarray(qd0, dtype=float)])
        built.plant.SetPositionsAndVelocities(plant_context, x0)
        for slide, body, pin, line, axis in built.slots:
            _place_slider(built.plant, plant_context, slide, body, pin, line, axis)
        max_step = dt if cfg["max_step"] is None else min(dt, float(cfg["max_step"]))
        integrator = ResetIntegratorFromFlags(simulator, str(cfg["integrator"]), max_step)
        if cfg["fixed_step"]:
            if str(cfg["integrator"]) not in _FIXED_STABILITY:
                raise ValueError(f"drake fixed_step runs {', '.join(_FIXED_STABILITY)}")
            integrator.set_fixed_step_mode(True)
        else:
            integrator.set_target_accuracy(float(cfg["target_accuracy"]))
        simulator.Initialize()
        return simulator, integrator, plant_context

    def _simulate_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                       steps: int, dt: float, cfg: dict,
                       reaction_joints: tuple[str, ...]) -> Samples:
        built = self._build(mechanism, cfg, dt)
        simulator, integrator, plant_context = self._simulator(built, q0, qd0, dt, cfg)
        plant = built.plant
        state = np.empty((steps + 2, 2 * built.n))
        discrete = _discrete(mechanism, cfg)
        wanted = [(name, mechanism.joints.index(mechanism.joint(name))) for name in reaction_joints]
        forces = {name: np.empty((steps + 2, 2)) for name, _ in wanted}
        driven = [p.name for p in mechanism.prescribed]
        actuators = np.empty((steps + 2, len(driven)))

        def read(k: int) -> None:
            x = plant.GetPositionsAndVelocities(plant_context)
            state[k] = x[built.state_index]
            if driven:
                actuators[k] = built.forces.actuators(x, k * dt, built.forces._laws(x, k * dt))
            if wanted:
                # a discrete plant reports the reactions of the step just taken, which the
                # state of its start (sample k - 1, turned as there) determines
                reaction = plant.get_reaction_forces_output_port().Eval(plant_context)
                for name, i in wanted:
                    joint = built.joints[i]
                    force = reaction[int(joint.index())].translational()
                    turn = joint.frame_on_child().CalcRotationMatrixInWorld(
                        plant_context).matrix()
                    if not discrete:
                        forces[name][k] = (turn @ force)[:2]
                    elif k > 0:
                        forces[name][k - 1] = (turns[name] @ force)[:2]
                    turns[name] = turn

        turns: dict[str, np.ndarray] = {}
        read(0)
        # the integrator's steps end on each sample; reactions need the accelerations
        # there, so every read-out happens as the run passes its sample
        with Stopwatch() as clock:
            for k in range(1, steps + 1):
                simulator.AdvanceTo(k * dt)
                read(k)
        if discrete and wanted:  # the last sample's reactions: one step beyond the run
            simulator.AdvanceTo((steps + 1) * dt)
            read(steps + 1)
        state, actuators = state[:steps + 1], actuators[:steps + 1]
        forces = {name: f[:steps + 1] for name, f in forces.items()}
        q = built.map.coordinates(state[:, :built.n])
        qd = built.map.rates(state[:, built.n:])
        actuator_forces = {name: actuators[:, k] for k, name in enumerate(driven)}
        control = None if cfg["fixed_step"] or discrete else ErrorControl(
            float(integrator.get_target_accuracy()), int(integrator.get_num_steps_taken()))
        # Drake reports no constraint forces (`EXPRESSIONS`)
        closures = {c.name: np.full((steps + 1, 1 if element_kind(c) == LINEAR_COUPLING else 2),
                                    np.nan) for c in mechanism.constraints}
        # Drake books the generalized forces on a joint's own coordinate (its laws, a
        # coupler constraint: unknown, so NaN on a slide it involves) as transmitted
        # through it; the ball constraints and point-to-point forces act on the bodies
        return Samples(q, qd, clock, constraint_forces=closures,
                       actuator_forces=actuator_forces, error_control=control,
                       transmitted=forces, coupling_forces=outside_forces(
                           mechanism, {}, closures)["coupling_forces"])

    def _bare_loop_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                        steps: int, dt: float, cfg: dict) -> BareLoop:
        """The diagram of `simulate`, advanced to the same sample times, nothing read."""
        built = self._build(mechanism, cfg, dt)
        simulator, _, plant_context = self._simulator(built, q0, qd0, dt, cfg)
        with Stopwatch() as clock:
            for k in range(1, steps + 1):
                simulator.AdvanceTo(k * dt)
        x = built.plant.GetPositionsAndVelocities(plant_context)[built.state_index]
        return BareLoop.mapped(clock.cpu, built.map, x[:built.n], x[built.n:])

    # --- linearization -------------------------------------------------------------------------
    def linearize(self, mechanism: Mechanism, q_eq: np.ndarray,
                  settings: Mapping | None = None, dt: float = 1e-3) -> Linearization | None:
        frame = self.linearization_frame(mechanism, settings)
        # a discrete plant's constraints are SAP's, whose solve is not differentiated here
        if frame is None or _discrete(mechanism, frame[0]):
            return None
        cfg, mech = frame
        built = self._build(mech, cfg, dt)
        context = built.diagram.CreateDefaultContext()
        plant_context = built.plant.GetMyMutableContextFromRoot(context)
        x_eq = np.zeros(built.plant.num_positions() + built.plant.num_velocities())
        x_eq[built.positions] = built.map.engine_values(q_eq)  # at rest
        built.plant.SetPositionsAndVelocities(plant_context, x_eq)
        if not built.python_forces:
            from pydrake.systems.framework import InputPortSelection, OutputPortSelection
            from pydrake.systems.primitives import Linearize

            linear = Linearize(built.plant, plant_context,
                               input_port_index=InputPortSelection.kNoInput,
                               output_port_index=OutputPortSelection.kNoOutput)
            A = np.asarray(linear.A())
            how = "drake Linearize of the MultibodyPlant (automatic differentiation)"
        else:
            derivatives = built.diagram.AllocateTimeDerivatives()

            def rates(x: np.ndarray) -> np.ndarray:
                context.SetContinuousState(x)
                built.diagram.CalcTimeDerivatives(context, derivatives)
                return derivatives.CopyToVector()

            A = central_jacobian(rates, context.get_continuous_state_vector().CopyToVector(),
                                 float(cfg["linearization_step"]))
            how = ("central differences of the Drake diagram's time derivatives "
                   "(CalcTimeDerivatives; a Python force system has no automatic "
                   "differentiation)")
        eig = np.linalg.eigvals(A)
        return Linearization(eigenvalues=eig[np.argsort(eig.imag)], method=how,
                             extra={"coordinates": "the plant's joint values and rates "
                                                   "(eigenvalues are invariant)"})


def _place_slider(plant, context, slide, body, pin, line, axis) -> None:
    """A slot's slider under its pin, moving with it along the slot (the pin's state
    already set)."""
    from pydrake.multibody.tree import JacobianWrtVariable

    at = plant.CalcPointsPositions(context, body.body_frame(), pin, line)[:, 0]
    J = plant.CalcJacobianTranslationalVelocity(context, JacobianWrtVariable.kV,
                                                body.body_frame(), pin, line, line)
    slide.set_translation(context, float(at @ axis))
    slide.set_translation_rate(context, float(J @ plant.GetVelocities(context) @ axis))


class _Recorder:
    """Calls into pydrake, each also written as a line of Python (`export`): a call given
    a variable name becomes ``name = text(args)``, one given "" a statement, one given
    None an expression that later lines inline. The objects are kept, so that their ids
    stay theirs."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.names: dict[int, str] = {}
        self.kept: list = []

    def code(self, value) -> str:
        """A recorded object by its name, a value as a literal (`script_export.literal`)."""
        return self.names[id(value)] if id(value) in self.names else literal(value)

    def __call__(self, var: str | None, fn, text: str, *args, **kwargs):
        out = fn(*args, **kwargs)
        call = f"{text}({', '.join([self.code(a) for a in args] + [f'{k}={self.code(v)}' for k, v in kwargs.items()])})"
        self.kept.append(out)
        if var is None:
            self.names[id(out)] = call
        else:
            self.lines.append(f"{var} = {call}" if var else call)
            if var:
                self.names[id(out)] = var
        return out


def _force_system(built: _Built):
    """A LeafSystem that reads the plant's state and outputs (0) the applied generalized
    force: tau = T^T Q of the build's coordinate laws plus its prescribed motions'
    actuators, and (1) the externally applied spatial forces of its point-to-point laws,
    all at the stage's time (contract point 6).

    The actuators (convention 9) impose each prescribed coordinate's acceleration: with
    the plant's mass matrix M and its generalized forces f without them (force elements,
    gravity, bias, the Python laws), and G the rows of q = T v + c that give the prescribed
    coordinates (in the plant's velocity order), G M^-1 (f + G^T Q_p) = q_p''(t), so
    Q_p = (G M^-1 G^T)^-1 (q_p''(t) - G M^-1 f): the actuator forces in the description's
    coordinates."""
    from pydrake.common.value import Value
    from pydrake.multibody.math import SpatialForce
    from pydrake.multibody.plant import ExternallyAppliedSpatialForce
    from pydrake.multibody.tree import JacobianWrtVariable, MultibodyForces
    from pydrake.systems.framework import BasicVector, LeafSystem

    plant, bodies = built.plant, built.bodies
    positions, velocities = built.positions, built.velocities
    nq, nv = plant.num_positions(), plant.num_velocities()
    laws = CoordinateLaws(built.mech, built.python_laws)
    points = [(f, ForceLaw.of(f).law, np.array(vec3(f.point_a)), np.array(vec3(f.point_b)))
              for f in built.python_p2p]
    kinematics = plant.CreateDefaultContext()
    T, c = built.map.T, built.map.c
    driven = built.driven
    select = np.zeros((built.n, nv))  # joint values' rates from the plant's velocities
    select[np.arange(built.n), velocities] = 1.0
    G = T[[m.index for m in driven]] @ select

    class _Forces(LeafSystem):
        def __init__(self) -> None:
            super().__init__()
            self.DeclareVectorInputPort("state", nq + nv)
            self.DeclareVectorOutputPort("generalized_force", nv, self._generalized)
            self.DeclareAbstractOutputPort(
                "spatial_forces", lambda: Value[list[ExternallyAppliedSpatialForce]]([]),
                self._spatial)

        def _laws(self, x: np.ndarray, t: float) -> np.ndarray:
            """The coordinate laws' generalized force, in the plant's velocity order."""
            tau = np.zeros(nv)
            if laws:
                Q = laws.generalized(T @ x[positions] + c, T @ x[nq + velocities], t)
                tau[velocities] = T.T @ np.asarray(Q)
            return tau

        def actuators(self, x: np.ndarray, t: float, tau_laws: np.ndarray) -> np.ndarray:
            """Q_p, the prescribed coordinates' actuator forces at state x and time t."""
            plant.SetPositionsAndVelocities(kinematics, x)
            elements = MultibodyForces(plant)
            plant.CalcForceElementsContribution(kinematics, elements)
            f = (plant.CalcGeneralizedForces(kinematics, elements)
                 - plant.CalcBiasTerm(kinematics) + tau_laws)
            for body, point, force in self._point_forces(t):
                J = plant.CalcJacobianTranslationalVelocity(
                    kinematics, JacobianWrtVariable.kV, bodies[body].body_frame(), point,
                    plant.world_frame(), plant.world_frame())
                f += J.T @ force
            M = plant.CalcMassMatrix(kinematics)
            wanted = np.array([m.acceleration(t) for m in driven])
            MG = np.linalg.solve(M, G.T)
            return np.linalg.solve(G @ MG, wanted - MG.T @ f)

        def _generalized(self, context, output: BasicVector) -> None:
            x = self.get_input_port(0).Eval(context)
            tau = self._laws(x, context.get_time())
            if driven:
                tau = tau + G.T @ self.actuators(x, context.get_time(), tau)
            output.SetFromVector(tau)

        def _point_forces(self, t: float) -> list:
            """(body, point in its frame, world force) of the point-to-point laws at the
            state already set in the kinematics context."""
            out = []
            for f, law, pa, pb in points:
                ends = [_point_motion(bodies[body], point, kinematics)
                        for body, point in ((f.body_a, pa), (f.body_b, pb))]
                d = ends[1][0] - ends[0][0]
                length = float(np.linalg.norm(d))
                rate = float(d @ (ends[1][1] - ends[0][1])) / length
                on_a = law(length, rate, t) * d / length  # tension pulls a towards b
                out += [(body, point, force) for body, point, force in
                        ((f.body_a, pa, on_a), (f.body_b, pb, -on_a)) if body != WORLD]
            return out

        def _spatial(self, context, output) -> None:
            forces = []
            if points:
                # the plant's own kinematics, in a context of this system's
                plant.SetPositionsAndVelocities(kinematics, self.get_input_port(0).Eval(context))
                for body, point, force in self._point_forces(context.get_time()):
                    applied = ExternallyAppliedSpatialForce()
                    applied.body_index = bodies[body].index()
                    applied.p_BoBq_B = point
                    applied.F_Bq_W = SpatialForce(np.zeros(3), force)
                    forces.append(applied)
            output.set_value(forces)

    return _Forces()


def _point_motion(body, point: np.ndarray, context) -> tuple[np.ndarray, np.ndarray]:
    """World position and velocity of a body point (body frame coordinates; planar: the
    angular velocity is about z)."""
    pose = body.EvalPoseInWorld(context)
    velocity = body.EvalSpatialVelocityInWorld(context)
    arm = pose.rotation().matrix() @ point
    w = velocity.rotational()[2]
    v = velocity.translational()
    return pose.translation() + arm, np.array([v[0] - w * arm[1], v[1] + w * arm[0], 0.0])


BACKEND = DrakeBackend()
