"""Attribute the samples of a py-spy raw (collapsed) profile of `mbfidelity run` to the
run's phases (first matching phase from the innermost frame outwards wins for nested
phases listed first). Record with:

  .venv/bin/py-spy record --subprocesses --rate 50 --format raw -o spy.txt -- \\
      .venv/bin/mbfidelity run --out /tmp/out
  .venv/bin/python benchmarks/spy_phases.py spy.txt
"""
import sys
from collections import Counter

#: (phase, substring of a frame "function (file:line)"), innermost-first priority: a
#: sample goes to the first phase in this list found anywhere in its stack
PHASES = [
    ("derivation (sympy)", "__init__ (mbfidelity/analytic/derivation.py"),
    ("errata: symbolic reduction (display text)", "_reduced_cached (mbfidelity/analytic/errata.py"),
    ("numeric model build (lambdify)", "__init__ (mbfidelity/analytic/numeric.py"),
    ("errata: other", "errata (mbfidelity/analytic/errata.py"),
    ("report: trajectory figures", "_figures (mbfidelity/reports/html.py"),
    ("report: mechanism drawing", "draw_mechanism (mbfidelity/reports/html.py"),
    ("report data: mechanism geometry", "mechanism_geometry (mbfidelity/comparisons/results_folder.py"),
    ("report data: series files", "save_series (mbfidelity/comparisons/results_folder.py"),
    ("reference: DOP853", "_dop853 (mbfidelity/analytic/reference.py"),
    ("reference: dependent coordinates", "_full_states (mbfidelity/analytic/reference.py"),
    ("reference: accelerations, multipliers, reactions", "_reference (mbfidelity/analytic/reference.py"),
    ("free-vibration fits", "fit_damped_sinusoid (mbfidelity/comparisons/metrics.py"),
    ("equilibria", "operating_equilibrium (mbfidelity/analytic/linear.py"),
    ("mujoco post-processing", "_read_out (mbfidelity/simulators/mujoco_backend.py"),
    ("mujoco", "mujoco_backend.py"),
    ("mujoco", "mujoco_mjcf.py"),
    ("pybullet", "pybullet_backend.py"),
    ("exudyn", "exudyn_backend.py"),
    ("pymunk", "pymunk_backend.py"),
    ("comparison: other", "compare (mbfidelity/comparisons/runner.py"),
    ("parent: write results/report", "write_re"),
    ("imports / start-up", "<module>"),
]


def main() -> None:
    counts, procs = Counter(), Counter()
    total = 0
    for line in open(sys.argv[1]):
        stack, _, n = line.rstrip("\n").rpartition(" ")
        n = int(n)
        total += n
        procs[stack.split(";", 1)[0]] += n
        for phase, key in PHASES:
            if key in stack:
                counts[phase] += n
                break
        else:
            counts["other"] += n
    rate = float(sys.argv[2]) if len(sys.argv) > 2 else 50.0
    print(f"{'phase':50s} {'CPU s':>7s} {'share':>6s}")
    for phase, n in counts.most_common():
        print(f"{phase:50s} {n / rate:7.1f} {100 * n / total:5.1f}%")
    print(f"{'total':50s} {total / rate:7.1f}")
    for p, n in procs.most_common():
        print(f"  {p[:60]:60s} {n / rate:7.1f} s")


if __name__ == "__main__":
    main()
