"""Convergence and work-precision study: error against dt for every engine on the
compound pendulum (large swing) and the double pendulum; observed order and wall time.

Usage: .venv/bin/python benchmarks/convergence.py
Writes benchmarks/records/convergence.json and convergence.png.
"""
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from mbfidelity.comparisons.convergence import convergence  # noqa: E402
from mbfidelity.simulators import all_backends  # noqa: E402

CASES = [("compound_pendulum", "large"), ("double_pendulum", "small")]
DTS = [4e-3, 2e-3, 1e-3, 5e-4]


def main() -> None:
    out = Path(__file__).parent / "records"
    out.mkdir(parents=True, exist_ok=True)
    studies = []
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for system, scenario in CASES:
        for sim, backend in all_backends().items():
            if not backend.available()[0]:
                continue
            st = convergence(system, sim, scenario, DTS, t_end=5.0)
            studies.append(st.as_dict())
            print(f"{system}/{scenario} {sim}: order {st.observed_order:.2f} "
                  f"(integrator {st.integrator_order}); errors "
                  + ", ".join(f"{p.error:.2e}" for p in st.points))
            axes[0].loglog([p.dt for p in st.points], [p.error for p in st.points], "o-",
                           label=f"{system} {sim}")
            axes[1].loglog([p.wall_time for p in st.points], [p.error for p in st.points], "o-",
                           label=f"{system} {sim}")
    axes[0].set_xlabel("dt [s]")
    axes[0].set_ylabel("max error / amplitude")
    axes[1].set_xlabel("wall time [s] (5 s simulated)")
    axes[1].set_title("work-precision")
    axes[0].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(out / "convergence.png", dpi=80)
    (out / "convergence.json").write_text(json.dumps(studies, indent=1))


if __name__ == "__main__":
    main()
