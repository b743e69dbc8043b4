"""The backend contract, common to every engine.

A backend translates an engine-neutral `Mechanism` (see `mbfidelity.systems.model`,
conventions 1-8) into one engine and runs it. The contract:

1. A backend is one module ``mbfidelity.simulators.<engine>_backend`` that defines
   ``BACKEND``, an instance of a `Backend` subclass whose `id` is the engine's id
   (``mujoco``, ``pybullet``, ``exudyn``, ``pymunk``). Importing the module must not
   import the engine; `available()` does.
2. `available()` returns ``(True, "")`` or ``(False, reason)``; a missing engine is a
   visible skip, never an error.
3. `version()` is the engine's version string; it is recorded in every result.
4. `default_settings()` returns every setting the backend uses, as JSON values, with the
   engine's distorting defaults neutralised (SIMULATORS.md); `setting_notes()` says, per
   key, which engine default it replaces and why. Users may override any key; unknown
   keys raise `ValueError` naming the valid ones.
5. `support(mechanism)` returns `Support(ok, reason)`: whether this backend can express
   the mechanism; when it cannot, the reason is reported as data, not raised.
6. `simulate(mechanism, q0, qd0, t_end, dt, settings, reaction_joints)` builds a fresh
   model, integrates from the state (q0, qd0) (description coordinates) with fixed step
   dt for round(t_end/dt) steps, and returns a `RunResult` sampled at every step,
   including t = 0:
   - ``q``, ``qd``: shape (N+1, n), in the description's coordinates and sign
     conventions (engines with relative or maximal coordinates map back);
   - ``reactions``: for each requested joint, shape (N+1, 2): the force the parent
     exerts on the child through the joint, world axes, belonging to the state at the
     same sample (NaN where the engine cannot give it for that sample);
   - ``constraint_forces``: for each closure constraint of the mechanism, shape (N+1, k),
     in physical terms at the same samples: PointOnPoint, the force on body_a from
     body_b (world x, y); PointOnLine, the force of the slot on the pin (world x, y);
     LinearCoupling, its generalized force (k = 1), with the sign of -multiplier;
   - ``wall_time``: seconds spent stepping only (build excluded), and ``cpu_time``: the
     CPU seconds (``time.process_time``) of the same stepping, comparable with point 9;
   - ``integrator_order``: the order of the scheme actually used (tolerances use it).
   Applied loads that depend on time are evaluated at the time of each integrator stage
   where the engine allows it.
7. `linearize(mechanism, q_eq, settings, dt)` returns the continuous-time eigenvalues of
   the engine's own linearization about the equilibrium q_eq (description coordinates),
   with a label of the facility used, or None when the engine has no such facility.
   Discrete-time eigenvalues are mapped with ln(lambda)/dt.
8. Backends never change the mechanism: a substitute (an intermediate slider body of
   small mass, a penalty spring) is named in the settings and its own error is measured.
9. `bare_loop(mechanism, q0, qd0, t_end, dt, settings)` builds the same model as
   `simulate` with the same arguments, sets the same initial state and runs the engine's
   loop for the same round(t_end/dt) steps with nothing per step beyond what the engine
   needs to step (the force laws it calls back, the loads and moving anchors it must be
   given before a step): no read-out, no samples. It returns the CPU seconds
   (``time.process_time``) of that loop, build excluded: the floor against which
   ``RunResult.cpu_time`` is measured (benchmarks/cost.py). Read-outs belong in
   `simulate`, batched so that its stepping costs little more than this loop.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np

from ..systems.model import Mechanism


@dataclass(frozen=True)
class Support:
    ok: bool
    reason: str = ""


@dataclass
class RunResult:
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    reactions: dict[str, np.ndarray]
    wall_time: float
    integrator_order: int
    settings: dict
    steps: int = 0
    constraint_forces: dict[str, np.ndarray] = field(default_factory=dict)
    cpu_time: float = 0.0

    def __post_init__(self) -> None:
        if self.q.shape != self.qd.shape or self.q.shape[0] != len(self.t):
            raise ValueError("RunResult: t, q and qd lengths differ")


@dataclass(frozen=True)
class Linearization:
    eigenvalues: np.ndarray  # continuous time, 1/s
    method: str
    extra: dict = field(default_factory=dict)


class Backend(ABC):
    id: str = ""

    @abstractmethod
    def available(self) -> tuple[bool, str]:
        """See the contract in the module docstring."""

    @abstractmethod
    def version(self) -> str:
        """See the contract in the module docstring."""

    @abstractmethod
    def default_settings(self) -> dict:
        """See the contract in the module docstring."""

    def setting_notes(self) -> dict[str, str]:
        return {}

    def support(self, mechanism: Mechanism) -> Support:
        return Support(True)

    @abstractmethod
    def simulate(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray, t_end: float,
                 dt: float, settings: Mapping | None = None,
                 reaction_joints: Sequence[str] = ()) -> RunResult:
        """See the contract in the module docstring."""

    @abstractmethod
    def bare_loop(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray, t_end: float,
                  dt: float, settings: Mapping | None = None) -> float:
        """See the contract in the module docstring."""

    def linearize(self, mechanism: Mechanism, q_eq: np.ndarray,
                  settings: Mapping | None = None, dt: float = 1e-3) -> Linearization | None:
        return None

    # helpers shared by backends
    def resolve_settings(self, settings: Mapping | None) -> dict:
        merged = dict(self.default_settings())
        for key, value in (settings or {}).items():
            if key not in merged:
                raise ValueError(
                    f"unknown {self.id} setting {key!r}; valid: {', '.join(sorted(merged))}")
            merged[key] = value
        return merged
