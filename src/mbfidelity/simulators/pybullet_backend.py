"""PyBullet backend: a reduced-coordinate Featherstone multibody (``createMultiBody``) with
a fixed base at the world origin, one link per joint (its engine joint value ``v = A q +
b``, `plan.CoordinateMap`), no collision shapes and explicit inertias.

Translation (generic over the description, conventions 1-8 of `systems.model`): each
element kind of the description (`plan.ELEMENT_KINDS`) has one builder, registered together
with the expressions it builds (`_builds`; `EXPRESSIONS` is that registry's declarations),
which puts the element into `_Translation`, the mechanism in PyBullet's terms; each closure
is one class per PyBullet construct (`_Pin`, `_Slider`, `_Rotor`, `_Gear`) that gives its
constraint's frames, places its extra link, and turns the engine's constraint rows into the
contract's force (signs measured, in each class).

Closure constraints (``createConstraint``) are solved with the velocity-level projected
Gauss-Seidel of the multibody solver (setting constraint_erp), then q_{k+1} = q_k + dt
v_{k+1}: exact for linear constraints, first order otherwise. Their forces are read with
``getConstraintState`` after a step (impulse / dt of that step, so they belong to the
state before it). Because the projection is velocity level, a constraint's curvature term
(centripetal J'v) enters the force one step late, through the position error: a run that
starts fast on a curved constraint reports at the first sample a force lacking J'v (and
half of it too much at the second); afterwards the forces are first-order accurate.

Reactions (setting reaction_method): by default the engine's own inverse dynamics on a
copy of the model (`_inverse_dynamics_forces`), which applies no element and no closure,
so that `reactions.joint_reaction` takes out the forces that reach the child's subtree
from outside.
"""
from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Callable, Iterator, Mapping, Sequence

import numpy as np

from ..analytic.modes import quadratic_eigenvalues
from ..systems.model import WORLD, LinearCoupling, Mechanism
from .base import (EXACT, NO_BEAM_ELEMENT, SEMI_IMPLICIT_EULER_STABILITY, SUBSTITUTE,
                   UNSUPPORTED, Backend, BareLoop, BeamElement, ElementBuilders, Expression,
                   Linearization, Samples, Scheme, Setting, Stopwatch, central_differences)
from .plan import (BODY, COORDINATE_FORCE_CUSTOM, COORDINATE_FORCE_LINEAR, HINGE_CLOSURE,
                   LINEAR_COUPLING, MASSLESS_BODY, POINT_ON_LINE, POINT_ON_POINT,
                   POINT_TO_POINT_CUSTOM, POINT_TO_POINT_LINEAR, PRESCRIBED, PRISMATIC,
                   REVOLUTE, ROLLING_CONTACT, EnginePlan, PairLoad, RollingGeometry,
                   SlotGeometry, carries_child, central_tensor, couples_two_engine_values,
                   element_kind, engine_coupling, held_by_closure, num,
                   one_joint_value, pair_load, parents_first, plane_point,
                   principal_inertia, ring_of_boxes, rolling_contact_report, rolling_geometry,
                   slide_axis, slot_geometry, spatial_tree_reason, turned, unit_axis, vec3)
from .reactions import outside_forces

_POINT_FORCE = ("applyExternalForce at both points every step, from the engine's link "
                "states at the start of the step (the single stage of its semi-implicit "
                "Euler)")
_JOINT_FORCE = ("joint force through setJointMotorControlArray(TORQUE_CONTROL) every step, "
                "tau = A^-T Q")
#: createMultiBody keeps the first 127 links and drops the rest without an error (measured)
_MAX_LINKS = 127


def _quat_z(angle: float) -> list[float]:
    """Quaternion (x, y, z, w) of a rotation by `angle` about z."""
    return [0.0, 0.0, math.sin(angle / 2.0), math.cos(angle / 2.0)]


def _pose(ls, link: int) -> tuple[float, float, float, float, float, float]:
    """(x, y, theta, vx, vy, omega) of a link's centre-of-mass frame from its link state
    (`ls[link]`; -1: the base; without velocities in the state they are zero)."""
    if link < 0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    st = ls[link]
    com, quat = st[0], st[1]
    vel, omega = (st[6], st[7][2]) if len(st) > 6 else ((0.0, 0.0, 0.0), 0.0)
    return com[0], com[1], 2.0 * math.atan2(quat[2], quat[3]), vel[0], vel[1], omega


@dataclass
class _Link:
    """A link of the multibody: one per description joint, then the extra links (a rotor,
    a slider, the contact's radial slider), whose frame is aligned with the parent's and
    whose centre of mass is at its origin (the defaults)."""

    name: str          # joint name
    parent: int        # translation link index of the parent body, -1 for the world
    revolute: bool
    mass: float
    inertia: float
    position: list[float]          # joint frame origin in the parent's link frame
    axis: list[float]               # joint axis in the joint (= link) frame
    body: str = ""     # child body of a description joint
    #: joint frame orientation in the parent's link frame
    orientation: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0, 1.0])
    #: centre of mass in the link frame
    inertial_position: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    #: a spatial body's principal moments and the quaternion of its principal axes in the
    #: link frame (None: the planar inertia on every axis, identity frame)
    principal: tuple[list[float], list[float]] | None = None


@dataclass
class _PointForce:
    """A point-to-point element (`plan.PairLoad`) on the links `link_a`, `link_b` (-1:
    world)."""

    pair: PairLoad
    link_a: int
    link_b: int

    def force(self, ls, t: float) -> tuple[float, float, float, float, float, float]:
        """(force on b x, y, point a x, y, point b x, y) from link states (`ls[link]`);
        the force on a is opposite."""
        return self.pair.force({self.pair.body_a: _pose(ls, self.link_a),
                                self.pair.body_b: _pose(ls, self.link_b)}, t)


def _slider_row_normal(u: np.ndarray) -> tuple[float, float]:
    """The in-plane linear row of btMultiBodySliderConstraint, in the parent (slot) frame:
    c0 = (first frame column e_i with |e_i x u| > 1e-6) x u, normalised (here +-z), and
    row 1 = u x c0 (row 0 = c0 is out of plane, its Jacobian vanishes)."""
    u3 = np.array([u[0], u[1], 0.0])
    for e in np.eye(3):
        c0 = np.cross(e, u3)
        if np.linalg.norm(c0) > 1e-6:
            c0 = c0 / np.linalg.norm(c0)
            c1 = np.cross(u3, c0)
            c1 = c1 / np.linalg.norm(c1)
            return float(c1[0]), float(c1[1])
    raise ValueError("zero slot direction")


# --- closure constraints: one class per PyBullet construct ---------------------------


@dataclass
class _Closure:
    """A closure constraint: one PyBullet constraint (`frames`, `options`) from the link
    `parent` to the link `child` (translation link indices, -1 = the fixed base)."""

    element: object
    parent: int
    child: int
    #: its child pivot is moved under the pin before every step
    follows_pin = False

    def options(self, cfg: dict) -> dict:
        """changeConstraint's keywords."""
        return {"maxForce": float(cfg["constraint_max_force"])}

    def place(self, p, cid: int, body: int, eidx: list[int], ls) -> None:
        """Set the state of its extra link from the description state (none here)."""


@dataclass
class _Pin(_Closure):
    """PointOnPoint: JOINT_POINT2POINT, parent = body_a's link at point_a, child =
    body_b's link at point_b (points in centre-of-mass frames = the description's body
    frames). Its rows along world x, y, z hold the force on the CHILD (a bar held at its
    tip by the base, bar = parent, reads -m g / 2): the contract's force on body_a (the
    parent) is minus the rows."""

    parent_point: tuple[float, float]
    child_point: tuple[float, float]

    def frames(self, p) -> tuple:
        """createConstraint's joint type, axis and parent and child pivots."""
        return p.JOINT_POINT2POINT, [0, 0, 0], vec3(self.parent_point), vec3(self.child_point)

    def force(self, rows: np.ndarray, q: np.ndarray, model: _Translation) -> np.ndarray:
        """getConstraintState rows (N, 6) -> the contract's force (signs measured)."""
        return -rows[:, :2]


@dataclass
class _Slot(_Pin):
    """PointOnLine: its geometry (`slot`), the links of the pin's body (`pin_link`) and
    of the slot body (`line_link`), and the extra link `aux`."""

    slot: SlotGeometry
    pin_link: int
    line_link: int
    aux: int

    def _states(self, ls) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """The frame states of the pin's body and of the slot body, from link states."""
        return _pose(ls, self.pin_link), _pose(ls, self.line_link)


@dataclass
class _Slider(_Slot):
    """PointOnLine, setting point_on_line = 'slider': a slider link (prismatic along the
    slot, small mass) on the slot body and a JOINT_POINT2POINT pin (parent) - slider
    (child); its force on the pin (parent) is minus the rows."""

    def place(self, p, cid: int, body: int, eidx: list[int], ls) -> None:
        """The slider sits under the pin and moves with it along the slot
        (`SlotGeometry.along`)."""
        p.resetJointState(body, eidx[self.aux], *self.slot.along(*self._states(ls)),
                          physicsClientId=cid)


@dataclass
class _Rotor(_Slot):
    """PointOnLine (default; built as its registered expression says): JOINT_PRISMATIC,
    rotor = parent (axis along the slot), slot body = child, has one in-plane row normal to
    the slot plus a row locking the rotor's angle to the slot body's. Row 1 is the
    in-plane normal of the slot (`_slider_row_normal`, turned with the slot body) and holds
    the force on the PARENT (checked with either body as parent on the scotch yoke); the
    parent is the rotor, i.e. the pin: the contract's force is + row 1 times that normal."""

    follows_pin = True

    def frames(self, p) -> tuple:
        return (p.JOINT_PRISMATIC, [*self.slot.direction, 0.0], [0.0, 0.0, 0.0],
                vec3(self.child_point))

    def place(self, p, cid: int, body: int, eidx: list[int], ls) -> None:
        """The rotor turned to the slot body's angle, th_slot - th_pin, at the relative
        rate w_slot - w_pin."""
        (_, _, th_p, _, _, w_p), (_, _, th_l, _, _, w_l) = self._states(ls)
        rel = math.remainder(th_l - th_p, 2.0 * math.pi)
        p.resetJointState(body, eidx[self.aux], rel, w_l - w_p, physicsClientId=cid)

    def force(self, rows: np.ndarray, q: np.ndarray, model: _Translation) -> np.ndarray:
        th = model.map.angle(self.slot.line_body, q)  # the world's: 0
        return rows[:, 1:2] * turned(th, *_slider_row_normal(self.slot.direction))

    def pivot(self, ls) -> list[float]:
        """The slot body's point under the pin (its projection on the slot line), in the
        slot body's frame: L + ((P - L) . u) u (why: the setting point_on_line's note)."""
        return [*self.slot.line_point_at(self.slot.position_along(*self._states(ls))), 0.0]


@dataclass
class _Gear(_Closure):
    """LinearCoupling: JOINT_GEAR jv[a] + ratio jv[b] = target between engine joints a =
    `parent` and b = `child`. Its one row f gives the joint forces f (1, ratio) on (a, b)
    (checked against inverse dynamics), i.e. (f / w_a) w = A^-T c f / w_a: the coupling's
    generalized force is c f / w_a and -lambda = f / w_a (`scale` = w_a)."""

    ratio: float
    target: float
    scale: float

    def frames(self, p) -> tuple:
        return p.JOINT_GEAR, [0, 0, 1], [0, 0, 0], [0, 0, 0]

    def options(self, cfg: dict) -> dict:
        kw = {"gearRatio": self.ratio, "maxForce": float(cfg["constraint_max_force"])}
        erp = float(cfg["gear_erp"])
        if erp:
            kw.update(erp=erp, relativePositionTarget=self.target)
        return kw

    def force(self, rows: np.ndarray, q: np.ndarray, model: _Translation) -> np.ndarray:
        return rows[:, :1] / self.scale


class _Translation(EnginePlan):
    """The mechanism in PyBullet's terms, built element by element by the builders
    registered per element kind (`_BUILDERS`) on the shared plan (`plan.EnginePlan`):
    `links`, one per description joint (the first `n`), then the extra links (the rolling
    contact's radial slider, one rotor or slider per PointOnLine); the `closures`, the
    point-to-point elements (`point_forces`) and the rolling `contact`."""

    def __init__(self, mech: Mechanism, cfg: Mapping) -> None:
        super().__init__(mech, cfg)
        self.link_of: dict[str, int] = {WORLD: -1}
        self.anchor_of: dict[str, tuple[float, float]] = {WORLD: (0.0, 0.0)}
        self.inertia_of: dict[str, tuple[float, float]] = {}  # body -> (mass, inertia)
        self.links: list[_Link] = []
        self.closures: list[_Pin | _Gear] = []
        self.point_forces: list[_PointForce] = []
        self.contact: RollingGeometry | None = None
        self.coupling: LinearCoupling | None = None  # the rolling coupling a contact stands for
        self.radial_link = -1
        self.fixed_links: list[int] = []  # engine links of the contact ring (`_build`)
        self.build(_BUILDERS)
        self.point_links = sorted({lk for pf in self.point_forces
                                   for lk in (pf.link_a, pf.link_b) if lk >= 0})


# --- the builders, registered per element kind with the expressions they build ---------
# (contract point 5), each building an element of its kind into the `_Translation`

_BUILDERS = ElementBuilders()
_builds = _BUILDERS.builds


@_builds(BODY, Expression(EXACT, "a link of the reduced-coordinate multibody with the "
                                 "explicit mass and central inertia (changeDynamics), "
                                 "no collision shape"))
def _massive_body(model: _Translation, body) -> None:
    model.inertia_of[body.name] = (num(body.mass), num(body.inertia))


@_builds(MASSLESS_BODY,
         Expression(EXACT, "a link of mass 0 and inertia 0: the articulated-body algorithm "
                           "inverts only each joint's articulated inertia, which its child "
                           "carries", when="it carries a child", applies=carries_child),
         Expression(SUBSTITUTE, "a small mass and inertia (massless_leaf_mass_ratio of the "
                                "smallest body's), since zero would make the articulated-"
                                "body algorithm singular",
                    when="it carries nothing but a closure constraint holds it",
                    applies=held_by_closure),
         Expression(UNSUPPORTED, "a massless link that carries nothing is singular for the "
                                 "articulated-body algorithm",
                    when="it carries nothing and no constraint holds it"))
def _massless_body(model: _Translation, body) -> None:
    mass, inertia = float(model.cfg["massless_link_mass"]), 0.0
    if not carries_child(model.mech, body) and held_by_closure(model.mech, body):
        ratio = float(model.cfg["massless_leaf_mass_ratio"])
        hinged = element_kind(model.mech.joint_of_child(body.name)) == REVOLUTE
        mass, inertia = ratio * model.m_min, ratio * model.i_min if hinged else 0.0
    model.inertia_of[body.name] = (mass, inertia)


@_builds(REVOLUTE, Expression(EXACT, "revolute link about z, the joint frame turned by "
                                     "angle_offset"))
@_builds(PRISMATIC, Expression(EXACT, "prismatic link along the unit axis (its length in "
                                      "v = A q + b)"))
def _joint_link(model: _Translation, j) -> None:
    """The link of description joint j: its URDF frame at the joint's anchor on the
    parent, turned by the angle offset (a slide's axis in the x-y plane of that frame,
    `plan.slide_axis`); its inertial frame at -child_anchor, so that it is the body frame
    (origin at the centre of mass). In a spatial open tree (model convention 10;
    `translation_reason` bounds the cases) the joint frame is aligned with the parent (no
    orientation offset), the hinge turns about the description's axis and the body's full
    tensor is given by its principal moments and axes."""
    parent, panchor = model.link_of[j.parent], model.anchor_of[j.parent]
    if model.mech.spatial:
        body = model.mech.body(j.child)
        pa, ca = np.array(vec3(j.parent_anchor)), np.array(vec3(j.child_anchor))
        tensor = central_tensor(model.mech, body)
        model.links.append(_Link(
            name=j.name, body=j.child, parent=parent, revolute=True, mass=num(body.mass),
            inertia=float(tensor[2, 2]), axis=list(unit_axis(j)),
            position=[float(v) for v in pa - np.array([*panchor, 0.0][:3])],
            inertial_position=[float(v) for v in -ca], principal=principal_inertia(tensor)))
        model.anchor_of[j.child] = tuple(-v for v in model.links[-1].inertial_position)
    else:
        pa, ca = plane_point(j.parent_anchor), plane_point(j.child_anchor)
        mass, inertia = model.inertia_of[j.child]
        revolute = element_kind(j) == REVOLUTE
        model.links.append(_Link(
            name=j.name, body=j.child, parent=parent, revolute=revolute, mass=mass,
            inertia=inertia, position=[pa[0] - panchor[0], pa[1] - panchor[1], 0.0],
            orientation=_quat_z(num(j.angle_offset)), inertial_position=[-ca[0], -ca[1], 0.0],
            axis=[0.0, 0.0, 1.0] if revolute else [*slide_axis(j), 0.0]))
        model.anchor_of[j.child] = ca
    model.link_of[j.child] = model.mech.joints.index(j)


@_builds(POINT_TO_POINT_LINEAR, Expression(EXACT, _POINT_FORCE))
@_builds(POINT_TO_POINT_CUSTOM, Expression(EXACT, _POINT_FORCE))
def _point_force(model: _Translation, f) -> None:
    model.point_forces.append(_PointForce(pair_load(model.mech, f), model.link_of[f.body_a],
                                          model.link_of[f.body_b]))


@_builds(COORDINATE_FORCE_LINEAR, Expression(EXACT, _JOINT_FORCE))
@_builds(COORDINATE_FORCE_CUSTOM, Expression(EXACT, _JOINT_FORCE))
def _coordinate_force(model: _Translation, f) -> None:
    """Nothing to build: the plan's coordinate laws are applied before every step."""


_BUILDERS.builds_time_load(Expression(EXACT, "evaluated at the time of the start of each "
                                              "step, the single stage of the semi-implicit "
                                              "Euler step"))


@_builds(POINT_ON_POINT, Expression(EXACT, "JOINT_POINT2POINT, solved at velocity level with "
                                           "erp 1 (no regularisation; the position error of "
                                           "a step is removed in the next)"))
def _point_on_point(model: _Translation, c) -> None:
    model.closures.append(_Pin(c, model.link_of[c.body_a], model.link_of[c.body_b],
                               plane_point(c.point_a), plane_point(c.point_b)))


@_builds(POINT_ON_LINE, Expression(SUBSTITUTE, "a rotor link on the pin (revolute, no mass, "
                                               "inertia rotor_inertia_ratio of the smallest) "
                                               "and a JOINT_PRISMATIC rotor -> slot body whose "
                                               "pivot follows the pin: the rotor's inertia is "
                                               "the only substitute (point_on_line='slider': "
                                               "a slider link of small mass)"))
def _point_on_line(model: _Translation, c) -> None:
    slot = slot_geometry(c)
    lp, pp = slot.line_point, slot.pin_point
    lpin, lline = model.link_of[c.body], model.link_of[c.line_body]
    k = len(model.links)
    geo = dict(slot=slot, pin_link=lpin, line_link=lline, aux=k)
    if model.cfg["point_on_line"] == "slider":
        anchor = model.anchor_of[c.line_body]
        mass = float(model.cfg["slider_mass_ratio"]) * model.m_min
        model.links.append(_Link(f"{c.name}:slider", lline, False, mass, 0.0,
                                 [lp[0] - anchor[0], lp[1] - anchor[1], 0.0],
                                 [*slot.direction, 0.0]))
        model.closures.append(_Slider(c, lpin, k, pp, (0.0, 0.0), **geo))
    else:
        anchor = model.anchor_of[c.body]
        inertia = float(model.cfg["rotor_inertia_ratio"]) * model.i_min
        model.links.append(_Link(f"{c.name}:rotor", lpin, True, 0.0, inertia,
                                 [pp[0] - anchor[0], pp[1] - anchor[1], 0.0], [0.0, 0.0, 1.0]))
        model.closures.append(_Rotor(c, k, lline, (0.0, 0.0), lp, **geo))


@_builds(LINEAR_COUPLING,
         Expression(EXACT, "JOINT_GEAR on the two engine joint values it involves, solved at "
                           "velocity level (exact for a linear constraint)",
                    when="two engine joint values", applies=couples_two_engine_values),
         Expression(UNSUPPORTED, "PyBullet's JOINT_GEAR constrains exactly two joints "
                                 "(jv_a + ratio jv_b = target); its gearAuxLink only adds that "
                                 "joint's current velocity as a target, it is not a three-term "
                                 "constraint, and a one-joint coupling would be a lock",
                    when="one, or three or more, engine joint values"))
def _linear_coupling(model: _Translation, c) -> None:
    w, rhs = engine_coupling(model.mech, c)
    nz = np.flatnonzero(w)
    if len(nz) != 2:  # guarded by support()
        raise ValueError(f"coupling {c.name}: {len(nz)} engine joints")
    ia, ib = sorted(nz, key=lambda i: -abs(w[i]))
    model.closures.append(_Gear(c, int(ia), int(ib), ratio=float(w[ib] / w[ia]),
                                target=float(rhs / w[ia]), scale=float(w[ia])))


# --- rolling by friction contact (a variant's stand-in for a rolling coupling) ---------


@_builds(ROLLING_CONTACT, Expression(SUBSTITUTE, "friction contact of a sphere disc on a ring "
                                                 "of contact_ring_boxes boxes (velocity-level "
                                                 "contact with erp; the hub on a massless "
                                                 "radial slider); its force is the tangential "
                                                 "contact force, its violation the slip"))
def _rolling_contact(model: _Translation, c) -> None:
    """The disc's hub rides on a massless radial slider on the arm, so that the contact,
    not the arm, carries the normal force (shapes and friction: `_contact_shapes`)."""
    model.contact, model.coupling = rolling_geometry(model.mech, c), c.coupling
    hub = model.links[model.contact.hub]
    k = len(model.links)
    model.links.append(_Link(f"{model.contact.coupling}:radial", hub.parent, False, 0.0, 0.0,
                             list(hub.position), [*model.contact.radial, 0.0]))
    hub.parent, hub.position = k, [0.0, 0.0, 0.0]
    model.radial_link = k


def _contact_shapes(p, cid: int, model: _Translation, cfg: dict
                    ) -> tuple[dict[int, int], tuple[int, list[int]]]:
    """Collision shapes of the contact variant: on the track, a ring of boxes whose
    inner faces are tangent to the track circle (a regular polygon with the circle as
    its incircle); on the disc, a sphere of the disc's radius centred on it (sphere-box
    contacts are analytic in Bullet). Shape frames are relative to the link (joint)
    frame, not to the centre of mass (measured with getAABB)."""
    ct = model.contact
    n_box = int(cfg["contact_ring_boxes"])
    if n_box < 8:
        raise ValueError("contact_ring_boxes must be at least 8")
    lo, li = model.link_of[ct.outer], model.link_of[ct.inner]
    off = model.links[lo].inertial_position  # body frame -> link frame: + this
    boxes, thick, half_len = ring_of_boxes((ct.centre[0] + off[0], ct.centre[1] + off[1]),
                                           ct.R, n_box)
    pos = [[x, y, 0.0] for x, y, _ in boxes]
    orn = [_quat_z(a) for _, _, a in boxes]
    half = [[thick / 2.0, half_len * 1.001, 2.0 * ct.r] for _ in boxes]
    # createCollisionShapeArray keeps only the first 16 children (measured with
    # getCollisionShapeData): the ring is split into compounds of 16 boxes, each on
    # its own massless fixed link on the track
    ring = []
    for k0 in range(0, n_box, 16):
        sl = slice(k0, min(k0 + 16, n_box))
        ring.append(p.createCollisionShapeArray(
            [p.GEOM_BOX] * len(half[sl]), halfExtents=half[sl],
            collisionFramePositions=pos[sl], collisionFrameOrientations=orn[sl],
            physicsClientId=cid))
    off = model.links[li].inertial_position
    disc = p.createCollisionShape(
        p.GEOM_SPHERE, radius=ct.r, collisionFramePosition=[
            ct.inner_centre[0] + off[0], ct.inner_centre[1] + off[1], 0.0],
        physicsClientId=cid)
    if min(ring) < 0 or disc < 0:
        raise RuntimeError("pybullet could not create the contact shapes")
    return {li: disc}, (lo, ring)

def _contact_dynamics(p, cid: int, body: int, eidx: list[int], model: _Translation,
                      cfg: dict) -> None:
    """Friction and contact solver parameters (Bullet combines the two links'
    friction coefficients by product: the disc gets 1, the track the setting)."""
    ct = model.contact
    disc = eidx[model.link_of[ct.inner]]
    for link, mu in [(e, float(cfg["contact_friction"])) for e in model.fixed_links] + [
            (disc, 1.0)]:
        for key, value in (("lateralFriction", mu), ("spinningFriction", 0.0),
                           ("rollingFriction", 0.0), ("restitution", 0.0)):
            p.changeDynamics(body, link, physicsClientId=cid, **{key: value})
    # only the disc and the ring collide (the ring's compounds overlap each other)
    for e in model.fixed_links:
        p.setCollisionFilterGroupMask(body, e, 1, 2, physicsClientId=cid)
    p.setCollisionFilterGroupMask(body, disc, 2, 1, physicsClientId=cid)
    p.setPhysicsEngineParameter(
        contactERP=float(cfg["contact_erp"]), frictionERP=float(cfg["contact_erp"]),
        contactSlop=0.0, restitutionVelocityThreshold=0.0,
        contactBreakingThreshold=float(cfg["contact_breaking_threshold"]),
        physicsClientId=cid)

def _contact_force(points, ring: set[int], disc: int) -> tuple[float, float, float]:
    """Force of the track on the disc (world x, y) summed over the contact points of
    the step, and the number of points. Bullet's normal on B points towards A; the
    normal and friction impulses push A along +n, +dir and B along -n, -dir."""
    fx = fy = 0.0
    count = 0
    for cp in points:
        la, lb = cp[3], cp[4]
        if la in ring and lb == disc:
            sign = -1.0
        elif la == disc and lb in ring:
            sign = 1.0
        else:
            continue
        nrm, fn = cp[7], cp[9]
        d1, f1, d2, f2 = cp[11], cp[10], cp[13], cp[12]
        fx += sign * (fn * nrm[0] + f1 * d1[0] + f2 * d2[0])
        fy += sign * (fn * nrm[1] + f1 * d1[1] + f2 * d2[1])
        count += 1
    return fx, fy, float(count)


_builds(PRESCRIBED,
        Expression(EXACT, "the joint's VELOCITY_CONTROL motor driven to (q(t+h) - q)/h with a "
                          "force that never saturates (prescribed_motion): the coordinate "
                          "lands on q(t+h) at every step; actuator force from getJointState",
                   when="the coordinate is one engine joint value", applies=one_joint_value),
        Expression(UNSUPPORTED, "the coordinate is a sum of engine joint values (an absolute "
                                "angle on a turning parent): one joint motor cannot impose "
                                "it without the parent's angle at t+h before the step",
                   when="otherwise"))(
    lambda model, prescribed: None)  # the plan's motion (`EnginePlan.driven`) drives its motor


_BUILDERS.refuses(HINGE_CLOSURE, "the spatial build closes no loop: a spatial closed loop "
                                  "has no constraint in it", "pybullet")


@dataclass
class _World:
    """A PyBullet client with the mechanism built and its initial state set
    (`PyBulletBackend._open`)."""

    cid: int
    body: int
    eidx: list[int]  # engine link index of each translation link
    model: _Translation
    cids: list[int]  # the PyBullet constraint of each closure


class PyBulletBackend(Backend):
    id = "pybullet"
    SETTINGS = {
        "joint_velocity_motors": Setting(
            False, bool,
            "False: every joint's default velocity motor (target 0) is switched off with "
            "VELOCITY_CONTROL force=0. PyBullet's default (True here) locks the joints "
            "(bullet3 #2463). Engine default: PyBullet Quickstart Guide, "
            "setJointMotorControl2: 'by default, each revolute joint and prismatic joint "
            "is motorized using a velocity motor'.",
            engine_default=True),
        "linear_damping": Setting(
            0.0, float,
            "Replaces the engine default (a velocity-proportional plus quadratic drag on "
            "every link: it takes energy out of every motion and lengthens the period of "
            "every swing; the out-of-the-box study measures by how much). Set with its own "
            "changeDynamics call: PyBullet's body-level setters (linearDamping, "
            "angularDamping, maxJointVelocity) reset the link index to -1, so "
            "mass/inertia passed in the same call land on the base (it becomes a floating "
            "base). Engine default: PyBullet Quickstart Guide, changeDynamics: "
            "linearDamping 'linear damping of the link (0.04 by default)'.",
            engine_default=0.04),
        "angular_damping": Setting(
            0.0, float,
            "Replaces the engine default (see linear_damping). Engine default: "
            "PyBullet Quickstart Guide, changeDynamics: angularDamping 'angular damping of "
            "the link (0.04 by default)'.",
            engine_default=0.04),
        "max_joint_velocity": Setting(
            1.0e6, float,
            "Replaces the engine default clamp on every joint rate (rad/s or m/s), which "
            "silently caps a fast run's rates. Engine "
            "default: PyBullet Quickstart Guide, changeDynamics: maxJointVelocity, "
            "'default maximum joint velocity is 100 units'.",
            engine_default=100.0),
        "explicit_inertia": Setting(
            True, bool,
            "True: the description's mass and central inertia are set on every link with "
            "changeDynamics(mass, localInertiaDiagonal). Without it a link without a "
            "collision shape gets inertia 0 (a point mass, which shortens a compound "
            "pendulum's period; the out-of-the-box study measures by how much). "
            "Engine default (False): PyBullet Quickstart Guide, loadURDF flags: without "
            "URDF_USE_INERTIA_FROM_FILE 'Bullet recomputed the inertia tensor based on "
            "mass and volume of the collision shape'; createMultiBody does the same.",
            engine_default=False),
        "sleeping": Setting(
            False, bool,
            "False: deactivation disabled. PyBullet multibodies created without "
            "URDF_ENABLE_SLEEPING do not sleep; when enabled a body whose squared rates "
            "stay below a threshold for a timeout freezes (the small-amplitude scenarios): "
            "bullet3 btMultiBody.h, 'INITIAL_SLEEP_EPSILON = btScalar(0.05);  // this is a "
            "squared velocity (m^2 s^-2)', 'INITIAL_SLEEP_TIMEOUT = btScalar(2);  // in "
            "seconds'."),
        "massless_link_mass": Setting(
            0.0, float,
            "Mass given to the description's massless link bodies; 0 (default) is exact "
            "(MASSLESS_BODY's expression); a positive value is a substitute whose effect "
            "shows in the error."),
        "reaction_method": Setting(
            "inverse_dynamics", ("inverse_dynamics", "joint_sensor"),
            "'inverse_dynamics' (default): calculateInverseDynamics on a copy with two "
            "massless prismatic joints in front of each reaction joint, at the engine's "
            "state and acceleration of the same step ((v_k+1 - v_k)/dt, exact for "
            "semi-implicit Euler). 'joint_sensor': enableJointForceTorqueSensor "
            "(world-space feedback); its second constraint pass of the articulated-body "
            "algorithm runs with the already updated velocities and the links' Coriolis "
            "accelerations but without the matching m w x v terms: exact on a single link "
            "(the spurious part vanishes), wrong on chains in motion (by the missing "
            "terms, which grow with the links' rates: the double pendulum's reactions "
            "leave the reference as soon as it swings)."),
        "linearize_step": Setting(
            1e-6, float,
            "Central-difference step (scaled by max(1, |x|)) for dK and dC of "
            "calculateInverseDynamics and of the applied force elements."),
        "constraint_erp": Setting(
            1.0, float,
            "Global erp (setPhysicsEngineParameter; the only one POINT2POINT and "
            "PRISMATIC constraints obey). The constraint solve is velocity-level, J(q_k) "
            "v_k+1 = -erp Phi(q_k) / dt: 1.0 removes each step's position error and "
            "leaves a violation of O(dt^2 v^2 curvature) that does not accumulate; a "
            "smaller erp carries part of each step's error into the next, so the "
            "violation builds up to a multiple of it and the trajectory errors grow with "
            "it (scotch yoke, eccentric cam). Set only for constrained mechanisms."),
        "gear_erp": Setting(
            0.0, float,
            "changeConstraint(erp) of the JOINT_GEAR constraints (0: off). A linear "
            "coupling solved at velocity level keeps its initial value exactly once the "
            "solver converges (q_k+1 = q_k + dt v_k+1 and J is constant); the 'GEAR "
            "drifts' of the engine defaults (a slow slip) came from the "
            "solver's early exit (solver_residual_threshold), not from a missing erp. "
            "When > 0, relativePositionTarget is set to the coupling's constant."),
        "constraint_max_force": Setting(
            1.0e12, float,
            "maxForce of every constraint; the engine default would clip the "
            "constraint forces (e.g. the start of a fast run). Engine default: bullet3 "
            "examples/SharedMemory/SharedMemoryPublic.h, b3UserConstraint: "
            "m_maxAppliedForce = 500.",
            engine_default=500.0),
        "solver_iterations": Setting(
            50, int,
            "numSolverIterations (engine default 50): the projected Gauss-Seidel sweeps "
            "over all constraint rows; fewer sweeps already gave the same results on the "
            "mechanisms here and more only cost time, so the default is kept as a margin."),
        "solver_residual_threshold": Setting(
            0.0, float,
            "solverResidualThreshold; the engine default ends the sweeps early (that is "
            "why the iteration count 'had no effect'), with a residual left in every "
            "step's solve, so the velocity-level couplings (rolling, belt) slip a little "
            "at each step and drift; 0 runs every sweep (the couplings then hold to "
            "round-off, at the same wall time). Engine default: "
            "PyBullet Quickstart Guide, setPhysicsEngineParameter: solverResidualThreshold "
            "'default value is 1e-7'.",
            engine_default=1e-7),
        "point_on_line": Setting(
            "prismatic", ("prismatic", "slider"),
            "'prismatic' (default; the build of POINT_ON_LINE's expression): the "
            "JOINT_PRISMATIC's child pivot is moved under the pin before every step "
            "(changeConstraint(jointChildPivot)): the engine evaluates the Jacobian at its "
            "pivots, fixed body points, and with the pivot fixed at the slot's line point "
            "the slot body feels the force there instead of at the pin (measured: a bar "
            "slotted along its own axis through its pivot then swings freely, receiving no "
            "torque). One normal row: well conditioned. 'slider': a slider link (prismatic "
            "along the slot, mass slider_mass_ratio x the smallest body mass) and a "
            "POINT2POINT pin -> slider; its two world-axis rows have effective masses "
            "1/m_slider along the slot and O(1) across it, which Gauss-Seidel cannot "
            "separate when the slot is oblique (the slotted bar diverges); fine for slots "
            "along x or y."),
        "rotor_inertia_ratio": Setting(
            1e-6, float,
            "Inertia of the rotor links of point_on_line='prismatic', relative to the "
            "smallest body inertia. The rotor turns with the slot body, so its inertia is "
            "the substitute's only error, which shrinks with it; the results do not "
            "depend on it over a wide range of decades."),
        "slider_mass_ratio": Setting(
            1e-6, float,
            "Mass of the slider links of point_on_line='slider', relative to the smallest "
            "body mass (it moves with the pin: an added point mass)."),
        "massless_leaf_mass_ratio": Setting(
            1e-6, float,
            "Mass (and, on a revolute joint, inertia) given to a massless body that "
            "carries nothing but is held by a closure constraint (e.g. a pin on its own "
            "guide): zero would make the articulated-body algorithm singular. Relative to "
            "the smallest body mass/inertia: too light a leaf leaves the solve so badly "
            "conditioned that it diverges (slotted link); above that the results do not "
            "depend on it."),
        "contact_friction": Setting(
            1.0, float,
            "Friction coefficient of the ring (the disc has 1; Bullet multiplies them). "
            "Contact variant only."),
        "contact_erp": Setting(
            0.2, float,
            "contactERP and frictionERP of the contact variant (engine 0.2)."),
        "contact_ring_boxes": Setting(
            720, int,
            "Boxes in the ring of the contact variant (16 per fixed link: "
            "createCollisionShapeArray keeps at most 16 children; a multibody keeps at "
            "most 127 links). Radial facet bump (R - r)(1/cos(pi/N) - 1)."),
        "prescribed_motion": Setting(
            "velocity_motor", ("velocity_motor",),
            "A prescribed coordinate (convention 9) is driven by the joint's VELOCITY_CONTROL "
            "motor with targetVelocity = (v(t+h) - v)/h on its engine joint value v = A q + b "
            "and force prescribed_motor_force, set before every step (the free joints' "
            "motors stay off): the motor is a velocity constraint of the same solve as the "
            "joints, so the free bodies feel the imposed acceleration within the step, and "
            "semi-implicit Euler (positions move with the new velocities) lands the "
            "coordinate on q(t+h): the imposed motion is exact to the solver's tolerance and "
            "the free coordinates keep the scheme's first order; the actuator force is the "
            "motor's applied force (getJointState()[3]) of the step that starts at the "
            "sample. Replaces resetJointState each step (the free bodies would never feel "
            "the acceleration, and a driven pendulum swings wrong) and the default motor "
            "gains (a soft motor lags the imposed motion)."),
        "prescribed_motor_force": Setting(
            1.0e9, float,
            "Maximum force/torque of a prescribed coordinate's velocity motor: large enough "
            "never to saturate, so the motor is a velocity constraint."),
        "contact_breaking_threshold": Setting(
            0.02, float,
            "contactBreakingThreshold (engine default 0.02 m: speculative contacts). "
            "Smaller values lowered the trajectory error of the contact variant and "
            "raised its slip (see the report)."),
    }

    # --- contract points 1-5 ---------------------------------------------------------
    ENGINE_MODULES = ('pybullet',)
    ENGINE_DISTRIBUTION = "pybullet"

    EXPRESSIONS = _BUILDERS.declared()

    SPATIAL_REASON = ""

    def translation_reason(self, mechanism: Mechanism) -> str:
        return (spatial_tree_reason(mechanism, closures=False, slides=False)
                if mechanism.spatial else "")

    # --- model building ----------------------------------------------------------------
    def _build(self, p, cid: int, model: _Translation, settings: dict,
               split: Sequence[int] = (), collision: Mapping[int, int] | None = None,
               fixed_shapes: tuple[int, Sequence[int]] | None = None
               ) -> tuple[int, list[int], dict[int, tuple[int, int]]]:
        """Create the multibody; `split` lists joint indices in front of which two massless
        prismatic joints (parent-frame x, y) are inserted; `collision` gives collision
        shapes of some model links (default none: no contacts); `fixed_shapes` = (model
        link, shapes) adds one massless JOINT_FIXED link per shape on that link (their
        engine indices go to `model.fixed_links`). Returns (body id, engine link index of
        each model link, {joint index: (x link, y link)})."""
        rows: list[tuple] = []  # per link, its columns of createMultiBody's arguments
        collision = dict(collision or {})
        engine_index: list[int] = [-1] * len(model.links)
        virtual: dict[int, tuple[int, int]] = {}

        def add(mass, pos, orn, ipos, parent, jtype, axis, shape=-1,
                iorn=(0.0, 0.0, 0.0, 1.0)) -> int:
            # createMultiBody counts links from 1; 0 = base
            rows.append((mass, shape, pos, orn, ipos, list(iorn), parent + 1, jtype, axis))
            return len(rows) - 1

        # parents first: the link order unless a link was re-parented onto a later one
        # (the rolling contact's radial link)
        for i in parents_first([lk.parent for lk in model.links]):
            lk = model.links[i]
            parent = engine_index[lk.parent] if lk.parent >= 0 else -1
            pos = lk.position
            if i in split:
                vx = add(0.0, pos, [0, 0, 0, 1], [0, 0, 0], parent, p.JOINT_PRISMATIC, [1, 0, 0])
                vy = add(0.0, [0, 0, 0], [0, 0, 0, 1], [0, 0, 0], vx, p.JOINT_PRISMATIC,
                         [0, 1, 0])
                virtual[i] = (vx, vy)
                parent, pos = vy, [0.0, 0.0, 0.0]
            jtype = p.JOINT_REVOLUTE if lk.revolute else p.JOINT_PRISMATIC
            engine_index[i] = add(lk.mass, pos, lk.orientation, lk.inertial_position,
                                  parent, jtype, lk.axis, collision.get(i, -1),
                                  *([lk.principal[1]] if lk.principal else []))
        host, host_shapes = fixed_shapes or (-1, ())
        fixed = [add(0.0, [0.0, 0.0, 0.0], [0, 0, 0, 1], [0.0, 0.0, 0.0], engine_index[host],
                     p.JOINT_FIXED, [0, 0, 1], shape) for shape in host_shapes]
        nl = len(rows)
        masses, shapes, positions, orientations, inertial, inertial_orientations, parents, \
            types, axes = map(list, zip(*rows))
        if nl > _MAX_LINKS:
            raise ValueError(f"pybullet multibodies keep at most {_MAX_LINKS} links "
                             f"(createMultiBody silently drops the rest); this model "
                             f"needs {nl}")
        extra = {"flags": p.URDF_USE_SELF_COLLISION} if collision else {}
        body = p.createMultiBody(
            baseMass=0.0, baseCollisionShapeIndex=-1, baseVisualShapeIndex=-1,
            basePosition=[0, 0, 0], baseOrientation=[0, 0, 0, 1],
            linkMasses=masses, linkCollisionShapeIndices=shapes,
            linkVisualShapeIndices=[-1] * nl, linkPositions=positions,
            linkOrientations=orientations, linkInertialFramePositions=inertial,
            linkInertialFrameOrientations=inertial_orientations, linkParentIndices=parents,
            linkJointTypes=types, linkJointAxis=axes, physicsClientId=cid, **extra)
        if body < 0:
            raise RuntimeError("pybullet createMultiBody failed")
        # createMultiBody stores the links in depth-first order of the tree, not in the
        # order given; its joint names "joint<k+1>" keep the given index k
        order = {p.getJointInfo(body, e, physicsClientId=cid)[1]: e for e in range(nl)}
        created = [order[f"joint{k + 1}".encode()] for k in range(nl)]
        engine_index = [created[k] for k in engine_index]
        virtual = {i: (created[vx], created[vy]) for i, (vx, vy) in virtual.items()}
        if fixed_shapes is not None:
            model.fixed_links = [created[k] for k in fixed]
        # body-level parameters in their own calls (they reset the link index to -1)
        for key, value in (
                ("linearDamping", float(settings["linear_damping"])),
                ("angularDamping", float(settings["angular_damping"])),
                ("maxJointVelocity", float(settings["max_joint_velocity"])),
                ("activationState", p.ACTIVATION_STATE_ENABLE_SLEEPING if settings["sleeping"]
                 else p.ACTIVATION_STATE_DISABLE_SLEEPING)):
            p.changeDynamics(body, -1, **{key: value}, physicsClientId=cid)
        for i, lk in enumerate(model.links if settings["explicit_inertia"] else ()):
            diagonal = lk.principal[0] if lk.principal else [lk.inertia] * 3
            p.changeDynamics(body, engine_index[i], mass=float(lk.mass),
                             localInertiaDiagonal=diagonal, physicsClientId=cid)
            info = p.getDynamicsInfo(body, engine_index[i], physicsClientId=cid)
            if (abs(info[0] - lk.mass) > 1e-12 * max(1.0, lk.mass)
                    or abs(info[2][2] - diagonal[2]) > 1e-12 * max(1.0, diagonal[2])):
                raise RuntimeError(f"pybullet did not take the inertia of link {lk.name}: {info}")
        if not settings["joint_velocity_motors"]:
            moving = sorted(set(range(nl)) - {created[k] for k in fixed})
            p.setJointMotorControlArray(body, moving, p.VELOCITY_CONTROL,
                                        targetVelocities=[0.0] * len(moving),
                                        forces=[0.0] * len(moving), physicsClientId=cid)
        return body, engine_index, virtual

    # --- contract points 6 and 9 ---------------------------------------------------------
    @contextmanager
    def _open(self, p, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray, dt: float,
              cfg: dict, sensor_joints: Sequence[int] = ()) -> Iterator[_World]:
        """Connect a DIRECT client, build the mechanism and set the state (q0, qd0);
        enable the joint force/torque sensor on the joints `sensor_joints` (description
        joint indices). The client is disconnected on leaving."""
        self.check_support(mechanism)
        model = _Translation(mechanism, cfg)
        n = model.n
        cid = p.connect(p.DIRECT)
        if cid < 0:
            raise RuntimeError("pybullet connect(DIRECT) failed")
        try:
            p.setGravity(*model.gravity_vector, physicsClientId=cid)
            p.setTimeStep(dt, physicsClientId=cid)
            p.setPhysicsEngineParameter(
                fixedTimeStep=dt, numSubSteps=0,
                jointFeedbackMode=p.JOINT_FEEDBACK_IN_WORLD_SPACE, physicsClientId=cid)
            if model.closures or model.contact is not None:
                p.setPhysicsEngineParameter(
                    erp=float(cfg["constraint_erp"]),
                    numSolverIterations=int(cfg["solver_iterations"]),
                    solverResidualThreshold=float(cfg["solver_residual_threshold"]),
                    physicsClientId=cid)
            shapes, ring = (_contact_shapes(p, cid, model, cfg)
                            if model.contact is not None else (None, None))
            body, eidx, _ = self._build(p, cid, model, cfg, collision=shapes, fixed_shapes=ring)
            jv0 = model.map.engine_values(q0)
            jvd0 = model.map.A @ np.asarray(qd0, dtype=float)
            for i in range(n):
                p.resetJointState(body, eidx[i], float(jv0[i]), float(jvd0[i]),
                                  physicsClientId=cid)
            if len(model.links) > n:  # the extra links from the (consistent) state
                ls = p.getLinkStates(body, eidx[:n], computeLinkVelocity=1,
                                     computeForwardKinematics=1, physicsClientId=cid)
                for c in model.closures:
                    c.place(p, cid, body, eidx, ls)
            cids = []  # one per closure, its frames relative to the body frames
            for c in model.closures:
                cids.append(p.createConstraint(
                    body, eidx[c.parent] if c.parent >= 0 else -1, body,
                    eidx[c.child] if c.child >= 0 else -1, *c.frames(p), physicsClientId=cid))
                if cids[-1] < 0:
                    raise RuntimeError(f"pybullet createConstraint failed for {c.element.name}")
                p.changeConstraint(cids[-1], **c.options(cfg), physicsClientId=cid)
            if model.contact is not None:
                _contact_dynamics(p, cid, body, eidx, model, cfg)
            for i in sensor_joints:
                p.enableJointForceTorqueSensor(body, eidx[i], True, physicsClientId=cid)
            yield _World(cid, body, eidx, model, cids)
        finally:
            p.disconnect(physicsClientId=cid)

    @staticmethod
    def _inputs(p, world: _World, dt: float, cfg: dict
                ) -> tuple[Callable[[int, list, list], list | None] | None, bool]:
        """The function that gives the engine what it needs before step k (t = k dt, `jv`
        and `jvd` the joint values and rates at the start of the step over at least the n
        coordinate links): the force elements (their builders' expressions), the PRISMATIC
        pivots (`_Rotor.pivot`), the prescribed motors (setting prescribed_motion); it
        returns the (x, y) force on point b of each point-to-point element (None where
        there are none). With it, whether it reads `jv` and `jvd`; (None, False) when
        nothing is given."""
        model, cid, body, eidx = world.model, world.cid, world.body, world.eidx
        n = model.n
        has_cf = bool(model.coordinate_laws)
        joint_forces = model.coordinate_laws.on_engine_values(model.map.T, model.map.c)
        n_pf = len(model.point_forces)
        moving = [(world.cids[r], c) for r, c in enumerate(model.closures) if c.follows_pin]
        driven = model.driven
        if not (has_cf or n_pf or moving or driven):
            return None, False
        set_motors = p.setJointMotorControlArray
        get_links = p.getLinkStates
        apply_force = p.applyExternalForce
        change = p.changeConstraint
        torque_mode, world_frame = p.TORQUE_CONTROL, p.WORLD_FRAME
        velocity_mode = p.VELOCITY_CONTROL
        links = eidx[:n]
        point_links = [eidx[k] for k in model.point_links]
        A, bvec = model.map.A, model.map.b
        moving_links = sorted({lk for _, c in moving for lk in (c.pin_link, c.line_link)
                               if lk >= 0})
        moving_eidx = [eidx[lk] for lk in moving_links]
        driven_links = [eidx[m.index] for m in driven]
        drives = [(float(A[m.index, m.index]), m.position, float(bvec[m.index]), m.index)
                  for m in driven]
        motor_force = [float(cfg["prescribed_motor_force"])] * len(driven)

        def apply(k: int, jv: list, jvd: list) -> list | None:
            t = k * dt
            forces = None
            if has_cf:
                set_motors(body, links, torque_mode, forces=joint_forces(jv[:n], jvd[:n], t),
                           physicsClientId=cid)
            if n_pf:
                ls = dict(zip(model.point_links, get_links(
                    body, point_links, computeLinkVelocity=1, computeForwardKinematics=1,
                    physicsClientId=cid)))
                forces = []
                for pf in model.point_forces:
                    fx, fy, ax, ay, bx, by = pf.force(ls, t)
                    forces.append((fx, fy))
                    if pf.link_b >= 0:
                        apply_force(body, eidx[pf.link_b], [fx, fy, 0.0], [bx, by, 0.0],
                                    world_frame, physicsClientId=cid)
                    if pf.link_a >= 0:
                        apply_force(body, eidx[pf.link_a], [-fx, -fy, 0.0], [ax, ay, 0.0],
                                    world_frame, physicsClientId=cid)
            if moving:
                ls = dict(zip(moving_links, get_links(body, moving_eidx, physicsClientId=cid)))
                for uid, c in moving:
                    change(uid, jointChildPivot=c.pivot(ls), physicsClientId=cid)
            if driven:
                t_next = (k + 1) * dt
                target = [(a * q(t_next) + c - jv[i]) / dt for a, q, c, i in drives]
                set_motors(body, driven_links, velocity_mode, targetVelocities=target,
                           forces=motor_force, physicsClientId=cid)
            return forces

        return apply, has_cf or bool(driven)

    def _bare_loop_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                        steps: int, dt: float, cfg: dict) -> BareLoop:
        """The world of `simulate` stepped with only the per-step inputs (`_inputs`)."""
        import pybullet as p

        with self._open(p, mechanism, q0, qd0, dt, cfg) as world:
            apply, reads = self._inputs(p, world, dt, cfg)
            step, cid = p.stepSimulation, world.cid
            get_states, body, links = p.getJointStates, world.body, world.eidx[:world.model.n]
            jv = jvd = []
            with Stopwatch() as clock:
                for k in range(steps):
                    if reads:
                        js = get_states(body, links, physicsClientId=cid)
                        jv, jvd = [s[0] for s in js], [s[1] for s in js]
                    if apply is not None:
                        apply(k, jv, jvd)
                    step(physicsClientId=cid)
            js = get_states(body, links, physicsClientId=cid)
            return BareLoop.mapped(clock.cpu, world.model.map, [s[0] for s in js],
                                   [s[1] for s in js])

    def scheme(self, mechanism: Mechanism, settings: Mapping | None = None) -> Scheme:
        return Scheme("semi-implicit Euler", 1, SEMI_IMPLICIT_EULER_STABILITY)

    def export(self, mechanism: Mechanism, coordinates: Sequence[str],
               initial_states: Mapping[str, tuple[np.ndarray, np.ndarray]],
               settings: Mapping | None = None, dt: float = 1e-3) -> tuple[str, list[str]]:
        """(a standalone Python script, what it does not reproduce): the build `simulate`
        makes, recorded call by call (simulators/script_export.py), from the first
        initial state, then stepping and the description's coordinates at the end."""
        import pybullet

        from .script_export import Recorder, script

        name, q0, qd0 = self.export_start(initial_states)
        cfg = self.resolve_settings(settings)
        recorder = Recorder(pybullet)
        with self._open(recorder, mechanism, q0, qd0, dt, cfg) as world:
            outside = []
            if mechanism.forces or any(c.follows_pin for c in world.model.closures):
                laws = [e.name for e in mechanism.forces]
                outside.append("the force laws' joint and point forces (TORQUE_CONTROL and "
                               f"applyExternalForce before every step): {', '.join(laws)}")
            if mechanism.prescribed:
                outside.append("the prescribed motions' velocity motors, set before every "
                               "step: " + ", ".join(p.name for p in mechanism.prescribed))
            n = world.model.n
            text = script(
                title=self.script_title("PyBullet", name, cfg),
                module="pybullet", connect="pybullet.connect(pybullet.DIRECT)",
                client_id=world.cid, calls=recorder.calls,
                step="pybullet.stepSimulation(physicsClientId=cid)",
                read=(f"[s[0] for s in pybullet.getJointStates({world.body}, "
                      f"{list(world.eidx[:n])}, physicsClientId=cid)]"),
                coordinates=coordinates, T=world.model.map.T, c=world.model.map.c, dt=dt,
                not_in_script=outside)
        return text, outside

    def _simulate_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                       steps: int, dt: float, cfg: dict,
                       reaction_joints: tuple[str, ...]) -> Samples:
        import pybullet as p

        joint_ids = [mechanism.joints.index(mechanism.joint(name)) for name in reaction_joints]
        use_sensor = bool(reaction_joints) and cfg["reaction_method"] == "joint_sensor"
        with self._open(p, mechanism, q0, qd0, dt, cfg,
                        sensor_joints=joint_ids if use_sensor else ()) as world:
            cid, body, eidx, model = world.cid, world.body, world.eidx, world.model
            contact, closures, n = model.contact, model.closures, model.n
            # one extra step gives the reaction/acceleration (and the constraint forces)
            # of the last sample
            total = steps + 1 if (reaction_joints or closures or contact
                                  or mechanism.prescribed) else steps
            JV, JVD = np.empty((total + 1, len(eidx))), np.empty((total + 1, len(eidx)))
            sensor = np.full((total + 1, len(joint_ids), 2), np.nan)
            # force on point b of each point-to-point element (on a: opposite)
            f_point = np.zeros((total + 1, len(model.point_forces), 2))
            CF = np.full((total + 1, len(closures), 6), np.nan)  # getConstraintState rows
            # contact variant: force of the track on the disc (x, y) and contact count
            FC = np.zeros((total + 1, 3))

            step, get_states = p.stepSimulation, p.getJointStates
            get_cstate, get_contacts = p.getConstraintState, p.getContactPoints
            sensor_slots = [eidx[i] for i in joint_ids]
            apply, _ = self._inputs(p, world, dt, cfg)
            driven_slots = [m.index for m in model.driven]
            motor = np.full((total + 1, len(driven_slots)), np.nan)
            if contact is not None:
                ring_links = set(model.fixed_links)
                disc_link = eidx[model.link_of[contact.inner]]

            js = get_states(body, eidx, physicsClientId=cid)
            with Stopwatch() as clock:
                for k in range(total):
                    JV[k] = jv = [s[0] for s in js]
                    JVD[k] = jvd = [s[1] for s in js]
                    if apply is not None and (forces := apply(k, jv, jvd)) is not None:
                        f_point[k] = forces
                    step(physicsClientId=cid)
                    js = get_states(body, eidx, physicsClientId=cid)
                    # what is read after a step (the motors', constraints', contacts' and
                    # sensors' forces) belongs to the state before it
                    motor[k] = [js[slot][3] for slot in driven_slots]
                    for r, uid in enumerate(world.cids):
                        st = get_cstate(uid, physicsClientId=cid)
                        CF[k, r, : len(st)] = st
                    if contact is not None:
                        FC[k] = _contact_force(
                            get_contacts(bodyA=body, bodyB=body, physicsClientId=cid),
                            ring_links, disc_link)
                    if use_sensor:
                        sensor[k] = [js[slot][2][:2] for slot in sensor_slots]
            JV[total] = [s[0] for s in js]
            JVD[total] = [s[1] for s in js]
            jv, jvd = JV[: steps + 1], JVD[: steps + 1]  # the samples

            q, qd = model.map.coordinates(jv[:, :n]), model.map.rates(jvd[:, :n])
            # getConstraintState rows -> the contract's physical terms (signs measured)
            forces = {c.element.name: c.force(CF[: steps + 1, r], q, model)
                      for r, c in enumerate(closures)}
            # inverse dynamics applies no element: the point-to-point and the closure
            # forces across the cut are in its force (on body_a: minus the force recorded
            # on point b); a gear is a joint force, which both routes see. Rolling by
            # contact: the contact carries what the description's arm and coupling
            # carried, so it counts as transmitted through the joints (contract point 6).
            # Checked by Newton's law on the scotch yoke's disc and the slotted bar
            # (3e-14 N)
            outside = outside_forces(mechanism, {pf.pair.name: -f_point[: steps + 1, e]
                                                 for e, pf in enumerate(model.point_forces)},
                                     forces)
            transmitted = {}
            if use_sensor:
                transmitted = {name: sensor[: steps + 1, r].copy()
                               for r, name in enumerate(reaction_joints)}
                outside["pair_forces"] = {}  # the joint's own force: no pair element in it
            elif reaction_joints:
                jvdd = (JVD[1: total + 1] - JVD[:total]) / dt
                transmitted = self._inverse_dynamics_forces(
                    p, cid, model, cfg, joint_ids, list(reaction_joints), jv, jvd,
                    jvdd[: steps + 1], q)

        extras = {}
        if contact is not None:
            extras["contact"] = report = rolling_contact_report(
                mechanism, model.coupling, contact, model.map, q, qd,
                jv[:, model.radial_link],  # the penetration: the radial slider's value
                FC[: steps + 1, :2], FC[: steps + 1, 2])
            forces[contact.coupling] = report.pop("friction")[:, None]
        # the motor acts on its own joint only: Q = A^T tau is A[i, i] tau
        actuators = {m.element.name: model.map.A[m.index, m.index] * motor[: steps + 1, r]
                     for r, m in enumerate(model.driven)}
        return Samples(q, qd, clock, constraint_forces=forces, actuator_forces=actuators,
                       extras=extras, transmitted=transmitted, **outside)

    def _inverse_dynamics_forces(self, p, cid: int, model: _Translation, cfg: dict,
                                 joint_ids: list[int], names: list[str], JV: np.ndarray,
                                 JVD: np.ndarray, JVDD: np.ndarray, q: np.ndarray
                                 ) -> dict[str, np.ndarray]:
        """The force from parent to child at each joint (world axes): the inverse-dynamics
        force on two massless prismatic joints (x, y of the parent frame) inserted in front
        of the joint. It applies no force element and no closure, so it holds every force
        that reaches the child's subtree from outside (`reactions.joint_reaction` takes
        them out)."""
        body, eidx, virtual = self._build(p, cid, model, cfg, split=set(joint_ids))
        ndof = p.getNumJoints(body, physicsClientId=cid)
        slots = np.array(eidx)
        vslots = [virtual[i] for i in joint_ids]
        N = len(JV)
        pos = np.zeros((N, ndof))
        vel = np.zeros((N, ndof))
        acc = np.zeros((N, ndof))
        pos[:, slots], vel[:, slots], acc[:, slots] = JV, JVD, JVDD
        out = np.empty((N, len(joint_ids), 2))
        inv_dyn = p.calculateInverseDynamics
        for k in range(N):
            tau = inv_dyn(body, pos[k].tolist(), vel[k].tolist(), acc[k].tolist(),
                          physicsClientId=cid)
            out[k] = [(tau[vx], tau[vy]) for vx, vy in vslots]
        return {name: turned(model.map.angle(model.mech.joints[i].parent, q),
                              out[:, r, 0], out[:, r, 1])
                for r, (i, name) in enumerate(zip(joint_ids, names))}

    def stored_inertia(self, mechanism: Mechanism, settings: Mapping | None = None
                       ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """getDynamicsInfo of each link: its local inertia diagonal and inertial frame
        orientation (a spatial link's frame is aligned with its body's)."""
        import pybullet as p

        rest, cfg = np.zeros(len(mechanism.joints)), self.resolve_settings(settings)
        with self._open(p, mechanism, rest, rest, 1e-3, cfg) as world:
            out = {}
            for i, lk in enumerate(world.model.links[:world.model.n]):
                info = p.getDynamicsInfo(world.body, world.eidx[i], physicsClientId=world.cid)
                R = np.array(p.getMatrixFromQuaternion(info[4], physicsClientId=world.cid))
                out[lk.body] = (np.array(info[2], dtype=float), R.reshape(3, 3))
            return out

    # --- contract point 7 --------------------------------------------------------------
    def linearize(self, mechanism: Mechanism, q_eq: np.ndarray,
                  settings: Mapping | None = None, dt: float = 1e-3) -> Linearization | None:
        frame = self.linearization_frame(mechanism, settings)
        if frame is None or mechanism.constraints:
            # inverse dynamics about a rest state (a driven joint does not rest):
            # calculateMassMatrix / calculateInverseDynamics describe the open tree only;
            # PyBullet has no constrained linearization (the free-vibration fit remains)
            return None
        import pybullet as p

        cfg, autonomous = frame
        q_eq = np.asarray(q_eq, dtype=float)
        with self._open(p, autonomous, q_eq, np.zeros(len(q_eq)), dt, cfg) as world:
            cid, body, eidx, model = world.cid, world.body, world.eidx, world.model
            n = model.n
            jv_eq = model.map.engine_values(q_eq)
            zeros = [0.0] * n
            perm = np.asarray(eidx[:n])  # engine (depth-first) index of each joint

            def engine(x: np.ndarray) -> list[float]:
                """Joint-ordered values -> the engine's link order."""
                y = np.empty(n)
                y[perm] = x
                return [float(v) for v in y]

            def applied(jv: np.ndarray, jvd: np.ndarray) -> np.ndarray:
                """Engine joint forces of the (autonomous) force elements at (jv, jvd)."""
                tau = model.joint_forces(model.map.coordinates(jv), model.map.rates(jvd), 0.0)
                if not model.point_forces:
                    return tau
                for i in range(n):
                    p.resetJointState(body, eidx[i], float(jv[i]), float(jvd[i]),
                                      physicsClientId=cid)
                ls = {lk: p.getLinkState(body, eidx[lk], computeLinkVelocity=1,
                                         computeForwardKinematics=1, physicsClientId=cid)
                      for lk in model.point_links}
                for pf in model.point_forces:
                    fx, fy, *_ = pf.force(ls, 0.0)
                    for link, point, sign in ((pf.link_b, pf.pair.point_b, 1.0),
                                              (pf.link_a, pf.pair.point_a, -1.0)):
                        if link < 0:
                            continue
                        # calculateJacobian takes the point in the URDF link frame (the
                        # joint frame), not about the centre of mass as its docstring says
                        ip = model.links[link].inertial_position
                        jac_t, _ = p.calculateJacobian(
                            body, eidx[link], [point[0] + ip[0], point[1] + ip[1], 0.0],
                            engine(jv), engine(jvd), zeros, physicsClientId=cid)
                        J = np.asarray(jac_t)[:2][:, perm]
                        tau = tau + sign * (J.T @ np.array([fx, fy]))
                return tau

            def residual(jv: np.ndarray, jvd: np.ndarray) -> np.ndarray:
                tau_id = p.calculateInverseDynamics(body, engine(jv), engine(jvd), zeros,
                                                    physicsClientId=cid)
                return np.asarray(tau_id)[perm] - applied(jv, jvd)

            M = np.atleast_2d(np.array(p.calculateMassMatrix(
                body, engine(jv_eq), physicsClientId=cid)))[np.ix_(perm, perm)]
            K, C = central_differences(residual, jv_eq, float(cfg["linearize_step"]))
        eig = quadratic_eigenvalues(M, C, K)
        return Linearization(
            eigenvalues=eig,
            method=("calculateMassMatrix + central differences of calculateInverseDynamics "
                    "(K, C) plus the applied force elements (coordinate laws; point-to-point "
                    "forces through calculateJacobian), which inverse dynamics omits"),
            extra={"M": M.tolist(), "K": K.tolist(), "C": C.tolist(),
                   "coordinates": "engine joint values"})

    # --- flexible elements (contract point 12) ----------------------------------------------
    BEAM_ELEMENTS = {
        NO_BEAM_ELEMENT: BeamElement(Expression(
            UNSUPPORTED, "PyBullet has no beam element: its deformables (loadSoftBody) are "
                         "soft bodies loaded from meshes, FEM tetrahedra (Neo-Hookean or "
                         "corotated) or mass-spring cloth with bending springs, none with a "
                         "bending stiffness EI of a 1-D rod; Bullet's C++ rope "
                         "(btSoftBodyHelpers::CreateRope) is not exposed in pybullet. A beam "
                         "there can only be a chain of rigid segments with hinge springs "
                         "(the discretized model of issue 12)")),
    }


BACKEND = PyBulletBackend()
