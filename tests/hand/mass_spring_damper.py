"""eq. 76-77: w0 = sqrt(k/m), zeta = c/(2 sqrt(k m))."""
import numpy as np

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def frequencies(v):
    return [np.sqrt(v["k"] / v["m"])]
