"""Benchmark: Drake's error-controlled integrators on a smooth tree, error against CPU.

The double pendulum's moderate swing (10 s, samples every 1 ms) against its reference, for
Drake's runge_kutta3 and runge_kutta5 at several target accuracies, beside the fixed-step
RK4 of MuJoCo and Exudyn at the same step: the trajectory error (max over the run,
relative to the amplitude, as the comparisons measure it), the stepping CPU seconds
(`RunResult.cpu_time`) and the number of integrator steps. No step of Drake's crosses a
sample, so at a loose accuracy the sampling step, not the accuracy, limits its step.

Usage: .venv/bin/python benchmarks/drake_accuracy.py
"""
from __future__ import annotations

import numpy as np

from mbfidelity.analytic.reference import reference
from mbfidelity.comparisons import metrics
from mbfidelity.simulators import get_backend
from mbfidelity.systems import get_system

RUNS = [("drake", {"integrator": "runge_kutta3", "target_accuracy": 1e-6}),
        ("drake", {"integrator": "runge_kutta3", "target_accuracy": 1e-8}),
        *[("drake", {"target_accuracy": a}) for a in (1e-6, 1e-8, 1e-10, 1e-12, 1e-14)],
        ("mujoco", {}), ("exudyn", {})]


def main() -> None:
    system = get_system("double_pendulum")
    sc = system.scenario("moderate")
    values = system.parameter_values(scenario=sc)
    mech = system.numeric_mechanism(values)
    dt = 1e-3
    ref = reference(system, sc, values, dt)
    scale = metrics.amplitude(ref.q, np.zeros(len(system.coordinates)))
    print(f"double_pendulum {sc.name}, T = {sc.t_end} s, dt = {dt} s; reference: {ref.method}")
    for engine, settings in RUNS:
        backend = get_backend(engine)
        if not backend.available()[0]:
            print(f"{engine}: not installed")
            continue
        run = backend.simulate(mech, ref.q[0], ref.qd[0], sc.t_end, dt, settings)
        error = metrics.trajectory_errors(run.q, ref.q, scale)[0]
        steps = run.error_control.steps if run.error_control else len(run.t) - 1
        print(f"{engine:7s} {str(settings):58s} error {error:.2e}  cpu {run.cpu_time:.3f} s"
              f"  steps {steps}")


if __name__ == "__main__":
    main()
