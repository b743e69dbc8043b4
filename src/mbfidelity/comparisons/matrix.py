"""The runner over the matrix system x simulator: tidy results (one row per system x
engine x settings x metric, with provenance) written to a folder."""
from __future__ import annotations

import csv
import json
import os
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Callable, Iterable, Mapping

import numpy as np

from ..systems import get_system
from . import results_folder
from .budget import become_worker
from ..analytic.derivation import cache_key
from .runner import (Comparison, compare, failed_comparison, isolated_compare, own_step,
                     provenance, record_incident)

#: wall-clock budget of one comparison when a job is re-run engine by engine after its
#: worker died (see `run_matrix`)
ISOLATED_TIMEOUT = 1800.0

ROW_FIELDS = ("system", "variant", "simulator", "engine_version", "metric", "value", "tolerance", "unit",
              "status", "passed", "reason", "dt", "settings", "git_describe", "date",
              "python", "platform")


def _one_system(args, run=compare) -> tuple[list[Comparison], float]:
    """Every engine on one system, in one process: the references are solved once
    (cached) and shared by all engines; with `variants`, also each variant of the system
    on the engines that build it. With `out`, what the report shows of the system is
    saved there (`results_folder`): each comparison's series (then dropped from the
    returned comparisons), the mechanism's drawing and the errata entries, made here in
    parallel on the derivation and models this process already built. Returns the
    comparisons and the job's CPU seconds."""
    system, sims, dt, variants, out, settings = args
    dt = own_step(system, dt)
    start = time.process_time()

    def attempt(sim, **kwargs) -> Comparison:
        try:
            return run(system, sim, dt=dt, keep_series=True, **kwargs)
        except Exception as exc:  # this comparison fails; the others go on
            return failed_comparison(system, sim, None, dt, kwargs.get("variant") or "",
                                     "comparison", exc)
    found = [attempt(sim, settings=settings.get(sim)) for sim in sims]
    if variants:
        for v in get_system(system).variants:
            # engines that do not build the variant give an "unsupported" row, with why
            found += [attempt(sim, variant=v.name) for sim in sims]
    if out is not None:
        try:
            _save_report_files(out, system, found)
        except Exception as exc:  # the results stand; the report shows the incident
            for c in found:
                c.series = {}
                record_incident(c, "*", "report files", exc)
    return found, time.process_time() - start


def _save_report_files(out: Path, system: str, found: list[Comparison]) -> None:
    """What the report shows of a system, saved in `out`: each comparison's series (then
    dropped from it), the mechanism's drawing and the errata entries."""
    for row, comps in results_folder.rows_of(found).items():
        results_folder.save_series(out, row, comps)
        results_folder.save_deviations(out, row, comps)
    for c in found:
        c.series = {}
    results_folder.save_system(out, system)


def _portable_system(args) -> tuple[list[Comparison], float]:
    """`_one_system` for a worker that may not share this machine's disk: the series stay
    in the returned comparisons, and the caller saves them (`_save_report_files`)."""
    system, sims, dt, variants, _, settings = args
    return _one_system((system, sims, dt, variants, None, settings))


def _run_on_cluster(scheduler: str, order: list[int], systems: list[str], common: tuple,
                    out: Path | None, collect: Callable) -> list[int]:
    """The jobs `order` (indices into `systems`) on an existing Dask cluster, one task per
    system, longest first; each finished job is collected as it completes. A job whose
    worker died on every try (dask's KilledWorker) is returned, to run again engine by
    engine like a crashed local job."""
    from dask.distributed import Client, KilledWorker
    from dask.distributed import as_completed as completed

    sims, dt, variants, settings = common
    crashed = []
    with Client(scheduler) as client:
        futures = {client.submit(_portable_system,
                                 (systems[i], sims, dt, variants, None, settings),
                                 pure=False): i for i in order}
        for fut in completed(list(futures)):
            i = futures[fut]
            try:
                job = fut.result()
            except KilledWorker:
                crashed.append(i)
                continue
            if out is not None:
                _save_report_files(out, systems[i], job[0])
            collect(i, job)
    return crashed


def _failed_job(system: str, sims: list[str], dt: float, exc: BaseException
                ) -> list[Comparison]:
    return [failed_comparison(system, sim, None, own_step(system, dt), "", "job", exc)
            for sim in sims]


def _isolated_job(args) -> tuple[list[Comparison], float]:
    """A job whose worker died, again, each comparison in a worker of its own with a
    wall-clock budget: the one that kills its worker is recorded as crashed (or
    timed_out) and the others complete."""
    def run(system_id, simulator, **kwargs):
        return isolated_compare(system_id, simulator, None, timeout=ISOLATED_TIMEOUT, **kwargs)
    return _one_system(args, run=run)


# --- finished jobs, kept for `run --resume` ---------------------------------------------


def _job_request(system: str, sims: list[str], dt: float, variants: bool,
                 settings: Mapping[str, dict]) -> tuple:
    """What a finished job answers: the system (its content key: description and
    derivation code), the engines, the step, whether variants ran and the settings."""
    return (system, cache_key(get_system(system)), tuple(sims), dt, variants,
            json.dumps(settings, sort_keys=True))


def _job_path(out: Path, system: str) -> Path:
    return out / "jobs" / f"{system}.json"


def _save_job(out: Path, request: tuple, job: tuple[list[Comparison], float]) -> None:
    """As plain data (JSON: nothing in an output folder is ever executed), atomically
    (temporary file, then rename): a run killed while writing leaves the previous state,
    never a partial file."""
    path = _job_path(out, request[0])
    path.parent.mkdir(parents=True, exist_ok=True)
    comparisons, cpu = job
    doc = {"request": list(request), "cpu_seconds": cpu, "provenance": {},
           "comparisons": [c.as_dict() for c in comparisons]}
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump(doc, fh, default=float)
    os.replace(tmp, path)


def _load_job(out: Path, request: tuple) -> tuple[list[Comparison], float] | None:
    """The saved job answering `request`, or None (missing, damaged, another request, or
    report files of the system that no longer load: recomputed, never trusted)."""
    try:
        doc = json.loads(_job_path(out, request[0]).read_text())
        if doc["request"] != json.loads(json.dumps(list(request))):
            return None
        _, comparisons = results_folder.comparisons_from_document(doc, "a saved job")
        cpu = float(doc["cpu_seconds"])
    except Exception:  # missing, partial, damaged or from another version
        return None
    if not results_folder.report_files_intact(out, request[0], comparisons):
        return None
    return comparisons, cpu


def reusable_jobs(out: Path, systems: Iterable[str], simulators: Iterable[str],
                  dt: float | None = None, variants: bool = False,
                  settings: Mapping[str, dict] | None = None) -> list[str]:
    """The systems whose finished job `out` holds for this request (`run --resume`)."""
    sims = list(simulators)
    return [s for s in systems
            if _load_job(out, _job_request(s, sims, dt, variants, settings or {})) is not None]


def estimated_cost(system_id: str) -> float:
    """A job's cost from the description, for systems never run into the folder:
    coordinates x (coordinates + constraint rows) x simulated seconds of the scenarios
    (the size of what is derived and solved, times the time stepped). In arbitrary
    units; only the order of the jobs depends on it."""
    system = get_system(system_id)
    n = len(system.coordinates)
    constraint_rows = n - len(system.mechanism.independent_coordinates)
    return float(n * (n + constraint_rows) * sum(sc.t_end for sc in system.scenarios))


def schedule(systems: Iterable[str], measured: Mapping[str, float] | None = None) -> list[str]:
    """The systems in dispatch order, longest job first (stable for equal costs), so that
    the last job to finish is a short one: by their `measured` CPU seconds (the last run's
    `job_costs.json`); a system without one by `estimated_cost`, scaled to seconds by the
    median ratio of measured to estimated costs of the others."""
    systems = list(systems)
    measured = {s: c for s, c in (measured or {}).items() if s in systems}
    estimate = {s: estimated_cost(s) for s in systems if s not in measured}
    ratios = [c / estimated_cost(s) for s, c in measured.items()]
    to_seconds = float(np.median(ratios)) if ratios else 1.0
    cost = {**{s: e * to_seconds for s, e in estimate.items()}, **measured}
    return sorted(systems, key=cost.__getitem__, reverse=True)


def run_matrix(systems: Iterable[str], simulators: Iterable[str], dt: float | None = None,
               workers: int | None = None,
               progress: Callable[[Comparison], None] | None = None,
               variants: bool = False, out: Path | None = None,
               resume: bool = False,
               settings: Mapping[str, dict] | None = None,
               scheduler: str | None = None) -> list[Comparison]:
    """Every system on every simulator, in `systems` order. With several workers the
    systems are dispatched longest first (`schedule`, with the job costs of the last run
    into `out`) to a process pool; each system is one job (its references and derivation
    are shared by its engines). With `out`, each job also saves what the report shows of
    its system there (see `_one_system`), and the jobs' CPU seconds are saved for the
    next run's order.

    Each finished job is also saved there as it completes (atomically); `resume` reuses
    the saved jobs that answer the same request (`reusable_jobs`) and runs only the
    others. A job whose worker process dies (a segfault in an engine) loses no
    other job: it runs again engine by engine, each comparison in a worker of its own
    (`_isolated_job`). `settings` maps an engine to the settings it runs with (its
    defaults for the others). With `scheduler` (a Dask scheduler's address) the jobs run
    on that cluster instead of the local pool, one task per system, with the same
    results; the workers need not share this machine's disk (`_run_on_cluster`)."""
    systems = list(systems)
    settings = dict(settings or {})
    sims = list(simulators)
    workers = workers or min(2, os.cpu_count() or 1)
    workers = max(1, min(workers, len(systems)))
    batches: dict[int, list[Comparison]] = {}
    costs: dict[str, float] = {}
    requests = {s: _job_request(s, sims, dt, variants, settings) for s in systems}

    def collect(i, job, fresh=True):
        batches[i], costs[systems[i]] = job
        if out is not None and fresh:
            _save_job(out, requests[systems[i]], job)
        if progress:
            for res in batches[i]:
                progress(res)

    todo = []
    for i, s in enumerate(systems):
        saved = _load_job(out, requests[s]) if (resume and out is not None) else None
        if saved is not None:
            collect(i, saved, fresh=False)
        else:
            todo.append(i)
    crashed = []

    def longest_first() -> list[int]:
        rank = {s: k for k, s in enumerate(schedule(systems, results_folder.load_job_costs(out)))}
        return sorted(todo, key=lambda i: rank[systems[i]])
    if scheduler and todo:
        crashed = _run_on_cluster(scheduler, longest_first(), systems,
                                  (sims, dt, variants, settings), out, collect)
    elif workers <= 1 or len(todo) <= 1:
        for i in todo:
            collect(i, _one_system((systems[i], sims, dt, variants, out, settings)))
    else:
        order = longest_first()
        with ProcessPoolExecutor(max_workers=workers, initializer=become_worker,
                                 initargs=(os.getpid(),)) as pool:
            futures = {pool.submit(_one_system,
                                   (systems[i], sims, dt, variants, out, settings)): i
                       for i in order}
            for fut in as_completed(futures):
                try:
                    job = fut.result()
                except BrokenProcessPool:
                    crashed.append(futures[fut])
                    continue
                except Exception as exc:  # the job could not come back: its rows fail
                    job = (_failed_job(systems[futures[fut]], sims, dt, exc), 0.0)
                collect(futures[fut], job)
    for i in sorted(crashed):
        collect(i, _isolated_job((systems[i], sims, dt, variants, out, settings)))
    if out is not None:
        results_folder.save_job_costs(out, costs)
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
