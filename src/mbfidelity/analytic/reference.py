"""Reference trajectories: exact where a closed form exists, otherwise DOP853 at tight
tolerance whose own error is estimated by a second solve at a 100x looser tolerance."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
from scipy.integrate import solve_ivp

from ..systems import System
from ..systems.model import Scenario
from .closed_forms import SOLUTIONS
from .numeric import numeric_model

TIGHT = 1e-12
LOOSE = 1e-11


@dataclass
class Reference:
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    reactions: dict[str, np.ndarray]
    energy: np.ndarray | None
    #: max |error| estimate of q over the run (per coordinate)
    error_estimate: np.ndarray
    method: str


def _dop853(model, y0: np.ndarray, t: np.ndarray, tol: float) -> np.ndarray:
    sol = solve_ivp(model.ode_rhs, (t[0], t[-1]), y0, method="DOP853", rtol=tol, atol=tol,
                    t_eval=t)
    if not sol.success:
        raise RuntimeError(f"reference solve failed: {sol.message}")
    return sol.y.T


def reference(system: System, scenario: Scenario, values: Mapping[str, float],
              dt: float, t_end: float | None = None,
              q0: np.ndarray | None = None, qd0: np.ndarray | None = None) -> Reference:
    """Sampled every dt from 0 to t_end (the scenario's by default)."""
    t_end = scenario.t_end if t_end is None else t_end
    steps = int(round(t_end / dt))
    t = np.arange(steps + 1) * dt
    if q0 is None:
        q0, qd0 = system.initial_state(scenario, values)
    n = len(q0)
    model = numeric_model(system.id, values)
    y0 = np.concatenate([q0, qd0])
    tight = _dop853(model, y0, t, TIGHT)
    exact = SOLUTIONS.get(system.exact_solution or "")
    if exact is not None:
        q, qd = exact(values, q0, qd0, t)
        # the closed form is exact to round-off; its distance to DOP853 bounds both
        error = np.max(np.abs(q - tight[:, :n]), axis=0)
        method = f"closed form ({system.exact_solution}); DOP853 rtol=atol={TIGHT:g} agrees"
    else:
        q, qd = tight[:, :n], tight[:, n:]
        loose = _dop853(model, y0, t, LOOSE)
        error = np.max(np.abs(loose[:, :n] - q), axis=0)
        method = f"DOP853 rtol=atol={TIGHT:g}; error estimated against rtol=atol={LOOSE:g}"
    qdd = model.accelerations(q, qd, t)
    reactions = {j: model.reaction(j, q, qd, qdd, t) for j in system.reaction_joints}
    energy = model.energy(q, qd) if model.derivation.conservative else None
    return Reference(t, q, qd, qdd, reactions, energy, error, method)
