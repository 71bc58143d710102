"""Study noise — thermal and noisy scattering in Hénon–Heiles (beyond the paper).

Stages (``hhscatter study noise simulate|analyze|plot [--scale S]``):

``simulate(study, workers=None, progress=True)``
    Engine runs with a scene ``[noise]`` (:class:`hhscatter.scene.scene.Noise`; the noise scheduler of
    :mod:`hhscatter.integrate.noise`), orbits uniform in the disk r < radius, r_esc = 1.5:

    * ``kramers_b<b>``: γ = gamma_kramers, T = ΔE/b for each barrier b of ``barriers``, orbits started in the
      well at E0 = well_energy < E_c, t_max from ``kramers_t_max``;
    * ``turnover_g<γ>``: T = ΔE/turnover_barrier for each γ of ``turnover_gammas``;
    * ``react_T0`` and ``react_T``: the paper's dissipative ensemble (E0 = react_energy, γ = react_gamma) without
      and with the heat bath T = ΔE/react_barrier; ``react_well``: the thermal rate at that (γ, T) from the well;
    * ``nodrag_E<E>_s<σ>``: γ = 0, noise strength σ (σ = 0: the conservative κ0) at each E0 of nodrag_energies.

``analyze(study)``
    Rates by the constant-hazard MLE on [t_relax + relax_widths/γ, t_max] (after relaxation;
    :func:`hhscatter.analysis.noise.thermal_rate`, left-truncated and right-censored; the window's two halves
    compared: ``halves_z``, ``constant_in_window``) against Kramers–Langer (:func:`hhscatter.analysis.noise.kramers_langer`,
    saddles and Hessians from the system); P(t) of the heat-bath ensemble against the drag-only one extended
    by re-activation (:func:`hhscatter.analysis.noise.reactivation_survival`); the no-drag rates on
    ``nodrag_window`` against κ0; each turnover rate against the Mel'nikov–Meshkov/Pollak–Grabert–Hänggi rate
    Υ(δ) k_KL (:func:`hhscatter.analysis.noise.turnover_rate`, δ = γS/T with S the action of the orbit at the
    saddle's energy through the well, :func:`hhscatter.analysis.noise.barrier_action`) and both Kramers limits,
    the theory's range stated as γ/ω_b ≤ THEORY_GAMMA_MAX. Writes ``noise.json`` (keys ``kramers``,
    ``turnover``, ``reactivation``, ``no_drag``) and the derived tables ``rates.parquet``, ``survival.parquet``.

``plot(study)``
    ``noise.png`` via ``plot_noise`` of the folder's ``figure.py``.
"""

from __future__ import annotations

import math
import zlib

import numpy as np
import pandas as pd

from hhscatter.scene.schema import Integer, Number, Numbers, Text
from hhscatter.studies.keys import RunKeys, number_key
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, SCALE, figure_stage

#: the turnover theory (Mel'nikov–Meshkov/PGH) assumes an underdamped barrier crossing: its ratios are read where
#: γ/ω_b ≤ this (ω_b the saddles' unstable frequency)
THEORY_GAMMA_MAX = 0.3


class Params(StudyParams):
    """``[study]`` of studies/noise/study.toml."""

    well_energy: Number  # E0 of the orbits started in the well
    t_relax: Number  # the rate window opens at t_relax + relax_widths/γ
    relax_widths: Number  # relaxation times 1/γ waited before the rate window opens
    constancy_z: Number  # the two halves of a rate window agree when |k₂ − k₁| < constancy_z σ
    flow: Text  # the noise flow between kicks: "taylor" or "symplectic" (hhscatter.scene.noise.Noise)
    gamma_kramers: Number
    barriers: Numbers  # ΔE/T
    kramers_t_max: Numbers
    turnover_barrier: Number
    turnover_gammas: Numbers
    turnover_t_max: Numbers
    turnover_n: Integer
    react_energy: Number
    react_gamma: Number
    react_barrier: Number
    react_n: Integer
    react_t_max: Number
    react_tail_start: Number  # start of the tail window of P_T(t)
    nodrag_energies: Numbers
    nodrag_sigmas: Numbers
    nodrag_n: Integer
    nodrag_t_max: Number
    nodrag_window: Numbers


def _barrier(study) -> float:
    """ΔE = E_c − V(min) of the system (energy units): the lowest saddle above the well's minimum."""
    m = study.model
    return m.critical_energy - float(m.potential(np.array(0.0), np.array(0.0)))


def _pairs(study, a, b):
    p = study.params
    xs, ys = getattr(p, a), getattr(p, b)
    if len(xs) != len(ys):
        raise ValueError(f"[study] {a} and {b} must have the same length, got {len(xs)} and {len(ys)}")
    return list(zip(xs, ys))


def _kramers_key(b) -> str:
    return f"kramers_b{number_key(b, 'g')}"


def _turnover_key(g) -> str:
    return f"turnover_g{number_key(g, 'g')}"


def _nodrag_key(E, s) -> str:
    return f"nodrag_E{number_key(E, '.2f')}_s{number_key(s, 'g')}"


def _record_seed(seed: int, key: str) -> int:
    """The seed of the rate record ``key``: derived from the study's seed and the key, so that no two records share
    initial conditions or noise streams."""
    return int(np.random.SeedSequence([int(seed), zlib.crc32(key.encode())]).generate_state(1)[0])


def _window_start(p, gamma: float) -> float:
    """The rate window's start (time units): t_relax + relax_widths/γ, after the start's relaxation."""
    return p.t_relax + p.relax_widths / gamma


def _runs(study):
    """{key: scene} of every raw run (module docstring); each key names one run (:class:`RunKeys`). The Kramers
    and turnover records each have their own seed (:func:`_record_seed`)."""
    p, dE = study.params, _barrier(study)
    runs = RunKeys()
    for b, t_max in _pairs(study, "barriers", "kramers_t_max"):
        runs[_kramers_key(b)] = dict(
            energy=p.well_energy, gamma=p.gamma_kramers, t_max=t_max, noise={"temperature": dE / b, "flow": p.flow}
        )
    for g, t_max in _pairs(study, "turnover_gammas", "turnover_t_max"):
        runs[_turnover_key(g)] = dict(
            energy=p.well_energy,
            gamma=g,
            t_max=t_max,
            n=p.turnover_n,
            noise={"temperature": dE / p.turnover_barrier, "flow": p.flow},
        )
    react = dict(energy=p.react_energy, gamma=p.react_gamma, t_max=p.react_t_max, n=p.react_n)
    runs["react_T0"] = react
    bath = {"temperature": dE / p.react_barrier, "flow": p.flow}
    runs["react_T"] = dict(react, noise=bath)
    runs["react_well"] = dict(react, energy=p.well_energy, noise=bath)
    for E in p.nodrag_energies:
        for s in p.nodrag_sigmas:
            runs[_nodrag_key(E, s)] = dict(
                energy=E,
                gamma=0.0,
                t_max=p.nodrag_t_max,
                n=p.nodrag_n,
                noise={"sigma": s, "flow": p.flow} if s > 0 else None,
            )
    scenes = {k: study.scene(k, **kw) for k, kw in runs.items()}
    for k, sc in scenes.items():
        if k.startswith(("kramers_", "turnover_")):
            scenes[k] = sc.replace(seed=_record_seed(sc.seed, k))
    return scenes


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None, progress=True) -> None: every raw run of :func:`_runs`."""
    for key, scene in _runs(study).items():
        study.run(key, scene, workers=workers, progress=progress)


# -- analyze ----------------------------------------------------------------
def _lifetimes(study, key):
    """(t_end, escaped, settled) arrays of raw run ``key``, in orbit order."""
    from hhscatter.data.read import read_by_orbit

    c = read_by_orbit(study.raw(key), ["outcome", "t_end"])
    o = np.asarray(c["outcome"].astype(str))
    return c["t_end"], o == "escaped", o == "settled"


def _rate_row(study, key, scene):
    from hhscatter.analysis.noise import kramers_langer, thermal_rate

    p = study.params
    t_start = _window_start(p, scene.gamma)
    t_end, escaped, _ = _lifetimes(study, key)
    r = thermal_rate(t_end, escaped, t_start, scene.t_max)
    (k1, e1), (k2, e2) = r.halves
    z = (k2 - k1) / math.hypot(e1, e2) if e1 > 0 and e2 > 0 else math.nan
    T = scene.noise.temperature
    kl = kramers_langer(scene.model, scene.gamma, T)
    return {
        "gamma": scene.gamma,
        "temperature": T,
        "barrier_over_T": kl.barrier_over_T,
        "rate": r.rate,
        "rate_err": r.rate_err,
        "kramers_langer": kl.rate,
        "ratio": r.rate / kl.rate,
        "ratio_err": r.rate_err / kl.rate,
        "n_events": r.n_events,
        "n": scene.n,
        "window": [t_start, scene.t_max],
        "rate_first_half": r.halves[0][0],
        "rate_second_half": r.halves[1][0],
        "rate_first_half_err": e1,
        "rate_second_half_err": e2,
        # the rate is constant inside the window: the halves' difference in standard errors
        "halves_z": z,
        "constant_in_window": bool(abs(z) < p.constancy_z),
        "seed": scene.seed,
        # a window without an escape: no rate (NaN), its one-sided 95 % upper bound and the ratio's
        **({"rate_upper95": r.upper95, "ratio_upper95": r.upper95 / kl.rate} if r.is_bound else {}),
    }


def _turnover_theory(study, row, scene) -> dict:
    """The turnover record ``row`` against Mel'nikov–Meshkov/PGH and both Kramers limits (module docstring)."""
    from hhscatter.analysis.noise import barrier_action, kramers_langer, turnover_rate

    m = scene.model
    kl = kramers_langer(m, scene.gamma, row["temperature"])
    tr = turnover_rate(kl, [barrier_action(m, k) for k in range(len(m.exits))])
    out = {
        "action": barrier_action(m, 0),
        "delta": tr.delta[0],
        "upsilon": tr.upsilon[0],
        "melnikov_meshkov": tr.rate,
        "energy_diffusion": tr.energy_diffusion,
        "gamma_over_omega_b": tr.gamma_over_omega_b,
        # within rounding: ω_b comes from an eigenvalue of the Hessian
        "theory_assumptions_hold": bool(tr.gamma_over_omega_b <= THEORY_GAMMA_MAX * (1 + 1e-9)),
    }
    for name, k in (("mm", tr.rate), ("ed", tr.energy_diffusion)):
        out[f"ratio_{name}"] = row["rate"] / k
        out[f"ratio_{name}_err"] = row["rate_err"] / k
    return out


def _reactivation(study, runs):
    """P(t) with and without the heat bath, the extension's prediction, and their numbers."""
    from hhscatter.analysis.noise import reactivation_check, thermal_rate

    p = study.params
    t0, esc0, set0 = _lifetimes(study, "react_T0")
    tT, escT, _ = _lifetimes(study, "react_T")
    tw, escw, _ = _lifetimes(study, "react_well")
    sc = runs["react_T"]
    k_well = thermal_rate(tw, escw, _window_start(p, sc.gamma), sc.t_max)
    try:
        c = reactivation_check(t0, esc0, set0, tT, escT, k_well.rate, sc.t_max, p.react_tail_start)
    except ValueError as e:
        raise ValueError(f"[study] react_tail_start: {e}") from None
    numbers = {
        "energy": p.react_energy,
        "gamma": sc.gamma,
        "temperature": sc.noise.temperature,
        "barrier_over_T": p.react_barrier,
        "n": sc.n,
        "settled_fraction_T0": c.settled_fraction,
        "escaped_fraction_T0": c.escaped_fraction,
        "t_settled_99": c.t_settled_99,
        "tail_window": [p.react_tail_start, sc.t_max],
        "tail_rate": c.tail.measured("rate").to_dict(),
        "thermal_rate": k_well.measured("rate").to_dict(),
        "tail_over_thermal": (c.tail.measured("rate") / k_well.measured("rate")).to_dict(),
        "model_max_deviation": c.max_deviation,
        "model_max_deviation_at": c.max_deviation_at,
        "model_max_deviation_sigma": c.max_deviation_sigma,
    }
    return numbers, c.table


def _no_drag(study, runs):
    from hhscatter.analysis.survival.relative_rates import relative_rates

    p = study.params
    lo, hi = p.nodrag_window
    sigmas = list(p.nodrag_sigmas)
    ref = sigmas.index(0) if 0 in sigmas else None
    rows = []
    for E in p.nodrag_energies:
        samples = [_lifetimes(study, _nodrag_key(E, s))[:2] for s in sigmas]
        for s, rr in zip(sigmas, relative_rates(samples, lo, hi, ref)):
            m = rr.rate
            row = {"energy": E, "sigma": s, "kappa": m.kappa, "kappa_err": m.kappa_err, "n_events": m.n_events}
            if rr.ratio is not None:
                row["kappa_over_kappa0"], row["kappa_over_kappa0_err"] = rr.ratio.value, rr.ratio.err
                # energy gained by diffusion over the window: ⟨E⟩ grows by σ² t (two degrees of freedom)
                row["energy_gain_at_window_end"] = s * s * hi
            rows.append(row)
    return rows


def _survival_tables(study, runs):
    """P(t) of every no-drag run on a common grid (the figure's panel)."""
    from hhscatter.analysis.survival.kaplan_meier import survival_curve

    p = study.params
    grid = np.linspace(0.0, p.nodrag_t_max, 301)
    frames = []
    for E in p.nodrag_energies:
        for s in p.nodrag_sigmas:
            t_end, esc, _ = _lifetimes(study, _nodrag_key(E, s))
            c = survival_curve(t_end, esc, grid)
            frames.append(pd.DataFrame({"energy": E, "sigma": s, "t": grid, "P": c.P, "P_err": c.P_err}))
    return pd.concat(frames, ignore_index=True)


def analyze(study):
    """analyze(study) -> None: rates against Kramers–Langer, the heat-bath P(t), the no-drag rates; noise.json."""
    p = study.params
    runs = _runs(study)
    kramers = [
        _rate_row(study, _kramers_key(b), runs[_kramers_key(b)]) for b, _ in _pairs(study, "barriers", "kramers_t_max")
    ]
    turnover = []
    for g, _ in _pairs(study, "turnover_gammas", "turnover_t_max"):
        row = _rate_row(study, _turnover_key(g), runs[_turnover_key(g)])
        turnover.append({**row, **_turnover_theory(study, row, runs[_turnover_key(g)])})
    react, react_table = _reactivation(study, runs)
    no_drag = _no_drag(study, runs)
    rates = pd.DataFrame([{"set": "kramers", **r} for r in kramers] + [{"set": "turnover", **r} for r in turnover])
    rates["window"] = rates["window"].map(lambda w: float(w[1]))
    study.write_table(rates.rename(columns={"window": "t_max"}), "rates.parquet")
    study.write_table(react_table, "reactivation.parquet")
    study.write_table(_survival_tables(study, runs), "no_drag.parquet")
    study.write_table(pd.DataFrame(no_drag), "no_drag_rates.parquet")
    hi = kramers[-1]
    study.compare(
        f"escape rate / Kramers–Langer at ΔE/T = {hi['barrier_over_T']:.3g}, γ = {hi['gamma']:g}",
        hi["ratio"],
        hi["ratio_err"],
        1.0,
        note="Kramers–Langer is the large-barrier limit; the ratio should tend to 1 as ΔE/T grows",
        convention="disk r < 0.5 at E0 = well_energy, rate window [t_relax + relax_widths/γ, t_max], r_esc 1.5",
    )
    study.write_numbers(
        {
            "kramers": kramers,
            "turnover": turnover,
            "reactivation": react,
            "no_drag": no_drag,
            "conventions": {
                "r_esc": runs["react_T"].r_esc,
                "ic_region": "disk r < 0.5",
                "rate": "constant-hazard MLE on [t_relax + relax_widths/γ, t_max], left-truncated, right-censored",
                "t_relax": p.t_relax,
                "relax_widths": p.relax_widths,
                "window_rule": f"t ≥ {p.t_relax:g} + {p.relax_widths:g}/γ; constant when the halves agree within "
                f"{p.constancy_z:g}σ",
                "all_constant_in_window": all(r["constant_in_window"] for r in kramers + turnover),
                "seeds": "one per Kramers and turnover record, derived from the study's seed and the record's key",
                "nodrag_window": list(p.nodrag_window),
                "kick": "0.1 min(1/ω, 1/γ) (the scene default)",
                "flow": p.flow,
                "turnover_theory": "Mel'nikov–Meshkov/PGH k = Υ(δ) k_KL, δ = γS/T, S the action of the orbit at "
                "the saddle's energy through the well; energy diffusion k_ED = δ k_TST",
                "theory_range": f"γ/ω_b ≤ {THEORY_GAMMA_MAX:g}",
            },
        }
    )


# -- plot -------------------------------------------------------------------
plot = figure_stage(
    "plot_noise",
    rates="rates",
    reactivation="reactivation",
    no_drag="no_drag",
    numbers=NUMBERS,
    path=PATH,
    scale=SCALE,
)
