"""Fig. 4-6, eq. 1-3 and Fig. 9, eq. 10-11, by hand. With x the chassis' downward
displacement and the compression s = x - y, the suspension's repulsion f(s) =
k_s s (1 + s^2/x_s^2) pushes the chassis up: m x'' = m g - f(x - y) (eq. 10; eq. 1 at
y = 0). With the road still (Y = 0), rest needs f(x_eq) = m g; f' = k_s (1 + 3 s^2/x_s^2)
> 0, so the cubic has one real root and the rest state is unique, stable, with
k = f'(x_eq) and w = sqrt(k/m) (eq. 3). Linearizing f(x - y) about (x_eq, 0) gives
m g + k (x - x_eq) - k y, hence eq. 11: m eps'' + k eps = k y(t); eq. 2-3 agree."""
import numpy as np

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def static_compression(v):
    roots = np.roots([v["k_s"] / v["x_s"] ** 2, 0.0, v["k_s"], -v["m"] * v["g"]])
    return float(roots[np.argmin(np.abs(roots.imag))].real)


def frequencies(v):
    x_eq = static_compression(v)
    k = v["k_s"] * (1 + 3 * x_eq**2 / v["x_s"] ** 2)
    return [np.sqrt(k / v["m"])]
