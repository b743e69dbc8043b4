"""Joint reactions (contract point 6) from what an engine measures, written once.

The reaction at a joint is the force its parent exerts on its child through it, in world
axes, as the derivation defines it (`analytic.derivation.Derivation.reaction`): Newton's
law on the child's subtree S,

    R = sum over the bodies b of S of m_b (a_b - g)  -  the forces entering S from outside,

where the forces from outside are

- those of the point-to-point elements and of the loop and slot constraints
  (PointOnPoint, PointOnLine) that join a body of S to a body outside it;
- on a prismatic joint, the generalized forces on its own coordinate, which act between
  parent and child along the slide: the coordinate laws (`CoordinateForce`) of that
  coordinate and the couplings (`LinearCoupling`) that involve it, each turned into the
  world force ``Q axis / |axis|^2`` with the axis turned with the parent (virtual power:
  `slide_direction`). A force on a hinge's coordinate is a couple, with no net force.

A prescribed coordinate's actuator is not among them: the derivation counts it as acting
through the joint. Nor is a rolling contact: it carries what the arm and the coupling it
replaces carried, which the description transmits through the joints.

An engine measures either the first sum (its centre-of-mass accelerations:
`subtree_force`) or a force it books as passing from parent to child (its own joint
reaction, an inverse-dynamics force, an internal force of its recursive algorithm). Such
a force holds the outside forces that the engine's build applies as joint forces or does
not see; `joint_reaction` takes out the ones the engine hands in, and the coordinate laws
of a prismatic joint's own slide, which every build applies as joint forces.

Sign convention of every force handed in (the contract's, base.py point 6), by element
name: a pair element (PointToPoint, PointOnPoint, PointOnLine) gives the force on its first
body (``body_a``; the pin's body) in world axes, shape (N, 2), its second body feeling the
opposite; a LinearCoupling gives its generalized force (-multiplier), shape (N,) or
(N, 1), which acts on each coordinate times that coordinate's coefficient. The coordinate
laws are evaluated here, from the samples.
"""
from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np

from ..systems.model import (
    CoordinateForce,
    LinearCoupling,
    Mechanism,
    PointOnLine,
    PointOnPoint,
    PointToPoint,
    Prismatic,
)
from .plan import CoordinateMap, ForceLaw, coordinate_map, num, turned

#: the elements whose force is a pair of opposite forces on two bodies
PAIR_ELEMENTS = (PointToPoint, PointOnPoint, PointOnLine)


def slide_direction(mech: Mechanism, joint: Prismatic, q: np.ndarray,
                    cmap: CoordinateMap | None = None) -> np.ndarray:
    """The world force on the child of a prismatic joint per unit generalized force on its
    coordinate, at each sample of q (rows): axis / |axis|^2, turned with the parent."""
    cmap = cmap or coordinate_map(mech)
    axis = np.array([num(joint.axis[0]), num(joint.axis[1])])
    axis = axis / float(axis @ axis)
    return turned(cmap.angle(joint.parent, q), axis[0], axis[1])


def subtree_force(mech: Mechanism, joint_name: str, t: np.ndarray,
                  accelerations: Mapping[str, np.ndarray]) -> np.ndarray:
    """sum m (a - g) over the massive bodies of the joint child's subtree, at the sample
    times t (N, 2), from the world acceleration (N, 2) of each one's centre of mass
    (`accelerations`, by body; massless bodies need none)."""
    joint = mech.joint(joint_name)
    g = np.array([0.0, -num(mech.gravity)])
    total = np.zeros((len(t), 2))
    for b in mech.subtree(joint.child):
        mass = num(mech.body(b).mass)
        if mass != 0:
            total += mass * (accelerations[b] - g)
    return total


def slide_generalized_force(mech: Mechanism, joint: Prismatic, t: np.ndarray,
                            q: np.ndarray, qd: np.ndarray,
                            coupling_forces: Mapping[str, np.ndarray]) -> np.ndarray:
    """The generalized force (N,) on a prismatic joint's own coordinate that acts between
    parent and child: its coordinate laws, evaluated on the samples, and the couplings
    among `coupling_forces` that involve it."""
    i = mech.coordinates.index(joint.coordinate)
    total = np.zeros(len(t))
    for f in mech.forces:
        if isinstance(f, CoordinateForce) and f.coordinate == joint.coordinate:
            # a couple (relative_to) joins hinge angles only (model validation)
            total += ForceLaw.of(f).vector_law(q[:, i], qd[:, i], t)
    for c in mech.constraints:
        if isinstance(c, LinearCoupling) and c.name in coupling_forces:
            coef = sum(num(v) for name, v in c.coefficients if name == joint.coordinate)
            if coef:
                total += coef * np.reshape(coupling_forces[c.name], len(t))
    return total


def joint_reaction(mech: Mechanism, joint_name: str, transmitted: np.ndarray,
                   t: np.ndarray, q: np.ndarray, qd: np.ndarray, *,
                   pair_forces: Mapping[str, np.ndarray] | None = None,
                   coupling_forces: Mapping[str, np.ndarray] | None = None,
                   cmap: CoordinateMap | None = None) -> np.ndarray:
    """The contract's reaction at a joint (N, 2) from `transmitted`, the force (N, 2) the
    engine books as passing from parent to child (or `subtree_force`): minus the forces
    entering the child's subtree from outside that it holds, namely the pair elements'
    forces in `pair_forces` that cross the cut, and on a prismatic joint its own slide's
    coordinate laws and the couplings in `coupling_forces` (module docstring: which
    elements, and the sign of each force). t, q, qd: the samples (description
    coordinates)."""
    pair_forces = pair_forces or {}
    coupling_forces = coupling_forces or {}
    joint = mech.joint(joint_name)
    known = {e.name for e in (*mech.forces, *mech.constraints)
             if isinstance(e, PAIR_ELEMENTS)}
    if set(pair_forces) - known:
        raise ValueError(f"not pair elements of the mechanism: {sorted(set(pair_forces) - known)}")
    inside = set(mech.subtree(joint.child))
    out = np.array(transmitted, dtype=float)
    for element in (*mech.forces, *mech.constraints):
        if element.name not in pair_forces or not isinstance(element, PAIR_ELEMENTS):
            continue
        first, second = ((element.body_a, element.body_b)
                         if isinstance(element, PointToPoint) else element.bodies)
        in_first, in_second = first in inside, second in inside
        if in_first != in_second:
            force = np.asarray(pair_forces[element.name], dtype=float)
            out -= force if in_first else -force
    if isinstance(joint, Prismatic):
        Q = slide_generalized_force(mech, joint, t, q, qd, coupling_forces)
        if Q.any():  # NaN too: an unknown force leaves the reaction unknown
            out -= Q[:, None] * slide_direction(mech, joint, q, cmap)
    return out


def joint_reactions(mech: Mechanism, joints: Sequence[str],
                    transmitted: Mapping[str, np.ndarray], t: np.ndarray, q: np.ndarray,
                    qd: np.ndarray, *, pair_forces: Mapping[str, np.ndarray] | None = None,
                    coupling_forces: Mapping[str, np.ndarray] | None = None
                    ) -> dict[str, np.ndarray]:
    """`joint_reaction` at each of `joints`, from the engine's force at each."""
    cmap = coordinate_map(mech)
    return {name: joint_reaction(mech, name, transmitted[name], t, q, qd,
                                 pair_forces=pair_forces, coupling_forces=coupling_forces,
                                 cmap=cmap)
            for name in joints}
