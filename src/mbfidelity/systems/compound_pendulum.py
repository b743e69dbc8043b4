"""Compound pendulum: a uniform bar pinned at one end (monograph §2.3, Fig. 7, eq. 4-6).

Geometry (φ from the downward vertical, counter-clockwise positive)::

        O  (pivot, world origin)
         \\
          \\  bar, length L, centre of mass G at l = L/2 from O
           G
            \\

The bar frame has its y axis along G->O, so the pivot is the body point (0, L/2) and
G = (l sin φ, -l cos φ). I_O = m L^2/3 (uniform bar). The exact motion from rest at any
amplitude below π is given by Jacobi's elliptic functions.
"""
import sympy as sp

from . import PrintedFormula, System, coordinate_symbols
from .model import Body, Mechanism, Parameter, Revolute, Scenario, Segment

PARAMETERS = (
    Parameter("m", 1.0, "kg", "mass of the bar", "MECHANISMS.md A; Fig. 7"),
    Parameter("L", 1.0, "m", "length of the bar (pinned at one end)", "MECHANISMS.md A"),
    Parameter("phi0", 0.05, "rad", "initial angle, released from rest", "MECHANISMS.md A",
              domain="real"),
)


def build(P) -> Mechanism:
    bar = Body("bar", P.m, P.m * P.L**2 / 12, (Segment((0, P.L / 2), (0, -P.L / 2)),))
    pivot = Revolute("pivot", "world", "bar", "phi", child_anchor=(0, P.L / 2))
    return Mechanism(bodies=(bar,), joints=(pivot,))


def printed(P):
    phi, phi_d, phi_dd = coordinate_symbols("phi")
    I_O, l = P.m * P.L**2 / 3, P.L / 2
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
    exact_solution="uniform_rod_pendulum_elliptic",
)
