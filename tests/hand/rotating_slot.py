"""Fig. 29, eq. 84 in the disc's frame: m x'' + c x' + (k - m omega^2) x = m g sin(omega t);
with the weight off, the characteristic equation m s^2 + c s + (k - m omega^2) = 0 (a real
pair, one positive, above the critical speed sqrt(k/m))."""
import numpy as np

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def frequencies(v):
    m, c, K = v["m"], v["c"], v["k"] - v["m"] * v["omega"] ** 2
    disc = c**2 - 4 * m * K
    if disc < 0:
        return [np.sqrt(K / m)]  # |s| of the complex pair
    r = np.sqrt(disc)
    return sorted([abs(-c + r) / (2 * m), abs(-c - r) / (2 * m)])
