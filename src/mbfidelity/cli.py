"""Command line (DESIGN.md): list, analyze, compare, run, errata."""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import List, Optional

import numpy as np
import typer

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="Cross-validate multibody simulators against exact models.")


def _fail(message: str) -> None:
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(2)


def _parse_params(items: Optional[List[str]]) -> dict[str, float]:
    out = {}
    for item in items or []:
        if "=" not in item:
            _fail(f"--param expects NAME=VALUE, got {item!r}")
        name, value = item.split("=", 1)
        try:
            out[name.strip()] = float(value)
        except ValueError:
            _fail(f"--param {name}: {value!r} is not a number")
    return out


def _system(system_id: str):
    from .systems import get_system

    try:
        return get_system(system_id)
    except KeyError as exc:
        _fail(exc.args[0])


def _values(system, params, scenarios=()):
    """(values, names of the parameters derived from their default's formula); every
    parameter set the command will use (with each scenario's values) is checked first:
    a bad one ends the command with one line (exit 2)."""
    try:
        for sc in scenarios:
            system.parameter_values(params, scenario=sc)
        return system.resolve_parameters(params)
    except (KeyError, ValueError) as exc:
        _fail(exc.args[0])


def _json(doc) -> None:
    typer.echo(json.dumps(doc, indent=1, default=_jsonable))


def _jsonable(x):
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, complex):
        return [x.real, x.imag]
    raise TypeError(type(x))


@app.command("list")
def list_(as_json: bool = typer.Option(False, "--json", help="print JSON")) -> None:
    """Systems, engines, and which engine supports which system."""
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
        rows.append({"system": s.id, "title": s.title, "source": s.source,
                     "coordinates": list(s.coordinates),
                     "scenarios": [sc.name for sc in s.scenarios], "simulators": support,
                     "variants": {v.name: {"simulators": list(v.settings),
                                           "description": v.description}
                                  for v in s.variants}})
    if as_json:
        _json({"systems": rows, "simulators": list(backends)})
        return
    typer.echo(f"{'system':26s} " + " ".join(f"{b:9s}" for b in backends) + " source")
    for r in rows:
        marks = " ".join(f"{'yes' if r['simulators'][b]['supported'] else 'no':9s}"
                         for b in backends)
        typer.echo(f"{r['system']:26s} {marks} {r['source']}")
        for b in backends:
            if not r["simulators"][b]["supported"] and r["simulators"][b]["reason"]:
                typer.echo(f"  {b} unsupported: {r['simulators'][b]['reason']}")
        for name, v in r["variants"].items():
            typer.echo(f"  variant {name}: {', '.join(v['simulators'])}")


def _use_cache(off: bool) -> None:
    if off:
        from .analytic import cache

        cache.disable()


def _modes(eq):
    return [m.as_dict() for m in eq.modes]


def _floquet_analysis(system, values, derived, reason: str, as_json: bool) -> None:
    """`analyze` of a periodic-coefficient driven system: the Floquet multipliers of the
    variational equations about each unexcited rest state over one excitation period."""
    from .analytic.errata import errata
    from .analytic.floquet import driven_floquet_summary

    floquet = driven_floquet_summary(system, values)
    doc = {
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
    if as_json:
        _json(doc)
        return
    typer.echo(f"{system.id}: {system.title} ({system.source})")
    typer.echo("parameters: " + ", ".join(f"{k}={v:g}" for k, v in values.items()))
    typer.echo(f"periodic coefficients: {reason}")
    for item in doc["floquet"]:
        typer.echo(f"Floquet about {item['q']} over T = {item['period']:.9g} s: "
                   f"{item['verdict']} (|multipliers| = "
                   + ", ".join(f"{m:.9g}" for m in item["moduli"]) + ")")


@app.command()
def analyze(system_id: str = typer.Argument(..., metavar="SYSTEM"),
            param: Optional[List[str]] = typer.Option(None, "--param", help="NAME=VALUE"),
            as_json: bool = typer.Option(False, "--json"),
            no_cache: bool = typer.Option(False, "--no-cache", help="recompute the derivations "
                                          "instead of reading the persistent cache"),
            ) -> None:
    """Equilibria with stability, M, K, C, modes, printed-vs-derived comparison."""
    from .analytic.errata import errata
    from .analytic.floquet import periodic_coefficients
    from .analytic.linear import find_equilibria, operating_equilibrium

    _use_cache(no_cache)
    system = _system(system_id)
    values, derived = _values(system, _parse_params(param))
    coords = list(system.coordinates)
    try:
        eqs = find_equilibria(system, values)
        op = operating_equilibrium(system, values)
    except (ValueError, TypeError, RuntimeError, np.linalg.LinAlgError) as exc:
        if system.driven and periodic_coefficients(system, values):
            _floquet_analysis(system, values, derived, str(exc), as_json)
            return
        _fail(f"{system.id} with these parameters has no assembled equilibrium near its "
              f"operating point ({exc})")
    equilibria = []
    for e in eqs:
        item = {"q": dict(zip(coords, e.q.tolist())), "stable": e.stable}
        if e.stable:
            item["modes"] = _modes(e)
        else:
            item["eigenvalues"] = [[s.real, s.imag] for s in e.eigenvalues]
        equilibria.append(item)
    doc = {
        "system": system.id, "title": system.title, "source": system.source,
        "coordinates": coords, "parameters": values, "derived_parameters": list(derived),
        "equilibria": equilibria,
        "operating_point": dict(zip(coords, op.q.tolist())),
        "linearization": {"q": dict(zip(coords, op.q.tolist())), "M": op.M, "C": op.C, "K": op.K},
        "stable": op.stable,
        "modes": _modes(op),
        "printed_vs_derived": [e.as_dict() for e in errata(system)],
    }
    if op.acceleration is not None:
        doc["static_equilibrium"] = None
        doc["relative_equilibrium"] = _relative_note(system, coords, op)
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
    if as_json:
        _json(doc)
        return
    typer.echo(f"{system.id}: {system.title} ({system.source})")
    typer.echo("parameters: " + ", ".join(f"{k}={v:g}" for k, v in values.items()))
    formulas = {p.name: p.default for p in system.all_parameters}
    if derived:
        typer.echo("derived: " + ", ".join(f"{k} = {formulas[k]}" for k in derived))
    if "relative_equilibrium" in doc:
        typer.echo(doc["relative_equilibrium"]["note"])
    for e in equilibria:
        kind = "relative equilibrium" if "relative_equilibrium" in doc else "equilibrium"
        typer.echo(f"{kind} {e['q']}: {'stable' if e['stable'] else 'unstable'}")
    typer.echo(f"at {doc['operating_point']}:")
    for key in ("M", "C", "K"):
        typer.echo(f"  {key} = {np.array2string(getattr(op, key), precision=6)}")
    for m in op.modes:
        typer.echo(f"  mode: f = {m.frequency_hz:.9g} Hz, zeta = {m.damping_ratio:.6g}, "
                   f"f_d = {m.damped_frequency_hz:.9g} Hz")
    if not op.stable:
        growth = max(s.real for s in op.eigenvalues)
        typer.echo(f"  unstable: fastest growth rate {growth:.9g} 1/s")
    if "stability_threshold" in doc:
        th = doc["stability_threshold"]
        if th["value"] is None:
            typer.echo(f"  stability: no change of stability for {th['parameter']} in "
                       f"[{th['scanned'][0]:g}, {th['scanned'][1]:g}]")
        else:
            side = "above" if th["stable_above"] else "below"
            typer.echo(f"  stability threshold: {th['parameter']} = {th['value']:.12g} "
                       f"(stable {side})")
    for h in doc.get("steady_state", []):
        typer.echo(f"  steady state {h['quantity']} {h['coordinate']}: "
                   f"{h['amplitude']:.9g} at {h['frequency_hz']:.9g} Hz, "
                   f"phase {h['phase']:.6g} rad")
    if "steady_state_note" in doc:
        typer.echo(f"  steady state: none ({doc['steady_state_note']})")
    for e in doc["printed_vs_derived"]:
        typer.echo(f"  {e['label']}: {e['verdict']} ({e['max_relative_difference']:.1e})")


def _relative_note(system, coords: list, op) -> dict:
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


def _settings(items: Optional[List[str]]) -> dict:
    out = {}
    for item in items or []:
        if "=" not in item:
            _fail(f"--setting expects KEY=VALUE, got {item!r}")
        k, v = item.split("=", 1)
        try:
            out[k] = json.loads(v)
        except json.JSONDecodeError:
            out[k] = v
    return out


@app.command("compare")
def compare_cmd(system_id: str = typer.Argument(..., metavar="SYSTEM"),
                sim: str = typer.Option(..., "--sim", help="mujoco | pybullet | exudyn | pymunk"),
                param: Optional[List[str]] = typer.Option(None, "--param", help="NAME=VALUE"),
                dt: float = typer.Option(1e-3, "--dt", help="time step, s"),
                t_end: Optional[float] = typer.Option(None, "--t-end", help="simulated time, s"),
                setting: Optional[List[str]] = typer.Option(
                    None, "--setting", help="engine setting KEY=VALUE (JSON value)"),
                variant: Optional[str] = typer.Option(
                    None, "--variant", help="build the system's named variant (e.g. contact)"),
                as_json: bool = typer.Option(False, "--json"),
                timeout: float = typer.Option(
                    900.0, "--timeout", help="wall-clock budget of the comparison, s"),
                no_cache: bool = typer.Option(False, "--no-cache", help="recompute the "
                                              "derivations instead of reading the cache"),
                ) -> None:
    """One comparison: metrics, tolerances, pass/fail (the engine runs in a worker
    process: a crash or a run past --timeout is reported, exit 1)."""
    from .comparisons.runner import isolated_compare
    from .simulators import get_backend

    _use_cache(no_cache)
    system = _system(system_id)
    params = _parse_params(param)
    _values(system, params, system.scenarios)
    try:
        get_backend(sim)
    except KeyError as exc:
        _fail(exc.args[0])
    if not dt > 0 or (t_end is not None and not t_end > 0):
        _fail("--dt and --t-end must be positive")
    try:
        result = isolated_compare(system.id, sim, params, dt=dt, t_end=t_end, timeout=timeout,
                                  settings=_settings(setting), variant=variant)
    except ValueError as exc:
        _fail(str(exc))
    doc = result.as_dict()
    if as_json:
        _json(doc)
    else:
        shown = f"{result.system}[{result.variant}]" if result.variant else result.system
        typer.echo(f"{shown} on {result.simulator} {result.engine_version}, dt={dt:g}")
        if not result.supported:
            typer.echo(f"  unsupported: {result.reason}")
        said = set()
        for m in result.metrics:
            extra = f"  ({m.reason})" if m.reason and m.reason not in said else ""
            said.add(m.reason)
            typer.echo(f"  {m.name:34s} {m.value:10.3e} <= {m.tolerance:9.3e}  {m.status}{extra}")
        for i in result.incidents:
            at = f" at t = {i['t_reached']:.6g} s" if i.get("t_reached") is not None else ""
            typer.echo(f"  {i['scenario']}: {i['outcome']}{at}: {i['message']}")
        typer.echo("PASSED" if result.passed else "FAILED")
    raise typer.Exit(0 if result.passed else 1)


@app.command()
def run(systems: Optional[List[str]] = typer.Option(None, "--systems", help="system ids"),
        sims: Optional[List[str]] = typer.Option(None, "--sims", help="simulator ids"),
        out: Path = typer.Option(Path("results"), "--out", help="output folder"),
        dt: float = typer.Option(1e-3, "--dt"),
        variants: bool = typer.Option(False, "--variants/--no-variants",
                                      help="also run each system's variants (e.g. rolling by "
                                           "friction contact) on the engines that build them"),
        no_cache: bool = typer.Option(False, "--no-cache", help="recompute the derivations "
                                      "instead of reading the persistent cache"),
        resume: bool = typer.Option(False, "--resume", help="continue a killed run into "
                                    "--out: reuse the systems it finished"),
        ) -> None:
    """The whole matrix: results (CSV, JSON) and the HTML report."""
    _use_cache(no_cache)
    from rich.progress import Progress

    from .comparisons.matrix import reusable_jobs, run_matrix, write_results
    from .reports.html import write_report
    from .simulators import all_backends
    from .systems import all_systems

    sys_ids = _split(systems) or list(all_systems())
    sim_ids = _split(sims) or list(all_backends())
    for s in sys_ids:
        _system(s)
    for e in sim_ids:
        if e not in all_backends():
            _fail(f"unknown simulator {e!r}; valid: {', '.join(all_backends())}")
    if resume:
        reused = reusable_jobs(out, sys_ids, sim_ids, dt, variants)
        typer.echo(f"resuming: {len(reused)} of {len(sys_ids)} systems finished in {out}, "
                   f"reused")
    start = time.perf_counter()
    with Progress(transient=False, disable=not sys.stderr.isatty()) as progress:
        task = progress.add_task("comparisons", total=len(sys_ids) * len(sim_ids))

        def tick(c):
            progress.update(task, advance=1, description=f"{c.system} / {c.simulator}")
        results = run_matrix(sys_ids, sim_ids, dt=dt, progress=tick, variants=variants,
                             out=out, resume=resume)
    write_results(results, out)
    index = write_report(out)
    elapsed = time.perf_counter() - start
    failed = [f"{c.system}/{c.simulator}" for c in results if c.supported and not c.passed]
    typer.echo(f"{len(results)} comparisons in {elapsed:.1f} s; "
               f"{sum(c.passed for c in results)} passed, {len(failed)} failed")
    for c in results:
        for i in c.incidents:
            typer.echo(f"  {c.system}/{c.simulator} {i['scenario']}: {i['outcome']}: "
                       f"{i['message']}")
    typer.echo(f"results: {out.resolve()}")
    typer.echo(f"report:  {index.resolve()}")


def _split(items):
    return [x for item in items or [] for x in item.split(",") if x]


@app.command("errata")
def errata_cmd(as_json: bool = typer.Option(False, "--json"),
               witnesses: bool = typer.Option(True, "--witnesses/--no-witnesses",
                                              help="run the engines on misprinted equations"),
               out: Optional[Path] = typer.Option(
                   None, "--out", help="also write errata.html and errata.json there"),
               no_cache: bool = typer.Option(False, "--no-cache", help="recompute the "
                                             "derivations instead of reading the cache"),
               ) -> None:
    """Every printed formula coded, compared with the derivation; engines as witnesses."""
    _use_cache(no_cache)
    from .comparisons.witnesses import witnessed_errata
    from .systems import all_systems

    entries = witnessed_errata(all_systems().values(), witnesses)
    if out is not None:
        from .comparisons.results_folder import save_errata
        from .reports.html import write_errata_page

        save_errata(entries, out)
        page = write_errata_page(out)
        if not as_json:
            typer.echo(f"errata page: {page.resolve()}")
    if as_json:
        _json({"errata": entries})
        return
    for e in entries:
        typer.echo(f"{e['system']:24s} {e['label']:58s} {e['verdict']}")
        if e["verdict"] != "agrees":
            typer.echo(f"    printed: {e['printed']}\n    derived: {e['derived']}")
            for sim, w in e.get("witnesses", {}).items():
                typer.echo(f"    {sim}: {w['verdict']}")


@app.command("strutt")
def strutt_cmd(grid: int = typer.Option(40, "--grid", help="points per axis"),
               lambda_range: str = typer.Option("-1,3", "--lambda", help="A,B"),
               gamma_range: str = typer.Option("0,3", "--gamma", help="A,B"),
               as_json: bool = typer.Option(False, "--json"),
               out: Optional[Path] = typer.Option(
                   None, "--out", help="also write strutt.json and strutt.png there"),
               ) -> None:
    """The Strutt chart of eq. 83 (Mathieu, period 2 pi) from Floquet theory."""
    from .analytic.strutt import strutt_chart

    def bounds(text: str, option: str) -> tuple[float, float]:
        try:
            a, b = (float(x) for x in text.split(","))
        except ValueError:
            _fail(f"{option} expects A,B (two numbers), got {text!r}")
        if not (np.isfinite(a) and np.isfinite(b) and a <= b):
            _fail(f"{option} expects finite A <= B, got {text!r}")
        return a, b

    if grid < 1:
        _fail(f"--grid must be a positive integer, got {grid}")
    chart = strutt_chart(grid, grid, bounds(lambda_range, "--lambda"),
                         bounds(gamma_range, "--gamma"))
    points = chart.points()
    counts = {v: sum(p["verdict"] == v for p in points) for v in ("stable", "unstable",
                                                                   "marginal")}
    doc = {"equation": "phi'' + (lambda + gamma cos t) phi = 0 (eq. 83, omega = 1)",
           "period": 2 * np.pi, "grid": grid, "counts": counts, "points": points}
    if out is not None:
        from .reports.strutt_figure import write_strutt_figure

        out.mkdir(parents=True, exist_ok=True)
        (out / "strutt.json").write_text(json.dumps(doc, indent=1))
        figure = write_strutt_figure(points, out / "strutt.png")
        if not as_json:
            typer.echo(f"Strutt chart: {figure.resolve()}")
    if as_json:
        _json(doc)
        return
    typer.echo(f"Strutt chart of eq. 83, {grid} x {grid} points: " +
               ", ".join(f"{k} {v}" for k, v in counts.items()))


def main() -> None:
    app()


if __name__ == "__main__":
    main()
