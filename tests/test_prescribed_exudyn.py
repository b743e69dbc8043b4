"""Exudyn's route for prescribed motion (a CoordinateConstraint whose offset user functions
give q(t), q'(t), under the implicit driven_solver) against the closed form of the
base-excited mass-spring-damper (monograph §8.2):

    m z'' + c z' + k z = -m y''(t),   actuator force F = (m_P + m) y'' + m z''.

Tolerances come from the trapezoidal rule (TrapezoidalIndex2, order 2): on an oscillator of
angular frequency w it leaves a phase error w^3 h^2 t / 12, so over a run of length T the
free coordinate is off by at most that phase times its amplitude; the prescribed
coordinate is the trapezoidal quadrature of the imposed rate, off by at most
h^2 T max|y'''| / 12; a factor 2 covers the second-order terms the leading one leaves out.
The order between two steps is checked to lie within 10 % of 2 (w h <= 0.02: asymptotic).
"""
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from mbfidelity.simulators import get_backend
from mbfidelity.systems import get_system
from mbfidelity.systems.model import TIME, Body, Mechanism, Prescribed, Revolute

BACKEND = get_backend("exudyn")
pytestmark = pytest.mark.skipif(not BACKEND.available()[0], reason="exudyn not installed")

T_END = 1.0
STEPS = (2e-3, 1e-3)


def _base_excited(motion: str = "sin"):
    system = get_system("base_excited_msd")
    values = system.parameter_values(scenario=system.scenario("omega_1wn"))
    mech = system.numeric_mechanism(values)
    m, k, c, m_p, amp, omega = (values[x] for x in ("m", "k", "c", "m_P", "Y", "Omega"))
    if motion == "cos":
        # starts with y''(0) != 0: the solver must start from consistent accelerations
        (actuator,) = mech.prescribed
        mech = replace(mech, prescribed=(replace(actuator, motion=amp * sp.cos(omega * TIME)),))
    y = sp.lambdify(TIME, mech.prescribed[0].motion)
    y_dd = sp.lambdify(TIME, mech.prescribed[0].acceleration)

    def closed_form(t: np.ndarray):
        def rhs(s, state):
            z, z_d = state
            return [z_d, (-m * y_dd(s) - c * z_d - k * z) / m]

        sol = solve_ivp(rhs, (0.0, t[-1]), [0.0, 0.0], method="DOP853", rtol=1e-12,
                        atol=1e-14, t_eval=t)
        z, z_d = sol.y
        z_dd = (-m * y_dd(t) - c * z_d - k * z) / m
        return y(t), z, (m_p + m) * y_dd(t) + m * z_dd

    return mech, closed_form, np.sqrt(k / m), amp * omega**3


def _errors(mech, closed_form, dt: float):
    run = BACKEND.simulate(mech, np.zeros(2), np.zeros(2), T_END, dt)
    y, z, force = closed_form(run.t)
    actuator = run.actuator_forces["actuator"]
    assert actuator.shape == run.t.shape
    return (np.max(np.abs(run.q[:, 1] - z)), np.max(np.abs(run.q[:, 0] - y)),
            np.max(np.abs(actuator - force)) / np.max(np.abs(force)), np.max(np.abs(z)),
            actuator)


@pytest.mark.parametrize("motion", ["sin", "cos"])
def test_route_is_second_order_against_the_closed_form(motion):
    mech, closed_form, omega_n, max_jerk = _base_excited(motion)
    assert BACKEND.scheme(mech).name == "TrapezoidalIndex2"
    results = [_errors(mech, closed_form, dt) for dt in STEPS]
    for dt, (e_free, e_driven, e_force, amplitude, _) in zip(STEPS, results):
        phase = omega_n**3 * dt**2 * T_END / 12
        assert e_free <= 2 * phase * amplitude, (dt, e_free)
        assert e_driven <= 2 * dt**2 * T_END * max_jerk / 12, (dt, e_driven)
        assert e_force <= 2 * phase, (dt, e_force)
    ratio = STEPS[0] / STEPS[1]
    for coarse, fine in zip(results[0][:3], results[1][:3]):
        order = np.log(coarse / fine) / np.log(ratio)
        assert 1.8 <= order <= 2.2, order


def test_actuator_force_does_not_alternate():
    """With q''(0) != 0, Exudyn's own initial accelerations (constraint time terms left
    out) make the trapezoidal multiplier alternate step to step; the consistent start
    removes it: the second difference stays at the smooth signal's (w h)^2 scale."""
    mech, closed_form, omega_n, _ = _base_excited("cos")
    dt = STEPS[1]
    actuator = _errors(mech, closed_form, dt)[4]
    second = np.max(np.abs(np.diff(actuator, 2)))
    assert second <= 2 * (omega_n * dt) ** 2 * np.max(np.abs(actuator))


def test_driven_mechanisms_refuse_explicit_solvers():
    mech = _base_excited()[0]
    with pytest.raises(ValueError, match="driven_solver"):
        BACKEND.simulate(mech, np.zeros(2), np.zeros(2), 0.01, 1e-3, {"driven_solver": "RK44"})
    with pytest.raises(ValueError, match="driven_solver"):
        BACKEND._solver_for(mech, {**BACKEND.default_settings(), "driven_solver": "RK44"})
    undriven = replace(mech, prescribed=())
    assert BACKEND.scheme(undriven).name == BACKEND.default_settings()["solver"]
    assert BACKEND.scheme(mech, {"driven_solver": "GeneralizedAlpha"}).name == "GeneralizedAlpha"


def test_absolute_angle_on_a_turning_parent_is_unsupported():
    """A CoordinateConstraint holds one engine coordinate; an absolute angle on a turning
    parent is a sum of two."""
    bodies = (Body("a", 1.0, 0.1), Body("b", 1.0, 0.1))
    joints = (Revolute("j1", "world", "a", "t1", child_anchor=(-0.2, 0)),
              Revolute("j2", "a", "b", "t2", parent_anchor=(0.2, 0), child_anchor=(-0.2, 0),
                       absolute=True))
    support = BACKEND.support(Mechanism(bodies, joints, gravity=9.81,
                                        prescribed=(Prescribed("motor", "t2", 2 * TIME),)))
    assert not support.ok and "absolute angle" in support.reason
    assert BACKEND.support(Mechanism(bodies, joints, gravity=9.81,
                                     prescribed=(Prescribed("motor", "t1", 2 * TIME),))).ok
