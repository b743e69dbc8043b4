"""The benchmark rows' table as the benchmarks ask for it: per problem and engine, the
error as the benchmark defines it (`System.benchmark_error`) and the CPU seconds of the
stepping, at the engine's default settings and the row's own step, over the problem's
whole run (`mbfidelity.api.benchmark_errors`); and, with --figure DIR, the convergence
study of the benchmark rows over their whole runs (its page draws the benchmark's error
against the CPU seconds: `mbfidelity convergence --systems ... --t-end ... --out DIR`).

Usage: .venv/bin/python benchmarks/benchmark_errors.py [--figure DIR]
Writes benchmarks/records/benchmark_errors.json and benchmark_errors.md (with --figure,
also the study's JSON as benchmarks/records/benchmark_work_precision.json).
"""
import argparse
import json
import math
from pathlib import Path

from mbfidelity import api
from mbfidelity.systems import all_systems


def _cell(x, fmt: str) -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, fmt)


def markdown(doc: dict) -> str:
    step = ("each row's own step" if doc["dt"] is None else f"step {doc['dt']:g} s")
    lines = [f"At {step}, each engine at its default settings, over each problem's whole "
             f"run ({doc['provenance'].get('git_describe', '')}).", "",
             "| problem | engine | step (s) | scheme | benchmark error | unit | CPU s | status |",
             "|---|---|---|---|---|---|---|---|"]
    for r in doc["rows"]:
        status = r["status"] + (f": {r['message']}" if r["message"] else "")
        if r["declared"]:
            status += (" (declared)" if r["status"] != "completed" else
                       f" (trajectory declared {r['declared'].split(':')[0]})")
        lines.append(f"| {r['system']} | {r['simulator']} | {_cell(r['dt'], 'g')} | "
                     f"{r.get('scheme', '-')} | "
                     f"{_cell(r['error'], '.3g')} | {r['unit']} | "
                     f"{_cell(r['cpu_time'], '.3g')} | {status} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--figure", type=Path, help="also run the convergence study of the "
                        "benchmark rows over their whole runs, its page in this folder")
    args = parser.parse_args()
    out = Path(__file__).parent / "records"
    out.mkdir(parents=True, exist_ok=True)
    doc = api.benchmark_errors()
    (out / "benchmark_errors.json").write_text(json.dumps(doc, indent=1,
                                                          default=api.jsonable))
    table = markdown(doc)
    (out / "benchmark_errors.md").write_text(table)
    print(table)
    if args.figure:
        rows = [s for s, sys in all_systems().items() if sys.benchmark_error is not None]
        longest = max(sc.t_end for s in rows for sc in all_systems()[s].scenarios)
        study = api.convergence(rows, t_end=longest, out=args.figure)
        (out / "benchmark_work_precision.json").write_text(
            (args.figure / "convergence.json").read_text())
        print(f"page: {args.figure / 'convergence.html'}; failed gates: {study['failed']}")


if __name__ == "__main__":
    main()
