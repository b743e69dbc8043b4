"""§6.1, Fig. 17, eq. 62-68: the simply supported beam with a block at a = c l as a chain of
N rigid segments (issue 12): the description against the hand's second derivation
(tests/hand/beam_with_block.py), the exact continuum, the printed Rayleigh estimates, and
the engines' chains and own flexible elements."""
import json
import math

import numpy as np
import pytest
import scipy.integrate
import scipy.optimize
from typer.testing import CliRunner

from mbfidelity.analytic.discretization import discretization_study
from mbfidelity.analytic.reference import consistent_initial_state
from mbfidelity.cli import app
from mbfidelity.systems import beam_with_block, get_system
from mbfidelity.systems.model import Parameter

from hand import facts

SYSTEM_ID = "beam_with_block"


@pytest.fixture(scope="module")
def system():
    return get_system(SYSTEM_ID)


@pytest.mark.parametrize("params", [["N=3"], ["c=0.3"], ["c=0.25", "N=2"], ["c=1"]])
def test_the_block_must_sit_on_a_node_of_the_chain(params):
    """c N must be an integer between 1 and N - 1 (an odd N leaves no node at mid-span, a
    quarter span needs N = 4, 8, ...): refused before any work, in one line, the
    condition checked at the values given (not at the catalog's own N = 4, c = 1/2)."""
    args = ["analyze", SYSTEM_ID]
    for p in params:
        args += ["--param", p]
    res = CliRunner().invoke(app, args)
    assert res.exit_code != 0
    assert "c N must be an integer with 1 <= c N <= N - 1" in res.output


def test_c_moves_the_block_to_its_node(system):
    """c = 1/4 with N = 4: the block on node 1, folded into segment 1 (mass rho l/N + m),
    the others bare; c = 0.3 with N = 10 and c = 3/4 are nodes too. A structural
    parameter: its own id, like N."""
    assert system.parameter_values({"c": 0.3, "N": 10})["c"] == 0.3
    assert system.parameter_values({"c": 0.75})["c"] == 0.75
    quarter = get_system("beam_with_block@N=4,c=0.25")
    assert quarter is system.with_structure({"c": 0.25})
    v = quarter.parameter_values()
    masses = [float(quarter.evaluate(b.mass, v)) for b in quarter.mechanism.bodies]
    h = v["l"] / 4
    assert masses == pytest.approx([v["rho"] * h + v["m"]] + [v["rho"] * h] * 3, rel=1e-15)
    with pytest.raises(ValueError, match="number for its default"):
        Parameter("c", "l/2", "1", "a structural position given by a formula", shapes=True)


def test_analyze_gives_the_continuum_both_rayleigh_estimates_and_the_chains_modes():
    """The issue's acceptance: `analyze --json --param N=...` has the exact continuum
    (9.0394 Hz at the defaults: 1.5708 sqrt(EI/(rho l^4)) for m = 0, §6.1), both printed
    Rayleigh estimates above it, and the chain's modes (those of the hand's chain)."""
    res = CliRunner().invoke(app, ["analyze", SYSTEM_ID, "--json", "--param", "N=6",
                                   "--param", "m=0"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    exact = doc["continuum"]["frequency_hz"]
    assert len(exact) == 3
    assert exact[0] == pytest.approx(math.pi / 2 * math.sqrt(100.0), rel=1e-9)  # pi^2/2pi
    assert [r["label"] for r in doc["rayleigh"]] == ["eq. 66-68", "§6.1, own weight"]
    # §6.1 prints 1.5822 and 1.5719 sqrt(EI/(rho l^4)) for c = 1/2, m = 0
    assert [r["frequency_hz"] / 10.0 for r in doc["rayleigh"]] == pytest.approx(
        [1.5822, 1.5719], abs=5e-5)
    assert all(r["relative_error"] > 0 for r in doc["rayleigh"])  # upper bounds
    v = get_system(SYSTEM_ID).parameter_values({"N": 6, "m": 0.0})
    hand = np.asarray(facts()[SYSTEM_ID].frequencies(v)) / (2 * math.pi)  # rad/s
    assert [m["frequency_hz"] for m in doc["modes"]] == pytest.approx(hand[:len(doc["modes"])],
                                                                      rel=1e-9)


def _receptance_frequencies(v, count: int, terms: int = 20000) -> list[float]:
    """The beam with the block by another route than the continuum's matching determinant:
    the bare simply supported beam's modes sin(n pi x / l) (w_n = (n pi / l)^2 sqrt(EI/rho),
    modal mass rho l / 2) give its receptance at x = a, and the block closes it:
    1 = m w^2 sum_n (2 / (rho l)) sin^2(n pi c) / (w_n^2 - w^2). One root between
    consecutive w_n (none where sin(n pi c) = 0: a bare mode with a node at the block is
    a mode of both, left out here). The series' tail beyond `terms` is below terms^-3 of
    its sum; Brent's method refines each root to 1e-14."""
    EI, rho, l, m, c = v["EI"], v["rho"], v["l"], v["m"], v["c"]
    n = np.arange(1, terms + 1)
    bare = (n * math.pi / l) ** 2 * math.sqrt(EI / rho)
    share = 2 / (rho * l) * np.sin(n * math.pi * c) ** 2

    def closure(w):
        return 1 - m * w**2 * np.sum(share / (bare**2 - w**2))

    roots, low = [], 0.0
    for high in bare:
        a, b = low + 1e-9 * high, high * (1 - 1e-12)
        if closure(a) * closure(b) < 0:
            roots.append(scipy.optimize.brentq(closure, a, b, xtol=1e-14, rtol=1e-15))
        low = high
        if len(roots) == count:
            return roots
    raise AssertionError("too few roots")


def _rayleigh_quotient(v, moment, deflection) -> float:
    """w^2 = integral M^2 / EI / (integral rho y^2 + m y(a)^2) for a static shape y with
    its bending moment M (pinned ends), by quadrature split at the block."""
    EI, rho, l, m, a = v["EI"], v["rho"], v["l"], v["m"], v["c"] * v["l"]
    quad = lambda f: sum(scipy.integrate.quad(f, x0, x1, epsabs=0, epsrel=1e-13)[0]
                         for x0, x1 in ((0, a), (a, l)))
    strain = quad(lambda x: moment(x) ** 2 / EI)
    inertia = quad(lambda x: rho * deflection(x) ** 2) + m * deflection(a) ** 2
    return math.sqrt(strain / inertia)


def test_analyze_at_a_quarter_span_gives_that_continuum_and_rayleighs_estimates():
    """The issue's acceptance: `analyze --param c=0.25 --json` gives the continuum of the
    block at a quarter span, checked against the receptance route (`_receptance_
    frequencies`, exact to 1e-13); the printed Rayleigh estimates (eq. 66-68 and the
    own-weight shape) against their quotients computed here by quadrature from the
    textbook's static shapes (a load F at a, b = l - a: y = F b x (l^2 - b^2 - x^2) /
    (6 EI l) left of it, M = F b x / l; a uniform q: y = q x (l^3 - 2 l x^2 + x^3) /
    (24 EI), M = q x (l - x) / 2: Gere, Mechanics of Materials, deflection tables), both
    above the exact frequency; and the chain of N = 4 with its block on node 1 against
    the hand's chain (tests/hand/beam_with_block.py)."""
    res = CliRunner().invoke(app, ["analyze", SYSTEM_ID, "--json", "--param", "c=0.25"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    v = get_system(SYSTEM_ID).parameter_values({"c": 0.25})
    exact = np.asarray(doc["continuum"]["frequency_hz"]) * 2 * math.pi
    assert exact == pytest.approx(_receptance_frequencies(v, 3), rel=1e-9)
    l, a = v["l"], v["c"] * v["l"]
    b = l - a
    point_load = _rayleigh_quotient(
        v, lambda x: b * x / l if x <= a else a * (l - x) / l,
        lambda x: (b * x * (l**2 - b**2 - x**2) if x <= a
                   else a * (l - x) * (l**2 - a**2 - (l - x) ** 2)) / (6 * v["EI"] * l))
    own_weight = _rayleigh_quotient(
        v, lambda x: x * (l - x) / 2,
        lambda x: x * (l**3 - 2 * l * x**2 + x**3) / (24 * v["EI"]))
    estimates = [r["frequency_hz"] * 2 * math.pi for r in doc["rayleigh"]]
    assert estimates == pytest.approx([point_load, own_weight], rel=1e-9)
    assert all(r["relative_error"] > 0 for r in doc["rayleigh"])  # upper bounds
    hand = np.asarray(facts()[SYSTEM_ID].frequencies(v)) / (2 * math.pi)
    assert [m["frequency_hz"] for m in doc["modes"]] == pytest.approx(hand, rel=1e-9)
    assert doc["continuum"]["discretization"]["frequency_hz"] == pytest.approx(hand, rel=1e-9)


@pytest.mark.parametrize("c", [0.25, 0.75, 0.125])
def test_without_the_block_its_position_changes_nothing(c):
    """m = 0: the continuum is the bare beam, (n pi)^2 sqrt(EI / (rho l^4)) whatever c."""
    from mbfidelity.analytic.continuum import continuum_summary

    v = get_system(SYSTEM_ID).parameter_values({"c": c, "m": 0.0, "N": 8})
    got = continuum_summary("beam_with_point_mass", v).frequency_hz
    unit = math.sqrt(v["EI"] / (v["rho"] * v["l"] ** 4)) / (2 * math.pi)
    assert got == pytest.approx([(n * math.pi) ** 2 * unit for n in (1, 2, 3)], rel=1e-9)


def test_the_chain_converges_to_the_continuum_at_second_order(system):
    """The hinge springs EI/h concentrate the curvature at the nodes: a central-difference
    discretization of EI y'''' (second order), so the first frequency's error falls as
    N^-2, here from below (the chain is softer than the beam). Successive orders for
    N = 2, 4, 8 within 0.2 of 2: the next term of the error is smaller by O(N^-2), which
    shifts the order estimated from N = 2 and 4 by about that much."""
    study = discretization_study(system, system.parameter_values(), [2, 4, 8], modes=1)
    errors = [row.relative_error[0] for row in study.rows]
    assert all(e < 0 for e in errors)
    orders = [math.log2(errors[i] / errors[i + 1]) for i in range(2)]
    assert orders == pytest.approx([2.0, 2.0], abs=0.2)


def test_off_mid_span_the_chain_converges_to_that_continuum_at_second_order(system):
    """The block at a quarter span (N = 4 and 8 have a node there): the chain's first
    frequency approaches the continuum of the same c from below, its error falling by 4
    when N doubles (order 2 within 0.2, as at mid-span)."""
    values = system.parameter_values({"c": 0.25})
    study = discretization_study(system, values, [4, 8], modes=1)
    errors = [row.relative_error[0] for row in study.rows]
    assert all(e < 0 for e in errors)
    assert math.log2(errors[0] / errors[1]) == pytest.approx(2.0, abs=0.2)


@pytest.mark.parametrize("c", [0.5, 0.25])
def test_the_release_starts_on_the_static_deflection_under_the_block(system, c):
    """The 'released' scenario: the block's node m g a^2 b^2 / (3 EI l) below the
    supports' line (eq. 64; m g l^3 / (48 EI) at a = l/2), the roller's end on y = 0,
    from rest."""
    sc = next(s for s in system.scenarios if s.name == "released")
    v = system.parameter_values({"c": c}, scenario=sc)
    built = system.with_structure(v)
    q0, qd0 = consistent_initial_state(built, sc, v)
    h = v["l"] / v["N"]
    th = np.asarray(q0)
    y_nodes = np.concatenate([[0.0], np.cumsum(h * np.sin(th))])
    a = c * v["l"]
    b = v["l"] - a
    assert -y_nodes[round(c * v["N"])] == pytest.approx(
        v["m"] * v["g"] * a**2 * b**2 / (3 * v["EI"] * v["l"]), rel=1e-12)
    assert abs(y_nodes[-1]) < 1e-12
    assert np.all(np.asarray(qd0) == 0)


def test_discretization_sets_each_engines_chain_and_own_elements_beside_the_exact_beam(
        tmp_path):
    """Issue 12 item 4: `discretization --sim` gives, for each N, the engine's chain against
    the derived one (its linearization gate) and against the continuum, and the engine's
    own flexible elements (Exudyn's ANCF cable and geometrically exact beam) on the same
    axes, each converging toward the exact value."""
    res = CliRunner().invoke(app, ["discretization", SYSTEM_ID, "--counts", "2,4",
                                   "--sim", "exudyn", "--out", str(tmp_path), "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    rows = doc["engines"]["exudyn"]["rows"]
    assert [r["N"] for r in rows] == [2, 4] and all(r["passed"] for r in rows)
    kinds = {x["kind"]: x for x in doc["flexible"]["series"] if x["simulator"] == "exudyn"}
    assert kinds, "Exudyn declares flexible elements"
    for x in kinds.values():
        if x["unsupported"]:
            continue
        errors = [abs(p["relative_error"][0]) for p in x["points"] if "relative_error" in p]
        assert errors and errors[-1] < errors[0] < 0.3
    assert (tmp_path / "discretization-beam_with_block.png").stat().st_size > 0


def test_the_soft_roller_is_judged_where_its_floor_is_below_the_gate(system):
    """MuJoCo's soft roller implies a backend-wide expected failure of trajectories
    (simulators/mujoco_mjcf.py SOFT_EQUALITY, 1e-6 to 1e-5); the beam's release gate is
    wider, so the system declares those metrics "judged": a pass passes, a failure still
    fails (not an expected failure), and the backend's declaration covers none of them."""
    from mbfidelity.comparisons.runner import _judge, expectation_for, expectations

    name = "released.trajectory_max"
    assert expectation_for(system, "mujoco", name).kind == "judged"
    backend_groups = [g for g in expectations(system, "mujoco")
                      if any(e.metric == "*.trajectory_*" and e.kind == "xfail" for e in g)]
    assert backend_groups, "MuJoCo declares its soft equalities' expected failures"
    assert _judge(system, "mujoco", name, 1e-3, 9e-3).status == "pass"
    assert _judge(system, "mujoco", name, 2e-2, 9e-3).status == "fail"
    with pytest.raises(ValueError, match="expectation kind"):
        type(expectation_for(system, "mujoco", name))("mujoco", name, "judge", "typo")


@pytest.mark.parametrize("N", [2, 4, 8])
def test_without_the_block_the_chain_is_the_hand_closed_form_of_fourth_order(N):
    """m = 0 and (nearly) no gravity: the derived chain's modes are the hand's closed form
    (tests/hand/beam_with_block.py `bare_chain_frequency`, any N) to 1e-9 (g = 1e-6 leaves
    a sag of 1e-8 rad whose geometric effect is of its square); their error against the
    continuum, w_k (k pi/l)^2 sqrt(EI/rho), is then -(k pi/N)^4/1440 at leading order
    (fourth order: the block at mid-span brings the second order back, for the modes that
    move it)."""
    hand = facts()[SYSTEM_ID]
    res = CliRunner().invoke(app, ["analyze", SYSTEM_ID, "--json", "--param", f"N={N}",
                                   "--param", "m=0", "--param", "g=1e-6"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    v = get_system(SYSTEM_ID).parameter_values({"N": N, "m": 0.0, "g": 1e-6})
    got = [m["frequency_hz"] * 2 * math.pi for m in doc["modes"]]
    assert len(got) == N - 1
    expected = [hand.bare_chain_frequency(v, k) for k in range(1, N)]
    assert got == pytest.approx(expected, rel=1e-9)
    for k, w in enumerate(expected, start=1):
        phi = k * math.pi / N
        if phi > math.pi / 4:
            continue  # the expansion below is asymptotic: modes with 8 nodes or more
        exact = (k * math.pi / v["l"]) ** 2 * math.sqrt(v["EI"] / v["rho"])
        # the series (SymPy): 1 - phi^4/1440 - phi^6/6048 - 19 phi^8/1382400 - ...; the
        # third term's coefficient relative to the first, 19 * 1440 / 1382400 = 0.0198,
        # doubled for the rest at phi <= pi/4
        ratio = (w / exact - 1) / (-phi**4 / 1440)
        assert ratio - 1 == pytest.approx(1440 / 6048 * phi**2, abs=0.04 * phi**4)


def test_a_declaration_may_hold_for_some_block_masses_only(system):
    """`Expectation.when` may name any parameter: Exudyn's release bound on the beam
    resolves from m = 0.95 up (measured: 0.096 at 0.95, 0.101 at 0.94), so its declaration
    applies below that mass only, evaluated at the values of the comparison under way."""
    from mbfidelity.comparisons import runner

    [declared] = [e for e in system.expectations if e.simulator == "exudyn"
                  and e.reason == beam_with_block.SECOND_ORDER_RELEASE_BOUND_LIGHT_BLOCK]
    assert declared.applies(system.structure, {"m": 0.0})
    assert not declared.applies(system.structure, {"m": 1.0})

    def exudyn_release_declared(values):
        token = runner._COMPARED_VALUES.set(values)
        try:
            return any(g[0] is declared for g in runner.expectations(system, "exudyn"))
        finally:
            runner._COMPARED_VALUES.reset(token)

    assert exudyn_release_declared(system.parameter_values({"m": 0.0}))
    assert not exudyn_release_declared(system.parameter_values())  # m = 1
    assert not exudyn_release_declared(None)  # outside a comparison: the defaults


@pytest.mark.parametrize("engine", ["exudyn", "pybullet", "pymunk"])
def test_the_off_centre_release_is_declared_off_mid_span_only(system, engine):
    """The release off mid-span excites the antisymmetric and fast modes the symmetric
    one leaves at rest: declared unresolved for the engines whose bound it exceeds, at
    any c but 1/2 (the structure of the chain built for that c)."""
    [declared] = [e for e in system.expectations if e.simulator == engine
                  and e.reason == beam_with_block.OFF_CENTRE_RELEASE_EXCITES_THE_FAST_MODES]
    for c, off in ((0.5, False), (0.25, True), (0.75, True), (7 / 16, True)):
        values = system.parameter_values({"c": c, "N": 16 if c == 7 / 16 else 4})
        assert declared.applies(system.with_structure(values).structure, values) is off


def test_mujocos_block_near_the_roller_declarations_hold_there_only(system):
    """MuJoCo's mirrored release is judged, and its soft roller's floor on the fastest
    mode's fit declared, with the block nearer the roller (c > 1/2) only: at c = 1/4 and
    1/2 the backend-wide declarations stand."""
    mine = [e for e in system.expectations if e.simulator == "mujoco" and e.reason in (
        beam_with_block.MIRROR_RELEASE_JUDGED_BLOCK_NEAR_THE_ROLLER,
        beam_with_block.SOFT_ROLLER_FLOOR_FASTEST_MODE_FIT)]
    assert len(mine) == 2
    for c, near in ((0.25, False), (0.5, False), (0.75, True)):
        values = system.parameter_values({"c": c})
        structure = system.with_structure(values).structure
        assert all(e.applies(structure, values) is near for e in mine)
