"""Block on an inclined conveyor belt: self-excitation by a falling friction law and its
limit cycle (monograph §7.2, Fig. 21-23).

Geometry (x along the incline, downwards; x = 0 with the spring relaxed)::

      wall
        \\--/\\/\\--[ m ]                the belt runs up the incline at v0 (towards the
         \\--[ c ]--[   ]                wall); the block slips over it at v = v0 + x'
          \\=================  belt     and the belt drags it up with Ft(v)
           \\  alpha

The belt's force on the block is -Ft(v0 + x') along x (eq. of §7.2): Ft(v) = a2 v^2 - a1 v
+ a0 for v > 0, extended oddly, Ft(-v) = -Ft(v) (the printed definition). It falls with v
for v < a1 / (2 a2) (dry friction dominates) and rises beyond (viscous friction): about the
rest state x_eq = (m g sin(alpha) - Ft(v0)) / k it acts as a damper of coefficient
Ft'(v0), negative on the falling branch; the rest state is unstable when c + Ft'(v0) < 0,
i.e. for v0 below the threshold (a1 - c) / (2 a2) (0.3 m/s at the printed values).

The odd extension jumps by 2 a0 at zero slip: a block carried by the belt (x' = -v0)
sticks to it while the force that holds it there, c v0 + m g sin(alpha) - k x, stays
within +-a0, and slips again when it leaves that band. The unstable rest state grows into
a stick-slip limit cycle (Fig. 23). The reference integrates the slip phases and follows
the stick phases exactly (analytic/sliding.py, Filippov's convention at the jump).

Printed and coded: the energies and the power of the non-conservative forces of §7.2, the
equilibrium, the equation of motion, the reduced inertia, damping and stiffness, the
stability statement (the reduced damping c + Ft'(v0) changes sign at the threshold). The
printed numbers (x_eq = 11.5 mm at v0 = 0.29 m/s, the threshold 0.3 m/s, a velocity
amplitude of about 0.3 m/s on the limit cycle) are hand facts (tests/hand/conveyor_belt.py).
"""
import math

import sympy as sp

from . import Expectation, PrintedFormula, System, coordinate_symbols
from .model import (COORD_RATE, Body, CoordinateForce, Mechanism, Parameter, Prismatic,
                    Rectangle, Scenario, coordinate_spring_damper)

PARAMETERS = (
    Parameter("m", 2.0, "kg", "mass of the block", "§7.2"),
    Parameter("k", 500.0, "N/m", "spring constant", "§7.2"),
    Parameter("c", 2.0, "N s/m", "viscous damping", "§7.2",
              domain="nonnegative"),
    Parameter("alpha", math.radians(25.0), "rad", "inclination of the belt (25 degrees)",
              "§7.2"),
    Parameter("v0", 0.29, "m/s", "speed of the belt (Fig. 23; the scenarios span "
              "0.29-0.31)", "§7.2, Fig. 22-23"),
    Parameter("a2", 10.0, "N s^2/m^2", "quadratic coefficient of the belt force Ft(v)",
              "§7.2"),
    Parameter("a1", 8.0, "N s/m", "linear coefficient of the belt force (Ft falls with "
              "the slip speed where a1 > 2 a2 v)", "§7.2"),
    Parameter("a0", 4.0, "N", "belt force at vanishing slip (the bound of the sticking "
              "force)", "§7.2", domain="nonnegative"),
    Parameter("xd0", 0.1, "m/s", "initial velocity (the initial position is x_eq)",
              "§7.2", domain="real"),
)

FIRST_ORDER_MIXED = (
    "Semi-implicit Euler on this weakly (negatively) damped oscillation: its O(h) "
    "distortion of the orbit and its O(h^2 w T) phase drift are of one size at the studied "
    "steps and partly cancel in the error's maximum, so the error falls irregularly with "
    "the step and no single order fits (mbfidelity convergence).")

#: the belt speeds of Fig. 22: unstable, critical and stable rest state
BELT_SPEEDS = (0.29, 0.30, 0.31)


def belt_force(P, slip):
    """Ft(v) of §7.2: a2 v^2 - a1 v + a0 for v > 0 and its odd extension for v < 0; zero
    at v = 0 exactly, the middle of the jump (Filippov's convex set)."""
    def rising(v):
        return P.a2 * v**2 - P.a1 * v + P.a0
    return sp.Piecewise((rising(slip), slip > 0), (-rising(-slip), slip < 0), (0, True))


def belt_power_function(P, slip):
    """G(v) with G'(v) = Ft(v): the belt's force on the block, -Ft(v0 + x'), is
    -dG(v0 + x')/dx', Rayleigh's form (its power is -Ft(v0 + x') x', not of one sign: the
    belt feeds energy in where Ft falls)."""
    def rising(v):
        return P.a2 * v**3 / 3 - P.a1 * v**2 / 2 + P.a0 * v
    return sp.Piecewise((rising(slip), slip > 0), (rising(-slip), slip < 0), (0, True))


def rest_position(P):
    """x_eq = (m g sin(alpha) - Ft(v0)) / k: the spring holds the weight's component less
    the belt's drag at slip v0 (§7.2)."""
    return (P.m * P.g * sp.sin(P.alpha)
            - (P.a2 * P.v0**2 - P.a1 * P.v0 + P.a0)) / P.k


def build(P) -> Mechanism:
    block = Body("block", P.m, P.m * (0.1**2 + 0.06**2) / 12, (Rectangle((0, 0), 0.1, 0.06),))
    return Mechanism(
        bodies=(block,),
        joints=(Prismatic("incline", "world", "block", "x",
                          axis=(sp.cos(P.alpha), -sp.sin(P.alpha))),),
        forces=(
            CoordinateForce("spring_damper", "x", **coordinate_spring_damper(P.k, 0, P.c)),
            CoordinateForce("belt", "x", -belt_force(P, P.v0 + COORD_RATE),
                            dissipation=belt_power_function(P, P.v0 + COORD_RATE)),
        ),
    )


def printed(P):
    x, x_d, x_dd = coordinate_symbols("x")
    m, k, c, alpha, v0 = P.m, P.k, P.c, P.alpha, P.v0
    g = P.g

    def Ft(v):
        # the printed two-branch law, with its coefficients as parameters (printed:
        # 10, 8, 4); the value at v = 0 is not printed
        return sp.Piecewise((P.a2 * v**2 - P.a1 * v + P.a0, v > 0),
                            (-(P.a2 * (-v) ** 2 - P.a1 * (-v) + P.a0), True))

    dFt_v0 = 2 * P.a2 * v0 - P.a1  # the printed law's slope at v0 (branch v > 0)
    return (
        PrintedFormula("§7.2, E_c", "kinetic_energy", m * x_d**2 / 2),
        PrintedFormula("§7.2, E_p", "potential_energy", k * x**2 / 2 - m * g * x * sp.sin(alpha)),
        PrintedFormula("§7.2, P_nc", "dissipation_power", -c * x_d**2 - Ft(v0 + x_d) * x_d,
                       note="Ft as printed, its coefficients as parameters"),
        PrintedFormula("§7.2, x_eq", "equilibrium",
                       {"x": (m * g * sp.sin(alpha) - Ft(v0)) / k}),
        PrintedFormula("§7.2, equation of motion", "eom",
                       [m * x_dd + c * x_d + k * x - m * g * sp.sin(alpha) + Ft(v0 + x_d)]),
        PrintedFormula("§7.2, m_red", "M", sp.Matrix([[m]])),
        PrintedFormula("§7.2, c_red = c + dFt/dv at v0", "C", sp.Matrix([[c + dFt_v0]])),
        PrintedFormula("§7.2, k_red", "K", sp.Matrix([[k]])),
    )


def _scenario(v0: float) -> Scenario:
    state = {0.29: "the rest state is unstable: self-excited growth onto the stick-slip "
                   "limit cycle (Fig. 23)",
             0.30: "the threshold: zero reduced damping",
             0.31: "the rest state is stable: the oscillation decays"}[v0]
    return Scenario(f"v0_{v0:.2f}".replace(".", "_"), {"x": rest_position_text},
                    {"x": "xd0"}, t_end=40.0, overrides={"v0": v0},
                    checks=("trajectory", "limit_cycle") + (
                        ("threshold",) if v0 == 0.30 else ()),
                    description=f"Fig. 22: belt at {v0:.2f} m/s, from x_eq with "
                                f"x' = 0.1 m/s; {state}")


#: x_eq as the scenarios' initial position (an expression of the parameters)
rest_position_text = "(m*g*sin(alpha) - (a2*v0**2 - a1*v0 + a0))/k"

SYSTEM = System(
    id="conveyor_belt",
    title="Block on an inclined conveyor belt (self-excited, stick-slip)",
    source="monograph §7.2, Fig. 21-23",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"x": rest_position(P)},
    printed=printed,
    scenarios=tuple(_scenario(v) for v in BELT_SPEEDS),
    stability_parameter="v0",
    expectations=(
        *(Expectation(engine, "convergence.order", "unresolved", FIRST_ORDER_MIXED)
          for engine in ("pybullet", "pymunk", "drake")),
    ),
)
