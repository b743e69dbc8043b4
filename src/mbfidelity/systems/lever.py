"""Lever on a torsional spring, driven by a force perpendicular to it (monograph §3.2,
Fig. 10, eq. 12-13).

Geometry, reconstructed from eq. 12 (phi from the horizontal, counter-clockwise)::

                         F(t) (perpendicular to the lever, at l from O; positive
                       \\      clockwise: its moment about O is -l F)
                    G   \\
                 .-o-----*
           phi .-'          G: centre of mass at e from O along the lever:
        O  o-'  ) - - - -      its height e sin(phi) gives eq. 12's weight term
          torsional spring k, neutral angle phi_n

The weight's moment about O is -m g e cos(phi), so eq. 12's term m g e (cos phi -
cos phi0) together with k (phi - phi0) is a linear spring whose neutral angle phi_n =
phi0 + m g e cos(phi0) / k makes phi0 the equilibrium with F = 0 (the preload of the
catalog, a formula default of phi_n). The force always stays perpendicular to the lever
(a follower force), so it is written as its moment -l F(t) on phi (a time load): the
motion is the same; the pivot reaction would differ by the force itself, and it is not
checked.

Printed and coded: eq. 12 (its spring term holds with the default phi_n, imposed as a
relation), the equilibrium phi0, and eq. 13's inertia I_O and stiffness k - m g e
sin(phi0).
"""
import sympy as sp

from . import Condition, PrintedFormula, System, coordinate_symbols
from .model import (TIME, Body, CoordinateForce, Mechanism, Parameter, Revolute, Scenario,
                    Segment, coordinate_spring_damper)

PARAMETERS = (
    Parameter("I_O", 0.1, "kg m^2", "moment of inertia of the lever about O",
              "Fig. 10"),
    Parameter("m", 1.0, "kg", "mass of the lever", "Fig. 10"),
    Parameter("e", 0.2, "m", "distance from O to the centre of mass, along the lever",
              "eq. 12"),
    Parameter("k", 20.0, "N m/rad", "torsional spring constant", "Fig. 10"),
    Parameter("phi0", float(sp.pi / 6), "rad", "equilibrium angle with F = 0 (30 deg)",
              "Fig. 10", domain="real"),
    Parameter("phi_n", "phi0 + m*g*e*cos(phi0)/k", "rad",
              "neutral angle of the torsional spring (default: the preload that makes phi0 "
              "the equilibrium)", "eq. 12", domain="real"),
    Parameter("l", 0.4, "m", "distance from O to where F acts", "eq. 12"),
    Parameter("F_a", 1.0, "N", "amplitude of F(t) = F_a sin(Omega t)", "project default",
              domain="real"),
    Parameter("Omega", 10.0, "rad/s", "angular frequency of F(t)", "project default"),
)


def preload_relation(P) -> dict:
    """phi_n as the monograph's eq. 12 implies it: phi0 is the equilibrium with F = 0."""
    return {"phi_n": P.phi0 + P.m * P.g * P.e * sp.cos(P.phi0) / P.k}


def build(P) -> Mechanism:
    # the lever's frame sits at G; O is the body point (-e, 0)
    lever = Body("lever", P.m, P.I_O - P.m * P.e**2, (Segment((-P.e, 0), (P.l - P.e, 0)),))
    return Mechanism(
        bodies=(lever,),
        joints=(Revolute("pivot", "world", "lever", "phi", child_anchor=(-P.e, 0)),),
        forces=(
            CoordinateForce("spring", "phi", **coordinate_spring_damper(P.k, P.phi_n)),
            CoordinateForce("force", "phi", -P.l * P.F_a * sp.sin(P.Omega * TIME)),
        ),
    )


def printed(P):
    phi, phi_d, phi_dd = coordinate_symbols("phi")
    I_O, m, g, e, k, phi0, l = P.I_O, P.m, P.g, P.e, P.k, P.phi0, P.l
    F = P.F_a * sp.sin(P.Omega * TIME)
    preload = preload_relation(P)
    return (
        PrintedFormula("Fig. 10, eq. 12", "eom",
                       [I_O * phi_dd + m * g * e * (sp.cos(phi) - sp.cos(phi0))
                        + k * (phi - phi0) + l * F],
                       relations=preload, note="row of phi; F(t) = F_a sin(Omega t)"),
        PrintedFormula("Fig. 10, equilibrium phi0 (F = 0)", "equilibrium", {"phi": phi0},
                       relations=preload),
        PrintedFormula("eq. 13 (inertia)", "M", sp.Matrix([[I_O]]), relations=preload),
        PrintedFormula("eq. 13 (stiffness)", "K",
                       sp.Matrix([[k - m * g * e * sp.sin(phi0)]]), relations=preload),
    )


SYSTEM = System(
    id="lever",
    title="Lever on a torsional spring driven by a perpendicular force",
    source="monograph §3.2, Fig. 10, eq. 12-13",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"phi": P.phi0},
    printed=printed,
    validity=(
        Condition("I_O > m*e**2", "the lever's central moment of inertia, I_O - m e^2, must "
                                  "be positive"),
    ),
    scenarios=(
        Scenario("free", {"phi": "phi0 + 0.05"}, overrides={"F_a": 0.0},
                 description="F = 0, released from rest 0.05 rad above phi0"),
        Scenario("forced", {"phi": "phi0"},
                 description="from rest at phi0, F(t) = F_a sin(Omega t) (no damping: the "
                             "free oscillation at the natural frequency persists)"),
    ),
    unexcited={"F_a": 0.0},
    excitation_frequencies=lambda P: (P.Omega,),
)
