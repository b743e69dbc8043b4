"""Default tolerances, each derived from the numerics that produce the error.

Notation: h the time step, p the order of the engine's integrator, T the simulated time,
w the fastest angular frequency of the motion (rad/s: the largest |s| of the linearization
at the operating point, or the trajectory's own max|q'|/amplitude if larger, e.g. under a
faster forcing).

* Trajectory (error relative to the motion's amplitude), order p >= 2. A p-th order
  one-step method commits a local error ~ (w h)^(p+1) per step, relative to the
  amplitude; over T/h steps on an oscillation whose error grows linearly (phase drift,
  not exponential divergence: scenarios are checked not to be chaotic) this sums to
  (w h)^p (w T). Gate: (w h)^p (1 + w T), plus the reference's own estimated error. No
  fitted constant: the leading coefficient is below 1 for the schemes used here (RK4
  1/120, generalized-alpha and trapezoidal 1/12).
* Trajectory, order 1. The first-order schemes of MuJoCo (Euler), PyBullet and Pymunk
  are semi-implicit (symplectic) Euler, which is conjugate to Stoermer-Verlet by an
  O(h) change of variables: on a conservative system with a constant mass matrix its
  error is a bounded offset (w h)/2 plus a second-order phase drift (w h)^2 w T / 24.
  Viscous damping breaks the symplectic structure: the damped frequency is then off by
  zeta w h / 2 (measured on the discrete map: 5.0e-4 at zeta = 0.1, w h = 0.01), a
  first-order phase drift zeta (w h) w T / 2.
  Gate: (w h) + (w h)^2 (1 + w T) + zeta (w h) w T. Where the mass matrix depends on the configuration
  (reduced coordinates of a double pendulum) or forces depend on velocity, the scheme is
  no longer symplectic and drifts at first order, (w h) w T: such cases fail this gate
  and are declared expected failures with that reason, so the gate keeps its teeth (a
  plain explicit Euler, which gains energy, fails it too, as it should).
  Errors are relative to the initial amplitude, and a drift only grows while there is
  motion to drift: a phase error rate d gives |q - q_ref| ~ a(t) d t for an amplitude
  a(t). So T above is the effective duration max_t t a(t)/a(0), taken from the
  reference's own envelope (`effective_duration`): T itself for a sustained motion,
  1/(e zeta w) for an exponential decay, in between for a saturating damper.
* Trajectory of a nearly linear motion, mode by mode. Near a stable equilibrium the
  motion is a sum of modes, and each mode's error follows its own frequency: coordinate c
  carries mode j with amplitude A_cj (from the initial state's modal coordinates), whose
  error is A_cj e_j with e_j the bound above at w = |s_j| (the same order, duration and
  damping). A mode outside the range of w h where its bound holds is still a bounded
  oscillation in a stable scheme (|R(s h)| <= 1 for RK4 and the trapezoidal and
  generalized-alpha rules; semi-implicit Euler's invariant ellipse stretches the amplitude
  by at most 1/sqrt(1 - (w h / 2)^2)): its error is at most twice its amplitude times that
  stretch. Gate: max_c sum_j A_cj e_j / a_c (a_c the coordinate's amplitude, as in the
  metric), plus twice the largest departure of the reference from the linear prediction
  (the nonlinear part of the motion, which the modes do not describe: at most the engine's
  own plus the reference's), plus the other allowances. It is used where it is tighter
  than the fastest-mode bound (a chain of segments released mostly in its first mode, the
  fast modes barely excited), for undriven motions about a stable static equilibrium.
* Reactions: a force error follows the acceleration error, w^2 times the position error,
  so relative to the force amplitude it has the same bound.
* Period: the phase drift per period is (w h)^p times 2 pi at most; for semi-implicit
  Euler (w h)^2 + zeta w h (see above). Plus the sampling resolution of zero-crossing
  interpolation (h/period)^2.
* Energy drift (conservative systems), relative to the kinetic-energy amplitude: the
  same as the trajectory (energy error is first order in the state error).
* Frequency from the engine's own continuous-time linearization (central differences
  with step 1e-6: truncation 1e-12, round-off 1e-16/1e-6 = 1e-10): FD_FREQUENCY = 1e-6.
  From a discrete transition matrix of an order-p scheme: (w_j h)^p for mode j, at its own
  frequency w_j (the map moves each eigenvalue by its own scheme error).
* Frequency and damping ratio from a free-vibration fit: (w_j h)^p of the integrator at
  the released mode's own frequency (each mode is released alone, the others enter at the
  amplitude squared; semi-implicit Euler: (w_j h)^2 + zeta_j w_j h, as for the period, its
  frequency being 2 arcsin(w h / 2) / h undamped, and its damping ratio off by zeta w h
  relative at most), plus
  FIT_RESOLUTION, the precision of a least-squares sinusoid fit over tens of periods of a
  sampled record, and the amplitude dependence of the frequency at the test amplitude
  (a pendulum's frequency shifts by amplitude^2/16: 6e-8 at 1e-3 rad).
* Steady-state amplitude of a driven system at the excitation frequency W. The scheme
  shifts the system's frequencies by a relative eps ((w h)^p for p >= 2; w h for
  semi-implicit Euler, its offset plus its damping error), and its discrete response to
  the sampled forcing by as much; a relative shift eps of the stiffness changes
  D = K - W^2 M + i W C by 2 eps K, so the response by up to 2 eps |K| |D^-1| (the
  amplification: 1/(zeta r) near resonance, 2/|1 - r^2| away from it for one degree of
  freedom at frequency ratio r). Gate: eps (1 + amplification), with w the fastest of W
  and the modes. The engine's amplitude is fitted over the whole periods that follow the
  transient's decay below a hundredth of the response, and compared with the reference's
  fitted over the same window (the residual transient is the same physics in both).
* Trajectory of a stable, damped driven system (slowest modal decay rate sigma > 0): its
  error is that of the steady response (the bound above, which does not grow with time:
  the forcing fixes the phase) plus that of the transient, whose phase error accumulates
  only while it lasts, about 1/sigma: (w_n h)^p (1 + w_n min(T, 1/sigma)) with w_n the
  fastest mode (semi-implicit Euler: its order-1 trajectory bound over the same time). The
  smaller of this and the general bound is the gate.
* Growth rate of an unstable motion (a real eigenvalue s > 0), fitted on the run: the
  scheme moves an eigenvalue by a relative (|s| h)^p (w h for semi-implicit Euler), with
  w the fastest of the eigenvalues and the excitation; plus FIT_RESOLUTION.
* Switching instants of a piecewise law (the end stops of §2.1: a spring k2 that engages
  at |x| = l; the force is continuous there, its slope jumps by k2). An engine that does
  not locate the corner integrates across it as if the law were smooth. Over the step
  that contains the corner the velocity increment is a quadrature of the acceleration,
  whose part (k2/m)|v| (t - t_c)_+ is a ramp starting inside the step (at a fraction
  theta of it): a rule exact for smooth laws misses E(theta) h^2 (k2/m)|v| of it, with
  max |E| = 1/2 for a one-point rule at the step's start (semi-implicit Euler), 1/8 for
  the trapezoidal and midpoint rules (second-order schemes), 1/24 for RK4's Simpson
  weights. So each switch leaves a velocity error c_p (k2/m)|v_j| h^2: O(h^2) whatever
  the order, where a smooth step leaves (w h)^(p+1) (RK4 loses two orders at a switch,
  first-order schemes none). A velocity error dv becomes a position error dv/w0 (w0 the
  damped frequency of the slowest piece), carried forward with the growth factor G of a
  perturbation of the motion (analytic/reference.py `sensitivity`: the motion is not
  chaotic, G stays of order one). The position error at switch i is therefore at most
  A g + G sum_{j<i} c_p (k2/m)|v_j| h^2 / w0, with A the amplitude and g the trajectory
  gate; a position error e shifts a crossing of |x| = l by e/|v_i| (v_i the crossing
  speed), and locating it by linear interpolation between samples adds at most
  h^2 |a_i| / (8 |v_i|) (a_i the acceleration there). That sum is the gate of each
  instant. It holds where the trajectory gate holds and while the shift stays below half
  the shortest interval between two switches (beyond, crossings can no longer be paired:
  the instant is unresolved).
* Stick-slip (a force that jumps by J at a rate surface x' = s, dry friction at zero
  slip, §7.2; acceleration jump a_J = J/m). No engine locates the surface: the step that
  reaches it integrates the wrong side's force over part of the step, a velocity error of
  at most a_J h whatever the scheme (a quadrature with positive weights misses at most the
  whole jump over one step), and while the exact motion sticks (x' = s) the engine's
  velocity chatters about s within that band, its position drifting by at most a_J h per
  unit time. The exact motion arrives at the surface with deceleration a+ (the one-sided
  acceleration there): a velocity error dv moves the arrival by dv/|a+| and the position
  there by dv^2/(2 |a+|). It leaves the surface where the holding force reaches its bound,
  at a fixed position x_r, which the engine's chattering motion meets within a_J h^2.
  Since every stick phase ends at x_r, a cycle's position errors do not carry over: each
  becomes a timing error dx/|s| of that cycle (`stick_slip_time_shift`), and those add up
  over the cycles, a phase drift the trajectory gate gains as max|x'| sum(dt_i) relative
  to the amplitude (`trajectory_allowance` of comparisons/checks/limit_cycle.py) and the
  mean period as sum(dt_i)/T. The cycle's amplitude, on the other hand, is set anew each
  cycle from x_r: its error is one period's smooth bound (w h)^p (1 + w P) plus the
  velocity band a_J h relative to the velocity amplitude, plus the sampling of the
  extremes (w h)^2/8. The bounds hold while a+ stays away from zero (a tangential arrival
  makes dv^2/|a+| grow without limit, and the gate says so by growing).
* Stability threshold (the parameter value p* where a mode's growth rate sigma(p)
  crosses zero, found by an engine by bisection on the sign of its own fitted growth
  rate). The engine's threshold moves by its error in sigma at the neutral mode over the
  slope |d sigma / dp|. An order-p scheme's amplification factor on an undamped mode is
  1 + O((w h)^(p+1)) per step, a growth-rate error of at most w (w h)^p (RK4: w (w h)^5 /
  144 from |R(i w h)|^2 = 1 - (w h)^6/72 + ...). Semi-implicit Euler is the exception that
  helps: its map on a linear oscillator with damping c (force at the step's velocity,
  either end) has determinant 1 - h c/m or 1/(1 + h c/m), so its growth rate vanishes
  exactly where c does; the first error term is second order, and w (w h)^2 bounds it.
  Plus FIT_RESOLUTION w, the resolution of the fitted growth rate. Gate on
  |p - p*| / p*: that over |d sigma / dp| p*, plus the bracket's final half-width. It
  holds while the perturbation stays in the linear range (the test's amplitude is a
  thirtieth of the belt speed, far from sticking).
* Trajectory of an error-controlled integrator (its steps chosen by the engine between
  the samples, e.g. Drake's Runge-Kutta 5 at a target accuracy eps). The step does not
  set the error: the controller accepts a step only when its local error estimate, in
  the engine's norm of the state change (an infinity norm with unit weights here: rad, m,
  rad/s, m/s), is below eps. Each step's local error is therefore at most eps (with
  local extrapolation, as in Dormand-Prince 5(4), the propagated solution's is smaller
  still, by a power of the step), and the global error is the sum of the N local errors
  the run took (the engine reports N), each carried forward by the motion: at most
  multiplied by the growth factor G of a perturbation over the run (analytic/reference.py
  `sensitivity`: of order one on a regular motion, which makes the sum a phase drift as
  in the fixed-step bound; exp(sigma T) on an unstable one). A velocity error dv becomes
  a position error of at most dv min(T, 1/w) (an oscillation at w, or a free drift over
  T). Relative to the smallest amplitude a of the coordinates:
  N eps G (1 + min(T, 1/w)) / a, with G at least 1.
  The number of steps reflects both the accuracy (a tighter eps takes more, smaller
  steps, N ~ w T eps^(-1/(p+1)) for an estimate of order p) and the sampling (no step
  crosses a sample, N >= T/dt), so the bound follows the run without a fitted constant.
  It holds while the error estimate is asymptotic (the accepted steps are small against
  1/w; tight eps) and the motion is not chaotic (the same proviso as above); the range
  w h of the fixed-step bounds does not apply, the ceiling MAX_TRAJECTORY_TOLERANCE does.
* Convergence of an error-controlled integrator (the convergence study's knob is its
  target accuracy eps, swept by decades; comparisons/convergence.py). The controller keeps
  each accepted step's error estimate, of order q (the embedded scheme's: Drake's
  Runge-Kutta 5 estimates with order 4, Runge-Kutta 3 and Radau 3 with order 2), at about
  eps: steps h ~ eps^(1/(q+1)), N ~ T/h of them. The global error is the sum of the local
  errors: N eps ~ eps^(q/(q+1)) without local extrapolation, and N h^(p+1) ~ eps with it
  (a propagated solution of order p = q + 1). So each decade of eps lowers the error by
  10^(q/(q+1)) at least: 3.2 for q = 1 (the slowest scheme offered), more for the others.
  The error is not a smooth function of eps, though: the signed local errors partly
  cancel, by an amount that changes with the step sequence (the controller's safety
  factor, rejected steps, steps shortened to end on a sample), so one accuracy can land
  well below the trend and the next decade then seems to stall. Gate: every tightening
  by ACCURACY_SPAN_DECADES = 2 decades lowers the error by MIN_ACCURACY_DECREASE = 2 per
  decade at least (a factor 4, where 10 at least is expected: a point may fall below the
  trend by a factor 2.5 without failing it), until the error reaches the floor of what
  the comparison resolves (the reference's own error times the convergence study's
  REFERENCE_MARGIN). A model error
  (a mass off, a law changed) sets a floor of its own that no accuracy lowers, far
  above the reference's: the error stops falling there and the gate fails. It holds
  where the error estimate is asymptotic and the controller, not the sampling, sets the
  steps: the mean step T/N within the fixed-step range w h <= ASYMPTOTIC_LIMIT[p], and at
  least twice as many steps as samples (ACCURACY_CONTROLLED_STEPS); looser accuracies are
  run and drawn, not judged (loose estimates are not asymptotic, and a step capped by the
  sampling makes the error independent of eps).
* Where the bounds hold. Each bound above is the leading term of the error's expansion
  in powers of w h. It holds while the neglected terms stay below it: for the order-p >= 2
  schemes used here (RK4, trapezoidal, generalized-alpha) the next term is smaller by
  about (w h)^2 and the leading coefficient is at most 1/12, so the bound holds up to
  w h = ASYMPTOTIC_LIMIT[p] = 0.5; semi-implicit Euler's offset (w h)/2 and its modified
  frequency 2 arcsin(w h/2)/h agree with their leading terms to (w h)^2/24 up to
  w h = 0.2. Beyond that range a gate says nothing and the metric is `unresolved`, with
  the reason. A bound that exceeds what the metric can still tell apart (a trajectory
  error of MAX_TRAJECTORY_TOLERANCE = 0.1 of the amplitude: the motion is then no longer
  the reference's; a frequency error of MAX_FREQUENCY_TOLERANCE = 0.05) is unresolved too:
  a pass would mean nothing.
* A posteriori, by the engine's own refinement (where the bound above does not resolve a
  metric: outside its range of w h, or above the ceiling). The metric is a distance
  v = |Q_h - Q_ref| between a quantity the engine computes at step h (a trajectory, a
  force history, a fitted amplitude, an energy history) and the reference's, in a norm
  |.| (max or rms over the samples, or an absolute value) relative to the reference's
  scale. The same comparison is made between the engine's own runs at h, h/2, h/4, each
  pair on the samples of its coarser run: d_k = |Q_(h/2^(k-1)) - Q_(h/2^k)|, and the
  observed order is log2(d1 / d2). (A max over the samples of h is at most the max over
  the finer samples, so the sum below holds on the samples of h; and an error every run
  makes once, at its first step, shows in every d_k instead of in d1 alone.) In the asymptotic regime of an order-p scheme Q_h = Q* + C h^p + ..., Q*
  the engine's limit, so d1 = |C| h^p (1 - 2^-p) and Richardson's estimate of the engine's
  own error at h is e(h) = d1 / (1 - 2^-p). The engine's distance to its limit is a
  telescoping sum (the triangle inequality, in any of the norms above),
  |Q_h - Q*| <= d1 + d2 + d3 + ..., and while each halving shrinks the difference by
  r <= 2^-(p - REFINEMENT_ORDER_MARGIN) (what the observed order checks: d2/d1 <= r) the
  tail is at most d2 / (1 - r), so |Q_h - Q*| <= d1 + d2 / (1 - r) <= d1 / (1 - r)
  = S e(h), with S = (1 - 2^-p) / (1 - r) the safety factor (1.71 for p = 1, 1.16 for
  p = 2, 1.03 for p = 4, at the margin 0.5). An engine whose limit is the exact motion,
  Q* = Q_exact, is then within d1 + d2 / (1 - r) + eps_ref of the reference (eps_ref the
  reference's own error, as for the a-priori gates); one whose limit is another motion (a
  mass off, a damping left on) is off by |Q* - Q_exact| however fine its step, which its
  own refinement does not predict. Gate: the observed order agrees with the scheme's,
  p - REFINEMENT_ORDER_MARGIN <= observed <= p_top + REFINEMENT_ORDER_MARGIN, and
  v <= d1 + d2 / (1 - r) + eps_ref. p_top is the fastest order the scheme's error terms
  have (`highest_order`): p, except semi-implicit Euler's 2 (its phase drift is second
  order on a conservative motion, its offset first order); r from the declared p is the
  conservative ratio in between. An order outside that range says the pair is not in
  the asymptotic regime (a difference that does not shrink: a floor; one that collapses:
  an error of the coarse run alone, e.g. its first step, that the finer runs do not
  share on the samples of h). Then the engine is run at h/8 too (and at h/16, the step
  budget, where that pair does not confirm it either) and the last pair confirms the
  order instead: the bound is d1 + d2 + d3 / (1 - r) (d1 + d2 + d3 + d4 / (1 - r)), the
  same sum with the unconfirmed differences taken as they are, and e(h) the same sum with
  the last pair's Richardson term d / (1 - 2^-p). A pass also
  needs the bound below the ceiling the metric can discriminate (as for the a-priori
  gates, 0.1 of the amplitude, 0.05 of a frequency): a wider bound says the engine's own
  error at h leaves no room to tell its limit from the reference (a model error that
  large would pass); a value above the bound fails whatever its width.
  The engine's limit. Where the bound at h is above the ceiling but the order is
  confirmed, the question the metric asks (is the engine's limit the exact motion?) is
  put to the finest refined run, h_K = h/2^K, instead, on the samples of h where the
  reference is known: with d'_k the same differences taken on those samples (an error
  of a run's first steps, between samples of h, is then left out of every d'_k alike),
  its distance to its own limit there is the tail d'_(K+1) + d'_(K+2) + ... <=
  d'_K r / (1 - r), while the observed order log2(d'_(K-1) / d'_K) confirms the ratio r
  (as above; otherwise no verdict), so an engine whose limit is the exact motion has
  v_K = |Q_(h_K) - Q_ref| <= d'_K r / (1 - r) + eps_ref (v_K measured as v), and one
  whose limit is off by D has v_K >= D - d'_K r / (1 - r): a model error D above twice
  that bound fails. The metric passes when v <= the bound at h (its error at h is the
  engine's own) and v_K <= d'_K r / (1 - r) + eps_ref, and that bound is below the
  ceiling (r / (1 - r) = 2.41 for p = 1, 0.55 for p = 2, 0.097 for p = 4 at the margin
  0.5). Where it is still above the ceiling at h/4 the engine is run at h/8 as
  well, and at h/16 where the observed order of the d'_k predicts that one more halving
  brings it within (or, where the d'_k fall faster than any term of the scheme, leaving
  a pre-asymptotic range so that the order is not yet confirmed, where one more halving
  at the scheme's fastest order would); h/16 is the step budget: a bound still above the ceiling there (or
  predicted to stay above it) leaves the metric unresolved, the engine's error not
  falling below what the metric can tell apart within the budget. Such a verdict is
  marked as the limit's (`rule` refinement_limit, with v_K and its bound).
  Differences at or below STEP_INDEPENDENT of the scale are round-off: the quantity does not depend on the step (an imposed motion sampled
  exactly), and the order is not asked for. A free-vibration fit is refined alike (the
  same release at h/2, h/4, fitted alike: d_k the differences of successive fitted
  frequencies relative to the mode's, or of damping ratios); its resolution
  FIT_RESOLUTION is then the floor, and eps_ref (the fit on the exact motion is off by as
  much). A growth rate judged against an eigenvalue and the other checks' metrics
  (comparisons/checks) are not refined, but for those a check names as a quantity of the
  run against the same quantity of the reference's (``REFINABLE``), which are distances
  like v: the amplitude over a final window; the Floquet growth rate, its estimator
  applied alike to two of the engine's runs, with eps_ref the estimator's error on the
  exact motion (the engine's limit read by the same estimator is the exact motion's
  reading, which is that far from ln|mu|max / T).
  An event the engine does not locate caps the order at which its error can fall,
  whatever its scheme: a step that reaches a jump of the force leaves a velocity error of
  at most a_J h ("Stick-slip": first order), one across a corner of the law
  c_p (k2/m) |v| h^2 ("Switching instants": second order). Each further event adds one
  such error, so the expansion Q_h = Q* + C h^q + ... holds with q = min(p, the event's
  order) while the events keep their sequence (the ranges of those bounds); a scenario's
  check names that order (comparisons/checks, `refinement_order`) and the refinement
  judges at q: its range q - margin to q_top + margin (q_top the fastest order of an
  order-q scheme, `highest_order`: differences falling faster than the event's order
  are not yet the asymptotic ones, the event's term being the one that remains as h
  falls), its r from q.
  A declared order cap. A property of the engine's model rather than of its scheme can
  set the order too: an equality constraint the engine makes soft, its force a stiff
  spring-damper towards the constraint with a time constant tau that follows the step
  (tau = c h), solves dynamics that differ from the rigid ones by the constraint's
  violation and its rate, which such a law keeps at O(tau^2) = O(h^2) of the motion
  whatever the scheme (a compliant plant's, first order, alike). The expansion is then
  Q_h = Q* + C2 h^q + C4 h^p + ..., Q* the rigid motion, and while tau stays in the
  range the engine accepts (tau >= 2 h where it raises a smaller one), the observed order
  lies between q and the scheme's p: a system declares q for that engine with its reason
  (systems `OrderCap`), and the refinement judges at q with the range q - margin to
  p_top + margin and r from q. r from q bounds the tail of every mix of the two terms
  (each shrinks at least that fast), so the bound and the limit's rule hold as above:
  an engine whose soft solution converges to the rigid motion passes, one whose limit is
  another motion (a mass off) fails. The constraint's force is not such a quantity: the
  soft law's force is the spring-damper's, k(h) times a violation of O(h^2) with
  k(h) = O(1/h^2), which converges to a regularised value (the impedance the law keeps
  at every step), not to the rigid multiplier: its differences do not shrink, the
  refinement has no asymptotic regime, and a system declares such a metric an expected
  failure with that mechanism (an "xfail" declaration where the order falls short
  judges it so, strictly: a metric that converges is reported).
  Where the bound holds: in the engine's asymptotic regime, which the observed order confirms on the last pair of halvings (the
  next terms of the expansion shrink faster; a cancellation exactly at the finest pair
  would overstate the order, which the max norm over a run makes unlikely). Where the
  order falls short down to h/16 (the differences stop shrinking with the step: a
  constraint's compliance, an event located to the step, a motion too fast), the metric
  stays `unresolved`, the observed order stated. The refinement runs cost six times the
  engine's run at h (h/2 and h/4; fourteen with h/8, thirty with h/16), only on the
  scenarios that have an unresolved metric.
  The a-posteriori verdicts follow the a-priori ones in reach: a pass says the engine
  converges, at its scheme's order, to a limit within the bound of the exact motion; an
  engine whose error at h is its own but whose limit is another motion fails, however
  wide its error at h (the refinement gate, or the limit's).
* Stability. An explicit scheme diverges on a mode with w h above its stability limit on
  the imaginary axis (RK4: 2 sqrt 2; semi-implicit Euler: 2; each backend names its
  scheme and limit, simulators/base.py point 10); a comparison refuses such a step
  before any work (`stability_refusal`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Sequence

if TYPE_CHECKING:  # annotations only: a rule that needs NumPy imports it itself
    import numpy as np

FD_FREQUENCY = 1e-6
FIT_RESOLUTION = 1e-5
#: amplitude of the free-vibration test, relative to the coordinate scale
FIT_AMPLITUDE = 1e-3


#: largest w h where the order-p bound holds (see the module docstring)
ASYMPTOTIC_LIMIT = {1: 0.2}
ASYMPTOTIC_LIMIT_HIGHER_ORDER = 0.5
MAX_TRAJECTORY_TOLERANCE = 0.1
MAX_FREQUENCY_TOLERANCE = 0.05
#: an error-controlled integrator's error must fall by this factor per decade of its target
#: accuracy (see the module docstring: at least 10^(1/2) expected)
MIN_ACCURACY_DECREASE = 2.0
#: the decades of target accuracy over which that fall is asked for (the module docstring)
ACCURACY_SPAN_DECADES = 2
#: a run's steps per sample above which the controller, not the sampling, chose its steps
ACCURACY_CONTROLLED_STEPS = 2.0


#: largest shortfall of the observed order below the declared one in the refinement rule
REFINEMENT_ORDER_MARGIN = 0.5
#: differences between the engine's runs at or below this (relative to the metric's scale)
#: are round-off: eps = 2.2e-16 per step over up to 1e5 steps (h/4 over the longest runs)
#: is 2e-11 of the state's magnitude, which is at most about 100 times the amplitude (a
#: coordinate far from its origin moving little)
STEP_INDEPENDENT = 1e-9


@dataclass(frozen=True)
class Gate:
    """A tolerance and, when its bound says nothing there, why (`unresolved`)."""

    tolerance: float
    unresolved: str = ""


def asymptotic_limit(order: int) -> float:
    return ASYMPTOTIC_LIMIT.get(order, ASYMPTOTIC_LIMIT_HIGHER_ORDER)


def gate(tolerance: float, w: float, h: float, order: int, ceiling: float,
         what: str = "of the amplitude") -> Gate:
    """`tolerance` as a Gate: unresolved outside the bound's range of w h, or above the
    ceiling the metric can still discriminate."""
    limit = asymptotic_limit(order)
    if w * h > limit:
        return Gate(tolerance, f"step too coarse for an order-{order} scheme at w = {w:.4g} "
                               f"rad/s: w h = {w * h:.3g} > {limit:g}, where the error bound "
                               f"no longer holds")
    if not tolerance <= ceiling:
        return Gate(tolerance, f"the error bound {tolerance:.3g} exceeds {ceiling:g} {what}: "
                               f"at this step and duration a pass would mean nothing")
    return Gate(tolerance)


def stability_refusal(w: float, h: float, scheme: str, limit: float | None) -> str:
    """'' when the step is stable on the fastest mode w; otherwise one line naming w h and
    the scheme's limit (an implicit scheme has none: `limit` None)."""
    if limit is None or not w * h > limit:
        return ""
    return (f"dt = {h:g} s cannot be stable with {scheme}: w h = {w * h:.3g} at the fastest "
            f"mode (w = {w:.4g} rad/s) exceeds the scheme's stability limit {limit:.3g}")


def trajectory_tolerance(w: float, h: float, order: int, t_end: float, zeta: float = 0.0) -> float:
    if order == 1:
        return w * h + (w * h) ** 2 * (1.0 + w * t_end) + zeta * w * h * w * t_end
    return (w * h) ** order * (1.0 + w * t_end)


def error_controlled_trajectory_tolerance(accuracy: float, steps: int, w: float,
                                          t_end: float, amplitude: float,
                                          growth: float = 1.0) -> float:
    """N eps G (1 + min(T, 1/w)) / a: the trajectory bound of an error-controlled
    integrator (module docstring), relative to the amplitude a."""
    carry = t_end if w <= 0 else min(t_end, 1.0 / w)
    return steps * accuracy * growth * (1.0 + carry) / amplitude


def error_controlled_gate(tolerance: float) -> Gate:
    """An error-controlled bound as a Gate: no range of w h applies (the engine picks its
    steps), the ceiling of a trajectory metric does."""
    if not tolerance <= MAX_TRAJECTORY_TOLERANCE:
        return Gate(tolerance, f"the error bound {tolerance:.3g} exceeds "
                               f"{MAX_TRAJECTORY_TOLERANCE:g} of the amplitude: at this "
                               f"accuracy and duration a pass would mean nothing")
    return Gate(tolerance)


def modal_trajectory_tolerance(amplitudes: np.ndarray, omegas: np.ndarray,
                               zetas: np.ndarray, scale: np.ndarray, h: float, order: int,
                               t_end: float) -> float:
    """max_c sum_j amplitudes[c, j] e_j / scale[c] (module docstring: mode by mode), e_j
    the trajectory bound at omegas[j] inside the bound's range of w h, twice the mode's
    largest amplitude in the scheme outside it (inf beyond its stability limit)."""
    import numpy as np

    limit = asymptotic_limit(order)
    errors = []
    for w, zeta in zip(omegas, zetas):
        if w * h <= limit:
            errors.append(trajectory_tolerance(w, h, order, t_end, max(zeta, 0.0)))
        elif order == 1:
            errors.append(2.0 / np.sqrt(1.0 - (w * h / 2) ** 2) if w * h < 2 else np.inf)
        else:
            errors.append(2.0)
    return float(np.max(np.asarray(amplitudes) @ np.asarray(errors) / np.asarray(scale)))


def scheme_frequency_error(w: float, h: float, order: int, zeta: float) -> float:
    """Relative shift of a mode's frequency by the scheme: (w h)^p; semi-implicit Euler's is
    second order, plus zeta w h from damping (see above)."""
    if order == 1:
        return (w * h) ** 2 + abs(zeta) * w * h
    return (w * h) ** order


def period_tolerance(w: float, h: float, order: int, period: float, zeta: float = 0.0) -> float:
    return scheme_frequency_error(w, h, order, zeta) + (h / period) ** 2


def fit_tolerance(w: float, h: float, order: int, zeta: float) -> float:
    return scheme_frequency_error(w, h, order, zeta) + FIT_RESOLUTION


def discrete_linearization_tolerance(w: float, h: float, order: int) -> float:
    return (w * h) ** order


def effective_duration(t, envelope) -> float:
    """max_t t a(t) / a(0) with a(t) the reference's amplitude still to come (see above)."""
    import numpy as np

    return float(np.max(np.asarray(t) * np.asarray(envelope)))


def steady_state_tolerance(w: float, h: float, order: int, amplification: float) -> float:
    eps = w * h if order == 1 else (w * h) ** order
    return eps * (1.0 + amplification)


def driven_trajectory_tolerance(w_excitation: float, w_modes: float, h: float, order: int,
                                t_end: float, sigma: float, amplification: float,
                                zeta: float) -> float:
    memory = min(t_end, 1.0 / sigma)
    steady = steady_state_tolerance(max(w_excitation, w_modes), h, order, amplification)
    return steady + trajectory_tolerance(w_modes, h, order, memory, zeta)


def growth_rate_tolerance(w: float, h: float, order: int) -> float:
    return (w * h if order == 1 else (w * h) ** order) + FIT_RESOLUTION


def floquet_growth_tolerance(w: float, h: float, order: int, estimator: float) -> float:
    """Relative error of a parametric growth rate ln|mu|max / T read from an engine's run
    (comparisons/checks/floquet.py). The scheme's one-period map is the monodromy to
    within a relative (w h)^p per step (w h for semi-implicit Euler), w the fastest of the
    excitation and the Floquet exponents, so ln|mu| moves by that over each of the T/h
    steps, relative to the growth over the period: the same relative bound as a constant-
    coefficient eigenvalue. Plus `estimator`, the error of the per-period-maxima estimator
    on the exact motion of the same scenario (the decaying partner and the periodic factor
    p(t) are not exactly removed by a straight line through the maxima)."""
    return growth_rate_tolerance(w, h, order) + estimator


#: largest quadrature error, in units of h^2 times the ramp's slope, of a step whose
#: acceleration has a corner inside it, by integrator order (see the module docstring)
CORNER_QUADRATURE = {1: 1 / 2, 2: 1 / 8, 3: 1 / 8, 4: 1 / 24}


def switching_time_tolerance(position_error: float, speed: float, acceleration: float,
                             h: float) -> float:
    """Shift of a crossing instant: the position error over the crossing speed plus the
    linear interpolation between samples (see the module docstring)."""
    return (position_error + h * h * abs(acceleration) / 8.0) / abs(speed)


def corner_velocity_error(order: int, slope_jump: float, speed: float, h: float) -> float:
    """Velocity error left by a step across a corner of the law (slope jump k2/m of the
    acceleration per unit displacement, crossing speed `speed`)."""
    coefficient = CORNER_QUADRATURE.get(order, CORNER_QUADRATURE[4])
    return coefficient * slope_jump * abs(speed) * h * h


def limit_cycle_tolerance(w: float, h: float, order: int, period: float,
                          acceleration_jump: float, velocity_amplitude: float) -> float:
    """Relative error of a stick-slip cycle's amplitude (module docstring, "Stick-slip")."""
    smooth = trajectory_tolerance(w, h, order, period)
    return smooth + acceleration_jump * h / velocity_amplitude + (w * h) ** 2 / 8


def stick_slip_time_shift(acceleration_jump: float, h: float, onset_deceleration: float,
                          stick_duration: float, surface_speed: float) -> float:
    """Timing error one stick-slip cycle adds (module docstring, "Stick-slip")."""
    dv = acceleration_jump * h
    dx = (dv * dv / (2.0 * abs(onset_deceleration)) + dv * stick_duration
          + acceleration_jump * h * h)
    return dx / abs(surface_speed)


def threshold_tolerance(w: float, h: float, order: int, slope: float) -> float:
    """Shift of a stability threshold in the parameter's units (module docstring,
    "Stability threshold"): growth-rate error at the neutral mode over |d sigma / dp|."""
    return (w * (w * h) ** max(order, 2) + FIT_RESOLUTION * w) / slope


# --- the round-off floor ---------------------------------------------------------------
#
# Every step of an engine rounds the state it computes: a few units in the last place of
# the largest coordinate, |q|max u (u = 2^-53). Over N steps those roundings add up to at
# most N ROUNDINGS_PER_STEP |q|max u (the linear worst case; a random walk gives sqrt(N)),
# whatever the scheme's truncation error. Relative to the scale the error is divided by
# (the motion's amplitude), a gate below that sum would judge round-off: it holds the
# floor N ROUNDINGS_PER_STEP u |q|max / scale. It matters only where the motion is tiny
# beside the coordinates' values (a mass of 1e9 kg barely moving, g of 1e-9), and is far
# below every truncation bound elsewhere (at N = 1e4 steps it is 1e-11 of the amplitude
# when |q|max = scale).

UNIT_ROUNDOFF = 2.0 ** -53
#: roundings of a coordinate per step (the update q + h v, and the stages that feed v)
ROUNDINGS_PER_STEP = 4


def roundoff_floor(steps: int, magnitude: float, scale: float) -> float:
    """The error round-off alone can make after `steps` steps of a state whose largest
    coordinate is `magnitude`, relative to `scale`."""
    return steps * ROUNDINGS_PER_STEP * UNIT_ROUNDOFF * magnitude / max(scale, 1e-300)


@dataclass(frozen=True)
class RefinementGate:
    """The a-posteriori gate of a metric from the engine's own refinement (see "A
    posteriori" above): `tolerance` = the telescoping bound + `reference_error`, with
    Richardson's `predicted_error`, or `unresolved` with why."""

    tolerance: float
    observed_order: float | None
    declared_order: int
    predicted_error: float
    differences: tuple[float, ...]
    reference_error: float
    unresolved: str = ""
    #: the bound on the finest refined run's distance to the reference if the engine's
    #: limit is the exact motion: its own remaining error plus `reference_error`
    #: (tolerances.py, "A posteriori", the engine's limit)
    limit_tolerance: float = math.inf

    def as_dict(self) -> dict:
        out = {"observed_order": self.observed_order, "declared_order": self.declared_order,
               "predicted_error": self.predicted_error, "differences": list(self.differences),
               "reference_error": self.reference_error}
        if self.unresolved:
            out["unresolved"] = self.unresolved
        return out


def highest_order(order: int) -> int:
    """The fastest order at which an order-`order` scheme's error can fall: semi-implicit
    Euler's phase drift is second order (its offset first), the other schemes' error is
    of their order."""
    return 2 if order == 1 else order


def refinement_safety(order: int) -> float:
    """S = (1 - 2^-p) / (1 - 2^-(p - margin)): the telescoping bound over e(h)."""
    return (1.0 - 2.0 ** -order) / (1.0 - 2.0 ** -(order - REFINEMENT_ORDER_MARGIN))


def limit_factor(order: int) -> float:
    """r / (1 - r), r = 2^-(p - margin): the bound on the tail after the finest refined
    run, per its last difference ("A posteriori", the engine's limit)."""
    shrink = 2.0 ** -(order - REFINEMENT_ORDER_MARGIN)
    return shrink / (1.0 - shrink)


def refinement_gate(differences: Sequence[float], order: int, reference_error: float,
                    floor: float = STEP_INDEPENDENT, top: int | None = None) -> RefinementGate:
    """The gate from the differences d_k = |Q_(h/2^(k-1)) - Q_(h/2^k)| (at least two) of an
    order-`order` scheme (module docstring, "A posteriori"): the last pair confirms the
    order, the earlier differences add as they are. Differences at or below `floor` are
    the quantity's own resolution (round-off; a fit's FIT_RESOLUTION). `top`: the order of
    the scheme whose convergence a declared order cap lowers to `order` (its fastest
    order bounds the observed one; "A declared order cap")."""
    d = [float(x) for x in differences]
    shrink = 2.0 ** -(order - REFINEMENT_ORDER_MARGIN)
    head, (last, tail) = sum(d[:-2]), d[-2:]
    predicted = head + last / (1.0 - 2.0 ** -order)
    bound = head + last + tail / (1.0 - shrink)
    if not all(math.isfinite(x) for x in d):
        return RefinementGate(math.inf, None, order, math.inf, tuple(d), reference_error,
                              "the refined runs give no finite difference")
    remaining = limit_factor(order)  # the tail after the finest run, per its d_K
    if max(last, tail) <= floor:
        return RefinementGate(head + floor / (1.0 - shrink) + reference_error, None,
                              order, head + floor, tuple(d), reference_error,
                              limit_tolerance=floor * remaining + reference_error)
    observed = (math.log2(last / tail) if last > 0 and tail > 0
                else math.inf if tail <= 0 else -math.inf)
    lowest, highest = order - REFINEMENT_ORDER_MARGIN, (
        highest_order(max(order, top or order)) + REFINEMENT_ORDER_MARGIN)
    unresolved = "" if lowest <= observed <= highest else (
        f"no asymptotic regime down to h/{2 ** len(d)}: the engine's own differences "
        f"between its last halvings fall at order {observed:.2f}, outside the scheme's "
        f"{lowest:g} to {highest:g}")
    return RefinementGate(bound + reference_error, observed, order, predicted, tuple(d),
                          reference_error, unresolved,
                          math.inf if unresolved else tail * remaining + reference_error)
