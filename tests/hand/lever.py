"""Fig. 10, eq. 12-13, by hand. G = e (cos phi, sin phi), so V = m g e sin(phi) +
k (phi - phi_n)^2 / 2 and T = I_O phi'^2 / 2; the force's moment about O is -l F(t).
Rest with F = 0: k (phi - phi_n) + m g e cos(phi) = 0. With phi_n = phi0 + m g e
cos(phi0)/k this is k (phi - phi0) + m g e (cos phi - cos phi0) = 0, eq. 12's static part,
solved by phi0. Its derivative k - m g e sin(phi) > 0 when k > m g e: one rest state, and
the stiffness there, k - m g e sin(phi_eq), is eq. 13's at phi_eq = phi0."""
import numpy as np
from scipy.optimize import brentq

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def valid(v):
    # k > m g e keeps the static moment monotonic: one rest state, near phi0
    return v["k"] > v["m"] * v["g"] * v["e"] and v["I_O"] > v["m"] * v["e"] ** 2


def rest_angle(v):
    mge = v["m"] * v["g"] * v["e"]

    def moment(phi):
        return v["k"] * (phi - v["phi_n"]) + mge * np.cos(phi)

    # moment is increasing; it changes sign within mge/k of phi_n
    span = mge / v["k"] + 1.0
    return brentq(moment, v["phi_n"] - span, v["phi_n"] + span, xtol=1e-15)


def frequencies(v):
    stiffness = v["k"] - v["m"] * v["g"] * v["e"] * np.sin(rest_angle(v))
    return [np.sqrt(stiffness / v["I_O"])]
