"""Printed formulas of the monograph against the symbolic derivation.

Every comparison is numeric at many random states and at two parameter sets (the defaults
and a random perturbation of them), so that no agreement is a coincidence of the default
values; verdicts are "agrees" or "misprint". The printed models themselves are here too
(`printed_model_trajectory`, `printed_multiplier_trajectory`, `printed_model_frequencies`):
the engines run against them as witnesses of a misprint in `comparisons/witnesses.py`.

Formulas with Lagrange multipliers and constraints (monograph §10, eq. 110-116), judged
independently of how the monograph normalises, orders or signs them:
- "constraint": the printed Phi must vanish on our constraint manifold and its Jacobian
  there must have the rank (row space) of ours: then both zero sets are manifolds of the
  same dimension, one containing the other, so they coincide locally.
- "constraint_jacobian": the printed matrix and the derived Phi_q must have the same row
  space (printed J = T Phi_q with T invertible), measured as the distance between the
  orthogonal projectors onto the two row spaces (the sine of their largest principal
  angle: 0 when equal, 1 when the ranks differ).
- "eom" with `multipliers`: at consistent states with the derived q'', the printed rows
  are linear in the printed multipliers, r0 + A lam_p = 0. (1) As a system: lam_p fitted by
  least squares, residual relative to each row's term scale: whether the printed
  equations admit our motion with some multipliers. (2) Row by row: the derivation's
  generalized constraint force Phi_q^T lam must equal the printed one, A lam_p (eq. 112:
  lam_j phi_ij is the generalized force of constraint j), which fixes lam_p from our
  multipliers by least squares; each row's residual with these lam_p says which rows are
  wrong (a fit of its own would hide an error of one row in the others).
- "dissipation_power": the printed P_nc against (Q + dV/dq) . q', the power of every
  generalized force that has no potential (dampers, friction, motors, time loads); the
  constraint forces do no work on consistent velocities.

The printed equations with multipliers as a model of their own (for the witnesses): the
printed rows, linear in (q'', lam_p), are written A(q, q', t) [q''; lam_p] + b(q, q', t) = 0
and closed with the DERIVED acceleration-level constraint Phi_q q'' = gamma, so the printed
dynamics evolve on the true constraint manifold (`printed_multiplier_trajectory`); their
modes at the derived equilibrium (printed static multipliers fitted there), the
multipliers eliminated with the left null space N of their coefficients and the motion
restricted to the manifold with the velocity basis S: N^T M_p S s^2 + N^T C_p S s +
N^T K_p S (`printed_model_frequencies`).
"""
from __future__ import annotations

import pickle
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Mapping

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from ..systems import PrintedFormula, System, coordinate_symbols
from ..systems.model import TIME, Prismatic
from . import cache
from .derivation import cache_key, derivation_of
from .linear import linearize, operating_equilibrium
from .relative_equilibrium import relative_residual
from .numeric import _lambdify, numeric_model

AGREEMENT = 1e-9  # relative; round-off of the numeric comparison is ~1e-14
#: condition number of the printed augmented matrix [A; Phi_q 0] beyond which the printed
#: model does not determine (q'', lam_p): singular printed model, no trajectory witness
SINGULAR_CONDITION = 1e10


@dataclass
class Erratum:
    system: str
    label: str
    kind: str
    printed: str
    derived: str
    verdict: str
    max_relative_difference: float
    note: str = ""
    witnesses: dict = field(default_factory=dict)
    #: kind-specific measurements behind the verdict (multiplier fits, row spaces)
    details: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def _parameter_sets(system: System, rng) -> list[dict[str, float]]:
    """The defaults and one random perturbation (+-30 %) that keeps the geometry valid
    and the mechanism assembled with an equilibrium near its operating point (redrawn
    otherwise)."""
    base = system.parameter_values()
    for _ in range(50):
        perturbed = {k: (v * rng.uniform(0.7, 1.3) if v != 0 else v) for k, v in base.items()}
        if not system.is_valid(perturbed):
            continue
        try:
            operating_equilibrium(system, perturbed)
        except (ValueError, TypeError, RuntimeError, np.linalg.LinAlgError):
            continue
        return [base, perturbed]
    return [base]


def _random_states(system: System, values, rng, count: int = 25):
    """Random consistent states: independent coordinates drawn around the operating point,
    dependent ones from the constraints."""
    op = system.operating_values(values)
    model = numeric_model(system.id, values)
    independent = set(system.mechanism.independent_coordinates)
    out = []
    while len(out) < count:
        q = op.copy()
        for i, j in enumerate(system.mechanism.joints):
            if j.coordinate not in independent:
                continue
            # closed loops: stay near the operating assembly branch (a large step may
            # land on another branch or a singular pose, where printed formulas lapse)
            spread = 0.3 if model.constrained else 1.2
            if isinstance(j, Prismatic):
                q[i] = op[i] * rng.uniform(1 - spread / 3, 1 + spread / 3) + (
                    0 if op[i] else rng.uniform(-0.1, 0.1))
            else:
                q[i] = op[i] + rng.uniform(-spread, spread)
        try:
            q = model.complete(q)
            model.velocity_basis(q)
        except (RuntimeError, np.linalg.LinAlgError):
            continue
        qd = model.velocity_basis(q) @ rng.uniform(-1.5, 1.5, size=len(model.independent))
        t = rng.uniform(0, 10)
        if model.driven:
            # prescribed coordinates where their motion puts them at t
            qp, qdp, _ = model.motion(t)
            q[model.driven], qd[model.driven] = qp, qdp
        out.append((q, qd, t))
    return out


def _equilibrium_at(system: System, values, pf: PrintedFormula):
    if pf.at is None:
        return operating_equilibrium(system, values)
    model = numeric_model(system.id, values)
    guess = system.operating_values(values)
    for name, value in pf.at.items():
        guess[system.coordinates.index(name)] = system.evaluate(value, values)
    return linearize(model, model.complete(guess))


def _term_scale(expr: sp.Expr, env: dict) -> float:
    terms = sp.Add.make_args(sp.expand(expr))
    return float(sum(abs(complex(t.xreplace(env))) for t in terms)) or 1.0


def _env(system: System, values, q, qd, qdd, t) -> dict:
    env = dict(system.subs(values))
    for name, a, b, c in zip(system.coordinates, q, qd, qdd):
        s, sd, sdd = coordinate_symbols(name)
        env.update({s: a, sd: b, sdd: c})
    env[TIME] = t
    return env


def _with_relations(system: System, values: dict, pf: PrintedFormula) -> dict:
    if not pf.relations:
        return values
    out = dict(values)
    for name, expr in pf.relations.items():
        out[name] = system.evaluate(expr, values)
    return out


def reduced_equations(system: System) -> list[sp.Expr] | None:
    """Equations of motion in the independent coordinates, symbolically, when the
    constraints can be solved for the dependent coordinates in closed form (else None):
    T, V and the generalized forces are restricted to the manifold and Lagrange's
    equations applied to them."""
    d = derivation_of(system.id)
    if not d.m:
        return list(d.residual)
    ind = [i for i in d.independent]
    q_of = d.explicit_dependent  # guarded: sympy's solve does not return on some loops
    if q_of is None:
        return None
    qi = [d.q[i] for i in ind]
    qdi = [d.qd[i] for i in ind]
    qddi = [d.qdd[i] for i in ind]
    qd_of = {d.qd[i]: sum(sp.diff(q_of[d.q[i]], a) * b for a, b in zip(qi, qdi))
             for i in d.dependent}
    sub = {**q_of, **qd_of}
    T = d.T.xreplace(sub)
    S = sp.Matrix([[sp.diff(q_of.get(d.q[k], d.q[k]), a) for a in qi] for k in range(d.n)])
    Q = (S.T * d.Q).xreplace(sub)
    eqs = []
    for a, (x, v, acc) in enumerate(zip(qi, qdi, qddi)):
        dT = sp.diff(T, v)
        ddt = sum(sp.diff(dT, y) * w for y, w in zip(qi, qdi)) + sum(
            sp.diff(dT, w) * z for w, z in zip(qdi, qddi))
        eqs.append(ddt - sp.diff(T, x) - Q[a])
    return eqs


#: rank of a numeric Jacobian: singular values above this fraction of the largest (entries
#: carry ~1e-16 relative round-off; a rank drop on the manifold would be O(1))
RANK_TOLERANCE = 1e-10


def _row_space(J: np.ndarray) -> np.ndarray:
    """Orthonormal basis (as rows) of the row space of J."""
    _, sv, vt = np.linalg.svd(np.atleast_2d(np.asarray(J, dtype=float)))
    if not sv.size or sv[0] == 0:
        return np.zeros((0, vt.shape[1]))
    return vt[: int(np.sum(sv > RANK_TOLERANCE * sv[0]))]


def row_space_distance(A: np.ndarray, B: np.ndarray) -> float:
    """||P_A - P_B||_2 for the orthogonal projectors onto the row spaces of A and B: the
    sine of the largest principal angle between them, 1 when their ranks differ.
    Insensitive to the order, sign and scale of the rows (J and T J, T invertible)."""
    va, vb = _row_space(A), _row_space(B)
    if va.shape[0] != vb.shape[0]:
        return 1.0
    return float(np.linalg.norm(va.T @ va - vb.T @ vb, 2))


def _num(expr, env: dict) -> float:
    return float(sp.sympify(expr).xreplace(env))


@lru_cache(maxsize=None)
def nonconservative_power(system_id: str) -> sp.Expr:
    """(Q + dV/dq) . q': the power of the generalized forces that have no potential."""
    d = derivation_of(system_id)
    if not d.energy_route:
        # a force element with neither potential nor dissipation declared cannot be sorted
        # into conservative and non-conservative
        raise ValueError(f"{system_id}: no potential for every force element; P_nc undefined")
    grad = sp.Matrix([sp.diff(d.V, x) for x in d.q])
    return sp.expand(((d.Q + grad).T * d.qd)[0])


def reduced_gradient(model, q: np.ndarray) -> np.ndarray:
    """dV/dq_i along the constraint manifold (independent coordinates): S^T grad V."""
    return model.velocity_basis(q).T @ model.potential_gradient(q)


def reduced_hessian(model, q: np.ndarray, step: float = 1e-3) -> np.ndarray:
    """d2V/dq_i dq_j along the manifold: central differences of `reduced_gradient`,
    Richardson-extrapolated: truncation ~ step^4 = 1e-12 and round-off of the gradient
    differences ~ 1e-16/step = 1e-13, both far below the 1e-9 agreement threshold."""
    ind = model.independent

    def grad_at(i: int, delta: float) -> np.ndarray:
        p = np.array(q, dtype=float)
        p[ind[i]] += delta
        return reduced_gradient(model, model.complete(p))

    H = np.empty((len(ind), len(ind)))
    for i in range(len(ind)):
        d1 = (grad_at(i, step) - grad_at(i, -step)) / (2 * step)
        d2 = (grad_at(i, step / 2) - grad_at(i, -step / 2)) / step
        H[:, i] = (4 * d2 - d1) / 3
    return H


def _compare(system: System, pf: PrintedFormula, rng) -> tuple[float, str, dict]:
    """(max relative difference, derived form as text, details)."""
    d = derivation_of(system.id)
    worst = 0.0
    derived_text = ""
    details: dict = {}
    for values in _parameter_sets(system, rng):
        values = _with_relations(system, values, pf)
        model = numeric_model(system.id, values)
        eq = _equilibrium_at(system, values, pf)
        if pf.kind == "eom":
            reduced = _reduced_cached(system.id)
            derived_text = ("; ".join(f"{r} = 0" for r in reduced) if reduced is not None
                            else "reduced numerically (constraints have no closed-form solution)")
            for q, qd, t in _random_states(system, values, rng):
                qdd = model.acceleration(q, qd, t)
                env = _env(system, values, q, qd, qdd, t)
                for r in pf.expr:
                    worst = max(worst, abs(float(r.xreplace(env))) / _term_scale(r, env))
        elif pf.kind == "kinetic_energy":
            derived_text = str(sp.factor_terms(d.T))
            for q, qd, t in _random_states(system, values, rng):
                env = _env(system, values, q, qd, np.zeros_like(q), t)
                Td = float(d.T.xreplace(env))
                worst = max(worst, abs(float(pf.expr.xreplace(env)) - Td) / max(abs(Td), 1e-300))
        elif pf.kind == "potential_energy":
            derived_text = str(d.V)
            qs = [coordinate_symbols(n)[0] for n in system.coordinates]
            for q, qd, t in _random_states(system, values, rng):
                env = _env(system, values, q, qd, np.zeros_like(q), t)
                # gradients along the constraint manifold: S^T grad V
                S = model.velocity_basis(q)
                gp = S.T @ np.array([float(sp.diff(pf.expr, s).xreplace(env)) for s in qs])
                gd = S.T @ np.array([float(sp.diff(d.V, s).xreplace(env)) for s in qs])
                worst = max(worst, np.max(np.abs(gp - gd)) / max(np.max(np.abs(gd)), 1e-12))
        elif pf.kind in ("M", "K", "C"):
            derived = {"M": eq.M, "K": eq.K, "C": eq.C}[pf.kind]
            printed = np.array(pf.expr.xreplace(system.subs(values)), dtype=float)
            derived_text = np.array2string(derived, precision=6)
            scale = max(np.max(np.abs(derived)), 1e-300)
            worst = max(worst, float(np.max(np.abs(printed - derived)) / scale))
        elif pf.kind == "equilibrium":
            q = system.operating_values(values)
            for name, value in pf.expr.items():
                q[system.coordinates.index(name)] = system.evaluate(value, values)
            q = model.complete(q)
            scale = max(1.0, float(np.max(np.abs(eq.K))))
            # a floating mechanism's equilibrium is relative: its residual with the rigid
            # accelerations that fit it (Italian notes §5.3.1)
            residual = (model.static_residual(q) if eq.rigid is None
                        else relative_residual(model, q, eq.rigid))
            worst = max(worst, float(np.max(np.abs(residual))) / scale)
            derived_text = f"q_eq = {np.array2string(eq.q, precision=9)}"
            if eq.acceleration is not None:
                derived_text += (f", moving rigidly with q'' = "
                                 f"{np.array2string(eq.acceleration, precision=9)}")
        elif pf.kind in ("frequency", "damping_ratio"):
            value = float(pf.expr.xreplace(system.subs(values)))
            if pf.kind == "frequency":
                candidates = [abs(m.eigenvalue) for m in eq.modes]
            else:
                candidates = [m.damping_ratio for m in eq.modes]
            best = min(candidates, key=lambda c: abs(c - value))
            worst = max(worst, abs(value - best) / max(abs(best), 1e-300))
            derived_text = f"{best:.12g} (closest derived mode, " + (
                "|s| rad/s)" if pf.kind == "frequency" else "zeta)")
        elif pf.kind == "constraint_force":
            name, expr = pf.expr
            actuator = name.startswith("actuator:")
            derived_text = (f"the force of {name[len('actuator:'):]!r} on its coordinate"
                            if actuator else f"from the multipliers of constraint {name!r}")
            exprs = list(expr) if isinstance(expr, (list, tuple, sp.MatrixBase)) else [expr]
            for q, qd, t in _random_states(system, values, rng):
                qdd, lam = model.dynamics(q, qd, t)
                if actuator:  # a prescribed coordinate's actuator force (§9.6)
                    qdd = model.acceleration(q, qd, t)  # the prescribed q'' included
                    f = np.atleast_1d(model.actuator_forces(
                        q[None, :], qd[None, :], qdd[None, :], np.array([t]))[
                        name[len("actuator:"):]][0])
                else:
                    f = model.constraint_forces(q[None, :], lam[None, :])[name][0]
                env = _env(system, values, q, qd, qdd, t)
                printed = np.array([float(sp.sympify(e).xreplace(env)) for e in exprs])
                worst = max(worst, float(np.max(np.abs(printed - f[:len(printed)])))
                            / max(float(np.max(np.abs(f))), 1e-12))
        elif pf.kind == "constraint":
            derived_text = "; ".join(f"{sp.simplify(r)} = 0" for r in d.Phi)
            rows = [sp.sympify(r) for r in pf.expr]
            qs = [coordinate_symbols(n)[0] for n in system.coordinates]
            jac = sp.Matrix(rows).jacobian(qs)
            zero = details.get("zero_set_residual", 0.0)
            dist = details.get("row_space_distance", 0.0)
            for q, qd, t in _random_states(system, values, rng):
                env = _env(system, values, q, qd, np.zeros_like(q), t)
                zero = max([zero] + [abs(_num(r, env)) / _term_scale(r, env) for r in rows])
                printed_J = np.array(jac.xreplace(env), dtype=float)
                dist = max(dist, row_space_distance(printed_J, model.constraint_jacobian(q)))
            details.update(zero_set_residual=zero, row_space_distance=dist)
            worst = max(zero, dist)
        elif pf.kind == "constraint_jacobian":
            derived_text = str(d.Phi_q.applyfunc(sp.simplify))
            dist = details.get("row_space_distance", 0.0)
            for q, qd, t in _random_states(system, values, rng):
                env = _env(system, values, q, qd, np.zeros_like(q), t)
                printed_J = np.array(sp.Matrix(pf.expr).xreplace(env), dtype=float)
                dist = max(dist, row_space_distance(printed_J, model.constraint_jacobian(q)))
            details.update(row_space_distance=dist)
            worst = dist
        elif pf.kind in ("potential_gradient", "potential_hessian"):
            derived_text = ("S^T grad V (the derived potential's gradient along the constraint "
                            "manifold, in the independent coordinates)" if pf.kind ==
                            "potential_gradient" else "d/dq_i of S^T grad V (central "
                            "differences on the manifold, Richardson-extrapolated)")
            for q, qd, t in _random_states(system, values, rng, count=10):
                env = _env(system, values, q, qd, np.zeros_like(q), t)
                if pf.kind == "potential_gradient":
                    derived = reduced_gradient(model, q)
                    printed = np.array([_num(e, env) for e in pf.expr])
                else:
                    derived = reduced_hessian(model, q)
                    printed = np.array(sp.Matrix(pf.expr).xreplace(env), dtype=float)
                worst = max(worst, float(np.max(np.abs(printed - derived)))
                            / max(float(np.max(np.abs(derived))), 1e-12))
        elif pf.kind == "dissipation_power":
            P = nonconservative_power(system.id)
            derived_text = str(P)
            for q, qd, t in _random_states(system, values, rng):
                env = _env(system, values, q, qd, np.zeros_like(q), t)
                # relative to the sum of the terms' magnitudes: P_nc is a sum of squares
                # that may nearly cancel against a motor's power
                scale = max(_term_scale(P, env), _term_scale(pf.expr, env))
                worst = max(worst, abs(_num(pf.expr, env) - _num(P, env)) / scale)
        else:
            raise ValueError(f"unknown printed-formula kind {pf.kind!r}")
    return worst, derived_text, details


def _derived_with_multipliers(system_id: str) -> list[str]:
    """Our Lagrange equations with multipliers (eq. 112 with the derived Phi_q): rows
    M q'' + h - Q + Phi_q^T lam = 0, as text."""
    d = derivation_of(system_id)
    lam = sp.Matrix(d.m, 1, [sp.Symbol(f"lam{k + 1}") for k in range(d.m)])
    rows = d.residual + d.Phi_q.T * lam
    return [str(sp.collect(sp.expand(r), list(lam))) for r in rows]


def _compare_multipliers(system: System, pf: PrintedFormula, rng) -> dict:
    """A printed "eom" with Lagrange multipliers (see the module docstring): worst relative
    residual per row with the multipliers implied by the derivation (`rows`), of the whole
    printed system with multipliers fitted by least squares (`system`), and how far the
    printed constraint-force directions are from spanning ours (`map`)."""
    lams = list(pf.multipliers)
    rows = [sp.expand(sp.sympify(r)) for r in pf.expr]
    A_sym = [[sp.diff(r, L) for L in lams] for r in rows]
    if any(sp.diff(a, L) != 0 for row in A_sym for a in row for L in lams):
        raise ValueError(f"{pf.label}: the printed rows are not linear in {lams}")
    r0_sym = [r.xreplace({L: 0 for L in lams}) for r in rows]
    # row i is the equation of coordinate i (the printed coordinates are the system's)
    by_coordinate = len(rows) == len(system.coordinates)
    out = {"rows": np.zeros(len(rows)), "system": 0.0, "map": 0.0}
    for values in _parameter_sets(system, rng):
        values = _with_relations(system, values, pf)
        model = numeric_model(system.id, values)
        for q, qd, t in _random_states(system, values, rng):
            qdd, lam = model.dynamics(q, qd, t)
            if model.driven:  # prescribed coordinates follow their motion (convention 9)
                qdd = model.acceleration(q, qd, t)
            env = _env(system, values, q, qd, qdd, t)
            A = np.array([[_num(a, env) for a in row] for row in A_sym]).reshape(len(rows), -1)
            r0 = np.array([_num(r, env) for r in r0_sym])

            def residuals(lam_p):
                e = {**env, **dict(zip(lams, lam_p))}
                return np.abs(r0 + A @ lam_p) / np.array([_term_scale(r, e) for r in rows])

            fitted, *_ = np.linalg.lstsq(A, -r0, rcond=None)
            out["system"] = max(out["system"], float(np.max(residuals(fitted))))
            if pf.multiplier_forces:
                forces = model.constraint_forces(q[None, :], lam[None, :])
                # an actuator's force (§9.6) is the derivation's too: "actuator:<name>"
                forces.update({f"actuator:{k}": v[:, None] for k, v in model.actuator_forces(
                    q[None, :], qd[None, :], qdd[None, :], np.array([t])).items()})
                mapped = np.array([forces[name][0, comp]
                                   for name, comp in (pf.multiplier_forces[L] for L in lams)])
            elif by_coordinate and model.constrained:
                # M q'' + h - Q = -Phi_q^T lam: the printed A lam_p must be Phi_q^T lam
                force = model.constraint_jacobian(q).T @ lam
                mapped, *_ = np.linalg.lstsq(A, force, rcond=None)
                out["map"] = max(out["map"], float(np.linalg.norm(A @ mapped - force))
                                 / max(float(np.linalg.norm(force)), 1e-300))
            else:
                mapped = fitted
            out["rows"] = np.maximum(out["rows"], residuals(mapped))
    return out


def _multiplier_errata(system: System, pf: PrintedFormula, rng) -> list[Erratum]:
    res = _compare_multipliers(system, pf, rng)
    derived = _derived_with_multipliers(system.id)
    names = [str(L) for L in pf.multipliers]
    common = {"multipliers": names, "system_fit_residual": res["system"],
              "multiplier_map_residual": res["map"]}
    out = [Erratum(system.id, f"{pf.label} (as a system, multipliers fitted)", "eom",
                   _printed_text(pf), "; ".join(f"{r} = 0" for r in derived),
                   "agrees" if res["system"] <= AGREEMENT else "misprint", res["system"],
                   pf.note, details={**common, "multipliers_from": "least-squares fit"})]
    by_coordinate = len(pf.expr) == len(system.coordinates)
    if not (pf.multiplier_forces or by_coordinate):
        return out  # per-row multipliers would be fitted too: rows could not fail
    for i, (r, w) in enumerate(zip(pf.expr, res["rows"])):
        out.append(Erratum(
            system.id, f"{pf.label}, row {i + 1}", "eom", f"{r} = 0",
            f"{derived[i]} = 0" if by_coordinate and i < len(derived) else "",
            "agrees" if w <= AGREEMENT else "misprint", float(w), pf.note,
            details={**common, "multipliers_from": "the derivation's constraint forces"}))
    return out


@lru_cache(maxsize=None)
def _reduced_cached(system_id: str):
    from ..systems import get_system

    system = get_system(system_id)
    eqs = reduced_equations(system)
    if eqs is None:
        return None
    # lengths are sqrt(x^2) = |x|; x keeps one sign over the mechanism's range, so take it
    # from the operating point (display only: the comparison is numeric)
    values = system.parameter_values()
    env = {**system.subs(values), **{coordinate_symbols(c)[0]: v for c, v in
                                     zip(system.coordinates, system.operating_values(values))}}

    def unsign(expr):
        return expr.replace(lambda e: isinstance(e, sp.Abs),
                            lambda e: e.args[0] * (1 if float(e.args[0].xreplace(env)) >= 0 else -1))
    def tidy(e):
        e = unsign(e)
        # simplify only what is small: on the larger reductions it runs for minutes, and
        # the text is for reading (the comparison is numeric)
        return sp.simplify(e) if sp.count_ops(e) < 60 else e
    return [tidy(e) for e in eqs]


def _printed_text(pf: PrintedFormula) -> str:
    if pf.kind == "eom":
        return "; ".join(f"{e} = 0" for e in pf.expr)
    if pf.kind == "equilibrium":
        return ", ".join(f"{k} = {v}" for k, v in pf.expr.items())
    return str(pf.expr)


def _one_equation_each(formulas) -> list[PrintedFormula]:
    """A printed system of equations gets one verdict per equation."""
    out = []
    for pf in formulas:
        if pf.kind == "eom" and len(pf.expr) > 1 and not pf.multipliers:
            out += [PrintedFormula(f"{pf.label}, row {i + 1}", "eom", [r], pf.note)
                    for i, r in enumerate(pf.expr)]
        else:
            out.append(pf)
    return out


def errata(system: System, seed: int = 20101) -> list[Erratum]:
    """Every printed formula of the system against the derivation. Deterministic, so kept
    in the persistent cache (`analytic.cache`) under the system's content key and the
    analytic code that computes it."""
    key, name = cache_key(system), f"errata-{seed}-{cache.analytic_digest()}.pickle"
    blob = cache.load(key, name)
    if blob is not None:
        try:
            return pickle.loads(blob)
        except Exception:  # an unreadable entry is recomputed, never trusted
            pass
    out = _errata(system, seed)
    cache.store(key, name, pickle.dumps(out, protocol=pickle.HIGHEST_PROTOCOL))
    return out


def _errata(system: System, seed: int) -> list[Erratum]:
    rng = np.random.default_rng(seed)
    out = []
    for pf in _one_equation_each(system.printed(system.symbols)):
        if pf.kind == "eom" and pf.multipliers:
            # one verdict for the printed system, one per row (module docstring)
            out += _multiplier_errata(system, pf, rng)
            continue
        worst, derived, details = _compare(system, pf, rng)
        verdict = "agrees" if worst <= AGREEMENT else "misprint"
        out.append(Erratum(system.id, pf.label, pf.kind, _printed_text(pf), derived, verdict,
                           float(worst), pf.note, details=details))
    return out


def printed_model_trajectory(system: System, pf: PrintedFormula, values: Mapping[str, float],
                             q0, qd0, t: np.ndarray) -> np.ndarray | None:
    """Integrate the printed equations of motion (kind "eom") when they determine the
    accelerations of the independent coordinates; returns those coordinates (N, k)."""
    if pf.kind != "eom" or pf.multipliers:
        return None  # with multipliers the printed equations need the constraints too
    model = numeric_model(system.id, values)
    syms = [coordinate_symbols(n) for n in system.coordinates]
    ind = model.independent
    given = {}
    for p in system.mechanism.prescribed:
        # prescribed coordinates are the given functions of time (§9.6)
        trio = syms[system.coordinates.index(p.coordinate)]
        given.update(zip(trio, (p.motion, p.rate, p.acceleration)))
    eqs = [sp.sympify(r).xreplace(given).xreplace(system.subs(values)) for r in pf.expr]
    used = set().union(*(e.free_symbols for e in eqs))
    if any(s in used for i, trio in enumerate(syms) if i not in ind for s in trio):
        return None  # written in dependent coordinates too
    qdd = [syms[i][2] for i in ind]
    sol = sp.solve(eqs, qdd, dict=True)
    if len(sol) != 1 or set(sol[0]) != set(qdd):
        return None
    args = [syms[i][0] for i in ind] + [syms[i][1] for i in ind] + [TIME]
    acc = sp.lambdify(args, [sol[0][a] for a in qdd], modules="math")
    k = len(ind)

    def rhs(tt, y):
        return np.concatenate([y[k:], acc(*y[:k], *y[k:], tt)])

    try:
        res = solve_ivp(rhs, (t[0], t[-1]), np.concatenate([q0[ind], qd0[ind]]),
                        method="DOP853", rtol=1e-12, atol=1e-12, t_eval=t)
    except (ZeroDivisionError, OverflowError, ValueError):
        return None  # the printed equations are singular on this motion: no witness
    return res.y[:k].T if res.success and res.y.shape[1] == len(t) else None


class SingularPrintedModel(ValueError):
    """The printed equations with multipliers do not determine (q'', lam_p) here."""


def _printed_linear_in_unknowns(system: System, pf: PrintedFormula,
                                values: Mapping[str, float]):
    """The printed rows of an "eom" with multipliers as A(q, q', t) x + b(q, q', t) with
    x = (q'', lam_p): (A, b) as sympy matrices with the parameter values substituted, and
    the symbols (q, q', q'', lam_p). Raises ValueError when the rows are not linear in x."""
    syms = [coordinate_symbols(n) for n in system.coordinates]
    q, qd, qdd = ([trio[k] for trio in syms] for k in range(3))
    lams = list(pf.multipliers)
    unknowns = qdd + lams
    rows = sp.Matrix([sp.sympify(r).xreplace(system.subs(values)) for r in pf.expr])
    A = rows.jacobian(unknowns)
    if any(x in A.free_symbols for x in unknowns):
        raise ValueError(f"{pf.label}: the printed rows are not linear in q'' and {lams}")
    b = rows.xreplace({x: 0 for x in unknowns})
    return A, b, (q, qd, qdd, lams)


def printed_multiplier_trajectory(system: System, pf: PrintedFormula,
                                  values: Mapping[str, float], q0, qd0,
                                  t: np.ndarray) -> tuple[np.ndarray, float]:
    """Integrate printed equations of motion with multipliers on the derived constraint
    manifold: A [q''; lam_p] + b = 0 (printed) closed by Phi_q q'' = gamma (derived), an
    index-1 system in all n coordinates, from a consistent (q0, qd0). Not in the
    independent coordinates as the reference: the printed motion need not stay clear of
    the singular poses of that chart (the five-bar's printed motion swings the bars inwards
    to Q = Q', where phi1, phi2 fix no wing angle). Returns (q (N, n) at t, the largest
    |Phi| along it: the drift, without Baumgarte or projection, is round-off of the
    integration, ~1e-13 over seconds). Raises `SingularPrintedModel` where the printed
    augmented matrix is singular (condition > `SINGULAR_CONDITION`), ValueError when the
    printed rows do not fit this form."""
    model = numeric_model(system.id, values)
    if not model.constrained:
        raise ValueError(f"{system.id}: printed multipliers on an unconstrained system")
    A_sym, b_sym, (q, qd, _, lams) = _printed_linear_in_unknowns(system, pf, values)
    n, m = model.n, model.m
    if A_sym.shape != (n, n + len(lams)) or len(lams) != m:
        raise ValueError(f"{pf.label}: {A_sym.shape[0]} rows and {len(lams)} multipliers for "
                         f"{n} coordinates and {m} constraints")
    args = q + qd + [TIME]
    A_fn = _lambdify(args, A_sym.tolist(), modules="math")
    b_fn = _lambdify(args, list(b_sym), modules="math")

    def rhs(tt, y):
        qq, vv = y[:n], y[n:]
        aug = np.zeros((n + m, n + m))
        aug[:n] = np.array(A_fn(*qq, *vv, tt), dtype=float)
        aug[n:, :n] = model.constraint_jacobian(qq)
        cond = np.linalg.cond(aug)
        if not np.isfinite(cond) or cond > SINGULAR_CONDITION:
            raise SingularPrintedModel(f"the printed model is singular at t = {tt:.4g} s "
                                       f"(condition {cond:.1e} of [A; Phi_q 0])")
        b = np.concatenate([-np.array(b_fn(*qq, *vv, tt), dtype=float).reshape(-1),
                            np.array(model._gamma(*qq, *vv), dtype=float).reshape(-1)])
        return np.concatenate([vv, np.linalg.solve(aug, b)[:n]])

    res = solve_ivp(rhs, (t[0], t[-1]), np.concatenate([q0, qd0]), method="DOP853",
                    rtol=1e-12, atol=1e-12, t_eval=t)
    if not res.success or res.y.shape[1] != len(t):
        raise SingularPrintedModel(f"the printed model is not integrable: {res.message}")
    q_t = res.y[:n].T
    drift = max(float(np.max(np.abs(model.constraint_values(x)))) for x in q_t)
    return q_t, drift


def _printed_multiplier_linearization(system: System, pf: PrintedFormula,
                                      values: Mapping[str, float], q_eq: np.ndarray):
    """(M, C, K) of the printed equations with multipliers at q_eq, on the derived
    manifold (module docstring), or None when q_eq is no equilibrium of the printed
    model or the printed rows carry time loads."""
    from scipy.linalg import null_space

    model = numeric_model(system.id, values)
    rows = sp.Matrix([sp.sympify(r).xreplace(system.subs(values)) for r in pf.expr])
    if TIME in rows.free_symbols:
        return None
    _, _, (q, qd, qdd, lams) = _printed_linear_in_unknowns(system, pf, values)
    at_rest = {**dict(zip(q, q_eq)), **{x: 0 for x in qd + qdd}}
    A_lam = np.array(rows.jacobian(lams).xreplace(at_rest), dtype=float)
    g = np.array(rows.xreplace({**at_rest, **{L: 0 for L in lams}}), dtype=float).reshape(-1)
    lam_p, *_ = np.linalg.lstsq(A_lam, -g, rcond=None)
    scale = max(float(np.max(np.abs(g))), float(np.max(np.abs(A_lam * lam_p))), 1e-300)
    if np.max(np.abs(g + A_lam @ lam_p)) > 1e-8 * scale:
        return None  # the printed statics do not balance here
    point = {**at_rest, **dict(zip(lams, lam_p))}
    M, C, K = (np.array(rows.jacobian(x).xreplace(point), dtype=float) for x in (qdd, qd, q))
    N = null_space(A_lam.T)  # N^T A_lam = 0: the printed multipliers eliminated
    S = model.tangent_basis(q_eq)
    if N.shape[1] != S.shape[1]:
        return None
    return N.T @ M @ S, N.T @ C @ S, N.T @ K @ S


def printed_model_frequencies(system: System, pf: PrintedFormula,
                              values: Mapping[str, float]) -> np.ndarray | None:
    """|s| of the modes (rad/s) when the printed M, K, C, kinetic or potential energy or
    frequency replaces the derived one at the equilibrium it refers to."""
    from .modes import quadratic_eigenvalues

    values = _with_relations(system, dict(values), pf)
    model = numeric_model(system.id, values)
    eq = _equilibrium_at(system, values, pf)
    M, C, K = eq.M.copy(), eq.C.copy(), eq.K.copy()
    subs = system.subs(values)
    if pf.kind in ("M", "K", "C"):
        printed = np.array(pf.expr.xreplace(subs), dtype=float)
        {"M": M, "K": K, "C": C}[pf.kind][...] = printed
    elif pf.kind in ("kinetic_energy", "potential_energy"):
        env = dict(subs)
        env.update({coordinate_symbols(c)[0]: v for c, v in zip(system.coordinates, eq.q)})
        S = model.velocity_basis(eq.q)
        if pf.kind == "kinetic_energy":
            vel = [coordinate_symbols(c)[1] for c in system.coordinates]
            H = sp.hessian(pf.expr, vel).xreplace({**env, **{v: 0 for v in vel}})
            M = S.T @ np.array(H, dtype=float) @ S
        else:
            if model.constrained:
                return None  # a printed potential on a loop needs its own constraint terms
            pos = [coordinate_symbols(c)[0] for c in system.coordinates]
            K = np.array(sp.hessian(pf.expr, pos).xreplace(env), dtype=float)
    elif pf.kind == "frequency":
        return np.array([float(pf.expr.xreplace(subs))])
    elif pf.kind == "eom" and pf.multipliers and model.constrained:
        try:
            printed = _printed_multiplier_linearization(system, pf, values, eq.q)
        except (ValueError, TypeError, np.linalg.LinAlgError):
            return None
        if printed is None:
            return None
        M, C, K = printed
    else:
        return None
    return np.sort(np.abs([s for s in quadratic_eigenvalues(M, C, K) if s.imag >= 0]))
