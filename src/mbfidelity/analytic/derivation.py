"""Lagrange's equations derived symbolically from a mechanism description (monograph §9.1,
eq. 97).

Route 1 (used for motion): positions of every body from the joints, velocities by
Jacobians, T = sum(m v^2/2 + I w^2/2), generalized forces from gravity and from every
force element by virtual power (eq. 95):

    M(q) q'' + h(q, q') = Q(q, q', t),   h = d/dt(dT/dq') - dT/dq - M q''.

A spatial mechanism (model convention 10) takes the same route in three dimensions: each
body's rotation matrix R(q) is composed along the tree, its angular velocity (body axes) is
read from the skew matrix R^T R' (never assumed), and T = sum(m v.v/2 + w.I w/2) with the
full central tensor I; gravity acts along -up. Its loops close by `HingeClosure` rows:
the three components of the point's gap and the two of the axes' misalignment. Planar
mechanisms keep the planar computation unchanged.

Route 2 (energy functions, used to cross-check the linearization, monograph eq. 107-109
and Italian notes §5.3.3-5.3.4): T, V and Rayleigh's D, whose Hessians at an equilibrium
are M, K and C.
"""
from __future__ import annotations

import inspect
import pickle
import random
from dataclasses import dataclass
from functools import lru_cache

import sympy as sp
from sympy.simplify.fu import TR10i

from ..systems import System, coordinate_symbols, get_system
from . import cache
from ..systems.model import (
    COORD,
    COORD_RATE,
    LENGTH,
    LENGTH_RATE,
    TIME,
    WORLD,
    CoordinateForce,
    HingeClosure,
    LinearCoupling,
    Mechanism,
    PointOnLine,
    PointOnPoint,
    PointToPoint,
    Prismatic,
    Revolute,
    as_column,
    as_column3,
    inertia_matrix,
    perpendicular_pair,
    rotation,
    rotation3,
)


@dataclass
class Pose:
    position: sp.Matrix  # 2x1, centre of mass in world axes
    angle: sp.Expr


@dataclass
class SpatialPose:
    position: sp.Matrix  # 3x1, centre of mass in world axes
    rotation: sp.Matrix  # 3x3, body axes to world axes


class Derivation:
    """Symbolic model of a mechanism (parameters stay symbols)."""

    def __init__(self, mechanism: Mechanism):
        self.mechanism = mechanism
        names = mechanism.coordinates
        syms = [coordinate_symbols(n) for n in names]
        self.q = sp.Matrix([s[0] for s in syms])
        self.qd = sp.Matrix([s[1] for s in syms])
        self.qdd = sp.Matrix([s[2] for s in syms])
        self.n = len(names)
        self.spatial = mechanism.spatial
        if self.spatial:
            self.poses = self._spatial_poses()
            self.joint_values = self._spatial_joint_values()
            self._spatial_energies()
        else:
            self.poses = self._poses()
            self.joint_values = self._joint_values()
            self._energies()
        self._forces()
        self._constraints()
        residual = self.M * self.qdd + self.h - self.Q
        self.residual = residual.applyfunc(sp.expand) if mechanism.simplify else residual

    def _tidy(self, expr):
        """simplify, unless the mechanism opts out (`Mechanism.simplify`: long chains)."""
        return sp.simplify(expr) if self.mechanism.simplify else expr

    def _tidy_inertia(self, expr):
        """A mass-matrix entry: simplify, or for a long chain a cheap canonical form that
        keeps its derivatives small: expanded, sin(x)^2 -> 1 - cos(x)^2, and the pairs
        cos a cos b + sin a sin b (and the sine pairs) combined into cos(a - b), sin(a - b)
        (fu's TR10i). Each step is polynomial in the entry's length."""
        if self.mechanism.simplify:
            return sp.simplify(expr)
        squared_sine = sp.Wild("x")
        expr = sp.expand(sp.expand(expr).replace(sp.sin(squared_sine) ** 2,
                                                 1 - sp.cos(squared_sine) ** 2))
        return sp.factor_terms(TR10i(expr))

    # --- kinematics ----------------------------------------------------------------------
    def _poses(self) -> dict[str, Pose]:
        poses = {WORLD: Pose(sp.zeros(2, 1), sp.Integer(0))}
        mech = self.mechanism
        for j, qj in zip(mech.joints, self.q):
            parent = poses[j.parent]
            Rp = rotation(parent.angle)
            if isinstance(j, Revolute):
                base = 0 if j.absolute else parent.angle
                angle = base + (-qj if j.clockwise else qj) + j.angle_offset
                anchor = parent.position + Rp * as_column(j.parent_anchor)
            elif isinstance(j, Prismatic):
                angle = parent.angle + j.angle_offset
                anchor = parent.position + Rp * (as_column(j.parent_anchor) + qj * as_column(j.axis))
            else:  # pragma: no cover - the Joint union is closed
                raise TypeError(j)
            position = anchor - rotation(angle) * as_column(j.child_anchor)
            poses[j.child] = Pose(position.applyfunc(self._tidy), self._tidy(angle))
        return poses

    def _joint_values(self) -> sp.Matrix:
        """The engines' relative joint values as (linear) functions of the coordinates."""
        vals = []
        for j, qj in zip(self.mechanism.joints, self.q):
            if isinstance(j, Revolute):
                vals.append(self._tidy(self.poses[j.child].angle - self.poses[j.parent].angle
                                        - j.angle_offset))
            else:
                vals.append(qj)
        return sp.Matrix(vals)

    def _spatial_poses(self) -> dict[str, SpatialPose]:
        """Positions and rotation matrices composed along the tree (convention 10)."""
        poses = {WORLD: SpatialPose(sp.zeros(3, 1), sp.eye(3))}
        for j, qj in zip(self.mechanism.joints, self.q):
            parent = poses[j.parent]
            if isinstance(j, Revolute):
                turn = rotation3(j.axis if j.axis is not None else (0, 0, 1),
                                 (-qj if j.clockwise else qj) + j.angle_offset)
                R = turn if j.absolute else parent.rotation * turn
                anchor = parent.position + parent.rotation * as_column3(j.parent_anchor)
            elif isinstance(j, Prismatic):
                R = parent.rotation * rotation3((0, 0, 1), j.angle_offset)
                anchor = parent.position + parent.rotation * (
                    as_column3(j.parent_anchor) + qj * as_column3(j.axis))
            else:  # pragma: no cover - the Joint union is closed
                raise TypeError(j)
            R = R.applyfunc(self._tidy)
            position = anchor - R * as_column3(j.child_anchor)
            poses[j.child] = SpatialPose(position.applyfunc(self._tidy), R)
        return poses

    def _spatial_joint_values(self) -> sp.Matrix:
        """The engines' joint values: the hinge angle about its axis (q, or -q when
        clockwise), the slide's coordinate."""
        return sp.Matrix([-qj if isinstance(j, Revolute) and j.clockwise else qj
                          for j, qj in zip(self.mechanism.joints, self.q)])

    def angular_velocity(self, body: str) -> sp.Matrix:
        """Angular velocity in the body's axes, from the skew matrix R^T R'; for a long
        chain (`Mechanism.simplify` false, where simplifying R^T R' grows exponentially
        with the depth) composed along the tree instead (`_composed_angular_velocity`)."""
        if not self.mechanism.simplify:
            return self._composed_angular_velocity(body)
        R = self.poses[body].rotation
        Rdot = sp.zeros(3, 3)
        for qi, vi in zip(self.q, self.qd):
            Rdot += R.diff(qi) * vi
        W = (R.T * Rdot).applyfunc(sp.simplify)
        skew = (W + W.T).applyfunc(sp.simplify)
        if any(e != 0 for e in skew):
            raise ValueError(f"R^T R' of {body} is not skew-symmetric: {skew}")
        return sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])

    def _composed_angular_velocity(self, body: str) -> sp.Matrix:
        """w_child = Rot^T w_parent + u q' (body axes; u the unit hinge axis, q' signed as
        the hinge turns; an absolute hinge: u q' alone; a slide: the parent's, turned by
        its fixed offset). Checked against R^T R' at one sample of the coordinates and
        rates, where its skew matrix must equal R^T R' to round-off."""
        mech = self.mechanism
        if body == WORLD:
            return sp.zeros(3, 1)
        composed = self.__dict__.setdefault("_composed_omega", {})
        if body in composed:
            return composed[body]
        j = mech.joint_of_child(body)
        i = mech.coordinates.index(j.coordinate)
        parent = self._composed_angular_velocity(j.parent)
        if isinstance(j, Revolute):
            u = as_column3(j.axis if j.axis is not None else (0, 0, 1))
            u = u / sp.sqrt(sum(c**2 for c in u))
            rate = -self.qd[i] if j.clockwise else self.qd[i]
            turn = rotation3(u, (-self.q[i] if j.clockwise else self.q[i]) + j.angle_offset)
            w = u * rate if j.absolute else turn.T * parent + u * rate
        else:
            w = rotation3((0, 0, 1), j.angle_offset).T * parent
        self._check_angular_velocity(body, w)
        composed[body] = w
        return w

    def _check_angular_velocity(self, body: str, w: sp.Matrix) -> None:
        rng = random.Random(body)
        sample = {x: rng.uniform(-2, 2) for x in (*self.q, *self.qd)}
        sample.update({s: rng.uniform(0.5, 2) for s in
                       (self.poses[body].rotation.free_symbols | w.free_symbols)
                       - set(sample)})
        R = self.poses[body].rotation
        Rdot = sum((R.diff(qi) * vi for qi, vi in zip(self.q, self.qd)), sp.zeros(3, 3))
        W = (R.T * Rdot).xreplace(sample).evalf()
        w_num = w.xreplace(sample).evalf()
        skew = sp.Matrix([[0, -w_num[2], w_num[1]], [w_num[2], 0, -w_num[0]],
                          [-w_num[1], w_num[0], 0]])
        if max(abs(e) for e in (W - skew)) > 1e-9:
            raise ValueError(f"the composed angular velocity of {body} is not R^T R'")

    def point(self, body: str, local) -> sp.Matrix:
        pose = self.poses[body]
        if self.spatial:
            return pose.position + pose.rotation * as_column3(local)
        return pose.position + rotation(pose.angle) * as_column(local)

    def up(self) -> sp.Matrix:
        """The unit up direction of a spatial mechanism."""
        u = as_column3(self.mechanism.up)
        return u / sp.sqrt(sum(c**2 for c in u))

    def velocity(self, expr: sp.Matrix) -> sp.Matrix:
        return expr.jacobian(self.q) * self.qd

    def acceleration(self, expr: sp.Matrix) -> sp.Matrix:
        v = self.velocity(expr)
        return expr.jacobian(self.q) * self.qdd + v.jacobian(self.q) * self.qd

    # --- energies ------------------------------------------------------------------------
    def _energies(self) -> None:
        mech = self.mechanism
        M = sp.zeros(self.n, self.n)
        V = sp.Integer(0)
        for b in mech.bodies:
            pose = self.poses[b.name]
            Jv = pose.position.jacobian(self.q)
            Jw = sp.Matrix([[sp.diff(pose.angle, qi) for qi in self.q]])
            M += b.mass * (Jv.T * Jv) + b.inertia * (Jw.T * Jw)
            V += b.mass * mech.gravity * pose.position[1]
        self.M = M.applyfunc(self._tidy_inertia)
        self._bias_forces()
        self.V_gravity = V

    def _spatial_energies(self) -> None:
        """M from T = sum(m v.v/2 + w.I w/2), w from R^T R' in body axes."""
        mech = self.mechanism
        M = sp.zeros(self.n, self.n)
        V = sp.Integer(0)
        up = self.up()
        for b in mech.bodies:
            pose = self.poses[b.name]
            Jv = pose.position.jacobian(self.q)
            Jw = self.angular_velocity(b.name).jacobian(self.qd)
            M += b.mass * (Jv.T * Jv) + Jw.T * inertia_matrix(b) * Jw
            V += b.mass * mech.gravity * (up.T * pose.position)[0]
        self.M = M.applyfunc(self._tidy)
        self._bias_forces()
        self.V_gravity = V

    def _bias_forces(self) -> None:
        """T = q'.M q'/2 and h = (dM/dt) q' - dT/dq."""
        T = (self.qd.T * self.M * self.qd)[0] / 2
        self.T = sp.expand(T) if self.mechanism.simplify else T
        # h = (dM/dt) q' - dT/dq
        Mdot = sp.zeros(self.n, self.n)
        for k in range(self.n):
            Mdot += self.M.diff(self.q[k]) * self.qd[k]
        dT_dq = sp.Matrix([sp.diff(self.T, qi) for qi in self.q])
        self.h = (Mdot * self.qd - dT_dq).applyfunc(self._tidy)

    # --- forces --------------------------------------------------------------------------
    def element_length(self, f: PointToPoint) -> tuple[sp.Expr, sp.Matrix]:
        d = self.point(f.body_b, f.point_b) - self.point(f.body_a, f.point_a)
        length = sp.sqrt(self._tidy((d.T * d)[0]))
        return length, d

    def gravity_vector(self) -> sp.Matrix:
        """Gravitational acceleration in world axes: (0, -g) planar, -g up spatial."""
        if self.spatial:
            return -self.mechanism.gravity * self.up()
        return sp.Matrix([0, -self.mechanism.gravity])

    def _forces(self) -> None:
        mech = self.mechanism
        g_vec = self.gravity_vector()
        Q = sp.zeros(self.n, 1)
        for b in mech.bodies:
            Jv = self.poses[b.name].position.jacobian(self.q)
            Q += Jv.T * (b.mass * g_vec)
        Q_autonomous = Q.copy()
        V = self.V_gravity
        D = sp.Integer(0)
        energy_route = True
        for f in mech.forces:
            Qf, Vf, Df = self.element_generalized_force(f)
            Q += Qf
            time_dependent = TIME in sp.sympify(Qf).free_symbols
            if not time_dependent:
                Q_autonomous += Qf
            if time_dependent:
                continue
            if Vf is None and Df is None:
                energy_route = False
                continue
            V += Vf if Vf is not None else 0
            D += Df if Df is not None else 0
        self.Q = Q.applyfunc(self._tidy)
        #: generalized forces without the explicitly time-dependent elements e(t) (the
        #: system whose equilibria are studied, monograph §8, eq. 78)
        self.Q_autonomous = Q_autonomous.applyfunc(self._tidy)
        self.V = self._tidy(V)
        self.D = self._tidy(D)
        self.energy_route = energy_route and self._energy_route_consistent()
        self.conservative = self.energy_route and self.D == 0 and not any(
            TIME in sp.sympify(e).free_symbols for e in self.Q)

    def element_generalized_force(self, f):
        """(Q contribution, potential or None, dissipation or None) of a force element."""
        if isinstance(f, PointToPoint):
            length, _ = self.element_length(f)
            rate = (sp.Matrix([length]).jacobian(self.q) * self.qd)[0]
            subs = {LENGTH: length, LENGTH_RATE: rate}
            tension = sp.sympify(f.tension).xreplace(subs)
            dl_dq = sp.Matrix([sp.diff(length, qi) for qi in self.q])
            Q = -tension * dl_dq
            V = sp.sympify(f.potential).xreplace(subs) if f.potential is not None else None
            D = sp.sympify(f.dissipation).xreplace(subs) if f.dissipation is not None else None
            return Q, V, D
        if isinstance(f, CoordinateForce):
            weights = f.weights(self.mechanism.coordinates)
            subs = {COORD: sum(s * self.q[i] for i, s in weights.items()),
                    COORD_RATE: sum(s * self.qd[i] for i, s in weights.items())}
            Q = sp.zeros(self.n, 1)
            force = sp.sympify(f.force).xreplace(subs)
            for i, s in weights.items():
                Q[i] = s * force
            V = sp.sympify(f.potential).xreplace(subs) if f.potential is not None else None
            D = sp.sympify(f.dissipation).xreplace(subs) if f.dissipation is not None else None
            return Q, V, D
        raise TypeError(f"unsupported force element {f!r}")

    def _energy_route_consistent(self) -> bool:
        """Q_autonomous must equal -dV/dq - dD/dq' for the energy route to apply."""
        grad = sp.Matrix([sp.diff(self.V, qi) for qi in self.q])
        dgrad = sp.Matrix([sp.diff(self.D, v) for v in self.qd])
        diff = (self.Q_autonomous + grad + dgrad).applyfunc(
            sp.simplify if self.mechanism.simplify else sp.expand)
        return all(e == 0 for e in diff)

    # --- constraints ---------------------------------------------------------------------
    def _constraints(self) -> None:
        """Phi(q) = 0, its Jacobian, gamma = -(Phi_q q')_q q' (so that Phi_q q'' = gamma)
        and the Hessian of each row (for the linearization on the constraint manifold)."""
        rows = []
        for c in self.mechanism.constraints:
            rows += list(self.constraint_rows(c))
        self.Phi = sp.Matrix(rows) if rows else sp.zeros(0, 1)
        self.m = len(rows)
        if self.m:
            self.Phi_q = self.Phi.jacobian(self.q)
            self.gamma = -(self.Phi_q * self.qd).jacobian(self.q) * self.qd
            self.Phi_hessians = [sp.hessian(r, self.q) for r in rows]
        else:
            self.Phi_q = sp.zeros(0, self.n)
            self.gamma = sp.zeros(0, 1)
            self.Phi_hessians = []
        names = self.mechanism.coordinates
        self.independent = [names.index(c) for c in self.mechanism.independent_coordinates]
        # prescribed coordinates are neither: given functions of time (numeric.py)
        driven = {names.index(c) for c in self.mechanism.driven_coordinates}
        self.dependent = [i for i in range(self.n)
                          if i not in self.independent and i not in driven]
        # an over-constrained loop: `redundant` rows follow from the others (model.py)
        independent_rows = self.m - self.mechanism.redundant
        if len(self.dependent) != independent_rows:
            raise ValueError(
                f"{independent_rows} independent constraint equations ({self.m} rows, "
                f"{self.mechanism.redundant} redundant) but {len(self.dependent)} dependent "
                "coordinates")

    @property
    def explicit_dependent(self) -> dict | None:
        """Dependent coordinates as closed-form functions of the independent ones, when
        sympy solves the constraints uniquely (None otherwise). Cached."""
        if not hasattr(self, "_explicit_dependent"):
            self._explicit_dependent = None
            if self.mechanism.branch:
                self._explicit_dependent = self._branch()
                return self._explicit_dependent
            # an unsimplified chain's loop is no case for sympy's solve (it does not return)
            if self.m and self.mechanism.simplify:
                dep = [self.q[i] for i in self.dependent]
                # sympy's solve does not return on trigonometric loops of several unknowns
                # (the five-bar loop): try it only when it is a single unknown or linear
                linear = all(sp.Poly(r, *dep).is_linear if r.is_polynomial(*dep) else False
                             for r in self.Phi)
                try:
                    sols = sp.solve(list(self.Phi), dep, dict=True) if (
                        len(dep) == 1 or linear) else []
                except NotImplementedError:
                    sols = []
                if len(sols) == 1 and set(sols[0]) == set(dep):
                    self._explicit_dependent = dict(sols[0])
        return self._explicit_dependent

    def _branch(self) -> dict:
        """The mechanism's assembly branch (`Mechanism.branch`) as dependent symbol ->
        expression of the independent ones, checked: every constraint row vanishes on it
        identically (ValueError otherwise)."""
        names = self.mechanism.coordinates
        independent = {self.q[i] for i in self.independent}
        out = {}
        for name, expr in self.mechanism.branch:
            expr = sp.sympify(expr).xreplace({coordinate_symbols(c)[0]: self.q[names.index(c)]
                                              for c in names})
            if not expr.free_symbols & set(self.q) <= independent:
                raise ValueError(f"branch of {name}: a function of the independent "
                                 f"coordinates only, not {expr}")
            out[self.q[names.index(name)]] = expr
        on_branch = self.Phi.xreplace(out)
        for k, row in enumerate(on_branch):
            if sp.simplify(sp.expand_trig(row)) != 0:
                raise ValueError(f"the branch does not close the mechanism: constraint row "
                                 f"{k} is {sp.simplify(row)} on it")
        return out

    @property
    def linear_statics(self) -> bool:
        """Whether the static problem is linear: the autonomous generalized forces at rest
        (q' = 0) and the constraint equations affine in q (their Jacobians free of q; an
        expression that is affine only after simplification counts as not). Its
        equilibria are then one affine set, a single point where the stiffness is
        regular, which Newton reaches from any start. Cached."""
        if not hasattr(self, "_linear_statics"):
            coordinates = set(self.q)
            rest = {v: 0 for v in self.qd}
            forces = self.Q_autonomous.xreplace(rest)
            rows = list(forces.jacobian(self.q)) + list(self.Phi_q)
            self._linear_statics = not any(sp.sympify(e).free_symbols & coordinates
                                           for e in rows)
        return self._linear_statics

    def reduced_dynamics(self):
        """(q(q_i), S, M_r, rhs_r) symbolically when `explicit_dependent` exists:
        q'' = S q_i'' + Sdot q_i', M_r q_i'' = rhs_r = S^T (Q - h - M Sdot q_i')."""
        if hasattr(self, "_reduced"):
            return self._reduced
        self._reduced = None
        q_of = self.explicit_dependent
        if q_of is None:
            return None
        qi = [self.q[i] for i in self.independent]
        qdi = [self.qd[i] for i in self.independent]
        q_full = sp.Matrix([q_of.get(x, x) for x in self.q])
        S = q_full.jacobian(qi)
        Sdot_qd = (S * sp.Matrix(qdi)).jacobian(qi) * sp.Matrix(qdi)
        sub = {x: v for x, v in zip(self.q, q_full)}
        sub.update({v: e for v, e in zip(self.qd, S * sp.Matrix(qdi))})
        M = self.M.xreplace(sub)
        rhs = (self.Q - self.h).xreplace(sub)
        # no simplify: lambdify's common-subexpression elimination does the useful part
        M_r = S.T * M * S
        rhs_r = S.T * (rhs - M * Sdot_qd)
        self._reduced = (q_full, S, M_r, rhs_r)
        return self._reduced

    def constraint_rows(self, c) -> list[sp.Expr]:
        if isinstance(c, HingeClosure):
            d = self.point(c.body_a, c.point_a) - self.point(c.body_b, c.point_b)
            n_a = self.poses[c.body_a].rotation * as_column3(c.axis_a)
            R_b = self.poses[c.body_b].rotation
            across = [(n_a.T * R_b * u)[0] for u in perpendicular_pair(c.axis_b)]
            return [self._tidy(e) for e in (*d, *across)]
        if isinstance(c, PointOnPoint):
            d = self.point(c.body_a, c.point_a) - self.point(c.body_b, c.point_b)
            return [d[0], d[1]]
        if isinstance(c, PointOnLine):
            u = rotation(self.poses[c.line_body].angle) * as_column(c.direction)
            normal = sp.Matrix([-u[1], u[0]]) / sp.sqrt(
                sp.sympify(c.direction[0]) ** 2 + sp.sympify(c.direction[1]) ** 2)
            d = self.point(c.body, c.point) - self.point(c.line_body, c.line_point)
            return [self._tidy((normal.T * d)[0])]
        if isinstance(c, LinearCoupling):
            names = self.mechanism.coordinates
            return [sum(coef * self.q[names.index(n)] for n, coef in c.coefficients) - c.constant]
        raise TypeError(f"unsupported constraint {c!r}")

    def constraint_force(self, c) -> sp.Matrix:
        """Physical force of a constraint per its multipliers LAMBDA_k (see base.py point 6):
        PointOnPoint: force on body_a; PointOnLine: slot force on the pin; LinearCoupling:
        its generalized force."""
        rows = self.constraint_row_slices()[c.name]
        lam = [sp.Symbol(f"_lambda{k}") for k in range(rows.start, rows.stop)]
        if isinstance(c, HingeClosure):
            return -sp.Matrix(lam[:3])
        if isinstance(c, PointOnPoint):
            return -sp.Matrix(lam)
        if isinstance(c, PointOnLine):
            u = rotation(self.poses[c.line_body].angle) * as_column(c.direction)
            normal = sp.Matrix([-u[1], u[0]]) / sp.sqrt(
                sp.sympify(c.direction[0]) ** 2 + sp.sympify(c.direction[1]) ** 2)
            return -lam[0] * normal
        return -sp.Matrix(lam)

    def constraint_row_slices(self) -> dict[str, slice]:
        out, k = {}, 0
        for c in self.mechanism.constraints:
            rows = (5 if isinstance(c, HingeClosure) else 2 if isinstance(c, PointOnPoint)
                    else 1)
            out[c.name] = slice(k, k + rows)
            k += rows
        return out

    # --- reactions -----------------------------------------------------------------------
    def reaction(self, joint_name: str) -> sp.Matrix:
        """Force (world x, y) that the parent exerts on the child through the joint, from
        Newton's law on the child's subtree: sum(m a) = R + gravity + element forces from
        outside the subtree. Expression of q, q', q'', t."""
        mech = self.mechanism
        joint = mech.joint(joint_name)
        subtree = set(mech.subtree(joint.child))
        g_vec = self.gravity_vector()
        total = sp.zeros(3 if self.spatial else 2, 1)
        for name in subtree:
            b = mech.body(name)
            if b.mass != 0:
                total += b.mass * (self.acceleration(self.poses[name].position) - g_vec)
        for f in mech.forces:
            total -= self._external_force_on(f, subtree, joint)
        for c in mech.constraints:
            total -= self._closure_force_on(c, subtree, joint)
        return total

    def _closure_force_on(self, c, subtree: set[str], joint) -> sp.Matrix:
        """Force of a closure constraint on the subtree (symbols _lambda_k): a loop or slot
        force where exactly one side is inside; a coupling's generalized force is a couple
        on revolute coordinates (no net force) and a force along a prismatic axis."""
        mech = self.mechanism
        if isinstance(c, (PointOnPoint, PointOnLine, HingeClosure)):
            first, second = c.bodies
            in_first, in_second = first in subtree, second in subtree
            if in_first == in_second:
                return sp.zeros(3 if self.spatial else 2, 1)
            force = self.constraint_force(c)  # on the first body
            return force if in_first else -force
        if isinstance(c, LinearCoupling):
            rows = self.constraint_row_slices()[c.name]
            lam = sp.Symbol(f"_lambda{rows.start}")
            total = sp.zeros(2, 1)
            for name, coef in c.coefficients:
                owner = mech.joints[mech.coordinates.index(name)]
                if owner is not joint or isinstance(owner, Revolute):
                    continue
                axis = as_column(owner.axis)
                axis_world = rotation(self.poses[owner.parent].angle) * axis
                total += -lam * sp.sympify(coef) * axis_world / (axis.T * axis)[0]
            return total
        raise TypeError(c)

    def _external_force_on(self, f, subtree: set[str], joint) -> sp.Matrix:
        if isinstance(f, PointToPoint):
            in_a, in_b = f.body_a in subtree, f.body_b in subtree
            if in_a == in_b:
                return sp.zeros(3 if self.spatial else 2, 1)
            length, d = self.element_length(f)
            rate = (sp.Matrix([length]).jacobian(self.q) * self.qd)[0]
            tension = sp.sympify(f.tension).xreplace({LENGTH: length, LENGTH_RATE: rate})
            unit = d / length  # from a to b
            return tension * unit if in_a else -tension * unit
        if isinstance(f, CoordinateForce):
            owner = self.mechanism.joints[self.mechanism.coordinates.index(f.coordinate)]
            if owner is not joint or isinstance(owner, Revolute) or f.relative_to:
                # internal to the subtree or a torque only
                return sp.zeros(3 if self.spatial else 2, 1)
            i = self.mechanism.coordinates.index(f.coordinate)
            force = sp.sympify(f.force).xreplace({COORD: self.q[i], COORD_RATE: self.qd[i]})
            if self.spatial:
                axis = as_column3(owner.axis)
                axis_world = self.poses[owner.parent].rotation * axis
            else:
                axis = as_column(owner.axis)
                axis_world = rotation(self.poses[owner.parent].angle) * axis
            # virtual power: F . (axis q') = Q q'  =>  F = Q axis / |axis|^2
            return force * axis_world / (axis.T * axis)[0]
        raise TypeError(f)


def cache_key(system: System) -> str:
    """Content key of the system's persistent cache entries (`analytic.cache`)."""
    return cache.system_key(inspect.getsourcefile(system.build), system.structure_tag)


@lru_cache(maxsize=None)
def derivation_of(system_id: str) -> Derivation:
    """The symbolic derivation of a catalog system: derived once per process, and kept in
    the persistent cache (with its closed-form reduction, also expensive) across
    processes."""
    system = get_system(system_id)
    key = cache_key(system)
    blob = cache.load(key, "derivation.pickle")
    if blob is not None:
        try:
            return pickle.loads(blob)
        except Exception:  # an unreadable entry is rebuilt, never trusted
            pass
    derivation = Derivation(system.mechanism)
    if derivation.m:
        derivation.reduced_dynamics()
    cache.store(key, "derivation.pickle", pickle.dumps(derivation, protocol=pickle.HIGHEST_PROTOCOL))
    return derivation


def derive(system: System) -> Derivation:
    return derivation_of(system.id)
