"""Simulator backends, one module per engine (``<engine>_backend.py``), discovered
automatically. The contract every backend honours is in `base`."""
from __future__ import annotations

import importlib
import pkgutil

from .base import Backend, Linearization, RunResult, Support

SIMULATOR_IDS = ("mujoco", "pybullet", "exudyn", "pymunk", "drake")


def all_backends() -> dict[str, Backend]:
    found: dict[str, Backend] = {}
    for info in pkgutil.iter_modules(__path__):
        if info.name.endswith("_backend"):
            module = importlib.import_module(f"{__name__}.{info.name}")
            backend = getattr(module, "BACKEND", None)
            if isinstance(backend, Backend):
                found[backend.id] = backend
    order = {sid: i for i, sid in enumerate(SIMULATOR_IDS)}
    return dict(sorted(found.items(), key=lambda kv: order.get(kv[0], len(order))))


def get_backend(simulator_id: str) -> Backend:
    backends = all_backends()
    if simulator_id not in backends:
        raise KeyError(f"unknown simulator {simulator_id!r}; valid: {', '.join(backends)}")
    return backends[simulator_id]


__all__ = ["Backend", "Linearization", "RunResult", "Support", "all_backends", "get_backend"]
