"""The spatial (3-D) description and derivation (model convention 10). Expected values are
independent: the planar derivation of the same mechanism, and Euler's equations for a rigid
body written out here by hand."""
import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from mbfidelity.analytic.derivation import Derivation
from mbfidelity.systems.model import GRAVITY as g
from mbfidelity.systems.model import Body, Mechanism, Revolute, rotation3

m, L, l, I_O, I_xx, I_yy, I_xy = sp.symbols("m L l I_O I_xx I_yy I_xy", positive=True)


def planar_pendulum() -> Mechanism:
    bar = Body("bar", m, I_O - m * l**2)
    return Mechanism((bar,), (Revolute("pivot", "world", "bar", "phi", child_anchor=(0, l)),))


def spatial_pendulum() -> Mechanism:
    """The compound pendulum of Fig. 7 as a 3-D body turning about z, its tensor with an
    in-plane product of inertia I_xy and the in-plane moments, which a rotation about z
    never excites."""
    tensor = ((I_xx, I_xy, 0), (I_xy, I_yy, 0), (0, 0, I_O - m * l**2))
    bar = Body.spatial("bar", m, tensor)
    pivot = Revolute("pivot", "world", "bar", "phi", child_anchor=(0, l, 0), axis=(0, 0, 1))
    return Mechanism((bar,), (pivot,))


def test_a_planar_mechanism_is_not_spatial():
    assert not planar_pendulum().spatial
    assert spatial_pendulum().spatial


def test_spatial_pendulum_has_the_planar_equations():
    planar, spatial = Derivation(planar_pendulum()), Derivation(spatial_pendulum())
    assert spatial.spatial and not planar.spatial
    for a, b in ((planar.M, spatial.M), (planar.h, spatial.h), (planar.Q, spatial.Q)):
        assert (a - b).applyfunc(sp.simplify) == sp.zeros(*a.shape)
    assert sp.simplify(planar.V - spatial.V) == 0
    # M, C, K at the equilibrium phi = 0: I_O, 0, m g l (Fig. 7, eq. 5)
    phi = spatial.q[0]
    assert sp.simplify(spatial.M[0, 0] - I_O) == 0
    assert sp.simplify(sp.diff(spatial.V, phi, 2).subs(phi, 0) - m * g * l) == 0
    assert spatial.D == 0


def _trajectory(derivation: Derivation, values: dict) -> np.ndarray:
    rhs = (derivation.M.inv() * (derivation.Q - derivation.h)).xreplace(values)
    f = sp.lambdify((derivation.q[0], derivation.qd[0]), rhs[0], "math")
    sol = solve_ivp(lambda t, y: [y[1], f(y[0], y[1])], (0, 3), [2.0, 0.0],
                    t_eval=np.linspace(0, 3, 31), rtol=1e-11, atol=1e-12)
    return sol.y[0]


def test_spatial_pendulum_trajectory_is_the_planar_one():
    values = {m: 1.0, l: 0.5, I_O: 1 / 3, I_xx: 0.05, I_yy: 0.002, I_xy: 0.004, g: 9.81}
    np.testing.assert_allclose(_trajectory(Derivation(spatial_pendulum()), values),
                               _trajectory(Derivation(planar_pendulum()), values),
                               rtol=0, atol=1e-12)


def test_angular_velocity_from_rotation_matrices():
    """Two hinges (z then a body-fixed x): body-axes angular velocity Rx(b)^T (0, 0, a')
    + (b', 0, 0), written out by hand."""
    a, b = sp.symbols("a b", real=True)
    body1 = Body.spatial("one", 1, ((1, 0, 0), (0, 1, 0), (0, 0, 1)))
    body2 = Body.spatial("two", 1, ((1, 0, 0), (0, 2, 0), (0, 0, 3)))
    mech = Mechanism((body1, body2), (
        Revolute("first", "world", "one", "a", axis=(0, 0, 1)),
        Revolute("second", "one", "two", "b", axis=(1, 0, 0))), up=(0, 0, 1))
    d = Derivation(mech)
    (_, qb), (va, vb) = list(d.q), list(d.qd)
    want = rotation3((1, 0, 0), qb).T * sp.Matrix([0, 0, va]) + sp.Matrix([vb, 0, 0])
    assert (d.angular_velocity("two") - want).applyfunc(sp.simplify) == sp.zeros(3, 1)
    # the frame's inertia about the vertical: 1 + 2 sin^2 b + 3 cos^2 b (Euler's equations)
    assert sp.simplify(d.M[0, 0] - (1 + 2 * sp.sin(qb)**2 + 3 * sp.cos(qb)**2)) == 0


def test_spatial_description_refuses_bad_tensors():
    with pytest.raises(ValueError, match="symmetric"):
        Body.spatial("x", 1, ((1, 0.1, 0), (0, 1, 0), (0, 0, 1)))
    with pytest.raises(ValueError, match="zz entry"):
        Body("x", 1, 2, inertia_tensor=((1, 0, 0), (0, 1, 0), (0, 0, 1)))


# --- conformance of the 3-D path: the planar compound pendulum rebuilt in 3-D -----------

def _spatial_copy(mech: Mechanism) -> Mechanism:
    """A numeric planar mechanism of hinged bodies rewritten with the 3-D elements: full
    tensors with in-plane moments and an in-plane product (never excited by a turn about
    z), three-component anchors, hinge axes z."""
    bodies = tuple(Body.spatial(b.name, b.mass, ((0.6 * b.inertia, 0.1 * b.inertia, 0),
                                                 (0.1 * b.inertia, 0.5 * b.inertia, 0),
                                                 (0, 0, b.inertia)), b.shapes)
                   for b in mech.bodies)
    joints = tuple(Revolute(j.name, j.parent, j.child, j.coordinate,
                            parent_anchor=(*j.parent_anchor, 0), child_anchor=(*j.child_anchor, 0),
                            axis=(0, 0, 1)) for j in mech.joints)
    return Mechanism(bodies, joints, mech.forces, mech.gravity)


def _three_d_engines():
    from mbfidelity.simulators import all_backends

    out = []
    for engine, backend in sorted(all_backends().items()):
        ok, _ = backend.available()
        if ok and not backend.SPATIAL_REASON:
            out.append(engine)
    return out


@pytest.mark.parametrize("engine", _three_d_engines())
def test_spatial_build_of_the_compound_pendulum_passes_the_planar_gates(engine):
    from mbfidelity.comparisons.metrics import amplitude, trajectory_errors
    from mbfidelity.comparisons.runner import compare
    from mbfidelity.simulators import all_backends
    from mbfidelity.systems import get_system

    system = get_system("compound_pendulum")
    planar = compare("compound_pendulum", engine, scenarios=["large"])
    gate = {m.name: m for m in planar.metrics}["large.trajectory_max"]
    assert gate.status == "pass"
    sc = next(s for s in system.scenarios if s.name == "large")
    values = system.parameter_values(scenario=sc)
    from mbfidelity.analytic.reference import reference

    ref = reference(system, sc, values, planar.dt)
    spatial = _spatial_copy(system.numeric_mechanism(values))
    assert spatial.spatial
    backend = all_backends()[engine]
    assert backend.support(spatial).ok, backend.support(spatial).reason
    run = backend.simulate(spatial, ref.q[0], ref.qd[0], sc.t_end, planar.dt,
                           planar.settings)
    n = min(len(run.t), len(ref.t))
    error, _ = trajectory_errors(run.q[:n], ref.q[:n], amplitude(ref.q, np.zeros(1)))
    assert error <= gate.tolerance, (error, gate.tolerance)
    # the planar build's own error, within the integrator's reach of it
    assert error == pytest.approx(gate.value, rel=0.5, abs=1e-9)
