"""Quarter-car suspension with a hardening spring, on flat ground and on a rough road
(monograph §2.2, Fig. 4-6, eq. 1-3; §3.2, Fig. 9, eq. 10-11).

Geometry (vertical; x and y both measured DOWNWARD)::

        +-----------+
        |  chassis  |   sprung mass m; x = its downward displacement from where the
        +-----------+   spring is relaxed with the road point P at y = 0
              |
              /  suspension (spring and tyre in one element): repulsion
              \\  f(s) = k_s s (1 + (s/x_s)^2), s = x - y the compression
              /
              |
        ======P======   road point / wheel (mass m_P), moved by the road profile:
                        y(t) = Y sin(2 pi v t / lam), downward like x

On flat ground (y = 0) the compression is x itself and m x'' = m g - f(x) (eq. 1); on the
road it is x - y(t) and m x'' = m g - f(x - y(t)) (eq. 10). That eq. 10 writes the
compression as x - y fixes the sense of y: along x, i.e. downward (Fig. 9 is not in the
text; a road height measured upward would make the compression x + y). The road profile
is symmetric, so the sense only flips the phase of the excitation.

The static equilibrium x_eq solves f(x_eq) = m g (Fig. 6); f is strictly increasing, so it
is the cubic's only real root (Cardano, `static_compression`). About it the tangent of
Fig. 6 has slope k = f'(x_eq) = k_s (1 + 3 x_eq^2 / x_s^2), the k of eq. 2, 3 and 11.

The road point is a body P of mass m_P (not in the catalog: the engines need a body to
drive; it changes the actuator force only), on a vertical guide, its coordinate y
prescribed (the road acts as the actuator of §4.5 and Fig. 26). The chassis has its own
vertical guide; the suspension acts between the chassis and P along the vertical, drawn
`SPRING_LENGTH` long when relaxed (a drawing length: the equations do not depend on it).
The law is used for extension too (s < 0, where a real tyre would leave the road); the
scenarios stay in compression.

Printed and coded: eq. 1 and 10 as equations of motion (eq. 1 on flat ground, Y = 0), the
equilibrium f(x_eq) = m g, and the linearized eq. 2-3 (inertia m, stiffness the tangent's
slope k, frequency sqrt(k/m)). Eq. 11, m eps'' + k eps = k y(t), has eq. 3's left-hand
side; its right-hand side is the linear term of -f(x - y) in y (tests/hand/suspension.py).
"""
from types import SimpleNamespace

import sympy as sp

from . import Condition, PrintedFormula, System, coordinate_symbols
from .model import (GRAVITY, LENGTH, TIME, Body, Mechanism, Parameter, PointToPoint,
                    Prescribed, Prismatic, Rectangle, Scenario)

#: drawn distance between the chassis' centre and P with the spring relaxed (m)
SPRING_LENGTH = sp.Rational(1, 2)

PARAMETERS = (
    Parameter("m", 250.0, "kg", "sprung mass (a quarter of the car)", "Fig. 4"),
    Parameter("k_s", 2e4, "N/m", "small-compression stiffness of the suspension",
              "Fig. 4"),
    Parameter("x_s", 0.1, "m", "compression at which the cubic term equals the linear one "
              "(hardening)", "Fig. 4"),
    Parameter("Y", 0.01, "m", "amplitude of the road profile y(t) = Y sin(2 pi v t / lam)",
              "Fig. 9", domain="real"),
    Parameter("v", 20.0, "m/s", "speed of the car along the road", "Fig. 9"),
    Parameter("lam", 5.0, "m", "wavelength lambda of the road profile (spelled lam: lambda "
              "is a Python keyword)", "Fig. 9"),
    Parameter("m_P", 30.0, "kg", "mass of the road point / wheel P that the road moves (not "
              "in the catalog: the engines need a body to drive; it changes the actuator "
              "force only)", "chosen here"),
    Parameter("dx0", 0.01, "m", "initial offset of the chassis from x_eq in the free run",
              "chosen here", domain="real"),
)


def spring_force(P, s):
    """f(s) = k_s s (1 + (s/x_s)^2): the suspension's repulsion at compression s."""
    return P.k_s * s * (1 + (s / P.x_s) ** 2)


def static_compression(P):
    """x_eq, the real root of f(x) = m g: x^3 + p x - q = 0 with p = x_s^2 and
    q = m g x_s^2 / k_s (Cardano; p > 0, so the root is unique and both cube roots are of
    positive numbers)."""
    p = P.x_s**2
    q = P.m * P.g * P.x_s**2 / P.k_s
    s = sp.sqrt(q**2 / 4 + p**3 / 27)
    return sp.cbrt(s + q / 2) - sp.cbrt(s - q / 2)


def road_profile(P):
    return P.Y * sp.sin(2 * sp.pi * P.v * TIME / P.lam)


def build(P) -> Mechanism:
    chassis = Body("chassis", P.m, P.m * (0.6**2 + 0.2**2) / 12, (Rectangle((0, 0), 0.6, 0.2),))
    wheel = Body("wheel", P.m_P, P.m_P * (0.3**2 + 0.1**2) / 12, (Rectangle((0, 0), 0.3, 0.1),))
    compression = SPRING_LENGTH - LENGTH
    return Mechanism(
        bodies=(chassis, wheel),
        joints=(Prismatic("chassis_guide", "world", "chassis", "x", axis=(0, -1)),
                Prismatic("road", "world", "wheel", "y", axis=(0, -1),
                          parent_anchor=(0, -SPRING_LENGTH))),
        forces=(PointToPoint("suspension", "wheel", (0, 0), "chassis", (0, 0),
                             # a repulsion is a negative tension
                             tension=-spring_force(P, compression),
                             potential=P.k_s * (compression**2 / 2
                                                + compression**4 / (4 * P.x_s**2))),),
        prescribed=(Prescribed("road", "y", road_profile(P)),),
    )


def printed(P):
    x, x_d, x_dd = coordinate_symbols("x")
    y, _, _ = coordinate_symbols("y")
    m, g = P.m, P.g
    x_eq = static_compression(P)
    s = sp.Symbol("s", real=True)
    k = sp.diff(spring_force(P, s), s).subs(s, x_eq)  # slope of the tangent at E (Fig. 6)
    flat = {"Y": 0}  # eq. 1-3: the car at rest on flat ground
    return (
        PrintedFormula("Fig. 5, eq. 1", "eom", [m * x_dd - m * g + spring_force(P, x)],
                       relations=flat, note="row of x, on flat ground (y = 0)"),
        PrintedFormula("Fig. 6, f(x_eq) = m g", "equilibrium", {"x": x_eq}, relations=flat,
                       note="x_eq: the real root of the cubic (the figure solves it "
                            "graphically)"),
        PrintedFormula("eq. 2-3 (inertia)", "M", sp.Matrix([[m]]), relations=flat),
        PrintedFormula("eq. 2-3 (stiffness k: slope of f at E, Fig. 6)", "K",
                       sp.Matrix([[k]]), relations=flat),
        PrintedFormula("eq. 3, sqrt(k/m)", "frequency", sp.sqrt(k / m), relations=flat),
        PrintedFormula("Fig. 9, eq. 10", "eom", [m * x_dd - m * g + spring_force(P, x - y)],
                       note="row of x; y(t) the road profile"),
    )


_L = float(SPRING_LENGTH)
_P = SimpleNamespace(**{p.name: p.symbol for p in PARAMETERS},
                     g=GRAVITY)

SYSTEM = System(
    id="suspension",
    title="Quarter-car suspension with a hardening spring on a rough road",
    source="monograph §2.2 and §3.2, Fig. 4-6 and 9, eq. 1-3 and 10-11",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"x": static_compression(P), "y": 0},
    printed=printed,
    validity=(
        Condition(f"k_s*{_L:g}*(1 + ({_L:g}/x_s)**2) > 2*m*g",
                  f"the static compression must stay well inside the drawn spring length "
                  f"{_L:g} m (f at that compression above twice the weight)"),
    ),
    scenarios=(
        Scenario("free", {"x": static_compression(_P) + _P.dx0}, overrides={"Y": 0.0},
                 description="flat ground, released from rest dx0 below the static "
                             "equilibrium: undamped oscillation on the hardening spring"),
        Scenario("road", {"x": static_compression(_P)}, t_end=5.0,
                 checks=("trajectory", "actuator"),
                 description="from rest at x_eq onto the road profile at 2 pi v / lam: the "
                             "free oscillation and the forced one superpose (no damping, "
                             "so no steady state)"),
    ),
    unexcited={"Y": 0.0},
    excitation_frequencies=lambda P: (2 * sp.pi * P.v / P.lam,),
)
