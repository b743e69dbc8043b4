"""Fig. 8 (eq. 7-9), by hand. With C = e (sin phi, -cos phi) the block rises
y = const - e cos(phi), so T = (I_O + m_b e^2 sin^2 phi) phi'^2 / 2 and
V = (m_e + m_b) g e (1 - cos phi) + T0 s + k s^2/2, s = l - (h - r),
l = sqrt(r^2 + h^2 - 2 r h cos phi), dl/dphi = r h sin(phi) / l.
dV/dphi = sin(phi) [(m_e + m_b) g e + (T0 + k s) r h / l]; the bracket is > 0 because
s >= 0 (l >= h - r), so the equilibria are sin(phi) = 0 only: phi = 0 and phi = pi.
K(0) = (m_e + m_b) g e + T0 r h / (h - r) > 0 (k drops out: s = 0 and ds/dphi = 0 there),
K(pi) = -(m_e + m_b) g e - (T0 + 2 k r) r h / (h + r) < 0. M(0) = I_O. The guide friction
gives C(0) = c e^2 sin^2(0) = 0, so the mode at phi = 0 is undamped to first order.
Eq. 8 is d/dt of T plus dV/dphi, term by term as above; eq. 9 and §4.1-4.4 agree."""
import numpy as np

EQUILIBRIA = (2, 1)  # phi = 0 stable, phi = pi unstable
MISPRINTS = set()


def valid(v):
    # the disc's central inertia I_O - m_e e^2 must stay positive; h > r keeps l > 0
    return v["I_O"] > v["m_e"] * v["e"] ** 2 and v["h"] > v["r"]


def frequencies(v):
    K = (v["m_e"] + v["m_b"]) * v["g"] * v["e"] + v["T0"] * v["r"] * v["h"] / (v["h"] - v["r"])
    return [np.sqrt(K / v["I_O"])]
