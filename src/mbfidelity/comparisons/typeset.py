"""The derived model and the printed formulas typeset as presentation MathML, for the
results folder (`results_folder.save_system`, `results_folder.save_errata`): the pages
show these strings as they are, and browsers lay MathML out natively.

A coordinate's rates (`phi_dot`, `phi_ddot`) are printed with Newton's dots over the
coordinate. A printed formula is set beside the derived one with the terms that differ
marked (class "differs"): both sides expanded into terms, a printed equation of motion
first scaled to the derived row's normalisation (the ratio of their coefficients of the
row's acceleration), and the difference printed - derived set below them.
"""
from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path
from typing import Callable

import numpy as np
import sympy as sp
from sympy.printing.mathml import MathMLPresentationPrinter

from ..analytic import cache
from ..analytic.derivation import cache_key, derivation_of
from ..analytic.errata import (_equilibrium_at, _one_equation_each, _reduced_cached,
                               _with_relations, nonconservative_power)
from ..analytic.continuum import continuum_summary
from ..analytic.linear import find_equilibria, operating_equilibrium
from ..analytic.rayleigh import section6_formulas
from ..systems import PrintedFormula, System, all_systems, coordinate_symbols, get_system
from ..systems.model import TIME

#: beyond this many operations an expression is summarised instead of typeset (a long
#: chain's equations fill pages and say nothing a student reads)
MAX_OPERATIONS = 600
#: significant digits of the numbers in a typeset matrix
DIGITS = 6
_RATE = re.compile(r"^(.*)_(ddot|dot)$")
_ACCENT = {"dot": "\u02d9", "ddot": "\u00a8"}


class _Printer(MathMLPresentationPrinter):
    """SymPy's presentation printer, with a coordinate's rates as accents."""

    def _print_Symbol(self, sym, style="plain"):
        match = _RATE.match(sym.name)
        if not match:
            return super()._print_Symbol(sym, style)
        base = super()._print_Symbol(sp.Symbol(match.group(1)), style)
        # the dots over the letter, under its subscript; no accent="true": Chromium then
        # places the dot by the font's accent attachment, which hides it over Greek letters
        letter = base.childNodes[0] if base.nodeName in ("msub", "msubsup") else base
        over = self.dom.createElement("mover")
        dots = self.dom.createElement("mo")
        dots.appendChild(self.dom.createTextNode(_ACCENT[match.group(2)]))
        if letter is base:
            over.appendChild(base)
            over.appendChild(dots)
            return over
        base.replaceChild(over, letter)
        over.appendChild(letter)
        over.appendChild(dots)
        return base


def inner(expr) -> str:
    """The MathML of an expression, without the <math> element."""
    return _Printer({"order": "none"}).doprint(sp.sympify(expr))


def block(content: str) -> str:
    """A displayed formula from MathML content."""
    return f'<math display="block">{content}</math>'


def inline(content: str) -> str:
    """A formula in the text's line from MathML content."""
    return f"<math>{content}</math>"


def mathml(expr) -> str:
    return block(inner(expr))


def equation(lhs, rhs=0) -> str:
    return block(f"<mrow>{inner(lhs)}<mo>=</mo>{inner(rhs)}</mrow>")


def number(x: float) -> str:
    """A number with DIGITS significant digits, an exponent as a power of ten."""
    text = f"{x:.{DIGITS}g}"
    if "e" not in text:
        return f"<mn>{text}</mn>"
    mantissa, exponent = text.split("e")
    return (f"<mrow><mn>{mantissa}</mn><mo>&#xB7;</mo><msup><mn>10</mn>"
            f"<mn>{int(exponent)}</mn></msup></mrow>")


def matrix(a: np.ndarray, marked: np.ndarray | None = None) -> str:
    """A numeric matrix; the entries where `marked` is True carry the class "differs"."""
    a = np.atleast_2d(np.asarray(a, dtype=float))
    rows = []
    for i, row in enumerate(a):
        cells = []
        for j, x in enumerate(row):
            cls = ' class="differs"' if marked is not None and marked[i, j] else ""
            cells.append(f"<mtd{cls}>{number(x)}</mtd>")
        rows.append(f"<mtr>{''.join(cells)}</mtr>")
    return f"<mrow><mo>[</mo><mtable>{''.join(rows)}</mtable><mo>]</mo></mrow>"


def _too_long(expr) -> bool:
    return sp.count_ops(expr) > MAX_OPERATIONS


def _summary(expr) -> str:
    return f"(not typeset: {sp.count_ops(expr)} operations)"


def terms(expr, marked: set | None = None) -> str:
    """The expanded expression term by term; the terms in `marked` carry the class
    "differs"."""
    parts = sp.Add.make_args(expr)
    out = []
    for k, t in enumerate(parts):
        negative = t.could_extract_minus_sign()
        body = inner(-t if negative else t)
        if marked is not None and t in marked:
            body = f'<mrow class="differs">{body}</mrow>'
        if negative:
            out.append(f"<mo>&#x2212;</mo>{body}")
        else:
            out.append(("<mo>+</mo>" if k else "") + body)
    return f"<mrow>{''.join(out)}</mrow>"


def compared(printed, derived, rhs: str = "", constant: tuple = (), mark: bool = True,
             points: tuple = ()) -> dict:
    """Printed and derived expressions set term by term, the terms found on one side only
    marked (when `mark`: a misprint), and their difference (printed - derived): the
    unmatched printed terms less the unmatched derived ones. Two terms match when they are
    equal at each of `points` (mappings symbol -> value: identities such as cot(-x) =
    -cot(x) are then no difference), or identical without points. With `constant` (the
    state's symbols), a potential is compared up to a constant: the terms free of them are
    never marked nor kept in the difference. Without `mark` (the formula agrees where it
    is compared) a difference that does not vanish (it vanishes on the constraint
    manifold or with the printed relations) is not set."""
    printed, derived = _polynomial(printed), _polynomial(derived)
    if _too_long(printed) or _too_long(derived):
        def side(e) -> str:
            return block(f"<mtext>{_summary(e)}</mtext>" if _too_long(e) else
                         terms(e) + (f"<mo>=</mo>{rhs}" if rhs else ""))
        return {"printed": side(printed), "derived": side(derived), "difference": ""}
    state = set(constant)

    def compared_terms(e) -> list:
        return [t for t in sp.Add.make_args(e) if not constant or t.free_symbols & state]
    p_only, d_only = _unmatched(compared_terms(printed), compared_terms(derived), points)
    # term by term, as the formulas are set (a simplification would regroup them)
    difference = sp.Add(*p_only) - sp.Add(*d_only)
    shown = mark or difference == 0
    tail = f"<mo>=</mo>{rhs}" if rhs else ""
    return {"printed": block(terms(printed, set(p_only) if mark else set()) + tail),
            "derived": block(terms(derived, set(d_only) if mark else set()) + tail),
            "difference": block(terms(difference)) if shown else "",
            "difference_text": str(difference) if shown else "",
            "note": "" if shown else ("equal where compared: on the constraint manifold "
                                      "or with the printed relations")}


def _polynomial(expr):
    """Expanded into terms over no common denominator (a denominator that cancels, as in
    a simplified reduction, would otherwise split one term into several)."""
    expr = sp.expand(expr)
    if _too_long(expr):
        return expr
    return sp.expand(sp.cancel(expr))


#: two terms are the same when their values at every point agree to this (relative)
SAME_TERM = 1e-9


def _unmatched(printed: list, derived: list, points: tuple) -> tuple[list, list]:
    """The terms of each side that no term of the other matches (one to one)."""
    def values(t):
        out = []
        for env in points:
            try:
                out.append(complex(sp.sympify(t.xreplace(env)).evalf()))
            except (TypeError, ValueError, ZeroDivisionError):
                return None
        return np.array(out)

    left = list(derived)
    left_values = [values(t) for t in left]
    p_only = []
    for t in printed:
        v = values(t) if points else None
        for k, u in enumerate(left):
            same = (t == u) if v is None or left_values[k] is None else bool(
                np.all(np.abs(v - left_values[k]) <= SAME_TERM * np.maximum(np.abs(v), 1.0)))
            if same:
                del left[k], left_values[k]
                break
        else:
            p_only.append(t)
    return p_only, left


def sample_points(system: System, d, count: int = 2, seed: int = 20101) -> tuple:
    """Points near the operating point (parameters within 10 % of their defaults, the
    coordinates within 0.3 of it, rates in [-1, 1]) at which printed and derived terms are
    matched; deterministic."""
    rng = np.random.default_rng(seed)
    values = system.parameter_values()
    op = system.operating_values(values)
    out = []
    for _ in range(count):
        env = system.subs({k: v * rng.uniform(0.9, 1.1) for k, v in values.items()})
        env[TIME] = rng.uniform(0, 10)
        for s, v in zip(d.q, op):
            env[s] = v + rng.uniform(-0.3, 0.3)
        for s in list(d.qd) + list(d.qdd):
            env[s] = rng.uniform(-1, 1)
        out.append(env)
    return tuple(out)


# --- the derived model ------------------------------------------------------------------


def _cached(system: System | None, kind: str, compute: Callable[[], dict | list],
            *extra: str):
    """`compute()`, kept in the persistent cache (`analytic.cache`) under the system's
    content key, named by this module's and the analytic code's digests: typesetting
    simplifies and expands, seconds per mechanism."""
    h = hashlib.sha256(Path(__file__).read_bytes())
    h.update("|".join((cache.analytic_digest(), *extra)).encode())
    key = cache_key(system) if system is not None else kind
    name = f"{kind}-{h.hexdigest()[:16]}.json"
    blob = cache.load(key, name)
    if blob is not None:
        try:
            return json.loads(blob)
        except ValueError:  # an unreadable entry is recomputed, never trusted
            pass
    doc = compute()
    cache.store(key, name, json.dumps(doc).encode())
    return doc


def model_document(system_id: str) -> dict:
    """The derived model (kept in the persistent cache, `_cached`)."""
    return _cached(get_system(system_id), "model-mathml", lambda: _model_document(system_id))


def _model_document(system_id: str) -> dict:
    """The derived model of a system as MathML: parameters, coordinates, T, V, the
    dissipation function, constraints, equations of motion; M, C, K at the operating
    equilibrium; every equilibrium found and the operating one's modes."""
    system = get_system(system_id)
    d = derivation_of(system_id)
    values = system.parameter_values()
    doc: dict = {"parameters": [
        {"name": p.name, "symbol": inline(inner(sp.Symbol(p.name))), "value": values[p.name],
         "default": str(p.default), "unit": p.unit, "meaning": p.meaning, "source": p.source}
        for p in system.parameters if p.name in values]}
    doc["coordinates"] = [inline(inner(s)) for s in d.q]
    doc["kinetic_energy"] = _typeset_equation(sp.Symbol("T"), d.T)
    doc["potential_energy"] = _typeset_equation(sp.Symbol("V"), d.V)
    doc["dissipation"] = _typeset_equation(sp.Symbol("D"), d.D) if d.D != 0 else ""
    doc["constraints"] = [_typeset_equation(r, 0) for r in d.Phi]
    doc["equations_of_motion"], doc["equations_note"] = _equations(system, d)
    doc["operating_point"] = {}
    try:
        eq = operating_equilibrium(system, values)
    except (ValueError, RuntimeError, np.linalg.LinAlgError) as exc:
        doc["operating_point_note"] = f"no operating equilibrium: {exc}"
        return doc
    doc["operating_point"] = {
        "q": block(_column([f"<mrow>{inner(s)}<mo>=</mo>{number(v)}</mrow>"
                            for s, v in zip(d.q, eq.q)])),
        "M": block(f"<mrow><mi>M</mi><mo>=</mo>{matrix(eq.M)}</mrow>"),
        "C": block(f"<mrow><mi>C</mi><mo>=</mo>{matrix(eq.C)}</mrow>"),
        "K": block(f"<mrow><mi>K</mi><mo>=</mo>{matrix(eq.K)}</mrow>"),
        "stable": bool(eq.stable),
        "modes": [{"frequency_hz": m.frequency_hz, "damping_ratio": m.damping_ratio,
                   "damped_frequency_hz": m.damped_frequency_hz,
                   "eigenvalue": [float(np.real(m.eigenvalue)), float(np.imag(m.eigenvalue))]}
                  for m in eq.modes]}
    doc["equilibria"] = _equilibria(system, values, d)
    return doc


def _typeset_equation(lhs, rhs) -> str:
    if _too_long(rhs):
        return block(f"<mrow>{inner(lhs)}<mo>=</mo><mtext>{_summary(rhs)}</mtext></mrow>")
    return equation(lhs, rhs)


def _column(rows: list[str]) -> str:
    return "<mtable>" + "".join(f"<mtr><mtd>{r}</mtd></mtr>" for r in rows) + "</mtable>"


def _equations(system: System, d) -> tuple[list[str], str]:
    """Lagrange's equations: in the independent coordinates when the constraints solve in
    closed form, else with the multipliers lambda_i of the constraints (eq. 112)."""
    if not d.m:
        return [_typeset_equation(r, 0) for r in d.residual], (
            "Lagrange's equations, M(q) q'' + h(q, q') = Q.")
    lam = sp.symbols(f"lambda_1:{d.m + 1}")
    rows = d.residual + d.Phi_q.T * sp.Matrix(lam)
    return [_typeset_equation(r, 0) for r in rows], (
        "Lagrange's equations with the constraints' multipliers (lambda_i), "
        "M(q) q'' + h(q, q') - Q + Phi_q^T lambda = 0, with the constraints below.")


def _equilibria(system: System, values, d) -> list[dict]:
    try:
        found = find_equilibria(system, values)
    except (ValueError, RuntimeError, np.linalg.LinAlgError):
        return []
    return [{"q": block(_column([f"<mrow>{inner(s)}<mo>=</mo>{number(v)}</mrow>"
                                 for s, v in zip(d.q, e.q)])),
             "stable": bool(e.stable),
             "frequencies_hz": [m.frequency_hz for m in e.modes]} for e in found]


# --- the printed formulas beside the derived ones ----------------------------------------


def errata_typeset(system: System, misprints: frozenset = frozenset()) -> dict[str, dict]:
    """`_errata_typeset`, kept in the persistent cache (`_cached`)."""
    return _cached(system, "errata-mathml", lambda: _errata_typeset(system, misprints),
                   *sorted(misprints))


def _errata_typeset(system: System, misprints: frozenset) -> dict[str, dict]:
    """label -> {"printed", "derived", "difference"} (MathML) of each printed formula of
    the system that has a symbolic derived counterpart; the others are typeset printed
    only. The differing terms are marked on the formulas labelled in `misprints`."""
    d = derivation_of(system.id)
    values = system.parameter_values()
    out: dict[str, dict] = {}
    reduced: list = []
    points = sample_points(system, d)

    def reduced_rows() -> list:
        if not reduced:
            reduced.extend(_general(e) for e in (_reduced_cached(system.id) or []))
        return reduced
    for pf in _one_equation_each(system.printed(system.symbols)):
        if pf.kind == "eom" and pf.multipliers:
            out.update(_with_multipliers(system, d, pf))
            continue
        try:
            out[pf.label] = _typeset_formula(system, d, pf, values, reduced_rows,
                                             pf.label in misprints, points)
        except (ValueError, TypeError, RuntimeError, np.linalg.LinAlgError) as exc:
            out[pf.label] = {"printed": "", "derived": "", "difference": "",
                             "note": f"not typeset: {exc}"}
    return out


def _with_multipliers(system: System, d, pf: PrintedFormula) -> dict[str, dict]:
    """A printed system of equations with multipliers (labels as `analytic.errata` gives
    its verdicts): the printed rows beside the derived ones, M q'' + h - Q + Phi_q^T
    lambda (their multipliers are normalised differently: no term is compared)."""
    derived = list(d.residual + d.Phi_q.T * sp.Matrix(sp.symbols(f"lambda_1:{d.m + 1}"))
                   if d.m else d.residual)
    rows = [sp.sympify(r) for r in pf.expr]

    def zero(e) -> str:
        return (f"<mtext>{_summary(e)}</mtext>" if _too_long(e)
                else f"<mrow>{inner(e)}<mo>=</mo><mn>0</mn></mrow>")
    out = {f"{pf.label} (as a system, multipliers fitted)": {
        "printed": block(_column([zero(r) for r in rows])),
        "derived": block(_column([zero(r) for r in derived])), "difference": ""}}
    for i, r in enumerate(rows):
        out[f"{pf.label}, row {i + 1}"] = {
            "printed": block(zero(r)),
            "derived": block(zero(derived[i])) if len(rows) == len(derived) else "",
            "difference": ""}
    return out


def _typeset_formula(system: System, d, pf: PrintedFormula, values, reduced,
                     mark: bool, points: tuple = ()) -> dict:
    if pf.kind == "kinetic_energy":
        return compared(pf.expr, _general(_on_manifold(d, d.T)), mark=mark, points=points)
    if pf.kind == "potential_energy":
        # compared up to a constant: the constant terms of the difference are not marked
        return compared(pf.expr, _general(_on_manifold(d, d.V)), constant=tuple(d.q),
                        mark=mark, points=points)
    if pf.kind == "dissipation_power":
        return compared(pf.expr, nonconservative_power(system.id), mark=mark, points=points)
    if pf.kind == "eom" and not pf.multipliers:
        row = pf.expr[0]
        derived = _matching_row(row, reduced(), d)
        if derived is None:
            return {"printed": equation(row), "derived": "", "difference": ""}
        return compared(row, derived, "<mn>0</mn>", mark=mark, points=points)
    if pf.kind in ("M", "K", "C"):
        values = _with_relations(system, values, pf)
        printed = np.array(pf.expr.xreplace(system.subs(values)), dtype=float)
        eq = _equilibrium_at(system, values, pf)
        derived = {"M": eq.M, "K": eq.K, "C": eq.C}[pf.kind]
        scale = max(float(np.max(np.abs(derived))), 1e-300)
        marked = np.abs(printed - derived) > 1e-9 * scale
        head = f"<mi>{pf.kind}</mi><mo>=</mo>"
        return {"printed": block(f"<mrow>{head}{inner(pf.expr)}<mo>=</mo>"
                                 f"{matrix(printed, marked)}</mrow>"),
                "derived": block(f"<mrow>{head}{matrix(derived, marked)}</mrow>"),
                "difference": block(matrix(printed - derived, marked))}
    if pf.kind == "equilibrium":
        rows = [f"<mrow>{inner(coordinate_symbols(k)[0])}<mo>=</mo>{inner(v)}</mrow>"
                for k, v in pf.expr.items()]
        return {"printed": block(_column(rows)), "derived": "", "difference": ""}
    if pf.kind == "constraint":
        return {"printed": block(_column([f"<mrow>{inner(r)}<mo>=</mo><mn>0</mn></mrow>"
                                           for r in pf.expr])),
                "derived": block(_column([f"<mrow>{inner(r)}<mo>=</mo><mn>0</mn></mrow>"
                                          for r in d.Phi])), "difference": ""}
    if pf.kind == "constraint_force":
        name, expr = pf.expr
        exprs = list(expr) if isinstance(expr, (list, tuple, sp.MatrixBase)) else [expr]
        return {"printed": block(_column([inner(e) for e in exprs])), "derived": "",
                "difference": ""}
    if pf.kind in ("frequency", "damping_ratio"):
        value = float(pf.expr.xreplace(system.subs(_with_relations(system, values, pf))))
        return {"printed": block(f"<mrow>{inner(pf.expr)}<mo>=</mo>{number(value)}</mrow>"),
                "derived": "", "difference": ""}
    expr = pf.expr
    if isinstance(expr, (list, tuple)):
        return {"printed": block(_column([inner(e) for e in expr])), "derived": "",
                "difference": ""}
    return {"printed": mathml(expr), "derived": "", "difference": ""}


def _general(expr):
    """A Piecewise by its general branch (the others hold on a set of measure zero, e.g.
    a spring of zero length)."""
    return expr.replace(lambda e: isinstance(e, sp.Piecewise), lambda e: e.args[-1][0])


def _on_manifold(d, expr):
    """An expression of all the coordinates in the independent ones, when the constraints
    solve for the dependent ones in closed form (as the printed formulas are written);
    else as it is."""
    if not d.m or d.explicit_dependent is None:
        return expr
    q_of = d.explicit_dependent
    independent = [d.q[i] for i in d.independent]
    rates = {d.qd[i]: sum(sp.diff(q_of[d.q[i]], a) * d.qd[k] for a, k in
                          zip(independent, d.independent)) for i in d.dependent}
    return expr.xreplace(rates).xreplace(q_of)


def _matching_row(row, reduced: list, d):
    """The derived row that a printed equation of motion corresponds to, scaled to the
    printed normalisation: of the rows k * derived, with k the ratio of the printed and
    derived coefficients of an acceleration when k is free of the state, the one that
    leaves the fewest terms in printed - k * derived."""
    state = set(d.q) | set(d.qd) | set(d.qdd)
    row = sp.expand(row)
    best, fewest = None, None
    for r in reduced:
        r = sp.expand(r)
        if _too_long(r):
            continue
        for acc in d.qdd:
            cp, cd = row.coeff(acc), r.coeff(acc)
            if cp == 0 or cd == 0:
                continue
            k = sp.simplify(cp / cd)
            if k.free_symbols & state:
                continue
            scaled = sp.expand(k * r)
            left = len(sp.Add.make_args(sp.expand(row - scaled)))
            if fewest is None or left < fewest:
                best, fewest = scaled, left
    return best


# --- §6: Rayleigh's method --------------------------------------------------------------


def section6_entries(system_id: str | None = None) -> list[dict]:
    """The printed formulas of §6 (`analytic.rayleigh`) as errata entries, typeset, and
    each Rayleigh estimate of a catalog continuum against its exact first frequency (an
    estimate agrees when it is an upper bound, as a Rayleigh quotient must be); all of
    them, or those of one system. Kept in the persistent cache (`_cached`)."""
    entries = _cached(None, "section6-mathml", _section6_entries)
    return [e for e in entries if system_id in (None, e["system"])]


def _section6_entries() -> list[dict]:
    out = []
    continua = {s.id: s.continuum for s in all_systems().values() if s.continuum}
    for f in section6_formulas():
        difference = f.difference()
        out += [{"system": system_id, "label": f.label, "kind": "rayleigh",
                    "printed": str(f.printed), "derived": str(f.derived),
                    "verdict": "agrees" if difference == 0 else "misprint",
                    "max_relative_difference": None, "note": f.note, "witnesses": {},
                    "details": {},
                    "mathml": {"printed": mathml(f.printed), "derived": mathml(f.derived),
                               "difference": mathml(difference)}}
                for system_id, model in continua.items() if model == f.continuum]
    for system_id in continua:
        system = get_system(system_id)
        summary = continuum_summary(system.continuum, system.parameter_values())
        exact = summary.frequency_hz[0]
        for r in summary.rayleigh:
            bound = r.frequency_hz >= exact * (1 - 1e-12)
            out.append({
                "system": system_id, "label": f"{r.label}: Rayleigh's estimate ({r.shape})",
                "kind": "rayleigh_estimate", "printed": f"{r.frequency_hz:.9g} Hz",
                "derived": f"{exact:.9g} Hz (the exact continuum's first frequency)",
                "verdict": "agrees" if bound else "misprint",
                "max_relative_difference": r.relative_error,
                "note": (f"an upper bound, {r.relative_error:+.3%} of the exact frequency, at "
                         "the default parameters" if bound else
                         "below the exact frequency: not a Rayleigh quotient"),
                "witnesses": {}, "details": {},
                "mathml": {"printed": block(f"<mrow><mi>f</mi><mo>=</mo>{number(r.frequency_hz)}"
                                            "<mtext>&#xA0;Hz</mtext></mrow>"),
                           "derived": block(f"<mrow><msub><mi>f</mi><mn>1</mn></msub><mo>=</mo>"
                                            f"{number(exact)}<mtext>&#xA0;Hz</mtext></mrow>"),
                           "difference": ""}})
    return out
