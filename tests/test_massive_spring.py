"""The spring with distributed mass (§6.2, Fig. 18, eq. 69-70) as a chain of N lumped
masses: N as a structural parameter (validated, keyed in every cache), the chain against
the hand derivation (tests/hand/massive_spring.py), `analyze`'s continuum and Rayleigh
keys, and the convergence of the chain toward the exact continuum as N^-2."""
import json
import math

import numpy as np
import pytest
import scipy.optimize
from typer.testing import CliRunner

from mbfidelity.analytic.continuum import (lumped_spring_error_coefficients,
                                           spring_with_end_mass_frequencies)
from mbfidelity.analytic.derivation import cache_key, derivation_of
from mbfidelity.analytic.discretization import chain_frequencies, discretization_study
from mbfidelity.analytic.linear import find_equilibria, operating_equilibrium
from mbfidelity.cli import app
from mbfidelity.systems import get_system

from hand import facts

HAND = facts()["massive_spring"]
SYSTEM_ID = "massive_spring"


def _values(N: int, **overrides) -> dict:
    s = get_system(SYSTEM_ID)
    return s.parameter_values({"N": N, **overrides})


def _exact_betas(ratio: float, count: int) -> list[float]:
    """Roots of beta tan(beta) = ratio, written here (independent of analytic/continuum)."""
    f = lambda b: b * math.sin(b) - ratio * math.cos(b)  # noqa: E731
    return [scipy.optimize.brentq(f, max(n * math.pi, 1e-12), n * math.pi + math.pi / 2,
                                  xtol=1e-15) for n in range(count)]


# --- N as a structural parameter ---------------------------------------------------------

@pytest.mark.parametrize("bad", [0, -2, 2.5, 1e-3])
def test_N_must_be_a_positive_integer(bad):
    with pytest.raises(ValueError, match=r"parameter N must be an integer >= 1"):
        get_system(SYSTEM_ID).parameter_values({"N": bad})


def test_N_shapes_the_mechanism_and_its_id():
    s = get_system(SYSTEM_ID)
    assert len(s.coordinates) == int(s.parameter_values()["N"])
    for N in (1, 3, 5):
        special = s.with_structure({"N": N})
        assert special.coordinates == tuple(f"u{i}" for i in range(1, N + 1))
        assert special.id == f"{SYSTEM_ID}@N={N}" and special.catalog_id == SYSTEM_ID
        assert get_system(special.id) is special  # the id resolves to the same object
        assert special.with_structure({"N": N}) is special
        assert special.with_structure(s.parameter_values()) is s
    with pytest.raises(KeyError, match="structural parameters are N"):
        get_system(f"{SYSTEM_ID}@M=3")
    with pytest.raises(KeyError, match="parameter N must be an integer >= 1, got 2.5"):
        get_system(f"{SYSTEM_ID}@N=2.5")


def test_every_cache_tells_the_structures_apart():
    """Derived for N = 3 first, then N = 5: each gets its own derivation, compiled model
    and persistent cache key (no entry of one N is ever served for another)."""
    s = get_system(SYSTEM_ID)
    three, five = s.with_structure({"N": 3}), s.with_structure({"N": 5})
    assert len({cache_key(s), cache_key(three), cache_key(five)}) == 3
    assert derivation_of(three.id).n == 3 and derivation_of(five.id).n == 5
    # through the values alone (the catalog id with N in the parameters), as every
    # caller that holds the catalog system does
    for N in (3, 5):
        eq = operating_equilibrium(s, _values(N))
        assert len(eq.q) == N
        np.testing.assert_allclose(eq.q, HAND.equilibrium(_values(N)), rtol=1e-12)


# --- the chain by hand ---------------------------------------------------------------------

def test_one_element_is_the_block_with_half_the_spring():
    v = _values(1)
    (mode,) = operating_equilibrium(get_system(SYSTEM_ID), v).modes
    assert abs(mode.eigenvalue) == pytest.approx(HAND.one_element_frequency(v), rel=1e-12)


def test_two_elements_mass_and_stiffness_by_hand():
    v = _values(2, m=1.7, rho=0.45)
    eq = operating_equilibrium(get_system(SYSTEM_ID), v)
    M, K = HAND.two_element_matrices(v)
    np.testing.assert_allclose(eq.M, M, rtol=1e-12)
    np.testing.assert_allclose(eq.K, K, rtol=1e-12)
    np.testing.assert_allclose(sorted(abs(m.eigenvalue) for m in eq.modes),
                               HAND.two_element_frequencies(v), rtol=1e-10)
    np.testing.assert_allclose(eq.q, HAND.equilibrium(v), rtol=1e-12)


@pytest.mark.parametrize("N", [1, 2, 5, 12])
def test_chain_modes_solve_the_hand_frequency_equation(N):
    v = _values(N, k=250.0, m=0.6)
    eq = operating_equilibrium(get_system(SYSTEM_ID), v)
    np.testing.assert_allclose(sorted(abs(m.eigenvalue) for m in eq.modes),
                               HAND.frequencies(v), rtol=1e-9)


def test_one_equilibrium_found_without_a_grid():
    """The statics are linear: the search starts at the operating point only (a grid of
    5^N starts would be 244140625 at N = 12)."""
    v = _values(12)
    eqs = find_equilibria(get_system(SYSTEM_ID), v)
    assert len(eqs) == 1 and eqs[0].stable
    np.testing.assert_allclose(eqs[0].q, HAND.equilibrium(v), rtol=1e-12)


# --- analyze: continuum and Rayleigh --------------------------------------------------------

def test_analyze_reports_continuum_rayleigh_and_the_chains_modes():
    res = CliRunner().invoke(app, ["analyze", SYSTEM_ID, "--param", "N=4", "--param", "m=0.5",
                                   "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    v = _values(4, m=0.5)
    k, Ms, m = v["k"], v["rho"] * v["l"], v["m"]
    exact_hz = [b * math.sqrt(k / Ms) / (2 * math.pi) for b in _exact_betas(Ms / m, 3)]
    np.testing.assert_allclose(doc["continuum"]["frequency_hz"], exact_hz, rtol=1e-9)
    (estimate,) = doc["rayleigh"]
    rayleigh_hz = math.sqrt(k / (m + Ms / 3)) / (2 * math.pi)  # eq. 70
    assert estimate["label"] == "eq. 69-70"
    assert estimate["frequency_hz"] == pytest.approx(rayleigh_hz, rel=1e-12)
    assert estimate["relative_error"] == pytest.approx(rayleigh_hz / exact_hz[0] - 1, rel=1e-9)
    assert estimate["relative_error"] > 0  # Rayleigh's quotient is an upper bound
    assert doc["coordinates"] == ["u1", "u2", "u3", "u4"]
    np.testing.assert_allclose([x["frequency_hz"] for x in doc["modes"]],
                               np.array(HAND.frequencies(v)) / (2 * math.pi), rtol=1e-9)
    assert doc["continuum"]["discretization"]["N"] == 4


def test_bad_N_is_one_line():
    res = CliRunner().invoke(app, ["analyze", SYSTEM_ID, "--param", "N=2.5", "--json"])
    assert res.exit_code == 2
    assert res.output.strip() == "error: parameter N must be an integer >= 1, got 2.5"


# --- convergence toward the continuum -------------------------------------------------------

def test_error_coefficient_limits():
    """C_n of analytic/continuum.py in its two limits, by hand: a massless end (the bare
    rod: lumped dispersion -(beta h)^2/24 with beta = (2n-1) pi/2) and a heavy block
    (the N = 1 chain k/(m + M_s/2) against k/(m + M_s/3): -r/12, r = M_s/m)."""
    light = lumped_spring_error_coefficients(1.0, 1e-9, 3)
    for n, c in enumerate(light, start=1):
        assert c == pytest.approx(-((2 * n - 1) * math.pi / 2) ** 2 / 24, rel=1e-6)
    r = 1e-4
    assert lumped_spring_error_coefficients(r, 1.0, 1)[0] == pytest.approx(-r / 12, rel=1e-3)


#: N of the fast check (the chain of the tests above, derived once): the first three
#: modes are in the asymptotic range, (beta_3 / N)^2 = (6.5/12)^2 = 0.29 at most for
#: mass ratios rho l / m below 1
FAST_N = 12


def test_chain_converges_as_N_squared_with_the_derived_constant():
    """The chain's error at N against C_n / N^2 (C_n derived by hand, not fitted): the
    next term of the expansion is O((beta_n / N)^2) relative to the leading one, so the
    ratio measured / predicted must be within 1 +- (beta_n / N)^2 (a bound the
    expansion's coefficients, all below 1/2 here, keep with margin)."""
    s = get_system(SYSTEM_ID)
    v = s.parameter_values()
    k, Ms, m = v["k"], v["rho"] * v["l"], v["m"]
    exact = [b * math.sqrt(k / Ms) for b in _exact_betas(Ms / m, 3)]
    betas = _exact_betas(Ms / m, 3)
    got = [2 * math.pi * f for f in chain_frequencies(s, v, FAST_N)]
    for w, e, c, b in zip(got, exact, lumped_spring_error_coefficients(Ms, m, 3), betas):
        measured, predicted = (w - e) / e, c / FAST_N**2
        assert measured < 0  # lumped: below the continuum
        assert measured / predicted == pytest.approx(1, abs=(b / FAST_N) ** 2)


@pytest.mark.slow
def test_convergence_study_to_32_elements():
    """The issue's study: N = 2, 4, 8, 16, 32; the fitted order over N = 8, 16, 32 is 2
    (lumped linear elements: second-order accurate in the element length), within the
    drift of the next term, O(N^-2) relative; the N = 32 error within 1 +- (beta/32)^2 of
    C_n / 32^2."""
    s = get_system(SYSTEM_ID)
    v = s.parameter_values()
    study = discretization_study(s, v)
    Ms, m = v["rho"] * v["l"], v["m"]
    betas = _exact_betas(Ms / m, 3)
    exact_hz = [f / (2 * math.pi) for f in spring_with_end_mass_frequencies(v["k"], Ms, m)]
    np.testing.assert_allclose(study.exact_hz, exact_hz, rtol=1e-12)
    for n, order in enumerate(study.fitted_order):
        assert order == pytest.approx(2, abs=4 * (betas[n] / 8) ** 2), n
    last = study.rows[-1]
    assert last.N == 32
    for err, c, b in zip(last.relative_error, study.leading_error, betas):
        assert err / (c / 32**2) == pytest.approx(1, abs=(b / 32) ** 2)


def test_discretization_command():
    """`mbfidelity discretization` prints the study; N = 1 and 2 against the hand forms."""
    res = CliRunner().invoke(app, ["discretization", SYSTEM_ID, "--counts", "1,2",
                                   "--param", "m=0.8", "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    v = _values(1, m=0.8)
    assert [r["N"] for r in doc["rows"]] == [1, 2]
    assert doc["rows"][0]["frequency_hz"][0] == pytest.approx(
        HAND.one_element_frequency(v) / (2 * math.pi), rel=1e-12)
    np.testing.assert_allclose(doc["rows"][1]["frequency_hz"],
                               np.array(HAND.two_element_frequencies(_values(2, m=0.8)))
                               / (2 * math.pi), rtol=1e-10)
    bad = CliRunner().invoke(app, ["discretization", SYSTEM_ID, "--counts", "2,0"])
    assert bad.exit_code == 2 and "parameter N must be an integer >= 1" in bad.output


def test_declarations_follow_the_structure():
    """An expectation's `when` is a relation of the structural parameters: the chain's
    fastest mode, hence w h at the default step, grows with N, so the declarations that
    hold at N = 16 do not at N = 8 (where every mode-by-mode gate resolves)."""
    from mbfidelity.comparisons.runner import expectations
    from mbfidelity.systems import Expectation

    s = get_system(SYSTEM_ID)

    def mujocos(system):
        return [g[0].metric for g in expectations(system, "mujoco")
                if g[0] in s.expectations and g[0].simulator == "mujoco"]

    assert mujocos(s.with_structure({"N": 1})) == []
    assert mujocos(s) == []  # N = 8
    assert mujocos(s.with_structure({"N": 16})) == ["frequency.fit_mode*", "damping.fit_mode*"]
    assert mujocos(s.with_structure({"N": 23})) == ["pulled.*", "frequency.fit_mode*",
                                                    "damping.fit_mode*"]
    assert mujocos(s.with_structure({"N": 26})) == ["pulled.*", "relaxed.*",
                                                    "frequency.fit_mode*", "damping.fit_mode*"]
    with pytest.raises(ValueError, match="relation of the parameters"):
        Expectation("*", "*", "xfail", "probe", when="M > 2").applies({"N": 3})


def test_each_engines_chain_against_the_hand_and_the_continuum(tmp_path):
    """Issue 12 items 4-5 for §6.2: each engine builds the chain for N = 2 and 12, its own
    linearization gives the hand-derived frequencies (the N-element frequency equation of
    tests/hand) within the linearization gate (1e-6: central differences, see
    comparisons/tolerances.py), and its error against the continuum is then the chain's,
    C_1 / N^2 within the (beta/N)^2 of the next term; Pymunk has no linearization and
    says so. The figure is drawn from the saved study."""
    res = CliRunner().invoke(app, ["discretization", SYSTEM_ID, "--counts", "2,12",
                                   "--sim", "mujoco", "--sim", "pybullet", "--sim", "exudyn",
                                   "--sim", "pymunk", "--json", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    exact = doc["exact_hz"][0]
    v = _values(12)
    beta = 2 * math.pi * exact / math.sqrt(v["k"] / (v["rho"] * v["l"]))  # w = beta sqrt(k/(rho l))
    for sim in ("mujoco", "pybullet", "exudyn"):
        rows = doc["engines"][sim]["rows"]
        assert [r["N"] for r in rows] == [2, 12] and all(r["passed"] for r in rows)
        for r in rows:
            hand = np.array(HAND.frequencies(_values(r["N"])))[:len(r["frequency_hz"])]
            np.testing.assert_allclose(r["frequency_hz"], hand / (2 * math.pi), rtol=1e-6)
        twelve = rows[1]["error_vs_continuum"][0]
        predicted = doc["leading_error"][0] / 12**2
        assert abs(twelve / predicted - 1) <= (beta / 12) ** 2
    assert doc["engines"]["pymunk"]["rows"] == []
    assert "no linearization" in doc["engines"]["pymunk"]["reason"]
    assert (tmp_path / "discretization-massive_spring.png").stat().st_size > 0


def test_the_report_shows_a_saved_discretization_study(tmp_path):
    from mbfidelity.reports.html import write_report

    runner = CliRunner()
    res = runner.invoke(app, ["run", "--systems", "mass_spring_damper", "--sims", "pymunk",
                              "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    res = runner.invoke(app, ["discretization", SYSTEM_ID, "--counts", "2,4", "--sim",
                              "exudyn", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert '<img src="discretization-massive_spring.png">' in write_report(tmp_path).read_text()
