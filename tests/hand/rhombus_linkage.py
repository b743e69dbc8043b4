"""Fig. 13 (§4.4), worked by hand on the rhombus O-A-P-B (side 2l, P on the vertical
through O, phi = angle of OA above the horizontal, spring k between the centres of OA and
OB with free length l0 = sqrt2 l - 4 m g/k).

Positions: G_OA = l(cos, sin), G_OB = l(-cos, sin), G_AP = l(cos, 3 sin), G_BP = l(-cos, 3 sin);
every bar turns at |phi_dot|. Hence
  T = (4 I_G + (4 + 16 cos^2 phi) m l^2) phi_dot^2 / 2              (= printed eq. 34, 35)
  V = m g l (1 + 1 + 3 + 3) sin phi + k/2 (2 l |cos phi| - l0)^2
    = 8 m g l (sin phi + cos phi - sqrt2/2) + 2 k l^2 (cos phi - sqrt2/2)^2 + 8 m^2 g^2/k
      for cos phi > 0: the printed E_p of eq. 34 up to a constant
  V' = 8 m g l cos phi - 2 k l sin phi (2 l cos phi - l0)        (cos phi > 0)
  V'(45 deg) = 4 sqrt2 m g l - sqrt2 k l (4 m g/k) = 0
  V''(45 deg) = -4 sqrt2 m g l + [4 k l^2 sin^2 - 2 k l cos (2 l cos - l0)](45 deg)
              = 2 k l^2 - 8 sqrt2 m g l                           (= printed linearization)
  w^2 = (2 k l^2 - 8 sqrt2 m g l) / (4 I_G + 12 m l^2).

Equilibria at the defaults (m g = 9.81, l = 0.25, k = 400, l0 = 0.25545): V' = 0 on
cos phi > 0 at 45 deg (minimum), at 27.60 deg (maximum: V' > 0 below it, V'(0) = 8 m g l,
and the collapse barrier V(27.6) - V(45) = 0.334 J) and at -65.16 deg (the rhombus hanging
below O, minimum); none else (V' sampled on a 2e5-point grid of (-90, 90) deg changes sign
only there). phi -> pi - phi (A and B swapped) mirrors all three. At +-90 deg the spring
has zero length and V has kinks (not equilibria); phi = 0, pi (P = O) is a singular
position, not an equilibrium (V'(0) = 8 m g l - 2 k l (0)(2 l - l0) = 19.6 N m). So 6,
4 stable.
"""
import numpy as np

# 45 deg and the hanging -65.2 deg (stable), 27.6 deg (unstable), each with its mirror
EQUILIBRIA = (6, 4)
MISPRINTS = set()
# With the free length that §4.4 implies (the spring guarantees the equilibrium at 45 deg),
# every printed formula of the section agrees: eq. 34 (T and E_p up to 8 m^2 g^2/k), eq. 35,
# eq. 36, phi_eq = 45 deg, and the linearized inertia and stiffness.
# (Reading the spring as relaxed at 45 deg would make E_p, eq. 35,
# eq. 36, phi_eq and the stiffness all wrong by the preload term 8 m g l (cos phi - sqrt2/2).)


def valid(v):
    """45 deg must be a stable equilibrium: 2 k l^2 > 8 sqrt2 m g l (with a margin); this
    also keeps the free length positive."""
    return v["k"] * v["l"] > 1.1 * 4 * np.sqrt(2) * v["m"] * v["g"]


def frequencies(v):
    m, l, I_G, k, g = v["m"], v["l"], v["I_G"], v["k"], v["g"]
    return [np.sqrt((2 * k * l**2 - 8 * np.sqrt(2) * m * g * l) / (4 * I_G + 12 * m * l**2))]
