"""Tests of the chaotic-saddle study ``saddle`` at its tiny scale.

The estimators are tested in tests/analysis/geometry/test_saddle.py against open maps with known κ, λ and d; here
the study's records are checked against the raw runs they come from and against the relation's arithmetic done by
hand: λ̄ = ΣΛ/ΣT of the tangent run's long-lived orbits, d₁ = D₁/2, λ̄(1 − d₁) and z.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

KEYS = {"system", "energy", "kappa", "kappa_err", "lyapunov", "lyapunov_err", "d0", "d0_err", "d1", "d1_err"}


@pytest.fixture(scope="module")
def built(tiny_studies):
    """The saddle study at the tiny scale (built with every study, in the order of the graph)."""
    return tiny_studies / "saddle" / "out" / "tiny"


def test_every_record_has_the_keys_and_d0_is_measured(built):
    doc = json.loads((built / "saddle.json").read_text())
    assert len(doc["saddle"]) == 3 and (built / "saddle.png").exists()
    for rec in doc["saddle"]:
        assert KEYS <= set(rec), rec["id"]
        if rec["d0"] is None:  # a point without d₀ says why
            assert any(n.startswith("d0: ") for n in rec["notes"]), rec["id"]
        else:
            assert 0 < rec["d0"] < 1 and rec["d0_err"] > 0, rec["id"]
    rec = next(r for r in doc["saddle"] if r["id"] == "henon_heiles-1.80")
    assert rec["d0"] is not None
    assert doc["dimensions_summary"]["n_d0"] == sum(r["d0"] is not None for r in doc["saddle"])


def test_the_lines_are_pairs_moved_by_eps_along_x_at_the_same_energy(built):
    import pandas as pd

    ics = pd.read_parquet(built / "derived" / "henon_heiles_r1.80_lines_ics.parquet")
    eps = sorted(ics["eps"].unique(), reverse=True)
    assert eps == pytest.approx([1e-2, 1e-3, 1e-4, 1e-5])
    m = ics[~ics["moved"]].merge(ics[ics["moved"]], on=["eps", "pair"], suffixes=("", "_m"))
    assert len(m) == (~ics["moved"]).sum() == ics["moved"].sum()
    assert np.allclose(m["x_m"] - m["x"], m["eps"], rtol=1e-9, atol=1e-15) and np.array_equal(m["y_m"], m["y"])
    for s in ("", "_m"):
        x, y, px, py = (m[c + s].to_numpy() for c in ("x", "y", "px", "py"))
        E = 0.5 * (px**2 + py**2) + 0.5 * (x**2 + y**2) + x**2 * y - y**3 / 3
        assert np.allclose(E, 1.8 / 6, rtol=1e-12)  # E = 1.8 E_c, E_c = 1/6
        assert np.allclose(x * px + y * py, 0, atol=1e-12)  # tangential: on the section ṙ = 0


def test_d0_counts_the_pairs_with_different_exits_from_the_raw_run(built):
    """k(ε): the pairs whose exit channels differ, counted by hand from the lines run (pairs with an orbit still
    inside at t_max left out); d₀ ≥ d₁ − 2σ by hand."""
    import pandas as pd

    from hhscatter.data.read import read_lifetimes

    doc = json.loads((built / "saddle.json").read_text())
    rec = next(r for r in doc["saddle"] if r["id"] == "henon_heiles-1.80")
    ics = pd.read_parquet(built / "derived" / "henon_heiles_r1.80_lines_ics.parquet")
    lt = read_lifetimes(built / "raw" / "henon_heiles_r1.80_lines", columns=["traj_id", "outcome", "exit_channel"])
    t = ics.merge(lt, on="traj_id")
    t["ch"] = np.where(t["outcome"].astype(str) == "escaped", t["exit_channel"].astype(float), np.nan)
    m = t[~t["moved"]].merge(t[t["moved"]], on=["eps", "pair"], suffixes=("", "_m"))
    for row in rec["d0_uncertainty"]:
        g = m[np.isclose(m["eps"], row["eps"]) & m["ch"].notna() & m["ch_m"].notna()]
        assert row["n"] == len(g) and row["k"] == int((g["ch"] != g["ch_m"]).sum())
    lo, hi = rec["d0_eps_range"]
    fitted = [r for r in rec["d0_uncertainty"] if lo <= r["eps"] <= hi]
    assert len(fitted) == rec["d0_n_eps"] >= 3 and all(r["k"] >= 2 for r in fitted)
    assert rec["d0_section"] == pytest.approx(2 * rec["d0"], rel=1e-12)
    if rec.get("d1") is not None:
        z = (rec["d0"] - rec["d1"]) / math.hypot(rec["d0_err"], rec["d1_err"])
        assert rec["d0_ge_d1"]["z"] == pytest.approx(z, rel=1e-12)
        assert rec["d0_ge_d1"]["holds"] is (z >= -2)


def test_the_lyapunov_exponent_is_the_tangent_run_s_stretch_over_time(built):
    """λ̄ = ΣΛ/ΣT over the orbits of the tangent run that left at t_end ≥ t_min, read from the raw table."""
    from hhscatter.data.read import read_lifetimes

    doc = json.loads((built / "saddle.json").read_text())
    rec = next(r for r in doc["saddle"] if r["id"] == "henon_heiles-1.80")
    lt = read_lifetimes(built / "raw" / "henon_heiles_r1.80_tangent", columns=["outcome", "t_end", "log_stretch"])
    keep = (lt["outcome"].astype(str) == "escaped") & (lt["t_end"] >= rec["t_min"])
    assert keep.sum() >= 50
    mean = lt["log_stretch"][keep].sum() / lt["t_end"][keep].sum()
    assert rec["lyapunov_detail"]["mean"] == pytest.approx(mean, rel=1e-12)
    assert rec["lyapunov"] == pytest.approx(
        mean if rec["lyapunov_detail"]["converged"] else rec["lyapunov_detail"]["extrapolated"], rel=1e-12
    )


def test_the_relation_is_checked_with_the_partial_dimension_half_the_section_s(built):
    doc = json.loads((built / "saddle.json").read_text())
    checked = [r for r in doc["saddle"] if r.get("z") is not None]
    assert checked and doc["summary"]["n_checked"] == len(checked)
    for r in checked:
        assert r["d1"] == pytest.approx(r["d1_section"] / 2, rel=1e-12)
        assert r["d1_err"] == pytest.approx(r["d1_section_err"] / 2, rel=1e-12)
        pred = r["lyapunov"] * (1 - r["d1"])
        sig = math.hypot(r["kappa_err"], math.hypot((1 - r["d1"]) * r["lyapunov_err"], r["lyapunov"] * r["d1_err"]))
        assert r["predicted"] == pytest.approx(pred, rel=1e-12)
        assert r["z"] == pytest.approx((r["kappa"] - pred) / sig, rel=1e-9)
        assert r["d1_eps_range"][0] > 0  # the smallest box: the points' distance to the saddle, not 0
    for r in doc["saddle"]:
        if r.get("z") is None:
            assert r["notes"], r["id"]  # a point without the relation says why


def test_the_tangent_runs_start_from_the_long_lived_orbits_initial_conditions(built):
    from hhscatter.data.read import read_lifetimes

    doc = json.loads((built / "saddle.json").read_text())
    rec = next(r for r in doc["saddle"] if r["id"] == "henon_heiles-2.40")
    main = read_lifetimes(built / "raw" / "henon_heiles_r2.40", columns=["traj_id", "x0", "y0", "outcome", "t_end"])
    tan = read_lifetimes(built / "raw" / "henon_heiles_r2.40_tangent", columns=["traj_id", "x0", "y0", "t_end"])
    long = main[(main["outcome"].astype(str) == "escaped") & (main["t_end"] >= rec["t_min"])]
    m = long.merge(tan, on="traj_id", suffixes=("", "_tan"))
    assert len(m) == len(long) == len(tan)
    assert np.array_equal(m["x0"], m["x0_tan"]) and np.array_equal(m["y0"], m["y0_tan"])
    # the same orbits, one integration: the tangent dynamics never set a step and the events are the main run's, so
    # every selected orbit ends at the main run's t_end, bit for bit (a rounding apart would be another orbit)
    assert m["t_end"].to_numpy().tobytes() == m["t_end_tan"].to_numpy().tobytes()
    assert rec["tangent_same_orbits"] == {"same_t_end": len(long), "selected": len(long)}


def test_the_d1_estimator_covers_the_baker_natural_measure_at_a_quick_scale_sample():
    """The study's d₁ estimator (its rules of study.toml) on 10⁴ points of 2000 orbits drawn from the natural
    measure of the area-preserving open baker map, the sample of a quick-scale point: its 2σ interval covers the
    closed form D₁ = 2 d₁ᵘ in at least 9 of 10 seeds (box counting with the same points read it high)."""
    import pandas as pd

    from hhscatter.analysis.geometry.saddle import SaddlePoints
    from hhscatter.studies import load_study, stage_module
    from tests.analysis.geometry.test_saddle import closed_forms, natural_measure

    study = load_study("saddle", "quick")
    est = stage_module("saddle")._d1_estimator(study.params)
    a = (0.45, 0.45)
    truth = 2 * closed_forms(a, a)["d1u"]
    covered = 0
    for seed in range(10):
        P, orbits = natural_measure(a, 2000, 5, seed)
        pts = pd.DataFrame({"traj_id": orbits, "t": 0.0, "x": P[:, 0], "y": P[:, 1]})
        sp = SaddlePoints(points=pts, t_min=100.0, window=(0.4, 0.6), n_long=2000, n_orbits=2000, n_points=len(pts),
                          n_beyond_record=0)  # fmt: skip
        d = est(sp)
        covered += abs(d.value - truth) <= 2 * d.err
    assert covered >= 9, covered


def test_a_system_s_own_tmin_efolds_replaces_the_study_s(built):
    """tiny: [study] tmin_efolds = 3, Barbanis' entry 2: its t_min is 2/κ of its main run, Hénon–Heiles' 3/κ, in the
    record, in the tangent run's selection and in the d₁ convergence rows."""
    from hhscatter.data.read import read_lifetimes

    doc = json.loads((built / "saddle.json").read_text())
    assert doc["rules"]["tmin_efolds"] == 3.0 and doc["rules"]["tmin_efolds_by_system"] == {"barbanis": 2.0}
    for rid, efolds in (("henon_heiles-1.80", 3.0), ("henon_heiles-2.40", 3.0), ("barbanis-2.60", 2.0)):
        rec = next(r for r in doc["saddle"] if r["id"] == rid)
        assert rec["t_min"] * rec["kappa"] == pytest.approx(efolds, rel=1e-12), rid
        if rec.get("d1_by_t_min"):
            assert rec["d1_by_t_min"][-1]["t_min_kappa"] == efolds, rid
    rec = next(r for r in doc["saddle"] if r["id"] == "barbanis-2.60")
    main = read_lifetimes(built / "raw" / "barbanis_r2.60", columns=["traj_id", "outcome", "t_end"])
    tan = read_lifetimes(built / "raw" / "barbanis_r2.60_tangent", columns=["traj_id"])
    long = main[(main["outcome"].astype(str) == "escaped") & (main["t_end"] >= 2.0 / rec["kappa"])]
    assert len(long) > len(main[(main["outcome"].astype(str) == "escaped") & (main["t_end"] >= 3.0 / rec["kappa"])])
    assert sorted(tan["traj_id"]) == sorted(long["traj_id"])


def test_a_system_s_own_lines_rules_replace_the_study_s_and_may_not_lie_after_them():
    """The paper scale: Barbanis' entry has lines_efolds 4 and lines_checks [3, 5], the others [study]'s 6 and
    [5, 7]; a system's own later than [study]'s latest (the lines run to 3 e-folds after it) is refused by name."""
    from types import SimpleNamespace

    from hhscatter.errors import ConfigError
    from hhscatter.studies import load_study, stage_module

    mod, study = stage_module("saddle"), load_study("saddle", "paper")
    assert mod._lines_rules(study, "barbanis") == (4.0, [3.0, 5.0])
    assert mod._lines_rules(study, "henon_heiles") == (6.0, [5.0, 7.0])
    assert mod._tmin_overrides(study)["lines_by_system"] == {
        "barbanis": {"lines_efolds": 4.0, "lines_checks": [3.0, 5.0]}
    }
    late = SimpleNamespace(params=SimpleNamespace(lines_efolds=6.0, lines_checks=[5.0, 7.0],
                                                  systems=[{"label": "b", "lines_efolds": 8.0}]))  # fmt: skip
    with pytest.raises(ConfigError, match=r"systems\[b\] lines_efolds/lines_checks must be ≤ 7"):
        mod._lines_rules(late, "b")


def test_d1_s_floor_is_a_fraction_of_the_extent_and_its_scan_holds_the_rule_s_d1(built):
    """d₁'s scaling range starts at d1_floor × the points' extent or above (never at a scale set by λ̄), and the
    floor scan's row with factor 1 is the record's d₁ itself (the same points, rule and seed); its floors are the
    rule's times d1_floor_factors."""
    doc = json.loads((built / "saddle.json").read_text())
    rules, checked = doc["rules"], 0
    for rec in doc["saddle"]:
        if rec.get("d1") is None:
            continue
        assert rec["d1_eps_min_extent"] == rules["d1_floor"] and rec["d1_eps_range_extent"][0] >= rules["d1_floor"]
        scan = rec["d1_floor_scan"]
        assert [r["factor"] for r in scan["rows"]] == rules["d1_floor_factors"]
        assert [r["floor"] for r in scan["rows"]] == pytest.approx(
            [f * rules["d1_floor"] for f in rules["d1_floor_factors"]]
        )
        one = next(r for r in scan["rows"] if r["factor"] == 1.0)
        assert one["d1"]["value"] == pytest.approx(rec["d1"], rel=1e-12)
        assert one["d1"]["err"] == pytest.approx(rec["d1_err"], rel=1e-12)
        assert 0 < scan["scatter_extent"] < 1
        checked += 1
    assert checked >= 1


def test_d1_s_estimator_takes_no_lyapunov_exponent():
    """The same points give the same d₁ whatever λ̄ and t_min: the estimator is a function of the points and the
    rules alone (its range d1_floor·extent … extent/min_boxes)."""
    import inspect

    import pandas as pd

    from hhscatter.analysis.geometry.saddle import SaddlePoints
    from hhscatter.studies import load_study, stage_module

    study = load_study("saddle", "quick")
    make = stage_module("saddle")._d1_estimator
    assert list(inspect.signature(make).parameters) == ["p"]
    rng = np.random.default_rng(0)
    t = 2 * np.pi * rng.random(4000)
    pts = pd.DataFrame({"traj_id": np.arange(4000), "t": 0.0, "x": np.cos(t), "y": np.sin(t)})
    d = [make(study.params)(SaddlePoints(points=pts, t_min=tm, window=(0.4, 0.6), n_long=4000, n_orbits=4000,
                                         n_points=4000, n_beyond_record=0)) for tm in (10.0, 1000.0)]  # fmt: skip
    assert (d[0].value, d[0].err, d[0].eps_range) == (d[1].value, d[1].err, d[1].eps_range)
    assert d[0].eps_range[0] >= study.params.d1_floor * 2.0  # the circle's extent is 2


def test_the_dense_lines_lie_on_lines_across_the_disk_at_the_energy(built):
    """lines_count lines y = const within 0.8 of the disk's radius, lines_n positions a line (fewer where V ≥ E),
    tangential momenta at E = 1.8 E_c: the initial conditions of d₁ on lines."""
    import pandas as pd

    doc = json.loads((built / "saddle.json").read_text())
    rules = doc["rules"]
    ics = pd.read_parquet(built / "derived" / "henon_heiles_r1.80_dlines_ics.parquet")
    assert sorted(ics["line"].unique()) == list(range(rules["lines_count"]))
    per = ics.groupby("line")
    assert per["y"].nunique().eq(1).all() and per.size().le(rules["lines_n"]).all()
    assert per.size().sum() > 0.9 * rules["lines_count"] * rules["lines_n"]
    assert np.all(np.abs(per["y"].first()) <= 0.8 * 0.5) and np.all(np.hypot(ics["x"], ics["y"]) < 0.5)
    x, y, px, py = (ics[c].to_numpy() for c in ("x", "y", "px", "py"))
    E = 0.5 * (px**2 + py**2) + 0.5 * (x**2 + y**2) + x**2 * y - y**3 / 3
    assert np.allclose(E, 1.8 / 6, rtol=1e-12) and np.allclose(x * px + y * py, 0, atol=1e-12)


def test_d1_on_lines_is_the_survivors_dimension_and_the_relation_is_done_with_it(built):
    """d₁ on lines recomputed from the raw run: the positions along their lines of the orbits that left at
    t_end ≥ lines_efolds/κ, each line a block, floor lines_floor; the relation κ against λ̄(1 − d₁) with it by hand."""
    import pandas as pd

    from hhscatter.analysis.geometry.saddle import information_dimension_neighbours
    from hhscatter.data.read import read_lifetimes

    doc = json.loads((built / "saddle.json").read_text())
    rules = doc["rules"]
    rec = next(r for r in doc["saddle"] if r["id"] == "henon_heiles-1.80")
    det = rec["d1_lines_detail"]
    ics = pd.read_parquet(built / "derived" / "henon_heiles_r1.80_dlines_ics.parquet")
    lt = read_lifetimes(built / "raw" / "henon_heiles_r1.80_dlines", columns=["traj_id", "outcome", "t_end"])
    m = ics.merge(lt, on="traj_id")
    sel = m[(m["outcome"].astype(str) == "escaped") & (m["t_end"] >= rules["lines_efolds"] / rec["kappa"])]
    assert det["n_points"] == len(sel) and det["n_lines"] == rules["lines_count"]
    d = information_dimension_neighbours(sel["x"].to_numpy(), blocks=sel["line"].to_numpy(), k_max=16,
                                         floor=rules["lines_floor"], n_boot=10, seed=0)  # fmt: skip
    assert rec["d1_lines"] == {"value": pytest.approx(d.value, rel=1e-12), "err": pytest.approx(d.err, rel=1e-12)}
    lam, d1 = rec["lyapunov"], rec["d1_lines"]["value"]
    assert det["predicted"]["value"] == pytest.approx(lam * (1 - d1), rel=1e-12)
    sig = math.hypot(rec["kappa_err"], det["predicted"]["err"])
    assert det["z"] == pytest.approx((rec["kappa"] - lam * (1 - d1)) / sig, rel=1e-9)
    assert det["scatter_extent"] == pytest.approx(math.exp(-lam * rules["lines_efolds"] / rec["kappa"]), rel=1e-12)
    assert [r["t_min_kappa"] for r in det["by_t_min"]] == sorted({rules["lines_efolds"], *rules["lines_checks"]})
    if rec.get("gap"):  # the gap's candidates include d₁ on lines
        assert "lines" in rec["gap"]
    # the bands: the same survivors, the estimator over each decade of a line's extent and the section's band alone
    from hhscatter.analysis.geometry.saddle import neighbour_scale_bands

    rows = [r for r in det["bands"] if r["t_min_kappa"] == rules["lines_efolds"]]
    decades = [(r["lo"], r["hi"]) for r in rows]
    assert decades[0][0] == rules["lines_floor"] and decades[-1][1] == pytest.approx(0.125)
    assert [hi for _lo, hi in decades[:-1]] == pytest.approx([10 * lo for lo, _hi in decades[:-1]])
    assert decades[-1][1] == pytest.approx(0.125) and all(hi >= 2 * lo for lo, hi in decades)  # no sliver at the top
    tab = neighbour_scale_bands(sel["x"].to_numpy(), blocks=sel["line"].to_numpy(), bands=decades, k_max=16,
                                n_boot=10, seed=0)  # fmt: skip
    for r, t in zip(rows, tab.itertuples()):
        assert (r["d1"] is None) == (not math.isfinite(t.value))
        if r["d1"]:
            assert r["d1"]["value"] == pytest.approx(t.value, rel=1e-12)
    sec = det["at_section_scales"]
    assert (sec["lo"], sec["hi"]) == (rules["d1_floor"], 0.125)
