"""Convergence of a discretized continuum (monograph §6) toward the exact one, in the
number of elements N: the system's count parameter (`System.with_structure`).

For each N the chain is derived like any mechanism and linearized at its operating
point; its first frequencies are compared with the continuum's exact ones
(`analytic/continuum.py`, the system's `continuum` model). The observed order is the
slope of log |error| against log N over the finest counts; where the continuum model
derives the leading error coefficient C_n (error = C_n / N^2 + O(N^-4)), the study
reports it next to the measured N^2 error.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np

from ..systems import System
from .continuum import continuum_summary
from .linear import operating_equilibrium

#: the element counts of the issue's study (issue 12)
DEFAULT_COUNTS = (2, 4, 8, 16, 32)


@dataclass
class ConvergenceRow:
    N: int
    frequency_hz: list[float]
    #: (chain - exact) / exact per mode
    relative_error: list[float]
    #: wall time (s) of derivation (or cache load), equilibrium and modes at this N
    seconds: float


@dataclass
class DiscretizationStudy:
    system: str
    parameter: str
    exact_hz: list[float]
    rows: list[ConvergenceRow]
    #: observed order per mode: -slope of log|error| vs log N over the three finest counts
    fitted_order: list[float]
    #: C_n of error = C_n / N^2 derived for the lumping (None: not derived)
    leading_error: list[float] | None = None
    notes: list[str] = field(default_factory=list)

    def as_dict(self) -> dict:
        return {"system": self.system, "parameter": self.parameter,
                "exact_hz": self.exact_hz,
                "rows": [{"N": r.N, "frequency_hz": r.frequency_hz,
                          "relative_error": r.relative_error, "seconds": r.seconds}
                         for r in self.rows],
                "fitted_order": self.fitted_order, "leading_error": self.leading_error,
                "notes": self.notes}


def structural_parameter(system: System) -> str:
    """The one count parameter of a discretized system (its number of elements; another
    structural parameter, a load's place along the chain, stays as given)."""
    counts = [p.name for p in system.all_parameters if p.domain == "count"]
    if len(counts) != 1:
        raise ValueError(f"{system.id}: a discretization study needs exactly one "
                         f"count parameter, not {sorted(counts) or 'none'}")
    return counts[0]


def chain_frequencies(system: System, values: Mapping[str, float], N: int,
                      modes: int = 3) -> list[float]:
    """The first `modes` natural frequencies (Hz) of the system built with N elements at
    its operating point (fewer when N has fewer modes)."""
    chosen = {**dict(values), structural_parameter(system): float(N)}
    eq = operating_equilibrium(system.with_structure(chosen), chosen)
    return [m.frequency_hz for m in eq.modes if m.frequency_hz > 0][:modes]


def fitted_order(counts: Sequence[int], errors: Sequence[float]) -> float:
    """-slope of the least-squares line of log |error| against log N."""
    x = np.log(np.asarray(counts, dtype=float))
    y = np.log(np.abs(np.asarray(errors, dtype=float)))
    return float(-np.polyfit(x, y, 1)[0])


def discretization_study(system: System, values: Mapping[str, float],
                         counts: Sequence[int] = DEFAULT_COUNTS,
                         modes: int = 3) -> DiscretizationStudy:
    """The first `modes` frequencies of the chain for each N in `counts` against the
    exact continuum's (`System.continuum`), with the fitted order per mode."""
    if not system.continuum:
        raise ValueError(f"{system.id} names no continuum model (System.continuum)")
    name = structural_parameter(system)
    summary = continuum_summary(system.continuum, values, modes)
    exact = summary.frequency_hz
    rows = []
    for N in counts:
        start = time.perf_counter()
        got = chain_frequencies(system, values, N, modes)
        seconds = time.perf_counter() - start
        rows.append(ConvergenceRow(N, got, [(f - e) / e for f, e in zip(got, exact)],
                                   seconds))
    orders = []
    for n in range(modes):
        usable = [(r.N, r.relative_error[n]) for r in rows if len(r.relative_error) > n]
        finest = usable[-3:]
        orders.append(fitted_order(*zip(*finest)) if len(finest) >= 2 else math.nan)
    return DiscretizationStudy(system.catalog_id, name, exact, rows, orders,
                               summary.leading_error)
