"""Exudyn backend: the minimal-coordinate route (`ObjectKinematicTree`).

Translation (generic over the description, conventions 1-8 of `systems.model`):

- every joint becomes one link of one kinematic tree, in joint order (parents come first);
  `Revolute` -> ``RevoluteZ``, `Prismatic` -> ``PrismaticX`` with the joint frame turned so
  that its x axis is the prismatic axis. Each link frame sits at the joint point of its
  body with orientation ``theta_body + beta`` (beta = 0 for revolute children, the axis
  angle minus the angle offset for prismatic children); the centre of mass is placed in
  that frame, so the description's body frames are reproduced exactly;
- the engine's joint values ``u`` are relative; description coordinates are the affine map
  ``q = T u + c`` (absolute revolute angles add the parent's angle, a non-unit prismatic
  axis scales the slide), generalized forces map with ``T^T``;
- massless link bodies are kept as zero-mass links (the tree accepts them while the
  mass matrix stays regular, i.e. while a massive descendant carries the coordinates);
- a spatial mechanism (model convention 10; open trees of massive bodies on relative
  counter-clockwise hinges about a link axis, without offset) gets RevoluteX/Y/Z links
  whose frames sit at the joints, aligned with their parents, with the full 3 x 3
  central tensor in ``linkInertiasCOM`` (stored as given: `stored_inertia`);
- gravity is the tree's own gravity vector; a `CoordinateForce` whose law is affine in
  COORD/COORD_RATE and free of TIME uses the tree's PD terms (C++), any other law is a
  Python ``forceUserFunction`` of the tree (called at every integrator stage with the
  stage time); a `PointToPoint` element is an ``ObjectConnectorSpringDamper`` between
  markers (native stiffness/damping/force when the law is affine in LENGTH/LENGTH_RATE,
  a ``springForceUserFunction`` otherwise);
- every step is sampled by in-memory sensors (write period dt/2, so each step is recorded
  exactly once), and Exudyn's C++ loop runs without Python stepping;
- reactions: the tree has no joint-force output, so the force parent -> child is Newton's
  law on the child's subtree, with the engine's centre-of-mass accelerations (kinematic
  tree sensors, end-of-step accelerations), minus gravity and minus the element forces
  that enter the subtree from outside (the engine's connector force, or the law on the
  owning prismatic joint). The solvers record zero accelerations at t = 0, so that sample
  uses the engine's mass matrix and right-hand side at the initial state;
- linearization: `mbs.ComputeLinearizedSystem` (exact M; K and D from Exudyn's
  forward-difference Jacobian, taken at two steps and Richardson-extrapolated), then the
  first-order eigenproblem with damping (all 2n eigenvalues).

Closure constraints (`PointOnPoint`, `PointOnLine`, `LinearCoupling`) stay on the tree and
are exact (index-3 algebraic equations, met to round-off):

- PointOnPoint -> ``ObjectJointRevolute2D`` between two rigid markers (tree links through
  ``MarkerKinematicTreeRigid``, the world through a ground body), marker 0 on body_a; its
  ``Force`` output is the force on body_a from body_b (world axes);
- PointOnLine -> ``ObjectJointPrismatic2D`` with ``constrainRotation=False`` (exact pin in
  slot), marker 0 the pin, marker 1 the slot body with the slot normal in its frame; its
  ``ForceLocal`` output is the slot's force on the pin in the pin marker's frame, turned to
  world axes with the pin body's angle;
- LinearCoupling -> ``ObjectConnectorCoordinateVector`` on the tree node's coordinates
  (marker 1 a ground node): the description coordinates are affine in the engine's
  (``q = T u + c``), so sum(coef q) - const = (coef T) u + (coef c - const), the same Phi;
  its ``Force`` output is the multiplier lam of M u'' + ... + Phi_u^T lam = f, so the
  coupling's generalized force is -lam;
- explicit solvers cannot run algebraic equations, so a constrained mechanism runs
  ``constrained_solver`` (GeneralizedAlpha, rho 0.9, or TrapezoidalIndex2; order 2). A
  massless subtree is accepted when a closure constraint holds it (the augmented matrix
  [M C^T; C 0] is then regular although M is not);
- reactions add the closure forces that enter the child's subtree; the t = 0 sample uses
  the implicit solver's consistent initial accelerations;
- linearization on the constraint manifold: the tree's M, K, D as above, Exudyn's
  constraint Jacobian C, the static multipliers C lam = f from Exudyn's own forces, the
  constraint stiffness d(C lam)/du by central differences of C, and the null-space
  projection of ``ComputeODE2Eigenvalues`` (which alone omits d(C lam)/du).

Prescribed motion (convention 9) is an algebraic equation on the tree as well:

- each prescribed coordinate q = scale u_p + shift (one engine joint value; an absolute
  angle on a turning parent, a sum of joint values, is refused) is an
  ``ObjectConnectorCoordinate`` between a ground coordinate and the tree node's coordinate
  p, equation u_p - UF(t) = 0 with ``offsetUserFunction`` UF = (q(t) - shift) / scale and
  ``offsetUserFunction_t`` its rate, both from `plan.Motion` (symbolic derivatives) and
  evaluated by the solver at its own times; the prescribed coordinates start on the motion
  (q(0), q'(0)) whatever the initial state says;
- Exudyn's explicit solvers silently ignore the offset (the coordinate would stay put),
  so a driven mechanism runs the implicit ``driven_solver`` and an explicit one is refused;
- Exudyn's initial accelerations leave the constraints' time terms out (as if q''(0) were
  0); the trapezoidal rule then carries the inconsistency as a multiplier that alternates
  from step to step and never decays. The backend computes the consistent initial
  accelerations and multipliers itself (engine M and right-hand side at t = 0, u_p'' =
  q''(0) / scale) and starts the solver from them;
- the actuator force is -lam / scale (Exudyn adds C_u^T lam = lam e_p to the engine
  equations; virtual work maps it to the description coordinate), read at every step as
  the solver leaves it, the t = 0 sample from the consistent start; reactions of a driven
  prismatic joint exclude the actuator force along the slide, like a coordinate force.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

import numpy as np

from ..systems.model import (
    WORLD,
    CoordinateForce,
    LinearCoupling,
    Mechanism,
    PointOnLine,
    PointOnPoint,
    PointToPoint,
    Revolute,
    inertia_matrix,
)
from ..analytic.linear import quadratic_eigenvalues
from ..systems._continua import Beam
from .base import (
    EXACT,
    RK3_STABILITY,
    RK4_STABILITY,
    SOFT,
    UNSUPPORTED,
    Backend,
    BareLoop,
    BeamElement,
    BeamModes,
    Expression,
    Linearization,
    Samples,
    Scheme,
    Setting,
    Stopwatch,
)
from .reactions import joint_reactions, subtree_force
from .plan import (
    CoordinateLaws,
    driven_start,
    spatial_tree_reason,
    BODY,
    PRESCRIBED,
    COORDINATE_FORCE_CUSTOM,
    COORDINATE_FORCE_LINEAR,
    LINEAR_COUPLING,
    MASSLESS_BODY,
    POINT_ON_LINE,
    POINT_ON_POINT,
    POINT_TO_POINT_CUSTOM,
    POINT_TO_POINT_LINEAR,
    PRISMATIC,
    REVOLUTE,
    ROLLING_CONTACT,
    TIME_LOAD,
    CoordinateMap,
    ForceLaw,
    constrained_bodies,
    coordinate_map,
    motions,
    num,
    rot,
    massive_below,
)

#: order of accuracy of the fixed-step solvers offered through the "solver" setting
#: (measured on the double pendulum; Exudyn's VelocityVerlet is left out: it warns "still
#: under development" and converged at first order)
_SOLVER_ORDER = {
    "RK44": 4,
    "RK67": 6,
    "RK33": 3,
    "ExplicitMidpoint": 2,
    "ExplicitEuler": 1,
    "GeneralizedAlpha": 2,
    "TrapezoidalIndex2": 2,
}
#: the engine's own beam elements (contract point 12)
ANCF_CABLE = "ANCFCable2D"
GEOMETRICALLY_EXACT = "BeamGeometricallyExact2D"
#: the geometrically exact element's shear stiffness, GA = factor EI / l^2: high, so that
#: its Timoshenko limit lies 5e-6 n^2 lower by shear (far below its error at N <= 32)
_GE_SHEAR_FACTOR = 1e6
#: its rotary inertia per length, factor rho l^2: it must be positive (the rotation
#: coordinates carry it) and lowers the frequencies by about (n pi)^2 factor / 2 = 5e-6 n^2;
#: 1e-8 put the rotary modes so high that the eigensolver's round-off reached 4e-5 on the
#: first mode at N = 32 with the block (measured against 1e-6; 1e-4 shows in the orders)
_GE_ROTARY_FACTOR = 1e-6
#: axial stiffness EA = factor EI / l^2 (the axial coordinates are held; any positive value)
_AXIAL_FACTOR = 1e4
#: solvers that handle algebraic (constraint) equations; Exudyn's explicit solvers stop
#: with "contains constraints that cannot be solved"
_CONSTRAINT_SOLVERS = ("GeneralizedAlpha", "TrapezoidalIndex2")


def _engine_coordinate(geo_T: np.ndarray, index: int) -> bool:
    """True when description coordinate `index` is one engine joint value (scaled and
    shifted): its row of q = T u + c has its only entry on the diagonal."""
    row = geo_T[index]
    return row[index] != 0 and np.count_nonzero(row) == 1


def _rot3(angle: float) -> np.ndarray:
    out = np.eye(3)
    out[:2, :2] = rot(angle)
    return out


@dataclass
class _ClosureItem:
    """One closure constraint as built in Exudyn, and how its engine force maps to the
    contract's physical terms."""

    name: str
    kind: str            # "point" (PointOnPoint), "line" (PointOnLine), "coupling"
    obj: int             # Exudyn object number
    frame_body: str = WORLD  # "line": the body of marker 0 (ForceLocal is in its frame)
    row: np.ndarray | None = None    # "coupling": Phi = row . u + offset (engine u)
    offset: float = 0.0


@dataclass
class _DrivenItem:
    """One prescribed coordinate as built in Exudyn: the ``CoordinateConstraint`` `obj`
    holding engine coordinate `index` at (q(t) - shift) / scale, where the description
    coordinate is q = scale u + shift."""

    name: str
    obj: int
    index: int
    scale: float
    shift: float


@dataclass
class _Geometry:
    """The link frames of Exudyn's kinematic tree for a (numeric) mechanism: one link per
    joint, its frame at the joint, turned to a prismatic joint's axis; the map between
    the description's coordinates and the engine's joint values is the shared one."""

    cmap: CoordinateMap
    link_of: dict[str, int]          # body name -> link index
    parents: list[int]
    types: list[str]                 # "R" or "P"
    offsets: list[np.ndarray]        # joint offsets (parent link frame), 2-vectors
    rotations: list[float]           # joint frame rotation against the parent link frame
    beta: dict[str, float]           # link frame orientation minus body angle
    com: dict[str, np.ndarray]       # centre of mass in the link frame

    @property
    def n(self) -> int:
        return len(self.parents)

    def local_point(self, body: str, point: Sequence[float]) -> np.ndarray:
        """A description body-frame point expressed in the body's link frame."""
        return self.com[body] + rot(-self.beta[body]) @ np.asarray(point, dtype=float)

    def frame_angle(self, body: str, u: np.ndarray) -> np.ndarray:
        """Orientation of the body's link frame (world: 0) for engine values u (rows)."""
        return u @ self.cmap.angle_v[body] + self.cmap.angle_v0[body] + self.beta[body]

    def coordinates(self, u: np.ndarray, ut: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Engine values and rates (rows) -> the description's coordinates and rates."""
        T = self.cmap.T
        return u @ T.T + self.cmap.c, ut @ T.T


_AXIS_JOINTS = {(1.0, 0.0, 0.0): "RevoluteX", (0.0, 1.0, 0.0): "RevoluteY",
                (0.0, 0.0, 1.0): "RevoluteZ"}


def _hinge_axis(j: Revolute) -> tuple[float, ...]:
    axis = np.array([num(v) for v in (j.axis if j.axis is not None else (0, 0, 1))])
    return tuple(float(v) for v in axis / np.linalg.norm(axis))


def _spatial_reason(mech: Mechanism) -> str:
    """Why the spatial tree cannot hold a spatial mechanism (empty: it can): besides the
    common conditions, its hinges turn about a link axis."""
    common = spatial_tree_reason(mech, closures=False, slides=False)
    if common:
        return common
    for j in mech.joints:
        if _hinge_axis(j) not in _AXIS_JOINTS:
            return (f"joint {j.name}: the tree's hinges turn about a link axis (RevoluteX, "
                    f"Y or Z), not about {_hinge_axis(j)}")
    return ""


def _spatial_tree(mech: Mechanism, exu) -> tuple[list, list, list, list, list]:
    """(joint types, joint offsets, central tensors, centres of mass, gravity) of a
    spatial open tree of hinges: each link frame at its joint, aligned with its parent
    (model convention 10), the body's full 3 x 3 tensor about its centre of mass."""
    def column(v):
        return [float(num(c)) for c in v] + [0.0] * (3 - len(v))

    types, offsets, tensors, coms = [], [], [], []
    com_of = {WORLD: [0.0, 0.0, 0.0]}
    for j in mech.joints:
        types.append(getattr(exu.JointType, _AXIS_JOINTS[_hinge_axis(j)]))
        offsets.append([a + b for a, b in zip(com_of[j.parent], column(j.parent_anchor))])
        com_of[j.child] = [-c for c in column(j.child_anchor)]
        coms.append(com_of[j.child])
        tensors.append(np.array(inertia_matrix(mech.body(j.child)).tolist(), dtype=float))
    up = np.array(column(mech.up))
    gravity = (-num(mech.gravity) * up / np.linalg.norm(up)).tolist()
    return types, offsets, tensors, coms, gravity


def _geometry(mech: Mechanism) -> _Geometry:
    link_of: dict[str, int] = {}
    parents: list[int] = []
    types: list[str] = []
    offsets: list[np.ndarray] = []
    rotations: list[float] = []
    beta: dict[str, float] = {WORLD: 0.0}
    com: dict[str, np.ndarray] = {WORLD: np.zeros(2)}
    cmap = coordinate_map(mech)
    for i, j in enumerate(mech.joints):
        p = j.parent
        parents.append(link_of[p] if p != WORLD else -1)
        link_of[j.child] = i
        # in-plane components (a spatial tree's 3-D ones: `_spatial_tree`)
        parent_anchor = np.array([num(v) for v in j.parent_anchor][:2])
        child_anchor = np.array([num(v) for v in j.child_anchor][:2])
        offset = num(j.angle_offset)
        # the joint point in the parent's link frame
        offsets.append(com[p] + rot(-beta[p]) @ parent_anchor)
        if isinstance(j, Revolute):
            types.append("R")
            rotations.append(offset - beta[p])
            beta[j.child] = 0.0
        else:
            types.append("P")
            axis = np.array([num(v) for v in j.axis])
            alpha = math.atan2(axis[1], axis[0])
            rotations.append(alpha - beta[p])
            beta[j.child] = alpha - offset
        com[j.child] = -rot(-beta[j.child]) @ child_anchor
    return _Geometry(cmap, link_of, parents, types, offsets, rotations, beta, com)


class ExudynBackend(Backend):
    id = "exudyn"
    SETTINGS = {
        "solver": Setting(
            "RK44", tuple(_SOLVER_ORDER),
            "Exudyn defaults to GeneralizedAlpha (2nd order, implicit). RK44 (classical "
            "Runge-Kutta, order 4) works on the kinematic tree without Newton iterations; "
            "also offered: RK44, RK67, RK33, ExplicitMidpoint, ExplicitEuler, "
            "GeneralizedAlpha, TrapezoidalIndex2 (integrator_order reports the order of "
            "the one used). Mechanisms with closure constraints run constrained_solver, "
            "with prescribed motion driven_solver. Engine default: Exudyn documentation, "
            "SolveDynamic(..., solverType=exudyn.DynamicSolverType.GeneralizedAlpha).",
            engine_default="GeneralizedAlpha"),
        "constrained_solver": Setting(
            "GeneralizedAlpha", _CONSTRAINT_SOLVERS,
            "Mechanisms with closure constraints (exact index-3 constraints: Exudyn's "
            "explicit solvers stop with 'contains constraints that cannot be solved'): "
            "GeneralizedAlpha (Exudyn's default, order 2) or TrapezoidalIndex2 (order 2, "
            "index-2 velocity constraints; positions drift slowly); 'solver' applies to "
            "mechanisms without closure constraints or prescribed motion only."),
        "driven_solver": Setting(
            "TrapezoidalIndex2", _CONSTRAINT_SOLVERS,
            "Mechanisms with prescribed motion (no Exudyn default: the route is the "
            "backend's): each prescribed coordinate is a CoordinateConstraint whose "
            "offsetUserFunction(_t) gives q(t), q'(t) at the solver's times, started from "
            "consistent accelerations. Only implicit solvers impose it: Exudyn's explicit "
            "solvers (RK44, ...) silently ignore the offset, so they are refused. "
            "TrapezoidalIndex2 (index 2: imposes q'(t); order 2 in the free and the "
            "prescribed coordinates and in the actuator force -lam/scale, read at every step "
            "as is: no alternation once the start is consistent). GeneralizedAlpha (index 3, "
            "constrained_spectral_radius: q(t) to round-off, free coordinates order 2, but "
            "its multiplier belongs to the algorithmic time, so the actuator force is only "
            "first order; measured on an inertial shaker: 8.8e-3 relative at dt 1e-3, "
            "8.8e-4 at 1e-4, against 8.5e-6 / 8.5e-8 with TrapezoidalIndex2)."),
        "constrained_spectral_radius": Setting(
            0.9, float,
            "GeneralizedAlpha on constrained mechanisms: Exudyn's default 0.9 kept; rho = "
            "1 (no numerical damping) lets the index-3 multipliers oscillate (measured: "
            "scotch yoke slot force error 1e4, slotted bar arctan damper failed Newton); "
            "0.8-0.99 changed trajectory errors by < 10 %."),
        "automatic_step_size": Setting(
            False, bool,
            "Exudyn default True lets error-controlled explicit solvers change the step; "
            "False keeps the fixed step dt the contract asks for. Engine default: Exudyn "
            "documentation, SimulationSettings timeIntegration.automaticStepSize = True.",
            engine_default=True),
        "ga_spectral_radius": Setting(
            1.0, float,
            "GeneralizedAlpha as 'solver' (unconstrained mechanisms). Exudyn default 0.9 "
            "adds numerical damping (energy decays); 1.0 removes it (no constraints, so "
            "rho = 1 is stable). Constrained: constrained_spectral_radius. Engine default: "
            "Exudyn documentation, SimulationSettings "
            "timeIntegration.generalizedAlpha.spectralRadius = 0.9.",
            engine_default=0.9),
        "ga_adaptive_step": Setting(
            False, bool,
            "Implicit solvers only. Exudyn default True silently reduces the step after a "
            "failed Newton solve; False keeps dt fixed (a failure is raised instead). "
            "Engine default: Exudyn documentation, SimulationSettings "
            "timeIntegration.adaptiveStep = True.",
            engine_default=True),
        "newton_relative_tolerance": Setting(
            1e-13, float,
            "Implicit solvers only. Exudyn default 1e-8 limits the accuracy of small "
            "motions; tightened. Engine default: Exudyn documentation, SimulationSettings "
            "timeIntegration.newton.relativeTolerance = 1e-8.",
            engine_default=1e-8),
        "newton_absolute_tolerance": Setting(
            1e-14, float,
            "Implicit solvers only. Exudyn default 1e-10; tightened for small amplitudes. "
            "Engine default: Exudyn documentation, SimulationSettings "
            "timeIntegration.newton.absoluteTolerance = 1e-10.",
            engine_default=1e-10),
        "modified_newton": Setting(
            False, bool,
            "Implicit solvers only. Exudyn default True reuses an old Jacobian; full "
            "Newton converges to the tight tolerances. Engine default: Exudyn "
            "documentation, SimulationSettings timeIntegration.newton.useModifiedNewton = "
            "True.",
            engine_default=True),
        "end_of_step_accelerations": Setting(
            True, bool,
            "Exudyn default True (kept): explicit solvers recompute the accelerations at "
            "the end of each step, so the sampled centre-of-mass accelerations (used for "
            "reactions) belong to the sampled state; False leaves last-stage "
            "accelerations."),
        "native_linear_laws": Setting(
            True, bool,
            "Backend choice: laws affine in the length/coordinate and its rate (no TIME) "
            "use Exudyn's built-in spring-damper and the tree's PD terms (C++); False "
            "sends every law through Python user functions (same model, slower)."),
        "write_solution_file": Setting(
            False, bool,
            "Exudyn default True writes coordinatesSolution.txt every 0.01 s (disk I/O "
            "inside the timed loop); the backend samples with in-memory sensors at every "
            "step instead (sensor write period dt replaces the 0.01 s default)."),
        "linearization_relative_epsilon": Setting(
            1e-4, float,
            "linearize(): relative step of Exudyn's numerical Jacobian (K, D), a forward "
            "difference. Exudyn default 1e-7 balances truncation and round-off at "
            "~1e-7..1e-6 absolute error in K and D; with linearization_richardson, 1e-4 "
            "gives ~1e-10 relative."),
        "linearization_richardson": Setting(
            True, bool,
            "linearize(): True evaluates Exudyn's Jacobian at eps and eps/2 and "
            "extrapolates (2 J(eps/2) - J(eps), error O(eps^2)); False is Exudyn's single "
            "forward difference (what ComputeODE2Eigenvalues uses)."),
        "linearization_constraint_step": Setting(
            1e-5, float,
            "linearize() with closure constraints: step (engine coordinate units) of the "
            "central differences of Exudyn's constraint Jacobian that give the constraint "
            "stiffness d(C lam)/du at a loaded equilibrium; Exudyn's "
            "ComputeODE2Eigenvalues leaves this term out."),
    }

    # --- identity --------------------------------------------------------------------------
    ENGINE_MODULES = ('exudyn', 'exudyn.utilities')

    def version(self) -> str:
        import exudyn

        return str(exudyn.__version__)

    # --- support ---------------------------------------------------------------------------
    EXPRESSIONS = {
        BODY: (Expression(EXACT, "a link of the ObjectKinematicTree with its mass, centre of "
                                 "mass and inertia"),),
        MASSLESS_BODY: (
            Expression(EXACT, "a zero-mass link: the mass matrix stays regular while a "
                              "massive descendant carries its coordinates, or a closure "
                              "constraint holds it (augmented matrix [M C^T; C 0])",
                       when="a massive body below it, or a constraint on its subtree",
                       applies=lambda mech, body: massive_below(mech, body) or bool(
                           constrained_bodies(mech) & set(mech.subtree(body.name)))),
            Expression(UNSUPPORTED, "it carries no mass and no constraint holds it: the "
                                    "kinematic tree's mass matrix would be singular",
                       when="only massless bodies below it, none constrained"),
        ),
        REVOLUTE: (Expression(EXACT, "RevoluteZ link of the kinematic tree"),),
        PRISMATIC: (Expression(EXACT, "PrismaticX link, the joint frame turned to the axis"),),
        POINT_TO_POINT_LINEAR: (Expression(EXACT, "ObjectConnectorSpringDamper with its own "
                                                  "stiffness, damping and force (C++)"),),
        POINT_TO_POINT_CUSTOM: (Expression(EXACT, "ObjectConnectorSpringDamper with a "
                                                  "springForceUserFunction, called at every "
                                                  "integrator stage"),),
        COORDINATE_FORCE_LINEAR: (Expression(EXACT, "the tree's PD terms and joint force "
                                                    "vector (C++) where the coordinate is one "
                                                    "engine coordinate, otherwise the tree's "
                                                    "forceUserFunction"),),
        COORDINATE_FORCE_CUSTOM: (Expression(EXACT, "the tree's forceUserFunction, called at "
                                                    "every integrator stage"),),
        TIME_LOAD: (Expression(EXACT, "a user function, called at every integrator stage "
                                      "with the stage time"),),
        POINT_ON_POINT: (Expression(EXACT, "ObjectJointRevolute2D: index-3 algebraic "
                                           "equations, met to round-off"),),
        POINT_ON_LINE: (Expression(EXACT, "ObjectJointPrismatic2D with the rotation free: an "
                                          "exact pin in slot"),),
        LINEAR_COUPLING: (Expression(EXACT, "ObjectConnectorCoordinateVector on the tree's "
                                            "coordinates (affine in the description's, so "
                                            "the coupling stays linear)"),),
        ROLLING_CONTACT: (Expression(UNSUPPORTED, "no contact is built on the kinematic tree: "
                                                  "Exudyn holds the rolling coupling exactly "
                                                  "(LinearCoupling)"),),
        PRESCRIBED: (
            Expression(EXACT, "ObjectConnectorCoordinate between a ground coordinate and the "
                              "joint's engine coordinate, offsetUserFunction(_t) = q(t), "
                              "q'(t) at the implicit solver's times (driven_solver), "
                              "started from consistent accelerations; actuator force "
                              "-multiplier / scale; order 2 (TrapezoidalIndex2) in the "
                              "coordinates and the force",
                       when="the prescribed coordinate is one engine joint value",
                       applies=lambda mech, prescribed: _engine_coordinate(
                           coordinate_map(mech).T, mech.coordinates.index(prescribed.coordinate))),
            Expression(UNSUPPORTED, "an absolute angle on a turning parent is a combination "
                                    "of engine joint values, which Exudyn's coordinate "
                                    "constraint (one coordinate, time offset) cannot hold",
                       when="the prescribed coordinate combines several joint values"),
        ),
    }

    SPATIAL_REASON = ""

    def stored_inertia(self, mechanism: Mechanism, settings: Mapping | None = None
                       ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """The tree's linkInertiasCOM as stored (a full 3 x 3 tensor, not diagonalised),
        in principal form."""
        cfg = self.resolve_settings(settings)
        zeros = np.zeros(len(mechanism.joints))
        _, mbs, _, _, tree, _, _ = self._build(mechanism, zeros, zeros, cfg)
        tensors = np.array(mbs.GetObjectParameter(tree, "linkInertiasCOM"), dtype=float)
        out = {}
        for j, tensor in zip(mechanism.joints, tensors.reshape(-1, 3, 3)):
            values, axes = np.linalg.eigh(tensor)
            out[j.child] = (values, axes)
        return out

    def translation_reason(self, mechanism: Mechanism) -> str:
        return _spatial_reason(mechanism) if mechanism.spatial else ""

    # --- model building --------------------------------------------------------------------
    def _build(self, mech: Mechanism, q0: np.ndarray, qd0: np.ndarray, settings: dict):
        import exudyn as exu
        from exudyn.itemInterface import (MarkerBodyPosition, MarkerKinematicTreeRigid,
                                          NodeGenericODE2, ObjectConnectorSpringDamper,
                                          ObjectGround, ObjectKinematicTree)

        geo = _geometry(mech)
        n = geo.n
        Tinv = np.linalg.inv(geo.cmap.T)
        u0 = Tinv @ (np.asarray(q0, dtype=float) - geo.cmap.c)
        ud0 = Tinv @ np.asarray(qd0, dtype=float)

        SC = exu.SystemContainer()
        mbs = SC.AddSystem()
        node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n,
                                           initialCoordinates=u0.tolist(),
                                           initialCoordinates_t=ud0.tolist(),
                                           numberOfODE2Coordinates=n))
        bodies = [j.child for j in mech.joints]
        joint_types = [exu.JointType.RevoluteZ if t == "R" else exu.JointType.PrismaticX
                       for t in geo.types]
        inertias = [np.diag([0.0, 0.0, num(mech.body(b).inertia)]) for b in bodies]
        coms = [[*geo.com[b], 0.0] for b in bodies]
        offsets = [[*o, 0.0] for o in geo.offsets]
        transformations = [_rot3(a) for a in geo.rotations]
        gravity = [0.0, -num(mech.gravity), 0.0]
        if mech.spatial:  # model convention 10; `_spatial_reason` bounds the cases
            joint_types, offsets, inertias, coms, gravity = _spatial_tree(mech, exu)
            transformations = [np.eye(3)] * n

        # coordinate forces: native PD terms where the law is affine and maps to one
        # engine coordinate, the rest through one Python user function of the tree
        P = np.zeros(n)
        D = np.zeros(n)
        f_const = np.zeros(n)
        python_laws: list[CoordinateForce] = []
        for f in mech.forces:
            if not isinstance(f, CoordinateForce):
                continue
            weights = f.weights(mech.coordinates)
            law = ForceLaw.of(f)
            aff = law.linear if settings["native_linear_laws"] else None
            # native when COORD is s u_j, one engine coordinate (then Q_u = s F(s u, s u_t))
            target = geo.cmap.law_target(weights)
            if aff is not None and target is not None:
                j, s = target
                a0, ax, av = aff
                f_const[j] += s * a0
                P[j] += -s * s * ax
                D[j] += -s * s * av
            else:
                python_laws.append(f)

        tree_args = dict(
            nodeNumber=node, gravity=gravity, baseOffset=[0.0, 0.0, 0.0],
            jointTypes=joint_types, linkParents=geo.parents,
            jointTransformations=exu.Matrix3DList(transformations),
            jointOffsets=exu.Vector3DList(offsets),
            linkInertiasCOM=exu.Matrix3DList(inertias), linkCOMs=exu.Vector3DList(coms),
            linkMasses=[num(mech.body(b).mass) for b in bodies],
        )
        if np.any(P) or np.any(D):
            tree_args.update(jointPControlVector=P.tolist(), jointDControlVector=D.tolist(),
                             jointPositionOffsetVector=[0.0] * n,
                             jointVelocityOffsetVector=[0.0] * n)
        if np.any(f_const):
            tree_args.update(jointForceVector=f_const.tolist())
        if python_laws:
            tree_args.update(forceUserFunction=self._coordinate_user_function(
                geo, CoordinateLaws(mech, python_laws)))
        tree = mbs.AddObject(ObjectKinematicTree(**tree_args))

        # point-to-point elements: spring-dampers between markers
        ground = None
        connectors: dict[str, object] = {}
        for f in mech.forces:
            if not isinstance(f, PointToPoint):
                continue
            if f.body_a == WORLD and f.body_b == WORLD:
                continue  # acts on nothing
            markers = []
            for body, point in ((f.body_a, f.point_a), (f.body_b, f.point_b)):
                pt = [num(v) for v in point]
                if body == WORLD:
                    if ground is None:
                        ground = mbs.AddObject(ObjectGround())
                    markers.append(mbs.AddMarker(MarkerBodyPosition(
                        bodyNumber=ground, localPosition=[*pt, 0.0])))
                else:
                    markers.append(mbs.AddMarker(MarkerKinematicTreeRigid(
                        objectNumber=tree, linkNumber=geo.link_of[body],
                        localPosition=[*geo.local_point(body, pt), 0.0])))
            law = ForceLaw.of(f)
            aff = law.linear if settings["native_linear_laws"] else None
            if aff is not None:
                b0, bl, bv = aff  # tension = b0 + bl L + bv L' = k (L - 0) + d L' + force
                conn = ObjectConnectorSpringDamper(markerNumbers=markers, referenceLength=0.0,
                                                   stiffness=bl, damping=bv, force=b0)
            else:
                # referenceLength 0, so deltaL is the length itself
                conn = ObjectConnectorSpringDamper(
                    markerNumbers=markers, referenceLength=0.0,
                    springForceUserFunction=self._tension_user_function(law.law))
            connectors[f.name] = mbs.AddObject(conn)
        return exu, mbs, SC, node, tree, geo, connectors

    @staticmethod
    def _add_closures(exu, mbs, mech: Mechanism, node: int, tree: int,
                      geo: _Geometry) -> list[_ClosureItem]:
        """The closure constraints as exact (index-3) Exudyn constraints on the tree:
        PointOnPoint -> ``ObjectJointRevolute2D`` (marker 0 on body_a), PointOnLine ->
        ``ObjectJointPrismatic2D`` with the rotation free (marker 0: the pin, marker 1: the
        slot body, whose frame carries the slot normal), LinearCoupling ->
        ``ObjectConnectorCoordinateVector`` on the tree node's coordinates (the description
        coordinates are affine in the engine's, so the coupling stays linear)."""
        from exudyn.itemInterface import (MarkerBodyRigid, MarkerKinematicTreeRigid,
                                          MarkerNodeCoordinates, NodePointGround,
                                          ObjectConnectorCoordinateVector, ObjectGround,
                                          ObjectJointPrismatic2D, ObjectJointRevolute2D)

        items: list[_ClosureItem] = []
        ground: list[int] = []

        def rigid_marker(body: str, point) -> int:
            pt = [num(v) for v in point]
            if body == WORLD:
                if not ground:
                    ground.append(mbs.AddObject(ObjectGround()))
                return mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground[0],
                                                     localPosition=[*pt, 0.0]))
            return mbs.AddMarker(MarkerKinematicTreeRigid(
                objectNumber=tree, linkNumber=geo.link_of[body],
                localPosition=[*geo.local_point(body, pt), 0.0]))

        node_marker = None
        ground_marker = None
        for c in mech.constraints:
            if isinstance(c, PointOnPoint):
                obj = mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[
                    rigid_marker(c.body_a, c.point_a), rigid_marker(c.body_b, c.point_b)]))
                items.append(_ClosureItem(c.name, "point", obj))
            elif isinstance(c, PointOnLine):
                d = np.array([num(v) for v in c.direction])
                d = d / float(np.hypot(*d))
                normal = np.array([-d[1], d[0]])  # the slot normal of the description
                normal_local = rot(-geo.beta[c.line_body]) @ normal
                # Exudyn: (p1 - p0) . A1 n1 = 0, p0 the pin, p1 the slot point
                obj = mbs.AddObject(ObjectJointPrismatic2D(
                    markerNumbers=[rigid_marker(c.body, c.point),
                                   rigid_marker(c.line_body, c.line_point)],
                    axisMarker0=[1.0, 0.0, 0.0], normalMarker1=[*normal_local, 0.0],
                    constrainRotation=False))
                items.append(_ClosureItem(c.name, "line", obj, frame_body=c.body))
            elif isinstance(c, LinearCoupling):
                a = np.zeros(geo.n)
                for name, coef in c.coefficients:
                    a[mech.coordinates.index(name)] += num(coef)
                row = a @ geo.cmap.T                      # Phi = row . u + offset
                offset = float(a @ geo.cmap.c) - num(c.constant)
                if node_marker is None:
                    node_marker = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=node))
                    ground_node = mbs.AddNode(NodePointGround())
                    ground_marker = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=ground_node))
                # Exudyn: X1 q1 - X0 q0 - v_off = 0 with q0 = u (marker 0), q1 empty
                obj = mbs.AddObject(ObjectConnectorCoordinateVector(
                    markerNumbers=[node_marker, ground_marker],
                    scalingMarker0=-row.reshape(1, -1), scalingMarker1=np.zeros((1, 0)),
                    offset=[-offset]))
                items.append(_ClosureItem(c.name, "coupling", obj, row=row, offset=offset))
            else:  # pragma: no cover - the Constraint union is closed
                raise TypeError(c)
        return items

    @staticmethod
    def _add_prescribed(mbs, mech: Mechanism, node: int, geo: _Geometry) -> list[_DrivenItem]:
        """Every prescribed coordinate as an ``ObjectConnectorCoordinate`` between a
        ground coordinate (marker 0) and the tree node's coordinate (marker 1): Exudyn's
        equation u - 0 - UF(t) = 0 with the offset UF(t) = (q(t) - shift) / scale and its
        rate UF_t, both evaluated by the solver at its own stage times (the index-2 solver
        imposes the rate, the index-3 one the position)."""
        from exudyn.itemInterface import (MarkerNodeCoordinate, NodePointGround,
                                          ObjectConnectorCoordinate)

        items: list[_DrivenItem] = []
        ground_marker = None
        for motion in motions(mech):
            p = motion.index
            scale, shift = float(geo.cmap.T[p, p]), float(geo.cmap.c[p])
            if ground_marker is None:
                ground_node = mbs.AddNode(NodePointGround())
                ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground_node,
                                                                   coordinate=0))
            marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=p))
            obj = mbs.AddObject(ObjectConnectorCoordinate(
                markerNumbers=[ground_marker, marker],
                offsetUserFunction=ExudynBackend._offset_function(motion.position, scale, shift),
                offsetUserFunction_t=ExudynBackend._offset_function(motion.rate, scale, 0.0)))
            items.append(_DrivenItem(motion.element.name, obj, p, scale, shift))
        return items

    @staticmethod
    def _offset_function(f: Callable[[float], float], scale: float, shift: float):
        def uf(mbs, t, item, offset):
            return (f(t) - shift) / scale
        return uf

    def _consistent_start(self, exu, mbs, cfg: dict, mech: Mechanism,
                          driven: list[_DrivenItem]) -> np.ndarray:
        """Initial accelerations and multipliers that meet the prescribed accelerations
        q''(0). Exudyn's own initial accelerations differentiate the constraints without
        their time terms (its documentation: dg/dt 'not implemented'), i.e. as if q''(0)
        were 0; the trapezoidal rule then carries that error as a step-to-step
        alternation of the multiplier that never decays, generalized-alpha as one that
        decays slowly. Here: u_p'' = q_p''(0) / scale, M_ff u_f'' = f_f - M_fp u_p'' with
        the engine's M and f at t = 0, lam_p = f_p - (M u'')_p (Exudyn: M u'' + C^T lam =
        f with C = e_p^T), written into the initial state that the solver starts from
        (computeInitialAccelerations off for driven runs). Returns lam (the solver records
        zero multipliers for the sample at t = 0)."""
        sim = self._simulation_settings(exu, cfg, 1.0, 1)
        helper = exu.MainSolverImplicitSecondOrder()
        helper.InitializeSolver(mbs, sim)
        helper.ComputeMassMatrix(mbs)
        mass = np.asarray(helper.GetSystemMassMatrix())
        n = len(mass)
        helper.ComputeODE2RHS(mbs)
        rhs = np.asarray(helper.GetSystemResidual())[:n]
        helper.FinalizeSolver(mbs, sim)
        accelerations = {m.index: m.acceleration(0.0) for m in motions(mech)}
        acc = np.zeros(n)
        held = [d.index for d in driven]
        for d in driven:
            acc[d.index] = accelerations[d.index] / d.scale
        free = [i for i in range(n) if i not in held]
        if free:
            acc[free] = np.linalg.solve(mass[np.ix_(free, free)],
                                        rhs[free] - mass[np.ix_(free, held)] @ acc[held])
        lam = rhs[held] - (mass @ acc)[held]
        initial = exu.ConfigurationType.Initial
        mbs.systemData.SetODE2Coordinates_tt(acc.tolist(), configuration=initial)
        mbs.systemData.SetAECoordinates(lam.tolist(), configuration=initial)
        return lam

    @staticmethod
    def _tension_user_function(law: Callable[..., float]):
        def uf(mbs, t, item, delta_l, delta_l_t, stiffness, damping, force):
            return law(delta_l, delta_l_t, t)  # referenceLength 0: delta_l is the length
        return uf

    @staticmethod
    def _coordinate_user_function(geo: _Geometry, laws: CoordinateLaws):
        """The laws' generalized force on the engine coordinates (T^T Q)."""
        T, c, n = geo.cmap.T, geo.cmap.c, geo.n
        if np.array_equal(T, np.eye(n)) and not np.any(c):
            def uf(mbs, t, item, u, u_t):  # description coordinates are the engine's
                return laws.generalized(u, u_t, t)
            return uf

        def uf_mapped(mbs, t, item, u, u_t):
            Q = laws.generalized(T @ np.asarray(u) + c, T @ np.asarray(u_t), t)
            return (T.T @ np.asarray(Q)).tolist()
        return uf_mapped

    def _simulation_settings(self, exu, settings: dict, t_end: float, steps: int):
        s = exu.SimulationSettings()
        ti = s.timeIntegration
        ti.numberOfSteps = steps
        ti.endTime = t_end
        ti.verboseMode = 0
        ti.automaticStepSize = bool(settings["automatic_step_size"])
        ti.adaptiveStep = bool(settings["ga_adaptive_step"])
        ti.explicit.computeEndOfStepAccelerations = bool(settings["end_of_step_accelerations"])
        ti.generalizedAlpha.spectralRadius = float(settings["ga_spectral_radius"])
        ti.generalizedAlpha.computeInitialAccelerations = True
        ti.newton.relativeTolerance = float(settings["newton_relative_tolerance"])
        ti.newton.absoluteTolerance = float(settings["newton_absolute_tolerance"])
        ti.newton.useModifiedNewton = bool(settings["modified_newton"])
        s.solution.file.write = bool(settings["write_solution_file"])
        s.solution.file.writePeriod = t_end / steps
        # half a step: every step is recorded exactly once, immune to rounding of t
        s.solution.sensors.writePeriod = 0.5 * t_end / steps
        s.staticSolver.verboseMode = 0
        s.staticSolver.newton.numericalDifferentiation.relativeEpsilon = float(
            settings["linearization_relative_epsilon"])
        s.linearSolver.ignoreSingularJacobian = False
        return s

    def export(self, mechanism: Mechanism, coordinates: Sequence[str],
               initial_states: Mapping[str, tuple[np.ndarray, np.ndarray]],
               settings: Mapping | None = None, dt: float = 1e-3) -> tuple[str, list[str]]:
        """(a standalone Python script, what it does not reproduce): every node, object,
        marker and load of the system `simulate` builds, as the dictionaries Exudyn
        reports for them (mbs.GetObject(i), ...), added back in the same order, the
        simulation settings as their dictionary, then `SolveDynamic` and the
        description's coordinates at the end (simulators/script_export.py). Python user
        functions (force laws, prescribed motion) cannot be written out: they are left
        out of the items and listed."""
        from .script_export import exudyn_script

        if not initial_states:
            raise ValueError("the script starts from a scenario's initial state: none given")
        name, (q0, qd0) = next(iter(initial_states.items()))
        cfg = self.resolve_settings(settings)
        support = self.support(mechanism)
        if not support.ok:
            raise ValueError(f"exudyn cannot express this mechanism: {support.reason}")
        solver = self._solver_for(mechanism, cfg)
        q0, qd0 = driven_start(mechanism, q0, qd0)
        exu, mbs, SC, node, tree, geo, _ = self._build(mechanism, q0, qd0, cfg)
        closures = self._add_closures(exu, mbs, mechanism, node, tree, geo)
        driven = self._add_prescribed(mbs, mechanism, node, geo)
        data = mbs.systemData
        items = [(kind, get(i)) for kind, count, get in (
            ("Node", data.NumberOfNodes(), mbs.GetNode),
            ("Object", data.NumberOfObjects(), mbs.GetObject),
            ("Marker", data.NumberOfMarkers(), mbs.GetMarker),
            ("Load", data.NumberOfLoads(), mbs.GetLoad)) for i in range(count)]
        sim = self._simulation_settings(exu, cfg, 1.0, int(round(1.0 / dt)))
        sim.timeIntegration.generalizedAlpha.computeInitialAccelerations = not driven
        if closures or driven:
            sim.timeIntegration.generalizedAlpha.spectralRadius = float(
                cfg["constrained_spectral_radius"])
        outside = []
        if mechanism.forces:
            outside.append("the force laws computed in Python user functions: "
                           + ", ".join(f.name for f in mechanism.forces))
        if driven:
            outside.append("the prescribed motions' offset user functions and the "
                           "consistent start the harness computes: "
                           + ", ".join(p.name for p in mechanism.prescribed))
        text = exudyn_script(
            title=(f"The mechanism as mbfidelity builds it in Exudyn {self.version()}, from "
                   f"the initial state of scenario {name!r}, solver {solver}.\nBackend "
                   f"settings:\n" + "\n".join(f"  {k} = {v!r}" for k, v in cfg.items())),
            items=items, simulation=sim.GetDictionary(), solver=solver, node=int(node),
            coordinates=coordinates, T=geo.cmap.T, c=geo.cmap.c, dt=dt, not_in_script=outside)
        return text, outside

    def scheme(self, mechanism: Mechanism, settings: Mapping | None = None) -> Scheme:
        solver = self._solver_for(mechanism, self.resolve_settings(settings))
        # implicit solvers are unconditionally stable; of the explicit ones only the
        # Runge-Kutta schemes with a stable stretch of the imaginary axis get a limit
        limits = {"RK44": RK4_STABILITY, "RK33": RK3_STABILITY}
        return Scheme(solver, _SOLVER_ORDER[solver], limits.get(solver))

    # --- simulation ------------------------------------------------------------------------
    def _simulate_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                       steps: int, dt: float, cfg: dict,
                       reaction_joints: tuple[str, ...]) -> Samples:
        solver = self._solver_for(mechanism, cfg)
        t_run = steps * dt
        q0, qd0 = driven_start(mechanism, q0, qd0)
        exu, mbs, SC, node, tree, geo, connectors = self._build(mechanism, q0, qd0, cfg)
        closures = self._add_closures(exu, mbs, mechanism, node, tree, geo)
        driven = self._add_prescribed(mbs, mechanism, node, geo)
        from exudyn.itemInterface import SensorKinematicTree, SensorNode, SensorObject

        ovt = exu.OutputVariableType
        sens = dict(storeInternal=True, writeToFile=False)
        s_u = mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=ovt.Coordinates, **sens))
        s_ut = mbs.AddSensor(SensorNode(nodeNumber=node, outputVariableType=ovt.Coordinates_t,
                                        **sens))
        # centre-of-mass accelerations of every massive body below a requested joint
        acc_bodies: set[str] = set()
        for name in reaction_joints:
            joint = mechanism.joint(name)
            acc_bodies |= {b for b in mechanism.subtree(joint.child)
                           if num(mechanism.body(b).mass) != 0}
        s_acc = {b: mbs.AddSensor(SensorKinematicTree(
            objectNumber=tree, linkNumber=geo.link_of[b], localPosition=[*geo.com[b], 0.0],
            outputVariableType=ovt.Acceleration, **sens)) for b in sorted(acc_bodies)}
        # engine force of every connector that can cross a requested joint
        s_conn = {name: mbs.AddSensor(SensorObject(objectNumber=obj, outputVariableType=ovt.Force,
                                                   **sens))
                  for name, obj in connectors.items()} if reaction_joints else {}
        # engine force of every closure constraint: the joints' force (world axes, on
        # marker 0) or, for the prismatic 2-D joint, the force in marker 0's frame; the
        # coordinate constraint's Lagrange multiplier
        s_closure = {c.name: mbs.AddSensor(SensorObject(
            objectNumber=c.obj, outputVariableType=ovt.ForceLocal if c.kind == "line"
            else ovt.Force, **sens)) for c in closures}
        # the multiplier of every prescribed coordinate's constraint
        s_driven = {d.name: mbs.AddSensor(SensorObject(objectNumber=d.obj,
                                                       outputVariableType=ovt.Force, **sens))
                    for d in driven}
        mbs.Assemble()
        # constrained and driven runs: the implicit solver's sample at t = 0 holds its
        # consistent initial accelerations (computeInitialAccelerations)
        acc0 = (self._initial_accelerations(exu, mbs, cfg, s_acc)
                if s_acc and not (closures or driven) else {})
        lam0 = self._consistent_start(exu, mbs, cfg, mechanism, driven) if driven else None
        clock = self._solve(exu, mbs, cfg, solver, bool(closures or driven), t_run, steps,
                            initial_accelerations=not driven)

        U = np.asarray(mbs.GetSensorStoredData(s_u))
        Ut = np.asarray(mbs.GetSensorStoredData(s_ut))
        t = U[:, 0]
        if len(t) != steps + 1 or abs(t[-1] - t_run) > 1e-9 * max(1.0, t_run):
            raise RuntimeError(f"exudyn sensors returned {len(t)} samples, expected {steps + 1}")
        u, ut = U[:, 1:], Ut[:, 1:]
        q, qd = geo.coordinates(u, ut)

        constraint_forces = {
            c.name: self._closure_force(c, np.asarray(mbs.GetSensorStoredData(s_closure[c.name])),
                                        geo, u)
            for c in closures}
        actuator_forces = {}
        for k, d in enumerate(driven):
            lam = np.asarray(mbs.GetSensorStoredData(s_driven[d.name]))[:, 1].copy()
            lam[0] = lam0[k]  # the solver records zero multipliers at t = 0
            actuator_forces[d.name] = self._actuator_force(d, lam)
        reactions: dict[str, np.ndarray] = {}
        if reaction_joints:
            acc = {b: np.asarray(mbs.GetSensorStoredData(s))[:, 1:3] for b, s in s_acc.items()}
            for b, a0 in acc0.items():  # the solver records zero accelerations at t = 0
                acc[b][0] = a0
            # Exudyn's connector force is the force on marker 0 (body_a)
            conn_force = {name: np.asarray(mbs.GetSensorStoredData(s))[:, 1:3]
                          for name, s in s_conn.items()}
            # Newton on each subtree: every element force from outside is taken out
            newton = {name: subtree_force(mechanism, name, t, acc) for name in reaction_joints}
            pairs = {**conn_force, **{c.name: constraint_forces[c.name] for c in closures
                                      if c.kind != "coupling"}}
            couplings = {c.name: constraint_forces[c.name] for c in closures
                         if c.kind == "coupling"}
            reactions = joint_reactions(mechanism, reaction_joints, newton, t, q, qd,
                                        pair_forces=pairs, coupling_forces=couplings)
        return Samples(q, qd, clock, reactions, constraint_forces, actuator_forces)

    def _bare_loop_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                        steps: int, dt: float, cfg: dict) -> BareLoop:
        """The system of `simulate` without its sensors, solved by the same solver."""
        solver = self._solver_for(mechanism, cfg)
        # SC owns mbs: it stays referenced until the solve returns
        q0, qd0 = driven_start(mechanism, q0, qd0)
        exu, mbs, SC, node, tree, geo, _ = self._build(mechanism, q0, qd0, cfg)
        closures = self._add_closures(exu, mbs, mechanism, node, tree, geo)
        driven = self._add_prescribed(mbs, mechanism, node, geo)
        mbs.Assemble()
        if driven:
            self._consistent_start(exu, mbs, cfg, mechanism, driven)
        clock = self._solve(exu, mbs, cfg, solver, bool(closures or driven), steps * dt,
                            steps, initial_accelerations=not driven)
        current = exu.ConfigurationType.Current
        u = np.asarray(mbs.systemData.GetODE2Coordinates(configuration=current))
        ut = np.asarray(mbs.systemData.GetODE2Coordinates_t(configuration=current))
        q, qd = geo.coordinates(u[None, :], ut[None, :])
        return BareLoop(clock.cpu, q[0], qd[0])

    def _solve(self, exu, mbs, cfg: dict, solver: str, constrained: bool, t_run: float,
               steps: int, initial_accelerations: bool = True) -> Stopwatch:
        """SolveDynamic over `steps` steps of the assembled system, timed.
        `initial_accelerations` False: the implicit solver starts from the accelerations
        already in the initial state instead of computing its own."""
        import exudyn.solver as exu_solver

        solver_type = getattr(exu.DynamicSolverType, solver)
        sim = self._simulation_settings(exu, cfg, t_run, steps)
        sim.timeIntegration.solverType = solver_type
        sim.timeIntegration.generalizedAlpha.computeInitialAccelerations = initial_accelerations
        if constrained:
            sim.timeIntegration.generalizedAlpha.spectralRadius = float(
                cfg["constrained_spectral_radius"])
        # Python user functions allocate on every call; Exudyn then prints a speed hint
        # after the run. The hint is expected here, so it is silenced for this call only.
        threshold = exu_solver.solverCheckMemoryAllocationsThreshold
        exu_solver.solverCheckMemoryAllocationsThreshold = float("inf")
        try:
            with Stopwatch() as clock:
                mbs.SolveDynamic(sim, solverType=solver_type)
            return clock
        finally:
            exu_solver.solverCheckMemoryAllocationsThreshold = threshold

    @staticmethod
    def _solver_for(mechanism: Mechanism, cfg: dict) -> str:
        """The solver this mechanism runs: 'constrained_solver' with closure constraints,
        'driven_solver' with prescribed motion, 'solver' otherwise. Both algebraic cases
        need an implicit solver: the explicit ones stop on closure constraints and
        silently ignore the offset of a prescribed coordinate."""
        key = ("constrained_solver" if mechanism.constraints
               else "driven_solver" if mechanism.prescribed else "solver")
        solver = str(cfg[key])
        if key != "solver" and solver not in _CONSTRAINT_SOLVERS:
            raise ValueError(
                f"exudyn {key} must be an implicit solver ({', '.join(_CONSTRAINT_SOLVERS)}); "
                f"got {solver!r}: Exudyn's explicit solvers "
                + ("stop on algebraic equations" if key == "constrained_solver" else
                   "ignore the offset function of a CoordinateConstraint, so the "
                   "prescribed coordinate would not move"))
        return solver

    @staticmethod
    def _closure_force(item: _ClosureItem, data: np.ndarray, geo: _Geometry,
                       u: np.ndarray) -> np.ndarray:
        """The engine's constraint force in the contract's terms (base.py point 6)."""
        if item.kind == "point":
            # the revolute 2-D joint's Force: the force on body_a (marker 0) from body_b
            return data[:, 1:3].copy()
        if item.kind == "line":
            # ForceLocal: force of the slot on the pin, in the pin marker's frame
            ang = geo.frame_angle(item.frame_body, u)
            c, s = np.cos(ang), np.sin(ang)
            fx, fy = data[:, 1], data[:, 2]
            return np.stack([c * fx - s * fy, s * fx + c * fy], axis=1)
        # coordinate constraint: Exudyn's multiplier enters as Phi_u^T lam, as in the
        # description (Phi identical), so the generalized force is -lam
        return -data[:, 1:2].copy()

    @staticmethod
    def _actuator_force(item: _DrivenItem, lam: np.ndarray) -> np.ndarray:
        """The actuator's generalized force on the description coordinate from the
        multiplier: Exudyn adds C_u^T lam = lam e_p to the engine equations, so the
        constraint pushes engine coordinate p with -lam, and q = scale u + shift maps it
        to -lam / scale on q (virtual work)."""
        return -lam / item.scale

    def _initial_accelerations(self, exu, mbs, cfg: dict, sensors: dict) -> dict[str, np.ndarray]:
        """Centre-of-mass accelerations at t = 0 from the engine's own mass matrix and
        right-hand side (the solvers store zero accelerations for the first sample)."""
        sim = self._simulation_settings(exu, cfg, 1.0, 1)
        sim.timeIntegration.solverType = exu.DynamicSolverType.RK44
        helper = exu.MainSolverExplicit()
        helper.InitializeSolver(mbs, sim)
        helper.ComputeMassMatrix(mbs)
        mass = np.asarray(helper.GetSystemMassMatrix())
        helper.ComputeODE2RHS(mbs)
        rhs = np.asarray(helper.GetSystemResidual())[:len(mass)]
        helper.FinalizeSolver(mbs, sim)
        a0 = np.linalg.solve(mass, rhs)
        mbs.systemData.SetODE2Coordinates_tt(a0.tolist(),
                                             configuration=exu.ConfigurationType.Current)
        return {b: np.asarray(mbs.GetSensorValues(s))[:2] for b, s in sensors.items()}

    # --- linearization ---------------------------------------------------------------------
    def linearize(self, mechanism: Mechanism, q_eq: np.ndarray,
                  settings: Mapping | None = None, dt: float = 1e-3) -> Linearization | None:
        cfg = self.resolve_settings(settings)
        support = self.support(mechanism)
        # a driven mechanism moves about a motion, not an equilibrium; Exudyn linearizes
        # about a static state only (ComputeLinearizedSystem)
        if not support.ok or mechanism.prescribed:
            return None
        q_eq = np.asarray(q_eq, dtype=float)
        if mechanism.constraints:
            return self._linearize_constrained(mechanism, q_eq, cfg)
        # the autonomous system: the excitation e(t) does not belong to the equilibrium
        exu, mbs, SC, node, tree, geo, _ = self._build(
            mechanism.without_time_loads(), q_eq, np.zeros_like(q_eq), cfg)
        mbs.Assemble()
        eps = float(cfg["linearization_relative_epsilon"])
        M, K, D = self._tree_mkd(exu, mbs, cfg)
        eig = quadratic_eigenvalues(M, D, K)
        how = ("two forward-difference Jacobians (eps, eps/2) Richardson-extrapolated"
               if cfg["linearization_richardson"] else "one forward-difference Jacobian")
        return Linearization(
            eigenvalues=eig[np.argsort(eig.imag)],
            method="exudyn mbs.ComputeLinearizedSystem (M exact; K, D from the kinematic "
                   f"tree's numerical Jacobian: {how}), first-order eigenproblem",
            extra={"coordinates": "engine relative joint values (eigenvalues are invariant)",
                   "relative_epsilon": eps},
        )


    def _tree_mkd(self, exu, mbs, cfg: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """M, K, D of the assembled tree from ``ComputeLinearizedSystem``; Exudyn
        differentiates forward (error O(eps)), so two steps (eps, eps/2) cancel that term
        when ``linearization_richardson`` is on."""
        def engine_mkd(relative_epsilon: float):
            sim = self._simulation_settings(exu, cfg, 1.0, 1)
            sim.staticSolver.newton.numericalDifferentiation.relativeEpsilon = relative_epsilon
            M, K, D = mbs.ComputeLinearizedSystem(simulationSettings=sim)[:3]
            return np.asarray(M), np.asarray(K), np.asarray(D)

        eps = float(cfg["linearization_relative_epsilon"])
        M, K, D = engine_mkd(eps)
        if cfg["linearization_richardson"]:
            _, K2, D2 = engine_mkd(eps / 2)
            K, D = 2 * K2 - K, 2 * D2 - D
        return M, K, D

    def _linearize_constrained(self, mechanism: Mechanism, q_eq: np.ndarray,
                               cfg: dict) -> Linearization:
        """Linearization on the constraint manifold from the engine's own matrices: M, K,
        D of the tree (``ComputeLinearizedSystem``, Richardson as above), the constraint
        Jacobian C (n x m, Exudyn's ``ComputeJacobianAE``), the static multipliers from
        the engine's forces (C lam = f at the equilibrium) and the constraint stiffness
        d(C lam)/du by central differences of Exudyn's C; then the null-space projection
        Exudyn's ``ComputeODE2Eigenvalues`` uses. (``ComputeODE2Eigenvalues`` itself has no
        d(C lam)/du term: the loaded slot of the eccentric cam came out 2.7 % low.)"""
        mech = mechanism.without_time_loads()
        exu, mbs, SC, node, tree, geo, _ = self._build(mech, q_eq, np.zeros_like(q_eq), cfg)
        self._add_closures(exu, mbs, mech, node, tree, geo)
        mbs.Assemble()
        n = geo.n
        u_eq = np.linalg.solve(geo.cmap.T, q_eq - geo.cmap.c)
        eps = float(cfg["linearization_relative_epsilon"])
        M, K, D = self._tree_mkd(exu, mbs, cfg)

        def forces_and_jacobian(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            """Exudyn's ODE2 right-hand side f and constraint Jacobian C (n x m) at u."""
            mbs.systemData.SetODE2Coordinates(u.tolist(),
                                              configuration=exu.ConfigurationType.Initial)
            sim = self._simulation_settings(exu, cfg, 1.0, 1)
            helper = exu.MainSolverStatic()
            helper.InitializeSolver(mbs, sim)
            helper.ComputeODE2RHS(mbs)
            f = np.asarray(helper.GetSystemResidual())[:n]
            # the ODE2 Jacobian call sizes and clears the system Jacobian, which
            # ComputeJacobianAE only adds into (ComputeLinearizedSystem does the same)
            helper.ComputeJacobianODE2RHS(mbs, scalarFactor_ODE2=-1, scalarFactor_ODE2_t=0,
                                          scalarFactor_ODE1=0)
            helper.ComputeJacobianAE(mbs, scalarFactor_ODE2=1.0, scalarFactor_ODE2_t=0.0,
                                     scalarFactor_ODE1=0.0, velocityLevel=False)
            C = np.asarray(helper.GetSystemJacobian())[:n, n:]
            helper.FinalizeSolver(mbs, sim)
            return f, C

        f, C = forces_and_jacobian(u_eq)
        lam = np.linalg.lstsq(C, f, rcond=None)[0]
        residual = float(np.max(np.abs(C @ lam - f), initial=0.0))
        step = float(cfg["linearization_constraint_step"])
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
        # a rigid mode (belt pulleys) has a structurally zero eigenvalue; the projection
        # leaves ~1e-15 |s| of round-off in it, which would read as a tiny frequency
        tiny = 1e-12 * max(float(np.max(np.abs(eig), initial=0.0)), 1e-300)
        eig = np.where(np.abs(eig.real) <= tiny, 0.0, eig.real) + 1j * np.where(
            np.abs(eig.imag) <= tiny, 0.0, eig.imag)
        how = ("Richardson-extrapolated forward differences"
               if cfg["linearization_richardson"] else "one forward difference")
        return Linearization(
            eigenvalues=eig[np.argsort(eig.imag)],
            method="exudyn tree M, K, D (mbs.ComputeLinearizedSystem, K and D by " + how
                   + "), constraint Jacobian C (MainSolverStatic.ComputeJacobianAE), static "
                   "multipliers from C lam = f, constraint stiffness d(C lam)/du by central "
                   "differences of C; null-space (SVD) projection as in "
                   "ComputeODE2Eigenvalues, first-order eigenproblem",
            extra={"coordinates": "null space of the engine's constraint Jacobian "
                                  "(eigenvalues are invariant)",
                   "relative_epsilon": eps, "constraint_step": step,
                   "multipliers": lam.tolist(), "equilibrium_residual": residual,
                   "constraint_rank": rank},
        )


    # --- flexible elements (contract point 12) ----------------------------------------------
    BEAM_ELEMENTS = {
        ANCF_CABLE: BeamElement(
            Expression(EXACT, "ObjectANCFCable2D: the Euler-Bernoulli beam element (cubic "
                              "Hermite position and slope per node, consistent mass); its "
                              "frequencies converge to the beam's from above"),
            order=4, limit="Euler-Bernoulli"),
        GEOMETRICALLY_EXACT: BeamElement(
            Expression(SOFT, "ObjectBeamGeometricallyExact2D: a shear-deformable (Reissner) "
                             "element with linear interpolation; it converges to a "
                             "Timoshenko beam, here of shear stiffness GA = "
                             f"{_GE_SHEAR_FACTOR:g} EI/l^2 and rotary inertia "
                             f"{_GE_ROTARY_FACTOR:g} rho l^2 per length, whose first "
                             "frequencies lie below Euler-Bernoulli's by about "
                             "(n pi)^2 EI / (2 GA l^2) = 5e-6 n^2 (shear) plus as much "
                             "(rotary inertia): far below the element's own error up to "
                             "N = 32"),
            order=2, limit="Timoshenko beam of large shear stiffness and small rotary inertia "
                           "(Euler-Bernoulli as GA -> infinity, rotary inertia -> 0)"),
    }

    def beam_frequencies(self, beam: Beam, kind: str, elements: int, count: int = 3,
                         settings: Mapping | None = None) -> BeamModes:
        """N elements of `kind` along x (`exudyn.beams.GenerateBeamElementsAlongLine`), the
        point mass an ``ObjectMassPoint2D`` on the node at x = a, and the frequencies from
        ``mbs.ComputeODE2Eigenvalues`` (dense, omega^2) with the supports as constrained
        coordinates: y = 0 at both end nodes. The axial coordinates (every node's x, and
        the ANCF slope's x component) are held as well: about the straight beam they
        decouple from bending, so this only removes the axial modes from the list and the
        round-off of the stiff axial terms (measured: ANCF bending frequencies equal with and
        without them to 1e-11 at EA = 1e4 EI/l^2, to 9e-9 at 1e8 EI/l^2; the geometrically
        exact element's to 3e-6, its eigensolver's round-off, at EA = 1e2..1e6 EI/l^2).
        No setting applies (no time integration)."""
        self.check_beam_request(beam, kind, elements, settings, "the eigenvalue route")
        import exudyn as exu
        import exudyn.beams
        from exudyn.itemInterface import (ObjectANCFCable2D, ObjectBeamGeometricallyExact2D,
                                          ObjectMassPoint2D)

        l, EI, rho = beam.length, beam.EI, beam.rho
        # axial stiffness: any positive value (held coordinates); a slender bar's order
        EA = _AXIAL_FACTOR * EI / l**2
        if kind == ANCF_CABLE:
            template = ObjectANCFCable2D(massPerLength=rho, bendingStiffness=EI,
                                         axialStiffness=EA)
        else:
            template = ObjectBeamGeometricallyExact2D(
                massPerLength=rho, crossSectionInertia=_GE_ROTARY_FACTOR * rho * l**2,
                bendingStiffness=EI, axialStiffness=EA,
                shearStiffness=_GE_SHEAR_FACTOR * EI / l**2)
        SC = exu.SystemContainer()
        mbs = SC.AddSystem()
        built = exudyn.beams.GenerateBeamElementsAlongLine(mbs, [0.0, 0.0, 0.0], [l, 0.0, 0.0],
                                                            elements, template)
        nodes = list(built["nodes"])
        if beam.point_mass > 0:
            mbs.AddObject(ObjectMassPoint2D(mass=beam.point_mass,
                                            nodeNumber=nodes[beam.node_of_point_mass(elements)]))
        mbs.Assemble()
        first = [mbs.GetNodeODE2Index(n) for n in nodes]
        # node coordinates: ANCF (x, y, x', y'), geometrically exact (x, y, theta)
        axial = first + ([i + 2 for i in first] if kind == ANCF_CABLE else [])
        held = sorted(set(axial + [first[0] + 1, first[-1] + 1]))
        t0 = time.process_time()
        omega2, _ = mbs.ComputeODE2Eigenvalues(constrainedCoordinates=held)
        cpu = time.process_time() - t0
        omega2 = np.sort(np.asarray(omega2, dtype=float))
        count = min(count, len(omega2))
        # a dense symmetric eigensolver's round-off in omega_k^2 is about eps omega_max^2,
        # relative eps omega_max^2 / omega_k^2 (taken for omega_k as well, conservatively)
        roundoff = [float(np.finfo(float).eps * omega2[-1] / w2) for w2 in omega2[:count]]
        return BeamModes(
            [float(math.sqrt(w2) / (2 * math.pi)) for w2 in omega2[:count]],
            "exudyn mbs.ComputeODE2Eigenvalues (dense, constrained coordinates: supports "
            "and axial coordinates held)",
            roundoff,
            {"coordinates": len(omega2),
             "axial_stiffness": EA, "cpu_time": cpu,
             **({"shear_stiffness": _GE_SHEAR_FACTOR * EI / l**2,
                 "rotary_inertia_per_length": _GE_ROTARY_FACTOR * rho * l**2}
                if kind == GEOMETRICALLY_EXACT else {})})


BACKEND = ExudynBackend()
