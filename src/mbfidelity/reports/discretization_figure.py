"""The figure of a discretized continuum (monograph §6) against its exact one:
|relative frequency error| against the number of elements N, log-log, one panel per mode:
the chain as derived, each engine's build of the chain (its own linearization), and, on
the first mode, each Rayleigh estimate as printed (a horizontal line: it does not depend
on N); drawn from the saved JSON of `mbfidelity discretization SYSTEM --out DIR`.
Nothing is computed here."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .beams_figure import mode_points  # noqa: E402

MARKERS = ("o", "s", "^", "v", "D")
#: the engines' own flexible elements (variants of a beam): dashed, filled markers
FLEXIBLE_STYLES = ("x--", "+--", "*--", "1--", "2--")
#: their colours (the Rayleigh lines are red)
FLEXIBLE_COLOURS = ("tab:green", "tab:purple", "tab:brown", "tab:olive", "tab:cyan")


def figure_name(system: str) -> str:
    return f"discretization-{system}.png"


def write_discretization_figure(doc: dict, path: Path) -> Path:
    """Draw the study `doc` (as the command saves it) into `path` (PNG)."""
    modes = len(doc["exact_hz"])
    fig, axes = plt.subplots(1, modes, figsize=(4.2 * modes, 3.6), squeeze=False)
    for k, ax in enumerate(axes[0]):
        chain = [(r["N"], abs(r["relative_error"][k])) for r in doc["rows"]
                 if len(r["relative_error"]) > k and r["relative_error"][k] != 0]
        if chain:
            order = doc["fitted_order"][k]
            ax.loglog(*zip(*chain), "k-", lw=2, alpha=0.5,
                      label=f"chain, derived (order {order:.2f})")
        for i, (sim, e) in enumerate(sorted(doc.get("engines", {}).items())):
            pts = [(r["N"], abs(r["error_vs_continuum"][k])) for r in e["rows"]
                   if len(r["error_vs_continuum"]) > k and r["error_vs_continuum"][k] != 0]
            if pts:
                ax.loglog(*zip(*pts), MARKERS[i % len(MARKERS)], mfc="none", ms=7 + 2 * i,
                          label=f"{sim} (its linearization)")
        for i, x in enumerate(doc.get("flexible", {}).get("series", [])):
            pts = mode_points(x, k)
            if pts and not x["unsupported"]:
                order = x["fitted_order"][k]
                ax.loglog(*zip(*pts), FLEXIBLE_STYLES[i % len(FLEXIBLE_STYLES)], ms=5,
                          color=FLEXIBLE_COLOURS[i % len(FLEXIBLE_COLOURS)],
                          label=f"{x['simulator']} {x['kind']}, own element"
                                + (f" (order {order:.2f})" if order is not None else ""))
        if k == 0:
            for r in doc.get("rayleigh", []):
                ax.axhline(abs(r["relative_error"]), ls="--", color="tab:red",
                           label=f"Rayleigh {r['label']}")
        ax.set_xscale("log", base=2)
        ax.set_xlabel(f"elements {doc['parameter']}")
        ax.set_ylabel(f"|f{k + 1} / f{k + 1},exact - 1|")
        ax.set_title(f"mode {k + 1} (exact {doc['exact_hz'][k]:.6g} Hz)", fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6)
    fig.suptitle(f"{doc['system']}: discretized chain and engines against the exact "
                 f"continuum", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path
