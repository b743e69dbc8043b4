"""IFToMM A02, the N-four-bar mechanism through its singular positions: the reference on
the parallelogram branch against the pendulum equation of that branch (written here from
its kinetic and potential energies, integrated by SciPy independently of the
derivation), its energy integral, the published values, and the branch's own check."""
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mbfidelity.analytic.derivation import Derivation
from mbfidelity.analytic.numeric import numeric_model
from mbfidelity.analytic.reference import reference
from mbfidelity.systems import get_system

A02 = "iftomm_a02_four_bar"


def _pendulum_b0(v, times):
    """B0 at `times` from the parallelogram's one-degree-of-freedom equation, written from
    T = J th'^2 / 2, V = G sin th (cranks: uniform bars turning about their pins; couplers:
    translating with the cranks' tips), by DOP853 at rtol = atol = 1e-12."""
    N, L, m, mc, g = (v[k] for k in ("N", "L", "m", "mc", "g"))
    J = (N + 1) * m * L * L / 3 + N * mc * L * L
    G = g * L * ((N + 1) * m / 2 + N * mc)
    sol = solve_ivp(lambda t, y: [y[1], -G * math.cos(y[0]) / J], (0, max(times)),
                    [math.pi / 2, -v["v0"] / L], method="DOP853", rtol=1e-12, atol=1e-12,
                    t_eval=times)
    return L * np.cos(sol.y[0]), L * np.sin(sol.y[0]), J, G


@pytest.mark.parametrize("N", [1, 2])
def test_reference_crosses_the_singular_positions_on_the_parallelogram(N):
    """Over 10 s the chain passes the flat (singular) position twice per turn; B0 at
    every 0.5 s within 1e-8 m of the independent one-degree-of-freedom solution (both
    DOP853 at 1e-12: their errors, a few 1e-10 over this run, stay far below it), and
    the energy constant to 1e-8 J (the integrator's tolerance over the run)."""
    s = get_system(A02)
    v = s.parameter_values({"N": N}, scenario=s.scenarios[0])
    ref = reference(s, s.scenarios[0], v, 1e-2, t_end=10.0)
    th0 = ref.q[:, list(s.with_structure(v).coordinates).index("th0")]
    times = np.arange(0, 10.0001, 0.5)
    rows = np.rint(times / 1e-2).astype(int)
    x, y, J, G = _pendulum_b0(v, times)
    assert np.max(np.abs(v["L"] * np.cos(th0[rows]) - x)) < 1e-8
    assert np.max(np.abs(v["L"] * np.sin(th0[rows]) - y)) < 1e-8
    # the motion did cross the singular positions (th0 = 0 and pi, mod 2 pi)
    assert np.ptp(th0) > 6 * math.pi
    energy0 = J * (v["v0"] / v["L"]) ** 2 / 2 + G  # upright: V = G sin(pi/2)
    assert ref.energy - ref.energy[0] == pytest.approx(np.zeros(len(ref.t)), abs=1e-8)
    assert ref.energy[0] == pytest.approx(energy0, rel=1e-12)


@pytest.mark.slow
def test_the_published_chain_of_forty_windows_over_the_published_duration():
    """N = 40 (the specification's), 20 s: B0 at 10 s and 20 s within 1e-8 m of the
    closed form, and the energy constant to 1e-7 J (81 bars: a total energy some forty
    times the double chain's, DOP853 at 1e-12 relative)."""
    from mbfidelity.systems.benchmarks.iftomm_a02_four_bar import closed_form_th0

    s = get_system(A02)
    v = s.parameter_values({"N": 40}, scenario=s.scenarios[0])
    ref = reference(s, s.scenarios[0], v, 1e-2)
    th0 = ref.q[:, list(s.with_structure(v).coordinates).index("th0")]
    for time in (10.0, 20.0):
        k = int(round(time / 1e-2))
        th = closed_form_th0(v, time)
        assert abs(math.cos(th0[k]) - math.cos(th)) < 1e-8
        assert abs(math.sin(th0[k]) - math.sin(th)) < 1e-8
    assert np.ptp(ref.energy) < 1e-7


def test_published_b0_at_10_s_within_1e6_of_the_published_values():
    """N = 2: the reference's B0 at t = 10 s against the closed form (Jacobi's amplitude,
    exact to round-off) within 1e-9 m, and against the value Exudyn's test model records
    at its finest step within 1e-6 m (its own second-order error is below that)."""
    from mbfidelity.analytic.published import compare_published

    s = get_system(A02)
    v = s.parameter_values({"N": 2})
    rows = compare_published(s, v)
    at10 = [p for p in rows if p["time"] == 10.0]
    assert len(at10) == 4 and all(p["applies"] for p in rows)
    closed = [p for p in at10 if "closed form" in p["source"]]
    exudyn = [p for p in at10 if "Exudyn" in p["source"]]
    assert all(abs(p["reference_value"] - p["published_value"]) < 1e-9 for p in closed)
    assert all(abs(p["reference_value"] - p["published_value"]) < 1e-6 for p in exudyn)
    x, y, _, _ = _pendulum_b0(v, [10.0])
    got = {p["quantity"]: p["reference_value"] for p in closed}
    assert got["B0.x"] == pytest.approx(x[0], abs=1e-9)
    assert got["B0.y"] == pytest.approx(y[0], abs=1e-9)


def test_a_branch_that_does_not_close_the_mechanism_is_refused():
    """Injected model error: the couplers said to turn with the cranks (psi = th0)."""
    s = get_system(A02)
    mech = s.with_structure({"N": 1}).mechanism
    wrong = tuple((name, e if name.startswith("th") else mech.branch[0][1])
                  for name, e in mech.branch)
    with pytest.raises(ValueError, match="does not close"):
        Derivation(replace(mech, branch=wrong)).explicit_dependent


def test_the_flat_position_is_singular_for_newtons_method():
    """Why the branch is needed: at th0 = 0 the constraint Jacobian has rank N, not 2N
    (the mobility jumps to N + 1), so Newton's method on the dependent coordinates has no
    regular matrix there."""
    s = get_system(A02)
    v = s.parameter_values({"N": 2})
    model = numeric_model(s.id, v)
    flat = np.zeros(model.n)
    J = model.constraint_jacobian(flat)
    assert np.linalg.matrix_rank(J) == 2
    assert np.linalg.matrix_rank(J[:, model.dependent]) < model.m


# --- analyze flags a configuration where the constraint Jacobian loses rank -----------

def _pose(N, th0, crank=None):
    q = {f"th{i}": th0 for i in range(N + 1)}
    q.update({f"psi{j}": 0.0 for j in range(1, N + 1)})
    if crank is not None:
        q["th1"] = crank
    return q


@pytest.mark.parametrize("th0,singular", [(0.0, True), (math.pi, True),
                                          (math.pi / 2, False), (1e-3, False)])
def test_the_constraint_rank_marks_the_flat_parallelogram_only(th0, singular):
    """The flat parallelogram (th0 = 0 or pi) has rank N of 2N; the upright one and one
    a milliradian from flat (an injected error of the pose) have full rank: the rank's
    tolerance (1e-8 of the largest singular value) tells a pose solved to round-off
    from one a milliradian away, whose smallest singular value is about 1e-3."""
    from mbfidelity.api import _constraint_rank

    s = get_system(A02)
    v = s.parameter_values({"N": 2})
    built = s.with_structure(v)
    q = _pose(2, th0)
    out = _constraint_rank(built, v, np.array([q[c] for c in built.coordinates]))
    assert out["constraint_rows"] == 4 and out["singular"] is singular
    assert out["constraint_rank"] == (2 if singular else 4)
    assert ("warning" in out) is singular


@pytest.mark.slow
def test_analyze_flags_the_singular_equilibrium_in_json_and_text():
    """Every equilibrium `analyze` lists carries the rank; those with a flat window are
    flagged (JSON) and warned about (text), the hanging parallelogram is not."""
    from typer.testing import CliRunner

    from mbfidelity.api import analyze
    from mbfidelity.cli import app

    doc = analyze(A02, {"N": 1})
    hanging = [e for e in doc["equilibria"] if e["stable"]
               and abs(e["q"]["th0"] + math.pi / 2) < 1e-9 and abs(e["q"]["psi1"]) < 1e-9]
    assert hanging and not hanging[0]["singular"]
    flagged = [e for e in doc["equilibria"] if e["singular"]]
    assert flagged and all(e["constraint_rank"] < e["constraint_rows"] for e in flagged)
    text = CliRunner().invoke(app, ["analyze", A02, "--param", "N=1"]).output
    assert text.count("warning: singular position") == len(flagged)


# --- named points: reported by the reference and analyze, judged like coordinates -------

def _a02_reference(N=2, dt=1e-2, t_end=10.0):
    s = get_system(A02)
    v = s.parameter_values({"N": N}, scenario=s.scenarios[0])
    return s.with_structure(v), v, reference(s, s.scenarios[0], v, dt, t_end=t_end)


def test_the_reference_reports_b0_as_the_first_cranks_tip():
    """B0 = L (cos th0, sin th0), its velocity L th0' (-sin th0, cos th0): written here
    from the geometry, against the reference's point (from the derivation's kinematics),
    and its error estimate no larger than L times th0's."""
    s, v, ref = _a02_reference()
    i = list(s.coordinates).index("th0")
    th, rate, L = ref.q[:, i], ref.qd[:, i], v["L"]
    expected = np.column_stack([L * np.cos(th), L * np.sin(th),
                                -L * rate * np.sin(th), L * rate * np.cos(th)])
    assert np.max(np.abs(ref.points["B0"] - expected)) < 1e-12
    assert ref.point_error_estimate["B0"] <= L * ref.error_estimate[i] * (1 + 1e-9)


def test_analyze_reports_the_points_at_the_end_of_each_scenario():
    """`analyze --json` `points`: B0 at the end of the published run (20 s) within 1e-8 m
    of the closed form (Jacobi's amplitude)."""
    from mbfidelity.api import _points_report
    from mbfidelity.systems.benchmarks.iftomm_a02_four_bar import closed_form_th0

    s = get_system(A02)
    v = s.parameter_values()
    report = _points_report(s.with_structure(v), v)
    assert [(p["point"], p["scenario"]) for p in report] == [
        ("B0", sc.name) for sc in s.scenarios]
    (b0,) = [p for p in report if p["scenario"] == "published"]
    th = closed_form_th0(v, 20.0)
    assert b0["point"] == "B0" and b0["time"] == pytest.approx(20.0)
    assert b0["position"] == pytest.approx([v["L"] * math.cos(th), v["L"] * math.sin(th)],
                                           abs=1e-8)
    assert b0["path_extent"] == pytest.approx(2 * v["L"], rel=1e-3)


def test_engine_points_take_the_shared_kinematics_of_the_coordinates():
    """The engines' route (the plan's planar forward kinematics of the coordinates) gives
    the derivation's points along the reference's states, to round-off."""
    from mbfidelity.comparisons.points import engine_points

    s, v, ref = _a02_reference(t_end=2.0)
    got = engine_points(s, v, s.numeric_mechanism(v), ref.q, ref.qd)
    assert np.max(np.abs(got["B0"] - ref.points["B0"])) < 1e-12


def test_the_point_gate_follows_the_coordinates_gate_and_sees_an_injected_error():
    """The reference against itself measures zero; th0 shifted by 1e-4 rad (an injected
    error) moves B0 by 1e-4 L, which the metric reports relative to B0's excursion; the
    gate is the coordinates' times G = L s_th0 / excursion (B0 depends on th0 alone)."""
    from types import SimpleNamespace

    from mbfidelity.comparisons.points import judge_points, point_gain
    from mbfidelity.comparisons.tolerances import Gate

    s, v, ref = _a02_reference(t_end=2.0)
    mech = s.numeric_mechanism(v)
    i = list(s.coordinates).index("th0")
    q_eq = s.operating_values(v)
    scale = np.max(np.abs(ref.q - q_eq), axis=0)
    excursion, gain = point_gain(s, v, ref, q_eq, scale)["B0"]
    assert gain == pytest.approx(v["L"] * scale[i] / excursion, rel=1e-12)
    recorded = {}

    def judge(label, value, gate):
        recorded[label] = (value, gate.tolerance)

    judge_points(s, v, mech, ref, ref, len(ref.t), q_eq, scale, Gate(1e-3), "run", judge)
    assert recorded["run.trajectory_point_B0_max"][0] < 1e-12
    assert recorded["run.trajectory_point_B0_max"][1] == pytest.approx(1e-3 * gain)
    shifted = ref.q.copy()
    shifted[:, i] += 1e-4
    judge_points(s, v, mech, ref, SimpleNamespace(q=shifted, qd=ref.qd), len(ref.t), q_eq,
                 scale, Gate(1e-3), "run", judge)
    assert recorded["run.trajectory_point_B0_max"][0] == pytest.approx(
        1e-4 * v["L"] / excursion, rel=1e-3)


def test_a_state_off_the_described_branch_is_refused_not_moved_onto_it():
    """A chain with its second window folded (crank 2 pointing back, coupler 2 upright:
    an assembly on another branch) is not on the parallelogram: the reference, which
    follows the described branch only, refuses to start there, and the comparisons
    release no run near such an equilibrium."""
    from mbfidelity.analytic.reference import consistent_initial_state
    from mbfidelity.systems.model import Scenario

    s = get_system(A02)
    v = s.parameter_values({"N": 2})
    model = numeric_model(s.id, v)
    folded = {"th0": -math.pi / 2, "th1": -math.pi / 2, "th2": -math.pi, "psi1": 0.0,
              "psi2": math.pi / 2}
    q = np.array([folded[c] for c in s.coordinates])
    assert np.max(np.abs(model.constraint_values(q))) < 1e-12  # it is an assembly
    assert not model.on_branch(q)
    assert model.on_branch(np.array([_pose(2, 0.3)[c] for c in s.coordinates]))
    with pytest.raises(ValueError, match="not on the mechanism's assembly branch"):
        consistent_initial_state(s, Scenario("folded", folded, t_end=1.0), v)


def test_a_value_published_for_two_windows_does_not_apply_to_one():
    """Exudyn's recorded B0 is for N = 2: under N = 1 it is reported as not applicable
    (the closed form applies at any N)."""
    from mbfidelity.analytic.published import compare_published

    s = get_system(A02)
    v = s.parameter_values({"N": 1})
    rows = compare_published(s.with_structure(v), v)
    assert {p["applies"] for p in rows if "Exudyn" in p["source"]} == {False}
    assert all(p["applies"] for p in rows if "closed form" in p["source"])
