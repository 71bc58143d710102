"""Tests of the dissipative-scattering analysis: decay, transitions, model, distance.

All inputs are synthetic with known answers (closed forms or generating
parameters); every random input is seeded.
"""

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from hhscatter.analysis.dissipative import decay, transitions
from hhscatter.analysis.dissipative import models as model
from hhscatter.analysis.geometry import distance
from hhscatter.reproduction.fig2 import PAPER_KAPPA

E0, GAMMA, MU, TAU0, EC = 0.3, 0.01, 0.91, 5.0, 1.0 / 6.0
N_ORBITS = 100_000


def binomial_sample(P, N, rng):
    """Independent binomial estimate of each P(t) with N orbits, and its standard error."""
    P = np.where(np.isnan(P), 1.0, P)
    Ph = rng.binomial(N, np.clip(P, 0, 1)) / N
    return Ph, np.sqrt(Ph * (1 - Ph) / N)


# ---------------------------------------------------------------------------
# decay
# ---------------------------------------------------------------------------
def test_mean_energy_groups_by_grid_time():
    snaps = pd.DataFrame(
        {
            "traj_id": [0, 1, 2, 0, 1, 0],
            "t": [0.0, 0.0, 0.0, 1.0, 1.0, 2.0],
            "energy": [0.3, 0.3, 0.3, 0.2, 0.4, 0.25],
        }
    )
    m = decay.mean_energy(snaps)
    assert m["t"].tolist() == [0.0, 1.0, 2.0]
    assert m["n"].tolist() == [3, 2, 1]
    np.testing.assert_allclose(m["mean_E"], [0.3, 0.3, 0.25])
    np.testing.assert_allclose(m["std_E"][:2], [0.0, np.sqrt(0.02)])
    np.testing.assert_allclose(m["sem_E"][1], np.sqrt(0.02) / np.sqrt(2))
    assert np.isnan(m["std_E"][2])
    np.testing.assert_allclose(m["hi_3sigma"][1] - m["lo_3sigma"][1], 6 * np.sqrt(0.02))


def test_mu_recovered_from_exact_exponential():
    t = np.arange(0.0, 301.0)
    E = E0 * np.exp(-MU * GAMMA * t)
    f = decay.fit_energy_decay(t, E, E0, GAMMA, window=(0, 200))
    assert f.mu == pytest.approx(MU, rel=1e-12)
    assert f.mu_free == pytest.approx(MU, rel=1e-10)
    assert f.E0_free == pytest.approx(E0, rel=1e-10)
    assert f.mu_err < 1e-10 and f.n_points == 201
    assert f.window == (0.0, 200.0)


def test_mu_noisy_decay_within_errors_and_errors_calibrated():
    """Pulls (μ̂ − μ)/σ_μ over many noisy realisations are standard normal."""
    t = np.arange(0.0, 201.0, 2.0)
    sig = 0.02
    rng = np.random.default_rng(11)
    pulls_fixed, pulls_free = [], []
    for _ in range(300):
        logE = np.log(E0) - MU * GAMMA * t + sig * rng.standard_normal(t.size)
        w = np.full(t.size, sig**-2)
        f = decay.fit_energy_decay(t, np.exp(logE), E0, GAMMA, (0, 200), w, absolute_sigma=True)
        pulls_fixed.append((f.mu - MU) / f.mu_err)
        pulls_free.append((f.mu_free - MU) / f.mu_free_err)
    # the analytic error of the fixed-intercept slope
    assert f.mu_err == pytest.approx(sig / np.sqrt(np.sum(t * t)) / GAMMA, rel=1e-12)
    for p in (np.array(pulls_fixed), np.array(pulls_free)):
        assert abs(p.mean()) < 0.2
        assert 0.85 < p.std() < 1.15
    # a single realisation: within 3 sigma, also with errors from the residuals
    logE = np.log(E0) - MU * GAMMA * t + sig * rng.standard_normal(t.size)
    f = decay.fit_energy_decay(t, np.exp(logE), E0, GAMMA, (0, 200))
    assert abs(f.mu - MU) < 3 * f.mu_err and abs(f.mu_free - MU) < 3 * f.mu_free_err
    assert f.mu_err == pytest.approx(sig / np.sqrt(np.sum(t * t)) / GAMMA, rel=0.25)


def test_mu_by_window_sees_late_time_exponent():
    """Piecewise exponent: 0.9 up to t = 200, then 1.0 (the paper's μ → 1 claim)."""
    t = np.arange(0.0, 501.0)
    logE = np.log(E0) - GAMMA * np.where(t < 200, 0.9 * t, 0.9 * 200 + 1.0 * (t - 200))
    tab = decay.mu_by_window(t, np.exp(logE), E0, GAMMA, [(0, 200), (250, 350), (350, 500)])
    np.testing.assert_allclose(tab["mu_free"], [0.9, 1.0, 1.0], rtol=1e-10)
    np.testing.assert_allclose(tab["mu"].iloc[0], 0.9, rtol=1e-10)
    # the E0-anchored exponent is a cumulative average: between 0.9 and 1, increasing
    assert 0.9 < tab["mu"].iloc[1] < tab["mu"].iloc[2] < 1.0
    assert list(tab.columns) == ["t_lo", "t_hi", "n_points", "mu", "mu_err", "mu_free", "mu_free_err"]


def test_fit_from_snapshot_table_and_histograms():
    rng = np.random.default_rng(2)
    n, tg = 500, np.arange(0.0, 101.0, 5.0)
    mu_i = rng.normal(MU, 0.05, n)
    E = E0 * np.exp(-mu_i[:, None] * GAMMA * tg[None, :])
    ii, jj = np.nonzero(np.ones_like(E, dtype=bool))
    snaps = pd.DataFrame({"traj_id": ii, "t": tg[jj], "energy": E[ii, jj]})
    m = decay.mean_energy(snaps)
    f = decay.fit_energy_decay_table(m, E0, GAMMA, (0, 100), weighted=True)
    # ⟨E⟩ of a Gaussian spread of exponents: ln⟨E⟩ = ln E0 − μγt + (σγt)²/2
    assert f.mu == pytest.approx(MU, abs=0.02)
    h = decay.energy_histograms(snaps, [0.0, 51.0, 99.0], bins=20)
    np.testing.assert_array_equal(h.t, [0.0, 50.0, 100.0])  # nearest grid times
    assert h.counts.shape == (3, 20) and (h.counts.sum(axis=1) == n).all()
    np.testing.assert_allclose((h.density[1:] * np.diff(h.edges)).sum(axis=1), 1.0)
    np.testing.assert_allclose(h.mean_E[1], E[:, 10].mean())


# ---------------------------------------------------------------------------
# transitions
# ---------------------------------------------------------------------------
def test_tau1_constructed_crossing():
    t = np.arange(0.0, 100.0)
    P0, Pg = np.exp(-0.1 * t), np.exp(-0.05 * t)
    # P_γ/P_0 = e^{0.05 t} = 2 at t = 20 ln 2, log-linear between grid points: exact
    assert transitions.tau1(t, Pg, P0, tau0=5.0) == pytest.approx(20 * math.log(2), rel=1e-12)
    assert transitions.tau1(t, Pg, P0, tau0=5.0, alpha=3.0) == pytest.approx(20 * math.log(3), rel=1e-12)
    assert transitions.tau1(t, Pg, lambda s: np.exp(-0.1 * s), tau0=5.0) == pytest.approx(20 * math.log(2))
    assert transitions.tau1(t, 1.5 * P0, P0, tau0=5.0) is None  # never
    assert transitions.tau1(t, 3.0 * P0, P0, tau0=5.5) == 5.5  # already at τ0


def test_tau1_ignores_crossings_before_tau0():
    t = np.linspace(0.0, 40.0, 4001)
    P0 = np.exp(-0.2 * t)
    # ln(P_γ/P_0) = ln 2 + 0.02 (t − 2)(t − 15): ≥ ln 2 for t ≤ 2 and t ≥ 15
    Pg = 2 * P0 * np.exp(0.02 * (t - 2) * (t - 15))
    assert transitions.tau1(t, Pg, P0, tau0=0.0) == 0.0
    assert transitions.tau1(t, Pg, P0, tau0=5.0) == pytest.approx(15.0, abs=1e-4)


def test_tau2_predicted_closed_form():
    assert transitions.tau2_predicted(E0, EC, MU, GAMMA) == pytest.approx(math.log(1.8) / (MU * GAMMA), rel=1e-14)
    assert transitions.tau2_predicted(0.3, 1 / 6, 0.91, 0.01) == pytest.approx(64.5919411980, rel=1e-10)
    gammas = np.array([0.001, 0.01, 0.1])
    tau2 = transitions.tau2_predicted(E0, EC, MU, gammas)
    np.testing.assert_allclose(tau2 * gammas, math.log(E0 / EC) / MU)  # τ2 ∝ 1/γ
    assert transitions.tau2_predicted(0.1, EC, MU, GAMMA) == 0.0
    assert transitions.tau2_predicted(E0, EC, MU, 0.0) == math.inf


def test_tau2_observed():
    lt = pd.DataFrame(
        {
            "traj_id": np.arange(6),
            "outcome": ["escaped", "settled", "escaped", "settled", "censored", "escaped"],
            "t_end": [3.0, 70.0, 10.0, 65.5, 100.0, 1.0],
        }
    )
    assert transitions.tau2_observed(lt) == 65.5
    assert transitions.tau2_observed(lt[lt.outcome != "settled"]) is None


def test_tau1_from_lifetime_tables():
    """Deterministic 'lifetimes' with exact quantiles: P_0 = e^{−0.1t}, P_γ = e^{−0.05t}."""
    n = 200_000
    u = (np.arange(n) + 0.5) / n
    lt0 = pd.DataFrame({"t_end": -np.log(u) / 0.1, "outcome": "escaped"})
    ltg = pd.DataFrame({"t_end": -np.log(u) / 0.05, "outcome": np.where(u < 0.3, "settled", "escaped")})
    tg = np.arange(0.0, 40.0, 0.5)
    assert transitions.tau1_from_lifetimes(ltg, lt0, tg, tau0=5.0) == pytest.approx(20 * math.log(2), abs=0.01)


# ---------------------------------------------------------------------------
# homogeneous survival model
# ---------------------------------------------------------------------------
KW = dict(kappa_of_E=PAPER_KAPPA, E0=E0, mu=MU, gamma=GAMMA, tau0=TAU0, E_c=PAPER_KAPPA.E_c)
TRUE = dict(f_ne=0.1, f_e=0.4, L=0.1, b=0.2)


def test_paper_kappa_fit():
    k = PAPER_KAPPA
    np.testing.assert_allclose(k([0.1, EC, 0.2, 0.3]), [0, 0, 13.63 / 900 + 0.001, 1.41 * (0.3 - EC)])


def test_survival_model_branches():
    t = np.array([0.0, 4.9, 5.0, 30.0, 64.0, 70.0, 150.0])
    P = model.survival_model(t, **KW, **TRUE)
    tau2 = math.log(E0 / EC) / (MU * GAMMA)
    assert np.isnan(P[:2]).all()
    assert P[2] == pytest.approx(0.5)
    E30 = E0 * math.exp(-MU * GAMMA * 30)
    assert P[3] == pytest.approx(0.1 + 0.4 * math.exp(-PAPER_KAPPA(E30) * 25))
    for i in (5, 6):
        g = 0.1 / (1 + math.exp(-0.2 * (t[i] - tau2))) ** 2
        assert P[i] == pytest.approx(0.1 * math.exp(-g * (t[i] - tau2)))
    # literal escape factor is not monotone (κ0(E(t)) → 0 as t → τ2); the integrated one is
    Pi = model.survival_model(np.arange(5.0, 64.0), **KW, **TRUE, hazard="integrated")
    Pp = model.survival_model(np.arange(5.0, 64.0), **KW, **TRUE)
    assert np.all(np.diff(Pi) <= 0) and np.any(np.diff(Pp) > 0)


def test_integrated_hazard_closed_forms():
    t = np.linspace(TAU0, 60.0, 12)
    const = dict(KW, kappa_of_E=lambda E: np.full(np.shape(E), 0.07))
    for hz in ("paper", "integrated"):
        P = model.survival_model(t, **const, **TRUE, tau2=100.0, hazard=hz)
        np.testing.assert_allclose(P, 0.1 + 0.4 * np.exp(-0.07 * (t - TAU0)), rtol=1e-9)
    lin = model.PiecewiseKappa(a2=0.0, a1=1.41, slope=1.41, E_switch=0.27, E_c=PAPER_KAPPA.E_c)  # κ = 1.41 (E − E_c)
    beta = MU * GAMMA
    K = 1.41 * (E0 * (np.exp(-beta * TAU0) - np.exp(-beta * t)) / beta - EC * (t - TAU0))
    P = model.survival_model(t, **dict(KW, kappa_of_E=lin), **TRUE, hazard="integrated")
    np.testing.assert_allclose(P, 0.1 + 0.4 * np.exp(-K), rtol=1e-6)


@pytest.mark.parametrize("hazard", ["paper", "integrated"])
def test_survival_fit_recovers_parameters(hazard):
    t = np.arange(0.0, 301.0)
    rng = np.random.default_rng(7 if hazard == "paper" else 8)
    P, P_err = binomial_sample(model.survival_model(t, **KW, **TRUE, hazard=hazard), N_ORBITS, rng)
    f = model.fit_survival_model(t, P, P_err, **KW, P_min=20 / N_ORBITS, hazard=hazard)
    assert f.success and f.free == ("f_ne", "L", "b")
    for name, val in TRUE.items():
        assert abs(f.values[name] - val) < 3 * f.errors[name], (name, f.values[name], f.errors[name])
        assert f.errors[name] < 0.05 * val
    assert 0.7 < f.chi2_red < 1.4
    assert f.rms_log_residual < 0.2 and f.dof == f.n_points - 3
    np.testing.assert_allclose(f.predict(t[10:]), f.params(t[10:]))


def test_survival_fit_errors_are_calibrated():
    """Pulls (fit − true)/σ over independent noisy curves have mean ≈ 0 and spread ≈ 1."""
    t = np.arange(0.0, 301.0)
    P_true = model.survival_model(t, **KW, **TRUE)
    pulls = {name: [] for name in TRUE}
    for seed in range(40):
        P, P_err = binomial_sample(P_true, N_ORBITS, np.random.default_rng(500 + seed))
        f = model.fit_survival_model(t, P, P_err, **KW, P_min=20 / N_ORBITS)
        for name, val in TRUE.items():
            pulls[name].append((f.values[name] - val) / f.errors[name])
    for name, p in pulls.items():
        p = np.asarray(p)
        assert abs(p.mean()) < 0.6, (name, p.mean())
        assert 0.6 < p.std() < 1.4, (name, p.std())


def test_survival_fit_with_free_tau2():
    t = np.arange(0.0, 301.0)
    rng = np.random.default_rng(9)
    tau2 = 58.3  # not the Eq. (eq:tau2) value 64.59
    P, P_err = binomial_sample(model.survival_model(t, **KW, **TRUE, tau2=tau2), N_ORBITS, rng)
    fixed = model.fit_survival_model(t, P, P_err, **KW, P_min=20 / N_ORBITS)
    free = model.fit_survival_model(t, P, P_err, **KW, P_min=20 / N_ORBITS, fit_tau2=True)
    assert "tau2" in free.free
    assert abs(free.values["tau2"] - tau2) < max(3 * free.errors["tau2"], 1.0)  # data grid step 1
    assert free.chi2_red < 1.5 < fixed.chi2_red


@pytest.mark.parametrize("hazard", ["paper", "integrated"])
def test_better_fit_names_the_constants_that_made_the_data(hazard):
    """Data made with one (κ0, μ); the same model fitted with those and with other constants (our quick-scale
    fig2/fig3 values): the generating constants have the smaller RMS log residual, whatever the dict order."""
    t = np.arange(0.0, 301.0)
    P, P_err = binomial_sample(
        model.survival_model(t, **KW, **TRUE, hazard=hazard), N_ORBITS, np.random.default_rng(21)
    )
    other = model.PiecewiseKappa(a2=10.69, a1=0.282, slope=1.396, E_switch=0.2709, E_c=PAPER_KAPPA.E_c)
    common = {"P_min": 20 / N_ORBITS, "hazard": hazard}
    right = model.fit_survival_model(t, P, P_err, **KW, **common)
    wrong = model.fit_survival_model(t, P, P_err, **dict(KW, kappa_of_E=other, mu=0.939), **common)
    assert right.rms_log_residual < wrong.rms_log_residual  # the premise, computed here independently
    assert model.better_fit({"generating": right, "other": wrong}) == "generating"
    assert model.better_fit({"other": wrong, "generating": right}) == "generating"
    assert model.better_fit({"a": right, "b": right}) is None  # a tie names neither
    shorter = model.fit_survival_model(t, P, P_err, **KW, **common, t_max=100.0)
    assert shorter.n_points < right.n_points
    with pytest.raises(ValueError, match="other points"):
        model.better_fit({"generating": right, "shorter": shorter})
    with pytest.raises(ValueError, match="at least two"):
        model.better_fit({"generating": right})


def test_predict_tau1_solves_eq_tau1():
    params = model.SurvivalModelParams(PAPER_KAPPA, E0, MU, GAMMA, TAU0, 64.59, 0.1, 0.4, 0.1, 0.2, PAPER_KAPPA.E_c)
    k0 = float(PAPER_KAPPA(E0))

    def P0(t):  # conservative curve at E0: P(τ0) e^{−κ0(E0)(t − τ0)}
        return 0.5 * np.exp(-k0 * (np.asarray(t) - TAU0))

    tau1 = model.predict_tau1(params, P0, alpha=2.0, t_max=200.0)
    assert TAU0 < tau1 < 64.59
    assert params(tau1) == pytest.approx(2 * P0(tau1), rel=1e-8)
    tt = np.linspace(TAU0, tau1, 2000)[:-1]
    assert np.all(params(tt) < 2 * P0(tt))
    # same answer from a tabulated P_0 and from tau1() on a dense model curve
    tg = np.linspace(0, 200, 20001)
    assert model.predict_tau1(params, (tg, P0(tg))) == pytest.approx(tau1, abs=1e-6)
    assert transitions.tau1(tg, params(tg), P0(tg), TAU0) == pytest.approx(tau1, abs=1e-4)
    assert model.predict_tau1(params, lambda t: 1.0 + 0 * np.asarray(t)) is None  # P_0 = 1: never


# ---------------------------------------------------------------------------
# mixture model
# ---------------------------------------------------------------------------
MIX_MU = np.array([0.6, 1.3])


@pytest.fixture(scope="module")
def two_population_snapshots():
    """Two equal sub-ensembles with decay exponents 0.6 and 1.3, alive until E < E_c."""
    rng = np.random.default_rng(3)
    n = 4000
    grp = np.repeat([0, 1], n // 2)
    tg = np.arange(0.0, 301.0, 2.0)
    E = E0 * np.exp(-MIX_MU[grp][:, None] * GAMMA * tg[None, :] + 0.002 * rng.standard_normal((n, tg.size)))
    alive = tg[None, :] < (np.log(E0 / EC) / (MIX_MU * GAMMA))[grp][:, None]
    ii, jj = np.nonzero(alive)
    return pd.DataFrame({"traj_id": ii.astype(np.int64), "t": tg[jj], "energy": E[ii, jj]})


def true_components():
    return model.MixtureComponents(
        t_ref=TAU0,
        by="rate",
        edges=np.array([0.0, 1.0, 2.0]),
        weights=np.array([0.5, 0.5]),
        n_ref=np.array([1, 1]),
        E_ref=np.array([E0, E0]),
        A=np.array([E0, E0]),
        mu=MIX_MU,
        mu_err=np.zeros(2),
        fit_window=(0.0, 1.0),
        gamma=GAMMA,
    )


@pytest.mark.parametrize("by", ["energy", "rate"])
def test_mixture_components_recover_sub_ensembles(two_population_snapshots, by):
    c = model.mixture_components(two_population_snapshots, gamma=GAMMA, t_ref=TAU0, n_components=2, by=by)
    order = np.argsort(c.mu)
    np.testing.assert_allclose(c.mu[order], MIX_MU, rtol=2e-3)
    np.testing.assert_allclose(c.weights, [0.5, 0.5], atol=0.01)
    np.testing.assert_allclose(c.A, E0, rtol=2e-3)
    np.testing.assert_allclose(c.tau2(EC)[order], np.log(E0 / EC) / (MIX_MU * GAMMA), rtol=3e-3)


def test_mixture_with_one_component_is_the_homogeneous_model():
    one = np.ones(1)
    c = model.MixtureComponents(
        TAU0, "energy", np.array([0.0, 1.0]), one, one, E0 * one, E0 * one, MU * one, 0 * one, (0.0, 1.0), GAMMA
    )
    t = np.arange(0.0, 200.0, 0.5)
    for hz in ("paper", "integrated"):
        Pm = model.mixture_survival_model(
            t,
            kappa_of_E=PAPER_KAPPA,
            components=c,
            tau0=TAU0,
            f_ne=0.1,
            P_tau0=0.5,
            L=0.1,
            b=0.2,
            hazard=hz,
            E_c=EC,
        )
        np.testing.assert_allclose(Pm, model.survival_model(t, **KW, **TRUE, hazard=hz), equal_nan=True)


@pytest.mark.parametrize("hazard", ["paper", "integrated"])
def test_mixture_fits_two_population_data_better(two_population_snapshots, hazard):
    snaps = two_population_snapshots
    t = np.arange(0.0, 301.0)
    rng = np.random.default_rng(21)
    f_ne_true = np.array([0.03, 0.12])  # slow (μ = 0.6), fast (μ = 1.3)
    P_true = model.mixture_survival_model(
        t,
        kappa_of_E=PAPER_KAPPA,
        components=true_components(),
        tau0=TAU0,
        f_ne=f_ne_true,
        P_tau0=0.5,
        L=0.1,
        b=0.2,
        hazard=hazard,
        E_c=EC,
    )
    P, P_err = binomial_sample(P_true, N_ORBITS, rng)
    # homogeneous model with the paper's procedure: μ from ⟨E⟩ on [0, 200]
    m = decay.mean_energy(snaps)
    mu_h = decay.fit_energy_decay(m["t"], m["mean_E"], E0, GAMMA, (0, 200)).mu
    common = dict(kappa_of_E=PAPER_KAPPA, tau0=TAU0, P_min=20 / N_ORBITS, hazard=hazard, E_c=PAPER_KAPPA.E_c)
    homog = model.fit_survival_model(t, P, P_err, E0=E0, mu=mu_h, gamma=GAMMA, **common)
    mix = model.fit_mixture_model(t, P, P_err, snaps, gamma=GAMMA, n_components=2, by="rate", **common)
    table = model.compare_fits({"homogeneous": homog, "mixture": mix})
    assert table.loc["mixture", "n_points"] == table.loc["homogeneous", "n_points"]
    assert mix.chi2_red < 2.0
    assert homog.chi2_red > 20 * mix.chi2_red
    assert mix.rms_log_residual < 0.5 * homog.rms_log_residual
    assert mix.aic < homog.aic
    # and the mixture recovers its generating parameters
    order = np.argsort(mix.params.components.mu)
    assert np.all(np.abs(mix.values["f_ne_k"][order] - f_ne_true) < 3 * mix.errors["f_ne_k"][order])
    for name, val in (("L", 0.1), ("b", 0.2), ("f_ne", 0.15), ("f_e", 0.35)):
        # 3.5σ: six comparisons per case, and the component paths are estimates
        assert abs(mix.values[name] - val) < 3.5 * mix.errors[name], (name, mix.values[name], mix.errors[name])


# ---------------------------------------------------------------------------
# distances
# ---------------------------------------------------------------------------
UNIT = (0.0, 1.0, 0.0, 1.0)


def gaussian_blob(n, rng, centre=(0.5, 0.5), sd=0.12):
    return rng.normal(centre, sd, (n, 2))


def test_distances_zero_for_identical_sets_and_symmetric():
    rng = np.random.default_rng(0)
    P, Q = gaussian_blob(3000, rng), gaussian_blob(2000, rng, centre=(0.55, 0.5))
    for kind in ("hellinger", "tv"):
        assert distance.histogram_distance(P, P, 0.05, UNIT, kind) == 0.0
        d_pq = distance.histogram_distance(P, Q, 0.05, UNIT, kind)
        assert d_pq > 0.05 and d_pq == pytest.approx(distance.histogram_distance(Q, P, 0.05, UNIT, kind), abs=1e-15)
    assert distance.sliced_wasserstein(P, P, 64, 1) == 0.0
    sw = distance.sliced_wasserstein(P, Q, 64, 1)
    assert sw > 0 and sw == pytest.approx(distance.sliced_wasserstein(Q, P, 64, 1), rel=1e-12)
    # disjoint supports: maximal distance
    assert distance.histogram_distance(P, P + 5.0, 0.05, None, "tv") == pytest.approx(1.0)
    assert distance.histogram_distance(P, P + 5.0, 0.05, None, "hellinger") == pytest.approx(1.0)


def test_histogram_distance_inequalities():
    rng = np.random.default_rng(1)
    for _ in range(30):
        P = gaussian_blob(rng.integers(50, 2000), rng, sd=rng.uniform(0.05, 0.3))
        Q = gaussian_blob(rng.integers(50, 2000), rng, centre=rng.uniform(0.3, 0.7, 2), sd=rng.uniform(0.05, 0.3))
        box = rng.choice([0.02, 0.05, 0.1, 0.3])
        tv = distance.histogram_distance(P, Q, box, UNIT, "tv")
        h = distance.histogram_distance(P, Q, box, UNIT, "hellinger")
        assert 0.0 <= tv <= 1.0 and 0.0 <= h <= 1.0
        assert h * h <= tv + 1e-12 and tv <= math.sqrt(2) * h + 1e-12


def test_distances_grow_monotonically_with_shift():
    rng = np.random.default_rng(2)
    P = gaussian_blob(20000, rng)
    shifts = [0.0, 0.02, 0.05, 0.1, 0.2]
    for kind in ("hellinger", "tv"):
        d = [distance.histogram_distance(P, P + [s, 0.0], 0.02, (-1, 2, -1, 2), kind) for s in shifts]
        assert np.all(np.diff(d) > 0), (kind, d)
    sw = [distance.sliced_wasserstein(P, P + [s, 0.0], 64, 0) for s in shifts]
    assert np.all(np.diff(sw) > 0)


def test_sliced_wasserstein_of_translation():
    rng = np.random.default_rng(3)
    P = rng.uniform(0, 1, (3000, 2))
    s = np.array([0.3, -0.4])  # |s| = 0.5
    assert distance.sliced_wasserstein(P, P + s, 128, seed=0) == pytest.approx(2 * 0.5 / math.pi, rel=1e-3)
    assert distance.sliced_wasserstein(P, P + s, 128, seed=0, p=2) == pytest.approx(0.5 / math.sqrt(2), rel=1e-3)
    rnd = distance.sliced_wasserstein(P, P + s, 400, seed=5, directions="random")
    assert rnd == pytest.approx(2 * 0.5 / math.pi, rel=0.05)
    # deterministic with the seed, different seeds differ slightly
    assert distance.sliced_wasserstein(P, P + s, 400, 5, directions="random") == rnd
    assert distance.sliced_wasserstein(P, P + s, 400, 6, directions="random") != rnd


def test_wasserstein_1d_unequal_sizes_matches_scipy():
    rng = np.random.default_rng(4)
    a, b = rng.normal(size=333), rng.normal(1.0, 2.0, size=1000)
    assert distance.wasserstein_1d(a, b) == pytest.approx(stats.wasserstein_distance(a, b), rel=1e-10)
    # W2 between N(0,1) and N(1,2²) is √(1 + 1) for large samples
    a, b = rng.normal(size=40000), rng.normal(1.0, 2.0, size=30000)
    assert distance.wasserstein_1d(a, b, p=2) == pytest.approx(math.sqrt(2), rel=0.02)


def test_split_half_baseline_matches_hellinger_noise_floor():
    """E[H²] ≈ (B − 1)/8 (1/n_A + 1/n_B) for B well-filled boxes."""
    rng = np.random.default_rng(5)
    X = rng.uniform(0, 1, (20000, 2))
    for box in (0.1, 0.05):
        B = round(1 / box) ** 2
        h2 = lambda A, C, box=box: distance.histogram_distance(A, C, box, UNIT) ** 2  # noqa: E731
        r = distance.split_half_baseline(X, h2, 40, seed=1)
        assert r.mean == pytest.approx((B - 1) / 8 * (2 / 10000), rel=0.15)
        assert r.std > 0
    # floor decreases with sample size
    small = distance.split_half_baseline(X[:2000], lambda A, C: distance.histogram_distance(A, C, 0.1, UNIT), 20)
    large = distance.split_half_baseline(X, lambda A, C: distance.histogram_distance(A, C, 0.1, UNIT), 20)
    assert small.mean > 2.5 * large.mean


def test_bootstrap_distance():
    rng = np.random.default_rng(6)
    P, Q = gaussian_blob(1500, rng), gaussian_blob(1500, rng, centre=(0.6, 0.5))
    fn = lambda A, B: distance.sliced_wasserstein(A, B, 32, 0)  # noqa: E731
    r = distance.bootstrap_distance(P, Q, fn, n_boot=30, seed=3)
    assert r == distance.bootstrap_distance(P, Q, fn, n_boot=30, seed=3)
    m, s = r
    assert 0 < s < 0.2 * m
    assert m == pytest.approx(fn(P, Q), abs=3 * s)
    assert m == pytest.approx(2 * 0.1 / math.pi, rel=0.3)


def _filaments(n, jitter, rng):
    xs = np.random.default_rng(5).uniform(0.05, 0.95, 25)  # common support: 25 vertical lines
    k = rng.integers(0, xs.size, n)
    return np.column_stack([xs[k] + jitter * rng.standard_normal(n), rng.uniform(0, 1, n)])


def test_distance_vs_scale_and_agreement_scale():
    rng = np.random.default_rng(7)
    boxes = [0.4, 0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625, 0.003125]
    P, Q = _filaments(12000, 0.0, rng), _filaments(12000, 0.0, rng)
    blurred = _filaments(12000, 0.01, rng)  # same filaments smeared over δ = 0.01
    same = distance.distance_vs_scale(P, Q, boxes, UNIT, n_splits=6, seed=1)
    blur = distance.distance_vs_scale(P, blurred, boxes, UNIT, n_splits=6, seed=1)
    assert same["box"].tolist() == boxes and (same["m"] == 6000).all()
    for col in ("hellinger", "tv", "hellinger_pq", "hellinger_noise", "hellinger_excess", "tv_noise_std"):
        assert col in same.columns
    # noise floor grows as boxes shrink; identical distributions agree at all informative scales
    assert np.all(np.diff(same["hellinger_noise"]) > 0)
    informative = same.loc[same["hellinger_noise"] <= 0.5, "box"].min()
    assert distance.agreement_scale(same) == informative
    # blur of size δ is resolved: agreement only at scales well above δ, excess grows below
    eps_star = distance.agreement_scale(blur)
    assert eps_star is not None and eps_star > 2 * 0.01
    fine = blur[blur["box"] <= 0.0125]
    assert (fine["hellinger_excess"] > 10 * fine["hellinger_noise_std"]).all()


def test_box_distances_bootstrap_of_several_distances_and_two_set_noise_floor():
    rng = np.random.default_rng(8)
    P, Q = gaussian_blob(800, rng), gaussian_blob(600, rng, centre=(0.55, 0.5))
    boxes = [0.25, 0.1]
    d = distance.box_distances(P, Q, boxes, UNIT)
    assert d.shape == (2, 2)
    assert d[1, 0] == distance.histogram_distance(P, Q, 0.1, UNIT, "hellinger")
    assert d[0, 1] == distance.histogram_distance(P, Q, 0.25, UNIT, "tv")
    # several distances of the same resamples: each part as if bootstrapped alone with the same seed
    both = distance.bootstrap_distance(
        P,
        Q,
        lambda A, B: (distance.box_distances(A, B, boxes, UNIT), distance.sliced_wasserstein(A, B, 16, 1)),
        7,
        seed=4,
    )
    alone = distance.bootstrap_distance(P, Q, lambda A, B: distance.sliced_wasserstein(A, B, 16, 1), 7, seed=4)
    assert both.mean[1] == alone.mean and both.std[1] == alone.std
    assert both.std[0].shape == (2, 2) and (both.std[0] > 0).all()
    # the two-set noise floor is distance_vs_scale's, split for split
    tab = distance.distance_vs_scale(P, Q, boxes, UNIT, kinds=("hellinger",), n_splits=5, seed=9, m=250)
    for j, box in enumerate(sorted(boxes, reverse=True)):
        nz = distance.split_half_noise(
            P, Q, lambda A, B, box=box: distance.histogram_distance(A, B, box, UNIT), m=250, n_splits=5, seed=9
        )
        assert nz.mean == pytest.approx(tab["hellinger_noise"].iloc[j], rel=1e-12)
        assert nz.std == pytest.approx(tab["hellinger_noise_std"].iloc[j], rel=1e-12)
    with pytest.raises(ValueError, match="m must be in"):
        distance.split_half_noise(P, Q, lambda A, B: 0.0, m=301)


def test_inside_mean_energy_pools_parts_and_splits_at_ec():
    rng = np.random.default_rng(3)
    rows = pd.DataFrame(
        {"traj_id": np.repeat(np.arange(60), 5), "t": np.tile(np.arange(5.0), 60), "energy": rng.uniform(0.1, 0.3, 300)}
    )
    parts = [rows.iloc[:120], rows.iloc[120:]]
    r = decay.inside_mean_energy(parts, EC)
    whole = decay.mean_energy(rows)
    np.testing.assert_allclose(r.inside["mean_E"], whole["mean_E"], rtol=1e-13)
    np.testing.assert_array_equal(r.inside["n"], whole["n"])
    np.testing.assert_allclose(r.above["mean_E"], decay.mean_energy(rows[rows["energy"] > EC])["mean_E"], rtol=1e-13)
    assert r.rows_below_ec == int((rows["energy"] <= EC).sum())


def test_bootstrap_mu_first_orbits_uses_the_first_k_orbits_and_scales_errors():
    rng = np.random.default_rng(4)
    t = np.arange(0.0, 100.0, 5.0)
    n = 400
    mu_i = rng.normal(MU, 0.05, n)
    rows = pd.DataFrame(
        {
            "traj_id": np.repeat(np.arange(n), t.size),
            "t": np.tile(t, n),
            "energy": (E0 * np.exp(-np.outer(mu_i, GAMMA * t))).ravel(),
        }
    )
    boot, scale = decay.bootstrap_mu_first_orbits(rows, n, 100, E0, GAMMA, [(0.0, 95.0)], n_boot=5, seed=2)
    sub = rows[rows["traj_id"] < 100]
    direct = decay.bootstrap_mu(sub["traj_id"], sub["t"], sub["energy"], E0, GAMMA, [(0.0, 95.0)], n_boot=5, seed=2)
    pd.testing.assert_frame_equal(boot, direct)
    assert scale == 0.5
    with pytest.raises(ValueError, match="k must be in"):
        decay.bootstrap_mu_first_orbits(rows, n, 0, E0, GAMMA, [(0.0, 95.0)])


def test_homogeneous_fit_steps_alone():
    """The steps of fit_survival_model (start values, bounds, parameters from θ, starts, one fit at fixed τ2)."""
    from hhscatter.analysis.dissipative.survival_model import HomogeneousProblem, _homogeneous_start

    t = np.arange(0.0, 301.0)
    P = model.survival_model(t, **KW, **TRUE, hazard="paper")
    sel = (t >= KW["tau0"]) & np.isfinite(P) & (P > 1e-4)
    tf, Pf = t[sel], P[sel]
    sf = 1e-3 * Pf
    P_tau0 = float(np.interp(KW["tau0"], t[np.isfinite(P)], P[np.isfinite(P)]))
    tau2 = transitions.tau2_predicted(KW["E0"], EC, KW["mu"], KW["gamma"])
    fne0, fe0, L0, b_starts = _homogeneous_start(tf, Pf, tau2, P_tau0, {}, None)
    assert 0 < fne0 <= 0.9 * P_tau0 and fe0 == pytest.approx(P_tau0 - fne0) and L0 > 0
    assert b_starts == (0.02, 0.1, 0.5)
    assert _homogeneous_start(tf, Pf, tau2, P_tau0, {"f_ne": 0.01}, {"b": 2.0})[0::3] == (0.01, (2.0,))
    prob = HomogeneousProblem(
        tf,
        Pf,
        sf,
        KW["kappa_of_E"],
        KW["E0"],
        KW["mu"],
        KW["gamma"],
        KW["tau0"],
        EC,
        "paper",
        "log",
        ("f_ne", "L", "b"),
        {},
        {"f_ne": fne0, "f_e": fe0, "L": L0},
        b_starts,
        True,
        P_tau0,
    )
    lo, hi = prob.bounds()
    assert hi[0] == P_tau0 and lo[1] == 1e-9 and hi[2] == 1e3
    v = prob.values([0.2, 0.3, 0.4], tau2)
    assert v["f_e"] == pytest.approx(P_tau0 - 0.2) and v["tau2"] == tau2 and (v["L"], v["b"]) == (0.3, 0.4)
    assert len(prob.starts()) == 3 and prob.starts([1, 2, 3], warm_only=True) == [[1, 2, 3]]
    sol, chi2, res = prob.fit_at(tau2)
    fitted = prob.values(sol.x, tau2)
    for name in ("f_ne", "L", "b"):
        assert fitted[name] == pytest.approx(TRUE[name], rel=1e-4), name
    assert chi2 < 1e-6 and np.allclose(prob.model(fitted)(tf), Pf, rtol=1e-6)
