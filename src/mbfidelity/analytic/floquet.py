"""Floquet analysis of linear systems with periodic coefficients, x' = A(t) x, A(t + T) = A(t)
(monograph §8.3-8.4, eq. 81-83: the pendulum whose pivot is moved vertically, Mathieu).

The monodromy matrix Phi(T) is the state-transition matrix over one period, X' = A(t) X,
X(0) = I, solved with DOP853 at a tight tolerance (FLOQUET_RTOL); a second solve at a
looser tolerance (CHECK_RTOL) gives the error estimate of the multipliers (the eigenvalues
of Phi(T)): the largest distance between the two solves' multipliers, matched one to one.

Verdict, with the error e of the multipliers:
- unstable: a multiplier with |mu| > 1 + e (growth by |mu| per period, rate ln|mu| / T);
- stable: every |mu| < 1 - e (decay), or the multipliers within e of the unit circle are
  simple there (separated by more than 2 e from each other: bounded motion, the elliptic
  case of a conservative system, whose multipliers lie on the circle exactly);
- marginal: otherwise (a multiplier within e of the unit circle that is double there,
  the boundary of a tongue; or one within e of the circle that neither solve separates).
The margin is the distance from the verdict's boundary in multiplier units: |mu|max - 1
for growth, 1 - |mu|max for decay, the smallest separation of the multipliers on the
circle (minus 2 e) for bounded motion, and 0 for marginal.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.integrate
import scipy.optimize

from . import memo

#: relative tolerance of the monodromy solve
FLOQUET_RTOL = 1e-12
#: relative tolerance of the check solve that estimates the error
CHECK_RTOL = 1e-9
#: floor of the error estimate (round-off of the monodromy's eigenvalues)
ROUND_OFF = 1e-12


@dataclass
class FloquetResult:
    period: float
    monodromy: np.ndarray
    multipliers: np.ndarray
    error: float
    verdict: str
    margin: float

    @property
    def max_abs_multiplier(self) -> float:
        return float(np.max(np.abs(self.multipliers)))

    @property
    def growth_rate(self) -> float:
        """ln|mu|max / T: the exponential rate of the fastest-growing solution (1/s)."""
        return float(np.log(self.max_abs_multiplier) / self.period)

    @property
    def stable(self) -> bool | None:
        """True / False, None when marginal."""
        return {"stable": True, "unstable": False}.get(self.verdict)

    def as_dict(self) -> dict:
        return {
            "period": self.period,
            "floquet_multipliers": [[float(m.real), float(m.imag)] for m in self.multipliers],
            "floquet_max_abs_multiplier": self.max_abs_multiplier,
            "floquet_error": self.error,
            "stable": self.stable,
            "verdict": self.verdict,
            "margin": self.margin,
        }


def monodromy_matrix(A: Callable[[float], np.ndarray], period: float, size: int,
                     rtol: float = FLOQUET_RTOL) -> np.ndarray:
    """Phi(T) of x' = A(t) x: the columns are the solutions from the unit vectors."""
    def rhs(t, y):
        return (A(t) @ y.reshape(size, size)).ravel()

    sol = scipy.integrate.solve_ivp(rhs, (0.0, period), np.eye(size).ravel(), method="DOP853",
                                    rtol=rtol, atol=rtol * 1e-3)
    if not sol.success:
        raise RuntimeError(f"monodromy solve failed: {sol.message}")
    return sol.y[:, -1].reshape(size, size)


def _matched_distance(a: np.ndarray, b: np.ndarray) -> float:
    cost = np.abs(a[:, None] - b[None, :])
    rows, cols = scipy.optimize.linear_sum_assignment(cost)
    return float(np.max(cost[rows, cols]))


def classify(multipliers: np.ndarray, error: float) -> tuple[str, float]:
    """(verdict, margin) of the multipliers known within `error` (module docstring)."""
    mu = np.asarray(multipliers, complex)
    moduli = np.abs(mu)
    largest = float(np.max(moduli))
    if largest > 1.0 + error:
        return "unstable", largest - 1.0
    if largest < 1.0 - error:
        return "stable", 1.0 - largest
    on_circle = mu[np.abs(moduli - 1.0) <= error]
    if len(on_circle) < 2:
        return "stable", 1.0 - largest if largest < 1.0 else 0.0
    gaps = np.abs(on_circle[:, None] - on_circle[None, :])
    separation = float(np.min(gaps[~np.eye(len(on_circle), dtype=bool)]))
    if separation > 2.0 * error:
        return "stable", separation - 2.0 * error
    return "marginal", 0.0


def floquet(A: Callable[[float], np.ndarray], period: float, size: int) -> FloquetResult:
    """Monodromy, multipliers, their error and the verdict of x' = A(t) x over one period."""
    phi = monodromy_matrix(A, period, size, FLOQUET_RTOL)
    check = monodromy_matrix(A, period, size, CHECK_RTOL)
    mu = np.linalg.eigvals(phi)
    error = max(_matched_distance(mu, np.linalg.eigvals(check)),
                ROUND_OFF * max(1.0, float(np.max(np.abs(mu)))))
    verdict, margin = classify(mu, error)
    return FloquetResult(float(period), phi, mu, error, verdict, margin)


def second_order_system(M: Callable[[float], np.ndarray], C: Callable[[float], np.ndarray],
                        K: Callable[[float], np.ndarray]) -> Callable[[float], np.ndarray]:
    """A(t) of M(t) q'' + C(t) q' + K(t) q = 0 in the state (q, q')."""
    def A(t: float) -> np.ndarray:
        Mt, Ct, Kt = M(t), C(t), K(t)
        n = Mt.shape[0]
        return np.block([[np.zeros((n, n)), np.eye(n)],
                         [-np.linalg.solve(Mt, Kt), -np.linalg.solve(Mt, Ct)]])
    return A


def excitation_period(system, values) -> float:
    """The period of a system excited at one angular frequency (System.excitation_frequencies)."""
    frequencies = sorted({round(system.evaluate(w, values), 12)
                          for w in system.excitation_frequencies(system.symbols)} - {0.0})
    if len(frequencies) != 1:
        raise ValueError(f"{system.id}: Floquet analysis needs one excitation frequency "
                         f"(has {len(frequencies)})")
    return 2.0 * np.pi / abs(frequencies[0])


def driven_floquet(system, values) -> list[tuple[np.ndarray, FloquetResult]]:
    """Floquet analysis of a periodically driven system about each rest state of its free
    coordinates with the excitation off (`System.unexcited`): the variational equations
    M(t) dq'' + C(t) dq' + K(t) dq = 0 of the free coordinates there, with the prescribed
    motion on, from the compiled model. Where the excitation also forces the free
    coordinates (R_f(t) != 0 at rest), that forcing is the inhomogeneous term and leaves
    the multipliers of the variational equations unchanged. Kept in the persistent cache
    (analytic/memo.py) under the parameter values."""
    return memo.cached(system, "driven_floquet", (dict(values),),
                       lambda: _driven_floquet(system, values))


def _driven_floquet(system, values) -> list[tuple[np.ndarray, FloquetResult]]:
    from .linear import driven_coefficients, driven_rest_states
    from .modes import companion_matrix
    from .numeric import numeric_model

    model = numeric_model(system.id, dict(values))
    period = excitation_period(system, values)
    free = model.independent
    results = []
    for q in driven_rest_states(system, values, only_operating=False):
        q_free = q[free]
        def A(t: float, q_free=q_free) -> np.ndarray:
            return companion_matrix(*driven_coefficients(model, q_free, t))

        results.append((q, floquet(A, period, 2 * len(free))))
    return results


def periodic_coefficients(system, values) -> bool:
    """Whether a driven system's variational equations about its unexcited rest states
    have coefficients that vary with the prescribed motion (then stability is Floquet's
    question, not an equilibrium's)."""
    from .linear import _PROBE_TIMES, driven_coefficients, driven_rest_states
    from .numeric import numeric_model

    try:
        model = numeric_model(system.id, dict(values))
        rests = driven_rest_states(system, values, only_operating=True)
    except (ValueError, TypeError, RuntimeError, np.linalg.LinAlgError):
        return False
    for q in rests:
        first = driven_coefficients(model, q[model.independent], _PROBE_TIMES[0])
        for t in _PROBE_TIMES[1:]:
            later = driven_coefficients(model, q[model.independent], t)
            if any(not np.allclose(a, b, rtol=1e-9, atol=0) for a, b in zip(first, later)):
                return True
    return False


def driven_floquet_summary(system, values) -> list[dict]:
    """`driven_floquet` as data: per unexcited rest state, its coordinates, the period,
    the multipliers (re, im) and their moduli, the verdict, its margin and the error."""
    coords = list(system.coordinates)
    return [{"q": dict(zip(coords, q.tolist())), "period": r.period,
             "multipliers": [[complex(m).real, complex(m).imag] for m in r.multipliers],
             "moduli": [float(abs(m)) for m in r.multipliers],
             "verdict": r.verdict, "margin": r.margin, "error": r.error}
            for q, r in driven_floquet(system, values)]


def parametrically_excited(system, values) -> bool:
    """Whether the system is excited parametrically only (§8.4): every rest state of the
    unexcited system stays a solution with the excitation on (the excitation does not
    force the free coordinates there), and about one of them the variational equations'
    coefficients vary with time. Then the linearization with the excitation off does not
    judge stability, and Floquet theory (`driven_floquet`) does. A system the excitation
    also forces keeps its forced steady state as the analysis (analytic/steady_state.py)."""
    from .linear import _PROBE_TIMES, TIME_INVARIANCE, _driven_blocks, driven_rest_states
    from .numeric import numeric_model

    if not system.mechanism.prescribed:
        return False
    model = numeric_model(system.id, dict(values))
    free = model.independent
    varying = False
    for q in driven_rest_states(system, values, only_operating=False):
        blocks = [_driven_blocks(model, q[free], t) for t in _PROBE_TIMES]
        flat = [np.concatenate([b.ravel() for b in block[:3]]) for block in blocks]
        scale = max(float(np.max(np.abs(flat[0]))), 1e-300)
        if any(float(np.max(np.abs(block[3]))) > TIME_INVARIANCE * scale for block in blocks):
            return False  # forced there
        varying = varying or any(float(np.max(np.abs(b - flat[0]))) > TIME_INVARIANCE * scale
                                 for b in flat[1:])
    return varying
