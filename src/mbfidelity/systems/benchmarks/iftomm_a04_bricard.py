"""IFToMM benchmark A04: Bricard's mechanism, an over-constrained spatial loop of five
rods and six hinges that moves although Grübler's count gives it no freedom.

Specification (problem A04 of the benchmark library of the Laboratorio de Ingeniería
Mecánica, University of A Coruña, lim.ii.udc.es/mbsbenchmark, dist/A04/
A04_specification.xml; González, Dopico, Lugrís, Cuadrado, Multibody System Dynamics
16:179-190, 2006; Bricard, Journal de Mathématiques pures et appliquées 3:113-148, 1897;
restated with body frames in RehabEngGroup/MBSbenchmarksInOpenSim,
src/A04-BricardsMechanism and help/benchmarks/A04_BricardsMechanism.rst): five uniform
rods of 1 kg and 1 m with a square section of 0.1 m, six revolute joints, gravity
9.81 m/s^2 along -y, released at rest in the position below, 10 s; the published quantity
is the time history of the point P3 (the hinge between rods 2 and 3).

Geometry (the initial position: the loop runs along six edges of a cube of side L; each
hinge axis is perpendicular to both rods it joins)::

    hinge  position        axis   joins
    O1     (0, 0, 0)       y      ground - rod 1 (along x)
    P2     (L, 0, 0)       z      rod 1 - rod 2 (along -y)
    P3     (L, -L, 0)      x      rod 2 - rod 3 (along z)
    P4     (L, -L, L)      y      rod 3 - rod 4 (along -x)
    P5     (0, -L, L)      z      rod 4 - rod 5 (along y)
    O6     (0, 0, L)       x      rod 5 - ground

Coordinates: the hinge angles q1..q5 of the tree ground - rod 1 - ... - rod 5 (zero in the
initial position, body frames parallel to the world's there); the sixth hinge closes the
loop (`HingeClosure`: five equations, the point and the axis). Grübler's count is
5 - 5 = 0; the geometry (all six links of length L with their two axes perpendicular, no
offsets: Bricard's linkage) makes one of the five closure equations follow from the
others along the whole motion (`redundant = 1`), so the constraint Jacobian has rank 4
and the mechanism one degree of freedom. Why the rank stays 4: the motion is a single
smooth curve of configurations (one degree of freedom everywhere on it, the linkage's
own mobility, not a crossing of branches), and with five coordinates the rank is five
less that mobility; the numeric model checks it at every configuration it assembles.
A rotation of the cube by a third of a turn about its diagonal maps each hinge on the one
two further along, so the motion keeps q1 = q3 = q5 and q2 = q4; q1 is the independent
coordinate (the loop hangs at q1 = pi/2, q2 = -pi/6).

What the sources publish. The benchmark gives P3's trajectory as a reference solution
file whose numbers the papers show only as a figure (the OpenSim port plots its result
over it); no number of it is restated here. What has a closed form is compared instead:
no force does work but gravity, so the total energy stays at its initial value, the
potential of the five rods at rest, -3 m g L (centres of mass at heights 0, -L/2, -L,
-L, -L/2). The benchmark's own error measure is P3's position over the run.

Rods: each a uniform square prism of side a about its axis, central inertia m a^2 / 6
about its length and m (L^2 + a^2) / 12 across it.
"""
import sympy as sp

from .. import BenchmarkError, Expectation, PointOutput, Published, System
from ..model import Body, HingeClosure, Mechanism, Parameter, Revolute, Scenario, Segment

SOURCE = ("IFToMM benchmark A04 (González et al., Multibody System Dynamics 16, 2006); "
          "closed form: conservation of energy from rest")

PARAMETERS = (
    Parameter("L", 1.0, "m", "length of each rod (the cube's side)", "IFToMM A04"),
    Parameter("m", 1.0, "kg", "mass of each rod", "IFToMM A04"),
    Parameter("a", 0.1, "m", "side of the rods' square section", "IFToMM A04"),
)

#: rod name, direction along the rod from its first hinge to its second (initial position)
_RODS = (("rod1", (1, 0, 0)), ("rod2", (0, -1, 0)), ("rod3", (0, 0, 1)),
         ("rod4", (-1, 0, 0)), ("rod5", (0, 1, 0)))
#: hinge axes (world axes, initial position) O1, P2, P3, P4, P5; O6's is x
_AXES = ((0, 1, 0), (0, 0, 1), (1, 0, 0), (0, 1, 0), (0, 0, 1))


def _rod(name, direction, P) -> Body:
    along = [sp.Rational(1, 12) * P.m * (P.L**2 + P.a**2)] * 3
    along[[abs(c) for c in direction].index(1)] = P.m * P.a**2 / 6
    tensor = tuple(tuple(along[i] if i == j else 0 for j in range(3)) for i in range(3))
    half = tuple(P.L * c / 2 for c in direction)
    back = tuple(-c for c in half)
    return Body.spatial(name, P.m, tensor, (Segment(back, half, width=P.a),))


def build(P) -> Mechanism:
    bodies = tuple(_rod(name, d, P) for name, d in _RODS)
    joints = []
    parent, parent_anchor = "world", (0, 0, 0)
    for k, ((name, d), axis) in enumerate(zip(_RODS, _AXES), start=1):
        half = tuple(P.L * c / 2 for c in d)
        joints.append(Revolute(f"J{k}", parent, name, f"q{k}", axis=axis,
                               parent_anchor=parent_anchor,
                               child_anchor=tuple(-c for c in half)))
        parent, parent_anchor = name, half
    closure = HingeClosure("O6", "rod5", parent_anchor, "world", (0, 0, P.L),
                           axis_a=(1, 0, 0), axis_b=(1, 0, 0))
    return Mechanism(bodies=bodies, joints=tuple(joints), constraints=(closure,),
                     independent=("q1",), redundant=1,
                     # SymPy's simplify of a five-deep chain of spatial rotations does
                     # not return in useful time: the derivation keeps its exact
                     # unsimplified expressions (lambdify's subexpression elimination)
                     simplify=False)


def _initial_energy(values) -> float:
    """T + V at the release: at rest, the rods' centres at heights 0, -L/2, -L, -L, -L/2."""
    return -3 * values["m"] * values["g"] * values["L"]


def published(P):
    return (Published("energy", 10.0, _initial_energy, SOURCE, kind="energy",
                      note="exact: no force but gravity does work, so T + V keeps its "
                           "value at the release"),)


#: why the closing hinge's force cannot be judged on an engine that reports it NaN
STATICALLY_INDETERMINATE = (
    "the closing hinge's force is not determined by the motion: one of the loop's closure "
    "equations follows from the others, so a self-stress of the loop can be added to the "
    "force without changing any acceleration (the reference reports the least-norm "
    "multipliers, a choice); MuJoCo's soft equalities split it by their regularisation, "
    "so it reports the force as NaN")


#: the specification's measure of a solution's error: its reference solution is the time
#: history of P3's position; every sample of the run counts here
ERROR = BenchmarkError(
    ("P3.x", "P3.y", "P3.z"), "run", "m",
    "IFToMM benchmark A04 specification (lim.ii.udc.es/mbsbenchmark, dist/A04): the time "
    "history of P3's position",
    "largest |P3 - P3_ref| component over the run")

SYSTEM = System(
    id="iftomm_a04_bricard",
    title="IFToMM A04: Bricard's mechanism (over-constrained spatial loop)",
    source="IFToMM benchmark A04 (González et al. 2006); Bricard 1897",
    parameters=PARAMETERS,
    build=build,
    operating_point=lambda P: {"q1": 0.0},
    scenarios=(
        Scenario("published", {"q1": 0.0}, t_end=10.0, checks=("trajectory",),
                 description="the benchmark: released at rest in the cube position, 10 s"),
    ),
    published=published,
    benchmark_error=ERROR,
    expectations=(Expectation("mujoco", "*.constraint_O6", "xfail", STATICALLY_INDETERMINATE),),
    points=lambda P: (PointOutput("P3", "rod2", (0, -P.L / 2, 0),
                                  "the hinge of rods 2 and 3: the published trajectory"),),
)
