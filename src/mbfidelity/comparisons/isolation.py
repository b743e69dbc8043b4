"""Engines run in a worker process, so that what an engine does to its process (a
segfault, an abort, a loop that never returns) costs one comparison, not the caller.

`isolated(fn, *args, timeout=..., **kwargs)` calls fn in a forked child and returns its
result; an exception raised by fn is raised again here (bad input stays bad input);
a child that dies raises `WorkerCrashed` (with its exit signal or code), one that
exceeds the wall-clock budget is killed and raises `WorkerTimedOut`. The child dies
with the caller and carries the worker memory limit (`budget.become_worker`).
"""
from __future__ import annotations

import multiprocessing
import os
import signal
import sys
from typing import Any, Callable

from .budget import become_worker


class WorkerCrashed(RuntimeError):
    """The worker process died without a result."""


class WorkerTimedOut(RuntimeError):
    """The worker process exceeded its wall-clock budget and was killed."""


def _child(conn, parent, fn, args, kwargs) -> None:
    become_worker(parent)
    # what engines print from their own code (Exudyn's solver banners) goes to stderr:
    # the caller's stdout may be a JSON document
    sys.stdout.flush()
    os.dup2(2, 1)
    try:
        result = ("ok", fn(*args, **kwargs))
    except BaseException as exc:  # raised again in the parent
        result = ("raised", exc)
    try:
        conn.send(result)
    except Exception as exc:  # an unpicklable result or exception
        conn.send(("raised", RuntimeError(f"the worker's result could not be returned: {exc}")))


def _describe(exitcode: int | None) -> str:
    if exitcode is not None and exitcode < 0:
        try:
            return f"killed by signal {signal.Signals(-exitcode).name}"
        except ValueError:
            return f"killed by signal {-exitcode}"
    return f"exited with code {exitcode} without a result"


def isolated(fn: Callable[..., Any], *args, timeout: float | None = None, **kwargs) -> Any:
    context = multiprocessing.get_context("fork")
    receiver, sender = context.Pipe(duplex=False)
    worker = context.Process(target=_child, args=(sender, os.getpid(), fn, args, kwargs),
                             daemon=True)
    worker.start()
    sender.close()
    try:
        if not receiver.poll(timeout):
            worker.kill()
            worker.join()
            raise WorkerTimedOut(f"no result within the {timeout:g} s budget (killed)")
        try:
            status, payload = receiver.recv()
        except EOFError:
            worker.join()
            raise WorkerCrashed(_describe(worker.exitcode)) from None
    finally:
        receiver.close()
    worker.join()
    if status == "raised":
        raise payload
    return payload
