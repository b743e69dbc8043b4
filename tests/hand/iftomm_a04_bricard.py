"""IFToMM A04, Bricard's mechanism, worked out here apart from the description: the five
rods' hinge points and rotations written with elementary rotations (y, z, x, y, z hinges
from the ground), on the motion's symmetric form.

Symmetry. A rotation of the cube by a third of a turn about its diagonal maps each
hinge of the loop on the hinge two further along, axes and rods included. The motion
through the cube position is a single curve (one degree of freedom), so it is mapped on
itself: q1 = q3 = q5 = th and q2 = q4 = ph, with one closure relation f(th, ph) = 0 (a
component of the loop's closure; `frequencies` checks that every closure equation
vanishes on the curve it follows).

Along that curve the mechanism is a system of one degree of freedom with T = m_e(th)
th'^2 / 2 and V(th) = m g sum(y_k) (the rods' centres): at an equilibrium V' = 0, and
its frequency is w^2 = V'' / m_e, with ph' = -f_th / f_ph and ph'' from differentiating
f = 0 twice. The rods are square prisms (m a^2 / 6 about the length, m (L^2 + a^2) / 12
across it).

Equilibria: V along the closed curve of the motion has one minimum (the loop hanging,
stable) and one maximum (unstable): two, one stable (the curve's only extremes, found
here by sampling V along it).
"""
from functools import lru_cache

import numpy as np
import sympy as sp
from scipy.optimize import brentq

EQUILIBRIA = (2, 1)
MISPRINTS = set()
#: the operating point's seed is the release position, not an equilibrium; the stable
#: equilibrium is the one `analyze` reports
OPERATING_POINT_STABLE = True

TH, PH = sp.symbols("th ph", real=True)
_L, _M, _A, _G = sp.symbols("L m a g", positive=True)


def _rx(t):
    return sp.Matrix([[1, 0, 0], [0, sp.cos(t), -sp.sin(t)], [0, sp.sin(t), sp.cos(t)]])


def _ry(t):
    return sp.Matrix([[sp.cos(t), 0, sp.sin(t)], [0, 1, 0], [-sp.sin(t), 0, sp.cos(t)]])


def _rz(t):
    return sp.Matrix([[sp.cos(t), -sp.sin(t), 0], [sp.sin(t), sp.cos(t), 0], [0, 0, 1]])


_TURNS = (_ry, _rz, _rx, _ry, _rz)
_UNIT = (sp.Matrix([0, 1, 0]), sp.Matrix([0, 0, 1]), sp.Matrix([1, 0, 0]),
         sp.Matrix([0, 1, 0]), sp.Matrix([0, 0, 1]))
_DIRECTION = ((1, 0, 0), (0, -1, 0), (0, 0, 1), (-1, 0, 0), (0, 1, 0))


@lru_cache(maxsize=1)
def _curve():
    """Compiled functions of (th, ph, L, m, a, g): the five closure residuals and their
    first and second partials, V and its partials, and m_e's pieces."""
    angles = (TH, PH, TH, PH, TH)
    R, point = sp.eye(3), sp.zeros(3, 1)
    centres, rotations, axes = [], [], []
    for turn, unit, angle, d in zip(_TURNS, _UNIT, angles, _DIRECTION):
        axes.append(R * unit)  # the hinge axis in world axes (before it turns)
        R = R * turn(angle)
        rod = R * sp.Matrix(d) * _L
        centres.append(point + rod / 2)
        rotations.append(R)
        point = point + rod
    closure = list(point - sp.Matrix([0, 0, _L])) + [
        (rotations[-1] * sp.Matrix([1, 0, 0]))[1], (rotations[-1] * sp.Matrix([1, 0, 0]))[2]]
    V = _M * _G * sum(c[1] for c in centres)
    args = (TH, PH, _L, _M, _A, _G)

    def f(e):
        return sp.lambdify(args, e, "numpy")

    out = {"closure": [f(c) for c in closure],
           "closure_d": [[f(sp.diff(c, x)) for x in (TH, PH)] for c in closure],
           "closure_dd": [[f(sp.diff(c, x, y)) for x, y in ((TH, TH), (TH, PH), (PH, PH))]
                          for c in closure],
           "V": f(V), "V_d": [f(sp.diff(V, x)) for x in (TH, PH)],
           "V_dd": [f(sp.diff(V, x, y)) for x, y in ((TH, TH), (TH, PH), (PH, PH))]}
    # velocities per unit th' with ph' = s: centre k moves with dc/dth + dc/dph s; rod k
    # turns with w_k = sum of the world axes of hinges 1..k times their rates (1 or s)
    rates = (1, 0, 1, 0, 1), (0, 1, 0, 1, 0)
    pieces = []
    for k, (c, Rk, d) in enumerate(zip(centres, rotations, _DIRECTION)):
        dc = [c.diff(TH), c.diff(PH)]
        w = [sum((axes[j] * rates[i][j] for j in range(k + 1)), sp.zeros(3, 1))
             for i in range(2)]
        across = _M * (_L**2 + _A**2) / 12
        inertia = sp.diag(*[_M * _A**2 / 6 if abs(x) else across for x in d])
        Iw = Rk * inertia * Rk.T
        pieces.append((dc, w, Iw))
    # m_e = A + 2 B s + C s^2
    A = sum(_M * (dc[0].T * dc[0])[0] + (w[0].T * Iw * w[0])[0] for dc, w, Iw in pieces)
    B = sum(_M * (dc[0].T * dc[1])[0] + (w[0].T * Iw * w[1])[0] for dc, w, Iw in pieces)
    C = sum(_M * (dc[1].T * dc[1])[0] + (w[1].T * Iw * w[1])[0] for dc, w, Iw in pieces)
    out["mass"] = [f(A), f(B), f(C)]
    return out


def _on_curve(th: float, p: tuple, guess: float) -> float:
    """ph on the motion's curve at th, by Newton on the closure row of largest slope."""
    fns = _curve()
    ph = guess
    for _ in range(60):
        k = int(np.argmax([abs(fp(th, ph, *p)) for _, fp in fns["closure_d"]]))
        step = fns["closure"][k](th, ph, *p) / fns["closure_d"][k][1](th, ph, *p)
        ph -= step
        if abs(step) < 1e-15:
            break
    residual = max(abs(c(th, ph, *p)) for c in fns["closure"])
    if residual > 1e-12 * p[0]:
        raise ValueError(f"the symmetric form leaves the closure at {residual}")
    return ph


def _slopes(th, ph, p):
    """(ph', ph'') along the curve, from f = 0 differentiated once and twice."""
    fns = _curve()
    k = int(np.argmax([abs(fp(th, ph, *p)) for _, fp in fns["closure_d"]]))
    ft, fp = (g(th, ph, *p) for g in fns["closure_d"][k])
    ftt, ftp, fpp = (g(th, ph, *p) for g in fns["closure_dd"][k])
    s = -ft / fp
    return s, -(ftt + 2 * ftp * s + fpp * s * s) / fp


def _dV(th, ph, p):
    fns = _curve()
    s, _ = _slopes(th, ph, p)
    Vt, Vp = (g(th, ph, *p) for g in fns["V_d"])
    return Vt + Vp * s


def frequencies(v):
    """The hanging mechanism's one frequency: the minimum of V along the motion, from
    the release position (th = ph = 0) by continuation in th."""
    p = (v["L"], v["m"], v["a"], v["g"])
    fns = _curve()
    # continuation along the curve in th from the cube position; V' changes sign at
    # the hanging minimum
    grid = np.linspace(0.0, 3.0, 61)
    phs, ph = [], 0.0
    for th in grid:
        ph = _on_curve(th, p, ph)
        phs.append(ph)
    dV = [_dV(th, ph, p) for th, ph in zip(grid, phs)]
    i = next(k for k in range(len(grid) - 1) if dV[k] < 0 <= dV[k + 1])
    th = brentq(lambda t: _dV(t, _on_curve(t, p, phs[i]), p), grid[i], grid[i + 1],
                xtol=1e-15, rtol=1e-15)
    ph = _on_curve(th, p, phs[i])
    s, s2 = _slopes(th, ph, p)
    Vt, Vp = (g(th, ph, *p) for g in fns["V_d"])
    Vtt, Vtp, Vpp = (g(th, ph, *p) for g in fns["V_dd"])
    stiffness = Vtt + 2 * Vtp * s + Vpp * s * s + Vp * s2
    A, B, C = (g(th, ph, *p) for g in fns["mass"])
    return [float(np.sqrt(stiffness / (A + 2 * B * s + C * s * s)))]
