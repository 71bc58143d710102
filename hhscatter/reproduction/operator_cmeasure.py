"""The transfer operator's measures on the section against sprinkler points of the c-measure (μ_c).

Per energy of the sprinkler sample and per energy of an operator's result, points are drawn from the operator's
measure carried one return forward (:func:`~hhscatter.analysis.geometry.ulam.measure_points`: "sprinkler",
"flux", "map") and compared with the sprinkler points by the debiased Hellinger distance over box sides
(:func:`~hhscatter.analysis.geometry.ulam.hellinger_by_box`). Nothing here reads a file. Units: positions and box
sides in the section's units (x, y); distances dimensionless.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import ulam

__all__ = ["measure_distances"]


def measure_distances(results: dict, points: pd.DataFrame, energies, boxes, extent, n_splits: int, seed: int, head,
                      rng):  # fmt: skip
    """measure_distances(results, points, energies, boxes, extent, n_splits, seed, head, rng) -> (rows, table, counts).

    Parameters
    ----------
    results : dict
        {E: an operator's result at energy E} (:func:`~hhscatter.analysis.geometry.ulam_convergence.energy_results`).
    points : DataFrame
        The sprinkler points (columns energy, x, y).
    energies : sequence of float
        The energies of the comparison: the sprinkler sample at each is compared with the operator's result at
        every one of them; all three kinds of measure at the same energy, the "sprinkler" one across energies.
    boxes, extent, n_splits, seed, head
        Box sides, the section's extent (x0, x1, y0, y1), the split-halves and their seed, the headline box side
        (:func:`~hhscatter.analysis.geometry.ulam.hellinger_by_box`).
    rng : numpy.random.Generator
        Draws the operator's points (as many as the sample's at that energy).

    Returns
    -------
    (list, DataFrame, dict)
        One record per (sample energy, operator energy, measure) with n and the headline distance
        (:func:`~hhscatter.analysis.geometry.ulam.hellinger_row`), the distance tables of all of them (columns
        fig1_energy, operator_energy, kind added), and {E: number of sprinkler points}.

    Examples
    --------
    >>> rows, tab, counts = measure_distances({}, pd.DataFrame({"energy": [0.3], "x": [0.0], "y": [0.0]}), [0.3],
    ...                                       [0.5], (-1, 1, -1, 1), 2, 0, 0.5, np.random.default_rng(0))
    >>> rows, len(tab), counts
    ([], 0, {0.3: 1})
    """
    rows, tabs, counts = [], [], {}
    for E in list(energies):
        Q = points[np.isclose(points["energy"], E, rtol=0, atol=1e-9)][["x", "y"]].to_numpy()
        counts[E] = int(len(Q))
        for ref_E in [e for e in results if any(np.isclose(e, c) for c in energies)]:
            kinds = ("sprinkler", "flux", "map") if np.isclose(ref_E, E) else ("sprinkler",)
            for kind in kinds:
                P = ulam.measure_points(results[ref_E], kind, len(Q), rng)
                tab, j = ulam.hellinger_by_box(P, Q, boxes, extent, n_splits, seed, head)
                tabs.append(tab.assign(fig1_energy=E, operator_energy=ref_E, kind=kind))
                rows.append(
                    {
                        "fig1_energy": E,
                        "operator_energy": ref_E,
                        "measure": kind,
                        "n": int(len(Q)),
                        **ulam.hellinger_row(tab, j),
                    }
                )
    return rows, (pd.concat(tabs, ignore_index=True) if tabs else pd.DataFrame()), counts
