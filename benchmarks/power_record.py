"""The power study's records from the power.json that `mbfidelity power --out DIR` writes.

    mbfidelity power --workers 2 --out DIR
    python benchmarks/power_record.py DIR --record benchmarks/records/power.json \
        --study benchmarks/records/power_study.json.gz

`--record`: per system x engine only the smallest rejected eps of each error kind, the runs
per kind, the verdict at the probe (1 %) and each default's verdict with why; the summary
(median smallest rejected eps per engine and kind, defaults rejected and acting) and the
cost as the command wrote them. `--study`: the command's power.json itself (every trial),
gzip-compressed with no time stamp, which `mbfidelity power --record` lends readings from
(`make report` does)."""
from __future__ import annotations

import argparse
import gzip
import json
from pathlib import Path


def entry_record(e: dict) -> dict:
    errors = e.get("errors", [])
    return {
        "system": e["system"], "simulator": e["simulator"],
        "engine_version": e.get("engine_version", ""), "supported": e["supported"],
        **({"reason": e["reason"]} if not e["supported"] else {}),
        "wall_time_s": round(e.get("wall_time_s", 0.0), 1),
        "comparisons": e.get("comparisons", 0),
        "engine_stepping_s": round(e.get("engine_time_s", 0.0), 2),
        "baseline_passed": e.get("baseline_passed"),
        "smallest_rejected": {p["kind"]: p["smallest_rejected"] for p in errors
                              if p["applicable"]},
        "runs_per_kind": {p["kind"]: len(p["trials"]) for p in errors if p["applicable"]},
        "at_one_percent": {p["kind"]: {"verdict": p.get("verdict"), "why": p.get("why")}
                           for p in errors if p["applicable"]},
        "not_monotone": [p["kind"] for p in errors
                         if p["applicable"] and not p.get("monotone", True)],
        "defaults": {d["setting"]: {"verdict": d["verdict"], "why": d["why"]}
                     for d in e.get("defaults", [])},
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path, help="the --out folder of mbfidelity power")
    parser.add_argument("--record", type=Path, required=True)
    parser.add_argument("--study", type=Path, help="also the whole power.json, gzipped")
    parser.add_argument("--command", default="mbfidelity power --workers 2 --out DIR")
    parser.add_argument("--note", default="")
    args = parser.parse_args()
    raw = (args.folder / "power.json").read_bytes()
    power = json.loads(raw)
    record = {"benchmark": "power", "command": args.command, "note": args.note,
              "provenance": power["provenance"], "cost": power.get("cost"),
              "summary": power["summary"],
              "entries": [entry_record(e) for e in power["entries"]]}
    args.record.write_text(json.dumps(record, indent=1) + "\n")
    print(f"{len(record['entries'])} entries -> {args.record}")
    if args.study is not None:
        with gzip.GzipFile(args.study, "wb", compresslevel=9, mtime=0) as f:
            f.write(raw)
        print(f"{len(raw)} bytes -> {args.study} ({args.study.stat().st_size} compressed)")


if __name__ == "__main__":
    main()
