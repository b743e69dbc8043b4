"""Massless links eliminated by their shape, for an engine without massless bodies.

The massless links eliminated by their shape (`Elimination`: folded into a host
(`Fold`, with its slot line `Fold.slot_line`), arms (`Arm`), free groups (`FreeGroup`);
`NotEliminable` where their frames do not follow) and every body's frame from the bodies
with mass (`EliminatedFrames`, `hung_frame`, `sample_columns`).
"""
from __future__ import annotations

from dataclasses import dataclass
from operator import itemgetter
from typing import Callable, Sequence

import numpy as np

from ...systems.model import (
    WORLD,
    Mechanism,
    PointOnLine,
    PointOnPoint,
    Prismatic,
    Revolute,
)
from .numeric import num, plane_point, rot
from .kinematics import atan2, cos_sin, linear_solver, moving_point


# --- massless links eliminated: their frames follow from the bodies with mass -----------


class NotEliminable(ValueError):
    """Massless bodies whose frames do not follow from the bodies around them (why)."""


def _closure_bodies(c) -> tuple[str, ...]:
    """The two bodies of a PointOnPoint or PointOnLine; () for other closures."""
    return c.bodies if isinstance(c, (PointOnPoint, PointOnLine)) else ()


@dataclass(frozen=True)
class Fold:
    """A massless link with one revolute and one prismatic joint (a guide arm carrying a
    slider, or a slider carrying a pin): it turns with `partner`, the body on the far side
    of its prismatic joint, about its revolute point, a point of `pin_body` (the near
    side); the pair of joints is one pin-in-slot between them."""

    link: str
    revolute: Revolute
    prismatic: Prismatic

    @property
    def turns_with_child(self) -> bool:
        """Whether the revolute joint is the link's inner one (the link turns with the
        prismatic joint's child, the pin is a point of the revolute joint's parent)."""
        return self.revolute.child == self.link

    @property
    def partner(self) -> str:
        return self.prismatic.child if self.turns_with_child else self.prismatic.parent

    @property
    def pin_body(self) -> str:
        return self.revolute.parent if self.turns_with_child else self.revolute.child

    @property
    def offset(self) -> float:
        """The link's angle minus its partner's."""
        offset = num(self.prismatic.angle_offset)
        return -offset if self.turns_with_child else offset

    @property
    def pin_point(self) -> tuple[float, float]:
        """The revolute point in the pin body's frame."""
        j = self.revolute
        return plane_point(j.parent_anchor if self.turns_with_child else j.child_anchor)

    @property
    def link_point(self) -> tuple[float, float]:
        """The revolute point in the link's frame."""
        j = self.revolute
        return plane_point(j.child_anchor if self.turns_with_child else j.parent_anchor)

    @property
    def slot_line(self) -> tuple[np.ndarray, np.ndarray]:
        """The line (base, direction) in the partner's frame on which the pin point
        (`pin_point`) runs, at base + q direction for the slide's coordinate q: the pair
        of joints as one pin-in-slot."""
        rev, pri = self.revolute, self.prismatic
        if self.turns_with_child:
            # the link turns with its child: the pivot (a point of the parent) slides on a
            # line of the child
            back = rot(-num(pri.angle_offset))
            base = np.array(plane_point(pri.child_anchor)) - back @ (
                np.array(plane_point(pri.parent_anchor)) - np.array(plane_point(rev.child_anchor)))
            return base, -back @ np.array(plane_point(pri.axis))
        # the link turns with its parent: the pin (a point of the child) slides on a line
        # of the parent
        base = np.array(plane_point(pri.parent_anchor)) + rot(num(pri.angle_offset)) @ (
            np.array(plane_point(rev.parent_anchor)) - np.array(plane_point(pri.child_anchor)))
        return base, np.array(plane_point(pri.axis))


@dataclass(frozen=True)
class Arm:
    """A massless link with revolute joints only, at two distinct points alpha, beta of
    the link (a fixed distance between the bodies at its two ends). `at_alpha`/`at_beta`:
    (body, point of that body) hinged there; the first is the representative (the world
    if it is one of them)."""

    link: str
    alpha: tuple[float, float]
    beta: tuple[float, float]
    at_alpha: tuple[tuple[str, tuple[float, float]], ...]
    at_beta: tuple[tuple[str, tuple[float, float]], ...]


@dataclass(frozen=True)
class FreeGroup:
    """Massless bodies that impose no constraint on the bodies with mass around them:
    their angles follow prismatic joints, their positions solve the (linear) joint
    equations."""

    bodies: tuple[str, ...]
    joints: tuple  # description joints with an end in `bodies`
    closures: tuple  # PointOnPoint / PointOnLine with an end in `bodies`
    #: (body, known body, offset): theta = theta_known + offset
    angles: tuple[tuple[str, str, float], ...]


def _arm(mech: Mechanism, name: str, massless: set[str]) -> Arm:
    joints = [j for j in mech.joints if name in (j.parent, j.child)]
    groups: list[tuple[np.ndarray, list[tuple[str, tuple[float, float]]]]] = []
    for j in joints:
        if j.parent == name:
            own, other, at = j.parent_anchor, j.child, j.child_anchor
        else:
            own, other, at = j.child_anchor, j.parent, j.parent_anchor
        own, at = np.array(plane_point(own)), np.array(plane_point(at))
        if other in massless:
            raise NotEliminable(f"massless body {name} is hinged to another massless body "
                                f"{other}")
        for point, members in groups:
            if np.allclose(point, own, rtol=0, atol=1e-12):
                members.append((other, tuple(at)))
                break
        else:
            groups.append((own, [(other, tuple(at))]))
    if len(groups) != 2:
        raise NotEliminable(f"massless body {name} has revolute joints at {len(groups)} "
                            "distinct points; only a link with two (an arm) can be eliminated")
    for _, members in groups:  # the world first: its point is exact
        members.sort(key=lambda m: m[0] != WORLD)
    seen = [m[0] for _, ms in groups for m in ms]
    if len(set(seen)) != len(seen):
        raise NotEliminable(f"massless body {name} is hinged twice to the same body")
    (pa, ma), (pb, mb) = groups
    return Arm(name, tuple(pa), tuple(pb), tuple(ma), tuple(mb))


def _free_group(mech: Mechanism, group: set[str], real: set[str],
                closures: list) -> FreeGroup:
    joints = tuple(j for j in mech.joints if j.parent in group or j.child in group)
    mine = tuple(c for c in closures if set(_closure_bodies(c)) & group)
    ends = ({b for j in joints for b in (j.parent, j.child)}
            | {b for c in mine for b in _closure_bodies(c)}) - group
    bad = [b for b in ends if b != WORLD and b not in real]
    if bad:
        raise NotEliminable(f"massless bodies {sorted(group)} are attached to other massless "
                            f"bodies {bad}")
    known = set(ends) | {WORLD}
    angles: list[tuple[str, str, float]] = []
    changed = True
    while changed:
        changed = False
        for j in joints:
            if not isinstance(j, Prismatic):
                continue
            off = num(j.angle_offset)
            if j.parent in known and j.child not in known:
                angles.append((j.child, j.parent, off))
                known.add(j.child)
                changed = True
            elif j.child in known and j.parent not in known:
                angles.append((j.parent, j.child, -off))
                known.add(j.parent)
                changed = True
    loose = sorted(group - known)
    if loose:
        raise NotEliminable(f"massless bodies {loose}: rotation not fixed by prismatic "
                            "joints, and not a foldable link or arm")
    unknowns = (2 * len(group) + sum(isinstance(j, Prismatic) for j in joints)
                + sum(isinstance(c, PointOnLine) for c in mine))
    equations = 2 * (len(joints) + len(mine))
    if unknowns != equations:
        raise NotEliminable(f"massless bodies {sorted(group)}: their joints and constraints "
                            f"impose {equations - unknowns:+d} conditions on the bodies "
                            "around them; only massless groups that leave them free (or fold "
                            "into one joint) can be eliminated")
    return FreeGroup(tuple(sorted(group)), joints, mine, tuple(angles))


def _group_equations(group: FreeGroup) -> tuple:
    """A free massless group's joint equations, read once: (column of each body's x,
    the number of unknowns, the angles (body, known body, offset), per equation pair the
    points (sign, body, local) whose sum vanishes and the travel (column, body,
    direction, sign) of a slide or a slot along a direction of a body, if any)."""
    column = {body: 2 * i for i, body in enumerate(group.bodies)}
    extra, equations = 2 * len(group.bodies), []
    for j in group.joints:
        slide = None
        if isinstance(j, Prismatic):
            slide, extra = (extra, j.parent, plane_point(j.axis), 1.0), extra + 1
        equations.append((((1.0, j.parent, plane_point(j.parent_anchor)),
                           (-1.0, j.child, plane_point(j.child_anchor))), slide))
    for c in group.closures:
        if isinstance(c, PointOnPoint):
            equations.append((((1.0, c.body_a, plane_point(c.point_a)),
                               (-1.0, c.body_b, plane_point(c.point_b))), None))
        else:
            equations.append((((1.0, c.body, plane_point(c.point)),
                               (-1.0, c.line_body, plane_point(c.line_point))),
                              (extra, c.line_body, plane_point(c.direction), -1.0)))
            extra += 1
    return column, extra, group.angles, tuple(equations)


class Elimination:
    """The massless bodies of a planar description eliminated, each by its shape: a link
    with one revolute and one prismatic joint is folded (`Fold`), a link with revolute
    joints at two points is an arm (`Arm`), and massless bodies whose angles are fixed by
    prismatic joints and whose joints and closures leave the bodies around them free
    (three relative degrees of freedom, e.g. two crossed carriages, or a pin running in
    two slots) form a free group (`FreeGroup`); other shapes raise `NotEliminable`.
    `joints`: the ids of the joints that an elimination stands for; `closures`: the ids of
    the closures that a free group consumes (its positions solve them); `kind`: per
    eliminated body, how its frame follows (`EliminatedFrames`); `follows`: the bodies
    with mass it follows."""

    def __init__(self, mech: Mechanism) -> None:
        massless = {b.name for b in mech.bodies if b.massless}
        geometric = [c for c in mech.constraints if _closure_bodies(c)]
        touched = {b for c in geometric for b in _closure_bodies(c)}
        self.folds: dict[str, Fold] = {}
        self.arms: dict[str, Arm] = {}
        self.groups: list[FreeGroup] = []
        self.joints: set[int] = set()
        rest = []
        for name in (b.name for b in mech.bodies if b.name in massless):
            inner = mech.joint_of_child(name)
            children = [j for j in mech.joints if j.parent == name]
            if name in touched:
                rest.append(name)
            elif (len(children) == 1
                    and {type(inner), type(children[0])} == {Revolute, Prismatic}
                    and inner.parent not in massless and children[0].child not in massless):
                outer = children[0]
                revolute, prismatic = ((inner, outer) if isinstance(inner, Revolute)
                                       else (outer, inner))
                self.folds[name] = Fold(name, revolute, prismatic)
                self.joints |= {id(inner), id(outer)}
            elif all(isinstance(j, Revolute) for j in [inner, *children]):
                self.arms[name] = _arm(mech, name, massless)
                self.joints |= {id(inner), *map(id, children)}
            else:
                rest.append(name)
        real = {b.name for b in mech.bodies} - massless
        remaining = set(rest)
        while remaining:
            group = {remaining.pop()}
            grown = True
            while grown:
                grown = False
                pairs = [(j.parent, j.child) for j in mech.joints] + [
                    _closure_bodies(c) for c in geometric]
                for a, b in pairs:
                    for x, y in ((a, b), (b, a)):
                        if x in group and y in remaining:
                            group.add(y)
                            remaining.discard(y)
                            grown = True
            self.groups.append(_free_group(mech, group, real, geometric))
        self.joints |= {id(j) for g in self.groups for j in g.joints}
        self.closures = {id(c) for g in self.groups for c in g.closures}
        self.kind: dict[str, tuple] = {}
        self.follows: dict[str, tuple[str, ...]] = {}
        for name, fold in self.folds.items():
            self.kind[name] = ("fold", fold.partner, fold.offset, fold.pin_body, fold.pin_point,
                               fold.link_point)
            self.follows[name] = (fold.partner, fold.pin_body)
        for name, arm in self.arms.items():
            (ra, pa), (rb, pb) = arm.at_alpha[0], arm.at_beta[0]
            ell = (arm.beta[0] - arm.alpha[0], arm.beta[1] - arm.alpha[1])
            self.kind[name] = ("link", ra, pa, rb, pb, ell, arm.alpha)
            self.follows[name] = (ra, rb)
        self.equations = [_group_equations(g) for g in self.groups]
        for i, (column, _, _, equations) in enumerate(self.equations):
            for name in column:
                self.kind[name] = ("group", i)
                self.follows[name] = tuple({p[1] for points, _ in equations
                                            for p in points} - column.keys())


def hung_frame(pin: tuple, th, w, local) -> tuple:
    """The `EliminatedFrames.state` of a body at angle th turning at w, whose point
    `local` is at the moving point `pin` (x, y, vx, vy)."""
    c, s = cos_sin(th)
    rx, ry = c * local[0] - s * local[1], s * local[0] + c * local[1]
    return pin[0] - rx, pin[1] - ry, th, c, s, pin[2] + w * ry, pin[3] - w * rx, w


class EliminatedFrames:
    """The frame state of each description body, computed when asked, from those of the
    bodies with mass (`massive`: body -> state): `state` gives (x, y, theta, cos theta,
    sin theta, vx, vy, omega), `frames[body]` the frame state (x, y, theta, vx, vy,
    omega). A folded link turns with its partner about its pin; an arm points from its
    end at alpha to its end at beta; a free massless group solves its joint equations,
    linear once its angles are known, and their time derivative for the rates. Numbers,
    arrays of samples or symbols (`traced`)."""

    def __init__(self, elimination: Elimination, massive: Callable[[str], tuple]):
        self.elimination, self.massive = elimination, massive
        self.cache: dict[str, tuple] = {WORLD: (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0)}

    def __getitem__(self, body: str) -> tuple:
        state = self.state(body)
        return state[:3] + state[5:]

    def state(self, body: str) -> tuple:
        if body in self.cache:
            return self.cache[body]
        kind = self.elimination.kind.get(body)
        if kind is None:
            state = self.massive(body)
        elif kind[0] == "fold":  # turns with `turner`, its point `local` on the pin
            _, turner, off, pin, pin_local, local = kind
            turning = self.state(turner)
            state = hung_frame(moving_point(self.state(pin), pin_local), turning[2] + off,
                          turning[7], local)
        elif kind[0] == "link":  # its alpha on the point a, its beta towards b
            _, ra, pa, rb, pb, ell, alpha = kind
            a, b = moving_point(self.state(ra), pa), moving_point(self.state(rb), pb)
            wx, wy = b[0] - a[0], b[1] - a[1]
            th = atan2(ell[0] * wy - ell[1] * wx, ell[0] * wx + ell[1] * wy)
            w = (wx * (b[3] - a[3]) - wy * (b[2] - a[2])) / (wx * wx + wy * wy)
            state = hung_frame(a, th, w, alpha)
        else:
            self._group(kind[1])
            return self.cache[body]
        self.cache[body] = state
        return state

    def _group(self, i: int) -> None:
        """A free group's positions (and its slides' and slots' travels) from its joint
        equations, then its rates from the same equations differentiated in time."""
        column, m, angles, equations = self.elimination.equations[i]
        turn: dict[str, tuple] = {}  # body -> (theta, omega)
        for body, known, off in angles:
            th, w = turn[known] if known in turn else itemgetter(2, 7)(self.state(known))
            turn[body] = (th + off, w)
        A = [[0.0] * m for _ in range(m)]
        known_p, known_v, slides = [], [], []
        for r, (points, slide) in enumerate(equations):
            gap = (0.0, 0.0, 0.0, 0.0)  # the known points' position and velocity
            for sign, body, local in points:
                if body in column:
                    A[2 * r][column[body]] += sign
                    A[2 * r + 1][column[body] + 1] += sign
                    th, w = turn[body]
                    c, s = cos_sin(th)
                    p = moving_point((0.0, 0.0, th, c, s, 0.0, 0.0, w), local)
                else:
                    p = moving_point(self.state(body), local)
                gap = tuple(g + sign * v for g, v in zip(gap, p))
            if slide is not None:  # the travel u along sign R d
                k, body, d, sign = slide
                th, w = turn[body] if body in turn else itemgetter(2, 7)(self.state(body))
                c, s = cos_sin(th)
                A[2 * r][k] = sign * (c * d[0] - s * d[1])
                A[2 * r + 1][k] = sign * (s * d[0] + c * d[1])
                slides.append((r, k, w))
            known_p += gap[:2]
            known_v += gap[2:]
        solve = linear_solver(A)
        x = solve([-v for v in known_p])
        for r, k, w in slides:  # d/dt (u sign R d) = u' sign R d + u omega perp(sign R d)
            known_v[2 * r] -= w * A[2 * r + 1][k] * x[k]
            known_v[2 * r + 1] += w * A[2 * r][k] * x[k]
        v = solve([-g for g in known_v])
        for body, c in column.items():
            th, w = turn[body]
            self.cache[body] = (x[c], x[c + 1], th, *cos_sin(th), v[c], v[c + 1], w)


def sample_columns(values: Sequence, n: int) -> np.ndarray:
    """(n, len(values)): each value, a number or n samples, as a column."""
    return np.column_stack([np.broadcast_to(np.asarray(v, float), (n,)) for v in values])
