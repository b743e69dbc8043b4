"""The Strutt chart by simulation (comparisons/strutt_engines.py): the pendulum each grid
point maps to obeys eq. 83 (its derivation, linearized), each engine's growth inside the
first tongue and at a stable point agrees with eq. 83's own, and the command reports
every engine's agreement."""
import json

import numpy as np
import pytest
import sympy as sp
from typer.testing import CliRunner

from mbfidelity.analytic.derivation import Derivation
from mbfidelity.cli import app
from mbfidelity.comparisons.strutt_engines import (KAPPA, engine_growth, exact_growth,
                                                   pendulum_for, pendulum_mechanism)
from mbfidelity.simulators import SIMULATOR_IDS, all_backends
from mbfidelity.systems.model import TIME


@pytest.mark.parametrize("lam,gamma", [(0.6, 0.4), (-0.3, 1.2)])
def test_the_mapped_pendulum_linearizes_to_eq_83(lam, gamma):
    """kappa = m l / I_O by hand (m = l = 1, I_G = 0.01); the free coordinate's equation,
    linearized about the equilibrium the point names, is psi'' + (lambda + gamma cos t) psi
    = 0 at several instants."""
    assert KAPPA == pytest.approx(1.0 / 1.01, rel=1e-15)
    point = pendulum_for(lam, gamma)
    derivation = Derivation(pendulum_mechanism(point))
    phi, phi_d, phi_dd = derivation.q[1], derivation.qd[1], derivation.qdd[1]
    y, y_d, y_dd = derivation.q[0], derivation.qd[0], derivation.qdd[0]
    motion = point.amplitude * sp.cos(TIME)
    row = derivation.residual[1].subs({y_dd: sp.diff(motion, TIME, 2), y_d: sp.diff(motion, TIME),
                                  y: motion})
    inertia = sp.diff(row, phi_dd)
    stiffness = sp.diff(row, phi).subs({phi_dd: 0, phi_d: 0, phi: point.equilibrium})
    for t in (0.0, 0.7, 2.0, 4.1):
        k = float((stiffness / inertia).subs({TIME: t, phi: point.equilibrium}))
        assert k == pytest.approx(lam + gamma * np.cos(t), abs=1e-12)


@pytest.mark.parametrize("simulator", SIMULATOR_IDS)
def test_each_engine_grows_inside_the_first_tongue_and_not_outside(simulator):
    """(0.25, 0.2): the centre of the first tongue, growth about 3e2 over 10 periods;
    (1.0, 0.3): stable, growth about 2. Each engine within 5 % of eq. 83's own growth at
    200 steps per period (first-order schemes: (w h) ~ 0.016 per step)."""
    if not all_backends()[simulator].available()[0]:
        pytest.skip(f"{simulator} not installed")
    support = all_backends()[simulator].support(pendulum_mechanism(pendulum_for(0.25, 0.2)))
    if not support.ok:
        pytest.skip(f"{simulator} cannot express the driven pendulum: {support.reason}")
    for lam, gamma in ((0.25, 0.2), (1.0, 0.3)):
        exact = exact_growth(lam, gamma)
        assert engine_growth(simulator, lam, gamma) == pytest.approx(exact, rel=0.05)


def test_strutt_with_engines_reports_their_agreement(tmp_path):
    res = CliRunner().invoke(app, ["strutt", "--grid", "5", "--sim", "mujoco", "--json",
                                   "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    summary = doc["simulation"]["engines"]["mujoco"]
    assert summary["decided_points"] > 0
    assert summary["agreement_with_eq83"] == 1.0, summary["disagreements"]
    assert all("mujoco" in p["engines"] for p in doc["points"])
    assert (tmp_path / "strutt.png").stat().st_size > 0
