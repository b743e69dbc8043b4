"""The convergence page: for every mechanism, the error against the step (fixed-step
engines), against the target accuracy (error-controlled engines) and against the CPU
seconds of the stepping (work-precision, every engine) on one figure, and the table of
fitted against declared orders (per decade of accuracy: the largest error ratio against
its gate), rendered from the saved convergence.json (`mbfidelity convergence --out
DIR`). A benchmark row (`System.benchmark_error`) adds its own work-precision panel, the
error as the benchmark defines it against the CPU seconds, and a table of it at every
step; an engine whose run fails shows as failed there, with the system's declared
reason."""
from __future__ import annotations

import json
from pathlib import Path

import jinja2
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

CONVERGENCE = "convergence.json"

TEMPLATE = jinja2.Template("""<!doctype html><html><head><meta charset="utf-8">
<title>mbfidelity convergence</title><style>
body{font-family:sans-serif;margin:2em;max-width:1300px}
table{border-collapse:collapse;margin-bottom:1.5em}td,th{border:1px solid #ccc;padding:3px 6px;font-size:13px}
th{background:#f0f0f0}.pass{background:#dff5df}.fail,.xpass{background:#f8d0d0}.xfail,.unresolved{background:#fbeec8}.unsupported{background:#e6e6e6}
img{max-width:100%}
</style></head><body>
<h1>Convergence and work-precision</h1>
<p>{{ doc.provenance.git_describe }} · {{ doc.provenance.date }} · steps {{ doc.steps|join(", ") if doc.steps is not string else "4, 2, 1 and 0.5 ms, scaled down where the motion is too fast for them (w h within the scheme's asymptotic range)" }} over
{{ doc.t_end }} s of each system's first scenario. Error: max |q - q_ref| over the run, relative to the
amplitude. The order is fitted on the steps whose error still falls (by {{ doc.min_decrease }} per halving
at least) and stays {{ doc.reference_margin }} times above the reference's own error; it must match the
order the engine declares within {{ doc.order_tolerance }}. An error-controlled engine is studied by its target
accuracy ({{ doc.accuracies|map("string")|join(", ") }}) at a sampling step of about 1/w: its error must fall by
{{ doc.min_accuracy_decrease }} per decade of accuracy at least, over every two decades (the cell: the largest ratio per
decade, the gate, and the slope of log error on log accuracy), where the controller sets asymptotic steps, down to the
reference's floor.</p>
<table><tr><th>system</th>{% for sim in sims %}<th>{{ sim }}: fitted / declared order</th>{% endfor %}</tr>
{% for sys in systems %}<tr><td><a href="#{{ sys }}">{{ sys }}</a></td>
{% for sim in sims %}{% set s = by[sys].get(sim) %}{% if s %}<td class="{{ s.metric.status }}" title="{{ s.metric.reason or s.flattened or s.failure or s.unsupported }}">
{% if s.knob == "accuracy" %}ratio {{ "%.2g"|format(s.worst_decrease) if s.worst_decrease is not none else "-" }} / {{ s.metric.tolerance }}{% if s.accuracy_slope is not none %}, slope {{ "%.2f"|format(s.accuracy_slope) }}{% endif %}{% else %}{{ "%.2f"|format(s.observed_order) if s.observed_order is not none else "-" }} / {{ s.integrator_order }}{% endif %} {{ s.metric.status }}</td>{% else %}<td>-</td>{% endif %}{% endfor %}</tr>{% endfor %}
</table>
{% for sys in systems %}<h2 id="{{ sys }}">{{ sys }}</h2>
<ul>{% for sim in sims %}{% set s = by[sys].get(sim) %}{% if s and (s.metric.reason or s.flattened or s.failure) %}<li><b>{{ sim }}</b> ({{ s.metric.status }}): {{ s.failure or s.metric.reason or s.flattened }}</li>{% endif %}{% endfor %}</ul>
<img src="{{ figures[sys] }}">
{% set bench = by[sys].values()|selectattr("benchmark_measure")|list %}{% if bench %}
<p>Benchmark's error: {{ bench[0].benchmark_measure }} ({{ bench[0].benchmark_unit }}), over the study's run.</p>
<table><tr><th>engine</th><th>step / target accuracy</th><th>benchmark error</th><th>CPU s</th></tr>
{% for s in bench %}{% for p in s.points %}<tr><td>{{ s.simulator }}</td><td>{{ "accuracy %g"|format(p.accuracy) if p.accuracy is not none else "dt %g s"|format(p.dt) }}</td>
<td{% if p.benchmark_error is none or p.benchmark_error != p.benchmark_error %} class="{{ 'xfail' if s.declared_failure else 'fail' }}" title="{{ s.declared_failure }}">did not complete{% if s.declared_failure %} (declared){% endif %}{% else %}>{{ "%.3g"|format(p.benchmark_error) }}{% endif %}</td>
<td>{{ "%.3g"|format(p.cpu_time) }}</td></tr>{% endfor %}{% if s.failure or s.unsupported %}<tr><td>{{ s.simulator }}</td><td colspan="3" class="{{ 'unsupported' if s.unsupported else ('xfail' if s.declared_failure else 'fail') }}">{{ s.unsupported or s.failure }}{% if s.declared_failure %}; declared: {{ s.declared_failure }}{% endif %}</td></tr>{% endif %}{% endfor %}
</table>{% endif %}{% endfor %}
</body></html>""")


def _completed(study: dict) -> bool:
    """Whether every run of the study finished with finite numbers."""
    return not study.get("failure") and all(
        p.get("benchmark_error") is None or p["benchmark_error"] == p["benchmark_error"]
        for p in study["points"])


def _benchmark_panel(ax, studies: list[dict]) -> None:
    """The benchmark's error against the CPU seconds, every engine; one that failed its
    run is labelled failed (declared, where the system declares why)."""
    for i, s in enumerate(studies):
        points = [p for p in s["points"] if p.get("benchmark_error") is not None
                  and p["benchmark_error"] == p["benchmark_error"] and p["benchmark_error"] > 0]
        label = s["simulator"] + ("" if _completed(s) else
                                  " (failed, declared)" if s.get("declared_failure")
                                  else " (failed)")
        ax.loglog([max(p["cpu_time"], 1e-6) for p in points],
                  [p["benchmark_error"] for p in points],
                  "s--" if s.get("knob") == "accuracy" else "o-", color=f"C{i}",
                  mfc="none" if not _completed(s) else None, label=label)
    unit = next((s["benchmark_unit"] for s in studies if s.get("benchmark_unit")), "")
    ax.set_xlabel("CPU seconds of stepping")
    ax.set_ylabel(f"benchmark error [{unit}]")
    ax.set_title("work-precision, the benchmark's error")


def _figure(system: str, studies: list[dict], out: Path) -> str:
    by_accuracy = any(s.get("knob") == "accuracy" and any(p["error"] > 0 for p in s["points"])
                      for s in studies)
    benchmark = any(s.get("benchmark_measure") for s in studies)
    panels = 2 + by_accuracy + benchmark
    fig, axes = plt.subplots(1, panels, figsize=(5.5 * panels, 4))
    steps, work = axes[0], axes[1 + by_accuracy]
    if benchmark:
        _benchmark_panel(axes[-1], studies)
    for i, s in enumerate(studies):
        points = [p for p in s["points"] if p["error"] > 0]
        if not points:
            continue
        if s.get("knob") == "accuracy":  # by_accuracy holds: it has points
            line, = axes[1].loglog([p["accuracy"] for p in points],
                                   [p["error"] for p in points], "s-", color=f"C{i}",
                                   label=f"{s['simulator']} (order {s['integrator_order']})")
            judged = [p for p in points if p["accuracy"] in s["judged_accuracies"]]
            axes[1].loglog([p["accuracy"] for p in judged], [p["error"] for p in judged], "o",
                           color=line.get_color(), mfc="none", ms=10)
            work.loglog([max(p["cpu_time"], 1e-6) for p in points],
                        [p["error"] for p in points], "s-", color=line.get_color(),
                        label=f"{s['simulator']} (target accuracy)")
            continue
        line, = steps.loglog([p["dt"] for p in points], [p["error"] for p in points], "o-",
                             color=f"C{i}",
                             label=f"{s['simulator']} (order {s['integrator_order']})")
        # the declared order's slope through the coarsest point
        dt0, e0 = points[0]["dt"], points[0]["error"]
        steps.loglog([p["dt"] for p in points],
                     [e0 * (p["dt"] / dt0) ** s["integrator_order"] for p in points], ":",
                     color=line.get_color(), lw=0.8)
        work.loglog([max(p["cpu_time"], 1e-6) for p in points], [p["error"] for p in points],
                    "o-", color=line.get_color(), label=s["simulator"])
    steps.set_xlabel("step dt [s]")
    steps.set_ylabel("max |q - q_ref| / amplitude")
    steps.set_title("error against the step (dotted: declared order)")
    if by_accuracy:
        axes[1].set_xlabel("target accuracy")
        axes[1].set_title("error-controlled: error against the accuracy (circled: judged)")
    work.set_xlabel("CPU seconds of stepping")
    work.set_title("work-precision")
    for ax in axes:  # a panel without curves (every engine there unsupported) has no legend
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    fig.suptitle(system)
    fig.tight_layout()
    name = f"convergence-{system}.png"
    fig.savefig(out / name, dpi=80)
    plt.close(fig)
    return name


def write_convergence_page(out: Path) -> Path:
    """convergence.html and its figures in `out`, from the convergence.json saved there."""
    doc = json.loads((out / CONVERGENCE).read_text())
    systems = list(dict.fromkeys(s["system"] for s in doc["studies"]))
    sims = list(dict.fromkeys(s["simulator"] for s in doc["studies"]))
    by = {sys: {s["simulator"]: s for s in doc["studies"] if s["system"] == sys}
          for sys in systems}
    figures = {sys: _figure(sys, list(by[sys].values()), out) for sys in systems}
    page = out / "convergence.html"
    page.write_text(TEMPLATE.render(doc=doc, systems=systems, sims=sims, by=by,
                                    figures=figures))
    return page
