"""The runner over the matrix system x simulator: tidy results (one row per system x
engine x settings x metric, with provenance) written to a folder."""
from __future__ import annotations

import csv
import json
import os
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Callable, Iterable

from ..systems import get_system
from .runner import DEFAULT_DT, Comparison, compare, provenance

ROW_FIELDS = ("system", "variant", "simulator", "engine_version", "metric", "value", "tolerance", "unit",
              "status", "passed", "reason", "dt", "settings", "git_describe", "date",
              "python", "platform")


def _one_system(args) -> list[Comparison]:
    """Every engine on one system, in one process: the references are solved once
    (cached) and shared by all engines; with `variants`, also each variant of the system
    on the engines that build it."""
    system, sims, dt, variants = args
    out = [compare(system, sim, dt=dt, keep_series=True) for sim in sims]
    if variants:
        for v in get_system(system).variants:
            # engines that do not build the variant give an "unsupported" row, with why
            out += [compare(system, sim, dt=dt, keep_series=True, variant=v.name)
                    for sim in sims]
    return out


def run_matrix(systems: Iterable[str], simulators: Iterable[str], dt: float = DEFAULT_DT,
               workers: int | None = None,
               progress: Callable[[Comparison], None] | None = None,
               variants: bool = False) -> list[Comparison]:
    sims = list(simulators)
    jobs = [(s, sims, dt, variants) for s in systems]
    workers = workers or min(2, os.cpu_count() or 1)
    results: list[Comparison] = []

    def collect(batch):
        for res in batch:
            results.append(res)
            if progress:
                progress(res)

    if workers <= 1:
        for job in jobs:
            collect(_one_system(job))
        return results
    with ProcessPoolExecutor(max_workers=workers) as pool:
        for batch in pool.map(_one_system, jobs):
            collect(batch)
    return results


def tidy_rows(results: list[Comparison], prov: dict) -> list[dict]:
    rows = []
    for c in results:
        common = {"system": c.system, "variant": c.variant, "simulator": c.simulator,
                  "engine_version": c.engine_version, "dt": c.dt,
                  "settings": json.dumps(c.settings, sort_keys=True),
                  **{k: prov[k] for k in ("git_describe", "date", "python", "platform")}}
        if not c.supported:
            rows.append({**common, "metric": "*", "value": "", "tolerance": "", "unit": "",
                         "status": "unsupported", "passed": "", "reason": c.reason})
        for m in c.metrics:
            rows.append({**common, "metric": m.name, "value": m.value, "tolerance": m.tolerance,
                         "unit": m.unit, "status": m.status, "passed": m.passed,
                         "reason": m.reason})
    return rows


def write_results(results: list[Comparison], out: Path) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    prov = provenance()
    rows = tidy_rows(results, prov)
    with open(out / "results.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=ROW_FIELDS)
        writer.writeheader()
        writer.writerows(rows)
    doc = {"provenance": prov, "comparisons": [c.as_dict() for c in results]}
    (out / "results.json").write_text(json.dumps(doc, indent=1, default=float))
    return doc
