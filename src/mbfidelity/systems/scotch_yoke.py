"""Scotch yoke with a cotangent spring (monograph §4.6, Fig. 14-16, eq. 43-55; guide
friction §7).

Geometry, reconstructed from the printed energies (eq. 45, 47) and spring length (eq. 44)::

            O  disc centre (world origin), disc angle phi
          /    pin P at radius r, P = (-r cos phi, -r sin phi): the block drops as phi grows
    ====P=========  horizontal slot through the block's centre, block at y = -r sin phi
       [ block m ]  guided vertically (coordinate y, dependent)
           |        spring from the block point b below the slot ...
          |||  cot  ... to the fixed point (0, -h): l = h - b - r sin phi (eq. 44)
    ------+------   repulsion F0 cot(pi l / (2 l0)) (eq. 43)

The printed weight potential is -m g r sin(phi) (eq. 47), which fixes the sense of phi.
The pin-slot contact is a point-on-line constraint whose multiplier is the slot force.

Printed formulas: eq. 43 (the cot law) and eq. 44 (the spring length) are the
description's inputs; every later formula is written with them, so eq. 46 and 49-55,
compared below, test them too. Eq. 47 and 48 (weight and spring potentials) are compared
through their sum, eq. 49 (the reference configurations differ, as the text says).
"""
import sympy as sp

from . import Condition, PrintedFormula, System, coordinate_symbols
from .model import (LENGTH, Body, Circle, CoordinateForce, Mechanism, Parameter, PointOnLine,
                    PointToPoint, Prismatic, Rectangle, Revolute, Scenario, COORD_RATE)

#: length of the block's slot (the drawn block's width): the pin, at x = -r cos(phi), must
#: stay in it
BLOCK_WIDTH = 0.3

PARAMETERS = (
    Parameter("I_O", 0.005, "kg m^2", "moment of inertia of the disc about O", "Fig. 14"),
    Parameter("m", 1.0, "kg", "mass of the block", "project default"),
    Parameter("r", 0.05, "m", "radius of the pin P", "Fig. 16"),
    Parameter("h", 0.2, "m", "depth of the spring's fixed end below O", "Fig. 16"),
    Parameter("b", 0.1, "m", "distance from the slot to the spring's end on the block", "project default"),
    Parameter("l0", 0.2, "m", "free length of the cot spring", "project default"),
    Parameter("F0", "m*g", "N", "spring constant of eq. 43 (default: m g)", "project default"),
    Parameter("c", 0.0, "N s/m", "viscous friction of the block's guide (§7 variant: 0.5)",
              "§7", domain="nonnegative"),
)


def build(P) -> Mechanism:
    # the disc's mass is not given; its centre of mass is on the axis, so it does not
    # enter the motion (only the pivot reaction): 0.5 kg for the engines
    disc = Body("disc", 0.5, P.I_O, (Circle((0, 0), 1.4 * P.r),))
    block = Body("block", P.m, P.m * (BLOCK_WIDTH**2 + 0.05**2) / 12,
                 (Rectangle((0, 0), BLOCK_WIDTH, 0.05),))
    cot_law = -P.F0 * sp.cot(sp.pi * LENGTH / (2 * P.l0))
    return Mechanism(
        bodies=(disc, block),
        joints=(
            Revolute("pivot", "world", "disc", "phi"),
            Prismatic("guide", "world", "block", "y", axis=(0, 1)),
        ),
        constraints=(PointOnLine("slot", "disc", (-P.r, 0), "block", (0, 0), (1, 0)),),
        independent=("phi",),
        forces=(
            PointToPoint("cot_spring", "world", (0, -P.h), "block", (0, -P.b), tension=cot_law,
                         potential=-2 * P.F0 * P.l0 / sp.pi * sp.log(sp.sin(sp.pi * LENGTH / (2 * P.l0)))),
            CoordinateForce("guide_friction", "y", -P.c * COORD_RATE,
                            dissipation=P.c * COORD_RATE**2 / 2),
        ),
    )


def printed(P):
    phi, phi_d, phi_dd = coordinate_symbols("phi")
    m, g, r, h, b, l0, F0, I_O = P.m, P.g, P.r, P.h, P.b, P.l0, P.F0, P.I_O
    special = {"F0": m * g, "l0": h, "b": h / 2}  # the relations stated before eq. 55
    l = h - b - r * sp.sin(phi)
    cot = sp.cot(sp.pi * l / (2 * l0))
    return (
        PrintedFormula("Fig. 14, eq. 45", "kinetic_energy",
                       (I_O + m * (r * sp.cos(phi)) ** 2) * phi_d**2 / 2),
        PrintedFormula("Fig. 14, eq. 46 (reduced inertia m(phi))", "kinetic_energy",
                       (I_O + m * (r * sp.cos(phi)) ** 2) * phi_d**2 / 2),
        PrintedFormula("Fig. 14, eq. 50 (dE_p/dphi)", "potential_gradient",
                       [(-m * g + F0 * cot) * r * sp.cos(phi)]),
        PrintedFormula("Fig. 14, eq. 52 (d2E_p/dphi2)", "potential_hessian", sp.Matrix([[
            m * g * r * sp.sin(phi) - F0 * cot * r * sp.sin(phi)
            + F0 * r**2 * sp.cos(phi) ** 2 * sp.pi / (2 * l0)
            * sp.csc(sp.pi * l / (2 * l0)) ** 2]])),
        PrintedFormula("Fig. 14, eq. 49 (with eq. 47-48)", "potential_energy",
                       -m * g * r * sp.sin(phi)
                       - 2 * F0 * l0 / sp.pi * sp.log(sp.sin(sp.pi * l / (2 * l0)))),
        PrintedFormula("Fig. 14, eq. 51", "eom", [
            (I_O + m * (r * sp.cos(phi)) ** 2) * phi_dd
            - sp.Rational(1, 2) * m * r**2 * sp.cos(phi) * sp.sin(phi) * phi_d**2
            + (-m * g + F0 * cot) * r * sp.cos(phi)]),
        PrintedFormula("Fig. 14, eq. 50 (phi_eq = pi/2)", "equilibrium", {"phi": sp.pi / 2}),
        PrintedFormula("Fig. 14, eq. 50 (phi_eq = -pi/2)", "equilibrium", {"phi": -sp.pi / 2}),
        PrintedFormula("Fig. 14, eq. 50 (third equilibrium)", "equilibrium", {
            "phi": sp.asin((h - b - 2 * l0 / sp.pi * sp.acot(m * g / F0)) / r)}),
        PrintedFormula("Fig. 14, eq. 53 (inertia at pi/2)", "M", sp.Matrix([[I_O]]),
                       at={"phi": sp.pi / 2}),
        PrintedFormula("Fig. 14, eq. 53 (stiffness at pi/2)", "K",
                       sp.Matrix([[(m * g - F0 * sp.cot(sp.pi * (h - b - r) / (2 * l0))) * r]]),
                       at={"phi": sp.pi / 2}),
        PrintedFormula("Fig. 14, eq. 54 (inertia at -pi/2)", "M", sp.Matrix([[I_O]]),
                       at={"phi": -sp.pi / 2}),
        PrintedFormula("Fig. 14, eq. 54 (stiffness at -pi/2)", "K",
                       sp.Matrix([[(-m * g + F0 * sp.cot(sp.pi * (h - b + r) / (2 * l0))) * r]]),
                       at={"phi": -sp.pi / 2}),
        PrintedFormula("Fig. 16, eq. 55 (inertia)", "M", sp.Matrix([[I_O + m * r**2]]),
                       relations=special, note="with F0 = m g, l0 = h, b = h/2"),
        PrintedFormula("Fig. 16, eq. 55 (stiffness)", "K",
                       sp.Matrix([[m * g * sp.pi * r**2 / h]]),
                       relations=special, note="with F0 = m g, l0 = h, b = h/2"),
        PrintedFormula("Fig. 16, f0 (as rad/s)", "frequency",
                       sp.sqrt(m * g * sp.pi * r**2 / ((I_O + m * r**2) * h)),
                       relations=special, note="with F0 = m g, l0 = h, b = h/2"),
    )


SYSTEM = System(
    id="scotch_yoke",
    title="Scotch yoke with a cotangent spring",
    source="monograph §4.6 and §7, Fig. 14-16, eq. 43-55",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"phi": 0, "y": 0},
    printed=printed,
    scenarios=(
        Scenario("small", {"phi": 0.05}, checks=("trajectory", "constraint_force"),
                 description="0.05 rad from the stable equilibrium phi = 0"),
        Scenario("large", {"phi": 1.2}, checks=("trajectory", "constraint_force"),
                 description="1.2 rad: the block swings close to its lowest point"),
        Scenario("damped", {"phi": 0.5}, overrides={"c": 0.5},
                 checks=("trajectory", "constraint_force"),
                 description="guide friction c = 0.5 (§7), from 0.5 rad"),
    ),
    validity=(
        # l = h - b - r sin(phi) over a turn spans [h - b - r, h - b + r]; the cot law is
        # finite only for 0 < l < 2 l0
        Condition("h - b - r > 0", "the cot spring's length h - b - r sin(phi) must stay "
                                   "positive over a turn"),
        Condition("h - b + r < 2*l0", "the cot spring's length h - b - r sin(phi) must stay "
                                      "below 2 l0 over a turn (the cot law's force is "
                                      "infinite there)"),
        Condition(f"2*r < {BLOCK_WIDTH}", f"the pin, at radius r, must stay in the block's "
                                          f"slot ({BLOCK_WIDTH} m long) over a turn"),
    ),
)
