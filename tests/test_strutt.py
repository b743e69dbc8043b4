"""The Strutt chart of eq. 83 (analytic/strutt.py) against closed forms of Mathieu's
equation and against the one-point Floquet analysis."""
import time

import numpy as np
import pytest

from mbfidelity.analytic.floquet import floquet
from mbfidelity.analytic.strutt import strutt_chart


def test_unforced_row_is_the_harmonic_oscillator():
    # gamma = 0: lambda < 0 grows as exp(sqrt(-lambda) t); lambda > 0 (away from n^2/4,
    # where the multipliers exp(+-i sqrt(lambda) 2 pi) coincide) is bounded
    chart = strutt_chart(9, 1, (-1.0, 3.0), (0.0, 0.0))
    for lam, verdict, mu in zip(chart.lambdas, chart.verdict[0], chart.max_abs_multiplier[0]):
        if lam < 0:
            assert verdict == "unstable"
            assert mu == pytest.approx(np.exp(np.sqrt(-lam) * 2 * np.pi), rel=1e-9)
        elif lam in (0.0, 0.25 * 4, 0.25 * 9, 0.25):
            assert verdict == "marginal", lam
        else:
            assert verdict == "stable", lam


def test_first_tongue_and_zeroth_curve_at_small_gamma():
    # at gamma = 0.1 (Nayfeh & Mook §5.2): first tongue 1/4 -+ gamma/2 - gamma^2/8, zeroth
    # curve -gamma^2/2; points 0.02 inside/outside the first, 0.005 across the zeroth
    chart = strutt_chart(5, 1, (0.18, 0.32), (0.1, 0.1))
    assert list(chart.verdict[0]) == ["stable", "unstable", "unstable", "unstable", "stable"]
    chart = strutt_chart(2, 1, (-0.01, 0.0), (0.1, 0.1))
    assert list(chart.verdict[0]) == ["unstable", "stable"]


def test_chart_agrees_with_the_one_point_analysis():
    chart = strutt_chart(7, 5, (-0.8, 2.5), (0.3, 2.5))
    for i, gamma in enumerate(chart.gammas):
        for j, lam in enumerate(chart.lambdas):
            one = floquet(lambda t: np.array([[0.0, 1.0], [-(lam + gamma * np.cos(t)), 0.0]]),
                          2 * np.pi, 2)
            assert chart.verdict[i, j] == one.verdict, (lam, gamma)
            assert chart.max_abs_multiplier[i, j] == pytest.approx(one.max_abs_multiplier,
                                                                   rel=1e-7, abs=1e-7)


def test_inverted_pendulum_region_exists():
    # eq. 82 gives negative lambda; the chart has a stable wedge there between the zeroth
    # curve lambda = -gamma^2/2 + 7 gamma^4/32 and the first tongue's lower boundary
    # 1/4 - gamma/2 - gamma^2/8 (Nayfeh & Mook §5.2): at gamma = 0.4, -0.074 < lambda < 0.03.
    # lambda = -0.03 sits 0.04 inside it; without shaking the same lambda is unstable
    chart = strutt_chart(1, 2, (-0.03, -0.03), (0.0, 0.4))
    assert list(chart.verdict[:, 0]) == ["unstable", "stable"]


def test_hundred_by_hundred_under_a_minute():
    start = time.process_time()
    chart = strutt_chart(100, 100)
    assert time.process_time() - start < 60.0
    assert chart.verdict.shape == (100, 100)


def test_strutt_command_json_and_figure(tmp_path):
    import json

    from typer.testing import CliRunner

    from mbfidelity.cli import app

    result = CliRunner().invoke(app, ["strutt", "--grid", "6", "--lambda", "-0.5,2",
                                      "--gamma", "0.2,1.5", "--json", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.output)
    assert len(doc["points"]) == 36
    chart = strutt_chart(6, 6, (-0.5, 2.0), (0.2, 1.5))
    assert [p["verdict"] for p in doc["points"]] == list(chart.verdict.ravel())
    assert {"lambda", "gamma", "floquet_max_abs_multiplier", "stable"} <= set(doc["points"][0])
    assert (tmp_path / "strutt.png").stat().st_size > 0
    bad = CliRunner().invoke(app, ["strutt", "--lambda", "2,1"])
    assert bad.exit_code == 2
