"""A spring with distributed mass carrying a block (monograph §6.2, Fig. 18, eq. 69-70),
as a chain of N lumped masses.

The monograph's system: a linear spring of stiffness k and unstretched length l, with
mass rho per unit unstretched length, fixed at one end and carrying a block m at the
other. Rayleigh's method with the static shape of an end load, z(x) = (x / l) z_a
(eq. 69), reduces the spring's inertia to a third of its mass: w = sqrt(k / (m + rho l/3))
(eq. 70). The exact continuum (a rod with an end mass) has w = beta sqrt(k / (rho l)) with
beta tan(beta) = rho l / m (`analytic/continuum.py`, model "spring_with_end_mass").

Fig. 18 is not in the text. The monograph's mass-spring systems (Fig. 4) stand vertically,
so the spring hangs here from the ceiling with the block at its lower end. Everything is
linear, so the weight only stretches the chain statically: the frequencies are those
about that static equilibrium (the operating point), and eq. 70's energies are measured
from it.

The discretized model (N elements, N a structural parameter: `--param N=16`)::

       ////////  ceiling (world origin)
          |
          /  segment 1: stiffness N k, relaxed length l/N   coordinate u1 (its stretch)
          o  coil1, mass rho l / N
          /  segment 2                                       u2
          o  coil2, mass rho l / N
          :
          /  segment N                                       uN
        [ m ] block: m + rho l / (2 N)

Lumping: the spring is cut into N equal segments, each a massless spring of stiffness N k
(N springs in series make k) carrying its mass rho l / N half at each end node. The half
at the ceiling is lost to the ground; every interior node carries two halves, rho l / N;
the block's node carries m plus one half, m + rho l / (2 N). This is the lumped-mass
finite-element model of the rod (linear elements), whose frequencies converge to the
continuum's as N^-2 from below (the interior nodes' dispersion and the end node's half
segment are both second-order approximations; `analytic/continuum.py`,
`lumped_spring_error_coefficients`, derives the leading constant).

Coordinates: node i slides on node i-1 along the downward vertical (a prismatic chain),
its coordinate u_i the stretch of segment i from its relaxed length, so that each spring
acts on one coordinate (MuJoCo's joint stiffness, Exudyn's coordinate spring, a Pymunk
damped spring between neighbours). Static equilibrium: segment i carries the weight of
everything below it, u_i = g (m + rho l (N - i + 1/2) / N) / (N k); the block then sits
g (m + rho l / 2) / k below its relaxed position, as for the continuum.

No printed formula of §6.2 describes the chain: eq. 69-70 (Rayleigh) and the exact
continuum are compared with it by `analyze` (keys `continuum`, `rayleigh`) and by the
convergence study in N, not as errata.
"""
import sympy as sp

from . import Expectation, System
from .model import (Body, Circle, CoordinateForce, Mechanism, Parameter, Prismatic, Rectangle,
                    Scenario, Segment, coordinate_spring_damper)

PARAMETERS = (
    Parameter("k", 100.0, "N/m", "stiffness of the whole spring", "Fig. 18"),
    Parameter("l", 1.0, "m", "unstretched length of the spring", "Fig. 18"),
    Parameter("rho", 0.3, "kg/m", "mass of the spring per unit unstretched length (rho l = "
              "0.3 kg)", "Fig. 18"),
    Parameter("m", 1.0, "kg", "mass of the block at the spring's end", "project default"),
    Parameter("N", 8, "1", "number of elements of the lumped chain (structural: it sets the "
              "coordinates; 8 keeps the checks fast, the convergence study goes to 32)",
              "chosen here", domain="count"),
    Parameter("z0", 0.01, "m", "extra pull of the block beyond the static equilibrium in the "
              "'pulled' scenario (eq. 69's shape along the spring)", "chosen here",
              domain="real"),
)

#: size of the drawn block (m) and radius of the drawn coil nodes (m): drawing only
BLOCK = 0.1
NODE = 0.015


def node_names(N: int) -> list[str]:
    return [f"coil{i}" for i in range(1, N)] + ["block"]


def build(P) -> Mechanism:
    N = P.N
    segment = P.l / N
    bodies, joints, forces = [], [], []
    parent = "world"
    for i, name in enumerate(node_names(N), start=1):
        if name == "block":
            mass = P.m + P.rho * segment / 2
            shapes = (Rectangle((0, 0), BLOCK, BLOCK), Segment((0, 0), (0, segment), 0.005))
            inertia = mass * (BLOCK**2 + BLOCK**2) / 12
        else:
            mass = P.rho * segment
            shapes = (Circle((0, 0), NODE), Segment((0, 0), (0, segment), 0.005))
            inertia = mass * NODE**2 / 2
        bodies.append(Body(name, mass, inertia, shapes))
        # the node hangs a relaxed segment below its parent; u_i stretches it downward
        joints.append(Prismatic(f"segment{i}", parent, name, f"u{i}", axis=(0, -1),
                                parent_anchor=(0, -segment)))
        forces.append(CoordinateForce(f"spring{i}", f"u{i}",
                                      **coordinate_spring_damper(N * P.k, 0)))
        parent = name
    return Mechanism(bodies=tuple(bodies), joints=tuple(joints), forces=tuple(forces))


def static_stretch(P, i: int) -> sp.Expr:
    """Segment i's stretch at rest: the weight below it over its stiffness N k."""
    return P.g * (P.m + P.rho * P.l * (P.N - i + sp.Rational(1, 2)) / P.N) / (P.N * P.k)


def operating_point(P) -> dict[str, sp.Expr]:
    return {f"u{i}": static_stretch(P, i) for i in range(1, P.N + 1)}


def pulled(P) -> dict[str, sp.Expr]:
    """The static equilibrium plus the end load's static shape (eq. 69): every segment
    stretched by z0 / N more, the block z0 below its rest position."""
    return {f"u{i}": static_stretch(P, i) + P.z0 / P.N for i in range(1, P.N + 1)}


def _scenarios() -> tuple[Scenario, ...]:
    return (
        Scenario("pulled", pulled, t_end=2.0,
                 description="from rest, the block z0 = 10 mm below the static equilibrium "
                             "with the coils in eq. 69's linear shape: mostly the first "
                             "mode"),
        Scenario("relaxed", lambda P: {}, t_end=2.0,
                 description="from rest with every segment relaxed: the block and the "
                             "coils fall under their weight and swing about the static "
                             "stretch (every mode)"),
    )


#: measured with `mbfidelity compare massive_spring --sim ENGINE --param N=...` at the
#: default k, rho l and dt = 1e-3 s. The gates are mode by mode (comparisons/tolerances.py):
#: the chain's fastest mode, about 2 N sqrt(k / (rho l)) (211.7 rad/s at N = 6, 508.0 at
#: N = 14), leaves a scheme's range of w h first at those N, and then only that mode's
#: share of a release counts beyond its bound.
#: the smallest N where each release's RK4 bound exceeds 0.1 (measured, see the reason)
PULLED_FROM, RELAXED_FROM = 23, 26
RK4_TRAJECTORY_BOUND_FROM_MANY_FAST_MODES = (
    "The trajectory gate is mode by mode: each of the chain's modes contributes its "
    "amplitude times its own RK4 bound, and a mode beyond the range of w h where that "
    "bound holds twice its amplitude. As N grows, more modes leave that range at the "
    "default step and their small shares add up: the bound exceeds the ceiling a "
    "trajectory gate can tell apart (comparisons/tolerances.py), where a pass would mean "
    "nothing.")

RK4_FIT_STEP_TOO_COARSE = (
    "The chain's fastest modes (about 2 N sqrt(k / (rho l))) lie beyond the range of w h "
    "where RK4's bound holds at the default step, so their fits are unresolved; the slower "
    "modes and the engines' linearizations are judged.")

SYSTEM = System(
    id="massive_spring",
    title="Spring with distributed mass and an end block, as a chain of N lumped masses",
    source="monograph §6.2, Fig. 18, eq. 69-70",
    parameters=PARAMETERS,
    build=build,
    operating_point=operating_point,
    scenarios=_scenarios(),
    continuum="spring_with_end_mass",
    expectations=(
        *(Expectation(engine, f"{scenario}.*", "unresolved",
                      RK4_TRAJECTORY_BOUND_FROM_MANY_FAST_MODES,
                      when=f"N >= {start}")
          for engine in ("mujoco", "exudyn")
          for scenario, start in (("pulled", PULLED_FROM), ("relaxed", RELAXED_FROM))),
        *(Expectation(engine, f"{kind}.fit_mode*", "unresolved", RK4_FIT_STEP_TOO_COARSE,
                      when="N >= 14")
          for engine in ("mujoco", "exudyn") for kind in ("frequency", "damping")),
    ),
)
