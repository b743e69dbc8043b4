"""Fig. 38, derived by hand.

Kinematics: arm angle theta (from the downward vertical), pulley angles phi1, phi2
relative to the arm, so the pulleys turn absolutely at theta' + phi1', theta' + phi2'.
Pulley 2's centre C = l (sin theta, -cos theta) moves at l theta'. Pulley 1's centre is
fixed at O. Belt without slip, open belt: the belt speed relative to the arm is
r1 phi1' = r2 phi2', so phi2' = rho phi1' with rho = r1/r2.

    T = I1 (theta' + phi1')^2 / 2 + I2 (theta' + rho phi1')^2 / 2 + m2 l^2 theta'^2 / 2
    V = -m2 g l cos(theta)
    D = c3 theta'^2 / 2 + c1 phi1'^2 / 2 + c2 (rho phi1')^2 / 2

so, constant over the configuration space,

    M = [[a, b], [b, d]],  a = I1 + I2 + m2 l^2,  b = I1 + I2 rho,  d = I1 + I2 rho^2
    C = diag(c3, c4),      c4 = c1 + c2 rho^2
    K = diag(k, 0),        k = m2 g l cos(theta_eq) = m2 g l at theta_eq = 0.

All of Fig. 38's printed E_c (both forms), E_p, M, K and C agree with this, and so does
its P_nc: the viscous moments' power is -2 D = -c3 theta'^2 - (c1 + c2 rho^2) phi1'^2.

Characteristic equation det(M s^2 + C s + K) = 0:
    (a s^2 + c3 s + k)(d s^2 + c4 s) - b^2 s^4
  = s [ (a d - b^2) s^3 + (a c4 + c3 d) s^2 + (c3 c4 + k d) s + k c4 ] = 0,
one root s = 0 (phi1 is cyclic: the zero frequency the monograph's K announces) and the
three roots of the cubic. Without damping the cubic gives s^2 = -k d / (a d - b^2), i.e.
the pendulum frequency sqrt(k d / (a d - b^2)) (undamped_frequencies below).

`frequencies` gives |s| for each mode as the analytic layer counts them (one per complex
pair, one per real root), because the generic test compares |s| of the damped
eigenvalues with this list; at the default (damped) values that is 0, the real root of
the drift mode, and |s| of the oscillation.

Equilibria: dV/dtheta = m2 g l sin(theta) = 0 -> theta = 0 (K > 0, stable, with the
damped drift of phi1 decaying to rest) and theta = pi (unstable); phi1 is arbitrary:
two one-parameter families of equilibria, counted here as (2, 1) modulo the cyclic phi1.
"""
import numpy as np

EQUILIBRIA = (2, 1)  # theta = 0 (stable) and theta = pi (unstable), any phi1
MISPRINTS = set()


def _matrices(v):
    rho = v["r1"] / v["r2"]
    a = v["I1"] + v["I2"] + v["m2"] * v["l"] ** 2
    b = v["I1"] + v["I2"] * rho
    d = v["I1"] + v["I2"] * rho**2
    c3, c4 = v["c3"], v["c1"] + v["c2"] * rho**2
    k = v["m2"] * v["g"] * v["l"]
    return a, b, d, c3, c4, k


def _modes(roots, scale):
    out = []
    for s in roots:
        if abs(s.imag) <= 1e-9 * scale:
            out.append(abs(s.real))
        elif s.imag > 0:
            out.append(abs(s))
    return sorted(out)


def frequencies(v):
    a, b, d, c3, c4, k = _matrices(v)
    cubic = np.roots([a * d - b**2, a * c4 + c3 * d, c3 * c4 + k * d, k * c4])
    roots = np.r_[0.0, cubic]
    return _modes(roots, max(np.abs(roots).max(), 1.0))


def undamped_frequencies(v):
    a, b, d, _, _, k = _matrices(v)
    return [0.0, np.sqrt(k * d / (a * d - b**2))]
