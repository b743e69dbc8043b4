"""Cold cost of the beam chain (beam_with_block) against N: derivation, then operating
equilibrium and modes, each in a fresh cache. Usage: python benchmarks/beam_chain_cost.py
N [N ...] (run with an empty MBFIDELITY_CACHE_DIR)."""
import sys
import time

from mbfidelity.analytic.derivation import Derivation
from mbfidelity.analytic.linear import operating_equilibrium
from mbfidelity.systems import get_system

for N in map(int, sys.argv[1:]):
    system = get_system("beam_with_block").with_structure({"N": N})
    start = time.perf_counter()
    Derivation(system.mechanism)
    derived = time.perf_counter()
    eq = operating_equilibrium(system, system.parameter_values())
    done = time.perf_counter()
    print(f"N={N} derivation {derived - start:.1f} s, equilibrium and modes "
          f"{done - derived:.1f} s, first frequencies (Hz) "
          f"{[round(m.frequency_hz, 9) for m in eq.modes[:3]]}", flush=True)
