"""Benchmark: wall time of `mbfidelity run` on the default matrix (target: < 2 minutes on the
project's 2-core machine) and the engines' cost per simulated second, from the same run.

Usage: .venv/bin/python benchmarks/run_matrix.py [--out benchmarks/records]
Writes benchmarks/records/run_matrix.json (appends a record per invocation).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(Path(__file__).parent / "records"))
    args = ap.parse_args()
    exe = Path(sys.executable).parent / "mbfidelity"
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        proc = subprocess.run([str(exe), "run", "--out", tmp], capture_output=True, text=True)
        elapsed = time.perf_counter() - start
        if proc.returncode != 0:
            sys.exit(proc.stderr)
        doc = json.loads((Path(tmp) / "results.json").read_text())
    per_engine: dict[str, dict] = {}
    for c in doc["comparisons"]:
        e = per_engine.setdefault(c["simulator"], {"wall_time_s": 0.0, "simulated_time_s": 0.0,
                                                   "engine_version": c["engine_version"]})
        e["wall_time_s"] += c["wall_time_s"]
        e["simulated_time_s"] += c["simulated_time_s"]
    for e in per_engine.values():
        e["wall_s_per_simulated_s"] = e["wall_time_s"] / max(e["simulated_time_s"], 1e-12)
    record = {"provenance": doc["provenance"], "cpu_count": os.cpu_count(),
              "run_wall_time_s": elapsed, "comparisons": len(doc["comparisons"]),
              "target_s": 120.0, "met": elapsed < 120.0, "engines": per_engine,
              "stdout_tail": proc.stdout.strip().splitlines()[-3:]}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "run_matrix.json"
    history = json.loads(path.read_text()) if path.exists() else []
    history.append(record)
    path.write_text(json.dumps(history, indent=1))
    print(json.dumps(record, indent=1))


if __name__ == "__main__":
    main()
