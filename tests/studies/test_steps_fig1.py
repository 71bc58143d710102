"""Steps of study fig1's analysis: the potential grid of Fig. 1a against the Hénon–Heiles potential in closed form."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from hhscatter.studies import load_study, stage_module

mod = stage_module("fig1")


def test_potential_grid_is_the_henon_heiles_potential_on_a_square_grid():
    written = {}
    study = SimpleNamespace(
        params=SimpleNamespace(grid_half_width=0.8, grid_points=5),
        model=load_study("fig1", "tiny").model,
        write_table=lambda df, name, **meta: written.update({name: (df, meta)}),
    )
    mod._write_potential_grid(study)
    df, meta = written["potential_grid.parquet"]
    assert len(df) == 25 and "5×5" in meta["description"]
    g = np.array([-0.8, -0.4, 0.0, 0.4, 0.8])
    assert np.allclose(np.unique(df["x"]), g) and np.allclose(np.unique(df["y"]), g)
    x, y = df["x"].to_numpy(), df["y"].to_numpy()
    np.testing.assert_allclose(df["V"], 0.5 * (x**2 + y**2) + x**2 * y - y**3 / 3, rtol=1e-14, atol=1e-15)
