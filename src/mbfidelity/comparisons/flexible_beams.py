"""The engines' own flexible elements against the exact continuum (monograph §6.1, Fig. 17;
issue 12 item 4): for each engine and each kind of flexible element it declares
(simulators/base.py, contract point 12), the simply supported beam with a point mass built
of N = 2, 4, 8, 16, 32 elements, its first three natural frequencies, their relative errors
against the exact Euler-Bernoulli values (analytic/continuum.py) and the convergence order
fitted per mode.

The order is the least-squares slope of log |error| against log N (negated) over the points
that measure the element: those whose error is at least `MARGIN` times both the exact
value's accuracy (`EXACT_ACCURACY`) and the route's own resolution (the engine's
eigensolver round-off, a free-vibration fit's error: `BeamModes.resolution`), which then
add at most a third to it, and below `ASYMPTOTIC_ERROR` (a mesh too coarse for a mode's
half-waves gives errors of order one, outside any power law). Fewer than `MIN_FIT_POINTS`
such points: no order, with the reason.

Sizes an engine cannot build are dropped with the reason (an odd N leaves no node at
a = l/2 for the point mass); an engine that is not installed, or has no flexible element,
is reported with its reason. The result is a JSON-able dict; reports/beams_figure.py draws
it from the saved JSON.
"""
from __future__ import annotations

import math
import time
from typing import Mapping, Sequence

from ..analytic.continuum import beam_with_point_mass_frequencies
from ..analytic.discretization import fitted_order
from ..simulators import all_backends
from ..simulators.base import UNSUPPORTED, Backend
from ..systems._continua import Beam

DEFAULT_ELEMENTS = (2, 4, 8, 16, 32)
MODES = 3
#: the exact continuum's relative accuracy (analytic/continuum.py: roots to 1e-13, checked
#: against independent closed forms to 1e-9 in tests/test_continuum.py)
EXACT_ACCURACY = 1e-9
#: a point is fitted when its error is at least MARGIN times the exact value's accuracy and
#: the route's resolution: they then add at most a third to it
MARGIN = 3.0
#: a relative error above this means the mesh does not resolve the mode (at N = 2 the
#: geometrically exact element's second and third modes are its rotary ones, errors 1e3)
ASYMPTOTIC_ERROR = 0.3
MIN_FIT_POINTS = 3
#: the catalog's cases (§6.1, Fig. 17): the bare beam and the block of 1 kg at
#: mid-span
DEFAULT_CASES = ({"m": 0.0}, {"m": 1.0})


def exact_frequencies_hz(beam: Beam, count: int = MODES) -> list[float]:
    """The first `count` natural frequencies (Hz) of the continuum (analytic/continuum.py)."""
    return [w / (2 * math.pi) for w in beam_with_point_mass_frequencies(
        beam.EI, beam.rho, beam.length, beam.point_mass, beam.point_position, count)]


def _fit_modes(points: list[dict], count: int) -> tuple[list, list, list]:
    orders, used, notes = [], [], []
    for k in range(count):
        chosen = []
        for p in points:
            errors = p.get("relative_error") or []
            if k >= len(errors) or errors[k] is None:
                continue
            floor = MARGIN * max(EXACT_ACCURACY, p["resolution"][k])
            if floor <= abs(errors[k]) < ASYMPTOTIC_ERROR:
                chosen.append((p["N"], errors[k]))
        used.append([n for n, _ in chosen])
        if len(chosen) >= MIN_FIT_POINTS:
            orders.append(fitted_order(*zip(*chosen)))
            notes.append("")
        else:
            orders.append(None)
            notes.append(f"{len(chosen)} point(s) between {MARGIN:g} x the exact value's "
                         f"accuracy or the route's resolution and {ASYMPTOTIC_ERROR:g}, "
                         f"{MIN_FIT_POINTS} needed for a fit")
    return orders, used, notes


def element_series(backend: Backend, kind: str, beam: Beam, elements: Sequence[int],
                   count: int = MODES, exact_hz: Sequence[float] | None = None) -> dict:
    """One engine x element kind: a point per N (frequencies, relative errors, or why the
    size is dropped) and the fitted order per mode."""
    declared = backend.beam_element(kind)
    exact = list(exact_hz) if exact_hz is not None else exact_frequencies_hz(beam, count)
    series = {"simulator": backend.id, "kind": kind, "level": declared.expression.level,
              "how": declared.expression.how, "declared_order": declared.order,
              "limit": declared.limit, "unsupported": "", "points": [],
              "fitted_order": [None] * count, "fitted_elements": [[] for _ in range(count)],
              "order_note": [""] * count}
    ok, why = backend.available()
    if not ok:
        series["unsupported"] = f"{backend.id} is not installed: {why}"
        return series
    series["version"] = backend.version()
    if declared.expression.level == UNSUPPORTED:
        series["unsupported"] = declared.expression.how
        return series
    for n in elements:
        point = {"N": int(n)}
        reason = backend.beam_size_reason(beam, kind, n)
        if reason:
            point["skipped"] = reason
            series["points"].append(point)
            continue
        t0 = time.perf_counter()
        try:
            modes = backend.beam_frequencies(beam, kind, n, count)
        except Exception as exc:  # an engine's failure is a result of the study
            point["failure"] = f"{type(exc).__name__}: {exc}"
            series["points"].append(point)
            continue
        found = modes.frequency_hz
        point.update({
            "frequency_hz": list(found),
            "relative_error": [f / e - 1 for f, e in zip(found, exact)]
                              + [None] * (count - len(found)),
            "resolution": list(modes.resolution) + [0.0] * (count - len(modes.resolution)),
            "method": modes.method, "extra": modes.extra,
            "wall_time": time.perf_counter() - t0})
        if len(found) < count:
            point["note"] = (f"N = {n} elements have {len(found)} bending mode(s) of "
                             f"{count}")
        series["points"].append(point)
    fitted = [p for p in series["points"] if "relative_error" in p]
    orders, used, notes = _fit_modes(fitted, count)
    series.update(fitted_order=orders, fitted_elements=used, order_note=notes)
    return series


def beam_study(beam: Beam, simulators: Sequence[str] | None = None,
               elements: Sequence[int] = DEFAULT_ELEMENTS, count: int = MODES) -> dict:
    """Every engine (default: all backends) x every flexible element it declares, for one
    beam."""
    backends = all_backends()
    ids = list(simulators) if simulators else list(backends)
    unknown = [s for s in ids if s not in backends]
    if unknown:
        raise ValueError(f"unknown simulator(s) {', '.join(unknown)}; valid: "
                         f"{', '.join(backends)}")
    exact = exact_frequencies_hz(beam, count)
    series = [element_series(backends[s], kind, beam, elements, count, exact)
              for s in ids for kind in backends[s].BEAM_ELEMENTS]
    return {"beam": beam.as_dict(), "exact_hz": exact, "modes": count,
            "elements": [int(n) for n in elements], "series": series}


def beam_of(continuum: str | None, values: Mapping[str, float]) -> Beam | None:
    """The `Beam` that a system's continuum model describes (its flexible-element variants:
    the same beam built of each engine's own elements), or None for another continuum.
    The block sits at a = c l (the catalog's c = 1/2, mid-span)."""
    if continuum != "beam_with_point_mass":
        return None
    return Beam.from_parameters({name: values[name] for name in ("l", "EI", "rho", "m", "c")})


def beams_document(cases: Sequence[Beam], simulators: Sequence[str] | None = None,
                   elements: Sequence[int] = DEFAULT_ELEMENTS, count: int = MODES) -> dict:
    """The study for each beam, with the fit's rules (what the saved JSON holds)."""
    from .runner import provenance

    return {"provenance": provenance(), "exact_accuracy": EXACT_ACCURACY, "margin": MARGIN,
            "asymptotic_error": ASYMPTOTIC_ERROR, "min_fit_points": MIN_FIT_POINTS,
            "cases": [beam_study(b, simulators, elements, count) for b in cases]}
