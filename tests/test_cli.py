"""The command line as a user meets it (DESIGN.md): JSON contracts and clear errors."""
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from mbfidelity.cli import app

runner = CliRunner()


def _json(args):
    res = runner.invoke(app, args)
    assert res.exit_code in (0, 1), res.output
    return json.loads(res.stdout)


def test_list_json_names_every_system_and_engine():
    doc = _json(["list", "--json"])
    ids = {s["system"] for s in doc["systems"]}
    assert {"compound_pendulum", "double_pendulum", "elastic_pendulum",
            "pendulum_sliding_block", "mass_spring_damper"} <= ids
    assert set(doc["simulators"]) <= {"mujoco", "pybullet", "exudyn", "pymunk"}


def test_analyze_json_contract_and_param_override():
    # Fig. 7, eq. 5 with L = 2: w0 = sqrt(3 g / (2 L))
    doc = _json(["analyze", "compound_pendulum", "--param", "L=2", "--json"])
    for key in ("system", "parameters", "equilibria", "linearization", "modes"):
        assert key in doc
    assert doc["parameters"]["L"] == 2
    stable = [e for e in doc["equilibria"] if e["stable"]]
    assert len(stable) == 1 and {"q", "stable", "modes"} <= set(stable[0])
    f = doc["modes"][0]["frequency_hz"]
    assert f == pytest.approx(np.sqrt(1.5 * 9.81 / 2) / (2 * np.pi), rel=1e-9)
    assert np.array(doc["linearization"]["M"]).shape == (1, 1)
    unstable = [e for e in doc["equilibria"] if not e["stable"]]
    assert unstable and "eigenvalues" in unstable[0]


def test_analyze_json_damped_modes():
    doc = _json(["analyze", "mass_spring_damper", "--param", "c=4", "--json"])
    (mode,) = doc["modes"]
    assert mode["damping_ratio"] == pytest.approx(4 / (2 * np.sqrt(100)), rel=1e-9)
    assert mode["damped_frequency_hz"] == pytest.approx(
        np.sqrt(100) * np.sqrt(1 - 0.2**2) / (2 * np.pi), rel=1e-9)


@pytest.mark.parametrize("args,needle", [
    (["analyze", "no_such_system"], "compound_pendulum, double_pendulum"),
    (["analyze", "compound_pendulum", "--param", "mass=2"], "valid: m, L"),
    (["analyze", "compound_pendulum", "--param", "L=-1"], "must be > 0"),
    (["analyze", "compound_pendulum", "--param", "L"], "NAME=VALUE"),
    (["compare", "compound_pendulum", "--sim", "gazebo"], "valid:"),
])
def test_bad_input_gets_one_line_error(args, needle):
    res = runner.invoke(app, args)
    assert res.exit_code == 2
    assert needle in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_compare_json_contract():
    doc = _json(["compare", "mass_spring_damper", "--sim", "mujoco", "--t-end", "2", "--json"])
    for key in ("system", "simulator", "engine_version", "settings", "metrics", "passed"):
        assert key in doc
    assert doc["engine_version"]
    for m in doc["metrics"]:
        assert {"name", "value", "tolerance", "passed"} <= set(m)


def test_errata_page_and_json(tmp_path):
    """`errata --out` writes the report page and JSON: every coded printed formula, with
    the known misprint of Fig. 14, eq. 51 (the spurious 1/2) among them."""
    res = runner.invoke(app, ["errata", "--no-witnesses", "--json", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    labels = {(e["system"], e["label"]): e["verdict"] for e in doc["errata"]}
    assert any("eq. 51" in label and verdict == "misprint" for (_, label), verdict in labels.items())
    page = (tmp_path / "errata.html").read_text()
    assert "eq. 116" in page and "misprint" in page
    assert json.loads((tmp_path / "errata.json").read_text())["errata"] == doc["errata"]


def test_unknown_variant_is_a_clear_error():
    res = runner.invoke(app, ["compare", "rolling_disc_track", "--sim", "pymunk",
                              "--variant", "levitating"])
    assert res.exit_code == 2 and "no variant 'levitating'" in res.output
