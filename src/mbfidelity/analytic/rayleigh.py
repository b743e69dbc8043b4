"""The printed formulas of §6 (Rayleigh's method, eq. 62-70) against their derivation.

§6.1 (Fig. 17) reduces the simply supported beam of length l, stiffness EI and mass rho
per length, with a block m at a = c l, to one degree of freedom at the block: with the
static deflection under a load at a as the assumed shape (eq. 63-66), the reduced
stiffness (eq. 65, 68) and the beam's reduced mass (eq. 67); and the same with the
deflection under the beam's own weight. §6.2 (Fig. 18) reduces the spring of mass rho l
with the linear shape of a static end load (eq. 69) to a third of its mass (eq. 70).

Derived here, identically in c, without the printed forms: each static shape solved from
the beam's equation (EI y'''' = load, pinned ends: y = y'' = 0; at the load's point y, y',
y'' continuous and EI y''' jumping by the load), referred to the block's point; the
reduced mass the integral of rho y^2, the reduced stiffness the integral of EI y''^2 (the
strain energy of the shape). A printed formula agrees when printed - derived simplifies to
zero. Rayleigh's estimates themselves are set against the exact continuum's first
frequency (`continuum.continuum_summary`): a quotient of an admissible shape is an upper
bound, so an estimate below the exact frequency would be an error.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

x, l, a, c, EI, F, q, rho = sp.symbols("x l a c EI F q rho", positive=True)


@dataclass(frozen=True)
class Section6Formula:
    """A printed formula of §6 and its derivation (SymPy expressions), for the continuum
    model it reduces (`continuum.CONTINUA`; a system names its model, `System.continuum`)."""

    continuum: str
    label: str
    printed: sp.Expr
    derived: sp.Expr
    note: str = ""

    def difference(self) -> sp.Expr:
        return sp.simplify(self.printed - self.derived)


def _pinned_static(load_at: sp.Expr | None) -> tuple[sp.Expr, sp.Expr]:
    """(left, right) static deflections of the pinned beam: under a point load F at
    `load_at` (left of it, right of it), or under a uniform load q (both the same) when
    `load_at` is None; solved from the general cubics (quartic under q)."""
    k = sp.symbols("k0:8")
    if load_at is None:
        y = q * x**4 / (24 * EI) + k[0] + k[1] * x + k[2] * x**2 + k[3] * x**3
        conditions = [y.subs(x, 0), sp.diff(y, x, 2).subs(x, 0), y.subs(x, l),
                      sp.diff(y, x, 2).subs(x, l)]
        solved = sp.solve(conditions, k[:4], dict=True)[0]
        y = sp.factor(y.subs(solved))
        return y, y
    left = k[0] + k[1] * x + k[2] * x**2 + k[3] * x**3
    right = k[4] + k[5] * x + k[6] * x**2 + k[7] * x**3
    jump = [sp.diff(right - left, x, n).subs(x, load_at) for n in range(3)]
    # EI y'''' = load per length (along +y): across the point load EI y''' jumps by F
    shear = EI * sp.diff(right - left, x, 3).subs(x, load_at) - F
    conditions = [left.subs(x, 0), sp.diff(left, x, 2).subs(x, 0), right.subs(x, l),
                  sp.diff(right, x, 2).subs(x, l), *jump, shear]
    solved = sp.solve(conditions, k, dict=True)[0]
    return sp.factor(left.subs(solved)), sp.factor(right.subs(solved))


def _reduced(left: sp.Expr, right: sp.Expr, at: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(mass coefficient, stiffness per EI) of a shape referred to its value at `at`:
    (1/l) integral of w^2 and integral of w''^2, w = y / y(at)."""
    y_at = left.subs(x, at)
    w_left, w_right = sp.simplify(left / y_at), sp.simplify(right / y_at)
    mass = (sp.integrate(w_left**2, (x, 0, at)) + sp.integrate(w_right**2, (x, at, l))) / l
    stiffness = (sp.integrate(sp.diff(w_left, x, 2) ** 2, (x, 0, at))
                 + sp.integrate(sp.diff(w_right, x, 2) ** 2, (x, at, l)))
    return sp.factor(sp.simplify(mass.subs(a, c * l))), sp.factor(
        sp.simplify(stiffness.subs(a, c * l)))


@lru_cache(maxsize=None)
def section6_formulas() -> tuple[Section6Formula, ...]:
    """Every printed formula of §6 the project codes (as printed, in the block's position
    c = a / l), each with its derivation."""
    b = l - a
    left, right = _pinned_static(a)
    z_a = sp.factor(left.subs(x, a))
    mass, stiffness = _reduced(left, right, a)
    s = c - 2 * c**3 + c**4
    uniform, _ = _pinned_static(None)
    # the uniform-load shape referred to the block at c l
    u_mass, u_stiffness = _reduced(uniform, uniform, a)
    spring_mass = sp.integrate(rho * (x / l) ** 2, (x, 0, l))
    beam = "beam_with_point_mass"
    return (
        Section6Formula(beam, "§6.1, eq. 64 (deflection z_a under F at a)",
                        F * a**2 * b**2 / (3 * EI * l), z_a),
        Section6Formula(beam, "§6.1, eq. 66 (the shape left of the load, z/z_a)",
                        x * (2 * l * a - a**2 - x**2) / (2 * (l - a) * a**2),
                        sp.factor(left / z_a)),
        Section6Formula(beam, "§6.1, eq. 66 (the shape right of the load, z/z_a)",
                        (l - x) * (2 * l * x - a**2 - x**2) / (2 * (l - a) ** 2 * a),
                        sp.factor(right / z_a)),
        Section6Formula(beam, "§6.1, eq. 67 (the beam's reduced mass, per rho l)",
                        (2 + 4 * c - c**2 - 6 * c**3 + 3 * c**4)
                        / (105 * (1 - c) ** 2 * c**2), mass,
                        note="17/35 at mid-span"),
        Section6Formula(beam, "§6.1, eq. 65 and 68 (the reduced stiffness, per EI)",
                        3 / ((1 - c) ** 2 * c**2 * l**3), stiffness),
        Section6Formula(beam, "§6.1, own-weight shape (the beam's reduced mass, per rho l)",
                        sp.Rational(31, 630) / s**2, u_mass,
                        note="the static deflection under the beam's own weight"),
        Section6Formula(beam, "§6.1, own-weight shape (the reduced stiffness, per EI)",
                        sp.Rational(24, 5) / (s**2 * l**3), u_stiffness,
                        note="the static deflection under the beam's own weight"),
        Section6Formula("spring_with_end_mass", "§6.2, eq. 69-70 (the spring's reduced mass)",
                        rho * l / 3, spring_mass, note="with the shape z = (x/l) z_a"),
    )
