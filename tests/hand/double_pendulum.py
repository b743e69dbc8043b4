"""Fig. 37: det(K - w^2 M) = 0 with the printed M and K (checked by hand:
M = [[I + 5ml^2, 2ml^2], [2ml^2, I + ml^2]], K = diag(3mgl, mgl))."""
import numpy as np

EQUILIBRIA = (4, 1)  # (0,0) stable; (0,pi), (pi,0), (pi,pi) unstable
MISPRINTS = set()


def frequencies(v):
    m, l, I, g = v["m"], v["l"], v["I"], v["g"]
    a, b, c = I + 5 * m * l**2, 2 * m * l**2, I + m * l**2
    k1, k2 = 3 * m * g * l, m * g * l
    # (k1 - a x)(k2 - c x) - b^2 x^2 = 0 with x = w^2
    x = np.roots([a * c - b**2, -(a * k2 + c * k1), k1 * k2])
    return sorted(np.sqrt(x.real))
