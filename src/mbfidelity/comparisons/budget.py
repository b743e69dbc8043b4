"""The budgets a command is held to before it starts work, and the limits its worker
processes carry.

- Steps: a comparison adds up the engine steps of every run it will make (each
  scenario's duration, each free-vibration fit's periods, at the step dt) before any
  reference is solved; above the step budget it is refused in one line that names the
  budget and how to raise it (`MBFIDELITY_MAX_STEPS`), or to shorten the runs
  (`--t-end`, a larger `--dt`). Every sample of a run is kept (q, qd and the reactions
  for the engine and for the reference), so the step count bounds the memory too.
- Memory: a worker process (an isolated comparison, a job of `run`) sets its address
  space limit to `MBFIDELITY_WORKER_MEMORY` bytes (default: three quarters of the
  machine's physical memory), so that a runaway allocation is a `MemoryError` in that
  worker, recorded as an incident, not the machine swapping.
- Life: a worker dies with its parent (Linux's parent-death signal, a watchdog thread
  elsewhere), whatever signal ended the parent.
"""
from __future__ import annotations

import os
import signal
import sys
import threading
import time
from dataclasses import dataclass

STEP_BUDGET_VARIABLE = "MBFIDELITY_MAX_STEPS"
#: engine steps of one comparison, all runs together (the catalog's largest comparison
#: takes well under a tenth of it at the default step)
DEFAULT_MAX_STEPS = 20_000_000

MEMORY_VARIABLE = "MBFIDELITY_WORKER_MEMORY"


@dataclass(frozen=True)
class PlannedRun:
    """One engine run a command will make: what it is, its simulated seconds, its step."""

    label: str
    duration: float
    dt: float

    @property
    def steps(self) -> float:
        return self.duration / self.dt


def max_steps() -> int:
    text = os.environ.get(STEP_BUDGET_VARIABLE)
    if not text:
        return DEFAULT_MAX_STEPS
    try:
        value = int(float(text))
    except ValueError:
        raise ValueError(f"{STEP_BUDGET_VARIABLE} must be a number of steps, got {text!r}")
    if value < 1:
        raise ValueError(f"{STEP_BUDGET_VARIABLE} must be at least 1, got {text!r}")
    return value


def refuse_over_budget(runs: list[PlannedRun]) -> None:
    """ValueError (one line) when the runs together exceed the step budget, naming the
    longest run."""
    total = sum(r.steps for r in runs)
    limit = max_steps()
    if not total > limit:
        return
    worst = max(runs, key=lambda r: r.steps)
    raise ValueError(
        f"the comparison needs {total:.3g} engine steps (the longest run, {worst.label}: "
        f"{worst.duration:.3g} s at dt = {worst.dt:g} s), above the step budget of "
        f"{limit:.3g}; shorten the runs with --t-end, or raise the budget with "
        f"{STEP_BUDGET_VARIABLE}=N")


def worker_memory_limit() -> int | None:
    """Bytes of address space a worker may use, or None where it cannot be known."""
    text = os.environ.get(MEMORY_VARIABLE)
    if text:
        try:
            return max(int(float(text)), 1)
        except ValueError:
            raise ValueError(f"{MEMORY_VARIABLE} must be a number of bytes, got {text!r}")
    try:
        physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return None
    return int(physical * 3 // 4)


def _limit_memory() -> None:
    try:
        import resource
    except ImportError:  # not a POSIX system
        return
    limit = worker_memory_limit()
    if limit is None:
        return
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    try:
        resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    except (ValueError, OSError):
        pass


def _die_with_parent(parent: int) -> None:
    if sys.platform.startswith("linux"):
        import ctypes

        try:
            libc = ctypes.CDLL(None, use_errno=True)
            PR_SET_PDEATHSIG = 1
            if libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0:
                if os.getppid() != parent:  # the parent died before the call
                    os._exit(1)
                return
        except (OSError, AttributeError):
            pass

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)
    threading.Thread(target=watch, daemon=True, name="parent-watchdog").start()


def become_worker(parent: int) -> None:
    """What every worker process does first: die with `parent`, carry the memory limit.
    `parent` is the pid of the process that started it (read before the fork)."""
    _die_with_parent(parent)
    _limit_memory()

