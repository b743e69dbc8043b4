"""Mass-spring-damper, free and force-excited (monograph §7, Fig. 19, eq. 76-77; §8.1,
Fig. 24, eq. 79).

Geometry::

      |--/\\/\\/--|
 wall |          [ m ] --> x   (horizontal guide; spring relaxed at x = 0)
      |---[ c ]--|          F(t) = F0 sin(Omega t)

Exact solution: the linear one (homogeneous part by the matrix exponential, particular
part by the complex frequency response).
"""
import sympy as sp

from . import PrintedFormula, System, coordinate_symbols
from .model import (TIME, Body, CoordinateForce, Mechanism, Parameter, Prismatic, Rectangle,
                    Scenario, coordinate_spring_damper)

PARAMETERS = (
    Parameter("m", 1.0, "kg", "mass", "Fig. 19"),
    Parameter("k", 100.0, "N/m", "spring constant", "project default"),
    Parameter("c", 2.0, "N s/m", "viscous damping", "project default", domain="nonnegative"),
    Parameter("F0", 1.0, "N", "force amplitude of F(t) = F0 sin(Omega t)", "project default",
              domain="real"),
    Parameter("Omega", 10.0, "rad/s", "forcing angular frequency", "project default"),
    Parameter("x0", 0.0, "m", "initial displacement (free run: 0.01, chosen here)",
              domain="real"),
)


def build(P) -> Mechanism:
    block = Body("block", P.m, P.m * (0.1**2 + 0.1**2) / 12, (Rectangle((0, 0), 0.1, 0.1),))
    return Mechanism(
        bodies=(block,),
        joints=(Prismatic("guide", "world", "block", "x", axis=(1, 0)),),
        forces=(
            CoordinateForce("spring_damper", "x", **coordinate_spring_damper(P.k, 0, P.c)),
            CoordinateForce("load", "x", P.F0 * sp.sin(P.Omega * TIME)),
        ),
    )


def printed(P):
    x, x_d, x_dd = coordinate_symbols("x")
    t = TIME
    m, k, c = P.m, P.k, P.c
    return (
        PrintedFormula("Fig. 24, eq. 79", "eom",
                       [m * x_dd + c * x_d + k * x - P.F0 * sp.sin(P.Omega * t)]),
        PrintedFormula("eq. 76 (inertia)", "M", sp.Matrix([[m]])),
        PrintedFormula("eq. 76 (damping)", "C", sp.Matrix([[c]])),
        PrintedFormula("eq. 76 (stiffness)", "K", sp.Matrix([[k]])),
        PrintedFormula("eq. 77, omega_0", "frequency", sp.sqrt(k / m)),
        PrintedFormula("eq. 77, zeta", "damping_ratio", c / (2 * sp.sqrt(k * m))),
    )


SYSTEM = System(
    id="mass_spring_damper",
    title="Mass-spring-damper, free and force-excited",
    source="monograph §7 and §8.1, Fig. 19 and 24, eq. 76-79",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"x": 0},
    printed=printed,
    scenarios=(
        Scenario("free", {"x": "x0"}, overrides={"F0": 0.0, "x0": 0.01},
                 description="free decay from x0 = 10 mm"),
        Scenario("forced_5", {"x": "x0"}, overrides={"Omega": 5.0},
                 description="from rest, F0 sin(5 t): below resonance"),
        Scenario("forced_10", {"x": "x0"}, overrides={"Omega": 10.0},
                 description="from rest, F0 sin(10 t): at resonance"),
        Scenario("forced_15", {"x": "x0"}, overrides={"Omega": 15.0},
                 description="from rest, F0 sin(15 t): above resonance"),
    ),
    exact_solution="forced_linear_oscillator",
)
