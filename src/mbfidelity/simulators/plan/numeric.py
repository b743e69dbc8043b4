"""Numbers from a numeric description entry and the planar rotations of the plan.

Numbers from description entries (`num`, `vec3`, `plane_point`; `NotNumeric` where an
entry still holds a parameter), planar rotations (`rot`, `turned`), the gravity vector and
a body's central inertia tensor in numbers (`gravity_vector`, `central_tensor`), the
coefficients of a linear law (`linear_law`), and a circle as a ring of boxes tangent to it
(a rolling contact's track, `ring_of_boxes`) or as its inscribed polygon
(`ring_of_chords`).
"""
from __future__ import annotations

import math

import numpy as np
import sympy as sp

from ...systems.model import Body, Mechanism, inertia_matrix


class NotNumeric(TypeError, ValueError):
    """A description entry still holds a parameter symbol."""


def num(x) -> float:
    """A float from a numeric description entry (number or SymPy expression)."""
    value = sp.sympify(x)
    if value.free_symbols:
        raise NotNumeric(f"expression {value} still has free symbols")
    return float(value)


def vec3(vector) -> list[float]:
    """A description vector, planar or spatial, as three numbers (planar: z = 0)."""
    return [num(v) for v in vector] + [0.0] * (3 - len(vector))


def rot(theta: float) -> np.ndarray:
    """The planar rotation matrix R(theta) (body frame to world axes)."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def turned(theta: np.ndarray, x, y) -> np.ndarray:
    """The vectors (x, y) turned by the angles theta, one row per sample (N, 2)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * x - s * y, s * x + c * y], axis=1)


def ring_of_boxes(centre, R: float, count: int
                  ) -> tuple[list[tuple[float, float, float]], float, float]:
    """The track of a rolling contact as `count` boxes whose inner faces are tangent to the
    circle of radius R about `centre` (a regular polygon with the circle as its incircle):
    each box's centre (x, y) and angle, the boxes' radial thickness (0.1 R) and the half
    length R tan(pi / count) at which neighbouring faces meet."""
    thick = 0.1 * R
    rho = R + thick / 2.0
    boxes = [(centre[0] + rho * math.cos(a), centre[1] + rho * math.sin(a), a)
             for a in (2.0 * math.pi * i / count for i in range(count))]
    return boxes, thick, R * math.tan(math.pi / count)


def ring_of_chords(centre, R: float, count: int) -> tuple[list[tuple[float, float]], float]:
    """The circle of radius R about `centre` as the `count` vertices of its inscribed
    regular polygon, and the polygon's sagitta R (1 - cos(pi / count)), the largest gap
    between a chord and the circle."""
    points = [(centre[0] + R * math.cos(2 * math.pi * i / count),
               centre[1] + R * math.sin(2 * math.pi * i / count)) for i in range(count)]
    return points, R * (1 - math.cos(math.pi / count))


def gravity_vector(mech: Mechanism) -> tuple[float, float, float]:
    """The acceleration of gravity in world axes: along -y, or in a spatial mechanism
    (model convention 10) against its `up`."""
    g = num(mech.gravity)
    if not mech.spatial:
        return 0.0, -g, 0.0
    up = np.array([num(u) for u in mech.up] + [0.0] * (3 - len(mech.up)), dtype=float)
    return tuple(float(v) for v in -g * up / np.linalg.norm(up))


def central_tensor(mech: Mechanism, body: Body) -> np.ndarray:
    """A body's 3 x 3 central inertia tensor in its frame (numbers): a spatial body's
    full tensor as given (model convention 10), a planar body's inertia about z."""
    if mech.spatial:
        return np.array(inertia_matrix(body).tolist(), dtype=float)
    return np.diag([0.0, 0.0, num(body.inertia)])


def linear_law(expr, x: sp.Symbol, xd: sp.Symbol) -> tuple[float, float, float] | None:
    """(a, b, c) with law = a + b x + c xd (numbers, no TIME), or None when the law is not
    of that form."""
    expr = sp.sympify(expr)
    if not expr.free_symbols <= {x, xd} or not expr.is_polynomial(x, xd):
        return None
    if expr.free_symbols and sp.Poly(expr, x, xd).total_degree() > 1:
        return None
    a = float(expr.xreplace({x: 0, xd: 0}))
    return a, float(sp.diff(expr, x)), float(sp.diff(expr, xd))


def plane_point(point) -> tuple[float, float]:
    """A description point's (x, y) as numbers."""
    return num(point[0]), num(point[1])
