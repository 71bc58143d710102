"""Study fig2's comparison of κ and τ* with the paper (its law of Fig. 2b per regime, the two definitions of τ*) on
synthetic input with a known answer."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from hhscatter.studies import stage_module

mod = stage_module("fig2")


class _Recorder:
    """Stands in for a Study: records compare() calls."""

    def __init__(self):
        self.rows = []

    def compare(self, quantity, ours, err=None, paper=None, **kw):
        self.rows.append({"quantity": quantity, "ours": ours, "err": err, "paper": paper, **kw})


def _fit_result(kappa=0.2, kappa_err=0.01):
    return SimpleNamespace(kappa=kappa, kappa_err=kappa_err)


def test_compare_pt_uses_the_paper_law_of_each_regime_and_no_tail_rows_without_a_tail():
    st = _Recorder()
    E_C = 1.0 / 6.0
    no_tail = SimpleNamespace(tail=None)
    mod.compare_pt(st, 0.25, _fit_result(), no_tail, E_C)  # below E_b = 0.27: a x² + b x
    mod.compare_pt(st, 0.30, _fit_result(), no_tail, E_C)  # above: c x
    x1, x2 = 0.25 - E_C, 0.30 - E_C
    assert [r["paper"] for r in st.rows] == pytest.approx([13.63 * x1**2 + 0.03 * x1, 1.41 * x2])
    assert [r["quantity"] for r in st.rows] == ["kappa(E0=0.25) [Fig. 2a]", "kappa(E0=0.30) [Fig. 2a]"]


def test_compare_pt_tau_star_error_is_the_distance_of_its_two_definitions():
    st = _Recorder()
    tl = SimpleNamespace(window=(80.0, 500.0), z=2.1, z_err=0.1)
    mod.compare_pt(st, 0.25, _fit_result(), SimpleNamespace(tail=tl, tau_star=95.0), 1.0 / 6.0)
    mod.compare_pt(st, 0.25, _fit_result(), SimpleNamespace(tail=tl, tau_star=float("inf")), 1.0 / 6.0)
    tau = [r for r in st.rows if r["quantity"].startswith("tau*")]
    assert (tau[0]["ours"], tau[0]["err"], tau[0]["verdict"]) == (95.0, 15.0, None)
    # no crossing: τ* = τ_c = 80, within 20 % of the paper's 100
    assert (tau[1]["ours"], tau[1]["err"], tau[1]["verdict"]) == (80.0, None, "agrees within 20 %")
    assert [r["ours"] for r in st.rows if r["quantity"].startswith("z ")] == [2.1, 2.1]
