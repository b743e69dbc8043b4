"""Fig. 34, eq. 99-101, by hand, in q = (y, phi).
T = m y'^2/2 + m b cos(phi) y' phi' + (I_G + m b^2) phi'^2/2 (O on x = 0,
G = O + b (cos phi, sin phi)); V = m g (y + b sin phi) + k u^2/2 with the spring's stretch
u = y + l tan(phi) - l0 (P at height y + l tan phi on the slot x = l);
D = c (y' + l sec^2(phi) phi')^2 / 2.
In the variables (u, phi) the potential separates:
V = [m g u + k u^2/2] + m g (b sin(phi) - l tan(phi)) + const,
so the equilibria are u = -m g/k and b cos(phi) = l sec^2(phi), i.e. cos^3(phi) = l/b
(eq. 101); on the branch cos(phi) < 0 both terms of f' = b cos - l sec^2 are negative: no
root. Two equilibria, phi = +-arccos((l/b)^(1/3)); f'' = -b sin(phi) - 2 l sec^2 tan(phi)
is < 0 at the positive root (saddle) and > 0 at the negative root (minimum: stable).
At an equilibrium (u = -m g/k, L = l sec^2(phi)):
M = [[m, m b cos], [m b cos, I_G + m b^2]],
K = [[k, k L], [k L, k L^2 - 2 m g l sec^2 tan - m g b sin]],  C = c [[1, L], [L, L^2]].
In (u, phi) the two modes decouple at an equilibrium: y' = u' - L phi', so the
cross inertia is m (b cos(phi) - L) = 0 there (b cos = l sec^2 is eq. 101), V separates and
D = c u'^2/2. Hence M = diag(m, I_G + m b^2 - m L^2) = diag(m, I_G + m b^2 sin^2(phi)),
K = diag(k, m g f''), and with l = b cos^3(phi): f'' = -b sin - 2 b sin = -3 b sin(phi).
Modes: u with |s| = sqrt(k/m) (damping ratio c/(2 sqrt(k m)); |s| is the undamped value
for one degree of freedom) and an undamped phi mode
w^2 = 3 m g b |sin(phi)| / (I_G + m b^2 sin^2(phi)) at the stable root.
Eq. 99 (T, V), eq. 100 (Lagrange with Q = -dD/dq') and eq. 101 agree with this; the §9.7
energies reduce to eq. 99 at x = 0.

Slot force on O (§9.7, Fig. 36), by Newton on the solid, horizontally. G = O + b (cos, sin)
with O on x = 0: a_Gx = -b (sin(phi) phi'' + cos(phi) phi'^2). The forces on the solid with
a horizontal component: the slot at O, F (along +x), and the massless pin P. P is pushed
by the spring-damper along its own slot x = l, upwards with F_s = -k u - c u' (u' =
y' + l sec^2(phi) phi'), by the fixed slot horizontally, and by the solid along the
solid's normal n = (-sin, cos): N n. P's vertical balance F_s - N cos(phi) = 0 gives
N = F_s / cos(phi), and the pin pushes the solid with N n, whose x-component is
-F_s tan(phi). So m a_Gx = F - F_s tan(phi):
    F = m b (-sin(phi) phi'' - cos(phi) phi'^2) + F_s tan(phi)
(the printed F_enllac, with F_molla = -k u). Power of the non-conservative forces: only
the damper, P_nc = -c u'^2 (eq. 99's P_nc, expanded)."""
import numpy as np

EQUILIBRIA = (2, 1)
MISPRINTS = set()


def valid(v):
    # an equilibrium needs b > l (eq. 101); keep it away from the degenerate b = l
    return v["l"] < 0.9 * v["b"]


def frequencies(v):
    m, b, I_G, k, l, g = (v[n] for n in ("m", "b", "I_G", "k", "l", "g"))
    sin = np.sqrt(1 - (l / b) ** (2 / 3))  # |sin(phi)| at cos(phi) = (l/b)^(1/3)
    w_phi = np.sqrt(3 * m * g * b * sin / (I_G + m * b**2 * sin**2))
    return sorted([np.sqrt(k / m), w_phi])


def slot_force(v, q, qd, qdd):
    """F on O along +x by Newton (docstring); q = (x, y, phi, s) arrays of shape (N, 4)."""
    m, b, k, c, l0, l = (v[n] for n in ("m", "b", "k", "c", "l0", "l"))
    y, phi = q[:, 1], q[:, 2]
    yd, w = qd[:, 1], qd[:, 2]
    a = qdd[:, 2]
    F_s = -k * (y + l * np.tan(phi) - l0) - c * (yd + l * w / np.cos(phi) ** 2)
    return m * b * (-np.sin(phi) * a - np.cos(phi) * w**2) + F_s * np.tan(phi)
