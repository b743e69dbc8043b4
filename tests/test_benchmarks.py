"""The community's benchmark problems (systems/benchmarks/) and what the description
needed for them: gravity of any finite value, point masses, non-negative mass and inertia.
Expected values are the problems' closed forms and published solutions, never our output."""
import math
from dataclasses import replace

import pytest
import sympy as sp
from scipy.special import ellipk

from mbfidelity.analytic.published import compare_published
from mbfidelity.comparisons.runner import compare
from mbfidelity.simulators import all_backends
from mbfidelity.simulators.base import EXACT, SUBSTITUTE
from mbfidelity.systems import Parameter, get_system
from mbfidelity.systems.model import Body

A01 = "iftomm_a01_pendulum"


# --- gravity of any finite value ---------------------------------------------------------

@pytest.mark.parametrize("g", [0.0, -9.81, 1e-9])
def test_gravity_takes_any_finite_value(g):
    s = get_system("compound_pendulum")
    values = s.parameter_values({"g": g})
    mech = s.numeric_mechanism(values)
    assert sp.sympify(mech.gravity).is_number and float(mech.gravity) == g
    with pytest.raises(ValueError, match="finite"):
        s.parameter_values({"g": math.inf})


def test_a_module_declaring_g_in_its_own_domain_stays_numeric():
    """A module that declares g itself (here non-negative, default 0: a horizontal
    mechanism) must give every engine a numeric mechanism: one symbol for gravity."""
    base = get_system("compound_pendulum")
    s = replace(base, id="horizontal_pendulum", parameters=base.parameters + (
        Parameter("g", 0.0, "m/s^2", "gravity", domain="nonnegative"),))
    mech = s.numeric_mechanism(s.parameter_values())
    assert sp.sympify(mech.gravity).is_number and float(mech.gravity) == 0.0
    for backend in all_backends().values():
        if backend.available()[0]:
            assert backend.support(mech).ok, backend.support(mech).reason


# --- mass and inertia: non-negative, a point mass allowed ------------------------------

@pytest.mark.parametrize("mass,inertia,needle", [(-1.0, 0.0, "mass must be >= 0"),
                                                 (1.0, -0.1, "inertia must be >= 0")])
def test_negative_mass_or_inertia_is_refused_in_one_line(mass, inertia, needle):
    with pytest.raises(ValueError, match=needle) as info:
        Body("b", mass, inertia)
    assert "\n" not in str(info.value)


def test_a_negative_mass_reached_through_a_real_parameter_is_refused():
    base = get_system(A01)
    s = replace(base, id="a01_signed_mass", parameters=tuple(
        replace(p, domain="real") if p.name == "m" else p for p in base.parameters))
    with pytest.raises(ValueError, match="mass must be >= 0"):
        s.numeric_mechanism(s.parameter_values({"m": -2.0}))


def test_every_engine_expresses_the_point_mass():
    """A01's bob has central inertia 0: engines that refuse it declare a substitute."""
    s = get_system(A01)
    mech = s.numeric_mechanism(s.parameter_values())
    (bob,) = mech.bodies
    for sid, backend in all_backends().items():
        if not backend.available()[0]:
            continue
        assert backend.support(mech).ok, f"{sid}: {backend.support(mech).reason}"
        level = backend.expression(mech, bob).level
        assert level == (SUBSTITUTE if sid in ("mujoco", "pymunk") else EXACT), sid


@pytest.mark.parametrize("simulator", ["mujoco", "pymunk"])
def test_the_point_mass_substitute_adds_its_moment_and_nothing_else(simulator):
    """The substitute moment m r^2 raises the pendulum's moment about the pivot by
    (r/L)^2, which lengthens every period by (r/L)^2/2 (T ~ sqrt(I_O)) to first order.
    At r = 0.03 L that is 4.5e-4, a hundred times the engines' own period error at the
    default step, so the measured period error must be it to within 3 %."""
    if not all_backends()[simulator].available()[0]:
        pytest.skip(f"{simulator} not installed")
    r = 0.03
    result = compare(A01, simulator, settings={"point_mass_gyration": r},
                     scenarios=["published"])
    period = next(m for m in result.metrics if m.name == "published.period")
    assert period.value == pytest.approx(r**2 / 2, rel=0.03)


# --- A01: the reference against the closed form ----------------------------------------

def _closed_form_period(v):
    return 4 * math.sqrt(v["L"] / v["g"]) * ellipk(math.sin(v["phi0"] / 2) ** 2)


@pytest.mark.parametrize("params", [{}, {"L": 0.7, "g": 3.0, "phi0": 2.5}])
def test_a01_reference_period_is_the_closed_form(params):
    """T = 4 sqrt(L/g) K(sin(phi0/2)) (K of parameter k^2): the reference (DOP853 at
    1e-12) measured over its periods within 1e-9 relative (its error estimate, ~1e-11)."""
    s = get_system(A01)
    v = s.parameter_values(params)
    (period,) = [p for p in compare_published(s, v) if p["quantity"] == "period"]
    assert period["reference_value"] == pytest.approx(_closed_form_period(v), rel=1e-9)


def test_a01_period_comparison_rejects_a_wrong_length():
    """Injected model error: the bar 1e-6 longer lengthens the period by 5e-7, which the
    1e-9 comparison must see."""
    s = get_system(A01)
    v = s.parameter_values()
    (period,) = [p for p in compare_published(s, {**v, "L": 1 + 1e-6})
                 if p["quantity"] == "period"]
    assert abs(period["reference_value"] / _closed_form_period(v) - 1) > 1e-7


def test_a01_published_point_position_is_the_reference():
    """P1 at t = 10 s from the elliptic closed form (Jacobi's sn, written here) against
    the reference's point, within its error estimate (1e-10)."""
    from scipy.special import ellipj

    s = get_system(A01)
    v = s.parameter_values()
    k = math.sin(v["phi0"] / 2)
    sn = ellipj(ellipk(k * k) - math.sqrt(v["g"] / v["L"]) * 10.0, k * k)[0]
    phi = 2 * math.asin(k * sn)
    got = {p["quantity"]: p for p in compare_published(s, v)}
    assert got["P1.x"]["reference_value"] == pytest.approx(v["L"] * math.sin(phi), abs=1e-9)
    assert got["P1.y"]["reference_value"] == pytest.approx(-v["L"] * math.cos(phi), abs=1e-9)
    assert all(p["relative_difference"] < 1e-9 for p in got.values())


# --- A03: the reference against the Test Set's published solution -----------------------

A03 = "iftomm_a03_andrews"
#: the Test Set for IVP Solvers, problem andrews, solution at t = 0.03 s (typed from
#: andrews.f, subroutine solut), in its order beta, Theta, gamma, Phi, delta, Omega, eps
TEST_SET_ANGLES = {"beta": 15.81077119629904, "Theta": -15.75637105984298,
                   "gamma": 0.04082224013073101, "Phi": -0.5347301163226948,
                   "delta": 0.5244099658805304, "Omega": 0.5347301163226948,
                   "epsilon": 1.048080741042263}


def test_a03_reference_angles_are_the_test_sets():
    """The seven angles at t = 0.03 s within 1e-9 relative of the published solution (a
    16-digit PSIDE solution; ours is DOP853 at 1e-12 on the chart of the crank angle)."""
    s = get_system(A03)
    got = {p["quantity"]: p for p in compare_published(s, s.parameter_values())}
    for name, value in TEST_SET_ANGLES.items():
        assert got[name]["published_value"] == value
        assert got[name]["reference_value"] == pytest.approx(value, rel=1e-9), name


@pytest.mark.parametrize("dt", [1e-3, 1e-4])
def test_a03_reference_sampling_keeps_the_assembly_at_any_step(dt):
    """The crank turns up to about a radian per millisecond: sampled every dt, each sample
    must still be on the motion's assembly branch, so the last one is the test set's
    state (a sample on another branch, or assembly lost, fails)."""
    from mbfidelity.analytic.reference import reference

    s = get_system(A03)
    v = s.parameter_values()
    ref = reference(s, s.scenarios[0], v, dt)
    last = dict(zip(s.coordinates, ref.q[-1]))
    assert ref.t[-1] == pytest.approx(0.03)
    for name, value in TEST_SET_ANGLES.items():
        assert last[name] == pytest.approx(value, rel=1e-9), name


def test_analyze_reports_the_published_values():
    """`analyze --json` gains `published`; a published number holds at the published
    parameters only (a closed form at any)."""
    from mbfidelity.api import analyze

    doc = analyze(A01, {"phi0": 1.0})
    assert {p["quantity"] for p in doc["published"]} == {"period", "P1.x", "P1.y"}
    assert all(p["applies"] and p["relative_difference"] < 1e-9 for p in doc["published"])
    s = get_system(A03)
    moved = compare_published(s, s.parameter_values({"mom": 0.04}))
    assert moved and not any(p["applies"] for p in moved)
    # g = 0: no swing, the closed form says so instead of dividing by zero
    level = analyze(A01, {"g": 0.0})["published"]
    assert level and not any(p["applies"] for p in level)
    assert all("g > 0" in p["note"] for p in level)


def test_the_mechanism_page_shows_the_published_solutions():
    """The run saves the published comparison with the system (results_folder) and the
    page lists it: A03's seven angles at t = 0.03 s, each within 1e-9 relative of the
    reference (the acceptance's bound). The test set's values differ from the reference by
    more than the reference's own error estimate (the reference is stable under tighter
    tolerances; the source's solution is itself numerical): the page flags each such row
    and gives the source's account beside it; a row within the estimate is marked as
    agreeing, and a misprint injected into one value is flagged."""
    from mbfidelity.comparisons.results_folder import published_solutions
    from markupsafe import escape

    from mbfidelity.reports import site

    entries = published_solutions(get_system(A03))
    angles = [p for p in entries if p["applies"] and p["time"] == 0.03
              and not p["quantity"].endswith("_dot")]
    assert len(angles) == 7
    assert all(p["relative_difference"] < 1e-9 for p in angles)

    def page(published):
        return site.MECHANISM.render(
            style="", system=A03, title="", source="", drawing="", model={}, errata=[],
            published=published, sections=[], errata_page=False, script="", convergence="",
            out_of_the_box=[])

    shown = page(entries)
    assert "<h2>Published solutions</h2>" in shown
    flagged = [p for p in entries if p["applies"] and p["beyond_reference_error"]]
    assert shown.count('<tr class="fail">') == len(flagged)
    assert shown.count('<tr class="pass">') == sum(
        1 for p in entries if p["applies"] and not p["beyond_reference_error"])
    assert all(p["note"] for p in flagged) and str(escape(flagged[0]["note"])) in shown
    within = dict(angles[0], beyond_reference_error=False)
    misprint = dict(within, published_value=within["published_value"] * 1.001,
                    relative_difference=1e-3, beyond_reference_error=True)
    assert page([within]).count('<tr class="pass">') == 1
    assert page([misprint]).count('<tr class="fail">') == 1
