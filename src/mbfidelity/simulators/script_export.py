"""A build through an engine's Python API, written out as a standalone script that needs
only the engine: it builds, steps and prints the description's coordinates through the
coordinate map. Two routes. PyBullet: the backend builds against a `Recorder` that stands
in for the engine's module, forwards every call and keeps those that change the world;
`script` writes them as literal calls (every default the backend neutralises is one of
them, visible). Exudyn: the system's items as the dictionaries Exudyn reports for them and
the simulation settings as theirs, added back in order (`exudyn_script`). Pymunk: the
space, its bodies and its constraints read back from the built space, each constructed
with its parameters and every attribute the backend sets (`pymunk_script`).

Recorded calls that only read the world (``get*``, ``compute*``) are left out, so are
``connect`` and ``disconnect`` (the script opens its own client). Identifiers the engine returns
(bodies, constraints, shapes) are deterministic in a fresh client, so they are written as
the numbers the recording saw.
"""
from __future__ import annotations

import math
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


# --- Exudyn: the system's items as the dictionaries Exudyn reports -----------------------

#: item keys that are derived from others, or only draw the item
EXUDYN_DERIVED_KEYS = ("jointHTs", "localHT")


def exudyn_literal(x: Any) -> str:
    """Python source of a value of an Exudyn item dictionary: its enums by name, its
    3-D lists by their constructors, item indices as numbers."""
    kind = type(x).__name__
    if kind in ("Matrix3DList", "Vector3DList", "Matrix6DList"):
        # these lists index but do not iterate safely
        return f"exudyn.{kind}({exudyn_literal([np.asarray(x[i]).tolist() for i in range(len(x))])})"
    if kind.endswith("Index"):
        return repr(int(x))
    if type(x).__module__.startswith("exudyn") and hasattr(x, "name"):
        return f"exudyn.{kind}.{x.name}"
    if isinstance(x, dict):
        return "{" + ", ".join(f"{k!r}: {exudyn_literal(v)}" for k, v in x.items()) + "}"
    if isinstance(x, (list, tuple)):
        return "[" + ", ".join(exudyn_literal(v) for v in x) + "]"
    return literal(x)


def _exudyn_item(kind: str, item: dict) -> tuple[str, bool]:
    """(source adding the item, whether a Python user function was left out)."""
    kept, dropped = {}, False
    for key, value in item.items():
        if key.startswith("V") or key in EXUDYN_DERIVED_KEYS:
            continue
        if "UserFunction" in key:
            dropped |= not (isinstance(value, int) and value == 0)
            continue
        kept[key] = value
    return f"mbs.Add{kind}({exudyn_literal(kept)})", dropped


def exudyn_script(*, title: str, items: Sequence[tuple[str, dict]], simulation: dict,
                  solver: str, node: int, coordinates: Sequence[str], T: np.ndarray,
                  c: np.ndarray, dt: float, not_in_script: Sequence[str]) -> str:
    """A script that adds the `items` back in order, sets the `simulation` settings'
    dictionary, solves with `solver` for the requested time and prints q = T u + c of
    the tree's coordinates u (node `node`) as JSON."""
    added = [_exudyn_item(kind, item) for kind, item in items]
    lines = [f'"""{title}', "",
             "Standalone: needs only the engine. Usage: python THIS_FILE [SECONDS] (default 1);",
             "prints the description's coordinates at that time as JSON."]
    if not_in_script:
        lines += ["", "Not in this script (the harness adds them, so the motion differs",
                  "from the harness's where they act):"]
        lines += [f"- {note}" for note in not_in_script]
    lines += ['"""', "import json", "import sys", "", "import exudyn", "",
              f"DT = {dt!r}", f"COORDINATES = {list(coordinates)!r}",
              "# description coordinates from the tree's coordinates u: q = T u + c",
              f"T = {literal(np.asarray(T))}", f"C = {literal(np.asarray(c))}", "",
              "SC = exudyn.SystemContainer()", "mbs = SC.AddSystem()"]
    lines += [source for source, _ in added]
    lines += ["mbs.Assemble()", "", "simulation = exudyn.SimulationSettings()",
              f"simulation.SetDictionary({exudyn_literal(simulation)})",
              "steps = int(round(float(sys.argv[1] if len(sys.argv) > 1 else 1.0) / DT))",
              "simulation.timeIntegration.numberOfSteps = steps",
              "simulation.timeIntegration.endTime = steps * DT",
              "simulation.solution.sensors.writePeriod = 0.5 * DT",
              f"mbs.SolveDynamic(simulation, solverType=exudyn.DynamicSolverType.{solver})",
              f"u = mbs.GetNodeOutput({node}, exudyn.OutputVariableType.Coordinates)",
              "q = [sum(T[i][j] * u[j] for j in range(len(u))) + C[i]",
              "     for i in range(len(COORDINATES))]",
              "print(json.dumps(dict(zip(COORDINATES, q))))", ""]
    return "\n".join(lines)


# --- Pymunk: the built space read back ---------------------------------------------------

#: constructor arguments of the constraints the backends build, after the two bodies
PYMUNK_CONSTRUCTORS = {
    "PivotJoint": ("anchor_a", "anchor_b"),
    "PinJoint": ("anchor_a", "anchor_b"),
    "GrooveJoint": ("groove_a", "groove_b", "anchor_b"),
    "GearJoint": ("phase", "ratio"),
}
#: attributes set after construction (a PinJoint's distance is measured at construction,
#: from wherever the bodies were then: it is set again)
PYMUNK_ATTRIBUTES = {"PinJoint": ("distance",)}
PYMUNK_COMMON = ("error_bias", "max_bias", "max_force", "collide_bodies")


def pymunk_script(*, title: str, space, first_iterations: int, iterations: int,
                  names: dict, dt: float, not_in_script: Sequence[str]) -> str:
    """A script that rebuilds `space` (bodies in their order, named by `names`: body ->
    name), steps it (`first_iterations` solver iterations in the first step, then
    `iterations`) and prints every body's frame position, angle, velocity and angular
    velocity as JSON."""
    import pymunk

    bodies = list(space.bodies)
    if space.shapes:
        raise ValueError("a space with shapes (contacts) is not written out")
    index = {b: i for i, b in enumerate(bodies)}

    def body(b) -> str:
        return "space.static_body" if b is space.static_body else f"bodies[{index[b]}]"

    lines = [f'"""{title}', "",
             "Standalone: needs only the engine. Usage: python THIS_FILE [SECONDS] (default 1);",
             "prints each body's frame position, angle, velocity and angular velocity as",
             "JSON."]
    if not_in_script:
        lines += ["", "Not in this script (the harness applies them at every step, so the",
                  "motion differs from the harness's where they act):"]
        lines += [f"- {note}" for note in not_in_script]
    lines += ['"""', "import json", "import math", "import sys", "", "import pymunk", "",
              f"DT = {dt!r}", f"NAMES = {[names[b] for b in bodies]!r}", "",
              "space = pymunk.Space()",
              f"space.gravity = {literal(tuple(space.gravity))}",
              f"space.damping = {literal(space.damping)}",
              f"space.sleep_time_threshold = {_pymunk_number(space.sleep_time_threshold)}",
              "bodies = []"]
    for b in bodies:
        kind = {pymunk.Body.DYNAMIC: "DYNAMIC", pymunk.Body.KINEMATIC: "KINEMATIC",
                pymunk.Body.STATIC: "STATIC"}[b.body_type]
        if kind == "DYNAMIC":
            lines.append(f"b = pymunk.Body({_pymunk_number(b.mass)}, "
                         f"{_pymunk_number(b.moment)})")
        else:
            lines.append(f"b = pymunk.Body(body_type=pymunk.Body.{kind})")
        lines += [f"b.center_of_gravity = {literal(tuple(b.center_of_gravity))}",
                  f"b.angle = {literal(b.angle)}",
                  f"b.position = {literal(tuple(b.position))}",
                  f"b.velocity = {literal(tuple(b.velocity))}",
                  f"b.angular_velocity = {literal(b.angular_velocity)}",
                  "space.add(b)", "bodies.append(b)"]
    lines.append("constraints = []")
    for c in space.constraints:
        kind = type(c).__name__
        if kind not in PYMUNK_CONSTRUCTORS:
            raise ValueError(f"a {kind} is not written out")
        args = [body(c.a), body(c.b)] + [literal(_plain(getattr(c, a)))
                                         for a in PYMUNK_CONSTRUCTORS[kind]]
        lines.append(f"c = pymunk.{kind}({', '.join(args)})")
        for attribute in PYMUNK_ATTRIBUTES.get(kind, ()) + PYMUNK_COMMON:
            value = getattr(c, attribute)
            lines.append(f"c.{attribute} = " + (repr(bool(value)) if attribute == "collide_bodies"
                                                 else _pymunk_number(value)))
        lines.append("constraints.append(c)")
    lines += ["space.add(*constraints)", "",
              "steps = int(round(float(sys.argv[1] if len(sys.argv) > 1 else 1.0) / DT))",
              "# the first step has no cached impulses to start from: more iterations",
              f"space.iterations = {int(first_iterations)}",
              "for k in range(steps):",
              "    space.step(DT)",
              "    if k == 0:",
              f"        space.iterations = {int(iterations)}",
              "print(json.dumps({name: [*b.position, b.angle, *b.velocity, b.angular_velocity]",
              "                  for name, b in zip(NAMES, bodies)}))", ""]
    return "\n".join(lines)


def _plain(value):
    """A pymunk Vec2d as a tuple; numbers as they are."""
    return tuple(value) if hasattr(value, "x") and hasattr(value, "y") else value


def _pymunk_number(x) -> str:
    """A number, with infinity written as math.inf."""
    if isinstance(x, bool):
        return repr(x)
    x = float(x)
    return ("math.inf" if x > 0 else "-math.inf") if math.isinf(x) else repr(x)
