"""Each backend's declared expression of every element kind (simulators/base.py, contract
point 5): exact, soft, substitute or unsupported, with the condition it applies under.

Usage: .venv/bin/python benchmarks/expressions_table.py   (a markdown table on stdout)
"""
from mbfidelity.simulators import all_backends
from mbfidelity.simulators.plan import ELEMENT_KINDS


def main() -> None:
    backends = all_backends()
    print("| element kind | " + " | ".join(backends) + " |")
    print("|---" * (len(backends) + 1) + "|")
    for kind in ELEMENT_KINDS:
        cells = []
        for backend in backends.values():
            cases = backend.EXPRESSIONS.get(kind, ())
            cells.append("; ".join(c.level + (f" ({c.when})" if c.when else "")
                                   for c in cases))
        print(f"| {kind} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
