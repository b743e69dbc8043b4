"""Equilibria, their stability, the linearized M, C, K and the modes (docs/user-guide.md;
the modes from the eigenvalues of M s^2 + C s + K = 0 as analytic/modes.py defines them).

A floating system (no ground, `System.rigid_directions`) has no static equilibrium under
a load with a non-zero resultant: its equilibria are relative ones (Italian notes
§5.3.1), found and linearized in analytic/relative_equilibrium.py.

A driven system (prescribed coordinates, monograph §8, §9.6) is linearized in its free
coordinates about the motion of the unexcited system (`System.unexcited`: the excitation's
amplitudes set to zero; the weight, in a rotating frame where it is the excitation): the
free coordinates at rest there while the prescribed ones follow their motion. That rest
state and the free blocks of dR/dq'', dR/dq', dR/dq (R = M q'' + h - Q) must not depend
on time; where they do (periodic coefficients), there is no equilibrium to linearize
about and Floquet theory applies instead (refused here, with the reason).
"""
from __future__ import annotations

import itertools
import warnings

import numpy as np
import scipy.linalg
import scipy.optimize

from ..systems import System
from ..systems.model import CoordinateForce, PointOnLine, PointOnPoint, Prismatic
from . import memo
from .modes import Equilibrium, is_stable, modes_from_eigenvalues, quadratic_eigenvalues
from .numeric import NumericModel, numeric_model
from .relative_equilibrium import relative_equilibria

def linearize(model: NumericModel, q_eq: np.ndarray) -> Equilibrium:
    M, C, K = model.linearization(q_eq)
    s = quadratic_eigenvalues(M, C, K)
    return Equilibrium(np.asarray(q_eq, float), is_stable(s), M, C, K, s,
                       modes_from_eigenvalues(s))


#: most starting points of a product grid; beyond it (more than 4 angular or 5 linear
#: independent coordinates: a chain of N elements has 5^N) the starts vary one coordinate
#: at a time (`_search_grid`), a number linear in the coordinates
MAX_GRID_STARTS = 4096


def _search_grid(system: System, values, op: np.ndarray) -> list[np.ndarray]:
    """Starting points over the independent coordinates: 8 angles per period for angular
    ones; for linear ones the operating value and points around it inside the limits.
    Every combination when there are at most MAX_GRID_STARTS of them; otherwise each
    coordinate's points with the others at the operating point (every catalog mechanism
    but the discretized chains stays within the product grid)."""
    mech = system.mechanism
    independent = set(mech.independent_coordinates)
    axes = []
    for i, j in enumerate(mech.joints):
        if j.coordinate not in independent:
            axes.append([op[i]])
            continue
        if isinstance(j, Prismatic):
            scale = max(abs(op[i]), 0.1)
            pts = op[i] + scale * np.array([0.0, -0.5, 0.5, -0.9, 2.0])
            lo, hi = (system.evaluate(b, values) if b is not None else None for b in j.limits)
            pts = [p for p in pts if (lo is None or p > lo) and (hi is None or p < hi)]
            axes.append(pts or [op[i]])
        else:
            axes.append(op[i] + np.linspace(-np.pi, np.pi, 8, endpoint=False))
    return _product_or_axes(axes, op)


def _admissible(system: System, values, q: np.ndarray) -> bool:
    for i, j in enumerate(system.mechanism.joints):
        if isinstance(j, Prismatic):
            lo, hi = (system.evaluate(b, values) if b is not None else None for b in j.limits)
            # open interval with a margin: a coordinate singularity on the boundary (the
            # polar origin s = 0) is not an admissible configuration
            margin = 1e-9 * max(1.0, abs(q[i]))
            if (lo is not None and not q[i] > lo + margin) or (
                    hi is not None and not q[i] < hi - margin):
                return False
    # a couple's hinge (`CoordinateForce.relative_to`) within one period of its value,
    # like every other angle: a hinge wound past half a turn is another winding
    coords = system.mechanism.coordinates
    for f in system.mechanism.forces:
        if isinstance(f, CoordinateForce) and f.relative_to is not None:
            if abs(q[coords.index(f.coordinate)] - q[coords.index(f.relative_to)]) > np.pi:
                return False
    return True


def wrap_angles(system: System, q: np.ndarray, op: np.ndarray) -> np.ndarray:
    """Angular coordinates into (op - pi, op + pi]; angles joined by couples
    (`Mechanism.wrap_groups`) shift with the first of their group."""
    q = np.array(q, dtype=float)
    for group in system.mechanism.wrap_groups():
        i = group[0]
        wrapped = op[i] - ((op[i] - q[i] + np.pi) % (2 * np.pi) - np.pi)
        if abs(wrapped - op[i] + np.pi) < 1e-12:
            wrapped = op[i] + np.pi
        shift = wrapped - q[i]
        q[i] = wrapped
        for k in group[1:]:
            q[k] += shift
    return q


def _solve_static(model: NumericModel, start: np.ndarray) -> np.ndarray | None:
    """Newton-type search over the independent coordinates from a full start (the
    dependent coordinates follow the constraints, warm-started from the start)."""
    ind = model.independent
    try:
        base = model.complete(start)
    except (RuntimeError, np.linalg.LinAlgError):
        return None
    state = {"q": base}

    def full(qi):
        guess = state["q"].copy()
        guess[ind] = qi
        state["q"] = model.complete(guess)
        return state["q"]

    def f(qi):
        return model.static_residual(full(qi))

    def jac(qi):
        return model.linearization(full(qi), chart=True)[2]

    try:
        sol = scipy.optimize.root(f, base[ind], jac=jac, method="hybr", tol=1e-14)
        q = full(sol.x)
    except (RuntimeError, ValueError, np.linalg.LinAlgError):
        return None
    if not np.all(np.isfinite(q)) or not _regular(model, q, base):
        return None
    # residual judged on the scale of the stiffness where the search started: a
    # coordinate singularity (slot parallel to its guide) has a huge K of its own
    scale = max(1.0, float(np.max(np.abs(model.linearization(base, chart=True)[2]))))
    if np.max(np.abs(model.static_residual(q))) > 1e-9 * scale:
        return None
    return q


def _regular(model: NumericModel, q: np.ndarray, start: np.ndarray, chart: bool = True) -> bool:
    """Not a coordinate singularity: the dependent coordinates stay finite and (in the
    chart of the independent coordinates) the constraint Jacobian stays well
    conditioned."""
    if np.max(np.abs(q)) > 1e6 * max(1.0, float(np.max(np.abs(start)))):
        return False
    if model.constrained and chart:
        J = model.constraint_jacobian(q)[:, model.dependent]
        if np.linalg.cond(J) > 1e10:
            return False
    return True


def _full_search_starts(system: System, values, op: np.ndarray) -> list[np.ndarray]:
    """Starts over every angular coordinate (dependent ones included), 5 per period, for
    closed loops whose other assembly branches no chart of independent coordinates
    reaches. An odd count: an even one starts at op + pi, the mirror pose of a symmetric
    loop, where Newton's first steps are ill-conditioned and the basin a start falls into
    changed with the machine's floating point (the five-bar mobile's second minimum was
    missed from 4 per period on one machine, found on another)."""
    axes = []
    for i, j in enumerate(system.mechanism.joints):
        if isinstance(j, Prismatic):
            axes.append([op[i]])
        else:
            axes.append(op[i] + np.linspace(-np.pi, np.pi, 5, endpoint=False))
    return _product_or_axes(axes, op)


def _product_or_axes(axes: list, op: np.ndarray) -> list[np.ndarray]:
    """Every combination of the axes' points when there are at most MAX_GRID_STARTS of
    them; otherwise each axis's points with the other coordinates at the operating point
    (a number of starts linear in the coordinates)."""
    if int(np.prod([len(a) for a in axes], dtype=float)) <= MAX_GRID_STARTS:
        return [np.array(p) for p in itertools.product(*axes)]
    starts = []
    for i, points in enumerate(axes):
        for x in points:
            start = np.array(op, dtype=float)
            start[i] = x
            starts.append(start)
    return starts


def _solve_full(model: NumericModel, start: np.ndarray) -> np.ndarray | None:
    x0 = np.concatenate([start, np.zeros(model.m)])
    try:
        sol = scipy.optimize.root(model.static_equations, x0, jac=model.static_jacobian,
                                  method="hybr", tol=1e-14)
    except (np.linalg.LinAlgError, ValueError):
        return None
    q = sol.x[: model.n]
    if not sol.success or not np.all(np.isfinite(sol.x)):
        return None
    J = model.constraint_jacobian(q)
    if np.linalg.matrix_rank(J, tol=1e-8 * max(1.0, np.abs(J).max())) < model.m:
        return None  # a singular pose (e.g. two pins coinciding): not a regular equilibrium
    scale = max(1.0, float(np.max(np.abs(model.static_jacobian(sol.x)))))
    if np.max(np.abs(model.static_equations(sol.x))) > 1e-9 * scale:
        return None
    return q


#: times (s) at which a driven system's rest state and its linear coefficients are checked
#: to be constant: incommensurate with any round period
_PROBE_TIMES = (0.0, 0.1234, 0.789, 1.5557, 3.0301)
#: relative variation of the coefficients above which they count as time-dependent
TIME_INVARIANCE = 1e-9


def unexcited_values(system: System, values) -> dict[str, float]:
    """The parameter values with the excitation switched off (`System.unexcited`)."""
    return {**dict(values), **{k: float(v) for k, v in system.unexcited.items()}}


def _driven_blocks(model: NumericModel, q_free: np.ndarray, t: float):
    """(M, C, K) of the free coordinates at rest at q_free, prescribed motion at t, and the
    free rows of R there."""
    f = model.independent
    q, qd = model.driven_state(np.concatenate([q_free, np.zeros(len(f))]), np.array([t]))
    qdd = np.zeros(model.n)
    qdd[model.driven] = model.motion(float(t))[2]
    M, J_qd, J_q = model.residual_jacobians(q[0], qd[0], qdd, t)
    R = model.residual(q[0], qd[0], qdd, t)[f]
    return M[np.ix_(f, f)], J_qd[np.ix_(f, f)], J_q[np.ix_(f, f)], R


def _solve_driven(model: NumericModel, start: np.ndarray) -> np.ndarray | None:
    """Rest state of the free coordinates (R_f = 0 at t = 0) from a full start."""
    f = model.independent

    def residual(x):
        return _driven_blocks(model, x, 0.0)[3]

    def jacobian(x):
        return _driven_blocks(model, x, 0.0)[2]

    try:
        sol = scipy.optimize.root(residual, np.asarray(start, float)[f], jac=jacobian,
                                  method="hybr", tol=1e-14)
    except (ValueError, np.linalg.LinAlgError):
        return None
    K = jacobian(sol.x)
    scale = max(1.0, float(np.max(np.abs(K))) * max(1.0, float(np.max(np.abs(sol.x)))))
    if not np.all(np.isfinite(sol.x)) or np.max(np.abs(residual(sol.x))) > 1e-9 * scale:
        return None
    q = np.array(start, dtype=float)
    q[f] = sol.x
    q[model.driven] = model.motion(0.0)[0]
    return q


def _linearize_driven(system: System, model: NumericModel, q: np.ndarray) -> Equilibrium:
    f = model.independent
    blocks = [_driven_blocks(model, q[f], t) for t in _PROBE_TIMES]
    M, C, K, _ = blocks[0]
    scale = max(float(np.max(np.abs(np.concatenate([M, C, K], axis=None)))), 1e-300)
    for Mt, Ct, Kt, Rt in blocks[1:]:
        varying = max(float(np.max(np.abs(Mt - M))), float(np.max(np.abs(Ct - C))),
                      float(np.max(np.abs(Kt - K))))
        if varying > TIME_INVARIANCE * scale or np.max(np.abs(Rt)) > 1e-9 * scale * max(
                1.0, float(np.max(np.abs(q[f])))):
            raise ValueError(
                f"{system.id}: with the excitation off ({_unexcited_text(system)}) the free "
                f"coordinates have no rest state with constant coefficients (they vary with "
                f"the prescribed motion): a periodic-coefficient system, for Floquet "
                f"analysis, not an equilibrium")
    s = quadratic_eigenvalues(M, C, K)
    return Equilibrium(q, is_stable(s), M, C, K, s, modes_from_eigenvalues(s))


def _unexcited_text(system: System) -> str:
    return ", ".join(f"{k} = {v:g}" for k, v in system.unexcited.items()) or "nothing to switch off"


def driven_coefficients(model: NumericModel, q_free: np.ndarray, t: float):
    """(M, C, K) of the free coordinates at rest at q_free with the prescribed motion at
    time t: the coefficients of the variational equations there."""
    return _driven_blocks(model, q_free, t)[:3]


def driven_rest_states(system: System, values, only_operating: bool) -> list[np.ndarray]:
    """Rest states of the free coordinates with the excitation off (full q; the
    prescribed coordinates where their motion puts them at t = 0)."""
    model = numeric_model(system.id, unexcited_values(system, values))
    op = system.operating_values(values)
    starts = [op] if only_operating else [op] + _search_grid(system, values, op)
    found: list[np.ndarray] = []
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for start in starts:
            q = _solve_driven(model, start)
            if q is None or not _admissible(system, values, q):
                continue
            # free angles into one period about the operating point (the prescribed
            # coordinates stay where their motion puts them)
            wrapped = wrap_angles(system, q, op)
            wrapped[model.driven] = q[model.driven]
            q = wrapped
            if any(np.allclose(q, other, atol=1e-7) for other in found):
                continue
            found.append(q)
    return found


def _driven_equilibria(system: System, values, only_operating: bool) -> list[Equilibrium]:
    model = numeric_model(system.id, unexcited_values(system, values))
    return [_linearize_driven(system, model, q)
            for q in driven_rest_states(system, values, only_operating)]


def find_equilibria(system: System, values) -> list[Equilibrium]:
    """Every equilibrium within one period of each angular coordinate (centred on the
    operating point), each classified by its linearization. The operating point comes
    first when it is an equilibrium. Closed loops are also searched in all coordinates
    and multipliers, so that equilibria on other assembly branches are found. A driven
    system's are the rest states of its free coordinates with the excitation off. Kept
    in the persistent cache (analytic/memo.py) under the parameter values."""
    system = system.with_structure(values)  # the chain of the number of elements in values
    return memo.cached(system, "equilibria", (dict(values),),
                       lambda: _find_equilibria(system, values))


def _find_equilibria(system: System, values) -> list[Equilibrium]:
    if system.mechanism.prescribed:
        return _driven_equilibria(system, values, only_operating=False)
    if system.rigid_directions(system.symbols):
        op = system.operating_values(values)
        return relative_equilibria(system, values, [op] + _search_grid(system, values, op))
    model = numeric_model(system.id, values)
    op = system.operating_values(values)
    found: list[np.ndarray] = []
    # a linear static problem has one equilibrium (or one family, reported once): Newton
    # reaches it from the operating point, and a grid would only find it again
    starts = [op] if model.derivation.linear_statics else (
        [op] + _search_grid(system, values, op))
    # grid starts may sit on singular poses of the chart (Newton then fails there and
    # the start is dropped): numpy's warnings would only say so on stderr
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        candidates = [_solve_static(model, s) for s in starts]
        if model.constrained and any(isinstance(c, (PointOnPoint, PointOnLine))
                                     for c in system.mechanism.constraints):
            candidates += [_solve_full(model, s)
                           for s in _full_search_starts(system, values, op)]
    for q in candidates:
        if q is None or not _regular(model, q, op, chart=False):
            continue
        try:
            # dependent coordinates re-solved after wrapping: a 2 pi shift of one angle
            # is no symmetry of a linear coupling (belt, rolling)
            q = model.complete(wrap_angles(system, q, op))
        except (RuntimeError, np.linalg.LinAlgError):
            continue
        if not _admissible(system, values, q):
            continue
        if any(_same_family(model, q, f) for f in found):
            continue
        found.append(q)
    return [linearize(model, q) for q in found]


def _same_family(model: NumericModel, a: np.ndarray, b: np.ndarray) -> bool:
    """Same equilibrium, or two members of one neutral family: their difference lies in
    the null space of K, e.g. a free pulley angle (one zero frequency, Fig. 38). A family
    is reported once, by its first member."""
    if np.allclose(a, b, atol=1e-7):
        return True
    if model.constrained:
        # same assembly branch: b's configuration carried to a's independent coordinates
        # by Newton lands on a
        guess = b.copy()
        guess[model.independent] = a[model.independent]
        try:
            carried = model.complete(guess)
        except (RuntimeError, np.linalg.LinAlgError):
            return False
        if not np.allclose(carried, a, atol=1e-6):
            return False
    diff = (a - b)[model.independent]
    K = model.linearization(b)[2]
    u, sv, vt = np.linalg.svd(K)
    null = vt[sv <= 1e-9 * max(sv.max(), 1.0)]
    if len(null) == 0:
        return False
    residual = diff - null.T @ (null @ diff)
    return bool(np.allclose(residual, 0, atol=1e-7))


def operating_equilibrium(system: System, values) -> Equilibrium:
    """The equilibrium the monograph studies (the system's operating point, refined), with
    its linearization and modes. Kept in the persistent cache (analytic/memo.py) under
    the parameter values."""
    system = system.with_structure(values)  # the chain of the number of elements in values
    return memo.cached(system, "operating_equilibrium", (dict(values),),
                       lambda: solve_operating_equilibrium(system, values))


def solve_operating_equilibrium(system: System, values) -> Equilibrium:
    """`operating_equilibrium` computed, not looked up: for a scan over many parameter
    values whose single points are not worth an entry each (analytic/stability.py)."""
    system = system.with_structure(values)
    if system.mechanism.prescribed:
        found = _driven_equilibria(system, values, only_operating=True)
        if not found:
            raise ValueError(f"{system.id}: no rest state of the free coordinates near the "
                             f"operating point with the excitation off "
                             f"({_unexcited_text(system)})")
        return found[0]
    if system.rigid_directions(system.symbols):
        found = relative_equilibria(system, values)
        if not found:
            raise ValueError(f"{system.id}: no relative equilibrium near the operating point")
        return found[0]
    model = numeric_model(system.id, values)
    op = system.operating_values(values)
    q = _solve_static(model, op)
    if q is None:
        raise ValueError(f"{system.id}: no equilibrium near the operating point {op}")
    return linearize(model, q)
