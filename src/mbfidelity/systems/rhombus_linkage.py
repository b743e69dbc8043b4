"""Rhombus of four equal bars with an internal spring (monograph §4.4, Fig. 13, eq. 34-36).

Geometry, reconstructed from the printed kinetic and potential energies (eq. 34)::

                 P = (0, 4 l sin phi): slides on the vertical through O (pin in a slot)
                / \\
      bar BP   /   \\   bar AP
              /     \\
             B       A      A = 2l (cos phi, sin phi), B = 2l (-cos phi, sin phi)
              \\     /
       bar OB  G2~~G1  bar OA     ~~ spring k between the centres G2 of OB and G1 of OA:
                \\ /                 length 2 l |cos phi|, free length sqrt2 l - 4 m g/k
                 O  fixed pivot (world origin)

phi is the angle of the bars OA and BP above the horizontal (counter-clockwise); the bars
OB and AP make the angle pi - phi. Each bar: mass m, length 2l, central inertia I_G.

Where each choice comes from:
- Rhombus O-A-P-B with P on the vertical through O: Fig. 13 as described in §4.4. Every bar turns at the rate |phi_dot| and the centres of the upper bars
  are at (+-l cos phi, 3 l sin phi); this gives 4 I_G + (4 + 16 cos^2 phi) m l^2, the
  printed inertia of eq. 34-35, only if phi is measured from the HORIZONTAL.
- Sense of phi (P above O for phi > 0): the weight of a rhombus whose diagonal OP is
  vertical is 2 m g y_P = 8 m g l sin(phi), the sin(phi) term of eq. 34; the printed
  linearized stiffness 2 k l^2 - 8 sqrt2 m g l (weight destabilizing) confirms that the
  rhombus stands on O.
- Spring: 2 k l^2 (cos phi - sqrt2/2)^2 = k/2 (2 l cos phi - sqrt2 l)^2 is a spring between
  two points 2 l cos phi apart: the centres G1, G2 of the two lower bars (the centres of
  the upper bars would give the same energy).
- Free length of the spring: sqrt2 l - 4 m g / k, so that its tension at 45 deg is 4 m g.
  §4.4 says the spring guarantees the equilibrium at phi = 45 deg, and the printed E_p of
  eq. 34 is exactly 8 m g l sin(phi) + k/2 (2 l cos phi - (sqrt2 l - 4 m g/k))^2 minus the
  constant 8 m^2 g^2/k: its term 8 m g l (cos phi - sqrt2/2), which no weight can produce,
  is the work of that preload, grouped with the weight. With this free length every
  printed formula of §4.4 follows (phi_eq = 45 deg, eq. 35, 36 and the linearized
  equation). A spring relaxed at 45 deg instead (a reading of §4.4's words alone): then 45 deg is
  not an equilibrium (V'(45 deg) = 4 sqrt2 m g l), the standing rhombus has no equilibrium
  at the defaults and it hangs far below (the variant is one line in `build`).

Equilibria at the defaults (V = 8 m g l sin phi + k/2 (2 l |cos phi| - l0)^2): 45 deg
(stable) and 27.6 deg (unstable: the standing rhombus is only held against a collapse
through the flat position by a barrier of 0.33 J), the hanging rhombus at -65.2 deg
(stable), and the mirror images (A and B swapped, phi -> pi - phi) of all three.

Coordinates: phi (bar OA) is independent. The other bars have their own angle coordinates
(phi_OB, phi_AP, phi_BP), chosen so that all four equal phi on the assembly branch of
the figure; the closures are P of AP = P of BP (PointOnPoint) and P on the vertical through
O (PointOnLine, the slot force; by the mirror symmetry it is zero along every motion
that starts on the figure's branch, and so is the vertical component of the pin force at
P). The flat position (phi = 0, P = O) and the upright/hanging stacks (phi = +-90 deg,
spring of zero length) are singular and are not crossed by the scenarios.
"""
import sympy as sp

from . import PrintedFormula, System, coordinate_symbols
from .model import (Body, Mechanism, Parameter, PointOnLine, PointOnPoint, PointToPoint,
                    Revolute, Scenario, Segment, linear_spring_damper)

PARAMETERS = (
    Parameter("m", 1.0, "kg", "mass of each bar", "Fig. 13"),
    Parameter("l", 0.25, "m", "half length of each bar (bars are 2l long)", "project default"),
    Parameter("I_G", "m*(2*l)**2/12", "kg m^2",
              "central moment of inertia of each bar (default: uniform bar, m(2l)^2/12)",
              "project default"),
    Parameter("k", 400.0, "N/m",
              "spring constant (free length sqrt2 l - 4 m g/k: tension 4 m g at 45 deg)",
              "eq. 34"),
)


def free_length(P):
    """sqrt2 l - 4 m g / k: the spring's tension at 45 deg, 4 m g, holds the weight there
    (eq. 34 and the 45 deg equilibrium of §4.4)."""
    return sp.sqrt(2) * P.l - 4 * P.m * P.g / P.k


def build(P) -> Mechanism:
    def bar(name):
        return Body(name, P.m, P.I_G, (Segment((-P.l, 0), (P.l, 0)),))

    end, start = (P.l, 0), (-P.l, 0)
    return Mechanism(
        bodies=(bar("OA"), bar("OB"), bar("AP"), bar("BP")),
        joints=(
            # bar OA at +phi from the horizontal
            Revolute("O_A", "world", "OA", "phi", child_anchor=start),
            # bar OB at pi - phi_OB
            Revolute("O_B", "world", "OB", "phi_OB", child_anchor=start,
                     angle_offset=sp.pi, clockwise=True),
            # bar AP at pi - phi_AP (absolute), hinged at A
            Revolute("A", "OA", "AP", "phi_AP", parent_anchor=end, child_anchor=start,
                     angle_offset=sp.pi, clockwise=True, absolute=True),
            # bar BP at +phi_BP (absolute), hinged at B
            Revolute("B", "OB", "BP", "phi_BP", parent_anchor=end, child_anchor=start,
                     absolute=True),
        ),
        constraints=(
            PointOnPoint("P", "AP", end, "BP", end),
            PointOnLine("slot", "AP", end, "world", (0, 0), (0, 1)),
        ),
        independent=("phi",),
        forces=(PointToPoint("spring", "OA", (0, 0), "OB", (0, 0),
                             **linear_spring_damper(P.k, free_length(P))),),
    )


def printed(P):
    phi, phi_d, phi_dd = coordinate_symbols("phi")
    m, l, I_G, k, g = P.m, P.l, P.I_G, P.k, P.g
    s, c, r2 = sp.sin(phi), sp.cos(phi), sp.sqrt(2) / 2
    inertia = 4 * I_G + (4 + 16 * c**2) * m * l**2
    F_red = 8 * m * g * l * (-c + s) + 4 * k * l**2 * (c - r2) * s
    q45 = {name: sp.pi / 4 for name in ("phi", "phi_OB", "phi_AP", "phi_BP")}
    return (
        PrintedFormula("Fig. 13, eq. 34 (kinetic energy)", "kinetic_energy",
                       sp.Rational(1, 2) * inertia * phi_d**2),
        PrintedFormula("Fig. 13, eq. 34 (potential energy)", "potential_energy",
                       8 * m * g * l * (s + c - r2) + 2 * k * l**2 * (c - r2) ** 2),
        PrintedFormula("Fig. 13, eq. 35 (reduced inertia m(phi))", "kinetic_energy",
                       sp.Rational(1, 2) * inertia * phi_d**2,
                       note="m(phi) compared through m(phi) phi_dot^2/2"),
        PrintedFormula("Fig. 13, eq. 35 (reduced conservative force)", "potential_gradient",
                       [-F_red], note="F_red compared as -dE_p/dphi along the mechanism"),
        PrintedFormula("Fig. 13, eq. 36", "eom", [
            inertia * phi_dd - 16 * m * l**2 * c * s * phi_d**2
            - 8 * m * g * l * (-c + s) - 4 * k * l**2 * (c - r2) * s]),
        PrintedFormula("Fig. 13, §4.4 text (phi_eq = 45 deg)", "equilibrium", q45,
                       note="all four bar coordinates equal phi on the figure's branch"),
        PrintedFormula("Fig. 13, linearized eq. after eq. 36 (inertia at 45 deg)", "M",
                       sp.Matrix([[4 * I_G + 12 * m * l**2]]), at=q45),
        PrintedFormula("Fig. 13, linearized eq. after eq. 36 (stiffness at 45 deg)", "K",
                       sp.Matrix([[2 * k * l**2 - 8 * sp.sqrt(2) * m * g * l]]), at=q45,
                       note="45 deg, where the preloaded spring holds the weight"),
    )


def _start(phi0):
    return {"phi": phi0, "phi_OB": phi0, "phi_AP": phi0, "phi_BP": phi0}


_CHECKS = ("trajectory", "constraint_force")

SYSTEM = System(
    id="rhombus_linkage",
    title="Rhombus of four equal bars with an internal spring",
    source="monograph §4.4, Fig. 13, eq. 34-36",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: _start(sp.pi / 4),
    printed=printed,
    scenarios=(
        Scenario("small", _start(sp.pi / 4 + 0.05), checks=_CHECKS,
                 description="0.05 rad above the standing equilibrium phi = 45 deg"),
        Scenario("large", _start(sp.pi / 4 - 0.2), checks=_CHECKS,
                 description="0.2 rad below 45 deg from rest: swings between 33.5 and 52.5 "
                             "deg, strongly nonlinear (the collapse barrier is at 27.6 deg; "
                             "from 0.2 rad above 45 deg the rhombus would collapse)"),
    ),
    notes="spring free length sqrt2 l - 4 m g/k (tension 4 m g at 45 deg), reconstructed "
          "from eq. 34; a spring 'relaxed at 45 deg' contradicts every printed formula",
)
