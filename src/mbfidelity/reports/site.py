"""The static site of a results folder: the index (the matrix of mechanisms x engines,
linking every page) and one page per mechanism (sketch, parameters, the derived model
typeset, the printed formulas beside the derived ones, each scenario's figures and an
animation of the exact motion and every engine's). Everything shown was computed upstream
and saved (`comparisons/results_folder.py`); the pages work from the file system with no
network: MathML is laid out by the browser, the animation is a local script drawing on a
canvas from frames embedded in the page."""
from __future__ import annotations

import json
from pathlib import Path
from urllib.parse import quote

import jinja2
from markupsafe import escape

#: the animation's script, written once beside the pages
ANIMATION_SCRIPT = "mbfidelity-animation.js"
#: engine -> colour, shared by the animation's legend and its drawing
COLOURS = {"exact": "rgba(0,0,0,0.35)", "mujoco": "#1f77b4", "pybullet": "#ff7f0e",
           "exudyn": "#2ca02c", "pymunk": "#d62728", "drake": "#9467bd"}
#: pages of other commands linked from the index when their files are present
OTHER_PAGES = (("errata.html", "Errata: the printed formulas against the derivation"),
               ("convergence.html", "Convergence and work-precision of every engine"),
               ("out_of_the_box.html", "Out of the box: each engine's defaults switched back on"),
               ("power.html", "Power of the gates: the smallest model error each rejects, "
                              "and the engines' defaults"),
               )
#: whole-catalogue figures shown on the index when present
INDEX_FIGURES = (("strutt.png", "The Strutt chart of eq. 83: stability of Mathieu's equation as "
                  "printed (§8.4, Fig. 28) from Floquet theory, and each engine's "
                  "classification by simulation (<code>mbfidelity strutt</code>)."),
                 ("beams.png", "Flexible beams: the simply supported beam with a block (§6.1, "
                  "Fig. 17) in each engine's flexible elements against the exact "
                  "Euler-Bernoulli frequencies (<code>mbfidelity beams</code>)."))

STYLE = """
body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em;color:#222;line-height:1.4}
table{border-collapse:collapse;margin:.5em 0 1.5em}td,th{border:1px solid #ccc;padding:3px 6px;
font-size:13px;vertical-align:top}th{background:#f0f0f0}.pass{background:#dff5df}
.fail{background:#f8d0d0}.xfail{background:#fbeec8}.xpass{background:#f8d0d0}
.measured{background:#e3ecf8}.unsupported{background:#e6e6e6}img{max-width:100%}
code{font-size:12px}math{font-size:110%}.formula{overflow-x:auto;max-width:100%}
div.formula math[display=block]{margin:.5em 0;padding:.1em 0}
td .formula{max-width:30vw}td code{white-space:pre-wrap;word-break:break-all}
.differs{background:#ffd0d0;outline:1px solid #c33}nav a{margin-right:1em}
.animation{display:inline-block;border:1px solid #ccc;padding:.5em;margin:.5em .5em 1em 0}
.animation canvas{display:block;background:#fff}.legend span{margin-right:.8em;font-size:12px}
.legend b{display:inline-block;width:1.5em;height:.35em;vertical-align:middle;margin-right:.3em}
"""

ENV = jinja2.Environment(autoescape=False, undefined=jinja2.StrictUndefined)
ENV.filters["url"] = lambda name: quote(name)
ENV.filters["e"] = lambda s: str(escape(s))

INDEX = ENV.from_string("""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>mbfidelity: simulators against exact models</title>
<style>{{ style }}</style></head><body>
<h1>mbfidelity: simulators against exact models</h1>
<p>git {{ prov.git_describe|e }} · {{ prov.date|e }} · Python {{ prov.python|e }} · {{ prov.platform|e }}.
Engines: {% for sim, v in versions.items() %}{{ sim }} {{ v|e }}{% if not loop.last %}, {% endif %}{% endfor %}.</p>
<p>Each mechanism's exact model is derived symbolically and integrated to round-off; every engine
runs the same mechanism and its motion, forces and frequencies are judged against it. Errors are
relative to each coordinate's amplitude; each tolerance follows from the integrator's order p,
the step h, the simulated time T and the fastest frequency w of the motion: (w h)^p (1 + w T)
for trajectories, and for semi-implicit Euler (w h) + (w h)^2 (1 + w T) + zeta (w h) w T (see
<code>comparisons/tolerances.py</code>). A cell counts its metrics by verdict; its colour is the
worst one (pass, xfail: an expected failure declared with its physical reason, measured: not
gated, fail).</p>
<h2>The matrix</h2>
<p id="verdicts">{{ summary.total }} metrics: {% for verdict, n in summary.counts.items() %}{{ n }} {{ verdict }}{% if not loop.last %}, {% endif %}{% endfor %}.
Unresolved: {{ summary.unresolved }} ({{ "%.2f"|format(100 * summary.unresolved_share) }} % of the metrics), {{ summary.declared }} of them declared with their reason.</p>
<table><tr><th>engine</th>{% for verdict in summary.counts %}<th>{{ verdict }}</th>{% endfor %}</tr>
{% for sim, found in summary.engines.items() %}<tr><td>{{ sim|e }}</td>{% for verdict in summary.counts %}<td>{{ found.get(verdict, 0) }}</td>{% endfor %}</tr>{% endfor %}
</table>
<table><tr><th>mechanism</th>{% for sim in sims %}<th>{{ sim }}</th>{% endfor %}</tr>
{% for row in rows %}<tr><td><a href="{{ pages[row]|url }}">{{ row|e }}</a><br><small>{{ titles[row]|e }}</small></td>
{% for sim in sims %}{% set c = cells[row].get(sim) %}{% if c %}<td class="{{ c.cls }}"><a href="{{ pages[row]|url }}#{{ anchors[row] }}">{{ c.text|e }}</a></td>{% else %}<td class="unsupported">-</td>{% endif %}{% endfor %}</tr>{% endfor %}
</table>
{% set failed = incidents.values()|select|list %}{% if failed %}<h2 class="fail">Incidents</h2>
<p>Stages that did not complete (the rest of the run stands):</p><ul>
{% for row, found in incidents.items() %}{% for i in found %}<li><a href="{{ pages[row]|url }}#{{ anchors[row] }}">{{ row|e }}</a>, <b>{{ i.simulator|e }}</b>, {{ i.scenario|e }}{% if i.stage %} ({{ i.stage|e }}){% endif %}: {{ i.outcome|e }}{% if i.get("t_reached") is not none %} at t = {{ "%.6g"|format(i.t_reached) }} s{% endif %}: {{ i.message|e }}</li>{% endfor %}{% endfor %}</ul>{% endif %}
{% if others %}<h2>Other pages</h2><ul>{% for name, title in others %}<li><a href="{{ name|url }}">{{ title }}</a></li>{% endfor %}
</ul>{% endif %}
{% for name, caption in figures %}<h2>{{ caption.split(":")[0] }}</h2><p>{{ caption }}{% if name == "strutt.png" and strutt_engines %} Engines: {{ strutt_engines|e }}.{% endif %}</p>
<img src="{{ name }}">{% endfor %}
{% if discretizations %}<h2>Discretized continua against the exact ones</h2>
<p>Each chain of N elements as derived, each engine's build of it (its own linearization) and
the printed Rayleigh estimates, against the exact continuum (§6; <code>mbfidelity discretization</code>).</p>
{% for fig in discretizations %}<img src="{{ fig }}">{% endfor %}{% endif %}
<h2>Why the engines deviate</h2><ul>{% for sim in sims %}<li><b>{{ sim }}</b>: {{ explanations.get(sim, "")|e }}</li>{% endfor %}</ul>
<p>Every metric of every comparison: <a href="summary.md">summary.md</a>, <a href="results.csv">results.csv</a>, <a href="results.json">results.json</a>.</p>
</body></html>""")

MECHANISM = ENV.from_string("""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>{{ system|e }}: {{ title|e }}</title>
<style>{{ style }}</style></head><body>
<nav><a href="index.html">index</a>{% if errata_page %}<a href="errata.html">errata</a>{% endif %}{% if out_of_the_box %}<a href="#out-of-the-box">out of the box</a>{% endif %}</nav>
<h1>{{ system|e }}</h1><p>{{ title|e }}{% if source %} ({{ source|e }}){% endif %}</p>
{% if drawing %}<h2>Sketch</h2><img src="{{ drawing|url }}" alt="{{ system|e }} at its operating equilibrium">{% endif %}
{% if not model %}<p class="fail">The derived model of this mechanism could not be saved (see
its incidents below).</p>{% else %}
<h2>Parameters</h2>
<table><tr><th>symbol</th><th>value</th><th>unit</th><th>meaning</th><th>default</th><th>source</th></tr>
{% for p in model.parameters %}<tr><td>{{ p.symbol }}</td><td>{{ "%.6g"|format(p.value) }}</td><td>{{ p.unit|e }}</td><td>{{ p.meaning|e }}</td><td><code>{{ p.default|e }}</code></td><td>{{ p.source|e }}</td></tr>{% endfor %}
</table>
<h2>The derived model</h2>
<p class="coordinates">Coordinates: {% for q in model.coordinates %}{{ q }}{% if not loop.last %}, {% endif %}{% endfor %}</p>
<h3>Kinetic and potential energy{% if model.dissipation %}, dissipation function{% endif %}</h3>
<div class="formula">{{ model.kinetic_energy }}{{ model.potential_energy }}{{ model.dissipation }}</div>
{% if model.constraints %}<h3>Constraints</h3><div class="formula">{% for c in model.constraints %}{{ c }}{% endfor %}</div>{% endif %}
<h3>Equations of motion</h3><p>{{ model.equations_note|e }}</p>
<div class="formula">{% for e in model.equations_of_motion %}{{ e }}{% endfor %}</div>
{% if model.operating_point %}{% set op = model.operating_point %}
<h3>At the operating equilibrium ({{ "stable" if op.stable else "unstable" }})</h3>
<div class="formula">{{ op.q }}{{ op.M }}{{ op.C }}{{ op.K }}</div>
<h3>Modes there</h3><table><tr><th>mode</th><th>natural frequency (Hz)</th><th>damping ratio</th><th>damped frequency (Hz)</th><th>eigenvalue (1/s)</th></tr>
{% for m in op.modes %}<tr><td>{{ loop.index }}</td><td>{{ "%.9g"|format(m.frequency_hz) }}</td><td>{{ "%.4g"|format(m.damping_ratio) }}</td><td>{{ "%.9g"|format(m.damped_frequency_hz) }}</td><td>{{ "%.6g"|format(m.eigenvalue[0]) }} {{ "%+.6g"|format(m.eigenvalue[1]) }} i</td></tr>{% endfor %}</table>
{% else %}<p>{{ model.get("operating_point_note", "")|e }}</p>{% endif %}
{% if model.get("equilibria") %}<h3>Equilibria found</h3><table><tr><th>equilibrium</th><th>stable</th><th>frequencies (Hz)</th></tr>
{% for e in model.equilibria %}<tr><td>{{ e.q }}</td><td>{{ "yes" if e.stable else "no" }}</td><td>{{ e.frequencies_hz|map("round", 6)|join(", ") }}</td></tr>{% endfor %}</table>{% endif %}{% endif %}
{% if published %}<h2>Published solutions</h2>
<p>What the problem's sources publish, against the derived reference at these parameters.
A difference within the reference's own error estimate (its change from its tolerance to a
ten times looser one) is the published value's rounding; one beyond it is flagged, with the
source's account where it gives one.</p>
<table><tr><th>quantity</th><th>t (s)</th><th>published</th><th>reference</th><th>relative difference</th><th>reference error</th><th>source</th></tr>
{% for p in published %}{% if p.get("error") %}<tr class="fail"><td colspan="7">not compared: {{ p.error|e }}</td></tr>
{% elif not p.applies %}<tr><td>{{ p.quantity|e }}</td><td>{{ p.time if p.time is not none else "" }}</td><td colspan="4">{{ p.get("note", "")|e }}</td><td>{{ p.source|e }}</td></tr>
{% else %}<tr class="{{ 'fail' if p.beyond_reference_error else 'pass' }}"><td>{{ p.quantity|e }}{% if p.get("note") %}<br><small>{{ p.note|e }}</small>{% endif %}</td><td>{{ p.time if p.time is not none else "(period)" }}</td><td>{{ "%.12g"|format(p.published_value) }}</td><td>{{ "%.12g"|format(p.reference_value) }}</td><td>{{ "%.2e"|format(p.relative_difference) }}</td><td>{{ "%.1e"|format(p.reference_error) }}</td><td>{{ p.source|e }}</td></tr>{% endif %}{% endfor %}</table>{% endif %}
{% if errata %}<h2>The printed formulas beside the derived ones</h2>
<p>Terms found on one side only are marked; printed equations of motion are first scaled to the
derived row's normalisation. A formula agrees when it matches the derivation to 1e-9 relative
at two parameter sets{% if errata_page %} (see <a href="errata.html">the errata</a>){% endif %}.</p>
<table><tr><th>formula</th><th>verdict</th><th>printed</th><th>derived</th><th>printed &#x2212; derived</th></tr>
{% for e in errata %}{% set t = e.get("mathml", {}) %}<tr class="{{ 'pass' if e.verdict == 'agrees' else 'fail' }}"><td>{{ e.label|e }}{% if e.note %}<br><small>{{ e.note|e }}</small>{% endif %}</td><td>{{ e.verdict }}</td>
<td><div class="formula">{{ t.printed if t.get("printed") else "<code>" ~ (e.printed|e) ~ "</code>" }}</div></td>
<td><div class="formula">{{ t.derived if t.get("derived") else "<code>" ~ (e.derived|e) ~ "</code>" }}</div></td>
<td><div class="formula">{{ t.get("difference", "") }}</div>{% if t.get("note") %}<small>{{ t.note|e }}</small>{% endif %}</td></tr>{% endfor %}</table>{% endif %}
{% for r in sections %}
<h2 id="{{ r.anchor }}">{{ r.row|e }}: the engines against the exact motion</h2><p>{{ r.title|e }}</p>
<table><tr><th>metric</th>{% for sim in r.sims %}<th>{{ sim }}</th>{% endfor %}</tr>
{% for name in r.metric_names %}<tr><td>{{ name|e }}</td>
{% for sim in r.sims %}{% set m = r.metrics[sim].get(name) %}{% if m %}<td class="{{ m.status }}" title="judged {{ (m.rule or 'a_priori')|replace('_', '-') }}{% if m.reason %}: {{ m.reason|e }}{% endif %}">{{ "%.2e"|format(m.value) }} / {{ "%.1e"|format(m.tolerance) }} {{ m.status }}</td>{% else %}<td class="unsupported">{{ r.unsupported.get(sim, "-")|e }}</td>{% endif %}{% endfor %}</tr>{% endfor %}</table>
{% if r.incidents %}<p class="fail">Incidents (stages that did not complete; the rest of the
run stands):</p><ul>{% for i in r.incidents %}<li><b>{{ i.simulator|e }}</b>, {{ i.scenario|e }}{% if i.stage %} ({{ i.stage|e }}){% endif %}: {{ i.outcome|e }}{% if i.get("t_reached") is not none %} at t = {{ "%.6g"|format(i.t_reached) }} s{% endif %}: {{ i.message|e }}</li>{% endfor %}</ul>{% endif %}
{% if r.deviations %}<h3>Why each engine deviates here</h3><ul>{% for sim, d in r.deviations.items() %}<li><b>{{ sim|e }}</b>: {{ d.scheme|e }}{% if d.order %} (order {{ d.order }}){% endif %} at dt = {{ "%g"|format(d.dt) }} s: its error falls as dt^{{ d.order or "?" }}{% if d.worst %}; its largest error here, {{ d.worst.metric|e }}, is {{ "%.2e"|format(d.worst.value) }} against a gate of {{ "%.2e"|format(d.worst.tolerance) }} ({{ d.worst.status }}){% endif %}{% if d.elements %}; not exact here: {% for e in d.elements %}{{ e.kind|e }} ({{ e.level }}: {{ e.how|e }}){% if not loop.last %}; {% endif %}{% endfor %}{% else %}; every element of the mechanism is built exactly{% endif %}.</li>{% endfor %}</ul>{% endif %}
{% if r.expected %}<p>Declared expected failures, each with the metrics it covers as measured in this run (value / gate, verdict, rule):</p><ul>{% for e in r.expected %}<li><b>{{ e.simulator|e }}</b>, {{ e.metric|e }} ({{ e.kind|e }}): {{ e.reason|e }}{% if e.measured %}<ul class="declared">{% for m in e.measured %}<li class="{{ m.status }}">{{ m.simulator|e }} {{ m.name|e }}: {{ "%.2e"|format(m.value) }} / {{ "%.1e"|format(m.tolerance) }} {{ m.status }} ({{ m.rule }}{{ m.limit|e }})</li>{% endfor %}</ul>{% endif %}</li>{% endfor %}</ul>{% endif %}
{% for w in r.liftoff %}<p class="xfail">Contact <b>{{ w.contact|e }}</b>, scenario {{ w.scenario|e }}: the
bilateral model pulls from t = {{ "%.3f"|format(w.t_ref) }} s (reference minimum {{ "%.3g"|format(w.min_ref) }} N);
a real unilateral contact would open there.</p>{% endfor %}
{% if r.frequencies %}<h3>Frequencies (Hz) at the operating equilibrium</h3>
<table><tr><th>mode</th><th>reference</th>{% for sim in r.sims %}<th>{{ sim }} linearization</th><th>{{ sim }} fit</th>{% endfor %}</tr>
{% for mode, f in r.frequencies.items() %}<tr><td>{{ mode|e }}</td><td>{{ "%.9f"|format(f.reference_hz) }}</td>
{% for sim in r.sims %}{% set e = f.engines.get(sim, {}) %}<td>{{ "%.9f"|format(e.get("linearization")) if e.get("linearization") is not none else "-" }}</td><td>{{ "%.9f"|format(e.get("fit")) if e.get("fit") is not none else "-" }}</td>{% endfor %}</tr>{% endfor %}</table>{% endif %}
{% if r.animation %}<h3>The motion: the exact reference (grey) and every engine</h3>
<script type="application/json" id="data-{{ r.anchor }}">{{ r.animation }}</script>
{% for sc in r.scenarios %}<div class="animation" data-source="data-{{ r.anchor }}" data-scenario="{{ sc|e }}">
<b>scenario {{ sc|e }}</b><canvas width="420" height="420"></canvas>
<button type="button">pause</button> <input type="range" min="0" value="0"> <span class="time"></span>
<div class="legend"></div></div>{% endfor %}
{% elif r.animation_error %}<p>No animation: {{ r.animation_error|e }}</p>{% endif %}
<h3>Scenarios: the coordinates and their errors against time</h3>
{% for fig in r.figures %}<img src="{{ fig|url }}" alt="{{ fig|e }}">{% endfor %}
{% endfor %}
{% if out_of_the_box %}<h2 id="out-of-the-box">Out of the box: each engine's own defaults switched back on</h2>
<p>The harness neutralises every engine default that would spoil the comparison. Here each one
(the engine's documented value: hover over its name for the citation) is switched back on
alone, then all together ("all": the engine as it comes), on every scenario and the frequency
checks (<code>mbfidelity out-of-the-box</code>; <a href="out_of_the_box.html">every mechanism</a>).
Verdict: rejected when a gate that holds with the harness's setting fails with the default (a
run that does not complete counts as rejected); "no effect" when no metric moved. Motion
change: the largest difference between the run with the default and the harness's run,
relative to the amplitude, in the scenario where it is largest against that scenario's
trajectory gate. Energy drift: the exact model's energy along the engine's run, its largest
departure relative to the largest kinetic energy, in the scenario where it is largest with the
default. Damping ratio: the error of mode 1's fitted damping ratio (what a default adds to a
conservative mechanism). Each as harness &#x2192; default.</p>
<table><tr><th>engine</th><th>default</th><th>engine value</th><th>harness value</th><th>verdict</th><th>motion change (gate, scenario)</th><th>energy drift (scenario)</th><th>damping ratio error, mode 1</th></tr>
{% for e in out_of_the_box %}{% if not e.supported %}<tr><td><a href="out_of_the_box.html#{{ e.anchor }}">{{ e.simulator }}</a></td><td colspan="7" class="unsupported">left out: {{ e.reason|e }}</td></tr>
{% elif not e.defaults %}<tr><td><a href="out_of_the_box.html#{{ e.anchor }}">{{ e.simulator }}</a></td><td colspan="7">no neutralised default declared by its backend</td></tr>
{% else %}{% for d in e.defaults %}<tr>{% if loop.first %}<td rowspan="{{ e.defaults|length }}"><a href="out_of_the_box.html#{{ e.anchor }}">{{ e.simulator }}</a>{% if e.recorded %}<br><small>recorded at {{ e.recorded|e }}</small>{% endif %}</td>{% endif %}
<td title="{{ d.note|e }}">{{ d.setting|e }}</td><td><code>{{ d.engine_value|e }}</code></td><td><code>{{ d.harness_value|e }}</code></td>
<td class="{{ d.cls }}" title="{{ d.rejected_by|e }}">{{ d.verdict }}{% for i in d.incidents %} ({{ i|e }}){% endfor %}</td>
<td>{% if d.motion.get("error") %}{{ d.motion.error|e }}{% elif d.motion.change is not none %}{{ "%.3g"|format(d.motion.change) }}{% if d.motion.gate is not none %} <small>({{ "%.2g"|format(d.motion.gate) }}, {{ d.motion.scenario|e }})</small>{% endif %}{% else %}-{% endif %}</td>
<td>{% if d.energy %}{{ "%.3g"|format(d.energy.neutralised) if d.energy.neutralised is not none else "-" }} &#x2192; {{ "%.3g"|format(d.energy.switched_on) }} <small>({{ d.energy.scenario|e }})</small>{% else %}-{% endif %}</td>
<td>{% if d.damping %}{{ "%.3g"|format(d.damping.neutralised) if d.damping.neutralised is not none else "-" }} &#x2192; {{ "%.3g"|format(d.damping.switched_on) }}{% else %}-{% endif %}</td></tr>{% endfor %}{% endif %}{% endfor %}
</table>{% endif %}
{% if convergence %}<h2>Convergence and work-precision</h2><img src="{{ convergence|url }}" alt="convergence of {{ system|e }}">{% endif %}
<script src="{{ script }}"></script>
</body></html>""")

ERRATA = ENV.from_string("""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>mbfidelity errata</title>
<style>{{ style }}body{max-width:none}</style></head><body>
<nav><a href="index.html">index</a></nav>
<h1>Errata: the monograph's printed formulas against the derivation</h1>
<p>git {{ prov.git_describe|e }} · {{ prov.date|e }} · engines: {% for sim, v in versions.items() %}{{ sim }} {{ v|e }}{% if not loop.last %}, {% endif %}{% endfor %}.
{% for verdict, n in counts.items() %}{{ n }} {{ verdict }}{% if not loop.last %}, {% endif %}{% endfor %}.</p>
<p>A formula agrees when it matches the derivation to 1e-9 relative at two parameter sets (the
defaults and a random perturbation of them), at many random states. Printed and derived forms are
expanded term by term; <span class="differs">a marked term</span> is found on one side only
(a printed equation of motion is first scaled to the derived row's normalisation, a potential is
compared up to a constant), and the last column is printed &#x2212; derived. Matrices are compared
at the default parameters, their differing entries marked. For each misprint the engines are
witnesses: they run the mechanism, and their motion (or their own linearization) is compared
with the printed and with the derived model.</p>
<p>Mechanisms: {% for s in systems %}<a href="#{{ s }}">{{ s }}</a>{% if not loop.last %} · {% endif %}{% endfor %}{% if section6 %} · <a href="#section6">§6, Rayleigh's method</a>{% endif %}</p>
{% for s, entries in systems.items() %}
<h2 id="{{ s }}">{{ s }}{% if s in pages %} <small>(<a href="{{ pages[s]|url }}">its page</a>)</small>{% endif %}</h2>
<table><tr><th>formula</th><th>verdict</th><th>relative difference</th><th>printed</th><th>derived</th><th>printed &#x2212; derived</th><th>engines (witnesses)</th></tr>
{% for e in entries %}{% set t = e.get("mathml", {}) %}<tr class="{{ 'pass' if e.verdict == 'agrees' else 'fail' }}"><td>{{ e.label|e }}{% if e.note %}<br><small>{{ e.note|e }}</small>{% endif %}</td>
<td>{{ e.verdict }}</td><td>{{ "%.2g"|format(e.max_relative_difference) if e.max_relative_difference is not none else "" }}</td>
<td><div class="formula">{{ t.printed if t.get("printed") else "<code>" ~ (e.printed|e) ~ "</code>" }}</div></td>
<td><div class="formula">{{ t.derived if t.get("derived") else "<code>" ~ (e.derived|e) ~ "</code>" }}</div></td>
<td><div class="formula">{{ t.get("difference", "") }}</div>{% if t.get("note") %}<small>{{ t.note|e }}</small>{% endif %}</td>
<td>{% for sim, w in (e.witnesses or {}).items() %}<b>{{ sim }}</b>: {{ w.verdict|e }}<br>{% endfor %}</td></tr>{% endfor %}
</table>{% endfor %}
{% if section6 %}<h2 id="section6">§6: Rayleigh's method (eq. 62-70)</h2>
<p>The printed reductions of the beam with a block at a = c l (§6.1, Fig. 17) and of the spring
with distributed mass (§6.2, Fig. 18), against their derivation identically in c: each static
shape solved from the beam's equation with pinned ends, the reduced mass the integral of
rho y<sup>2</sup>, the reduced stiffness the integral of EI y''<sup>2</sup> (a formula agrees when
printed &#x2212; derived simplifies to zero). Then each Rayleigh estimate against the exact
continuum's first frequency at the default parameters: a Rayleigh quotient is an upper bound.</p>
<table><tr><th>mechanism</th><th>formula</th><th>verdict</th><th>printed</th><th>derived</th><th>printed &#x2212; derived</th></tr>
{% for e in section6 %}{% set t = e.get("mathml", {}) %}<tr class="{{ 'pass' if e.verdict == 'agrees' else 'fail' }}"><td>{% if e.system in pages %}<a href="{{ pages[e.system]|url }}">{{ e.system }}</a>{% else %}{{ e.system }}{% endif %}</td>
<td>{{ e.label|e }}{% if e.note %}<br><small>{{ e.note|e }}</small>{% endif %}</td><td>{{ e.verdict }}</td>
<td><div class="formula">{{ t.get("printed", "") }}</div></td><td><div class="formula">{{ t.get("derived", "") }}</div></td>
<td><div class="formula">{{ t.get("difference", "") }}</div></td></tr>{% endfor %}</table>{% endif %}
</body></html>""")

SCRIPT = """// The mechanism's motion from frames embedded in the page: the exact reference and every
// engine drawn together on one canvas, advancing at 25 frames per second.
(function () {
  "use strict";
  var COLOURS = %(colours)s;
  function setup(box) {
    var data = JSON.parse(document.getElementById(box.dataset.source).textContent);
    var sc = data.scenarios[box.dataset.scenario];
    var canvas = box.querySelector("canvas"), ctx = canvas.getContext("2d");
    var slider = box.querySelector("input"), label = box.querySelector(".time");
    var button = box.querySelector("button"), legend = box.querySelector(".legend");
    var names = Object.keys(sc.traces);
    var lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
    names.forEach(function (n) {
      sc.traces[n].forEach(function (f) {
        f.forEach(function (p) {
          for (var k = 0; k < 2; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
        });
      });
    });
    var rmax = 0;
    data.items.forEach(function (item) { if (item.radius) { rmax = Math.max(rmax, item.radius); } });
    var span = (Math.max(hi[0] - lo[0], hi[1] - lo[1], 1e-9) + 2 * rmax) * 1.1;
    var mid = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2];
    var size = canvas.width, scale = size / span;
    function px(p) { return [size / 2 + (p[0] - mid[0]) * scale, size / 2 - (p[1] - mid[1]) * scale]; }
    names.forEach(function (n) {
      var s = document.createElement("span"), b = document.createElement("b");
      b.style.background = COLOURS[n] || "#888";
      s.appendChild(b);
      var end = sc.traces[n].length < sc.t.length ? " (ends at t = " + sc.t[sc.traces[n].length - 1] + " s)" : "";
      s.appendChild(document.createTextNode(n + end));
      legend.appendChild(s);
    });
    var frame = 0, playing = true;
    slider.max = sc.t.length - 1;
    function draw() {
      ctx.clearRect(0, 0, size, size);
      names.forEach(function (n) {
        var frames = sc.traces[n];
        if (!frames.length || frame >= frames.length) { return; }
        var f = frames[frame], exact = n === "exact";
        ctx.strokeStyle = ctx.fillStyle = COLOURS[n] || "#888";
        ctx.lineWidth = exact ? 7 : 2;
        data.items.forEach(function (item) {
          var pts = item.points.map(function (i) { return px(f[i]); });
          ctx.beginPath();
          if (item.kind === "joint") {
            ctx.arc(pts[0][0], pts[0][1], exact ? 5 : 3, 0, 2 * Math.PI);
            ctx.fill();
            return;
          }
          if (item.kind === "circle") {
            ctx.arc(pts[0][0], pts[0][1], item.radius * scale, 0, 2 * Math.PI);
            ctx.stroke();
            return;
          }
          ctx.moveTo(pts[0][0], pts[0][1]);
          for (var k = 1; k < pts.length; k++) { ctx.lineTo(pts[k][0], pts[k][1]); }
          if (item.kind === "polygon") { ctx.closePath(); }
          ctx.stroke();
        });
      });
      slider.value = frame;
      label.textContent = "t = " + sc.t[frame].toFixed(2) + " s";
      box.dataset.frame = frame;
    }
    slider.addEventListener("input", function () { frame = +slider.value; draw(); });
    button.addEventListener("click", function () {
      playing = !playing;
      button.textContent = playing ? "pause" : "play";
    });
    setInterval(function () {
      if (playing) { frame = (frame + 1) %% sc.t.length; draw(); }
    }, 40);
    draw();
  }
  Array.prototype.forEach.call(document.querySelectorAll(".animation"), setup);
})();
"""


def write_script(out: Path) -> str:
    """The animation's script beside the pages; its file name."""
    (out / ANIMATION_SCRIPT).write_text(SCRIPT % {"colours": json.dumps(COLOURS)})
    return ANIMATION_SCRIPT


def embedded_json(doc: dict) -> str:
    """JSON safe inside a <script> element (no "</" closes it early)."""
    return json.dumps(doc, separators=(",", ":")).replace("</", "<\\/")


def page_name(system: str) -> str:
    return f"{system}.html"


def anchor(row: str) -> str:
    return "row-" + "".join(ch if ch.isalnum() else "-" for ch in row)
