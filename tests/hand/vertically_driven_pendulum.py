"""§8.3, eq. 80 with the pivot at rest (Y = 0, the unexcited system): (I_G + m l^2) phi''
+ m l g sin(phi) = 0, rest states phi = n pi (one hanging, stable; one inverted); about
hanging (the operating point, eq. 81) the characteristic equation
(I_G + m l^2) s^2 + m l g = 0. With the pivot shaken, Floquet judges (tests/test_cli.py)."""
import numpy as np

EQUILIBRIA = (2, 1)
MISPRINTS = set()


def frequencies(v):
    return [np.sqrt(v["m"] * v["l"] * v["g"] / (v["I_G"] + v["m"] * v["l"] ** 2))]
