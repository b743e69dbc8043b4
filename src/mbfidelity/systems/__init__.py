"""The mechanism catalog: one module per mechanism, discovered automatically.

Each module defines ``SYSTEM = System(...)``. Adding a mechanism means adding a module
here and nothing else (the pattern of dm_control's suite). The modules here are the
monograph's mechanisms; a subpackage ``systems/<group>/`` holds a group of its own
(``benchmarks``: the multibody community's benchmark problems), found the same way.

A user's own mechanisms, written the same way, join the catalog from outside the
package: module files named in the environment variable ``MBFIDELITY_SYSTEM_PATH``
(separated by the platform's path separator; the command line's ``--system-path FILE``
sets it, so worker processes see them too), and modules or systems registered under the
entry-point group ``mbfidelity.systems`` by an installed package. A module that cannot
be loaded, defines no ``SYSTEM``, or reuses an id is refused with one ValueError naming
the file and the problem.
"""
from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
import os
import pkgutil
import sys
from pathlib import Path
from dataclasses import dataclass, field, replace
from functools import cached_property
from types import SimpleNamespace
from typing import Callable, Mapping

import sympy as sp

from .model import (
    GRAVITY,
    STANDARD_GRAVITY,
    Expr,
    Mechanism,
    Parameter,
    Scenario,
)

#: the kinds of checks a scenario names
CHECK_KINDS = ("trajectory", "reaction", "frequency")

#: separates a catalog id from the structural parameters of one of its specialisations
#: (``massive spring with N = 16 elements`` is ``<id>@N=16``; `System.with_structure`)
STRUCTURE_MARK = "@"


def coordinate_symbols(name: str) -> tuple[sp.Symbol, sp.Symbol, sp.Symbol]:
    """(q, q_dot, q_ddot) symbols of a coordinate, as used in printed formulas."""
    return (
        sp.Symbol(name, real=True),
        sp.Symbol(f"{name}_dot", real=True),
        sp.Symbol(f"{name}_ddot", real=True),
    )


@dataclass(frozen=True)
class PrintedFormula:
    """A formula as the monograph prints it, coded as printed (with its equation number).

    kind:
      "eom"               residuals (one per printed equation) in q, q_dot, q_ddot
      "kinetic_energy"    expression in q, q_dot
      "potential_energy"  expression in q (compared up to a constant)
      "M", "K", "C"       matrix at the operating point (coordinates in system order)
      "equilibrium"       mapping coordinate -> printed equilibrium value
      "frequency"         natural angular frequency (rad/s) at the operating point
      "damping_ratio"     damping ratio at the operating point
      "constraint_force"  (constraint name, expression or list of expressions in q, q_dot,
                          q_ddot): its physical force (simulators/base.py point 6); the
                          name "actuator:<name>" compares a prescribed coordinate's
                          actuator force on that coordinate instead
      "constraint"        list of printed constraint equations Phi(q) = 0 (closure, slot,
                          rolling), each row an expression in q; its zero set must be the
                          mechanism's (rows in any order, sign or scale)
      "constraint_jacobian" matrix (rows x coordinates in system order) of the printed
                          kinematic constraint equations Phi_q q' = 0 (eq. 110, 114); its
                          row space must be the derived Phi_q's
      "potential_gradient" list, per independent coordinate, of dE_p/dq_i written in the
                          independent coordinates (compared along the constraint manifold)
      "potential_hessian" matrix d2E_p/dq_i dq_j in the independent coordinates
      "dissipation_power" printed P_nc(q, q_dot, t): power of the non-conservative forces
                          (dampers, friction, motors), compared with Q_nc . q_dot
    An "eom" may contain printed Lagrange multipliers (eq. 112): list their symbols in
    `multipliers`; the residuals must be linear in them, and any normalisation or sign of
    the printed multipliers is accepted (they are fitted, see analytic/errata.py). With one
    row per coordinate, in system order, each row also gets its own verdict.
    Matrices, frequencies and damping ratios refer to the equilibrium `at` (independent
    coordinate -> value) when given, otherwise to the operating point.
    """

    label: str
    kind: str
    expr: object
    note: str = ""
    at: Mapping[str, Expr] | None = None
    #: parameter relations under which the formula is printed (name -> expression of
    #: other parameters); imposed on every parameter set it is compared at
    relations: Mapping[str, Expr] | None = None
    #: symbols of the printed Lagrange multipliers in an "eom" (eq. 112), in printed order
    multipliers: tuple[sp.Symbol, ...] = ()
    #: where the printed multipliers are physical constraint forces: symbol -> (constraint
    #: name, component of its force in the contract's terms), or an actuator's force of a
    #: prescribed coordinate: ("actuator:<name>", 0); their values then come from the
    #: derivation, so that every row is tested (none can absorb a fitted value)
    multiplier_forces: Mapping[sp.Symbol, tuple[str, int]] | None = None


@dataclass(frozen=True)
class ContactOutput:
    """A physical contact force, compared and watched.

    Its value is the component along `direction` of a joint reaction (source
    "reaction:<joint>", the force on the child) or of a closure force (source
    "constraint:<name>": on the pin of a slot, on body_a of a loop closure; a coupling's
    scalar force when `direction` is None). `direction` is a unit vector written with the
    coordinate symbols and the parameters. `unilateral`: the real contact can only push
    (value >= 0); where the bilateral model pulls, a real mechanism would separate, and
    the comparison says when."""

    name: str
    source: str
    direction: tuple[Expr, Expr] | None = None
    unilateral: bool = True
    description: str = ""

    @property
    def kind(self) -> str:
        return self.source.split(":", 1)[0]

    @property
    def target(self) -> str:
        return self.source.split(":", 1)[1]


@dataclass(frozen=True)
class PointOutput:
    """A named point of a body, whose world position and velocity the reference reports
    and the comparisons judge like the coordinates (a benchmark publishes the trajectory
    of a point, not the joints' angles). `position` is in the body's frame (its centre
    of mass at the origin, model convention 2), written with the parameters."""

    name: str
    body: str
    position: tuple[Expr, ...]
    description: str = ""


@dataclass(frozen=True)
class Variant:
    """Another way some engines can build the mechanism (say rolling by friction contact
    instead of the coupling constraint), as description data: `constraints` (a function
    of the parameter symbols, like `System.build`) gives the elements that take the place
    of the description's constraints of the same name; the scenarios and references stay
    the description's. `settings`: the engines that build it, each with its own settings.
    The gates belong to the description; a variant's distance from them is the variant's
    own error, measured and reported (status "measured"), with `reason` saying why it
    differs."""

    name: str
    settings: Mapping[str, Mapping[str, object]]  # engine id -> settings
    description: str
    reason: str
    constraints: Callable[[SimpleNamespace], tuple] = lambda P: ()


@dataclass(frozen=True)
class Condition:
    """A condition on the parameters without which the geometry does not exist: a spring
    length that must stay positive over the motion, a pin that must stay in its slot, a
    loop that must be able to close. `relation` is a SymPy relation of parameter names
    (conditions over the motion are written at their worst case, e.g. the cot spring's
    length h - b - r sin(phi) over a turn: ``"h - b - r > 0"``); `meaning` says what it
    guarantees. Parameter sets that violate one are refused before any work."""

    relation: str
    meaning: str


PUBLISHED_KINDS = ("state", "period", "energy")


@dataclass(frozen=True)
class Published:
    """A value a source publishes for a scenario's motion (a benchmark's solution), which
    `analyze` compares with the reference (analytic/published.py).

    kind "state": `expression` (of the coordinate symbols, `coordinate_symbols`, and the
    parameters) at the instant `time` (s); kind "period": the period of `coordinate`
    (`time` None); kind "energy": the total mechanical energy T + V at the instant
    `time` (a conservative motion's closed form: its initial value). `value`: the published number, which holds at the parameters the
    source publishes it for (the defaults: under other values it is reported as not
    applicable), or a function of the parameter values (name -> value) for a closed form,
    which holds at any. `scenario`: the scenario it belongs to (None: the first)."""

    quantity: str
    time: float | None
    value: float | Callable[[Mapping[str, float]], float]
    source: str
    kind: str = "state"
    expression: Expr | None = None
    coordinate: str | None = None
    scenario: str | None = None
    #: how the source obtained the value (a closed form, a numerical solution and its
    #: tolerances): why it may differ from the reference beyond the reference's error
    note: str = ""

    def __post_init__(self) -> None:
        if self.kind not in PUBLISHED_KINDS:
            raise ValueError(f"published {self.quantity}: kind {self.kind!r} is not one of "
                             f"{', '.join(PUBLISHED_KINDS)}")
        if self.kind == "energy":
            if self.time is None or self.expression is not None:
                raise ValueError(f"published {self.quantity}: an energy value has a time "
                                 "and no expression")
        elif (self.kind == "state") != (self.expression is not None
                                        and self.time is not None):
            raise ValueError(f"published {self.quantity}: a state value has an expression "
                             "and a time, a period neither")
        if self.kind == "period" and self.coordinate is None:
            raise ValueError(f"published {self.quantity}: a period names its coordinate")


BENCHMARK_ERROR_AT = ("run", "end")


@dataclass(frozen=True)
class BenchmarkError:
    """How a benchmark measures a solution's error, as its specification states it (the
    accuracy that, with the CPU time, a code reports on the problem).

    `quantities`: the published quantities, each a named point's component
    (``"P1.x"``, ``"B0.vy"``: x, y, z for the position, vx, vy, vz for the velocity of a
    `PointOutput`) or a coordinate's name (``"beta"``). `at` "run": the largest absolute
    difference from the reference over every sample of the run; "end": the difference at
    the run's last instant (a source that publishes the state at one time). The error is
    the largest over the quantities, in their own unit (`unit`). `scenario`: the run it
    measures (None: the first)."""

    quantities: tuple[str, ...]
    at: str
    unit: str
    source: str
    description: str = ""
    scenario: str | None = None

    def __post_init__(self) -> None:
        if self.at not in BENCHMARK_ERROR_AT:
            raise ValueError(f"benchmark error at {self.at!r} is not one of "
                             f"{', '.join(BENCHMARK_ERROR_AT)}")
        if not self.quantities:
            raise ValueError("a benchmark error names at least one quantity")


EXPECTATION_KINDS = ("xfail", "unsupported", "unresolved", "judged")


@dataclass(frozen=True)
class OrderCap:
    """The order at which an engine's solution converges on this system where a physical
    property of its model, not its scheme, sets it (comparisons/tolerances.py, "A
    posteriori", a declared order cap): e.g. an equality constraint the engine makes soft
    with a time constant that follows the step. `simulator` is an fnmatch pattern; the
    refinement judges the engine's metrics at `order` (the scheme's fastest order still
    bounds the observed one), and `reason` says why."""

    simulator: str
    order: int
    reason: str


@dataclass(frozen=True)
class Expectation:
    """An exception as data (scikit-learn's common-check pattern).

    kind "xfail": the metric is expected to fail its gate (strict: a pass is reported);
    kind "unsupported": the engine cannot express the mechanism (or scenario) at all;
    kind "unresolved": at the default step neither the metric's a-priori error bound nor
    the engine's own refinement says anything (comparisons/tolerances.py: no asymptotic
    regime down to h/8, or a bound above the ceiling a gate can discriminate), so it is
    measured and shown, not judged (strict too: a declaration whose metrics all resolve
    is reported, and their passes become unexpected);
    kind "judged": the metric is judged by its gate (a failure fails) although a
    backend-wide declaration (simulators/base.py `expected_failures`) expects it to fail:
    the reason says why that backend's floor lies below this system's gate.
    `simulator` and `metric` are fnmatch patterns ("*" matches all). `when`: a relation
    of the system's parameters (``"N >= 5"``, ``"m < 0.8"``) outside which the declaration
    does not apply: a chain's fastest mode, hence w h at the default step, grows with its
    number of elements; a lighter block raises the beam's first frequency."""

    simulator: str
    metric: str
    kind: str
    reason: str
    when: str | None = None

    def __post_init__(self) -> None:
        if self.kind not in EXPECTATION_KINDS:
            raise ValueError(f"expectation kind {self.kind!r} is not one of "
                             f"{', '.join(EXPECTATION_KINDS)}")

    def applies(self, structure: Mapping[str, int | float],
                values: Mapping[str, float] | None = None) -> bool:
        """Whether the declaration holds for a system built with `structure`, compared at
        the parameter `values` (a `when` may name any parameter: a bound that resolves
        for one block mass may not for another)."""
        if self.when is None:
            return True
        names = {k: sp.Float(v) for k, v in (values or {}).items()}
        names.update({k: sp.sympify(v) for k, v in structure.items()})
        verdict = sp.sympify(self.when, locals=names)
        if verdict not in (sp.true, sp.false):
            raise ValueError(f"expectation condition {self.when!r} must be a relation of the "
                             f"parameters {sorted(names) or '(none)'}")
        return bool(verdict)


@dataclass(frozen=True)
class System:
    id: str
    title: str
    source: str
    parameters: tuple[Parameter, ...]
    build: Callable[[SimpleNamespace], Mechanism]
    operating_point: Callable[[SimpleNamespace], Mapping[str, Expr]]
    scenarios: tuple[Scenario, ...]
    #: the monograph's printed formulas, as a function of the parameter symbols
    printed: Callable[[SimpleNamespace], tuple[PrintedFormula, ...]] = lambda P: ()
    reaction_joints: tuple[str, ...] = ()
    #: physical contact forces (normal, friction) read from reactions or closure forces
    contacts: Callable[[SimpleNamespace], tuple[ContactOutput, ...]] = lambda P: ()
    #: named body points whose positions and velocities are reported and judged
    points: Callable[[SimpleNamespace], tuple[PointOutput, ...]] = lambda P: ()
    expectations: tuple[Expectation, ...] = ()
    #: orders below the scheme's at which an engine converges on this system, each with
    #: its physical reason (OrderCap; the refinement judges at the lowest that matches)
    order_caps: tuple[OrderCap, ...] = ()
    variants: tuple[Variant, ...] = ()
    #: conditions on the parameters for the geometry to exist (checked on every set)
    validity: tuple[Condition, ...] = ()
    #: name of an exact solution in mbfidelity.analytic.closed_forms, if one exists
    exact_solution: str | None = None
    #: driven systems (monograph §8, §9.6): parameter values that switch the excitation
    #: off (its amplitudes set to zero; gravity, in a rotating frame whose weight is the
    #: excitation): the reference motion about which the free coordinates are linearized
    unexcited: Mapping[str, float] = field(default_factory=dict)
    #: the excitation's angular frequencies (rad/s), expressions of the parameters: the
    #: linear steady-state response is computed at each
    excitation_frequencies: Callable[[SimpleNamespace], tuple[Expr, ...]] = lambda P: ()
    #: named quantities of the motion, expressions of the coordinate symbols and the
    #: parameters (e.g. the absolute position x = y + z of a base-excited block, §8.2):
    #: their steady-state response is computed and checked like a coordinate's
    observables: Callable[[SimpleNamespace], Mapping[str, Expr]] = lambda P: {}
    #: a floating mechanism (no ground, Italian notes §5.3.1): directions in the
    #: coordinates (coordinate -> component) along which it moves as a rigid whole, with
    #: no stiffness or damping and a mass matrix that does not change; its equilibrium is
    #: a relative one, the configuration that translates rigidly with the acceleration
    #: the loads give it (analytic/relative_equilibrium.py)
    rigid_directions: Callable[[SimpleNamespace], tuple[Mapping[str, Expr], ...]] = (
        lambda P: ())
    #: a parameter on which the operating equilibrium's stability turns (the belt speed
    #: of a self-excited system, §7.2): `analyze` reports where it changes stability
    stability_parameter: str | None = None
    #: a discretized continuum (monograph §6): the name of its exact continuum model in
    #: mbfidelity.analytic.continuum (`CONTINUA`), whose frequencies and Rayleigh
    #: estimates `analyze` reports next to the chain's modes; the number of elements is
    #: the system's count parameter (domain "count")
    continuum: str | None = None
    #: duration (s) of the generated releases near the other stable equilibria
    #: (comparisons/runner.py `near_equilibrium_scenarios`); None: the runner's default.
    #: A stiff chain sets a few periods of its first mode: over the default its fast
    #: modes alone cost a minute of reference
    near_equilibrium_t_end: float | None = None
    #: a stiff motion (damping or stiffness rates far above the motion's own, e.g. a
    #: stiff spring-damper coupler): the reference is integrated by an implicit method
    #: (Radau IIA with the model's exact Jacobian, analytic/reference.py) instead of
    #: DOP853, whose stability bound would force steps far below what the accuracy needs
    stiff: bool = False
    #: the step (s) a comparison runs this row at when it is given none (None: the
    #: project's default): a stiff row's, where the default step would put an explicit
    #: scheme's w h on the fastest mode beyond its stability limit (the module says why)
    step: float | None = None
    #: values the sources publish for the motion (a benchmark's solution), a function of
    #: the parameter symbols like `printed`: `analyze` compares each with the reference
    published: Callable[[SimpleNamespace], tuple[Published, ...]] = lambda P: ()
    #: how the benchmark measures a solution's error (the convergence study measures the
    #: engines with it too, next to its own relative measure); None: no benchmark
    benchmark_error: BenchmarkError | None = None
    notes: str = ""
    module_doc: str = field(default="", compare=False)
    #: the catalog group (set by the discovery): "monograph", a subpackage's name (the
    #: benchmark problems), or "user"
    group: str = field(default="", compare=False)

    @property
    def driven(self) -> bool:
        """Moved by something outside it: a prescribed coordinate or a harmonic
        excitation (monograph §8, §9.6)."""
        return bool(self.mechanism.prescribed) or bool(self.excitation_frequencies(self.symbols))

    def variant(self, name: str) -> Variant:
        for v in self.variants:
            if v.name == name:
                return v
        raise ValueError(f"{self.id} has no variant {name!r}; variants: "
                         f"{', '.join(v.name for v in self.variants) or 'none'}")

    @cached_property
    def all_parameters(self) -> tuple[Parameter, ...]:
        names = {p.name for p in self.parameters}
        extra = () if "g" in names else (
            Parameter("g", STANDARD_GRAVITY, "m/s^2", "gravitational acceleration (along "
                      "-y; any finite value, 0 for a horizontal or a space mechanism)",
                      domain="real"),
        )
        return tuple(self.parameters) + extra

    @cached_property
    def symbols(self) -> SimpleNamespace:
        """The parameters as SymPy symbols, for `build` and the other description
        functions; a structural parameter is its value instead (it shapes the
        mechanism: `with_structure`)."""
        return SimpleNamespace(**{p.name: p.structural_value(p.default) if p.structural
                                  else p.symbol for p in self.all_parameters})

    @cached_property
    def parameter_symbols(self) -> SimpleNamespace:
        """Every parameter as its SymPy symbol, structural ones too: what a relation
        between parameters (a validity condition) is written in."""
        return SimpleNamespace(**{p.name: p.symbol for p in self.all_parameters})

    # --- structural parameters -----------------------------------------------------------
    # A parameter of domain "count" (the number of elements of a discretized continuum)
    # shapes the mechanism: its coordinates, bodies and derivation; so does a real one
    # marked `shapes` (which element of the chain carries a load placed at a fraction of
    # its length). A System is built for one value of each (its defaults);
    # `with_structure` gives the System built for other values: the same description with
    # those defaults and the id "<catalog id>@<name>=<value>,...", so that everything
    # keyed by the id (the in-process caches, the persistent cache through
    # `structure_tag`, results rows) tells the structures apart, and `get_system`
    # resolves such an id.

    @cached_property
    def structure(self) -> dict[str, int | float]:
        """The structural parameters this System is built for (name -> a count's integer,
        a `shapes` parameter's float)."""
        return {p.name: p.structural_value(p.default) for p in self.all_parameters
                if p.structural}

    @property
    def structure_tag(self) -> str:
        """"name=value,..." of the structure ("" without structural parameters)."""
        return ",".join(f"{k}={v}" for k, v in sorted(self.structure.items()))

    @property
    def catalog_id(self) -> str:
        """The id in the catalog (without the structure of a specialisation)."""
        return self.id.split(STRUCTURE_MARK, 1)[0]

    def with_structure(self, values: Mapping[str, float]) -> "System":
        """The System built for the structural parameters in `values` (others ignored;
        absent ones keep this System's): itself when they are its own. Each value is
        validated (a count an integer >= 1, ValueError otherwise). The specialisations of
        a catalog system are kept, one object per structure."""
        current = self.structure
        if not current:
            return self
        known = {p.name: p for p in self.all_parameters}
        wanted = dict(current)
        for name in current:
            if name in values:
                value = float(values[name])
                known[name].validate(value)
                wanted[name] = known[name].structural_value(value)
        if wanted == current:
            return self
        base = self.__dict__.get("_catalog_system", self)
        if wanted == base.structure:
            return base
        kept = base.__dict__.setdefault("_specialisations", {})
        key = tuple(sorted(wanted.items()))
        if key not in kept:
            tag = ",".join(f"{k}={v}" for k, v in key)
            special = replace(base, id=f"{base.id}{STRUCTURE_MARK}{tag}", parameters=tuple(
                replace(p, default=wanted[p.name]) if p.structural else p
                for p in base.parameters))
            special.__dict__["_catalog_system"] = base
            kept[key] = special
        return kept[key]

    @cached_property
    def mechanism(self) -> Mechanism:
        """The symbolic mechanism (parameters as symbols)."""
        mech = self.build(self.symbols)
        if mech.gravity is not GRAVITY and sp.sympify(mech.gravity) != GRAVITY:
            raise ValueError(f"{self.id}: gravity must be the parameter g")
        return mech

    @property
    def coordinates(self) -> tuple[str, ...]:
        return self.mechanism.coordinates

    def parameter_values(self, overrides: Mapping[str, float] | None = None,
                         scenario: Scenario | None = None) -> dict[str, float]:
        """Defaults, then the scenario's values, then the user's overrides (validated),
        then the defaults given by formulas that neither set; the set must meet the
        system's `validity` conditions (ValueError naming the violated one)."""
        return self.resolve_parameters(overrides, scenario)[0]

    def derived_parameters(self, overrides: Mapping[str, float] | None = None,
                           scenario: Scenario | None = None) -> tuple[str, ...]:
        """Names of the parameters whose value comes from their default's formula (not
        set by the scenario or the user)."""
        return self.resolve_parameters(overrides, scenario)[1]

    def resolve_parameters(self, overrides: Mapping[str, float] | None = None,
                           scenario: Scenario | None = None
                           ) -> tuple[dict[str, float], tuple[str, ...]]:
        """(values, names of the derived parameters): see `parameter_values`."""
        known = {p.name: p for p in self.all_parameters}
        given: dict[str, float] = {}
        if scenario is not None:
            given.update({k: float(v) for k, v in scenario.overrides.items()})
        for name, value in (overrides or {}).items():
            if name not in known:
                raise KeyError(
                    f"unknown parameter {name!r} for {self.id}; valid: {', '.join(known)}"
                )
            known[name].validate(float(value))
            given[name] = float(value)
        values = {name: float(p.default) for name, p in known.items() if not p.derived}
        values.update(given)
        pending = [name for name, p in known.items() if p.derived and name not in given]
        derived = tuple(pending)
        while pending:  # a formula may use another derived parameter
            ready = [n for n in pending if set(self._formulas[n][0]) <= set(values)]
            if not ready:
                raise ValueError(f"{self.id}: the formulas of {', '.join(pending)} depend "
                                 f"on each other")
            for name in ready:
                args, law = self._formulas[name]
                try:
                    value = float(law(*(values[a] for a in args)))
                    known[name].validate(value)
                except (ValueError, ArithmeticError) as exc:
                    raise ValueError(f"{self.id}: default of {name} = {known[name].default}: "
                                     f"{exc}") from None
                values[name] = value
            pending = [n for n in pending if n not in ready]
        values = {name: values[name] for name in known}
        self.check_validity(values)
        return values, derived

    def check_validity(self, values: Mapping[str, float]) -> None:
        """Raise ValueError (one line, the first violated condition) when `values` leave
        the geometry's domain."""
        for condition, lhs, rhs, op in self._conditions:
            a = float(lhs(*(values[n] for n in lhs.names)))
            b = float(rhs(*(values[n] for n in rhs.names)))
            if not _RELATIONS[op](a, b):
                raise ValueError(f"{self.id}: the parameters violate {condition.relation} "
                                 f"({a:.6g} {op} {b:.6g} is false): {condition.meaning}")
        for body, what, f in self._body_quantities:
            value = float(f(*(values[n] for n in f.names)))
            if not value >= 0:
                raise ValueError(f"{self.id}: body {body}'s {what} must be >= 0 (a point mass "
                                 f"has zero inertia), got {value:g} at these parameters")

    @cached_property
    def _body_quantities(self):
        """(body, "mass" | "inertia", compiled expression) of every body of the
        description, whatever parameters they depend on: each must stay non-negative."""
        out = []
        for b in self.mechanism.bodies:
            tensor = b.inertia_tensor
            moments = [b.inertia] + ([tensor[i][i] for i in range(3)] if tensor else [])
            for what, expr in [("mass", b.mass)] + [("inertia", m) for m in moments]:
                out.append((b.name, what, _compiled(sp.sympify(expr), self.symbols)))
        return tuple(out)

    def is_valid(self, values: Mapping[str, float]) -> bool:
        try:
            self.check_validity(values)
        except ValueError:
            return False
        return True

    @cached_property
    def _formulas(self) -> dict[str, tuple[tuple[str, ...], Callable[..., float]]]:
        """name -> (the parameters its formula uses, the compiled formula)."""
        names = {p.name for p in self.all_parameters}
        out = {}
        for p in self.all_parameters:
            if not p.derived:
                continue
            expr = sp.sympify(p.default, locals=vars(self.symbols))
            args = tuple(sorted(str(x) for x in expr.free_symbols))
            if not set(args) <= names - {p.name}:
                raise ValueError(f"{self.id}: default of {p.name} ({p.default}) must be a "
                                 f"formula of the other parameters")
            out[p.name] = (args, sp.lambdify([getattr(self.symbols, a) for a in args], expr,
                                             modules="math"))
        return out

    @cached_property
    def _conditions(self):
        out = []
        # in the parameters' symbols, structural ones too: a condition on them (a load on
        # a node of the chain) holds for the values checked, not for this System's own
        for c in self.validity:
            rel = sp.sympify(c.relation, locals=vars(self.parameter_symbols), evaluate=False)
            if not isinstance(rel, sp.core.relational.Relational):
                raise ValueError(f"{self.id}: validity condition {c.relation!r} is not a "
                                 f"relation")
            if rel.rel_op not in _RELATIONS:
                raise ValueError(f"{self.id}: validity condition {c.relation!r} must be an "
                                 f"inequality")
            out.append((c, _compiled(rel.lhs, self.parameter_symbols),
                        _compiled(rel.rhs, self.parameter_symbols), rel.rel_op))
        return tuple(out)

    def subs(self, values: Mapping[str, float]) -> dict[sp.Symbol, float]:
        """Parameter symbol -> value (structural parameters are no symbols: left out)."""
        structural = self.structure
        return {getattr(self.symbols, k): v for k, v in values.items() if k not in structural}

    def numeric_mechanism(self, values: Mapping[str, float],
                          variant: str | None = None) -> Mechanism:
        """The mechanism with numbers for the parameters; with `variant`, the variant's
        constraints in place of the description's of the same name (what an engine
        builds for the variant). Built for the structure in `values`."""
        built = self.with_structure(values)
        if built is not self:
            return built.numeric_mechanism(values, variant)
        mech = self.mechanism
        if variant:
            instead = {c.name: c for c in self.variant(variant).constraints(self.symbols)}
            mech = replace(mech, constraints=tuple(instead.get(c.name, c)
                                                   for c in mech.constraints))
        return mech.substitute(self.subs(values))

    def scenario(self, name: str) -> Scenario:
        for s in self.scenarios:
            if s.name == name:
                return s
        raise KeyError(
            f"unknown scenario {name!r} for {self.id}; valid: "
            + ", ".join(s.name for s in self.scenarios)
        )

    def initial_state(self, scenario: Scenario, values: Mapping[str, float]):
        import numpy as np

        built = self.with_structure(values)
        if built is not self:
            return built.initial_state(scenario, values)
        # a function of the parameters where the coordinates depend on the structure
        q0_of, qd0_of = (x(self.symbols) if callable(x) else x
                         for x in (scenario.q0, scenario.qd0))
        q0 = np.array([self.evaluate(q0_of.get(c, 0), values) for c in self.coordinates])
        qd0 = np.array([self.evaluate(qd0_of.get(c, 0), values) for c in self.coordinates])
        return q0, qd0

    def evaluate(self, expr, values: Mapping[str, float]) -> float:
        """A number, an expression of parameter symbols, or a string naming them."""
        parsed = sp.sympify(expr, locals=vars(self.symbols)) if isinstance(expr, str) else expr
        return float(sp.sympify(parsed).xreplace(self.subs(values)))

    def operating_values(self, values: Mapping[str, float]):
        import numpy as np

        built = self.with_structure(values)
        if built is not self:
            return built.operating_values(values)
        op = self.operating_point(self.symbols)
        return np.array([self.evaluate(op.get(c, 0), values) for c in self.coordinates])


_RELATIONS = {">": float.__gt__, ">=": float.__ge__, "<": float.__lt__, "<=": float.__le__}


def _compiled(expr, symbols: SimpleNamespace):
    """An expression of parameters as a fast function; `.names` lists its arguments."""
    names = tuple(sorted(str(x) for x in sp.sympify(expr).free_symbols))
    law = sp.lambdify([getattr(symbols, n) for n in names], expr, modules="math")
    law.names = names
    return law


SYSTEM_PATH_VARIABLE = "MBFIDELITY_SYSTEM_PATH"
ENTRY_POINT_GROUP = "mbfidelity.systems"


#: the group of the package's own modules (the monograph's mechanisms); a subpackage
#: systems/<group>/ holds another group (the community's benchmark problems)
MONOGRAPH_GROUP = "monograph"
USER_GROUP = "user"


def _catalog_modules():
    """(group, module name, module) of every mechanism module of the package."""
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_") or info.name == "model":
            continue
        if not info.ispkg:
            yield MONOGRAPH_GROUP, info.name, importlib.import_module(f"{__name__}.{info.name}")
            continue
        package = importlib.import_module(f"{__name__}.{info.name}")
        for sub in pkgutil.iter_modules(package.__path__):
            if not sub.name.startswith("_"):
                yield info.name, sub.name, importlib.import_module(
                    f"{package.__name__}.{sub.name}")


def _discover() -> dict[str, System]:
    found: dict[str, System] = {}
    for group, name, module in _catalog_modules():
        system = getattr(module, "SYSTEM", None)
        if isinstance(system, System):
            if system.id != name:
                raise ValueError(f"module {name} defines system {system.id}")
            if system.id in found:
                raise ValueError(f"module {module.__name__}: system id {system.id!r} is "
                                 "already in the catalog")
            object.__setattr__(system, "module_doc", module.__doc__ or "")
            object.__setattr__(system, "group", group)
            found[system.id] = system
    for source, module in _user_modules():
        _register_user_system(found, source, module)
    return dict(sorted(found.items()))


def _user_modules():
    """(where it came from, module or System) of every user mechanism."""
    for entry in os.environ.get(SYSTEM_PATH_VARIABLE, "").split(os.pathsep):
        if entry:
            yield entry, _load_module_file(Path(entry))
    for point in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        source = f"entry point {point.name} = {point.value} ({ENTRY_POINT_GROUP})"
        try:
            yield source, point.load()
        except Exception as exc:  # a user's module: any error is reported, in one line
            raise ValueError(f"{source}: cannot be loaded: {type(exc).__name__}: {exc}") from exc


def _load_module_file(path: Path):
    if not path.is_file() or path.suffix != ".py":
        raise ValueError(f"{path}: not a Python file (a mechanism module, like those in "
                         f"mbfidelity/systems/)")
    name = f"mbfidelity_user_systems.{path.stem}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses and pickling look modules up by name
    try:
        spec.loader.exec_module(module)
    except (Exception, SystemExit) as exc:  # a user's module: any error, in one line
        del sys.modules[name]
        raise ValueError(f"{path}: cannot be loaded: {type(exc).__name__}: {exc}") from exc
    return module


def _register_user_system(found: dict[str, System], source: str, module) -> None:
    system = module if isinstance(module, System) else getattr(module, "SYSTEM", None)
    if not isinstance(system, System):
        raise ValueError(f"{source}: defines no SYSTEM = mbfidelity.systems.System(...)")
    if system.id in found:
        raise ValueError(f"{source}: system id {system.id!r} is already in the catalog")
    try:
        system.mechanism  # the description must build from its parameters' symbols
    except Exception as exc:  # a user's module: any error is reported, in one line
        raise ValueError(f"{source}: {system.id}'s build fails: {type(exc).__name__}: "
                         f"{exc}") from exc
    object.__setattr__(system, "module_doc", getattr(module, "__doc__", None) or "")
    object.__setattr__(system, "group", USER_GROUP)
    found[system.id] = system


_REGISTRY: dict[str, System] | None = None


def all_systems() -> dict[str, System]:
    global _REGISTRY
    if _REGISTRY is None:
        _REGISTRY = _discover()
    return _REGISTRY


def get_system(system_id: str) -> System:
    """The catalog's system, or (``<id>@<name>=<value>,...``) its specialisation to
    those structural parameters (`System.with_structure`)."""
    systems = all_systems()
    catalog_id, mark, tag = system_id.partition(STRUCTURE_MARK)
    if catalog_id not in systems:
        raise KeyError(f"unknown system {system_id!r}; valid: {', '.join(systems)}")
    system = systems[catalog_id]
    if not mark:
        return system
    values = {}
    for item in tag.split(","):
        name, equals, value = item.partition("=")
        if name not in system.structure or not equals:
            raise KeyError(f"unknown system {system_id!r}: {catalog_id}'s structural "
                           f"parameters are {', '.join(system.structure) or 'none'}")
        try:
            values[name] = float(value)
        except ValueError:
            raise KeyError(f"unknown system {system_id!r}: {name} must be a number") from None
    try:
        return system.with_structure(values)
    except ValueError as exc:
        raise KeyError(f"unknown system {system_id!r}: {exc}") from None
