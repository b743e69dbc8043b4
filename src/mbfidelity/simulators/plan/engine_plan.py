"""What every translation starts from, conditions of an expression that follow from the
description alone, and the elements between two bodies read from their frame states.

What every translation starts from (`EnginePlan`, with the smallest mass and inertia
`smallest_mass_and_inertia`); conditions of an element's expression (`carries_child`,
`held_by_closure`, `couples_two_engine_values`, with the coupling on the engine joint
values `engine_coupling`); the elements between two bodies (`PairLoad`, `pair_load`,
`SlotGeometry`, `slot_geometry`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from ...systems.model import (
    Body,
    CoordinateForce,
    LinearCoupling,
    Mechanism,
    PointOnLine,
    PointToPoint,
)
from .numeric import gravity_vector, num, plane_point
from .kinds_and_laws import CoordinateLaws, ForceLaw, constrained_bodies, elements, motions
from .coordinates import coordinate_map
from .kinematics import point_state
from .force_loads import coupling_row, element_loads


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

    def position_along(self, pin: tuple, line: tuple) -> float:
        """`along`'s position s alone, by the same arithmetic on one step's floats (what
        an engine that moves the slot's pivot every step needs)."""
        c, s = math.cos(line[2]), math.sin(line[2])
        ux = c * self.direction[0] - s * self.direction[1]
        uy = s * self.direction[0] + c * self.direction[1]
        (px, py), (lx, ly) = _position(pin, self.pin_point), _position(line, self.line_point)
        return (px - lx) * ux + (py - ly) * uy

    def line_point_at(self, s: float) -> tuple[float, float]:
        """The slot body's point of its line at s along it: L + s u (body frame)."""
        ux, uy = self.direction
        return self.line_point[0] + s * ux, self.line_point[1] + s * uy


def _position(state: tuple, local) -> tuple[float, float]:
    """World position of a body point from the body frame's state (x, y, theta, ...) of
    floats: `point_state`'s position, term by term."""
    c, s = math.cos(state[2]), math.sin(state[2])
    return state[0] + (c * local[0] - s * local[1]), state[1] + (s * local[0] + c * local[1])


def slot_geometry(c: PointOnLine) -> SlotGeometry:
    """The `SlotGeometry` of a PointOnLine (its direction made a unit vector)."""
    u = np.array([num(c.direction[0]), num(c.direction[1])])
    u = u / float(np.hypot(*u))
    return SlotGeometry(c.body, plane_point(c.point), c.line_body, plane_point(c.line_point),
                        (float(u[0]), float(u[1])))


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
