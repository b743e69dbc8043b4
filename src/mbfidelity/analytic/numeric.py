"""Numeric evaluation of a derived model for given parameter values.

Coordinates q are the joints' coordinates (redundant when the mechanism has closure
constraints). Motion is integrated in the independent coordinates q_i; the dependent ones
follow from Phi(q) = 0 by Newton's method, velocities from q' = S(q) q_i'. Accelerations
and multipliers come from the augmented system (monograph §10)

    [ M      Phi_q^T ] [ q'' ]   [ Q - h ]
    [ Phi_q  0       ] [ lam ] = [ gamma ].

The linearization at an equilibrium is taken on the constraint manifold:
M_r = S^T M S, C_r = S^T C S, K_r = S^T (K + sum_k lam_k Hess(Phi_k)) S, with lam the
static multipliers. Without constraints S = I and these reduce to eq. 104-109.

An over-constrained loop (`Mechanism.redundant` rows implied by the others) has a
constraint Jacobian of rank m - redundant everywhere and a singular augmented matrix:
the dependent coordinates are then solved by least squares (exact, the rows being
consistent), the accelerations on the constraint manifold (q'' = S a + c with
S^T M S a = S^T (Q - h - M c)), and of the multipliers, which the redundancy leaves
undetermined, the least-norm ones are reported. The rank is checked at every
configuration assembled: a loop whose geometry no longer makes the rows redundant is
refused.

A driven mechanism (prescribed coordinates q_p = q_p(t), monograph §9.6) is integrated in
its free coordinates q_f: with the prescribed positions, rates and accelerations given,
M_ff q_f'' = (Q - h)_f - M_fp q_p''(t). The rows of the prescribed coordinates then give
the actuator forces: tau_p = (M q'' + h - Q)_p.
"""
from __future__ import annotations

import builtins
import dis
import inspect
from functools import cached_property, lru_cache, partial
from typing import Callable, Mapping

import numpy as np
import sympy as sp

from ..systems import get_system
from ..systems.model import TIME
from . import cache
from .derivation import Derivation, cache_key, derivation_of

NEWTON_TOL = 1e-14
NEWTON_MAX = 50
#: singular values of the constraint Jacobian below this fraction of the largest count as
#: zero: configurations are solved to about NEWTON_TOL, so a singular value that vanishes
#: at a singular position is of that order there, while at a regular one each is of the
#: order of the mechanism's lengths
RANK_TOLERANCE = 1e-8


#: derivatives of |length| carry DiracDelta(length): zero wherever the length is not
#: zero, which is everywhere a mechanism can be
_DELTA = {"DiracDelta": lambda *args: 0.0}


def _lambdify(args, expr, modules="numpy") -> Callable:
    return sp.lambdify(args, expr, modules=[_DELTA, modules], cse=True)


def _matrix(fn, *args) -> np.ndarray:
    return np.atleast_2d(np.array(fn(*args), dtype=float))


@lru_cache(maxsize=None)
def _namespace(modules: str) -> dict:
    """The globals lambdify gives its generated code for `modules`."""
    return _lambdify([], 0, modules).__globals__


def _global_names(code) -> set[str]:
    names = {ins.argval for ins in dis.get_instructions(code) if ins.opname == "LOAD_GLOBAL"}
    for const in code.co_consts:
        if hasattr(const, "co_code"):
            names |= _global_names(const)
    return names


def _from_source(source: str, modules: str, label: str) -> Callable:
    namespace = dict(_namespace(modules))
    exec(compile(source, f"<mbfidelity {label}>", "exec"), namespace)
    return namespace["_lambdifygenerated"]


def _residual_at_rest_terms(d: Derivation) -> sp.Matrix:
    """The part of the autonomous residual M q'' + h - Q_aut whose Jacobians in q and q'
    at rest (q' = q'' = 0) are the linearization's stiffness and damping. With M a
    function of q alone, M q'' is linear in q'' and h = M' q' - dT/dq homogeneous
    quadratic in q': both Jacobians of both vanish at rest, and what remains is -Q_aut
    (differentiating h of a long spatial chain is what would cost; route 2, the Hessians
    of T, V and D, still checks the result). A mass matrix that depends on anything
    else keeps the whole residual."""
    rates = set(d.qd) | set(d.qdd) | {TIME}
    if any(sp.sympify(e).free_symbols & rates for e in d.M):
        return d.M * d.qdd + d.h - d.Q_autonomous
    return -d.Q_autonomous


def _vanishes(expr) -> bool:
    """Whether `expr` is identically zero. A value clearly off zero at a sample point
    proves it is not, at no cost; only an expression that vanishes there is simplified
    (simplify of a long unsimplified expression, `Mechanism.simplify` false, does not
    return in useful time)."""
    expr = sp.sympify(expr)
    if expr == 0:
        return True
    sample = {x: 0.3 + 0.1 * i for i, x in enumerate(sorted(expr.free_symbols, key=str))}
    try:
        value = complex(expr.xreplace(sample).evalf())
    except (TypeError, ValueError):  # a pole at the sample: no evidence either way
        value = 0.0
    if np.isfinite(value) and abs(value) > 1e-9:
        return False
    return sp.simplify(expr) == 0


class CompiledSystem:
    """Every numeric function of one system's derivation, compiled once, with the
    parameter values as leading arguments (`NumericModel` binds them): a new parameter
    set costs no compilation. The generated source of each function is kept in the
    persistent cache (`analytic.cache`); a cached function and a freshly compiled one
    are the same source executed the same way."""

    def __init__(self, system_id: str):
        system = get_system(system_id)
        self.system_id = system_id
        self.key = cache_key(system)
        self.parameters = [p.symbol for p in system.all_parameters]
        self.parameter_names = [p.name for p in system.all_parameters]
        self._functions: dict[str, Callable | None] = {}

    @cached_property
    def derivation(self) -> Derivation:
        return derivation_of(self.system_id)

    def function(self, name: str, build: Callable[[], tuple | None]) -> Callable | None:
        """The compiled function `name`; `build()` gives (args, expression, modules), or
        None where the function does not exist for this system."""
        if name in self._functions:
            return self._functions[name]
        payload = cache.load(self.key, f"{name}.py")
        if payload is not None:
            modules, _, source = payload.decode().partition("\n")
            fn = None if modules == "none" else _from_source(source, modules, name)
        else:
            spec = build()
            if spec is None:
                fn, modules, source = None, "none", ""
            else:
                args, expr, modules = spec
                source = inspect.getsource(_lambdify(self.parameters + list(args), expr, modules))
                fn = _from_source(source, modules, name)
            # the source runs in lambdify's fixed namespace for its modules: cache it only
            # when every global it reads is there
            if fn is None or _global_names(fn.__code__) <= set(_namespace(modules)) | set(
                    dir(builtins)):
                cache.store(self.key, f"{name}.py", f"{modules}\n{source}".encode())
        self._functions[name] = fn
        return fn


@lru_cache(maxsize=None)
def compiled_system(system_id: str) -> CompiledSystem:
    return CompiledSystem(system_id)


class NumericModel:
    """A derivation's compiled functions bound to parameter values."""

    def __init__(self, compiled: CompiledSystem, values: Mapping[str, float]):
        self.compiled = compiled
        d = self.derivation = compiled.derivation
        self.values = {k: float(values[k]) for k in compiled.parameter_names}
        self.parameter_values = tuple(self.values[k] for k in compiled.parameter_names)
        self.subs = dict(zip(compiled.parameters, self.parameter_values))
        self.n, self.m = d.n, d.m
        self.independent, self.dependent = list(d.independent), list(d.dependent)
        self.constrained = self.m > 0
        #: constraint rows implied by the others (an over-constrained loop, model.py)
        self.redundant = d.mechanism.redundant
        mech = d.mechanism
        self.driven = [mech.coordinates.index(c) for c in mech.driven_coordinates]
        self.actuators = [p.name for p in mech.prescribed]
        q, qd, qdd = list(d.q), list(d.qd), list(d.qdd)
        args = q + qd + [TIME]
        zero_vel = {v: 0 for v in qd + qdd}
        fn = self._bound
        self._M = fn("M", lambda: (q, d.M, "numpy"))
        self._rhs = fn("rhs", lambda: (args, list(d.Q - d.h), "numpy"))
        # explicit q'' keeps the reference solver's right-hand side cheap
        self._acc_explicit = fn("acc_explicit", lambda: (
            args, list(d.M.LUsolve(d.Q - d.h)), "math")
            if self.n <= 3 and not self.constrained and not self.driven else None)
        if self.driven:
            self._motion = fn("motion", lambda: ([TIME], [
                sp.sympify(x) for p in mech.prescribed
                for x in (p.motion, p.rate, p.acceleration)], "numpy"))
            self._acc_driven = fn("acc_driven", lambda: self._driven_acceleration_expr())
        self._residual = fn("residual", lambda: (q + qd + qdd + [TIME], list(d.residual), "numpy"))
        self._Q_static = fn("Q_static", lambda: (
            q, list(d.Q_autonomous.xreplace(zero_vel)), "numpy"))
        energy_route = d.energy_route
        self._energy = fn("energy", lambda: (q + qd, d.T + d.V, "numpy") if energy_route
                          else None)
        self._V = fn("V", lambda: (q, d.V, "numpy") if energy_route else None)
        # route 1 linearization: Jacobians of the autonomous residual at rest (eq. 104-109)
        r_aut = _residual_at_rest_terms(d)
        self._lin_C = fn("lin_C", lambda: (q, r_aut.jacobian(d.qd).xreplace(zero_vel), "numpy"))
        self._lin_K = fn("lin_K", lambda: (q, r_aut.jacobian(d.q).xreplace(zero_vel), "numpy"))
        if energy_route:
            self._hess_T = fn("hess_T", lambda: (q, sp.hessian(d.T, qd), "numpy"))
            self._hess_V = fn("hess_V", lambda: (q, sp.hessian(d.V, q), "numpy"))
            self._hess_D = fn("hess_D", lambda: (
                q, sp.hessian(d.D, qd).xreplace({v: 0 for v in qd}), "numpy"))
        if self.constrained:
            self._Phi = fn("Phi", lambda: (q, list(d.Phi), "numpy"))
            self._Phi_q = fn("Phi_q", lambda: (q, d.Phi_q, "numpy"))
            self._gamma = fn("gamma", lambda: (q + qd, list(d.gamma), "numpy"))
            self._Phi_hess = [fn(f"Phi_hess{k}", lambda H=H: (q, H, "numpy"))
                              for k, H in enumerate(d.Phi_hessians)]
        self._reactions: dict[str, Callable] = {}
        self._warm: np.ndarray | None = None
        #: (q, S(q)) of the last state completed from `_warm`: the Newton predictor
        self._tangent: tuple[np.ndarray, np.ndarray] | None = None
        # closed-form reduction (constraints solved symbolically): a cheap explicit ODE
        self._explicit = None
        small_reduced = self.constrained and len(self.independent) <= 3
        qi = [d.q[i] for i in self.independent]
        qdi = [d.qd[i] for i in self.independent]

        def reduced(part):
            r = d.reduced_dynamics() if small_reduced else None
            return None if r is None else part(*r)

        explicit = (
            fn("explicit_q", lambda: reduced(lambda q_full, S, M_r, rhs_r: (
                qi, list(q_full), "math"))),
            fn("explicit_qd", lambda: reduced(lambda q_full, S, M_r, rhs_r: (
                qi + qdi, list(S * sp.Matrix(qdi)), "math"))),
            fn("explicit_acc", lambda: reduced(lambda q_full, S, M_r, rhs_r: (
                qi + qdi + [TIME], list(M_r.LUsolve(rhs_r)), "math"))),
        )
        if explicit[0] is not None:
            self._explicit = explicit
        # route 2 with closed-form constraints: exact Hessian of V(q(q_i))

        def hess_V_reduced():
            r = d.reduced_dynamics() if self.constrained and energy_route else None
            if r is None:
                return None
            V_r = d.V.xreplace(dict(zip(d.q, r[0])))
            return qi, sp.hessian(V_r, qi), "numpy"

        self._hess_V_reduced = fn("hess_V_reduced", hess_V_reduced)

    def _driven_acceleration_expr(self):
        """(q_f, q_f', t) -> q_f'' in closed form (prescribed motions substituted), for
        up to three free coordinates; None otherwise (solved numerically)."""
        d, mech = self.derivation, self.derivation.mechanism
        free = self.independent
        if len(free) > 3:
            return None
        given = {}
        for k, p in zip(self.driven, mech.prescribed):
            given.update({d.q[k]: p.motion, d.qd[k]: p.rate, d.qdd[k]: p.acceleration})
        M = d.M.xreplace(given)
        rhs = (d.Q - d.h).xreplace(given)
        M_ff = M.extract(free, free)
        qdd_p = sp.Matrix([given[d.qdd[k]] for k in self.driven])
        b = rhs.extract(free, [0]) - M.extract(free, self.driven) * qdd_p
        args = [d.q[i] for i in free] + [d.qd[i] for i in free] + [TIME]
        return args, list(M_ff.LUsolve(b)), "math"

    def motion(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q_p, q_p', q_p'') of the prescribed coordinates at time(s) t: each of shape
        (len(driven),) for a scalar t, (N, len(driven)) for N times."""
        t_arr = np.asarray(t, dtype=float)
        vals = [np.broadcast_to(np.asarray(v, dtype=float), t_arr.shape)
                for v in self._motion(t_arr)]
        k = len(self.driven)
        parts = [np.stack(vals[j::3], axis=-1) if k else np.zeros(t_arr.shape + (0,))
                 for j in range(3)]
        return parts[0], parts[1], parts[2]

    def driven_state(self, y: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Full (q, q') from free states y = (q_f, q_f') (rows of samples) at times t."""
        y = np.atleast_2d(y)
        k = len(self.independent)
        qp, qdp, _ = self.motion(np.asarray(t, dtype=float).reshape(-1))
        q = np.zeros((len(y), self.n))
        qd = np.zeros((len(y), self.n))
        q[:, self.independent], qd[:, self.independent] = y[:, :k], y[:, k:2 * k]
        q[:, self.driven], qd[:, self.driven] = qp, qdp
        return q, qd

    def actuator_forces(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                        t: np.ndarray) -> dict[str, np.ndarray]:
        """The generalized force of each prescribed coordinate's actuator along a sampled
        motion, (N,) per actuator (model convention 9)."""
        if not self.driven:
            return {}
        d, N = self.derivation, len(t)
        r = self._along("residual", lambda: (
            list(d.q) + list(d.qd) + list(d.qdd) + [TIME], list(d.residual), "numpy"),
            (*np.asarray(q, float).T, *np.asarray(qd, float).T, *np.asarray(qdd, float).T,
             np.asarray(t, float)), N)
        return {name: r[:, k] for name, k in zip(self.actuators, self.driven)}

    def residual_jacobians(self, q, qd, qdd, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(dR/dq'', dR/dq', dR/dq) of R = M q'' + h - Q at one state (n x n each): the
        linearization of every row, the time-dependent loads included."""
        d = self.derivation
        args = list(d.q) + list(d.qd) + list(d.qdd) + [TIME]
        R = d.M * d.qdd + d.h - d.Q
        J_qd = self._bound("res_jac_qd", lambda: (args, R.jacobian(d.qd), "numpy"))
        J_q = self._bound("res_jac_q", lambda: (args, R.jacobian(d.q), "numpy"))
        vals = (*q, *qd, *qdd, t)
        return self.mass_matrix(q), _matrix(J_qd, *vals), _matrix(J_q, *vals)

    def _bound(self, name: str, build) -> Callable | None:
        f = self.compiled.function(name, build)
        return None if f is None else partial(f, *self.parameter_values)

    @cached_property
    def conservative(self) -> bool:
        """No dissipation and no time-dependent load at these parameter values."""
        d = self.derivation
        dissipation = d.D.xreplace(self.subs)
        q_aut_t = any(TIME in sp.sympify(e).free_symbols for e in d.Q.xreplace(self.subs))
        return bool(d.energy_route and not q_aut_t and not self.driven
                    and _vanishes(dissipation))

    # --- constraint manifold -------------------------------------------------------------
    def constraint_values(self, q) -> np.ndarray:
        return np.array(self._Phi(*q), dtype=float) if self.constrained else np.zeros(0)

    def constraint_jacobian(self, q) -> np.ndarray:
        return _matrix(self._Phi_q, *q) if self.constrained else np.zeros((0, self.n))

    def complete(self, q_guess) -> np.ndarray:
        """Solve Phi(q) = 0 for the dependent coordinates, independent ones held."""
        q = np.array(q_guess, dtype=float)
        if not self.constrained:
            return q
        dep = self.dependent
        for _ in range(NEWTON_MAX):
            phi = self.constraint_values(q)
            J = self.constraint_jacobian(q)[:, dep]
            step = self._solve_dependent(J, phi)
            q[dep] -= step
            if np.max(np.abs(step)) <= NEWTON_TOL * max(1.0, np.max(np.abs(q[dep]))):
                break
        else:
            raise RuntimeError("the constraint equations did not converge (assembly lost)")
        if np.max(np.abs(self.constraint_values(q))) > 1e-10:
            raise RuntimeError("the constraint equations have no solution here")
        if self.redundant:
            self._check_rank(q)
        return q

    def _solve_dependent(self, J_dep: np.ndarray, rhs: np.ndarray) -> np.ndarray:
        """x with J_dep x = rhs, for one sample or a batch (leading axis). With redundant
        rows (an over-constrained loop) J_dep has more rows than columns and full column
        rank: the system is consistent and its least-squares solution, by the
        pseudo-inverse, is the exact one (Gauss-Newton converges as Newton does)."""
        if not self.redundant:
            if rhs.ndim == J_dep.ndim - 1:
                return np.linalg.solve(J_dep, rhs[..., None])[..., 0]
            return np.linalg.solve(J_dep, rhs)
        pinv = np.linalg.pinv(J_dep, rcond=RANK_TOLERANCE)
        return pinv @ rhs if rhs.ndim == J_dep.ndim else (pinv @ rhs[..., None])[..., 0]

    def _check_rank(self, q) -> None:
        """The rank the mechanism declares (rows less its redundant ones) holds at q: a
        loop whose geometry no longer makes a row redundant (a rod of another length)
        is rigid or cannot close, and its reduction to n - rank coordinates is wrong."""
        rank, _ = self.constraint_rank(q)
        if rank != self.m - self.redundant:
            raise RuntimeError(
                f"the constraint Jacobian has rank {rank} here, not the {self.m} rows less "
                f"the {self.redundant} redundant the mechanism declares: its geometry does "
                "not make them redundant")

    def on_branch(self, q, tol: float = 1e-8) -> bool:
        """Whether the configuration q lies on the mechanism's described assembly branch
        (`Mechanism.branch`; angles compared modulo 2 pi); True without one."""
        if not self.derivation.mechanism.branch:
            return True
        q = np.asarray(q, dtype=float)
        gap = np.array(self._explicit[0](*q[self.independent]), dtype=float) - q
        mech = self.derivation.mechanism
        angular = np.array([mech.angular(c) for c in mech.coordinates])
        gap[angular] = np.remainder(gap[angular] + np.pi, 2 * np.pi) - np.pi
        return bool(np.max(np.abs(gap)) <= tol)

    def constraint_rank(self, q) -> tuple[int, np.ndarray]:
        """(rank, singular values) of the constraint Jacobian at q, by its singular value
        decomposition: singular values below RANK_TOLERANCE times the largest count as
        zero. Full rank is the number of constraint rows; less marks a singular position
        (branches of the assembly cross, the mobility is n - rank) or redundant
        constraints."""
        if not self.constrained:
            return 0, np.zeros(0)
        sv = np.linalg.svd(self.constraint_jacobian(q), compute_uv=False)
        return int(np.sum(sv > RANK_TOLERANCE * sv.max())), sv

    def velocity_basis(self, q) -> np.ndarray:
        """S with q' = S q_i' (n x n_independent)."""
        n, ind, dep = self.n, self.independent, self.dependent
        S = np.zeros((n, len(ind)))
        S[ind, np.arange(len(ind))] = 1.0
        if self.constrained:
            J = self.constraint_jacobian(q)
            S[dep, :] = -self._solve_dependent(J[:, dep], J[:, ind])
        return S

    def state_from_independent(self, qi, qdi, guess=None) -> tuple[np.ndarray, np.ndarray]:
        if self._explicit is not None:
            return (np.array(self._explicit[0](*qi), dtype=float),
                    np.array(self._explicit[1](*qi, *qdi), dtype=float))
        predictor = None
        if guess is None:
            guess = self._warm if self._warm is not None else np.zeros(self.n)
            if self._tangent is not None and self._tangent[0] is guess:
                predictor = self._tangent[1]
        q = np.array(guess, dtype=float)
        if predictor is not None:
            # first-order predictor along the constraint manifold: Newton then starts
            # a step's square away from the solution
            q += predictor @ (np.asarray(qi, dtype=float) - q[self.independent])
        q[self.independent] = qi
        q = self.complete(q)
        S = self.velocity_basis(q)
        self._warm, self._tangent = q, (q, S)
        return q, S @ np.asarray(qdi, dtype=float)

    # --- dynamics ------------------------------------------------------------------------
    def mass_matrix(self, q) -> np.ndarray:
        return _matrix(self._M, *q)

    def dynamics(self, q, qd, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(q'', lam) at a consistent state."""
        rhs = np.array(self._rhs(*q, *qd, t), dtype=float).reshape(-1)
        if not self.constrained:
            return np.linalg.solve(self.mass_matrix(q), rhs), np.zeros(0)
        J = self.constraint_jacobian(q)
        n = self.n
        if self.redundant:
            gamma = np.array(self._gamma(*q, *qd), dtype=float).reshape(-1)
            qdd, lam = self._redundant_dynamics(self.mass_matrix(q)[None], J[None],
                                                rhs[None], gamma[None])
            return qdd[0], lam[0]
        A = np.zeros((n + self.m, n + self.m))
        A[:n, :n] = self.mass_matrix(q)
        A[:n, n:] = J.T
        A[n:, :n] = J
        b = np.concatenate([rhs, np.array(self._gamma(*q, *qd), dtype=float).reshape(-1)])
        sol = np.linalg.solve(A, b)
        return sol[: self.n], sol[self.n:]

    def _redundant_dynamics(self, M, J, rhs, gamma) -> tuple[np.ndarray, np.ndarray]:
        """(q'', lam) of N samples (leading axis) whose constraint Jacobian has redundant
        rows, where the augmented matrix is singular: q'' = S a + c on the constraint
        manifold (J S = 0, J c = gamma with c zero in the independent coordinates), the
        reduced equations S^T M S a = S^T (rhs - M c) (regular: M is positive definite on
        the motions the constraints allow), and of the multipliers, which the rows'
        redundancy leaves undetermined (a rigid over-constrained loop is statically
        indeterminate), the least-norm ones with Phi_q^T lam = rhs - M q''."""
        ind, dep, N = self.independent, self.dependent, len(M)
        S = np.zeros((N, self.n, len(ind)))
        S[:, ind, np.arange(len(ind))] = 1.0
        S[:, dep, :] = -self._solve_dependent(J[:, :, dep], J[:, :, ind])
        c = np.zeros((N, self.n))
        c[:, dep] = self._solve_dependent(J[:, :, dep], gamma)
        St = np.transpose(S, (0, 2, 1))
        a = np.linalg.solve(St @ M @ S, (St @ (rhs - (M @ c[..., None])[..., 0])[..., None]))
        qdd = (S @ a)[..., 0] + c
        force = rhs - (M @ qdd[..., None])[..., 0]
        lam = (np.linalg.pinv(np.transpose(J, (0, 2, 1)), rcond=RANK_TOLERANCE)
               @ force[..., None])[..., 0]
        return qdd, lam

    def acceleration(self, q, qd, t: float) -> np.ndarray:
        if self.driven:
            return self.dynamics_along(np.atleast_2d(q), np.atleast_2d(qd),
                                       np.atleast_1d(float(t)))[0][0]
        if self._acc_explicit is not None:
            return np.array(self._acc_explicit(*q, *qd, t), dtype=float).reshape(-1)
        return self.dynamics(q, qd, t)[0]

    def ode_rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """Right-hand side in the independent coordinates, y = (q_i, q_i')."""
        k = len(self.independent)
        if self.driven:
            if self._acc_driven is not None:
                return np.concatenate([y[k:], self._acc_driven(*y, t)])
            q, qd = self.driven_state(y, np.atleast_1d(t))
            return np.concatenate([y[k:], self.acceleration(q[0], qd[0], t)[self.independent]])
        if not self.constrained:
            return np.concatenate([y[k:], self.acceleration(y[:k], y[k:], t)])
        if self._explicit is not None:
            return np.concatenate([y[k:], self._explicit[2](*y, t)])
        q, qd = self.state_from_independent(y[:k], y[k:])
        return np.concatenate([y[k:], self.dynamics(q, qd, t)[0][self.independent]])

    def ode_jacobian(self, t: float, y: np.ndarray) -> np.ndarray:
        """d(ode_rhs)/dy of an unconstrained, undriven model, exact: with R = M q'' + h - Q
        zero along the motion, dq''/dq = -M^-1 dR/dq and dq''/dq' = -M^-1 dR/dq' at the
        state's q'' (an implicit integrator's Newton matrix; a finite-difference one
        fails on a coordinate the equations do not contain, such as a free shaft's
        angle, whose column is zero)."""
        if self.constrained or self.driven:
            raise ValueError("the exact Jacobian is written for unconstrained, undriven "
                             "models")
        k = len(self.independent)
        q, qd = y[:k], y[k:]
        M, R_qd, R_q = self.residual_jacobians(q, qd, self.acceleration(q, qd, t), t)
        J = np.zeros((2 * k, 2 * k))
        J[:k, k:] = np.eye(k)
        J[k:, :k] = -np.linalg.solve(M, R_q)
        J[k:, k:] = -np.linalg.solve(M, R_qd)
        return J

    def residual(self, q, qd, qdd, t: float) -> np.ndarray:
        return np.array(self._residual(*q, *qd, *qdd, t), dtype=float).reshape(-1)

    def energy(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """T + V along sampled states (arrays of shape (N, n))."""
        if self._energy is None:
            raise ValueError("this model has no potential for every force element")
        return np.asarray(self._energy(*q.T, *qd.T), dtype=float) * np.ones(len(q))

    # --- statics and linearization -------------------------------------------------------
    def static_multipliers(self, q) -> np.ndarray:
        if not self.constrained:
            return np.zeros(0)
        Q = np.array(self._Q_static(*q), dtype=float).reshape(-1)
        lam, *_ = np.linalg.lstsq(self.constraint_jacobian(q).T, Q, rcond=None)
        return lam

    def reduced_static_force(self, q) -> np.ndarray:
        """S^T Q at rest without time loads (zero at an equilibrium), q consistent."""
        Q = np.array(self._Q_static(*q), dtype=float).reshape(-1)
        return self.velocity_basis(q).T @ Q

    def potential_gradient(self, q) -> np.ndarray:
        """dV/dq in all coordinates (needs every force element's potential)."""
        if self._V is None:
            raise ValueError("a force element has no potential: V is undefined")
        if getattr(self, "_grad_V", None) is None:
            d = self.derivation
            self._grad_V = self._bound("grad_V", lambda: (
                list(d.q), [sp.diff(d.V, x) for x in d.q], "numpy"))
        return np.array([float(v) for v in self._grad_V(*q)])

    def static_residual(self, q) -> np.ndarray:
        """Residual at rest without the time-dependent loads, in the independent
        coordinates: zero at an equilibrium."""
        return -self.reduced_static_force(q)

    def static_equations(self, x: np.ndarray) -> np.ndarray:
        """Equilibrium in all coordinates and multipliers, x = (q, lam):
        Q(q) - Phi_q^T lam = 0 and Phi(q) = 0 (no chart of independent coordinates)."""
        q, lam = x[: self.n], x[self.n:]
        Q = np.array(self._Q_static(*q), dtype=float).reshape(-1)
        return np.concatenate([Q - self.constraint_jacobian(q).T @ lam,
                               self.constraint_values(q)])

    def static_jacobian(self, x: np.ndarray) -> np.ndarray:
        q, lam = x[: self.n], x[self.n:]
        J = self.constraint_jacobian(q)
        K = _matrix(self._lin_K, *q) + sum(l * _matrix(H, *q) for l, H in zip(lam, self._Phi_hess))
        return np.block([[-K, -J.T], [J, np.zeros((self.m, self.m))]])

    def tangent_basis(self, q) -> np.ndarray:
        """Velocities allowed by the constraints: the chart of the independent
        coordinates where it is regular, an orthonormal null-space basis of Phi_q on
        another assembly branch where that chart is singular."""
        if not self.constrained:
            return np.eye(self.n)
        J = self.constraint_jacobian(q)
        if np.linalg.cond(J[:, self.dependent]) < 1e8:
            return self.velocity_basis(q)
        _, sv, vt = np.linalg.svd(J)
        return vt[len(sv[sv > 1e-10 * sv.max()]):].T

    def linearization(self, q, chart: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(M, C, K) in the independent coordinates at the consistent configuration q
        (in a null-space basis where that chart is singular, unless `chart`; eigenvalues
        do not depend on the basis)."""
        S = self.velocity_basis(q) if chart else self.tangent_basis(q)
        M = self.mass_matrix(q)
        C = _matrix(self._lin_C, *q)
        K = _matrix(self._lin_K, *q)
        if self.constrained:
            lam = self.static_multipliers(q)
            K = K + sum(l * _matrix(H, *q) for l, H in zip(lam, self._Phi_hess))
        return S.T @ M @ S, S.T @ C @ S, S.T @ K @ S

    def energy_linearization(self, q):
        """(M, C, K) as Hessians of T, D, V (route 2), or None where it does not apply.
        With constraints, K is the Hessian of the reduced potential V(q(q_i)): exact when
        the constraints solve in closed form, otherwise by Richardson-extrapolated central
        differences (precise to ~1e-9 relative)."""
        if not self.derivation.energy_route:
            return None
        S = self.velocity_basis(q)
        M = S.T @ _matrix(self._hess_T, *q) @ S
        C = S.T @ _matrix(self._hess_D, *q) @ S
        if not self.constrained:
            return M, C, _matrix(self._hess_V, *q)
        # the closed-form reduction holds on its own branch only (a described branch:
        # `Mechanism.branch`; an equilibrium on another is differentiated numerically)
        if self._hess_V_reduced is not None and self.on_branch(q):
            return M, C, _matrix(self._hess_V_reduced, *np.asarray(q)[self.independent])
        k = len(self.independent)

        def V(qi):
            guess = np.array(q, dtype=float)
            guess[self.independent] = qi
            return float(np.real(self._V(*self.complete(guess))))

        qi0 = np.asarray(q, dtype=float)[self.independent]

        def hessian(h):
            K = np.zeros((k, k))
            for a in range(k):
                for b in range(k):
                    ea, eb = np.eye(k)[a] * h, np.eye(k)[b] * h
                    K[a, b] = (V(qi0 + ea + eb) - V(qi0 + ea - eb) - V(qi0 - ea + eb)
                               + V(qi0 - ea - eb)) / (4 * h * h)
            return K

        # Richardson extrapolation of the O(h^2) central difference
        return M, C, (4 * hessian(5e-4) - hessian(1e-3)) / 3

    # --- reactions -----------------------------------------------------------------------
    def reaction(self, joint: str, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                 t: np.ndarray, lam: np.ndarray | None = None) -> np.ndarray:
        """(N, 2) reaction force on the child at `joint`, world axes. In a constrained
        mechanism the closure forces that enter the child's subtree are part of the
        balance: give the multipliers `lam` (N, m) of the same samples, or they are
        computed from (q, q', t)."""
        if joint not in self._reactions:
            d = self.derivation
            lam_syms = [sp.Symbol(f"_lambda{k}") for k in range(self.m)]
            self._reactions[joint] = self._bound(f"reaction-{joint}", lambda: (
                list(d.q) + list(d.qd) + list(d.qdd) + [TIME] + lam_syms,
                list(d.reaction(joint)), "numpy"))
        if self.m and lam is None:
            lam = self.dynamics_along(q, qd, t)[1]
        lam_cols = lam.T if self.m else ()
        fx, fy = self._reactions[joint](*q.T, *qd.T, *qdd.T, t, *lam_cols)
        return np.column_stack([np.broadcast_to(np.asarray(f, dtype=float), (len(t),))
                                for f in (fx, fy)])

    def accelerations(self, q: np.ndarray, qd: np.ndarray, t: np.ndarray) -> np.ndarray:
        return self.dynamics_along(q, qd, t)[0]

    def constraint_forces(self, q: np.ndarray, lam: np.ndarray) -> dict[str, np.ndarray]:
        """Physical constraint forces along a sampled motion (see base.py point 6)."""
        d = self.derivation
        out = {}
        rows = d.constraint_row_slices()
        for c in d.mechanism.constraints:
            cols = list(range(rows[c.name].start, rows[c.name].stop))
            lam_syms = [sp.Symbol(f"_lambda{k}") for k in cols]
            fn = self._bound(f"constraint_force-{c.name}", lambda c=c, lam_syms=lam_syms: (
                list(d.q) + lam_syms, list(d.constraint_force(c)), "numpy"))
            vals = fn(*q.T, *lam[:, cols].T)
            out[c.name] = np.column_stack([np.broadcast_to(np.asarray(v, dtype=float), (len(q),))
                                           for v in vals])
        return out

    def dynamics_along(self, q: np.ndarray, qd: np.ndarray, t: np.ndarray):
        """(q'' (N, n), multipliers (N, m)) along a sampled motion: the augmented system
        of every sample assembled from array-valued functions and solved as one batch."""
        d, n, m, N = self.derivation, self.n, self.m, len(t)
        q, qd, t = np.asarray(q, float), np.asarray(qd, float), np.asarray(t, float)
        args = (*q.T, *qd.T, t)
        A = np.zeros((N, n + m, n + m))
        A[:, :n, :n] = self._along("M_flat", lambda: (list(d.q), list(d.M), "numpy"),
                                   q.T, N).reshape(N, n, n)
        b = np.zeros((N, n + m))
        b[:, :n] = self._along("rhs", lambda: (list(d.q) + list(d.qd) + [TIME],
                                               list(d.Q - d.h), "numpy"), args, N)
        if self.driven:
            # prescribed rows replaced by q_p'' = q_p''(t)
            qdd_p = self.motion(t)[2]
            for j, k in enumerate(self.driven):
                A[:, k, :] = 0.0
                A[:, k, k] = 1.0
                b[:, k] = qdd_p[:, j]
        if m and self.redundant:
            gamma = self._along("gamma", None, (*q.T, *qd.T), N)
            return self._redundant_dynamics(A[:, :n, :n], self._jacobians_along(q),
                                            b[:, :n], gamma)
        if m:
            J = self._jacobians_along(q)
            A[:, :n, n:] = np.transpose(J, (0, 2, 1))
            A[:, n:, :n] = J
            b[:, n:] = self._along("gamma", None, (*q.T, *qd.T), N)
        sol = np.linalg.solve(A, b[..., None])[..., 0]
        return sol[:, :n], sol[:, n:]

    def complete_along(self, qi: np.ndarray, guesses: np.ndarray) -> np.ndarray:
        """`complete` for N samples at once, (N, n): Newton's iterations on every sample
        together, each from its own guess (rows of `guesses`), a row frozen once its step
        meets the tolerance of `complete`."""
        q = np.array(guesses, dtype=float)
        q[:, self.independent] = qi
        dep, N = self.dependent, len(q)
        active = np.ones(N, dtype=bool)
        for _ in range(NEWTON_MAX):
            rows = q[active]
            phi = self._along("Phi", None, rows.T, len(rows))
            J = self._jacobians_along(rows)[:, :, dep]
            step = self._solve_dependent(J, phi)
            rows[:, dep] -= step
            q[active] = rows
            done = np.max(np.abs(step), axis=1) <= NEWTON_TOL * np.maximum(
                1.0, np.max(np.abs(rows[:, dep]), axis=1))
            active[np.flatnonzero(active)[done]] = False
            if not active.any():
                break
        else:
            raise RuntimeError("the constraint equations did not converge (assembly lost)")
        if np.max(np.abs(self._along("Phi", None, q.T, N))) > 1e-10:
            raise RuntimeError("the constraint equations have no solution here")
        if self.redundant:
            for row in q:
                self._check_rank(row)
        return q

    def velocities_along(self, q: np.ndarray, qdi: np.ndarray) -> np.ndarray:
        """q' = S(q) q_i' for N consistent samples, (N, n)."""
        N = len(q)
        ind, dep = self.independent, self.dependent
        J = self._jacobians_along(q)
        qd = np.zeros((N, self.n))
        qd[:, ind] = qdi
        qd[:, dep] = -self._solve_dependent(J[:, :, dep], (J[:, :, ind] @ qdi[..., None])[..., 0])
        return qd

    def point_states(self, q: np.ndarray, qd: np.ndarray) -> dict[str, np.ndarray]:
        """World position and velocity of each named point of the system
        (`System.points`) along N sampled states: (N, 2 d) per point, the d position
        components then the d velocity components (d = 2 planar, 3 spatial)."""
        system, d = get_system(self.compiled.system_id), self.derivation
        q, qd = np.atleast_2d(np.asarray(q, float)), np.atleast_2d(np.asarray(qd, float))
        out = {}
        for p in system.points(system.symbols):
            if p.body not in d.poses:
                raise ValueError(f"{system.id}: point {p.name} is on {p.body!r}, which is not "
                                 f"a body of the mechanism")

            def build(p=p):
                r = d.point(p.body, p.position)
                return list(d.q) + list(d.qd), list(r) + list(d.velocity(r)), "numpy"
            out[p.name] = self._along(f"point-{p.name}", build, (*q.T, *qd.T), len(q))
        return out

    def _jacobians_along(self, q: np.ndarray) -> np.ndarray:
        """Phi_q at N samples, (N, m, n)."""
        d = self.derivation
        return self._along("Phi_q_flat", lambda: (list(d.q), list(d.Phi_q), "numpy"),
                           q.T, len(q)).reshape(len(q), self.m, self.n)

    def _along(self, name: str, build, args, N: int) -> np.ndarray:
        """(N, k) values of the list-valued compiled function `name` at N samples."""
        fn = self.compiled.function(name, build)
        values = fn(*self.parameter_values, *args)
        return np.stack([np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in values],
                        axis=1)


@lru_cache(maxsize=64)
def _numeric_cached(system_id: str, items: tuple) -> NumericModel:
    return NumericModel(compiled_system(system_id), dict(items))


def numeric_model(system_id: str, values: Mapping[str, float]) -> NumericModel:
    """The system's compiled model bound to `values`; for the structure in `values`
    (a system with structural parameters: `System.with_structure`)."""
    system = get_system(system_id)
    if system.structure:
        system_id = system.with_structure(values).id
    return _numeric_cached(system_id, tuple(sorted(values.items())))


def contact_forces(system, values: Mapping[str, float], q: np.ndarray,
                   reactions: Mapping[str, np.ndarray],
                   constraint_forces: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Each `ContactOutput` of the system along a sampled motion, (N,) per contact: the
    same projection for the reference and for every engine's own reactions and closure
    forces. A source missing from the inputs gives NaN (the engine cannot report it)."""
    from ..systems import coordinate_symbols

    P = system.symbols
    compiled = compiled_system(system.id)
    bound = tuple(float(values[k]) for k in compiled.parameter_names)
    coords = [coordinate_symbols(c)[0] for c in system.coordinates]
    out: dict[str, np.ndarray] = {}
    for c in system.contacts(P):
        pool = reactions if c.kind == "reaction" else constraint_forces
        if c.kind not in ("reaction", "constraint"):
            raise ValueError(f"{system.id}: contact {c.name!r}: source must be "
                             f"'reaction:<joint>' or 'constraint:<name>', not {c.source!r}")
        force = pool.get(c.target)
        if force is None:
            out[c.name] = np.full(len(q), np.nan)
            continue
        force = np.asarray(force, dtype=float)
        if c.direction is None:
            if force.shape[1] != 1:
                raise ValueError(f"{system.id}: contact {c.name!r} needs a direction "
                                 f"({c.source} is a vector)")
            out[c.name] = force[:, 0]
            continue
        fn = compiled.function(f"contact_direction-{c.name}", lambda c=c: (
            coords, [sp.sympify(x) for x in c.direction], "numpy"))
        ux, uy = (np.broadcast_to(np.asarray(v, dtype=float), (len(q),)) for v in fn(*bound, *q.T))
        out[c.name] = ux * force[:, 0] + uy * force[:, 1]
    return out
