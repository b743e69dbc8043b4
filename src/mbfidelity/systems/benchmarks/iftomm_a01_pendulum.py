"""IFToMM benchmark A01: the simple pendulum, a point mass on a massless rigid bar.

Specification (González, Dopico, Lugrís, Cuadrado, Multibody System Dynamics 16:179-190,
2006, problem A01 of the benchmark library of the Laboratorio de Ingeniería Mecánica,
University of A Coruña; restated in the OpenSim port RehabEngGroup/MBSbenchmarksInOpenSim,
help/benchmarks/A01_SimplePendulum.rst, and in Exudyn's example
pendulumIftommBenchmark.py): a point P1 of mass 1 kg on a massless bar of 1 m hinged to
the ground, gravity 9.81 m/s^2 along -y, released at rest with the bar horizontal, 10 s.
The published quantity is P1's position (x, y).

Geometry (phi from the downward vertical, counter-clockwise positive)::

        O  (pivot, world origin)
         \\
          \\  massless bar, length L
           P1  point mass m

P1 = L (sin phi, -cos phi). The benchmark's own angle is measured from the other side
(P1 starts at x = -1 m in the OpenSim port); released from the horizontal at rest, the
motion is the same up to the mirror x -> -x, which leaves y and the period unchanged.
Here P1 starts at x = +L (phi = pi/2).

The body is the point mass itself: mass m, central inertia 0 (model convention 2), its
frame's y axis along P1 -> O so that the pivot is its body point (0, L). Its motion from
rest at phi0 has the closed form sin(phi/2) = k sn(K(k) - w t, k), k = sin(phi0/2),
w = sqrt(g/L), with period 4 K(k) / w (Jacobi's elliptic functions, parameter k^2):
`published` compares the reference with both.
"""
import math

import sympy as sp

from .. import BenchmarkError, Expectation, PointOutput, Published, System
from ..model import Body, Mechanism, Parameter, Revolute, Scenario, Segment

SOURCE = ("IFToMM benchmark A01 (González et al., Multibody System Dynamics 16, 2006); "
          "closed form: Jacobi's elliptic functions")

CLOSED_FORM = "exact (Jacobi's elliptic functions, SciPy's ellipk and ellipj to round-off)"

PARAMETERS = (
    Parameter("m", 1.0, "kg", "mass of the point P1", "IFToMM A01"),
    Parameter("L", 1.0, "m", "length of the massless bar", "IFToMM A01"),
    Parameter("phi0", math.pi / 2, "rad", "initial angle from the downward vertical, "
              "released from rest (the benchmark: horizontal, pi/2)", "IFToMM A01",
              domain="real"),
)


def build(P) -> Mechanism:
    bob = Body("bob", P.m, 0, (Segment((0, 0), (0, P.L), width=0.01),))
    pivot = Revolute("pivot", "world", "bob", "phi", child_anchor=(0, P.L))
    return Mechanism(bodies=(bob,), joints=(pivot,))


def _swings(values) -> None:
    """The closed form is that of a swing: gravity down and a start below the top."""
    if not (values["g"] > 0 and abs(values["phi0"]) < math.pi):
        raise ValueError("the closed form holds for g > 0 and |phi0| < pi (a swing)")


def _closed_form_phi(values, t: float) -> float:
    """phi(t) from rest at phi0 (sin(phi/2) = k sn(K - w t | k^2))."""
    from scipy.special import ellipj, ellipk

    _swings(values)
    k = math.sin(values["phi0"] / 2)
    w = math.sqrt(values["g"] / values["L"])
    sn, _, _, _ = ellipj(ellipk(k * k) - w * t, k * k)
    return 2 * math.asin(k * sn)


def _period(values) -> float:
    from scipy.special import ellipk

    _swings(values)
    k = math.sin(values["phi0"] / 2)
    return 4 * math.sqrt(values["L"] / values["g"]) * float(ellipk(k * k))


def published(P):
    phi = sp.Symbol("phi", real=True)
    return (
        Published("period", None, _period, SOURCE, kind="period", coordinate="phi",
                  note=CLOSED_FORM),
        Published("P1.x", 10.0, lambda v: v["L"] * math.sin(_closed_form_phi(v, 10.0)),
                  SOURCE, expression=P.L * sp.sin(phi), note=CLOSED_FORM),
        Published("P1.y", 10.0, lambda v: -v["L"] * math.cos(_closed_form_phi(v, 10.0)),
                  SOURCE, expression=-P.L * sp.cos(phi), note=CLOSED_FORM),
    )


#: the specification's measure of a solution's error: its reference solution is the time
#: history of P1's x and y, and it grades a solution by their largest error over the run
#: (1e-1 m low, 1e-3 m high precision). The specification compares a fixed number of
#: output steps; every sample of the run counts here, which bounds the value at any subset
ERROR = BenchmarkError(
    ("P1.x", "P1.y"), "run", "m",
    "IFToMM benchmark A01 specification (lim.ii.udc.es/mbsbenchmark, dist/A01): the time "
    "history of P1's x and y; high precision 1e-3",
    "largest |P1 - P1_ref| component over the run")

SYSTEM = System(
    id="iftomm_a01_pendulum",
    title="IFToMM A01: simple pendulum (point mass on a massless bar)",
    source="IFToMM benchmark A01 (González et al. 2006)",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"phi": 0},
    scenarios=(
        Scenario("published", {"phi": "phi0"}, t_end=10.0, checks=("trajectory", "reaction"),
                 description="the benchmark: released from the horizontal at rest, 10 s"),
    ),
    reaction_joints=("pivot",),
    published=published,
    benchmark_error=ERROR,
    points=lambda P: (PointOutput("P1", "bob", (0, 0), "the point mass: the published "
                                  "trajectory"),),
    expectations=tuple(
        Expectation(engine, "convergence.order", "unresolved",
                    "a fourth-order scheme resolves the swing to the reference's own error "
                    "within the study's default steps: fewer than three steps lower the "
                    "error before it meets that floor, too few to fit an order")
        for engine in ("mujoco", "exudyn")),
)
