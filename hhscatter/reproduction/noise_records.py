"""The records of thermal and noisy escape: measured rates beside Kramers–Langer and the turnover theory.

:func:`rate_record` sets a thermal rate measured on a window (:func:`~hhscatter.analysis.noise.kramers.thermal_rate`)
beside the Kramers–Langer rate of the system at the same (γ, T), with the window's two halves compared;
:func:`turnover_record` adds the Mel'nikov–Meshkov/PGH rate and both Kramers limits, :func:`saddle_turnover_terms`
each saddle's part of them, :func:`shell_theory_record` the energy-diffusion rates of the well's energy shells,
:func:`turnover_theories_record` both at once and :func:`two_saddle_turnover_record` a series of them on a system with
several saddles, each saddle's terms beside; :func:`two_saddle_record` the
multi-saddle sum's lowest term and the escapes' exit shares against each term's share; :func:`saddle_terms` lists a
system's saddles; :func:`finite_barrier_record` fits the ratios against T/ΔE beside the transition-state
correction; :func:`absorbing_radius_record` compares a rate measured at two escape radii; :func:`no_drag_records`,
:func:`no_drag_survival` and :func:`survivor_record` give the rates, P(t) and the survivors' energies of noise
without drag; :func:`reactivation_record` the heat-bath P(t) against the drag-only one extended by re-activation.
Every value with an error is a :class:`~hhscatter.analysis.stats.measured.Measured` until it is written: flat as
``x`` and ``x_err`` in the rate records (their table's columns), ``{"value", "err"}`` elsewhere. Nothing here reads
a file. Units: rates in 1/time, times in time units, energies and temperatures in energy units.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from hhscatter.analysis.noise.energy_diffusion import is_separable, thermal_well_shells, well_energy_diffusion
from hhscatter.analysis.noise.finite_barrier import finite_barrier_fit, transition_state_correction
from hhscatter.analysis.noise.kramers import (
    exit_fractions,
    kramers_langer,
    thermal_rate,
    window_constancy,
)
from hhscatter.analysis.noise.reactivation import reactivation_check
from hhscatter.analysis.noise.survivors import noise_energy_gain, survivor_energies
from hhscatter.analysis.noise.turnover import barrier_action, turnover_rate
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.stats.verdicts import verdict
from hhscatter.analysis.survival.kaplan_meier import survival_curve
from hhscatter.analysis.survival.relative_rates import relative_rates

__all__ = [
    "absorbing_radius_record",
    "finite_barrier_record",
    "no_drag_records",
    "no_drag_survival",
    "pretty_potential",
    "rate_record",
    "rates_table",
    "reactivation_record",
    "saddle_terms",
    "saddle_turnover_terms",
    "shell_theory_record",
    "survivor_record",
    "theory_conventions",
    "turnover_record",
    "turnover_theories_record",
    "two_saddle_record",
    "two_saddle_turnover_record",
]


def _flat(name: str, m: Measured) -> dict:
    """A measured value as the two flat keys of a rate record: ``name`` and ``name_err``."""
    return {name: m.value, f"{name}_err": m.err}


def _halves(rate, z_max: float) -> dict:
    """The rates on a window's two halves and whether they agree within ``z_max`` σ (``halves_z``)."""
    c = window_constancy(rate, z_max)
    return {
        "rate_first_half": c.first.value,
        "rate_second_half": c.second.value,
        "rate_first_half_err": c.first.err,
        "rate_second_half_err": c.second.err,
        "halves_z": c.z,
        "constant_in_window": c.constant,
    }


def rate_record(
    t_end, escaped, model, gamma: float, temperature: float, window, *, n: int, r_esc: float, seed: int, z_max: float
) -> dict:
    """The thermal rate of one ensemble on ``window`` beside the Kramers–Langer rate of ``model`` at (γ, T).

    Parameters
    ----------
    t_end, escaped : array_like
        Each orbit's end time and whether it escaped (the rest are censored at their t_end).
    model : hhscatter.model.System
        The system (its saddles and Hessians give Kramers–Langer).
    gamma, temperature : float
        The drag γ (1/time) and the bath's T (energy).
    window : (float, float)
        [t_start, t_stop] of the rate (after the orbits have relaxed in the well).
    n, r_esc, seed : int, float, int
        The ensemble's size, escape radius and seed, kept in the record.
    z_max : float
        The window's two halves agree when |z| < z_max.

    Returns
    -------
    dict
        gamma, temperature, barrier_over_T, rate and rate_err, kramers_langer, ratio and ratio_err (rate over
        Kramers–Langer), n_events, n, window, the halves (``rate_first_half`` … ``halves_z``,
        ``constant_in_window``), r_esc, seed; a window without an escape has NaN rate and ratio and their one-sided
        95 % upper bounds ``rate_upper95``, ``ratio_upper95``.

    Examples
    --------
    Hénon–Heiles at γ = 1, ΔE/T = 3: 40 escapes at t = 10, 20, …, 400 and 60 orbits censored at 400; on [0, 400]
    the rate is 40 over the exposure 8200 + 24000, and its error the rate over √40:

    >>> from hhscatter.model import HenonHeiles
    >>> t = np.r_[np.arange(1, 41) * 10.0, np.full(60, 400.0)]
    >>> esc = np.r_[np.ones(40, bool), np.zeros(60, bool)]
    >>> r = rate_record(t, esc, HenonHeiles(), 1.0, 1 / 18, (0.0, 400.0), n=100, r_esc=1.5, seed=1, z_max=3.0)
    >>> r["rate"] == 40 / 32200, round(r["rate_err"] / r["rate"] * 40**0.5, 12), round(r["barrier_over_T"], 12)
    (True, 1.0, 3.0)
    >>> r["ratio"] == r["rate"] / r["kramers_langer"], r["n_events"], r["window"]
    (True, 40, [0.0, 400.0])
    """
    t_start, t_stop = (float(w) for w in window)
    r = thermal_rate(t_end, escaped, t_start, t_stop)
    kl = kramers_langer(model, gamma, temperature)
    rate = r.measured("rate")
    return {
        "gamma": gamma,
        "temperature": temperature,
        "barrier_over_T": kl.barrier_over_T,
        **_flat("rate", rate),
        "kramers_langer": kl.rate,
        **_flat("ratio", rate.over(kl.rate)),
        "n_events": r.n_events,
        "n": n,
        "window": [t_start, t_stop],
        # the rate is constant inside the window: the halves' difference in standard errors
        **_halves(r, z_max),
        "r_esc": r_esc,
        "seed": seed,
        # a window without an escape: no rate (NaN), its one-sided 95 % upper bound and the ratio's
        **({"rate_upper95": r.upper95, "ratio_upper95": r.upper95 / kl.rate} if r.is_bound else {}),
    }


def rates_table(series: dict) -> pd.DataFrame:
    """The rate records of every series as one table: ``series`` {name: list of rate records}; a row per record
    with its series' name under ``set``, the window's end as ``t_max`` (time) in place of the window, and
    without the nested per-saddle terms (``saddles``).

    Examples
    --------
    >>> r = {"gamma": 1.0, "rate": 0.01, "window": (23.0, 150.0), "saddles": [{"exit": 0}]}
    >>> t = rates_table({"kramers": [r], "turnover": [dict(r, gamma=0.1)]})
    >>> t[["set", "gamma", "t_max"]].to_dict("records")
    [{'set': 'kramers', 'gamma': 1.0, 't_max': 150.0}, {'set': 'turnover', 'gamma': 0.1, 't_max': 150.0}]
    >>> "saddles" in t.columns
    False
    """
    rows = [{"set": name, **{k: v for k, v in r.items() if k != "saddles"}} for name, rs in series.items() for r in rs]
    rates = pd.DataFrame(rows)
    rates["window"] = rates["window"].map(lambda w: float(w[1]))
    return rates.rename(columns={"window": "t_max"})


def turnover_record(record: dict, model, gamma_max: float) -> dict:
    """A :func:`rate_record` against the Mel'nikov–Meshkov/PGH rate Υ(δ) k_KL and the energy-diffusion limit.

    ``record``: the rate record (its gamma, temperature, rate and rate_err); ``model``: its system (δ = γS/T with
    S the action of the orbit at each saddle's energy through the well); ``gamma_max``: the theory assumes an
    underdamped barrier crossing, read where γ/ω_b ≤ gamma_max.

    Returns the action (energy·time) and δ, Υ of the lowest saddle, melnikov_meshkov and energy_diffusion (1/time),
    gamma_over_omega_b, theory_assumptions_hold, and the rate's ratios to both rates: ratio_mm, ratio_ed with
    their errors.

    Examples
    --------
    Hénon–Heiles at γ = 0.1, ΔE/T = 3: a rate equal to Υ k_KL ± 5 % has ratio_mm 1 ± 0.05; γ/ω_b = 0.1:

    >>> from hhscatter.model import HenonHeiles
    >>> from hhscatter.analysis.noise import kramers_langer, turnover_rate, barrier_action
    >>> m = HenonHeiles()
    >>> k = turnover_rate(kramers_langer(m, 0.1, 1 / 18), [barrier_action(m, i) for i in range(3)]).rate
    >>> t = turnover_record({"gamma": 0.1, "temperature": 1 / 18, "rate": k, "rate_err": 0.05 * k}, m, 0.3)
    >>> round(t["ratio_mm"], 12), round(t["ratio_mm_err"], 12), round(t["gamma_over_omega_b"], 9)
    (1.0, 0.05, 0.1)
    >>> t["theory_assumptions_hold"], turnover_record({**t, "gamma": 0.1, "temperature": 1 / 18, "rate": k,
    ...     "rate_err": 0.0}, m, 0.05)["theory_assumptions_hold"]
    (True, False)
    """
    kl = kramers_langer(model, record["gamma"], record["temperature"])
    tr = turnover_rate(kl, [barrier_action(model, k) for k in range(len(model.exits))])
    out = {
        "action": barrier_action(model, 0),
        "delta": tr.delta[0],
        "upsilon": tr.upsilon[0],
        "melnikov_meshkov": tr.rate,
        "energy_diffusion": tr.energy_diffusion,
        "gamma_over_omega_b": tr.gamma_over_omega_b,
        # within rounding: ω_b comes from an eigenvalue of the Hessian
        "theory_assumptions_hold": bool(tr.gamma_over_omega_b <= gamma_max * (1 + 1e-9)),
    }
    rate = Measured(record["rate"], record["rate_err"])
    for name, k in (("mm", tr.rate), ("ed", tr.energy_diffusion)):
        out.update(_flat(f"ratio_{name}", rate.over(k)))
    return out


def shell_theory_record(record: dict, ed) -> dict:
    """A :func:`rate_record` against the energy-diffusion theory of the well's energy shells (an
    :class:`~hhscatter.analysis.noise.energy_diffusion.EnergyDiffusion` at the record's γ and T): the shell-averaged
    δ, the rates (1/time) with the microcanonical flux above the barrier (``shell_energy_diffusion``), absorbing
    at the barrier (``shell_absorbing``), Υ(δ) k_KL on the shell δ (``shell_turnover``), the anharmonic
    transition-state rate, the shells' top energy, and the measured rate's ratios to the first three:
    ratio_shell, ratio_shell_absorbing, ratio_shell_turnover with their errors.

    Examples
    --------
    >>> from hhscatter.analysis.noise import EnergyDiffusion
    >>> ed = EnergyDiffusion(0.01, 0.05, rate=2e-3, rate_absorbing=4e-3, absorbing_limit=5e-3,
    ...                      transition_state=1e-2, delta=0.5, turnover=3e-3, phase_volume_barrier=0.6, top=0.8)
    >>> r = shell_theory_record({"rate": 2.2e-3, "rate_err": 1e-4}, ed)
    >>> round(r["ratio_shell"], 12), round(r["ratio_shell_err"], 12), round(r["ratio_shell_absorbing"], 12)
    (1.1, 0.05, 0.55)
    >>> r["shell_delta"], r["shell_top"]
    (0.5, 0.8)
    """
    rate = Measured(record["rate"], record["rate_err"])
    out = {
        "shell_delta": ed.delta,
        "shell_energy_diffusion": ed.rate,
        "shell_absorbing": ed.rate_absorbing,
        "shell_turnover": ed.turnover,
        "shell_transition_state": ed.transition_state,
        "shell_top": ed.top,
    }
    for name, k in (("shell", ed.rate), ("shell_absorbing", ed.rate_absorbing), ("shell_turnover", ed.turnover)):
        out.update(_flat(f"ratio_{name}", rate.over(k)))
    return out


def turnover_theories_record(
    record: dict, model, *, gamma_max: float, shell_top_widths: float, shell_grid: int, shell_energies: int
) -> dict:
    """A :func:`rate_record` against every turnover theory: :func:`turnover_record` (Mel'nikov–Meshkov/PGH and both
    Kramers limits, read where γ/ω_b ≤ ``gamma_max``) and :func:`shell_theory_record` (the energy-diffusion rates of
    ``model``'s well at the record's γ and T, on the shells up to E_b + ``shell_top_widths`` T of
    :func:`~hhscatter.analysis.noise.energy_diffusion.thermal_well_shells` on a ``shell_grid``² lattice and
    ``shell_energies`` energies, computed once per system and T).

    Examples
    --------
    Hénon–Heiles at γ = 0.01, ΔE/T = 3 (coarse shells): the rate over each theory, the keys of both records:

    >>> from hhscatter.model import HenonHeiles
    >>> rec = {"gamma": 0.01, "temperature": 1 / 18, "rate": 1e-3, "rate_err": 1e-4}
    >>> r = turnover_theories_record(rec, HenonHeiles(), gamma_max=0.3, shell_top_widths=6.0, shell_grid=201,
    ...                              shell_energies=401)
    >>> r["theory_assumptions_hold"], round(r["shell_top"], 6), round(r["ratio_shell"] * r["shell_energy_diffusion"], 9)
    (True, 0.5, 0.001)
    """
    shells = thermal_well_shells(
        model, record["temperature"], top_widths=shell_top_widths, grid=shell_grid, n_energies=shell_energies
    )
    ed = well_energy_diffusion(model, record["gamma"], record["temperature"], shells=shells)
    return {**turnover_record(record, model, gamma_max), **shell_theory_record(record, ed)}


def two_saddle_turnover_record(records: list[dict], model, *, barrier_over_T: float, potential: str) -> dict:
    """A turnover series of a system with several saddles: each record (of :func:`turnover_theories_record`) with
    its saddles' terms (:func:`saddle_turnover_terms`) under ``saddles``, beside the series' ΔE/T of the lowest
    saddle (``barrier_over_T``), the system's ``potential`` and whether it is separable
    (:func:`~hhscatter.analysis.noise.energy_diffusion.is_separable`: the drag then acts on the energy of each
    degree of freedom apart; None without records).

    Examples
    --------
    >>> from hhscatter.model import make_system
    >>> v = "(x**2 + y**2)/2 - x**3/3 - 5*y**3/18"
    >>> r = two_saddle_turnover_record([{"gamma": 0.1, "temperature": 1 / 18}], make_system(potential=v),
    ...                                barrier_over_T=3.0, potential=v)
    >>> r["separable"], len(r["records"][0]["saddles"]), r["barrier_over_T"]
    (True, 2, 3.0)
    """
    rows = [{**r, "saddles": saddle_turnover_terms(model, r["gamma"], r["temperature"])} for r in records]
    return {
        "barrier_over_T": barrier_over_T,
        "potential": potential,
        "separable": is_separable(model) if rows else None,
        "records": rows,
    }


def theory_conventions(
    *,
    gamma_max: float,
    energy_diffusion_gamma_max: float,
    shell_top_widths: float,
    shell_grid: int,
    shell_energies: int,
) -> dict:
    """The conventions of the turnover theories, as published beside the records: the theories in words, the
    range of Mel'nikov–Meshkov/PGH (γ/ω_b ≤ ``gamma_max``), the γ up to which the shells' energy-diffusion
    theories are read (``energy_diffusion_gamma_max``, 1/time) and the shells' settings
    (:func:`turnover_theories_record`).

    Examples
    --------
    >>> c = theory_conventions(gamma_max=0.3, energy_diffusion_gamma_max=0.01, shell_top_widths=12.0,
    ...                        shell_grid=1201, shell_energies=4001)
    >>> c["theory_range"], c["shell_grid"], "E_b + 12 T" in c["shell_theory"]
    ('γ/ω_b ≤ 0.3', 1201, True)
    """
    return {
        "turnover_theory": "Mel'nikov–Meshkov/PGH k = Υ(δ) k_KL, δ = γS/T, S the action of the orbit at "
        "the saddle's energy through the well; energy diffusion k_ED = δ k_TST",
        "theory_range": f"γ/ω_b ≤ {gamma_max:g}",
        "shell_theory": "energy diffusion on the well's energy shells (two degrees of freedom, ergodic): "
        "D(E) = γT⟨|p|²⟩_E, the lowest rate of the Fokker–Planck equation in E with the shells' phase "
        "volume, absorbing at E_b or with the microcanonical flux over the saddles' dividing lines above "
        f"it (shells up to E_b + {shell_top_widths:g} T); δ_shell = its absorbing large-barrier rate over "
        "the shells' transition-state rate",
        "energy_diffusion_gamma_max": energy_diffusion_gamma_max,
        "shell_top_widths": shell_top_widths,
        "shell_grid": shell_grid,
        "shell_energies": shell_energies,
    }


def saddle_turnover_terms(model, gamma: float, temperature: float) -> list[dict]:
    """Each saddle's part of the turnover theory at (γ, T) (1/time for the rates): its exit, barrier (energy) and
    ω_b (1/time), the action S (energy·time) of the orbit at its energy through the well
    (:func:`~hhscatter.analysis.noise.turnover.barrier_action`), δ = γS/T and Υ(δ), its Kramers–Langer term
    k_KL,s, its Mel'nikov–Meshkov/PGH term Υ(δ) k_KL,s and its energy-diffusion term δ k_TST,s; the terms of all
    saddles sum to the rates of :func:`turnover_record`.

    Examples
    --------
    Hénon–Heiles' three equal saddles at γ = 0.1, ΔE/T = 3: S = 6/5, δ = 0.1 · 1.2 · 18 = 2.16, each term a third:

    >>> from hhscatter.model import HenonHeiles
    >>> s = saddle_turnover_terms(HenonHeiles(), 0.1, 1 / 18)
    >>> len(s), round(s[0]["action"], 10), round(s[0]["delta"], 10), round(s[0]["upsilon"], 4)
    (3, 1.2, 2.16, 0.6634)
    >>> t = turnover_record({"gamma": 0.1, "temperature": 1 / 18, "rate": 1.0, "rate_err": 0.1}, HenonHeiles(), 0.3)
    >>> bool(abs(sum(x["melnikov_meshkov"] for x in s) - t["melnikov_meshkov"]) < 1e-15)
    True
    """
    kl = kramers_langer(model, gamma, temperature)
    actions = [barrier_action(model, k) for k in range(len(model.exits))]
    tr = turnover_rate(kl, actions)
    return [
        {
            "exit": i,
            "barrier": t.barrier,
            "omega_b": t.omega_b,
            "action": a,
            "delta": d,
            "upsilon": u,
            "kramers_langer": t.rate,
            "melnikov_meshkov": u * t.rate,
            "energy_diffusion": d * t.omega_b / t.lambda_plus * t.rate,
        }
        for i, (t, a, d, u) in enumerate(zip(kl.terms, actions, tr.delta, tr.upsilon))
    ]


def two_saddle_record(record: dict, exit_channel, t_end, escaped, model) -> dict:
    """A :func:`rate_record` of a system with several saddles against the lowest saddle's Kramers–Langer term
    alone, and the share of the escapes in its window over each saddle against that term's share of the sum.

    ``record``: the rate record; ``exit_channel``, ``t_end``, ``escaped``: each orbit's exit (the index of the
    system's exit), end time and whether it escaped; ``model``: the system. Adds kramers_langer_lowest,
    ratio_lowest and its error, and exit_shares (per exit: its barrier, the predicted share, the measured one with
    its error or one-sided 95 % bound, the verdict by the 2σ rule and z).

    Examples
    --------
    Hénon–Heiles' three equal saddles at ΔE/T = 3: each term is a third of the sum; 30, 30 and 40 escapes:

    >>> from hhscatter.model import HenonHeiles
    >>> m = HenonHeiles()
    >>> t = np.linspace(1.0, 100.0, 100)
    >>> ch = np.r_[np.zeros(30, int), np.ones(30, int), np.full(40, 2)]
    >>> rec = {"gamma": 1.0, "temperature": 1 / 18, "rate": 0.03, "rate_err": 0.003, "window": [0.0, 100.0]}
    >>> s = two_saddle_record(rec, ch, t, np.ones(100, bool), m)
    >>> [round(x["predicted"], 12) for x in s["exit_shares"]], [x["measured"] for x in s["exit_shares"]]
    ([0.333333333333, 0.333333333333, 0.333333333333], [0.3, 0.3, 0.4])
    >>> s["ratio_lowest"] == 0.03 / s["kramers_langer_lowest"], s["exit_shares"][2]["verdict"]
    (True, 'agrees (z = +1.4)')
    """
    kl = kramers_langer(model, record["gamma"], record["temperature"])
    low = min(range(len(kl.terms)), key=lambda i: kl.terms[i].barrier)
    k_low = kl.terms[low].rate
    out = dict(record)
    out["kramers_langer_lowest"] = k_low
    out.update(_flat("ratio_lowest", Measured(record["rate"], record["rate_err"]).over(k_low)))
    lo, hi = record["window"]
    shares = []
    for i, (term, f) in enumerate(zip(kl.terms, exit_fractions(t_end, escaped, exit_channel, lo, hi, len(kl.terms)))):
        pred = term.rate / kl.rate
        v = verdict(f.value, f.err, pred)
        shares.append(
            {
                "exit": i,
                "barrier": term.barrier,
                "predicted": pred,
                "measured": f.value,
                "measured_err": f.err,
                "measured_upper95": f.upper,
                "measured_lower95": f.lower,
                "verdict": v.text(),
                "z": v.z,
            }
        )
    out["exit_shares"] = shares
    return out


def saddle_terms(model, gamma: float, temperature: float) -> list[dict]:
    """The saddles of ``model`` with their Kramers–Langer terms at (γ, T): x, y, barrier (energy), ω_b (1/time) and
    the prefactor (1/time).

    Examples
    --------
    >>> from hhscatter.model import HenonHeiles
    >>> s = saddle_terms(HenonHeiles(), 1.0, 1 / 18)
    >>> len(s), round(s[0]["barrier"], 12), round(s[0]["omega_b"], 9)
    (3, 0.166666666667, 1.0)
    """
    kl = kramers_langer(model, gamma, temperature)
    return [
        {"x": t.x, "y": t.y, "barrier": t.barrier, "omega_b": t.omega_b, "prefactor": t.prefactor} for t in kl.terms
    ]


def pretty_potential(expr: str) -> str:
    """A potential's text as pages print it: integer powers as superscripts, no ``*``, the minus sign.

    Examples
    --------
    >>> pretty_potential("(x**2 + y**2)/2 - 5*y**3/18")
    '(x² + y²)/2 − 5y³/18'
    """
    sup = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")
    out = re.sub(r"\*\*(\d+)", lambda m: m.group(1).translate(sup), expr)
    return out.replace("*", "").replace("-", "−")


def finite_barrier_record(kramers: list[dict], model) -> dict:
    """The ratios k/k_KL of :func:`rate_record` s against T/ΔE: the weighted fit of their first correction (with
    and without the intercept fixed at 1) beside the transition-state correction of ``model``.

    Examples
    --------
    Ratios 1 + 0.5 T/ΔE at ΔE/T = 2, 4, 8 (a straight line): intercept 1, slope 0.5, χ² 0:

    >>> from hhscatter.model import HenonHeiles
    >>> rows = [{"barrier_over_T": b, "ratio": 1 + 0.5 / b, "ratio_err": 0.01} for b in (2.0, 4.0, 8.0)]
    >>> f = finite_barrier_record(rows, HenonHeiles())
    >>> round(f["intercept"]["value"], 9), round(f["slope"]["value"], 9), round(f["chi2"], 12)
    (1.0, 0.5, 0.0)
    >>> f["T_over_barrier_range"]
    [0.125, 0.5]
    """
    f = finite_barrier_fit(
        [r["barrier_over_T"] for r in kramers], [r["ratio"] for r in kramers], [r["ratio_err"] for r in kramers]
    )
    c = transition_state_correction(model)
    return {
        "intercept": f.measured("intercept").to_dict(),
        "slope": f.measured("slope").to_dict(),
        "chi2": f.chi2,
        "dof": f.dof,
        "p_value": f.p_value,
        "slope_intercept_one": f.measured("slope_unit").to_dict(),
        "chi2_intercept_one": f.chi2_unit,
        "dof_intercept_one": f.dof_unit,
        "T_over_barrier_range": list(f.x_range),
        "transition_state_slope": c.slope,
        "laplace_well": c.well,
        "laplace_saddles": list(c.saddles),
        "fit": "k/k_KL = a + c T/ΔE, weights 1/σ² of the ratios; and k/k_KL − 1 = c T/ΔE (a = 1)",
        "theory": "c_TST = ΔE (A_s − A_well): the first correction of k_TST from Laplace's expansion of the well's "
        "and the dividing line's configuration integrals; the transmission factor's own correction is not included",
    }


def absorbing_radius_record(near: dict, far: dict) -> dict:
    """One rate measured at two escape radii (independent ensembles): :func:`rate_record` s ``near`` (the default
    radius) and ``far``; their ratio, its shift from 1 and the verdict of "the same rate" by the 2σ rule.

    Examples
    --------
    Rates 0.012 ± 0.0009 and 0.010 ± 0.0008: ratio 1.2 with σ = 1.2 √(0.075² + 0.08²) = 0.1316, z = 1.52:

    >>> near = {"rate": 0.010, "rate_err": 0.0008, "r_esc": 1.5}
    >>> far = {"barrier_over_T": 3.0, "rate": 0.012, "rate_err": 0.0009, "ratio": 0.9, "ratio_err": 0.07,
    ...        "r_esc": 3.0, "n_events": 500, "window": [23.0, 150.0], "constant_in_window": True, "seed": 7}
    >>> a = absorbing_radius_record(near, far)
    >>> round(a["rate_ratio"]["value"], 12), round(a["rate_ratio"]["err"], 4), round(a["shift"]["value"], 12)
    (1.2, 0.1316, 0.2)
    >>> a["verdict"], a["rate_default"]
    ('agrees (z = +1.5)', {'value': 0.01, 'err': 0.0008})
    """
    rate_near, rate_far = Measured(near["rate"], near["rate_err"]), Measured(far["rate"], far["rate_err"])
    ratio = rate_far / rate_near
    v = verdict(ratio.value, ratio.err, 1.0)
    return {
        "barrier_over_T": far["barrier_over_T"],
        "r_esc_default": near["r_esc"],
        "r_esc": far["r_esc"],
        "rate_default": rate_near.to_dict(),
        "rate": rate_far.to_dict(),
        "ratio_kramers_langer": Measured(far["ratio"], far["ratio_err"]).to_dict(),
        "rate_ratio": ratio.to_dict(),
        "shift": Measured(ratio.value - 1.0, ratio.err).to_dict(),
        "verdict": v.text(),
        "z": v.z,
        "n_events": far["n_events"],
        "window": far["window"],
        "constant_in_window": far["constant_in_window"],
        "seed": far["seed"],
    }


def survivor_record(energy: float, sigma: float, t: float, alive, e_end, threshold: float) -> dict:
    """The energies of the orbits of a no-drag noisy ensemble (start energy ``energy``, noise ``sigma``) still
    inside at ``t``: ``alive`` marks them, ``e_end`` holds every orbit's energy at t; their mean, spread, quantiles
    and the fraction below ``threshold`` (with at least two survivors), beside ⟨E⟩ of the whole ensemble, E0 + σ² t.

    Examples
    --------
    Four orbits, two alive with energies 0.2 and 0.3; threshold 0.25:

    >>> s = survivor_record(0.25, 0.1, 10.0, np.array([True, False, True, False]), np.array([0.2, 9, 0.3, 9]), 0.25)
    >>> s["n"], s["n_alive"], round(s["ensemble_mean_energy"], 12), round(s["mean_energy"], 12), s["below_ec"]
    (4, 2, 0.35, 0.25, 0.5)
    """
    alive = np.asarray(alive, dtype=bool)
    row = {"energy": energy, "sigma": sigma, "t": t, "n": int(alive.size), "n_alive": int(alive.sum())}
    # ⟨E⟩ of the whole ensemble, were every orbit kept: E0 + σ² t (two momenta)
    row["ensemble_mean_energy"] = energy + noise_energy_gain(sigma, t)
    if alive.sum() >= 2:
        se = survivor_energies(np.asarray(e_end)[alive], threshold)
        row.update(
            mean_energy=se.mean,
            mean_energy_err=se.mean_err,
            sd_energy=se.sd,
            energy_q10=se.quantiles[0.1],
            energy_q50=se.quantiles[0.5],
            energy_q90=se.quantiles[0.9],
            below_ec=se.below,
            below_ec_err=se.below_err,
            below_ec_upper95=se.below_upper,
            below_ec_lower95=se.below_lower,
        )
    return row


def no_drag_records(energy: float, sigmas, samples, window, z_max: float) -> list[dict]:
    """The escape rates of no-drag ensembles at one start energy, one per noise strength σ of ``sigmas``
    (``samples``: their (t_end, escaped) arrays), on ``window``: κ with its error, the halves of the window
    compared within ``z_max`` σ, and, when σ = 0 is among them, κ/κ0 and the energy gained by diffusion by the
    window's end (σ² t).

    Examples
    --------
    Two ensembles of 100 orbits, all escaped at t = 10 … 1000 and at t = 5 … 500: κ = 100/Σt, the second twice the
    first:

    >>> t = np.arange(1, 101) * 10.0
    >>> rows = no_drag_records(0.3, [0.0, 0.01], [(t, np.ones(100, bool)), (t / 2, np.ones(100, bool))], (0, 2e3), 3)
    >>> bool(rows[0]["kappa"] == 100 / t.sum()), rows[1]["kappa_over_kappa0"], rows[1]["energy_gain_at_window_end"]
    (True, 2.0, 0.2)
    """
    lo, hi = window
    sigmas = list(sigmas)
    ref = sigmas.index(0) if 0 in sigmas else None
    rows = []
    for s, rr, (t_end, esc) in zip(sigmas, relative_rates(samples, lo, hi, ref), samples):
        m = rr.rate
        row = {"energy": energy, "sigma": s, "kappa": m.kappa, "kappa_err": m.kappa_err, "n_events": m.n_events}
        row.update(_halves(thermal_rate(t_end, esc, lo, hi), z_max))
        if rr.ratio is not None:
            row.update(_flat("kappa_over_kappa0", rr.ratio))
            # energy gained by diffusion over the window: ⟨E⟩ grows by σ² t (two degrees of freedom)
            row["energy_gain_at_window_end"] = noise_energy_gain(s, hi)
        rows.append(row)
    return rows


def no_drag_survival(energy: float, sigma: float, t_end, escaped, grid) -> pd.DataFrame:
    """P(t) ± its error (Kaplan–Meier) of one no-drag ensemble on ``grid`` (time units), with its energy and σ.

    Examples
    --------
    >>> f = no_drag_survival(0.3, 0.0, np.array([1.0, 2.0, 3.0, 4.0]), np.ones(4, bool), np.array([0.0, 2.5]))
    >>> f["P"].round(12).tolist(), list(f.columns)
    ([1.0, 0.5], ['energy', 'sigma', 't', 'P', 'P_err'])
    """
    c = survival_curve(t_end, escaped, grid)
    return pd.DataFrame({"energy": energy, "sigma": sigma, "t": grid, "P": c.P, "P_err": c.P_err})


def reactivation_record(drag_only, bath, well, *, t_max: float, tail_start: float, window_start: float, about: dict):
    """The heat-bath P(t) against the drag-only one extended by re-activation, and their numbers.

    ``drag_only``: (t_end, escaped, settled) of the ensemble without temperature; ``bath``: (t_end, escaped) of
    the same ensemble in the bath; ``well``: (t_end, escaped) of orbits started in the well at the same (γ, T),
    whose thermal rate on [window_start, t_max] re-activates the settled orbits; ``tail_start``: the start of the
    bath P(t)'s tail window; ``about``: the ensemble's description (energy, gamma, temperature, barrier_over_T, n),
    written first. Returns (numbers, table): the tail's rate over the thermal rate, the settled and escaped
    fractions without temperature, the model's largest deviation; the table is P(t) of both and the prediction
    (:func:`~hhscatter.analysis.noise.reactivation.reactivation_check`).

    Examples
    --------
    Orbits that settle at τ ~ U(0, 10) and leave the well at rate 0.05 in the bath; orbits started in the well
    leave at the same rate: the tail's rate over the thermal rate is 1 within its error.

    >>> rng = np.random.default_rng(0)
    >>> tau = rng.uniform(0, 10, 4000)
    >>> t_bath, t_well = tau + rng.exponential(20.0, tau.size), rng.exponential(20.0, tau.size)
    >>> numbers, table = reactivation_record(
    ...     (tau, np.zeros(tau.size, bool), np.ones(tau.size, bool)),
    ...     (np.minimum(t_bath, 200.0), t_bath < 200.0),
    ...     (np.minimum(t_well, 200.0), t_well < 200.0),
    ...     t_max=200.0, tail_start=20.0, window_start=0.0, about={"n": 4000})
    >>> numbers["n"], numbers["settled_fraction_T0"], numbers["tail_window"]
    (4000, 1.0, [20.0, 200.0])
    >>> r = numbers["tail_over_thermal"]
    >>> abs(r["value"] - 1) < 3 * r["err"]
    True
    """
    k_well = thermal_rate(*well, window_start, t_max)
    c = reactivation_check(*drag_only, *bath, k_well.rate, t_max, tail_start)
    numbers = {
        **about,
        "settled_fraction_T0": c.settled_fraction,
        "escaped_fraction_T0": c.escaped_fraction,
        "t_settled_99": c.t_settled_99,
        "tail_window": [tail_start, t_max],
        "tail_rate": c.tail.measured("rate").to_dict(),
        "thermal_rate": k_well.measured("rate").to_dict(),
        "tail_over_thermal": (c.tail.measured("rate") / k_well.measured("rate")).to_dict(),
        "model_max_deviation": c.max_deviation,
        "model_max_deviation_at": c.max_deviation_at,
        "model_max_deviation_sigma": c.max_deviation_sigma,
    }
    return numbers, c.table
