"""Fig. 31, eq. 86: (M + m) x'' + c x' + k x = m omega^2 e cos(omega t); the frame carries
the whole rotor mass: omega_n = sqrt(k/(M + m))."""
import numpy as np

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def frequencies(v):
    return [np.sqrt(v["k"] / (v["M"] + v["m"]))]
