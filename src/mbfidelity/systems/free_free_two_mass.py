"""Two free masses joined by a spring, pushed by a constant force (Italian notes §5.3.1,
Fig. 5.1, eq. 5.39-5.52; the linearization routes of §5.3.2-5.3.4).

Geometry (no ground, no gravity along the motion)::

   F -->[ m ]--/\\/\\/\\--[ m ]        x1: absolute position of mass 1
          1       k         2        dx: stretch of the spring (x2 - x1 minus its free
                                         length l0; eq. 5.46's Delta x)

Mass 1 slides on the world (coordinate x1), mass 2 slides on mass 1 (coordinate dx): the
spring acts on dx, between the two masses; the constant force F acts on x1, between the
world and mass 1 (a load, not a potential: eq. 5.39 writes it as the external force).
The free length l0 only places the drawing; it enters no equation.

There is no static equilibrium in absolute coordinates: the resultant F has nothing to
react on but the inertia of the whole (eq. 5.41), so the centre of mass accelerates at
F/(2m) (eq. 5.42). The notes' equilibrium is a relative one (eq. 5.44-5.52): the masses
translate rigidly with that acceleration while the spring holds the stretch that
accelerates mass 2, dx = -F/(2k) (a compression: F pushes mass 1 towards mass 2). The
system declares x1 as its rigid direction (both masses move, dx fixed); the analytic
layer solves the rigid acceleration together with dx, and linearizes about that motion:
a rigid-body mode at zero frequency and the relative oscillation at sqrt(2k/m), the two
masses vibrating in opposition about the centre of mass (reduced mass m/2).

Printed and coded (the minus signs, lost in the notes' text layer, restored from the
force balance each equation states): eq. 5.39 and 5.43 (the two balances in absolute
coordinates, x2 = x1 + l0 + dx), eq. 5.41 with 5.40 (the whole system through its centre
of mass), eq. 5.50 with 5.44-5.49 (mass 2 in the relative coordinates), and eq. 5.51-5.52
(the stretch of the relative equilibrium).

Exact solution: the centre of mass uniformly accelerated, the stretch harmonic at
sqrt(2k/m) about -F/(2k) (`analytic/closed_forms.py`, `free_pair_under_constant_force`).
"""

from . import PrintedFormula, System, coordinate_symbols
from .model import (Body, CoordinateForce, Mechanism, Parameter, Prismatic, Rectangle,
                    Scenario, coordinate_spring_damper)

PARAMETERS = (
    Parameter("m", 1.0, "kg", "mass of each of the two bodies", "Fig. 5.1"),
    Parameter("k", 100.0, "N/m", "spring constant", "Fig. 5.1"),
    Parameter("F", 10.0, "N", "constant force on mass 1, along the line of the masses "
              "(positive towards mass 2)", "Fig. 5.1", domain="real"),
    Parameter("l0", 0.5, "m", "free length of the spring (drawing only; chosen here)"),
)

#: side of the square blocks drawn for the masses (m)
BLOCK = 0.1


def build(P) -> Mechanism:
    inertia = P.m * (BLOCK**2 + BLOCK**2) / 12
    mass1 = Body("mass1", P.m, inertia, (Rectangle((0, 0), BLOCK, BLOCK),))
    mass2 = Body("mass2", P.m, inertia, (Rectangle((0, 0), BLOCK, BLOCK),))
    return Mechanism(
        bodies=(mass1, mass2),
        joints=(
            Prismatic("slide1", "world", "mass1", "x1", axis=(1, 0)),
            Prismatic("spring_axis", "mass1", "mass2", "dx", axis=(1, 0),
                      parent_anchor=(P.l0, 0)),
        ),
        forces=(
            CoordinateForce("spring", "dx", **coordinate_spring_damper(P.k, 0)),
            CoordinateForce("push", "x1", P.F),
        ),
    )


def printed(P):
    x1, x1_d, x1_dd = coordinate_symbols("x1")
    dx, dx_d, dx_dd = coordinate_symbols("dx")
    m, k, F = P.m, P.k, P.F
    # absolute position of mass 2 and the centre of mass (eq. 5.40), in the coordinates
    x2_dd = x1_dd + dx_dd
    xcg_dd = (x1_dd + x2_dd) / 2
    x2_rel_dd = dx_dd / 2  # eq. 5.49: x2' = dx / 2
    return (
        PrintedFormula("eq. 5.39, 5.43", "eom",
                       [F - m * x1_dd - m * x2_dd,        # eq. 5.39
                        -k * dx - m * x2_dd],             # eq. 5.43: x2 - x1 - l0 = dx
                       note="balance of the whole system and of mass 2, absolute "
                            "coordinates"),
        PrintedFormula("eq. 5.41 (with 5.40)", "eom", [F - 2 * m * xcg_dd],
                       note="the whole system through its centre of mass"),
        PrintedFormula("eq. 5.50 (with 5.44-5.49)", "eom",
                       [-k * dx - m * (xcg_dd + x2_rel_dd)],
                       note="mass 2 in the relative coordinates about the centre of mass"),
        PrintedFormula("eq. 5.51-5.52", "equilibrium", {"dx": -F / (2 * k)},
                       note="relative equilibrium: the stretch while the pair accelerates "
                            "rigidly at F/(2m) (eq. 5.42)"),
    )


SYSTEM = System(
    id="free_free_two_mass",
    title="Two free masses joined by a spring, pushed by a constant force",
    source="Italian notes §5.3.1-5.3.4, Fig. 5.1, eq. 5.39-5.52",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"x1": 0, "dx": -P.F / (2 * P.k)},
    rigid_directions=lambda P: ({"x1": 1},),
    printed=printed,
    scenarios=(
        Scenario("from_rest", {"x1": 0, "dx": 0}, t_end=5.0,
                 checks=("trajectory", "floating"),
                 description="from rest with the spring relaxed: the pair accelerates at "
                             "F/(2m) while the stretch swings between 0 and -F/k"),
        Scenario("drifting", {"x1": 0, "dx": "-F/(2*k) + 0.02"}, {"x1": -1.0}, t_end=5.0,
                 checks=("trajectory", "floating"),
                 description="moving backwards at 1 m/s, the stretch 20 mm off the "
                             "relative equilibrium: F stops the pair and drives it back"),
    ),
    exact_solution="free_pair_under_constant_force",
)
