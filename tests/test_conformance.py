"""One conformance suite run against every engine (scikit-learn's common-check pattern):
cases generated over system x simulator x applicable check, ids like
``double_pendulum-pybullet-frequency``. A missing engine or a mechanism an engine cannot
express is a visible skip with its reason; expected failures are strict (an unexpected
pass fails, so fixed problems surface)."""
from functools import lru_cache

import pytest

from hand import facts
from mbfidelity.comparisons.runner import compare
from mbfidelity.simulators import SIMULATOR_IDS, all_backends
from mbfidelity.systems import all_systems

CHECKS = {
    "trajectory": ("trajectory_max", "trajectory_rms", "period", "energy_drift"),
    "reaction": ("reaction_",),
    "frequency": ("frequency.", "damping."),
    "constraint": ("constraint_", "contact_"),
    # driven mechanisms (issue 9): the engine's imposed motion, the actuator forces, and
    # the steady-state amplitudes or growth rates measured from its own run
    "driven": ("imposed_", "actuator_", "steady_state_", "growth_rate"),
}


def _applicable(system):
    checks = ["trajectory"]
    if not getattr(HAND.get(system.id), "NO_FREE_VIBRATION", None):
        checks.append("frequency")
    if any("reaction" in sc.checks for sc in system.scenarios) and system.reaction_joints:
        checks.append("reaction")
    if system.mechanism.constraints and any("constraint_force" in sc.checks
                                            for sc in system.scenarios):
        checks.append("constraint")
    if system.mechanism.prescribed:
        checks.append("driven")
    return checks


HAND = facts()
CASES = [(s.id, sim, check) for s in all_systems().values() for sim in SIMULATOR_IDS
         for check in _applicable(s)]


@lru_cache(maxsize=None)
def _comparison(system_id, simulator):
    return compare(system_id, simulator)


def _belongs(metric_name: str, check: str) -> bool:
    if check == "frequency":
        return metric_name.startswith(CHECKS["frequency"])
    tail = metric_name.split(".", 1)[-1]
    return any(tail.startswith(p) for p in CHECKS[check]) and not metric_name.startswith(
        CHECKS["frequency"])


def _marks(system_id: str, simulator: str) -> list:
    """Its system's worker group. In `make test-slow`: Drake's driven rows (the actuator's
    inverse dynamics runs in Python at every integrator stage) and its rows on the discrete
    plant (closures, couplings, slots: the SAP solver's step and the Python force system
    at every step; tests/test_drake.py gates its closed loops on two mechanisms), and
    every engine on a stiff row (its own small step over the whole run)."""
    marks = [pytest.mark.xdist_group(system_id)]
    system = all_systems()[system_id]
    mechanism = system.mechanism
    if simulator == "drake" and (mechanism.prescribed or mechanism.constraints):
        marks.append(pytest.mark.slow)
    if system.stiff:  # its own small step over the whole run, and a stiff reference
        marks.append(pytest.mark.slow)
    return marks


@pytest.mark.parametrize("system_id,simulator,check", [
    pytest.param(a, b, c, id=f"{a}-{b}-{c}", marks=_marks(a, b)) for a, b, c in CASES])
def test_conformance(system_id, simulator, check):
    backend = all_backends().get(simulator)
    if backend is None:
        pytest.skip(f"no backend module for {simulator}")
    ok, why = backend.available()
    if not ok:
        pytest.skip(f"{simulator} not installed: {why}")
    result = _comparison(system_id, simulator)
    if not result.supported:
        pytest.skip(f"{simulator} cannot express {system_id}: {result.reason}")
    metrics = [m for m in result.metrics if _belongs(m.name, check)]
    assert metrics, f"no {check} metric was produced"
    bad = [f"{m.name}: {m.value:.3e} > {m.tolerance:.3e}" for m in metrics if m.status == "fail"]
    xpassed = [f"{m.name}: passed ({m.value:.3e} <= {m.tolerance:.3e}) but declared xfail: "
               f"{m.reason}" for m in metrics if m.status == "xpass"]
    unresolved = [f"{m.name}: {m.reason}" for m in metrics
                  if m.status == "unresolved" and not m.expected]
    assert not bad, "gates failed:\n" + "\n".join(bad)
    assert not unresolved, ("gates that cannot judge (declare them, with the measured "
                            "reason):\n" + "\n".join(unresolved))
    assert not xpassed, "unexpected passes (strict expected failures):\n" + "\n".join(xpassed)


# --- variants: another build of the same mechanism (rolling by friction contact) -------
# Not gated by the description's tolerances (its distance from them is the variant's own
# error, reported as "measured"); what must hold is physics the variant promises.

VARIANT_CASES = [(s.id, v.name, sim) for s in all_systems().values() for v in s.variants
                 for sim in v.settings]


# a long study (the disc on a ring of 720 contact facets: 40-170 s of CPU per engine), in
# `make test-slow` like the variants' rows of the report (`run --variants`)
@pytest.mark.slow
@pytest.mark.parametrize("system_id,variant,simulator", [
    pytest.param(a, b, c, id=f"{a}[{b}]-{c}", marks=pytest.mark.xdist_group(f"{a}[{b}]"))
    for a, b, c in VARIANT_CASES])
def test_rolling_contact_variant_keeps_rolling(system_id, variant, simulator):
    """Fig. 39 disc released 1.2 rad up the track: the reference needs |f|/N <= 0.68 and
    the contact offers a friction coefficient of 1, so the disc must not slip grossly:
    losing grip (or the contact) would put the coordinates O(1) off. The soft, faceted
    contact may creep: the bound is 10 % of the amplitude (measured 2-6 %). The normal
    force may chatter from facet to facet, but its rms distance from the reference must
    stay below half the largest normal force (a lost contact gives 1)."""
    backend = all_backends()[simulator]
    ok, why = backend.available()
    if not ok:
        pytest.skip(f"{simulator} not installed: {why}")
    result = compare(system_id, simulator, scenarios=["large"], variant=variant)
    assert result.supported, result.reason
    by_name = {m.name: m for m in result.metrics}
    assert by_name["large.trajectory_rms"].value < 0.1
    normal = by_name["large.contact_normal"].detail
    assert normal["reference_min"] > 0
    assert normal["rms_error"] < 0.5
    assert all(m.status in ("pass", "measured") for m in result.metrics)


@pytest.mark.xdist_group("grouping-check")
def test_cases_of_one_system_share_a_worker(request):
    """The cases of one system run on one worker so that its comparison is made once
    (`_comparison` is cached per process): under `--dist loadgroup` pytest-xdist marks
    each grouped case's id with its group. A pytest that xdist cannot rename (pytest 9
    with xdist 3.8) silently spreads the cases and doubles the suite's time."""
    if not getattr(request.config.option, "loadgroup", False):
        pytest.skip("not run by a pytest-xdist worker with --dist loadgroup")
    assert request.node.nodeid.endswith("@grouping-check")
