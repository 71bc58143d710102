"""The record of one c-measure run (hhscatter.reproduction.fig1) on synthetic lifetimes and crossings."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from hhscatter.reproduction.fig1 import POINT_COLUMNS, energy_record

KAPPA, N = 0.04, 20_000


def _run(t_rec=30.0, seed=7):
    rng = np.random.default_rng(seed)
    t_end = rng.exponential(1 / KAPPA, N)
    lt = pd.DataFrame({"traj_id": np.arange(N), "e0": 0.35, "gamma": 0.0, "outcome": "escaped", "t_end": t_end})
    alive = np.flatnonzero(t_end > t_rec)
    sec = pd.DataFrame(
        {
            "traj_id": alive,
            "t": t_rec + rng.uniform(0.0, 3.0, alive.size),
            "x": rng.uniform(-0.5, 0.5, alive.size),
            "y": rng.uniform(-0.5, 0.5, alive.size),
            "px": 0.0,
            "py": 0.1,
            "energy": 0.35 + rng.uniform(-1e-10, 2e-10, alive.size),
        }
    )
    return lt, sec


def test_the_record_counts_survivors_and_points_and_measures_the_run_own_rate():
    lt, sec = _run()
    choice = {"t_rec": 30.0, "kappa": 0.041, "kappa_err": 0.002, "tau0": 3.0, "t_stop": 90.0, "n_pilot": 500}
    rec, pts = energy_record(0.35, choice, 130.0, lt, sec, 31.0, "raw/E0.35")
    survivors = int(np.sum(lt["t_end"] > 30.0))
    assert rec["n_survivors_at_t_rec"] == survivors == rec["n_points"] and rec["n_orbits"] == N
    assert rec["t_rec_times_kappa"] == pytest.approx(30.0 * 0.041)
    assert rec["fit_window_pilot"] == [3.0, 90.0] and rec["kappa_used"] == {"value": 0.041, "err": 0.002}
    assert (rec["t_max"], rec["t_rec_rule_with_current_code"], rec["raw_run"]) == (130.0, 31.0, "raw/E0.35")
    assert rec["max_energy_deviation"] == pytest.approx(np.max(np.abs(sec["energy"] - 0.35)))
    own = rec["kappa_main_run"]
    assert abs(own["value"] - KAPPA) < 4 * own["err"] and own["err"] < 0.1 * KAPPA  # the exponential's rate
    assert list(pts.columns) == POINT_COLUMNS and (pts["energy"] == 0.35).all()
    np.testing.assert_array_equal(pts["e_cross"], sec["energy"])
    np.testing.assert_array_equal(pts[["x", "y"]].to_numpy(), sec[["x", "y"]].to_numpy())


def test_a_run_without_crossings_has_no_energy_deviation():
    lt, sec = _run()
    choice = {"t_rec": 30.0, "kappa": 0.04, "kappa_err": 0.002, "tau0": 3.0, "t_stop": 90.0, "n_pilot": 500}
    rec, pts = energy_record(0.35, choice, 130.0, lt, sec.iloc[:0], 30.0, "raw/E0.35")
    assert rec["max_energy_deviation"] == 0.0 and rec["n_points"] == 0 and len(pts) == 0
