"""Default tolerances, each derived from the numerics that produce the error.

Notation: h the time step, p the order of the engine's integrator, T the simulated time,
w the fastest angular frequency of the motion (rad/s: the largest |s| of the linearization
at the operating point, or the trajectory's own max|q'|/amplitude if larger, e.g. under a
faster forcing).

* Trajectory (error relative to the motion's amplitude). A p-th order one-step method
  commits a local error ~ (w h)^(p+1) per step, relative to the amplitude; over T/h steps
  on an oscillation whose error grows linearly (phase drift, not exponential divergence)
  this sums to (w h)^p (w T). The bounded O((w h)^p) offset of staggered schemes
  (semi-implicit Euler) adds (w h)^p. Gate: (w h)^p (1 + w T), plus the reference's own
  estimated error. No fitted constant: the leading coefficient of the error expansion is
  below 1 for every scheme used here (Euler 1/2, RK4 1/120, generalized-alpha 1/12).
* Reactions: a force error follows the acceleration error, w^2 times the position error,
  so relative to the force amplitude it has the same bound.
* Period: the phase drift per period is (w h)^p times 2 pi at most: gate (w h)^p, plus
  the sampling resolution of zero-crossing interpolation (h/period)^2.
* Energy drift (conservative systems), relative to the kinetic-energy amplitude: the
  same as the trajectory (energy error is first order in the state error).
* Frequency from the engine's own continuous-time linearization (central differences
  with step 1e-6: truncation 1e-12, round-off 1e-16/1e-6 = 1e-10): FD_FREQUENCY = 1e-6.
  From a discrete transition matrix of an order-p scheme: (w h)^p.
* Frequency and damping ratio from a free-vibration fit: (w h)^p of the integrator plus
  FIT_RESOLUTION, the precision of a least-squares sinusoid fit over tens of periods of a
  sampled record, and the amplitude dependence of the frequency at the test amplitude
  (a pendulum's frequency shifts by amplitude^2/16: 6e-8 at 1e-3 rad).
"""
from __future__ import annotations

FD_FREQUENCY = 1e-6
FIT_RESOLUTION = 1e-5
#: amplitude of the free-vibration test, relative to the coordinate scale
FIT_AMPLITUDE = 1e-3


def trajectory_tolerance(w: float, h: float, order: int, t_end: float) -> float:
    return (w * h) ** order * (1.0 + w * t_end)


def period_tolerance(w: float, h: float, order: int, period: float) -> float:
    return (w * h) ** order + (h / period) ** 2


def fit_tolerance(w: float, h: float, order: int) -> float:
    return (w * h) ** order + FIT_RESOLUTION


def discrete_linearization_tolerance(w: float, h: float, order: int) -> float:
    return (w * h) ** order
