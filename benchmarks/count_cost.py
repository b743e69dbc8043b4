"""What a count parameter costs: `analyze` of a chain (derivation without the cache,
compilation, equilibria, modes) at growing numbers of elements, each in a fresh process
(wall and CPU seconds, peak resident memory), and the power law fitted to them. The
largest count a parameter admits (systems/model.py `MAX_COUNT`) is held to keep the
largest chain well inside `analyze`'s default time budget.

Usage: .venv/bin/python benchmarks/count_cost.py [SYSTEM] [N ...]
Writes benchmarks/records/count_cost.json.
"""
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

SYSTEM = sys.argv[1] if len(sys.argv) > 1 else "massive_spring"
COUNTS = [int(n) for n in sys.argv[2:]] or [4, 8, 16, 32]
MBFIDELITY = Path(sys.executable).with_name("mbfidelity")
RECORD = Path(__file__).parent / "records" / "count_cost.json"

points = []
for n in COUNTS:
    start = time.perf_counter()
    done = subprocess.run(["/usr/bin/time", "-f", "%U %S %M", str(MBFIDELITY), "analyze",
                           SYSTEM, "--param", f"N={n}", "--no-cache", "--json"],
                          capture_output=True, text=True)
    wall = time.perf_counter() - start
    lines = done.stderr.strip().splitlines()
    user, system_cpu, peak_kb = lines[-1].split()
    points.append({"N": n, "wall_s": wall, "cpu_s": float(user) + float(system_cpu),
                   "peak_rss_mb": int(peak_kb) / 1024, "exit": done.returncode,
                   "error": lines[-2] if done.returncode and len(lines) > 1 else ""})
    print(points[-1], flush=True)
done_points = [p for p in points if p["exit"] == 0]  # the law of the sizes that work
ns = np.array([p["N"] for p in done_points], dtype=float)
cpu = np.array([p["cpu_s"] for p in done_points])
exponent, log_c = np.polyfit(np.log(ns), np.log(cpu), 1)
doc = {"system": SYSTEM, "command": "mbfidelity analyze SYSTEM --param N=n --no-cache",
       "points": points, "fitted_cpu_s": f"{np.exp(log_c):.3g} * N^{exponent:.2f}",
       "date": time.strftime("%Y-%m-%d")}
RECORD.write_text(json.dumps(doc, indent=1) + "\n")
print(doc["fitted_cpu_s"])
