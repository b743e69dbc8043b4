"""Exudyn backend: the minimal-coordinate route (`ObjectKinematicTree`).

Translation (generic over the description, conventions 1-8 of `systems.model`). Each
element kind has one builder, registered with the expressions it declares (`_builds`;
`EXPRESSIONS` is read from that registry; each declaration names the Exudyn item built):

- every joint becomes one link of one kinematic tree, in joint order, its frames the
  shared ones (`plan.LinkFrames`); a spatial mechanism (model convention 10) gets
  RevoluteX/Y/Z (PrismaticX/Y/Z) links with the full 3 x 3 central tensor in
  ``linkInertiasCOM`` (stored as given: `stored_inertia`);
- the engine's joint values ``u`` are relative; description coordinates are the shared
  affine map ``q = T u + c`` (`plan.CoordinateMap`), generalized forces map with ``T^T``;
- massless bodies are zero-mass links, gravity is the tree's own gravity vector, affine
  laws use Exudyn's own terms (C++) and any other law a Python user function called at
  every integrator stage with the stage time;
- every step is sampled by in-memory sensors (write period dt/2, so each step is recorded
  exactly once), and Exudyn's C++ loop runs without Python stepping;
- reactions: the tree has no joint-force output, so the force parent -> child is Newton's
  law on the child's subtree (`reactions.subtree_newton`), with the engine's
  centre-of-mass accelerations (kinematic tree sensors, end-of-step accelerations);
- linearization: `mbs.ComputeLinearizedSystem`, with closure constraints on the
  constraint manifold from Exudyn's constraint Jacobian (`linearize`).

Closure constraints and prescribed coordinates (convention 9) stay on the tree as
algebraic equations, met to round-off; each builder says how its engine force maps to
the contract's. Explicit solvers cannot run them (they stop on closure constraints and
silently ignore a prescribed coordinate's offset), so such mechanisms run the implicit
``constrained_solver`` or ``driven_solver``, a driven one started from consistent
accelerations and multipliers (`_consistent_start`). The actuator acts through the joint,
so the reactions include it (`reactions`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import singledispatch
from typing import Callable, Mapping, Sequence

import numpy as np

from ..analytic.modes import quadratic_eigenvalues
from ..systems._continua import Beam
from ..systems.model import (WORLD, Body, CoordinateForce, LinearCoupling, Mechanism,
                             PointOnLine, PointOnPoint, PointToPoint, Prescribed, Prismatic,
                             Revolute)
from .base import (EXACT, RK3_STABILITY, RK4_STABILITY, SOFT, UNSUPPORTED, Backend, BareLoop,
                   BeamElement, BeamModes, ElementBuilders, Expression, Linearization, Samples,
                   Scheme, Setting, Stopwatch, constraint_manifold_eigenvalues)
from .plan import (BODY, COORDINATE_FORCE_CUSTOM, COORDINATE_FORCE_LINEAR, HINGE_CLOSURE,
                   LINEAR_COUPLING, MASSLESS_BODY, POINT_ON_LINE, POINT_ON_POINT,
                   POINT_TO_POINT_CUSTOM, POINT_TO_POINT_LINEAR, PRESCRIBED, PRISMATIC, REVOLUTE,
                   ROLLING_CONTACT, TIME_LOAD, CoordinateLaws, ForceLaw, LinkFrames, Motion,
                   axis_aligned, central_tensor, coupling_row, driven_start, gravity_vector, held_below,
                   link_axis, link_frames, num, one_joint_value, prescribed_start, rot_z,
                   spatial_tree_reason, turned)
from .reactions import subtree_bodies, subtree_newton

#: the fixed-step solvers offered through the "solver" setting: (order of accuracy,
#: measured on the double pendulum; stability limit: implicit solvers are unconditionally
#: stable, and of the explicit ones only the Runge-Kutta schemes with a stable stretch of
#: the imaginary axis have one). Exudyn's VelocityVerlet is left out: it warns "still
#: under development" and converged at first order.
_SOLVERS = {
    "RK44": (4, RK4_STABILITY),
    "RK67": (6, None),
    "RK33": (3, RK3_STABILITY),
    "ExplicitMidpoint": (2, None),
    "ExplicitEuler": (1, None),
    "GeneralizedAlpha": (2, None),
    "TrapezoidalIndex2": (2, None),
}
#: the engine's own beam elements (contract point 12)
ANCF_CABLE = "ANCFCable2D"
GEOMETRICALLY_EXACT = "BeamGeometricallyExact2D"
#: the geometrically exact element's shear stiffness, GA = factor EI / l^2: high, so that
#: its Timoshenko limit lies 5e-6 n^2 lower by shear (far below its error at N <= 32)
_GE_SHEAR_FACTOR = 1e6
#: its rotary inertia per length, factor rho l^2: it must be positive (the rotation
#: coordinates carry it) and lowers the frequencies by about (n pi)^2 factor / 2 = 5e-6 n^2;
#: 1e-8 put the rotary modes so high that the eigensolver's round-off reached 4e-5 on the
#: first mode at N = 32 with the block (measured against 1e-6; 1e-4 shows in the orders)
_GE_ROTARY_FACTOR = 1e-6
#: axial stiffness EA = factor EI / l^2 (the axial coordinates are held; any positive value)
_AXIAL_FACTOR = 1e4
#: solvers that handle algebraic (constraint) equations; Exudyn's explicit solvers stop
#: with "contains constraints that cannot be solved"
_CONSTRAINT_SOLVERS = ("GeneralizedAlpha", "TrapezoidalIndex2")


@dataclass
class _ConstraintItem:
    """One closure constraint or prescribed coordinate as built in Exudyn: its object, the
    output its sensor reads ("Force" or "ForceLocal") and how that output maps to the
    contract's physical terms (sensor rows, engine values u -> force)."""

    name: str
    obj: int
    output: str
    force: Callable[[np.ndarray, np.ndarray], np.ndarray]


# --- element builders, registered per element kind with their expressions ------------------

#: element kind -> (its builder, the expressions it declares: contract point 5). A body's
#: builder gives its link's mass and central tensor, a joint's its Exudyn joint type, any
#: other element's adds its items to the `_System` being built.
_ELEMENTS = ElementBuilders()
_builds, _builder = _ELEMENTS.builds, _ELEMENTS.of


@_builds(BODY, Expression(EXACT, "a link of the ObjectKinematicTree with its mass, centre "
                                 "of mass and inertia"))
@_builds(MASSLESS_BODY,
         Expression(EXACT, "a zero-mass link: the mass matrix stays regular while a massive "
                           "descendant carries its coordinates, or a closure constraint holds "
                           "it (augmented matrix [M C^T; C 0])",
                    when="a massive body below it, or a constraint on its subtree",
                    applies=held_below),
         Expression(UNSUPPORTED, "it carries no mass and no constraint holds it: the "
                                 "kinematic tree's mass matrix would be singular",
                    when="only massless bodies below it, none constrained"))
def _link_inertia(body: Body, mech: Mechanism) -> tuple[float, np.ndarray]:
    """The link's mass and central tensor (`plan.central_tensor`; the link frame is
    aligned with the body frame: beta = 0 in a spatial tree, and a planar tensor is
    diagonal about z), stored as given (`stored_inertia`)."""
    return num(body.mass), central_tensor(mech, body)


@_builds(REVOLUTE,
         Expression(EXACT, "RevoluteZ link of the kinematic tree (spatial: RevoluteX, Y or Z)",
                    when="a planar hinge, or a spatial one about a link axis",
                    applies=axis_aligned),
         Expression(UNSUPPORTED, "the spatial tree's hinges turn about a link axis "
                                 "(RevoluteX, Y or Z), not about any other axis",
                    when="a spatial hinge about another axis"))
def _hinge(joint: Revolute, mech: Mechanism) -> str:
    """The Exudyn joint type of the hinge's link (its frame: `plan.link_frames`)."""
    return "Revolute" + link_axis(joint) if mech.spatial else "RevoluteZ"


@_builds(PRISMATIC,
         Expression(EXACT, "PrismaticX link, the joint frame turned to the axis (spatial: "
                           "PrismaticX, Y or Z)",
                    when="a planar slide, or a spatial one along a link axis",
                    applies=axis_aligned),
         Expression(UNSUPPORTED, "the spatial tree's slides run along a link axis "
                                 "(PrismaticX, Y or Z), not along any other axis",
                    when="a spatial slide along another axis"))
def _slide(joint: Prismatic, mech: Mechanism) -> str:
    """As `_hinge`: a planar slide's joint frame has its x axis along the slide."""
    return "Prismatic" + link_axis(joint) if mech.spatial else "PrismaticX"


def _tree_links(mech: Mechanism, geo: LinkFrames, exu) -> dict:
    """The ``ObjectKinematicTree`` arguments that describe its links (the frames of `geo`,
    each joint's type and each body's mass and tensor from its builder) and gravity, along
    -y or, in a spatial mechanism, against its `up`."""
    bodies = [mech.body(j.child) for j in mech.joints]
    masses, tensors = zip(*(_builder(b)(b, mech) for b in bodies))
    return dict(gravity=list(gravity_vector(mech)), baseOffset=[0.0, 0.0, 0.0],
                jointTypes=[getattr(exu.JointType, _builder(j)(j, mech)) for j in mech.joints],
                linkParents=geo.parents,
                jointTransformations=exu.Matrix3DList([rot_z(a) for a in geo.rotations]),
                jointOffsets=exu.Vector3DList([list(o) for o in geo.offsets]),
                linkInertiasCOM=exu.Matrix3DList(list(tensors)),
                linkCOMs=exu.Vector3DList([list(geo.com[b.name]) for b in bodies]),
                linkMasses=list(masses))


@dataclass
class _System:
    """The Exudyn system of one mechanism as the builders add to it: the engine and its
    item classes, the system container (it owns `mbs`: it stays referenced while `mbs` is
    used), the tree node and object, the tree's coordinate-force terms (set on the tree
    once every element is built: `set_tree_forces`), and the connectors, closures and
    prescribed coordinates built, the latter's accelerations u_p''(0) by engine coordinate
    (`start`)."""

    exu: object
    items: object
    SC: object
    mbs: object
    mech: Mechanism
    geo: LinkFrames
    cfg: dict
    node: int = -1
    tree: int = -1
    P: np.ndarray = field(init=False)      # the tree's PD terms and joint forces
    D: np.ndarray = field(init=False)
    force: np.ndarray = field(init=False)
    python_laws: list = field(default_factory=list)
    connectors: dict[str, int] = field(default_factory=dict)
    closures: list[_ConstraintItem] = field(default_factory=list)
    driven: list[_ConstraintItem] = field(default_factory=list)
    start: dict[int, float] = field(default_factory=dict)
    shared: dict[str, object] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.P, self.D, self.force = (np.zeros(self.geo.n) for _ in range(3))

    def once(self, key: str, make: Callable[[], object]) -> object:
        """An item several elements share (the ground, its markers), made at first use."""
        if key not in self.shared:
            self.shared[key] = make()
        return self.shared[key]

    def ground_node(self) -> int:
        return self.once("ground node", lambda: self.mbs.AddNode(self.items.NodePointGround()))

    def marker(self, body: str, point, rigid: bool = False) -> int:
        """A marker at a body-frame point: on a tree link, or on the ground body (a rigid
        marker where a joint needs its orientation)."""
        pt = [num(v) for v in point]
        if body == WORLD:
            ground = self.once("ground", lambda: self.mbs.AddObject(self.items.ObjectGround()))
            kind = self.items.MarkerBodyRigid if rigid else self.items.MarkerBodyPosition
            return self.mbs.AddMarker(kind(bodyNumber=ground, localPosition=[*pt, 0.0]))
        return self.mbs.AddMarker(self.items.MarkerKinematicTreeRigid(
            objectNumber=self.tree, linkNumber=self.geo.link_of[body],
            localPosition=list(self.geo.local_point(body, pt))))

    def native(self, element) -> tuple[float, float, float] | None:
        """The element's affine law where the engine's own terms carry it (setting
        native_linear_laws), None where a user function does."""
        return ForceLaw.of(element).linear if self.cfg["native_linear_laws"] else None

    def set_tree_forces(self) -> None:
        """The coordinate-force terms the builders collected, set on the tree: PD terms
        and joint forces (C++), one Python ``forceUserFunction`` for the other laws."""
        n = self.geo.n
        terms: dict[str, object] = {}
        if np.any(self.P) or np.any(self.D):
            terms.update(jointPControlVector=self.P.tolist(),
                         jointDControlVector=self.D.tolist(),
                         jointPositionOffsetVector=[0.0] * n,
                         jointVelocityOffsetVector=[0.0] * n)
        if np.any(self.force):
            terms.update(jointForceVector=self.force.tolist())
        if self.python_laws:  # their generalized force on the engine coordinates, T^T Q
            law = CoordinateLaws(self.mech, self.python_laws).on_engine_values(
                self.geo.cmap.T, self.geo.cmap.c)
            terms.update(forceUserFunction=lambda mbs, t, item, u, u_t: law(u, u_t, t))
        for key, value in terms.items():
            self.mbs.SetObjectParameter(self.tree, key, value)

    def sensor(self, kind: str, **arguments) -> int:
        """An in-memory sensor of `kind` (SensorNode, SensorObject, ...)."""
        return self.mbs.AddSensor(getattr(self.items, kind)(
            storeInternal=True, writeToFile=False, **arguments))

    def stored(self, sensor: int) -> np.ndarray:
        """A sensor's samples: rows (t, values...)."""
        return np.asarray(self.mbs.GetSensorStoredData(sensor))


@_builds(TIME_LOAD, Expression(EXACT, "a user function, called at every integrator stage "
                                      "with the stage time"))
@_builds(COORDINATE_FORCE_CUSTOM, Expression(EXACT, "the tree's forceUserFunction, called "
                                                    "at every integrator stage"))
@_builds(POINT_TO_POINT_CUSTOM, Expression(EXACT, "ObjectConnectorSpringDamper with a "
                                                  "springForceUserFunction, called at every "
                                                  "integrator stage"))
@_builds(POINT_TO_POINT_LINEAR, Expression(EXACT, "ObjectConnectorSpringDamper with its own "
                                                  "stiffness, damping and force (C++)"))
@_builds(COORDINATE_FORCE_LINEAR, Expression(EXACT, "the tree's PD terms and joint force "
                                                    "vector (C++) where the coordinate is one "
                                                    "engine coordinate, otherwise the tree's "
                                                    "forceUserFunction"))
@singledispatch
def _force_element(element, system: _System) -> None:
    """A force element on the engine's own terms (C++) where its law is affine and free of
    TIME (`_System.native`), otherwise through a Python user function, called at every
    integrator stage with the stage time."""
    raise TypeError(f"no force route for {type(element).__name__}")


@_force_element.register
def _(f: PointToPoint, system: _System) -> None:
    """An ``ObjectConnectorSpringDamper`` between the element's points, reference length
    0 (its deltaL is the length itself)."""
    if f.body_a == WORLD and f.body_b == WORLD:
        return  # acts on nothing
    law = system.native(f)
    if law is None:
        tension = ForceLaw.of(f).law
        terms = dict(springForceUserFunction=lambda mbs, t, item, length, rate, stiffness,
                     damping, force: tension(length, rate, t))
    else:
        b0, bl, bv = law  # tension = b0 + bl L + bv L' = k (L - 0) + d L' + force
        terms = dict(stiffness=bl, damping=bv, force=b0)
    markers = [system.marker(f.body_a, f.point_a), system.marker(f.body_b, f.point_b)]
    system.connectors[f.name] = system.mbs.AddObject(system.items.ObjectConnectorSpringDamper(
        markerNumbers=markers, referenceLength=0.0, **terms))


@_force_element.register
def _(f: CoordinateForce, system: _System) -> None:
    # native when COORD is s u_j, one engine coordinate (then Q_u = s F(s u, s u_t))
    spring = system.geo.cmap.joint_spring(f.weights(system.mech.coordinates), system.native(f))
    if spring is None:  # the tree's forceUserFunction (`_System.set_tree_forces`)
        system.python_laws.append(f)
        return
    j, force, stiffness, damping = spring
    system.force[j] += force
    system.P[j] += stiffness
    system.D[j] += damping


@_builds(POINT_ON_POINT, Expression(EXACT, "ObjectJointRevolute2D: index-3 algebraic "
                                           "equations, met to round-off"))
def _revolute_2d(c: PointOnPoint, system: _System) -> None:
    obj = system.mbs.AddObject(system.items.ObjectJointRevolute2D(markerNumbers=[
        system.marker(c.body_a, c.point_a, rigid=True),
        system.marker(c.body_b, c.point_b, rigid=True)]))
    # its Force: the force on body_a (marker 0) from body_b, world axes
    system.closures.append(_ConstraintItem(c.name, obj, "Force",
                                        lambda data, u: data[:, 1:3].copy()))


@_builds(POINT_ON_LINE, Expression(EXACT, "ObjectJointPrismatic2D with the rotation free: an "
                                          "exact pin in slot"))
def _prismatic_2d(c: PointOnLine, system: _System) -> None:
    geo = system.geo
    normal_local = geo.local_normal(c.line_body, c.direction)  # the slot normal
    # Exudyn: (p1 - p0) . A1 n1 = 0, p0 the pin, p1 the slot point
    obj = system.mbs.AddObject(system.items.ObjectJointPrismatic2D(
        markerNumbers=[system.marker(c.body, c.point, rigid=True),
                       system.marker(c.line_body, c.line_point, rigid=True)],
        axisMarker0=[1.0, 0.0, 0.0], normalMarker1=[*normal_local, 0.0],
        constrainRotation=False))

    def slot_force(data: np.ndarray, u: np.ndarray) -> np.ndarray:
        """ForceLocal: the slot's force on the pin in the pin marker's frame, turned to
        world axes."""
        return turned(geo.frame_angle(c.body, u), data[:, 1], data[:, 2])

    system.closures.append(_ConstraintItem(c.name, obj, "ForceLocal", slot_force))


@_builds(LINEAR_COUPLING, Expression(EXACT, "ObjectConnectorCoordinateVector on the tree's "
                                            "coordinates (affine in the description's, so "
                                            "the coupling stays linear)"))
def _coordinate_vector(c: LinearCoupling, system: _System) -> None:
    mbs, items = system.mbs, system.items
    # row . u = constant
    row, constant = system.geo.cmap.on_engine_values(*coupling_row(system.mech, c))
    node_marker, ground_marker = system.once("coordinate markers", lambda: (
        mbs.AddMarker(items.MarkerNodeCoordinates(nodeNumber=system.node)),
        mbs.AddMarker(items.MarkerNodeCoordinates(nodeNumber=system.ground_node()))))
    # Exudyn: X1 q1 - X0 q0 - v_off = 0 with q0 = u (marker 0), q1 empty
    obj = mbs.AddObject(items.ObjectConnectorCoordinateVector(
        markerNumbers=[node_marker, ground_marker], scalingMarker0=-row.reshape(1, -1),
        scalingMarker1=np.zeros((1, 0)), offset=[constant]))
    # its Force is the multiplier, entering as Phi_u^T lam as in the description (Phi
    # identical): the generalized force is -lam
    system.closures.append(_ConstraintItem(c.name, obj, "Force",
                                        lambda data, u: -data[:, 1:2].copy()))


@_builds(
    PRESCRIBED,
    Expression(EXACT, "ObjectConnectorCoordinate between a ground coordinate and the "
                      "joint's engine coordinate, offsetUserFunction(_t) = q(t), q'(t) at the "
                      "implicit solver's times (driven_solver), started from consistent "
                      "accelerations; actuator force -multiplier / scale; order 2 "
                      "(TrapezoidalIndex2) in the coordinates and the force",
               when="the prescribed coordinate is one engine joint value",
               applies=one_joint_value),
    Expression(UNSUPPORTED, "an absolute angle on a turning parent is a combination of "
                            "engine joint values, which Exudyn's coordinate constraint (one "
                            "coordinate, time offset) cannot hold",
               when="the prescribed coordinate combines several joint values"))
def _coordinate_constraint(p: Prescribed, system: _System) -> None:
    """An ``ObjectConnectorCoordinate`` between a ground coordinate (marker 0) and the
    tree node's coordinate (marker 1): Exudyn's equation u - 0 - UF(t) = 0 with the offset
    UF(t) = (q(t) - shift) / scale and its rate UF_t, both evaluated by the solver at its
    own stage times (the index-2 solver imposes the rate, the index-3 one the position)."""
    mbs, items, cmap = system.mbs, system.items, system.geo.cmap
    motion = Motion(p, system.mech.coordinates.index(p.coordinate))
    k = motion.index
    scale, shift = float(cmap.T[k, k]), float(cmap.c[k])
    ground_marker = system.once("ground coordinate", lambda: mbs.AddMarker(
        items.MarkerNodeCoordinate(nodeNumber=system.ground_node(), coordinate=0)))
    marker = mbs.AddMarker(items.MarkerNodeCoordinate(nodeNumber=system.node, coordinate=k))
    position, rate = motion.position, motion.rate
    obj = mbs.AddObject(items.ObjectConnectorCoordinate(
        markerNumbers=[ground_marker, marker],
        offsetUserFunction=lambda mbs, t, item, offset: (position(t) - shift) / scale,
        offsetUserFunction_t=lambda mbs, t, item, offset: rate(t) / scale))
    system.start[k] = motion.acceleration(0.0) / scale
    # its Force is the multiplier lam: Exudyn adds C_u^T lam = lam e_k to the engine
    # equations, so the constraint pushes engine coordinate k with -lam, -lam / scale on q
    # (virtual work)
    system.driven.append(_ConstraintItem(p.name, obj, "Force",
                                         lambda data, u: -data[:, 1] / scale))


_ELEMENTS.refuses(ROLLING_CONTACT, "no contact is built on the kinematic tree: Exudyn holds "
                  "the rolling coupling exactly (LinearCoupling)", "exudyn")
_ELEMENTS.refuses(HINGE_CLOSURE, "the spatial tree closes no loop: a spatial closed loop has "
                  "no constraint in it", "exudyn")


def _build(mech: Mechanism, q0: np.ndarray, qd0: np.ndarray, cfg: dict) -> _System:
    """The Exudyn system of `mech` started at (q0, qd0): the tree node, the kinematic
    tree, then every force, closure constraint and prescribed coordinate by its kind's
    builder, in description order."""
    import exudyn as exu
    import exudyn.itemInterface as items

    geo = link_frames(mech)
    u0, ud0 = geo.values(q0, qd0)
    SC = exu.SystemContainer()
    system = _System(exu, items, SC, SC.AddSystem(), mech, geo, cfg)
    system.node = system.mbs.AddNode(items.NodeGenericODE2(
        referenceCoordinates=[0.0] * geo.n, initialCoordinates=u0.tolist(),
        initialCoordinates_t=ud0.tolist(), numberOfODE2Coordinates=geo.n))
    system.tree = system.mbs.AddObject(items.ObjectKinematicTree(
        nodeNumber=system.node, **_tree_links(mech, geo, exu)))
    for element in (*mech.forces, *mech.constraints, *mech.prescribed):
        _builder(element)(element, system)
    system.set_tree_forces()
    return system


class ExudynBackend(Backend):
    id = "exudyn"
    SETTINGS = {
        "solver": Setting(
            "RK44", tuple(_SOLVERS),
            "Exudyn defaults to GeneralizedAlpha (2nd order, implicit). RK44 (classical "
            "Runge-Kutta, order 4) works on the kinematic tree without Newton iterations "
            "(integrator_order reports the order of the solver used). Mechanisms with "
            "closure constraints run constrained_solver, with prescribed motion "
            "driven_solver. Engine default: Exudyn documentation, "
            "SolveDynamic(..., solverType=exudyn.DynamicSolverType.GeneralizedAlpha).",
            engine_default="GeneralizedAlpha"),
        "constrained_solver": Setting(
            "GeneralizedAlpha", _CONSTRAINT_SOLVERS,
            "Mechanisms with closure constraints (exact index-3 constraints: Exudyn's "
            "explicit solvers stop with 'contains constraints that cannot be solved'): "
            "GeneralizedAlpha (Exudyn's default, order 2) or TrapezoidalIndex2 (order 2, "
            "index-2 velocity constraints; positions drift slowly)."),
        "driven_solver": Setting(
            "TrapezoidalIndex2", _CONSTRAINT_SOLVERS,
            "Mechanisms with prescribed motion (no Exudyn default: the route is the "
            "backend's): each prescribed coordinate is a CoordinateConstraint whose "
            "offsetUserFunction(_t) gives q(t), q'(t) at the solver's times, started from "
            "consistent accelerations. Only implicit solvers impose it: Exudyn's explicit "
            "solvers (RK44, ...) silently ignore the offset, so they are refused. "
            "TrapezoidalIndex2 (index 2: imposes q'(t); order 2 in the free and the "
            "prescribed coordinates and in the actuator force -lam/scale, read at every step "
            "as is: no alternation once the start is consistent). GeneralizedAlpha (index 3, "
            "constrained_spectral_radius: q(t) to round-off, free coordinates order 2, but "
            "its multiplier belongs to the algorithmic time, so the actuator force is only "
            "first order, against second order with TrapezoidalIndex2, as an inertial "
            "shaker's actuator force shows)."),
        "constrained_spectral_radius": Setting(
            0.9, float,
            "GeneralizedAlpha on constrained mechanisms: Exudyn's default 0.9 kept; rho = "
            "1 (no numerical damping) lets the index-3 multipliers oscillate undamped (the "
            "scotch yoke's slot force is swamped by the oscillation, the slotted bar's "
            "arctan damper fails Newton); values near the default change the trajectory "
            "errors little."),
        "automatic_step_size": Setting(
            False, bool,
            "Exudyn default True lets error-controlled explicit solvers change the step; "
            "False keeps the fixed step dt the contract asks for. Engine default: Exudyn "
            "documentation, SimulationSettings timeIntegration.automaticStepSize = True.",
            engine_default=True),
        "ga_spectral_radius": Setting(
            1.0, float,
            "GeneralizedAlpha as 'solver' (unconstrained mechanisms). The engine default "
            "adds numerical damping (energy decays); 1.0 removes it (no constraints, so "
            "rho = 1 is stable). Constrained: constrained_spectral_radius. Engine default: "
            "Exudyn documentation, SimulationSettings "
            "timeIntegration.generalizedAlpha.spectralRadius = 0.9.",
            engine_default=0.9),
        "ga_adaptive_step": Setting(
            False, bool,
            "Implicit solvers only. Exudyn default True silently reduces the step after a "
            "failed Newton solve; False keeps dt fixed (a failure is raised instead). "
            "Engine default: Exudyn documentation, SimulationSettings "
            "timeIntegration.adaptiveStep = True.",
            engine_default=True),
        "newton_relative_tolerance": Setting(
            1e-13, float,
            "Implicit solvers only. The engine default limits the accuracy of small "
            "motions; tightened. Engine default: Exudyn documentation, SimulationSettings "
            "timeIntegration.newton.relativeTolerance = 1e-8.",
            engine_default=1e-8),
        "newton_absolute_tolerance": Setting(
            1e-14, float,
            "Implicit solvers only. The engine default, tightened for small amplitudes. "
            "Engine default: Exudyn documentation, SimulationSettings "
            "timeIntegration.newton.absoluteTolerance = 1e-10.",
            engine_default=1e-10),
        "modified_newton": Setting(
            False, bool,
            "Implicit solvers only. Exudyn default True reuses an old Jacobian; full "
            "Newton converges to the tight tolerances. Engine default: Exudyn "
            "documentation, SimulationSettings timeIntegration.newton.useModifiedNewton = "
            "True.",
            engine_default=True),
        "end_of_step_accelerations": Setting(
            True, bool,
            "Exudyn default True (kept): explicit solvers recompute the accelerations at "
            "the end of each step, so the sampled centre-of-mass accelerations (used for "
            "reactions) belong to the sampled state; False leaves last-stage "
            "accelerations."),
        "native_linear_laws": Setting(
            True, bool,
            "Backend choice: laws affine in the length/coordinate and its rate (no TIME) "
            "use Exudyn's built-in spring-damper and the tree's PD terms (C++); False "
            "sends every law through Python user functions (same model, slower)."),
        "write_solution_file": Setting(
            False, bool,
            "Exudyn default True writes coordinatesSolution.txt at every solution write "
            "period (disk I/O inside the timed loop); the backend samples with in-memory "
            "sensors at every step instead (sensor write period dt replaces the engine's "
            "default period)."),
        "linearization_relative_epsilon": Setting(
            1e-4, float,
            "linearize(): relative step of Exudyn's numerical Jacobian (K, D), a forward "
            "difference. Exudyn's default step, near the square root of the machine "
            "epsilon u, balances a forward difference's truncation O(eps) against its "
            "round-off O(u/eps), each then about sqrt(u); with linearization_richardson "
            "the truncation is O(eps^2), so a larger step (the harness's) cuts the "
            "round-off u/eps while the truncation stays small."),
        "linearization_richardson": Setting(
            True, bool,
            "linearize(): True evaluates Exudyn's Jacobian at eps and eps/2 and "
            "extrapolates (2 J(eps/2) - J(eps), error O(eps^2)); False is Exudyn's single "
            "forward difference (what ComputeODE2Eigenvalues uses)."),
        "linearization_constraint_step": Setting(
            1e-5, float,
            "linearize() with closure constraints: step (engine coordinate units) of the "
            "central differences of Exudyn's constraint Jacobian that give the constraint "
            "stiffness d(C lam)/du at a loaded equilibrium; Exudyn's "
            "ComputeODE2Eigenvalues leaves this term out."),
    }

    # --- identity --------------------------------------------------------------------------
    ENGINE_MODULES = ('exudyn', 'exudyn.utilities')
    ENGINE_DISTRIBUTION = "exudyn"

    # --- support ---------------------------------------------------------------------------
    EXPRESSIONS = _ELEMENTS.declared()

    SPATIAL_REASON = ""

    def stored_inertia(self, mechanism: Mechanism, settings: Mapping | None = None
                       ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """The tree's linkInertiasCOM as stored (a full 3 x 3 tensor, not diagonalised),
        in principal form."""
        zeros = np.zeros(len(mechanism.joints))
        system = _build(mechanism, zeros, zeros, self.resolve_settings(settings))
        tensors = np.array(system.mbs.GetObjectParameter(system.tree, "linkInertiasCOM"),
                           dtype=float)
        return {j.child: np.linalg.eigh(tensor)
                for j, tensor in zip(mechanism.joints, tensors.reshape(-1, 3, 3))}

    def translation_reason(self, mechanism: Mechanism) -> str:
        """A spatial mechanism: the common conditions of a spatial tree (its point-to-point
        elements are spring-dampers between tree markers; each joint's axis is checked by
        its builder's declared cases)."""
        return (spatial_tree_reason(mechanism, closures=False, slides=True, point_forces=True)
                if mechanism.spatial else "")

    # --- model building: the element builders above; the consistent start --------------------
    def _engine_terms(self, system: _System, constraint_jacobian: bool = False
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """The engine's mass matrix M, ODE2 right-hand side f and, when asked, constraint
        Jacobian C (n x m) at the initial state, from Exudyn's static solver helper."""
        exu, mbs, n = system.exu, system.mbs, system.geo.n
        sim = self._simulation_settings(system)
        helper = exu.MainSolverStatic()
        helper.InitializeSolver(mbs, sim)
        helper.ComputeMassMatrix(mbs)
        mass = np.asarray(helper.GetSystemMassMatrix())
        helper.ComputeODE2RHS(mbs)
        rhs = np.asarray(helper.GetSystemResidual())[:n]
        C = None
        if constraint_jacobian:
            # the ODE2 Jacobian call sizes and clears the system Jacobian, which
            # ComputeJacobianAE only adds into (ComputeLinearizedSystem does the same)
            helper.ComputeJacobianODE2RHS(mbs, scalarFactor_ODE2=-1, scalarFactor_ODE2_t=0,
                                          scalarFactor_ODE1=0)
            helper.ComputeJacobianAE(mbs, scalarFactor_ODE2=1.0, scalarFactor_ODE2_t=0.0,
                                     scalarFactor_ODE1=0.0, velocityLevel=False)
            C = np.asarray(helper.GetSystemJacobian())[:n, n:]
        helper.FinalizeSolver(mbs, sim)
        return mass, rhs, C

    def _consistent_start(self, system: _System) -> np.ndarray:
        """Initial accelerations and multipliers that meet the prescribed accelerations
        q''(0). Exudyn's own initial accelerations differentiate the constraints without
        their time terms (its documentation: dg/dt 'not implemented'), i.e. as if q''(0)
        were 0; the trapezoidal rule then carries that error as a step-to-step
        alternation of the multiplier that never decays, generalized-alpha as one that
        decays slowly. Here: `plan.prescribed_start` with u_p'' = q_p''(0) / scale and the
        engine's M and f at t = 0, written into the initial state that the solver starts
        from (computeInitialAccelerations off for driven runs). Returns lam (the solver
        records zero multipliers for the sample at t = 0)."""
        mass, rhs, _ = self._engine_terms(system)
        acc, lam = prescribed_start(mass, rhs, system.start)
        initial = system.exu.ConfigurationType.Initial
        system.mbs.systemData.SetODE2Coordinates_tt(acc.tolist(), configuration=initial)
        system.mbs.systemData.SetAECoordinates(lam.tolist(), configuration=initial)
        return lam

    def _simulation_settings(self, system: _System, t_end: float = 1.0, steps: int = 1):
        """Exudyn's SimulationSettings of the system for `steps` steps over `t_end` (a solver
        helper: one step), from the backend settings: a driven run starts from the
        consistent accelerations already in its initial state (`_consistent_start`)
        instead of the implicit solver's own; a run with algebraic equations uses the
        constrained spectral radius."""
        settings = system.cfg
        s = system.exu.SimulationSettings()
        ti = s.timeIntegration
        ti.numberOfSteps = steps
        ti.endTime = t_end
        ti.verboseMode = 0
        ti.automaticStepSize = bool(settings["automatic_step_size"])
        ti.adaptiveStep = bool(settings["ga_adaptive_step"])
        ti.explicit.computeEndOfStepAccelerations = bool(settings["end_of_step_accelerations"])
        ti.generalizedAlpha.spectralRadius = float(settings[
            "constrained_spectral_radius" if system.closures or system.driven
            else "ga_spectral_radius"])
        ti.generalizedAlpha.computeInitialAccelerations = not system.driven
        ti.newton.relativeTolerance = float(settings["newton_relative_tolerance"])
        ti.newton.absoluteTolerance = float(settings["newton_absolute_tolerance"])
        ti.newton.useModifiedNewton = bool(settings["modified_newton"])
        s.solution.file.write = bool(settings["write_solution_file"])
        s.solution.file.writePeriod = t_end / steps
        # half a step: every step is recorded exactly once, immune to rounding of t
        s.solution.sensors.writePeriod = 0.5 * t_end / steps
        s.staticSolver.verboseMode = 0
        s.staticSolver.newton.numericalDifferentiation.relativeEpsilon = float(
            settings["linearization_relative_epsilon"])
        s.linearSolver.ignoreSingularJacobian = False
        return s

    def export(self, mechanism: Mechanism, coordinates: Sequence[str],
               initial_states: Mapping[str, tuple[np.ndarray, np.ndarray]],
               settings: Mapping | None = None, dt: float = 1e-3) -> tuple[str, list[str]]:
        """(a standalone Python script, what it does not reproduce): every node, object,
        marker and load of the system `simulate` builds, as the dictionaries Exudyn
        reports for them (mbs.GetObject(i), ...), added back in the same order, the
        simulation settings as their dictionary, then `SolveDynamic` and the
        description's coordinates at the end (simulators/script_export.py). Python user
        functions (force laws, prescribed motion) cannot be written out: they are left
        out of the items and listed."""
        from .script_export import exudyn_script

        name, q0, qd0 = self.export_start(initial_states)
        cfg, steps = self._run_frame(mechanism, 1.0, dt, settings)  # support and settings
        solver = self._solver_for(mechanism, cfg)
        system = _build(mechanism, *driven_start(mechanism, q0, qd0), cfg)
        mbs, data = system.mbs, system.mbs.systemData
        items = [(kind, get(i)) for kind, count, get in (
            ("Node", data.NumberOfNodes(), mbs.GetNode),
            ("Object", data.NumberOfObjects(), mbs.GetObject),
            ("Marker", data.NumberOfMarkers(), mbs.GetMarker),
            ("Load", data.NumberOfLoads(), mbs.GetLoad)) for i in range(count)]
        sim = self._simulation_settings(system, 1.0, steps)
        outside = [f"{what}: {', '.join(e.name for e in elements)}" for what, elements in (
            ("the force laws computed in Python user functions", mechanism.forces),
            ("the prescribed motions' offset user functions and the consistent start the "
             "harness computes", mechanism.prescribed)) if elements]
        text = exudyn_script(
            title=self.script_title("Exudyn", name, cfg, f", solver {solver}"),
            items=items, simulation=sim.GetDictionary(), solver=solver, node=int(system.node),
            coordinates=coordinates, T=system.geo.cmap.T, c=system.geo.cmap.c, dt=dt,
            not_in_script=outside)
        return text, outside

    def scheme(self, mechanism: Mechanism, settings: Mapping | None = None) -> Scheme:
        solver = self._solver_for(mechanism, self.resolve_settings(settings))
        return Scheme(solver, *_SOLVERS[solver])

    # --- simulation ------------------------------------------------------------------------
    def _simulate_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                       steps: int, dt: float, cfg: dict,
                       reaction_joints: tuple[str, ...]) -> Samples:
        t_run = steps * dt
        system = _build(mechanism, q0, qd0, cfg)
        geo, closures, driven = system.geo, system.closures, system.driven
        ovt = system.exu.OutputVariableType
        s_u, s_ut = (system.sensor("SensorNode", nodeNumber=system.node, outputVariableType=v)
                     for v in (ovt.Coordinates, ovt.Coordinates_t))
        # centre-of-mass accelerations of every massive body below a requested joint
        s_acc = {b: system.sensor("SensorKinematicTree", objectNumber=system.tree,
                                  linkNumber=geo.link_of[b], localPosition=list(geo.com[b]),
                                  outputVariableType=ovt.Acceleration)
                 for b in subtree_bodies(mechanism, reaction_joints)}

        def force_sensor(obj: int, output: str = "Force") -> int:
            return system.sensor("SensorObject", objectNumber=obj,
                                 outputVariableType=getattr(ovt, output))

        # engine force of every connector that can cross a requested joint; of every
        # closure constraint and prescribed coordinate (its item says which output)
        s_conn = ({name: force_sensor(obj) for name, obj in system.connectors.items()}
                  if reaction_joints else {})
        s_items = {c.name: force_sensor(c.obj, c.output) for c in (*closures, *driven)}
        system.mbs.Assemble()
        # constrained and driven runs: the implicit solver's sample at t = 0 holds its
        # consistent initial accelerations (computeInitialAccelerations)
        acc0 = (self._initial_accelerations(system, s_acc)
                if s_acc and not (closures or driven) else {})
        clock, lam0 = self._solve(system, t_run, steps)

        U, Ut = system.stored(s_u), system.stored(s_ut)
        t = U[:, 0]
        if len(t) != steps + 1 or abs(t[-1] - t_run) > 1e-9 * max(1.0, t_run):
            raise RuntimeError(f"exudyn sensors returned {len(t)} samples, expected {steps + 1}")
        u, ut = U[:, 1:], Ut[:, 1:]
        q, qd = geo.coordinates(u, ut)

        data = {name: system.stored(s) for name, s in s_items.items()}
        for k, d in enumerate(driven):  # the solver records zero multipliers at t = 0
            data[d.name][0, 1] = lam0[k]
        constraint_forces = {c.name: c.force(data[c.name], u) for c in closures}
        actuator_forces = {d.name: d.force(data[d.name], u) for d in driven}
        acc = {b: system.stored(s)[:, 1:3] for b, s in s_acc.items()}
        for b, a0 in acc0.items():  # the solver records zero accelerations at t = 0
            acc[b][0] = a0
        # Newton on each subtree: every element force from outside is taken out;
        # Exudyn's connector force is the force on marker 0 (body_a)
        connectors = {name: system.stored(s)[:, 1:3] for name, s in s_conn.items()}
        return Samples(q, qd, clock, constraint_forces=constraint_forces,
                       actuator_forces=actuator_forces, **subtree_newton(
                           mechanism, reaction_joints, t, acc, connectors, constraint_forces))

    def _bare_loop_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                        steps: int, dt: float, cfg: dict) -> BareLoop:
        """The system of `simulate` without its sensors, solved by the same solver."""
        system = _build(mechanism, q0, qd0, cfg)
        system.mbs.Assemble()
        clock = self._solve(system, steps * dt, steps)[0]
        data, current = system.mbs.systemData, system.exu.ConfigurationType.Current
        q, qd = system.geo.coordinates(*(np.array([read(configuration=current)]) for read in (
            data.GetODE2Coordinates, data.GetODE2Coordinates_t)))
        return BareLoop(clock.cpu, q[0], qd[0])

    def _solve(self, system: _System, t_run: float, steps: int
               ) -> tuple[Stopwatch, np.ndarray | None]:
        """SolveDynamic over `steps` steps of the assembled system by its solver
        (`_solver_for`), timed, and the multipliers of a driven run's consistent start,
        computed first (None for other runs)."""
        import exudyn.solver as exu_solver

        lam0 = self._consistent_start(system) if system.driven else None
        solver_type = getattr(system.exu.DynamicSolverType,
                              self._solver_for(system.mech, system.cfg))
        sim = self._simulation_settings(system, t_run, steps)
        sim.timeIntegration.solverType = solver_type
        # Python user functions allocate on every call; Exudyn then prints a speed hint
        # after the run. The hint is expected here, so it is silenced for this call only.
        threshold = exu_solver.solverCheckMemoryAllocationsThreshold
        exu_solver.solverCheckMemoryAllocationsThreshold = float("inf")
        try:
            with Stopwatch() as clock:
                system.mbs.SolveDynamic(sim, solverType=solver_type)
            return clock, lam0
        finally:
            exu_solver.solverCheckMemoryAllocationsThreshold = threshold

    def _solver_for(self, mechanism: Mechanism, cfg: dict) -> str:
        """The solver this mechanism runs: 'constrained_solver' with closure constraints,
        'driven_solver' with prescribed motion, 'solver' otherwise, checked against its
        setting. Both algebraic cases admit only implicit solvers: the explicit ones stop
        on closure constraints and silently ignore the offset of a prescribed
        coordinate."""
        key = ("constrained_solver" if mechanism.constraints
               else "driven_solver" if mechanism.prescribed else "solver")
        self.SETTINGS[key].check(self.id, key, cfg[key])
        return str(cfg[key])

    def _initial_accelerations(self, system: _System, sensors: dict) -> dict[str, np.ndarray]:
        """Centre-of-mass accelerations at t = 0 from the engine's own mass matrix and
        right-hand side (the solvers store zero accelerations for the first sample)."""
        mass, rhs, _ = self._engine_terms(system)
        system.mbs.systemData.SetODE2Coordinates_tt(
            np.linalg.solve(mass, rhs).tolist(),
            configuration=system.exu.ConfigurationType.Current)
        return {b: np.asarray(system.mbs.GetSensorValues(s))[:2] for b, s in sensors.items()}

    # --- linearization ---------------------------------------------------------------------
    def linearize(self, mechanism: Mechanism, q_eq: np.ndarray,
                  settings: Mapping | None = None, dt: float = 1e-3) -> Linearization | None:
        # Exudyn linearizes about a static state only (ComputeLinearizedSystem)
        frame = self.linearization_frame(mechanism, settings)
        if frame is None:
            return None
        cfg, autonomous = frame
        q_eq = np.asarray(q_eq, dtype=float)
        system = _build(autonomous, q_eq, np.zeros_like(q_eq), cfg)
        system.mbs.Assemble()
        M, K, D = self._tree_mkd(system)
        eps = float(cfg["linearization_relative_epsilon"])
        if mechanism.constraints:
            eig, method, extra = self._on_constraint_manifold(system, q_eq, M, K, D, eps)
        else:
            eig = quadratic_eigenvalues(M, D, K)
            how = ("two forward-difference Jacobians (eps, eps/2) Richardson-extrapolated"
                   if cfg["linearization_richardson"] else "one forward-difference Jacobian")
            method = ("exudyn mbs.ComputeLinearizedSystem (M exact; K, D from the kinematic "
                      f"tree's numerical Jacobian: {how}), first-order eigenproblem")
            extra = {"coordinates": "engine relative joint values (eigenvalues are invariant)",
                     "relative_epsilon": eps}
        return Linearization(eigenvalues=eig[np.argsort(eig.imag)], method=method, extra=extra)

    def _tree_mkd(self, system: _System) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M, K, D of the assembled tree from ``ComputeLinearizedSystem``; Exudyn
        differentiates forward (error O(eps)), so two steps (eps, eps/2) cancel that term
        when ``linearization_richardson`` is on."""
        def engine_mkd(relative_epsilon: float):
            sim = self._simulation_settings(system)
            sim.staticSolver.newton.numericalDifferentiation.relativeEpsilon = relative_epsilon
            M, K, D = system.mbs.ComputeLinearizedSystem(simulationSettings=sim)[:3]
            return np.asarray(M), np.asarray(K), np.asarray(D)

        eps = float(system.cfg["linearization_relative_epsilon"])
        M, K, D = engine_mkd(eps)
        if system.cfg["linearization_richardson"]:
            _, K2, D2 = engine_mkd(eps / 2)
            K, D = 2 * K2 - K, 2 * D2 - D
        return M, K, D

    def _on_constraint_manifold(self, system: _System, q_eq: np.ndarray, M: np.ndarray,
                                K: np.ndarray, D: np.ndarray, eps: float
                                ) -> tuple[np.ndarray, str, dict]:
        """(eigenvalues, method, extra) on the constraint manifold
        (`constraint_manifold_eigenvalues`) from the tree's M, K, D (`_tree_mkd`) and
        Exudyn's forces f and constraint Jacobian C (n x m, ``ComputeJacobianAE``): the
        null-space projection ``ComputeODE2Eigenvalues`` uses, with the constraint stiffness
        d(C lam)/du it leaves out (without it a loaded slot's frequency, the eccentric cam's,
        comes out low)."""
        cfg, cmap = system.cfg, system.geo.cmap
        u_eq = np.linalg.solve(cmap.T, q_eq - cmap.c)

        def forces_and_jacobian(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            """Exudyn's ODE2 right-hand side f and constraint Jacobian C (n x m) at u."""
            system.mbs.systemData.SetODE2Coordinates(
                u.tolist(), configuration=system.exu.ConfigurationType.Initial)
            return self._engine_terms(system, constraint_jacobian=True)[1:]

        step = float(cfg["linearization_constraint_step"])
        eig, found = constraint_manifold_eigenvalues(M, K, D, forces_and_jacobian, u_eq, step)
        how = ("Richardson-extrapolated forward differences"
               if cfg["linearization_richardson"] else "one forward difference")
        method = ("exudyn tree M, K, D (mbs.ComputeLinearizedSystem, K and D by " + how
                  + "), constraint Jacobian C (MainSolverStatic.ComputeJacobianAE), static "
                  "multipliers from C lam = f, constraint stiffness d(C lam)/du by central "
                  "differences of C; null-space (SVD) projection as in "
                  "ComputeODE2Eigenvalues, first-order eigenproblem")
        return eig, method, {"coordinates": "null space of the engine's constraint Jacobian "
                                            "(eigenvalues are invariant)",
                             "relative_epsilon": eps, **found}

    # --- flexible elements (contract point 12) ----------------------------------------------
    BEAM_ELEMENTS = {
        ANCF_CABLE: BeamElement(
            Expression(EXACT, "ObjectANCFCable2D: the Euler-Bernoulli beam element (cubic "
                              "Hermite position and slope per node, consistent mass); its "
                              "frequencies converge to the beam's from above"),
            order=4, limit="Euler-Bernoulli"),
        GEOMETRICALLY_EXACT: BeamElement(
            Expression(SOFT, "ObjectBeamGeometricallyExact2D: a shear-deformable (Reissner) "
                             "element with linear interpolation; it converges to a "
                             "Timoshenko beam, here of shear stiffness GA = "
                             f"{_GE_SHEAR_FACTOR:g} EI/l^2 and rotary inertia "
                             f"{_GE_ROTARY_FACTOR:g} rho l^2 per length, whose first "
                             "frequencies lie below Euler-Bernoulli's by about "
                             "(n pi)^2 EI / (2 GA l^2) = 5e-6 n^2 (shear) plus as much "
                             "(rotary inertia): far below the element's own error up to "
                             "N = 32"),
            order=2, limit="Timoshenko beam of large shear stiffness and small rotary inertia "
                           "(Euler-Bernoulli as GA -> infinity, rotary inertia -> 0)"),
    }

    def beam_frequencies(self, beam: Beam, kind: str, elements: int, count: int = 3,
                         settings: Mapping | None = None) -> BeamModes:
        """N elements of `kind` along x (`exudyn.beams.GenerateBeamElementsAlongLine`), the
        point mass an ``ObjectMassPoint2D`` on the node at x = a, and the frequencies from
        ``mbs.ComputeODE2Eigenvalues`` (dense, omega^2) with the supports as constrained
        coordinates: y = 0 at both end nodes. The axial coordinates (every node's x, and
        the ANCF slope's x component) are held as well: about the straight beam they
        decouple from bending, so this only removes the axial modes from the list and the
        round-off of the stiff axial terms (measured: ANCF bending frequencies equal with and
        without them to 1e-11 at EA = 1e4 EI/l^2, to 9e-9 at 1e8 EI/l^2; the geometrically
        exact element's to 3e-6, its eigensolver's round-off, at EA = 1e2..1e6 EI/l^2).
        No setting applies (no time integration)."""
        self.check_beam_request(beam, kind, elements, settings, "the eigenvalue route")
        import exudyn as exu
        import exudyn.beams
        from exudyn.itemInterface import (ObjectANCFCable2D, ObjectBeamGeometricallyExact2D,
                                          ObjectMassPoint2D)

        l, EI, rho = beam.length, beam.EI, beam.rho
        EA = _AXIAL_FACTOR * EI / l**2
        # the geometrically exact element's shear and rotary terms, reported with its modes
        terms = ({"shear_stiffness": _GE_SHEAR_FACTOR * EI / l**2,
                  "rotary_inertia_per_length": _GE_ROTARY_FACTOR * rho * l**2}
                 if kind == GEOMETRICALLY_EXACT else {})
        template = (ObjectANCFCable2D(massPerLength=rho, bendingStiffness=EI, axialStiffness=EA)
                    if kind == ANCF_CABLE else ObjectBeamGeometricallyExact2D(
                        massPerLength=rho, crossSectionInertia=terms["rotary_inertia_per_length"],
                        bendingStiffness=EI, axialStiffness=EA,
                        shearStiffness=terms["shear_stiffness"]))
        SC = exu.SystemContainer()
        mbs = SC.AddSystem()
        built = exudyn.beams.GenerateBeamElementsAlongLine(mbs, [0.0, 0.0, 0.0], [l, 0.0, 0.0],
                                                            elements, template)
        nodes = list(built["nodes"])
        if beam.point_mass > 0:
            mbs.AddObject(ObjectMassPoint2D(mass=beam.point_mass,
                                            nodeNumber=nodes[beam.node_of_point_mass(elements)]))
        mbs.Assemble()
        first = [mbs.GetNodeODE2Index(n) for n in nodes]
        # node coordinates: ANCF (x, y, x', y'), geometrically exact (x, y, theta)
        axial = first + ([i + 2 for i in first] if kind == ANCF_CABLE else [])
        held = sorted(set(axial + [first[0] + 1, first[-1] + 1]))
        with Stopwatch() as clock:
            omega2, _ = mbs.ComputeODE2Eigenvalues(constrainedCoordinates=held)
        return BeamModes.from_squared(
            omega2, count, "exudyn mbs.ComputeODE2Eigenvalues (dense, constrained "
            "coordinates: supports and axial coordinates held)",
            {"coordinates": len(omega2), "axial_stiffness": EA, "cpu_time": clock.cpu, **terms})


BACKEND = ExudynBackend()
