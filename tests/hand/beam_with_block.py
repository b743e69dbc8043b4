"""§6.1, Fig. 17: the simply supported beam with the block at a = c l, as the chain of N
rigid segments of the description, by hand (a second derivation, from energies written
here, not from the code under test).

Segment b (length h = l/N, mass m_b, centre of mass c_b from its left node, central moment
I_b; the block m is folded into segment c N at its right end, the node x = c l: the chain
has such a node only when c N is an integer between 1 and N - 1, `block_node`). With
absolute angles th_i and e(th) = (cos th, sin th), its centre of mass is
sum_{k<b} h e(th_k) + c_b e(th_b), so d/dth_i of it is a_bi e'(th_i), a_bi = h (i < b),
c_b (i = b), 0 (i > b), and

    M_ij = cos(th_i - th_j) sum_b m_b a_bi a_bj + delta_ij I_i,
    V = sum_{i>1} (EI/h)(th_i - th_(i-1))^2 / 2 + g sum_b m_b y_b,
    Phi = h sum_i sin th_i = 0 (the roller on y = 0).

At an equilibrium grad V + lam grad Phi = 0; on the constraint's tangent space (basis S)
the modes solve det(S^T (V'' + lam Phi'') S - w^2 S^T M S) = 0.

N = 2 in closed form (the catalog's coarsest chain): th1 = -a, th2 = a keeps the roller on
y = 0, one coordinate a, with segment 1 (m1 = rho h + m, c1 = (rho h^2/2 + m h)/m1)
pinned and segment 2 sliding:
    V(a) = 2 k a^2 - g (m h + rho h^2) sin a,  k = EI/h,
    T = (m h^2 + rho h^3/3 + rho h^3 (9 sin^2 a + cos^2 a)/4 + rho h^3/12) a'^2 / 2,
so without gravity w^2 = 4k / (m h^2 + rho h^3 (1/3 + 1/4 + 1/12)) = (32 EI / l^3) /
(m + rho l / 3), the discrete analogue of Rayleigh's (48 EI / l^3) / (m + 17 rho l / 35).

Equilibria at the defaults: the chain straight up to its sag along +x, between its
supports, and its mirror along -x (every th near pi, the roller at x = -l): at both the
hinge springs EI/h exceed the moment of the loads, (m + rho l) g l, by EI/(h (m + rho l) g
l) = 20 at N = 4, so both are minima of V on the constraint: 2 stable. The chain can also
fold back through the pin's vertical, held there by the roller's force (a buckled chain
with hinges bent by O(1) rad): those are not counted here (`EQUILIBRIA` total None).
No printed formula describes the chain (eq. 62-68 estimate the continuum): no misprint.
"""
import math

import numpy as np
import scipy.linalg
import scipy.optimize

EQUILIBRIA = (None, 2)
MISPRINTS = set()


def block_node(v) -> int:
    """The node k = c N that carries the block (x = k h = c l)."""
    k = round(v["c"] * v["N"])
    assert 1 <= k <= v["N"] - 1 and math.isclose(k, v["c"] * v["N"]), "no node at c l"
    return k


def _segments(v):
    N, l, rho, m = int(v["N"]), v["l"], v["rho"], v["m"]
    h = l / N
    k = block_node(v)
    out = []
    for b in range(1, N + 1):
        if b == k:
            mass = rho * h + m
            c = (rho * h * h / 2 + m * h) / mass
            inertia = rho * h**3 / 12 + rho * h * (h / 2 - c) ** 2 + m * (h - c) ** 2
        else:
            mass, c, inertia = rho * h, h / 2, rho * h**3 / 12
        out.append((mass, c, inertia))
    return h, out


def _lever(h, segments):
    """a[b, i]: the lever of angle i for segment b's centre of mass."""
    N = len(segments)
    a = np.zeros((N, N))
    for b, (_, c, _) in enumerate(segments):
        a[b, :b] = h
        a[b, b] = c
    return a


def _mass_matrix(th, h, segments):
    a = _lever(h, segments)
    mass = np.array([s[0] for s in segments])
    coupling = (a * mass[:, None]).T @ a
    return coupling * np.cos(th[:, None] - th[None, :]) + np.diag([s[2] for s in segments])


def _potential_gradient_and_hessian(th, v, h, segments):
    N = len(th)
    k = v["EI"] / h
    g = v["g"]
    a = _lever(h, segments)
    mass = np.array([s[0] for s in segments])
    # gravity: y_b = sum_i a_bi sin th_i
    w = mass @ a  # sum_b m_b a_bi
    grad = g * w * np.cos(th)
    hess = np.diag(-g * w * np.sin(th))
    for i in range(1, N):
        d = th[i] - th[i - 1]
        grad[i] += k * d
        grad[i - 1] -= k * d
        hess[i, i] += k
        hess[i - 1, i - 1] += k
        hess[i, i - 1] -= k
        hess[i - 1, i] -= k
    return grad, hess


def straight_equilibrium(v) -> np.ndarray:
    """The sagged chain between the supports, from the straight one."""
    h, segments = _segments(v)
    N = len(segments)

    def equations(x):
        th, lam = x[:N], x[N]
        grad, _ = _potential_gradient_and_hessian(th, v, h, segments)
        return np.append(grad + lam * h * np.cos(th), h * np.sum(np.sin(th)))

    sol = scipy.optimize.fsolve(equations, np.zeros(N + 1), xtol=1e-14, full_output=True)
    return sol[0]


def frequencies(v):
    h, segments = _segments(v)
    N = len(segments)
    x = straight_equilibrium(v)
    th, lam = x[:N], x[N]
    _, hess = _potential_gradient_and_hessian(th, v, h, segments)
    stiffness = hess + lam * np.diag(-h * np.sin(th))
    S = scipy.linalg.null_space((h * np.cos(th))[None, :])
    M = _mass_matrix(th, h, segments)
    w2 = scipy.linalg.eigh(S.T @ stiffness @ S, S.T @ M @ S, eigvals_only=True)
    return sorted(math.sqrt(x) for x in w2)


def two_segment_frequency_without_gravity(v) -> float:
    return math.sqrt(32 * v["EI"] / v["l"] ** 3 / (v["m"] + v["rho"] * v["l"] / 3))


def bare_chain_frequency(v, k: int) -> float:
    """The k-th angular frequency of the chain without the block (m = 0) and without
    gravity, for any N, in closed form.

    Small transverse node displacements y_i (y_0 = y_N = 0, the roller sliding along x at
    second order): segment i turns by (y_i - y_(i-1))/h, so the hinge at node i bends by
    (y_(i+1) - 2 y_i + y_(i-1))/h and V = (EI / 2h^3) sum_i (second difference of y)^2;
    a segment's kinetic energy (centre speed (y'_(i-1) + y'_i)/2, central moment rho h^3/12)
    is (rho h / 6)(y'_(i-1)^2 + y'_(i-1) y'_i + y'_i^2), the consistent mass of a linear
    element. Both operators are symmetric Toeplitz with ends that vanish, so y_i =
    sin(k pi i / N) is a mode: with phi = k pi / N, the second difference has eigenvalue
    -4 sin^2(phi/2) and the mass rho h (2 + cos phi)/3, so

        w_k^2 = 48 EI sin^4(phi/2) / (rho h^4 (2 + cos phi)).

    Against the continuum's w_k = (k pi / l)^2 sqrt(EI/rho): the ratio is (2 sin(phi/2)/
    phi)^2 sqrt(3/(2 + cos phi)) = 1 - phi^4/1440 - ..., the second-order terms of the
    stiffness (-phi^2/12) and of the mass (+phi^2/12) cancelling: fourth order in 1/N."""
    h = v["l"] / v["N"]
    phi = k * math.pi / v["N"]
    return math.sqrt(48 * v["EI"] * math.sin(phi / 2) ** 4
                     / (v["rho"] * h**4 * (2 + math.cos(phi))))
