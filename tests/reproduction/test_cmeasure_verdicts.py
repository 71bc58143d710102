"""Paper-comparison rows of the section points against the c-measure, on records with a known answer."""

from __future__ import annotations

import pandas as pd
import pytest

from hhscatter.reproduction.cmeasure_verdicts import (
    REFS_QUANTITY,
    VERDICT_QUANTITY,
    closer_comparisons,
    difference_comparisons,
    interval_verdict,
    qualify_our_5b,
    reference_comparisons,
    scale_comparisons,
)


@pytest.mark.parametrize(
    "lo, hi, sign, word",
    [
        (0.1, 0.2, +1, "agrees"),
        (-0.2, -0.1, +1, "differs"),
        (-0.1, 0.1, +1, "no significant difference"),
        (-0.2, -0.1, -1, "agrees"),
        (0.1, 0.2, -1, "differs"),
        (0.0, 0.1, -1, "no significant difference"),
    ],
)
def test_interval_verdict(lo, hi, sign, word):
    assert interval_verdict(lo, hi, sign) == word


def test_our_5b_differs_only_if_the_authors_5b_does():
    """Our 5b (5a filtered to the band) 'differs' is qualified when the authors' own 5b agrees."""

    def rows(auth_verdict):
        return [
            {"quantity": "Fig. 5b: SW1(diss, μ_c^0.30) < SW1(diss, μ_c^0.35)", "verdict": "differs"},
            {"quantity": "Fig. 5a: SW1(diss, μ_c^0.30) < SW1(diss, μ_c^0.35)", "verdict": "differs"},
            {
                "quantity": REFS_QUANTITY.format(s="5b") + ": the authors' 5a and 5b runs, r < 1 on every set",
                "verdict": auth_verdict,
                "authors": True,
            },
        ]

    agreeing = rows("agrees")
    qualify_our_5b(agreeing, "like for like")
    assert agreeing[0]["verdict"].startswith("differs in our convention only")
    assert agreeing[1]["verdict"] == "differs"  # 5a is not 5b
    differing = rows("differs")
    qualify_our_5b(differing, "like for like")
    assert differing[0]["verdict"] == "differs"
    # our 5b − 5a row is checked against the authors' row of the like-for-like construction
    ab = [
        {"quantity": VERDICT_QUANTITY.format(label="ours"), "verdict": "differs"},
        {"quantity": VERDICT_QUANTITY.format(label="like"), "verdict": "no significant difference", "authors": True},
    ]
    qualify_our_5b(ab, "like")
    assert ab[0]["verdict"].endswith("construction of 5b: no significant difference")


def _diff_row(key, lo, hi):
    return {
        "construction": key,
        "label": key,
        "delta": (lo + hi) / 2,
        "delta_interval": [lo, hi],
        "d_5a": 0.2,
        "d_5b": 0.2 + (lo + hi) / 2,
        "box": 0.05,
        "offsets": 16,
        "offset_spread_of_delta": 0.01,
    }


def test_difference_comparisons_qualify_ours_by_the_like_for_like_row():
    rec = {
        "rows": [
            _diff_row("cut_offsets", -0.02, 0.01),
            _diff_row("ours", 0.01, 0.03),
            {"construction": "old", "note": "x"},
        ],
        "level": 0.95,
        "n_boot": 100,
    }
    rows = difference_comparisons(rec, {"cut_offsets": "authors' setup", "ours": None, "old": "a"})
    assert [r["verdict"] for r in rows] == [
        "no significant difference",
        "differs in our convention only; in the authors' construction, like for like: no significant difference",
    ]
    assert rows[0]["authors"] and rows[0]["convention"] == "authors' setup" and not rows[1]["authors"]
    assert rows[1]["ours"] == "+0.020 [+0.010, +0.030]" and "95 % interval from 100" in rows[1]["note"]
    rec["rows"][0] = _diff_row("cut_offsets", 0.01, 0.02)
    assert difference_comparisons(rec, {"cut_offsets": "a", "ours": None})[1]["verdict"] == "differs"


def test_reference_comparisons_are_closer_to_e1_when_delta_is_positive():
    iv = lambda v, lo, hi: {"value": v, "interval": [lo, hi]}  # noqa: E731
    rows = [
        {"construction": c, "label": c, "set": s, "d_E1": iv(0.1, 0.05, 0.15), "d_E2": iv(0.3, 0.2, 0.4)}
        | {"delta": iv(d, lo, hi), "n_set": 10, "n_E1": 20, "n_E2": 30}
        for c, s, d, lo, hi in (("ours", "5a", 0.2, 0.1, 0.3), ("authors", "5b", -0.1, -0.2, 0.05))
    ]
    rec = {"rows": rows, "E1": 0.3, "E2": 0.35, "box": 0.05, "offsets": 16, "level": 0.95, "n_boot": 100}
    out = reference_comparisons(rec, "authors' square ICs")
    assert [(r["verdict"], r["authors"], r["convention"]) for r in out] == [
        ("agrees", False, None),
        ("no significant difference", True, "authors' square ICs"),
    ]
    assert out[0]["quantity"].startswith(REFS_QUANTITY.format(s="5a")) and "10 / 20 / 30 points" in out[0]["note"]


def test_scale_comparisons():
    def rec(share, steps):
        c = lambda t, e: {"t_star": t, "eps_delta": e, "eps_delta_interval": [e, None], "d": [0.3, 0.2]}  # noqa: E731
        return {
            "curves": [c(8.5, None), c(17.0, 0.05)],
            "level": 0.95,
            "eps_shrink_share": share,
            "n_boot": 100,
            "delta": 0.1,
            "box_headline": 0.05,
            "boxes": [0.1, 0.05],
            "offsets": 16,
            "steps": [{"value": (lo + hi) / 2, "interval": [lo, hi]} for lo, hi in steps],
        }

    eps, d = scale_comparisons(rec(0.96, [(-0.03, -0.01)]))
    assert (eps["verdict"], d["verdict"]) == ("agrees", "agrees")
    assert "t*=8.5: none [none, none]; t*=17.0: 0.05 [0.05, none]" == eps["ours"]
    assert d["ours"].startswith("t*=8.5: 0.200, t*=17.0: 0.200; steps -0.020")
    eps, d = scale_comparisons(rec(0.5, [(-0.03, -0.01), (0.01, 0.02)]))
    assert (eps["verdict"], d["verdict"]) == ("not shown", "differs")
    assert scale_comparisons(rec(0.5, [(-0.03, 0.01)]))[1]["verdict"] == "not shown"
    assert scale_comparisons(None) == [] and scale_comparisons({"note": "too few"}) == []


def test_closer_comparisons_by_sliced_wasserstein_with_two_sigma():
    pg = pd.DataFrame(
        [
            {"gamma": g, "t_star": 17.0, "t_star_err": 0.2, "N": 10000, "n_a_all": 30, "n_a": 25}
            | {"mean_E_a": 0.301, "std_E_a": 0.01}
            for g in (0.01, 0.02)
        ]
    )
    sw = {
        ("a", "E1"): (0.020, 0.002),
        ("a", "E2"): (0.030, 0.002),
        ("b", "E1"): (0.020, 0.004),
        ("b", "E2"): (0.030, 0.004),
    }
    stab = pd.DataFrame([{"gamma": 0.01, "set": s, "ref": r, "sw1": v, "sw1_err": e} for (s, r), (v, e) in sw.items()])
    rows, closer = closer_comparisons(
        pg, stab, 0.01, mu=0.9, mu_err=0.01, mu_source="fig3.json:mu", E1=0.3, paper={"t_star": 17.0, "fraction": 3e-3}
    )
    # a: 0.020 + 2·√(2)·0.002 = 0.0257 < 0.030; b: 0.020 + 2·√2·0.004 = 0.0313 ≥ 0.030
    assert closer == {"a": True, "b": False}
    assert [r["verdict"] for r in rows[3:]] == ["agrees", "differs"]
    t, frac, mean_e = rows[:3]
    assert (t["ours"], t["err"], t["paper"]) == (17.0, 0.2, 17.0) and "fig3.json:mu" in t["note"]
    assert frac["ours"] == 3e-3 and frac["err"] == pytest.approx((3e-3 * (1 - 3e-3) / 1e4) ** 0.5)
    assert frac["verdict"] == "comparable"
    assert mean_e["err"] == pytest.approx(0.01 / 5) and mean_e["paper"] == 0.3
