"""Relative equilibrium of a floating mechanism and the two routes to its linearization
(Italian notes §5.3.1-5.3.4).

A mechanism with no ground under a load with a non-zero resultant has no static
equilibrium: no configuration makes every acceleration vanish (eq. 5.39-5.42). The notes'
reference solution is relative: the configuration that translates rigidly, every point
with the same uniform acceleration, while the internal coordinates stay constant
(eq. 5.44-5.52). The system declares the rigid directions r_j (coordinate space,
`System.rigid_directions`); the relative equilibrium is the q and the accelerations a_j
that solve

    R(q, 0, sum_j a_j r_j) = M(q) r a + h(q, 0) - Q(q, 0) = 0,   r_j . (q - q_op) = 0,

the second fixing where along the rigid directions the configuration is reported (any
rigid shift of it is the same relative equilibrium). Along the reference motion
q(t) = q + r a t^2/2 the coefficients of the linearized equations are constant when the
mechanism is invariant under the rigid translation (checked at a shifted, moving probe
state; refused otherwise). The rigid directions carry no stiffness and no damping
(checked): each gives a double zero eigenvalue, the rigid-body mode at zero frequency,
reported once; the stability of the relative motion is judged on the other eigenvalues.

The two routes of §5.3.2:
1. direct linearization of the equations of motion (§5.3.3, eq. 5.54-5.63): the
   Jacobians of R = M q'' + h - Q in q'', q', q at the reference state, its acceleration
   included;
2. quadratic forms of T, D and V about the configuration at rest (§5.3.4, eq. 5.64-5.75)
   with the generalized force of the elements that have no potential or dissipation
   function linearized (eq. 5.58-5.59): M = d2T/dq'2, C = d2D/dq'2 - dQ/dq',
   K = d2V/dq2 - dQ/dq. It does not see the reference's acceleration, so it agrees with
   route 1 where the mass matrix does not change along the reference (a translation).
"""
from __future__ import annotations

import warnings

import numpy as np
import scipy.optimize
import sympy as sp

from ..systems import System
from .derivation import derivation_of
from .modes import Equilibrium, Mode, is_stable, modes_from_eigenvalues, quadratic_eigenvalues
from .numeric import NumericModel, numeric_model

#: relative size of K r, C r (and of the change of the coefficients at a shifted, moving
#: probe state) above which a declared rigid direction is not rigid: round-off level
RIGIDITY = 1e-9
#: shift along the rigid directions (in units of the coordinates) and rigid speed of the
#: probe state at which translation invariance is checked
_PROBE_SHIFT, _PROBE_SPEED = 0.731, 1.37


def rigid_matrix(system: System, values) -> np.ndarray:
    """The declared rigid directions as the columns of an n x r matrix (unit columns)."""
    directions = system.rigid_directions(system.symbols)
    cols = []
    for d in directions:
        unknown = set(d) - set(system.coordinates)
        if unknown:
            raise ValueError(f"{system.id}: rigid direction names unknown coordinates "
                             f"{sorted(unknown)}")
        v = np.array([system.evaluate(d.get(c, 0), values) for c in system.coordinates])
        cols.append(v / np.linalg.norm(v))
    return np.array(cols).T.reshape(len(system.coordinates), len(cols))


def floating(system: System) -> bool:
    return bool(system.rigid_directions(system.symbols))


def relative_residual(model: NumericModel, q: np.ndarray, rigid: np.ndarray) -> np.ndarray:
    """R(q, 0, r a) with the rigid accelerations a that fit it best (least squares): zero
    at a relative equilibrium."""
    R0 = model.residual(q, np.zeros(model.n), np.zeros(model.n), 0.0)
    Mr = model.mass_matrix(q) @ rigid
    a, *_ = np.linalg.lstsq(Mr, -R0, rcond=None)
    return R0 + Mr @ a


def _solve(model: NumericModel, rigid: np.ndarray, op: np.ndarray, start: np.ndarray):
    n, r = rigid.shape
    zeros = np.zeros(n)

    def equations(z):
        q, a = z[:n], z[n:]
        return np.concatenate([model.residual(q, zeros, rigid @ a, 0.0), rigid.T @ (q - op)])

    def jacobian(z):
        q, a = z[:n], z[n:]
        M, _, J_q = model.residual_jacobians(q, zeros, rigid @ a, 0.0)
        return np.block([[J_q, M @ rigid], [rigid.T, np.zeros((r, r))]])

    z0 = np.concatenate([start - rigid @ (rigid.T @ (start - op)), np.zeros(r)])
    try:
        sol = scipy.optimize.root(equations, z0, jac=jacobian, method="hybr", tol=1e-14)
    except (ValueError, np.linalg.LinAlgError):
        return None
    if not np.all(np.isfinite(sol.x)):
        return None
    scale = max(1.0, float(np.max(np.abs(jacobian(sol.x)))))
    if np.max(np.abs(equations(sol.x))) > 1e-9 * scale * max(1.0, float(np.max(np.abs(sol.x)))):
        return None
    return sol.x[:n], sol.x[n:]


def direct_linearization(model: NumericModel, q: np.ndarray, qd: np.ndarray,
                         qdd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Route 1 (§5.3.3): (dR/dq'', dR/dq', dR/dq) at the reference state."""
    return model.residual_jacobians(np.asarray(q, float), np.asarray(qd, float),
                                    np.asarray(qdd, float), 0.0)


def quadratic_forms_linearization(system: System, values, q: np.ndarray
                                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Route 2 (§5.3.4): Hessians of T and D in q' and of V in q at (q, 0), with the
    generalized force of the elements without a potential or a dissipation function
    linearized (eq. 5.58-5.59). Unconstrained mechanisms, autonomous loads."""
    d = derivation_of(system.id)
    if system.mechanism.constraints:
        raise ValueError(f"{system.id}: the quadratic-form route is coded for mechanisms "
                         f"without closure constraints")
    subs = system.subs(values)
    T, D, V = (e.xreplace(subs) for e in (d.T, d.D, d.V))
    grad_V = sp.Matrix([sp.diff(V, x) for x in d.q])
    grad_D = sp.Matrix([sp.diff(D, v) for v in d.qd])
    # what is left of Q once the potential and dissipative parts are taken out
    Q_rest = d.Q_autonomous.xreplace(subs) + grad_V + grad_D
    at = {**dict(zip(d.q, map(float, q))), **{v: 0.0 for v in d.qd}}

    def num(expr):
        return np.array(sp.Matrix(expr).xreplace(at).evalf(), dtype=float)

    M = num(sp.hessian(T, d.qd))
    C = num(sp.hessian(D, d.qd) - Q_rest.jacobian(d.qd))
    K = num(sp.hessian(V, d.q) - Q_rest.jacobian(d.q))
    return M, C, K


def linearize_relative(system: System, model: NumericModel, q: np.ndarray, a: np.ndarray,
                       rigid: np.ndarray) -> Equilibrium:
    """The linearization about the relative equilibrium (q, rigid accelerations a)."""
    n, r = rigid.shape
    qdd = rigid @ a
    M, C, K = direct_linearization(model, q, np.zeros(n), qdd)
    scale = max(float(np.max(np.abs(np.concatenate([M, C, K], axis=None)))), 1e-300)
    if max(float(np.max(np.abs(K @ rigid))), float(np.max(np.abs(C @ rigid)))) > RIGIDITY * scale:
        raise ValueError(f"{system.id}: a declared rigid direction carries stiffness or "
                         f"damping (K r, C r are not zero): it is not a rigid-body motion")
    probe_q = q + _PROBE_SHIFT * rigid.sum(axis=1)
    probe_qd = _PROBE_SPEED * rigid.sum(axis=1)
    Mp, Cp, Kp = direct_linearization(model, probe_q, probe_qd, qdd)
    Rp = model.residual(probe_q, probe_qd, qdd, 0.0)
    varying = max(float(np.max(np.abs(Mp - M))), float(np.max(np.abs(Cp - C))),
                  float(np.max(np.abs(Kp - K))), float(np.max(np.abs(Rp))))
    if varying > RIGIDITY * scale:
        raise ValueError(f"{system.id}: the mechanism is not invariant under its declared "
                         f"rigid translation: no relative equilibrium with constant "
                         f"coefficients")
    s = quadratic_eigenvalues(M, C, K)
    # each rigid direction: a double zero eigenvalue (s^2 = 0)
    order = np.argsort(np.abs(s))
    relative = s[order[2 * r:]]
    modes = [Mode(0.0, 0.0, 0.0, 0j) for _ in range(r)] + modes_from_eigenvalues(relative)
    stable = is_stable(relative) if len(relative) else True
    return Equilibrium(np.asarray(q, float), stable, M, C, K, s, modes,
                       acceleration=qdd, rigid=rigid)


def relative_equilibria(system: System, values, starts: list[np.ndarray] | None = None
                        ) -> list[Equilibrium]:
    """The relative equilibria reached from `starts` (default: the operating point),
    the operating one first."""
    model = numeric_model(system.id, values)
    if model.constrained or model.driven:
        raise ValueError(f"{system.id}: relative equilibria are coded for open trees "
                         f"without prescribed coordinates")
    rigid = rigid_matrix(system, values)
    op = system.operating_values(values)
    found = []
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for start in starts or [op]:
            sol = _solve(model, rigid, op, np.asarray(start, float))
            if sol is None or any(np.allclose(sol[0], f[0], atol=1e-7) for f in found):
                continue
            found.append(sol)
    return [linearize_relative(system, model, q, a, rigid) for q, a in found]
