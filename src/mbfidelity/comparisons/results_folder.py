"""The results folder: everything the report pages show, computed here and saved, and
read back by `reports` (which computes nothing of its own).

Layout of a folder written by `mbfidelity run --out DIR` (and `mbfidelity errata --out`):

    results.json, results.csv   every metric of every comparison (`matrix.write_results`)
    job_costs.json              CPU seconds of each system's job in the last run into this
                                folder (the dispatch order of the next run, `matrix.schedule`)
    report_data/<row>.npz       the series the figures draw, per scenario: the reference
                                once (t, q_ref, contact forces), and per engine q, scale,
                                tolerance, contact forces
    report_data/<row>.animation.json  the motion drawn: every scenario's frames of the
                                exact reference and of each engine (`animation`)
    report_data/<system>.json   the mechanism at its operating equilibrium as drawn
                                (world-frame geometry), its derived model typeset as
                                MathML (`typeset.model_document`) and the system's errata
                                entries, typeset beside the derived forms
    errata.json                 every printed formula, its verdict and the engines'
                                witnesses (`mbfidelity errata --out`), and §6's
                                Rayleigh formulas and estimates (`typeset.section6_entries`)
    jobs/<system>.json          each finished system's comparisons, as plain data, for
                                `run --resume` (reused only when it and the system's
                                report files load and answer the same request)
    .mbfidelity.lock            held by the run writing into the folder

A row is the system id, with the variant in brackets for a variant's comparisons.
"""
from __future__ import annotations

import hashlib
import json
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path
from typing import Iterable, Iterator

import numpy as np
import sympy as sp

from ..analytic.errata import errata
from ..analytic.linear import operating_equilibrium
from ..analytic.numeric import numeric_model
from ..analytic.published import compare_published
from ..simulators import all_backends
from ..systems import get_system
from ..systems.model import WORLD, Circle, Rectangle, Segment
from . import file_cache, typeset
from .animation import animation
from .runner import Comparison, Metric, provenance

RESULTS = "results.json"
JOB_COSTS = "job_costs.json"
REPORT_DATA = "report_data"
ERRATA = "errata.json"

#: separates a scenario's name from the array's name in a series file (scenario names
#: and contact names are identifiers, so they never contain it)
KEY_SEPARATOR = "/"


def row_id(c) -> str:
    """A comparison's row name: the system id, with the variant in brackets."""
    return f"{c.system}[{c.variant}]" if getattr(c, "variant", "") else c.system


def base_id(row: str) -> str:
    """The system id of a row."""
    return row.split("[", 1)[0]


def series_path(out: Path, row: str) -> Path:
    """Where the series of a row's comparisons are saved."""
    return out / REPORT_DATA / f"{row}.npz"


# --- series ----------------------------------------------------------------------------

#: the reference's arrays of a scenario's series, shared by the row's engines
REFERENCE_ARRAYS = ("t", "q_ref")


def save_series(out: Path, row: str, comps: Iterable[Comparison]) -> None:
    """The series of a row's comparisons (`compare(..., keep_series=True)`), the arrays
    the figures draw, as one compressed file: per scenario the reference once (its
    samples t, q_ref and reference contact forces, as long as the longest engine run;
    each engine's are a prefix of them), and per engine q, scale, tolerance and the
    engine's contact forces. An engine whose reference arrays are not such a prefix
    keeps its own."""
    comps = [c for c in comps if c.series]
    arrays: dict[str, np.ndarray] = {}
    for scenario in dict.fromkeys(name for c in comps for name in c.series):
        runs = [c for c in comps if scenario in c.series]
        longest = max(runs, key=lambda c: len(c.series[scenario]["t"])).series[scenario]
        shared = _reference_arrays(longest)
        for name, a in shared.items():
            arrays[_key(scenario, "reference", name)] = a
        for c in runs:
            s = c.series[scenario]
            own = _reference_arrays(s)
            for name, a in own.items():
                if not np.array_equal(a, shared[name][:len(a)], equal_nan=True):
                    arrays[_key(scenario, c.simulator, name)] = a
            arrays[_key(scenario, c.simulator, "q")] = s["q"]
            arrays[_key(scenario, c.simulator, "scale")] = np.asarray(s["scale"])
            arrays[_key(scenario, c.simulator, "tolerance")] = np.asarray(s["tolerance"])
            for contact, (_, f_run) in s["contacts"].items():
                arrays[_key(scenario, c.simulator, _contact("engine", contact))] = f_run
            for label, a in s.get("checks", {}).items():
                arrays[_key(scenario, c.simulator, _check(label))] = np.asarray(a)
    path = series_path(out, row)
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, **arrays)
    save_animation(out, row)


def animation_path(out: Path, row: str) -> Path:
    return out / REPORT_DATA / f"{row}.animation.json"


def save_animation(out: Path, row: str) -> None:
    """The row's motion as drawn frames (`animation.animation`), from its saved series;
    a mechanism whose drawing cannot follow its coordinates gets the reason instead.
    The file is kept in the persistent cache by what it is made from (`file_cache`: the
    row, its series, the animation code and the system's description and derivation)."""
    path = animation_path(out, row)
    try:
        series = load_series(out, row)
    except (TypeError, ValueError, NameError, KeyError) as exc:
        path.write_text(json.dumps({"error": f"{type(exc).__name__}: {exc}"}))
        return

    def make() -> list[str]:
        try:
            doc = animation(base_id(row), series)
        except (TypeError, ValueError, NameError, KeyError) as exc:
            doc = {"error": f"{type(exc).__name__}: {exc}"}
        if doc is None:
            doc = {"error": "the variant's coordinates are not the mechanism's drawn ones"}
        # compact: the frames are the page's largest data
        path.write_text(json.dumps(doc, separators=(",", ":")))
        return [path.name]
    file_cache.made("animation", (row, series), _animation_code(base_id(row)), path.parent,
                    make)


@lru_cache(maxsize=None)
def _animation_code(system_id: str) -> bytes:
    """What a system's frames depend on beside the series (file_cache): the animation
    module, the system's description and derivation (its cache key), the analytic code
    and the libraries that evaluate them."""
    import scipy

    from ..analytic.cache import analytic_digest
    from ..analytic.derivation import cache_key
    from . import animation as animation_module

    h = hashlib.sha256(Path(animation_module.__file__).read_bytes())
    h.update("|".join((cache_key(get_system(system_id)), analytic_digest(), np.__version__,
                       sp.__version__, scipy.__version__)).encode())
    return h.digest()


def load_animation(out: Path, row: str) -> dict | None:
    """The row's frames as `save_animation` saved them (None when none were)."""
    path = animation_path(out, row)
    return json.loads(path.read_text()) if path.exists() else None


def _reference_arrays(s: dict) -> dict[str, np.ndarray]:
    out = {name: s[name] for name in REFERENCE_ARRAYS}
    for contact, (f_ref, _) in s["contacts"].items():
        out[_contact("reference", contact)] = f_ref
    return out


def _contact(side: str, name: str) -> str:
    return f"{side}_contact{KEY_SEPARATOR}{name}"


def _check(label: str) -> str:
    return f"check{KEY_SEPARATOR}{label}"


def _key(scenario: str, owner: str, name: str) -> str:
    return KEY_SEPARATOR.join((scenario, owner, name))


def load_series(out: Path, row: str) -> dict[str, dict]:
    """simulator -> scenario -> {"t", "q_ref", "q", "scale", "tolerance", "contacts":
    name -> (reference, engine), "checks": label -> array (what the scenario's checks
    kept for the figures)}, as `save_series` saved them (empty when none were)."""
    path = series_path(out, row)
    if not path.exists():
        return {}
    with np.load(path) as data:
        saved: dict[str, dict[str, dict]] = {}
        for key in data.files:
            scenario, owner, name = key.split(KEY_SEPARATOR, 2)
            saved.setdefault(owner, {}).setdefault(scenario, {})[name] = data[key]
    shared = saved.pop("reference", {})
    series: dict[str, dict] = {}
    for simulator, scenarios in saved.items():
        for scenario, own in scenarios.items():
            n = len(own["q"])
            ref = {name: a[:n] for name, a in shared[scenario].items()}
            ref.update({name: a for name, a in own.items() if name in ref})
            s = {"t": ref["t"], "q_ref": ref["q_ref"], "q": own["q"], "scale": own["scale"],
                 "tolerance": float(own["tolerance"]), "contacts": {}, "checks": {}}
            for name, a in own.items():
                if name.startswith(_check("")):
                    s["checks"][name[len(_check("")):]] = a
            prefix = _contact("engine", "")
            for name, f_run in own.items():
                if name.startswith(prefix):
                    contact = name[len(prefix):]
                    s["contacts"][contact] = (ref[_contact("reference", contact)], f_run)
            series.setdefault(simulator, {})[scenario] = s
    return series


# --- per system: the drawing and the errata ----------------------------------------------


def mechanism_geometry(system_id: str) -> dict:
    """The mechanism at its operating equilibrium in world coordinates, in drawing order:
    each body's shapes (segments, circles, rectangles as polygons) and, for a body with
    mass, its centre of mass; then each joint's anchor on its parent."""
    system = get_system(system_id)
    values = system.parameter_values()
    eq = operating_equilibrium(system, values)
    model = numeric_model(system_id, values)
    d = model.derivation
    env = {**model.subs, **dict(zip(d.q, eq.q))}

    def world(body: str, p) -> list[float]:
        pt = sp.Matrix(p) if body == WORLD else d.point(body, p)
        return [float(sp.sympify(c).xreplace(env)) for c in pt]

    items: list[dict] = []
    mech = system.numeric_mechanism(values)
    for b in mech.bodies:
        for shape in b.shapes:
            if isinstance(shape, Segment):
                items.append({"kind": "segment",
                              "points": [world(b.name, shape.a), world(b.name, shape.b)]})
            elif isinstance(shape, Circle) and mech.spatial:
                # a circle in the body's plane, tilted in space: its points, projected
                # by the drawing like any other
                cx, cy = (float(v) for v in shape.center)
                r = float(shape.radius)
                items.append({"kind": "polygon", "points": [
                    world(b.name, (cx + r * np.cos(t), cy + r * np.sin(t)))
                    for t in np.linspace(0, 2 * np.pi, 24, endpoint=False)]})
            elif isinstance(shape, Circle):
                items.append({"kind": "circle", "center": world(b.name, shape.center),
                              "radius": float(shape.radius)})
            elif isinstance(shape, Rectangle):
                cx, cy = (float(v) for v in shape.center)
                w, h = float(shape.width) / 2, float(shape.height) / 2
                items.append({"kind": "polygon", "points": [
                    world(b.name, (cx + sx * w, cy + sy * h))
                    for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))]})
        if float(b.mass) > 0:
            items.append({"kind": "centre_of_mass", "at": world(b.name, (0, 0))})
    for j in mech.joints:
        items.append({"kind": "joint", "at": world(j.parent, j.parent_anchor)})
    return {"system": system_id, "coordinates": list(system.coordinates),
            "operating_point": [float(v) for v in eq.q], "items": items,
            "view": _view(mech, items)}


def _view(mech, items: list[dict]) -> list[int]:
    """The two world axes a drawing shows: x and y for a planar mechanism; for a spatial
    one, the two along which its drawn points spread most (in axis order)."""
    if not mech.spatial:
        return [0, 1]
    points = np.array([p + [0.0] * (3 - len(p)) for item in items
                       for p in item.get("points", []) + [item[k] for k in ("at", "center")
                                                          if k in item]])
    spread = np.ptp(points, axis=0)
    return sorted(int(k) for k in np.argsort(-spread, kind="stable")[:2])


def deviations(comps: Iterable[Comparison]) -> dict[str, dict]:
    """Why each engine deviates on this row, from this run: per engine the scheme it ran
    (name, order, step), its largest error against its gate (the metric with the
    largest value / tolerance), and each element of the mechanism it does not express
    exactly (the element kind, the level: soft or substitute, how)."""
    from ..simulators import get_backend
    from ..simulators.plan import elements

    out: dict[str, dict] = {}
    for c in comps:
        if not c.supported:
            continue
        backend = get_backend(c.simulator)
        system = get_system(c.system)
        mech = system.numeric_mechanism(c.parameters, c.variant or None)
        scheme = backend.scheme(mech, c.settings)
        judged = [m for m in c.metrics if m.tolerance and m.tolerance == m.tolerance
                  and m.value == m.value and m.unit != "stage completed"]
        worst = max(judged, key=lambda m: m.value / m.tolerance, default=None)
        inexact = {}
        for kind, element in elements(mech):
            e = backend.expression(mech, element)
            if e.level != "exact":
                inexact[(kind, e.level, e.how)] = None
        out[c.simulator] = {
            "scheme": scheme.name if scheme else "", "order": scheme.order if scheme else None,
            "dt": c.dt,
            "worst": ({"metric": worst.name, "value": worst.value,
                       "tolerance": worst.tolerance, "status": worst.status}
                      if worst is not None else None),
            "elements": [{"kind": k, "level": lvl, "how": how} for k, lvl, how in inexact]}
    return out


def save_deviations(out: Path, row: str, comps: Iterable[Comparison]) -> None:
    path = out / REPORT_DATA / f"{row}.deviations.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    _write_json(path, deviations(comps))


def load_deviations(out: Path, row: str) -> dict:
    path = out / REPORT_DATA / f"{row}.deviations.json"
    return json.loads(path.read_text()) if path.exists() else {}


def save_system(out: Path, system_id: str) -> None:
    """The system's drawing geometry and its errata entries (printed formulas against the
    derivation, without the engines' witnesses)."""
    system = get_system(system_id)
    doc = {"drawing": mechanism_geometry(system_id),
           "model": typeset.model_document(system_id),
           "errata": with_typeset([e.as_dict() for e in errata(system)])
           + typeset.section6_entries(system_id),
           "published": published_solutions(system)}
    path = out / REPORT_DATA / f"{system_id}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    _write_json(path, doc)


def published_solutions(system) -> list[dict]:
    """The values a benchmark's sources publish against the reference at the run's
    (default) parameters (analytic/published.py); a comparison that cannot be made is one
    entry saying why, so that the page shows it instead of losing the rest."""
    if not system.published(system.symbols):
        return []
    try:
        return compare_published(system, system.parameter_values())
    except Exception as exc:  # noqa: BLE001 - shown on the page, the run goes on
        return [{"quantity": "*", "error": f"{type(exc).__name__}: {exc}"}]


def load_system(out: Path, system_id: str) -> dict:
    """{"drawing": ..., "model": ..., "errata": [...], "published": [...]} as
    `save_system` saved them."""
    return json.loads((out / REPORT_DATA / f"{system_id}.json").read_text())


# --- the metrics -----------------------------------------------------------------------


LOCK = ".mbfidelity.lock"


@contextmanager
def exclusive(out: Path) -> Iterator[None]:
    """Holds `out` for one run: a second run into the same folder while this one works is
    refused with a ValueError (one line) instead of interleaving its files. The lock is
    the operating system's (released when the process ends, however it ends)."""
    out.mkdir(parents=True, exist_ok=True)
    handle = open(out / LOCK, "a+")
    try:
        import fcntl
    except ImportError:  # not a POSIX system: no lock
        fcntl = None
    try:
        if fcntl is not None:
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                raise ValueError(f"{out}: another run is writing into this folder; wait for "
                                 f"it to finish or choose another --out") from None
        yield
    finally:
        handle.close()


def report_files_intact(out: Path, system_id: str, comparisons: Iterable[Comparison]) -> bool:
    """Whether what the report shows of a finished system (its drawing and errata, each
    row's series) is in `out` and loads."""
    try:
        load_system(out, system_id)
        for row in rows_of(comparisons):
            load_series(out, row)
    except Exception:  # missing, truncated or damaged: the system is recomputed
        return False
    return True


def load_results(out: Path) -> tuple[dict, list[Comparison]]:
    """(provenance, comparisons) of results.json, without their series (`load_series`)."""
    return comparisons_from_document(json.loads((out / RESULTS).read_text()), str(out))


def comparisons_from_document(doc: dict, source: str = "results") -> tuple[dict, list[Comparison]]:
    """(provenance, comparisons) of a results document as `matrix.write_results` wrote it
    (a ValueError naming `source` when it is not one)."""
    try:
        comparisons = []
        for c in doc["comparisons"]:
            for m in c["metrics"]:
                _check_metric(m)
            metrics = [Metric(name=m["name"], value=m["value"], tolerance=m["tolerance"],
                              passed=m["passed"], status=m["status"],
                              reason=m.get("reason", ""), unit=m["unit"],
                              detail=m.get("detail", {}), expected=m.get("expected", False),
                              rule=m.get("rule", "a_priori"),
                              refinement=m.get("refinement", {}))
                       for m in c["metrics"]]
            comparisons.append(Comparison(
                system=c["system"], simulator=c["simulator"],
                engine_version=c["engine_version"], settings=c["settings"],
                parameters=c["parameters"], dt=c["dt"], metrics=metrics,
                supported=c["supported"], reason=c["reason"], wall_time=c["wall_time_s"],
                simulated_time=c["simulated_time_s"], variant=c["variant"],
                incidents=c.get("incidents", []),
                refinement_wall_time=c.get("refinement_wall_time_s", 0.0)))
        return doc["provenance"], comparisons
    except (KeyError, TypeError, AttributeError) as exc:
        raise ValueError(f"{source}: not a results document of mbfidelity ({exc})") from exc


def _check_metric(m: dict) -> None:
    """TypeError naming the field unless the metric's numbers are numbers."""
    for key in ("value", "tolerance"):
        if isinstance(m[key], bool) or not isinstance(m[key], (int, float)):
            raise TypeError(f"metric {m.get('name')!r}: {key} is not a number: {m[key]!r}")
    if not isinstance(m["status"], str) or not isinstance(m["name"], str):
        raise TypeError(f"metric {m.get('name')!r}: name and status must be text")


# --- job costs -------------------------------------------------------------------------


def load_job_costs(out: Path | None) -> dict[str, float]:
    """system -> CPU seconds of its job in the last run into `out` (empty when none, or
    when the file is unreadable: only the dispatch order depends on it)."""
    if out is None:
        return {}
    try:
        costs = json.loads((out / JOB_COSTS).read_text())
        return {str(k): float(v) for k, v in costs.items()}
    except (OSError, ValueError, TypeError, AttributeError):
        return {}


def save_job_costs(out: Path, costs: dict[str, float]) -> None:
    """Merged into the folder's earlier costs: a run of some systems keeps the others'."""
    out.mkdir(parents=True, exist_ok=True)
    _write_json(out / JOB_COSTS, {**load_job_costs(out), **costs})


# --- errata with witnesses -------------------------------------------------------------


def engine_versions() -> dict[str, str]:
    """id -> version of every installed engine."""
    out = {}
    for sim, backend in all_backends().items():
        if backend.available()[0]:
            out[sim] = backend.version()
    return out


def save_errata(entries: list[dict], out: Path) -> Path:
    """errata.json: the entries, with the provenance and the engines' versions."""
    out.mkdir(parents=True, exist_ok=True)
    path = out / ERRATA
    _write_json(path, {"provenance": provenance(), "engines": engine_versions(),
                       "errata": with_typeset(entries),
                       "section6": typeset.section6_entries()})
    return path


def with_typeset(entries: list[dict]) -> list[dict]:
    """The entries with their printed and derived forms typeset ("mathml": printed,
    derived, difference; `typeset.errata_typeset`), matched by system and label."""
    typeset_of: dict[str, dict] = {}
    out = []
    for e in entries:
        if e["system"] not in typeset_of:
            misprints = frozenset(x["label"] for x in entries
                                  if x["system"] == e["system"] and x["verdict"] != "agrees")
            typeset_of[e["system"]] = typeset.errata_typeset(get_system(e["system"]),
                                                             misprints)
        out.append({**e, "mathml": typeset_of[e["system"]].get(e["label"], {})})
    return out


def load_errata(out: Path) -> dict:
    """{"provenance", "engines", "errata", "section6"} as `save_errata` saved them (a
    folder written before §6 was saved has no "section6")."""
    return json.loads((out / ERRATA).read_text())


def _write_json(path: Path, doc) -> None:
    path.write_text(json.dumps(doc, indent=1, default=float))


def rows_of(results: Iterable) -> dict[str, list]:
    """row -> its comparisons, in the order of `results`."""
    rows: dict[str, list] = {}
    for c in results:
        rows.setdefault(row_id(c), []).append(c)
    return rows
