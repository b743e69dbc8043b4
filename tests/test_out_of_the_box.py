"""The out-of-the-box study (comparisons/out_of_the_box.py): PyBullet's documented link
damping, switched back on alone, drains the compound pendulum as Bullet's own damping law
says, and the mechanism's page shows the reading.

Bullet's multibody (btMultiBody::computeAccelerationsArticulatedBodyAlgorithmMultiDof in
the engine's source) applies on every link, in its centre-of-mass frame, the force
-m v (k + k |v|) and the moment -I_c w (k + k |w|), k being the link's linear or angular
damping (PyBullet's changeDynamics, 0.04 by default). On the compound pendulum (Fig. 7: a
bar of mass m pinned at O, centre of mass at l from O, I_O about O, I_c = I_O - m l^2 about
its centre) swinging as phi = A cos(w0 t), w0^2 = m g l / I_O, the cycle average (k << w0;
<sin^2> = 1/2, <|sin|^3> = 4 / 3 pi) of the power the law takes gives

    d(A^2)/dt = -k a A^2 (1 + b A),
    linear damping:  a = m l^2 / I_O, b = (8 / 3 pi) w0 l   (the centre's speed is l phi')
    angular damping: a = I_c / I_O,   b = (8 / 3 pi) w0,

solved by A(t) = A0 e^(-k a t / 2) / (1 + b A0 (1 - e^(-k a t / 2))). A release from rest
at A0 has lost 1 - (A(T) / A0)^2 of its energy by T, relative to its largest kinetic energy:
the energy drift the comparison measures. The frequency check's free vibration (released
at tolerances.FIT_AMPLITUDE rad) decays with the damping ratio zeta = k a / (2 w0), the
b A term adding at most zeta b FIT_AMPLITUDE.
"""
import json
import math
import re

import pytest

from mbfidelity import api
from mbfidelity.comparisons.out_of_the_box import engine_defaults
from mbfidelity.comparisons.tolerances import FIT_AMPLITUDE
from mbfidelity.simulators import all_backends, get_backend
from mbfidelity.systems import get_system

SYSTEM, ENGINE = "compound_pendulum", "pybullet"
DAMPING = ("linear_damping", "angular_damping")


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """A site of the pendulum on PyBullet, with the reading of its two link dampings."""
    ok, why = get_backend(ENGINE).available()
    if not ok:
        pytest.skip(why)
    out = tmp_path_factory.mktemp("box")
    api.run([SYSTEM], [ENGINE], out)
    study = api.out_of_the_box([SYSTEM], [ENGINE], out, defaults=DAMPING)
    (entry,) = study.entries
    return out, {d.setting: d for d in entry.defaults}


def _law(setting: str) -> tuple[float, float, float, float]:
    """(k, a, b, w0) of the damping law above for `setting`."""
    values = get_system(SYSTEM).parameter_values()
    m, l, I_O, g = (values[k] for k in ("m", "l", "I_O", "g"))
    w0 = math.sqrt(m * g * l / I_O)
    k = get_backend(ENGINE).SETTINGS[setting].out_of_the_box(1e-3)
    if setting == "linear_damping":
        return k, m * l**2 / I_O, 8 / (3 * math.pi) * w0 * l, w0
    return k, (I_O - m * l**2) / I_O, 8 / (3 * math.pi) * w0, w0


@pytest.mark.parametrize("setting", DAMPING)
def test_link_damping_drains_the_energy_as_bullets_law_says(site, setting):
    """On the small release (0.05 rad, 10 s): the energy drift with the default is the
    closed form's loss, within the engine's own drift (the neutralised run's, which may
    add to it), the loss's ripple within a cycle (it goes as sin^2: the energy departs
    from its cycle average by up to k a / 2 w0 of itself) and the harmonic swing's error
    (A0^2 relative); the fitted damping ratio is zeta within zeta b FIT_AMPLITUDE (the
    amplitude term), zeta^2 (the cycle average) and the neutralised fit's own error. Both
    exceed the gates, which reject the default. Without Bullet's quadratic term (b = 0)
    the loss would be 1.6e-2 (linear) and 1.4e-2 (angular) lower: beyond each bound."""
    _, found = site
    d = found[setting]
    k, a, b, w0 = _law(setting)
    scenario = next(sc for sc in get_system(SYSTEM).scenarios if sc.name == "small")
    A0, T = scenario.overrides["phi0"], scenario.t_end
    decay = math.exp(-k * a * T / 2)
    expected = 1 - (decay / (1 + b * A0 * (1 - decay))) ** 2
    drift = d.motion["scenarios"]["small"]
    bound = drift["energy_drift_neutralised"] + k * a / (2 * w0) + A0**2 * expected
    assert abs(drift["energy_drift_switched_on"] - expected) <= bound, (expected, drift)
    assert abs(drift["energy_drift_switched_on"] - (1 - decay**2)) > bound  # b matters

    zeta = k * a / (2 * w0)
    damping = d.effect["damping.fit_mode1"]
    assert abs(damping["switched_on"] - zeta) <= (
        zeta * b * FIT_AMPLITUDE + zeta**2 + damping["neutralised"]), (zeta, damping)
    assert d.rejected
    assert {"small.energy_drift", "damping.fit_mode1"} <= set(d.rejected_by)


def test_the_pages_show_the_reading(site):
    """The mechanism's page has its out-of-the-box row (PyBullet, each damping: rejected,
    the energy drift harness -> default as saved), the index and the mechanism's page
    link the study's page, and that page links back to the mechanism."""
    out, _ = site
    saved = json.loads((out / "out_of_the_box.json").read_text())
    (entry,) = saved["entries"]
    page = (out / f"{SYSTEM}.html").read_text()
    section = page[page.index('id="out-of-the-box"'):]
    section = section[:section.index("</table>")]
    for d in entry["defaults"]:
        row = section[section.index(f">{d['setting']}</td>"):]
        row = row[:row.index("</tr>")]
        assert ">rejected<" in row
        drifts = max((m for m in d["motion"]["scenarios"].values()),
                     key=lambda m: m["energy_drift_switched_on"])
        assert (f"{drifts['energy_drift_neutralised']:.3g} &#x2192; "
                f"{drifts['energy_drift_switched_on']:.3g}") in row
    assert f'href="out_of_the_box.html#{SYSTEM}-{ENGINE}"' in section
    assert 'href="out_of_the_box.html"' in (out / "index.html").read_text()
    assert f'href="{SYSTEM}.html"' in (out / "out_of_the_box.html").read_text()


def test_every_neutralised_default_is_cited():
    """What the study switches on is each engine's documented value: the note of every
    setting with an engine default names where it is documented ("Engine default", then
    the source)."""
    cited = 0
    for engine, backend in all_backends().items():
        for key in engine_defaults(engine):
            assert re.search(r"Engine default[^:]*: \S", backend.SETTINGS[key].note), \
                (engine, key)
            cited += 1
    assert cited >= 4


def test_a_default_the_step_cannot_hold_is_recorded_as_refused():
    """MuJoCo's default integrator, semi-implicit Euler, is stable for w h < 2 only; the
    harness's RK4 up to w h = 2.78. On the mass-spring-damper (Fig. 1: w = sqrt(k / m),
    the modulus of its eigenvalues) at w h = 2.4 the neutralised run goes, and the harness
    refuses the Euler run before it starts (`runner.UnstableStep`): the study records the
    refusal as that default's run (rejected, with the incident) instead of raising out of
    the system's whole job."""
    from mbfidelity.comparisons import out_of_the_box

    ok, why = get_backend("mujoco").available()
    if not ok:
        pytest.skip(why)
    system = get_system("mass_spring_damper")
    v = system.parameter_values(None, scenario=system.scenarios[0])
    w = math.sqrt(v["k"] / v["m"])
    entry = out_of_the_box.defaults_entry("mass_spring_damper", "mujoco", 2.4 / w,
                                          only=["integrator"])
    (d,) = entry.defaults
    assert entry.supported and d.setting == "integrator" and d.engine_value == "Euler"
    assert d.rejected and d.verdict == "rejected"
    (incident,) = d.incidents
    assert incident["outcome"] == "refused"
    assert "cannot be stable" in incident["message"] and "w h = 2.4" in incident["message"]


def test_one_engine_that_fails_leaves_the_systems_other_engines_measured(monkeypatch):
    """A reading that raises (here an injected error on PyBullet's) becomes that engine's
    entry, not measured and saying why; the system's other engines are measured."""
    from mbfidelity.comparisons import out_of_the_box
    from mbfidelity.comparisons.power import PowerEntry

    def reading(system_id, simulator, dt, only, kinds):
        if simulator == "pybullet":
            raise RuntimeError("injected failure")
        return PowerEntry(system_id, simulator, dt=dt)

    monkeypatch.setattr(out_of_the_box, "cached_entry", reading)
    entries, _ = out_of_the_box._system_job("mass_spring_damper",
                                            ["mujoco", "pybullet", "pymunk"], None, None)
    assert [e.simulator for e in entries] == ["mujoco", "pybullet", "pymunk"]
    assert [e.supported for e in entries] == [True, False, True]
    assert entries[1].reason == "not measured: RuntimeError: injected failure"


def test_a_row_whose_neutralised_run_has_no_energy_drift_renders(tmp_path):
    """A scenario where the neutralised run measured no energy drift and the default's run
    did (IFToMM A02 on Exudyn, its published scenario): the mechanism page's row shows
    "-" for the missing value beside the measured one."""
    from mbfidelity.reports import site
    from mbfidelity.reports.html import _out_of_the_box_rows

    default = {"setting": "a_default", "engine_value": 1.0, "harness_value": 0.0,
               "acts": True, "moved": True, "verdict": "below the gates", "why": "",
               "rejected": False, "rejected_by": [], "effect": {}, "incidents": [],
               "motion": {"scenarios": {"published": {"energy_drift_neutralised": None,
                                                      "energy_drift_switched_on": 2e-6}}}}
    doc = {"provenance": {}, "entries": [
        {"system": "s", "simulator": "exudyn", "supported": True, "reason": "",
         "defaults": [default]}]}
    (tmp_path / "out_of_the_box.json").write_text(json.dumps(doc))
    rows = _out_of_the_box_rows(tmp_path)["s"]
    page = site.MECHANISM.render(
        style="", title="t", source="", drawing="", script="", convergence="", errata=[],
        published=[], errata_page=False, system="s", sections=[], model={},
        out_of_the_box=rows)
    assert "- &#x2192; 2e-06 <small>(published)</small>" in page
