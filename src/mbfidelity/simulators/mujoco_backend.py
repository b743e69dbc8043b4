"""MuJoCo backend: the description is translated to MJCF text (`mujoco_mjcf`, one builder
per element kind with its declared expression) and integrated with RK4.

Laws MuJoCo cannot hold natively run in the passive callback (`_Compiled._make_callback`),
prescribed motions in the control callback (`_Compiled._make_control`); closures are soft
equalities whose force and violation are read at every sample (`_ClosureSamples`), and
joint reactions start from the force MuJoCo books as transmitted (`_Transmitted`).
"""
from __future__ import annotations

import contextlib
import math
from typing import Callable, Iterator, Mapping, Sequence

import numpy as np

from ..analytic.modes import quadratic_eigenvalues
from ..systems._continua import Beam
from ..systems.model import Mechanism
from . import mujoco_mjcf
from .base import (
    RELEASE_AMPLITUDE,
    RELEASE_OMEGA_DT,
    RELEASE_PERIODS,
    RK4_STABILITY,
    SEMI_IMPLICIT_EULER_STABILITY,
    SUBSTITUTE,
    BareLoop,
    Backend,
    BeamElement,
    BeamModes,
    Expression,
    Linearization,
    Samples,
    Scheme,
    Setting,
    Stopwatch,
    semi_implicit_euler_modes,
    stiffness_by_central_differences,
)
from .mujoco_mjcf import (
    POINT_MASS_GYRATION,
    Closure,
    Build,
    fmt,
    translate,
)
from .plan import (ImposedMotions, constrained_modes, coupled, geometric_stiffness, num,
                   spatial_tree_reason, stage_time)
from .reactions import tension_pair_force


class _Compiled:
    """A compiled MuJoCo model of a build, stepped at the step its MJCF is written for
    (`Build.dt`: the closures' and contacts' solref follow it), plus the index maps and
    the callbacks."""

    def __init__(self, build: Build, integrator: str, autoreset: bool = False) -> None:
        import mujoco

        self.mujoco, self.build, dt = mujoco, build, build.dt
        # the file carries the step and the settings' options (`mujoco_mjcf.mjcf`); the
        # integrator and autoreset given here may differ (a linearization's Euler copy)
        self.model = m = mujoco.MjModel.from_xml_string(build.xml)
        m.opt.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{integrator.upper()}")
        bit = int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
        m.opt.disableflags = m.opt.disableflags & ~bit if autoreset else m.opt.disableflags | bit
        self.data = mujoco.MjData(m)

        def addresses(names: list[str]) -> tuple[np.ndarray, np.ndarray]:
            """The joints' qpos and dof addresses."""
            return (np.array([m.joint(nm).qposadr[0] for nm in names], dtype=int),
                    np.array([m.joint(nm).dofadr[0] for nm in names], dtype=int))

        self.qadr, self.vadr = addresses([j.name for j in build.mech.joints])
        sliders = [cl for cl in build.closures if cl.kind == "slider"]
        self.slider_jnt = np.array([m.joint(cl.slider).id for cl in sliders], dtype=int)
        self.slider_qadr, self.slider_vadr = addresses([cl.slider for cl in sliders])
        self.slider_body = np.array([m.body(cl.slider).id for cl in sliders], dtype=int)
        self.slider_sites = [(m.site(cl.site1).id, m.site(cl.site2).id) for cl in sliders]
        #: each closure's equalities (a hinge closure has two connects)
        self.eq_id = [[m.equality(cl.element.name).id]
                      + ([m.equality(f"{cl.element.name}:axis").id] if cl.kind == "hinge" else [])
                      if cl.kind != "contact" else [] for cl in build.closures]
        contacts = [cl for cl in build.closures if cl.kind == "contact"]
        self.radial_qadr, self.radial_vadr = addresses([cl.slider for cl in contacts])
        self.disc_geom = [m.geom(f"{cl.element.name}:disc").id for cl in contacts]
        self.callback = self._make_callback(dt)
        #: the actuator forces (description coordinates) the control callback applied last
        self.actuator = np.zeros(len(build.mech.prescribed))
        self.control = self._make_control(integrator, dt)

    def efc_jacobian(self) -> np.ndarray:
        """The constraint Jacobian efc_J (nefc, nv), dense (after mj_forward)."""
        mujoco, m, d = self.mujoco, self.model, self.data
        if not mujoco.mj_isSparse(m):
            return d.efc_J.reshape(d.nefc, m.nv).copy()
        J = np.zeros((d.nefc, m.nv))
        mujoco.mju_sparse2dense(J, d.efc_J, d.efc_J_rownnz, d.efc_J_rowadr, d.efc_J_colind)
        return J

    def inverse_fd(self, reset: Callable[[], None], eps: float
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Continuous-time K, C, M of mjd_inverseFD (finite differences of mj_inverse) at
        the state `reset` sets, central differences by combining the forward (+eps) and
        backward (-eps) ones; its outputs are transposed (row i = derivative with respect
        to input i)."""
        mujoco, m, d = self.mujoco, self.model, self.data
        mats = []
        for h in (eps, -eps):
            reset()
            d.qacc[:] = 0
            mujoco.mj_forward(m, d)
            d.qacc[:] = 0
            DfDq, DfDv, DfDa = (np.zeros((m.nv, m.nv)) for _ in range(3))
            mujoco.mjd_inverseFD(m, d, h, False, DfDq, DfDv, DfDa, None, None, None, None)
            mats.append((DfDq, DfDv, DfDa))
        return tuple((mats[0][i] + mats[1][i]).T / 2 for i in range(3))

    def contact_state(self, cl: Closure, k_contact: int) -> tuple[float, float]:
        """After mj_forward, for a rolling coupling built as contact (the k-th such
        closure): the generalized force of the disc's contacts on the description
        coordinates (A^T qfrc), as the coupling's value -lam, i.e. that on the disc's
        coordinate over its coefficient; and the accumulated slip Phi = c.q - const."""
        mujoco, m, d = self.mujoco, self.model, self.data
        kinds = {int(mujoco.mjtConstraint.mjCNSTR_CONTACT_FRICTIONLESS),
                 int(mujoco.mjtConstraint.mjCNSTR_CONTACT_PYRAMIDAL),
                 int(mujoco.mjtConstraint.mjCNSTR_CONTACT_ELLIPTIC)}
        rows = [r for r in range(d.nefc) if int(d.efc_type[r]) in kinds
                and self.disc_geom[k_contact] in d.contact.geom[d.efc_id[r]]]
        # the joint-space force of the disc's contacts
        qfrc = self.efc_jacobian()[rows].T @ d.efc_force[rows] if rows else np.zeros(m.nv)
        Q = self.build.map.A.T @ qfrc[self.vadr]
        j = cl.contact.hub
        q = self.build.map.coordinates(d.qpos[self.qadr])
        return Q[j] / cl.coef[j], cl.coef @ q - num(cl.element.constant)

    def _make_callback(self, dt: float):
        """The passive callback of the laws MuJoCo cannot hold natively (time loads among
        them), or None."""
        build, model = self.build, self.model
        half = dt / 2
        # COORD = row . (v - b) over the joints' (qpos, dof) addresses; the law's force F
        # acts on those dofs as row F (A^-T e_j F: row j of A^-1)
        coord_terms = []
        for e in build.coord:
            if e.native is not None:
                continue
            ins = tuple((int(self.qadr[i]), int(self.vadr[i]), float(e.row[i]))
                        for i in np.flatnonzero(e.row))
            coord_terms.append((e.law, ins, float(-e.row @ build.map.b)))
        p2p_terms = []
        for e in build.p2p:
            if e.native is not None:
                continue
            tid = model.tendon(e.element.name).id
            adr, nnz = int(model.ten_J_rowadr[tid]), int(model.ten_J_rownnz[tid])
            cols = np.array(model.ten_J_colind[adr:adr + nnz])
            p2p_terms.append((e.law, tid, adr, adr + nnz, cols))
        if not coord_terms and not p2p_terms:
            return None

        def passive(m, d) -> None:
            if m is not model:  # the callback is global: act on our model only
                return
            t = stage_time(d.time, half)  # MuJoCo's clock adds h at every step
            qfrc = d.qfrc_passive
            if coord_terms:
                qpos, qvel = d.qpos.tolist(), d.qvel.tolist()
                for law, ins, const in coord_terms:
                    x, xd = const, 0.0
                    for qa, va, c in ins:
                        x += c * qpos[qa]
                        xd += c * qvel[va]
                    force = law(x, xd, t)
                    for _, va, c in ins:
                        qfrc[va] += c * force
            for law, tid, a0, a1, cols in p2p_terms:
                tension = law(d.ten_length[tid], d.ten_velocity[tid], t)
                qfrc[cols] -= tension * d.ten_J[a0:a1]  # -T dL/dq

        return passive

    def _make_control(self, integrator: str, dt: float):
        """The control callback that imposes the prescribed motions (`plan.ImposedMotions`:
        Q_p written to qfrc_applied, f = qfrc_passive - qfrc_bias, the passive callback's
        forces being in qfrc_passive), or None. RK4 calls the callback at every stage with
        the stage time, H = M. The first-order integrators move the velocity by h H^-1
        (force) with H the matrix they solve (Euler: M + h diag(dof_damping), its implicit
        damping; implicitfast and implicit: also the tendon dampers' J^T b J; implicit adds
        the velocity derivative of the bias forces, by central differences, exact for a
        quadratic)."""
        build, model, mujoco = self.build, self.model, self.mujoco
        discrete = integrator != "RK4"
        imposed = ImposedMotions(build.mech, build.map, self.vadr, model.nv, discrete, dt)
        if not imposed.k:
            return None
        nv, h, qadr, actuator = model.nv, float(dt), self.qadr, self.actuator
        stack = np.zeros((1 + imposed.k, nv))  # the free force and the actuators' columns
        stack[1:] = imposed.Tp
        solved = np.zeros_like(stack)
        # Euler damps implicitly unless eulerdamp is disabled
        eulerdamp = not model.opt.disableflags & int(mujoco.mjtDisableBit.mjDSBL_EULERDAMP)
        damping = (np.diag(model.dof_damping) if discrete and (integrator != "Euler" or eulerdamp)
                   else None)
        tendons = ([int(i) for i in np.flatnonzero(model.tendon_damping)]
                   if integrator in ("implicit", "implicitfast") else [])
        coriolis = integrator == "implicit"
        if damping is not None and not damping.any() and not tendons and not coriolis:
            damping = None
        full = np.zeros((nv, nv))
        bias = np.zeros(nv)
        bias_minus = np.zeros(nv)

        def matrix(m, d) -> np.ndarray:
            """H: the matrix the integrator solves with (damping is not None)."""
            mujoco.mj_fullM(m, d, full)
            H = full + h * damping
            for tid in tendons:
                adr, nnz = int(d.ten_J_rowadr[tid]), int(d.ten_J_rownnz[tid])
                J = np.zeros(nv)
                J[d.ten_J_colind[adr:adr + nnz]] = d.ten_J[adr:adr + nnz]
                H += h * m.tendon_damping[tid] * np.outer(J, J)
            if coriolis:
                v0 = d.qvel.copy()
                for i in range(nv):
                    for sign, out in ((1.0, bias), (-1.0, bias_minus)):
                        d.qvel[:] = v0
                        d.qvel[i] += sign * 1e-3
                        mujoco.mj_comVel(m, d)
                        mujoco.mj_rne(m, d, 0, out)
                    H[:, i] += h * (bias - bias_minus) / 2e-3  # - h d(-bias)/dv
                d.qvel[:] = v0
                mujoco.mj_comVel(m, d)
            return H

        # fixed buffers of the data, viewed once (the callback runs at every stage)
        data = self.data
        passive, bias_force, applied = data.qfrc_passive, data.qfrc_bias, data.qfrc_applied
        qpos, qvel = data.qpos, data.qvel
        solve_m, subtract = mujoco.mj_solveM, np.subtract
        half = h / 2

        def control(m, d) -> None:
            if m is not model:  # the callback is global: act on our model only
                return
            t = stage_time(d.time, half)  # MuJoCo's clock adds h at every step
            subtract(passive, bias_force, out=stack[0])
            if damping is None:
                solve_m(m, d, solved, stack)
            else:
                solved[:] = np.linalg.solve(matrix(m, d), stack.T).T
            target = imposed.targets(t, qpos[qadr] if discrete else None, qvel)
            imposed.actuator_forces(solved, target, actuator, applied)

        return control

    def set_state(self, q: np.ndarray, qd: np.ndarray, t: float = 0.0) -> None:
        """Description state -> MuJoCo state; the slider bodies of point-on-line
        constraints are placed where the (consistent) state puts the pins: their slide
        value is (P - L) . u and its rate (v_P - v_L) . u, with v_L the velocity of the
        slot body's material point under the slider."""
        mujoco, m, d = self.mujoco, self.model, self.data
        d.qpos[self.qadr] = self.build.map.engine_values(q)
        d.qvel[self.vadr] = self.build.map.A @ np.asarray(qd, dtype=float)
        d.time = t
        d.qpos[self.radial_qadr] = 0.0
        d.qvel[self.radial_vadr] = 0.0
        if len(self.slider_jnt):
            d.qpos[self.slider_qadr] = 0.0
            d.qvel[self.slider_vadr] = 0.0
            mujoco.mj_kinematics(m, d)
            for k, (pin, sl) in enumerate(self.slider_sites):
                u = d.xaxis[self.slider_jnt[k]]
                d.qpos[self.slider_qadr[k]] = (d.site_xpos[pin] - d.site_xpos[sl]) @ u
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            jp, js = np.zeros((3, m.nv)), np.zeros((3, m.nv))
            rates = []
            for k, (pin, sl) in enumerate(self.slider_sites):
                mujoco.mj_jacSite(m, d, jp, None, pin)
                mujoco.mj_jacSite(m, d, js, None, sl)
                u = d.xaxis[self.slider_jnt[k]]
                rates.append(((jp - js) @ d.qvel) @ u)
            d.qvel[self.slider_vadr] = rates


class _ClosureSamples:
    """Each closure's force in the contract's physical terms and its violation
    (PointOnPoint: distance of the two points, m; HingeClosure: the larger distance of its
    two connects' points, m, its force NaN (not determined by the motion); PointOnLine:
    signed distance of the pin from the slot line, m; LinearCoupling: Phi) over the
    sampled states. `record(k)`, after mj_forward at sample k, copies what the closures
    need (their equality rows' force and position, the sliders' acceleration and axis, the
    contacts' state); `result()` forms the physical terms over all samples at once."""

    def __init__(self, comp: _Compiled, n_samples: int) -> None:
        self.comp, self.n = comp, n_samples
        self.closures = comp.build.closures
        self.contacts = [cl for cl in self.closures if cl.kind == "contact"]
        n_sliders = len(comp.slider_jnt)
        self.sliders = list(enumerate(comp.slider_body)) if n_sliders else []
        self.obj_body = int(comp.mujoco.mjtObj.mjOBJ_BODY)
        self.acc = np.empty((n_samples, n_sliders, 6))
        self.axis = np.empty((n_samples, n_sliders, 3))
        self.contact_force = np.empty((n_samples, len(self.contacts)))
        self.contact_violation = np.empty((n_samples, len(self.contacts)))
        self.rows: list[np.ndarray] | None = None  # each closure's equality rows

    def _layout(self) -> None:
        """The equality rows of each closure, from the first sample: MuJoCo puts the
        equality rows first, in equality order, the same at every sample."""
        d = self.comp.data
        eq_type = int(self.comp.mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        nefc = d.nefc
        eq_rows = np.flatnonzero(d.efc_type[:nefc] == eq_type)
        if len(eq_rows) != d.ne or not np.array_equal(eq_rows, np.arange(d.ne)):
            raise RuntimeError("mujoco: the equality rows do not come first")
        eq_ids = d.efc_id[:nefc][eq_rows]
        self.rows = [eq_rows[np.isin(eq_ids, eids)] for eids in self.comp.eq_id]
        self.ne = d.ne
        self.force = np.empty((self.n, self.ne))
        self.pos = np.empty((self.n, self.ne))

    def record(self, k: int) -> None:
        comp = self.comp
        mujoco, m, d = comp.mujoco, comp.model, comp.data
        if self.rows is None:
            self._layout()
        if d.ne != self.ne:
            raise RuntimeError("mujoco: the closures' equality rows changed between samples")
        self.force[k] = d.efc_force[:self.ne]
        self.pos[k] = d.efc_pos[:self.ne]
        if self.sliders:  # after mj_rnePostConstraint
            acc = self.acc[k]
            for j, bid in self.sliders:
                mujoco.mj_objectAcceleration(m, d, self.obj_body, bid, acc[j], 0)
            self.axis[k] = d.xaxis[comp.slider_jnt]
        for j, cl in enumerate(self.contacts):
            self.contact_force[k, j], self.contact_violation[k, j] = comp.contact_state(cl, j)

    def result(self) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        m = self.comp.model
        forces: dict[str, np.ndarray] = {}
        violation: dict[str, np.ndarray] = {}
        k_slider = k_contact = 0
        for cl, rr in zip(self.closures, self.rows or [()] * len(self.closures)):
            name = cl.element.name
            if cl.kind == "contact":
                forces[name] = self.contact_force[:, [k_contact]]
                violation[name] = self.contact_violation[:, k_contact]
                k_contact += 1
                continue
            f, pos = self.force[:, rr], self.pos[:, rr]
            if cl.kind == "tendon":
                # the row's Jacobian in description coordinates is c: J^T f = c f = -c lam
                forces[name] = f[:, :1]
                violation[name] = pos[:, 0]
            elif cl.kind == "hinge":
                # mujoco_mjcf's HINGE_FORCE_INDETERMINATE; the connects of the hinge point
                # and of the axis point
                forces[name] = np.full((self.n, 3), np.nan)
                violation[name] = np.maximum(np.linalg.norm(pos[:, :3], axis=1),
                                             np.linalg.norm(pos[:, 3:6], axis=1))
            elif cl.kind == "connect":
                # rows p1 - p2 (world), J = J1 - J2: f acts on body_a at site1
                forces[name] = f[:, :2]
                violation[name] = np.array([math.hypot(x, y) for x, y in pos[:, :2].tolist()])
            else:
                # the slider's mass belongs to the pin (plan.slider_masses): the
                # slot's force on pin + slider is the slide joint's force on the slider,
                # m_s a_s - (weight not cancelled) + (connect force on the pin); MuJoCo's
                # body accelerations are proper accelerations a - g
                bid = self.comp.slider_body[k_slider]
                ms = m.body_mass[bid]
                cancelled = ms * m.opt.gravity[:2] * m.body_gravcomp[bid]
                forces[name] = f[:, :2] + ms * self.acc[:, k_slider, 3:5] + cancelled
                u = self.axis[:, k_slider]
                violation[name] = -u[:, 1] * pos[:, 0] + u[:, 0] * pos[:, 1]  # n . (P - L)
                k_slider += 1
        return forces, violation


class _Transmitted:
    """Per joint the force MuJoCo books as passing from parent to child (``cfrc_int[body,
    3:6]`` of the child's MJCF body, world axes, after mj_rnePostConstraint). Forces MuJoCo
    books as joint-space passive forces (joint springs and dampers, the callback, tendon
    equalities) are inside that number, so the base takes out those acting on the child's
    subtree from outside (`reactions.joint_reaction`): per point-to-point element that the
    callback applies, its force on body_a is recorded here; native tendon forces are
    already external (MuJoCo puts them in ``cfrc_ext``).
    `record(k)` after mj_forward and mj_rnePostConstraint at sample k; `result(t)`."""

    def __init__(self, comp: _Compiled, n_samples: int, joints: Sequence[str]) -> None:
        build, m = comp.build, comp.model
        self.comp, self.joints = comp, joints
        self.bodies = sorted({build.carrier[build.mech.joint(j).child] for j in joints})
        self.bid = np.array([m.body(b).id for b in self.bodies])
        self.p2p = [e for e in build.p2p if e.native is None]
        self.tids = np.array([m.tendon(e.element.name).id for e in self.p2p], dtype=int)
        self.sid = np.array([[m.site(f"{e.element.name}:{x}").id for x in "ab"]
                             for e in self.p2p], dtype=int).reshape(-1, 2)
        # rolling by contact: the contact carries what the description's arm and coupling
        # carried, so it counts as transmitted through the joints (contract point 6)
        self.discs = [cl.contact for cl in build.closures if cl.kind == "contact"]
        self.disc_bid = np.array([m.body(build.carrier[g.inner]).id for g in self.discs],
                                 dtype=int)
        N = n_samples
        self.cf = np.empty((N, len(self.bodies), 2))
        self.ext = np.empty((N, len(self.discs), 2))
        self.ten = np.empty((N, len(self.tids), 2))
        self.spos = np.empty((N, len(self.tids), 2, 2))

    def record(self, k: int) -> None:
        d = self.comp.data
        self.cf[k] = d.cfrc_int[self.bid, 3:5]
        if len(self.disc_bid):
            self.ext[k] = d.cfrc_ext[self.disc_bid, 3:5]  # contact force on the disc (world)
        if len(self.tids):
            self.ten[k, :, 0] = d.ten_length[self.tids]
            self.ten[k, :, 1] = d.ten_velocity[self.tids]
            self.spos[k] = d.site_xpos[self.sid][:, :, :2]

    def result(self, t: np.ndarray) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
        build = self.comp.build
        transmitted: dict[str, np.ndarray] = {}
        for name in self.joints:
            joint = build.mech.joint(name)
            inside = set(build.mech.subtree(joint.child))
            r = self.cf[:, self.bodies.index(build.carrier[joint.child])].copy()
            for i, g in enumerate(self.discs):
                if g.inner in inside and g.outer not in inside:
                    r += self.ext[:, i]
            transmitted[name] = r
        pairs = {e.element.name: tension_pair_force(e.element, self.ten[:, i, 0],
                                                    self.ten[:, i, 1], t, self.spos[:, i, 0],
                                                    self.spos[:, i, 1])
                 for i, e in enumerate(self.p2p)}
        return transmitted, pairs


@contextlib.contextmanager
def _callbacks_installed(comp: _Compiled) -> Iterator[None]:
    """Installs the passive callback (and the control callback of prescribed motions,
    when there is one) for a block and restores the previous ones after: MuJoCo's
    callbacks are process-global."""
    import mujoco

    previous = []
    try:
        for get, put, callback in (
                (mujoco.get_mjcb_passive, mujoco.set_mjcb_passive, comp.callback),
                (mujoco.get_mjcb_control, mujoco.set_mjcb_control, comp.control)):
            if callback is not None:
                previous.append((put, get()))
                put(callback)
        yield
    finally:
        for put, callback in reversed(previous):
            put(callback)


#: the engine's own flexible element (contract point 12)
FLEX_1D = "flexcomp_1d"
_FLEX_NAME = "beam"
#: vertex radius, a fraction of l: geometry only (contacts are off); young follows from it
_FLEX_RADIUS_FACTOR = 0.01
#: central-difference step of the linearization, a fraction of l (passive forces are
#: linear in it to ~1e-12; round-off ~1e-10 relative)
_FLEX_FD_STEP = 1e-6


class MujocoBackend(Backend):
    id = "mujoco"
    SETTINGS = {
        "integrator": Setting(
            "RK4", ("Euler", "implicit", "implicitfast", "RK4"),  # orders: `scheme`
            "Replaces MuJoCo's default 'Euler' (semi-implicit, first order: an O(h) phase "
            "error on a pendulum) by 'RK4' (fourth order; the passive callback, hence "
            "every custom and time-dependent force, is evaluated at each stage at the "
            "stage time). Also accepted: Euler, implicit, implicitfast (order 1). With "
            "Euler, MuJoCo integrates joint/tendon damping implicitly (eulerdamp). Engine "
            "default: MuJoCo XML reference, option/integrator: '[Euler, RK4, implicit, "
            "implicitfast], \"Euler\"'.",
            engine_default="Euler"),
        "native_springs": Setting(
            True, bool,
            "true: force laws linear in length/coordinate and rate (no time) use MuJoCo's "
            "own tendon stiffness/springlength/damping and joint "
            "stiffness/springref/damping (exact for the description, free length 0 "
            "included); false: every law goes through the passive callback. Only the "
            "implicit integrators see the difference (they differentiate native damping "
            "but not callback forces, mujoco #2433)."),
        "linearization": Setting(
            "inverseFD", ("inverseFD", "transitionFD"),
            "'inverseFD' (default): continuous-time M, C, K from mjd_inverseFD (finite "
            "differences of mj_inverse), central differences by combining +eps and -eps; "
            "eigenvalues of the first-order system. 'transitionFD': mjd_transitionFD "
            "discrete A on a copy of the model with the Euler integrator when the run "
            "uses RK4 (RK4 is not supported there), mapped with ln(lambda)/dt; carries "
            "the step's own O(h) error."),
        "fd_eps": Setting(
            1e-6, float,
            "Finite-difference step of mjd_inverseFD / mjd_transitionFD."),
        "autoreset": Setting(
            False, bool,
            "false replaces MuJoCo's default (autoreset on), which silently resets the "
            "state to qpos0 when an acceleration is NaN or huge and would show a "
            "divergence as a jump back to the start; off, it shows as NaN/inf. Engine "
            "default: MuJoCo XML reference, option/flag/autoreset '\"enable\"'.",
            engine_default=True),
        "constraint_timeconst_steps": Setting(
            2.0, float,
            "Closure equalities: solref time constant in time steps (solref[0] = steps * "
            "dt) instead of the engine default, a fixed duration of many steps: a "
            "constraint that relaxes that slowly lets the loops open under load (the "
            "out-of-the-box study measures by how much). MuJoCo clamps it to 2 dt unless "
            "refsafe is off, so 2 is the stiffest it takes by default; on the scotch yoke "
            "with RK4 a shorter constant (refsafe off) kept the trajectory but raised the "
            "force error, and a much shorter one was unstable. Engine default: MuJoCo XML "
            "reference, equality/solref '\"0.02 1\"' (seconds: over dt in steps).",
            engine_default=0.02, engine_default_in_seconds=True),
        "constraint_dampratio": Setting(
            1.0, float,
            "solref[1] of the closure equalities (1 = critical; below 1 MuJoCo also "
            "stiffens the constraint, which worsens the errors and, far enough below, "
            "makes RK4 unstable)."),
        "constraint_solimp": Setting(
            [0.9999, 0.9999, 0.001, 0.5, 2.0], list,
            "solimp of the closure equalities instead of the engine default: the "
            "impedance 0.9999 is MuJoCo's ceiling (higher values are clamped), and a "
            "closure force lags the exact one by one minus the impedance (relative), so "
            "every lower impedance lets the loop's force, and with it the trajectory, lag "
            "further. Engine default: MuJoCo XML reference, equality/solimp '\"0.9 0.95 "
            "0.001 0.5 2\"'.",
            engine_default=[0.9, 0.95, 0.001, 0.5, 2.0]),
        "refsafe": Setting(
            True, bool,
            "MuJoCo's default (on): solref time constants below 2 dt are raised to 2 dt. "
            "Off lets constraint_timeconst_steps < 2 act (no gain: see "
            "constraint_timeconst_steps)."),
        "diagexact": Setting(
            True, bool,
            "true (MuJoCo default false): mjENBL_DIAGEXACT, the constraint regularisation "
            "uses the exact diagonal of J M^-1 J^T instead of the body_invweight0 "
            "estimate (taken once, at the reference configuration); with the estimate a "
            "constraint's softness is wrong wherever the true diagonal departs from it, "
            "so the scotch yoke's slot force starts low and its violation grows (the "
            "out-of-the-box study measures by how much). Engine default: MuJoCo XML "
            "reference, option/flag/diagexact '\"disable\"'.",
            engine_default=False),
        "slider_mass_ratio": Setting(
            0.3, float,
            "Mass of each point-on-line slider as a fraction of the largest point mass "
            "its pin body can give up (the rest keeps a positive inertia); it is taken "
            "out of the pin body (exact while the constraint holds). Lighter sliders "
            "pass less inertial force through the soft connect but condition it worse "
            "across rotating slots; the harness's value sits between the two effects, "
            "where the results depend least on it."),
        "massless_mass_ratio": Setting(
            3e-4, float,
            "Substitute mass of a massless body that a constraint or point force loads "
            "(e.g. a massless pin in a slot), times the lightest body's mass; weight "
            "cancelled. Not compensated: it adds inertia, while a lighter one softens "
            "the constraints through it (their stiffness scales with the mass they "
            "move). The harness's value balances the two on the slotted link of Fig. 34, "
            "where both act: heavier or lighter substitutes worsen its trajectory and "
            "frequency errors."),
        "point_mass_gyration": Setting(
            POINT_MASS_GYRATION, float,
            "Radius of gyration (m) of the inertia given to a point mass (central "
            "inertia 0), which MuJoCo rejects below mjMINVAL (MuJoCo API reference, "
            "types: '#define mjMINVAL 1E-15 // minimum value in any denominator'; the "
            "substitute is at least POINT_MASS_INERTIA_FLOOR, above it). The body's "
            "moment about a pivot at d grows by the relative (r/d)^2, and a pendulum's "
            "period by (r/d)^2/2: negligible while r is far below the mechanism's "
            "lengths."),
        "link_mass_ratio": Setting(
            1e-9, float,
            "Substitute mass of a massless kinematic link that cannot be folded (several "
            "child joints, no constraint on it), times the lightest body's mass; its "
            "tree children carry the inertia, so it can be tiny: the trajectory error it "
            "adds shrinks with it (belt arm)."),
        "substitute_gravcomp": Setting(
            True, bool,
            "Cancel the weight of substitute bodies whose mass is not taken from a body "
            "of the description (MuJoCo body gravcomp=1)."),
        "contact_timeconst_steps": Setting(
            2.0, float,
            "RollingContact: solref[0] of the contacts in steps. Engine default: MuJoCo "
            "XML reference, geom/solref '\"0.02 1\"' (seconds: over dt in steps).",
            engine_default=0.02, engine_default_in_seconds=True),
        "contact_dampratio": Setting(
            1.0, float,
            "RollingContact: solref[1] of the contacts."),
        "contact_solimp": Setting(
            [0.9999, 0.9999, 0.001, 0.5, 2.0], list,
            "RollingContact: solimp of the contacts (the engine default lets the "
            "rolling contact slip and lose energy). Engine default: MuJoCo XML "
            "reference, geom/solimp '\"0.9 0.95 0.001 0.5 2\"'.",
            engine_default=[0.9, 0.95, 0.001, 0.5, 2.0]),
        "contact_friction": Setting(
            1.0, float,
            "RollingContact: sliding friction coefficient of the disc."),
        "contact_cone": Setting(
            "pyramidal", ("pyramidal", "elliptic"),
            "RollingContact: MuJoCo friction cone, pyramidal or elliptic."),
        "impratio": Setting(
            1.0, float,
            "RollingContact: MuJoCo impratio (friction-to-normal impedance)."),
        "noslip_iterations": Setting(
            0, int,
            "RollingContact: MuJoCo's noslip post-processing iterations (0 = off, "
            "MuJoCo's default); they remove the regularised friction's creep."),
        "ring_segments": Setting(
            720, int,
            "RollingContact: number of boxes forming the ring."),
        "prescribed_motion": Setting(
            "acceleration", ("acceleration",),
            "Prescribed coordinates: a control callback (set_mjcb_control) imposes the "
            "acceleration through qfrc_applied, solved with mj_solveM at every RK4 stage "
            "at the stage time (q''(t): fourth order with RK4); under Euler, implicit and "
            "implicitfast it imposes the discrete acceleration ((q(t+h) - q)/h - q')/h "
            "with the matrix the step solves (first order in the free coordinates, the "
            "prescribed one on q(t) at every step). The applied force is the actuator "
            "force. MuJoCo has no exact imposed motion: joint equalities with a moving "
            "reference and mocap welds are soft (they lag the reference by their "
            "constraint's relaxation), position actuators lag."),
    }

    ENGINE_MODULES = ('mujoco',)
    #: the Python package bundles the C library of the same version (mj_versionString)
    ENGINE_DISTRIBUTION = "mujoco"

    #: per element kind, what its registered builder makes (mujoco_mjcf)
    EXPRESSIONS = mujoco_mjcf.EXPRESSIONS

    SPATIAL_REASON = ""

    def translation_reason(self, mechanism: Mechanism) -> str:
        if mechanism.spatial:
            # closures become equalities, slides slide joints, point-to-point elements
            # spatial tendons between sites
            return spatial_tree_reason(mechanism, closures=True, slides=True, point_forces=True)
        if all(b.massless for b in mechanism.bodies):
            return "every body is massless (no mass scale for the substitute bodies)"
        return ""

    # --- translation ---------------------------------------------------------------------
    def _build(self, mechanism: Mechanism, settings: dict, dt: float | None = None) -> Build:
        self.check_support(mechanism)
        return translate(mechanism, settings, dt)

    def to_mjcf(self, mechanism: Mechanism, settings: Mapping | None = None,
                dt: float | None = None) -> str:
        """The MJCF text of the translated mechanism (with the integrator and contact
        solver settings, the flags `_Compiled` sets and, when given, the time step), to
        save and load with ``MjModel.from_xml_path``. Laws that need the passive callback
        are not in the file."""
        return self._build(mechanism, self.resolve_settings(settings), dt=dt).xml

    def export(self, mechanism: Mechanism, coordinates: Sequence[str],
               initial_states: Mapping[str, tuple[np.ndarray, np.ndarray]],
               settings: Mapping | None = None, dt: float = 1e-3) -> tuple[str, list[str]]:
        """(MJCF, what the file alone does not reproduce). The file is `to_mjcf`'s, with a
        keyframe per initial state (named after it, in MuJoCo's coordinates) and the map
        from the description's coordinates as custom numerics: ``qpos[mbfidelity_qadr] =
        A q + b`` (``mbfidelity_A`` row-major, ``mbfidelity_b``), the coordinates' names in
        the custom text ``mbfidelity_coordinates``. Force laws the harness applies in the
        passive callback, and prescribed motions it imposes in the control callback, are
        not in the file: they are listed in the second element (empty: the file alone
        moves as the harness's build)."""
        s = self.resolve_settings(settings)
        build = self._build(mechanism, s, dt=dt)
        comp = _Compiled(build, s["integrator"], bool(s["autoreset"]))
        keys = []
        for name, (q, qd) in initial_states.items():
            comp.set_state(np.asarray(q, dtype=float), np.asarray(qd, dtype=float))
            keys.append(f'    <key name="{name}" qpos="{fmt(*comp.data.qpos)}" '
                        f'qvel="{fmt(*comp.data.qvel)}"/>')
        custom = (f'  <custom>\n'
                  f'    <numeric name="mbfidelity_qadr" data="{fmt(*comp.qadr)}"/>\n'
                  f'    <numeric name="mbfidelity_A" data="{fmt(*build.map.A.ravel())}"/>\n'
                  f'    <numeric name="mbfidelity_b" data="{fmt(*build.map.b)}"/>\n'
                  f'    <text name="mbfidelity_coordinates" data="{" ".join(coordinates)}"/>\n'
                  f'  </custom>\n')
        keyframes = "  <keyframe>\n" + "\n".join(keys) + "\n  </keyframe>\n" if keys else ""
        head, tail = build.xml.rsplit("</mujoco>", 1)
        xml = f"{head}{custom}{keyframes}</mujoco>{tail}"
        outside = []
        laws = [e.element.name for e in build.coord + build.p2p if e.native is None]
        if laws:
            outside.append("force laws applied by the harness's passive callback "
                           f"(mjcb_passive): {', '.join(laws)}")
        if comp.control is not None:
            outside.append("prescribed motions imposed by the harness's control callback "
                           f"(mjcb_control): {', '.join(p.name for p in mechanism.prescribed)}")
        return xml, outside

    def stored_inertia(self, mechanism: Mechanism, settings: Mapping | None = None
                       ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """body_inertia and body_iquat of the compiled model (the compiler diagonalises
        fullinertia; the body frame is the description's)."""
        import mujoco

        model = mujoco.MjModel.from_xml_string(self.to_mjcf(mechanism, settings))
        out = {}
        for b in mechanism.bodies:
            bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b.name)
            R = np.empty(9)
            mujoco.mju_quat2Mat(R, model.body_iquat[bid])
            out[b.name] = (np.array(model.body_inertia[bid], dtype=float), R.reshape(3, 3))
        return out

    def scheme(self, mechanism: Mechanism, settings: Mapping | None = None) -> Scheme:
        integrator = str(self.resolve_settings(settings)["integrator"])
        if integrator == "RK4":
            return Scheme("RK4", 4, RK4_STABILITY)
        # Euler, implicit and implicitfast: semi-implicit Euler (implicit in damping only)
        return Scheme(f"semi-implicit Euler ({integrator})", 1, SEMI_IMPLICIT_EULER_STABILITY)

    # --- simulation ----------------------------------------------------------------------
    def _simulate_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                       steps: int, dt: float, cfg: dict,
                       reaction_joints: tuple[str, ...]) -> Samples:
        import mujoco

        comp = self._compiled(mechanism, cfg, dt, q0, qd0)
        m, d = comp.model, comp.data
        # every sample is one row (qpos, qvel), written by one mj_getState call per step
        spec = int(mujoco.mjtState.mjSTATE_QPOS) | int(mujoco.mjtState.mjSTATE_QVEL)
        states = np.empty((steps + 1, mujoco.mj_stateSize(m, spec)))
        step, get_state = mujoco.mj_step, mujoco.mj_getState
        get_state(m, d, states[0], spec)
        with _callbacks_installed(comp):
            with Stopwatch() as clock:
                for row in states[1:]:
                    step(m, d)
                    get_state(m, d, row, spec)
            qpos, qvel = states[:, :m.nq], states[:, m.nq:]
            t = dt * np.arange(steps + 1)
            actuators, forces, violation, transmitted, pairs = self._read_out(
                comp, qpos, qvel, t, reaction_joints)
        cmap = comp.build.map
        q, qd = cmap.coordinates(qpos[:, comp.qadr]), cmap.rates(qvel[:, comp.vadr])
        # a coupling's tendon equality acts in joint space: cfrc_int counts it as
        # transmitted
        couplings = {cl.element.name: forces[cl.element.name] for cl in comp.build.closures
                     if cl.kind == "tendon"}
        # the substitute's own error: each closure's violation at every sample
        return Samples(q, qd, clock, constraint_forces=forces, actuator_forces=actuators,
                       extras={"constraint_violation": violation}, transmitted=transmitted,
                       pair_forces=pairs, coupling_forces=couplings)

    def _bare_loop_impl(self, mechanism: Mechanism, q0: np.ndarray, qd0: np.ndarray,
                        steps: int, dt: float, cfg: dict) -> BareLoop:
        """The model of `simulate`, stepped by one mj_step(nstep=N) call (the passive
        callback installed, as MuJoCo calls it at every stage)."""
        import mujoco

        comp = self._compiled(mechanism, cfg, dt, q0, qd0)
        with _callbacks_installed(comp):
            with Stopwatch() as clock:
                if steps:
                    mujoco.mj_step(comp.model, comp.data, nstep=steps)
        return BareLoop.mapped(clock.cpu, comp.build.map, comp.data.qpos[comp.qadr],
                               comp.data.qvel[comp.vadr])

    def _compiled(self, mechanism: Mechanism, cfg: dict, dt: float, q0: np.ndarray,
                  qd0: np.ndarray) -> _Compiled:
        comp = _Compiled(self._build(mechanism, cfg, dt=dt), cfg["integrator"],
                         bool(cfg["autoreset"]))
        comp.set_state(q0, qd0)
        return comp

    @staticmethod
    def _read_out(comp: _Compiled, qpos: np.ndarray, qvel: np.ndarray, t: np.ndarray,
                  joints: Sequence[str]):
        """One pass over the sampled states, outside the timed loop: mj_forward at each
        sample's time (and mj_rnePostConstraint where reactions or sliders need the
        bodies' accelerations), reading each prescribed coordinate's actuator force (what
        the control callback applies there) and the `_ClosureSamples` and `_Transmitted`."""
        import mujoco

        m, d = comp.model, comp.data
        prescribed = comp.build.mech.prescribed
        actuators = np.empty((len(t), len(prescribed)))
        readers = [r for r in (_ClosureSamples(comp, len(t)) if comp.build.closures else None,
                               _Transmitted(comp, len(t), joints) if joints else None) if r]
        post = bool(joints) or bool(len(comp.slider_jnt))
        d_qpos, d_qvel = d.qpos, d.qvel  # fixed buffers of d (the efc arrays are not)
        forward, post_constraint = mujoco.mj_forward, mujoco.mj_rnePostConstraint
        for k in range(len(t)):
            d_qpos[:] = qpos[k]
            d_qvel[:] = qvel[k]
            d.time = t[k]
            forward(m, d)
            if post:
                post_constraint(m, d)
            actuators[k] = comp.actuator
            for reader in readers:
                reader.record(k)
        forces, violation = readers[0].result() if comp.build.closures else ({}, {})
        transmitted, pairs = readers[-1].result(t) if joints else ({}, {})
        return ({p.name: actuators[:, i] for i, p in enumerate(prescribed)}, forces,
                violation, transmitted, pairs)

    # --- linearization -------------------------------------------------------------------
    @staticmethod
    def _constrained_modes(comp: _Compiled, q_eq: np.ndarray, eps: float):
        """Eigenvalues of the engine's model with its closures as exact constraints:
        with T a basis of the null space of the equality Jacobian J at q_eq and f the
        closure forces that balance the tree there, the reduced matrices are T^T M T,
        T^T C T and T^T (K - d(J^T f)/dq) T, where M, C, K come from mjd_inverseFD with the
        equality constraints disabled."""
        import mujoco

        m, d = comp.model, comp.data
        nv, n = m.nv, comp.build.n
        eq_type = int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        dsbl_eq = int(mujoco.mjtDisableBit.mjDSBL_EQUALITY)

        def jacobian() -> np.ndarray:
            mujoco.mj_forward(m, d)
            return comp.efc_jacobian()[[r for r in range(d.nefc) if d.efc_type[r] == eq_type]]

        comp.set_state(q_eq, np.zeros(n))
        qpos0 = d.qpos.copy()
        d.qvel[:] = 0
        J = jacobian()
        # the static balance of the tree: J^T f = qfrc_bias - qfrc_passive (v = 0, a = 0)
        rhs = d.qfrc_bias - d.qfrc_passive
        load = np.linalg.norm(d.qfrc_bias) + np.linalg.norm(d.qfrc_passive)
        f = np.linalg.lstsq(J.T, rhs, rcond=None)[0]

        def jacobian_at(i: int, h: float) -> np.ndarray:
            dq = np.zeros(nv)
            dq[i] = h
            d.qpos[:] = qpos0
            mujoco.mj_integratePos(m, d.qpos, dq, 1.0)
            return jacobian()

        G = geometric_stiffness(jacobian_at, f, nv, eps)
        d.qpos[:] = qpos0

        def reset() -> None:
            d.qpos[:] = qpos0
            d.qvel[:] = 0

        m.opt.disableflags |= dsbl_eq
        try:
            K, C, M = comp.inverse_fd(reset, eps)
        finally:
            m.opt.disableflags &= ~dsbl_eq
        eig, T, (Mr, Cr, Kr) = constrained_modes(M, C, K - G, J)
        residual = float(np.linalg.norm(J.T @ f - rhs) / max(load, 1e-300))
        return eig, {"M_reduced": Mr, "C_reduced": Cr, "K_reduced": Kr, "basis": T,
                     "closure_forces": f, "balance_residual": residual}

    def linearize(self, mechanism: Mechanism, q_eq: np.ndarray,
                  settings: Mapping | None = None, dt: float = 1e-3) -> Linearization | None:
        import mujoco

        frame = self.linearization_frame(mechanism, settings)
        if frame is None:
            return None
        s, mechanism = frame
        mechanism = coupled(mechanism)  # a contact has no linearization: the exact coupling
        build = self._build(mechanism, s, dt=dt)
        n, eps = build.n, float(s["fd_eps"])
        q_eq = np.asarray(q_eq, dtype=float)
        # MuJoCo refuses both derivative routines on an RK4 model: use an Euler copy (the
        # continuous-time inverse dynamics do not depend on the integrator)
        integrator = s["integrator"] if s["integrator"] != "RK4" else "Euler"
        comp = _Compiled(build, integrator)
        m, d = comp.model, comp.data
        with _callbacks_installed(comp):
            if s["linearization"] == "inverseFD" and build.closures:
                eig, extra = self._constrained_modes(comp, q_eq, eps)
                method = ("mujoco mjd_inverseFD with the equalities off (M, C, K of the tree, "
                          f"central differences, eps={eps:g}) plus the geometric stiffness "
                          "of the closure forces (equality Jacobian efc_J differentiated, "
                          "forces from the static balance J^T f = qfrc_bias - "
                          "qfrc_passive), reduced to the null space of efc_J (exact "
                          "constraints: MuJoCo's soft regularisation is left out)")
            elif s["linearization"] == "inverseFD":
                K, C, M = comp.inverse_fd(lambda: comp.set_state(q_eq, np.zeros(n)), eps)
                K, C, M = (X[np.ix_(comp.vadr, comp.vadr)] for X in (K, C, M))
                eig = quadratic_eigenvalues(M, C, K)
                A = build.map.A  # v = A q + b: in description coordinates, A^T X A
                extra = {"M": A.T @ M @ A, "C": A.T @ C @ A, "K": A.T @ K @ A}
                method = ("mujoco mjd_inverseFD: continuous-time M, C, K (central "
                          f"differences of mj_inverse, eps={eps:g})")
            else:
                comp.set_state(q_eq, np.zeros(n))
                mujoco.mj_forward(m, d)
                Ad = np.zeros((2 * m.nv + m.na, 2 * m.nv + m.na))
                mujoco.mjd_transitionFD(m, d, eps, True, Ad, None, None, None)
                eig = np.log(np.linalg.eigvals(Ad).astype(complex)) / dt
                extra = {"A_discrete": Ad, "integrator": integrator, "discrete_order": 1}
                method = (f"mujoco mjd_transitionFD ({integrator} step, dt={dt:g}, "
                          f"centered, eps={eps:g}), ln(lambda)/dt")
        if build.closures and s["linearization"] == "transitionFD":
            method += ("; soft closures: the spectrum includes the constraints' own fast "
                       "modes (time constant solref) and the substitute bodies' dofs")
        # order by imaginary then real part: real parts of undamped modes are FD noise
        eig = eig[np.lexsort((eig.real, eig.imag))]
        return Linearization(eigenvalues=eig, method=method, extra=extra)


    # --- flexible elements (contract point 12) ----------------------------------------------
    BEAM_ELEMENTS = {
        FLEX_1D: BeamElement(
            Expression(SUBSTITUTE, "a 1-D flexcomp with <elasticity young=EI/(pi r^4/4)>: a "
                                   "discrete elastic rod (bending from the angle between "
                                   "consecutive edges, vertex masses lumped) in place of a "
                                   "beam element; pinned end vertices. Its frequencies are "
                                   "those of the central-difference beam, below "
                                   "Euler-Bernoulli's by about (n pi)^2 / (12 N^2); no "
                                   "eigenvalue facility works on it (mjd_transitionFD "
                                   "gave nonsense), so they come from free-vibration fits",
                       reason="discrete elastic rod with lumped masses: second order in N"),
            order=2, limit="Euler-Bernoulli"),
    }

    def beam_frequencies(self, beam: Beam, kind: str, elements: int, count: int = 3,
                         settings: Mapping | None = None) -> BeamModes:
        """N flex edges along x (vertices i l / N, the end vertices pinned; gravity and
        contacts off), the point mass added to the vertex at x = a (in the MjSpec, then
        recompiled: raising ``body_mass`` of the compiled model left MuJoCo's mass matrix
        unchanged, measured). MuJoCo spreads a flexcomp's mass equally over all N + 1
        vertices, pinned ones included, so the flexcomp gets rho l (N + 1) / N and each
        moving vertex carries rho l / N.

        Frequencies by free-vibration fits (`base.semi_implicit_euler_modes`): each mode is
        released alone, from the mode shape of the engine's own elastic forces (central
        differences of ``qfrc_passive`` in the vertices' y coordinates with MuJoCo's mass
        matrix: the engine's linearization, kept as a cross-check), at the amplitude
        `RELEASE_AMPLITUDE` l, and integrated with MuJoCo's Euler (semi-implicit; its
        implicit integrators do not run flex). The fit's own error (`resolution`, its
        distance to the linearization, which bounds it, is reported with each frequency; the
        linear prediction's residual is at round-off of the record, so most of that
        distance is the linearization's own round-off."""
        self.check_beam_request(beam, kind, elements, settings,
                                "the flex route (its integrator and step are fixed)")
        import mujoco

        N, l = elements, beam.length
        radius = _FLEX_RADIUS_FACTOR * l
        young = beam.EI / (math.pi * radius**4 / 4)
        xml = (
            "<mujoco><option timestep=\"1e-5\" integrator=\"Euler\" gravity=\"0 0 0\">"
            "<flag contact=\"disable\"/></option><worldbody>"
            f"<flexcomp name=\"{_FLEX_NAME}\" type=\"grid\" count=\"{N + 1} 1 1\" "
            f"spacing=\"{l / N!r} 1 1\" dim=\"1\" radius=\"{radius!r}\" "
            f"mass=\"{beam.rho * l * (N + 1) / N!r}\">"
            f"<elasticity young=\"{young!r}\" poisson=\"0\" damping=\"0\"/>"
            f"<pin id=\"0 {N}\"/></flexcomp></worldbody></mujoco>")
        spec = mujoco.MjSpec.from_string(xml)
        model = spec.compile()
        if beam.point_mass > 0:
            vertex = spec.body(f"{_FLEX_NAME}_{beam.node_of_point_mass(N)}")
            vertex.mass = vertex.mass + beam.point_mass
            model = spec.compile()
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        M = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, M)

        def passive(q: np.ndarray) -> np.ndarray:
            data.qpos[:] = q  # slide and hinge joints: qpos j is dof j
            mujoco.mj_forward(model, data)
            return data.qfrc_passive

        # the engine's linearization: K = -d qfrc_passive / dq by central differences
        K = stiffness_by_central_differences(passive, data.qpos.copy(), _FLEX_FD_STEP * l)
        y = [int(model.jnt_dofadr[j]) for j in range(model.njnt)
             if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE
             and np.allclose(model.jnt_axis[j], (0.0, 1.0, 0.0))]

        def release(shape: np.ndarray) -> None:
            mujoco.mj_resetData(model, data)
            data.qpos[y] = shape

        fit = semi_implicit_euler_modes(
            M, K, y, count, RELEASE_AMPLITUDE * l,
            lambda dt: setattr(model.opt, "timestep", dt), release,
            lambda: mujoco.mj_step(model, data), lambda: data.qpos[y])
        return BeamModes(
            fit.frequency_hz,
            "mujoco free-vibration fit: single-mode release, semi-implicit Euler, linear "
            "prediction of the modal coordinate, Euler's dispersion inverted",
            fit.resolution,
            {"timestep": fit.step, "omega_max_dt": RELEASE_OMEGA_DT,
             "periods": RELEASE_PERIODS, "amplitude": RELEASE_AMPLITUDE * l, "young": young,
             "radius": radius, "linearized_hz": fit.linearized_hz,
             "uncorrected_fit_hz": fit.uncorrected_hz, "cpu_time": fit.cpu_time})


BACKEND = MujocoBackend()
