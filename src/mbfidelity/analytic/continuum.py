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
from dataclasses import dataclass, replace
from typing import Callable, Mapping

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


# --- the continua of the catalog's discretized systems (System.continuum) ---------------


@dataclass(frozen=True)
class RayleighEstimate:
    """A first-frequency estimate by Rayleigh's method, coded as printed."""

    label: str
    shape: str
    frequency_hz: float
    #: (estimate - exact) / exact, against the continuum's first frequency: positive,
    #: Rayleigh's quotient being an upper bound
    relative_error: float

    def as_dict(self) -> dict:
        return {"label": self.label, "shape": self.shape, "frequency_hz": self.frequency_hz,
                "relative_error": self.relative_error}


@dataclass(frozen=True)
class ContinuumSummary:
    """What the exact continuum says of a discretized system's parameters: its first
    natural frequencies, the monograph's Rayleigh estimates, and the leading coefficient
    C_n of the discretization's relative error C_n / N^2 (N elements), mode by mode, as
    derived for the system's lumping (None where not derived)."""

    model: str
    description: str
    frequency_hz: list[float]
    rayleigh: list[RayleighEstimate]
    leading_error: list[float] | None = None

    def as_dict(self) -> dict:
        return {"model": self.model, "description": self.description,
                "frequency_hz": self.frequency_hz,
                "discretization_leading_error": self.leading_error}


def rayleigh_massive_spring(k: float, spring_mass: float, m: float) -> float:
    """§6.2 eq. 69-70 as printed: with the linear shape z = (x/l) z_a of a static end load,
    m_red = m + rho l / 3 and k_red = k, so f0 = sqrt(k / (m + rho l / 3)) / (2 pi) (Hz)."""
    return math.sqrt(k / (m + spring_mass / 3)) / (2 * math.pi)


def lumped_spring_error_coefficients(spring_mass: float, m: float, count: int = 3) -> list[float]:
    """Leading coefficients C_n of the lumped chain's relative frequency error,
    w_N / w - 1 = C_n / N^2 + O(N^-4), for the spring of mass M_s cut into N segments of
    stiffness N k with half of each segment's mass at each end node (the ground's half
    lost, the end node m + M_s / (2N)).

    Derivation (by hand): node displacements u_j = sin(j theta) satisfy every interior
    node's equation when w^2 = (4 N^2 k / M_s) sin^2(theta / 2); the end node's equation
    then reduces to tan(N theta) = (M_s / m) cot(theta / 2) / (2 N). With theta = b / N and
    r = M_s / m: b tan(b) (2N/b) tan(b / 2N) = r, i.e. f(b) (1 + b^2 / (12 N^2)) = r with
    f(b) = b tan b, to O(N^-4). Against the exact root beta of f(beta) = r, b = beta + d
    with d = -r beta^2 / (12 N^2 f'(beta)), f'(beta) = (r + r^2 + beta^2) / beta; and
    w_N = 2 N sqrt(k / M_s) sin(b / 2N) = b sqrt(k / M_s) (1 - b^2 / (24 N^2)). So
    C_n = -beta_n^2 (1/24 + r / (12 (r + r^2 + beta_n^2))): the bare rod's dispersion
    -beta^2/24 (m -> 0) plus the end mass's share; m >> M_s gives -r/12, the N = 1 chain's
    k / (m + M_s/2) against k / (m + M_s/3). Negative: the lumped nodes carry more of the
    spring's mass through the motion than the continuum does, so the chain's frequencies
    lie below the continuum's."""
    r = spring_mass / m
    return [-beta**2 * (1 / 24 + r / (12 * (r + r**2 + beta**2)))
            for beta in spring_with_end_mass_betas(r, count)]


def spring_with_end_mass(values: Mapping[str, float], count: int = 3) -> ContinuumSummary:
    """The spring of stiffness k, length l, mass rho per length with the end block m
    (§6.2, Fig. 18): parameters k, l, rho, m."""
    k, spring_mass, m = values["k"], values["rho"] * values["l"], values["m"]
    exact = [w / (2 * math.pi) for w in spring_with_end_mass_frequencies(k, spring_mass, m, count)]
    estimate = rayleigh_massive_spring(k, spring_mass, m)
    return ContinuumSummary(
        model="spring_with_end_mass",
        description="rod of stiffness k and mass rho l fixed at one end with a mass m at "
                    "the other: beta tan(beta) = rho l / m, w = beta sqrt(k / (rho l))",
        frequency_hz=exact,
        rayleigh=[RayleighEstimate("eq. 69-70", "z(x) = (x/l) z_a, static end load",
                                   estimate, (estimate - exact[0]) / exact[0])],
        leading_error=lumped_spring_error_coefficients(spring_mass, m, count))


def rayleigh_beam_block_load_shape(EI: float, rho: float, l: float, m: float, c: float) -> float:
    """§6.1 eq. 66-68 as printed: the static deflection under a load at a = c l as the
    assumed shape; k_red = 3 EI / (c^2 (1 - c)^2 l^3) at the block, and the beam's mass
    reduced to the block's point by (2 + 4c - c^2 - 6c^3 + 3c^4) / (105 c^2 (1 - c)^2).
    Returns the estimate of the first angular frequency (rad/s)."""
    stiffness = 3 * EI / ((1 - c) ** 2 * c**2 * l**3)
    mass = m + (2 + 4 * c - c**2 - 6 * c**3 + 3 * c**4) / (105 * (1 - c) ** 2 * c**2) * rho * l
    return math.sqrt(stiffness / mass)


def rayleigh_beam_own_weight_shape(EI: float, rho: float, l: float, m: float, c: float) -> float:
    """§6.1 as printed, the second shape: the static deflection under the beam's own
    uniform weight, y ~ x/l - 2 (x/l)^3 + (x/l)^4, referred to the block's point
    (s = c - 2c^3 + c^4): k_red = 24 EI / (5 s^2 l^3), the beam's reduced mass
    31 rho l / (630 s^2). Returns the first angular frequency's estimate (rad/s)."""
    s = c - 2 * c**3 + c**4
    stiffness = 24 * EI / (5 * s**2 * l**3)
    mass = m + 31 / (630 * s**2) * rho * l
    return math.sqrt(stiffness / mass)


def beam_with_point_mass(values: Mapping[str, float], count: int = 3) -> ContinuumSummary:
    """The simply supported beam of length l, stiffness EI, mass rho per length with a
    block m at a = c l (§6.1, Fig. 17; the catalog's c = 1/2): parameters l, EI, rho, m,
    c. The leading error of the rigid-segment chain is not derived (None)."""
    EI, rho, l, m, c = values["EI"], values["rho"], values["l"], values["m"], values["c"]
    exact = [w / (2 * math.pi)
             for w in beam_with_point_mass_frequencies(EI, rho, l, m, c * l, count)]
    estimates = [
        RayleighEstimate("eq. 66-68", "static deflection under the block's load",
                         rayleigh_beam_block_load_shape(EI, rho, l, m, c) / (2 * math.pi), 0.0),
        RayleighEstimate("§6.1, own weight", "static deflection under the beam's weight",
                         rayleigh_beam_own_weight_shape(EI, rho, l, m, c) / (2 * math.pi), 0.0)]
    return ContinuumSummary(
        model="beam_with_point_mass",
        description="Euler-Bernoulli beam, simply supported, with a point mass at a = c l: "
                    "the 4 x 4 matching determinant of the mode shapes on both sides",
        frequency_hz=exact,
        rayleigh=[replace(r, relative_error=(r.frequency_hz - exact[0]) / exact[0])
                  for r in estimates])


#: the continuum models a system may name (`System.continuum`)
CONTINUA: dict[str, Callable[..., ContinuumSummary]] = {
    "spring_with_end_mass": spring_with_end_mass,
    "beam_with_point_mass": beam_with_point_mass,
}


def continuum_summary(name: str, values: Mapping[str, float], count: int = 3) -> ContinuumSummary:
    if name not in CONTINUA:
        raise ValueError(f"no continuum model {name!r}; known: {', '.join(CONTINUA)}")
    return CONTINUA[name](values, count)
