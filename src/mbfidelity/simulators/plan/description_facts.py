"""Small facts of the description an engine's translation asks for.

Whether a line passes through a body's centre of mass (`line_through_origin`) and a
body's angle is constant (`rotation_fixed`); a body's mass felt at a point
(`effective_mass`) and what a host keeps of its inertia beside its substitutes (`compensated_host`); continuous angles and a
coupling's residual (`continued_angles`, `coupling_residual`); principal inertias
(`principal_inertia`); a rolling contact's geometry and report (`RollingGeometry`,
`rolling_geometry`, `rolling_contact_report`); for an engine that holds a slot by a slider
body, the sliders' masses taken out of the pin body (`SliderSplit`, `slider_masses`); for
a linearization with the closures held exactly, the closure forces' geometric stiffness
and the modes on the constraint's null space (`geometric_stiffness`,
`constrained_modes`); the mechanism's length scale (`length_scale`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

import numpy as np

from ...analytic.modes import quadratic_eigenvalues
from ...systems.model import (
    WORLD,
    HingeClosure,
    LinearCoupling,
    Mechanism,
    Prismatic,
    Revolute,
    RollingContact,
)
from .numeric import num, turned
from .kinds_and_laws import POINT_ON_LINE, element_kind
from .coordinates import CoordinateMap
from .kinematics import coordinate_reader
from .force_loads import coupling_row


# --- small facts of the description an engine's translation asks for ---------------------


def line_through_origin(base: np.ndarray, direction: np.ndarray) -> bool:
    """Whether the line base + u direction (in a body's frame) passes through the frame's
    origin, the body's centre of mass."""
    scale = float(np.linalg.norm(direction)) * max(float(np.linalg.norm(base)), 1.0)
    return abs(float(base[0] * direction[1] - base[1] * direction[0])) <= 1e-12 * scale


def rotation_fixed(mech: Mechanism, body: str) -> bool:
    """Whether the body's angle is constant: every joint from the world to it is
    prismatic (its moment of inertia then enters no equation of motion)."""
    while body != WORLD:
        j = mech.joint_of_child(body)
        if not isinstance(j, Prismatic):
            return False
        body = j.parent
    return True


def effective_mass(m: float, inertia: float, d: float) -> float:
    """Mass of a rigid body felt at a point at distance d from its centre of mass, across
    the radius: m I / (I + m d^2)."""
    return m * inertia / (inertia + m * d * d)


def compensated_host(m: float, inertia: float, parts: Sequence[tuple[float, tuple, float]]
                     ) -> tuple[float, np.ndarray, float]:
    """What is left of a body of mass m and central moment `inertia` when substitute
    bodies take over part of it (`parts`: each one's mass, its centre of gravity in the
    body's frame and its own central moment), so that the body and its substitutes
    together have exactly the described inertia: (mass m1 = m - sum m_i, centre of
    gravity c1 = -sum m_i p_i / m1 in the body's frame, central moment I - sum (I_i +
    m_i |p_i|^2) - m1 |c1|^2); the caller checks that m1 and the moment stay positive."""
    m1 = m - sum(mi for mi, _, _ in parts)
    first = sum(mi * np.array(p) for mi, p, _ in parts)
    c1 = -first / m1 if m1 > 0 else np.zeros(2)
    i1 = inertia - sum(ii + mi * float(np.dot(p, p)) for mi, p, ii in parts
                       ) - m1 * float(c1 @ c1)
    return m1, c1, i1


def continued_angles(mech: Mechanism, q: np.ndarray, q0: np.ndarray) -> np.ndarray:
    """The samples q (rows) with every hinge angle unwrapped and continued from q0 (an
    angle read by atan2 jumps by 2 pi); q is changed in place and returned."""
    for i, j in enumerate(mech.joints):
        if isinstance(j, Revolute):
            col = np.unwrap(q[:, i])
            q[:, i] = col + 2 * math.pi * round((q0[i] - col[0]) / (2 * math.pi))
    return q


def coupling_residual(mech: Mechanism, coupling: LinearCoupling
                      ) -> Callable[[Mapping], object]:
    """The residual sum c_i q_i - C of a coupling as a function of the bodies' frame
    states (numbers, arrays of samples or symbols), the coordinates read by
    `coordinate_reader`."""
    terms = [(num(coef), coordinate_reader(mech.joints[i]), mech.joints[i])
             for name, coef in coupling.coefficients for i in [mech.coordinates.index(name)]]
    return lambda frames: (sum(coef * read(frames[j.parent], frames[j.child])[0]
                               for coef, read, j in terms) - num(coupling.constant))


def principal_inertia(tensor: np.ndarray) -> tuple[list[float], list[float]]:
    """(principal moments, quaternion x y z w of the principal axes) of a symmetric
    3 x 3 central tensor: the eigenvectors, made a right-handed frame."""
    values, vectors = np.linalg.eigh(tensor)
    if np.linalg.det(vectors) < 0:
        vectors[:, 2] = -vectors[:, 2]
    from scipy.spatial.transform import Rotation

    return [float(v) for v in values], [float(v) for v in Rotation.from_matrix(vectors).as_quat()]


@dataclass
class RollingGeometry:
    """Where a RollingContact's friction stand-in sits: a disc (inner circle of radius r)
    on a radius arm about the centre of a circular track (outer circle, radius R)."""

    coupling: str
    outer: str
    inner: str
    R: float
    r: float
    centre: tuple[float, float]       # outer circle centre, outer body frame
    inner_centre: tuple[float, float]  # inner circle centre, inner body frame
    hub: int                          # joint index of the inner body (its parent: the arm)
    radial: tuple[float, float]        # unit direction track centre -> hub, arm frame


def rolling_geometry(mech: Mechanism, c: RollingContact) -> RollingGeometry:
    """The geometry of a RollingContact: the ring is centred at the arm's hinge on the
    track, the disc's circle at its hub, and the radial direction runs along the arm from
    that hinge to the hub."""
    hub, hinge = mech.joint_of_child(c.disc), mech.joint_of_child(c.arm)
    centre = tuple(num(v) for v in hinge.parent_anchor)
    arm = (np.array([num(v) for v in hub.parent_anchor])
           - np.array([num(v) for v in hinge.child_anchor]))
    u = arm / np.linalg.norm(arm)
    return RollingGeometry(c.name, c.track, c.disc, num(c.track_radius), num(c.disc_radius),
                           centre, tuple(num(v) for v in hub.child_anchor),
                           mech.joints.index(hub), (float(u[0]), float(u[1])))


@dataclass(frozen=True)
class SliderSplit:
    """The masses of the sliders of the slots whose pin is on one body (`slider_masses`),
    by slot name, and what the pin body keeps: (mass, planar inertia about its centre of
    mass, centre of mass in its frame), or None where it keeps its own."""

    masses: dict[str, float]
    kept: tuple[float, float, np.ndarray] | None


def slider_masses(mech: Mechanism, pin_body: str, ratio: float, lightest: float,
                  substitute: float | None = None) -> SliderSplit:
    """The point masses of the sliders of the PointOnLine constraints whose pin is on
    `pin_body`, for an engine that holds a slot by a slider body sliding along it,
    connected to the pin. The slider follows the pin point, so its mass is taken out of
    the pin body (mass, centre of mass and inertia adjusted so that body + sliders have
    the description's mass, first and second moments: exact while the constraints hold):
    `ratio` times the largest equal point masses at the pins that leave a positive
    inertia. A slider on a fixed pin does not move: `ratio` times the slot body's mass
    (`lightest`, the lightest body's, where the slot body is the world or massless); on a
    massless pin body, `ratio` times its `substitute` mass, which carries the sliders."""
    cons = [c for c in mech.constraints
            if element_kind(c) == POINT_ON_LINE and c.body == pin_body]
    if pin_body == WORLD:
        masses = {}
        for c in cons:
            lb = c.line_body
            heavy = lb != WORLD and not mech.body(lb).massless
            masses[c.name] = ratio * (num(mech.body(lb).mass) if heavy else lightest)
        return SliderSplit(masses, None)
    if substitute is not None:
        return SliderSplit({c.name: ratio * substitute for c in cons}, None)
    body = mech.body(pin_body)
    pts = [np.array([num(c.point[0]), num(c.point[1])]) for c in cons]
    mp, ip = num(body.mass), num(body.inertia)
    # the largest point masses at the pins that leave a positive inertia
    bound = mp * ip / (ip + mp * sum(float(p @ p) for p in pts)) / len(cons)
    masses = [ratio * bound for _ in cons]
    rest, com, inertia = compensated_host(mp, ip, [(mc, p, 0.0) for mc, p in zip(masses, pts)])
    return SliderSplit({c.name: mc for c, mc in zip(cons, masses)}, (rest, inertia, com))


def geometric_stiffness(jacobian_at: Callable[[int, float], np.ndarray],
                        forces: np.ndarray, n: int, eps: float) -> np.ndarray:
    """d(J^T f)/dq at fixed closure forces f, by central differences: column i from the
    constraint Jacobian J at the state moved by +eps and by -eps along coordinate i
    (`jacobian_at(i, h)`)."""
    G = np.zeros((n, n))
    for i in range(n):
        cols = [jacobian_at(i, h).T @ forces for h in (eps, -eps)]
        G[:, i] = (cols[0] - cols[1]) / (2 * eps)
    return G


def constrained_modes(M: np.ndarray, C: np.ndarray, K: np.ndarray, J: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, ...]]:
    """The eigenvalues of M, C, K with the constraints of Jacobian J held exactly: with
    T a basis of J's null space (the right singular vectors beyond its numerical rank),
    those of T^T M T, T^T C T, T^T K T. Returns (eigenvalues, T, the reduced matrices)."""
    U, sv, Vt = np.linalg.svd(J)
    rank = int(np.sum(sv > 1e-9 * max(sv.max(initial=0.0), 1e-300)))
    T = Vt[rank:].T
    Mr, Cr, Kr = (T.T @ X @ T for X in (M, C, K))
    eig = quadratic_eigenvalues(Mr, Cr, Kr)
    # rigid modes (a free pulley) come out as round-off: make them exact zeros
    eig[np.abs(eig) < 1e-10 * max(np.max(np.abs(eig)), 1e-300)] = 0.0
    return eig, T, (Mr, Cr, Kr)


def rolling_contact_report(mech: Mechanism, coupling: LinearCoupling,
                           geometry: RollingGeometry, cmap: CoordinateMap, q: np.ndarray,
                           qd: np.ndarray, penetration: np.ndarray, force: np.ndarray,
                           points: np.ndarray) -> dict[str, np.ndarray]:
    """Measured errors of a RollingContact's friction stand-in, from the force of the
    track on the disc (`force`, world x, y per sample): slip (the coupling's Phi, m), slip
    rate (m/s), the `penetration` of the disc into the track (m), normal and friction
    force (N), the friction ratio |f| / N and the number of contact `points`; `friction`
    (the tangential component f, track on disc, along t = k x u with u from the track
    centre to the disc) is what the coupling's -lambda stands for."""
    cvec, const = coupling_row(mech, coupling)
    u = turned(cmap.angle(mech.joints[geometry.hub].parent, q), *geometry.radial)
    ux, uy = u[:, 0], u[:, 1]
    normal = -(force[:, 0] * ux + force[:, 1] * uy)
    friction = force[:, 0] * -uy + force[:, 1] * ux
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.abs(friction) / normal
    return {"slip": q @ cvec - const, "slip_rate": qd @ cvec, "penetration": penetration,
            "normal_force": normal, "friction": friction, "friction_ratio": ratio,
            "contact_points": points}


def length_scale(mech: Mechanism) -> float:
    """A length of the mechanism's own size: the largest distance of a joint anchor or a
    hinge closure's point from the frame it is given in."""
    points = [a for j in mech.joints for a in (j.parent_anchor, j.child_anchor)]
    points += [p for c in mech.constraints if isinstance(c, HingeClosure)
               for p in (c.point_a, c.point_b)]
    return max((math.sqrt(sum(num(v) ** 2 for v in p)) for p in points), default=1.0) or 1.0
