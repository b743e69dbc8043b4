"""Pymunk's route for prescribed motion (a constraint whose target moves every step)
against closed forms that do not involve the engine.

The backend's scheme is semi-implicit Euler (first order): the free coordinates and the
actuator force must converge as h, i.e. their errors must shrink tenfold from h = 1e-3
to 1e-4. The runs keep w h <= 0.01 on every mode and every forcing frequency, so the
second-order terms are about w h = 1 % of the first-order one and the measured slope
must lie within 10^(1 +- 0.1) (a tenth of a decade covers them with a margin of two).
The size of the first-order error itself is bounded by w h relative to the amplitude,
which is what a first-order method's accumulated phase and amplitude error reaches over
a few periods of a lightly damped response (measured: a third of it or less).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from mbfidelity.simulators.pymunk_backend import BACKEND
from mbfidelity.systems import get_system
from mbfidelity.systems.model import (
    TIME,
    Body,
    CoordinateForce,
    Mechanism,
    Prescribed,
    Prismatic,
    coordinate_spring_damper,
)

pytestmark = pytest.mark.skipif(not BACKEND.available()[0], reason="pymunk not importable")

FIRST_ORDER = (10**0.9, 10**1.1)  # error ratio between h = 1e-3 and 1e-4 (module doc)


def _linear_response(mass: float, c: float, k: float, force, t: np.ndarray):
    """z, z'' of mass z'' + c z' + k z = force(t) from rest (DOP853, rtol 1e-12)."""
    def rhs(time, y):
        return [y[1], (force(time) - c * y[1] - k * y[0]) / mass]

    sol = solve_ivp(rhs, (t[0], t[-1]), [0.0, 0.0], method="DOP853", rtol=1e-12,
                    atol=1e-15, t_eval=t)
    z, zd = sol.y
    zdd = (np.array([force(x) for x in t]) - c * zd - k * z) / mass
    return z, zdd


def _errors(mech, q0, qd0, t_end, dt, free, driven, name, reference):
    run = BACKEND.simulate(mech, q0, qd0, t_end, dt)
    z_ref, force_ref, y_ref = reference(run.t)
    free_error = np.max(np.abs(run.q[:, free] - z_ref)) / np.max(np.abs(z_ref))
    driven_error = np.max(np.abs(run.q[:, driven] - y_ref))
    force = run.actuator_forces[name]
    assert force.shape == run.t.shape and math.isnan(force[0])  # sample 0: no step before it
    force_error = np.max(np.abs(force[1:] - force_ref[1:])) / np.max(np.abs(force_ref))
    return free_error, driven_error, force_error


def test_base_excitation_converges_at_first_order_to_the_closed_form():
    """base_excited_msd at resonance: m z'' + c z' + k z = -m y''(t), actuator
    (m_P + m) y'' + m z''; the base is on y(t) at every sample (round-off)."""
    system = get_system("base_excited_msd")
    scenario = system.scenario("omega_1wn")
    P = system.parameter_values(scenario=scenario)
    mech = system.numeric_mechanism(P)
    m, k, c, m_P, Y, W = (P[n] for n in ("m", "k", "c", "m_P", "Y", "Omega"))
    assert math.sqrt(k / m) * 1e-3 <= 0.01 and W * 1e-3 <= 0.01
    i_y, i_z = mech.coordinates.index("y"), mech.coordinates.index("z")
    q0, qd0 = np.zeros(2), np.zeros(2)
    qd0[i_y] = Y * W

    def reference(t):
        ydd = lambda x: -Y * W**2 * math.sin(W * x)  # noqa: E731
        z, zdd = _linear_response(m, c, k, lambda x: -m * ydd(x), t)
        y2 = np.array([ydd(x) for x in t])
        return z, (m_P + m) * y2 + m * zdd, Y * np.sin(W * t)

    coarse = _errors(mech, q0, qd0, 2.0, 1e-3, i_z, i_y, "actuator", reference)
    fine = _errors(mech, q0, qd0, 2.0, 1e-4, i_z, i_y, "actuator", reference)
    for h, (free, driven, force) in ((1e-3, coarse), (1e-4, fine)):
        bound = math.sqrt(k / m) * h
        assert free <= bound, (h, free, bound)
        assert force <= bound, (h, force, bound)
        assert driven <= 1e-12 * Y, (h, driven)
    for name, a, b in (("free", coarse[0], fine[0]), ("actuator", coarse[2], fine[2])):
        assert FIRST_ORDER[0] <= a / b <= FIRST_ORDER[1], (name, a / b)


def test_slide_driven_on_a_free_frame_loads_the_frame_with_its_inertia():
    """An inner mass m driven y(t) = Y cos(W t) along a frame M on a spring (the inertial
    shaker, case 4): (M + m) x'' + c x' + k x = -m y''(t), actuator m (x'' + y''). The
    frame feels the inner mass only through the moving PivotJoint, and the motion's
    q''(0) != 0 checks the start (no transient at samples 1 and 2)."""
    M, m, k, c, Y, W = 2.0, 0.5, 200.0, 1.0, 0.02, 8.0
    mech = Mechanism(
        bodies=(Body("frame", M, 0.05), Body("inner", m, 0.002)),
        joints=(Prismatic("guide", "world", "frame", "x", axis=(1, 0)),
                Prismatic("drive", "frame", "inner", "y", axis=(1, 0),
                          parent_anchor=(0, 0.05))),
        forces=(CoordinateForce("spring", "x", **coordinate_spring_damper(k, 0, c)),),
        prescribed=(Prescribed("shaker", "y", Y * sp.cos(W * TIME)),),
        gravity=9.81,
    )
    assert BACKEND.support(mech).ok
    q0, qd0 = np.array([0.0, Y]), np.zeros(2)

    def reference(t):
        ydd = lambda x: -Y * W**2 * math.cos(W * x)  # noqa: E731
        x, xdd = _linear_response(M + m, c, k, lambda s: -m * ydd(s), t)
        return x, m * (xdd + np.array([ydd(s) for s in t])), Y * np.cos(W * t)

    free, driven, force = _errors(mech, q0, qd0, 2.0, 1e-3, 0, 1, "shaker", reference)
    bound = math.sqrt(k / (M + m)) * 1e-3
    assert free <= bound and force <= bound, (free, force, bound)
    assert driven <= 1e-12 * Y
    # the route's per-step work: the target moves in the bare loop too (contract point 9)
    assert BACKEND.bare_loop(mech, q0, qd0, 0.01, 1e-3) >= 0.0


def test_a_run_builds_its_own_route_whatever_ran_before():
    """The two routes of setting prescribed_motion build different spaces on the same
    engine bodies, whose compiled frames and loads are reused between runs: a run with
    one route after a run with the other must equal the same run in a fresh process (an
    empty cache), sample for sample."""
    from mbfidelity.simulators import pymunk_backend

    system = get_system("rotating_slot")
    values = system.parameter_values()
    mech = system.numeric_mechanism(values)
    q0, qd0 = system.initial_state(system.scenarios[0], values)
    route = {"prescribed_motion": "moving_constraint"}
    pymunk_backend._CACHE.clear()
    BACKEND.simulate(mech, q0, qd0, 0.05, 1e-3)  # the default route: a kinematic driver
    after_default = BACKEND.simulate(mech, q0, qd0, 0.05, 1e-3, route)
    pymunk_backend._CACHE.clear()
    fresh = BACKEND.simulate(mech, q0, qd0, 0.05, 1e-3, route)
    np.testing.assert_array_equal(after_default.q, fresh.q)
    np.testing.assert_array_equal(after_default.actuator_forces["motor"],
                                  fresh.actuator_forces["motor"])
