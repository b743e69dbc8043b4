"""A floating mechanism pushed by a constant load (Italian notes §5.3.1): its centre of
mass accelerates uniformly while the internal coordinates vibrate about their relative
equilibrium. Measured from the engine's run, for a mechanism that declares rigid
directions (`System.rigid_directions`):

* `cg_acceleration`: the rigid acceleration, fitted as the quadratic coefficient of the
  rigid coordinate of the centre of mass, x_CG = r . q'' ... (least squares of
  c0 + c1 t + c2 t^2 on the engine's centre of mass; a = 2 c2), against the relative
  equilibrium's (F/(2m) for the pair). Any one-step scheme of order >= 1 integrates a
  constant acceleration with at most an error linear in t (semi-implicit Euler:
  a h t/2), which the fit absorbs; what is left is the engine's error in the load or the
  masses. A relative error e in the acceleration moves the centre of mass by e times its
  excursion a T^2/2, the scale on which the trajectory gate judges the growing
  coordinate: gate, the scenario's trajectory gate.
* `cg_position`: max |x_CG - x_CG,ref| over the run relative to the reference's own
  excursion max |x_CG,ref(t) - x_CG,ref(0)| (it grows quadratically: a fixed scale would
  make late samples weigh T^2 times the early ones); gate: the trajectory gate.
* `mean_stretch`: the offset of each internal coordinate, fitted with its oscillation
  (least squares of s0 + A cos(w t) + B sin(w t) at the engine's own frequency w), against
  the relative equilibrium's (-F/(2k) for the pair), relative to the coordinate's own
  excursion about it (the scale of the trajectory metric of that coordinate): gate, the
  trajectory gate.
* `oscillation_frequency`: the engine's frequency of that coordinate (free-vibration fit)
  against the relative equilibrium's oscillatory mode (sqrt(2k/m) for the pair); gate:
  the free-vibration fit's (`tolerances.fit_tolerance`).

The centre of mass along the rigid direction r is r^T M q / r^T M r with M the relative
equilibrium's mass matrix (the mass-weighted mean displacement along r; constant M for a
translating mechanism): for the pair, x1 + dx/2 = x_CG - l0/2.
"""
from __future__ import annotations

import numpy as np

from .. import tolerances
from ..metrics import fit_damped_sinusoid
from . import ScenarioRun

CHECK = "floating"


def centre_of_mass(run: ScenarioRun, q: np.ndarray) -> np.ndarray:
    """The centre of mass along the rigid direction, for each sampled configuration:
    with the rigid direction r (unit, coordinate space) and the relative equilibrium's
    mass matrix M, r^T M q / r^T M r is the mass-weighted average displacement along r
    (for the pair: (2 x1 + dx)/2 = x_CG - l0/2)."""
    eq = run.equilibrium
    r = eq.rigid[:, 0]
    weights = eq.M @ r
    return q @ weights / float(r @ weights)


def measure(run: ScenarioRun) -> None:
    eq = run.equilibrium
    if eq.rigid is None or eq.acceleration is None:
        raise ValueError(f"{run.system.id}: the floating check needs a relative equilibrium "
                         f"(declare the system's rigid_directions)")
    t = run.t
    n = run.n
    tol = run.gate
    q_run, q_ref = run.run.q[:n], run.reference.q[:n]
    r = eq.rigid[:, 0]
    a_ref = float(r @ eq.acceleration)
    cg_run, cg_ref = centre_of_mass(run, q_run), centre_of_mass(run, q_ref)
    internal = [i for i in range(len(r)) if abs(r[i]) < 1e-12]
    if not np.all(np.isfinite(q_run)):  # a diverged run: every measure fails
        labels = ["cg_acceleration", "cg_position"] + [
            f"{kind}_{run.system.coordinates[i]}" for i in internal
            for kind in ("mean", "oscillation_frequency")]
        for label in labels:
            run.judge(label, float("inf"), tol)
        return

    basis = np.column_stack([np.ones_like(t), t, t**2])
    (_, _, c2), *_ = np.linalg.lstsq(basis, cg_run, rcond=None)
    a_run = 2 * float(c2)
    a_scale = max(abs(a_ref), 1e-300)
    metric = run.judge("cg_acceleration", abs(a_run - a_ref) / a_scale, tol)
    metric.detail = {"reference": a_ref, "engine": a_run, "unit": "m/s^2"}

    excursion = max(float(np.max(np.abs(cg_ref - cg_ref[0]))), 1e-300)
    run.judge("cg_position", float(np.max(np.abs(cg_run - cg_ref))) / excursion, tol)
    run.series["cg"] = np.column_stack([cg_ref, cg_run])

    oscillatory = [m for m in eq.modes if m.damped_frequency_hz > 0]
    if not oscillatory or not internal:
        return
    w_ref = abs(oscillatory[0].eigenvalue)
    order = run.run.integrator_order
    fit_gate = tolerances.gate(
        tolerances.fit_tolerance(w_ref, run.dt, order, oscillatory[0].damping_ratio),
        w_ref, run.dt, order, tolerances.MAX_FREQUENCY_TOLERANCE, "relative")
    for i in internal:
        name = run.system.coordinates[i]
        s_eq = float(eq.q[i])
        scale = max(float(np.max(np.abs(q_ref[:, i] - s_eq))), 1e-300)
        try:
            w_run, _ = fit_damped_sinusoid(t, q_run[:, i] - s_eq, w_ref, 0.0)
        except RuntimeError:
            w_run = float("nan")
        if np.isfinite(w_run):
            cols = np.column_stack([np.ones_like(t), np.cos(w_run * t), np.sin(w_run * t)])
            (mean, _, _), *_ = np.linalg.lstsq(cols, q_run[:, i], rcond=None)
            value = abs(float(mean) - s_eq) / scale
            freq_error = abs(w_run - w_ref) / w_ref
        else:
            mean, value, freq_error = float("nan"), float("inf"), float("inf")
        metric = run.judge(f"mean_{name}", value, tol)
        metric.detail = {"reference": s_eq, "engine": float(mean), "scale": scale}
        metric = run.judge(f"oscillation_frequency_{name}", freq_error, fit_gate)
        metric.detail = {"reference_rad_s": w_ref, "engine_rad_s": w_run}
