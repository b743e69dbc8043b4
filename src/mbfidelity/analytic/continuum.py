"""Exact natural frequencies of the two continua of the monograph's chapter on distributed
parameters, for comparison with Rayleigh's estimates (§6.1 eq. 62-68, §6.2 eq. 69-70) and
with discretized models.

(a) A simply supported Euler-Bernoulli beam (bending stiffness EI, mass per length rho,
length l) carrying a point mass m at x = a (§6.1, Fig. 17). On each side of the mass a
mode shape that satisfies y = y'' = 0 at its support is A sin(k x) + B sinh(k x), with
k^4 = rho w^2 / EI (x measured from the left support on the left, from the right support
on the right). At x = a: y, y' and y'' are continuous and the shear force jumps by the
inertia of the mass, EI (y'''(a+) - y'''(a-)) = m w^2 y(a). The four conditions make a
4x4 homogeneous system whose determinant vanishes at the natural frequencies.

(b) A spring (rod) of stiffness k and distributed mass M_s = rho l, fixed at one end and
carrying a mass m at the other (§6.2, Fig. 18): the axial modes give beta tan(beta) = M_s/m
with w = beta sqrt(k / M_s).

Roots are bracketed by sign changes on a fine scan in the dimensionless wavenumber and
refined with Brent's method; every scan has a hard bound and raises when it is hit.
"""
from __future__ import annotations

import math

import numpy as np
import scipy.optimize

#: scan step in the dimensionless wavenumber, as a fraction of pi: well below the spacing
#: of consecutive roots (which is at least about pi/2 for both continua)
_SCAN_STEP = math.pi / 256
#: the scans stop (and raise) past this many multiples of pi
_SCAN_LIMIT_PI = 200


def _beam_determinant(lam: float, c: float, mass_ratio: float) -> float:
    """Determinant of the matching conditions at the mass, for dimensionless wavenumber
    lam = k l, mass position c = a / l and mass ratio m / (rho l). The sinh/cosh columns
    are divided by cosh so that the entries stay bounded at large lam (same zeros)."""
    ka, kb = lam * c, lam * (1.0 - c)
    sa, ca_ = math.sin(ka), math.cos(ka)
    sb, cb = math.sin(kb), math.cos(kb)
    tha, thb = math.tanh(ka), math.tanh(kb)
    inertia = mass_ratio * lam
    # unknowns: A, B/cosh(ka) on the left, C, D/cosh(kb) on the right
    matrix = np.array(
        [
            [sa, tha, -sb, -thb],                      # y continuous
            [ca_, 1.0, cb, 1.0],                       # y' continuous (dx = -ds on the right)
            [-sa, tha, sb, -thb],                      # y'' continuous
            [ca_ - inertia * sa, -1.0 - inertia * tha, cb, -1.0],  # shear jump m w^2 y(a)
        ]
    )
    return float(np.linalg.det(matrix))


def _first_roots(function, count: int, start: float) -> list[float]:
    """The first `count` roots of `function` above `start`, by sign changes on a scan of
    step _SCAN_STEP, refined to 1e-13 relative."""
    roots: list[float] = []
    left = start
    f_left = function(left)
    steps = int(_SCAN_LIMIT_PI * math.pi / _SCAN_STEP)
    for _ in range(steps):
        right = left + _SCAN_STEP
        f_right = function(right)
        if f_left == 0.0:
            roots.append(left)
        elif f_left * f_right < 0.0:
            roots.append(scipy.optimize.brentq(function, left, right, xtol=1e-14, rtol=1e-13, maxiter=200))
        if len(roots) == count:
            return roots
        left, f_left = right, f_right
    raise RuntimeError(f"only {len(roots)} of {count} roots found below {_SCAN_LIMIT_PI} pi")


def beam_with_point_mass_wavenumbers(c: float, mass_ratio: float, count: int = 3) -> list[float]:
    """The first `count` dimensionless wavenumbers k l of a simply supported beam with a
    point mass of m = mass_ratio * rho l at a = c l (0 < c < 1)."""
    if not 0.0 < c < 1.0:
        raise ValueError(f"the mass must lie between the supports: c = {c}")
    if mass_ratio < 0.0:
        raise ValueError(f"negative mass ratio {mass_ratio}")
    return _first_roots(lambda lam: _beam_determinant(lam, c, mass_ratio), count, start=_SCAN_STEP / 2)


def beam_with_point_mass_frequencies(EI: float, rho: float, l: float, m: float, a: float,
                                     count: int = 3) -> list[float]:
    """The first `count` natural angular frequencies (rad/s) of a simply supported beam
    (bending stiffness EI, mass per length rho, length l) with a point mass m at x = a:
    w = (k l)^2 sqrt(EI / (rho l^4))."""
    wavenumbers = beam_with_point_mass_wavenumbers(a / l, m / (rho * l), count)
    return [lam**2 * math.sqrt(EI / (rho * l**4)) for lam in wavenumbers]


def spring_with_end_mass_betas(mass_ratio: float, count: int = 3) -> list[float]:
    """The first `count` roots beta of beta tan(beta) = mass_ratio (= M_s / m, spring mass
    over end mass). The n-th root lies in ((n-1) pi, (n-1) pi + pi/2); it is the root of
    beta sin(beta) - mass_ratio cos(beta), which has no poles."""
    if mass_ratio <= 0.0:
        raise ValueError(f"the spring mass ratio must be positive: {mass_ratio}")
    roots = []
    for n in range(count):
        low, high = n * math.pi, n * math.pi + math.pi / 2
        function = lambda beta: beta * math.sin(beta) - mass_ratio * math.cos(beta)
        if n == 0:
            low = 0.0
        roots.append(scipy.optimize.brentq(function, low, high, xtol=1e-15, rtol=1e-14, maxiter=200))
    return roots


def spring_with_end_mass_frequencies(k: float, spring_mass: float, m: float, count: int = 3) -> list[float]:
    """The first `count` natural angular frequencies (rad/s) of a spring of stiffness k and
    mass spring_mass, fixed at one end, with a mass m at the other: w = beta sqrt(k / M_s).
    m = 0 gives the free-end rod, beta = (2n - 1) pi / 2."""
    if m == 0.0:
        betas = [(2 * n + 1) * math.pi / 2 for n in range(count)]
    else:
        betas = spring_with_end_mass_betas(spring_mass / m, count)
    return [beta * math.sqrt(k / spring_mass) for beta in betas]
