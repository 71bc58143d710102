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

from tests.study_copy import copy_study_folder

KEYS = {"system", "energy", "kappa", "kappa_err", "lyapunov", "lyapunov_err", "d0", "d0_err", "d1", "d1_err"}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    from hhscatter.studies import run_stage

    root = tmp_path_factory.mktemp("studies")
    copy_study_folder("saddle", root)
    run_stage("saddle", "all", "tiny", workers=1, progress=False, root=root)
    return root / "saddle" / "out" / "tiny"


def test_every_record_has_the_issue_s_keys_and_d0_is_stated_as_not_measured(built):
    doc = json.loads((built / "saddle.json").read_text())
    assert len(doc["saddle"]) == 3 and (built / "saddle.png").exists()
    for rec in doc["saddle"]:
        assert KEYS <= set(rec), rec["id"]
        assert rec["d0"] is None and rec["d0_err"] is None
    assert "not measured" in doc["d0_note"]


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
    # the same orbit again (the tangent variables change only heyoka's steps): the same lifetime to roundoff growth
    assert np.max(np.abs(m["t_end"] - m["t_end_tan"])) < 1e-3
