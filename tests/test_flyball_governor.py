"""The stiff flyball governor (IFToMM A05, systems/benchmarks/iftomm_a05_flyball_governor.py):
a spatial tree (free shaft, slide, two hinged rods) with stiff spatial spring-damper
couplers, whose reference is integrated by Radau IIA. Expected values come from the hand
derivation (tests/hand/iftomm_a05_flyball_governor.py): the angular momentum about the
shaft, which no torque changes, and the slow swing's far turning point on Watt's rigid
linkage with that momentum and the energy the stiff couplers barely dissipate."""
import numpy as np
import pytest

from hand import iftomm_a05_flyball_governor as hand
from mbfidelity.analytic.numeric import numeric_model
from mbfidelity.analytic.reference import consistent_initial_state, integrate
from mbfidelity.systems import get_system

A05 = "iftomm_a05_flyball_governor"


def _solve(values, t, tol=1e-10):
    s = get_system(A05)
    model = numeric_model(A05, values)
    q0, qd0 = consistent_initial_state(s, s.scenarios[0], values)
    return model, integrate(model, np.concatenate([q0, qd0]), t, tol, stiff=True)


@pytest.mark.parametrize("params", [{}, {"m": 3.0, "omega0": 8.0, "alpha0": 0.4, "d": 0.08}])
def test_the_published_momentum_is_the_hand_closed_form(params):
    """The module's published H_0 = I_axis(phi_0) omega_0 equals the hand's (written
    apart, body by body), at the defaults and elsewhere."""
    s = get_system(A05)
    v = s.parameter_values(params)
    (item,) = s.published(s.symbols)
    assert item.value(v) == pytest.approx(hand.initial_angular_momentum(v), rel=1e-13)


def test_the_reference_keeps_the_angular_momentum():
    """H = I_axis(phi1, phi2) psi' (hand) stays at H_0 along the Radau solution: the
    integration at 1e-10 over 2 s (two swings) keeps it to about the tolerance times H's
    scale (H_0 ~ 54 kg m^2/s: within 1e-7); the swing changes I_axis and psi' by some
    20 %, so a wrong moment or a lost torque-free balance would show at that scale."""
    s = get_system(A05)
    v = s.parameter_values()
    t = np.linspace(0.0, 2.0, 41)
    _, y = _solve(v, t)
    H = np.array([hand.axial_moment(v, row[2], -row[3]) * row[4] for row in y])
    assert np.ptp(y[:, 4]) > 0.1 * v["omega0"]  # the shaft's speed did change
    np.testing.assert_allclose(H, hand.initial_angular_momentum(v), rtol=0, atol=1e-7)


def test_the_swing_turns_where_the_rigid_linkage_does():
    """The slider's far turning point against the hand's rigid linkage (couplers at l0,
    H and the energy kept): the couplers stretch under the swing's loads by F/k (forces
    of a few hundred newtons: a few 1e-4 m each) and their dampers take a little of the
    energy, so the two agree to 1e-3 m, while the swing itself spans 0.24 m."""
    v = get_system(A05).parameter_values()
    t = np.linspace(0.0, 1.0, 2001)  # the first swing, up and back
    _, y = _solve(v, t)
    s0, far = hand.turning_points(v)
    assert y[0, 1] == pytest.approx(s0, abs=1e-12)
    assert far - s0 > 0.2
    assert np.max(y[:, 1]) == pytest.approx(far, abs=1e-3)


@pytest.mark.slow
def test_the_implicit_reference_agrees_with_dop853():
    """Radau IIA with the exact Jacobian against the explicit DOP853 (whose steps the
    couplers' decay rates keep near 1e-4 s), both at the reference's tolerance 1e-12,
    over the benchmark's 10 s: the two methods share nothing but the equations, so their
    distance bounds the reference's error; it must stay within the reference's own
    estimate (the change to 1e-11, a few 1e-12 m) and far below the engines' errors."""
    from mbfidelity.analytic.reference import LOOSE, TIGHT

    v = get_system(A05).parameter_values()
    t = np.linspace(0.0, 10.0, 101)
    model, implicit = _solve(v, t, tol=TIGHT)
    loose = integrate(model, implicit[0], t, LOOSE, stiff=True)
    explicit = integrate(model, implicit[0], t, TIGHT, stiff=False)
    estimate = np.max(np.abs(loose[:, 1] - implicit[:, 1]))
    assert estimate < 1e-10
    np.testing.assert_allclose(implicit[:, 1], explicit[:, 1], rtol=0, atol=estimate)


# --- engines ---------------------------------------------------------------------------

@pytest.mark.parametrize("simulator", ["mujoco", "exudyn"])
def test_the_engines_build_the_couplers_in_space(simulator):
    """MuJoCo's build (hinges, a slide joint, a spatial tendon with its own stiffness,
    free length and damping per coupler) and Exudyn's (a kinematic tree of RevoluteY/Z
    and PrismaticY links, an ObjectConnectorSpringDamper per coupler between tree
    markers) follow the Radau solution over the first half swing at the row's step, both
    with their RK4: the error on the swing is of order (w h)^4 w T with
    w ~ 7 rad/s, h = 1e-4 s (about 1e-13 m), the couplers' fast modes are barely excited
    from unstretched couplers, and the reference's own error is near its tolerance, so
    the two agree to 1e-8 m in s (a wrong attachment point or law would move s by the
    order of its own error: millimetres)."""
    from mbfidelity.simulators import all_backends
    from mbfidelity.systems.benchmarks.iftomm_a05_flyball_governor import STEP

    BACKEND = all_backends()[simulator]
    if not BACKEND.available()[0]:
        pytest.skip(f"{simulator} not installed")

    s = get_system(A05)
    v = s.parameter_values()
    mech = s.numeric_mechanism(v)
    assert BACKEND.support(mech).ok
    q0, qd0 = consistent_initial_state(s, s.scenarios[0], v)
    run = BACKEND.simulate(mech, q0, qd0, 0.5, STEP)
    _, y = _solve(v, run.t[::500])
    assert np.ptp(y[:, 1]) > 0.1  # the slider moved
    np.testing.assert_allclose(run.q[::500, 1], y[:, 1], rtol=0, atol=1e-8)


def test_the_project_step_is_refused_on_the_couplers():
    """At the project's default step (1e-3 s) RK4 cannot be stable on the couplers'
    fastest decay (w h far beyond its limit): the comparison refuses it before any run,
    and the row's own step (`System.step`) is what a comparison given no step uses."""
    pytest.importorskip("mujoco")
    from mbfidelity.comparisons.runner import compare

    with pytest.raises(ValueError, match="cannot be stable with mujoco's RK4"):
        compare(A05, "mujoco", dt=1e-3)
    assert get_system(A05).step is not None and get_system(A05).step < 1e-3


@pytest.mark.slow
def test_mujoco_passes_and_a_heavier_ball_is_rejected():
    """MuJoCo passes every gate at the row's step; with both balls 1 % heavier in its
    build only (the reference keeps the true mass) the swing's balance of centrifugal pull,
    weight and the slider's weight shifts, and s(t) moves far beyond the trajectory gate."""
    pytest.importorskip("mujoco")
    from mbfidelity.comparisons import power
    from mbfidelity.comparisons.runner import compare

    baseline = compare(A05, "mujoco")
    assert baseline.supported and baseline.passed, baseline.metrics
    mutated = compare(A05, "mujoco", engine_scale={"m": 1.01})
    rejecting = power.rejecting_metrics(baseline, mutated)
    assert not mutated.passed
    assert any(name.startswith("published.trajectory") for name in rejecting), rejecting


@pytest.mark.slow
def test_the_benchmark_error_table_runs_the_governor_at_its_step():
    """`api.benchmark_errors`: MuJoCo completes the benchmark's 10 s at the row's step,
    its error in s well below a millimetre."""
    pytest.importorskip("mujoco")
    from mbfidelity import api

    row, = api.benchmark_errors([A05], ["mujoco"])["rows"]
    assert row["status"] == "completed" and row["dt"] == get_system(A05).step
    assert set(row["errors"]) == {"s"} and row["error"] < 1e-6


@pytest.mark.slow
def test_a_published_value_within_the_solves_tolerance_is_not_flagged():
    """At other parameters the published momentum and the reference's differ at round-off
    (the change between the two solves' tolerances is then round-off too): within the
    tight solve's tolerance relative to the value, not flagged; a published value off by
    1e-9 is."""
    from mbfidelity.analytic.published import compare_published
    from mbfidelity.analytic.reference import TIGHT

    s = get_system("iftomm_a05_flyball_governor")
    values = s.parameter_values({"omega0": 8.0, "k": 4e5})
    (entry,) = compare_published(s, values)
    assert entry["applies"] and entry["reference_error"] >= TIGHT * abs(entry["reference_value"])
    assert not entry["beyond_reference_error"], entry
    off = abs(entry["published_value"] * 1e-9)
    assert off > entry["reference_error"]  # a misprint of that size would be flagged
