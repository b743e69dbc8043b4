"""The report's figures kept in the persistent cache (comparisons/file_cache.py): taken
from it only for the same inputs, byte for byte the files the drawing writes, and drawn
again when anything they are drawn from changes."""
import hashlib

import numpy as np

from mbfidelity.comparisons import results_folder
from mbfidelity.comparisons.matrix import write_results
from mbfidelity.comparisons.runner import Comparison, Metric
from mbfidelity.reports import html

ROW = "compound_pendulum"


def _comparisons(bias: float = 0.0) -> list[Comparison]:
    t = np.linspace(0.0, 2.0, 2001)
    q_ref = 0.1 * np.cos(2.0 * np.pi * t)[:, None]
    out = []
    for k, sim in enumerate(("mujoco", "pymunk")):
        c = Comparison(ROW, sim, "0", {}, {}, 1e-3,
                       metrics=[Metric("small.trajectory_max", 0.01, 0.1, True, "pass")])
        q = q_ref * (1.0 + 1e-3 * (k + 1)) + bias
        c.series = {"small": {"t": t, "q_ref": q_ref, "q": q, "reactions": {},
                              "tolerance": 0.1, "scale": np.ones(1), "checks": {},
                              "contacts": {}}}
        out.append(c)
    return out


def _save(out, comps) -> None:
    results_folder.save_series(out, ROW, comps)
    for c in comps:
        c.series = {}
    write_results(comps, out)


def _pngs(out) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(out.glob("*.png"))}


def test_figures_come_from_the_cache_bitwise_and_only_for_the_same_inputs(tmp_path,
                                                                         monkeypatch):
    monkeypatch.setenv("MBFIDELITY_CACHE_DIR", str(tmp_path / "cache"))
    # the frames are another test's (they need the derivation: seconds in an empty cache)
    monkeypatch.setattr(results_folder, "save_animation", lambda out, row: None)
    out = tmp_path / "results"
    _save(out, _comparisons())
    html.write_report(out, workers=1)
    drawn = _pngs(out)
    assert f"{ROW}-small.png" in drawn
    assert list((tmp_path / "cache").glob("report-files/plots-*.figures"))

    # the same inputs: the files come from the cache, the drawing is not called
    calls = []
    real = html._figures
    monkeypatch.setattr(html, "_figures", lambda *a: calls.append(a) or real(*a))
    for p in out.glob("*.png"):
        p.unlink()
    html.write_report(out, workers=1)
    assert calls == [] and _pngs(out) == drawn

    # without the cache, the drawing writes the same bytes
    monkeypatch.setenv("MBFIDELITY_NO_CACHE", "1")
    html.write_report(out, workers=1)
    assert len(calls) == 1 and _pngs(out) == drawn
    monkeypatch.delenv("MBFIDELITY_NO_CACHE")

    # an engine's series changed: drawn again, another figure
    _save(out, _comparisons(bias=0.05))
    html.write_report(out, workers=1)
    assert len(calls) == 2
    assert _pngs(out)[f"{ROW}-small.png"] != drawn[f"{ROW}-small.png"]


def test_inputs_are_named_exactly():
    """Equal inputs, equal names; another value, type, dtype or shape, another name."""
    from mbfidelity.comparisons.file_cache import entry_name

    values = (np.zeros(3), np.zeros(3, dtype=np.float32), np.zeros(4), np.zeros((3, 1)),
              [0.0, 0.0], (0.0, 0.0), {"a": 0.0}, {"b": 0.0}, 0.0, -0.0, 0, "0", None)
    names = [entry_name("plots", v, b"code") for v in values]
    assert len(set(names)) == len(values)
    assert names == [entry_name("plots", v, b"code") for v in values]
    assert entry_name("drawing", values[0], b"code") != names[0]
    assert entry_name("plots", values[0], b"other code") != names[0]


def test_animation_frames_come_from_the_cache_bitwise(tmp_path, monkeypatch):
    monkeypatch.setenv("MBFIDELITY_CACHE_DIR", str(tmp_path / "cache"))
    out = tmp_path / "results"
    _save(out, _comparisons())
    path = results_folder.animation_path(out, ROW)
    frames = path.read_bytes()
    assert b'"scenarios"' in frames
    assert list((tmp_path / "cache").glob("report-files/animation-*.figures"))

    # the same series: the frames come from the cache, the animation is not computed
    path.unlink()
    real = results_folder.animation
    monkeypatch.setattr(results_folder, "animation", lambda *a: 1 / 0)
    results_folder.save_animation(out, ROW)
    assert path.read_bytes() == frames
    monkeypatch.setattr(results_folder, "animation", real)

    # without the cache, the same bytes; another series, other frames
    monkeypatch.setenv("MBFIDELITY_NO_CACHE", "1")
    results_folder.save_animation(out, ROW)
    assert path.read_bytes() == frames
    monkeypatch.delenv("MBFIDELITY_NO_CACHE")
    _save(out, _comparisons(bias=0.05))
    assert path.read_bytes() != frames
