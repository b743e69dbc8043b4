"""End stops (monograph §2.1, Fig. 1-2): the piecewise-exact reference against an
independent solve written here (DOP853 restarted at every switch, the switches located as
events of |x| = l), and Fig. 2's statement that the motion settles in the central band
after about 2.5 s."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mbfidelity.analytic.closed_forms import elastic_stop_events, oscillator_with_elastic_stops
from mbfidelity.systems import get_system


def _piecewise_solve(v, x0, v0, t_end):
    m, k1, c, k2, l = (v[n] for n in ("m", "k1", "c", "k2", "l"))

    def rhs(t, y):
        x, xd = y
        stop = -k2 * (x - l) if x > l else (-k2 * (x + l) if x < -l else 0.0)
        return [xd, (-2 * k1 * x - 2 * c * xd + stop) / m]

    def hit_right(t, y):
        return y[0] - l

    def hit_left(t, y):
        return y[0] + l

    t, y, events = 0.0, [x0, v0], []
    samples_t, samples_x = [], []
    while t < t_end:
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=1e-12, atol=1e-14,
                        events=(hit_right, hit_left), dense_output=True)
        hits = sorted(te for group in sol.t_events for te in group if te > t + 1e-12)
        stop_at = hits[0] if hits else t_end
        grid = np.linspace(t, stop_at, 50)
        samples_t += list(grid)
        samples_x += list(sol.sol(grid)[0])
        if not hits:
            break
        events.append(stop_at)
        y = sol.sol(stop_at)
        t = stop_at + 1e-13  # past the corner, on the next piece
    return np.array(events), np.array(samples_t), np.array(samples_x)


@pytest.mark.parametrize("overrides", [{}, {"k2": 500.0, "c": 0.5}, {"l": 0.03, "x0": 0.08}])
def test_switching_instants_and_motion_match_an_independent_event_solve(overrides):
    s = get_system("end_stops")
    v = s.parameter_values(overrides)
    events, t, x = _piecewise_solve(v, v["x0"], v["v0"], 5.0)
    exact = elastic_stop_events(v, v["x0"], v["v0"], 5.0)
    assert len(exact) == len(events)
    np.testing.assert_allclose([e.t for e in exact], events, atol=1e-9)
    q, _ = oscillator_with_elastic_stops(v, np.array([v["x0"]]), np.array([v["v0"]]), t)
    np.testing.assert_allclose(q[:, 0], x, atol=1e-9 * max(1.0, np.max(np.abs(x))))


def test_fig2_motion_settles_in_the_band_after_about_2_5_s():
    s = get_system("end_stops")
    v = s.parameter_values()
    exact = elastic_stop_events(v, v["x0"], v["v0"], 5.0)
    assert 2.0 < exact[-1].t < 3.0  # Fig. 2: about 2.5 s
