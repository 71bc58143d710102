"""The escape-criterion analysis (hhscatter.reproduction.escape_criterion): the common window, the paired κ
shift, the returns, the exit channels and the recommended r_esc, on synthetic ensembles with a known answer."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hhscatter.reproduction.escape_criterion import (
    channel_rows,
    common_window,
    criterion_numbers,
    follow_returns,
    kappa_row,
    paired_runs,
    recommend_r_esc,
    return_quantity,
    returns_row,
    with_return_counts,
)

KAPPA = 0.1


def _paired(n=20000, scale=0.8, seed=3):
    t = np.random.default_rng(seed).exponential(1 / KAPPA, n)
    obs = np.ones(n, bool)
    return {1.5: (t, obs), 2.0: (t * scale, obs)}  # t·0.8: the same orbits escaping at rate κ/0.8


def test_common_window_starts_after_the_reference_curve_fell_to_p_start():
    arrs = _paired()
    _, own, win = common_window(arrs, [1.5, 2.0], 1.5, 0.1)
    assert win[0] >= math.log(10) / KAPPA - 1.0  # P_ref = e^{-κt} reaches 0.1 at t = ln 10/κ ≈ 23
    assert win[1] > win[0] and all(own[r] is not None for r in (1.5, 2.0))
    assert own[1.5].kappa == pytest.approx(KAPPA, rel=0.05)


def test_kappa_row_measures_the_shift_of_a_faster_paired_ensemble():
    arrs = _paired()
    _, own, win = common_window(arrs, [1.5, 2.0], 1.5, 0.1)
    row, ps = kappa_row(0.3, 2.0, 1.5, arrs, own, win, n_groups=16)
    expected = KAPPA / 0.8 - KAPPA  # exactly 0.025 in law
    assert abs(row["kappa_shift"] - expected) < 3 * row["kappa_shift_err"] and row["kappa_shift_err"] < 0.01
    assert row["kappa"] == pytest.approx(KAPPA / 0.8, rel=0.05) and ps.kappa_ref == pytest.approx(KAPPA, rel=0.05)
    assert row["dt_end_mean"] == pytest.approx(-0.2 * arrs[1.5][0].mean())  # t_alt − t_ref = −0.2 t_ref
    assert math.isnan(row["flight_mean"]) and math.isnan(row["kappa_shift_follow"])  # no follow runs given
    ref, _ = kappa_row(0.3, 1.5, 1.5, arrs, own, win, n_groups=16)
    assert (ref["kappa_shift"], ref["kappa_shift_err"], ref["time_shift"]) == (0.0, 0.0, 0.0)


def test_kappa_row_flight_time_on_identical_trajectories():
    arrs = _paired()
    _, own, win = common_window(arrs, [1.5, 2.0], 1.5, 0.1)
    t_ref = np.array([1.0, 2.0, np.nan, 4.0])
    returns = {1.5: {"t_esc": t_ref}, 2.0: {"t_esc": t_ref + np.array([0.5, 1.5, 0.0, np.nan])}}
    row, _ = kappa_row(0.3, 2.0, 1.5, arrs, own, win, returns, np.full(4, 100.0), n_groups=16)
    assert (row["flight_mean"], row["flight_median"]) == (1.0, 1.0)  # orbits 0 and 1: 0.5 and 1.5
    assert row["flight_err"] == pytest.approx(np.std([0.5, 1.5], ddof=1) / math.sqrt(2))


def _returns(frac_back):
    n = 100
    t_esc = np.linspace(1.0, 100.0, n)
    back = np.arange(n) < frac_back * n
    return {
        "t_esc": t_esc,
        "returned": back,
        "t_return": np.where(back, t_esc + 1.0, np.nan),
        "t_reesc": np.where(back, t_esc + 6.0, np.nan),
    }


def test_returns_row_counts_returns_with_wilson_intervals_and_the_fast_reescapes():
    follow = pd.DataFrame({"outcome": ["escaped"] * 99 + ["censored"], "energy_error": np.full(100, 1e-12)})
    lyap = SimpleNamespace(r_min=1.0, r_max=1.2)
    row = returns_row(0.3, 1.03, _returns(0.1), np.zeros(100, bool), (50.0, 90.0), 0.1, lyap, follow, fast=10.0)
    assert (row["n_escaped"], row["n_returned"], row["n_reescaped"], row["n_fast"]) == (100, 10, 10, 10)
    assert row["frac"] == pytest.approx(0.1, abs=0.01) and row["lo"] < 0.1 < row["hi"]
    assert (row["n_escaped_late"], row["n_returned_late"]) == (50, 0)  # the returning orbits escaped early
    assert row["stay_median"] == 5.0 and row["n_censored_follow"] == 1
    none = returns_row(0.3, 2.0, _returns(0.0), np.zeros(100, bool), (50.0, 90.0), 0.1, lyap, follow)
    assert none["n_returned"] == 0 and math.isnan(none["stay_median"]) and math.isnan(none["frac_fast"])


def test_channel_rows_split_all_early_and_late_escapes():
    ch = np.array([0, 0, 1, 2, 2, 2, -1])
    t = np.array([1.0, 20.0, 2.0, 3.0, 30.0, 40.0, 50.0])
    rows = pd.DataFrame(channel_rows(0.3, 1.5, ch, t, (10.0, 60.0)))
    counts = rows.pivot(index="subset", columns="channel", values="count")
    assert counts.loc["all"].tolist() == [2, 1, 3] and counts.loc["early"].tolist() == [1, 1, 1]
    assert counts.loc["late"].tolist() == [1, 0, 2]
    assert rows.loc[rows["subset"] == "early", "frac"].tolist() == pytest.approx([1 / 3] * 3)


def test_recommend_r_esc_is_the_smallest_radius_beyond_the_lyapunov_orbit_without_returns():
    ret = pd.DataFrame({"r_esc": [1.03, 1.1, 1.5, 2.0] * 2, "n_returned": [5, 0, 0, 0, 2, 1, 0, 0]})
    lyap = pd.DataFrame({"energy": [0.25, 0.35], "r_max": [1.05, 1.2]})
    assert recommend_r_esc(ret, lyap, 1.03)["recommended"] == 1.5  # 1.1 has a return and is inside r_max = 1.2
    assert recommend_r_esc(ret.assign(n_returned=1), lyap, 1.03)["recommended"] == 2.0  # none qualifies: the largest


def _kappa_and_returns():
    """κ and return tables at E = 0.3, r_esc = 1.5 (the reference) and 2.0, as kappa_row and returns_row give them."""
    kap = pd.DataFrame(
        {
            "energy": [0.3, 0.3],
            "r_esc": [1.5, 2.0],
            **{c: [0.1, 0.1] for c in ("kappa", "kappa_err", "kappa_lsq", "kappa_lsq_err", "t_start", "t_stop")},
            **{
                c: [0.0, 0.001]
                for c in (
                    "kappa_shift",
                    "kappa_shift_err",
                    "mle_shift",
                    "mle_shift_err",
                    "kappa_shift_follow",
                    "kappa_shift_follow_err",
                    "time_shift",
                    "flight_mean",
                    "flight_err",
                    "dt_end_mean",
                    "dt_end_err",
                )
            },
        }
    )
    ret = pd.DataFrame(
        {"energy": [0.3, 0.3], "r_esc": [1.5, 2.0], "n_returned": [0, 0], "kappa_ref": [0.1, 0.1]}
        | {c: [0.0, 0.0] for c in ("frac", "lo", "hi", "upper95", "frac_late", "lo_late", "hi_late", "t_late")}
        | {c: [0, 0] for c in ("n_escaped", "n_recrossed", "n_reescaped", "stay_median", "stay_mean")}
        | {c: [0.0, 0.0] for c in ("frac_fast", "frac_fast_lo", "frac_fast_hi")}
    )
    return kap, ret


def test_criterion_numbers_compare_shifts_returns_and_channels():
    kap, ret = _kappa_and_returns()
    chan = pd.DataFrame(channel_rows(0.3, 1.5, np.array([0, 1, 2]), np.array([1.0, 2.0, 3.0]), (10.0, 20.0)))
    lyap = pd.DataFrame({"energy": [0.3], "r_min": [1.0], "r_max": [1.2], "period": [6.0]})
    numbers, rows = criterion_numbers([0.3], [1.5, 2.0], 1.5, kap, ret, chan, lyap, r_in=1.0, fast=10.0)
    assert [r["quantity"] for r in rows] == [
        "κ(E=0.30, r_esc=2) − κ(r_esc=1.5)",
        "fraction returning inside r<1 after crossing r_esc=1.5 (E=0.30)",
        "fraction returning inside r<1 after crossing r_esc=2 (E=0.30)",
        "escape fraction through channel 0 (E=0.30, r_esc=1.5)",
        "escape fraction through channel 1 (E=0.30, r_esc=1.5)",
        "escape fraction through channel 2 (E=0.30, r_esc=1.5)",
    ]
    assert rows[-1]["paper"] == pytest.approx(1 / 3) and rows[0]["paper"] == 0.0
    assert numbers["default_r_esc"]["recommended"] == 1.5
    # the reference radius is recorded as the authors' value, not as a "current" default
    assert numbers["default_r_esc"]["authors"] == 1.5 and "current" not in numbers["default_r_esc"]
    assert numbers["returns"]["E=0.30"]["r_esc=2"]["typical_survivor_fraction_within_reesc_fast"] == pytest.approx(
        1 - math.exp(-1.0)
    )
    assert numbers["channels"]["E=0.30"]["r_esc=1.5"]["all"]["channel 0"]["value"] == pytest.approx(1 / 3)


def test_channel_rows_state_the_family_chi2_and_the_chance_count():
    """Each channel row's note gives the χ² p-value of its energy's three fractions (scipy's chisquare of the counts,
    computed here independently) and how many of the rows a 2σ rule flags by chance under exact symmetry
    (3 rows × erfc(√2) ≈ 0.14)."""
    from scipy import stats

    counts = np.array([300, 360, 340])
    ch = np.repeat([0, 1, 2], counts)
    chan = pd.DataFrame(channel_rows(0.3, 1.5, ch, np.linspace(1.0, 50.0, ch.size), (10.0, 20.0)))
    kap, ret = _kappa_and_returns()
    lyap = pd.DataFrame({"energy": [0.3], "r_min": [1.0], "r_max": [1.2], "period": [6.0]})
    _, rows = criterion_numbers([0.3], [1.5, 2.0], 1.5, kap, ret, chan, lyap, r_in=1.0, fast=10.0)
    notes = [r["note"] for r in rows if r["quantity"].startswith("escape fraction")]
    p = stats.chisquare(counts).pvalue
    assert len(notes) == 3
    assert all(f"χ² p = {p:.2g}" in n and "0.1 of these 3 rows lie beyond 2σ by chance" in n for n in notes)


def test_the_lyapunov_table_spans_every_exit_of_the_system_it_is_given():
    """lyapunov_table reads the exits from the system (no Hénon–Heiles default): the row of a Hénon–Heiles with its
    symmetry broken (+ 0.03 x³: three saddles at three energies) covers each exit's Lyapunov orbit; Hénon–Heiles'
    three exits give exit 0's extent (three-fold symmetry)."""
    from hhscatter.analysis.geometry.channels import lyapunov_orbit
    from hhscatter.model import HenonHeiles
    from hhscatter.model.spec import system_from_spec
    from hhscatter.reproduction.escape_criterion import lyapunov_table

    bar = system_from_spec({"potential": "x**2/2 + y**2/2 + x**2*y - y**3/3 + 0.03*x**3"})
    E = max(e.energy for e in bar.exits) + 0.05
    (row,) = lyapunov_table([E], bar).itertuples()
    each = [lyapunov_orbit(E, bar, exit=k) for k in range(len(bar.exits))]
    assert row.n_exits == len(bar.exits) == 3
    assert row.r_max == max(L.r_max for L in each) and row.r_min == min(L.r_min for L in each)
    assert len({round(L.r_max, 6) for L in each}) > 1  # the exits differ: exit 0 alone would not do
    hh = HenonHeiles()
    (row,) = lyapunov_table([0.25], hh).itertuples()
    L0 = lyapunov_orbit(0.25, hh)
    assert row.n_exits == 3 and abs(row.r_max - L0.r_max) < 1e-9 and abs(row.period - L0.period) < 1e-9


def test_paired_runs_read_the_reference_first_and_refuse_other_orbits():
    ids = np.arange(4)
    runs = {r: (ids, np.full(4, r), np.ones(4, bool), np.full(4, 1, np.int8)) for r in (1.5, 2.0)}
    order = []

    def read(r):
        order.append(r)
        return runs[r]

    arrs, chans = paired_runs(read, [1.5, 2.0], 2.0, 0.3)
    assert order == [2.0, 1.5] and arrs[1.5][0].tolist() == [1.5] * 4 and chans[2.0].tolist() == [1] * 4
    runs[1.5] = (ids[::-1],) + runs[1.5][1:]
    with pytest.raises(ValueError, match=r"E=0.3: runs r_esc=1.5 and 2.0 do not hold the same orbits"):
        paired_runs(runs.get, [1.5, 2.0], 2.0, 0.3)


def test_follow_returns_of_an_orbit_that_comes_back_and_one_that_leaves():
    # orbit 1 (listed first, unsorted): out through 1.5 and 2.0 for good; orbit 0: out through 1.5, back inside
    # r_in = 1 at t = 4, out again through 1.5 at t = 6 and 2.0 at t = 7
    cross = pd.DataFrame(
        {
            "traj_id": [1, 1, 0, 0, 0, 0, 0, 0],
            "t": [2.0, 3.0, 1.0, 4.0, 2.0, 6.0, 3.5, 7.0],
            "radius": [1.5, 2.0, 1.5, 1.0, 1.5, 1.5, 1.0, 2.0],
            "direction": [1, 1, 1, -1, -1, 1, 1, 1],
        }
    )
    ends = pd.DataFrame(
        {"traj_id": [1, 0], "outcome": "escaped", "t_end": [3.0, 7.0], "e0": [0.3, 0.3], "e_end": [0.31, 0.29]}
    )
    ends, rs, back = follow_returns(cross, ends, [1.5, 2.0], 1.0)
    assert ends["traj_id"].tolist() == [0, 1]
    np.testing.assert_allclose(ends["energy_error"], [0.01, 0.01])
    assert rs[1.5]["returned"].tolist() == [True, False] and rs[1.5]["t_return"][0] == 4.0
    assert rs[1.5]["t_reesc"][0] == 6.0 and rs[2.0]["returned"].tolist() == [False, False]
    assert back[1.5].tolist() == [True, False] and back[2.0].tolist() == [False, False]


def test_a_return_row_without_returns_states_its_count_and_no_sigma():
    """No return among the n escaped orbits: the row carries n (for its one-sided bound) and no Wilson σ, so that it
    is read as "< bound (95 %)" and judged by the bound, never as "0 ± σ" with a z-score."""
    from hhscatter.publish.formatting import ours_cell
    from hhscatter.reproduction.verdicts import row_verdict

    kap, ret = _kappa_and_returns()
    ret = ret.assign(n_escaped=[60000, 60000], n_returned=[3, 0], frac=[3 / 60000, 0.0], hi=[1e-4, 1.7e-5])
    chan = pd.DataFrame(channel_rows(0.3, 1.5, np.array([0, 1, 2]), np.array([1.0, 2.0, 3.0]), (10.0, 20.0)))
    lyap = pd.DataFrame({"energy": [0.3], "r_min": [1.0], "r_max": [1.2], "period": [6.0]})
    _, rows = criterion_numbers([0.3], [1.5, 2.0], 1.5, kap, ret, chan, lyap, r_in=1.0, fast=10.0)
    some, none = (next(row for row in rows if row["quantity"] == return_quantity(1.0, r, 0.3)) for r in (1.5, 2.0))
    assert some["n"] == none["n"] == 60000
    assert some["err"] == pytest.approx(0.5e-4) and none["err"] is None
    assert ours_cell(none) == "< 5.0e-5 (95 %)"  # 1 − 0.05^(1/60000) = 4.99e-5
    assert row_verdict(none) == "consistent (bound)" and row_verdict(some) == "agrees (z = +1.0)"  # 3 returns: a z


def test_return_rows_written_without_their_count_take_it_from_the_returns_record():
    """A record written before the rows carried n: its row "0 ± 5e-7" (half the Wilson 1σ interval at n = 10⁶) is
    read as the bound 1 − 0.05^(1/10⁶) ≈ 3.0e-6 from the record's n_escaped; other rows and other studies' numbers
    stay as they are."""
    from hhscatter.publish.formatting import comparison_table

    q = return_quantity(1.0, 1.5, 0.25)
    doc = {
        "config": {"study": {"r_in": 1.0}},
        "returns": {"E=0.25": {"r_esc=1.5": {"n_escaped": 1000000, "n_returned": 0}}},
        "paper_comparison": [
            {"quantity": q, "ours": 0.0, "err": 4.999995e-07, "paper": 0.0, "verdict": "agrees within 2σ"},
            {"quantity": "κ shift", "ours": 0.001, "err": 0.001, "paper": 0.0},
        ],
    }
    rows = with_return_counts(doc)["paper_comparison"]
    assert rows[0]["n"] == 1000000 and "n" not in rows[1]
    table = comparison_table(rows, scale="paper")
    assert "| < 3.0e-6 (95 %) |" in table and "| consistent (bound) |" in table
    assert "± 5" not in table.splitlines()[2] and "z = +0.0" not in table
    assert with_return_counts({"paper_comparison": rows[1:]}) == {"paper_comparison": rows[1:]}
    assert "n" not in doc["paper_comparison"][0]  # the record itself is not changed


def test_a_returns_record_states_the_count_of_each_fraction_so_a_zero_reads_as_its_bound():
    """The folded numbers table writes each leaf by format_value: a fraction of 0 of n = 60 000 reads as the bound
    1 − 0.05^(1/60000) ≈ 5.0e-5 of the comparison row, never "0 [0, 1.7e-05]". Records written before the fractions
    carried n get it from n_escaped; the late fraction from its Wilson 1σ interval, whose upper end at 0 of n is
    1/(n + 1)."""
    from hhscatter.publish.formatting import format_value

    cell = {
        "n_escaped": 60000,
        "n_returned": 0,
        "fraction": {"value": 0.0, "lo": 0.0, "hi": 1 / 60001, "upper95": 6.4e-05},
        "fraction_late": {"value": 0.0, "lo": 0.0, "hi": 1 / 6394, "t_late": 13.0},
    }
    doc = {"config": {"study": {"r_in": 1.0, "z": 1.0}}, "returns": {"E=0.30": {"r_esc=1.5": cell}}}
    out = with_return_counts(doc)["returns"]["E=0.30"]["r_esc=1.5"]
    assert format_value(out["fraction"]) == "< 5.0e-5 (95 %)"  # 1 − 0.05^(1/60000) = 4.99e-5
    assert out["fraction_late"]["n"] == 6393
    assert format_value(out["fraction_late"]) == "< 4.7e-4 (95 %)"  # 1 − 0.05^(1/6393) = 4.69e-4
    assert "n" not in cell["fraction"]  # the record itself is not changed
    some = {"value": 0.003, "lo": 0.0027, "hi": 0.0032, "n": 60000}
    assert format_value(some) == "0.003 [0.0027, 0.0032]"


def test_returns_row_writes_the_one_sided_bound_of_a_count_of_zero():
    """``upper95`` of a cell without a return is 1 − 0.05^(1/n) (the tables' bound), not the two-sided 95 % Wilson
    upper end 1.96²/(n + 1.96²)."""
    from types import SimpleNamespace as NS

    n = 500
    s = {
        "t_esc": np.arange(1.0, n + 1.0),
        "returned": np.zeros(n, bool),
        "t_return": np.full(n, np.nan),
        "t_reesc": np.full(n, np.nan),
    }
    follow = pd.DataFrame({"outcome": ["escaped"] * n, "energy_error": [0.0] * n})
    row = returns_row(0.3, 1.5, s, np.zeros(n, bool), (10.0, 50.0), 0.1, NS(r_min=1.1, r_max=1.3), follow)
    assert row["upper95"] == pytest.approx(1 - 0.05 ** (1 / n), rel=1e-12)
