"""The motion of a mechanism as drawn frames, for the pages' animations: the shapes of
`results_folder.mechanism_geometry`, placed by the derived kinematics at each saved
sample of the exact reference and of every engine (`results_folder.save_series`).

Frames are evenly spaced samples of the saved series (at most FRAMES per scenario, the
animation's time axis); each frame holds every drawn point's two shown world coordinates
(the drawing's view), rounded to DECIMALS of the scene's size.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
import sympy as sp

from ..analytic.linear import operating_equilibrium
from ..analytic.numeric import numeric_model
from ..systems import get_system
from ..systems.model import WORLD, Circle, Rectangle, Segment

#: frames per scenario: smooth at 25 frames per second over 8 s of playing
FRAMES = 200
#: digits kept of each coordinate, relative to the scene's size (a pixel of a 400-pixel
#: canvas is 2.5e-3 of it)
DECIMALS = 4


@lru_cache(maxsize=None)
def _drawing(system_id: str, scenario: str = ""):
    """(items, points(q) -> array (n_points, 3), view) of a system with the parameter
    values of its scenario (the defaults for a scenario it does not declare): the drawn
    items referring to rows of the points array."""
    system = get_system(system_id)
    declared = {sc.name: sc for sc in system.scenarios}
    values = system.parameter_values(scenario=declared.get(scenario))
    model = numeric_model(system_id, values)
    d = model.derivation
    mech = system.numeric_mechanism(values)
    exprs: list = []

    def point(body: str, p) -> int:
        pt = sp.Matrix(list(p) + [0] * (3 - len(p))) if body == WORLD else d.point(body, p)
        pt = list(pt) + [0] * (3 - len(pt))
        exprs.append([sp.sympify(c).xreplace(model.subs) for c in pt])
        return len(exprs) - 1

    items: list[dict] = []
    for b in mech.bodies:
        for shape in b.shapes:
            if isinstance(shape, Segment):
                items.append({"kind": "segment",
                              "points": [point(b.name, shape.a), point(b.name, shape.b)]})
            elif isinstance(shape, Circle) and not mech.spatial:
                # planar: its centre moves, its radius stays (one point a frame)
                items.append({"kind": "circle", "points": [point(b.name, shape.center)],
                              "radius": float(shape.radius)})
            elif isinstance(shape, Circle):
                cx, cy = (float(v) for v in shape.center)
                r = float(shape.radius)
                items.append({"kind": "polygon", "points": [
                    point(b.name, (cx + r * np.cos(t), cy + r * np.sin(t)))
                    for t in np.linspace(0, 2 * np.pi, 16, endpoint=False)]})
            elif isinstance(shape, Rectangle):
                cx, cy = (float(v) for v in shape.center)
                w, h = float(shape.width) / 2, float(shape.height) / 2
                items.append({"kind": "polygon", "points": [
                    point(b.name, (cx + sx * w, cy + sy * h))
                    for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]})
    for j in mech.joints:
        items.append({"kind": "joint", "points": [point(j.parent, j.parent_anchor)]})
    f = sp.lambdify([list(d.q)], sp.Matrix(exprs), modules="numpy")

    def points(q: np.ndarray) -> np.ndarray:
        out = np.array(f(q), dtype=float).reshape(len(exprs), 3)
        return out
    eq = operating_equilibrium(system, values)
    return items, points, _view(points(eq.q), mech.spatial)


def _view(at_rest: np.ndarray, spatial: bool) -> list[int]:
    if not spatial:
        return [0, 1]
    spread = np.ptp(at_rest, axis=0)
    return sorted(int(k) for k in np.argsort(-spread, kind="stable")[:2])


def animation(row_system: str, series: dict[str, dict]) -> dict | None:
    """The frames of every scenario of a row, from `load_series`-shaped series
    (simulator -> scenario -> {"t", "q_ref", "q", ...}); None when the row's coordinates
    are not the system's (a variant built otherwise)."""
    items, _, view = _drawing(row_system)
    n = len(get_system(row_system).coordinates)
    scenarios: dict[str, dict] = {}
    for simulator, by_scenario in series.items():
        for name, s in by_scenario.items():
            if s["q"].ndim != 2 or s["q"].shape[1] != n:
                return None
            sc = scenarios.setdefault(name, {"t": None, "reference": None, "engines": {}})
            if sc["t"] is None or len(s["t"]) > len(sc["t"]):
                sc["t"], sc["q_ref"] = s["t"], s["q_ref"]
            sc["engines"][simulator] = s["q"]
    out = {"system": row_system, "view": view, "items": items, "scenarios": {}}
    for name, sc in sorted(scenarios.items()):
        t = np.asarray(sc["t"], dtype=float)
        pick = np.unique(np.linspace(0, len(t) - 1, min(FRAMES, len(t))).round().astype(int))
        points = _drawing(row_system, name)[1]
        traces = {"exact": _frames(points, sc["q_ref"], pick, view)}
        for simulator, q in sc["engines"].items():
            traces[simulator] = _frames(points, q, pick[pick < len(q)], view)
        scale = max((np.nanmax(np.abs(np.array(f, dtype=float))) for f in traces.values()
                     if len(f)), default=1.0)
        digits = DECIMALS - int(np.floor(np.log10(scale))) if scale > 0 else DECIMALS
        out["scenarios"][name] = {
            "t": [round(float(x), 4) for x in t[pick]],
            "traces": {k: _rounded(v, digits) for k, v in traces.items()}}
    return out


def _frames(points, q: np.ndarray, pick: np.ndarray, view: list[int]) -> list:
    i, j = view
    frames = []
    for k in pick:
        qk = np.asarray(q[k], dtype=float)
        if not np.all(np.isfinite(qk)):
            break  # the engine's run ended (diverged) here
        p = points(qk)
        frames.append(p[:, [i, j]])
    return frames


def _rounded(frames: list, digits: int) -> list:
    return [[[round(float(x), digits) for x in p] for p in f] for f in frames]
