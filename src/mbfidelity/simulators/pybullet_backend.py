"""PyBullet backend: a reduced-coordinate Featherstone multibody (``createMultiBody``) with
a fixed base at the world origin, one link per joint, no collision shapes and explicit
inertias.

Translation (generic over the description, conventions 1-8 of `systems.model`):

- Each body becomes one link whose URDF link frame sits at the anchor of the joint that
  places it (the body's ``child_anchor``) with the body's orientation; the inertial frame
  is offset by ``-child_anchor`` so that it is the body frame (origin at the centre of
  mass). PyBullet's ``linkPositions`` are relative to the parent's link frame.
- ``Revolute``: axis z; ``angle_offset`` is the joint frame's orientation. Absolute
  angles (``absolute=True``), clockwise coordinates and non-unit prismatic axes make the
  engine's joint values an affine map of the description coordinates, ``jv = A q + b``;
  states map back with ``A^-1`` and generalized forces map as ``tau = A^-T Q``.
- ``Prismatic``: axis in the x-y plane of the joint frame (the parent axis rotated by
  ``-angle_offset``), normalised (its length goes into ``A``).
- Massless bodies are links of mass 0 and inertia 0: Featherstone's articulated-body
  algorithm only inverts the articulated inertia of each joint, which the child carries.
- Closure constraints are not translated (PyBullet's ``createConstraint`` is a
  velocity-level, drifting solver; see SIMULATORS.md): `support` says so.
- ``CoordinateForce``: joint forces through ``setJointMotorControlArray(TORQUE_CONTROL)``
  every step. ``PointToPoint``: ``applyExternalForce`` (world frame) at both points every
  step, from the engine's own link states. Both are evaluated at the state and time at
  the start of the step, which is the single stage of PyBullet's semi-implicit Euler.

Reactions: PyBullet's joint force/torque sensor (``enableJointForceTorqueSensor``) adds a
second "constraint pass" of the articulated-body algorithm, run with the already updated
velocities and with the Coriolis accelerations of the links but without the matching
``m w x v`` terms; on a chain it is wrong as soon as the joints move (1.7 N on the double
pendulum after 0.15 s), while on a single link the spurious part vanishes. The default
route therefore reads the reaction from the engine's own inverse dynamics
(``calculateInverseDynamics``) on a copy of the model in which two massless prismatic
joints (parent-frame x and y) are inserted in front of each requested joint, at the
engine's state and its acceleration of the same step (``(v_{k+1} - v_k)/dt``, exact for
semi-implicit Euler). The sensor stays available (setting ``reaction_method``).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

import numpy as np
import sympy as sp

from ..systems.model import (
    COORD,
    COORD_RATE,
    LENGTH,
    LENGTH_RATE,
    TIME,
    WORLD,
    CoordinateForce,
    Mechanism,
    PointToPoint,
    Prismatic,
    Revolute,
    compile_law,
)
from .base import Backend, Linearization, RunResult, Support

_REACTION_METHODS = ("inverse_dynamics", "joint_sensor")


def _num(x) -> float:
    """A number from a numeric description entry (sympy or float)."""
    return float(sp.sympify(x))


def _quat_z(angle: float) -> list[float]:
    """Quaternion (x, y, z, w) of a rotation by `angle` about z."""
    return [0.0, 0.0, math.sin(angle / 2.0), math.cos(angle / 2.0)]


@dataclass
class _Link:
    name: str          # joint name
    body: str          # child body
    parent: int        # engine link index of the parent body, -1 for the world
    revolute: bool
    mass: float
    inertia: float
    position: list[float]          # joint frame origin in the parent's link frame
    orientation: list[float]       # joint frame orientation in the parent's link frame
    inertial_position: list[float]  # centre of mass in the link frame
    axis: list[float]               # joint axis in the joint (= link) frame
    axis_parent: np.ndarray         # unit prismatic axis in the parent body frame (2,)


@dataclass
class _PointForce:
    name: str
    link_a: int   # -1: world
    point_a: tuple[float, float]
    link_b: int
    point_b: tuple[float, float]
    law: Callable[[float, float, float], float]
    body_a: str
    body_b: str
    time_dependent: bool


@dataclass
class _CoordForce:
    index: int
    law: Callable[[float, float, float], float]
    time_dependent: bool


class _Plan:
    """Numeric translation of a (numeric) mechanism into PyBullet terms."""

    def __init__(self, mech: Mechanism, massless_mass: float) -> None:
        self.mech = mech
        self.coords = mech.coordinates
        n = self.n = len(self.coords)
        self.gravity = _num(mech.gravity)
        link_of: dict[str, int] = {WORLD: -1}
        anchor_of: dict[str, tuple[float, float]] = {WORLD: (0.0, 0.0)}
        # body angle = ang_c . q + ang_d (affine in the coordinates)
        ang_c: dict[str, np.ndarray] = {WORLD: np.zeros(n)}
        ang_d: dict[str, float] = {WORLD: 0.0}
        A = np.zeros((n, n))
        b = np.zeros(n)
        self.links: list[_Link] = []
        for i, j in enumerate(mech.joints):
            body = mech.body(j.child)
            pa = (_num(j.parent_anchor[0]), _num(j.parent_anchor[1]))
            ca = (_num(j.child_anchor[0]), _num(j.child_anchor[1]))
            off = _num(j.angle_offset)
            panchor = anchor_of[j.parent]
            e_i = np.eye(n)[i]
            axis_parent = np.zeros(2)
            if isinstance(j, Revolute):
                axis = [0.0, 0.0, 1.0]
                turn = -e_i if getattr(j, "clockwise", False) else e_i
                if j.absolute:
                    ang_c[j.child], ang_d[j.child] = turn.copy(), off
                    A[i] = turn - ang_c[j.parent]
                    b[i] = -ang_d[j.parent]
                else:
                    ang_c[j.child], ang_d[j.child] = ang_c[j.parent] + turn, ang_d[j.parent] + off
                    A[i] = turn
            elif isinstance(j, Prismatic):
                ax = np.array([_num(j.axis[0]), _num(j.axis[1])])
                length = float(np.hypot(*ax))
                axis_parent = ax / length
                c, s = math.cos(-off), math.sin(-off)
                axis = [c * axis_parent[0] - s * axis_parent[1],
                        s * axis_parent[0] + c * axis_parent[1], 0.0]
                ang_c[j.child], ang_d[j.child] = ang_c[j.parent].copy(), ang_d[j.parent] + off
                A[i] = length * e_i
            else:  # guarded by support()
                raise TypeError(f"unsupported joint {j!r}")
            mass, inertia = _num(body.mass), _num(body.inertia)
            if body.massless:
                mass, inertia = massless_mass, 0.0
            self.links.append(_Link(
                name=j.name, body=j.child, parent=link_of[j.parent],
                revolute=isinstance(j, Revolute), mass=mass, inertia=inertia,
                position=[pa[0] - panchor[0], pa[1] - panchor[1], 0.0],
                orientation=_quat_z(off),
                inertial_position=[-ca[0], -ca[1], 0.0],
                axis=axis, axis_parent=axis_parent))
            link_of[j.child] = i
            anchor_of[j.child] = ca
        self.link_of = link_of
        self.ang_c, self.ang_d = ang_c, ang_d
        self.A, self.b = A, b
        self.Ainv = np.linalg.inv(A)
        self.AinvT = self.Ainv.T
        self.identity_map = bool(np.array_equal(A, np.eye(n)) and not b.any())

        self.coord_forces: list[_CoordForce] = []
        self.point_forces: list[_PointForce] = []
        for f in mech.forces:
            if isinstance(f, CoordinateForce):
                law = compile_law(f.force, (COORD, COORD_RATE, TIME))
                self.coord_forces.append(_CoordForce(
                    self.coords.index(f.coordinate), law,
                    TIME in sp.sympify(f.force).free_symbols))
            elif isinstance(f, PointToPoint):
                law = compile_law(f.tension, (LENGTH, LENGTH_RATE, TIME))
                self.point_forces.append(_PointForce(
                    f.name, link_of[f.body_a],
                    (_num(f.point_a[0]), _num(f.point_a[1])),
                    link_of[f.body_b], (_num(f.point_b[0]), _num(f.point_b[1])),
                    law, f.body_a, f.body_b, TIME in sp.sympify(f.tension).free_symbols))
        self.point_links = sorted({lk for pf in self.point_forces
                                   for lk in (pf.link_a, pf.link_b) if lk >= 0})

    # --- coordinate maps -------------------------------------------------------------
    def joint_values(self, q: np.ndarray) -> np.ndarray:
        return self.A @ np.asarray(q, dtype=float) + self.b

    def coordinates(self, jv: np.ndarray) -> np.ndarray:
        """Rows of engine joint values -> description coordinates."""
        return (np.asarray(jv) - self.b) @ self.AinvT

    def rates(self, jvd: np.ndarray) -> np.ndarray:
        return np.asarray(jvd) @ self.AinvT

    def coordinate_torques(self, q, qd, t: float, autonomous: bool = False) -> np.ndarray:
        """Engine joint forces of all CoordinateForce elements (tau = A^-T Q)."""
        Q = np.zeros(self.n)
        for cf in self.coord_forces:
            if autonomous and cf.time_dependent:
                continue
            Q[cf.index] += cf.law(q[cf.index], qd[cf.index], t)
        return self.AinvT @ Q


class PyBulletBackend(Backend):
    id = "pybullet"

    # --- contract points 1-5 ---------------------------------------------------------
    def available(self) -> tuple[bool, str]:
        try:
            import pybullet  # noqa: F401
        except Exception as exc:  # pragma: no cover - depends on the environment
            return False, f"pybullet not importable: {exc}"
        return True, ""

    def version(self) -> str:
        try:
            from importlib.metadata import version
            return version("pybullet")
        except Exception:  # pragma: no cover
            import pybullet
            return f"api {pybullet.getAPIVersion()}"

    def default_settings(self) -> dict:
        return {
            "joint_velocity_motors": False,
            "linear_damping": 0.0,
            "angular_damping": 0.0,
            "max_joint_velocity": 1.0e6,
            "explicit_inertia": True,
            "sleeping": False,
            "massless_link_mass": 0.0,
            "reaction_method": "inverse_dynamics",
            "linearize_step": 1.0e-6,
        }

    def setting_notes(self) -> dict[str, str]:
        return {
            "joint_velocity_motors": (
                "False: every joint's default velocity motor (target 0) is switched off with "
                "VELOCITY_CONTROL force=0. PyBullet's default (True here) locks the joints "
                "(bullet3 #2463)."),
            "linear_damping": (
                "Replaces the engine default 0.04 (a velocity-proportional plus quadratic drag "
                "on every link: -15 % period on a 2 rad swing). Set with its own changeDynamics "
                "call: PyBullet's body-level setters (linearDamping, angularDamping, "
                "maxJointVelocity) reset the link index to -1, so mass/inertia passed in the "
                "same call land on the base (it becomes a floating base)."),
            "angular_damping": "Replaces the engine default 0.04 (see linear_damping).",
            "max_joint_velocity": (
                "Replaces the engine clamp of 100 rad/s (or m/s) on every joint rate."),
            "explicit_inertia": (
                "True: the description's mass and central inertia are set on every link with "
                "changeDynamics(mass, localInertiaDiagonal). Without it a link without a "
                "collision shape gets inertia 0 (a point mass; -13 % period on the pendulum). "
                "No collision shapes are created, so there are no contacts between links."),
            "sleeping": (
                "False: deactivation disabled. PyBullet multibodies created without "
                "URDF_ENABLE_SLEEPING do not sleep; when enabled a body whose squared joint "
                "rates stay below 0.05 for 2 s freezes (the small-amplitude scenarios)."),
            "massless_link_mass": (
                "Mass given to the description's massless link bodies; 0 (default) is exact: "
                "PyBullet accepts a zero-mass, zero-inertia link that carries a massive "
                "child. A positive value is a substitute whose effect shows in the error."),
            "reaction_method": (
                "'inverse_dynamics' (default): calculateInverseDynamics on a copy with two "
                "massless prismatic joints in front of each reaction joint, at the engine's "
                "state and acceleration of the same step. 'joint_sensor': "
                "enableJointForceTorqueSensor (world-space feedback); exact on a single link, "
                "wrong on chains in motion (its constraint pass re-adds Coriolis terms)."),
            "linearize_step": (
                "Central-difference step (scaled by max(1, |x|)) for dK and dC of "
                "calculateInverseDynamics and of the applied force elements."),
        }

    def support(self, mechanism: Mechanism) -> Support:
        extra = getattr(mechanism, "constraints", ())
        if extra:
            names = ", ".join(f"{c.name} ({type(c).__name__})" for c in extra)
            return Support(False, "closure constraints are not translated by this backend "
                                  f"(reduced-coordinate tree only): {names}")
        for j in mechanism.joints:
            if not isinstance(j, (Revolute, Prismatic)):
                return Support(False, f"joint type {type(j).__name__} not supported")
            if isinstance(j, Prismatic):
                try:
                    if math.hypot(_num(j.axis[0]), _num(j.axis[1])) == 0.0:
                        return Support(False, f"prismatic joint {j.name} has a zero axis")
                except TypeError:
                    return Support(False, "mechanism is not numeric (substitute parameters)")
        for f in mechanism.forces:
            if not isinstance(f, (PointToPoint, CoordinateForce)):
                return Support(False, f"force element {type(f).__name__} not supported")
        parents = {j.parent for j in mechanism.joints}
        for body in mechanism.bodies:
            if body.massless and body.name not in parents:
                return Support(False, f"massless body {body.name} carries nothing: singular")
        return Support(True)

    # --- model building ----------------------------------------------------------------
    def _build(self, p, cid: int, plan: _Plan, settings: dict,
               split: Sequence[int] = ()) -> tuple[int, list[int], dict[int, tuple[int, int]]]:
        """Create the multibody; `split` lists joint indices in front of which two massless
        prismatic joints (parent-frame x, y) are inserted. Returns (body id, engine link
        index of each description joint, {joint index: (x link, y link)})."""
        masses, positions, orientations, inertial, parents, types, axes = [], [], [], [], [], [], []
        engine_index: list[int] = []
        virtual: dict[int, tuple[int, int]] = {}

        def add(mass, pos, orn, ipos, parent, jtype, axis) -> int:
            masses.append(mass)
            positions.append(pos)
            orientations.append(orn)
            inertial.append(ipos)
            parents.append(parent + 1)  # createMultiBody counts links from 1; 0 = base
            types.append(jtype)
            axes.append(axis)
            return len(masses) - 1

        for i, lk in enumerate(plan.links):
            parent = engine_index[lk.parent] if lk.parent >= 0 else -1
            pos = lk.position
            if i in split:
                vx = add(0.0, pos, [0, 0, 0, 1], [0, 0, 0], parent, p.JOINT_PRISMATIC, [1, 0, 0])
                vy = add(0.0, [0, 0, 0], [0, 0, 0, 1], [0, 0, 0], vx, p.JOINT_PRISMATIC,
                         [0, 1, 0])
                virtual[i] = (vx, vy)
                parent, pos = vy, [0.0, 0.0, 0.0]
            jtype = p.JOINT_REVOLUTE if lk.revolute else p.JOINT_PRISMATIC
            engine_index.append(add(lk.mass, pos, lk.orientation, lk.inertial_position,
                                    parent, jtype, lk.axis))
        nl = len(masses)
        body = p.createMultiBody(
            baseMass=0.0, baseCollisionShapeIndex=-1, baseVisualShapeIndex=-1,
            basePosition=[0, 0, 0], baseOrientation=[0, 0, 0, 1],
            linkMasses=masses, linkCollisionShapeIndices=[-1] * nl,
            linkVisualShapeIndices=[-1] * nl, linkPositions=positions,
            linkOrientations=orientations, linkInertialFramePositions=inertial,
            linkInertialFrameOrientations=[[0, 0, 0, 1]] * nl, linkParentIndices=parents,
            linkJointTypes=types, linkJointAxis=axes, physicsClientId=cid)
        if body < 0:
            raise RuntimeError("pybullet createMultiBody failed")
        # body-level parameters in their own calls (they reset the link index to -1)
        p.changeDynamics(body, -1, linearDamping=float(settings["linear_damping"]),
                         physicsClientId=cid)
        p.changeDynamics(body, -1, angularDamping=float(settings["angular_damping"]),
                         physicsClientId=cid)
        p.changeDynamics(body, -1, maxJointVelocity=float(settings["max_joint_velocity"]),
                         physicsClientId=cid)
        p.changeDynamics(body, -1, activationState=(
            p.ACTIVATION_STATE_ENABLE_SLEEPING if settings["sleeping"]
            else p.ACTIVATION_STATE_DISABLE_SLEEPING), physicsClientId=cid)
        for i, lk in enumerate(plan.links):
            if settings["explicit_inertia"]:
                p.changeDynamics(body, engine_index[i], mass=float(lk.mass),
                                 localInertiaDiagonal=[lk.inertia] * 3, physicsClientId=cid)
            info = p.getDynamicsInfo(body, engine_index[i], physicsClientId=cid)
            if settings["explicit_inertia"] and (
                    abs(info[0] - lk.mass) > 1e-12 * max(1.0, lk.mass)
                    or abs(info[2][2] - lk.inertia) > 1e-12 * max(1.0, lk.inertia)):
                raise RuntimeError(f"pybullet did not take the inertia of link {lk.name}: {info}")
        if not settings["joint_velocity_motors"]:
            p.setJointMotorControlArray(body, list(range(nl)), p.VELOCITY_CONTROL,
                                        targetVelocities=[0.0] * nl, forces=[0.0] * nl,
                                        physicsClientId=cid)
        return body, engine_index, virtual

    def _connect(self, p, settings: dict, dt: float, gravity: float) -> int:
        cid = p.connect(p.DIRECT)
        if cid < 0:
            raise RuntimeError("pybullet connect(DIRECT) failed")
        p.setGravity(0.0, -gravity, 0.0, physicsClientId=cid)
        p.setTimeStep(dt, physicsClientId=cid)
        p.setPhysicsEngineParameter(
            fixedTimeStep=dt, numSubSteps=0,
            jointFeedbackMode=p.JOINT_FEEDBACK_IN_WORLD_SPACE, physicsClientId=cid)
        return cid

    @staticmethod
    def _points(ls, pf: _PointForce) -> tuple[float, float, float, float, float, float,
                                                float, float]:
        """World position and velocity of both points of an element from link states."""
        out = []
        for link, (px, py) in ((pf.link_a, pf.point_a), (pf.link_b, pf.point_b)):
            if link < 0:
                out += [px, py, 0.0, 0.0]
                continue
            st = ls[link]
            com, quat, vel, omega = st[0], st[1], st[6], st[7][2]
            th = 2.0 * math.atan2(quat[2], quat[3])
            c, s = math.cos(th), math.sin(th)
            rx, ry = c * px - s * py, s * px + c * py
            out += [com[0] + rx, com[1] + ry, vel[0] - omega * ry, vel[1] + omega * rx]
        return tuple(out)  # type: ignore[return-value]

    @staticmethod
    def _tension_force(pf: _PointForce, pts, t: float) -> tuple[float, float, float, float,
                                                                 float, float]:
        """(force on b x, y, point a x, y, point b x, y); the force on a is opposite."""
        ax, ay, vax, vay, bx, by, vbx, vby = pts
        dx, dy = bx - ax, by - ay
        length = math.hypot(dx, dy)
        if length == 0.0:
            return 0.0, 0.0, ax, ay, bx, by
        ux, uy = dx / length, dy / length
        rate = ux * (vbx - vax) + uy * (vby - vay)
        tension = pf.law(length, rate, t)
        return -tension * ux, -tension * uy, ax, ay, bx, by

    # --- contract point 6 --------------------------------------------------------------
    def simulate(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray, t_end: float,
                 dt: float, settings: Mapping | None = None,
                 reaction_joints: Sequence[str] = ()) -> RunResult:
        import pybullet as p

        cfg = self.resolve_settings(settings)
        if cfg["reaction_method"] not in _REACTION_METHODS:
            raise ValueError(f"reaction_method must be one of {_REACTION_METHODS}")
        ok = self.support(mechanism)
        if not ok.ok:
            raise ValueError(f"pybullet cannot express this mechanism: {ok.reason}")
        plan = _Plan(mechanism, float(cfg["massless_link_mass"]))
        n, steps = plan.n, int(round(t_end / dt))
        joint_ids = [mechanism.joints.index(mechanism.joint(name)) for name in reaction_joints]
        use_sensor = bool(reaction_joints) and cfg["reaction_method"] == "joint_sensor"
        # one extra step gives the reaction/acceleration of the last sample
        total = steps + 1 if reaction_joints else steps

        cid = self._connect(p, cfg, dt, plan.gravity)
        try:
            body, eidx, _ = self._build(p, cid, plan, cfg)
            jv0 = plan.joint_values(q0)
            jvd0 = plan.A @ np.asarray(qd0, dtype=float)
            for i in range(n):
                p.resetJointState(body, eidx[i], float(jv0[i]), float(jvd0[i]),
                                  physicsClientId=cid)
            if use_sensor:
                for i in joint_ids:
                    p.enableJointForceTorqueSensor(body, eidx[i], True, physicsClientId=cid)

            JV = np.empty((total + 1, n))
            JVD = np.empty((total + 1, n))
            sensor = np.full((total + 1, len(joint_ids), 2), np.nan)
            n_pf = len(plan.point_forces)
            f_point = np.zeros((total + 1, n_pf, 2))  # force on point b (on a: opposite)
            tau_applied = np.zeros((total + 1, n))  # engine joint forces of CoordinateForces

            step = p.stepSimulation
            get_states = p.getJointStates
            set_motors = p.setJointMotorControlArray
            get_links = p.getLinkStates
            apply_force = p.applyExternalForce
            torque_mode, world = p.TORQUE_CONTROL, p.WORLD_FRAME
            links = eidx
            has_cf = bool(plan.coord_forces)
            point_links = [eidx[k] for k in plan.point_links]
            pos_of = {k: m for m, k in enumerate(plan.point_links)}
            AinvT, Ainv, bvec = plan.AinvT, plan.Ainv, plan.b
            identity = plan.identity_map
            sensor_slots = [eidx[i] for i in joint_ids]

            js = get_states(body, links, physicsClientId=cid)
            t0 = time.perf_counter()
            for k in range(total):
                t = k * dt
                jv = [s[0] for s in js]
                jvd = [s[1] for s in js]
                JV[k] = jv
                JVD[k] = jvd
                if has_cf:
                    if identity:
                        tau = plan.coordinate_torques(jv, jvd, t)
                    else:
                        q = Ainv @ (np.asarray(jv) - bvec)
                        qd = Ainv @ np.asarray(jvd)
                        tau = plan.coordinate_torques(q, qd, t)
                    tau_applied[k] = tau
                    set_motors(body, links, torque_mode, forces=tau.tolist(),
                               physicsClientId=cid)
                if n_pf:
                    ls = get_links(body, point_links, computeLinkVelocity=1,
                                   computeForwardKinematics=1, physicsClientId=cid)
                    ls_by_link = {lk: ls[pos_of[lk]] for lk in plan.point_links}
                    for e, pf in enumerate(plan.point_forces):
                        fx, fy, ax, ay, bx, by = self._tension_force(
                            pf, self._points(ls_by_link, pf), t)
                        f_point[k, e] = fx, fy
                        if pf.link_b >= 0:
                            apply_force(body, eidx[pf.link_b], [fx, fy, 0.0], [bx, by, 0.0],
                                        world, physicsClientId=cid)
                        if pf.link_a >= 0:
                            apply_force(body, eidx[pf.link_a], [-fx, -fy, 0.0], [ax, ay, 0.0],
                                        world, physicsClientId=cid)
                step(physicsClientId=cid)
                js = get_states(body, links, physicsClientId=cid)
                if use_sensor:
                    # the feedback read after a step belongs to the state before it
                    for r, slot in enumerate(sensor_slots):
                        rf = js[slot][2]
                        sensor[k, r] = rf[0], rf[1]
            wall = time.perf_counter() - t0
            JV[total] = [s[0] for s in js]
            JVD[total] = [s[1] for s in js]

            reactions: dict[str, np.ndarray] = {}
            if reaction_joints:
                if use_sensor:
                    for r, name in enumerate(reaction_joints):
                        reactions[name] = sensor[: steps + 1, r].copy()
                else:
                    jvdd = (JVD[1: total + 1] - JVD[:total]) / dt
                    reactions = self._reactions_by_inverse_dynamics(
                        p, cid, plan, cfg, joint_ids, list(reaction_joints),
                        JV[: steps + 1], JVD[: steps + 1], jvdd[: steps + 1],
                        f_point[: steps + 1])
                self._remove_coordinate_forces(plan, joint_ids, list(reaction_joints),
                                               reactions, plan.coordinates(JV[: steps + 1]),
                                               tau_applied[: steps + 1])
        finally:
            p.disconnect(physicsClientId=cid)

        q = plan.coordinates(JV[: steps + 1])
        qd = plan.rates(JVD[: steps + 1])
        return RunResult(t=np.arange(steps + 1) * dt, q=q, qd=qd, reactions=reactions,
                         wall_time=wall, integrator_order=1, settings=cfg, steps=steps)

    @staticmethod
    def _remove_coordinate_forces(plan: _Plan, joint_ids: list[int], names: list[str],
                                  reactions: dict[str, np.ndarray], q: np.ndarray,
                                  tau: np.ndarray) -> None:
        """Both routes see the force that the coordinate laws apply along a prismatic
        joint; the description counts it as an applied load, not as part of the reaction
        (derivation: `_external_force_on`), so it is taken out here."""
        for i, name in zip(joint_ids, names):
            lk = plan.links[i]
            if lk.revolute or not tau[:, i].any():
                continue
            joint = plan.mech.joints[i]
            th = q @ plan.ang_c[joint.parent] + plan.ang_d[joint.parent]
            c, s = np.cos(th), np.sin(th)
            ux, uy = lk.axis_parent
            reactions[name] -= tau[:, i, None] * np.stack([c * ux - s * uy, s * ux + c * uy],
                                                           axis=1)

    def _reactions_by_inverse_dynamics(self, p, cid: int, plan: _Plan, cfg: dict,
                                       joint_ids: list[int], names: list[str],
                                       JV: np.ndarray, JVD: np.ndarray, JVDD: np.ndarray,
                                       f_point: np.ndarray) -> dict[str, np.ndarray]:
        """Reaction = inverse-dynamics force on two massless prismatic joints (x, y of the
        parent frame) inserted in front of the joint, minus the point-to-point forces that
        reach the child's subtree from outside (they act on the bodies, not through the
        joint)."""
        body, eidx, virtual = self._build(p, cid, plan, cfg, split=set(joint_ids))
        ndof = p.getNumJoints(body, physicsClientId=cid)
        slots = np.array(eidx)
        vslots = [virtual[i] for i in joint_ids]
        N = len(JV)
        pos = np.zeros((N, ndof))
        vel = np.zeros((N, ndof))
        acc = np.zeros((N, ndof))
        pos[:, slots], vel[:, slots], acc[:, slots] = JV, JVD, JVDD
        out = np.empty((N, len(joint_ids), 2))
        inv_dyn = p.calculateInverseDynamics
        for k in range(N):
            tau = inv_dyn(body, pos[k].tolist(), vel[k].tolist(), acc[k].tolist(),
                          physicsClientId=cid)
            for r, (vx, vy) in enumerate(vslots):
                out[k, r] = tau[vx], tau[vy]
        q = plan.coordinates(JV)
        reactions: dict[str, np.ndarray] = {}
        for r, (i, name) in enumerate(zip(joint_ids, names)):
            joint = plan.mech.joints[i]
            th = q @ plan.ang_c[joint.parent] + plan.ang_d[joint.parent]
            c, s = np.cos(th), np.sin(th)
            fx, fy = out[:, r, 0], out[:, r, 1]
            R = np.stack([c * fx - s * fy, s * fx + c * fy], axis=1)
            subtree = set(plan.mech.subtree(joint.child))
            for e, pf in enumerate(plan.point_forces):
                in_a, in_b = pf.body_a in subtree, pf.body_b in subtree
                if in_b and not in_a:
                    R -= f_point[:, e]
                elif in_a and not in_b:
                    R += f_point[:, e]
            reactions[name] = R
        return reactions

    # --- contract point 7 --------------------------------------------------------------
    def linearize(self, mechanism: Mechanism, q_eq: np.ndarray,
                  settings: Mapping | None = None, dt: float = 1e-3) -> Linearization | None:
        import pybullet as p

        cfg = self.resolve_settings(settings)
        ok = self.support(mechanism)
        if not ok.ok:
            return None
        plan = _Plan(mechanism, float(cfg["massless_link_mass"]))
        n = plan.n
        h_rel = float(cfg["linearize_step"])
        cid = self._connect(p, cfg, dt, plan.gravity)
        try:
            body, eidx, _ = self._build(p, cid, plan, cfg)
            jv_eq = plan.joint_values(np.asarray(q_eq, dtype=float))
            zeros = [0.0] * n

            def applied(jv: np.ndarray, jvd: np.ndarray) -> np.ndarray:
                """Engine joint forces of the autonomous force elements at (jv, jvd)."""
                q = plan.coordinates(jv)
                qd = plan.rates(jvd)
                tau = plan.coordinate_torques(q, qd, 0.0, autonomous=True)
                pfs = [pf for pf in plan.point_forces if not pf.time_dependent]
                if not pfs:
                    return tau
                for i in range(n):
                    p.resetJointState(body, eidx[i], float(jv[i]), float(jvd[i]),
                                      physicsClientId=cid)
                ls = {lk: p.getLinkState(body, eidx[lk], computeLinkVelocity=1,
                                         computeForwardKinematics=1, physicsClientId=cid)
                      for lk in plan.point_links}
                for pf in pfs:
                    fx, fy, *_ = self._tension_force(pf, self._points(ls, pf), 0.0)
                    for link, point, sign in ((pf.link_b, pf.point_b, 1.0),
                                              (pf.link_a, pf.point_a, -1.0)):
                        if link < 0:
                            continue
                        # calculateJacobian takes the point in the URDF link frame (the
                        # joint frame), not about the centre of mass as its docstring says
                        ip = plan.links[link].inertial_position
                        jac_t, _ = p.calculateJacobian(
                            body, eidx[link], [point[0] + ip[0], point[1] + ip[1], 0.0],
                            list(map(float, jv)), list(map(float, jvd)), zeros,
                            physicsClientId=cid)
                        J = np.asarray(jac_t)[:2]
                        tau = tau + sign * (J.T @ np.array([fx, fy]))
                return tau

            def residual(jv: np.ndarray, jvd: np.ndarray) -> np.ndarray:
                tau_id = p.calculateInverseDynamics(body, list(map(float, jv)),
                                                    list(map(float, jvd)), zeros,
                                                    physicsClientId=cid)
                return np.asarray(tau_id) - applied(jv, jvd)

            M = np.atleast_2d(np.array(p.calculateMassMatrix(
                body, list(map(float, jv_eq)), physicsClientId=cid)))
            K = np.zeros((n, n))
            C = np.zeros((n, n))
            v0 = np.zeros(n)
            for i in range(n):
                h = h_rel * max(1.0, abs(jv_eq[i]))
                e = np.zeros(n)
                e[i] = h
                K[:, i] = (residual(jv_eq + e, v0) - residual(jv_eq - e, v0)) / (2 * h)
                hv = h_rel
                ev = np.zeros(n)
                ev[i] = hv
                C[:, i] = (residual(jv_eq, v0 + ev) - residual(jv_eq, v0 - ev)) / (2 * hv)
        finally:
            p.disconnect(physicsClientId=cid)
        Minv = np.linalg.inv(M)
        state = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
        eig = np.linalg.eigvals(state).astype(complex)
        return Linearization(
            eigenvalues=eig,
            method=("calculateMassMatrix + central differences of calculateInverseDynamics "
                    "(K, C) plus the applied force elements (coordinate laws; point-to-point "
                    "forces through calculateJacobian), which inverse dynamics omits"),
            extra={"M": M.tolist(), "K": K.tolist(), "C": C.tolist(),
                   "coordinates": "engine joint values"})


BACKEND = PyBulletBackend()
