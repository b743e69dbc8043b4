"""A user's mechanism whose force law blows up: a block on a softening-then-hardening
spring, F = -k x + a x^3, released beyond the barrier x^2 = k / a, runs off to infinity in
finite time (for x0 = 0.1, k = 1, a = 1e4 the escape time is about 0.15 s): no reference
can be solved over the scenario, and no engine can follow it."""
from mbfidelity.systems import System
from mbfidelity.systems.model import (COORD, Body, CoordinateForce, Mechanism, Parameter,
                                     Prismatic, Scenario)

PARAMETERS = (
    Parameter("m", 1.0, "kg", "mass"),
    Parameter("k", 1.0, "N/m", "linear stiffness"),
    Parameter("a", 1e4, "N/m^3", "cubic coefficient (destabilising)"),
    Parameter("x0", 0.1, "m", "release", domain="real"),
)


def build(P) -> Mechanism:
    block = Body("block", P.m, P.m * 0.01 / 6)
    x = Prismatic("guide", "world", "block", "x", axis=(1, 0))
    return Mechanism(bodies=(block,), joints=(x,),
                     forces=(CoordinateForce("law", "x", -P.k * COORD + P.a * COORD**3),))


SYSTEM = System(
    id="user_blowup_force", title="a force law that blows up", source="fault injection",
    parameters=PARAMETERS, build=build, operating_point=lambda P: {"x": 0},
    scenarios=(Scenario("release", {"x": "x0"}, t_end=1.0, description="beyond the barrier"),),
)
