"""A pendulum on a cart held by a spring: a mechanism that is not in the catalog, written
the way the catalog's modules are (src/mbfidelity/systems/), to be put through the same
derivation and engines with ``--system-path examples/cart_pendulum.py``.

Geometry::

    wall |--/\\/\\/\\--[  cart  ]        cart: mass M on a horizontal rail, x = 0 where the
                          O               spring k is relaxed
                          |\\  phi         bar: uniform, mass m, length L, pinned at O on the
                          | \\             cart, phi from the downward vertical
"""
from mbfidelity.systems import System
from mbfidelity.systems.model import (Body, CoordinateForce, Mechanism, Parameter, Prismatic,
                                      Rectangle, Revolute, Scenario, Segment,
                                      coordinate_spring_damper)

PARAMETERS = (
    Parameter("M", 2.0, "kg", "mass of the cart", "chosen here"),
    Parameter("m", 0.5, "kg", "mass of the bar", "chosen here"),
    Parameter("L", 0.6, "m", "length of the bar", "chosen here"),
    Parameter("k", 80.0, "N/m", "spring between the wall and the cart", "chosen here"),
)


def build(P) -> Mechanism:
    cart = Body("cart", P.M, P.M * (0.2**2 + 0.1**2) / 12, (Rectangle((0, 0), 0.2, 0.1),))
    bar = Body("bar", P.m, P.m * P.L**2 / 12, (Segment((0, P.L / 2), (0, -P.L / 2)),))
    return Mechanism(
        bodies=(cart, bar),
        joints=(Prismatic("rail", "world", "cart", "x", axis=(1, 0)),
                Revolute("pin", "cart", "bar", "phi", child_anchor=(0, P.L / 2))),
        forces=(CoordinateForce("spring", "x", **coordinate_spring_damper(P.k, 0)),),
    )


SYSTEM = System(
    id="cart_pendulum",
    title="Pendulum on a cart held by a spring (a user's mechanism)",
    source="examples/cart_pendulum.py (not in the monograph)",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"x": 0, "phi": 0},
    scenarios=(Scenario("swing", {"x": 0.02, "phi": 0.3}, t_end=5.0, checks=("trajectory",),
                        description="cart and bar released together"),),
)
