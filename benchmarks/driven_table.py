"""The driven mechanisms' measured table (issue 9) from an `mbfidelity run --out` folder:
per system x engine, the worst value / gate of each metric family (trajectory, imposed
motion, actuator force, frequency fit, steady state, growth rate) with its status, and
each engine's imposed-motion route with its order (from the settings the run recorded).

Usage: .venv/bin/python benchmarks/driven_table.py RESULTS_DIR > benchmarks/records/driven.md
"""
import json
import sys
from pathlib import Path

FAMILIES = {
    "trajectory": (".trajectory_max",),
    "imposed": (".imposed_",),
    "actuator": (".actuator_",),
    "frequency": ("frequency.fit_mode",),
    "steady state": (".steady_state_",),
    "growth rate": (".growth_rate",),
}
ROUTE_KEYS = ("prescribed_motion", "prescribed_route", "driven_solver", "prescribed")


def _cell(metrics: list[dict]) -> str:
    if not metrics:
        return ""
    worst = max(metrics, key=lambda m: (m["value"] / m["tolerance"]
                                        if m["tolerance"] and m["value"] == m["value"] else 0))
    statuses = sorted({m["status"] + ("*" if m.get("expected") else "") for m in metrics})
    return f"{worst['value']:.1e} / {worst['tolerance']:.1e} ({', '.join(statuses)})"


def main(folder: str) -> None:
    doc = json.loads((Path(folder) / "results.json").read_text())
    rows = [c for c in doc["comparisons"] if any(
        any(p in m["name"] for p in (".imposed_", ".steady_state_", ".growth_rate"))
        for m in c["metrics"]) or c["system"] in ("lever",)]
    print("| system | engine | " + " | ".join(FAMILIES) + " |")
    print("|---" * (len(FAMILIES) + 2) + "|")
    routes = {}
    for c in sorted(rows, key=lambda c: (c["system"], c["simulator"])):
        cells = [_cell([m for m in c["metrics"] if any(p in m["name"] for p in pats)])
                 for pats in FAMILIES.values()]
        print(f"| {c['system']} | {c['simulator']} | " + " | ".join(cells) + " |")
        for key in ROUTE_KEYS:
            if key in c["settings"]:
                routes[c["simulator"]] = f"{key} = {c['settings'][key]}"
    print("\nvalue / gate of the worst metric of each family (status; * = declared "
          "unresolved). Routes recorded in the settings:")
    for engine, route in sorted(routes.items()):
        print(f"- {engine}: {route}")


if __name__ == "__main__":
    main(sys.argv[1])
