"""The gates in a user's hands (issue 14): `check` against the installed engines and a
baseline, `diff` between two runs, a user's own mechanism module through the commands."""
import json
import os
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from mbfidelity import systems
from mbfidelity.cli import app

pytest_plugins = ["pytester"]
runner = CliRunner()
EXAMPLE = Path(__file__).parents[1] / "examples" / "cart_pendulum.py"


@pytest.fixture(autouse=True)
def _catalog_restored():
    """`--system-path` adds to the process's catalog (through the environment, for the
    workers): the next tests see the catalog alone again."""
    before = os.environ.get(systems.SYSTEM_PATH_VARIABLE)
    yield
    if before is None:
        os.environ.pop(systems.SYSTEM_PATH_VARIABLE, None)
    else:
        os.environ[systems.SYSTEM_PATH_VARIABLE] = before
    systems._REGISTRY = None


def _check(*args):
    return runner.invoke(app, ["check", "--systems", "compound_pendulum", "--sims", "mujoco",
                               "--json", *args])


def test_a_changed_setting_is_named_by_check_against_its_baseline(tmp_path):
    first = _check("--out", str(tmp_path / "base"))
    assert first.exit_code == 0, first.output
    (verdict,) = json.loads(first.output)["verdicts"]
    assert (verdict["system"], verdict["verdict"], verdict["failing"]) == (
        "compound_pendulum", "pass", [])
    # MuJoCo's semi-implicit Euler instead of RK4: still within its own (first-order)
    # gates, so the check passes, but every trajectory metric moves
    second = _check("--out", str(tmp_path / "euler"), "--setting", 'mujoco.integrator="Euler"',
                    "--baseline", str(tmp_path / "base"))
    assert second.exit_code == 0, second.output
    diff = json.loads(second.output)["diff"]
    (pair,) = diff["pairs"]
    assert pair["settings"] == {"integrator": ["RK4", "Euler"]}
    moved = {m["name"] for m in pair["metrics"] if m["kind"] == "moved"}
    assert {"small.trajectory_max", "large.trajectory_max"} <= moved
    assert not diff["worse"]

    # the same run again: deterministic, so nothing moved at all
    again = runner.invoke(app, ["diff", str(tmp_path / "euler"), str(tmp_path / "euler"),
                                "--json"])
    assert again.exit_code == 0
    assert json.loads(again.output)["pairs"] == []


def test_diff_exits_1_when_a_gate_got_worse_and_writes_its_page(tmp_path):
    base = tmp_path / "base"
    assert _check("--out", str(base)).exit_code == 0
    # a recorded baseline (a results.json under another name) in which one gate failed
    # earlier, and a new run where another fails: one flip is better, one worse
    doc = json.loads((base / "results.json").read_text())
    metrics = doc["comparisons"][0]["metrics"]
    metrics[0].update(status="fail", passed=False)
    recorded = tmp_path / "recorded_baseline.json"
    recorded.write_text(json.dumps(doc))
    worse = json.loads((base / "results.json").read_text())
    worse["comparisons"][0]["metrics"][1].update(status="fail", passed=False)
    (tmp_path / "new").mkdir()
    (tmp_path / "new" / "results.json").write_text(json.dumps(worse))

    res = runner.invoke(app, ["diff", str(recorded), str(tmp_path / "new"), "--html",
                              str(tmp_path / "diff.html")])
    assert res.exit_code == 1, res.output
    assert f"flipped  {metrics[1]['name']}" in res.output and "[WORSE]" in res.output
    page = (tmp_path / "diff.html").read_text()
    assert metrics[0]["name"] in page and metrics[1]["name"] in page
    assert json.loads((tmp_path / "diff.json").read_text())["worse"] is True


def test_diff_of_something_that_is_not_a_run_is_one_line(tmp_path):
    res = runner.invoke(app, ["diff", str(tmp_path), str(tmp_path)])
    assert res.exit_code == 2
    assert "no readable results.json" in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_a_users_mechanism_goes_through_analyze_and_check(tmp_path):
    """The README's example, a pendulum on a cart held by a spring (not in the catalog):
    its linearization about the hanging rest state is, by hand, M = [[M + m, m L/2],
    [m L/2, m L^2/3]], K = diag(k, m g L/2)."""
    res = runner.invoke(app, ["--system-path", str(EXAMPLE), "analyze", "cart_pendulum",
                              "--json"])
    assert res.exit_code == 0, res.output
    lin = json.loads(res.output)["linearization"]
    M, m, L, k, g = 2.0, 0.5, 0.6, 80.0, 9.81
    np.testing.assert_allclose(lin["M"], [[M + m, m * L / 2], [m * L / 2, m * L**2 / 3]],
                               rtol=1e-12)
    np.testing.assert_allclose(lin["K"], [[k, 0], [0, m * g * L / 2]], rtol=1e-12,
                               atol=1e-12)
    res = runner.invoke(app, ["check", "--system-path", str(EXAMPLE), "--systems",
                              "cart_pendulum", "--sims", "mujoco", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert "cart_pendulum" in res.output and "PASS" in res.output


def test_a_bad_mechanism_module_is_one_clear_line(tmp_path):
    cases = {
        "broken.py": ("def build(:\n", "SyntaxError"),
        "empty.py": ('"""nothing here"""\n', "defines no SYSTEM"),
        "twice.py": ("from mbfidelity.systems.compound_pendulum import SYSTEM\n",
                     "already in the catalog"),
    }
    for name, (text, needle) in cases.items():
        path = tmp_path / name
        path.write_text(text)
        res = runner.invoke(app, ["--system-path", str(path), "list"])
        assert res.exit_code == 2, (name, res.output)
        assert needle in res.output and str(path) in res.output, (name, res.output)
        assert len(res.output.strip().splitlines()) == 1, (name, res.output)


@pytest.mark.parametrize("system_id", ["double_pendulum", "rhombus_linkage", "rolling_disc_track"])
def test_an_exported_mjcf_moves_in_plain_mujoco_as_the_harness_build(tmp_path, system_id):
    """Issue 14: the file, loaded by MuJoCo alone from its first keyframe, stepped 2 s,
    read back through its own coordinate map, matches the harness's run to 1e-12 (a
    chain, a closed loop of soft equalities, and a disc rolling on a track)."""
    import mujoco

    from mbfidelity.analytic.reference import consistent_initial_state
    from mbfidelity.simulators import get_backend

    path = tmp_path / f"{system_id}.xml"
    res = runner.invoke(app, ["export", system_id, "--sim", "mujoco", "--out", str(path)])
    assert res.exit_code == 0, res.output
    # nothing of the build left to the harness's callbacks or set on the compiled model
    # (a scenario that changes parameters has no keyframe: that is named, not the model)
    assert "callback" not in res.output and "compiled model" not in res.output
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    qadr = model.numeric("mbfidelity_qadr").data.astype(int)
    n = len(qadr)
    A = model.numeric("mbfidelity_A").data.reshape(n, n)
    b = model.numeric("mbfidelity_b").data
    dt, steps = model.opt.timestep, 2000
    for _ in range(steps):
        mujoco.mj_step(model, data)
    q_plain = np.linalg.solve(A, data.qpos[qadr] - b)

    system = systems.get_system(system_id)
    values = system.parameter_values()
    (scenario,) = [sc for sc in system.scenarios if sc.name == model.key(0).name]
    q0, qd0 = consistent_initial_state(system, scenario, values)
    run = get_backend("mujoco").simulate(system.numeric_mechanism(values), q0, qd0,
                                         steps * dt, dt)
    assert np.max(np.abs(run.q[steps] - q0)) > 1e-2  # it moved
    assert np.max(np.abs(run.q[steps] - q_plain)) <= 1e-12


def test_the_pytest_plugin_runs_the_gates_in_an_empty_folder(pytester):
    """`pytest --mbfidelity` (entry point pytest11) in a folder with no tests: one test per
    system x engine, with readable ids; a bad choice is a usage error."""
    res = pytester.runpytest_subprocess("--mbfidelity", "--mbfidelity-systems=compound_pendulum",
                                        "--mbfidelity-sims=mujoco", "-v")
    res.assert_outcomes(passed=1)
    res.stdout.fnmatch_lines(["*mbfidelity/compound_pendulum-mujoco PASSED*"])
    bad = pytester.runpytest_subprocess("--mbfidelity", "--mbfidelity-systems=no_such_system")
    assert bad.ret == pytest.ExitCode.USAGE_ERROR
    bad.stderr.fnmatch_lines(["*unknown no_such_system*"])
    # without the option the plugin adds nothing
    assert pytester.runpytest_subprocess().ret == pytest.ExitCode.NO_TESTS_COLLECTED


def test_the_python_api_returns_what_the_cli_prints():
    """`mbfidelity.compare` is what `mbfidelity compare --json` prints (deterministic: the
    same metrics, bitwise); bad input is a ValueError of one line."""
    import mbfidelity

    result = mbfidelity.compare("compound_pendulum", "mujoco")
    printed = json.loads(runner.invoke(app, ["compare", "compound_pendulum", "--sim", "mujoco",
                                             "--json"]).output)
    assert result.as_dict()["metrics"] == printed["metrics"]
    assert result.passed is printed["passed"] is True
    doc = mbfidelity.analyze("compound_pendulum", {"m": 2.0})
    shown = json.loads(runner.invoke(app, ["analyze", "compound_pendulum", "--param", "m=2",
                                           "--json"]).output)
    np.testing.assert_array_equal(doc["linearization"]["K"], shown["linearization"]["K"])
    assert doc["modes"] == shown["modes"] and doc["equilibria"] == shown["equilibria"]
    for bad in (lambda: mbfidelity.compare("no_such_system", "mujoco"),
                lambda: mbfidelity.compare("compound_pendulum", "gazebo"),
                lambda: mbfidelity.compare("compound_pendulum", "mujoco", {"m": -1.0})):
        with pytest.raises(ValueError) as err:
            bad()
        assert "\n" not in str(err.value)


#: what each script shows of the defaults its backend neutralises
NEUTRALISED = {"pybullet": ("linearDamping=0.0", "angularDamping=0.0"),
               "exudyn": ("'automaticStepSize': False", "'adaptiveStep': False"),
               "pymunk": ("space.damping = 1.0", "space.sleep_time_threshold = math.inf")}


@pytest.mark.parametrize("engine", sorted(NEUTRALISED))
@pytest.mark.parametrize("system_id", ["double_pendulum", "five_bar_bird"])
def test_an_exported_script_moves_as_the_harness_build(tmp_path, system_id, engine):
    """Issue 14: the standalone script (only the engine imported) run for 1 s gives the
    harness's coordinates to 1e-12, on a chain and on a closed loop (Pymunk's prints its
    bodies' states: their angles against the harness's, through the coordinate map); the
    defaults the backend neutralises are visible in it."""
    import subprocess
    import sys

    from mbfidelity.analytic.reference import consistent_initial_state
    from mbfidelity.simulators import get_backend

    path = tmp_path / f"{system_id}.py"
    res = runner.invoke(app, ["export", system_id, "--sim", engine, "--out", str(path)])
    assert res.exit_code == 0, res.output
    assert "not in the file" not in res.output
    text = path.read_text()
    assert "import mbfidelity" not in text and "from mbfidelity" not in text
    assert all(shown in text for shown in NEUTRALISED[engine])
    out = subprocess.run([sys.executable, str(path), "1.0"], capture_output=True, text=True,
                         check=True, timeout=120, cwd=tmp_path).stdout
    printed = json.loads(out.strip().splitlines()[0])

    system = systems.get_system(system_id)
    values = system.parameter_values()
    scenario = system.scenarios[0]
    q0, qd0 = consistent_initial_state(system, scenario, values)
    run = get_backend(engine).simulate(system.numeric_mechanism(values), q0, qd0, 1.0, 1e-3)
    assert np.max(np.abs(run.q[-1] - q0)) > 1e-3  # it moved
    if engine == "pymunk":
        from mbfidelity.simulators.plan import coordinate_map

        angles = coordinate_map(system.numeric_mechanism(values))
        assert printed  # every engine body, by name
        np.testing.assert_allclose([state[2] for state in printed.values()],
                                   [float(angles.angle(body, run.q[-1])) for body in printed],
                                   rtol=0, atol=1e-12)
        return
    np.testing.assert_allclose([printed[c] for c in system.coordinates], run.q[-1],
                               rtol=0, atol=1e-12)


def test_an_installed_package_registers_its_mechanism_by_entry_point(tmp_path, monkeypatch):
    """A package that declares `[project.entry-points."mbfidelity.systems"]` adds its
    mechanism to the catalog: here a distribution on sys.path (its .dist-info with the
    entry point, as pip would install it) whose module is the README's example."""
    import importlib
    import shutil

    shutil.copy(EXAMPLE, tmp_path / "users_cart.py")
    (tmp_path / "users_cart.py").write_text(
        (tmp_path / "users_cart.py").read_text().replace('id="cart_pendulum"',
                                                         'id="users_cart"'))
    info = tmp_path / "users_cart-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: users-cart\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(
        f"[{systems.ENTRY_POINT_GROUP}]\nusers_cart = users_cart\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    importlib.invalidate_caches()
    systems._REGISTRY = None
    res = runner.invoke(app, ["list", "--json"])
    assert res.exit_code == 0, res.output
    assert "users_cart" in {s["system"] for s in json.loads(res.output)["systems"]}
