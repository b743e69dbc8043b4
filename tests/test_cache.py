"""The persistent derivation cache (analytic/cache.py): results bitwise identical with a
cold cache, a warm one and none; corrupted or partial entries rebuilt; concurrent fills
safe; keys follow the content they depend on."""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from mbfidelity.analytic import cache

# a constrained mechanism (closed-form reduction, multipliers, reactions, contact forces)
# and an unconstrained one: every kind of compiled function is used
PROBE = """
import numpy as np
from mbfidelity.systems import get_system
from mbfidelity.analytic.linear import find_equilibria
from mbfidelity.analytic.reference import reference
for sid in ("scotch_yoke", "double_pendulum"):
    s = get_system(sid)
    v = s.parameter_values()
    eqs = find_equilibria(s, v)
    r = reference(s, s.scenarios[0], v, 1e-3, 0.3)
    parts = [r.q, r.qd, r.qdd, r.error_estimate, *r.reactions.values(),
             *(r.constraint_forces or {}).values()]
    parts += [e.eigenvalues.view(float) for e in eqs] + [e.q for e in eqs]
    print(sid, [np.ascontiguousarray(p).tobytes().hex() for p in parts])
"""


def _probe(cache_dir: Path | None, **env) -> str:
    environ = {**os.environ, **env}
    environ.pop("MBFIDELITY_NO_CACHE", None)
    if cache_dir is None:
        environ["MBFIDELITY_NO_CACHE"] = "1"
    else:
        environ["MBFIDELITY_CACHE_DIR"] = str(cache_dir)
    done = subprocess.run([sys.executable, "-c", PROBE], env=environ, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.fixture(scope="module")
def cold_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cache")
    return folder, _probe(folder)


def test_cold_warm_and_uncached_results_are_bitwise_identical(cold_run):
    folder, cold = cold_run
    entries = list(folder.glob("*/*"))
    assert any(p.name == "derivation.pickle" for p in entries)
    assert any(p.suffix == ".py" for p in entries)
    assert not list(folder.glob("*/.*.tmp")), "a temporary file was left behind"
    warm = _probe(folder, PYTHONHASHSEED="7")
    assert warm == cold
    assert _probe(None) == cold
    # nothing was written with the cache off
    assert sorted(folder.glob("*/*")) == sorted(entries)


def test_corrupted_and_truncated_entries_are_rebuilt(cold_run, tmp_path):
    folder, cold = cold_run
    damaged = tmp_path / "damaged"
    shutil.copytree(folder, damaged)
    pickles = sorted(damaged.glob("*/derivation.pickle"))
    sources = sorted(damaged.glob("*/rhs.py"))
    assert pickles and sources
    pickles[0].write_bytes(pickles[0].read_bytes()[:100])         # truncated
    blob = bytearray(sources[0].read_bytes())
    blob[-5] ^= 0xFF                                                # one corrupted byte
    sources[0].write_bytes(bytes(blob))
    (sources[-1]).write_bytes(b"")                                  # empty
    assert _probe(damaged) == cold
    # the damaged entries were replaced by valid ones
    for path in (pickles[0], sources[0], sources[-1]):
        digest, _, payload = path.read_bytes().partition(b"\n")
        assert digest == hashlib.sha256(payload).hexdigest().encode()


def test_two_processes_filling_one_cache_at_once(tmp_path, cold_run):
    _, cold = cold_run
    folder = tmp_path / "shared"
    env = {**os.environ, "MBFIDELITY_CACHE_DIR": str(folder)}
    env.pop("MBFIDELITY_NO_CACHE", None)
    procs = [subprocess.Popen([sys.executable, "-c", PROBE], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outputs = [p.communicate(timeout=600) for p in procs]
    assert all(p.returncode == 0 for p in procs), [o[1] for o in outputs]
    assert outputs[0][0] == outputs[1][0] == cold
    assert not list(folder.glob("*/.*.tmp"))
    assert _probe(folder) == cold


def test_load_rejects_what_store_did_not_write(tmp_path, monkeypatch):
    monkeypatch.setenv("MBFIDELITY_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("MBFIDELITY_NO_CACHE", raising=False)
    cache.store("k", "entry", b"payload")
    assert cache.load("k", "entry") == b"payload"
    path = tmp_path / "k" / "entry"
    path.write_bytes(path.read_bytes() + b"x")
    assert cache.load("k", "entry") is None
    assert cache.load("k", "missing") is None
    monkeypatch.setenv("MBFIDELITY_NO_CACHE", "1")
    cache.store("k", "other", b"payload")
    assert not (tmp_path / "k" / "other").exists()


def test_key_follows_the_content(tmp_path):
    import mbfidelity.systems.scotch_yoke as module

    systems_dir = tmp_path / "systems"
    shutil.copytree(Path(module.__file__).parent, systems_dir,
                    ignore=shutil.ignore_patterns("__pycache__"))
    copy = systems_dir / "scotch_yoke.py"
    original = cache.system_key(str(copy))
    assert cache.system_key(str(copy)) == original
    cache._file_digest.cache_clear()
    copy.write_text(copy.read_text().replace('0.005, "kg m^2"', '0.006, "kg m^2"'))
    assert cache.system_key(str(copy)) != original
    cache._file_digest.cache_clear()
    model = systems_dir / "model.py"
    model.write_text(model.read_text() + "\n# changed\n")
    changed = cache.system_key(str(copy))
    cache._file_digest.cache_clear()
    # another mechanism's module is not part of this one's key
    other = systems_dir / "double_pendulum.py"
    other.write_text(other.read_text() + "\n# changed\n")
    assert cache.system_key(str(copy)) == changed
