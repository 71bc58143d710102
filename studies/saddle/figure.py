"""Figure of the chaotic-saddle study ``saddle`` (draws the numbers JSON; computes nothing)."""

from __future__ import annotations

from hhscatter.publish.figures import agg_pyplot, save_panels

COLORS = {"henon_heiles": "#2166ac", "contopoulos": "#b2182b", "barbanis": "#1b7837"}
MARKERS = {"henon_heiles": "o", "contopoulos": "s", "barbanis": "^"}


def _done(records):
    return [r for r in records if r.get("predicted") is not None]


def _lines(records):
    return [r for r in records if r.get("d1_lines") and "predicted" in r.get("d1_lines_detail", {})]


def _banded(records):
    """The points with d₁ on lines band by band (at the rule's t_min) of the system that has the most of them."""

    def bands(r):
        det = r.get("d1_lines_detail") or {}
        return [b for b in det.get("bands", []) if b["t_min_kappa"] == det.get("t_min_kappa") and b["d1"]]

    rs = [r for r in records if bands(r)]
    if not rs:
        return None, []
    label = max(dict.fromkeys(r["system"] for r in rs), key=lambda s: sum(r["system"] == s for r in rs))
    return label, [(r, bands(r)) for r in rs if r["system"] == label]


def _scales_panel(ax, numbers, plt):
    """(d) d₁ on lines over each band of scales (its geometric middle, fractions of a line's extent) per energy of
    one system, the section's d₁ at the middle of its own band (filled) and 1 − κ/λ̄ (dashed)."""
    label, pts = _banded(numbers["saddle"])
    cmap = plt.get_cmap("viridis")
    for i, (r, bs) in enumerate(pts):
        col = cmap(i / max(len(pts) - 1, 1))
        x = [(b["lo"] * b["hi"]) ** 0.5 for b in bs]
        ax.errorbar(x, [b["d1"]["value"] for b in bs], [b["d1"]["err"] for b in bs], fmt="o:", mfc="white",
                    color=col, capsize=3, label=f"E/E_c = {r['ratio']:g}: lines")  # fmt: skip
        sec = r["d1_lines_detail"].get("at_section_scales") or {}
        if r.get("d1") is not None and sec:
            mid = 1.25 * (sec["lo"] * sec["hi"]) ** 0.5  # set off to the right of the lines' band there
            ax.errorbar([mid], [r["d1"]], [r["d1_err"]], fmt="s", color=col, capsize=3)
        if r.get("d1_implied") is not None:
            ax.axhline(r["d1_implied"], color=col, ls="--", lw=1, alpha=0.7)
    ax.set_xscale("log")
    ax.set_xlabel("scale (fraction of the extent: a line's, or the section points')")
    ax.set_ylabel("partial dimension d₁ over the band")
    ax.set_title(f"(d) d₁ across scales, {label or 'no point with bands'}: lines (open), section (filled), "
                 "1 − κ/λ̄ (dashed)", fontsize=10)  # fmt: skip
    if pts:  # the legend in a band of its own above the points
        lo, hi = ax.get_ylim()
        ax.set_ylim(lo, hi + 0.12 * (hi - lo))
        ax.legend(fontsize=7, ncol=4, loc="upper center")


def plot_saddle(numbers, path):
    """Four panels: (a) κ against λ̄(1 − d₁) per point, d₁ from the section points (filled) and on lines (open);
    (b) the section's D₁ measured and implied, 2(1 − κ/λ̄), and its D₀ = 2(1 − α) from the uncertainty exponent on
    lines; (c) d₁ from the section points (D₁/2), d₁ on lines and 1 − κ/λ̄ against E/E_c; (d) d₁ on lines band by
    band of scales, with the section's d₁ on its own band and 1 − κ/λ̄."""
    plt = agg_pyplot()
    recs = _done(numbers["saddle"])
    fig, ((a, b), (c, d)) = plt.subplots(2, 2, figsize=(14, 10.4))
    _scales_panel(d, numbers, plt)
    for label in dict.fromkeys(r["system"] for r in numbers["saddle"]):
        col, mk = COLORS.get(label, "k"), MARKERS.get(label, "o")
        rs = [r for r in _lines(numbers["saddle"]) if r["system"] == label]
        if rs:
            p = [r["d1_lines_detail"]["predicted"] for r in rs]
            a.errorbar([q["value"] for q in p], [r["kappa"] for r in rs], xerr=[q["err"] for q in p],
                       yerr=[r["kappa_err"] for r in rs], fmt=mk, mfc="white", color=col, capsize=3,
                       label=f"{label}: d₁ on lines")  # fmt: skip
            c.errorbar([r["ratio"] for r in rs], [r["d1_lines"]["value"] for r in rs],
                       [r["d1_lines"]["err"] for r in rs], fmt=mk + ":", mfc="white", color=col, capsize=3,
                       label=f"{label}: d₁ on lines")  # fmt: skip
        rs = [r for r in recs if r["system"] == label]
        if rs:
            x = [r["ratio"] for r in rs]
            c.errorbar(x, [r["d1"] for r in rs], [r["d1_err"] for r in rs], fmt=mk + "-", color=col, capsize=3,
                       label=f"{label}: D₁/2, section points")  # fmt: skip
            c.errorbar(x, [r["d1_implied"] for r in rs], [r["d1_implied_err"] for r in rs], fmt="--", color=col,
                       alpha=0.6, label=f"{label}: 1 − κ/λ̄")  # fmt: skip
    hi = 0.0
    for label in dict.fromkeys(r["system"] for r in recs):
        rs = [r for r in recs if r["system"] == label]
        col, mk = COLORS.get(label, "k"), MARKERS.get(label, "o")
        a.errorbar([r["predicted"] for r in rs], [r["kappa"] for r in rs], xerr=[r["predicted_err"] for r in rs],
                   yerr=[r["kappa_err"] for r in rs], fmt=mk, color=col, capsize=3,
                   label=f"{label}: d₁ = D₁/2")  # fmt: skip
        hi = max(hi, *(max(r["predicted"] + r["predicted_err"], r["kappa"]) for r in rs))
        for r in _lines(rs):
            q = r["d1_lines_detail"]["predicted"]
            hi = max(hi, q["value"] + q["err"])
        x = [r["ratio"] for r in rs]
        b.errorbar(x, [r["d1_section"] for r in rs], [r["d1_section_err"] for r in rs], fmt=mk + "-", color=col,
                   capsize=3, label=f"{label}: measured D₁")  # fmt: skip
        b.errorbar(x, [2 * r["d1_implied"] for r in rs], [2 * r["d1_implied_err"] for r in rs], fmt=mk + "--",
                   mfc="none", color=col, capsize=3, alpha=0.7, label=f"{label}: 2(1 − κ/λ̄)")  # fmt: skip
    for label in dict.fromkeys(r["system"] for r in numbers["saddle"]):
        rs = [r for r in numbers["saddle"] if r["system"] == label and r.get("d0") is not None]
        if rs:
            b.errorbar([r["ratio"] for r in rs], [2 * r["d0"] for r in rs], [2 * r["d0_err"] for r in rs],
                       fmt=MARKERS.get(label, "o") + ":", mfc="white", color=COLORS.get(label, "k"), capsize=3,
                       label=f"{label}: D₀ = 2(1 − α), lines")  # fmt: skip
    hi = 1.1 * hi if hi > 0 else 1.0
    a.plot([0, hi], [0, hi], color="0.5", lw=1, label="κ = λ̄(1 − d₁)")
    a.set_xlim(0, hi)
    a.set_ylim(0, hi)
    a.set_xlabel("λ̄ (1 − d₁)   (1/time)")
    a.set_ylabel("κ   (1/time)")
    a.set_title("(a) the Kantz–Grassberger relation")
    a.legend(fontsize=8)
    b.set_xlabel("E / E_c")
    b.set_ylabel("dimension on the section: D₁ = 2 d₁, D₀ = 2 d₀")
    b.set_title("(b) D₁ measured and implied by κ and λ̄; D₀ from lines")
    for ax, scale in ((b, 2.0), (c, 1.0)):  # a dimension below 0 (λ̄ < κ: 1 − κ/λ̄ < 0) is named, not drawn
        off = [f"{r['system']} {r['ratio']:g}: {scale * r['d1_implied']:.2f}" for r in recs if r["d1_implied"] < 0]
        if off:  # an empty handle: the note sits in the legend
            ax.set_ylim(bottom=0.0)
            ax.plot([], [], " ", label=("2(1 − κ/λ̄)" if scale == 2 else "1 − κ/λ̄") + " < 0 (λ̄ < κ), off the axis: "
                    + "; ".join(off))  # fmt: skip
    b.legend(fontsize=7)
    c.set_xlabel("E / E_c")
    c.set_ylabel("partial dimension d₁")
    c.set_title("(c) d₁: section points, lines, and 1 − κ/λ̄")
    c.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    save_panels(fig, path, dpi=180)
    plt.close(fig)
