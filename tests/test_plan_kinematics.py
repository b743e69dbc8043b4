"""The shared numeric kinematics of simulators/plan, checked against its forward
kinematics (`body_states`, `point_state`) on every planar catalog mechanism, and the
elimination of massless links (`plan.EliminatedFrames`; in Pymunk, its description frames
and the virtual power of its loads) against the same."""
from __future__ import annotations

import functools

import numpy as np
import pytest

from mbfidelity.simulators.plan import (
    ForceLaw,
    body_states,
    element_loads,
    joint_coordinates,
    point_state,
    traced,
)
from mbfidelity.systems.model import PointToPoint

#: round-off bound of the comparisons: a few hundred operations on values of order 1-100
TOL = 1e-10


@functools.lru_cache(maxsize=None)
def _planar() -> tuple:
    """(id, numeric mechanism, parameter values) of every planar catalog row."""
    from mbfidelity.comparisons.runner import _engine_mechanism
    from mbfidelity.systems import all_systems

    out = []
    for sid, system in sorted(all_systems().items()):
        values = system.parameter_values(None, scenario=system.scenarios[0])
        mech = _engine_mechanism(system, values, None)
        if not mech.spatial:
            out.append((sid, mech))
    return tuple(out)


def _random_states(mech, samples: int, seed: int = 7):
    rng = np.random.default_rng(seed)
    n = len(mech.coordinates)
    return rng.uniform(-2, 2, (samples, n)), rng.uniform(-3, 3, (samples, n))


def _stacked(mech, q, qd) -> dict:
    """body_states over samples, as arrays (one entry per sample)."""
    rows = [body_states(mech, qi, qdi) for qi, qdi in zip(q, qd)]
    return {b: tuple(np.array([r[b][i] for r in rows]) for i in range(6)) for b in rows[0]}


def test_joint_coordinates_invert_the_forward_kinematics():
    """q -> body frames (body_states) -> q again, on numbers and on arrays of samples:
    a sign, offset or axis-scale error of any joint kind breaks the round trip."""
    for sid, mech in _planar():
        q, qd = _random_states(mech, 5)
        for qi, qdi in zip(q, qd):
            got_q, got_qd = joint_coordinates(mech, body_states(mech, qi, qdi))
            assert np.allclose(got_q, qi, rtol=0, atol=TOL), sid
            assert np.allclose(got_qd, qdi, rtol=0, atol=TOL), sid
        got_q, got_qd = joint_coordinates(mech, _stacked(mech, q, qd))
        assert np.allclose(np.column_stack(got_q), q, rtol=0, atol=TOL), sid
        assert np.allclose(np.column_stack(got_qd), qd, rtol=0, atol=TOL), sid


def _power(loads, states) -> float:
    """sum of F . v(point) + tau omega of loads on bodies in the given frame states."""
    total = 0.0
    for body, force, point, torque in loads:
        x, y, _, vx, vy, w = states[body]
        total += torque * w
        if force is not None:
            total += force[0] * (vx - w * (point[1] - y)) + force[1] * (vy + w * (point[0] - x))
    return total


def _element_power(mech, element, q, qd, states, t: float) -> float:
    """The power of a force element from its law alone: -T L' for a point-to-point
    element of tension T (it pulls its points together), Q x' for a coordinate force."""
    law = ForceLaw.of(element)
    if isinstance(element, PointToPoint):
        pa = point_state(states[element.body_a], [float(v) for v in element.point_a])
        pb = point_state(states[element.body_b], [float(v) for v in element.point_b])
        d, v = np.subtract(pb[:2], pa[:2]), np.subtract(pb[2:], pa[2:])
        length = float(np.hypot(*d))
        rate = float(d @ v) / length
        return -law.law(length, rate, t) * rate
    weights = element.weights(mech.coordinates)
    x = sum(sign * q[i] for i, sign in weights.items())
    xd = sum(sign * qd[i] for i, sign in weights.items())
    return law.law(x, xd, t) * xd


def test_element_loads_have_the_power_of_their_law():
    """Every force element's loads on the bodies (virtual power of the law's force or
    generalized force) deliver the law's power at random states: a load on the wrong
    body, point, sign or axis changes it."""
    checked = 0
    for sid, mech in _planar():
        q, qd = _random_states(mech, 3)
        for qi, qdi in zip(q, qd):
            states = body_states(mech, qi, qdi)
            for f in mech.forces:
                got = _power(element_loads(mech, f)(states, 0.3), states)
                want = _element_power(mech, f, qi, qdi, states, 0.3)
                assert got == pytest.approx(want, rel=TOL, abs=TOL), (sid, f.name)
                checked += 1
    assert checked > 50


def test_traced_step_function_is_the_numeric_one():
    """A force element's loads traced into straight-line code give the numbers the
    numeric function gives."""
    sid, mech = next((sid, m) for sid, m in _planar() if sid == "elastic_pendulum")
    f = mech.forces[0]
    q, qd = _random_states(mech, 1)
    n = len(mech.joints)

    def power(*args):
        states = _body_states_on_symbols(mech, args[:n], args[n:2 * n])
        return [_power(element_loads(mech, f)(states, args[-1]), states)]

    compiled = traced(power, 2 * n + 1)
    states = body_states(mech, q[0], qd[0])
    want = _power(element_loads(mech, f)(states, 0.3), states)
    assert compiled(*q[0], *qd[0], 0.3)[0] == pytest.approx(want, rel=TOL, abs=TOL)


def _body_states_on_symbols(mech, q, qd) -> dict:
    """body_states on symbols: the planar tree by `point_state` (simulators/plan)."""
    from mbfidelity.simulators.plan import cos_sin, point_state, num
    from mbfidelity.systems.model import WORLD, Revolute

    st = {WORLD: (0.0,) * 6}
    for j, qj, qdj in zip(mech.joints, q, qd):
        parent = st[j.parent]
        pa = (num(j.parent_anchor[0]), num(j.parent_anchor[1]))
        ca = (num(j.child_anchor[0]), num(j.child_anchor[1]))
        off = num(j.angle_offset)
        if isinstance(j, Revolute):
            s = -1.0 if j.clockwise else 1.0
            th = (0.0 if j.absolute else parent[2]) + s * qj + off
            w = (0.0 if j.absolute else parent[5]) + s * qdj
            ax, ay, avx, avy = point_state(parent, pa)
        else:
            th, w = parent[2] + off, parent[5]
            axis = (num(j.axis[0]), num(j.axis[1]))
            ax, ay, avx, avy = point_state(parent, (pa[0] + qj * axis[0], pa[1] + qj * axis[1]))
            c, s = cos_sin(parent[2])
            avx += qdj * (c * axis[0] - s * axis[1])
            avy += qdj * (s * axis[0] + c * axis[1])
        c, s = cos_sin(th)
        rx, ry = c * ca[0] - s * ca[1], s * ca[0] + c * ca[1]
        st[j.child] = (ax - rx, ay - ry, th, avx + w * ry, avy - w * rx, w)
    return st


# --- Pymunk: eliminated massless links ---------------------------------------------------

#: catalog rows whose Pymunk build eliminates massless links: folded (a revolute and a
#: prismatic joint), arms (two hinge points), free groups (their joint equations)
ELIMINATED = ("elastic_pendulum", "pendulum_sliding_block", "belt_pulleys", "five_bar_bird",
              "slotted_link_spring_damper")


@functools.lru_cache(maxsize=None)
def _moving_state(sid: str) -> tuple:
    """(numeric mechanism, q, qd): a consistent state in motion, the reference's after
    0.2 s."""
    from mbfidelity.analytic.reference import reference
    from mbfidelity.comparisons.runner import DEFAULT_DT, _engine_mechanism
    from mbfidelity.systems import all_systems

    system = all_systems()[sid]
    sc = system.scenarios[0]
    values = system.parameter_values(None, scenario=sc)
    ref = reference(system, sc, values, DEFAULT_DT, 0.2)
    return _engine_mechanism(system, values, None), ref.q[-1], ref.qd[-1]


@pytest.mark.parametrize("sid", ELIMINATED)
def test_eliminated_frames_follow_the_forward_kinematics(sid):
    """plan.EliminatedFrames, given the frames of the bodies with mass (body_states at a
    consistent state in motion), gives every eliminated massless link's frame as
    body_states does: no engine involved."""
    from mbfidelity.simulators.plan import EliminatedFrames, Elimination, coupled, cos_sin

    mech, q, qd = _moving_state(sid)
    mech = coupled(mech)
    want = body_states(mech, q, qd)
    elimination = Elimination(mech)
    assert elimination.kind

    def massive(body: str) -> tuple:
        x, y, th, vx, vy, w = want[body]
        return (x, y, th, *cos_sin(th), vx, vy, w)

    frames = EliminatedFrames(elimination, massive)
    for name in elimination.kind:
        scale = max(1.0, float(np.max(np.abs(want[name]))))
        assert np.allclose(frames[name], want[name], rtol=0, atol=TOL * scale), (sid, name)


@pytest.mark.parametrize("sid", ELIMINATED)
def test_pymunk_frames_and_load_power_follow_the_description(sid):
    """From the engine state Pymunk builds at a consistent state, its description frames
    (eliminated links included) are those of body_states, and its compiled engine loads
    deliver the description's element power (the virtual-power Jacobian of an eliminated
    link, f . v + tau omega over the engine bodies at their centres of gravity)."""
    pytest.importorskip("pymunk")
    from mbfidelity.comparisons.runner import DEFAULT_DT
    from mbfidelity.simulators.pymunk_backend import BACKEND

    mech, q0, qd0 = _moving_state(sid)
    assert np.any(qd0 != 0)
    cfg = BACKEND.resolve_settings(None)
    layout, comp, space, bodies, balanced, _ = BACKEND._prepare(mech, q0, qd0, cfg, DEFAULT_DT)
    assert layout.elimination.kind
    row = BACKEND._reader(space, layout, bodies)()
    frames = comp.frames(np.array([row]))
    want = body_states(balanced, q0, qd0)
    for b in balanced.bodies:
        got = np.array([np.ravel(v)[0] for v in frames[b.name]])
        scale = max(1.0, float(np.max(np.abs(want[b.name]))))
        assert np.allclose(got, want[b.name], rtol=0, atol=TOL * scale), (sid, b.name)
    if not balanced.forces:
        return
    t = 0.3
    loads = comp.loads_math(*row, 0.0, t)
    engine_power = sum(loads[3 * i] * row[6 * k + 3] + loads[3 * i + 1] * row[6 * k + 4]
                       + loads[3 * i + 2] * row[6 * k + 5] for i, k in enumerate(comp.loaded))
    description_power = sum(_element_power(balanced, f, q0, qd0, want, t)
                            for f in balanced.forces)
    assert np.allclose(comp.engine_loads(row, 0.0, t), loads, rtol=1e-12, atol=1e-12)
    assert engine_power == pytest.approx(description_power, rel=1e-9, abs=1e-9), sid
