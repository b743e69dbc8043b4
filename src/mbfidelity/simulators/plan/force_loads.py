"""The loads of the force elements on the bodies, and the joint geometry they are read by.

A load on a body (`Load`) and its wrench about a centre (`wrench`); the pose, path and
velocity of a joint (`joint_pose`, `slide_path`, `joint_velocity`); the loads of a
coordinate law (`coordinate_load`) and of every force element (`element_loads`, on the
bodies `force_bodies`); a coupling's row on the description coordinates
(`coupling_row`).
"""
from __future__ import annotations

from typing import Callable, Mapping

import numpy as np

from ...systems.model import (
    CoordinateForce,
    LinearCoupling,
    Mechanism,
    PointToPoint,
    Prismatic,
    Revolute,
    RollingContact,
)
from .numeric import num, plane_point, rot
from .kinds_and_laws import ForceLaw
from .kinematics import coordinate_reader, cos_sin, law_value, point_state, sqrt


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
