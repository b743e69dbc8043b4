"""The results folder a run leaves (comparisons/results_folder.py): the report pages are
rendered from it alone, and the pool's dispatch order comes from its measured job costs
or, without them, from the descriptions."""
import hashlib
import json

from typer.testing import CliRunner

from mbfidelity.cli import app
from mbfidelity.comparisons.matrix import estimated_cost, schedule
from mbfidelity.comparisons.results_folder import (JOB_COSTS, REPORT_DATA, load_results,
                                                   load_series)


def _digest(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_report_is_rendered_from_the_saved_results_alone(tmp_path):
    res = CliRunner().invoke(app, ["run", "--systems", "compound_pendulum", "--sims", "mujoco",
                                   "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    figures = sorted(tmp_path.glob("*.png"))
    assert [p.name for p in figures] == ["compound_pendulum-drawing.png",
                                        "compound_pendulum-large.png",
                                        "compound_pendulum-small.png"]
    pages = {p.name: p.read_text() for p in tmp_path.glob("*.html")}
    assert set(pages) == {"index.html", "compound_pendulum.html"}
    summary = (tmp_path / "summary.md").read_text()
    made = {p.name: _digest(p) for p in figures}
    _, (comparison,) = load_results(tmp_path)
    series = load_series(tmp_path, "compound_pendulum")[comparison.simulator]
    assert set(series) == {"small", "large"}
    for s in series.values():
        assert len(s["t"]) == len(s["q"]) == len(s["q_ref"]) and s["tolerance"] > 0
    assert json.loads((tmp_path / JOB_COSTS).read_text())["compound_pendulum"] > 0
    assert (tmp_path / REPORT_DATA / "compound_pendulum.json").exists()

    # the same pages again, in a fresh process pool and serially, from the folder only
    from mbfidelity.reports.html import write_report

    for workers in (2, 1):
        for p in figures:
            p.unlink()
        write_report(tmp_path, workers=workers)
        assert {p.name: p.read_text() for p in tmp_path.glob("*.html")} == pages
        assert (tmp_path / "summary.md").read_text() == summary
        assert {p.name: _digest(p) for p in sorted(tmp_path.glob("*.png"))} == made


def test_schedule_prefers_measured_costs():
    systems = ["compound_pendulum", "rhombus_linkage", "double_pendulum"]
    # without measurements: the description's estimate, the four-bar loop first
    assert schedule(systems)[0] == "rhombus_linkage"
    assert schedule(systems)[-1] == "compound_pendulum"
    # measured costs win over the estimates
    assert schedule(systems, {"compound_pendulum": 3.0, "rhombus_linkage": 1.0,
                              "double_pendulum": 2.0}) == ["compound_pendulum",
                                                           "double_pendulum", "rhombus_linkage"]
    # the unmeasured ones are placed by their estimates scaled to seconds
    ratio = estimated_cost("double_pendulum") / estimated_cost("compound_pendulum")
    measured = {"compound_pendulum": 10.0, "rhombus_linkage": 10.0 * ratio * 0.5}
    assert schedule(systems, measured) == ["double_pendulum", "rhombus_linkage",
                                           "compound_pendulum"]


def test_check_series_are_saved_and_drawn(tmp_path):
    """Issue 11: what a scenario's checks measure (here the end-stop instants of Fig. 2)
    reaches the report as its own figure, drawn from the saved series."""
    res = CliRunner().invoke(app, ["run", "--systems", "end_stops", "--sims", "mujoco",
                                   "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    checks = load_series(tmp_path, "end_stops")["mujoco"]["fig2"]["checks"]
    errors, gates = checks["stop_events_error"], checks["stop_events_tolerance"]
    assert len(errors) == len(gates) == len(checks["stop_events_reference"]) > 0
    assert (tmp_path / "end_stops-fig2-checks.png").stat().st_size > 0
    assert "end_stops-fig2-checks.png" in (tmp_path / "end_stops.html").read_text()


def test_every_catalog_mechanism_is_drawn(tmp_path):
    """The report's drawing of each system at its operating point (`make report` once
    stopped on the first spatial one: 3-D points into a planar polygon). A spatial
    mechanism is drawn on the two world axes its points spread along most."""
    from mbfidelity.comparisons.results_folder import mechanism_geometry
    from mbfidelity.reports.html import draw_mechanism
    from mbfidelity.systems import all_systems, get_system

    for system_id in all_systems():
        geometry = mechanism_geometry(system_id)
        assert len(geometry["view"]) == 2
        if not get_system(system_id).mechanism.spatial:
            assert geometry["view"] == [0, 1]
        name = draw_mechanism(geometry, tmp_path)
        assert (tmp_path / name).stat().st_size > 0
