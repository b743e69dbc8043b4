"""Fig. 35, §9.6, by hand. Block at h (sin phi, -cos phi) + x (cos phi, sin phi), arm's
G_s at b (sin phi, -cos phi): T = (I_s + m_s b^2 + I_b + m_b (h^2 + x^2)) phi'^2/2 +
m_b x'^2/2 + m_b h phi' x', V = m_s g b (1 - cos phi) + m_b g (h - h cos phi + x sin phi).
dT/dx = m_b x phi'^2, so Lagrange's x row is m_b (x'' + h phi'') - m_b x phi'^2 +
m_b g sin(phi) = F_act, as §9.6's equation prints it; the intermediate line
dE_c/dx = m_b phi'^2 lacks the factor x (not coded: no formula kind for it). The phi row
I phi'' + 2 m_b x x' phi' + m_b h x'' + dV/dphi = T_mot agrees.
Unexcited (T_a = x_a = 0, x = x0): dV/dphi = g (A sin phi + B cos phi) with
A = m_s b + m_b h, B = m_b x0 vanishes at tan(phi) = -B/A and at that angle + pi: two rest
states, the hanging one (cos phi > 0) stable with K = g sqrt(A^2 + B^2), the other
unstable; M = I_s + m_s b^2 + I_b + m_b (h^2 + x0^2)."""
import numpy as np

EQUILIBRIA = (2, 1)
MISPRINTS = set()


def frequencies(v):
    A = v["m_s"] * v["b"] + v["m_b"] * v["h"]
    B = v["m_b"] * v["x0"]
    K = v["g"] * np.hypot(A, B)
    M = v["I_s"] + v["m_s"] * v["b"] ** 2 + v["I_b"] + v["m_b"] * (v["h"] ** 2 + v["x0"] ** 2)
    return [np.sqrt(K / M)]
