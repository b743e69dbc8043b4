"""§8.2, relative coordinate: m z'' + c z' + k z = -m y''(t); with the base at rest the
block oscillates at sqrt(k/m) (the base's mass only loads the actuator)."""
import numpy as np

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def frequencies(v):
    return [np.sqrt(v["k"] / v["m"])]
