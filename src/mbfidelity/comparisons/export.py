"""A mechanism as the harness builds it in an engine, saved for use outside the harness:
for MuJoCo the MJCF (loadable by ``mujoco.MjModel.from_xml_path``) with a keyframe per
scenario's initial state and the coordinate map (simulators/mujoco_backend.py, `export`);
for an engine built through its Python API, a standalone script of the recorded build
calls (PyBullet, Drake's plant calls), of the system's item dictionaries (Exudyn) or of
the space read back (Pymunk), see simulators/script_export.py. A backend without `export` has none."""
from __future__ import annotations

from typing import Mapping

from ..analytic.reference import consistent_initial_state
from ..simulators import get_backend
from ..systems import get_system
from .runner import own_step


def export_model(system_id: str, simulator: str, params: Mapping[str, float] | None = None,
                 settings: Mapping | None = None,
                 dt: float | None = None) -> tuple[str, list[str]]:
    """(the engine's model file, what the file alone does not reproduce of the harness's
    build). Keyframes for the scenarios that run at these parameters (a scenario that
    overrides a parameter builds another model). ValueError for what cannot be exported."""
    system = get_system(system_id)
    dt = own_step(system_id, dt)
    backend = get_backend(simulator)
    if not hasattr(backend, "export"):
        raise ValueError(f"no export for {simulator}: its build is not recorded as a file or "
                         f"a script (export exists for MuJoCo's MJCF and the other engines' scripts)")
    values = system.parameter_values(params)
    system = system.with_structure(values)  # built for the user's number of elements
    mech = system.numeric_mechanism(values)
    support = backend.support(mech)
    if not support.ok:
        raise ValueError(f"{simulator} cannot express {system.id}: {support.reason}")
    states = {}
    for sc in system.scenarios:
        if system.parameter_values(params, scenario=sc) == values:
            states[sc.name] = consistent_initial_state(system, sc, values)
    text, outside = backend.export(mech, system.coordinates, states, settings, dt)
    skipped = [sc.name for sc in system.scenarios if sc.name not in states]
    if skipped:
        outside.append(f"no initial state for the scenarios that change parameters: "
                       f"{', '.join(skipped)}")
    return text, outside
