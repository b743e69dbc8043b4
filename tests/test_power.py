"""The power study (comparisons/power.py): injected model errors reach the engine's build
only and are rejected where their closed-form effect exceeds the gates; a neutralised
engine default switched back on is rejected; the neutralised defaults are data."""
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from mbfidelity.comparisons import out_of_the_box, power
from mbfidelity.comparisons.runner import compare
from mbfidelity.simulators import all_backends, get_backend
from mbfidelity.systems import get_system


def _installed(engine: str) -> None:
    ok, why = get_backend(engine).available()
    if not ok:
        pytest.skip(why)


def test_engine_defaults_are_admitted_and_differ():
    """Every neutralised default's engine value is a value the setting admits (so the
    studies can switch it on) and is not the harness's own; its note cites where it comes
    from."""
    found = 0
    for engine, backend in all_backends().items():
        for key, setting in backend.SETTINGS.items():
            value = setting.out_of_the_box(1e-3)
            if value is None:
                continue
            found += 1
            setting.check(engine, key, value)
            assert value != setting.default, (engine, key)
            assert "default" in setting.note.lower(), (engine, key)
    assert found >= 4  # at least one per engine
    for engine in ("pybullet", "mujoco", "pymunk", "exudyn"):
        assert any(s.engine_default is not None
                   for s in get_backend(engine).SETTINGS.values()), engine


def test_mutated_parameter_per_kind():
    """The compound pendulum has a mass, an inertia about the pivot, a length that moves
    the centre of mass (L alone only draws the bar) and g, and no spring or damper."""
    system = get_system("compound_pendulum")
    values = system.parameter_values(None, scenario=system.scenarios[0])
    chosen = {k: power.mutated_parameter(system, k, values) for k in power.ERROR_KINDS}
    assert chosen == {"mass": "m", "inertia": "I_O", "length": "l", "gravity": "g",
                      "stiffness": None, "damping": None}


#: the compound pendulum's small-oscillation frequency is sqrt(m g l / I_O): a length l
#: (I_O about the pivot held) changed by eps changes it by sqrt(1 + eps) - 1
LENGTH_ERROR = 0.1


def test_length_error_reaches_the_engine_only_and_is_rejected():
    """The engine's free-vibration frequency moves by the closed form sqrt(1.1) - 1 while
    the reference keeps the true one: the fit measures that shift to within the gate that
    the unmutated engine meets (its own error), and the comparison is rejected by it."""
    _installed("mujoco")
    baseline = compare("compound_pendulum", "mujoco", scenarios=["small"])
    mutated = compare("compound_pendulum", "mujoco", scenarios=["small"],
                      engine_scale={"l": 1 + LENGTH_ERROR})
    expected = math.sqrt(1 + LENGTH_ERROR) - 1
    for name in ("frequency.fit_mode1", "frequency.linearization_mode1"):
        before = next(m for m in baseline.metrics if m.name == name)
        after = next(m for m in mutated.metrics if m.name == name)
        assert before.status == "pass"
        # the engine's own error is below the gate (baseline); the shift adds to it
        assert abs(after.value - expected) <= before.tolerance + before.value, name
        assert after.detail["reference_hz"] == before.detail["reference_hz"]
    assert not mutated.passed
    assert "frequency.fit_mode1" in power.rejecting_metrics(baseline, mutated)


def _phase_drift(w: float, eps: float, t_end: float) -> float:
    """max over [0, t_end] of |cos(w' t) - cos(w t)|, w' = w sqrt(1 + eps): the linear
    trajectory change of a release from rest, relative to its amplitude."""
    t = np.linspace(0.0, t_end, 200001)
    return float(np.max(np.abs(np.cos(w * math.sqrt(1 + eps) * t) - np.cos(w * t))))


def test_smallest_rejected_length_error_matches_the_gates():
    """PyBullet (first order) on the compound pendulum's small release (near-linear: the
    closed form cos(w t) holds to the amplitude squared, which the true and the mutated
    runs share): the smallest rejected eps of a length error lies between the first decade
    at which the closed-form effect may exceed a gate (the linear phase drift against the
    trajectory gate, the frequency shift sqrt(1 + eps) - 1 against each frequency gate,
    the engine's own error, the baseline's value, taken as adding) and the first at which
    it must (that error taken as subtracting)."""
    _installed("pybullet")
    system = get_system("compound_pendulum")
    entry = out_of_the_box.power_entry("compound_pendulum", "pybullet", kinds=("length",),
                              defaults=False)
    found = entry.errors[0]
    assert found.parameter == "l" and found.smallest_rejected is not None
    baseline = compare("compound_pendulum", "pybullet", scenarios=["small"])
    trajectory = next(m for m in baseline.metrics if m.name == "small.trajectory_max")
    frequency = [m for m in baseline.metrics if m.name.startswith("frequency.")]
    assert trajectory.status == "pass" and frequency
    values = system.parameter_values(None, scenario=system.scenarios[0])
    w = math.sqrt(values["m"] * values["g"] * values["l"] / values["I_O"])
    t_end = system.scenarios[0].t_end

    def exceeds(eps: float, sign: float) -> bool:
        shift = math.sqrt(1 + eps) - 1
        return (_phase_drift(w, eps, t_end) + sign * trajectory.value > trajectory.tolerance
                or any(shift + sign * m.value > m.tolerance for m in frequency))

    may = min(e for e in power.EPSILONS if exceeds(e, +1.0))
    must = min(e for e in power.EPSILONS if exceeds(e, -1.0))
    assert may <= found.smallest_rejected <= must, (may, found.smallest_rejected, must)


def test_pybullet_default_damping_is_rejected_on_a_pendulum():
    """PyBullet's link damping 0.04 (its out-of-the-box value), switched back on, drains
    the compound pendulum's energy: a gate that holds without it fails with it."""
    _installed("pybullet")
    backend = get_backend("pybullet")
    on = {k: backend.SETTINGS[k].out_of_the_box(1e-3)
          for k in ("linear_damping", "angular_damping")}
    assert on == {"linear_damping": 0.04, "angular_damping": 0.04}
    baseline = compare("compound_pendulum", "pybullet", scenarios=["small"])
    damped = compare("compound_pendulum", "pybullet", scenarios=["small"], settings=on)
    rejected_by = power.rejecting_metrics(baseline, damped)
    assert rejected_by
    assert any(name.startswith("damping.") or name.endswith(".energy_drift")
               for name in rejected_by), rejected_by


def test_power_command_writes_both_documents_and_pages(tmp_path):
    """`mbfidelity power --json --out DIR`: the smallest rejected eps per injected error
    (on the grid, or None), the kinds without a parameter marked not applicable, each
    neutralised default with its verdict, and both pages rendered from the saved JSON.
    Pymunk (two neutralised defaults) keeps it short."""
    import json

    from typer.testing import CliRunner

    from mbfidelity.cli import app

    _installed("pymunk")
    res = CliRunner().invoke(app, ["power", "--systems", "compound_pendulum", "--sims",
                                   "pymunk", "--json", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    (entry,) = doc["entries"]
    kinds = {p["kind"]: p for p in entry["errors"]}
    assert set(kinds) == set(power.ERROR_KINDS)
    assert not kinds["stiffness"]["applicable"] and not kinds["damping"]["applicable"]
    for kind in ("mass", "inertia", "length", "gravity"):
        assert kinds[kind]["smallest_rejected"] in power.EPSILONS
        # a 1 % error of any of them moves the pendulum beyond its gates
        assert kinds[kind]["motion_change"]["beyond_gate"]
    for kind in ("mass", "inertia", "length", "gravity"):
        assert kinds[kind]["verdict"] == power.REJECTED, kinds[kind]
        assert kinds[kind]["monotone"]
    defaults = {d["setting"]: d for d in entry["defaults"]}
    assert set(defaults) == {"error_bias", "iterations", "all"}
    # a single pin joint leaves the solver's iterations nothing to resolve: the change of
    # every judged quantity is within its gate (rounding), so it acts on nothing
    assert defaults["iterations"]["verdict"] in (power.BELOW_GATES, power.NO_EFFECT)
    assert not defaults["iterations"]["acts"]
    assert doc["summary"]["pymunk"]["defaults"]["not_rejected"] == []
    # Pymunk's error bias drains the 2 rad swing (invisible on the small one)
    assert defaults["error_bias"]["rejected"]
    assert any(name.startswith("large.") for name in defaults["error_bias"]["rejected_by"])
    assert json.loads((tmp_path / "power.json").read_text())["summary"] == doc["summary"]
    box = json.loads((tmp_path / "out_of_the_box.json").read_text())
    assert box["entries"][0]["defaults"][0]["setting"] == "error_bias"
    for page in ("power.html", "out_of_the_box.html"):
        assert "compound_pendulum" in (tmp_path / page).read_text()


def test_mujoco_euler_is_rejected_at_the_harness_gates():
    """MuJoCo's default integrator, Euler (semi-implicit: the velocity first), switched
    back on: on a harmonic swing from rest the conserved modified energy is
    E - (h w^2 / 2) q v, so the energy departs from its start by up to h w / 2 of the
    largest kinetic energy (|q v| <= A^2 w / 2), within (w h + A^2) of itself (the next
    order and the pendulum's anharmonicity). Its own verdict judges it against the bound of
    a first-order scheme, which it meets; the power study holds the gates at the
    harness's RK4 run, which is wrong by orders less, and rejects it there."""
    _installed("mujoco")
    assert power.engine_defaults("mujoco")["integrator"] == "Euler"
    system = get_system("compound_pendulum")
    values = system.parameter_values(None, scenario=system.scenarios[0])
    w, h, A = math.sqrt(values["m"] * values["g"] * values["l"] / values["I_O"]), 1e-3, 0.05
    assert values["phi0"] == A
    baseline = compare("compound_pendulum", "mujoco", scenarios=["small"])
    euler = compare("compound_pendulum", "mujoco", scenarios=["small"],
                    settings={"integrator": "Euler"})
    assert baseline.passed
    drift = power.metric_named(euler, "small.energy_drift")
    neutral = power.metric_named(baseline, "small.energy_drift")
    assert abs(drift.value - w * h / 2) <= w * h / 2 * (w * h + A**2) + neutral.value
    assert drift.status == "pass" and euler.passed  # its own, first-order, gate
    assert drift.value > neutral.tolerance  # the harness's gate
    rejected_by = power.rejecting_metrics(baseline, euler)
    assert {"small.energy_drift", "small.trajectory_max"} <= set(rejected_by)
    assert power.rejecting_metrics(baseline, baseline) == []


def test_a_declared_failure_rejects_what_moves_beyond_the_engines_own_error():
    """MuJoCo fails the slotted link's trajectory gates by declaration (the massless pin
    carries a substitute mass on soft equalities), so they cannot judge a default by the
    gate alone. MuJoCo's default diagexact (False) moves the undamped run by far more than
    the gate; the trajectory metric rejects it because its value exceeds the neutralised
    run's by more than the tolerance, which by the triangle inequality bounds the change
    of the motion itself from below."""
    _installed("mujoco")
    system, scenario = "slotted_link_spring_damper", "undamped"
    off = compare(system, "mujoco", scenarios=[scenario], keep_series=True)
    on = compare(system, "mujoco", scenarios=[scenario], keep_series=True,
                 settings={"diagexact": power.engine_defaults("mujoco")["diagexact"]})
    name = f"{scenario}.trajectory_max"
    before, after = power.metric_named(off, name), power.metric_named(on, name)
    assert before.status == "xfail"
    values = get_system(system).parameter_values()
    free = power.free_coordinates(get_system(system), values)
    q_off, q_on = (np.asarray(c.series[scenario]["q"], dtype=float) for c in (off, on))
    scale = np.asarray(off.series[scenario]["scale"], dtype=float)
    n = min(len(q_off), len(q_on))
    change = float(np.max(np.abs(q_on[:n, free] - q_off[:n, free]) / scale[free]))
    assert change >= after.value - before.value - 1e-12  # the triangle inequality
    assert after.value > before.value + before.tolerance
    assert name + power.BEYOND_BASELINE in power.rejecting_metrics(off, on)
    assert power.rejecting_metrics(off, off) == []


def test_an_error_the_motion_does_not_depend_on_is_below_the_gates():
    """The mass-spring-damper slides on a horizontal guide: g is normal to its only
    coordinate, so an error of g changes no judged quantity of the exact model (trajectory
    and frequency change by exactly 0). The study classifies it below the gates with that
    reason, not as a blind gate, after the single run the grid's top needs (a gate that
    rejected an error the motion does not see would be a false alarm)."""
    _installed("mujoco")
    entry = out_of_the_box.power_entry("mass_spring_damper", "mujoco", kinds=("gravity",),
                              defaults=False)
    (found,) = entry.errors
    assert found.parameter == "g" and found.smallest_rejected is None
    assert [t.eps for t in found.trials] == [power.EPSILONS[-1]]
    changes = found.motion_change["against_gates"]
    assert "trajectory" in changes and any(k.startswith("frequency mode") for k in changes)
    assert all(v["change"] == 0.0 for v in changes.values())
    assert found.verdict == power.BELOW_GATES and "do not depend on g" in found.why


def _reading(neutralised: float, incidents: list, change: dict) -> power.DefaultPower:
    return power.DefaultPower(
        "a_default", 1.0, 0.0, rejected=False, moved=True, change=change,
        effect={"s.trajectory_max": {"neutralised": neutralised, "switched_on": 0.5,
                                     "tolerance": 1e-3, "unit": "relative",
                                     "status": "xfail"}},
        incidents=incidents)


def test_a_default_on_a_run_the_engine_fails_without_it_is_told_apart_from_a_blind_gate():
    """The verdict rule of a default (`classify_default`): a crash the neutralised run has
    too does not make the default act; a motion the engine does not produce without it
    (its trajectory metric not finite there) is "on a failed run", not a blind gate; the
    same change of a finite motion away from the reference is "not rejected"."""
    from mbfidelity.comparisons.runner import Comparison

    crash = {"scenario": "s", "stage": "engine run", "outcome": "crashed", "message": "x"}
    baseline = Comparison("sys", "engine", "", {}, {}, 1e-3)
    baseline.incidents.append(dict(crash))
    within = {"quantity": "s.motion", "change": 1e-6, "gate": 1e-3, "ratio": 1e-3}
    shared = _reading(0.1, [dict(crash)], within)
    power.classify_default(shared, baseline)
    assert not shared.acts and shared.verdict == power.BELOW_GATES
    new = _reading(0.1, [dict(crash, scenario="t")], within)
    power.classify_default(new, baseline)
    assert new.acts  # a crash of its own
    beyond = {"quantity": "s.motion", "change": math.inf, "gate": 1e-3, "ratio": math.inf}
    failed = _reading(math.inf, [], beyond)
    power.classify_default(failed, baseline)
    assert failed.verdict == power.ON_FAILED_RUN
    finite = _reading(0.1, [], beyond)
    power.classify_default(finite, baseline)
    assert finite.verdict == power.NOT_REJECTED
    # no metric moved: whatever the motion change says, the default acts on nothing
    still = _reading(0.1, [], beyond)
    still.moved = False
    power.classify_default(still, baseline)
    assert not still.acts and still.verdict == power.NO_EFFECT


def test_a_motion_not_finite_in_both_runs_is_no_change():
    """`_motion_change`: the largest |q_on - q_off| over the amplitude, where a sample
    not finite in one run only is an infinite change and one not finite in both runs (the
    engine's run fails there with or without the default) is none."""
    from types import SimpleNamespace

    nan = float("nan")
    off = np.array([[0.0, 5.0], [0.1, 5.0], [nan, 5.0], [nan, 5.0]])
    scale = np.array([0.5, 1.0])
    neutral = {"s": (off, scale)}
    same_failure = off.copy()
    same_failure[1, 0] = 0.2  # 0.1 away, at amplitude 0.5
    on = SimpleNamespace(series={"s": {"q": same_failure}})
    change = out_of_the_box._motion_change(neutral, on, [0])["s"]["trajectory_change"]
    assert change == pytest.approx(0.2)
    its_own = off.copy()
    its_own[2, 0] = 0.3  # finite where the neutralised run is not
    on = SimpleNamespace(series={"s": {"q": its_own}})
    assert out_of_the_box._motion_change(neutral, on, [0])["s"]["trajectory_change"] == math.inf
    on = SimpleNamespace(series={"s": {"q": off.copy()}})  # the same failing run
    assert out_of_the_box._motion_change(neutral, on, [0, 1])["s"]["trajectory_change"] == 0.0


def test_a_reading_is_kept_by_its_content_and_made_again_for_another_engine_version(
        tmp_path, monkeypatch):
    """`cached_entry`: the second call takes the reading from the persistent cache, equal
    to the one made but for the mark; another engine version is another key, so an
    upgraded engine's readings are made again."""
    from mbfidelity.comparisons import out_of_the_box

    _installed("pymunk")
    monkeypatch.setenv("MBFIDELITY_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("MBFIDELITY_NO_CACHE", raising=False)
    args = ("compound_pendulum", "pymunk", 1e-3, (), ("mass",))
    made = out_of_the_box.cached_entry(*args)
    assert not made.from_cache and made.errors[0].trials
    kept = out_of_the_box.cached_entry(*args)
    assert kept.from_cache
    assert {**kept.as_dict(), "from_cache": False} == made.as_dict()
    key = out_of_the_box._entry_key(*args)
    monkeypatch.setattr(get_backend("pymunk"), "version", lambda: "another version")
    assert out_of_the_box._entry_key(*args) != key


def test_each_modes_change_is_set_against_the_gate_of_that_mode():
    """The belt and pulleys on Pymunk: the free-vibration fit judges the second mode only
    (the first is not fitted), so a 1 % error of the pulley's inertia, which moves the
    first mode's frequency, is set against the gates that judge what it moves (the
    trajectory, the second mode), not against the second mode's gate for the first mode's
    change (which made it a blind gate)."""
    _installed("pymunk")
    entry = out_of_the_box.power_entry("belt_pulleys", "pymunk", kinds=("inertia",), defaults=False)
    (found,) = entry.errors
    judged = found.motion_change["against_gates"]
    for quantity, gate in judged.items():
        if quantity.startswith("frequency mode"):
            assert gate["metric"].endswith("_mode" + quantity.split()[-1])
    assert "frequency mode 1" not in judged
    assert found.verdict != power.NOT_REJECTED, found.why


@given(threshold=st.integers(0, len(power.EPSILONS)),
       start=st.integers(0, len(power.EPSILONS) - 1))
def test_search_from_the_predicted_decade_finds_the_first_rejected(threshold, start):
    """Whatever decade the prediction names, the search returns the first rejected one of
    a monotone rejection (len: none), in at most five runs (the plain bisection's bound on
    six decades), and in at most two where the prediction is right or one decade low."""
    calls = []

    def rejects(i: int) -> bool:
        calls.append(i)
        return i >= threshold

    assert power.first_rejected(rejects, start) == threshold
    assert len(calls) == len(set(calls)) and len(calls) <= 5
    if start in (threshold, threshold - 1):
        assert len(calls) <= 2


def _record(tmp_path, study, describe: str, kinds):
    """A recorded study as `mbfidelity power --out` saves it (its power.json), gzipped."""
    import gzip
    import json

    doc = power.power_document([e.as_dict() for e in study.entries],
                               {**study.provenance, "git_describe": describe})
    doc["error_kinds"] = {k: list(power.ERROR_KINDS[k]) for k in kinds}
    path = tmp_path / "power.json.gz"
    path.write_bytes(gzip.compress(json.dumps(doc).encode()))
    return path


def test_a_recorded_study_lends_the_readings_of_the_installed_engines_only(
        tmp_path, monkeypatch):
    """`out_of_the_box_study(record=)`: a reading the record made with the installed
    engine's version at the same step is taken from it as it was made (marked with the
    state of the package that made it, no comparison counted); with another engine
    version, at another step, or in a layout this version does not read, the study makes
    it. The pages say where a reading came from."""
    import json

    from mbfidelity.reports.html import _out_of_the_box_rows
    from mbfidelity.reports.power_page import POWER, write_power_pages

    _installed("pymunk")
    monkeypatch.setenv("MBFIDELITY_NO_CACHE", "1")
    kinds = ("mass",)
    made = out_of_the_box.out_of_the_box_study(["compound_pendulum"], ["pymunk"],
                                               kinds=kinds)
    record = out_of_the_box.read_record(_record(tmp_path, made, "v0-recorded", kinds))

    measured = []  # what the study asks to be made (a stand-in reading: the real one is above)
    monkeypatch.setattr(out_of_the_box, "defaults_entry", lambda system_id, sim, dt, *a, **k: (
        measured.append(sim) or power.PowerEntry(system_id, sim, dt=dt, comparisons=1)))
    lent = out_of_the_box.out_of_the_box_study(["compound_pendulum"], ["pymunk"],
                                               kinds=kinds, record=record)
    assert measured == []
    (entry,) = lent.entries
    assert entry.recorded == "v0-recorded"
    assert {**entry.as_dict(), "recorded": ""} == made.entries[0].as_dict()
    assert lent.cost()["comparisons"] == 0 and lent.cost()["recorded_entries"] == 1
    assert lent.provenance["record"]["git_describe"] == "v0-recorded"
    (tmp_path / POWER).write_text(json.dumps(lent.power_document()))
    (tmp_path / "out_of_the_box.json").write_text(json.dumps(lent.as_dict()))
    for page in write_power_pages(tmp_path):
        assert "recorded at v0-recorded" in page.read_text()
    (row,) = _out_of_the_box_rows(tmp_path)["compound_pendulum"]  # the mechanism page's
    assert row["recorded"] == "v0-recorded"

    # a reading of a layout this version does not read: made by the study
    later = {**record, "entries": [{**e, "a_later_field": 1} for e in record["entries"]]}
    again = out_of_the_box.out_of_the_box_study(["compound_pendulum"], ["pymunk"],
                                                kinds=kinds, record=later)
    assert len(measured) == 1 and not again.entries[0].recorded
    # another step: made by the study
    again = out_of_the_box.out_of_the_box_study(["compound_pendulum"], ["pymunk"],
                                                dt=made.entries[0].dt / 2, kinds=kinds,
                                                record=record)
    assert len(measured) == 2 and not again.entries[0].recorded
    # another version of the engine: made by the study
    monkeypatch.setattr(get_backend("pymunk"), "version", lambda: "another version")
    again = out_of_the_box.out_of_the_box_study(["compound_pendulum"], ["pymunk"],
                                                kinds=kinds, record=record)
    assert len(measured) == 3 and not again.entries[0].recorded
    assert again.cost()["comparisons"] > 0 and again.cost()["recorded_entries"] == 0


def test_a_record_that_is_not_a_power_study_is_refused(tmp_path):
    """`read_record` and `recorded_readings` refuse a missing file, a file that is not
    JSON, a JSON document that is not a power study, and a study of other error kinds;
    the command says why and stops."""
    import json

    from typer.testing import CliRunner

    from mbfidelity.cli import app

    with pytest.raises(ValueError, match="no recorded power study"):
        out_of_the_box.read_record(tmp_path / "missing.json")
    (tmp_path / "bad.json").write_text("not json")
    with pytest.raises(ValueError, match="is not a recorded power study"):
        out_of_the_box.read_record(tmp_path / "bad.json")
    (tmp_path / "other.json").write_text(json.dumps({"entries": []}))
    with pytest.raises(ValueError, match="no provenance, error_kinds"):
        out_of_the_box.read_record(tmp_path / "other.json")
    doc = {"provenance": {}, "error_kinds": {"mass": ["kg"]}, "entries": []}
    with pytest.raises(ValueError, match="injected mass"):
        out_of_the_box.recorded_readings(doc, tuple(power.ERROR_KINDS))
    res = CliRunner().invoke(app, ["power", "--systems", "compound_pendulum", "--record",
                                   str(tmp_path / "missing.json")])
    assert res.exit_code != 0 and "no recorded power study" in res.output


def test_the_committed_record_reads_back_as_power_entries():
    """benchmarks/records/power_study.json.gz (what `make report` lends readings from):
    a power study of every error kind whose every entry this version reads back
    (`PowerEntry.from_dict` refuses a field it does not know), each made at its system's
    own step."""
    from pathlib import Path

    from mbfidelity.comparisons.runner import own_step

    path = Path(__file__).resolve().parent.parent / "benchmarks/records/power_study.json.gz"
    doc = out_of_the_box.read_record(path)
    readings = out_of_the_box.recorded_readings(doc, tuple(power.ERROR_KINDS))
    assert readings
    for (system, sim), reading in readings.items():
        entry = power.PowerEntry.from_dict(reading)
        assert entry.recorded and (entry.system, entry.simulator) == (system, sim)
        assert entry.dt == own_step(system, None)
