"""A benchmark's own error measure (`System.benchmark_error`, issue 25 item 5): the
measure is the one the benchmark defines, checked against the pendulum's closed form
(IFToMM A01: sin(phi/2) = k sn(K(k) - w t | k^2), independent of the derivation); an
injected model error (a 1 % longer pendulum in one engine) raises the convergence
study's benchmark error by what the closed form predicts; a run the system declares
failed shows as failed on the convergence page."""
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.special import ellipj, ellipk

from mbfidelity.analytic.reference import reference
from mbfidelity.comparisons.benchmark_error import benchmark_errors, declared_failure
from mbfidelity.comparisons.convergence import convergence
from mbfidelity.systems import BenchmarkError, get_system

A01 = "iftomm_a01_pendulum"
T = 2.0    # about one swing (the period is 2.37 s): every phase of the motion is measured
DT = 1e-3


def closed_form_phi(t: np.ndarray, L: float, g: float = 9.81,
                    phi0: float = math.pi / 2) -> np.ndarray:
    """The pendulum released from rest at phi0 (Jacobi's elliptic functions)."""
    k = math.sin(phi0 / 2)
    sn, _, _, _ = ellipj(ellipk(k * k) - math.sqrt(g / L) * t, k * k)
    return 2 * np.arcsin(k * sn)


def closed_form_p1(t: np.ndarray, L: float) -> np.ndarray:
    phi = closed_form_phi(t, L)
    return np.column_stack([L * np.sin(phi), -L * np.cos(phi)])


def _a01():
    system = get_system(A01)
    sc = system.scenarios[0]
    values = system.parameter_values(scenario=sc)
    return system, values, system.numeric_mechanism(values), reference(system, sc, values,
                                                                        DT, T)


def test_the_benchmark_error_is_the_largest_error_of_p1s_coordinates():
    """A01's measure is the largest error of P1's x and y over the run (the
    specification's reference solution). A run whose angle is off by a constant eps has
    P1 off by L (sin(phi + eps) - sin phi, cos phi - cos(phi + eps)): its largest
    component over the closed form's motion is the expected error. The reference's own
    error (DOP853 at 1e-12, about 1e-10 rad) moves that by eps times it at most."""
    system, values, mech, ref = _a01()
    eps = 1e-3
    got = benchmark_errors(system, values, mech, ref, ref.q + eps, ref.qd)
    phi = closed_form_phi(ref.t, values["L"])
    dx = values["L"] * np.abs(np.sin(phi + eps) - np.sin(phi))
    dy = values["L"] * np.abs(np.cos(phi + eps) - np.cos(phi))
    assert got["P1.x"] == pytest.approx(dx.max(), abs=1e-12)
    assert got["P1.y"] == pytest.approx(dy.max(), abs=1e-12)
    assert got["error"] == max(got["P1.x"], got["P1.y"])
    # a measure at the run's end on a coordinate: the offset itself, there only
    at_end = replace(system, benchmark_error=BenchmarkError(("phi",), "end", "rad", "test"))
    ramp = ref.q + eps * ref.t[:, None] / ref.t[-1]  # 0 at the start, eps at the end
    assert benchmark_errors(at_end, values, mech, ref, ramp, ref.qd)["error"] == \
        pytest.approx(eps, rel=1e-12)
    # a run that stops early (or leaves the finite numbers) has no error
    assert math.isnan(benchmark_errors(system, values, mech, ref, ref.q[:-5],
                                       ref.qd[:-5])["error"])


def test_a_longer_pendulum_raises_the_benchmark_error_by_the_closed_forms_amount():
    """MuJoCo (RK4) builds the pendulum 1 % longer; the reference keeps the true length.
    Its benchmark error is then the distance between the two closed-form motions (their
    periods differ by 0.5 %: P1 drifts by centimetres within a swing), within the
    engine's own error for the longer pendulum plus the reference's (the triangle
    inequality on the largest error): RK4 at 1 ms on a 0.5 % slower swing errs as much as
    on the true one to a few per cent, so twice the nominal run's error bounds it."""
    nominal = convergence(A01, "mujoco", dts=(DT,), t_end=T).points[0]
    longer = convergence(A01, "mujoco", dts=(DT,), t_end=T,
                         engine_scale={"L": 1.01}).points[0]
    t = np.arange(longer.steps + 1) * DT
    predicted = np.abs(closed_form_p1(t, 1.01) - closed_form_p1(t, 1.0)).max()
    *_, ref = _a01()
    bound = 2 * nominal.benchmark_error + ref.point_error_estimate["P1"]
    assert abs(longer.benchmark_error - predicted) <= bound
    assert predicted > 1e6 * bound  # the injected error dominates the measure


def test_a_declared_failure_shows_on_the_convergence_page(tmp_path):
    """An engine whose run leaves the finite numbers (MuJoCo on A02, declared in the
    row's module) is listed as not completed, with the declared reason, not left out."""
    import json

    from mbfidelity.reports.convergence_page import CONVERGENCE, write_convergence_page

    from mbfidelity.systems.benchmarks.iftomm_a02_four_bar import SINGULAR_MUJOCO

    reason = declared_failure(get_system("iftomm_a02_four_bar"), "mujoco", "published")
    assert reason == SINGULAR_MUJOCO
    assert declared_failure(get_system("iftomm_a02_four_bar"), "pybullet", "published") == ""
    point = {"dt": 1e-3, "error": float("nan"), "wall_time": 1.0, "cpu_time": 1.0,
             "steps": 100, "accuracy": None, "integrator_steps": None,
             "benchmark_error": float("nan")}
    study = {"system": "iftomm_a02_four_bar", "scenario": "published", "simulator": "mujoco",
             "integrator_order": 4, "points": [point], "observed_order": None,
             "knob": "step", "flattened": "", "failure": "", "unsupported": "",
             "benchmark_measure": "B0", "benchmark_unit": "m, m/s",
             "declared_failure": reason,
             "metric": {"status": "xfail", "reason": reason, "tolerance": 0.5}}
    doc = {"provenance": {"git_describe": "", "date": ""}, "steps": [1e-3], "t_end": 20.0,
           "accuracies": [], "min_accuracy_decrease": 2, "order_tolerance": 0.5,
           "min_decrease": 1.5, "reference_margin": 3, "studies": [study]}
    (tmp_path / CONVERGENCE).write_text(json.dumps(doc))
    page = write_convergence_page(tmp_path).read_text()
    assert "did not complete (declared)" in page
    assert SINGULAR_MUJOCO in page
    assert (tmp_path / "convergence-iftomm_a02_four_bar.png").exists()


def test_the_default_step_table_reports_each_quantity_and_refuses_other_rows():
    """`api.benchmark_errors`: the largest of the quantities' errors, the CPU seconds of
    the stepping, over the problem's whole run; a row without a measure is refused."""
    from mbfidelity import api

    doc = api.benchmark_errors([A01], ["mujoco"])
    row, = doc["rows"]
    assert row["status"] == "completed" and row["t_end"] == 10.0
    assert set(row["errors"]) == {"P1.x", "P1.y"}
    assert row["error"] == max(row["errors"].values())
    assert row["cpu_time"] > 0
    with pytest.raises(ValueError, match="no benchmark error"):
        api.benchmark_errors(["compound_pendulum"], ["mujoco"])
