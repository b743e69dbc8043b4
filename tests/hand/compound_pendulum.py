"""Fig. 7, eq. 5: I_O phi'' + m g l phi = 0 (for the uniform bar, the defaults, I_O =
m L^2/3 and l = L/2)."""
import numpy as np

EQUILIBRIA = (2, 1)  # phi = 0 (stable), pi (unstable)
MISPRINTS = set()


def frequencies(v):
    return [np.sqrt(v["m"] * v["g"] * v["l"] / v["I_O"])]
