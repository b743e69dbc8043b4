"""Modes of the linearized equations M q'' + C q' + K q = 0: their eigenvalues s, one mode
per complex-conjugate pair (the member with Im s > 0) and one per real eigenvalue, with
frequency_hz = |s|/(2 pi), damping_ratio = -Re(s)/|s|, damped_frequency_hz = |Im s|/(2 pi);
the equilibrium record they belong to, and linear stability. Shared by static equilibria
(analytic/linear.py) and relative ones (analytic/relative_equilibrium.py)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

#: relative size below which the real part of an eigenvalue counts as zero (conservative
#: systems have purely imaginary s; round-off leaves ~1e-15 |s|)
ZERO_REAL_PART = 1e-9


@dataclass
class Mode:
    frequency_hz: float
    damping_ratio: float
    damped_frequency_hz: float
    eigenvalue: complex

    def as_dict(self) -> dict:
        return {
            "frequency_hz": self.frequency_hz,
            "damping_ratio": self.damping_ratio,
            "damped_frequency_hz": self.damped_frequency_hz,
            "eigenvalue": [self.eigenvalue.real, self.eigenvalue.imag],
        }


@dataclass
class Equilibrium:
    q: np.ndarray
    stable: bool
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    eigenvalues: np.ndarray
    modes: list[Mode] = field(default_factory=list)
    #: a relative equilibrium (floating mechanism, analytic/relative_equilibrium.py): the
    #: reference's uniform acceleration q'' (None: a static equilibrium) and the rigid
    #: directions (columns)
    acceleration: np.ndarray | None = None
    rigid: np.ndarray | None = None


def companion_matrix(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray:
    """First-order form A of M q'' + C q' + K q = 0, state (q, q')."""
    n = M.shape[0]
    return np.block([[np.zeros((n, n)), np.eye(n)],
                     [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])


def quadratic_eigenvalues(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray:
    """All 2n roots s of det(M s^2 + C s + K) = 0, as complex numbers."""
    return scipy.linalg.eigvals(companion_matrix(M, C, K)).astype(complex)


def modes_from_eigenvalues(eigenvalues: np.ndarray) -> list[Mode]:
    s_all = np.asarray(eigenvalues, dtype=complex)
    scale = max(np.max(np.abs(s_all)), 1e-300)
    modes = []
    for s in s_all:
        if abs(s.imag) <= ZERO_REAL_PART * scale:
            s = complex(s.real, 0.0)
        elif s.imag < 0:
            continue  # the conjugate partner carries the mode
        mag = abs(s)
        modes.append(Mode(
            frequency_hz=mag / (2 * np.pi),
            damping_ratio=(-s.real / mag + 0.0) if mag > 0 else 0.0,
            damped_frequency_hz=abs(s.imag) / (2 * np.pi),
            eigenvalue=s,
        ))
    return sorted(modes, key=lambda m: (m.frequency_hz, m.damping_ratio))


def is_stable(eigenvalues: np.ndarray) -> bool:
    """Lyapunov stable in the linear sense: no eigenvalue with a positive real part and no
    repeated zero eigenvalue (a rigid undamped drift, monograph §4.6)."""
    s = np.asarray(eigenvalues, dtype=complex)
    scale = max(np.max(np.abs(s)), 1.0)
    if np.any(s.real > ZERO_REAL_PART * scale):
        return False
    return int(np.sum(np.abs(s) <= ZERO_REAL_PART * scale)) <= 1


def oscillatory_instability(eigenvalues: np.ndarray) -> bool:
    """Unstable only through oscillatory modes (complex pairs with a positive real part, as
    in self-excitation, monograph §7): a small release oscillates with a growing amplitude,
    so its frequency and (negative) damping ratio can be measured. A real positive
    eigenvalue (a static divergence) departs without oscillating."""
    s = np.asarray(eigenvalues, dtype=complex)
    scale = max(np.max(np.abs(s)), 1.0)
    growing = s[s.real > ZERO_REAL_PART * scale]
    return len(growing) > 0 and bool(np.all(np.abs(growing.imag) > ZERO_REAL_PART * scale))
