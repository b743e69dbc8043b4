"""The Strutt chart figure (monograph Fig. 28, eq. 83): the Floquet regions on the
(lambda, gamma) grid (stable, unstable, marginal), from a chart's saved JSON points; where
engines classified the points by simulation, a marker per engine at every decided point
it classifies unlike eq. 83 (comparisons/strutt_engines.py)."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402

#: colour index of each Floquet verdict
CODES = {"stable": 0, "unstable": 1, "marginal": 2}
#: marker of each engine's disagreements
MARKERS = ("x", "+", "1", "o")


def write_strutt_figure(points: list[dict], path: Path) -> Path:
    """Draw the chart from `points` (each with lambda, gamma, verdict) into `path` (PNG)."""
    lambdas = np.unique([p["lambda"] for p in points])
    gammas = np.unique([p["gamma"] for p in points])
    grid = np.full((len(gammas), len(lambdas)), np.nan)
    for p in points:
        grid[np.searchsorted(gammas, p["gamma"]), np.searchsorted(lambdas, p["lambda"])] = \
            CODES[p["verdict"]]
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    ax.pcolormesh(lambdas, gammas, grid, shading="nearest", vmin=0, vmax=2,
                  cmap=ListedColormap(["#cfe8cf", "#f2b8b8", "#888888"]))
    engines = list(dict.fromkeys(e for p in points for e in p.get("engines", {})))
    for marker, engine in zip(MARKERS, engines):
        wrong = [p for p in points if p.get("decided")
                 and p["engines"][engine]["class"] != p["exact_class"]]
        ax.plot([p["lambda"] for p in wrong], [p["gamma"] for p in wrong], marker,
                ls="none", ms=5, mfc="none", label=f"{engine}: {len(wrong)} differ")
    if engines:
        ax.legend(fontsize=7, loc="upper left")
    ax.set_xlabel("lambda")
    ax.set_ylabel("gamma")
    ax.set_title("Strutt chart of eq. 83 (Floquet): green stable, red unstable, grey marginal",
                 fontsize=9)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
