"""One facility for studies made of many independent runs (the Strutt chart by
simulation, step convergence, amplitude curves): `sweep(function, items)` returns
[function(item) for item in items], in the order of the items, computed on

- a local process pool (concurrent.futures.ProcessPoolExecutor) by default, or
- an existing Dask cluster when a scheduler address is given (dask.distributed.Client;
  the address of a `dask scheduler`, or of a LocalCluster).

Each item runs in a fresh call of a module-level function with the same arguments, so
the results are identical either way (no shared state, no ordering effects); the
function and the items must be picklable.
"""
from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor
from typing import Any

from .budget import become_worker


def sweep(function: Callable[[Any], Any], items: Iterable[Any], scheduler: str | None = None,
          workers: int | None = None) -> list[Any]:
    """function(item) for every item, in order; on a Dask cluster when `scheduler` is given,
    else on `workers` local processes (None: one per core; 1: in this process)."""
    items = list(items)
    if scheduler:
        from dask.distributed import Client

        with Client(scheduler) as client:
            return client.gather(client.map(function, items, pure=False))
    if workers == 1:
        return [function(item) for item in items]
    with ProcessPoolExecutor(max_workers=workers, initializer=become_worker,
                             initargs=(os.getpid(),)) as pool:
        return list(pool.map(function, items))
