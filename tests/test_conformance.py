"""One conformance suite run against every engine (scikit-learn's common-check pattern):
cases generated over system x simulator x applicable check, ids like
``double_pendulum-pybullet-frequency``. A missing engine or a mechanism an engine cannot
express is a visible skip with its reason; expected failures are strict (an unexpected
pass fails, so fixed problems surface)."""
from functools import lru_cache

import pytest

from mbfidelity.comparisons.runner import compare
from mbfidelity.simulators import SIMULATOR_IDS, all_backends
from mbfidelity.systems import all_systems

CHECKS = {
    "trajectory": ("trajectory_max", "trajectory_rms", "period", "energy_drift"),
    "reaction": ("reaction_",),
    "frequency": ("frequency.", "damping."),
    "constraint": ("constraint_",),
}


def _applicable(system):
    checks = ["trajectory", "frequency"]
    if any("reaction" in sc.checks for sc in system.scenarios) and system.reaction_joints:
        checks.append("reaction")
    if system.mechanism.constraints and any("constraint_force" in sc.checks
                                            for sc in system.scenarios):
        checks.append("constraint")
    return checks


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


@pytest.mark.parametrize("system_id,simulator,check", [
    pytest.param(a, b, c, id=f"{a}-{b}-{c}", marks=pytest.mark.xdist_group(a))
    for a, b, c in CASES])
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
    assert not bad, "gates failed:\n" + "\n".join(bad)
    assert not xpassed, "unexpected passes (strict expected failures):\n" + "\n".join(xpassed)
