"""End-to-end test of the study ``basins`` at SCALE=tiny (built in graph order by conftest's tiny_studies)."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
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
    # like-for-like Wada, local exponents, energy scan, the cut-off prediction, E_b and μ from upstream
    fig2 = json.loads((tiny_studies / "fig2" / "out" / "tiny" / "fig2.json").read_text())
    assert nums["E_b"]["value"] == fig2["kappa_fit"]["E_b"]["value"]
    fig3 = json.loads((tiny_studies / "fig3" / "out" / "tiny" / "fig3.json").read_text())
    assert nums["mu"]["value"] == fig3["mu"]["value"]
    for p in nums["per_point"]:
        assert "wada_exits" in p and "local_d" in p and "slim_fractal" in p
        if p["gamma"] == 0:
            assert p["wada_exits"] is None or p["wada_exits"]["basins"] == ["exit 0", "exit 1", "exit 2"]
    recs = nums["cutoff_prediction"]
    assert {(r["E0"], r["gamma"]) for r in recs} == {
        (p["energy"], p["gamma"]) for p in nums["per_point"] if p["gamma"] > 0
    }
    for r in recs:
        assert {"E0", "gamma", "eps_c", "eps_c_err", "eps_c_predicted"} <= set(r)
        assert 0 <= r["eps_c_predicted"] < 1
    scan = pd.read_parquet(out / "derived" / "basins_energy_scan.parquet")
    assert sorted(scan.energy) == [0.2, 0.3] and (scan.above_E_b == (scan.energy > nums["E_b"]["value"])).all()
    # S_b, S_bb at fixed box sides: on every grid the study computes (the maps and the scan maps at the study's
    # energies), each side a whole number of that grid's cells, the same side giving the same physical box
    recs = nums["entropy_by_box"]
    cfg = nums["config"]["study"]
    scan_too = any(abs(e - E) < 1e-12 for e in cfg["scan_energies"] for E in cfg["energies"])
    assert {(r["grid"], r["map"]) for r in recs} == {(n, "map")} | ({(cfg["scan_grid"], "scan")} if scan_too else set())
    for r in recs:
        assert r["box_cells"] >= 2 and abs(r["box_side"] - r["box_cells"] * 2.0 / r["grid"]) < 1e-12
        assert 0 <= r["S_b"] <= r["S_bb"] + 1e-12 or r["S_bb"] != r["S_bb"]
    assert {round(r["box_side"], 9) for r in recs if r["map"] == "map"} >= {0.083333333, 0.166666667}
    summ = nums["cutoff_summary"]
    assert summ["n_resolved"] == sum(1 for r in nums["cutoff_prediction"] if r["detected"])


def test_subgrid_cells_are_cells_of_the_map_and_their_entropies_are_the_subsampled_maps():
    """Every k-th cell from k // 2 (k odd) has the centre of the coarse grid's cell: (j + ½)·h·k = (k·j + k//2 + ½)·h.
    The entropies at the fixed sides are those of that subsampled image; an even k (no common centres) and a
    subgrid that does not divide the map give nothing."""
    from types import SimpleNamespace

    from hhscatter.analysis.geometry.basins import entropy_by_box
    from hhscatter.studies.study import stage_module

    mod = stage_module("basins")
    n, k, ext = 60, 5, (-1.0, 1.0, -1.0, 1.0)
    fine = (np.arange(n) + 0.5) * 2.0 / n - 1.0
    coarse = (np.arange(n // k) + 0.5) * 2.0 / (n // k) - 1.0
    assert np.allclose(fine[k // 2 :: k], coarse)
    X, Y = np.meshgrid(fine, fine)
    img = np.where(np.sin(7 * X) * np.cos(5 * Y) > 0, 0, 1).astype(np.int8)
    img[X**2 + Y**2 > 0.95] = -1
    study = SimpleNamespace(params=SimpleNamespace(box_sides=[1 / 3, 2 / 3], box_subgrids=[12, 15, 7]))
    rows = mod._entropy_by_subgrid(study, img, 0.25, 0.0, ext)
    want = entropy_by_box(img[2::5, 2::5], ext, [1 / 3, 2 / 3], outside=-1)
    assert [r["map"] for r in rows] == ["every 5th cell"] * 2  # 15: k = 4 is even; 7 does not divide 60
    assert [r["grid"] for r in rows] == [12, 12]
    assert np.allclose([r["S_b"] for r in rows], want["S_b"]) and np.allclose([r["S_bb"] for r in rows], want["S_bb"])


def test_the_deciding_orbits_own_decay_is_counted_from_the_raw_runs(tiny_studies):
    """mu_own: Σ ln(E0/E_end)/(γ Σ t) over the reference orbits whose outcome differs from their moved copy's at the
    smallest resolved ε, counted here from the raw runs."""
    from hhscatter.data.read import read_lifetimes

    out = tiny_studies / "basins" / "out" / "tiny"
    nums = json.loads((out / "basins.json").read_text())
    cfg = nums["config"]["study"]
    checked = 0
    for p in nums["per_point"]:
        if p["gamma"] == 0:
            assert p["mu_own"] is None
            continue
        if p["mu_own"] is None:
            continue
        i = cfg["eps"].index(p["smallest_resolved_eps"])
        lt = read_lifetimes(
            out / "raw" / f"unc{i}_E{p['energy']:.2f}_g{p['gamma']:g}",
            columns=["traj_id", "outcome", "exit_channel", "t_end", "e0", "e_end"],
        ).sort_values("traj_id")
        oc = lt["outcome"].astype(str).to_numpy()
        code = np.where(oc == "escaped", lt["exit_channel"].astype(float).fillna(-1), np.where(oc == "settled", 3, 4))
        m = len(lt) // 2
        ref = lt.iloc[:m][code[:m] != code[m:]]
        mu = np.log(ref["e0"] / ref["e_end"]).sum() / (p["gamma"] * ref["t_end"].sum())
        assert p["mu_own"]["value"] == pytest.approx(mu, rel=1e-12) and p["mu_own"]["n_orbits"] == len(ref)
        checked += 1
    assert checked >= 1


def test_the_cut_off_is_re_predicted_with_the_saddle_s_lambda(tiny_studies):
    """λ̄(E) of the Hénon–Heiles records beside the basins' decision rate and κ/α at the energies both have; the
    predicted ε_c with λ̄ and the basins' μ equals λ̄'s closed form where λ̄ is one constant (one energy)."""
    saddle = json.loads((tiny_studies / "saddle" / "out" / "tiny" / "saddle.json").read_text())
    doc = basins = json.loads((tiny_studies / "basins" / "out" / "tiny" / "basins.json").read_text())
    hh = sorted(
        (r["energy"], r["lyapunov"], r["lyapunov_err"]) for r in saddle["saddle"] if r["system"] == "henon_heiles"
    )
    hh = [x for x in hh if x[1] is not None]
    assert [(r["energy"], r["lam"], r["lam_err"]) for r in doc["lambda_tangent"]["rows"]] == hh
    scan = {round(r["energy"], 9): r for r in basins["energy_scan"]}
    rows = doc["rate_table"]
    assert [r["E0"] for r in rows] == [E for E, _, _ in hh if round(E, 9) in scan]
    for r in rows:
        s = scan[round(r["E0"], 9)]
        assert (r["decision"], r["kappa_over_alpha"]) == (s["lam"], s["lam_kg"])
        assert r["decision_over_tangent"] == pytest.approx(s["lam"] / r["tangent"], rel=1e-12)
    cut = doc["cutoff_saddle"]
    assert {(r["E0"], r["gamma"]) for r in cut} == {
        (p["energy"], p["gamma"]) for p in basins["per_point"] if p["gamma"] > 0
    }
    ec, mu = 1 / 6, basins["mu"]["value"]
    for r in cut:
        grid = np.linspace(ec, r["E0"], 2001)
        lam = np.interp(grid, [x[0] for x in hh], [x[1] for x in hh])
        v = lam / grid
        big = np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(grid)) / (mu * r["gamma"])  # ln(1/ε_c) = ∫λ/E dE / (μγ)
        assert r["eps_c_tangent"] == pytest.approx(math.exp(-big), rel=1e-6)


def test_each_orbit_s_stretch_is_counted_from_the_raw_runs(tiny_studies):
    """S(ln 1/ε) of a point: the reference orbits of its uncertainty runs whose Λ = ∫λ̄(E(t))dt, integrated here in
    time along E(t) = e0 (e_end/e0)^{t/t_end} with λ̄ of the saddle's Hénon–Heiles records, exceeds ln(1/ε)."""
    from hhscatter.data.read import read_lifetimes

    out = tiny_studies / "basins" / "out" / "tiny"
    doc = json.loads((out / "basins.json").read_text())
    rows = doc["lambda_tangent"]["rows"]
    En, lam = np.array([r["energy"] for r in rows]), np.array([r["lam"] for r in rows])
    rec = next(r for r in doc["stretch"] if r["gamma"] > 0)
    E, g = rec["energy"], rec["gamma"]
    L = []
    for i, _eps in enumerate(doc["eps"]):
        lt = read_lifetimes(out / "raw" / f"unc{i}_E{E:.2f}_g{g:g}", columns=["traj_id", "t_end", "e0", "e_end"])
        ref = lt.sort_values("traj_id").iloc[: len(lt) // 2]
        e0, e1, T = (ref[c].to_numpy(dtype=float) for c in ("e0", "e_end", "t_end"))
        u = np.linspace(0.0, 1.0, 4001)[None, :]
        Et = e0[:, None] * (np.maximum(e1, 1e-12)[:, None] / e0[:, None]) ** u
        v = np.interp(Et, En, lam)
        L.append(T * np.sum(0.5 * (v[:, 1:] + v[:, :-1]), axis=1) / (u.size - 1))
    L = np.concatenate(L)
    assert rec["n_orbits"] == L.size
    for r in rec["rows"]:
        k = np.count_nonzero(L > math.log(1 / r["eps"]))
        assert r["S"] == pytest.approx(k / L.size, abs=2 / L.size)  # an orbit at the threshold may round either way
        assert (r["f_over_S"] is None) == (k == 0)
    assert doc["stretch_summary"]["statement"]
