"""CPU seconds of the reference solves of the closed-loop mechanisms (rhombus, five-bar),
each measured after a short warm-up solve in the same process (derivation loaded,
functions compiled), so that only the integration and its Newton projections count.

Usage: .venv/bin/python benchmarks/reference_cost.py
"""
import time

from mbfidelity.analytic.reference import reference
from mbfidelity.systems import get_system

for system_id in ("rhombus_linkage", "five_bar_bird"):
    system = get_system(system_id)
    for scenario in system.scenarios[:2]:
        values = system.parameter_values(scenario=scenario)
        reference(system, scenario, values, 2e-3, 0.2)  # warm-up: a different solve
        start = time.process_time()
        reference(system, scenario, values, 1e-3)
        print(f"{system_id} {scenario.name}: {time.process_time() - start:.2f} s CPU")
