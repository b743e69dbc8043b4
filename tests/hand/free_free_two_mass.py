"""Italian notes §5.3.1, by hand, in the coordinates (x1, dx) with x2 = x1 + l0 + dx:
T = m x1'^2/2 + m (x1' + dx')^2/2, V = k dx^2/2, Q = (F, 0). So M = [[2m, m], [m, m]],
K = [[0, 0], [0, k]], and det(M s^2 + K) = s^2 (m^2 s^4 + 2 m k s^2): a rigid-body mode
(s = 0, reported once) and the relative oscillation s^2 = -2k/m. The relative equilibrium
(dx constant, both masses at a = F/(2m)): row x1, 2 m a = F; row dx, m a + k dx = 0, so
dx = -F/(2k) (eq. 5.52). One relative equilibrium, its relative motion stable."""
import numpy as np

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def frequencies(v):
    return [0.0, np.sqrt(2 * v["k"] / v["m"])]
