"""The index page's summary: every metric of the run counted by verdict, in all and per
engine, with the unresolved ones' share and how many of them are declared."""
from mbfidelity.comparisons.matrix import write_results
from mbfidelity.comparisons.runner import Comparison, Metric
from mbfidelity.reports.html import verdict_summary, write_report


def _comparison(simulator: str, statuses: list[str], declared: int = 0) -> Comparison:
    metrics = []
    for k, status in enumerate(statuses):
        m = Metric(f"small.metric{k}", 0.1, 0.2, status == "pass", status)
        m.expected = status == "unresolved" and k < declared  # the first `declared` metrics
        metrics.append(m)
    return Comparison("compound_pendulum", simulator, "0", {}, {}, 1e-3, metrics=metrics)


RESULTS = [
    _comparison("mujoco", ["pass", "pass", "pass", "xfail"]),
    _comparison("pymunk", ["pass", "fail", "unresolved", "unresolved"], declared=3),
]


def test_metrics_are_counted_by_verdict_in_all_and_per_engine():
    found = verdict_summary(RESULTS)
    assert found["total"] == 8
    assert found["counts"] == {"pass": 4, "fail": 1, "xfail": 1, "unresolved": 2}
    assert list(found["counts"]) == ["pass", "fail", "xfail", "unresolved"]
    assert found["engines"] == {"mujoco": {"pass": 3, "xfail": 1},
                                "pymunk": {"pass": 1, "fail": 1, "unresolved": 2}}
    assert found["unresolved"] == 2 and found["declared"] == 1
    assert found["unresolved_share"] == 0.25


def test_the_index_page_shows_the_counts(tmp_path):
    write_results(RESULTS, tmp_path)
    page = write_report(tmp_path, workers=1).read_text()
    assert "8 metrics: 4 pass, 1 fail, 1 xfail, 2 unresolved." in page
    assert "Unresolved: 2 (25.00 % of the metrics), 1 of them declared" in page
    assert "<tr><td>pymunk</td><td>1</td><td>1</td><td>0</td><td>2</td></tr>" in page
