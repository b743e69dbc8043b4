"""Distances between an engine run and the reference."""
from __future__ import annotations

import warnings

import numpy as np
import scipy.optimize


def amplitude(q_ref: np.ndarray, q_eq: np.ndarray) -> np.ndarray:
    """Excursion of each coordinate from the equilibrium over the run (floored so a
    coordinate that barely moves is judged against the others' scale)."""
    a = np.max(np.abs(q_ref - q_eq), axis=0)
    return np.maximum(a, 1e-3 * max(float(np.max(a)), 1e-12))


def envelope(q_ref: np.ndarray, q_eq: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """Amplitude still to come at each sample: max over later samples and coordinates of
    |q - q_eq| / scale, normalised to 1 at its start."""
    dev = np.max(np.abs(q_ref - q_eq) / scale, axis=1)
    ahead = np.maximum.accumulate(dev[::-1])[::-1]
    return ahead / max(float(ahead[0]), 1e-300)


def trajectory_errors(q: np.ndarray, q_ref: np.ndarray, scale: np.ndarray) -> tuple[float, float]:
    """(max, rms) of |q - q_ref| / scale over time and coordinates."""
    err = np.abs(q - q_ref) / scale
    return float(np.max(err)), float(np.sqrt(np.mean(err**2)))


def mean_period(t: np.ndarray, x: np.ndarray) -> float | None:
    """Mean period from upward zero crossings (linear interpolation); None if fewer than
    two crossings."""
    s = np.signbit(x)
    idx = np.nonzero(s[:-1] & ~s[1:])[0]
    if len(idx) < 2:
        return None
    tc = t[idx] - x[idx] * (t[idx + 1] - t[idx]) / (x[idx + 1] - x[idx])
    return float((tc[-1] - tc[0]) / (len(tc) - 1))


def relative_vector_error(f: np.ndarray, f_ref: np.ndarray, scale: float = 0.0) -> float:
    """max |f - f_ref| / max(max |f_ref|, scale) over samples (Euclidean norms), NaN
    samples (of either) ignored."""
    ok = ~np.any(np.isnan(f), axis=1) & ~np.any(np.isnan(f_ref), axis=1)
    if not np.any(ok):
        return float("nan")
    num = np.max(np.linalg.norm(f[ok] - f_ref[ok], axis=1))
    return float(num / max(np.nanmax(np.linalg.norm(f_ref, axis=1)), scale, 1e-300))


#: evaluations of the model one seed of the free-vibration fit may take (MINPACK's
#: maxfev): a clean free vibration converges in a few tens, a record that is not one (a
#: mode an engine default has reshaped) would otherwise search for minutes
FIT_EVALUATIONS = 200


def fit_damped_sinusoid(t: np.ndarray, x: np.ndarray, w_guess: float, zeta_guess: float):
    """Least-squares fit of x = A exp(-sigma t) cos(wd t + phase) + offset.
    Returns (undamped angular frequency, damping ratio)."""
    xs = x - np.mean(x[-len(x) // 5:]) if len(x) > 10 else x
    # a record that does not cross its mean twice holds no oscillation (a joint locked by
    # an engine's default motor): the least squares would spend their whole budget on it
    if np.count_nonzero(np.diff(xs > 0)) < 2:
        raise RuntimeError("free-vibration fit: the record does not oscillate")
    wd0 = w_guess * np.sqrt(max(1 - zeta_guess**2, 1e-6))
    sigma0 = zeta_guess * w_guess
    a0 = float(np.max(np.abs(xs[: max(len(xs) // 20, 3)])))

    def model(tt, a, sigma, wd, ph, off):
        return a * np.exp(-sigma * tt) * np.cos(wd * tt + ph) + off

    def jacobian(tt, a, sigma, wd, ph, off):
        e = np.exp(-sigma * tt)
        c, s = e * np.cos(wd * tt + ph), e * np.sin(wd * tt + ph)
        return np.column_stack([c, -a * tt * c, -a * tt * s, -a * s, np.ones_like(tt)])

    def fit(p0):
        with warnings.catch_warnings():
            # the covariance is not used; an exact fit makes it inestimable
            warnings.simplefilter("ignore", scipy.optimize.OptimizeWarning)
            p, _ = scipy.optimize.curve_fit(model, t, x, p0=p0, jac=jacobian,
                                            maxfev=FIT_EVALUATIONS, xtol=1e-14,
                                            ftol=1e-14)
        return float(np.sum((model(t, *p) - x) ** 2)), p

    # amplitude, phase and offset for the seeded (wd, sigma) by linear least squares, and
    # four phases: the best of the five fits (a record holding two modes has several
    # local minima)
    e = np.exp(-sigma0 * t)
    basis = np.column_stack([e * np.cos(wd0 * t), e * np.sin(wd0 * t), np.ones_like(t)])
    (c1, c2, off0), *_ = np.linalg.lstsq(basis, x, rcond=None)
    seeds = [[float(np.hypot(c1, c2)), sigma0, wd0, float(np.arctan2(-c2, c1)), float(off0)]]
    seeds += [[a0, sigma0, wd0, ph0, 0.0] for ph0 in (0.0, np.pi / 2, np.pi, -np.pi / 2)]
    best = None
    for p0 in seeds:
        try:
            res = fit(p0)
        except RuntimeError:
            continue
        if best is None or res[0] < best[0]:
            best = res
    if best is None:
        raise RuntimeError("free-vibration fit did not converge")
    _, (a, sigma, wd, ph, off) = best
    w0 = float(np.hypot(abs(wd), sigma))
    return w0, float(sigma / w0)


def fit_growth_rate(t: np.ndarray, x: np.ndarray, eigenvalues, frequencies) -> float:
    """Growth rate sigma of x(t) = a exp(sigma t) + (the other real modes, fixed at their
    linearization's rates) + harmonics at the excitation `frequencies` + offset, by
    least squares with sigma the one nonlinear unknown (variable projection), searched
    within a factor 2 of the linearization's largest real eigenvalue."""
    s = np.asarray(eigenvalues, dtype=complex)
    top = float(np.max(s.real))
    others = [v for v in s if not np.isclose(v.real, top) or abs(v.imag) > 0]

    def basis(sigma: float) -> np.ndarray:
        cols = [np.exp(sigma * t), np.ones_like(t)]
        for v in others:
            e = np.exp(v.real * t)
            cols += [e * np.cos(v.imag * t)] + ([e * np.sin(v.imag * t)] if v.imag else [])
        for w in frequencies:
            cols += [np.cos(w * t), np.sin(w * t)]
        return np.column_stack(cols)

    def misfit(sigma: float) -> float:
        A = basis(sigma)
        coef, *_ = np.linalg.lstsq(A, x, rcond=None)
        return float(np.sum((A @ coef - x) ** 2))

    found = scipy.optimize.minimize_scalar(misfit, bounds=(top / 2, 2 * top), method="bounded",
                                           options={"xatol": 1e-12 * top})
    return float(found.x)
