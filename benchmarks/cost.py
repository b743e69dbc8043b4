"""Benchmark: what `mbfidelity run` costs beside the engines, from one invocation.

Runs `mbfidelity run` on the default matrix (or --systems/--sims) twice with the same
cache folder (environment variable MBFIDELITY_CACHE_DIR, a fresh temporary folder: the
derivations and the numerical results of analytic/memo.py, reference trajectories,
equilibria, modes): first cold (empty cache), then warm. For each run it measures

- total: CPU seconds of the whole run, every process (the command and its pool workers:
  resource.getrusage(RUSAGE_CHILDREN) around the command), minus the CPU seconds of the
  bare loops this benchmark adds (below);
- stepping: CPU seconds inside engine stepping, per engine: `RunResult.cpu_time` of every
  `Backend.simulate` call of the run (comparisons, free-vibration fits, errata witnesses);
- bare: CPU seconds of the engine's bare loop, per engine: after each `simulate` call the
  same backend's `bare_loop` with the same arguments (same built model, same initial state,
  same number of steps, no read-out).

and records the ratios total / stepping (targets: <= 2.0 cold, <= 1.3 warm) and stepping /
bare per engine (target: <= 1.5). Absolute seconds depend on the machine's load; the ratios
come from one run, where stepping and bare loop run back to back on the same model.
The record says whether the run was the default matrix (`default_matrix`) or which systems
and engines it ran, and how many result entries (by kind) the cold run left in the cache.

With --cache DIR the runs use that cache folder (kept afterwards) instead of a fresh
one; with --warm-only (and --cache) only the warm run is measured, against what the folder
already holds (the entries a previous run of the same code left there: on a matrix whose
cold run would not fit in the time at hand).

Usage: .venv/bin/python benchmarks/cost.py [--systems a,b] [--sims x,y] [--out DIR]
           [--cache DIR [--warm-only]] [--no-record]
Appends a record to benchmarks/records/cost.json (or DIR/cost.json) and prints it.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: the child process and its pool workers append one JSON line per simulate call here
LOG_VARIABLE = "MBFIDELITY_COST_LOG"
CACHE_VARIABLE = "MBFIDELITY_CACHE_DIR"
TARGETS = {"total_over_stepping_cold": 2.0, "total_over_stepping_warm": 1.3,
           "stepping_over_bare": 1.5}


# --- inside the measured run (child process and its workers) ------------------------------
_current_system = {"id": ""}


def _log(record: dict) -> None:
    # one short append per call: lines from several processes do not interleave
    with open(os.environ[LOG_VARIABLE], "a", encoding="utf-8") as fh:
        fh.write(json.dumps(record) + "\n")


def _instrument() -> None:
    """Wrap every backend's `simulate` (record its stepping CPU time, then run and time the
    bare loop on the same arguments) and the matrix job (to name the system)."""
    from mbfidelity.comparisons import matrix
    from mbfidelity.simulators import all_backends

    for backend in all_backends().values():
        cls = type(backend)
        if getattr(cls.simulate, "_cost_wrapped", False):
            continue
        original = cls.simulate

        def simulate(self, mechanism, q0, qd0, t_end, dt, settings=None, reaction_joints=(),
                     _original=original):
            c0 = time.process_time()
            run = _original(self, mechanism, q0, qd0, t_end, dt, settings, reaction_joints)
            c1 = time.process_time()
            bare = self.bare_loop(mechanism, q0, qd0, t_end, dt, settings)
            c2 = time.process_time()
            _log({"pid": os.getpid(), "system": _current_system["id"], "engine": self.id,
                  "steps": run.steps, "stepping_cpu_s": run.cpu_time,
                  "stepping_wall_s": run.wall_time, "simulate_cpu_s": c1 - c0,
                  "bare_cpu_s": bare, "bare_call_cpu_s": c2 - c1})
            return run

        simulate._cost_wrapped = True
        cls.simulate = simulate
    if matrix._one_system is not _named_job:
        _original_job["job"] = matrix._one_system
        matrix._one_system = _named_job


_original_job: dict = {}


def _named_job(args):
    """The matrix job (one system), with its system id noted for the records (a module
    function: the pool pickles it by name)."""
    _current_system["id"] = args[0]
    return _original_job["job"](args)


def _child(argv: list[str]) -> None:
    from mbfidelity.cli import main

    sys.argv = ["mbfidelity", *argv]
    main()


if os.environ.get(LOG_VARIABLE):
    # also in pool workers started by spawn/forkserver, which import this module anew
    _instrument()


# --- the benchmark ------------------------------------------------------------------------
def _cpu_children() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def _measure(run_args: list[str], cache: Path, label: str) -> dict:
    with tempfile.TemporaryDirectory(prefix=f"cost_{label}_") as tmp:
        log = Path(tmp) / "calls.jsonl"
        out = Path(tmp) / "results"
        env = dict(os.environ, **{CACHE_VARIABLE: str(cache), LOG_VARIABLE: str(log)})
        cmd = [sys.executable, str(Path(__file__).resolve()), "--child", "--",
               "run", "--out", str(out), *run_args]
        c0, w0 = _cpu_children(), time.perf_counter()
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
        c1, w1 = _cpu_children(), time.perf_counter()
        if proc.returncode != 0:
            sys.exit(f"{label} run failed:\n{proc.stdout}\n{proc.stderr}")
        calls = [json.loads(line) for line in log.read_text().splitlines()]
        doc = json.loads((out / "results.json").read_text())
    added = sum(c["bare_call_cpu_s"] for c in calls)
    total = (c1 - c0) - added
    engines: dict[str, dict] = {}
    for c in calls:
        e = engines.setdefault(c["engine"], {"calls": 0, "steps": 0, "stepping_cpu_s": 0.0,
                                             "bare_cpu_s": 0.0, "simulate_cpu_s": 0.0})
        e["calls"] += 1
        e["steps"] += c["steps"]
        e["stepping_cpu_s"] += c["stepping_cpu_s"]
        e["bare_cpu_s"] += c["bare_cpu_s"]
        e["simulate_cpu_s"] += c["simulate_cpu_s"]
    for e in engines.values():
        e["stepping_over_bare"] = e["stepping_cpu_s"] / max(e["bare_cpu_s"], 1e-12)
        e["met"] = e["stepping_over_bare"] <= TARGETS["stepping_over_bare"]
    systems: dict[str, dict] = {}
    for c in calls:
        s = systems.setdefault(c["system"] or "(outside a matrix job)", {})
        e = s.setdefault(c["engine"], {"stepping_cpu_s": 0.0, "bare_cpu_s": 0.0})
        e["stepping_cpu_s"] += c["stepping_cpu_s"]
        e["bare_cpu_s"] += c["bare_cpu_s"]
    stepping = sum(e["stepping_cpu_s"] for e in engines.values())
    versions = {}
    for c in doc["comparisons"]:
        versions.setdefault(c["simulator"], c["engine_version"])
    return {
        "run_wall_s": w1 - w0,
        "total_cpu_s": total,
        "added_bare_loop_cpu_s": added,
        "stepping_cpu_s": stepping,
        "simulate_cpu_s": sum(e["simulate_cpu_s"] for e in engines.values()),
        "bare_cpu_s": sum(e["bare_cpu_s"] for e in engines.values()),
        "total_over_stepping": total / max(stepping, 1e-12),
        "comparisons": len(doc["comparisons"]),
        "ran": {"systems": sorted({c["system"] for c in doc["comparisons"]}),
                "sims": sorted({c["simulator"] for c in doc["comparisons"]})},
        "passed": sum(c["passed"] for c in doc["comparisons"]),
        "comparison_wall_time_s": sum(c["wall_time_s"] for c in doc["comparisons"]),
        "engines": engines,
        "systems": systems,
        "engine_versions": versions,
        "provenance": doc["provenance"],
        "stdout_tail": proc.stdout.strip().splitlines()[-3:],
    }


def _git_describe() -> str:
    root = Path(__file__).resolve().parent.parent
    proc = subprocess.run(["git", "describe", "--always", "--dirty"], cwd=root,
                          capture_output=True, text=True)
    return proc.stdout.strip() or "unknown"


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        _child(sys.argv[3:] if sys.argv[2:3] == ["--"] else sys.argv[2:])
        return
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--systems", default="")
    ap.add_argument("--sims", default="")
    ap.add_argument("--out", default=str(Path(__file__).parent / "records"))
    ap.add_argument("--no-record", action="store_true", help="print only")
    ap.add_argument("--cache", default="", help="cache folder to use and keep")
    ap.add_argument("--warm-only", action="store_true",
                    help="measure the warm run only, against --cache as it is")
    args = ap.parse_args()
    if args.warm_only and not args.cache:
        ap.error("--warm-only needs --cache (a folder a previous run filled)")
    run_args = []
    if args.systems:
        run_args += ["--systems", args.systems]
    if args.sims:
        run_args += ["--sims", args.sims]
    cache = Path(args.cache) if args.cache else Path(tempfile.mkdtemp(prefix="mbfidelity_cache_"))
    try:
        cold = None if args.warm_only else _measure(run_args, cache, "cold")
        entries: dict[str, int] = {}
        for path in cache.glob("*/*.pickle"):
            kind = path.name.rsplit("-", 1)[0] if "-" in path.name else path.stem
            entries[kind] = entries.get(kind, 0) + 1
        warm = _measure(run_args, cache, "warm")
    finally:
        if not args.cache:
            shutil.rmtree(cache, ignore_errors=True)
    ratios = {
        "total_over_stepping_cold": cold["total_over_stepping"] if cold else None,
        "total_over_stepping_warm": warm["total_over_stepping"],
        "stepping_over_bare_cold": ({k: e["stepping_over_bare"]
                                     for k, e in cold["engines"].items()} if cold else None),
        "stepping_over_bare_warm": {k: e["stepping_over_bare"] for k, e in warm["engines"].items()},
    }
    measured = [r for r in (ratios["stepping_over_bare_cold"],
                            ratios["stepping_over_bare_warm"]) if r]
    met = {
        "total_over_stepping_cold": (ratios["total_over_stepping_cold"]
                                     <= TARGETS["total_over_stepping_cold"]) if cold else None,
        "total_over_stepping_warm": ratios["total_over_stepping_warm"]
        <= TARGETS["total_over_stepping_warm"],
        "stepping_over_bare": {k: max(r.get(k, 0.0) for r in measured)
                               <= TARGETS["stepping_over_bare"]
                               for k in ratios["stepping_over_bare_warm"]},
    }
    record = {
        "benchmark": "cost",
        "command": " ".join([Path(sys.executable).name, *sys.argv]),
        "run_command": " ".join(["mbfidelity", "run", *run_args]),
        "default_matrix": not args.systems and not args.sims,
        "systems": warm["ran"]["systems"],
        "sims": warm["ran"]["sims"],
        "warm_only": bool(args.warm_only),
        # before the warm run: after the cold one, or as --cache held them
        "cache_entries_after_cold": dict(sorted(entries.items())),
        "git_describe": _git_describe(),
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "cpu_count": os.cpu_count(),
        "load_average_after": os.getloadavg(),
        "engine_versions": warm["engine_versions"],
        "targets": TARGETS,
        "ratios": ratios,
        "met": met,
        "cold": cold,
        "warm": warm,
    }
    text = json.dumps(record, indent=1)
    print(text)
    if not args.no_record:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        path = out / "cost.json"
        history = json.loads(path.read_text()) if path.exists() else []
        history.append(record)
        path.write_text(json.dumps(history, indent=1) + "\n")


if __name__ == "__main__":
    main()
