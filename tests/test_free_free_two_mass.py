"""free_free_two_mass (Italian notes §5.3.1-5.3.4): every expected value written here
from Newton's law on each mass, independently of the derivation."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mbfidelity.analytic.closed_forms import SOLUTIONS
from mbfidelity.analytic.errata import errata
from mbfidelity.analytic.linear import find_equilibria, operating_equilibrium
from mbfidelity.analytic.numeric import numeric_model
from mbfidelity.analytic.relative_equilibrium import (direct_linearization,
                                                      quadratic_forms_linearization)
from mbfidelity.systems import get_system

SYSTEM = get_system("free_free_two_mass")
PARAMETER_SETS = [SYSTEM.parameter_values(),
                  SYSTEM.parameter_values({"m": 2.5, "k": 37.0, "F": -4.0}),
                  SYSTEM.parameter_values({"m": 0.3, "k": 500.0, "F": 0.0})]


@pytest.mark.parametrize("v", PARAMETER_SETS)
def test_relative_equilibrium_is_eq_5_42_and_5_52(v):
    m, k, F = v["m"], v["k"], v["F"]
    (eq,) = find_equilibria(SYSTEM, v)
    assert eq.q[1] == pytest.approx(-F / (2 * k), abs=1e-14)      # eq. 5.52
    np.testing.assert_allclose(eq.acceleration, [F / (2 * m), 0.0], atol=1e-13)  # eq. 5.42
    assert eq.stable


@pytest.mark.parametrize("v", PARAMETER_SETS)
def test_modes_rigid_and_relative(v):
    eq = operating_equilibrium(SYSTEM, v)
    w = sorted(abs(mode.eigenvalue) for mode in eq.modes)
    np.testing.assert_allclose(w, [0.0, np.sqrt(2 * v["k"] / v["m"])], rtol=1e-12, atol=0)
    m, k = v["m"], v["k"]
    np.testing.assert_allclose(eq.M, [[2 * m, m], [m, m]], rtol=1e-14)
    np.testing.assert_allclose(eq.K, [[0, 0], [0, k]], rtol=1e-14)
    np.testing.assert_allclose(eq.C, 0, atol=0)


@pytest.mark.parametrize("v", PARAMETER_SETS)
def test_both_linearization_routes_agree(v):
    """§5.3.3 (Jacobians of the equations of motion at the accelerated reference) against
    §5.3.4 (quadratic T, D, V with the constant F's generalized force linearized)."""
    eq = operating_equilibrium(SYSTEM, v)
    model = numeric_model(SYSTEM.id, v)
    route1 = direct_linearization(model, eq.q, np.zeros(2), eq.acceleration)
    route2 = quadratic_forms_linearization(SYSTEM, v, eq.q)
    for a, b in zip(route1, route2):
        np.testing.assert_allclose(a, b, atol=1e-12 * max(1.0, np.abs(a).max()))


def _newton(v):
    """m x1'' = F + k dx, m x2'' = -k dx, with dx = x2 - x1 - l0."""
    m, k, F, l0 = v["m"], v["k"], v["F"], v["l0"]

    def rhs(t, y):
        x1, x2, v1, v2 = y
        dx = x2 - x1 - l0
        return [v1, v2, (F + k * dx) / m, -k * dx / m]
    return rhs


@pytest.mark.parametrize("scenario", [s.name for s in SYSTEM.scenarios])
def test_closed_form_against_newton_on_each_mass(scenario):
    sc = SYSTEM.scenario(scenario)
    v = SYSTEM.parameter_values(scenario=sc)
    q0, qd0 = SYSTEM.initial_state(sc, v)
    t = np.linspace(0, sc.t_end, 1001)
    q, qd = SOLUTIONS[SYSTEM.exact_solution](v, q0, qd0, t)
    y0 = [q0[0], q0[0] + v["l0"] + q0[1], qd0[0], qd0[0] + qd0[1]]
    sol = solve_ivp(_newton(v), (0, sc.t_end), y0, method="DOP853", rtol=1e-13, atol=1e-12,
                    t_eval=t)
    scale = np.max(np.abs(sol.y[0]))
    np.testing.assert_allclose(q[:, 0], sol.y[0], atol=1e-10 * scale)
    np.testing.assert_allclose(q[:, 1], sol.y[1] - sol.y[0] - v["l0"], atol=1e-10)
    np.testing.assert_allclose(qd[:, 1], sol.y[3] - sol.y[2], atol=1e-9)
    # the centre of mass: uniformly accelerated at F/(2m) (eq. 5.42)
    cg = (sol.y[0] + sol.y[1]) / 2
    cg_hand = cg[0] + (y0[2] + y0[3]) / 2 * t + v["F"] / (4 * v["m"]) * t**2
    np.testing.assert_allclose(cg, cg_hand, atol=1e-10 * scale)


def test_closed_form_solves_the_derived_equations():
    sc = SYSTEM.scenario("from_rest")
    v = SYSTEM.parameter_values(scenario=sc)
    q0, qd0 = SYSTEM.initial_state(sc, v)
    t = np.linspace(0, sc.t_end, 501)
    q, _ = SOLUTIONS[SYSTEM.exact_solution](v, q0, qd0, t)
    sol = solve_ivp(numeric_model(SYSTEM.id, v).ode_rhs, (0, sc.t_end), np.r_[q0, qd0],
                    method="DOP853", rtol=1e-13, atol=1e-12, t_eval=t)
    np.testing.assert_allclose(q.T, sol.y[:2], atol=1e-9 * np.max(np.abs(q)))


def test_printed_formulas_agree():
    verdicts = {e.label: e.verdict for e in errata(SYSTEM)}
    assert verdicts and set(verdicts.values()) == {"agrees"}, verdicts


def test_analyze_says_there_is_no_static_equilibrium(tmp_path):
    from typer.testing import CliRunner

    from mbfidelity.cli import app

    out = CliRunner().invoke(app, ["analyze", SYSTEM.id])
    assert out.exit_code == 0, out.output
    assert "no static equilibrium in absolute coordinates" in out.output
    assert "relative equilibrium" in out.output
