"""Fig. 14-16. Equilibria from eq. 50: phi = +-pi/2, and the third one
sin(phi*) = (h - b - l*)/r with l* = (2 l0/pi) arccot(m g/F0), plus its mirror pi - phi*
(same block height, pin on the other side) which eq. 50's arcsin omits. Stiffness from
eq. 52 at phi* (the first two terms cancel there since F0 cot = m g):
K = F0 r^2 cos^2(phi*) (pi/(2 l0)) csc^2, csc^2 = 1 + (m g/F0)^2; M = I_O + m r^2 cos^2."""
import numpy as np

EQUILIBRIA = (4, 2)  # 0 and pi stable, +-pi/2 unstable: four, where Fig. 16 shows three
MISPRINTS = {
    # with m(phi) = I_O + m r^2 cos^2(phi) (eq. 46), eq. 38's term m'(phi) phi'^2/2 is
    # -m r^2 sin(phi) cos(phi) phi'^2; eq. 51 prints it with a spurious factor 1/2
    "Fig. 14, eq. 51",
}


def _third(v):
    l_star = 2 * v["l0"] / np.pi * (np.pi / 2 - np.arctan(v["m"] * v["g"] / v["F0"]))
    return (v["h"] - v["b"] - l_star) / v["r"]


def valid(v):
    return (abs(_third(v)) < 0.9 and v["h"] - v["b"] + v["r"] < 2 * v["l0"]
            and v["h"] - v["b"] - v["r"] > 0)


def frequencies(v):
    cos2 = 1 - _third(v) ** 2
    csc2 = 1 + (v["m"] * v["g"] / v["F0"]) ** 2
    k = v["F0"] * v["r"] ** 2 * cos2 * np.pi / (2 * v["l0"]) * csc2
    return [np.sqrt(k / (v["I_O"] + v["m"] * v["r"] ** 2 * cos2))]
