"""A small check per point of the backend contract (simulators/base.py), run on every
installed backend in the manner of scikit-learn's common estimator checks: the samples
start at the initial state (point 6), the reaction is the force the parent exerts on the
child (point 6), and the scheme a backend declares before stepping (point 10) is the one
its runs report and the one their errors show (the observed order). The mechanism is the
compound pendulum of Fig. 7, whose exact motion is Jacobi's elliptic functions."""
import functools

import numpy as np
import pytest

from mbfidelity.analytic.reference import reference
from mbfidelity.comparisons import metrics
from mbfidelity.simulators import all_backends
from mbfidelity.systems import get_system

INSTALLED = [b for b in all_backends().values() if b.available()[0]]
SYSTEM = get_system("compound_pendulum")


def _pendulum(phi0: float):
    sc = SYSTEM.scenario("large")
    values = SYSTEM.parameter_values({"phi0": phi0}, scenario=sc)
    return sc, values, SYSTEM.numeric_mechanism(values)


@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_first_sample_is_the_initial_state(backend):
    _, _, mech = _pendulum(1.0)
    q0, qd0 = np.array([1.0]), np.array([-0.5])
    run = backend.simulate(mech, q0, qd0, 0.01, 1e-3)
    assert len(run.t) == 11 and run.t[0] == 0.0 and abs(run.t[-1] - 0.01) < 1e-15
    assert np.allclose(run.q[0], q0, rtol=0, atol=1e-12)
    assert np.allclose(run.qd[0], qd0, rtol=0, atol=1e-12)


@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_reaction_is_the_force_of_the_parent_on_the_child(backend):
    """Hanging at rest, the pivot carries the bar's weight: the world pushes it up with
    m g (statics), at every sample the engine can give (the contract allows NaN where it
    cannot: Pymunk's force comes from the momentum change into a sample, none at t = 0)."""
    _, values, mech = _pendulum(0.0)
    run = backend.simulate(mech, np.zeros(1), np.zeros(1), 0.05, 1e-3, None, ("pivot",))
    weight = values["m"] * values["g"]
    got = run.reactions["pivot"]
    given = np.all(np.isfinite(got), axis=1)
    assert np.all(given[1:])
    assert np.allclose(got[given], [0.0, weight], rtol=0, atol=1e-9 * weight)


@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_declared_order_is_reported_and_observed(backend):
    """The order `scheme` declares is the order of the run and of its error: halving the
    step divides the error by about 2^p (within half an order), on a 1 rad swing whose w h
    stays in every scheme's asymptotic range at these steps."""
    sc, values, mech = _pendulum(1.0)
    scheme = backend.scheme(mech)
    errors = []
    for dt in (4e-3, 2e-3):
        ref = reference(SYSTEM, sc, values, dt, 1.0)
        run = backend.simulate(mech, ref.q[0], ref.qd[0], 1.0, dt)
        assert run.integrator_order == scheme.order
        errors.append(metrics.trajectory_errors(run.q, ref.q, np.array([1.0]))[0])
    observed = np.log2(errors[0] / errors[1])
    assert abs(observed - scheme.order) <= 0.5, (errors, observed)


# --- contract point 9: the bare loop steps the model of `simulate` -----------------------

@functools.lru_cache(maxsize=None)
def _catalog_starts() -> tuple:
    """Each catalog row's first scenario at the default step: (id, numeric mechanism, the
    reference's consistent initial state, the step); computed once per test process."""
    from mbfidelity.comparisons.runner import DEFAULT_DT, _engine_mechanism
    from mbfidelity.systems import all_systems

    out = []
    for sid, system in sorted(all_systems().items()):
        sc = system.scenarios[0]
        values = system.parameter_values(None, scenario=sc)
        ref = reference(system, sc, values, DEFAULT_DT, BARE_STEPS * DEFAULT_DT)
        out.append((sid, _engine_mechanism(system, values, None), ref.q[0], ref.qd[0],
                    DEFAULT_DT))
    return tuple(out)


BARE_STEPS = 20


def _angle_aware_gap(mech, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a - b| per coordinate, revolute angles compared modulo 2 pi: an engine that reads
    a link's angle by atan2 gives the state, not the number of turns, after a bare loop."""
    from mbfidelity.systems.model import Revolute

    gap = np.abs(a - b)
    for i, joint in enumerate(mech.joints):
        if isinstance(joint, Revolute):
            gap[i] = abs(np.angle(np.exp(1j * (a[i] - b[i]))))
    return gap


def _unstable_at(system_id: str, backend, mech, dt: float) -> bool:
    """Whether the comparison refuses the row at this step: the engine's scheme cannot be
    stable on its fastest mode (a stiff row, whose states then overflow to NaN)."""
    from mbfidelity.comparisons.runner import _refuse_unstable_step
    from mbfidelity.systems import get_system

    system = get_system(system_id)
    try:
        _refuse_unstable_step(system, backend, mech, backend.resolve_settings({}),
                              system.parameter_values(None, scenario=system.scenarios[0]), dt)
    except ValueError:
        return True
    return False


@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_bare_loop_ends_in_the_state_of_simulate(backend):
    """On every catalog row the engine expresses: after the same steps from the same state,
    the bare loop (nothing read per step) ends where `simulate` ends. Both step the same
    model, so they agree to round-off: the only difference is the map back to description
    coordinates of one row against many (a matrix product whose summation order may
    differ), bounded by 64 unit round-offs of the state's size."""
    checked = 0
    for sid, mech, q0, qd0, dt in _catalog_starts():
        if not backend.support(mech).ok or _unstable_at(sid, backend, mech, dt):
            continue
        run = backend.simulate(mech, q0, qd0, BARE_STEPS * dt, dt)
        bare = backend.bare_loop_run(mech, q0, qd0, BARE_STEPS * dt, dt)
        assert isinstance(bare.cpu_time, float) and bare.cpu_time >= 0.0
        for got, want in ((bare.q, run.q[-1]), (bare.qd, run.qd[-1])):
            bound = 64 * np.finfo(float).eps * np.maximum(1.0, np.abs(want))
            assert np.all(_angle_aware_gap(mech, got, want) <= bound), sid
        checked += 1
    assert checked >= 10


@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_bare_loop_check_tells_a_different_model_apart(backend):
    """The check above rejects a bare loop of another model: the compound pendulum with
    its weight 1 % larger and its inertia about the pivot kept changes the acceleration by
    1 %, and the rate after 20 steps far beyond the round-off bound."""
    _, values, mech = _pendulum(1.0)
    heavier = SYSTEM.numeric_mechanism({**values, "m": values["m"] * 1.01})
    q0, qd0, dt = np.array([1.0]), np.array([0.0]), 1e-3
    run = backend.simulate(mech, q0, qd0, BARE_STEPS * dt, dt)
    bare = backend.bare_loop_run(heavier, q0, qd0, BARE_STEPS * dt, dt)
    assert np.any(np.abs(bare.qd - run.qd[-1]) > 1e3 * 64 * np.finfo(float).eps)


@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_the_base_refuses_what_the_backend_cannot_run(backend):
    """The run's frame (simulators/base.py, point 6) is the base's: a step that is not
    positive and an unknown reaction joint are refused before any engine is built."""
    _, _, mech = _pendulum(1.0)
    with pytest.raises(ValueError, match="step must be positive"):
        backend.simulate(mech, np.array([1.0]), np.array([0.0]), 0.01, 0.0)
    with pytest.raises(KeyError):
        backend.simulate(mech, np.array([1.0]), np.array([0.0]), 0.01, 1e-3, None, ("nope",))


# --- contract point 5: every declared case builds and runs -------------------------------

def _gear_pair():
    """Two wheels on fixed pivots geared on their absolute angles (r1 phi1 + r2 phi2 = 0):
    the case of a coupling that no catalog row takes in every engine (Pymunk's GearJoint
    on two body angles)."""
    from mbfidelity.systems.model import Body, LinearCoupling, Mechanism, Revolute

    return Mechanism(
        bodies=(Body("wheel1", 1.0, 0.02), Body("wheel2", 2.0, 0.08)),
        joints=(Revolute("hub1", "world", "wheel1", "phi1"),
                Revolute("hub2", "world", "wheel2", "phi2", parent_anchor=(0.5, 0.0))),
        constraints=(LinearCoupling("gear", (("phi1", 0.1), ("phi2", 0.2))),),
        independent=("phi1",), gravity=9.81)


def _variant_starts(backend) -> list[tuple]:
    """The catalog's variants this engine builds, with their settings (e.g. rolling by
    friction contact in place of the rolling coupling)."""
    from mbfidelity.comparisons.runner import DEFAULT_DT, _engine_mechanism
    from mbfidelity.systems import all_systems

    out = []
    for sid, system in sorted(all_systems().items()):
        for variant in system.variants:
            if backend.id not in variant.settings:
                continue
            sc = system.scenarios[0]
            values = system.parameter_values(None, scenario=sc)
            ref = reference(system, sc, values, DEFAULT_DT, 5 * DEFAULT_DT)
            out.append((f"{sid} ({variant.name})", _engine_mechanism(system, values, variant.name),
                        ref.q[0], ref.qd[0], DEFAULT_DT, dict(variant.settings[backend.id])))
    return out


def _case_key(backend, kind, expression) -> tuple:
    cases = backend.EXPRESSIONS[kind]
    return kind, next(i for i, c in enumerate(cases) if c is expression or c == expression)


@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_every_declared_case_builds_and_runs(backend):
    """Each case a backend declares buildable (exact, soft or substitute) is taken by some
    mechanism (a catalog row, or the gear pair above), and the engine builds it and runs
    five steps to a finite state: a declaration without the code that builds it fails."""
    from mbfidelity.simulators.plan import elements

    declared = {(kind, i) for kind, cases in backend.EXPRESSIONS.items()
                for i, c in enumerate(cases) if c.level != "unsupported"}
    starts = [(sid, mech, q0, qd0, dt, None) for sid, mech, q0, qd0, dt in _catalog_starts()]
    starts += _variant_starts(backend)
    starts.append(("gear pair", _gear_pair(), np.array([0.3, -0.15]), np.array([1.0, -0.5]),
                   1e-3, None))
    built: dict[tuple, str] = {}
    for sid, mech, q0, qd0, dt, settings in starts:
        if not backend.support(mech).ok:
            continue
        new = {_case_key(backend, kind, backend.expression(mech, element))
               for kind, element in elements(mech)} & declared
        if not new - set(built):
            continue
        run = backend.simulate(mech, q0, qd0, 5 * dt, dt, settings)
        assert np.all(np.isfinite(run.q)) and np.all(np.isfinite(run.qd)), sid
        built.update({key: sid for key in new if key not in built})
    assert set(built) == declared, sorted(declared - set(built))


@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_a_prescribed_coordinate_starts_on_its_motion(backend):
    """Point 6: the motion the engine is given decides where a prescribed coordinate
    starts, not the state handed in; otherwise a wrong motion (an offset of the base's
    law) would never show in the engine's run. The base excitation of Fig. 25 starts 5 cm
    off its law here; the first sample must lie on the law, with the law's rate (a
    kinematic driver that starts with the rate of its first step, (q(h) - q(0))/h, is
    within h/2 max|q''| of it: Taylor's remainder)."""
    from mbfidelity.simulators.plan import motions

    system = get_system("base_excited_msd")
    values = system.parameter_values(None, scenario=system.scenarios[0])
    mech = system.numeric_mechanism(values)
    if not backend.support(mech).ok:
        pytest.skip(backend.support(mech).reason)
    (motion,) = motions(mech)
    q0, qd0 = np.zeros(len(mech.joints)), np.zeros(len(mech.joints))
    q0[motion.index] = motion.position(0.0) + 0.05
    h = 1e-3
    run = backend.simulate(mech, q0, qd0, 0.01, h)
    assert abs(run.q[0, motion.index] - motion.position(0.0)) < 1e-12
    amplitude, omega = 0.01, 5.0  # the law y = 0.01 sin(5 t) of this scenario
    assert motion.position(0.3) == pytest.approx(amplitude * np.sin(omega * 0.3), abs=1e-15)
    assert abs(run.qd[0, motion.index] - motion.rate(0.0)) <= h / 2 * amplitude * omega ** 2
