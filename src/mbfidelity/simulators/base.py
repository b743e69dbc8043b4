"""The backend contract, common to every engine.

A backend translates an engine-neutral `Mechanism` (see `mbfidelity.systems.model`,
conventions 1-8) into one engine and runs it. The contract:

1. A backend is one module ``mbfidelity.simulators.<engine>_backend`` that defines
   ``BACKEND``, an instance of a `Backend` subclass whose `id` is the engine's id
   (``mujoco``, ``pybullet``, ``exudyn``, ``pymunk``, ``drake``). Importing the module must not
   import the engine; `available()` does.
2. `available()` (the base imports the backend's `ENGINE_MODULES`) returns ``(True, "")``
   or ``(False, reason)``; a missing engine is a visible skip, never an error.
3. `version()` is the engine's version string; it is recorded in every result.
4. Settings are declared once, in the backend's `SETTINGS` table: per key a `Setting`
   with its default (a JSON value, the engine's distorting defaults neutralised,
   docs/engines.md), the values or the type it admits, and a note saying which engine
   default it replaces and why; where it replaces one, `engine_default` holds the engine's
   out-of-the-box value (cited in the note), which the power and out-of-the-box studies
   switch back on. `default_settings()` and `setting_notes()` derive from
   the table. Users may override any key; `resolve_settings` checks every override
   centrally: an unknown key, a value of the wrong type or outside the admitted values
   raises `ValueError` naming the valid ones.
5. Exactness is declared per element kind of the description (`plan.ELEMENT_KINDS`): the
   backend's `EXPRESSIONS` table gives, per kind, the `Expression`(s) it can build, each
   exact, soft, substitute or unsupported, with how and why; where the case depends on
   the element (a massless link that can or cannot be folded, a slot through the centres
   of mass or not), each case carries its condition as code (`Expression.applies`), so
   that the declaration and the rule that selects it are one thing. A soft or substitute expression names the metrics
   it is expected to fail wherever the element occurs (`expected_failures`, with the
   physical `reason`); the comparisons derive the strict expected failures of a
   mechanism from them (`expected_failures(backend, mechanism)`), so system modules
   declare only what is specific to the mechanism. `support(mechanism)` follows from the
   declarations: `Support(ok, reason)`, false with the reason when the description is not
   translatable (`plan.description_reason`), when the engine's structure refuses it
   (`translation_reason`) or when one of its elements is unsupported; reported as data,
   not raised.
6. `simulate(mechanism, q0, qd0, t_end, dt, settings, reaction_joints)` builds a fresh
   model, integrates from the state (q0, qd0) (description coordinates; the base puts
   each prescribed coordinate on its motion at t = 0, `plan.driven_start`, so that the
   motion the engine is given decides where it starts) with fixed step
   dt for round(t_end/dt) steps, and returns a `RunResult` sampled at every step,
   including t = 0. The base owns it (in the manner of SciPy's `OdeSolver.step`): it
   resolves the settings, refuses an unsupported mechanism or an unknown reaction joint,
   counts the steps, takes the order from `scheme` and assembles and checks the
   `RunResult`; a backend writes `_simulate_impl`, which builds, steps (timed with
   `Stopwatch`) and reads out into `Samples`:
   - ``q``, ``qd``: shape (N+1, n), in the description's coordinates and sign
     conventions (engines with relative or maximal coordinates map back);
   - ``reactions``: for each requested joint, shape (N+1, 2): the force the parent
     exerts on the child through the joint, world axes, belonging to the state at the
     same sample (NaN where the engine cannot give it for that sample); a backend
     hands in what its engine books as transmitted and the outside forces that holds,
     and the base takes them out (`Samples`, point 11);
   - ``constraint_forces``: for each closure constraint of the mechanism, shape (N+1, k),
     in physical terms at the same samples: PointOnPoint, the force on body_a from
     body_b (world x, y); PointOnLine, the force of the slot on the pin (world x, y);
     LinearCoupling, its generalized force (k = 1), with the sign of -multiplier;
   - ``actuator_forces``: for each `Prescribed` element, shape (N+1,): the generalized
     force its actuator exerts on the coordinate (model convention 9: positive along the
     coordinate), belonging to the state at the same sample (NaN where the engine cannot
     give it); the prescribed coordinates themselves are in ``q``, ``qd`` as the engine
     moved them, so that the error of the engine's route to impose q(t) is measured;
   - ``wall_time``: seconds spent stepping only (build excluded), and ``cpu_time``: the
     CPU seconds (``time.process_time``) of the same stepping, comparable with point 9;
   - ``integrator_order``: the order of the scheme actually used (tolerances use it);
   - ``error_control``: for an error-controlled integrator (its steps chosen by the engine
     between the samples), its target accuracy and the steps it took (the
     trajectory gate follows from them, comparisons/tolerances.py); None for a fixed step.
   Applied loads that depend on time are evaluated at the time of each integrator stage
   where the engine allows it, and so are prescribed motions (`plan.Motion`): the engine
   imposes q(t) by its most exact route, named in its settings with its order.
7. `linearize(mechanism, q_eq, settings, dt)` returns the continuous-time eigenvalues of
   the engine's own linearization about the equilibrium q_eq (description coordinates),
   with a label of the facility used, or None when the engine has no such facility.
   Discrete-time eigenvalues are mapped with ln(lambda)/dt.
8. Backends never change the mechanism: a substitute (an intermediate slider body of
   small mass, a penalty spring) is named in the settings and its own error is measured.
9. `bare_loop(mechanism, q0, qd0, t_end, dt, settings)` (owned by the base; a backend
   writes `_bare_loop_impl`, which also reads the final state, outside the timed loop, so
   that `bare_loop_run` can show it is the state `simulate` ends in) builds the same
   model as `simulate` with the same arguments, sets the same initial state and runs the engine's
   loop for the same round(t_end/dt) steps with nothing per step beyond what the engine
   needs to step (the force laws it calls back, the loads and moving anchors it must be
   given before a step): no read-out, no samples. It returns the CPU seconds
   (``time.process_time``) of that loop, build excluded: the floor against which
   ``RunResult.cpu_time`` is measured (benchmarks/cost.py). Read-outs belong in
   `simulate`, batched so that its stepping costs little more than this loop.
10. `scheme(mechanism, settings)` names the integration scheme the run will use, its
    order and its stability limit (the largest stable w h on an undamped mode; None for an
    unconditionally stable implicit scheme), known before any stepping, so that a step
    that cannot be stable is refused up front.
11. Shared steps: what every backend needs before its engine enters is computed once, in
    `plan` (numbers, rotations, element kinds, force laws classified and compiled, the
    map between description coordinates and engine joint values, forward kinematics),
    the reactions' bookkeeping once, in `reactions`, run by `simulate` (from the force an
    engine books as transmitted, or its centre-of-mass accelerations, the forces entering
    the child's subtree from outside taken out), and settings are validated here; a
    backend translates the plan into its engine, steps it and reads out.
12. Flexible elements (optional): a backend declares in `BEAM_ELEMENTS`, per kind of the
    engine's own flexible (beam) element, a `BeamElement`: its `Expression` (exact: the
    element discretizes the Euler-Bernoulli beam itself; soft: it converges to a
    neighbouring model, e.g. a Timoshenko beam of finite shear stiffness; substitute: the
    engine puts another construct in the beam's place, e.g. a discrete elastic rod with
    lumped masses; unsupported: the engine has none, with the reason), the order in the
    number of elements N at which its frequencies are expected to converge, and the model
    they converge to. An engine without any declares one unsupported entry under
    `NO_BEAM_ELEMENT`. `beam_size_reason(beam, kind, N)` says why N elements of that kind
    cannot carry the beam (empty: they can), and `beam_frequencies(beam, kind, N, count,
    settings)` returns `BeamModes`: the first `count` natural frequencies (Hz) of bending
    (fewer when N elements have fewer bending modes)
    of the `Beam` (systems/_continua.py; straight, gravity off, simply supported, a point
    mass on the node at x = a) built of N equal elements of that kind, with a label of
    the facility that gave them (the engine's eigenvalue solver, or a free-vibration fit
    where it has none that works), the route's own relative error per mode (round-off, the
    fit's error) and what the route adds (settings, step).
"""
from __future__ import annotations

import copy
import math
import time
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Callable, ClassVar, Mapping, Sequence

import numpy as np

from ..systems import Expectation
from ..systems._continua import Beam
from ..systems.model import CoordinateForce, Mechanism, PointToPoint
from .plan import (COORDINATE_FORCE_CUSTOM, ELEMENT_KINDS, POINT_TO_POINT_CUSTOM, TIME_LOAD,
                   CoordinateMap, description_reason, driven_start, element_kind, elements)
from .reactions import joint_reactions

EXACT, SOFT, SUBSTITUTE, UNSUPPORTED = "exact", "soft", "substitute", "unsupported"
LEVELS = (EXACT, SOFT, SUBSTITUTE, UNSUPPORTED)


@dataclass(frozen=True)
class Expression:
    """How a backend expresses one element kind (contract point 5): `level` (exact, soft,
    substitute, unsupported), `how` (the engine construct, and why it is or is not
    exact), `when` (the condition, where a kind has several cases) and `applies`, that
    condition as code: a kind's cases are tried in order and the first that applies is
    the element's (the last one, without a condition, holds otherwise). A soft or substitute
    expression may name `expected_failures`, metric patterns (fnmatch, as in
    `Expectation.metric`) it is expected to push beyond the gates wherever the element
    occurs, with the physical `reason`: one strict declaration, met when at least one
    metric it covers fails."""

    level: str
    how: str
    when: str = ""
    expected_failures: tuple[str, ...] = ()
    reason: str = ""
    #: the condition `when` states, as code: (numeric mechanism, element) -> bool; None
    #: for a kind's only case and for the case that holds otherwise (the last one)
    applies: Callable[[Mechanism, object], bool] | None = field(
        default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        if self.level not in LEVELS:
            raise ValueError(f"level {self.level!r} is not one of {LEVELS}")
        if self.expected_failures and (self.level not in (SOFT, SUBSTITUTE) or not self.reason):
            raise ValueError("only a soft or substitute expression, with its reason, "
                             "declares expected failures")


@dataclass(frozen=True)
class Setting:
    """One engine setting (contract point 4). `allowed` is either the tuple of admitted
    values or the type of the value (a type or a tuple of types): ``float`` admits ints
    too, ``list`` a list of numbers, ``type(None)`` null; booleans are never numbers."""

    default: object
    allowed: object
    note: str
    #: where `default` neutralises a distorting engine default: the value the engine uses
    #: out of the box, in this setting's terms (the note cites the engine's documentation
    #: for it); None where the default is the engine's own or has no engine counterpart
    engine_default: object = None
    #: the setting counts time steps while the engine's default is a duration:
    #: `engine_default` is then in seconds (see `out_of_the_box`)
    engine_default_in_seconds: bool = False

    def out_of_the_box(self, dt: float) -> object:
        """The engine's own value at step `dt` (None: nothing neutralised)."""
        if self.engine_default is not None and self.engine_default_in_seconds:
            return float(self.engine_default) / dt
        return copy.deepcopy(self.engine_default)

    def check(self, engine: str, key: str, value: object) -> None:
        """Raise `ValueError` when `value` is not admitted."""
        if not _is_types(self.allowed):
            if value not in self.allowed:
                raise ValueError(f"{engine} setting {key} must be one of "
                                 f"{', '.join(map(repr, self.allowed))}; got {value!r}")
            return
        types = self.allowed if isinstance(self.allowed, tuple) else (self.allowed,)
        if not any(_has_type(value, t) for t in types):
            names = " or ".join("null" if t is type(None) else t.__name__ for t in types)
            raise ValueError(f"{engine} setting {key} must be {names}; got {value!r}")


def _is_types(allowed: object) -> bool:
    return isinstance(allowed, type) or (
        isinstance(allowed, tuple) and all(isinstance(a, type) for a in allowed))


def _has_type(value: object, kind: type) -> bool:
    if kind is bool:
        return isinstance(value, bool)
    if isinstance(value, bool):
        return False
    if kind is float:
        return isinstance(value, (int, float))
    if kind is list:
        return isinstance(value, (list, tuple)) and all(_has_type(v, float) for v in value)
    return isinstance(value, kind)


class ElementBuilders(dict):
    """A backend's builders, one per element kind of the description
    (`plan.ELEMENT_KINDS`), each registered with `builds` together with the expressions it
    declares (contract point 5: the declaration and the code that builds the element are
    one thing). A mapping kind -> builder; `declared()` is the backend's `EXPRESSIONS`."""

    def __init__(self) -> None:
        super().__init__()
        self.expressions: dict[str, tuple[Expression, ...]] = {}

    def builds(self, kind: str, *expressions: Expression) -> Callable:
        """Register the decorated function as the builder of `kind`, with its expressions."""
        def register(builder: Callable) -> Callable:
            self[kind], self.expressions[kind] = builder, expressions
            return builder
        return register

    def of(self, element) -> Callable:
        """The builder of an element of the description."""
        return self[element_kind(element)]

    def builds_time_load(self, *expressions: Expression) -> None:
        """Register the builder of `plan.TIME_LOAD`, with its expressions: a load that
        depends on time is built as the element it is, by the builder registered for its
        custom law's kind (`POINT_TO_POINT_CUSTOM`, `COORDINATE_FORCE_CUSTOM`): a law of
        TIME is never linear, so no engine holds it as a native element."""
        custom = {PointToPoint: POINT_TO_POINT_CUSTOM, CoordinateForce: COORDINATE_FORCE_CUSTOM}
        self.builds(TIME_LOAD, *expressions)(lambda model, f: self[custom[type(f)]](model, f))

    def refuses(self, kind: str, how: str, engine: str) -> None:
        """Register `kind` as unsupported (`how`: why), with a builder that raises
        (support() refuses the element before any build)."""
        def refused(model, element) -> None:
            raise ValueError(f"{engine} builds no {kind} ({element.name}): support() refuses it")
        self.builds(kind, Expression(UNSUPPORTED, how))(refused)

    def declared(self) -> dict[str, tuple[Expression, ...]]:
        """The registered expressions per kind, in the order of `plan.ELEMENT_KINDS`."""
        return {kind: self.expressions[kind] for kind in ELEMENT_KINDS
                if kind in self.expressions}


@dataclass(frozen=True)
class Support:
    ok: bool
    reason: str = ""


#: stability limits on the imaginary axis (largest stable w h on an undamped mode)
RK4_STABILITY = 2 * math.sqrt(2)
RK3_STABILITY = math.sqrt(3)
SEMI_IMPLICIT_EULER_STABILITY = 2.0


@dataclass(frozen=True)
class Scheme:
    """The integration scheme of a run (contract point 10)."""

    name: str
    order: int
    stability_limit: float | None


@dataclass(frozen=True)
class ErrorControl:
    """How an error-controlled integrator ran (contract point 6): the `accuracy` it kept
    every step's local error estimate below (the engine's own measure, in the state's
    units), and the number of `steps` it took. Fixed-step runs have none."""

    accuracy: float
    steps: int


@dataclass
class RunResult:
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    reactions: dict[str, np.ndarray]
    wall_time: float
    integrator_order: int
    settings: dict
    steps: int = 0
    constraint_forces: dict[str, np.ndarray] = field(default_factory=dict)
    cpu_time: float = 0.0
    actuator_forces: dict[str, np.ndarray] = field(default_factory=dict)
    error_control: ErrorControl | None = None

    def __post_init__(self) -> None:
        if self.q.shape != self.qd.shape or self.q.shape[0] != len(self.t):
            raise ValueError("RunResult: t, q and qd lengths differ")


def central_differences(residual: Callable[[np.ndarray, np.ndarray], np.ndarray],
                        x: np.ndarray, h_rel: float) -> tuple[np.ndarray, np.ndarray]:
    """(K, C): the derivatives of `residual(x, v)` (the generalized forces an engine's
    inverse dynamics leaves unbalanced) by x and by v at (x, 0), by central differences
    (contract point 7), the step in x_i h_rel max(1, |x_i|), in v_i h_rel."""
    n = len(x)
    K = np.zeros((n, n))
    C = np.zeros((n, n))
    v0 = np.zeros(n)
    for i, e in enumerate(np.eye(n)):
        h = h_rel * max(1.0, abs(x[i]))
        K[:, i] = (residual(x + h * e, v0) - residual(x - h * e, v0)) / (2 * h)
        C[:, i] = (residual(x, v0 + h_rel * e) - residual(x, v0 - h_rel * e)) / (2 * h_rel)
    return K, C


def central_jacobian(f: Callable[[np.ndarray], np.ndarray], x0: np.ndarray, step: float
                     ) -> np.ndarray:
    """df/dx at x0 by central differences (contract point 7): column k is (f(x0 + step
    e_k) - f(x0 - step e_k)) / (2 step), exact for a quadratic f up to round-off (about
    eps |f| / step); `f` may reuse its output's storage (each value is copied)."""
    columns = []
    for k in range(len(x0)):
        ends = []
        for sign in (1.0, -1.0):
            x = np.array(x0, dtype=float)
            x[k] += sign * step
            ends.append(np.array(f(x), dtype=float))
        columns.append((ends[0] - ends[1]) / (2 * step))
    return np.column_stack(columns)


def step_count(t_end: float, dt: float) -> int:
    """The number of fixed steps of a run of `t_end` seconds (contract point 6)."""
    return int(round(t_end / dt))


class Stopwatch:
    """Wall and CPU seconds of the stepping a backend times (contract points 6 and 9):
    ``with Stopwatch() as clock: ...`` then ``clock.wall``, ``clock.cpu``."""

    wall: float = 0.0
    cpu: float = 0.0

    def __enter__(self) -> "Stopwatch":
        self._wall, self._cpu = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc) -> None:
        self.cpu = time.process_time() - self._cpu
        self.wall = time.perf_counter() - self._wall


@dataclass
class Samples:
    """What a backend's `_simulate_impl` reads out (contract point 6): the samples in the
    description's coordinates, the forces, the stepping's `clock`, and `extras`, attributes
    beyond the contract set on the `RunResult` (a substitute's own constraint violation,
    a contact's report), read by the reports when present.

    The reactions are either given as such (`reactions`) or, as most engines measure them,
    as what the engine books as passing from parent to child at each requested joint
    (`transmitted`, or its subtree's Newton force), together with the forces from outside
    the child's subtree that this force holds: the pair elements' (`pair_forces`) and the
    couplings' (`coupling_forces`); the base then takes them out once
    (`reactions.joint_reactions`, contract point 11)."""

    q: np.ndarray
    qd: np.ndarray
    clock: Stopwatch
    reactions: dict[str, np.ndarray] = field(default_factory=dict)
    constraint_forces: dict[str, np.ndarray] = field(default_factory=dict)
    actuator_forces: dict[str, np.ndarray] = field(default_factory=dict)
    error_control: ErrorControl | None = None
    extras: dict[str, object] = field(default_factory=dict)
    #: per requested joint, the force the engine books as transmitted (None: `reactions`
    #: holds the contract's reactions already)
    transmitted: Mapping[str, np.ndarray] | None = None
    pair_forces: Mapping[str, np.ndarray] = field(default_factory=dict)
    coupling_forces: Mapping[str, np.ndarray] = field(default_factory=dict)


@dataclass
class BareLoop:
    """A bare loop's CPU seconds (contract point 9) and the state it ended in
    (description coordinates), read after the timed loop."""

    cpu_time: float
    q: np.ndarray
    qd: np.ndarray

    @classmethod
    def mapped(cls, cpu_time: float, cmap: CoordinateMap, values, rates) -> "BareLoop":
        """The bare loop's end state from the engine's joint values and rates (one row,
        mapped as `simulate` maps its samples)."""
        return cls(cpu_time, cmap.coordinates(np.array([values]))[0],
                   cmap.rates(np.array([rates]))[0])


@dataclass(frozen=True)
class BeamElement:
    """One kind of an engine's own flexible element (contract point 12): how it expresses
    the Euler-Bernoulli beam (`expression`), the order p of its frequencies' convergence,
    error ~ N^-p (None where unsupported), and the model it converges to."""

    expression: Expression
    order: float | None = None
    limit: str = ""


@dataclass
class BeamModes:
    """Frequencies of a discretized beam (contract point 12): `frequency_hz` (first
    `count`, ascending), the facility used (`method`), per mode the route's own relative
    error (`resolution`: the eigensolver's round-off, a fit's error; an error against the
    continuum below it measures the route, not the element) and what the route adds
    (`extra`: step, settings, cross-checks)."""

    frequency_hz: list[float]
    method: str
    resolution: list[float] = field(default_factory=list)
    extra: dict = field(default_factory=dict)

    @classmethod
    def from_squared(cls, omega2, count: int, method: str, extra: dict) -> "BeamModes":
        """The first `count` frequencies from all squared circular frequencies omega^2 of
        a dense symmetric eigensolver, each with its round-off: about eps omega_max^2 in
        omega_k^2, relative eps omega_max^2 / omega_k^2 (taken for omega_k as well,
        conservatively)."""
        omega2 = np.sort(np.asarray(omega2, dtype=float))
        count = min(count, len(omega2))
        roundoff = [float(np.finfo(float).eps * omega2[-1] / w2) for w2 in omega2[:count]]
        return cls([float(math.sqrt(w2) / (2 * math.pi)) for w2 in omega2[:count]], method,
                   roundoff, extra)


#: the key of the one unsupported entry of an engine without flexible elements
NO_BEAM_ELEMENT = "none"


#: release amplitude of a free-vibration fit's mode, a fraction of the beam's length: the
#: geometric nonlinearity stays ~1e-12
RELEASE_AMPLITUDE = 1e-6
#: periods of each mode in its record
RELEASE_PERIODS = 5
#: omega_max h of the fits' step (semi-implicit Euler is stable below 2)
RELEASE_OMEGA_DT = 0.5


def stiffness_by_central_differences(force: Callable[[np.ndarray], np.ndarray],
                                     q0: np.ndarray, step: float) -> np.ndarray:
    """K = -d force / dq at q0 (symmetrised) by central differences of `step`; `force(q)`
    is an engine's elastic generalized force at q."""
    n = len(q0)
    K = np.zeros((n, n))
    for j in range(n):
        for sign in (1.0, -1.0):
            q = q0.copy()
            q[j] += sign * step
            K[:, j] -= sign * force(q) / (2 * step)
    return 0.5 * (K + K.T)


@dataclass
class ModalFit:
    """Frequencies (Hz) of free-vibration fits (`semi_implicit_euler_modes`): per mode
    the fitted frequency, its `resolution` (relative distance to the linearization's), the
    fit before the integrator's dispersion is inverted (`uncorrected_hz`) and the
    linearization's (`linearized_hz`); the fits' `step` and the CPU seconds of their
    stepping."""

    frequency_hz: list[float]
    resolution: list[float]
    uncorrected_hz: list[float]
    linearized_hz: list[float]
    step: float
    cpu_time: float


def semi_implicit_euler_modes(M: np.ndarray, K: np.ndarray, moving: Sequence[int],
                              count: int, amplitude: float, set_step: Callable[[float], None],
                              release: Callable[[np.ndarray], None],
                              advance: Callable[[], None],
                              positions: Callable[[], np.ndarray]) -> ModalFit:
    """The first `count` modes of an engine stepping with semi-implicit Euler (v += h a,
    then q += h v), by free-vibration fits. M, K: the engine's mass matrix and
    linearization over all its coordinates; `moving`: the coordinates the modes move in
    (their shapes from M and K there). Each mode is released alone (`release` puts the
    engine at rest at the shape, of largest entry `amplitude`) and stepped (`advance`)
    for `RELEASE_PERIODS` periods at a step (`set_step`) with omega_max h =
    `RELEASE_OMEGA_DT`. The record is the modal coordinate (mass-weighted projection of
    `positions` on the shape); for one undamped mode it obeys s[n+1] + s[n-1] = 2
    cos(theta) s[n] exactly, so cos(theta) is fitted by least squares on all samples
    (linear prediction), and omega = 2 sin(theta / 2) / h inverts the semi-implicit
    Euler's dispersion (cos theta = 1 - (omega h)^2 / 2 for a linear undamped mode), which
    otherwise adds (omega h)^2 / 24. The fit's own error (`resolution`) is taken as its
    distance to the linearization, which bounds it."""
    import scipy.linalg

    omega_max = math.sqrt(max(scipy.linalg.eigh(K, M, eigvals_only=True)[-1], 0.0))
    y = moving
    lam, shapes = scipy.linalg.eigh(K[np.ix_(y, y)], M[np.ix_(y, y)])
    # n moving coordinates have n modes: fewer than `count` at few coordinates
    count = min(count, len(lam))
    dt = RELEASE_OMEGA_DT / omega_max
    set_step(dt)
    frequencies, resolution, raw, cpu = [], [], [], 0.0
    for k in range(count):
        omega_lin = math.sqrt(lam[k])
        shape = shapes[:, k] * (amplitude / np.max(np.abs(shapes[:, k])))
        weights = M[np.ix_(y, y)] @ shapes[:, k]
        release(shape)
        steps = int(math.ceil(RELEASE_PERIODS * 2 * math.pi / omega_lin / dt))
        record = np.empty(steps + 1)
        record[0] = positions() @ weights
        t0 = time.process_time()
        for n in range(steps):
            advance()
            record[n + 1] = positions() @ weights
        cpu += time.process_time() - t0
        middle = record[1:-1]
        cos_theta = float(middle @ (record[2:] + record[:-2]) / (2 * middle @ middle))
        theta = math.acos(min(max(cos_theta, -1.0), 1.0))
        omega = 2 * math.sin(theta / 2) / dt
        frequencies.append(omega / (2 * math.pi))
        resolution.append(abs(omega / omega_lin - 1))
        raw.append(theta / dt / (2 * math.pi))
    linearized = [float(math.sqrt(v) / (2 * math.pi)) for v in lam[:count]]
    return ModalFit(frequencies, resolution, raw, linearized, dt, cpu)


@dataclass(frozen=True)
class Linearization:
    eigenvalues: np.ndarray  # continuous time, 1/s
    method: str
    extra: dict = field(default_factory=dict)


def constraint_manifold_eigenvalues(
        M: np.ndarray, K: np.ndarray, D: np.ndarray,
        forces_and_jacobian: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
        u_eq: np.ndarray, step: float) -> tuple[np.ndarray, dict]:
    """(eigenvalues, what the route found) of a tree (M, K, D on its n coordinates u)
    whose closure constraints hold it at the equilibrium u_eq, from the engine's forces f
    and constraint Jacobian C (n x m) at u (`forces_and_jacobian`): the static multipliers
    of C lam = f (least squares), the constraint stiffness H = d(C lam)/du by central
    differences of C with `step`, and the projection of M, K + H, D on the null space of
    C^T (SVD), then the first-order eigenproblem with damping. Eigenvalue parts within
    1e-12 of the largest |s| are set to zero: a rigid mode (belt pulleys) has a
    structurally zero eigenvalue, which the projection's round-off would turn into a tiny
    frequency. The facts: the step, the multipliers, the equilibrium's residual
    max |C lam - f| and the rank of C."""
    from ..analytic.modes import quadratic_eigenvalues

    n = len(u_eq)
    f, C = forces_and_jacobian(u_eq)
    lam = np.linalg.lstsq(C, f, rcond=None)[0]
    residual = float(np.max(np.abs(C @ lam - f), initial=0.0))
    H = np.zeros((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = step
        H[:, k] = (forces_and_jacobian(u_eq + e)[1] - forces_and_jacobian(u_eq - e)[1]) @ lam
    H /= 2 * step
    U, sv, _ = np.linalg.svd(C)
    rank = int(np.sum(sv > 1e-12 * max(1.0, float(np.max(sv, initial=0.0)))))
    N = U[:, rank:]
    Mn, Kn, Dn = N.T @ M @ N, N.T @ (K + H) @ N, N.T @ D @ N
    eig = quadratic_eigenvalues(Mn, Dn, Kn)
    tiny = 1e-12 * max(float(np.max(np.abs(eig), initial=0.0)), 1e-300)
    eig = np.where(np.abs(eig.real) <= tiny, 0.0, eig.real) + 1j * np.where(
        np.abs(eig.imag) <= tiny, 0.0, eig.imag)
    return eig, {"constraint_step": step, "multipliers": lam.tolist(),
                 "equilibrium_residual": residual, "constraint_rank": rank}


class Backend(ABC):
    id: str = ""
    #: every setting the backend uses (contract point 4), in the order they are reported
    SETTINGS: ClassVar[Mapping[str, Setting]] = {}
    #: per element kind, the cases the backend can build (contract point 5); a kind that
    #: is missing is unsupported
    EXPRESSIONS: ClassVar[Mapping[str, tuple[Expression, ...]]] = {}
    #: the settings under which the step is a convergence study's knob (an engine that
    #: chooses its own steps runs at a fixed step there); empty: its defaults
    CONVERGENCE_SETTINGS: ClassVar[Mapping[str, object]] = {}
    #: the setting that holds an error-controlled integrator's target accuracy, the
    #: convergence study's knob for the engine (its step study stays available under
    #: CONVERGENCE_SETTINGS); empty: the engine steps at a fixed step, its knob is the step
    ACCURACY_SETTING: ClassVar[str] = ""
    #: why the backend does not build spatial mechanisms (model convention 10); empty
    #: when it does
    SPATIAL_REASON: ClassVar[str] = (
        "its translation is planar: a spatial mechanism (full inertia tensor, hinges "
        "about any axis) has no build in this backend")

    #: the engine's Python modules, imported by `available` (never at import time)
    ENGINE_MODULES: ClassVar[tuple[str, ...]] = ()

    def available(self) -> tuple[bool, str]:
        """(True, "") when every module of `ENGINE_MODULES` imports; otherwise (False,
        why): a missing or broken engine is a visible skip, never an error."""
        import importlib

        for name in self.ENGINE_MODULES:
            try:
                importlib.import_module(name)
            except Exception as exc:  # noqa: BLE001 - any import failure is data
                return False, f"{name} is not importable: {exc}"
        return True, ""

    #: the engine's distribution (its package's name), whose installed version `version`
    #: reports; a backend that reads its engine's version otherwise overrides `version`
    ENGINE_DISTRIBUTION: ClassVar[str] = ""

    def version(self) -> str:
        """See the contract in the module docstring (point 3)."""
        from importlib.metadata import version

        return version(self.ENGINE_DISTRIBUTION)

    def default_settings(self) -> dict:
        """Every setting's default, from `SETTINGS` (fresh copies: callers may mutate)."""
        return {key: copy.deepcopy(s.default) for key, s in self.SETTINGS.items()}

    def setting_notes(self) -> dict[str, str]:
        """Per setting, which engine default it replaces and why, from `SETTINGS`."""
        return {key: s.note for key, s in self.SETTINGS.items()}

    def expression(self, mechanism: Mechanism, element) -> Expression:
        """How this backend expresses one element of the (numeric) mechanism."""
        kind = element_kind(element)
        cases = self.EXPRESSIONS.get(kind, ())
        if not cases:
            return Expression(UNSUPPORTED, f"{self.id} has no translation of a {kind}")
        for case in cases:
            if case.applies is None or case.applies(mechanism, element):
                return case
        raise RuntimeError(f"{self.id}: no declared case of {kind} applies to "
                           f"{getattr(element, 'name', element)!r}")

    def accuracy_knob(self, mechanism: Mechanism, settings: Mapping | None = None) -> str:
        """`ACCURACY_SETTING` where the engine's integrator chooses its own steps for this
        mechanism (the convergence study's knob), '' where it steps at a fixed step."""
        return self.ACCURACY_SETTING

    def stored_inertia(self, mechanism: Mechanism, settings: Mapping | None = None
                       ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """A spatial mechanism's central inertia as the engine stored it, read back from
        the built model: per body, (principal moments, principal axes as the columns of a
        rotation in the body's frame). Empty where the backend does not read it back."""
        return {}

    def translation_reason(self, mechanism: Mechanism) -> str:
        """Why the engine's structure cannot hold the mechanism although no single element
        is unsupported (empty string: it can)."""
        return ""

    def support(self, mechanism: Mechanism) -> Support:
        """Contract point 5: from the description's checks, the engine's structure and the
        declared expression of every element."""
        reason = (description_reason(mechanism)
                  or (self.SPATIAL_REASON if mechanism.spatial else "")
                  or self.translation_reason(mechanism))
        if reason:
            return Support(False, reason)
        for kind, element in elements(mechanism):
            e = self.expression(mechanism, element)
            if e.level == UNSUPPORTED:
                return Support(False, f"{kind} {element.name}: {e.how}")
        return Support(True)

    def check_support(self, mechanism: Mechanism) -> None:
        """ValueError naming the engine and the reason where `support` refuses the
        mechanism."""
        support = self.support(mechanism)
        if not support.ok:
            raise ValueError(f"{self.id} cannot express this mechanism: {support.reason}")

    def simulate(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray, t_end: float,
                 dt: float, settings: Mapping | None = None,
                 reaction_joints: Sequence[str] = ()) -> RunResult:
        """See contract point 6: the run's frame, around the backend's `_simulate_impl`."""
        cfg, steps = self._run_frame(mechanism, t_end, dt, settings)
        for name in reaction_joints:
            mechanism.joint(name)  # KeyError for an unknown joint
        order = self.scheme(mechanism, cfg).order
        out = self._simulate_impl(mechanism, *driven_start(mechanism, q0, qd0), steps, dt,
                                  cfg, tuple(reaction_joints))
        t = np.arange(steps + 1) * dt
        n = len(mechanism.joints)
        if out.q.shape != (steps + 1, n) or out.qd.shape != (steps + 1, n):
            raise RuntimeError(f"{self.id} returned samples of shape {out.q.shape}, "
                               f"{out.qd.shape}; expected {(steps + 1, n)}")
        reactions = out.reactions
        if out.transmitted is not None:
            reactions = joint_reactions(mechanism, reaction_joints, out.transmitted, t, out.q,
                                        out.qd, pair_forces=out.pair_forces,
                                        coupling_forces=out.coupling_forces)
        run = RunResult(t=t, q=out.q, qd=out.qd, reactions=reactions,
                        wall_time=out.clock.wall, integrator_order=order, settings=cfg,
                        steps=steps, constraint_forces=out.constraint_forces,
                        cpu_time=out.clock.cpu, actuator_forces=out.actuator_forces,
                        error_control=out.error_control)
        for key, value in out.extras.items():
            setattr(run, key, value)
        return run

    def export_start(self, initial_states: Mapping[str, tuple[np.ndarray, np.ndarray]]
                     ) -> tuple[str, np.ndarray, np.ndarray]:
        """(scenario, q0, qd0): the first initial state, the one an exported script starts
        from; ValueError when none is given."""
        if not initial_states:
            raise ValueError("the script starts from a scenario's initial state: none given")
        name, (q0, qd0) = next(iter(initial_states.items()))
        return name, q0, qd0

    def script_title(self, engine: str, scenario: str, cfg: Mapping, detail: str = "") -> str:
        """The title of an exported script: the engine and its version, the scenario whose
        initial state it starts from (`detail` appended to that sentence) and the backend
        settings, one per line."""
        return (f"The mechanism as mbfidelity builds it in {engine} {self.version()}, from "
                f"the initial state of scenario {scenario!r}{detail}.\nBackend settings:\n"
                + "\n".join(f"  {k} = {v!r}" for k, v in cfg.items()))

    def bare_loop(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray, t_end: float,
                  dt: float, settings: Mapping | None = None) -> float:
        """See contract point 9: the CPU seconds of the bare loop."""
        return self.bare_loop_run(mechanism, q0, qd0, t_end, dt, settings).cpu_time

    def bare_loop_run(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                      t_end: float, dt: float, settings: Mapping | None = None) -> BareLoop:
        """The bare loop's CPU seconds and the state it ended in (contract point 9)."""
        cfg, steps = self._run_frame(mechanism, t_end, dt, settings)
        return self._bare_loop_impl(mechanism, *driven_start(mechanism, q0, qd0), steps,
                                    dt, cfg)

    def _run_frame(self, mechanism: Mechanism, t_end: float, dt: float,
                   settings: Mapping | None) -> tuple[dict, int]:
        """The resolved settings and the step count; ValueError for a mechanism the
        backend cannot express or a step that is not positive."""
        cfg = self.resolve_settings(settings)
        if not (dt > 0 and math.isfinite(dt)):
            raise ValueError(f"the step must be positive and finite; got {dt!r}")
        self.check_support(mechanism)
        return cfg, step_count(t_end, dt)

    @abstractmethod
    def _simulate_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                       steps: int, dt: float, cfg: dict,
                       reaction_joints: tuple[str, ...]) -> Samples:
        """Build the mechanism, set (q0, qd0), take `steps` steps of `dt` timed by a
        `Stopwatch`, and read out every sample (contract point 6)."""

    @abstractmethod
    def _bare_loop_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                        steps: int, dt: float, cfg: dict) -> BareLoop:
        """The model of `_simulate_impl`, stepped with nothing read (contract point 9)."""

    def scheme(self, mechanism: Mechanism, settings: Mapping | None = None) -> Scheme | None:
        """See the contract in the module docstring (None: not known before stepping)."""
        return None

    def linearize(self, mechanism: Mechanism, q_eq: np.ndarray,
                  settings: Mapping | None = None, dt: float = 1e-3) -> Linearization | None:
        return None

    def linearization_frame(self, mechanism: Mechanism, settings: Mapping | None
                            ) -> tuple[dict, Mechanism] | None:
        """(the resolved settings, the autonomous mechanism: its time loads removed, as
        the excitation e(t) does not belong to the equilibrium) for `linearize`; None
        where no linearization is taken: an unsupported mechanism, or a driven one (it
        moves about a motion, not about an equilibrium)."""
        cfg = self.resolve_settings(settings)
        if not self.support(mechanism).ok or mechanism.prescribed:
            return None
        return cfg, mechanism.without_time_loads()

    #: per kind of the engine's own flexible element, its declaration (contract point 12)
    BEAM_ELEMENTS: ClassVar[Mapping[str, BeamElement]] = {
        NO_BEAM_ELEMENT: BeamElement(Expression(UNSUPPORTED, "no flexible element declared"))}

    def beam_element(self, kind: str) -> BeamElement:
        """The declaration of one kind; an undeclared kind is unsupported."""
        if kind not in self.BEAM_ELEMENTS:
            return BeamElement(Expression(UNSUPPORTED, f"{self.id} declares no flexible "
                                                       f"element {kind!r}; declared: "
                                                       f"{', '.join(self.BEAM_ELEMENTS)}"))
        return self.BEAM_ELEMENTS[kind]

    def beam_size_reason(self, beam: Beam, kind: str, elements: int) -> str:
        """Why `elements` elements of `kind` cannot carry `beam` (empty: they can). The
        point mass needs a node at x = a; the kind must be supported."""
        declared = self.beam_element(kind).expression
        if declared.level == UNSUPPORTED:
            return declared.how
        if elements < 1:
            return f"N = {elements}: at least one element is needed"
        if beam.point_mass > 0 and beam.node_of_point_mass(elements) is None:
            return (f"N = {elements}: no node at a = {beam.point_position:g} "
                    f"(c = {beam.c:g}) to carry the point mass")
        return ""

    def check_beam_request(self, beam: Beam, kind: str, elements: int,
                           settings: Mapping | None, route: str) -> None:
        """ValueError naming the engine and kind when `elements` elements of `kind` cannot
        carry `beam`, or when settings are given to a `route` that takes none."""
        reason = self.beam_size_reason(beam, kind, elements)
        if reason:
            raise ValueError(f"{self.id} {kind}: {reason}")
        if settings:
            raise ValueError(f"{self.id} {kind}: {route} takes no settings; got "
                             f"{sorted(settings)}")

    def beam_frequencies(self, beam: Beam, kind: str, elements: int, count: int = 3,
                         settings: Mapping | None = None) -> BeamModes:
        """See contract point 12 (an engine without flexible elements raises)."""
        raise NotImplementedError(f"{self.id}: {self.beam_element(kind).expression.how}")

    # helpers shared by backends
    def resolve_settings(self, settings: Mapping | None) -> dict:
        """The defaults with the user's overrides, each checked against `SETTINGS`."""
        merged = self.default_settings()
        for key, value in (settings or {}).items():
            if key not in self.SETTINGS:
                raise ValueError(
                    f"unknown {self.id} setting {key!r}; valid: {', '.join(sorted(merged))}")
            self.SETTINGS[key].check(self.id, key, value)
            merged[key] = value
        return merged


def expected_failures(backend: Backend, mechanism: Mechanism) -> tuple[tuple[Expectation, ...], ...]:
    """The strict expected failures that the backend's declarations imply for a
    (numeric, supported) mechanism: per distinct soft or substitute expression of its
    elements that names metric patterns, one declaration (a tuple of `Expectation`s,
    kind "xfail", one per pattern, with the expression's reason), met when at least one
    metric it covers fails."""
    out: list[tuple[Expectation, ...]] = []
    seen: set[tuple] = set()
    for _, element in elements(mechanism):
        e = backend.expression(mechanism, element)
        key = (e.expected_failures, e.reason)
        if e.expected_failures and key not in seen:
            seen.add(key)
            out.append(tuple(Expectation(backend.id, pattern, "xfail", e.reason)
                             for pattern in e.expected_failures))
    return tuple(out)
