"""The figure of the engines' flexible elements against the exact beam (§6.1, Fig. 17):
|relative frequency error| against the number of elements N, log-log, one panel per case
(point mass m) and mode, one line per engine x element kind (hollow markers: points the
fitted order leaves out), the exact value's accuracy as a floor line; drawn from the saved JSON of `mbfidelity beams --out DIR`
(comparisons/flexible_beams.py). Nothing is computed here."""
from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

BEAMS = "beams.json"
FIGURE = "beams.png"
MARKERS = ("o", "s", "^", "v", "D", "x")
#: errors above this are off the chart
TOP = 10.0


def mode_points(series: dict, k: int) -> list[tuple[int, float]]:
    """(N, |relative error|) of mode k over a flexible-element series' points (those with
    an error to draw on a log scale)."""
    return [(p["N"], abs(p["relative_error"][k])) for p in series["points"]
            if "relative_error" in p and p["relative_error"][k] is not None
            and p["relative_error"][k] != 0]


def write_beams_figure(doc: dict, path: Path) -> Path:
    """Draw the study `doc` (as `beams_document` returns it) into `path` (PNG)."""
    cases = doc["cases"]
    modes = max(c["modes"] for c in cases)
    fig, axes = plt.subplots(len(cases), modes, figsize=(4.2 * modes, 3.6 * len(cases)),
                             squeeze=False)
    for row, case in zip(axes, cases):
        beam = case["beam"]
        drawn = [s for s in case["series"] if not s["unsupported"]]
        for k, ax in enumerate(row):
            for i, s in enumerate(drawn):
                pts = mode_points(s, k)
                if not pts:
                    continue
                order = s["fitted_order"][k]
                label = (f"{s['simulator']} {s['kind']}"
                         + (f" (order {order:.2f})" if order is not None else ""))
                line, = ax.loglog(*zip(*pts), marker=MARKERS[i % len(MARKERS)], ms=4,
                                  label=label)
                # hollow: the points the order's fit left out (round-off, pre-asymptotic)
                out = [(n, e) for n, e in pts if n not in s["fitted_elements"][k]]
                if out:
                    ax.plot(*zip(*out), ls="none", marker=MARKERS[i % len(MARKERS)], ms=6,
                            mfc="white", color=line.get_color())
            ax.axhline(doc["exact_accuracy"], color="grey", ls=":", lw=1,
                       label=f"exact value's accuracy {doc['exact_accuracy']:g}")
            # an unresolved mode's error (1e2..1e4: the rotary modes of two shear-deformable
            # elements) would squash the rest; it is in the JSON
            ax.set_ylim(0.3 * doc["exact_accuracy"], TOP)
            ax.set_xscale("log", base=2)
            ax.set_xlabel("elements N")
            ax.set_ylabel(f"|f{k + 1} / f{k + 1},exact - 1|")
            ax.set_title(f"mode {k + 1}, m = {beam['point_mass']:g} kg at a = "
                         f"{beam['point_position']:g} m (exact {case['exact_hz'][k]:.5g} Hz)",
                         fontsize=8)
            ax.grid(True, which="both", lw=0.3)
            ax.legend(fontsize=6)
    fig.suptitle("Simply supported beam, l = {length:g} m, EI = {EI:g} N m^2, rho = {rho:g} "
                 "kg/m: engines' flexible elements against the exact continuum (§6.1); hollow: "
                 f"left out of the order's fit; errors above {TOP:g} off the chart"
                 .format(**cases[0]["beam"]), fontsize=9)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def write_beams_from_folder(out: Path) -> Path:
    """beams.png in `out`, from the beams.json saved there."""
    return write_beams_figure(json.loads((Path(out) / BEAMS).read_text()), Path(out) / FIGURE)
