"""Peer integrators of ``make bench`` (benchmarks/peers.py) against independent references.

References: closed-form properties of the composition (weights, symmetry),
numerical convergence order against heyoka long double, and the long-double
reference orbits (exact Taylor event location) for the event handling.
"""

import numpy as np
import pytest

numba = pytest.importorskip("numba")

from benchmarks import peers
from benchmarks.reference import reference_orbits
from hhscatter.integrate.engine import state_at
from hhscatter.scene.scene import Scene


@pytest.fixture(scope="module")
def cons_ics():
    from benchmarks.workprecision import scene_ics

    return scene_ics(0.27, 0.0, 24, 99)


@pytest.fixture(scope="module")
def cons_ref(cons_ics):
    return reference_orbits(cons_ics, t_max=5000.0)


def test_kahanli8_weights_are_the_kahan_li_s17odr8_composition():
    """Σγ = 1 (consistency) and Σγ³ = 0 (order-3 condition of a symmetric composition of 2nd-order steps)."""
    a, b = peers.kahanli8_coefficients()
    g = a[:17]
    assert len(peers.KAHANLI8_GAMMA) == 9
    assert np.allclose(g, g[::-1], rtol=0, atol=0)  # symmetric
    assert abs(g.sum() - 1) < 1e-15
    assert abs(b.sum() - 1) < 1e-15
    assert abs((g**3).sum()) < 1e-15
    # order-5 condition for symmetric compositions (Σγ⁵ = 0) holds too
    assert abs((g**5).sum()) < 1e-15


def test_kahanli8_converges_with_order_8():
    """Error at t = 2 vs heyoka long double for dt = 0.4, 0.2, 0.1 (above round-off): fitted order in [7.5, 8.6]."""
    s0 = np.array([0.1, -0.2, 0.35, 0.2])
    T = 2.0
    exact = state_at(Scene(energy=0.27, n=1), s0, T, fp_type=np.longdouble).astype(float)
    dts = np.array([0.4, 0.2, 0.1])
    errs = np.array([np.abs(peers.kahanli8_propagate(s0, dt, int(round(T / dt))) - exact).max() for dt in dts])
    order = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    assert 7.5 < order < 8.6, (errs, order)
    # a wrong weight (the 15-stage set, or a typo) would show as order ≤ 6: check that the test can fail
    g = np.array(peers.KAHANLI8_GAMMA)
    bad = g.copy()
    bad[0] *= 1.0 + 1e-3
    saved = peers.KAHANLI8_GAMMA
    try:
        peers.KAHANLI8_GAMMA = tuple(bad)
        errs_bad = np.array([np.abs(peers.kahanli8_propagate(s0, dt, int(round(T / dt))) - exact).max() for dt in dts])
    finally:
        peers.KAHANLI8_GAMMA = saved
    assert np.polyfit(np.log(dts), np.log(errs_bad), 1)[0] < 3


def test_kahanli8_escape_rules(cons_ics, cons_ref):
    """Step-end escape lags the root by < dt; the root-found escape matches the reference to ~1e-11."""
    dt = 0.05
    step = peers.kahanli8(cons_ics, dt)
    root = peers.kahanli8(cons_ics, dt, rootfind=True)
    esc = cons_ref["outcome"] == 0
    assert esc.sum() >= 20
    assert (step.outcome == cons_ref["outcome"]).all() and (root.outcome == cons_ref["outcome"]).all()
    lag = step.t_end[esc] - cons_ref["t_end"][esc]
    assert (lag > -1e-9).all() and (lag < dt + 1e-9).all()
    short = esc & (cons_ref["t_end"] < 20)
    rel = np.abs(root.t_end[short] - cons_ref["t_end"][short]) / cons_ref["t_end"][short]
    assert rel.max() < 1e-10
    # at the root the orbit is on the circle r = r_esc
    r = np.hypot(root.state_end[esc, 0], root.state_end[esc, 1])
    assert np.abs(r - 1.03).max() < 1e-13


def test_dop853_escape_times_and_energy(cons_ics, cons_ref):
    """Numba DOP853 at tol 1e-12: outcomes equal, short escape times within 1e-9, energy within 1e-11."""
    res = peers.dop853(cons_ics, 1e-12)
    assert (res.outcome == cons_ref["outcome"]).all()
    esc = cons_ref["outcome"] == 0
    short = esc & (cons_ref["t_end"] < 20)
    assert (np.abs(res.t_end[short] - cons_ref["t_end"][short]) / cons_ref["t_end"][short]).max() < 1e-9
    e0 = 0.27
    assert np.abs(res.e_end[esc] - e0).max() / e0 < 1e-11


def test_dop853_tolerance_controls_error(cons_ics, cons_ref):
    """Looser tolerance, larger error: median escape-time error at 1e-7 ≫ at 1e-13 (the control works)."""
    esc = cons_ref["outcome"] == 0
    med = []
    for tol in (1e-7, 1e-13):
        r = peers.dop853(cons_ics, tol)
        med.append(np.median(np.abs(r.t_end[esc] - cons_ref["t_end"][esc]) / cons_ref["t_end"][esc]))
    assert med[0] > 100 * med[1]
    assert med[1] < 1e-11


def test_dissipative_peers_match_reference():
    """DOP853 (numba and SciPy) with the engine's dissipative rules: outcomes and escape/settle times vs long double."""
    from benchmarks.workprecision import scene_ics

    ics = scene_ics(0.3, 0.01, 10, 5)
    ref = reference_orbits(ics, gamma=0.01)
    for res in (peers.dop853(ics, 1e-12, gamma=0.01), peers.scipy_dop853(ics[:4], 1e-10, gamma=0.01)):
        n = len(res.t_end)
        assert (res.outcome == ref["outcome"][:n]).all()
        short = ref["t_end"][:n] < 30
        rel = np.abs(res.t_end - ref["t_end"][:n])[short] / ref["t_end"][:n][short]
        assert rel.max() < 1e-7


def test_section_mode_first_crossing(cons_ics):
    """First section crossing: where KahanLi8/DOP853 find the reference's crossing, the state agrees to 1e-9.

    Their step-end sign-change detection may skip a pair of crossings inside one
    step (seen for DOP853 at tol 1e-13: crossings 0.044 apart); the engine's
    polynomial root isolation must not: it finds exactly the reference's crossing.
    """
    from benchmarks.workprecision import section_accuracy

    ref = reference_orbits(cons_ics[:12], section=True)
    assert (ref["outcome"] == 3).sum() >= 3
    for res in (peers.kahanli8(cons_ics[:12], 0.02, section=True), peers.dop853(cons_ics[:12], 1e-13, section=True)):
        acc = section_accuracy(res, ref)
        assert acc["section_mismatch"] <= 2
        assert acc["section_err_p99"] < 1e-9
        on = res.outcome == 3
        s = res.state_end[on]
        assert np.abs(s[:, 0] * s[:, 2] + s[:, 1] * s[:, 3]).max() < 1e-13
    acc = section_accuracy(peers.engine(cons_ics[:12], 1e-15, section=True), ref)
    assert acc["section_mismatch"] == 0 and acc["section_err_p99"] < 1e-12


def test_bad_input_names_parameter(cons_ics):
    with pytest.raises(ValueError, match="dt"):
        peers.kahanli8(cons_ics, 0.0)
    with pytest.raises(ValueError, match="tol"):
        peers.dop853(cons_ics, 2.0)
    with pytest.raises(ValueError, match="ics"):
        peers.dop853(np.zeros((3, 3)), 1e-9)


def test_reference_long_double_vs_real128(cons_ics):
    """The reference itself: long double vs real128 escape times agree to ~ε_ld·e^{λt} (1e-16 for t < 10, 1e-13 all)."""
    import heyoka as hy

    ld = reference_orbits(cons_ics[:3])
    q = reference_orbits(cons_ics[:3], fp_type=hy.real128)
    assert (ld["outcome"] == q["outcome"]).all()
    rel = np.abs(ld["t_end"] - q["t_end"]) / q["t_end"]
    assert rel.max() < 1e-13
    assert rel[q["t_end"] < 10].max() < 1e-16


def test_workprecision_tiny_end_to_end(tmp_path, monkeypatch):
    """``python -m benchmarks --scale tiny`` with a tmp root writes CSV, PNG and summary.md."""
    import shutil
    from pathlib import Path

    import pandas as pd

    from benchmarks import workprecision

    shutil.copy(Path(__file__).resolve().parents[2] / "benchmarks" / "bench.toml", tmp_path / "bench.toml")
    workprecision.main(["--scale", "tiny", "--root", str(tmp_path), "--no-throughput"])
    out = tmp_path / "out" / "bench" / "tiny"
    df = pd.read_csv(out / "workprecision.csv")
    assert {"conservative", "dissipative"} <= set(df.scene)
    assert (out / "workprecision.png").stat().st_size > 10_000
    assert "Speed of hhscatter" in (out / "summary.md").read_text()
    # every method at least ended every orbit like the reference at its loosest setting
    assert (df.outcome_mismatch <= 1).all()
    eng = df[df.is_engine & (df.setting == "tol=1e-15")]
    assert (eng.rel_err_median < 1e-13).all()
