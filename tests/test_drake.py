"""The Drake backend (simulators/drake_backend.py): an optional engine that is a visible
skip when pydrake is absent, and the trajectory gate of its error-controlled integrator
(comparisons/tolerances.py), which must reject a model error."""
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from mbfidelity.comparisons import tolerances
from mbfidelity.comparisons.runner import compare
from mbfidelity.simulators import all_backends, get_backend
from mbfidelity.systems import get_system


def _drake():
    backend = get_backend("drake")
    ok, why = backend.available()
    if not ok:
        pytest.skip(f"drake not installed: {why}")
    return backend


def test_a_missing_pydrake_is_reported_not_raised():
    """Importing the backends never imports pydrake; with pydrake unimportable the engine
    says so through `available()` and every other engine is still listed."""
    script = (
        "import sys\n"
        "from mbfidelity.simulators import all_backends\n"
        "backends = all_backends()\n"
        "assert 'pydrake' not in sys.modules, 'discovery imported pydrake'\n"
        "sys.modules['pydrake'] = None  # as if it were not installed\n"
        "ok, why = backends['drake'].available()\n"
        "assert not ok and 'pydrake' in why, why\n"
        "assert {'mujoco', 'pybullet', 'exudyn', 'pymunk'} <= set(backends)\n"
        "print('ok')\n")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


def test_the_error_controlled_bound_is_the_sum_of_the_local_errors():
    """N eps G (1 + min(T, 1/w)) / a, by hand: a velocity error is carried for 1/w on an
    oscillation and for the whole run on a free drift; an unstable motion multiplies every
    local error by at most its growth factor G."""
    assert tolerances.error_controlled_trajectory_tolerance(1e-10, 2000, 4.0, 10.0, 0.5) == \
        pytest.approx(2000 * 1e-10 * 1.25 / 0.5, rel=1e-15)
    assert tolerances.error_controlled_trajectory_tolerance(1e-10, 2000, 0.0, 3.0, 1.0) == \
        pytest.approx(2000 * 1e-10 * 4.0, rel=1e-15)
    assert tolerances.error_controlled_trajectory_tolerance(1e-10, 2000, 4.0, 10.0, 0.5, 30.0) \
        == pytest.approx(30 * 2000 * 1e-10 * 1.25 / 0.5, rel=1e-15)
    assert tolerances.error_controlled_gate(0.2).unresolved
    assert not tolerances.error_controlled_gate(1e-6).unresolved


def test_the_gate_rejects_a_drake_build_one_percent_heavier(monkeypatch):
    """The double pendulum's moderate swing (reference: the exact model) on a Drake
    build whose lower link is 1 % heavier: its motion departs from the reference far
    beyond the error-controlled gate, so the gate fails it; the true build passes the
    same gate."""
    backend = _drake()
    truthful = compare("double_pendulum", "drake", scenarios=["moderate"], t_end=2.0)
    good = {m.name: m for m in truthful.metrics}["moderate.trajectory_max"]
    assert good.status == "pass"
    simulate = type(backend).simulate

    def heavier(self, mechanism, *args, **kwargs):
        bodies = tuple(replace(b, mass=1.01 * float(b.mass)) if b.name == mechanism.bodies[-1].name
                       else b for b in mechanism.bodies)
        return simulate(self, replace(mechanism, bodies=bodies), *args, **kwargs)

    monkeypatch.setattr(type(backend), "simulate", heavier)
    wrong = compare("double_pendulum", "drake", scenarios=["moderate"], t_end=2.0)
    bad = {m.name: m for m in wrong.metrics}["moderate.trajectory_max"]
    assert bad.status == "fail" and bad.value > 10 * bad.tolerance
    assert bad.tolerance == pytest.approx(good.tolerance, rel=0.5)  # the same gate


def test_fixed_step_mode_converges_at_the_declared_order():
    """runge_kutta3 at a fixed step (the convergence study's knob): the compound
    pendulum's error against its own run at a quarter of the step falls by 2^3 per
    halving, within half an order."""
    backend = _drake()
    system = get_system("compound_pendulum")
    mech = system.numeric_mechanism(system.parameter_values())
    settings = {"integrator": "runge_kutta3", "fixed_step": True}
    assert backend.scheme(mech, settings).order == 3
    finals = [backend.simulate(mech, np.array([1.0]), np.array([0.0]), 1.0, dt, settings).q[-1, 0]
              for dt in (0.02, 0.01, 0.0025)]
    order = np.log2(abs(finals[0] - finals[2]) / abs(finals[1] - finals[2]))
    # e(h) - e(h/4) over e(h/2) - e(h/4) = (1 - 4^-p) / (2^-p - 4^-p): 9 for p = 3
    assert order == pytest.approx(np.log2(9.0), abs=0.5)


def test_drake_is_discovered_like_the_other_engines():
    assert "drake" in all_backends()
    assert all_backends()["drake"].id == "drake"


def test_the_exported_script_rebuilds_the_simulated_plant(tmp_path):
    """`export` writes the recorded plant calls as a standalone script: run alone, it
    ends where `simulate` ends after one second from the same initial state."""
    import ast

    from mbfidelity.comparisons.export import export_model

    backend = _drake()
    text, outside = export_model("double_pendulum", "drake")
    assert outside == []
    script = tmp_path / "double_pendulum.py"
    script.write_text(text)
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    printed = ast.literal_eval(out.stdout.strip().splitlines()[-1])
    system = get_system("double_pendulum")
    mech = system.numeric_mechanism(system.parameter_values())
    from mbfidelity.analytic.reference import consistent_initial_state

    q0, qd0 = consistent_initial_state(system, system.scenarios[0], system.parameter_values())
    run = backend.simulate(mech, q0, qd0, 1.0, 1e-3)
    assert list(printed) == list(system.coordinates)
    np.testing.assert_allclose(list(printed.values()), run.q[-1], rtol=0, atol=1e-12)


def test_the_error_falls_with_the_target_accuracy_down_to_a_model_errors_floor():
    """The convergence study's knob for Drake is its target accuracy (comparisons/
    convergence.py). On Fig. 7's pendulum (exact elliptic reference) the error falls by
    at least MIN_ACCURACY_DECREASE per decade over the judged accuracies (the gate
    passes). With the engine's mass a millionth heavier (its build only) the error stops
    falling at that model's own distance from the true motion (the exact models of both
    masses, an independent measure), and the gate rejects the curve."""
    from mbfidelity.analytic.reference import reference
    from mbfidelity.comparisons import metrics
    from mbfidelity.comparisons.convergence import (ACCURACY_METRIC, DEFAULT_STEPS,
                                                    MIN_FIT_POINTS, convergence, judge_order)

    _drake()
    true = convergence("compound_pendulum", "drake")
    assert true.knob == "accuracy" and len(true.judged_accuracies) >= MIN_FIT_POINTS
    metric = judge_order(true)
    assert metric.name == ACCURACY_METRIC and metric.status == "pass", true.as_dict()
    assert metric.value <= 1 / tolerances.MIN_ACCURACY_DECREASE
    errors = [p.error for p in true.points if p.accuracy in true.judged_accuracies]
    assert all(b < a for a, b in zip(errors, errors[1:]))  # monotone where judged

    heavier = convergence("compound_pendulum", "drake", engine_scale={"m": 1 + 1e-6})
    wrong = judge_order(heavier)
    assert wrong.status == "fail" and wrong.value > 1 / tolerances.MIN_ACCURACY_DECREASE
    # the floor: the exact motion of the heavier pendulum against the true one, sampled
    # as the study samples
    system = get_system("compound_pendulum")
    sc = system.scenarios[0]
    values = system.parameter_values(scenario=sc)
    k = int(round(heavier.points[0].dt / DEFAULT_STEPS[2]))
    exact = reference(system, sc, values, DEFAULT_STEPS[2], 2.0)
    model = reference(system, sc, {**values, "m": values["m"] * (1 + 1e-6)},
                      DEFAULT_STEPS[2], 2.0)
    floor, _ = metrics.trajectory_errors(model.q[::k], exact.q[::k],
                                         metrics.amplitude(exact.q, np.zeros(1)))
    # by the triangle inequality they differ by at most Drake's own error on the heavier
    # model, about its error on the true one (a millionth apart): twice that bounds it
    assert abs(heavier.points[-1].error - floor) <= 2 * true.points[-1].error
    assert floor > 1e3 * true.points[-1].error  # the floor is the model's, not Drake's


def test_closed_loops_run_on_the_discrete_plant_and_a_model_error_is_rejected():
    """A belt (a LinearCoupling of two joint values: Drake's coupler constraint) and a
    rhombus closed by a pin in a slot (a ball constraint and the slot's slider substitute)
    run on the discrete SAP plant: first order (semi-implicit Euler's gates), their motion
    within those gates, their constraint forces declared not reported; an arm 2 % longer
    in the engine's build fails the same gate."""
    backend = _drake()
    for system_id in ("belt_pulleys", "rhombus_linkage"):
        system = get_system(system_id)
        mech = system.numeric_mechanism(system.parameter_values())
        assert backend.support(mech).ok
        assert backend.scheme(mech).order == 1 and backend.accuracy_knob(mech) == ""
        result = compare(system_id, "drake", scenarios=["small"], t_end=0.5)
        by_name = {m.name: m for m in result.metrics}
        assert by_name["small.trajectory_max"].status == "pass", by_name["small.trajectory_max"]
        forces = [m for m in result.metrics if m.name.startswith("small.constraint_")]
        assert forces and all(m.status == "xfail" for m in forces)
    heavier = compare("belt_pulleys", "drake", scenarios=["small"], t_end=0.5,
                      engine_scale={"l": 1.02})
    bad = {m.name: m for m in heavier.metrics}["small.trajectory_max"]
    assert bad.status in ("fail", "xfail") and bad.value > bad.tolerance
