"""κ from the conditionally invariant measure (c-measure) of the true-time map, Eq. (eqn:kappa_cmeasure_truetime).

:func:`kappa_from_cmeasure` solves ∫e^{κT}dμ_c = 1 + μ_c(ℰ) for κ from the
return times T of section crossings sampled from μ_c and the fraction that
exits before returning; :func:`cmeasure_sample_from_sections` builds that
sample from the engine's ``sections`` and ``lifetimes`` tables (as
DataFrames: no I/O here). Beyond the paper: an estimator of κ independent of
P(t) (study fig2).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize
from scipy.special import logsumexp

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.measured import WithErrors
from hhscatter.errors import ConfigError

__all__ = ["CMeasureKappa", "cmeasure_sample_from_sections", "kappa_from_cmeasure"]


# ---------------------------------------------------------------------------
# κ from the c-measure of the true-time map
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class CMeasureKappa(WithErrors):
    """Result of :func:`kappa_from_cmeasure` (κ in 1/time).

    kappa, kappa_err (bootstrap std), kappa_err_delta (delta method),
    mu_exit = n_exit/M (the c-measure of the exit set, μ_c(𝓔)), n_samples M,
    n_exit, boot (bootstrap replicates of κ).
    """

    method = "c-measure"
    n_field = "n_samples"

    kappa: float
    kappa_err: float
    kappa_err_delta: float
    mu_exit: float
    n_samples: int
    n_exit: int
    boot: np.ndarray = field(repr=False)


def _solve_renewal(T, M, w=None):
    """Root κ > 0 of log Σ_i w_i e^{κ T_i} = log M (returning points only; weights w_i ≥ 0, default 1)."""
    n_ret = T.size if w is None else float(np.sum(w))
    if n_ret == 0:
        return math.inf
    if n_ret >= M:
        return 0.0
    logM = math.log(M)

    def h(k):
        return float(logsumexp(k * T, b=w)) - logM

    hi = 1.0 / max(float(np.mean(T)), 1e-300)
    while h(hi) <= 0:
        hi *= 2.0
        if hi > 1e300:
            return math.inf
    return float(optimize.brentq(h, 0.0, hi, xtol=1e-14, rtol=1e-12))


def kappa_from_cmeasure(
    return_times, n_exit, *, orbits=None, exit_orbits=None, n_boot: int = 200, rng=None
) -> CMeasureKappa:
    """kappa_from_cmeasure(return_times, n_exit, *, orbits=None, exit_orbits=None, n_boot=200, rng=None) -> CMeasureKappa.

    Escape rate κ (1/time) from section data via the true-time-map relation
    Eq. (eqn:kappa_cmeasure_truetime),  ∫_Ω e^{κT} dμ_c = 1 + μ_c(𝓔).

    Input: a sample of M points on the Poincaré section distributed by the
    c-measure μ_c; ``return_times`` are the times T_i (time units) to the next
    section crossing of the points that return, ``n_exit`` the number of
    sample points that leave Ω before crossing again (the set 𝓔), so
    M = len(return_times) + n_exit.

    Estimator
    ---------
        (1/M) Σ_{i returns} e^{κ T_i} = 1,      κ > 0 its unique root,

    equivalently (1/M)[Σ_{returns} e^{κT_i} + Σ_{exits} e^{κ·0}] = 1 + n_exit/M,
    the sample version of Eq. (eqn:kappa_cmeasure_truetime) in which exiting
    points carry T = 0 (their exit times do not enter).

    Derivation.  In the asymptotic regime the flux of section crossings
    decays as the survival probability: crossings at y during [t, t + dt]
    occur at rate j(y, t) = e^{−κt} ρ(y), and μ_c (dμ_c = ρ dy / ∫ρ) is the
    distribution of crossing points, conditionally invariant under the flow.
    Every crossing at x ∉ 𝓔 at time t produces the crossing h(x) at time
    t + T(x); crossings at x ∈ 𝓔 produce none.  Conservation of crossings,
    j(y, t) = Σ_{h(x)=y} j(x, t − T(x)) |Dh(x)|⁻¹, integrated over y, gives
        ∫ρ = ∫_{Ω∖𝓔} ρ(x) e^{κT(x)} dx   ⇔   ∫_{Ω∖𝓔} e^{κT} dμ_c = 1,
    which is Eq. (eqn:kappa_cmeasure_truetime) once 𝓔 is included with T = 0
    (∫_𝓔 e^{0} dμ_c = μ_c(𝓔)).  Checks: for T ≡ 1 (a plain map) it gives
    e^κ (1 − μ_c(𝓔)) = 1, i.e. Eq. (eqn:kappa_cmeasure_discrete); for a renewal
    process (return with probability q after T ~ F, else exit) it is the
    Lotka equation q E_F[e^{κT}] = 1 of the exponential decay of P(t).
    Exit times are irrelevant provided they are short compared with 1/κ
    (light-tailed).

    Sampling.  The measure is the *flux* measure: take every section crossing
    of the ensemble that occurs in a late time window [t1, t2] (t1 ≫ τ0) as
    one sample point (see :func:`cmeasure_sample_from_sections`).  Taking
    instead the first crossing after t* of each survivor (sprinkler method)
    weights a point by 1 − e^{−κ T_back} (T_back: time since its previous
    crossing), which is harmless only when T_back and T are uncorrelated.

    Errors: ``kappa_err`` is the std of ``n_boot`` bootstrap replicates
    (``rng`` seed or Generator). With ``orbits`` (the orbit of each return
    time) and ``exit_orbits`` (the orbit of each exit point, ``n_exit`` of
    them) the bootstrap resamples *orbits*, the independent unit: one orbit
    gives several section crossings whose return times are correlated, and
    resampling crossings as if independent makes the error too small. Without
    them it resamples the M points (exits included), right only when every
    point comes from its own orbit. ``kappa_err_delta`` is the delta-method
    value √(Var(Y)/M) / mean(T Y), Y_i = e^{κT_i} (0 for exits), which also
    treats the points as independent.
    """
    T, n_exit, M = _checked_sample(return_times, n_exit)
    kappa = _solve_renewal(T, M)
    err_delta = _delta_method_error(T, M, kappa)
    gen = np.random.default_rng(rng)
    if orbits is not None or exit_orbits is not None:
        boot = _orbit_bootstrap(T, n_exit, orbits, exit_orbits, int(n_boot), gen)
    else:
        boot = _point_bootstrap(T, n_exit, M, int(n_boot), gen)
    err = float(np.std(boot, ddof=1)) if n_boot > 1 else math.nan
    return CMeasureKappa(
        kappa=float(kappa),
        kappa_err=err,
        kappa_err_delta=float(err_delta),
        mu_exit=n_exit / M,
        n_samples=M,
        n_exit=n_exit,
        boot=boot,
    )


# the steps of kappa_from_cmeasure
def _checked_sample(return_times, n_exit):
    """The checked c-measure sample: (return times T (time units), number of exits, sample size M)."""
    T = check.numbers(return_times, "return_times", min_size=0, positive=True)
    n_exit = check.count(n_exit, "n_exit", 0)
    M = T.size + n_exit
    if M == 0:
        raise ConfigError("empty sample")
    return T, n_exit, M


def _delta_method_error(T, M, kappa):
    """Delta-method error of κ (1/time): √(Var(Y)/M) / mean(T Y), Y_i = e^{κT_i} (0 for exits); NaN if κ = ∞."""
    if math.isfinite(kappa) and kappa > 0:
        Y = np.exp(kappa * T)
        var_Y = (float(np.sum(Y * Y)) / M) - (float(np.sum(Y)) / M) ** 2
        slope = float(np.sum(T * Y)) / M
        return math.sqrt(max(var_Y, 0.0) / M) / slope
    return math.nan if not math.isfinite(kappa) else 0.0


def _point_bootstrap(T, n_exit, M, n_boot, gen) -> np.ndarray:
    """κ replicates from resampling the M sample points (exits: a binomial count), as if each were its own orbit."""
    boot = np.empty(n_boot)
    for i in range(n_boot):
        ne = int(gen.binomial(M, n_exit / M))
        Tb = T[gen.integers(0, T.size, M - ne)] if T.size else T
        boot[i] = _solve_renewal(Tb, M)
    return boot


def _orbit_bootstrap(T, n_exit, orbits, exit_orbits, n_boot, gen) -> np.ndarray:
    """κ replicates from resampling orbits with replacement (each orbit brings all its sample points)."""
    orbits = np.asarray([] if orbits is None else orbits).ravel()
    exit_orbits = np.asarray([] if exit_orbits is None else exit_orbits).ravel()
    if orbits.size != T.size or exit_orbits.size != n_exit:
        raise ConfigError(
            f"orbits must give the orbit of each of the {T.size} return times and exit_orbits of "
            f"each of the {n_exit} exits, got {orbits.size} and {exit_orbits.size}"
        )
    ids, inv = np.unique(np.concatenate([orbits, exit_orbits]), return_inverse=True)
    of_T = inv[: T.size]
    points = np.bincount(inv, minlength=ids.size)  # sample points (returns and exits) per orbit
    boot = np.empty(n_boot)
    for i in range(n_boot):
        c = np.bincount(gen.integers(0, ids.size, ids.size), minlength=ids.size)
        boot[i] = _solve_renewal(T, float(c @ points), c[of_T].astype(float))
    return boot


def cmeasure_sample_from_sections(
    sections, lifetimes, t_from, t_to, *, t_record_end=math.inf, drop_censored: bool = False, with_orbits: bool = False
):
    """cmeasure_sample_from_sections(sections, lifetimes, t_from, t_to, *, t_record_end=inf, drop_censored=False, with_orbits=False) -> (return_times, n_exit, n_undetermined[, orbits, exit_orbits]).

    Builds the input of :func:`kappa_from_cmeasure` from the engine's tables
    (one conservative ensemble).  Every crossing in ``sections`` with
    t_from ≤ t ≤ t_to (time units) is a sample point of the flux c-measure;
    its return time is the time to the same orbit's next recorded crossing.
    A crossing with no later crossing is an *exit* if the orbit left
    ('escaped'/'settled') at t_end ≤ ``t_record_end`` (the end of the section
    recording, ``SectionWindow.t_to``), otherwise *undetermined* (censored, or
    a crossing after the recording may have been missed) and dropped — choose
    t_to well before min(t_record_end, t_max) so that this count is ~0.
    ``sections`` must hold every crossing (SectionWindow without energy
    filter and first_only=False) from t_from to t_record_end.

    ``drop_censored=True`` removes every orbit that is still inside at its
    t_end (outcome 'censored') before sampling.  With t_max ≫ t_record_end
    these are the orbits on KAM tori: they cross the section for ever, are
    not part of the c-measure of the chaotic saddle, and would bias κ low by
    their share of the late crossings.

    ``with_orbits=True`` also returns the orbit (``traj_id``) of each return
    time and of each exit, for the bootstrap over orbits of
    :func:`kappa_from_cmeasure`.
    """
    check.table(sections, "sections", ("traj_id", "t"), min_rows=0)
    check.table(lifetimes, "lifetimes", ("traj_id", "outcome", "t_end"), min_rows=0)
    check.real(t_from, "t_from")  # an empty window (t_from > t_to, or NaN) gives an empty sample
    check.real(t_to, "t_to")
    check.real(t_record_end, "t_record_end")
    if drop_censored:
        keep = lifetimes.loc[lifetimes["outcome"].astype(object) != "censored", "traj_id"]
        sections = sections[sections["traj_id"].isin(keep)]
    s = sections[["traj_id", "t"]].sort_values(["traj_id", "t"], kind="stable")
    nxt = s.groupby("traj_id", sort=False)["t"].shift(-1)
    s = s.assign(t_next=nxt.to_numpy())
    s = s[(s["t"] >= t_from) & (s["t"] <= t_to)]
    ret = s["t_next"].notna().to_numpy()
    T = (s["t_next"] - s["t"]).to_numpy()[ret]
    last = s.loc[~ret, ["traj_id"]]
    lt = lifetimes[["traj_id", "outcome", "t_end"]].copy()
    lt["outcome"] = lt["outcome"].astype(object)
    last = last.merge(lt, on="traj_id", how="left")
    if last["outcome"].isna().any():
        raise ConfigError("sections refer to traj_ids missing from lifetimes")
    leaves = last["outcome"].isin(["escaped", "settled"]).to_numpy() & (last["t_end"].to_numpy() <= t_record_end)
    n_exit = int(np.count_nonzero(leaves))
    n_und = int(leaves.size - n_exit)
    if n_und:
        warnings.warn(f"{n_und} sample crossings have an undetermined fate and were dropped", stacklevel=2)
    if with_orbits:
        return (T.astype(float), n_exit, n_und, s["traj_id"].to_numpy()[ret], last["traj_id"].to_numpy()[leaves])
    return T.astype(float), n_exit, n_und
