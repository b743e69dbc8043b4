"""§2.1, Fig. 1-2, by hand. Between the stops both pairs act (2 k1, 2 c) and the stops
do not: m x'' + 2 c x' + 2 k1 x = 0, so about x = 0 the frequency is sqrt(2 k1 / m). The
only force-free state is x = 0 (outside the band 2 k1 x + k2 (|x| - l) has the sign of x),
stable. The three printed equations are those of Newton's law on the block with the stop
pushing back k2 (|x| - l) beyond the gap."""
import numpy as np

EQUILIBRIA = (1, 1)
MISPRINTS = set()


def frequencies(v):
    return [np.sqrt(2 * v["k1"] / v["m"])]
