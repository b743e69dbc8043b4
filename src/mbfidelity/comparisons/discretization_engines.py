"""Each engine's build of a discretized continuum (monograph §6) for every number of
elements N of a discretization study (`analytic/discretization.py`): its frequencies from
its own linearization (`Backend.linearize`, the same route as `compare`'s
`frequency.linearization_mode*` metrics) at the chain's operating point, judged against
the chain's (the same mechanism: the linearization gate of `tolerances`) and set beside
the exact continuum's (the chain's discretization error plus the engine's own).

An engine without a linearization (Pymunk) is reported with that reason; its
free-vibration fits of the chain are `compare`'s.
"""
from __future__ import annotations

from typing import Mapping, Sequence

from ..analytic.discretization import DiscretizationStudy, structural_parameter
from ..analytic.linear import operating_equilibrium
from ..analytic.modes import modes_from_eigenvalues
from ..simulators import get_backend
from ..systems import System
from . import tolerances
from .runner import DEFAULT_DT


def engine_discretization(system: System, values: Mapping[str, float],
                          study: DiscretizationStudy, simulators: Sequence[str],
                          dt: float = DEFAULT_DT) -> dict:
    """Per engine, per N of the study: the engine's first frequencies, their relative
    errors against the chain's and against the exact continuum's, the gate of the
    first against the chain's, and whether every mode met it."""
    name = structural_parameter(system)
    out: dict[str, dict] = {}
    for sim in simulators:
        backend = get_backend(sim)
        ok, why = backend.available()
        rows: list[dict] = []
        method = ""
        reason = "" if ok else f"engine not available: {why}"
        for row in study.rows if ok else ():
            chosen = {**dict(values), name: float(row.N)}
            built = system.with_structure(chosen)
            eq = operating_equilibrium(built, chosen)
            mech = built.numeric_mechanism(chosen)
            support = backend.support(mech)
            if not support.ok:
                reason = support.reason
                break
            lin = backend.linearize(mech, eq.q, None, dt)
            if lin is None:
                reason = f"{sim} has no linearization of its own (its fits are compare's)"
                break
            method = lin.method
            got = [m.frequency_hz for m in modes_from_eigenvalues(lin.eigenvalues)
                   if m.frequency_hz > 0][:len(row.frequency_hz)]
            w_max = max(abs(m.eigenvalue) for m in eq.modes)
            order = lin.extra.get("discrete_order")
            # the gate of compare's frequency.linearization_mode* metrics
            gate = (tolerances.discrete_linearization_tolerance(w_max, dt, order)
                    if order else tolerances.FD_FREQUENCY)
            vs_chain = [(g - c) / c for g, c in zip(got, row.frequency_hz)]
            rows.append({"N": row.N, "frequency_hz": got,
                         "error_vs_chain": vs_chain,
                         "error_vs_continuum": [(g - e) / e
                                                for g, e in zip(got, study.exact_hz)],
                         "gate_vs_chain": gate,
                         "passed": len(got) == len(row.frequency_hz)
                         and all(abs(e) <= gate for e in vs_chain)})
        out[sim] = {"engine_version": backend.version() if ok else "", "method": method,
                    "rows": rows if not reason else [], "reason": reason}
    return out
