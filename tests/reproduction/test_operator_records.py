"""The operator's κ records and their comparison with κ0 (hhscatter.reproduction.operator_records), on one-return
samples whose rate is known in closed form."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.geometry import ulam_convergence as uc
from hhscatter.reproduction.operator_records import kappa_comparisons, kappa_records

EXACT = math.log(4 / 3) / 2  # a quarter of every box leaves per return of time 2: ¾ e^{2κ} = 1


def _samples():
    """16 boxes of side 0.5 over [−1, 1]², 16 samples each: a quarter escape, a quarter return into their own box,
    the rest into the next box."""
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


def _results(energies):
    out = {}
    for E in energies:
        res = uc.energy_results(_samples(), (-1, 1, -1, 1), 0.5, [1, 2], [4, 16], 16, 3, 2, 1, E)
        res["islands"] = {"probes": 10, "trapped_boxes": 0}
        res["cut_boxes"] = uc.measure_on_cut_boxes(res, 16)
        out[E] = res
    return out


@pytest.mark.parametrize("verdicts", [True, False])
def test_kappa_records_keep_the_grid_energies_and_mark_the_others_mixed(verdicts):
    res = _results([0.2, 0.3])
    out = kappa_records(
        res, {0.3: (EXACT, 0.001)}, {}, samples=16, box=0.5, grid_energies=[0.30000000001], verdicts=verdicts
    )
    assert [r["energy"] for r in out["records"]] == [0.3] and out["results"] is res
    (conv,) = out["convergence"]
    assert conv["kappa_inf"] == pytest.approx(EXACT, rel=1e-9) and "cut_share" in conv
    assert ("verdict_kappa0" in conv) is verdicts and "residual_kappa0" in conv
    assert [m["energy"] for m in out["mixed"]] == [0.2, 0.3] and out["mixed"][0]["probes"] == 10
    assert out["mixed"][0]["record"]["note"].startswith("mixed phase space") and "record" not in out["mixed"][1]
    assert len(out["rows"]) == 2 * 4 and [g["kind"].iloc[0] for g in out["grids"]] == ["estimate", "bootstrap"]
    assert (out["grids"][0]["energy"] == 0.3).all()


def test_kappa_comparisons_only_where_both_numbers_are_there():
    conv = [
        {"energy": 0.3, "kappa_inf": 0.2, "err": 0.01, "kappa0": 0.23, "kappa0_err": 0.01, "kappa_finest": 0.19},
        {"energy": 0.35, "kappa_inf": 0.3, "err": 0.01, "kappa0": None},
    ]
    (row,) = kappa_comparisons(conv, 0.01)
    assert (row["ours"], row["err"], row["paper"], row["paper_err"]) == (0.2, 0.01, 0.23, 0.01)
    assert row["verdict"].startswith("differs")  # |0.2 − 0.23| = 0.03 > 2 √(0.01² + 0.01²)
    assert row["note"] == "fig2 ± 0.01; finest boxes 0.01: κ = 0.19"
