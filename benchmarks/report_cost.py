"""Benchmark: the CPU seconds of rendering the report of a results folder, with the cache
of report files (comparisons/file_cache.py) empty and then filled, and whether both give
the same figures byte for byte.

Renders `reports.html.write_report(DIR, workers=1)` (in this process, so that its CPU time
is this process's) twice with a fresh temporary cache folder (MBFIDELITY_CACHE_DIR): the
first draws every figure, the second takes them from the cache. The folder's pages and
figures are rewritten (the same files).

Usage: .venv/bin/python benchmarks/report_cost.py RESULTS_DIR
"""
import hashlib
import json
import os
import sys
import tempfile
import time
from pathlib import Path


def _figures(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.glob("*.png"))}


def main() -> None:
    folder = Path(sys.argv[1])
    with tempfile.TemporaryDirectory(prefix="report_cost_") as cache:
        os.environ["MBFIDELITY_CACHE_DIR"] = cache
        from mbfidelity.reports.html import write_report

        seconds, drawn = [], []
        for _ in ("empty", "filled"):
            for p in folder.glob("*.png"):
                p.unlink()
            c0 = time.process_time()
            write_report(folder, workers=1)
            seconds.append(time.process_time() - c0)
            drawn.append(_figures(folder))
    print(json.dumps({"folder": str(folder), "figures": len(drawn[0]),
                      "cpu_s_cache_empty": seconds[0], "cpu_s_cache_filled": seconds[1],
                      "same_figures": drawn[0] == drawn[1]}, indent=1))


if __name__ == "__main__":
    main()
