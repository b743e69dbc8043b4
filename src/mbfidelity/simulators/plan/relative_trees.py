"""The link frames of an engine with a tree of relative joints.

Its link frames (`LinkFrames`, `link_frames`: one link per joint, its frame at the joint,
a slide's joint frame turned to its axis, `joint_frame_turn`), a joint's axis
(`unit_axis`, `link_axis`) and the rotation about z (`rot_z`), the condition that a
joint's axis is a link axis (`axis_aligned`), and an order of a tree's links with every parent first
(`parents_first`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ...systems.model import WORLD, Mechanism, Prismatic, Revolute
from .numeric import num, rot
from .coordinates import CoordinateMap, coordinate_map


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
