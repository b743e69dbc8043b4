"""The exact continuum frequencies (analytic/continuum.py) against independent results:
the bare beam's pi^2 n^2 sqrt(EI/(rho l^4)), the massless beam with a mass (stiffness
3 EI l / (a^2 b^2)) plus Rayleigh's 17/35 of the beam mass at mid-span, a sine-series
Ritz model of the beam written here, and the spring's free-rod and light-spring limits."""
import math

import numpy as np
import pytest
import scipy.linalg

from mbfidelity.analytic.continuum import (
    beam_with_point_mass_frequencies,
    spring_with_end_mass_frequencies,
)

EI, RHO, L = 2.5e3, 7.8, 1.3


@pytest.mark.parametrize("c", [0.5, 0.3, 0.77])
def test_beam_without_mass_is_the_simply_supported_beam(c):
    w = beam_with_point_mass_frequencies(EI, RHO, L, 0.0, c * L)
    w1 = math.pi**2 * math.sqrt(EI / (RHO * L**4))
    for n, value in enumerate(w, start=1):
        assert value == pytest.approx(n**2 * w1, rel=1e-9)


def test_heavy_mass_at_mid_span_is_the_massless_beam_with_rayleigh_mass():
    """m >> rho l: w^2 = k_s / (m + 17/35 rho l) up to O((rho l/m)^2), with the massless
    beam's stiffness k_s = 3 EI l / (a^2 b^2) = 48 EI / l^3 at a = l/2."""
    ratio = 1e-4
    m = RHO * L / ratio
    k_s = 3 * EI * L / ((L / 2) ** 2 * (L / 2) ** 2)
    assert k_s == pytest.approx(48 * EI / L**3)
    w = beam_with_point_mass_frequencies(EI, RHO, L, m, L / 2, count=1)[0]
    assert w == pytest.approx(math.sqrt(k_s / m), rel=ratio)
    assert w == pytest.approx(math.sqrt(k_s / (m + 17 / 35 * RHO * L)), rel=1e-7)


def test_heavy_mass_off_centre_tends_to_the_massless_beam():
    ratio, a = 1e-6, 0.3 * L
    m = RHO * L / ratio
    k_s = 3 * EI * L / (a**2 * (L - a) ** 2)
    w = beam_with_point_mass_frequencies(EI, RHO, L, m, a, count=1)[0]
    assert w == pytest.approx(math.sqrt(k_s / m), rel=1e-6)


def _ritz_sine_series(m: float, a: float, terms: int) -> np.ndarray:
    """Ritz model on the beam's own modes sin(j pi x / l): an upper bound converging to
    the exact frequencies, independent of the matching-conditions determinant."""
    j = np.arange(1, terms + 1)
    stiffness = EI * (j * math.pi / L) ** 4 * L / 2
    shape_at_mass = np.sin(j * math.pi * a / L)
    # in coordinates scaled to unit modal stiffness the lowest frequencies are the largest
    # eigenvalues 1/w^2 of the scaled mass matrix: well conditioned for many terms
    scaled_shape = shape_at_mass / np.sqrt(stiffness)
    scaled_mass = np.diag(RHO * L / 2 / stiffness) + m * np.outer(scaled_shape, scaled_shape)
    inverse_squares = scipy.linalg.eigh(scaled_mass, eigvals_only=True, subset_by_index=[terms - 3, terms - 1])
    return np.sort(1 / np.sqrt(inverse_squares))


@pytest.mark.parametrize("c, mass_ratio", [(0.5, 1.0), (0.3, 0.4), (0.77, 3.0), (0.5, 20.0)])
def test_beam_with_mass_agrees_with_a_sine_series_ritz_model(c, mass_ratio):
    m, a = mass_ratio * RHO * L, c * L
    exact = np.array(beam_with_point_mass_frequencies(EI, RHO, L, m, a))
    ritz = _ritz_sine_series(m, a, terms=600)
    assert np.all(ritz >= exact * (1 - 1e-10))  # Ritz is an upper bound
    np.testing.assert_allclose(exact, ritz, rtol=1e-8)


def test_mass_at_a_node_leaves_that_mode_alone():
    """At mid-span the antisymmetric second mode has a node under the mass."""
    w = beam_with_point_mass_frequencies(EI, RHO, L, 5 * RHO * L, L / 2)
    assert w[1] == pytest.approx(4 * math.pi**2 * math.sqrt(EI / (RHO * L**4)), rel=1e-9)


K, SPRING_MASS = 400.0, 0.2


def test_massless_end_is_the_free_rod():
    w = spring_with_end_mass_frequencies(K, SPRING_MASS, 0.0)
    for n, value in enumerate(w, start=1):
        assert value == pytest.approx((2 * n - 1) * math.pi / 2 * math.sqrt(K / SPRING_MASS), rel=1e-12)


@pytest.mark.parametrize("ratio", [1e-2, 1e-3])
def test_light_spring_adds_a_third_of_its_mass(ratio):
    """beta tan beta = r expands as x + x^2/3 + 2 x^3/15 = r (x = beta^2), so
    x = r - r^2/3 + 4 r^3/45 while k/(m + M_s/3) gives r - r^2/3 + r^3/9: the relative
    error of w^2 is r^2/45 at leading order."""
    m = SPRING_MASS / ratio
    w = spring_with_end_mass_frequencies(K, SPRING_MASS, m, count=1)[0]
    approx = K / (m + SPRING_MASS / 3)
    relative_error = (approx - w**2) / w**2
    assert relative_error == pytest.approx(ratio**2 / 45, rel=5 * ratio)


def test_spring_roots_satisfy_the_frequency_equation():
    m = 0.35
    for w in spring_with_end_mass_frequencies(K, SPRING_MASS, m):
        beta = w / math.sqrt(K / SPRING_MASS)
        assert beta * math.tan(beta) == pytest.approx(SPRING_MASS / m, rel=1e-9)


# Rayleigh's estimates of §6.1 (eq. 67-68 with the shape of eq. 66, then with the
# uniform-load shape) and §6.2 (eq. 69-70), written here from the monograph's formulas,
# compared with the exact continuum: Rayleigh's quotient is an upper bound.

def _rayleigh_point_load_shape(m, c):
    stiffness = 3 * EI / ((1 - c) ** 2 * c**2 * L**3)
    mass = m + (2 + 4 * c - c**2 - 6 * c**3 + 3 * c**4) / (105 * (1 - c) ** 2 * c**2) * RHO * L
    return math.sqrt(stiffness / mass)


def _rayleigh_uniform_load_shape(m, c):
    shape_at_mass = c - 2 * c**3 + c**4
    stiffness = 24 * EI / (5 * shape_at_mass**2 * L**3)
    mass = m + 31 / (630 * shape_at_mass**2) * RHO * L
    return math.sqrt(stiffness / mass)


def test_printed_values_at_mid_span_without_block():
    """§6.1 prints f = 1.5822, 1.5719 (the two shapes) and 1.5708 (exact) times
    sqrt(EI/(rho l^4)) for c = 0.5, m = 0."""
    unit = math.sqrt(EI / (RHO * L**4))
    exact = beam_with_point_mass_frequencies(EI, RHO, L, 0.0, L / 2, count=1)[0] / (2 * math.pi)
    assert exact / unit == pytest.approx(1.5708, abs=5e-5)
    assert _rayleigh_point_load_shape(0.0, 0.5) / (2 * math.pi) / unit == pytest.approx(1.5822, abs=5e-5)
    assert _rayleigh_uniform_load_shape(0.0, 0.5) / (2 * math.pi) / unit == pytest.approx(1.5719, abs=5e-5)


@pytest.mark.parametrize("c", [0.5, 0.3, 0.15])
def test_rayleigh_estimates_bound_the_exact_beam_frequency_from_above(c):
    """Both estimates lie above the exact first frequency. The point-load static shape
    becomes the first mode as the block dominates, so its excess shrinks as m grows; the
    uniform-load shape is the static shape of the bare beam, best without the block."""
    point_excess, uniform_excess = [], []
    for mass_ratio in (0.0, 0.2, 1.0, 5.0):
        m = mass_ratio * RHO * L
        exact = beam_with_point_mass_frequencies(EI, RHO, L, m, c * L, count=1)[0]
        point, uniform = _rayleigh_point_load_shape(m, c), _rayleigh_uniform_load_shape(m, c)
        assert point >= exact * (1 - 1e-12) and uniform >= exact * (1 - 1e-12)
        point_excess.append(point / exact - 1)
        uniform_excess.append(uniform / exact - 1)
    assert point_excess == sorted(point_excess, reverse=True)
    assert uniform_excess[0] == min(uniform_excess)


def test_rayleigh_estimate_of_the_massive_spring_bounds_the_exact_frequency():
    """§6.2 eq. 70: w = sqrt(k / (m + rho l / 3)) with the linear shape of eq. 69, the
    static shape under an end load: above the exact value, the more so the heavier the
    spring relative to the block."""
    excess = []
    for mass_ratio in (0.05, 0.5, 2.0):
        m = SPRING_MASS / mass_ratio
        exact = spring_with_end_mass_frequencies(K, SPRING_MASS, m, count=1)[0]
        estimate = math.sqrt(K / (m + SPRING_MASS / 3))
        assert estimate >= exact * (1 - 1e-12)
        excess.append(estimate / exact - 1)
    assert excess == sorted(excess)


def test_printed_rayleigh_coefficients_of_section_6_are_the_integrals_of_their_shapes():
    """Errata check of §6.1 eq. 62-68 and §6.2 eq. 69-70, derived here by integration
    (SymPy) for any block position c = a/l: the static deflection under a load at a
    (eq. 63 at x = a, eq. 66 on both sides) gives the printed reduced mass (eq. 67) and
    stiffness (eq. 68, equal to eq. 65); the uniform-load shape gives 31/630 and 24/5 over
    (c - 2c^3 + c^4)^2; the spring's linear shape (eq. 69) gives a third of its mass
    (eq. 70). No misprint: each printed coefficient is the integral, identically in c."""
    import sympy as sp

    x, l, a, c, EI, F = sp.symbols("x l a c EI F", positive=True)
    b = l - a
    # the load-point shape from the beam's own static solution (F at a, pinned ends),
    # not from eq. 66: y = F b x (l^2 - b^2 - x^2) / (6 EI l) left of the load
    left = F * b * x * (l**2 - b**2 - x**2) / (6 * EI * l)
    right = F * a * (l - x) * (2 * l * x - x**2 - a**2) / (6 * EI * l)
    y_a = left.subs(x, a)
    assert sp.simplify(y_a - F * b**2 * a**2 / (3 * EI * l)) == 0  # eq. 64's z_a
    assert sp.simplify(right.subs(x, a) - y_a) == 0
    assert sp.simplify(sp.diff(left, x).subs(x, a) - sp.diff(right, x).subs(x, a)) == 0
    w_left, w_right = sp.simplify(left / y_a), sp.simplify(right / y_a)
    assert sp.simplify(w_left - x * (2 * l * a - a**2 - x**2) / (2 * (l - a) * a**2)) == 0
    assert sp.simplify(w_right - (l - x) * (2 * l * x - a**2 - x**2)
                       / (2 * (l - a) ** 2 * a)) == 0  # eq. 66 as printed
    mass = (sp.integrate(w_left**2, (x, 0, a)) + sp.integrate(w_right**2, (x, a, l))) / l
    stiffness = (sp.integrate(sp.diff(w_left, x, 2) ** 2, (x, 0, a))
                 + sp.integrate(sp.diff(w_right, x, 2) ** 2, (x, a, l)))
    printed_mass = (2 + 4 * c - c**2 - 6 * c**3 + 3 * c**4) / (105 * (1 - c) ** 2 * c**2)
    assert sp.simplify(mass.subs(a, c * l) - printed_mass) == 0  # eq. 67
    assert sp.simplify(stiffness.subs(a, c * l) - 3 / ((1 - c) ** 2 * c**2 * l**3)) == 0
    assert printed_mass.subs(c, sp.Rational(1, 2)) == sp.Rational(17, 35)  # "0,4857"
    # the uniform-load shape, from EI y'''' = rho g with pinned ends
    u = x / l
    uniform = (u - 2 * u**3 + u**4) / (c - 2 * c**3 + c**4)
    assert sp.simplify(sp.diff(uniform, x, 4) * l**4 * (c - 2 * c**3 + c**4) - 24) == 0
    assert [sp.simplify(uniform.subs(x, 0)), sp.simplify(uniform.subs(x, l)),
            sp.simplify(sp.diff(uniform, x, 2).subs(x, 0)),
            sp.simplify(sp.diff(uniform, x, 2).subs(x, l))] == [0, 0, 0, 0]
    s = c - 2 * c**3 + c**4
    assert sp.simplify(sp.integrate(uniform**2, (x, 0, l)) / l - sp.Rational(31, 630) / s**2) == 0
    assert sp.simplify(sp.integrate(sp.diff(uniform, x, 2) ** 2, (x, 0, l))
                       - sp.Rational(24, 5) / (s**2 * l**3)) == 0
    # §6.2: the spring's shape x/l (eq. 69) reduces its mass to a third (eq. 70)
    assert sp.integrate((x / l) ** 2, (x, 0, l)) / l == sp.Rational(1, 3)
