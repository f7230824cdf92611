"""The sampled data of the reconstruction benchmarks, re-implemented: their names, the test
functions, the seeded generator and where in each cell the points fall."""

import numpy as np


RECONSTRUCTION = ("recon1d_nodes", "recon1d_basis")


FUNCTIONS = {
    "one": lambda x: np.ones_like(x),
    "x": lambda x: x,
    "x2": lambda x: x * x,
    "sin_pi": lambda x: np.sin(np.pi * x),
    "x_plus_1": lambda x: x + 1.0,
    "const_1_5": lambda x: np.full_like(x, 1.5),
    "sin_plus_2": lambda x: np.sin(x) + 2.0,
}


class Lcg:
    """mpmlab's generator: x <- 6364136223846793005 x + 1442695040888963407 mod 2^64, the top
    53 bits as the fraction of a uniform number in [0, 1)."""

    def __init__(self, seed):
        self.state = seed

    def unit(self):
        self.state = (6364136223846793005 * self.state + 1442695040888963407) % 2**64
        return (self.state >> 11) / 2.0**53


def cell_fractions(spacing, c, n, rng):
    """Where the n points of cell c go along one axis, as sorted fractions of the cell: equal
    (cell-centred sub-intervals), interior (j/(n+1)), random, or mixed (Wobbes Fig 1: edges
    and draws in cell 0, the left edge and draws in cell 1, equal in cell 2, random after)."""
    if spacing == "equal" or (spacing == "mixed" and c == 2):
        f = [(j + 0.5) / n for j in range(n)]
    elif spacing == "interior":
        f = [j / (n + 1) for j in range(1, n + 1)]
    elif spacing == "mixed" and c == 0:
        f = [0.0, 1.0] + [rng.unit() for _ in range(n - 2)]
    elif spacing == "mixed" and c == 1:
        f = [0.0] + [rng.unit() for _ in range(n - 1)]
    else:
        assert spacing in ("random", "mixed"), spacing
        f = [rng.unit() for _ in range(n)]
    return sorted(f)
