"""A spatial closed loop with a redundant constraint: Bricard's mechanism (IFToMM A04,
systems/benchmarks/iftomm_a04_bricard.py), described with a `HingeClosure` and `redundant = 1`.
Expected values come from the loop's geometry and mechanics, never from our output: the
closure's velocity rows written by hand from the hinge axes (twists), the known mobility
of the linkage (one, with five tree coordinates: rank 4 of 5 rows), and the conservation
of energy (no force but gravity does work)."""
import os

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from mbfidelity import systems
from mbfidelity.systems.model import HingeClosure, Mechanism, Revolute

BRICARD = "iftomm_a04_bricard"

#: the initial (cube) position: hinge points and unit axes O1, P2, P3, P4, P5 (L = 1)
POINTS = np.array([(0, 0, 0), (1, 0, 0), (1, -1, 0), (1, -1, 1), (0, -1, 1)], float)
AXES = np.array([(0, 1, 0), (0, 0, 1), (1, 0, 0), (0, 1, 0), (0, 0, 1)], float)
O6 = np.array([0.0, 0.0, 1.0])


@pytest.fixture
def catalog_with(request):
    """The catalog with the given mechanism modules added through the system path (as
    `--system-path` does), restored afterwards."""
    before = os.environ.get(systems.SYSTEM_PATH_VARIABLE)

    def add(*paths):
        os.environ[systems.SYSTEM_PATH_VARIABLE] = os.pathsep.join(map(str, paths))
        systems._REGISTRY = None
    yield add
    if before is None:
        os.environ.pop(systems.SYSTEM_PATH_VARIABLE, None)
    else:
        os.environ[systems.SYSTEM_PATH_VARIABLE] = before
    systems._REGISTRY = None


def _model(values=None):
    from mbfidelity.analytic.numeric import numeric_model

    s = systems.get_system(BRICARD)
    return s, numeric_model(BRICARD, s.parameter_values(values or {}))


def _hand_jacobian() -> np.ndarray:
    """The closure's velocity rows at the cube position from the twists of the five tree
    hinges: rod 5's point at O6 moves with sum u_k x (O6 - p_k) q_k', rod 5 turns with
    w = sum u_k q_k'; the axis rows n . u_b, n . w_b with n = x, u_b = z, w_b = -y
    (`perpendicular_pair` of x) change at (w x n) . z = -w_y and (w x n) . (-y) = -w_z."""
    point_rows = np.array([np.cross(u, O6 - p) for u, p in zip(AXES, POINTS)]).T
    return np.vstack([point_rows, -AXES[:, 1], -AXES[:, 2]])


def test_a_spatial_mechanism_takes_hinge_closures_only():
    tree = (Revolute("J", "world", "b", "q", axis=(1, 0, 0)),)
    from mbfidelity.systems.model import Body, PointOnPoint

    body = Body.spatial("b", 1.0, ((1, 0, 0), (0, 1, 0), (0, 0, 1)))
    with pytest.raises(ValueError, match="planar"):
        Mechanism(bodies=(body,), joints=tree, independent=("q",),
                  constraints=(PointOnPoint("c", "b", (0, 0), "world", (0, 0)),))
    with pytest.raises(ValueError, match="three components"):
        Mechanism(bodies=(body,), joints=tree, independent=("q",),
                  constraints=(HingeClosure("c", "b", (0, 0), "world", (0, 0, 0),
                                            (1, 0, 0), (1, 0, 0)),))
    with pytest.raises(ValueError, match="redundant"):
        Mechanism(bodies=(body,), joints=tree, redundant=1)


def test_the_closure_rows_are_the_twists_and_one_is_redundant():
    """The derivation's Jacobian at the cube position equals the rows written from the
    hinge twists; its rank is 4 = 5 coordinates less the linkage's one degree of freedom
    (Bricard's: Grübler's count 5 - 5 = 0), at the start and along the motion."""
    _, model = _model()
    hand = _hand_jacobian()
    np.testing.assert_allclose(model.constraint_jacobian(np.zeros(5)), hand, atol=1e-12)
    assert np.linalg.matrix_rank(hand) == 4
    for q1 in (0.0, 0.3, -0.3):
        guess = np.zeros(5)
        guess[0] = q1
        q = model.complete(guess)
        assert np.max(np.abs(model.constraint_values(q))) < 1e-12
        assert model.constraint_rank(q)[0] == 4


def test_the_reference_conserves_energy():
    """From rest in the cube position the rods fall under gravity alone: T + V keeps its
    initial value -3 m g L (centres at heights 0, -L/2, -L, -L, -L/2) to the integration
    tolerance (DOP853 at 1e-10 over 1 s: the error per unit time stays near the
    tolerance times the energy's scale, m g L = 9.81 J)."""
    s, model = _model()
    v = s.parameter_values()
    y0 = np.zeros(2)
    sol = solve_ivp(model.ode_rhs, (0.0, 1.0), y0, method="DOP853", rtol=1e-10,
                    atol=1e-10, dense_output=True)
    assert sol.success
    t = np.linspace(0.0, 1.0, 21)
    states = [model.state_from_independent(y[:1], y[1:]) for y in sol.sol(t).T]
    q = np.array([a for a, _ in states])
    qd = np.array([b for _, b in states])
    energy = model.energy(q, qd)
    assert np.max(np.abs(q[:, 0])) > 0.1  # it moved
    np.testing.assert_allclose(energy, -3 * v["m"] * v["g"] * v["L"], rtol=0, atol=1e-7)
    # the redundant multipliers: least-norm, and the equations of motion hold with them
    qdd, lam = model.dynamics(q[-1], qd[-1], 1.0)
    residual = model.residual(q[-1], qd[-1], qdd, 1.0) + model.constraint_jacobian(
        q[-1]).T @ lam
    np.testing.assert_allclose(residual, 0, atol=1e-9)


LONGER_ROD = '''
from dataclasses import replace
from mbfidelity.systems.benchmarks import iftomm_a04_bricard as base

def build(P):
    mech = base.build(P)
    rod3 = mech.joints[3]  # J4: rod 4 hangs from rod 3's far end, 1 % further out
    longer = replace(rod3, parent_anchor=tuple(1.02 * c for c in rod3.parent_anchor))
    return replace(mech, joints=mech.joints[:3] + (longer,) + mech.joints[4:])

SYSTEM = replace(base.SYSTEM, id="bricard_longer_rod", build=build)
'''


@pytest.mark.slow
def test_a_rod_one_percent_longer_is_caught(catalog_with, tmp_path):
    """Rod 3 1 % longer (its far hinge 0.01 L further out): the six hinges no longer
    form Bricard's linkage, the loop cannot close with the rank the description declares
    (a generic 6R loop is rigid: rank 5), and assembling it is refused."""
    module = tmp_path / "bricard_longer_rod.py"
    module.write_text(LONGER_ROD)
    catalog_with(module)
    from mbfidelity.analytic.numeric import numeric_model

    s = systems.get_system("bricard_longer_rod")
    model = numeric_model(s.id, s.parameter_values())
    assert np.max(np.abs(model.constraint_values(np.zeros(5)))) == pytest.approx(0.01)
    with pytest.raises(RuntimeError, match="rank|no solution|assembly lost"):
        model.complete(np.zeros(5))


@pytest.mark.slow
def test_analyze_compares_the_published_energy_over_the_whole_run():
    """`analyze`'s published entry: T + V at the end of the benchmark's 10 s equals its
    value at the release, -3 m g L, within the reference's own error estimate."""
    from mbfidelity.analytic.published import compare_published

    s = systems.get_system(BRICARD)
    values = s.parameter_values()
    (entry,) = compare_published(s, values)
    assert entry["quantity"] == "energy" and entry["applies"]
    assert entry["published_value"] == pytest.approx(-3 * 9.81, rel=1e-15)
    assert not entry["beyond_reference_error"]
    assert entry["reference_error"] < 1e-8
