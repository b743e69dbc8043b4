"""Motion of a one-coordinate system whose force law jumps where the rate crosses a value
(dry friction at zero slip, §7.2): slip phases integrated, stick phases followed exactly.

A force element may jump across a surface q' = s (a `CoordinateForce` whose Piecewise
conditions involve the rate: `rate_surfaces` finds them from the description). On either
side the motion is smooth and is integrated by DOP853, each side with its own law (the
rate is held on the side's edge inside the right-hand side, so the stages of the step
that reaches the surface never see the other side's force). At the surface, with the
one-sided accelerations a+ = q''(q, s + 0) and a- = q''(q, s - 0), Filippov's convention
decides: if a+ <= 0 <= a- both sides push the motion onto the surface and it sticks there,
q' = s, q'' = 0 (the force holds any value between its two limits); otherwise it crosses.
A stick phase ends where a+ turns positive or a- negative along q = q_s + s (t - t_s): the
first sign change on the sample grid, refined by Brent's method to round-off. The
instants of every stick and release are returned with the motion.

The error of a solve is estimated against a second one at a looser tolerance (the switching
instants move with the slip phases' error and carry it forward).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np
import scipy.optimize
import sympy as sp
from scipy.integrate import solve_ivp

from ..systems import System
from ..systems.model import COORD, COORD_RATE, CoordinateForce

#: how far beyond the surface (relative to max(1, |s|)) a side's law is evaluated to read
#: its one-sided limit: the law's slope times this is far below the solve's tolerance
SIDE_OFFSET = 1e-12


@dataclass(frozen=True)
class RateSurface:
    """q'_i = rate, where a force on coordinate `coordinate` (index) jumps by `jump`."""

    coordinate: int
    rate: float
    jump: float


@dataclass(frozen=True)
class Switch:
    """An instant the motion sticks to the surface ("stick") or leaves it ("slip")."""

    t: float
    kind: str
    q: float


def rate_surfaces(system: System, values: Mapping[str, float]) -> list[RateSurface]:
    """The surfaces q' = s across which a coordinate force of the description jumps:
    boundaries of Piecewise conditions written in the rate (COORD_RATE)."""
    subs = system.subs(values)
    out = []
    for f in system.mechanism.forces:
        if not isinstance(f, CoordinateForce):
            continue
        law = sp.sympify(f.force)
        for pw in law.atoms(sp.Piecewise):
            for _, cond in pw.args:
                for rel in cond.atoms(sp.core.relational.Relational):
                    if COORD_RATE not in rel.free_symbols:
                        continue
                    boundary = sp.solve(sp.Eq(rel.lhs, rel.rhs), COORD_RATE)
                    for b in boundary:
                        s = float(sp.sympify(b).xreplace(subs))
                        delta = SIDE_OFFSET * max(1.0, abs(s)) * 1e3
                        at = law.xreplace(subs).xreplace({COORD: 0})
                        jump = float(at.xreplace({COORD_RATE: s + delta})
                                     - at.xreplace({COORD_RATE: s - delta}))
                        if abs(jump) > 1e-6 * max(1.0, abs(float(
                                at.xreplace({COORD_RATE: s + delta})))):
                            i = system.coordinates.index(f.coordinate)
                            if not any(r.coordinate == i and r.rate == s for r in out):
                                out.append(RateSurface(i, s, jump))
    return out


def integrate_with_sliding(acc: Callable[[float, float, float], float], x0: float, v0: float,
                           t: np.ndarray, surface: float, tol: float):
    """(x, v, a) at the sample times t and the switches, for x'' = acc(x, x', t) whose
    right-hand side jumps across x' = surface (module docstring)."""
    s = float(surface)
    delta = SIDE_OFFSET * max(1.0, abs(s))
    t = np.asarray(t, dtype=float)
    x_out, v_out, a_out = (np.full(len(t), np.nan) for _ in range(3))
    switches: list[Switch] = []

    def one_sided(x: float, tt: float) -> tuple[float, float]:
        return acc(x, s + delta, tt), acc(x, s - delta, tt)

    def side_at_surface(x: float, tt: float) -> int:
        a_plus, a_minus = one_sided(x, tt)
        if a_plus > 0:
            return 1
        if a_minus < 0:
            return -1
        return 0

    t0, x, v = float(t[0]), float(x0), float(v0)
    mode = int(np.sign(v - s)) if v != s else side_at_surface(x, t0)
    end = float(t[-1])
    while t0 < end:
        pending = (t >= t0) & np.isnan(x_out)
        if mode == 0:
            x_s, t_s = x, t0
            grid = np.concatenate([[t_s], t[pending & (t > t_s)]])

            def leaving(tt: float) -> float:
                a_plus, a_minus = one_sided(x_s + s * (tt - t_s), tt)
                return max(a_plus, -a_minus)

            k = next((i for i, tt in enumerate(grid) if leaving(tt) > 0), None)
            if k is None:
                t_release = end
            elif k == 0:
                t_release = t_s
            else:
                t_release = scipy.optimize.brentq(leaving, grid[k - 1], grid[k],
                                                  xtol=1e-15, rtol=4 * np.finfo(float).eps)
                while leaving(t_release) <= 0 and t_release < grid[k]:
                    t_release = np.nextafter(t_release, np.inf)
            sel = pending & (t <= t_release)
            x_out[sel] = x_s + s * (t[sel] - t_s)
            v_out[sel] = s
            a_out[sel] = 0.0
            if t_release >= end:
                break
            x = x_s + s * (t_release - t_s)
            v, t0 = s, float(t_release)
            mode = side_at_surface(x, t0)
            switches.append(Switch(t0, "slip", x))
            continue

        side = mode

        def rhs(tt, y, side=side):
            rate = max(y[1], s + delta) if side > 0 else min(y[1], s - delta)
            return [y[1], acc(y[0], rate, tt)]

        def reaches_surface(tt, y):
            return y[1] - s

        reaches_surface.terminal = True
        reaches_surface.direction = -side
        samples = t[pending]
        sol = solve_ivp(rhs, (t0, end), [x, v], method="DOP853", rtol=tol, atol=tol,
                        t_eval=samples, events=reaches_surface)
        if sol.status == -1:
            raise RuntimeError(f"sliding reference: slip phase failed: {sol.message}")
        n = sol.t.size
        idx = np.flatnonzero(pending)[:n]
        x_out[idx], v_out[idx] = sol.y[0], sol.y[1]
        a_out[idx] = [rhs(tt, y)[1] for tt, y in zip(sol.t, sol.y.T)]
        if sol.status == 0:
            break
        t0 = float(sol.t_events[0][0])
        x = float(sol.y_events[0][0][0])
        v = s
        mode = side_at_surface(x, t0)
        if mode == 0:
            switches.append(Switch(t0, "stick", x))
        elif mode == side:
            raise RuntimeError(f"sliding reference: the motion reaches x' = {s:g} at "
                               f"t = {t0:.6g} s and cannot leave it on its own side")
    return x_out, v_out, a_out, switches


def model_acceleration(model, coordinate: int = 0) -> Callable[[float, float, float], float]:
    """acc(x, x', t) of a one-coordinate numeric model."""
    if model.n != 1:
        raise ValueError("the sliding reference handles one coordinate "
                         f"(this model has {model.n})")

    def acc(x: float, v: float, tt: float) -> float:
        return float(model.acceleration(np.array([x]), np.array([v]), tt)[coordinate])

    return acc


@dataclass(frozen=True)
class LimitCycle:
    """The stick-slip cycle through a release state: amplitude (x_max - x_min)/2, the half
    range of x', the period (slip arc plus stick phase), the extremes, and the amplitude's
    error estimate (tight against loose solve)."""

    amplitude: float
    velocity_amplitude: float
    period: float
    x_min: float
    x_max: float
    error: float


def _slip_arc(acc, surface: float, x_release: float, t_release: float, tol: float):
    """From the release state (x_release, surface) to the next stick: the x extremes (at
    x' = 0, events), the lowest and highest x', and the arc's end."""
    s = float(surface)
    delta = SIDE_OFFSET * max(1.0, abs(s))
    side = 1 if acc(x_release, s + delta, t_release) > 0 else -1

    def rhs(tt, y):
        rate = max(y[1], s + delta) if side > 0 else min(y[1], s - delta)
        return [y[1], acc(y[0], rate, tt)]

    def reaches_surface(tt, y):
        return y[1] - s

    def turns(tt, y):
        return y[1]

    reaches_surface.terminal = True
    reaches_surface.direction = -side
    span = 1e3  # s: far beyond any period; the arc ends at the surface
    sol = solve_ivp(rhs, (t_release, t_release + span), [x_release, s], method="DOP853",
                    rtol=tol, atol=tol, events=(reaches_surface, turns), dense_output=True)
    if sol.status != 1:
        raise RuntimeError("limit cycle: the slip arc does not return to the surface")
    t_end = float(sol.t_events[0][0])
    x_end = float(sol.y_events[0][0][0])
    xs = [x_release, x_end] + [float(y[0]) for y in sol.y_events[1]]
    # x' is extremal where x'' = 0: sample the dense output finely and refine
    tt = np.linspace(t_release, t_end, 4001)
    v = sol.sol(tt)[1]
    k_lo, k_hi = int(np.argmin(v)), int(np.argmax(v))

    def extreme(k, sign):
        a, b = tt[max(k - 1, 0)], tt[min(k + 1, len(tt) - 1)]
        found = scipy.optimize.minimize_scalar(lambda u: sign * sol.sol(u)[1], bounds=(a, b),
                                               method="bounded", options={"xatol": 1e-14})
        return float(sol.sol(found.x)[1])

    v_lo, v_hi = min(extreme(k_lo, 1), s), max(extreme(k_hi, -1), s)
    return min(xs), max(xs), v_lo, v_hi, t_end, x_end


def limit_cycle(acc, surface: float, x_release: float, t_release: float = 0.0,
                tol: float = 1e-12) -> LimitCycle:
    """The stick-slip cycle through the release state (x_release, x' = surface) of
    `integrate_with_sliding`'s motion: one slip arc to the next stick, then the stick phase
    back to x_release at the surface speed."""
    def one(tol_):
        x_lo, x_hi, v_lo, v_hi, t_end, x_end = _slip_arc(acc, surface, x_release,
                                                         t_release, tol_)
        stick = (x_release - x_end) / surface
        return x_lo, x_hi, v_lo, v_hi, (t_end - t_release) + stick

    x_lo, x_hi, v_lo, v_hi, period = one(tol)
    loose = one(tol * 10)
    amplitude = (x_hi - x_lo) / 2
    error = abs((loose[1] - loose[0]) / 2 - amplitude)
    return LimitCycle(amplitude, (v_hi - v_lo) / 2, period, x_lo, x_hi, error)
