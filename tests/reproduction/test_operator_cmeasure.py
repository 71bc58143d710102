"""The operator's measures against sprinkler points (hhscatter.reproduction.operator_cmeasure) on a synthetic
operator whose measures are known: every box maps to the next one, so each measure is uniform over the boxes."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from synthetic_operator import BOX, EXTENT, transition_table

from hhscatter.analysis.geometry import ulam_convergence as uc
from hhscatter.reproduction.operator_cmeasure import measure_distances


def _result():
    """The synthetic table's operator at E = 0.3: every measure is uniform over the 16 box centres."""
    return uc.energy_results(transition_table(), EXTENT, BOX, [1], [16], 16, 2, 2, 1, 0.3)


def _centres(n, energy, rng):
    """n sprinkler points, each at a box centre chosen uniformly: the operator's measure itself."""
    c = rng.integers(0, 16, n)
    return pd.DataFrame({"energy": energy, "x": -0.75 + 0.5 * (c % 4), "y": -0.75 + 0.5 * (c // 4)})


def test_every_measure_at_the_same_energy_and_the_sprinkler_one_across_energies():
    rng = np.random.default_rng(4)
    res = _result()
    pts = pd.concat([_centres(4000, 0.3, rng), _centres(3000, 0.35, rng)], ignore_index=True)
    rows, tab, counts = measure_distances(
        {0.3: res, 0.35: res}, pts, [0.3, 0.35], [0.5, 1.0], EXTENT, 4, 1, 0.5, np.random.default_rng(0)
    )
    assert counts == {0.3: 4000, 0.35: 3000}
    pairs = [(r["fig1_energy"], r["operator_energy"], r["measure"]) for r in rows]
    assert pairs == [
        (0.3, 0.3, "sprinkler"),
        (0.3, 0.3, "flux"),
        (0.3, 0.3, "map"),
        (0.3, 0.35, "sprinkler"),
        (0.35, 0.3, "sprinkler"),
        (0.35, 0.35, "sprinkler"),
        (0.35, 0.35, "flux"),
        (0.35, 0.35, "map"),
    ]
    assert [r["n"] for r in rows] == [4000] * 4 + [3000] * 4
    assert all(r["box"] == 0.5 for r in rows)  # the headline box side
    # the same uniform measure on both sides: the debiased distance is small (sampling noise of a few thousand points)
    assert all(0.0 <= r["hellinger_debiased"] < 0.035 for r in rows)
    assert len(tab) == 8 * 2 and set(tab["kind"]) == {"sprinkler", "flux", "map"}


def test_an_operator_energy_outside_the_comparison_is_left_out():
    rng = np.random.default_rng(5)
    pts = _centres(500, 0.3, rng)
    rows, _, counts = measure_distances(
        {0.3: _result(), 0.4: _result()}, pts, [0.3], [0.5], EXTENT, 2, 0, 0.5, np.random.default_rng(1)
    )
    assert {r["operator_energy"] for r in rows} == {0.3} and counts == {0.3: 500}


def test_a_sample_unlike_the_operator_measure_is_at_the_closed_form_distance():
    """Half of the sample in box 0, half uniform: p = (1/2 + 1/32, 1/32, …) against q = 1/16 each; the Hellinger
    distance √(1 − Σ √(p q)) is 0.3935."""
    rng = np.random.default_rng(6)
    c = np.where(rng.random(8000) < 0.5, 0, rng.integers(0, 16, 8000))
    pts = pd.DataFrame({"energy": 0.3, "x": -0.75 + 0.5 * (c % 4), "y": -0.75 + 0.5 * (c // 4)})
    rows, _, _ = measure_distances({0.3: _result()}, pts, [0.3], [0.5], EXTENT, 4, 1, 0.5, np.random.default_rng(2))
    p = np.full(16, 1 / 32)
    p[0] += 0.5
    exact = np.sqrt(1 - np.sum(np.sqrt(p / 16)))
    assert [r["hellinger_debiased"] for r in rows] == pytest.approx([exact] * 3, abs=0.02)
