"""The out-of-the-box study: what each engine default the harness neutralises does to a
mechanism when it is switched back on, and, with `kinds`, the power study's model errors
(comparisons/power.py) from the same neutralised run: one study makes both documents.

For every system x engine: the neutralised run (the harness's settings; every declared
scenario and the frequency checks, `runner.compare(scenarios=declared)`), then each
neutralised default (`Setting.engine_default`: the engine's documented value, cited in the
setting's note) switched back on alone, and all of them together (the engine as a user gets
it), each in the same comparison, judged at the neutralised run's gates (the harness's
gates at its configuration, `runner.compare(held_gates=)`). Recorded per default, in the power study's format
(`power.DefaultPower`): the gates' verdict (rejected when a metric that holds in the
neutralised run fails with the default, or the run does not complete:
`power.rejecting_metrics`), whether anything moved at all and what it moved most against
its gate (`power.largest_change`, `power.classify_default`), the effect metric by metric
against the neutralised run (trajectory error, energy drift, period, and the frequency and
damping ratio of the free-vibration fits), and per scenario the motion change: the largest
difference between the engine's motion with the default and without it, relative to the
coordinate's amplitude (as the trajectory gate measures), against the scenario's
trajectory gate.

Cost: one job per system in a process pool (as `matrix.run_matrix`), its engines one after
the other. The neutralised run is made in the job's process, so that the reference solves,
derivations and equilibria it computes are shared by each default's run, a process forked
from it (comparisons/isolation.py) with a wall-clock budget (`RUN_BUDGET_FACTOR` times the
neutralised run, at least `RUN_BUDGET_FLOOR`): a default that makes its engine crash, or
run past the budget, costs that run, recorded with its incident (it counts as rejected),
and nothing else. A job whose own process dies (the neutralised run crashed its engine) is
made again engine by engine, each in a worker of its own. The near-equilibrium checks of
`mbfidelity run` are not run. With `kinds` (`mbfidelity power`), each model error's runs
(the first scenario) are judged against the same neutralised run, forked from the same
process.

Each system x engine's reading is kept in the persistent cache under the content it
depends on (`cached_entry`): a report made again with the same code, engines and
libraries takes the readings from there, and an engine's upgrade makes its readings alone
again. A recorded study (the power.json a study wrote, `recorded_readings`) lends its
readings the same way, but matched by the engine's version and the step only: a reading
from it is marked with the state of the package that made it (`PowerEntry.recorded`), and
the readings it lacks, or made with another version of the engine, are made by the study.
"""
from __future__ import annotations

import gzip
import hashlib
import json
import os
import pickle
import resource
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Callable, Iterable, Mapping

import numpy as np

from ..analytic import cache
from ..analytic.derivation import cache_key
from ..simulators import get_backend
from ..systems import get_system
from .budget import become_worker
from .isolation import WorkerCrashed, WorkerTimedOut, isolated
from .power import (ERROR_KINDS, RUN_TIMEOUT_FACTOR, RUN_TIMEOUT_FLOOR, DefaultPower, PowerEntry,
                    classify_default, effect_against, engine_defaults, error_powers,
                    free_coordinates, largest_change, metric_named, out_of_the_box_document,
                    power_document, rejecting_metrics, same_metrics, worst_scenario)
from .runner import (Comparison, UnstableStep, compare, failed_comparison, isolated_compare,
                     own_step)

#: wall-clock budget of one default's run: this many times the neutralised run's wall
#: time, at least RUN_BUDGET_FLOOR s. A default can make a run much longer than the
#: harness's (a joint locked by a motor leaves the free-vibration fits a record without
#: oscillation to search); beyond the budget the run is recorded as timed out
RUN_BUDGET_FACTOR = 10.0
RUN_BUDGET_FLOOR = 60.0
#: wall-clock budget of one system x engine made again in a worker of its own after its
#: job's process died
ENTRY_TIMEOUT = 1800.0
#: the name of every neutralised default switched on together
ALL = "all"


def _motion_change(neutral: Mapping[str, tuple], on: Comparison, free: list[int]) -> dict:
    """Per scenario, the largest |q_on - q_off| over the free coordinates relative to
    their amplitude (the trajectory gate's scale), from the two comparisons' series: a
    sample not finite in one run only is an infinite change, one not finite in both (a
    run that fails there either way) none."""
    out = {}
    for name, series in on.series.items():
        if name not in neutral:
            continue
        q_off, scale = neutral[name]
        q_on = np.asarray(series["q"], dtype=float)
        n = min(len(q_off), len(q_on))
        a, b = q_on[:n][:, free], q_off[:n][:, free]
        with np.errstate(invalid="ignore"):
            change = np.abs(a - b) / scale[free]
        change[~np.isfinite(change)] = np.inf
        change[~np.isfinite(a) & ~np.isfinite(b)] = 0.0
        out[name] = {"trajectory_change": float(change.max()) if change.size else np.inf}
    return out


def _switched_on(system_id: str, simulator: str, dt: float, declared: list[str],
                 settings: dict, neutral: Mapping[str, tuple], free: list[int],
                 held: Mapping[str, dict]) -> tuple[Comparison, dict]:
    """One default's comparison (a worker's task), judged at the neutralised run's gates
    (`held`): the comparison without its series and the motion change against the
    neutralised run per scenario."""
    c = compare(system_id, simulator, dt=dt, scenarios=declared, settings=settings,
                keep_series=True, held_gates=held)
    motion = _motion_change(neutral, c, free)
    c.series = {}
    return c, motion


def _reading(key: str, value: object, harness: object, note: str, neutral: Comparison,
             run: Comparison, motion: dict, declared: list[str],
             wall_time: float) -> DefaultPower:
    """The default's verdict and effect against the neutralised run."""
    by = rejecting_metrics(neutral, run)
    scenarios = {}
    for name in declared:
        m = dict(motion.get(name, {}))
        gate = metric_named(neutral, f"{name}.trajectory_max")
        if gate is not None and "trajectory_change" in m:
            m["trajectory_gate"] = gate.tolerance
            m["beyond_gate"] = bool(m["trajectory_change"] > gate.tolerance)
        before, after = (metric_named(c, f"{name}.energy_drift") for c in (neutral, run))
        m["energy_drift_neutralised"] = before.value if before is not None else None
        m["energy_drift_switched_on"] = after.value if after is not None else None
        scenarios[name] = m
    d = DefaultPower(key, value, harness, bool(by), by, run.passed,
                     moved=not same_metrics(neutral, run), effect=effect_against(neutral, run),
                     note=note, incidents=run.incidents, wall_time_s=wall_time,
                     change=largest_change(neutral, run, scenarios))
    d.motion["scenarios"] = scenarios
    measured = {k: v for k, v in scenarios.items() if "trajectory_change" in v}
    if measured:
        name, worst = worst_scenario(measured)
        d.motion.update(worst, scenario=name)
    else:
        d.motion["error"] = "; ".join(f"{i['outcome']}: {i['message']}"
                                      for i in run.incidents) or "no motion recorded"
    d.motion["beyond_gate"] = any(m.get("beyond_gate", False) for m in scenarios.values())
    classify_default(d, neutral)
    return d


def defaults_entry(system_id: str, simulator: str, dt: float | None = None,
                   only: Iterable[str] | None = None, kinds: Iterable[str] = ()
                   ) -> PowerEntry:
    """The out-of-the-box reading of one system on one engine (see the module doc); with
    `only`, just those of the engine's neutralised defaults, each alone (no "all"); with
    `kinds`, the power study's model errors of those kinds too."""
    kinds = tuple(kinds)
    dt = own_step(system_id, dt)
    started = time.perf_counter()
    system = get_system(system_id)
    backend = get_backend(simulator)
    declared = [sc.name for sc in system.scenarios]
    entry = PowerEntry(system.id, simulator, scenario=declared[0],
                       defaults_scenarios=declared, dt=dt)
    ok, why = backend.available()
    if not ok:
        entry.supported, entry.reason = False, f"engine not available: {why}"
        return entry
    entry.engine_version = backend.version()
    switched = engine_defaults(simulator, dt)
    if only is not None:
        switched = {k: v for k, v in switched.items() if k in set(only)}
    if not switched and not kinds:  # nothing to switch on: no run
        return entry
    values = system.parameter_values(None, scenario=system.scenarios[0])
    free = free_coordinates(system.with_structure(values), values)
    entry.comparisons += 1
    # the model errors alone need the first scenario only
    scenarios = declared if switched else declared[:1]
    neutral = compare(system.id, simulator, dt=dt, scenarios=scenarios,
                      keep_series=bool(switched))
    entry.engine_time_s += neutral.wall_time
    if not neutral.supported:
        entry.supported, entry.reason = False, neutral.reason
        entry.wall_time_s = time.perf_counter() - started
        return entry
    series = {name: (np.asarray(s["q"], dtype=float), np.asarray(s["scale"], dtype=float))
              for name, s in neutral.series.items()}
    neutral.series = {}
    entry.baseline_passed = neutral.passed
    entry.baseline_not_holding = [m.name for m in neutral.metrics
                                  if m.status not in ("pass", "xpass", "measured")]
    budget = max(RUN_BUDGET_FLOOR, RUN_BUDGET_FACTOR * (time.perf_counter() - started))
    # a default's or a model error's run is judged at the neutralised run's gates
    # (comparisons/power.py)
    held = {m.name: m.as_dict() for m in neutral.metrics}
    if kinds:
        error_budget = max(RUN_TIMEOUT_FLOOR, RUN_TIMEOUT_FACTOR * neutral.wall_time)

        def mutated(**kwargs) -> Comparison:
            entry.comparisons += 1
            c = isolated_compare(system.id, simulator, dt=dt, scenarios=declared[:1],
                                 timeout=error_budget, held_gates=held, **kwargs)
            entry.engine_time_s += c.wall_time
            return c

        entry.errors = error_powers(system, simulator, kinds, neutral, dt, mutated)
    chosen = [(key, {key: value}) for key, value in switched.items()]
    if len(switched) > 1 and only is None:
        chosen.append((ALL, dict(switched)))
    for key, settings in chosen:
        began = time.perf_counter()
        entry.comparisons += 1
        try:
            run, motion = isolated(_switched_on, system.id, simulator, dt, declared, settings,
                                   series, free, held, timeout=budget)
        except UnstableStep as exc:  # the engine's own default cannot run at this step
            run = failed_comparison(system.id, simulator, None, dt, "", "step", exc,
                                    "refused")
            motion = {}
        except (ValueError, KeyError):
            raise
        except Exception as exc:  # crashed or past its budget: the run's incident
            outcome = ("timed_out" if isinstance(exc, WorkerTimedOut) else
                       "crashed" if isinstance(exc, WorkerCrashed) else "failed")
            run = failed_comparison(system.id, simulator, None, dt, "", "worker", exc, outcome)
            motion = {}
        entry.engine_time_s += run.wall_time
        setting = backend.SETTINGS.get(key)
        entry.defaults.append(_reading(
            key, settings[key] if key in settings else settings,
            setting.default if setting is not None else None,
            setting.note if setting is not None else
            "every neutralised default switched back on together: the engine as it comes",
            neutral, run, motion, declared, time.perf_counter() - began))
    entry.wall_time_s = time.perf_counter() - started
    return entry


def power_entry(system_id: str, simulator: str, dt: float | None = None,
                kinds: Iterable[str] = tuple(ERROR_KINDS), defaults: bool = True
                ) -> PowerEntry:
    """The power study of one system on one engine (comparisons/power.py): the model
    errors of `kinds`, and with `defaults` the out-of-the-box reading from the same
    baseline (`defaults_entry`)."""
    return defaults_entry(system_id, simulator, dt, only=None if defaults else (),
                          kinds=tuple(kinds))


def _cpu_seconds() -> float:
    """CPU seconds of this process and of its finished children (the forked runs)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


#: the cache folder of the readings (`cached_entry`)
CACHE_FOLDER = "power"
#: bump when the layout or the meaning of a cached reading changes
CACHE_FORMAT = "2"


@lru_cache(maxsize=1)
def _package_digest() -> str:
    """Digest of every module of the package: the description, the derivation, the
    comparisons and the backends all decide a reading."""
    root = Path(__file__).resolve().parent.parent
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def _entry_key(system_id: str, simulator: str, dt: float, only, kinds) -> str | None:
    """Content key of one system x engine's reading: the package's code and the system's
    module, the engine's version (an upgraded engine's readings are made again, the
    others' kept), the numerical libraries' and Python's versions, and the study's
    arguments. None where the engine is not installed."""
    import scipy
    import sympy

    backend = get_backend(simulator)
    if not backend.available()[0]:
        return None
    h = hashlib.sha256()
    # the system's own module too: a user's mechanism lives outside the package
    for part in (CACHE_FORMAT, _package_digest(), cache_key(get_system(system_id)),
                 system_id, simulator, backend.version(),
                 float(dt).hex(), repr(None if only is None else sorted(only)),
                 repr(tuple(kinds)), np.__version__, scipy.__version__, sympy.__version__,
                 repr(sys.version_info[:3])):
        h.update(f"{part}|".encode())
    return h.hexdigest()[:32]


def cached_entry(system_id: str, simulator: str, dt: float, only, kinds=()) -> PowerEntry:
    """`defaults_entry`, kept in the persistent cache (analytic/cache.py: its folder, its
    switch, its checksums) under the content it depends on (`_entry_key`): a reading is
    deterministic but for its timings, so one taken from the cache is the one the run
    made (`from_cache`, with that run's timings)."""
    key = _entry_key(system_id, simulator, dt, only, kinds)
    if key is not None:
        payload = cache.load(CACHE_FOLDER, key)
        if payload is not None:
            try:
                entry = pickle.loads(payload)
            except Exception:  # a reading of an older layout: made again
                entry = None
            if isinstance(entry, PowerEntry):
                entry.from_cache = True
                return entry
    entry = defaults_entry(system_id, simulator, dt, only, kinds)
    if key is not None:
        cache.store(CACHE_FOLDER, key, pickle.dumps(entry))
    return entry


def read_record(path: str | Path) -> dict:
    """A recorded power study: the power.json that `mbfidelity power --out` wrote, plain or
    gzip-compressed. `ValueError` when the file is missing or is not such a document."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"no recorded power study at {path}")
    raw = path.read_bytes()
    try:
        doc = json.loads(gzip.decompress(raw) if raw[:2] == b"\x1f\x8b" else raw)
    except (OSError, EOFError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{path} is not a recorded power study: {exc}") from None
    missing = [k for k in ("provenance", "error_kinds", "entries") if not (
        isinstance(doc, dict) and k in doc)]
    if missing:
        raise ValueError(f"{path} is not a recorded power study (the power.json of "
                         f"`mbfidelity power --out`): no {', '.join(missing)}")
    return doc


def recorded_readings(doc: Mapping, kinds: Iterable[str]) -> dict[tuple[str, str], dict]:
    """(system, engine) -> the reading of a recorded study (`read_record`), each marked
    with the state of the package that made it (`PowerEntry.recorded`: its own mark where
    it was itself lent by an older record). `ValueError` when the record injected other
    error kinds than `kinds`."""
    if set(doc["error_kinds"]) != set(kinds):
        raise ValueError(f"the recorded study injected {', '.join(doc['error_kinds'])}; "
                         f"this study injects {', '.join(kinds)}")
    made_by = str(doc["provenance"].get("git_describe", "unknown"))
    return {(e["system"], e["simulator"]): {**e, "recorded": e.get("recorded") or made_by}
            for e in doc["entries"]}


def _lent(reading: Mapping | None, simulator: str, dt: float) -> PowerEntry | None:
    """A recorded reading where it was made with the installed version of the engine at
    step `dt`; None where the study must make it (a reading of a layout this version does
    not read, too)."""
    if reading is None:
        return None
    backend = get_backend(simulator)
    if not backend.available()[0] or reading.get("engine_version") != backend.version() \
            or reading.get("dt") != dt:
        return None
    try:
        return PowerEntry.from_dict({**reading, "from_cache": False})
    except (TypeError, KeyError, AttributeError):
        return None


def _system_job(system_id: str, sims: list[str], dt: float | None, only, kinds=(),
                recorded: Mapping[str, dict] | None = None
                ) -> tuple[list[PowerEntry], float]:
    """Every engine's reading of one system (`dt` None: the system's own step): lent by
    `recorded` (engine -> a recorded reading, `_lent`) or `cached_entry`; and the job's
    CPU seconds."""
    dt = own_step(system_id, dt)
    start = _cpu_seconds()
    recorded = recorded or {}
    entries = [_lent(recorded.get(sim), sim, dt) or _contained_entry(system_id, sim, dt, only,
                                                                       kinds)
               for sim in sims]
    return entries, _cpu_seconds() - start


def _not_measured(system_id: str, simulator: str, dt: float, why: str) -> PowerEntry:
    """The entry of a reading that could not be made, saying why."""
    return PowerEntry(system_id, simulator, supported=False, dt=dt, reason=why[:500])


def _contained_entry(system_id: str, simulator: str, dt: float, only, kinds) -> PowerEntry:
    """`cached_entry`, or where it raises, an entry that says why it was not measured:
    one engine's failure leaves the system's other engines measured (and nothing cached,
    so that the next study tries again)."""
    try:
        return cached_entry(system_id, simulator, dt, only, kinds)
    except Exception as exc:
        return _not_measured(system_id, simulator, dt,
                             f"not measured: {type(exc).__name__}: {exc}")


def _isolated_entry(system_id: str, simulator: str, dt: float, only, kinds=()
                    ) -> PowerEntry:
    """`defaults_entry` in a worker of its own: a process that dies, or a reading that
    raises, gives an entry that says so, with every default unmeasured."""
    try:
        return isolated(defaults_entry, system_id, simulator, dt, only, kinds,
                        timeout=ENTRY_TIMEOUT)
    except (WorkerCrashed, WorkerTimedOut) as exc:
        return _not_measured(system_id, simulator, dt, f"the neutralised run did not "
                                                       f"complete ({type(exc).__name__}: {exc})")
    except Exception as exc:
        return _not_measured(system_id, simulator, dt,
                             f"not measured: {type(exc).__name__}: {exc}")


@dataclass
class OutOfTheBoxStudy:
    entries: list[PowerEntry]
    provenance: dict = field(default_factory=dict)
    wall_time_s: float = 0.0
    workers: int = 1
    #: system -> CPU seconds of its job (its forked runs included)
    job_cpu_s: dict = field(default_factory=dict)

    def cost(self) -> dict:
        """What this study spent: its wall time and CPU, the comparisons of the readings it
        made (not of those a record lent), and each reading's wall time (a lent one's, as
        recorded)."""
        return {"wall_time_s": self.wall_time_s, "workers": self.workers,
                "comparisons": sum(e.comparisons for e in self.entries if not e.recorded),
                "recorded_entries": sum(bool(e.recorded) for e in self.entries),
                "cpu_s": sum(self.job_cpu_s.values()), "job_cpu_s": self.job_cpu_s,
                "per_entry_wall_time_s": {f"{e.system}/{e.simulator}": e.wall_time_s
                                          for e in self.entries}}

    def as_dict(self) -> dict:
        """The document of the out-of-the-box page (`power.out_of_the_box_document`), with
        the study's cost."""
        return out_of_the_box_document({"provenance": self.provenance, "cost": self.cost(),
                                        "entries": [e.as_dict() for e in self.entries]})

    def power_document(self) -> dict:
        """The document of the power page (`power.power_document`), with the study's
        cost."""
        return power_document([e.as_dict() for e in self.entries], self.provenance,
                              self.cost())

    def summary(self) -> dict:
        """The power study's summary (`power.summary_of`)."""
        return self.power_document()["summary"]


def out_of_the_box_study(systems: Iterable[str], sims: Iterable[str],
                         dt: float | None = None, workers: int | None = None,
                         order: Iterable[str] | None = None,
                         progress: Callable[[PowerEntry], None] | None = None,
                         only: Iterable[str] | None = None, kinds: Iterable[str] = (),
                         record: Mapping | None = None) -> OutOfTheBoxStudy:
    """`defaults_entry` for every system x engine, in `systems` x `sims` order; one job
    per system in a pool of `workers` processes (default: up to 2), dispatched in `order`
    (default: `systems`; the longest first keeps the pool busy to the end). `only`
    names the defaults switched on (each engine those of them it neutralises); `kinds`
    adds the power study's model errors of those kinds (`defaults_entry`). `record` (a
    recorded power study, `read_record`; with every default and `kinds` only) lends the
    readings it made with the installed engines at the same step (`_lent`)."""
    kinds = tuple(kinds)
    only = None if only is None else tuple(only)
    from .runner import provenance

    lent: dict[str, dict[str, dict]] = {}
    if record is not None:
        if only is not None:
            raise ValueError("a recorded study lends whole readings: every default")
        for (system_id, sim), reading in recorded_readings(record, kinds).items():
            lent.setdefault(system_id, {})[sim] = reading

    started = time.perf_counter()
    systems, sims = list(systems), list(sims)
    order = [s for s in (order or systems) if s in systems]
    workers = max(1, min(workers or min(2, os.cpu_count() or 1), len(systems)))
    found: dict[str, list[PowerEntry]] = {}
    cpu: dict[str, float] = {}

    def collect(system_id: str, job: tuple[list[PowerEntry], float]) -> None:
        found[system_id], cpu[system_id] = job
        entries = found[system_id]
        if progress is not None:
            for e in entries:
                progress(e)

    crashed = []
    if workers == 1:
        for s in order:
            collect(s, _system_job(s, sims, dt, only, kinds, lent.get(s)))
    else:
        with ProcessPoolExecutor(max_workers=workers, initializer=become_worker,
                                 initargs=(os.getpid(),)) as pool:
            futures = {pool.submit(_system_job, s, sims, dt, only, kinds, lent.get(s)): s
                       for s in order}
            for fut in as_completed(futures):
                try:
                    collect(futures[fut], fut.result())
                except BrokenProcessPool:
                    crashed.append(futures[fut])
                except Exception as exc:  # the job could not come back: its entries say so
                    why = f"not measured: {type(exc).__name__}: {exc}"
                    collect(futures[fut], ([_not_measured(futures[fut], sim,
                                                          own_step(futures[fut], dt), why)
                                            for sim in sims], 0.0))
    for s in crashed:
        start = _cpu_seconds()
        step = own_step(s, dt)
        entries = [_lent(lent.get(s, {}).get(sim), sim, step)
                   or _isolated_entry(s, sim, step, only, kinds) for sim in sims]
        collect(s, (entries, _cpu_seconds() - start))
    entries = [e for s in systems for e in found[s]]
    made = provenance()
    if record is not None:
        made["record"] = {k: record["provenance"].get(k) for k in ("git_describe", "date")}
    return OutOfTheBoxStudy(entries, made, time.perf_counter() - started, workers,
                            {s: cpu[s] for s in systems})
