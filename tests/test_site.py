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


def test_section6_formulas_are_derived_and_a_changed_one_is_caught():
    """§6 (eq. 62-70): every printed Rayleigh reduction equals its derivation identically
    in c (by hand: eq. 67 at mid-span is 17/35, the spring's third of eq. 70); the same
    derivation against eq. 67 with 104 for 105 leaves a difference, and every estimate is
    an upper bound of the exact continuum's first frequency."""
    from dataclasses import replace

    from mbfidelity.analytic.rayleigh import c, section6_formulas
    from mbfidelity.comparisons.typeset import section6_entries

    formulas = {f.label: f for f in section6_formulas()}
    assert all(f.difference() == 0 for f in formulas.values())
    eq67 = formulas["§6.1, eq. 67 (the beam's reduced mass, per rho l)"]
    assert eq67.derived.subs(c, sp.Rational(1, 2)) == sp.Rational(17, 35)
    wrong = replace(eq67, printed=eq67.printed * sp.Rational(105, 104))
    assert wrong.difference() != 0
    entries = section6_entries()
    estimates = [e for e in entries if e["kind"] == "rayleigh_estimate"]
    assert len(estimates) == 3 and all(e["max_relative_difference"] > 0 for e in estimates)
    assert all(e["verdict"] == "agrees" and e["mathml"]["printed"] for e in entries)


def test_every_catalog_mechanism_can_be_animated():
    """Every mechanism's drawing follows its coordinates (`make report` animates them
    all): at the operating point the drawn points are finite, and the joints' anchors are
    where the saved sketch puts them."""
    from mbfidelity.comparisons.animation import _drawing
    from mbfidelity.comparisons.results_folder import mechanism_geometry
    from mbfidelity.systems import all_systems

    for system_id, system in all_systems().items():
        items, points, view = _drawing(system_id)
        geometry = mechanism_geometry(system_id)
        at = points(np.array(geometry["operating_point"]))
        assert np.all(np.isfinite(at)), system_id
        sketched = [j["at"] for j in geometry["items"] if j["kind"] == "joint"]
        drawn = [at[i["points"][0]] for i in items if i["kind"] == "joint"]
        assert len(sketched) == len(drawn), system_id
        for s, d in zip(sketched, drawn):
            s = np.array(list(s) + [0.0] * (3 - len(s)))
            assert np.allclose(s, d, atol=1e-9), system_id


def test_why_each_engine_deviates_names_its_scheme_worst_metric_and_soft_elements():
    """The per-mechanism explanation comes from the run: the scheme the backend declares,
    the metric furthest beyond (or closest to) its gate, and every element it does not
    build exactly; the five-bar's loop closure is MuJoCo's soft `connect`, exact in
    Exudyn."""
    from mbfidelity.comparisons.results_folder import deviations
    from mbfidelity.comparisons.runner import Comparison, Metric
    from mbfidelity.systems import get_system

    values = get_system("five_bar_bird").parameter_values()
    comps = [Comparison("five_bar_bird", sim, "", {}, values, 1e-3, metrics=[
        Metric("small.trajectory_max", 1e-6, 1e-5, True, "pass"),
        Metric("small.constraint_P", 2e-6, 1e-6, False, "xfail")]) for sim in
        ("mujoco", "exudyn")]
    found = deviations(comps)
    assert found["mujoco"]["order"] == 4 and found["exudyn"]["order"] == 2
    assert found["mujoco"]["worst"]["metric"] == "small.constraint_P"
    assert [e["kind"] for e in found["mujoco"]["elements"]] == ["PointOnPoint"]
    assert found["mujoco"]["elements"][0]["level"] == "soft"
    assert found["exudyn"]["elements"] == []
