"""Fig. 11, eq. 14 with h = 0 (the unexcited system): a pendulum of length l0 whose
particle also turns (central inertia I_G): (I_G + m l0^2) phi'' + m g l0 sin(phi) = 0; rest
states phi = 0 (stable) and pi. The radial equation of the particle gives the pull
F = m (g cos(phi) + l phi'^2 - l''), l'' = -h'': the printed F, m (-h'' + h'^2 + g cos(phi))
cos(phi), differs from it."""
import numpy as np

EQUILIBRIA = (2, 1)
MISPRINTS = {"Fig. 11, eq. 14 (string pull F)"}


def frequencies(v):
    return [np.sqrt(v["m"] * v["g"] * v["l0"] / (v["I_G"] + v["m"] * v["l0"] ** 2))]
