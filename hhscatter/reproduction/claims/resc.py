"""r_esc sensitivity of claims 3 and 5: μ measured, μ predicted, the survivors' own-⟨K⟩ μ and 2⟨K⟩/E at E0 itself,
per escape radius, with the same N and rules for each (the default radius and ``resc_values``)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from hhscatter.analysis.stats.measured import Measured
from hhscatter.reproduction.claims.kappa import rate_or_reason
from hhscatter.reproduction.claims.keys import resc_key
from hhscatter.reproduction.claims.mu import (
    mu_conservative,
    mu_measured,
    mu_of_E,
    mu_predicted,
    mu_windows,
)


def resc_values(p, m) -> list:
    """[None (the default), *resc_values valid for this system (beyond its saddle distance, not its default)]."""
    default = m.default_escape_radius(p.e0_ratio * m.critical_energy)
    return [None, *(R for R in p.resc_values if R > m.saddle_radius and R != default)]


def resc_rows(runs, systems) -> list:
    """μ measured, μ predicted (c-measure), the survivors' own-⟨K⟩ μ and 2⟨K⟩/E at E0 itself, per r_esc (the
    default and resc_values), the same N and rules for each: the r_esc sensitivity of claims 3 and 5."""
    p = runs.params
    out = []
    for label, spec, m in systems:
        Rs = resc_values(p, m)
        if len(Rs) < 2:
            continue
        ec = m.critical_energy
        E0 = p.e0_ratio * ec
        for R in Rs:
            fits = {}
            for r in p.resc_ratios:
                lt = runs.lifetimes(resc_key(label, R, f"r{r:.3f}"))
                res, _ = rate_or_reason(lt[lt["outcome"] != "censored"], p.min_survivors)
                if res is not None:  # too few escapes: no κ, τ0 for the probe window at this energy
                    fits["escaping", r] = res
            keys = {r: resc_key(label, R, f"probe_r{r:.3f}") for r in p.resc_ratios}
            mdf = pd.DataFrame(mu_conservative(runs, label, m, fits, keys=keys))
            meas, _, (own, _) = mu_measured(
                runs, label, m, E0, key=resc_key(label, R, f"g{p.mu_gamma:g}"), n=p.resc_diss_n
            )
            pred, _, _ = mu_predicted(runs, mdf, ec, E0)
            c = mdf[(mdf["kind"] == "c-measure") & np.isclose(mdf["ratio"], p.e0_ratio)]
            r_esc = float(m.default_escape_radius(E0)) if R is None else float(R)
            for wname, w in mu_windows(runs).items():
                (v, e), (pv, pe) = own[wname], pred["c-measure", wname]
                out.append(
                    {
                        "id": f"{label}-r{r_esc:g}-{wname}",
                        "system": spec["name"],
                        "label": label,
                        "r_esc": r_esc,
                        "default": R is None,
                        "window": list(w),
                        "mu_measured": Measured.of(*meas[wname]).to_dict(),
                        "mu_predicted": Measured.of(pv, pe).to_dict(),
                        "mu_own_K": Measured.of(v, e).to_dict(),
                        "moment_test": (Measured.of(v, e) - Measured.of(pv, pe)).to_dict(),
                        "kinetic_at_E0": Measured.of(
                            *(c[["mu", "mu_err"]].iloc[0] if len(c) else (None, None))
                        ).to_dict(),
                        "kinetic_at_E0_interpolated_without_E0": float(
                            mu_of_E(mdf[~np.isclose(mdf["ratio"], p.e0_ratio)], ec)(E0)
                        ),
                        "n_diss": p.resc_diss_n,
                        "n_probe": p.resc_probe_n,
                    }
                )
    return out
