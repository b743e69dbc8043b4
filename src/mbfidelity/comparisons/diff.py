"""What changed between two runs: per system x engine x metric, the engine versions and
settings side by side, the metrics that moved, the gates that flipped, the metrics that
are new or vanished. Results are deterministic (the same inputs give bitwise the same
metrics), so any difference is real: a moved value is reported however small.

A run is a results folder (`mbfidelity run --out DIR`, `mbfidelity check --out DIR`) or a
recorded baseline, its `results.json` alone. A gate got worse when a metric that passed
(or was declared) no longer does, or a comparison that passed no longer does.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

from .results_folder import RESULTS, comparisons_from_document, row_id
from .runner import Comparison, Metric

#: metric statuses that do not fail a comparison (an unresolved one only if declared)
from .verdict import HOLDING, holds  # noqa: F401  (the one rule, re-exported)


@dataclass
class MetricChange:
    name: str
    #: moved (value or tolerance differ, same verdict) | flipped (the verdict changed) |
    #: new | vanished
    kind: str
    old: dict | None
    new: dict | None
    #: a gate that held and no longer does
    worse: bool = False


@dataclass
class PairDiff:
    """One system (row) on one engine in both runs, or in one of them."""
    row: str
    simulator: str
    #: changed | same | new | vanished
    kind: str
    versions: tuple[str, str] | None = None
    #: key -> [old, new] for every engine setting that differs
    settings: dict = field(default_factory=dict)
    #: dt and parameters that differ, key -> [old, new]
    inputs: dict = field(default_factory=dict)
    passed: tuple[bool, bool] | None = None
    metrics: list[MetricChange] = field(default_factory=list)

    @property
    def worse(self) -> bool:
        return bool(self.passed and self.passed[0] and not self.passed[1]) or any(
            m.worse for m in self.metrics)


@dataclass
class ResultsDiff:
    old: str
    new: str
    provenance: tuple[dict, dict]
    pairs: list[PairDiff]

    @property
    def worse(self) -> bool:
        return any(p.worse for p in self.pairs)

    def as_dict(self) -> dict:
        return {"old": self.old, "new": self.new,
                "provenance": {"old": self.provenance[0], "new": self.provenance[1]},
                "worse": self.worse,
                "pairs": [{**asdict(p), "worse": p.worse} for p in self.pairs
                          if p.kind != "same"],
                "unchanged": [f"{p.row}/{p.simulator}" for p in self.pairs
                              if p.kind == "same"]}


def load_run(path: Path) -> tuple[dict, list[Comparison]]:
    """A run given as its folder or as a results document (results.json, or a recorded
    baseline under another name)."""
    path = Path(path)
    document = path / RESULTS if path.is_dir() else path
    try:
        doc = json.loads(document.read_text())
    except (OSError, ValueError) as exc:
        raise ValueError(f"{path}: no readable {RESULTS} (a results folder of `mbfidelity "
                         f"run` or `check`, or a recorded results.json): {exc}") from exc
    return comparisons_from_document(doc, str(document))


def _same_number(a: float, b: float) -> bool:
    return a == b or (math.isnan(a) and math.isnan(b))


def _metric_dict(m: Metric) -> dict:
    return {"value": m.value, "tolerance": m.tolerance, "status": m.status,
            "holds": holds(m), "unit": m.unit}


def _metric_changes(old: Comparison, new: Comparison) -> list[MetricChange]:
    before = {m.name: m for m in old.metrics}
    after = {m.name: m for m in new.metrics}
    changes = []
    for name in list(before) + [n for n in after if n not in before]:
        a, b = before.get(name), after.get(name)
        if a is None:
            changes.append(MetricChange(name, "new", None, _metric_dict(b)))
        elif b is None:
            changes.append(MetricChange(name, "vanished", _metric_dict(a), None))
        elif a.status != b.status or holds(a) != holds(b):
            changes.append(MetricChange(name, "flipped", _metric_dict(a), _metric_dict(b),
                                        worse=holds(a) and not holds(b)))
        elif not (_same_number(a.value, b.value) and _same_number(a.tolerance, b.tolerance)):
            changes.append(MetricChange(name, "moved", _metric_dict(a), _metric_dict(b)))
    return changes


def _differing(a: dict, b: dict) -> dict:
    return {k: [a.get(k), b.get(k)] for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)}


def diff_runs(old: Path, new: Path) -> ResultsDiff:
    """The differences between two runs (folders or recorded results.json files)."""
    prov_old, comps_old = load_run(old)
    prov_new, comps_new = load_run(new)
    before = {(row_id(c), c.simulator): c for c in comps_old}
    after = {(row_id(c), c.simulator): c for c in comps_new}
    pairs = []
    for key in list(before) + [k for k in after if k not in before]:
        a, b = before.get(key), after.get(key)
        if a is None or b is None:
            one = a or b
            pairs.append(PairDiff(*key, kind="vanished" if b is None else "new",
                                  versions=(one.engine_version,) * 2))
            continue
        pair = PairDiff(*key, kind="same", versions=(a.engine_version, b.engine_version),
                        settings=_differing(a.settings, b.settings),
                        inputs=_differing({"dt": a.dt, **a.parameters},
                                          {"dt": b.dt, **b.parameters}),
                        passed=(a.passed, b.passed), metrics=_metric_changes(a, b))
        if (pair.settings or pair.inputs or pair.metrics or a.passed != b.passed
                or a.engine_version != b.engine_version or a.supported != b.supported):
            pair.kind = "changed"
        pairs.append(pair)
    return ResultsDiff(str(old), str(new), (prov_old, prov_new), pairs)
