"""The page of a diff between two runs (comparisons/diff.py), rendered from the diff's
saved form (`ResultsDiff.as_dict()`): what changed per system x engine, worse gates
first."""
from __future__ import annotations

import json
from pathlib import Path

import jinja2

TEMPLATE = jinja2.Template("""<!doctype html><html><head><meta charset="utf-8">
<title>mbfidelity diff</title><style>
body{font-family:sans-serif;margin:2em;max-width:1400px}
table{border-collapse:collapse;margin-bottom:1.5em}td,th{border:1px solid #ccc;padding:3px 6px;font-size:13px}
th{background:#f0f0f0}.worse{background:#f8d0d0}.better{background:#dff5df}code{font-size:12px}
</style></head><body>
<h1>What changed between two runs</h1>
<p>old: <code>{{ d.old }}</code> ({{ d.provenance.old.git_describe }}, {{ d.provenance.old.date }})<br>
new: <code>{{ d.new }}</code> ({{ d.provenance.new.git_describe }}, {{ d.provenance.new.date }})<br>
{% if d.worse %}<b>a gate got worse</b>{% else %}no gate got worse{% endif %};
{{ d.pairs|length }} system × engine pairs changed, {{ d.unchanged|length }} unchanged
(results are deterministic: any difference is real).</p>
{% for p in pairs %}<h2 class="{{ 'worse' if p.worse else '' }}">{{ p.row }} / {{ p.simulator }}: {{ p.kind }}</h2>
<p>{% if p.versions %}engine {{ p.versions[0] }}{% if p.versions[0] != p.versions[1] %} → {{ p.versions[1] }}{% endif %}{% endif %}
{% if p.passed %}; comparison {{ 'passed' if p.passed[0] else 'failed' }} → {{ 'passed' if p.passed[1] else 'failed' }}{% endif %}</p>
{% if p.settings or p.inputs %}<table><tr><th>setting / input</th><th>old</th><th>new</th></tr>
{% for k, v in p.settings.items() %}<tr><td>setting {{ k }}</td><td><code>{{ v[0] }}</code></td><td><code>{{ v[1] }}</code></td></tr>{% endfor %}
{% for k, v in p.inputs.items() %}<tr><td>{{ k }}</td><td><code>{{ v[0] }}</code></td><td><code>{{ v[1] }}</code></td></tr>{% endfor %}
</table>{% endif %}
{% if p.metrics %}<table><tr><th>metric</th><th>change</th><th>old value</th><th>old status</th><th>new value</th><th>new status</th><th>tolerance (old → new)</th></tr>
{% for m in p.metrics %}<tr class="{{ 'worse' if m.worse else ('better' if m.kind == 'flipped' else '') }}"><td>{{ m.name }}</td><td>{{ m.kind }}</td>
<td>{{ "%.6g"|format(m.old.value) if m.old else "" }}</td><td>{{ m.old.status if m.old else "" }}</td>
<td>{{ "%.6g"|format(m.new.value) if m.new else "" }}</td><td>{{ m.new.status if m.new else "" }}</td>
<td>{{ "%.3g"|format(m.old.tolerance) if m.old else "" }} → {{ "%.3g"|format(m.new.tolerance) if m.new else "" }}</td></tr>{% endfor %}
</table>{% endif %}{% endfor %}
</body></html>""")


def write_diff_page(diff: dict, path: Path) -> Path:
    """Writes the page of `diff` (a `ResultsDiff.as_dict()`) to `path`, and the diff as
    JSON beside it (same name, .json)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    pairs = sorted(diff["pairs"], key=lambda p: not p["worse"])
    path.write_text(TEMPLATE.render(d=diff, pairs=pairs))
    path.with_suffix(".json").write_text(json.dumps(diff, indent=1, default=float))
    return path
