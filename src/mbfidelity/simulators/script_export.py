"""A build through an engine's Python API, written out as a standalone script: the
backend builds the mechanism against a `Recorder` that stands in for the engine's module,
forwards every call and keeps those that change the world; `script` writes them as
literal calls (every default the backend neutralises is one of them, visible), then steps
and prints the description's coordinates through the coordinate map.

Calls that only read the world (``get*``, ``compute*``) are left out, so are ``connect``
and ``disconnect`` (the script opens its own client). Identifiers the engine returns
(bodies, constraints, shapes) are deterministic in a fresh client, so they are written as
the numbers the recording saw.
"""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

#: name prefixes of calls that do not change the world
READ_ONLY = ("get", "compute", "connect", "disconnect", "isConnected", "isNumpyEnabled")


class Recorder:
    """Stands in for an engine's Python module (e.g. pybullet): attributes that are not
    callable (constants) pass through; every call is forwarded and recorded."""

    def __init__(self, module: Any) -> None:
        self._module = module
        self.calls: list[tuple[str, tuple, dict]] = []

    def __getattr__(self, name: str):
        attr = getattr(self._module, name)
        if not callable(attr):
            return attr

        def call(*args, **kwargs):
            result = attr(*args, **kwargs)
            if not name.startswith(READ_ONLY):
                self.calls.append((name, args, kwargs))
            return result
        return call


def literal(x: Any) -> str:
    """Python source of a value of an engine call: numbers exactly (repr round-trips a
    float), sequences element by element."""
    if isinstance(x, (bool, np.bool_)):
        return repr(bool(x))
    if isinstance(x, (int, np.integer)):
        return repr(int(x))
    if isinstance(x, (float, np.floating)):
        return repr(float(x))
    if isinstance(x, np.ndarray):
        return literal(x.tolist())
    if isinstance(x, (list, tuple)):
        inner = ", ".join(literal(v) for v in x)
        return f"[{inner}]" if isinstance(x, list) else f"({inner}{',' if len(x) == 1 else ''})"
    if isinstance(x, (str, bytes)):
        return repr(x)
    raise TypeError(f"cannot write {type(x).__name__} as a literal")


def _call_source(module: str, name: str, args: tuple, kwargs: dict, client: str,
                 client_id: int) -> str:
    parts = [literal(a) for a in args]
    for key, value in kwargs.items():
        parts.append(f"{key}={client}" if key == "physicsClientId" and value == client_id
                     else f"{key}={literal(value)}")
    return f"{module}.{name}({', '.join(parts)})"


def script(*, title: str, module: str, connect: str, client_id: int,
           calls: Sequence[tuple[str, tuple, dict]], step: str, read: str,
           coordinates: Sequence[str], T: np.ndarray, c: np.ndarray, dt: float,
           not_in_script: Sequence[str]) -> str:
    """The script: `connect` opens the client as `cid`, the recorded `calls`, then `step`
    (one step, source) STEPS times and `read` (source of the engine joint values as a
    list, `values`); prints the description coordinates q = T values + c as JSON."""
    lines = [f'"""{title}', "",
             "Standalone: needs only the engine. Usage: python THIS_FILE [SECONDS] (default 1);",
             "prints the description's coordinates at that time as JSON."]
    if not_in_script:
        lines += ["", "Not in this script (the harness applies them at every step, so the",
                  "motion differs from the harness's where they act):"]
        lines += [f"- {note}" for note in not_in_script]
    lines += ['"""', "import json", "import sys", "", f"import {module}", "",
              f"DT = {dt!r}", f"COORDINATES = {list(coordinates)!r}",
              "# description coordinates from the engine joint values: q = T values + c",
              f"T = {literal(np.asarray(T))}", f"C = {literal(np.asarray(c))}", "",
              f"cid = {connect}"]
    lines += [_call_source(module, name, args, kwargs, "cid", client_id)
              for name, args, kwargs in calls]
    lines += ["", "steps = int(round(float(sys.argv[1] if len(sys.argv) > 1 else 1.0) / DT))",
              "for _ in range(steps):", f"    {step}", f"values = {read}",
              "q = [sum(T[i][j] * values[j] for j in range(len(values))) + C[i]",
              "     for i in range(len(COORDINATES))]",
              "print(json.dumps(dict(zip(COORDINATES, q))))", ""]
    return "\n".join(lines)
