"""The runner over the matrix system x simulator: tidy results (one row per system x
engine x settings x metric, with provenance) written to a folder."""
from __future__ import annotations

import csv
import json
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
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
    on the engines that build it. With `prerender`, the system's report figures and
    errata are made here too (`reports.html.prerender`), in parallel and on the
    derivation and models this process already built, instead of serially in the parent
    by `write_report`."""
    system, sims, dt, variants, *rest = args
    prerender = bool(rest and rest[0])
    out = [compare(system, sim, dt=dt, keep_series=True) for sim in sims]
    if variants:
        for v in get_system(system).variants:
            # engines that do not build the variant give an "unsupported" row, with why
            out += [compare(system, sim, dt=dt, keep_series=True, variant=v.name)
                    for sim in sims]
    if prerender:
        from ..reports.html import prerender as prerender_report

        prerender_report(out)
    return out


#: relative cost of each system's job (CPU seconds of `_one_system` with the four engines,
#: report prerendering included, measured on the 2-core reference machine): the jobs are
#: dispatched longest first, so that the last job to finish is a short one. Unknown
#: systems count as the longest (they start first). Only the order depends on these.
JOB_COST = {
    "rhombus_linkage": 33.9, "rolling_disc_track": 19.9, "five_bar_bird": 18.5,
    "slotted_link_spring_damper": 15.9, "scotch_yoke": 13.5, "eccentric_cam": 11.7,
    "pendulum_sliding_block": 8.7, "elastic_pendulum": 8.7, "slotted_bar_arctan_damper": 7.8,
    "belt_pulleys": 6.0, "double_pendulum": 3.5, "mass_spring_damper": 3.4,
    "compound_pendulum": 2.4,
}


def _cost(system: str) -> float:
    return JOB_COST.get(system, max(JOB_COST.values()) + 1.0)


def schedule(systems: Iterable[str]) -> list[str]:
    """The systems in dispatch order: longest job first (stable for equal costs)."""
    return sorted(systems, key=_cost, reverse=True)


def run_matrix(systems: Iterable[str], simulators: Iterable[str], dt: float = DEFAULT_DT,
               workers: int | None = None,
               progress: Callable[[Comparison], None] | None = None,
               variants: bool = False, prerender: bool = True) -> list[Comparison]:
    """Every system on every simulator, in `systems` order. With several workers the
    systems are dispatched longest first (`schedule`) to a process pool; each system is
    one job (its references and derivation are shared by its engines). `prerender`:
    also make each system's report figures and errata in its job (see `_one_system`)."""
    systems = list(systems)
    sims = list(simulators)
    workers = workers or min(2, os.cpu_count() or 1)
    workers = max(1, min(workers, len(systems)))
    batches: dict[int, list[Comparison]] = {}

    def collect(i, batch):
        batches[i] = batch
        if progress:
            for res in batch:
                progress(res)

    if workers <= 1:
        for i, s in enumerate(systems):
            collect(i, _one_system((s, sims, dt, variants, prerender)))
    else:
        order = sorted(range(len(systems)), key=lambda i: _cost(systems[i]), reverse=True)
        with ProcessPoolExecutor(max_workers=workers) as pool:
            futures = {pool.submit(_one_system, (systems[i], sims, dt, variants, prerender)): i
                       for i in order}
            for fut in as_completed(futures):
                collect(futures[fut], fut.result())
    # in the order of `systems`, whatever order the jobs finished in
    return [res for i in range(len(systems)) for res in batches[i]]


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
