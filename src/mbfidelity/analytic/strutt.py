"""The Strutt chart: stability of Mathieu's equation as printed in the monograph (§8.4,
eq. 83, Fig. 28) with omega = 1,

    phi'' + (lambda + gamma cos t) phi = 0,    period 2 pi,

from Floquet theory (analytic/floquet.py) over a (lambda, gamma) grid. The monodromy
matrices of all grid points are solved together: one DOP853 solve of the stacked
variational equations (each point's 2 x 2 state-transition matrix) at FLOQUET_RTOL, and
one at CHECK_RTOL whose distance from it is each point's error estimate; each point is
then classified by `floquet.classify` (stable / unstable / marginal).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.integrate

from .floquet import CHECK_RTOL, FLOQUET_RTOL, ROUND_OFF, classify

PERIOD = 2.0 * np.pi
#: default ranges of the chart (chosen here: the first three tongues and the negative
#: lambda where the inverted pendulum of eq. 82 can be stable)
LAMBDA_RANGE = (-1.0, 3.0)
GAMMA_RANGE = (0.0, 3.0)


@dataclass
class StruttChart:
    lambdas: np.ndarray          # (n_lambda,)
    gammas: np.ndarray           # (n_gamma,)
    multipliers: np.ndarray      # (n_gamma, n_lambda, 2) complex
    error: np.ndarray            # (n_gamma, n_lambda)
    verdict: np.ndarray          # (n_gamma, n_lambda) str

    @property
    def max_abs_multiplier(self) -> np.ndarray:
        return np.max(np.abs(self.multipliers), axis=-1)

    def points(self) -> list[dict]:
        out = []
        for i, gamma in enumerate(self.gammas):
            for j, lam in enumerate(self.lambdas):
                verdict = str(self.verdict[i, j])
                out.append({"lambda": float(lam), "gamma": float(gamma),
                            "floquet_max_abs_multiplier": float(self.max_abs_multiplier[i, j]),
                            "floquet_error": float(self.error[i, j]),
                            "stable": {"stable": True, "unstable": False}.get(verdict),
                            "verdict": verdict})
        return out


def mathieu_monodromies(lam: np.ndarray, gamma: np.ndarray, rtol: float) -> np.ndarray:
    """Monodromy matrices (N, 2, 2) of eq. 83 at the points (lam[k], gamma[k])."""
    lam = np.asarray(lam, float).ravel()
    gamma = np.asarray(gamma, float).ravel()
    n = lam.size

    def rhs(t, y):
        # rows: phi of the two unit starts, then their rates
        state = y.reshape(4, n)
        stiffness = lam + gamma * np.cos(t)
        return np.concatenate([state[2:], -stiffness * state[:2]]).ravel()

    start = np.concatenate([np.ones(n), np.zeros(n), np.zeros(n), np.ones(n)])
    sol = scipy.integrate.solve_ivp(rhs, (0.0, PERIOD), start, method="DOP853",
                                    rtol=rtol, atol=rtol * 1e-3)
    if not sol.success:
        raise RuntimeError(f"Strutt chart solve failed: {sol.message}")
    end = sol.y[:, -1].reshape(4, n)
    # Phi = [[phi_1, phi_2], [phi_1', phi_2']]
    return np.stack([np.stack([end[0], end[1]], axis=-1),
                     np.stack([end[2], end[3]], axis=-1)], axis=-2)


def strutt_chart(n_lambda: int, n_gamma: int, lambda_range=LAMBDA_RANGE,
                 gamma_range=GAMMA_RANGE) -> StruttChart:
    """Floquet verdicts of eq. 83 on an n_lambda x n_gamma grid (ends included)."""
    lambdas = np.linspace(*lambda_range, n_lambda)
    gammas = np.linspace(*gamma_range, n_gamma)
    L, G = np.meshgrid(lambdas, gammas)
    tight = mathieu_monodromies(L, G, FLOQUET_RTOL)
    loose = mathieu_monodromies(L, G, CHECK_RTOL)
    mu = np.linalg.eigvals(tight)
    mu_check = np.linalg.eigvals(loose)
    # match the two solves' pairs one to one (two ways to pair two multipliers)
    straight = np.max(np.abs(mu - mu_check), axis=-1)
    crossed = np.max(np.abs(mu - mu_check[:, ::-1]), axis=-1)
    error = np.maximum(np.minimum(straight, crossed),
                       ROUND_OFF * np.maximum(1.0, np.max(np.abs(mu), axis=-1)))
    verdict = np.array([classify(m, e)[0] for m, e in zip(mu, error)])
    shape = (n_gamma, n_lambda)
    return StruttChart(lambdas, gammas, mu.reshape(*shape, 2), error.reshape(shape),
                       verdict.reshape(shape))


def mathieu_point(point: tuple[float, float]) -> dict:
    """The one-point Floquet analysis of eq. 83 at (lambda, gamma), as a JSON-able dict
    (a sweep's unit of work)."""
    from .floquet import floquet

    lam, gamma = float(point[0]), float(point[1])
    result = floquet(lambda t: np.array([[0.0, 1.0], [-(lam + gamma * np.cos(t)), 0.0]]),
                     PERIOD, 2)
    return {"lambda": lam, "gamma": gamma, **result.as_dict()}
