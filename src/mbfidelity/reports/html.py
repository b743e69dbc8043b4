"""HTML report rendered from a results folder (`comparisons/results_folder.py`): summary
table, trajectory overlays, error-against-time figures, frequency table, errata. It renders
saved results only: every number, series and shape on the pages was computed upstream and
saved; from the descriptions it reads only titles, coordinate names and the declared
expected failures."""
from __future__ import annotations

import fnmatch
import hashlib
import json
import os
from concurrent.futures import ProcessPoolExecutor
from functools import lru_cache
from pathlib import Path
from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Circle as CirclePatch  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402

from ..comparisons import file_cache  # noqa: E402
from ..comparisons.results_folder import (base_id, load_animation, load_deviations,  # noqa: E402
                                          load_errata, load_results, load_series,
                                          load_system, row_id, rows_of, series_path)
from ..systems import get_system  # noqa: E402
from . import site  # noqa: E402
from .check_figures import check_figure  # noqa: E402
from .power_page import OUT_OF_THE_BOX, write_out_of_the_box_page  # noqa: E402

#: why an engine deviates, in words a student can follow (docs/engines.md)
EXPLANATIONS = {
    "mujoco": "Reduced coordinates; RK4 by default here (its Euler is semi-implicit, with an "
              "O(h) phase offset). Massless links are folded into their child body. Loops and "
              "slots use equality constraints, which are soft: their forces fall about 1e-4 "
              "short and a small violation makes up the rest.",
    "pybullet": "Reduced coordinates (Featherstone) with semi-implicit Euler: first order, and "
                "not symplectic when the mass matrix depends on the configuration, so the phase "
                "drifts (double pendulum, sliding block). Hidden joint motors and 0.04 link "
                "damping are switched off here; left on they stop or slow a pendulum.",
    "exudyn": "Minimal coordinates (kinematic tree) with an explicit RK4 (fourth order); "
              "closed loops and slots add exact joints and need generalized-alpha (second "
              "order).",
    "pymunk": "Maximal coordinates: every body free, joints enforced by iterated impulses at "
              "the velocity level; semi-implicit Euler (first order). Error correction "
              "(error_bias) is off here; its default bleeds energy out of a pendulum.",
}

def _cell(c) -> dict:
    """A matrix cell: its metrics counted by status, coloured by the worst; a comparison
    whose verdict is a failure without a failing metric (an incident, an unresolved
    metric) is coloured as failed. The text is plain (the page escapes it)."""
    if not c.supported:
        return {"cls": "unsupported", "text": "cannot express: " + c.reason}
    statuses = [m.status for m in c.metrics]
    worst = next((s for s in ("fail", "xpass", "unresolved", "xfail", "measured")
                  if s in statuses), "pass")
    counts = [f"{statuses.count(s)} {s}" for s in ("pass", "fail", "xfail", "xpass",
                                                   "measured", "unresolved")
              if statuses.count(s)]
    if c.incidents:
        counts.append(f"{len(c.incidents)} incident" + "s" * (len(c.incidents) > 1))
    if c.verdict == "fail" and worst in ("pass", "xfail", "measured", "unresolved"):
        worst = "fail"
    elif worst == "unresolved":  # declared unresolved: it holds, as an expected failure
        worst = "xfail"
    return {"cls": worst, "text": ", ".join(counts)}


#: the order in which the summary counts metrics by verdict
VERDICT_ORDER = ("pass", "fail", "xfail", "xpass", "unresolved", "measured")


def verdict_summary(results) -> dict:
    """The metrics of the run counted by verdict: in all ("total", "counts"), per engine
    ("engines": simulator -> verdict -> count), and the unresolved ones (their share of
    all metrics, and how many of them are declared with their reason)."""
    counts: dict[str, int] = {}
    engines: dict[str, dict[str, int]] = {}
    unresolved = declared = 0
    for c in results:
        mine = engines.setdefault(c.simulator, {})
        for m in c.metrics:
            counts[m.status] = counts.get(m.status, 0) + 1
            mine[m.status] = mine.get(m.status, 0) + 1
            if m.status == "unresolved":
                unresolved += 1
                declared += bool(m.expected)

    def ordered(found: dict[str, int]) -> dict[str, int]:
        return {s: found[s] for s in sorted(found, key=lambda s: (
            VERDICT_ORDER.index(s) if s in VERDICT_ORDER else len(VERDICT_ORDER), s))}
    total = sum(counts.values())
    return {"total": total, "counts": ordered(counts),
            "engines": {sim: ordered(found) for sim, found in engines.items()},
            "unresolved": unresolved, "declared": declared,
            "unresolved_share": unresolved / total if total else 0.0}


#: points per line in the figures: a 10 in, 80 dpi axis is 800 pixels wide, so a line of
#: 10^4 samples is drawn as its envelope over 2 x ENVELOPE_BINS points (see `_envelope`)
ENVELOPE_BINS = 1000


def _envelope(t: np.ndarray, y: np.ndarray, bins: int = ENVELOPE_BINS):
    """The samples of y that draw the same line at the figure's resolution: the first and
    last, and in each of `bins` equal runs of samples its minimum and maximum, in time
    order. Lines with NaN, and short ones, are drawn whole. Drawing (and placing the
    legend "best", which tests every vertex) is then ~5x cheaper."""
    n = len(y)
    if n <= 4 * bins or not np.all(np.isfinite(y)):
        return t, y
    size = -(-n // bins)  # samples per run; the last run is padded with its last value
    padded = np.concatenate([y, np.full(size * bins - n, y[-1])]).reshape(bins, size)
    base = np.arange(bins) * size
    idx = np.concatenate([[0, n - 1], base + np.argmin(padded, axis=1),
                          base + np.argmax(padded, axis=1)])
    idx = np.unique(np.minimum(idx, n - 1))
    return t[idx], y[idx]


def _figures(system_id: str, comps, out: Path) -> list[str]:
    names = []
    scenarios = {name for c in comps for name in c.series}
    system = get_system(base_id(system_id))
    # a driven system's prescribed coordinates run away (phi = w t): its free ones are drawn
    drawn = [(i, c) for i, c in enumerate(system.coordinates)
             if c not in system.mechanism.driven_coordinates]
    for scenario in sorted(scenarios):
        with_contacts = any(c.series.get(scenario, {}).get("contacts") for c in comps)
        fig, axes = plt.subplots(3 if with_contacts else 2, 1,
                                 figsize=(10, 8.5 if with_contacts else 6), sharex=True)
        drawn_ref = False
        for c in comps:
            s = c.series.get(scenario)
            if s is None:
                continue
            t = s["t"]
            if not drawn_ref:
                for i, name in drawn:
                    axes[0].plot(*_envelope(t, s["q_ref"][:, i]), "k-", lw=2.5, alpha=0.35,
                                 label=f"reference {name}")
                drawn_ref = True
            for i, name in drawn:
                axes[0].plot(*_envelope(t, s["q"][:, i]), lw=0.8,
                             label=f"{c.simulator} {name}")
            if with_contacts:
                for k, (cname, (f_ref, f_run)) in enumerate(sorted(s["contacts"].items())):
                    if not any(ln.get_label() == f"reference {cname}" for ln in axes[2].lines):
                        axes[2].plot(*_envelope(t, f_ref), "k-", lw=2.5, alpha=0.35,
                                     label=f"reference {cname}")
                    axes[2].plot(*_envelope(t, np.nan_to_num(f_run)), lw=0.8,
                                 ls="-" if k == 0 else "--", label=f"{c.simulator} {cname}")
            err = np.max(np.abs(s["q"] - s["q_ref"]) / s["scale"], axis=1)
            axes[1].semilogy(*_envelope(t, np.maximum(err, 1e-16)), lw=0.8, label=c.simulator)
            axes[1].axhline(s["tolerance"], ls="--", lw=0.6, color=axes[1].lines[-1].get_color())
        axes[0].set_ylabel("coordinates")
        axes[0].legend(fontsize=7, ncol=4)
        axes[1].set_ylabel("|q - q_ref| / amplitude")
        axes[-1].set_xlabel("t [s]")
        axes[1].legend(fontsize=7)
        if with_contacts:
            axes[2].axhline(0.0, color="k", lw=0.5, ls=":")
            axes[2].set_ylabel("contact / actuator forces")
            axes[2].legend(fontsize=7, ncol=4)
        fig.suptitle(f"{system_id}, scenario {scenario} (dashed: tolerances)")
        fig.tight_layout()
        name = f"{system_id}-{scenario}.png"
        fig.savefig(out / name, dpi=80)
        plt.close(fig)
        names.append(name)
        checks = check_figure(system_id, scenario, comps, system.coordinates, out)
        if checks:
            names.append(checks)
    return names


def write_report(out: Path, workers: int | None = None) -> Path:
    """The site (`reports/site.py`): index.html, one page per mechanism, summary.md and
    the figures, from the results saved in `out`; the figures are drawn by a pool of
    `workers` processes (default: up to 2)."""
    prov, results = load_results(out)
    by_system = rows_of(results)
    sims = list(dict.fromkeys(c.simulator for c in results))
    rows = list(by_system)
    figures = _render_figures(out, by_system, workers)
    frequencies = frequency_table(results)
    saved = {system: _saved_system(out, system, by_system)
             for system in dict.fromkeys(map(base_id, rows))}
    # after the figures and the saved files: their failures are incidents too
    incidents = {r: [{"simulator": c.simulator, **i} for c in comps for i in c.incidents]
                 for r, comps in by_system.items()}
    versions = {c.simulator: c.engine_version for c in results if c.engine_version}
    script = site.write_script(out)
    errata_page = (out / "errata.json").exists()
    box = _out_of_the_box_rows(out)
    for system, files in saved.items():
        mine = [row for row in rows if base_id(row) == system]
        drawing = next((f for row in mine for f in figures[row]
                        if f == f"{system}-drawing.png"), "")
        sections = [_section(out, row, by_system[row],
                             [f for f in figures[row] if f != drawing], frequencies,
                             incidents[row]) for row in mine]
        described = get_system(system)
        convergence = out / f"convergence-{system}.png"
        (out / site.page_name(system)).write_text(site.MECHANISM.render(
            style=site.STYLE, system=system, title=described.title, source=described.source,
            drawing=drawing, model=files.get("model", {}), errata=files.get("errata", []),
            published=files.get("published", []),
            sections=sections, errata_page=errata_page, script=script,
            convergence=convergence.name if convergence.exists() else "",
            out_of_the_box=box.get(system, [])))
    if errata_page:  # (again) now that it can link the mechanism pages
        write_errata_page(out)
    if box:  # (again) now that it can link the index and the mechanism pages
        write_out_of_the_box_page(out, {s: site.page_name(s) for s in saved})
    others = [(name, title) for name, title in site.OTHER_PAGES if (out / name).exists()]
    page = site.INDEX.render(
        style=site.STYLE, prov=prov, versions=versions, sims=sims, rows=rows,
        cells={r: {c.simulator: _cell(c) for c in comps} for r, comps in by_system.items()},
        pages={r: site.page_name(base_id(r)) for r in rows},
        anchors={r: site.anchor(r) for r in rows}, titles={r: _title(r) for r in rows},
        others=others, explanations=EXPLANATIONS, incidents=incidents,
        summary=verdict_summary(results),
        figures=[(name, caption) for name, caption in site.INDEX_FIGURES
                 if (out / name).exists()], strutt_engines=_strutt_engines(out),
        discretizations=sorted(p.name for p in out.glob("discretization-*.png")))
    index = out / "index.html"
    index.write_text(page)
    (out / "summary.md").write_text(_markdown(results, prov))
    return index


def _out_of_the_box_rows(out: Path) -> dict[str, list[dict]]:
    """system -> its engines' out-of-the-box readings (out_of_the_box.json, when saved
    there and readable), each default with what its row on the mechanism's page shows:
    the verdict, the motion change in the scenario where it is largest against its gate,
    the energy drift where it is largest with the default, and mode 1's fitted damping
    ratio error, each beside the neutralised run's."""
    try:
        doc = json.loads((out / OUT_OF_THE_BOX).read_text())
    except (OSError, ValueError):  # none saved, or damaged: the pages go without the row
        return {}
    rows: dict[str, list[dict]] = {}
    for e in doc.get("entries", []):
        defaults = []
        for d in e.get("defaults", []):
            motion = d.get("motion", {})
            drifts = [(name, m) for name, m in motion.get("scenarios", {}).items()
                      if m.get("energy_drift_switched_on") is not None]
            energy = max(drifts, key=lambda item: item[1]["energy_drift_switched_on"],
                         default=None)
            damping = d.get("effect", {}).get("damping.fit_mode1")
            # the power study's classification (power.classify_default), where saved
            verdict = d.get("verdict") or ("rejected" if d["rejected"] else "passes"
                                           if d["acts"] else "no effect")
            defaults.append({
                "setting": d["setting"], "note": d.get("note", ""),
                "engine_value": "each above" if d["setting"] == "all"
                else json.dumps(d["engine_value"]),
                "harness_value": "" if d.get("harness_value") is None
                else json.dumps(d["harness_value"]),
                "verdict": verdict, "cls": {"rejected": "fail", "passes": "pass"}.get(
                    verdict, "pass" if d["acts"] or d.get("moved") else "unsupported"),
                "rejected_by": ", ".join(d.get("rejected_by", [])),
                "incidents": [i["outcome"] for i in d.get("incidents", [])],
                "motion": ({"error": motion["error"]} if "error" in motion else {
                    "change": motion.get("trajectory_change"),
                    "gate": motion.get("trajectory_gate"),
                    "scenario": motion.get("scenario", "")}),
                "energy": None if energy is None else {
                    "scenario": energy[0],
                    "neutralised": energy[1]["energy_drift_neutralised"],
                    "switched_on": energy[1]["energy_drift_switched_on"]},
                "damping": None if damping is None else {
                    "neutralised": damping["neutralised"],
                    "switched_on": damping["switched_on"]}})
        rows.setdefault(e["system"], []).append({
            "simulator": e["simulator"], "supported": e["supported"],
            "reason": e.get("reason", ""), "anchor": f"{e['system']}-{e['simulator']}",
            "recorded": e.get("recorded", ""), "defaults": defaults})
    return rows


def _section(out: Path, row: str, comps, figures: list[str], frequencies: dict,
             incidents: list[dict]) -> dict:
    """A row's part of its mechanism's page: metrics, incidents, frequencies, figures,
    animation."""
    sims = [c.simulator for c in comps]
    try:
        frames = load_animation(out, row) or {}
    except Exception as exc:  # a damaged file: the page says so and stands
        frames = {"error": f"{type(exc).__name__}: {exc}"[:500]}
    try:
        deviating = load_deviations(out, row)
    except Exception:  # a damaged file: the section is left out
        deviating = {}
    return {"row": row, "anchor": site.anchor(row), "title": _title(row), "sims": sims,
            "metrics": {c.simulator: {m.name: m for m in c.metrics} for c in comps},
            "metric_names": list(dict.fromkeys(m.name for c in comps for m in c.metrics)),
            "unsupported": {c.simulator: "cannot express: " + c.reason for c in comps
                            if not c.supported},
            "expected": _expected(row, comps), "liftoff": contact_warnings(comps),
            "frequencies": frequencies.get(row, {}), "figures": figures,
            "animation": site.embedded_json(frames) if frames.get("scenarios") else "",
            "animation_error": frames.get("error", "no saved series"),
            "scenarios": list(frames.get("scenarios", {})), "incidents": incidents,
            "deviations": deviating}


def _strutt_engines(out: Path) -> str:
    """Each engine's agreement with eq. 83 in the saved Strutt chart, as text ("" when
    no engine classified it)."""
    path = out / "strutt.json"
    if not path.exists():
        return ""
    engines = json.loads(path.read_text()).get("simulation", {}).get("engines", {})
    return "; ".join(f"{e}: {s['agreement_with_eq83']:.1%} of {s['decided_points']} points "
                     f"agree" for e, s in engines.items())


def _render_figures(out: Path, rows: dict[str, list], workers: int | None) -> dict[str, list]:
    """row -> its figure files (the mechanism's drawing first), drawn from the saved
    series and geometry; in a process pool, the rows with the most data first."""
    drawings = list(dict.fromkeys(map(base_id, rows)))

    def data_size(row: str) -> int:
        path = series_path(out, row)
        return path.stat().st_size if path.exists() else 0

    order = sorted(rows, key=data_size, reverse=True)
    workers = max(1, min(workers or min(2, os.cpu_count() or 1), len(order)))
    if workers == 1:
        drawn = {s: _draw_saved(out, s) for s in drawings}
        plotted = {row: _plot_saved(out, row, rows[row]) for row in order}
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            plotting = {row: pool.submit(_plot_saved, out, row, rows[row]) for row in order}
            drawing = {s: pool.submit(_draw_saved, out, s) for s in drawings}
            plotted = {row: f.result() for row, f in plotting.items()}
            drawn = {s: f.result() for s, f in drawing.items()}
    figures = {}
    for row in rows:
        files = drawn[base_id(row)] + plotted[row]
        for failure in (f for f in files if f.startswith("!")):
            _figure_incident(rows, row, RuntimeError(failure[1:]))
        figures[row] = [f for f in files if not f.startswith("!")]
    return figures


def _saved_system(out: Path, system_id: str, rows: dict[str, list]) -> dict:
    """The system's saved drawing, model and errata entries; a file that does not load is
    an incident of the system's comparisons (the page says so) instead of the end of the
    report."""
    try:
        return load_system(out, system_id)
    except Exception as exc:
        _figure_incident(rows, system_id, exc)
        return {}


def _figure_incident(rows: dict[str, list], row: str, exc: BaseException) -> None:
    for c in rows.get(row, []):
        c.incidents.append({"scenario": "*", "stage": "figure", "outcome": "failed",
                            "t_reached": None,
                            "message": f"{type(exc).__name__}: {exc}"[:500]})


@lru_cache(maxsize=None)
def _drawing_code() -> bytes:
    """The digest of the code that draws the figures (file_cache): every module of
    `reports/`, and the Matplotlib and NumPy versions."""
    h = hashlib.sha256(f"matplotlib {matplotlib.__version__}|numpy {np.__version__}".encode())
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.digest()


def _draw_saved(out: Path, system_id: str) -> list[str]:
    try:
        drawing = load_system(out, system_id)["drawing"]
        # the same geometry draws the same file: kept in the cache (file_cache)
        return file_cache.made("drawing", drawing, _drawing_code(), out,
                               lambda: [draw_mechanism(drawing, out)])
    except Exception as exc:  # shown as an incident by the caller
        return [f"!{type(exc).__name__}: {exc}"]


def _plot_saved(out: Path, row: str, comps) -> list[str]:
    try:
        series = load_series(out, row)
        for c in comps:
            c.series = series.get(c.simulator, {})
        system = get_system(base_id(row))
        # what `_figures` draws from, alone: the same inputs draw the same files, kept in
        # the cache (file_cache)
        inputs = (row, [c.simulator for c in comps], series, tuple(system.coordinates),
                  tuple(system.mechanism.driven_coordinates))
        return file_cache.made("plots", inputs, _drawing_code(), out,
                               lambda: _figures(row, comps, out))
    except Exception as exc:  # one row's figures fail; the report stands
        return [f"!{type(exc).__name__}: {exc}"]


def write_errata_page(out: Path) -> Path:
    """errata.html from the errata.json saved in `out`: every printed formula typeset
    beside the derived one with the differing terms marked, its verdict and witnesses."""
    doc = load_errata(out)
    systems: dict[str, list] = {}
    for e in doc["errata"]:
        systems.setdefault(e["system"], []).append(e)
    pages = {s: site.page_name(s) for s in systems if (out / site.page_name(s)).exists()}
    page = out / "errata.html"
    section6 = doc.get("section6", [])
    page.write_text(site.ERRATA.render(style=site.STYLE, systems=systems, pages=pages,
                                       prov=doc["provenance"], versions=doc["engines"],
                                       counts=_verdict_counts(doc["errata"] + section6),
                                       section6=section6))
    return page


def _verdict_counts(entries: list[dict]) -> dict[str, int]:
    counts: dict[str, int] = {}
    for e in entries:
        counts[e["verdict"]] = counts.get(e["verdict"], 0) + 1
    return counts


def _title(shown: str) -> str:
    system = get_system(base_id(shown))
    if shown == system.id:
        return system.title
    v = system.variant(shown[len(system.id) + 1:-1])
    return f"{system.title}, variant {v.name}: {v.description}"


def _expected(shown: str, comps=()) -> list:
    """The row's declarations, each with the metrics it covers in `comps` as measured now
    (engine, metric, value, gate, verdict, rule): a reason states the mechanism, the
    numbers come from the run."""
    system = get_system(base_id(shown))
    if shown == system.id:
        declared = [SimpleNamespace(simulator=e.simulator, metric=e.metric, reason=e.reason,
                                    kind=e.kind, measured=[])
                    for e in system.expectations
                    if e.applies(system.structure, system.parameter_values())]
        for c in comps:
            for m in c.metrics:
                # the first declaration that matches a metric is the one that covers it
                first = next((d for d in declared if fnmatch.fnmatch(c.simulator, d.simulator)
                              and fnmatch.fnmatch(m.name, d.metric)), None)
                if first is not None:
                    limit = (m.refinement or {}).get("limit")
                    first.measured.append(SimpleNamespace(
                        simulator=c.simulator, name=m.name, value=m.value,
                        tolerance=m.tolerance, status=m.status,
                        rule=(m.rule or "a_priori").replace("_", "-"),
                        limit=(f"; its limit, at h/{limit['divisor']}: "
                               f"{limit['value']:.2e} / {limit['tolerance']:.1e}"
                               if limit else "")))
        return declared
    v = system.variant(shown[len(system.id) + 1:-1])
    return [SimpleNamespace(simulator=", ".join(v.settings), metric="(measured, not gated)",
                            reason=v.reason, kind="measured", measured=[])]


def contact_warnings(comps) -> list[dict]:
    """Unilateral contacts whose reference force turns negative (the bilateral model pulls
    where a real contact would open), with each engine's minimum and first negative time."""
    found: dict[tuple[str, str], dict] = {}
    for c in comps:
        for m in c.metrics:
            d = m.detail or {}
            if ".contact_" not in m.name or d.get("reference_first_negative_s") is None:
                continue
            scenario, contact = m.name.split(".contact_", 1)
            w = found.setdefault((scenario, contact), {
                "scenario": scenario, "contact": contact, "engines": {},
                "t_ref": d["reference_first_negative_s"], "min_ref": d["reference_min"]})
            if d.get("engine_min") is not None:
                w["engines"][c.simulator] = {"min": d["engine_min"],
                                             "t": d.get("engine_first_negative_s")}
    return list(found.values())


def _worst(c, prefixes) -> str:
    ms = [m for m in c.metrics if any(p in m.name for p in prefixes)]
    if not ms:
        return "-"
    worst = max(ms, key=lambda m: m.value / m.tolerance if m.tolerance else m.value)
    flag = {"pass": "", "xfail": " (xfail)", "fail": " FAIL", "xpass": " XPASS",
            "measured": " (measured)", "unresolved": " (unresolved)"}[worst.status]
    return f"{worst.value:.1e}/{worst.tolerance:.0e}{flag}"


def error_table(results) -> list[str]:
    """System x engine: the worst metric (value/tolerance) of each check."""
    lines = ["| system | engine | version | trajectory | forces | frequency | wall s |",
             "|---|---|---|---|---|---|---|"]
    for c in results:
        if not c.supported:
            lines.append(f"| {row_id(c)} | {c.simulator} | {c.engine_version} | unsupported: "
                         f"{c.reason} | | | |")
            continue
        lines.append(
            f"| {row_id(c)} | {c.simulator} | {c.engine_version} | "
            f"{_worst(c, ('trajectory_max',))} | {_worst(c, ('.reaction_', '.constraint_', '.contact_'))} | "
            f"{_worst(c, ('frequency.',))} | {c.wall_time:.2f} |")
    return lines


def _markdown(results, prov: dict) -> str:
    lines = [f"# mbfidelity summary ({prov['git_describe']}, {prov['date']})", "",
             "Worst metric of each check, as value/tolerance (relative errors; dt = "
             f"{results[0].dt if results else ''} s):", ""]
    lines += error_table(results)
    lines += ["", "## Every metric", "",
              "| system | simulator | metric | value | tolerance | status |",
              "|---|---|---|---|---|---|"]
    for c in results:
        if not c.supported:
            lines.append(f"| {row_id(c)} | {c.simulator} | * | | | unsupported: {c.reason} |")
        for m in c.metrics:
            lines.append(f"| {row_id(c)} | {c.simulator} | {m.name} | {m.value:.3e} | "
                         f"{m.tolerance:.3e} | {m.status} |")
    return "\n".join(lines) + "\n"


def frequency_table(results) -> dict:
    """system -> rows (mode, reference Hz, engine -> {method: Hz})."""
    table: dict = {}
    for c in results:
        for m in c.metrics:
            if not m.name.startswith("frequency.") or not m.detail:
                continue
            mode = m.name.split("mode")[-1]
            rows = table.setdefault(row_id(c), {})
            row = rows.setdefault(mode, {"reference_hz": m.detail["reference_hz"], "engines": {}})
            kind = "linearization" if "linearization" in m.name else "fit"
            row["engines"].setdefault(c.simulator, {})[kind] = m.detail.get("engine_hz")
    return table


def draw_mechanism(geometry: dict, out: Path) -> str:
    """The mechanism at its operating equilibrium, from its saved geometry
    (`results_folder.mechanism_geometry`)."""
    system_id = geometry["system"]
    # the world axes drawn (a side view of a spatial mechanism; older folders: x, y)
    i, j = geometry.get("view", [0, 1])

    def at(p):
        p = list(p) + [0.0] * (3 - len(p))  # a world anchor may be given in the plane
        return p[i], p[j]
    fig, ax = plt.subplots(figsize=(4, 4))
    for item in geometry["items"]:
        kind = item["kind"]
        if kind == "segment":
            a, c = (at(p) for p in item["points"])
            ax.plot([a[0], c[0]], [a[1], c[1]], "-", lw=4, color="tab:blue", alpha=0.7)
        elif kind == "circle":
            ax.add_patch(CirclePatch(at(item["center"]), item["radius"], fill=False, lw=2,
                                     color="tab:green"))
        elif kind == "polygon":
            ax.add_patch(Polygon([at(p) for p in item["points"]], closed=True, fill=False,
                                 lw=2, color="tab:orange"))
        elif kind == "centre_of_mass":
            ax.plot(*at(item["at"]), "k+", ms=8)
        elif kind == "joint":
            ax.plot(*at(item["at"]), "o", color="k", ms=5, mfc="white")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.margins(0.2)
    ax.set_xlabel("xyz"[i], fontsize=7)
    ax.set_ylabel("xyz"[j], fontsize=7)
    pose = ", ".join(f"{c} = {v:.4g}" for c, v in zip(geometry["coordinates"],
                                                     geometry["operating_point"]))
    ax.set_title(f"{system_id} at {pose}", fontsize=7)
    name = f"{system_id}-drawing.png"
    fig.savefig(out / name, dpi=80)
    plt.close(fig)
    return name
