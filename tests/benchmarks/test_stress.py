"""Stress cases of ``make stress`` (benchmarks/stress.py) at small size.

Each case compares the engine with an independent reference (heyoka long
double with exact event location, or the conservation law) and returns
``ok`` by its own acceptance rule; the asserts here restate the rule's core so
that a failure names what broke.
"""

import numpy as np
import pytest

from benchmarks import stress


def test_energy_drift_of_censored_orbits_small():
    """tol 1e-15: |ΔH|/H of orbits censored at t_sel at t = 1000 ≤ 1e-13 (conservation law as reference)."""
    r = stress.case_energy_drift(n_orbits=2, n_try=300, tols=(1e-15,), t_max=1000.0, t_sel=1000.0, n_times=5)
    assert r.extra["n_orbits"] >= 1, "no censored orbit found"
    assert r.ok, r.finding
    assert max(row["max_rel_energy_err"] for row in r.rows) < 1e-13


@pytest.mark.slow
def test_energy_drift_grows_slower_at_tighter_tolerance():
    """tol 1e-9 drifts (≥ 1e-11 at t = 5000) while tol 1e-15 stays ≤ 1e-13: the tolerance is what bounds drift."""
    r = stress.case_energy_drift(n_orbits=4, tols=(1e-9, 1e-15), t_max=5000.0)
    last = {row["tol"]: row["max_rel_energy_err"] for row in r.rows if row["t"] == 5000.0}
    assert last[1e-15] < 1e-13 and last[1e-9] > 1e-11
    assert r.ok, r.finding


def test_near_threshold_small():
    """E − E_c = 1e-2: valid outcomes, energy at escape conserved, short escapes match the reference."""
    r = stress.case_near_threshold(deltas=(1e-2,), n=12, t_max=300.0, n_ref=6, t_ref=60.0)
    row = r.rows[0]
    assert row["valid"]
    assert row["max_energy_err_at_escape"] < 1e-12
    assert row["ref_agree_short"] == row["ref_short_escapes"]
    assert r.ok, r.finding


def test_saddle_starts_small():
    """Orbits started at the saddle: escape events and times equal the long-double reference at tol 1e-15."""
    r = stress.case_saddle_starts(offsets=(0.0, 1e-8), n_dir=3, tols=(1e-15,))
    assert sum(row["ref_escaped"] for row in r.rows) >= 4
    assert all(row["missed"] == 0 and row["spurious"] == 0 for row in r.rows), r.rows
    assert r.ok


def test_tangent_points_are_tangent():
    """The constructed grazing states have ṙ = 0 and r̈ < 0 on r = r_t (closed-form check of the construction)."""
    for x, y, px, py in stress._tangent_points(r_t=1.02):
        r = np.hypot(x, y)
        assert abs(r - 1.02) < 1e-14
        assert abs(x * px + y * py) < 1e-14
        fx, fy = -x - 2 * x * y, -y - x * x + y * y
        rdd = (px * px + py * py) / r + (x * fx + y * fy) / r
        assert rdd < 0 and abs(rdd + 0.02) < 1e-9


def test_tangent_to_escape_circle_small():
    """Gap ±1e-9 to r = r_esc: escape found exactly when the reference finds one (tol 1e-15)."""
    r = stress.case_tangent_resc(gaps=(1e-9, -1e-9), tols=(1e-15,))
    rows = {row["gap"]: row for row in r.rows}
    assert rows[-1e-9]["ref_escaped"] == rows[-1e-9]["n"]  # poking out: every reference orbit escapes
    assert all(row["missed"] == 0 and row["spurious"] == 0 for row in r.rows), r.rows
    assert r.ok


@pytest.mark.slow
def test_tangent_tolerance_matters():
    """At tol 1e-9 a gap of 1e-14 is below the state error: disagreements appear (the case can fail)."""
    r = stress.case_tangent_resc(gaps=(1e-14, -1e-14), tols=(1e-9,))
    assert sum(row["missed"] + row["spurious"] for row in r.rows) > 0


def test_section_skim_small():
    """Near double roots of ṙ = 0 (η = ±1e-8): crossing pairs found exactly as by the reference."""
    r = stress.case_section_skim(etas=(1e-8, -1e-8), tols=(1e-15,))
    assert sum(row["ref_crossings_near_T"] for row in r.rows) >= 4
    assert all(row["missed"] == 0 and row["duplicated"] == 0 for row in r.rows), r.rows
    assert r.ok


def test_dissipation_extremes_and_far_radius_small():
    """γ = 1 and r_far = 1e8 (orbits followed far towards blow-up): finite tables, outcomes as the reference.

    Before the far event was normalised (engine.py), r_far = 1e8 loosened the
    step-size control and gave wrong outcomes for orbits that never left.
    """
    r = stress.case_dissipation_extremes(gammas=(1.0,), n=12, r_fars=(1e8,), r_far_gamma=0.1, n_ref=6)
    for row in r.rows:
        assert not row.get("error"), row
        assert row["nonfinite_values"] == 0
        assert row["ref_outcome_agree"] == row["ref_n"], row
    assert r.ok, r.finding


def test_far_radius_does_not_change_results():
    """Escape/settle times do not depend on r_far (it only decides when an escaped orbit is dropped)."""
    from hhscatter.integrate.engine import run_chunk
    from hhscatter.scene.ics import region_ics
    from hhscatter.scene.scene import Scene

    base = Scene(energy=0.3, gamma=0.05, n=16, seed=3)
    ics = region_ics(base, 0, 16)
    out = [run_chunk(base.replace(r_far=rf), ics, np.arange(16)).lifetimes for rf in (3.0, 1e4)]
    assert (out[0]["outcome"] == out[1]["outcome"]).all()
    assert np.abs(out[0]["t_end"] - out[1]["t_end"]).max() <= 1e-12 * out[0]["t_end"].max()


def test_first_section_crossing_inside_the_first_step():
    """ICs lie exactly on the section; a crossing within the first Taylor step (t ≈ 0.03–0.25) must be recorded.

    Orbits found by ``make bench`` (seed 2026, E = 0.27) whose first crossing
    the engine lost before the section event got its 1e-300 offset (engine.py).
    Reference: heyoka long double, first crossing with φ̇ > 0.
    """
    from benchmarks import peers
    from benchmarks.reference import reference_orbits
    from benchmarks.workprecision import scene_ics

    ics = scene_ics(0.27, 0.0, 425, 2026)[[23, 92, 120, 333, 352, 424]]
    ref = reference_orbits(ics, section=True, t_max=5.0)
    assert (ref["outcome"] == 3).all() and (ref["t_end"] < 0.3).all()
    eng = peers.engine(ics, 1e-15, t_max=5.0, section=True)
    assert (eng.outcome == 3).all()
    assert np.abs(eng.t_end - ref["t_end"]).max() < 1e-12, (eng.t_end, ref["t_end"])


def test_statistics_small():
    """Same ICs at tol 1e-12 and 1e-15: the escape-time distributions are indistinguishable (KS p > 0.01)."""
    r = stress.case_statistics(n=600, n_diss=200)
    assert all(row["ks_p"] > 0.01 for row in r.rows)
    assert r.ok, r.finding


def test_cmeasure_distance_small():
    """Fig. 5a point sets at tol 1e-12 and 1e-15 (same ICs) closer than the sets' own split-half noise."""
    r = stress.case_cmeasure_distance(n=3000)
    row = r.rows[0]
    assert row["points_b"] >= 10
    assert row["sw_between_tols"] < row["sw_split_half_noise"], r.finding


def test_stress_tiny_end_to_end(tmp_path):
    """``python -m benchmarks.stress --scale tiny`` with a tmp root writes every case's CSV and summary.md."""
    import shutil
    from pathlib import Path

    shutil.copy(Path(__file__).resolve().parents[2] / "benchmarks" / "stress.toml", tmp_path / "stress.toml")
    rc = stress.main(["--scale", "tiny", "--root", str(tmp_path), "--only", "saddle_starts", "statistics"])
    out = tmp_path / "out" / "stress" / "tiny"
    assert rc == 0
    assert (out / "saddle_starts.csv").exists() and (out / "statistics.csv").exists()
    assert "| saddle_starts | ok |" in (out / "summary.md").read_text()
