"""Fig. 33, eq. 98 linearized at s = m g/k, phi = 0: the two equations decouple,
m s'' + k s = 0 and (m s_eq^2 + I_G) phi'' + m g s_eq phi = 0."""
import numpy as np

EQUILIBRIA = (1, 1)  # s = mg/k; phi = pi would need s < 0
MISPRINTS = {
    # d/dt((m s^2 + I_G) phi') = (m s^2 + I_G) phi'' + 2 m s s' phi': eq. 98 drops the
    # Coriolis term 2 m s s' phi' from the phi equation.
    "Fig. 33, eq. 98, row 2",
}


def frequencies(v):
    s = v["m"] * v["g"] / v["k"]
    return sorted([np.sqrt(v["k"] / v["m"]),
                   np.sqrt(v["m"] * v["g"] * s / (v["m"] * s**2 + v["I_G"]))])
