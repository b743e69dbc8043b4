"""A user's double pendulum whose second bar has a central inertia of 1e-20 kg m^2
(valid by its domain: positive), nearly a point mass: the engines' linearizations and
steps are ill-conditioned there."""
from mbfidelity.systems import System
from mbfidelity.systems.model import Body, Mechanism, Parameter, Revolute, Scenario

PARAMETERS = (
    Parameter("m", 1.0, "kg", "mass of each bar"),
    Parameter("l", 0.5, "m", "half length of each bar"),
    Parameter("I2", 1e-20, "kg m^2", "central inertia of the second bar"),
)


def build(P) -> Mechanism:
    upper = Body("upper", P.m, P.m * (2 * P.l) ** 2 / 12)
    lower = Body("lower", P.m, P.I2)
    return Mechanism(
        bodies=(upper, lower),
        joints=(Revolute("shoulder", "world", "upper", "phi1", child_anchor=(0, P.l)),
                Revolute("elbow", "upper", "lower", "phi2", parent_anchor=(0, -P.l),
                         child_anchor=(0, P.l))))


SYSTEM = System(
    id="user_tiny_inertia", title="a bar of inertia 1e-20", source="fault injection",
    parameters=PARAMETERS, build=build, operating_point=lambda P: {"phi1": 0, "phi2": 0},
    scenarios=(Scenario("swing", {"phi1": 0.1, "phi2": 0.1}, t_end=1.0),),
)
