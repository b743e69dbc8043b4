"""Cost of a discretized chain's analysis against its number of elements: derivation,
compiled model, equilibrium search and the operating point's modes, for the system with
one structural parameter given on the command line (default: the catalog's spring with
distributed mass), e.g. `MBFIDELITY_CACHE_DIR=/tmp/fresh python benchmarks/chain_cost.py
massive_spring 32` (a fresh cache directory measures the first derivation; run it twice
for the cached cost)."""
import sys
import time

from mbfidelity.analytic.derivation import derivation_of
from mbfidelity.analytic.discretization import structural_parameter
from mbfidelity.analytic.linear import find_equilibria, operating_equilibrium
from mbfidelity.analytic.numeric import numeric_model
from mbfidelity.systems import get_system


def main(system_id: str, N: int) -> None:
    system = get_system(system_id)
    values = system.parameter_values({structural_parameter(system): N})
    special = system.with_structure(values)
    t0 = time.perf_counter()
    derivation_of(special.id)
    t1 = time.perf_counter()
    numeric_model(special.id, values)
    t2 = time.perf_counter()
    equilibria = find_equilibria(special, values)
    t3 = time.perf_counter()
    eq = operating_equilibrium(special, values)
    t4 = time.perf_counter()
    print(f"{special.id}: derivation {t1 - t0:.2f} s, compiled model {t2 - t1:.2f} s, "
          f"equilibria ({len(equilibria)}) {t3 - t2:.3f} s, operating point and modes "
          f"{t4 - t3:.3f} s, total {t4 - t0:.2f} s; first frequencies "
          + ", ".join(f"{m.frequency_hz:.9g}" for m in eq.modes[:3]) + " Hz")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "massive_spring",
         int(sys.argv[2]) if len(sys.argv) > 2 else 32)
