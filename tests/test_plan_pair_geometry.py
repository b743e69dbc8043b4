"""The engine-neutral helpers of simulators/plan and base.py that a backend calls in
place of its own geometry and numerics: the pin and slot geometry from the bodies' frame
states, a point-to-point element's pair force, a slide's unit axis, the coordinate laws
on engine joint values, a parents-first link order and the linearization's central
differences, each against a value built independently (by construction or in closed
form)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from mbfidelity.simulators.base import central_differences
from mbfidelity.simulators.plan import (CoordinateLaws, coordinate_map, pair_load,
                                        parents_first, slide_axis,
                                        slot_geometry)
from mbfidelity.systems.model import (LENGTH, CoordinateForce, PointOnLine, PointToPoint,
                                      Prismatic)

#: round-off bound: a few dozen operations on values of order 1-10
TOL = 1e-12


def _frame(point_world, local, theta, omega, point_velocity) -> tuple:
    """The frame state (x, y, theta, vx, vy, omega) of a body turned by theta at rate
    omega whose point `local` is at `point_world` moving at `point_velocity`."""
    c, s = math.cos(theta), math.sin(theta)
    rx, ry = c * local[0] - s * local[1], s * local[0] + c * local[1]
    return (point_world[0] - rx, point_world[1] - ry, theta,
            point_velocity[0] + omega * ry, point_velocity[1] - omega * rx, omega)


def test_slot_geometry_reads_where_the_pin_is_placed():
    """A pin placed at L + s u + d n, moving at v_L + r u + w n, is read at s along the
    slot with rate r, whatever its distance d from the line (u, n: the slot's unit
    direction and normal in world axes, L the slot body's line point and v_L that point's
    velocity); a slot whose direction is scaled reads the same."""
    slot = PointOnLine("slot", "pin_body", (0.3, -0.2), "line_body", (0.5, 0.1), (3.0, 4.0))
    geo = slot_geometry(slot)
    theta, omega = 0.7, -1.3
    line = (0.4, -0.9, theta, 0.25, 0.6, omega)
    lx, ly, lvx, lvy = (line[0] + math.cos(theta) * 0.5 - math.sin(theta) * 0.1,
                        line[1] + math.sin(theta) * 0.5 + math.cos(theta) * 0.1,
                        line[3] - omega * (math.sin(theta) * 0.5 + math.cos(theta) * 0.1),
                        line[4] + omega * (math.cos(theta) * 0.5 - math.sin(theta) * 0.1))
    c, si = math.cos(theta), math.sin(theta)
    u = (c * 0.6 - si * 0.8, si * 0.6 + c * 0.8)
    n = (-u[1], u[0])
    for s, d, r, w in [(0.0, 0.0, 0.0, 0.0), (1.7, 0.0, -0.4, 0.0), (-0.8, 0.03, 2.0, 0.5)]:
        pin = _frame((lx + s * u[0] + d * n[0], ly + s * u[1] + d * n[1]), (0.3, -0.2), -0.4,
                     0.9, (lvx + r * u[0] + w * n[0], lvy + r * u[1] + w * n[1]))
        along, rate = geo.along(pin, line)
        assert along == pytest.approx(s, abs=TOL) and rate == pytest.approx(r, abs=TOL)
        assert geo.position_along(pin, line) == along  # the same arithmetic: bitwise
        assert geo.line_point_at(s) == pytest.approx((0.5 + 0.6 * s, 0.1 + 0.8 * s), abs=TOL)
    assert geo.direction == pytest.approx((0.6, 0.8), abs=TOL)


def test_pair_force_of_a_spring():
    """Two body points 5 m apart (3-4-5) on a spring of stiffness 2 N/m and free length
    1 m: the spring pulls b towards a with 8 N = 2 (5 - 1) along the line,
    applied at the points; where the points coincide the force has no direction: zero."""
    spring = PointToPoint("spring", "a", (0.5, 0.0), "b", (0.0, -1.0), 2 * (LENGTH - 1))
    pair = pair_load(None, spring)
    state_a = _frame((1.0, 2.0), (0.5, 0.0), 0.3, 0.0, (0.0, 0.0))
    state_b = _frame((4.0, 6.0), (0.0, -1.0), -1.1, 0.0, (0.0, 0.0))
    fx, fy, ax, ay, bx, by = pair.force({"a": state_a, "b": state_b}, 0.0)
    assert (fx, fy) == pytest.approx((-8.0 * 0.6, -8.0 * 0.8), abs=TOL)
    assert (ax, ay, bx, by) == pytest.approx((1.0, 2.0, 4.0, 6.0), abs=TOL)
    pinned = pair_load(None, PointToPoint("pinned", "a", (0.5, 0.0), "b", (0.5, 0.0),
                                          2 * (LENGTH - 1)))
    fx, fy, ax, ay, bx, by = pinned.force({"a": state_a, "b": state_a}, 0.0)
    assert (fx, fy) == (0.0, 0.0) and (ax, ay, bx, by) == pytest.approx((1.0, 2.0) * 2)


def test_slide_axis_is_the_unit_axis_turned_into_the_joint_frame():
    """Axis (3, 4) in the parent's frame, joint frame turned by +90 degrees: the unit
    axis (0.6, 0.8) seen from the joint frame is (0.8, -0.6)."""
    joint = Prismatic("slide", "world", "cart", "x", (3, 4), angle_offset=math.pi / 2)
    assert slide_axis(joint) == pytest.approx((0.8, -0.6), abs=TOL)


def test_coordinate_laws_on_engine_values_keep_their_power():
    """On every planar catalog mechanism with coordinate laws and engine joint values that
    differ from its coordinates, tau . v' equals Q . q' (the power does not depend on the
    coordinates it is written in), with Q the laws' generalized force."""
    from mbfidelity.comparisons.runner import _engine_mechanism
    from mbfidelity.systems import all_systems

    rng = np.random.default_rng(3)
    checked = 0
    for system in all_systems().values():
        mech = _engine_mechanism(system, system.parameter_values(None), None)
        laws = [f for f in mech.forces if isinstance(f, CoordinateForce)]
        cmap = coordinate_map(mech)
        if mech.spatial or not laws or cmap.identity:
            continue
        coordinate_laws = CoordinateLaws(mech, laws)
        v, vd = rng.uniform(-1, 1, (2, len(mech.coordinates)))
        q, qd = cmap.coordinates(v), cmap.rates(vd)
        tau = np.asarray(coordinate_laws.on_engine_values(cmap.T, cmap.c)(v, vd, 0.3))
        Q = np.asarray(coordinate_laws.generalized(q, qd, 0.3))
        assert tau @ vd == pytest.approx(Q @ qd, rel=1e-10, abs=1e-10), system.id
        checked += 1
    assert checked > 0


def test_parents_first_orders_a_reparented_tree():
    """Link 0 hangs from link 2, which hangs from link 1 on the root: 1, 2, 0."""
    assert parents_first([2, -1, 1]) == [1, 2, 0]
    assert parents_first([-1, 0, 0, 2]) == [0, 1, 2, 3]


def test_central_differences_of_a_known_residual():
    """residual(x, v) = K0 x + C0 v + x_0^3 e_0: K = K0 + 3 x_0^2 e_0 e_0^T and C = C0 at
    (x, 0); central differences are exact for the linear part and leave h^2 x_0 (about
    1e-12 here) on the cubic."""
    K0 = np.array([[2.0, -1.0], [-1.0, 3.0]])
    C0 = np.array([[0.1, 0.0], [0.2, 0.4]])

    def residual(x, v):
        return K0 @ x + C0 @ v + np.array([x[0] ** 3, 0.0])

    x = np.array([1.5, -0.5])
    K, C = central_differences(residual, x, 1e-6)
    assert np.allclose(K, K0 + np.diag([3 * x[0] ** 2, 0.0]), rtol=0, atol=1e-8)
    assert np.allclose(C, C0, rtol=0, atol=1e-8)
