"""The linearization's stiffness and damping are the Jacobians of the autonomous residual
M q'' + h - Q_aut at rest; numeric.py takes them from -Q_aut alone, since M q'' (linear
in q'') and h (homogeneous quadratic in q') have vanishing Jacobians at q' = q'' = 0.
Checked here against the whole residual's Jacobians at sampled configurations, on a
planar chain, a spatial rotor and a mechanism with a nonlinear damper."""
import copy
import random

import pytest
import sympy as sp

from mbfidelity.analytic.derivation import derivation_of
from mbfidelity.analytic.numeric import _residual_at_rest_terms
from mbfidelity.systems import get_system

ROWS = ("double_pendulum", "dynamic_unbalance", "slotted_bar_arctan_damper")


def _largest_gap(d, system_id: str) -> float:
    """max |J_full - J_rest| over both Jacobians at three configurations (exact
    arithmetic, then evaluated), with the catalog's parameter values."""
    s = get_system(system_id)
    values = s.subs(s.parameter_values())
    at_rest = {v: 0 for v in (*d.qd, *d.qdd)}
    full = d.M * d.qdd + d.h - d.Q_autonomous
    rest = _residual_at_rest_terms(d)
    rng = random.Random(system_id)
    gap = 0.0
    for wrt in (d.q, d.qd):
        J_full = full.jacobian(wrt).xreplace(at_rest).xreplace(values)
        J_rest = rest.jacobian(wrt).xreplace(at_rest).xreplace(values)
        for _ in range(3):
            q = {x: sp.Rational(rng.randint(-200, 200), 100) for x in d.q}
            diff = (J_full - J_rest).xreplace(q).evalf()
            gap = max(gap, max((abs(e) for e in diff), default=0.0))
    return float(gap)


@pytest.mark.parametrize("system_id", ROWS)
def test_the_residual_at_rest_drops_the_inertial_terms_exactly(system_id):
    """Exact zero up to the evaluation's round-off (15 digits of terms of order one)."""
    assert _largest_gap(derivation_of(system_id), system_id) < 1e-12


def test_a_bias_force_linear_in_the_rates_is_not_dropped():
    """An h with a term linear in q' (which no Lagrangian h has) would make the rest
    residual wrong: the comparison above sees it."""
    d = copy.copy(derivation_of("double_pendulum"))
    d.h = d.h + sp.Matrix([d.qd[1], -d.qd[0]])
    assert _largest_gap(d, "double_pendulum") > 0.5
