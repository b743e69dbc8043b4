"""Andrews' squeezer from its published equations (Hairer & Wanner II §VII.7; the Test
Set's andrews problem), written here in the test set's coordinates q = (beta, Theta,
gamma, Phi, delta, Omega, epsilon) and independently of the description: the closure
g(q) = 0 (E reached three ways from the rod), the spring's and the drive's potential
V = c0 (L - l0)^2 / 2 - mom beta, and the published mass matrix M(q).

At an equilibrium (grad V + G^T lam = 0, g = 0) the one mode on the constraint manifold has
w^2 = n^T (H_V + sum lam_i H_gi) n / n^T M n, n spanning the null space of G = dg/dq.

Equilibria, counted by reasoning: with g = 0 the dyads A-G-E and A-H-E carry no load, so
the statics is the loop O-F-E-B under the torque and the spring: one equilibrium where the
spring holds the torque (stable, beta near -3.0) and one where it balances it unstably
(beta near -0.12), on the assembly branch of the published state; each with the 2 x 2
assemblies of the two dyads: 8 equilibria, 4 stable.
"""
import numpy as np
import sympy as sp

from mbfidelity.systems.benchmarks.iftomm_a03_andrews import (
    D_, DA, E_, EA, FA, RA, RR, SA, SB, SC, SD, SS, TA, TB, U_, UA, UB, XA, XB, XC, YA, YB,
    YC, ZF, ZT)

EQUILIBRIA = (8, 4)
MISPRINTS = set()
#: the equilibrium search (analytic/linear.py) seeds one coordinate at a time when a
#: full grid over seven angles would be too many starts, and misses one dyad assembly
SEARCH_MISSES = ("beyond MAX_GRID_STARTS the closed-loop search seeds one angle at a "
                 "time, so a combination of two dyad assemblies away from the operating "
                 "point is not reached")
OPERATING_POINT_STABLE = True

STATICS = {"c0": 4530.0, "l0": 0.07785, "mom": 0.033, "g": 0.0}


def relations(v):
    """The equilibrium depends on c0, l0 and mom alone (g = 0: the masses do not load
    it): they are held at the published values, so that random draws vary the masses and
    inertias, on which the frequency depends, about the same equilibrium (scaled, the
    stable equilibrium can leave the basin of the operating point's guess)."""
    return {**v, **STATICS}


_q = sp.symbols("beta Theta gamma Phi delta Omega epsilon", real=True)
_ORDER = ("beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon")  # test set order


def _equations():
    be, th, ga, ph, de, om, ep = _q
    c, s = sp.cos, sp.sin
    ex, ey = RR * c(be) - D_ * c(be + th), RR * s(be) - D_ * s(be + th)  # E from the rod
    g = sp.Matrix([
        ex - (XB + SS * s(ga)), ey - (YB - SS * c(ga)),
        ex - (XA + ZT * c(de) + E_ * s(ph + de)), ey - (YA + ZT * s(de) - E_ * c(ph + de)),
        ex - (XA + U_ * s(ep) + ZF * c(om + ep)), ey - (YA - U_ * c(ep) + ZF * s(om + ep)),
    ])
    xd, yd = XB + SD * c(ga) + SC * s(ga), YB + SD * s(ga) - SC * c(ga)
    c0, l0, mom = sp.symbols("c0 l0 mom", positive=True)
    V = c0 * (sp.sqrt((xd - XC) ** 2 + (yd - YC) ** 2) - l0) ** 2 / 2 - mom * be
    m = sp.symbols("m1:8", positive=True)
    i = sp.symbols("I1:8", positive=True)
    M = sp.zeros(7, 7)
    M[0, 0] = m[0] * RA**2 + m[1] * (RR**2 - 2 * DA * RR * c(th) + DA**2) + i[0] + i[1]
    M[1, 0] = M[0, 1] = m[1] * (DA**2 - DA * RR * c(th)) + i[1]
    M[1, 1] = m[1] * DA**2 + i[1]
    M[2, 2] = m[2] * (SA**2 + SB**2) + i[2]
    M[3, 3] = m[3] * (E_ - EA) ** 2 + i[3]
    M[4, 3] = M[3, 4] = m[3] * ((E_ - EA) ** 2 + ZT * (E_ - EA) * s(ph)) + i[3]
    M[4, 4] = (m[3] * (ZT**2 + 2 * ZT * (E_ - EA) * s(ph) + (E_ - EA) ** 2)
               + m[4] * (TA**2 + TB**2) + i[3] + i[4])
    M[5, 5] = m[5] * (ZF - FA) ** 2 + i[5]
    M[6, 5] = M[5, 6] = m[5] * ((ZF - FA) ** 2 - U_ * (ZF - FA) * s(om)) + i[5]
    M[6, 6] = (m[5] * ((ZF - FA) ** 2 - 2 * U_ * (ZF - FA) * s(om) + U_**2)
               + m[6] * (UA**2 + UB**2) + i[5] + i[6])
    lam = sp.symbols("lam1:7", real=True)
    lagrangian = V + sum(l * gi for l, gi in zip(lam, g))
    params = (c0, l0, mom, *m, *i)
    G = g.jacobian(_q)
    statics = sp.Matrix([sp.diff(lagrangian, x) for x in _q] + list(g))
    unknowns = (*_q, *lam)
    return dict(
        statics=sp.lambdify([unknowns, params], statics, "numpy"),
        statics_jacobian=sp.lambdify([unknowns, params], statics.jacobian(unknowns), "numpy"),
        G=sp.lambdify([_q, params], G, "numpy"),
        H=sp.lambdify([unknowns, params], sp.hessian(lagrangian, _q), "numpy"),
        M=sp.lambdify([_q, params], M, "numpy"),
    )


_EQ = None

#: the stable equilibrium on the published state's assembly branch (the operating point)
_START = np.array([-3.0, 3.04, 0.041, -0.534, 0.524, 0.534, 1.048])


def frequencies(v):
    global _EQ
    if _EQ is None:
        _EQ = _equations()
    params = (v["c0"], v["l0"], v["mom"], *(v[f"m{k}"] for k in range(1, 8)),
              *(v[f"I{k}"] for k in range(1, 8)))
    x = np.concatenate([_START, np.zeros(6)])
    for _ in range(100):  # Newton on the statics with multipliers
        step = np.linalg.solve(_EQ["statics_jacobian"](x, params),
                               np.ravel(_EQ["statics"](x, params)))
        x -= step
        if np.max(np.abs(step)) < 1e-15:
            break
    q = x[:7]
    _, _, vt = np.linalg.svd(_EQ["G"](q, params))
    n = vt[-1]
    k = n @ _EQ["H"](x, params) @ n
    m = n @ _EQ["M"](q, params) @ n
    return [np.sqrt(k / m)]
