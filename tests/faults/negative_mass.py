"""A user's module whose default mass is negative (its parameter declared real): the
description builds, but no parameter set may give a body a negative mass."""
from mbfidelity.systems import System
from mbfidelity.systems.model import Body, Mechanism, Parameter, Revolute, Scenario

PARAMETERS = (
    Parameter("m", -2.0, "kg", "mass of the bar", domain="real"),
    Parameter("l", 0.5, "m", "distance from the pivot to the centre of mass"),
)


def build(P) -> Mechanism:
    bar = Body("bar", P.m, 0.01)
    return Mechanism(bodies=(bar,), joints=(
        Revolute("pivot", "world", "bar", "phi", child_anchor=(0, P.l)),))


SYSTEM = System(
    id="user_negative_mass", title="a negative mass by default", source="fault injection",
    parameters=PARAMETERS, build=build, operating_point=lambda P: {"phi": 0},
    scenarios=(Scenario("swing", {"phi": 0.1}, t_end=1.0),),
)
