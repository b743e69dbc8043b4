"""Driven mechanisms (monograph §8, §9.6; issue 9): prescribed coordinates, actuator forces,
linearization about the unexcited motion, steady-state response. Expected values are
closed forms written here from the monograph's equations (eq. 84, 86, §8.2), not from our
code."""
import numpy as np
import pytest
import sympy as sp

from mbfidelity.analytic.derivation import Derivation, derivation_of
from mbfidelity.analytic.linear import operating_equilibrium
from mbfidelity.analytic.reference import reference
from mbfidelity.analytic.steady_state import steady_state
from mbfidelity.systems import coordinate_symbols, get_system
from mbfidelity.systems.base_excited_msd import absolute_mechanism

RNG = np.random.default_rng(2026)


def _draw(system_id, **fixed):
    s = get_system(system_id)
    base = s.parameter_values()
    values = {k: v * RNG.uniform(0.5, 2.0) if v else v for k, v in base.items()
              if not s.all_parameters[[p.name for p in s.all_parameters].index(k)].derived}
    values.update(fixed)
    return s, s.parameter_values(values)


def test_base_excitation_two_formulations_agree_symbolically():
    """§8.2: the absolute coordinate x (block guided by the ground, spring between P and
    the block) and the relative z (block on the moving base) give the same equation of the
    block once x = y + z."""
    s = get_system("base_excited_msd")
    rel = derivation_of(s.id)
    ab = Derivation(absolute_mechanism(s.symbols))
    y, yd, ydd = coordinate_symbols("y")
    z, zd, zdd = coordinate_symbols("z")
    x, xd, xdd = coordinate_symbols("x")
    to_relative = {x: y + z, xd: yd + zd, xdd: ydd + zdd}
    # the spring's length |GAP + z| is GAP + z wherever the block is right of P
    rows_ab = [sp.lambdify(list(rel.q) + list(rel.qd) + list(rel.qdd),
                           r.xreplace(to_relative).xreplace(s.subs(s.parameter_values())))
               for r in ab.residual]
    rows_rel = [sp.lambdify(list(rel.q) + list(rel.qd) + list(rel.qdd),
                            r.xreplace(s.subs(s.parameter_values()))) for r in rel.residual]
    for _ in range(20):
        state = RNG.uniform(-0.2, 0.2, size=6)
        # the block's row is the same equation
        assert rows_ab[1](*state) == pytest.approx(rows_rel[1](*state), abs=1e-12)
        # the base's row: in absolute coordinates the spring acts on the base, in
        # relative ones the block's inertia does; they differ by the block's row
        assert rows_ab[0](*state) + rows_ab[1](*state) == pytest.approx(
            rows_rel[0](*state), abs=1e-12)


@pytest.mark.parametrize("ratio", [0.5, 1.0, 2.0, 3.7])
def test_base_excitation_transmissibility_both_coordinates(ratio):
    """§8.2: |Z/Y| = m W^2 / |k - m W^2 + i c W| and |X/Y| = sqrt(k^2 + (c W)^2) / |...|,
    at random parameters."""
    s, v = _draw("base_excited_msd", ratio=ratio)
    m, k, c, Y, W = v["m"], v["k"], v["c"], v["Y"], v["Omega"]
    D = abs(k - m * W**2 + 1j * c * W)
    ss = steady_state(s, v)
    assert ss.of("z")[0].amplitude == pytest.approx(abs(Y) * m * W**2 / D, rel=1e-12)
    assert ss.of("x", "observable")[0].amplitude == pytest.approx(
        abs(Y) * np.hypot(k, c * W) / D, rel=1e-12)


def test_base_excitation_actuator_force_closed_form():
    """The base's row: (m_P + m) y'' + m z'' (the spring and damper are internal)."""
    s = get_system("base_excited_msd")
    sc = s.scenarios[1]
    v = s.parameter_values(scenario=sc)
    r = reference(s, sc, v, 1e-3)
    want = (v["m_P"] + v["m"]) * r.qdd[:, 0] + v["m"] * r.qdd[:, 1]
    np.testing.assert_allclose(r.actuator_forces["actuator"], want,
                               atol=1e-12 * np.abs(want).max())
    Y, W = v["Y"], v["Omega"]
    np.testing.assert_allclose(r.qdd[:, 0], -Y * W**2 * np.sin(W * r.t), atol=1e-12 * Y * W**2)


def test_unbalanced_rotor_amplitude_curve_eq86():
    """eq. 86: |X| = m e w^2 / |k - (M + m) w^2 + i c w| over 0.5-2 times the natural
    frequency, at random parameters."""
    for ratio in (0.5, 0.75, 0.9, 1.0, 1.1, 1.5, 2.0):
        s, v = _draw("unbalanced_rotor", ratio=ratio)
        M, m, e, k, c, w = v["M"], v["m"], v["e"], v["k"], v["c"], v["omega"]
        want = m * e * w**2 / abs(k - (M + m) * w**2 + 1j * c * w)
        assert steady_state(s, v).of("x")[0].amplitude == pytest.approx(want, rel=1e-11)


@pytest.mark.parametrize("seed", range(4))
def test_rotating_slot_critical_speed_eq84(seed):
    """eq. 84: stable below sqrt(k/m), unstable above, for any k, m; above it the growth
    rate is the positive root of m s^2 + c s + (k - m w^2) = 0."""
    rng = np.random.default_rng(seed)
    k, m = rng.uniform(10, 200), rng.uniform(0.1, 3)
    critical = np.sqrt(k / m)
    s = get_system("rotating_slot")
    below = s.parameter_values({"k": k, "m": m, "omega": 0.97 * critical})
    above = s.parameter_values({"k": k, "m": m, "omega": 1.03 * critical})
    assert operating_equilibrium(s, below).stable
    eq = operating_equilibrium(s, above)
    assert not eq.stable
    c, K = above["c"], k - m * above["omega"] ** 2
    root = (-c + np.sqrt(c**2 - 4 * m * K)) / (2 * m)
    assert max(x.real for x in eq.eigenvalues) == pytest.approx(root, rel=1e-10)


def test_reference_settles_on_the_steady_state():
    """The reference's own late motion (DOP853) against the closed-form steady state of
    eq. 86: after 5 s the transient (decay rate c/(2(M + m))) is below 1e-4."""
    s = get_system("unbalanced_rotor")
    sc = s.scenario("ratio_1_5")
    v = s.parameter_values(scenario=sc)
    r = reference(s, sc, v, 1e-3)
    M, m, e, k, c, w = v["M"], v["m"], v["e"], v["k"], v["c"], v["omega"]
    X = m * e * w**2 / (k - (M + m) * w**2 + 1j * c * w)
    late = r.t > 4.0
    want = np.real(X * np.exp(1j * w * r.t[late]))
    decay = np.exp(-c / (2 * (M + m)) * 4.0)
    np.testing.assert_allclose(r.q[late, 0], want, atol=2 * decay * abs(X) + 1e-12)


def test_errata_can_fail_on_a_driven_system():
    """eq. 84 with the centrifugal term's sign flipped (k + m w^2) and eq. 86 without the
    rotor's mass on the frame are judged misprints: the printed rows are evaluated with
    the prescribed coordinates on their motion (the check is not vacuous)."""
    from mbfidelity.analytic.errata import _compare
    from mbfidelity.systems import PrintedFormula
    from mbfidelity.systems.model import TIME

    s = get_system("rotating_slot")
    P = s.symbols
    x, x_d, x_dd = coordinate_symbols("x")
    good = PrintedFormula("eq. 84", "eom", [P.m * x_dd + P.c * x_d + (P.k - P.m * P.omega**2) * x
                                            - P.m * P.g * sp.sin(P.omega * TIME)])
    wrong = PrintedFormula("eq. 84 flipped", "eom", [
        P.m * x_dd + P.c * x_d + (P.k + P.m * P.omega**2) * x
        - P.m * P.g * sp.sin(P.omega * TIME)])
    assert _compare(s, good, np.random.default_rng(1))[0] < 1e-12
    assert _compare(s, wrong, np.random.default_rng(1))[0] > 1e-2
    s = get_system("unbalanced_rotor")
    P = s.symbols
    wrong = PrintedFormula("eq. 86 without m", "eom", [
        P.M * x_dd + P.c * x_d + P.k * x - P.m * P.omega**2 * P.e * sp.cos(P.omega * TIME)])
    assert _compare(s, wrong, np.random.default_rng(1))[0] > 1e-2
