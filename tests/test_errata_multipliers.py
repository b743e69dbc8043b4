"""Printed formulas with constraints, Lagrange multipliers, constraint forces and powers of
the non-conservative forces (monograph §7.1, §9.7, §10; Fig. 20, 36, 38, 39, 40): the
errata layer against facts worked out by hand in tests/hand/, never against numbers taken
from our own output."""
import json
from functools import lru_cache

import numpy as np
import pytest
import sympy as sp

from mbfidelity.analytic.errata import (AGREEMENT, Erratum, _compare, _multiplier_errata,
                                        errata, row_space_distance)
from mbfidelity.analytic.numeric import numeric_model
from mbfidelity.systems import PrintedFormula, coordinate_symbols, get_system
from mbfidelity.systems.model import TIME

from hand import facts

HAND = facts()


@lru_cache(maxsize=None)
def _errata(system_id):
    return tuple(errata(get_system(system_id)))


def _angles():
    return [coordinate_symbols(f"phi{i}") for i in range(1, 5)]


def _five_bar_hand_eq116(lam):
    s = get_system("five_bar_bird")
    trio = _angles()
    return HAND["five_bar_bird"].eq116_by_hand([t[0] for t in trio], [t[1] for t in trio],
                                               [t[2] for t in trio], lam, s.symbols)


def test_row_space_distance_ignores_row_order_sign_and_scale():
    rng = np.random.default_rng(0)
    J = rng.normal(size=(2, 4))
    T = np.array([[0.0, -3.0], [0.5, 2.0]])  # invertible
    assert row_space_distance(T @ J, J) < 1e-14  # round-off of two SVDs of 2 x 4 matrices
    other = J.copy()
    other[0, 0] += 0.1
    assert row_space_distance(other, J) > 1e-3
    assert row_space_distance(np.vstack([J[0], 2 * J[0]]), J) == 1.0  # rank 1 against 2


def test_five_bar_hand_equations_with_any_multiplier_normalisation_agree():
    """eq116_by_hand (Lagrange on the hand T, V) must agree row by row and as a system,
    whatever the normalisation of the multipliers: lam = T mu with T invertible."""
    s = get_system("five_bar_bird")
    mu = sp.symbols("mu1 mu2", real=True)
    for T in ([[1, 0], [0, 1]], [[0, sp.Rational(5, 2)], [-sp.Rational(2, 5), sp.Rational(3, 10)]]):
        lam = sp.Matrix(T) * sp.Matrix(mu)
        pf = PrintedFormula("hand eq. 116", "eom", _five_bar_hand_eq116(list(lam)),
                            multipliers=mu)
        rows = _multiplier_errata(s, pf, np.random.default_rng(3))
        assert [e.verdict for e in rows] == ["agrees"] * 5, [
            (e.label, e.max_relative_difference) for e in rows]


def test_five_bar_eq116_verdicts():
    """Each printed row is wrong (hand MISPRINTS), and so is the printed system: its
    residual with the best multipliers is far above round-off."""
    by_label = {e.label: e for e in _errata("five_bar_bird")}
    for i in range(1, 5):
        e = by_label[f"Fig. 40, eq. 116, row {i}"]
        assert e.verdict == "misprint" and e.max_relative_difference > 1e-3, e
        # the printed multiplier terms span our constraint forces (eq. 114 is right)
        assert e.details["multiplier_map_residual"] < AGREEMENT
    system = by_label["Fig. 40, eq. 116 (as a system, multipliers fitted)"]
    assert system.verdict == "misprint" and system.max_relative_difference > 1e-3
    for label in ("Fig. 40, eq. 113", "Fig. 40, eq. 114"):
        assert by_label[label].verdict == "agrees", by_label[label]


def test_five_bar_eq116_rows_2_to_4_inherit_eq115():
    """Lagrange's equations (eq. 112 with the multiplier terms of eq. 116) of the printed
    E_c and E_p of eq. 115, worked symbolically here: rows 2, 3, 4 of eq. 116 are exactly
    these (their errors come from eq. 115), row 1 differs by m_c l^2 phi1'' alone."""
    s = get_system("five_bar_bird")
    P = s.symbols
    printed = {pf.label: pf for pf in s.printed(P)}
    T = printed["Fig. 40, eq. 115 (kinetic energy)"].expr
    V = printed["Fig. 40, eq. 115 (potential energy)"].expr
    eq116 = printed["Fig. 40, eq. 116"]
    trio = _angles()
    q, qd, qdd = ([t[k] for t in trio] for k in range(3))
    L = eq116.multipliers
    for i in range(4):
        dT = sp.diff(T, qd[i])
        ddt = sum(sp.diff(dT, x) * v for x, v in zip(q, qd)) + sum(
            sp.diff(dT, v) * a for v, a in zip(qd, qdd))
        lagrange = ddt - sp.diff(T, q[i]) + sp.diff(V, q[i])
        row = eq116.expr[i]
        multiplier_terms = sum(sp.diff(row, x) * x for x in L)
        gap = sp.simplify(sp.expand(row - multiplier_terms - lagrange))
        assert gap == (-P.m_c * P.l**2 * qdd[0] if i == 0 else 0), (i, gap)


def test_five_bar_loop_and_jacobian_by_hand():
    """The hand loop Phi (rows swapped, signed, scaled) and its Jacobian agree; a loop with
    one sign changed, and a rank-deficient Jacobian, are misprints."""
    s = get_system("five_bar_bird")
    P = s.symbols
    p = [t[0] for t in _angles()]
    x, y = HAND["five_bar_bird"].loop_by_hand(p, P)
    rng = np.random.default_rng(5)

    def verdict(kind, expr):
        worst, _, _ = _compare(s, PrintedFormula("hand", kind, expr), rng)
        return worst <= AGREEMENT

    assert verdict("constraint", [-3 * y, x / 2])
    assert not verdict("constraint", [x, y + 2 * P.l * sp.cos(p[1])])  # l cos(phi2) sign
    J = sp.Matrix([x, y]).jacobian(p)
    assert verdict("constraint_jacobian", sp.Matrix([[1, 2], [0, -1]]) * J)
    assert not verdict("constraint_jacobian", sp.Matrix([J[0, :], 2 * J[0, :]]))


def test_slotted_link_slot_force_by_newton():
    """The derived slot force on O against Newton on the solid (hand file), at states
    built here from (y, phi, y', phi'); and the printed F_enllac (§9.7) agrees."""
    s = get_system("slotted_link_spring_damper")
    hand = HAND["slotted_link_spring_damper"]
    rng = np.random.default_rng(11)
    for v in (s.parameter_values(), s.parameter_values({"c": 9.0, "b": 0.4})):
        model = numeric_model(s.id, v)
        phi0 = -np.arccos((v["l"] / v["b"]) ** (1 / 3))
        q, qd, qdd, lam = [], [], [], []
        for _ in range(20):
            y, phi = rng.uniform(-0.1, 0.3), phi0 + rng.uniform(-0.4, 0.4)
            yd, w = rng.uniform(-1, 1), rng.uniform(-2, 2)
            # x = 0 (slot of O), s = y + l tan(phi) (P in both slots)
            q.append([0.0, y, phi, y + v["l"] * np.tan(phi)])
            qd.append([0.0, yd, w, yd + v["l"] * w / np.cos(phi) ** 2])
            a, l_ = model.dynamics(np.array(q[-1]), np.array(qd[-1]), 0.0)
            qdd.append(a)
            lam.append(l_)
        q, qd, qdd, lam = map(np.array, (q, qd, qdd, lam))
        got = model.constraint_forces(q, lam)["slot_O"]
        want = hand.slot_force(v, q, qd, qdd)
        # round-off of the augmented solve (condition ~1e3 here) on forces of ~10 N
        np.testing.assert_allclose(got[:, 0], want, rtol=0, atol=1e-10 * np.abs(want).max())
        np.testing.assert_allclose(got[:, 1], 0, atol=1e-10 * np.abs(want).max())
    (e,) = [e for e in _errata(s.id) if e.kind == "constraint_force"]
    assert e.verdict == "agrees", e


def test_dissipation_power_controls():
    """Hand P_nc of Fig. 38 (hand file: D = c3 theta'^2/2 + (c1 + c2 rho^2) phi1'^2/2, P_nc =
    -2 D) agrees and the same without the belt's rho^2 does not; the printed P_nc of eq. 110
    (Fig. 39) with the motor switched on agrees (not in rolling_disc_track.printed yet)."""
    rng = np.random.default_rng(2)
    belt = get_system("belt_pulleys")
    P = belt.symbols
    thd, p1d = coordinate_symbols("theta")[1], coordinate_symbols("phi1")[1]
    rho = P.r1 / P.r2
    for c2, ok in ((P.c2 * rho**2, True), (P.c2, False)):
        pf = PrintedFormula("hand", "dissipation_power", -P.c3 * thd**2 - (P.c1 + c2) * p1d**2)
        assert (_compare(belt, pf, rng)[0] <= AGREEMENT) is ok

    disc = get_system("rolling_disc_track")
    P = disc.symbols
    thd, phd = coordinate_symbols("theta")[1], coordinate_symbols("phi")[1]
    printed = ((-P.c_O * thd) * thd + (-P.c_J * (thd + phd)) * (thd + phd)
               + P.T_m * sp.sin(P.Omega * TIME) * thd)
    pf = PrintedFormula("Fig. 39, eq. 110, P_nc", "dissipation_power", printed,
                        relations={"T_m": 1.5})  # T_m = 0 by default: switch the motor on
    assert _compare(disc, pf, rng)[0] <= AGREEMENT


def test_new_rows_serialise_and_render():
    """The JSON of `mbfidelity errata --json` keeps its keys (adds `details`), and the
    report's errata page renders the new kinds."""
    from mbfidelity.reports.site import ERRATA, STYLE

    rows = [e.as_dict() for sid in ("five_bar_bird", "slotted_link_spring_damper")
            for e in _errata(sid)]
    for r in rows:
        assert set(Erratum.__dataclass_fields__) == set(r)
    kinds = {r["kind"] for r in rows}
    assert {"constraint", "constraint_jacobian", "constraint_force", "dissipation_power",
            "eom"} <= kinds
    json.dumps(rows)  # plain floats and strings only
    systems: dict = {}
    for r in rows:
        systems.setdefault(r["system"], []).append(r)
    page = ERRATA.render(style=STYLE, systems=systems, pages={},
                         prov={"git_describe": "", "date": ""}, versions={}, counts={},
                         section6=[])
    for label in ("Fig. 40, eq. 113", "Fig. 40, eq. 116 (as a system, multipliers fitted)",
                  "Fig. 36, §9.7 (F_enllac = F_act)", "Fig. 34, eq. 99 (P_nc)"):
        assert label in page


def _hand_eq116_formula():
    """Eq. 116 as Lagrange on the hand T, V gives it, with printed-style multipliers of
    another normalisation (lam = T mu, T invertible): the control of the witnesses."""
    mu = sp.symbols("mu1 mu2", real=True)
    T = sp.Matrix([[0, sp.Rational(5, 2)], [-sp.Rational(2, 5), sp.Rational(3, 10)]])
    lam = T * sp.Matrix(mu)
    return PrintedFormula("hand eq. 116", "eom", _five_bar_hand_eq116(list(lam)),
                          multipliers=mu)


def test_printed_multiplier_model_of_correct_equations_is_the_derived_one():
    """Control of the witness machinery of eq. 116: correct equations with multipliers
    (hand file), integrated on the derived manifold by printed_multiplier_trajectory,
    follow the reference, and their linearization has the derived modes; the printed
    eq. 116 does neither."""
    from mbfidelity.analytic.errata import printed_model_frequencies, printed_multiplier_trajectory
    from mbfidelity.analytic.linear import operating_equilibrium
    from mbfidelity.analytic.reference import reference

    s = get_system("five_bar_bird")
    scenario = s.scenarios[-1]
    values = s.parameter_values(scenario=scenario)
    ref = reference(s, scenario, values, 1e-2, t_end=1.0)
    (printed,) = [pf for pf in s.printed(s.symbols) if pf.multipliers]
    hand = _hand_eq116_formula()
    q, drift = printed_multiplier_trajectory(s, hand, values, ref.q[0], ref.qd[0], ref.t)
    # two DOP853 solves at rtol = atol = 1e-12 of a motion of ~0.5 rad over 1 s
    assert np.max(np.abs(q - ref.q)) < 1e-8 and drift < 1e-10
    q, _ = printed_multiplier_trajectory(s, printed, values, ref.q[0], ref.qd[0], ref.t)
    assert np.max(np.abs(q - ref.q)) > 1e-2

    base = s.parameter_values()
    derived = np.sort([abs(m.eigenvalue) for m in operating_equilibrium(s, base).modes])
    np.testing.assert_allclose(printed_model_frequencies(s, hand, base), derived, rtol=1e-9)
    assert np.max(np.abs(printed_model_frequencies(s, printed, base) / derived - 1)) > 1e-2


def test_five_bar_eq116_engine_witness_sides_with_the_derivation():
    """Every misprint is confirmed by an engine: eq. 116 (the system row and each row cite
    the same witness) has at least one engine whose trajectory, and modes where it
    linearizes, are closer to the derived model than to the printed one."""
    from mbfidelity.comparisons.witnesses import witness
    from mbfidelity.simulators import all_backends

    if not any(b.available()[0] for b in all_backends().values()):
        pytest.skip("no simulation engine installed: no witness of eq. 116")
    s = get_system("five_bar_bird")
    rows = [e for e in _errata(s.id) if e.label.startswith("Fig. 40, eq. 116")]
    assert len(rows) == 5
    for e in rows:
        w = witness(s, e)
        assert w, e.label
        siding = [sim for sim, x in w.items() if x["sides_with"] == "derivation"]
        assert siding, (e.label, w)
        for sim in siding:
            x = w[sim]
            assert x["verdict"].startswith("sides with the derivation")
            assert x["max_error_to_derived"] < 0.1 * x["max_error_to_printed"], (sim, x)


def test_scotch_yoke_potential_derivatives_by_hand():
    """Fig. 14, eq. 50 and 52, worked out here from V(phi) = -m g r sin(phi) + V_cot(l),
    l = h - b - r sin(phi), dV_cot/dl = -F0 cot(pi l / (2 l0)): the hand forms must agree;
    the same forms with the curvature term's sign flipped, or without the chain rule's
    cos(phi), must not."""
    s = get_system("scotch_yoke")
    P = s.symbols
    phi = coordinate_symbols("phi")[0]
    l = P.h - P.b - P.r * sp.sin(phi)
    u = sp.pi * l / (2 * P.l0)
    dV = -P.m * P.g * P.r * sp.cos(phi) + P.F0 * sp.cot(u) * P.r * sp.cos(phi)
    curvature = P.F0 * P.r**2 * sp.cos(phi) ** 2 * sp.pi / (2 * P.l0) / sp.sin(u) ** 2
    d2V = (P.m * P.g - P.F0 * sp.cot(u)) * P.r * sp.sin(phi) + curvature
    rng = np.random.default_rng(4)
    cases = [("potential_gradient", [dV], True),
             ("potential_gradient", [dV / sp.cos(phi)], False),
             ("potential_hessian", sp.Matrix([[d2V]]), True),
             ("potential_hessian", sp.Matrix([[d2V - 2 * curvature]]), False)]
    for kind, expr, ok in cases:
        worst, _, _ = _compare(s, PrintedFormula("hand", kind, expr), rng)
        assert (worst <= AGREEMENT) is ok, (kind, worst)


def test_slot_actuator_equations_rows_cannot_absorb_the_actuator_force():
    """§9.7 (Fig. 36): F_act takes the derived slot force on O (it is not fitted), so row 1
    is a real test: with F_act's sign flipped, row 1 is a misprint and rows 2-3 (without
    F_act) still agree."""
    s = get_system("slotted_link_spring_damper")
    (pf,) = [p for p in s.printed(s.symbols) if p.multipliers]
    F = pf.multipliers[0]
    wrong = PrintedFormula(pf.label, "eom", [pf.expr[0] + 2 * F] + list(pf.expr[1:]),
                           multipliers=pf.multipliers, multiplier_forces=pf.multiplier_forces)
    rows = {e.label: e.verdict for e in _multiplier_errata(s, wrong, np.random.default_rng(2))}
    assert rows[f"{pf.label}, row 1"] == "misprint"
    assert rows[f"{pf.label}, row 2"] == rows[f"{pf.label}, row 3"] == "agrees"
    right = {e.label: e.verdict for e in _multiplier_errata(s, pf, np.random.default_rng(2))}
    assert set(right.values()) == {"agrees"}


@pytest.mark.slow  # all four engines on the rolling disc, residuals at every sample: ~2 min
def test_singular_printed_equations_get_a_residual_witness():
    """Fig. 39: the printed equations of motion have no phi'' in row 2 (singular: they
    cannot be integrated), so the witness puts each engine's motion into both sets of
    equations: an engine's motion must satisfy the derived ones far better."""
    from mbfidelity.comparisons.witnesses import witness
    from mbfidelity.simulators import all_backends

    if not any(b.available()[0] for b in all_backends().values()):
        pytest.skip("no simulation engine installed")
    s = get_system("rolling_disc_track")
    e = next(e for e in _errata(s.id) if e.kind == "eom" and e.verdict == "misprint")
    w = witness(s, e)
    siding = [x for x in w.values() if x["sides_with"] == "derivation"]
    assert siding, w
    for x in siding:
        assert x["derived_relative_residual"] < 0.1 * min(x["printed_relative_residuals"])
