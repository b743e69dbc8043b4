"""IFToMM A05, the stiff flyball governor, worked out here apart from the description:
positions written in the shaft's frame (y up along the shaft, the rods in its x-y plane),
energies summed body by body.

Rods with their balls. A rod of mass m_r = rho L b^2 hinged at (+-d, L) swings at phi
from the downward vertical; its ball m sits at L from the hinge. About the hinge its
moment is I_h = m_r (L^2 + b^2)/12 + m_r (L/2)^2 + m L^2; its weight's moment
(m_r L/2 + m L) g sin phi. About the shaft's axis (the rod at phi, turning with the
shaft): the rod's own moment about the vertical through its centre (m_r b^2/6 along the
rod, m_r (L^2 + b^2)/12 across it, so m_r (b^2 (1 + cos^2 phi) + L^2 sin^2 phi)/12),
plus m_r (d + (L/2) sin phi)^2 and m (d + L sin phi)^2.

Coupler i runs from the slider's point (+-d, s) to the rod's midpoint
(+-(d + (L/2) sin phi), L - (L/2) cos phi): length l with
l^2 = (L/2)^2 sin^2 phi + (L - (L/2) cos phi - s)^2, tension k (l - l0) + c l'.

Angular momentum about the axis. Gravity is parallel to the axis, the base hinge turns
freely about it and the couplers are internal: H = I_axis(phi1, phi2) psi' is constant,
H_0 = I_axis(pi/2 - alpha0) omega0 (the rods' swing and the slide add nothing to it: their
velocities lie in planes through the axis).

Slow swing. The couplers are stiff (k l0 / (m g) ~ 1e4): the governor moves nearly as
Watt's rigid linkage, with l = l0, and the couplers' dampers, whose rate l' is then
nearly zero, take almost no energy from it (the slow swing's damping rate, about the
spring's deflection rate squared times c, is orders of magnitude below its frequency).
On the rigid linkage with H fixed, at a turning point of the swing (phi' = s' = 0) the
energy is H^2 / (2 I_axis(phi)) + V(phi): equal at both turning points, so the second
turning point is the other root of E(phi) = E(phi_0) (`turning_points`).

Equilibria (at rest): each rod hangs straight down or stands straight up with its
coupler along the shaft; the springs admit more (bent) configurations, which are not
counted (total None). None is stable in the linear sense: the shaft's angle psi is free,
with no stiffness and no damping, a rigid undamped drift (a double zero eigenvalue).

The operating equilibrium (both rods hanging, phi = 0, each coupler vertical from
(d, s) to (d, L/2), stretched by the slider's weight: T = rho a^3 g / 2, l = l0 + T/k,
s = L/2 - l): in (psi, s, phi1, phi2)
    M = diag(I_axis(0), rho a^3, I_h, I_h)
    K: psi none; s from both springs 2k (dl/ds = -1, dl/dphi = 0 at phi = 0);
       phi: (m_r L/2 + m L) g + T d2l/dphi2 with d2l/dphi2 = (L/2)(L - s)/l
    C: s 2c (dampers along the couplers), nothing else.
So psi gives a double zero, each rod sqrt(K_phi/I_h), and the slider the two roots of
rho a^3 r^2 + 2 c r + 2 k = 0 (real at the defaults: overdamped).
"""
import math

import numpy as np
from scipy.optimize import brentq

EQUILIBRIA = (None, 0)
MISPRINTS = set()
#: the hanging rest state is not stable in the linear sense (the free shaft drifts)
OPERATING_POINT_STABLE = False
#: why no free-vibration check applies: there is no stable equilibrium to release near
NO_FREE_VIBRATION = ("every equilibrium drifts with the free shaft (a rigid, undamped "
                     "rotation about its axis): none is stable to vibrate about")


def rod_mass(v):
    return v["rho"] * v["L"] * v["b"] ** 2


def hinge_moment(v) -> float:
    m_r = rod_mass(v)
    return m_r * (v["L"] ** 2 + v["b"] ** 2) / 12 + m_r * (v["L"] / 2) ** 2 + v["m"] * v["L"] ** 2


def axial_moment(v, phi1: float, phi2: float | None = None) -> float:
    """I_axis with the rods at phi1 and phi2 from the downward vertical (both outward
    positive); phi2 defaults to phi1 (the symmetric position)."""
    m_r, L, b, d = rod_mass(v), v["L"], v["b"], v["d"]

    def arm(phi):
        own = m_r * (b**2 * (1 + math.cos(phi) ** 2) + L**2 * math.sin(phi) ** 2) / 12
        return own + m_r * (d + L / 2 * math.sin(phi)) ** 2 + v["m"] * (d + L * math.sin(phi)) ** 2

    shaft = m_r * b**2 / 6
    slider = v["rho"] * v["a"] ** 5 / 6
    return shaft + slider + arm(phi1) + arm(phi1 if phi2 is None else phi2)


def initial_angular_momentum(v) -> float:
    return axial_moment(v, math.pi / 2 - v["alpha0"]) * v["omega0"]


def linkage_height(v, phi: float) -> float:
    """s of the rigid linkage (couplers at l0) with both rods at phi."""
    L = v["L"]
    horizontal = L / 2 * math.sin(phi)
    return L - L / 2 * math.cos(phi) - math.sqrt(v["l0"] ** 2 - horizontal**2)


def _potential(v, phi: float) -> float:
    """Gravity's potential of the rigid linkage (both rods at phi), from the base."""
    g, L = v["g"], v["L"]
    rods = 2 * (rod_mass(v) * (L - L / 2 * math.cos(phi)) + v["m"] * (L - L * math.cos(phi)))
    return g * (rods + v["rho"] * v["a"] ** 3 * linkage_height(v, phi))


def turning_points(v) -> tuple[float, float]:
    """(s at the release, s at the other turning point) of the slow swing on the rigid
    linkage with H = H_0: E(phi) = H_0^2 / (2 I_axis(phi)) + V(phi) takes its initial
    value again at the far turning point (the rods swinging outwards: the release has
    more centrifugal pull than weight, so they rise)."""
    phi0 = math.pi / 2 - v["alpha0"]
    H = initial_angular_momentum(v)

    def excess(phi):
        return (H**2 / (2 * axial_moment(v, phi)) + _potential(v, phi)
                - H**2 / (2 * axial_moment(v, phi0)) - _potential(v, phi0))

    # the rods cannot pass the coupler's reach: sin phi < 2 l0 / L
    top = min(math.asin(min(1.0, 2 * v["l0"] / v["L"])), math.pi / 2) - 1e-9
    grid = np.linspace(phi0 + 1e-6, top, 400)
    values = [excess(p) for p in grid]
    i = next(i for i in range(len(grid) - 1) if values[i] < 0 <= values[i + 1])
    far = brentq(excess, grid[i], grid[i + 1], xtol=1e-15)
    return linkage_height(v, phi0), linkage_height(v, far)


def frequencies(v):
    """|r| of the operating equilibrium's modes, as the analytic layer counts them: the
    free shaft's double zero, each rod's swing, the slider's two real roots."""
    m_s = v["rho"] * v["a"] ** 3
    T = m_s * v["g"] / 2
    length = v["l0"] + T / v["k"]
    s = v["L"] / 2 - length
    stiffness = ((rod_mass(v) * v["L"] / 2 + v["m"] * v["L"]) * v["g"]
                 + T * (v["L"] / 2) * (v["L"] - s) / length)
    swing = math.sqrt(stiffness / hinge_moment(v))
    slider = np.roots([m_s, 2 * v["c"], 2 * v["k"]])
    if np.any(np.abs(slider.imag) > 0):  # underdamped: one mode, |r| = sqrt(2k/m_s)
        slider_modes = [math.sqrt(2 * v["k"] / m_s)]
    else:
        slider_modes = sorted(abs(slider.real))
    return sorted([0.0, 0.0, swing, swing] + list(slider_modes))
