"""The gates as a pytest plugin (entry point ``pytest11``), for a user's own test session:
``pytest --mbfidelity`` adds one test per system x engine, id ``mbfidelity/<system>-<engine>``,
that runs the comparison and fails with the gates that failed (the conformance suite of
this repository, `tests/test_conformance.py`, judged the same way: a declared expected
failure holds, an unexpected pass fails). Inert without ``--mbfidelity``.

Options: ``--mbfidelity-systems a,b`` and ``--mbfidelity-sims x,y`` choose the matrix
(default: every system, every installed engine); ``--mbfidelity-system-path FILE`` adds a
mechanism module of one's own (repeatable); ``--mbfidelity-dt`` sets the step.
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("mbfidelity", "multibody simulators against exact models")
    group.addoption("--mbfidelity", action="store_true",
                    help="run mbfidelity's gates: one test per system x engine")
    group.addoption("--mbfidelity-systems", default="", metavar="IDS",
                    help="comma-separated system ids (default: all)")
    group.addoption("--mbfidelity-sims", default="", metavar="IDS",
                    help="comma-separated engines (default: every installed one)")
    group.addoption("--mbfidelity-system-path", action="append", default=[], metavar="FILE",
                    help="a mechanism module of your own (repeatable)")
    group.addoption("--mbfidelity-dt", type=float, default=1e-3, metavar="S",
                    help="time step of the engines (default 1e-3 s)")


class GatesFailed(AssertionError):
    """The gates of one comparison that failed, one per line."""


class GateItem(pytest.Item):
    """One system on one engine: every gate of the comparison must pass or be declared."""

    def __init__(self, *, system_id: str, simulator: str, dt: float, **kwargs) -> None:
        super().__init__(**kwargs)
        self.system_id, self.simulator, self.dt = system_id, simulator, dt

    def runtest(self) -> None:
        from .comparisons.runner import compare
        from .comparisons.verdict import UNSUPPORTED, failure_lines, verdict

        result = compare(self.system_id, self.simulator, dt=self.dt)
        if verdict(result) == UNSUPPORTED:  # declared: a visible skip with the reason
            pytest.skip(f"unsupported (declared): {self.simulator} cannot express "
                        f"{self.system_id}: {result.reason}")
        lines = failure_lines(result)
        if lines:
            raise GatesFailed("\n".join(lines))

    def repr_failure(self, excinfo, style=None):
        if isinstance(excinfo.value, GatesFailed):
            return (f"{self.system_id} on {self.simulator}: gates failed\n"
                    f"{excinfo.value}")
        return super().repr_failure(excinfo, style)

    def reportinfo(self):
        return Path("mbfidelity"), None, f"mbfidelity {self.system_id} on {self.simulator}"


def _split(text: str) -> list[str]:
    return [x for x in text.split(",") if x]


def pytest_collection_modifyitems(session: pytest.Session, config: pytest.Config,
                                  items: list) -> None:
    if not config.getoption("--mbfidelity"):
        return
    from . import systems
    from .simulators import all_backends

    paths = [str(Path(p).resolve()) for p in config.getoption("--mbfidelity-system-path")]
    if paths:
        known = [p for p in os.environ.get(systems.SYSTEM_PATH_VARIABLE, "").split(os.pathsep)
                 if p]
        os.environ[systems.SYSTEM_PATH_VARIABLE] = os.pathsep.join(
            dict.fromkeys(known + paths))
        systems._REGISTRY = None
    try:
        catalog = systems.all_systems()
    except ValueError as exc:
        raise pytest.UsageError(str(exc)) from exc
    chosen = _split(config.getoption("--mbfidelity-systems")) or list(catalog)
    unknown = [s for s in chosen if s not in catalog]
    if unknown:
        raise pytest.UsageError(f"--mbfidelity-systems: unknown {', '.join(unknown)}; valid: "
                                f"{', '.join(catalog)}")
    backends = all_backends()
    sims = _split(config.getoption("--mbfidelity-sims")) or [
        e for e, b in backends.items() if b.available()[0]]
    unknown = [e for e in sims if e not in backends]
    if unknown:
        raise pytest.UsageError(f"--mbfidelity-sims: unknown {', '.join(unknown)}; valid: "
                                f"{', '.join(backends)}")
    dt = config.getoption("--mbfidelity-dt")
    for system_id in chosen:
        for simulator in sims:
            items.append(GateItem.from_parent(session, name=f"mbfidelity/{system_id}-{simulator}",
                                              system_id=system_id, simulator=simulator, dt=dt))
