"""`mbfidelity run --resume` (issue 8): a killed run continues where it stopped; the
results equal those of an uninterrupted run."""
import json
import shutil

from typer.testing import CliRunner

from mbfidelity.cli import app
from mbfidelity.comparisons.matrix import reusable_jobs

runner = CliRunner()
ARGS = ["run", "--systems", "compound_pendulum,mass_spring_damper", "--sims", "pymunk"]


def _metrics(folder):
    doc = json.loads((folder / "results.json").read_text())
    return [(c["system"], c["simulator"], m["name"], m["value"], m["tolerance"], m["status"])
            for c in doc["comparisons"] for m in c["metrics"]]


def test_resumed_run_equals_an_uninterrupted_one(tmp_path):
    clean = tmp_path / "clean"
    res = runner.invoke(app, ARGS + ["--out", str(clean)])
    assert res.exit_code == 0, res.output
    # a run killed after its first job: only that job's file survived
    killed = tmp_path / "killed"
    shutil.copytree(clean, killed)
    (killed / "results.json").unlink()
    (killed / "jobs" / "mass_spring_damper.json").unlink()
    (killed / "jobs" / ".partial.tmp").write_bytes(b"\x80 truncated")  # a write cut short
    res = runner.invoke(app, ARGS + ["--out", str(killed), "--resume"])
    assert res.exit_code == 0, res.output
    assert "1 of 2 systems finished" in res.output
    assert _metrics(killed) == _metrics(clean)
    # a saved job answers its own request only (other engines, another step)
    systems = ["compound_pendulum", "mass_spring_damper"]
    assert reusable_jobs(killed, systems, ["pymunk"]) == systems
    assert reusable_jobs(killed, systems, ["mujoco"]) == []
    assert reusable_jobs(killed, systems, ["pymunk"], dt=5e-4) == []
