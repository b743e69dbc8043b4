"""Disc rolling inside an oscillating circular track (monograph §9.8 example 3, Fig. 39,
eq. 110 and the equations and matrices after it).

Geometry (pinned by the project: the figure is not in the monograph's text)::

      O (world origin): the track's pivot, on the track's rim
      +------------- C = (R cos theta, -R sin theta)   theta turns the track CLOCKWISE
      |           .  |  .
      |        .     |     .      track: circle of radius R about C (m_p, I_p), its
      |      .       G       .    centre of mass G = C + e (-sin theta, -cos theta),
      |      .        \\      .    i.e. e from C perpendicular to OC (depth R sin + e cos)
      |       .        D     .    massless arm CD, ABSOLUTE angle phi from the downward
      |         .     (d)  .      vertical: D = C + (R - r)(sin phi, -cos phi)
      |            .  J .         disc (m_d, I_d, radius r) pinned at D, spin psi relative
                                  to the arm; it touches the track at J = C + R (sin, -cos)

Bodies and joints: world -(theta, clockwise)-> track -(phi, absolute)-> arm -(psi)-> disc.
The track frame's origin is G; O and C are the track points (-R, e) and (0, e) of that
frame, so that at theta = 0 the track frame is aligned with the world.

Rolling without slipping, derived (not assumed). With u = (sin phi, -cos phi) (C to D to
J) and t = (cos phi, sin phi) = k x u, the track turns at -theta', the arm at phi', the disc
at phi' + psi'. The velocity of the disc's material point at J minus the track's is

    v_slip = [ (R - r) phi' + r (phi' + psi') - R (-theta') ] t = (R theta' + R phi' + r psi') t,

so the rolling constraint is the LinearCoupling Phi = R theta + R phi + r psi = 0 (metres
of slip; psi = -R (theta + phi) / r). The disc spins absolutely at
-(R theta' + (R - r) phi') / r, not at phi' as the printed E_c assumes (see the hand
facts for the consequences: E_c, M and both printed equations of motion are misprints).

Passive resistances (printed P_nc of eq. 110): c_O theta'^2 and c_J (theta' + phi')^2,
theta' + phi' being the turning rate of CD relative to the track. The c_J moment is put
on the disc's hub D, between the arm and the disc: a viscous torque c_J (r/R)^2 psi' there
dissipates exactly c_J (theta' + phi')^2 because psi' = -(R/r)(theta' + phi'). (A torque
between the track and the arm cannot be written on one coordinate with phi absolute; the
hub is the only placement a one-coordinate element can take.)

Contact forces at J:
- friction: the coupling's generalized force -Phi_q^T lambda is the virtual power of a
  tangential force -lambda t on the disc at J and +lambda t on the track at J, so the
  friction force of the track on the disc is f t with f = -lambda (N). The analytic layer
  and the engines report the coupling's force as -lambda = f. With the c_J couple at the
  hub (this model), the massless arm also carries a transverse force; for a rolling-
  resistance couple acting between the track and the disc instead (same motion), the
  friction would be f - c_J r (theta' + phi') / (R (R - r)).
- normal force: the massless arm CD holds the disc centre at R - r from C; in this model
  it takes the place of the normal contact force (its line of action C-D-J is the normal
  at J). N = -u . F_hub, with F_hub the force the arm exerts on the disc at D (positive N:
  the track presses the disc towards C). Equivalently, by Newton on the disc,
  N = -u . m_d (a_D - g_vec). Rolling needs N > 0 and a friction coefficient of at
  least |f|/N: a release from rest far up the track (phi = 1.5 rad with theta = 0.3)
  drives N negative, which is why the large scenario starts at phi = 1.2 rad.

Driving torque T_m(t) of eq. 110: modelled as T_m sin(Omega t) on theta; T_m = 0 by default,
Omega is a parameter not in the monograph, needed only to give the torque
input a frequency (H(omega) of the monograph is the linear response to it).

Printed formulas coded below: E_c and E_p of eq. 110, both equations of motion as
printed, the equilibrium (theta, phi) = (0, 0) under the printed relation
M0 = (m_p + m_d) g R, and M, K, C at that equilibrium. P_nc, the generalized forces
Q_theta, Q_phi and the intermediate derivatives of E_c and E_p are printed too; P_nc is
compared directly (kind "dissipation_power", motor on), Q_theta and Q_phi through C and the
equations of motion;
the intermediate dE_c/dtheta' prints (R + e)^2 where E_c has R^2 + e^2 (the same slip
reaches equation 1). The matrix equation with e(t) = {T_m, 0} repeats M, C, K.
"""
import sympy as sp

from . import (Condition, ContactOutput, PrintedFormula, System, Variant,
               coordinate_symbols)
from .model import (COORD, COORD_RATE, TIME, Body, Circle, CoordinateForce, LinearCoupling,
                    Mechanism, Parameter, Revolute, RollingContact, Scenario, Segment)

PARAMETERS = (
    Parameter("m_p", 4.0, "kg", "mass of the track", "Fig. 39"),
    Parameter("I_p", 0.5, "kg m^2", "central moment of inertia of the track", "project default"),
    Parameter("R", 0.5, "m", "radius of the track (= distance OC)", "project default"),
    Parameter("e", 0.1, "m", "offset of the track's centre of mass from C, perpendicular to OC",
              "project default"),
    Parameter("m_d", 1.0, "kg", "mass of the disc", "project default"),
    Parameter("r", 0.1, "m", "radius of the disc", "project default"),
    Parameter("I_d", "m_d*r**2/2", "kg m^2",
              "central moment of inertia of the disc (default: uniform disc, m_d r^2/2)",
              "project default"),
    Parameter("k_t", 50.0, "N m/rad", "torsional spring constant on theta", "project default"),
    Parameter("M0", "(m_p + m_d)*g*R", "N m",
              "spring moment at theta = 0, against theta (default: (m_p + m_d) g R, so that "
              "theta = 0 is the equilibrium)", "Fig. 39", domain="real"),
    Parameter("c_O", 0.5, "N m s", "viscous moment at the pivot O, on theta'",
              "project default", domain="nonnegative"),
    Parameter("c_J", 0.05, "N m s", "viscous rolling resistance on theta' + phi'",
              "project default", domain="nonnegative"),
    Parameter("T_m", 0.0, "N m", "amplitude of the motor torque T_m(t) = T_m sin(Omega t)",
              "project default (T_m(t) = 0)", domain="real"),
    Parameter("Omega", 5.0, "rad/s", "angular frequency of the motor torque (not in the "
              "catalog: only used when T_m is not 0)", "chosen here"),
)


def _no_slip(P):
    """Phi = R theta + R phi + r psi: metres of slip at J (module docstring)."""
    return ("theta", P.R), ("phi", P.R), ("psi", P.r)


def build(P) -> Mechanism:
    track = Body("track", P.m_p, P.I_p, (Circle((0, P.e), P.R), Segment((-P.R, P.e), (0, P.e))))
    arm = Body("arm", 0, 0, (Segment((0, 0), (0, -(P.R - P.r))),))
    disc = Body("disc", P.m_d, P.I_d, (Circle((0, 0), P.r),))
    return Mechanism(
        bodies=(track, arm, disc),
        joints=(
            Revolute("pivot", "world", "track", "theta", child_anchor=(-P.R, P.e),
                     clockwise=True),
            Revolute("centre", "track", "arm", "phi", parent_anchor=(0, P.e), absolute=True),
            Revolute("hub", "arm", "disc", "psi", parent_anchor=(0, -(P.R - P.r))),
        ),
        constraints=(LinearCoupling("rolling", _no_slip(P)),),
        independent=("theta", "phi"),
        forces=(
            CoordinateForce("torsion_spring", "theta", -(P.M0 + P.k_t * COORD),
                            potential=P.M0 * COORD + P.k_t * COORD**2 / 2),
            CoordinateForce("pivot_friction", "theta", -P.c_O * COORD_RATE,
                            dissipation=P.c_O * COORD_RATE**2 / 2),
            # psi' = -(R/r)(theta' + phi'): this dissipates c_J (theta' + phi')^2
            CoordinateForce("rolling_resistance", "psi", -P.c_J * (P.r / P.R) ** 2 * COORD_RATE,
                            dissipation=P.c_J * (P.r / P.R) ** 2 * COORD_RATE**2 / 2),
            CoordinateForce("motor", "theta", P.T_m * sp.sin(P.Omega * TIME)),
        ),
    )


def printed(P):
    th, th_d, th_dd = coordinate_symbols("theta")
    ph, ph_d, ph_dd = coordinate_symbols("phi")
    m_p, I_p, R, e, m_d, r, I_d = P.m_p, P.I_p, P.R, P.e, P.m_d, P.r, P.I_d
    g, k_t, M0, c_O, c_J = P.g, P.k_t, P.M0, P.c_O, P.c_J
    T_m = P.T_m * sp.sin(P.Omega * TIME)
    balance = {"M0": (m_p + m_d) * g * R}  # printed after the equilibrium conditions
    note = "at q_eq = (0, 0), with M0 = (m_p + m_d) g R as printed"
    return (
        PrintedFormula("Fig. 39, eq. 110, E_c", "kinetic_energy",
                       (I_p + m_p * (R**2 + e**2) + m_d * R**2) * th_d**2 / 2
                       + (I_d + m_d * (R - r) ** 2) * ph_d**2 / 2
                       + (-2 * m_d * (R - r) * R * sp.sin(th + ph) * th_d * ph_d) / 2),
        PrintedFormula("Fig. 39, eq. 110, E_p", "potential_energy",
                       -m_p * g * (R * sp.sin(th) + e * sp.cos(th))
                       - m_d * g * (R * sp.sin(th) + (R - r) * sp.cos(ph))
                       + M0 * th + k_t * th**2 / 2),
        PrintedFormula("Fig. 39, equations of motion (after eq. 110)", "eom", [
            (I_p + m_p * (R + e) ** 2 + m_d * R**2) * th_dd
            - m_d * (R - r) * R * (sp.sin(th + ph) * ph_dd + sp.cos(th + ph) * ph_d**2)
            - m_p * g * (R * sp.cos(th) - e * sp.sin(th)) - m_d * g * R * sp.cos(th)
            + M0 + k_t * th + c_O * th_d + c_J * (th_d + ph_d) - T_m,
            (I_d + m_d * (R - r) ** 2) * th_dd
            - m_d * (R - r) * R * (sp.sin(th + ph) * th_dd + sp.cos(th + ph) * th_d**2)
            + m_d * g * (R - r) * sp.sin(ph) + c_J * (th_d + ph_d),
        ]),
        # printed with the motor's power T_m(t) theta'; the motor is switched on (T_m =
        # 1.5 N m) so that its term is tested too
        PrintedFormula("Fig. 39, eq. 110, P_nc", "dissipation_power",
                       (-c_O * th_d) * th_d + (-c_J * (th_d + ph_d)) * (th_d + ph_d)
                       + T_m * th_d, relations={"T_m": 1.5},
                       note="motor on (T_m = 1.5 N m) so that its power is compared"),
        PrintedFormula("Fig. 39, equilibrium (theta, phi) = (0, 0)", "equilibrium",
                       {"theta": 0, "phi": 0}, relations=balance,
                       note="phi_eq = 0 from dE_p/dphi; theta_eq = 0 with M0 = (m_p + m_d) g R"),
        PrintedFormula("Fig. 39, matrix M", "M", sp.Matrix([
            [I_p + m_p * (R**2 + e**2) + m_d * R**2, 0],
            [0, I_d + m_d * (R - r) ** 2]]), relations=balance, note=note),
        PrintedFormula("Fig. 39, matrix K", "K", sp.Matrix([
            [m_p * g * R + k_t, 0],
            [0, m_d * g * (R - r)]]), relations=balance, note=note),
        PrintedFormula("Fig. 39, matrix C", "C", sp.Matrix([
            [c_O + c_J, c_J],
            [c_J, c_J]]), relations=balance, note=note),
    )


def contacts(P):
    ph = coordinate_symbols("phi")[0]
    return (
        ContactOutput("normal", "reaction:hub", (-sp.sin(ph), sp.cos(ph)),
                      description="normal force of the track on the disc at J, towards C "
                                  "(carried by the massless arm CD)"),
        ContactOutput("friction", "constraint:rolling", None, unilateral=False,
                      description="friction force of the track on the disc at J along "
                                  "t = (cos phi, sin phi): the rolling coupling's -lambda"),
    )


_CHECKS = ("trajectory", "constraint_force")

SYSTEM = System(
    id="rolling_disc_track",
    title="Disc rolling inside an oscillating circular track",
    source="monograph §9.8 example 3, Fig. 39, eq. 110",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"theta": 0, "phi": 0, "psi": 0},
    printed=printed,
    contacts=contacts,
    validity=(Condition("r < R", "the disc must fit inside the track"),),
    scenarios=(
        Scenario("small", {"theta": 0.05, "phi": 0.1}, checks=_CHECKS,
                 description="near the equilibrium (0, 0): theta = 0.05, phi = 0.1 rad, from rest"),
        Scenario("large", {"theta": -0.3, "phi": 1.2}, checks=_CHECKS,
                 description="the disc released 1.2 rad up the track, theta = -0.3 rad (the "
                             "normal force stays positive, |friction|/N < 0.7)"),
        Scenario("undamped", {"theta": 0.0, "phi": 1.0}, checks=_CHECKS,
                 overrides={"c_O": 0.0, "c_J": 0.0},
                 description="no passive resistances (energy conserved; the friction is then "
                             "unambiguous), disc released 1 rad up the track"),
        Scenario("forced", {}, checks=_CHECKS, overrides={"T_m": 2.0, "Omega": 5.0},
                 description="from rest at the equilibrium, motor torque 2 sin(5 t) N m"),
    ),
    notes="The printed E_c takes the disc's spin as phi'; rolling gives "
          "-(R theta' + (R - r) phi')/r (see the module docstring).",
    variants=(
        Variant("contact", {e: {} for e in ("mujoco", "pybullet", "pymunk")},
                description="rolling by friction contact (friction coefficient 1): the disc "
                            "touches a ring of boxes (MuJoCo, PyBullet) or segments (Pymunk); "
                            "the arm becomes a free radial slider, so the contact carries the "
                            "normal force",
                reason="friction contact is regularised (soft normal and tangential "
                       "response with a time constant of a few steps) on a faceted ring: "
                       "the normal force chatters from facet to facet, the disc creeps "
                       "(micro-slip) and the contact dissipates; the description's gates are "
                       "those of an ideal rolling constraint",
                constraints=lambda P: (RollingContact(
                    "rolling", disc="disc", arm="arm", track="track", disc_radius=P.r,
                    track_radius=P.R,
                    coefficients=_no_slip(P)),)),
    ),
)
