"""κ0(E) under the conventions of the κ figure (IC region × window rule), and the κ(E) law's spread across them.

The rows and the law that a study of κ near E_c sets side by side: per run, κ under the two window rules
(:func:`convention_rows`: the data-driven plateau windows and the windows fixed by P levels, each with the
plateau check of :mod:`hhscatter.analysis.survival.kappa_conventions`); over the runs, the energies where every
defined convention agrees (:func:`stable_energies`); the κ(E) law fitted per convention on them
(:func:`fit_laws`) and its parameters' spread across the conventions (:func:`law_spread`), the systematic
uncertainty of "the κ(E) law". Nothing here reads a file. Units: κ in 1/time, energies in energy units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.survival.kappa_conventions import escape_rate_p_levels, plateau_rate
from hhscatter.analysis.survival.kappa_energy import fit_kappa_energy, kappa_law_summary
from hhscatter.errors import ConfigError

__all__ = ["LAW_PARAMETERS", "ConventionSpread", "convention_rows", "fit_laws", "law_spread", "stable_energies"]


def stable_energies(table, *, rel_tol: float = 0.1, min_defined: int = 2):
    """stable_energies(table, *, rel_tol=0.1, min_defined=2) -> DataFrame: energy, n_defined, rel_range, stable.

    ``table``: one row per (energy, convention) with columns ``energy``,
    ``kappa``, ``defined``. κ at an energy is *stable* when at least
    ``min_defined`` conventions define it and (max − min)/mean of their κ is
    ≤ ``rel_tol``.
    """
    check.table(table, "table", ("energy", "kappa", "defined"), min_rows=0)
    check.number(rel_tol, "rel_tol", minimum=0.0)
    check.count(min_defined, "min_defined", 1)
    rows = []
    for energy, g in table.groupby("energy", sort=True):
        k = g.loc[g["defined"].astype(bool), "kappa"].to_numpy(float)
        rel = float((k.max() - k.min()) / k.mean()) if k.size >= 1 and k.mean() > 0 else math.nan
        rows.append(
            {
                "energy": float(energy),
                "n_defined": int(k.size),
                "rel_range": rel,
                "stable": bool(k.size >= min_defined and rel <= rel_tol),
            }
        )
    return pd.DataFrame(rows)


LAW_PARAMETERS = ("a", "b", "c", "E_b")


@dataclass(frozen=True)
class ConventionSpread:
    """One parameter across conventions: its :class:`~hhscatter.analysis.stats.measured.Measured` (the mean over
    the conventions, error √(spread² + err_stat²)), ``err_stat`` (the largest statistical error of one convention),
    ``spread`` (half the range across conventions) and ``per_convention`` {convention: value}; same unit as the
    parameter.

    Examples
    --------
    >>> ConventionSpread(Measured(12.0, 2.5), 1.5, 2.0, {"one": 10.0, "two": 14.0}).to_dict()["err"]
    2.5
    """

    measured: Measured
    err_stat: float
    spread: float
    per_convention: dict

    def to_dict(self) -> dict:
        """``{value, err_stat, spread, err, per_convention}``: the record as a numbers JSON holds it."""
        m = self.measured
        fields = ("value", "err_stat", "spread", "err", "per_convention")
        return dict(zip(fields, (m.value, self.err_stat, self.spread, m.err, self.per_convention)))


def law_spread(fits: dict) -> dict:
    """law_spread({convention: KappaEnergyFit}) -> {param: {value, err_stat, spread, err, per_convention}}.

    ``value`` = mean over conventions; ``spread`` = half the range across
    conventions (the systematic uncertainty of the law from its definition);
    ``err_stat`` = the largest statistical error of one convention's fit;
    ``err`` = √(spread² + err_stat²).
    """
    check.mapping(fits, "fits", min_size=1)
    for name, f in fits.items():
        check.having(f, f"fits[{name!r}]", LAW_PARAMETERS, "a KappaEnergyFit (fit_kappa_energy)")
    out = {}
    for p in LAW_PARAMETERS:
        vals = {name: float(getattr(f, p)) for name, f in fits.items()}
        errs = [float(getattr(f, f"{p}_err", math.nan)) for f in fits.values()]
        v = np.array(list(vals.values()))
        spread = float((v.max() - v.min()) / 2) if v.size else math.nan
        stat = float(np.nanmax(errs)) if errs and np.isfinite(errs).any() else math.nan
        total = float(math.hypot(spread, stat)) if math.isfinite(stat) else spread
        m = Measured(float(v.mean()) if v.size else math.nan, total, "mean over conventions", len(vals))
        out[p] = ConventionSpread(m, stat, spread, vals).to_dict()
    return out


def convention_rows(
    t_end, observed, result, *, p_hi: float = 0.5, p_lo: float = 1e-2, max_bias: float = 0.1
) -> list[dict]:
    """κ of one run under the two window rules, one row each: ``plateau`` (the windows of ``result``, the run's
    :func:`~hhscatter.analysis.survival.escape_rate.escape_rate`) and ``plevel`` (windows fixed by the P levels
    p_hi, p_lo); κ is ill-defined (``defined`` False, with its ``reason``) where the censored fraction biases the slope
    at the window end by more than ``max_bias``. Rows: windows, n, n_escaped_at_start, kappa (1/time), kappa_err,
    kappa_stat, kappa_spread, t_lo, t_hi, trapped_fraction, bias_at_end, defined, reason.

    Examples
    --------
    >>> from hhscatter.analysis.survival.escape_rate import escape_rate
    >>> t = np.random.default_rng(2).exponential(5.0, 20000)
    >>> obs = np.ones(t.size, bool)
    >>> [r["windows"] for r in convention_rows(t, obs, escape_rate(t, obs, detect_tail=False))]
    ['plateau', 'plevel']
    """
    t_end = check.numbers(t_end, "t_end", minimum=0.0)
    observed = check.mask(observed, "observed", t_end.size)
    rates = {  # plateau_rate checks ``result`` before any work
        "plateau": plateau_rate(result, t_end, observed, max_bias=max_bias),
        "plevel": escape_rate_p_levels(t_end, observed, p_hi=p_hi, p_lo=p_lo, max_bias=max_bias),
    }
    return [
        {
            "windows": rule,
            "n": int(t_end.size),
            "n_escaped_at_start": int(((t_end == 0) & observed).sum()),
            "kappa": r.kappa,
            "kappa_err": r.kappa_err,
            "kappa_stat": r.kappa_stat,
            "kappa_spread": r.kappa_spread,
            "t_lo": r.t_lo,
            "t_hi": r.t_hi,
            "trapped_fraction": r.censored_fraction,  # the key of the tables written before
            "bias_at_end": r.bias_at_end,
            "defined": bool(r.defined),
            "reason": r.reason,
        }
        for rule, r in rates.items()
    ]


def fit_laws(table, names, energies, E_c: float, *, n_boot: int, seed: int, min_points: int = 5):
    """The κ(E) law (continuous at E_b, :func:`~hhscatter.analysis.survival.kappa_energy.fit_kappa_energy`) per
    convention, on the rows of ``table`` (columns convention, energy, kappa, kappa_err, defined) where κ is defined
    and the energy is among ``energies`` (the stable ones).

    Returns (fits, info): fits {name: KappaEnergyFit} of the conventions with at least ``min_points`` energies (a,
    b and the break need points on both sides); info {name: {"energies": [...], "fit": its numbers or None}}.
    """
    check.table(table, "table", ("convention", "energy", "kappa", "kappa_err", "defined"), min_rows=0)
    if isinstance(names, (str, bytes, dict)) or not isinstance(names, (list, tuple)):
        raise ConfigError(f"names must be a list of convention names, got {type(names).__name__}")
    check.numbers(sorted(energies) if isinstance(energies, (set, frozenset)) else energies, "energies", min_size=0)
    check.number(E_c, "E_c")
    check.count(n_boot, "n_boot", 0)
    check.count(min_points, "min_points", 1)
    fits, info = {}, {}
    for name in names:
        d = table[(table["convention"] == name) & table["defined"] & table["energy"].isin(energies)]
        info[name] = {"energies": [float(e) for e in d["energy"]], "fit": None}
        if len(d) < min_points:
            continue
        with counted("survival.kappa_conventions.fit"):
            fits[name] = fit_kappa_energy(
                d["energy"], d["kappa"], d["kappa_err"], E_c, continuous=True, n_boot=n_boot, rng=seed
            )
        info[name]["fit"] = kappa_law_summary(fits[name])
    return fits, info
