"""MuJoCo's route for prescribed motion (a control callback that imposes the acceleration
through qfrc_applied): its error against the closed form of base excitation, its order
under RK4, the discrete route under Euler, and the actuator forces' coordinate
conventions (absolute and clockwise hinges, a slide along a long axis, two drives)
against the symbolic equations of motion at the engine's own states."""
import math

import numpy as np
import pytest
import sympy as sp

from mbfidelity.systems import get_system
from mbfidelity.systems.model import (TIME, Body, CoordinateForce, Mechanism, Prescribed,
                                      Prismatic, Revolute, coordinate_spring_damper)
from mbfidelity.simulators.plan import motions

mujoco_backend = pytest.importorskip("mbfidelity.simulators.mujoco_backend")
pytest.importorskip("mujoco")
BACKEND = mujoco_backend.BACKEND


def _base_excited(ratio: float = 1.0):
    system = get_system("base_excited_msd")
    scenario = next(s for s in system.scenarios if s.overrides.get("ratio") == ratio)
    values = system.parameter_values(scenario=scenario)
    return system.numeric_mechanism(values), {str(k): float(v) for k, v in values.items()}


def _closed_form(P: dict, t: np.ndarray):
    """m z'' + c z' + k z = -m y''(t) with y = Y sin(W t), from rest (z = z' = 0): the
    steady state plus the damped free motion that meets the initial state. Returns z and
    the actuator force (m_P + m) y'' + m z''."""
    m, k, c, Y, W = P["m"], P["k"], P["c"], P["Y"], P["Omega"]
    # steady state z_p = A sin(W t) + B cos(W t) of m z'' + c z' + k z = m Y W^2 sin(W t)
    det = (k - m * W**2) ** 2 + (c * W) ** 2
    A = m * Y * W**2 * (k - m * W**2) / det
    B = -m * Y * W**2 * c * W / det
    wn, zeta = math.sqrt(k / m), c / (2 * math.sqrt(k * m))
    wd = wn * math.sqrt(1 - zeta**2)
    # homogeneous part e^(-zeta wn t) (C cos wd t + D sin wd t): z(0) = 0, z'(0) = 0
    C = -B
    D = (-A * W + zeta * wn * C) / wd
    decay = np.exp(-zeta * wn * t)
    z = A * np.sin(W * t) + B * np.cos(W * t) + decay * (C * np.cos(wd * t) + D * np.sin(wd * t))
    zd = (A * W * np.cos(W * t) - B * W * np.sin(W * t)
          + decay * ((-zeta * wn * C + wd * D) * np.cos(wd * t)
                     + (-zeta * wn * D - wd * C) * np.sin(wd * t)))
    ydd = -Y * W**2 * np.sin(W * t)
    zdd = (-m * ydd - c * zd - k * z) / m
    return z, (P["m_P"] + m) * ydd + m * zdd


def _start(mech):
    q0, qd0 = np.zeros(len(mech.coordinates)), np.zeros(len(mech.coordinates))
    for mv in motions(mech):
        q0[mv.index], qd0[mv.index] = mv.position(0.0), mv.rate(0.0)
    return q0, qd0


def _errors(dt: float, integrator: str = "RK4", t_end: float = 2.0):
    mech, P = _base_excited()
    q0, qd0 = _start(mech)
    run = BACKEND.simulate(mech, q0, qd0, t_end, dt, {"integrator": integrator})
    z, force = _closed_form(P, run.t)
    y = motions(mech)[0].along(run.t)[0]
    return (np.max(np.abs(run.q[:, 1] - z)) / np.max(np.abs(z)),
            np.max(np.abs(run.q[:, 0] - y)) / P["Y"],
            np.max(np.abs(run.actuator_forces["actuator"] - force)) / np.max(np.abs(force)),
            P)


def test_rk4_route_against_the_closed_form():
    """RK4's phase error on a mode w is (w h)^5 / 120 per step, so after t_end it is
    w t_end (w h)^4 / 120 relative; the forcing at W = w (resonance, ratio 1) is
    integrated at the same order. The gate allows 10 times that estimate."""
    dt, t_end = 1e-3, 2.0
    free, prescribed, force, P = _errors(dt, t_end=t_end)
    w = math.sqrt(P["k"] / P["m"])
    gate = 10 * w * t_end * (w * dt) ** 4 / 120
    assert free < gate
    assert prescribed < gate
    assert force < gate


def test_rk4_route_is_fourth_order():
    """Halving the step divides an RK4 error by 2^4; the next term of the expansion is
    O(w h) = 0.1 relative at h = 0.01, which moves the observed order by at most
    log2(1.1) = 0.14: the observed order must lie within 4 +- 0.25."""
    coarse, fine = _errors(0.01), _errors(0.005)
    for e_coarse, e_fine in zip(coarse[:3], fine[:3]):
        assert abs(math.log2(e_coarse / e_fine) - 4) < 0.25


def test_euler_route_lands_on_the_motion_and_is_first_order():
    """Under Euler the discrete acceleration puts the prescribed coordinate on q(t+h) at
    every step: what is left is the round-off of one step (a few ulps of y, and of the
    cancellation in (q(t+h) - q)/h multiplied back by h), which the next step removes,
    so it does not grow with the number of steps; 1000 eps of the amplitude bounds it.
    The free coordinate and the force are first order (observed order within 1 +- 0.1:
    the next term is O(w h) = 0.01 relative at h = 1e-3)."""
    coarse, fine = _errors(1e-3, "Euler"), _errors(5e-4, "Euler")
    assert coarse[1] < 1000 * np.finfo(float).eps and fine[1] < 1000 * np.finfo(float).eps
    for i in (0, 2):
        assert abs(math.log2(coarse[i] / fine[i]) - 1) < 0.1


def _two_drives() -> Mechanism:
    """A carriage driven along a rail of axis length 2, an arm on a torsional spring on
    it, a link at the arm's tip whose ABSOLUTE clockwise angle (with an offset) is
    driven: two drives, and the free arm between them."""
    cart, arm, link = Body("cart", 1.0, 0.01), Body("arm", 0.8, 0.03), Body("link", 0.3, 0.004)
    return Mechanism(
        bodies=(cart, arm, link),
        joints=(Prismatic("rail", "world", "cart", "s", axis=(2, 0)),
                Revolute("hinge", "cart", "arm", "theta", child_anchor=(-0.15, 0)),
                Revolute("wrist", "arm", "link", "phi", parent_anchor=(0.15, 0),
                         child_anchor=(-0.05, 0.01), absolute=True, clockwise=True,
                         angle_offset=0.2)),
        forces=(CoordinateForce("torsion", "theta", **coordinate_spring_damper(20.0, 0, 0.1)),),
        prescribed=(Prescribed("rail_drive", "s", 0.05 * sp.sin(4 * TIME)),
                    Prescribed("wrist_drive", "phi", 0.4 + 0.3 * sp.sin(5 * TIME))),
        gravity=9.81)


def test_actuator_forces_follow_the_coordinate_conventions():
    """At the engine's own sampled states, the symbolic equations (free rows solved for
    the free accelerations, the prescribed ones given) give each actuator force; the
    engine's must agree to round-off (the same state, the same time), whatever the
    coordinate's sign, offset and axis length."""
    from dataclasses import replace

    from mbfidelity.analytic.derivation import Derivation

    mech = _two_drives()
    q0, qd0 = _start(mech)
    run = BACKEND.simulate(mech, q0, qd0, 0.5, 1e-3)
    derivation = Derivation(replace(mech, prescribed=()))
    args = [*derivation.q, *derivation.qd, *derivation.qdd, TIME]
    mass = sp.lambdify(args, derivation.M, "numpy")
    residual = sp.lambdify(args, derivation.residual, "numpy")
    moves = motions(mech)
    driven = [mv.index for mv in moves]
    free = [i for i in range(len(mech.coordinates)) if i not in driven]
    for k in range(0, len(run.t), 50):
        t, q, qd = run.t[k], run.q[k], run.qd[k]
        qdd = np.zeros(len(q))
        qdd[driven] = [mv.acceleration(t) for mv in moves]
        M = np.array(mass(*q, *qd, *qdd, t), dtype=float)
        r = np.array(residual(*q, *qd, *qdd, t), dtype=float).ravel()
        qdd[free] = np.linalg.solve(M[np.ix_(free, free)], -r[free])
        r = np.array(residual(*q, *qd, *qdd, t), dtype=float).ravel()
        for mv in moves:
            engine = run.actuator_forces[mv.element.name][k]
            assert engine == pytest.approx(r[mv.index], rel=1e-9, abs=1e-9)
