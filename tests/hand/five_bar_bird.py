"""Fig. 40 (§10.1), worked by hand on the geometry the system module pins:

  Q = l(-s1, -c1), Q' = (e, 0) + l(-s2, -c2), P = Q + a(s3, -c3) = Q' + a(-s4, -c4),
  G1 = Q + b(-s3, c3), G2 = Q' + b(s4, c4)      (s_i = sin phi_i, c_i = cos phi_i)

Velocities: v_G1 = (-l c1 w1 - b c3 w3, l s1 w1 - b s3 w3), v_P = (-l c1 w1 + a c3 w3,
l s1 w1 + a s3 w3), v_G2 = (-l c2 w2 + b c4 w4, l s2 w2 - b s4 w4), so

  T = I (w3^2 + w4^2)/2 + m (l^2 w1^2 + b^2 w3^2 + 2 l b cos(phi1 + phi3) w1 w3)/2
      + m (l^2 w2^2 + b^2 w4^2 - 2 l b cos(phi2 - phi4) w2 w4)/2
      + m_c (l^2 w1^2 + a^2 w3^2 - 2 l a cos(phi1 + phi3) w1 w3)/2
  V = -(m + m_c) g l c1 - m g l c2 + (m g b - m_c g a) c3 + m g b c4   (= printed eq. 115)
  Phi = P_left - P_right = (-l s1 + a s3 - e + l s2 + a s4, -l c1 - a c3 + l c2 + a c4)
        (eq. 113 up to the order and sign of its rows; eq. 114 is its Jacobian).

Operating equilibrium: the mobile is symmetric about x = e/2 (P on the axis, the wings
mirror images), so the hanging equilibrium has phi2 = -phi1 = theta, phi3 = phi4 = psi with
l sin(theta) + a sin(psi) = e/2. On that family V = -(2m + m_c) g l cos(theta)
+ (2 m b - m_c a) g cos(psi), psi' = -l cos(theta)/(a cos(psi)), and dV/dtheta = 0 reads
  (2m + m_c) sin(theta) + (2 m b - m_c a) sin(psi) cos(theta)/(a cos(psi)) = 0,
which has one root in (0, asin(e/(2l))) when m_c a > 2 m b (checked in `valid`). At it,
K = S^T (Hess V + lam1 Hess Phi_1 + lam2 Hess Phi_2) S and M = S^T M4 S with the static
multipliers grad V + Phi_q^T lam = 0 and S the velocity basis for (phi1', phi2').

Equilibria at the defaults (all four angles within one period): 12, counted by solving
grad V + Phi_q^T lam = 0, Phi = 0 (six equations, no chart) from 2 x 8100 starts covering
both assembly branches over the (phi1, phi2) torus, and from 20000 random starts: the same
12 each time. Reduced Hessians: 2 minima (the hanging mobile, V = -0.6291 J, and a crossed
configuration with both bars above O-O', V = +0.3226 J), 8 saddles and 2 maxima. Check:
2 - 8 + 2 = -4 is the Euler characteristic of the configuration surface (the (phi1, phi2)
region where the wings reach, |QQ'| <= 2a, has chi = 0 (counted on a 1600 x 1600 grid of
the torus); it is covered twice (P on either side of QQ'), and over the two points where
Q = Q' (phi2 = -phi1 = asin(e/(2l)) and pi minus that) P may be anywhere on a circle: each
replaces a point of both sheets by a tube joining them, so chi = 2*0 - 4 = -4).
"""
import numpy as np
from scipy.optimize import brentq

EQUILIBRIA = (12, 2)
MISPRINTS = {
    # cross terms: the geometry gives +2 l b cos(phi1 + phi3) (wing 1), -2 l b cos(phi2 - phi4)
    # (wing 2) and -2 l a cos(phi1 + phi3) (body); eq. 115 prints -, -cos(phi2 + phi4) and +
    "Fig. 40, eq. 115 (kinetic energy)",
    # eq. 116: Lagrange's equations of T and V above with the multiplier terms of eq. 112
    # (`eq116_by_hand`); the printed multiplier terms are right, the inertia terms are not.
    # Row 1: phi1'' has (m + m_c) l^2 (eq. 115 itself has m_c l^2 w1^2/2), and the phi3
    # coupling is (m l b - m_c l a)(cos(phi1+phi3) phi3'' - sin(phi1+phi3) phi3'^2), sign
    # reversed. Row 2: m l b(-cos(phi2 - phi4) phi4'' - sin(phi2 - phi4) phi4'^2), printed with
    # phi2 + phi4. Row 3: coupling sign reversed as in row 1. Row 4: as row 2 with
    # -m l b(cos(phi2 - phi4) phi2'' - sin(phi2 - phi4) phi2'^2); its "(I + m b^2 + )" is a
    # stray plus (I + m b^2 is right). Rows 2-4 are exactly Lagrange's equations of the
    # printed E_c (inherited errors); row 1's m l^2 is not.
    "Fig. 40, eq. 116, row 1", "Fig. 40, eq. 116, row 2",
    "Fig. 40, eq. 116, row 3", "Fig. 40, eq. 116, row 4",
    # as a system: with the true accelerations no multipliers satisfy the four printed rows
    # (four equations, two multipliers, the inertia errors are not constraint forces)
    "Fig. 40, eq. 116 (as a system, multipliers fitted)",
}
# agree: eq. 115 potential energy; eq. 113 (= (-Phi_y, Phi_x) of Phi above: same zero set)
# and eq. 114 (its Jacobian = [[0, -1], [1, 0]] Phi_q)


def eq116_by_hand(p, d, a, lam, v):
    """Lagrange's equations with multipliers (eq. 112) of T and V above, in the printed
    multipliers of eq. 114 (force of wing 2 on wing 1 at P = (lam2, -lam1)): four sympy
    residuals. p, d, a: angles, rates, accelerations (phi1..phi4); v: parameter symbols."""
    import sympy as sp

    l, A, b, m, I, m_c, g = v.l, v.a, v.b, v.m, v.I, v.m_c, v.g
    s, c = sp.sin, sp.cos
    k13 = m * l * b - m_c * l * A  # coefficient of cos(phi1 + phi3) w1 w3 in T
    s24, c24 = s(p[1] - p[3]), c(p[1] - p[3])
    L1, L2 = lam
    return [
        (m + m_c) * l**2 * a[0] + k13 * (c(p[0] + p[2]) * a[2] - s(p[0] + p[2]) * d[2] ** 2)
        + (m + m_c) * g * l * s(p[0]) + L1 * l * s(p[0]) + L2 * l * c(p[0]),
        m * l**2 * a[1] - m * l * b * (c24 * a[3] + s24 * d[3] ** 2)
        + m * g * l * s(p[1]) - L1 * l * s(p[1]) - L2 * l * c(p[1]),
        (I + m * b**2 + m_c * A**2) * a[2]
        + k13 * (c(p[0] + p[2]) * a[0] - s(p[0] + p[2]) * d[0] ** 2)
        + (m_c * g * A - m * g * b) * s(p[2]) + L1 * A * s(p[2]) - L2 * A * c(p[2]),
        (I + m * b**2) * a[3] - m * l * b * (c24 * a[1] - s24 * d[1] ** 2)
        - m * g * b * s(p[3]) - L1 * A * s(p[3]) - L2 * A * c(p[3]),
    ]


def loop_by_hand(p, v):
    """Phi = P(wing 1) - P(wing 2) (x, y) above, as sympy expressions."""
    import sympy as sp

    l, A, e = v.l, v.a, v.e
    s, c = sp.sin, sp.cos
    return [-l * s(p[0]) + A * s(p[2]) - e + l * s(p[1]) + A * s(p[3]),
            -l * c(p[0]) - A * c(p[2]) + l * c(p[1]) + A * c(p[3])]


def valid(v):
    """Assembly with the bars hanging (e < 2a, e < 2l) and a body heavy enough to hang
    below the hinges (m_c a > 2 m b): then the hanging equilibrium exists."""
    return (v["e"] < 1.8 * v["a"] and v["e"] < 1.8 * v["l"]
            and v["m_c"] * v["a"] > 1.2 * 2 * v["m"] * v["b"])


def _hanging(v):
    l, a, b, e, m, m_c = v["l"], v["a"], v["b"], v["e"], v["m"], v["m_c"]

    def psi(theta):
        return np.arcsin((e / 2 - l * np.sin(theta)) / a)

    def dV(theta):
        p = psi(theta)
        return ((2 * m + m_c) * np.sin(theta)
                + (2 * m * b - m_c * a) * np.sin(p) * np.cos(theta) / (a * np.cos(p)))

    top = np.arcsin(min(1.0, e / (2 * l)))
    theta = brentq(dV, 0.0, top, xtol=1e-15, rtol=1e-15)
    return np.array([-theta, theta, psi(theta), psi(theta)])


def frequencies(v):
    l, a, b, m, I, m_c, g = v["l"], v["a"], v["b"], v["m"], v["I"], v["m_c"], v["g"]
    q = _hanging(v)
    s1, s2, s3, s4 = np.sin(q)
    c1, c2, c3, c4 = np.cos(q)
    c13, c24 = np.cos(q[0] + q[2]), np.cos(q[1] - q[3])
    # mass matrix of T above (coordinates phi1..phi4)
    M = np.zeros((4, 4))
    M[0, 0] = (m + m_c) * l**2
    M[1, 1] = m * l**2
    M[2, 2] = I + m * b**2 + m_c * a**2
    M[3, 3] = I + m * b**2
    M[0, 2] = M[2, 0] = (m * l * b - m_c * l * a) * c13
    M[1, 3] = M[3, 1] = -m * l * b * c24
    gradV = g * np.array([(m + m_c) * l * s1, m * l * s2, -(m * b - m_c * a) * s3, -m * b * s4])
    hessV = g * np.diag([(m + m_c) * l * c1, m * l * c2, -(m * b - m_c * a) * c3, -m * b * c4])
    J = np.array([[-l * c1, l * c2, a * c3, a * c4],
                  [l * s1, -l * s2, a * s3, -a * s4]])
    H1 = np.diag([l * s1, -l * s2, -a * s3, -a * s4])
    H2 = np.diag([l * c1, -l * c2, a * c3, -a * c4])
    lam = np.linalg.solve(J[:, 2:].T, -gradV[2:])  # rows phi3, phi4 of grad V + J^T lam = 0
    assert np.allclose(gradV[:2] + J[:, :2].T @ lam, 0, atol=1e-12)
    S = np.vstack([np.eye(2), -np.linalg.solve(J[:, 2:], J[:, :2])])
    K = S.T @ (hessV + lam[0] * H1 + lam[1] * H2) @ S
    Mr = S.T @ M @ S
    w2 = np.linalg.eigvals(np.linalg.solve(Mr, K)).real
    return sorted(np.sqrt(w2))
