"""Persistent cache of numerical results that are expensive and deterministic: reference
trajectories, their sensitivity, equilibria with their modes, stability thresholds, steady
states, Floquet multipliers.

An entry lives beside the system's derivation (analytic/cache.py: the folder named by the
content of the system's module and of the description machinery, its structure, SymPy and
Python) under a name that is the digest of everything else the result depends on:

- the kind of result and its inputs, exactly (every float by its bits and type, every
  array by its dtype, shape and bytes): parameter values, the initial state the solve
  starts from (after it is put on the constraint manifold), t_end, the output step, the
  solver tolerances and any other argument;
- the code that computes it: every module of `analytic/` (`cache.analytic_digest`), and
  the NumPy and SciPy versions (the integrator, the linear algebra).

Any change to them gives another name, so an entry is never stale. A result is stored
only for a catalog system (`get_system(system.id)` is the object passed): a System built
elsewhere under a catalog id may differ from the module its key names.

Reads and writes go through analytic/cache.py: the same folder (``$MBFIDELITY_CACHE_DIR``
or the user cache directory), the same switch (``MBFIDELITY_NO_CACHE``), the same
checksum (a damaged entry is recomputed, never trusted) and the same atomic writes
(parallel workers filling one entry each leave a complete file). A stored result is the
pickled object the computation returned, and a computed result is returned as it comes
back from its pickle (the arrays contiguous, as a load gives them): what a computation
then does with it is bitwise the same whether the entry was computed or loaded.
Within one process, results are also kept in memory (the most recent `MEMORY_SIZE`; a
reference trajectory, large, in analytic/reference.py's own bounded memory instead).
"""
from __future__ import annotations

import hashlib
import pickle
from collections import OrderedDict
from typing import Any, Callable, TypeVar

import numpy as np

from . import cache

#: bump when the layout or the meaning of an entry changes
FORMAT = "1"
#: results kept in memory per process (a comparison matrix job reuses a handful)
MEMORY_SIZE = 128

T = TypeVar("T")

_memory: OrderedDict[tuple[str, str], Any] = OrderedDict()


def _canonical(value: Any) -> str:
    """A text that names `value` exactly: equal texts, equal inputs (type included: an
    int and a float of the same value may compute differently)."""
    if value is None or isinstance(value, (bool, str)):
        return repr(value)
    if isinstance(value, (int, np.integer)):
        return f"{type(value).__name__}:{int(value)}"
    if isinstance(value, (float, np.floating)):
        return f"{type(value).__name__}:{float(value).hex()}"
    if isinstance(value, np.ndarray):
        array = np.ascontiguousarray(value)
        return (f"ndarray:{array.dtype.str}:{array.shape}:"
                f"{hashlib.sha256(array.tobytes()).hexdigest()}")
    if isinstance(value, dict) or hasattr(value, "items"):
        items = sorted((str(k), _canonical(v)) for k, v in value.items())
        return "{" + ",".join(f"{k!r}:{v}" for k, v in items) + "}"
    if isinstance(value, (tuple, list)):
        return f"{type(value).__name__}(" + ",".join(_canonical(v) for v in value) + ")"
    raise TypeError(f"no exact key for a {type(value).__name__}")


def _versions() -> str:
    import scipy

    return f"numpy {np.__version__}|scipy {scipy.__version__}"


def entry(system, kind: str, inputs: tuple) -> tuple[str, str] | None:
    """(folder, name) of the entry of `kind` for `inputs`, or None where the result is not
    stored (a system outside the catalog, an input without an exact key)."""
    from ..systems import get_system
    from .derivation import cache_key

    try:
        if get_system(system.id) is not system:
            return None
        text = "|".join((FORMAT, kind, cache.analytic_digest(), _versions(),
                         _canonical(inputs)))
    except (KeyError, TypeError):
        return None
    return cache_key(system), f"{kind}-{hashlib.sha256(text.encode()).hexdigest()[:32]}.pickle"


def cached(system, kind: str, inputs: tuple, compute: Callable[[], T],
           remember: bool = True) -> T:
    """`compute()`, or the result it returned before for the same system, kind and
    inputs (in memory, else from the persistent cache). An exception is not stored.
    `remember=False`: not kept in memory (a large result its caller keeps itself)."""
    where = entry(system, kind, inputs)
    if where is None:
        return compute()
    if where in _memory:
        _memory.move_to_end(where)
        return _memory[where]
    result = _MISSING
    blob = cache.load(*where)
    if blob is not None:
        try:
            result = pickle.loads(blob)
        except Exception:  # an unreadable entry is recomputed, never trusted
            result = _MISSING
    if result is _MISSING:
        blob = pickle.dumps(compute(), protocol=pickle.HIGHEST_PROTOCOL)
        cache.store(*where, blob)
        # what is returned is what a later load gives, layout included: a view (a column
        # slice of the solver's output) comes back as a contiguous copy, and NumPy sums
        # a contiguous array in another order than a strided one
        result = pickle.loads(blob)
    if remember:
        _memory[where] = result
        if len(_memory) > MEMORY_SIZE:
            _memory.popitem(last=False)
    return result


_MISSING = object()
