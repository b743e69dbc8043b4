"""The map between the description coordinates q and the engine joint values v.

Every engine joint is relative (v = theta_child - theta_parent - angle_offset for a hinge,
the slide along the unit axis for a prismatic joint), so ``v = A q + b`` with the inverse
``q = T v + c``, and the body angles are affine in both (`CoordinateMap`,
`coordinate_map`); a coordinate law whose argument is one engine joint value can sit on
that joint (`CoordinateMap.law_target`). A prismatic joint's unit axis in its joint frame
(`slide_axis`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ...systems.model import WORLD, Mechanism, Prismatic, Revolute
from .numeric import num


# --- description coordinates and engine joint values -----------------------------------


@dataclass(frozen=True)
class CoordinateMap:
    """Description coordinates q and engine joint values v of a numeric mechanism:
    ``v = A q + b`` and ``q = T v + c`` (T = A^-1; A is lower triangular with +-1 or the
    axis length on the diagonal: absolute angles subtract the parent's angle, clockwise
    coordinates change sign, slides run along the unit axis). Body angles are affine in
    both: ``theta = angle_c[body] . q + angle_d[body] = angle_v[body] . v +
    angle_v0[body]``. Generalized forces map with the transposes (tau = T^T Q)."""

    A: np.ndarray
    b: np.ndarray
    c: np.ndarray
    angle_c: dict[str, np.ndarray]
    angle_d: dict[str, float]
    angle_v: dict[str, np.ndarray]
    angle_v0: dict[str, float]

    @cached_property
    def T(self) -> np.ndarray:
        return np.linalg.inv(self.A)

    @cached_property
    def identity(self) -> bool:
        """Whether the engine joint values are the description coordinates."""
        n = len(self.b)
        return bool(np.array_equal(self.A, np.eye(n)) and not self.b.any())

    def engine_values(self, q: np.ndarray) -> np.ndarray:
        return self.A @ np.asarray(q, dtype=float) + self.b

    def coordinates(self, v: np.ndarray) -> np.ndarray:
        """Engine joint values (one row per sample, or one vector) -> coordinates."""
        return (np.asarray(v) - self.b) @ self.T.T

    def rates(self, vd: np.ndarray) -> np.ndarray:
        return np.asarray(vd) @ self.T.T

    def angle(self, body: str, q: np.ndarray) -> np.ndarray:
        """The body's angle at q (rows of q give one angle per row)."""
        return q @ self.angle_c[body] + self.angle_d[body]

    def law_row(self, weights: dict[int, int]) -> np.ndarray:
        """The row r with COORD = sum sign q_i = r . (v - b) (`weights`, as in
        `CoordinateForce.weights`), so that the law's force acts with r F on the engine
        joint values; weights below 1e-12 are round-off of T and set to zero."""
        row = sum(sign * self.T[i] for i, sign in weights.items())
        return np.where(np.abs(row) < 1e-12, 0.0, row)

    def law_target(self, weights: dict[int, int]) -> tuple[int, float] | None:
        """(j, r) when a coordinate law's argument COORD = sum sign q_i (`weights`, as in
        `CoordinateForce.weights`) is r v_j, one engine joint value without offset (an
        engine can then hold the law on its joint j: force r F(r v_j, r v_j') on v_j);
        None otherwise. Weights below 1e-12 are round-off of T and set to zero."""
        row = sum(sign * self.T[i] for i, sign in weights.items())
        row = np.where(np.abs(row) < 1e-12, 0.0, row)
        shift = sum(sign * self.c[i] for i, sign in weights.items())
        target = np.flatnonzero(row)
        if len(target) != 1 or shift != 0:
            return None
        return int(target[0]), float(row[target[0]])

    def joint_spring(self, weights: dict[int, int], linear: tuple[float, float, float] | None
                     ) -> tuple[int, float, float, float] | None:
        """(j, force, stiffness, damping) where a linear coordinate law F = a + b COORD +
        c COORD' (`linear`; None: not linear) acts on one engine joint value, COORD = r v_j
        (`law_target`): tau_j = r F(r v_j, r v_j') = force - stiffness v_j - damping v_j'
        with force = r a, stiffness = -r^2 b, damping = -r^2 c; None otherwise."""
        target = self.law_target(weights)
        if linear is None or target is None:
            return None
        (j, r), (a, b, c) = target, linear
        return j, r * a, -r * r * b, -r * r * c

    def on_engine_values(self, coefficients: np.ndarray, constant: float
                         ) -> tuple[np.ndarray, float]:
        """A linear relation sum a_k q_k = C on the coordinates written on the engine
        joint values: (a T, C - a c), since q = T v + c; weights below 1e-12 of the
        largest are round-off of T and set to zero."""
        row = np.asarray(coefficients, dtype=float) @ self.T
        row = np.where(np.abs(row) <= 1e-12 * np.max(np.abs(row), initial=0.0), 0.0, row)
        return row, float(constant - np.asarray(coefficients, dtype=float) @ self.c)


def coordinate_map(mech: Mechanism) -> CoordinateMap:
    """The `CoordinateMap` of a numeric mechanism."""
    n = len(mech.joints)
    angle_c: dict[str, np.ndarray] = {WORLD: np.zeros(n)}
    angle_d: dict[str, float] = {WORLD: 0.0}
    angle_v: dict[str, np.ndarray] = {WORLD: np.zeros(n)}
    angle_v0: dict[str, float] = {WORLD: 0.0}
    A = np.zeros((n, n))
    b = np.zeros(n)
    c = np.zeros(n)
    for i, j in enumerate(mech.joints):
        cp, dp = angle_c[j.parent], angle_d[j.parent]
        off = num(j.angle_offset)
        e_i = np.eye(n)[i]
        if isinstance(j, Revolute):
            sign = -1.0 if j.clockwise else 1.0
            angle_v[j.child] = angle_v[j.parent] + e_i
            if j.absolute:
                angle_c[j.child] = sign * e_i
                angle_d[j.child] = off
                A[i] = sign * e_i - cp  # v = theta_child - theta_parent - offset
                b[i] = -dp
                c[i] = sign * angle_v0[j.parent]  # sign q = theta_parent + v
            else:
                angle_c[j.child] = cp + sign * e_i
                angle_d[j.child] = dp + off
                A[i, i] = sign
        else:
            angle_v[j.child] = angle_v[j.parent].copy()
            angle_c[j.child] = cp.copy()
            angle_d[j.child] = dp + off
            A[i, i] = math.hypot(num(j.axis[0]), num(j.axis[1]))  # the slide along the unit axis
        angle_v0[j.child] = angle_v0[j.parent] + off
    return CoordinateMap(A, b, c, angle_c, angle_d, angle_v, angle_v0)


def slide_axis(j: Prismatic) -> tuple[float, float]:
    """A prismatic joint's unit axis in its joint frame (the parent's frame turned by the
    angle offset): the description's axis, given in the parent's frame, turned by
    -angle_offset and normalised (its length is the slide's scale in `CoordinateMap.A`)."""
    length = math.hypot(num(j.axis[0]), num(j.axis[1]))
    ax, ay = num(j.axis[0]) / length, num(j.axis[1]) / length
    c, s = math.cos(-num(j.angle_offset)), math.sin(-num(j.angle_offset))
    return c * ax - s * ay, s * ax + c * ay
