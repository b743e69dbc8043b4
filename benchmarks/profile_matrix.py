"""Where the time of `mbfidelity run` goes (see benchmarks/run_matrix.py for the
end-to-end wall time).

Usage:
  .venv/bin/python benchmarks/profile_matrix.py timeline [--workers 2]
      the default matrix as `mbfidelity run` runs it: per job (system) start/end per
      worker process, then the parent's write_results / write_report phases
  .venv/bin/python benchmarks/profile_matrix.py serial [--systems a,b] [--prof FILE]
      every system in this process under cProfile: inclusive time of each phase
      (derivation, lambdify, references, equilibria, engines, post-processing, fits)

Phases overlap (a reference includes building the numeric model, which includes the
derivation); the table is inclusive time, not a partition.
"""
import argparse
import cProfile
import os
import pstats
import sys
import tempfile
import time
from pathlib import Path

PHASES = {
    "derivation (sympy)": ("derivation.py", "__init__"),
    "numeric model (lambdify)": ("numeric.py", "_numeric_cached"),
    "reference total": ("reference.py", "_reference"),
    "  reference DOP853": ("reference.py", "_dop853"),
    "  reference full states": ("reference.py", "_full_states"),
    "  reference dynamics_along": ("numeric.py", "dynamics_along"),
    "  reference accelerations": ("numeric.py", "accelerations"),
    "operating equilibrium": ("linear.py", "operating_equilibrium"),
    "frequency checks": ("runner.py", "_compare_frequencies"),
    "  damped-sinusoid fits": ("metrics.py", "fit_damped_sinusoid"),
    "  kinetic amplitude": ("runner.py", "_kinetic_amplitude"),
    "mujoco simulate": ("mujoco_backend.py", "simulate"),
    "  mujoco _read_out": ("mujoco_backend.py", "_read_out"),
    "mujoco linearize": ("mujoco_backend.py", "linearize"),
    "pybullet simulate": ("pybullet_backend.py", "simulate"),
    "pybullet linearize": ("pybullet_backend.py", "linearize"),
    "exudyn simulate": ("exudyn_backend.py", "simulate"),
    "exudyn linearize": ("exudyn_backend.py", "linearize"),
    "pymunk simulate": ("pymunk_backend.py", "simulate"),
    "pymunk linearize": ("pymunk_backend.py", "linearize"),
    "report data: errata": ("errata.py", "errata"),
    "report data: geometry": ("results_folder.py", "mechanism_geometry"),
    "report data: series": ("results_folder.py", "save_series"),
}


def _phase_times(stats: pstats.Stats) -> dict[str, float]:
    out = dict.fromkeys(PHASES, 0.0)
    for (filename, _, func), (_, _, _, cum, _) in stats.stats.items():
        for phase, (fname, fn) in PHASES.items():
            if filename.endswith(fname) and func == fn:
                out[phase] += cum
    return out


def serial(systems, prof_path):
    from mbfidelity.comparisons.matrix import _one_system
    from mbfidelity.simulators import all_backends

    sims = list(all_backends())
    rows, total = {}, None
    for s in systems:
        pr = cProfile.Profile()
        t0 = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            pr.enable()
            _one_system((s, sims, 1e-3, False, Path(tmp), {}))
            pr.disable()
        stats = pstats.Stats(pr)
        rows[s] = {"wall": time.perf_counter() - t0, **_phase_times(stats)}
        total = stats if total is None else total.add(stats)
        print(f"{s:28s} {rows[s]['wall']:6.1f} s", file=sys.stderr, flush=True)
    names = ["wall"] + list(PHASES)
    print(f"{'phase':28s} " + " ".join(f"{s[:9]:>9s}" for s in systems) + "     total")
    for n in names:
        vals = [rows[s][n] for s in systems]
        print(f"{n:28s} " + " ".join(f"{v:9.2f}" for v in vals) + f" {sum(vals):9.2f}")
    if prof_path:
        total.dump_stats(prof_path)


def _timed_job(args):
    from mbfidelity.comparisons import matrix

    t0, c0 = time.time(), time.process_time()
    res, _ = matrix._one_system(args)
    return os.getpid(), args[0], t0, time.time(), time.process_time() - c0, res


def timeline(workers):
    """The pool as run_matrix runs it, with each job's start, end and CPU time."""
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from mbfidelity.comparisons import matrix
    from mbfidelity.reports.html import write_report
    from mbfidelity.simulators import all_backends
    from mbfidelity.systems import all_systems

    start = time.time()
    sims = list(all_backends())
    systems = list(all_systems())
    order = matrix.schedule(systems)
    batches, cpu = {}, 0.0
    with tempfile.TemporaryDirectory() as tmp:
        args = [(s, sims, 1e-3, False, Path(tmp)) for s in order]
        with ProcessPoolExecutor(max_workers=workers) as pool:
            futures = [pool.submit(_timed_job, a) for a in args]
            for fut in as_completed(futures):
                pid, s, t0, t1, c, res = fut.result()
                cpu += c
                print(f"pid {pid:7d} {s:28s} {t0 - start:6.1f} -> {t1 - start:6.1f} "
                      f"({t1 - t0:5.1f} s wall, {c:5.1f} s CPU)", flush=True)
                batches[s] = res
        results = [r for s in systems for r in batches[s]]
        t_pool = time.time()
        matrix.write_results(results, Path(tmp))
        t_res = time.time()
        write_report(Path(tmp))
        t_rep = time.time()
    print(f"pool {t_pool - start:.1f} s (jobs' CPU {cpu:.1f} s); write_results "
          f"{t_res - t_pool:.1f} s; write_report {t_rep - t_res:.1f} s; total "
          f"{t_rep - start:.1f} s")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("mode", choices=("serial", "timeline"))
    ap.add_argument("--systems", default="")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--prof", default="")
    args = ap.parse_args()
    if args.mode == "serial":
        from mbfidelity.systems import all_systems

        systems = [s for s in args.systems.split(",") if s] or list(all_systems())
        serial(systems, args.prof)
    else:
        timeline(args.workers)


if __name__ == "__main__":
    main()
