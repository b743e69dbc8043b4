"""The persistent cache of numerical results (analytic/memo.py): reference trajectories,
sensitivities, equilibria and modes, stability thresholds, steady states and Floquet
multipliers are bitwise the same computed into an empty cache, computed again and loaded
from the filled one; a comparison's metrics are the same with a cold cache, a warm one
and none; a damaged entry is recomputed; two processes filling one folder at once are
safe; an entry's name follows every input."""
from __future__ import annotations

import dataclasses
import hashlib
import os
import pickle
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mbfidelity.analytic import cache, memo

# an unconstrained system (its reference a column slice of the solver's output), a
# constrained one (dependent coordinates, multipliers, reactions), a driven one (steady
# state), one with a stability parameter and a parametrically excited one (Floquet). With
# MBFIDELITY_EXPECT_LOADED set, every computation behind the cache raises: each result
# must come from the folder.
PROBE = """
import os, sys
import numpy as np
from mbfidelity.analytic import floquet, linear, reference as refmod, stability
from mbfidelity.analytic import steady_state as ss
from mbfidelity.systems import get_system

if os.environ.get("MBFIDELITY_EXPECT_LOADED"):
    def computed(*args, **kwargs):
        raise AssertionError("computed, not loaded from the cache")
    for module, name in ((refmod, "_reference"), (refmod, "_sensitivity"),
                         (linear, "solve_operating_equilibrium"), (linear, "_find_equilibria"),
                         (stability, "_stability_threshold"), (ss, "_steady_state"),
                         (floquet, "_driven_floquet")):
        setattr(module, name, computed)

out = {}
for sid in ("double_pendulum", "scotch_yoke"):
    s = get_system(sid)
    v = s.parameter_values()
    r = refmod.reference(s, s.scenarios[0], v, 1e-3, 0.5)
    arrays = {"t": r.t, "q": r.q, "qd": r.qd, "qdd": r.qdd, "error": r.error_estimate,
              "multipliers": r.multipliers,
              "energy": np.zeros(0) if r.energy is None else r.energy,
              # sums depend on the arrays' memory layout, not only on their values
              "sums": np.array([r.q.sum(), r.qd.sum(), r.qdd.sum()]),
              "sensitivity": np.array([refmod.sensitivity(s, s.scenarios[0], v)])}
    arrays.update({f"reaction_{k}": x for k, x in r.reactions.items()})
    arrays.update({f"force_{k}": x for k, x in (r.constraint_forces or {}).items()})
    eq = linear.operating_equilibrium(s, v)
    arrays.update(eq_q=eq.q, eq_M=eq.M, eq_C=eq.C, eq_K=eq.K, eq_s=eq.eigenvalues,
                  eq_modes=np.array([m.frequency_hz for m in eq.modes]))
    for k, e in enumerate(linear.find_equilibria(s, v)):
        arrays.update({f"eq{k}_q": e.q, f"eq{k}_s": e.eigenvalues})
    out.update({f"{sid}.{k}": x for k, x in arrays.items()})
s = get_system("base_excited_msd")
harmonics = ss.steady_state(s, s.parameter_values()).harmonics
out["steady_state"] = np.array([h.phasor for h in harmonics])
s = get_system("conveyor_belt")
th = stability.stability_threshold(s, s.parameter_values())
out["threshold"] = np.array([c.value for c in th.crossings])
s = get_system("vertically_driven_pendulum")
found = floquet.driven_floquet(s, s.parameter_values())
out["floquet"] = np.array([r.multipliers for _, r in found])
np.savez(sys.argv[1], **out)
"""


def _run(args: list[str], folder: Path | None, **env) -> subprocess.CompletedProcess:
    environ = {**os.environ, **env}
    environ.pop("MBFIDELITY_NO_CACHE", None)
    environ.pop("MBFIDELITY_EXPECT_LOADED", None)
    if folder is None:
        environ["MBFIDELITY_NO_CACHE"] = "1"
    else:
        environ["MBFIDELITY_CACHE_DIR"] = str(folder)
    environ.update(env)
    return subprocess.run(args, env=environ, capture_output=True, text=True, timeout=600)


def _probe(folder: Path | None, out: Path, **env) -> dict[str, np.ndarray]:
    done = _run([sys.executable, "-c", PROBE, str(out)], folder, **env)
    assert done.returncode == 0, done.stderr
    with np.load(out) as data:
        return {k: data[k] for k in data.files}


def _assert_same(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for k in a:
        assert a[k].dtype == b[k].dtype and np.array_equal(a[k], b[k]), k


@pytest.fixture(scope="module")
def filled(tmp_path_factory):
    """A cache folder filled by one probe from empty, a copy of it with the derivations
    only (each result then computed: no derivation is repeated, they are slow), and what
    the first probe computed."""
    folder = tmp_path_factory.mktemp("results_cache")
    cold = _probe(folder, folder.parent / "cold.npz")
    derivations = folder.parent / "derivations_only"
    shutil.copytree(folder, derivations,
                    ignore=lambda d, names: [n for n in names if n.endswith(".pickle")
                                             and n != "derivation.pickle"])
    return folder, derivations, cold


def _entries(folder: Path, kind: str) -> list[Path]:
    return sorted(folder.glob(f"*/{kind}-*.pickle"))


def test_loaded_results_are_bitwise_those_computed(filled, tmp_path):
    folder, derivations, cold = filled
    for kind in ("reference", "sensitivity", "operating_equilibrium", "equilibria",
                 "steady_state", "stability_threshold", "driven_floquet"):
        assert _entries(folder, kind), kind
    assert not list(folder.glob("*/.*.tmp")), "a temporary file was left behind"
    written = sorted(folder.glob("*/*"))
    # every result loaded (its computation raises), bitwise equal, in another hash seed
    warm = _probe(folder, tmp_path / "warm.npz", MBFIDELITY_EXPECT_LOADED="1",
                  PYTHONHASHSEED="3")
    _assert_same(cold, warm)
    assert sorted(folder.glob("*/*")) == written
    # computed again, nothing read from the results cache
    assert not _entries(derivations, "reference")
    _assert_same(cold, _probe(derivations, tmp_path / "computed.npz"))


def test_damaged_entries_are_recomputed(filled, tmp_path):
    folder, _, cold = filled
    damaged = tmp_path / "damaged"
    shutil.copytree(folder, damaged)
    references = _entries(damaged, "reference")
    sensitivity = _entries(damaged, "sensitivity")[0]
    # the equilibrium of a system the probe asks for it directly
    equilibrium = sorted(references[0].parent.glob("operating_equilibrium-*.pickle"))[0]
    references[0].write_bytes(references[0].read_bytes()[:200])      # truncated
    blob = bytearray(references[1].read_bytes())
    blob[-7] ^= 0xFF                                                  # one byte flipped
    references[1].write_bytes(bytes(blob))
    sensitivity.write_bytes(b"")                                      # empty
    # a valid checksum over a payload that is no pickle: recomputed, never trusted
    payload = b"not a pickle"
    equilibrium.write_bytes(hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload)
    _assert_same(cold, _probe(damaged, tmp_path / "repaired.npz"))
    for path in (*references, sensitivity, equilibrium):
        digest, _, body = path.read_bytes().partition(b"\n")
        assert digest == hashlib.sha256(body).hexdigest().encode(), path.name
        pickle.loads(body)


def test_two_processes_filling_one_folder_at_once(filled, tmp_path):
    _, derivations, cold = filled
    folder = tmp_path / "shared"
    shutil.copytree(derivations, folder)
    env = {**os.environ, "MBFIDELITY_CACHE_DIR": str(folder)}
    env.pop("MBFIDELITY_NO_CACHE", None)
    env.pop("MBFIDELITY_EXPECT_LOADED", None)
    outs = [tmp_path / f"p{i}.npz" for i in range(2)]
    procs = [subprocess.Popen([sys.executable, "-c", PROBE, str(o)], env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for o in outs]
    errors = [p.communicate(timeout=600)[1] for p in procs]
    assert all(p.returncode == 0 for p in procs), errors
    for o in outs:
        with np.load(o) as data:
            _assert_same(cold, {k: data[k] for k in data.files})
    assert not list(folder.glob("*/.*.tmp"))
    _assert_same(cold, _probe(folder, tmp_path / "after.npz", MBFIDELITY_EXPECT_LOADED="1"))


def test_a_comparisons_metrics_are_the_same_cold_warm_and_uncached(tmp_path, monkeypatch):
    from collections import OrderedDict

    from mbfidelity.analytic import reference as refmod
    from mbfidelity.comparisons.runner import compare

    folder = tmp_path / "cache"
    monkeypatch.delenv("MBFIDELITY_NO_CACHE", raising=False)
    monkeypatch.setenv("MBFIDELITY_CACHE_DIR", str(folder))

    def metrics() -> list:
        # nothing this process kept of an earlier comparison: each result is computed or
        # read from the folder
        monkeypatch.setattr(refmod, "_CACHE", {})
        monkeypatch.setattr(memo, "_memory", OrderedDict())
        result = compare("mass_spring_damper", "mujoco")
        # repr: every float exactly, and a NaN equal to itself
        return [(m.name, repr(m.value), repr(m.tolerance), m.status) for m in result.metrics]

    cold = metrics()
    assert _entries(folder, "reference")
    solve = refmod._reference

    def computed(*args, **kwargs):
        raise AssertionError("the reference was solved, not loaded from the cache")
    monkeypatch.setattr(refmod, "_reference", computed)
    warm = metrics()
    assert len(cold) > 5
    assert warm == cold
    monkeypatch.setattr(refmod, "_reference", solve)
    monkeypatch.setenv("MBFIDELITY_NO_CACHE", "1")
    assert metrics() == cold


def test_an_entry_name_follows_every_input(monkeypatch, tmp_path):
    from mbfidelity.systems import get_system

    s = get_system("double_pendulum")
    v = s.parameter_values()
    q0 = np.array([0.1, 0.2])
    base = memo.entry(s, "reference", (v, q0, 1e-3, 10.0))
    assert base is not None
    assert base == memo.entry(s, "reference", (dict(v), q0.copy(), 1e-3, 10.0))
    first = sorted(v)[0]
    nudged = dict(v, **{first: np.nextafter(v[first], np.inf)})
    q1 = q0.copy()
    q1[1] = np.nextafter(q1[1], 1.0)
    others = [memo.entry(s, "reference", args) for args in (
        (nudged, q0, 1e-3, 10.0), (v, q1, 1e-3, 10.0), (v, q0, 5e-4, 10.0),
        (v, q0, 1e-3, 10.5), (v, q0.astype(np.float32), 1e-3, 10.0),
        (v, q0, 1e-3, 10))]
    others.append(memo.entry(s, "sensitivity", (v, q0, 1e-3, 10.0)))
    others.append(memo.entry(get_system("scotch_yoke"), "reference", (v, q0, 1e-3, 10.0)))
    names = {base, *others}
    assert len(names) == len(others) + 1
    # another version of analytic/ (its digest) names another entry
    monkeypatch.setattr(cache, "analytic_digest", lambda: "another")
    assert memo.entry(s, "reference", (v, q0, 1e-3, 10.0)) != base
    # a System that is not the catalog's object is never stored: its content is not
    # what its module (the key) says
    assert memo.entry(dataclasses.replace(s), "reference", (v, q0, 1e-3, 10.0)) is None
