"""The shared geometry an engine in maximal coordinates is placed by (the plan), without an
engine: each against the forward kinematics (`plan.body_states`, written independently)
or a closed form (parallel axes, the chord of a circle)."""
import math

import numpy as np
import pytest

from mbfidelity.simulators.plan import (Elimination, PitchPair, body_states, compensated_host,
                                        joint_pose, joint_velocity, point_state,
                                        ring_of_chords, slide_path)
from mbfidelity.systems import all_systems
from mbfidelity.systems.model import WORLD, Body, Mechanism, Prismatic, Revolute

#: round-off of a few products of numbers of order one
TOL = 1e-12


def _world_joints() -> Mechanism:
    """A slide and a clockwise hinge on the world, with anchors and angle offsets."""
    return Mechanism(
        bodies=(Body("block", 2.0, 0.1), Body("arm", 1.0, 0.05)),
        joints=(Prismatic("slide", WORLD, "block", "x", axis=(2.0, 1.0),
                          parent_anchor=(0.3, 0.1), child_anchor=(0.1, -0.2),
                          angle_offset=0.4),
                Revolute("hinge", WORLD, "arm", "phi", parent_anchor=(-0.5, 0.2),
                         child_anchor=(0.3, 0.1), angle_offset=0.7, clockwise=True)),
        gravity=9.81)


@pytest.mark.parametrize("q,qd", [((0.3, 1.1), (0.7, -2.0)), ((-1.2, -0.4), (0.0, 3.5))])
def test_a_joint_pose_and_velocity_are_those_of_the_forward_kinematics(q, qd):
    """On the world: a slide's pose is the world point of the child's anchor and its
    velocity that anchor's; a hinge's pose is the child's angle, its velocity the child's
    angular velocity with the anchor at rest; a slide's path carries the child's origin."""
    mech = _world_joints()
    slide, hinge = mech.joints
    states = body_states(mech, q, qd)
    x, y, vx, vy = point_state(states["block"], (0.1, -0.2))
    assert np.allclose(joint_pose(slide)(q[0]), (x, y), rtol=0, atol=TOL)
    assert np.allclose(joint_velocity(slide, qd[0]), (vx, vy, states["block"][5]),
                       rtol=0, atol=TOL)
    base, axis = slide_path(slide)
    assert np.allclose(base + q[0] * axis, states["block"][:2], rtol=0, atol=TOL)
    _, _, vx, vy = point_state(states["arm"], (0.3, 0.1))
    assert joint_pose(hinge)(q[1]) == pytest.approx(states["arm"][2], abs=TOL)
    assert np.allclose(joint_velocity(hinge, qd[1]), (vx, vy, states["arm"][5]),
                       rtol=0, atol=TOL)


def _folds():
    """Links that fold (one revolute and one prismatic joint), turning with the slide's
    child or with its parent, with anchors and an angle offset off every origin; and the
    catalog's."""
    hinge = dict(parent_anchor=(0.2, 0.3), child_anchor=(0.1, -0.1))
    slide = dict(axis=(1.0, 0.5), parent_anchor=(0.05, 0.2), child_anchor=(-0.1, 0.15),
                 angle_offset=0.3)
    bodies = (Body("link", 0, 0), Body("block", 2.0, 0.1))
    built = {
        "with-child": Mechanism(bodies, (Revolute("pin", WORLD, "link", "phi", **hinge),
                                         Prismatic("slot", "link", "block", "s", **slide))),
        "with-parent": Mechanism(bodies, (Prismatic("slot", WORLD, "link", "s", **slide),
                                          Revolute("pin", "link", "block", "phi", **hinge))),
    }
    for system in all_systems().values():
        mech = system.numeric_mechanism(system.parameter_values())
        if any(b.massless for b in mech.bodies) and not mech.spatial:
            built[system.id] = mech
    for label, mech in built.items():
        try:
            elimination = Elimination(mech)
        except ValueError:
            continue
        for fold in elimination.folds.values():
            yield pytest.param(mech, fold, id=f"{label}-{fold.link}")


@pytest.mark.parametrize("mech,fold", list(_folds()))
def test_a_folded_links_pin_runs_on_its_partners_slot_line(mech, fold):
    """At random poses of the tree, the folded link's pin point is the point base + q
    direction of the line `Fold.slot_line` gives in its partner's frame, q the slide's
    coordinate (so that the slide's limits are the line's)."""
    rng = np.random.default_rng(7)
    base, direction = fold.slot_line
    slide = mech.joints.index(fold.prismatic)
    for _ in range(5):
        q = rng.uniform(-1.5, 1.5, len(mech.joints))
        states = body_states(mech, q, np.zeros(len(q)))
        pin = np.array(point_state(states[fold.pin_body], fold.pin_point)[:2])
        at = base + q[slide] * np.asarray(direction)
        along = point_state(states[fold.partner], (at[0], at[1]))[:2]
        assert np.allclose(pin, along, rtol=0, atol=TOL * (1 + abs(q[slide])))


def test_pitch_points_meet_without_residual_and_part_by_its_length():
    """Hubs d apart on x: the pitch point lies lam d from a's hub; a residual phi moves
    b's point across the hub line by phi d / (k_a + k_b)."""
    pair = PitchPair("arm", "ring", "disc", (0.0, 0.0), (0.0, 0.0), 0.4, -3.0, 1.0)
    lam = -3.0 / (-3.0 + 1.0)
    ha, hb = (1.0, 2.0), (1.4, 2.0)
    ca, cb = pair.pitch_points(ha, hb, 0.0)
    assert np.allclose(ca, cb, rtol=0, atol=TOL)
    assert np.allclose(ca, (1.0 + lam * 0.4, 2.0), rtol=0, atol=TOL)
    ca, cb = pair.pitch_points(ha, hb, 0.05)
    assert np.allclose(np.subtract(ca, cb), (0.0, 0.05 * 0.4 / (-2.0)), rtol=0, atol=TOL)
    assert pair.circles[2] == pytest.approx(abs(lam) * 0.4) and pair.circles[6]


def test_a_compensated_host_and_its_substitutes_have_the_described_inertia():
    """Mass, centre of mass (the host frame's origin) and central moment of host and
    substitutes together, by the parallel-axis theorem, are the described ones."""
    m, inertia = 3.0, 0.5
    parts = [(0.4, (0.3, -0.2), 0.01), (0.2, (-0.1, 0.5), 0.0)]
    m1, c1, i1 = compensated_host(m, inertia, parts)
    masses = [m1] + [p[0] for p in parts]
    points = [np.asarray(c1)] + [np.array(p[1]) for p in parts]
    assert sum(masses) == pytest.approx(m, abs=TOL)
    assert np.allclose(sum(mi * p for mi, p in zip(masses, points)), 0.0, rtol=0, atol=TOL)
    about_origin = i1 + sum(p[2] for p in parts) + sum(
        mi * float(p @ p) for mi, p in zip(masses, points))
    assert about_origin == pytest.approx(inertia, abs=TOL)


@pytest.mark.parametrize("count", [3, 8, 720])
def test_a_ring_of_chords_is_inscribed_with_its_sagitta(count):
    """The vertices lie on the circle; the sagitta is R minus the distance of a chord's
    midpoint from the centre."""
    centre, R = (0.2, -0.3), 1.5
    points, sagitta = ring_of_chords(centre, R, count)
    radii = [math.dist(p, centre) for p in points]
    assert len(points) == count and np.allclose(radii, R, rtol=0, atol=TOL)
    mid = np.add(points[0], points[1]) / 2
    assert sagitta == pytest.approx(R - math.dist(mid, centre), abs=TOL)
