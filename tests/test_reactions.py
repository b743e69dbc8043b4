"""The joint reaction's bookkeeping (simulators/reactions.py), written once for every
engine: the slide direction by virtual power against the shared forward kinematics, the
forces entering a subtree taken out with the contract's signs (checked on a frictionless
guide, whose reaction has no component along its slide), and on every engine the
reaction at each slide of the catalog, normal to it, and at a prescribed slide, which
carries the actuator's force as in the derivation."""
import dataclasses
import functools
import math

import numpy as np
import pytest

from mbfidelity.analytic.linear import operating_equilibrium
from mbfidelity.analytic.reference import reference
from mbfidelity.comparisons import metrics, tolerances
from mbfidelity.comparisons.runner import characteristic_frequency
from mbfidelity.comparisons.runner import DEFAULT_DT, _engine_mechanism
from mbfidelity.simulators import all_backends, get_backend, reactions
from mbfidelity.simulators.base import EXACT
from mbfidelity.simulators.plan import BODY, MASSLESS_BODY, body_states, elements, num
from mbfidelity.simulators.reactions import (joint_reaction, slide_direction,
                                             slide_generalized_force, subtree_force)
from mbfidelity.systems import all_systems, get_system
from mbfidelity.systems.model import (COORD, COORD_RATE, Body, CoordinateForce,
                                      LinearCoupling, Mechanism, PointToPoint, Prismatic,
                                      Revolute)

INSTALLED = [b for b in all_backends().values() if b.available()[0]]

M_BLOCK, G = 2.0, 9.81
AXIS = (3.0, 4.0)  # |axis| = 5: the slide coordinate is not a length
TH, S, SD = 0.7, 0.2, 0.3  # arm angle, slide value and rate of the state checked


def _arm_and_block(cable_from_block: bool) -> Mechanism:
    """A hinged arm carrying a block on a slide along (3, 4), with a linear law on the
    slide, a cable of constant tension 5 N from the block to the world point (1, 2), a
    spring between arm and world (outside the slide's subtree) and a coupling of the slide
    with the arm's angle."""
    block, world = ("block", (0, 0)), ("world", (1.0, 2.0))
    a, b = (block, world) if cable_from_block else (world, block)
    return Mechanism(
        bodies=(Body("arm", 1.0, 0.1), Body("block", M_BLOCK, 0.01)),
        joints=(Revolute("hinge", "world", "arm", "th"),
                Prismatic("slide", "arm", "block", "s", axis=AXIS)),
        forces=(CoordinateForce("law", "s", -10 * COORD - 2 * COORD_RATE + 1),
                PointToPoint("cable", a[0], a[1], b[0], b[1], 5),
                PointToPoint("stay", "arm", (0.5, 0), "world", (0, 1), 7)),
        gravity=G,
        constraints=(LinearCoupling("gear", (("s", 2), ("th", 1))),), independent=("th",))


def _turn(th: float, v) -> np.ndarray:
    return np.array([math.cos(th) * v[0] - math.sin(th) * v[1],
                     math.sin(th) * v[0] + math.cos(th) * v[1]])


def test_slide_direction_is_the_virtual_power_dual_of_the_slide():
    """F . v = Q q': the world force per unit generalized force, dotted with the block's
    velocity per unit slide rate (forward kinematics, the arm turned), is 1."""
    mech = _arm_and_block(True)
    q = np.array([[TH, S], [-2.1, -0.4]])
    for row in q:
        vx, vy = body_states(mech, row, (0.0, 1.0))["block"][3:5]
        direction = slide_direction(mech, mech.joint("slide"), row[None, :])[0]
        assert direction @ (vx, vy) == pytest.approx(1.0, rel=1e-14)


@pytest.mark.parametrize("cable_from_block", [True, False])
def test_a_frictionless_guide_pushes_across_its_slide(cable_from_block):
    """Newton on the block with the weight, the cable, the slide's law and the coupling's
    generalized force: whatever the block's acceleration across the slide, the guide's
    force (the reaction) is normal to the slide, m a.n minus the other forces' normal
    part. The cable's force is handed in on its first body, whichever end that is."""
    mech = _arm_and_block(cable_from_block)
    t, q, qd = np.zeros(1), np.array([[TH, S]]), np.array([[0.4, SD]])
    u = _turn(TH, AXIS) / 5.0
    n = np.array([-u[1], u[0]])
    block = _turn(TH, (S * AXIS[0], S * AXIS[1]))
    cable = 5.0 * (np.array([1.0, 2.0]) - block) / np.linalg.norm(np.array([1.0, 2.0]) - block)
    coupling = 0.55  # the coupling's generalized force, on s times its coefficient 2
    law = -10 * S - 2 * SD + 1
    slide = (law + 2 * coupling) * _turn(TH, AXIS) / 25.0
    applied = np.array([0.0, -M_BLOCK * G]) + cable + slide
    across = 0.37  # a . n, free: the guide supplies it
    a = (applied @ u / M_BLOCK) * u + across * n
    transmitted = subtree_force(mech, "slide", t, {"block": a[None, :]})
    pairs = {"cable": (cable if cable_from_block else -cable)[None, :],
             "stay": np.array([[1e3, -1e3]])}  # both ends outside the subtree
    got = joint_reaction(mech, "slide", transmitted, t, q, qd, pair_forces=pairs,
                         coupling_forces={"gear": np.array([[coupling]])})[0]
    expected = (M_BLOCK * across - applied @ n) * n
    assert got == pytest.approx(expected, rel=1e-12, abs=1e-12)
    assert abs(got @ u) <= 1e-12 * np.linalg.norm(got)


def test_only_pair_elements_are_handed_in_as_pairs():
    mech = _arm_and_block(True)
    with pytest.raises(ValueError, match="law"):
        joint_reaction(mech, "slide", np.zeros((1, 2)), np.zeros(1), np.zeros((1, 2)),
                       np.zeros((1, 2)), pair_forces={"law": np.zeros((1, 2))})


# --- every engine: a prescribed slide's reaction carries its actuator -------------------

T, DT = 1.0, 1e-3
PRESCRIBED_SLIDES = {
    # the string's pull is the actuator's force: the reaction along the string is all of it
    "variable_length_pendulum": "string",
    # the road lifts the wheel through its prescribed guide
    "suspension": "road",
}


@pytest.mark.parametrize("system_id", sorted(PRESCRIBED_SLIDES))
@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_reaction_at_a_prescribed_slide(backend, system_id):
    """The derivation counts a prescribed coordinate's actuator as acting through its
    joint, so the reaction there holds its force. Each engine is held to the trajectory
    gate of its own scheme (the reaction follows from its accelerations); the reaction with
    the actuator's force taken out along the slide, what a bookkeeping that counted the
    actuator as an outside force would return, is rejected."""
    system = get_system(system_id)
    joint = PRESCRIBED_SLIDES[system_id]
    sc = system.scenarios[0]
    values = system.parameter_values(scenario=sc)
    mech = system.numeric_mechanism(values)
    if not backend.support(mech).ok:
        pytest.skip(backend.support(mech).reason)
    ref = reference(dataclasses.replace(system, reaction_joints=(joint,)), sc, values, DT, T)
    run = backend.simulate(mech, ref.q[0], ref.qd[0], T, DT, None, (joint,))
    eq = operating_equilibrium(system, values)
    w = characteristic_frequency(eq.modes, ref.q, ref.qd, eq.q)
    gate = tolerances.trajectory_tolerance(w, DT, run.integrator_order, T)
    got = run.reactions[joint][1:]  # the first sample may precede the engine's solve
    assert np.all(np.isfinite(got))
    assert metrics.relative_vector_error(got, ref.reactions[joint][1:]) <= gate
    (actuator,) = run.actuator_forces.values()
    without = got - actuator[1:, None] * slide_direction(mech, mech.joint(joint), run.q[1:])
    assert metrics.relative_vector_error(without, ref.reactions[joint][1:]) > gate


# --- every engine: a slide's reaction is normal to it ------------------------------------

#: the largest component along a slide, relative to the forces at stake: round-off of the
#: summed terms (the engines' accelerations come from their own step or solve) stays
#: below 1e-11 on every engine; a slide law left in the reaction leaves its whole force
ALONG_SLIDE = 1e-9


@functools.lru_cache(maxsize=None)
def _slide_rows() -> tuple:
    """Each catalog row with a slide that no motion is prescribed on: (id, numeric
    mechanism, the reference's initial state, step, sixty steps, those slides)."""
    out = []
    for sid, system in sorted(all_systems().items()):
        sc = system.scenarios[0]
        values = system.parameter_values(None, scenario=sc)
        mech = _engine_mechanism(system, values, None)
        driven = {p.coordinate for p in mech.prescribed}
        slides = tuple(j.name for j in mech.joints
                       if isinstance(j, Prismatic) and j.coordinate not in driven)
        if slides:
            dt = getattr(sc, "dt", None) or system.step or DEFAULT_DT  # a stiff row's own
            t_end = min(sc.t_end, 60 * dt)
            ref = reference(system, sc, values, dt, t_end)
            out.append((sid, mech, ref.q[0], ref.qd[0], dt, t_end, slides))
    return tuple(out)


def _along_slides(backend, mech, q0, qd0, dt, t_end, slides) -> float:
    """The largest component of the reaction along its slide over the run, relative to
    the largest of the reaction, the slide's laws and the weight below it."""
    run = backend.simulate(mech, q0, qd0, t_end, dt, None, slides)
    worst = 0.0
    for name in slides:
        joint, got = mech.joint(name), run.reactions[name]
        u = slide_direction(mech, joint, run.q)
        u /= np.linalg.norm(u, axis=1)[:, None]
        laws = slide_generalized_force(mech, joint, run.t, run.q, run.qd, {})
        weight = num(mech.gravity) * sum(num(mech.body(b).mass)
                                         for b in mech.subtree(joint.child))
        scale = max(np.nanmax(np.linalg.norm(got, axis=1)), np.max(np.abs(laws)), weight)
        worst = max(worst, np.nanmax(np.abs(np.sum(got * u, axis=1))) / scale)
    return worst


@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_a_slides_reaction_is_normal_to_it(backend):
    """A frictionless slide pushes across itself only: the forces along it between
    parent and child are its coordinate's laws (and couplings), which the reaction leaves
    out. Every catalog row whose bodies the engine expresses exactly (a substitute body's
    own inertia would load the slide)."""
    checked = 0
    for sid, mech, q0, qd0, dt, t_end, slides in _slide_rows():
        if not backend.support(mech).ok or any(
                backend.expression(mech, e).level != EXACT
                for kind, e in elements(mech) if kind in (BODY, MASSLESS_BODY)):
            continue
        assert _along_slides(backend, mech, q0, qd0, dt, t_end, slides) <= ALONG_SLIDE, sid
        checked += 1
    assert checked >= 10


def test_a_slide_law_left_in_the_reaction_is_rejected(monkeypatch):
    """The same check with the bookkeeping's slide laws dropped: the massive spring's
    segments then carry their springs' forces along the slides."""
    (row,) = [r for r in _slide_rows() if r[0] == "massive_spring"]
    monkeypatch.setattr(reactions, "slide_generalized_force",
                        lambda mech, joint, t, *rest: np.zeros(len(t)))
    assert _along_slides(get_backend("exudyn"), *row[1:]) > ALONG_SLIDE


#: a rack's coupling force is read in a second pass over the samples, whose iterative
#: constraint solve (where the engine has one) agrees with the first to the solver's
#: tolerance, far below this; the coupling's force left in is 1e-2 of the weight
ALONG_RACK = 1e-6


def _rack_and_pinion() -> Mechanism:
    """A rack on a horizontal guide (axis of length 2) driven by a hinged pinion, 2 x =
    0.1 phi, with a spring on the rack's coordinate (no catalog row couples a slide)."""
    return Mechanism(
        bodies=(Body("pinion", 1.0, 0.02), Body("rack", 2.0, 0.05)),
        joints=(Revolute("axle", "world", "pinion", "phi"),
                Prismatic("guide", "world", "rack", "x", axis=(2.0, 0.0),
                          parent_anchor=(0, -0.3))),
        forces=(CoordinateForce("spring", "x", -40 * COORD),),
        gravity=G,
        constraints=(LinearCoupling("gear", (("x", 2.0), ("phi", -0.1))),),
        independent=("phi",))


@pytest.mark.parametrize("backend", INSTALLED, ids=lambda b: b.id)
def test_a_racks_guide_pushes_across_itself(backend):
    """The coupling's generalized force on the rack's coordinate acts along the guide,
    between world and rack: the reaction leaves it out (module docstring) and is the
    weight alone, normal to the guide. An engine that does not report the coupling's force
    cannot give this reaction either (NaN, contract point 6)."""
    mech = _rack_and_pinion()
    if not backend.support(mech).ok:
        pytest.skip(backend.support(mech).reason)
    run = backend.simulate(mech, np.array([0.5, 0.025]), np.zeros(2), 0.05, 1e-3, None,
                           ("guide",))
    got = run.reactions["guide"]
    if np.isnan(run.constraint_forces["gear"]).all():
        assert np.isnan(got).all()
        return
    weight = num(mech.body("rack").mass) * G
    assert np.all(np.isfinite(got))
    assert np.max(np.abs(got[:, 0])) <= ALONG_RACK * weight
    assert np.allclose(got[:, 1], weight, rtol=ALONG_RACK)


# --- forces from the bodies' motion (reactions.balance_forces, actuator_force) ----------

L_ARM, M_BOB, I_BOB = 0.8, 1.5, 0.05


def _pendulum(th: float) -> tuple[Mechanism, dict]:
    """A bob hinged to the world at (0, 0) through its point (0, L) above its centre of
    mass, held at rest at angle th (0: hanging), and its frames over three samples."""
    mech = Mechanism(bodies=(Body("bob", M_BOB, I_BOB),),
                     joints=(Revolute("hinge", "world", "bob", "th", child_anchor=(0, L_ARM)),),
                     gravity=G)
    states = body_states(mech, [th], [0.0])
    return mech, {b: tuple(np.full(3, v) for v in st) for b, st in states.items()}


def test_balance_forces_of_a_hanging_bob_carry_its_weight():
    """At rest, hanging: the hinge holds the weight, R = (0, m g) on the bob; the balance
    is solved exactly (residual 0)."""
    mech, frames = _pendulum(0.0)
    after = {b: tuple(v[1:] for v in st) for b, st in frames.items()}
    needed = np.tile([0.0, M_BOB * G, 0.0], (2, 1))  # m (a - g), no moment about the centre
    joint_forces, closures, residual = reactions.balance_forces(mech, after, needed)
    assert closures == {}
    assert np.allclose(joint_forces["hinge"], [[0.0, M_BOB * G]] * 2, rtol=0, atol=1e-12)
    assert residual < 1e-12


@pytest.mark.parametrize("th", [0.0, 0.4, -1.1])
def test_actuator_force_holding_a_bob_at_rest_is_the_gravity_moment(th):
    """A hinge's actuator holding the bob at rest at angle th balances the weight's
    moment about the hinge: Q = m g L sin(th) (statics)."""
    mech, frames = _pendulum(th)
    ahead = {b: tuple(v[:-1] for v in st) for b, st in frames.items()}
    force = reactions.actuator_force(mech, mech.joints[0], frames, ahead, [], 1e-3)
    assert np.allclose(force, M_BOB * G * L_ARM * math.sin(th), rtol=1e-12, atol=1e-12)
