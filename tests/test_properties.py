"""Property tests over parameter ranges of every mechanism (Hypothesis, derandomized so
that every run draws the same examples).

- Defaults given by formulas follow the parameters they depend on, and a value given
  explicitly (by the user or a scenario) wins.
- The linearization from the derivation agrees with the hand-derived facts (tests/hand)
  at random valid parameters.
- The reference trajectory conserves energy, where the system is conservative, to within
  what its own error estimate allows.
- Invalid parameter sets are refused and valid ones are not: the refusal is compared
  with the geometry checked by hand over the motion (spring lengths sampled over a turn,
  pins in their slots, loops that close), not with the conditions' own code.
"""
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from mbfidelity.analytic.linear import operating_equilibrium
from mbfidelity.analytic.numeric import numeric_model
from mbfidelity.analytic.reference import consistent_initial_state, reference
from mbfidelity.systems import Scenario, all_systems, get_system

from hand import facts

SYSTEMS = list(all_systems())
HAND = facts()

#: a handful of examples per system, the same ones on every run (CI is deterministic)
FEW = settings(max_examples=5, derandomize=True, database=None, deadline=None,
               suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])

#: the catalog's default formulas (each system module's parameters), written out here
FORMULAS = {
    "compound_pendulum": {"l": lambda v: v["L"] / 2, "I_O": lambda v: v["m"] * v["L"] ** 2 / 3},
    "double_pendulum": {"I": lambda v: v["m"] * (2 * v["l"]) ** 2 / 12},
    "rhombus_linkage": {"I_G": lambda v: v["m"] * (2 * v["l"]) ** 2 / 12},
    "scotch_yoke": {"F0": lambda v: v["m"] * v["g"]},
    "rolling_disc_track": {"M0": lambda v: (v["m_p"] + v["m_d"]) * v["g"] * v["R"],
                           "I_d": lambda v: v["m_d"] * v["r"] ** 2 / 2},
    # driven systems: the excitation's frequency as a ratio of the natural one, so that
    # the scenarios' ratios hold for any mass and stiffness (§8.2, eq. 86)
    "base_excited_msd": {"Omega": lambda v: v["ratio"] * (v["k"] / v["m"]) ** 0.5},
    "unbalanced_rotor": {"omega": lambda v: v["ratio"] * (v["k"] / (v["M"] + v["m"])) ** 0.5},
    "inertial_shaker": {"Omega": lambda v: v["ratio"] * (v["k"] / (v["M"] + v["m"])) ** 0.5},
    # the rotor symmetric about its axis but for I23 (I1 = I2; eq. 88)
    "dynamic_unbalance": {"I2": lambda v: v["I1"]},
    # IFToMM A02: every link 1 kg and 1 m, couplers as cranks unless given
    "iftomm_a02_four_bar": {"b": lambda v: v["L"], "mc": lambda v: v["m"]},
    # parametric resonance: the pumping at twice the small-swing frequency (Fig. 11)
    "variable_length_pendulum": {"Omega": lambda v: 2 * (v["g"] / v["l0"]) ** 0.5},
    # the preload that makes phi0 the lever's equilibrium (Fig. 10, eq. 12)
    "lever": {"phi_n": lambda v: v["phi0"] + v["m"] * v["g"] * v["e"] * math.cos(v["phi0"])
              / v["k"]},
}


def _by_hand(system_id, overrides):
    """Defaults, the overrides, then the catalog's formulas for what is not given."""
    s = get_system(system_id)
    v = {p.name: p.default for p in s.all_parameters if not p.derived}
    v.update(overrides)
    for name, formula in FORMULAS.get(system_id, {}).items():
        v.setdefault(name, formula(v))
    return v


def _overrides(system_id, low, high):
    """Every parameter with a non-zero default scaled by a factor in [low, high]; each
    derived one either left to its formula or given explicitly."""
    s = get_system(system_id)
    base = s.parameter_values()
    factors = st.floats(low, high)
    # a structural parameter (an integer number of elements) is not scaled
    parts = {p.name: st.one_of(st.none(), factors) if p.derived else factors
             for p in s.all_parameters if base[p.name] != 0 and not p.structural}
    return st.fixed_dictionaries(parts).map(
        lambda drawn: {name: base[name] * f for name, f in drawn.items() if f is not None})


@pytest.mark.parametrize("system_id", SYSTEMS)
def test_every_parameter_must_be_finite(system_id):
    s = get_system(system_id)
    for p in s.all_parameters:
        for bad in (math.inf, -math.inf, math.nan):
            with pytest.raises(ValueError, match=f"parameter {p.name} must be finite"):
                s.parameter_values({p.name: bad})


def test_derived_systems_are_the_catalogs():
    derived = {sid: {p.name for p in s.all_parameters if p.derived}
               for sid, s in all_systems().items()}
    assert {k: v for k, v in derived.items() if v} == {k: set(v) for k, v in FORMULAS.items()}


@pytest.mark.parametrize("system_id", sorted(FORMULAS))
@FEW
@given(data=st.data())
def test_formula_defaults_follow_their_parameters(system_id, data):
    s = get_system(system_id)
    overrides = data.draw(_overrides(system_id, 0.5, 2.0))
    try:
        values, derived = s.resolve_parameters(overrides)
    except ValueError:
        assume(False)
    want = _by_hand(system_id, overrides)
    assert set(derived) == set(FORMULAS[system_id]) - set(overrides)
    for name in values:
        assert values[name] == pytest.approx(want[name], rel=1e-12), name


@pytest.mark.parametrize("system_id", sorted(FORMULAS))
def test_a_value_given_for_a_derived_parameter_wins(system_id):
    """Given by the user or by a scenario, in that order of precedence."""
    s = get_system(system_id)
    for name in FORMULAS[system_id]:
        base = s.parameter_values()[name]
        by_scenario = Scenario("probe", {}, overrides={name: 0.9 * base})
        values, derived = s.resolve_parameters(None, by_scenario)
        assert values[name] == 0.9 * base and name not in derived
        values, derived = s.resolve_parameters({name: 0.8 * base}, by_scenario)
        assert values[name] == 0.8 * base and name not in derived


@pytest.mark.parametrize("system_id", SYSTEMS)
@FEW
@given(data=st.data())
def test_linearization_agrees_with_hand_facts(system_id, data):
    s = get_system(system_id)
    try:
        values = s.parameter_values(data.draw(_overrides(system_id, 0.5, 2.0)))
    except ValueError:
        assume(False)
    values = getattr(HAND[system_id], "relations", lambda v: v)(values)
    assume(getattr(HAND[system_id], "valid", lambda v: True)(values))
    eq = operating_equilibrium(s, values)
    got = sorted(abs(m.eigenvalue) for m in eq.modes)
    np.testing.assert_allclose(got, HAND[system_id].frequencies(values), rtol=1e-9)


# every scenario: whether it is conservative takes the derivation, made in the test (and
# kept in the cache for the others) rather than by every worker while it collects
SCENARIOS = [(sid, sc.name) for sid in SYSTEMS for sc in get_system(sid).scenarios]
#: seconds of each scenario integrated (the reference solves twice, tight and loose)
ENERGY_SECONDS = 3.0


@pytest.mark.parametrize("system_id,scenario", SCENARIOS)
@settings(max_examples=3, derandomize=True, database=None, deadline=None,
          suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(data=st.data())
def test_reference_conserves_energy_to_its_error_estimate(system_id, scenario, data):
    """The exact motion keeps E constant, so the reference's energy varies only through
    its own error: |dE| <= |dV/dq| dq + |M q'| dq'. For an oscillation of amplitude A
    and angular frequency w, |dV/dq| <= M w^2 A and |M q'| <= M w A, and dq' ~ w dq, so
    the spread of E relative to the largest kinetic energy M w^2 A^2 / 2 is at most
    8 dq / A, with dq the reference's error estimate (coordinate by coordinate, the
    worst ratio), plus the round-off of evaluating E."""
    s = get_system(system_id)
    sc = s.scenario(scenario)
    if not numeric_model(system_id, s.parameter_values(scenario=sc)).conservative:
        pytest.skip("not conservative (dissipation or excitation)")
    drawn = data.draw(_overrides(system_id, 0.8, 1.25))
    overrides = {k: v for k, v in drawn.items() if k not in sc.overrides}
    try:
        values = s.parameter_values(overrides, scenario=sc)
    except ValueError:
        assume(False)
    assume(getattr(HAND[system_id], "valid", lambda v: True)(values))
    try:
        consistent_initial_state(s, sc, values)
    except (ValueError, RuntimeError, np.linalg.LinAlgError):
        assume(False)  # no assembly at these values: the scenario does not exist there
    model = numeric_model(system_id, values)
    assert model.conservative
    # at most the scenario's duration (a benchmark's 0.03 s run of a fast mechanism)
    t_end = min(ENERGY_SECONDS, sc.t_end)
    ref = reference(s, sc, values, dt=min(1e-2, t_end / 100), t_end=t_end)
    kinetic = max(0.5 * w @ model.mass_matrix(x) @ w for x, w in zip(ref.q, ref.qd))
    amplitude = np.ptp(ref.q, axis=0) / 2
    moving = amplitude > 1e-9 * amplitude.max()
    relative_error = np.max(ref.error_estimate[moving] / amplitude[moving])
    roundoff = 1e-12 * max(1.0, np.abs(ref.energy).max() / kinetic)
    assert np.ptp(ref.energy) / kinetic <= 8 * relative_error + roundoff


# --- validity: the geometry checked by hand, over the motion where it moves -------------

TURN = np.linspace(0.0, 2 * np.pi, 1441)


def _scotch_yoke(v):
    spring = v["h"] - v["b"] - v["r"] * np.sin(TURN)  # eq. 44 over a turn
    pin_x = -v["r"] * np.cos(TURN)
    return (np.all(spring > 0) and np.all(spring < 2 * v["l0"])
            and np.all(np.abs(pin_x) < 0.15))  # the slot is the block's 0.3 m


def _eccentric_cam(v):
    u = np.c_[np.sin(TURN), -np.cos(TURN)]
    A, C, F = v["r"] * u, v["e"] * u, np.array([0.0, -v["h"]])
    spring = np.linalg.norm(A - F, axis=1)
    return (v["I_O"] - v["m_e"] * v["e"] ** 2 > 0  # central inertia of the disc
            and v["e"] < v["R"]  # the pivot lies in the disc
            and np.all(np.linalg.norm(A - C, axis=1) <= v["R"] * (1 + 1e-12))
            and np.all(spring > 0)
            and math.isclose(spring[0], v["h"] - v["r"]))  # T0's length, as the law reads it


def _five_bar_bird(v):
    # bars hanging: Q = (0, -l), Q' = (e, -l); wings reaching a from them meet iff |QQ'| < 2a
    Q, Q_prime = np.array([0.0, -v["l"]]), np.array([v["e"], -v["l"]])
    return np.linalg.norm(Q_prime - Q) < 2 * v["a"]


def _slotted_link(v):
    # eq. 101 needs cos^3(phi) = l/b < 1; P at rest is l0 - m g / k above the anchor
    return v["l"] / v["b"] < 1 and v["l0"] - v["m"] * v["g"] / v["k"] > 0


GEOMETRY = {
    "compound_pendulum": lambda v: v["I_O"] - v["m"] * v["l"] ** 2 > 0 and v["l"] <= v["L"],
    "eccentric_cam": _eccentric_cam,
    "scotch_yoke": _scotch_yoke,
    "slotted_bar_arctan_damper": lambda v: v["I_O"] - v["m1"] * v["l"] ** 2 > 0,
    "slotted_link_spring_damper": _slotted_link,
    "rolling_disc_track": lambda v: v["r"] < v["R"],
    "belt_pulleys": lambda v: v["l"] > v["r1"] + v["r2"],
    "five_bar_bird": _five_bar_bird,
    "lever": lambda v: v["I_O"] - v["m"] * v["e"] ** 2 > 0,
    # the static compression (f(s) = m g) inside the drawn spring length 0.5 m, with margin
    "suspension": lambda v: v["k_s"] * 0.5 * (1 + (0.5 / v["x_s"]) ** 2) > 2 * v["m"] * v["g"],
}


@pytest.mark.parametrize("system_id", SYSTEMS)
@settings(max_examples=25, derandomize=True, database=None, deadline=None)
@given(data=st.data())
def test_invalid_parameter_sets_are_refused_and_valid_ones_are_not(system_id, data):
    s = get_system(system_id)
    overrides = data.draw(_overrides(system_id, 0.2, 5.0))
    expected_valid = GEOMETRY.get(system_id, lambda v: True)(_by_hand(system_id, overrides))
    try:
        s.parameter_values(overrides)
        refused = None
    except ValueError as exc:
        refused = str(exc)
    if expected_valid:
        assert refused is None, refused
    else:
        assert refused is not None and refused.startswith(f"{system_id}: the parameters "
                                                          f"violate ")
        assert "\n" not in refused


@pytest.mark.parametrize("system_id,overrides,needle", [
    ("scotch_yoke", {"b": 0.3}, "h - b - r > 0"),
    ("scotch_yoke", {"r": 0.5}, "h - b - r > 0"),
    ("scotch_yoke", {"l0": 0.05}, "h - b + r < 2*l0"),
    ("scotch_yoke", {"r": 0.16, "h": 0.5, "l0": 0.5}, "2*r < 0.3"),
    ("compound_pendulum", {"l": 0.7}, "I_O > m*l**2"),
    ("compound_pendulum", {"l": 1.2, "I_O": 2.0}, "l <= L"),
    ("eccentric_cam", {"h": 0.04}, "h > r"),
    ("eccentric_cam", {"e": 0.09, "I_O": 0.1, "R": 0.05}, "e < R"),
    ("rolling_disc_track", {"r": 0.6}, "r < R"),
    ("belt_pulleys", {"l": 0.1}, "r1 + r2 < l"),
    ("five_bar_bird", {"e": 0.31}, "e < 2*a"),
    ("slotted_link_spring_damper", {"l": 0.4}, "l < b"),
    ("slotted_link_spring_damper", {"k": 30.0}, "k*l0 > m*g"),
    ("slotted_bar_arctan_damper", {"l": 0.3}, "I_O > m1*l**2"),
    ("lever", {"e": 0.4}, "I_O > m*e**2"),
    ("suspension", {"k_s": 10.0}, "k_s*0.5*(1 + (0.5/x_s)**2) > 2*m*g"),
])
def test_the_refusal_names_the_violated_condition(system_id, overrides, needle):
    with pytest.raises(ValueError, match=f"violate {re.escape(needle)} "):
        get_system(system_id).parameter_values(overrides)
