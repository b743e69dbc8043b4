"""Pymunk (Chipmunk 2) backend: planar rigid bodies in maximal coordinates.

Translation of the description (conventions of `mbfidelity.systems.model`). Each element
kind has one builder, registered with the expressions it declares (`_builds`;
`EXPRESSIONS` is read from that registry), which state what it builds. Bodies with mass
are ``pymunk.Body``s, the world is ``space.static_body`` (at the origin, angle 0). No
shapes are created (except for a RollingContact's circles), so nothing can collide.
Chipmunk has no massless bodies: they are eliminated (`plan.Elimination`) and stand for
one constraint between the bodies around them (`_eliminated`); their frames follow from
the engine bodies (`plan.EliminatedFrames`), and loads on them reach the engine bodies by
virtual power (`plan.MaximalFrames.engine_loads`).

A ``LinearCoupling`` is written on absolute body angles, sum k_b theta_b = const. Three
bodies A, B, K with sum k = 0, A and B hinged on the carrier K (belt pulleys on an arm, a
disc rolling in a moving track), are an internal/external gear pair on the carrier, i.e.
rolling of the pitch circles at the pitch point C (`plan.PitchPair`). That is a
``PivotJoint`` between A and B whose anchors are moved to C before every solve (pre-solve
callback, at the position-updated configuration): its tangential row is the coupling, its
normal row is implied by the carrier (redundant), and the coupling's position error is put
into the tangential anchor gap (`plan.PitchPair.pitch_points`) so that Chipmunk's own error
correction removes it.

Chipmunk reports only the magnitude of an impulse, so the forces are reconstructed from
Newton-Euler over each step (`PymunkBackend._simulate_impl`).

Chipmunk's step (cpSpaceStep): positions x += h v (old velocity); constraints pre-step at
the new positions; v += h (g + F/m); warm-started Gauss-Seidel velocity iterations that
also remove the position error (bias velocity -error * (1 - error_bias^h) / h). It is
first order (semi-implicit Euler with velocity-level constraints).
"""
from __future__ import annotations

import math
from types import SimpleNamespace
from dataclasses import astuple, dataclass, field
from typing import Callable, Mapping, Sequence

import numpy as np

from ..systems.model import (WORLD, LinearCoupling, Mechanism, PointOnLine, PointOnPoint, Prismatic,
                             Revolute, RollingContact)
from .base import (EXACT, NO_BEAM_ELEMENT, SEMI_IMPLICIT_EULER_STABILITY, SUBSTITUTE, UNSUPPORTED,
                   Backend, BareLoop, BeamElement, ElementBuilders, Expression, Samples, Scheme,
                   Setting, Stopwatch)
from .reactions import motion_forces
from .plan import (BODY, COORDINATE_FORCE_CUSTOM, COORDINATE_FORCE_LINEAR, HINGE_CLOSURE,
                   LINEAR_COUPLING, MASSLESS_BODY, POINT_ON_LINE, POINT_ON_POINT,
                   POINT_TO_POINT_CUSTOM, POINT_TO_POINT_LINEAR, PRESCRIBED, PRISMATIC, REVOLUTE,
                   ROLLING_CONTACT, TIME_LOAD, Elimination, MaximalFrames, Motion,
                   NotEliminable, PitchPair, body_states, compensated_host, coupled,
                   coupled_angles, description_reason, effective_mass, element_kind, element_loads,
                   joint_pose, joint_velocity, line_through_origin, num, pitch_pairs, plane_point,
                   point_mass, point_state, rigid_body, ring_of_chords, rotation_fixed, slide_path,
                   stepped_start)

#: how a Prescribed coordinate is imposed (setting prescribed_motion)
_DRIVE_ROUTES = ("kinematic_on_world", "moving_constraint")
#: radius of gyration (m) of the moment a point mass is given (setting point_mass_gyration)
POINT_MASS_GYRATION = 1e-6
_ELEMENT_FORCE = ("body forces and torques from one compiled function of the body states, "
                  "evaluated at the position-updated state x + h v (element_forces): a "
                  "consistent semi-implicit Euler step")
#: how element forces are evaluated within a Chipmunk step
_FORCE_MODES = ("position_updated", "step_start")


@dataclass(frozen=True)
class _Groove:
    """A Chipmunk GrooveJoint: the point `anchor` of body `pin` slides on the slot
    base + u direction, u in [lo, hi] (None: the setting groove_half_length), fixed in
    body `slot`; `phase` is set when the relative rotation is locked as well (GearJoint,
    ratio 1)."""

    slot: str
    pin: str
    base: tuple[float, float]
    direction: tuple[float, float]
    lo: float | None
    hi: float | None
    anchor: tuple[float, float]
    phase: float | None


@dataclass(frozen=True)
class _Carrier:
    """Slider substitute: an engine body that belongs to description body `host`.
    kind "pin": point mass (infinite moment) pinned at `point`; kind "slot": glued to the
    host (pivot + gear), its centre of mass at `point` (host frame)."""

    name: str
    host: str
    kind: str
    point: tuple[float, float]
    mass: float
    moment: float
    constraint: str


@dataclass(frozen=True)
class _Pitch(PitchPair):
    """The pitch pair of the LinearCoupling `name`: a PivotJoint between a and b at the
    pitch point (see the module docstring), or with `contact` colliding pitch circles."""

    name: str
    wrap: float  # Phi jumps by this when a massless carrier's angle wraps (0: none)
    contact: bool


@dataclass(frozen=True)
class _Drive(Motion):
    """A prescribed coordinate's motion on `joint`, whose parent is the world or a body
    with mass and whose child has mass (how it is imposed: the PRESCRIBED expression,
    `PymunkBackend._schedule`)."""

    joint: Revolute | Prismatic
    kinematic: bool  # the child is a Body.KINEMATIC driver (a joint on the world)

    @property
    def name(self) -> str:
        return self.element.name


@dataclass
class _Layout:
    """The engine constructs of `mech` at the resolved settings `cfg` (`_plan`)."""

    mech: Mechanism
    cfg: Mapping
    dynamic: list[str] = field(default_factory=list)  # bodies with mass, in description order
    pivots: list[tuple] = field(default_factory=list)  # PivotJoints (a, b, anchor a, anchor b)
    grooves: list[_Groove] = field(default_factory=list)
    #: the massless links eliminated, and how their frames follow
    elimination: Elimination | None = None
    carriers: list[_Carrier] = field(default_factory=list)
    #: engine centre of gravity (description frame) of compensated hosts
    cog: dict[str, tuple[float, float]] = field(default_factory=dict)
    #: engine (mass, moment) of every engine body
    engine_mass: dict[str, tuple[float, float]] = field(default_factory=dict)
    #: PinJoints (a, b, anchor a, anchor b, massless link)
    pins: list[tuple] = field(default_factory=list)
    #: GearJoints of couplings and glued carriers (a, b, phase, ratio)
    gears: list[tuple[str, str, float, float]] = field(default_factory=list)
    pitches: list[_Pitch] = field(default_factory=list)
    infinite: set[str] = field(default_factory=set)
    drives: list[_Drive] = field(default_factory=list)
    #: ids of joints that build no constraint of their own
    eliminated: set[int] = field(default_factory=set)

    @property
    def engine(self) -> list[str]:
        return self.dynamic + [c.name for c in self.carriers]

    @property
    def massless(self) -> list[str]:
        return [b.name for b in self.mech.bodies if element_kind(b) == MASSLESS_BODY]

    def engine_ok(self, body: str) -> bool:
        return body == WORLD or body in self.dynamic


class _Refused(ValueError):
    """Why Chipmunk cannot express the mechanism (`PymunkBackend.translation_reason`)."""


_GROOVE_LIMIT = (
    "Chipmunk's GrooveJoint computes the impulse that would stop the whole relative "
    "velocity of pin and slot (2x2 mass matrix) and keeps only its component normal to "
    "the slot; that is the exact pin-in-slot impulse only if the slot normal is a "
    "principal direction of that matrix in every pose, i.e. the slot line passes through "
    "the slot body's centre of mass (or the slot is on the world) and the pin is at the "
    "pin body's centre of mass (or on the world). Otherwise the sliding velocity leaks "
    "into the normal direction (measured: velocity jump at the first step, O(h) joint "
    "drift, divergence for large offsets)")


# --- element builders, registered per element kind with their expressions ------------------

#: element kind -> (its builder, the expressions it declares: contract point 5). A body's,
#: joint's, closure's or prescribed motion's builder takes (layout, element) and adds
#: its part to the layout (`_plan`), refusing (`_Refused`) what Chipmunk cannot express; a
#: force element's takes (mechanism, element) and gives its loads as a function of the
#: frames and t, which the compiled body forces sum (`_compile`).
_ELEMENTS = ElementBuilders()
_builds, _builder = _ELEMENTS.builds, _ELEMENTS.of


@_builds(BODY,
         Expression(EXACT, "pymunk.Body(mass, moment) whose frame is the description's "
                           "(centre of gravity at its origin), no shapes",
                    when="mass and inertia > 0", applies=rigid_body),
         Expression(SUBSTITUTE, "a point mass: pymunk.Body(mass, m r^2), r the setting "
                                "point_mass_gyration. Chipmunk divides by the moment "
                                "(its constraint solver uses the inverse moment, "
                                "infinite at zero); the substitute changes the body's "
                                "moment about any point by m r^2, relative (r/d)^2 at "
                                "a distance d",
                    when="mass > 0, inertia 0", applies=point_mass),
         Expression(UNSUPPORTED, "Chipmunk needs a mass > 0 (or mass and inertia both 0 "
                                 "for a massless link that can be eliminated)",
                    when="mass 0, inertia > 0"))
def _engine_body(layout, body) -> None:
    """A body with mass is an engine body (a point mass gets its substitute moment,
    `_mass_moment`); one whose rotation is fixed gets an infinite moment: it is taken out of
    every rotational equation, where a GearJoint holding its angle would be solved only
    iteratively (two such bodies in a chain drift apart under a velocity-level groove
    without error correction)."""
    if not num(body.mass) > 0:
        raise _Refused(f"body {body.name}: mass 0 and inertia {num(body.inertia)}; Chipmunk "
                       "needs a mass > 0 (or both 0 for a massless link that can be "
                       "eliminated)")
    layout.dynamic.append(body.name)
    if rotation_fixed(layout.mech, body.name):
        layout.infinite.add(body.name)


@_builds(MASSLESS_BODY, Expression(EXACT, "eliminated (Chipmunk has no massless bodies): "
                                          "folded into one GrooveJoint (a revolute and a "
                                          "prismatic joint), an arm PinJoint (revolute joints "
                                          "at two points), or a free group whose positions "
                                          "solve its joint equations; other shapes are "
                                          "refused (support)"))
def _eliminated(layout, body) -> None:
    """The constraint that stands for an eliminated link (`plan.Elimination` found its
    shape): a folded link's GrooveJoint, its pin point on its partner's line
    (`plan.Fold.slot_line`), refused when it would not be exact in Chipmunk; an arm's
    PinJoint and the PivotJoints between bodies hinged at the same point of it; a free
    group's links impose none."""
    eliminated = layout.elimination
    if body.name in eliminated.folds:
        fold = eliminated.folds[body.name]
        base, direction = fold.slot_line
        slot_ok = fold.partner == WORLD or line_through_origin(base, direction)
        pin_ok = fold.pin_body == WORLD or not any(fold.pin_point)
        if not (slot_ok and pin_ok):
            where = ("slot line off the slot body's centre of mass" if not slot_ok
                     else "pin off the pin body's centre of mass")
            raise _Refused(f"massless link {fold.link} folds into a groove with its {where}. "
                           f"{_GROOVE_LIMIT}")
        layout.grooves.append(_Groove(fold.partner, fold.pin_body, tuple(base), tuple(direction),
                                      *_limits(fold.prismatic), fold.pin_point, None))
    elif body.name in eliminated.arms:
        link = eliminated.arms[body.name]
        (ra, pa), (rb, pb) = link.at_alpha[0], link.at_beta[0]
        for other, point in link.at_alpha[1:]:
            layout.pivots.append((ra, other, pa, point))
        for other, point in link.at_beta[1:]:
            layout.pivots.append((rb, other, pb, point))
        layout.pins.append((ra, rb, pa, pb, link.link))


def _limits(j: Prismatic) -> tuple[float | None, float | None]:
    return tuple(None if v is None else num(v) for v in j.limits)  # type: ignore[return-value]


@_builds(REVOLUTE, Expression(EXACT, "PivotJoint at the two anchors"))
def _hinge(layout, j: Revolute) -> None:
    if id(j) not in layout.eliminated:
        layout.pivots.append((j.parent, j.child, plane_point(j.parent_anchor),
                              plane_point(j.child_anchor)))


@_builds(PRISMATIC, Expression(EXACT, "GrooveJoint along the child's centre-of-mass path and "
                                      "a GearJoint locking the rotation; refused (support) "
                                      "unless the path passes through the parent's centre "
                                      "of mass or the parent is the world. " + _GROOVE_LIMIT))
def _slide(layout, j: Prismatic) -> None:
    if id(j) in layout.eliminated:
        return
    # with the rotation locked the pin can be the child's centre of mass, its frame origin
    base, axis = slide_path(j)
    if j.parent != WORLD and not line_through_origin(base, axis):
        raise _Refused(f"prismatic joint {j.name}: the child's centre-of-mass path misses the "
                       f"parent's centre of mass. {_GROOVE_LIMIT}")
    layout.grooves.append(_Groove(j.parent, j.child, tuple(base), tuple(axis), *_limits(j),
                                  (0.0, 0.0), num(j.angle_offset)))


# a force element's loads on the description bodies
for _kind in (POINT_TO_POINT_LINEAR, POINT_TO_POINT_CUSTOM, COORDINATE_FORCE_LINEAR,
              COORDINATE_FORCE_CUSTOM):
    _builds(_kind, Expression(EXACT, _ELEMENT_FORCE))(element_loads)
_builds(TIME_LOAD, Expression(EXACT, _ELEMENT_FORCE + ", at t + h"))(element_loads)


@_builds(PRESCRIBED, Expression(EXACT, "on the world: a Body.KINEMATIC child whose velocity "
                                       "is set every step to (q(t + 2h) - q(t + h))/h after "
                                       "the position update; on a free body: a constraint "
                                       "between the two bodies whose target (a slide: "
                                       "PivotJoint to parent_anchor + q axis; a hinge: "
                                       "GearJoint phase) is set to q(t + 2h) with error_bias "
                                       "0. The coordinate is on q(t) at every sample; the "
                                       "free coordinates and the actuator force (Newton-Euler "
                                       "on the child subtree) converge at first order, the "
                                       "scheme's (setting prescribed_motion). Refused "
                                       "(support) on a joint with a massless body"))
def _drive(layout, p) -> None:
    """A prescribed coordinate's `_Drive`: on the world (with the default route) a
    kinematic child, turning about its centre of gravity, which is put on the hinge; a
    prescribed slide is held by a moving PivotJoint instead of a groove."""
    mech = layout.mech
    index = mech.coordinates.index(p.coordinate)
    j = mech.joints[index]
    if not (layout.engine_ok(j.child) and j.child != WORLD and layout.engine_ok(j.parent)):
        raise _Refused(f"prescribed motion {p.name}: joint {j.name} joins a massless body; "
                       "the constraint that imposes the motion acts between bodies with mass "
                       "(or the world)")
    kinematic = layout.cfg["prescribed_motion"] == _DRIVE_ROUTES[0] and j.parent == WORLD
    layout.drives.append(_Drive(p, index, j, kinematic))
    if element_kind(j) == PRISMATIC or kinematic:  # its joint is the drive's constraint
        layout.eliminated.add(id(j))
    if kinematic and element_kind(j) == REVOLUTE and any(plane_point(j.child_anchor)):
        layout.cog[j.child] = plane_point(j.child_anchor)


def _massless_end(layout, c, bodies) -> None:
    bad = [b for b in bodies if not layout.engine_ok(b)]
    if bad:
        raise _Refused(f"constraint {c.name}: on massless body {bad[0]} that cannot be "
                       "eliminated with it")


@_builds(POINT_ON_POINT, Expression(EXACT, "PivotJoint"))
def _pivot(layout, c: PointOnPoint) -> None:
    _massless_end(layout, c, (c.body_a, c.body_b))
    layout.pivots.append((c.body_a, c.body_b, plane_point(c.point_a), plane_point(c.point_b)))


@_builds(
    POINT_ON_LINE,
    Expression(EXACT, "GrooveJoint", when="the slot line passes through the slot body's "
                                           "centre of mass (or the slot is on the world or a "
                                           "body whose rotation is fixed) and the pin is the "
                                           "pin body's",
               applies=lambda mech, slot: not _substituted(mech, slot)),
    Expression(SUBSTITUTE, "a pin slider (point mass pinned to the pin) and/or a slot "
                           "carrier (glued to the slot body, centred on the line) in an exact "
                           "GrooveJoint, their mass taken out of the host "
                           "(slider_compensation). " + _GROOVE_LIMIT,
               when="otherwise"))
def _slot(layout, c: PointOnLine) -> None:
    _massless_end(layout, c, (c.body, c.line_body))
    point, base, axis = (np.array(plane_point(v)) for v in (c.point, c.line_point, c.direction))
    direction = axis / float(np.linalg.norm(axis))

    def substitute(kind: str, host: str, at: np.ndarray) -> str:
        """A carrier of `host` at its point `at`: a glued slot carrier (kind "slot") or
        a point-mass pin slider (kind "pin"), pinned there."""
        m, inertia = num(layout.mech.body(host).mass), num(layout.mech.body(host).inertia)
        mass = float(layout.cfg["slider_mass_fraction"]) * effective_mass(
            m, inertia, float(np.linalg.norm(at)))
        name = f"_{kind}_{'carrier' if kind == 'slot' else 'slider'}_{c.name}"
        layout.carriers.append(_Carrier(name, host, kind, tuple(at), mass,
                                        mass * inertia / m if kind == "slot" else math.inf,
                                        c.name))
        layout.pivots.append((host, name, tuple(at), (0.0, 0.0)))
        return name

    slot, pin, anchor = c.line_body, c.body, point
    if slot != WORLD and not line_through_origin(base, direction):
        if rotation_fixed(layout.mech, slot):
            layout.infinite.add(slot)
        else:  # slot carrier glued to the slot body, its centre on the line
            foot = base - float(base @ direction) * direction
            slot, base = substitute("slot", slot, foot), base - foot
            layout.gears.append((c.line_body, slot, 0.0, 1.0))
    if pin != WORLD and point.any():
        if rotation_fixed(layout.mech, pin):
            layout.infinite.add(pin)
        else:  # pin slider: a point mass pinned to the pin point
            pin, anchor = substitute("pin", pin, point), np.zeros(2)
    layout.grooves.append(_Groove(slot, pin, tuple(base), tuple(direction), None, None,
                                  tuple(anchor), None))


@_builds(ROLLING_CONTACT, Expression(
    SUBSTITUTE, "the pitch circles collide (a Circle inside a ring of contact_segments "
                "Segments) with Coulomb friction, the carrier arm removed: what a "
                "game-physics user would build. Measured on the disc of Fig. 39: trajectory "
                "error 2-10 % of the amplitude (coupling 2-2.6e-3), slip up to 3e-4 m, "
                "single-step losses of contact from one chord to the next"))
def _contact(layout, c: RollingContact) -> None:
    _coupling(layout, c.coupling, contact=True)


@_builds(
    LINEAR_COUPLING,
    Expression(EXACT, "GearJoint on the absolute angles of two bodies",
               when="two body angles",
               applies=lambda mech, coupling: not _substituted(mech, coupling)),
    Expression(EXACT, "a PivotJoint between the two bodies hinged on a common carrier, "
                      "moved to the pitch point before every solve: its tangential row is "
                      "the coupling (gear pair, belt, rolling); other couplings are refused "
                      "(support)",
               when="three body angles, two hinged on a carrier"))
def _coupling(layout, c: LinearCoupling, contact: bool = False) -> None:
    """A GearJoint (two body angles) or a pitch pair (`_Pitch`); refused when the coupling
    cannot be expressed. With `contact` (a RollingContact stands for the coupling) the pitch
    circles collide instead: that needs a pitch pair on a massless carrier, whose arm the
    contact replaces."""
    mech, engine_ok, massless = layout.mech, layout.engine_ok, layout.massless
    slides = [name for name, _ in c.coefficients
              if element_kind(mech.joints[mech.coordinates.index(name)]) == PRISMATIC]
    if slides:
        raise _Refused(f"coupling {c.name}: coordinate {slides[0]} is prismatic; Chipmunk "
                       "couples only angles (GearJoint)")
    k, k0, bodies, scale = coupled_angles(mech, c)
    if not bodies:
        raise _Refused(f"coupling {c.name}: no body angle enters it")
    arm = (f"contact {c.name}: the disc and the track must be hinged on a massless carrier "
           "arm, which the contact replaces")
    if len(bodies) <= 2 and all(engine_ok(b) for b in bodies):
        if contact:
            raise _Refused(arm)
        a, b = bodies if len(bodies) == 2 else (bodies[0], WORLD)
        layout.gears.append((a, b, -k0 / k[a], 1.0 if b == WORLD else -k[b] / k[a]))
        return
    for pair in pitch_pairs(mech, k, bodies, scale):
        if not (engine_ok(pair.a) and engine_ok(pair.b)):
            continue
        if contact and pair.carrier not in massless:  # its hinges would keep the distance
            raise _Refused(arm)
        wrap = 2 * math.pi * abs(k[pair.carrier]) if pair.carrier in massless else 0.0
        layout.pitches.append(_Pitch(*astuple(pair), c.name, wrap, contact))
        return
    raise _Refused(f"coupling {c.name}: on the angles of {sorted(bodies)}; Chipmunk's GearJoint "
                   "couples the absolute angles of two bodies, and a coupling of three is "
                   "expressible here only as two bodies hinged on a common carrier (gear pair, "
                   "belt, rolling: a pivot at the pitch point)")


_ELEMENTS.refuses(HINGE_CLOSURE, "Pymunk is a planar (2-D) engine: a spatial closed loop "
                                  "has no expression in it", "pymunk")


def _plan(mech: Mechanism, cfg: Mapping) -> _Layout:
    """The engine layout at the resolved settings `cfg`, built by each element's
    registered builder; refused (`_Refused`, with the reason) when the mechanism cannot be
    expressed. The bodies and prescribed motions come first (which bodies are engine
    bodies, which joints a drive holds), then the eliminated links' shapes
    (`plan.Elimination`), the joints, the links, the closures."""
    reason = description_reason(mech)
    if reason:
        raise _Refused(reason)
    layout = _Layout(mech, cfg)
    massless = layout.massless
    for body in mech.bodies:
        if body.name not in massless:  # a massless body's builder runs after the joints
            _builder(body)(layout, body)
    for p in mech.prescribed:
        _builder(p)(layout, p)
    try:
        layout.elimination = Elimination(mech)
    except NotEliminable as reason:
        raise _Refused(f"{reason} (Chipmunk has no massless bodies)") from None
    layout.eliminated |= layout.elimination.joints
    for element in (*mech.joints, *map(mech.body, massless)):
        _builder(element)(layout, element)
    for c in mech.constraints:
        if id(c) not in layout.elimination.closures:
            _builder(c)(layout, c)
    _engine_masses(layout)
    return layout


def _engine_masses(layout: _Layout) -> None:
    """The engine (mass, moment) of every engine body, the slider substitutes' taken out
    of their hosts (setting slider_compensation) where every groove stays exact; refused
    when a groove is not exact."""
    mech = layout.mech
    for name in layout.dynamic:
        layout.engine_mass[name] = _mass_moment(layout, name)
    for car in layout.carriers:
        layout.engine_mass[car.name] = (car.mass, car.moment)
    if layout.cfg["slider_compensation"]:
        for host in dict.fromkeys(car.host for car in layout.carriers):
            m1, c1, i1 = compensated_host(
                num(mech.body(host).mass), num(mech.body(host).inertia),
                [(car.mass, car.point, car.moment if car.kind == "slot" else 0.0)
                 for car in layout.carriers if car.host == host])
            if m1 > 0 and i1 > 0:  # else not compensated: no mass or moment would be left
                layout.engine_mass[host] = (m1, i1)
                layout.cog[host] = (float(c1[0]), float(c1[1]))
    # every groove must stay exact with the engine centres of mass: not compensated where a
    # host's centre of gravity must stay on a groove
    for _ in range(2):
        for g in layout.grooves:
            for body, ok in zip((g.slot, g.pin), _groove_exact(layout, g)):
                if not ok and body in layout.cog:
                    del layout.cog[body]
                    layout.engine_mass[body] = _mass_moment(layout, body)
    for g in layout.grooves:
        if not all(_groove_exact(layout, g)):
            raise _Refused(f"groove {g.slot}/{g.pin} is not exact in Chipmunk. {_GROOVE_LIMIT}")


def _mass_moment(layout: _Layout, name: str) -> tuple[float, float]:
    """A description body's engine (mass, moment): the moment is infinite where its
    rotation is fixed (`_engine_body`), else its central inertia, or m r^2 for a point
    mass (the BODY expressions; r the setting point_mass_gyration)."""
    body = layout.mech.body(name)
    inertia = num(body.inertia)
    if name in layout.infinite:
        inertia = math.inf
    elif not inertia > 0:
        inertia = num(body.mass) * float(layout.cfg["point_mass_gyration"]) ** 2
    return num(body.mass), inertia


def _groove_exact(layout: _Layout, g: _Groove) -> tuple[bool, bool]:
    """Whether the groove's slot line passes through the slot body's engine centre of
    mass, and whether its pin is the pin body's (`_GROOVE_LIMIT`): not needed on the world
    or a body of infinite moment (a fixed rotation, a point-mass slider)."""
    slot_ok = g.slot == WORLD or g.slot in layout.infinite or line_through_origin(
        np.subtract(g.base, layout.cog.get(g.slot, (0.0, 0.0))), np.array(g.direction))
    pin_ok = (g.pin == WORLD or layout.engine_mass.get(g.pin, (1, 1))[1] == math.inf
              or np.allclose(g.anchor, layout.cog.get(g.pin, (0.0, 0.0)), rtol=0, atol=1e-12))
    return slot_ok, pin_ok


_CACHE: dict[tuple, MaximalFrames] = {}


def _compile(mech: Mechanism, layout: _Layout) -> MaximalFrames:
    """How every description body's frame follows from the layout's engine bodies and the
    force elements' loads on them (`plan.MaximalFrames`; the substitute carriers follow no
    description frame), compiled once and reused by every run on the same engine bodies."""
    key = (mech, tuple(layout.engine), tuple(sorted(layout.cog.items())),
           tuple(sorted(layout.engine_mass.items())), tuple(layout.pitches))
    if key not in _CACHE:
        if len(_CACHE) > 64:
            _CACHE.clear()
        _CACHE[key] = MaximalFrames(mech, layout.elimination, layout.engine,
                                    {name: layout.cog.get(name) for name in layout.dynamic},
                                    [_builder(f)(mech, f) for f in mech.forces])
    return _CACHE[key]


def _parts(mech: Mechanism, layout: _Layout) -> list[tuple[str, float, float]]:
    """Per engine body, the description body it makes up (a substitute's host), its mass
    and its moment (`reactions.maximal_balance`); an infinite moment is a fixed rotation
    (alpha = 0: the described inertia) or a point-mass slider (none)."""
    carriers = {c.name: c for c in layout.carriers}
    out = []
    for name in layout.engine:
        m, inertia = layout.engine_mass[name]
        if inertia == math.inf:
            inertia = num(mech.body(name).inertia) if name in layout.dynamic else 0.0
        out.append((name if name in layout.dynamic else carriers[name].host, m, inertia))
    return out


def _substituted(mech: Mechanism, c: PointOnLine | LinearCoupling) -> bool:
    """In the layout at the default settings (refused as a whole: translation_reason), a
    slot's pin or line sits on a substitute carrier body, or a coupling is held by a pivot
    moved to the pitch point of a carrier."""
    try:
        layout = _plan(mech, BACKEND.default_settings())
    except _Refused:
        return False
    return c.name in {car.constraint for car in layout.carriers} | {p.name for p in layout.pitches}


class PymunkBackend(Backend):
    id = "pymunk"
    SETTINGS = {
        "point_mass_gyration": Setting(
            POINT_MASS_GYRATION, float,
            "Radius of gyration r (m) of the moment m r^2 given to a point mass (central "
            "inertia 0; Chipmunk needs a moment > 0): its moment about a pivot at d "
            "grows by the relative (r/d)^2, negligible while r is far below the "
            "mechanism's lengths."),
        "error_bias": Setting(
            0.0, float,
            "Fraction of a joint's position error left after 1 s, on every constraint. 0 "
            "removes the whole error in the next step (bias velocity -error/h). The "
            "engine default (a tenth of the error removed per sixtieth of a second, by "
            "the formula quoted below) removes only part of it per step, and its "
            "correction velocity enters the real velocity: the joint gap stays O(h) "
            "instead of O(h^2), and the correction's velocity feeds the trajectory and "
            "the energy (the out-of-the-box study measures by how much). Engine default: "
            "Pymunk API reference, Constraint.error_bias 'Defaults to pow(1.0 - 0.1, "
            "60.0)'.",
            engine_default=0.9 ** 60),
        "iterations": Setting(
            50, int,
            "Gauss-Seidel velocity iterations per step (space.iterations). A single joint "
            "is solved in one iteration, a chain is not: a double pendulum's reactions "
            "keep converging with the iterations after its trajectory has, and a scotch "
            "yoke with light slider substitutes diverged with the engine default. 50 "
            "keeps a margin at negligible cost. Engine default: Pymunk API reference, "
            "Space.iterations 'Defaults to 10'.",
            engine_default=10),
        "start_iterations": Setting(
            1000, int,
            "Gauss-Seidel iterations of the first step only, which has no previous "
            "impulses to warm-start from: with only the per-step iterations, a closed "
            "loop or a slider substitute is left unconverged (the rhombus's slot force "
            "is off at the first samples). Later steps converge from the warm start; "
            "tree mechanisms were already converged (bit-identical results)."),
        "damping": Setting(
            1.0, float,
            "space.damping, the fraction of velocity kept after 1 s: Pymunk's default 1 (no "
            "damping), stated so that it is recorded."),
        "sleep_time_threshold": Setting(
            None, (float, type(None)),
            "space.sleep_time_threshold in s; null = never sleep (Pymunk default inf). "
            "Sleeping freezes a small oscillation (a body below the sleep threshold stops)."),
        "element_forces": Setting(
            "position_updated", _FORCE_MODES,
            "When force elements are evaluated in a step. Chipmunk moves positions (x += "
            "h v) before it applies body.force, so a force from the state sampled before "
            "space.step() ('step_start', what user code usually does) makes the step "
            "explicit Euler for it, which pumps energy into every oscillation (elastic "
            "pendulum, sliding block). 'position_updated' evaluates the laws at x + h v "
            "and t + h, where Chipmunk pre-steps its constraints and its own "
            "DampedSpring: a consistent semi-implicit Euler step (symplectic: on "
            "conservative laws its energy error stays bounded, O(h)). Pymunk has no hook for laws of length rate or "
            "time, so the backend applies body forces and torques (no engine default is "
            "replaced)."),
        "groove_half_length": Setting(
            1000.0, float,
            "Extent (m) of a Chipmunk groove (a finite segment whose ends act as stops) on "
            "a prismatic side without a limit and on every point-on-line slot; the "
            "description's finite limits are the groove ends."),
        "slider_mass_fraction": Setting(
            0.5, float,
            "Mass of a slider substitute (a pin-in-slot whose GrooveJoint would not be "
            "exact: the POINT_ON_LINE expression) as this fraction of the host body's "
            "effective mass at its point, m I / (I + m d^2); must stay below 1 (the host "
            "keeps a positive moment). With slider_compensation it does not enter the "
            "dynamics (the scotch yoke's trajectory is the same at every fraction), only "
            "the convergence of the Gauss-Seidel solve, slow for a light body between "
            "heavy ones: from the cold start a lighter slider leaves the slot force "
            "further off at the first samples, and a very light one made the rhombus "
            "loop diverge unless the iterations were raised."),
        "slider_compensation": Setting(
            True, bool,
            "true: the substitute's mass (and a slot carrier's moment) is taken out of "
            "its host (mass, centre of gravity via body.center_of_gravity, moment), so "
            "host + substitute have exactly the described inertia; false: the substitute "
            "adds its mass to the mechanism (teaching mode: shows the dynamic effect of "
            "a slider mass, the error that the compensation removes; the scotch yoke and "
            "the slotted link show it)."),
        "prescribed_motion": Setting(
            _DRIVE_ROUTES[0], _DRIVE_ROUTES,
            "How a Prescribed coordinate q(t) is imposed (Pymunk has no driven joint; "
            "the PRESCRIBED expression says how each route builds it). "
            "'kinematic_on_world' (default): a joint on the world makes its child a "
            "Body.KINEMATIC driver (its centre of gravity on the hinge); a joint on a "
            "free body (a rotor on a frame, an inner mass in a frame) is a moving "
            "constraint, so the frame feels the driven body's inertia. "
            "'moving_constraint': the constraint on the world too (a light driven body "
            "between the world and a heavy child makes the Gauss-Seidel solve diverge, "
            "or converge only with far more iterations: a block running out of the slot "
            "of a turning disc). Either way the coordinate starts with the rate (q(h) - "
            "q0)/h. With the default, the free coordinates and the actuator force "
            "converge at the scheme's first order in the step, and the prescribed "
            "coordinate is exact to round-off (a block on a base moved at its natural "
            "frequency, a block on a spring in the slot of a turning disc, a frame on a "
            "spring shaken by an unbalanced rotor)."),
        "contact_friction": Setting(
            10.0, float,
            "Friction coefficient of a RollingContact (Chipmunk multiplies the two shapes' "
            "coefficients: this one on the inner shape, 1 on the ring). Must exceed "
            "|friction| / normal force at all times or the disc slides."),
        "contact_segments": Setting(
            720, int,
            "Number of Segment shapes of a RollingContact's ring, inscribed in the "
            "pitch circle; space.collision_slop is set to the chord's sagitta so that the "
            "polygon's penetration is not 'corrected' against the carrier joint."),
    }

    ENGINE_MODULES = ('pymunk',)

    def version(self) -> str:
        import pymunk

        return f"{pymunk.version} (Chipmunk {pymunk.chipmunk_version.split('-')[0]})"

    EXPRESSIONS = _ELEMENTS.declared()

    SPATIAL_REASON = ("Pymunk is a planar (2-D) engine: a spatial mechanism (full inertia "
                      "tensor, hinges about horizontal axes) has no expression in it")

    def translation_reason(self, mechanism: Mechanism) -> str:
        try:
            _plan(mechanism, self.default_settings())
        except _Refused as refused:
            return str(refused)
        return ""

    # --- building ------------------------------------------------------------------------
    def _prepare(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray, cfg: dict,
                 h: float):
        """Build: (layout, compiled functions, space, engine bodies, the mechanism as
        balanced: a RollingContact stands for its coupling, the movers of the prescribed
        coordinates)."""
        import pymunk

        try:
            layout = _plan(mechanism, cfg)
        except _Refused as refused:
            raise ValueError(f"pymunk cannot express this mechanism: {refused}") from None
        if layout.drives:
            # every step moves a prescribed coordinate with (q(t + h) - q)/h: started with
            # q'(0), the driven body's velocity would jump by h q'' twice (actuator force
            # 0.62 and 0.31 of its range off at samples 1 and 2 on a shaker driven by cos,
            # whatever h)
            qd0 = stepped_start(mechanism, q0, qd0, h)
        # a RollingContact's force is balanced as the coupling it stands for (the layout
        # holds the contact itself)
        mech = coupled(mechanism)
        comp = _compile(mech, layout)
        space = pymunk.Space()
        space.gravity = (0.0, -num(mech.gravity))
        space.damping = float(cfg["damping"])
        space.iterations = int(cfg["iterations"])
        sleep = cfg["sleep_time_threshold"]
        space.sleep_time_threshold = math.inf if sleep is None else float(sleep)
        state = body_states(mech, q0, qd0)
        bodies: dict[str, pymunk.Body] = {WORLD: space.static_body}
        drivers = {d.joint.child for d in layout.drives if d.kinematic}
        for name in layout.engine:
            # no shapes: nothing collides
            body = (pymunk.Body(body_type=pymunk.Body.KINEMATIC) if name in drivers
                    else pymunk.Body(*layout.engine_mass[name]))
            if name in layout.dynamic:
                x, y, th, vx, vy, w = state[name]
                cog = layout.cog.get(name)
            else:
                car = next(c for c in layout.carriers if c.name == name)
                x, y, vx, vy = point_state(state[car.host], car.point)
                th, w = (state[car.host][2], state[car.host][5]) if car.kind == "slot" else (0.0, 0.0)
                cog = None
            body.angle = th  # before the position: pymunk places the frame with the angle
            if cog:
                body.center_of_gravity = cog
                _, _, vx, vy = point_state((x, y, th, vx, vy, w), cog)
            body.position = (x, y)
            body.velocity = (vx, vy)  # of the centre of gravity
            body.angular_velocity = w
            space.add(body)
            bodies[name] = body
        half = float(cfg["groove_half_length"])

        def spins(name: str) -> bool:
            return name != WORLD and layout.engine_mass[name][1] != math.inf

        constraints: list = []
        for parent, child, pa, ca in layout.pivots:
            constraints.append(pymunk.PivotJoint(bodies[parent], bodies[child], pa, ca))
        # a rolling contact holds the disc itself: the arm that stood for it goes (kept, the
        # distance would be enforced twice and Gauss-Seidel may leave the contact's normal
        # impulse, hence its friction, at zero)
        replaced = {p.carrier for p in layout.pitches if p.contact}
        for a, b, pa, pb, link in layout.pins:
            if link not in replaced:
                constraints.append(pymunk.PinJoint(bodies[a], bodies[b], pa, pb))
        for g in layout.grooves:
            base, direction = np.array(g.base), np.array(g.direction)
            lo = -half if g.lo is None else g.lo
            hi = half if g.hi is None else g.hi
            a, b = bodies[g.slot], bodies[g.pin]
            constraints.append(pymunk.GrooveJoint(a, b, tuple(base + lo * direction),
                                                  tuple(base + hi * direction), g.anchor))
            if g.phase is not None and (spins(g.slot) or spins(g.pin)):
                constraints.append(pymunk.GearJoint(a, b, g.phase, 1.0))
        for a, b, phase, ratio in layout.gears:
            constraints.append(pymunk.GearJoint(bodies[a], bodies[b], phase, ratio))
        for i, pitch in enumerate(layout.pitches):
            if pitch.contact:
                self._contact_shapes(space, bodies, pitch, i, cfg)
            else:
                constraints.append(self._pitch_pivot(pymunk, bodies, layout, pitch,
                                                     comp.coupling_phi(pitch.name)))
        for c in constraints:
            c.error_bias = float(cfg["error_bias"])
        space.add(*constraints)
        movers = self._drive_constraints(layout, space, bodies, spins, q0)
        return layout, comp, space, [bodies[n] for n in layout.engine], mech, movers

    @staticmethod
    def _drive_constraints(layout: _Layout, space, bodies: dict, spins, q0):
        """The constraints that impose the prescribed coordinates (the PRESCRIBED
        expression; a hinge's PivotJoint is built with the other hinges), added to the
        space, and per coordinate (constraint, attribute, value of q): the attribute that
        moves its target to the pose q gives (`plan.joint_pose`); a kinematic driver's is
        its body. Their error_bias is 0 whatever the setting: the gap to the target is
        removed in one step (bias velocity -gap/h), which is how the target becomes the
        position of the next step."""
        import pymunk

        movers = []
        for d in layout.drives:
            j = d.joint
            if d.kinematic:
                movers.append(bodies[j.child])
                continue
            child, pose, q = bodies[j.child], joint_pose(j), float(q0[d.index])
            if element_kind(j) == PRISMATIC:
                parent = bodies[j.parent]
                added = [pymunk.PivotJoint(parent, child, pose(q), plane_point(j.child_anchor))]
                if spins(j.parent) or spins(j.child):
                    added.append(pymunk.GearJoint(parent, child, num(j.angle_offset), 1.0))
                movers.append((added[0], "anchor_a", pose))
            else:
                parent = bodies[WORLD if j.absolute else j.parent]
                added = [pymunk.GearJoint(parent, child, pose(q), 1.0)]
                movers.append((added[0], "phase", pose))
            for c in added:
                c.error_bias = 0.0
            space.add(*added)
        return movers

    @staticmethod
    def _schedule(layout: _Layout, movers, n_steps: int, h: float):
        """Per mover (constraint, attribute, values): the value to set before step k, the
        target q(t_(k+2)). Chipmunk moves positions with the velocities of the previous
        step's solve, so the velocity solved in step k (at the positions of t_(k+1), bias
        -gap/h) carries the coordinate to q(t_(k+2)) in step k + 1."""
        out = []
        for d, mover in zip(layout.drives, movers):
            targets = [d.position((k + 2) * h) for k in range(n_steps)]
            if d.kinematic:
                PymunkBackend._drive_kinematic(d, mover, targets, h)
                continue
            constraint, attribute, value = mover
            out.append((constraint, attribute, [value(q) for q in targets]))
        return out

    @staticmethod
    def _drive_kinematic(d: _Drive, body, targets: list[float], h: float) -> None:
        """A kinematic driver on the world: its velocity_func (called in step k after
        the positions moved to t_(k+1), before the solve) sets the velocity that carries
        it to q(t_(k+2)) in step k + 1, so the free bodies' constraints are solved against
        the driver's velocity of the next position update, as with a moving constraint.
        Its engine centre of gravity is the hinge point (or it does not turn), whose
        velocity is the joint's (`plan.joint_velocity`: its parent is the world)."""
        rates = np.diff([d.position(h), *targets]) / h
        step = iter([joint_velocity(d.joint, r) for r in rates])

        def velocity_func(body, gravity, damping, dt):
            vx, vy, w = next(step)
            body.velocity = (vx, vy)
            body.angular_velocity = w

        body.velocity_func = velocity_func

    @staticmethod
    def _pitch_pivot(pymunk, bodies, layout: _Layout, pitch: _Pitch, phi_fn):
        """PivotJoint between the two coupled bodies, moved to the pitch points before
        every solve (the module docstring)."""
        a, b = bodies[pitch.a], bodies[pitch.b]
        engine = [bodies[n] for n in layout.engine]
        cogs = [layout.cog.get(n) for n in layout.engine]
        last: list[float | None] = [None]

        def anchors():
            pos = []
            for body, cog in zip(engine, cogs):
                p = body.local_to_world(cog) if cog else body.position
                pos += [p.x, p.y, body.angle]
            value = phi_fn(*pos)
            if pitch.wrap and last[0] is not None:  # a massless carrier's angle wrapped
                value += pitch.wrap * round((last[0] - value) / pitch.wrap)
            last[0] = value
            ca, cb = pitch.pitch_points(a.local_to_world(pitch.hub_a),
                                        b.local_to_world(pitch.hub_b), value)
            return a.world_to_local(ca), b.world_to_local(cb)

        pa, pb = anchors()
        joint = pymunk.PivotJoint(a, b, pa, pb)

        def pre_solve(constraint, space):
            constraint.anchor_a, constraint.anchor_b = anchors()

        joint.pre_solve = pre_solve
        return joint

    @staticmethod
    def _contact_shapes(space, bodies, pitch: _Pitch, index: int, cfg: dict) -> None:
        """The pitch circles as colliding shapes with friction (a RollingContact)."""
        import pymunk

        a, hub_a, rho_a, b, hub_b, rho_b, internal = pitch.circles
        flt = pymunk.ShapeFilter(categories=1 << (index % 32), mask=1 << (index % 32))
        shapes = []
        if internal:
            (ring, centre, rho), (disc, dcentre, drho) = sorted(
                [(a, hub_a, rho_a), (b, hub_b, rho_b)], key=lambda s: -s[2])
            n = int(cfg["contact_segments"])
            # chords inscribed in the pitch circle, rounded with the sagitta: the disc on
            # the pitch circle overlaps them by between 1 and 2 sagittas everywhere (at a
            # vertex too), so the contact never opens; a slop of 3 sagittas keeps Chipmunk
            # from pushing the disc out of that overlap
            pts, sagitta = ring_of_chords(centre, rho, n)
            segs = [pymunk.Segment(bodies[ring], pts[i], pts[(i + 1) % n], sagitta)
                    for i in range(n)]
            for i, seg in enumerate(segs):
                seg.set_neighbors(pts[i - 1], pts[(i + 2) % n])
                seg.friction = 1.0
            shapes += segs
            circle = pymunk.Circle(bodies[disc], drho, tuple(dcentre))
            circle.friction = float(cfg["contact_friction"])
            shapes.append(circle)
            space.collision_slop = 3.0 * sagitta
        else:
            # two circles held at touching distance by the carrier: inflated by 1e-6 of
            # their size so that they overlap (and stay in contact), slop above that
            grow = 1e-6 * max(rho_a, rho_b)
            for body, centre, rho in ((a, hub_a, rho_a), (b, hub_b, rho_b)):
                circle = pymunk.Circle(bodies[body], rho + grow, tuple(centre))
                circle.friction = float(cfg["contact_friction"]) if body == b else 1.0
                shapes.append(circle)
            space.collision_slop = 4.0 * grow
        for s in shapes:
            s.elasticity = 0.0
            s.filter = flt
        space.add(*shapes)

    # --- running -------------------------------------------------------------------------
    @staticmethod
    def _reader(space, layout: _Layout, bodies: list) -> Callable[[], list[float]]:
        """A function returning the state row of the engine bodies: per body, the centre
        of gravity (x, y), angle, its velocity (vx, vy) and angular velocity. The row is
        read for all bodies by one `pymunk.batch` call when the space lists them in
        `bodies` order and none can fall asleep (which would reorder them); the position
        of a body whose centre of gravity is off its frame origin is then read again as
        `local_to_world(cog)`, as the body-by-body read does."""
        import pymunk.batch

        cogs = [layout.cog.get(n) for n in layout.engine]
        off_origin = [(6 * i, b, cog) for i, (b, cog) in enumerate(zip(bodies, cogs)) if cog]

        def centred(row: list[float]) -> list[float]:
            for i, b, cog in off_origin:
                row[i:i + 2] = b.local_to_world(cog)
            return row

        fields = pymunk.batch.BodyFields
        buffer = pymunk.batch.Buffer()
        get = pymunk.batch.get_space_bodies
        get(space, fields.BODY_ID, buffer)
        ids = list(memoryview(buffer.int_buf()).cast("P"))
        if space.sleep_time_threshold != math.inf or ids[:len(bodies)] != [b.id for b in bodies]:
            return lambda: centred([v for b in bodies for v in (
                *b.position, b.angle, *b.velocity, b.angular_velocity)])
        wanted = fields.POSITION | fields.ANGLE | fields.VELOCITY | fields.ANGULAR_VELOCITY
        width = 6 * len(bodies)

        def read_batch() -> list[float]:
            buffer.clear()
            get(space, wanted, buffer)
            return centred(memoryview(buffer.float_buf()).cast("d")[:width].tolist())

        return read_batch

    def _bare_loop_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                        n_steps: int, dt: float, cfg: dict) -> BareLoop:
        """The space of `simulate` stepped with only its element forces: those need the
        state at the start of each step, the rest runs step after step. Angles of
        eliminated links (read by atan2) are given on the branch nearest the start."""
        run = self._run(mechanism, q0, qd0, n_steps, float(dt), cfg, record=False)
        q, qd = run.comp.coordinates(np.array([run.read()]), q0)
        return BareLoop(run.clock.cpu, q[0], qd[0])

    def _run(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray, n_steps: int,
             h: float, cfg: dict, record: bool) -> SimpleNamespace:
        """Build the space and take `n_steps` steps of `h`, timed; with `record` every
        sample's body states are read (`rows`), otherwise only what the element forces
        need. Returns the run's parts: layout, mechanism (as balanced), comp, clock, read,
        rows, H and shift (where the loads are evaluated)."""
        layout, comp, space, bodies, mechanism, movers = self._prepare(mechanism, q0, qd0, cfg, h)
        # loads at x + h v and t + h (see setting notes), or at the sampled state
        H, shift = (h, 1) if cfg["element_forces"] == "position_updated" else (0.0, 0)
        read = self._reader(space, layout, bodies)
        rows = [read()] if record else []
        step = space.step
        loads = comp.loads_math
        targets = [bodies[k] for k in comp.loaded]
        schedule = self._schedule(layout, movers, n_steps, h)
        iterations = int(cfg["iterations"])
        # the first step has no cached impulses to start from (see start_iterations)
        space.iterations = max(iterations, int(cfg["start_iterations"]))
        with Stopwatch() as clock:
            for k in range(n_steps):
                if loads is not None:
                    out = loads(*(rows[-1] if record else read()), H, (k + shift) * h)
                    for i, b in enumerate(targets):
                        b.force = (out[3 * i], out[3 * i + 1])
                        b.torque = out[3 * i + 2]
                for constraint, attribute, values in schedule:
                    setattr(constraint, attribute, values[k])
                step(h)
                if record:
                    rows.append(read())
                if k == 0:
                    space.iterations = iterations
        return SimpleNamespace(layout=layout, mechanism=mechanism, comp=comp, clock=clock,
                               read=read, rows=rows, H=H, shift=shift)

    # no `linearize`: Chipmunk has no linearization facility, frequencies come from the fits
    def scheme(self, mechanism: Mechanism, settings: Mapping | None = None) -> Scheme:
        return Scheme("semi-implicit Euler", 1, SEMI_IMPLICIT_EULER_STABILITY)

    def export(self, mechanism: Mechanism, coordinates: Sequence[str],
               initial_states: Mapping[str, tuple[np.ndarray, np.ndarray]],
               settings: Mapping | None = None, dt: float = 1e-3) -> tuple[str, list[str]]:
        """(a standalone Python script, what it does not reproduce): the space `simulate`
        builds, read back body by body and constraint by constraint
        (simulators/script_export.py), stepped as `simulate` steps it; it prints the
        engine bodies' states (the description's coordinates are computed from them by
        the harness's compiled functions, which are not written out)."""
        from .script_export import pymunk_script

        name, q0, qd0 = self.export_start(initial_states)
        cfg = self.resolve_settings(settings)
        layout, comp, space, bodies, balanced, movers = self._prepare(
            mechanism, np.asarray(q0, float), np.asarray(qd0, float), cfg, float(dt))
        outside = []
        if comp.loads_math is not None:
            outside.append("the force laws' body forces and torques, set before every "
                           "step: " + ", ".join(f.name for f in mechanism.forces))
        if layout.drives:
            outside.append("the prescribed motions' moving targets and kinematic drivers: "
                           + ", ".join(p.name for p in mechanism.prescribed))
        if any(c.pre_solve is not None for c in space.constraints):
            outside.append("the pre-solve callbacks that move rolling pitch points")
        text = pymunk_script(
            title=self.script_title("Pymunk", name, cfg), space=space,
            first_iterations=max(int(cfg["iterations"]), int(cfg["start_iterations"])),
            iterations=int(cfg["iterations"]),
            names=dict(zip(bodies, layout.engine)), dt=dt, not_in_script=outside)
        return text, outside

    def _simulate_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                       n_steps: int, dt: float, cfg: dict,
                       reaction_joints: tuple[str, ...]) -> Samples:
        """The samples and the forces. Chipmunk reports only an impulse's magnitude, and a
        closure may be a substitute (slider, pitch pivot, contact), so the forces over each
        step n -> n+1 come from Newton-Euler over the step, minus the element loads as
        applied in it (at the position-updated state x + H v and t + shift h;
        `reactions.motion_forces`): in a tree, on the joint child's subtree; with closure
        constraints, the balance of every description body, made of its engine parts
        (`_parts`). Chipmunk computes that impulse at the position-updated configuration
        x(n+1), so it is given to sample n+1 (on the pendulums it is several times closer to
        the model's reaction at that sample than at sample n); sample 0 has no step before
        it and is NaN. A start with angular velocity shows an O(1) transient at sample 1
        of a tree's reactions: the first step also builds the steady O(h^2) joint gap of
        the position update, and its impulse contains that correction. With closures a
        start with velocity shows one too: Chipmunk's velocity is staggered (v_n ~ v(t_n +
        h/2), whose constraint component is -h times the curvature term), the exact
        initial velocity is not, and the first impulse makes up the difference: 1.5 times
        the centripetal part (eccentric cam spinning at 40 rad/s: contact force 0.38 off at
        sample 1, 5e-4 at sample 2)."""
        h = float(dt)
        run = self._run(mechanism, q0, qd0, n_steps, h, cfg, record=True)
        mechanism, comp, layout = run.mechanism, run.comp, run.layout
        S = np.array(run.rows)
        t = np.arange(n_steps + 1) * h
        q, qd = comp.coordinates(S, q0)
        reactions, constraint_forces, actuator_forces, _ = motion_forces(
            mechanism, comp, S, _parts(mechanism, layout), run.H, t[:-1] + run.shift * h,
            h, reaction_joints, {d.name: d.joint for d in layout.drives})
        return Samples(q, qd, run.clock, reactions, constraint_forces, actuator_forces)

    # --- flexible elements (contract point 12) ----------------------------------------------
    BEAM_ELEMENTS = {
        NO_BEAM_ELEMENT: BeamElement(Expression(
            UNSUPPORTED, "Pymunk (Chipmunk2D) simulates rigid bodies only: no flexible or "
                         "deformable element of any kind. A beam there is a chain of rigid "
                         "segments with rotational springs (the discretized model of issue "
                         "12)")),
    }


BACKEND = PymunkBackend()
