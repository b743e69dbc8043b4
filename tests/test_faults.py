"""Fault injection: what a user can bring (a mechanism the catalog does not resemble, an
extreme value the domains allow, a damaged or shared output folder, a killed parent) ends
in one line and exit 2 for bad input, or in an incident of the one comparison it concerns,
with everything else kept. Each case names the fault; the user modules are in
tests/faults/."""
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from typer.testing import CliRunner

from mbfidelity import api, systems
from mbfidelity.cli import app
from mbfidelity.comparisons import budget, results_folder
from mbfidelity.comparisons.isolation import isolated

FAULTS = Path(__file__).parent / "faults"
MBFIDELITY = str(Path(sys.executable).with_name("mbfidelity"))
runner = CliRunner()


def _mbfidelity(*args, env=None, timeout=300):
    return subprocess.run([MBFIDELITY, *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, env={**os.environ, **(env or {})})


def _one_line_refusal(done) -> str:
    """Exit 2, one line on stderr, no traceback anywhere: the line."""
    assert done.returncode == 2, (done.returncode, done.stdout, done.stderr)
    assert "Traceback" not in done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), done.stderr
    return lines[0]


@pytest.fixture
def user_modules(monkeypatch):
    """The fault modules join the catalog, as `--system-path` does."""
    monkeypatch.setenv(systems.SYSTEM_PATH_VARIABLE, os.pathsep.join(
        str(FAULTS / name) for name in ("blowup_force.py", "tiny_inertia.py")))
    monkeypatch.setattr(systems, "_REGISTRY", None)
    yield
    systems._REGISTRY = None


def _escape_time(k: float, a: float, x0: float) -> float:
    """Time for x'' = -k x + a x^3 (unit mass) released at rest at x0 beyond the barrier
    to reach infinity: the integral of dx / sqrt(2 (V(x0) - V(x))), V = k x^2/2 - a x^4/4,
    with x = x0 / s over s in (0, 1]; the 1/sqrt(1 - s) singularity at the release is
    quad's algebraic weight, and both ends take their limits."""
    V = lambda x: k * x**2 / 2 - a * x**4 / 4  # noqa: E731

    def f(s: float) -> float:
        if s <= 0.0:  # x -> inf: V(x0) - V(x) ~ a x^4 / 4
            return 1 / (x0 * math.sqrt(a / 2))
        if s >= 1.0:  # x -> x0: V(x0) - V(x) ~ -V'(x0) x0 (1 - s)
            return x0 / math.sqrt(2 * (a * x0**3 - k * x0) * x0)
        return (x0 / s**2) * math.sqrt((1 - s) / (2 * (V(x0) - V(x0 / s))))
    value, _ = quad(f, 0, 1, weight="alg", wvar=(0, -0.5))
    return value


def test_reference_that_cannot_be_solved_is_an_incident_with_the_time_reached(user_modules):
    """A force law that blows up: the reference stops near the analytic escape time; the
    comparison fails with that incident, and its other stages (the engine's
    linearization) are kept."""
    result = api.compare("user_blowup_force", "mujoco", timeout=None)
    assert result.verdict == "fail"
    (incident,) = [i for i in result.incidents if i["stage"] == "reference"]
    escape = _escape_time(1.0, 1e4, 0.1)
    assert 0.9 * escape < incident["t_reached"] <= escape
    assert any(m.name == "frequency.linearization_mode1" and m.status == "pass"
               for m in result.metrics)


def test_engine_linearization_that_raises_keeps_every_incident(user_modules):
    """MuJoCo refuses a body of inertia 1e-20: its build, its linearization and each fit
    are incidents of this comparison (stage named), not bad input."""
    result = api.compare("user_tiny_inertia", "mujoco", timeout=None)
    stages = {i["stage"] for i in result.incidents}
    assert {"engine run", "linearization"} <= stages
    assert result.verdict == "fail" and "mjMINVAL" in result.incidents[0]["message"]


def test_run_completes_beside_a_system_that_fails_and_the_report_shows_it(tmp_path):
    """`run` over a catalog system and a user module whose reference cannot be solved,
    the global option given after the command: every other item completes, the results
    and the report are written, the incident is on the page."""
    out = tmp_path / "run"
    done = _mbfidelity("run", "--systems", "compound_pendulum,user_blowup_force", "--sims",
                       "pymunk", "--out", out, "--system-path", FAULTS / "blowup_force.py")
    assert done.returncode == 0, done.stderr
    doc = json.loads((out / "results.json").read_text())
    verdicts = {c["system"]: c["verdict"] for c in doc["comparisons"]}
    assert verdicts == {"compound_pendulum": "pass", "user_blowup_force": "fail"}
    page = (out / "index.html").read_text()
    assert "Incidents" in page and "reference solve failed" in page


def test_convergence_item_that_fails_fails_alone(user_modules):
    from mbfidelity.comparisons.convergence import _study_item

    doc = _study_item(("user_blowup_force", "pymunk", None, 0.5, "auto"))
    assert doc["metric"]["status"] == "fail" and "reference" in doc["failure"]


@pytest.mark.parametrize("args, says", [
    (["compare", "compound_pendulum", "--sim", "mujoco", "--t-end", "inf"], "t_end"),
    (["compare", "compound_pendulum", "--sim", "mujoco", "--timeout", "0"], "timeout"),
    (["compare", "compound_pendulum", "--sim", "mujoco", "--timeout", "-1"], "timeout"),
    (["analyze", "massive_spring", "--param", "N=1e6"], "at most"),
    # ten periods of a 5e-5 Hz mode at 1 ms: beyond the step budget, refused before work
    (["compare", "mass_spring_damper", "--sim", "mujoco", "--param", "m=1e9"], "budget"),
    (["--system-path", FAULTS / "exits_on_import.py", "list"], "SystemExit"),
    (["--system-path", FAULTS / "negative_mass.py", "analyze", "user_negative_mass"],
     "mass must be >= 0"),
    (["--system-path", FAULTS / "negative_mass.py", "compare", "user_negative_mass",
      "--sim", "mujoco", "--param", "m=1", "--param", "l=-1"], "l must be > 0"),
])
def test_bad_input_is_one_line(args, says):
    assert says in _one_line_refusal(_mbfidelity(*args))


def test_output_paths_are_checked_before_work(tmp_path):
    a_file = tmp_path / "file"
    a_file.write_text("not a folder")
    assert "is a file" in _one_line_refusal(_mbfidelity(
        "export", "compound_pendulum", "--out", a_file / "model.xml"))
    assert "is a folder" in _one_line_refusal(_mbfidelity(
        "export", "compound_pendulum", "--out", tmp_path))
    for command in (["run", "--systems", "compound_pendulum"],
                    ["check", "--systems", "compound_pendulum"]):
        start = time.perf_counter()
        assert "is a file" in _one_line_refusal(_mbfidelity(*command, "--out", a_file))
        assert time.perf_counter() - start < 60  # refused before any comparison ran


def test_results_whose_metric_is_not_a_number_are_refused(tmp_path):
    doc = {"provenance": {}, "comparisons": [{
        "system": "compound_pendulum", "simulator": "mujoco", "engine_version": "x",
        "settings": {}, "parameters": {}, "dt": 1e-3, "supported": True, "reason": "",
        "wall_time_s": 0, "simulated_time_s": 0, "variant": "", "metrics": [
            {"name": "small.trajectory_max", "value": "0.1", "tolerance": 1e-3,
             "passed": True, "status": "pass", "unit": "relative"}]}]}
    bad = tmp_path / "results.json"
    bad.write_text(json.dumps(doc))
    assert "not a number" in _one_line_refusal(_mbfidelity("diff", bad, bad))


def test_unsupported_is_declared_not_a_failure():
    """Pymunk is planar: the spatial rotor is declared unsupported, exit 0, with why."""
    done = _mbfidelity("compare", "dynamic_unbalance", "--sim", "pymunk")
    assert done.returncode == 0 and "UNSUPPORTED (declared): Pymunk is a planar" in done.stdout


def test_fits_follow_t_end_and_round_off_is_not_judged():
    """A mass of 1e9 kg barely moves in 0.5 s: the fits that need ten periods are not
    measured (said so), and the trajectory's round-off is not a failure."""
    result = api.compare("mass_spring_damper", "mujoco", {"m": 1e9}, t_end=0.5, timeout=None)
    assert result.verdict == "pass"
    fit = next(m for m in result.metrics if m.name == "frequency.fit_mode1")
    assert fit.status == "unresolved" and "not measured" in fit.reason


def test_the_round_off_floor_still_rejects_a_changed_model(monkeypatch):
    """At g = 1e-9 the pendulum barely moves in 1 s and its gates would sit below
    round-off without the floor; with it the correct engine passes, and an engine whose
    model has g 1 % off (injected into the engine's build only: the reference keeps
    g = 1e-9) still fails. phi'' = -(m g l / I_O) phi = -1.5 g phi for the uniform bar, so
    the angles differ by 0.01 x 1.5 g phi0 t^2 / 2 = 3.8e-13 rad at t = 1 s, 7.5e-12 of the
    0.05 rad amplitude: 17 times the floor, 1e3 steps x 4 x 2^-53 = 4.4e-13."""
    from mbfidelity.comparisons.runner import compare
    from mbfidelity.systems import System

    args = ("compound_pendulum", "mujoco", {"g": 1e-9})
    good = compare(*args, t_end=1.0, scenarios=["small"])
    assert good.verdict == "pass"
    built = System.numeric_mechanism
    monkeypatch.setattr(System, "numeric_mechanism", lambda self, values, variant=None: built(
        self, {**values, "g": values["g"] * 1.01}, variant))
    wrong = compare(*args, t_end=1.0, scenarios=["small"])
    failed = {m.name for m in wrong.metrics if m.status == "fail"}
    assert "small.trajectory_max" in failed


def test_resume_executes_nothing_and_recomputes_what_is_damaged(tmp_path):
    out = tmp_path / "run"
    args = ["run", "--systems", "compound_pendulum", "--sims", "pymunk", "--out", str(out)]
    assert runner.invoke(app, args).exit_code == 0
    first = json.loads((out / "results.json").read_text())
    marker = tmp_path / "executed"
    # a crafted pickle in the folder: unpickling it would create the marker
    (out / "jobs" / "compound_pendulum.pickle").write_bytes(
        b"cos\nsystem\n(S'touch " + str(marker).encode() + b"'\ntR.")
    # the reused system's series damaged: it must be recomputed, not crash
    for npz in (out / "report_data").glob("*.npz"):
        npz.write_bytes(npz.read_bytes()[:100])
    res = runner.invoke(app, args + ["--resume"])
    assert res.exit_code == 0, res.output
    assert "0 of 1 systems finished" in res.output
    assert not marker.exists()
    again = json.loads((out / "results.json").read_text())
    strip = lambda d: [(c["system"], [(m["name"], m["value"]) for m in c["metrics"]])  # noqa
                       for c in d["comparisons"]]
    assert strip(again) == strip(first)
    # a damaged saved job: recomputed too
    (out / "jobs" / "compound_pendulum.json").write_text("{not json")
    res = runner.invoke(app, args + ["--resume"])
    assert res.exit_code == 0 and "0 of 1 systems finished" in res.output


def test_two_runs_into_one_folder_are_refused(tmp_path):
    out = tmp_path / "shared"
    with results_folder.exclusive(out):
        line = _one_line_refusal(_mbfidelity("run", "--systems", "compound_pendulum",
                                             "--sims", "pymunk", "--out", out))
    assert "another run is writing" in line


def _children(pid: int) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                found.append(int(entry.name))
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("command", [
    ["compare", "beam_with_block", "--sim", "pymunk"],
    ["run", "--systems", "beam_with_block,massive_spring", "--sims", "pymunk"],
])
def test_workers_die_with_their_parent(command, tmp_path):
    """SIGKILL to the command: its worker processes end with it."""
    if command[0] == "run":
        command = command + ["--out", str(tmp_path / "run")]
    parent = subprocess.Popen([MBFIDELITY, *command], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        workers = []
        while not workers and time.monotonic() < deadline and parent.poll() is None:
            time.sleep(0.2)
            workers = _children(parent.pid)
        assert workers, "no worker process appeared"
        time.sleep(1.0)
        workers = _children(parent.pid)
        parent.kill()
        parent.wait()
        deadline = time.monotonic() + 15
        while any(map(_alive, workers)) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not any(map(_alive, workers))
    finally:
        if parent.poll() is None:
            parent.kill()


def _grab(n_bytes: int) -> int:
    return int(np.ones(n_bytes // 8).sum())


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_worker_carries_the_memory_limit(monkeypatch):
    """An allocation above the worker limit is a MemoryError there, not the machine's
    memory: the limit is the caller's address space plus 512 MiB, the array 1 GiB."""
    size_kb = int(next(line for line in Path("/proc/self/status").read_text().splitlines()
                       if line.startswith("VmSize:")).split()[1])
    monkeypatch.setenv(budget.MEMORY_VARIABLE, str(size_kb * 1024 + 2**29))
    with pytest.raises(MemoryError):
        isolated(_grab, 2**30, timeout=60)
    assert isolated(_grab, 2**20, timeout=60) == 2**17
