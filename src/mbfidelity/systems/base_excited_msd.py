"""Mass-spring-damper excited through its support (monograph §8.2, Fig. 25-26).

Geometry (horizontal guide; the spring and damper are relaxed at z = 0)::

      base (prescribed)            block m
     |<- y(t) ->|                 |<- z ->|
     [  P  ]--/\\/\\/--[ m ]    x = y + z: the block's absolute position
            |--[ c ]--|

The base carries the end P of the spring-damper and is moved as y(t) = Y sin(Omega t) by
an actuator; the block slides on the base's line (coordinate z relative to P, the
spring's and damper's deformation, the monograph's relative coordinate). The monograph's
absolute coordinate x is the block's position in the fixed frame; `absolute_mechanism`
writes the same system with x as the joint coordinate (block guided by the ground) so that
the two derivations can be compared (tests/hand). The actuator drives the base (mass m_P, not in the
catalog): its force is m_P y'' plus the force F_ext of §8.2 that holds P against the spring
and the damper.

Printed: the absolute equation m x'' + c x' + k x = c y' + k y and the relative one
m z'' + c z' + k z = -m y'' (§8.2). The energies of §8.2 leave the base out (or take it
massless); the description gives it a mass, so they are not compared.
"""
import sympy as sp

from . import PrintedFormula, System, coordinate_symbols
from .model import (LENGTH, LENGTH_RATE, TIME, Body, CoordinateForce, Mechanism, Parameter,
                    PointToPoint,
                    Prescribed, Prismatic, Rectangle, Scenario, coordinate_spring_damper)

#: length of the block and the base drawings; the absolute formulation's spring runs
#: between P and the block's centre, this far apart when relaxed (a drawing length: the
#: equations do not depend on it)
GAP = 0.3

PARAMETERS = (
    Parameter("m", 1.0, "kg", "mass of the block", "Fig. 25"),
    Parameter("k", 100.0, "N/m", "spring constant", "Fig. 25"),
    Parameter("c", 2.0, "N s/m", "viscous damping", "Fig. 25",
              domain="nonnegative"),
    Parameter("m_P", 0.5, "kg", "mass of the moving base that carries P (not in the catalog: "
              "the engines need a body to drive; it changes the actuator force only)",
              "chosen here"),
    Parameter("Y", 0.01, "m", "amplitude of the base motion y(t) = Y sin(Omega t)",
              "project default", domain="real"),
    Parameter("ratio", 1.0, "1", "base frequency over the natural frequency sqrt(k/m) (the "
              "transmissibility scenarios set it)", "chosen here"),
    Parameter("Omega", "ratio*sqrt(k/m)", "rad/s", "angular frequency of the base motion",
              "project default"),
)


def base_motion(P):
    return P.Y * sp.sin(P.Omega * TIME)


def build(P) -> Mechanism:
    """The relative formulation: the block on the moving base (coordinate z)."""
    base = Body("base", P.m_P, P.m_P * (0.05**2 + 0.2**2) / 12,
                (Rectangle((0, 0), 0.05, 0.2),))
    block = Body("block", P.m, P.m * (0.1**2 + 0.1**2) / 12, (Rectangle((0, 0), 0.1, 0.1),))
    return Mechanism(
        bodies=(base, block),
        joints=(Prismatic("base_guide", "world", "base", "y", axis=(1, 0)),
                Prismatic("block_guide", "base", "block", "z", axis=(1, 0),
                          parent_anchor=(GAP, 0))),
        forces=(CoordinateForce("spring_damper", "z", **coordinate_spring_damper(P.k, 0, P.c)),),
        prescribed=(Prescribed("actuator", "y", base_motion(P)),),
    )


def absolute_mechanism(P) -> Mechanism:
    """The absolute formulation of §8.2: the block guided by the ground (coordinate x),
    the spring-damper between P and the block (same physics, same actuator)."""
    base = Body("base", P.m_P, P.m_P * (0.05**2 + 0.2**2) / 12,
                (Rectangle((0, 0), 0.05, 0.2),))
    block = Body("block", P.m, P.m * (0.1**2 + 0.1**2) / 12, (Rectangle((0, 0), 0.1, 0.1),))
    stretch = LENGTH - GAP
    return Mechanism(
        bodies=(base, block),
        joints=(Prismatic("base_guide", "world", "base", "y", axis=(1, 0)),
                Prismatic("block_guide", "world", "block", "x", axis=(1, 0),
                          parent_anchor=(GAP, 0))),
        forces=(PointToPoint("spring_damper", "base", (0, 0), "block", (0, 0),
                             tension=P.k * stretch + P.c * LENGTH_RATE,
                             potential=P.k * stretch**2 / 2),),
        prescribed=(Prescribed("actuator", "y", base_motion(P)),),
    )


def printed(P):
    z, z_d, z_dd = coordinate_symbols("z")
    y, y_d, y_dd = coordinate_symbols("y")
    m, k, c = P.m, P.k, P.c
    return (
        PrintedFormula("§8.2, relative coordinate z (frame of P)", "eom",
                       [m * z_dd + c * z_d + k * z + m * y_dd], note="row of z"),
        PrintedFormula("§8.2, relative coordinate, Galilean frame", "eom",
                       [m * (z_dd + y_dd) + c * z_d + k * z], note="row of z"),
        # the absolute equation, written with its definition x = y + z
        PrintedFormula("§8.2, absolute coordinate x = y + z", "eom",
                       [m * (y_dd + z_dd) + c * (y_d + z_d) + k * (y + z) - c * y_d - k * y],
                       note="row of z, x = y + z substituted"),
    )


def transmissibility_scenario(ratio: float) -> Scenario:
    return Scenario(f"omega_{ratio:g}wn".replace(".", "_"), {"z": 0}, t_end=10.0,
                    overrides={"ratio": ratio},
                    checks=("trajectory", "actuator", "steady_state"),
                    description=f"from rest, base at Omega = {ratio:g} sqrt(k/m): transient, "
                                f"then the steady state whose amplitude ratio is the "
                                f"transmissibility")


SYSTEM = System(
    id="base_excited_msd",
    title="Mass-spring-damper excited through its base",
    source="monograph §8.2, Fig. 25-26",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"z": 0},
    printed=printed,
    scenarios=(
        transmissibility_scenario(0.5),
        transmissibility_scenario(1.0),
        transmissibility_scenario(2.0),
    ),
    unexcited={"Y": 0.0},
    # the monograph's absolute coordinate: the block's position in the fixed frame
    observables=lambda P: {"x": sp.Symbol("y", real=True) + sp.Symbol("z", real=True)},
    exact_solution="base_excited_relative",
    excitation_frequencies=lambda P: (P.Omega,),
    notes="Transmissibility: |X/Y| = sqrt(k^2 + (c Omega)^2) / |k - m Omega^2 + i c Omega| "
          "(absolute x = y + z) and |Z/Y| = m Omega^2 / |k - m Omega^2 + i c Omega| "
          "(relative z).",
)
