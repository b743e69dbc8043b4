"""Fig. 20, §7.1, by hand. x = h tan(phi), x' = h sec^2(phi) phi', so
T = (I_O + m2 h^2 sec^4 phi) phi'^2 / 2, V = k h^2 tan^2(phi)/2 + m1 g l (1 - cos phi),
generalized damper force Q = -(2 F0/pi) arctan(x'/v0) h sec^2(phi); its power Q phi' =
-(2 F0/pi) arctan(x'/v0) x' is the printed P_nc (the spring has a potential: not in P_nc).
m'(phi)/2 = 2 m2 h^2 sec^4(phi) tan(phi) (as printed). Linearized at 0:
M = I_O + m2 h^2, C = (2 F0/pi)(1/v0) h^2, K = k h^2 + m1 g l; a single degree of freedom,
so |s| = sqrt(K/M) whatever the damping.
Equilibria: dV/dphi = sin(phi) (k h^2 / cos^3(phi) + m1 g l). On the branch |phi| < pi/2
only phi = 0. The slot is a whole line through O, so a second assembly branch exists
(cos(phi) < 0, pin in the slot above O): there only phi = pi (k h^2/|cos|^3 >= k h^2 >
m1 g l at the defaults), with K = k h^2 - m1 g l > 0 and the same damping: stable."""
import numpy as np

EQUILIBRIA = (2, 2)  # phi = 0 and the inverted-branch phi = pi, both stable
MISPRINTS = {
    # the damper term of the printed equation of motion has 2 F0 / v0 in front of the
    # arctan; the generalized force of the law -(2 F0/pi) arctan(x'/v0) (the printed P_nc)
    # is (2 F0/pi) arctan(h sec^2(phi) phi'/v0) h sec^2(phi): pi, not v0
    "Fig. 20, §7.1 equation of motion",
}


def valid(v):
    # the bar's central inertia I_O - m1 l^2 must stay positive
    return v["I_O"] > v["m1"] * v["l"] ** 2


def frequencies(v):
    M = v["I_O"] + v["m2"] * v["h"] ** 2
    K = v["k"] * v["h"] ** 2 + v["m1"] * v["g"] * v["l"]
    return [np.sqrt(K / M)]
