"""The power pages, rendered from the saved power.json and out_of_the_box.json only
(`mbfidelity power --out DIR`, `mbfidelity out-of-the-box --out DIR`): power.html, the
smallest injected model error the gates reject per system x engine and error kind, and
whether they reject each neutralised engine default switched back on; out_of_the_box.html,
what each of those defaults does to the motion against the neutralised run. Each page links
the other pages of the folder that exist when it is written (the site writes
out_of_the_box.html again, `reports/html.py`)."""
from __future__ import annotations

import json
from pathlib import Path

import jinja2

POWER = "power.json"
OUT_OF_THE_BOX = "out_of_the_box.json"

STYLE = """body{font-family:sans-serif;margin:2em;max-width:1400px}
table{border-collapse:collapse;margin-bottom:1.5em}td,th{border:1px solid #ccc;padding:3px 6px;font-size:13px}
th{background:#f0f0f0}.pass{background:#dff5df}.fail{background:#f8d0d0}.weak{background:#fbeec8}
.na{background:#e6e6e6;color:#666}small{color:#555}"""

#: where a recorded study lent readings (comparisons/out_of_the_box.py, `_lent`)
RECORD_NOTE = """{% if doc.provenance.record %}<p><b>{{ doc.cost.recorded_entries }} of the {{ doc.entries|length }}
readings were taken from a recorded study (written at {{ doc.provenance.record.git_describe }},
{{ doc.provenance.record.date }})</b>, each where it was made with the engine version
installed now at the same step, and each marked "recorded at" with the state of the package
that made it; this study made the others. A recorded reading does not see a change of the gates or of
the builds made since its mark: <code>make power</code> makes every reading again.</p>{% endif %}
"""

_ENV = jinja2.Environment(autoescape=True)
_ENV.filters["eps"] = lambda x: "-" if x is None else (x if isinstance(x, str) else f"{x:.0e}")
_ENV.filters["num"] = lambda x: "-" if x is None else (x if isinstance(x, str) else f"{x:.3g}")

POWER_TEMPLATE = _ENV.from_string("""<!doctype html><html><head><meta charset="utf-8">
<title>mbfidelity gate power</title><style>{{ style }}</style></head><body>
<h1>Gate power: the smallest model error each engine's gates reject</h1>
<p>{{ doc.provenance.git_describe }} · {{ doc.provenance.date }}.{% if doc.cost %} {{ doc.entries|length }}
system x engine entries, {{ doc.cost.comparisons }} comparisons, {{ "%.0f"|format(doc.cost.wall_time_s) }} s of wall time
on {{ doc.cost.workers }} worker processes.{% endif %} One parameter of each kind is
multiplied by (1 + eps) in the engine's build only (the reference keeps the true value);
eps on the decade grid {{ doc.epsilons|map("eps")|join(", ") }}, searched at the grid's
ends first and by bisection between them, assuming a larger error is rejected whenever a
smaller one is (a cell marked "not monotone" has runs that break it). Each run is the system's first scenario and the
frequency checks (a default's: every declared scenario). A run is rejected when a metric
that holds in the neutralised run fails, or exceeds that run's tolerance (the gates are
held at the harness's configuration), or when a metric the neutralised run fails by
declaration exceeds its value there by more than the tolerance (marked "beyond the
baseline's error"). A cell gives the smallest rejected eps and the
parameter. At a {{ doc.probe|eps }} error each kind is classified: rejected; below the
gates (grey: the exact model's change of each judged quantity, trajectory, actuator force
and frequency, is within its gate, so no sound gate could reject it); not rejected (yellow:
a judged quantity moves beyond its gate and no gate catches it, a defect). A default
switched on is classified the same way from the engine's runs with and without it: it
acts when it moves a judged quantity by more than its gate; one that moves it toward the
reference (a smaller error with it) is "closer to the reference".</p>
""" + RECORD_NOTE + """<h2>Summary: median smallest rejected eps</h2>
<table><tr><th>engine</th>{% for k in kinds %}<th>{{ k }}</th>{% endfor %}<th>defaults that act: rejected</th></tr>
{% for sim, row in doc.summary.items() %}<tr><td>{{ sim }}</td>
{% for k in kinds %}<td>{{ row[k].median_smallest_rejected|eps }} <small>({{ row[k].systems }} systems{% if row[k].not_rejected_at_largest %}, {{ row[k].not_rejected_at_largest }} not rejected at {{ doc.epsilons[-1]|eps }}{% endif %}{% if row[k].at_probe %}; at {{ doc.probe|eps }}: {{ row[k].at_probe['rejected'] }} rejected, {{ row[k].at_probe['below the gates'] }} below the gates{% if row[k].at_probe['not rejected'] %}, <b>{{ row[k].at_probe['not rejected'] }} not rejected</b>{% endif %}{% endif %})</small></td>{% endfor %}
<td>{{ row.defaults.rejected }} / {{ row.defaults.acting }}{% if row.defaults.not_rejected %} <small><b>not rejected: {{ row.defaults.not_rejected|join(', ') }}</b></small>{% endif %}{% if row.defaults.closer_to_reference %} <small>closer to the reference: {{ row.defaults.closer_to_reference|join(', ') }}</small>{% endif %}{% if row.defaults.on_failed_run %} <small>on a failed run: {{ row.defaults.on_failed_run|join(', ') }}</small>{% endif %}{% if row.defaults.below_gates %} <small>({{ row.defaults.below_gates|length }} below the gates)</small>{% endif %}</td></tr>{% endfor %}</table>
<h2>Per system and engine</h2>
<table><tr><th>system</th><th>engine</th><th>baseline</th>{% for k in kinds %}<th>{{ k }}</th>{% endfor %}<th>defaults switched on</th></tr>
{% for e in doc.entries %}<tr><td>{{ e.system }}</td><td>{{ e.simulator }}{% if e.recorded %} <small>recorded at {{ e.recorded }}</small>{% endif %}</td>
{% if not e.supported %}<td class="na" colspan="{{ kinds|length + 2 }}">unsupported: {{ e.reason }}</td>
{% else %}<td class="{{ 'pass' if e.baseline_passed else 'fail' }}" title="{{ e.baseline_not_holding|join(', ') }}">{{ 'passes' if e.baseline_passed else 'fails' }}</td>
{% for p in e.errors %}{% if not p.applicable %}<td class="na" title="{{ p.reason }}">n/a</td>
{% else %}<td class="{{ 'pass' if p.verdict == 'rejected' else ('weak' if p.verdict == 'not rejected' else 'na') }}" title="{{ p.why }}">{{ p.smallest_rejected|eps if p.smallest_rejected is not none else 'not rejected' }} <small>{{ p.parameter }}{% if p.verdict and p.verdict != 'rejected' %}; 1 %: {{ p.verdict }}{% endif %}{% if p.monotone is false %}; not monotone{% endif %}</small></td>{% endif %}{% endfor %}
<td>{% for d in e.defaults %}<span class="{{ 'pass' if d.rejected else ('weak' if d.verdict == 'not rejected' else 'na') }}" title="{{ d.why }}">{{ d.setting }}: {{ d.verdict }}</span>{% if not loop.last %}; {% endif %}{% endfor %}</td>{% endif %}</tr>{% endfor %}
</table>
<h2>Errors not rejected at {{ doc.probe|eps }}: the exact model's change against the gates</h2>
<table><tr><th>system</th><th>engine</th><th>kind</th><th>parameter</th><th>smallest rejected</th><th>verdict at {{ doc.probe|eps }}</th><th>why</th><th>judged quantities: change / gate (metric's status)</th></tr>
{% for e in doc.entries if e.supported %}{% for p in e.errors if p.applicable and p.verdict != 'rejected' %}<tr><td>{{ e.system }}</td><td>{{ e.simulator }}</td><td>{{ p.kind }}</td><td>{{ p.parameter }}</td>
<td>{{ p.smallest_rejected|eps if p.smallest_rejected is not none else 'not rejected' }}</td><td class="{{ 'weak' if p.verdict == 'not rejected' else 'na' }}">{{ p.verdict }}</td><td>{{ p.why }}</td>
<td>{% for q, g in (p.motion_change.against_gates or {}).items() %}{{ q }} {{ g.change|num }} / {{ g.gate|num }} <small>({{ g.status }})</small>{% if not loop.last %}; {% endif %}{% endfor %}</td></tr>{% endfor %}{% endfor %}
</table>
<h2>Defaults switched on and not rejected</h2>
<table><tr><th>system</th><th>engine</th><th>default</th><th>value</th><th>verdict</th><th>largest change against its gate</th><th>why</th></tr>
{% for e in doc.entries if e.supported %}{% for d in e.defaults if not d.rejected %}<tr><td>{{ e.system }}</td><td>{{ e.simulator }}</td><td title="{{ d.note }}">{{ d.setting }}</td><td>{{ 'each above' if d.setting == 'all' else d.engine_value }}</td>
<td class="{{ 'weak' if d.verdict == 'not rejected' else 'na' }}">{{ d.verdict }}</td><td>{% if d.change %}{{ d.change.quantity }}: {{ d.change.change|num }} / {{ d.change.gate|num }}{% else %}-{% endif %}</td><td>{{ d.why }}</td></tr>{% endfor %}{% endfor %}
</table>
<p><a href="out_of_the_box.html">What each engine default does out of the box</a></p>
</body></html>""")

OUT_OF_THE_BOX_TEMPLATE = _ENV.from_string("""<!doctype html><html><head><meta charset="utf-8">
<title>mbfidelity out of the box</title><style>{{ style }}</style></head><body>
{% if links.index %}<nav><a href="index.html">index</a></nav>{% endif %}
<h1>Out of the box: what each engine default the harness neutralises does</h1>
<p>{{ doc.provenance.git_describe }} · {{ doc.provenance.date }}.{% if doc.cost %} {{ doc.entries|length }}
system x engine readings, {{ doc.cost.comparisons }} comparisons, {{ "%.0f"|format(doc.cost.wall_time_s) }} s of wall time
on {{ doc.cost.workers }} worker processes.{% endif %} Each default (the engine's
documented value, cited in its note: hover the setting) is switched back on alone, then all
together ("all": the engine as it comes), on every scenario the system declares. "Motion
change": the largest difference between the run with the default and the same run with the
harness's setting, relative to the amplitude, against that scenario's trajectory gate, in the
scenario where it is largest against its gate (named). Energy drift: the largest
change of the exact model's energy along the run, relative to the largest kinetic energy.
Damping ratio: what the free-vibration fit of mode 1 finds added to the exact one. Verdict:
rejected when a gate that holds with the harness's setting fails with the default (a run that
does not complete counts as rejected: timed out, crashed); "no effect" when no metric moved.</p>
""" + RECORD_NOTE + """{% if left %}<h2>Left out</h2><p>What the study could not measure, with the reason: an
engine that cannot build the mechanism, a run with a default that did not complete (its
verdict counts it as rejected; its effect is not measured).</p><ul>
{% for anchor, what, why in left %}<li><a href="#{{ anchor }}">{{ what }}</a>: {{ why }}</li>{% endfor %}</ul>{% endif %}
{% for e in doc.entries %}<h2 id="{{ e.system }}-{{ e.simulator }}">{% if e.system in links.pages %}<a href="{{ links.pages[e.system] }}">{{ e.system }}</a>{% else %}{{ e.system }}{% endif %} · {{ e.simulator }} {{ e.engine_version }}{% if e.recorded %} <small>(recorded at {{ e.recorded }})</small>{% endif %}</h2>
{% if not e.supported %}<p>left out: {{ e.reason }}</p>{% elif not e.defaults %}<p>no neutralised default declared by its backend (<code>Setting.engine_default</code>).</p>{% else %}
<table><tr><th>default</th><th>engine value</th><th>harness value</th><th>verdict</th><th>motion change (gate)</th><th>energy drift: harness → default</th><th>damping ratio added (mode 1)</th><th>frequency error (mode 1)</th></tr>
{% for d in e.defaults %}{% set damp = d.effect.get('damping.fit_mode1') %}{% set freq = d.effect.get('frequency.fit_mode1') %}
<tr><td title="{{ d.note }}">{{ d.setting }}</td><td>{{ 'each above' if d.setting == 'all' else d.engine_value }}</td><td>{{ d.harness_value if d.harness_value is not none else '-' }}</td>
<td class="{{ 'pass' if d.rejected else ('weak' if d.verdict == 'not rejected' else 'na') }}" title="{{ d.why }}">{{ d.verdict }}{% for i in d.incidents %} ({{ i.outcome }}){% endfor %}{% if not d.rejected %}<br><small>{{ d.why }}</small>{% endif %}</td>
<td>{% if d.motion.error %}{{ d.motion.error }}{% else %}{{ d.motion.trajectory_change|num }} <small>(gate {{ d.motion.trajectory_gate|num }}, {{ d.motion.scenario }})</small>{% endif %}</td>
<td>{% if d.motion.energy_drift_switched_on is not none and not d.motion.error %}{{ d.motion.energy_drift_neutralised|num }} → {{ d.motion.energy_drift_switched_on|num }}{% else %}-{% endif %}</td>
{% for m in (damp, freq) %}<td>{% if m %}{{ m.neutralised|num }} → {{ m.switched_on|num }} <small>(gate {{ m.tolerance|num }})</small>{% else %}-{% endif %}</td>{% endfor %}</tr>{% endfor %}
</table>{% endif %}{% endfor %}
{% if links.power %}<p><a href="power.html">Gate power</a></p>{% endif %}
</body></html>""")


def write_power_pages(out: Path) -> tuple[Path, Path]:
    """power.html and out_of_the_box.html in `out`, from the JSON saved there."""
    power = json.loads((out / POWER).read_text())
    kinds = list(power["error_kinds"])
    power_page = out / "power.html"
    power_page.write_text(POWER_TEMPLATE.render(doc=power, kinds=kinds, style=STYLE))
    return power_page, write_out_of_the_box_page(out)


def write_out_of_the_box_page(out: Path, pages: dict[str, str] | None = None) -> Path:
    """out_of_the_box.html in `out`, from the out_of_the_box.json saved there; `pages`
    maps a system to its mechanism page (linked from its heading)."""
    box = json.loads((out / OUT_OF_THE_BOX).read_text())
    links = {"index": (out / "index.html").exists() or bool(pages),
             "power": (out / "power.html").exists(), "pages": pages or {}}
    left = []
    for e in box["entries"]:
        anchor = f"{e['system']}-{e['simulator']}"
        if not e["supported"]:
            left.append((anchor, f"{e['system']} · {e['simulator']}", e["reason"]))
        for d in e["defaults"]:
            for i in d.get("incidents", []):
                left.append((anchor, f"{e['system']} · {e['simulator']} · {d['setting']}",
                             f"{i['outcome']}: {i['message']}"))
    page = out / "out_of_the_box.html"
    page.write_text(OUT_OF_THE_BOX_TEMPLATE.render(doc=box, style=STYLE, links=links,
                                                   left=left))
    return page
