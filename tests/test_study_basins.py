"""End-to-end test of the study ``basins`` at SCALE=tiny (built in graph order by conftest's tiny_studies)."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
from scipy import stats


def test_basins_tiny_end_to_end(tiny_studies):
    out = tiny_studies / "basins" / "out" / "tiny"
    nums = json.loads((out / "basins.json").read_text())
    assert (out / "basins.png").stat().st_size > 10_000
    maps = pd.read_parquet(out / "derived" / "basins_maps.parquet")
    n = nums["grid"]
    for p in nums["per_point"]:
        lab = maps[(maps.energy == p["energy"]) & (maps.gamma == p["gamma"])].label.to_numpy().reshape(n, n)
        assert set(np.unique(lab)) <= {-1, 0, 1, 2, 3, 4}
        if p["gamma"] == 0:
            assert not (lab == 3).any()  # nothing settles without drag
            # the three-fold symmetry of the potential: on the rotation-invariant disk r < 0.9 the exits take
            # equal shares within binomial error (counted here from the map, independently of analyze)
            c = (np.arange(n) + 0.5) * 2.0 / n - 1.0
            r = np.hypot(*np.meshgrid(c, c))
            counts = np.bincount(lab[(lab >= 0) & (lab <= 2) & (r < 0.9)], minlength=3)
            assert counts.min() > 0 and stats.chisquare(counts).pvalue > 1e-3, counts
            assert p["channel_symmetry_p"] > 1e-3
        else:
            assert (lab == 3).any()  # with drag some orbits settle
        fr = sum(v["value"] for v in p["fractions"].values())
        assert abs(fr - 1) < 1e-9
    unc = pd.read_parquet(out / "derived" / "basins_uncertainty.parquet")
    assert ((unc.f >= 0) & (unc.f <= 1)).all()
    # f(ε) falls with ε where it is resolved (more ICs change outcome under larger shifts)
    for _, u in unc.groupby(["energy", "gamma"]):
        u = u.sort_values("eps")
        assert u.f.iloc[-1] > u.f.iloc[0]
