"""The a-posteriori rule (comparisons/tolerances.py, "A posteriori"): where the a-priori
bound says nothing, the engine's own refinement judges, and it tells an engine converging
to the reference from one converging to another motion."""
import math

import pytest

from mbfidelity.comparisons import tolerances
from mbfidelity.comparisons.runner import compare


def _differences(limit_offset: float, c: float, p: int, h: float, halvings: int):
    """d_k and v for an exact expansion Q_h = Q* + c h^p, the reference at Q* - offset."""
    q = [limit_offset + c * (h / 2**k) ** p for k in range(halvings + 1)]
    return [abs(a - b) for a, b in zip(q, q[1:])], abs(q[0])


@pytest.mark.parametrize("p", [1, 2, 4])
def test_richardson_predicts_the_error_of_an_exact_expansion(p):
    d, v = _differences(0.0, 3.0, p, 0.1, 2)
    gate = tolerances.refinement_gate(d, p, 0.0)
    assert not gate.unresolved
    assert math.isclose(gate.observed_order, p, rel_tol=1e-9)
    # e(h) = d1 / (1 - 2^-p) is the whole error when Q_h - Q* = c h^p exactly
    assert math.isclose(gate.predicted_error, v, rel_tol=1e-9)
    assert v <= gate.tolerance <= tolerances.refinement_safety(p) * v * (1 + 1e-12)


def test_a_limit_off_the_reference_fails_the_refinement_gate():
    # converging at order 1 to a motion 1e-3 away: the refinement predicts 3e-4 at h
    d, v = _differences(1e-3, 3e-3, 1, 0.1, 2)
    gate = tolerances.refinement_gate(d, 1, 0.0)
    assert not gate.unresolved and v > gate.tolerance


def test_differences_that_do_not_shrink_at_the_declared_order_leave_it_unresolved():
    d, _ = _differences(0.0, 1.0, 1, 0.1, 2)
    gate = tolerances.refinement_gate(d, 2, 0.0)  # first-order differences, order 2 declared
    assert "no asymptotic regime" in gate.unresolved


def test_pymunk_unbalanced_rotor_gets_a_verdict_on_every_metric_and_passes():
    """At resonance semi-implicit Euler's a-priori bound exceeds 0.1 of the amplitude
    (lightly damped transient): every metric of the scenario is judged by the
    refinement, and the engine, which converges to eq. 86's motion, passes."""
    result = compare("unbalanced_rotor", "pymunk", scenarios=["ratio_1"])
    scenario = [m for m in result.metrics if m.name.startswith("ratio_1.")]
    assert scenario and all(m.rule == "refinement" for m in scenario)
    # every gate passes (a declaration about other scenarios may flag a pass of this
    # one as unexpected: the comparison of one scenario is not the declared one)
    assert all(m.passed for m in result.metrics), [m.as_dict() for m in result.metrics]
    trajectory = next(m for m in scenario if m.name.endswith("trajectory_max")).as_dict()
    numbers = trajectory["refinement"]
    assert numbers["observed_order"] >= 1 - tolerances.REFINEMENT_ORDER_MARGIN
    assert numbers["predicted_error"] > 0 and trajectory["rule"] == "refinement"


def test_pybullet_out_of_the_box_damping_fails_the_refinement_gate():
    """PyBullet's default body damping (the harness turns it off) makes the engine converge
    to a damped rotor: the motor torque that keeps the speed is then far from eq. 86's,
    however fine the step, and the refinement says so where the a-priori bound could not."""
    damped = compare("unbalanced_rotor", "pybullet", scenarios=["ratio_0_5"],
                     settings={"linear_damping": 0.04, "angular_damping": 0.04})
    torque = next(m for m in damped.metrics if m.name == "ratio_0_5.actuator_motor")
    assert torque.rule == "refinement" and torque.status == "fail"
    assert not damped.passed
    correct = compare("unbalanced_rotor", "pybullet", scenarios=["ratio_0_5"])
    assert all(m.passed for m in correct.metrics)
    assert next(m for m in correct.metrics if m.name == "ratio_0_5.actuator_motor").rule == \
        "refinement"


def test_the_fit_refinement_rejects_a_damping_left_on():
    """At dt = 0.025 s (w h = 0.25, beyond semi-implicit Euler's range 0.2) the fit gates
    are unresolved a priori; the refined fits judge them: PyBullet as the harness builds it
    passes, with its default body damping on the fitted damping ratio is off by about
    damping / (2 w) = 2e-3, which its own refinement does not predict."""
    def fitted_damping(settings):
        result = compare("mass_spring_damper", "pybullet", dt=0.025, scenarios=["free"],
                         settings=settings)
        return next(m for m in result.metrics if m.name == "damping.fit_mode1")

    correct = fitted_damping(None)
    assert correct.rule == "refinement" and correct.status == "pass"
    damped = fitted_damping({"linear_damping": 0.04, "angular_damping": 0.04})
    assert damped.rule == "refinement" and damped.status == "fail"
