"""The operator's κ records and their comparison with κ0 (hhscatter.reproduction.operator_records), on one-return
samples whose rate is known in closed form."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from synthetic_operator import BOX, EXTENT, KAPPA, transition_table

from hhscatter.analysis.geometry import ulam_convergence as uc
from hhscatter.errors import ConfigError
from hhscatter.reproduction.operator_records import (
    convergence_summary,
    cost_row,
    cost_rows,
    dissipative_comparison,
    kappa_comparisons,
    kappa_record,
    kappa_records,
    probe_islands,
)


def _results(energies):
    out = {}
    for E in energies:
        res = uc.energy_results(transition_table(), EXTENT, BOX, [1, 2], [4, 16], 16, 3, 2, 1, E)
        res["islands"] = {"probes": 10, "trapped_boxes": 0}
        res["cut_boxes"] = uc.measure_on_cut_boxes(res, 16)
        out[E] = res
    return out


@pytest.mark.parametrize("verdicts", [True, False])
def test_kappa_records_keep_the_grid_energies_and_mark_the_others_mixed(verdicts):
    res = _results([0.2, 0.3])
    out = kappa_records(
        res, {0.3: (KAPPA, 0.001)}, {}, samples=16, box=0.5, grid_energies=[0.30000000001], verdicts=verdicts
    )
    assert [r["energy"] for r in out["records"]] == [0.3] and out["results"] is res
    (conv,) = out["convergence"]
    assert conv["kappa_inf"] == pytest.approx(KAPPA, rel=1e-9) and "cut_share" in conv
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


def test_probe_islands_marks_the_boxes_of_the_censored_probes_only():
    res = uc.energy_results(transition_table(), EXTENT, BOX, [1], [16], 16, 0, 1, 1, 0.3)
    cells = np.arange(16)
    outcomes = np.array(["escaped"] * 16, dtype=object)
    outcomes[[3, 7]] = "censored"
    outcomes[11] = "stopped"  # a probe stopped early says nothing about its box
    rec = probe_islands(cells, outcomes, res["tr"], res["ids"], res["keep"], res["sub"])
    assert rec["probes"] == 16 and rec["trapped_boxes"] == 2
    assert rec["trapped_share_of_saddle_class"] == pytest.approx(2 / 16)  # every box is on the saddle's class
    assert "kappa_without_trapped_boxes" in rec and len(rec["modes_P"]) == 4
    none = probe_islands(cells, ["escaped"] * 16, res["tr"], res["ids"], res["keep"], res["sub"])
    assert none["trapped_boxes"] == 0 and none["trapped_share_of_saddle_class"] == 0.0
    assert "kappa_without_trapped_boxes" not in none


def test_cost_rows_scale_each_route_to_the_target_error():
    rng = np.random.default_rng(7)
    t = rng.exponential(1 / 0.05, 20000)
    lt = pd.DataFrame({"outcome": np.where(t > 100.0, "censored", "escaped"), "t_end": np.minimum(t, 100.0)})
    rec = {"energy": 0.3, "kappa": 0.05, "kappa_stat_err": 0.001, "discretisation_bias": -0.0005, "err": 0.0012,
           "orbit_time": 1e5}  # fmt: skip
    rows = cost_rows({0.3: lt, 0.4: lt}, [rec], {0.3: (0.049, 0.0005)}, 0.01)
    assert [r["energy"] for r in rows] == [0.3, 0.4]
    a, b = rows
    assert abs(a["pt_kappa"] - 0.05) < 4 * a["pt_err"] and a["pt_err"] < 0.05 / 50
    assert a["pt_orbits"] == 20000 and a["pt_orbit_time"] == pytest.approx(float(np.minimum(t, 100.0).sum()))
    assert a["pt_orbit_time_1pct"] == pytest.approx(a["pt_orbit_time"] * (a["pt_rel"] / 0.01) ** 2)
    assert (a["fig2_kappa"], a["fig2_err"]) == (0.049, 0.0005) and math.isnan(b["fig2_kappa"])
    # the operator's route: statistics 2 % and bias 1 % against 0.71 % each: factors 8 and 2, the larger counts
    assert a["op_rel"] == pytest.approx(0.024) and a["op_orbit_time_1pct"] == pytest.approx(8e5)
    assert a["pt_rel_at_op_cost"] == pytest.approx(a["pt_rel"] * math.sqrt(a["pt_orbit_time"] / 1e5))
    assert "op_kappa" not in b


def _halving_ensemble():
    """1024 orbits of which half leave at every unit of time (t_end = 1 … 10, the last one censored at 12), and the
    first crossings after t* = 2 of those alive at 2.5 (uniform positions; energy 0.35 at t = 0.5, 0.3 at 2.5)."""
    t_end = np.concatenate([np.full(2 ** (10 - j), float(j)) for j in range(1, 11)] + [[12.0]])
    lt = pd.DataFrame({"traj_id": np.arange(1024), "outcome": ["escaped"] * 1023 + ["censored"], "t_end": t_end})
    alive = np.flatnonzero(t_end > 2.5)
    rng = np.random.default_rng(0)
    sec = pd.DataFrame(
        {
            "traj_id": np.repeat(alive, 2),
            "t": np.tile([0.5, 2.5], len(alive)),
            "x": rng.uniform(-1, 1, 2 * len(alive)),
            "y": rng.uniform(-1, 1, 2 * len(alive)),
            "energy": np.tile([0.35, 0.3], len(alive)),
        }
    )
    return lt, sec


def test_dissipative_comparison_of_an_operator_and_an_ensemble_that_both_halve_per_unit_time():
    # four unit boxes, one energy bin; of every box's 8 samples half come back to the box's centre after a time 1,
    # half leave at time 1: the operator's P(t) is 2^−t, and so is the ensemble's
    cell, rank = np.repeat(np.arange(4), 8), np.tile(np.arange(8), 4)
    tab = pd.DataFrame(
        {
            "cell": cell,
            "rank": rank,
            "w": 1.0,
            "censored": False,
            "ret": rank % 2 == 0,
            "T": 1.0,
            "t_end": 1.0,
            "x1": -0.5 + cell % 2,
            "y1": -0.5 + cell // 2,
            "e1": 0.3,
            "ebin": 0,
        }
    )
    lt, sec = _halving_ensemble()
    numbers, curves, pts, dtab = dissipative_comparison(
        tab, lt, sec, extent=(-1, 1, -1, 1), box=1.0, edges=np.array([0.2, 0.4]), radius=1.0, dt=1.0,
        t_horizon=10.0, t_star=2.0, max_return_time=3.0, boxes=[1.0, 0.5], n_splits=2, seed=1, box_headline=0.5,
        energy=0.3, gamma=0.01,
    )  # fmt: skip
    exact = 0.5 ** np.arange(11)
    assert curves["t"].tolist() == list(range(11))
    for col in ("sim", "operator", "reduced"):
        assert curves[col].to_numpy() == pytest.approx(exact, rel=1e-12)
    assert (numbers["energy"], numbers["gamma"], numbers["t_star"], numbers["dt"]) == (0.3, 0.01, 2.0, 1.0)
    assert numbers["states"] == 4 and numbers["samples"] == 32 and numbers["initial_mass_lost"] == 0.0
    assert numbers["sim_orbits"] == 1024 and numbers["sim_orbit_time"] == float(lt["t_end"].sum())
    assert numbers["operator_orbit_time"] == 32.0
    assert numbers["lnP_max_operator"] == pytest.approx(0.0, abs=1e-12)
    assert numbers["compared_until"] == 5.0  # 1024 · 2^−5 = 32 ≥ 30 orbits, 2^−6 · 1024 = 16 < 30
    (kb,) = numbers["kappa_bins"]
    assert kb["kappa"] == pytest.approx(math.log(2), rel=1e-12)
    at = {r["t"]: r for r in numbers["P_at"]}
    assert at[2.0]["sim"] == 0.25 and at[2.0]["sim_err"] == pytest.approx(math.sqrt(0.25 * 0.75 / 1024))
    # after t* = 2: the operator's crossings at the four box centres carry the mass P(2) = 1/4; the simulated
    # ones are the crossings at 2.5 of the 256 orbits alive then (energy 0.3, not the 0.35 of t = 0.5)
    op, sim = pts[pts["set"] == "operator"], pts[pts["set"] == "sim"]
    assert op["w"].sum() == pytest.approx(0.25) and set(zip(op["x"], op["y"])) == {
        (-0.5, -0.5),
        (0.5, -0.5),
        (-0.5, 0.5),
        (0.5, 0.5),
    }
    assert len(sim) == numbers["t_star_points_sim"] == 256 and (sim["energy"] == 0.3).all()
    assert numbers["t_star_mean_energy"]["operator"] == pytest.approx(0.3)
    assert numbers["t_star_mean_energy"]["sim"] == pytest.approx(0.3)
    # both spread evenly over the four unit boxes: no distance at side 1 beyond the noise
    assert dtab["box"].tolist() == [1.0, 0.5] and dtab["hellinger_debiased"].iloc[0] == pytest.approx(0.0, abs=0.05)
    assert numbers["t_star_hellinger_debiased"]["box"] == 0.5


# -- the pieces: each refuses a wrong argument before any work, naming it --------------------------------------
PT = {"kappa": 0.05, "kappa_err": 0.001, "orbits": 5000, "orbit_time": 1e5}
RECORDS = [{"energy": 0.3, "kappa_inf": 0.2, "z_kappa0": 0.5, "residual_kappa0": 0.01}]
PIECES = {
    "kappa_record": (kappa_record, {"E": 0.3, "res": _results([0.3])[0.3], "samples": 16, "box": 0.5}),
    "convergence_summary": (convergence_summary, {"records": RECORDS}),
    "cost_row": (cost_row, {"E": 0.3, "pt": PT, "rec": None, "kappa0": {}, "target": 0.01}),
}
WRONG = [
    ("kappa_record", "res", {"rows": []}),
    ("kappa_record", "kappa0", (0.1,)),
    ("kappa_record", "box", 0.0),
    ("convergence_summary", "records", "x"),
    ("convergence_summary", "records", [{"kappa_inf": 0.2}]),
    ("convergence_summary", "z_agree", 0.0),
    ("cost_row", "pt", {"kappa": 0.05}),
    ("cost_row", "target", 0.0),
]


@pytest.mark.parametrize("name", sorted(PIECES))
def test_the_valid_call_of_a_piece_runs(name):
    f, kwargs = PIECES[name]
    assert f(**kwargs)


@pytest.mark.parametrize(("name", "arg", "bad"), WRONG, ids=[f"{n}-{a}-{i}" for i, (n, a, _) in enumerate(WRONG)])
def test_a_wrong_argument_of_a_piece_is_refused_naming_it(name, arg, bad):
    f, kwargs = PIECES[name]
    with pytest.raises(ConfigError, match=arg):
        f(**{**kwargs, arg: bad})
