"""Pymunk's element builders: one registered per element kind, each with the expression it
declares (contract point 5: the declaration and the code that builds the element are one
thing); every supported catalog mechanism's layout holds each of its bodies, joints and
prescribed motions, and a builder that builds nothing is caught."""
import pytest

from mbfidelity.simulators.base import UNSUPPORTED
from mbfidelity.simulators.plan import ELEMENT_KINDS, PRISMATIC, REVOLUTE, element_kind, num
from mbfidelity.systems import all_systems
from mbfidelity.systems.model import WORLD

pytest.importorskip("pymunk")
from mbfidelity.simulators import pymunk_backend  # noqa: E402
from mbfidelity.simulators.pymunk_backend import BACKEND  # noqa: E402


def _mechanisms():
    """(label, numeric mechanism) of the catalog and its variants (default values)."""
    for system in all_systems().values():
        for variant in (None, *(v.name for v in system.variants)):
            yield f"{system.id}/{variant}", system.numeric_mechanism(system.parameter_values(),
                                                                     variant)


def _missing(mech) -> list[str]:
    """What of the description the layout does not hold: a body with mass that is no
    engine body; a joint between engine bodies (or the world) with no Chipmunk constraint
    of its kind between them (a PivotJoint for a hinge, a GrooveJoint for a slide) unless
    a drive holds it; a prescribed motion without its drive. Joints of eliminated massless
    links are held by the link's constraint instead."""
    layout = pymunk_backend._plan(mech, BACKEND.default_settings())
    missing = [f"body {b.name}" for b in mech.bodies
               if num(b.mass) > 0 and b.name not in layout.dynamic]
    engine = set(layout.dynamic) | {WORLD}
    pivots = {(a, b) for a, b, _, _ in layout.pivots}
    grooves = {(g.slot, g.pin) for g in layout.grooves}
    driven = {d.joint.name for d in layout.drives}
    for joint in mech.joints:
        if not {joint.parent, joint.child} <= engine or joint.name in driven:
            continue
        held = pivots if element_kind(joint) == REVOLUTE else grooves
        if (joint.parent, joint.child) not in held:
            missing.append(f"joint {joint.name}")
    if [d.name for d in layout.drives] != [p.name for p in mech.prescribed]:
        missing.append("prescribed motions")
    return missing


def test_every_element_kind_has_one_builder_with_its_declaration():
    assert set(pymunk_backend._ELEMENTS) == set(ELEMENT_KINDS)
    assert BACKEND.EXPRESSIONS == {kind: pymunk_backend._ELEMENTS.expressions[kind]
                                   for kind in ELEMENT_KINDS}


def test_each_supported_mechanism_layout_holds_its_elements():
    """Over the catalog and its variants, every supported mechanism's layout holds each
    body, joint and prescribed motion; every element kind Pymunk can build occurs in one
    of them."""
    built = set()
    for label, mech in _mechanisms():
        if not BACKEND.support(mech).ok:
            continue
        assert _missing(mech) == [], label
        built |= {element_kind(e) for group in (mech.bodies, mech.joints, mech.forces,
                                                mech.constraints, mech.prescribed)
                  for e in group}
    assert built == {kind for kind in ELEMENT_KINDS
                     if any(e.level != UNSUPPORTED for e in BACKEND.EXPRESSIONS[kind])}


@pytest.mark.parametrize("kind", [REVOLUTE, PRISMATIC])
def test_a_joint_builder_that_builds_nothing_is_caught(kind, monkeypatch):
    """The check above rejects a layout whose joint builder adds nothing."""
    monkeypatch.setitem(pymunk_backend._ELEMENTS, kind, lambda ctx, element: None)
    caught = [label for label, mech in _mechanisms()
              if any(element_kind(j) == kind for j in mech.joints)
              and BACKEND.support(mech).ok and _missing(mech)]
    assert caught
