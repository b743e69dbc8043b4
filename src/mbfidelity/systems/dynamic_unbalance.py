"""Frame on a torsional spring excited by a dynamically unbalanced rotor (monograph §8.8,
Fig. 32, eq. 87-88): a spatial mechanism (model convention 10).

Geometry (z up; the rotor's axis horizontal, along the frame's x axis)::

          z |   frame b: turns by psi about the vertical on the torsional spring k_t,
            |   its centre of mass on that axis, moment I_Gb about it
        ----+----  rotor r: spun at phi = omega t about the frame's x axis by a motor,
            |      its centre of mass G at the crossing of the two axes

The rotor's central tensor in the monograph's rotor basis {e1, e2, e3} (e3 the spin axis,
e2 vertical at phi = 0) has the product I23: the spin axis is not principal. In the body
axes used here (x = e3, y = e1, z = e2, aligned with the frame at phi = 0) it reads
[[I3, 0, I23], [0, I1, 0], [I23, 0, I2]]; the vertical is then (sin phi, cos phi, 0) in
{e1, e2, e3}, the monograph's angular velocity Omega = (psi' sin phi, psi' cos phi, omega).
The frame's moments about the horizontal axes never act (it turns about the vertical
only): it is given the isotropic tensor I_Gb. Both centres of mass are on the axes, so
gravity does no work; the masses only let engines build the bodies.

The vertical component of the angular momentum theorem gives eq. 87; with I1 = I2 (the
rotor symmetric about its axis but for the product I23) its inertia about the vertical is
constant and eq. 88 is a torsional oscillator forced by I23 omega^2 sin(omega t).
Otherwise the coefficients vary with phi = omega t: a periodic-coefficient (parametric)
system, whose stability is Floquet's question, not an equilibrium's (the comparisons gate
a run against the linearization's modes, so the catalog's scenario is eq. 88's case; the
general one is checked against the derivation in tests/). The motor's torque
that keeps omega constant is the e3 component of the rotor's angular momentum derivative
printed in §8.8 (the prescribed spin's actuator force, convention 9).
"""
import sympy as sp

from . import Expectation, PrintedFormula, System, coordinate_symbols
from .model import (TIME, Body, Circle, CoordinateForce, Mechanism, Parameter, Prescribed,
                    Rectangle, Revolute, Scenario, coordinate_spring_damper)

PARAMETERS = (
    Parameter("I_Gb", 0.05, "kg m^2", "moment of inertia of the frame about the vertical",
              "Fig. 32"),
    Parameter("k_t", 10.0, "N m/rad", "torsional spring constant", "Fig. 32"),
    Parameter("I1", 0.01, "kg m^2", "rotor's central moment about e1 (horizontal, across "
              "the spin axis)", "Fig. 32"),
    Parameter("I2", "I1", "kg m^2", "rotor's central moment about e2 (default: I1, the "
              "case of eq. 88)", "Fig. 32"),
    Parameter("I3", 0.015, "kg m^2", "rotor's central moment about its spin axis e3",
              "Fig. 32"),
    Parameter("I23", 0.001, "kg m^2", "rotor's product of inertia of e2 and e3 (the dynamic "
              "unbalance)", "Fig. 32", domain="real"),
    Parameter("omega", 5.0, "rad/s", "spin speed of the rotor", "Fig. 32"),
    Parameter("m_b", 2.0, "kg", "mass of the frame (no part in the motion: its centre of "
              "mass is on the axis)", "chosen here"),
    Parameter("m_r", 1.0, "kg", "mass of the rotor (no part in the motion: its centre of "
              "mass is on both axes)", "chosen here"),
)

MOTOR = sp.Symbol("T_motor", real=True)


def build(P) -> Mechanism:
    frame = Body.spatial("frame", P.m_b, ((P.I_Gb, 0, 0), (0, P.I_Gb, 0), (0, 0, P.I_Gb)),
                         (Rectangle((0, 0), 0.3, 0.2),))
    rotor = Body.spatial("rotor", P.m_r, ((P.I3, 0, P.I23), (0, P.I1, 0), (P.I23, 0, P.I2)),
                         (Circle((0, 0), 0.08),))
    return Mechanism(
        bodies=(frame, rotor),
        joints=(Revolute("vertical", "world", "frame", "psi", axis=(0, 0, 1)),
                Revolute("spin", "frame", "rotor", "phi", axis=(1, 0, 0))),
        forces=(CoordinateForce("torsion_spring", "psi", **coordinate_spring_damper(P.k_t, 0)),),
        prescribed=(Prescribed("motor", "phi", P.omega * TIME),),
        up=(0, 0, 1),
    )


def printed(P):
    psi, psi_d, psi_dd = coordinate_symbols("psi")
    phi, phi_d, phi_dd = coordinate_symbols("phi")
    I1, I2, I23, I_Gb, k_t, w = P.I1, P.I2, P.I23, P.I_Gb, P.k_t, P.omega
    s, c = sp.sin(phi), sp.cos(phi)
    eq87 = ((I1 * s**2 + I2 * c**2 + I_Gb) * psi_dd + 2 * (I1 - I2) * s * c * w * psi_d
            + k_t * psi - I23 * w**2 * s)
    # e3 component of dL_Gr/dt as printed (§8.8): the motor's torque about the spin axis
    dL3 = (I23 * psi_dd * c - I23 * psi_d * w * s + I2 * psi_d**2 * s * c
           + I23 * psi_d * w * s - I1 * psi_d**2 * s * c)
    return (
        PrintedFormula("Fig. 32, eq. 87", "eom", [eq87], note="row of psi, phi = omega t"),
        PrintedFormula("Fig. 32, eq. 88", "eom",
                       [(I1 + I_Gb) * psi_dd + k_t * psi - I23 * w**2 * sp.sin(w * TIME)],
                       relations={"I2": "I1"},
                       note="row of psi with I1 = I2 = I_Gr, phi = omega t"),
        PrintedFormula("Fig. 32, §8.8 (eq. 87 and the e3 component of dL_Gr/dt: the motor "
                       "torque T_motor)", "eom", [eq87, dL3 - MOTOR],
                       multipliers=(MOTOR,), multiplier_forces={MOTOR: ("actuator:motor", 0)},
                       note="rows (psi, phi); phi = omega t, T_motor the motor's torque"),
    )


VERLET_START = (
    "Semi-implicit Euler's positions are the Stormer-Verlet sequence (second order) but for "
    "the first step, whose error h^2 a(0)/2 acts as an O(h) error of the initial velocity "
    "and makes the scheme first order; this scenario starts on the steady response at "
    "psi = 0, where the acceleration is zero, so the error falls as dt^2 (mbfidelity "
    "convergence).")
REFERENCE_FLOOR = (
    "At the study's default steps RK4's error meets the reference's own after two "
    "halvings, too few points above it for a fit; at coarser steps (mbfidelity convergence "
    "--steps) the fit shows RK4's fourth order.")

SYSTEM = System(
    id="dynamic_unbalance",
    title="Frame on a torsional spring with a dynamically unbalanced rotor (3-D)",
    source="monograph §8.8, Fig. 32, eq. 87-88",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"psi": 0, "phi": 0},
    printed=printed,
    scenarios=(
        Scenario("steady", {"psi": 0}, {"psi": "I23*omega**3/(k_t - (I1 + I_Gb)*omega**2)"},
                 t_end=5.0, checks=("trajectory", "actuator"),
                 description="started on the steady response of eq. 88 (psi = A sin(omega "
                             "t)): no free oscillation is excited (I1 = I2, no damping)"),
    ),
    unexcited={"I23": 0.0},
    excitation_frequencies=lambda P: (P.omega,),
    expectations=(Expectation("pybullet", "convergence.order", "xfail", VERLET_START),
                  Expectation("mujoco", "convergence.order", "unresolved", REFERENCE_FLOOR)),
)
