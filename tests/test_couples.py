"""A hinge spring written two ways: on a relative angle (`CoordinateForce`), and as a
couple between two absolute angles (`CoordinateForce.relative_to`). The chain of three
hinged bars is the same mechanism in both, so the derivations' energies agree at every
state and every engine's run of one is its run of the other (the same joints, the spring
on the same hinge)."""
import numpy as np
import pytest

from mbfidelity.analytic.derivation import Derivation
from mbfidelity.systems.model import (Body, CoordinateForce, Mechanism, Revolute, Segment,
                                      coordinate_spring_damper)

#: bar length (m), mass (kg), hinge stiffness (N m/rad), hinge damping (N m s/rad)
L, MASS, K, C = 0.4, 0.7, 9.0, 0.05


def _chain(absolute: bool, simplify: bool = True) -> Mechanism:
    bodies, joints, forces = [], [], []
    for i in range(1, 4):
        bodies.append(Body(f"bar{i}", MASS, MASS * L * L / 12,
                           (Segment((-L / 2, 0), (L / 2, 0), 0.01),)))
        if i == 1:
            joints.append(Revolute("pin", "world", "bar1", "q1", child_anchor=(-L / 2, 0)))
            continue
        joints.append(Revolute(f"hinge{i}", f"bar{i - 1}", f"bar{i}", f"q{i}",
                               parent_anchor=(L / 2, 0), child_anchor=(-L / 2, 0),
                               absolute=absolute))
        law = coordinate_spring_damper(K, 0, C)
        forces.append(CoordinateForce(f"spring{i}", f"q{i}", **law,
                                      relative_to=f"q{i - 1}" if absolute else None))
    return Mechanism(bodies=tuple(bodies), joints=tuple(joints), forces=tuple(forces),
                     gravity=9.81, simplify=simplify)


#: absolute angles from relative ones: th = L_cum q
CUMULATIVE = np.tril(np.ones((3, 3)))


@pytest.mark.parametrize("simplify", [True, False])
def test_the_couple_is_the_hinge_spring_in_the_derivation(simplify):
    import sympy as sp

    rel, ab = Derivation(_chain(False)), Derivation(_chain(True, simplify))
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, qd = rng.uniform(-2, 2, 3), rng.uniform(-3, 3, 3)
        th, thd = CUMULATIVE @ q, CUMULATIVE @ qd
        at_rel = {**dict(zip(rel.q, q)), **dict(zip(rel.qd, qd))}
        at_abs = {**dict(zip(ab.q, th)), **dict(zip(ab.qd, thd))}
        for e_rel, e_abs in ((rel.T, ab.T), (rel.V, ab.V), (rel.D, ab.D)):
            assert float(e_abs.xreplace(at_abs)) == pytest.approx(
                float(e_rel.xreplace(at_rel)), rel=1e-12, abs=1e-12)
        # virtual power: Q_abs . d(th) = Q_rel . dq with d(th) = L_cum dq
        Q_rel = np.array(sp.Matrix(rel.Q).xreplace(at_rel), dtype=float).ravel()
        Q_abs = np.array(sp.Matrix(ab.Q).xreplace(at_abs), dtype=float).ravel()
        np.testing.assert_allclose(CUMULATIVE.T @ Q_abs, Q_rel, rtol=1e-12, atol=1e-12)


def test_a_couple_must_join_two_hinge_angles():
    with pytest.raises(ValueError, match="another coordinate"):
        Mechanism(bodies=(Body("a", 1.0, 0.1, ()),),
                  joints=(Revolute("pin", "world", "a", "q1"),),
                  forces=(CoordinateForce("s", "q1", 0, relative_to="q1"),))


def _engines():
    from mbfidelity.simulators import all_backends

    return sorted(name for name, b in all_backends().items() if b.available()[0])


@pytest.mark.parametrize("engine", _engines())
def test_every_engine_runs_the_couple_as_the_hinge_spring(engine):
    """Released bent, the chain swings and its hinges work: the absolute angles of the two
    builds agree to round-off (each engine sees the same joints and the same hinge
    torques; only the description's coordinates differ)."""
    from mbfidelity.simulators import all_backends

    backend = all_backends()[engine]
    q0_rel = np.array([-1.2, 0.5, -0.4])
    qd0_rel = np.array([0.3, -0.2, 0.6])
    runs = []
    for absolute in (False, True):
        mech = _chain(absolute)
        assert backend.support(mech).ok, backend.support(mech).reason
        to = CUMULATIVE if absolute else np.eye(3)
        run = backend.simulate(mech, to @ q0_rel, to @ qd0_rel, 1.0, 1e-3)
        runs.append(run.q if absolute else run.q @ CUMULATIVE.T)
    # the hinges swing by ~1 rad; only the round-off of the two coordinate maps differs
    # (measured at most 3.1e-15 rad over the 1000 steps, all four engines)
    np.testing.assert_allclose(runs[1], runs[0], rtol=0, atol=1e-12)
