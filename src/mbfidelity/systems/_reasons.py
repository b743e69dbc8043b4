"""Physical reasons for expected failures shared by several mechanisms (each measured;
the numbers per mechanism are in the results)."""

MUJOCO_MASSLESS_PIN = (
    "MuJoCo rejects massless moving bodies, so the massless pin P carries a substitute mass "
    "(3e-4 of the lightest body) held by soft equalities; the added inertia and the soft "
    "slot trade against each other and no mass brings the motion or the second mode "
    "(off by 2e-4, proportional to the substitute mass) within the RK4 gates.")

SEMI_IMPLICIT_DRIFT = (
    "Semi-implicit Euler on a configuration-dependent mass matrix is not symplectic: the "
    "phase drifts at first order, (w h) w T, beyond the semi-implicit-Euler gate; the error "
    "halves with the step (measured convergence at first order).")

VELOCITY_LEVEL_STARTUP = (
    "The engine's velocity-level constraint solve has no memory of the centripetal load "
    "at the start of a fast spin (40 rad/s): the contact force misses m_b e w^2 on the "
    "first step(s) and overshoots on the next, an error that does not shrink with dt; after "
    "that the force follows the reference within the gate.")

FIRST_ORDER_BOUND_TOO_WIDE = (
    "At the default step (1e-3 s) the error bound of semi-implicit Euler, (w h) + (w h)^2 "
    "(1 + w T) + zeta (w h) w T, exceeds 0.1 of the amplitude on this scenario (damped modes "
    "over its duration, comparisons/tolerances.py): a gate that wide cannot tell a right "
    "motion from a wrong one, so the error is measured and shown, not judged. A step a few "
    "times smaller brings the bound back under 0.1.")


def coarse_first_order(*patterns: str, engines: tuple[str, ...] = ("pybullet", "pymunk")):
    """'unresolved' declarations of the metrics `patterns` for the semi-implicit Euler
    engines (FIRST_ORDER_BOUND_TOO_WIDE)."""
    from . import Expectation

    return tuple(Expectation(e, p, "unresolved", FIRST_ORDER_BOUND_TOO_WIDE)
                 for e in engines for p in patterns)


SECOND_ORDER_BOUND_TOO_WIDE = (
    "At the default step (1e-3 s) the error bound of a second-order scheme (Exudyn's "
    "trapezoidal rule), (w h)^2 (1 + w T) with T the motion's memory (the lightly damped "
    "transient lasts 1/sigma) or its duration, exceeds 0.1 of the amplitude on this "
    "scenario (comparisons/tolerances.py): the error is measured and shown, not judged. The "
    "bound's leading coefficient is 1 where the trapezoidal rule's phase error is 1/12 of "
    "it; a step three times smaller brings the bound under 0.1.")


def coarse_second_order(*patterns: str, engines: tuple[str, ...] = ("exudyn",)):
    """'unresolved' declarations of the metrics `patterns` for the second-order engines
    (SECOND_ORDER_BOUND_TOO_WIDE)."""
    from . import Expectation

    return tuple(Expectation(e, p, "unresolved", SECOND_ORDER_BOUND_TOO_WIDE)
                 for e in engines for p in patterns)
