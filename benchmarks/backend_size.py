"""The size of each engine backend, by what its lines hold.

    python benchmarks/backend_size.py [--json]

Per backend module (simulators/*_backend.py and the modules only one backend imports,
MuJoCo's MJCF writer): its lines, and of them the lines of text (string literals of 40 or
more characters: docstrings, the settings' notes, the declared expressions' reasons),
comments, blank lines and the rest (code). Also `isinstance` calls, which the backend
contract's element-kind registry replaces."""
from __future__ import annotations

import argparse
import ast
import json
from pathlib import Path

SIMULATORS = Path(__file__).resolve().parent.parent / "src" / "mbfidelity" / "simulators"
#: backend -> its modules
BACKENDS = {"mujoco": ("mujoco_backend.py", "mujoco_mjcf.py"),
            "pybullet": ("pybullet_backend.py",), "exudyn": ("exudyn_backend.py",),
            "pymunk": ("pymunk_backend.py",), "drake": ("drake_backend.py",)}
#: a string literal at least this long is text (a name or a format string is code)
TEXT_CHARS = 40


def module_size(path: Path) -> dict[str, int]:
    source = path.read_text()
    lines = source.splitlines()
    text: set[int] = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) \
                and len(node.value) >= TEXT_CHARS:
            text.update(range(node.lineno, node.end_lineno + 1))
    comments = {i + 1 for i, line in enumerate(lines) if line.lstrip().startswith("#")}
    blank = {i + 1 for i, line in enumerate(lines) if not line.strip()}
    comments -= text
    return {"lines": len(lines), "text": len(text), "comments": len(comments),
            "blank": len(blank), "code": len(lines) - len(text | comments | blank),
            "isinstance": source.count("isinstance(")}


def sizes() -> dict[str, dict[str, int]]:
    out = {}
    for backend, modules in BACKENDS.items():
        total: dict[str, int] = {}
        for name in modules:
            for k, v in module_size(SIMULATORS / name).items():
                total[k] = total.get(k, 0) + v
        out[backend] = total
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    table = sizes()
    if args.json:
        print(json.dumps(table, indent=1))
        return
    keys = ("lines", "text", "comments", "blank", "code", "isinstance")
    print(f"{'backend':10s}" + "".join(f"{k:>11s}" for k in keys))
    for backend, row in table.items():
        print(f"{backend:10s}" + "".join(f"{row[k]:11d}" for k in keys))
    four = [table[b] for b in ("mujoco", "pybullet", "exudyn", "pymunk")]
    print(f"{'the four':10s}" + "".join(f"{sum(r[k] for r in four):11d}" for k in keys))


if __name__ == "__main__":
    main()
