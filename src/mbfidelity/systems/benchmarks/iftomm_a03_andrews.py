"""IFToMM benchmark A03: Andrews' squeezing mechanism, seven bodies in closed loops, one
degree of freedom, driven by a constant torque against a stiff spring.

Specification: Hairer and Wanner, Solving Ordinary Differential Equations II (§VII.7,
after Schiehlen's collection of multibody benchmarks), stated as the problem "andrews"
of the Test Set for IVP Solvers (F. Mazzia, C. Magherini, University of Bari; andrews.f:
the parameters, the consistent initial state and a reference solution at t = 0.03 s to
16 digits, computed with PSIDE at tolerances 1e-14), and as problem A03 of the IFToMM
benchmark library (González, Dopico, Lugrís, Cuadrado, Multibody System Dynamics 16,
2006; restated with body frames in RehabEngGroup/MBSbenchmarksInOpenSim,
help/benchmarks/A03_AndrewsMechanism.rst). No gravity (g = 0, a parameter like any).

Geometry (fixed points O = (0, 0), A = (xa, ya), B = (xb, yb), C = (xc, yc); the angles
of the test set, counter-clockwise)::

    crank OF (1) turns about O by beta; rod FE (2) on the crank at F, relative angle Theta
    triangle BDE (3) turns about B by gamma; the spring (c0, free length l0) joins D to C
    AG (5) turns about A by delta; EG (4) on AG at G, relative angle Phi
    AH (7) turns about A by epsilon; HE (6) on AH at H, relative angle Omega
    E: the rod's end, the triangle's, EG's and HE's: three closures of two equations

    F = O + rr u(beta)            E = F - d u(beta + Theta)         u(a) = (cos a, sin a)
    E = B + ss v(gamma)           D = B + sd u(gamma) + sc v(gamma)  v(a) = (sin a, -cos a)
    G = A + zt u(delta)           E = G + e v(delta + Phi)
    H = A + u v(epsilon)          E = H + zf u(epsilon + Omega)

Body frames (origin at the centre of mass, convention 2; x along u of the body's angle):
the centres of mass are those of the OpenSim port's tables: crank (ra, 0) from O, rod
(-da, 0) from F, triangle (sb, -sa) from B (B, D, E at (0, 0), (sd, -sc), (0, -ss)), AG
(ta, tb) from A (G at (zt, 0)), EG (0, ea) from E towards G, AH (-ub, -ua) from A (H at
(0, -u)), HE (-fa, 0) from E. The test set's mass matrix depends on the distances alone
(m3 (sa^2 + sb^2), m7 (ua^2 + ub^2), ...), so with g = 0 the directions do not enter;
under gravity they follow the port's figure.

Coordinates in joint order (each joint after its parent): beta, Theta, gamma, delta, Phi,
epsilon, Omega; the independent one is beta (the crank: regular over the motion).
Parameters: the masses, inertias, drive torque, spring constant and free length, and g;
the lengths and fixed points are the published geometry's (a length alone changed would
leave the loops unable to close at the published initial state).
"""

from .. import (BenchmarkError, Expectation, OrderCap, Published, System,
                coordinate_symbols)
from ..model import (COORD, Body, CoordinateForce, Mechanism, Parameter, PointOnPoint,
                     PointToPoint, Revolute, Scenario, Segment, linear_spring_damper)

SOURCE = ("Test Set for IVP Solvers (Mazzia, Magherini, University of Bari), problem "
          "andrews, reference solution at t = 0.03 s (PSIDE, tolerances 1e-14)")

# the published geometry (m): fixed points and body dimensions (test set, andrews.f)
XA, YA, XB, YB, XC, YC = -0.06934, -0.00227, -0.03635, 0.03273, 0.014, 0.072
D_, DA, E_, EA, RR, RA = 28e-3, 115e-4, 2e-2, 1421e-5, 7e-3, 92e-5
SS, SA, SB, SC, SD = 35e-3, 1874e-5, 1043e-5, 18e-3, 2e-2
TA, TB, U_, UA, UB = 2308e-5, 916e-5, 4e-2, 1228e-5, 449e-5
ZF, ZT, FA = 2e-2, 4e-2, 1421e-5

_BODIES = (  # name, mass, central inertia (test set)
    ("1", 0.04325, 2.194e-6), ("2", 0.00365, 4.410e-7), ("3", 0.02373, 5.255e-6),
    ("4", 0.00706, 5.667e-7), ("5", 0.07050, 1.169e-5), ("6", 0.00706, 5.667e-7),
    ("7", 0.05498, 1.912e-5),
)
_NAMES = {"1": "crank OF", "2": "rod FE", "3": "triangle BDE", "4": "bar EG",
          "5": "bar AG", "6": "bar HE", "7": "bar AH"}

PARAMETERS = tuple(
    p for name, m, i in _BODIES for p in (
        Parameter(f"m{name}", m, "kg", f"mass of the {_NAMES[name]} (body {name})",
                  "Test Set andrews; IFToMM A03"),
        Parameter(f"I{name}", i, "kg m^2", f"central moment of inertia of the "
                  f"{_NAMES[name]} (body {name})", "Test Set andrews; IFToMM A03"),
    )
) + (
    Parameter("mom", 0.033, "N m", "constant drive torque on the crank", "Test Set andrews",
              domain="real"),
    Parameter("c0", 4530.0, "N/m", "spring constant (D to C)", "Test Set andrews"),
    Parameter("l0", 0.07785, "m", "free length of the spring", "Test Set andrews"),
    Parameter("g", 0.0, "m/s^2", "gravitational acceleration along -y (the problem has "
              "none)", "Test Set andrews", domain="real"),
)

#: the test set's consistent initial state (rad), at rest
INITIAL = {"beta": -0.0617138900142764496358948458001, "Theta": 0.0,
           "gamma": 0.455279819163070380255912382449,
           "Phi": 0.222668390165885884674473185609,
           "delta": 0.487364979543842550225598953530,
           "Omega": -0.222668390165885884674473185609,
           "epsilon": 1.23054744454982119249735015568}

#: the test set's solution at t = 0.03 s: angles (rad) and angular velocities (rad/s)
SOLUTION = {"beta": (0.1581077119629904e+2, 0.1139920302151208e+4),
            "Theta": (-0.1575637105984298e+2, -0.1424379294994111e+4),
            "gamma": (0.4082224013073101e-1, 0.1103291221937134e+2),
            "Phi": (-0.5347301163226948e+0, 0.1929337464421385e+2),
            "delta": (0.5244099658805304e+0, 0.5735699284790808e+0),
            "Omega": (0.5347301163226948e+0, -0.1929337464421385e+2),
            "epsilon": (0.1048080741042263e+1, 0.3231791658026955e+0)}


def build(P) -> Mechanism:
    def body(name, shapes):
        return Body(name, getattr(P, f"m{name}"), getattr(P, f"I{name}"), shapes)

    e_rod = (DA - D_, 0)
    bodies = (
        body("1", (Segment((-RA, 0), (RR - RA, 0)),)),
        body("2", (Segment((DA, 0), e_rod),)),
        body("3", (Segment((-SB, SA), (-SB, SA - SS)), Segment((-SB, SA), (SD - SB, SA - SC)),
                   Segment((SD - SB, SA - SC), (-SB, SA - SS)))),
        body("5", (Segment((-TA, -TB), (ZT - TA, -TB)),)),
        body("4", (Segment((0, E_ - EA), (0, -EA)),)),
        body("7", (Segment((UB, UA), (UB, UA - U_)),)),
        body("6", (Segment((-(ZF - FA), 0), (FA, 0)),)),
    )
    joints = (
        Revolute("O", "world", "1", "beta", child_anchor=(-RA, 0)),
        Revolute("F", "1", "2", "Theta", parent_anchor=(RR - RA, 0), child_anchor=(DA, 0)),
        Revolute("B", "world", "3", "gamma", parent_anchor=(XB, YB), child_anchor=(-SB, SA)),
        Revolute("A5", "world", "5", "delta", parent_anchor=(XA, YA), child_anchor=(-TA, -TB)),
        Revolute("G", "5", "4", "Phi", parent_anchor=(ZT - TA, -TB), child_anchor=(0, E_ - EA)),
        Revolute("A7", "world", "7", "epsilon", parent_anchor=(XA, YA), child_anchor=(UB, UA)),
        Revolute("H", "7", "6", "Omega", parent_anchor=(UB, UA - U_),
                 child_anchor=(-(ZF - FA), 0)),
    )
    return Mechanism(
        bodies=bodies,
        joints=joints,
        forces=(
            CoordinateForce("drive", "beta", P.mom, potential=-P.mom * COORD),
            PointToPoint("spring", "3", (SD - SB, SA - SC), "world", (XC, YC),
                         **linear_spring_damper(P.c0, P.l0)),
        ),
        constraints=(
            PointOnPoint("E_triangle", "2", e_rod, "3", (-SB, SA - SS)),
            PointOnPoint("E_EG", "2", e_rod, "4", (0, -EA)),
            PointOnPoint("E_HE", "2", e_rod, "6", (FA, 0)),
        ),
        independent=("beta",),
    )


#: how the test set obtained its solution (why it may differ from the reference beyond
#: the reference's own error estimate)
NOTE = ("a numerical solution of the index-3 formulation (PSIDE, rtol = atol = 1e-14, "
        "Cray C90 double precision), not a closed form: its own error may exceed the "
        "reference's estimate; the reference's value is stable under tighter tolerances")


def published(P):
    out = []
    for name, (angle, rate) in SOLUTION.items():
        q, qd, _ = coordinate_symbols(name)
        out.append(Published(name, 0.03, angle, SOURCE, expression=q, note=NOTE))
        out.append(Published(f"{name}_dot", 0.03, rate, SOURCE, expression=qd, note=NOTE))
    return tuple(out)


#: why no gate can judge PyBullet's and Drake's published run at the default step (1 ms)
_UNRESOLVED = (
    "In the published run the crank turns more than twice within a few dozen steps of "
    "the default: the first-order engine's own error bound there, from its refinement, "
    "exceeds what the metric can tell apart, and the bound on its limit is predicted to "
    "stay above that down to the step budget, so the metric is measured and shown; the "
    "engines are judged on this run at the steps of the convergence study")

#: why MuJoCo's solution converges at second order here (comparisons/tolerances.py, "A
#: declared order cap")
_SOFT_CLOSURE = (
    "the three closures at E are MuJoCo equality constraints, which are soft: a "
    "spring-damper towards the constraint whose time constant follows the step, so the "
    "solved dynamics differ from the rigid ones by a violation of second order in the "
    "step, beside RK4's fourth-order error")

#: why MuJoCo's motion is judged although its backend expects a soft closure to fail
_SOFT_MOTION_JUDGED = (
    "MuJoCo's soft closures keep the motion's error of second order in the step (the "
    "declared order cap): its own refinement at that order bounds it, and the motion and "
    "energy are judged against that bound, which a limit other than the rigid motion fails")

#: why PyBullet's forces in two of the closures at E do not converge
_CORRECTED_CLOSURE_FORCE = (
    "PyBullet's closure force is the impulse of its velocity-level solve, which also "
    "removes the position error the previous step left (erp Phi / dt): a violation of "
    "second order in the step over the step squared, a part that does not shrink with the "
    "step; the rod's end E carries three closures, and this share of it does not converge "
    "to the rigid multiplier")

#: why Drake's motion is judged although its backend expects compliant closures to fail
_COMPLIANT_MOTION_JUDGED = (
    "Drake's compliant closures follow the step, so the motion's error stays of the first "
    "order its discrete plant declares: the refinement at that order judges the releases' "
    "motion and energy, which a limit other than the rigid motion fails")

#: why MuJoCo's closure forces do not converge to the rigid multipliers
_SOFT_CONSTRAINT_FORCE = (
    "MuJoCo's closure force is its soft constraint's spring-damper force, a stiffness "
    "that grows as the step falls times a violation that shrinks as fast: it converges to "
    "a regularised value set by the constraint's impedance, not to the rigid Lagrange "
    "multiplier, so its difference from the reference does not shrink with the step")

#: the error as the test set measures a solver's accuracy: at the end of the run
#: (t = 0.03 s, where it publishes the solution), on the seven angles; here the largest
#: absolute error among them
ERROR = BenchmarkError(
    tuple(SOLUTION), "end", "rad", SOURCE,
    "largest |angle - angle_ref| of the seven angles at the end of the run")

SYSTEM = System(
    id="iftomm_a03_andrews",
    title="IFToMM A03: Andrews' squeezing mechanism",
    source="IFToMM benchmark A03; Hairer & Wanner II §VII.7; Test Set for IVP Solvers, andrews",
    parameters=PARAMETERS,
    build=build,
    # the stable equilibrium on the published state's assembly branch: the spring holds
    # the drive torque (the crank turned back about 3 rad from the published start)
    operating_point=lambda P: {"beta": -3.0, "Theta": 3.04, "gamma": 0.041, "delta": 0.524,
                               "Phi": -0.534, "epsilon": 1.048, "Omega": 0.534},
    scenarios=(
        Scenario("published", dict(INITIAL), t_end=0.03, checks=("trajectory",),
                 description="the test set's consistent initial state at rest, 0.03 s"),
    ),
    published=published,
    benchmark_error=ERROR,
    expectations=(  # the first match declares a metric
        Expectation("exudyn", "convergence.order", "xfail",
                    "Exudyn's implicit scheme does not converge its Newton iteration at the "
                    "study's coarsest step, where the crank turns about a radian per step: "
                    "the study stops there"),
        Expectation("mujoco", "convergence.order", "xfail",
                    "MuJoCo's equality constraints are soft, with a reference time constant "
                    "that follows the step: their error falls as dt^2 beside RK4's dt^4, "
                    "and over the study's steps the mix gives an order between the two"),
        *(Expectation(engine, "convergence.order", "xfail",
                      "the study's steps for this short, fast run are few per turn of the "
                      "crank and lie outside the first-order scheme's asymptotic range: the "
                      "error falls faster than first order over them")
          for engine in ("pybullet", "pymunk", "drake")),
        Expectation("exudyn", "published.completed", "xfail",
                    "Exudyn's implicit scheme solves each step by Newton's method, which "
                    "does not converge when the crank turns about a radian within one "
                    "step: the solver stops (a step well below a millisecond runs)"),
        Expectation("mujoco", "*.constraint_*", "xfail", _SOFT_CONSTRAINT_FORCE),
        Expectation("mujoco", "*", "judged", _SOFT_MOTION_JUDGED),
        *(Expectation("pybullet", f"*.constraint_{closure}", "xfail", _CORRECTED_CLOSURE_FORCE)
          for closure in ("E_EG", "E_HE")),
        # Pymunk's and Exudyn's refinements reach their asymptotic range within the step
        # budget and judge every metric, MuJoCo's at its declared order; PyBullet's and
        # Drake's do on the releases, not on the published run
        Expectation("pybullet", "published.trajectory_rms", "unresolved", _UNRESOLVED),
        Expectation("drake", "published.trajectory_*", "unresolved", _UNRESOLVED),
        Expectation("drake", "*.constraint_*", "xfail",
                    "Drake's discrete plant holds the closures with compliant constraints "
                    "and does not report their forces: there is nothing to compare"),
        Expectation("drake", "*", "judged", _COMPLIANT_MOTION_JUDGED),
    ),
    order_caps=(OrderCap("mujoco", 2, _SOFT_CLOSURE),),
    # releases near the other stable equilibria last as long as the published run
    near_equilibrium_t_end=0.03,
)
