"""Declarations state the mechanism of a failure, never a measured number or an engine
version: the numbers come from the run (the results show each declared metric's value and
gate), and a sentence that quotes them turns false at the next engine upgrade while the
strict check, which looks at pass or fail only, still holds."""
import re

import pytest

from mbfidelity.simulators import all_backends
from mbfidelity.systems import all_systems, get_system

#: what a reason must not contain: a decimal or scientific number, a number with a unit,
#: an engine's version, a measured ratio spelled out
MEASURED_OR_VERSION = re.compile(r"""(?ix)
    \d+\.\d+                                    # a decimal number
  | \d(\.\d+)?e[-+]?\d+                         # scientific notation
  | \d+\s*(rad/s|m/s|mm\b|ms\b|kg\b|hz\b|%|deg\b|degrees|n\s?m\b|n/m\b)  # with a unit
  | (mujoco|pybullet|pymunk|exudyn|drake)\s+v?\d  # an engine version
  | \b(twice|half|two|three|four|five|six|seven|eight|nine|ten|hundred|thousand)\s+
      (times|percent|as\s+(much|many|large))    # a measured ratio in words
  | \b(twenty|thirty|forty|fifty|sixty|seventy|eighty|ninety)\b
""")
#: citations, not measurements: the monograph's sections, equations and figures
CITATION = re.compile(r"§\s*\d+(\.\d+)*|\beqs?\.\s*\d+(-\d+)?|\bfigs?\.\s*\d+(-\d+)?", re.I)


def offending(reason: str) -> list[str]:
    return [m.group(0) for m in MEASURED_OR_VERSION.finditer(CITATION.sub("", reason))]


def declarations() -> list[tuple[str, str]]:
    found = []
    for system_id in all_systems():
        system = get_system(system_id)
        found += [(f"{system_id}: {e.simulator} {e.metric}", e.reason)
                  for e in system.expectations]
        found += [(f"{system_id} variant {v.name}", v.reason) for v in system.variants]
    for engine, backend in all_backends().items():
        found += [(f"{engine} {kind}", e.reason) for kind, cases in backend.EXPRESSIONS.items()
                  for e in cases if e.reason]
    return found


@pytest.mark.parametrize("text,hits", [
    ("falls short by 3e-4 of the amplitude", ["3e-4"]),
    ("a fast spin (40 rad/s)", ["40 rad/s"]),
    ("passes 0.1 of the amplitude", ["0.1"]),
    ("since MuJoCo 4.0 the solver", ["MuJoCo 4"]),
    ("bends the hinges by up to three times as much", ["three times"]),
    ("the run is thirty steps long", ["thirty"]),
    ("eq. 86 and §7.2, Fig. 31: a velocity error of order h^2, RK4's fourth order, 2 dt", []),
])
def test_the_pattern_tells_measurements_from_citations(text, hits):
    assert offending(text) == hits


def test_no_declaration_quotes_a_measured_number_or_an_engine_version():
    found = declarations()
    assert len(found) > 40  # the systems' and the backends' declarations were all read
    bad = {where: offending(reason) for where, reason in found if offending(reason)}
    assert not bad, bad


def test_the_report_shows_each_declared_metric_with_its_value_and_gate_of_the_run():
    """A declaration's reason carries no numbers: the mechanism's page lists, under each
    declaration, the metrics it covers with the value and gate of the run being shown."""
    from mbfidelity.comparisons.runner import Comparison, Metric
    from mbfidelity.reports.html import _expected

    run = Comparison("vertically_driven_pendulum", "pybullet", "", {}, {}, 1e-3)
    run.metrics = [Metric("hanging.actuator_actuator", 0.25, 0.03, False, "xfail"),
                   Metric("hanging.trajectory_max", 0.002, 0.03, True, "pass")]
    shown = {e.metric: e for e in _expected("vertically_driven_pendulum", [run])
             if e.simulator == "pybullet"}
    (covered,) = shown["*.actuator_actuator"].measured
    assert (covered.name, covered.value, covered.tolerance, covered.status) == (
        "hanging.actuator_actuator", 0.25, 0.03, "xfail")
    # a metric no declaration matches is not listed under one
    assert all(m.name != "hanging.trajectory_max" for e in shown.values() for m in e.measured)
