"""Compare two `mbfidelity run --out` folders: every metric value (relative difference),
statuses, the report page (provenance lines ignored) and the figure files.

Usage: .venv/bin/python benchmarks/compare_results.py BEFORE_DIR AFTER_DIR
Exit status 1 when statuses, metric names or the page differ, or a value differs by more
than --rtol (default 1e-9 relative).
"""
import argparse
import hashlib
import json
import re
import sys
from pathlib import Path


def _metrics(folder: Path) -> dict:
    doc = json.loads((folder / "results.json").read_text())
    out = {}
    for c in doc["comparisons"]:
        key = (c["system"], c.get("variant", ""), c["simulator"])
        for m in c["metrics"]:
            out[key + (m["name"],)] = (m["value"], m["tolerance"], m["status"])
        if not c["supported"]:
            out[key + ("*",)] = (None, None, "unsupported")
    return out


def _rel(a, b) -> float:
    if a == b or (a is None and b is None):
        return 0.0
    if a is None or b is None or isinstance(a, str) or isinstance(b, str):
        return float("inf")
    if a != a and b != b:  # both NaN
        return 0.0
    return abs(a - b) / max(abs(a), abs(b), 1e-300)


def _page(folder: Path) -> str:
    text = (folder / "index.html").read_text()
    text = re.sub(r"git \S+ · \S+", "", text)  # provenance line
    return re.sub(r"[0-9.]+ s\b", "", text)  # wall times


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--rtol", type=float, default=1e-9)
    args = ap.parse_args()
    a, b = Path(args.before), Path(args.after)
    ma, mb = _metrics(a), _metrics(b)
    bad = 0
    if set(ma) != set(mb):
        print("metric sets differ:", sorted(set(ma) ^ set(mb))[:20])
        bad += 1
    worst = []
    for k in sorted(set(ma) & set(mb)):
        (va, ta, sa), (vb, tb, sb) = ma[k], mb[k]
        if sa != sb:
            print("status differs:", k, sa, sb)
            bad += 1
        worst.append((max(_rel(va, vb), _rel(ta, tb)), k, va, vb))
    worst.sort(reverse=True)
    identical = sum(1 for w in worst if w[0] == 0.0)
    print(f"{len(worst)} metrics: {identical} identical; largest relative differences:")
    for w in worst[:8]:
        print(f"  {w[0]:.2e} {'/'.join(w[1])}: {w[2]!r} -> {w[3]!r}")
    if worst and worst[0][0] > args.rtol:
        bad += 1
    same_page = _page(a) == _page(b)
    print("index.html (provenance and wall times ignored):", "same" if same_page else "DIFFERS")
    bad += not same_page
    pngs = sorted(p.name for p in a.glob("*.png"))
    differ = [n for n in pngs if not (b / n).exists() or hashlib.sha256((a / n).read_bytes())
              .digest() != hashlib.sha256((b / n).read_bytes()).digest()]
    print(f"{len(pngs)} figures; {len(differ)} differ byte-wise: {differ[:10]}")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
