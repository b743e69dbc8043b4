"""The command line as a user meets it (docs/user-guide.md): JSON contracts and clear errors."""
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from mbfidelity.cli import app

runner = CliRunner()


def _json(args):
    res = runner.invoke(app, args)
    assert res.exit_code in (0, 1), res.output
    return json.loads(res.stdout)


def test_list_json_names_every_system_and_engine():
    doc = _json(["list", "--json"])
    ids = {s["system"] for s in doc["systems"]}
    assert {"compound_pendulum", "double_pendulum", "elastic_pendulum",
            "pendulum_sliding_block", "mass_spring_damper"} <= ids
    assert set(doc["simulators"]) <= {"mujoco", "pybullet", "exudyn", "pymunk", "drake"}


def test_analyze_json_contract_and_param_override():
    # Fig. 7, eq. 5 with L = 2: w0 = sqrt(3 g / (2 L))
    doc = _json(["analyze", "compound_pendulum", "--param", "L=2", "--json"])
    for key in ("system", "parameters", "equilibria", "linearization", "modes"):
        assert key in doc
    assert doc["parameters"]["L"] == 2
    # l = L/2 and I_O = m L^2/3 follow L (formula defaults)
    assert doc["derived_parameters"] == ["l", "I_O"]
    assert doc["parameters"]["l"] == 1 and doc["parameters"]["I_O"] == pytest.approx(4 / 3)
    stable = [e for e in doc["equilibria"] if e["stable"]]
    assert len(stable) == 1 and {"q", "stable", "modes"} <= set(stable[0])
    f = doc["modes"][0]["frequency_hz"]
    assert f == pytest.approx(np.sqrt(1.5 * 9.81 / 2) / (2 * np.pi), rel=1e-9)
    assert np.array(doc["linearization"]["M"]).shape == (1, 1)
    unstable = [e for e in doc["equilibria"] if not e["stable"]]
    assert unstable and "eigenvalues" in unstable[0]


def test_analyze_double_pendulum_bars_follow_mass_and_length():
    """Fig. 37 with two uniform bars (I = m (2l)^2/12 = m l^2/3): det(K - w^2 M) = 0 with
    M = m l^2 [[16/3, 2], [2, 4/3]], K = m g l diag(3, 1) gives, with x = w^2 l/g,
    28 x^2 - 84 x + 27 = 0, x = 3/2 -+ 3/sqrt(7): independent of m; with the inertia of
    the default bar (1/12) instead, the frequencies would differ."""
    doc = _json(["analyze", "double_pendulum", "--param", "m=2", "--param", "l=0.3", "--json"])
    assert doc["derived_parameters"] == ["I"]
    assert doc["parameters"]["I"] == pytest.approx(2 * 0.6**2 / 12, rel=1e-12)
    g, l = 9.81, 0.3
    want = [np.sqrt(g / l * (1.5 + sign * 3 / np.sqrt(7))) / (2 * np.pi) for sign in (-1, 1)]
    got = [mode["frequency_hz"] for mode in doc["modes"]]
    assert got == pytest.approx(want, rel=1e-9)
    explicit = _json(["analyze", "double_pendulum", "--param", "m=2", "--param", "l=0.3",
                      "--param", "I=0.05", "--json"])
    assert explicit["derived_parameters"] == [] and explicit["parameters"]["I"] == 0.05


@pytest.mark.parametrize("k,m", [(50.0, 0.5), (180.0, 2.0)])
def test_analyze_rotating_slot_critical_speed_follows_k_and_m(k, m):
    """Issue 9 acceptance, eq. 84: the block in the turning slot is stable below
    sqrt(k/m) and unstable above, for the k, m the user passes; below, the steady state
    of the weight's excitation is m g / |k - 2 m w^2 + i c w| (eq. 84 with x ~ e^{i w t})."""
    critical = np.sqrt(k / m)
    common = ["analyze", "rotating_slot", "--param", f"k={k}", "--param", f"m={m}"]
    below = _json(common + ["--param", f"omega={0.9 * critical}", "--json"])
    above = _json(common + ["--param", f"omega={1.1 * critical}", "--json"])
    assert below["stable"] and not above["stable"]
    assert below["free_coordinates"] == ["x"] and "phi" in below["prescribed"]
    (line,) = [h for h in below["steady_state"] if h["quantity"] == "position"]
    w, c = 0.9 * critical, below["parameters"]["c"]
    assert line["amplitude"] == pytest.approx(m * 9.81 / abs(k - 2 * m * w**2 + 1j * c * w),
                                              rel=1e-10)
    assert line["frequency_hz"] == pytest.approx(w / (2 * np.pi), rel=1e-12)
    assert above["steady_state"] == [] and "unstable" in above["steady_state_note"]


def test_analyze_json_damped_modes():
    doc = _json(["analyze", "mass_spring_damper", "--param", "c=4", "--json"])
    (mode,) = doc["modes"]
    assert mode["damping_ratio"] == pytest.approx(4 / (2 * np.sqrt(100)), rel=1e-9)
    assert mode["damped_frequency_hz"] == pytest.approx(
        np.sqrt(100) * np.sqrt(1 - 0.2**2) / (2 * np.pi), rel=1e-9)


@pytest.mark.parametrize("args,needle", [
    (["analyze", "no_such_system"], "valid: actuated_arm, base_excited_msd,"),
    (["analyze", "compound_pendulum", "--param", "mass=2"], "valid: m, L"),
    (["analyze", "compound_pendulum", "--param", "L=-1"], "must be > 0"),
    (["analyze", "compound_pendulum", "--param", "L"], "NAME=VALUE"),
    (["compare", "compound_pendulum", "--sim", "gazebo"], "valid:"),
    (["analyze", "compound_pendulum", "--param", "m=inf"], "must be finite"),
    (["analyze", "compound_pendulum", "--param", "L=nan"], "must be finite"),
    (["analyze", "scotch_yoke", "--param", "b=0.3"], "violate h - b - r > 0"),
    (["analyze", "scotch_yoke", "--param", "r=0.5"], "violate h - b - r > 0"),
    (["compare", "scotch_yoke", "--sim", "pymunk", "--param", "b=0.3"], "violate h - b - r > 0"),
    (["compare", "scotch_yoke", "--sim", "pymunk", "--param", "m=-inf"], "must be finite"),
    (["analyze", "compound_pendulum", "--param", "l=0.7"], "violate I_O > m*l**2"),
])
def test_bad_input_gets_one_line_error(args, needle):
    res = runner.invoke(app, args)
    assert res.exit_code == 2
    assert needle in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_compare_json_contract():
    doc = _json(["compare", "mass_spring_damper", "--sim", "mujoco", "--t-end", "2", "--json"])
    for key in ("system", "simulator", "engine_version", "settings", "metrics", "passed"):
        assert key in doc
    assert doc["engine_version"]
    for m in doc["metrics"]:
        assert {"name", "value", "tolerance", "passed"} <= set(m)


def test_errata_page_and_json(tmp_path):
    """`errata --out` writes the report page and JSON: every coded printed formula, with
    the known misprint of Fig. 14, eq. 51 (the spurious 1/2) among them."""
    res = runner.invoke(app, ["errata", "--no-witnesses", "--json", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.stdout)
    labels = {(e["system"], e["label"]): e["verdict"] for e in doc["errata"]}
    assert any("eq. 51" in label and verdict == "misprint" for (_, label), verdict in labels.items())
    page = (tmp_path / "errata.html").read_text()
    assert "eq. 116" in page and "misprint" in page
    # the saved entries add their typeset forms (MathML) to what --json prints
    saved = json.loads((tmp_path / "errata.json").read_text())["errata"]
    assert [{k: v for k, v in e.items() if k != "mathml"} for e in saved] == doc["errata"]
    assert all("mathml" in e for e in saved)


def test_unknown_variant_is_a_clear_error():
    res = runner.invoke(app, ["compare", "rolling_disc_track", "--sim", "pymunk",
                              "--variant", "levitating"])
    assert res.exit_code == 2 and "no variant 'levitating'" in res.output


# --- issue 8: gates that can fail, steps that cannot be stable, failures contained -----


def test_unstable_step_is_refused_before_any_work():
    # w = sqrt(k/m) = 3.16e4 rad/s: RK4 is stable only for w h <= 2 sqrt 2
    res = runner.invoke(app, ["compare", "mass_spring_damper", "--sim", "mujoco",
                              "--param", "k=1e9"])
    assert res.exit_code == 2, res.output
    assert "stability limit 2.83" in res.output and "w h = 31.6" in res.output
    assert "Traceback" not in res.output


def test_coarse_step_cannot_pass_on_its_error_at_h():
    # w h = 0.2 x 7 rad/s: far outside semi-implicit Euler's asymptotic range (w h <= 0.2)
    res = runner.invoke(app, ["compare", "double_pendulum", "--sim", "pymunk", "--dt", "0.2",
                              "--t-end", "4", "--json"])
    doc = json.loads(res.stdout)
    # the engine's own refinement bounds its error at h above what a trajectory can tell
    # apart: no trajectory passes on it; where the refinement reaches the asymptotic
    # regime within the step budget, the engine's limit is judged on its finest run
    # instead (comparisons/tolerances.py, "A posteriori"), and the JSON says so
    trajectories = [m for m in doc["metrics"] if ".trajectory_" in m["name"]]
    assert trajectories
    for m in trajectories:
        assert m["status"] == "unresolved" or (
            m["rule"] == "refinement_limit" and m["tolerance"] > 0.1
            and m["refinement"]["limit"]["tolerance"] <= 0.1), m


def test_engine_failure_is_recorded_not_raised():
    # Exudyn's generalized-alpha Newton iteration gives up on the large swing at h = 0.1
    res = runner.invoke(app, ["compare", "five_bar_bird", "--sim", "exudyn", "--dt", "0.1",
                              "--t-end", "3"])
    assert res.exit_code == 1, res.output
    assert "crashed" in res.output and "Traceback" not in res.output


# Kapitza (Landau & Lifshitz, Mechanics §30), for eq. 80 with the equivalent length
# L_e = (I_G + m l^2)/(m l): the inverted position is stable to leading order in Y/L_e when
# Y^2 Omega^2 > 2 g L_e, and otherwise leaves at the rate of the averaged (effective)
# potential, sqrt(g/L_e - Y^2 Omega^2 / (2 L_e^2)). Defaults (the project's): m = 1,
# l = 0.2, I_G = 0.001, Omega = 2 pi 50: Y = 0.01 gives a ratio Y^2 Omega^2/(2 g L_e) of
# 2.45 (stable), Y = 0.005 one of 0.61 (unstable); the O(Y/L_e) corrections are 0.05 at most.
def _kapitza_rate(Y, m=1.0, l=0.2, I_G=0.001, W=2 * np.pi * 50, g=9.81):
    L_e = (I_G + m * l * l) / (m * l)
    return np.sqrt(g / L_e - (Y * W) ** 2 / (2 * L_e**2))


@pytest.mark.parametrize("Y, inverted_stable", [(0.01, True), (0.005, False)])
def test_analyze_parametric_excitation_reports_floquet_per_rest_state(Y, inverted_stable):
    doc = _json(["analyze", "vertically_driven_pendulum", "--param", f"Y={Y}", "--json"])
    assert "parametric_excitation" in doc
    by_angle = {round(e["q"]["phi"] / np.pi) % 2: e for e in doc["equilibria"]}
    assert set(by_angle) == {0, 1}  # hanging and inverted (§8.3: phi_eq = n pi)
    inverted, hanging = by_angle[1], by_angle[0]
    assert inverted["stable"] is inverted_stable
    assert hanging["stable"] is True and doc["stable"] is True  # the operating point  # far below the first tongue (Omega >> 2 omega0)
    assert len(inverted["floquet_multipliers"]) == 2
    f = inverted["floquet"]
    assert f["period"] == pytest.approx(1 / 50, rel=1e-12)
    if not inverted_stable:
        rate = np.log(f["floquet_max_abs_multiplier"]) / f["period"]
        assert rate == pytest.approx(_kapitza_rate(Y), rel=0.05)


def test_analyze_parametric_excitation_text_names_the_floquet_verdicts():
    res = runner.invoke(app, ["analyze", "vertically_driven_pendulum"])
    assert res.exit_code == 0, res.output
    assert res.output.count("Floquet stable") == 2


# Fig. 11, eq. 14: l phi'' + 2 l' phi' + g phi = 0 about phi = 0 with l = l0 - h_a sin(Omega t).
# Parametric resonance (Landau & Lifshitz, Mechanics §27): the first instability tongue is
# centred on Omega = 2 w0, w0 = sqrt(g/l0), its width proportional to h_a/l0; above it
# (Omega = 3 w0 lies beyond the first tongue, and the others are at 2 w0 / n) the motion
# stays bounded: over one period the monodromy's determinant is (l(0)/l(T))^2 = 1, so the
# multipliers sit on the unit circle.
@pytest.mark.parametrize("ratio, stable", [(2.0, False), (3.0, True)])
def test_analyze_variable_length_pendulum_tongue(ratio, stable):
    w0 = np.sqrt(9.81 / 1.0)
    doc = _json(["analyze", "variable_length_pendulum", "--param", f"Omega={ratio * w0}",
                 "--json"])
    hanging = [e for e in doc["equilibria"] if abs(e["q"]["phi"]) < 1e-9]
    assert len(hanging) == 1 and hanging[0]["stable"] is stable
    mu = np.array([complex(*m) for m in hanging[0]["floquet_multipliers"]])
    assert abs(np.prod(mu) - 1.0) < 1e-8
