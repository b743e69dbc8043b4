"""Exact solutions, independent of the symbolic derivation and of any ODE solver.

Each is named by its mathematics; a system names the one that solves its equations in
its `exact_solution`. Each takes the parameter values (by the parameter names it
documents), the initial state and sample times, and returns (q, qd) arrays of shape (N, n).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np
import scipy.linalg
import scipy.optimize
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
    x, v = _harmonically_forced(values["m"], values["c"], values["k"], -1j * values["F0"],
                                values["Omega"], q0[0], qd0[0], t)
    return x[:, None], v[:, None]


def base_excited_relative(values: Mapping[str, float], q0, qd0, t: np.ndarray):
    """Base y = Y sin(W t) prescribed, block's relative coordinate z (§8.2):
    m z'' + c z' + k z = -m y'' = m Y W^2 sin(W t). Coordinates (y, z)."""
    Y, W = values["Y"], values["Omega"]
    z, zd = _harmonically_forced(values["m"], values["c"], values["k"],
                                 -1j * values["m"] * Y * W**2, W, q0[1], qd0[1], t)
    return np.column_stack([Y * np.sin(W * t), z]), np.column_stack([Y * W * np.cos(W * t), zd])


def rotating_slot_eq84(values: Mapping[str, float], q0, qd0, t: np.ndarray):
    """Disc turned at phi = w t, block along the slot (Fig. 29, eq. 84):
    m x'' + c x' + (k - m w^2) x = m g sin(w t), stable or not. Coordinates (phi, x)."""
    m, w = values["m"], values["omega"]
    x, xd = _harmonically_forced(m, values["c"], values["k"] - m * w**2,
                                 -1j * m * values["g"], w, q0[1], qd0[1], t)
    return np.column_stack([w * t, x]), np.column_stack([np.full_like(t, w), xd])


def unbalanced_rotor_eq86(values: Mapping[str, float], q0, qd0, t: np.ndarray):
    """Frame x, rotor turned at phi = w t (Fig. 31, eq. 86):
    (M + m) x'' + c x' + k x = m e w^2 cos(w t). Coordinates (x, phi)."""
    m, w = values["m"], values["omega"]
    x, xd = _harmonically_forced(values["M"] + m, values["c"], values["k"],
                                 m * values["e"] * w**2, w, q0[0], qd0[0], t)
    return np.column_stack([x, w * t]), np.column_stack([xd, np.full_like(t, w)])


def _harmonically_forced(m: float, c: float, k: float, F: complex, W: float, x0: float,
                         v0: float, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """m x'' + c x' + k x = Re(F exp(i W t)) from (x0, v0): the particular solution from
    the complex frequency response (k may be negative: an unstable system) plus the
    homogeneous one by the exact matrix exponential."""
    H = 1.0 / (k - m * W**2 + 1j * c * W)
    xp = np.real(F * H * np.exp(1j * W * t))
    vp = np.real(1j * W * F * H * np.exp(1j * W * t))
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    y0 = np.array([x0 - xp[0], v0 - vp[0]])
    # exp(A t) y0 on every sample: eigen-decomposition when diagonalisable, else expm
    evals, V = np.linalg.eig(A)
    if abs(evals[0] - evals[1]) > 1e-9 * max(1.0, abs(evals[0])):
        coef = np.linalg.solve(V, y0.astype(complex))
        yh = np.real((V[None, :, :] * (coef * np.exp(np.outer(t, evals)))[:, None, :]).sum(axis=2))
    else:
        yh = np.array([scipy.linalg.expm(A * ti) @ y0 for ti in t])
    return xp + yh[:, 0], vp + yh[:, 1]


# --- piecewise-linear oscillator with elastic end stops (monograph §2.1) -----------------


def _linear_piece(m: float, C: float, K: float, y0: float, v0: float,
                  t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """m y'' + C y' + K y = 0 from (y0, v0), any damping: with s = C/(2m) and
    D = K/m - s^2, y = exp(-s t) (y0 Co(t) + (v0 + s y0) Si(t)) and
    y' = exp(-s t) (v0 Co(t) - (s v0 + (K/m) y0) Si(t)), where Co = cos(sqrt(D) t),
    Si = sin(sqrt(D) t)/sqrt(D) (cosh, sinh over damped; 1, t critically damped)."""
    s = C / (2.0 * m)
    D = K / m - s * s
    if D > 0:
        w = np.sqrt(D)
        co, si = np.cos(w * t), t * np.sinc(w * t / np.pi)
    elif D < 0:
        w = np.sqrt(-D)
        co, si = np.cosh(w * t), np.sinh(w * t) / w
    else:
        co, si = np.ones_like(t), t
    decay = np.exp(-s * t)
    return (decay * (y0 * co + (v0 + s * y0) * si),
            decay * (v0 * co - (s * v0 + K / m * y0) * si))


@dataclass(frozen=True)
class StopEvent:
    """A switching instant of the end-stop oscillator: `kind` "hit" (|x| reaches l going
    out, the stop engages) or "release" (back to l going in); `side` +1 right, -1 left;
    `velocity` x' at that instant."""

    t: float
    kind: str
    side: int
    velocity: float


@dataclass(frozen=True)
class _Piece:
    start: float
    side: int  # 0 between the stops, +1 / -1 against the right / left stop
    x0: float
    v0: float


def _stop_pieces(values: Mapping[str, float], x0: float, v0: float, t_end: float):
    """The chain of linear pieces from (x0, v0) up to t_end, and the events between them.

    On a piece with stiffness K and neutral point x_n (0 between the stops, +-k2 l / K
    against them) the motion is `_linear_piece` in y = x - x_n. A piece ends at the first
    root of x(t) = +-l: the piece's closed form is sampled at 1/64 of its period to bracket
    the zeros of x' (simple, a half period apart), x is monotonic between them, so each
    crossing is bracketed there and found by brentq to round-off."""
    m, k1, c, k2, l = (values[n] for n in ("m", "k1", "c", "k2", "l"))
    C = 2.0 * c
    pieces, events = [], []
    t0, x, v = 0.0, float(x0), float(v0)
    side = 0 if abs(x) < l or (abs(x) == l and x * v <= 0) else int(np.sign(x))
    while True:
        pieces.append(_Piece(t0, side, x, v))
        K = 2.0 * k1 + (k2 if side else 0.0)
        x_n = side * k2 * l / K
        horizon = t_end - t0
        if horizon <= 0:
            break

        def state(tau, x=x, v=v, K=K, x_n=x_n):
            y, yd = _linear_piece(m, C, K, x - x_n, v, np.atleast_1d(np.asarray(tau, float)))
            return y + x_n, yd

        resolution = 2 * np.pi / np.sqrt(K / m) / 64
        grid = np.linspace(0.0, horizon, int(np.ceil(horizon / resolution)) + 2)
        _, vg = state(grid)
        turns = [scipy.optimize.brentq(lambda s: state(s)[1][0], a, b, xtol=1e-15,
                                       rtol=4 * np.finfo(float).eps)
                 for a, b, va, vb in zip(grid[:-1], grid[1:], vg[:-1], vg[1:])
                 if va * vb < 0]
        nodes = [0.0] + [s for s in turns if s > 0] + [horizon]
        targets = (l, -l) if side == 0 else (side * l,)
        found = None
        for a, b in zip(nodes[:-1], nodes[1:]):
            xa, xb = state(a)[0][0], state(b)[0][0]
            for target in targets:
                ga, gb = xa - target, xb - target
                if a == 0.0 and ga == 0.0:
                    continue  # the piece starts on this boundary
                if ga * gb <= 0 and gb != ga:
                    found = (scipy.optimize.brentq(lambda s: state(s)[0][0] - target, a, b,
                                                   xtol=1e-15, rtol=4 * np.finfo(float).eps),
                             target)
                    break
            if found:
                break
        if found is None:
            break
        tau, target = found
        v = float(state(tau)[1][0])
        t0, x = t0 + tau, target
        if side == 0:
            side = int(np.sign(target))
            events.append(StopEvent(t0, "hit", side, v))
        else:
            events.append(StopEvent(t0, "release", side, v))
            side = 0
    return pieces, events


def oscillator_with_elastic_stops(values: Mapping[str, float], q0, qd0, t: np.ndarray):
    """m x'' + 2 c x' + 2 k1 x + s(x) = 0 with the stops s = k2 (x - l) for x > l,
    k2 (x + l) for x < -l, zero between (§2.1, Fig. 1): piecewise exact, each linear piece
    in closed form, the switching instants found on the closed forms (`elastic_stop_events`)."""
    pieces, _ = _stop_pieces(values, float(q0[0]), float(qd0[0]), float(np.max(t)))
    m, k1, c, k2, l = (values[n] for n in ("m", "k1", "c", "k2", "l"))
    starts = np.array([p.start for p in pieces])
    which = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(pieces) - 1)
    x, v = np.empty(len(t)), np.empty(len(t))
    for i, p in enumerate(pieces):
        sel = which == i
        if not np.any(sel):
            continue
        K = 2.0 * k1 + (k2 if p.side else 0.0)
        x_n = p.side * k2 * l / K
        y, yd = _linear_piece(m, 2.0 * c, K, p.x0 - x_n, p.v0, t[sel] - p.start)
        x[sel], v[sel] = y + x_n, yd
    return x[:, None], v[:, None]


def elastic_stop_events(values: Mapping[str, float], x0: float, v0: float,
                        t_end: float) -> list[StopEvent]:
    """The instants the stops of `oscillator_with_elastic_stops` are hit and released up to
    t_end, each a root of its piece's closed form to round-off."""
    return _stop_pieces(values, x0, v0, t_end)[1]


SOLUTIONS: dict[str, Callable] = {
    "rigid_pendulum_elliptic": rigid_pendulum_elliptic,
    "forced_linear_oscillator": forced_linear_oscillator,
    "base_excited_relative": base_excited_relative,
    "rotating_slot_eq84": rotating_slot_eq84,
    "unbalanced_rotor_eq86": unbalanced_rotor_eq86,
    "oscillator_with_elastic_stops": oscillator_with_elastic_stops,
}


# --- two free masses and a spring (Italian notes §5.3.1) ------------------------------


def free_pair_under_constant_force(values: Mapping[str, float], q0, qd0, t: np.ndarray):
    """Two masses m joined by a spring k, a constant force F on mass 1, no ground;
    coordinates (x1, dx), x1 of mass 1, dx the spring's stretch. Newton on each mass:
    m x1'' = F + k dx, m x2'' = -k dx. Their sum moves the centre of mass
    x_CG = x1 + (l0 + dx)/2 at F/(2m); their difference gives
    dx'' + (2k/m) dx = -F/m, a harmonic motion at w = sqrt(2k/m) about -F/(2k). Then
    x1 = x_CG - (l0 + dx)/2."""
    m, k, F = values["m"], values["k"], values["F"]
    w = np.sqrt(2 * k / m)
    s_eq = -F / (2 * k)
    x10, s0 = float(q0[0]), float(q0[1])
    v10, sd0 = float(qd0[0]), float(qd0[1])
    s = s_eq + (s0 - s_eq) * np.cos(w * t) + sd0 / w * np.sin(w * t)
    sd = -(s0 - s_eq) * w * np.sin(w * t) + sd0 * np.cos(w * t)
    a = F / (2 * m)
    v_cg0 = v10 + sd0 / 2
    x1 = x10 + (s0 - s) / 2 + v_cg0 * t + a * t**2 / 2
    v1 = v_cg0 + a * t - sd / 2
    return np.column_stack([x1, s]), np.column_stack([v1, sd])


SOLUTIONS["free_pair_under_constant_force"] = free_pair_under_constant_force
