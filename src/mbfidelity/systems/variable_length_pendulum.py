"""Pendulum of variable length (monograph §3.2, Fig. 11, eq. 14).

Geometry (φ from the downward vertical, counter-clockwise positive)::

        O  (the string passes through a hole at O; its end Q is pulled to height h(t))
         \\
          \\  l = l0 - h(t), the string's free length OP
           P  particle m

The string is inextensible and perfectly flexible: the particle P moves on the line OP,
which turns about O, at the distance l(t) = l0 - h(t) imposed by the motion of the end Q.
Here a massless arm turns about O (coordinate φ) and the particle slides on it
(coordinate l, prescribed: convention 9); the actuator's force on l is minus the string's
pull F. The particle is given a small central inertia I_G (chosen here: the engines need
one; it turns with the string); the printed equations are for a particle and are compared
with I_G = 0.

Derivation (Lagrange, T = m (l'^2 + l^2 φ'^2)/2 + I_G φ'^2/2, V = -m g l cos φ):
(I_G + m l^2) φ'' + 2 m l l' φ' + m g l sin φ = 0, which is eq. 14's first line for
I_G = 0; the pull F = m (g cos φ + l φ'^2 - l''), the radial equation of P.
With h(t) periodic the coefficients are periodic in time (parametric vibrations, §3.2):
the rest state φ = 0 with h = 0 is judged by Floquet theory (analytic/floquet.py).

Printed F (eq. 14, second line) against the derivation: the printed m (-h'' + h'^2 +
g cos φ) cos φ has the sign of h'' reversed, h'^2 where the centripetal term l φ'^2
stands, and an extra factor cos φ; `mbfidelity errata` reports it.
"""
import sympy as sp

from . import Expectation, PrintedFormula, System, coordinate_symbols
from .model import (TIME, Body, Circle, Mechanism, Parameter, Prescribed, Prismatic,
                    Revolute, Scenario)

PYBULLET_TIME_VARYING_INERTIA = (
    "PyBullet's semi-implicit Euler on the time-varying inertia m l(t)^2 of the swing is not "
    "symplectic: the pumped swing's phase drifts at first order, just beyond the gate at "
    "every step (the error and the gate both halve with the step).")

PARAMETERS = (
    Parameter("m", 1.0, "kg", "mass of the particle", "Fig. 11"),
    Parameter("I_G", 1e-5, "kg m^2", "central inertia of the particle (not in the catalog: "
              "the engines need one; the printed equations take it zero)", "chosen here"),
    Parameter("l0", 1.0, "m", "free length of the string with h = 0", "Fig. 11"),
    Parameter("h_a", 0.05, "m", "amplitude of the end's height h(t) = h_a sin(Omega t)",
              "project default", domain="real"),
    Parameter("Omega", "2*sqrt(g/l0)", "rad/s", "angular frequency of h(t) (twice the "
              "small-swing frequency: parametric resonance)", "project default"),
    Parameter("phi0", 0.05, "rad", "initial angle, released from rest", "project default",
              domain="real"),
)


def length(P):
    return P.l0 - P.h_a * sp.sin(P.Omega * TIME)


def build(P) -> Mechanism:
    arm = Body("arm", 0, 0)
    particle = Body("particle", P.m, P.I_G, (Circle((0, 0), 0.03),))
    return Mechanism(
        bodies=(arm, particle),
        joints=(Revolute("pivot", "world", "arm", "phi"),
                Prismatic("string", "arm", "particle", "l", axis=(0, -1), limits=(0, None))),
        prescribed=(Prescribed("string_pull", "l", length(P)),),
    )


def printed(P):
    phi, phi_d, phi_dd = coordinate_symbols("phi")
    l, l_d, l_dd = coordinate_symbols("l")
    m, g = P.m, P.g
    # eq. 14 is written with h = l0 - l: h' = -l', h'' = -l''
    h_d, h_dd = -l_d, -l_dd
    pull = m * (-h_dd + h_d**2 + g * sp.cos(phi)) * sp.cos(phi)
    return (
        PrintedFormula("Fig. 11, eq. 14 (equation of motion)", "eom",
                       [l * phi_dd + 2 * l_d * phi_d + g * sp.sin(phi)],
                       note="row of phi, divided by m l", relations={"I_G": 0}),
        # the actuator pushes along l: its force is minus the string's pull F
        PrintedFormula("Fig. 11, eq. 14 (string pull F)", "constraint_force",
                       ("actuator:string_pull", -pull), relations={"I_G": 0}),
        PrintedFormula("§3.2, phi = 0 with h = 0", "equilibrium", {"phi": 0}),
    )


SYSTEM = System(
    id="variable_length_pendulum",
    title="Pendulum of variable length (string pulled through a hole)",
    source="monograph §3.2, Fig. 11, eq. 14",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"phi": 0},
    printed=printed,
    scenarios=(
        Scenario("pumped", {"phi": "phi0"}, t_end=10.0,
                 checks=("trajectory", "actuator"),
                 description="released 0.05 rad from hanging, the string's length modulated "
                             "at twice the swing frequency: the swing grows (parametric "
                             "resonance)"),
        # the growing Floquet solution about phi = 0 starts almost as a pure velocity
        # (h(0) = 0, rising): a release from rest first decays along the other one
        # a deeper modulation (h_a = 0.15 m) grows three times faster, so that the rate
        # is read within a short run
        Scenario("growth", {"phi": 0}, qd0={"phi": "phi0*sqrt(g/l0)"}, t_end=12.0,
                 overrides={"phi0": 0.002, "h_a": 0.15}, checks=("trajectory", "floquet"),
                 description="launched from hanging at 0.002 sqrt(g/l0) rad/s, h_a = 0.15 m: "
                             "the swing grows at the Floquet rate, read while it stays linear"),
    ),
    unexcited={"h_a": 0.0},
    expectations=(Expectation("pybullet", "pumped.trajectory_max", "xfail",
                              PYBULLET_TIME_VARYING_INERTIA),
                  Expectation("mujoco", "convergence.order", "unresolved",
                              "At the study's default steps RK4's error meets the "
                              "reference's own after one halving, too few points above it "
                              "for a fit; at coarser steps (mbfidelity convergence --steps) "
                              "the fit shows RK4's fourth order."),),
    excitation_frequencies=lambda P: (P.Omega,),
    notes="Parametric resonance at Omega = 2 sqrt(g/l0): the swing grows at the Floquet rate "
          "ln|mu|max / T about phi = 0.",
)
