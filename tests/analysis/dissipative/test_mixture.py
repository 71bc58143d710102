"""hhscatter.analysis.dissipative.mixture: the steps of the mixture model on sub-ensembles with known paths."""

from types import SimpleNamespace

import numpy as np
import pytest

from hhscatter.analysis.dissipative.mixture import (
    MixtureComponents,
    _component_fraction_errors,
    _member_decay_laws,
    _mixture_parameters,
    _MixtureProblem,
    _orbits_at,
    _quantile_bins,
    _sub_ensemble_paths,
    _total_fraction_errors,
    fit_mixture_model,
    mixture_components_arrays,
    mixture_survival_model,
)
from hhscatter.analysis.dissipative.survival_model import survival_model
from hhscatter.reproduction.fig2 import PAPER_KAPPA

E0, GAMMA, TAU0 = 0.3, 0.01, 5.0
MU = np.array([0.6, 1.3])


def components(weights=(0.5, 0.5), mu=MU, A=(E0, E0)):
    w = np.asarray(weights, dtype=float)
    return MixtureComponents(
        TAU0,
        "rate",
        np.linspace(0.0, 1.0, w.size + 1),
        w,
        np.ones(w.size, int),
        np.asarray(A, float),
        np.asarray(A, float),
        np.asarray(mu, float),
        np.zeros(w.size),
        (0.0, 1.0),
        GAMMA,
    )


@pytest.mark.parametrize("hazard", ["paper", "integrated"])
def test_one_component_and_identical_components_are_the_homogeneous_model(hazard):
    """K = 1, and K = 3 sub-ensembles on the same path with f_ne,k = w_k f_ne: both are survival_model."""
    t = np.arange(0.0, 200.0, 0.5)
    homog = survival_model(
        t,
        kappa_of_E=PAPER_KAPPA,
        E0=E0,
        mu=0.91,
        gamma=GAMMA,
        tau0=TAU0,
        f_ne=0.1,
        f_e=0.4,
        L=0.1,
        b=0.2,
        hazard=hazard,
        E_c=PAPER_KAPPA.E_c,
    )
    common = {
        "kappa_of_E": PAPER_KAPPA,
        "tau0": TAU0,
        "P_tau0": 0.5,
        "L": 0.1,
        "b": 0.2,
        "hazard": hazard,
        "E_c": PAPER_KAPPA.E_c,
    }
    one = mixture_survival_model(t, components=components((1.0,), (0.91,), (E0,)), f_ne=0.1, **common)
    np.testing.assert_array_equal(np.isnan(one), np.isnan(homog))
    np.testing.assert_allclose(one, homog, rtol=1e-14, equal_nan=True)
    w = np.array([0.2, 0.3, 0.5])
    three = mixture_survival_model(t, components=components(w, (0.91,) * 3, (E0,) * 3), f_ne=0.1 * w, **common)
    np.testing.assert_allclose(three, homog, rtol=1e-12, equal_nan=True)


SNAP_T = np.arange(0.0, 101.0, 5.0)


def snapshots(mu_i, t=SNAP_T, a_i=None):
    """Exact snapshots ln E_i(t) = a_i − μ_i γ t of orbits 10, 11, … (ids deliberately not sorted by row)."""
    a_i = np.log(E0) * np.ones(len(mu_i)) if a_i is None else np.asarray(a_i)
    ids = np.repeat(np.arange(10, 10 + len(mu_i))[::-1], t.size)
    tt = np.tile(t, len(mu_i))
    e = np.exp(np.repeat(a_i[::-1], t.size) - np.repeat(np.asarray(mu_i)[::-1], t.size) * GAMMA * tt)
    return ids, tt, e


def test_orbits_at_the_nearest_snapshot_time():
    ids, t, e = snapshots([0.5, 1.0, 2.0])
    t_used, ids_ref, e_ref = _orbits_at(ids, t, e, 7.6)
    assert t_used == 10.0
    np.testing.assert_array_equal(ids_ref, [10, 11, 12])
    np.testing.assert_allclose(e_ref, E0 * np.exp(-np.array([0.5, 1.0, 2.0]) * GAMMA * 10.0), rtol=1e-14)


def test_member_decay_laws_recover_each_orbit():
    mu_i, a_i = np.array([0.5, 1.0, 2.0]), np.log([0.2, 0.3, 0.4])
    ids, t, e = snapshots(mu_i, a_i=a_i)
    mu, a = _member_decay_laws(ids, t, e, np.array([10, 11, 12]), GAMMA, (0.0, np.inf))
    np.testing.assert_allclose(mu, mu_i, rtol=1e-10)
    np.testing.assert_allclose(a, a_i, rtol=1e-10)
    # one snapshot in the window: no decay law (NaN); an orbit without any snapshot (id 99): NaN as well
    mu1, a1 = _member_decay_laws(ids, t, e, np.array([10, 11, 99]), GAMMA, (20.0, 20.0))
    assert np.isnan(mu1).all() and np.isnan(a1).all()
    mu2, _ = _member_decay_laws(ids, t, e, np.array([10, 11, 99]), GAMMA, (0.0, np.inf))
    np.testing.assert_allclose(mu2[:2], mu_i[:2], rtol=1e-10)
    assert np.isnan(mu2[2])


def test_quantile_bins():
    key = np.array([5.0, 0.0, 7.0, 1.0, np.nan, 2.0, 3.0, 6.0, 4.0])
    edges, comp, n = _quantile_bins(key, 4, 0.0)
    np.testing.assert_allclose(edges, [0.0, 1.75, 3.5, 5.25, 7.0])
    np.testing.assert_array_equal(comp, [2, 0, 3, 0, -1, 1, 1, 3, 2])
    np.testing.assert_array_equal(n, [2, 2, 2, 2])
    edges, comp, n = _quantile_bins(np.arange(5.0), 2, 0.0)  # a key on an inner edge: the upper bin
    np.testing.assert_array_equal(edges, [0.0, 2.0, 4.0])
    np.testing.assert_array_equal(comp, [0, 0, 1, 1, 1])
    with pytest.raises(ValueError, match="usable orbits"):
        _quantile_bins(key, 9, 0.0)
    with pytest.raises(ValueError, match="ties"):
        _quantile_bins(np.array([1.0, 1.0, 1.0, 2.0]), 3, 0.0)


def test_sub_ensemble_paths():
    comp = np.array([0, 1, 0, 1, -1])
    e_ref = np.array([1.0, 2.0, 3.0, 4.0, 9.0])
    mu_i = np.array([0.5, 1.0, 0.7, np.nan, 3.0])
    a_ref = np.log([0.2, 0.3, 0.4, 0.5, 0.6])
    A, mu, mu_err, E_mean = _sub_ensemble_paths(comp, e_ref, mu_i, a_ref, 2)
    np.testing.assert_allclose(E_mean, [2.0, 3.0])  # every member counts for the energy
    np.testing.assert_allclose(mu, [0.6, 1.0])  # members with a defined μ_i only
    np.testing.assert_allclose(A, [np.sqrt(0.2 * 0.4), 0.3])  # exp of the mean a_i: geometric mean
    assert mu_err[0] == pytest.approx(np.std([0.5, 0.7], ddof=1) / np.sqrt(2)) and np.isnan(mu_err[1])
    with pytest.raises(ValueError, match="sub-ensemble 1"):
        _sub_ensemble_paths(comp, e_ref, np.array([0.5, np.nan, 0.7, np.nan, 3.0]), a_ref, 2)


def test_components_recover_two_exact_populations():
    mu_i = np.repeat(MU, 50)
    ids, t, e = snapshots(mu_i)
    c = mixture_components_arrays(ids, t, e, gamma=GAMMA, t_ref=TAU0, n_components=2, by="rate")
    np.testing.assert_allclose(c.mu, MU, rtol=1e-10)
    np.testing.assert_allclose(c.A, E0, rtol=1e-10)
    np.testing.assert_array_equal(c.weights, [0.5, 0.5])


def test_parameters_and_problem():
    assert _mixture_parameters(3, "free", {"L": 0.1}) == (
        ["f_ne_0", "f_ne_1", "f_ne_2", "L", "b"],
        ["f_ne_0", "f_ne_1", "f_ne_2", "b"],
    )
    assert _mixture_parameters(3, "shared", {}) == (["phi", "L", "b"], ["phi", "L", "b"])
    with pytest.raises(ValueError, match="unknown parameters"):
        _mixture_parameters(2, "shared", {"f_ne_0": 0.1})
    c = components((0.25, 0.75))
    t = np.arange(5.0, 50.0)
    prob = _MixtureProblem(
        t,
        np.ones(t.size),
        np.ones(t.size),
        PAPER_KAPPA,
        c,
        TAU0,
        1 / 6,
        "paper",
        "log",
        "shared",
        ["phi", "b"],
        {"L": 0.1},
        {"phi": 0.3, "L": 0.05},
        [0.02, 0.1],
    )
    lo, hi = prob.bounds(0.5)
    np.testing.assert_array_equal(lo, [0.0, 1e-6])
    np.testing.assert_array_equal(hi, [1.0, 1e3])
    v, fk = prob.unpack([0.4, 0.3], 0.5)
    assert (v["phi"], v["L"], v["b"]) == (0.4, 0.1, 0.3)  # θ over fixed over guesses
    np.testing.assert_allclose(fk, [0.4 * 0.25 * 0.5, 0.4 * 0.75 * 0.5])
    assert prob.starts() == [[0.3, 0.02], [0.3, 0.1]]
    free = _MixtureProblem(
        *[getattr(prob, f) for f in ("tf", "Pf", "sf", "kappa_of_E", "components", "tau0", "E_c", "hazard", "space")],
        "free",
        ["f_ne_0", "f_ne_1"],
        {},
        {"f_ne_0": 0.1, "f_ne_1": 0.2, "L": 0.1},
        [0.2],
    )
    np.testing.assert_array_equal(free.bounds(0.5)[1], [0.125, 0.375])  # f_ne,k ≤ w_k P(τ0)


@pytest.mark.parametrize(
    "hazard, p0", [("integrated", None), ("paper", {"f_ne_0": 0.036, "f_ne_1": 0.144, "L": 0.12, "b": 0.25})]
)
def test_fit_recovers_the_generating_mixture(hazard, p0):
    """Noiseless P(t) of a two-path mixture (σ = 10⁻³ P): the fit returns its f_ne,k, L and b.

    With the literal ("paper") hazard the default start (φ from P at the first τ2,k, where that model has risen
    back to w_k P(τ0)) ends in a local minimum (χ² ≈ 3·10⁵ here): that case starts within 20 % of the truth.
    """
    c = components()
    t = np.arange(0.0, 301.0)
    f_ne = np.array([0.03, 0.12])
    P = mixture_survival_model(
        t,
        kappa_of_E=PAPER_KAPPA,
        components=c,
        tau0=TAU0,
        f_ne=f_ne,
        P_tau0=0.5,
        L=0.1,
        b=0.2,
        hazard=hazard,
        E_c=PAPER_KAPPA.E_c,
    )
    ok = np.isfinite(P) & (P > 1e-5)
    fit = fit_mixture_model(
        t[ok],
        P[ok],
        1e-3 * P[ok],
        c,
        kappa_of_E=PAPER_KAPPA,
        tau0=TAU0,
        P_tau0=0.5,
        hazard=hazard,
        p0=p0,
        E_c=PAPER_KAPPA.E_c,
    )
    np.testing.assert_allclose(fit.values["f_ne_k"], f_ne, rtol=1e-4)
    assert (fit.values["L"], fit.values["b"]) == pytest.approx((0.1, 0.2), rel=1e-4)
    assert fit.values["f_ne"] == pytest.approx(0.15, rel=1e-4) and fit.chi2 < 1e-6
    assert fit.free == ("f_ne_0", "f_ne_1", "L", "b")


def test_fraction_errors_from_a_known_covariance():
    """Free mode: σ²(f_ne) = 1ᵀ C 1 over the f_ne,k block; shared: σ(f_ne,k) = w_k P(τ0) σ(φ); with P(τ0)'s error
    the sensitivity enters as d f_ne/d P(τ0)."""
    C = np.array([[4.0, 1.0, 0.5], [1.0, 9.0, 0.0], [0.5, 0.0, 1.0]]) * 1e-4
    st = SimpleNamespace(cov_fit=C, sens=np.zeros(3), cov=C)
    fne, fe = _total_fraction_errors(["f_ne_0", "f_ne_1", "L"], "free", {}, st, 0.5, 0.0)
    assert fne == pytest.approx(np.sqrt(1e-4 * (4 + 9 + 2)), rel=1e-12) and fe == fne
    errs = {"f_ne_0": 0.02, "f_ne_1": 0.03}
    np.testing.assert_array_equal(
        _component_fraction_errors(["f_ne_0", "f_ne_1", "L"], "free", {}, errs, np.array([0.5, 0.5]), st, 0.5, 0.0),
        [0.02, 0.03],
    )
    w = np.array([0.25, 0.75])
    st1 = SimpleNamespace(cov_fit=np.array([[0.01]]), sens=np.array([0.2]), cov=None)
    v = {"phi": 0.4}
    fk = _component_fraction_errors(["phi"], "shared", v, {}, w, st1, 0.5, 0.1)
    # f_ne,k = φ w_k P: ∂/∂φ = w_k P, d/dP = w_k P ∂φ/∂P + w_k φ
    expected = np.sqrt((w * 0.5) ** 2 * 0.01 + ((w * 0.5 * 0.2 + w * 0.4) * 0.1) ** 2)
    np.testing.assert_allclose(fk, expected, rtol=1e-12)
    fne, fe = _total_fraction_errors(["phi"], "shared", v, st1, 0.5, 0.1)
    d = 0.5 * 0.2 + 0.4
    assert fne == pytest.approx(np.sqrt(0.25 * 0.01 + (d * 0.1) ** 2), rel=1e-12)
    assert fe == pytest.approx(np.sqrt(0.25 * 0.01 + ((1 - d) * 0.1) ** 2), rel=1e-12)
