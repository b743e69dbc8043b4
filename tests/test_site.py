"""The site's content as saved upstream (comparisons/typeset.py, comparisons/animation.py):
the derived model typeset, a misprint's differing terms found and marked, and the motion
drawn. Expected values are hand derivations, independent of the code under test."""
import numpy as np
import sympy as sp

from mbfidelity.comparisons.animation import animation
from mbfidelity.comparisons.typeset import errata_typeset, model_document
from mbfidelity.systems import get_system


def test_double_pendulum_model_is_typeset_with_its_matrices():
    """Fig. 37 with m = 1 kg, l = 0.5 m, I = m (2l)^2 / 12: by hand, M = [[I + m l^2 +
    m (2l)^2, 2 m l^2], [2 m l^2, I + m l^2]] = [[4/3, 1/2], [1/2, 1/3]] and K =
    diag(3 m g l, m g l) at the hanging equilibrium."""
    doc = model_document("double_pendulum")
    # rates with Newton's dot over the coordinate
    assert "<mover>" in doc["kinetic_energy"] and "&#729;" in doc["kinetic_energy"]
    assert len(doc["equations_of_motion"]) == 2 and "&#168;" in doc["equations_of_motion"][0]
    op = doc["operating_point"]
    for entry in ("1.33333", "0.5", "0.333333"):
        assert f"<mn>{entry}</mn>" in op["M"]
    for entry in (f"{3 * 9.81 * 0.5:.6g}", f"{9.81 * 0.5:.6g}"):
        assert f"<mn>{entry}</mn>" in op["K"]
    assert op["stable"] and len(op["modes"]) == 2
    assert {p["name"]: p["unit"] for p in doc["parameters"]}["I"] == "kg m^2"


def test_a_misprint_is_marked_with_its_difference():
    """Fig. 14, eq. 51 prints the centripetal term with a spurious 1/2. By hand, from T =
    (I_O + m r^2 cos^2 phi) phi'^2 / 2 and the guide's friction -c y' on y = r sin phi,
    Lagrange gives (I_O + m r^2 cos^2) phi'' - m r^2 sin cos phi'^2 + c r^2 cos^2 phi' + ...:
    printed - derived = m r^2 sin cos phi'^2 / 2 - c r^2 cos^2 phi' (the printed equation
    is written without friction). Both misprinted terms are marked; an agreeing formula
    (eq. 45) has none."""
    system = get_system("scotch_yoke")
    typeset = errata_typeset(system, frozenset({"Fig. 14, eq. 51"}))
    eq51 = typeset["Fig. 14, eq. 51"]
    m, r, c, phi, phi_dot = sp.symbols("m r c phi phi_dot")
    expected = (m * r**2 * sp.sin(phi) * sp.cos(phi) * phi_dot**2 / 2
                - c * r**2 * sp.cos(phi) ** 2 * phi_dot)
    assert sp.simplify(sp.sympify(eq51["difference_text"]) - expected) == 0
    assert eq51["printed"].count('class="differs"') >= 1
    assert eq51["derived"].count('class="differs"') >= 1
    eq45 = typeset["Fig. 14, eq. 45"]
    assert "differs" not in eq45["printed"] + eq45["derived"]
    assert sp.sympify(eq45["difference_text"]) == 0


def test_the_motion_is_drawn_rigidly():
    """The compound pendulum's frames: the bar's free end stays at L from the pivot, and a
    quarter turn of phi turns it by a quarter turn about the pivot."""
    t = np.array([0.0, 1.0])
    q = np.array([[0.0], [np.pi / 2]])
    doc = animation("compound_pendulum", {"exact_only": {"s": {"t": t, "q_ref": q, "q": q}}})
    frames = doc["scenarios"]["s"]["traces"]["exact"]
    segment = next(i for i in doc["items"] if i["kind"] == "segment")["points"]
    pivot = next(i for i in doc["items"] if i["kind"] == "joint")["points"][0]
    L = get_system("compound_pendulum").parameter_values()["L"]
    arms = []
    for f in frames:
        ends = [np.array(f[k]) - np.array(f[pivot]) for k in segment]
        far = max(ends, key=np.linalg.norm)
        assert abs(np.linalg.norm(far) - L) < 1e-3
        arms.append(far)
    cos = np.dot(arms[0], arms[1]) / (np.linalg.norm(arms[0]) * np.linalg.norm(arms[1]))
    assert abs(cos) < 1e-3
