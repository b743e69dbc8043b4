"""The engine-neutral numeric plan of a mechanism, written once for every backend.

A backend receives a numeric `Mechanism` (parameters substituted) and translates it into
its engine. What that translation needs before any engine enters is the same for all of
them and lives here:

- numbers from description entries (`num`), planar rotations (`rot`);
- the element kinds of the description (`ELEMENT_KINDS`, `elements`): the vocabulary in
  which each backend declares how exactly it expresses an element (`base.Expression`);
- the checks that a description can be translated at all (`description_reason`: every
  entry numeric, no zero axis, slot direction or coupling);
- the force laws, compiled once, with their classification (`ForceLaw`): linear (a
  spring of stiffness -b and free length -a/b, a damper of coefficient c, or a constant
  force, ``a + b x + c x'`` with no TIME) or custom; the coordinate laws' generalized
  force, as an engine's force callback evaluates it (`CoordinateLaws`);
- the prescribed motions (`Motion`, `motions`) and the start state they impose
  (`driven_start`);
- the map between the description coordinates q and the engine joint values v
  (`CoordinateMap`): every engine joint is relative (v = theta_child - theta_parent -
  angle_offset for a hinge, the slide along the unit axis for a prismatic joint), so
  ``v = A q + b`` with the inverse ``q = T v + c``, and the body angles are affine in
  both; a coordinate law whose argument is one engine joint value can sit on that joint
  (`CoordinateMap.law_target`);
- the planar kinematics: the bodies' frames from q (`body_states`) and q from the
  frames (`joint_coordinates`), and the force elements' loads on the bodies
  (`element_loads`), on numbers, on arrays of samples, or on symbols, which `traced`
  compiles into the straight-line code of a step;
- for an engine without massless bodies, the massless links eliminated by their shape
  (`Elimination`: folded, arms, free groups) and every body's frame from the bodies with
  mass (`EliminatedFrames`);
- for an engine in maximal coordinates, the description's frames and coordinates from
  its bodies' states and the element loads on those bodies (`MaximalFrames`), the
  joint and link geometry its constraints and drivers are placed by (`slide_path`,
  `joint_pose`, `joint_velocity`, `Fold.slot_line`, `coupled_angles`, `PitchPair`'s
  circles and pitch points, `ring_of_chords`), what a host keeps of its inertia beside
  its substitutes (`compensated_host`) and a drive's first-step rate (`stepped_start`);
- a coupling of hinge coordinates on the absolute body angles (`angle_coupling`) and as
  rolling of pitch circles on a carrier (`pitch_pairs`), and small facts a translation
  asks for (`line_through_origin`, `rotation_fixed`, `effective_mass`);
- for an engine with a tree of relative joints, its link frames (`LinkFrames`: one link
  per joint, its frame at the joint, a slide's joint frame turned to its axis), the
  conditions such a tree needs (`axis_aligned`, `one_joint_value`, `held_below`) and a
  driven run's consistent start (`prescribed_start`);
- for an engine whose bodies carry chains of joints but not massless bodies, the massless
  links folded into them (`joint_chains`); for one that holds a slot by a slider body, the
  sliders' masses taken out of the pin body (`slider_masses`); for one without an exact
  imposed motion, the prescribed motions imposed by generalized forces (`ImposedMotions`,
  at the stage time `stage_time`); for a linearization with the closures held exactly,
  the closure forces' geometric stiffness and the modes on the constraint's null space
  (`geometric_stiffness`, `constrained_modes`);
- what every translation starts from (`EnginePlan`), more conditions of an expression
  that follow from the description alone (`carries_child`, `held_by_closure`,
  `couples_two_engine_values`), and the elements between two bodies read from their
  frame states (`PairLoad`, `SlotGeometry`).


The modules, each importing only those above it:

- `numeric`: numbers from description entries, planar rotations, gravity and inertia;
- `coordinates`: the map between description coordinates and engine joint values;
- `kinds_and_laws`: element kinds, force laws, prescribed motions, translatability;
- `kinematics`: forward and planar kinematics, massless bodies folded into joint chains;
- `force_loads`: the loads of the force elements on the bodies;
- `eliminated_links`: massless links eliminated for an engine without massless bodies;
- `description_facts`: small facts of the description a translation asks for;
- `maximal_coordinates`: an engine in maximal coordinates and hinge-angle couplings;
- `relative_trees`: the link frames of a tree of relative joints;
- `engine_plan`: `EnginePlan`, conditions of an expression, elements between two bodies.

This package re-exports the names the backends and the comparisons import from it.
"""
from .numeric import (
    central_tensor, gravity_vector, num, plane_point, ring_of_boxes, ring_of_chords, rot,
    turned, vec3,
)
from .coordinates import (
    CoordinateMap, coordinate_map, slide_axis,
)
from .kinds_and_laws import (
    BODY, COORDINATE_FORCE_CUSTOM, COORDINATE_FORCE_LINEAR, CoordinateLaws, ELEMENT_KINDS,
    ForceLaw, HINGE_CLOSURE, ImposedMotions, LINEAR_COUPLING, MASSLESS_BODY, Motion,
    POINT_ON_LINE, POINT_ON_POINT, POINT_TO_POINT_CUSTOM, POINT_TO_POINT_LINEAR, PRESCRIBED,
    PRISMATIC, REVOLUTE, ROLLING_CONTACT, TIME_LOAD, coupled, description_reason,
    driven_start, element_kind, elements, held_below, massive_below, motions,
    one_joint_value, point_mass, prescribed_start, rigid_body, stage_time, stepped_start,
)
from .kinematics import (
    PAIR_ELEMENTS, body_states, cos_sin, foldable_massless, joint_chains, joint_coordinates,
    pair_element_bodies, point_state, spatial_tree_reason, traced,
)
from .force_loads import (
    Load, coordinate_load, coupling_row, element_loads, joint_pose, joint_velocity,
    slide_path, wrench,
)
from .eliminated_links import (
    EliminatedFrames, Elimination, NotEliminable, sample_columns,
)
from .description_facts import (
    RollingGeometry, compensated_host, constrained_modes, effective_mass,
    geometric_stiffness, length_scale, line_through_origin, principal_inertia,
    rolling_contact_report, rolling_geometry, rotation_fixed, slider_masses,
)
from .maximal_coordinates import (
    MaximalFrames, PitchPair, coupled_angles, pitch_pairs,
)
from .relative_trees import (
    LinkFrames, axis_aligned, link_axis, link_frames, parents_first, rot_z, unit_axis,
)
from .engine_plan import (
    EnginePlan, PairLoad, SlotGeometry, carries_child, couples_two_engine_values,
    engine_coupling, held_by_closure, pair_load, slot_geometry,
)

__all__ = [
    "BODY", "COORDINATE_FORCE_CUSTOM", "COORDINATE_FORCE_LINEAR", "CoordinateLaws",
    "CoordinateMap", "ELEMENT_KINDS", "EliminatedFrames", "Elimination", "EnginePlan",
    "ForceLaw", "HINGE_CLOSURE", "ImposedMotions", "LINEAR_COUPLING", "LinkFrames", "Load",
    "MASSLESS_BODY", "MaximalFrames", "Motion", "NotEliminable", "PAIR_ELEMENTS",
    "POINT_ON_LINE", "POINT_ON_POINT", "POINT_TO_POINT_CUSTOM", "POINT_TO_POINT_LINEAR",
    "PRESCRIBED", "PRISMATIC", "PairLoad", "PitchPair", "REVOLUTE", "ROLLING_CONTACT",
    "RollingGeometry", "SlotGeometry", "TIME_LOAD", "axis_aligned", "body_states",
    "carries_child", "central_tensor", "compensated_host", "constrained_modes",
    "coordinate_load", "coordinate_map", "cos_sin", "coupled", "coupled_angles",
    "couples_two_engine_values", "coupling_row", "description_reason", "driven_start",
    "effective_mass", "element_kind", "element_loads", "elements", "engine_coupling",
    "foldable_massless", "geometric_stiffness", "gravity_vector", "held_below",
    "held_by_closure", "joint_chains", "joint_coordinates", "joint_pose", "joint_velocity",
    "length_scale", "line_through_origin", "link_axis", "link_frames", "massive_below",
    "motions", "num", "one_joint_value", "pair_element_bodies", "pair_load",
    "parents_first", "pitch_pairs", "plane_point", "point_mass", "point_state",
    "prescribed_start", "principal_inertia", "rigid_body", "ring_of_boxes",
    "ring_of_chords", "rolling_contact_report", "rolling_geometry", "rot", "rot_z",
    "rotation_fixed", "sample_columns", "slide_axis", "slide_path", "slider_masses",
    "slot_geometry", "spatial_tree_reason", "stage_time", "stepped_start", "traced",
    "turned", "unit_axis", "vec3", "wrench",
]
