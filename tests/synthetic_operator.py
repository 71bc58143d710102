"""The synthetic transition table of the operator tests: its measures and its escape rate are known in closed form.

16 boxes of side 0.5 over [−1, 1]², 16 samples each: a quarter escape, a quarter return into their own box (the
operator is aperiodic) and the rest into the next box (cyclically), all at time 2. Every measure is uniform over
the 16 box centres, and the rate is κ = ln(4/3)/2 (¾ e^{2κ} = 1).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

#: the table's extent (x_min, x_max, y_min, y_max) and box side
EXTENT = (-1.0, 1.0, -1.0, 1.0)
BOX = 0.5
#: the escape rate of the table: a quarter of every box leaves per return of time 2
KAPPA = math.log(4 / 3) / 2


def transition_table() -> pd.DataFrame:
    """The one-return samples of the 16 boxes (columns of ``ulam_convergence.energy_results``'s input)."""
    cell, rank = np.repeat(np.arange(16), 16), np.tile(np.arange(16), 16)
    nxt = np.where(rank % 4 == 1, cell, (cell + 1) % 16)
    return pd.DataFrame(
        {
            "cell": cell,
            "rank": rank,
            "w": 1.0,
            "censored": False,
            "ret": rank % 4 > 0,
            "T": 2.0,
            "t_end": 2.0,
            "x1": -0.75 + 0.5 * (nxt % 4),
            "y1": -0.75 + 0.5 * (nxt // 4),
            "e1": 0.3,
        }
    )
