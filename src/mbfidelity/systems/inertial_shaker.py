"""Frame on a spring and damper shaken by an inner mass that an internal actuator drives
(monograph §8.6, Fig. 30, eq. 85).

Geometry (horizontal guide, as eq. 85's momentum balance in the horizontal direction)::

      |--/\\/\\/--+-------------------+
 wall |   k      |  frame M    [m]   |--> x    frame on a fixed guide; spring and
      |---[ c ]--|        |<-y->|    |         damper relaxed at x = 0
                 +-------------------+
                   inner mass m driven by the actuator: y(t) = Y sin(Omega t),
                   its position relative to the frame

The inner mass slides on a guide of the frame (a prescribed prismatic joint whose parent
is the frame), so its absolute velocity is x' + y' and the momentum of the two gives
M x'' + m (x'' + y'') = -k x - c x' (eq. 85): the frame moves as a mass M + m excited by
the inner mass's d'Alembert force -m y''(t). The actuator pushes the inner mass with
m (x'' + y''), and the frame back with as much. Gravity acts across the guides.

Printed and coded: eq. 85 (both lines) and the energies of the system in the fixed frame
(§8.6). Not coded: the powers P_nc = -c x'^2 + P_act and the balance in the frame of M,
which contain the actuator's power P_act, an unknown of the printed equations (the
actuator force m (x'' + y'') that they imply is checked through the actuator's output).
"""
import sympy as sp

from . import PrintedFormula, System, coordinate_symbols
from .model import (TIME, Body, CoordinateForce, Mechanism, Parameter, Prescribed, Prismatic,
                    Rectangle, Scenario, coordinate_spring_damper)

PARAMETERS = (
    Parameter("M", 5.0, "kg", "mass of the frame (inner mass excluded)",
              "Fig. 30"),
    Parameter("k", 2000.0, "N/m", "spring constant", "Fig. 30"),
    Parameter("c", 10.0, "N s/m", "viscous damping", "Fig. 30",
              domain="nonnegative"),
    Parameter("m", 0.5, "kg", "inner mass", "Fig. 30"),
    Parameter("Y", 0.02, "m", "amplitude of the inner mass's motion y(t) = Y sin(Omega t) "
              "relative to the frame", "project default", domain="real"),
    Parameter("ratio", 1.0, "1", "drive frequency over the natural frequency sqrt(k/(M + m)) "
              "(the scenarios set it)", "chosen here"),
    Parameter("Omega", "ratio*sqrt(k/(M + m))", "rad/s", "angular frequency of the drive",
              "eq. 85"),
)

#: drive frequencies of the scenarios, as ratios to the natural frequency sqrt(k/(M + m))
DRIVE_RATIOS = (0.5, 1.0, 2.0)


def build(P) -> Mechanism:
    frame = Body("frame", P.M, P.M * (0.3**2 + 0.15**2) / 12, (Rectangle((0, 0), 0.3, 0.15),))
    inner = Body("inner", P.m, P.m * (0.05**2 + 0.05**2) / 12, (Rectangle((0, 0), 0.05, 0.05),))
    return Mechanism(
        bodies=(frame, inner),
        joints=(Prismatic("guide", "world", "frame", "x", axis=(1, 0)),
                Prismatic("inner_guide", "frame", "inner", "y", axis=(1, 0))),
        forces=(CoordinateForce("spring_damper", "x", **coordinate_spring_damper(P.k, 0, P.c)),),
        prescribed=(Prescribed("actuator", "y", P.Y * sp.sin(P.Omega * TIME)),),
    )


def printed(P):
    x, x_d, x_dd = coordinate_symbols("x")
    _, y_d, y_dd = coordinate_symbols("y")
    M, m, k, c = P.M, P.m, P.k, P.c
    return (
        PrintedFormula("Fig. 30, eq. 85 (momentum of frame and inner mass)", "eom",
                       [M * x_dd + m * (x_dd + y_dd) + k * x + c * x_d],
                       note="row of x; y(t) the inner mass's drive"),
        PrintedFormula("Fig. 30, eq. 85", "eom",
                       [(M + m) * x_dd + c * x_d + k * x + m * y_dd],
                       note="row of x; y(t) the inner mass's drive"),
        PrintedFormula("§8.6, fixed frame (kinetic energy)", "kinetic_energy",
                       M * x_d**2 / 2 + m * (x_d + y_d) ** 2 / 2),
        PrintedFormula("§8.6, fixed frame (potential energy)", "potential_energy",
                       k * x**2 / 2),
    )


def drive(ratio: float) -> Scenario:
    return Scenario(f"ratio_{ratio:g}".replace(".", "_"), {"x": 0}, t_end=10.0,
                    overrides={"ratio": ratio},
                    checks=("trajectory", "actuator", "steady_state"),
                    description=f"from rest, inner mass driven at {ratio:g} times the natural "
                                f"frequency: the transient decays, then the frame's "
                                f"steady-state amplitude of eq. 85")


SYSTEM = System(
    id="inertial_shaker",
    title="Frame shaken by an actuator-driven inner mass",
    source="monograph §8.6, Fig. 30, eq. 85",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"x": 0, "y": 0},
    printed=printed,
    scenarios=tuple(drive(r) for r in DRIVE_RATIOS),
    unexcited={"Y": 0.0},
    excitation_frequencies=lambda P: (P.Omega,),
)
