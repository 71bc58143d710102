"""Study fig4: P(t) for several γ at E0 = 0.3 and the times τ0, τ1, τ2 (paper Fig. 4 = fig:survprob).

Paper: survival probability P(t) of the dissipative Hénon–Heiles system for
several small γ with the conservative curve (γ = 0) for comparison; for
γ = 10⁻² the times τ0, τ1, τ2 are marked.  A settled orbit (energy reached
E_c inside Ω) leaves at its settling time, an escaped one at its escape time.

Definitions used here (all times in model units):

* τ0 — end of the irregular initial regime; the paper says it is
  effectively independent of γ, so it is measured once, on the conservative
  curve P_0, by the data-driven rule of
  :func:`hhscatter.analysis.survival.windows.choose_windows` (the first time after
  which the local escape rate stays within 10 % / 3σ of its plateau value;
  the same rule as the Fig. 2 escape-rate fits).
* τ1 — Eq. (eqn:tau1): first t ≥ τ0 with P_γ(t) = α P_0(t), α = 2
  (:func:`hhscatter.analysis.dissipative.transitions.tau1` on a fine grid, log-linear
  interpolation).  ``n0_at_tau1`` = N·P_0(τ1) tells whether P_0 is still
  resolved there (flag ``tau1_resolved``: at least ``min_ref_orbits`` orbits).
* τ2 observed — "the first time at which the energy of a non-escaping orbit
  dropped below E_c" (Fig. 6b caption): the smallest settling time.  Being a
  minimum over N·f_settled orbits it decreases with N (the paper used N =
  10⁷); the 1 % and 50 % quantiles of the settling times are given as
  N-independent companions. Its interval is the distribution-free
  order-statistic interval of the quantile it estimates, t_{1/N}
  (:func:`~hhscatter.analysis.dissipative.transitions.tau2_observed_interval`, ≥ 68 %:
  ``tau2_obs_lo``, ``tau2_obs_hi``; ``tau2_obs_err`` is its half-width), not
  a bootstrap of the minimum; the exponent of τ2,obs ∝ γ^−p is an
  unweighted log-log fit (a minimum has no error to weight by).
* τ2 predicted — Eq. (eq:tau2), ln(E0/E_c)/(μγ), with μ measured by this
  study on its own γ = ``mu_gamma`` run exactly as in study fig3 (⟨E⟩ over
  orbits not escaped, settled orbits continued, log fit on ``mu_window``),
  one μ for all γ as in the paper (τ2 ∝ 1/γ).  Also given with the paper's
  μ = 0.91, and fig3's μ is recorded beside it (``[needs] mu_crosscheck``).

Other errors: paired bootstrap over orbits (every γ shares the same initial
conditions, orbit i gets the same multiplicity in every ensemble).

Raw runs: ``raw/gamma<γ:g>`` — ``gamma0``, ``gamma0.001``, ``gamma0.002``,
``gamma0.005``, ``gamma0.01``, ``gamma0.02``; the μ run's snapshots include
its settled orbits, continued past E_c.  Published for other studies (fig6
reads them, never the raw runs): ``fig4.json`` and the derived tables, among
them ``fig4_lifetimes.parquet`` (γ, t_end, outcome of every orbit).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from hhscatter.analysis.dissipative.decay import decay_exponent, snapshot_grid
from hhscatter.analysis.stats.measured import Measured
from hhscatter.reproduction.transition_tables import (
    survival_ratio_tables,
    transition_comparisons,
    transition_table,
)
from hhscatter.scene.schema import Integer, Number, NumberLists, Numbers
from hhscatter.studies import _upstream as up
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, Param, figure_stage


class Params(StudyParams):
    """``[study]`` of studies/fig4/study.toml."""

    gammas: Numbers  # increasing, with 0 (the conservative reference)
    mark_gamma: Number
    alpha: Number
    tau_grid_step: Number
    min_ref_orbits: Number
    mu_gamma: Number
    snapshot_grid: NumberLists
    mu_window: Numbers
    paper_mu: Number
    n_boot: Integer
    n_boot_orbits: Integer
    boot_seed: Integer


LIFETIMES_TABLE = "fig4_lifetimes.parquet"  # published: other studies read it (derived/), never the raw runs


def raw_key(gamma: float) -> str:
    """raw_key(gamma) -> 'gamma<γ:g>', e.g. raw_key(0.001) == 'gamma0.001', raw_key(0) == 'gamma0'."""
    return f"gamma{float(gamma):g}"


def _gammas(study):
    gs = list(study.params.gammas)
    if 0.0 not in gs:
        raise ValueError("fig4 [study].gammas must contain 0 (the conservative reference P_0)")
    if sorted(gs) != gs or len(set(gs)) != len(gs):
        raise ValueError(f"fig4 [study].gammas must be increasing and distinct, got {gs}")
    mg = study.params.mu_gamma
    if mg not in gs:
        raise ValueError(f"fig4 [study].mu_gamma = {mg} must be one of gammas {gs}")
    return gs, mg


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None) -> None: one engine run per γ (same ICs); for mu_gamma with snapshots,
    settled orbits continued to the last grid time."""
    gs, mg = _gammas(study)
    grid = snapshot_grid(study.params.snapshot_grid)
    for g in gs:
        key = raw_key(g)
        extra = {"snapshots": tuple(grid), "continue_settled": True} if g == mg else {"snapshots": None}
        study.run(key, study.scene(key, gamma=g, **extra), workers=workers, progress=progress)


def _tau0_rule(grid, P0, n):
    from hhscatter.analysis.survival.windows import choose_windows

    return choose_windows(grid, P0, n_total=n).tau0


def analyze(study):
    """analyze(study) -> None: P(t) per γ, τ0/τ1/τ2 (+ bootstrap), μ, derived tables and fig4.json.

    Steps: the paired lifetimes (:func:`_read_lifetimes`), P(t) on the τ grid and
    τ0, the study's own μ (:func:`_own_mu`), the paired bootstrap, the τ table
    (:func:`~hhscatter.reproduction.transition_tables.transition_table`), the figure's tables, the
    paper comparison (:func:`~hhscatter.reproduction.transition_tables.transition_comparisons`) and
    the numbers (:func:`_numbers`).
    """
    from hhscatter.analysis.dissipative.transitions import subsample_bootstrap_transition_times, survival_on_grid
    from hhscatter.analysis.survival.fits import observed_from_outcome

    gs, mg = _gammas(study)
    E0 = float(study.config["scene"]["energy"])
    alpha = study.params.alpha
    dt = study.params.tau_grid_step
    lts, N, t_last = _read_lifetimes(study, gs)

    # fine grid for τ0/τ1 (P on it is exact: no censoring before t_max in these runs)
    grid = np.round(np.arange(0.0, t_last + dt, dt), 9)
    obs = {g: observed_from_outcome(lt["outcome"]) for g, lt in lts.items()}
    P = {g: survival_on_grid(lts[g]["t_end"].to_numpy(), obs[g], grid) for g in gs}
    tau0 = float(_tau0_rule(grid, P[0.0], N))

    mu, mu_err, cont, win = _own_mu(study, mg, E0, N)
    # fig3's μ beside this study's own (a declared need: [needs].mu_crosscheck)
    mu_fig3 = up.numbers(study, study.upstream("mu_crosscheck")).get("mu")

    # paired bootstrap on the orbits traj_id < K (all at quick scale); σ scaled by √(K/N) beyond
    nb = study.params.n_boot
    sb = subsample_bootstrap_transition_times(
        {g: lts[g] for g in gs},
        0.0,
        grid,
        n_orbits=study.params.n_boot_orbits,
        tau0=_tau0_rule,
        alpha=alpha,
        n_boot=nb,
        seed=study.params.boot_seed + 1,
    )
    boot, bscale, K = sb.replicates, sb.scale, sb.n_orbits
    taus = transition_table(
        lts,
        grid,
        P,
        tau0,
        boot,
        bscale,
        E0=E0,
        E_c=study.model.critical_energy,
        mu=mu,
        mu_err=mu_err,
        paper_mu=study.params.paper_mu,
        alpha=alpha,
        min_ref_orbits=study.params.min_ref_orbits,
        key=raw_key,
    )
    surv, ratio = survival_ratio_tables(lts, grid, P, dt, t_last, key=raw_key)

    meta = {"E0": E0, "alpha": alpha, "tau0_rule": "choose_windows on P_0"}
    study.write_table(taus, "fig4_tau.parquet", **meta)
    study.write_table(surv, "fig4_survival.parquet", **meta)
    study.write_table(ratio, "fig4_ratio.parquet", **meta)
    # published for the studies that build on fig4 (fig6): every orbit's lifetime per γ, orbit order
    # one row group per γ, written one after the other (6 × 1e7 rows at paper scale: never concatenated)
    study.write_table_streamed(
        (_lifetimes_arrow(g, lts[g]) for g in gs),
        LIFETIMES_TABLE,
        **meta,
        description="lifetimes (t_end, outcome) of every orbit per γ, rows in traj_id order; "
        "the same initial conditions for every γ; one row group per γ",
    )

    tau0_err = sb.err("tau0")
    rows, exponents = transition_comparisons(
        taus,
        N=N,
        E0=E0,
        E_c=study.model.critical_energy,
        mu_gamma=mg,
        mu_window=win,
        mu=mu,
        mu_err=mu_err,
        mu_other=mu_fig3,
        tau0=tau0,
        tau0_err=tau0_err,
        paper_mu=study.params.paper_mu,
    )
    for row in rows:
        study.compare(**row)
    study.write_numbers(
        _numbers(
            study, taus, gs, N, E0, alpha, dt, mg, win, mu, mu_err, mu_fig3, cont, tau0, tau0_err, exponents, nb, K
        )
    )


def _lifetimes_arrow(g, lt):
    """Arrow table (gamma, t_end, outcome) of one γ; outcome dictionary-encoded (pandas reads it as a category)."""
    import pyarrow as pa

    n = len(lt)
    return pa.table(
        {
            "gamma": pa.array(np.full(n, float(g))),
            "t_end": pa.array(lt["t_end"].to_numpy()),
            "outcome": pa.array(lt["outcome"]).cast(pa.dictionary(pa.int8(), pa.string())),
        }
    )


def _read_lifetimes(study, gs):
    """({γ: DataFrame(t_end, outcome) in traj_id order}, N, last t_end): the runs must share their initial
    conditions (paired ensembles); only what the analysis needs is kept (N = 1e7 per curve at paper scale).

    Read as Arrow columns (no Python string per orbit: ``outcome`` stays a categorical of 1 byte per orbit),
    so memory is ~40 bytes per orbit while one run is read and ~9 bytes per orbit and γ kept.
    """
    from hhscatter.data.read import read_by_orbit

    lts, ref = {}, None
    for g in gs:
        c = read_by_orbit(study.raw(raw_key(g)), ["x0", "y0", "outcome", "t_end"])
        xy = (c["x0"], c["y0"])
        if ref is None:
            ref = xy
        elif xy[0].shape != ref[0].shape or not (np.array_equal(xy[0], ref[0]) and np.array_equal(xy[1], ref[1])):
            raise ValueError(f"fig4: run {raw_key(g)} does not share the initial conditions of {raw_key(gs[0])}")
        lts[g] = pd.DataFrame({"t_end": c["t_end"], "outcome": c["outcome"]})
        del c, xy
    t_last = max(float(lt["t_end"].max()) for lt in lts.values())
    return lts, len(ref[0]), t_last


def _own_mu(study, mg, E0, N):
    """(μ, σ_μ, continuation counts, window) of this study's own γ = mu_gamma run, fig3's definition
    (:func:`~hhscatter.analysis.dissipative.decay.decay_exponent`)."""
    import pyarrow.dataset as ds

    from hhscatter.data.read import iter_parts, read_snapshots

    run, k = study.raw(raw_key(mg)), min(study.params.n_boot_orbits, N)
    d = decay_exponent(
        iter_parts(run, "snapshots", ["t", "energy"]),
        read_snapshots(run, filters=ds.field("traj_id") < k),
        N,
        k,
        E0,
        mg,
        study.model.critical_energy,
        study.params.mu_window,
        n_boot=study.params.n_boot,
        seed=study.params.boot_seed,
    )
    return d.mu, d.mu_err, {"rows_below_ec": d.rows_below_ec}, d.window


def _fin(v):
    return None if not np.isfinite(v) else float(v)


def _numbers(
    study, taus, gs, N, E0, alpha, dt, mg, win, mu, mu_err, mu_fig3, cont, tau0, tau0_err, exponents, nb, K
) -> dict:
    """The content of fig4.json (definitions stated with the numbers)."""

    def exponent(name):
        p, e = exponents[name]
        return None if p is None else Measured(p, e).to_dict()

    return {
        "E0": E0,
        "n_orbits_per_curve": N,
        "gammas": gs,
        "alpha": alpha,
        "raw_keys": {f"{g:g}": raw_key(g) for g in gs},
        "tables": {"lifetimes": LIFETIMES_TABLE, "tau": "fig4_tau.parquet", "survival": "fig4_survival.parquet"},
        "raw_key_naming": (
            "raw runs are studies/fig4/out/<scale>/raw/gamma<γ formatted with %g>: gamma0 (conservative "
            "reference), gamma0.001, gamma0.002, gamma0.005, gamma0.01, gamma0.02; every run has the "
            "same initial conditions (seed, n); raw/gamma<mu_gamma> also holds the energies of that "
            "run's settled orbits after settling (snapshots schema)"
        ),
        "tau0_rule": (
            "τ0 = choose_windows(P_0).tau0: first time after which the local escape rate of the conservative "
            "curve stays within max(10 %, 3σ) of its plateau (hhscatter.analysis.survival.escape_rate)"
        ),
        "tau1_definition": f"first t ≥ τ0 with P_γ(t) = α P_0(t), α = {alpha:g} (Eq. eqn:tau1), grid step {dt:g}",
        "tau2_obs_definition": "min settling time (first E = E_c inside Ω); depends on N",
        "tau2_pred_definition": f"ln(E0/E_c)/(μγ) with μ from this study's γ = {mg:g} run on [{win[0]:g}, {win[1]:g}]",
        "mu": Measured(float(mu), mu_err).to_dict(),
        "mu_gamma": mg,
        "mu_window": list(win),
        "mu_fig3": mu_fig3,
        "paper_mu": study.params.paper_mu,
        "continuation": {k: v for k, v in cont.items() if k != "key"},
        "tau0": Measured(_fin(tau0), _fin(tau0_err)).to_dict(),
        "taus": [
            {
                "gamma": r.gamma,
                "key": r.key,
                "f_escaped": r.f_escaped,
                "f_settled": r.f_settled,
                "f_censored": r.f_censored,
                "tau1": Measured(_fin(r.tau1), _fin(r.tau1_err)).to_dict(),
                "n0_at_tau1": None if not np.isfinite(r.n0_at_tau1) else r.n0_at_tau1,
                "tau1_resolved": r.tau1_resolved,
                "tau2_obs": {
                    **Measured(_fin(r.tau2_obs), _fin(r.tau2_obs_err)).to_dict(),
                    "lo": _fin(r.tau2_obs_lo),
                    "hi": _fin(r.tau2_obs_hi),
                    "coverage": _fin(r.tau2_obs_coverage),
                },
                "t_settle_q01": Measured(_fin(r.t_settle_q01), _fin(r.t_settle_q01_err)).to_dict(),
                "t_settle_q50": Measured(_fin(r.t_settle_q50), _fin(r.t_settle_q50_err)).to_dict(),
                "tau2_pred": Measured(_fin(r.tau2_pred), _fin(r.tau2_pred_err)).to_dict(),
                "tau2_pred_paper_mu": None if not np.isfinite(r.tau2_pred_paper_mu) else r.tau2_pred_paper_mu,
            }
            for r in taus.itertuples()
        ],
        "tau2_gamma_exponent": exponent("tau2"),
        "settle_median_gamma_exponent": exponent("settle_median"),
        "tau1_gamma_exponent": exponent("tau1"),
        "n_boot": nb,
        "n_boot_orbits": K,
        "errors": (
            "paired bootstrap over orbits (Poisson multiplicities) on the first n_boot_orbits orbits, "
            "scaled by sqrt(n_boot_orbits/N); τ2,obs (a minimum): the distribution-free order-statistic "
            "interval [lo, hi] of the quantile t_1/N it estimates (exact coverage given), err its half-width; "
            "its γ exponent from an unweighted fit"
        ),
    }


plot = figure_stage(
    "plot_fig4", "fig4_survival", "fig4_ratio", "fig4_tau", NUMBERS, PATH, mark_gamma=Param("mark_gamma")
)
