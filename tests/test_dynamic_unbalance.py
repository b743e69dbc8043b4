"""The dynamically unbalanced rotor (monograph §8.8, Fig. 32, eq. 87-88), a spatial
mechanism. Expected values are the closed forms worked by hand in tests/hand/
dynamic_unbalance.py (steady response of eq. 88, motor torque about e3)."""
import numpy as np
import pytest

from mbfidelity.analytic.linear import operating_equilibrium
from mbfidelity.analytic.reference import reference
from mbfidelity.systems import get_system
from mbfidelity.systems.model import Scenario

from hand import dynamic_unbalance as hand

SYSTEM = get_system("dynamic_unbalance")


#: eq. 87 with I1 != I2: periodic coefficients, so not a catalog scenario (the
#: comparisons gate runs against an equilibrium's modes)
PARAMETRIC = Scenario("parametric", {"psi": 0}, t_end=5.0,
                      overrides={"I1": 0.012, "I2": 0.008}, checks=("trajectory", "actuator"))


def _scenario(name):
    if name == PARAMETRIC.name:
        return PARAMETRIC
    return next(sc for sc in SYSTEM.scenarios if sc.name == name)


def test_the_description_is_spatial_and_pymunk_says_why_it_cannot_build_it():
    from mbfidelity.simulators import all_backends

    assert SYSTEM.mechanism.spatial
    mech = SYSTEM.numeric_mechanism(SYSTEM.parameter_values())
    support = all_backends()["pymunk"].support(mech)
    assert not support.ok and "planar (2-D) engine" in support.reason


def test_steady_scenario_follows_the_steady_response_of_eq88():
    sc = _scenario("steady")
    v = SYSTEM.parameter_values(scenario=sc)
    ref = reference(SYSTEM, sc, v, 1e-2)
    A = hand.steady_amplitude(v)
    w = v["omega"]
    np.testing.assert_allclose(ref.q[:, 0], A * np.sin(w * ref.t), rtol=0, atol=1e-9 * abs(A))
    np.testing.assert_allclose(ref.q[:, 1], w * ref.t, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["steady", "parametric"])
def test_motor_torque_is_the_e3_component_of_the_momentum_derivative(name):
    sc = _scenario(name)
    v = SYSTEM.parameter_values(scenario=sc)
    ref = reference(SYSTEM, sc, v, 1e-2)
    want = hand.motor_torque(v, ref.t, ref.qd[:, 0], ref.qdd[:, 0])
    got = ref.actuator_forces["motor"]
    assert np.max(np.abs(want)) > 1e-5  # the check is not vacuous
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.max(np.abs(want)))


def test_unequal_moments_make_a_parametric_system_without_an_equilibrium():
    """I1 != I2 (eq. 87): the inertia about the vertical varies with omega t, so the
    driven linearization, which needs constant coefficients, refuses it."""
    v = SYSTEM.parameter_values({"I1": 0.012, "I2": 0.008})
    with pytest.raises(ValueError, match="periodic-coefficient"):
        operating_equilibrium(SYSTEM, v)


def test_natural_frequency_of_eq88():
    v = SYSTEM.parameter_values()
    (mode,) = operating_equilibrium(SYSTEM, v).modes
    assert abs(mode.eigenvalue) == pytest.approx(hand.frequencies(v)[0], rel=1e-12)


@pytest.mark.parametrize("engine", ["mujoco", "pybullet", "exudyn"])
def test_each_engine_stores_the_full_tensor(engine):
    """The rotor's tensor as the engine stored it (principal moments and axes, read back)
    is the description's; its principal moments, worked by hand: I1, and the eigenvalues
    (I2 + I3)/2 -+ sqrt(((I3 - I2)/2)^2 + I23^2) of the e2-e3 block."""
    from mbfidelity.comparisons.runner import compare
    from mbfidelity.simulators import all_backends

    ok, why = all_backends()[engine].available()
    if not ok:
        pytest.skip(why)
    result = compare("dynamic_unbalance", engine, scenarios=["steady"])
    rotor = {m.name: m for m in result.metrics}["inertia.rotor"]
    assert rotor.status == "pass", (rotor.value, rotor.tolerance)
    v = SYSTEM.parameter_values()
    mean, half = (v["I2"] + v["I3"]) / 2, np.hypot((v["I3"] - v["I2"]) / 2, v["I23"])
    np.testing.assert_allclose(sorted(rotor.detail["engine_principal_moments"]),
                               sorted([v["I1"], mean - half, mean + half]), rtol=1e-12)


@pytest.mark.parametrize("ratio, verdict", [(1.0, "unstable"), (0.8, "stable")])
def test_analyze_gives_the_floquet_stability_of_the_parametric_case(ratio, verdict):
    """I1 != I2: d/dt(J(t) psi') + k_t psi = 0 with J = J0 + dJ cos(2 omega t),
    J0 = I_Gb + (I1 + I2)/2, dJ = (I2 - I1)/2 (eq. 87 at I23 = 0), a Hill equation: the
    first parametric-resonance tongue sits at 2 omega = 2 sqrt(k_t/J0); at |dJ|/J0 = 0.22
    its centre is unstable and 0.8 of it lies outside."""
    import json

    from typer.testing import CliRunner

    from mbfidelity.cli import app

    I1, I2, I_Gb, k_t = 0.03, 0.001, 0.05, 10.0
    omega = ratio * np.sqrt(k_t / (I_Gb + (I1 + I2) / 2))
    out = CliRunner().invoke(app, ["analyze", "dynamic_unbalance", "--json",
                                   "--param", f"I1={I1}", "--param", f"I2={I2}",
                                   "--param", f"omega={omega}"])
    assert out.exit_code == 0, out.output
    doc = json.loads(out.output)
    assert doc["linearization"] is None and "periodic-coefficient" in doc["periodic_coefficients"]
    (result,) = doc["floquet"]
    assert result["verdict"] == verdict, result
    assert result["period"] == pytest.approx(2 * np.pi / omega, rel=1e-12)


def test_printed_angular_momentum_and_its_derivative_agree_with_the_derivation():
    """§8.8 prints Omega, L_Gr = I_Gr Omega and the three components of dL_Gr/dt in the
    rotor basis {e1, e2, e3}. From the derivation's rotation matrices: Omega in body axes
    (x, y, z) = (e3, e1, e2), and dL/dt = (dL/dt)_body + Omega x L with psi'' free and
    phi = omega t; every printed component (coded here as printed) must match."""
    import sympy as sp

    from mbfidelity.analytic.derivation import derivation_of
    from mbfidelity.systems import coordinate_symbols

    d = derivation_of("dynamic_unbalance")
    P = SYSTEM.symbols
    psi, psi_d, psi_dd = coordinate_symbols("psi")
    phi, phi_d, phi_dd = coordinate_symbols("phi")
    I1, I2, I3, I23, w = P.I1, P.I2, P.I3, P.I23, P.omega
    s, c = sp.sin(phi), sp.cos(phi)
    body = d.angular_velocity("rotor")  # (x, y, z) = (e3, e1, e2)
    omega_e = sp.Matrix([body[1], body[2], body[0]])
    assert (omega_e - sp.Matrix([psi_d * s, psi_d * c, phi_d])).applyfunc(sp.simplify) == \
        sp.zeros(3, 1)
    I_e = sp.Matrix([[I1, 0, 0], [0, I2, I23], [0, I23, I3]])
    L = I_e * omega_e
    rates = {psi: psi_d, psi_d: psi_dd, phi: phi_d, phi_d: phi_dd}
    L_dot = sp.Matrix([sum(sp.diff(e, x) * v for x, v in rates.items()) for e in L])
    L_dot = (L_dot + omega_e.cross(L)).subs({phi_d: w, phi_dd: 0})
    printed = sp.Matrix([
        I1 * psi_dd * s + I1 * psi_d * w * c + I23 * psi_d**2 * c**2 + I3 * psi_d * w * c
        - I2 * psi_d * w * c - I23 * w**2,
        I2 * psi_dd * c - I2 * psi_d * w * s - I23 * psi_d**2 * s * c - I3 * psi_d * w * s
        + I1 * psi_d * w * s,
        I23 * psi_dd * c - I23 * psi_d * w * s + I2 * psi_d**2 * s * c + I23 * psi_d * w * s
        - I1 * psi_d**2 * s * c])
    assert (L_dot - printed).applyfunc(sp.simplify) == sp.zeros(3, 1)
