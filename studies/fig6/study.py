"""Study fig6: the survival model against simulations (paper Fig. 6, fig:model_data_comparison).

Paper (Sec. III.B.3): with κ_γ(t) = κ0(E(t)), κ0(E) the conservative escape
rate of Fig. 2b and E(t) = E0 e^{−μγt} of Fig. 3, Eq. (eqn:surv_prob_model)

    P_γ(t) = f_ne + f_e exp(−κ_γ(t)(t − τ0))        τ0 ≤ t ≤ τ2
           = f_ne exp(−g(t, γ)(t − τ2))             t > τ2,   g = L/(1 + e^{−b(t−τ2)})²,

with f_ne + f_e = P(τ0) and τ2 = ln(E0/E_c)/(μγ), Eq. (eq:tau2).  (a) the model
against simulated P(t) for several (E0, γ); (b) τ1 (Eq. (eqn:tau1), α = 2)
and τ2 predicted vs observed as functions of γ at E0 = 0.3.  The paper notes
that "a mixture model for P(t) involving multiple sub-ensembles, each with
their own energy decay exponent μ" should improve the agreement.

Stages
------
simulate   one run per (E0, γ) in ``pairs`` with energy snapshots (raw keys
           ``E<E0>_g<γ>``).
analyze    inputs (the studies of ``[needs]``, their published outputs only):
           κ0(E) (fig2.json), μ (fig3.json), τ0 and the observed τ table
           (fig4.json) and fig4's lifetimes at E0 = 0.3 (its derived table).  Per pair:
           Kaplan–Meier P(t); fits of the homogeneous model with the paper's
           literal escape factor (hazard "paper") and with the cumulative
           hazard exp(−∫κ0) ("integrated") — free f_ne, L, b; f_e = P(τ0) − f_ne;
           τ2 from Eq. (eq:tau2) —, and of the mixture model with the same
           number of free parameters (K energy quantiles at t_ref = τ0,
           per-orbit μ_i from the snapshots, one never-escaping share φ for all).
           For fig4's γ values: the homogeneous fit and the model's τ1
           (:func:`hhscatter.analysis.dissipative.model_comparison.predict_tau1` against fig4's γ = 0
           curve), τ2 = ln(E0/E_c)/(μγ).  Writes derived tables and fig6.json.

           The paper's own constants beside ours (``[study] paper_*``: κ0(E) of
           the Fig. 2b caption, μ = 0.91 of Sec. III.A): the same homogeneous
           fits (free f_ne, L, b; τ0 ours, the paper gives none) with κ0 and μ
           held at the paper's values, on the same fitted points, in both
           hazard forms; their RMS log residuals beside ours, which of the two
           fits the simulation better, and the τ1, τ2 they predict (fig6.json
           key ``paper_constants``; comparison rows with ``authors=True``).
plot       Fig. 6 from the derived tables.

Errors: the fit errors treat the points of one Kaplan–Meier curve as
independent (``absolute_sigma``); the points are positively correlated, so
χ²/dof and the parameter errors are indicative (coarse grid ``fit_dt``).
"""

from __future__ import annotations

import math

import pandas as pd

from hhscatter.analysis.stats.measured import Measured
from hhscatter.reproduction import model_tables as mt
from hhscatter.reproduction import model_verdicts as mv
from hhscatter.scene.schema import Bool, Integer, Number, NumberLists, NumberOr, Numbers, OneOf, Text, Texts
from hhscatter.studies import _upstream as up
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, figure_stage


class Mixture(StudyParams):
    """One entry of ``[study] mixtures``."""

    name: Text
    by: OneOf("energy", "rate")
    t_ref: NumberOr("tau0")
    fne_mode: OneOf("shared", "free")


class Params(StudyParams):
    """``[study]`` of studies/fig6/study.toml."""

    pairs: NumberLists  # [[E0, γ], ...]
    dt: Number
    fit_dt: Number
    min_count: Number
    hazards: Texts
    fit_tau2: Bool = False
    n_components: Integer
    mixtures: list[Mixture]
    mixture_fit_window: Numbers
    mixture_max_orbits: Integer = None  # the mixture model uses the snapshots of orbits traj_id < this (None: all)
    mixture_plotted: Text = None
    alpha: Number
    paper_kappa_a: Number  # the paper's κ0(E) law (Fig. 2b caption): a x² + b x below E_b, c x above,
    paper_kappa_b: Number  #   x = E − E_c; a in 1/(time·energy²), b and c in 1/(time·energy), E_b an energy
    paper_kappa_c: Number
    paper_kappa_Eb: Number
    paper_mu: Number  # the paper's energy-decay exponent (Sec. III.A, Fig. 3), dimensionless
    kappa_a_key: Text
    kappa_b_key: Text
    kappa_c_key: Text
    kappa_Eb_key: Text
    mu_key: Text
    tau0_key: Text
    tau_table_key: Text
    tau_gamma_field: Text
    tau1_field: Text
    tau2_field: Text
    fig4_E0: Number


DEV_TAU0 = 5.0  # development fallback only (the paper gives no number for τ0)
PC = mt.PAPER_CONSTANTS  # name of the model evaluated with the paper's constants (columns, tables, JSON key)


def pair_key(E0: float, g: float) -> str:
    """pair_key(E0, γ) -> raw run key, e.g. 'E0.30_g0.01'."""
    return f"E{E0:.2f}_g{g:g}"


def _pairs(study):
    out = []
    for p in study.params.pairs:
        if len(p) != 2:
            raise ValueError(f"[study] pairs must hold [E0, gamma] pairs, got {p!r}")
        out.append((float(p[0]), float(p[1])))
    return out


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None) -> None; one run per (E0, γ) pair with energy snapshots."""
    for E0, g in _pairs(study):
        study.run(pair_key(E0, g), study.scene(pair_key(E0, g), energy=E0, gamma=g), workers=workers, progress=progress)


# ---------------------------------------------------------------------------
# analysis helpers
# ---------------------------------------------------------------------------
def paper_constants(study) -> dict:
    """paper_constants(study) -> {a, b, c, E_b, mu}: the paper's constants as ``[study] paper_*`` states them.

    κ0(E) = a x² + b x for E < E_b and c x for E ≥ E_b, x = E − E_c (paper
    Fig. 2b = fig:kappa-E-dependence, caption; κ0 in 1/time, E_b an energy),
    and μ (Eq. (eqn:energy_exp_decay), dimensionless; Sec. III.A, Fig. 3 =
    fig:energy_decay).  Read from study.toml, never written in the code.
    """
    return {
        "a": study.params.paper_kappa_a,
        "b": study.params.paper_kappa_b,
        "c": study.params.paper_kappa_c,
        "E_b": study.params.paper_kappa_Eb,
        "mu": study.params.paper_mu,
    }


def _inputs(study):
    inputs = {}
    ks = study.upstream("kappa")
    kv = {}
    # the paper's values stand in only under the development fallback (labelled in inputs and the figure)
    pc = paper_constants(study)
    for name in ("a", "b", "c", "E_b"):
        key = getattr(study.params, "kappa_Eb_key" if name == "E_b" else f"kappa_{name}_key")
        kv[name], _ = up.value_or_fallback(study, ks, key, pc[name], inputs, f"kappa_{name}")
    E_c = study.model.critical_energy  # E_c = ω⁶/(6λ²) of the scene's model
    kappa = mt.kappa_from_constants(kv, E_c)
    mu, mu_err = up.value_or_fallback(study, study.upstream("mu"), study.params.mu_key, pc["mu"], inputs, "mu")
    tau0, _ = up.value_or_fallback(study, study.upstream("tau"), study.params.tau0_key, DEV_TAU0, inputs, "tau0")
    return inputs, kappa, float(mu), float(mu_err if mu_err is not None else math.nan), float(tau0), E_c


def _mixture_variants(study):
    """The [study] mixtures list: dicts with name, by ("energy"/"rate"), t_ref ("tau0" or a time), fne_mode."""
    out = []
    for v in study.params.mixtures:
        missing = {"name", "by", "t_ref", "fne_mode"} - set(v)
        if missing:
            raise ValueError(f"[study] mixtures entries need {sorted(missing)}: {v!r}")
        if not str(v["name"]).startswith("mixture"):
            raise ValueError(f"[study] mixtures names must start with 'mixture', got {v['name']!r}")
        out.append(dict(v))
    return out


def analyze(study):
    """analyze(study) -> None; model fits, τ predictions, derived tables and fig6.json."""
    import pyarrow as pa

    s = _setup(study)
    curves, fit_rows, comp_rows, cmp_rows, pc_rows = [], [], [], [], []
    for E0, g in _pairs(study):
        cur, rows = _fit_pair(study, s, E0, g)
        curves.append(cur)
        for acc, new in zip((fit_rows, comp_rows, cmp_rows, pc_rows), rows):
            acc.extend(new)
        # 1e7 lifetimes and 1e6 orbits' snapshots per pair at paper scale (gone with _fit_pair): not kept for the next
        pa.default_memory_pool().release_unused()
    curves = pd.concat(curves, ignore_index=True)
    fits = pd.DataFrame(fit_rows)
    comps = pd.concat(comp_rows, ignore_index=True)
    cmps = pd.concat(cmp_rows, ignore_index=True)
    pcf = pd.DataFrame(pc_rows)
    taus, tau_curves, pct = _tau_predictions(study, s)

    study.write_table(curves, "curves.parquet", tau0=s.tau0, mu=s.mu)
    study.write_table(fits, "fits.parquet")
    study.write_table(comps, "mixture_components.parquet")
    study.write_table(cmps, "compare_fits.parquet")
    study.write_table(taus, "tau_vs_gamma.parquet")
    study.write_table(tau_curves, "tau2_curve.parquet")
    study.write_table(pcf, f"{PC}_fits.parquet", constants=s.pc)
    study.write_table(pct, f"{PC}_taus.parquet", constants=s.pc)

    _compare_with_paper(study, s, fits, cmps, taus, pcf, pct)
    study.write_numbers(_numbers(s, fits, cmps, comps, taus, pcf, pct))


def _setup(study) -> mt.ModelInputs:
    """Read inputs: κ0(E), μ and τ0 of the upstream studies, the paper's constants, the model variants."""
    inputs, kappa, mu, mu_err, tau0, E_c = _inputs(study)
    pc = paper_constants(study)
    kappa_pc = mt.kappa_from_constants(pc, E_c)
    hazards = list(study.params.hazards)
    return mt.ModelInputs(inputs, kappa, mu, mu_err, tau0, E_c, pc, kappa_pc, hazards, _mixture_variants(study))


def _fit_pair(study, s: mt.ModelInputs, E0: float, g: float):
    """One (E0, γ): its lifetimes and (on demand) snapshots read, the model fits of
    :func:`~hhscatter.reproduction.model_tables.pair_fits`."""
    import pyarrow.dataset as pads

    from hhscatter.data.read import read_lifetimes, read_snapshots

    label = pair_key(E0, g)
    raw = study.raw(label)
    lt = read_lifetimes(raw, columns=["t_end", "outcome"], categorical=True)  # 9 bytes per orbit

    def snapshots():
        # the mixture needs per-orbit energy records: at N = 1e7 they are ~1e8 rows, so it uses the first
        # mixture_max_orbits orbits (a uniform random subset: the initial conditions are i.i.d. in traj_id)
        cap = study.params.mixture_max_orbits
        keep = pads.field("t") >= s.tau0
        if cap is not None:
            keep = keep & (pads.field("traj_id") < cap)
        return read_snapshots(raw, filters=keep)

    p = study.params
    return mt.pair_fits(
        lt,
        snapshots,
        s,
        label=label,
        E0=E0,
        gamma=g,
        dt=p.dt,
        fit_dt=p.fit_dt,
        min_count=p.min_count,
        fit_tau2=p.fit_tau2,
        n_components=p.n_components,
        fit_end=p.mixture_fit_window[1],
    )


def _tau_predictions(study, s: mt.ModelInputs):
    """τ1, τ2 vs γ at fig4's E0 (:func:`~hhscatter.reproduction.model_tables.tau_predictions` on fig4's
    published tables)."""
    p = study.params
    ref = _fig4_reference(study, s.inputs, p.dt)
    return mt.tau_predictions(ref, s, dt=p.dt, fit_dt=p.fit_dt, min_count=p.min_count, alpha=p.alpha)


def _compare_with_paper(study, s: mt.ModelInputs, fits, cmps, taus, pcf, pct) -> None:
    """Compare with the paper: μ used, goodness of the homogeneous fits, the mixtures, τ1 and τ2, its constants."""
    kappa = s.kappa
    ours_const = {"a": kappa.a2, "b": kappa.a1, "c": kappa.slope, "E_b": kappa.E_switch, "mu": s.mu}
    study.compare("μ used (from fig3)", s.mu, s.mu_err, s.pc["mu"], note=s.inputs["mu"]["source"])
    setup = study.convention_label
    rows = [
        *mv.homogeneous_comparisons(fits, ours_const, setup),
        *mv.mixture_comparisons(cmps, s.hazards, s.mixtures),
        *mv.tau_comparisons(taus, s.hazards),
        *mv.constants_comparisons(s.pc, s.tau0, pcf, pct, s.hazards, setup),
    ]
    for row in rows:
        study.compare(**row)


def _numbers(s: mt.ModelInputs, fits, cmps, comps, taus, pcf, pct) -> dict:
    """fig6.json: the inputs, κ0(E), μ, τ0, every fit and comparison, τ vs γ, the paper's constants."""
    kappa = s.kappa
    return {
        "inputs": s.inputs,
        "dev_fallback": up.any_fallback(s.inputs),
        "kappa0": {"a": kappa.a2, "b": kappa.a1, "c": kappa.slope, "E_b": kappa.E_switch, "E_c": s.E_c},
        "mu": Measured(s.mu, s.mu_err).to_dict(),
        "tau0": s.tau0,
        "fits": fits.to_dict(orient="records"),
        "compare_fits": cmps.to_dict(orient="records"),
        "mixture_components": comps.to_dict(orient="records"),
        "tau_vs_gamma": taus.to_dict(orient="records"),
        PC: mt.constants_record(s.pc, s.E_c, s.tau0, pcf, pct, s.hazards),
    }


# ---------------------------------------------------------------------------
# panel (b): τ1, τ2 against γ at fig4's E0
# ---------------------------------------------------------------------------
def _fig4_reference(study, inputs, dt) -> mt.TauReference:
    """Observed τ1, τ2 from fig4's table and fig4's P(t) lifetimes (its published derived table)
    (:func:`~hhscatter.reproduction.model_tables.tau_reference`)."""
    import pyarrow as pa

    from hhscatter.data.read import read_lifetimes

    E0 = study.params.fig4_E0
    other = study.upstream("tau")
    try:
        doc = up.numbers(study, other)
        table, _ = up.lookup(doc, study.params.tau_table_key, what=f"{other}.json")
        rows = pd.DataFrame(table)
        fields = tuple(getattr(study.params, k) for k in ("tau_gamma_field", "tau1_field", "tau2_field"))
        missing = set(fields) - set(rows.columns)
        if missing:
            raise up.UpstreamError(
                f"{other}.json:{study.params.tau_table_key} rows lack {sorted(missing)}; have {sorted(rows.columns)}"
            )
        inputs["tau_table"] = {"source": f"{other}.json:{study.params.tau_table_key}"}
        # P(t) of the τ study's runs from its published lifetimes table (never its raw runs)
        tname = doc.get("tables", {}).get("lifetimes")
        if not tname:
            raise up.UpstreamError(f"{other}.json names no published lifetimes table ('tables': {{'lifetimes': …}})")
        inputs["tau_lifetimes"] = {"source": f"{other}: derived/{tname}"}
        # one γ at a time (6 × 1e7 rows at paper scale): only the γ of the τ table and the reference γ = 0
        by_gamma = {}
        for g in sorted({0.0, *(float(v) for v in rows[fields[0]])}):
            d = up.table(study, other, tname, filters=[("gamma", "==", g)], columns=["t_end", "outcome"])
            if len(d):
                by_gamma[g] = d.reset_index(drop=True)
            del d
            pa.default_memory_pool().release_unused()
        if 0.0 not in by_gamma:
            raise up.UpstreamError(f"{other}'s {tname} has no γ = 0 rows (the conservative reference)")
        return mt.tau_reference(rows, by_gamma, E0=E0, dt=dt, fields=fields)
    except up.UpstreamError:
        if not up.dev_fallback_enabled():
            raise
        # development only: observed τ2 from this study's own E0 = 0.3 runs, no τ1 (no γ = 0 run)
        inputs["tau_table"] = {"source": up.DEV_SOURCE + ": own E0 runs, τ1 not available"}
        lifetimes = {
            g: read_lifetimes(study.raw(pair_key(e, g)), columns=["t_end", "outcome"], categorical=True)
            for e, g in _pairs(study)
            if abs(e - E0) < 1e-12
        }
        return mt.tau2_reference(lifetimes, E0)


plot = figure_stage(
    "plot_fig6",
    "curves",
    "fits",
    "tau_vs_gamma",
    "tau2_curve",
    "compare_fits",
    NUMBERS,
    PATH,
    pc_fits=f"{PC}_fits",
    pc_taus=f"{PC}_taus",
)
