"""Wall seconds of the Strutt chart by simulation (comparisons/strutt_engines.py) for the
four engines, on a local Dask cluster of 1 and of 2 workers (one thread each), and the
speed-up; the agreement of each engine with eq. 83 on the way. Appends to
benchmarks/records/strutt_engines.json.

Usage: .venv/bin/python benchmarks/strutt_engines.py [--grid N] [--sims a,b]
"""
import argparse
import datetime
import json
import pathlib
import platform
import subprocess
import time

from dask.distributed import LocalCluster

from mbfidelity.analytic.strutt import strutt_chart
from mbfidelity.comparisons.strutt_engines import engine_chart
from mbfidelity.simulators import all_backends


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--grid", type=int, default=50)
    parser.add_argument("--sims", default="")
    args = parser.parse_args()
    sims = [s for s in args.sims.split(",") if s] or [
        e for e, b in all_backends().items() if b.available()[0]]
    runs = []
    for workers in (1, 2):
        points = strutt_chart(args.grid, args.grid).points()
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          dashboard_address=":0") as cluster:
            start = time.perf_counter()
            doc = engine_chart(points, sims, scheduler=cluster.scheduler_address)
            wall = time.perf_counter() - start
        runs.append({"workers": workers, "wall_s": round(wall, 2),
                     "agreement_with_eq83": {e: s["agreement_with_eq83"]
                                             for e, s in doc["engines"].items()},
                     "disagreements": {e: len(s["disagreements"])
                                       for e, s in doc["engines"].items()}})
        print(runs[-1])
    record = {
        "grid": args.grid, "engines": sims, "runs": runs,
        "speedup_2_over_1": round(runs[0]["wall_s"] / runs[1]["wall_s"], 3),
        "platform": platform.platform(),
        "git": subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True,
                              text=True).stdout.strip(),
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }
    print(record["speedup_2_over_1"])
    path = pathlib.Path(__file__).parent / "records" / "strutt_engines.json"
    records = json.loads(path.read_text()) if path.exists() else []
    path.write_text(json.dumps(records + [record], indent=1) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
