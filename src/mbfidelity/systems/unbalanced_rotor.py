"""Frame on a spring and damper excited by an unbalanced rotor turning at constant speed
(monograph §8.7, Fig. 31, eq. 86).

Geometry (horizontal guide)::

     |--/\\/\\/--[ frame M ]--> x        rotor pivoted at O on the frame, turned by an
     |--[ c ]---[   O.  G ]            actuator at phi = omega t (counter-clockwise from
                                       the x axis); its centre of mass G at distance e
                                       from O: G = O + e (cos phi, sin phi)

Horizontally, (M + m) x'' + c x' + k x = m omega^2 e cos(omega t) (eq. 86): excitation by
the rotor's inertia force, amplitude m e omega^2. The rotor's central inertia I_r (not in
the catalog) sets the actuator torque only; gravity acts across the guide.
"""
import sympy as sp

from . import PrintedFormula, System, coordinate_symbols
from .model import (TIME, Body, Circle, CoordinateForce, Mechanism, Parameter, Prescribed,
                    Prismatic, Rectangle, Revolute, Scenario, coordinate_spring_damper)

PARAMETERS = (
    Parameter("M", 10.0, "kg", "mass of the frame (rotor excluded)", "Fig. 31"),
    Parameter("m", 1.0, "kg", "mass of the rotor", "Fig. 31"),
    Parameter("e", 0.001, "m", "eccentricity of the rotor's centre of mass",
              "Fig. 31", domain="nonnegative"),
    Parameter("k", 1e5, "N/m", "spring constant", "Fig. 31"),
    Parameter("c", 50.0, "N s/m", "viscous damping", "Fig. 31",
              domain="nonnegative"),
    Parameter("ratio", 1.0, "1", "rotor speed over the natural frequency sqrt(k/(M + m)) "
              "(the scenarios span 0.5-2)", "project default"),
    Parameter("omega", "ratio*sqrt(k/(M + m))", "rad/s", "angular speed of the rotor",
              "project default"),
    Parameter("I_r", 1e-3, "kg m^2", "central moment of inertia of the rotor (not in the "
              "catalog: it changes the actuator torque only)", "chosen here"),
)

#: speeds of the amplitude curve, as ratios to the natural frequency sqrt(k/(M + m))
SPEED_RATIOS = (0.5, 0.75, 0.9, 1.0, 1.1, 1.5, 2.0)


def build(P) -> Mechanism:
    frame = Body("frame", P.M, P.M * (0.3**2 + 0.2**2) / 12, (Rectangle((0, 0), 0.3, 0.2),))
    rotor = Body("rotor", P.m, P.I_r, (Circle((0, 0), 0.05),))
    return Mechanism(
        bodies=(frame, rotor),
        joints=(Prismatic("guide", "world", "frame", "x", axis=(1, 0)),
                Revolute("axle", "frame", "rotor", "phi", child_anchor=(-P.e, 0))),
        forces=(CoordinateForce("spring_damper", "x", **coordinate_spring_damper(P.k, 0, P.c)),),
        prescribed=(Prescribed("motor", "phi", P.omega * TIME),),
    )


def printed(P):
    x, x_d, x_dd = coordinate_symbols("x")
    M, m, e, k, c, w = P.M, P.m, P.e, P.k, P.c, P.omega
    return (
        PrintedFormula("Fig. 31, eq. 86 (momentum of frame and rotor)", "eom",
                       [M * x_dd + m * (x_dd - w**2 * e * sp.cos(w * TIME)) + k * x + c * x_d],
                       note="row of x, phi = omega t"),
        PrintedFormula("Fig. 31, eq. 86", "eom",
                       [(M + m) * x_dd + c * x_d + k * x - m * w**2 * e * sp.cos(w * TIME)],
                       note="row of x, phi = omega t"),
    )


def rotor_speed(ratio: float) -> Scenario:
    return Scenario(f"ratio_{ratio:g}".replace(".", "_"), {"x": 0}, t_end=5.0,
                    overrides={"ratio": ratio},
                    checks=("trajectory", "actuator", "steady_state"),
                    description=f"rotor at {ratio:g} times the natural frequency, "
                                f"from rest: the transient decays (zeta ~ 0.024), then the "
                                f"steady-state amplitude of eq. 86")


SYSTEM = System(
    id="unbalanced_rotor",
    title="Frame excited by an unbalanced rotor",
    source="monograph §8.7, Fig. 31, eq. 86",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"x": 0, "phi": 0},
    printed=printed,
    scenarios=tuple(rotor_speed(r) for r in SPEED_RATIOS),
    unexcited={"e": 0.0},
    exact_solution="unbalanced_rotor_eq86",
    excitation_frequencies=lambda P: (P.omega,),
)
