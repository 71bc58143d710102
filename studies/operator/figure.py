"""Figure of study operator: κ(E) by Ulam's method against fig2, convergence, μ_c, the dissipative P(t), the
energies at t* and the cost comparison (drawn from operator.json and the derived tables; nothing computed)."""

from __future__ import annotations

import numpy as np


def plot_operator(nums, conv, surv, pts, ulam_pts, fig1_pts, path):
    """plot_operator(nums, conv, surv, pts, ulam_pts, fig1_pts, path) -> None; writes operator.png and siblings.

    Two panels at most per file, so that each stays legible at the page's content width: ``path``
    (operator.png): (a) κ(E) by Ulam's method against fig2's, (b) its convergence in box side and samples;
    operator_cmeasure.png (when fig1's points are given): the operator's c-measure μ_c against fig1's sprinkler
    points; operator_dissipative.png: (a) the dissipative P(t), simulated, operator and reduced operator, (b)
    the energies of the first crossing after t*; operator_cost.png: the orbit-time cost of κ at 1 %.
    Inputs: operator.json's numbers and the study's derived tables (pandas DataFrames).
    """
    from pathlib import Path

    import matplotlib.pyplot as plt

    path = Path(path)
    fig, ax = plt.subplots(1, 2, figsize=(12, 5.2))
    recs = nums["kappa_ulam"]
    E = np.array([r["energy"] for r in recs])
    _panel_kappa(ax[0], nums, recs, E)
    _panel_convergence(ax[1], conv, recs)
    _save(fig, path)
    if fig1_pts is not None and ulam_pts is not None:
        fig, c = plt.subplots(figsize=(7, 6.6))
        _panel_cmeasure(c, nums, ulam_pts, fig1_pts)
        _save(fig, path.with_name(path.stem + "_cmeasure.png"))
    dn = nums["dissipative"]
    fig, ax = plt.subplots(1, 2, figsize=(12, 5.2))
    _panel_survival(ax[0], dn, surv)
    _panel_t_star_energy(ax[1], dn, pts)
    _save(fig, path.with_name(path.stem + "_dissipative.png"))
    fig, f = plt.subplots(figsize=(7, 5))
    _panel_cost(f, nums["cost"])
    _save(fig, path.with_name(path.stem + "_cost.png"))


def _save(fig, path):
    import matplotlib.pyplot as plt

    from hhscatter.publish.figures import save_panels

    fig.tight_layout()
    fig.savefig(path, dpi=120)
    if len(fig.axes) > 1:
        save_panels(fig, path, dpi=120)  # each panel legible at a page's full width
    plt.close(fig)


def _panel_kappa(a, nums, recs, E):
    """(a) κ(E): Ulam's κ∞ (the headline: extrapolated in box side and samples per box) and its finest-box values
    against fig2's κ0 and long-run κ."""
    f2 = [(r["energy"], r["fig2_kappa"], r["fig2_err"]) for r in recs if r.get("fig2_kappa") is not None]
    if f2:
        e2, k2, s2 = map(np.array, zip(*f2))
        a.errorbar(e2, k2, s2, fmt="s", color="k", mfc="none", ms=7, capsize=3, label="fig2: κ0 from P(t)")
    cm = [(r["energy"], r["fig2_kappa_cm"], r["fig2_kappa_cm_err"]) for r in recs if r.get("fig2_kappa_cm") is not None]
    if cm:
        ec, kc, sc = map(np.array, zip(*cm))
        a.errorbar(
            ec + 0.004,
            kc,
            sc,
            fmt="D",
            color="C0",
            mfc="none",
            ms=6,
            capsize=3,
            label="fig2: κ from long-run crossings (true-time rel.)",
        )
    a.errorbar(
        E,
        [r["kappa"] for r in recs],
        [r["err"] for r in recs],
        fmt="o",
        color="C3",
        mfc="none",
        ms=5,
        capsize=2,
        alpha=0.6,
        label=f"Ulam, finest box {recs[0]['box']:g} (err: stat ⊕ linear box-side bias)",
    )
    inf = [(r["energy"], r["kappa_inf"], r["err"]) for r in nums.get("kappa_convergence", []) if r.get("kappa_inf")]
    if inf:
        ei, ki, si = map(np.array, zip(*inf))
        a.errorbar(
            ei - 0.004, ki, si, fmt="o", color="C3", ms=7, capsize=3, label="Ulam κ∞: box → 0, samples → ∞ (headline)"
        )
    for m in nums.get("mixed_phase_space", []):
        rec = m.get("record")
        if rec:
            a.errorbar(
                [rec["energy"]],
                [rec["kappa"]],
                [rec["err"]],
                fmt="o",
                color="0.6",
                capsize=3,
                label=f"Ulam at E = {rec['energy']:g} (mixed)",
            )
            if rec.get("fig2_kappa") is not None:
                a.errorbar([rec["energy"]], [rec["fig2_kappa"]], [rec["fig2_err"]], fmt="s", color="0.6", mfc="none")
    a.set(xlabel="E", ylabel="κ (1/time)", title="(a) escape rate: root of ρ(M(κ)) = 1 against P(t)")
    a.legend(fontsize=9)


def _panel_convergence(b, conv, recs):
    """(b) discretisation bias: κ_Ulam/κ0(fig2) against the box side and the samples per box."""
    cb = conv[conv["vary"] == "box"]
    for i, (e, g) in enumerate(cb.groupby("energy")):
        g = g.sort_values("box")
        ref = next((r.get("fig2_kappa") for r in recs if np.isclose(r["energy"], e)), None)
        if ref is None:
            continue
        b.plot(g["box"], g["kappa"] / ref, "o-", color=f"C{i}", ms=4, label=f"E = {e:g}")
        cs = conv[(conv["vary"] == "samples") & np.isclose(conv["energy"], e)]
        b.plot(
            cs["box"] * (1 + 0.12 * np.log2(cs["samples"] / cs["samples"].max())),
            cs["kappa"] / ref,
            "^",
            color=f"C{i}",
            ms=4,
            mfc="none",
        )
    b.axhline(1, color="k", lw=0.8)
    b.set_xscale("log")
    b.set(
        xlabel="box side (M per finest box: triangles, left = fewer)",
        ylabel="κ_Ulam / κ0(fig2)",
        title="(b) discretisation bias: κ vs box side",
    )
    b.legend(fontsize=9, ncol=2)


def _panel_cmeasure(c, nums, ulam_pts, fig1_pts):
    """(c) μ_c: the operator's sprinkler measure (grey) against fig1's points, with their debiased distance."""
    if ulam_pts is not None and len(ulam_pts):
        e0 = float(ulam_pts["energy"].iloc[0])
        u = ulam_pts[np.isclose(ulam_pts["energy"], e0)]
        h, xe, ye = np.histogram2d(u["x"], u["y"], bins=220, range=[[-1.05, 1.05], [-1.05, 1.05]])
        c.imshow(np.log10(h.T + 1), origin="lower", extent=[-1.05, 1.05, -1.05, 1.05], cmap="Greys")
        if fig1_pts is not None:
            f = fig1_pts[np.isclose(fig1_pts["energy"], e0)]
            c.plot(f["x"], f["y"], ".", color="C3", ms=1.2, alpha=0.6, label=f"fig1 sprinkler points ({len(f)})")
            c.legend(fontsize=8, loc="lower left", markerscale=6)
        d = [
            r
            for r in nums["cmeasure_distances"]
            if np.isclose(r["fig1_energy"], e0) and np.isclose(r["operator_energy"], e0) and r["measure"] == "sprinkler"
        ]
        t = f"μ_c at E = {e0:g}: operator (grey) vs fig1"
        if d:
            t += f"\ndebiased H(ε={d[0]['box']:g}) = {d[0]['hellinger_debiased']:.3f}"
        c.set(xlabel="x", ylabel="y", title=t)
        c.set_aspect("equal")


def _panel_survival(dd, dn, surv):
    """(d) the dissipative P(t): simulated, operator on (box × E bin) and reduced operator on ρ(E)."""
    dd.semilogy(surv["t"], surv["sim"], "k-", lw=1.6, label=f"simulated (N = {dn['sim_orbits']})")
    dd.semilogy(surv["t"], surv["operator"], "--", color="C3", lw=1.4, label="operator on (box × E bin)")
    dd.semilogy(
        surv["t"], np.maximum(surv["reduced"], 1e-12), ":", color="C0", lw=1.6, label="reduced operator on ρ(E)"
    )
    dd.axvline(dn["t_star"], color="0.5", lw=0.8)
    lo = max(1.0 / dn["sim_orbits"], 1e-6)
    dd.set_ylim(lo / 3, 1.2)
    t_hi = dn.get("compared_until") or surv["t"].max()
    dd.set_xlim(0, min(float(surv["t"].max()), 1.5 * float(t_hi)))
    dd.set(xlabel="t", ylabel="P(t)", title=f"(a) dissipative P(t): E0 = {dn['energy']:g}, γ = {dn['gamma']:g}")
    dd.legend(fontsize=8)


def _panel_t_star_energy(e, dn, pts):
    """(e) energies of the survivors' first crossing after t*: operator (weighted) against the simulation."""
    op, sim = pts[pts["set"] == "operator"], pts[pts["set"] == "sim"]
    bins = np.linspace(min(op["energy"].min(), sim["energy"].min() if len(sim) else 1), dn["energy"], 40)
    e.hist(
        op["energy"], bins=bins, weights=op["w"] / op["w"].sum(), histtype="step", color="C3", lw=1.5, label="operator"
    )
    if len(sim):
        e.hist(
            sim["energy"],
            bins=bins,
            weights=np.full(len(sim), 1.0 / len(sim)),
            histtype="step",
            color="k",
            lw=1.5,
            label=f"simulated ({len(sim)} orbits)",
        )
    e.set(
        xlabel="E at the first crossing after t*",
        ylabel="share",
        title=f"(b) survivors at t* = {dn['t_star']:g}: energy",
    )
    e.legend(fontsize=8)


def _panel_cost(f, cost):
    """(f) orbit-time for κ at 1 %: the P(t) route against the Ulam operator."""
    x = np.arange(len(cost))
    f.bar(x - 0.2, [r["pt_orbit_time_1pct"] for r in cost], 0.4, color="0.4", label="P(t) route (fig2's rule)")
    f.bar(x + 0.2, [r.get("op_orbit_time_1pct", np.nan) for r in cost], 0.4, color="C3", label="Ulam operator")
    f.set_yscale("log")
    f.set_xticks(x, [f"E = {r['energy']:g}" for r in cost])
    f.set(ylabel="orbit-time for κ at 1 % (time units)", title="cost of κ at 1 %")
    f.legend(fontsize=8)


def plot_residuals(nums, grid, path):
    """Write operator_residuals.png: (a) κ_Ulam/κ_ref − 1 against E, (b) the extrapolation of κ in samples per box.

    (a) the extrapolated κ∞ against fig2's κ0 from P(t) and against fig2's κ from long-run crossings, the
    error bar κ∞'s error and the shaded bar the reference's (both over κ_ref); the finest partition's κ as
    crosses. (b) κ on the grid of box sides × samples per box against M^(−1/2), one colour per energy, one
    marker per box side, with the fitted κ∞ + a·b + β·M^(−1/2) at b → 0 (dashed) ending at κ∞.
    Inputs: operator.json's numbers and the derived table convergence_grid.parquet.
    """
    import matplotlib.pyplot as plt

    from hhscatter.publish.figures import save_panels

    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 6.2))
    recs = [r for r in nums.get("kappa_convergence", []) if r.get("kappa_inf") is not None]
    for k, (ref, lab, dx) in enumerate((("kappa0", "κ0 from P(t)", -0.003), ("kappa_cm", "κ from crossings", 0.003))):
        rs = [r for r in recs if r.get(ref) is not None]
        if not rs:
            continue
        E = np.array([r["energy"] for r in rs]) + dx
        res = np.array([r[f"residual_{ref}"] for r in rs])
        own = np.array([r["err"] / abs(r[ref]) for r in rs])
        refe = np.array([r[f"{ref}_err"] / r[ref] for r in rs])
        a.bar(E, 2 * refe, bottom=res - refe, width=0.005, color=f"C{k}", alpha=0.25)
        a.errorbar(
            E,
            res,
            own,
            fmt="o" if k == 0 else "D",
            color=f"C{k}",
            capsize=3,
            label=f"κ∞ vs fig2's {lab} (bar: ours; shade: fig2's)",
        )
        a.plot(
            E,
            [r[f"residual_finest_{ref}"] for r in rs],
            "x",
            color=f"C{k}",
            ms=7,
            label=f"finest boxes, no extrapolation, vs {lab}",
        )
    a.axhline(0, color="k", lw=0.8)
    a.set(xlabel="E", ylabel="κ_Ulam / κ_ref − 1", title="(a) residuals of Ulam's κ")
    a.legend(fontsize=9, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=1)
    if grid is not None and len(grid):
        est = grid[grid["kind"] == "estimate"]
        marks = {s: m for s, m in zip(sorted(est["box"].unique()), "os^")}
        for i, (e, g) in enumerate(est.groupby("energy")):
            rec = next((r for r in recs if np.isclose(r["energy"], e)), None)
            for s, gs in g.groupby("box"):
                gs = gs.sort_values("samples")
                b.plot(gs["samples"] ** -0.5, gs["kappa"], marks.get(s, "o") + "-", color=f"C{i}", ms=4, lw=0.6)
            if rec:
                xs = np.linspace(0, (g["samples"] ** -0.5).max(), 20)
                b.plot(xs, rec["kappa_inf"] + rec["coef_samples"] * xs, "--", color=f"C{i}", lw=0.8)
                b.errorbar(
                    [0],
                    [rec["kappa_inf"]],
                    [rec["err"]],
                    fmt="*",
                    color=f"C{i}",
                    ms=9,
                    capsize=3,
                    label=f"E = {e:g}: κ∞ = {rec['kappa_inf']:.4f}",
                )
        b.set_yscale("log")
        b.set(
            xlabel="M^(−1/2) (M samples per box)",
            ylabel="κ (1/time)",
            title="(b) κ on box sides (○ □ △: finest, ×2, ×4)\n× samples per box",
        )
        b.legend(fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    save_panels(fig, path, dpi=110)  # each panel legible at a page's full width
    plt.close(fig)
