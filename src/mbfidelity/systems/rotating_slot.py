"""Block in a radial slot of a disc turning at constant speed in a vertical plane
(monograph §8.5, Fig. 29, eq. 84).

Geometry::

            slot (through O, turning with the disc)
             \\
              \\  [m]  block at distance x from O along the slot
               \\ /
                O ------   disc pivoted at O, turned by an actuator: phi = omega t,
                           clockwise (the sense in which eq. 84's weight term is
                           + m g sin(phi): the slot's direction is (cos phi, -sin phi))

The spring k (relaxed at O) and the damper c act along the slot. In the disc's frame the
block feels the drag force m phi'^2 x and Coriolis (normal to the slot, taken by its
walls), so the relative motion obeys m x'' + c x' + (k - m omega^2) x = m g sin(omega t):
stable below the critical speed sqrt(k/m), unstable above (§8.5). The disc's inertia I_d
and the block's central inertia I_b (not in the catalog) set the actuator torque only.
"""
import sympy as sp

from . import PrintedFormula, System, coordinate_symbols
from .model import (TIME, Body, Circle, CoordinateForce, Mechanism, Parameter, Prescribed,
                    Prismatic, Rectangle, Revolute, Scenario, coordinate_spring_damper)

PARAMETERS = (
    Parameter("m", 0.5, "kg", "mass of the block", "Fig. 29"),
    Parameter("k", 50.0, "N/m", "spring constant (relaxed at O)", "Fig. 29"),
    Parameter("c", 0.5, "N s/m", "viscous damping along the slot", "Fig. 29",
              domain="nonnegative"),
    Parameter("omega", 5.0, "rad/s", "angular speed of the disc (scenarios: 5, 9.5, 10.5)",
              "eq. 84"),
    Parameter("I_d", 0.05, "kg m^2", "moment of inertia of the disc about O (not in the "
              "catalog: it changes the actuator torque only)", "chosen here"),
    Parameter("I_b", 1e-4, "kg m^2", "central moment of inertia of the block (not in the "
              "catalog)", "chosen here"),
    Parameter("x0", 0.01, "m", "initial position of the block along the slot", "chosen here",
              domain="real"),
)


def build(P) -> Mechanism:
    disc = Body("disc", 1.0, P.I_d, (Circle((0, 0), 0.3),))
    block = Body("block", P.m, P.I_b, (Rectangle((0, 0), 0.04, 0.03),))
    return Mechanism(
        bodies=(disc, block),
        joints=(Revolute("pivot", "world", "disc", "phi", clockwise=True),
                Prismatic("slot", "disc", "block", "x", axis=(1, 0))),
        forces=(CoordinateForce("spring_damper", "x", **coordinate_spring_damper(P.k, 0, P.c)),),
        prescribed=(Prescribed("motor", "phi", P.omega * TIME),),
    )


def printed(P):
    x, x_d, x_dd = coordinate_symbols("x")
    m, k, c, g, w = P.m, P.k, P.c, P.g, P.omega
    return (
        PrintedFormula("Fig. 29, eq. 84", "eom",
                       [m * x_dd + c * x_d + (k - m * w**2) * x - m * g * sp.sin(w * TIME)],
                       note="row of x, phi = omega t"),
        PrintedFormula("§8.5, critical speed", "frequency", sp.sqrt(k / m - w**2),
                       note="undamped frequency of the relative motion; zero at omega = "
                            "sqrt(k/m), beyond which the block is unstable"),
    )


def speed(omega: float, t_end: float, label: str) -> Scenario:
    checks = ("trajectory", "actuator", "steady_state") if omega < 10 else (
        "trajectory", "actuator", "growth_rate")
    return Scenario(f"omega_{omega:g}".replace(".", "_"), {"x": "x0"}, t_end=t_end,
                    overrides={"omega": omega}, checks=checks,
                    description=f"omega = {omega:g} rad/s: {label}")


SYSTEM = System(
    id="rotating_slot",
    title="Block in a radial slot of a turning disc",
    source="monograph §8.5, Fig. 29, eq. 84",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"phi": 0, "x": 0},
    printed=printed,
    validity=(),
    scenarios=(
        speed(5.0, 20.0, "well below the critical speed sqrt(k/m) = 10 rad/s (defaults)"),
        speed(9.5, 20.0, "just below the critical speed: soft relative spring, large "
                         "response to the weight"),
        speed(10.5, 2.0, "above the critical speed: the block runs away exponentially"),
    ),
    # in the disc's frame the weight is the excitation (eq. 84's right-hand side)
    unexcited={"g": 0.0},
    exact_solution="rotating_slot_eq84",
    excitation_frequencies=lambda P: (P.omega,),
)
