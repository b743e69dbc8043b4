"""Count the metrics of an `mbfidelity run --out` folder by engine and verdict, by the rule
that judged them, and list the unresolved ones with their reasons.

Usage: .venv/bin/python benchmarks/verdict_counts.py RESULTS_DIR [--json]
           [--record FILE [--command TEXT] [--commit REV] [--note TEXT]]
With --record, appends the counts to FILE (a JSON list, e.g.
benchmarks/records/verdict_counts.json) with the command that made the folder, the commit
it ran (default: the folder's provenance), the run's date and a note.
"""
import argparse
import collections
import json
import sys
from pathlib import Path


def counts(folder: Path) -> dict:
    doc = json.loads((folder / "results.json").read_text())
    by_engine: dict = collections.defaultdict(collections.Counter)
    rules: collections.Counter = collections.Counter()
    unresolved = []
    for c in doc["comparisons"]:
        for m in c["metrics"]:
            by_engine[c["simulator"]][m["status"]] += 1
            rules[m.get("rule", "a_priori")] += 1
            if m["status"] == "unresolved":
                unresolved.append({"system": c["system"], "engine": c["simulator"],
                                   "metric": m["name"], "declared": m.get("expected", False),
                                   "rule": m.get("rule", "a_priori"),
                                   "reason": m.get("reason", "")})
    total = sum(sum(v.values()) for v in by_engine.values())
    return {"comparisons": len(doc["comparisons"]), "metrics": total,
            "by_engine": {e: dict(sorted(v.items())) for e, v in sorted(by_engine.items())},
            "by_rule": dict(rules), "unresolved": unresolved,
            "unresolved_fraction": len(unresolved) / total if total else 0.0}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("folder")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--record", default="", help="append the counts to this JSON list")
    ap.add_argument("--command", default="", help="the command that made the folder")
    ap.add_argument("--commit", default="", help="the commit it ran")
    ap.add_argument("--note", default="")
    args = ap.parse_args()
    found = counts(Path(args.folder))
    if args.record:
        prov = json.loads((Path(args.folder) / "results.json").read_text())["provenance"]
        record = {"benchmark": "verdict_counts",
                  "command": " ".join(["python", "benchmarks/verdict_counts.py", args.folder]),
                  "run_command": args.command, "commit": args.commit or prov["git_describe"],
                  "date": prov["date"], "note": args.note,
                  **{k: v for k, v in found.items()},
                  "undeclared": sum(not u["declared"] for u in found["unresolved"])}
        path = Path(args.record)
        history = json.loads(path.read_text()) if path.exists() else []
        history.append(record)
        path.write_text(json.dumps(history, indent=1) + "\n")
        print(f"recorded in {path}", file=sys.stderr)
    if args.json:
        print(json.dumps(found, indent=1))
        return
    print(f"{found['comparisons']} comparisons, {found['metrics']} metrics, "
          f"{len(found['unresolved'])} unresolved ({found['unresolved_fraction']:.2%})")
    for engine, statuses in found["by_engine"].items():
        print(f"  {engine}: " + ", ".join(f"{n} {s}" for s, n in statuses.items()))
    print("  by rule: " + ", ".join(f"{n} {r}" for r, n in found["by_rule"].items()))
    for u in found["unresolved"]:
        print(f"  unresolved {u['system']} {u['engine']} {u['metric']}"
              f"{' (declared)' if u['declared'] else ''}")


if __name__ == "__main__":
    main()
