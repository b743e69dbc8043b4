"""Wall and CPU seconds of the engines' Strutt chart (comparisons/strutt_engine.py) on a
small grid, on 1 and 2 local workers (comparisons/sweep.py), with each engine's agreement
with Floquet; writes benchmarks/records/strutt_engines.json.

Usage: .venv/bin/python benchmarks/strutt_engines.py [GRID]
"""
import datetime
import json
import pathlib
import platform
import subprocess
import sys
import time

from mbfidelity.analytic.strutt import GAMMA_RANGE, LAMBDA_RANGE, strutt_chart
from mbfidelity.comparisons.strutt_engine import engine_chart
from mbfidelity.simulators import SIMULATOR_IDS, all_backends

grid = int(sys.argv[1]) if len(sys.argv) > 1 else 6
chart = strutt_chart(grid, grid)
rows = []
for simulator in SIMULATOR_IDS:
    backend = all_backends().get(simulator)
    if backend is None or not backend.available()[0]:
        continue
    for workers in (1, 2):
        wall, cpu = time.perf_counter(), time.process_time()
        result = engine_chart(simulator, chart, workers=workers)
        row = {"simulator": simulator, "grid": grid, "workers": workers,
               "wall_s": round(time.perf_counter() - wall, 3),
               # the parent's CPU only: with workers > 1 the runs' CPU is in the children
               "parent_cpu_s": round(time.process_time() - cpu, 3),
               "agreement": result["agreement"], "classified": result["classified"],
               "disagreements": [(p["lambda"], p["gamma"]) for p in result["points"]
                                 if p.get("agrees") is False]}
        print(row, flush=True)
        rows.append(row)
record = {
    "lambda_range": LAMBDA_RANGE, "gamma_range": GAMMA_RANGE, "rows": rows,
    "platform": platform.platform(), "processor_count_note": "2 cores shared by several agents",
    "git": subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True,
                          text=True).stdout.strip(),
    "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
}
out = pathlib.Path(__file__).parent / "records" / "strutt_engines.json"
out.write_text(json.dumps(record, indent=2) + "\n")
print(f"wrote {out}")
