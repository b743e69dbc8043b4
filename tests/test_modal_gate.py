"""The mode-by-mode trajectory gate (comparisons/tolerances.py, "Trajectory of a nearly
linear motion, mode by mode"; comparisons/runner.py `_modal_trajectory_gate`).

Expected values come from the modes solved here independently (SciPy's symmetric
generalized eigenproblem on the equilibrium's M and K, not the companion matrix the gate
uses) and from the single-mode bound of the module docstring."""
import numpy as np
import pytest
import scipy.linalg

from mbfidelity.analytic.linear import operating_equilibrium
from mbfidelity.analytic.reference import reference
from mbfidelity.comparisons import metrics, tolerances
from mbfidelity.comparisons.runner import _modal_trajectory_gate
from mbfidelity.systems import get_system

DT = 1e-3
RK4 = 4


def _release(system, shape: np.ndarray, t_end: float):
    """The linear lumped spring (massive_spring, default N = 8), released from rest at its
    static equilibrium plus `shape` (stretches)."""
    values = system.parameter_values()
    eq = operating_equilibrium(system, values)
    ref = reference(system, system.scenarios[0], values, DT, t_end, q0=eq.q + shape,
                    qd0=np.zeros_like(eq.q))
    return values, eq, ref


def _gate(system, values, eq, ref, t_end):
    free = list(range(len(system.coordinates)))
    scale = metrics.amplitude(ref.q, eq.q)
    return _modal_trajectory_gate(system, values, eq, ref, free, scale, DT, RK4, t_end, 0.0)


def _modes(eq):
    w2, shapes = scipy.linalg.eigh(eq.K, eq.M)
    return np.sqrt(w2), shapes


def test_a_release_in_one_mode_gets_that_modes_bound():
    """A pure first-mode release: the bound is the first mode's own RK4 bound, exactly
    (every coordinate's amplitude is that mode's share), not the fastest mode's (which at
    N = 8 says nothing: w h = 0.29, w T = 570)."""
    system = get_system("massive_spring")
    values, eq, _ = _release(system, np.zeros(8), 0.01)
    w, shapes = _modes(eq)
    t_end = 2.0
    values, eq, ref = _release(system, 0.01 * shapes[:, 0] / np.max(np.abs(shapes[:, 0])),
                               t_end)
    gate = _gate(system, values, eq, ref, t_end)
    expected = tolerances.trajectory_tolerance(w[0], DT, RK4, t_end)
    assert not gate.unresolved
    # the other modes' shares are round-off of the release (1e-16), and the reference's
    # departure from the linear prediction is at most its own estimated error, counted twice
    ref_error = float(np.max(ref.error_estimate / metrics.amplitude(ref.q, eq.q)))
    assert expected * (1 - 1e-9) <= gate.tolerance <= expected + 2 * ref_error
    fastest = tolerances.trajectory_tolerance(w[-1], DT, RK4, t_end)
    assert fastest > 1 and gate.tolerance < 1e-3


def test_a_fast_modes_share_counts_twice_past_its_range():
    """One per cent of the fastest mode (w h = 0.29 at N = 8 is inside RK4's range) and one
    per cent of a mode past it at dt = 2e-3 s: each share adds its amplitude times its own
    bound, twice the amplitude past the range (a stable scheme keeps it bounded)."""
    system = get_system("massive_spring")
    values, eq, _ = _release(system, np.zeros(8), 0.01)
    w, shapes = _modes(eq)
    unit = shapes / np.max(np.abs(shapes), axis=0)
    shape = 0.01 * (unit[:, 0] + 0.01 * unit[:, -1])
    t_end = 0.5
    values, eq, ref = _release(system, shape, t_end)
    free = list(range(8))
    scale = metrics.amplitude(ref.q, eq.q)
    for dt, fast_error in ((1e-3, tolerances.trajectory_tolerance(w[-1], 1e-3, RK4, t_end)),
                           (2e-3, 2.0)):
        assert (w[-1] * dt <= 0.5) == (dt == 1e-3)
        gate = _modal_trajectory_gate(system, values, eq, ref, free, scale, dt, RK4, t_end, 0.0)
        shares = np.abs(0.01 * np.column_stack([unit[:, 0], 0.01 * unit[:, -1]]))
        errors = np.array([tolerances.trajectory_tolerance(w[0], dt, RK4, t_end), fast_error])
        expected = float(np.max(shares @ errors / scale))
        assert gate.tolerance == pytest.approx(expected, rel=1e-4)


def test_a_large_swing_is_not_split_into_modes():
    """The compound pendulum's 2 rad release (Fig. 7) departs from its linearization by
    more than its amplitude within a period: the mode-by-mode gate declares itself
    unresolved, and the comparison keeps the fastest-frequency bound."""
    system = get_system("compound_pendulum")
    scenario = next(s for s in system.scenarios if s.name == "large")
    values = system.parameter_values(scenario=scenario)
    eq = operating_equilibrium(system, values)
    ref = reference(system, scenario, values, DT, scenario.t_end)
    scale = metrics.amplitude(ref.q, eq.q)
    gate = _modal_trajectory_gate(system, values, eq, ref, [0], scale, DT, RK4,
                                  scenario.t_end, 0.0)
    assert gate.unresolved and gate.tolerance > 2.0
