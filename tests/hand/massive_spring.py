"""§6.2, Fig. 18: the spring (stiffness k, length l, mass M_s = rho l) hung from the ceiling
with the block m, as a chain of N lumped masses, by hand.

Lumping: N segments of stiffness N k; the segment mass M_s / N split half to each end
node, the ceiling's half lost: nodes 1..N-1 carry mu = M_s / N, node N (the block)
m_N = m + M_s / (2N). Coordinates: u_i the stretch of segment i, so node j sits
x_j = u_1 + ... + u_j (+ relaxed lengths) below the ceiling.

N = 1: T = (m + M_s/2) u1'^2 / 2, V = k u1^2 / 2 - (m + M_s/2) g u1:
w = sqrt(k / (m + M_s/2)) (against Rayleigh's sqrt(k / (m + M_s/3)) of eq. 70), and the
equilibrium u1 = g (m + M_s/2) / k.

N = 2: x1 = u1, x2 = u1 + u2; mu = M_s/2, m_2 = m + M_s/4.
T = mu u1'^2/2 + m_2 (u1' + u2')^2/2, V = 2k (u1^2 + u2^2)/2 - g (mu x1 + m_2 x2):
  M = [[mu + m_2, m_2], [m_2, m_2]],  K = [[2k, 0], [0, 2k]],
  det(K - w^2 M) = 0:  mu m_2 w^4 - 2k (mu + 2 m_2) w^2 + 4k^2 = 0;
  equilibrium: dV/du2 = 0 gives u2 = g m_2 / (2k), dV/du1 = 0 gives u1 = g (mu + m_2)/(2k).

Any N: in absolute node displacements y_j (y_0 = 0 at the ceiling) an interior node's
equation is -w^2 mu y_j = N k (y_{j+1} - 2 y_j + y_{j-1}); y_j = sin(j theta) solves it
with w^2 = 4 N k sin^2(theta/2) / mu = (4 N^2 k / M_s) sin^2(theta/2). The end node,
-w^2 m_N y_N = N k (y_{N-1} - y_N), then reads (with w^2 M_s/(2N) = N k (1 - cos theta))
w^2 m sin(N theta) = N k sin(theta) cos(N theta), i.e. without poles
2 N sin(theta/2) sin(N theta) - (M_s/m) cos(theta/2) cos(N theta) = 0: one root with
N theta in each ((n-1) pi, (n-1) pi + pi/2), n = 1..N (the sign changes there).
Equilibrium: segment i carries the weight below it, u_i = g (m + M_s (N - i + 1/2)/N) / (N k).

One equilibrium (the statics are linear, K = N k I regular), stable. No printed formula
describes the chain (eq. 69-70 estimate the continuum): no misprint.
"""
import math

import numpy as np
import scipy.optimize

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def frequencies(v):
    N, k, m = int(v["N"]), v["k"], v["m"]
    Ms = v["rho"] * v["l"]

    def end_condition(theta):
        return (2 * N * math.sin(theta / 2) * math.sin(N * theta)
                - Ms / m * math.cos(theta / 2) * math.cos(N * theta))

    out = []
    for n in range(1, N + 1):
        low, high = (n - 1) * math.pi / N, ((n - 1) * math.pi + math.pi / 2) / N
        theta = scipy.optimize.brentq(end_condition, low, high, xtol=1e-15, rtol=1e-15)
        out.append(2 * N * math.sqrt(k / Ms) * math.sin(theta / 2))
    return sorted(out)


def one_element_frequency(v):
    return math.sqrt(v["k"] / (v["m"] + v["rho"] * v["l"] / 2))


def two_element_matrices(v):
    """(M, K) of the N = 2 chain in (u1, u2), as above."""
    mu, m2 = v["rho"] * v["l"] / 2, v["m"] + v["rho"] * v["l"] / 4
    return (np.array([[mu + m2, m2], [m2, m2]]), np.array([[2 * v["k"], 0.0], [0.0, 2 * v["k"]]]))


def two_element_frequencies(v):
    """Roots of mu m_2 w^4 - 2k (mu + 2 m_2) w^2 + 4 k^2 = 0."""
    mu, m2, k = v["rho"] * v["l"] / 2, v["m"] + v["rho"] * v["l"] / 4, v["k"]
    roots = np.roots([mu * m2, -2 * k * (mu + 2 * m2), 4 * k**2])
    return sorted(np.sqrt(roots.real))


def equilibrium(v):
    N = int(v["N"])
    Ms = v["rho"] * v["l"]
    return np.array([v["g"] * (v["m"] + Ms * (N - i + 0.5) / N) / (N * v["k"])
                     for i in range(1, N + 1)])
