"""Fig. 39, eq. 110, derived by hand from the geometry the system module pins.

Positions (theta clockwise, phi absolute from the downward vertical):
    C = R (cos th, -sin th),  G = C + e (-sin th, -cos th),  D = C + (R - r)(sin ph, -cos ph).
Velocities: |v_G|^2 = (R^2 + e^2) th'^2 (G turns about O at distance sqrt(R^2 + e^2));
    v_D = R th' (-sin th, -cos th) + (R - r) ph' (cos ph, sin ph),
    |v_D|^2 = R^2 th'^2 + (R - r)^2 ph'^2 - 2 R (R - r) sin(th + ph) th' ph'.

Rolling inside the track. Track angular velocity -th' (clockwise), contact J = C + R u,
u = (sin ph, -cos ph), t = (cos ph, sin ph). Disc point at J: v_D + w_d r t; track point at
J: v_C - th' R t. No slip: (R - r) ph' + r w_d = -R th', so the disc turns absolutely at
    w_d = -(R th' + (R - r) ph') / r        (not ph').

    T = (I_p + m_p (R^2 + e^2)) th'^2/2 + m_d |v_D|^2/2 + I_d (R th' + (R - r) ph')^2/(2 r^2)
    V = -m_p g (R sin th + e cos th) - m_d g (R sin th + (R - r) cos ph) + M0 th + k_t th^2/2
    D = c_O th'^2/2 + c_J (th' + ph')^2/2

Equilibria: dV/dph = m_d g (R - r) sin ph = 0 -> ph = 0 or pi;
    dV/dth = M0 + k_t th - g ((m_p + m_d) R cos th - m_p e sin th) = 0. Its derivative
    k_t + g ((m_p + m_d) R sin th + m_p e cos th) >= k_t - g sqrt(((m_p + m_d) R)^2 + (m_p e)^2)
    is positive at the defaults (50 > 24.8), so th_eq is unique (th_eq = 0 when
    M0 = (m_p + m_d) g R). Two equilibria: (th_eq, 0) stable, (th_eq, pi) unstable
    (K22 = m_d g (R - r) cos pi < 0).

Linearization at (th_eq, 0):
    M11 = I_p + m_p (R^2 + e^2) + m_d R^2 + I_d R^2 / r^2
    M12 = -m_d R (R - r) sin(th_eq) + I_d R (R - r) / r^2
    M22 = (m_d + I_d / r^2)(R - r)^2
    K11 = g (m_p (R sin th_eq + e cos th_eq) + m_d R sin th_eq) + k_t,  K12 = 0,
    K22 = m_d g (R - r)
    C = [[c_O + c_J, c_J], [c_J, c_J]]
det(M s^2 + C s + K) = a4 s^4 + a3 s^3 + a2 s^2 + a1 s + a0 with
    a4 = M11 M22 - M12^2,  a3 = M11 C22 + C11 M22 - 2 M12 C12,
    a2 = M11 K22 + C11 C22 + K11 M22 - C12^2,  a1 = C11 K22 + K11 C22,  a0 = K11 K22.
`frequencies` gives |s| per mode (one per complex pair, one per real root), which is what
the generic test compares (the damped eigenvalues of the analytic layer);
`undamped_frequencies` gives sqrt of the roots of det(K - w^2 M) = 0.
"""
import numpy as np
from scipy.optimize import brentq

EQUILIBRIA = (2, 1)  # (0, 0) stable, (0, pi) unstable
MISPRINTS = {
    # the disc's spin is -(R th' + (R - r) ph')/r by the rolling condition; eq. 110 takes
    # it as ph' (term I_d ph'^2/2): the rotational energy of the disc is wrong
    "Fig. 39, eq. 110, E_c",
    # follows the wrong E_c (disc spin) and moreover writes m_p (R + e)^2 for the track's
    # m_p (R^2 + e^2) (|OG|^2) of its own E_c
    "Fig. 39, equations of motion (after eq. 110), row 1",
    # follows the wrong E_c (disc spin) and moreover its leading term multiplies th''
    # where d/dt(dE_c/dph') gives (I_d + m_d (R - r)^2) ph''
    "Fig. 39, equations of motion (after eq. 110), row 2",
    # with the rolling spin M11 gains I_d R^2/r^2, M22 is (m_d + I_d/r^2)(R - r)^2 and
    # M12 = I_d R (R - r)/r^2 is not zero
    "Fig. 39, matrix M",
    # d2E_p/dth2 at th = 0 is m_p g e + k_t (from the printed E_p itself), not m_p g R + k_t
    "Fig. 39, matrix K",
}


def _dV(th, v):
    g = v["g"]
    return (v["M0"] + v["k_t"] * th
            - g * ((v["m_p"] + v["m_d"]) * v["R"] * np.cos(th) - v["m_p"] * v["e"] * np.sin(th)))


def valid(v):
    # dV/dth strictly increasing: one equilibrium in theta
    g = v["g"]
    return v["k_t"] > g * np.hypot((v["m_p"] + v["m_d"]) * v["R"], v["m_p"] * v["e"])


def theta_eq(v):
    return brentq(_dV, -20.0, 20.0, args=(v,), xtol=1e-15, rtol=1e-15)


def matrices(v):
    m_p, I_p, R, e = v["m_p"], v["I_p"], v["R"], v["e"]
    m_d, r, I_d, g = v["m_d"], v["r"], v["I_d"], v["g"]
    th = theta_eq(v)
    M = np.array([
        [I_p + m_p * (R**2 + e**2) + m_d * R**2 + I_d * R**2 / r**2,
         -m_d * R * (R - r) * np.sin(th) + I_d * R * (R - r) / r**2],
        [0.0, (m_d + I_d / r**2) * (R - r) ** 2]])
    M[1, 0] = M[0, 1]
    K = np.diag([g * (m_p * (R * np.sin(th) + e * np.cos(th)) + m_d * R * np.sin(th)) + v["k_t"],
                 m_d * g * (R - r)])
    C = np.array([[v["c_O"] + v["c_J"], v["c_J"]], [v["c_J"], v["c_J"]]])
    return M, C, K


def frequencies(v):
    M, C, K = matrices(v)
    a4 = M[0, 0] * M[1, 1] - M[0, 1] ** 2
    a3 = M[0, 0] * C[1, 1] + C[0, 0] * M[1, 1] - 2 * M[0, 1] * C[0, 1]
    a2 = M[0, 0] * K[1, 1] + C[0, 0] * C[1, 1] + K[0, 0] * M[1, 1] - C[0, 1] ** 2
    a1 = C[0, 0] * K[1, 1] + K[0, 0] * C[1, 1]
    a0 = K[0, 0] * K[1, 1]
    roots = np.roots([a4, a3, a2, a1, a0])
    scale = np.abs(roots).max()
    out = [abs(s.real) if abs(s.imag) <= 1e-9 * scale else abs(s)
           for s in roots if s.imag >= -1e-9 * scale]
    return sorted(out)


def undamped_frequencies(v):
    M, _, K = matrices(v)
    # det(K - x M) = 0, x = w^2
    a = M[0, 0] * M[1, 1] - M[0, 1] ** 2
    b = -(M[0, 0] * K[1, 1] + K[0, 0] * M[1, 1])
    return sorted(np.sqrt(np.roots([a, b, K[0, 0] * K[1, 1]]).real))
