"""IFToMM A01: a point mass m on a massless bar L, T = m L^2 phi'^2 / 2 and
V = -m g L cos(phi), so m L^2 phi'' + m g L sin(phi) = 0: w = sqrt(g/L) about phi = 0."""
import numpy as np

EQUILIBRIA = (2, 1)  # phi = 0 (stable), pi (unstable)
MISPRINTS = set()


def frequencies(v):
    return [np.sqrt(v["g"] / v["L"])]
