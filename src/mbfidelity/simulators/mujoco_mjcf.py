"""The MJCF translation of a numeric mechanism for the MuJoCo backend.

Each element kind of the description (`plan.ELEMENT_KINDS`) has one builder, registered
with `_builds` together with the `Expression`(s) it declares (contract point 5), so that
the declaration and the code that builds the element are one thing; `translate` runs the
builders over the description's elements in order, each adding MJCF fragments to a
`Build`, and `mjcf` assembles them. Body frames and joint
anchors come from `plan.body_states` at the reference configuration (every engine joint
value 0); engine joint values relate to the description coordinates by
`plan.CoordinateMap`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from ..systems.model import (
    WORLD,
    Circle,
    CoordinateForce,
    HingeClosure,
    Mechanism,
    PointOnLine,
    PointOnPoint,
    PointToPoint,
    Rectangle,
    RollingContact,
    Segment,
)
from .base import EXACT, SOFT, SUBSTITUTE, UNSUPPORTED, ElementBuilders, Expression
from .plan import (
    BODY,
    COORDINATE_FORCE_CUSTOM,
    COORDINATE_FORCE_LINEAR,
    HINGE_CLOSURE,
    LINEAR_COUPLING,
    MASSLESS_BODY,
    POINT_ON_LINE,
    POINT_ON_POINT,
    POINT_TO_POINT_CUSTOM,
    POINT_TO_POINT_LINEAR,
    PRESCRIBED,
    PRISMATIC,
    REVOLUTE,
    ROLLING_CONTACT,
    EnginePlan,
    ForceLaw,
    RollingGeometry,
    body_states,
    central_tensor,
    coupling_row,
    foldable_massless,
    joint_chains,
    length_scale,
    num,
    point_mass,
    rigid_body,
    pair_element_bodies,
    ring_of_boxes,
    rolling_geometry,
    rot,
    slider_masses,
    vec3,
)

#: what MuJoCo's soft equalities cost (docs/engines.md; the numbers per mechanism are
#: measured in the results)
SOFT_EQUALITY = (
    "MuJoCo's equality constraints are soft: the impedance is capped below 1 (solimp) and "
    "the reference time constant is tied to the step (2 dt), so each constraint force "
    "falls short of the exact one by the impedance's shortfall and a small violation makes "
    "up the rest; the constraint forces and the trajectories then carry a floor of their "
    "own, above RK4's gates, which no solref/solimp choice removes. The time constant "
    "follows the step, so the violation, and the trajectory error with it, falls as dt^2: "
    "the observed order of convergence is 2, not RK4's 4 (mbfidelity convergence).")
#: the metrics a soft closure is expected to push beyond the RK4 gates: its own force and
#: the contact forces read from it, the motion and the energy the motion carries, and the
#: order of convergence of the motion
SOFT_EQUALITY_METRICS = ("*.trajectory_*", "*.energy_drift", "*.constraint_*", "*.contact_*",
                         "convergence.order")


def _soft_equality(level: str, how: str) -> Expression:
    """The expression of a closure held by MuJoCo's soft equalities (`SOFT_EQUALITY`)."""
    return Expression(level, how, expected_failures=SOFT_EQUALITY_METRICS, reason=SOFT_EQUALITY)


def fmt(*xs: float) -> str:
    return " ".join(format(float(x), ".17g") for x in xs)


def _xyz(point) -> str:
    """A point of the description as an MJCF position."""
    return fmt(*vec3(point))


def _z_quat(angle: float) -> str:
    """An MJCF quat: a turn by `angle` about z."""
    return fmt(math.cos(angle / 2), 0, 0, math.sin(angle / 2))


def _inertial(mass: float, inertia: float, com: Sequence[float] = (0.0, 0.0)) -> str:
    """An explicit <inertial>: without one MuJoCo derives the mass from the geoms' density."""
    return (f'<inertial pos="{fmt(com[0], com[1], 0)}" mass="{fmt(mass)}" '
            f'diaginertia="{fmt(inertia, inertia, inertia)}"/>')


@dataclass
class _P2P:
    element: PointToPoint  # its spatial tendon is named after it
    native: tuple[float, float, float] | None  # (stiffness, springlength, damping)
    law: Callable[..., float]


@dataclass
class _Coord:
    element: CoordinateForce
    j: int  # description joint index (of its engine joint where the law is native)
    native: tuple[float, float, float] | None  # (a, b, c) in engine units of joint j
    law: Callable[..., float]
    #: COORD = row . (v - b) over the engine joint values v, and the joint forces are
    #: row * force
    row: np.ndarray


@dataclass
class Closure:
    """A closure constraint and its MJCF equality: ``connect`` (PointOnPoint: site1 on
    body_a, site2 on body_b), ``hinge`` (HingeClosure: that connect at the hinge point and
    a second one, ``{name}:axis``, at a point on the hinge axis), ``slider`` (PointOnLine:
    a connect between the pin's site1 and the origin site2 of a slider body that slides
    along the slot on the slot body),
    ``tendon`` (LinearCoupling: a fixed tendon sum(w_j v_j) over the engine joint values
    held at ``offset`` by a tendon equality) or ``contact`` (RollingContact: the same
    weights, no equality)."""

    element: object
    kind: str
    site1: str = ""
    site2: str = ""
    slider: str = ""  # slider body (and its slide joint) name
    weights: dict[str, float] = field(default_factory=dict)
    offset: float = 0.0
    coef: np.ndarray | None = None  # LinearCoupling: coefficients over the coordinates
    contact: RollingGeometry | None = None  # RollingContact: where its disc and ring sit


@dataclass
class _Joint:
    """An MJCF joint: its type and its axis and (hinge) position in its MJCF body's frame;
    `law`: the description joint index whose native law it carries, if any."""

    name: str
    type: str
    axis: Sequence[float]
    pos: Sequence[float] | None = None
    law: int | None = None

    def xml(self, attrs: str) -> str:
        pos = "" if self.pos is None else f' pos="{fmt(*self.pos)}"'
        return (f'<joint name="{self.name}" type="{self.type}" axis="{fmt(*self.axis)}"'
                f'{pos}{attrs}/>')


#: radius of gyration of the substitute bodies (their inertia is mass * GYRATION**2)
GYRATION = 0.01
#: the same for sliders: they turn with the slot body, whose inertia they add to
SLIDER_GYRATION = 1e-5
#: radius of gyration (m) of the inertia a point mass is given (setting
#: point_mass_gyration)
POINT_MASS_GYRATION = 1e-6
#: the least substitute inertia of a point mass (kg m^2): ten times MuJoCo's mjMINVAL
POINT_MASS_INERTIA_FLOOR = 1e-14


class Build(EnginePlan):
    """The MJCF build of a numeric mechanism, on its shared plan (`plan.EnginePlan`: the
    settings `cfg`, the map between the description coordinates q and the engine joint
    values v, the lightest body's mass): the fragments each element's builder adds (per
    MJCF body: the <body> attributes, joints, <inertial>, sites, contact geoms, slider
    bodies; the tendons and equalities) and what the callbacks and the read-outs need."""

    def __init__(self, mech: Mechanism, settings: dict, dt: float | None) -> None:
        super().__init__(mech, settings)
        chains = joint_chains(mech)
        self.foldable = chains.foldable
        self.carrier = chains.carrier  # description body -> MJCF body carrying it
        #: MJCF body -> description joint indices, in order (MuJoCo applies a body's
        #: joints in order), and its MJCF parent
        self.chains, self.mj_parent = chains.chains, chains.parent
        #: the step the file is written for (MJCF's default 0.002 s when written without one)
        self.dt = dt or 0.002
        #: linear laws as MuJoCo's own springs and dampers; the substitutes' weight cancelled
        self.native = bool(settings["native_springs"])
        self.gravcomp = bool(settings["substitute_gravcomp"])
        #: body frames at the reference configuration of the MJCF: every engine joint value 0
        self.frames = body_states(mech, self.map.T @ (-self.map.b), np.zeros(self.n))
        self.heads: dict[str, str] = {}
        self.joints: dict[str, list[_Joint]] = {}
        self.inertial: dict[str, str] = {}
        self.sites: dict[str, list[str]] = {}
        self.geoms: dict[str, list[str]] = {}
        self.sliders: dict[str, list[list[str]]] = {}
        self.p2p: list[_P2P] = []
        self.coord: list[_Coord] = []
        self.closures: list[Closure] = []
        #: substitute (mass, inertia) of massless bodies that cannot be folded
        self.substitutes: dict[str, tuple[float, float]] = {}
        #: per engine joint, the summed linear coordinate laws (a, k, c) it may carry natively
        self.joint_native: dict[int, list[float]] = {}
        self.slider_mass: dict[str, float] = {}
        self.xml = ""

    def add_site(self, body: str, name: str, pos: str) -> None:
        self.sites.setdefault(body, []).append(f'<site name="{name}" pos="{pos}"/>')

    def add_frame(self, body: str, gravcomp: bool = False) -> None:
        """The <body> attributes: its frame relative to its MJCF parent at the reference
        configuration (spatial: parent_anchor - child_anchor, model convention 10)."""
        if self.mech.spatial:
            j = self.mech.joints[self.chains[body][0]]
            pa, ca = (np.array(vec3(a)) for a in (j.parent_anchor, j.child_anchor))
            self.heads[body] = f'name="{body}" pos="{fmt(*(pa - ca))}"'
            return
        x, y, th = self.frames[body][:3]
        xp, yp, thp = self.frames[self.mj_parent[body]][:3]
        rel = rot(thp).T @ np.array([x - xp, y - yp])
        ang = th - thp
        self.heads[body] = (f'name="{body}" pos="{fmt(rel[0], rel[1], 0)}" '
                            f'quat="{_z_quat(ang)}"'
                            + (' gravcomp="1"' if gravcomp and self.gravcomp else ""))

    def anchor(self, hinge) -> np.ndarray:
        """A hinge's anchor (world) at the reference configuration."""
        x, y, th = self.frames[hinge.parent][:3]
        return np.array([x, y]) + rot(th) @ np.array([num(v) for v in hinge.parent_anchor[:2]])

    def local(self, body: str, vector: np.ndarray) -> np.ndarray:
        """A world vector in the frame of an MJCF body at the reference configuration."""
        return rot(self.frames[body][2]).T @ vector

    def coupling(self, c, kind: str, **extra) -> Closure:
        """A linear relation c . q = C as a fixed tendon over the engine joint values."""
        coef, constant = coupling_row(self.mech, c)
        w, offset = self.map.on_engine_values(coef, constant)
        weights = {self.mech.joints[i].name: float(w[i]) for i in np.flatnonzero(w)}
        return Closure(c, kind, weights=weights, offset=offset, coef=coef, **extra)


# --- element builders, each registered with its declared expression (contract point 5) --

#: element kind -> its builder (taking the `Build` and the element), with its expressions
_BUILDERS = ElementBuilders()
_builds = _BUILDERS.builds


@_builds(
    BODY,
    Expression(EXACT, "an MJCF body whose frame is the centre-of-mass frame, with an "
                      "explicit <inertial> (planar inertia on z, the same on x and y)",
               when="mass and inertia > 0", applies=rigid_body),
    Expression(SUBSTITUTE, "a point mass: an explicit <inertial> of inertia m r^2, "
                           "r the setting point_mass_gyration. MuJoCo's compiler "
                           "rejects moving bodies whose inertia is below mjMINVAL "
                           "(also when a welded child carries the mass); the "
                           "substitute changes the body's moment about any point by "
                           "m r^2, relative (r/d)^2 at a distance d",
               when="mass > 0, inertia 0", applies=point_mass),
    Expression(UNSUPPORTED, "MuJoCo rejects moving bodies with zero mass",
               when="mass 0, inertia > 0"))
def _body(build: Build, body) -> None:
    build.add_frame(body.name)
    mass, inertia = num(body.mass), num(body.inertia)
    if build.mech.spatial:  # the full central tensor (read back by `stored_inertia`)
        I = central_tensor(build.mech, body)
        build.inertial[body.name] = (
            f'<inertial pos="0 0 0" mass="{fmt(mass)}" fullinertia="'
            f'{fmt(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2])}"/>')
        return
    if inertia == 0:  # a point mass: above MuJoCo's mjMINVAL (1e-15) whatever the mass
        radius = float(build.cfg["point_mass_gyration"])
        inertia = max(mass * radius**2, POINT_MASS_INERTIA_FLOOR)
    build.inertial[body.name] = _inertial(mass, inertia)


@_builds(
    MASSLESS_BODY,
    Expression(EXACT, "folded: its joints become a chain of joints of its single "
                      "child's MJCF body, anchors and axes at the reference "
                      "configuration",
               when="one child joint, and no constraint or point force on it",
               applies=lambda mech, body: body.name in foldable_massless(mech)),
    Expression(SUBSTITUTE, "a body of small mass (link_mass_ratio of the lightest "
                           "body for a kinematic link, massless_mass_ratio where a "
                           "constraint or a point force loads it), weight cancelled: "
                           "MuJoCo rejects massless moving bodies",
               when="several child joints, or loaded by a constraint or point force"))
def _massless_body(build: Build, body) -> None:
    if body.name in build.foldable:
        return
    # a loaded one is heavier: the notes of the two settings say why
    loaded = body.name in pair_element_bodies(build.mech)
    key = "massless_mass_ratio" if loaded else "link_mass_ratio"
    mass = float(build.cfg[key]) * build.m_min
    build.substitutes[body.name] = (mass, mass * GYRATION**2)
    build.add_frame(body.name, gravcomp=True)
    build.inertial[body.name] = _inertial(mass, mass * GYRATION**2)


@_builds(REVOLUTE, Expression(EXACT, "hinge about z on the relative angle (absolute and "
                                     "clockwise coordinates through v = A q + b)"))
def _revolute(build: Build, joint) -> None:
    i, body = build.mech.joints.index(joint), build.carrier[joint.child]
    if build.mech.spatial:  # about the description's axis at child_anchor
        axis = [num(v) for v in (joint.axis if joint.axis is not None else (0, 0, 1))]
        pos = vec3(joint.child_anchor)
    else:
        axis = (0, 0, 1)
        loc = build.local(body, build.anchor(joint) - np.array(build.frames[body][:2]))
        pos = (loc[0], loc[1], 0)
    build.joints.setdefault(body, []).append(_Joint(joint.name, "hinge", axis, pos, i))


@_builds(PRISMATIC, Expression(EXACT, "slide joint in the x-y plane (limits are admissible "
                                      "intervals, not stops)"))
def _prismatic(build: Build, joint) -> None:
    i, body = build.mech.joints.index(joint), build.carrier[joint.child]
    # no MuJoCo joint limits: a limit is a soft constraint that would only act outside the
    # description's admissible interval
    axis = vec3(joint.axis)
    if not build.mech.spatial:  # the axis turns with the parent
        world = rot(build.frames[joint.parent][2]) @ np.array(axis[:2])
        ax = build.local(body, world)
        axis = (ax[0], ax[1], 0)
    build.joints.setdefault(body, []).append(_Joint(joint.name, "slide", axis, None, i))


def _point_to_point(build: Build, f: PointToPoint) -> None:
    """A spatial tendon between two sites; a law linear in LENGTH and LENGTH_RATE that
    MuJoCo's tendon spring (stiffness >= 0, free length >= 0) and damper can hold is
    native, any other the passive callback's."""
    law = ForceLaw.of(f)
    build.p2p.append(_P2P(f, law.tendon_spring if build.native else None, law.law))
    for tag, body, point in (("a", f.body_a, f.point_a), ("b", f.body_b, f.point_b)):
        build.add_site(body, f"{f.name}:{tag}", _xyz(point))


def _coordinate_force(build: Build, f: CoordinateForce) -> None:
    """Joint stiffness/springref/damping where the law is linear and its argument is one
    engine joint value (`CoordinateMap.law_target`), otherwise the passive callback."""
    law, weights = ForceLaw.of(f), f.weights(build.mech.coordinates)
    row = build.map.law_row(weights)
    j = build.mech.coordinates.index(f.coordinate)
    lin = law.linear if build.native else None
    target = build.map.law_target(weights)
    spec = None
    if lin is not None and target is not None:
        j, r = target  # COORD = r v_j: F(COORD) on COORD is r F(r v_j) on v_j
        a, kq, cq = lin
        spec = (a * r, kq * r * r, cq * r * r)
        acc = build.joint_native.setdefault(j, [0.0, 0.0, 0.0])
        acc[:] = [acc[0] + spec[0], acc[1] + spec[1], acc[2] + spec[2]]
    build.coord.append(_Coord(f, j, spec, law.law, row))


_builds(
    POINT_TO_POINT_LINEAR,
    Expression(EXACT, "spatial tendon with its own stiffness, springlength and damping "
                      "(native_springs; otherwise the passive callback)"))(_point_to_point)
_builds(POINT_TO_POINT_CUSTOM,
        Expression(EXACT, "spatial tendon, -T dL/dq from the passive callback at every "
                          "integrator stage"))(_point_to_point)
_builds(COORDINATE_FORCE_LINEAR,
        Expression(EXACT, "joint stiffness, springref and damping where the coordinate is "
                          "one engine joint, otherwise the passive callback"))(_coordinate_force)
_builds(COORDINATE_FORCE_CUSTOM,
        Expression(EXACT, "passive callback (set_mjcb_passive) at every integrator "
                          "stage"))(_coordinate_force)
_BUILDERS.builds_time_load(Expression(EXACT, "passive callback, evaluated at every RK4 stage "
                                             "at the stage time"))


@_builds(POINT_ON_POINT, _soft_equality(SOFT, "connect equality between two sites"))
def _point_on_point(build: Build, c: PointOnPoint) -> None:
    build.closures.append(Closure(c, "connect", f"{c.name}:a", f"{c.name}:b"))
    for site, body, point in ((f"{c.name}:a", c.body_a, c.point_a),
                              (f"{c.name}:b", c.body_b, c.point_b)):
        build.add_site(body, site, _xyz(point))


#: the second connect of a hinge closure sits this many times the mechanism's length
#: scale (`plan.length_scale`) along the hinge axis: the couple that keeps the axes parallel is
#: the two connects' forces times their distance, so a span much shorter than the bodies
#: softens the axis's rows (a given violation of the points is a larger tilt); a span of
#: the bodies' own size conditions them like the point's
HINGE_SPAN_FACTOR = 1.0
#: why a hinge closure's force is not reported (contract point 6: NaN)
HINGE_FORCE_INDETERMINATE = (
    "the hinge closure's force is not reported (NaN): a loop whose closure equations are "
    "redundant is statically indeterminate, so the constraint force is not determined by "
    "the motion (a self-stress of the loop can be added to it without changing any "
    "acceleration); the reference reports the least-norm multipliers and MuJoCo's soft "
    "equalities a split of their own, neither of them the mechanism's")


@_builds(HINGE_CLOSURE, _soft_equality(
    SOFT, "two connect equalities, one at the hinge point and one at a point on the hinge "
          "axis (axis_a on body_a and axis_b on body_b, taken pointing the same way): "
          "together they hold the point and the axis's direction (six rows, one of them, "
          "the axial distance, implied by the others; a loop's redundant equations more), "
          "which soft equalities tolerate (their regularisation splits the force among "
          "dependent rows). " + HINGE_FORCE_INDETERMINATE))
def _hinge_closure(build: Build, c: HingeClosure) -> None:
    span = HINGE_SPAN_FACTOR * length_scale(build.mech)
    build.closures.append(Closure(c, "hinge", f"{c.name}:a", f"{c.name}:b"))
    for tag, body, point, axis in (("a", c.body_a, c.point_a, c.axis_a),
                                   ("b", c.body_b, c.point_b, c.axis_b)):
        p, n = (np.array([num(v) for v in x], dtype=float) for x in (point, axis))
        build.add_site(body, f"{c.name}:{tag}", fmt(*p))
        build.add_site(body, f"{c.name}:axis:{tag}", fmt(*(p + span * n / np.linalg.norm(n))))


@_builds(POINT_ON_LINE, _soft_equality(
    SUBSTITUTE, "no point-on-line equality: a slider body on the slot body (slide joint "
                "along the slot) connected to the pin, its mass taken out of the pin body "
                "(exact while the constraint holds); the connect is soft"))
def _point_on_line(build: Build, c: PointOnLine) -> None:
    if c.name not in build.slider_mass:
        # a slider of a sizeable fraction of the pin body's mass keeps the connect's rows
        # well conditioned: MuJoCo's regularisation is relative to each world-axis row's
        # diagonal, and a tiny slider mass makes the row along the slot dominate and soften
        # the row across it
        substitute = build.substitutes.get(c.body, (None,))[0]
        split = slider_masses(build.mech, c.body, float(build.cfg["slider_mass_ratio"]),
                              build.m_min, substitute)
        build.slider_mass.update(split.masses)
        if split.kept is not None:
            build.inertial[c.body] = _inertial(*split.kept)
    mass = build.slider_mass[c.name]
    inertia = mass * SLIDER_GYRATION**2
    cl = Closure(c, "slider", f"{c.name}:pin", f"{c.name}:slider", f"{c.name}:slider")
    build.closures.append(cl)
    build.add_site(c.body, cl.site1, _xyz(c.point))
    # the weight of a slider on a fixed pin (it does not move) or on a substitute is cancelled
    gravcomp = (c.body == WORLD or c.body in build.substitutes) and build.gravcomp
    dr = [num(v) for v in c.direction]
    # the slot body's MJCF frame is its description frame (slot bodies are never folded):
    # the slider starts at line_point, its joint value is the distance along the unit
    # slot direction
    parent = WORLD if c.line_body == WORLD else build.carrier[c.line_body]
    build.sliders.setdefault(parent, []).append([
        f'<body name="{cl.slider}" pos="{_xyz(c.line_point)}"'
        + (' gravcomp="1">' if gravcomp else ">"),
        f'  <joint name="{cl.slider}" type="slide" axis="{fmt(dr[0], dr[1], 0)}"/>',
        "  " + _inertial(mass, inertia),
        f'  <site name="{cl.site2}"/>',
        "</body>"])


@_builds(LINEAR_COUPLING, _soft_equality(
    SOFT, "fixed tendon sum(w_j v_j) over the engine joint values held by a tendon "
          "equality (an exact linear relation; soft like every equality)"))
def _linear_coupling(build: Build, c) -> None:
    build.closures.append(build.coupling(c, "tendon"))


@_builds(ROLLING_CONTACT, Expression(SUBSTITUTE, "friction contact of a sphere disc on a ring "
                                                 "of ring_segments boxes (soft, regularised "
                                                 "friction; the arm's length freed by a "
                                                 "radial slide); its force is the contacts' "
                                                 "generalized force on the disc's coordinate "
                                                 "over its coefficient, its violation the "
                                                 "slip; linearize uses the coupling"))
def _rolling_contact(build: Build, c: RollingContact) -> None:
    mech, s = build.mech, build.cfg
    # the arm's hinge and the slide that frees its length go to the disc's MJCF body
    if c.arm not in build.foldable:
        raise ValueError(f"mujoco cannot build {c.name}: the arm {c.arm} must be a massless "
                         "link that carries the disc only")
    geo = rolling_geometry(mech, c)
    cl = build.coupling(c, "contact", slider=f"{c.name}:radial", contact=geo)
    build.closures.append(cl)
    params = (f' condim="3" friction="{fmt(s["contact_friction"], 0, 0)}" solref="'
              f'{fmt(float(s["contact_timeconst_steps"]) * build.dt, s["contact_dampratio"])}"'
              f' solimp="{fmt(*s["contact_solimp"])}"')
    disc = build.carrier[geo.inner]
    build.geoms.setdefault(disc, []).append(
        f'<geom name="{c.name}:disc" type="sphere" size="{fmt(geo.r)}" '
        f'pos="{_xyz(geo.inner_centre)}" contype="2" conaffinity="0"{params}/>')
    nseg = int(s["ring_segments"])
    # the inner faces lie at R and meet: a polygon circumscribing R
    boxes, t, half = ring_of_boxes(geo.centre, geo.R, nseg)
    for x, y, a in boxes:
        build.geoms.setdefault(build.carrier[geo.outer], []).append(
            f'<geom type="box" size="{fmt(t / 2, half, 2 * geo.r)}" '
            f'pos="{fmt(x, y, 0)}" quat="{_z_quat(a)}" '
            f'contype="0" conaffinity="2"{params}/>')
    # the arm's length is freed: the contact's normal force replaces it (a slide right
    # after the arm's hinge, along the arm)
    hinge = mech.joint_of_child(c.arm)
    anchor, hub = build.anchor(hinge), build.anchor(mech.joints[geo.hub])
    u = build.local(disc, (hub - anchor) / np.linalg.norm(hub - anchor))
    joints = build.joints[disc]
    at = next(k for k, jt in enumerate(joints) if jt.name == hinge.name)
    joints.insert(at + 1, _Joint(cl.slider, "slide", (u[0], u[1], 0)))


_builds(PRESCRIBED, Expression(EXACT, "the acceleration imposed by a control callback "
                                      "(qfrc_applied from mj_solveM, every RK4 stage at "
                                      "the stage time; setting prescribed_motion); the "
                                      "applied force is the actuator force"))(
    lambda build, p: None)  # nothing in the MJCF: the backend's control callback imposes it

#: per element kind, the expression(s) its registered builder makes, in the kinds' order
EXPRESSIONS = _BUILDERS.declared()


def translate(mech: Mechanism, settings: dict, dt: float | None = None) -> Build:
    """The build of a numeric mechanism under the (resolved) settings; `dt`: the step the
    file is written for."""
    build = Build(mech, settings, dt)
    build.build(_BUILDERS)
    # a joint can carry one stiffness/springref/damping: the summed linear laws must be a
    # spring towards a reference (b < 0) or a pure damper; otherwise use the callback
    for i, (a, k, c) in build.joint_native.items():
        if not (c <= 0 and (k < 0 or (k == 0 and a == 0))):
            for e in build.coord:
                if e.j == i:
                    e.native = None
    build.xml = mjcf(build, dt)
    return build


def _segment_geom(shape: Segment) -> str:
    # a spatial segment has three-component ends; a planar one lies at z = 0
    a, b = (vec3(end) for end in (shape.a, shape.b))
    r = num(shape.width) / 2
    if a == b:
        return f'<geom type="sphere" size="{fmt(r)}" pos="{fmt(*a)}"/>'
    return f'<geom type="capsule" size="{fmt(r)}" fromto="{fmt(*a, *b)}"/>'


def _rectangle_geom(shape: Rectangle) -> str:
    w, h = num(shape.width), num(shape.height)
    return (f'<geom type="box" size="{fmt(w / 2, h / 2, min(w, h) / 4)}" '
            f'pos="{_xyz(shape.center)}"/>')


_SHAPE_GEOMS = {
    Segment: _segment_geom,
    Circle: lambda s: f'<geom type="sphere" size="{fmt(num(s.radius))}" pos="{_xyz(s.center)}"/>',
    Rectangle: _rectangle_geom,
}


def mjcf(build: Build, dt: float | None = None) -> str:
    """The MJCF text of a build, from the fragments its builders made, with the
    integrator, the contact solver options and the flags of its settings and, when given,
    the time step `dt`."""
    mech = build.mech
    native_joint = {e.j for e in build.coord if e.native is not None}

    def law(i: int | None) -> str:
        """MuJoCo's own spring and damper of the linear law a + k v + c v' on joint i."""
        if i not in native_joint:
            return ""
        a, k, c = build.joint_native[i]
        ref = -a / k if k != 0 else 0.0
        return f' stiffness="{fmt(-k)}" springref="{fmt(ref)}" damping="{fmt(-c)}"'

    def indent(depth: int, lines) -> list[str]:
        return [f"{'  ' * depth}{x}" for x in lines]

    def inside(name: str) -> list[str]:
        """What an MJCF body (or the world) holds after its own elements: its sites, its
        child bodies, its sliders."""
        lines = list(build.sites.get(name, []))
        for child in build.chains:
            if build.mj_parent[child] == name:
                lines += [f"<body {build.heads[child]}>"]
                lines += indent(1, [jt.xml(law(jt.law)) for jt in build.joints[child]]
                                + [build.inertial[child]]
                                + [_SHAPE_GEOMS[type(s)](s) for s in mech.body(child).shapes]
                                + build.geoms.get(child, []) + inside(child))
                lines += ["</body>"]
        return lines + [x for slider in build.sliders.get(name, []) for x in slider]

    s = build.cfg
    equalities = [cl for cl in build.closures if cl.kind != "contact"]
    option = (f'integrator="{s["integrator"]}" cone="{s["contact_cone"]}" '
              f'impratio="{fmt(s["impratio"])}" '
              f'noslip_iterations="{int(s["noslip_iterations"])}"'
              + (f' timestep="{fmt(dt)}"' if dt else ""))
    flags = ['contact="disable"'] if not build.geoms else ['contact="enable"',
                                                            'filterparent="disable"']
    flags += [flag for flag, on in (
        ('autoreset="disable"', not s["autoreset"]), ('refsafe="disable"', not s["refsafe"]),
        ('diagexact="enable"', s["diagexact"])) if on]
    out = [
        '<mujoco model="mbfidelity">',
        '  <compiler angle="radian" inertiafromgeom="false"/>',
        f'  <option {option} gravity="{fmt(*build.gravity_vector)}">',
        f'    <flag {" ".join(flags)}/>',
        "  </option>",
        '  <default><geom contype="0" conaffinity="0" rgba="0.4 0.6 0.8 1"/></default>',
        "  <worldbody>",
    ]
    out += indent(2, inside(WORLD))
    out.append("  </worldbody>")
    couplings = [cl for cl in build.closures if cl.kind in ("tendon", "contact")]
    if build.p2p or couplings:
        out.append("  <tendon>")
        for cl in couplings:
            out.append(f'    <fixed name="{cl.element.name}">')
            out += [f'      <joint joint="{jn}" coef="{fmt(w)}"/>' for jn, w in cl.weights.items()]
            out.append("    </fixed>")
        for e in build.p2p:
            k, l0, c = e.native if e.native is not None else (0.0, 0.0, 0.0)
            out += [f'    <spatial name="{e.element.name}" stiffness="{fmt(k)}" '
                    f'springlength="{fmt(l0, l0)}" damping="{fmt(c)}">',
                    f'      <site site="{e.element.name}:a"/>',
                    f'      <site site="{e.element.name}:b"/>',
                    "    </spatial>"]
        out.append("  </tendon>")
    if equalities:
        tau = float(s["constraint_timeconst_steps"]) * build.dt
        soft = (f' solref="{fmt(tau, s["constraint_dampratio"])}"'
                f' solimp="{fmt(*s["constraint_solimp"])}"')
        out.append("  <equality>")
        for cl in equalities:
            name = cl.element.name
            out.append(f'    <tendon name="{name}" tendon1="{name}" '
                       f'polycoef="{fmt(cl.offset, 0, 0, 0, 0)}"{soft}/>' if cl.kind == "tendon"
                       else f'    <connect name="{name}" site1="{cl.site1}" '
                            f'site2="{cl.site2}"{soft}/>')
            if cl.kind == "hinge":
                out.append(f'    <connect name="{name}:axis" site1="{name}:axis:a" '
                           f'site2="{name}:axis:b"{soft}/>')
        out.append("  </equality>")
    out.append("</mujoco>")
    return "\n".join(out) + "\n"
