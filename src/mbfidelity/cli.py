"""Command line (docs/user-guide.md): list, analyze, compare, run, errata, strutt, convergence,
beams (the engines' flexible elements against the exact beam of §6.1); and the users'
gates: check (the gates against the installed engines, optionally against a baseline) and
diff (what changed between two runs)."""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from types import SimpleNamespace
from typing import List, Optional

import numpy as np
import typer

#: the --dt option of the commands that run engines
STEP_HELP = "time step, s (default: the row's own step, else 0.001)"

app = typer.Typer(add_completion=False, no_args_is_help=True,
                  help="Cross-validate multibody simulators against exact models.")


def _use_system_paths(paths: Optional[List[Path]]) -> None:
    """A user's mechanism modules join the catalog (systems/__init__.py): through the
    environment, so that worker processes load them too."""
    if not paths:
        return
    import os

    from . import systems

    previous = os.environ.get(systems.SYSTEM_PATH_VARIABLE)
    known = previous.split(os.pathsep) if previous else []
    added = [str(Path(p).resolve()) for p in paths]
    os.environ[systems.SYSTEM_PATH_VARIABLE] = os.pathsep.join(
        dict.fromkeys(known + added))
    systems._REGISTRY = None
    try:
        systems.all_systems()
    except ValueError as exc:
        if previous is None:
            os.environ.pop(systems.SYSTEM_PATH_VARIABLE)
        else:
            os.environ[systems.SYSTEM_PATH_VARIABLE] = previous
        systems._REGISTRY = None
        _fail(str(exc))


def _out_folder(value: Optional[Path]) -> Optional[Path]:
    """An --out folder checked before any work (one line and exit 2 when it cannot be
    written)."""
    if value is not None:
        from .api import checked_output_folder

        try:
            checked_output_folder(value)
        except ValueError as exc:
            _fail(str(exc))
    return value


SYSTEM_PATH_HELP = ("a mechanism module of your own (written like those in "
                    "mbfidelity/systems/), added to the catalog; repeatable")


@app.callback()
def _options(system_path: Optional[List[Path]] = typer.Option(
        None, "--system-path", help=SYSTEM_PATH_HELP)) -> None:
    """Cross-validate multibody simulators against exact models."""
    _use_system_paths(system_path)


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
    from .api import jsonable

    typer.echo(json.dumps(doc, indent=1, default=jsonable))


@app.command("list")
def list_(as_json: bool = typer.Option(False, "--json", help="print JSON")) -> None:
    """Systems, engines, and which engine supports which system."""
    from . import api

    doc = api.list_systems()
    rows, backends = doc["systems"], doc["simulators"]
    if as_json:
        _json(doc)
        return
    typer.echo(f"{'system':26s} " + " ".join(f"{b:9s}" for b in backends) + " source")
    group = None
    for r in sorted(rows, key=lambda r: (r["group"] != "monograph", r["group"])):
        if r["group"] != group:
            group = r["group"]
            typer.echo(f"[{group}]")
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


def _print_floquet(doc: dict) -> None:
    """`analyze`'s text for a periodic-coefficient driven system."""
    typer.echo(f"{doc['system']}: {doc['title']} ({doc['source']})")
    typer.echo("parameters: " + ", ".join(f"{k}={v:g}" for k, v in doc["parameters"].items()))
    typer.echo(f"periodic coefficients: {doc['periodic_coefficients']}")
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
            timeout: float = typer.Option(
                900.0, "--timeout", help="wall-clock budget of the analysis, s (> 0)"),
            ) -> None:
    """Equilibria with stability, M, K, C, modes, printed-vs-derived comparison."""
    from . import api

    _use_cache(no_cache)
    system = _system(system_id)
    params = _parse_params(param)
    values, derived = _values(system, params)
    try:
        doc = api.analyze(system.id, params, timeout=timeout)
    except ValueError as exc:
        _fail(str(exc))
    except RuntimeError as exc:  # the worker crashed or ran out of time or memory
        typer.echo(f"error: analyze {system.id}: {exc}", err=True)
        raise typer.Exit(1)
    if doc.get("floquet") is not None:
        if as_json:
            _json(doc)
        else:
            _print_floquet(doc)
        return
    op = SimpleNamespace(**{k: np.asarray(doc["linearization"][k]) for k in "MCK"})
    equilibria = doc["equilibria"]
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
        if "floquet" in e:  # a parametric excitation: Floquet's verdict (api.analyze)
            f = e["floquet"]
            typer.echo(f"{kind} {e['q']}: Floquet {f['verdict']} (|mu|max = "
                       f"{f['floquet_max_abs_multiplier']:.9g} +- {f['floquet_error']:.1e} "
                       f"over the period {f['period']:.6g} s)")
            continue
        typer.echo(f"{kind} {e['q']}: {'stable' if e['stable'] else 'unstable'}")
        if e.get("singular"):
            typer.echo(f"  warning: {e['warning']}")
    if "parametric_excitation" in doc:
        typer.echo(f"parametric excitation: {doc['parametric_excitation']}")
    typer.echo(f"at {doc['operating_point']}:")
    for key in ("M", "C", "K"):
        typer.echo(f"  {key} = {np.array2string(getattr(op, key), precision=6)}")
    for m in doc["modes"]:
        typer.echo(f"  mode: f = {m['frequency_hz']:.9g} Hz, zeta = {m['damping_ratio']:.6g}, "
                   f"f_d = {m['damped_frequency_hz']:.9g} Hz")
    if not doc["stable"]:
        typer.echo(f"  unstable: fastest growth rate {doc['growth_rate']:.9g} 1/s")
    if "continuum" in doc:
        c, chain = doc["continuum"], doc["continuum"]["discretization"]
        typer.echo(f"  exact continuum ({c['model']}): "
                   + ", ".join(f"{f:.9g}" for f in c["frequency_hz"]) + " Hz")
        for r in doc["rayleigh"]:
            typer.echo(f"  Rayleigh {r['label']} ({r['shape']}): {r['frequency_hz']:.9g} Hz, "
                       f"{r['relative_error']:+.3e} against the exact first frequency")
        typer.echo(f"  chain of {chain['parameter']} = {chain[chain['parameter']]} against the "
                   f"continuum: " + ", ".join(f"{e:+.3e}" for e in chain["relative_error"]))
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
                dt: Optional[float] = typer.Option(None, "--dt", help=STEP_HELP),
                t_end: Optional[float] = typer.Option(None, "--t-end", help="simulated time, s"),
                setting: Optional[List[str]] = typer.Option(
                    None, "--setting", help="engine setting KEY=VALUE (JSON value)"),
                variant: Optional[str] = typer.Option(
                    None, "--variant", help="build the system's named variant (e.g. contact)"),
                as_json: bool = typer.Option(False, "--json"),
                timeout: float = typer.Option(
                    900.0, "--timeout", help="wall-clock budget of the comparison, s (> 0)"),
                no_cache: bool = typer.Option(False, "--no-cache", help="recompute the "
                                              "derivations instead of reading the cache"),
                ) -> None:
    """One comparison: metrics, tolerances, pass/fail (the engine runs in a worker
    process: a crash or a run past --timeout is reported, exit 1)."""
    from . import api

    _use_cache(no_cache)
    system = _system(system_id)
    params = _parse_params(param)
    _values(system, params, system.scenarios)
    try:
        result = api.compare(system.id, sim, params, dt=dt, t_end=t_end, timeout=timeout,
                             settings=_settings(setting), variant=variant)
    except ValueError as exc:
        _fail(str(exc))
    doc = result.as_dict()
    if as_json:
        _json(doc)
    else:
        shown = f"{result.system}[{result.variant}]" if result.variant else result.system
        typer.echo(f"{shown} on {result.simulator} {result.engine_version}, dt={result.dt:g}")
        said = set()
        for m in result.metrics:
            extra = f"  ({m.reason})" if m.reason and m.reason not in said else ""
            said.add(m.reason)
            typer.echo(f"  {m.name:34s} {m.value:10.3e} <= {m.tolerance:9.3e}  {m.status}{extra}")
        for i in result.incidents:
            at = f" at t = {i['t_reached']:.6g} s" if i.get("t_reached") is not None else ""
            stage = f" ({i['stage']})" if i.get("stage") else ""
            typer.echo(f"  {i['scenario']}{stage}: {i['outcome']}{at}: {i['message']}")
        if result.verdict == "unsupported":
            typer.echo(f"UNSUPPORTED (declared): {result.reason}")
        else:
            typer.echo("PASSED" if result.passed else "FAILED")
    raise typer.Exit(1 if result.verdict == "fail" else 0)


@app.command()
def run(systems: Optional[List[str]] = typer.Option(None, "--systems", help="system ids"),
        sims: Optional[List[str]] = typer.Option(None, "--sims", help="simulator ids"),
        out: Path = typer.Option(Path("results"), "--out", callback=_out_folder, help="output folder"),
        dt: Optional[float] = typer.Option(None, "--dt", help=STEP_HELP),
        variants: bool = typer.Option(False, "--variants/--no-variants",
                                      help="also run each system's variants (e.g. rolling by "
                                           "friction contact) on the engines that build them"),
        no_cache: bool = typer.Option(False, "--no-cache", help="recompute the derivations "
                                      "instead of reading the persistent cache"),
        resume: bool = typer.Option(False, "--resume", help="continue a killed run into "
                                    "--out: reuse the systems it finished"),
        setting: Optional[List[str]] = typer.Option(
            None, "--setting", help="ENGINE.KEY=VALUE: an engine setting (JSON value)"),
        scheduler: Optional[str] = typer.Option(
            None, "--scheduler", help="a Dask scheduler's address: the systems run on that "
                                      "cluster (default: a local process pool)"),
        ) -> None:
    """The whole matrix: results (CSV, JSON) and the HTML report."""
    _use_cache(no_cache)
    settings = _engine_settings(setting)
    from rich.progress import Progress

    from . import api
    from .comparisons.matrix import reusable_jobs
    from .simulators import all_backends
    from .systems import all_systems

    sys_ids = _split(systems) or list(all_systems())
    for s in sys_ids:
        _system(s)
    try:
        sim_ids = api.checked_simulators(_split(sims) or all_backends())
        api.checked_duration("--dt", dt)
    except ValueError as exc:
        _fail(str(exc))
    if resume:
        reused = reusable_jobs(out, sys_ids, sim_ids, dt, variants, settings)
        typer.echo(f"resuming: {len(reused)} of {len(sys_ids)} systems finished in {out}, "
                   f"reused")
    start = time.perf_counter()
    with Progress(transient=False, disable=not sys.stderr.isatty()) as progress:
        task = progress.add_task("comparisons", total=len(sys_ids) * len(sim_ids))

        def tick(c):
            progress.update(task, advance=1, description=f"{c.system} / {c.simulator}")
        try:
            results = api.run(sys_ids, sim_ids, out, dt=dt, settings=settings,
                              variants=variants, resume=resume, scheduler=scheduler,
                              progress=tick)
        except ValueError as exc:
            _fail(str(exc))
    elapsed = time.perf_counter() - start
    verdicts = [c.verdict for c in results]
    typer.echo(f"{len(results)} comparisons in {elapsed:.1f} s; "
               f"{verdicts.count('pass')} passed, {verdicts.count('fail')} failed, "
               f"{verdicts.count('unsupported')} unsupported (declared)")
    for c in results:
        for i in c.incidents:
            stage = f" ({i['stage']})" if i.get("stage") else ""
            typer.echo(f"  {c.system}/{c.simulator} {i['scenario']}{stage}: {i['outcome']}: "
                       f"{i['message']}")
    typer.echo(f"results: {out.resolve()}")
    typer.echo(f"report:  {(out / 'index.html').resolve()}")


def _split(items):
    return [x for item in items or [] for x in item.split(",") if x]


def _engine_settings(items: Optional[List[str]]) -> dict[str, dict]:
    """ENGINE.KEY=VALUE items -> {engine: {key: value}}, each engine's settings validated
    by its backend (one line and exit 2 for a bad one)."""
    from .simulators import all_backends

    out: dict[str, dict] = {}
    for item in items or []:
        head = item.split("=", 1)[0]
        if "=" not in item or "." not in head:
            _fail(f"--setting expects ENGINE.KEY=VALUE, got {item!r}")
        engine, rest = item.split(".", 1)
        if engine not in all_backends():
            _fail(f"--setting {item!r}: unknown simulator {engine!r}; valid: "
                  f"{', '.join(all_backends())}")
        out.setdefault(engine, {}).update(_settings([rest]))
    for engine, chosen in out.items():
        try:
            all_backends()[engine].resolve_settings(chosen)
        except (KeyError, ValueError) as exc:
            _fail(f"--setting for {engine}: {exc.args[0] if exc.args else exc}")
    return out


@app.command("errata")
def errata_cmd(as_json: bool = typer.Option(False, "--json"),
               witnesses: bool = typer.Option(True, "--witnesses/--no-witnesses",
                                              help="run the engines on misprinted equations"),
               out: Optional[Path] = typer.Option(
                   None, "--out", callback=_out_folder, help="also write errata.html and errata.json there"),
               no_cache: bool = typer.Option(False, "--no-cache", help="recompute the "
                                             "derivations instead of reading the cache"),
               ) -> None:
    """Every printed formula coded, compared with the derivation; engines as witnesses."""
    _use_cache(no_cache)
    from . import api

    entries = api.errata(witnesses, out)
    if out is not None and not as_json:
        typer.echo(f"errata page: {(out / 'errata.html').resolve()}")
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
                   None, "--out", callback=_out_folder, help="also write strutt.json and strutt.png there"),
               sim: Optional[List[str]] = typer.Option(
                   None, "--sim", help="also classify every point by this engine's runs "
                                       "(repeatable)"),
               scheduler: Optional[str] = typer.Option(
                   None, "--scheduler", help="a Dask scheduler's address for the engines' "
                                             "runs (default: a local process pool)"),
               steps_per_period: int = typer.Option(
                   200, "--steps-per-period", help="engine steps per excitation period"),
               periods: int = typer.Option(10, "--periods",
                                           help="excitation periods of each engine run"),
               ) -> None:
    """The Strutt chart of eq. 83 (Mathieu, period 2 pi) from Floquet theory, and with
    --sim from each engine's simulation of the pendulum that maps to every point."""
    from . import api

    def bounds(text: str, option: str) -> tuple[float, float]:
        try:
            a, b = (float(x) for x in text.split(","))
        except ValueError:
            _fail(f"{option} expects A,B (two numbers), got {text!r}")
        return a, b

    try:
        doc = api.strutt(grid, bounds(lambda_range, "--lambda"), bounds(gamma_range, "--gamma"),
                         _split(sim), scheduler=scheduler, steps_per_period=steps_per_period,
                         periods=periods, out=out)
    except ValueError as exc:
        _fail(str(exc))
    counts = doc["counts"]
    if out is not None and not as_json:
        typer.echo(f"Strutt chart: {(out / 'strutt.png').resolve()}")
    if as_json:
        _json(doc)
        return
    typer.echo(f"Strutt chart of eq. 83, {grid} x {grid} points: " +
               ", ".join(f"{k} {v}" for k, v in counts.items()))
    for e, summary in doc.get("simulation", {}).get("engines", {}).items():
        typer.echo(f"  {e}: agrees with eq. 83 at {summary['agreement_with_eq83']:.1%} of "
                   f"{summary['decided_points']} decided points "
                   f"({len(summary['disagreements'])} differ)")


@app.command("discretization")
def discretization_cmd(system_id: str = typer.Argument(..., metavar="SYSTEM"),
                       param: Optional[List[str]] = typer.Option(None, "--param",
                                                                 help="NAME=VALUE"),
                       counts: str = typer.Option("2,4,8,16,32", "--counts",
                                                  help="numbers of elements, comma-separated"),
                       sims: Optional[List[str]] = typer.Option(
                           None, "--sim", help="also each engine's build of the chain, "
                                               "from its own linearization (repeatable)"),
                       out: Optional[Path] = typer.Option(
                           None, "--out", callback=_out_folder, help="also write discretization-SYSTEM.json and "
                                               ".png there"),
                       as_json: bool = typer.Option(False, "--json"),
                       ) -> None:
    """A discretized continuum (monograph §6) against its exact one: the first three
    frequencies for each number of elements, their errors, the fitted order and the
    leading error derived for the lumping; with --sim, each engine's chain against the
    derived one (exit 1 when an engine misses its linearization gate)."""
    from . import api
    from .reports.discretization_figure import figure_name

    system = _system(system_id)
    params = _parse_params(param)
    _values(system, params)
    try:
        chosen = [int(c) for c in counts.split(",") if c.strip()]
    except ValueError:
        _fail(f"--counts expects integers separated by commas, got {counts!r}")
    try:
        doc = api.discretization(system.id, params, chosen, _split(sims), out=out)
    except ValueError as exc:
        _fail(str(exc))
    failed = doc["failed"]
    study = SimpleNamespace(**{**doc, "rows": [SimpleNamespace(**r) for r in doc["rows"]]})
    if as_json:
        _json(doc)
        raise typer.Exit(1 if failed else 0)
    typer.echo(f"{study.system}: exact continuum "
               + ", ".join(f"{f:.9g}" for f in study.exact_hz) + " Hz")
    for row in study.rows:
        typer.echo(f"  {study.parameter} = {row.N:3d}: "
                   + ", ".join(f"{f:.9g} Hz ({e:+.3e})"
                               for f, e in zip(row.frequency_hz, row.relative_error))
                   + f"  [{row.seconds:.2f} s]")
    typer.echo("  fitted order: " + ", ".join(f"{o:.4f}" for o in study.fitted_order))
    if study.leading_error is not None:
        typer.echo("  derived leading error C_n (error = C_n / N^2): "
                   + ", ".join(f"{c:.6g}" for c in study.leading_error))
    for r in doc["rayleigh"]:
        typer.echo(f"  Rayleigh {r['label']}: {r['frequency_hz']:.9g} Hz "
                   f"({r['relative_error']:+.3e})")
    for e, x in doc.get("engines", {}).items():
        if x["reason"]:
            typer.echo(f"  {e}: {x['reason']}")
            continue
        for r in x["rows"]:
            typer.echo(f"  {e} {study.parameter} = {r['N']:3d}: against the chain "
                       + ", ".join(f"{v:+.1e}" for v in r["error_vs_chain"])
                       + f" (gate {r['gate_vs_chain']:.0e}); against the continuum "
                       + ", ".join(f"{v:+.3e}" for v in r["error_vs_continuum"])
                       + ("" if r["passed"] else "  FAILED"))
    for x in doc.get("flexible", {}).get("series", []):
        _echo_flexible_series(x)
    if out is not None:
        typer.echo(f"figure: {out / figure_name(study.system)}")
    raise typer.Exit(1 if failed else 0)


@app.command("convergence")
def convergence_cmd(systems: Optional[List[str]] = typer.Option(None, "--systems",
                                                                help="system ids"),
                    sims: Optional[List[str]] = typer.Option(
                        None, "--sims", help="simulator ids (default: every installed one)"),
                    steps: Optional[str] = typer.Option(
                        None, "--steps", help="the steps, s (multiples of the finest; "
                                              "default: 4, 2, 1, 0.5 ms, scaled down for a "
                                              "fast motion)"),
                    t_end: float = typer.Option(2.0, "--t-end", help="simulated time, s"),
                    knob: str = typer.Option(
                        "auto", "--knob", help="auto: an error-controlled engine (drake) "
                                               "by its target accuracy, the others by the "
                                               "step; step: every engine by the step"),
                    out: Optional[Path] = typer.Option(
                        None, "--out", callback=_out_folder, help="also write convergence.json, convergence.html "
                                            "and the figures there"),
                    scheduler: Optional[str] = typer.Option(
                        None, "--scheduler", help="a Dask scheduler's address (default: a "
                                                  "local process pool)"),
                    as_json: bool = typer.Option(False, "--json"),
                    ) -> None:
    """Error against the step and work-precision, per system x engine: the fitted order
    next to the engine's declared order (gate: within 0.5, where the curve still falls);
    an error-controlled engine's error against its target accuracy (gate: it falls by 2
    per decade over every two decades, down to the reference's floor). Exit 1 when a gate
    fails."""
    from . import api

    dts = None
    if steps is not None:
        try:
            dts = [float(x) for x in steps.split(",") if x]
        except ValueError:
            _fail(f"--steps expects numbers A,B,...; got {steps!r}")
    try:
        doc = api.convergence(_split(systems) or None, _split(sims) or None, dts, t_end,
                              scheduler=scheduler, out=out, knob=knob)
    except ValueError as exc:
        _fail(str(exc))
    studies, failed = doc["studies"], doc["failed"]
    if out is not None:
        page = out / "convergence.html"
    if as_json:
        _json(doc)
    else:
        for s in studies:
            if s["knob"] == "accuracy":
                worst = s["worst_decrease"]
                typer.echo(f"{s['system']:28s} {s['simulator']:9s} error ratio per accuracy "
                           f"decade {'-' if worst is None else f'{worst:.2g}'} / "
                           f"{s['metric']['tolerance']:g}  {s['metric']['status']}")
                continue
            order = (f"{s['observed_order']:.2f}" if s["observed_order"] is not None else "-")
            typer.echo(f"{s['system']:28s} {s['simulator']:9s} order {order:>5s} / "
                       f"{s['integrator_order']}  {s['metric']['status']}")
        for s in studies:  # a benchmark row: its own error measure at every point
            if s.get("benchmark_measure"):
                typer.echo(f"{s['system']:28s} {s['simulator']:9s} benchmark error "
                           f"[{s['benchmark_unit']}] / CPU s: " + ", ".join(
                               f"{p['benchmark_error']:.3g} / {p['cpu_time']:.3g}"
                               for p in s["points"])
                           + (f"  (failed{', declared' if s['declared_failure'] else ''})"
                              if s["failure"] or s["declared_failure"] else ""))
        if out is not None:
            typer.echo(f"page: {page.resolve()}")
    raise typer.Exit(1 if failed else 0)


@app.command("beams")
def beams_cmd(sim: Optional[List[str]] = typer.Option(
                  None, "--sim", help="simulator ids (repeatable or A,B; default: every "
                                      "backend, those without flexible elements say why)"),
              elements: str = typer.Option("2,4,8,16,32", "--elements",
                                           help="numbers of elements N, A,B,..."),
              param: Optional[List[str]] = typer.Option(
                  None, "--param", help="NAME=VALUE of the beam (l, EI, rho, m, c); "
                                        "default: m = 0 and m = 1, c = 0.5 (§6.1)"),
              modes: int = typer.Option(3, "--modes", help="frequencies per point"),
              as_json: bool = typer.Option(False, "--json"),
              out: Optional[Path] = typer.Option(
                  None, "--out", callback=_out_folder, help="also write beams.json and beams.png there"),
              ) -> None:
    """The engines' own flexible elements against the exact beam of §6.1 (Fig. 17): the
    first natural frequencies of the simply supported beam with a point mass, built of N
    elements of each kind, their relative errors and the fitted convergence order."""
    from . import api

    try:
        sizes = [int(x) for x in elements.split(",") if x]
    except ValueError:
        _fail(f"--elements expects integers A,B,...; got {elements!r}")
    try:
        doc = api.beams(_split(sim), sizes, _parse_params(param), modes, out=out)
    except ValueError as exc:
        _fail(str(exc))
    if out is not None:
        figure = out / "beams.png"
    if as_json:
        _json(doc)
        return
    for case in doc["cases"]:
        beam = case["beam"]
        typer.echo(f"m = {beam['point_mass']:g} kg at a = {beam['point_position']:g} m; exact "
                   + ", ".join(f"{f:.6g}" for f in case["exact_hz"]) + " Hz")
        for s in case["series"]:
            _echo_flexible_series(s)
    if out is not None:
        typer.echo(f"figure: {figure.resolve()}")


def _echo_flexible_series(s: dict) -> None:
    """One engine x flexible element kind of a beam study: its errors per N, its orders."""
    name = f"  {s['simulator']} {s['kind']}"
    if s["unsupported"]:
        typer.echo(f"{name}: unsupported: {s['unsupported']}")
        return
    typer.echo(f"{name} ({s['level']}, declared order {s['declared_order']})")
    for p in s["points"]:
        if "relative_error" not in p:
            typer.echo(f"    N = {p['N']:3d}: {p.get('skipped') or p.get('failure')}")
            continue
        typer.echo(f"    N = {p['N']:3d}: " + "  ".join(
            f"{e:+.2e}" if e is not None else "    -    " for e in p["relative_error"]))
    typer.echo("    order:   " + "  ".join(
        f"{o:9.2f}" if o is not None else "    -    " for o in s["fitted_order"]))


@app.command("check")
def check_cmd(systems: Optional[List[str]] = typer.Option(None, "--systems", help="system ids"),
              sims: Optional[List[str]] = typer.Option(
                  None, "--sims", help="simulator ids (default: every installed engine)"),
              baseline: Optional[Path] = typer.Option(
                  None, "--baseline", help="a results folder (or results.json) to compare "
                                           "with: a gate that got worse fails the check"),
              out: Path = typer.Option(Path("mbfidelity-check"), "--out", callback=_out_folder,
                                       help="where the results are written"),
              dt: Optional[float] = typer.Option(None, "--dt", help=STEP_HELP),
              setting: Optional[List[str]] = typer.Option(
                  None, "--setting", help="ENGINE.KEY=VALUE: an engine setting (JSON value)"),
              report: bool = typer.Option(False, "--report/--no-report",
                                          help="also write the HTML report into --out"),
              as_json: bool = typer.Option(False, "--json"),
              system_path: Optional[List[Path]] = typer.Option(
                  None, "--system-path", help=SYSTEM_PATH_HELP),
              no_cache: bool = typer.Option(False, "--no-cache", help="recompute the "
                                            "derivations instead of reading the cache"),
              ) -> None:
    """The gates of the installed package against the installed engines: a verdict per
    system x engine, the results in --out; exit 0 only if every gate passes or is declared
    (and, with --baseline, none got worse than there). One line in a user's CI."""
    _use_system_paths(system_path)
    _use_cache(no_cache)
    from . import api

    try:
        outcome = api.check(_split(systems) or None, _split(sims) or None, out,
                            baseline=baseline, dt=dt, settings=_engine_settings(setting),
                            report=report)
    except ValueError as exc:
        _fail(str(exc))
    if as_json:
        _json(outcome.as_dict())
    else:
        for v in outcome.verdicts:
            why = (f"  {', '.join(v.failing)}" if v.verdict == "fail" else
                   f"  {v.reason}" if v.verdict == "unsupported" else "")
            typer.echo(f"{v.system:28s} {v.simulator:9s} {v.verdict.upper():11s}{why}")
        if outcome.diff is not None:
            _print_diff(outcome.diff)
        typer.echo(f"results: {outcome.results}")
        typer.echo("CHECK PASSED" if outcome.passed else "CHECK FAILED")
    raise typer.Exit(0 if outcome.passed else 1)


def _print_diff(changes) -> None:
    changed = [p for p in changes.pairs if p.kind != "same"]
    typer.echo(f"diff {changes.old} -> {changes.new}: {len(changed)} of {len(changes.pairs)} "
               f"system x engine pairs changed" + (", a gate got worse" if changes.worse
                                                   else ""))
    for p in changed:
        head = f"  {p.row}/{p.simulator}: {p.kind}"
        if p.versions and p.versions[0] != p.versions[1]:
            head += f"; engine {p.versions[0]} -> {p.versions[1]}"
        if p.passed and p.passed[0] != p.passed[1]:
            head += f"; {'passed' if p.passed[0] else 'failed'} -> " \
                    f"{'passed' if p.passed[1] else 'failed'}"
        typer.echo(head + ("  [WORSE]" if p.worse else ""))
        for key, (a, b) in p.settings.items():
            typer.echo(f"    setting {key}: {a!r} -> {b!r}")
        for key, (a, b) in p.inputs.items():
            typer.echo(f"    input {key}: {a!r} -> {b!r}")
        for m in p.metrics:
            a = f"{m.old['value']:.6g} ({m.old['status']})" if m.old else "-"
            b = f"{m.new['value']:.6g} ({m.new['status']})" if m.new else "-"
            typer.echo(f"    {m.kind:8s} {m.name:34s} {a} -> {b}"
                       + ("  [WORSE]" if m.worse else ""))


@app.command("diff")
def diff_cmd(old: Path = typer.Argument(..., metavar="OLD", help="results folder or "
                                        "results.json (e.g. a recorded baseline)"),
             new: Path = typer.Argument(..., metavar="NEW", help="results folder or "
                                        "results.json"),
             as_json: bool = typer.Option(False, "--json"),
             html_page: Optional[Path] = typer.Option(None, "--html",
                                                      help="also write the diff as a page"),
             ) -> None:
    """What changed between two runs, per system x engine x metric: engine versions and
    settings, metrics that moved, gates that flipped, new and vanished metrics. Exit 1
    when a gate got worse."""
    from . import api

    try:
        if html_page is not None:
            api.checked_output_file(html_page, "--html")
        changes = api.diff(old, new)
    except ValueError as exc:
        _fail(str(exc))
    if html_page is not None:
        from .reports.diff_page import write_diff_page

        write_diff_page(changes.as_dict(), html_page)
    if as_json:
        _json(changes.as_dict())
    else:
        _print_diff(changes)
        if html_page is not None:
            typer.echo(f"page: {html_page.resolve()}")
    raise typer.Exit(1 if changes.worse else 0)


@app.command("export")
def export_cmd(system_id: str = typer.Argument(..., metavar="SYSTEM"),
               sim: str = typer.Option("mujoco", "--sim", help="the engine (MJCF: mujoco)"),
               out: Path = typer.Option(..., "--out", help="file to write"),
               param: Optional[List[str]] = typer.Option(None, "--param", help="NAME=VALUE"),
               setting: Optional[List[str]] = typer.Option(
                   None, "--setting", help="engine setting KEY=VALUE (JSON value)"),
               dt: Optional[float] = typer.Option(None, "--dt", help="time step written in the model, s (default: the row's own step, else 0.001)"),
               ) -> None:
    """The mechanism as the harness builds it, saved: MuJoCo's MJCF with a keyframe per
    scenario and the map from the description's coordinates (custom numerics)."""
    from . import api

    system = _system(system_id)
    params = _parse_params(param)
    _values(system, params, system.scenarios)
    try:
        api.checked_output_file(out)
        text, outside = api.export(system.id, sim, params, settings=_settings(setting), dt=dt)
    except ValueError as exc:
        _fail(str(exc))
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    typer.echo(f"{system.id} for {sim}: {out.resolve()}")
    for note in outside:
        typer.echo(f"  not in the file: {note}")


GLOBAL_OPTIONS = ("--system-path",)


def global_options_first(argv: list[str]) -> list[str]:
    """The arguments with every global option (and its value) moved before the command,
    so that `mbfidelity run --system-path F` means `mbfidelity --system-path F run`. A
    command's own `--system-path` (check's) stays where it is."""
    head, rest, i = [], [], 0
    own = {"check"}
    command = next((a for a in argv if not a.startswith("-")), None)
    while i < len(argv):
        arg = argv[i]
        name = arg.split("=", 1)[0]
        if name in GLOBAL_OPTIONS and command not in own:
            if "=" in arg:
                head.append(arg)
            else:
                head += argv[i:i + 2]
                i += 1
        else:
            rest.append(arg)
        i += 1
    return head + rest


# --- gate power (comparisons/power.py) ---------------------------------------------------


@app.command("power")
def power_cmd(systems: Optional[List[str]] = typer.Option(None, "--systems", help="system ids"),
              sims: Optional[List[str]] = typer.Option(
                  None, "--sims", help="simulator ids (default: every installed one)"),
              dt: Optional[float] = typer.Option(None, "--dt", help=STEP_HELP),
              out: Optional[Path] = typer.Option(
                  None, "--out", callback=_out_folder,
                  help="also write power.json, out_of_the_box.json and their pages there "
                       "(and the site again, when the folder holds a run)"),
              workers: Optional[int] = typer.Option(
                  None, "--workers", min=1, help="processes (default: up to 2)"),
              record: Optional[Path] = typer.Option(
                  None, "--record",
                  help="a recorded study (the power.json of an earlier --out, plain or "
                       ".gz): its readings made with the installed engines' versions at "
                       "the same step are taken from it, the others made"),
              as_json: bool = typer.Option(False, "--json"),
              ) -> None:
    """What the gates catch: per system x engine, the smallest relative error of a mass,
    an inertia, a length, g, a stiffness and a damping coefficient injected into the
    engine's build (decade grid 1e-6..1e-1) that the gates reject, and each neutralised
    engine default switched back on: rejected, below the gates, or not rejected (a blind
    gate), with its effect. The out-of-the-box study's document comes from the same runs."""
    from . import api

    def progress(entry) -> None:
        if as_json:
            return
        found = ", ".join(f"{p.kind} {p.smallest_rejected:g}" if p.smallest_rejected
                          else f"{p.kind} {'not rejected' if p.applicable else 'n/a'}"
                          for p in entry.errors)
        typer.echo(f"{entry.system:28s} {entry.simulator:9s} "
                   + (found if entry.supported else f"unsupported: {entry.reason}")
                   + (f" (recorded at {entry.recorded})" if entry.recorded else ""))
        for p in entry.errors:
            if p.applicable and p.verdict != "rejected":
                typer.echo(f"    {p.kind} at 1 %: {p.verdict}: {p.why}")
        for d in entry.defaults:
            typer.echo(f"    default {d.setting} = {d.engine_value}: {d.verdict}: {d.why}")

    try:
        study = api.power(_split(systems) or None, _split(sims) or None, out, dt=dt,
                          workers=workers, progress=progress, record=record)
    except ValueError as exc:
        _fail(str(exc))
    if as_json:
        _json(study.power_document())
    elif out is not None:
        typer.echo(f"pages: {(out / 'power.html').resolve()}, "
                   f"{(out / 'out_of_the_box.html').resolve()}")


@app.command("out-of-the-box")
def out_of_the_box_cmd(systems: Optional[List[str]] = typer.Option(None, "--systems",
                                                                help="system ids"),
                       sims: Optional[List[str]] = typer.Option(
                           None, "--sims", help="simulator ids (default: every installed one)"),
                       dt: Optional[float] = typer.Option(None, "--dt", help=STEP_HELP),
                       out: Optional[Path] = typer.Option(
                           None, "--out", callback=_out_folder,
                           help="also write out_of_the_box.json and out_of_the_box.html there "
                                "(and the site again, when the folder holds a run)"),
                       workers: Optional[int] = typer.Option(
                           None, "--workers", min=1, help="processes (default: up to 2)"),
                       default: Optional[List[str]] = typer.Option(
                           None, "--default", help="switch on only this neutralised default "
                                                   "(repeatable; default: each one, and all "
                                                   "together)"),
                       as_json: bool = typer.Option(False, "--json"),
                       ) -> None:
    """What each engine does out of the box: per system x engine, each default the harness
    neutralises switched back on alone and all together, on every declared scenario and
    the frequency checks; rejected by the gates or not, and its effect against the
    neutralised run (motion change, energy drift, damping ratio)."""
    from . import api

    def progress(entry) -> None:
        if as_json:
            return
        head = f"{entry.system:28s} {entry.simulator:9s}"
        if not entry.supported:
            typer.echo(f"{head} left out: {entry.reason}")
            return
        typer.echo(f"{head} {entry.wall_time_s:.1f} s"
                   + ("" if entry.defaults else ", no default neutralised"))
        for d in entry.defaults:
            verdict = f"{d.verdict}: {d.why}"
            change = d.motion.get("trajectory_change")
            moved = (f"; motion change {change:.3g} (gate {d.motion['trajectory_gate']:.3g}, "
                     f"{d.motion['scenario']})" if change is not None
                     and "trajectory_gate" in d.motion else "")
            drifts = [m for m in d.motion.get("scenarios", {}).values()
                      if m.get("energy_drift_switched_on") is not None]
            worst = max(drifts, key=lambda m: m["energy_drift_switched_on"], default=None)
            drained = (f"; energy drift {worst['energy_drift_neutralised']:.3g} -> "
                       f"{worst['energy_drift_switched_on']:.3g}" if worst else "")
            typer.echo(f"    {d.setting} = {d.engine_value}: {verdict}{moved}{drained}")

    start = time.perf_counter()
    try:
        study = api.out_of_the_box(_split(systems) or None, _split(sims) or None, out, dt=dt,
                                   workers=workers, defaults=_split(default) or None,
                                   progress=progress)
    except ValueError as exc:
        _fail(str(exc))
    if as_json:
        _json(study.as_dict())
        return
    typer.echo(f"{len(study.entries)} system x engine readings in "
               f"{time.perf_counter() - start:.1f} s")
    if out is not None:
        typer.echo(f"page: {(out / 'out_of_the_box.html').resolve()}")


def main() -> None:
    try:
        app(args=global_options_first(sys.argv[1:]), prog_name="mbfidelity")
    except OSError as exc:  # a path given by the user that cannot be read or written
        where = f": {exc.filename}" if exc.filename else ""
        typer.echo(f"error: {exc.strerror or exc}{where}", err=True)
        sys.exit(2)


if __name__ == "__main__":
    main()
