"""Floquet analysis (analytic/floquet.py) against closed forms of the Mathieu equation
x'' + (delta + eps cos t) x = 0 (period 2 pi, the normalisation of monograph eq. 83 with
omega = 1) and the Kapitza criterion for the inverted pendulum with a shaken pivot."""
import numpy as np
import pytest

from mbfidelity.analytic.floquet import classify, floquet, second_order_system


def mathieu(delta: float, eps: float):
    return lambda t: np.array([[0.0, 1.0], [-(delta + eps * np.cos(t)), 0.0]])


def test_constant_coefficients_give_the_exponential():
    # x'' + w^2 x = 0 over T: multipliers exp(+-i w T), on the circle and distinct
    w, T = 1.3, 2 * np.pi
    result = floquet(lambda t: np.array([[0.0, 1.0], [-w * w, 0.0]]), T, 2)
    expected = np.sort_complex(np.exp(np.array([1j, -1j]) * w * T))
    assert np.allclose(np.sort_complex(result.multipliers), expected, atol=1e-10)
    assert result.verdict == "stable"
    assert result.error < 1e-8


# first tongue (delta near 1/4): boundaries delta = 1/4 -+ eps/2 + O(eps^2) (Nayfeh & Mook,
# Nonlinear Oscillations §5.2; the eps^2 term is -eps^2/8 on both). At eps = 0.1 the
# boundaries are 0.20 and 0.30 within 0.0013; the points below sit 0.02 from them.
@pytest.mark.parametrize("delta, verdict", [
    (0.25, "unstable"), (0.22, "unstable"), (0.28, "unstable"),
    (0.18, "stable"), (0.32, "stable")])
def test_mathieu_first_tongue(delta, verdict):
    result = floquet(mathieu(delta, 0.1), 2 * np.pi, 2)
    assert result.verdict == verdict, (delta, result.multipliers, result.error)
    assert abs(np.prod(result.multipliers) - 1.0) < 1e-9  # Liouville: trace of A is 0


def test_mathieu_growth_inside_the_tongue():
    # Landau & Lifshitz, Mechanics §27: x'' + w0^2 (1 + h cos(2 w0 t)) x = 0 grows at most
    # at the rate h w0 / 4. Here w0 = 1/2 and w0^2 h = eps, so the rate is eps/2 + O(eps^2)
    eps = 0.05
    result = floquet(mathieu(0.25, eps), 2 * np.pi, 2)
    assert result.growth_rate == pytest.approx(eps / 2, rel=0.02)


# the transition curve through the origin: delta = -eps^2/2 + O(eps^4) (stable above)
@pytest.mark.parametrize("delta, verdict", [(0.0, "stable"), (-0.01, "unstable")])
def test_mathieu_zeroth_curve(delta, verdict):
    assert floquet(mathieu(delta, 0.1), 2 * np.pi, 2).verdict == verdict


def inverted_pendulum(g: float, length: float, Y: float, W: float):
    """phi from the upward vertical, pivot y = Y cos(W t): the vertical acceleration of
    the pivot adds to gravity, l phi'' = (g + y'') sin(phi), linearized about phi = 0."""
    return lambda t: np.array([[0.0, 1.0],
                               [(g - Y * W * W * np.cos(W * t)) / length, 0.0]])


# Kapitza (Landau & Lifshitz, Mechanics §30): the inverted position is stable to leading
# order in Y/l when Y^2 W^2 > 2 g l. With Y = 0.01 m, W = 2 pi 50: Y^2 W^2 = 9.87 m^2/s^2;
# l = 0.25 m gives a ratio Y^2 W^2 / (2 g l) of 2.0, l = 1 m a ratio of 0.5 (the
# criterion's corrections are O(Y/l) = 0.04 and 0.01, far inside those margins).
@pytest.mark.parametrize("length, verdict", [(0.25, "stable"), (1.0, "unstable")])
def test_kapitza_inverted_pendulum(length, verdict):
    g, Y, W = 9.81, 0.01, 2 * np.pi * 50
    result = floquet(inverted_pendulum(g, length, Y, W), 2 * np.pi / W, 2)
    assert result.verdict == verdict, (result.multipliers, result.error)


def test_kapitza_unstable_rate_matches_the_static_one_without_shaking():
    # Y = 0: phi'' = (g/l) phi, growth rate sqrt(g/l)
    result = floquet(inverted_pendulum(9.81, 0.5, 0.0, 10.0), 2 * np.pi / 10.0, 2)
    assert result.growth_rate == pytest.approx(np.sqrt(9.81 / 0.5), rel=1e-9)


def test_second_order_system_with_damping_decays():
    # q'' + 2 z w q' + w^2 q = 0, written through M, C, K: |mu| = exp(-z w T)
    z, w, T = 0.05, 2.0, 1.0
    A = second_order_system(lambda t: np.eye(1), lambda t: np.array([[2 * z * w]]),
                            lambda t: np.array([[w * w]]))
    result = floquet(A, T, 2)
    assert result.max_abs_multiplier == pytest.approx(np.exp(-z * w * T), rel=1e-9)
    assert result.verdict == "stable" and result.margin > 0


def test_classify_double_multiplier_on_the_circle_is_marginal():
    assert classify(np.array([1.0 + 1e-7, 1.0 - 1e-7]), 1e-6)[0] == "marginal"
    assert classify(np.array([-1.0, -1.0]), 1e-9)[0] == "marginal"
    assert classify(np.array([1.2, 1 / 1.2]), 1e-9) == ("unstable", pytest.approx(0.2))


def test_driven_system_with_constant_coefficients_gives_exp_of_its_matrix():
    # the base-excited block (§8.2): m z'' + c z' + k z = -m y''(t); its variational
    # equations have constant coefficients, so the monodromy is exp(A T), A the companion
    # matrix of (m, c, k) written here from the printed equation
    import scipy.linalg

    from mbfidelity.analytic.floquet import driven_floquet
    from mbfidelity.systems import get_system

    system = get_system("base_excited_msd")
    values = system.parameter_values({"ratio": 1.7})
    m, c, k = values["m"], values["c"], values["k"]
    period = 2 * np.pi / (1.7 * np.sqrt(k / m))
    expected = np.linalg.eigvals(scipy.linalg.expm(
        np.array([[0.0, 1.0], [-k / m, -c / m]]) * period))
    ((q, result),) = driven_floquet(system, values)
    assert result.period == pytest.approx(period, rel=1e-12)
    assert np.allclose(np.sort_complex(result.multipliers), np.sort_complex(expected),
                       atol=1e-9)
    assert result.verdict == "stable"


def test_periodic_growth_rate_reads_a_floquet_solution():
    # x = (1 + 0.3 cos(W t)) exp(sigma t) + the decaying partner exp(-sigma t): the per-period
    # maxima grow by exactly exp(sigma T) once the partner has faded
    from mbfidelity.comparisons.checks.floquet import periodic_growth_rate

    sigma, W = 2.0, 40.0
    T = 2 * np.pi / W
    t = np.arange(0.0, 3.0, 1e-4)
    x = 1e-4 * ((1 + 0.3 * np.cos(W * t)) * np.exp(sigma * t) + np.exp(-sigma * t))
    assert periodic_growth_rate(t, np.abs(x), T, sigma) == pytest.approx(sigma, rel=2e-3)


def test_periodic_growth_rate_needs_linear_periods():
    from mbfidelity.comparisons.checks.floquet import periodic_growth_rate

    t = np.arange(0.0, 1.0, 1e-3)
    assert periodic_growth_rate(t, np.full_like(t, 1.0), 0.1, 1.0) is None  # never linear
