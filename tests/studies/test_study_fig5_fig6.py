"""Studies fig5 (c-measure comparison) and fig6 (survival model): new analysis helpers and tiny end-to-end runs.

The analysis functions are tested against closed forms and constructed data;
the end-to-end tests run both studies at scale ``tiny`` in a temporary
studies root, with the upstream inputs made here: real tiny simulations in
the layout of studies fig1/fig4 and minimal numbers JSONs carrying the
paper's values (μ = 0.91, κ0 fit 13.63/0.03/1.41/0.27) as stated inputs.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.dissipative.models import time_to_energy
from hhscatter.analysis.geometry import distance as dist
from hhscatter.model import HenonHeiles
from hhscatter.reproduction.verdicts import NO_VERDICT

E_C = HenonHeiles().critical_energy  # the paper's system's E_c
from hhscatter.analysis.dissipative.transitions import tau2_predicted
from hhscatter.studies import _upstream as up

REPO = Path(__file__).resolve().parents[2]


# ---------------------------------------------------------------------------
# analysis helpers
# ---------------------------------------------------------------------------
def test_time_to_energy_inverts_the_exponential_law():
    # paper: E2 = 0.35 → E1 = 0.30 with μ = 0.91, γ = 0.01 gives t* ≈ 17
    ts = time_to_energy(0.35, 0.30, 0.91, 0.01)
    assert ts == pytest.approx(math.log(0.35 / 0.30) / 0.0091, rel=1e-14)
    assert 0.35 * math.exp(-0.91 * 0.01 * ts) == pytest.approx(0.30, rel=1e-14)
    assert round(ts) == 17
    # Eq. (eq:tau2) is the special case E1 = E_c
    g = np.array([1e-3, 1e-2, 2e-2])
    np.testing.assert_allclose(time_to_energy(0.3, E_C, 0.9, g), tau2_predicted(0.3, E_C, 0.9, g), rtol=1e-14)
    with pytest.raises(ValueError, match="E0 >= E1"):
        time_to_energy(0.2, 0.3, 1.0, 0.01)
    with pytest.raises(ValueError, match="mu\\*gamma"):
        time_to_energy(0.35, 0.3, 1.0, 0.0)


def test_first_crossings_picks_first_after_t_from_then_filters_energy():
    sec = pd.DataFrame(
        {
            "traj_id": [1, 1, 1, 2, 2, 3, 4],
            "t": [5.0, 17.5, 19.0, 16.0, 18.0, 30.0, 10.0],
            "x": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7],
            "y": 0.0,
            "energy": [0.33, 0.31, 0.299, 0.30, 0.30, 0.28, 0.32],
        }
    )
    out = dist.first_crossings(sec.sample(frac=1.0, random_state=3), 17.0)  # order must not matter
    assert out["traj_id"].tolist() == [1, 2, 3]  # orbit 4 has no crossing after t*
    assert out["t"].tolist() == [17.5, 18.0, 30.0]
    # the band filter acts on the first crossing: orbit 1's first crossing (E = 0.31) is out of
    # the band, and its later in-band crossing (E = 0.299) must NOT be taken instead
    band = dist.first_crossings(sec, 17.0, e_min=0.295, e_max=0.305)
    assert band["traj_id"].tolist() == [2]
    with pytest.raises(ValueError, match="columns"):
        dist.first_crossings(sec.drop(columns="t"), 1.0)


def test_distance_vs_scale_common_sample_size():
    rng = np.random.default_rng(4)
    P = rng.random((4000, 2))
    Q = rng.random((1000, 2))  # same distribution, fewer points
    boxes = [0.25, 0.125]
    small = dist.distance_vs_scale(P, Q, boxes, (0, 1, 0, 1), n_splits=6, seed=1, m=100)
    full = dist.distance_vs_scale(P, Q, boxes, (0, 1, 0, 1), n_splits=6, seed=1)
    assert (small["m"] == 100).all() and (full["m"] == 500).all()
    # finite-sample noise floor E[H²] ≈ B/8 (1/m + 1/m) for B boxes with many counts each
    # (B = 16 boxes of side 0.25: ≥ 6 points per box at m = 100): shrinks as 1/√m
    for tab, m in ((small, 100), (full, 500)):
        assert tab["hellinger_noise"].iloc[0] == pytest.approx(math.sqrt(16 / 8 * 2 / m), rel=0.2)
        # same distribution: the cross distance sits on the noise floor
        z = (tab["hellinger_pq"] - tab["hellinger_noise"]) / np.hypot(
            tab["hellinger_pq_std"], tab["hellinger_noise_std"]
        )
        assert (np.abs(z) < 3).all()
    assert (small["hellinger_noise"] > full["hellinger_noise"]).all()
    with pytest.raises(ValueError, match="m must be in"):
        dist.distance_vs_scale(P, Q, boxes, (0, 1, 0, 1), n_splits=2, m=501)


def test_debiased_hellinger_recovers_exact_distance_of_shifted_uniforms():
    # P uniform on [0,1]², Q uniform on [0.1,1.1]×[0,1]; on boxes anchored at x = 0 the exact
    # Hellinger distance of the coarse-grained distributions is H² = 1 − Σ√(p q):
    #   ε = 0.1: 90 of 100 cells shared with p = q = 0.01 → H² = 0.1
    #   ε = 0.2: per column Σ√(pq) = √(0.2·0.1) + 4·0.2 → H² = 0.2 − √0.02
    exact = {0.2: math.sqrt(0.2 - math.sqrt(0.02)), 0.1: math.sqrt(0.1)}
    rng = np.random.default_rng(11)
    n = 8000
    P = rng.random((n, 2))
    Q = rng.random((n, 2)) + [0.1, 0.0]
    ext = (0.0, 1.1 + 1e-9, 0.0, 1.0 + 1e-9)
    for m in (600, 4000):
        tab = dist.distance_vs_scale(P, Q, [0.2, 0.1], ext, kinds=("hellinger",), n_splits=6, seed=3, m=m)
        d, lo, hi = dist.debiased_distance(tab)
        for box, dv, lv, hv, raw in zip(tab["box"], d, lo, hi, tab["hellinger_pq"]):
            # the correction is exact for shared cells with p = q; the edge cells (p ≠ q) and the
            # finite full sample leave a few per cent, against 7–20 % bias of the raw value at m = 600
            assert dv == pytest.approx(exact[box], rel=0.06), (m, box)
            assert lv <= dv <= hv
            assert raw - exact[box] > abs(dv - exact[box])  # the raw split-half value is biased upwards
        assert dist.agreement_scale_debiased(tab, delta=0.28) == 0.2  # 0.242 ≤ δ < 0.316
        assert dist.agreement_scale_debiased(tab, delta=0.2) is None
    # identical distributions: the corrected distance is compatible with 0 at every scale
    same = dist.distance_vs_scale(
        P, rng.random((n, 2)), [0.2, 0.1, 0.05], ext, kinds=("hellinger",), n_splits=6, seed=3
    )
    d, lo, hi = dist.debiased_distance(same)
    assert (lo == 0).all() and (d < 0.05).all()
    assert dist.agreement_scale_debiased(same, delta=0.05) == 0.05


def test_upstream_lookup_dotted_keys_and_errors():
    doc = {
        "energies": {"E0.30": {"t_rec": 24.0}},
        "mu": {"value": 0.93, "err": 0.01},
        "taus": [{"gamma": 0.01, "tau1": {"value": 17.0, "err": 1.0}}],
    }
    assert up.lookup(doc, "energies.E0.30.t_rec")[0] == 24.0
    assert up.lookup(doc, "mu") == (0.93, 0.01)
    assert up.lookup(doc, "taus.0.tau1") == (17.0, 1.0)
    with pytest.raises(up.UpstreamError, match="present: \\['energies', 'mu', 'taus'\\]"):
        up.lookup(doc, "kappa_fit.a")


# ---------------------------------------------------------------------------
# tiny end-to-end runs (every study built at scale tiny in graph order: conftest.py)
# ---------------------------------------------------------------------------
def _numbers(root: Path, name: str) -> dict:
    return json.loads((root / name / "out" / "tiny" / f"{name}.json").read_text())


def test_fig5_tiny_end_to_end(tiny_studies):
    from hhscatter.studies import load_study

    study = load_study("fig5", "tiny", root=tiny_studies)
    nums = json.loads(study.numbers_path.read_text())
    assert study.figure_path.stat().st_size > 10_000
    assert nums["dev_fallback"] is False
    assert nums["inputs"]["mu"]["source"] == "fig3.json:mu"
    mu = _numbers(tiny_studies, "fig3")["mu"]["value"]
    assert nums["mu"]["value"] == mu
    # t* from fig3's μ (Eq. (eqn:energy_exp_decay)) for each γ
    for g in (0.03, 0.02):
        assert nums["t_star"][f"gamma{g:g}"]["value"] == pytest.approx(math.log(0.35 / 0.30) / (mu * g))
    # the c-measure samples are fig1's published points (its derived table), not its raw runs
    fig1 = pd.read_parquet(tiny_studies / "fig1" / "out" / "tiny" / "derived" / "cmeasure_points.parquet")
    for label, E in (("E1", 0.30), ("E2", 0.35)):
        src = nums["inputs"][f"cmeasure_{label}"]
        assert src["source"].startswith("fig1: derived/cmeasure_points.parquet")
        assert src["n_points"] == int(np.isclose(fig1["energy"], E).sum())
    pts = pd.read_parquet(study.out / "derived" / "points.parquet")
    per = {r["gamma"]: r for r in nums["per_gamma"]}
    for g in (0.03, 0.02):
        a = pts[(pts["gamma"] == g) & (pts["set"] == "a")]
        b = pts[(pts["gamma"] == g) & (pts["set"] == "b")]
        assert len(a) == per[g]["n_a"] > 0
        assert (a["t"] >= per[g]["t_star"]).all() and a["traj_id"].is_unique
        assert set(b["traj_id"]) <= set(a["traj_id"])
        assert ((b["energy"] >= 0.295) & (b["energy"] <= 0.305)).all()
        # energy of a crossing lies below E2 and above E_c (the orbit still scatters)
        assert (a["energy"] < 0.35).all() and (a["energy"] > E_C).all()
    summ = pd.read_parquet(study.out / "derived" / "distance_summary.parquet")
    assert {"sw1", "sw1_err", "hellinger", "hellinger_err", "agreement_scale"} <= set(summ.columns)
    assert ((summ["hellinger"] >= 0) & (summ["hellinger"] <= 1)).all()
    assert any(r["quantity"].startswith("t*") for r in nums["paper_comparison"])


def test_fig5_fails_clearly_without_fig1(tiny_studies, tmp_path, monkeypatch, copy_study):
    from hhscatter.studies import run_stage

    monkeypatch.delenv(up.DEV_ENV, raising=False)
    for name in ("fig3", "fig5"):
        shutil.copytree(tiny_studies / name, tmp_path / name)
    shutil.copy(tiny_studies / "conventions.toml", tmp_path / "conventions.toml")  # a studies folder is self-contained
    copy_study("fig1", tmp_path)
    with pytest.raises(up.UpstreamError, match="fig5 needs the published outputs of fig1 .*make fig5 SCALE=tiny"):
        run_stage("fig5", "analyze", "tiny", root=tmp_path)


def test_fig6_tiny_end_to_end(tiny_studies):
    from hhscatter.studies import load_study

    study = load_study("fig6", "tiny", root=tiny_studies)
    nums = json.loads(study.numbers_path.read_text())
    assert study.figure_path.stat().st_size > 10_000
    assert nums["dev_fallback"] is False
    fig2, fig3, fig4 = (_numbers(tiny_studies, n) for n in ("fig2", "fig3", "fig4"))
    assert nums["kappa0"]["a"] == fig2["kappa_fit"]["a"]["value"] and nums["tau0"] == fig4["tau0"]["value"]
    assert nums["mu"]["value"] == fig3["mu"]["value"]
    assert nums["inputs"]["tau_lifetimes"]["source"] == "fig4: derived/fig4_lifetimes.parquet"
    fits = pd.DataFrame(nums["fits"])
    assert set(fits["model"]) == {"homogeneous", "mixture_tau0", "mixture_free"}
    # a shared-φ mixture has as many free parameters as the homogeneous model, a free one K − 1 more
    nf = fits.groupby("model")["n_free"].max()
    assert nf["mixture_tau0"] == nf["homogeneous"] == 3 and nf["mixture_free"] == 3 + 2 - 1
    assert set(fits["hazard"]) == {"paper", "integrated"}
    assert (fits["n_points"] > 3).all()
    # all models are compared on the same points
    for (_, _), grp in fits.groupby(["pair", "hazard"]):
        assert grp["n_points"].nunique() == 1
    # constraint f_ne + f_e = P(τ0) of Eq. (eqn:surv_prob_model)
    hom = fits[fits["model"] == "homogeneous"]
    np.testing.assert_allclose(hom["f_ne"] + hom["f_e"], hom["P_tau0"], rtol=1e-12)
    taus = pd.DataFrame(nums["tau_vs_gamma"])
    row = taus[taus["gamma"] == 0.02].iloc[0]
    assert row["tau2_predicted"] == pytest.approx(math.log(0.3 / E_C) / (fig3["mu"]["value"] * 0.02))
    t4 = next(r for r in fig4["taus"] if r["gamma"] == 0.02)
    assert row["tau1_observed"] == t4["tau1"]["value"] and row["tau2_observed"] == t4["tau2_obs"]["value"]
    assert row["tau1_pred_integrated"] is None or row["tau1_pred_integrated"] >= nums["tau0"]


def test_fig5_authors_convention_rows_are_their_sets_and_recompute_deterministically(tiny_studies):
    """The authors' Fig. 5 convention: square ICs (goodICs) at E2, their windows, r < 1 — built from runs
    whose scenes say so, and the same numbers when the analysis runs again."""
    from hhscatter.data.read import read_sections
    from hhscatter.studies import load_study, run_stage

    study = load_study("fig5", "tiny", root=tiny_studies)
    nums = json.loads(study.numbers_path.read_text())
    auth = nums["authors_convention"]
    g = nums["gamma_main"]
    for key, check in (
        ("5a_authors", lambda s: (s["t"] > 17.0) & (s["t"] < 30.0)),
        ("5b_authors", lambda s: (s["energy"] >= 0.295) & (s["energy"] <= 0.305)),
    ):
        scene = json.loads((study.raw(key) / "scene.json").read_text())["scene"]
        assert scene["region"] == "square" and scene["gamma"] == g and scene["sections"]["first_only"]
        sec = read_sections(study.raw(key))
        assert sec["traj_id"].is_unique and check(sec).all()  # one crossing per orbit, in the window
        assert auth["n_points"][key] == int((np.hypot(sec["x"], sec["y"]) < 1).sum())
    rows = {r["quantity"]: r for r in nums["paper_comparison"]}
    # the authors' rows are paired: 5a and 5b against both references, one row each, like for like
    paired = [
        q
        for q, r in rows.items()
        if r["authors"] and q.startswith(("Fig. 5a closer", "Fig. 5b closer")) and "than to μ_c^0.35, paired" in q
    ]
    refs = {r["set"]: r for r in nums["refs_paired"]["rows"] if r["construction"] == "authors" and "set" in r}
    assert len(paired) == len(refs) and all(
        r["n_set"] == min(auth["n_points"][f"{s}_authors"], study.params.n_cap) for s, r in refs.items()
    )
    assert not any("both in the authors' convention" in q for q in rows)  # the split-spread row is retired
    run_stage("fig5", "analyze", "tiny", root=tiny_studies)
    again = json.loads(study.numbers_path.read_text())["authors_convention"]
    assert again == auth


def test_fig5_paired_records_of_the_references_and_panel_d(tiny_studies):
    """5a/5b against μ_c^0.30 and μ_c^0.35 and panel (d) carry paired intervals: Δ is the difference of
    the two distances in every replicate, so its mean is the difference of the means; panel (d) has one curve per
    γ (ordered by t*) with its bands around the mean, and one step between consecutive t*."""
    from hhscatter.studies import load_study

    study = load_study("fig5", "tiny", root=tiny_studies)
    nums = json.loads(study.numbers_path.read_text())
    refs = nums["refs_paired"]
    assert {r["construction"] for r in refs["rows"]} == {"ours", "authors"}
    for r in refs["rows"]:
        if "delta" in r:
            assert r["delta"]["value"] == pytest.approx(r["d_E2"]["value"] - r["d_E1"]["value"], abs=1e-12)
            assert r["delta"]["interval"][0] <= r["delta"]["value"] <= r["delta"]["interval"][1]
    pdl = nums["panel_d"]
    if pdl is None or "curves" not in pdl:
        return
    ts = [c["t_star"] for c in pdl["curves"]]
    assert ts == sorted(ts) and len(pdl["steps"]) == len(ts) - 1
    for c in pdl["curves"]:
        assert len(c["d"]) == len(pdl["boxes"]) and all(
            lo <= d <= hi for lo, d, hi in zip(c["d_lo"], c["d"], c["d_hi"])
        )
    assert 0.0 <= pdl["eps_shrink_share"] <= 1.0


def test_fig5_sensitivity_runs_are_the_authors_runs_with_random_momenta(tiny_studies):
    """The sensitivity row: 5a/5b_authors_random are the authors' scenes but for momentum = 'random', and
    the verdict has its row, made like 'cut_offsets' from those runs, with its own convention."""
    from hhscatter.data.read import read_sections
    from hhscatter.studies import load_study

    study = load_study("fig5", "tiny", root=tiny_studies)
    nums = json.loads(study.numbers_path.read_text())
    for key in ("5a_authors", "5b_authors"):
        base = json.loads((study.raw(key) / "scene.json").read_text())["scene"]
        rand = json.loads((study.raw(f"{key}_random") / "scene.json").read_text())["scene"]
        assert "momentum" not in base and rand.pop("momentum") == "random"
        assert {k: v for k, v in rand.items() if k != "name"} == {k: v for k, v in base.items() if k != "name"}
        sec = read_sections(study.raw(f"{key}_random"))
        assert len(sec) and sec["traj_id"].is_unique and (sec["t"] > 0).all()
    rows = {r["construction"]: r for r in nums["verdict_5b"]["rows"]}
    assert set(rows) == {"old", "cut", "cut_offsets", "cut_offsets_random", "ours"}
    r = rows["cut_offsets_random"]
    a = read_sections(study.raw("5a_authors_random"))
    assert r.get("n_5a", len(a)) == min(int((np.hypot(a["x"], a["y"]) < 1).sum()), study.params.n_cap)
    assert r.get("n_ref") == rows["cut_offsets"].get("n_ref") and r.get("offsets") == rows["cut_offsets"].get("offsets")
    comp = [c for c in nums["paper_comparison"] if "momenta in random directions" in c["quantity"]]
    assert len(comp) == ("delta" in r) and all("momentum = 'random'" in c["convention"] for c in comp)


# ---------------------------------------------------------------------------
# fig6: the survival model with the paper's own constants beside ours
# ---------------------------------------------------------------------------
def test_fig6_paper_constant_kappa_law_is_the_fig2b_caption():
    """κ0(E) built from study.toml's paper_* keys against the caption of the paper's Fig. 2b, by hand:
    13.63 x² + 0.03 x below E = 0.27 and 1.41 x from there on, x = E − 1/6; no escape at or below E_c."""
    from hhscatter.reproduction.model_tables import kappa_from_constants
    from hhscatter.studies import load_study, stage_module

    mod = stage_module("fig6")
    for scale in ("tiny", "quick", "paper"):
        study = load_study("fig6", scale)
        pc = mod.paper_constants(study)
        assert pc["mu"] == 0.91
        kappa = kappa_from_constants(pc, study.model.critical_energy)
        E = np.array([0.1, 1 / 6, 0.2, 0.25, 0.2699, 0.27, 0.3, 0.35, 0.4])
        x = E - 1 / 6
        by_hand = [
            0.0,
            0.0,
            13.63 * x[2] ** 2 + 0.03 * x[2],
            13.63 * x[3] ** 2 + 0.03 * x[3],
            13.63 * x[4] ** 2 + 0.03 * x[4],
            1.41 * x[5],
            1.41 * x[6],
            1.41 * x[7],
            1.41 * x[8],
        ]
        np.testing.assert_allclose(kappa(E), by_hand, rtol=1e-12, atol=1e-15)
        # e.g. κ0(0.3) = 1.41 · 2/15 = 0.188 and κ0(0.25) = 13.63/144 + 0.0025
        assert float(kappa(0.3)) == pytest.approx(0.188, rel=1e-12)
        assert float(kappa(0.25)) == pytest.approx(13.63 / 144 + 0.0025, rel=1e-12)


def _fig6_pc(nums):
    """The rows made with the paper's constants: the JSON key and the comparison rows marked authors=True."""
    return nums["paper_constants"], [r for r in nums["paper_comparison"] if r["authors"]]


def test_fig6_paper_constant_rows_recompute_deterministically(tiny_studies):
    from hhscatter.studies import load_study, run_stage

    study = load_study("fig6", "tiny", root=tiny_studies)
    nums = json.loads(study.numbers_path.read_text())
    pc, rows = _fig6_pc(nums)
    assert {k: pc["constants"][k] for k in ("a", "b", "c", "E_b", "mu")} == {
        "a": 13.63,
        "b": 0.03,
        "c": 1.41,
        "E_b": 0.27,
        "mu": 0.91,
    }
    ours = pd.DataFrame(nums["fits"])
    ours = ours[ours["model"] == "homogeneous"].set_index(["pair", "hazard"])
    assert sorted((v["pair"], v["hazard"]) for v in pc["fits"]) == sorted(ours.index)  # every pair and hazard
    for v in pc["fits"]:
        # Eq. (eq:tau2) with μ = 0.91, by hand
        assert v["tau2_predicted"] == pytest.approx(math.log(v["E0"] / E_C) / (0.91 * v["gamma"]), rel=1e-12)
        mine = ours.loc[(v["pair"], v["hazard"])]
        # same fitted points as our constants' fit, and "better" is the smaller of the two residuals
        assert v["n_points"] == mine["n_points"] and v["rms_log_residual_ours"] == mine["rms_log_residual"]
        want = (
            "ours"
            if v["rms_log_residual_ours"] < v["rms_log_residual"]
            else "paper_constants"
            if v["rms_log_residual"] < v["rms_log_residual_ours"]
            else "tie"
        )
        assert v["better"] == want
    assert rows and all(
        r["convention"].startswith("authors': paper's constants (a, b, c, E_b, μ) = (13.63, 0.03, 1.41, 0.27, 0.91)")
        or r["convention"].startswith("authors': paper's μ = 0.91")
        for r in rows
    )
    assert all(r["verdict"] == NO_VERDICT for r in rows)  # a smoke test: values, no verdict
    # the curves of panel (a): one per hazard with the paper's constants, beside ours
    curves = pd.read_parquet(study.out / "derived" / "curves.parquet")
    assert {"paper_constants_paper", "paper_constants_integrated"} <= set(curves.columns)
    run_stage("fig6", "analyze", "tiny", root=tiny_studies)
    again = json.loads(study.numbers_path.read_text())
    assert _fig6_pc(again) == (pc, rows)


def test_fig6_changing_a_paper_constant_changes_only_its_rows(tiny_studies, tmp_path):
    from hhscatter.studies import load_study, run_stage

    for name in ("fig2", "fig3", "fig4", "fig6"):
        shutil.copytree(tiny_studies / name, tmp_path / name)
    shutil.copy(tiny_studies / "conventions.toml", tmp_path / "conventions.toml")  # a studies folder is self-contained
    before = json.loads(load_study("fig6", "tiny", root=tmp_path).numbers_path.read_text())
    toml = tmp_path / "fig6" / "study.toml"
    text = toml.read_text()
    assert text.count("paper_mu = 0.91\n") == 1 and text.count("paper_kappa_a = 13.63\n") == 1
    toml.write_text(
        text.replace("paper_mu = 0.91\n", "paper_mu = 0.8\n").replace(
            "paper_kappa_a = 13.63\n", "paper_kappa_a = 20.0\n"
        )
    )
    run_stage("fig6", "analyze", "tiny", root=tmp_path)
    after = json.loads(load_study("fig6", "tiny", root=tmp_path).numbers_path.read_text())
    pc0, rows0 = _fig6_pc(before)
    pc1, rows1 = _fig6_pc(after)
    assert pc1["constants"]["mu"] == 0.8 and pc1["constants"]["a"] == 20.0
    assert len(pc1["fits"]) == len(pc0["fits"]) > 0
    for v, v0 in zip(pc1["fits"], pc0["fits"]):
        assert (v["pair"], v["hazard"]) == (v0["pair"], v0["hazard"])
        assert v["tau2_predicted"] == pytest.approx(math.log(v["E0"] / E_C) / (0.8 * v["gamma"]), rel=1e-12)
        assert v["rms_log_residual"] != v0["rms_log_residual"]
        assert v["rms_log_residual_ours"] == v0["rms_log_residual_ours"]
    assert [r["ours"] for r in rows1] != [r["ours"] for r in rows0]
    assert all("0.8" in r["convention"] for r in rows1) and not any("0.91" in r["convention"] for r in rows1)
    # the rows with our constants are not touched
    for key in ("fits", "tau_vs_gamma", "kappa0", "mu", "compare_fits"):
        assert after[key] == before[key], key


def test_fig6_paper_constants_set_to_ours_reproduce_our_fit(tiny_studies, tmp_path):
    """The two arms differ by the constants alone: with the paper_* keys set to our fitted κ0(E) and μ (fig2, fig3
    at tiny scale), each fit with "the paper's constants" is our fit (same points, starts and free parameters), a tie."""
    from hhscatter.studies import load_study, run_stage

    for name in ("fig2", "fig3", "fig4", "fig6"):
        shutil.copytree(tiny_studies / name, tmp_path / name)
    shutil.copy(tiny_studies / "conventions.toml", tmp_path / "conventions.toml")  # a studies folder is self-contained
    k = _numbers(tmp_path, "fig2")["kappa_fit"]
    mine = {
        "paper_kappa_a": k["a"]["value"],
        "paper_kappa_b": k["b"]["value"],
        "paper_kappa_c": k["c"]["value"],
        "paper_kappa_Eb": k["E_b"]["value"],
        "paper_mu": _numbers(tmp_path, "fig3")["mu"]["value"],
    }
    toml = tmp_path / "fig6" / "study.toml"
    text = toml.read_text()
    for key, paper in (
        ("paper_kappa_a", "13.63"),
        ("paper_kappa_b", "0.03"),
        ("paper_kappa_c", "1.41"),
        ("paper_kappa_Eb", "0.27"),
        ("paper_mu", "0.91"),
    ):
        assert text.count(f"\n{key} = {paper}\n") == 1, key
        text = text.replace(f"\n{key} = {paper}\n", f"\n{key} = {mine[key]!r}\n")
    toml.write_text(text)
    run_stage("fig6", "analyze", "tiny", root=tmp_path)
    nums = json.loads(load_study("fig6", "tiny", root=tmp_path).numbers_path.read_text())
    pc = nums["paper_constants"]
    assert pc["constants"]["mu"] == mine["paper_mu"] == nums["mu"]["value"]
    assert pc["fits"]
    for v in pc["fits"]:
        assert v["tau2_predicted"] == v["tau2_predicted_ours"]
        assert v["rms_log_residual"] == v["rms_log_residual_ours"] and v["better"] == "tie"
    curves = pd.read_parquet(tmp_path / "fig6" / "out" / "tiny" / "derived" / "curves.parquet")
    for h in ("paper", "integrated"):
        np.testing.assert_array_equal(curves[f"paper_constants_{h}"], curves[f"homogeneous_{h}"])
