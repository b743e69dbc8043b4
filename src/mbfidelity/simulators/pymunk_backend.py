"""Pymunk (Chipmunk 2) backend: planar rigid bodies in maximal coordinates.

Translation of the description (conventions of `mbfidelity.systems.model`):

* every body with mass becomes a ``pymunk.Body(mass, moment)`` whose frame is the centre
  of mass (Chipmunk's centre of gravity left at the origin); the world is
  ``space.static_body`` (at the origin, angle 0). No shapes are created, so nothing can
  collide.
* ``Revolute`` -> ``PivotJoint`` at the two local anchors.
* ``Prismatic`` -> ``GrooveJoint`` whose slot is the path of the child's centre of mass
  in the parent's frame (pa - R(offset) ca + q axis, q between the limits, or
  +-``groove_half_length`` where a side is unbounded) with the pin at the child's centre
  of mass, plus a ``GearJoint`` (ratio 1, phase = angle_offset) that locks the relative
  rotation.
* Chipmunk has no massless bodies. A massless link with one revolute and one prismatic
  joint (a guide arm carrying a slider, or a slider carrying a pin) is folded: the link
  turns with the body on the far side of its prismatic joint (its "partner") and its
  revolute point (the "pin") is a point of the other body, so the pair of joints is one
  ``GrooveJoint``: a slot in the partner's frame along which the pin slides. Loads on the
  folded link are moved to the real bodies by virtual power (a force f at a link point W
  = f at the pin on the pin's body + torque (W - pin) x f on the partner).
* Chipmunk's groove impulse is exact only when the slot passes through the slot body's
  centre of mass and the pin is the pin body's centre of mass (or either is the world):
  it solves the full 2x2 point problem and projects the impulse on the slot normal.
  Other geometries are reported as unsupported (see `_GROOVE_LIMIT`).
* Force elements are applied as body forces and torques, evaluated every step by one
  compiled function of the body states (a Python call per step).

Chipmunk's step (cpSpaceStep): positions x += h v (old velocity); constraints pre-step at
the new positions; v += h (g + F/m); warm-started Gauss-Seidel velocity iterations that
also remove the position error (bias velocity -error * (1 - error_bias^h) / h). It is
first order (semi-implicit Euler with velocity-level constraints).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

import numpy as np
import sympy as sp

from ..systems.model import (
    COORD,
    COORD_RATE,
    LENGTH,
    LENGTH_RATE,
    TIME,
    WORLD,
    CoordinateForce,
    Mechanism,
    PointToPoint,
    Prismatic,
    Revolute,
    as_column,
    rotation,
)
from .base import Backend, Linearization, RunResult, Support

#: how element forces are evaluated within a Chipmunk step
_FORCE_MODES = ("position_updated", "step_start")


@dataclass(frozen=True)
class _Fold:
    """A massless link folded into a GrooveJoint between `partner` and `pin_body`."""

    link: str
    inner: Revolute | Prismatic  # parent -> link
    outer: Revolute | Prismatic  # link -> child
    partner: str  # body the link turns with (the far side of its prismatic joint)
    pin_body: str  # body that carries the revolute point (the near side of it)


@dataclass(frozen=True)
class _Groove:
    """A Chipmunk GrooveJoint: the point `anchor` of body `pin` slides on the slot
    base + u direction, u in [lo, hi] (None: unbounded), fixed in body `slot`; `phase` is
    set when the relative rotation is locked as well (GearJoint, ratio 1)."""

    slot: str
    pin: str
    base: tuple[float, float]
    direction: tuple[float, float]
    lo: float | None
    hi: float | None
    anchor: tuple[float, float]
    phase: float | None


@dataclass(frozen=True)
class _Layout:
    dynamic: list[str]  # bodies with mass, in description order: the engine bodies
    folds: dict[str, _Fold]
    pivots: list[tuple[str, str, tuple[float, float], tuple[float, float]]]
    grooves: list[_Groove]


@dataclass
class _Compiled:
    """Everything derived once per mechanism (symbolic, then compiled). The engine state
    is, per engine body, (x, y, theta, vx, vy, omega)."""

    layout: _Layout
    loaded: list[int]  # indices of engine bodies that receive element loads
    loads_math: Callable | None  # (*state, H, t) -> flat (fx, fy, tau) for `loaded`
    external_np: dict[str, Callable]  # joint -> (*state, H, t) -> (fx, fy) from elements
    coords_np: Callable  # (*state) -> (q..., qd...)
    masses: dict[str, float]


def _num(x) -> float:
    return float(sp.sympify(x))


def _is_number(x) -> bool:
    return not sp.sympify(x).free_symbols


def _cross(r: sp.Matrix, f: sp.Matrix) -> sp.Expr:
    return r[0] * f[1] - r[1] * f[0]


def _vec(v) -> np.ndarray:
    return np.array([_num(v[0]), _num(v[1])])


def _rot(th: float) -> np.ndarray:
    return np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])


def _through_origin(base: np.ndarray, direction: np.ndarray) -> bool:
    """Whether the line base + u direction passes through the body's centre of mass."""
    scale = float(np.linalg.norm(direction)) * max(float(np.linalg.norm(base)), 1.0)
    return abs(float(base[0] * direction[1] - base[1] * direction[0])) <= 1e-12 * scale


_GROOVE_LIMIT = (
    "Chipmunk's GrooveJoint computes the impulse that would stop the whole relative "
    "velocity of pin and slot (2x2 mass matrix) and keeps only its component normal to "
    "the slot; that is the exact pin-in-slot impulse only if the slot normal is a "
    "principal direction of that matrix in every pose, i.e. the slot line passes through "
    "the slot body's centre of mass (or the slot is on the world) and the pin is at the "
    "pin body's centre of mass (or on the world). Otherwise the sliding velocity leaks "
    "into the normal direction (measured: velocity jump at the first step, O(h) joint "
    "drift, divergence for large offsets)")


def _grooves(mech: Mechanism, folds: dict[str, _Fold]) -> list[_Groove] | str:
    """The GrooveJoints of the prismatic joints and of the folded links, or why one of
    them would not be exact in Chipmunk."""
    out: list[_Groove] = []

    def ends(j: Prismatic) -> tuple[float | None, float | None]:
        return tuple(None if v is None else _num(v) for v in j.limits)  # type: ignore[return-value]

    folded = {id(f.outer) for f in folds.values()} | {id(f.inner) for f in folds.values()}
    for j in mech.joints:
        if not isinstance(j, Prismatic) or id(j) in folded:
            continue
        # the child's centre of mass travels on pa - R(offset) ca + q axis (parent frame);
        # with the rotation locked the pin can be the child's centre of mass
        base = _vec(j.parent_anchor) - _rot(_num(j.angle_offset)) @ _vec(j.child_anchor)
        axis = _vec(j.axis)
        if j.parent != WORLD and not _through_origin(base, axis):
            return (f"prismatic joint {j.name}: the child's centre-of-mass path misses the "
                    f"parent's centre of mass. {_GROOVE_LIMIT}")
        out.append(_Groove(j.parent, j.child, tuple(base), tuple(axis), *ends(j), (0.0, 0.0),
                           _num(j.angle_offset)))
    for fold in folds.values():
        if isinstance(fold.inner, Revolute):
            # the link turns with its child: the pivot (a point of the parent) slides on a
            # line of the child, base + q direction in the child's frame
            rev, pri = fold.inner, fold.outer
            back = _rot(-_num(pri.angle_offset))
            base = _vec(pri.child_anchor) - back @ (_vec(pri.parent_anchor) - _vec(rev.child_anchor))
            direction = -back @ _vec(pri.axis)
            anchor = _vec(rev.parent_anchor)
            slot_ok = _through_origin(base, direction)
            pin_ok = rev.parent == WORLD or not anchor.any()
        else:
            # the link turns with its parent: the pin (a point of the child) slides on a
            # line of the parent
            pri, rev = fold.inner, fold.outer
            base = _vec(pri.parent_anchor) + _rot(_num(pri.angle_offset)) @ (
                _vec(rev.parent_anchor) - _vec(pri.child_anchor))
            direction = _vec(pri.axis)
            anchor = _vec(rev.child_anchor)
            slot_ok = pri.parent == WORLD or _through_origin(base, direction)
            pin_ok = not anchor.any()
        if not (slot_ok and pin_ok):
            where = ("slot line off the slot body's centre of mass" if not slot_ok
                     else "pin off the pin body's centre of mass")
            return f"massless link {fold.link} folds into a groove with its {where}. {_GROOVE_LIMIT}"
        out.append(_Groove(fold.partner, fold.pin_body, tuple(base), tuple(direction),
                           *ends(pri), tuple(anchor), None))
    return out


def _plan(mech: Mechanism) -> _Layout | str:
    """The engine layout (bodies, folded links, pivots, grooves), or the reason the
    mechanism cannot be expressed exactly."""
    if not _is_number(mech.gravity):
        return "gravity is not numeric (pass a numeric mechanism)"
    if getattr(mech, "constraints", ()):
        names = ", ".join(f"{type(c).__name__} {c.name}" for c in mech.constraints)
        return (f"closure constraints ({names}) are not translated by this backend; only "
                "tree mechanisms (joints and folded massless links) are")
    dynamic: list[str] = []
    massless: list[str] = []
    for b in mech.bodies:
        if not (_is_number(b.mass) and _is_number(b.inertia)):
            return f"body {b.name}: mass/inertia not numeric (pass a numeric mechanism)"
        m, i = _num(b.mass), _num(b.inertia)
        if m == 0 and i == 0:
            massless.append(b.name)
        elif m > 0 and i > 0:
            dynamic.append(b.name)
        else:
            return (f"body {b.name}: mass {m} and inertia {i}; Chipmunk needs both > 0 "
                    "(or both 0 for a foldable massless link)")
    for j in mech.joints:
        if not isinstance(j, (Revolute, Prismatic)):
            return f"joint {j.name}: type {type(j).__name__} not supported"
        values = [*j.parent_anchor, *j.child_anchor, j.angle_offset]
        if isinstance(j, Prismatic):
            values += [*j.axis, *(v for v in j.limits if v is not None)]
        if not all(_is_number(v) for v in values):
            return f"joint {j.name}: geometry not numeric (pass a numeric mechanism)"
        if isinstance(j, Prismatic) and _num(j.axis[0]) ** 2 + _num(j.axis[1]) ** 2 == 0:
            return f"joint {j.name}: zero prismatic axis"
    folds: dict[str, _Fold] = {}
    for name in massless:
        inner = mech.joint_of_child(name)
        children = [j for j in mech.joints if j.parent == name]
        if len(children) != 1:
            return (f"massless body {name} has {len(children)} child joints; only a link with "
                    "exactly one child can be folded (Chipmunk has no massless bodies)")
        outer = children[0]
        if {type(inner), type(outer)} != {Revolute, Prismatic}:
            return (f"massless body {name}: joints {type(inner).__name__} + "
                    f"{type(outer).__name__}; only a revolute + prismatic pair folds into a "
                    "Chipmunk GrooveJoint")
        if inner.parent in massless or outer.child in massless:
            return f"massless body {name} is attached to another massless body"
        if isinstance(inner, Revolute):
            folds[name] = _Fold(name, inner, outer, partner=outer.child, pin_body=inner.parent)
        else:
            folds[name] = _Fold(name, inner, outer, partner=inner.parent, pin_body=outer.child)
    for f in mech.forces:
        if not isinstance(f, (PointToPoint, CoordinateForce)):
            return f"force element {f.name}: type {type(f).__name__} not supported"
        law = f.tension if isinstance(f, PointToPoint) else f.force
        if sp.sympify(law).free_symbols - {LENGTH, LENGTH_RATE, COORD, COORD_RATE, TIME}:
            return f"force element {f.name}: law has free parameters (pass a numeric mechanism)"
        if isinstance(f, PointToPoint) and not all(
                _is_number(v) for v in (*f.point_a, *f.point_b)):
            return f"force element {f.name}: points not numeric"
    grooves = _grooves(mech, folds)
    if isinstance(grooves, str):
        return grooves
    folded = {id(f.outer) for f in folds.values()} | {id(f.inner) for f in folds.values()}
    pivots = [(j.parent, j.child, tuple(_vec(j.parent_anchor)), tuple(_vec(j.child_anchor)))
              for j in mech.joints if isinstance(j, Revolute) and id(j) not in folded]
    return _Layout(dynamic, folds, pivots, grooves)


class _Kinematics:
    """Description-level poses as expressions of the engine bodies' states."""

    def __init__(self, mech: Mechanism, dynamic: list[str], folds: dict[str, _Fold]):
        self.mech, self.folds = mech, folds
        self.P: list[sp.Symbol] = []
        self.V: list[sp.Symbol] = []
        self.sym: dict[str, tuple[sp.Matrix, sp.Expr]] = {}
        for k, name in enumerate(dynamic):
            # names unlike lambdify's common-subexpression temporaries (x0, x1, ...)
            x, y, th = sp.symbols(f"bx_{k} by_{k} bth_{k}", real=True)
            vx, vy, w = sp.symbols(f"bvx_{k} bvy_{k} bw_{k}", real=True)
            self.P += [x, y, th]
            self.V += [vx, vy, w]
            self.sym[name] = (sp.Matrix([x, y]), th)
        self.sym[WORLD] = (sp.zeros(2, 1), sp.Integer(0))

    def pose(self, name: str) -> tuple[sp.Matrix, sp.Expr]:
        if name in self.sym:
            return self.sym[name]
        fold = self.folds[name]
        if isinstance(fold.inner, Revolute):  # link turns with its child, pin on the parent
            _, th_c = self.pose(fold.outer.child)
            th = th_c - fold.outer.angle_offset
            pin = self.point(fold.inner.parent, fold.inner.parent_anchor)
            p = pin - rotation(th) * as_column(fold.inner.child_anchor)
        else:  # link turns with its parent, pin on the child
            _, th_p = self.pose(fold.inner.parent)
            th = th_p + fold.inner.angle_offset
            pin = self.point(fold.outer.child, fold.outer.child_anchor)
            p = pin - rotation(th) * as_column(fold.outer.parent_anchor)
        self.sym[name] = (p, th)
        return p, th

    def point(self, body: str, local) -> sp.Matrix:
        p, th = self.pose(body)
        return p + rotation(th) * as_column(local)

    def pin(self, fold: _Fold) -> sp.Matrix:
        if isinstance(fold.inner, Revolute):
            return self.point(fold.inner.parent, fold.inner.parent_anchor)
        return self.point(fold.outer.child, fold.outer.child_anchor)

    def rate(self, expr: sp.Expr) -> sp.Expr:
        return sum((sp.diff(expr, p) * v for p, v in zip(self.P, self.V)), sp.Integer(0))

    def coordinate(self, j: Revolute | Prismatic) -> sp.Expr:
        p_p, th_p = self.pose(j.parent)
        p_c, th_c = self.pose(j.child)
        if isinstance(j, Revolute):
            return th_c - (0 if j.absolute else th_p) - j.angle_offset
        axis = as_column(j.axis)
        d = p_c + rotation(th_c) * as_column(j.child_anchor) - p_p \
            - rotation(th_p) * as_column(j.parent_anchor)
        return (axis.T * rotation(th_p).T * d)[0] / (axis.T * axis)[0]


def _element_loads(mech: Mechanism, kin: _Kinematics):
    """Per element, the loads on description bodies: (body, force or None, world point,
    torque). Forces in a pair act at a common world point."""
    coords = [kin.coordinate(j) for j in mech.joints]
    loads: list[tuple[str, sp.Matrix | None, sp.Matrix | None, sp.Expr]] = []
    for f in mech.forces:
        if isinstance(f, PointToPoint):
            pa, pb = kin.point(f.body_a, f.point_a), kin.point(f.body_b, f.point_b)
            d = pb - pa
            length = sp.sqrt(d[0] ** 2 + d[1] ** 2)
            tension = sp.sympify(f.tension).xreplace(
                {LENGTH: length, LENGTH_RATE: kin.rate(length)})
            u = d / length
            loads.append((f.body_b, -tension * u, pb, 0))
            loads.append((f.body_a, tension * u, pa, 0))
        else:
            i = mech.coordinates.index(f.coordinate)
            j = mech.joints[i]
            value = sp.sympify(f.force).xreplace({COORD: coords[i], COORD_RATE: kin.rate(coords[i])})
            if isinstance(j, Revolute):
                loads.append((j.child, None, None, value))
                loads.append((j.parent, None, None, -value))
            else:
                _, th_p = kin.pose(j.parent)
                axis = as_column(j.axis)
                force = value * rotation(th_p) * axis / (axis.T * axis)[0]
                w = kin.point(j.child, j.child_anchor)
                loads.append((j.child, force, w, 0))
                loads.append((j.parent, -force, w, 0))
    return loads


def _engine_loads(loads, kin: _Kinematics, dynamic: list[str]) -> dict[int, list[sp.Expr]]:
    """Body loads (fx, fy, tau about the centre of mass) on the engine bodies."""
    out: dict[int, list[sp.Expr]] = {}

    def add(body: str, force, point, torque) -> None:
        if body == WORLD:
            return
        if body in kin.folds:  # virtual power through the massless link
            fold = kin.folds[body]
            if force is not None:
                pin = kin.pin(fold)
                add(fold.pin_body, force, pin, 0)
                torque = torque + _cross(point - pin, force)
            add(fold.partner, None, None, torque)
            return
        acc = out.setdefault(dynamic.index(body), [sp.Integer(0)] * 3)
        if force is not None:
            p, _ = kin.pose(body)
            acc[0] += force[0]
            acc[1] += force[1]
            acc[2] += _cross(point - p, force)
        acc[2] += torque

    for body, force, point, torque in loads:
        add(body, force, point, torque)
    return out


_CACHE: dict[Mechanism, _Compiled] = {}


def _compile(mech: Mechanism, layout: _Layout) -> _Compiled:
    if mech in _CACHE:
        return _CACHE[mech]
    dynamic = layout.dynamic
    kin = _Kinematics(mech, dynamic, layout.folds)
    H = sp.Symbol("H", real=True)
    # loads are evaluated at the position-updated state x + H v (H = dt or 0)
    predicted = {p: p + H * v for p, v in zip(kin.P, kin.V)}
    state = [s for k in range(len(dynamic))
             for s in (*kin.P[3 * k:3 * k + 3], *kin.V[3 * k:3 * k + 3])]
    args = [*state, H, TIME]
    loads = _element_loads(mech, kin)
    per_body = _engine_loads(loads, kin, dynamic)
    loaded = sorted(per_body)
    loads_math = None
    if loaded:
        flat = [e.xreplace(predicted) for k in loaded for e in per_body[k]]
        loads_math = sp.lambdify(args, flat, modules="math", cse=True)
    external_np: dict[str, Callable] = {}
    for j in mech.joints:
        subtree = set(mech.subtree(j.child))
        total = sp.zeros(2, 1)
        for body, force, _, _ in loads:
            if force is not None and body in subtree:
                total += force
        external_np[j.name] = sp.lambdify(args, list(total.xreplace(predicted)),
                                          modules="numpy", cse=True)
    coords = [kin.coordinate(j) for j in mech.joints]
    coords_np = sp.lambdify(state, coords + [kin.rate(c) for c in coords],
                            modules="numpy", cse=True)
    masses = {b.name: _num(b.mass) for b in mech.bodies}
    compiled = _Compiled(layout, loaded, loads_math, external_np, coords_np, masses)
    if len(_CACHE) > 64:
        _CACHE.clear()
    _CACHE[mech] = compiled
    return compiled


def _initial_states(mech: Mechanism, q0, qd0) -> dict[str, tuple[float, ...]]:
    """(x, y, theta, vx, vy, omega) of every description body at (q0, qd0), by planar
    forward kinematics in joint order (conventions 3-5)."""
    st: dict[str, tuple[float, ...]] = {WORLD: (0.0,) * 6}

    def rot(th: float, v) -> tuple[float, float]:
        c, s = math.cos(th), math.sin(th)
        return c * v[0] - s * v[1], s * v[0] + c * v[1]

    for j, q, qd in zip(mech.joints, q0, qd0):
        x, y, th_p, vx, vy, w_p = st[j.parent]
        pa = (_num(j.parent_anchor[0]), _num(j.parent_anchor[1]))
        ca = (_num(j.child_anchor[0]), _num(j.child_anchor[1]))
        off = _num(j.angle_offset)
        if isinstance(j, Revolute):
            th = (0.0 if j.absolute else th_p) + q + off
            w = (0.0 if j.absolute else w_p) + qd
            r = rot(th_p, pa)
            va = (vx - w_p * r[1], vy + w_p * r[0])
        else:
            th, w = th_p + off, w_p
            axis = (_num(j.axis[0]), _num(j.axis[1]))
            r = rot(th_p, (pa[0] + q * axis[0], pa[1] + q * axis[1]))
            slide = rot(th_p, axis)
            va = (vx - w_p * r[1] + qd * slide[0], vy + w_p * r[0] + qd * slide[1])
        a = (x + r[0], y + r[1])
        rc = rot(th, ca)
        st[j.child] = (a[0] - rc[0], a[1] - rc[1], th, va[0] + w * rc[1], va[1] - w * rc[0], w)
    return st


class PymunkBackend(Backend):
    id = "pymunk"

    def available(self) -> tuple[bool, str]:
        try:
            import pymunk  # noqa: F401
        except Exception as exc:  # a missing or broken engine is a visible skip
            return False, f"pymunk not importable: {exc}"
        return True, ""

    def version(self) -> str:
        import pymunk

        return f"{pymunk.version} (Chipmunk {pymunk.chipmunk_version.split('-')[0]})"

    def default_settings(self) -> dict:
        return {
            "error_bias": 0.0,
            "iterations": 50,
            "damping": 1.0,
            "sleep_time_threshold": None,
            "element_forces": "position_updated",
            "groove_half_length": 1000.0,
        }

    def setting_notes(self) -> dict[str, str]:
        return {
            "error_bias": (
                "Fraction of a joint's position error left after 1 s, on every constraint. "
                "Pymunk's default (1-0.1)^60 = 1.8e-3 removes only part of the error per "
                "step and its correction velocity enters the real velocity: measured on the "
                "2 rad compound pendulum, joint gap 1.2e-3 m (O(h)), 0.64 rad trajectory "
                "error and 5 % energy drift in 10 s at h = 1e-3. 0 removes the whole error "
                "in the next step (bias velocity -error/h): gap 1e-5 m (O(h^2)), 3.6e-3 rad."),
            "iterations": (
                "Gauss-Seidel velocity iterations per step (space.iterations; Pymunk "
                "default 10). A single joint is solved in one iteration; a chain is not: "
                "on the small double-pendulum swing the reaction error was 1.8e-3 "
                "(relative) with 10 and 1.4e-4 with 20 or more (20, 30, 50, 100 identical; "
                "trajectories identical from 10 on, reactions 65 % off with 1). 50 keeps a "
                "margin at negligible cost."),
            "damping": (
                "space.damping, the fraction of velocity kept after 1 s. Pymunk's default "
                "is already 1 (no damping); stated explicitly so it is recorded."),
            "sleep_time_threshold": (
                "space.sleep_time_threshold in s; null = never sleep (Pymunk default inf). "
                "Sleeping froze a small oscillation when enabled (SIMULATORS.md)."),
            "element_forces": (
                "When force elements are evaluated in a step. Chipmunk moves positions "
                "(x += h v) before it applies body.force, so a force computed from the "
                "sampled state before space.step() ('step_start', what user code usually "
                "does) makes the step explicit Euler for that force: energy grew by 114 % "
                "(elastic pendulum) and 90 % (sliding block) in 10 s at h = 1e-3. "
                "'position_updated' (default) evaluates the laws at x + h v and t + h, the "
                "configuration at which Chipmunk pre-steps its constraints and its own "
                "DampedSpring: a consistent semi-implicit Euler step (energy drift 0.4-0.5 %). "
                "No engine default is replaced: Pymunk has no hook for laws of length "
                "rate or time, so the backend applies body forces and torques."),
            "groove_half_length": (
                "Chipmunk grooves are finite segments: a prismatic side without a limit "
                "is given this extent in m (the groove ends act as stops). Finite limits "
                "of the description are used as the groove ends."),
        }

    def support(self, mechanism: Mechanism) -> Support:
        plan = _plan(mechanism)
        if isinstance(plan, str):
            return Support(False, plan)
        return Support(True)

    # --- building ------------------------------------------------------------------------
    @staticmethod
    def _build(mech: Mechanism, layout: _Layout, q0, qd0, cfg: dict):
        import pymunk

        space = pymunk.Space()
        space.gravity = (0.0, -_num(mech.gravity))
        space.damping = float(cfg["damping"])
        space.iterations = int(cfg["iterations"])
        sleep = cfg["sleep_time_threshold"]
        space.sleep_time_threshold = math.inf if sleep is None else float(sleep)
        state = _initial_states(mech, q0, qd0)
        bodies: dict[str, pymunk.Body] = {WORLD: space.static_body}
        for name in layout.dynamic:
            b = mech.body(name)
            body = pymunk.Body(_num(b.mass), _num(b.inertia))  # no shapes: nothing collides
            x, y, th, vx, vy, w = state[name]
            body.position = (x, y)
            body.angle = th
            body.velocity = (vx, vy)
            body.angular_velocity = w
            space.add(body)
            bodies[name] = body
        half = float(cfg["groove_half_length"])
        constraints: list = []
        for parent, child, pa, ca in layout.pivots:
            constraints.append(pymunk.PivotJoint(bodies[parent], bodies[child], pa, ca))
        for g in layout.grooves:
            base, direction = np.array(g.base), np.array(g.direction)
            lo = -half if g.lo is None else g.lo
            hi = half if g.hi is None else g.hi
            a, b = bodies[g.slot], bodies[g.pin]
            constraints.append(pymunk.GrooveJoint(a, b, tuple(base + lo * direction),
                                                  tuple(base + hi * direction), g.anchor))
            if g.phase is not None:
                constraints.append(pymunk.GearJoint(a, b, g.phase, 1.0))
        for c in constraints:
            c.error_bias = float(cfg["error_bias"])
        space.add(*constraints)
        return space, [bodies[n] for n in layout.dynamic]

    # --- running -------------------------------------------------------------------------
    def simulate(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray, t_end: float,
                 dt: float, settings: Mapping | None = None,
                 reaction_joints: Sequence[str] = ()) -> RunResult:
        cfg = self.resolve_settings(settings)
        if cfg["element_forces"] not in _FORCE_MODES:
            raise ValueError(f"element_forces must be one of {_FORCE_MODES}")
        layout = _plan(mechanism)
        if isinstance(layout, str):
            raise ValueError(f"pymunk cannot express this mechanism: {layout}")
        comp = _compile(mechanism, layout)
        space, bodies = self._build(mechanism, layout, np.asarray(q0, float),
                                    np.asarray(qd0, float), cfg)
        n_steps = int(round(t_end / dt))
        h = float(dt)
        # loads at x + h v and t + h (see setting notes), or at the sampled state
        H, shift = (h, 1) if cfg["element_forces"] == "position_updated" else (0.0, 0)

        def read() -> list[float]:
            row: list[float] = []
            for b in bodies:
                row.extend(b.position)
                row.append(b.angle)
                row.extend(b.velocity)
                row.append(b.angular_velocity)
            return row

        rows = [read()]
        step = space.step
        loads = comp.loads_math
        targets = [bodies[k] for k in comp.loaded]
        start = time.perf_counter()
        if loads is None:
            for _ in range(n_steps):
                step(h)
                rows.append(read())
        else:
            for k in range(n_steps):
                out = loads(*rows[-1], H, (k + shift) * h)
                for i, b in enumerate(targets):
                    b.force = (out[3 * i], out[3 * i + 1])
                    b.torque = out[3 * i + 2]
                step(h)
                rows.append(read())
        wall = time.perf_counter() - start

        S = np.array(rows)
        n = len(mechanism.joints)
        t = np.arange(n_steps + 1) * h
        cols = [np.broadcast_to(np.asarray(c, float), t.shape) for c in comp.coords_np(*S.T)]
        q, qd = np.column_stack(cols[:n]), np.column_stack(cols[n:])
        reactions = {j: self._reaction(mechanism, comp, j, S, H, shift, h, t)
                     for j in reaction_joints}
        return RunResult(t=t, q=q, qd=qd, reactions=reactions, wall_time=wall,
                         integrator_order=1, settings=cfg, steps=n_steps)

    @staticmethod
    def _reaction(mech: Mechanism, comp: _Compiled, joint: str, S: np.ndarray,
                  H: float, shift: int, h: float, t: np.ndarray) -> np.ndarray:
        """Force the parent exerts on the child: Newton on the child's subtree over the
        step n -> n+1, sum m (v(n+1) - v(n))/h - m g - (element forces from outside, as
        applied in that step). Chipmunk computes that impulse at the position-updated
        configuration x(n+1), so it is given to sample n+1 (measured on the pendulums:
        3.5-40x closer to the model's reaction at that sample than at sample n); sample 0
        has no step before it and is NaN. A start with angular velocity shows an O(1)
        transient at sample 1: the first step also builds the steady O(h^2) joint gap of
        the position update, and its impulse contains that correction."""
        j = mech.joint(joint)
        g = _num(mech.gravity)
        dynamic = comp.layout.dynamic
        total = np.zeros((len(t) - 1, 2))
        for name in mech.subtree(j.child):
            if name not in dynamic:
                continue  # massless link
            k = dynamic.index(name)
            m = comp.masses[name]
            total[:, 0] += m * np.diff(S[:, 6 * k + 3]) / h
            total[:, 1] += m * (np.diff(S[:, 6 * k + 4]) / h + g)
        ext = comp.external_np[joint](*S[:-1].T, H, t[:-1] + shift * h)
        for i in range(2):
            total[:, i] -= np.broadcast_to(np.asarray(ext[i], float), (len(t) - 1,))
        out = np.full((len(t), 2), np.nan)
        out[1:] = total
        return out

    def linearize(self, mechanism: Mechanism, q_eq: np.ndarray,
                  settings: Mapping | None = None, dt: float = 1e-3) -> Linearization | None:
        # Chipmunk has no linearization facility (SIMULATORS.md)
        return None


BACKEND = PymunkBackend()
