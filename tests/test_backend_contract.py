"""The backend contract's shared parts (simulators/base.py), checked on every backend
without running an engine: settings declared once and validated centrally."""
import pytest

from mbfidelity.simulators import all_backends
from mbfidelity.simulators.base import Setting

BACKENDS = list(all_backends().values())


@pytest.mark.parametrize("backend", BACKENDS, ids=lambda b: b.id)
def test_settings_table_gives_defaults_and_notes(backend):
    defaults, notes = backend.default_settings(), backend.setting_notes()
    assert list(defaults) == list(notes) == list(backend.SETTINGS)
    assert all(notes.values()), "every setting says which engine default it replaces"
    # every default is admitted by its own declaration
    assert backend.resolve_settings(defaults) == defaults
    # callers get fresh copies of list values
    lists = [key for key, value in defaults.items() if isinstance(value, list)]
    for key in lists:
        defaults[key].append(0.0)
    assert all(backend.default_settings()[key] != defaults[key] for key in lists)


@pytest.mark.parametrize("backend", BACKENDS, ids=lambda b: b.id)
def test_unknown_setting_names_the_valid_ones(backend):
    with pytest.raises(ValueError, match=f"unknown {backend.id} setting 'no_such_key'; "
                                         f"valid: .*{sorted(backend.SETTINGS)[0]}"):
        backend.resolve_settings({"no_such_key": 1})


@pytest.mark.parametrize("backend", BACKENDS, ids=lambda b: b.id)
def test_choices_and_types_are_checked(backend):
    for key, setting in backend.SETTINGS.items():
        if isinstance(setting.allowed, tuple) and not isinstance(setting.allowed[0], type):
            with pytest.raises(ValueError, match=f"{key} must be one of .*{setting.allowed[0]!r}"):
                backend.resolve_settings({key: "not a choice"})
            assert backend.resolve_settings({key: setting.allowed[-1]})[key] == setting.allowed[-1]
        elif setting.allowed is bool:
            with pytest.raises(ValueError, match=f"{key} must be bool"):
                backend.resolve_settings({key: 1})
        elif setting.allowed in (float, int):
            with pytest.raises(ValueError, match=f"{key} must be"):
                backend.resolve_settings({key: "1"})
            with pytest.raises(ValueError, match=f"{key} must be"):
                backend.resolve_settings({key: True})


def test_setting_types():
    assert Setting(1.0, float, "n").check("e", "k", 2) is None  # an int is a float value
    with pytest.raises(ValueError, match="must be int"):
        Setting(1, int, "n").check("e", "k", 2.5)
    with pytest.raises(ValueError, match="must be list"):
        Setting([1.0], list, "n").check("e", "k", ["a"])
    assert Setting(None, (float, type(None)), "n").check("e", "k", None) is None
    with pytest.raises(ValueError, match="must be float or null"):
        Setting(None, (float, type(None)), "n").check("e", "k", "x")


# --- exactness declared per element kind --------------------------------------------

from dataclasses import replace  # noqa: E402

from mbfidelity.comparisons.runner import expectation_for, expectations  # noqa: E402
from mbfidelity.simulators.base import LEVELS, expected_failures  # noqa: E402
from mbfidelity.simulators.plan import ELEMENT_KINDS, elements  # noqa: E402
from mbfidelity.systems import get_system  # noqa: E402
from mbfidelity.systems.model import LinearCoupling  # noqa: E402


def _numeric(system_id):
    system = get_system(system_id)
    return system.numeric_mechanism(system.parameter_values())


@pytest.mark.parametrize("backend", BACKENDS, ids=lambda b: b.id)
def test_every_element_kind_is_declared(backend):
    assert set(backend.EXPRESSIONS) == set(ELEMENT_KINDS)
    for kind, cases in backend.EXPRESSIONS.items():
        assert cases and all(e.level in LEVELS and e.how for e in cases), kind
        if len(cases) > 1:
            assert all(e.when for e in cases), f"{kind}: several cases need their conditions"
            # each condition is code beside its statement; the last case holds otherwise
            assert all(callable(e.applies) for e in cases[:-1]), kind
            assert cases[-1].applies is None, kind
        else:
            assert cases[0].applies is None, kind


@pytest.mark.parametrize("backend", BACKENDS, ids=lambda b: b.id)
def test_catalog_elements_take_declared_cases(backend):
    for system_id in ("rhombus_linkage", "slotted_link_spring_damper", "belt_pulleys",
                      "rolling_disc_track", "mass_spring_damper"):
        mech = _numeric(system_id)
        declared = [backend.expression(mech, element) for _, element in elements(mech)]
        for (kind, _), expression in zip(elements(mech), declared):
            assert expression in backend.EXPRESSIONS[kind]
        # supported unless one of its elements is declared unsupported (Drake's continuous
        # plant has no constraints)
        refused = [e for e in declared if e.level == "unsupported"]
        assert backend.support(mech).ok == (not refused)


def test_support_follows_the_declarations():
    # a body with inertia and no mass: MuJoCo refuses it (a point mass it substitutes)
    weightless = _numeric("compound_pendulum")
    weightless = replace(weightless, bodies=tuple(replace(b, mass=0)
                                                  for b in weightless.bodies))
    support = all_backends()["mujoco"].support(weightless)
    assert not support.ok and "zero mass" in support.reason
    assert all_backends()["pybullet"].support(weightless).ok
    disc = _numeric("rolling_disc_track")
    three = LinearCoupling("three", tuple((c, k + 1.0) for k, c in enumerate(disc.coordinates)))
    support = all_backends()["pybullet"].support(replace(disc, constraints=(three,)))
    assert not support.ok and "JOINT_GEAR constrains exactly two joints" in support.reason


def test_expected_failures_derive_from_soft_expressions():
    mujoco, exudyn = all_backends()["mujoco"], all_backends()["exudyn"]
    (group,) = expected_failures(mujoco, _numeric("rhombus_linkage"))  # loop and slot: one
    assert {e.metric for e in group} >= {"*.trajectory_*", "*.constraint_*"}
    assert all(e.simulator == "mujoco" and e.kind == "xfail" and "soft" in e.reason
               for e in group)
    assert expected_failures(exudyn, _numeric("rhombus_linkage")) == ()
    assert expected_failures(mujoco, _numeric("double_pendulum")) == ()
    # the comparisons merge them after the system's own declarations
    system = get_system("scotch_yoke")
    assert expectations(system, "mujoco")[-1] == group
    assert expectation_for(system, "mujoco", "large.constraint_slot") in group
    assert expectation_for(system, "exudyn", "large.constraint_slot") is None


def test_variant_is_description_data():
    """The rolling-by-contact variant is a RollingContact element in place of the rolling
    coupling, not a shape the backends recognise."""
    system = get_system("rolling_disc_track")
    mech = system.numeric_mechanism(system.parameter_values(), "contact")
    (contact,) = mech.constraints
    assert contact.coupling == _numeric("rolling_disc_track").constraints[0]
    for sid in system.variant("contact").settings:
        backend = all_backends()[sid]
        assert backend.support(mech).ok
        assert backend.expression(mech, contact).level == "substitute"
    support = all_backends()["exudyn"].support(mech)
    assert not support.ok and support.reason.startswith("RollingContact rolling:")


# --- flexible elements (contract point 12) ---------------------------------------------

from mbfidelity.simulators.base import NO_BEAM_ELEMENT, UNSUPPORTED, BeamElement  # noqa: E402


@pytest.mark.parametrize("backend", BACKENDS, ids=lambda b: b.id)
def test_flexible_elements_are_declared(backend):
    """Every backend declares its flexible elements, or one unsupported entry with the
    reason; a supported kind names the order it converges at and its limit."""
    declared = backend.BEAM_ELEMENTS
    assert declared and all(isinstance(e, BeamElement) and e.expression.how
                            for e in declared.values())
    for kind, e in declared.items():
        if e.expression.level == UNSUPPORTED:
            assert kind == NO_BEAM_ELEMENT and len(declared) == 1
        else:
            assert e.order and e.order > 0 and e.limit
    assert backend.beam_element("no such kind").expression.level == UNSUPPORTED
