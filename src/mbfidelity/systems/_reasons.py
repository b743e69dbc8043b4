"""Physical reasons for expected failures shared by several mechanisms: each states the
mechanism of the failure; the numbers come from the run (the results show each declared
metric's value and gate)."""

MUJOCO_MASSLESS_PIN = (
    "MuJoCo rejects massless moving bodies, so the massless pin P carries a substitute mass "
    "(a small fraction of the lightest body's) held by soft equalities; the added inertia and the soft "
    "slot trade against each other and no mass brings the motion or the second mode "
    "(off in proportion to the substitute mass) within the RK4 gates.")

SEMI_IMPLICIT_DRIFT = (
    "Semi-implicit Euler on a configuration-dependent mass matrix is not symplectic: the "
    "phase drifts at first order, (w h) w T, beyond the semi-implicit-Euler gate; the error "
    "halves with the step (the engine's own refinement converges at first order), but at "
    "the default step it is beyond what a gate can tell apart.")

VELOCITY_LEVEL_STARTUP = (
    "The engine's velocity-level constraint solve has no memory of the centripetal load "
    "at the start of a fast spin: the contact force misses m_b e w^2 on the "
    "first step(s) and overshoots on the next, an error that does not shrink with dt; after "
    "that the force follows the reference within the gate.")
