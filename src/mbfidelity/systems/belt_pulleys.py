"""Two pulleys joined by a belt on an oscillating arm (monograph §9.8 example 2, Fig. 38).

Geometry (arm angle theta from the downward vertical, counter-clockwise; pulley angles
relative to the arm, counter-clockwise)::

        wall
        |   O (world origin): pivot of the massless arm OC (c3 viscous, arm/wall)
        |  (1)  pulley 1 (I1, r1) centred at O, angle phi1 relative to the arm (c1)
        |  | |
        |  | |   open, non-slipping belt: r1 phi1 = r2 phi2 (relative angles)
        |  | |
        |  (2)  pulley 2 (I2, r2, mass m2) centred at C, angle phi2 relative to the arm (c2)
             C = l (sin theta, -cos theta)

Where each choice comes from:
- theta from the downward vertical: the printed E_p = m2 g l (1 - cos theta) (Fig. 38).
- phi1, phi2 relative to the arm: the printed first form of E_c has the absolute rates
  theta' + phi1', theta' + phi2' (both counter-clockwise like theta).
- the belt coupling r1 phi1 = r2 phi2 on the relative angles, same sense (open belt): the
  expanded E_c has the cross term I2 (r1/r2) theta' phi1' and I2 (r1/r2)^2 phi1'^2, i.e.
  phi2' = (r1/r2) phi1'; P_nc has c2 (r1/r2)^2 phi1'^2 for the same reason.
- the arm and the belt are massless (the text says so). Pulley 1's mass is not given: its
  centre is on the pivot, so it only loads the pivot; it is given the mass of a uniform
  disc of inertia I1 and radius r1 (2 I1 / r1^2) for the engines.
- q = {theta, phi1} independent (the monograph's), phi2 dependent.

Belt force: the coupling Phi = r1 phi1 - r2 phi2 = 0 (metres of belt) has a multiplier
lambda in newtons; its generalized force -Phi_q^T lambda is a torque -r1 lambda on pulley 1
and +r2 lambda on pulley 2. So lambda is the belt's tension difference
T_a - T_b, where branch a is the one that turns pulley 2 counter-clockwise (and pulley 1
clockwise): with the arm hanging down it is the branch on the arm's right (+x) side. An
inextensible belt fixes only this difference, not the preload. The analytic layer and the
engines report the coupling force as -lambda (simulators/base.py point 6).

Printed formulas coded below: E_c in both printed forms, E_p, P_nc (kind
"dissipation_power": the viscous moments' power, with c2 (r1/r2)^2 through the belt), the
equilibrium theta = 0, and the matrices M, K, C. Q_theta, Q_phi1 are printed too (there
is no printed-formula kind for a generalized force); they enter through P_nc and C.
The linearization has one zero frequency: phi1 is cyclic (the pulley pair can turn at any
angle relative to the arm without changing the potential).
"""
import sympy as sp

from . import Condition, PrintedFormula, System, coordinate_symbols
from .model import (COORD_RATE, Body, Circle, CoordinateForce, LinearCoupling, Mechanism,
                    Parameter, Revolute, Scenario, Segment)

PARAMETERS = (
    Parameter("I1", 0.01, "kg m^2", "moment of inertia of pulley 1 about its centre O",
              "Fig. 38"),
    Parameter("r1", 0.05, "m", "radius of pulley 1", "Fig. 38"),
    Parameter("I2", 0.04, "kg m^2", "central moment of inertia of pulley 2",
              "Fig. 38"),
    Parameter("r2", 0.1, "m", "radius of pulley 2", "Fig. 38"),
    Parameter("m2", 2.0, "kg", "mass of pulley 2", "Fig. 38"),
    Parameter("l", 0.4, "m", "arm length OC (distance between the pulley centres)",
              "Fig. 38"),
    Parameter("c1", 0.01, "N m s", "viscous friction of pulley 1 on the arm",
              "Fig. 38", domain="nonnegative"),
    Parameter("c2", 0.02, "N m s", "viscous friction of pulley 2 on the arm",
              "Fig. 38", domain="nonnegative"),
    Parameter("c3", 0.1, "N m s", "viscous friction of the arm on the wall",
              "Fig. 38", domain="nonnegative"),
)


def _viscous(name, coordinate, c):
    return CoordinateForce(name, coordinate, -c * COORD_RATE, dissipation=c * COORD_RATE**2 / 2)


def build(P) -> Mechanism:
    arm = Body("arm", 0, 0, (Segment((0, 0), (0, -P.l)),))
    # pulley 1's mass is not given and does not enter the motion (centre on the pivot):
    # a uniform disc of inertia I1 and radius r1
    pulley1 = Body("pulley1", 2 * P.I1 / P.r1**2, P.I1, (Circle((0, 0), P.r1),))
    pulley2 = Body("pulley2", P.m2, P.I2, (Circle((0, 0), P.r2),))
    return Mechanism(
        bodies=(arm, pulley1, pulley2),
        joints=(
            Revolute("pivot", "world", "arm", "theta"),
            Revolute("hub1", "arm", "pulley1", "phi1"),
            Revolute("hub2", "arm", "pulley2", "phi2", parent_anchor=(0, -P.l)),
        ),
        constraints=(LinearCoupling("belt", (("phi1", P.r1), ("phi2", -P.r2))),),
        independent=("theta", "phi1"),
        forces=(
            _viscous("friction_arm_wall", "theta", P.c3),
            _viscous("friction_pulley1", "phi1", P.c1),
            _viscous("friction_pulley2", "phi2", P.c2),
        ),
    )


def printed(P):
    th, th_d, _ = coordinate_symbols("theta")
    _, p1_d, _ = coordinate_symbols("phi1")
    _, p2_d, _ = coordinate_symbols("phi2")
    I1, I2, m2, l, g, r1, r2 = P.I1, P.I2, P.m2, P.l, P.g, P.r1, P.r2
    c1, c2, c3 = P.c1, P.c2, P.c3
    rho = r1 / r2
    m12 = I1 + I2 * rho
    return (
        PrintedFormula("Fig. 38, E_c (first form)", "kinetic_energy",
                       I1 * (th_d + p1_d) ** 2 / 2 + I2 * (th_d + p2_d) ** 2 / 2
                       + m2 * l**2 * th_d**2 / 2),
        PrintedFormula("Fig. 38, E_c (in theta, phi1)", "kinetic_energy",
                       (I1 + I2 + m2 * l**2) * th_d**2 / 2 + (I1 + I2 * rho**2) * p1_d**2 / 2
                       + m12 * th_d * p1_d),
        PrintedFormula("Fig. 38, E_p", "potential_energy", m2 * g * l * (1 - sp.cos(th))),
        PrintedFormula("Fig. 38, equilibrium theta = 0", "equilibrium", {"theta": 0}),
        PrintedFormula("Fig. 38, matrix M", "M",
                       sp.Matrix([[I1 + I2 + m2 * l**2, m12], [m12, I1 + I2 * rho**2]])),
        PrintedFormula("Fig. 38, matrix K", "K", sp.Matrix([[m2 * g * l, 0], [0, 0]])),
        PrintedFormula("Fig. 38, matrix C", "C", sp.Matrix([[c3, 0], [0, c1 + c2 * rho**2]])),
        PrintedFormula("Fig. 38, P_nc", "dissipation_power",
                       (-c3 * th_d) * th_d + (-(c1 + c2 * rho**2) * p1_d) * p1_d),
    )


_CHECKS = ("trajectory", "constraint_force")

SYSTEM = System(
    id="belt_pulleys",
    title="Two belt-coupled pulleys on an oscillating arm",
    source="monograph §9.8 example 2, Fig. 38",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"theta": 0, "phi1": 0, "phi2": 0},
    printed=printed,
    validity=(Condition("r1 + r2 < l", "the pulleys, whose centres are l apart, must not "
                                       "overlap"),),
    scenarios=(
        Scenario("small", {"theta": 0.05}, checks=_CHECKS,
                 description="0.05 rad from the stable equilibrium theta = 0, from rest"),
        Scenario("large", {"theta": 2.0}, {"phi1": 5.0}, checks=_CHECKS,
                 description="2 rad from the bottom with the pulleys spinning (phi1' = 5 rad/s)"),
        Scenario("undamped", {"theta": 0.8}, {"phi1": 3.0}, checks=_CHECKS,
                 overrides={"c1": 0.0, "c2": 0.0, "c3": 0.0},
                 description="no passive resistances (energy conserved), 0.8 rad, phi1' = 3 rad/s"),
    ),
    notes="phi1 is cyclic: every theta = 0 (theta = pi) with any phi1 is an equilibrium; "
          "the linearization has one zero frequency.",
)
