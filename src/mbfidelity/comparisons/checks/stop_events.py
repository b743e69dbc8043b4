"""The instants elastic end stops are hit and released (monograph §2.1, Fig. 2), measured on
the engine's run against the exact switching instants.

Applies to a system whose parameters name the stop law: gap `l`, stop stiffness `k2`,
mass `m`, springs `k1` and dampers `c` of the pairs (the end-stop mechanism of §2.1). The exact
instants are roots of the piecewise closed form (`analytic.closed_forms.
elastic_stop_events`). On the engine's samples a crossing of |x| = l is located by linear
interpolation between the two samples around it: outward a hit, inward a release. The
metrics:

- ``stop_event_count``: how many switches the engine makes beyond the reference's (or
  misses), gate 0;
- ``stop_hit_time``, ``stop_release_time``: the timing error (s) of the switch whose
  error is the largest fraction of its own gate, with that gate (so the metric passes
  when every switch passes);
- ``band_entry_time``: the last release, after which the motion stays in the band
  -l <= x <= l (Fig. 2 puts it at about 2.5 s).

Gates: comparisons/tolerances.py, "Switching instants of a piecewise law": the position
error (trajectory gate times the amplitude, plus the velocity error each earlier corner
leaves, which is O(h^2) whatever the integrator's order) over the crossing speed, plus the
interpolation between samples. A switch whose gate exceeds half the shortest interval
between two switches cannot be told apart from its neighbours: unresolved.
"""
from __future__ import annotations

import numpy as np

from ...analytic.closed_forms import elastic_stop_events
from ...analytic.reference import sensitivity
from .. import metrics, tolerances
from . import ScenarioRun

CHECK = "stop_events"


def crossings(t: np.ndarray, x: np.ndarray, l: float) -> list[tuple[float, str, int]]:
    """(instant, "hit" or "release", side) of every crossing of |x| = l in the samples,
    each instant interpolated linearly between the two samples around it."""
    outside = np.abs(x) > l
    out = []
    for k in np.flatnonzero(outside[1:] != outside[:-1]):
        side = int(np.sign(x[k + 1] if outside[k + 1] else x[k]))
        target = side * l
        theta = (target - x[k]) / (x[k + 1] - x[k])
        out.append((float(t[k] + theta * (t[k + 1] - t[k])),
                    "hit" if outside[k + 1] else "release", side))
    return out


def refinement_order(system, scenario, values, reference, order: int) -> int | None:
    """2: each step across a corner of the stop law leaves a velocity error of order h^2
    whatever the scheme (comparisons/tolerances.py, "Switching instants"), so a scheme of
    higher order converges at second order here."""
    return 2


def trajectory_allowance(system, scenario, values, reference, equilibrium, dt: float,
                         order: int) -> float:
    """What the switches add to the trajectory gate, relative to the amplitude (module
    docstring of comparisons/tolerances.py, "Switching instants"): each switch of the exact
    motion leaves a velocity error c_p (k2/m) |v| h^2, a position error of that over w0,
    carried forward with the perturbation growth factor G."""
    v = values
    m, k1, c, k2 = (v[n] for n in ("m", "k1", "c", "k2"))
    exact = elastic_stop_events(v, float(reference.q[0, 0]), float(reference.qd[0, 0]),
                                float(reference.t[-1]))
    w0 = np.sqrt(max(2 * k1 / m - (c / m) ** 2, 0.0)) or np.sqrt(2 * k1 / m)
    kicks = sum(tolerances.corner_velocity_error(order, k2 / m, e.velocity, dt) for e in exact)
    amplitude = float(metrics.amplitude(reference.q[:, :1], equilibrium.q[:1])[0])
    return sensitivity(system, scenario, v) * kicks / w0 / amplitude


def measure(run: ScenarioRun) -> None:
    v = run.values
    m, k1, c, k2, l = (v[n] for n in ("m", "k1", "c", "k2", "l"))
    ref, h = run.reference, run.dt
    t_end = float(run.t[-1])
    exact = elastic_stop_events(v, float(ref.q[0, 0]), float(ref.qd[0, 0]), t_end)
    found = crossings(run.run.t[: run.n], run.run.q[: run.n, 0], l)
    run.series["stop_events_reference"] = np.array([e.t for e in exact])
    run.series["stop_events_engine"] = np.array([f[0] for f in found])
    run.judge("stop_event_count", float(abs(len(found) - len(exact))), 0.0, "events")

    order = run.run.integrator_order
    amplitude = float(metrics.amplitude(ref.q[:, :1], run.equilibrium.q[:1])[0])
    growth = sensitivity(run.system, run.scenario, v)
    w0 = np.sqrt(max(2 * k1 / m - (c / m) ** 2, 0.0)) or np.sqrt(2 * k1 / m)
    times = [e.t for e in exact]
    ceiling = 0.5 * float(np.min(np.diff(times))) if len(times) > 1 else t_end
    smooth = amplitude * run.gate.tolerance
    corner, rows = 0.0, []
    for e, f in zip(exact, found):
        accel = -(2 * k1 * e.side * l + 2 * c * e.velocity) / m
        gate = tolerances.switching_time_tolerance(smooth + growth * corner / w0, e.velocity,
                                                   accel, h)
        same = f[1] == e.kind and f[2] == e.side
        rows.append((e, abs(f[0] - e.t) if same else float("inf"), gate))
        corner += tolerances.corner_velocity_error(order, k2 / m, e.velocity, h)
    run.series["stop_events_error"] = np.array([r[1] for r in rows])
    run.series["stop_events_tolerance"] = np.array([r[2] for r in rows])

    def judge(label: str, chosen: list) -> None:
        if not chosen:
            return
        if run.gate.unresolved:
            run.unresolved(label, float("nan"), run.gate.unresolved, "s")
            return
        resolved = [r for r in chosen if r[2] <= ceiling]
        if not resolved:
            e, _, gate = chosen[0]
            run.unresolved(label, gate, f"the timing bound {gate:.3g} s exceeds half the "
                                        f"shortest interval between two switches "
                                        f"({ceiling:.3g} s): switches cannot be paired", "s")
            return
        e, error, gate = max(resolved, key=lambda r: r[1] / r[2])
        run.judge(label, error, gate, "s")

    judge("stop_hit_time", [r for r in rows if r[0].kind == "hit"])
    judge("stop_release_time", [r for r in rows if r[0].kind == "release"])
    if exact and len(found) == len(exact):
        judge("band_entry_time", [rows[-1]])
    elif exact:
        run.judge("band_entry_time", float("inf"), rows[-1][2] if rows else 0.0, "s")
