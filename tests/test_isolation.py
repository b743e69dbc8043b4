"""Engines run in worker processes (comparisons/isolation.py): what kills or hangs the
worker costs one comparison, not the caller."""
import ctypes
import time

import pytest

from mbfidelity.comparisons.isolation import WorkerCrashed, WorkerTimedOut, isolated


def _segfault():
    return ctypes.string_at(0)


def test_result_and_exceptions_cross_the_process_boundary():
    assert isolated(divmod, 7, 2) == (3, 1)
    with pytest.raises(ValueError, match="invalid literal"):
        isolated(int, "x")


def test_a_segfault_is_a_crash_of_the_worker_only():
    with pytest.raises(WorkerCrashed, match="SIGSEGV"):
        isolated(_segfault)


def test_a_hang_is_killed_at_the_budget():
    start = time.perf_counter()
    with pytest.raises(WorkerTimedOut):
        isolated(time.sleep, 30, timeout=0.5)
    assert time.perf_counter() - start < 10
