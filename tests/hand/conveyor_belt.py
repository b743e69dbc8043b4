"""§7.2, by hand. With x down the incline and the belt's force -Ft(v0 + x'):
m x'' + c x' + k x - m g sin(alpha) + Ft(v0 + x') = 0. At rest (x' = 0) the slip is v0, so
x_eq = (m g sin(alpha) - Ft(v0)) / k, the only rest state. Linearized, Ft(v0 + e') =
Ft(v0) + Ft'(v0) e' with Ft'(v) = 2 a2 v - a1 on v > 0: m e'' + (c + 2 a2 v0 - a1) e' + k e = 0,
undamped frequency sqrt(k/m), unstable where c + 2 a2 v0 - a1 < 0, i.e. below
v0* = (a1 - c) / (2 a2) (0.3 m/s printed). At the defaults (v0 = 0.29) the rest state is
unstable."""
import numpy as np

EQUILIBRIA = (1, 0)
#: at v0 = 0.29 m/s the reduced damping c + Ft'(v0) = 2 + (2*10*0.29 - 8) = -0.2 N s/m < 0
OPERATING_POINT_STABLE = False
MISPRINTS = set()


def frequencies(v):
    return [np.sqrt(v["k"] / v["m"])]


def threshold(v):
    """The belt speed where c + Ft'(v0) = 0."""
    return (v["a1"] - v["c"]) / (2 * v["a2"])
