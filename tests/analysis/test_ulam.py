"""Ulam's method from one-return samples (hhscatter.analysis.geometry.ulam) on synthetic input with known answers:
the dissipative comparison's steps, κ's extrapolation in box side and samples per box, the residuals."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.geometry import transfer as tf
from hhscatter.analysis.geometry import ulam
from hhscatter.errors import ConfigError


def test_survival_agreement_on_constructed_curves():
    """Operator P = P_sim·e^0.1 (|ln ratio| 0.1 everywhere), reduced P = P_sim·e^(−0.2 t/T); compared while
    P_sim·N ≥ 30."""
    dt, N = 0.5, 1000
    grid = np.arange(0, 201) * dt  # up to t = 100
    P_sim = np.exp(-0.05 * grid)  # P_sim·N ≥ 30 up to t = ln(1000/30)/0.05 = 70.1
    P_op = P_sim * math.exp(0.1)
    P_red = P_sim * np.exp(-0.2 * grid / 100)
    out = ulam.survival_agreement(grid, dt, 20.0, P_sim, P_op, P_red, N)
    t_until = 70.0  # the last grid time with P_sim·N ≥ 30
    assert out["compared_until"] == t_until
    assert out["lnP_rms_operator"] == pytest.approx(0.1, rel=1e-12)
    assert out["lnP_max_operator"] == pytest.approx(0.1, rel=1e-12)
    assert out["lnP_max_reduced"] == pytest.approx(0.2 * t_until / 100, rel=1e-12)
    ok = grid <= t_until
    assert out["lnP_rms_reduced"] == pytest.approx(np.sqrt(np.mean((0.2 * grid[ok] / 100) ** 2)), rel=1e-12)
    # the fixed times within the grid, t* among them, with the binomial error of P_sim
    assert [r["t"] for r in out["P_at"]] == [5.0, 10.0, 20.0, 25.0, 40.0, 60.0, 80.0, 100.0]
    r = out["P_at"][2]
    assert r["sim"] == pytest.approx(math.exp(-1.0), rel=1e-15)
    assert r["sim_err"] == pytest.approx(math.sqrt(math.exp(-1) * (1 - math.exp(-1)) / N), rel=1e-12)
    assert r["operator"] == pytest.approx(math.exp(-0.9), rel=1e-12)


def test_survival_agreement_without_comparable_times_is_nan():
    grid = np.arange(0, 11) * 1.0
    P = np.full(11, 0.01)
    out = ulam.survival_agreement(grid, 1.0, 5.0, P, P, P, 100)  # P·N = 1 < 30 everywhere
    assert all(math.isnan(out[k]) for k in ("lnP_rms_operator", "lnP_max_reduced", "compared_until"))
    assert [r["t"] for r in out["P_at"]] == [5.0, 10.0, 5.0]  # t* = 5 listed where given


def test_survival_agreement_writes_a_simulated_zero_as_its_one_sided_bound():
    grid = np.arange(0, 201) * 0.5
    P_sim = np.where(grid < 90, np.exp(-0.05 * grid), 0.0)  # no orbit of 1000 left from t = 90 on
    out = ulam.survival_agreement(grid, 0.5, 20.0, P_sim, P_sim, P_sim, 1000)
    last = out["P_at"][-1]
    assert last["t"] == 100.0 and last["sim"] == 0 and last["sim_err"] is None
    assert last["sim_upper"] == pytest.approx(1 - 0.05 ** (1 / 1000), abs=1e-6) and last["sim_cl"] == 0.95


def test_t_star_energies_weighted_and_plain_moments():
    pred = pd.DataFrame({"energy": [0.1, 0.2, 0.4], "w": [1.0, 2.0, 1.0]})
    sim = pd.DataFrame({"energy": [0.1, 0.3]})
    out = ulam.t_star_energies(pred, sim)
    mean = (0.1 + 0.4 + 0.4) / 4  # weights 1/4, 2/4, 1/4
    assert out["t_star_mean_energy"]["operator"] == pytest.approx(mean, rel=1e-14)
    var = (0.1 - mean) ** 2 / 4 + 2 * (0.2 - mean) ** 2 / 4 + (0.4 - mean) ** 2 / 4
    assert out["t_star_std_energy"]["operator"] == pytest.approx(math.sqrt(var), rel=1e-12)
    sd = math.sqrt(0.02)  # sample std of (0.1, 0.3)
    assert out["t_star_mean_energy"]["sim"] == pytest.approx(0.2, rel=1e-14)
    assert out["t_star_mean_energy"]["sim_err"] == pytest.approx(sd / math.sqrt(2), rel=1e-12)
    assert out["t_star_std_energy"]["sim"] == pytest.approx(sd, rel=1e-12)
    assert out["t_star_points_sim"] == 2
    # a single simulated point: no spread
    assert math.isnan(ulam.t_star_energies(pred, sim.iloc[:1])["t_star_std_energy"]["sim"])


def test_sample_transitions_merge_boxes_and_keep_the_first_ranks():
    """Four finest boxes (2 × 2 of side 1 over [0, 2]²), two samples each: merged 2 × 2 they are one state; the
    first rank alone keeps one sample per box; a censored sample is dropped; an image outside is an escape."""
    tab = pd.DataFrame(
        {
            "cell": [0, 0, 1, 1, 2, 2, 3, 3],
            "rank": [0, 1] * 4,
            "w": 1.0,
            "ret": [True, True, True, False, True, True, True, True],
            "T": [1.0, 2.0, 1.5, np.nan, 1.0, 1.0, 1.0, 1.0],
            "x1": [0.5, 1.5, 0.5, np.nan, 1.5, 1.5, 5.0, 0.5],
            "y1": [0.5, 0.5, 1.5, np.nan, 1.5, 0.5, 5.0, 0.5],
            "censored": [False] * 7 + [True],
        }
    )
    tr, ids, t = ulam.sample_transitions(tab, (0, 2, 0, 2), 1.0)
    assert len(t) == 7 and tr.n_states == 4 and ids.tolist() == [0, 1, 2, 3]
    assert tr.dst.tolist() == [0, 1, 2, -1, 3, 1, -1]  # (5, 5) lies outside: escape
    one, _, _ = ulam.sample_transitions(tab, (0, 2, 0, 2), 1.0, c=2)
    assert one.n_states == 1 and one.src.tolist() == [0] * 7
    first, _, t1 = ulam.sample_transitions(tab, (0, 2, 0, 2), 1.0, m_max=1)
    assert t1["rank"].tolist() == [0, 0, 0, 0]


def test_saddle_kappa_of_a_uniform_leak():
    """One box that returns with weight share q after time T, else escapes: ρ(M(κ)) = q e^{κT} = 1 → κ = −ln q / T."""
    q, T = 0.75, 2.0
    tr = tf.Transitions([0, 0, 0, 0], [0, 0, 0, -1], [T, T, T, 1.0], 1)
    kap, kmap, info, keep, sub = ulam.saddle_kappa(tr)
    assert kap == pytest.approx(-math.log(q) / T, rel=1e-10) and kmap == pytest.approx(-math.log(q), rel=1e-10)
    assert info["saddle_states"] == 1 and info["closed_classes"] == 0


def test_sequences_are_taken_like_arrays():
    """The state ids, the survival curves and the grid pass their checks as plain sequences: the estimators
    give the same results for lists as for arrays."""
    tr = tf.Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    tr_l, k_l = ulam.reduced_operator(tr, [0, 1], 2, 1)
    tr_a, k_a = ulam.reduced_operator(tr, np.array([0, 1]), 2, 1)
    np.testing.assert_array_equal(tr_l.w, tr_a.w)
    assert k_l == k_a
    n0_l, lost_l = ulam.disk_density(1.0, (-1, 1, -1, 1), 1.0, [0, 1, 2], 4, 0)
    n0_a, lost_a = ulam.disk_density(1.0, (-1, 1, -1, 1), 1.0, np.array([0, 1, 2]), 4, 0)
    np.testing.assert_array_equal(n0_l, n0_a)
    assert lost_l == lost_a == pytest.approx(0.25, abs=1e-3)
    grid = np.arange(11.0)
    curves = [np.exp(-grid / 10), np.exp(-grid / 9), np.exp(-grid / 11)]
    as_lists = ulam.survival_agreement(list(grid), 1.0, 5.0, *[list(c) for c in curves], 1000)
    assert as_lists == ulam.survival_agreement(grid, 1.0, 5.0, *curves, 1000)


def test_energy_states_of_a_section_taller_than_wide():
    """Boxes of side 1 on (−1, 1) × (−2, 2): 2 × 4 = 8 boxes, so the (box, energy bin) state ids are bin·8 + box.
    A sample in box 2 of bin 1 lands in box 7 (x = 0.5, y = 1.5) at an energy of bin 0; one in box 6 of bin 0
    lands in box 0 at an energy of bin 1. The disk r < 0.5 covers boxes 2 … 5 alike, and only box 2 is a state
    of the top bin."""
    tab = pd.DataFrame(
        {
            "cell": [2, 6],
            "rank": [0, 0],
            "w": 1.0,
            "censored": False,
            "ret": [True, True],
            "T": 1.0,
            "x1": [0.5, -0.5],
            "y1": [1.5, -1.5],
            "e1": [0.05, 0.15],
            "ebin": [1, 0],
            "t_end": 1.0,
        }
    )
    tr, ids, _ = ulam.sample_transitions(tab, (-1, 1, -2, 2), 1.0, ebins=[0.0, 0.1, 0.2])
    assert ids.tolist() == [6, 7, 8, 10]  # (bin 0, box 6), (bin 0, box 7), (bin 1, box 0), (bin 1, box 2)
    assert ids[tr.src].tolist() == [10, 6] and ids[tr.dst].tolist() == [7, 8]
    kw = dict(dt=1.0, t_horizon=2.0, t_star=1.0, max_return_time=2.0, radius=0.5)
    op = ulam.dissipative_operator(tab, (-1, 1, -2, 2), 1.0, [0.0, 0.1, 0.2], **kw)
    assert op["n_cells"] == 8
    assert op["lost"] == pytest.approx(0.75, abs=1e-3)


def test_a_disk_on_no_state_is_refused():
    """No state of the top energy bin under the disk: refused, naming the radius (not a density of NaN)."""
    with pytest.raises(ConfigError, match="radius"):
        ulam.disk_density(0.5, (-1, 1, -1, 1), 1.0, np.array([0, 1]), 4, 1)
