"""IFToMM benchmark A05: the stiff flyball governor, Watt's governor whose two coupler
rods are replaced by stiff spring-dampers.

Specification (problem A05 of the benchmark library of the Laboratorio de Ingeniería
Mecánica, University of A Coruña, lim.ii.udc.es/mbsbenchmark, dist/A05/
A05_specification.xml; González, Dopico, Lugrís, Cuadrado, Multibody System Dynamics
16:179-190, 2006; the geometry below is pinned from the OpenSim port
RehabEngGroup/MBSbenchmarksInOpenSim, help/benchmarks/A05_FlyballGovernor.rst and
src/A05-FlyballGovernor/createModel.cpp, which states every body frame and joint): a
shaft and two rods, each a prism of 1 m by 0.01 m by 0.01 m, a slider that is a cube of
0.1 m, all of density 3000 kg/m^3; a point mass of 5 kg at the far end of each rod; each
rod's midpoint tied to the slider by a spring-damper of stiffness 8e5 N/m, damping
4e4 N s/m and free length 0.5 m; gravity 9.81 m/s^2 along the shaft, downwards. At the
start the slider is at s = 0.5 m, the rods 30 degrees below the horizontal, everything
at rest relative to the shaft, and the shaft turns at 2 pi rad/s; 10 s. The published
quantity is the slider's coordinate s(t).

Geometry (world y up, along the shaft; the figure's plane is x-y at the start)::

          H2 o-------o H1          hinges at height L, at -d and +d from the axis
            /    |    \\
       m   / M2  |  M1 \\   m      rods of length L, point masses m at their far ends
          /  \\   |   /  \\          spring-dampers from the midpoints M to the slider's
              A2[ S ]A1            points A at -d and +d from the axis
                 |
                 |  shaft, hinged to the ground at its base (height 0)

Coordinates: psi, the shaft's angle about the vertical (its hinge is free: the port
gives the shaft's 2 pi rad/s as the initial speed of an unactuated hinge, so the speed
changes as the balls rise); s, the slider's height above the shaft's base (a slide along
the shaft, turning with it); phi1, phi2, the rods' angles about their hinges' axes (z of
the shaft), from the downward vertical, phi1 counter-clockwise (rod 1 swings out to +x),
phi2 clockwise as seen from +z (rod 2 swings out to -x, so phi2 = -phi1 in the symmetric
motion). The benchmark's 30 degrees below the horizontal is phi1 = -phi2 = 60 degrees.
At the defaults the initial state makes each spring exactly its free length (the hinge,
the rod's midpoint and the slider's point form an equilateral triangle of side 0.5 m),
so the motion starts from unstretched couplers, as in the port.

Bodies (model convention 2, frames at the centres of mass): the shaft (rho L b^2, a prism
along y), the slider (rho a^3, a cube), and each rod with its point mass as one rigid
body: mass m_r + m with m_r = rho L b^2, centre of mass at l_c = (m_r L/2 + m L)/(m_r + m)
from the hinge, central moments m_r b^2/6 about the rod and m_r (L^2 + b^2)/12 +
m_r (L/2 - l_c)^2 + m (L - l_c)^2 across it (the point mass has no central inertia).

Stiffness. Each coupler is a spring of 8e5 N/m with a damper of 4e4 N s/m, on bodies of a
few kilograms: the damping rate c/m is of the order of 1e4 1/s while the governor swings
at a few rad/s. The reference is therefore integrated with an implicit method (`stiff`,
analytic/reference.py); an explicit engine needs steps well below 2 m/c, and the
comparisons run this row at its own step (`STEP`, `System.step`) instead of the
project's default.

Engines. MuJoCo builds it natively (hinges, a slide joint, and a spatial tendon with its
own stiffness, free length and damping for each coupler), and so does Exudyn (a
kinematic tree of RevoluteY, PrismaticY and RevoluteZ links, and an
ObjectConnectorSpringDamper between tree markers for each coupler). The planar engine
(Pymunk) has no spatial expression; PyBullet's spatial build takes hinges only (no
slide) and Drake's translation is planar, and their backends say so.

Equilibria. At rest the rods hang (or stand) with the couplers along the shaft, and the
springs admit bent configurations too; the shaft's angle is free at every one of them
(no stiffness, no damping: a rigid, undamped drift, a double zero eigenvalue), so none is
stable in the linear sense and no free-vibration check applies. The operating point is
the hanging one; its modes are the rods' swings and the slider's two overdamped roots.

What the sources publish. The benchmark gives s(t) as a reference solution file whose
numbers the papers show only as a figure (the OpenSim port plots its s over it); no
number of it is restated here. What has a closed form is compared instead: no torque
about the shaft's axis acts on the mechanism (gravity is parallel to it, the base hinge
turns freely, the spring-dampers are internal), so the angular momentum about the axis
keeps its initial value, I_0 omega_0 with I_0 the moment of inertia about the axis in
the initial position. The benchmark's own error measure is s over the run.
"""
import math
from types import SimpleNamespace

import sympy as sp

from .. import BenchmarkError, Expectation, Published, System, coordinate_symbols
from ..model import (Body, Mechanism, Parameter, PointToPoint, Prismatic, Revolute,
                     Scenario, Segment, linear_spring_damper)

SOURCE = ("IFToMM benchmark A05 (González et al., Multibody System Dynamics 16, 2006); "
          "closed form: conservation of the angular momentum about the shaft")

PARAMETERS = (
    Parameter("L", 1.0, "m", "length of the shaft and of each rod", "IFToMM A05"),
    Parameter("b", 0.01, "m", "side of the square section of the shaft and the rods",
              "IFToMM A05"),
    Parameter("a", 0.1, "m", "side of the cubic slider", "IFToMM A05"),
    Parameter("rho", 3000.0, "kg/m^3", "density of the shaft, the rods and the slider",
              "IFToMM A05"),
    Parameter("m", 5.0, "kg", "each point mass, at a rod's far end", "IFToMM A05"),
    Parameter("k", 8e5, "N/m", "stiffness of each spring-damper", "IFToMM A05"),
    Parameter("c", 4e4, "N s/m", "damping of each spring-damper", "IFToMM A05"),
    Parameter("l0", 0.5, "m", "free length of each spring-damper", "IFToMM A05"),
    Parameter("d", 0.05, "m", "distance from the shaft's axis of each rod's hinge and of "
              "each spring-damper's point on the slider",
              "OpenSim port of IFToMM A05 (createModel.cpp)"),
    Parameter("s0", 0.5, "m", "initial height of the slider above the shaft's base",
              "IFToMM A05"),
    Parameter("alpha0", math.pi / 6, "rad", "initial angle of the rods below the "
              "horizontal", "IFToMM A05"),
    Parameter("omega0", 2 * math.pi, "rad/s", "initial speed of the shaft",
              "IFToMM A05", domain="real"),
)


def rod_mass(P):
    return P.rho * P.L * P.b**2


def arm_centre(P):
    """Distance from a rod's hinge to the centre of mass of the rod with its ball."""
    m_r = rod_mass(P)
    return (m_r * P.L / 2 + P.m * P.L) / (m_r + P.m)


def _prism(mass, along, side, axis: int):
    """Central tensor of a square prism of length `along` along body axis `axis`."""
    moments = [mass * (along**2 + side**2) / 12] * 3
    moments[axis] = mass * side**2 / 6
    return tuple(tuple(moments[i] if i == j else 0 for j in range(3)) for i in range(3))


def _arm(name: str, P) -> Body:
    m_r = rod_mass(P)
    l_c = arm_centre(P)
    across = m_r * (P.L**2 + P.b**2) / 12 + m_r * (P.L / 2 - l_c)**2 + P.m * (P.L - l_c)**2
    along = m_r * P.b**2 / 6
    tensor = ((across, 0, 0), (0, along, 0), (0, 0, across))
    # the rod hangs along -y from its hinge at (0, l_c, 0) at phi = 0
    return Body.spatial(name, m_r + P.m, tensor,
                        (Segment((0, l_c, 0), (0, l_c - P.L, 0), width=P.b),))


def build(P) -> Mechanism:
    shaft = Body.spatial("shaft", rod_mass(P), _prism(rod_mass(P), P.L, P.b, 1),
                         (Segment((0, -P.L / 2, 0), (0, P.L / 2, 0), width=P.b),))
    slider = Body.spatial("slider", P.rho * P.a**3,
                          _prism(P.rho * P.a**3, P.a, P.a, 1),
                          (Segment((-P.a / 2, 0, 0), (P.a / 2, 0, 0), width=P.a),))
    arms = (_arm("rod1", P), _arm("rod2", P))
    l_c = arm_centre(P)
    joints = (
        Revolute("base", "world", "shaft", "psi", axis=(0, 1, 0),
                 parent_anchor=(0, 0, 0), child_anchor=(0, -P.L / 2, 0)),
        Prismatic("slide", "shaft", "slider", "s", axis=(0, 1, 0),
                  parent_anchor=(0, -P.L / 2, 0), child_anchor=(0, 0, 0)),
        Revolute("hinge1", "shaft", "rod1", "phi1", axis=(0, 0, 1),
                 parent_anchor=(P.d, P.L / 2, 0), child_anchor=(0, l_c, 0)),
        Revolute("hinge2", "shaft", "rod2", "phi2", axis=(0, 0, 1),
                 parent_anchor=(-P.d, P.L / 2, 0), child_anchor=(0, l_c, 0)),
    )
    law = linear_spring_damper(P.k, P.l0, P.c)
    midpoint = (0, l_c - P.L / 2, 0)
    forces = (PointToPoint("coupler1", "slider", (P.d, 0, 0), "rod1", midpoint, **law),
              PointToPoint("coupler2", "slider", (-P.d, 0, 0), "rod2", midpoint, **law))
    return Mechanism(bodies=(shaft, slider) + arms, joints=joints, forces=forces,
                     # SymPy's simplify of the couplers' spatial lengths and their
                     # derivatives does not return in useful time: the derivation keeps
                     # its exact unsimplified expressions (lambdify's subexpression
                     # elimination)
                     simplify=False)


def arm_axial_moment(P, phi) -> sp.Expr:
    """One rod with its ball at angle phi from the downward vertical, about the shaft's
    axis: the rod's own moment about the vertical through its centre (its principal
    moments m_r b^2/6 along it and m_r (L^2 + b^2)/12 across it, the rod at phi from the
    vertical: m_r (b^2 (1 + cos^2 phi) + L^2 sin^2 phi)/12), its centre at d + (L/2)
    sin phi from the axis, the ball at d + L sin phi."""
    m_r = rod_mass(P)
    own = m_r * (P.b**2 * (1 + sp.cos(phi)**2) + P.L**2 * sp.sin(phi)**2) / 12
    return (own + m_r * (P.d + P.L / 2 * sp.sin(phi))**2
            + P.m * (P.d + P.L * sp.sin(phi))**2)


def _angular_momentum(P) -> sp.Expr:
    """The angular momentum about the shaft's axis, an expression of the coordinates and
    rates: the axial moments of the shaft (m_r b^2/6), the slider (rho a^5/6) and the two
    arms at their current angles, times the shaft's speed (the rods swing in a plane
    through the axis and the slider slides along it: neither adds to it)."""
    psi_d = coordinate_symbols("psi")[1]
    phi1, phi2 = coordinate_symbols("phi1")[0], coordinate_symbols("phi2")[0]
    own = rod_mass(P) * P.b**2 / 6 + P.rho * P.a**5 / 6
    return (own + arm_axial_moment(P, phi1) + arm_axial_moment(P, -phi2)) * psi_d


def _initial_momentum(values) -> float:
    """I_0 omega_0: `_angular_momentum` in the initial position (phi1 = -phi2 = pi/2 -
    alpha0) at the initial speed."""
    v = SimpleNamespace(**values)
    phi = sp.pi / 2 - v.alpha0
    own = rod_mass(v) * v.b**2 / 6 + v.rho * v.a**5 / 6
    return float((own + 2 * arm_axial_moment(v, phi)) * v.omega0)


def published(P):
    return (Published("H_axis", 10.0, _initial_momentum, SOURCE,
                      expression=_angular_momentum(P),
                      note="exact: no torque about the shaft's axis acts, so the angular "
                           "momentum about it keeps its initial value I_0 omega_0"),)


#: the specification's measure of a solution's error: its reference solution is the time
#: history of the slider's coordinate s; every sample of the run counts here
ERROR = BenchmarkError(
    ("s",), "run", "m",
    "IFToMM benchmark A05 specification (lim.ii.udc.es/mbsbenchmark, dist/A05): the time "
    "history of the slider's coordinate s",
    "largest |s - s_ref| over the run")


def _initial_angles(P) -> dict:
    phi = sp.pi / 2 - P.alpha0
    return {"psi": 0, "s": P.s0, "phi1": phi, "phi2": -phi}


#: the engines' step (s): the couplers' fastest decay rate, about 2 c / m_slider at rest,
#: is some 2.7e4 1/s, and an explicit scheme is stable only for w h below a limit of
#: order one (RK4: about 2.8); the project's default of 1e-3 s is ten times beyond it
STEP = 1e-4


def _hanging(P) -> dict:
    """The governor at rest: the rods hanging straight down, the slider on the vertical
    couplers at their free length (gravity sags it by rho a^3 g / (2 k) more)."""
    return {"psi": 0, "s": P.L / 2 - P.l0, "phi1": 0, "phi2": 0}


STEPS_AT_THE_FLOOR = (
    "The study's steps keep the fastest eigenvalue, the couplers' damping rate, within "
    "the scheme's asymptotic range; at such steps the engine's error over the study's run "
    "is already at the reference's own, so no halving lowers it and there is no range to "
    "fit an order on (the scheme's order shows on the trajectory gate at the row's step).")

SYSTEM = System(
    id="iftomm_a05_flyball_governor",
    title="IFToMM A05: stiff flyball governor (spatial, stiff spring-damper couplers)",
    source="IFToMM benchmark A05 (González et al. 2006)",
    parameters=PARAMETERS,
    build=build,
    operating_point=_hanging,
    scenarios=(
        Scenario("published", _initial_angles, lambda P: {"psi": P.omega0},
                 t_end=10.0, checks=("trajectory",),
                 description="the benchmark: the shaft at 2 pi rad/s, rods 30 degrees "
                             "below the horizontal, slider at 0.5 m, 10 s"),
    ),
    published=published,
    benchmark_error=ERROR,
    # the couplers' damping rates (about c/m, 1e4 1/s) against the governor's swing
    stiff=True,
    step=STEP,
    expectations=tuple(Expectation(engine, "convergence.order", "unresolved",
                                   STEPS_AT_THE_FLOOR) for engine in ("mujoco", "exudyn")),
)
