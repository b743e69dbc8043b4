"""The Python API: what the command line does, as functions returning the typed results
the CLI prints as JSON (each has ``as_dict()``). The CLI is a thin layer over it.

    import mbfidelity
    doc = mbfidelity.analyze(system_id, {"m": 2.0})        # equilibria, M, C, K, modes
    result = mbfidelity.compare(system_id, "mujoco")   # a Comparison (ids: mbfidelity list)
    result.passed, [m.name for m in result.metrics if m.status == "fail"]
    outcome = mbfidelity.check(systems=[system_id], sims=["mujoco"], out="gates")
    outcome.passed, outcome.verdicts
    mbfidelity.diff("gates-before", "gates")                     # a ResultsDiff

Errors in the input (an unknown system or engine, a parameter outside its domain, a bad
setting) raise ValueError with one line that names the problem.
"""
from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Iterable, Mapping

from .comparisons.diff import ResultsDiff, diff_runs, holds
from .comparisons.runner import DEFAULT_DT, Comparison

__all__ = ["list_systems", "analyze", "compare", "run", "errata", "strutt", "discretization",
           "convergence", "benchmark_errors", "beams", "check", "diff", "export", "power", "out_of_the_box",
           "Verdict", "CheckResult", "DEFAULT_DT"]


def _system(system_id: str):
    from .systems import get_system

    try:
        return get_system(system_id)
    except KeyError as exc:
        raise ValueError(exc.args[0]) from None


def _backend(simulator: str):
    from .simulators import get_backend

    try:
        return get_backend(simulator)
    except KeyError as exc:
        raise ValueError(exc.args[0]) from None


def checked_output_folder(out: str | Path, option: str = "--out") -> Path:
    """`out` as a folder results can be written into (it may not exist yet), or a
    ValueError in one line, before any work: it is not a file, no parent is a file, and
    the nearest existing folder is writable."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"{option} {out}: is a file, not a folder")
    _checked_parents(out, option)
    return out


def checked_output_file(out: str | Path, option: str = "--out") -> Path:
    """`out` as a file that can be written (its folder may not exist yet), or a ValueError
    in one line, before any work."""
    out = Path(out)
    if out.is_dir():
        raise ValueError(f"{option} {out}: is a folder, not a file")
    if out.exists() and not os.access(out, os.W_OK):
        raise ValueError(f"{option} {out}: the file is not writable")
    _checked_parents(out, option)
    return out


def _checked_parents(path: Path, option: str) -> None:
    for parent in path.absolute().parents:
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(f"{option} {path}: {parent} is a file, not a folder")
            if not os.access(parent, os.W_OK | os.X_OK):
                raise ValueError(f"{option} {path}: {parent} is not writable")
            return


def checked_duration(name: str, value: float | None) -> None:
    """ValueError (one line) unless `value` is None or a finite number > 0."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value:g}")


def _checked_parameters(system, params: Mapping[str, float] | None) -> None:
    """Every parameter set the comparison will use (with each scenario's values)."""
    try:
        for sc in system.scenarios:
            system.parameter_values(params, scenario=sc)
    except KeyError as exc:
        raise ValueError(exc.args[0]) from None


def analyze(system_id: str, params: Mapping[str, float] | None = None, *,
            timeout: float | None = None) -> dict:
    """What `mbfidelity analyze --json` prints: the equilibria with their stability (and
    modes), the operating point's linearization M, C, K (arrays) and modes, the printed
    formulas against the derivation; a floating mechanism's relative equilibrium, a
    self-excited one's stability threshold, a driven one's steady state. With `timeout`
    (seconds) the analysis runs in a worker process with that budget and the worker
    memory limit: a worker that dies, runs out of memory or out of time raises
    RuntimeError (bad input still raises ValueError)."""
    checked_duration("timeout", timeout)
    if timeout is None:
        return _analyze_here(system_id, params)
    from .comparisons.budget import worker_memory_limit
    from .comparisons.isolation import isolated

    _system(system_id)
    try:
        return isolated(_analyze_here, system_id, params, timeout=timeout)
    except MemoryError:
        raise RuntimeError(f"out of memory (the worker limit is {worker_memory_limit():.3g} "
                           f"bytes; MBFIDELITY_WORKER_MEMORY raises it)") from None


def _constraint_rank(system, values: Mapping[str, float], q) -> dict:
    """The constraint Jacobian's rank at an equilibrium, and where it is below the number
    of constraint rows a warning: a singular position ({} without constraints)."""
    from .analytic.numeric import numeric_model

    model = numeric_model(system.id, values)
    if not model.constrained:
        return {}
    rank, _ = model.constraint_rank(q)
    # an over-constrained loop's redundant rows lower the rank everywhere, not singularly
    regular = model.m - model.redundant
    out = {"constraint_rank": rank, "constraint_rows": model.m,
           "singular": rank < regular}
    if model.redundant:
        out["redundant_rows"] = model.redundant
    if rank < regular:
        out["warning"] = (
            f"singular position: the constraint Jacobian has rank {rank} of {regular} "
            f"here (assembly branches cross; the mobility is {model.n - rank}, not "
            f"{model.n - regular}): the stability and modes are those of the first-order "
            f"motions allowed here, and a motion through it may change branch")
    return out


#: reference samples per scenario for the named points' report
POINT_SAMPLES = 2000


def _points_report(system, values: Mapping[str, float]) -> list[dict]:
    """Each named point (`System.points`) at the end of each scenario, from the
    reference: its world position and velocity there, the largest distance over the run
    between the reference's position and that of its error-estimating solve, and the
    extent of its path (the largest distance from its start)."""
    import numpy as np

    from .analytic.reference import reference

    out = []
    for sc in system.scenarios:
        ref = reference(system, sc, values, sc.t_end / POINT_SAMPLES)
        for p in system.points(system.symbols):
            state = ref.points[p.name]
            d = state.shape[1] // 2
            out.append({
                "point": p.name, "body": p.body,
                "position_in_body": [str(c) for c in p.position],
                "scenario": sc.name, "time": float(ref.t[-1]),
                "position": state[-1, :d].tolist(), "velocity": state[-1, d:].tolist(),
                "error_estimate": ref.point_error_estimate[p.name],
                "path_extent": float(np.max(np.linalg.norm(state[:, :d] - state[0, :d],
                                                           axis=1))),
            })
    return out


def _analyze_here(system_id: str, params: Mapping[str, float] | None = None) -> dict:
    import numpy as np

    from .analytic.errata import errata
    from .analytic.linear import find_equilibria, operating_equilibrium
    from .analytic.modes import oscillatory_instability

    system = _system(system_id)
    try:
        values, derived = system.resolve_parameters(params)
    except KeyError as exc:
        raise ValueError(exc.args[0]) from None
    system = system.with_structure(values)  # built for the user's number of elements
    coords = list(system.coordinates)
    try:
        eqs = find_equilibria(system, values)
        op = operating_equilibrium(system, values)
    except (ValueError, TypeError, RuntimeError, np.linalg.LinAlgError) as exc:
        from .analytic.floquet import driven_floquet_summary, periodic_coefficients

        if system.driven and periodic_coefficients(system, values):
            return _floquet_document(system, values, derived, str(exc),
                                     driven_floquet_summary(system, values))
        raise ValueError(f"{system.id} with these parameters has no assembled equilibrium "
                         f"near its operating point ({exc})") from None

    def modes(eq) -> list[dict]:
        return [m.as_dict() for m in eq.modes]

    equilibria = []
    for e in eqs:
        item = {"q": dict(zip(coords, e.q.tolist())), "stable": e.stable}
        item.update(_constraint_rank(system, values, e.q))
        if e.stable or oscillatory_instability(e.eigenvalues):
            # a self-excited mode has a frequency and a negative damping ratio
            item["modes"] = modes(e)
        if not e.stable:
            item["eigenvalues"] = [[s.real, s.imag] for s in e.eigenvalues]
        equilibria.append(item)
    doc = {
        "system": system.id, "title": system.title, "source": system.source,
        "coordinates": coords, "parameters": values, "derived_parameters": list(derived),
        "equilibria": equilibria,
        "operating_point": dict(zip(coords, op.q.tolist())),
        "linearization": {"q": dict(zip(coords, op.q.tolist())), "M": op.M, "C": op.C,
                          "K": op.K},
        "stable": op.stable,
        "modes": modes(op),
        "printed_vs_derived": [e.as_dict() for e in errata(system)],
    }
    if not op.stable:
        doc["growth_rate"] = float(max(s.real for s in op.eigenvalues))
    if system.continuum:
        _continuum(system, values, op, doc)
    if system.driven:
        _parametric_stability(system, values, coords, doc)
    if op.acceleration is not None:
        doc["static_equilibrium"] = None
        doc["relative_equilibrium"] = _relative_equilibrium(system, coords, op)
    if system.stability_parameter:
        from .analytic.stability import stability_threshold

        doc["stability_threshold"] = stability_threshold(system, values).as_dict()
    if system.driven:
        from .analytic.steady_state import steady_state

        response = steady_state(system, values)
        doc["free_coordinates"] = list(system.mechanism.independent_coordinates)
        doc["prescribed"] = {p.coordinate: str(p.motion) for p in system.mechanism.prescribed}
        doc["linearization"]["about"] = ("rest state of the free coordinates with the "
                                         "excitation off: " + ", ".join(
                                             f"{k} = {v:g}" for k, v in system.unexcited.items()))
        doc["steady_state"] = [h.as_dict() for h in response.harmonics]
        if response.reason:
            doc["steady_state_note"] = response.reason
        else:
            doc["steady_state_harmonic_residual"] = response.harmonic_residual
    if system.points(system.symbols):
        doc["points"] = _points_report(system, values)
    if system.published(system.symbols):
        from .analytic.published import compare_published

        # what the sources publish (a benchmark's solution) against the reference
        doc["published"] = compare_published(system, values)
    return doc


def _continuum(system, values: dict, op, doc: dict) -> None:
    """A discretized continuum (monograph §6, `System.continuum`): the exact continuum's
    first frequencies (`continuum`), the printed Rayleigh estimates against the exact
    first frequency (`rayleigh`), and the chain's error against the continuum at this
    number of elements, with the leading error C_n / N^2 derived for its lumping."""
    from .analytic.continuum import continuum_summary
    from .analytic.discretization import structural_parameter

    summary = continuum_summary(system.continuum, values)
    name = structural_parameter(system)
    N = int(values[name])
    chain = [m.frequency_hz for m in op.modes if m.frequency_hz > 0][:len(summary.frequency_hz)]
    doc["continuum"] = summary.as_dict()
    doc["continuum"]["discretization"] = {
        "parameter": name, name: N, "frequency_hz": chain,
        "relative_error": [(f - e) / e for f, e in zip(chain, summary.frequency_hz)],
        "predicted_relative_error": (None if summary.leading_error is None else
                                     [c / N**2 for c in summary.leading_error[:len(chain)]]),
    }
    doc["rayleigh"] = [r.as_dict() for r in summary.rayleigh]


def _parametric_stability(system, values: dict, coords: list, doc: dict) -> None:
    """A parametric-only excitation (monograph §8.4; analytic.floquet.parametrically_excited):
    the rest states of the unexcited system stay solutions with the excitation on, and the
    excitation makes their variational equations' coefficients periodic, so each rest state
    is judged by its Floquet multipliers over one excitation period: `floquet_multipliers`,
    `floquet` and `stable` of each equilibrium (and `floquet_multipliers`,
    `operating_point_floquet` and `stable` of the operating point) are Floquet's;
    the linearization and its modes stay those with the excitation off."""
    import numpy as np

    from .analytic.floquet import driven_floquet, parametrically_excited

    if not parametrically_excited(system, values):
        return
    results = driven_floquet(system, values)
    doc["parametric_excitation"] = (
        "the excitation makes the coefficients of the variational equations about the rest "
        "states periodic in time (monograph §8.4): 'stable' is Floquet's verdict over one "
        "excitation period; the linearization and modes are those with the excitation off")
    for item in doc["equilibria"] + [None]:
        q = np.array([(item["q"] if item else doc["operating_point"])[c] for c in coords])
        match = [r for rest, r in results if np.allclose(rest, q, atol=1e-6)
                 or np.allclose(np.mod(rest - q + np.pi, 2 * np.pi) - np.pi, 0, atol=1e-6)]
        if not match:
            continue
        floquet = match[0].as_dict()
        target = item if item is not None else doc
        target["floquet_multipliers"] = floquet["floquet_multipliers"]
        # the document's own "floquet" names a periodic-coefficient system's list
        target["floquet" if item is not None else "operating_point_floquet"] = floquet
        target["stable"] = match[0].stable


def _floquet_document(system, values: dict, derived, reason: str, floquet: list) -> dict:
    """`analyze` of a driven system whose variational equations have periodic coefficients
    (no constant linearization): the Floquet multipliers about each unexcited rest state
    over one excitation period."""
    from .analytic.errata import errata

    return {
        "system": system.id, "title": system.title, "source": system.source,
        "coordinates": list(system.coordinates), "parameters": values,
        "derived_parameters": list(derived),
        "free_coordinates": list(system.mechanism.independent_coordinates),
        "prescribed": {p.coordinate: str(p.motion) for p in system.mechanism.prescribed},
        "linearization": None,
        "periodic_coefficients": reason,
        "floquet": floquet,
        "stable": bool(floquet) and all(r["verdict"] == "stable" for r in floquet),
        "printed_vs_derived": [e.as_dict() for e in errata(system)],
    }


def _relative_equilibrium(system, coords: list, op) -> dict:
    """What `analyze` says of a floating mechanism (Italian notes §5.3.1)."""
    acceleration = dict(zip(coords, op.acceleration.tolist()))
    rigid = [dict(zip(coords, col.tolist())) for col in op.rigid.T]
    moving = ", ".join(f"{c}'' = {a:.9g}" for c, a in acceleration.items() if a)
    return {
        "acceleration": acceleration,
        "rigid_directions": rigid,
        "note": ((f"no static equilibrium in absolute coordinates: {system.id} has no "
                  f"ground, and its loads have a resultant that only the inertia of the "
                  f"whole balances ({moving}); reported instead: the relative equilibrium "
                  f"(Italian notes §5.3.1), the configuration that moves rigidly with that "
                  f"uniform acceleration, linearized about that motion"
                  if moving else
                  f"{system.id} has no ground, and its loads have no resultant here: its "
                  f"relative equilibrium (Italian notes §5.3.1) is at rest")
                 + "; its rigid-body mode has zero frequency, and 'stable' judges the "
                   "relative motion"),
    }


def checked_simulators(simulators: Iterable[str], installed: bool = False) -> list[str]:
    """The engine ids, each known (and, with `installed`, installed), or a ValueError in
    one line naming the valid ones: the one check every command makes."""
    ids = list(simulators)
    for e in ids:
        backend = _backend(e)
        if installed:
            ok, why = backend.available()
            if not ok:
                raise ValueError(f"{e} is not installed: {why}")
    return ids


def list_systems() -> dict:
    """What `mbfidelity list --json` prints: every system with its scenarios, variants
    and, per engine, whether it can express it (and why not)."""
    from .simulators import all_backends
    from .systems import all_systems

    backends = all_backends()
    rows = []
    for s in all_systems().values():
        mech = s.numeric_mechanism(s.parameter_values())
        support = {}
        for sid, b in backends.items():
            ok, why = b.available()
            sup = b.support(mech) if ok else None
            support[sid] = {"supported": bool(ok and sup.ok),
                            "reason": why if not ok else (sup.reason if not sup.ok else "")}
        rows.append({"system": s.id, "group": s.group, "title": s.title, "source": s.source,
                     "coordinates": list(s.coordinates),
                     "scenarios": [sc.name for sc in s.scenarios], "simulators": support,
                     "variants": {v.name: {"simulators": list(v.settings),
                                           "description": v.description}
                                  for v in s.variants}})
    return {"systems": rows, "simulators": list(backends)}


def errata(witnesses: bool = True, out: str | Path | None = None) -> list[dict]:
    """Every printed formula the project codes against the derivation, with the engines
    as witnesses of every misprint (`witnesses`); with `out`, errata.json and errata.html
    are written there."""
    from .comparisons.witnesses import witnessed_errata
    from .systems import all_systems

    if out is not None:
        out = checked_output_folder(out)
    entries = witnessed_errata(all_systems().values(), witnesses)
    if out is not None:
        from .comparisons.results_folder import save_errata
        from .reports.html import write_errata_page

        save_errata(entries, out)
        write_errata_page(out)
    return entries


STRUTT_EQUATION = "phi'' + (lambda + gamma cos t) phi = 0 (eq. 83, omega = 1)"


def strutt(grid: int = 40, lambda_range: tuple[float, float] = (-1.0, 3.0),
           gamma_range: tuple[float, float] = (0.0, 3.0), sims: Iterable[str] = (), *,
           scheduler: str | None = None, steps_per_period: int = 200, periods: int = 10,
           out: str | Path | None = None) -> dict:
    """The Strutt chart of eq. 83 from Floquet theory on a grid x grid chart, and with
    `sims` each engine's classification of every point by simulation; with `out`,
    strutt.json and strutt.png are written there."""
    import json

    import numpy as np

    from .analytic.strutt import strutt_chart

    engines = checked_simulators(sims, installed=True)
    for name, (a, b) in (("lambda", lambda_range), ("gamma", gamma_range)):
        if not (math.isfinite(a) and math.isfinite(b) and a <= b):
            raise ValueError(f"the {name} range must be finite A <= B, got {a:g}, {b:g}")
    if grid < 1:
        raise ValueError(f"the grid must have at least 1 point per axis, got {grid}")
    if engines and (steps_per_period < 4 or periods < 1):
        raise ValueError("steps per period must be at least 4 and periods at least 1")
    if out is not None:
        out = checked_output_folder(out)
    chart = strutt_chart(grid, grid, tuple(lambda_range), tuple(gamma_range))
    points = chart.points()
    counts = {v: sum(p["verdict"] == v for p in points)
              for v in ("stable", "unstable", "marginal")}
    doc = {"equation": STRUTT_EQUATION, "period": 2 * np.pi, "grid": grid, "counts": counts,
           "points": points}
    if engines:
        from .comparisons.strutt_engines import engine_chart

        doc["simulation"] = engine_chart(points, engines, scheduler=scheduler,
                                         periods=periods, steps_per_period=steps_per_period)
    if out is not None:
        from .reports.strutt_figure import write_strutt_figure

        out.mkdir(parents=True, exist_ok=True)
        (out / "strutt.json").write_text(json.dumps(doc, indent=1))
        write_strutt_figure(points, out / "strutt.png")
    return doc


def discretization(system_id: str, params: Mapping[str, float] | None = None,
                   counts: Iterable[int] = (2, 4, 8, 16, 32), sims: Iterable[str] = (), *,
                   out: str | Path | None = None) -> dict:
    """A discretized continuum against its exact one for each number of elements (the
    frequencies, their errors, the fitted order, the printed Rayleigh estimates); with
    `sims`, each engine's build of the chain from its own linearization, and each
    engine's own flexible elements for a beam. `failed` lists the engine rows that miss
    their gate. With `out`, discretization-SYSTEM.json and .png are written there."""
    import json

    from .analytic.continuum import continuum_summary
    from .analytic.discretization import discretization_study

    system = _system(system_id)
    try:
        values, _ = system.resolve_parameters(params)
    except KeyError as exc:
        raise ValueError(exc.args[0]) from None
    engines = checked_simulators(sims)
    if out is not None:
        out = checked_output_folder(out)
    study = discretization_study(system, values, list(counts))
    doc = study.as_dict()
    doc["rayleigh"] = [r.as_dict() for r in
                       continuum_summary(system.continuum, values).rayleigh]
    if engines:
        from .comparisons.discretization_engines import engine_discretization
        from .comparisons.flexible_beams import beam_of, beam_study

        doc["engines"] = engine_discretization(system, values, study, engines)
        beam = beam_of(system.continuum, values)
        if beam is not None:
            # the variants: the same beam of each engine's own flexible elements (no
            # gravity: modal work about the straight beam)
            doc["flexible"] = beam_study(beam, engines, list(counts))
    doc["failed"] = [f"{e}@{study.parameter}={r['N']}"
                     for e, x in doc.get("engines", {}).items()
                     for r in x["rows"] if not r["passed"]]
    if out is not None:
        from .reports.discretization_figure import figure_name, write_discretization_figure

        out.mkdir(parents=True, exist_ok=True)
        (out / f"discretization-{study.system}.json").write_text(json.dumps(doc, indent=1))
        write_discretization_figure(doc, out / figure_name(study.system))
    return doc


def convergence(systems: Iterable[str] | None = None, sims: Iterable[str] | None = None,
                steps: Iterable[float] | None = None, t_end: float = 2.0, *,
                scheduler: str | None = None, out: str | Path | None = None,
                knob: str = "auto") -> dict:
    """Error against the step and work-precision for every system x engine (default:
    every installed engine), the fitted order against the declared one; an
    error-controlled engine by its target accuracy (`knob` "auto"; "step" runs it at
    fixed steps too); `failed` lists the studies whose gate fails. With `out`,
    convergence.json, its page and figures are written there."""
    import json

    import numpy as np

    from .comparisons import convergence as conv
    from .comparisons.runner import provenance
    from .simulators import all_backends
    from .systems import all_systems

    sys_ids = list(systems or all_systems())
    for s in sys_ids:
        _system(s)
    sim_ids = (checked_simulators(sims) if sims else
               [e for e, b in all_backends().items() if b.available()[0]])
    dts = None
    if steps is not None:
        dts = sorted(set(steps), reverse=True)
        if len(dts) < conv.MIN_FIT_POINTS or not all(np.isfinite(d) and d > 0 for d in dts):
            raise ValueError(f"the steps need at least {conv.MIN_FIT_POINTS} positive values; "
                             f"got {list(steps)}")
    checked_duration("t_end", t_end)
    if out is not None:
        out = checked_output_folder(out)
    if knob not in ("auto", "step"):
        raise ValueError(f"the knob is 'auto' or 'step'; got {knob!r}")
    studies = conv.convergence_matrix(sys_ids, sim_ids, dts, t_end, scheduler=scheduler,
                                      knob=knob)
    doc = {"provenance": provenance(), "steps": dts or "automatic", "t_end": t_end,
           "knob": knob, "accuracies": list(conv.DEFAULT_ACCURACIES),
           "min_accuracy_decrease": conv.tolerances.MIN_ACCURACY_DECREASE,
           "order_tolerance": conv.ORDER_TOLERANCE, "min_decrease": conv.MIN_DECREASE,
           "reference_margin": conv.REFERENCE_MARGIN, "studies": studies}
    doc["failed"] = [f"{s['system']}/{s['simulator']}" for s in studies
                     if s["metric"]["status"] in ("fail", "xpass")
                     or (s["metric"]["status"] == "unresolved"
                         and not s["metric"].get("expected"))]
    if out is not None:
        from .reports.convergence_page import CONVERGENCE, write_convergence_page

        out.mkdir(parents=True, exist_ok=True)
        (out / CONVERGENCE).write_text(json.dumps(doc, indent=1, default=jsonable))
        write_convergence_page(out)
    return doc


def benchmark_errors(systems: Iterable[str] | None = None,
                     sims: Iterable[str] | None = None, dt: float | None = None) -> dict:
    """Each engine's error as the benchmark defines it (`System.benchmark_error`) and its
    CPU seconds of stepping, at its default settings and the step `dt` (None: each row's
    own step, `System.step`, else DEFAULT_DT; every row states the step it ran), over each
    benchmark row's whole scenario (default: every row that declares a measure, every
    installed engine); a run that does not complete is reported with its status and the
    system's declared reason. `rows` lists them in system x engine order."""
    import numpy as np

    from .comparisons.benchmark_error import default_step_error
    from .comparisons.runner import provenance
    from .simulators import all_backends
    from .systems import all_systems

    sys_ids = list(systems) if systems else [
        s for s in all_systems() if _system(s).benchmark_error is not None]
    for s in sys_ids:
        if _system(s).benchmark_error is None:
            raise ValueError(f"{s} declares no benchmark error measure")
    sim_ids = (checked_simulators(sims) if sims else
               [e for e, b in all_backends().items() if b.available()[0]])
    if dt is not None and not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"the step must be positive; got {dt}")
    rows = [default_step_error(s, e, dt) for s in sys_ids for e in sim_ids]
    return {"provenance": provenance(), "dt": dt, "rows": rows}


def jsonable(x):
    """A JSON encoder's `default` for the NumPy values and complex numbers of the
    documents the API returns."""
    import numpy as np

    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, complex):
        return [x.real, x.imag]
    raise TypeError(type(x))


def beams(sims: Iterable[str] | None = None, elements: Iterable[int] = (2, 4, 8, 16, 32),
          params: Mapping[str, float] | None = None, modes: int = 3, *,
          out: str | Path | None = None) -> dict:
    """The engines' own flexible elements against the exact beam of §6.1 (default: the
    block of 0 and 1 kg at mid-span): the first `modes` natural frequencies of the beam
    built of N elements of each kind, their errors and fitted orders. With `out`,
    beams.json and beams.png are written there."""
    import json

    from .comparisons.flexible_beams import DEFAULT_CASES, beams_document
    from .systems._continua import Beam

    engines = checked_simulators(sims or ())
    sizes = sorted(set(int(n) for n in elements))
    if not sizes or any(n < 1 for n in sizes):
        raise ValueError(f"the numbers of elements must be positive integers; got {sizes}")
    if modes < 1:
        raise ValueError("modes must be at least 1")
    given = dict(params or {})
    cases = [given] if "m" in given else [{**case, **given} for case in DEFAULT_CASES]
    try:
        beam_list = [Beam.from_parameters(case) for case in cases]
    except TypeError as exc:
        raise ValueError(str(exc)) from None
    if out is not None:
        out = checked_output_folder(out)
    doc = beams_document(beam_list, engines or None, sizes, modes)
    if out is not None:
        from .reports.beams_figure import BEAMS, FIGURE, write_beams_figure

        out.mkdir(parents=True, exist_ok=True)
        (out / BEAMS).write_text(json.dumps(doc, indent=1, default=jsonable))
        write_beams_figure(json.loads((out / BEAMS).read_text()), out / FIGURE)
    return doc


def compare(system_id: str, simulator: str, params: Mapping[str, float] | None = None, *,
            dt: float | None = None, t_end: float | None = None,
            settings: Mapping | None = None, variant: str | None = None,
            timeout: float | None = 900.0) -> Comparison:
    """One system on one engine: every scenario's metrics against their gates. The engine
    runs in a worker process; a crash or a run past `timeout` seconds is recorded as an
    incident of a failed comparison (None: in this process, no time limit)."""
    from .comparisons.runner import compare as compare_here
    from .comparisons.runner import isolated_compare

    system = _system(system_id)
    backend = _backend(simulator)
    ok, why = backend.available()
    if not ok:
        raise ValueError(f"{simulator} is not installed: {why}")
    _checked_parameters(system, params)
    checked_duration("dt", dt)
    checked_duration("t_end", t_end)
    checked_duration("timeout", timeout)
    if timeout is None:
        return compare_here(system.id, simulator, params, dt=dt, t_end=t_end,
                            settings=settings, variant=variant)
    return isolated_compare(system.id, simulator, params, dt=dt, t_end=t_end,
                            timeout=timeout, settings=settings, variant=variant)


def _matrix(systems: Iterable[str] | None, sims: Iterable[str] | None,
            installed_only: bool) -> tuple[list[str], list[str]]:
    from .simulators import all_backends
    from .systems import all_systems

    sys_ids = list(systems or all_systems())
    for s in sys_ids:
        _system(s)
    backends = all_backends()
    if sims:
        sim_ids = checked_simulators(sims, installed=True)
    else:
        sim_ids = [e for e, b in backends.items() if b.available()[0] or not installed_only]
    return sys_ids, sim_ids


def _validated_settings(settings: Mapping[str, Mapping] | None) -> dict[str, dict]:
    out = {}
    for engine, chosen in (settings or {}).items():
        backend = _backend(engine)
        try:
            backend.resolve_settings(chosen)
        except (KeyError, ValueError) as exc:
            raise ValueError(f"settings for {engine}: {exc.args[0] if exc.args else exc}") \
                from None
        out[engine] = dict(chosen)
    return out


def run(systems: Iterable[str] | None = None, sims: Iterable[str] | None = None,
        out: str | Path | None = None, *, dt: float | None = None,
        settings: Mapping[str, Mapping] | None = None, variants: bool = False,
        resume: bool = False, report: bool = True,
        scheduler: str | None = None, progress=None) -> list[Comparison]:
    """The matrix systems x engines (default: all of both). With `out`, the results
    (results.json, results.csv) and, with `report`, the HTML report are written there.
    `settings` maps an engine to its settings; `scheduler`, a Dask scheduler's address,
    runs the systems on that cluster (same results as the local pool). A failure of one
    system x engine is an incident of that comparison; the others complete. Two runs into
    one folder at once are refused (the second one, in one line)."""
    from .comparisons.matrix import run_matrix, write_results

    from .comparisons.results_folder import exclusive

    sys_ids, sim_ids = _matrix(systems, sims, installed_only=False)
    checked_duration("dt", dt)
    chosen = _validated_settings(settings)
    if out is None:
        return run_matrix(sys_ids, sim_ids, dt=dt, variants=variants, out=None,
                          settings=chosen, scheduler=scheduler, progress=progress)
    out = checked_output_folder(out)
    with exclusive(out):
        results = run_matrix(sys_ids, sim_ids, dt=dt, variants=variants, out=out,
                             resume=resume, settings=chosen, scheduler=scheduler,
                             progress=progress)
        write_results(results, out)
        if report:
            from .reports.html import write_report

            write_report(out)
    return results


@dataclass
class Verdict:
    """One system on one engine in a check."""
    system: str
    simulator: str
    engine_version: str
    #: pass | fail | unsupported
    verdict: str
    #: the metrics that failed the comparison
    failing: list[str] = field(default_factory=list)
    reason: str = ""
    incidents: list[str] = field(default_factory=list)


@dataclass
class CheckResult:
    passed: bool
    results: str
    verdicts: list[Verdict]
    diff: ResultsDiff | None = None

    def as_dict(self) -> dict:
        return {"passed": self.passed, "results": self.results,
                "verdicts": [asdict(v) for v in self.verdicts],
                "diff": self.diff.as_dict() if self.diff else None}


def check(systems: Iterable[str] | None = None, sims: Iterable[str] | None = None,
          out: str | Path = "mbfidelity-check", *, baseline: str | Path | None = None,
          dt: float | None = None, settings: Mapping[str, Mapping] | None = None,
          report: bool = False) -> CheckResult:
    """The gates against the installed engines (default: every installed one): a verdict
    per system x engine and the results in `out`. Passed when every gate passes or is
    declared and, with a `baseline` (a results folder or results.json), none got worse
    than there."""
    if baseline is not None:
        from .comparisons.diff import load_run

        load_run(Path(baseline))  # a ValueError now, before the work, if it is not one
    checked_output_folder(out)
    results = run(*_matrix(systems, sims, installed_only=True), out=out, dt=dt,
                  settings=settings, report=report)
    verdicts = [Verdict(c.system, c.simulator, c.engine_version, c.verdict,
                        [m.name for m in c.metrics if not holds(m)], c.reason,
                        [i["outcome"] for i in c.incidents])
                for c in results]
    changes = diff_runs(Path(baseline), Path(out)) if baseline is not None else None
    passed = all(v.verdict != "fail" for v in verdicts) and not (changes and changes.worse)
    return CheckResult(passed, str(Path(out).resolve()), verdicts, changes)


def diff(old: str | Path, new: str | Path) -> ResultsDiff:
    """What changed between two runs (results folders or results.json files)."""
    return diff_runs(Path(old), Path(new))


def export(system_id: str, simulator: str = "mujoco", params: Mapping[str, float] | None = None,
           *, settings: Mapping | None = None, dt: float | None = None) -> tuple[str, list[str]]:
    """(the engine's model file as text, what the file alone does not reproduce): MuJoCo's
    MJCF with a keyframe per scenario and the coordinate map."""
    from .comparisons.export import export_model

    system = _system(system_id)
    _backend(simulator)
    _checked_parameters(system, params)
    checked_duration("dt", dt)
    return export_model(system.id, simulator, params, settings, dt)


# --- gate power (comparisons/power.py) ---------------------------------------------------


def power(systems: Iterable[str] | None = None, sims: Iterable[str] | None = None,
          out: str | Path | None = None, *, dt: float | None = None,
          workers: int | None = None, progress=None, record: str | Path | None = None):
    """The power study (comparisons/power.py) of systems x engines (default: all systems,
    every installed engine): per injected model error the smallest relative error the
    gates reject, per neutralised default whether they reject it, both from one
    neutralised run per system x engine (comparisons/out_of_the_box.py); one job per
    system in a pool of `workers` processes (default: up to 2), the longest first. With
    `record` (the power.json of an earlier study, plain or gzip-compressed), each reading
    it holds made with the installed engine's version at the same step is taken from it
    (marked with the state of the package that made it) and only the others are made. With
    `out`, power.json and out_of_the_box.json and their pages (power.html,
    out_of_the_box.html) are written there; where the folder holds a run's results, its
    site is written again (as `out_of_the_box`). Returns the `OutOfTheBoxStudy`, whose
    `power_document()` is power.json."""
    import json

    from .comparisons.matrix import schedule
    from .comparisons.out_of_the_box import out_of_the_box_study, read_record
    from .comparisons.power import ERROR_KINDS
    from .comparisons.results_folder import load_job_costs

    sys_ids, sim_ids = _matrix(systems, sims, installed_only=True)
    checked_duration("dt", dt)
    folder = checked_output_folder(out) if out is not None else None
    recorded = read_record(record) if record is not None else None
    order = schedule(sys_ids, load_job_costs(folder) if folder is not None else None)
    study = out_of_the_box_study(sys_ids, sim_ids, dt, workers=workers, order=order,
                                 progress=progress, kinds=tuple(ERROR_KINDS),
                                 record=recorded)
    if folder is not None:
        from .reports.power_page import OUT_OF_THE_BOX, POWER, write_power_pages

        folder.mkdir(parents=True, exist_ok=True)
        (folder / POWER).write_text(json.dumps(study.power_document(), indent=1,
                                               default=jsonable))
        (folder / OUT_OF_THE_BOX).write_text(json.dumps(study.as_dict(), indent=1,
                                                        default=jsonable))
        write_power_pages(folder)
        if (folder / "results.json").exists():
            from .reports.html import write_report

            write_report(folder)
    return study


def out_of_the_box(systems: Iterable[str] | None = None, sims: Iterable[str] | None = None,
                   out: str | Path | None = None, *, dt: float | None = None,
                   workers: int | None = None, defaults: Iterable[str] | None = None,
                   progress=None):
    """The out-of-the-box study (comparisons/out_of_the_box.py) of systems x engines
    (default: all systems, every installed engine): each engine default the harness
    neutralises switched back on alone and all together, its verdict and its effect
    against the neutralised run; one job per system in a pool of `workers` processes
    (default: up to 2), the longest first. `defaults` names the defaults switched on
    (each alone; default: every one, and all together). With `out`, out_of_the_box.json and
    out_of_the_box.html are written there; where the folder holds a run's results, its
    site is written again so that each mechanism's page shows its row (`mbfidelity run`
    into the folder afterwards does the same). Returns the `OutOfTheBoxStudy`."""
    import json

    from .comparisons.matrix import schedule
    from .comparisons.out_of_the_box import engine_defaults, out_of_the_box_study
    from .comparisons.results_folder import load_job_costs

    sys_ids, sim_ids = _matrix(systems, sims, installed_only=True)
    checked_duration("dt", dt)
    if defaults is not None:
        defaults = list(defaults)
        known = {k for sim in sim_ids for k in engine_defaults(sim, dt)}
        unknown = [k for k in defaults if k not in known]
        if unknown:
            raise ValueError(f"no engine among {', '.join(sim_ids)} neutralises "
                             f"{', '.join(unknown)}; its neutralised defaults: "
                             f"{', '.join(sorted(known)) or 'none'}")
    folder = checked_output_folder(out) if out is not None else None
    order = schedule(sys_ids, load_job_costs(folder) if folder is not None else None)
    study = out_of_the_box_study(sys_ids, sim_ids, dt, workers=workers, order=order,
                                 progress=progress, only=defaults)
    if folder is not None:
        from .reports.power_page import OUT_OF_THE_BOX, write_out_of_the_box_page

        folder.mkdir(parents=True, exist_ok=True)
        (folder / OUT_OF_THE_BOX).write_text(json.dumps(study.as_dict(), indent=1,
                                                        default=jsonable))
        write_out_of_the_box_page(folder)
        if (folder / "results.json").exists():
            from .reports.html import write_report

            write_report(folder)
    return study
