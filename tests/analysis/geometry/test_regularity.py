"""The shadow-orbit indicator against orbits whose type an independent integration fixes.

Reference: scipy's DOP853 on Hénon–Heiles' equations and their variational equations written out here (not the
package's system code), the tangent vector renormalised every 50 time units; its finite-time Lyapunov exponent
over [0, T] is ~1e-4 on a torus and 0.04–0.07 in the chaotic sea at E = 1/8 (bounded: nothing escapes).
"""

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

from hhscatter.analysis.geometry.regularity import (
    G_MAX,
    indicator_systematic,
    regular_fraction,
    shadow_ics,
    shadow_indicator,
    variational_indicator,
)
from hhscatter.integrate.engine import run_chunk
from hhscatter.outcomes import OUTCOMES
from hhscatter.scene.scene import Scene, SectionWindow

E = 0.125


def _V(x, y):
    return 0.5 * (x**2 + y**2) + x**2 * y - y**3 / 3


def _rhs(t, z):
    x, y, px, py, dx, dy, dpx, dpy = z
    vxx, vyy, vxy = 1 + 2 * y, 1 - 2 * y, 2 * x
    return [px, py, -x - 2 * x * y, -y - x * x + y * y, dpx, dpy, -vxx * dx - vxy * dy, -vxy * dx - vyy * dy]


def _ftle_reference(z0, T, every=50.0):
    z, s = np.concatenate([z0, [1.0, 0.0, 0.0, 0.0]]), 0.0
    for _ in range(int(T / every)):
        z = solve_ivp(_rhs, (0, every), z, method="DOP853", rtol=1e-10, atol=1e-12).y[:, -1]
        n = np.linalg.norm(z[4:])
        s, z[4:] = s + np.log(n), z[4:] / n
    return s / T


def _section_ics(ys):
    # on x = 0 with p_y = 0 and p_x > 0: φ̇ = −y p_x > 0 for y < 0 (these cross the recorded section ṙ = 0, φ̇ > 0)
    return np.column_stack([np.zeros_like(ys), ys, np.sqrt(2 * (E - _V(0.0, ys))), np.zeros_like(ys)])


def test_shadow_indicator_calls_tori_regular_and_the_sea_chaotic():
    T = 600.0
    ics = _section_ics(np.array([-0.35, -0.30, -0.20, -0.10]))
    ref = np.array([_ftle_reference(z, T) for z in ics])
    assert (ref[:2] < 1e-3).all() and (ref[2:] > 0.02).all()  # two tori, two chaotic orbits (the reference says)
    sc = Scene(energy=0.2, n=len(ics), t_max=T, sections=SectionWindow(t_from=T - 100, t_to=T))
    sh, d0 = shadow_ics(ics, _V)
    base = pd.DataFrame(run_chunk(sc, ics, np.arange(len(ics))).sections)
    shadow = pd.DataFrame(run_chunk(sc, sh, np.arange(len(ics))).sections)
    ind = shadow_indicator(base, shadow, np.arange(len(ics)), d0, T - 100)
    assert ind["regular"].tolist() == list(ref < 1e-3)
    # the chaotic orbits' separation saturates far above the threshold, the tori's stays far below it
    assert (ind["growth"][2:] > 10 * G_MAX).all() and (ind["growth"][:2] < G_MAX / 1e2).all()


def test_shadow_ics_keep_the_energy_and_the_distance():
    rng = np.random.default_rng(3)
    s = _section_ics(rng.uniform(-0.3, 0.3, 50))
    sh, d0 = shadow_ics(s, _V)
    H = lambda a: 0.5 * (a[:, 2] ** 2 + a[:, 3] ** 2) + _V(a[:, 0], a[:, 1])  # noqa: E731
    np.testing.assert_allclose(H(sh), H(s), rtol=0, atol=1e-15)
    assert ((d0 >= 1e-9) & (d0 < 2e-9)).all()


def test_shadow_ics_refuse_a_state_without_kinetic_energy():
    with pytest.raises(ValueError, match="no shadow"):
        shadow_ics(np.array([[0.0, 0.0, 0.0, 0.0]]), _V)


def test_one_orbit_leaving_makes_the_pair_chaotic_and_none_crossing_is_said():
    base = pd.DataFrame({"traj_id": [0, 1], "t": [95.0, 96.0], "x": 0.1, "y": 0.0, "px": 0.3, "py": 0.1})
    shadow = base.iloc[:1]
    ind = shadow_indicator(base, shadow, [0, 1, 2], 1e-9, 90.0)
    assert ind["kind"].tolist() == ["regular", "chaotic", "none"]


def test_regular_fraction_error_is_binomial_and_never_zero():
    f, e = regular_fraction(10000, 2500)
    assert f == 0.25 and abs(e - np.sqrt(0.25 * 0.75 / 1e4)) < 1e-6
    assert regular_fraction(10000, 0)[1] > 1e-5


def test_threshold_systematic_is_the_largest_shift_over_the_thresholds():
    from hhscatter.analysis.geometry.regularity import threshold_systematic

    growth = np.array([5.0, 2e3, 2e3, 3e4, 3e4, 3e4, 1e9, np.inf, np.nan])
    r = threshold_systematic(100, growth)
    # below 1e3: 1, below 1e4: 3, below 1e5: 6 of 100
    assert r["by_threshold"] == {1e3: 0.01, 1e4: 0.03, 1e5: 0.06}
    assert (
        r["value"] == 0.03
        and r["syst"] == pytest.approx(0.03)
        and r["stat"] == pytest.approx((0.03 * 0.97 / 100 + 1 / 4e4) ** 0.5 / 1.01)  # Wilson 1σ half-width
    )
    with pytest.raises(ValueError, match="n_orbits"):
        threshold_systematic(3, growth)


#: section ICs (x = 0, p_y = 0, y below) at E = 1/8 at the edges of three islands: the band where the indicator's
#: growth lies between a torus' (~1) and the saturated chaotic sea's (~1e8), sticky orbits among them
BAND_YS = (-0.4155, -0.4145, -0.2745, -0.2735, -0.1265, -0.1255, -0.1155, -0.1145, -0.1135)


@pytest.mark.slow
def test_threshold_agrees_with_a_long_reference_on_orbits_spanning_the_ambiguous_band():
    """Labels from an independent integration 1.5 times longer than the indicator's (scipy, variational equations,
    T = 3000): regular where λ_T < 0.003 (a growth below ~10⁴ over T: shear), chaotic where λ_T > 0.005 (above
    ~3·10⁶), undecided between. The indicator at t ≥ 1900 (as the generality study runs it) agrees with every
    decided label at its threshold and at a decade either side (the thresholds of the systematic)."""
    T, t_from, T_ref = 2000.0, 1900.0, 3000.0
    ics = _section_ics(np.array(BAND_YS))
    ref = np.array([_ftle_reference(z, T_ref) for z in ics])
    label = np.where(ref < 0.003, "regular", np.where(ref > 0.005, "chaotic", "undecided"))
    decided = label != "undecided"
    assert decided.sum() >= 8 and (label == "regular").sum() >= 3 and (label == "chaotic").sum() >= 3
    sc = Scene(energy=0.2, n=len(ics), t_max=T, sections=SectionWindow(t_from=t_from, t_to=T))
    sh, d0 = shadow_ics(ics, _V)
    base = pd.DataFrame(run_chunk(sc, ics, np.arange(len(ics))).sections)
    shadow = pd.DataFrame(run_chunk(sc, sh, np.arange(len(ics))).sections)
    ind = shadow_indicator(base, shadow, np.arange(len(ics)), d0, t_from)
    g = ind["growth"].to_numpy()
    assert ((g > 10) & (g < 1e7)).sum() >= 3  # the set spans the band between tori and the saturated sea
    for g_max in (G_MAX / 10, G_MAX, G_MAX * 10):
        called = np.where(g < g_max, "regular", "chaotic")
        assert (called[decided] == label[decided]).all(), (g_max, list(zip(BAND_YS, ref, g)))


def _tangent_lifetimes(ics, T):
    """The engine's tangent run of ``ics`` to T (Hénon–Heiles, bounded at E = 1/8: every orbit censored at T)."""
    lt = run_chunk(Scene(energy=0.2, n=len(ics), t_max=T, tangent=True), ics, np.arange(len(ics))).lifetimes
    out = pd.DataFrame({k: lt[k] for k in ("traj_id", "t_end", "log_stretch")})
    return out.assign(outcome=np.asarray(OUTCOMES)[np.asarray(lt["outcome"])])


def test_variational_indicator_labels_tori_and_the_sea_as_an_independent_integration_does():
    T = 600.0
    ics = _section_ics(np.array([-0.35, -0.30, -0.20, -0.10]))
    ref = np.array([_ftle_reference(z, T) for z in ics])
    assert (ref[:2] < 1e-3).all() and (ref[2:] > 0.02).all()  # two tori, two chaotic orbits (the reference says)
    lab = variational_indicator(_tangent_lifetimes(ics, T), T)
    assert lab["label"].tolist() == ["regular", "regular", "chaotic", "chaotic"]
    # the chaotic sea: the engine's exponent is the reference's λ_T (the same orbit, independent integrators;
    # after e^{λT} ≈ e^{30} the two trajectories differ, their exponents over the sea do not by much)
    np.testing.assert_allclose(lab["ftle"][2:], ref[2:], rtol=0.35)
    # the tori: both exponents are those of a linear shear, Λ = λ_T·T of order ln(shear·T), far below the sea's
    assert (np.abs(lab["ftle"][:2] * T - ref[:2] * T) < 3.0).all()


def test_variational_ftle_of_a_torus_falls_like_ln_t_over_t_and_the_sea_keeps_its_lambda():
    ics = _section_ics(np.array([-0.35, -0.10]))
    ftle = {T: variational_indicator(_tangent_lifetimes(ics, T), T)["ftle"].to_numpy() for T in (300.0, 2400.0)}
    # the torus: its stretch stays within ln(1 + t) + O(1) (a shear at most: u(0) need not lie across the tori), so
    # λ_T falls at least like ln(t)/t and is far below the labels' threshold
    for T in (300.0, 2400.0):
        assert abs(ftle[T][0] * T) < np.log1p(T) + 1.0, (T, ftle[T][0] * T)
    assert abs(ftle[2400.0][0]) < (np.log1p(2400.0) + 1.0) / 2400.0 < 0.005
    # the sea: over the long time λ_T is the independent integration's λ (within the finite-time spread), far
    # above the torus' λ_T
    assert ftle[2400.0][1] == pytest.approx(_ftle_reference(ics[1], 2400.0), rel=0.35)
    assert ftle[2400.0][1] > 20 * ftle[2400.0][0]


def test_variational_indicator_calls_an_escaped_orbit_chaotic_and_refuses_bad_tables():
    lt = pd.DataFrame(
        {"traj_id": [0, 1], "outcome": ["censored", "escaped"], "t_end": [3000.0, 50.0], "log_stretch": [3.0, 0.1]}
    )
    assert variational_indicator(lt, 3000.0)["label"].tolist() == ["regular", "chaotic"]
    with pytest.raises(ValueError, match="t_min"):
        variational_indicator(lt.assign(t_end=[1000.0, 50.0]), 3000.0)
    with pytest.raises(ValueError, match="log_stretch"):
        variational_indicator(lt.drop(columns="log_stretch"), 3000.0)
    with pytest.raises(ValueError, match="ftle_chaotic"):
        variational_indicator(lt, 3000.0, ftle_regular=0.01, ftle_chaotic=0.005)


def test_indicator_systematic_scales_the_bands_disagreements_to_the_whole_band():
    # 500 orbits, 60 in the band, 6 of them labelled: ×10. In the band: two called chaotic by the shadow are
    # regular by the label, one called regular is chaotic, one undecided, two agree; outside: one disagreement.
    shadow = [False, False, True, True, True, False, True, False]
    label = ["regular", "regular", "chaotic", "undecided", "regular", "chaotic", "chaotic", "chaotic"]
    band = [True, True, True, True, True, True, False, False]
    r = indicator_systematic(500, 60, shadow, label, band)
    assert r["scale"] == 10.0
    assert (r["disagree_to_regular"], r["disagree_to_chaotic"], r["disagree_outside"]) == (2, 1, 1)
    assert r["n_labelled"] == 8 and r["n_band_labelled"] == 6 and r["n_undecided"] == 1
    assert r["syst"] == pytest.approx(30 / 500) and r["shift"] == pytest.approx(10 / 500)
    with pytest.raises(ValueError, match="n_band"):
        indicator_systematic(500, 5, shadow, label, band)
    with pytest.raises(ValueError, match="label"):
        indicator_systematic(500, 60, shadow, ["maybe"] * 8, band)
    with pytest.raises(ValueError, match="one entry per labelled orbit"):
        indicator_systematic(500, 60, shadow[:-1], label, band)
