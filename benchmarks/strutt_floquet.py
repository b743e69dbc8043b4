"""Wall and CPU seconds of the Strutt chart of eq. 83 from Floquet theory
(analytic/strutt.py) on grids up to 100 x 100, with the verdict counts; writes
benchmarks/records/strutt_floquet.json.

Usage: .venv/bin/python benchmarks/strutt_floquet.py
"""
import collections
import datetime
import json
import pathlib
import platform
import subprocess
import time

from mbfidelity.analytic.strutt import GAMMA_RANGE, LAMBDA_RANGE, strutt_chart

rows = []
for n in (20, 50, 100):
    wall, cpu = time.perf_counter(), time.process_time()
    chart = strutt_chart(n, n)
    row = {"grid": n, "wall_s": round(time.perf_counter() - wall, 3),
           "cpu_s": round(time.process_time() - cpu, 3),
           "verdicts": dict(collections.Counter(str(v) for v in chart.verdict.ravel())),
           "max_error": float(chart.error.max())}
    print(row)
    rows.append(row)
record = {
    "lambda_range": LAMBDA_RANGE, "gamma_range": GAMMA_RANGE, "rows": rows,
    "platform": platform.platform(), "processor_count_note": "2 cores shared by several agents",
    "git": subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True,
                          text=True).stdout.strip(),
    "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
}
out = pathlib.Path(__file__).parent / "records" / "strutt_floquet.json"
out.write_text(json.dumps(record, indent=2) + "\n")
print(f"wrote {out}")
