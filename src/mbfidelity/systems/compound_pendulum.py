"""Compound pendulum: a uniform bar pinned at one end (monograph §2.3, Fig. 7, eq. 4-6).

Geometry (φ from the downward vertical, counter-clockwise positive)::

        O  (pivot, world origin)
         \\
          \\  bar, length L, centre of mass G at l = L/2 from O
           G
            \\

The bar frame has its y axis along G->O, so the pivot is the body point (0, l) and
G = (l sin φ, -l cos φ); the bar's central inertia is I_O - m l^2. The defaults of l and
I_O are the uniform bar's formulas, l = L/2 and I_O = m L^2/3 (eq. 5), evaluated
at the user's m and L unless l or I_O are given too. The exact motion from rest at any
amplitude below π is given by Jacobi's elliptic functions.
"""
import sympy as sp

from . import Condition, PrintedFormula, System, coordinate_symbols
from .model import Body, Mechanism, Parameter, Revolute, Scenario, Segment

PARAMETERS = (
    Parameter("m", 1.0, "kg", "mass of the bar", "Fig. 7"),
    Parameter("L", 1.0, "m", "length of the bar (pinned at one end)", "project default"),
    Parameter("l", "L/2", "m", "distance from the pivot O to the centre of mass (default: "
              "uniform bar, L/2)", "Fig. 7"),
    Parameter("I_O", "m*L**2/3", "kg m^2", "moment of inertia about the pivot O (default: "
              "uniform bar, m L^2/3)", "eq. 5"),
    Parameter("phi0", 0.05, "rad", "initial angle, released from rest", "project default",
              domain="real"),
)


def build(P) -> Mechanism:
    bar = Body("bar", P.m, P.I_O - P.m * P.l**2, (Segment((0, P.l), (0, P.l - P.L)),))
    pivot = Revolute("pivot", "world", "bar", "phi", child_anchor=(0, P.l))
    return Mechanism(bodies=(bar,), joints=(pivot,))


def printed(P):
    phi, phi_d, phi_dd = coordinate_symbols("phi")
    I_O, l = P.I_O, P.l
    return (
        PrintedFormula("Fig. 7, eq. 4", "eom", [I_O * phi_dd + P.m * P.g * l * sp.sin(phi)]),
        PrintedFormula("Fig. 7, eq. 5 (inertia)", "M", sp.Matrix([[I_O]])),
        PrintedFormula("Fig. 7, eq. 5 (stiffness)", "K", sp.Matrix([[P.m * P.g * l]])),
        PrintedFormula("§2.3, phi_eq = n pi (n = 0)", "equilibrium", {"phi": 0}),
        PrintedFormula("eq. 42 applied to eq. 5", "frequency", sp.sqrt(P.m * P.g * l / I_O)),
    )


SYSTEM = System(
    id="compound_pendulum",
    title="Compound pendulum (uniform bar pinned at one end)",
    source="monograph §2.3, Fig. 7, eq. 4-6",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"phi": 0},
    printed=printed,
    scenarios=(
        Scenario("small", {"phi": "phi0"}, overrides={"phi0": 0.05},
                 checks=("trajectory", "reaction"),
                 description="released from rest at 0.05 rad (near-linear)"),
        Scenario("large", {"phi": "phi0"}, overrides={"phi0": 2.0},
                 checks=("trajectory", "reaction"),
                 description="released from rest at 2.0 rad (strongly nonlinear)"),
    ),
    reaction_joints=("pivot",),
    validity=(
        Condition("I_O > m*l**2", "the bar's central moment of inertia, I_O - m l^2, must be "
                                  "positive"),
        Condition("l <= L", "the centre of mass must lie on the bar"),
    ),
    exact_solution="rigid_pendulum_elliptic",
)
