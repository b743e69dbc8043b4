"""The N-four-bar (IFToMM A02) by hand, N = 2 at the defaults (cranks and couplers of
length L, masses m and mc, ground pins b = L apart).

Hanging parallelogram (every crank at -pi/2, the couplers horizontal): the couplers
translate with the cranks' tips, so T = [(N + 1) m L^2/3 + N mc L^2] th'^2 / 2 (a crank
turns about its pin: m L^2/12 + m (L/2)^2) and V = g L [(N + 1) m/2 + N mc] sin th; one
mode, w^2 = g L [(N + 1) m/2 + N mc] / [(N + 1) m L^2/3 + N mc L^2].

Equilibria (the stable ones counted). A window of four equal bars closes in three ways:
the parallelogram P (th_i = th_{i-1}), K0 (th_{i-1} = 0: B_{i-1} on A_i, crank i free,
its coupler laid on it) and Kpi (th_i = pi: B_i on A_{i-1}, crank i-1 free). Each
coupler's centre is the middle of its tips, so V = g L [m/2 sum sin th_i + mc/2 sum
(sin th_{j-1} + sin th_j)] = g (sin th0 + 3/2 sin th1 + sin th2) at the defaults. Its
minima on the nine pairs of window branches: (P, P) all at -pi/2; (P, Kpi) th0 = th1 =
-pi/2, th2 = pi; (K0, P) th0 = 0, th1 = th2 = -pi/2; (K0, Kpi) th0 = 0, th1 = -pi/2,
th2 = pi: four stable equilibria at regular poses. The other pairs' minima ((P, K0),
(K0, K0), (Kpi, P), (Kpi, Kpi); (Kpi, K0) does not close) sit where a window is flat: the
constraint Jacobian loses rank there and gravity's load on the flat window has no
first-order reaction, so they are no equilibria of the constrained equations (no
multipliers balance the load). Only the first lies on the described branch (the
parallelogram): the near-equilibrium releases start near none of the others, which the
reference (following that branch) cannot follow.
"""
import math

EQUILIBRIA = (None, 4)
#: stable equilibria on the described assembly branch (Mechanism.branch)
STABLE_ON_BRANCH = 1
MISPRINTS = set()


def frequencies(v):
    N, L, m, mc, g = 2, v["L"], v["m"], v.get("mc", v["m"]), v["g"]
    return [math.sqrt(g * L * ((N + 1) * m / 2 + N * mc)
                      / ((N + 1) * m * L * L / 3 + N * mc * L * L))]
