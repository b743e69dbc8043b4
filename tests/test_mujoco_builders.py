"""MuJoCo's element builders: one registered per element kind, each with the expression
it declares, and each builds its elements into an MJCF model that MuJoCo compiles, with
every description joint as an engine joint (contract point 5: the declaration and the
code that builds the element are one thing)."""
import pytest

from mbfidelity.simulators.plan import ELEMENT_KINDS, elements
from mbfidelity.systems import all_systems

mujoco = pytest.importorskip("mujoco")
from mbfidelity.simulators import mujoco_mjcf  # noqa: E402
from mbfidelity.simulators.mujoco_backend import BACKEND  # noqa: E402


def test_every_element_kind_has_one_builder_with_its_declaration():
    assert list(mujoco_mjcf._BUILDERS) and set(mujoco_mjcf._BUILDERS) == set(ELEMENT_KINDS)
    assert BACKEND.EXPRESSIONS == {kind: mujoco_mjcf._BUILDERS.expressions[kind]
                                   for kind in ELEMENT_KINDS}


def test_each_builder_builds_its_elements_into_a_model_mujoco_compiles():
    """Over the catalog and its variants (default values), every supported mechanism's
    MJCF compiles and holds each description joint; every element kind but the
    unsupported body case is built at least once."""
    built = set()
    for system in all_systems().values():
        for variant in (None, *(v.name for v in system.variants)):
            mech = system.numeric_mechanism(system.parameter_values(), variant)
            if not BACKEND.support(mech).ok:
                continue
            model = mujoco.MjModel.from_xml_string(BACKEND.to_mjcf(mech))
            for joint in mech.joints:
                assert model.joint(joint.name).id >= 0, (system.id, variant, joint.name)
            built |= {kind for kind, _ in elements(mech)}
    assert built == set(ELEMENT_KINDS)
