"""Arm turned by a motor, carrying a block that a linear actuator positions along a guide
(monograph §9.6, Fig. 35): one free coordinate (phi) and one forced one (x).

Geometry, reconstructed from the energies of §9.6 (phi counter-clockwise, 0 hanging)::

              O  pivot (horizontal axis), motor torque T_mot(t) on the arm
              |
              |  arm s: centre of mass G_s at b below O along the arm (the
            G_s o   m_s g b (1 - cos phi) of E_p), central inertia I_s
              |
     - - - - -+----[b]----->  guide of the arm, perpendicular to it at h below O;
              |<-x->|          the block b (m_b, central inertia I_b) at x along it

G_s = b (sin phi, -cos phi) and the block at h (sin phi, -cos phi) + x (cos phi, sin phi):
its height -h cos(phi) + x sin(phi) gives E_p's m_b g (h - h cos phi + x sin phi), and its
velocity (h phi' + x', x phi') in the arm's axes gives E_c's m_b (h^2 + x^2) phi'^2/2 +
m_b x'^2/2 + m_b h phi' x'; the block turns with the arm (I_b phi'^2/2). The linear
actuator imposes x(t) = x0 + x_a sin(Omega_x t) (a prescribed prismatic joint whose parent
is the arm; its force F_act, along +x, is the output); the motor's torque T_mot(t) =
T_a sin(Omega_T t) on phi is a time load. With both amplitudes zero the block stays at x0
and the arm rests where the weights balance, tan(phi) = -m_b x0 / (m_s b + m_b h).

Printed and coded: E_c, E_p, the derivative of E_p in phi, and Lagrange's equations for
x and phi with F_act as the unknown of the x row (a multiplier: the row that determines
it). The intermediate line dE_c/dx = m_b phi'^2 (the equations themselves carry
m_b phi'^2 x) has no formula kind to be coded with; P_nc = T_mot phi' + F_act x' contains
the actuator's unknown force and is not coded either.
"""
import sympy as sp

from . import PrintedFormula, System, coordinate_symbols
from .model import (TIME, Body, CoordinateForce, Mechanism, Parameter, Prescribed, Prismatic,
                    Rectangle, Revolute, Scenario, Segment)

PARAMETERS = (
    Parameter("I_s", 0.05, "kg m^2", "central moment of inertia of the arm s",
              "Fig. 35"),
    Parameter("m_s", 1.0, "kg", "mass of the arm s", "Fig. 35"),
    Parameter("b", 0.3, "m", "distance from O to the arm's centre of mass",
              "Fig. 35"),
    Parameter("I_b", 0.001, "kg m^2", "central moment of inertia of the block b",
              "Fig. 35"),
    Parameter("m_b", 0.5, "kg", "mass of the block b", "Fig. 35"),
    Parameter("h", 0.1, "m", "offset of the guide from O along the arm",
              "Fig. 35"),
    Parameter("T_a", 0.5, "N m", "amplitude of the motor torque T_mot(t) = T_a sin(Omega_T t)",
              "project default", domain="real"),
    Parameter("Omega_T", 3.0, "rad/s", "angular frequency of the motor torque",
              "project default"),
    Parameter("x0", 0.1, "m", "mean position of the block, x(t) = x0 + x_a sin(Omega_x t)",
              "project default", domain="real"),
    Parameter("x_a", 0.05, "m", "amplitude of the imposed position", "project default",
              domain="real"),
    Parameter("Omega_x", 2.0, "rad/s", "angular frequency of the imposed position",
              "project default"),
)

F_ACT = sp.Symbol("F_act", real=True)


def rest_angle(P):
    """The arm's rest angle with both excitations off (block at x0)."""
    return -sp.atan(P.m_b * P.x0 / (P.m_s * P.b + P.m_b * P.h))


def build(P) -> Mechanism:
    # the arm's frame sits at G_s: O is the body point (0, b), the guide's origin (0, b - h)
    arm = Body("arm", P.m_s, P.I_s, (Segment((0, P.b), (0, P.b - P.h)),
                                      Segment((-0.1, P.b - P.h), (0.25, P.b - P.h))))
    block = Body("block", P.m_b, P.I_b, (Rectangle((0, 0), 0.04, 0.03),))
    return Mechanism(
        bodies=(arm, block),
        joints=(Revolute("pivot", "world", "arm", "phi", child_anchor=(0, P.b)),
                Prismatic("guide", "arm", "block", "x", axis=(1, 0),
                          parent_anchor=(0, P.b - P.h))),
        forces=(CoordinateForce("motor", "phi", P.T_a * sp.sin(P.Omega_T * TIME)),),
        prescribed=(Prescribed("actuator", "x", P.x0 + P.x_a * sp.sin(P.Omega_x * TIME)),),
    )


def printed(P):
    phi, phi_d, phi_dd = coordinate_symbols("phi")
    x, x_d, x_dd = coordinate_symbols("x")
    I_s, m_s, b, I_b, m_b, h, g = P.I_s, P.m_s, P.b, P.I_b, P.m_b, P.h, P.g
    T_mot = P.T_a * sp.sin(P.Omega_T * TIME)
    inertia = I_s + m_s * b**2 + I_b + m_b * (h**2 + x**2)  # I of §9.6
    dEp_dphi = m_s * g * b * sp.sin(phi) + m_b * g * (h * sp.sin(phi) + x * sp.cos(phi))
    return (
        PrintedFormula("Fig. 35, §9.6 (E_c)", "kinetic_energy",
                       inertia * phi_d**2 / 2 + m_b * x_d**2 / 2 + m_b * h * phi_d * x_d),
        PrintedFormula("Fig. 35, §9.6 (E_p)", "potential_energy",
                       m_s * g * b * (1 - sp.cos(phi))
                       + m_b * g * (h - h * sp.cos(phi) + x * sp.sin(phi))),
        PrintedFormula("Fig. 35, §9.6 (dE_p/dphi)", "potential_gradient", [dEp_dphi]),
        # rows in system order (phi, x); F_act, the actuator's unknown force, enters the
        # x row only, which determines it
        PrintedFormula("Fig. 35, §9.6 (Lagrange equations, F_act of the actuator)", "eom", [
            inertia * phi_dd + 2 * m_b * x * x_d * phi_d + m_b * h * x_dd + dEp_dphi - T_mot,
            m_b * (x_dd + h * phi_dd) - m_b * phi_d**2 * x + m_b * g * sp.sin(phi) - F_ACT],
            multipliers=(F_ACT,), multiplier_forces={F_ACT: ("actuator:actuator", 0)},
            note="T_mot(t) = T_a sin(Omega_T t); x(t) imposed; F_act: the actuator's force"),
    )


SYSTEM = System(
    id="actuated_arm",
    title="Arm with a motor and a block positioned by a linear actuator",
    source="monograph §9.6, Fig. 35",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"phi": rest_angle(P), "x": P.x0},
    printed=printed,
    scenarios=(
        Scenario("driven", {"phi": "-atan(m_b*x0/(m_s*b + m_b*h))", "x": "x0"},
                 {"x": "x_a*Omega_x"}, t_end=10.0, checks=("trajectory", "actuator"),
                 description="from rest at the arm's unexcited rest angle: the motor torque "
                             "and the block's imposed motion act together (no damping)"),
    ),
    unexcited={"T_a": 0.0, "x_a": 0.0},
    excitation_frequencies=lambda P: (P.Omega_T, P.Omega_x),
)
