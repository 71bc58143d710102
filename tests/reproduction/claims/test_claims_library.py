"""The claims' analysis (hhscatter.reproduction.claims): a reason per κ convention, claim 6 independent of the order of
the systems, the evidence records."""

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hhscatter.model.spec import system_from_spec
from hhscatter.reproduction.claims.dissipative import claim6
from hhscatter.reproduction.claims.evidence import (
    first_below,
    indicator_record,
    kappa0_defined_by_rule,
    kappa0_rule,
    labelled_selection,
    long_time_record,
    regular_record,
    total_error,
    validity_map,
)
from hhscatter.reproduction.claims.kappa import kappa_rows
from hhscatter.reproduction.claims.records import Claims


class _Runs:
    def __init__(self, params, tables):
        self.params, self.tables = params, tables

    def lifetimes(self, key):
        return self.tables[key]


def _lt(t, censored=()):
    out = np.where(np.isin(np.arange(len(t)), censored), "censored", "escaped")
    return pd.DataFrame({"traj_id": np.arange(len(t)), "t_end": t, "outcome": pd.Categorical(out)})


def test_each_kappa_convention_carries_its_own_reason():
    # too few orbits for the window rule, in all orbits and in the escaping ones: each row says its own failure
    p = SimpleNamespace(ratios=[1.5], min_survivors=50.0, max_plateau_bias=0.1, p_levels=[0.5, 0.01], alt_region="well")
    t = np.random.default_rng(1).exponential(10.0, 30)
    runs = _Runs(p, {"s_r1.500": _lt(t), "s_well_r1.500": _lt(t)})
    rows = {r["convention"]: r for r in kappa_rows(runs, "s", system_from_spec({"name": "henon_heiles"}))[0]}
    assert rows["plateau"]["reason"].startswith("window rule failed: ")
    assert rows["escaping"]["reason"].startswith("window rule failed on the escaping orbits: ")
    assert rows["well"]["reason"].startswith("window rule failed with well ICs: ")


def _fit(rms):
    return SimpleNamespace(rms_log_residual=rms, chi2_red=1.0, n_points=10, values={}, predict=lambda t: t)


def test_claim6_verdicts_do_not_depend_on_the_order_of_the_systems():
    curve = SimpleNamespace(t=np.arange(10.0), P=np.ones(10))
    res = {
        lab: {
            "conv": "plateau",
            "tau0": 1.0,
            "curve": curve,
            "reason": "",
            "law": True,
            "fits": {"paper": _fit(rms), "integrated": _fit(rms)},
        }
        for lab, rms in (("hh", 1.0), ("co", 2.0), ("ba", 1.2))
    }
    p = SimpleNamespace(mu_gamma=0.01, sm_fit_dt=2.0, sm_min_count=20.0)
    verdicts = []
    for order in (["hh", "co", "ba"], ["co", "ba", "hh"]):
        c = Claims()
        claim6(c, {k: res[k] for k in order}, "hh", p)
        verdicts.append({(r["system"], r["quantity"]): r["verdict"] for r in c.rows})
    assert verdicts[0] == verdicts[1]
    assert verdicts[1][("co", "survival model (paper hazard) at γ = 0.01: rms log residual")].startswith("worse")
    assert verdicts[1][("hh", "survival model (paper hazard) at γ = 0.01: rms log residual")].startswith("reference")


def test_long_time_record_separates_regular_orbits_from_the_decay():
    rng = np.random.default_rng(4)
    n = 20000
    reg = rng.random(n) < 0.3  # regular: never leave
    t = np.where(reg, 2000.0, np.minimum(rng.exponential(1 / 0.004, n), 2000.0))
    lt = _lt(t, censored=np.flatnonzero(t >= 2000.0))
    rows, rec = long_time_record(lt, np.flatnonzero(reg), [100.0, 2000.0], 100.0, [100.0, 1000.0, 2000.0])
    assert rows[1]["P"] > 0.3 and abs(rec["P_inf"] - 0.3) < 4 * rec["P_inf_err"]
    assert abs(rec["kappa_nonregular"] - 0.004) < 4 * rec["kappa_nonregular_err"] and rec["exponential"]
    assert rec["regular_fraction_of_censored"] > 0.9


def test_long_time_record_gives_a_bound_where_no_orbit_is_left_and_says_too_few():
    rng = np.random.default_rng(8)
    t = rng.exponential(20.0, 2000)  # every orbit gone long before t = 2000, none censored
    lt = _lt(t, censored=[])
    rows, rec = long_time_record(lt, [], [100.0, 2000.0], 1.0, [1.0, 1000.0, 2000.0])
    assert rows[1]["P"] == 0 and rows[1]["P_err"] is None
    assert rows[1]["P_upper"] == pytest.approx(1 - 0.05 ** (1 / 2000), abs=1e-6) and rows[1]["P_cl"] == 0.95
    assert rec["P_inf"] == 0 and rec["P_inf_upper"] == pytest.approx(1 - 0.05 ** (1 / 2000), abs=1e-6)
    # a handful of non-regular orbits after t0: neither "one exponential" nor "not one": too few orbits
    few = _lt(np.concatenate([rng.exponential(5.0, 1988), 100.0 + rng.exponential(50.0, 12)]), censored=[])
    _, rec = long_time_record(few, [], [100.0], 100.0, [100.0, 1000.0])
    assert rec["exponential"] is None and rec["exponential_verdict"] == "too few orbits"


def test_long_time_record_gives_a_hazard_bin_without_escape_its_bound():
    rng = np.random.default_rng(3)
    t = np.concatenate([rng.uniform(100.0, 1000.0, 200), np.full(50, 2000.0)])  # no escape after t = 1000
    lt = _lt(t, censored=np.flatnonzero(t >= 2000.0))
    _, rec = long_time_record(lt, [], [100.0], 100.0, [100.0, 1000.0, 2000.0])
    full, empty = rec["hazard_nonregular"]
    assert full["events"] == 200 and full["err"] > 0 and "hazard_upper" not in full
    assert empty["events"] == 0 and empty["hazard"] == 0.0 and empty["err"] is None
    assert empty["hazard_upper"] == pytest.approx(-math.log(0.05) / (50 * 1000.0)) and empty["hazard_cl"] == 0.95


def test_regular_record_carries_the_threshold_systematic_and_a_bound_at_zero():
    lt = _lt(np.full(1000, 2000.0), censored=np.arange(1000))
    ind = pd.DataFrame({"traj_id": np.arange(6), "growth": [10.0, 5e3, 2e4, 5e4, 1e9, np.inf]})
    ind = ind.assign(regular=ind["growth"] < 1e4, kind=np.where(ind["growth"] < 1e4, "regular", "chaotic"))
    r = regular_record(lt, ind)
    assert r["fraction"] == 0.002 and r["syst"] == pytest.approx(0.002)  # 1 below 1e3, 4 below 1e5
    assert "fraction_upper" not in r and r["err"] > 0
    r0 = regular_record(lt, ind.assign(regular=False, growth=np.inf))
    assert r0["fraction"] == 0 and r0["err"] is None and r0["fraction_upper"] == pytest.approx(0.002991, abs=1e-6)


def test_validity_map_joins_claims_and_evidence_by_system_and_energy():
    reg = [{"system": "barbanis", "label": "b", "e_ratio": 1.5, "ics": "disk/tangential", "fraction": 0.1, "err": 0.01}]
    fits = [
        {
            "system": "barbanis",
            "e_ratio": 1.5,
            "ics": "disk/tangential",
            "P_inf": 0.1,
            "P_inf_err": 0.01,
            "exponential": False,
        }
    ]
    kappa = [{"system": "b", "ratio": 1.5, "convention": "plateau", "defined": False}]
    claims = [
        {
            "claim": "2",
            "system": "b",
            "quantity": "κ_cm/κ0 − 1 at E/E_c = 1.5 (all orbits, plateau windows)",
            "verdict": "undetermined",
        }
    ]
    (v,) = validity_map(reg, fits, kappa, claims, ics="disk/tangential")
    assert (v["kappa0_defined"], v["claim2"], v["exponential"], v["plateau"]) == (False, "undetermined", False, True)
    assert first_below(reg + [{**reg[0], "e_ratio": 2.0, "fraction": 0.0}], ics="disk/tangential") == {
        "barbanis": {"from": 2.0, "text": "from 2 E_c on"}
    }
    assert first_below(reg, ics="disk/tangential")["barbanis"]["from"] is None


def test_labelled_selection_takes_the_band_and_a_sample_either_side_and_skips_a_fraction_of_0_or_1():
    g = np.array([1.0, 2.0, 3.0, 20.0, 300.0, 4e3, 5e4, 6e5, 1e8, 2e8, np.inf, np.nan])
    ind = pd.DataFrame({"traj_id": np.arange(100, 112), "growth": g, "regular": g < 1e4})
    sel = labelled_selection(ind, 1000, (10.0, 1e7), 3, 2, 5)
    band = sel[sel["in_band"]]
    assert len(band) == 3 and ((band["growth"] > 10) & (band["growth"] < 1e7)).all()
    assert (sel["growth"] <= 10).sum() == 2 and (sel["growth"] >= 1e7).sum() == 2 and sel["growth"].notna().all()
    again = labelled_selection(ind, 1000, (10.0, 1e7), 3, 2, 5)
    assert sel.equals(again)  # the same seed: the same orbits
    assert labelled_selection(ind.assign(regular=False), 1000, (10.0, 1e7), 3, 2, 5) is None
    assert labelled_selection(ind.assign(regular=True), 12, (10.0, 1e7), 3, 2, 5) is None


def test_indicator_record_carries_the_confusion_per_threshold_and_the_scaled_systematic():
    ids = np.arange(6)
    ind = pd.DataFrame({"traj_id": np.arange(50), "growth": np.r_[[5.0, 50.0, 2e3, 2e4, 3e5, 1e9], np.full(44, 40.0)]})
    sel = pd.DataFrame({"traj_id": ids, "growth": ind["growth"][:6], "in_band": [False, True, True, True, True, False]})
    lt = pd.DataFrame(  # labels at T = 3000: regular (Λ < 9), chaotic (Λ > 15 or escaped), undecided between
        {
            "traj_id": ids,
            "outcome": ["censored"] * 5 + ["escaped"],
            "t_end": [3000.0] * 5 + [700.0],
            "log_stretch": [2.0, 40.0, 12.0, 5.0, 30.0, 1.0],
        }
    )
    rec = indicator_record(
        200, ind, sel, lt, 3000.0, band=(10.0, 1e7), ftle_regular=0.003, ftle_chaotic=0.005, thresholds=[1e4, 1e3, 1e5]
    )
    # band of the ensemble: 4 of the first 6 and the 44 at G = 40 → 48; labelled in the band: 4 → ×12.
    # At 1e4 in the band: 50 (regular) is chaotic, 2e3 (regular) undecided, 2e4 (chaotic) regular, 3e5 agrees.
    assert rec["n_band"] == 48 and rec["n_labelled"] == 6 and rec["n_band_labelled"] == 4 and rec["n_undecided"] == 1
    assert (rec["disagree_to_regular"], rec["disagree_to_chaotic"], rec["disagree_outside"]) == (1, 1, 0)
    assert rec["syst"] == pytest.approx(2 * 12 / 200) and rec["shift"] == 0.0
    c = {row["g_max"]: row for row in rec["confusion"]}
    assert [c[1e4][k] for k in ("regular_regular", "regular_chaotic", "regular_undecided")] == [1, 1, 1]
    assert [c[1e4][k] for k in ("chaotic_regular", "chaotic_chaotic", "chaotic_undecided")] == [1, 2, 0]
    assert c[1e3]["chaotic_undecided"] == 1 and c[1e5]["regular_regular"] == 2  # 2e3 above 1e3; 2e4 below 1e5
    with pytest.raises(ValueError, match="labelled run"):
        indicator_record(
            200, ind, sel, lt.iloc[:5], 3000.0, band=(10.0, 1e7), ftle_regular=0.003, ftle_chaotic=0.005,
            thresholds=[1e4],
        )  # fmt: skip


def test_validity_map_carries_the_total_error_of_the_regular_fraction():
    reg = {"system": "barbanis", "label": "b", "e_ratio": 1.05, "ics": "disk/tangential", "fraction": 0.6}
    r = {**reg, "err": 0.003, "syst": 0.004, "syst_indicator": 0.012, "err_total": total_error(0.003, 0.004, 0.012)}
    (v,) = validity_map([r], [], [], [], ics="disk/tangential")
    assert v["regular_err_total"] == pytest.approx(0.013) and v["regular_syst_indicator"] == 0.012
    assert total_error(0.003, 0.004, None) == pytest.approx(0.005) and total_error(None) is None


def _taus(obs, lo, hi, pred, pred_err):
    return pd.DataFrame(
        {
            "gamma": [0.005, 0.01],
            "n": [1000, 1000],
            "tau0": [8.0, 8.0],
            "tau0_err": [0.4, 0.4],
            "tau1": [np.nan, np.nan],
            "tau1_err": [np.nan, np.nan],
            "tau2_obs": [np.nan, obs],
            "tau2_obs_lo": [np.nan, lo],
            "tau2_obs_hi": [np.nan, hi],
            "p0_trapped": [0.0, 0.0],
            "t_settle_q50": [200.0, 100.0],
            "t_settle_q50_err": [2.0, 1.0],
            "tau2_pred": [125.0, pred],
            "tau2_pred_err": [0.02, pred_err],
        }
    )


def test_claim4_tau2_ratio_is_judged_by_the_one_rule_with_both_errors():
    """τ2,obs / τ2,pred carries an error (half-width of the order-statistic interval, and the prediction's) and the
    one verdict rule: a first settling time at 0.93 of the prediction with its interval [0, τ2,obs] agrees (|z| ≈
    0.2); the same ratio with a tight interval differs. No fixed tolerance."""
    from hhscatter.reproduction.claims.dissipative import claim4

    def rec(*args):
        c = Claims()
        claim4(c, "s", _taus(*args), 0.01)
        return next(r for r in c.rows if r["quantity"].startswith("τ2 observed"))

    wide = rec(58.0, 0.0, 58.0, 62.5, 0.01)
    assert abs(wide["err"] - 0.928 * 0.5) < 1e-3
    assert wide["verdict"] == "agrees (z = −0.2)"
    tight = rec(58.0, 57.5, 58.5, 62.5, 0.01)
    assert abs(tight["err"] - 0.928 * 0.5 / 58.0) < 1e-5
    assert tight["verdict"].startswith("differs (z = −")
    assert "within 15 %" not in wide["verdict"] + tight["verdict"]


def test_a_claim_verdict_is_the_one_rule_written_as_every_verdict():
    """z_verdict applies the rule of every table (|z| ≤ 2, both errors) and writes z as Verdict.text does ("−"),
    checked against z computed here; without our error it says why, as every undetermined cell does."""
    import math

    from hhscatter.reproduction.claims.records import z_verdict

    for value, err, ref, ref_err in [
        (1.1, 0.1, 1.0, 0.0),
        (0.5, 0.1, 1.0, 0.0),
        (0.996, 0.1, 1.0, 0.0),
        (1.0, 0.02, 1.05, 0.01),
        (0.9, 0.03, 1.0, 0.04),
        (1.3, 0.1, 1.0, 0.1),
    ]:
        z = (value - ref) / math.hypot(err, ref_err)
        word = "ok" if abs(z) <= 2 else "bad"
        sign = "−" if z < 0 else "+"
        assert z_verdict(value, err, ref, "ok", "bad", ref_err) == f"{word} (z = {sign}{abs(z):.1f})"
    assert z_verdict(0.5, None, 1.0, "ok", "bad") == "undetermined: no uncertainty of ours"
    assert z_verdict(None, 0.1, 1.0, "ok", "bad").startswith("undetermined: no value of ours")
    assert z_verdict(1.0, 0.0, 1.0, "ok", "bad") == "ok"
    # the sign of z is written "−"; a label's own hyphens stay as written
    assert z_verdict(0.7, 0.1, 1.0, "the c-measure's", "not the c-measure's") == "not the c-measure's (z = −3.0)"


def _plateau_cell(n_censored, regular_fraction, *, n=20000, kappa=0.05, t_max=800.0, seed=3):
    """One validity-map cell made the way the study makes it: κ0 rows of a κ0 run (exponential escape at ``kappa``
    plus ``n_censored`` orbits still inside at t_max) joined with a regular-fraction record at that energy."""
    p = SimpleNamespace(ratios=[2.2], min_survivors=50.0, max_plateau_bias=0.1, p_levels=[0.5, 0.01], alt_region=None)
    t = np.minimum(np.random.default_rng(seed).exponential(1 / kappa, n), t_max)
    t[:n_censored] = t_max
    lt = _lt(t, censored=np.arange(n_censored))
    rows, _ = kappa_rows(_Runs(p, {"b_r2.200": lt}), "b", system_from_spec({"name": "henon_heiles"}))
    n_reg = round(regular_fraction * n)
    reg = [
        {
            "id": "barbanis-2.2-disk",
            "system": "barbanis",
            "label": "b",
            "e_ratio": 2.2,
            "ics": "disk/tangential",
            "fraction": n_reg / n,
            "err": math.sqrt(n_reg / n * (1 - n_reg / n) / n),
            "n": n,
            "n_regular": n_reg,
        }
    ]
    (cell,) = validity_map(reg, [], rows, [], ics="disk/tangential", max_bias=p.max_plateau_bias)
    return cell


def test_kappa0_defined_is_decided_by_the_plateau_share_not_by_the_regular_fraction():
    """A cell like Barbanis at 2.2 E_c: 0.12 % of the orbits regular (below 1 %) and still inside at t_max. With
    N·e^(−κ t_hi) ≈ 50 orbits left at the window's end, 24 trapped ones are ≈ 50 % of P there: κ0 is ill-defined,
    whatever the regular fraction; without them it is defined. The map records the numbers that decide it."""
    cell = _plateau_cell(24, 0.0012)
    assert cell["regular_fraction"] < 0.01 and (cell["n_regular"], cell["n"]) == (24, 20000)
    assert cell["kappa0_defined"] is False
    assert cell["plateau_bias"] > 0.1
    assert cell["trapped_fraction"] == pytest.approx(24 / 20000)
    assert cell["kappa0_verdict"].startswith("ill-defined: f∞/P(t_hi) = ") and cell["kappa0_verdict"].endswith("> 10 %")
    assert kappa0_defined_by_rule(cell, 0.1) is False
    free = _plateau_cell(0, 0.0)
    assert free["kappa0_defined"] is True and free["plateau_bias"] == 0.0
    assert free["kappa0"]["value"] == pytest.approx(0.05, rel=0.05)
    assert free["kappa0_verdict"] == "defined: f∞/P(t_hi) = 0 % ≤ 10 %"
    assert "the regular fraction does not enter the rule" in kappa0_rule(0.1, 50.0)


@pytest.mark.parametrize("n_censored", [0, 1, 2, 5, 24, 400])
def test_the_stated_kappa0_rule_reproduces_the_codes_decision_in_every_cell(n_censored):
    cell = _plateau_cell(n_censored, 0.0)
    assert kappa0_defined_by_rule(cell, 0.1) is cell["kappa0_defined"]


def test_a_map_cell_without_a_kappa0_run_has_no_verdict_and_the_rule_says_none():
    reg = [{"system": "barbanis", "label": "b", "e_ratio": 5.0, "ics": "d", "fraction": 0.0, "err": None, "n": 10}]
    (cell,) = validity_map(reg, [], [], [], ics="d", max_bias=0.1)
    assert cell["kappa0_defined"] is None and "kappa0" not in cell
    assert kappa0_defined_by_rule(cell, 0.1) is None


def _prompt_then_slow(n, seed=3):
    """Lifetimes of a fast-escaping ensemble: 95 % leave after a flight time of 0.8 at hazard 1.3, the other 5 %
    from t = 6 at the rate κ = 0.26 of the exponential regime (the shape of P(t) of Contopoulos at 2.6 E_c)."""
    rng = np.random.default_rng(seed)
    fast = rng.random(n) < 0.95
    t = np.where(fast, 0.8 + rng.exponential(1 / 1.3, n), 6.0 + rng.exponential(1 / 0.26, n))
    return pd.DataFrame({"traj_id": np.arange(n), "t_end": t, "outcome": "escaped"})


def test_kappa0_is_undefined_where_the_window_holds_the_dead_time_before_the_first_escape():
    """With 2000 orbits the floor of 50 survivors sits at P = 0.025: the exponential regime (κ = 0.26) spans about
    one e-fold above it and the prompt burst more, so the plateau rule takes the burst from t = 0 (κ ≈ 1.1, an
    e-fold of it before anyone has left). That κ is not the regime's: κ0 is undefined and says why. With 20 000
    orbits the same distribution gives the regime's κ = 0.26."""
    from hhscatter.reproduction.claims.kappa import window_rate

    p = SimpleNamespace(min_survivors=50.0, max_plateau_bias=0.1)
    small, res, why = window_rate(_prompt_then_slow(2000), p, "window rule failed")
    assert why == "" and res.tau0 == 0.0 and res.kappa > 0.8  # the burst, as the window rule finds it
    assert not small.defined and "before the first escape" in small.reason
    large, res, _ = window_rate(_prompt_then_slow(20000), p, "window rule failed")
    assert large.defined and abs(large.kappa - 0.26) < 0.03 and res.tau0 > 5.0


@pytest.mark.parametrize(
    ("seed", "why"),
    [
        (3, "; window starts 0.8 time units (0.91 e-folds of κ) before the first escape: a prompt burst"),
        (
            5,
            "; window spans 0.32 e-folds of κ (< 1) in 0.48 time units (< 6.28): the local slope where the prompt burst",
        ),
    ],
)
def test_a_map_cell_undefined_by_the_dead_time_records_its_numbers_and_the_rule_gives_the_same_decision(seed, why):
    """A κ0 run whose plateau window is the prompt burst (2000 orbits; seed 3: the window starts at 0, an e-fold of
    its κ before anyone has left; seed 5: a third of an e-fold at the burst's end): the cell records the window and
    the first escape, the rule applied to the cell's numbers gives the code's "undefined", and the verdict says
    why."""
    p = SimpleNamespace(ratios=[2.6], min_survivors=50.0, max_plateau_bias=0.1, p_levels=[0.5, 0.01], alt_region=None)
    lt = _prompt_then_slow(2000, seed=seed)
    rows, _ = kappa_rows(_Runs(p, {"b_r2.600": lt}), "b", system_from_spec({"name": "henon_heiles"}))
    reg = [{"system": "barbanis", "label": "b", "e_ratio": 2.6, "ics": "d", "fraction": 0.0, "err": None, "n": 2000}]
    (cell,) = validity_map(reg, [], rows, [], ics="d", max_bias=0.1)
    assert cell["kappa0_defined"] is False and cell["plateau_bias"] == 0.0
    assert cell["kappa0_t_first"] == pytest.approx(lt["t_end"].min())
    assert 0.0 <= cell["kappa0_tau0"] < cell["kappa0_t_hi"] < 6.0
    assert kappa0_defined_by_rule(cell, 0.1) is False
    assert cell["kappa0_verdict"].startswith("ill-defined: f∞/P(t_hi) = 0 % ≤ 10 %" + why)
    assert cell["kappa0_verdict"].endswith("not an exponential regime; κ ill-defined")


def test_kappa0_is_undefined_where_a_short_window_lies_inside_the_prompt_burst():
    """The same distribution, another draw of 2000 orbits (seed 5): the plateau rule takes a window after the first
    escape, [2.8, 3.3], where every escape is a burst orbit (the slow 5 % leave only from t = 6): κ ≈ 0.66 against
    the regime's 0.26, over a third of an e-fold. κ0 is undefined and says why; with 20 000 orbits of that seed the
    window is the regime's, over more than an e-fold, and κ0 is defined and right."""
    from hhscatter.reproduction.claims.kappa import window_rate

    p = SimpleNamespace(min_survivors=50.0, max_plateau_bias=0.1)
    lt = _prompt_then_slow(2000, seed=5)
    small, res, why = window_rate(lt, p, "window rule failed")
    assert why == "" and lt["t_end"].min() < res.tau0 < 6.0 and res.kappa > 0.5  # inside the burst, after t_first
    assert not small.defined and "spans 0.3" in small.reason and "e-folds of κ (< 1)" in small.reason
    large, res, _ = window_rate(_prompt_then_slow(20000, seed=5), p, "window rule failed")
    assert large.defined and abs(large.kappa - 0.26) < 0.03 and res.tau0 > 5.0


def test_a_window_of_more_than_an_e_fold_in_the_fast_decay_passes_the_burst_conditions():
    """Seed 0 of the same distribution: the plateau rule takes [1.47, 2.77], after the first escape (0.8), where the
    fast 95 % decay over their 5 % floor: κ ≈ 1.0 over 1.3 e-folds of it in 1.3 time units. Neither condition of
    the dead-time check holds (it starts after the first escape; it spans more than an e-fold), so κ0 is defined:
    a window of an e-fold or more is a measured exponential stretch, whatever follows it, as in the short windows
    far above threshold whose κ holds with N (Hénon–Heiles and Contopoulos at 5 E_c: 1.4–2.1 e-folds in 2.2–4.3 time
    units with 2000 orbits). Which stretch is the regime is the window rule's choice over the orbits it has: with
    20 000 orbits of that seed it is the slow one, κ = 0.26."""
    from hhscatter.analysis.survival.kappa_conventions import dead_time_check
    from hhscatter.reproduction.claims.kappa import window_rate

    p = SimpleNamespace(min_survivors=50.0, max_plateau_bias=0.1)
    lt = _prompt_then_slow(2000, seed=0)
    small, res, why = window_rate(lt, p, "window rule failed")
    t_first = lt["t_end"].min()
    assert why == "" and t_first < res.tau0 < res.t_stop < 6.0  # inside the fast decay, after the first escape
    efolds = small.kappa * (res.t_stop - res.tau0)
    assert 1.0 < efolds and res.t_stop - res.tau0 < 2 * np.pi and 0.8 < small.kappa < 1.3
    assert small.defined and dead_time_check(res.tau0, t_first, small.kappa, t_hi=res.t_stop) == (True, "")
    # one e-fold less and the same window is the burst's hand-over (the second condition)
    assert not dead_time_check(res.tau0, t_first, small.kappa, t_hi=res.t_stop, min_efolds=efolds + 0.01)[0]
    large, res, _ = window_rate(_prompt_then_slow(20000, seed=0), p, "window rule failed")
    assert large.defined and abs(large.kappa - 0.26) < 0.03 and res.tau0 > 5.0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_one_exponential_of_2000_orbits_keeps_kappa0_defined_under_the_burst_conditions(seed):
    """A pure exponential (κ = 0.05 after a flight time of 2, no burst): the window spans several e-folds and starts
    after the first escape, so neither dead-time condition fires."""
    from hhscatter.reproduction.claims.kappa import window_rate

    p = SimpleNamespace(min_survivors=50.0, max_plateau_bias=0.1)
    t = 2.0 + np.random.default_rng(seed).exponential(1 / 0.05, 2000)
    rate, _, why = window_rate(_lt(t), p, "window rule failed")
    assert why == "" and rate.defined and abs(rate.kappa - 0.05) < 0.005
