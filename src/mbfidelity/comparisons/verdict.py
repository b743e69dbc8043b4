"""The one verdict rule, used by the runner, `diff`, `check`, the command line and the
pytest plugin.

A metric holds when it passes, is a declared expected failure that failed (xfail), is a
variant's own measurement, or is a declared unresolved metric. A comparison is

- ``unsupported`` when the engine cannot express the system (declared, with the
  reason): never a failure, never silent;
- ``pass`` when every metric holds and no stage failed;
- ``fail`` otherwise (a gate failed, an unexpected pass, an incident).
"""
from __future__ import annotations

PASS, FAIL, UNSUPPORTED = "pass", "fail", "unsupported"
HOLDING = ("pass", "xfail", "measured")


def holds(metric) -> bool:
    """Whether the metric lets its comparison pass."""
    return metric.status in HOLDING or (metric.status == "unresolved" and metric.expected)


def verdict(comparison) -> str:
    """pass | fail | unsupported, for a `Comparison`."""
    if not comparison.supported:
        return UNSUPPORTED
    return PASS if all(holds(m) for m in comparison.metrics) else FAIL


def failure_lines(comparison) -> list[str]:
    """Why the comparison failed, one line per metric or incident (empty when it did
    not)."""
    lines = []
    for m in comparison.metrics:
        if holds(m):
            continue
        if m.status == "xpass":
            lines.append(f"{m.name}: passed but declared an expected failure ({m.reason})")
        elif m.status == "unresolved":
            lines.append(f"{m.name}: cannot judge ({m.reason})")
        elif m.unit == "stage completed" or m.name.endswith(".completed"):
            continue  # said by its incident
        else:
            lines.append(f"{m.name}: {m.value:.3e} > {m.tolerance:.3e}")
    for i in comparison.incidents:
        stage = f" ({i['stage']})" if i.get("stage") else ""
        lines.append(f"{i['scenario']}{stage}: {i['outcome']}: {i['message']}")
    return lines
