"""Drake's element builders: one registered per element kind, each with the expression it
declares (contract point 5: the declaration and the code that builds the element are one
thing); every supported catalog mechanism builds into a plant that holds each of its
elements, and a builder that builds nothing is caught."""
import numpy as np
import pytest

from mbfidelity.simulators.plan import (COORDINATE_FORCE_LINEAR, ELEMENT_KINDS, HINGE_CLOSURE,
                                        LINEAR_COUPLING, POINT_ON_LINE,
                                        POINT_ON_POINT, PRISMATIC, REVOLUTE, ROLLING_CONTACT,
                                        element_kind, elements, num)
from mbfidelity.systems import all_systems, get_system

pytest.importorskip("pydrake")
from mbfidelity.simulators import drake_backend  # noqa: E402
from mbfidelity.simulators.drake_backend import BACKEND  # noqa: E402
from pydrake.multibody.tree import BodyIndex  # noqa: E402

DT = 1e-3
#: every law through the Python force system: each force element then has a name there
PYTHON_LAWS = {"native_elements": False}


def _mechanisms():
    """(label, numeric mechanism) of the catalog and its variants (default values)."""
    for system in all_systems().values():
        for variant in (None, *(v.name for v in system.variants)):
            yield f"{system.id}/{variant}", system.numeric_mechanism(system.parameter_values(),
                                                                     variant)


def _missing(mech, settings=PYTHON_LAWS) -> list[str]:
    """What of the description the Drake build does not hold: a body's mass (the plant's
    total mass is the description's: a slot's slider only borrows its point mass), a joint
    of the description's name and type, a closure or coupling (one Drake constraint each),
    a force law (in the Python force system, where every law goes with `PYTHON_LAWS`), a
    prescribed motion (imposed by that system)."""
    built = BACKEND._build(mech, BACKEND.resolve_settings(settings), DT)
    plant, missing = built.plant, []
    mass = sum(plant.get_body(BodyIndex(i)).default_mass() for i in range(1, plant.num_bodies()))
    if not mass == pytest.approx(sum(num(b.mass) for b in mech.bodies), rel=1e-12, abs=1e-15):
        missing.append(f"total mass {mass}")
    types = {REVOLUTE: "revolute", PRISMATIC: "prismatic"}
    for joint in mech.joints:
        if not (plant.HasJointNamed(joint.name)
                and plant.GetJointByName(joint.name).type_name() == types[element_kind(joint)]):
            missing.append(f"joint {joint.name}")
    closures = [c for c in mech.constraints
                if element_kind(c) in (POINT_ON_POINT, POINT_ON_LINE, LINEAR_COUPLING)]
    if plant.num_constraints() != len(closures):
        missing.append(f"{len(closures)} constraints, {plant.num_constraints()} built")
    laws = {f.name for f in built.python_laws + built.python_p2p}
    missing += [f"law {f.name}" for f in mech.forces
                if f.name not in laws and getattr(f, "body_a", 0) != getattr(f, "body_b", 1)]
    if [m.element for m in built.driven] != list(mech.prescribed):
        missing.append("prescribed motions")
    return missing


def test_every_element_kind_has_one_builder_with_its_declaration():
    assert set(drake_backend._BUILDERS) == set(ELEMENT_KINDS)
    assert BACKEND.EXPRESSIONS == {kind: drake_backend._BUILDERS.expressions[kind]
                                   for kind in ELEMENT_KINDS}


def test_every_supported_mechanism_builds_and_holds_its_elements():
    """Over the catalog and its variants, every mechanism Drake supports builds (default
    settings) and its build with every law in the Python force system holds each element;
    between them every element kind but the unsupported rolling contact and hinge closure
    is built, on both the continuous and the discrete plant."""
    kinds, plants = set(), set()
    for label, mech in _mechanisms():
        if not BACKEND.support(mech).ok:
            continue
        built = BACKEND._build(mech, BACKEND.resolve_settings(None), DT)
        plants.add(built.plant.time_step() > 0)
        assert _missing(mech) == [], label
        kinds |= {kind for kind, _ in elements(mech)}
    assert kinds == set(ELEMENT_KINDS) - {ROLLING_CONTACT, HINGE_CLOSURE} and plants == {True, False}


#: one mechanism per element kind that holds it
COVERING = {"body": "compound_pendulum", "massless body": "elastic_pendulum",
            "Revolute": "compound_pendulum", "Prismatic": "mass_spring_damper",
            "PointToPoint, linear law": "elastic_pendulum",
            "PointToPoint, custom law": "suspension",
            "CoordinateForce, linear law": "mass_spring_damper",
            "CoordinateForce, custom law": "end_stops", "time load": "actuated_arm",
            "PointOnPoint": "five_bar_bird", "PointOnLine": "eccentric_cam",
            "LinearCoupling": "belt_pulleys", "Prescribed": "actuated_arm"}


@pytest.mark.parametrize("kind", sorted(COVERING))
def test_a_builder_that_builds_nothing_is_caught(kind, monkeypatch):
    assert set(COVERING) == set(ELEMENT_KINDS) - {ROLLING_CONTACT, HINGE_CLOSURE}  # all Drake builds
    system = get_system(COVERING[kind])
    mech = system.numeric_mechanism(system.parameter_values())
    assert kind in {k for k, _ in elements(mech)} and _missing(mech) == []
    monkeypatch.setitem(drake_backend._BUILDERS, kind, lambda build, element: None)
    try:
        missing = _missing(mech)
    except KeyError as error:  # a joint on a body that was never built
        missing = [f"body {error}"]
    assert missing


def test_drakes_own_elements_give_the_forces_the_python_laws_give(monkeypatch):
    """On the continuous plant, the laws Drake's own elements hold (springs, dampers,
    bushings) give the time derivatives that the same laws evaluated in Python give, at a
    state away from equilibrium (agreement to rounding: the same arithmetic in another
    order); a build whose coordinate springs are left out where Drake would hold them
    differs."""
    state = np.random.default_rng(0).uniform(-0.5, 0.5, 16)

    def derivatives(mech, settings) -> np.ndarray:
        built = BACKEND._build(mech, BACKEND.resolve_settings(settings), DT)
        assert built.plant.time_step() == 0
        if settings is None:  # Drake's own elements hold some law: the check is not empty
            assert built.plant.num_force_elements() > 1 or any(built.damping)
        context = built.diagram.CreateDefaultContext()
        context.SetContinuousState(state[:context.num_continuous_states()])
        return built.diagram.EvalTimeDerivatives(context).CopyToVector()

    mechs = [get_system(s).numeric_mechanism(get_system(s).parameter_values())
             for s in ("elastic_pendulum", "mass_spring_damper", "pendulum_sliding_block")]
    for mech in mechs:
        assert derivatives(mech, None) == pytest.approx(derivatives(mech, PYTHON_LAWS),
                                                        rel=1e-12, abs=1e-12)
    monkeypatch.setitem(drake_backend._BUILDERS, COORDINATE_FORCE_LINEAR,
                        lambda build, f: None if f.name in build.springs
                        else build.python_laws.append(f))
    assert derivatives(mechs[1], None) != pytest.approx(derivatives(mechs[1], PYTHON_LAWS),
                                                        rel=1e-6)
