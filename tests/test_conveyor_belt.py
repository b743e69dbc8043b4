"""conveyor_belt (monograph §7.2, Fig. 21-23): every expected value written here from the
printed equation of motion m x'' + c x' + k x - m g sin(alpha) + Ft(v0 + x') = 0 and the
dry-friction facts of sticking (the belt holds the block while the force needed stays
within +-Ft(0+) = +-a0), independently of the derivation and of analytic/sliding.py."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mbfidelity.analytic.linear import find_equilibria, operating_equilibrium
from mbfidelity.analytic.numeric import numeric_model
from mbfidelity.analytic.reference import reference
from mbfidelity.analytic.sliding import (integrate_with_sliding, limit_cycle, model_acceleration,
                                        rate_surfaces)
from mbfidelity.analytic.stability import stability_threshold
from mbfidelity.systems import get_system

SYSTEM = get_system("conveyor_belt")
RNG = np.random.default_rng(72)
PARAMETER_SETS = [SYSTEM.parameter_values()] + [
    SYSTEM.parameter_values({"c": float(RNG.uniform(0.5, 4.0)), "m": float(RNG.uniform(0.5, 4)),
                             "k": float(RNG.uniform(100, 900)), "a2": float(RNG.uniform(5, 15)),
                             "a1": float(RNG.uniform(6, 10))})
    for _ in range(3)]


def _branch(v, slip):
    """Ft on the branch slip > 0."""
    return v["a2"] * slip**2 - v["a1"] * slip + v["a0"]


@pytest.mark.parametrize("v", PARAMETER_SETS)
def test_threshold_is_where_c_plus_dFt_vanishes(v):
    """§7.2: unstable where dFt/dv(v0) < -c; Ft' = 2 a2 v - a1, so v0* = (a1 - c)/(2 a2),
    whatever m and k; stable above it."""
    found = stability_threshold(SYSTEM, v)
    assert found.nearest.value == pytest.approx((v["a1"] - v["c"]) / (2 * v["a2"]), rel=1e-12)
    assert found.nearest.stable_above


@pytest.mark.parametrize("v0, stable", [(0.29, False), (0.31, True)])
def test_rest_state_and_its_stability_fig_22(v0, stable):
    v = SYSTEM.parameter_values({"v0": v0})
    (eq,) = find_equilibria(SYSTEM, v)
    x_eq = (v["m"] * v["g"] * np.sin(v["alpha"]) - _branch(v, v0)) / v["k"]
    assert eq.q[0] == pytest.approx(x_eq, rel=1e-13)
    assert eq.stable is stable
    damping = v["c"] + 2 * v["a2"] * v0 - v["a1"]
    np.testing.assert_allclose(eq.C, [[damping]], rtol=1e-12)
    growth = max(s.real for s in eq.eigenvalues)
    assert growth == pytest.approx(-damping / (2 * v["m"]), rel=1e-10)


def test_printed_rest_position_fig_23():
    """Fig. 23: x_eq = 11.5 mm at v0 = 0.29 m/s (printed to 0.1 mm)."""
    eq = operating_equilibrium(SYSTEM, SYSTEM.parameter_values({"v0": 0.29}))
    assert round(eq.q[0] * 1e3, 1) == 11.5


@pytest.mark.parametrize("v0", [0.30, 0.31])
def test_reference_without_sticking_is_the_smooth_branch(v0):
    """Above the threshold the slip stays positive: the printed equation on its branch
    v > 0, integrated here, is the whole story."""
    v = SYSTEM.parameter_values({"v0": v0})
    sc = SYSTEM.scenario(f"v0_{v0:.2f}".replace(".", "_"))
    ref = reference(SYSTEM, sc, v, 1e-2)
    g_sin = v["m"] * v["g"] * np.sin(v["alpha"])

    def rhs(t, y):
        x, xd = y
        return [xd, (g_sin - v["c"] * xd - v["k"] * x - _branch(v, v0 + xd)) / v["m"]]

    sol = solve_ivp(rhs, (0, ref.t[-1]), [ref.q[0, 0], 0.1], method="DOP853", rtol=1e-12,
                    atol=1e-14, t_eval=ref.t)
    assert np.min(v0 + sol.y[1]) > 0
    np.testing.assert_allclose(ref.q[:, 0], sol.y[0], atol=2e-10)
    assert ref.switches == []


def test_stick_slip_facts_fig_23():
    """v0 = 0.29: the motion grows, then sticks and slips. Every release happens where the
    force needed to hold the block, c v0 + m g sin(alpha) - k x, reaches a0; every stick
    starts with the block at the belt's speed; between them it moves with the belt; the
    cycle repeats; and over one closed cycle the non-conservative forces do no net work
    (the energy returns to its value). Fig. 23: the velocity amplitude settles at about
    0.3 m/s from about 20 s on."""
    v = SYSTEM.parameter_values({"v0": 0.29})
    sc = SYSTEM.scenario("v0_0_29")
    ref = reference(SYSTEM, sc, v, 1e-3)
    v0, k, c, a0 = 0.29, v["k"], v["c"], v["a0"]
    g_sin = v["m"] * v["g"] * np.sin(v["alpha"])
    x_release = (c * v0 + g_sin - a0) / k
    sticks = [s for s in ref.switches if s.kind == "stick"]
    releases = [s for s in ref.switches if s.kind == "slip"]
    assert len(releases) > 20 and 19 < sticks[0].t < 23
    for s in releases:
        assert s.q == pytest.approx(x_release, abs=1e-12)
    for a, b in zip(sticks, releases):
        assert b.t - a.t == pytest.approx((a.q - b.q) / v0, rel=1e-9)
        inside = (ref.t > a.t) & (ref.t < b.t)
        np.testing.assert_allclose(ref.qd[inside, 0], -v0, atol=0)
    periods = np.diff([s.t for s in releases])
    np.testing.assert_allclose(periods, periods[0], rtol=1e-8)
    late = ref.t > 25
    assert 0.28 < (np.max(ref.qd[late, 0]) - np.min(ref.qd[late, 0])) / 2 < 0.31
    # energy balance over the settled cycle from the last release, sampled finely: the
    # trapezoid rule is exact to (h^2) on the smooth arcs and misses at most half a step
    # of the power's jump (2 a0 v0) at each of the two switches
    h = 2e-6
    t = releases[-2].t + np.arange(int((releases[-1].t - releases[-2].t) / h) + 1) * h
    model = numeric_model(SYSTEM.id, v)
    x, xd, _, _ = integrate_with_sliding(model_acceleration(model), releases[-2].q, -v0, t,
                                         -v0, 1e-12)
    slip = v0 + xd
    belt = np.where(slip > 0, _branch(v, np.abs(slip)), -_branch(v, np.abs(slip)))
    stuck = slip == 0
    # while stuck the belt holds the block: its force is whatever balances the rest
    belt[stuck] = g_sin - c * xd[stuck] - k * x[stuck]
    power = -c * xd**2 - belt * xd
    work = np.trapezoid(power, t) - power[-1] * (releases[-1].t - t[-1])
    assert abs(work) < 2 * (2 * a0 * v0) * h
    assert np.trapezoid(c * xd**2, t) > 1e3 * 2 * (2 * a0 * v0) * h


def test_limit_cycle_amplitude_from_the_release_state():
    """The cycle computed from the release state alone (analytic/sliding.limit_cycle)
    equals the settled part of the long reference solve."""
    v = SYSTEM.parameter_values({"v0": 0.29})
    ref = reference(SYSTEM, SYSTEM.scenario("v0_0_29"), v, 1e-3)
    releases = [s for s in ref.switches if s.kind == "slip"]
    model = numeric_model(SYSTEM.id, v)
    surface = rate_surfaces(SYSTEM, v)[0]
    cycle = limit_cycle(model_acceleration(model), surface.rate, releases[0].q, releases[0].t)
    settled = ref.t > releases[0].t
    x = ref.q[settled, 0]
    # sampled extremes at h = 1e-3: within (w h)^2/8 = 3e-5 of the amplitude
    assert (np.max(x) - np.min(x)) / 2 == pytest.approx(cycle.amplitude, rel=3.2e-5)
    assert cycle.period == pytest.approx(np.diff([s.t for s in releases]).mean(), rel=1e-9)
    assert cycle.error < 1e-8 * cycle.amplitude


def test_rate_surface_found_from_the_description():
    v = SYSTEM.parameter_values({"v0": 0.3})
    (surface,) = rate_surfaces(SYSTEM, v)
    assert surface.rate == pytest.approx(-0.3, abs=1e-15)
    assert abs(surface.jump) == pytest.approx(2 * v["a0"], rel=1e-6)
    assert rate_surfaces(get_system("end_stops"), get_system("end_stops").parameter_values()) == []
