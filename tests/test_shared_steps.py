"""Shared steps of simulators/plan, base.py and reactions.py that an engine's
translation calls (the sliders' masses, a semi-implicit Euler engine's free-vibration fit,
modes with constraints held exactly, the geometric stiffness of constraint forces, the
outside forces the reactions take out, the builder of time loads, a Jacobian by central
differences), each checked against an independent statement of what it computes."""
from __future__ import annotations

import math

import numpy as np
import pytest

from mbfidelity.simulators.base import (EXACT, RELEASE_PERIODS, ElementBuilders, Expression,
                                        central_jacobian, semi_implicit_euler_modes)
from mbfidelity.simulators.plan import (
    COORDINATE_FORCE_CUSTOM,
    LINEAR_COUPLING,
    POINT_ON_LINE,
    POINT_ON_POINT,
    POINT_TO_POINT_CUSTOM,
    TIME_LOAD,
    constrained_modes,
    element_kind,
    geometric_stiffness,
    num,
    slider_masses,
)
from mbfidelity.simulators.reactions import outside_forces
from mbfidelity.systems.model import WORLD, PointToPoint

#: round-off bound: a few dozen operations on values of order 1-100
TOL = 1e-10


def _slotted_pin_bodies() -> list:
    """(id, mechanism, pin body) of every catalog slot whose pin is on a body with mass."""
    from mbfidelity.comparisons.runner import _engine_mechanism
    from mbfidelity.systems import all_systems

    out = []
    for sid, system in sorted(all_systems().items()):
        mech = _engine_mechanism(system, system.parameter_values(None), None)
        for c in mech.constraints:
            if (element_kind(c) == POINT_ON_LINE and c.body != WORLD
                    and not mech.body(c.body).massless):
                out.append((sid, mech, c.body))
    return out


def test_sliders_take_their_mass_out_of_the_pin_body_and_keep_its_moments():
    """Body + sliders keep the description's mass, centre of mass (the body frame's
    origin) and moment about it (parallel-axis theorem), with a positive inertia left."""
    cases = _slotted_pin_bodies()
    assert cases, "the catalog has slots with a massive pin body"
    for sid, mech, pin_body in cases:
        split = slider_masses(mech, pin_body, 0.3, 1.0)
        rest, inertia, com = split.kept
        body = mech.body(pin_body)
        pins = [np.array([num(c.point[0]), num(c.point[1])]) for c in mech.constraints
                if element_kind(c) == POINT_ON_LINE and c.body == pin_body]
        masses = list(split.masses.values())
        assert len(masses) == len(pins) and all(m > 0 for m in masses), sid
        mass, first = rest + sum(masses), rest * com + sum(m * p for m, p in zip(masses, pins))
        second = inertia + rest * com @ com + sum(m * p @ p for m, p in zip(masses, pins))
        assert mass == pytest.approx(num(body.mass), rel=TOL), sid
        assert np.allclose(first, 0.0, atol=TOL * num(body.mass)), sid
        assert second == pytest.approx(num(body.inertia), rel=TOL), sid
        assert inertia > 0, sid


def test_free_vibration_fit_inverts_semi_implicit_euler():
    """Two masses on springs (wall - k1 - m1 - k2 - m2) stepped by semi-implicit Euler
    (v += h M^-1 (-K q), q += h v): the fit returns the continuous frequencies, the roots
    of det(K - w^2 M) = 0 in closed form, although each mode's discrete frequency is
    (w h)^2 / 24 away from them (about 1 % at the fit's w_max h = 0.5). The linear
    prediction is exact for a linear mode: only round-off stays (each of the ~100 steps a
    period adds ~1e-16 relative to the record)."""
    m1, m2, k1, k2 = 1.0, 0.5, 40.0, 25.0
    M = np.diag([m1, m2])
    K = np.array([[k1 + k2, -k2], [-k2, k2]])
    # det(K - L M) = m1 m2 L^2 - (m1 k2 + m2 (k1 + k2)) L + k1 k2
    a, b, c = m1 * m2, -(m1 * k2 + m2 * (k1 + k2)), k1 * k2
    roots = sorted(((-b - math.sqrt(b * b - 4 * a * c)) / (2 * a),
                    (-b + math.sqrt(b * b - 4 * a * c)) / (2 * a)))
    expected = [math.sqrt(L) / (2 * math.pi) for L in roots]
    state = {"q": np.zeros(2), "v": np.zeros(2), "h": 0.0}
    Minv = np.linalg.inv(M)

    def release(shape: np.ndarray) -> None:
        state["q"], state["v"] = shape.copy(), np.zeros(2)

    def advance() -> None:
        state["v"] = state["v"] + state["h"] * (Minv @ (-K @ state["q"]))
        state["q"] = state["q"] + state["h"] * state["v"]

    fit = semi_implicit_euler_modes(M, K, [0, 1], 3, 1e-3,
                                    lambda h: state.__setitem__("h", h), release, advance,
                                    lambda: state["q"])
    assert len(fit.frequency_hz) == 2  # two coordinates: two modes, not three
    assert fit.frequency_hz == pytest.approx(expected, rel=1e-12)
    assert fit.linearized_hz == pytest.approx(expected, rel=TOL)
    # the uncorrected fit carries the integrator's dispersion: it must differ
    assert abs(fit.uncorrected_hz[-1] / expected[-1] - 1) > 1e-3
    assert fit.step == pytest.approx(0.5 / (2 * math.pi * expected[-1]), rel=TOL)
    assert RELEASE_PERIODS >= 2


def test_constrained_modes_hold_the_constraint_exactly():
    """Two masses m on springs k to the ground, held together (x1 = x2, J = [1, -1]): one
    mode, of mass 2 m and stiffness 2 k, eigenvalues +- i sqrt(k / m); the basis spans
    x1 = x2."""
    m, k = 2.0, 50.0
    M, C, K = np.diag([m, m]), np.zeros((2, 2)), np.diag([k, k])
    eig, T, (Mr, Cr, Kr) = constrained_modes(M, C, K, np.array([[1.0, -1.0]]))
    assert T.shape == (2, 1) and abs(T[0, 0] - T[1, 0]) < TOL
    assert sorted(eig.imag) == pytest.approx([-math.sqrt(k / m), math.sqrt(k / m)], rel=TOL)
    assert np.allclose(eig.real, 0.0, atol=TOL)
    assert Kr[0, 0] / Mr[0, 0] == pytest.approx(k / m, rel=TOL)


def test_geometric_stiffness_of_a_circle_constraint():
    """g(q) = |q|^2 - L^2 (a point held on a circle), J = 2 q^T: J^T f = 2 f q, whose
    derivative at fixed f is 2 f I; central differences of a linear function leave only
    round-off."""
    q0, f = np.array([0.3, -1.2, 0.7]), 4.5

    def jacobian_at(i: int, h: float) -> np.ndarray:
        q = q0.copy()
        q[i] += h
        return (2 * q)[None, :]

    G = geometric_stiffness(jacobian_at, np.array([f]), 3, 1e-6)
    # round-off: eps |J^T f| / step = 1e-16 * 10 / 1e-6, i.e. ~1e-9
    assert np.allclose(G, 2 * f * np.eye(3), rtol=0, atol=1e-8)


def test_central_jacobian_of_a_known_function():
    """f(x) = (x_0^2 x_1, sin x_1, 3 x_0 - x_1): the polynomial rows are quadratic or
    linear in each entry, where central differences are exact up to round-off (eps |f| /
    step, ~1e-12 here); on sin x_1 they give (sin(x_1 + h) - sin(x_1 - h)) / (2 h) =
    cos x_1 sin(h) / h in closed form (a one-sided difference would be off by h/2 sin x_1,
    ~5e-5). `f` hands back one buffer that it overwrites: every value is kept apart."""
    x, h = np.array([0.7, -1.3]), 1e-4
    buffer = np.empty(3)

    def f(y: np.ndarray) -> np.ndarray:
        buffer[:] = y[0] ** 2 * y[1], math.sin(y[1]), 3 * y[0] - y[1]
        return buffer

    J = central_jacobian(f, x, h)
    assert J.shape == (3, 2)
    exact = np.array([[2 * x[0] * x[1], x[0] ** 2], [0.0, math.cos(x[1]) * math.sin(h) / h],
                      [3.0, -1.0]])
    assert np.allclose(J, exact, rtol=0, atol=1e-10)


def test_a_time_load_is_built_by_the_builder_of_its_custom_law():
    """A load that depends on time is the element it is: a point-to-point element's goes
    to the builder registered for a point-to-point custom law, a coordinate force's to
    that of a coordinate custom law, and TIME_LOAD declares the expression given."""
    import sympy as sp

    from mbfidelity.systems.model import TIME, CoordinateForce

    builders, built = ElementBuilders(), []
    builders.builds(POINT_TO_POINT_CUSTOM)(lambda target, f: built.append((target, "point")))
    builders.builds(COORDINATE_FORCE_CUSTOM)(lambda target, f: built.append((target, "coord")))
    declared = Expression(EXACT, "at each stage's time")
    builders.builds_time_load(declared)
    loads = (PointToPoint("pull", "a", (0, 0), "b", (1, 0), sp.sin(TIME)),
             CoordinateForce("push", "x", sp.cos(TIME)))
    for target, load in enumerate(loads):
        assert element_kind(load) == TIME_LOAD
        builders.of(load)(target, load)
    assert built == [(0, "point"), (1, "coord")]
    assert builders.declared()[TIME_LOAD] == (declared,)


def test_outside_forces_hand_pair_elements_and_couplings_apart():
    """The forces an engine's transmitted force holds, by the contract's sign convention
    (simulators/reactions.py): the point-to-point elements' and the pin and slot
    closures' (two opposite forces on two bodies) are pair forces, every other closure's
    (a coupling's generalized force) a coupling force; each array is handed on as given.
    Checked on every catalog mechanism, which together hold all three closure kinds."""
    from mbfidelity.comparisons.runner import _engine_mechanism
    from mbfidelity.systems import all_systems

    seen: set[str] = set()
    for sid, system in sorted(all_systems().items()):
        mech = _engine_mechanism(system, system.parameter_values(None), None)
        element_forces = {f.name: np.full((3, 2), float(i)) for i, f in enumerate(mech.forces)
                          if isinstance(f, PointToPoint)}
        constraint_forces = {c.name: np.full((3, 2), -float(i))
                             for i, c in enumerate(mech.constraints)}
        kinds = {c.name: element_kind(c) for c in mech.constraints}
        out = outside_forces(mech, element_forces, constraint_forces)
        pins_and_slots = {n for n, kind in kinds.items()
                          if kind in (POINT_ON_POINT, POINT_ON_LINE)}
        assert set(out["pair_forces"]) == set(element_forces) | pins_and_slots, sid
        assert set(out["coupling_forces"]) == set(kinds) - pins_and_slots, sid
        given = {**element_forces, **constraint_forces}
        for split in out.values():
            assert all(split[n] is given[n] for n in split), sid
        seen |= set(kinds.values())
    assert {POINT_ON_POINT, POINT_ON_LINE, LINEAR_COUPLING} <= seen
