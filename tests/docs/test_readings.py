"""Readings are generated like numbers: no study page types a comparative or qualitative reading by hand, every
``[[reading:…]]`` renders from the committed JSON, and each reading's words follow its numbers and their
uncertainties (the inputs here are built by hand, so the expected words are known without the code)."""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path

import pytest

from hhscatter.publish.numbers import load_numbers, render_refs, typed_readings
from hhscatter.publish.readings import (
    READINGS,
    closer_words,
    factor_words,
    pass_fail_words,
    trend,
    trend_words,
)

ROOT = Path(__file__).resolve().parents[2]
PAGES = sorted((ROOT / "studies").glob("*/page.md"))
#: the pages that report results beside the study pages: the headline results of the README and the docs home (one
#: template), the home page, the studies index, the paper-scale page
RESULT_PAGES = [
    ROOT / "tools" / "readme_results.md",
    ROOT / "docs" / "index.md",
    ROOT / "docs" / "studies" / "index.md",
    ROOT / "docs" / "studies" / "paper-scale.md",
]


@pytest.mark.parametrize(
    "page", PAGES + RESULT_PAGES, ids=lambda p: p.parent.name if p.name == "page.md" else p.relative_to(ROOT).as_posix()
)
def test_no_study_page_types_a_reading(page):
    found = typed_readings(page.read_text())
    assert not found, f"{page.relative_to(ROOT)}: readings typed by hand (write [[reading:…]]): {found}"


def test_the_scan_finds_the_readings_that_were_typed():
    """The sentences these pages typed before their readings were generated are found."""
    typed = [
        "predicts the cut-off of their scaling to\nwithin a factor of a few, with no free parameter.",
        "Both point sets lie far closer to μ_c^0.30: the paper's premise for\nFig. 5 holds without qualification.",
        "The non-regular orbits of Contopoulos and Barbanis never decay as one exponential below 2.6 E_c.",
        "the ratio approaches 1 from below as the barrier grows",
        "b = 0.08 ± 0.07, consistent with a quadratic onset",
        "The exit basins are Wada at every energy and S_bb > ln 2 everywhere",
        "κ/α (column `lam_kg` of `energy_scan`) follows\n  the decision rate (`lam`) from 0.19 to 0.375; they part near E_c",
        "the measured rate matches the prediction",
        "the fit overestimates ⟨E⟩ at large t",
        "At the paper scale every shift at\n      E ≥ 0.30 is several σ from zero and the same for r_esc = 1.1, 1.5 and 2",
        "The κ shifts with r_esc move by up to about 2σ of their quick errors",
        "The extrapolation in samples per box removes it within its\nerror",
        "its a ε² and b ε terms are of similar size, so its local\n  slope lies between 1 and 2",
        "At the smallest γ Hénon–Heiles escapes\n  1.08 times as often as κ0 predicts",
        "It changes the numbers, not the picture: at 1.05 E_c",
        "The paper-scale intervals are about three times\n      narrower and every quick value lies inside",
    ]
    assert all(typed_readings(t) for t in typed)
    assert typed_readings('the paper says "μ approaches 1"') == []


@pytest.mark.parametrize("name", sorted(READINGS))
def test_every_reading_renders_from_the_committed_numbers(name):
    text = render_refs(f"[[reading:{name}]]", ROOT)
    assert text and "[[" not in text and "nan" not in text.lower()


def test_every_reading_a_page_names_exists():
    for page in PAGES:
        render_refs(page.read_text(), ROOT, where=page.parent.name)  # NumberRefError on an unknown reading


def test_trend_words_follow_the_fit_and_its_sigma():
    rising = trend([1, 2, 3, 4], [0.80, 0.85, 0.90, 0.95], [0.01] * 4)  # slope 0.05, σ = 0.01/√5
    assert rising["slope"] == pytest.approx(0.05) and rising["err"] == pytest.approx(0.01 / 5**0.5)
    assert trend_words(rising, "the ratio", "ΔE/T").startswith("the ratio rises with ΔE/T")
    flat = trend([1, 2, 3, 4], [0.90, 0.93, 0.89, 0.92], [0.03] * 4)
    assert "no trend in ΔE/T resolved at 2σ" in trend_words(flat, "the ratio", "ΔE/T")


def test_a_factor_is_never_called_few_when_intervals_do_not_overlap():
    assert "off by a factor 1.1 to 6.6" in factor_words(1.08, 6.6, 1, 5)
    assert "overlap in 1 of 5" in factor_words(1.08, 6.6, 1, 5)
    assert factor_words(1.02, 1.3, 4, 4).startswith("the prediction is within a factor 1.3 in all 4 cases")


def test_closer_follows_the_two_distances_and_their_errors():
    assert closer_words(0.10, 0.01, 0.50, 0.01, "A", "B", "d").startswith("closer to A by d")
    assert closer_words(0.50, 0.01, 0.10, 0.01, "A", "B", "d").startswith("closer to B by d")
    assert closer_words(0.10, 0.02, 0.12, 0.02, "A", "B", "d").startswith("as close to A as to B")


def test_never_and_always_only_when_every_cell_says_so():
    assert pass_fail_words([("1", False), ("2", False)], "one", "not one") == "not one at every tested cell (1, 2)"
    mixed = pass_fail_words([("1", False), ("2", True), ("3", None)], "one", "not one")
    assert mixed == "not one at 1; one at 2; not tested at 3"


def _loader(docs):
    return lambda study, scale: docs[study]


def test_the_fig5_premise_follows_both_distances():
    """With SW1 closer to μ_c^0.30 for both sets, the premise holds by both distances; with 5b's SW1 reversed (the
    committed numbers), it depends on the distance for 5b."""
    doc = copy.deepcopy(load_numbers(ROOT, "fig5")[0])
    g = doc["gamma_main"]
    for r in doc["distances"]:
        if r["gamma"] == g:
            r["sw1"], r["sw1_err"] = (0.01, 0.001) if r["ref"] == "E1" else (0.05, 0.001)
    text = READINGS["fig5.premise"](_loader({"fig5": doc}))
    assert text.endswith("holds for both sets by both distances")
    committed = READINGS["fig5.premise"](_loader({"fig5": load_numbers(ROOT, "fig5")[0]}))
    assert "for 5b it depends on the distance" in committed and "closer to μ_c^0.35 by SW1" in committed


def test_the_noise_reading_says_below_one_only_beyond_two_sigma():
    doc = {"kramers": [{"barrier_over_T": x, "ratio": 1.0 - 0.1 / x, "ratio_err": 0.001} for x in (3, 4, 5, 6)]}
    text = READINGS["noise.kramers"](_loader({"noise": doc}))
    assert text.startswith("the ratio lies below 1 by more than 2σ at ΔE/T = 3, 4, 5, 6") and "it rises with" in text
    doc = {"kramers": [{"barrier_over_T": x, "ratio": 1.0, "ratio_err": 0.05} for x in (3, 4, 5, 6)]}
    text = READINGS["noise.kramers"](_loader({"noise": doc}))
    assert text.startswith("no ratio lies below 1 by 2σ and within 2σ of 1 at 3, 4, 5, 6")


def test_the_resc_page_names_the_tools_own_default():
    """The page says the rule's pick is the tool's default for Hénon–Heiles: it is, at every energy of the study,
    and the page no longer calls the reference radius the default."""
    from hhscatter.model import HenonHeiles

    for scale in ("quick", "paper"):
        # the reference radius is recorded under what it is, the authors' value (the study's r_ref)
        other, _ = load_numbers(ROOT, "resc", scale)
        assert other["default_r_esc"]["authors"] == other["r_ref"] and "current" not in other["default_r_esc"]
    doc, _ = load_numbers(ROOT, "resc")
    pick, ref = doc["default_r_esc"]["recommended"], doc["default_r_esc"]["authors"]
    assert pick != ref
    for e in doc["energies"]:
        assert HenonHeiles().default_escape_radius(e) == pytest.approx(pick)
    page = (ROOT / "studies" / "resc" / "page.md").read_text()
    assert "[[resc:default_r_esc.recommended]]; that is the tool's own default" in page
    # the reference radius is read as what it is (the study's r_ref), not as a "current default"
    assert "default_r_esc.authors" not in page and "r_esc = [[resc:r_ref]], the authors' value" in page
    rendered = render_refs(page, ROOT)
    assert f"the default r_esc = {ref:g}" not in rendered
    # the study's parameters, shown on the page with their comments, do not call it the default either
    toml = (ROOT / "studies" / "resc" / "study.toml").read_text()
    r_ref_line = next(line for line in toml.splitlines() if line.startswith("r_ref"))
    assert "current default" not in r_ref_line and "not the tool's default" in r_ref_line


def _beyond_the_paper():
    import tomllib

    for page in PAGES:
        about = tomllib.loads((page.parent / "study.toml").read_text())["about"]
        if not about.get("paper"):
            yield page


@pytest.mark.parametrize("page", list(_beyond_the_paper()), ids=lambda p: p.parent.name)
def test_a_page_beyond_the_paper_states_its_limits(page):
    """A section "## Limits" that names the scale of its numbers (from the JSON), N and what the study does not
    show."""
    text = page.read_text()
    assert "\n## Limits\n" in text, page.parent.name
    section = text.split("\n## Limits\n", 1)[1].split("\n## ", 1)[0]
    name = page.parent.name
    assert f"[[{name}:scale]]" in section or f"[[{name}@" in section, "the scale, from the JSON"
    assert "|int]]" in section, "N, from the JSON"
    assert "does not show" in section


def test_the_turnover_reading_follows_each_step_and_its_errors():
    rows = [{"gamma": g, "ratio": r, "ratio_err": 0.01} for g, r in ((0.03, 0.3), (0.1, 0.6), (0.3, 0.61), (1, 1.0))]
    text = READINGS["noise.turnover"](_loader({"noise": {"turnover": rows}}))
    assert "below 1 by more than 2σ at γ = 0.03, 0.1, 0.3 and within 2σ of 1 at γ = 1" in text
    assert "rises by more than 2σ at 2 of the 3 steps in γ (0.03 → 0.1; 0.3 → 1)" in text
    assert "no resolved change at 0.1 → 0.3" in text


def test_the_no_drag_reading_says_below_only_beyond_two_sigma():
    rows = [
        {"energy": 0.3, "sigma": 0.0, "kappa_over_kappa0": 1.0, "kappa_over_kappa0_err": 0.05},
        {"energy": 0.3, "sigma": 0.01, "kappa_over_kappa0": 0.95, "kappa_over_kappa0_err": 0.05},
        {"energy": 0.3, "sigma": 0.02, "kappa_over_kappa0": 0.70, "kappa_over_kappa0_err": 0.05},
    ]
    text = READINGS["noise.no_drag"](_loader({"noise": {"no_drag": rows}}))
    assert text == (
        "the rate over the window is σ = 0.01: κ0 within 2σ at E0 = 0.3 (z = −1.0); "
        "σ = 0.02: below κ0 at E0 = 0.3 (z = −6.0)"
    )


def test_the_one_exponential_reading_says_too_few_orbits_where_the_pooled_test_has_no_verdict():
    """Records of the pooled test (with ``exponential_verdict``): a cell without a p-value is "too few orbits", and
    the caveat about nearly empty cells is replaced by the pooling rule; older records keep the caveat."""
    rows = [
        {"label": "a", "ics": "disk/tangential", "e_ratio": 1.05, "p_nonregular": 0.4},
        {"label": "a", "ics": "disk/tangential", "e_ratio": 1.5, "p_nonregular": None},
    ]
    new = [r | {"exponential_verdict": "too few orbits" if r["p_nonregular"] is None else "yes"} for r in rows]
    text = READINGS["generality.one_exponential"](_loader({"generality": {"systems": {"a": {}}, "long_time": new}}))
    assert "too few orbits for the test at 1.5" in text and "pooled until each expects at least 5 orbits" in text
    old = READINGS["generality.one_exponential"](_loader({"generality": {"systems": {"a": {}}, "long_time": rows}}))
    assert "not tested at 1.5" in old and "a handful of orbits drives χ²" in old


def test_the_turnover_theory_reading_follows_the_ratios_and_the_range():
    def row(g, ratio, err, holds):
        return {"gamma": g, "ratio_mm": ratio, "ratio_mm_err": err, "theory_assumptions_hold": holds}

    doc = {
        "turnover": [row(0.01, 0.97, 0.02, True), row(0.1, 0.80, 0.02, True), row(1.0, 1.30, 0.02, False)],
        "conventions": {"theory_range": "γ/ω_b ≤ 0.3"},
    }
    text = READINGS["noise.turnover_theory"](lambda study, scale: doc)
    assert text == (
        "where γ/ω_b ≤ 0.3 (γ = 0.01, 0.1) the rate over Υ(δ) k_KL is within 2σ of 1 at γ = 0.01; below 1 by more "
        "than 2σ at γ = 0.1, |ratio − 1| at most 20.0%; outside that range above 1 by more than 2σ at γ = 1"
    )
    assert "not in this scale's numbers" in READINGS["noise.turnover_theory"](
        lambda study, scale: {"turnover": [{"gamma": 1.0}], "conventions": {}}
    )


def test_the_low_gamma_theory_reading_names_the_theory_the_points_agree_with():
    """Two low-γ points and one above the limit; the flux closure agrees with both at 2σ, the absorbing one is
    below 1 at both (the measured rate 1/0.6 to 1/0.5 times smaller), the other two differ."""

    def row(g, flux, absorbing, turnover, mm, b=3.0):
        return (
            {"gamma": g, "barrier_over_T": b, "ratio_shell": flux, "ratio_shell_err": 0.02}
            | {"ratio_shell_absorbing": absorbing, "ratio_shell_absorbing_err": 0.01}
            | {"ratio_shell_turnover": turnover, "ratio_shell_turnover_err": 0.01, "ratio_mm": mm, "ratio_mm_err": 0.01}
        )

    doc = {
        "turnover": [row(0.003, 0.98, 0.5, 0.7, 1.2), row(0.01, 1.03, 0.6, 0.8, 1.1), row(0.1, 2.0, 0.1, 3.0, 3.0)],
        "conventions": {"energy_diffusion_gamma_max": 0.01},
    }
    text = READINGS["noise.low_gamma_theory"](lambda study, scale: doc)
    assert text.startswith("at γ ≤ 0.01 (2 points, in this order: Hénon–Heiles at ΔE/T = 3, γ = 0.003, 0.01)")
    assert (
        "over the shells' energy diffusion with the flux over the dividing lines above E_b: 0.980 ± 0.020, "
        "1.030 ± 0.020 (within 2σ of 1 at 2 of 2; |ratio − 1| at most 3.0%)" in text
    )
    assert "(within 2σ of 1 at 0 of 2; |ratio − 1| at most 20.0%)" in text
    assert "By system, on Hénon–Heiles (2 points) they agree at 2σ with the shells' energy diffusion with the" in text
    assert "The absorbing closure's rate is 1.67 to 2.00 times the measured one" in text
    assert "the largest deviation falls to 3.0% on Hénon–Heiles" in text and "separable" not in text
    doc["turnover"][0]["ratio_shell"] = 0.9
    doc["two_saddles_turnover"] = {"barrier_over_T": 3.0, "separable": True, "records": [row(0.01, 0.7, 0.3, 0.5, 0.9)]}
    text = READINGS["noise.low_gamma_theory"](lambda study, scale: doc)
    assert (
        "on Hénon–Heiles (2 points) no theory agrees at 2σ at every point; the closest is the shells' energy "
        "diffusion with the flux over the dividing lines above E_b, within 10.0% of every point (within 2σ at 1 of 2)"
    ) in text
    assert "on the two-saddle system (1 point) no theory agrees at 2σ at every point; the closest is Υ(δ) k_KL" in text
    assert "10.0% on Hénon–Heiles and 30.0% on the two-saddle system" in text
    assert "The two-saddle potential is separable" in text
    doc["conventions"]["energy_diffusion_gamma_max"] = 0.001
    assert READINGS["noise.low_gamma_theory"](lambda study, scale: doc) == (
        "no turnover point at γ ≤ 0.001 is in this scale's numbers"
    )


def _prose(text: str) -> str:
    """A page's words without its code (fenced and inline) and its number references."""
    text = re.sub(r"```.*?```", " ", text, flags=re.S)
    text = re.sub(r"\[\[.*?\]\]", " ", text, flags=re.S)
    return re.sub(r"`[^`\n]*`", " ", text)


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.parent.name)
def test_study_pages_name_survivors_by_the_glossary(page):
    """Survivors are regular, chaotic but confined or censored (the glossary); "trapped" meant each of them on some
    page, so the prose does not use it."""
    words = _prose(page.read_text())
    assert not re.search(r"\btrapped\b", words, flags=re.I), page.parent.name
    glossary = (ROOT / "docs" / "equations.md").read_text()
    for term in ("| regular |", "| chaotic but confined |", "| censored |"):
        assert glossary.count(term) == 1, term  # one meaning each


def test_the_hh_1_05_reading_writes_a_hazard_bin_without_escape_as_its_bound():
    def b(lo, hi, h, e, n, **kw):
        return {"t_lo": lo, "t_hi": hi, "hazard": h, "err": e, "events": n, **kw}

    bins = [
        b(100.0, 200.0, 0.003, 0.0003, 100),
        b(200.0, 400.0, 0.003, 0.0003, 100),
        b(400.0, 800.0, 0.0, None, 0, hazard_upper=3.0e-4, hazard_cl=0.95),
        b(800.0, 1400.0, 0.0, None, 0, hazard_upper=2.0e-4, hazard_cl=0.95),
    ]
    doc = {
        "kappa": [
            {"system": "henon_heiles", "ratio": 1.05, "convention": "plateau", "defined": False, "kappa": 0.003}
            | {"trapped_fraction": 0.1, "reason": "plateau"}
        ],
        "validity_map": [{"id": "henon_heiles-1.05-disk", "regular_fraction": 0.0}],
        "long_time": [{"id": "henon_heiles-1.05-disk", "n": 1000, "hazard_nonregular": bins}],
        "config": {"scene": {"t_max": 800.0}},
    }
    text = READINGS["generality.hh_1_05"](_loader({"generality": doc}))
    assert "no escape in [400, 800]: < 3.0e−4 (95 %)" in text
    assert "[800, 1400]: < 2.0e−4 (95 %)" in text and "± 0 " not in text and "nan" not in text
    assert "is constant within its errors (weighted mean 0.00300 ± 0.00021" in text


def test_the_energy_scan_reading_says_every_energy_only_when_each_one_passes():
    """Wada and S_bb > ln 2 (by 2σ) are "at all … scan energies" only when each energy says so; otherwise the energies
    are named. α's trend is the study's weighted slope; S_b's a weighted line through the scan (here flat)."""

    def row(e, wada, s_bb, s_b):
        return {"energy": e, "wada_exits": wada, "S_bb": s_bb, "S_bb_err": 0.01, "S_b": s_b, "S_b_err": 0.01}

    doc = {
        "energy_scan": [row(0.2, True, 0.80, 0.50), row(0.3, True, 0.79, 0.51), row(0.4, True, 0.78, 0.50)],
        "energy_trend": {"alpha_slope": {"value": 2.0, "err": 0.5}},
    }
    text = READINGS["basins.energy_scan"](_loader({"basins": doc}))
    assert text.startswith("the exit basins are Wada at all 3 scan energies (E = 0.2 to 0.4); S_bb above ln 2")
    assert "α rises with E (weighted slope 2.0 ± 0.5 per unit energy, z = +4.0)" in text
    assert "S_b shows no trend in E resolved at 2σ" in text
    doc["energy_scan"][1] = row(0.3, False, 0.70, 0.51)  # not Wada, and S_bb 0.70 within 2σ of ln 2 = 0.693
    text = READINGS["basins.energy_scan"](_loader({"basins": doc}))
    assert text.startswith("the exit basins are not Wada at 0.3; Wada at 0.2, 0.4; S_bb not above ln 2 by 2σ at 0.3")


def _finite_barrier_doc(slope, slope_err, unit, unit_err, p_value, chi2=3.0, dof=4):
    return {
        "finite_barrier": {
            "intercept": {"value": 0.98, "err": 0.015},
            "slope": {"value": slope, "err": slope_err},
            "chi2": chi2,
            "dof": dof,
            "p_value": p_value,
            "slope_intercept_one": {"value": unit, "err": unit_err},
            "T_over_barrier_range": [0.125, 1 / 3],
            "transition_state_slope": -2 / 9,
        }
    }


def test_the_finite_barrier_reading_compares_the_slopes_with_the_theory_and_zero():
    text = READINGS["noise.finite_barrier"](_loader({"noise": _finite_barrier_doc(-0.13, 0.07, -0.23, 0.02, 0.5)}))
    assert "the intercept 0.980 ± 0.015, which agrees with 1 (z = -1.3)" in text.replace("−", "-")
    assert "c_TST = −0.222: the free slope agrees with it (z = +1.3) and lies within 2σ of 0 (z = −1.9)" in text
    assert "the slope at intercept 1 agrees with it (z = −0.4) and is resolved from 0 (z = −11.5)" in text
    assert "scatter" not in text
    far = READINGS["noise.finite_barrier"](_loader({"noise": _finite_barrier_doc(0.5, 0.1, 0.3, 0.02, 0.01, 12, 4)}))
    assert "the free slope differs from it (z = +7.2) and is resolved from 0 (z = +5.0)" in far
    assert "understated by about √(χ²/dof) = 1.7" in far


def test_the_absorbing_radius_reading_says_a_shift_only_beyond_two_sigma():
    def row(b, ratio, err):
        return {"barrier_over_T": b, "r_esc": 3.0, "r_esc_default": 1.5, "rate_ratio": {"value": ratio, "err": err}}

    text = READINGS["noise.absorbing_radius"](
        _loader({"noise": {"absorbing_radius": [row(5, 0.9, 0.02), row(3, 0.98, 0.02)]}})
    )
    assert text == (
        "at ΔE/T = 3 the rate at r_esc = 3 is 0.980 ± 0.020 of that at 1.5 (shift −2.0 ± 2.0 %, z = −1.0: no shift "
        "resolved at 2σ); at ΔE/T = 5 the rate at r_esc = 3 is 0.900 ± 0.020 of that at 1.5 (shift −10.0 ± 2.0 %, "
        "z = −5.0: the larger radius lowers the rate)"
    )


def _survivors_doc(means, halves):
    """E0 = 0.3, σ = 0.02: the survivors' mean energies at t = 10, 55, 100 (error 0.002) and the rate's halves."""
    surv = [
        {
            "energy": 0.3,
            "sigma": 0.02,
            "t": t,
            "n_alive": 500,
            "ensemble_mean_energy": 0.3 + 0.0004 * t,
            "mean_energy": m,
            "mean_energy_err": 0.002,
            "below_ec": 0.74,
            "below_ec_err": 0.02,
        }
        for t, m in zip((10.0, 55.0, 100.0), means)
    ]
    (k1, e1), (k2, e2) = halves
    z = (k2 - k1) / (e1**2 + e2**2) ** 0.5
    rate = {
        "energy": 0.3,
        "sigma": 0.02,
        "rate_first_half": k1,
        "rate_first_half_err": e1,
        "rate_second_half": k2,
        "rate_second_half_err": e2,
        "halves_z": z,
        "constant_in_window": abs(z) < 3,
    }
    return {"no_drag_survivors": surv, "no_drag": [rate], "conventions": {"nodrag_window": [10.0, 100.0]}}


def test_the_survivors_reading_says_they_lost_energy_only_when_measured_so():
    lost = READINGS["noise.no_drag_survivors"](
        _loader({"noise": _survivors_doc((0.29, 0.194, 0.17), ((0.157, 0.004), (0.021, 0.003)))})
    )
    assert "0.2900 ± 0.0020 at t = 10, 0.1940 ± 0.0020 at t = 55, 0.1700 ± 0.0020 at t = 100" in lost
    assert "(below E0 by more than 2σ at every one of these times)" in lost
    assert "E0 + σ²t is 0.34 at t = 100; 74.0 ± 2.0 % of the 500 orbits inside at t = 100 lie below E_c" in lost
    assert "is not constant: 0.157 ± 0.004 on the first half, 0.021 ± 0.003 on the second (z = −27.2)" in lost
    assert "the orbits that stay have lost energy although the noise raises the ensemble's mean" in lost
    kept = READINGS["noise.no_drag_survivors"](
        _loader({"noise": _survivors_doc((0.299, 0.302, 0.301), ((0.157, 0.004), (0.150, 0.004)))})
    )
    assert "below E0 by more than 2σ at none of them" in kept and "constant within the halves' errors" in kept
    assert "have lost energy" not in kept
    assert "not in this scale's numbers" in READINGS["noise.no_drag_survivors"](_loader({"noise": {"no_drag": []}}))


def test_the_two_saddles_reading_compares_the_sum_its_lowest_term_and_the_exit_shares():
    def share(i, barrier, pred, meas, err):
        return {
            "exit": i,
            "barrier": barrier,
            "predicted": pred,
            "measured": meas,
            "measured_err": err,
            "z": (meas - pred) / err,
        }

    rec = {
        "barrier_over_T": 2.0,
        "ratio": 0.97,
        "ratio_err": 0.02,
        "ratio_lowest": 1.40,
        "ratio_lowest_err": 0.03,
        "exit_shares": [share(0, 1 / 6, 0.71, 0.70, 0.01), share(1, 0.24, 0.29, 0.30, 0.01)],
    }
    text = READINGS["noise.two_saddles"](_loader({"noise": {"two_saddles": {"records": [rec]}}}))
    assert text == (
        "at ΔE/T = 2 the rate over the two-saddle sum Σ_s k_KL,s is 0.970 ± 0.020, which agrees with 1 (z = −1.5), "
        "and over the lowest saddle's term alone (ΔE = 0.167) 1.40 ± 0.03, which differs from 1 (z = +13.3); the "
        "higher saddle (ΔE = 0.24) takes 0.300 ± 0.010 of the escapes in the window, against its term's share 0.290 "
        "of the sum, which agrees with it (z = +1.0)"
    )


def test_a_shift_that_rounds_to_zero_is_written_without_a_sign():
    row = {"barrier_over_T": 3, "r_esc": 3.0, "r_esc_default": 1.5, "rate_ratio": {"value": 0.997, "err": 0.05}}
    text = READINGS["noise.absorbing_radius"](_loader({"noise": {"absorbing_radius": [row]}}))
    assert "(shift 0 ± 5 %, z = −0.1: no shift resolved at 2σ)" in text


def _turnover_row(gamma, ratio, err, barrier, holds):
    return {"gamma": gamma, "ratio_mm": ratio, "ratio_mm_err": err, "barrier_over_T": barrier,
            "theory_assumptions_hold": holds}  # fmt: skip


def test_the_turnover_barriers_reading_states_the_range_within_fifteen_percent_and_the_low_gamma_excess():
    """A ratio is within 15 % when its 2σ interval lies inside [0.85, 1.15]: 1.167 ± 0.019 reaches 1.129 to 1.205
    and 1.123 ± 0.017 reaches 1.089 to 1.157 (undecided), 0.700 ± 0.010 lies outside (beyond), 1.10 ± 0.02 inside.
    The excess at γ = 0.003 falls from 16.7 % to 10.0 %: −6.7 ± √(1.9² + 2.0²) = −6.7 ± 2.8 points (z = −2.4);
    scaled by 3/5 the first would be 10.0 ± 1.1 %, which 10.0 ± 2.0 % matches (z = 0)."""
    lo = [_turnover_row(g, r, e, 3.0, g < 1) for g, r, e in
          ((0.003, 1.167, 0.019), (0.01, 1.123, 0.017), (0.03, 1.045, 0.015), (0.1, 1.017, 0.014), (1.0, 0.70, 0.01))]  # fmt: skip
    hi = [_turnover_row(g, r, 0.02, 5.0, g < 1) for g, r in ((0.003, 1.10), (0.01, 1.05), (0.03, 1.0), (0.1, 0.98), (1.0, 0.95))]  # fmt: skip
    text = READINGS["noise.turnover_barriers"](_loader({"noise": {"turnover": lo, "turnover_high": hi}}))
    assert (
        "at ΔE/T = 3 the rate over Υ(δ) k_KL is within 15 % from γ = 0.03 to 0.1; beyond 15 % at γ = 1 "
        "(0.700 ± 0.010); undecided at 15 % at γ = 0.003 (1.167 ± 0.019), 0.01 (1.123 ± 0.017)" in text
    )
    assert (
        "at ΔE/T = 5 the rate over Υ(δ) k_KL is within 15 % from γ = 0.003 to 1 (the theory's range: γ ≤ 0.1)" in text
    )
    assert "16.7 ± 1.9 % at ΔE/T = 3 and 10.0 ± 2.0 % at 5: it shrinks by 6.7 ± 2.8 points (z = −2.4)" in text
    assert "an excess ∝ T/ΔE would be 10.0 ± 1.1 % at 5" in text
    one = READINGS["noise.turnover_barriers"](_loader({"noise": {"turnover": lo}}))
    assert one == "the turnover at a second barrier is not in this scale's numbers"


def test_the_two_saddle_turnover_reading_compares_each_end_with_its_limit():
    def row(g, ratio, ratio_ed, ratio_mm, high_share):
        saddles = [{"barrier": 1 / 6, "delta": 20 * g, "melnikov_meshkov": 1 - high_share},
                   {"barrier": 0.24, "delta": 30 * g, "melnikov_meshkov": high_share}]  # fmt: skip
        return {"gamma": g, "ratio": ratio, "ratio_err": 0.01, "ratio_ed": ratio_ed, "ratio_ed_err": 0.01,
                "ratio_mm": ratio_mm, "ratio_mm_err": 0.02, "melnikov_meshkov": 1.0, "saddles": saddles}  # fmt: skip

    doc = {"barrier_over_T": 3.0, "records": [row(3.0, 1.05, 9.0, 1.05, 0.05), row(0.01, 0.17, 0.70, 1.20, 0.2)]}
    text = READINGS["noise.saddles_turnover"](_loader({"noise": {"two_saddles_turnover": doc}}))
    assert "from γ = 0.01 to 3, the rate over the sum Σ_s Υ(δ_s) k_KL,s is within 15 % at γ = 3 only" in text
    assert "beyond 15 % at γ = 0.01 (1.200 ± 0.020)" in text
    assert "At γ = 3 the rate over the Kramers–Langer sum is 1.050 ± 0.010, which differs from 1 (z = +5.0)" in text
    assert "0.700 ± 0.010 of the energy-diffusion limit" in text
    assert "share of the theory's sum is 0.200 at γ = 0.01 and 0.050 at 3 (its δ_s = 0.3 at γ = 0.01" in text
    empty = READINGS["noise.saddles_turnover"](_loader({"noise": {}}))
    assert empty == "the two-saddle system's turnover is not in this scale's numbers"


def test_kappa_over_alpha_against_the_decision_rate_by_energy():
    """κ/α within 2σ (the 1σ of both combined) of λ or not, energy by energy; an energy without κ/α is left out."""
    from hhscatter.publish.readings import reading

    scan = [
        {"energy": 0.19, "lam": 0.23, "lam_err": 0.01, "lam_kg": 0.19, "lam_kg_err": 0.01},  # 0.04 > 2·0.0141
        {"energy": 0.25, "lam": 0.41, "lam_err": 0.01, "lam_kg": 0.40, "lam_kg_err": 0.01},  # 0.01 < 2·0.0141
        {"energy": 0.5, "lam": 0.77, "lam_err": 0.01, "lam_kg": None, "lam_kg_err": None},
    ]
    text = reading(lambda study, scale: {"energy_scan": scan}, "basins.kantz_grassberger")
    assert text == "κ/α and λ are more than 2σ apart at E = 0.19; κ/α lies within 2σ of λ at E = 0.25"


def test_the_scan_finds_the_comparisons_that_were_typed():
    """The comparative sentences the study pages typed before their comparisons were generated are found."""
    typed = [
        "one plausible reason why the measured ε_c lies\n  below the prediction.",
        "the κ(E) law still differs from the paper's below E_b in every\n      convention.",
        "In our own construction (5b = 5a filtered to the band) 5b is clearly farther,",
        "| none (d > δ at every scale) |",
        "No like-for-like row differs\n      from zero at the quick scale; at the paper scale one does",
        "The measured P(t) drops below the extension during the transient",
        "the two halves of every heat-bath window are compared (all within",
        "is below the 0.1 that fig5 uses as its tolerance. But only the *sprinkler* measure does.",
        "its ε*_δ is twice as large, and its λ larger than κ/α; the quick fit is better, the paper's worse",
        "the rate exceeds the prediction and is consistent",
        "μ measured from ⟨E⟩(t) hardly moves",
        "but the prediction from the\nconservative ⟨K⟩ crosses it:",
        "refinement and crosses fig2's κ0 (the finest-partition table below)",
        "(Barbanis): close to Eq. (eq:tau2)'s 1/γ.",
        "so they differ slightly from fig2–fig4.",
        "so 0.91 stands for [0.905, 0.915), far wider than our error.",
        "the intervals of the two-reference comparison are slightly narrow",
        "λ∞ is far below ΣΛ/ΣT",
        "roughly the same",
        "nearly constant",
        "essentially unchanged",
        "clearly farther",
        "about the same rate",
        "much larger",
        "well above 1",
    ]
    missed = [t for t in typed if not typed_readings(t)]
    assert not missed, missed
    # explanations and definitions that are no comparison of results stay free of the scan
    assert typed_readings("the two halves of every window are compared; a ring of box sides below 1/16") == []
    # a crossing of the section, an orbit that crosses a radius, the potential well below E: no reading
    assert typed_readings("the first crossing of the section; an orbit crosses r_esc; the well below E") == []


def test_interval_side_reads_the_interval_not_the_value():
    from hhscatter.publish.readings import interval_side

    assert interval_side(0.046, 0.060, 0.0) == "above" and interval_side(-0.02, -0.001, 0.0) == "below"
    assert interval_side(-0.01, 0.02, 0.0) == "straddles" and interval_side(0.032, 0.038, 0.1) == "below"


def test_the_5b_reading_follows_the_sign_of_the_interval():
    def doc(lo, hi):
        return {"verdict_5b": {"rows": [{"construction": "ours", "delta": (lo + hi) / 2, "delta_interval": [lo, hi]}]}}

    farther = READINGS["fig5.ours_5b"](_loader({"fig5": doc(0.04, 0.06)}))
    assert farther.startswith("5b lies farther from μ_c^0.30 than 5a: Δ = d(5b) − d(5a) = +0.050")
    assert READINGS["fig5.ours_5b"](_loader({"fig5": doc(-0.06, -0.04)})).startswith("5b lies nearer")
    assert READINGS["fig5.ours_5b"](_loader({"fig5": doc(-0.01, 0.03)})).startswith("5b and 5a are as near")


def test_the_law_reading_judges_every_convention_with_the_papers_half_unit():
    """a = 13.0 ± 0.3 in one convention is 2.1σ from the paper's 13.63 (± 0.005): differs; 13.1 is 1.8σ: agrees."""
    law = {
        p: {"err_stat": e, "per_convention": {"one": v1, "two": v2}}
        for p, e, v1, v2 in (("a", 0.3, 13.0, 13.1), ("b", 0.01, 0.2, 0.3))
    }
    comp = [
        {"quantity": "a (κ(E) law across conventions)", "paper": 13.63, "paper_err": 0.005},
        {"quantity": "b (κ(E) law across conventions)", "paper": 0.03, "paper_err": 0.005},
    ]
    text = READINGS["fig2.law_below_break"](
        _loader({"fig2": {"kappa_conventions": {"law": law}, "paper_comparison": comp}})
    )
    assert text == (
        "a against the paper's 13.63: differs at one; agrees at two; "
        "b differs from the paper's 0.03 in every convention (one, two)"
    )


def test_the_reactivation_reading_fails_beyond_two_standard_errors_only():
    def doc(sigma, ratio):
        r = {"model_max_deviation": 0.2, "model_max_deviation_at": 25.0, "model_max_deviation_sigma": sigma}
        return {"reactivation": {**r, "tail_over_thermal": {"value": ratio, "err": 0.02}}}

    text = READINGS["noise.reactivation"](_loader({"noise": doc(43.8, 1.02)}))
    assert text.startswith("fails in the transient: it differs from the measured P(t) by up to 0.200 (at t = 25")
    assert "after it the measured tail decays at the thermal rate (ratio 1.020 ± 0.020, z = +1.0 against 1)" in text
    text = READINGS["noise.reactivation"](_loader({"noise": doc(1.5, 1.10)}))
    assert text.startswith("holds within 2 standard errors") and "does not decay at the thermal rate" in text


def test_the_operator_reading_sorts_each_measure_by_its_interval_against_the_tolerance():
    rows = [
        {
            "measure": m,
            "fig1_energy": 0.3,
            "operator_energy": 0.3,
            "hellinger_debiased": (lo + hi) / 2,
            "hellinger_debiased_lo": lo,
            "hellinger_debiased_hi": hi,
        }
        for m, lo, hi in (("sprinkler", 0.03, 0.04), ("flux", 0.09, 0.12), ("map", 0.4, 0.5))
    ]
    docs = {"operator": {"cmeasure_distances": rows}, "fig5": {"panel_d": {"delta": 0.1}}}
    text = READINGS["operator.tolerance"](_loader(docs))
    assert "lies below fig5's tolerance δ = 0.1 for sprinkler 0.035 [0.030, 0.040]" in text
    assert "above δ = 0.1 for map 0.450" in text and "with an interval that holds δ = 0.1 for flux" in text


def _outside_scale_notes(text: str) -> str:
    """A page without its folded "Quick scale vs paper scale" notes (the indented block under the note's line)."""
    out, inside = [], False
    for line in text.split("\n"):
        if line.startswith("??? note") and "Quick scale" in line:
            inside = True
        elif inside and line.strip() and not line.startswith("    "):
            inside = False
        out.append("" if inside else line)
    return "\n".join(out)


def quick_quotes_the_headline_holds(text: str, holds) -> list[str]:
    """The references of a page to its study's other scale (``[[study@quick:…]]``), outside the scale-change note,
    whose number the headline scale holds too (``holds(study, path)``), unless their paragraph quotes it beside the
    same number at the headline scale or beside a number that only the quick scale has (a comparison made at one
    scale): such a number is read at the scale of the run that made the page's claims."""
    from hhscatter.publish.numbers import REF

    found = []
    for para in re.split(r"\n\s*\n", _outside_scale_notes(text)):
        refs = [m for m in REF.finditer(para)]
        quick = [m for m in refs if m.group("scale") == "quick"]
        only_quick = any(not holds(m.group("study"), m.group("path")) for m in quick)
        for m in quick:
            beside = any(
                r.group("scale") != "quick"
                and (r.group("study"), r.group("path")) == (m.group("study"), m.group("path"))
                for r in refs
            )
            if holds(m.group("study"), m.group("path")) and not (beside or only_quick):
                found.append(m.group(0))
    return found


def _headline_holds(study: str, path: str) -> bool:
    from hhscatter.publish.numbers import NumberRefError, headline_scale, resolve

    if headline_scale(ROOT, study) == "quick":
        return False
    try:
        resolve(load_numbers(ROOT, study, "paper")[0], path)
    except (NumberRefError, KeyError, IndexError, TypeError, ValueError, StopIteration):
        return False
    return True


def test_the_scan_finds_a_quick_number_where_the_headline_scale_has_it():
    have = {("g", "a"), ("g", "a.verdict"), ("g", "b")}

    def holds(study, path):
        return (study, path) in have

    page = (
        "The shift is [[g@quick:a]] ([[g@quick:a.verdict]]).\n\n"
        "Quick [[g@quick:b]] against paper [[g:b]].\n\n"
        "The other convention [[g@quick:c]] beside its disk value [[g@quick:a]].\n\n"
        '??? note "Quick scale vs paper scale"\n\n    [[g@quick:a]] → [[g:a]]\n\nAfter [[g:a]].'
    )
    assert quick_quotes_the_headline_holds(page, holds) == ["[[g@quick:a]]", "[[g@quick:a.verdict]]"]


@pytest.mark.parametrize("page", PAGES + RESULT_PAGES, ids=lambda p: p.parent.name if p.name == "page.md" else p.name)
def test_a_page_reads_its_claims_at_the_headline_scale(page):
    """A number the headline (paper-scale) record holds is not quoted from the quick scale, whose verdict may
    differ (generality's r_esc shift of κ0: "no shift resolved" at the quick scale, "shifts" at the paper scale)."""
    found = quick_quotes_the_headline_holds(page.read_text(), _headline_holds)
    assert not found, f"{page.relative_to(ROOT)}: quick-scale numbers the paper scale holds: {found}"


def test_the_resc_shift_reading_sorts_each_energy_by_its_verdict():
    def row(ratio, conv, verdict, value=None, err=None):
        shift = {"value": value, "err": err}
        return {"label": "hh", "e_ratio": ratio, "convention": conv, "r_esc": 1.03, "verdict": verdict, "shift": shift}

    doc = {
        "systems": {"hh": {}},
        "resc_kappa": [
            row(1.8, "plateau", "shifts (z = +4.3)", 0.044, 0.010),
            row(1.2, "plateau", "no shift resolved (z = +0.7)", 0.02, 0.03),
            row(2.6, "plateau", "undetermined: κ0 ill-defined at r_esc = 1.5"),
        ],
    }
    text = READINGS["generality.resc_shift"](_loader({"generality": doc}))
    assert "For hh (r_esc = 1.03), all orbits: shifts at 1.8 E_c (0.044 ± 0.010)" in text
    assert "no shift resolved at 1.2 E_c" in text and "undetermined (κ0 ill-defined at a radius) at 2.6 E_c" in text
    assert "Escaping orbits" not in text  # no row of that convention


def test_the_map_coverage_reading_names_the_grid_energies_without_a_cell():
    cells = [{"label": "hh", "e_ratio": x} for x in (1.05, 1.5, 5.0)]
    doc = {"scale": "paper", "systems": {"hh": {}}, "validity_map": cells}
    doc["config"] = {"study": {"ratios": [1.05, 1.5, 1.7, 2.2]}}
    text = READINGS["generality.map_coverage"](_loader({"generality": doc}))
    assert text == "the map (paper scale) has hh 3 cells, the claims' grid without 1.7, 2.2 E_c and 5 E_c beyond it"
    doc["validity_map"] = [{"label": "hh", "e_ratio": x} for x in (1.05, 1.5, 1.7, 2.2)]
    text = READINGS["generality.map_coverage"](_loader({"generality": doc}))
    assert text == "the map (paper scale) has hh 4 cells, the whole claims' grid"


def test_the_resc_readings_follow_the_shifts_and_their_errors():
    def shift(v, e):
        return {"shift_vs_ref": {"value": v, "err": e}}

    ref = shift(0.0, 0.0)
    paper = {
        "r_ref": 1.03,
        "kappa": {
            "E=0.25": {"r_esc=1.03": ref, "r_esc=1.5": shift(-0.001, 0.001), "r_esc=2": shift(-0.0012, 0.001)},
            "E=0.30": {"r_esc=1.03": ref, "r_esc=1.5": shift(-0.008, 0.001), "r_esc=2": shift(-0.002, 0.001)},
        },
    }
    quick = copy.deepcopy(paper)
    quick["kappa"]["E=0.30"]["r_esc=1.5"] = shift(-0.004, 0.002)
    text = READINGS["resc.shifts"](_loader({"resc": paper}))
    assert text.startswith("at E = 0.25 no shift is resolved from zero (|z| ≤ 1.2), the radii's shifts agree")
    assert (
        "at E = 0.30 every shift lies 2.0–8.0σ from zero, the radii's shifts differ (largest difference 4.2σ)" in text
    )
    moves = READINGS["resc.scale_moves"](lambda study, scale: quick if scale == "quick" else paper)
    assert moves.startswith("the κ shifts moved by at most 2.0σ of their quick-scale errors (the largest at E = 0.30")


def test_the_validity_reading_splits_the_cells_at_1_percent_by_the_total_error():
    cells = [
        {"label": "a", "e_ratio": 1.1, "kappa0_defined": True, "regular_fraction": 0.008, "regular_err_total": 0.004},
        {"label": "a", "e_ratio": 1.5, "kappa0_defined": True, "regular_fraction": 0.002, "regular_err_total": 0.001},
        {"label": "a", "e_ratio": 1.05, "kappa0_defined": False, "regular_fraction": 0.3, "regular_err_total": 0.05},
    ]
    text = READINGS["generality.validity"](_loader({"generality": {"validity_map": cells}}))
    assert "of the 3 cells of the map with a κ0 verdict, 1 have a regular fraction below 1 % with its total" in text
    assert "Of the 1 cells at or above 1 % with it, κ0 is defined at 0" in text
    assert "the total error reaches across 1 % at a 1.1" in text and "Both conditions are met for a at 1.5 E_c" in text


def test_the_indicator_systematic_reading_sums_the_labelled_cells_and_names_the_largest():
    """Two labelled cells (b: indicator 1.44 % below threshold 4.3 %; c: indicator 4.5 % above threshold 1 %) and one
    without: 900 orbits, 24 undecided, 27 and 5 disagreements; the indicator the larger in 1 of 2 cells, largest at
    c; the largest total error hypot(0.5, 1, 4.5) % = 4.6 % at c (b: hypot(0.5, 4.3, 1.44) % = 4.56 %)."""

    def rec(label, n_band, to_chaotic, to_regular, syst_ind, syst):
        L = {"t_label": 3000.0, "ftle_regular": 0.003, "ftle_chaotic": 0.005, "n_labelled": 450, "n_band": n_band}
        L |= {"n_band_labelled": 400, "n_undecided": 12, "disagree_to_chaotic": to_chaotic}
        L |= {"disagree_to_regular": to_regular, "disagree_outside": 1, "shift": 0.0, "syst": syst_ind}
        return {"label": label, "e_ratio": 1.05, "fraction": 0.6, "syst": syst, "syst_indicator": syst_ind} | {
            "err_total": math.hypot(0.005, syst, syst_ind),
            "labelled": L,
        }

    doc = {"regular_fraction": [rec("b", 5754, 7, 3, 0.0144, 0.043), rec("c", 8237, 20, 2, 0.045, 0.01)]}
    doc["regular_fraction"].append({"label": "h", "e_ratio": 2.0, "fraction": 0.0, "labelled": None})
    text = READINGS["generality.indicator_systematic"](_loader({"generality": doc}))
    assert text.startswith("The labelled sets: 2 cells, 900 orbits, 24 of them undecided; in the bands 27")
    assert "27 orbits are regular by the shadow and chaotic by the FTLE and 5 the reverse" in text
    assert "the larger of the two in 1 of 2 cells and largest at c 1.05 E_c (4.5 %, threshold systematic 1 %)" in text
    assert "the largest total error is at c 1.05 E_c, 60 % ± 4.6 %" in text
    assert " h " not in text
    doc["regular_fraction"] = doc["regular_fraction"][2:]
    assert READINGS["generality.indicator_systematic"](_loader({"generality": doc})).startswith("No cell")


def _mu_rows(pred_default, pred_second):
    """generality's r_esc rows of one system: measured μ 0.94 ± 0.001 at both radii on the paper's window, the given
    predictions ± 0.002; a row on another window that the reading must not read."""
    row = {"label": "hh", "window": [0.0, 200.0], "mu_measured": {"value": 0.94, "err": 0.001}}
    return {
        "systems": {"hh": {"mu_by_window": {"paper": {"window": [0.0, 200.0]}}}},
        "resc": [
            {**row, "r_esc": 1.5, "default": True, "mu_predicted": {"value": pred_default, "err": 0.002}},
            {**row, "r_esc": 1.03, "default": False, "mu_predicted": {"value": pred_second, "err": 0.002}},
            {**row, "window": [0.0, 64.0], "r_esc": 1.03, "default": False, "mu_predicted": {"value": 0.5, "err": 0.1}},
        ],
    }


def test_the_mu_reading_says_crosses_only_when_both_sides_are_resolved():
    """The μ prediction "crosses" the measured μ between the radii only when it lies more than 2σ below it at one
    radius and more than 2σ above it at the other (z = ∓0.01/√(0.001² + 0.002²) = ∓4.5); at 0.939 it lies within 2σ
    (z = −0.4), and the reading says where the two agree."""
    text = READINGS["generality.mu_radius"](_loader({"generality": _mu_rows(0.93, 0.95)}))
    assert "the measured μ does not move resolved at 2σ" in text
    assert "lies below it (z = −4.5) at r_esc = 1.5 (the default) and above it (z = +4.5) at 1.03" in text
    assert "it crosses the measured μ between the radii; the prediction moves" in text and "z = +7.1)" in text
    assert text.endswith("within 2σ for hh at neither radius")
    text = READINGS["generality.mu_radius"](_loader({"generality": _mu_rows(0.939, 0.95)}))
    assert "lies within 2σ of it (z = −0.4) at r_esc = 1.5" in text and "crosses" not in text
    assert text.endswith("within 2σ for hh at 1.5")


def test_the_generality_page_reads_mu_against_the_radius_from_the_numbers():
    """The μ sentence of the r_esc paragraph is the generated reading, not typed words ("hardly moves", "crosses")."""
    page = (ROOT / "studies" / "generality" / "page.md").read_text()
    assert "[[reading:generality.mu_radius]]" in page
    assert "hardly" not in page and "crosses it" not in page


def test_the_operator_reading_at_the_mixed_energy_says_crosses_only_when_both_sides_are_resolved():
    """Ulam's κ on the finest boxes against fig2's κ0 at E = 0.20, per scale: 0.030 ± 0.002 against 0.022 ± 0.001 is
    above (z = +3.6), 0.015 ± 0.002 below (z = −3.1): from one side to the other; at 0.025 the quick side is within
    2σ (z = +1.3) and nothing crosses."""

    def doc(kappa, box):
        row = {"energy": 0.2, "kappa": kappa, "err": 0.002, "box": box, "fig2_kappa": 0.022, "fig2_err": 0.001}
        return {"kappa_ulam": [row, {**row, "energy": 0.3}]}

    def text(k_quick):
        docs = {"quick": doc(k_quick, 0.0125), "paper": doc(0.015, 0.00625)}
        return READINGS["operator.mixed_refinement"](lambda study, scale: docs[scale])

    out = text(0.030)
    assert "0.0300 ± 0.0020 on boxes of side 0.0125 (quick scale), above fig2's κ0 (z = +3.6)" in out
    assert "below fig2's κ0 (z = −3.1)" in out and out.endswith("from one side of fig2's κ0 to the other")
    assert "it falls from side 0.0125 to 0.00625" in out
    out = text(0.025)
    assert "within 2σ of fig2's κ0 (z = +1.3)" in out and "other side" not in out and "to the other" not in out


def _saddle_point(system, ratio, b, b_err, t_min):
    return {"system": system, "ratio": ratio, "t_min": t_min, "lyapunov_detail": {"b": {"value": b, "err": b_err}}}


def test_the_saddle_offset_reading_sorts_the_points_by_the_sign_of_their_resolved_one_over_t_term():
    """Λ₀ = 10 ± 2 (z = 5) puts λ∞ below ΣΛ/ΣT, −1 ± 0.2 above, 0.3 ± 0.2 (z = 1.5) resolves nothing; t_min is
    given as a share of its system's own t_max (400 for "c", else the study's 200)."""
    config = {"study": {"t_max": 200.0, "systems": [{"label": "henon_heiles"}, {"label": "c", "t_max": 400.0}]}}
    points = [
        _saddle_point("henon_heiles", 1.2, 0.3, 0.2, 150.0),
        _saddle_point("henon_heiles", 3.0, -1.0, 0.2, 20.0),
        _saddle_point("c", 1.7, 10.0, 2.0, 300.0),
    ]
    text = READINGS["saddle.lambda_offset"](_loader({"saddle": {"config": config, "saddle": points}}))
    assert text == (
        "Λ₀ > 0 by more than 2σ, λ∞ below ΣΛ/ΣT, at c E/E_c = 1.7 (Λ₀ = 10.0 ± 2.0, t_min = 0.75 t_max). "
        "Λ₀ < 0 by more than 2σ, λ∞ above ΣΛ/ΣT, at Hénon–Heiles E/E_c = 3 (Λ₀ = −1.00 ± 0.20, t_min = 0.10 t_max). "
        "Λ₀ within 2σ of 0 at the other point (t_min 0.75 t_max)"
    )
    flat = [_saddle_point("henon_heiles", 1.2, 0.3, 0.2, 150.0), _saddle_point("henon_heiles", 1.5, 0.1, 0.2, 50.0)]
    text = READINGS["saddle.lambda_offset"](_loader({"saddle": {"config": config, "saddle": flat}}))
    assert text == "Λ₀ within 2σ of 0 at all 2 points (t_min from 0.25 to 0.75 t_max)"


@pytest.mark.parametrize("scale", ["quick", "paper"])
def test_the_saddle_offset_reading_renders_at_both_scales(scale):
    """The saddle page renders from either scale's JSON (paper when committed, else quick): its reading reads both."""
    text = READINGS["saddle.lambda_offset"](lambda study, _: load_numbers(ROOT, study, scale)[0])
    doc = load_numbers(ROOT, "saddle", scale)[0]
    fitted = [p for p in doc["saddle"] if (p.get("lyapunov_detail") or {}).get("b")]
    assert text.count(" (Λ₀ = ") + int(re.search(r"at (?:the other|all) (\d+) points", text).group(1)) == len(fitted)


def test_the_saddle_no_lyapunov_reading_tests_how_the_exponents_move_with_the_lifetime():
    """A point without λ̄: λ̄(T) 0.074 ± 0.002 → 0.044 ± 0.001 (z = −13.4) "falls to"; 0.060 ± 0.002 → 0.061 ± 0.002
    "stays at"; a point with λ̄ or without bins of T is not named; with none left the reading says so."""

    def pt(system, ratio, a, b, lam=None, **kw):
        det = {"by_T": [{"T": 380.0, **a}, {"T": 560.0, **b}], "extrapolated": -0.02, "extrapolated_err": 0.005}
        return {"system": system, "ratio": ratio, "lyapunov": lam, "lyapunov_detail": det, **kw}

    hyp = {"threshold": 0.5, "shares": [{"threshold": 0.5, "share": {"value": 0.12, "err": 0.01}}]}
    points = [
        pt(
            "barbanis",
            1.9,
            {"value": 0.074, "err": 0.002},
            {"value": 0.044, "err": 0.001},
            hyperbolic=hyp,
            d1=0.70,
            d1_err=0.02,
            d1_lines={"value": 0.75, "err": 0.02},
        ),
        pt("contopoulos", 1.7, {"value": 0.060, "err": 0.002}, {"value": 0.061, "err": 0.002}),
        pt("henon_heiles", 1.5, {"value": 0.41, "err": 0.002}, {"value": 0.40, "err": 0.002}, lam=0.41),
        {"system": "henon_heiles", "ratio": 3.0, "lyapunov": None, "lyapunov_detail": {}},
    ]
    text = READINGS["saddle.no_lyapunov"](_loader({"saddle": {"saddle": points}}))
    assert text == (
        "no λ̄ at Barbanis E/E_c = 1.9 (λ̄(T) = 0.0740 ± 0.0020 at T = 380 falls to 0.0440 ± 0.0010 at T = 560, "
        "z = −13.4; λ∞ = −0.020 ± 0.005; Λ/T below 0.5·ΣΛ/ΣT at a share 0.120 ± 0.010 of the orbits; "
        "d₁ = 0.700 ± 0.020 on the section, 0.750 ± 0.020 on lines); Contopoulos E/E_c = 1.7 (λ̄(T) = 0.0600 ± "
        "0.0020 at T = 380 stays at 0.0610 ± 0.0020 at T = 560, z = +0.4; λ∞ = −0.020 ± 0.005)"
    )
    text = READINGS["saddle.no_lyapunov"](_loader({"saddle": {"saddle": points[2:]}}))
    assert text == "every point of this scale with a 1/T fit has λ̄"


def _b_docs(b_generality, err_generality):
    """fig2 with b = 0.25 ± 0.025 against E − E_c (E_c = 0.2: b·E_c = 0.05 ± 0.005, 10σ from 0) below E_b = 0.3,
    and generality's b in ε = E/E_c − 1 below ε_b = 0.6."""
    fig2 = {
        "E_c": 0.2,
        "kappa_fit": {"b": {"value": 0.25, "err": 0.025}, "E_b": {"value": 0.3, "err": 0.003}},
        "config": {
            "study": {"grid_n": 1000, "grid_energies": [0.21, 0.3, 0.4]},
            "scene": {"r_esc": 1.03, "t_max": 500},
        },
    }
    claims = [
        {"id": "henon_heiles-1-5", "value": b_generality, "err": err_generality},
        {"id": "henon_heiles-1-4", "value": 0.6, "err": 0.1},
    ]
    generality = {
        "claims": claims,
        "config": {"study": {"ratios": [1.05, 2.0], "grid_n": 500}, "scene": {"t_max": 800}},
    }
    return {"fig2": fig2, "generality": generality}


def test_the_b_relation_reading_compares_the_two_in_one_variable_and_says_resolved_only_beyond_two_sigma():
    """0.08 ± 0.07 against b·E_c = 0.05 ± 0.005: z = 0.03/√(0.07² + 0.005²) = +0.4, generality 1.1σ from 0; 0.30 ±
    0.02: z = 0.25/0.0206 = +12.1, 15σ from 0."""
    text = READINGS["b_relation"](_loader(_b_docs(0.08, 0.07)))
    assert "below its break E_b = 0.300 ± 0.003 (ε_b = 0.50), of 3 energies from 0.21 to 0.4" in text
    assert "it is b·E_c = 0.050 ± 0.005" in text and "fitted below its break ε_b = 0.60 ± 0.10" in text
    assert text.endswith(
        "The two agree (z = +0.4); generality's error is 14 times fig2's: fig2 resolves b from 0 (10σ), "
        "generality does not resolve b from 0 (1.1σ)"
    )
    text = READINGS["b_relation"](_loader(_b_docs(0.30, 0.02)))
    assert text.endswith(
        "The two differ (z = +12.1); generality's error is 4 times fig2's: fig2 resolves b from 0 (10σ), "
        "generality resolves b from 0 (15σ)"
    )


def _law_docs(beta, beta_err):
    """One system, two conventions: "p" with a = 1, b = 0.1, break 0.5, defined at ε = 0.1 and 0.3 (slope
    (2aε + b)/(aε + b) = 1.5 at 0.1 and 1.1/0.6 = 1.83 at 0.5; b/(aε) = 1 and 0.2); "q" with a ≤ 0 (no slope)."""
    law = {"a": {"value": 1.0, "err": 0.1}, "b": {"value": 0.1, "err": 0.01}, "eps_b": {"value": 0.5, "err": 0.1}}
    kappa = [
        {"system": "s", "convention": "p", "eps": e, "defined": ok}
        for e, ok in ((0.05, False), (0.1, True), (0.3, True))
    ]
    return {
        "generality": {
            "systems": {"s": {"kappa_law": {"p": law, "q": {**law, "a": {"value": -1.0, "err": 0.1}}}}},
            "kappa": kappa,
            "claims": [{"id": "s-1-2", "value": beta, "err": beta_err, "reference": 2.0}],
        }
    }


def test_the_law_slope_reading_computes_the_local_slope_at_both_ends_and_places_beta_by_two_sigma():
    text = READINGS["generality.law_slope"](_loader(_law_docs(1.6, 0.05)))
    assert "p (ε 0.10 to 0.50): b/(a ε) 1 → 0.2, slope 1.50 → 1.83" in text and "q (" not in text
    assert (
        "β = 1.60 ± 0.05 lies inside the range of these slopes (1.50 to 1.83): the two fits do not contradict" in text
    )
    assert "lies within 2σ of the range" in READINGS["generality.law_slope"](_loader(_law_docs(1.45, 0.05)))
    assert "lies below these slopes (1.50 to 1.83) by more than 2σ" in READINGS["generality.law_slope"](
        _loader(_law_docs(1.2, 0.05))
    )
    assert "lies above these slopes" in READINGS["generality.law_slope"](_loader(_law_docs(2.2, 0.1)))


def _excess_docs(value, err):
    claims = [
        {"id": "a-7-0", "claim": "7", "quantity": "ratio", "system": "a", "value": value, "err": err, "reference": 1.0},
        {
            "id": "b-7-0",
            "claim": "7",
            "quantity": "ratio",
            "system": "b",
            "value": None,
            "err": None,
            "reference": None,
        },
    ]
    return {"generality": {"systems": {"a": {}, "b": {}}, "claims": claims}}


def test_the_escape_excess_reading_names_the_mechanism_only_for_an_excess_beyond_two_sigma():
    """1.08 ± 0.002 is 40σ above 1 (more often, the convex κ0's mechanism); 1.002 ± 0.002 is 1σ (no side); 0.9 ±
    0.01 is 10σ below (less often); a record without a value is undetermined."""
    text = READINGS["generality.escape_excess"](_loader(_excess_docs(1.08, 0.002)))
    assert text.startswith(
        "a escapes 1.0800 ± 0.0020 times as often as κ0 at E0 e^(−μγt) predicts (differs (z = +40.0))"
    )
    assert ": more often, as the energy spread makes the mean of a convex κ0(E_i) exceed" in text
    assert text.endswith(
        "; undetermined for b (τ0 comes after E(t) has reached the lowest energy with a defined κ0; "
        "the claims' table gives the times)"
    )
    text = READINGS["generality.escape_excess"](_loader(_excess_docs(1.002, 0.002)))
    assert "(agrees (z = +1.0))" in text and "more often" not in text and "less often" not in text
    assert ": less often" in READINGS["generality.escape_excess"](_loader(_excess_docs(0.9, 0.01)))


def _gap_docs(predicted):
    win = {
        "window": [0.0, 200.0],
        "measured": {"value": 0.95, "err": 0.0001},
        "predicted_c_measure": {"value": predicted, "err": 0.0001},
    }
    return {
        "generality": {
            "systems": {"s": {"mu_by_window": {"paper": win}}},
            "claims": [{"id": "s-3-0", "value": 0.95, "err": 0.0001, "reference": 0.91}],
        }
    }


def test_the_mu_gap_reading_propagates_the_papers_last_digit_and_words_the_share_by_two_sigma():
    """Paper 0.91 (± 0.005), measured 0.95: the gap is 0.04. Predicted 0.94 covers 0.75 of it, σ ≈ 0.005·0.01/0.04²
    = 0.031 (the paper's digit dominates): more than half. 0.95 covers all of it; 0.925 covers 0.375 ± 0.078, not
    resolved from one half; 0.89 lies on the other side of 0.91 (−0.5 ± 0.16): none of it."""
    text = READINGS["generality.mu_gap"](_loader(_gap_docs(0.94)))
    assert text.startswith("on [0, 200] the prediction from the conservative ⟨K⟩ covers 0.75 ± 0.03 of the gap")
    assert "the paper's 0.91 (± 0.005, half its last digit)" in text
    assert text.endswith(": more than half of it, by more than 2σ")
    assert READINGS["generality.mu_gap"](_loader(_gap_docs(0.95))).endswith(": all of it within 2σ")
    assert READINGS["generality.mu_gap"](_loader(_gap_docs(0.925))).endswith(
        ": a share not resolved from one half at 2σ"
    )
    assert READINGS["generality.mu_gap"](_loader(_gap_docs(0.89))).endswith(
        ": none of it (the prediction lies on the other side of the paper's value by more than 2σ)"
    )


def _smooth_docs(e_smooth, e_none, eb, eb_err):
    trend = {"E_smooth_S_b": e_smooth, "E_no_trapped": e_none}
    return {"basins": {"energy_trend": trend, "E_b": {"value": eb, "err": eb_err}}}


def test_the_smooth_order_reading_places_the_change_on_the_scan_grid_and_against_the_break_by_two_sigma():
    """E* = 0.26 against the last censored energy 0.24 (above) and E_b = 0.2755 ± 0.0026 (0.26 < 0.2703: below);
    E* = 0.24 = 0.24 (at, as the quick scale has it); E* = 0.275 within 2σ of 0.2755 (0.2703 to 0.2807)."""
    text = READINGS["basins.smooth_order"](_loader(_smooth_docs(0.26, 0.24, 0.2755, 0.0026)))
    assert text == (
        "above the energy from which no orbit is left censored at t_max (0.24) and below fig2's break energy "
        "E_b = 0.2755 ± 0.0026 by more than 2σ"
    )
    assert READINGS["basins.smooth_order"](_loader(_smooth_docs(0.24, 0.24, 0.2755, 0.0026))).startswith("at the")
    assert READINGS["basins.smooth_order"](_loader(_smooth_docs(0.22, 0.24, 0.2755, 0.0026))).startswith("below the")
    assert READINGS["basins.smooth_order"](_loader(_smooth_docs(0.275, 0.24, 0.2755, 0.0026))).endswith("within 2σ")
    assert "above fig2's break" in READINGS["basins.smooth_order"](_loader(_smooth_docs(0.3, 0.24, 0.2755, 0.0026)))


def _f5_docs(quick_rows, paper_rows):
    def rows(rs):
        return {
            "verdict_5b": {"rows": [{"construction": c, "delta": d, "delta_interval": [lo, hi]} for c, d, lo, hi in rs]}
        }

    docs = {"quick": rows(quick_rows), None: rows(paper_rows)}
    return lambda study, scale: docs[scale]


def test_the_fig5_intervals_reading_gives_the_width_ratios_and_calls_statistics_only_when_every_pair_overlaps():
    """cut: quick [−0.03, 0.03] (width 0.06) against paper [0.00, 0.02] (0.02): 3.0 times, value 0.0 inside; ours:
    quick [0.04, 0.08] against [0.05, 0.07]: 2.0 times, value 0.06 inside; with ours' paper interval moved to
    [0.09, 0.11] the two do not overlap."""
    text = READINGS["fig5.intervals_by_scale"](
        _f5_docs(
            [("cut", 0.0, -0.03, 0.03), ("ours", 0.06, 0.04, 0.08)],
            [("cut", 0.01, 0.0, 0.02), ("ours", 0.06, 0.05, 0.07)],
        )
    )
    assert text == (
        "the paper-scale 95 % intervals are 2.0 to 3.0 times narrower than the quick ones; 2 of 2 quick values lie "
        "inside their paper-scale interval, and every quick interval overlaps its paper-scale one: statistics"
    )
    text = READINGS["fig5.intervals_by_scale"](
        _f5_docs(
            [("cut", 0.0, -0.03, 0.03), ("ours", 0.06, 0.04, 0.08)],
            [("cut", 0.01, 0.0, 0.02), ("ours", 0.1, 0.09, 0.11)],
        )
    )
    assert "1 of 2 quick values" in text and text.endswith("do not overlap for ours: not statistics alone there")


def test_the_regular_majority_reading_says_more_than_half_only_two_sigma_above_one_half():
    """0.64 ± 0.04 (0.56 > 0.5): more than half; 0.51 ± 0.03: within 2σ of one half; a count of 0 (its bound) and
    0.40 ± 0.01: less than half; the well ICs are not read."""

    def cell(cid, f, err=None, upper=None):
        return {"id": cid, "regular_fraction": f, "regular_err_total": err, "regular_fraction_upper": upper}

    cells = [
        cell("a-1.05-disk", 0.64, 0.04),
        cell("a-1.1-disk", 0.51, 0.03),
        cell("a-1.05-well", 0.9, 0.01),
        cell("b-1.05-disk", 0.0, upper=3e-4),
        cell("b-1.1-disk", 0.40, 0.01),
    ]
    text = READINGS["generality.regular_majority"](_loader({"generality": {"validity_map": cells}}))
    assert text == (
        "more than half of the orbits are regular by the indicator (the fraction 2σ of its total error above one "
        "half) for a at 1.05 E_c; about half, within 2σ of one half, for a at 1.1 E_c; less than half at every "
        "energy for b"
    )


def test_the_paper_radius_reading_sorts_the_energies_by_where_the_radius_lies_against_each_lyapunov_orbit():
    """r_esc = 1.03 against orbits spanning [1.001, 1.002] (beyond), [1.02, 1.05] (cuts) and [1.04, 1.09] (inside)."""
    lyap = {
        "E=0.30": {"r_min": 1.04, "r_max": 1.09},
        "E=0.17": {"r_min": 1.001, "r_max": 1.002},
        "E=0.25": {"r_min": 1.02, "r_max": 1.05},
    }
    text = READINGS["resc.paper_radius"](_loader({"resc": {"r_esc": [1.5, 1.03], "lyapunov": lyap}}))
    assert text == (
        "r_esc = 1.03 lies inside the exits' Lyapunov orbits (an orbit crossing it may come back) at E = 0.30; "
        "cuts them at E = 0.25; lies beyond them at E = 0.17"
    )


def _grid(kappa):
    """The eigenvector convergence grid of the operator study: three box sides × three samples per box."""
    cells = [(0.0125, 4), (0.0125, 16), (0.0125, 64), (0.025, 16), (0.025, 64), (0.025, 256), (0.05, 64)]
    cells += [(0.05, 256), (0.05, 1024)]
    return [{"energy": 0.3, "box": b, "samples_per_box": m, "kappa": kappa(b, m, i)} for i, (b, m) in enumerate(cells)]


def test_the_operator_trends_state_the_fitted_exponents_and_resolve_them_at_two_sigma():
    """κ = 0.2·M^(−0.05)·b^0 with a ±0.1 % wobble: the M exponent −0.050 is resolved (falls), the b exponent 0 is
    not; κ = 0.2·b^(−0.05) gives the mirror words."""
    wobble = (1, -1, 0, 1, -1, 0, -1, 1, 0)

    def docs(kappa):
        return _loader({"operator": {"cmeasure_convergence": _grid(kappa)}})

    g = docs(lambda b, m, i: 0.2 * m**-0.05 * math.exp(1e-3 * wobble[i]))
    text = READINGS["operator.samples_trend"](g)
    assert text.startswith("at fixed box side κ falls as M grows (κ ∝ M^s, exponent −0.050")
    assert READINGS["operator.box_trend"](g).startswith("at fixed samples per box κ shows no trend in b resolved at 2σ")
    g = docs(lambda b, m, i: 0.2 * b**-0.05 * math.exp(1e-3 * wobble[i]))
    assert READINGS["operator.box_trend"](g).startswith("at fixed samples per box κ rises as the boxes shrink")
    assert "κ shows no trend in M resolved at 2σ" in READINGS["operator.samples_trend"](g)


def test_the_operator_reduced_reading_states_the_rms_against_the_spread_of_ln_p():
    """P_sim = 1, 0.1, 0.01 (t = 1, 2, 3; t = 4 past the compared time): ln P's variance is 2·ln(10)²/3 = 3.534,
    an rms of 0.30 is 0.09/3.534 = 2.5 % of it, over 2.0 decades."""
    rows = [{"t": t, "sim": p} for t, p in ((1.0, 1.0), (2.0, 0.1), (3.0, 0.01), (4.0, 0.001))]
    d = {"P_at": rows, "compared_until": 3.0, "lnP_rms_reduced": 0.30, "lnP_rms_operator": 0.20}
    text = READINGS["operator.reduced"](_loader({"operator": {"dissipative": d}}))
    assert text == (
        "ρ(E) alone follows ln P(t) to an rms of 0.30, above the full operator's 0.20, while P_sim falls by 2.0 "
        "decades over t = 1 to 3: its mean square is 2.5 % of the variance of ln P_sim at the table's times up to t = 3"
    )


def test_the_operator_spread_reading_is_wider_only_beyond_two_sigma_of_the_simulated_spread():
    """N = 5001 survivors with spread 0.01: its error is 0.01/√10000 = 0.0001; 0.0103 is +3σ (wider), 0.0101 +1σ."""

    def text(op):
        d = {"t_star_std_energy": {"operator": op, "sim": 0.01}, "t_star_points_sim": 5001}
        return READINGS["operator.t_star_spread"](_loader({"operator": {"dissipative": d}}))

    assert text(0.0103).endswith("wider than the simulated spread by more than 2σ (ratio 1.03, z = +3.0)")
    assert text(0.0101).endswith("within 2σ of the simulated spread (ratio 1.01, z = +1.0)")
    assert "narrower" in text(0.0096)


def test_the_operator_cost_reading_orders_the_routes_only_where_the_lower_bound_decides():
    def row(e, pt, op):
        return {"energy": e, "pt_orbit_time_1pct": pt, "op_orbit_time_1pct": op}

    def text(rows):
        return READINGS["operator.cost"](_loader({"operator": {"cost": rows}}))

    assert text([row(0.3, 1.0, 4.0), row(0.25, 2.0, 3.0)]) == (
        "for κ alone the P(t) route needs less orbit-time at all 2 cost energies (0.25, 0.3) (the operator's lower "
        "bound over the P(t) route's: 1.5 to 4.0)"
    )
    mixed = text([row(0.25, 1.0, 4.0), row(0.3, 5.0, 3.0)])
    assert "at E = 0.25;" in mixed and "at E = 0.3 the operator's lower bound lies under" in mixed
    assert "does not decide which route is cheaper" in text([row(0.25, 5.0, 3.0)])


def test_the_operator_finest_reading_takes_its_verdicts_from_the_one_rule():
    """0.21 ± 0.003 against 0.20 ± 0.004 is z = +2.0 (agrees, at the rule's edge); 0.15 ± 0.001 against 0.10 ± 0.001
    differs (z = +35.4)."""

    def row(e, k, ke, f, fe):
        return {"energy": e, "kappa": k, "kappa_stat_err": ke, "fig2_kappa": f, "fig2_err": fe}

    rows = [row(0.3, 0.21, 0.003, 0.20, 0.004), row(0.25, 0.15, 0.001, 0.10, 0.001)]
    text = READINGS["operator.finest"](_loader({"operator": {"kappa_ulam": rows}}))
    assert text == (
        "the finest boxes alone give 0.210 ± 0.003 at E = 0.3 (statistical error), against fig2's κ0: agrees "
        "(z = +2.0); of the 2 energies, they differ from it at E = 0.25 (z = +35.4)"
    )


def test_the_fig6_scale_reading_counts_the_fits_whose_residual_grows_from_the_two_scales():
    """10⁵ → 10⁶ orbits is 10 times; 20 → 23 and 30 → 31 points gain 1 to 3; the rms grows in one fit of two."""

    def fit(pair, n, points, rms):
        return {
            "pair": pair,
            "model": "homogeneous",
            "hazard": "paper",
            "N": n,
            "n_points": points,
            "rms_log_residual": rms,
        }

    docs = {
        "quick": {"fits": [fit("a", 100_000, 20, 0.5), fit("b", 100_000, 30, 2.0)]},
        "paper": {"fits": [fit("a", 1_000_000, 23, 0.9), fit("b", 1_000_000, 31, 1.5)]},
    }
    text = READINGS["fig6.fit_range"](lambda study, scale: docs[scale])
    assert text == (
        "with 10 times the orbits per pair the fits take 1 to 3 more points each, and the rms log residual grows in 1 "
        "of the 2 fits (pair × model × hazard); it does not grow in b homogeneous (paper)"
    )


def test_the_tangent_orbits_reading_counts_the_same_ends_or_names_the_earlier_run():
    """With the key at every point: the counts summed (1 590 + 10 of 1 590 + 12); without it: the earlier run and
    the orbits λ̄ rests on, from the smallest count to the largest."""

    def point(same=None, sel=None, n=None):
        p = {"lyapunov": 0.2, "lyapunov_detail": {"n_orbits": n}}
        return p | ({"tangent_same_orbits": {"same_t_end": same, "selected": sel}} if sel is not None else {})

    new = READINGS["saddle.tangent_orbits"](_loader({"saddle": {"saddle": [point(1590, 1590), point(10, 12)]}}))
    assert (
        new
        == "at this scale the tangent run ended 1 600 of 1 602 selected orbits at the main run's t_end (over its 2 points)"
    )
    old = READINGS["saddle.tangent_orbits"](_loader({"saddle": {"saddle": [point(n=18), point(n=1500)]}}))
    assert old.startswith("this scale's numbers come from an earlier tangent run") and old.endswith(
        "from 18 to 1 500 per point"
    )


def test_the_floor_scan_reading_tests_each_floor_against_the_rule_s_by_the_verdict_rule():
    """Hand-built scans: at the first point the floor × 0.25 moves d₁ by 0.05 with σ = √(0.01² + 0.01²) = 0.0141
    (z = +3.5, beyond 2σ) and × 4 by 0.01 (z = −0.7); at the second every floor is within 2σ (and × 4 has no d₁);
    the third has no d₁ at the rule's floor (untested); a point without a scan is not a cell."""

    def row(factor, value=None, err=0.01):
        return {"factor": factor, "d1": None if value is None else {"value": value, "err": err}}

    points = [
        {
            "system": "henon_heiles",
            "ratio": 1.5,
            "d1_floor_scan": {"rows": [row(0.25, 0.74), row(1.0, 0.69), row(4.0, 0.68)]},
        },
        {"system": "barbanis", "ratio": 2.6, "d1_floor_scan": {"rows": [row(0.25, 0.60), row(1.0, 0.59), row(4.0)]}},
        {"system": "contopoulos", "ratio": 1.7, "d1_floor_scan": {"rows": [row(0.25, 0.6), row(1.0)]}},
        {"system": "henon_heiles", "ratio": 3.0},
    ]
    doc = {"saddle": {"saddle": points, "rules": {"d1_floor_factors": [0.25, 1.0, 4.0]}}}
    text = READINGS["saddle.floor_scan"](_loader(doc))
    assert text == (
        "d₁ moves beyond 2σ with the floor at Hénon–Heiles E/E_c = 1.5 (×0.25: d₁ = 0.740 ± 0.010, z = +3.5); d₁ stays "
        "within 2σ with the floor × 0.25, 4 at every other point (Barbanis E/E_c = 2.6); no d₁ at the floor at "
        "Contopoulos E/E_c = 1.7; no d₁ with the floor × 4 (fewer than four scales above it) at Barbanis E/E_c = 2.6"
    )
    every = {"saddle": {"saddle": points[1:2], "rules": {"d1_floor_factors": [0.25, 1.0, 4.0]}}}
    assert READINGS["saddle.floor_scan"](_loader(every)) == (
        "d₁ stays within 2σ with the floor × 0.25, 4 at every point (Barbanis E/E_c = 2.6); no d₁ with the floor × 4 "
        "(fewer than four scales above it) at Barbanis E/E_c = 2.6"
    )
    none = {"saddle": {"saddle": points[3:], "rules": {"d1_floor_factors": [1.0]}}}
    assert READINGS["saddle.floor_scan"](_loader(none)) == "no point of this scale has d₁'s floor scan"
