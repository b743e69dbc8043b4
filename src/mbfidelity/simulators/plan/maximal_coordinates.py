"""An engine in maximal coordinates: its bodies' states, the description's frames, and
couplings of hinge angles on the bodies' absolute angles.

The description's frames and coordinates from an engine's body states and the element
loads on those bodies (`MaximalFrames`, `split_state_row`); a coupling of hinge
coordinates on the absolute body angles (`angle_coupling`, `coupled_angles`) and as
rolling of pitch circles on a carrier (`PitchPair`'s circles and pitch points,
`pitch_pairs`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Callable, Iterator, Mapping, Sequence

import numpy as np

from ...systems.model import WORLD, LinearCoupling, Mechanism, Revolute
from .numeric import num, plane_point
from .kinematics import cos_sin, joint_coordinates, traced
from .force_loads import Load, force_bodies, wrench
from .eliminated_links import EliminatedFrames, Elimination, hung_frame, sample_columns
from .description_facts import continued_angles, coupling_residual


# --- an engine in maximal coordinates: its bodies' states and the description's frames ---

_ZERO = (0.0, 0.0, 0.0)
_UNITS = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def split_state_row(row: Sequence, H=0.0) -> tuple[list, list]:
    """Per engine body, (x, y, theta) moved by H times the rates, and the rates, from a
    state row (numbers, symbols or columns of samples; 6 entries per engine body)."""
    P = [tuple(row[k + i] + H * row[k + 3 + i] for i in range(3)) for k in range(0, len(row), 6)]
    V = [tuple(row[k + 3 + i] for i in range(3)) for k in range(0, len(row), 6)]
    return P, V


class MaximalFrames:
    """How every description body's frame follows from the states of an engine in maximal
    coordinates, read once. The engine's bodies (`engine`, in the order of its state rows:
    per body its centre of gravity x, y, its angle and their rates) are the description's
    bodies with mass, whose frames are placed from their centre of gravity (at the point
    `cogs` of the body's frame where it is off the frame's origin), and substitutes of the
    engine's own; an eliminated massless link follows them (`EliminatedFrames` of
    `elimination`). `elements`: per force element, its loads as a function of the frames
    and t (`element_loads`), which reach the engine bodies `loaded`."""

    def __init__(self, mech: Mechanism, elimination: Elimination, engine: Sequence[str],
                 cogs: Mapping[str, Sequence[float] | None], elements: Sequence[Callable]):
        self.mech, self.elimination = mech, elimination
        self.index = {name: k for k, name in enumerate(engine)}
        self.n = len(engine)
        self.cogs = {name: tuple(map(float, cog)) for name, cog in cogs.items() if cog}
        #: per eliminated body, the engine bodies it follows
        self.follows = {name: tuple(sorted(self.index[b] for b in set(bodies)
                                           if b in self.index))
                        for name, bodies in elimination.follows.items()}
        self.elements = list(elements)
        loaded: set[int] = set()
        for f in mech.forces:
            for body in set(force_bodies(mech, f)) - {WORLD}:
                loaded |= set(self.follows[body]) if body in self.follows else {self.index[body]}
        self.loaded = sorted(loaded)  # engine bodies that receive element loads
        self.phis: dict[str, Callable] = {}  # compiled `coupling_phi`s

    def at(self, P: Sequence, V: Sequence) -> EliminatedFrames:
        """The frames from the engine bodies' positions P and rates V (x, y, theta of the
        centre of gravity and their rates, per engine body)."""
        def massive(body: str) -> tuple:
            k, cog = self.index[body], self.cogs.get(body)
            (x, y, th), (vx, vy, w) = P[k], V[k]
            if cog:  # the frame whose point cog is the centre of gravity
                return hung_frame((x, y, vx, vy), th, w, cog)
            return (x, y, th, *cos_sin(th), vx, vy, w)

        return EliminatedFrames(self.elimination, massive)

    def frames(self, S: np.ndarray, H: float = 0.0) -> EliminatedFrames:
        """The frames over state rows S (one sample per row) at x + H v."""
        return self.at(*split_state_row(np.asarray(S, dtype=float).T, H))

    def coordinates(self, S: np.ndarray, q0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Engine body states (rows of `S`) -> the description's coordinates and rates;
        the angles of eliminated links, which come from atan2, continued from q0."""
        q, qd = (sample_columns(cols, len(S))
                 for cols in joint_coordinates(self.mech, self.frames(S)))
        return continued_angles(self.mech, q, q0), qd

    def body_loads(self, frames: EliminatedFrames, t) -> list[Load]:
        """The element loads on the description bodies."""
        return [load for element in self.elements for load in element(frames, t)]

    def coupling_phi(self, name: str) -> Callable[..., float]:
        """The residual Phi = sum k q - const of the coupling `name`, as a compiled
        function of the engine bodies' positions (x, y, theta each)."""
        if name in self.phis:
            return self.phis[name]
        residual = coupling_residual(self.mech, next(c for c in self.mech.constraints
                                                     if c.name == name))

        def phi(*pos: float) -> list:
            return [residual(self.at([pos[k:k + 3] for k in range(0, len(pos), 3)],
                                     [_ZERO] * self.n))]

        compiled = traced(phi, 3 * self.n)
        self.phis[name] = lambda *pos: compiled(*pos)[0]
        return self.phis[name]

    @cached_property
    def loads_math(self) -> Callable | None:
        """`engine_loads` compiled: (*state row, H, t) -> flat (fx, fy, tau) of the
        `loaded` engine bodies (None without force elements)."""
        if not self.elements:
            return None
        return traced(lambda *args: self.engine_loads(args[:-2], args[-2], args[-1]),
                      6 * self.n + 2)

    def engine_loads(self, row: Sequence, H, t) -> list:
        """The element loads (fx, fy at the centre of gravity, tau) on the `loaded`
        engine bodies at the position-updated state x + H v of one state row. A load on
        an eliminated massless body reaches the engine bodies it follows by virtual
        power, J^T f, J's columns its velocities for a unit rate of each engine state."""
        P, V = split_state_row(row, H)
        frames = self.at(P, V)
        out = {k: [0.0, 0.0, 0.0] for k in self.loaded}
        for load in self.body_loads(frames, t):
            body, force, point, torque = load
            if body == WORLD:
                continue
            if body not in self.follows:
                k = self.index[body]
                out[k] = [a + b for a, b in zip(out[k], wrench(load, P[k][:2]))]
                continue
            x, y = frames.state(body)[:2]
            for k in self.follows[body]:
                for i, unit in enumerate(_UNITS):
                    rates = [_ZERO] * len(P)
                    rates[k] = unit
                    vx, vy, w = self.at(P, rates).state(body)[5:]
                    out[k][i] += torque * w if force is None else (
                        torque * w + force[0] * (vx - w * (point[1] - y))
                        + force[1] * (vy + w * (point[0] - x)))
        return [v for k in self.loaded for v in out[k]]


# --- a coupling of hinge angles on the bodies' absolute angles --------------------------


def angle_coupling(mech: Mechanism, coupling: LinearCoupling) -> tuple[dict[str, float], float]:
    """A coupling of hinge coordinates, sum c_i q_i = C, written on the absolute body
    angles as sum k_b theta_b = k0: (k per body, the world included, k0). Every coordinate
    it weighs must be a hinge's."""
    k: dict[str, float] = {}
    k0 = num(coupling.constant)
    for name, coef in coupling.coefficients:
        j = mech.joints[mech.coordinates.index(name)]
        s = -1.0 if j.clockwise else 1.0
        coef = num(coef)
        k[j.child] = k.get(j.child, 0.0) + coef * s
        if not j.absolute:
            k[j.parent] = k.get(j.parent, 0.0) - coef * s
        k0 += coef * s * num(j.angle_offset)
    return k, k0


def coupled_angles(mech: Mechanism, coupling: LinearCoupling
                   ) -> tuple[dict[str, float], float, list[str], float]:
    """`angle_coupling` (k, k0), the bodies whose angle enters it (a coefficient above the
    round-off of the coefficients' size), in order, and that size."""
    k, k0 = angle_coupling(mech, coupling)
    scale = max((abs(v) for v in k.values()), default=0.0)
    return k, k0, [b for b, v in k.items() if b != WORLD and abs(v) > 1e-12 * scale], scale


@dataclass(frozen=True)
class PitchPair:
    """Two bodies a, b hinged on a common carrier (the world as b: a hinged on a carrier
    hinged on the world) whose angle coupling k_a theta_a + k_b theta_b + k_carrier
    theta_carrier = const has sum k = 0: an internal/external gear pair on the carrier,
    i.e. rolling of the pitch circles at the pitch point a + lam (b - a), lam = k_a /
    (k_a + k_b), on the line of the hubs, `d` apart on the carrier."""

    carrier: str
    a: str
    b: str
    hub_a: tuple[float, float]  # a's point at its hinge on the carrier
    hub_b: tuple[float, float]
    d: float
    k_a: float
    k_b: float

    @property
    def lam(self) -> float:
        return self.k_a / (self.k_a + self.k_b)

    @property
    def circles(self) -> tuple:
        """The pitch circles (a, its centre hub_a, radius, b, its centre hub_b, radius,
        internal): radii |lam| d and |lam - 1| d, one inside the other unless 0 < lam < 1."""
        return (self.a, self.hub_a, abs(self.lam) * self.d, self.b, self.hub_b,
                abs(self.lam - 1) * self.d, not 0.0 < self.lam < 1.0)

    def pitch_points(self, ha, hb, phi: float) -> tuple[tuple, tuple]:
        """The pitch point as a point of a and as a point of b (world axes), from the world
        positions ha, hb of the hubs: on the line of the hubs, lam d from a's hub; b's is
        moved along the pitch tangent by the coupling's residual phi as a length,
        phi d / (k_a + k_b), so that a joint holding the two points together holds the
        coupling, its position error the joint's gap."""
        scale = self.d / (self.k_a + self.k_b)
        dx, dy = hb[0] - ha[0], hb[1] - ha[1]
        dist = math.hypot(dx, dy)
        ux, uy = dx / dist, dy / dist
        e = scale * phi
        ra, rb = self.lam * self.d, (self.lam - 1.0) * self.d
        return ((ha[0] + ra * ux, ha[1] + ra * uy),
                (hb[0] + rb * ux + e * uy, hb[1] + rb * uy - e * ux))


def pitch_pairs(mech: Mechanism, k: Mapping[str, float], bodies: Sequence[str],
                scale: float) -> Iterator[PitchPair]:
    """The pitch pairs (`PitchPair`) that a coupling on the absolute angles of `bodies`
    (`angle_coupling`; coefficients k, of size `scale`) can be, one per carrier among
    them, in the order of `bodies`."""
    for K in bodies:
        others = [b for b in bodies if b != K]
        hubs: dict[str, tuple[tuple, tuple]] = {}  # body -> (its hub point, K's hub point)
        for j in mech.joints:
            if isinstance(j, Revolute) and K in (j.parent, j.child):
                if j.parent == K:
                    hubs[j.child] = (tuple(np.array(plane_point(j.child_anchor))),
                                     tuple(np.array(plane_point(j.parent_anchor))))
                else:
                    hubs[j.parent] = (tuple(np.array(plane_point(j.parent_anchor))),
                                      tuple(np.array(plane_point(j.child_anchor))))
        if not set(others) <= set(hubs):
            continue
        if len(others) == 2:
            A, B = others
            if abs(sum(k[b] for b in bodies)) > 1e-12 * scale:
                continue
            ka, kb = k[A], k[B]
        elif len(others) == 1 and WORLD in hubs:
            A, B = others[0], WORLD
            ka = k[A]
            kb = -(k[K] + ka)
        else:
            continue
        d = float(np.linalg.norm(np.subtract(hubs[B][1], hubs[A][1])))
        if d == 0.0 or abs(ka + kb) <= 1e-12 * scale:
            continue
        yield PitchPair(K, A, B, hubs[A][0], hubs[B][0], d, ka, kb)
