"""Fig. 12 linearized: (I_G + m rho0^2) phi'' + m g rho0 phi = 0, m rho'' + k rho = 0."""
import numpy as np

EQUILIBRIA = (2, 1)  # (0, rho0) stable; (pi, rho0 - 2mg/k) unstable
MISPRINTS = {
    # the Coriolis term is 2 m rho rho' phi'; the printed 2 m phi' rho' lacks the factor
    # rho (not even dimensionally consistent)
    "Fig. 12, equations of motion (unnumbered, after eq. 15), row 1",
    # along the arm gravity gives m g cos(phi), balanced by the preload m g at phi = 0:
    # the printed equation drops m g (1 - cos phi) (harmless once linearized)
    "Fig. 12, equations of motion (unnumbered, after eq. 15), row 2",
}


def frequencies(v):
    return sorted([np.sqrt(v["k"] / v["m"]),
                   np.sqrt(v["m"] * v["g"] * v["rho0"] / (v["I_G"] + v["m"] * v["rho0"] ** 2))])
