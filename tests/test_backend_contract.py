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
