"""The fitting rule of the dissipative figures (hhscatter.reproduction.hazard_fits), on binomial samples of the
survival model with known parameters."""

import numpy as np
import pytest

from hhscatter.analysis.dissipative import models as model
from hhscatter.errors import ConfigError
from hhscatter.reproduction.fig2 import PAPER_KAPPA
from hhscatter.reproduction.hazard_fits import (
    best_fit,
    fit_homogeneous_hazards,
    plateau_level,
    survival_fit_points,
)

E0, GAMMA, MU, TAU0 = 0.3, 0.01, 0.91, 5.0
N_ORBITS = 100_000
KW = dict(kappa_of_E=PAPER_KAPPA, E0=E0, mu=MU, gamma=GAMMA, tau0=TAU0, E_c=PAPER_KAPPA.E_c)
TRUE = dict(f_ne=0.1, f_e=0.4, L=0.1, b=0.2)
T = np.linspace(0.0, 20.0, 41)
P = np.exp(-0.2 * T)


def binomial_sample(P, N, rng):
    """Independent binomial estimate of each P(t) with N orbits, and its standard error."""
    P = np.where(np.isnan(P), 1.0, P)
    Ph = rng.binomial(N, np.clip(P, 0, 1)) / N
    return Ph, np.sqrt(Ph * (1 - Ph) / N)


def test_fit_homogeneous_hazards_by_the_figure_rule_recovers_the_model_it_sampled():
    """fig6's rule (coarse points, P(τ0) held, three starts, best χ²), now shared: a binomial sample of the model
    with known f_ne, L, b gives them back within 3σ for both hazards, and P(τ0) is read off the curve."""
    for hazard, seed in (("paper", 11), ("integrated", 12)):
        t = np.arange(0.0, 301.0, 0.5)
        rng = np.random.default_rng(seed)
        P, P_err = binomial_sample(model.survival_model(t, **KW, **TRUE, hazard=hazard), N_ORBITS, rng)
        P = np.where(t < TAU0, 1.0, P)  # the irregular regime is not modelled: any curve before τ0
        P_err = np.where(t < TAU0, 1e-3, P_err)
        tf, Pf, sf = survival_fit_points(t, P, P_err, TAU0, 2.0, N_ORBITS, 20)
        assert np.all(np.diff(tf) >= 1.5) and tf[0] >= TAU0 and np.all(Pf * N_ORBITS >= 20)
        kw = {("kappa" if k == "kappa_of_E" else k): v for k, v in KW.items()}
        fits = fit_homogeneous_hazards(
            t, P, P_err, tf, Pf, sf, **kw, hazards=[hazard], fit_tau2=False, P_min=20 / N_ORBITS
        )
        f = fits[hazard]
        assert f.values["P_tau0"] == pytest.approx(plateau_level(t, P, TAU0))
        for name in ("f_ne", "L", "b"):
            assert abs(f.values[name] - TRUE[name]) < 3 * f.errors[name], (hazard, name, f.values[name])


def test_best_fit_skips_the_starts_that_fail_and_refuses_when_all_do():
    def fit(p0):
        if p0 is None:
            raise ValueError("bad start")
        return type("Fit", (), {"chi2": abs(p0["x"] - 1.0)})()

    assert best_fit(fit, [None, {"x": 3.0}, {"x": 0.5}]).chi2 == 0.5
    with pytest.raises(RuntimeError, match="every starting point"):
        best_fit(fit, [None])


@pytest.mark.parametrize(
    ("f", "kwargs", "arg"),
    [
        (
            survival_fit_points,
            {"t": T, "P": P, "P_err": 0.01 * P, "tau0": 1.0, "fit_dt": 2.0, "n": 1000, "min_count": 20},
            "fit_dt",
        ),  # fmt: skip
        (
            survival_fit_points,
            {"t": T, "P": P, "P_err": 0.01 * P, "tau0": "x", "fit_dt": 2.0, "n": 1000, "min_count": 20},
            "tau0",
        ),  # fmt: skip
        (plateau_level, {"t": T, "P": P, "t_q": "x"}, "t_q"),
        (plateau_level, {"t": T[::-1], "P": P, "t_q": 5.0}, "t"),
    ],
)
def test_a_wrong_argument_is_refused_naming_it(f, kwargs, arg):
    bad = {**kwargs}
    if arg == "fit_dt":
        bad["fit_dt"] = 0.0
    with pytest.raises(ConfigError, match=rf"^{arg}\b"):
        f(**bad)
