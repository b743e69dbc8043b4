"""PyBullet's route for prescribed motion (the joint's velocity motor driven to
(q(t+h) - q)/h, simulators/pybullet_backend.py) against a closed form that does not
involve the engine: base_excited_msd at resonance, m z'' + c z' + k z = -m y''(t) (§8.2),
actuator force (m_P + m) y'' + m z''.

The scheme is semi-implicit Euler (first order): from h = 1e-3 to 1e-4 the free
coordinate's and the actuator force's errors must shrink tenfold, within 10^(1 +- 0.1)
(w h <= 0.01 on the mode and the forcing: the second-order terms are ~1 % of the first
order one). Their size is bounded by w h relative to the amplitude (a first-order
method's phase and amplitude error over a few periods of a lightly damped response).
The base itself lands on y(t+h) at every step: its error is the motor's solver residual,
round-off of the coordinate."""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from mbfidelity.simulators.pybullet_backend import BACKEND
from mbfidelity.systems import get_system
from mbfidelity.systems.model import (TIME, Body, CoordinateForce, Mechanism, Prescribed,
                                      Prismatic, Rectangle, coordinate_spring_damper)

pytestmark = pytest.mark.skipif(not BACKEND.available()[0], reason="pybullet not importable")

FIRST_ORDER = (10**0.9, 10**1.1)


def _errors(dt: float):
    system = get_system("base_excited_msd")
    P = system.parameter_values(scenario=system.scenario("omega_1wn"))
    mech = system.numeric_mechanism(P)
    m, k, c, m_P, Y, W = (P[n] for n in ("m", "k", "c", "m_P", "Y", "Omega"))
    assert math.sqrt(k / m) * 1e-3 <= 0.01 and W * 1e-3 <= 0.01
    q0, qd0 = np.zeros(2), np.array([Y * W, 0.0])
    run = BACKEND.simulate(mech, q0, qd0, 2.0, dt)

    def rhs(t, y):
        return [y[1], (m * Y * W**2 * math.sin(W * t) - c * y[1] - k * y[0]) / m]

    sol = solve_ivp(rhs, (0.0, 2.0), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-15,
                    t_eval=run.t)
    z, zd = sol.y
    ydd = -Y * W**2 * np.sin(W * run.t)
    zdd = (-m * ydd - c * zd - k * z) / m
    force_ref = (m_P + m) * ydd + m * zdd
    force = run.actuator_forces["actuator"]
    # the motor's force of the step that starts at each sample: the last sample too
    assert force.shape == run.t.shape and np.all(np.isfinite(force))
    return (np.max(np.abs(run.q[:, 1] - z)) / np.max(np.abs(z)),
            np.max(np.abs(run.q[:, 0] - Y * np.sin(W * run.t))),
            np.max(np.abs(force - force_ref)) / np.max(np.abs(force_ref)),
            math.sqrt(k / m) * dt)


def test_base_excitation_converges_at_first_order_to_the_closed_form():
    coarse, fine = _errors(1e-3), _errors(1e-4)
    for (free, driven, force, wh) in (coarse, fine):
        assert free <= wh and force <= wh
        assert driven <= 1e-12
    assert FIRST_ORDER[0] <= coarse[0] / fine[0] <= FIRST_ORDER[1]
    assert FIRST_ORDER[0] <= coarse[2] / fine[2] <= FIRST_ORDER[1]


def test_a_scaled_reversed_slide_is_driven_and_read_in_its_own_coordinate():
    """The base slide along (-2, 0) and the block's along (-1, 0) (convention 5: the base
    moves by -2 y): the motor drives the engine joint value A y = 2 y and its force maps
    back as Q_y = A tau. Mirrored, the block's relative motion obeys
    m z'' + c z' + k z = -2 m y''; the actuator force is Q_y = 2 ((m_P + m) 2 y'' + m z'')."""
    m, k, c, m_P, Y, W = 1.0, 100.0, 2.0, 0.5, 0.01, 10.0
    dt, t_end = 1e-3, 2.0
    mech = Mechanism(
        bodies=(Body("base", m_P, m_P * (0.05**2 + 0.2**2) / 12, (Rectangle((0, 0), 0.05, 0.2),)),
                Body("block", m, m * (0.1**2 + 0.1**2) / 12, (Rectangle((0, 0), 0.1, 0.1),))),
        joints=(Prismatic("base_guide", "world", "base", "y", axis=(-2, 0)),
                Prismatic("block_guide", "base", "block", "z", axis=(-1, 0),
                          parent_anchor=(-0.3, 0))),
        forces=(CoordinateForce("spring_damper", "z", **coordinate_spring_damper(k, 0, c)),),
        prescribed=(Prescribed("actuator", "y", Y * sp.sin(W * TIME)),),
        gravity=9.81,
    )
    run = BACKEND.simulate(mech, np.zeros(2), np.array([Y * W, 0.0]), t_end, dt)

    def rhs(t, y):
        return [y[1], (2 * m * Y * W**2 * math.sin(W * t) - c * y[1] - k * y[0]) / m]

    sol = solve_ivp(rhs, (0.0, t_end), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-15,
                    t_eval=run.t)
    z, zd = sol.y
    ydd = -Y * W**2 * np.sin(W * run.t)
    zdd = (-2 * m * ydd - c * zd - k * z) / m
    force_ref = 2 * ((m_P + m) * 2 * ydd + m * zdd)
    force = run.actuator_forces["actuator"]
    wh = math.sqrt(k / m) * dt  # the first-order bound of the test above
    assert np.max(np.abs(run.q[:, 0] - Y * np.sin(W * run.t))) <= 1e-12
    assert np.max(np.abs(run.q[:, 1] - z)) <= wh * np.max(np.abs(z))
    assert np.max(np.abs(force - force_ref)) <= wh * np.max(np.abs(force_ref))
