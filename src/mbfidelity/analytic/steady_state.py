"""The linear steady-state response of a driven system to its harmonic excitation
(monograph §8.1-8.7).

About the rest state of the free coordinates with the excitation off (`linear`), the free
coordinates obey M x'' + C x' + K x = F(t), where F(t) = -R_f is what the excitation
leaves in the free rows of R = M q'' + h - Q at that rest state (the prescribed motion
with its amplitudes, time loads, the weight in a turning frame). F is sampled over whole
periods and projected on 1, cos(W t), sin(W t) for each excitation frequency W of the
system; each harmonic's response is X = (K - W^2 M + i W C)^-1 F. The actuator force of
each prescribed coordinate follows from its own row, linearized the same way. A response
is written x(t) = amplitude cos(W t + phase).

For a linear system this is the exact steady state (the transient decays away); for a
nonlinear one it is the first-order response, and the part of F that the harmonics do not
carry is reported (`harmonic_residual`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..systems import System
from . import memo
from .linear import operating_equilibrium, unexcited_values
from .numeric import numeric_model

#: whole periods of the slowest excitation sampled, and samples per fastest period
PERIODS, SAMPLES_PER_PERIOD = 4, 64


@dataclass(frozen=True)
class Harmonic:
    """One line of the steady state: `quantity` "position" (a free coordinate),
    "actuator_force" (the actuator of a prescribed coordinate) or "observable" (one of
    the system's `observables`, named in `coordinate`)."""

    coordinate: str
    quantity: str
    frequency_hz: float
    amplitude: float
    phase: float
    #: complex amplitude, x(t) = Re(phasor exp(i W t))
    phasor: complex

    def as_dict(self) -> dict:
        return {"coordinate": self.coordinate, "quantity": self.quantity,
                "frequency_hz": self.frequency_hz, "amplitude": self.amplitude,
                "phase": self.phase}


@dataclass(frozen=True)
class SteadyState:
    harmonics: tuple[Harmonic, ...]
    #: max |F - its harmonic projection| / max |F|: 0 for a purely harmonic excitation
    harmonic_residual: float
    #: why there is no steady state ("" when there is one)
    reason: str = ""

    def of(self, coordinate: str, quantity: str = "position") -> list[Harmonic]:
        return [h for h in self.harmonics if h.coordinate == coordinate
                and h.quantity == quantity]


def excitation_frequencies(system: System, values) -> list[float]:
    return [system.evaluate(w, values) for w in system.excitation_frequencies(system.symbols)]


def steady_state(system: System, values) -> SteadyState:
    """The linear steady-state response (module docstring); empty with the reason when
    the system has no excitation frequency or its rest state is unstable. Kept in the
    persistent cache (analytic/memo.py) under the parameter values."""
    return memo.cached(system, "steady_state", (dict(values), PERIODS, SAMPLES_PER_PERIOD),
                       lambda: _steady_state(system, values))


def _steady_state(system: System, values) -> SteadyState:
    freqs = excitation_frequencies(system, values)
    if not freqs:
        return SteadyState((), 0.0, "the system declares no harmonic excitation")
    eq = operating_equilibrium(system, values)
    if not eq.stable:
        return SteadyState((), 0.0, "the rest state is unstable: no steady state (the motion "
                                    "grows)")
    model = numeric_model(system.id, values)
    model0 = numeric_model(system.id, unexcited_values(system, values))
    f, p = model.independent, model.driven
    span = PERIODS * 2 * np.pi / min(freqs)
    N = int(np.ceil(span * max(freqs) / (2 * np.pi) * SAMPLES_PER_PERIOD))
    t = np.linspace(0.0, span, N, endpoint=False)
    q = np.tile(eq.q, (N, 1))
    qd = np.zeros((N, model.n))
    qdd = np.zeros((N, model.n))
    if p:
        qp, qdp, qddp = model.motion(t)
        q[:, p], qd[:, p], qdd[:, p] = qp, qdp, qddp
    R = np.array([model.residual(q[k], qd[k], qdd[k], t[k]) for k in range(N)])
    basis = [np.ones(N)] + [g(w * t) for w in freqs for g in (np.cos, np.sin)]
    A = np.column_stack(basis)
    coef, *_ = np.linalg.lstsq(A, R, rcond=None)
    fitted = A @ coef
    F_scale = max(float(np.max(np.abs(R[:, f]))), 1e-300)
    residual = float(np.max(np.abs(fitted[:, f] - R[:, f])) / F_scale)
    # actuator rows linearized about the unexcited rest state
    qdd0 = np.zeros(model.n)
    if p:
        qdd0[p] = model0.motion(0.0)[2]
    qd0 = np.zeros(model.n)
    if p:
        qd0[p] = model0.motion(0.0)[1]
    Mfull, Jqd, Jq = model0.residual_jacobians(eq.q, qd0, qdd0, 0.0)
    names = system.coordinates
    observables = observable_functions(system, values)
    harmonics = []
    for j, w in enumerate(freqs):
        a, b = coef[1 + 2 * j], coef[2 + 2 * j]
        phasor_R = a - 1j * b  # R_k(t) = Re(phasor exp(i w t))
        D = eq.K - w**2 * eq.M + 1j * w * eq.C
        X = np.linalg.solve(D, -phasor_R[f])
        for i, x in zip(f, X):
            harmonics.append(_line(names[i], "position", w, x))
        for k, name in zip(p, model.actuators):
            tau = phasor_R[k] + (Jq[k, f] + 1j * w * Jqd[k, f] - w**2 * Mfull[k, f]) @ X
            harmonics.append(_line(names[k], "actuator_force", w, tau))
        for label, (value_of, gradient) in observables.items():
            o = value_of(*q.T)
            o = np.broadcast_to(np.asarray(o, dtype=float), (N,))
            oc, *_ = np.linalg.lstsq(A, o, rcond=None)
            grad = np.asarray(gradient(*eq.q), dtype=float).reshape(-1)
            phasor = (oc[1 + 2 * j] - 1j * oc[2 + 2 * j]) + grad[f] @ X
            harmonics.append(_line(label, "observable", w, phasor))
    return SteadyState(tuple(harmonics), residual)


def observable_functions(system: System, values) -> dict:
    """name -> (value(q...), gradient(q...)) of each observable at these parameters,
    compiled from its expression in the coordinate symbols."""
    from ..systems import coordinate_symbols

    q = [coordinate_symbols(c)[0] for c in system.coordinates]
    out = {}
    for name, expr in system.observables(system.symbols).items():
        e = sp.sympify(expr).xreplace(system.subs(values))
        out[name] = (sp.lambdify(q, e, modules="numpy"),
                     sp.lambdify(q, [sp.diff(e, x) for x in q], modules="numpy"))
    return out


def _line(coordinate: str, quantity: str, w: float, phasor: complex) -> Harmonic:
    return Harmonic(coordinate, quantity, w / (2 * np.pi), float(abs(phasor)),
                    float(np.angle(phasor)), complex(phasor))
