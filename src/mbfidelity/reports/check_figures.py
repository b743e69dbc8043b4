"""Figures of the scenario checks (comparisons/checks/), drawn from what each check saved
in the results folder: the phase portrait of a limit cycle against the reference's, the
stability threshold each engine's bisection brackets against the analytic one, the error
of every end-stop instant against its gate, and a floating body's centre of mass against
the reference's. One figure per scenario holding every kind present; none when a scenario's
checks saved nothing."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

THRESHOLD_PREFIX = "threshold_"


def _saved(comps, scenario: str) -> list[tuple[str, dict]]:
    """(simulator, the scenario's series) for every engine that ran it."""
    return [(c.simulator, c.series[scenario]) for c in comps if scenario in c.series]


def _phase_portrait(ax, runs, coordinate: str) -> None:
    drawn_ref = False
    for sim, s in runs:
        checks = s["checks"]
        if "phase_xd" not in checks:
            continue
        n = len(checks["phase_xd"])
        if not drawn_ref:
            ax.plot(s["q_ref"][:n, 0], checks["phase_xd_reference"], "k-", lw=2.5,
                    alpha=0.35, label="reference")
            drawn_ref = True
        ax.plot(s["q"][:n, 0], checks["phase_xd"], lw=0.6, label=sim)
    ax.set_xlabel(coordinate)
    ax.set_ylabel(f"{coordinate}'")
    ax.set_title("phase portrait (limit cycle)")
    ax.legend(fontsize=7)


def _thresholds(ax, runs) -> None:
    """Each engine's bracket [lo, hi] and its midpoint; the analytic value as a line."""
    names = []
    for k, (sim, s) in enumerate(runs):
        for label, (found, p_star, lo, hi) in sorted(
                (label, a) for label, a in s["checks"].items()
                if label.startswith(THRESHOLD_PREFIX)):
            names.append(label[len(THRESHOLD_PREFIX):])
            ax.errorbar([k], [found], yerr=[[found - lo], [hi - found]], fmt="o", capsize=4,
                        label=f"{sim}: {found:.6g}")
            ax.axhline(p_star, color="k", lw=0.8, ls="--")
    ax.set_xticks(range(len(runs)), [sim for sim, _ in runs])
    ax.set_ylabel(", ".join(dict.fromkeys(names)))
    ax.set_title("stability threshold: engine bisection (bars: bracket) vs analytic (dashed)")
    ax.legend(fontsize=7)


def _stop_events(ax, runs) -> None:
    """The error of each stop instant (an unmatched event, drawn at the top, has no finite
    error) and its gate, both against the reference instant."""
    for sim, s in runs:
        checks = s["checks"]
        if "stop_events_error" not in checks:
            continue
        err, gate = checks["stop_events_error"], checks["stop_events_tolerance"]
        t = checks["stop_events_reference"][:len(err)]
        line, = ax.semilogy(t, np.where(np.isfinite(err), np.maximum(err, 1e-16), np.nan),
                            "o", ms=3, label=f"{sim} |t - t_ref|")
        ax.semilogy(t, gate, "_", ms=8, color=line.get_color())
        unmatched = ~np.isfinite(err)
        if np.any(unmatched):
            ax.plot(t[unmatched], np.full(int(np.sum(unmatched)), np.nanmax(gate)), "x",
                    color=line.get_color(), label=f"{sim}: wrong or missing event")
    ax.set_xlabel("reference instant [s]")
    ax.set_ylabel("stop instant error [s]")
    ax.set_title("end-stop events (dashes: each event's gate)")
    ax.legend(fontsize=7)


def _centre_of_mass(ax, runs) -> None:
    drawn_ref = False
    for sim, s in runs:
        cg = s["checks"].get("cg")
        if cg is None:
            continue
        cg = cg.reshape(len(cg), -1)
        half = cg.shape[1] // 2
        t = s["t"][:len(cg)]
        if not drawn_ref:
            for j in range(half):
                ax.plot(t, cg[:, j], "k-", lw=2.5, alpha=0.35,
                        label="reference" if j == 0 else None)
            drawn_ref = True
        for j in range(half):
            ax.plot(t, cg[:, half + j], lw=0.8, label=sim if j == 0 else None)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("centre of mass [m]")
    ax.set_title("floating system: centre of mass")
    ax.legend(fontsize=7)


PANELS = (
    (lambda checks: "phase_xd" in checks, _phase_portrait),
    (lambda checks: any(k.startswith(THRESHOLD_PREFIX) for k in checks), _thresholds),
    (lambda checks: "stop_events_error" in checks, _stop_events),
    (lambda checks: "cg" in checks, _centre_of_mass),
)


def check_figure(row: str, scenario: str, comps, coordinates: tuple[str, ...],
                 out: Path) -> str | None:
    """Draws `row-scenario-checks.png` in `out` from the engines' saved check series;
    returns its file name, or None when the scenario's checks saved nothing to draw."""
    runs = _saved(comps, scenario)
    panels = [draw for present, draw in PANELS
              if any(present(s.get("checks", {})) for _, s in runs)]
    if not panels:
        return None
    fig, axes = plt.subplots(len(panels), 1, figsize=(10, 4 * len(panels)), squeeze=False)
    for ax, draw in zip(axes[:, 0], panels):
        with_data = [(sim, s) for sim, s in runs if s.get("checks")]
        if draw is _phase_portrait:
            draw(ax, with_data, coordinates[0])
        else:
            draw(ax, with_data)
    fig.suptitle(f"{row}, scenario {scenario}: checks")
    fig.tight_layout()
    name = f"{row}-{scenario}-checks.png"
    fig.savefig(out / name, dpi=80)
    plt.close(fig)
    return name
