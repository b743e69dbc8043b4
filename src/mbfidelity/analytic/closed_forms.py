"""Exact solutions, independent of the symbolic derivation and of any ODE solver.

Each is named by its mathematics; a system names the one that solves its equations in
its `exact_solution`. Each takes the parameter values (by the parameter names it
documents), the initial state and sample times, and returns (q, qd) arrays of shape (N, n).
"""
from __future__ import annotations

from typing import Callable, Mapping

import numpy as np
import scipy.linalg
import scipy.special


def rigid_pendulum_elliptic(values: Mapping[str, float], q0, qd0, t: np.ndarray):
    """Libration of a rigid pendulum about its pivot O (mass m, centre of mass at l from
    O, moment of inertia I_O about O), I_O phi'' + m g l sin(phi) = 0 (Fig. 7, eq. 4),
    any amplitude < pi: sin(phi/2) = k sn(w0 t + u0 | k^2), k = sin(phi_max/2), w0 = sqrt(m g l / I_O)."""
    m, l, I_O, g = values["m"], values["l"], values["I_O"], values["g"]
    w0 = np.sqrt(m * g * l / I_O)
    phi0, dphi0 = float(q0[0]), float(qd0[0])
    k = np.sqrt(np.sin(phi0 / 2) ** 2 + (dphi0 / (2 * w0)) ** 2)
    if not k < 1:
        raise ValueError("the pendulum rotates over the top: no libration solution")
    mpar = k**2
    if k == 0:
        zeros = np.zeros((len(t), 1))
        return zeros, zeros.copy()
    K = scipy.special.ellipk(mpar)
    ratio = np.clip(np.sin(phi0 / 2) / k, -1.0, 1.0)
    u_first = scipy.special.ellipkinc(np.arcsin(ratio), mpar)
    # cn(u0) has the sign of the initial velocity
    u0 = u_first if dphi0 >= 0 else 2 * K - u_first
    if dphi0 == 0:
        u0 = K if phi0 > 0 else -K
    sn, cn, dn, _ = scipy.special.ellipj(w0 * t + u0, mpar)
    phi = 2 * np.arcsin(np.clip(k * sn, -1, 1))
    dphi = 2 * k * w0 * cn  # d/dt sin(phi/2) = k w0 cn dn, and cos(phi/2) = dn
    return phi[:, None], dphi[:, None]


def forced_linear_oscillator(values: Mapping[str, float], q0, qd0, t: np.ndarray):
    """m x'' + c x' + k x = F0 sin(Omega t) (eq. 79): the particular solution from the
    complex frequency response plus the homogeneous one by the exact matrix exponential."""
    m, k, c = values["m"], values["k"], values["c"]
    F0, W = values["F0"], values["Omega"]
    H = 1.0 / (k - m * W**2 + 1j * c * W)
    xp = np.imag(F0 * H * np.exp(1j * W * t))
    vp = np.imag(1j * W * F0 * H * np.exp(1j * W * t))
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    y0 = np.array([q0[0] - xp[0], qd0[0] - vp[0]])
    # exp(A t) y0 on every sample: eigen-decomposition when diagonalisable, else expm
    evals, V = np.linalg.eig(A)
    if abs(evals[0] - evals[1]) > 1e-9 * max(1.0, abs(evals[0])):
        coef = np.linalg.solve(V, y0.astype(complex))
        yh = np.real((V[None, :, :] * (coef * np.exp(np.outer(t, evals)))[:, None, :]).sum(axis=2))
    else:
        yh = np.array([scipy.linalg.expm(A * ti) @ y0 for ti in t])
    return (xp + yh[:, 0])[:, None], (vp + yh[:, 1])[:, None]


SOLUTIONS: dict[str, Callable] = {
    "rigid_pendulum_elliptic": rigid_pendulum_elliptic,
    "forced_linear_oscillator": forced_linear_oscillator,
}
