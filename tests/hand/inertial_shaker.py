"""Fig. 30, eq. 85, by hand. The inner mass moves at x' + y' in the fixed frame, so
T = M x'^2/2 + m (x' + y')^2/2, V = k x^2/2, D = c x'^2/2 and Lagrange's x row is
(M + m) x'' + m y'' + c x' + k x = 0: eq. 85, both lines. With y = 0 the frame and the
inner mass move together on the spring: w = sqrt(k/(M + m)). The y row gives the actuator
force m (x'' + y'')."""
import numpy as np

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def frequencies(v):
    return [np.sqrt(v["k"] / (v["M"] + v["m"]))]
