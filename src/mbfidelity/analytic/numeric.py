"""Numeric evaluation of a derived model for given parameter values."""
from __future__ import annotations

from functools import lru_cache
from typing import Callable, Mapping

import numpy as np
import sympy as sp

from ..systems import get_system
from ..systems.model import TIME
from .derivation import Derivation, derivation_of


def _lambdify(args, expr, modules="numpy") -> Callable:
    return sp.lambdify(args, expr, modules=modules, cse=True)


class NumericModel:
    """A derivation with parameter values substituted and compiled.

    Vectors are numpy arrays in the system's coordinate order."""

    def __init__(self, derivation: Derivation, subs: Mapping[sp.Symbol, float]):
        d = self.derivation = derivation
        self.n = d.n
        self.subs = dict(subs)
        q, qd, qdd = list(d.q), list(d.qd), list(d.qdd)
        self._args = q + qd + [TIME]
        sub = lambda e: e.xreplace(self.subs)  # noqa: E731
        M = d.M.xreplace(self.subs)
        rhs = (d.Q - d.h).xreplace(self.subs)
        self._M = _lambdify(q, M)
        self._rhs = _lambdify(self._args, rhs)
        if self.n <= 3:
            # explicit q'' keeps the reference solver's right-hand side cheap
            acc = M.LUsolve(rhs)
            self._acc_explicit = _lambdify(self._args, list(acc), modules="math")
        else:
            self._acc_explicit = None
        self._residual = _lambdify(q + qd + qdd + [TIME], d.residual.xreplace(self.subs))
        self._residual_autonomous = _lambdify(
            q, (d.M * d.qdd + d.h - d.Q_autonomous).xreplace(
                {**self.subs, **{v: 0 for v in qd + qdd}}))
        self._energy = _lambdify(q + qd, sub(d.T + d.V)) if d.energy_route else None
        # route 1 linearization: Jacobians of the autonomous residual (eq. 104-109)
        r_aut = (d.M * d.qdd + d.h - d.Q_autonomous).xreplace(self.subs)
        zero_vel = {v: 0 for v in qd + qdd}
        self._lin_M = _lambdify(q, r_aut.jacobian(d.qdd).xreplace(zero_vel))
        self._lin_C = _lambdify(q, r_aut.jacobian(d.qd).xreplace(zero_vel))
        self._lin_K = _lambdify(q, r_aut.jacobian(d.q).xreplace(zero_vel))
        # route 2: Hessians of T, V and D
        if d.energy_route:
            self._hess_T = _lambdify(q, sp.hessian(d.T, qd).xreplace(self.subs))
            self._hess_V = _lambdify(q, sp.hessian(d.V, q).xreplace(self.subs))
            self._hess_D = _lambdify(q, sp.hessian(d.D, qd).xreplace({**self.subs, **{v: 0 for v in qd}}))
        self._reactions: dict[str, Callable] = {}

    # --- dynamics ------------------------------------------------------------------------
    def mass_matrix(self, q) -> np.ndarray:
        return np.atleast_2d(np.array(self._M(*q), dtype=float))

    def acceleration(self, q, qd, t: float) -> np.ndarray:
        if self._acc_explicit is not None:
            return np.array(self._acc_explicit(*q, *qd, t), dtype=float).reshape(-1)
        rhs = np.array(self._rhs(*q, *qd, t), dtype=float).reshape(-1)
        return np.linalg.solve(self.mass_matrix(q), rhs)

    def ode_rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        n = self.n
        return np.concatenate([y[n:], self.acceleration(y[:n], y[n:], t)])

    def residual(self, q, qd, qdd, t: float) -> np.ndarray:
        return np.array(self._residual(*q, *qd, *qdd, t), dtype=float).reshape(-1)

    def static_residual(self, q) -> np.ndarray:
        """Residual at rest without the time-dependent loads: zero at an equilibrium."""
        return np.array(self._residual_autonomous(*q), dtype=float).reshape(-1)

    def energy(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """T + V along sampled states (arrays of shape (N, n))."""
        if self._energy is None:
            raise ValueError("this model has no potential for every force element")
        return np.asarray(self._energy(*q.T, *qd.T), dtype=float) * np.ones(len(q))

    # --- linearization -------------------------------------------------------------------
    def linearization(self, q_eq) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(M, C, K) from the Jacobians of the equations of motion (route 1)."""
        f = lambda fn: np.atleast_2d(np.array(fn(*q_eq), dtype=float))  # noqa: E731
        return f(self._lin_M), f(self._lin_C), f(self._lin_K)

    def energy_linearization(self, q_eq):
        """(M, C, K) as Hessians of T, D, V (route 2), or None where it does not apply."""
        if not self.derivation.energy_route:
            return None
        f = lambda fn: np.atleast_2d(np.array(fn(*q_eq), dtype=float))  # noqa: E731
        return f(self._hess_T), f(self._hess_D), f(self._hess_V)

    # --- reactions -----------------------------------------------------------------------
    def reaction(self, joint: str, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                 t: np.ndarray) -> np.ndarray:
        """(N, 2) reaction force on the child at `joint`, world axes."""
        if joint not in self._reactions:
            d = self.derivation
            expr = d.reaction(joint).xreplace(self.subs)
            self._reactions[joint] = _lambdify(list(d.q) + list(d.qd) + list(d.qdd) + [TIME],
                                               list(expr))
        fx, fy = self._reactions[joint](*q.T, *qd.T, *qdd.T, t)
        return np.column_stack([np.broadcast_to(np.asarray(f, dtype=float), (len(t),))
                                for f in (fx, fy)])

    def accelerations(self, q: np.ndarray, qd: np.ndarray, t: np.ndarray) -> np.ndarray:
        return np.array([self.acceleration(a, b, c) for a, b, c in zip(q, qd, t)])


@lru_cache(maxsize=64)
def _numeric_cached(system_id: str, items: tuple) -> NumericModel:
    system = get_system(system_id)
    return NumericModel(derivation_of(system_id), system.subs(dict(items)))


def numeric_model(system_id: str, values: Mapping[str, float]) -> NumericModel:
    return _numeric_cached(system_id, tuple(sorted(values.items())))
